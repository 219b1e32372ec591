//! The anti-aliasing evaluation's supersampled ground truth on lavapipe,
//! validation on (issue 17 item 6, `dermis::eval::aa_eval`): the box filter
//! of a real supersampled frame against a plain CPU average, each AA mode
//! lowering the edge-pixel error to it on the synthetic lines scene by a
//! stated margin, and a frame with no edges whose reference is the 1x frame
//! within rounding.

use crate::common;

use dermis::app::aa_eval::{mode_frame, mode_frames, plan_view, reference};
use dermis::eval::aa_eval::{score_view, AaScene, ViewFrames};
use dermis::eval::supersample::{box_filter_srgb8, edge_mask};
use dermis::format::srgb_to_linear;
use dermis::post::AaMode;
use dermis::render::RenderSettings;
use dermis::run::{run, FrameCounts, RunOptions};
use dermis::scene::camera::Camera;
use dermis::scene::lines::lines_scene;
use dermis::scene::mesh::{Material, Mesh, Object, Vertex};
use dermis::scene::Scene;

/// A view of aa-eval's at the distance and head count of `s`.
fn view_of(s: &RenderSettings) -> AaScene {
    AaScene {
        name: "test view".into(),
        source: "built in code".into(),
        distance_heads: s.distance_heads,
        heads: s.heads,
    }
}

/// The lines card's frame at `w` x `h`, `k` close-up distances away, with
/// the study view's SSS method.
fn lines_settings(w: u32, h: u32, k: f32) -> RenderSettings {
    let s = RenderSettings::study();
    RenderSettings {
        width: w,
        height: h,
        shadow_size: 256,
        distance_heads: k * Camera::close_up_distance_heads(s.fovy_deg),
        ..s
    }
}

/// The supersampled frame's blocks averaged by a plain loop (f64, the
/// renderer's own sRGB decode, the textbook encode): what `box_filter_srgb8`
/// must give, within one step of rounding.
#[test]
fn box_filter_of_a_rendered_frame_matches_a_cpu_average() {
    let ctx = common::ctx();
    let (w, h, n) = (48u32, 27u32, 4u32);
    let s = RenderSettings {
        width: w * n,
        height: h * n,
        ..lines_settings(w, h, 1.5)
    };
    let cap = run(&ctx, &lines_scene(), &s, &RunOptions::capture_once("test"))
        .unwrap()
        .capture
        .unwrap();
    let got = box_filter_srgb8(&cap.ldr, w, h, n).unwrap();
    let enc = |l: f64| {
        let c = if l <= 0.0031308 {
            12.92 * l
        } else {
            1.055 * l.powf(1.0 / 2.4) - 0.055
        };
        (c * 255.0).round() as i32
    };
    let sw = (w * n) as usize;
    let mut worst = 0;
    for y in 0..h as usize {
        for x in 0..w as usize {
            for c in 0..3 {
                let mut sum = 0.0f64;
                for j in 0..n as usize {
                    for i in 0..n as usize {
                        let p = ((y * n as usize + j) * sw + x * n as usize + i) * 4 + c;
                        sum += f64::from(srgb_to_linear(cap.ldr[p]));
                    }
                }
                let want = enc(sum / f64::from(n * n));
                let d = (i32::from(got[(y * w as usize + x) * 4 + c]) - want).abs();
                worst = worst.max(d);
            }
        }
    }
    assert!(
        worst <= 1,
        "box filter off the CPU average by {worst} steps"
    );
    // The frame has edges: the filter changed something against the 1x frame.
    let one = run(
        &ctx,
        &lines_scene(),
        &lines_settings(w, h, 1.5),
        &RunOptions::capture_once("test"),
    )
    .unwrap()
    .capture
    .unwrap();
    let edges = edge_mask(&got, &one.ldr).unwrap();
    assert!(edges.iter().filter(|&&e| e).count() > 50);
}

/// Each AA mode's edge-pixel relative RMSE to the 4 x 4 supersampled frame,
/// as a share of no AA's, on the lines card at 160 x 90 at two distances:
/// at most `MARGIN`. Measured on lavapipe: 0.64-0.66 (FXAA), 0.75-0.82 (MLAA),
/// 0.73-0.77 (SMAA 1x); docs/aa.md has the table.
#[test]
fn every_mode_lowers_the_edge_error_to_the_supersampled_frame_on_thin_lines() {
    const MARGIN: f64 = 0.9;
    let ctx = common::ctx();
    let (w, h) = (160u32, 90u32);
    let scene = lines_scene();
    for k in [1.0f32, 2.0] {
        let s = lines_settings(w, h, k);
        let v = view_of(&s);
        let p = plan_view(&v, &scene, &s, 4).unwrap();
        let reference = reference(&ctx, &p).unwrap();
        let modes = mode_frames(&ctx, &p, FrameCounts::ONE, &|_| {}, &|| {}).unwrap();
        let (rows, _) = score_view("lines", &ViewFrames { reference, modes }, w, h).unwrap();
        for r in &rows {
            eprintln!(
                "lines {k}x {:<5} edge px {:>5}  rRMSE edges {:.4} ({:.3} of none)  FLIP edges {:.4} ({:.3})  rRMSE all {:.4}  FLIP all {:.4}",
                r.mode,
                r.edge_pixels,
                r.error.rmse_edges.unwrap(),
                r.rmse_edges_vs_none.unwrap(),
                r.error.flip_edges.unwrap(),
                r.flip_edges_vs_none.unwrap(),
                r.error.rmse_frame,
                r.error.flip_frame
            );
        }
        // No AA stage, no AA pass timed (the composite and tone map are not the AA's).
        assert_eq!(rows[0].aa_ms, 0.0);
        assert!(
            rows[0].edge_pixels > 200,
            "edge pixels: {}",
            rows[0].edge_pixels
        );
        for r in &rows[1..] {
            let share = r.rmse_edges_vs_none.unwrap();
            assert!(
                share <= MARGIN,
                "--aa {} at {k}x: edge rRMSE {share:.3} of no AA's, over {MARGIN}",
                r.mode
            );
        }
    }
}

/// A flat card filling the frame, lit evenly: no edge, so the supersampled
/// frame box-filtered is the 1x frame within rounding.
#[test]
fn a_frame_with_no_edges_has_the_1x_frame_as_its_reference() {
    let ctx = common::ctx();
    let side = 11.5f32;
    let corner = |x: f32, y: f32| Vertex {
        position: [x, y, 0.0],
        normal: [0.0, 0.0, 1.0],
        uv: [(x + side) / (2.0 * side), (side - y) / (2.0 * side)],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    let mesh = Mesh {
        vertices: vec![
            corner(-side, -side),
            corner(side, -side),
            corner(side, side),
            corner(-side, side),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let head_bounds = mesh.bounds();
    let scene = Scene {
        tracks: None,
        name: "uniform card".into(),
        mm_per_unit: 10.0,
        head: Object {
            morph: Default::default(),
            mesh,
            material: Material::skin([0.6, 0.45, 0.4]),
        },
        parts: Vec::new(),
        backdrop: None,
        head_bounds,
        forward: glam::Vec3::Z,
        source: None,
    };
    let (w, h) = (64u32, 36u32);
    // Half a close-up away: the card (one head high) overfills the frame.
    let mut s = lines_settings(w, h, 0.5);
    // The key light along the view: a light at a grazing angle would alias
    // the card's own shadow-map lookup (acne), an edge of its own.
    s.light.azimuth_deg = 0.0;
    s.light.elevation_deg = 0.0;
    let v = view_of(&s);
    let p = plan_view(&v, &scene, &s, 4).unwrap();
    assert_eq!(p.modes[0].0, AaMode::None);
    let reference = reference(&ctx, &p).unwrap();
    let (one, ..) = mode_frame(&ctx, &p.modes[0].1, FrameCounts::ONE).unwrap();
    let worst = reference
        .iter()
        .zip(&one)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    eprintln!("no-edge card: reference off the 1x frame by at most {worst} steps");
    assert!(worst <= 1, "reference off the 1x frame by {worst} steps");
    assert!(edge_mask(&reference, &one).unwrap().iter().all(|&e| !e));
}

/// `dermis aa-eval` end to end on the lines views at 64 x 36, validation on:
/// the table, aa-eval.json (one row per view and mode), the CSV and the
/// chart; and the size guard's one-line errors before any device opens.
#[test]
fn aa_eval_command_writes_its_files_and_guards_the_size() {
    let out = dermis::scene::gltf_load::fixture::temp_dir("aa-eval");
    let o = common::dermis()
        .args([
            "aa-eval",
            "--device",
            "llvmpipe",
            "--validate",
            "--scenes",
            "lines",
        ])
        .args([
            "--width", "64", "--height", "36", "--warmup", "0", "--frames", "1",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.contains("lines 4x") && stdout.contains("smaa"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(out.join("aa-eval.json")).unwrap();
    // aa-eval.json reads back typed, with its run header.
    let typed: dermis::eval::aa_eval::AaEvalReport = serde_json::from_str(&text).unwrap();
    assert_eq!(
        (typed.run.width, typed.run.height, typed.factor),
        (64, 36, 4)
    );
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    // A row per view and post mode, and per MSAA count the device renders
    // (lavapipe: 4x), scored beside them.
    let counts: Vec<u32> = common::ctx()
        .facts
        .framebuffer_sample_counts
        .iter()
        .copied()
        .filter(|&n| (2..=8).contains(&n))
        .collect();
    let per_view = AaMode::ALL.len() + counts.len();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3 * per_view);
    for n in &counts {
        let label = dermis::eval::aa_eval::msaa_label(*n);
        let msaa: Vec<_> = rows.iter().filter(|r| r["mode"] == label).collect();
        assert_eq!(msaa.len(), 3, "{label} rows");
        // MSAA lowers the edge error on every lines view (the margin the
        // post modes are held to).
        for r in msaa {
            assert!(r["rmse_edges_vs_none"].as_f64().unwrap() < 0.9, "{r}");
        }
    }
    assert_eq!(json["factor"], 4);
    let csv = std::fs::read_to_string(out.join("aa-eval.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * per_view);
    let msaa_png = counts.first().map(|&n| {
        format!(
            "views/lines-1x/{}.png",
            dermis::eval::aa_eval::msaa_label(n)
        )
    });
    for f in [
        "chart.png",
        "chart.svg",
        "views/lines-1x/reference.png",
        "views/lines-1x/edges.png",
    ]
    .into_iter()
    .map(String::from)
    .chain(msaa_png)
    {
        assert!(out.join(&f).is_file(), "{f} missing");
    }
    let _ = std::fs::remove_dir_all(&out);
    // Refused before a device opens, in one line.
    for (args, says) in [
        (&["--factor", "9"][..], "1..=8"),
        (&["--width", "8000", "--height", "4000"][..], "32000x16000"),
    ] {
        let o = common::dermis()
            .args(["aa-eval", "--device", "no-such-device", "--out"])
            .arg(&out)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(says), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
}
