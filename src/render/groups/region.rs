//! Where a group works: the SSS region of its own characters with its own
//! method's reach (`method::region`, whole screen with `--sss-region
//! screen`), the skin region a fade from no SSS blends in, and the skin's
//! depths that size its kernels on screen.

use ash::vk;
use glam::Mat4;

use crate::method::region::{scene_region, PixelRect, ReachScale, RegionMode, RegionView};
use crate::method::SssMethod;
use crate::render::frame::Frame;
use crate::scene::Scene;

/// Where `method`, working on the characters `instances`, has work in
/// `scene` (the whole screen without a region).
pub fn region_for(
    frame: &Frame,
    scene: &Scene,
    method: &dyn SssMethod,
    instances: &[Mat4],
) -> Vec<PixelRect> {
    region_by(frame, scene, instances, |d, scale| {
        method.reach_px(d, scale)
    })
}

/// The skin of the characters `instances` on screen, reaching no further
/// (the whole screen with `--sss-region screen`): where a fade from no SSS
/// copies and blends.
pub fn skin_region(frame: &Frame, scene: &Scene, instances: &[Mat4]) -> Vec<PixelRect> {
    region_by(frame, scene, instances, |_, _| Some(0.0))
}

fn region_by(
    frame: &Frame,
    scene: &Scene,
    instances: &[Mat4],
    reach: impl Fn(f32, &ReachScale) -> Option<f32>,
) -> Vec<PixelRect> {
    let extent = frame.extent;
    let full = PixelRect::full(extent.width, extent.height);
    let s = &frame.settings;
    let view = frame.view_info();
    let probe = ReachScale {
        height_px: extent.height,
        tan_half_fovy: view.tan_half_fovy(),
        mm_per_unit: frame.mm_per_unit,
        max_strength: 1.0,
    };
    // A run stepping through the motion moves the skin after the region is
    // made (frame 0's), and a crowd playing a file's clip poses each
    // character's skin apart from the scene's (a skeleton can carry it far
    // from where the scene's mesh lies): the whole screen.
    let steps = scene.tracks.as_ref().is_some_and(|t| {
        t.step.is_some()
            || matches!(t.motion, crate::scene::crowd_motion::Motion::File(_))
                && instances.len() > 1
    });
    if s.sss_region == RegionMode::Screen || steps || reach(1.0, &probe).is_none() {
        return vec![full];
    }
    scene_region(
        scene,
        instances,
        &region_view(frame),
        view.tan_half_fovy(),
        s.sss_region_tile,
        reach,
    )
}

/// Where the skin of the characters `instances` lies in depth
/// (`view::region::skin_depths`).
pub fn depths_for(frame: &Frame, scene: &Scene, instances: &[Mat4]) -> Vec<(f64, f32)> {
    crate::view::region::skin_depths(scene, instances, &region_view(frame))
}

/// The camera as the region code projects with it.
fn region_view(frame: &Frame) -> RegionView {
    let view = frame.view_info();
    RegionView {
        view: frame.camera.view(),
        proj: frame.camera.proj(view.aspect()),
        near: frame.camera.near,
        width: frame.extent.width,
        height: frame.extent.height,
    }
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
