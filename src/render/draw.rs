//! The raster boilerplate of full-screen passes, in one place: viewport and
//! scissor, colour-only rendering, and the stencil-tested full-screen draw.

use ash::vk;

use super::region::PixelRect;
use crate::graph::PassContext;
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

/// Begins dynamic rendering into colour attachments `views` (no depth), storing
/// them, with `load` as every attachment's load op, and sets the viewport.
pub fn begin_color_rendering(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    views: &[vk::ImageView],
    extent: vk::Extent2D,
    load: vk::AttachmentLoadOp,
) {
    let att: Vec<vk::RenderingAttachmentInfo> = views
        .iter()
        .map(|&v| {
            vk::RenderingAttachmentInfo::default()
                .image_view(v)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
        })
        .collect();
    let info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        })
        .layer_count(1)
        .color_attachments(&att);
    unsafe { ctx.device.cmd_begin_rendering(cmd, &info) };
    set_viewport(ctx, cmd, extent);
}

/// The rectangles of a pixel region as scissors.
pub fn scissors(region: &[PixelRect]) -> Vec<vk::Rect2D> {
    region
        .iter()
        .map(|r| vk::Rect2D {
            offset: vk::Offset2D {
                x: r.x0 as i32,
                y: r.y0 as i32,
            },
            extent: vk::Extent2D {
                width: r.width(),
                height: r.height(),
            },
        })
        .collect()
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

/// A full-screen triangle into `colors` (loaded, stored), tested against a
/// read-only depth/stencil attachment (stencil reference `stencil_ref`, used when
/// the pipeline tests stencil), drawn once per rectangle of `region` (disjoint,
/// so no pixel is shaded twice; empty: nothing is drawn). `state` sets push
/// constants and other dynamic state.
#[allow(clippy::too_many_arguments)]
pub fn fullscreen_stencil_draw(
    pc: &PassContext,
    pipeline: &Pipeline,
    set: vk::DescriptorSet,
    colors: &[vk::ImageView],
    depth_stencil: vk::ImageView,
    extent: vk::Extent2D,
    region: &[vk::Rect2D],
    stencil_ref: u32,
    state: impl Fn(&Context, vk::CommandBuffer),
) {
    let ctx = pc.ctx;
    let cmd = pc.cmd;
    let color_att: Vec<vk::RenderingAttachmentInfo> = colors
        .iter()
        .map(|&v| {
            vk::RenderingAttachmentInfo::default()
                .image_view(v)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE)
        })
        .collect();
    // Read-only depth/stencil: loaded for the tests, never stored.
    let ds_att = vk::RenderingAttachmentInfo::default()
        .image_view(depth_stencil)
        .image_layout(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::LOAD)
        .store_op(vk::AttachmentStoreOp::NONE);
    let info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        })
        .layer_count(1)
        .color_attachments(&color_att)
        .depth_attachment(&ds_att)
        .stencil_attachment(&ds_att);
    unsafe {
        ctx.device.cmd_begin_rendering(cmd, &info);
        ctx.device
            .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.raw);
        set_viewport(ctx, cmd, extent);
        if pipeline.has_stencil {
            ctx.device.cmd_set_stencil_reference(
                cmd,
                vk::StencilFaceFlags::FRONT_AND_BACK,
                stencil_ref,
            );
        }
        ctx.device.cmd_bind_descriptor_sets(
            cmd,
            vk::PipelineBindPoint::GRAPHICS,
            pipeline.layout,
            0,
            &[set],
            &[],
        );
        state(ctx, cmd);
        for rect in region {
            ctx.device
                .cmd_set_scissor(cmd, 0, std::slice::from_ref(rect));
            ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
        }
        ctx.device.cmd_end_rendering(cmd);
    }
}
