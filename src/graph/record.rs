//! The executor ([`record_passes`]): it brackets each pass with its debug label,
//! timestamps and queries, emits the barriers its declared accesses need
//! (one call), begins and ends dynamic rendering from its declared
//! attachments around the closure (or dispatches after it): the closure
//! binds its pipeline and sets, pushes constants and draws.

use ash::vk;

use super::attach::{ColorTarget, DepthStencil, Load};
use super::context::{Declared, PassContext};
use super::pass::{Cost, Pass};
use super::resources::Resources;
use super::work::PassRole;
use crate::vk::context::Context;
use crate::vk::profiler::{PassTiming, Profiler};

/// What the GPU measured for one pass in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSample {
    pub name: String,
    pub role: PassRole,
    /// The pass is a mixed frame's merge (`Pass::merge`).
    pub merge: bool,
    pub barrier_ms: f64,
    pub gpu_ms: f64,
    pub input_primitives: Option<u64>,
    pub fragment_invocations: Option<u64>,
    pub compute_invocations: Option<u64>,
    pub samples_passed: u64,
}

impl PassSample {
    pub fn new(pass: &Pass, t: PassTiming) -> Self {
        PassSample {
            name: pass.name.clone(),
            role: pass.role,
            merge: pass.merge,
            barrier_ms: t.barrier_ms,
            gpu_ms: t.gpu_ms,
            input_primitives: t.input_primitives,
            fragment_invocations: t.fragment_invocations,
            compute_invocations: t.compute_invocations,
            samples_passed: t.samples_passed,
        }
    }
}

/// The store op of a written attachment: STORE (every image a pass draws is
/// read later), but DONT_CARE for a multisampled one that the pass resolves:
/// nothing reads its samples after the resolve, which happens before the
/// store, so a tiler need not write them out.
fn store_op(resolved: bool) -> vk::AttachmentStoreOp {
    if resolved {
        vk::AttachmentStoreOp::DONT_CARE
    } else {
        vk::AttachmentStoreOp::STORE
    }
}

/// Begins dynamic rendering of `colors` and `depth` over `area` from the
/// origin, views and layouts from the pass's declared accesses, and sets
/// viewport, scissor and the stencil reference the declaration names.
fn begin_rendering(
    pc: &PassContext,
    colors: &[ColorTarget],
    depth: Option<DepthStencil>,
    area: vk::Extent2D,
) {
    let color_att: Vec<vk::RenderingAttachmentInfo> = colors
        .iter()
        .map(|c| {
            let (op, clear) = match c.load {
                Load::Keep => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
                Load::DontCare => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
                Load::Clear(v) => (vk::AttachmentLoadOp::CLEAR, v),
            };
            let (view, layout) = pc.attachment(c.image);
            let att = vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(layout)
                .load_op(op)
                .store_op(store_op(c.resolve.is_some()))
                .clear_value(vk::ClearValue {
                    color: vk::ClearColorValue { float32: clear },
                });
            // Every colour format dermis renders is float or UNORM, so the
            // resolve is the average of the samples (the box filter MSAA is).
            match c.resolve.map(|single| pc.attachment(single)) {
                Some((view, layout)) => att
                    .resolve_mode(vk::ResolveModeFlags::AVERAGE)
                    .resolve_image_view(view)
                    .resolve_image_layout(layout),
                None => att,
            }
        })
        .collect();
    let ds_att = depth.map(|d| {
        let (view, layout) = pc.attachment(d.image);
        let att = vk::RenderingAttachmentInfo::default()
            .image_view(view)
            .image_layout(layout);
        // Depth and stencil both from sample 0: the one mode every device
        // has for both (VK_KHR_depth_stencil_resolve), and one surface's
        // depth and group code together (docs/aa.md).
        let att = match d.resolve.map(|single| pc.attachment(single)) {
            Some((view, layout)) => att
                .resolve_mode(vk::ResolveModeFlags::SAMPLE_ZERO)
                .resolve_image_view(view)
                .resolve_image_layout(layout),
            None => att,
        };
        match d.clear {
            Some((depth, stencil)) => att
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(store_op(d.resolve.is_some()))
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue { depth, stencil },
                }),
            // Read-only depth/stencil: loaded for the tests, never stored.
            None => att
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::NONE),
        }
    });
    let rect = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: area,
    };
    let mut info = vk::RenderingInfo::default()
        .render_area(rect)
        .layer_count(1)
        .color_attachments(&color_att);
    if let (Some(att), Some(d)) = (&ds_att, depth) {
        info = info.depth_attachment(att);
        if pc.res.texel_format(d.image).has_stencil() {
            info = info.stencil_attachment(att);
        }
    }
    let (device, cmd) = (&pc.ctx.device, pc.cmd);
    unsafe {
        device.cmd_begin_rendering(cmd, &info);
        device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: area.width as f32,
                height: area.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        device.cmd_set_scissor(cmd, 0, &[rect]);
        // Set before the closure binds its pipeline: the stencil-testing
        // pipelines take their reference as dynamic state, which a bind keeps.
        if let Some(reference) = depth.and_then(|d| d.stencil_ref) {
            device.cmd_set_stencil_reference(cmd, vk::StencilFaceFlags::FRONT_AND_BACK, reference);
        }
    }
}

/// Records one pass's commands: dynamic rendering around its closure for a
/// raster pass, its dispatch after the closure for a compute pass.
fn record_one(ctx: &Context, cmd: vk::CommandBuffer, res: &Resources, pass: &Pass) {
    let declared = Declared {
        name: &pass.name,
        images: &pass.images,
        buffers: &pass.buffers,
        sets: &pass.sets,
    };
    let pc = |target| PassContext {
        ctx,
        cmd,
        target,
        res,
        pass: declared,
    };
    match &pass.cost {
        Some(Cost::Raster(r)) => {
            let renderings: Vec<Vec<ColorTarget>> = if r.each_target_alone {
                r.colors.iter().map(|&c| vec![c]).collect()
            } else {
                vec![r.colors.clone()]
            };
            for (i, colors) in renderings.iter().enumerate() {
                let pc = pc(i);
                begin_rendering(&pc, colors, r.depth, pass.area(r, res, i));
                (pass.record)(&pc);
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            }
        }
        Some(Cost::Dispatch { groups, .. }) => {
            (pass.record)(&pc(0));
            unsafe {
                ctx.device
                    .cmd_dispatch(cmd, groups[0], groups[1], groups[2])
            };
        }
        Some(Cost::DispatchIndirect { args, offset, .. }) => {
            (pass.record)(&pc(0));
            unsafe {
                ctx.device
                    .cmd_dispatch_indirect(cmd, res.buffer(*args), *offset)
            };
        }
        Some(Cost::Other(_)) | None => (pass.record)(&pc(0)),
    }
}

/// Records `passes` into `cmd` in order. With a profiler, pass `i` uses query
/// slots `i`; the caller reads them after the fence.
pub fn record_passes(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    resources: &mut Resources,
    passes: &[Pass],
    profiler: Option<&Profiler>,
) {
    if let Some(p) = profiler {
        assert!(
            passes.len() as u32 <= p.max_passes,
            "{} passes but the profiler holds {}",
            passes.len(),
            p.max_passes
        );
        p.reset(ctx, cmd);
    }
    for (i, pass) in passes.iter().enumerate() {
        let i = i as u32;
        ctx.begin_label(cmd, &pass.name);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 0);
        }
        resources.transition(ctx, cmd, &pass.images, &pass.buffers);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 1);
            p.begin_stats(ctx, cmd, i);
        }
        record_one(ctx, cmd, resources, pass);
        if let Some(p) = profiler {
            p.end_stats(ctx, cmd, i);
            p.stamp(ctx, cmd, i, 2);
        }
        ctx.end_label(cmd);
    }
}
