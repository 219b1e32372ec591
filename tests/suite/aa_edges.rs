//! The edge sources of MLAA and SMAA (`--aa-edges`, issue 17) on lavapipe,
//! validation on: MLAA's depth variant (thesis ch. 9.3, Listing 9.1) against
//! `aa::edges::mlaa_depth_edges` on a synthetic depth image and on a rendered
//! frame's linear depth, edgel for edgel, with the stencil culling's counts;
//! SMAA's colour variant against `aa::edges::smaa_color_edges` and its
//! presets (`--smaa-preset`) against their thresholds; and options that do
//! not apply refused in one line before a device opens.

use crate::aa::{blocks_with, gamma, gpu_edges, settings, Rng};
use crate::common;

use dermis::aa::edges::{
    luma, mlaa_depth_edges, mlaa_luma_edges, smaa_color_edges, smaa_luma_edges, Edges, Image,
    LocalContrast, Preset,
};
use dermis::aa::mlaa_weights::edge_pixels;
use dermis::graph::work::PassRole;
use dermis::post::mlaa::depth_threshold;
use dermis::post::{AaMode, EdgeSource, PostOptions};
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::egg_scene;

const W: usize = 96;
const H: usize = 64;

fn with_edges(s: RenderSettings, e: EdgeSource) -> RenderSettings {
    RenderSettings {
        post: PostOptions {
            aa_edges: Some(e),
            ..s.post
        },
        ..s
    }
}

/// A depth image in scene units: rectangles of depths from a palette on a
/// far ground, and a ramp whose steps (0.08 of the threshold per pixel) are
/// a slope, not an edge. Every difference between two palette depths is at
/// least 5 % away from the threshold (no near-ties; the GPU and the CPU
/// subtract the same f32 values, so even a tie would agree).
fn depth_image(threshold: f32, seed: u64) -> Vec<f32> {
    let mut rng = Rng(seed);
    let palette = [2.0, 0.3, 1.6, 0.45, 4.0, 0.8].map(|f| 5.0 + f * threshold);
    for (i, a) in palette.iter().enumerate() {
        for b in &palette[i + 1..] {
            assert!(((a - b).abs() - threshold).abs() > 0.05 * threshold);
        }
    }
    let mut d = vec![20.0 * threshold; W * H];
    for k in 0..12 {
        let z = palette[k % palette.len()];
        let (x0, y0) = (rng.below(W as u64) as usize, rng.below(H as u64) as usize);
        let (rw, rh) = (
            2 + rng.below(W as u64 / 3) as usize,
            1 + rng.below(H as u64 / 3) as usize,
        );
        for y in y0..(y0 + rh).min(H) {
            for x in x0..(x0 + rw).min(W) {
                d[y * W + x] = z;
            }
        }
    }
    // The ramp: bottom-left quarter, rising left to right.
    for y in 3 * H / 4..H {
        for x in 0..W / 4 {
            d[y * W + x] = 3.0 + 0.08 * threshold * x as f32;
        }
    }
    d
}

/// MLAA's depth pass against `mlaa_depth_edges` at the threshold the pass
/// pushes (`post::mlaa::depth_threshold`: 10 mm in scene units), edgel for
/// edgel; the stencil then culls the weights and blend passes to the edge
/// pixels (samples passed of passes 1, 2 and 4 equal `edge_pixels`' count).
/// The ramp inside the bottom-left quarter has no edge.
#[test]
fn mlaa_depth_edges_equal_the_cpu_reference_and_the_stencil_culls() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let t = depth_threshold(scene.mm_per_unit);
    for seed in [3, 777] {
        let s = with_edges(
            settings(W as u32, H as u32, AaMode::Mlaa),
            EdgeSource::Depth,
        );
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let depth = depth_image(t, seed);
        let zero = vec![0u16; W * H * 4];
        r.upload_sss_inputs(&zero, &depth, &vec![false; W * H])
            .unwrap();
        r.upload_ldr(&vec![128u8; W * H * 4]).unwrap();
        let (_, samples) = r.run_post_only().unwrap();
        let cpu = mlaa_depth_edges(&depth, W, H, t).unwrap();
        let gpu = gpu_edges(&mut r, W, H);
        for (i, (g, c)) in gpu.edgels.iter().zip(&cpu.edgels).enumerate() {
            assert_eq!(g, c, "seed {seed}: edgels of pixel ({}, {})", i % W, i / W);
        }
        let on_edge = edge_pixels(&cpu);
        let count = on_edge.iter().filter(|&&e| e).count() as u64;
        for y in 3 * H / 4 + 1..H {
            for x in 1..W / 4 - 1 {
                if depth[y * W + x] < 4.0 {
                    continue; // a rectangle covers the ramp here
                }
                assert!(
                    !on_edge[y * W + x],
                    "seed {seed}: the ramp has an edge at ({x}, {y})"
                );
            }
        }
        // The stage's passes in order: edges, weights, copy, blend.
        let post: Vec<_> = samples
            .iter()
            .filter(|p| p.role == PassRole::Post)
            .collect();
        assert_eq!(post.len(), 4);
        for i in [0, 1, 3] {
            assert_eq!(post[i].samples_passed, count, "seed {seed}: pass {i}");
        }
        let edgels = cpu.edgels.iter().filter(|e| e.left || e.top).count();
        println!("seed {seed}: {edgels} pixels with a depth edgel, {count} edge pixels (samples passed of passes 1, 2, 4): GPU = CPU");
        assert!(count > 200, "{count}");
    }
}

/// A rendered egg frame with `--aa mlaa --aa-edges depth`: the GPU edges equal
/// `mlaa_depth_edges` of the frame's own linear depth (read back by the
/// capture), and the silhouette against the far plane is found.
#[test]
fn mlaa_depth_edges_of_a_rendered_frame_equal_the_cpu_reference() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let s = RenderSettings {
        distance_heads: 1.5,
        ..with_edges(
            settings(W as u32, H as u32, AaMode::Mlaa),
            EdgeSource::Depth,
        )
    };
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let cap = r.capture(false).unwrap();
    let gpu = gpu_edges(&mut r, W, H);
    let cpu = mlaa_depth_edges(&cap.depth, W, H, depth_threshold(scene.mm_per_unit)).unwrap();
    assert_eq!(gpu, cpu);
    let n = edge_pixels(&cpu).iter().filter(|&&e| e).count();
    println!("rendered egg: {n} edge pixels from depth, GPU = CPU");
    assert!(n > 50, "{n}");
}

/// `--aa-edges` and `--smaa-preset` and the modes they apply to: one error
/// line, before a device opens (`--device` names none that exists, so
/// reaching it would fail otherwise), for depth with SMAA, colour with MLAA,
/// any source without an MLAA or SMAA stage, a preset without SMAA.
#[test]
fn edge_sources_that_do_not_apply_are_refused_before_a_device_opens() {
    for (aa, flag, value) in [
        ("smaa", "--aa-edges", "depth"),
        ("fxaa", "--aa-edges", "luma"),
        ("none", "--aa-edges", "depth"),
        ("mlaa", "--aa-edges", "color"),
        ("mlaa", "--smaa-preset", "low"),
        ("none", "--smaa-preset", "high"),
    ] {
        let o = common::dermis()
            .args(["render", "--device", "no-such-device", "--aa", aa])
            .args([flag, value])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(
            err.contains(flag) && err.contains(aa) && err.lines().count() == 1,
            "{aa} {flag} {value}: {err}"
        );
        assert!(!err.contains("no-such-device"), "{err}");
    }
}

/// The colour delta SMAA's colour edges use: the largest R, G, B difference.
fn color_delta(a: [f32; 4], b: [f32; 4]) -> f32 {
    (a[0] - b[0])
        .abs()
        .max((a[1] - b[1]).abs())
        .max((a[2] - b[2]).abs())
}

/// Random blocks (rectangles of a 7-colour palette on grey) whose colour
/// deltas are free of ties: none within 1e-3 of the high preset's 0.1, and no
/// delta within 1e-3 of twice another (the local contrast test `2 c >=
/// c_max`), so no f32 rounding can flip an edgel.
fn color_blocks(seed: u64) -> Vec<u8> {
    let mut rng = Rng(seed);
    let f = |c: [u8; 3]| {
        [
            c[0] as f32 / 255.0,
            c[1] as f32 / 255.0,
            c[2] as f32 / 255.0,
            1.0,
        ]
    };
    let mut palette: Vec<[u8; 3]> = vec![[128, 128, 128]];
    let mut tries = 0;
    while palette.len() < 7 {
        tries += 1;
        assert!(tries < 1_000_000, "no palette without ties");
        let c = [0, 1, 2].map(|_| rng.below(256) as u8);
        let mut with = palette.clone();
        with.push(c);
        let mut d = vec![0.0];
        for (i, a) in with.iter().enumerate() {
            for b in &with[i + 1..] {
                d.push(color_delta(f(*a), f(*b)));
            }
        }
        let t = Preset::High.threshold();
        let ok = d.iter().all(|&x| (x - t).abs() > 1e-3)
            && d.iter()
                .all(|&x| d.iter().all(|&y| x == y || (2.0 * x - y).abs() > 1e-3));
        if ok {
            palette = with;
        }
    }
    let mut px = vec![palette[0]; W * H];
    for k in 0..14 {
        let c = palette[1 + k % (palette.len() - 1)];
        let (x0, y0) = (rng.below(W as u64) as usize, rng.below(H as u64) as usize);
        let (rw, rh) = (
            2 + rng.below(W as u64 / 2) as usize,
            1 + rng.below(H as u64 / 3) as usize,
        );
        for y in y0..(y0 + rh).min(H) {
            for x in x0..(x0 + rw).min(W) {
                px[y * W + x] = c;
            }
        }
    }
    px.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect()
}

/// Pixels whose left or top delta passes `t` before the local contrast
/// adaptation: what SMAA's edge pass keeps in the stencil.
fn thresholded(img: &[[f32; 4]], t: f32, delta: impl Fn([f32; 4], [f32; 4]) -> f32) -> u64 {
    let at = |x: usize, y: usize| img[y * W + x];
    let mut n = 0;
    for y in 0..H {
        for x in 0..W {
            let left = delta(at(x, y), at(x.saturating_sub(1), y)) >= t;
            let top = delta(at(x, y), at(x, y.saturating_sub(1))) >= t;
            n += u64::from(left || top);
        }
    }
    n
}

fn run_smaa(
    ctx: &dermis::vk::context::Context,
    rgba8: &[u8],
    options: PostOptions,
) -> (Edges, Vec<[f32; 4]>, Vec<dermis::graph::PassSample>) {
    let s = RenderSettings {
        post: options,
        ..settings(W as u32, H as u32, AaMode::Smaa)
    };
    let mut r = Renderer::new(ctx, &egg_scene(), &s).unwrap();
    r.upload_ldr(rgba8).unwrap();
    let (out, samples) = r.run_post_only().unwrap();
    (gpu_edges(&mut r, W, H), out, samples)
}

/// SMAA's colour edge pass against `smaa_color_edges(.., 0.1, Shared)` edgel
/// for edgel on three tie-free colour-block frames; the stencil culls the
/// weights pass to the pixels whose colour delta passes the threshold.
#[test]
fn smaa_color_edges_equal_the_cpu_reference() {
    let ctx = common::ctx();
    let color = PostOptions {
        aa_edges: Some(EdgeSource::Color),
        ..PostOptions::default()
    };
    for seed in [11, 4242, 31337] {
        let rgba8 = color_blocks(seed);
        let (gpu, _, samples) = run_smaa(&ctx, &rgba8, color);
        let px = gamma(&rgba8);
        let img = Image::new(W, H, &px).unwrap();
        let t = Preset::High.threshold();
        let cpu = smaa_color_edges(&img, t, LocalContrast::Shared).unwrap();
        for (i, (g, c)) in gpu.edgels.iter().zip(&cpu.edgels).enumerate() {
            assert_eq!(g, c, "seed {seed}: edgels of pixel ({}, {})", i % W, i / W);
        }
        let kept = thresholded(&px, t, color_delta);
        let post: Vec<_> = samples
            .iter()
            .filter(|p| p.role == PassRole::Post)
            .collect();
        // The stage's passes in order: edges, weights, blend.
        assert_eq!(post.len(), 3);
        assert_eq!(
            (post[0].samples_passed, post[1].samples_passed),
            (kept, kept)
        );
        let adapted = cpu.edgels.iter().filter(|e| e.left || e.top).count();
        // Luma would miss some: a colour step of equal luma is an edge here.
        let luma_kept = thresholded(&px, t, |a, b| (luma(a) - luma(b)).abs());
        println!("seed {seed}: {kept} pixels pass the colour threshold ({luma_kept} the luma one), {adapted} keep an edgel: GPU = CPU");
        assert!(adapted > 100 && adapted as u64 <= kept, "seed {seed}");
    }
}

/// SMAA's presets: on a tie-free block frame each preset's GPU edges equal
/// `smaa_luma_edges` at its threshold (low 0.15, medium and high 0.1, ultra
/// 0.05) and the stencil keeps the pixels passing it, so a higher threshold
/// keeps fewer; `--smaa-preset high` is the default frame bit for bit; the
/// low frame changes only pixels with a low-preset edgel on a side; medium
/// (high's threshold, no diagonals or corners, 8 steps) finds high's edges
/// and blends them differently.
#[test]
fn smaa_presets_follow_their_thresholds() {
    let ctx = common::ctx();
    let rgba8 = blocks_with(W, H, 1234, true);
    let px = gamma(&rgba8);
    let img = Image::new(W, H, &px).unwrap();
    // No luma delta of the frame lies near any preset's threshold.
    let mut colours: Vec<[f32; 4]> = px.clone();
    colours.sort_by(|a, b| a.partial_cmp(b).unwrap());
    colours.dedup();
    for a in &colours {
        for b in &colours {
            let d = (luma(*a) - luma(*b)).abs();
            for p in Preset::ALL {
                assert!(
                    (d - p.threshold()).abs() > 1e-4,
                    "{d} near {}",
                    p.threshold()
                );
            }
        }
    }
    let preset = |p: Option<Preset>| PostOptions {
        smaa_preset: p,
        ..PostOptions::default()
    };
    let input = run_input(&rgba8);
    let (_, default_out, _) = run_smaa(&ctx, &rgba8, preset(None));
    let mut kept_by = Vec::new();
    let mut outs = Vec::new();
    for p in Preset::ALL {
        let (gpu, out, samples) = run_smaa(&ctx, &rgba8, preset(Some(p)));
        let cpu = smaa_luma_edges(&img, p.threshold(), LocalContrast::Shared).unwrap();
        assert_eq!(gpu, cpu, "{p:?}");
        let kept = mlaa_luma_edges(&img, p.threshold())
            .unwrap()
            .edgels
            .iter()
            .filter(|e| e.left || e.top)
            .count() as u64;
        let post: Vec<_> = samples
            .iter()
            .filter(|s| s.role == PassRole::Post)
            .collect();
        assert_eq!(
            (post[0].samples_passed, post[1].samples_passed),
            (kept, kept),
            "{p:?}"
        );
        let changed = out.iter().zip(&input).filter(|(o, i)| o != i).count();
        println!("{p:?}: threshold {}, {kept} pixels kept in the stencil, {} with an edgel after adaptation, {changed} pixels changed", p.threshold(), cpu.edgels.iter().filter(|e| e.left || e.top).count());
        kept_by.push(kept);
        outs.push((p, out, cpu));
    }
    assert!(
        kept_by[0] < kept_by[2] && kept_by[2] < kept_by[3],
        "{kept_by:?}"
    );
    assert_eq!(kept_by[1], kept_by[2]);
    let high = &outs[2].1;
    assert!(
        high == &default_out,
        "--smaa-preset high is not the default frame"
    );
    // Low: every changed pixel has a low-preset edgel on one of its sides.
    let (_, low, low_edges) = &outs[0];
    for (i, (o, x)) in low.iter().zip(&input).enumerate() {
        if o != x {
            let (px_, py) = (i % W, i / W);
            let e = |x: usize, y: usize| low_edges.at(x.min(W - 1), y.min(H - 1));
            let near =
                e(px_, py).left || e(px_, py).top || e(px_ + 1, py).left || e(px_, py + 1).top;
            assert!(near, "low changed ({px_}, {py}) off its edges");
        }
    }
    assert!(outs[1].1 != *high, "medium blends as high does");
}

/// The input frame as the post-only run's output reads it back (linear
/// floats decoded from sRGB), to see which pixels a stage changed.
fn run_input(rgba8: &[u8]) -> Vec<[f32; 4]> {
    use dermis::format::srgb_to_linear;
    rgba8
        .chunks_exact(4)
        .map(|c| {
            [
                srgb_to_linear(c[0]),
                srgb_to_linear(c[1]),
                srgb_to_linear(c[2]),
                c[3] as f32 / 255.0,
            ]
        })
        .collect()
}
