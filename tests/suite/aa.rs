//! The post chain's anti-aliasing stages on lavapipe, validation on (issue 17):
//! MLAA's passes against the CPU references of `dermis::aa` on synthetic
//! tone-mapped frames (edges exactly, blending weights exactly, the passes
//! after the first culled to the edge pixels by the stencil, proved by
//! samples passed and by shader invocations), locality (no pixel off an edge
//! changes), and FXAA's and MLAA's error against a supersampled image.
//! SMAA 1x's edges against its reference, its stencil culling, a step edge's
//! weights against the area table, its diagonal path, and every stage's
//! set-up failing cleanly at each creation step.
//!
//! Over 800 lines because every test here shares the synthetic frames (the
//! tie-free random blocks, staircases, supersampled scenes) and the
//! read-back glue defined once at the top: split, each part would need them
//! again.

use crate::common;

use dermis::aa::edges::{
    mlaa_luma_edges, smaa_luma_edges, Edgel, Edges, Image, LocalContrast, Preset,
    MLAA_LUMA_THRESHOLD,
};
use dermis::aa::mlaa_area::MlaaAreaTex;
use dermis::aa::mlaa_weights::{edge_pixels, top_line, weights, SEARCH_DISTANCE};
use dermis::aa::revector;
use dermis::format::srgb_to_linear;
use dermis::post::AaMode;
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::egg_scene;
use dermis::vk::context::Context;

pub(crate) fn settings(w: u32, h: u32, aa: AaMode) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        shadow_size: 64,
        aa,
        ..RenderSettings::study().with(common::m("none"), &[])
    }
}

/// An sRGB-encoded RGBA8 frame as the gamma-space floats the CPU references read.
pub(crate) fn gamma(rgba8: &[u8]) -> Vec<[f32; 4]> {
    rgba8
        .chunks_exact(4)
        .map(|c| [0, 1, 2, 3].map(|i| c[i] as f32 / 255.0))
        .collect()
}

/// A deterministic generator (xorshift), so the images repeat.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// Overlapping rectangles of random colours on a grey ground, and a few
/// aliased discs: lines of every length, corners, U, Z and L shapes. Colours
/// whose luma difference lies within 1e-3 of the threshold are drawn again,
/// so the f32 ulps of a GPU dot product cannot flip an edgel (no ties).
fn blocks(w: usize, h: usize, seed: u64) -> Vec<u8> {
    blocks_with(w, h, seed, false)
}

/// `blocks` for SMAA (`ratio_ties`): neither do two luma differences of the
/// palette lie within 1e-3 of a factor 2 (the local contrast test `2 c >=
/// c_max`), with a palette of 7.
pub(crate) fn blocks_with(w: usize, h: usize, seed: u64, ratio_ties: bool) -> Vec<u8> {
    let mut rng = Rng(seed);
    let mut palette: Vec<[u8; 3]> = vec![[128, 128, 128]];
    let luma = |c: [u8; 3]| {
        dermis::aa::edges::luma([
            c[0] as f32 / 255.0,
            c[1] as f32 / 255.0,
            c[2] as f32 / 255.0,
            1.0,
        ])
    };
    let deltas = |p: &[[u8; 3]]| -> Vec<f32> {
        let mut d = vec![0.0];
        for (i, a) in p.iter().enumerate() {
            for b in &p[i + 1..] {
                d.push((luma(*a) - luma(*b)).abs());
            }
        }
        d
    };
    let size = if ratio_ties { 7 } else { 8 };
    let mut tries = 0;
    while palette.len() < size {
        tries += 1;
        assert!(tries < 1_000_000, "no palette without ties");
        let c = [0, 1, 2].map(|_| rng.below(256) as u8);
        let far = palette
            .iter()
            .all(|&p| ((luma(p) - luma(c)).abs() - MLAA_LUMA_THRESHOLD).abs() > 1e-3);
        let mut with = palette.clone();
        with.push(c);
        let d = deltas(&with);
        let no_ratio_tie = d
            .iter()
            .all(|&x| d.iter().all(|&y| x == y || (2.0 * x - y).abs() > 1e-3));
        if far && (!ratio_ties || no_ratio_tie) {
            palette = with;
        }
    }
    let mut px = vec![palette[0]; w * h];
    for k in 0..14 {
        let c = palette[1 + k % (palette.len() - 1)];
        let (x0, y0) = (rng.below(w as u64) as usize, rng.below(h as u64) as usize);
        let (rw, rh) = (
            2 + rng.below(w as u64 / 2) as usize,
            1 + rng.below(h as u64 / 3) as usize,
        );
        if k % 3 == 2 {
            // A disc of radius rh.
            let r = (rh + 2) as f32;
            for (i, p) in px.iter_mut().enumerate() {
                let (dx, dy) = ((i % w) as f32 - x0 as f32, (i / w) as f32 - y0 as f32);
                if dx * dx + dy * dy <= r * r {
                    *p = c;
                }
            }
        } else {
            for y in y0..(y0 + rh).min(h) {
                for x in x0..(x0 + rw).min(w) {
                    px[y * w + x] = c;
                }
            }
        }
    }
    px.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect()
}

/// The GPU's edges texture as `Edges` (.r left, .g top).
pub(crate) fn gpu_edges(r: &mut Renderer, w: usize, h: usize) -> Edges {
    let id = r.post_image("edges").unwrap();
    let tex = r.read_back(id).unwrap();
    Edges {
        width: w,
        height: h,
        edgels: tex
            .iter()
            .map(|t| Edgel {
                left: t[0] > 0.5,
                top: t[1] > 0.5,
            })
            .collect(),
    }
}

/// The GPU's weights texture as bytes.
fn gpu_weights(r: &mut Renderer) -> Vec<[u8; 4]> {
    let id = r.post_image("weights").unwrap();
    r.read_back(id)
        .unwrap()
        .iter()
        .map(|t| t.map(|v| (v * 255.0).round() as u8))
        .collect()
}

/// The CPU mirror's weights with the area texture's bytes.
fn cpu_weights(edges: &Edges) -> Vec<[u8; 4]> {
    let tex = MlaaAreaTex::generate();
    let rg8 = tex.rg8();
    let w = weights(edges, |l| {
        let Some(p) = l.pattern else { return [0.0; 2] };
        let (x, y) = dermis::aa::mlaa_area::texel(p, l.left, l.right).expect("within reach");
        let i = 2 * (y * dermis::aa::mlaa_area::AREA_SIZE + x);
        [rg8[i] as f32 / 255.0, rg8[i + 1] as f32 / 255.0]
    });
    w.iter()
        .map(|t| t.map(|v| (v * 255.0).round() as u8))
        .collect()
}

struct MlaaRun {
    cpu_edges: Edges,
    gpu_edges: Edges,
    input: Vec<[f32; 4]>,
    output: Vec<[f32; 4]>,
    samples: Vec<dermis::graph::PassSample>,
    weights: Vec<[u8; 4]>,
}

fn run_mlaa(ctx: &Context, w: usize, h: usize, rgba8: &[u8]) -> MlaaRun {
    let mut r = Renderer::new(
        ctx,
        &egg_scene(),
        &settings(w as u32, h as u32, AaMode::Mlaa),
    )
    .unwrap();
    r.upload_ldr(rgba8).unwrap();
    let (output, samples) = r.run_post_only().unwrap();
    let px = gamma(rgba8);
    MlaaRun {
        cpu_edges: mlaa_luma_edges(&Image::new(w, h, &px).unwrap(), MLAA_LUMA_THRESHOLD).unwrap(),
        gpu_edges: gpu_edges(&mut r, w, h),
        input: rgba8
            .chunks_exact(4)
            .map(|c| {
                [
                    srgb_to_linear(c[0]),
                    srgb_to_linear(c[1]),
                    srgb_to_linear(c[2]),
                    c[3] as f32 / 255.0,
                ]
            })
            .collect(),
        output,
        weights: gpu_weights(&mut r),
        samples,
    }
}

const W: usize = 96;
const H: usize = 64;

/// Pass 1 against `aa::edges::mlaa_luma_edges` and pass 2 against the CPU
/// mirror `aa::mlaa_weights`, both exactly, on three synthetic frames.
#[test]
fn mlaa_edges_and_weights_equal_the_cpu_references() {
    let ctx = common::ctx();
    for seed in [7, 1234, 99991] {
        let run = run_mlaa(&ctx, W, H, &blocks(W, H, seed));
        let edgels = run
            .cpu_edges
            .edgels
            .iter()
            .filter(|e| e.left || e.top)
            .count();
        assert!(edgels > 100, "seed {seed}: only {edgels} edgels");
        for (i, (g, c)) in run
            .gpu_edges
            .edgels
            .iter()
            .zip(&run.cpu_edges.edgels)
            .enumerate()
        {
            assert_eq!(g, c, "seed {seed}: edgels of pixel ({}, {})", i % W, i / W);
        }
        let cpu = cpu_weights(&run.cpu_edges);
        let nonzero = cpu.iter().filter(|t| t.iter().any(|&v| v > 0)).count();
        for (i, (g, c)) in run.weights.iter().zip(&cpu).enumerate() {
            assert_eq!(g, c, "seed {seed}: weights of pixel ({}, {})", i % W, i / W);
        }
        println!("seed {seed}: {edgels} pixels with an edgel, {nonzero} with a non-zero weight: GPU = CPU");
        assert!(nonzero > 50, "seed {seed}: {nonzero}");
    }
}

/// Passes 2 and 3 run on the edge pixels only: their samples passed equal the
/// CPU reference's count of pixels with an edgel on any side (what pass 1's
/// discard leaves in the stencil), and so do pass 1's.
#[test]
fn mlaa_stencil_culls_passes_2_and_3_to_the_edge_pixels() {
    let ctx = common::ctx();
    let run = run_mlaa(&ctx, W, H, &blocks(W, H, 7));
    let expected = edge_pixels(&run.cpu_edges).iter().filter(|&&e| e).count() as u64;
    for name in ["mlaa edges", "mlaa weights", "mlaa blend"] {
        let p = run.samples.iter().find(|p| p.name == name).unwrap();
        println!(
            "{name}: {} samples passed of {} pixels, {:?} fragment invocations, {:.3} ms",
            p.samples_passed,
            W * H,
            p.fragment_invocations,
            p.gpu_ms
        );
        assert_eq!(p.samples_passed, expected, "{name}");
    }
    assert!(expected > 0 && expected < (W * H) as u64 / 2, "{expected}");
}

/// The same by shader invocations on a rendered frame (the fetch-counting
/// build counts invocations that reach main): with early stencil, passes 2 and
/// 3 run exactly once per edge pixel of the frame's own edges texture, pass 1
/// once per pixel; llvmpipe's pipeline statistics count rasterised blocks
/// before the early tests (docs/tests.md), so these counts are the proof.
#[test]
fn mlaa_shaders_run_once_per_edge_pixel() {
    let ctx = common::counting_ctx();
    let s = RenderSettings {
        distance_heads: 1.5,
        ..settings(96, 64, AaMode::Mlaa)
    };
    let mut r = Renderer::new(&ctx, &egg_scene(), &s).unwrap();
    let counts = r.count_fetches().unwrap();
    let edges = gpu_edges(&mut r, 96, 64);
    let expected = edge_pixels(&edges).iter().filter(|&&e| e).count() as u64;
    let inv = |name: &str| counts.iter().find(|c| c.name == name).unwrap().invocations;
    println!(
        "edge pixels {expected} of {}; invocations: edges {}, weights {}, blend {}",
        96 * 64,
        inv("mlaa edges"),
        inv("mlaa weights"),
        inv("mlaa blend")
    );
    assert!(expected > 0, "the egg has a silhouette");
    assert_eq!(inv("mlaa edges"), 96 * 64);
    assert_eq!(inv("mlaa weights"), expected);
    assert_eq!(inv("mlaa blend"), expected);
}

/// A rising staircase of runs `n` (a step edge of slope 1/n): the GPU's
/// weights equal the CPU mirror's byte for byte, and along an interior run
/// they sum to the chapter's Z area, n/4 (two triangles of n/8), within the
/// area texture's 8-bit rounding.
#[test]
fn mlaa_weights_of_a_step_edge_follow_the_chapters_formula() {
    let ctx = common::ctx();
    let (w, h) = (64usize, 24usize);
    for n in [3usize, 5, 8] {
        let (dark, light) = (51u8, 204u8);
        let rgba8: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                let v = if y + x / n >= 20 { light } else { dark };
                [v, v, v, 255]
            })
            .collect();
        let run = run_mlaa(&ctx, w, h, &rgba8);
        assert_eq!(run.gpu_edges, run.cpu_edges, "n {n}");
        assert_eq!(run.weights, cpu_weights(&run.cpu_edges), "n {n}");
        let k = 2;
        let row = 20 - k;
        let mut gpu_sum = 0.0;
        let mut exact_sum = 0.0;
        for x in k * n..k * n + n {
            let l = top_line(&run.cpu_edges, x, row).unwrap();
            let a = revector::area(l.pattern.unwrap(), l.left as f64, l.right as f64, 0.0, None);
            exact_sum += a[0] + a[1];
            let t = run.weights[row * w + x];
            gpu_sum += (t[0] as f64 + t[1] as f64) / 255.0;
        }
        println!(
            "n {n}: run weights sum {gpu_sum:.4} on the GPU, {exact_sum:.4} exact, n/4 = {:.4}",
            n as f64 / 4.0
        );
        assert!((exact_sum - n as f64 / 4.0).abs() < 1e-9);
        assert!(
            (gpu_sum - n as f64 / 4.0).abs() <= n as f64 / 255.0,
            "n {n}: {gpu_sum}"
        );
    }
}

/// No pixel off the edges changes: every changed pixel has an edgel on one of
/// its sides, so none farther than the search distance from an edge does.
#[test]
fn mlaa_changes_no_pixel_away_from_an_edge() {
    let ctx = common::ctx();
    for seed in [7, 1234] {
        let run = run_mlaa(&ctx, W, H, &blocks(W, H, seed));
        let on_edge = edge_pixels(&run.cpu_edges);
        let mut changed = 0;
        for (i, (o, x)) in run.output.iter().zip(&run.input).enumerate() {
            if o == x {
                continue;
            }
            changed += 1;
            assert!(
                on_edge[i],
                "seed {seed}: pixel ({}, {}) off every edge changed",
                i % W,
                i / W
            );
            let near = (0..W * H).any(|j| {
                on_edge[j]
                    && (j % W).abs_diff(i % W) <= SEARCH_DISTANCE
                    && (j / W).abs_diff(i / W) <= SEARCH_DISTANCE
            });
            assert!(
                near,
                "seed {seed}: pixel {i} farther than {SEARCH_DISTANCE} from an edge"
            );
        }
        println!("seed {seed}: {changed} pixels changed, all on edges");
        assert!(changed > 50, "MLAA blended something: {changed}");
    }
}

/// A slanted half-plane and a disc, white on black, box-filtered from 16 x 16
/// samples per pixel (the supersampled truth, linear light) and point-sampled
/// at pixel centres (aliased).
fn edge_scene(w: usize, h: usize) -> (Vec<u8>, Vec<[f32; 4]>) {
    sampled_scene(w, h, |x, y| {
        let line = y > 0.35 * x + 6.0 && x < 0.7 * w as f32;
        let (dx, dy) = (x - 0.75 * w as f32, y - 0.4 * h as f32);
        line || dx * dx + dy * dy < 14.0 * 14.0
    })
}

/// White where `inside` holds on black: (point-sampled RGBA8, 16 x 16
/// box-filtered linear truth).
fn sampled_scene(
    w: usize,
    h: usize,
    inside: impl Fn(f32, f32) -> bool,
) -> (Vec<u8>, Vec<[f32; 4]>) {
    let s = 16;
    let mut aliased = Vec::new();
    let mut truth = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let v = if inside(x as f32 + 0.5, y as f32 + 0.5) {
                255
            } else {
                0
            };
            aliased.extend([v, v, v, 255]);
            let mut n = 0;
            for j in 0..s {
                for i in 0..s {
                    let (px, py) = (
                        x as f32 + (i as f32 + 0.5) / s as f32,
                        y as f32 + (j as f32 + 0.5) / s as f32,
                    );
                    n += usize::from(inside(px, py));
                }
            }
            let c = n as f32 / (s * s) as f32;
            truth.push([c, c, c, 1.0]);
        }
    }
    (aliased, truth)
}

fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| {
            (0..3)
                .map(|c| (p[c] as f64 - q[c] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

/// Each mode lowers the error to the supersampled image: RMSE (linear light,
/// whole image) at most `MARGIN` of the aliased image's.
#[test]
fn fxaa_and_mlaa_lower_the_error_to_a_supersampled_edge() {
    const MARGIN: f64 = 0.65;
    let ctx = common::ctx();
    let (w, h) = (96usize, 64usize);
    let (aliased, truth) = edge_scene(w, h);
    let aliased_lin: Vec<[f32; 4]> = aliased
        .chunks_exact(4)
        .map(|c| {
            [
                srgb_to_linear(c[0]),
                srgb_to_linear(c[1]),
                srgb_to_linear(c[2]),
                1.0,
            ]
        })
        .collect();
    let base = rmse(&aliased_lin, &truth);
    for mode in [AaMode::Fxaa, AaMode::Mlaa, AaMode::Smaa] {
        let mut r = Renderer::new(&ctx, &egg_scene(), &settings(w as u32, h as u32, mode)).unwrap();
        r.upload_ldr(&aliased).unwrap();
        let (out, samples) = r.run_post_only().unwrap();
        let e = rmse(&out, &truth);
        let ms: f64 = samples.iter().map(|s| s.gpu_ms).sum();
        println!(
            "{mode}: RMSE {e:.4} against the aliased image's {base:.4} (ratio {:.3}), {ms:.3} ms",
            e / base
        );
        assert!(e <= MARGIN * base, "{mode}: {e:.4} vs {base:.4}");
    }
}

/// Whole frames under validation: each mode renders; MLAA's frame equals
/// the frame without anti-aliasing on every pixel off its edges, FXAA's
/// differs somewhere; `--aa none` records no post pass.
#[test]
fn every_mode_renders_a_frame() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let (w, h) = (96u32, 64u32);
    let frame = |aa| {
        let s = RenderSettings {
            distance_heads: 1.5,
            ..settings(w, h, aa)
        };
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let names: Vec<String> = r.passes().iter().map(|p| p.name.clone()).collect();
        (r.capture(false).unwrap(), names)
    };
    let (none, none_passes) = frame(AaMode::None);
    assert!(!none_passes
        .iter()
        .any(|n| n.starts_with("mlaa") || n.starts_with("fxaa")));
    let (mlaa, mlaa_passes) = frame(AaMode::Mlaa);
    for p in ["mlaa edges", "mlaa weights", "mlaa copy", "mlaa blend"] {
        assert!(mlaa_passes.iter().any(|n| n == p), "{p}: {mlaa_passes:?}");
    }
    let px = gamma(&none.ldr);
    let edges = mlaa_luma_edges(
        &Image::new(w as usize, h as usize, &px).unwrap(),
        MLAA_LUMA_THRESHOLD,
    )
    .unwrap();
    let on_edge = edge_pixels(&edges);
    let mut changed = 0;
    let pairs = none.ldr.chunks_exact(4).zip(mlaa.ldr.chunks_exact(4));
    for (i, ((a, b), &edge)) in pairs.zip(&on_edge).enumerate() {
        if a != b {
            changed += 1;
            assert!(edge, "pixel {i} off the edges changed");
        }
    }
    assert!(changed > 0, "MLAA changed no pixel of the egg's silhouette");
    let (smaa, smaa_passes) = frame(AaMode::Smaa);
    for p in ["smaa edges", "smaa weights", "smaa blend"] {
        assert!(smaa_passes.iter().any(|n| n == p), "{p}: {smaa_passes:?}");
    }
    assert!(smaa.ldr != none.ldr, "SMAA changed nothing");
    let (fxaa, fxaa_passes) = frame(AaMode::Fxaa);
    assert!(fxaa_passes.iter().any(|n| n == "fxaa"));
    assert!(fxaa.ldr != none.ldr, "FXAA changed nothing");
    println!("MLAA changed {changed} of {} pixels", w * h);
}

/// A post-only SMAA run: the renderer (to read its images back), the output
/// and the pass samples.
type SmaaRun<'c> = (Renderer<'c>, Vec<[f32; 4]>, Vec<dermis::graph::PassSample>);

fn run_smaa<'c>(ctx: &'c Context, w: usize, h: usize, rgba8: &[u8]) -> SmaaRun<'c> {
    let mut r = Renderer::new(
        ctx,
        &egg_scene(),
        &settings(w as u32, h as u32, AaMode::Smaa),
    )
    .unwrap();
    r.upload_ldr(rgba8).unwrap();
    let (out, samples) = r.run_post_only().unwrap();
    (r, out, samples)
}

/// SMAA's edge pass against `aa::edges::smaa_luma_edges` (threshold 0.1,
/// SMAA.hlsl's shared local-contrast maximum) exactly; its weights pass runs
/// on the pixels with a thresholded left or top delta only (what pass 1
/// keeps in the stencil before the adaptation), by samples passed.
#[test]
fn smaa_edges_equal_the_cpu_reference_and_the_stencil_culls_the_weights() {
    let ctx = common::ctx();
    let mut removed = 0;
    // Vertical grey stripes whose steps differ enough that the local contrast
    // test removes the weaker edgels beside the strong ones (no ties: every
    // delta and twice every delta is far from 0.1 and from every other).
    let stripes: Vec<u8> = (0..W * H)
        .flat_map(|i| {
            let v = [20u8, 60, 240, 130, 90][i % W % 5];
            [v, v, v, 255]
        })
        .collect();
    let images = [7, 1234, 99991]
        .map(|seed| (seed, blocks_with(W, H, seed, true)))
        .into_iter()
        .chain([(0, stripes)]);
    for (seed, rgba8) in images {
        let (mut r, _, samples) = run_smaa(&ctx, W, H, &rgba8);
        let px = gamma(&rgba8);
        let img = Image::new(W, H, &px).unwrap();
        let cpu = smaa_luma_edges(&img, Preset::High.threshold(), LocalContrast::Shared).unwrap();
        let gpu = gpu_edges(&mut r, W, H);
        for (i, (g, c)) in gpu.edgels.iter().zip(&cpu.edgels).enumerate() {
            assert_eq!(g, c, "seed {seed}: edgels of pixel ({}, {})", i % W, i / W);
        }
        let thresholded = mlaa_luma_edges(&img, Preset::High.threshold()).unwrap();
        let kept = thresholded
            .edgels
            .iter()
            .filter(|e| e.left || e.top)
            .count() as u64;
        let adapted = cpu.edgels.iter().filter(|e| e.left || e.top).count();
        for name in ["smaa edges", "smaa weights"] {
            let p = samples.iter().find(|p| p.name == name).unwrap();
            assert_eq!(p.samples_passed, kept, "seed {seed}: {name}");
        }
        let blend = samples.iter().find(|p| p.name == "smaa blend").unwrap();
        assert_eq!(
            blend.samples_passed,
            (W * H) as u64,
            "the blend runs everywhere"
        );
        println!("seed {seed}: {kept} pixels pass the threshold (samples passed of edges and weights), {adapted} keep an edgel after the local contrast test: GPU = CPU");
        assert!(adapted as u64 <= kept && adapted > 60, "seed {seed}");
        removed += kept - adapted as u64;
    }
    assert!(removed > 0, "the local contrast test removed no edgel");
}

/// A bilinear fetch of the SMAA area texture's bytes at texture coordinate
/// `uv` (texel centres at i + 0.5, clamp to edge), as areas.
fn area_bilinear(uv: [f32; 2]) -> [f32; 2] {
    let (w, h) = (dermis::aa::smaa_area::WIDTH, dermis::aa::smaa_area::HEIGHT);
    let rg = dermis::aa::smaa_area::area_tex_rg8();
    let (fx, fy) = (uv[0] * w as f32 - 0.5, uv[1] * h as f32 - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let at = |x: f32, y: f32, c: usize| {
        let x = (x as isize).clamp(0, w as isize - 1) as usize;
        let y = (y as isize).clamp(0, h as isize - 1) as usize;
        rg[2 * (y * w + x) + c] as f32 / 255.0
    };
    [0, 1].map(|c| {
        let top = at(x0, y0, c) * (1.0 - tx) + at(x0 + 1.0, y0, c) * tx;
        let bottom = at(x0, y0 + 1.0, c) * (1.0 - tx) + at(x0 + 1.0, y0 + 1.0, c) * tx;
        top * (1.0 - ty) + bottom * ty
    })
}

/// A rising staircase of runs `n`: on an interior run every top edgel is a
/// rising Z (crossing below at the left end, above at the right: e = 0.75,
/// 0.25), with no diagonal (n >= 3) and no corner to round, so its SMAA
/// weights are the area texture at `sqrt` of the distances to the run's ends
/// (`smaa_area::ortho_texcoord`, bilinear): the GPU's within two 8-bit steps
/// (lavapipe's filter weights are fixed point). This checks the searches'
/// distances, the crossing edges and the table's orientation on Vulkan.
#[test]
fn smaa_weights_of_a_step_edge_are_the_area_texture_at_its_distances() {
    let ctx = common::ctx();
    let (w, h) = (96usize, 24usize);
    for n in [3usize, 5, 8, 12] {
        let rgba8: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                let v = if y + x / n >= 20 { 204 } else { 51 };
                [v, v, v, 255]
            })
            .collect();
        let (mut r, _, _) = run_smaa(&ctx, w, h, &rgba8);
        let weights = gpu_weights(&mut r);
        let k = 2;
        let row = 20 - k;
        let mut worst: f32 = 0.0;
        let mut sum = 0.0;
        for x in k * n..k * n + n {
            let (l, rt) = ((x - k * n) as f32, (k * n + n - 1 - x) as f32);
            let uv = dermis::aa::smaa_area::ortho_texcoord([l.sqrt(), rt.sqrt()], 0.75, 0.25, 0);
            let want = area_bilinear(uv);
            let t = weights[row * w + x];
            for c in 0..2 {
                worst = worst.max((t[c] as f32 / 255.0 - want[c]).abs());
            }
            sum += (t[0] as f64 + t[1] as f64) / 255.0;
        }
        println!(
            "n {n}: worst |GPU - table| {:.4}, run weights sum {sum:.4} (the exact Z: n/4 = {:.4})",
            worst,
            n as f64 / 4.0
        );
        assert!(worst <= 2.0 / 255.0 + 1e-6, "n {n}: {worst}");
    }
}

/// SMAA changes no pixel off its edges: a changed pixel has a non-zero
/// weight on one of its four sides, which needs an edgel there.
#[test]
fn smaa_changes_no_pixel_away_from_an_edge() {
    let ctx = common::ctx();
    let rgba8 = blocks_with(W, H, 1234, true);
    let (mut r, out, _) = run_smaa(&ctx, W, H, &rgba8);
    let on_edge = edge_pixels(&gpu_edges(&mut r, W, H));
    let input: Vec<[f32; 4]> = rgba8
        .chunks_exact(4)
        .map(|c| {
            [
                srgb_to_linear(c[0]),
                srgb_to_linear(c[1]),
                srgb_to_linear(c[2]),
                c[3] as f32 / 255.0,
            ]
        })
        .collect();
    let mut changed = 0;
    for (i, (o, x)) in out.iter().zip(&input).enumerate() {
        if o != x {
            changed += 1;
            assert!(
                on_edge[i],
                "pixel ({}, {}) off every edge changed",
                i % W,
                i / W
            );
        }
    }
    println!("{changed} pixels changed, all on edges");
    assert!(changed > 50, "{changed}");
}

/// A 45-degree staircase is a diagonal pattern for SMAA (ch. 10.4.2): every
/// interior top edgel takes the diagonal half of the area table, pattern 0
/// (both ends past the 8-step diagonal search), whose texels hold (64, 64):
/// a quarter each way, where the orthogonal path would see one-pixel lines.
/// The errors to the supersampled truth are printed, not asserted for SMAA:
/// for this line (0.3 pixel below the steps' corners) the table's blend of the
/// black pixel across, 0.25, overshoots its true 0.045 (docs/aa.md).
#[test]
fn smaa_takes_the_diagonal_path_on_45_degree_edges() {
    let ctx = common::ctx();
    let (w, h) = (96usize, 64usize);
    let (aliased, truth) = sampled_scene(w, h, |x, y| {
        let a = y > x - 20.3 && x < 60.0;
        let b = y < 90.7 - x && x >= 60.0;
        a || b
    });
    let lin = |rgba8: &[u8]| -> Vec<[f32; 4]> {
        rgba8
            .chunks_exact(4)
            .map(|c| {
                [
                    srgb_to_linear(c[0]),
                    srgb_to_linear(c[1]),
                    srgb_to_linear(c[2]),
                    1.0,
                ]
            })
            .collect()
    };
    let base = rmse(&lin(&aliased), &truth);
    let rg = dermis::aa::smaa_area::area_tex_rg8();
    let (tx, ty) = dermis::aa::smaa_area::diag_texel(0, 7, 7, 0);
    let t = 2 * (ty * dermis::aa::smaa_area::WIDTH + tx);
    let table = [rg[t], rg[t + 1]];
    assert_eq!(table, [64, 64]);
    let mut errors = Vec::new();
    for mode in [AaMode::Mlaa, AaMode::Smaa, AaMode::Fxaa] {
        let mut r = Renderer::new(&ctx, &egg_scene(), &settings(w as u32, h as u32, mode)).unwrap();
        r.upload_ldr(&aliased).unwrap();
        let (out, _) = r.run_post_only().unwrap();
        if mode == AaMode::Smaa {
            let weights = gpu_weights(&mut r);
            // The falling diagonal's top edgels, ten pixels from both its ends.
            for x in 32..50 {
                let y = x - 20;
                assert_eq!(weights[y * w + x][..2], table, "({x}, {y})");
            }
        }
        let e = rmse(&out, &truth);
        println!("{mode} on 45-degree edges: RMSE {e:.4} against the aliased image's {base:.4} (ratio {:.3})", e / base);
        errors.push(e);
    }
    assert!(errors[0] < base && errors[2] < base, "{errors:?} vs {base}");
}

/// Every anti-aliasing stage tears down clean, also when its set-up fails:
/// the renderer's set-up is made to fail at each of its creation steps in
/// turn (`Context::fail_creation_after`, as tests/teardown.rs does for the
/// methods; the stage's pipelines, table uploads and images among them);
/// each failure is one error line and frees its memory at once, and after a
/// clean frame the device is destroyed with nothing left.
#[test]
fn every_stage_and_every_failed_stage_set_up_tear_down_clean() {
    let scene = egg_scene();
    for mode in [AaMode::Fxaa, AaMode::Mlaa, AaMode::Smaa] {
        let ctx = common::ctx();
        let s = settings(64, 36, mode);
        let steps = common::fail_each_creation_step(&ctx, &scene, &s, &mode.to_string());
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        r.capture(false).unwrap();
        drop(r);
        ctx.finish()
            .unwrap_or_else(|e| panic!("{mode}: teardown after {steps} failures: {e:#}"));
        println!("{mode}: {steps} creation steps failed in turn, clean");
    }
}

/// Pass 3 against Eq. 9.1 and Listing 9.5 on the GPU's own weights: every
/// pixel's output is the average, weighted by its four areas (its own top
/// and left edgels' first, the bottom neighbour's top and the right
/// neighbour's left edgels' second), of its colour blended toward each
/// neighbour by that area, in linear light; pixels without weight keep their
/// colour exactly. Within 2.5/255 in linear light: the sRGB output's half step
/// (up to 2.4 times larger in linear at the bright end) and lavapipe's
/// fixed-point filter weights.
#[test]
fn mlaa_blend_is_the_area_weighted_average_of_eq_9_1() {
    let ctx = common::ctx();
    for seed in [7, 99991] {
        let rgba8 = blocks(W, H, seed);
        let run = run_mlaa(&ctx, W, H, &rgba8);
        let c = |x: usize, y: usize| run.input[y.min(H - 1) * W + x.min(W - 1)];
        let wt = |x: usize, y: usize, k: usize| {
            run.weights[y.min(H - 1) * W + x.min(W - 1)][k] as f32 / 255.0
        };
        let mut worst: f32 = 0.0;
        let mut blended = 0;
        for y in 0..H {
            for x in 0..W {
                // North, south, west, east, and the neighbour each blends toward.
                let a = [wt(x, y, 0), wt(x, y + 1, 1), wt(x, y, 2), wt(x + 1, y, 3)];
                let n = [
                    c(x, y.saturating_sub(1)),
                    c(x, y + 1),
                    c(x.saturating_sub(1), y),
                    c(x + 1, y),
                ];
                let sum: f32 = a.iter().sum();
                let out = run.output[y * W + x];
                if sum == 0.0 {
                    assert_eq!(out, c(x, y), "seed {seed}: ({x}, {y}) has no weight");
                    continue;
                }
                blended += 1;
                for ch in 0..3 {
                    let want: f32 = (0..4)
                        .map(|k| a[k] * ((1.0 - a[k]) * c(x, y)[ch] + a[k] * n[k][ch]))
                        .sum::<f32>()
                        / sum;
                    worst = worst.max((out[ch] - want).abs());
                }
            }
        }
        println!(
            "seed {seed}: {blended} pixels blended, worst |GPU - Eq. 9.1| {worst:.5} (linear)"
        );
        assert!(blended > 100, "{blended}");
        assert!(worst <= 2.5 / 255.0, "seed {seed}: {worst}");
    }
}

/// `dermis render --aa MODE` (validation on): the report names the mode and
/// lists its passes, role `post`, timed and counted like every other pass;
/// without `--aa` the report has no `aa` key; a mode it does not know is one
/// error line.
#[test]
fn render_reports_the_mode_and_its_passes() {
    let dir = dermis::scene::gltf_load::fixture::temp_dir("aa");
    let render = |aa: Option<&str>, out: &std::path::Path| {
        let mut c = common::dermis();
        c.args([
            "render",
            "--validate",
            "--device",
            "llvmpipe",
            "--width",
            "64",
        ])
        .args(["--height", "48", "--frames", "2", "--warmup", "0", "--out"])
        .arg(out);
        if let Some(aa) = aa {
            c.args(["--aa", aa]);
        }
        c.output().unwrap()
    };
    for (mode, passes) in [
        (
            "mlaa",
            &["mlaa edges", "mlaa weights", "mlaa copy", "mlaa blend"][..],
        ),
        ("smaa", &["smaa edges", "smaa weights", "smaa blend"][..]),
        ("fxaa", &["fxaa"][..]),
    ] {
        let out = dir.join(mode);
        let o = render(Some(mode), &out);
        assert!(
            o.status.success(),
            "{mode}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["aa"], mode);
        let listed: Vec<&serde_json::Value> = report["passes"].as_array().unwrap().iter().collect();
        for p in passes {
            let q = listed
                .iter()
                .find(|q| q["name"] == *p)
                .unwrap_or_else(|| panic!("{mode}: no pass {p} in the report"));
            assert_eq!(q["role"], "post", "{p}");
        }
    }
    let out = dir.join("none");
    assert!(render(None, &out).status.success());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(report.get("aa").is_none());
    let o = render(Some("smaa-t2x"), &dir.join("bad"));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("smaa-t2x"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
