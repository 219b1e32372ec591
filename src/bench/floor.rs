//! The floor of a pass: the time its texture fetches and pixel writes would take
//! at the device's measured ceilings. Fetch units and ROPs work concurrently, so
//! the floor is the larger of the two, not their sum. Pure arithmetic.

use serde::Serialize;

/// Rates measured by the ceiling probes, in giga-operations per second.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Ceilings {
    pub bilinear_rgba16f_gtaps: f64,
    pub point_rgba16f_gtaps: f64,
    pub bilinear_r32f_gtaps: f64,
    pub point_r32f_gtaps: f64,
    pub fill_rgba16f_gpix: f64,
}

/// A kind of fetch the passes make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fetch {
    BilinearRgba16f,
    PointRgba16f,
    BilinearR32f,
    PointR32f,
}

/// What one fragment of a pass does.
#[derive(Clone, Debug, PartialEq)]
pub struct PassCost {
    pub fetches: Vec<(Fetch, f64)>,
    pub writes: f64,
}

impl Ceilings {
    fn rate(&self, f: Fetch) -> f64 {
        match f {
            Fetch::BilinearRgba16f => self.bilinear_rgba16f_gtaps,
            Fetch::PointRgba16f => self.point_rgba16f_gtaps,
            Fetch::BilinearR32f => self.bilinear_r32f_gtaps,
            Fetch::PointR32f => self.point_r32f_gtaps,
        }
    }
}

/// Floor in milliseconds for `invocations` fragments.
pub fn floor_ms(cost: &PassCost, invocations: u64, c: &Ceilings) -> f64 {
    let n = invocations as f64;
    // giga-ops / (giga-ops per second) = seconds; x1e3 for ms.
    let fetch_s: f64 = cost
        .fetches
        .iter()
        .map(|&(f, per)| n * per / (c.rate(f) * 1e9))
        .sum();
    let fill_s = n * cost.writes / (c.fill_rgba16f_gpix * 1e9);
    fetch_s.max(fill_s) * 1e3
}

/// Cost of one separable SSS pass with `n_samples` taps: centre colour and depth
/// by texelFetch, then n-1 bilinear colour taps and, with follow-surface, n-1
/// bilinear depth taps; one RGBA16F write.
pub fn separable_pass_cost(n_samples: usize, follow_surface: bool) -> PassCost {
    let taps = n_samples.saturating_sub(1) as f64;
    let mut fetches = vec![
        (Fetch::PointRgba16f, 1.0),
        (Fetch::PointR32f, 1.0),
        (Fetch::BilinearRgba16f, taps),
    ];
    if follow_surface {
        fetches.push((Fetch::BilinearR32f, taps));
    }
    PassCost {
        fetches,
        writes: 1.0,
    }
}

/// One pass of an ssg Gaussian (Listing 4.1): centre colour and depth plus two
/// depth texels for the gradient by texelFetch, 7 bilinear colour taps; the
/// vertical pass writes two targets (RT1 and the blended RTF).
pub fn ssg_pass_cost(vertical: bool) -> PassCost {
    PassCost {
        fetches: vec![
            (Fetch::PointRgba16f, 1.0),
            (Fetch::PointR32f, 3.0),
            (Fetch::BilinearRgba16f, 7.0),
        ],
        writes: if vertical { 2.0 } else { 1.0 },
    }
}

/// ss-jittered: centre colour, centre depth and four gradient texels by
/// texelFetch, 12 bilinear ring taps, one write.
pub fn jittered_cost() -> PassCost {
    PassCost {
        fetches: vec![
            (Fetch::PointRgba16f, 1.0),
            (Fetch::PointR32f, 5.0),
            (Fetch::BilinearRgba16f, 12.0),
        ],
        writes: 1.0,
    }
}

/// Composite: two point fetches, one write. Tone map: one fetch, one write.
pub fn composite_cost() -> PassCost {
    PassCost {
        fetches: vec![(Fetch::PointRgba16f, 2.0)],
        writes: 1.0,
    }
}

pub fn tonemap_cost() -> PassCost {
    PassCost {
        fetches: vec![(Fetch::PointRgba16f, 1.0)],
        writes: 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h100_like() -> Ceilings {
        Ceilings {
            bilinear_rgba16f_gtaps: 31.0,
            point_rgba16f_gtaps: 31.0,
            bilinear_r32f_gtaps: 31.0,
            point_r32f_gtaps: 31.0,
            fill_rgba16f_gpix: 7.0,
        }
    }

    #[test]
    fn fetch_bound_pass() {
        // 1080p, 17 taps of colour + 17 of depth with follow-surface:
        // (1 + 1 + 16 + 16) fetches x 2073600 / 31e9 = 2.274 ms.
        let ms = floor_ms(&separable_pass_cost(17, true), 1920 * 1080, &h100_like());
        assert!((ms - 34.0 * 2073600.0 / 31e9 * 1e3).abs() < 1e-9, "{ms}");
    }

    #[test]
    fn fill_bound_pass() {
        // One fetch and one write: the 7 Gpix/s fill dominates.
        let ms = floor_ms(&tonemap_cost(), 7_000_000, &h100_like());
        assert!((ms - 1.0).abs() < 1e-9);
        assert_eq!(floor_ms(&tonemap_cost(), 0, &h100_like()), 0.0);
    }

    #[test]
    fn follow_surface_adds_depth_taps() {
        let a = separable_pass_cost(9, false);
        let b = separable_pass_cost(9, true);
        assert_eq!(b.fetches.len(), a.fetches.len() + 1);
        assert_eq!(b.fetches.last(), Some(&(Fetch::BilinearR32f, 8.0)));
    }
}
