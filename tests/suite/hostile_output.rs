//! Outputs a hostile or unlucky user points dermis at (issue 15 item 11): a
//! full disk (`/dev/full`, whose writes fail with ENOSPC, and a tiny tmpfs
//! where one can be mounted), a FIFO, a killed run. Each ends in one clean
//! error line and a non-zero exit (never exit 0 with an empty file), and no
//! truncated file is left under a final name: `output::write_with` writes a
//! temporary beside it and renames it only when complete.

use dermis::scene::gltf_load::fixture::TempDir;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn dermis() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_dermis"));
    c.env("RUST_BACKTRACE", "0");
    c
}

fn tmp(name: &str) -> TempDir {
    dermis::scene::gltf_load::fixture::temp_dir(&format!("hostile-out-{name}"))
}

/// A small render or bench on lavapipe with validation.
fn small(cmd: &str) -> Command {
    let mut c = dermis();
    c.args([
        cmd,
        "--device",
        "llvmpipe",
        "--validate",
        "--width",
        "64",
        "--height",
        "48",
        "--shadow-size",
        "128",
        "--warmup",
        "0",
        "--frames",
        "1",
    ]);
    c
}

/// Runs `c`, killing it and failing if it takes longer than `limit` (a
/// FIFO must never hang a run).
fn output_within(mut c: Command, limit: Duration) -> Output {
    let mut child = c
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the run did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Asserts a failed run with exactly one error line containing every phrase.
fn one_error_line(o: &Output, phrases: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "the run succeeded: {stderr}");
    assert_ne!(o.status.code(), Some(101), "panicked: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "not one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for p in phrases {
        assert!(lines[0].contains(p), "'{p}' not in: {stderr}");
    }
    stderr
}

/// No temporary (`.NAME.PID.tmp`) left in `dir`.
fn no_temporaries(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "{name} left in {}", dir.display());
    }
}

#[test]
fn a_full_disk_is_one_error_line_and_a_failure() {
    // bench's report on a full device.
    let mut c = small("bench");
    c.args(["--report", "/dev/full"]);
    one_error_line(&c.output().unwrap(), &["/dev/full", "No space left"]);

    // A render whose report.json lands on the full device: the images before
    // it are whole, nothing is half-written, the run fails.
    let d = tmp("full-report");
    std::os::unix::fs::symlink("/dev/full", d.join("report.json")).unwrap();
    let mut c = small("render");
    c.arg("--out").arg(&d);
    one_error_line(&c.output().unwrap(), &["report.json", "No space left"]);
    let png = image::open(d.join("frame.png")).unwrap();
    assert_eq!((png.width(), png.height()), (64, 48));
    no_temporaries(&d);

    // The trace on a full device, after every other output was written.
    let d = tmp("full-trace");
    let mut c = small("render");
    c.arg("--out").arg(&d).args(["--trace", "/dev/full"]);
    one_error_line(&c.output().unwrap(), &["/dev/full", "No space left"]);
    let _ = std::fs::remove_dir_all(d);
}

/// A tmpfs of a few kilobytes, unmounted on drop (before its folder goes).
struct TinyDisk(TempDir);

impl TinyDisk {
    /// `None` where this process may not mount (not root, no CAP_SYS_ADMIN).
    fn mount(kb: u32) -> Option<TinyDisk> {
        let d = tmp(&format!("tmpfs-{kb}k"));
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={kb}k"), "tmpfs"])
            .arg(&d)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        ok.then_some(TinyDisk(d))
    }
}

impl Drop for TinyDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.0.path()).status();
    }
}

// A disk that fills up part way through the outputs: whatever was written
// is whole, the file that did not fit is not there at all.
#[test]
fn a_disk_that_fills_up_leaves_no_truncated_file() {
    let Some(disk) = TinyDisk::mount(24) else {
        eprintln!("cannot mount a tmpfs here: the /dev/full test covers ENOSPC");
        return;
    };
    let out = disk.0.join("out");
    let mut c = small("render");
    c.arg("--out").arg(&out);
    // 64x48 RGBA32F EXRs are about 48 KB each: the first does not fit in 24 KB.
    one_error_line(&c.output().unwrap(), &["No space left"]);
    for name in ["frame.png", "diffuse.exr", "depth.exr", "report.json"] {
        let p = out.join(name);
        if p.exists() {
            match name {
                "report.json" => {
                    dermis::report::load(&p).unwrap();
                }
                _ => {
                    image::open(&p).unwrap_or_else(|e| panic!("{name} is not whole: {e}"));
                }
            }
        }
    }
    assert!(
        !out.join("report.json").exists(),
        "report.json is written last"
    );
    no_temporaries(&out);
}

#[test]
fn a_fifo_as_an_output_is_refused_before_any_work() {
    let d = tmp("fifo");
    let fifo = d.join("report.json");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let mut c = small("render");
    c.arg("--out").arg(&d);
    let o = output_within(c, Duration::from_secs(60));
    one_error_line(&o, &["report.json", "is a FIFO"]);
    assert!(!d.join("frame.png").exists(), "the render ran");

    // bench's report, and a trace beside a good report.
    let mut c = small("bench");
    c.arg("--report").arg(&fifo);
    one_error_line(&output_within(c, Duration::from_secs(60)), &["is a FIFO"]);
    let mut c = small("bench");
    c.arg("--report").arg(d.join("r.json"));
    c.arg("--trace").arg(&fifo);
    one_error_line(&output_within(c, Duration::from_secs(60)), &["is a FIFO"]);
    assert!(!d.join("r.json").exists(), "the bench ran");
    let _ = std::fs::remove_dir_all(d);
}

// A run killed before its outputs are complete leaves the previous report
// whole under its name (and nothing half-written beside it).
#[test]
fn a_killed_run_leaves_the_old_report_whole() {
    let d = tmp("killed");
    let report = d.join("bench.json");
    std::fs::write(&report, b"{\"old\": true}").unwrap();
    let mut c = dermis();
    c.args([
        "bench", "--device", "llvmpipe", "--width", "64", "--height", "48", "--warmup", "0",
        "--frames", "100000", "--report",
    ])
    .arg(&report)
    .arg("--trace")
    .arg(d.join("trace.json"))
    .stdout(Stdio::null())
    .stderr(Stdio::null());
    let mut child = c.spawn().unwrap();
    std::thread::sleep(Duration::from_secs(3));
    assert!(child.try_wait().unwrap().is_none(), "the bench ended early");
    child.kill().unwrap();
    let _ = child.wait();
    assert_eq!(std::fs::read(&report).unwrap(), b"{\"old\": true}");
    assert!(!d.join("trace.json").exists());
    no_temporaries(&d);
    let _ = std::fs::remove_dir_all(d);
}
