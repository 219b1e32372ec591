//! Hostile but fair input on the GPU (issue 11), lavapipe with validation on:
//! a texture larger than the device allows, a far outlier vertex, a flat object,
//! and the extremes of every documented range, each rendered for real. (The CLI
//! sweep of every flag is in tests/cli.rs; the glTF fuzzer in tests/gltf_fuzz.rs.)

mod common;

use dermis::render::{Capture, RenderSettings};
use dermis::run::{run, RunOptions};
use dermis::scene::mesh::Texture;
use dermis::scene::procedural::flat_card;
use dermis::scene::{default_scene, egg_scene, scene_from_head, Scene};
use dermis::vk::context::Context;
use glam::{Mat4, Vec3};

fn small() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 36,
        shadow_size: 256,
        ..Default::default()
    }
}

fn capture(ctx: &Context, scene: &Scene, s: &RenderSettings) -> Capture {
    let out = run(ctx, scene, s, &RunOptions::capture_once("hostile"))
        .unwrap_or_else(|e| panic!("{}: {e:#}", scene.name));
    ctx.check_validation("after the render").unwrap();
    out.capture.expect("a capture")
}

/// Pixels of skin in the frame (the diffuse alpha is the SSS strength).
fn skin_pixels(c: &Capture) -> usize {
    c.diffuse.iter().filter(|p| p[3] > 0.0).count()
}

fn assert_finite(c: &Capture, what: &str) {
    assert_eq!(c.hdr_nonfinite, 0, "{what}: non-finite HDR pixels");
    assert!(
        c.diffuse.iter().flatten().all(|v| v.is_finite()),
        "{what}: non-finite diffuse light"
    );
}

// Issue 11: a texture larger than maxImageDimension2D was created anyway (a
// validation error; undefined behaviour without validation). It is downscaled
// to the limit, with a warning.
#[test]
fn a_texture_larger_than_the_device_allows_is_downscaled() {
    let ctx = common::ctx();
    let max = ctx.facts.max_image_dimension_2d;
    let mut scene = default_scene();
    let (w, h) = (max + 1, 2);
    scene.head.material.base_color = Some(Texture {
        width: w,
        height: h,
        rgba8: vec![200; (w * h * 4) as usize],
    });
    let c = capture(&ctx, &scene, &small());
    assert!(skin_pixels(&c) > 100);
    assert_finite(&c, "oversized texture");
    ctx.finish().unwrap();
}

// Issue 11: a flat object was framed edge-on, so only its shadow showed. It now
// faces the camera with its largest extent, however it lies.
#[test]
fn a_flat_object_is_seen_face_on() {
    use std::f32::consts::{FRAC_PI_2, PI};
    let ctx = common::ctx();
    let s = RenderSettings {
        distance_heads: 2.0,
        ..small()
    };
    for (m, name) in [
        (Mat4::IDENTITY, "facing +Z"),
        (Mat4::from_rotation_y(FRAC_PI_2), "facing +X"),
        (Mat4::from_rotation_y(PI), "facing -Z"),
        (Mat4::from_rotation_x(-FRAC_PI_2), "lying flat"),
    ] {
        let scene = scene_from_head(name, flat_card(2.0, 1.0, m, [0.6, 0.45, 0.4]), None).unwrap();
        let c = capture(&ctx, &scene, &s);
        // Two heads' distance from a card two units wide: a third of the frame
        // or more is card (edge-on: none).
        let frac = skin_pixels(&c) as f64 / (64.0 * 36.0);
        assert!(
            frac > 0.3,
            "{name}: {:.0}% of the frame is card",
            frac * 100.0
        );
        assert_finite(&c, name);
    }
    ctx.finish().unwrap();
}

// Issue 11: one vertex at 1e31 (one flipped byte) turned the whole frame black:
// the camera and the shadow map framed the universe. The head now shows as
// without the vertex (the triangles that use it cross the screen as thin slivers).
#[test]
fn a_far_outlier_vertex_leaves_the_head_in_the_frame() {
    let ctx = common::ctx();
    let clean = egg_scene();
    let good = scene_from_head("clean", clean.head.clone(), None).unwrap();
    let reference = skin_pixels(&capture(&ctx, &good, &small()));
    assert!(reference > 200, "{reference}");
    for far in [
        Vec3::new(0.0, 1e31, 0.0),
        Vec3::new(1e31, -1e31, 0.0),
        Vec3::new(0.0, 0.0, -1e31),
    ] {
        let mut head = clean.head.clone();
        head.mesh.vertices[1000].position = far.into();
        let bad = scene_from_head("outlier", head, None).unwrap();
        let c = capture(&ctx, &bad, &small());
        let n = skin_pixels(&c);
        assert!(
            (n as f64 - reference as f64).abs() < 0.1 * reference as f64,
            "{far}: {n} skin pixels, {reference} without the vertex"
        );
        assert_finite(&c, "outlier");
    }
    ctx.finish().unwrap();
}

// Every end of every documented range renders finite images (issue 11: huge
// values gave NaN pixels or black frames; they are refused now, and what is
// accepted must be safe). Values the CLI sweep accepts are here too.
#[test]
fn the_ends_of_every_range_render_finite_images() {
    let ctx = common::ctx();
    let scene = default_scene();
    let sep = common::m("separable");
    let base = small();
    type Edit = fn(&mut RenderSettings);
    let cases: Vec<(&str, Edit)> = vec![
        ("exposure max", |s| {
            s.exposure = *dermis::render::settings::EXPOSURE_RANGE.end()
        }),
        ("exposure min", |s| {
            s.exposure = *dermis::render::settings::EXPOSURE_RANGE.start()
        }),
        ("light max", |s| {
            s.light.intensity = dermis::scene::light::MAX_INTENSITY
        }),
        ("light 0", |s| s.light.intensity = 0.0),
        ("ambient max", |s| {
            s.ambient = dermis::render::settings::MAX_AMBIENT
        }),
        ("ambient 0", |s| s.ambient = 0.0),
        ("distance max", |s| {
            s.distance_heads = dermis::render::settings::MAX_DISTANCE_HEADS
        }),
        ("distance 1e-30", |s| s.distance_heads = 1e-30),
        ("light from below", |s| s.light.elevation_deg = -90.0),
        ("light behind", |s| s.light.azimuth_deg = -180.0),
        ("fovy min", |s| s.fovy_deg = 0.51),
        ("fovy max", |s| s.fovy_deg = 169.9),
        ("tile 1", |s| s.sss_region_tile = 1),
        ("falloff max", |s| {
            *s = s.clone().with(
                common::m("separable"),
                &[("falloff", "100,100,100"), ("strength", "1,1,1")],
            )
        }),
        ("falloff 1e-30", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("falloff", "1e-30,1e-30,1e-30")])
        }),
        ("width max", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("sss-width-mm", "1000")])
        }),
        ("width 1e-30", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("sss-width-mm", "1e-30")])
        }),
        ("strength 0", |s| {
            *s = s
                .clone()
                .with(common::m("separable"), &[("strength", "0,0,0")])
        }),
    ];
    for (what, edit) in cases {
        let mut s = base.clone().with(sep, &[]);
        edit(&mut s);
        s.validate(u32::MAX)
            .unwrap_or_else(|e| panic!("{what}: {e:#}"));
        let c = capture(&ctx, &scene, &s);
        assert_finite(&c, what);
    }
    // The ground truth at the smallest density (one sample a triangle).
    let s = base
        .clone()
        .with(common::m("reference"), &[("density", "1e-30")]);
    assert_finite(&capture(&ctx, &egg_scene(), &s), "density 1e-30");
    ctx.finish().unwrap();
}
