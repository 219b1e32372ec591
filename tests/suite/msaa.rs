//! MSAA with the SSS pipeline (`--msaa`, issue 17 item 5; docs/aa.md, "MSAA
//! with the SSS pipeline") on lavapipe, validation on: the device's sample
//! counts and the one-line refusals, every method at 4x or its one-line
//! refusal, interior pixels kept and silhouettes brought toward a
//! supersampled frame, the SSS stencil passes passing exactly the resolved
//! stencil's skin pixels, and `dermis budget` pricing the multisampled
//! geometry pass.

use crate::common;

use dermis::app::aa_eval::reference;
use dermis::eval::supersample::{edge_mask, score};
use dermis::graph::work::{PassRole, Work};
use dermis::method::METHODS;
use dermis::mix::assign::Rules;
use dermis::mix::stencil_code;
use dermis::render::settings::Assignment;
use dermis::render::{RenderSettings, Renderer};
use dermis::run::{run, RunOptions};
use dermis::scene::camera::Camera;
use dermis::scene::egg_scene;
use dermis::scene::lines::lines_scene;
use serde_json::Value;

/// The sample count the tests multisample at: lavapipe's one count above 1.
const MSAA: u32 = 4;

fn egg(w: u32, h: u32, msaa: u32) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        shadow_size: 256,
        distance_heads: 1.5,
        msaa,
        ..RenderSettings::study()
    }
}

/// A refusal is one line that names what it refuses.
fn one_line(e: &anyhow::Error, names: &str) {
    let msg = format!("{e:#}");
    assert!(!msg.contains('\n'), "more than one line: {msg}");
    assert!(msg.contains(names), "'{names}' not in: {msg}");
}

/// The device says which counts it renders; lavapipe renders 1x and 4x (its
/// framebuffer limits), so 4x is the tests' count. A count the device lacks
/// and a count `--msaa` does not take are each one error line.
#[test]
fn sample_counts_of_the_device_and_one_line_refusals() {
    let ctx = common::ctx();
    let counts = &ctx.facts.framebuffer_sample_counts;
    println!(
        "{}: framebuffer sample counts {counts:?}, depth resolve modes {:?}, stencil {:?}",
        ctx.facts.name, ctx.facts.depth_resolve_modes, ctx.facts.stencil_resolve_modes
    );
    assert!(counts.contains(&1) && counts.contains(&MSAA), "{counts:?}");
    let scene = egg_scene();
    for n in [2u32, 8] {
        if counts.contains(&n) {
            continue;
        }
        let e = Renderer::new(&ctx, &scene, &egg(32, 24, n)).err().unwrap();
        one_line(&e, &format!("cannot render {n}x MSAA"));
    }
    for n in [0u32, 3, 16] {
        let e = egg(32, 24, n).validate().unwrap_err();
        one_line(&e, "--msaa must be 1, 2, 4 or 8");
    }
    let mut ids = egg(32, 24, MSAA);
    ids.character_ids = true;
    one_line(&ids.validate().unwrap_err(), "--character-ids");
}

/// Every registered method renders a 4x frame under validation, or says in
/// one line, before a device is used, why it cannot; a frame of several
/// methods refuses the same way when one of its groups cannot.
#[test]
fn every_method_renders_at_4x_or_refuses_in_one_line() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let mut rendered = Vec::new();
    for m in METHODS {
        let s = egg(64, 48, MSAA).with(m, &[]);
        if m.no_msaa.is_some() {
            one_line(&s.validate().unwrap_err(), m.name);
            let e = Renderer::new(&ctx, &scene, &s).err().unwrap();
            one_line(&e, "--msaa 4");
            continue;
        }
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let cap = r.capture(false).unwrap();
        assert_eq!(cap.hdr_nonfinite, 0, "{}", m.name);
        assert!(cap.ldr.iter().any(|&b| b > 0), "{}: black frame", m.name);
        let geometry = r
            .passes()
            .iter()
            .find(|p| p.role == PassRole::Geometry)
            .and_then(|p| p.declared_work(&r.resources))
            .unwrap();
        assert!(
            matches!(geometry, Work::Raster { msaa: MSAA, .. }),
            "{}",
            m.name
        );
        rendered.push(m.name);
    }
    println!("rendered at {MSAA}x: {rendered:?}");
    assert!(rendered.len() >= 5, "{rendered:?}");
    let mut mixed = egg(64, 48, MSAA);
    mixed.heads = 2;
    mixed.assignment = Some(Assignment::Rules(
        "0=separable,*=tsd".parse::<Rules>().unwrap(),
    ));
    let e = Renderer::new(&ctx, &scene, &mixed).err().unwrap();
    one_line(&e, "method tsd cannot run with --msaa 4");
}

/// Per-pixel sRGB distance of two frames: the largest channel step.
fn step(a: &[u8], b: &[u8], i: usize) -> u8 {
    (0..3)
        .map(|c| a[i * 4 + c].abs_diff(b[i * 4 + c]))
        .max()
        .unwrap()
}

/// On the lines card (160 x 90, the aa-eval test's view), with no SSS and with
/// the separable SSS: pixels 4 or more pixels from every edge pixel (where
/// the 4 x 4 supersampled frame and the 1x frame differ) keep the 1x frame
/// within one sRGB step (measured: all equal); most edge pixels change; and the edge pixels'
/// relative RMSE to the supersampled frame falls to at most `MARGIN` of
/// the 1x frame's (measured 0.29; the post modes reach 0.66-0.82 on this
/// view: MSAA resolves coverage that no post-process filter sees).
#[test]
fn interior_pixels_keep_the_1x_frame_and_silhouettes_approach_the_supersampled_frame() {
    const MARGIN: f64 = 0.4;
    const FAR_PX: i64 = 4;
    let ctx = common::ctx();
    let scene = lines_scene();
    let (w, h) = (160u32, 90u32);
    for method in ["none", "separable"] {
        let s = RenderSettings {
            width: w,
            height: h,
            shadow_size: 256,
            distance_heads: Camera::close_up_distance_heads(RenderSettings::study().fovy_deg),
            ..RenderSettings::study()
        }
        .with(common::m(method), &[]);
        let frame = |msaa| {
            let s = RenderSettings { msaa, ..s.clone() };
            run(&ctx, &scene, &s, &RunOptions::capture_once("msaa test"))
                .unwrap()
                .capture
                .unwrap()
                .ldr
        };
        let (one, four) = (frame(1), frame(MSAA));
        let view = dermis::eval::aa_eval::AaScene {
            name: method.into(),
            source: "built in".into(),
            distance_heads: s.distance_heads,
            heads: s.heads,
        };
        let p = dermis::app::aa_eval::plan_view(&view, &scene, &s, 4).unwrap();
        let truth = reference(&ctx, &p).unwrap();
        let mask = edge_mask(&truth, &one).unwrap();
        let (wi, hi) = (w as i64, h as i64);
        let near_edge = |x: i64, y: i64| {
            (-FAR_PX..=FAR_PX).any(|dy| {
                (-FAR_PX..=FAR_PX).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..wi).contains(&u) && (0..hi).contains(&v) && mask[(v * wi + u) as usize]
                })
            })
        };
        let (mut interior, mut worst, mut moved) = (0, 0u8, 0);
        for y in 0..hi {
            for x in 0..wi {
                if near_edge(x, y) {
                    continue;
                }
                let d = step(&one, &four, (y * wi + x) as usize);
                interior += 1;
                worst = worst.max(d);
                moved += usize::from(d > 0);
            }
        }
        let edges: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
        let changed = edges.iter().filter(|&&i| step(&one, &four, i) > 0).count();
        let e1 = score(&one, &truth, &mask, w, h).unwrap();
        let e4 = score(&four, &truth, &mask, w, h).unwrap();
        let (r1, r4) = (e1.rmse_edges.unwrap(), e4.rmse_edges.unwrap());
        println!(
            "{method}: {interior} interior px, {moved} moved, worst {worst} steps; {} edge px, {changed} changed; edge rRMSE 1x {r1:.4} {MSAA}x {r4:.4} ({:.3}); edge FLIP 1x {:.4} {MSAA}x {:.4}",
            edges.len(),
            r4 / r1,
            e1.flip_edges.unwrap(),
            e4.flip_edges.unwrap()
        );
        assert!(
            interior > (w * h / 4) as usize,
            "{method}: {interior} interior pixels"
        );
        assert!(
            worst <= 1,
            "{method}: an interior pixel moved {worst} steps"
        );
        assert!(edges.len() > 200, "{method}: {} edge pixels", edges.len());
        assert!(
            changed * 2 > edges.len(),
            "{method}: {changed} of {} edge pixels changed",
            edges.len()
        );
        assert!(
            r4 <= MARGIN * r1,
            "{method}: edge rRMSE {r4:.4} over {MARGIN} x {r1:.4}"
        );
    }
}

/// At 4x every stencil-tested SSS pass (stencil only, no depth test) passes
/// exactly the pixels whose resolved stencil holds its group's code: the
/// single-method frame (code 1) and a frame of two methods (codes 1 and 3),
/// counted against the stencil read back after the frame.
#[test]
fn sss_stencil_passes_pass_exactly_the_resolved_skin_pixels() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let single = egg(96, 64, MSAA);
    let mut mixed = egg(96, 64, MSAA);
    mixed.heads = 2;
    // Side by side: both heads in frame.
    mixed.layout = dermis::scene::layout::Layout::Grid;
    mixed.assignment = Some(Assignment::Rules(
        "0=separable,*=ss-jittered".parse::<Rules>().unwrap(),
    ));
    for (what, s) in [("separable", single), ("separable + ss-jittered", mixed)] {
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let cap = r.capture(false).unwrap();
        let stencil = r.read_stencil().unwrap();
        let passes = r.passes();
        assert_eq!(passes.len(), cap.samples.len());
        let mut tested = 0;
        for (p, sample) in passes.iter().zip(&cap.samples) {
            // Stencil only: a depth test too (ssg's Gaussian LOD) passes fewer.
            let stencil_tested = matches!(
                p.declared_work(&r.resources),
                Some(Work::Raster { depth_stencil: Some(ds), .. }) if ds.stencil_test && !ds.depth_test
            );
            if p.role != PassRole::Sss || !stencil_tested {
                continue;
            }
            let code = stencil_code(p.group.unwrap_or(0)) as u8;
            let skin = stencil.iter().filter(|&&v| v == code).count() as u64;
            assert!(skin > 0, "{what}: no pixel holds code {code}");
            assert_eq!(
                sample.samples_passed, skin,
                "{what}: a pass of group {:?}",
                p.group
            );
            tested += 1;
        }
        let skin = stencil.iter().filter(|&&v| v & 1 == 1).count();
        let alpha = cap.diffuse.iter().filter(|p| p[3] > 0.0).count();
        println!("{what}: {tested} stencil-tested SSS passes; {skin} skin pixels in the resolved stencil, {alpha} with resolved SSS strength > 0");
        assert!(tested >= 2, "{what}: {tested} passes");
    }
}

/// `dermis render --msaa 4` names the count in its report (1x names none);
/// `dermis budget --msaa 4` declares the geometry pass at 4 samples and
/// prices it above the 1x pass on the Xbox 360 and the Steam Deck (profiles
/// with a per-sample rate; one without leaves the pass unpriced); `--msaa 3`
/// is one error line before a device opens.
#[test]
fn render_reports_and_budget_prices_the_multisampled_geometry_pass() {
    let dir = dermis::scene::gltf_load::fixture::temp_dir("msaa");
    let cli = |cmd: &str, msaa: &str, out: &std::path::Path, extra: &[&str]| {
        common::dermis()
            .args([cmd, "--validate", "--device", "llvmpipe", "--width", "96"])
            .args([
                "--height",
                "54",
                "--shadow-size",
                "256",
                "--frames",
                "1",
                "--warmup",
                "0",
            ])
            .args(["--msaa", msaa, "--out"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap()
    };
    let json = |p: std::path::PathBuf| -> Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    for (msaa, named) in [("1", None), ("4", Some(4))] {
        let out = dir.join(format!("render{msaa}"));
        let o = cli("render", msaa, &out, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let report = json(out.join("report.json"));
        assert_eq!(report["msaa"].as_u64(), named, "--msaa {msaa}");
    }
    let mut priced = Vec::new();
    for msaa in ["1", "4"] {
        let out = dir.join(format!("budget{msaa}"));
        let o = cli("budget", msaa, &out, &["--profile", "xbox360,steam-deck"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let b = json(out.join("budget.json"));
        let run = &b["runs"][0];
        let frame = run["frame"]["passes"].as_array().unwrap();
        let g = frame.iter().position(|p| p["role"] == "geometry").unwrap();
        assert_eq!(
            frame[g]["work"]["msaa"].as_u64(),
            Some(msaa.parse().unwrap())
        );
        let ms: Vec<f64> = run["budgets"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["passes"][g]["modelled_ms"].as_f64().unwrap())
            .collect();
        priced.push(ms);
    }
    println!(
        "geometry pass modelled ms (xbox360, steam deck): 1x {:?}, 4x {:?}",
        priced[0], priced[1]
    );
    for (one, four) in priced[0].iter().zip(&priced[1]) {
        assert!(four > one, "4x {four} ms not above 1x {one} ms");
    }
    let o = cli("render", "3", &dir.join("bad"), &[]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("--msaa must be 1, 2, 4 or 8"), "{stderr}");
}

/// The 4x frame tears down clean, also when its set-up fails: the set-up is
/// made to fail at each of its creation steps in turn (the multisampled
/// images and the multisampled geometry pipeline among them), each failure
/// is one error line and frees its memory at once, and after a clean frame
/// the device is destroyed with nothing left.
#[test]
fn every_failed_4x_set_up_step_tears_down_clean() {
    let scene = egg_scene();
    let ctx = common::ctx();
    let s = egg(48, 32, MSAA);
    let steps = common::fail_each_creation_step(&ctx, &scene, &s, "--msaa 4");
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    r.capture(false).unwrap();
    r.read_stencil().unwrap();
    drop(r);
    ctx.finish()
        .unwrap_or_else(|e| panic!("teardown after {steps} failures: {e:#}"));
    println!("{MSAA}x: {steps} creation steps failed in turn, clean");
}
