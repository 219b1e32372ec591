//! The floor of a pass: the time its texture fetches and pixel writes would take
//! at the device's measured ceilings. Fetch units and ROPs work concurrently, so
//! the floor is the larger of the two, not their sum. A dispatch's floor is its
//! fetches at the compute path's probed rates (`compute_floor_ms`). Pure
//! arithmetic.

use crate::graph::work::{ColorWrite, Fetch, Filter, Format, Work};

// report.json's types: the schema lives in `report`.
pub use crate::report::{Ceilings, ComputeCeilings};

/// Floor in milliseconds of a dispatch that ran `invocations` invocations:
/// its exactly declared fetches at the compute path's probed rates. Fetches
/// declared as bounds (behind a branch) and kinds no probe measured (the
/// stencil) are left out, so it stays a floor; `None` when nothing is left
/// to count or the compute rates were not probed.
pub fn compute_floor_ms(work: &Work, invocations: u64, c: &Ceilings) -> Option<f64> {
    let (Work::Compute { shader, .. }, Some(rates)) = (work, c.compute.as_ref()) else {
        return None;
    };
    let n = invocations as f64;
    let mut fetch_s = 0.0;
    for f in shader.fetches.iter().filter(|f| f.exact) {
        if let Some(rate) = compute_fetch_rate(rates, f) {
            fetch_s += n * f.count / (rate * 1e9);
        }
    }
    (fetch_s > 0.0).then_some(fetch_s * 1e3)
}

/// The rate of a declared fetch among a path's probed rates (bilinear and
/// point RGBA16F, bilinear and point R32F), if a probe measured that kind.
fn rate_of(f: &Fetch, [b16, p16, b32, p32]: [f64; 4]) -> Option<f64> {
    Some(match (f.format, f.filter) {
        (Format::Rgba16Float, Filter::Bilinear) => b16,
        (Format::Rgba16Float, Filter::Point) => p16,
        (Format::R32Float, Filter::Bilinear) => b32,
        (Format::R32Float, Filter::Point) => p32,
        _ => return None,
    })
}

/// A fragment shader's fetch rate of a declared fetch.
fn fetch_rate(c: &Ceilings, f: &Fetch) -> Option<f64> {
    let r = [
        c.bilinear_rgba16f_gtaps,
        c.point_rgba16f_gtaps,
        c.bilinear_r32f_gtaps,
        c.point_r32f_gtaps,
    ];
    rate_of(f, r)
}

/// A compute shader's fetch rate of a declared fetch.
fn compute_fetch_rate(c: &ComputeCeilings, f: &Fetch) -> Option<f64> {
    let r = [
        c.bilinear_rgba16f_gtaps,
        c.point_rgba16f_gtaps,
        c.bilinear_r32f_gtaps,
        c.point_r32f_gtaps,
    ];
    rate_of(f, r)
}

/// Fill rate of a declared colour write, if a probe measured that kind.
fn fill_rate(c: &Ceilings, w: &ColorWrite) -> Option<f64> {
    Some(match (w.format, w.blend) {
        (Format::Rgba16Float, false) => c.fill_rgba16f_gpix,
        (Format::Rgba16Float, true) => c.blend_rgba16f_gpix?,
        (Format::Rgba8Srgb | Format::Rgba8Unorm, false) => c.fill_rgba8_gpix?,
        _ => return None,
    })
}

/// Floor in milliseconds of a pass that shaded `invocations` fragments: its
/// declared fetches at the probed fetch rates against its writes at the probed
/// fill rates, the larger of the two. `None` where the floor would not be a
/// floor: a pass whose declared counts are upper bounds (branches), or one that
/// fetches or writes a kind no probe measured (the geometry pass's RGBA8 maps
/// and depth compares, depth-only and copy passes).
pub fn floor_ms(work: &Work, invocations: u64, c: &Ceilings) -> Option<f64> {
    let Work::Raster {
        shader: Some(shader),
        color,
        ..
    } = work
    else {
        return None;
    };
    let n = invocations as f64;
    let mut fetch_s = 0.0;
    for f in &shader.fetches {
        if !f.exact {
            return None;
        }
        // giga-ops / (giga-ops per second) = seconds.
        fetch_s += n * f.count / (fetch_rate(c, f)? * 1e9);
    }
    // Attachments of one MRT pass go through the ROPs one after another.
    let mut fill_s = 0.0;
    for w in color {
        fill_s += n / (fill_rate(c, w)? * 1e9);
    }
    Some(fetch_s.max(fill_s) * 1e3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::ShaderWork;

    fn h100_like() -> Ceilings {
        Ceilings {
            bilinear_rgba16f_gtaps: 31.0,
            point_rgba16f_gtaps: 31.0,
            bilinear_r32f_gtaps: 31.0,
            point_r32f_gtaps: 31.0,
            fill_rgba16f_gpix: 7.0,
            fill_rgba8_gpix: Some(14.0),
            blend_rgba16f_gpix: Some(3.5),
            compute: Some(ComputeCeilings {
                bilinear_rgba16f_gtaps: 500.0,
                point_rgba16f_gtaps: 500.0,
                bilinear_r32f_gtaps: 500.0,
                point_r32f_gtaps: 1000.0,
                store_rgba16f_gpix: 200.0,
            }),
        }
    }

    #[test]
    fn a_dispatch_is_floored_by_its_exact_fetches_at_the_compute_rates() {
        let shader = |fetches| ShaderWork {
            shader: "c".into(),
            fetches,
            ..Default::default()
        };
        let mut bound = fetch(Format::Rgba16Float, Filter::Bilinear, 100.0);
        bound.exact = false;
        let work = Work::Compute {
            shader: shader(vec![
                fetch(Format::Rgba16Float, Filter::Point, 5.0),
                fetch(Format::R32Float, Filter::Point, 5.0),
                bound,
            ]),
            invocations: 1_000_000,
        };
        // 5 M at 500 G/s and 5 M at 1000 G/s: 0.015 ms; the bound is left out.
        let f = compute_floor_ms(&work, 1_000_000, &h100_like()).unwrap();
        assert!((f - 0.015).abs() < 1e-12, "{f}");
        // No compute rates, or only bounds: no floor.
        let old = Ceilings {
            compute: None,
            ..h100_like()
        };
        assert_eq!(compute_floor_ms(&work, 1_000_000, &old), None);
        let only_bounds = Work::Compute {
            shader: shader(vec![Fetch {
                exact: false,
                ..fetch(Format::Rgba16Float, Filter::Point, 5.0)
            }]),
            invocations: 1,
        };
        assert_eq!(compute_floor_ms(&only_bounds, 10, &h100_like()), None);
        // A raster pass has no compute floor.
        let r = raster(vec![fetch(Format::Rgba16Float, Filter::Point, 1.0)], vec![]);
        assert_eq!(compute_floor_ms(&r, 10, &h100_like()), None);
    }

    fn fetch(format: Format, filter: Filter, count: f64) -> Fetch {
        Fetch {
            texture: "t".into(),
            format,
            filter,
            count,
            exact: true,
            coherent: true,
            spread: Vec::new(),
        }
    }

    fn raster(fetches: Vec<Fetch>, color: Vec<ColorWrite>) -> Work {
        Work::Raster {
            shader: Some(ShaderWork {
                shader: "s".into(),
                fetches,
                ..Default::default()
            }),
            color,
            depth_stencil: None,
            width: 1920,
            height: 1080,
            triangles: 1,
            msaa: 1,
            clears: vec![],
        }
    }

    const RGBA16F: ColorWrite = ColorWrite {
        format: Format::Rgba16Float,
        blend: false,
    };

    #[test]
    fn fetch_bound_pass() {
        // 1080p, 17 taps of colour + 17 of depth with follow-surface:
        // (1 + 1 + 16 + 16) fetches x 2073600 / 31e9 = 2.274 ms.
        let w = raster(
            vec![
                fetch(Format::Rgba16Float, Filter::Point, 1.0),
                fetch(Format::R32Float, Filter::Point, 1.0),
                fetch(Format::Rgba16Float, Filter::Bilinear, 16.0),
                fetch(Format::R32Float, Filter::Bilinear, 16.0),
            ],
            vec![RGBA16F],
        );
        let ms = floor_ms(&w, 1920 * 1080, &h100_like()).unwrap();
        assert!((ms - 34.0 * 2073600.0 / 31e9 * 1e3).abs() < 1e-9, "{ms}");
    }

    #[test]
    fn fill_bound_pass() {
        // Two fetches and one write: the 7 Gpix/s fill dominates.
        let composite = raster(
            vec![fetch(Format::Rgba16Float, Filter::Point, 2.0)],
            vec![RGBA16F],
        );
        let ms = floor_ms(&composite, 7_000_000, &h100_like()).unwrap();
        assert!((ms - 1.0).abs() < 1e-9);
        assert_eq!(floor_ms(&composite, 0, &h100_like()), Some(0.0));
        // The tone map writes 32 bpp, at its own (here twice the) rate.
        let tonemap = raster(
            vec![fetch(Format::Rgba16Float, Filter::Point, 1.0)],
            vec![ColorWrite {
                format: Format::Rgba8Srgb,
                blend: false,
            }],
        );
        let ms = floor_ms(&tonemap, 7_000_000, &h100_like()).unwrap();
        assert!((ms - 0.5).abs() < 1e-9, "{ms}");
    }

    #[test]
    fn mrt_writes_add_up() {
        // ssg vertical: one plain and one blended RGBA16F write per pixel:
        // 1/7 + 1/3.5 ns per pixel, more than its 11 fetches at 31 Gtap/s.
        let fetches = vec![
            fetch(Format::Rgba16Float, Filter::Point, 1.0),
            fetch(Format::R32Float, Filter::Point, 3.0),
            fetch(Format::Rgba16Float, Filter::Bilinear, 7.0),
        ];
        let blended = ColorWrite {
            blend: true,
            ..RGBA16F
        };
        let v = raster(fetches.clone(), vec![RGBA16F, blended]);
        let ms = floor_ms(&v, 1_000_000, &h100_like()).unwrap();
        let fill = 1e6 / 7e9 + 1e6 / 3.5e9;
        assert!((ms - fill * 1e3).abs() < 1e-9, "{ms}");
        let h = floor_ms(&raster(fetches, vec![RGBA16F]), 1_000_000, &h100_like()).unwrap();
        assert!((h - 11.0 * 1e6 / 31e9 * 1e3).abs() < 1e-9, "{h}");
    }

    // No floor where it would not bound the pass from below.
    #[test]
    fn no_floor_for_upper_bounds_or_unprobed_kinds() {
        let mut f = fetch(Format::Rgba16Float, Filter::Bilinear, 32.0);
        f.exact = false;
        assert_eq!(
            floor_ms(&raster(vec![f], vec![RGBA16F]), 100, &h100_like()),
            None
        );
        let rgba8 = fetch(Format::Rgba8Unorm, Filter::Bilinear, 1.0);
        assert_eq!(
            floor_ms(&raster(vec![rgba8], vec![RGBA16F]), 100, &h100_like()),
            None
        );
        let copy = Work::Copy {
            texels: 10,
            bytes_per_texel: 8,
            rects: 1,
        };
        assert_eq!(floor_ms(&copy, 100, &h100_like()), None);
    }
}
