//! Texture-space diffusion (`tsd`, `tsd-opt`) on lavapipe with validation:
//! the stretch map and the convolution chain against their CPU mirrors on
//! a small synthetic unwrapped mesh, the seams, the optimisations' texels
//! against a CPU visibility prediction (by counts of the fetch-counting build),
//! the depth-sized viewport, the z pre-passes' zero invocations, far
//! characters keeping their maps, and each optimisation's change to the image.
//!
//! Over 800 lines because every test of the area shares one synthetic unwrapped
//! mesh and its CPU mirrors; split, each file would rebuild the fixture.

use crate::common;

use dermis::eval::metrics::relative_rmse;
use dermis::method::tsd::Tsd;
use dermis::render::counting::{site, PassCounts};
use dermis::render::readback::DumpedImage;
use dermis::render::{Capture, RenderSettings, Renderer};
use dermis::scene::mesh::{Material, Mesh, Object, Texture, Vertex};
use dermis::scene::Scene;
use dermis::skin::texel::F16Rounding;
use dermis::skin::tsd::{
    clip_planes, depth_scale, map_size, nearest_corner_distance, reference_distance,
    triangle_stretch, BACKFACE_BIAS, CULL_COS, THESIS_D_REF,
};
use dermis::skin::tsd_mirror::{blur_chain, keeps, texel_hits, ChainInput, KeepRule, VertexTerms};
use glam::Vec3;

// --- Scenes ---------------------------------------------------------------------------

/// A gently curved 60 x 40 mm sheet facing +Z, unwrapped as two islands (a
/// seam down the middle, a gutter between them) with a non-linear u, so the
/// stretch varies from column to column.
fn sheet_mesh() -> Mesh {
    let (nx, ny) = (12usize, 10usize);
    let mut m = Mesh::default();
    for side in 0..2 {
        let first = m.vertices.len() as u32;
        for j in 0..=ny {
            for i in 0..=nx {
                let t = i as f32 / nx as f32;
                let x = -30.0 + 30.0 * side as f32 + 30.0 * t;
                let y = -20.0 + 40.0 * j as f32 / ny as f32;
                let u0 = if side == 0 { 0.03 } else { 0.55 };
                m.vertices.push(Vertex {
                    position: [x, y, 4.0 * (x / 40.0).cos() * (y / 50.0).cos()],
                    normal: [0.0, 0.0, 1.0],
                    uv: [u0 + 0.42 * t.powf(1.4), 0.05 + 0.9 * j as f32 / ny as f32],
                    tangent: [1.0, 0.0, 0.0, 1.0],
                });
            }
        }
        let at = |i: usize, j: usize| first + (j * (nx + 1) + i) as u32;
        for j in 0..ny {
            for i in 0..nx {
                m.indices.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                m.indices.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    m.compute_normals();
    m.generate_tangents();
    m
}

/// A UV sphere of radius `r` (one island, a seam and two poles).
fn sphere_mesh(r: f32) -> Mesh {
    let (rings, segs) = (24usize, 32usize);
    let mut m = Mesh::default();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segs {
            let ph = std::f32::consts::TAU * j as f32 / segs as f32;
            let n = Vec3::new(th.sin() * ph.sin(), th.cos(), th.sin() * ph.cos());
            m.vertices.push(Vertex {
                position: (n * r).into(),
                normal: n.into(),
                uv: [j as f32 / segs as f32, i as f32 / rings as f32],
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: usize, j: usize| (i * (segs + 1) + j) as u32;
    for i in 0..rings {
        for j in 0..segs {
            if i != 0 {
                m.indices.extend([at(i, j), at(i + 1, j), at(i, j + 1)]);
            }
            if i != rings - 1 {
                m.indices
                    .extend([at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)]);
            }
        }
    }
    m.generate_tangents();
    m
}

/// 8 x 8 checks of two skin tones (sRGB).
fn checker() -> Texture {
    let n = 64u32;
    let mut rgba8 = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let c = if (x / 8 + y / 8) % 2 == 0 {
                [220, 170, 150, 255]
            } else {
                [90, 50, 40, 255]
            };
            rgba8.extend(c);
        }
    }
    Texture {
        width: n,
        height: n,
        rgba8,
    }
}

fn scene_of(mesh: Mesh, mm_per_unit: f32, albedo: Option<Texture>) -> Scene {
    let head_bounds = mesh.bounds();
    Scene {
        tracks: None,
        name: "tsd test".into(),
        mm_per_unit,
        head: Object {
            morph: Default::default(),
            mesh,
            material: Material {
                base_color: albedo,
                ..Material::skin([0.8, 0.6, 0.5])
            },
        },
        parts: Vec::new(),
        backdrop: None,
        head_bounds,
        forward: Vec3::Z,
        source: None,
    }
}

fn settings(method: &str, opts: &[(&str, &str)], w: u32, h: u32, distance: f32) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        shadow_size: 256,
        distance_heads: distance,
        ..RenderSettings::study()
    }
    .with(common::m(method), opts)
}

fn dump<'a>(cap: &'a Capture, pass: &str, image: &str) -> &'a DumpedImage {
    cap.dumps
        .iter()
        .find(|d| d.pass == pass && d.image == image)
        .unwrap_or_else(|| panic!("no dump of '{image}' after '{pass}'"))
}

fn counts<'a>(c: &'a [PassCounts], pass: &str) -> &'a PassCounts {
    c.iter()
        .find(|p| p.name == pass)
        .unwrap_or_else(|| panic!("no pass '{pass}'"))
}

fn fetches(c: &PassCounts, s: u32) -> u64 {
    c.fetches.iter().find(|f| f.0 == s).map_or(0, |f| f.1)
}

fn tsd<'a>(r: &'a Renderer<'_>) -> &'a Tsd {
    r.method_as::<Tsd>().expect("a tsd renderer")
}

// --- Stretch and convolution against the CPU ------------------------------------------

// The stretch maps hold each triangle's texels per millimetre (1/|dP/dx|),
// and the twelve passes of the chain give the CPU chain's map (normalised
// convolution on premultiplied coverage, Vulkan bilinear taps, f16 stores)
// from the GPU's own irradiance and stretch maps, up to the stated bound.
#[test]
fn stretch_and_convolution_match_the_cpu_references() {
    let ctx = common::ctx();
    let scene = scene_of(sheet_mesh(), 1.0, Some(checker()));
    let t = 128usize;
    let s = settings("tsd", &[("irradiance-size", "128")], 96, 64, 1.6);
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let cap = r.capture(true).unwrap();
    let irr = dump(&cap, "tsd irradiance c0", "tsd irradiance");
    let su = dump(&cap, "tsd irradiance c0", "tsd stretch u");
    let sv = dump(&cap, "tsd irradiance c0", "tsd stretch v");
    let mesh = &scene.head.mesh;
    let m = tsd(&r);
    assert!(!m.atlas.repacked, "two islands apart keep their UVs");
    let model = m.characters[0].model;
    // Stretch: every covered texel against its triangle's Jacobian.
    let hits = texel_hits(&m.atlas.uv, &mesh.indices, t as u32, 1e-5);
    let (mut checked, mut worst) = (0, 0.0f32);
    for (i, h) in hits.iter().enumerate() {
        let (Some(h), true) = (h, irr.rgba[i][3] > 0.0) else {
            continue;
        };
        let ix = &mesh.indices[3 * h.tri..3 * h.tri + 3];
        let p = [0, 1, 2]
            .map(|k| model.transform_point3(Vec3::from(mesh.vertices[ix[k] as usize].position)));
        let uv = [0, 1, 2].map(|k| m.atlas.uv[ix[k] as usize]);
        let want = triangle_stretch(p, uv, t as f32, scene.mm_per_unit);
        for (got, want) in [(su.rgba[i][0], want[0]), (sv.rgba[i][0], want[1])] {
            worst = worst.max((got - want).abs() / want);
        }
        checked += 1;
    }
    assert!(checked > t * t / 3, "{checked} covered texels");
    assert!(worst < 1e-3, "stretch off by {worst} (relative)");
    // The chain from the GPU's inputs.
    let input = ChainInput {
        size: t,
        area: t,
        irradiance: &irr.rgba,
        stretch_u: &su.rgba.iter().map(|p| p[0]).collect::<Vec<_>>(),
        stretch_v: &sv.rgba.iter().map(|p| p[0]).collect::<Vec<_>>(),
        shaded: None,
        alpha_test: false,
        rounding: F16Rounding::TowardZero,
    };
    let cpu = blur_chain(&input, &vec![[0.0; 4]; t * t]);
    let gpu = dump(&cap, "tsd g6 v c0", "tsd map c0");
    let first_u = dump(&cap, "tsd g1 u c0", "tsd temp");
    let max = irr
        .rgba
        .iter()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .fold(0.0f32, f32::max);
    let err = |a: &[[f32; 4]], b: &[[f32; 4]]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (0..4).map(|c| (x[c] - y[c]).abs()).fold(0.0f32, f32::max))
            .fold(0.0f32, f32::max)
            / max
    };
    let _diff_first =
        common::DiffOnFailure::new("tsd-first-pass", t, t, &first_u.rgba, &cpu.passes[0]);
    let _diff_map = common::DiffOnFailure::new("tsd-map", t, t, &gpu.rgba, &cpu.map);
    let e1 = err(&first_u.rgba, &cpu.passes[0]);
    let e12 = err(&gpu.rgba, &cpu.map);
    println!("first pass {e1:.2e}, map {e12:.2e} of the brightest texel {max}");
    // Bound: per pass, one f16 ulp of the stored value (2^-10 relative) and the
    // quantised bilinear weights (2^-9 of a neighbour difference per tap, at
    // most the brightest texel); twelve passes and the map's own rounding.
    // (Measured on lavapipe: 0 and 6.5e-4.)
    assert!(e1 < 2e-3, "first pass off by {e1}");
    assert!(e12 < 5e-3, "map off by {e12}");
    assert!(gpu
        .rgba
        .iter()
        .zip(&cpu.map)
        .all(|(g, c)| (g[3] > 0.0) == (c[3] > 0.0)));
}

// Uniform light on a flat albedo: every texel of the map with coverage holds
// the irradiance, up to the islands' edges (the seam): the blur pulls no
// background in. And the final pass writes that value on every skin pixel.
#[test]
fn seams_pull_in_no_background() {
    let ctx = common::ctx();
    let scene = scene_of(sheet_mesh(), 1.0, None);
    let mut s = settings("tsd", &[("irradiance-size", "64")], 96, 64, 1.6);
    s.light.intensity = 0.0;
    s.ambient = 0.5;
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let cap = r.capture(true).unwrap();
    let map = dump(&cap, "tsd g6 v c0", "tsd map c0");
    let irr = dump(&cap, "tsd irradiance c0", "tsd irradiance");
    let want = [0.8f32 * 0.5, 0.6 * 0.5, 0.5 * 0.5];
    let (mut edge, mut worst) = (0, 0.0f32);
    for (i, p) in map.rgba.iter().enumerate() {
        if p[3] == 0.0 {
            continue;
        }
        for c in 0..3 {
            worst = worst.max((p[c] - want[c]).abs() / want[c]);
        }
        // A texel whose 4-neighbourhood leaves the island: where a plain blur
        // would read background.
        let (x, y) = (i % 64, i / 64);
        let outside = |dx: i32, dy: i32| {
            let (a, b) = (x as i32 + dx, y as i32 + dy);
            !(0..64).contains(&a)
                || !(0..64).contains(&b)
                || irr.rgba[(b * 64 + a) as usize][3] == 0.0
        };
        if outside(1, 0) || outside(-1, 0) || outside(0, 1) || outside(0, -1) {
            edge += 1;
        }
    }
    assert!(edge > 50, "{edge} edge texels");
    // Bound: twelve f16 stores (truncated on lavapipe: up to 2^-10 each, one
    // sign) and six blends; a plain blur would lose up to half at the edges.
    assert!(worst < 5e-3, "the map strays {worst} from the constant");
    let (mut skin, mut worst) = (0, 0.0f32);
    for p in &cap.diffuse {
        if p[3] > 0.0 {
            skin += 1;
            for c in 0..3 {
                worst = worst.max((p[c] - want[c]).abs() / want[c]);
            }
        }
    }
    assert!(skin > 500, "{skin} skin pixels");
    assert!(
        worst < 5e-3,
        "the final pass strays {worst} from the constant"
    );
}

// --- The optimisations' texels by count -----------------------------------------------

/// The texels a run shaded in character `k`'s irradiance map (alpha > 0).
fn shaded(cap: &Capture, k: usize) -> Vec<bool> {
    dump(cap, &format!("tsd irradiance c{k}"), "tsd irradiance")
        .rgba
        .iter()
        .map(|p| p[3] > 0.0)
        .collect()
}

/// The CPU's prediction of which of the `covered` texels `rule` keeps, and
/// how many lie on a threshold (either answer is right there).
fn predict(
    r: &Renderer,
    mesh: &Mesh,
    covered: &[bool],
    size: u32,
    rule: KeepRule,
) -> (Vec<bool>, Vec<bool>) {
    let m = tsd(r);
    let f = &r.frame;
    let aspect = f.extent.width as f32 / f.extent.height as f32;
    let planes = clip_planes(f.camera.view_proj(aspect));
    let terms = VertexTerms::new(mesh, m.characters[0].model, f.camera.eye, &planes);
    let hits = texel_hits(&m.atlas.uv, &mesh.indices, size, 1e-5);
    let mut keep = vec![false; covered.len()];
    let mut tie = vec![false; covered.len()];
    for i in 0..covered.len() {
        if !covered[i] {
            continue;
        }
        match hits[i] {
            None => tie[i] = true,
            Some(h) => {
                let (e, c) = terms.at(&h, &mesh.indices);
                match keeps(rule, e, &c, 1e-3) {
                    Some(k) => keep[i] = k,
                    None => tie[i] = true,
                }
            }
        }
    }
    (keep, tie)
}

/// GPU-kept texels equal the prediction except on ties; returns the kept count.
fn agree(gpu: &[bool], keep: &[bool], tie: &[bool], what: &str) -> usize {
    let wrong = (0..gpu.len())
        .filter(|&i| gpu[i] != keep[i] && !tie[i])
        .count();
    let ties = tie.iter().filter(|&&t| t).count();
    let kept = gpu.iter().filter(|&&k| k).count();
    println!("{what}: {kept} kept, {ties} on a threshold");
    assert_eq!(
        wrong, 0,
        "{what}: {wrong} texels differ from the CPU's prediction"
    );
    assert!(ties <= kept / 50 + 8, "{what}: {ties} ties");
    assert!(kept > 0);
    kept
}

// A sphere too big for the frame: the culled map (stencil and alpha test)
// keeps exactly the texels within 105 degrees of the eye, the clipped map
// exactly those inside the six planes of eq. 3.4, the z pre-pass exactly
// those with N.V + 0.3 >= 0; the convolutions run (or fetch) for those alone.
#[test]
fn culled_clipped_and_prepassed_maps_shade_the_predicted_texels() {
    let ctx = common::counting_ctx();
    let scene = scene_of(sphere_mesh(10.0), 10.0, None);
    let mesh = &scene.head.mesh;
    let t = 64u32;
    let n = (t * t) as u64;
    let off = [
        ("irradiance-size", "64"),
        ("cull", "off"),
        ("depth-sized", "false"),
        ("clip", "false"),
        ("z-prepass", "false"),
    ];
    let run = |opts: &[(&str, &str)]| {
        let all: Vec<(&str, &str)> = off.iter().chain(opts).copied().collect();
        let s = settings("tsd-opt", &all, 64, 96, 2.5);
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let cap = r.capture(true).unwrap();
        let c = r.count_fetches().unwrap();
        (r, cap, c)
    };
    let (_, plain, plain_counts) = run(&[]);
    let covered = shaded(&plain, 0);
    let n_cov = covered.iter().filter(|&&c| c).count() as u64;
    assert_eq!(
        counts(&plain_counts, "tsd irradiance c0").invocations,
        n_cov
    );
    assert_eq!(counts(&plain_counts, "tsd g1 u c0").invocations, n);
    let bilinear = site(0, 0, 1);

    // Culled, stencil mask: the convolutions run for the kept texels only.
    let (r, cap, c) = run(&[("cull", "stencil")]);
    let rule = KeepRule {
        min_eye_dot: Some(CULL_COS),
        clip: false,
    };
    let (keep, tie) = predict(&r, mesh, &covered, t, rule);
    let kept = agree(&shaded(&cap, 0), &keep, &tie, "culled (stencil)") as u64;
    assert!(kept < n_cov * 3 / 4, "the sphere's back is culled");
    for p in [
        "tsd irradiance c0",
        "tsd g1 u c0",
        "tsd g3 v c0",
        "tsd g6 v c0",
    ] {
        assert_eq!(counts(&c, p).invocations, kept, "{p}");
    }
    // Culled, the thesis' alpha test: every texel runs, only kept ones fetch taps.
    let (r, cap, c) = run(&[("cull", "alpha")]);
    let (keep, tie) = predict(&r, mesh, &covered, t, rule);
    let kept_alpha = agree(&shaded(&cap, 0), &keep, &tie, "culled (alpha)") as u64;
    assert_eq!(kept_alpha, kept);
    for p in ["tsd g1 u c0", "tsd g6 v c0"] {
        assert_eq!(counts(&c, p).invocations, n, "{p}");
        assert_eq!(fetches(counts(&c, p), bilinear), 6 * kept, "{p}");
    }
    // Clipped: off-screen texels are never shaded (no mask: the blur still runs).
    let (r, cap, c) = run(&[("clip", "true")]);
    let rule = KeepRule {
        min_eye_dot: None,
        clip: true,
    };
    let (keep, tie) = predict(&r, mesh, &covered, t, rule);
    let kept_clip = agree(&shaded(&cap, 0), &keep, &tie, "clipped") as u64;
    assert!(kept_clip < n_cov * 9 / 10, "the frame cuts the sphere");
    assert_eq!(counts(&c, "tsd irradiance c0").invocations, kept_clip);
    // Clipped and culled by stencil: both, and the convolutions skip the rest.
    let (r, cap, c) = run(&[("clip", "true"), ("cull", "stencil")]);
    let rule = KeepRule {
        min_eye_dot: Some(CULL_COS),
        clip: true,
    };
    let (keep, tie) = predict(&r, mesh, &covered, t, rule);
    let both = agree(&shaded(&cap, 0), &keep, &tie, "clipped and culled") as u64;
    assert_eq!(counts(&c, "tsd g2 u c0").invocations, both);
    // The z pre-passes with clipping: depth 0 inside the planes, 1 where N.V + 0.3 < 0.
    let (r, cap, c) = run(&[("clip", "true"), ("z-prepass", "true")]);
    let rule = KeepRule {
        min_eye_dot: Some(-BACKFACE_BIAS),
        clip: true,
    };
    let (keep, tie) = predict(&r, mesh, &covered, t, rule);
    let pre = agree(&shaded(&cap, 0), &keep, &tie, "z pre-passes") as u64;
    for p in ["tsd irradiance c0", "tsd g1 u c0", "tsd g6 v c0"] {
        assert_eq!(counts(&c, p).invocations, pre, "{p}");
    }
}

// Three characters of a crowd in a portrait frame: the two in the second
// row stand outside the view frustum, so the z pre-pass writes nothing for
// them and every later pass of theirs runs no invocation at all.
#[test]
fn characters_outside_the_frustum_run_no_texture_space_invocation() {
    let ctx = common::counting_ctx();
    let scene = scene_of(sphere_mesh(10.0), 10.0, None);
    let mut s = settings(
        "tsd-opt",
        &[("irradiance-size", "64"), ("depth-sized", "false")],
        48,
        96,
        1.5,
    );
    s.heads = 3;
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let outside: Vec<bool> = tsd(&r).characters.iter().map(|c| c.outside).collect();
    assert_eq!(outside, [false, true, true]);
    let c = r.count_fetches().unwrap();
    for (k, out) in outside.iter().enumerate() {
        let own: Vec<&PassCounts> = c
            .iter()
            .filter(|p| p.name.ends_with(&format!(" c{k}")))
            .collect();
        assert_eq!(own.len(), 14, "mask, irradiance and twelve blurs");
        for p in own {
            if *out {
                assert_eq!(p.invocations, 0, "{}", p.name);
            } else if !p.name.starts_with("tsd mask") {
                assert!(p.invocations > 0, "{}", p.name);
            }
        }
    }
    // The passes are still listed per character: three irradiance passes.
    let irr = r
        .passes()
        .iter()
        .filter(|p| p.name.starts_with("tsd irradiance c"))
        .count();
    assert_eq!(irr, 3);
}

// Eq. 3.1-3.2 through the viewport: the passes work in T = round(s T_max)
// texels, s = min(d_ref / d, 1) from the nearest corner of the box.
#[test]
fn the_depth_sized_viewport_is_s_times_t_max() {
    let ctx = common::counting_ctx();
    let scene = scene_of(sphere_mesh(10.0), 10.0, None);
    let opts = [
        ("irradiance-size", "256"),
        ("cull", "off"),
        ("clip", "false"),
        ("z-prepass", "false"),
    ];
    let s = settings("tsd-opt", &opts, 96, 64, 8.0);
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let m = tsd(&r);
    let ch = &m.characters[0];
    let cam = r.frame.camera;
    let d = nearest_corner_distance(cam.eye, &scene.head.mesh.bounds().transformed(&ch.model));
    let d_ref = reference_distance(THESIS_D_REF, 10.0, 64, cam.fovy_rad, 256);
    let sc = depth_scale(d_ref, d);
    assert!(sc < 0.5, "s = {sc}");
    let size = map_size(sc, 256);
    assert_eq!(ch.size, size);
    assert!((ch.s - size as f32 / 256.0).abs() < 1e-6);
    let c = r.count_fetches().unwrap();
    for p in ["tsd g1 u c0", "tsd g4 v c0"] {
        assert_eq!(counts(&c, p).invocations, (size * size) as u64, "{p}");
    }
}

// --- Far characters -------------------------------------------------------------------

// With every head "far", each map is refreshed on its first frame and then
// once every `refresh` frames, staggered; in between its passes shade
// nothing and the image stays the same (the static scene's map is reused).
#[test]
fn far_characters_keep_their_maps_between_refreshes() {
    let ctx = common::ctx();
    let scene = scene_of(sphere_mesh(10.0), 10.0, None);
    let mut s = settings(
        "tsd-opt",
        &[
            ("irradiance-size", "64"),
            ("far-px", "100000"),
            ("refresh", "3"),
            ("cull", "off"),
        ],
        96,
        64,
        3.0,
    );
    s.heads = 2;
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    assert!(tsd(&r).characters.iter().all(|c| c.far && !c.outside));
    let first = r.capture(false).unwrap();
    let frames = r.frames(6, |_| {}).unwrap();
    for (f, samples) in frames.iter().enumerate() {
        let frame = f as u64 + 1;
        for k in 0..2 {
            let p = samples
                .iter()
                .find(|p| p.name == format!("tsd g1 u c{k}"))
                .unwrap();
            let due = dermis::skin::tsd::refreshes(frame, k, 3);
            assert_eq!(p.samples_passed > 0, due, "frame {frame} character {k}");
        }
    }
    let later = r.capture(false).unwrap();
    assert_eq!(
        first.diffuse, later.diffuse,
        "a reused map renders the same image"
    );
}

// --- The image ------------------------------------------------------------------------

// Each optimisation alone, and all together, against plain `tsd` on the
// face's skin pixels. Culling, clipping and the z pre-passes drop texels
// whose light reaches visible ones only through the blur's tails (beyond 105
// degrees, behind the frame's edge): < 1% (measured on lavapipe: 0.39%,
// 0.014%, 0.38%). Depth-sized maps shade about one texel per pixel at the
// thesis' d_ref, and bilinear look-ups of a map that coarse miss the pixel's
// own shading (shadow edges, the lips' creases): < 6% (measured 4.0% at
// this 160 x 100 frame). All off is `tsd` bit for bit.
#[test]
fn optimisations_change_the_image_within_tolerance() {
    let ctx = common::ctx();
    let scene = dermis::scene::default_scene();
    let base = [("irradiance-size", "512")];
    let run = |method: &str, opts: &[(&str, &str)]| {
        let all: Vec<(&str, &str)> = base.iter().chain(opts).copied().collect();
        let s = settings(method, &all, 160, 100, 4.0);
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        r.capture(false).unwrap().diffuse
    };
    let plain = run("tsd", &[]);
    let mask: Vec<bool> = plain.iter().map(|p| p[3] > 0.0).collect();
    assert!(mask.iter().filter(|&&m| m).count() > 1000);
    let none = [
        ("cull", "off"),
        ("depth-sized", "false"),
        ("clip", "false"),
        ("z-prepass", "false"),
    ];
    let all_off = run("tsd-opt", &none);
    let _diff = common::DiffOnFailure::new("tsd-opt-all-off", 160, 100, &all_off, &plain);
    assert_eq!(all_off, plain, "all off is plain tsd");
    let only = |k: &'static str, v: &'static str| -> Vec<(&'static str, &'static str)> {
        let mut o: Vec<(&str, &str)> = none.iter().filter(|(n, _)| *n != k).copied().collect();
        o.push((k, v));
        o
    };
    for (what, opts, tol) in [
        ("culled (stencil)", only("cull", "stencil"), 0.01),
        ("culled (alpha)", only("cull", "alpha"), 0.01),
        ("clipped", only("clip", "true"), 0.01),
        ("z pre-passes", only("z-prepass", "true"), 0.01),
        ("depth-sized", only("depth-sized", "true"), 0.06),
        ("all", Vec::new(), 0.06),
    ] {
        let img = run("tsd-opt", &opts);
        let _diff = common::DiffOnFailure::new(format!("tsd-opt-{what}"), 160, 100, &img, &plain);
        let e = relative_rmse(&img, &plain, &mask).unwrap();
        println!("{what}: {e:.3e} relative RMSE against tsd");
        assert!(e < tol, "{what}: {e}");
    }
}

// --- The budget model -----------------------------------------------------------------

/// A frame as `dermis budget` prices it: the run's report (declared work,
/// its clears, the images, samples passed) with each pass's fetches and shaded
/// fragments from the fetch-counting build.
fn frame_input(
    scene: &dermis::scene::Scene,
    s: &RenderSettings,
    label: &str,
) -> dermis::budget::FrameInput {
    use dermis::app::budget::{method_frame, BudgetOptions};
    let (ctx, counting) = (common::ctx(), common::counting_ctx());
    let opts = BudgetOptions {
        profiles: Vec::new(),
        out: std::env::temp_dir(),
        frames: dermis::run::FrameCounts::ONE,
        rescale: dermis::budget::Rescale::AsRun,
        count_fetches: true,
        print: false,
        command: label.to_string(),
    };
    let frame = dermis::render::FrameRequest::new(scene, s.clone()).expect("a valid frame");
    method_frame(&ctx, Some(&counting), &frame, &opts).expect("the budget's frame")
}

// Every texture-space pass of every character is priced on every hardware
// profile; on the Xbox 360 the maps a pass renders are resolved out of eDRAM
// before the next pass samples them.
#[test]
fn the_budget_model_prices_every_texture_space_pass_on_every_profile() {
    use dermis::budget::profile::{list_profiles, Profile};
    use dermis::budget::{price_frame, ParamSet, Rescale};
    let scene = dermis::scene::default_scene();
    let mut s = settings("tsd-opt", &[("irradiance-size", "128")], 96, 64, 3.0);
    s.heads = 2;
    let frame = frame_input(&scene, &s, "tsd-opt, 2 heads");
    let per_character = frame
        .passes
        .iter()
        .filter(|p| p.name.ends_with(" c1"))
        .count();
    assert_eq!(per_character, 14);
    let profiles = list_profiles();
    assert!(profiles.len() >= 10, "{profiles:?}");
    for name in &profiles {
        let prof = Profile::load(name).unwrap();
        let b = price_frame(&prof, &frame, &ParamSet::fitted(), Rescale::AsRun);
        let mut tsd_ms = 0.0;
        for p in b.passes.iter().filter(|p| p.name.starts_with("tsd")) {
            let ms = p
                .modelled_ms
                .unwrap_or_else(|| panic!("{name}: '{}' unpriced: {:?}", p.name, p.unpriced));
            assert!(ms.is_finite() && ms >= 0.0, "{name}: {} {ms}", p.name);
            tsd_ms += ms;
            if let Some(e) = &p.edram {
                // Every map a texture-space draw writes is read by the next pass.
                if p.name.starts_with("tsd irradiance") || p.name.contains(" u c") {
                    assert!(
                        !e.resolves.is_empty(),
                        "{name}: '{}' resolves nothing",
                        p.name
                    );
                }
            }
        }
        println!(
            "{name}: texture-space passes {tsd_ms:.3} ms, frame {:.3} ms",
            b.total_ms
        );
        assert!(b.total_ms.is_finite());
    }
}

// --- Where the screen-space methods fail ----------------------------------------------

/// tests/stability.rs's halo scene, unwrapped: a lit skin ball 30 mm in front
/// of an unlit skin wall (a nose over a cheek), each its own UV island.
fn halo_scene() -> Scene {
    let mut m = Mesh::default();
    let v = |x: f32, y: f32, u: f32, w: f32| Vertex {
        position: [x, y, 0.0],
        normal: [0.0, 0.0, 1.0],
        uv: [u, w],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    m.vertices.extend([
        v(-15.0, -15.0, 0.02, 0.45),
        v(15.0, -15.0, 0.45, 0.45),
        v(15.0, 15.0, 0.45, 0.02),
        v(-15.0, 15.0, 0.02, 0.02),
    ]);
    m.indices.extend([0, 1, 2, 0, 2, 3]);
    let ball = sphere_mesh(4.0);
    let base = m.vertices.len() as u32;
    m.vertices.extend(ball.vertices.iter().map(|b| Vertex {
        position: [b.position[0], b.position[1], b.position[2] + 7.0],
        uv: [0.55 + 0.43 * b.uv[0], 0.02 + 0.96 * b.uv[1]],
        ..*b
    }));
    m.indices.extend(ball.indices.iter().map(|i| i + base));
    m.generate_tangents();
    scene_of(m, 10.0, None)
}

// Texture space has no screen-space halo: light scatters along the surface
// (within each UV island), never across a depth gap on screen. The unlit wall
// behind the lit ball gets nothing, as in the reference (separable 0.061,
// ssg 0.47, ss-jittered 2.87 in tests/stability.rs's same measure).
#[test]
fn no_halo_across_a_depth_gap() {
    let ctx = common::ctx();
    let scene = halo_scene();
    for method in ["tsd", "tsd-opt"] {
        let mut s = settings(method, &[("irradiance-size", "128")], 96, 64, 1.6);
        s.ambient = 0.0;
        s.transmittance = false;
        s.light.azimuth_deg = 120.0;
        s.light.elevation_deg = 0.0;
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let cap = r.capture(true).unwrap();
        let depth = &dump(&cap, "geometry", "linear depth").rgba;
        let wall = depth.iter().fold(0.0f32, |m, d| m.max(d[0]));
        let lit: f64 = cap
            .diffuse
            .iter()
            .map(|p| (p[0] + p[1] + p[2]) as f64)
            .sum();
        let leak: f64 = cap
            .diffuse
            .iter()
            .zip(depth)
            .filter(|(_, d)| d[0] > wall - 1.0)
            .map(|(p, _)| (p[0] + p[1] + p[2]) as f64)
            .sum();
        println!("{method}: energy on the unlit wall {leak} (the ball's {lit})");
        assert!(lit > 1.0, "the ball is lit");
        assert_eq!(leak, 0.0, "{method} leaks across the gap");
    }
}

// Thin parts, as tests/stability.rs measures them: the procedural head lit
// from behind, relative RMSE over the pixels where the reference receives
// light through the ears, with and without the transmittance term (which
// tsd adds to its irradiance maps, so it is blurred along the surface).
#[test]
fn thin_parts_with_and_without_transmittance() {
    let ctx = common::ctx();
    let scene = dermis::scene::egg_scene();
    let backlit = |method: &str, transmittance: bool| {
        let mut s = settings(
            method,
            &[("irradiance-size", "1024"), ("density", "8")],
            160,
            96,
            2.0,
        );
        s.shadow_size = 1024;
        s.transmittance = transmittance;
        s.ambient = 0.0;
        s.light.azimuth_deg = 165.0;
        s.light.elevation_deg = 5.0;
        s
    };
    let run = |s: &RenderSettings| {
        let mut r = Renderer::new(&ctx, &scene, s).unwrap();
        let cap = r.capture(true).unwrap();
        (dump(&cap, "geometry", "diffuse").rgba.clone(), cap.diffuse)
    };
    let (direct, reference) = run(&backlit("reference", false));
    let thin: Vec<bool> = reference
        .iter()
        .zip(&direct)
        .map(|(r, d)| r[3] > 0.0 && r[0] > 1.5 * d[0] + 0.005)
        .collect();
    let skin: Vec<bool> = reference.iter().map(|p| p[3] > 0.0).collect();
    assert!(thin.iter().filter(|&&t| t).count() > 10);
    let n_thin = thin.iter().filter(|&&t| t).count() as f64;
    let red = |img: &[[f32; 4]]| {
        img.iter()
            .zip(&thin)
            .filter(|(_, &t)| t)
            .map(|(p, _)| p[0] as f64)
            .sum::<f64>()
            / n_thin
    };
    let red_ref = red(&reference);
    for method in ["tsd", "tsd-opt"] {
        let (_, off) = run(&backlit(method, false));
        let (_, on) = run(&backlit(method, true));
        let e = |img: &[[f32; 4]], m: &[bool]| relative_rmse(img, &reference, m).unwrap();
        let (thin_off, thin_on) = (e(&off, &thin), e(&on, &thin));
        let (red_off, red_on) = (red(&off), red(&on));
        println!(
            "{method}: thin parts {thin_off:.3} without, {thin_on:.3} with transmittance; all skin {:.3} / {:.3}; mean red on the thin parts {red_off:.4} / {red_on:.4} (reference {red_ref:.4})",
            e(&off, &skin),
            e(&on, &skin)
        );
        // Without transmittance plain texture space gets some light through
        // (blurred along the surface, the light on the ear's back wraps round its
        // rim to the front), more than the screen-space methods (0.99-1.00,
        // tests/stability.rs); tsd-opt culls the ear's back (beyond 105 degrees),
        // so less wraps. Measured on lavapipe: tsd 0.816, tsd-opt 0.916.
        assert!(thin_off > 0.7 && thin_off < 0.99, "{method}: {thin_off}");
        // With transmittance the thin parts gain light where the truth has it,
        // and, as for the screen-space methods, eq. 5.12 over-transmits against
        // the energy-conserving ground truth (a back-lit ear splits its light
        // between its two sides): tsd 1.088, tsd-opt 1.052 with (mean red 0.051
        // and 0.050 against the truth's 0.032).
        assert!(
            red_on > red_off + 0.25 * (red_ref - red_off),
            "{method}: transmittance added too little light ({red_off} -> {red_on}, reference {red_ref})"
        );
        assert!(
            thin_on < 1.5 * thin_off,
            "{method}: {thin_on} vs {thin_off}"
        );
    }
}
