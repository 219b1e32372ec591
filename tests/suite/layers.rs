//! The shape of the code, checked by reading it (no GPU): the layers of
//! `src/lib.rs` hold (a module uses only the ones below it), the pure core and
//! the pure files above it name neither `ash`, `crate::vk` nor `crate::graph`,
//! no two sibling files import each other in a cycle, `render/mod.rs` stays
//! small and long functions say why. (That no code compares a pass label is
//! checked in tests/suite/work.rs, on the labels the frames really have.)
//!
//! The checks read paths, not text: comments and string literals are dropped,
//! grouped imports (`use crate::{a, b::{c, d}}`) are expanded, and `super::`
//! and `self::` are resolved against the file's own module, so every way of
//! naming a module is seen. The reader is tested on small sources below.
//!
//! Why a rule checked here and not a workspace crate for the device-free core:
//! the pure modules share the crate's error and serde conventions and are
//! named by about a hundred `crate::` paths across the tree; a crate split
//! would rewrite every one of them while six branches edit the same files.
//! The rule below states the same boundary and fails on the first path that
//! crosses it; a crate can follow once the tree is quiet.
//!
//! Over 800 lines because every rule shares the one reader of paths above
//! it, and the reader's own tests sit beside it: split, each part would need
//! the reader again.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

// The layers, bottom up, written once in `src/lib.rs`. A module may use
// modules of its own layer index or lower. The bottom layer is the pure core:
// it cannot name `vk` or `graph`, which sit above it.
use dermis::LAYERS;

/// Files above the pure core that must stay pure too (paths under `src/`).
const PURE_FILES: &[&str] = &[
    "eval/metrics.rs",
    "eval/supersample.rs",
    "post/bloom_pyramid.rs",
    "budget/model.rs",
    "budget/msaa.rs",
    "budget/table91.rs",
    "plan/cost.rs",
    "plan/character.rs",
    "plan/choose.rs",
    "plan/solve.rs",
    "plan/dolly.rs",
    "plan/over_time.rs",
    "plan/fades.rs",
    "plan/skin_patches.rs",
    "plan/price_grid.rs",
];

/// What no pure file may name: the Vulkan bindings, and the crate's device
/// and graph layers.
const FORBIDDEN: &[&[&str]] = &[&["ash"], &["crate", "vk"], &["crate", "graph"]];

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
    without_tests(&s).to_string()
}

fn without_tests(s: &str) -> &str {
    match s.find("#[cfg(test)]") {
        Some(i) => &s[..i],
        None => s,
    }
}

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The module path of a file under `src/`: `skin/ssg.rs` is `[skin, ssg]`,
/// `skin/mod.rs` is `[skin]`, `lib.rs` is `[]`.
fn module_of(rel: &Path) -> Vec<String> {
    let mut m: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let last = m.pop().unwrap_or_default();
    let stem = last.trim_end_matches(".rs");
    if !["mod", "lib", "main"].contains(&stem) {
        m.push(stem.to_string());
    }
    m
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    Path, // `::`
    Open,
    Close,
    Comma,
    Other,
}

/// Identifiers and the punctuation paths are made of; comments, string and
/// character literals dropped (a path named in a comment names nothing).
fn tokens(text: &str) -> Vec<Tok> {
    let c: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        let next = c.get(i + 1).copied();
        if ch == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && next == Some('*') {
            // Block comments nest in Rust.
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if ch == '"' || (ch == 'r' && (next == Some('"') || next == Some('#'))) {
            i = skip_string(&c, i);
            out.push(Tok::Other);
        } else if ch == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            let close = if c.get(i + 1) == Some(&'\\') {
                c[i + 2..]
                    .iter()
                    .position(|&x| x == '\'')
                    .map(|k| i + 2 + k)
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(k) => i = k + 1,
                None => i += 1,
            }
            out.push(Tok::Other);
        } else if ch.is_alphabetic() || ch == '_' {
            let s = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            out.push(Tok::Ident(c[s..i].iter().collect()));
        } else if ch.is_ascii_digit() {
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_' || c[i] == '.') {
                i += 1;
            }
            out.push(Tok::Other);
        } else if ch.is_whitespace() {
            i += 1;
        } else {
            out.push(match ch {
                ':' if next == Some(':') => {
                    i += 1;
                    Tok::Path
                }
                '{' => Tok::Open,
                '}' => Tok::Close,
                ',' => Tok::Comma,
                _ => Tok::Other,
            });
            i += 1;
        }
    }
    out
}

/// Index after the string literal starting at `i` (plain, byte or raw).
fn skip_string(c: &[char], mut i: usize) -> usize {
    if c[i] == 'r' {
        let mut hashes = 0;
        i += 1;
        while c.get(i) == Some(&'#') {
            hashes += 1;
            i += 1;
        }
        if c.get(i) != Some(&'"') {
            return i; // `r#ident`, not a string
        }
        i += 1;
        while i < c.len() {
            if c[i] == '"' && (0..hashes).all(|h| c.get(i + 1 + h) == Some(&'#')) {
                return i + 1 + hashes;
            }
            i += 1;
        }
        return i;
    }
    i += 1;
    while i < c.len() {
        match c[i] {
            '\\' => i += 2,
            '"' => return i + 1,
            _ => i += 1,
        }
    }
    i
}

/// Every path in `text`, grouped imports expanded: `use a::{b, c::{d, e}}`
/// gives `a::b`, `a::c::d`, `a::c::e`; `self` inside a group names its
/// parent; a glob ends the path at its parent.
fn paths(text: &str) -> Vec<Vec<String>> {
    let t = tokens(text);
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let after_keyword = i > 0 && matches!(&t[i - 1], Tok::Ident(k) if is_keyword(k));
        let starts = match &t[i] {
            Tok::Ident(k) => !is_keyword(k) && (i == 0 || t[i - 1] != Tok::Path),
            // A leading `::` (`use ::ash::vk`) starts an absolute path.
            Tok::Path => {
                matches!(t.get(i + 1), Some(Tok::Ident(_)))
                    && (i == 0 || after_keyword || !matches!(t[i - 1], Tok::Ident(_) | Tok::Close))
            }
            _ => false,
        };
        if starts {
            let from = if t[i] == Tok::Path { i + 1 } else { i };
            i = tree(&t, from, Vec::new(), &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// Rust keywords that may stand before a path but never begin one
/// (`crate`, `self`, `super` and `Self` do begin paths).
fn is_keyword(w: &str) -> bool {
    [
        "as", "async", "await", "break", "const", "continue", "dyn", "else", "enum", "extern",
        "fn", "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub",
        "ref", "return", "static", "struct", "trait", "type", "unsafe", "use", "where", "while",
    ]
    .contains(&w)
}

/// Reads one path tree at `i` under `prefix`, pushing each leaf path; returns
/// the index after it.
fn tree(t: &[Tok], mut i: usize, mut prefix: Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    loop {
        match t.get(i) {
            Some(Tok::Ident(name)) => {
                if name != "self" || prefix.is_empty() {
                    prefix.push(name.clone());
                }
                i += 1;
            }
            Some(Tok::Open) if !prefix.is_empty() => {
                // A group: subtrees separated by commas, up to the closing brace.
                i += 1;
                loop {
                    match t.get(i) {
                        Some(Tok::Close) => {
                            i += 1;
                            break;
                        }
                        Some(Tok::Comma) => i += 1,
                        // `b as c`: the new name is no path.
                        Some(Tok::Ident(k)) if k == "as" => i += 2,
                        Some(Tok::Ident(_)) | Some(Tok::Open) => {
                            i = tree(t, i, prefix.clone(), out);
                        }
                        None => break,
                        _ => i += 1, // `*`, `as` renames are idents, handled above
                    }
                }
                return i;
            }
            _ => {
                out.push(prefix);
                return i;
            }
        }
        if t.get(i) == Some(&Tok::Path) {
            i += 1;
        } else {
            // `a::b as c`: the rename names nothing more.
            out.push(prefix);
            return i;
        }
    }
}

/// A path made absolute: `crate::...` as written; `super::`/`self::` against
/// `module` (the file's module path), each `super` one level up; other paths
/// (`ash::vk`, `std::..`, local names) as written.
fn resolve(path: &[String], module: &[String]) -> Vec<String> {
    let mut p = path;
    let mut base: Vec<String> = module.to_vec();
    let mut relative = false;
    while let Some(first) = p.first() {
        match first.as_str() {
            "super" => {
                base.pop();
                relative = true;
            }
            "self" => relative = true,
            _ => break,
        }
        p = &p[1..];
    }
    if !relative {
        return path.to_vec();
    }
    let mut out = vec!["crate".to_string()];
    out.extend(base);
    out.extend(p.iter().cloned());
    out
}

/// Every path `text` names, absolute (see [`resolve`]), in a file of module `module`.
fn named(text: &str, module: &[String]) -> Vec<Vec<String>> {
    paths(text).iter().map(|p| resolve(p, module)).collect()
}

/// Top-level crate modules `text` names (`crate::NAME...`).
fn crate_modules(text: &str, module: &[String]) -> BTreeSet<String> {
    named(text, module)
        .into_iter()
        .filter(|p| p.len() >= 2 && p[0] == "crate")
        .map(|p| p[1].clone())
        .collect()
}

/// The forbidden paths a pure file names, as written out (`crate::vk::x`).
fn impurities(text: &str, module: &[String]) -> Vec<String> {
    named(text, module)
        .into_iter()
        .filter(|p| {
            FORBIDDEN
                .iter()
                .any(|f| p.len() >= f.len() && p[..f.len()].iter().zip(*f).all(|(a, b)| a == b))
        })
        .map(|p| p.join("::"))
        .collect()
}

/// The file under `src/` a crate path leads to: its longest prefix that is a
/// module file (`crate::skin::ssg::Stretch` -> skin/ssg.rs).
fn file_of(path: &[String]) -> Option<PathBuf> {
    if path.first().map(String::as_str) != Some("crate") {
        return None;
    }
    (2..=path.len()).rev().find_map(|k| {
        let base = src().join(path[1..k].join("/"));
        [base.with_extension("rs"), base.join("mod.rs")]
            .into_iter()
            .find(|c| c.is_file())
    })
}

/// Whether a file (path under `src/`) must be pure.
fn must_be_pure(rel: &Path) -> bool {
    let m = module_of(rel);
    let top = m.first().map(String::as_str).unwrap_or("");
    layer(top) == Some(0) || PURE_FILES.iter().any(|f| rel == Path::new(f))
}

#[test]
fn the_reader_sees_grouped_nested_and_relative_paths() {
    let m = |s: &str| s.split("::").map(String::from).collect::<Vec<_>>();
    let skin_ssg = m("skin::ssg");
    // A grouped import naming vk is caught, however deep the group.
    let grouped = "use crate::{scene::mesh::Mesh, vk::context::Context};";
    assert_eq!(
        impurities(grouped, &skin_ssg),
        vec!["crate::vk::context::Context"]
    );
    let nested = "use crate::{a::{b, c::{d, e}}, graph::{self, Pass}};";
    assert_eq!(
        named(nested, &skin_ssg),
        vec![
            m("crate::a::b"),
            m("crate::a::c::d"),
            m("crate::a::c::e"),
            m("crate::graph"),
            m("crate::graph::Pass")
        ]
    );
    assert_eq!(
        impurities(nested, &skin_ssg),
        vec!["crate::graph", "crate::graph::Pass"]
    );
    // super::super:: climbs out of the module, to the crate root here.
    let up = "fn f() -> super::super::vk::memory::Buffer { todo!() }";
    assert_eq!(impurities(up, &skin_ssg), vec!["crate::vk::memory::Buffer"]);
    assert_eq!(
        crate_modules("use super::profile::X;", &skin_ssg),
        BTreeSet::from(["skin".to_string()])
    );
    // ash by any spelling.
    for s in [
        "use ash::vk;",
        "let f = ash::vk::Format::UNDEFINED;",
        "use ::ash::{vk, Device};",
        "use {ash::vk};",
    ] {
        assert!(!impurities(s, &skin_ssg).is_empty(), "{s}");
    }
    // Words in comments and strings name nothing; a clean file is clean.
    let clean = "//! Not `crate::vk`.\n/* use crate::graph; /* nested */ */\nuse crate::scene::mesh::{Aabb, Mesh};\nconst S: &str = \"crate::vk::x\"; const R: &str = r#\"ash::vk\"#; fn g<'a>(c: char) -> bool { c == '\"' || c == '{' }";
    assert!(
        impurities(clean, &skin_ssg).is_empty(),
        "{:?}",
        impurities(clean, &skin_ssg)
    );
    assert_eq!(
        crate_modules(clean, &skin_ssg),
        BTreeSet::from(["scene".to_string()])
    );
    // A path after a method call or a type's own path is not a new path.
    assert!(impurities("let x = a.vk::<u8>(); let y = Foo::vk;", &skin_ssg).is_empty());
}

/// tools/build.rs compiles src/shader_constants.rs on its own (`#[path]`), so
/// it may name nothing of the crate and import nothing but std.
#[test]
fn the_shader_constants_stand_alone() {
    let text = code(&src().join("shader_constants.rs"));
    let module = module_of(Path::new("shader_constants.rs"));
    let foreign: Vec<String> = named(&text, &module)
        .into_iter()
        .filter(|p| p.len() >= 2 && p[0] == "crate")
        .map(|p| p.join("::"))
        .collect();
    assert!(foreign.is_empty(), "{foreign:?}");
    let t = tokens(&text);
    for (i, tok) in t.iter().enumerate() {
        if *tok == Tok::Ident("use".into()) {
            assert_eq!(
                t.get(i + 1),
                Some(&Tok::Ident("std".into())),
                "shader_constants.rs imports beyond std"
            );
        }
    }
}

/// Every shader is named after what owns it: a method module (`separable_*`,
/// `poisson_*`, ... as in `src/method/`), a pass of the frame around the
/// methods, the bench's probes, or an include shared across owners.
#[test]
fn shaders_are_named_after_their_owner() {
    let methods: Vec<String> = std::fs::read_dir(src().join("method"))
        .unwrap()
        .map(|e| e.unwrap().path())
        // A method is a file or a folder with its own mod.rs (tsd/, reference/).
        .filter(|p| p.extension().is_some_and(|x| x == "rs") || p.join("mod.rs").is_file())
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .filter(|m| !["mod", "options", "region", "screen", "none"].contains(&m.as_str()))
        .collect();
    // The frame's own passes and the bench's probes.
    let frame = [
        "fullscreen",
        "shadow",
        "geometry",
        "composite",
        "tonemap",
        "probe",
        "deform",
    ];
    // The post chain's stages (`src/post/`, one file each) and their shared include.
    let post: Vec<String> = std::fs::read_dir(src().join("post"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .map(|m| if m == "mod" { "post".to_string() } else { m })
        .collect();
    // Includes whose facts several owners share.
    let shared = [
        "shader_constants",
        "view_scale",
        "tissue",
        "lighting",
        "frame_uniforms",
        "fetch_count",
        "driver_workarounds",
        "screen_common",
    ];
    let dir = src().parent().unwrap().join("shaders");
    let mut seen = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        let stem = name.split('.').next().unwrap();
        let owned = |p: &str| stem == p || stem.starts_with(&format!("{p}_"));
        assert!(
            methods.iter().any(|m| owned(m))
                || frame.iter().any(|p| owned(p))
                || post.iter().any(|p| owned(p))
                || shared.contains(&stem),
            "shaders/{name} is named after no method, frame pass or shared include"
        );
        seen += 1;
    }
    assert!(
        seen > 30 && methods.contains(&"separable".to_string()),
        "{seen} {methods:?}"
    );
}

#[test]
fn the_module_of_a_file() {
    assert_eq!(module_of(Path::new("skin/ssg.rs")), ["skin", "ssg"]);
    assert_eq!(module_of(Path::new("skin/mod.rs")), ["skin"]);
    assert!(module_of(Path::new("lib.rs")).is_empty());
    assert!(must_be_pure(Path::new("skin/ssg.rs")) && must_be_pure(Path::new("budget/model.rs")));
    assert!(
        !must_be_pure(Path::new("budget/units.rs")) && !must_be_pure(Path::new("method/mod.rs"))
    );
    let m = |s: &str| s.split("::").map(String::from).collect::<Vec<_>>();
    assert_eq!(
        file_of(&m("crate::skin::ssg::Stretch")),
        Some(src().join("skin/ssg.rs"))
    );
    assert_eq!(
        file_of(&m("crate::graph::work::Format")),
        Some(src().join("graph/mod.rs"))
    );
    assert_eq!(
        file_of(&m("crate::work::Format")),
        Some(src().join("work.rs"))
    );
    assert_eq!(file_of(&m("std::fmt")), None);
}

/// The pure core (the bottom layer) and the pure files above it name neither
/// `ash`, `crate::vk` nor `crate::graph`, nor reach them through any file
/// they lead to: pure math cannot reach Vulkan.
#[test]
fn pure_math_names_no_vulkan() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut checked = 0;
    let mut bad = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(src()).unwrap();
        if !must_be_pure(rel) {
            continue;
        }
        checked += 1;
        for p in impurities(&code(f), &module_of(rel)) {
            bad.push(format!("{} names {p}", rel.display()));
        }
    }
    assert!(
        bad.is_empty(),
        "pure files name Vulkan:\n{}",
        bad.join("\n")
    );
    // Nor through another file: every file a pure file's paths lead to is
    // pure too (`crate::graph::work::X` leads to graph/mod.rs, which is not).
    for f in &files {
        let rel = f.strip_prefix(src()).unwrap();
        if !must_be_pure(rel) {
            continue;
        }
        let mut seen = BTreeSet::from([f.clone()]);
        let mut todo = vec![(f.clone(), rel.display().to_string())];
        while let Some((g, chain)) = todo.pop() {
            let grel = g.strip_prefix(src()).unwrap().to_path_buf();
            let text = code(&g);
            let module = module_of(&grel);
            if let Some(p) = impurities(&text, &module).first() {
                bad.push(format!("{chain} names {p}"));
            }
            for path in named(&text, &module) {
                if let Some(h) = file_of(&path).filter(|h| !seen.contains(h)) {
                    seen.insert(h.clone());
                    let next = format!("{chain} -> {}", h.strip_prefix(src()).unwrap().display());
                    todo.push((h, next));
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "pure files reach Vulkan:\n{}",
        bad.join("\n")
    );
    for f in PURE_FILES {
        assert!(
            src().join(f).is_file(),
            "PURE_FILES names {f}, which is gone"
        );
    }
    assert!(checked > 30, "{checked}");
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
        for to in crate_modules(&code(f), &module_of(rel)) {
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

/// The one list names every module `src/lib.rs` declares, each once. (A
/// listed module without files yet, such as `app` before the command wing
/// lands, constrains nothing: the rules above read files.)
#[test]
fn the_layer_list_names_every_module_once() {
    let lib = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    let declared: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ")?.strip_suffix(';'))
        .collect();
    assert!(declared.len() > 20, "{declared:?}");
    for m in &declared {
        assert!(
            layer(m).is_some(),
            "src/lib.rs declares `{m}`, which no layer of LAYERS lists"
        );
    }
    let mut listed: Vec<&str> = LAYERS.iter().flat_map(|l| l.iter().copied()).collect();
    let n = listed.len();
    listed.sort_unstable();
    listed.dedup();
    assert_eq!(listed.len(), n, "LAYERS lists a module twice");
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
            let rel = p.strip_prefix(src()).unwrap();
            let module = module_of(rel);
            // The folder's own module path: a sibling is one more segment.
            let mut folder = vec!["crate".to_string()];
            folder.extend(module[..module.len() - 1].iter().cloned());
            for path in named(&code(p), &module) {
                let n = folder.len();
                if path.len() > n && path[..n] == folder[..] {
                    let other = &path[n];
                    if other != name && names.contains(other) {
                        edges.entry(name.clone()).or_default().insert(other.clone());
                    }
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
            // A signature over several lines that ends in `;` before any `{` is
            // a declaration (a trait's method): it has no body to measure.
            let declared_only = all[i..]
                .iter()
                .find(|m| m.contains('{') || m.trim_end().ends_with(';'))
                .is_some_and(|m| !m.contains('{'));
            if declared_only {
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

/// No source file over 800 lines without a reason at its top ("Over 800
/// lines because ..." in its leading `//!` doc): in src/, tests/ and tools/.
#[test]
fn long_files_say_why() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for d in ["src", "tests", "tools"] {
        rust_files(&root.join(d), &mut files);
    }
    let mut unexplained = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let n = text.lines().count();
        let reason = text
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .any(|l| l.contains("Over 800 lines because"));
        if n > 800 && !reason {
            unexplained.push(format!("{} ({n} lines)", f.display()));
        }
    }
    assert!(
        unexplained.is_empty(),
        "files over 800 lines with no reason at their top (\"Over 800 lines because ...\"): {unexplained:?}"
    );
}
