//! Calibration: the points of `points` priced once on their profiles, the fit
//! of [`ModelParams`] and its held-out scores.
//!
//! Fit: least squares of `ln(modelled / measured)`, by Nelder-Mead over the
//! logarithms of the parameters (each kept within [`LO`], [`HI`]), one set per
//! rate source. The probed profiles' set is fitted whole on the benchmark
//! points (hundreds of passes). The peak-rate profiles' set is fitted on the
//! published points (32 frames), which say nothing of hierarchical-Z
//! rejection, incoherent taps or copy rectangles (their implementations have
//! none, or one kind each): those three structural parameters are taken from
//! the probed fit and only the efficiency scales, the rejection scale and the
//! fixed cost per pass ([`PEAK_FREE`]) are fitted on the published points,
//! from several starts ([`fit_peak`]: that objective has more than one minimum).
//! A weak prior ([`PRIOR_WEIGHT`]) holds each free parameter near its start
//! (scales 1: the rates are reached) where the points do not determine it.
//!
//! Held out: each published point is scored leave-one-out (fitted on the other
//! published points: they are few); the benchmark reports are split in two
//! halves (alternate report files per GPU, a report's passes together) and the
//! second half is scored with parameters fitted on the first.

use anyhow::{Context, Result};
use serde::Serialize;

use crate::budget::params::{ModelParams, ParamSet, N_PARAMS};
use crate::budget::points::{benchmark, published, Group, Point, Select};
use crate::budget::profile::{Profile, RateSource};
use crate::budget::transfers::price_units;
use crate::budget::units::UnitTimes;
use crate::graph::work::PassRole;

/// A point priced once: the unit times of its selected passes.
#[derive(Clone, Debug)]
pub struct Priced {
    pub point: Point,
    pub rates: RateSource,
    pub units: Vec<UnitTimes>,
    /// Passes the profile could not price (the point is then not scored).
    pub unpriced: Vec<String>,
}

impl Priced {
    pub fn predict(&self, p: &ModelParams) -> f64 {
        self.units.iter().map(|u| u.combine(p)).sum()
    }

    fn usable(&self) -> bool {
        self.unpriced.is_empty() && self.point.measured_ms > 0.0
    }
}

/// Prices a point's frame on its profile.
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
        rates: prof.profile.rates,
        point,
    }
}

/// Every point priced on its profile, and the benchmark reports left out.
pub fn priced_points() -> Result<(Vec<Priced>, Vec<String>)> {
    let (bench, skipped) = benchmark()?;
    let mut cache: Vec<Profile> = Vec::new();
    let mut out = Vec::new();
    for p in published()?.into_iter().chain(bench) {
        let prof = match cache.iter().find(|c| c.profile.name == p.profile) {
            Some(c) => c.clone(),
            None => {
                let c = Profile::load(&p.profile).with_context(|| format!("point {}", p.id))?;
                cache.push(c.clone());
                c
            }
        };
        out.push(price_point(p, &prof));
    }
    Ok((out, skipped))
}

/// Lower and upper bounds of the parameters (in `ModelParams::to_vec` order).
pub const LO: [f64; N_PARAMS] = [
    0.1, 0.1, 0.1, 0.1, 0.01, 0.001, 0.1, 0.01, 0.01, 0.1, 0.01, 0.1, 0.1, 0.1,
];
pub const HI: [f64; N_PARAMS] = [
    10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 1000.0, 1000.0, 100.0, 1000.0, 10.0, 10.0, 100.0,
];
/// Where every fit starts.
const START: ModelParams = ModelParams {
    texture_scale: 1.0,
    alu_scale: 1.0,
    fill_scale: 1.0,
    memory_scale: 1.0,
    reject_scale: 1.0,
    hiz_reject_scale: 0.25,
    incoherent_factor: 1.0,
    fixed_kpix_per_pass: 20.0,
    rect_kpix: 5.0,
    incoherent_radius_px: 2.0,
    fixed_kpix_per_dispatch: 20.0,
    compute_alu_scale: 1.0,
    compute_incoherent_factor: 1.0,
    // Where the term can bind: the separable blur's staged bytes at the
    // H100's probed rate are a 26th of its time, so from 1 the objective is
    // flat in it and the descent never moves it.
    shared_scale: 16.0,
};

/// Which parameters the peak-rate fit frees (`ModelParams::to_vec` order):
/// all but `hiz_reject_scale`, `incoherent_factor`, `rect_kpix`,
/// `incoherent_radius_px` and the four of dispatches (no published point
/// times a dispatch: the H100's are taken).
pub const PEAK_FREE: [bool; N_PARAMS] = [
    true, true, true, true, true, false, false, true, false, false, false, false, false, false,
];
const ALL_FREE: [bool; N_PARAMS] = [true; N_PARAMS];

/// The start of the peak-rate fit: the structural parameters of `probed`.
fn peak_start(probed: &ModelParams) -> ModelParams {
    ModelParams {
        hiz_reject_scale: probed.hiz_reject_scale,
        incoherent_factor: probed.incoherent_factor,
        rect_kpix: probed.rect_kpix,
        incoherent_radius_px: probed.incoherent_radius_px,
        fixed_kpix_per_dispatch: probed.fixed_kpix_per_dispatch,
        compute_alu_scale: probed.compute_alu_scale,
        compute_incoherent_factor: probed.compute_incoherent_factor,
        shared_scale: probed.shared_scale,
        ..START
    }
}

/// Weight of the prior: a free parameter a factor e from its start costs
/// as much as this many points missed by a factor e. Weak against hundreds
/// of benchmark points, it holds the parameters 32 published points do not
/// determine near their start instead of letting them run to a bound.
pub const PRIOR_WEIGHT: f64 = 0.1;

/// What a fit minimises: the squared log errors summed, plus the prior on
/// the free parameters.
pub fn objective(
    points: &[&Priced],
    p: &ModelParams,
    start: &ModelParams,
    free: &[bool; N_PARAMS],
) -> f64 {
    let (v, s0) = (p.to_vec(), start.to_vec());
    let prior: f64 = (0..N_PARAMS)
        .filter(|&i| free[i])
        .map(|i| (v[i] / s0[i]).ln().powi(2))
        .sum();
    loss(points, p) * points.len() as f64 + PRIOR_WEIGHT * prior
}

/// Mean squared log error.
pub fn loss(points: &[&Priced], p: &ModelParams) -> f64 {
    let mut sum = 0.0;
    let mut n = 0usize;
    for q in points {
        let pred = q.predict(p);
        if pred <= 0.0 {
            continue;
        }
        let e = (pred / q.point.measured_ms).ln();
        sum += e * e;
        n += 1;
    }
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

fn from_log(x: &[f64; N_PARAMS]) -> ModelParams {
    let mut v = [0.0; N_PARAMS];
    for i in 0..N_PARAMS {
        v[i] = x[i].exp().clamp(LO[i], HI[i]);
    }
    ModelParams::from_vec(v)
}

/// Every parameter fitted from [`START`] (module docs).
pub fn fit(points: &[&Priced]) -> ModelParams {
    fit_from(points, START, ALL_FREE)
}

/// Nelder-Mead on the logarithms of the `free` parameters from `start`
/// (the others kept), restarted from its best point until it stops
/// improving. Points that cannot be priced are left out.
pub fn fit_from(points: &[&Priced], start: ModelParams, free: [bool; N_PARAMS]) -> ModelParams {
    local_fit(points, start, start, free).0
}

/// The peak-rate fit: [`fit_from`] `start`, and again from `start` with each
/// free parameter halved and doubled (the prior still centred on `start`),
/// keeping the lowest objective. 32 points trade the fill scale, the memory
/// scale and the fixed cost against each other, and the objective has more
/// than one minimum: one descent from `start` can stop in the worse one
/// (it did once the Xbox 360's ALU became vector issue: 5.67 against 5.12).
pub fn fit_peak(points: &[&Priced], start: ModelParams) -> ModelParams {
    let free: Vec<usize> = (0..N_PARAMS).filter(|&i| PEAK_FREE[i]).collect();
    let mut froms = vec![start];
    for &i in &free {
        for f in [0.5, 2.0] {
            let mut v = start.to_vec();
            v[i] = (v[i] * f).clamp(LO[i], HI[i]);
            froms.push(ModelParams::from_vec(v));
        }
    }
    froms
        .into_iter()
        .map(|from| local_fit(points, start, from, PEAK_FREE))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(start, |best| best.0)
}

/// Nelder-Mead from `from` on the objective with its prior centred on
/// `start`; returns the parameters and their objective.
fn local_fit(
    points: &[&Priced],
    start: ModelParams,
    from: ModelParams,
    free: [bool; N_PARAMS],
) -> (ModelParams, f64) {
    let usable: Vec<&Priced> = points.iter().copied().filter(|q| q.usable()).collect();
    let x0 = start.to_vec().map(f64::ln);
    let y0 = from.to_vec().map(f64::ln);
    let idx: Vec<usize> = (0..N_PARAMS).filter(|&i| free[i]).collect();
    let full = |y: &[f64; N_PARAMS]| {
        let mut x = x0;
        for (k, &i) in idx.iter().enumerate() {
            x[i] = y[k];
        }
        x
    };
    let f = |y: &[f64; N_PARAMS]| objective(&usable, &from_log(&full(y)), &start, &free);
    let mut best = [0.0; N_PARAMS];
    for (k, &i) in idx.iter().enumerate() {
        best[k] = y0[i];
    }
    let mut best_f = f(&best);
    for _ in 0..6 {
        let (y, fy) = nelder_mead(&f, best, idx.len(), 0.7, 4000);
        let improved = fy < best_f - 1e-10;
        if fy < best_f {
            best = y;
            best_f = fy;
        }
        if !improved {
            break;
        }
    }
    (from_log(&full(&best)), best_f)
}

type Vertex = ([f64; N_PARAMS], f64);

/// Nelder-Mead over the first `n` coordinates of `x0` (the rest stay 0).
fn nelder_mead(
    f: &dyn Fn(&[f64; N_PARAMS]) -> f64,
    x0: [f64; N_PARAMS],
    n: usize,
    step: f64,
    iters: usize,
) -> Vertex {
    let mut s: Vec<Vertex> = Vec::with_capacity(n + 1);
    s.push((x0, f(&x0)));
    for i in 0..n {
        let mut x = x0;
        x[i] += step;
        s.push((x, f(&x)));
    }
    let comb = |a: &[f64; N_PARAMS], b: &[f64; N_PARAMS], t: f64| {
        let mut r = [0.0; N_PARAMS];
        for i in 0..n {
            r[i] = a[i] + t * (b[i] - a[i]);
        }
        r
    };
    for _ in 0..iters {
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (s[n].1 - s[0].1).abs() < 1e-12 {
            break;
        }
        let mut c = [0.0; N_PARAMS];
        for (x, _) in &s[..n] {
            for i in 0..n {
                c[i] += x[i] / n as f64;
            }
        }
        let worst = s[n].0;
        let r = comb(&c, &worst, -1.0);
        let fr = f(&r);
        if fr < s[0].1 {
            let e = comb(&c, &worst, -2.0);
            let fe = f(&e);
            s[n] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < s[n - 1].1 {
            s[n] = (r, fr);
        } else {
            let k = comb(&c, &worst, 0.5);
            let fk = f(&k);
            if fk < s[n].1 {
                s[n] = (k, fk);
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
    s[0]
}

/// One scored point.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub id: String,
    pub source: String,
    pub group: Group,
    pub set: String,
    pub profile: String,
    pub measured_ms: f64,
    /// Predicted with parameters fitted without this point.
    pub held_out_ms: Option<f64>,
    /// Predicted with the parameters fitted on everything.
    pub fitted_ms: Option<f64>,
    /// |held_out / measured - 1|.
    pub held_out_error: Option<f64>,
    pub note: String,
}

/// Median and worst of a set of errors.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    pub set: String,
    pub points: usize,
    pub median: f64,
    pub worst: f64,
}

pub fn summarize(set: &str, errors: &[f64]) -> Summary {
    let mut e = errors.to_vec();
    e.sort_by(f64::total_cmp);
    let n = e.len();
    if n == 0 {
        return Summary {
            set: set.into(),
            ..Summary::default()
        };
    }
    let median = crate::report::median_of_sorted(&e);
    Summary {
        set: set.into(),
        points: n,
        median,
        worst: e[n - 1],
    }
}

/// The calibration table.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    /// Fitted on every point (what [`ParamSet::fitted`] holds).
    pub fitted_all: ParamSet,
    /// The probed set fitted on the first benchmark half.
    pub fitted_half: ModelParams,
    pub rows: Vec<Row>,
    pub summaries: Vec<Summary>,
}

/// Fits both parameter sets on every point (module docs).
pub fn fit_all(points: &[Priced]) -> ParamSet {
    let of = |r: RateSource| -> Vec<&Priced> { points.iter().filter(|p| p.rates == r).collect() };
    let probed = fit(&of(RateSource::Probed));
    ParamSet {
        peak: fit_peak(&of(RateSource::Peak), peak_start(&probed)),
        probed,
    }
}

/// Whether a benchmark point is in the held-out half: the odd report files of
/// its set, in file order.
fn held_out_half(points: &[Priced]) -> Vec<bool> {
    let mut files: Vec<(&str, &str)> = points
        .iter()
        .filter(|p| p.point.group == Group::Benchmark)
        .map(|p| (p.point.set.as_str(), p.point.file.as_str()))
        .collect();
    files.sort();
    files.dedup();
    points
        .iter()
        .map(|p| {
            p.point.group == Group::Benchmark && {
                let same: Vec<&&str> = files
                    .iter()
                    .filter(|f| f.0 == p.point.set)
                    .map(|f| &f.1)
                    .collect();
                same.iter()
                    .position(|f| **f == p.point.file)
                    .is_some_and(|i| i % 2 == 1)
            }
        })
        .collect()
}

/// Runs the whole protocol (module docs).
pub fn calibrate(points: &[Priced]) -> Calibration {
    let test = held_out_half(points);
    let train: Vec<&Priced> = points
        .iter()
        .zip(&test)
        .filter(|(p, t)| p.rates == RateSource::Probed && !**t)
        .map(|(p, _)| p)
        .collect();
    let half = fit(&train);
    let all = fit_all(points);
    let mut rows = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let held = if !p.usable() {
            None
        } else if p.point.group == Group::Benchmark {
            test[i].then(|| p.predict(&half))
        } else {
            let others: Vec<&Priced> = points
                .iter()
                .enumerate()
                .filter(|(j, q)| *j != i && q.rates == p.rates && q.point.group == Group::Published)
                .map(|(_, q)| q)
                .collect();
            let params = match p.rates {
                RateSource::Peak => fit_peak(&others, peak_start(&all.probed)),
                RateSource::Probed => fit(&others),
            };
            Some(p.predict(&params))
        };
        rows.push(Row {
            id: p.point.id.clone(),
            source: p.point.source.clone(),
            group: p.point.group,
            set: p.point.set.clone(),
            profile: p.point.profile.clone(),
            measured_ms: p.point.measured_ms,
            held_out_ms: held,
            fitted_ms: p.usable().then(|| p.predict(all.get(p.rates))),
            held_out_error: held.map(|h| (h / p.point.measured_ms - 1.0).abs()),
            note: if p.unpriced.is_empty() {
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
    let mut sets: Vec<String> = rows
        .iter()
        .filter(|r| r.group == Group::Benchmark)
        .map(|r| r.set.clone())
        .collect();
    sets.dedup();
    let mut summaries = vec![summarize(
        "published (leave-one-out)",
        &errs(&|r| r.group == Group::Published),
    )];
    for s in &sets {
        summaries.push(summarize(
            &format!("benchmark {s} (second half)"),
            &errs(&|r| r.group == Group::Benchmark && &r.set == s),
        ));
        summaries.push(summarize(
            &format!("benchmark {s}, 1080p passes"),
            &errs(&|r| r.group == Group::Benchmark && &r.set == s && is_1080p(&r.id)),
        ));
    }
    summaries.push(summarize("all held-out points", &errs(&|_| true)));
    Calibration {
        fitted_all: all,
        fitted_half: half,
        rows,
        summaries,
    }
}

fn is_1080p(id: &str) -> bool {
    id.contains("1920x1080") || id.contains("1080p") || id.contains(" 1080-")
}

/// The tables as Markdown (docs/budget-calibration.md): the published rows
/// (every benchmark row too with `benchmark_rows`) and the summaries.
pub fn markdown(c: &Calibration, benchmark_rows: bool) -> String {
    let mut s = String::new();
    s.push_str("| point | profile | measured ms | held-out ms | error | fitted-all ms | note |\n");
    s.push_str("|---|---|---|---|---|---|---|\n");
    let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for r in &c.rows {
        if r.group == Group::Benchmark && !benchmark_rows {
            continue;
        }
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
    s.push_str("\n| set | points | median error | worst |\n|---|---|---|---|\n");
    for m in &c.summaries {
        s.push_str(&format!(
            "| {} | {} | {:.0}% | {:.0}% |\n",
            m.set,
            m.points,
            m.median * 100.0,
            m.worst * 100.0
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_constants_match_the_fit() {
        let (pts, _) = priced_points().unwrap();
        let fitted = fit_all(&pts);
        for r in [RateSource::Peak, RateSource::Probed] {
            let refs: Vec<&Priced> = pts.iter().filter(|p| p.rates == r && p.usable()).collect();
            let (start, free) = match r {
                RateSource::Peak => (peak_start(&fitted.probed), PEAK_FREE),
                RateSource::Probed => (START, ALL_FREE),
            };
            let of = |p: &ModelParams| objective(&refs, p, &start, &free);
            let (a, b) = (of(ParamSet::fitted().get(r)), of(fitted.get(r)));
            assert!(
                a <= b * 1.01 + 1e-9,
                "FITTED ({r:?}) is stale: loss {a} vs {b} at {:?}",
                fitted.get(r)
            );
        }
    }

    // The multi-start fit keeps the best of its descents, the plain one
    // among them: never worse than it on the published points.
    #[test]
    fn the_peak_fit_is_no_worse_than_one_descent() {
        let (pts, _) = priced_points().unwrap();
        let probed = ParamSet::fitted().probed;
        let refs: Vec<&Priced> = pts
            .iter()
            .filter(|p| p.rates == RateSource::Peak && p.usable())
            .collect();
        let start = peak_start(&probed);
        let of = |p: &ModelParams| objective(&refs, p, &start, &PEAK_FREE);
        let (multi, one) = (fit_peak(&refs, start), fit_from(&refs, start, PEAK_FREE));
        assert!(
            of(&multi) <= of(&one) + 1e-9,
            "{} > {}",
            of(&multi),
            of(&one)
        );
    }

    #[test]
    fn summaries() {
        let s = summarize("t", &[0.3, 0.1, 0.2, 0.5]);
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
            // 2.0 before the H100's depth-only rate halved (13.97 -> 6.75 G/s): the same time.
            reject_scale: 0.97,
            hiz_reject_scale: 0.2,
            incoherent_factor: 1.0,
            fixed_kpix_per_pass: 30.0,
            rect_kpix: 4.0,
            incoherent_radius_px: 2.0,
            ..START
        };
        let (all, _) = priced_points().unwrap();
        let mut pts: Vec<Priced> = all
            .into_iter()
            .filter(|p| p.point.group == Group::Benchmark && p.point.set == "H100")
            .filter(|p| p.point.file.starts_with("separable_1920") && p.usable())
            .collect();
        for p in &mut pts {
            p.point.measured_ms = p.predict(&truth);
        }
        let got = fit(&pts.iter().collect::<Vec<_>>());
        let l = loss(&pts.iter().collect::<Vec<_>>(), &got);
        assert!(l < 1e-4, "loss {l}: {got:?}");
    }

    #[test]
    fn every_point_is_priced() {
        let (pts, skipped) = priced_points().unwrap();
        assert!(skipped.is_empty(), "{skipped:?}");
        let published = pts
            .iter()
            .filter(|p| p.point.group == Group::Published)
            .count();
        assert_eq!(published, 12 + 3 + 6 + 9 + 2);
        assert!(pts.len() > 800, "{}", pts.len());
        for p in &pts {
            assert!(p.unpriced.is_empty(), "{}: {:?}", p.point.id, p.unpriced);
            assert!(p.predict(&ModelParams::PEAK) > 0.0, "{}", p.point.id);
        }
    }
}
