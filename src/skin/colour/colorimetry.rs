//! A reflectance spectrum to the linear sRGB dermis renders in: lit by D65
//! (sRGB's white, so no chromatic adaptation), seen by the CIE 1931 observer,
//! normalised so that a perfect white reflector has Y = 1, then the sRGB
//! matrix (IEC 61966-2-1). The thesis names no illuminant for its table
//! (ch. 7.6); D65 is the one whose white the renderer's colours assume.

use super::spectra::{
    CIE1931_XBAR_5NM, CIE1931_YBAR_5NM, CIE1931_ZBAR_5NM, D65_5NM, FIRST_NM, SAMPLES, STEP_NM,
};

/// A spectrum at the tables' 81 wavelengths (`spectra`).
pub type Spectrum = [f64; SAMPLES];

/// CIE XYZ of `reflectance` under D65, Y = 1 for a perfect white.
pub fn xyz(reflectance: &Spectrum) -> [f64; 3] {
    let mut out = [0.0; 3];
    let mut white_y = 0.0;
    for (i, &r) in reflectance.iter().enumerate() {
        let s = D65_5NM[i] as f64;
        let cmf = [
            CIE1931_XBAR_5NM[i],
            CIE1931_YBAR_5NM[i],
            CIE1931_ZBAR_5NM[i],
        ];
        for c in 0..3 {
            out[c] += r * s * cmf[c] as f64;
        }
        white_y += s * CIE1931_YBAR_5NM[i] as f64;
    }
    out.map(|v| v / white_y)
}

/// XYZ to linear sRGB (IEC 61966-2-1's matrix).
pub fn linear_srgb_of_xyz([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    ]
}

/// The linear sRGB of `reflectance` under D65.
pub fn linear_srgb(reflectance: &Spectrum) -> [f64; 3] {
    linear_srgb_of_xyz(xyz(reflectance))
}

/// The sRGB transfer function to 8 bits (clamped to [0, 1] first).
pub fn srgb8(linear: [f64; 3]) -> [u8; 3] {
    linear.map(|c| {
        let c = c.clamp(0.0, 1.0);
        let e = if c <= 0.0031308 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round() as u8
    })
}

/// A spectrum sampled at `step_nm` from `first_nm` resampled to the tables'
/// wavelengths: linear between its samples, held at its ends beyond them.
pub fn resample(samples: &[f32], first_nm: f64, step_nm: f64) -> Spectrum {
    std::array::from_fn(|i| {
        let nm = FIRST_NM + STEP_NM * i as f64;
        let x = ((nm - first_nm) / step_nm).clamp(0.0, (samples.len() - 1) as f64);
        let k = (x.floor() as usize).min(samples.len().saturating_sub(2));
        let f = x - k as f64;
        let next = samples.get(k + 1).copied().unwrap_or(samples[k]);
        samples[k] as f64 * (1.0 - f) + next as f64 * f
    })
}

#[cfg(test)]
mod tests {
    use super::super::spectra::*;
    use super::*;

    // The perfect white reflector under D65 is sRGB's white, (1, 1, 1): the
    // tables, the normalisation and the matrix agree (the matrix is given to
    // four decimals, so within 5e-4).
    #[test]
    fn a_perfect_white_is_srgb_white() {
        let rgb = linear_srgb(&[1.0; SAMPLES]);
        for c in rgb {
            assert!((c - 1.0).abs() < 5e-4, "{rgb:?}");
        }
        let [x, y, z] = xyz(&[1.0; SAMPLES]);
        // D65's white point (0.95047, 1, 1.08883), within the 5 nm tables' sums.
        assert!((x - 0.95047).abs() < 1e-3 && y == 1.0 && (z - 1.08883).abs() < 1e-3);
    }

    // Two published spectra with published sRGB (BabelColor's ColorChecker
    // average): dark skin to the level, light skin within two levels.
    #[test]
    fn the_colorchecker_skin_patches_give_their_published_srgb() {
        let dark = resample(&CHECKER_DARK_SKIN_10NM, 380.0, 10.0);
        assert_eq!(srgb8(linear_srgb(&dark)), CHECKER_DARK_SKIN_SRGB8);
        let light = srgb8(linear_srgb(&resample(
            &CHECKER_LIGHT_SKIN_10NM,
            380.0,
            10.0,
        )));
        for c in 0..3 {
            let d = (light[c] as i32 - CHECKER_LIGHT_SKIN_SRGB8[c] as i32).abs();
            assert!(d <= 2, "{light:?} against {CHECKER_LIGHT_SKIN_SRGB8:?}");
        }
    }

    #[test]
    fn resampling_keeps_the_samples_and_holds_the_ends() {
        let s = resample(&[0.0, 1.0, 3.0], 400.0, 10.0);
        assert_eq!(s[0], 0.0, "380 nm: held at the first sample");
        assert_eq!(s[4], 0.0, "400 nm");
        assert_eq!(s[5], 0.5, "405 nm");
        assert_eq!(s[6], 1.0, "410 nm");
        assert_eq!(s[7], 2.0, "415 nm");
        assert_eq!(s[80], 3.0, "780 nm: held at the last");
    }
}
