//! The skin-colour lookup table of thesis ch. 7.6 (Fig. 7.9): linear sRGB
//! of skin over melanin (u) and dermal haemoglobin (v), each sampled by its
//! cube root (eq. 7.7) so that the table spends its texels where skin lives
//! (melanosome fractions of 1-6% for light skin, 11-16% moderately and
//! 18-43% darkly pigmented: Jacques, OMLC). Eq. 7.7's roots are scaled to
//! Table 7.1's ranges, so the table spans them edge to edge: C_m = 0.5 u^3,
//! C_hd = 0.32 v^3, with the figure's 61% eumelanin and C_he = 0.25 C_hd.
//! Each entry is the two-layer model's total diffuse reflectance (`layers`)
//! under D65 (`colorimetry`). The thesis multiplies its scattered,
//! colourless light by the entry at each texel's (u, v), post-scatter
//! texturing; dermis does not upload the table yet (`--skin-tone` takes one
//! entry as an untextured skin's albedo).

use super::colorimetry::linear_srgb;
use super::layers::{reflectance, Chromophores};
use crate::scene::source::SkinTone;

/// Table 7.1's largest melanin and dermal haemoglobin fractions.
pub const MAX_MELANIN: f64 = 0.5;
pub const MAX_DERMAL_BLOOD: f64 = 0.32;
/// The figure's eumelanin share and epidermal-to-dermal blood ratio.
pub const EUMELANIN: f64 = 0.61;
pub const EPIDERMAL_PER_DERMAL_BLOOD: f64 = 0.25;

/// The chromophores at table coordinates (u, v) in [0, 1]^2 (clamped).
pub fn chromophores(u: f64, v: f64) -> Chromophores {
    let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
    let dermal = MAX_DERMAL_BLOOD * v * v * v;
    Chromophores {
        melanin: MAX_MELANIN * u * u * u,
        eumelanin: EUMELANIN,
        epidermal_blood: EPIDERMAL_PER_DERMAL_BLOOD * dermal,
        dermal_blood: dermal,
    }
}

/// The table coordinates of fractions `melanin` and `dermal_blood` (eq. 7.7).
pub fn coordinates(melanin: f64, dermal_blood: f64) -> (f64, f64) {
    (
        (melanin / MAX_MELANIN).clamp(0.0, 1.0).cbrt(),
        (dermal_blood / MAX_DERMAL_BLOOD).clamp(0.0, 1.0).cbrt(),
    )
}

/// The linear sRGB of skin at (u, v).
pub fn colour(u: f64, v: f64) -> [f64; 3] {
    linear_srgb(&reflectance(&chromophores(u, v)))
}

/// The table: `size` x `size` entries at texel centres, row v, column u,
/// linear sRGB.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourTable {
    pub size: usize,
    pub rgb: Vec<[f32; 3]>,
}

impl ColourTable {
    pub fn new(size: usize) -> ColourTable {
        let size = size.max(2);
        let centre = |k: usize| (k as f64 + 0.5) / size as f64;
        let rgb = (0..size * size)
            .map(|k| colour(centre(k % size), centre(k / size)).map(|c| c as f32))
            .collect();
        ColourTable { size, rgb }
    }

    /// The entry of column `u` and row `v`.
    pub fn at(&self, u: usize, v: usize) -> [f32; 3] {
        self.rgb[v * self.size + u]
    }

    /// Bilinear between entries at table coordinates `(u, v)` in [0, 1]^2,
    /// clamped to the edge entries: what a linear sampler of the table
    /// uploaded as a texture returns.
    pub fn sample(&self, u: f64, v: f64) -> [f32; 3] {
        let last = (self.size - 1) as f64;
        let fx = (u * self.size as f64 - 0.5).clamp(0.0, last);
        let fy = (v * self.size as f64 - 0.5).clamp(0.0, last);
        let (x0, y0) = (fx as usize, fy as usize);
        let (x1, y1) = ((x0 + 1).min(self.size - 1), (y0 + 1).min(self.size - 1));
        let (tx, ty) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
        let lerp = |a: [f32; 3], b: [f32; 3], t: f32| [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t);
        lerp(
            lerp(self.at(x0, y0), self.at(x1, y0), tx),
            lerp(self.at(x0, y1), self.at(x1, y1), tx),
            ty,
        )
    }

    /// The linear sRGB of skin with volume fractions `melanin` and
    /// `dermal_blood`, looked up by eq. 7.7's cube roots.
    pub fn skin(&self, melanin: f64, dermal_blood: f64) -> [f32; 3] {
        let (u, v) = coordinates(melanin, dermal_blood);
        self.sample(u, v)
    }
}

/// A fair dermal blood fraction (2%) the tones share.
pub const TONE_DERMAL_BLOOD: f64 = 0.02;

/// The melanin fraction of each tone: the middle of the melanosome
/// fractions of light, moderately and darkly pigmented skin (Jacques, OMLC:
/// 1.3-6.3%, 11-16%, 18-43%).
pub fn tone_melanin(t: SkinTone) -> f64 {
    match t {
        SkinTone::Light => 0.038,
        SkinTone::Medium => 0.135,
        SkinTone::Dark => 0.305,
    }
}

/// The tone's table coordinates.
pub fn tone_coordinates(t: SkinTone) -> (f64, f64) {
    coordinates(tone_melanin(t), TONE_DERMAL_BLOOD)
}

/// The tone's linear sRGB albedo.
pub fn tone_albedo(t: SkinTone) -> [f64; 3] {
    let (u, v) = tone_coordinates(t);
    colour(u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Both chromophores absorb at every visible wavelength: more of either
    // makes every channel darker (the table falls along both axes).
    #[test]
    fn the_table_falls_along_both_axes() {
        let t = ColourTable::new(16);
        for v in 0..t.size {
            for u in 0..t.size {
                let c = t.at(u, v);
                if u + 1 < t.size {
                    let n = t.at(u + 1, v);
                    assert!(
                        (0..3).all(|k| n[k] <= c[k]),
                        "melanin at ({u}, {v}): {c:?} -> {n:?}"
                    );
                }
                if v + 1 < t.size {
                    let n = t.at(u, v + 1);
                    assert!(
                        (0..3).all(|k| n[k] <= c[k]),
                        "blood at ({u}, {v}): {c:?} -> {n:?}"
                    );
                }
                assert!(c.iter().all(|&x| x > 0.0 && x < 1.0), "{c:?}");
            }
        }
    }

    // Blood absorbs green and blue far more than red (haemoglobin's bands at
    // 415, 540 and 575 nm): at light melanin, more blood reddens the skin,
    // green over red falling. At the darkest melanin the epidermis hides the
    // dermis: the blood axis barely moves the colour (under 10%).
    #[test]
    fn blood_reddens_light_skin_and_melanin_hides_it() {
        let (u, _) = coordinates(0.01, 0.0);
        let pale = colour(u, 0.0);
        let flushed = colour(u, 0.8);
        assert!(
            flushed[1] / flushed[0] < 0.9 * pale[1] / pale[0],
            "{pale:?} {flushed:?}"
        );
        let dark_pale = colour(1.0, 0.0);
        let dark_flushed = colour(1.0, 0.8);
        for c in 0..3 {
            assert!(
                dark_flushed[c] / dark_pale[c] > 0.9,
                "{dark_pale:?} {dark_flushed:?}"
            );
        }
    }

    // An independent implementation (a clean-room Python of the same model,
    // written apart from this file from the papers' equations and the public
    // tables) gave these linear sRGB at (C_m, C_hd): the two agree within 1%.
    #[test]
    fn the_table_against_an_independent_implementation() {
        let independent = [
            ((0.0, 0.0), [0.608, 0.580, 0.525]),
            ((0.008, 0.008), [0.456, 0.339, 0.293]),
            ((0.064, 0.064), [0.179, 0.123, 0.093]),
            ((0.216, 0.32), [0.068, 0.046, 0.032]),
        ];
        for ((m, b), want) in independent {
            let (u, v) = coordinates(m, b);
            let got = colour(u, v);
            for c in 0..3 {
                assert!(
                    (got[c] / want[c] - 1.0).abs() < 0.01 + 0.0005 / want[c],
                    "({m}, {b}): {got:?} against {want:?}"
                );
            }
        }
    }

    #[test]
    fn coordinates_invert_the_chromophores() {
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 1.0)] {
            let c = chromophores(u, v);
            let (u2, v2) = coordinates(c.melanin, c.dermal_blood);
            assert!((u - u2).abs() < 1e-12 && (v - v2).abs() < 1e-12);
            assert_eq!(c.eumelanin, 0.61);
            assert!((c.epidermal_blood - 0.25 * c.dermal_blood).abs() < 1e-15);
        }
        assert_eq!(coordinates(1.0, 1.0), (1.0, 1.0), "clamped to Table 7.1");
    }

    // The tones darken along melanin and keep skin's hue (red over green over
    // blue).
    #[test]
    fn three_tones_along_melanin() {
        let [light, medium, dark] = SkinTone::ALL.map(tone_albedo);
        for c in 0..3 {
            assert!(
                light[c] > medium[c] && medium[c] > dark[c],
                "{light:?} {medium:?} {dark:?}"
            );
        }
        for t in [light, medium, dark] {
            assert!(t[0] > t[1] && t[1] > t[2], "{t:?}");
        }
    }
}
