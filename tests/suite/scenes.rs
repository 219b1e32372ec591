//! Whole frames on lavapipe with validation (synchronization validation on):
//! the default scene, the Lee Perry-Smith head, many heads, and a scene with no
//! skin, checked for finite, non-constant output and sane reports.

use crate::common;

use dermis::render::RenderSettings;
use dermis::run::{run, FrameCounts, RunOptions};
use dermis::scene::gltf_load::TextureOverrides;
use dermis::scene::{default_scene, load_gltf_scene, Scene};

fn opts(capture: bool) -> RunOptions {
    RunOptions {
        frames: FrameCounts::new(1, 2).unwrap(),
        capture,
        dump: capture,
        ceilings: false,
        command: "test".into(),
        progress: false,
    }
}

fn small() -> RenderSettings {
    RenderSettings {
        width: 160,
        height: 96,
        shadow_size: 256,
        ..RenderSettings::study()
    }
}

/// Renders and checks the frame and the report; returns the report for more checks.
fn render_and_check(scene: &Scene, s: &RenderSettings) -> dermis::run::Report {
    let ctx = common::ctx();
    let out = run(&ctx, scene, s, &opts(true)).expect("render");
    let r = out.report;
    let cap = out.capture.expect("capture");
    assert_eq!(cap.ldr.len(), (s.width * s.height * 4) as usize);
    // Non-constant: the frame holds many distinct colours, not a clear colour.
    let mut distinct: Vec<[u8; 3]> = cap
        .ldr
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    distinct.sort();
    distinct.dedup();
    assert!(
        distinct.len() > 50,
        "only {} distinct colours",
        distinct.len()
    );
    // Every pass output is finite (the dumps are linear float).
    assert!(!cap.dumps.is_empty());
    for d in &cap.dumps {
        assert!(
            d.rgba.iter().flatten().all(|v| v.is_finite()),
            "{} -> {} has non-finite texels",
            d.pass,
            d.image
        );
    }
    // The report: every pass timed, the frame total the sum.
    assert_eq!(r.run.width, s.width);
    assert!(!r.passes.is_empty());
    for p in &r.passes {
        assert!(
            p.gpu_ms.median > 0.0 && p.gpu_ms.min > 0.0,
            "pass {} has no time",
            p.name
        );
        assert!(p.gpu_ms.min <= p.gpu_ms.median && p.gpu_ms.median <= p.gpu_ms.p95);
    }
    let json = serde_json::to_value(&r).unwrap();
    for key in [
        "device",
        "driver",
        "width",
        "height",
        "method",
        "warmup_frames",
        "measured_frames",
        "passes",
        "frame",
    ] {
        assert!(json.get(key).is_some(), "report lacks {key}");
    }
    r
}

fn skin_samples(r: &dermis::run::Report, pass: &str) -> u64 {
    r.passes
        .iter()
        .find(|p| p.name == pass)
        .unwrap_or_else(|| panic!("no pass {pass}"))
        .samples_passed
}

#[test]
fn default_scene_renders() {
    let r = render_and_check(&default_scene(), &small());
    let names: Vec<&str> = r.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "shadow map",
            "geometry",
            "sss seed copy",
            "sss horizontal",
            "sss vertical",
            "composite",
            "tonemap"
        ]
    );
    let skin = skin_samples(&r, "sss horizontal");
    assert!(skin > 500 && skin < 160 * 96, "skin pixels {skin}");
    assert_eq!(skin, skin_samples(&r, "sss vertical"));
    assert_eq!(skin_samples(&r, "composite"), 160 * 96);
}

#[test]
fn lee_perry_smith_renders() {
    let Some(path) = common::lps_path() else {
        return;
    };
    let scene = load_gltf_scene(&path, &TextureOverrides::default(), None).unwrap();
    let s = RenderSettings {
        distance_heads: 2.9,
        ..small()
    };
    let r = render_and_check(&scene, &s);
    assert!(
        skin_samples(&r, "sss horizontal") > 160 * 96 / 4,
        "a close-up is mostly skin"
    );
}

#[test]
fn many_heads_render_more_skin() {
    let scene = default_scene();
    let one = render_and_check(&scene, &small());
    let five = render_and_check(
        &scene,
        &RenderSettings {
            heads: 5,
            ..small()
        },
    );
    // Five heads, pulled back to fit: each smaller, all together still skin.
    assert!(skin_samples(&five, "sss horizontal") > 0);
    assert_ne!(
        skin_samples(&one, "sss horizontal"),
        skin_samples(&five, "sss horizontal")
    );
}

// The crowd the multi-character benchmarks use: the camera stays where one
// head's shot puts it and the characters stand behind, so every character added
// adds skin on screen (the old grid pulled the camera back instead: 25 heads had
// fewer skin pixels than one). Skin pixels are the separable passes' samples
// passed, which the stencil limits to skin exactly.
#[test]
fn a_crowd_of_1_4_16_64_heads_adds_skin_with_every_step() {
    let scene = default_scene();
    let ctx = common::ctx();
    let mut skin = Vec::new();
    for heads in [1, 4, 16, 64] {
        let s = RenderSettings {
            width: 320,
            height: 180,
            shadow_size: 512,
            heads,
            ..RenderSettings::study()
        };
        let out = run(&ctx, &scene, &s, &opts(false)).expect("render");
        let n = out
            .report
            .passes
            .iter()
            .find(|p| p.name == "sss horizontal")
            .expect("the separable pass")
            .samples_passed;
        println!("{heads} heads: {n} skin pixels");
        skin.push(n);
    }
    for w in skin.windows(2) {
        assert!(w[1] > w[0], "skin pixels {skin:?}");
    }
    assert!(skin[3] > 2 * skin[0], "{skin:?}");
}

#[test]
fn a_scene_without_skin_runs_no_sss_fragments() {
    let mut scene = default_scene();
    scene.head.material.skin = false;
    let r = render_and_check(&scene, &small());
    assert_eq!(skin_samples(&r, "sss horizontal"), 0);
    assert_eq!(skin_samples(&r, "sss vertical"), 0);
}

#[test]
fn method_none_has_no_sss_passes() {
    let r = render_and_check(
        &default_scene(),
        &RenderSettings {
            method: common::m("none"),
            ..small()
        },
    );
    assert!(r.passes.iter().all(|p| !p.name.starts_with("sss")));
}
