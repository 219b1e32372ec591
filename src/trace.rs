//! A run's measured frames as a timeline in the Chrome trace-event format
//! (the "Trace Event Format" document; JSON object form), which Perfetto
//! (ui.perfetto.dev) and chrome://tracing open: `--trace FILE.json` of
//! `render` and `bench`.
//!
//! - One process (pid 1) named by an `M` (metadata) `process_name` event
//!   for the method and device; two threads named by `thread_name` (and
//!   ordered by `thread_sort_index`): tid 1, the GPU's timeline, and tid 2,
//!   one slice per measured frame.
//! - Every slice is an `X` (complete) event: `ts` its start and `dur` its
//!   length, both in microseconds, as the format requires. On the GPU track
//!   each pass is two slices, back to back, as the profiler's three
//!   timestamps split it: its barriers (`cat` "barrier", named "barriers
//!   before PASS"), then the pass itself (`cat` "pass", args: role, counts).
//!   The report keeps barrier time out of the pass times (STYLE habit 2);
//!   the trace shows it as its own slices for the same reason.
//! - Times come from the GPU timestamps (durations, scaled by the device's
//!   timestamp period). Within a frame the slices are contiguous because the
//!   timestamps are: a pass's end and the next pass's start are written back
//!   to back. Frames are laid end to end from 0: the time between two
//!   submissions is the CPU's (waiting on the fence, reading queries back),
//!   not the frame's, and the profiler does not measure it.
//!
//! So each pass's slices sum, over the frames, to what the report's
//! statistics were taken over: their median is the report's `gpu_ms.median`
//! (a test checks it on a real run, tests/trace.rs).

use std::path::Path;

use anyhow::Result;
use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::graph::PassSample;
use crate::output::write_json;
use crate::report::Report;

/// The process every event belongs to.
pub const PID: u32 = 1;
/// The GPU's track: barriers and passes.
pub const GPU_TID: u32 = 1;
/// One slice per measured frame.
pub const FRAME_TID: u32 = 2;

/// One event of the trace (the fields the format names; `dur` only on
/// complete events).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Event {
    pub name: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub cat: String,
    /// `X`: complete event; `M`: metadata.
    pub ph: String,
    /// Start, in microseconds.
    pub ts: f64,
    /// Length in microseconds (complete events).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dur: Option<f64>,
    pub pid: u32,
    pub tid: u32,
    #[serde(default)]
    pub args: serde_json::Value,
}

/// A trace file in the format's JSON object form.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Trace {
    #[serde(rename = "traceEvents")]
    pub trace_events: Vec<Event>,
    #[serde(rename = "displayTimeUnit")]
    pub display_time_unit: String,
    /// Shown as the trace's metadata: what ran, where, and how the timeline
    /// is laid out.
    #[serde(rename = "otherData")]
    pub other_data: serde_json::Value,
}

fn metadata(name: &str, tid: u32, args: serde_json::Value) -> Event {
    Event {
        name: name.into(),
        cat: String::new(),
        ph: "M".into(),
        ts: 0.0,
        dur: None,
        pid: PID,
        tid,
        args,
    }
}

fn slice(name: String, cat: &str, tid: u32, ts: f64, dur: f64, args: serde_json::Value) -> Event {
    Event {
        name,
        cat: cat.into(),
        ph: "X".into(),
        ts,
        dur: Some(dur),
        pid: PID,
        tid,
        args,
    }
}

/// The timeline of `frames` (every measured frame's samples) of the run
/// `report` describes (module docs).
pub fn build(report: &Report, frames: &[Vec<PassSample>]) -> Trace {
    let mut ev = vec![
        metadata(
            "process_name",
            0,
            json!({ "name": format!("dermis {} on {}", report.method, report.run.device.device) }),
        ),
        metadata(
            "thread_name",
            GPU_TID,
            json!({ "name": "GPU (barriers and passes)" }),
        ),
        metadata("thread_sort_index", GPU_TID, json!({ "sort_index": 0 })),
        metadata("thread_name", FRAME_TID, json!({ "name": "frames" })),
        metadata("thread_sort_index", FRAME_TID, json!({ "sort_index": 1 })),
    ];
    // Microseconds since the first measured frame began.
    let mut t = 0.0f64;
    for (k, frame) in frames.iter().enumerate() {
        let start = t;
        for s in frame {
            let barrier_us = s.barrier_ms * 1e3;
            let pass_us = s.gpu_ms * 1e3;
            ev.push(slice(
                format!("barriers before {}", s.name),
                "barrier",
                GPU_TID,
                t,
                barrier_us,
                json!({ "frame": k, "pass": s.name }),
            ));
            t += barrier_us;
            ev.push(slice(
                s.name.clone(),
                "pass",
                GPU_TID,
                t,
                pass_us,
                json!({
                    "frame": k,
                    "role": s.role,
                    "fragment_invocations": s.fragment_invocations,
                    "samples_passed": s.samples_passed,
                }),
            ));
            t += pass_us;
        }
        ev.push(slice(
            format!("frame {k}"),
            "frame",
            FRAME_TID,
            start,
            t - start,
            json!({ "frame": k, "passes": frame.len() }),
        ));
    }
    Trace {
        trace_events: ev,
        display_time_unit: "ms".into(),
        other_data: other_data(report),
    }
}

/// The trace's `otherData`: the run header (every field, by serialisation)
/// and what the timeline is.
fn other_data(report: &Report) -> serde_json::Value {
    let mut v = serde_json::to_value(&report.run).unwrap_or_else(|_| json!({}));
    if let Some(m) = v.as_object_mut() {
        m.insert("method".into(), json!(report.method));
        m.insert("scene".into(), json!(report.scene));
        m.insert(
            "timeline".into(),
            json!("GPU timestamps; frames laid end to end (the CPU's time between submissions is not in the trace); each pass's barriers are their own slice before it"),
        );
    }
    v
}

/// Writes the trace of a run to `path` (through `output`).
pub fn write(path: &Path, report: &Report, frames: &[Vec<PassSample>]) -> Result<()> {
    write_json(path, &build(report, frames))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::PassRole;
    use crate::report::{aggregate, Stats};

    fn sample(name: &str, barrier_ms: f64, gpu_ms: f64) -> PassSample {
        PassSample {
            input_primitives: None,
            name: name.into(),
            role: PassRole::Sss,
            merge: false,
            barrier_ms,
            gpu_ms,
            fragment_invocations: Some(7),
            compute_invocations: None,
            samples_passed: 5,
        }
    }

    fn report_of(frames: &[Vec<PassSample>]) -> Report {
        let (passes, frame) = aggregate(frames, &[]);
        serde_json::from_value(serde_json::json!({
            "dermis_version": "0", "command": "t", "device": "d", "device_type": "cpu",
            "driver": "x", "vulkan_api": "1.3", "validation": false, "width": 4,
            "height": 2, "method": "m", "transmittance": true,
            "transmittance_profile": "thesis", "scene": "s", "mm_per_unit": 1.0,
            "heads": 1, "distance_heads": 2.0, "fovy_deg": 20.0,
            "light": { "azimuth_deg": 0.0, "elevation_deg": 0.0, "intensity": 1.0 },
            "warmup_frames": 0, "measured_frames": frames.len(),
            "passes": passes, "frame": frame,
        }))
        .unwrap()
    }

    // The format's rules (complete events with ts and dur, metadata naming
    // the process and threads), and slices that sum to the report's times.
    #[test]
    fn slices_follow_the_format_and_sum_to_the_report() {
        let frames: Vec<Vec<PassSample>> = [(0.01, 1.5, 0.0, 0.25), (0.02, 1.25, 0.001, 0.5)]
            .iter()
            .cycle()
            .take(5)
            .map(|&(b0, g0, b1, g1)| vec![sample("a", b0, g0), sample("b", b1, g1)])
            .collect();
        let report = report_of(&frames);
        let json = serde_json::to_string(&build(&report, &frames)).unwrap();
        let trace: Trace = serde_json::from_str(&json).unwrap();
        let meta: Vec<&Event> = trace.trace_events.iter().filter(|e| e.ph == "M").collect();
        assert!(meta
            .iter()
            .any(|e| e.name == "process_name" && e.args["name"].is_string()));
        for tid in [GPU_TID, FRAME_TID] {
            assert!(meta.iter().any(|e| e.name == "thread_name" && e.tid == tid));
        }
        let slices: Vec<&Event> = trace.trace_events.iter().filter(|e| e.ph == "X").collect();
        assert_eq!(slices.len(), 5 * (2 * 2 + 1));
        assert!(slices
            .iter()
            .all(|e| e.pid == PID && e.dur.is_some_and(|d| d >= 0.0) && e.ts >= 0.0));
        // The GPU track: each slice starts where the one before ended.
        let gpu: Vec<&&Event> = slices.iter().filter(|e| e.tid == GPU_TID).collect();
        for w in gpu.windows(2) {
            assert_eq!(w[0].ts + w[0].dur.unwrap(), w[1].ts);
        }
        for p in &report.passes {
            let of = |cat: &str, name: &str| -> Vec<f64> {
                gpu.iter()
                    .filter(|e| e.cat == cat && e.name == name)
                    .map(|e| e.dur.unwrap() / 1e3)
                    .collect()
            };
            let pass = Stats::of(&of("pass", &p.name)).unwrap();
            let bar = Stats::of(&of("barrier", &format!("barriers before {}", p.name))).unwrap();
            assert!((pass.median - p.gpu_ms.median).abs() < 1e-12, "{}", p.name);
            assert!((pass.p95 - p.gpu_ms.p95).abs() < 1e-12);
            assert!((bar.median - p.barrier_ms.median).abs() < 1e-12);
        }
        let frame_ms: Vec<f64> = slices
            .iter()
            .filter(|e| e.tid == FRAME_TID)
            .map(|e| e.dur.unwrap() / 1e3)
            .collect();
        let f = Stats::of(&frame_ms).unwrap();
        assert!((f.median - report.frame.unwrap().gpu_ms.median).abs() < 1e-12);
    }
}
