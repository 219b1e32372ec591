//! Per-pass statistics over measured frames, the printed table and the JSON report.

use serde::Serialize;

use crate::graph::work::{ImageUse, PassRole, Work};
use crate::graph::PassSample;

/// Median, minimum and 95th percentile of a set of times (ms).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
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
}

#[derive(Clone, Debug, Serialize)]
pub struct PassReport {
    pub name: String,
    pub role: PassRole,
    pub gpu_ms: Stats,
    /// Time of the barriers before the pass, kept out of `gpu_ms`.
    pub barrier_ms: Stats,
    /// Fragment shader invocations (pipeline statistics) of the last measured frame.
    pub fragment_invocations: Option<u64>,
    /// Samples that passed depth and stencil tests (occlusion query), last measured frame.
    pub samples_passed: u64,
    /// Lower bound from the measured device ceilings (bench only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor_ms: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor_ratio: Option<f64>,
    /// The pass's declared work per unit (see `graph::work`).
    pub work: Option<Work>,
    /// The images it touches and how.
    pub images: Vec<ImageUse>,
}

#[derive(Clone, Debug, Serialize)]
pub struct FrameReport {
    /// Sum of pass and barrier times per frame.
    pub gpu_ms: Stats,
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
            PassReport {
                name: s.name.clone(),
                role: s.role,
                work: decl.work,
                images: decl.images,
                gpu_ms: Stats::of(&gpu).expect("non-empty"),
                barrier_ms: Stats::of(&bar).expect("non-empty"),
                fragment_invocations: frames.last().and_then(|f| f[i].fragment_invocations),
                samples_passed: frames.last().map(|f| f[i].samples_passed).unwrap_or(0),
                floor_ms: None,
                floor_ratio: None,
            }
        })
        .collect();
    let totals: Vec<f64> = frames
        .iter()
        .map(|f| f.iter().map(|s| s.gpu_ms + s.barrier_ms).sum())
        .collect();
    (
        passes,
        Stats::of(&totals).map(|gpu_ms| FrameReport { gpu_ms }),
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
        "pass", "median ms", "min ms", "p95 ms", "barrier ms", "frag invocs", "samples pass"
    );
    if has_floor {
        let _ = write!(s, " {:>10} {:>9}", "floor ms", "x floor");
    }
    s.push('\n');
    for p in passes {
        let inv = p
            .fragment_invocations
            .map(|v| v.to_string())
            .unwrap_or_else(|| "n/a".into());
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
    }
    s
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
                    name: "a".into(),
                    role: PassRole::Sss,
                    barrier_ms: 0.0,
                    gpu_ms: a,
                    fragment_invocations: Some(5),
                    samples_passed: 5,
                },
                PassSample {
                    name: "b".into(),
                    role: PassRole::Post,
                    barrier_ms: 0.5,
                    gpu_ms: b,
                    fragment_invocations: None,
                    samples_passed: 0,
                },
            ]
        };
        let (p, frame) = aggregate(&[f(1.0, 2.0), f(3.0, 4.0), f(2.0, 3.0)], &[]);
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].gpu_ms.median, 2.0);
        assert_eq!(p[1].gpu_ms.min, 2.0);
        assert_eq!(p[0].fragment_invocations, Some(5));
        assert_eq!(p[1].role, PassRole::Post);
        assert_eq!(frame.unwrap().gpu_ms.median, 5.5);
        let t = table(&p, None);
        assert!(t.contains("median ms") && t.lines().count() == 3);
    }
}
