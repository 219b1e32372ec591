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
    pub fill_rgba8_gpix: f64,
    /// RGBA16F with constant-factor blending (read-modify-write).
    pub blend_rgba16f_gpix: f64,
}

/// A kind of fetch the passes make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fetch {
    BilinearRgba16f,
    PointRgba16f,
    BilinearR32f,
    PointR32f,
}

/// A kind of pixel write the passes make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Write {
    Rgba16f,
    Rgba16fBlend,
    Rgba8,
}

/// What one fragment of a pass does.
#[derive(Clone, Debug, PartialEq)]
pub struct PassCost {
    pub fetches: Vec<(Fetch, f64)>,
    pub writes: Vec<(Write, f64)>,
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

    fn fill(&self, w: Write) -> f64 {
        match w {
            Write::Rgba16f => self.fill_rgba16f_gpix,
            Write::Rgba16fBlend => self.blend_rgba16f_gpix,
            Write::Rgba8 => self.fill_rgba8_gpix,
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
    // Attachments of one MRT pass go through the ROPs one after another.
    let fill_s: f64 = cost
        .writes
        .iter()
        .map(|&(w, per)| n * per / (c.fill(w) * 1e9))
        .sum();
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
        writes: vec![(Write::Rgba16f, 1.0)],
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
        writes: if vertical {
            vec![(Write::Rgba16f, 1.0), (Write::Rgba16fBlend, 1.0)]
        } else {
            vec![(Write::Rgba16f, 1.0)]
        },
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
        writes: vec![(Write::Rgba16f, 1.0)],
    }
}

/// Composite: two point fetches, one write. Tone map: one fetch, one write.
pub fn composite_cost() -> PassCost {
    PassCost {
        fetches: vec![(Fetch::PointRgba16f, 2.0)],
        writes: vec![(Write::Rgba16f, 1.0)],
    }
}

pub fn tonemap_cost() -> PassCost {
    PassCost {
        fetches: vec![(Fetch::PointRgba16f, 1.0)],
        writes: vec![(Write::Rgba8, 1.0)],
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
            fill_rgba8_gpix: 14.0,
            blend_rgba16f_gpix: 3.5,
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
        let ms = floor_ms(&composite_cost(), 7_000_000, &h100_like());
        assert!((ms - 1.0).abs() < 1e-9);
        assert_eq!(floor_ms(&composite_cost(), 0, &h100_like()), 0.0);
        // The tone map writes 32 bpp, at its own (here twice the) rate.
        let ms = floor_ms(&tonemap_cost(), 7_000_000, &h100_like());
        assert!((ms - 0.5).abs() < 1e-9, "{ms}");
    }

    #[test]
    fn mrt_writes_add_up() {
        // ssg vertical: one plain and one blended RGBA16F write per pixel:
        // 1/7 + 1/3.5 ns per pixel, more than its 11 fetches at 31 Gtap/s.
        let ms = floor_ms(&ssg_pass_cost(true), 1_000_000, &h100_like());
        let fill = 1e6 / 7e9 + 1e6 / 3.5e9;
        assert!((ms - fill * 1e3).abs() < 1e-9, "{ms}");
        let h = floor_ms(&ssg_pass_cost(false), 1_000_000, &h100_like());
        assert!((h - 11.0 * 1e6 / 31e9 * 1e3).abs() < 1e-9, "{h}");
    }

    #[test]
    fn follow_surface_adds_depth_taps() {
        let a = separable_pass_cost(9, false);
        let b = separable_pass_cost(9, true);
        assert_eq!(b.fetches.len(), a.fetches.len() + 1);
        assert_eq!(b.fetches.last(), Some(&(Fetch::BilinearR32f, 8.0)));
    }
}
