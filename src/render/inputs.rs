//! Writes into the frame's images outside the frame, as passes of the graph:
//! synthetic SSS inputs (tests compare the GPU passes with CPU references on
//! them) and fills of the intermediates (zeroed at set-up outside the SSS
//! region; poisoned by tests so a tap that reads outside shows). Their accesses
//! are declared here once: the renderer creates the images with the usages they
//! need, and the passes use the same kinds.

use anyhow::{bail, Result};
use ash::vk;

use super::Renderer;
use crate::graph::work::{PassRole, Work};
use crate::graph::{ImageId, Pass, PassContext};
use crate::method::{FrameTargets, STENCIL_SKIN};
use crate::vk::barrier::AccessKind;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;

/// How the uploads write the targets (whole contents): what
/// `Pass::transfer_dst` declares.
const UPLOAD_ACCESS: AccessKind = AccessKind::TransferWrite;
/// How fills write the intermediates (whole contents, by a clear): what
/// `Pass::clear_dst` declares.
pub const FILL_ACCESS: AccessKind = AccessKind::ClearWrite;

/// The images `upload_sss_inputs`, `upload_normals`, `upload_hdr` and `upload_ldr` write.
pub fn upload_accesses(t: &FrameTargets) -> Vec<(ImageId, AccessKind)> {
    [t.diffuse, t.linear_depth, t.depth_stencil, t.hdr, t.ldr]
        .into_iter()
        .chain(t.normals)
        .map(|i| (i, UPLOAD_ACCESS))
        .collect()
}

/// One upload: the image, its bytes, and (aspect, offset in the bytes) per region.
type Upload<'a> = (ImageId, &'a [u8], Vec<(vk::ImageAspectFlags, u64)>);

/// A setup pass copying `buffer` into `image`: one region per (aspect, offset).
fn upload_pass<'a>(
    name: &str,
    image: ImageId,
    buffer: vk::Buffer,
    aspects: Vec<(vk::ImageAspectFlags, u64)>,
    extent: vk::Extent2D,
    bytes: u64,
) -> Pass<'a> {
    let mut pass = Pass::new(name, PassRole::Setup);
    let dst = pass.transfer_dst(image);
    debug_assert_eq!(dst.access(), UPLOAD_ACCESS);
    pass.work(Work::Copy {
        texels: extent.width as u64 * extent.height as u64,
        bytes_per_texel: (bytes / (extent.width as u64 * extent.height as u64).max(1)) as u32,
        rects: aspects.len() as u32,
    })
    .record(move |pc: &PassContext| {
        let regions: Vec<vk::BufferImageCopy> = aspects
            .iter()
            .map(|&(aspect, offset)| {
                vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(aspect)
                            .layer_count(1),
                    )
                    .image_extent(vk::Extent3D {
                        width: extent.width,
                        height: extent.height,
                        depth: 1,
                    })
            })
            .collect();
        pc.copy_buffer_to_image(buffer, dst, &regions);
    })
}

impl Renderer<'_> {
    /// Fills every intermediate of the method with `value` in every channel.
    pub(super) fn fill_intermediates(&mut self, value: f32) -> Result<()> {
        let ids: Vec<_> = self.groups.iter().flat_map(|g| g.intermediates()).collect();
        let passes: Vec<Pass> = ids
            .into_iter()
            .map(|id| {
                let e = self.resources.extent(id);
                let mut pass =
                    Pass::new(format!("fill {}", self.resources.name(id)), PassRole::Setup);
                let dst = pass.clear_dst(id);
                debug_assert_eq!(dst.access(), FILL_ACCESS);
                pass.work(Work::Clear {
                    texels: e.width as u64 * e.height as u64,
                    bytes_per_texel: 8,
                })
                .record(move |pc: &PassContext| {
                    let range = vk::ImageSubresourceRange::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .level_count(1)
                        .layer_count(1);
                    let value = vk::ClearColorValue {
                        float32: [value; 4],
                    };
                    pc.clear_color_image(dst, &value, &[range]);
                })
            })
            .collect();
        self.submit_untimed(&passes, "while filling the intermediates")
    }

    /// Fills the SSS intermediates with `value` (tests): texels the seed copies
    /// skip keep it, so a tap that reads one shows in the output.
    pub fn poison_intermediates(&mut self, value: f32) -> Result<()> {
        self.fill_intermediates(value)
    }

    /// Uploads synthetic inputs into the SSS targets (tests): diffuse RGBA as f16,
    /// linear depth (the depth buffer gets the matching projected depth), and the
    /// stencil skin bit. The skin is then wherever the upload says, so the SSS
    /// region becomes the whole screen.
    pub fn upload_sss_inputs(
        &mut self,
        diffuse_f16: &[u16],
        depth: &[f32],
        skin: &[bool],
    ) -> Result<()> {
        let t = self.frame.targets;
        let ds_format = self.resources.format(t.depth_stencil);
        if ds_format != vk::Format::D32_SFLOAT_S8_UINT {
            bail!("depth/stencil uploads need D32_SFLOAT_S8_UINT, the device gave {ds_format:?}");
        }
        let extent = self.frame.extent;
        let ndc: Vec<f32> = depth
            .iter()
            .map(|&d| self.ndc_depth(d).clamp(0.0, 1.0))
            .collect();
        let mut ds_bytes: Vec<u8> = bytemuck::cast_slice(&ndc).to_vec();
        let stencil_offset = ds_bytes.len() as u64;
        ds_bytes.extend(skin.iter().map(|&s| if s { STENCIL_SKIN as u8 } else { 0 }));
        let color = vk::ImageAspectFlags::COLOR;
        let uploads: [Upload; 3] = [
            (
                t.diffuse,
                bytemuck::cast_slice(diffuse_f16),
                vec![(color, 0)],
            ),
            (
                t.linear_depth,
                bytemuck::cast_slice(depth),
                vec![(color, 0)],
            ),
            (
                t.depth_stencil,
                &ds_bytes,
                vec![
                    (vk::ImageAspectFlags::DEPTH, 0),
                    (vk::ImageAspectFlags::STENCIL, stencil_offset),
                ],
            ),
        ];
        self.upload(uploads.into_iter().collect(), extent)?;
        let full = crate::method::region::PixelRect::full(extent.width, extent.height);
        self.set_region(vec![full]);
        Ok(())
    }

    /// Uploads synthetic view-space normals (RGBA f16) into level 0 of the normal
    /// target (tests of methods that read normals).
    pub fn upload_normals(&mut self, normals_f16: &[u16]) -> Result<()> {
        let Some(id) = self.frame.targets.normals else {
            bail!("this method has no normal target");
        };
        let extent = self.frame.extent;
        self.upload(
            vec![(
                id,
                bytemuck::cast_slice(normals_f16),
                vec![(vk::ImageAspectFlags::COLOR, 0)],
            )],
            extent,
        )
    }

    /// Uploads a synthetic HDR composite (tests of the bloom): RGBA f16
    /// bits, row-major, top row first.
    pub fn upload_hdr(&mut self, rgba_f16: &[u16]) -> Result<()> {
        let extent = self.frame.extent;
        let want = extent.width as usize * extent.height as usize * 4;
        if rgba_f16.len() != want {
            bail!(
                "a {}x{} composite needs {want} half floats, got {}",
                extent.width,
                extent.height,
                rgba_f16.len()
            );
        }
        let hdr = self.frame.targets.hdr;
        self.upload(
            vec![(
                hdr,
                bytemuck::cast_slice(rgba_f16),
                vec![(vk::ImageAspectFlags::COLOR, 0)],
            )],
            extent,
        )
    }

    /// Uploads a synthetic tone-mapped frame (tests of the post chain):
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub fn upload_ldr(&mut self, rgba8: &[u8]) -> Result<()> {
        let extent = self.frame.extent;
        let want = extent.width as usize * extent.height as usize * 4;
        if rgba8.len() != want {
            bail!(
                "a {}x{} frame needs {want} bytes, got {}",
                extent.width,
                extent.height,
                rgba8.len()
            );
        }
        let ldr = self.frame.targets.ldr;
        self.upload(
            vec![(ldr, rgba8, vec![(vk::ImageAspectFlags::COLOR, 0)])],
            extent,
        )
    }

    fn upload(&mut self, uploads: Vec<Upload>, extent: vk::Extent2D) -> Result<()> {
        // Freed when this returns: after the upload's fence (`submit_untimed`
        // waits on it), or at once on an error.
        let mut staging = Guard::new(self.ctx, Vec::new());
        for (id, bytes, _) in &uploads {
            staging.push(Buffer::with_data(
                self.ctx,
                &format!("{} upload", self.resources.name(*id)),
                bytes,
                vk::BufferUsageFlags::TRANSFER_SRC,
            )?);
        }
        let passes: Vec<Pass> = uploads
            .into_iter()
            .zip(staging.iter())
            .map(|((id, bytes, aspects), b)| {
                upload_pass(
                    &format!("upload {}", self.resources.name(id)),
                    id,
                    b.raw,
                    aspects,
                    extent,
                    bytes.len() as u64,
                )
            })
            .collect();
        self.submit_untimed(&passes, "while uploading test inputs")
    }
}
