//! report.json's schema, in one place: the types `run` writes for `render`
//! and `bench` ([`Report`] and what it holds), read back typed by `budget`
//! and `compare` through one loader ([`load`]); and the statistics over
//! measured frames and the printed table that fill and show them.
//!
//! Reports older than a field read it as `None` where no value would be true
//! of those runs (`role` and `work`, absent before passes declared them; the
//! SSS region, absent before regions, when the SSS passes covered the screen;
//! `layout`), and as empty where nothing was there (the method's options and
//! details, floors, ceilings, probes). Every report under docs/ loads (a test
//! reads them all).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context as _, Result};
use serde::{Deserialize, Serialize};

use crate::graph::work::{ImageUse, PassRole, Work};
use crate::graph::PassSample;
use crate::header::{DeviceHeader, RunHeader};
use crate::method::region::RegionMode;
use crate::render::request::FrameSettings;
use crate::scene::layout::Layout;
use crate::skin::transmittance::TransmittanceProfile;

/// The JSON report of `render` and `bench`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    /// Version, command line, device, driver, size and frame counts, at the
    /// top under the names reports have always used.
    #[serde(flatten)]
    pub run: RunHeader,
    /// Everything the frame was made from, whole: `dermis render --settings
    /// report.json` renders it again. Absent in reports from before issue 27.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<FrameSettings>,
    pub method: String,
    /// Every option of the method, given or default.
    #[serde(default)]
    pub method_options: BTreeMap<String, String>,
    /// What the method reports of itself (kernel, fit, stretch, samples...).
    #[serde(default)]
    pub method_details: serde_json::Value,
    pub transmittance: bool,
    pub transmittance_profile: TransmittanceProfile,
    /// `None`: a report from before SSS regions (the SSS passes covered the screen).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sss_region: Option<RegionMode>,
    /// Pixels inside the region the SSS passes worked in (the screen without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sss_region_pixels: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sss_region_rects: Option<u64>,
    /// The post chain's anti-aliasing (`--aa`, `post::AaMode::name`); `None`
    /// without one (so a `--aa none` report is the one from before the chain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aa: Option<String>,
    /// The bloom before the tone map (`--bloom`); absent without it.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub bloom: bool,
    /// MLAA's or SMAA's edge source when `--aa-edges` named one
    /// (`post::EdgeSource::name`); absent otherwise (luma).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aa_edges: Option<String>,
    /// SMAA's preset when `--smaa-preset` named one (`Preset::name`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smaa_preset: Option<String>,
    /// Samples per pixel of the geometry pass (`--msaa`) when more than one;
    /// `None` at 1x (so a 1x report is the one from before `--msaa`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub msaa: Option<u32>,
    pub scene: String,
    pub mm_per_unit: f32,
    pub heads: u32,
    /// `None`: a report from before layouts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layout: Option<Layout>,
    pub distance_heads: f32,
    pub fovy_deg: f32,
    pub light: LightReport,
    pub passes: Vec<PassReport>,
    pub frame: Option<FrameReport>,
    /// Sum of the SSS passes (every pass of role `sss`) per frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sss_total_ms: Option<Stats>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ceilings: Option<Ceilings>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probes: Option<Vec<ProbeResult>>,
    /// The method groups of the frame (issue 16): one in a single-method
    /// frame, one per distinct choice with `--assign` or `--plan`; empty in
    /// a report from before groups.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupReport>,
}

/// One method instance of a frame: its choice, its stencil code, its
/// characters and where its passes worked.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupReport {
    pub index: usize,
    /// The choice as `--assign` spells it (`method[:key=value...]`; the
    /// method's name in a single-method frame).
    pub choice: String,
    pub method: String,
    /// Every option of the method, given or default.
    #[serde(default)]
    pub options: BTreeMap<String, String>,
    /// The stencil value of its skin pixels (`mix::stencil_code`).
    pub stencil: u32,
    /// Frame indices of its characters.
    pub characters: Vec<usize>,
    /// Its SSS region: rectangles `[x0, y0, x1, y1]` (exclusive ends) and
    /// their pixels (empty for a group with no SSS in a mix).
    pub region_rects: Vec<[u32; 4]>,
    pub region_pixels: u64,
    /// Skin pixels of its characters on screen, when the run counted them
    /// (a captured frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin_pixels: Option<u64>,
    /// Its colour in `groups.png` (sRGB), when one was written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tint: Option<[u8; 3]>,
    /// Its one character's cross-fade, when it fades.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade: Option<FadeReport>,
}

/// A fading character's old setting in a group's report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FadeReport {
    /// The old setting as `--assign` spells it.
    pub from: String,
    /// Its share of the character's result.
    pub weight: f64,
    /// Where the keep is copied, the old setting works and its result is blended.
    pub region_rects: Vec<[u32; 4]>,
    pub region_pixels: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LightReport {
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    pub intensity: f32,
}

/// Reads a report (report.json of `render`, the `--report` of `bench`): the
/// one loader every reader of reports goes through.
pub fn load(path: &Path) -> Result<Report> {
    let text = crate::files::read_text(path, "report", crate::files::MAX_TEXT_FILE)?;
    let r: Report =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    r.check()
        .with_context(|| format!("report {}", path.display()))?;
    Ok(r)
}

impl Report {
    /// The ranges `render` holds its settings to, for a report whoever wrote it:
    /// the frame's sides within 1..=`MAX_IMAGE_SIDE`, at most `MAX_HEADS` heads,
    /// the field of view and the scale as `render` takes them, measured times
    /// finite and not negative.
    pub fn check(&self) -> Result<()> {
        use crate::render::settings::{check_fovy, MAX_HEADS, MAX_IMAGE_SIDE};
        for (what, v) in [("width", self.run.width), ("height", self.run.height)] {
            if !(1..=MAX_IMAGE_SIDE).contains(&v) {
                anyhow::bail!(
                    "{what} must be within 1..={MAX_IMAGE_SIDE} pixels (as render's --{what}), got {v}"
                );
            }
        }
        if self.heads > MAX_HEADS {
            anyhow::bail!("heads must be within 1..={MAX_HEADS}, got {}", self.heads);
        }
        check_fovy(self.fovy_deg)?;
        crate::scene::check_mm_per_unit(self.mm_per_unit)?;
        for p in &self.passes {
            let t = p.gpu_ms.median;
            if !(t.is_finite() && t >= 0.0) {
                anyhow::bail!(
                    "pass '{}': gpu_ms.median must be a finite number, not negative, got {t}",
                    p.name
                );
            }
        }
        Ok(())
    }
}

/// Rates measured by the ceiling probes, in giga-operations per second
/// (`bench::ceilings` measures them, `bench::floor` prices passes with them).
/// Fields added after the first reports are `Option`s: `None` in a report
/// from before their probe (or on a device without the feature).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Ceilings {
    pub bilinear_rgba16f_gtaps: f64,
    pub point_rgba16f_gtaps: f64,
    pub bilinear_r32f_gtaps: f64,
    pub point_r32f_gtaps: f64,
    pub fill_rgba16f_gpix: f64,
    /// `None`: a report from before this probe (docs/perf/h100-run1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill_rgba8_gpix: Option<f64>,
    /// RGBA16F with constant-factor blending (read-modify-write); `None` as above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend_rgba16f_gpix: Option<f64>,
    /// The compute path's rates (probe_fetch.comp, 16x16 groups): fetches
    /// as the fragment probes make them, and RGBA16F storage-image stores;
    /// `None` in reports from before they were probed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compute: Option<ComputeCeilings>,
    /// Fetches of an RGBA8 texture (the AA passes' and the geometry pass's
    /// maps), bilinear and point (issue 28).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bilinear_rgba8_gtaps: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_rgba8_gtaps: Option<f64>,
    /// Depth-compare (2x2 PCF) fetches of a D32 depth image, the geometry
    /// pass's shadow taps (probe_pcf.frag).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pcf_d32_gtaps: Option<f64>,
    /// Depth-only fill of the shadow map's D32 format (no fragment shader).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill_depth_d32_gpix: Option<f64>,
    /// Pixels a second written with the geometry pass's attachments at once
    /// (RGBA16F, RGBA16F, R32F and depth/stencil written; probe_fill_mrt.frag).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill_geometry_mrt_gpix: Option<f64>,
    /// Triangles a second that cover no sample (set-up and rasteriser alone;
    /// probe_triangles.vert), into a D32 attachment with no fragment shader
    /// (the shadow pass's state) and into the geometry pass's attachments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles_depth_gtris: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles_geometry_gtris: Option<f64>,
    /// Bytes a second of a whole-image RGBA16F copy (`vkCmdCopyImage`, as
    /// the seed copies and MLAA's copy), giga-bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub copy_gbytes: Option<f64>,
}

/// The compute path's measured rates (giga-taps or giga-stores a second).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputeCeilings {
    pub bilinear_rgba16f_gtaps: f64,
    pub point_rgba16f_gtaps: f64,
    pub bilinear_r32f_gtaps: f64,
    pub point_r32f_gtaps: f64,
    pub store_rgba16f_gpix: f64,
    /// Shared-memory reads, giga-bytes a second (probe_shared.comp: 16-byte
    /// loads, conflict-free, in 16x16 groups); `None` before issue 28.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shared_load_gbytes: Option<f64>,
    /// The median time of a dispatch of one 16x16 group (the store probe's
    /// shader) with its barriers and timestamps: what any dispatch costs
    /// before its work (ms); `None` before it was probed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dispatch_ms: Option<f64>,
}

impl Ceilings {
    /// The measured rates, for the bench printout.
    pub fn summary(&self) -> String {
        let rate = |v: Option<f64>| v.map_or("not measured".into(), |v| format!("{v:.2}"));
        let compute = self.compute.map_or(String::new(), |c| {
            format!(
                "; compute: bilinear rgba16f {:.1} Gtap/s, point rgba16f {:.1}, bilinear r32f {:.1}, point r32f {:.1}, store rgba16f {:.2} Gpix/s, shared loads {} GB/s, a one-group dispatch {} ms",
                c.bilinear_rgba16f_gtaps, c.point_rgba16f_gtaps, c.bilinear_r32f_gtaps, c.point_r32f_gtaps, c.store_rgba16f_gpix, rate(c.shared_load_gbytes), c.dispatch_ms.map_or("not measured".into(), |v| format!("{v:.4}"))
            )
        });
        format!(
            "ceilings: bilinear rgba16f {:.1} Gtap/s, point rgba16f {:.1}, bilinear r32f {:.1}, point r32f {:.1}; fill rgba16f {:.2} Gpix/s, rgba8 {}, blended rgba16f {}{compute}\n\
             raster: bilinear rgba8 {} Gtap/s, point rgba8 {}, pcf d32 {}; depth-only fill d32 {} Gpix/s, geometry MRT fill {}; triangles depth-only {} Gtri/s, geometry attachments {}; copy {} GB/s",
            self.bilinear_rgba16f_gtaps, self.point_rgba16f_gtaps, self.bilinear_r32f_gtaps, self.point_r32f_gtaps, self.fill_rgba16f_gpix, rate(self.fill_rgba8_gpix), rate(self.blend_rgba16f_gpix),
            rate(self.bilinear_rgba8_gtaps), rate(self.point_rgba8_gtaps), rate(self.pcf_d32_gtaps), rate(self.fill_depth_d32_gpix), rate(self.fill_geometry_mrt_gpix), rate(self.triangles_depth_gtris), rate(self.triangles_geometry_gtris), rate(self.copy_gbytes)
        )
    }
}

/// One ceiling probe's measurement.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProbeResult {
    pub name: String,
    pub taps_per_fragment: i32,
    pub fragments: u64,
    pub gpu_ms: Stats,
    /// Giga-taps (or giga-pixels for the fill probe) per second at the median.
    pub rate_g_per_s: f64,
}

/// Median, minimum and 95th percentile of a set of times (ms).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub median: f64,
    pub min: f64,
    pub p95: f64,
}

/// The median of sorted, non-empty `v` (the mean of the middle two when even).
pub fn median_of_sorted(v: &[f64]) -> f64 {
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

impl Stats {
    /// Nearest-rank statistics; `None` for an empty set.
    pub fn of(values: &[f64]) -> Option<Stats> {
        if values.is_empty() {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(|a, b| a.total_cmp(b));
        let n = v.len();
        let median = median_of_sorted(&v);
        let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
        Some(Stats {
            median,
            min: v[0],
            p95: v[rank - 1],
        })
    }
}

/// What a pass declares of itself, for the report.
#[derive(Clone, Debug, Default)]
pub struct PassDecl {
    pub work: Option<Work>,
    pub images: Vec<ImageUse>,
    /// The pass's method group and its characters (none for the frame's own passes).
    pub group: Option<usize>,
    pub characters: Vec<usize>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassReport {
    pub name: String,
    /// `None`: a report from before passes declared their role and work.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<PassRole>,
    pub gpu_ms: Stats,
    /// Time of the barriers before the pass, kept out of `gpu_ms`.
    pub barrier_ms: Stats,
    /// Primitives a drawing pass's input assembler read (pipeline
    /// statistics), last measured frame (`None` in reports from before they
    /// were counted, and for passes that draw nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_primitives: Option<u64>,
    /// Fragment shader invocations (pipeline statistics) of the last measured frame.
    pub fragment_invocations: Option<u64>,
    /// Compute shader invocations, last measured frame (`None` in reports
    /// from before they were counted, and for passes that dispatch nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compute_invocations: Option<u64>,
    /// Samples that passed depth and stencil tests (occlusion query), last measured frame.
    pub samples_passed: u64,
    /// Lower bound from the measured device ceilings (bench only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor_ms: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor_ratio: Option<f64>,
    /// Why a benched pass has no floor (bench only; `floor::no_floor_reason`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_floor: Option<String>,
    /// The pass's declared work per unit (see `graph::work`).
    #[serde(default)]
    pub work: Option<Work>,
    /// The images it touches and how.
    #[serde(default)]
    pub images: Vec<ImageUse>,
    /// The method group the pass belongs to (`Report::groups`) and that
    /// group's characters; `None` and empty for the frame's own passes and
    /// in a report from before groups.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<usize>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub characters: Vec<usize>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrameReport {
    /// Sum of pass and barrier times per frame.
    pub gpu_ms: Stats,
    /// CPU time of building the frame's passes and recording them into the
    /// command buffer, per measured frame (`None`: a report from before it
    /// was measured).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_record_ms: Option<Stats>,
}

/// Aggregates frames of pass samples (every frame has the same passes in
/// order), with each pass's declaration (`decls[i]` for pass `i`).
pub fn aggregate(
    frames: &[Vec<PassSample>],
    decls: &[PassDecl],
) -> (Vec<PassReport>, Option<FrameReport>) {
    let Some(first) = frames.first() else {
        return (Vec::new(), None);
    };
    let passes = first
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let gpu: Vec<f64> = frames.iter().map(|f| f[i].gpu_ms).collect();
            let bar: Vec<f64> = frames.iter().map(|f| f[i].barrier_ms).collect();
            let decl = decls.get(i).cloned().unwrap_or_default();
            // A dispatch's own count (0 included: an indirect dispatch over
            // an empty list); none for the other passes.
            let dispatch = matches!(decl.work, Some(Work::Compute { .. }));
            let decl_raster = matches!(decl.work, Some(Work::Raster { .. }));
            PassReport {
                name: s.name.clone(),
                role: Some(s.role),
                work: decl.work,
                images: decl.images,
                group: decl.group,
                characters: decl.characters,
                gpu_ms: Stats::of(&gpu).expect("non-empty"),
                barrier_ms: Stats::of(&bar).expect("non-empty"),
                input_primitives: frames
                    .last()
                    .and_then(|f| f[i].input_primitives)
                    .filter(|_| decl_raster),
                fragment_invocations: frames.last().and_then(|f| f[i].fragment_invocations),
                compute_invocations: frames
                    .last()
                    .and_then(|f| f[i].compute_invocations)
                    .filter(|_| dispatch),
                samples_passed: frames.last().map(|f| f[i].samples_passed).unwrap_or(0),
                floor_ms: None,
                floor_ratio: None,
                no_floor: None,
            }
        })
        .collect();
    let totals: Vec<f64> = frames
        .iter()
        .map(|f| f.iter().map(|s| s.gpu_ms + s.barrier_ms).sum())
        .collect();
    (
        passes,
        Stats::of(&totals).map(|gpu_ms| FrameReport {
            gpu_ms,
            cpu_record_ms: None,
        }),
    )
}

/// The per-pass table every run prints.
pub fn table(passes: &[PassReport], frame: Option<&FrameReport>) -> String {
    use std::fmt::Write;
    let has_floor = passes.iter().any(|p| p.floor_ratio.is_some());
    let mut s = String::new();
    let _ = write!(
        s,
        "{:<18} {:>10} {:>10} {:>10} {:>11} {:>14} {:>13}",
        "pass", "median ms", "min ms", "p95 ms", "barrier ms", "invocations", "samples pass"
    );
    if has_floor {
        let _ = write!(s, " {:>10} {:>9}", "floor ms", "x floor");
    }
    s.push('\n');
    for p in passes {
        // A dispatch's compute invocations (marked), else the fragments.
        let inv = match (p.compute_invocations, p.fragment_invocations) {
            (Some(c), _) => format!("{c} cs"),
            (None, Some(f)) => f.to_string(),
            (None, None) => "n/a".into(),
        };
        let _ = write!(
            s,
            "{:<18} {:>10.4} {:>10.4} {:>10.4} {:>11.4} {:>14} {:>13}",
            p.name,
            p.gpu_ms.median,
            p.gpu_ms.min,
            p.gpu_ms.p95,
            p.barrier_ms.median,
            inv,
            p.samples_passed
        );
        if has_floor {
            match (p.floor_ms, p.floor_ratio) {
                (Some(f), Some(r)) => {
                    let _ = write!(s, " {:>10.4} {:>9.2}", f, r);
                }
                _ => {
                    let _ = write!(s, " {:>10} {:>9}", "-", "-");
                }
            }
        }
        s.push('\n');
    }
    if let Some(f) = frame {
        let _ = writeln!(
            s,
            "{:<18} {:>10.4} {:>10.4} {:>10.4}",
            "frame (sum)", f.gpu_ms.median, f.gpu_ms.min, f.gpu_ms.p95
        );
        if let Some(c) = &f.cpu_record_ms {
            let _ = writeln!(
                s,
                "{:<18} {:>10.4} {:>10.4} {:>10.4}",
                "cpu recording", c.median, c.min, c.p95
            );
        }
    }
    // Every pass without a floor says why (issue 28: a floor for every pass).
    for p in passes {
        if let Some(why) = &p.no_floor {
            let _ = writeln!(s, "no floor: {}: {why}", p.name);
        }
    }
    s
}

/// The groups of a frame of several methods, one line each (nothing for a
/// single-method frame: its one group is the whole frame).
pub fn groups_table(groups: &[GroupReport]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    if groups.len() < 2 && groups.iter().all(|g| g.fade.is_none()) {
        return s;
    }
    let _ = writeln!(
        s,
        "{:<6} {:<34} {:>7} {:>10} {:>13} {:>11}",
        "group", "choice", "stencil", "characters", "region px", "skin px"
    );
    for g in groups {
        let skin = g.skin_pixels.map_or("-".to_string(), |p| p.to_string());
        let _ = writeln!(
            s,
            "{:<6} {:<34} {:>7} {:>10} {:>13} {:>11}",
            format!("#{}", g.index),
            g.choice,
            g.stencil,
            g.characters.len(),
            g.region_pixels,
            skin
        );
        if let Some(f) = &g.fade {
            let _ = writeln!(
                s,
                "{:<6} {:<34} {:>7} {:>10} {:>13} {:>11}",
                "",
                format!("  fading from {} ({:.0}%)", f.from, 100.0 * f.weight),
                "",
                "",
                f.region_pixels,
                ""
            );
        }
    }
    s
}

/// The header's device part for the device `ctx` opened.
pub fn device_header(ctx: &crate::vk::context::Context) -> DeviceHeader {
    let f = &ctx.facts;
    DeviceHeader {
        device: f.name.clone(),
        device_type: f.device_type.clone(),
        driver: f.driver.clone(),
        vulkan_api: f.api_version.clone(),
        validation: ctx.validation,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_nearest_rank() {
        let v: Vec<f64> = (1..=20).map(|i| i as f64).collect();
        let s = Stats::of(&v).unwrap();
        assert_eq!(s.min, 1.0);
        assert_eq!(s.median, 10.5);
        assert_eq!(s.p95, 19.0);
        let s = Stats::of(&[3.0, 1.0, 2.0]).unwrap();
        assert_eq!((s.min, s.median, s.p95), (1.0, 2.0, 3.0));
        assert!(Stats::of(&[]).is_none());
    }

    #[test]
    fn aggregates_frames_per_pass() {
        let f = |a: f64, b: f64| {
            vec![
                PassSample {
                    input_primitives: None,
                    name: "a".into(),
                    role: PassRole::Sss,
                    merge: false,
                    barrier_ms: 0.0,
                    gpu_ms: a,
                    fragment_invocations: Some(5),
                    compute_invocations: None,
                    samples_passed: 5,
                },
                PassSample {
                    input_primitives: None,
                    name: "b".into(),
                    role: PassRole::Post,
                    merge: false,
                    barrier_ms: 0.5,
                    gpu_ms: b,
                    fragment_invocations: None,
                    compute_invocations: None,
                    samples_passed: 0,
                },
            ]
        };
        let (p, frame) = aggregate(&[f(1.0, 2.0), f(3.0, 4.0), f(2.0, 3.0)], &[]);
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].gpu_ms.median, 2.0);
        assert_eq!(p[1].gpu_ms.min, 2.0);
        assert_eq!(p[0].fragment_invocations, Some(5));
        assert_eq!(p[1].role, Some(PassRole::Post));
        assert_eq!(frame.unwrap().gpu_ms.median, 5.5);
        let t = table(&p, None);
        assert!(t.contains("median ms") && t.lines().count() == 3);
    }

    /// Every JSON file under `dir` (recursively) that looks like a report.
    fn reports_under(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                reports_under(&p, out);
            } else if p.extension().is_some_and(|x| x == "json") {
                let v: serde_json::Value =
                    serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
                if v.get("passes").is_some() && v.get("device").is_some() {
                    out.push(p);
                }
            }
        }
    }

    // The one loader reads every report the project has kept, from the
    // oldest (no roles, no regions, no layouts, fewer probes) to today's;
    // one of today's shape written back is its file exactly (the schema's
    // names and defaults agree with the writer).
    #[test]
    fn every_kept_report_loads_and_round_trips() {
        let mut files = Vec::new();
        reports_under(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("docs"),
            &mut files,
        );
        assert!(files.len() > 300, "{} reports", files.len());
        let mut with_layout = 0;
        for f in &files {
            let r = load(f).unwrap_or_else(|e| panic!("{e:#}"));
            assert!(!r.passes.is_empty(), "{}", f.display());
            let again: Report = serde_json::from_str(&serde_json::to_string(&r).unwrap()).unwrap();
            assert_eq!(
                serde_json::to_value(&again).unwrap(),
                serde_json::to_value(&r).unwrap(),
                "{}",
                f.display()
            );
            // A report of today's shape writes back to its file (the same
            // field names and defaults as the writer; both texts read by the
            // same parser, so a float compares as the same text would).
            if r.layout.is_some() {
                with_layout += 1;
                let text = |s: &str| serde_json::from_str::<serde_json::Value>(s).unwrap();
                let back = text(&serde_json::to_string(&r).unwrap());
                assert!(
                    back == text(&std::fs::read_to_string(f).unwrap()),
                    "{}",
                    f.display()
                );
            }
        }
        // Old and new files both: the defaults were exercised.
        assert!(with_layout > 0 && with_layout < files.len());
        let e = load(Path::new("/nonexistent/report.json")).unwrap_err();
        assert!(format!("{e:#}").contains("report not found: /nonexistent/report.json"));
    }
}
