//! The compute path (`--path compute`): its images against the fragment
//! path's on the same inputs, its tile list by counts (the tiles dispatched
//! are the tiles that hold skin, predicted here from the mask), and a kernel
//! wider than the shared-memory apron.

use crate::common;

use dermis::graph::PassSample;
use dermis::method::tiles::{skin_tiles, TILE_INVOCATIONS};
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::egg_scene;
use dermis::skin::texel::round_f16;

const W: usize = 100;
const H: usize = 70;

/// The shared synthetic inputs (`common::synthetic_sss_inputs`), the
/// island at (93, 64), the depth step from 8.0 to 8.2.
fn inputs() -> (Vec<[f32; 4]>, Vec<f32>, Vec<bool>) {
    common::synthetic_sss_inputs(W, H, (93.0, 64.0), [8.0, 8.2])
}

fn settings() -> RenderSettings {
    RenderSettings {
        width: W as u32,
        height: H as u32,
        shadow_size: 64,
        ..RenderSettings::study()
    }
}

fn run(options: &[(&str, &str)], path: &str) -> (Vec<[f32; 4]>, Vec<PassSample>) {
    run_method("separable", options, path)
}

fn run_method(
    method: &str,
    options: &[(&str, &str)],
    path: &str,
) -> (Vec<[f32; 4]>, Vec<PassSample>) {
    run_on(method, options, path, inputs())
}

type Inputs = (Vec<[f32; 4]>, Vec<f32>, Vec<bool>);

fn run_on(
    method: &str,
    options: &[(&str, &str)],
    path: &str,
    (diffuse, depth, skin): Inputs,
) -> (Vec<[f32; 4]>, Vec<PassSample>) {
    let ctx = common::ctx();
    let scene = egg_scene();
    let mut o = options.to_vec();
    o.push(("path", path));
    let s = settings().with(common::m(method), &o);
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    if method == "poisson" {
        // A view-space normal field with a crease (poisson weighs by normals;
        // the SSS-only run draws no geometry to write them).
        let n16: Vec<u16> = (0..W * H)
            .flat_map(|i| {
                let (x, y) = ((i % W) as f32, (i / W) as f32);
                let nx = if x < 50.0 { -0.3 } else { 0.5 } + 0.1 * (y / 9.0).sin();
                let n = [nx, 0.2 * (x / 13.0).cos(), 1.0];
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                [n[0] / l, n[1] / l, n[2] / l, 0.0].map(|v| half::f16::from_f32(v).to_bits())
            })
            .collect();
        r.upload_normals(&n16).unwrap();
    }
    common::sss_only(&mut r, &diffuse, &depth, &skin)
}

/// A physical invariant no code of ours produced: every method's kernel
/// keeps the light it moves, so uniform light on a flat, all-skin screen
/// comes out as it went in (each channel within 2e-3, the half-float
/// storage of the passes' chain). A compute blur that dropped a tap, read
/// the apron at the wrong offset, or mixed RTF with the wrong weight would
/// darken or tint it.
#[test]
fn uniform_light_comes_out_as_it_went_in_on_the_compute_path() {
    let light = round_f16([0.55, 0.4, 0.3, 1.0]);
    let uniform = || (vec![light; W * H], vec![8.0; W * H], vec![true; W * H]);
    for method in ["separable", "ssg", "ss-jittered", "poisson"] {
        let (out, passes) = run_on(method, &[], "compute", uniform());
        assert!(
            passes
                .iter()
                .any(|p| p.compute_invocations.unwrap_or(0) > 0),
            "{method}: no dispatch ran"
        );
        let mut worst = 0.0f32;
        for p in &out {
            for c in 0..4 {
                worst = worst.max((p[c] - light[c]).abs() / light[c]);
            }
        }
        println!("{method} compute: uniform light, worst relative change {worst:.2e}");
        assert!(worst <= 2e-3, "{method}: uniform light changed by {worst}");
    }
}

/// One half-float ulp of `v` (normal range).
fn ulp16(v: f32) -> f32 {
    2f32.powi(v.abs().max(6.1e-5).log2().floor() as i32 - 10)
}

/// The compute image against the fragment one: every channel within one
/// half-float ulp; returns the share of pixels equal bit for bit.
fn within_one_ulp(name: &str, compute: &[[f32; 4]], fragment: &[[f32; 4]]) -> f64 {
    let _diff = common::DiffOnFailure::new(name, W, H, compute, fragment);
    let (mut worst, mut over) = (0.0f32, 0);
    for i in 0..W * H {
        for c in 0..4 {
            let d = (compute[i][c] - fragment[i][c]).abs() / ulp16(fragment[i][c]);
            worst = worst.max(d);
            over += (d > 1.0) as usize;
        }
    }
    println!("{name}: worst {worst} ulp, {over} channels over one");
    let mut same = 0;
    for i in 0..W * H {
        for c in 0..4 {
            let (a, b) = (compute[i][c], fragment[i][c]);
            assert!(
                (a - b).abs() <= ulp16(b),
                "{name}: pixel ({}, {}) channel {c}: compute {a} fragment {b}",
                i % W,
                i / W
            );
        }
        same += (compute[i] == fragment[i]) as usize;
    }
    same as f64 / (W * H) as f64
}

#[test]
fn compute_matches_fragment_within_one_half_ulp() {
    let (diffuse, _, skin) = inputs();
    for follow in ["true", "false"] {
        for samples in ["9", "17", "33"] {
            let o = [("follow-surface", follow), ("samples", samples)];
            let (frag, _) = run(&o, "fragment");
            let (comp, passes) = run(&o, "compute");
            let name = format!("compute-vs-fragment-follow-{follow}-{samples}");
            let same = within_one_ulp(&name, &comp, &frag);
            println!("{name}: {:.4} of pixels bit for bit", same);
            for i in 0..W * H {
                if !skin[i] {
                    assert_eq!(comp[i], diffuse[i], "{name}: non-skin pixel {i} changed");
                }
            }
            // The blur did something.
            let changed = (0..W * H)
                .filter(|&i| skin[i] && comp[i] != diffuse[i])
                .count();
            assert!(changed > skin.iter().filter(|&&s| s).count() / 2, "{name}");
            // No seed copy on the compute path.
            assert!(passes.iter().all(|p| p.name != "sss seed copy"), "{name}");
        }
    }
}

/// ss-jittered and poisson: the same arithmetic (jittered_body.glsl,
/// poisson_body.glsl) through the same sampler, so the same bits but for
/// the store's rounding; their merge writes the skin pixels back, and no
/// seed copy runs.
#[test]
fn jittered_and_poisson_on_compute_match_fragment() {
    let (diffuse, _, skin) = inputs();
    for (method, pass) in [("ss-jittered", "ss-jittered"), ("poisson", "poisson")] {
        let (frag, _) = run_method(method, &[], "fragment");
        let (comp, passes) = run_method(method, &[], "compute");
        let same = within_one_ulp(&format!("{method}-compute-vs-fragment"), &comp, &frag);
        println!("{method}: {same:.4} of pixels bit for bit");
        for i in 0..W * H {
            if !skin[i] {
                assert_eq!(comp[i], diffuse[i], "{method}: non-skin pixel {i} changed");
            }
        }
        let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
        assert!(
            names.contains(&"sss merge") && !names.iter().any(|n| n.ends_with("seed copy")),
            "{method}: {names:?}"
        );
        let tiles = skin_tiles(&skin, W, H) as u64 * TILE_INVOCATIONS as u64;
        for name in [pass, "sss merge"] {
            let p = passes.iter().find(|p| p.name == name).unwrap();
            if let Some(inv) = p.compute_invocations {
                assert_eq!(inv, tiles, "{method} {name}: invocations");
            }
        }
    }
}

#[test]
fn a_kernel_wider_than_the_apron_reads_beyond_it() {
    // 40 mm at 0.58 mm a pixel: taps reach about 70 px, past the 32-texel
    // apron, where the compute blur reads the images themselves.
    let o = [("sss-width-mm", "40"), ("samples", "33")];
    let (frag, _) = run(&o, "fragment");
    let (comp, _) = run(&o, "compute");
    let same = within_one_ulp("compute-vs-fragment-wide", &comp, &frag);
    println!("wide kernel: {same:.4} of pixels bit for bit");
}

#[test]
fn tiles_dispatched_are_the_tiles_that_hold_skin() {
    let ctx = common::ctx();
    let (_, _, skin) = inputs();
    let (_, passes) = run(&[], "compute");
    let find = |name: &str| {
        passes
            .iter()
            .find(|p| p.name == name)
            .unwrap_or_else(|| panic!("no pass {name}"))
    };
    let Some(inv) = find("sss horizontal").compute_invocations else {
        assert!(
            !ctx.facts.pipeline_statistics,
            "statistics on, yet none counted"
        );
        return;
    };
    let tiles = skin_tiles(&skin, W, H) as u64;
    let all = (W.div_ceil(16) * H.div_ceil(16)) as u64;
    assert!(
        tiles > 0 && tiles < all,
        "the input leaves tiles without skin"
    );
    let per_tile = TILE_INVOCATIONS as u64;
    assert_eq!(inv, tiles * per_tile, "horizontal: invocations");
    assert_eq!(
        find("sss vertical").compute_invocations,
        Some(tiles * per_tile),
        "vertical: invocations"
    );
    // The classification runs over the region's box (here the whole frame).
    assert_eq!(find("sss tiles").compute_invocations, Some(all * per_tile));
    // No fragment work at all.
    for name in ["sss tiles", "sss horizontal", "sss vertical"] {
        assert_eq!(find(name).fragment_invocations, Some(0), "{name}");
    }
}

#[test]
fn no_skin_dispatches_no_tile() {
    let ctx = common::ctx();
    let scene = egg_scene();
    let s = settings().with(common::m("separable"), &[("path", "compute")]);
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let (diffuse, depth, _) = inputs();
    let skin = vec![false; W * H];
    let diffuse: Vec<[f32; 4]> = diffuse.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
    let (gpu, passes) = common::sss_only(&mut r, &diffuse, &depth, &skin);
    assert_eq!(gpu, diffuse, "with no skin the image is untouched");
    for name in ["sss horizontal", "sss vertical"] {
        let p = passes.iter().find(|p| p.name == name).unwrap();
        if let Some(inv) = p.compute_invocations {
            assert_eq!(inv, 0, "{name}");
        }
    }
}

/// The post-SSS diffuse light of one frame of `s` (validation on).
fn frame(s: &RenderSettings) -> (Vec<[f32; 4]>, Vec<PassSample>) {
    let ctx = common::ctx();
    let scene = dermis::scene::default_scene();
    let mut r = Renderer::new(&ctx, &scene, s).expect("renderer");
    let cap = r.capture(false).expect("frame");
    (cap.diffuse, cap.samples)
}

/// Every channel of two frames within one half-float ulp; the share of
/// pixels equal bit for bit.
fn frames_within_one_ulp(name: &str, a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut same = 0;
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..4 {
            assert!(
                (x[c] - y[c]).abs() <= ulp16(y[c]),
                "{name}: pixel {i} channel {c}: compute {} fragment {}",
                x[c],
                y[c]
            );
        }
        same += (x == y) as usize;
    }
    same as f64 / a.len() as f64
}

#[test]
fn the_default_head_is_the_same_on_both_paths() {
    let base = RenderSettings {
        width: 192,
        height: 108,
        shadow_size: 256,
        ..RenderSettings::study()
    };
    let (frag, _) = frame(&base.clone().with(common::m("separable"), &[]));
    let (comp, passes) = frame(
        &base
            .clone()
            .with(common::m("separable"), &[("path", "compute")]),
    );
    let skin = frag.iter().filter(|p| p[3] > 0.0).count();
    assert!(skin > 1000, "{skin} skin pixels");
    let same = frames_within_one_ulp("head", &comp, &frag);
    println!("head: {same:.4} of pixels bit for bit, {skin} skin pixels");
    let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
    for n in [
        "sss tiles reset",
        "sss tiles",
        "sss horizontal",
        "sss vertical",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
}

#[test]
fn a_mixed_frame_takes_the_compute_path_per_group() {
    use dermis::mix::assign::Rules;
    use dermis::render::settings::Assignment;
    use dermis::scene::layout::Layout;
    let mixed = |rules: &str| {
        let rules: Rules = rules.parse().expect("rules");
        RenderSettings {
            width: 160,
            height: 90,
            heads: 5,
            layout: Layout::Crowd,
            distance_heads: 3.0,
            shadow_size: 256,
            assignment: Some(Assignment::Rules(rules)),
            ..RenderSettings::study()
        }
    };
    // Only group 0's path differs: every pixel, its neighbours' included,
    // within one ulp.
    let (frag, _) = frame(&mixed("0=separable,1=separable:preset=physical,*=ssg"));
    let (comp, passes) = frame(&mixed(
        "0=separable:path=compute,1=separable:preset=physical:path=compute,*=ssg",
    ));
    let same = frames_within_one_ulp("mixed", &comp, &frag);
    println!("mixed frame: {same:.4} of pixels bit for bit");
    // Each compute group lists its own tiles.
    let lists = passes
        .iter()
        .filter(|p| p.name.ends_with("sss tiles"))
        .count();
    assert_eq!(
        lists,
        2,
        "{:?}",
        passes.iter().map(|p| &p.name).collect::<Vec<_>>()
    );
}

/// The teardown sweep (tests/teardown.rs) for the compute path: set-up made
/// to fail at each of its creation steps in turn leaves no memory and no
/// object behind (the tile list's pipeline and buffers, the stencil views).
/// Every step of the first method, every fourth of the others from their own
/// offsets (`common::sweep_steps`; `.ci/run` tries every step of each).
#[test]
fn every_failed_setup_step_of_the_compute_path_tears_down_clean() {
    for (i, method) in ["separable", "ssg", "ss-jittered", "poisson"]
        .into_iter()
        .enumerate()
    {
        setup_failures_tear_down_clean(i, method);
    }
}

fn setup_failures_tear_down_clean(case: usize, method: &str) {
    let ctx = common::ctx();
    let scene = dermis::scene::default_scene();
    let s = RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..Default::default()
    }
    .with(common::m(method), &[("path", "compute")]);
    let live =
        |ctx: &dermis::vk::context::Context| ctx.allocator().generate_report().allocations.len();
    let base = live(&ctx);
    let before = ctx.creations();
    drop(Renderer::new(&ctx, &scene, &s).expect("a clean set-up"));
    let steps = ctx.creations() - before;
    let mut tried = 0;
    for k in common::sweep_steps(case, steps) {
        tried += 1;
        ctx.fail_creation_after(Some(k));
        let e = match Renderer::new(&ctx, &scene, &s) {
            Ok(_) => panic!("step {k} of {steps} did not fail"),
            Err(e) => format!("{e:#}"),
        };
        assert!(e.contains("injected failure"), "{method} step {k}: {e}");
        assert_eq!(
            live(&ctx),
            base,
            "{method} step {k} ({e}) left memory allocated"
        );
        ctx.check_validation(&format!("after set-up failed at step {k}"))
            .unwrap();
    }
    ctx.fail_creation_after(None);
    ctx.finish().expect("teardown after every failure");
    println!("{method} on the compute path: {steps} creation steps, {tried} failed in turn, clean");
}

/// ssg on the compute path: each Gaussian's passes over its own tile list
/// (depth-based skipping per tile), each pixel tested as the fragment path's
/// stencil and depth tests test it, RTF mixed as its blend mixes: within one
/// half-float ulp of the fragment path, on synthetic inputs and on the head
/// seen from far enough that the LOD skips Gaussians.
#[test]
fn ssg_compute_matches_fragment_and_skips_gaussians_by_tile() {
    for o in [
        vec![("fit", "6")],
        vec![("fit", "4")],
        vec![("fit", "6"), ("lod", "false")],
    ] {
        let (frag, _) = run_method("ssg", &o, "fragment");
        let (comp, _) = run_method("ssg", &o, "compute");
        let name = format!("ssg-{o:?}");
        let same = within_one_ulp(&name, &comp, &frag);
        println!("{name}: {same:.4} of pixels bit for bit");
    }
    let far = |path: &str| RenderSettings {
        width: 192,
        height: 108,
        shadow_size: 256,
        distance_heads: 4.0,
        ..RenderSettings::study().with(common::m("ssg"), &[("path", path)])
    };
    let (frag, _) = frame(&far("fragment"));
    let (comp, passes) = frame(&far("compute"));
    let same = frames_within_one_ulp("ssg-far", &comp, &frag);
    let inv = |n: &str| {
        passes
            .iter()
            .find(|p| p.name == n)
            .and_then(|p| p.compute_invocations)
    };
    let (first, last) = (inv("ssg g2 horizontal"), inv("ssg g6 horizontal"));
    println!("ssg far: {same:.4} of pixels bit for bit; invocations g2 {first:?}, g6 {last:?}");
    if let (Some(a), Some(b)) = (first, last) {
        // The narrow Gaussian spans under a pixel on this far head: its
        // tiles drop out of its list, the widest Gaussian keeps them.
        assert!(b > 0 && a < b, "g2 {a} g6 {b}");
    }
}
