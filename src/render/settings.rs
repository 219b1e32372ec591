//! What a render is asked to do, validated before any GPU work.

use anyhow::{bail, Result};
use serde::Serialize;

use super::screen::MaskMode;
use crate::scene::light::KeyLight;
use crate::skin::kernel::{Preset, SeparableKernel, SssParams};
use crate::skin::ssg::GaussianFit;

/// The SSS method of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Separable SSS (thesis ch. 6).
    Separable,
    /// Screen-space sum of Gaussians (thesis ch. 4, "SS Full").
    Ssg,
    /// Hable et al.'s 13-tap jittered kernel in screen space ("SS Jittered").
    SsJittered,
    /// Poisson-disk screen-space SSS weighted by depth and normal (seed 003).
    Poisson,
    /// The ground truth: brute-force integral over the skin surface (compute).
    Reference,
    /// No subsurface scattering: the baseline every method is compared to.
    None,
}

impl std::str::FromStr for Method {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "separable" | "ssss" => Ok(Method::Separable),
            "ssg" => Ok(Method::Ssg),
            "ss-jittered" | "jittered" => Ok(Method::SsJittered),
            "poisson" => Ok(Method::Poisson),
            "reference" | "ground-truth" => Ok(Method::Reference),
            "none" | "off" => Ok(Method::None),
            other => bail!(
                "unknown method '{other}' (valid: separable, ssg, ss-jittered, poisson, reference, none)"
            ),
        }
    }
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Separable => "separable",
            Method::Ssg => "ssg",
            Method::SsJittered => "ss-jittered",
            Method::Poisson => "poisson",
            Method::Reference => "reference",
            Method::None => "none",
        }
    }
}

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub method: Method,
    pub samples: usize,
    pub preset: Preset,
    pub params: SssParams,
    pub follow_surface: bool,
    pub transmittance: bool,
    /// ssg: the Gaussian fit of Table 4.2.
    pub fit: GaussianFit,
    /// ssg: depth-based Gaussian level of detail (section 4.2.1).
    pub lod: bool,
    /// ssg: stencil test or dynamic branch.
    pub mask: MaskMode,
    /// Limit the SSS passes to the skin's neighbourhood, or run them on the screen.
    pub sss_region: super::region::RegionMode,
    /// Side of the region's screen tiles in pixels (smaller: tighter, more draws).
    pub sss_region_tile: u32,
    /// Which T(s) transmittance uses (eq. 5.12 as published, or the plane integral).
    pub transmittance_profile: crate::skin::transmittance::TransmittanceProfile,
    /// reference: surface samples per mm^2.
    pub reference_density: f32,
    pub heads: u32,
    /// Camera distance from the head centre, in head heights.
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
            method: Method::Separable,
            samples: 17,
            preset: Preset::Table61,
            params: Preset::Table61.params(),
            follow_surface: true,
            transmittance: true,
            fit: GaussianFit::Six,
            lod: true,
            mask: MaskMode::Stencil,
            sss_region: super::region::RegionMode::Skin,
            sss_region_tile: super::region::TILE_PX,
            reference_density: 32.0,
            transmittance_profile: crate::skin::transmittance::TransmittanceProfile::Thesis,
            heads: 1,
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
        if self.samples % 2 == 0 || !(3..=SeparableKernel::MAX_SAMPLES).contains(&self.samples) {
            bail!(
                "samples must be odd and within 3..={}, got {}",
                SeparableKernel::MAX_SAMPLES,
                self.samples
            );
        }
        self.params.validate()?;
        if !(1..=1024).contains(&self.sss_region_tile) {
            bail!(
                "the SSS region's tile must be 1..=1024 pixels, got {}",
                self.sss_region_tile
            );
        }
        if self.heads == 0 || self.heads > 1024 {
            bail!("heads must be within 1..=1024, got {}", self.heads);
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
        let mut b = s.clone();
        b.params.width_mm = -1.0;
        assert!(b.validate(16384).is_err());
        let mut b = s.clone();
        b.samples = 16;
        assert!(b.validate(16384).unwrap_err().to_string().contains("odd"));
        let mut b = s;
        b.light.intensity = f32::NAN;
        assert!(b.validate(16384).is_err());
    }

    #[test]
    fn method_names_round_trip() {
        for m in [
            Method::Separable,
            Method::Ssg,
            Method::SsJittered,
            Method::Poisson,
            Method::Reference,
            Method::None,
        ] {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        assert!("ssg-typo".parse::<Method>().is_err());
    }
}
