//! Every pass's declared work against the shader it describes: each method's
//! frame runs with the fetch-counting build of its shaders (lavapipe,
//! validation on), pass by pass, and the fetches each shader really made are
//! held to what its pass declares: exact counts exactly, upper bounds as bounds,
//! and no fetch that is not declared.

use crate::common;

use std::collections::BTreeMap;

use dermis::aa::edges::Preset;
use dermis::graph::work::Work;
use dermis::method::METHODS;
use dermis::post::{AaMode, EdgeSource};
use dermis::render::counting::{filter_kind, site};
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::egg_scene;
use dermis::vk::shader::reflect;

/// Renders `s` with the fetch-counting build and holds every pass's counted
/// fetches to its declaration; the passes checked.
fn check_declarations(
    ctx: &dermis::vk::context::Context,
    scene: &dermis::scene::Scene,
    label: &str,
    s: RenderSettings,
) -> usize {
    let mut checked = 0;
    let s = RenderSettings {
        width: 96,
        height: 64,
        shadow_size: 128,
        distance_heads: 1.5,
        ..s
    };
    let mut r = Renderer::new(ctx, scene, &s).unwrap();
    let counts = r.count_fetches().unwrap();
    let passes = r.passes();
    assert_eq!(counts.len(), passes.len());
    for (c, p) in counts.iter().zip(&passes) {
        let at = format!("{label}: pass '{}'", p.name);
        let work = p.declared_work(&r.resources);
        let shader = match &work {
            Some(Work::Raster {
                shader: Some(sh), ..
            }) => sh,
            Some(Work::Compute { shader, .. }) => shader,
            _ => {
                assert_eq!(c.invocations, 0, "{at}: runs no shader");
                assert!(c.fetches.is_empty(), "{at}: {:?}", c.fetches);
                continue;
            }
        };
        let refl = reflect(&[&shader.shader]).unwrap();
        // Declared fetches per counter site: (exact sum, bound sum, all exact).
        let mut declared: BTreeMap<u32, (f64, bool)> = BTreeMap::new();
        for f in &shader.fetches {
            let b = refl
                .bindings
                .iter()
                .find(|b| b.name == f.texture)
                .unwrap_or_else(|| {
                    panic!(
                        "{at}: {} declares '{}', which it has no binding for",
                        shader.shader, f.texture
                    )
                });
            let e = declared
                .entry(site(b.set, b.binding, filter_kind(f.filter)))
                .or_insert((0.0, true));
            e.0 += f.count;
            e.1 &= f.exact;
        }
        let n = c.invocations as f64;
        let counted: BTreeMap<u32, u64> = c.fetches.iter().copied().collect();
        for (s, &got) in &counted {
            assert!(
                declared.contains_key(s),
                "{at}: site {s} fetched {got} times but is not declared ({:?})",
                shader.fetches
            );
        }
        for (s, &(per, exact)) in &declared {
            let got = counted.get(s).copied().unwrap_or(0) as f64;
            if exact {
                assert_eq!(
                    got,
                    per * n,
                    "{at}: site {s}: {got} fetches for {n} invocations, {per} declared each"
                );
            } else {
                assert!(
                    got <= per * n,
                    "{at}: site {s}: {got} fetches exceed the bound {per} x {n}"
                );
            }
        }
        checked += 1;
    }
    checked
}

// The wrinkle maps' fetches (thesis ch. 8): the geometry pass, texture
// space's irradiance and both of the ground truth's shading passes read them
// where an expression weighs a zone, and declare them.
#[test]
fn wrinkle_fetches_are_declared() {
    let ctx = common::counting_ctx();
    let mut scene = dermis::scene::face::face_scene();
    scene
        .set_morph_weights(&[("surprise".into(), 1.0), ("disgust".into(), 0.5)])
        .unwrap();
    let mut checked = 0;
    for (name, options) in [
        ("separable", &[][..]),
        ("tsd", &[]),
        ("reference", &[("density", "2")]),
    ] {
        let s = RenderSettings::study().with(common::m(name), options);
        checked += check_declarations(&ctx, &scene, &format!("{name} wrinkled"), s);
    }
    assert!(checked >= 10, "{checked}");
}

#[test]
fn declared_fetches_are_what_the_shaders_fetch() {
    let ctx = common::counting_ctx();
    let scene = egg_scene();
    let mut checked = 0;
    for m in METHODS {
        let mut settings: Vec<(String, RenderSettings)> = m
            .eval
            .iter()
            .map(|e| {
                (
                    format!("{} {}", m.name, e.label),
                    RenderSettings::study().with(m, e.options),
                )
            })
            .collect();
        if m.ground_truth {
            settings.push((
                m.name.to_string(),
                RenderSettings::study().with(m, &[("density", "2")]),
            ));
        }
        // The compute path's dispatches (tiles, blurs, merge) where the
        // method has one.
        if m.options.iter().any(|o| o.key == "path") {
            settings.push((
                format!("{} --path compute", m.name),
                RenderSettings::study().with(m, &[("path", "compute")]),
            ));
        }
        // The post chain's stages, once (they follow every method alike).
        if std::ptr::eq(*m, METHODS[0]) {
            for aa in [AaMode::Mlaa, AaMode::Fxaa, AaMode::Smaa] {
                let s = RenderSettings::study().with(m, &[]);
                settings.push((format!("{} --aa {aa}", m.name), RenderSettings { aa, ..s }));
            }
            let mut s = RenderSettings::study().with(m, &[]);
            s.post.bloom = true;
            settings.push((format!("{} --bloom", m.name), s));
            let mut s = RenderSettings::study().with(m, &[]);
            s.aa = AaMode::Mlaa;
            s.post.aa_edges = Some(EdgeSource::Depth);
            settings.push((format!("{} --aa mlaa --aa-edges depth", m.name), s));
            for (preset, edges) in [
                (Preset::Low, EdgeSource::Luma),
                (Preset::Ultra, EdgeSource::Color),
            ] {
                let mut s = RenderSettings::study().with(m, &[]);
                s.aa = AaMode::Smaa;
                s.post.aa_edges = Some(edges);
                s.post.smaa_preset = Some(preset);
                settings.push((format!("{} --aa smaa {preset:?} {edges}", m.name), s));
            }
            // The multisampled geometry pass shades once a pixel: its
            // declared fetches hold at 4x too (lavapipe's one count above 1).
            let s = RenderSettings::study().with(m, &[]);
            settings.push((
                format!("{} --msaa 4", m.name),
                RenderSettings { msaa: 4, ..s },
            ));
        }
        // Post-scatter texturing's geometry and composite variants, with the
        // normal target (poisson) and without (the first method).
        if std::ptr::eq(*m, METHODS[0]) || m.name == "poisson" {
            let s = RenderSettings::study().with(m, &[]);
            settings.push((
                format!("{} --texturing post", m.name),
                RenderSettings {
                    texturing: dermis::render::settings::Texturing::Post,
                    ..s
                },
            ));
        }
        for (label, s) in settings {
            checked += check_declarations(&ctx, &scene, &label, s);
        }
    }
    println!("{checked} pass declarations checked against their shaders");
    assert!(checked > 40, "{checked}");
}

fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Labels name passes; behaviour keys on roles, declared work and marks
/// (`Pass::merge`). So no code outside tests compares a string with a pass's
/// label: collected here from every method's frame and from a frame of
/// several methods with a fade, as recorded (a group's `#N ` dropped, then up
/// to the first digit, so "#2 ssg g2 horizontal" stands for every
/// Gaussian's pass of every group, and "mix merge #1" for every merge).
#[test]
fn no_code_compares_a_pass_label() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let small = || RenderSettings {
        width: 64,
        height: 40,
        shadow_size: 64,
        ..RenderSettings::study()
    };
    let mut frames: Vec<RenderSettings> = METHODS
        .iter()
        .map(|m| small().with(m, &[("density", "1")]))
        .collect();
    let fade = r#"{"version":1,"characters":3,"assignments":[
        {"character":0,"method":"separable","fade":{"method":"ssg","weight":0.5}},
        {"character":1,"method":"poisson"},{"character":2,"method":"ss-jittered"}]}"#;
    frames.push(RenderSettings {
        heads: 3,
        assignment: Some(dermis::render::settings::Assignment::Plan(
            serde_json::from_str(fade).unwrap(),
        )),
        ..small()
    });
    let mut labels = std::collections::BTreeSet::new();
    for s in &frames {
        let r = Renderer::new(&ctx, &scene, s).unwrap();
        for p in r.passes() {
            let name = p.name.as_str();
            let name = match name.strip_prefix('#') {
                Some(rest) => rest
                    .trim_start_matches(|c: char| c.is_ascii_digit())
                    .trim_start(),
                None => name,
            };
            let label: String = name.chars().take_while(|c| !c.is_ascii_digit()).collect();
            labels.insert(label.trim_end_matches([' ', '#']).to_string());
        }
    }
    labels.extend([
        "readback".to_string(),
        "upload".to_string(),
        "fill".to_string(),
    ]);
    assert!(
        labels.contains("sss horizontal")
            && labels.contains("ssg g")
            && labels.contains("mix merge")
            && labels.contains("fade blend"),
        "{labels:?}"
    );
    let mut files = Vec::new();
    rust_files(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &mut files,
    );
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        // Unit tests may name passes: they test labels.
        let text = text.split("#[cfg(test)]").next().unwrap_or_default();
        for label in &labels {
            for op in [
                "== \"",
                "!= \"",
                "starts_with(\"",
                "ends_with(\"",
                "contains(\"",
                "strip_prefix(\"",
            ] {
                let needle = format!("{op}{label}");
                assert!(
                    !text.contains(&needle),
                    "{} compares with the pass label '{label}' ({needle})",
                    f.display()
                );
            }
            assert!(
                !text.contains(&format!("\"{label}\" =>"))
                    && !text.contains(&format!("\"{label}\" |")),
                "{} matches on the pass label '{label}'",
                f.display()
            );
        }
    }
}
