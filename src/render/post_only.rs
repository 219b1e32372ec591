//! The post chain alone (tests): its passes on whatever the tone-mapped frame
//! holds (`Renderer::upload_ldr` puts a synthetic image there), so the AA
//! stages are checked against their CPU references on known images.

use anyhow::{bail, Result};

use super::{submit_and_read, Renderer};
use crate::graph::{ImageId, PassSample};

impl Renderer<'_> {
    /// Runs the post chain's anti-aliasing passes (not the tone map, which
    /// would overwrite the uploaded frame) and reads back the frame's output (linear
    /// float RGBA, decoded from sRGB) with each pass's samples.
    pub fn run_post_only(&mut self) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
        let mut passes = Vec::new();
        let ldr = self.frame.targets.ldr;
        let output = self
            .frame
            .post
            .anti_alias(&mut passes, &self.resources, ldr);
        if passes.is_empty() {
            bail!("the post-only run needs an anti-aliasing stage (--aa)");
        }
        submit_and_read(
            self.ctx,
            &self.submit,
            &mut self.resources,
            output,
            passes,
            true,
            "during the post-only run",
        )
    }

    /// Runs the bloom's passes alone on whatever the HDR composite holds
    /// (`Renderer::upload_hdr` puts a synthetic image there) and reads back
    /// the bloomed composite with each pass's samples.
    pub fn run_bloom_only(&mut self) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
        let mut passes = Vec::new();
        let hdr = self.frame.targets.hdr;
        let output = self.frame.post.bloom(&mut passes, &self.resources, hdr);
        if passes.is_empty() {
            bail!("the bloom-only run needs --bloom");
        }
        submit_and_read(
            self.ctx,
            &self.submit,
            &mut self.resources,
            output,
            passes,
            true,
            "during the bloom-only run",
        )
    }

    /// The post stage's image `name` (see `post::AaStage::images`).
    pub fn post_image(&self, name: &str) -> Result<ImageId> {
        match self.frame.post.image(name) {
            Some(id) => Ok(id),
            None => bail!("the post stage has no image '{name}'"),
        }
    }
}
