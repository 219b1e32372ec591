//! Counting what the passes' shaders really fetch (tests): with a context that
//! builds every pipeline from the fetch-counting build of its shaders, each
//! pass of a frame runs on its own between a zeroing of the counters and a
//! read-back, so the counts are per pass.

use anyhow::{bail, Context as _, Result};

use super::Renderer;
use crate::graph::work::{Filter, PassRole, Work};
use crate::graph::{Pass, PassContext};
use crate::vk::barrier::AccessKind;
use crate::vk::context::FETCH_COUNTERS;

/// One pass's counts.
#[derive(Clone, Debug)]
pub struct PassCounts {
    pub name: String,
    /// Shader invocations that reached main (helper invocations excluded).
    pub invocations: u64,
    /// Fetches by site: 1 + (set * 16 + binding) * 4 + kind (fetch_count.glsl).
    pub fetches: Vec<(u32, u64)>,
}

/// The counter site of a fetch of binding (`set`, `binding`) of `kind` (see
/// [`filter_kind`]; shaders/fetch_count.glsl's SITE).
pub fn site(set: u32, binding: u32, kind: u32) -> u32 {
    1 + (set * 16 + binding) * 4 + kind
}

/// The kind number of a filter in the shaders' counter sites.
pub fn filter_kind(f: Filter) -> u32 {
    match f {
        Filter::Point => 0,
        Filter::Bilinear => 1,
        Filter::DepthCompare => 2,
        Filter::Trilinear => 3,
    }
}

/// The binding (`set`, `binding`) and filter of a counter site: [`site`]'s inverse.
pub fn decode_site(site: u32) -> (u32, u32, Filter) {
    let k = site - 1;
    let filter = match k % 4 {
        0 => Filter::Point,
        1 => Filter::Bilinear,
        2 => Filter::DepthCompare,
        _ => Filter::Trilinear,
    };
    ((k / 4) / 16, (k / 4) % 16, filter)
}

impl Renderer<'_> {
    /// Runs one frame pass by pass and returns every pass's counts. Needs a
    /// context made with `count_fetches`.
    pub fn count_fetches(&mut self) -> Result<Vec<PassCounts>> {
        let ctx = self.ctx;
        let counter = ctx
            .fetch_counts
            .as_ref()
            .context("counting fetches needs a context made with count_fetches")?;
        let id = self.resources.add_buffer("fetch counters", counter.raw);
        let mut out = Vec::new();
        // One frame, recorded pass by pass.
        self.begin_frame();
        let n = self.passes().len();
        for i in 0..n {
            let mut passes = self
                .frame
                .passes(&self.groups, &self.merge, &self.resources);
            let mut pass = passes.swap_remove(i);
            drop(passes);
            let counted = match pass.declared_work(&self.resources) {
                Some(Work::Compute { .. }) => AccessKind::ComputeStorageReadWrite,
                _ => AccessKind::FragmentStorageReadWrite,
            };
            let name = pass.name.clone();
            pass.buffers.push((id, counted));
            let mut zero = Pass::new("zero fetch counters", PassRole::Setup);
            // vkCmdFillBuffer runs in the copy stage (what synchronization validation sees).
            let counters = zero.transfer_dst_buffer(id);
            let zero = zero.record(move |pc: &PassContext| pc.fill_buffer(counters, 0));
            let host = Pass::new("fetch counters to host", PassRole::Setup).host_read(id);
            super::submit_passes(
                ctx,
                &self.submit,
                &mut self.resources,
                &[zero, pass, host],
                false,
                "while counting fetches",
            )?;
            let words = counter.read()?;
            if words.len() != FETCH_COUNTERS as usize {
                bail!("fetch counters read back {} words", words.len());
            }
            out.push(PassCounts {
                name,
                invocations: words[0] as u64,
                fetches: words
                    .iter()
                    .enumerate()
                    .skip(1)
                    .filter(|(_, &c)| c > 0)
                    .map(|(s, &c)| (s as u32, c as u64))
                    .collect(),
            });
        }
        self.resources
            .truncate_buffers(self.resources.buffer_count() - 1);
        Ok(out)
    }
}
