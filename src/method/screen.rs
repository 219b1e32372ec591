//! What the screen-space methods share: their intermediates, the seed copy that
//! fills them, the descriptor set of a blur that reads colour and depth, and the
//! work declaration of a stencil-masked full-screen pass.
//!
//! Why seed copies: the SSS passes shade only skin pixels, but their taps read
//! neighbours. Copying the diffuse target into an intermediate first makes its
//! non-skin texels hold what a full-screen blur would have read, so later passes
//! see a consistent neighbourhood and non-skin pixels leave SSS bit for bit
//! unchanged.

use anyhow::Result;
use ash::vk;

use super::{FrameView, MethodBind};
use crate::graph::work::{ColorWrite, DepthStencilUse, Fetch, Filter, PassRole, ShaderWork, Work};
use crate::graph::{work_format, ImageDesc, ImageId, Pass, PassContext, Resources};
use crate::vk::barrier::AccessKind;
use crate::vk::pipeline::{Bind, Pipeline};
use crate::vk::shader_stats::alu_estimate;

/// Declares an intermediate shaped like the diffuse target.
pub fn declare_intermediate(res: &mut Resources, diffuse: ImageId, name: &str) -> ImageId {
    let desc = ImageDesc::new(name, res.extent(diffuse), res.format(diffuse));
    res.declare(desc)
}

/// A fetch declaration: `count` fetches of `image` (its format) through the
/// shader variable `texture`.
pub fn fetch(res: &Resources, image: ImageId, texture: &str, filter: Filter, count: f64) -> Fetch {
    Fetch {
        texture: texture.into(),
        format: work_format(res.format(image))
            .unwrap_or_else(|| panic!("image '{}' has a format work cannot name", res.name(image))),
        filter,
        count,
        exact: true,
        coherent: true,
    }
}

/// A fetch some invocations skip (behind a branch): `count` is the most any makes.
pub fn fetch_at_most(
    res: &Resources,
    image: ImageId,
    texture: &str,
    filter: Filter,
    count: f64,
) -> Fetch {
    Fetch {
        exact: false,
        ..fetch(res, image, texture, filter, count)
    }
}

/// A colour-write declaration for `image`.
pub fn color_write(res: &Resources, image: ImageId, blend: bool) -> ColorWrite {
    ColorWrite {
        format: work_format(res.format(image)).expect("colour targets have work formats"),
        blend,
    }
}

/// The work of a full-screen pass tested against the frame's depth/stencil
/// (stencil on the skin bit when `stencil`, depth when `depth_test`): `shader`
/// runs per shaded fragment with `fetches` and its ALU at `loop_trips`, one
/// triangle per region rectangle.
pub fn masked_work(
    f: &FrameView,
    shader: &str,
    loop_trips: &[u32],
    fetches: Vec<Fetch>,
    color: Vec<ColorWrite>,
    stencil: bool,
    depth_test: bool,
) -> Work {
    let ds = f.targets.depth_stencil;
    Work::Raster {
        shader: Some(ShaderWork {
            shader: shader.into(),
            fetches,
            alu: alu_estimate(shader, loop_trips),
            ..Default::default()
        }),
        color,
        depth_stencil: Some(DepthStencilUse {
            format: work_format(f.res.format(ds)).expect("depth formats have work formats"),
            depth_test,
            depth_write: false,
            stencil_test: stencil,
            stencil_write: false,
        }),
        width: f.extent.width,
        height: f.extent.height,
        triangles: f.region.len() as u64,
        msaa: 1,
        clears: vec![],
    }
}

/// A pass that copies `src` (the diffuse target) into each of `dsts` within
/// `region`: the seeds every method's intermediates start from.
pub fn seed_copy<'a>(
    name: &str,
    f: &FrameView<'a, '_>,
    src: ImageId,
    region: &'a [vk::Rect2D],
    dsts: &[ImageId],
) -> Pass<'a> {
    let extent = f.extent;
    let whole = region.len() == 1
        && region[0].offset == vk::Offset2D::default()
        && region[0].extent == extent;
    // A copy of part of the image keeps the rest (the zeros written at set-up):
    // its barrier must not discard the old contents.
    let write = if whole {
        AccessKind::TransferWrite
    } else {
        AccessKind::TransferWritePartial
    };
    let texels: u64 = region
        .iter()
        .map(|r| r.extent.width as u64 * r.extent.height as u64)
        .sum::<u64>()
        * dsts.len() as u64;
    let bytes_per_texel = work_format(f.res.format(src)).map_or(0, |w| w.bytes_per_texel());
    let mut pass = Pass::new(name, PassRole::Sss)
        .image(src, AccessKind::TransferRead)
        .work(Work::Copy {
            texels,
            bytes_per_texel,
            rects: (region.len() * dsts.len()) as u32,
        });
    for &d in dsts {
        pass = pass.image(d, write);
    }
    let dsts = dsts.to_vec();
    pass.record(move |pc: &PassContext| {
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let copies: Vec<vk::ImageCopy> = region
            .iter()
            .map(|r| {
                let offset = vk::Offset3D {
                    x: r.offset.x,
                    y: r.offset.y,
                    z: 0,
                };
                vk::ImageCopy::default()
                    .src_subresource(layers)
                    .dst_subresource(layers)
                    .src_offset(offset)
                    .dst_offset(offset)
                    .extent(vk::Extent3D {
                        width: r.extent.width,
                        height: r.extent.height,
                        depth: 1,
                    })
            })
            .collect();
        if copies.is_empty() {
            return; // no skin on screen: nothing reads the seeds
        }
        for &dst in &dsts {
            unsafe {
                pc.ctx.device.cmd_copy_image(
                    pc.cmd,
                    pc.image(src).raw,
                    pc.layout(src),
                    pc.image(dst).raw,
                    pc.layout(dst),
                    &copies,
                )
            };
        }
    })
}

/// Set 0 of a blur that reads `color` and the linear depth through the
/// bilinear sampler (`colorTex`, `depthTex`, `linearClamp`).
pub fn source_set(
    b: &MethodBind,
    pipeline: &Pipeline,
    color: ImageId,
) -> Result<vk::DescriptorSet> {
    b.pool.write_set(
        b.ctx,
        pipeline,
        0,
        &[
            ("colorTex", Bind::Texture(b.res.view(color))),
            (
                "depthTex",
                Bind::Texture(b.res.view(b.targets.linear_depth)),
            ),
            ("linearClamp", Bind::Sampler(b.samplers.linear_clamp)),
        ],
    )
}
