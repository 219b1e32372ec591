//! The test suite's own checks: no test file is left out of a test binary
//! (Cargo.toml sets `autotests = false`, so a new tests/*.rs runs only once a
//! `[[test]]` or a `mod` names it), and a failed image comparison leaves its
//! difference image.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::common;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("listing tests/").flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The files a module file pulls in: `mod NAME;` (NAME.rs or NAME/mod.rs
/// beside a main.rs or mod.rs, NAME.rs in FILE's folder otherwise, which
/// covers this suite's layout) and `#[path = "P"] mod NAME;` (P beside FILE).
fn modules_of(file: &Path, out: &mut BTreeSet<PathBuf>) {
    let Ok(text) = std::fs::read_to_string(file) else {
        return;
    };
    let dir = file.parent().expect("a file's folder");
    let mut path_attr: Option<String> = None;
    for line in text.lines().map(str::trim) {
        if let Some(p) = line
            .strip_prefix("#[path = \"")
            .and_then(|r| r.strip_suffix("\"]"))
        {
            path_attr = Some(p.to_string());
            continue;
        }
        let decl = line
            .strip_prefix("pub mod ")
            .or_else(|| line.strip_prefix("mod "))
            .and_then(|r| r.strip_suffix(';'));
        if let Some(name) = decl {
            let candidates = match path_attr.take() {
                Some(p) => vec![dir.join(p)],
                None => vec![
                    dir.join(format!("{name}.rs")),
                    dir.join(name).join("mod.rs"),
                ],
            };
            for c in candidates {
                if let Ok(c) = c.canonicalize() {
                    if out.insert(c.clone()) {
                        modules_of(&c, out);
                    }
                }
            }
        } else if !line.starts_with("//") && !line.is_empty() {
            path_attr = None;
        }
    }
}

#[test]
fn every_test_file_is_in_a_test_binary() {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).expect("Cargo.toml");
    let manifest: toml::Table = manifest.parse().expect("Cargo.toml parses");
    let targets: Vec<PathBuf> = manifest["test"]
        .as_array()
        .expect("[[test]] targets")
        .iter()
        .map(|t| root().join(t["path"].as_str().expect("a [[test]] path")))
        .collect();
    let mut reached = BTreeSet::new();
    for t in &targets {
        let t = t.canonicalize().expect("a [[test]] path that exists");
        reached.insert(t.clone());
        modules_of(&t, &mut reached);
    }
    let mut files = Vec::new();
    rust_files(&root().join("tests"), &mut files);
    let left_out: Vec<String> = files
        .iter()
        .filter(|f| !reached.contains(&f.canonicalize().unwrap()))
        .map(|f| f.display().to_string())
        .collect();
    assert!(
        left_out.is_empty(),
        "in no test binary (add a `mod` to tests/suite/main.rs or a [[test]] to Cargo.toml): {left_out:?}"
    );
    assert!(reached.len() > 15, "{reached:?}");
}

// The witness writes nothing on success, and the difference image on a panic.
#[test]
fn a_failed_image_comparison_writes_its_difference_image() {
    let (w, h) = (4, 2);
    let got = vec![[0.5f32, 0.25, 0.125, 1.0]; w * h];
    let mut want = got.clone();
    want[5] = [0.0, 1.0, 0.125, 1.0];
    let name = format!("harness-check-{}", std::process::id());
    let path = common::diff_dir().join(format!("{name}.png"));
    {
        let _ok = common::DiffOnFailure::new(name.clone(), w, h, &got, &got);
    }
    assert!(!path.exists(), "written on success: {}", path.display());
    let failed = std::panic::catch_unwind(|| {
        let _diff = common::DiffOnFailure::new(name.clone(), w, h, &got, &want);
        assert_eq!(got, want, "the images differ (expected here)");
    });
    assert!(failed.is_err());
    let img = image::open(&path)
        .unwrap_or_else(|e| panic!("no difference image at {}: {e}", path.display()))
        .to_rgb8();
    assert_eq!(img.dimensions(), (3 * w as u32, h as u32));
    // Third panel: white where the pixels differ most, black where they agree.
    let d = img.get_pixel(2 * w as u32 + 1, 1);
    assert_eq!(d.0[1], 255, "{d:?}");
    assert_eq!(img.get_pixel(2 * w as u32, 0).0, [0, 0, 0]);
    std::fs::remove_file(&path).expect("removing the check's image");
}

/// The README's two commands (a fresh machine's render and its tests) and
/// `.ci/run` agree: CI runs exactly the README's test command first, and
/// the README shows exactly two commands under "Two commands".
#[test]
fn ci_runs_the_readmes_test_command() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let section = readme
        .split("## Two commands")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("README's \"Two commands\" section");
    let blocks: Vec<&str> = section
        .split("```sh\n")
        .skip(1)
        .filter_map(|b| b.split("```").next())
        .map(str::trim)
        .collect();
    assert_eq!(blocks.len(), 2, "{blocks:?}");
    assert_eq!(blocks[1], "tools/setup.sh && cargo test");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    let first = ci
        .lines()
        .map(str::trim)
        .find(|l| {
            !l.is_empty() && !l.starts_with('#') && !l.starts_with("set ") && !l.starts_with("cd ")
        })
        .expect("a command in .ci/run");
    assert_eq!(first, blocks[1], ".ci/run's first command");
}
