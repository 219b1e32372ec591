//! What the screen-space methods share: their intermediates, the seed copy that
//! fills them, the descriptor set of a blur that reads colour and depth, and the
//! stencil-masked full-screen pass (declared once, here).
//!
//! Why seed copies: the SSS passes shade only skin pixels, but their taps read
//! neighbours. Copying the diffuse target into an intermediate first makes its
//! non-skin texels hold what a full-screen blur would have read, so later passes
//! see a consistent neighbourhood and non-skin pixels leave SSS bit for bit
//! unchanged.

use ash::vk;

use super::{FrameView, MethodSetup};
use crate::graph::draw::fullscreen_in;
use crate::graph::work::{Fetch, Filter, PassRole, ShaderWork, Work};
use crate::graph::{
    Binding, ColorTarget, DepthStencil, GraphSet, ImageDesc, ImageId, Load, Pass, PassContext,
    Resources,
};
use crate::vk::context::Context;
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
        format: res.texel_format(image),
        filter,
        count,
        exact: true,
        coherent: true,
        spread: Vec::new(),
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

/// A full-screen pass tested against the frame's depth/stencil: the one
/// declaration of every stencil-masked SSS pass (separable, ssg, ss-jittered,
/// poisson).
pub struct Masked<'a> {
    pub name: String,
    /// The fragment shader, with its loop trip counts for the ALU estimate.
    pub shader: &'static str,
    pub loop_trips: Vec<u32>,
    pub pipeline: &'a Pipeline,
    /// Its set 0: the images the shader samples (what the pass declares it
    /// reads), bound by name.
    pub set: &'a GraphSet,
    /// What the shader fetches from them.
    pub fetches: Vec<Fetch>,
    /// The colour targets (loaded: pixels outside the mask keep their
    /// contents), each with whether it is blended.
    pub targets: Vec<(ImageId, bool)>,
    /// Stencil-tested on the group's code (`FrameView::stencil`) /
    /// depth-tested (against the depth the
    /// pipeline's triangle is drawn at).
    pub stencil: bool,
    pub depth_test: bool,
}

/// The pass of `m`: the pipeline's full-screen triangle drawn once per
/// rectangle of the frame's SSS region, over the frame's depth/stencil (read
/// only); `state` sets push constants and other dynamic state after the bind.
pub fn masked_pass<'a>(
    f: &FrameView<'a, '_>,
    m: Masked<'a>,
    state: impl Fn(&Context, vk::CommandBuffer) + 'a,
) -> Pass<'a> {
    let ds = f.targets.depth_stencil;
    let region = f.region;
    let work = ShaderWork {
        shader: m.shader.into(),
        fetches: m.fetches,
        alu: alu_estimate(m.shader, &m.loop_trips),
        ..Default::default()
    };
    let mut pass = Pass::new(m.name, PassRole::Sss);
    let set = pass.set(m.set);
    pass = pass.depth_stencil(
        DepthStencil::test_only(ds)
            .depth_test(m.depth_test)
            .stencil_test(m.stencil.then_some(f.stencil)),
    );
    for (t, blend) in m.targets {
        let target = ColorTarget::new(t, Load::Keep);
        pass = pass.color(if blend { target.blended() } else { target });
    }
    let pipeline = m.pipeline;
    pass.draws(Some(work), region.len() as u64)
        .record(move |pc: &PassContext| fullscreen_in(pc, pipeline, &[set], Some(region), &state))
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
    let texels: u64 = region
        .iter()
        .map(|r| r.extent.width as u64 * r.extent.height as u64)
        .sum::<u64>()
        * dsts.len() as u64;
    let bytes_per_texel = f.res.texel_format(src).bytes_per_texel();
    let mut pass = Pass::new(name, PassRole::Sss);
    let src = pass.transfer_src(src);
    // A copy of part of the image keeps the rest (the zeros written at set-up):
    // its barrier must not discard the old contents.
    let dsts: Vec<_> = dsts
        .iter()
        .map(|&d| {
            if whole {
                pass.transfer_dst(d)
            } else {
                pass.transfer_dst_part(d)
            }
        })
        .collect();
    pass.work(Work::Copy {
        texels,
        bytes_per_texel,
        rects: (region.len() * dsts.len()) as u32,
    })
    .record(move |pc: &PassContext| {
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
            pc.copy_image(src, dst, &copies);
        }
    })
}

/// Set 0 of a blur that reads `color` and the linear depth through the
/// bilinear sampler (`colorTex`, `depthTex`, `linearClamp`).
pub fn source_set(s: &MethodSetup, pipeline: &Pipeline, color: ImageId) -> GraphSet {
    GraphSet::new(
        s.res,
        pipeline,
        0,
        vec![
            ("colorTex", Binding::Sampled(color)),
            ("depthTex", Binding::Sampled(s.targets.linear_depth)),
            (
                "linearClamp",
                Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
            ),
        ],
    )
}
