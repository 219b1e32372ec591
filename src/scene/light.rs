//! The key light and its shadow frustum.

use anyhow::{bail, Result};
use glam::{Mat4, Quat, Vec3};

/// Largest key-light intensity accepted. The geometry pass writes light x
/// albedo and the specular lobe into RGBA16F (largest value 65504): at 100 the
/// brightest specular highlight stays an order of magnitude below it, while
/// the default is 2.5. Beyond, highlights overflow to infinity and the tone map
/// turns them into NaN.
pub const MAX_INTENSITY: f32 = 100.0;
const _: () = assert!(
    MAX_INTENSITY as f64 == 100.0,
    "crate::ranges::LIGHT_INTENSITY says 100"
);

/// A directional key light placed relative to the face, so light setups read the same
/// for any head orientation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyLight {
    /// 0 = from the camera side (along the face's forward), positive turns
    /// counter-clockwise about +Y seen from above (for a face looking at +Z, +90 lights
    /// from +X, the viewer's right).
    pub azimuth_deg: f32,
    /// Up from the horizontal plane.
    pub elevation_deg: f32,
    /// Linear RGB.
    pub color: [f32; 3],
    pub intensity: f32,
}

impl KeyLight {
    /// Unit vector from the scene toward the light.
    pub fn direction_to_light(&self, forward: Vec3) -> Vec3 {
        let flat = Vec3::new(forward.x, 0.0, forward.z)
            .try_normalize()
            .unwrap_or(Vec3::Z);
        let around = Quat::from_rotation_y(self.azimuth_deg.to_radians()) * flat;
        let (s, c) = self.elevation_deg.to_radians().sin_cos();
        (around * c + Vec3::Y * s).normalize()
    }

    /// User-facing settings come from the command line: reject values that would
    /// produce NaNs or negative light.
    pub fn validate(&self) -> Result<()> {
        crate::ranges::LIGHT_AZIMUTH.check(self.azimuth_deg)?;
        crate::ranges::LIGHT_ELEVATION.check(self.elevation_deg)?;
        if self.color.iter().any(|c| !c.is_finite() || *c < 0.0) {
            bail!(
                "light colour must be finite and non-negative, got {:?}",
                self.color
            );
        }
        crate::ranges::LIGHT_INTENSITY.check(self.intensity)?;
        Ok(())
    }
}

/// Shadow-map projection for a light, plus the scale that turns depth differences into
/// scene distances (translucency uses the distance light travelled inside the skin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightFrame {
    pub view_proj: Mat4,
    pub depth_range_units: f32,
    /// Side of the square the shadow map covers, scene units.
    pub extent_units: f32,
}

impl LightFrame {
    /// Width of one shadow-map texel at any receiver (the projection is
    /// orthographic), in millimetres: what a crowd's shadow map loses against
    /// one head's (the accuracy model's third axis, docs/accuracy.md).
    pub fn texel_mm(&self, shadow_size: u32, mm_per_unit: f32) -> f64 {
        f64::from(self.extent_units) * f64::from(mm_per_unit) / f64::from(shadow_size.max(1))
    }
}

/// Orthographic shadow projection for a directional light fitted to a bounding sphere:
/// depth is linear, so the shadow map's depth difference times depth_range_units is a
/// distance in scene units (Vulkan depth 0..1, same clip conventions as Camera::proj).
pub fn shadow_frame(dir_to_light: Vec3, center: Vec3, radius: f32) -> LightFrame {
    let dir = dir_to_light.try_normalize().unwrap_or(Vec3::Y);
    // 1% margin so points exactly on the sphere stay inside after rounding.
    let r = if radius.is_finite() && radius > 0.0 {
        radius * 1.01
    } else {
        1e-3
    };
    let eye = center + dir * (2.0 * r);
    let up = if dir.dot(Vec3::Y).abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let view = Mat4::look_at_rh(eye, center, up);
    let mut proj = Mat4::orthographic_rh(-r, r, -r, r, r, 3.0 * r);
    proj.y_axis.y = -proj.y_axis.y;
    LightFrame {
        view_proj: proj * view,
        depth_range_units: 2.0 * r,
        extent_units: 2.0 * r,
    }
}

#[cfg(test)]
mod tests {
    use super::super::camera::project;
    use super::*;

    fn light(az: f32, el: f32) -> KeyLight {
        KeyLight {
            azimuth_deg: az,
            elevation_deg: el,
            color: [1.0; 3],
            intensity: 3.0,
        }
    }

    #[test]
    fn azimuth_and_elevation() {
        let f = Vec3::Z;
        assert!((light(0.0, 0.0).direction_to_light(f) - Vec3::Z).length() < 1e-6);
        assert!((light(90.0, 0.0).direction_to_light(f) - Vec3::X).length() < 1e-6);
        assert!((light(0.0, 90.0).direction_to_light(f) - Vec3::Y).length() < 1e-6);
        let d = light(30.0, 45.0).direction_to_light(Vec3::new(1.0, 0.0, 0.0));
        assert!((d.length() - 1.0).abs() < 1e-6 && (d.y - 0.5f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn a_texel_is_the_fitted_extent_over_the_size() {
        let f = shadow_frame(Vec3::Y, Vec3::ZERO, 100.0);
        // 1% margin on the radius: 202 units over 2048 texels, 2 mm a unit.
        assert!((f.texel_mm(2048, 2.0) - 202.0 * 2.0 / 2048.0).abs() < 1e-4);
        assert!((f.texel_mm(512, 2.0) / f.texel_mm(2048, 2.0) - 4.0).abs() < 1e-9);
    }

    #[test]
    fn validation() {
        assert!(light(10.0, 20.0).validate().is_ok());
        assert!(light(f32::NAN, 0.0).validate().is_err());
        assert!(light(0.0, 91.0).validate().is_err());
        let mut l = light(0.0, 0.0);
        l.intensity = -1.0;
        assert!(l.validate().is_err());
        l.intensity = 1.0;
        l.color[1] = f32::INFINITY;
        assert!(l.validate().is_err());
    }

    #[test]
    fn sphere_fits_and_depth_is_affine_in_distance() {
        let dir = Vec3::new(0.4, 0.7, -0.3).normalize();
        let (c, r) = (Vec3::new(1.0, -2.0, 0.5), 7.0);
        let f = shadow_frame(dir, c, r);
        let mut samples = Vec::new();
        for i in 0..20 {
            for j in 0..40 {
                let t = (i as f32 + 0.5) / 20.0 * std::f32::consts::PI;
                let p = j as f32 / 40.0 * std::f32::consts::TAU;
                let on = c + r * Vec3::new(t.sin() * p.cos(), t.cos(), t.sin() * p.sin());
                let ndc = project(&f.view_proj, on);
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "{ndc}");
                samples.push((on, ndc.z));
            }
        }
        // Moving one unit toward the light lowers depth by exactly 1/depth_range_units.
        for (p, z) in samples.iter().step_by(37) {
            let z2 = project(&f.view_proj, *p + dir * 0.5).z;
            assert!(((z - z2) * f.depth_range_units - 0.5).abs() < 1e-4);
            // and sideways moves do not change it
            let side = dir.any_orthonormal_vector();
            assert!((project(&f.view_proj, *p + side * 0.1).z - z).abs() < 1e-5);
        }
    }
}
