//! Calibration: the published timings as data, the frames that stand for
//! their scenes, the fit of [`ModelParams`] and its held-out scores.
//!
//! Fit: least squares of `ln(modelled / measured)` over the points, the
//! published ones and the benchmark ones weighted as two equal groups, by
//! Nelder-Mead over the logarithms of the seven parameters (each kept in
//! [0.1, 10], the fixed cost in [0.01, 1000] kpix). Held out: the benchmark
//! reports are split in two halves (alternate files, a run's passes together);
//! the second half is scored with parameters fitted on the first half and all
//! published points; each published point is scored leave-one-out (fitted on
//! the other published points and the first benchmark half).
//!
//! Table 6.2 as extracted has its headers swapped (see [`published`]).

use anyhow::{Context, Result};
use serde::Serialize;

use crate::budget::frames::{self, perf_dir, Rebuild, Region};
use crate::budget::input::FrameInput;
use crate::budget::model::{price_units, ModelParams, UnitTimes};
use crate::budget::profile::Profile;
use crate::graph::work::PassRole;

/// The parameters fitted on every point (`fit_all`), kept here so that
/// pricing needs no fit; `fitted_constants_match_the_fit` checks them.
pub const FITTED: ModelParams = ModelParams {
    texture_scale: 1.2003,
    alu_scale: 0.9423,
    fill_scale: 1.1549,
    memory_scale: 0.6779,
    reject_scale: 1.0949,
    incoherent_factor: 1.1296,
    fixed_kpix_per_pass: 24.203,
};

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
    pub profile: String,
    pub measured_ms: f64,
    pub frame: FrameInput,
    pub select: Select,
    /// Whether the point is used to fit (every point is scored).
    pub fit: bool,
    pub note: String,
}

/// A point priced once: the unit times of its selected passes.
#[derive(Clone, Debug)]
pub struct Priced {
    pub point: Point,
    pub units: Vec<UnitTimes>,
    /// Passes the profile could not price (the point is then not scored).
    pub unpriced: Vec<String>,
}

impl Priced {
    pub fn predict(&self, p: &ModelParams) -> f64 {
        self.units.iter().map(|u| u.combine(p)).sum()
    }
}

fn load(prof_cache: &mut Vec<Profile>, name: &str) -> Result<Profile> {
    if let Some(p) = prof_cache.iter().find(|p| p.profile.name == name) {
        return Ok(p.clone());
    }
    let p = Profile::load(name)?;
    prof_cache.push(p.clone());
    Ok(p)
}

/// Prices a point's frame on its profile (the hook for real frames: build
/// [`Point`]s with frames from dermis runs of the same scenes).
pub fn price_point(point: Point, prof: &Profile) -> Priced {
    let all = price_units(prof, &point.frame);
    let picked: Vec<_> = match &point.select {
        Select::Sss => all
            .into_iter()
            .filter(|u| u.role == PassRole::Sss)
            .collect(),
        Select::Frame => all.into_iter().filter(|u| u.role.is_frame_cost()).collect(),
        Select::Pass(i) => all.into_iter().skip(*i).take(1).collect(),
    };
    let unpriced = picked
        .iter()
        .filter(|u| !u.unpriced.is_empty())
        .map(|u| format!("{}: {}", u.name, u.unpriced.join(", ")))
        .collect();
    Priced {
        units: picked.iter().map(|u| u.units).collect(),
        unpriced,
        point,
    }
}

fn report(rel: &str, rb: Rebuild) -> Result<FrameInput> {
    Ok(frames::frame_from_report(&perf_dir().join(rel), rb)?.frame)
}

fn pt(
    id: &str,
    source: &str,
    profile: &str,
    ms: f64,
    frame: FrameInput,
    select: Select,
    note: &str,
) -> Point {
    Point {
        id: id.to_string(),
        source: source.to_string(),
        group: Group::Published,
        profile: profile.to_string(),
        measured_ms: ms,
        frame,
        select,
        fit: true,
        note: note.to_string(),
    }
}

/// The published points, transcribed.
///
/// - Thesis 000 Table 6.2 (ms, 1080p, 17 samples): extracted as
///   `GTX580 mid/close: Ours 1.05 0.1, SoG 3.07 0.71; GTX470: 4.6 0.13,
///   10.38 0.89; GT130M: 13.66 0.81, 40.02 3.94`. Read against the text ("in
///   close views ... the cost is around a millisecond"; "fixed costs ... only a
///   0.1 ms overhead, compared with the 0.71 ms" of the screen-space
///   technique; ch. 6 intro: 1.06 vs 3.07 ms on a GTX 580), the first column
///   of each GPU is the close shot and the second the mid shot: the headers are
///   swapped. The GTX 470 close-up of "Ours" (4.6 ms) disagrees with Fig. 6.4
///   (1.77 ms, 17 samples, 1080p close-up, GTX 470): both are kept and scored;
///   docs/budget-calibration.md says which the model sides with.
/// - Fig. 6.4: 1.02 / 1.77 / 3.15 ms for 9 / 17 / 33 samples, GTX 470, 1080p.
/// - Table 4.4 (fps, 8600M GS, 720p, 4x MSAA, 1/3/5 heads): No SSS 51/41/40,
///   SS Jittered 42/32/33, SS Full 29/24/25. The SSS cost is the frame-time
///   difference (1000/fps(SSS) - 1000/fps(No SSS)).
/// - Seed 001 Table 5.2 (ms, GTX 970M, 1681x942, 20 samples): Close 9.428 /
///   1.731 / 1.799, Mid 2.01 / 0.492 / 0.487, Far 0.676 / 0.312 / 0.36 for
///   Gaussian sum / Artistic / Pre-int kernel.
/// - Thesis 000 Table 9.1 (MLAA, 720p, grand average): Xbox 360 3.79 ms,
///   GeForce 9800 GTX+ 0.44 ms.
///
/// Scenes: the thesis' close and mid shots are dermis's 1080p close-up (head =
/// screen height, 32% skin) and mid shot (17%), its SSSS shader without
/// follow-surface (its default) and, like every implementation of that era,
/// full-screen passes with a stencil and whole-image copies; Table 4.4's shots
/// are dermis's 720p "near" runs; seed 001's close/mid/far are dermis's 1080p
/// close, mid and far shots rescaled to 1681x942, with follow-surface (its
/// shader fetches depth per tap) and 20 samples.
pub fn published() -> Result<Vec<Point>> {
    let t62 = "thesis 000 Table 6.2 (headers read swapped: first column close)";
    let screen = |follow: Option<bool>, samples: Option<u32>| Rebuild {
        region: Region::Screen,
        samples,
        follow_surface: follow,
        ..Rebuild::default()
    };
    // The thesis' separable shader (SSSS): no seed copy, no follow-surface.
    let ssss = Rebuild {
        no_seed_copy: true,
        ..screen(Some(false), None)
    };
    let skinless = |rb: Rebuild| Rebuild {
        skinless: true,
        ..rb
    };
    // Close: "the head almost fills the screen" (text) = dermis's 1080p near shot.
    let sep_close = report("h100/separable_1920x1080_near_1h.json", ssss)?;
    let ssg_close = report("h100/ssg_lod_1920x1080_near_1h.json", screen(None, None))?;
    // Mid: the column equals the text's "fixed costs (scenes with no visible
    // scattering)": 0.1 and 0.71 ms on the GTX 580, so no skin is shaded.
    let sep_mid = report("h100/sep_1080p_mid_s17.json", skinless(ssss))?;
    let ssg_mid = report(
        "h100/nofollow/ssg_1080p_mid.json",
        skinless(screen(None, None)),
    )?;
    let mut v = Vec::new();
    for (gpu, prof, sc, sm, gc, gm) in [
        ("GTX 580", "geforce-gtx-580", 1.05, 0.1, 3.07, 0.71),
        ("GTX 470", "geforce-gtx-470", 4.6, 0.13, 10.38, 0.89),
        ("GT 130M", "geforce-gt-130m", 13.66, 0.81, 40.02, 3.94),
    ] {
        v.push(pt(
            &format!("T6.2 {gpu} close separable"),
            t62,
            prof,
            sc,
            sep_close.clone(),
            Select::Sss,
            "",
        ));
        v.push(pt(
            &format!("T6.2 {gpu} mid separable"),
            t62,
            prof,
            sm,
            sep_mid.clone(),
            Select::Sss,
            "",
        ));
        v.push(pt(
            &format!("T6.2 {gpu} close SoG"),
            t62,
            prof,
            gc,
            ssg_close.clone(),
            Select::Sss,
            "",
        ));
        v.push(pt(
            &format!("T6.2 {gpu} mid SoG"),
            t62,
            prof,
            gm,
            ssg_mid.clone(),
            Select::Sss,
            "",
        ));
    }
    for (n, ms) in [(9u32, 1.02), (17, 1.77), (33, 3.15)] {
        let f = report(&format!("h100/sep_1080p_close_s{n}.json"), ssss)?;
        v.push(pt(
            &format!("F6.4 GTX 470 close {n} samples"),
            "thesis 000 Fig. 6.4",
            "geforce-gtx-470",
            ms,
            f,
            Select::Sss,
            "",
        ));
    }
    let fps = [
        (1u32, 51.0, 42.0, 29.0),
        (3, 41.0, 32.0, 24.0),
        (5, 40.0, 33.0, 25.0),
    ];
    for (heads, none, jit, full) in fps {
        let d = |x: f64| 1000.0 / x - 1000.0 / none;
        let ssg = report(
            &format!("h100/ssg_lod_1280x720_near_{heads}h.json"),
            screen(None, None),
        )?;
        let jf = report(
            &format!("h100/jittered_1280x720_near_{heads}h.json"),
            screen(None, None),
        )?;
        let src = "thesis 000 Table 4.4 (SSS = frame-time difference from No SSS)";
        v.push(pt(
            &format!("T4.4 8600M GS SS Full {heads} heads"),
            src,
            "geforce-8600m-gs",
            d(full),
            ssg,
            Select::Sss,
            "fps to 2 digits: +-0.6 ms",
        ));
        v.push(pt(
            &format!("T4.4 8600M GS SS Jittered {heads} heads"),
            src,
            "geforce-8600m-gs",
            d(jit),
            jf,
            Select::Sss,
            "fps to 2 digits: +-0.6 ms",
        ));
    }
    let t52 = "seed 001 Table 5.2 (GTX 970M, 1681x942, 20 samples)";
    for (shot, rel, gs, art, pre) in [
        (
            "close",
            "h100/sep_1080p_close_s17.json",
            9.428,
            1.731,
            1.799,
        ),
        ("mid", "h100/sep_1080p_mid_s17.json", 2.01, 0.492, 0.487),
        (
            "far",
            "h100/separable_1920x1080_far_1h.json",
            0.676,
            0.312,
            0.36,
        ),
    ] {
        let f = report(rel, screen(Some(true), Some(20)))?.rescaled(1681, 942);
        let g = frames::six_gaussian_frame(&f, 20);
        let p = "geforce-gtx-970m";
        v.push(pt(
            &format!("T5.2 970M {shot} Gaussian sum"),
            t52,
            p,
            gs,
            g,
            Select::Sss,
            "12 passes built from first principles",
        ));
        v.push(pt(
            &format!("T5.2 970M {shot} Artistic"),
            t52,
            p,
            art,
            f.clone(),
            Select::Sss,
            "",
        ));
        v.push(pt(
            &format!("T5.2 970M {shot} Pre-int kernel"),
            t52,
            p,
            pre,
            f,
            Select::Sss,
            "same shader as Artistic",
        ));
    }
    let mlaa = frames::mlaa_frame(1280, 720, 0.15, 8.0);
    let t91 = "thesis 000 Table 9.1 (grand average of 10 games)";
    v.push(pt(
        "T9.1 Xbox 360 MLAA",
        t91,
        "xbox360",
        3.79,
        mlaa.clone(),
        Select::Frame,
        "first principles: 15% edge pixels, 8 search taps assumed",
    ));
    v.push(pt(
        "T9.1 9800 GTX+ MLAA",
        t91,
        "geforce-9800-gtx-plus",
        0.44,
        mlaa,
        Select::Frame,
        "first principles: 15% edge pixels, 8 search taps assumed",
    ));
    Ok(v)
}

/// Every pass of every H100 report (top level of `docs/perf/h100/`), one
/// point each; the Poisson pass is scored but not fitted (its taps per pixel
/// are assumed, see `frames::POISSON_TAPS_ASSUMED`).
pub fn benchmark() -> Result<Vec<Point>> {
    let mut v = Vec::new();
    for f in frames::h100_frames()? {
        for (i, p) in f.frame.passes.iter().enumerate() {
            let Some(ms) = p.measured_ms else { continue };
            v.push(Point {
                id: format!("{} / {}", f.file, p.name),
                source: "docs/perf/h100 (NVIDIA H100, medians of 100 frames)".into(),
                group: Group::Benchmark,
                profile: "nvidia-h100".into(),
                measured_ms: ms,
                frame: f.frame.clone(),
                select: Select::Pass(i),
                fit: p.name != "poisson",
                note: if p.name == "poisson" {
                    "taps per pixel assumed (32)".into()
                } else {
                    String::new()
                },
            });
        }
    }
    Ok(v)
}

/// Every point priced on its profile.
pub fn priced_points() -> Result<Vec<Priced>> {
    let mut cache = Vec::new();
    let mut out = Vec::new();
    for p in published()?.into_iter().chain(benchmark()?) {
        let prof = load(&mut cache, &p.profile).with_context(|| format!("point {}", p.id))?;
        out.push(price_point(p, &prof));
    }
    Ok(out)
}

const LO: [f64; 7] = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.01];
const HI: [f64; 7] = [10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 1000.0];

/// Mean squared log error, the two groups weighted equally.
pub fn loss(points: &[&Priced], p: &ModelParams) -> f64 {
    let mut sums = [0.0f64; 2];
    let mut counts = [0usize; 2];
    for q in points {
        let pred = q.predict(p);
        if pred <= 0.0 {
            continue;
        }
        let g = (q.point.group == Group::Benchmark) as usize;
        let e = (pred / q.point.measured_ms).ln();
        sums[g] += e * e;
        counts[g] += 1;
    }
    (0..2)
        .filter(|&g| counts[g] > 0)
        .map(|g| sums[g] / counts[g] as f64)
        .sum()
}

fn from_log(x: &[f64; 7]) -> ModelParams {
    let mut v = [0.0; 7];
    for i in 0..7 {
        v[i] = x[i].exp().clamp(LO[i], HI[i]);
    }
    ModelParams::from_vec(v)
}

/// Nelder-Mead on the log-parameters, restarted from its best point until it
/// stops improving.
pub fn fit(points: &[&Priced]) -> ModelParams {
    let usable: Vec<&Priced> = points
        .iter()
        .copied()
        .filter(|q| q.point.fit && q.unpriced.is_empty())
        .collect();
    let f = |x: &[f64; 7]| loss(&usable, &from_log(x));
    let mut best = [0.0f64; 7]; // all parameters 1
    let mut best_f = f(&best);
    for _ in 0..6 {
        let (x, fx) = nelder_mead(&f, best, 0.7, 3000);
        let improved = fx < best_f - 1e-10;
        if fx < best_f {
            best = x;
            best_f = fx;
        }
        if !improved {
            break;
        }
    }
    from_log(&best)
}

fn nelder_mead(
    f: &dyn Fn(&[f64; 7]) -> f64,
    x0: [f64; 7],
    step: f64,
    iters: usize,
) -> ([f64; 7], f64) {
    const N: usize = 7;
    let mut s: Vec<([f64; N], f64)> = Vec::with_capacity(N + 1);
    s.push((x0, f(&x0)));
    for i in 0..N {
        let mut x = x0;
        x[i] += step;
        s.push((x, f(&x)));
    }
    let comb = |a: &[f64; N], b: &[f64; N], t: f64| {
        let mut r = [0.0; N];
        for i in 0..N {
            r[i] = a[i] + t * (b[i] - a[i]);
        }
        r
    };
    for _ in 0..iters {
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (s[N].1 - s[0].1).abs() < 1e-12 {
            break;
        }
        let mut c = [0.0; N];
        for (x, _) in &s[..N] {
            for i in 0..N {
                c[i] += x[i] / N as f64;
            }
        }
        let worst = s[N].0;
        let r = comb(&c, &worst, -1.0);
        let fr = f(&r);
        if fr < s[0].1 {
            let e = comb(&c, &worst, -2.0);
            let fe = f(&e);
            s[N] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < s[N - 1].1 {
            s[N] = (r, fr);
        } else {
            let k = comb(&c, &worst, 0.5);
            let fk = f(&k);
            if fk < s[N].1 {
                s[N] = (k, fk);
            } else {
                let b = s[0].0;
                for item in s.iter_mut().skip(1) {
                    let x = comb(&b, &item.0, 0.5);
                    *item = (x, f(&x));
                }
            }
        }
    }
    s.sort_by(|a, b| a.1.total_cmp(&b.1));
    (s[0].0, s[0].1)
}

/// One scored point.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub id: String,
    pub source: String,
    pub group: Group,
    pub profile: String,
    pub measured_ms: f64,
    /// Predicted with parameters fitted without this point.
    pub held_out_ms: Option<f64>,
    /// Predicted with the parameters fitted on everything.
    pub fitted_ms: Option<f64>,
    /// |held_out / measured - 1|.
    pub held_out_error: Option<f64>,
    pub in_fit: bool,
    pub note: String,
}

/// Median and worst of a set of errors.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    pub points: usize,
    pub median: f64,
    pub worst: f64,
}

pub fn summarize(errors: &[f64]) -> Summary {
    let mut e = errors.to_vec();
    e.sort_by(f64::total_cmp);
    let n = e.len();
    if n == 0 {
        return Summary::default();
    }
    let median = if n % 2 == 1 {
        e[n / 2]
    } else {
        0.5 * (e[n / 2 - 1] + e[n / 2])
    };
    Summary {
        points: n,
        median,
        worst: e[n - 1],
    }
}

/// The calibration table.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    pub fitted_all: ModelParams,
    pub fitted_half: ModelParams,
    pub rows: Vec<Row>,
    pub published: Summary,
    pub benchmark: Summary,
    /// The 1080p benchmark passes (the 20% target).
    pub benchmark_1080p: Summary,
    pub all: Summary,
}

/// Fits on everything.
pub fn fit_all(points: &[Priced]) -> ModelParams {
    fit(&points.iter().collect::<Vec<_>>())
}

/// Runs the whole protocol (module docs).
pub fn calibrate(points: &[Priced]) -> Calibration {
    // Benchmark halves: alternate report files.
    let mut files: Vec<&str> = points
        .iter()
        .filter(|p| p.point.group == Group::Benchmark)
        .map(|p| p.point.frame.label.as_str())
        .collect();
    files.dedup();
    let test_half = |p: &Priced| {
        p.point.group == Group::Benchmark
            && files
                .iter()
                .position(|f| *f == p.point.frame.label)
                .is_some_and(|i| i % 2 == 1)
    };
    let train: Vec<&Priced> = points.iter().filter(|p| !test_half(p)).collect();
    let half = fit(&train);
    let all = fit_all(points);
    let mut rows = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let priced = p.unpriced.is_empty();
        let held = if !priced {
            None
        } else if p.point.group == Group::Benchmark {
            if test_half(p) {
                Some(p.predict(&half))
            } else {
                None
            }
        } else {
            let others: Vec<&Priced> = points
                .iter()
                .enumerate()
                .filter(|(j, q)| *j != i && !test_half(q))
                .map(|(_, q)| q)
                .collect();
            Some(p.predict(&fit(&others)))
        };
        rows.push(Row {
            id: p.point.id.clone(),
            source: p.point.source.clone(),
            group: p.point.group,
            profile: p.point.profile.clone(),
            measured_ms: p.point.measured_ms,
            held_out_ms: held,
            fitted_ms: priced.then(|| p.predict(&all)),
            held_out_error: held.map(|h| (h / p.point.measured_ms - 1.0).abs()),
            in_fit: p.point.fit,
            note: if priced {
                p.point.note.clone()
            } else {
                format!("unpriced: {}", p.unpriced.join("; "))
            },
        });
    }
    let errs = |f: &dyn Fn(&Row) -> bool| -> Vec<f64> {
        rows.iter()
            .filter(|r| f(r))
            .filter_map(|r| r.held_out_error)
            .collect()
    };
    Calibration {
        fitted_all: all,
        fitted_half: half,
        published: summarize(&errs(&|r| r.group == Group::Published)),
        benchmark: summarize(&errs(&|r| r.group == Group::Benchmark)),
        benchmark_1080p: summarize(&errs(&|r| {
            r.group == Group::Benchmark && r.id.contains("1080")
        })),
        all: summarize(&errs(&|_| true)),
        rows,
    }
}

/// The table as Markdown (docs/budget-calibration.md).
pub fn markdown(c: &Calibration, benchmark_rows: bool) -> String {
    let mut s = String::new();
    s.push_str("| point | profile | measured ms | held-out ms | error | fitted-all ms | note |\n|---|---|---|---|---|---|---|\n");
    for r in &c.rows {
        if r.group == Group::Benchmark && !benchmark_rows {
            continue;
        }
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
        s.push_str(&format!(
            "| {} | {} | {:.3} | {} | {} | {} | {} |\n",
            r.id,
            r.profile,
            r.measured_ms,
            f(r.held_out_ms),
            r.held_out_error
                .map_or("-".into(), |e| format!("{:.0}%", e * 100.0)),
            f(r.fitted_ms),
            r.note
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_constants_match_the_fit() {
        let pts = priced_points().unwrap();
        let refs: Vec<&Priced> = pts
            .iter()
            .filter(|p| p.point.fit && p.unpriced.is_empty())
            .collect();
        let fitted = fit_all(&pts);
        let (a, b) = (loss(&refs, &FITTED), loss(&refs, &fitted));
        assert!(
            a <= b * 1.01 + 1e-9,
            "FITTED is stale: loss {a} vs {b} at {fitted:?}"
        );
    }

    #[test]
    fn summaries() {
        let s = summarize(&[0.3, 0.1, 0.2, 0.5]);
        assert_eq!((s.points, s.median, s.worst), (4, 0.25, 0.5));
    }

    #[test]
    fn fit_recovers_known_parameters() {
        // Points priced at known parameters are fitted back to them.
        let truth = ModelParams {
            texture_scale: 1.3,
            alu_scale: 1.0,
            fill_scale: 1.1,
            memory_scale: 1.0,
            reject_scale: 2.0,
            incoherent_factor: 1.0,
            fixed_kpix_per_pass: 30.0,
        };
        let mut pts: Vec<Priced> = priced_points()
            .unwrap()
            .into_iter()
            .filter(|p| {
                p.point.group == Group::Benchmark
                    && p.point.fit
                    && p.point.id.contains("separable_1920")
            })
            .collect();
        for p in &mut pts {
            p.point.measured_ms = p.predict(&truth);
        }
        let got = fit(&pts.iter().collect::<Vec<_>>());
        let l = loss(&pts.iter().collect::<Vec<_>>(), &got);
        assert!(l < 1e-4, "loss {l}: {got:?}");
    }

    #[test]
    fn published_points_are_priced() {
        let pts = priced_points().unwrap();
        let published: Vec<_> = pts
            .iter()
            .filter(|p| p.point.group == Group::Published)
            .collect();
        assert_eq!(published.len(), 12 + 3 + 6 + 9 + 2);
        for p in &published {
            assert!(p.unpriced.is_empty(), "{}: {:?}", p.point.id, p.unpriced);
            assert!(p.predict(&ModelParams::PEAK) > 0.0, "{}", p.point.id);
        }
    }

    /// Prints the calibration table: `cargo test --release --lib budget::calibration -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn print_calibration() {
        let pts = priced_points().unwrap();
        let c = calibrate(&pts);
        println!("{}", markdown(&c, std::env::var_os("ALL_ROWS").is_some()));
        println!("fitted (all points): {:?}", c.fitted_all);
        println!("fitted (train half): {:?}", c.fitted_half);
        println!(
            "published {:?}\nbenchmark {:?}\nbenchmark 1080p {:?}\nall {:?}",
            c.published, c.benchmark, c.benchmark_1080p, c.all
        );
        let worst: Vec<_> = {
            let mut r: Vec<_> = c
                .rows
                .iter()
                .filter(|r| r.group == Group::Benchmark && r.held_out_error.is_some())
                .collect();
            r.sort_by(|a, b| {
                b.held_out_error
                    .unwrap()
                    .total_cmp(&a.held_out_error.unwrap())
            });
            r.into_iter().take(25).collect()
        };
        for r in worst {
            println!(
                "{} {:.4} {:.4} {:.0}%",
                r.id,
                r.measured_ms,
                r.held_out_ms.unwrap(),
                r.held_out_error.unwrap() * 100.0
            );
        }
    }
}
