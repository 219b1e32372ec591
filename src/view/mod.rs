//! The view as the pure math sees it: how many pixels a millimetre of skin
//! spans at a depth ([`ViewScale`], the one place that scale is computed) and
//! where on screen the SSS passes have work ([`region`]). Pure: no Vulkan, no
//! graph; `method`, `render` and the CPU mirrors in `skin` and `reference`
//! read it.
//!
//! Every expression keeps the order of operations the passes have always
//! used: the images they feed are hashed bit for bit, and f32 products
//! rounded in another order differ in the last bit.

pub mod region;

/// What converts millimetres on the surface into pixels on screen: the
/// frame's height, the vertical field of view and the scene's scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewScale {
    pub height_px: u32,
    /// `tan(fovy / 2)`.
    pub tan_half_fovy: f32,
    /// Millimetres per scene unit.
    pub mm_per_unit: f32,
}

impl ViewScale {
    /// The scale of a view with vertical field of view `fovy_rad`.
    pub fn new(height_px: u32, fovy_rad: f32, mm_per_unit: f32) -> ViewScale {
        ViewScale {
            height_px,
            tan_half_fovy: tan_half(fovy_rad),
            mm_per_unit,
        }
    }

    /// Scene units the screen's height spans at view depth `depth`:
    /// `2 depth tan(fovy/2)`.
    pub fn screen_height_units(&self, depth: f32) -> f32 {
        2.0 * depth * self.tan_half_fovy
    }

    /// Pixels per millimetre on screen at view depth `depth` (scene units):
    /// `height / (2 depth tan(fovy/2) mm_per_unit)`, the scale every
    /// screen-space kernel converts its millimetres with (shaders/view_scale.glsl
    /// spells the same product).
    pub fn px_per_mm(&self, depth: f32) -> f32 {
        self.height_px as f32 / (self.screen_height_units(depth) * self.mm_per_unit)
    }

    /// Millimetres one pixel spans at unit view depth (`1 / px_per_mm(1)`,
    /// as `2 tan(fovy/2) mm_per_unit / height`).
    pub fn mm_per_px_per_depth(&self) -> f32 {
        2.0 * self.tan_half_fovy * self.mm_per_unit / self.height_px as f32
    }

    /// The focal length in pixels, `height / (2 tan(fovy/2))`: a length `l`
    /// (scene units) at depth `d` spans `l f / d` pixels.
    pub fn focal_px(&self) -> f32 {
        self.height_px as f32 / (2.0 * self.tan_half_fovy)
    }

    /// Projected height in pixels of something `size` units tall at
    /// distance `d` (at least 1e-6 units, so an eye inside a box stays finite).
    pub fn projected_px(&self, size: f32, d: f32) -> f32 {
        self.height_px as f32 * size / self.screen_height_units(d.max(1e-6))
    }
}

/// `tan(fovy / 2)` of a vertical field of view in radians.
pub fn tan_half(fovy_rad: f32) -> f32 {
    (0.5 * fovy_rad).tan()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_per_mm_match_the_screen_height() {
        // 1 unit = 10 mm; a screen 2 * 5 * tan(45 deg) = 10 units = 100 mm tall on 500 rows.
        let s = ViewScale {
            height_px: 500,
            tan_half_fovy: 1.0,
            mm_per_unit: 10.0,
        };
        assert!((s.px_per_mm(5.0) - 5.0).abs() < 1e-6);
        assert!((s.mm_per_px_per_depth() * s.px_per_mm(1.0) - 1.0).abs() < 1e-6);
        // The focal length: one unit at depth d spans f / d pixels.
        assert!((s.focal_px() / 5.0 / s.mm_per_unit - s.px_per_mm(5.0)).abs() < 1e-6);
        assert!((s.projected_px(10.0, 5.0) - 500.0).abs() < 1e-4);
        assert!(s.projected_px(1.0, 0.0).is_finite());
    }

    #[test]
    fn the_scale_of_a_field_of_view() {
        let s = ViewScale::new(720, 20f32.to_radians(), 230.0);
        // The thesis' view: 720 / (2 tan 10 deg 230 mm) = 8.876 px per mm at depth 1.
        assert!((s.px_per_mm(1.0) - 8.876).abs() < 1e-3);
        // Nearer is bigger, in inverse proportion.
        assert!((s.px_per_mm(0.5) - 2.0 * s.px_per_mm(1.0)).abs() < 1e-4);
    }
}
