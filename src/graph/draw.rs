//! The draw boilerplate of raster passes, in one place (the executor has begun
//! rendering by the time a record closure runs): the full-screen triangle,
//! drawn once or once per rectangle of a region.

use ash::vk;

use super::{PassContext, SetRef};
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

/// One full-screen triangle with `pipeline` and its sets from 0 = `sets`; `state` sets
/// push constants and other dynamic state after the bind.
pub fn fullscreen(
    pc: &PassContext,
    pipeline: &Pipeline,
    sets: &[SetRef],
    state: impl Fn(&Context, vk::CommandBuffer),
) {
    fullscreen_in(pc, pipeline, sets, None, state)
}

/// A full-screen triangle drawn once per rectangle of `region` as its scissor
/// (disjoint, so no pixel is shaded twice; empty: nothing is drawn), or once
/// over the render area when `region` is `None`.
pub fn fullscreen_in(
    pc: &PassContext,
    pipeline: &Pipeline,
    sets: &[SetRef],
    region: Option<&[vk::Rect2D]>,
    state: impl Fn(&Context, vk::CommandBuffer),
) {
    let (ctx, cmd) = (pc.ctx, pc.cmd);
    pc.bind(pipeline, sets);
    state(ctx, cmd);
    unsafe {
        match region {
            None => ctx.device.cmd_draw(cmd, 3, 1, 0, 0),
            Some(rects) => {
                for rect in rects {
                    ctx.device
                        .cmd_set_scissor(cmd, 0, std::slice::from_ref(rect));
                    ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
                }
            }
        }
    }
}
