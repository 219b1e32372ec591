//! Reading targets back to the host: the final image, and with `--dump` every
//! pass output right after the pass that wrote it (later passes may overwrite
//! a target, as the vertical SSS pass does with the diffuse one).

use anyhow::{bail, Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::format::{Aspect, Format};
use crate::graph::work::{PassRole, Work};
use crate::graph::{BufferId, ImageId, Pass, PassContext, Resources};
use crate::vk::context::Context;
use crate::vk::format::{aspect_flag, from_vk};
use crate::vk::memory::Buffer;

/// One pass output as linear float RGBA.
pub struct DumpedImage {
    pub pass: String,
    pub image: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<[f32; 4]>,
}

/// An image read back as it is stored: its format and bytes.
pub type RawImage = (vk::Format, Vec<u8>);

struct Pending {
    pass: String,
    image: ImageId,
    buffer: Buffer,
    buffer_id: BufferId,
}

/// Which images to read back and where they land.
pub struct ReadbackPlan {
    dump: bool,
    /// Read after the last pass, in this order (one submission for all).
    finals: Vec<ImageId>,
    pending: Vec<Pending>,
    /// `pending[..dumped]` are the dumps; the final copies follow.
    dumped: usize,
    /// Buffer count of the graph before this plan added its own, restored at the end.
    buffers_before: usize,
    /// Depth/stencil images are read back as their stencil aspect (one byte
    /// a texel) instead of their depth.
    stencil: bool,
}

/// Label prefix of the readback passes (a label only: they are found by role).
const PREFIX: &str = "readback";

/// Texels of `format` as linear float RGBA, as the format table decodes a
/// readback of it (single channels replicated to RGB).
pub fn to_rgba_f32(format: vk::Format, bytes: &[u8]) -> Result<Vec<[f32; 4]>> {
    match from_vk(format).and_then(Format::readback) {
        Some((_, _, decode)) => Ok(decode.to_rgba(bytes)),
        None => bail!("reading back {format:?} is not supported"),
    }
}

impl ReadbackPlan {
    /// The `finals` as they are after the last pass, plus every pass output
    /// when `dump` is set.
    pub fn new(dump: bool, finals: &[ImageId]) -> Self {
        ReadbackPlan {
            dump,
            finals: finals.to_vec(),
            pending: Vec::new(),
            dumped: 0,
            buffers_before: 0,
            stencil: false,
        }
    }

    /// The stencil of one depth/stencil image, read after all passes.
    pub fn single_stencil(image: ImageId) -> Self {
        ReadbackPlan {
            stencil: true,
            ..Self::single(image)
        }
    }

    /// Just one image, read after all passes.
    pub fn single(image: ImageId) -> Self {
        Self::new(false, &[image])
    }

    /// The copy holding `id` as the last pass left it: the dump after its last
    /// writer, or its own final copy.
    fn last_copy(&self, id: ImageId) -> Option<&Pending> {
        self.pending.iter().rev().find(|p| p.image == id)
    }

    fn copy_pass<'a>(
        &mut self,
        ctx: &Context,
        res: &mut Resources,
        pass: &str,
        id: ImageId,
    ) -> Result<Option<Pass<'a>>> {
        // Mip levels above 0 are tracked as their own resources but not
        // dumped, and a multisampled image cannot be copied to a buffer: its
        // resolved image is dumped in its place.
        if res.level_of(id) > 0 || res.samples(id) > 1 {
            return Ok(None);
        }
        // The aspect and its bytes a texel from the format table: a stencil
        // plan's stencil, else what the format reads back as.
        let format = res.texel_format(id);
        let copied = match format.copy_bytes(Aspect::Stencil) {
            Some(bytes) if self.stencil => Some((Aspect::Stencil, bytes)),
            _ => format.readback().map(|(aspect, bytes, _)| (aspect, bytes)),
        };
        let Some((aspect, bpt)) = copied else {
            return Ok(None);
        };
        let aspect = aspect_flag(aspect);
        let extent = res.extent(id);
        let size = extent.width as u64 * extent.height as u64 * u64::from(bpt);
        let name = format!("{PREFIX} {pass} -> {}", res.name(id));
        let buffer = Buffer::new(
            ctx,
            &name,
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let buffer_id = res.add_buffer(&name, buffer.raw);
        self.pending.push(Pending {
            pass: pass.to_string(),
            image: id,
            buffer,
            buffer_id,
        });
        let mut copy = Pass::new(name, PassRole::Readback);
        let (src, dst) = (copy.transfer_src(id), copy.transfer_dst_buffer(buffer_id));
        Ok(Some(
            copy.work(Work::Copy {
                texels: extent.width as u64 * extent.height as u64,
                bytes_per_texel: bpt,
                rects: 1,
            })
            .record(move |pc: &PassContext| {
                let region = vk::BufferImageCopy::default()
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(aspect)
                            .layer_count(1),
                    )
                    .image_extent(vk::Extent3D {
                        width: extent.width,
                        height: extent.height,
                        depth: 1,
                    });
                pc.copy_image_to_buffer(src, dst, &[region]);
            }),
        ))
    }

    /// Returns `passes` with the readback copies inserted, and a last pass that
    /// makes the copies visible to the host.
    pub fn interleave<'a>(
        &mut self,
        ctx: &Context,
        res: &mut Resources,
        passes: Vec<Pass<'a>>,
    ) -> Result<Vec<Pass<'a>>> {
        self.buffers_before = res.buffer_count();
        let mut out = Vec::with_capacity(passes.len() * 2 + 2);
        for p in passes {
            let written: Vec<ImageId> = p
                .images
                .iter()
                .filter(|(_, a)| a.is_write())
                .map(|(i, _)| *i)
                .collect();
            let name = p.name.clone();
            out.push(p);
            if self.dump {
                for id in written {
                    if let Some(c) = self.copy_pass(ctx, res, &name, id)? {
                        out.push(c);
                    }
                }
            }
        }
        self.dumped = self.pending.len();
        for id in self.finals.clone() {
            // A dump made after the image's last writer already holds it.
            if self.dump && self.last_copy(id).is_some() {
                continue;
            }
            let c = self
                .copy_pass(ctx, res, "final", id)?
                .with_context(|| format!("{} cannot be read back", res.name(id)))?;
            out.push(c);
        }
        let mut host = Pass::new(format!("{PREFIX} to host"), PassRole::Readback);
        for p in &self.pending {
            host = host.host_read(p.buffer_id);
        }
        out.push(host);
        Ok(out)
    }

    fn read(&self, p: &Pending, res: &Resources) -> Result<(u32, u32, vk::Format, Vec<u8>)> {
        let e = res.extent(p.image);
        Ok((
            e.width,
            e.height,
            res.format(p.image),
            p.buffer.read()?.to_vec(),
        ))
    }

    /// After the fence: each final image's format and raw bytes, in the order
    /// given, and every dump as float. The readback buffers are freed whatever
    /// happens.
    pub fn finish(
        mut self,
        ctx: &Context,
        res: &mut Resources,
    ) -> Result<(Vec<RawImage>, Vec<DumpedImage>)> {
        let out = self.collect(res);
        self.release(ctx, res);
        out
    }

    fn collect(&self, res: &Resources) -> Result<(Vec<RawImage>, Vec<DumpedImage>)> {
        let finals = self
            .finals
            .iter()
            .map(|&id| {
                let p = self
                    .last_copy(id)
                    .with_context(|| format!("{} was not read back", res.name(id)))?;
                let (_, _, format, bytes) = self.read(p, res)?;
                Ok((format, bytes))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut dumps = Vec::new();
        for p in &self.pending[..self.dumped] {
            let (w, h, format, bytes) = self.read(p, res)?;
            dumps.push(DumpedImage {
                pass: p.pass.clone(),
                image: res.name(p.image).to_string(),
                width: w,
                height: h,
                rgba: to_rgba_f32(format, &bytes)?,
            });
        }
        Ok((finals, dumps))
    }

    /// After the fence: the first final image as float RGBA.
    pub fn finish_single(self, ctx: &Context, res: &mut Resources) -> Result<Vec<[f32; 4]>> {
        let (finals, _) = self.finish(ctx, res)?;
        let (format, bytes) = finals.first().context("nothing was read back")?;
        to_rgba_f32(*format, bytes)
    }

    /// After the fence: the bytes of the one image read back (a stencil
    /// plan's: one byte a texel, rows top to bottom).
    pub fn finish_bytes(self, ctx: &Context, res: &mut Resources) -> Result<Vec<u8>> {
        let (mut finals, _) = self.finish(ctx, res)?;
        anyhow::ensure!(!finals.is_empty(), "nothing was read back");
        Ok(finals.swap_remove(0).1)
    }

    /// Frees the readback buffers of a plan whose submission failed.
    pub fn discard(mut self, ctx: &Context, res: &mut Resources) {
        self.release(ctx, res);
    }

    fn release(&mut self, ctx: &Context, res: &mut Resources) {
        for mut p in self.pending.drain(..) {
            p.buffer.destroy(ctx);
        }
        res.truncate_buffers(self.buffers_before);
    }
}

// Beside the plan it uses (render/mod.rs stays small).
impl super::Renderer<'_> {
    /// Reads the stencil of the frame's (single-sample) depth/stencil target
    /// back, one byte a pixel, after a frame: each pixel's group code as the
    /// SSS passes test it (with `--msaa`, the resolve's sample 0).
    pub fn read_stencil(&mut self) -> Result<Vec<u8>> {
        let id = self.frame.targets.depth_stencil;
        let mut plan = ReadbackPlan::single_stencil(id);
        let (ctx, submit) = (self.ctx, &self.submit);
        let done = plan
            .interleave(ctx, &mut self.resources, Vec::new())
            .and_then(|p| {
                super::submit_passes(
                    ctx,
                    submit,
                    &mut self.resources,
                    &p,
                    false,
                    "while reading back the stencil",
                )
            });
        if let Err(e) = done {
            plan.discard(ctx, &mut self.resources);
            return Err(e);
        }
        plan.finish_bytes(ctx, &mut self.resources)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_formats() {
        let one = half::f16::from_f32(1.5).to_bits().to_le_bytes();
        let mut b = Vec::new();
        for _ in 0..4 {
            b.extend_from_slice(&one);
        }
        assert_eq!(
            to_rgba_f32(vk::Format::R16G16B16A16_SFLOAT, &b).unwrap(),
            vec![[1.5; 4]]
        );
        let px = to_rgba_f32(vk::Format::R8G8B8A8_SRGB, &[255, 0, 188, 255]).unwrap()[0];
        assert!((px[0] - 1.0).abs() < 1e-6 && px[1] == 0.0 && (px[2] - 0.5).abs() < 0.01);
        assert!(to_rgba_f32(vk::Format::BC1_RGB_UNORM_BLOCK, &[0; 8]).is_err());
    }
}
