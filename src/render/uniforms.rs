//! The frame's uniform block (`FrameUniforms`, shaders/frame_uniforms.glsl):
//! camera, key light, ambient, and the shadow and transmittance parameters,
//! filled once at set-up from the settings, the framing and the scene.

use super::settings::RenderSettings;
use crate::scene::camera::Camera;
use crate::scene::light::LightFrame;
use crate::scene::Scene;
use crate::skin::transmittance::shrink_units;

/// Receiver bias of the shadow test along the light, in millimetres: half a
/// millimetre keeps skin from shadowing itself at the shadow map's resolution.
const SHADOW_BIAS_MM: f32 = 0.5;

/// std140 layout of `FrameUniforms` (shaders/frame_uniforms.glsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub view: [[f32; 4]; 4],
    pub light_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    pub light_dir: [f32; 4],
    pub light_color: [f32; 4],
    pub ambient: [f32; 4],
    pub params: [f32; 4],
    pub shadow_params: [f32; 4],
    /// x: 1 for post-scatter texturing (`settings::Texturing`).
    pub shading: [f32; 4],
}

impl FrameUniforms {
    /// The block for `settings` seen by `camera` under `light_frame` in
    /// `scene`; `transmittance`: whether the frame's methods want the
    /// geometry pass's transmittance (the ground truth does not).
    pub fn new(
        settings: &RenderSettings,
        scene: &Scene,
        camera: Camera,
        light_frame: LightFrame,
        transmittance: bool,
    ) -> Self {
        let aspect = settings.width as f32 / settings.height as f32;
        let light_dir = settings.light.direction_to_light(scene.forward);
        let light = settings.light;
        let mm = scene.mm_per_unit;
        let bias = SHADOW_BIAS_MM / mm / light_frame.depth_range_units;
        FrameUniforms {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            view: camera.view().to_cols_array_2d(),
            light_view_proj: light_frame.view_proj.to_cols_array_2d(),
            camera_pos: camera.eye.extend(1.0).to_array(),
            light_dir: light_dir.extend(0.0).to_array(),
            light_color: [
                light.color[0] * light.intensity,
                light.color[1] * light.intensity,
                light.color[2] * light.intensity,
                0.0,
            ],
            ambient: [settings.ambient; 4],
            params: [
                mm,
                light_frame.depth_range_units,
                shrink_units(mm),
                (settings.transmittance && transmittance) as u32 as f32,
            ],
            shadow_params: [
                1.0 / settings.shadow_size as f32,
                bias,
                settings.transmittance_profile.exponent_scale(),
                0.0,
            ],
            shading: [(!settings.texturing.is_pre()) as u32 as f32, 0.0, 0.0, 0.0],
        }
    }
}
