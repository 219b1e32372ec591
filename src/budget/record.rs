//! A run's report as the model reads it (`report::Report`, the schema of
//! `dermis render`/`bench`, live or loaded by `report::load`) and the
//! [`FrameInput`] built from it: each pass's role, declared work and images, its counts and its
//! measured time, with two rules stated here and written into the frame's
//! provenance:
//!
//! - **Fragments shaded** ([`FRAGMENTS_RULE`]). Drivers count fragment-shader
//!   invocations differently: NVIDIA after the early tests (the count is what
//!   ran), llvmpipe (lavapipe) for whole rasterised blocks before them (up to
//!   1.4x what ran). So on NVIDIA the model takes the invocation count; on any
//!   other driver, for a pass that writes depth (the geometry pass) the samples
//!   that passed the depth test (what an early-Z GPU shades: a fragment hidden
//!   by one drawn earlier is not shaded, one hidden by one drawn later is, as
//!   on the GPU), and for every other pass with a shader the invocations the
//!   fetch-counting build counted in `main` (exact: helper invocations count
//!   nothing; equal to the samples passed on stencil-masked passes, and right
//!   where a shader discards), or the samples passed when there was no
//!   counting run.
//! - **Fetches** ([`apply_counts`]): with a counting run, every declared
//!   fetch's count becomes what its shader really fetched per invocation
//!   (fetches at its binding and filter / invocations), so a declared upper
//!   bound (Poisson's 32 taps, the geometry pass's branches) is replaced by
//!   the average the frame really took.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::budget::input::{FrameInput, PassInput};
use crate::graph::work::{Filter, PassRole, ShaderWork, Work};
use crate::report::{PassReport, Report};

/// The fragments rule (module docs), for reports.
pub const FRAGMENTS_RULE: &str = "fragments shaded = the pipeline-statistics invocation count on \
NVIDIA (it counts after the early tests); on other drivers (llvmpipe counts rasterised blocks \
before them) the samples that passed the depth test for a pass that writes depth (what an \
early-Z GPU shades), and for other passes with a shader the invocations the fetch-counting \
build counted in main (the samples passed when there was no counting run)";

/// How the driver of the run `r` counts fragment invocations.
pub fn counting(r: &Report) -> FragmentCounting {
    FragmentCounting::of(&r.run.device.device, &r.run.device.driver)
}

/// When a driver's pipeline statistics count fragment-shader invocations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FragmentCounting {
    /// After the early depth/stencil tests: what ran (NVIDIA).
    AfterEarlyTests,
    /// Before them, for whole rasterised blocks (llvmpipe), or not known.
    BeforeEarlyTests,
}

impl FragmentCounting {
    pub fn of(device: &str, driver: &str) -> FragmentCounting {
        let nvidia = |s: &str| s.to_ascii_lowercase().contains("nvidia");
        if nvidia(device) || nvidia(driver) {
            FragmentCounting::AfterEarlyTests
        } else {
            FragmentCounting::BeforeEarlyTests
        }
    }
}

/// What the fetch-counting build counted in one pass, by texture variable.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CountedPass {
    pub name: String,
    /// Shader invocations that reached `main`.
    pub invocations: u64,
    /// (texture variable, filter, fetches made).
    pub fetches: Vec<(String, Filter, u64)>,
}

/// Replaces every declared fetch count of `s` with what was fetched per
/// invocation (declared fetches sharing a texture and filter share its count
/// in proportion to their declared counts). `false` (nothing changed) when the
/// pass ran no invocation.
pub fn apply_counts(s: &mut ShaderWork, c: &CountedPass) -> bool {
    if c.invocations == 0 {
        return false;
    }
    let declared: Vec<f64> = s
        .fetches
        .iter()
        .map(|f| {
            s.fetches
                .iter()
                .filter(|g| g.texture == f.texture && g.filter == f.filter)
                .map(|g| g.count)
                .sum()
        })
        .collect();
    for (f, total_declared) in s.fetches.iter_mut().zip(declared) {
        let made: u64 = c
            .fetches
            .iter()
            .filter(|(t, filter, _)| *t == f.texture && *filter == f.filter)
            .map(|x| x.2)
            .sum();
        let share = if total_declared > 0.0 {
            f.count / total_declared
        } else {
            1.0
        };
        f.count = made as f64 / c.invocations as f64 * share;
        f.exact = true;
    }
    true
}

/// Shaded fragments of one pass (module docs).
fn fragments(
    p: &PassReport,
    work: &Work,
    counting: FragmentCounting,
    counted: Option<&CountedPass>,
) -> u64 {
    let Work::Raster {
        shader: Some(_),
        depth_stencil,
        msaa,
        ..
    } = work
    else {
        return match work {
            Work::Compute { invocations, .. } => *invocations,
            _ => 0,
        };
    };
    let passed = p.samples_passed / u64::from((*msaa).max(1));
    if counting == FragmentCounting::AfterEarlyTests {
        return p.fragment_invocations.unwrap_or(passed);
    }
    if depth_stencil.is_some_and(|d| d.depth_write) {
        return passed;
    }
    counted.map_or(passed, |c| c.invocations)
}

/// Pixels a pass's triangles cover before its early tests, for passes that
/// test without writing depth (the stencil-masked SSS passes, the
/// stencil-culled AA passes): for an SSS pass, the SSS region's pixels when it
/// draws one triangle per rectangle of the region; else its whole render
/// area. Only SSS passes draw the region: a post pass's one full-screen
/// triangle beside a one-rectangle region is the whole screen (it was taken
/// for the region once, and the Xbox 360's MLAA resolves priced at a fifth).
/// `None` for passes that reject nothing early.
fn rasterized(rec: &Report, role: PassRole, work: &Work) -> Option<u64> {
    let Work::Raster {
        depth_stencil: Some(ds),
        width,
        height,
        triangles,
        ..
    } = work
    else {
        return None;
    };
    if ds.depth_write || !(ds.depth_test || ds.stencil_test) {
        return None;
    }
    let area = u64::from(*width) * u64::from(*height);
    match (role, rec.sss_region_pixels, rec.sss_region_rects) {
        (PassRole::Sss, Some(px), Some(rects)) if rects == *triangles => Some(px),
        _ => Some(area),
    }
}

/// The frame of a run: every pass with its declaration and counts, fetch
/// counts from `counted` (one per pass, in order) when given.
pub fn frame_from_record(
    rec: &Report,
    counted: Option<&[CountedPass]>,
    label: &str,
) -> Result<FrameInput> {
    if let Some(c) = counted {
        if c.len() != rec.passes.len() {
            bail!(
                "the counting run has {} passes, the run {}",
                c.len(),
                rec.passes.len()
            );
        }
    }
    let counting = counting(rec);
    let mut passes = Vec::new();
    let mut any_counted = false;
    for (i, p) in rec.passes.iter().enumerate() {
        let (Some(role), Some(work)) = (p.role, p.work.clone()) else {
            bail!(
                "pass `{}` declares no role or work (a report from before passes declared them)",
                p.name
            );
        };
        let c = counted.map(|c| &c[i]);
        let mut work = work;
        if let (Work::Compute { invocations, .. }, Some(n)) = (&mut work, p.compute_invocations) {
            // An indirect dispatch is declared at its bound (the region's
            // tiles): the run's pipeline statistics say how many it ran.
            *invocations = n;
        }
        let mut q = PassInput::new(&p.name, role, work);
        q.fragments = fragments(p, &q.work, counting, c);
        q.samples_passed = p.samples_passed;
        q.rasterized_pixels = rasterized(rec, role, &q.work);
        q.images = p.images.clone();
        q.measured_ms = Some(p.gpu_ms.median);
        if let Some(c) = c {
            let shader = match &mut q.work {
                Work::Raster {
                    shader: Some(s), ..
                } => Some(s),
                Work::Compute { shader, .. } => Some(shader),
                _ => None,
            };
            if let Some(s) = shader {
                q.fetches_counted = apply_counts(s, c);
                any_counted |= q.fetches_counted;
            }
        }
        passes.push(q);
    }
    let mut provenance = vec![format!(
        "run on {} ({}); fragments: {}",
        rec.run.device.device,
        rec.run.device.driver,
        match counting {
            FragmentCounting::AfterEarlyTests => "invocation counts (this driver counts after the early tests)",
            FragmentCounting::BeforeEarlyTests =>
                "samples passed for depth-writing passes, the counting build's invocations for the others (this driver counts before the early tests)",
        }
    )];
    provenance.push(if any_counted {
        "fetches: counted by the fetch-counting build (fetches made / invocations, per pass)".into()
    } else {
        "fetches: as declared (upper bounds where a shader branches)".into()
    });
    let multisampled = passes
        .iter()
        .any(|p| matches!(p.work, Work::Raster { msaa, .. } if msaa > 1));
    if multisampled && counting == FragmentCounting::BeforeEarlyTests {
        provenance.push(
            "msaa: this driver's counts give no partly covered pixel (fragments are the samples \
             passed / samples per pixel), so MSAA compression is priced as if no triangle edge \
             crossed a pixel: a lower bound (budget::msaa)"
                .into(),
        );
    }
    Ok(FrameInput {
        label: label.to_string(),
        width: rec.run.width,
        height: rec.run.height,
        passes,
        provenance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::{DepthStencilUse, Fetch, Format, PassRole};
    use crate::report::Stats;

    fn shader(taps: f64) -> ShaderWork {
        let f = |texture: &str, filter, count| Fetch {
            texture: texture.into(),
            format: Format::Rgba16Float,
            filter,
            count,
            exact: false,
            coherent: true,
            spread: Vec::new(),
        };
        ShaderWork {
            shader: "poisson.frag".into(),
            fetches: vec![
                f("colorChain", Filter::Point, 1.0),
                f("colorChain", Filter::Bilinear, taps),
            ],
            ..Default::default()
        }
    }

    #[test]
    fn counted_fetches_replace_declared_bounds() {
        let mut s = shader(32.0);
        let c = CountedPass {
            name: "poisson".into(),
            invocations: 1000,
            fetches: vec![
                ("colorChain".into(), Filter::Point, 1000),
                ("colorChain".into(), Filter::Bilinear, 12_000),
            ],
        };
        assert!(apply_counts(&mut s, &c));
        assert_eq!(s.fetches[0].count, 1.0);
        assert_eq!(s.fetches[1].count, 12.0);
        assert!(s.fetches.iter().all(|f| f.exact));
        // A pass that shaded nothing keeps its declaration.
        let mut t = shader(32.0);
        assert!(!apply_counts(&mut t, &CountedPass::default()));
        assert_eq!(t.fetches[1].count, 32.0);
    }

    fn record(device: &str) -> Report {
        let ds = |write| DepthStencilUse {
            format: Format::D32FloatS8Uint,
            depth_test: true,
            depth_write: write,
            stencil_test: !write,
            stencil_write: write,
        };
        let raster = |write, triangles| Work::Raster {
            shader: Some(shader(8.0)),
            color: vec![],
            depth_stencil: Some(ds(write)),
            width: 100,
            height: 50,
            triangles,
            msaa: 1,
            clears: vec![],
        };
        let stats = Stats {
            median: 0.5,
            min: 0.5,
            p95: 0.5,
        };
        let pass = |name: &str, role, work| PassReport {
            input_primitives: None,
            name: name.into(),
            role: Some(role),
            gpu_ms: stats,
            barrier_ms: stats,
            fragment_invocations: Some(4000),
            compute_invocations: None,
            samples_passed: 3000,
            floor_ms: None,
            floor_ratio: None,
            no_floor: None,
            work: Some(work),
            images: vec![],
            group: None,
            characters: vec![],
        };
        // What every report holds (an old one's fields default), then the passes.
        let mut r: Report = serde_json::from_value(serde_json::json!({
            "dermis_version": "0", "command": "", "device": device, "device_type": "",
            "driver": "", "vulkan_api": "", "validation": false, "width": 100,
            "height": 50, "method": "poisson", "transmittance": true,
            "transmittance_profile": "thesis", "scene": "", "mm_per_unit": 1.0,
            "heads": 1, "distance_heads": 1.0, "fovy_deg": 20.0,
            "light": { "azimuth_deg": 0.0, "elevation_deg": 0.0, "intensity": 1.0 },
            "warmup_frames": 0, "measured_frames": 1, "passes": [], "frame": null,
            "sss_region_pixels": 2000, "sss_region_rects": 3,
        }))
        .unwrap();
        r.passes = vec![
            pass("geometry", PassRole::Geometry, raster(true, 5000)),
            pass("poisson", PassRole::Sss, raster(false, 3)),
        ];
        r
    }

    #[test]
    fn an_indirect_dispatch_is_priced_at_what_it_ran() {
        let mut r = record("llvmpipe");
        let dispatch = |compute_invocations| PassReport {
            work: Some(Work::Compute {
                shader: ShaderWork::default(),
                // The declared bound: every tile of the region's box.
                invocations: 100 * 256,
            }),
            compute_invocations,
            fragment_invocations: Some(0),
            ..r.passes[1].clone()
        };
        r.passes = vec![dispatch(Some(7 * 256)), dispatch(Some(0)), dispatch(None)];
        let f = frame_from_record(&r, None, "t").unwrap();
        let ran: Vec<u64> = f
            .passes
            .iter()
            .map(|p| match p.work {
                Work::Compute { invocations, .. } => invocations,
                _ => panic!(),
            })
            .collect();
        // Counted: what ran (none, for an empty list); not counted: the bound.
        assert_eq!(ran, [7 * 256, 0, 100 * 256]);
        assert_eq!(f.passes[0].fragments, 7 * 256);
    }

    #[test]
    fn fragments_follow_the_driver_rule() {
        let counted = [
            CountedPass {
                name: "geometry".into(),
                invocations: 4500,
                fetches: vec![],
            },
            CountedPass {
                name: "poisson".into(),
                invocations: 1500,
                fetches: vec![("colorChain".into(), Filter::Bilinear, 15_000)],
            },
        ];
        let nv = frame_from_record(&record("NVIDIA H200"), Some(&counted), "t").unwrap();
        assert_eq!(nv.passes[0].fragments, 4000);
        assert_eq!(nv.passes[1].fragments, 4000);
        let lp = frame_from_record(&record("llvmpipe (LLVM 15)"), Some(&counted), "t").unwrap();
        // Depth-writing pass: samples passed; others: the counting build's invocations.
        assert_eq!(lp.passes[0].fragments, 3000);
        assert_eq!(lp.passes[1].fragments, 1500);
        let bare = frame_from_record(&record("llvmpipe"), None, "t").unwrap();
        assert_eq!(bare.passes[1].fragments, 3000);
        // The stencil pass covers the region (3 rectangles = its 3 triangles).
        assert_eq!(lp.passes[1].rasterized_pixels, Some(2000));
        assert_eq!(lp.passes[0].rasterized_pixels, None);
        assert!(lp.passes[1].fetches_counted);
        let Work::Raster {
            shader: Some(s), ..
        } = &lp.passes[1].work
        else {
            panic!()
        };
        assert_eq!(s.fetches[1].count, 10.0);
        assert_eq!(lp.passes[1].measured_ms, Some(0.5));
        assert!(lp.provenance[1].contains("counted"));
    }

    #[test]
    fn a_post_pass_beside_a_one_rectangle_region_covers_the_screen() {
        let mut r = record("llvmpipe");
        r.sss_region_rects = Some(1);
        let one_triangle = |w: &mut Work| {
            if let Work::Raster { triangles, .. } = w {
                *triangles = 1;
            }
        };
        one_triangle(r.passes[1].work.as_mut().unwrap());
        let mut post = r.passes[1].clone();
        post.name = "mlaa weights".into();
        post.role = Some(PassRole::Post);
        r.passes.push(post);
        let f = frame_from_record(&r, None, "t").unwrap();
        // The SSS pass draws the region's one rectangle; MLAA's full-screen
        // triangle covers the 100 x 50 screen.
        assert_eq!(f.passes[1].rasterized_pixels, Some(2000));
        assert_eq!(f.passes[2].rasterized_pixels, Some(5000));
    }

    #[test]
    fn old_reports_without_declarations_are_refused() {
        let mut r = record("NVIDIA H100");
        r.passes[0].work = None;
        let e = frame_from_record(&r, None, "t").unwrap_err().to_string();
        assert!(
            e.contains("geometry") && e.contains("no role or work"),
            "{e}"
        );
    }
}
