//! The files one command writes, declared together and prepared once before
//! any device opens (issue 27): every folder exists and can be written, every
//! file can be written, no two outputs of the run are the same file (a
//! `--trace` aimed at the run's own `report.json` is refused, not written
//! over), and what an earlier run of the command left in its folder is
//! removed first, so the folder ends with this run's files only and a failed
//! run leaves no stale file under a final name.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};

use super::{check_writable_file, prepare_out_dir};

/// Files a command owns in a subfolder of its output folder: every file of
/// `sub/` whose name ends with `suffix` (a dump's `passes/NN_*.exr`,
/// plan-motion's `plans/frame-KKK.json`), or with an empty suffix the whole
/// subfolder (aa-eval's `views/`, a folder per view). Removed before the run,
/// as the command writes a new set of them whose names depend on the run.
#[derive(Clone, Copy, Debug)]
pub struct Owned {
    pub sub: &'static str,
    pub suffix: &'static str,
}

#[derive(Clone, Debug)]
enum Output {
    /// A folder (`--out`) and the files the command writes into it.
    Folder {
        flag: &'static str,
        dir: PathBuf,
        files: Vec<String>,
        owned: Vec<Owned>,
    },
    /// A single file (`--trace`, `bench --report`).
    File { flag: &'static str, path: PathBuf },
}

/// The outputs of one command, declared before they are prepared.
#[derive(Clone, Debug, Default)]
pub struct OutputPaths {
    outputs: Vec<Output>,
}

impl OutputPaths {
    pub fn new() -> Self {
        Self::default()
    }

    /// The folder `dir` given by `flag`, with the files the command writes
    /// there (names, or `sub/name`) and the files it owns by pattern.
    pub fn folder(
        mut self,
        flag: &'static str,
        dir: &Path,
        files: &[&str],
        owned: &[Owned],
    ) -> Self {
        self.outputs.push(Output::Folder {
            flag,
            dir: dir.to_path_buf(),
            files: files.iter().map(|f| f.to_string()).collect(),
            owned: owned.to_vec(),
        });
        self
    }

    /// A single output file given by `flag` (none when `path` is `None`).
    pub fn file(mut self, flag: &'static str, path: Option<&Path>) -> Self {
        if let Some(p) = path {
            self.outputs.push(Output::File {
                flag,
                path: p.to_path_buf(),
            });
        }
        self
    }

    /// Checks and prepares every output (module docs), in one line per
    /// failure naming the flag.
    pub fn prepare(&self) -> Result<()> {
        // Folders first: the files' identities are taken in existing folders.
        for o in &self.outputs {
            match o {
                Output::Folder {
                    flag, dir, files, ..
                } => {
                    check_not_dangling(flag, dir)?;
                    if dir.exists() && !dir.is_dir() {
                        bail!("{flag} {} exists and is not a directory", dir.display());
                    }
                    prepare_out_dir(dir).with_context(|| format!("{flag} {}", dir.display()))?;
                    for f in files {
                        let path = dir.join(f);
                        if let Some(parent) =
                            Path::new(f).parent().filter(|p| !p.as_os_str().is_empty())
                        {
                            let sub = dir.join(parent);
                            if sub.exists() && !sub.is_dir() {
                                bail!("{flag}: {} exists and is not a directory", sub.display());
                            }
                        }
                        check_writable_file(&path).with_context(|| flag.to_string())?;
                    }
                }
                Output::File { flag, path } => {
                    check_not_dangling(flag, path)?;
                    super::prepare_file(path).with_context(|| flag.to_string())?;
                }
            }
        }
        self.check_distinct()?;
        for o in &self.outputs {
            if let Output::Folder {
                dir, files, owned, ..
            } = o
            {
                for f in files {
                    remove_regular_file(&dir.join(f))?;
                }
                for w in owned {
                    let sub = dir.join(w.sub);
                    // A link is not the command's own folder: left alone.
                    let real_dir = std::fs::symlink_metadata(&sub).is_ok_and(|m| m.is_dir());
                    if !real_dir {
                        continue;
                    }
                    if w.suffix.is_empty() {
                        std::fs::remove_dir_all(&sub).with_context(|| {
                            format!("removing {} (an earlier run's output)", sub.display())
                        })?;
                        continue;
                    }
                    let entries = std::fs::read_dir(&sub)
                        .with_context(|| format!("reading {}", sub.display()))?;
                    for e in entries {
                        let e = e.with_context(|| format!("reading {}", sub.display()))?;
                        if e.file_name().to_string_lossy().ends_with(w.suffix) {
                            remove_regular_file(&e.path())?;
                        }
                    }
                }
            }
        }
        crate::checks::ran("output paths");
        Ok(())
    }

    /// No two outputs name the same file (through links and `..` alike), and
    /// no single file lies in a subfolder a folder output owns.
    fn check_distinct(&self) -> Result<()> {
        let mut seen: BTreeMap<PathBuf, String> = BTreeMap::new();
        let mut owned_dirs: Vec<(PathBuf, String)> = Vec::new();
        for o in &self.outputs {
            let named: Vec<(PathBuf, String)> = match o {
                Output::Folder {
                    flag,
                    dir,
                    files,
                    owned,
                } => {
                    for w in owned {
                        owned_dirs.push((
                            identity(&dir.join(w.sub)),
                            format!(
                                "the {}/ files this run writes into {flag} {}",
                                w.sub,
                                dir.display()
                            ),
                        ));
                    }
                    files
                        .iter()
                        .map(|f| {
                            (
                                identity(&dir.join(f)),
                                format!("the {f} this run writes into {flag} {}", dir.display()),
                            )
                        })
                        .collect()
                }
                Output::File { flag, path } => {
                    vec![(identity(path), format!("{flag} {}", path.display()))]
                }
            };
            for (id, what) in named {
                if let Some(other) = seen.get(&id) {
                    bail!("{what} is the same file as {other}: give each output its own path");
                }
                if let Some((_, owner)) = owned_dirs.iter().find(|(d, _)| id.parent() == Some(d)) {
                    bail!("{what} lies among {owner}: give it a path outside that folder");
                }
                seen.insert(id, what);
            }
        }
        Ok(())
    }
}

/// A path that is a symbolic link to nothing: said as such (creating through
/// it would fail with a bare "File exists").
fn check_not_dangling(flag: &str, path: &Path) -> Result<()> {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if is_link && std::fs::metadata(path).is_err() {
        let to = std::fs::read_link(path)
            .map(|t| t.display().to_string())
            .unwrap_or_else(|_| "?".into());
        bail!(
            "{flag} {} is a symbolic link to {to}, which does not exist",
            path.display()
        );
    }
    Ok(())
}

/// The file `path` names, as one spelling: its folder made canonical (links
/// and `..` resolved; the folders exist by now) and, when the file itself is
/// a link, what it points to.
fn identity(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(parent), Some(name)) => {
            let parent = if parent.as_os_str().is_empty() {
                Path::new(".")
            } else {
                parent
            };
            match std::fs::canonicalize(parent) {
                Ok(p) => p.join(name),
                Err(_) => identity(parent).join(name),
            }
        }
        _ => path.to_path_buf(),
    }
}

/// Removes `path` if it is a regular file (an earlier run's output); a
/// device, link target or folder is left alone.
fn remove_regular_file(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_file() => std::fs::remove_file(path)
            .with_context(|| format!("removing {} (an earlier run's output)", path.display())),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("dermis-paths-{name}-"))
            .tempdir()
            .unwrap()
    }

    #[test]
    fn an_output_aimed_at_another_of_the_same_run_is_refused() {
        let d = tmp("same");
        let out = d.path().join("out");
        let trace = out.join("report.json");
        let e = OutputPaths::new()
            .folder("--out", &out, &["frame.png", "report.json"], &[])
            .file("--trace", Some(&trace))
            .prepare()
            .unwrap_err();
        let e = format!("{e:#}");
        assert!(e.contains("--trace") && e.contains("same file"), "{e}");
        // Through a `..` and a link too.
        std::os::unix::fs::symlink(&out, d.path().join("link")).unwrap();
        let e = OutputPaths::new()
            .folder("--out", &out, &["report.json"], &[])
            .file("--trace", Some(&d.path().join("link/../out/report.json")))
            .prepare()
            .unwrap_err();
        assert!(format!("{e:#}").contains("same file"), "{e:#}");
        // A file among the ones a folder owns by pattern.
        let e = OutputPaths::new()
            .folder(
                "--out",
                &out,
                &[],
                &[Owned {
                    sub: "passes",
                    suffix: ".exr",
                }],
            )
            .file("--trace", Some(&out.join("passes/t.json")))
            .prepare()
            .unwrap_err();
        assert!(format!("{e:#}").contains("passes/"), "{e:#}");
    }

    #[test]
    fn an_earlier_runs_files_go_and_others_stay() {
        let d = tmp("stale");
        let out = d.path().join("out");
        std::fs::create_dir_all(out.join("plans")).unwrap();
        for f in [
            "report.json",
            "plans/frame-000.json",
            "plans/frame-031.json",
            "mine.txt",
        ] {
            std::fs::write(out.join(f), b"old").unwrap();
        }
        OutputPaths::new()
            .folder(
                "--out",
                &out,
                &["report.json"],
                &[Owned {
                    sub: "plans",
                    suffix: ".json",
                }],
            )
            .prepare()
            .unwrap();
        assert!(!out.join("report.json").exists());
        assert!(!out.join("plans/frame-031.json").exists());
        // A file the command does not write is the user's.
        assert!(out.join("mine.txt").exists());
    }

    #[test]
    fn a_dangling_link_is_named_as_one() {
        let d = tmp("dangling");
        let out = d.path().join("out");
        std::os::unix::fs::symlink(d.path().join("gone"), &out).unwrap();
        let e = OutputPaths::new()
            .folder("--out", &out, &["report.json"], &[])
            .prepare()
            .unwrap_err();
        let e = format!("{e:#}");
        assert!(
            e.contains("symbolic link") && e.contains("does not exist"),
            "{e}"
        );
    }
}
