//! The raster boilerplate of passes, in one place: dynamic rendering into the
//! images a pass declared (views and layouts from the graph, never typed at the
//! call site), viewport and scissor, and the stencil-tested full-screen draw.

use ash::vk;

use super::{ImageId, PassContext};
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

/// How a render pass treats one attachment's old contents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// Keep them (blending, partial draws).
    Keep,
    /// Every pixel is overwritten: the old contents need not be read.
    Discard,
    /// Clear to this colour (or depth in `[0]`, stencil 0).
    Clear([f32; 4]),
}

impl Load {
    fn op(self) -> (vk::AttachmentLoadOp, vk::ClearValue) {
        match self {
            Load::Keep => (vk::AttachmentLoadOp::LOAD, vk::ClearValue::default()),
            Load::Discard => (vk::AttachmentLoadOp::DONT_CARE, vk::ClearValue::default()),
            Load::Clear(c) => (
                vk::AttachmentLoadOp::CLEAR,
                vk::ClearValue {
                    color: vk::ClearColorValue { float32: c },
                },
            ),
        }
    }
}

/// A depth/stencil attachment of a render pass.
#[derive(Clone, Copy, Debug)]
pub struct DepthTarget {
    pub image: ImageId,
    /// `None`: loaded for testing only, never stored (read-only).
    pub clear_depth: Option<f32>,
    /// Whether the image has a stencil aspect to attach.
    pub stencil: bool,
}

/// Begins dynamic rendering into the colour attachments `colors` (each with
/// its load behaviour) and an optional depth/stencil attachment, over the
/// whole of the first attachment, and sets viewport and scissor to it.
pub fn begin_rendering(pc: &PassContext, colors: &[(ImageId, Load)], depth: Option<DepthTarget>) {
    let extent = colors
        .first()
        .map(|c| c.0)
        .or(depth.map(|d| d.image))
        .map(|id| pc.res.extent(id))
        .expect("a render pass needs at least one attachment");
    let color_att: Vec<vk::RenderingAttachmentInfo> = colors
        .iter()
        .map(|&(id, load)| {
            let (op, clear) = load.op();
            vk::RenderingAttachmentInfo::default()
                .image_view(pc.view(id))
                .image_layout(pc.layout(id))
                .load_op(op)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(clear)
        })
        .collect();
    let ds_att = depth.map(|d| {
        let att = vk::RenderingAttachmentInfo::default()
            .image_view(pc.view(d.image))
            .image_layout(pc.layout(d.image));
        match d.clear_depth {
            Some(z) => att
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: z,
                        stencil: 0,
                    },
                }),
            // Read-only depth/stencil: loaded for the tests, never stored.
            None => att
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::NONE),
        }
    });
    let mut info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        })
        .layer_count(1)
        .color_attachments(&color_att);
    if let (Some(att), Some(d)) = (&ds_att, depth) {
        info = info.depth_attachment(att);
        if d.stencil {
            info = info.stencil_attachment(att);
        }
    }
    unsafe { pc.ctx.device.cmd_begin_rendering(pc.cmd, &info) };
    set_viewport(pc.ctx, pc.cmd, extent);
}

/// Viewport and scissor covering `extent`.
pub fn set_viewport(ctx: &Context, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
    unsafe {
        ctx.device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: extent.width as f32,
                height: extent.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        ctx.device.cmd_set_scissor(
            cmd,
            0,
            &[vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            }],
        );
    }
}

/// A full-screen pass: `pipeline` with set 0 = `set`, drawn into `colors`
/// (contents discarded), one triangle.
pub fn fullscreen_draw(
    pc: &PassContext,
    pipeline: &Pipeline,
    set: vk::DescriptorSet,
    colors: &[ImageId],
    state: impl Fn(&Context, vk::CommandBuffer),
) {
    let colors: Vec<(ImageId, Load)> = colors.iter().map(|&c| (c, Load::Discard)).collect();
    begin_rendering(pc, &colors, None);
    pipeline.bind(pc.ctx, pc.cmd, &[set]);
    state(pc.ctx, pc.cmd);
    unsafe {
        pc.ctx.device.cmd_draw(pc.cmd, 3, 1, 0, 0);
        pc.ctx.device.cmd_end_rendering(pc.cmd);
    }
}

/// A full-screen triangle into `colors` (loaded, stored), tested against the
/// read-only depth/stencil attachment `depth_stencil` (stencil reference
/// `stencil_ref`, used when the pipeline tests stencil), drawn once per
/// rectangle of `region` (disjoint, so no pixel is shaded twice; empty: nothing
/// is drawn). `state` sets push constants and other dynamic state.
#[allow(clippy::too_many_arguments)] // each argument is one independent fact of the draw
pub fn fullscreen_stencil_draw(
    pc: &PassContext,
    pipeline: &Pipeline,
    set: vk::DescriptorSet,
    colors: &[ImageId],
    depth_stencil: ImageId,
    region: &[vk::Rect2D],
    stencil_ref: u32,
    state: impl Fn(&Context, vk::CommandBuffer),
) {
    let (ctx, cmd) = (pc.ctx, pc.cmd);
    let colors: Vec<(ImageId, Load)> = colors.iter().map(|&c| (c, Load::Keep)).collect();
    begin_rendering(
        pc,
        &colors,
        Some(DepthTarget {
            image: depth_stencil,
            clear_depth: None,
            stencil: true,
        }),
    );
    pipeline.bind(ctx, cmd, &[set]);
    unsafe {
        if pipeline.has_stencil {
            ctx.device.cmd_set_stencil_reference(
                cmd,
                vk::StencilFaceFlags::FRONT_AND_BACK,
                stencil_ref,
            );
        }
    }
    state(ctx, cmd);
    unsafe {
        for rect in region {
            ctx.device
                .cmd_set_scissor(cmd, 0, std::slice::from_ref(rect));
            ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
        }
        ctx.device.cmd_end_rendering(cmd);
    }
}
