//! The edge sources of MLAA and SMAA (`--aa-edges`, issue 17) on lavapipe,
//! validation on: MLAA's depth variant (thesis ch. 9.3, Listing 9.1) against
//! `aa::edges::mlaa_depth_edges` on a synthetic depth image and on a rendered
//! frame's linear depth, edgel for edgel, with the stencil culling's counts;
//! and options that do not apply refused in one line before a device opens.

use crate::aa::{gpu_edges, settings};
use crate::common;

use dermis::aa::edges::mlaa_depth_edges;
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
    let mut rng = crate::aa::Rng(seed);
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

/// `--aa-edges` and the modes it applies to: one error line, before a device
/// opens (`--device` names none that exists, so reaching it would fail
/// otherwise), for depth with SMAA or FXAA and for any source without an
/// MLAA or SMAA stage.
#[test]
fn edge_sources_that_do_not_apply_are_refused_before_a_device_opens() {
    for (aa, edges) in [
        ("smaa", "depth"),
        ("fxaa", "luma"),
        ("none", "depth"),
        ("mlaa", "color"),
    ] {
        let o = common::dermis()
            .args(["render", "--device", "no-such-device", "--aa", aa])
            .args(["--aa-edges", edges])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(
            err.contains("--aa-edges") && err.contains(aa) && err.lines().count() == 1,
            "{aa} {edges}: {err}"
        );
        assert!(!err.contains("no-such-device"), "{err}");
    }
}
