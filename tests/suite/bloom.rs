//! The bloom (`--bloom`, `post::bloom`) on lavapipe, validation on: its
//! passes on synthetic HDR composites against what the pyramid must do
//! whatever its code (a uniform frame stays uniform, a pixel's light is kept,
//! its halo is symmetric and falls, with the closed-form width of
//! `bloom_pyramid::halo_variance`), a frame without `--bloom` has no bloom
//! image or pass, the passes are in the report with role `post` and their
//! declared work, and every failed set-up step cleans up.

use crate::common;

use dermis::graph::work::PassRole;
use dermis::post::bloom_pyramid::{halo, halo_variance, COARSEST_STEP, STRENGTH};
use dermis::post::{AaMode, PostOptions};
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::egg_scene;
use dermis::vk::context::Context;

fn settings(w: u32, h: u32, bloom: bool) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        shadow_size: 64,
        aa: AaMode::None,
        post: PostOptions {
            bloom,
            ..PostOptions::default()
        },
        ..RenderSettings::study().with(common::m("none"), &[])
    }
}

fn f16(v: f32) -> u16 {
    half::f16::from_f32(v).to_bits()
}

/// The bloom's passes alone on an uploaded composite: the bloomed image
/// (linear float RGBA) and the passes' samples.
fn run_bloom(
    ctx: &Context,
    w: u32,
    h: u32,
    rgba: &[[f32; 4]],
) -> (Vec<[f32; 4]>, Vec<dermis::graph::PassSample>) {
    let mut r = Renderer::new(ctx, &egg_scene(), &settings(w, h, true)).unwrap();
    let bits: Vec<u16> = rgba.iter().flat_map(|p| p.map(f16)).collect();
    r.upload_hdr(&bits).unwrap();
    r.run_bloom_only().unwrap()
}

/// The invariant of a normalised pyramid in an energy-conserving mix
/// (`(1 - s) in + s B`, the levels' and the Gaussian's weights summing to
/// 1): a uniform composite comes out as it went in, at every pixel, borders
/// included (every read clamps). Values exact in f16, so within one f16
/// step (the intermediates are f16).
#[test]
fn a_uniform_composite_stays_uniform() {
    let ctx = common::ctx();
    let (w, h) = (97u32, 61u32); // odd sizes: the levels' last texels clamp
    let c = [0.75f32, 2.5, 6.0, 1.0];
    let (out, samples) = run_bloom(&ctx, w, h, &vec![c; (w * h) as usize]);
    let mut worst: f32 = 0.0;
    for p in &out {
        for ch in 0..3 {
            worst = worst.max((p[ch] - c[ch]).abs() / c[ch]);
        }
    }
    println!(
        "uniform {c:?} through {} bloom passes: worst relative change {worst:e}",
        samples.len()
    );
    assert_eq!(samples.len(), 13, "4 reductions, 8 blurs, the combine");
    assert!(samples.iter().all(|s| s.role == PassRole::Post));
    assert!(worst <= 1.0 / 1024.0, "{worst}");
}

/// A single bright pixel on the coarsest level's grid (a multiple of 16:
/// where the sample-centred pyramid is symmetric about it), far from the
/// border: the light it loses is the light its halo holds (the frame's sum is
/// kept), the halo is symmetric about it along both axes and falls
/// monotonically, its variance per axis is the closed form
/// `bloom_pyramid::halo_variance` (each level `4^k var_G + (4^k - 1) / 6`,
/// mixed by the level weights) within 2 %, and every pixel but the centre is
/// the CPU mirror `bloom_pyramid::halo` within 1 % of the halo's peak (the
/// centre, near 900, within two f16 steps of its value).
#[test]
fn a_bright_pixel_spreads_into_the_predicted_halo() {
    let ctx = common::ctx();
    let (w, h) = (256usize, 256usize);
    let (x0, y0) = (8 * COARSEST_STEP, 8 * COARSEST_STEP);
    let e = 1000.0f32;
    let mut img = vec![[0.0, 0.0, 0.0, 1.0]; w * h];
    img[y0 * w + x0] = [e, e, e, 1.0];
    let (out, _) = run_bloom(&ctx, w as u32, h as u32, &img);
    let v = |x: usize, y: usize| f64::from(out[y * w + x][1]);
    let s = f64::from(STRENGTH);
    let e = f64::from(e);
    let total: f64 = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| v(x, y))
        .sum();
    let (mut mx, mut my) = (0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            mx += (x as f64 - x0 as f64).powi(2) * v(x, y);
            my += (y as f64 - y0 as f64).powi(2) * v(x, y);
        }
    }
    // The centre pixel's own (1 - s) share has no second moment: the
    // moments are the halo's, which holds s of the light.
    let (var_x, var_y) = (mx / (s * e), my / (s * e));
    let want = halo_variance();
    println!(
        "sum {total:.3} of {e}; halo variance x {var_x:.3}, y {var_y:.3} px^2 (sigma {:.3}, {:.3}) against the closed form {want:.3} (sigma {:.3})",
        var_x.sqrt(),
        var_y.sqrt(),
        want.sqrt()
    );
    assert!((total - e).abs() < 5e-3 * e, "light not kept: {total}");
    for var in [var_x, var_y] {
        assert!((var - want).abs() < 0.02 * want, "{var} vs {want}");
    }
    let halo_at = |d: usize| v(x0 + d, y0);
    let peak = halo_at(1);
    let mut worst_sym: f64 = 0.0;
    for d in 1..96 {
        let r = halo_at(d);
        for other in [v(x0 - d, y0), v(x0, y0 + d), v(x0, y0 - d)] {
            worst_sym = worst_sym.max((other - r).abs() / peak);
        }
        // Falling: each step out is lower, up to one f16 step of the value.
        assert!(
            r <= halo_at(d - 1) * (1.0 + 1.0 / 1024.0),
            "rises at {d}: {r} after {}",
            halo_at(d - 1)
        );
    }
    assert!(halo_at(48) < 0.05 * peak && halo_at(95) < halo_at(48));
    assert!(worst_sym < 0.01, "asymmetric by {worst_sym} of the peak");
    let cpu = halo(w, h, x0, y0);
    let mut worst: f64 = 0.0;
    for (i, c) in cpu.iter().enumerate() {
        let want = s * e * c;
        if i == y0 * w + x0 {
            let want = want + (1.0 - s) * e;
            let got = f64::from(out[i][1]);
            assert!(
                (got - want).abs() <= 2.0 * want / 1024.0,
                "centre {got} vs {want}"
            );
            continue;
        }
        worst = worst.max((f64::from(out[i][1]) - want).abs());
    }
    println!(
        "symmetric within {worst_sym:.2e} of the peak {peak:.4}; worst |GPU - mirror| {worst:.4} ({:.2e} of the peak)",
        worst / peak
    );
    assert!(worst < 0.01 * peak, "{worst} vs peak {peak}");
}

fn frame_passes(r: &Renderer) -> Vec<(String, PassRole, Vec<String>)> {
    r.passes()
        .iter()
        .map(|p| {
            let images = p
                .images
                .iter()
                .map(|(id, _)| r.resources.name(*id).to_string())
                .collect();
            (p.name.clone(), p.role, images)
        })
        .collect()
}

/// Without `--bloom` no bloom image is declared and no pass touches one:
/// the post passes are the tone map alone, reading the composite. With it
/// the extra passes are 13, all role `post`, before the tone map, which reads
/// the bloomed composite, and the tone-mapped frame changes.
#[test]
fn without_bloom_the_frame_has_no_bloom_pass() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let run = |bloom| {
        let s = RenderSettings {
            distance_heads: 1.5,
            ..settings(96, 64, bloom)
        };
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let passes = frame_passes(&r);
        let names: Vec<String> = r
            .resources
            .image_ids()
            .map(|id| r.resources.name(id).to_string())
            .collect();
        let cap = r.capture(false).unwrap();
        (passes, names, cap.ldr)
    };
    let (plain, plain_images, plain_ldr) = run(false);
    assert!(
        !plain_images.iter().any(|n| n.contains("bloom")),
        "{plain_images:?}"
    );
    // The composite (writing hdr) and the tone map (hdr into ldr).
    let post: Vec<_> = plain.iter().filter(|p| p.1 == PassRole::Post).collect();
    assert_eq!(post.len(), 2, "the composite and the tone map: {post:?}");
    assert_eq!(post[1].2, ["hdr", "ldr"], "{:?}", post[1]);
    let (bloomed, _, bloomed_ldr) = run(true);
    let extra: Vec<_> = bloomed
        .iter()
        .filter(|p| p.2.iter().any(|i| i.contains("bloom")))
        .collect();
    assert_eq!(bloomed.len(), plain.len() + 13);
    assert_eq!(
        extra.len(),
        14,
        "13 bloom passes and the tone map reading it"
    );
    assert!(extra.iter().all(|p| p.1 == PassRole::Post));
    let tonemap = bloomed
        .iter()
        .position(|p| p.2.iter().any(|i| i == "ldr"))
        .unwrap();
    assert_eq!(bloomed[tonemap].2, ["bloomed hdr", "ldr"]);
    assert!(bloomed[..tonemap]
        .iter()
        .rev()
        .take(13)
        .all(|p| p.1 == PassRole::Post));
    let changed = plain_ldr
        .chunks_exact(4)
        .zip(bloomed_ldr.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count();
    println!(
        "--bloom changed {changed} of {} pixels of the frame",
        96 * 64
    );
    assert!(changed > 100, "{changed}");
}

/// `dermis render --validate --bloom`: the report says `"bloom": true` and
/// lists the 13 bloom passes (the passes writing a bloom image) with role
/// `post` and declared raster work; without `--bloom` the report has no
/// `bloom` key and no pass touches a bloom image.
#[test]
fn render_reports_the_bloom_passes() {
    let dir = dermis::scene::gltf_load::fixture::temp_dir("bloom");
    let render = |bloom: bool, out: &std::path::Path| {
        let mut c = common::dermis();
        c.args(["render", "--validate", "--device", "llvmpipe"])
            .args(["--width", "64", "--height", "48", "--frames", "2"])
            .args(["--warmup", "0", "--out"])
            .arg(out);
        if bloom {
            c.arg("--bloom");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("report.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let writes_bloom =
        |p: &serde_json::Value| {
            p["images"].as_array().unwrap().iter().any(|i| {
                i["image"].as_str().unwrap().contains("bloom") && i["kind"] == "color-target"
            })
        };
    let with = render(true, &dir.join("bloom"));
    assert_eq!(with["bloom"], true);
    let passes = with["passes"].as_array().unwrap();
    let bloom: Vec<_> = passes.iter().filter(|p| writes_bloom(p)).collect();
    assert_eq!(bloom.len(), 13, "{bloom:?}");
    for p in &bloom {
        assert_eq!(p["role"], "post", "{p}");
        assert_eq!(p["work"]["kind"], "raster", "{p}");
        assert!(
            !p["work"]["shader"]["fetches"]
                .as_array()
                .unwrap()
                .is_empty(),
            "{p}"
        );
        assert!(p["samples_passed"].as_u64().unwrap() > 0, "{p}");
    }
    let without = render(false, &dir.join("plain"));
    assert!(without.get("bloom").is_none());
    assert!(!without["passes"]
        .as_array()
        .unwrap()
        .iter()
        .any(writes_bloom));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The bloom's set-up fails cleanly at each of its creation steps in turn
/// (`Context::fail_creation_after`, as for the AA stages): one error line,
/// its memory freed at once, and the device destroyed with nothing left
/// after a clean frame.
#[test]
fn every_failed_bloom_set_up_tears_down_clean() {
    let scene = egg_scene();
    let ctx = common::ctx();
    let s = settings(64, 36, true);
    let steps = common::fail_each_creation_step(&ctx, &scene, &s, "--bloom");
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    r.capture(false).unwrap();
    drop(r);
    ctx.finish().unwrap();
    println!("--bloom: {steps} creation steps failed in turn, clean");
}
