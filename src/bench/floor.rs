//! The floor of a pass: the time its work would take at the device's measured
//! ceilings. Fetch units, ROPs, the rasteriser's set-up and the compute
//! path's load/store units work concurrently (or, where they share a unit,
//! at least one of them must finish), so the floor is the largest of the
//! times, never their sum:
//!
//! - a raster pass: its exact fetches at the fragment path's fetch rates
//!   (bilinear/point RGBA16F, R32F, RGBA8, depth-compare D32), its fill (its
//!   fragments through its attachments: the geometry pass's MRT set at its own
//!   probed rate, a depth-only pass at the depth-only rate, other passes one
//!   attachment after another), and its triangles at the probed set-up rate;
//! - a dispatch: its exact fetches at the compute path's rates and the
//!   shared memory every invocation moves at the probed shared-memory
//!   bandwidth;
//! - a copy: its bytes at the probed copy bandwidth.
//!
//! Work no probe measured, and fetches declared as bounds (behind a branch),
//! are left out, so the floor stays a floor; a pass where nothing is left
//! has none, and [`pass_floor`] says why. Pure arithmetic.

use crate::graph::work::{ColorWrite, Fetch, Filter, Format, Work};

// report.json's types: the schema lives in `report`.
pub use crate::report::{Ceilings, ComputeCeilings};

/// What a benched pass counted in its last measured frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counts {
    /// Fragment shader invocations (pipeline statistics).
    pub fragments: Option<u64>,
    /// Compute shader invocations (`None`: the pass dispatched nothing).
    pub compute: Option<u64>,
    /// Samples that passed the depth and stencil tests.
    pub samples_passed: u64,
}

/// The colour attachments of the geometry pass, the set whose fill is
/// probed as one (probe_fill_mrt.frag; `render::targets`).
pub const GEOMETRY_MRT: [Format; 3] = [Format::Rgba16Float, Format::Rgba16Float, Format::R32Float];

/// The floor of one pass in milliseconds, or why it has none.
pub fn pass_floor(work: Option<&Work>, counts: Counts, c: &Ceilings) -> Result<f64, String> {
    match work {
        None => Err("no declared work".into()),
        Some(w @ Work::Compute { .. }) => match counts.compute {
            Some(n) => compute_floor_ms(w, n, c).ok_or_else(|| compute_reason(w, c)),
            None => Err("dispatched nothing".into()),
        },
        Some(w @ Work::Raster { .. }) => raster_floor_ms(w, counts, c).ok_or_else(|| {
            "none of its work is of a probed kind (unprobed formats, or fetches only behind branches)".into()
        }),
        Some(Work::Copy {
            texels,
            bytes_per_texel,
            ..
        }) => match c.copy_gbytes {
            // Its bytes at the probed RGBA16F copy's bandwidth (a smaller
            // texel copies no faster per byte; each rectangle's fixed cost
            // is left out).
            Some(rate) if rate > 0.0 => {
                Ok(*texels as f64 * f64::from(*bytes_per_texel) / (rate * 1e9) * 1e3)
            }
            _ => Err("a copy, and the copy rate was not probed".into()),
        },
        Some(Work::Clear {
            texels,
            bytes_per_texel,
        }) => Err(format!(
            "a clear of {} bytes: the command's fixed cost, which no probed rate bounds",
            texels * u64::from(*bytes_per_texel)
        )),
    }
}

fn compute_reason(w: &Work, c: &Ceilings) -> String {
    if c.compute.is_none() {
        return "the compute rates were not probed".into();
    }
    let Work::Compute { shader, .. } = w else {
        unreachable!("called for dispatches")
    };
    let bounds = shader.fetches.iter().any(|f| !f.exact);
    let fixed = c
        .compute
        .and_then(|r| r.dispatch_ms)
        .map_or(String::new(), |ms| {
            format!(" (only a dispatch's fixed cost, {ms:.4} ms, is certain)")
        });
    format!(
        "its fetches are {} and no shared-memory traffic is certain for every invocation{fixed}",
        if bounds {
            "bounds behind branches"
        } else {
            "of unprobed kinds"
        }
    )
}

/// Floor in milliseconds of a dispatch that ran `invocations` invocations:
/// the larger of its exactly declared fetches at the compute path's probed
/// rates and the shared-memory bytes every invocation moves at the probed
/// shared-memory bandwidth (writes priced as loads: both go through the
/// same banks, one 4-byte word per bank a clock on the GPUs we know), after
/// the probed cost of a one-group dispatch where it was probed: the launch,
/// the barrier's drain and the timestamps every pass of the frame has around
/// it, which come before and after the work, not beside it (0.012-0.014 ms on
/// the H100, a third of a small pass). `None` when nothing is left to count
/// or the compute rates were not probed.
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
    let shared_s = match rates.shared_load_gbytes {
        Some(r) if r > 0.0 => n * shader.shared_bytes / (r * 1e9),
        _ => 0.0,
    };
    // Storage writes are left out: the blurs declare theirs at skin pixels
    // only (at most), and a dispatch's invocations include the others.
    let s = fetch_s.max(shared_s);
    (s > 0.0).then_some(s * 1e3 + rates.dispatch_ms.unwrap_or(0.0))
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

/// A fragment shader's fetch rate of a declared fetch: the four probed on
/// both paths, RGBA8 (either colour space: the sRGB decode is free on the
/// GPUs we know, and an RGBA8 fetch costs no more than the probe's) and the
/// shadow map's depth compares.
fn fetch_rate(c: &Ceilings, f: &Fetch) -> Option<f64> {
    let r = [
        c.bilinear_rgba16f_gtaps,
        c.point_rgba16f_gtaps,
        c.bilinear_r32f_gtaps,
        c.point_r32f_gtaps,
    ];
    rate_of(f, r).or(match (f.format, f.filter) {
        (Format::Rgba8Unorm | Format::Rgba8Srgb, Filter::Bilinear) => c.bilinear_rgba8_gtaps,
        (Format::Rgba8Unorm | Format::Rgba8Srgb, Filter::Point) => c.point_rgba8_gtaps,
        (Format::D32Float, Filter::DepthCompare) => c.pcf_d32_gtaps,
        _ => None,
    })
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

/// Floor in milliseconds of a pass that shaded and wrote `invocations`
/// fragments (one sample each): [`raster_floor_ms`].
pub fn floor_ms(work: &Work, invocations: u64, c: &Ceilings) -> Option<f64> {
    let counts = Counts {
        fragments: Some(invocations),
        compute: None,
        samples_passed: invocations,
    };
    raster_floor_ms(work, counts, c)
}

/// The raster floor: the largest of its exact fetches of probed kinds per
/// shaded fragment, its writes per written sample at the probed fill rates,
/// and its triangles at the set-up rate probed in its state. `None` when
/// nothing is of a probed kind.
pub fn raster_floor_ms(work: &Work, counts: Counts, c: &Ceilings) -> Option<f64> {
    let Work::Raster {
        shader,
        color,
        depth_stencil,
        triangles,
        msaa,
        ..
    } = work
    else {
        return None;
    };
    let mut counted = false;
    let mut fetch_s = 0.0;
    let mut fill_s = 0.0;
    // Fetches are made per shaded fragment (NVIDIA counts invocations after
    // the early tests); writes per sample that passed the tests and was not
    // discarded (SMAA's and MLAA's edge passes discard most fragments), a
    // pixel's samples written together.
    let n = counts.fragments.unwrap_or(0) as f64;
    let written = counts.samples_passed as f64 / f64::from((*msaa).max(1));
    if let Some(shader) = shader {
        for f in shader.fetches.iter().filter(|f| f.exact) {
            if let Some(rate) = fetch_rate(c, f) {
                // giga-ops / (giga-ops per second) = seconds.
                fetch_s += n * f.count / (rate * 1e9);
                counted = true;
            }
        }
        let formats: Vec<Format> = color.iter().map(|w| w.format).collect();
        let writes_depth = depth_stencil.is_some_and(|d| d.depth_write);
        match c.fill_geometry_mrt_gpix {
            Some(rate)
                if formats.starts_with(&GEOMETRY_MRT)
                    && writes_depth
                    && !color.iter().any(|w| w.blend) =>
            {
                fill_s = written / (rate * 1e9);
                // Targets beyond the probed set (poisson's normals,
                // post-scatter texturing's albedo) through the ROPs after
                // it, each at its single-target rate. (Before, such a pass
                // summed single-target rates alone and left the unprobed
                // R32F out: its floor fell below the 3-target pass's.)
                for w in &color[GEOMETRY_MRT.len()..] {
                    if let Some(rate) = fill_rate(c, w) {
                        fill_s += written / (rate * 1e9);
                    }
                }
                counted = true;
            }
            _ => {
                // Attachments of one MRT pass go through the ROPs one after
                // another; an unprobed one is left out.
                for w in color {
                    if let Some(rate) = fill_rate(c, w) {
                        fill_s += written / (rate * 1e9);
                        counted = true;
                    }
                }
            }
        }
    } else if let Some(ds) = depth_stencil.filter(|d| d.depth_write) {
        // Depth-only (the shadow map): no fragment shader runs; the samples
        // that passed are written, at the probed depth-only rate.
        if let (Format::D32Float, Some(rate)) = (ds.format, c.fill_depth_d32_gpix) {
            fill_s = written / (rate * 1e9);
            counted = true;
        }
    }
    // Triangles: a full-screen pass's one or few are nothing; a mesh pass's
    // go through set-up at the rate probed in its own state.
    let tri_rate = match (
        shader.is_some(),
        depth_stencil.is_some_and(|d| d.depth_write),
    ) {
        (false, true) => c.triangles_depth_gtris,
        (true, true) if !color.is_empty() => c.triangles_geometry_gtris,
        _ => None,
    };
    let mut tri_s = 0.0;
    if let Some(rate) = tri_rate {
        tri_s = *triangles as f64 / (rate * 1e9);
        counted = true;
    }
    counted.then_some(fetch_s.max(fill_s).max(tri_s) * 1e3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::{DepthStencilUse, ShaderWork};

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
                shared_load_gbytes: Some(30_000.0),
                dispatch_ms: None,
            }),
            bilinear_rgba8_gtaps: Some(31.0),
            point_rgba8_gtaps: Some(62.0),
            pcf_d32_gtaps: Some(15.5),
            fill_depth_d32_gpix: Some(28.0),
            fill_geometry_mrt_gpix: Some(2.0),
            triangles_depth_gtris: Some(4.0),
            triangles_geometry_gtris: Some(2.0),
            copy_gbytes: None,
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
        // With a probed one-group dispatch, its fixed cost comes first.
        let mut probed = h100_like();
        if let Some(c) = probed.compute.as_mut() {
            c.dispatch_ms = Some(0.013);
        }
        let f = compute_floor_ms(&work, 1_000_000, &probed).unwrap();
        assert!((f - 0.028).abs() < 1e-12, "{f}");
        let why = pass_floor(
            Some(&Work::Compute {
                shader: shader(vec![Fetch {
                    exact: false,
                    ..fetch(Format::Rgba16Float, Filter::Point, 5.0)
                }]),
                invocations: 1,
            }),
            Counts {
                compute: Some(10),
                ..Counts::default()
            },
            &probed,
        )
        .unwrap_err();
        assert!(why.contains("0.0130 ms"), "{why}");
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

    // Bounds (behind branches) and unprobed kinds are left out, so the floor
    // stays a floor; a pass with nothing left has none.
    #[test]
    fn bounds_and_unprobed_kinds_are_left_out() {
        let mut bound = fetch(Format::Rgba16Float, Filter::Bilinear, 32.0);
        bound.exact = false;
        let point = fetch(Format::Rgba16Float, Filter::Point, 62.0);
        // 62 point fetches at 31 Gtap/s (2 ns) beat the 1/7 ns fill; the
        // bound's 32 bilinear are not counted.
        let ms = floor_ms(
            &raster(vec![bound.clone(), point], vec![RGBA16F]),
            1_000_000,
            &h100_like(),
        )
        .unwrap();
        assert!((ms - 2.0).abs() < 1e-9, "{ms}");
        // Only the bound: the fill alone.
        let ms = floor_ms(&raster(vec![bound], vec![RGBA16F]), 7_000_000, &h100_like()).unwrap();
        assert!((ms - 1.0).abs() < 1e-9, "{ms}");
        // An unprobed fetch kind and an unprobed write: nothing to count.
        let r16 = fetch(Format::R16Float, Filter::Bilinear, 1.0);
        let r16_write = ColorWrite {
            format: Format::R16Float,
            blend: false,
        };
        assert_eq!(
            floor_ms(&raster(vec![r16], vec![r16_write]), 100, &h100_like()),
            None
        );
        let copy = Work::Copy {
            texels: 10,
            bytes_per_texel: 8,
            rects: 1,
        };
        assert_eq!(floor_ms(&copy, 100, &h100_like()), None);
        let why = pass_floor(Some(&copy), Counts::default(), &h100_like()).unwrap_err();
        assert!(why.contains("copy"), "{why}");
        // With the copy probed: its bytes at the copy bandwidth, 80 B at
        // 400 GB/s.
        let probed = Ceilings {
            copy_gbytes: Some(400.0),
            ..h100_like()
        };
        let ms = pass_floor(Some(&copy), Counts::default(), &probed).unwrap();
        assert!((ms - 80.0 / 400e9 * 1e3).abs() < 1e-15, "{ms}");
        let clear = Work::Clear {
            texels: 4,
            bytes_per_texel: 4,
        };
        let why = pass_floor(Some(&clear), Counts::default(), &h100_like()).unwrap_err();
        assert!(why.contains("16 bytes"), "{why}");
        assert!(pass_floor(None, Counts::default(), &h100_like()).is_err());
    }

    fn depth_use(format: Format, write: bool) -> DepthStencilUse {
        DepthStencilUse {
            format,
            depth_test: true,
            depth_write: write,
            stencil_test: false,
            stencil_write: write,
        }
    }

    fn mesh_pass(
        shader: Option<ShaderWork>,
        color: Vec<ColorWrite>,
        ds: DepthStencilUse,
        triangles: u64,
    ) -> Work {
        Work::Raster {
            shader,
            color,
            depth_stencil: Some(ds),
            width: 2048,
            height: 2048,
            triangles,
            msaa: 1,
            clears: vec![],
        }
    }

    // The shadow map: depth only, no fragment shader; floored by the larger
    // of its triangles at the depth-only set-up rate and the samples it
    // wrote at the depth-only fill rate.
    #[test]
    fn a_depth_only_pass_is_its_triangles_or_its_depth_writes() {
        let shadow = mesh_pass(None, vec![], depth_use(Format::D32Float, true), 4_000_000);
        let counts = |samples| Counts {
            fragments: Some(0),
            compute: None,
            samples_passed: samples,
        };
        // 4 M triangles at 4 Gtri/s: 1 ms; 14 M samples at 28 Gpix/s: 0.5 ms.
        let ms = pass_floor(Some(&shadow), counts(14_000_000), &h100_like()).unwrap();
        assert!((ms - 1.0).abs() < 1e-9, "{ms}");
        // 56 M samples: 2 ms, the writes bound it.
        let ms = pass_floor(Some(&shadow), counts(56_000_000), &h100_like()).unwrap();
        assert!((ms - 2.0).abs() < 1e-9, "{ms}");
        // A depth format the probe did not write: the triangles alone.
        let d32s8 = mesh_pass(
            None,
            vec![],
            depth_use(Format::D32FloatS8Uint, true),
            4_000_000,
        );
        let ms = pass_floor(Some(&d32s8), counts(56_000_000), &h100_like()).unwrap();
        assert!((ms - 1.0).abs() < 1e-9, "{ms}");
        // Before the raster probes: no floor, and it says why.
        let old = Ceilings {
            triangles_depth_gtris: None,
            fill_depth_d32_gpix: None,
            ..h100_like()
        };
        assert!(pass_floor(Some(&shadow), counts(1), &old).is_err());
    }

    // The geometry pass: its attachments as one MRT write at their probed
    // rate, its PCF and RGBA8 fetches, its triangles at the set-up rate in
    // its state; bounds (the normal map behind a branch) left out.
    #[test]
    fn the_geometry_pass_is_its_mrt_fill_its_fetches_or_its_triangles() {
        let gbuffer: Vec<ColorWrite> = GEOMETRY_MRT
            .iter()
            .map(|&format| ColorWrite {
                format,
                blend: false,
            })
            .collect();
        let mut normal = fetch(Format::Rgba8Unorm, Filter::Bilinear, 1.0);
        normal.exact = false;
        let shader = ShaderWork {
            shader: "geometry.frag".into(),
            fetches: vec![
                fetch(Format::D32Float, Filter::DepthCompare, 9.0),
                fetch(Format::Rgba8Unorm, Filter::Bilinear, 2.0),
                normal,
            ],
            ..Default::default()
        };
        let ds = depth_use(Format::D32FloatS8Uint, true);
        let g = mesh_pass(Some(shader), gbuffer, ds, 200_000);
        let counts = Counts {
            fragments: Some(2_000_000),
            compute: None,
            samples_passed: 2_000_000,
        };
        // Fetches: 2 M x (9 / 15.5 + 2 / 31) ns = 1.290 ms; fill 2 M / 2
        // Gpix/s = 1 ms; triangles 0.2 M / 2 Gtri/s = 0.1 ms.
        let ms = pass_floor(Some(&g), counts, &h100_like()).unwrap();
        let want = 2e6 * (9.0 / 15.5e9 + 2.0 / 31e9) * 1e3;
        assert!((ms - want).abs() < 1e-9, "{ms} vs {want}");
        // Without the PCF and RGBA8 probes: the MRT fill.
        let old = Ceilings {
            pcf_d32_gtaps: None,
            bilinear_rgba8_gtaps: None,
            ..h100_like()
        };
        let ms = pass_floor(Some(&g), counts, &old).unwrap();
        assert!((ms - 1.0).abs() < 1e-9, "{ms}");
        // A fourth target (post-scatter's albedo, RGBA16F) adds its own
        // fill after the probed set's: never less than the 3-target pass.
        let mut with_albedo = GEOMETRY_MRT
            .iter()
            .map(|&format| ColorWrite {
                format,
                blend: false,
            })
            .collect::<Vec<_>>();
        with_albedo.push(ColorWrite {
            format: Format::Rgba16Float,
            blend: false,
        });
        let post = mesh_pass(g_shader_of(&g), with_albedo, ds, 200_000);
        let ms = pass_floor(Some(&post), counts, &old).unwrap();
        let single = 2e6 / (old.fill_rgba16f_gpix * 1e9) * 1e3;
        assert!(
            (ms - (1.0 + single)).abs() < 1e-9,
            "{ms} vs {}",
            1.0 + single
        );
        // 20 M triangles: 10 ms, set-up bound.
        let dense = mesh_pass(
            g_shader_of(&g),
            GEOMETRY_MRT
                .iter()
                .map(|&format| ColorWrite {
                    format,
                    blend: false,
                })
                .collect(),
            ds,
            20_000_000,
        );
        let ms = pass_floor(Some(&dense), counts, &h100_like()).unwrap();
        assert!((ms - 10.0).abs() < 1e-9, "{ms}");
    }

    fn g_shader_of(w: &Work) -> Option<ShaderWork> {
        match w {
            Work::Raster { shader, .. } => shader.clone(),
            _ => None,
        }
    }

    // Colour is written per sample that passed: an edge pass that discards
    // most fragments is floored by its fetches per invocation and its few
    // writes; at 4x MSAA the samples of a pixel are written together.
    #[test]
    fn writes_count_the_samples_that_passed() {
        let rgba8 = ColorWrite {
            format: Format::Rgba8Unorm,
            blend: false,
        };
        let edges = raster(
            vec![fetch(Format::Rgba8Unorm, Filter::Point, 3.1)],
            vec![rgba8],
        );
        let counts = Counts {
            fragments: Some(10_000_000),
            compute: None,
            samples_passed: 1_000_000,
        };
        // Fetches 31 M at 62 Gtap/s: 0.5 ms; writes 1 M at 14 Gpix/s: 0.071 ms.
        let ms = pass_floor(Some(&edges), counts, &h100_like()).unwrap();
        assert!((ms - 0.5).abs() < 1e-9, "{ms}");
        let Work::Raster {
            shader,
            color,
            depth_stencil,
            width,
            height,
            triangles,
            clears,
            ..
        } = raster(vec![], vec![RGBA16F])
        else {
            unreachable!()
        };
        let ms4 = Work::Raster {
            shader,
            color,
            depth_stencil,
            width,
            height,
            triangles,
            msaa: 4,
            clears,
        };
        let counts = Counts {
            fragments: Some(7_000_000),
            compute: None,
            samples_passed: 28_000_000,
        };
        let ms = pass_floor(Some(&ms4), counts, &h100_like()).unwrap();
        assert!((ms - 1.0).abs() < 1e-9, "{ms}");
    }

    // A compute blur: its exact fetches or the shared memory every
    // invocation moves, the larger; its stores (at skin pixels only) are
    // left out.
    #[test]
    fn a_dispatch_is_its_fetches_or_its_shared_memory() {
        let work = |shared_bytes| Work::Compute {
            shader: ShaderWork {
                shader: "separable_blur.comp".into(),
                fetches: vec![fetch(Format::R32Float, Filter::Point, 5.0)],
                storage_write_bytes: 8.0,
                shared_bytes,
                ..Default::default()
            },
            invocations: 1_000_000,
        };
        let counts = Counts {
            fragments: None,
            compute: Some(1_000_000),
            samples_passed: 0,
        };
        // Fetches: 5 M at 1000 Gtap/s = 0.005 ms; shared 60 MB at 30 TB/s = 0.002 ms.
        let ms = pass_floor(Some(&work(60.0)), counts, &h100_like()).unwrap();
        assert!((ms - 0.005).abs() < 1e-12, "{ms}");
        // 600 bytes each: 0.02 ms, the shared memory bounds it.
        let ms = pass_floor(Some(&work(600.0)), counts, &h100_like()).unwrap();
        assert!((ms - 0.02).abs() < 1e-12, "{ms}");
        // A dispatch that ran nothing has no floor, and says so.
        let none = Counts {
            compute: None,
            ..counts
        };
        assert!(pass_floor(Some(&work(60.0)), none, &h100_like())
            .unwrap_err()
            .contains("nothing"));
    }
}
