//! The calibration points: each a measured number, the profile of the GPU
//! that measured it, and the frame that stands for its scene.
//!
//! - **Published** ([`published`]): thesis 000 Table 6.2 (6 cells per method),
//!   Fig. 6.4 (3), Table 4.4 (the SSS cost of SS Full and SS Jittered at 1/3/5
//!   heads), seed 001 Table 5.2 (9) and Table 9.1 (MLAA, 2). Their frames are
//!   dermis's frames of the same scenes, rendered on lavapipe and stored in
//!   `profiles/frames/published/` (`tools/budget_frames.sh`), transformed
//!   into the implementation each source timed (`frames`).
//! - **Benchmark** ([`benchmark`]): every pass of every report of
//!   `docs/perf/h100/` (priced with the stored frame of its configuration,
//!   `frames::paired_frame`) and of every directory of new-format bench
//!   reports in [`BENCH_DIRS`] (the H200's, once committed), each on the
//!   profile of the GPU that ran it; and the H100's compute-path runs of
//!   issue 28 at the 1080p close-up ([`ISSUE28_FIT`]), with the counted
//!   fetches of their stored frames (`profiles/frames/issue28/`). The same
//!   runs at the 1080p mid shot and at 4K ([`ISSUE28_HELD_OUT`]) are in no
//!   fit: [`issue28_held_out`] scores the model on them.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

use crate::budget::frames::{
    self, frames_dir, json_files, load_frame, paired_frame, perf_dir, scale_taps, six_gaussians,
    skinless, with_counted_fetches, without_seed_copies,
};
use crate::budget::input::FrameInput;
use crate::budget::record::frame_from_record;
use crate::report;

/// Directories of new-format bench reports under `docs/perf/`: (directory,
/// profile of the GPU that ran them, a word its device name must contain).
/// A missing directory contributes nothing; a report from another device is
/// left out (named in the skipped list).
pub const BENCH_DIRS: &[(&str, &str, &str)] = &[("h200", "nvidia-h200", "H200")];

/// docs/perf/issue28/h100/'s reports that calibrate the compute path (the
/// 1080p close-up, every compute method; each report's raster passes join
/// too), paired with `profiles/frames/issue28/NAME.json`.
pub const ISSUE28_FIT: &[&str] = &[
    "1080-close-1-compute",
    "1080-close-1-ssg-compute",
    "1080-close-1-ss-jittered-compute",
    "1080-close-1-poisson-compute",
    "1080-close-1-gather-20",
    "1080-close-1-gather-40",
    "1080-close-1-gather-80",
    "1080-close-1-gather-burley-40",
];

/// The same directory's runs kept out of every fit (other shots and sizes):
/// the model's out-of-sample check.
pub const ISSUE28_HELD_OUT: &[&str] = &[
    "1080-mid-1-compute",
    "1080-mid-1-ssg-compute",
    "1080-mid-1-gather-20",
    "1080-mid-1-gather-40",
    "1080-mid-1-gather-80",
    "1080-mid-1-gather-burley-40",
    "2160-close-1-compute",
    "2160-mid-1-compute",
];

/// The set the issue-28 points are summarised in.
pub const ISSUE28_SET: &str = "H100 compute";

/// Where a point comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Group {
    Published,
    Benchmark,
}

/// Which passes of the frame a measured number covers.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Select {
    /// Every SSS pass (the papers' "subsurface scattering" time).
    Sss,
    /// Every frame-cost pass.
    Frame,
    /// One pass, by index.
    Pass(usize),
}

/// One measured number and the frame that stands for its scene.
#[derive(Clone, Debug)]
pub struct Point {
    pub id: String,
    pub source: String,
    pub group: Group,
    /// The set the point is summarised in ("published", "H100", "H200").
    pub set: String,
    pub profile: String,
    pub measured_ms: f64,
    pub frame: FrameInput,
    pub select: Select,
    /// The report file of a benchmark point (the halves split by file).
    pub file: String,
    pub note: String,
}

fn stored(name: &str) -> Result<FrameInput> {
    load_frame(&frames_dir().join("published").join(format!("{name}.json")))
}

fn published_point(
    id: String,
    source: &str,
    profile: &str,
    ms: f64,
    frame: FrameInput,
    note: &str,
) -> Point {
    Point {
        id,
        source: source.to_string(),
        group: Group::Published,
        set: "published".into(),
        profile: profile.to_string(),
        measured_ms: ms,
        frame,
        select: Select::Sss,
        file: String::new(),
        note: note.to_string(),
    }
}

/// Thesis 000 Table 6.2 and Fig. 6.4: see docs/budget-calibration.md for the
/// reading (the extracted table's headers are swapped: the first column of
/// each GPU is the close shot; the mid column is the "fixed cost" of passes
/// that shade no skin). The SSSS shader: no seed copy, no follow-surface, the
/// whole screen with a stencil.
fn thesis_ch6() -> Result<Vec<Point>> {
    let t62 = "thesis 000 Table 6.2 (headers read swapped: first column close)";
    let sep_close = without_seed_copies(&stored("t62_separable_close")?);
    let sep_mid = skinless(&without_seed_copies(&stored("t62_separable_mid")?));
    let ssg_close = stored("t62_ssg_close")?;
    let ssg_mid = skinless(&stored("t62_ssg_mid")?);
    let mut v = Vec::new();
    for (gpu, prof, cells) in [
        ("GTX 580", "geforce-gtx-580", [1.05, 0.1, 3.07, 0.71]),
        ("GTX 470", "geforce-gtx-470", [4.6, 0.13, 10.38, 0.89]),
        ("GT 130M", "geforce-gt-130m", [13.66, 0.81, 40.02, 3.94]),
    ] {
        for (what, ms, f) in [
            ("close separable", cells[0], &sep_close),
            ("mid separable", cells[1], &sep_mid),
            ("close SoG", cells[2], &ssg_close),
            ("mid SoG", cells[3], &ssg_mid),
        ] {
            let id = format!("T6.2 {gpu} {what}");
            v.push(published_point(id, t62, prof, ms, f.clone(), ""));
        }
    }
    for (n, ms) in [(9u32, 1.02), (17, 1.77), (33, 3.15)] {
        let f = without_seed_copies(&stored(&format!("f64_s{n}"))?);
        let id = format!("F6.4 GTX 470 close {n} samples");
        v.push(published_point(
            id,
            "thesis 000 Fig. 6.4",
            "geforce-gtx-470",
            ms,
            f,
            "",
        ));
    }
    Ok(v)
}

/// Table 4.4 (fps, 8600M GS, 720p, 4x MSAA): the SSS cost is the frame-time
/// difference from "No SSS" (integer fps: +-0.6 ms); seed 001 Table 5.2;
/// Table 9.1 (MLAA, first principles).
fn other_sources() -> Result<Vec<Point>> {
    let mut v = Vec::new();
    let src = "thesis 000 Table 4.4 (SSS = frame-time difference from No SSS)";
    for (heads, none, jit, full) in [
        (1u32, 51.0, 42.0, 29.0),
        (3, 41.0, 32.0, 24.0),
        (5, 40.0, 33.0, 25.0),
    ] {
        let d = |x: f64| 1000.0 / x - 1000.0 / none;
        let note = "fps to 2 digits: +-0.6 ms; dermis renders 1x, the thesis 4x MSAA";
        for (what, ms, name) in [
            ("SS Full", d(full), format!("t44_ssg_{heads}h")),
            ("SS Jittered", d(jit), format!("t44_jittered_{heads}h")),
        ] {
            let id = format!("T4.4 8600M GS {what} {heads} heads");
            v.push(published_point(
                id,
                src,
                "geforce-8600m-gs",
                ms,
                stored(&name)?,
                note,
            ));
        }
    }
    let t52 = "seed 001 Table 5.2 (GTX 970M, 1681x942, 20 samples)";
    for (shot, gs, art, pre) in [
        ("close", 9.428, 1.731, 1.799),
        ("mid", 2.01, 0.492, 0.487),
        ("far", 0.676, 0.312, 0.36),
    ] {
        // Rendered with 21 samples (20 taps); 20 samples have 19.
        let f = scale_taps(&stored(&format!("t52_{shot}"))?, 19.0 / 20.0);
        let p = "geforce-gtx-970m";
        v.push(published_point(
            format!("T5.2 970M {shot} Gaussian sum"),
            t52,
            p,
            gs,
            six_gaussians(&f),
            "12 passes: the separable pass six times",
        ));
        v.push(published_point(
            format!("T5.2 970M {shot} Artistic"),
            t52,
            p,
            art,
            f.clone(),
            "",
        ));
        v.push(published_point(
            format!("T5.2 970M {shot} Pre-int kernel"),
            t52,
            p,
            pre,
            f,
            "same shader as Artistic",
        ));
    }
    let mlaa = frames::mlaa_frame(1280, 720, 0.15, 8.0);
    let t91 = "thesis 000 Table 9.1 (grand average of 10 games)";
    let note = "first principles: 15% edge pixels, 8 search taps assumed";
    for (id, prof, ms) in [
        ("T9.1 Xbox 360 MLAA", "xbox360", 3.79),
        ("T9.1 9800 GTX+ MLAA", "geforce-9800-gtx-plus", 0.44),
    ] {
        let mut p = published_point(id.into(), t91, prof, ms, mlaa.clone(), note);
        p.select = Select::Frame;
        v.push(p);
    }
    Ok(v)
}

/// Every published point.
pub fn published() -> Result<Vec<Point>> {
    let mut v = thesis_ch6()?;
    v.extend(other_sources()?);
    Ok(v)
}

/// One point per measured frame-cost pass of `frame`.
fn pass_points(
    frame: &FrameInput,
    set: &str,
    profile: &str,
    file: &str,
    source: &str,
) -> Vec<Point> {
    frame
        .passes
        .iter()
        .enumerate()
        .filter(|(_, p)| p.role.is_frame_cost())
        .filter_map(|(i, p)| {
            let ms = p.measured_ms?;
            Some(Point {
                id: format!("{set} {file} / {}", p.name),
                source: source.to_string(),
                group: Group::Benchmark,
                set: set.to_string(),
                profile: profile.to_string(),
                measured_ms: ms,
                frame: frame.clone(),
                select: Select::Pass(i),
                file: file.to_string(),
                note: String::new(),
            })
        })
        .collect()
}

/// Every benchmark point (module docs), and the reports that could not be
/// used (file: why).
pub fn benchmark() -> Result<(Vec<Point>, Vec<String>)> {
    let mut v = Vec::new();
    let mut skipped = Vec::new();
    let h100 = "docs/perf/h100 (NVIDIA H100, medians of 100 frames)";
    for path in json_files(&perf_dir().join("h100"))? {
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        let rep = report::load(&path)?;
        let stored = frames_dir().join("h100").join(format!("{name}.json"));
        match load_frame(&stored).and_then(|f| paired_frame(&rep, &f)) {
            Ok(f) => v.extend(pass_points(&f, "H100", "nvidia-h100", &name, h100)),
            Err(e) => skipped.push(format!("h100/{name}: {e:#}")),
        }
    }
    for (dir, profile, device) in BENCH_DIRS {
        let set = dir.to_uppercase();
        let source = format!("docs/perf/{dir}");
        for path in json_files(&perf_dir().join(dir))? {
            let name = path.file_stem().unwrap_or_default().to_string_lossy();
            let stored = load_frame(&frames_dir().join("matrix").join(format!("{name}.json"))).ok();
            match new_format_frame(&path, device, stored.as_ref())
                .with_context(|| format!("{dir}/{name}"))
            {
                Ok(f) => v.extend(pass_points(&f, &set, profile, &name, &source)),
                Err(e) => skipped.push(format!("{e:#}")),
            }
        }
    }
    match issue28(ISSUE28_FIT) {
        Ok(p) => v.extend(p),
        Err(e) => skipped.push(format!("{e:#}")),
    }
    Ok((v, skipped))
}

/// A new-format report of `device` as a frame, with the counted fetches of
/// `stored` (its configuration's frame) when given.
fn new_format_frame(path: &Path, device: &str, stored: Option<&FrameInput>) -> Result<FrameInput> {
    let name = path.file_stem().unwrap_or_default().to_string_lossy();
    let r = report::load(path)?;
    if !r.run.device.device.contains(device) {
        anyhow::bail!("run on {}, not an {device}", r.run.device.device);
    }
    let frame = frame_from_record(&r, None, &name)?;
    Ok(with_counted_fetches(&frame, stored))
}

/// The points of docs/perf/issue28/h100/'s reports `names` (set
/// [`ISSUE28_SET`]), each with its stored frame's counted fetches: a report
/// without its stored frame is an error (the compute passes' fetch counts
/// are bounds until counted).
fn issue28(names: &[&str]) -> Result<Vec<Point>> {
    let source = "docs/perf/issue28/h100 (NVIDIA H100, medians of 200 frames)";
    let mut v = Vec::new();
    for name in names {
        let path = perf_dir().join("issue28/h100").join(format!("{name}.json"));
        let stored = load_frame(&frames_dir().join("issue28").join(format!("{name}.json")))
            .with_context(|| format!("issue28/h100/{name}: its stored frame"))?;
        let rep = report::load(&path)?;
        let names = |v: Vec<&str>| v.join(", ");
        let (a, b): (Vec<&str>, Vec<&str>) = (
            rep.passes.iter().map(|p| p.name.as_str()).collect(),
            stored.passes.iter().map(|p| p.name.as_str()).collect(),
        );
        if a != b {
            anyhow::bail!(
                "issue28/h100/{name}: passes differ from its stored frame's: report [{}], frame [{}]",
                names(a),
                names(b)
            );
        }
        let f = new_format_frame(&path, "H100", Some(&stored))
            .with_context(|| format!("issue28/h100/{name}"))?;
        v.extend(pass_points(&f, ISSUE28_SET, "nvidia-h100", name, source));
    }
    Ok(v)
}

/// The points of [`ISSUE28_HELD_OUT`]: in no fit, scored out of sample.
pub fn issue28_held_out() -> Result<Vec<Point>> {
    issue28(ISSUE28_HELD_OUT)
}
