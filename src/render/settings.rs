//! What a render is asked to do, validated before any GPU work: the frame's
//! settings, the SSS method (a registry entry) and the options given to it.

use anyhow::{bail, Context as _, Result};

use crate::method::region::{RegionMode, TILE_PX};
use crate::method::{default_method, MethodEntry, MethodOptions};
use crate::scene::layout::Layout;
use crate::scene::light::KeyLight;
use crate::skin::transmittance::TransmittanceProfile;

/// Largest frame side and shadow map dermis accepts before the device says
/// more (its maxImageDimension2D is checked once it is open).
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most characters a scene may hold.
pub const MAX_HEADS: u32 = 1024;

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub method: &'static MethodEntry,
    /// Options given to the methods (each reads its own; see `method::options`).
    pub options: MethodOptions,
    pub transmittance: bool,
    /// Which T(s) transmittance uses (eq. 5.12 as published, or the plane integral).
    pub transmittance_profile: TransmittanceProfile,
    /// Limit the SSS passes to the skin's neighbourhood, or run them on the screen.
    pub sss_region: RegionMode,
    /// Side of the region's screen tiles in pixels (smaller: tighter, more draws).
    pub sss_region_tile: u32,
    pub heads: u32,
    /// How the characters stand when there are several.
    pub layout: Layout,
    /// Camera distance from the (first) head's centre, in head heights.
    pub distance_heads: f32,
    pub fovy_deg: f32,
    pub light: KeyLight,
    /// Constant ambient irradiance (white), so unlit skin is not black.
    pub ambient: f32,
    pub exposure: f32,
    pub shadow_size: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 1280,
            height: 720,
            method: default_method(),
            options: MethodOptions::default(),
            transmittance: true,
            transmittance_profile: TransmittanceProfile::Thesis,
            sss_region: RegionMode::Skin,
            sss_region_tile: TILE_PX,
            heads: 1,
            layout: Layout::Crowd,
            distance_heads: 4.0,
            fovy_deg: 20.0,
            light: KeyLight {
                azimuth_deg: 60.0,
                elevation_deg: 30.0,
                color: [1.0, 0.96, 0.92],
                intensity: 2.5,
            },
            ambient: 0.08,
            exposure: 2.0,
            shadow_size: 2048,
        }
    }
}

impl RenderSettings {
    /// These settings with `method` and option `key` set to `value` (tests, eval).
    pub fn with(mut self, method: &'static MethodEntry, options: &[(&str, &str)]) -> Self {
        self.method = method;
        self.options = self.options.with(options);
        self
    }

    /// Rejects settings that would give a bad frame or a driver error, with one
    /// clear message each.
    pub fn validate(&self, max_image_dimension: u32) -> Result<()> {
        for (what, v) in [("width", self.width), ("height", self.height)] {
            if v == 0 {
                bail!("{what} must be at least 1 pixel");
            }
            if v > max_image_dimension {
                bail!("{what} {v} exceeds the device limit of {max_image_dimension} pixels");
            }
        }
        if self.shadow_size == 0 || self.shadow_size > max_image_dimension {
            bail!(
                "shadow map size must be within 1..={max_image_dimension}, got {}",
                self.shadow_size
            );
        }
        (self.method.check)(&self.method.opts(&self.options))
            .with_context(|| format!("method {}", self.method.name))?;
        if !(1..=1024).contains(&self.sss_region_tile) {
            bail!(
                "the SSS region's tile must be 1..=1024 pixels, got {}",
                self.sss_region_tile
            );
        }
        if self.heads == 0 || self.heads > MAX_HEADS {
            bail!("heads must be within 1..={MAX_HEADS}, got {}", self.heads);
        }
        if !self.distance_heads.is_finite() || self.distance_heads <= 0.0 {
            bail!(
                "camera distance must be a positive number of head heights, got {}",
                self.distance_heads
            );
        }
        if !self.fovy_deg.is_finite() || self.fovy_deg <= 0.5 || self.fovy_deg >= 170.0 {
            bail!(
                "vertical field of view must be within 0.5..170 degrees, got {}",
                self.fovy_deg
            );
        }
        self.light.validate()?;
        if !self.ambient.is_finite() || self.ambient < 0.0 {
            bail!(
                "ambient must be finite and non-negative, got {}",
                self.ambient
            );
        }
        if !self.exposure.is_finite() || self.exposure <= 0.0 {
            bail!("exposure must be a positive number, got {}", self.exposure);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::lookup;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        let s = RenderSettings::default();
        s.validate(16384).unwrap();
        let mut b = s.clone();
        b.width = 0;
        assert!(b.validate(16384).unwrap_err().to_string().contains("width"));
        let mut b = s.clone();
        b.height = 20000;
        assert!(b
            .validate(16384)
            .unwrap_err()
            .to_string()
            .contains("device limit"));
        for tile in [0, 2000] {
            let mut b = s.clone();
            b.sss_region_tile = tile;
            assert!(b.validate(16384).unwrap_err().to_string().contains("tile"));
        }
        let mut b = s.clone();
        b.distance_heads = f32::NAN;
        assert!(b
            .validate(16384)
            .unwrap_err()
            .to_string()
            .contains("distance"));
        let sep = lookup("separable").unwrap();
        let b = s.clone().with(sep, &[("sss-width-mm", "-1")]);
        assert!(b.validate(16384).is_err());
        let b = s.clone().with(sep, &[("samples", "16")]);
        let e = format!("{:#}", b.validate(16384).unwrap_err());
        assert!(e.contains("odd"), "{e}");
        // An option of another method is not this method's business.
        let b = s.clone().with(lookup("ssg").unwrap(), &[("samples", "16")]);
        b.validate(16384).unwrap();
        let mut b = s;
        b.light.intensity = f32::NAN;
        assert!(b.validate(16384).is_err());
    }
}
