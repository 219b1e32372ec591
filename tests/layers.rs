//! The shape of the code, checked by reading it (no GPU): the layers of
//! `src/lib.rs` hold (a module uses only the ones below it), no two sibling
//! files import each other in a cycle, `render/mod.rs` stays small and long
//! functions say why. (That no code compares a pass label is checked in
//! tests/work_gpu.rs, on the labels the frames really have.)

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom up, as `src/lib.rs` documents them. A module may use
/// modules of its own layer index or lower; `run` and `report` share a layer.
const LAYERS: &[&[&str]] = &[
    &["files"],
    &["vk"],
    &["graph"],
    &["scene", "skin", "reference"],
    &["method"],
    &["render"],
    &["report", "bench", "run", "budget", "plot"],
    &["eval"],
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The file without its trailing `#[cfg(test)]` module (tests may reach anywhere).
fn code(path: &Path) -> String {
    let s = std::fs::read_to_string(path).unwrap();
    match s.find("#[cfg(test)]") {
        Some(i) => s[..i].to_string(),
        None => s,
    }
}

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// Top-level modules named by `crate::NAME` in `text`.
fn crate_refs(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find("crate::") {
        let tail = &rest[i + 7..];
        let name: String = tail
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if !name.is_empty() {
            out.insert(name);
        }
        rest = tail;
    }
    out
}

#[test]
fn layers_hold_and_modules_form_no_cycle() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let rel = f.strip_prefix(src()).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if ["lib", "main"].contains(&top.as_str()) {
            continue;
        }
        let from = layer(&top).unwrap_or_else(|| panic!("module '{top}' is in no layer of LAYERS"));
        for to in crate_refs(&code(f)) {
            if to == top {
                continue;
            }
            let l = layer(&to)
                .unwrap_or_else(|| panic!("{} uses crate::{to}, in no layer", rel.display()));
            assert!(
                l <= from,
                "{} (layer {from}) uses crate::{to} (layer {l}): a lower layer may not use a higher one",
                rel.display()
            );
            edges.entry(top.clone()).or_default().insert(to);
        }
    }
    // Within a layer, modules may use each other, but not in a cycle.
    assert_acyclic(&edges, "modules");
}

/// Sibling files of one folder (not counting its mod.rs, which declares them)
/// must not import each other in a cycle.
#[test]
fn sibling_files_form_no_cycle() {
    let mut dirs = vec![src()];
    let mut checked = 0;
    while let Some(d) = dirs.pop() {
        let mut siblings = Vec::new();
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "rs")
                && !["mod.rs", "lib.rs", "main.rs"]
                    .contains(&p.file_name().unwrap().to_str().unwrap())
            {
                siblings.push(p);
            }
        }
        let names: Vec<String> = siblings
            .iter()
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (p, name) in siblings.iter().zip(&names) {
            let text = code(p);
            for other in &names {
                if other != name
                    && (text.contains(&format!("super::{other}::"))
                        || text.contains(&format!("super::{other}::{{"))
                        || text.contains(&format!("use super::{other};")))
                {
                    edges.entry(name.clone()).or_default().insert(other.clone());
                }
            }
        }
        assert_acyclic(&edges, &d.display().to_string());
        checked += siblings.len();
    }
    assert!(checked > 50, "{checked}");
}

fn assert_acyclic(edges: &BTreeMap<String, BTreeSet<String>>, what: &str) {
    // Depth-first search with colours: a grey node reached again is a cycle.
    fn visit(
        n: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        colour: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
        what: &str,
    ) {
        match colour.get(n) {
            Some(1) => panic!("import cycle in {what}: {} -> {n}", path.join(" -> ")),
            Some(2) => return,
            _ => {}
        }
        colour.insert(n.to_string(), 1);
        path.push(n.to_string());
        for m in edges.get(n).into_iter().flatten() {
            visit(m, edges, colour, path, what);
        }
        path.pop();
        colour.insert(n.to_string(), 2);
    }
    let mut colour = BTreeMap::new();
    for n in edges.keys() {
        visit(n, edges, &mut colour, &mut Vec::new(), what);
    }
}

#[test]
fn the_renderer_stays_small_and_long_functions_say_why() {
    let render = std::fs::read_to_string(src().join("render/mod.rs")).unwrap();
    let lines = render.lines().count();
    assert!(lines < 600, "render/mod.rs has {lines} lines");
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let all: Vec<&str> = text.lines().collect();
        for (i, l) in all.iter().enumerate() {
            let t = l.trim_start();
            let is_fn = (t.starts_with("fn ")
                || t.starts_with("pub fn ")
                || t.starts_with("pub(crate) fn "))
                && !t.ends_with(';');
            if !is_fn {
                continue;
            }
            let indent = l.len() - t.len();
            // The function ends at the first line closing at its indentation.
            let end = all[i + 1..]
                .iter()
                .position(|m| {
                    m.len() - m.trim_start().len() == indent && m.trim_start().starts_with('}')
                })
                .map_or(all.len(), |k| i + 1 + k);
            let len = end - i;
            let reason = all[i.saturating_sub(6)..i]
                .iter()
                .any(|c| c.contains("Long because"));
            assert!(
                len <= 150 || reason,
                "{}:{}: a function of {len} lines needs a comment saying why (\"Long because ...\")",
                f.display(),
                i + 1
            );
        }
    }
}
