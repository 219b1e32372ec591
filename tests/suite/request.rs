//! The command wing's one checked request (issue 27): a report renders its
//! frame again bit for bit from its own settings, every check of a command
//! runs once, and each hostile class of input ends in one clean line or a
//! correct output, with no stale or truncated file under a final name.

use std::path::Path;
use std::process::Output;

use crate::common;

fn tmp(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("dermis-request-{tag}-"))
        .tempdir()
        .unwrap()
}

/// The small lavapipe frame every run here renders.
const SMALL: [&str; 14] = [
    "--device",
    "llvmpipe",
    "--validate",
    "--width",
    "64",
    "--height",
    "36",
    "--view",
    "study",
    "--shadow-size",
    "256",
    "--warmup",
    "0",
    "--frames",
];

fn run(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = common::dermis();
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn ok(args: &[&str]) -> Output {
    let o = run(args, &[]);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// A failed run whose only error line holds every phrase (notes may come
/// before it), with no panic and no validation message.
fn one_error(o: &Output, phrases: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "succeeded: {stderr}");
    assert_ne!(o.status.code(), Some(101), "panicked: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    for p in phrases {
        assert!(errors[0].contains(p), "'{p}' not in: {stderr}");
    }
    assert!(!stderr.contains("Validation"), "{stderr}");
    stderr
}

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every pass's counts of a report, by name.
fn counts(report: &Path) -> Vec<(String, Option<u64>, u64)> {
    let r = dermis::report::load(report).unwrap();
    r.passes
        .iter()
        .map(|p| (p.name.clone(), p.fragment_invocations, p.samples_passed))
        .collect()
}

/// Each method (the ground truth at one sample per mm^2, the texture-space
/// ones at 128-texel maps), a mixed frame with a fade and a frame with the
/// post chain: rendered, then rendered again from nothing but the report's
/// settings, give the same bytes and the same counts.
#[test]
fn a_reports_settings_render_its_frame_again_bit_for_bit() {
    let d = tmp("again");
    let plan = d.path().join("fade.json");
    std::fs::write(
        &plan,
        r#"{"version":1,"characters":3,"assignments":[
            {"character":0,"method":"separable","fade":{"method":"ssg","weight":0.5}},
            {"character":1,"method":"ss-jittered"},
            {"character":2,"method":"none","fade":{"method":"separable","weight":0.25}}]}"#,
    )
    .unwrap();
    let mut configs: Vec<(String, Vec<String>)> = dermis::method::METHODS
        .iter()
        .map(|m| {
            let mut a = vec!["--method".to_string(), m.name.to_string()];
            match m.name {
                "reference" => a.extend(["--density".into(), "1".into()]),
                "tsd" | "tsd-opt" => a.extend(["--irradiance-size".into(), "128".into()]),
                _ => {}
            }
            (m.name.to_string(), a)
        })
        .collect();
    configs.push((
        "mixed".into(),
        [
            "--heads",
            "3",
            "--layout",
            "grid",
            "--plan",
            plan.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec(),
    ));
    configs.push((
        "post".into(),
        [
            "--aa",
            "smaa",
            "--smaa-preset",
            "ultra",
            "--bloom",
            "--light-azimuth",
            "-40",
        ]
        .map(String::from)
        .to_vec(),
    ));
    for (name, extra) in &configs {
        let (a, b) = (
            d.path().join(format!("{name}-a")),
            d.path().join(format!("{name}-b")),
        );
        let mut args: Vec<&str> = vec!["render"];
        args.extend(SMALL);
        args.push("1");
        args.extend(extra.iter().map(String::as_str));
        args.extend(["--out", a.to_str().unwrap()]);
        ok(&args);
        ok(&[
            "render",
            "--device",
            "llvmpipe",
            "--validate",
            "--warmup",
            "0",
            "--frames",
            "1",
            "--settings",
            a.join("report.json").to_str().unwrap(),
            "--out",
            b.to_str().unwrap(),
        ]);
        for f in ["frame.png", "diffuse.exr", "depth.exr"] {
            assert!(
                bytes(&a.join(f)) == bytes(&b.join(f)),
                "{name}: {f} differs"
            );
        }
        assert_eq!(
            counts(&a.join("report.json")),
            counts(&b.join("report.json")),
            "{name}"
        );
        let (ra, rb) = (
            dermis::report::load(&a.join("report.json")).unwrap(),
            dermis::report::load(&b.join("report.json")).unwrap(),
        );
        assert_eq!(ra.settings, rb.settings, "{name}");
        assert!(ra.settings.is_some(), "{name}: no settings in the report");
    }
}

/// The checks of `render`, `bench` and `reference` each run once per command
/// (`DERMIS_CHECK_COUNTS` prints them): the settings, the groups, the frame
/// counts, the outputs, the scene, and the device's limits once it is open.
#[test]
fn every_check_of_a_command_runs_once() {
    let d = tmp("checks");
    let out = d.path().join("r");
    let bench = d.path().join("bench.json");
    let cases: Vec<Vec<&str>> = vec![
        [
            "render",
            "--heads",
            "3",
            "--layout",
            "grid",
            "--assign",
            "0=ssg,*=separable",
            "--out",
        ]
        .into_iter()
        .chain([out.to_str().unwrap()])
        .collect(),
        vec!["bench", "--report", bench.to_str().unwrap()],
        vec![
            "reference",
            "--density",
            "1",
            "--out",
            out.to_str().unwrap(),
        ],
    ];
    for case in cases {
        let mut args = vec![case[0]];
        args.extend(SMALL);
        args.push("1");
        args.extend(&case[1..]);
        // reference takes no frame counts.
        if case[0] == "reference" {
            let i = args.iter().position(|a| *a == "--warmup").unwrap();
            args.drain(i..i + 4);
        }
        let o = run(&args, &[("DERMIS_CHECK_COUNTS", "1")]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{args:?}: {stderr}");
        let line = stderr
            .lines()
            .find(|l| l.starts_with("checks: "))
            .unwrap_or_else(|| panic!("no check counts: {stderr}"));
        let checks: Vec<(&str, u32)> = line["checks: ".len()..]
            .split(' ')
            .map(|kv| {
                let (k, v) = kv.split_once('=').unwrap();
                (k, v.parse().unwrap())
            })
            .collect();
        let mut want = vec![
            "device-limits",
            "groups",
            "in-view",
            "output-paths",
            "scene",
            "settings",
        ];
        if case[0] != "reference" {
            want.push("frame-counts");
        }
        want.sort();
        let mut names: Vec<&str> = checks.iter().map(|c| c.0).collect();
        names.sort();
        assert_eq!(names, want, "{case:?}: {line}");
        assert!(checks.iter().all(|c| c.1 == 1), "{case:?}: {line}");
    }
}

/// Counts a file brings are held to the range the command line gives the
/// same quantity before anything is allocated from them.
#[test]
fn counts_from_files_and_flags_are_bounded() {
    let d = tmp("bounded");
    for (tag, n) in [("huge", "1000000000000"), ("none", "0")] {
        let plan = d.path().join(format!("{tag}.json"));
        std::fs::write(
            &plan,
            format!(r#"{{"version":1,"characters":{n},"assignments":[]}}"#),
        )
        .unwrap();
        let o = run(
            &[
                "render",
                "--device",
                "no-such-device-opens",
                "--plan",
                plan.to_str().unwrap(),
            ],
            &[],
        );
        let e = one_error(&o, &["characters must be within 1..=1024", n]);
        // No advice to give a count no frame can have.
        assert!(!e.contains("--heads 0"), "{e}");
    }
    let o = run(
        &[
            "plan-check",
            "--device",
            "no-such-device-opens",
            "--timed-profile",
            "nvidia-h200",
            "--timed-frames",
            "1000000000000",
        ],
        &[],
    );
    let e = one_error(&o, &["--timed-frames must be within"]);
    assert!(!e.contains("no-such-device"), "{e}");
}

/// An output of a run that another output of the same run names is refused
/// before any device opens; nothing is written over.
#[test]
fn an_output_aimed_at_another_output_of_the_run_is_refused() {
    let d = tmp("collide");
    let out = d.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("report.json"), b"mine").unwrap();
    let o = run(
        &[
            "render",
            "--device",
            "no-such-device-opens",
            "--out",
            out.to_str().unwrap(),
            "--trace",
            out.join("report.json").to_str().unwrap(),
        ],
        &[],
    );
    one_error(&o, &["--trace", "same file"]);
    assert_eq!(bytes(&out.join("report.json")), b"mine");
    let f = d.path().join("b.json");
    let o = run(
        &[
            "bench",
            "--device",
            "no-such-device-opens",
            "--report",
            f.to_str().unwrap(),
            "--trace",
            f.to_str().unwrap(),
        ],
        &[],
    );
    one_error(&o, &["same file"]);
    // A dangling link as the folder: said as such, not "File exists".
    let link = d.path().join("dangling");
    std::os::unix::fs::symlink(d.path().join("gone"), &link).unwrap();
    let o = run(
        &[
            "render",
            "--device",
            "no-such-device-opens",
            "--out",
            link.to_str().unwrap(),
        ],
        &[],
    );
    let e = one_error(&o, &["symbolic link", "does not exist"]);
    assert!(!e.contains("File exists"), "{e}");
}

/// A run into a folder leaves there its own files only: the dumps and the
/// groups' picture of an earlier run into it are gone.
#[test]
fn a_folder_holds_its_last_runs_files_only() {
    let d = tmp("stale");
    let out = d.path().join("out");
    let o = out.to_str().unwrap();
    let mut first = vec!["render"];
    first.extend(SMALL);
    first.extend([
        "1",
        "--heads",
        "3",
        "--layout",
        "grid",
        "--assign",
        "0=ssg,*=separable",
        "--dump",
        "--out",
        o,
    ]);
    ok(&first);
    assert!(out.join("groups.png").is_file());
    let dumps = |p: &Path| std::fs::read_dir(p.join("passes")).map_or(0, |r| r.count());
    let before = dumps(&out);
    let mut second = vec!["render"];
    second.extend(SMALL);
    second.extend(["1", "--method", "none", "--dump", "--out", o]);
    ok(&second);
    assert!(!out.join("groups.png").exists() && !out.join("characters.png").exists());
    let after = dumps(&out);
    // none's frame: shadow, geometry's four targets, composite, tone map.
    assert!(after < before && after == 7, "{before} dumps, then {after}");
}

/// A named profile that does not exist is an error, not a case that never
/// matches; every option a command does not read is named in a note.
#[test]
fn unknown_profiles_are_errors_and_unread_options_are_named() {
    for args in [
        vec!["plan", "--profile", "no-such-gpu", "--budget-ms", "1"],
        vec![
            "budget",
            "--device",
            "no-such-device-opens",
            "--profile",
            "no-such-gpu",
        ],
        vec![
            "plan-check",
            "--device",
            "no-such-device-opens",
            "--cases",
            "xbox360:1",
            "--timed-profile",
            "no-such-gpu",
        ],
        vec![
            "plan-motion",
            "--device",
            "no-such-device-opens",
            "--profile",
            "no-such-gpu",
            "--budget-ms",
            "1",
        ],
    ] {
        let o = run(&args, &[]);
        let e = one_error(&o, &["no profile 'no-such-gpu'"]);
        assert!(
            e.contains("xbox360"),
            "the built-in profiles are listed: {e}"
        );
        assert!(!e.contains("no-such-device"), "{e}");
    }
    let d = tmp("notes");
    let o = ok(&[
        "plan",
        "--profile",
        "xbox360",
        "--budget-ms",
        "1",
        "--width",
        "128",
        "--height",
        "72",
        "--validate",
        "--aa",
        "fxaa",
        "--out",
        d.path().to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    for note in [
        "note: --validate is ignored: plan opens no device",
        "note: --aa is ignored: plan prices the skin SSS alone",
    ] {
        assert!(stderr.contains(note), "{stderr}");
    }
}

/// What the docs say works works: a frame of several methods renders at 4x
/// MSAA (its groups' picture, which needs the id pass, is left out with a
/// note), not refused over an option nobody gave.
#[test]
fn a_mixed_frame_renders_multisampled() {
    let d = tmp("msaa");
    let mut args = vec!["render"];
    args.extend(SMALL);
    args.extend([
        "1",
        "--heads",
        "3",
        "--layout",
        "grid",
        "--assign",
        "0=ssg,*=separable",
        "--msaa",
        "4",
        "--out",
    ]);
    args.push(d.path().to_str().unwrap());
    let o = ok(&args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("groups.png and characters.png are not written"),
        "{stderr}"
    );
    assert!(!stderr.contains("--character-ids"), "{stderr}");
    assert!(d.path().join("frame.png").is_file() && !d.path().join("groups.png").exists());
}

/// A sweep checks every frame it will render before the first renders: a
/// setting one of its methods refuses is one line before any device opens.
#[test]
fn a_sweep_refuses_what_it_cannot_render_before_it_starts() {
    let o = run(
        &[
            "eval",
            "--device",
            "no-such-device-opens",
            "--scenes",
            "quick",
            "--msaa",
            "4",
        ],
        &[],
    );
    let e = one_error(&o, &["cannot run with --msaa 4", "on 'procedural'"]);
    assert!(!e.contains("no-such-device"), "{e}");
}

/// Messages name the real cause: a full disk under an EXR is an encoding
/// failure (not "decoding"); a profile that gives skin SSS no budget prints
/// no infinite share; a depth of +inf in a compared output is refused, not
/// compared.
#[test]
fn messages_name_the_real_cause() {
    let d = tmp("causes");
    let out = d.path().join("full");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink("/dev/full", out.join("diffuse.exr")).unwrap();
    let mut args = vec!["render"];
    args.extend(SMALL);
    args.extend(["1", "--out", out.to_str().unwrap()]);
    let e = one_error(
        &run(&args, &[]),
        &["diffuse.exr", "encoding OpenExr", "No space left"],
    );
    assert!(!e.contains("decoding"), "{e}");

    let text =
        std::fs::read_to_string(dermis::budget::profile::profiles_dir().join("xbox360.toml"))
            .unwrap();
    std::fs::create_dir_all(d.path().join("mine")).unwrap();
    let none = d.path().join("mine/xbox360.toml");
    let text = text.replacen("sss_share = 0.10", "sss_share = 0.0", 1);
    assert!(text.contains("sss_share = 0.0"));
    std::fs::write(&none, text).unwrap();
    let budget_out = d.path().join("budget");
    let mut args = vec!["budget"];
    args.extend(SMALL);
    args.extend([
        "1",
        "--declared-fetches",
        "--profile",
        none.to_str().unwrap(),
        "--out",
        budget_out.to_str().unwrap(),
    ]);
    let o = ok(&args);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        !stdout.contains("inf%") && !stdout.contains("NaN"),
        "{stdout}"
    );
    assert!(stdout.contains("gives skin SSS no budget"), "{stdout}");

    // A render output whose depth holds +inf.
    let a = d.path().join("a");
    let mut args = vec!["render"];
    args.extend(SMALL);
    args.extend(["1", "--out", a.to_str().unwrap()]);
    ok(&args);
    let (w, h, mut depth) = dermis::output::read_exr(&a.join("depth.exr")).unwrap();
    depth[5][0] = f32::INFINITY;
    let img =
        image::Rgba32FImage::from_raw(w, h, depth.iter().flatten().copied().collect()).unwrap();
    img.save(a.join("depth.exr")).unwrap();
    let o = run(
        &[
            "compare",
            a.to_str().unwrap(),
            a.to_str().unwrap(),
            "--out",
            d.path().join("c").to_str().unwrap(),
        ],
        &[],
    );
    one_error(&o, &["depth.exr", "NaN or infinite", "(5, 0)"]);
}

/// A binary that runs anywhere (issue 27): no code a command runs reads the
/// source tree. The functions that name it (`CARGO_MANIFEST_DIR`) serve the
/// tools and the tests only: outside tests, only the calibration's and the
/// porting tables' modules (run by `tools/examples/`) call them; the
/// commands read the copies built into the binary (`dermis::embedded`).
#[test]
fn no_command_reads_the_source_tree() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let readers = [
        "frames_dir()",
        "perf_dir()",
        "profiles_dir()",
        "default_dir()",
        "plan_frames_dir()",
    ];
    let tools = [
        "budget/points.rs",
        "budget/porting.rs",
        "budget/calibration.rs",
    ];
    let mut files = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    let mut found = Vec::new();
    for f in &files {
        let rel = f
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        // A test module's own file (`mod tests;`) runs in the source tree.
        if rel.ends_with("/tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(f).unwrap();
        // Unit tests read the source tree: they run in it.
        let code = text.split("#[cfg(test)]").next().unwrap_or_default();
        let mut in_fn = String::new();
        for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
            if let Some(name) = line
                .split("fn ")
                .nth(1)
                .and_then(|r| r.split('(').next())
                .filter(|_| {
                    line.trim_start().starts_with("pub fn ") || line.trim_start().starts_with("fn ")
                })
            {
                in_fn = format!("{name}()");
            }
            // The source tree is named only inside the readers themselves.
            if line.contains("CARGO_MANIFEST_DIR") && !readers.contains(&in_fn.as_str()) {
                found.push(format!("{rel}: {} (in {in_fn})", line.trim()));
            }
            // A call: the name not part of a longer one, and not its definition.
            let calls = readers.iter().any(|r| {
                line.match_indices(r).any(|(i, _)| {
                    let before = &line[..i];
                    let joined = before
                        .chars()
                        .last()
                        .is_some_and(|c| c.is_alphanumeric() || c == '_');
                    !joined && !before.ends_with("fn ")
                })
            });
            if calls && !tools.contains(&rel.as_str()) {
                found.push(format!("{rel}: {}", line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "the source tree read at run time:\n{}",
        found.join("\n")
    );
}
