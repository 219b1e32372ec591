//! Precomputed Beckmann distribution for the Kelemen/Szirmay-Kalos skin
//! specular (GPU Gems 3, ch. 14), plus Schlick's Fresnel term.

/// Reflectance of skin at normal incidence (GPU Gems 3 uses 0.028).
pub const SKIN_F0: f32 = 0.028;

/// Beckmann distribution as used by the KS specular:
/// `exp(-tan^2(a) / m^2) / (m^2 cos^4(a))`, `a = acos(ndoth)`.
///
/// This is GPU Gems 3's version without the 1/pi factor (its hemispherical
/// integral against `cos` is pi, not 1). Returns 0 for `ndoth <= 0`
/// (half vector below the surface) and for `m <= 0` (a zero-roughness lobe
/// is a delta that a texture cannot represent).
pub fn beckmann(ndoth: f64, m: f64) -> f64 {
    if ndoth <= 0.0 || m <= 0.0 || ndoth.is_nan() || m.is_nan() {
        return 0.0;
    }
    let c = ndoth.min(1.0);
    let c2 = c * c;
    // tan^2 from cos directly; avoids acos/tan round trip near 1.
    let tan2 = (1.0 - c2) / c2;
    let m2 = m * m;
    (-tan2 / m2).exp() / (m2 * c2 * c2)
}

/// `size x size` row-major look-up texture, `u = ndoth = (i + 0.5)/size`
/// along x, `v = m = (j + 0.5)/size` along y.
///
/// Stored value `0.5 * beckmann^0.1`: the 0.1 power compresses the huge
/// dynamic range (up to ~size^2) into [0, 1]-ish texels so an 8/16-bit or
/// filtered texture keeps precision; the shader recovers
/// `D = pow(2 * tex, 10)` exactly as GPU Gems 3 does.
pub fn beckmann_lut(size: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(size * size);
    for j in 0..size {
        let m = (j as f64 + 0.5) / size as f64;
        for i in 0..size {
            let ndoth = (i as f64 + 0.5) / size as f64;
            out.push((0.5 * beckmann(ndoth, m).powf(0.1)) as f32);
        }
    }
    out
}

/// Schlick's Fresnel approximation `F = e + f0 (1 - e)`, `e = (1 - v.h)^5`.
///
/// `v_dot_h` is clamped to [0, 1] because normalisation rounding can push
/// it slightly outside, which would otherwise give F > 1 or negative bases.
pub fn fresnel_schlick(v_dot_h: f32, f0: f32) -> f32 {
    let base = 1.0 - v_dot_h.clamp(0.0, 1.0);
    let e = base.powi(5);
    e + f0 * (1.0 - e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_points() {
        assert!((beckmann(1.0, 0.3) - 1.0 / 0.09).abs() < 1e-12);
        assert_eq!(beckmann(0.0, 0.3), 0.0);
        assert_eq!(beckmann(-0.5, 0.3), 0.0);
        assert_eq!(beckmann(0.5, 0.0), 0.0);
        // Compare with the acos/tan formulation.
        let (c, m) = (0.7f64, 0.35f64);
        let a = c.acos();
        let want = (-(a.tan() / m).powi(2)).exp() / (m * m * c.powi(4));
        assert!((beckmann(c, m) - want).abs() < 1e-12 * want);
    }

    #[test]
    fn hemisphere_integral_is_pi() {
        // integral D(cos t) cos t dw = 2 pi integral D cos t sin t dt = pi.
        for m in [0.2, 0.35, 0.6] {
            let n = 200_000;
            let h = std::f64::consts::FRAC_PI_2 / f64::from(n);
            let s: f64 = (0..n)
                .map(|i| {
                    let t = (f64::from(i) + 0.5) * h;
                    beckmann(t.cos(), m) * t.cos() * t.sin() * h
                })
                .sum();
            let total = 2.0 * std::f64::consts::PI * s;
            assert!(
                (total - std::f64::consts::PI).abs() < 1e-6,
                "m={m}: {total}"
            );
        }
    }

    #[test]
    fn lut_round_trip() {
        let size = 128;
        let lut = beckmann_lut(size);
        assert_eq!(lut.len(), size * size);
        let mut nonzero = 0;
        for j in 0..size {
            for i in 0..size {
                let ndoth = (i as f64 + 0.5) / size as f64;
                let m = (j as f64 + 0.5) / size as f64;
                let want = beckmann(ndoth, m);
                let got = (2.0 * f64::from(lut[j * size + i])).powi(10);
                assert!(
                    (got - want).abs() <= 1e-5 * want,
                    "texel ({i},{j}): {got} vs {want}"
                );
                nonzero += usize::from(want > 0.0);
            }
        }
        assert!(nonzero > size * size / 2);
    }

    #[test]
    fn fresnel_limits() {
        assert!((fresnel_schlick(1.0, SKIN_F0) - SKIN_F0).abs() < 1e-7);
        assert!((fresnel_schlick(0.0, SKIN_F0) - 1.0).abs() < 1e-7);
        assert!((fresnel_schlick(1.2, SKIN_F0) - SKIN_F0).abs() < 1e-7);
        let mid = fresnel_schlick(0.5, SKIN_F0);
        assert!((mid - (0.03125 + SKIN_F0 * 0.96875)).abs() < 1e-6);
    }
}
