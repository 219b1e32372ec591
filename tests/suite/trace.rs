//! `--trace FILE.json` on a real run (lavapipe, validation on): the file is
//! Chrome trace-event JSON as Perfetto reads it (complete `X` events with
//! `ts`/`dur` in microseconds, `M` events naming the process and threads),
//! and its slices sum to the report's pass times: per pass, the median (and
//! minimum and p95) of its slices is the report's `gpu_ms`, of its barrier
//! slices the report's `barrier_ms`, and of the frame slices `frame.gpu_ms`.

use std::process::Command;

use dermis::report::Stats;
use dermis::trace::{Trace, FRAME_TID, GPU_TID};

const FRAMES: usize = 5;

fn close(a: Stats, b: Stats, what: &str) {
    // The trace holds microseconds: 1e-9 ms is far below a timestamp tick.
    for (x, y) in [(a.median, b.median), (a.min, b.min), (a.p95, b.p95)] {
        assert!(
            (x - y).abs() <= 1e-9 * y.abs().max(1.0),
            "{what}: {a:?} vs {b:?}"
        );
    }
}

#[test]
fn trace_slices_sum_to_the_report_pass_times() {
    let d = dermis::scene::gltf_load::fixture::temp_dir("trace");
    let trace_path = d.join("t/trace.json");
    let o = Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args([
            "render",
            "--device",
            "llvmpipe",
            "--validate",
            "--width",
            "96",
            "--height",
            "64",
            "--shadow-size",
            "128",
            "--warmup",
            "1",
            "--frames",
            &FRAMES.to_string(),
            "--out",
        ])
        .arg(&d)
        .arg("--trace")
        .arg(&trace_path)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = dermis::report::load(&d.join("report.json")).unwrap();
    let text = std::fs::read_to_string(&trace_path).unwrap();

    // The format, read as plain JSON (not through dermis's own types).
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let events = v["traceEvents"].as_array().unwrap();
    for e in events {
        let ph = e["ph"].as_str().unwrap();
        assert!(ph == "X" || ph == "M", "{e}");
        assert!(
            e["name"].is_string() && e["pid"].is_u64() && e["tid"].is_u64(),
            "{e}"
        );
        if ph == "X" {
            assert!(e["ts"].as_f64().unwrap() >= 0.0 && e["dur"].as_f64().unwrap() >= 0.0);
        } else {
            assert!(e["args"]["name"].is_string() || e["args"]["sort_index"].is_u64());
        }
    }
    let named = |what: &str, tid: u64| {
        events
            .iter()
            .any(|e| e["ph"] == "M" && e["name"] == what && e["tid"] == tid)
    };
    assert!(named("thread_name", GPU_TID.into()) && named("thread_name", FRAME_TID.into()));
    assert!(events.iter().any(|e| e["name"] == "process_name"));

    let trace: Trace = serde_json::from_str(&text).unwrap();
    let durations = |tid: u32, cat: &str, name: &str| -> Vec<f64> {
        trace
            .trace_events
            .iter()
            .filter(|e| e.ph == "X" && e.tid == tid && e.cat == cat && e.name == name)
            .map(|e| e.dur.unwrap() / 1e3)
            .collect()
    };
    assert_eq!(report.run.measured_frames, FRAMES);
    assert!(report.passes.len() >= 5);
    for p in &report.passes {
        let pass = durations(GPU_TID, "pass", &p.name);
        assert_eq!(pass.len(), FRAMES, "{}", p.name);
        close(Stats::of(&pass).unwrap(), p.gpu_ms, &p.name);
        let bar = durations(GPU_TID, "barrier", &format!("barriers before {}", p.name));
        close(Stats::of(&bar).unwrap(), p.barrier_ms, &p.name);
    }
    let frames: Vec<f64> = trace
        .trace_events
        .iter()
        .filter(|e| e.ph == "X" && e.tid == FRAME_TID)
        .map(|e| e.dur.unwrap() / 1e3)
        .collect();
    assert_eq!(frames.len(), FRAMES);
    close(
        Stats::of(&frames).unwrap(),
        report.frame.unwrap().gpu_ms,
        "frame",
    );
    let _ = std::fs::remove_dir_all(d);
}
