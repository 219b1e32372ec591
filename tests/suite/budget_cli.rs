//! `dermis budget` on lavapipe with validation: every registered method's
//! frame priced on the Xbox 360 profile (and on two more side by side), every
//! pass of the frame listed and none unpriced, the JSON, frame files and chart
//! written; a bad profile is one error line.

use dermis::scene::gltf_load::fixture::TempDir;

use crate::common::dermis;
use dermis::method::METHODS;
use serde_json::Value;

fn tmp(name: &str) -> TempDir {
    dermis::scene::gltf_load::fixture::temp_dir(&format!("budget-{name}"))
}

/// Runs `dermis budget` small on lavapipe with validation; returns budget.json and stdout.
fn budget(name: &str, args: &[&str]) -> (Value, String, TempDir) {
    let out = tmp(name);
    let o = dermis()
        .args([
            "budget",
            "--validate",
            "--device",
            "llvmpipe",
            "--width",
            "160",
            "--height",
            "90",
            "--shadow-size",
            "256",
            "--warmup",
            "0",
            "--frames",
            "1",
            "--out",
        ])
        .arg(&out)
        .args(args)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "dermis budget {args:?} failed: {}\n{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("budget.json")).unwrap()).unwrap();
    (json, stdout, out)
}

/// Every frame-cost pass of every run is priced on every profile, in the
/// frame's order, and the run's frame file exists.
fn every_pass_priced(json: &Value, out: &std::path::Path) -> Vec<String> {
    let mut methods = Vec::new();
    for run in json["runs"].as_array().unwrap() {
        let method = run["method"].as_str().unwrap().to_string();
        let frame: Vec<&Value> = run["frame"]["passes"].as_array().unwrap().iter().collect();
        assert!(frame.len() >= 4, "{method}: {} passes", frame.len());
        for b in run["budgets"].as_array().unwrap() {
            let profile = b["profile"].as_str().unwrap();
            let priced = b["passes"].as_array().unwrap();
            let names = |v: &[&Value]| -> Vec<String> {
                v.iter()
                    .map(|p| p["name"].as_str().unwrap().to_string())
                    .collect()
            };
            assert_eq!(
                names(&priced.iter().collect::<Vec<_>>()),
                names(&frame),
                "{method} on {profile}: passes differ"
            );
            assert!(
                b["unpriced_passes"].as_array().unwrap().is_empty(),
                "{method} on {profile}: {}",
                b["unpriced_passes"]
            );
            for p in priced {
                assert!(
                    p["modelled_ms"].as_f64().is_some_and(|m| m >= 0.0),
                    "{method} on {profile}: pass {} unpriced",
                    p["name"]
                );
            }
            assert!(b["total_ms"].as_f64().unwrap() > 0.0);
        }
        assert!(out.join("frames").join(format!("{method}.json")).is_file());
        methods.push(method);
    }
    methods
}

#[test]
fn every_method_is_priced_on_the_xbox_360() {
    let (json, stdout, out) = budget(
        "compare",
        &[
            "--profile",
            "xbox360",
            "--profile",
            "switch-handheld,steam-deck",
            "--compare-methods",
        ],
    );
    assert!(json["fragments_rule"].as_str().unwrap().contains("NVIDIA"));
    assert!(json["fetch_counts"]
        .as_str()
        .unwrap()
        .starts_with("counted"));
    let profiles: Vec<&str> = json["profiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(profiles, ["xbox360", "switch-handheld", "steam-deck"]);
    let mut methods = every_pass_priced(&json, &out);
    // eDRAM on the Xbox 360 only: tiles and resolves where a target is read back.
    let sep = &json["runs"][0]["budgets"];
    assert!(sep[0]["passes"]
        .as_array()
        .unwrap()
        .iter()
        .any(|p| p["edram"]["resolves"]
            .as_array()
            .is_some_and(|r| !r.is_empty())));
    assert!(sep[1]["passes"][0]["edram"].is_null());
    for p in &profiles {
        assert!(stdout.contains(&format!("profile {p}")), "{p} not printed");
    }
    for f in ["budget.png", "budget.svg"] {
        assert!(out.join(f).metadata().unwrap().len() > 1000, "{f}");
    }
    // The ground truth is left out of the comparison: priced on its own.
    let gt = METHODS.iter().find(|m| m.ground_truth).unwrap();
    let (json, _, out) = budget(
        "reference",
        &[
            "--profile",
            "xbox360",
            "--method",
            gt.name,
            "--density",
            "1",
        ],
    );
    methods.extend(every_pass_priced(&json, &out));
    // A compute dispatch on the Xbox 360 is priced as a pixel shader, flagged.
    assert!(
        json["runs"][0]["budgets"][0]["substitutions"]
            .as_u64()
            .unwrap()
            > 0
    );
    let mut registered: Vec<String> = METHODS.iter().map(|m| m.name.to_string()).collect();
    methods.sort();
    registered.sort();
    assert_eq!(methods, registered, "every registered method is priced");
}

/// A new-format bench report (what the H200 matrix will commit) reads back
/// into the model's frame: every pass with its role and work.
#[test]
fn a_bench_report_reads_back_as_a_frame() {
    let out = tmp("bench");
    let report = out.join("r.json");
    let o = dermis()
        .args([
            "bench",
            "--validate",
            "--device",
            "llvmpipe",
            "--width",
            "96",
            "--height",
            "64",
            "--shadow-size",
            "128",
            "--warmup",
            "0",
            "--frames",
            "1",
            "--method",
            "poisson",
            "--report",
        ])
        .arg(&report)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rec = dermis::report::load(&report).unwrap();
    let f = dermis::budget::record::frame_from_record(&rec, None, "bench").unwrap();
    assert_eq!(f.passes.len(), rec.passes.len());
    assert!(f.passes.iter().all(|p| p.measured_ms.is_some()));
    assert!(f.provenance[1].contains("declared"));
    // Every probe ran (under validation) and gave a finite, positive figure,
    // the one-group dispatch's time among them (what a dispatch's floor
    // starts from, bench::floor).
    let probes = rec.probes.as_ref().expect("bench reports its probes");
    assert!(
        probes.len() >= 22 && probes.iter().all(|p| p.gpu_ms.median > 0.0),
        "{probes:?}"
    );
    let c = rec.ceilings.expect("bench reports its ceilings");
    let cs = c.compute.expect("the compute rates were probed");
    assert!(cs.dispatch_ms.is_some_and(|ms| ms > 0.0 && ms.is_finite()));
}

#[test]
fn a_bad_profile_is_one_error_line() {
    let out = tmp("bad");
    let o = dermis()
        .args([
            "budget",
            "--device",
            "llvmpipe",
            "--profile",
            "xbox-361",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].contains("no profile 'xbox-361'") && lines[0].contains("xbox360"),
        "{stderr}"
    );
}
