//! Where the methods fail (issue: stability tests), on lavapipe with validation:
//! extremes, background bleeding, and the halo across a depth discontinuity.
//! Thresholds come from measurements printed by the tests and recorded in
//! docs/accuracy.md.

use crate::common;

use dermis::method::{MethodEntry, MethodOptions};
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::mesh::{Aabb, Material, Mesh, Object, Vertex};
use dermis::scene::{egg_scene, Scene};
use dermis::vk::context::Context;
use glam::Vec3;

fn methods() -> [&'static MethodEntry; 5] {
    ["separable", "ssg", "ss-jittered", "poisson", "reference"].map(common::m)
}

/// Options with the reference's surface-sample density set.
fn density(d: f32) -> MethodOptions {
    MethodOptions::default().with(&[("density", &d.to_string())])
}

fn small(method: &'static MethodEntry) -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 40,
        shadow_size: 128,
        method,
        options: density(4.0),
        ..RenderSettings::study()
    }
}

/// Geometry-pass diffuse and the final diffuse after SSS.
fn before_after(
    ctx: &Context,
    scene: &Scene,
    s: &RenderSettings,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut r = Renderer::new(ctx, scene, s).unwrap();
    let cap = r.capture(true).unwrap();
    let before = cap
        .dumps
        .iter()
        .find(|d| d.pass == "geometry" && d.image == "diffuse")
        .unwrap()
        .rgba
        .clone();
    (before, cap.diffuse)
}

/// Case 5: Extremes: every output finite and non-negative, no validation message.
#[test]
fn extremes_stay_finite_and_non_negative() {
    let ctx = common::ctx();
    let scene = egg_scene();
    type Tweak = fn(&mut RenderSettings);
    let cases: [(&str, Tweak); 6] = [
        ("sub-pixel head", |s| s.distance_heads = 400.0),
        ("head filling 4x the screen", |s| s.distance_heads = 0.7),
        ("grazing light", |s| {
            s.light.azimuth_deg = 90.0;
            s.light.elevation_deg = 0.5
        }),
        ("light from behind", |s| s.light.azimuth_deg = 180.0),
        ("zero SSS width", |s| s.options.set("sss-width-mm", "0")),
        ("huge SSS width", |s| s.options.set("sss-width-mm", "1000")),
    ];
    for method in methods() {
        for (name, tweak) in cases {
            let mut s = small(method);
            tweak(&mut s);
            let (_, after) = before_after(&ctx, &scene, &s);
            for (i, p) in after.iter().enumerate() {
                assert!(
                    p.iter().all(|v| v.is_finite() && *v >= 0.0),
                    "{method:?} / {name}: pixel {i} is {p:?}"
                );
            }
        }
    }
}

/// Case 7: Background bleeding: non-skin pixels leave every method bit for bit.
#[test]
fn non_skin_pixels_are_untouched_by_every_method() {
    let ctx = common::ctx();
    let scene = egg_scene();
    for method in methods() {
        let (before, after) = before_after(
            &ctx,
            &scene,
            &RenderSettings {
                distance_heads: shot_close(),
                ..small(method)
            },
        );
        let mut n = 0;
        for (b, a) in before.iter().zip(&after) {
            if b[3] <= 0.0 {
                assert_eq!(a, b, "{method:?} changed a non-skin pixel");
                n += 1;
            }
        }
        assert!(n > 100, "the view holds background ({n} pixels)");
    }
}

fn shot_close() -> f32 {
    dermis::scene::camera::Camera::close_up_distance_heads(20.0)
}

/// A lit skin ball 30 mm in front of an unlit skin wall (a nose over a cheek):
/// scale 10 mm per unit, so the gap is 3 units, well beyond the reference's 10.9 mm cut-off.
fn halo_scene() -> Scene {
    let mut mesh = Mesh {
        vertices: Vec::new(),
        indices: Vec::new(),
    };
    // Wall: 30 x 30 units at z = 0 facing +Z.
    let v = |x: f32, y: f32| Vertex {
        position: [x, y, 0.0],
        normal: [0.0, 0.0, 1.0],
        uv: [0.5, 0.5],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    mesh.vertices.extend([
        v(-15.0, -15.0),
        v(15.0, -15.0),
        v(15.0, 15.0),
        v(-15.0, 15.0),
    ]);
    mesh.indices.extend([0, 1, 2, 0, 2, 3]);
    // Ball: radius 4 units, centre 7 units in front of the wall (3 units of gap).
    let (rings, segs, r, c) = (24u32, 48u32, 4.0f32, Vec3::new(0.0, 0.0, 7.0));
    let base = mesh.vertices.len() as u32;
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segs {
            let ph = 2.0 * std::f32::consts::PI * j as f32 / segs as f32;
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            mesh.vertices.push(Vertex {
                position: (c + n * r).to_array(),
                normal: n.to_array(),
                uv: [j as f32 / segs as f32, i as f32 / rings as f32],
                tangent: [0.0; 4],
            });
        }
    }
    for i in 0..rings {
        for j in 0..segs {
            let a = base + i * (segs + 1) + j;
            let b = a + segs + 1;
            mesh.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
        }
    }
    mesh.generate_tangents();
    let bounds = Aabb::from_points(mesh.vertices.iter().map(|v| Vec3::from(v.position))).unwrap();
    Scene {
        tracks: None,
        name: "halo".into(),
        mm_per_unit: 10.0,
        head: Object {
            morph: Default::default(),
            mesh,
            material: Material::skin([0.6, 0.45, 0.4]),
        },
        parts: Vec::new(),
        backdrop: None,
        head_bounds: bounds,
        forward: Vec3::Z,
        source: None,
    }
}

/// Case 2: Halo: light leaking from the lit ball onto the unlit wall around it.
#[test]
fn halo_across_a_depth_discontinuity() {
    let ctx = common::ctx();
    let scene = halo_scene();
    let base = |method: &'static MethodEntry| {
        let mut s = RenderSettings {
            width: 96,
            height: 64,
            shadow_size: 256,
            method,
            options: density(4.0),
            distance_heads: 1.6,
            ambient: 0.0,
            transmittance: false,
            ..RenderSettings::study()
        };
        // From behind and to the side: the ball's right flank is lit, the wall (facing +Z) is not.
        s.light.azimuth_deg = 120.0;
        s.light.elevation_deg = 0.0;
        s
    };
    let leak = |s: &RenderSettings| -> f64 {
        let mut r = Renderer::new(&ctx, &scene, s).unwrap();
        let cap = r.capture(true).unwrap();
        let depth = &cap
            .dumps
            .iter()
            .find(|d| d.pass == "geometry" && d.image == "linear depth")
            .unwrap()
            .rgba;
        let wall = depth.iter().cloned().fold(0.0f32, |m, d| m.max(d[0]));
        // Wall pixels: within 1 unit of the farthest depth (the ball is 3+ units nearer).
        cap.diffuse
            .iter()
            .zip(depth)
            .filter(|(_, d)| d[0] > wall - 1.0)
            .map(|(p, _)| (p[0] + p[1] + p[2]) as f64)
            .sum()
    };
    let (before, _) = before_after(&ctx, &scene, &base(common::m("none")));
    assert!(before.iter().any(|p| p[0] > 0.05), "the ball is lit");
    let reference = leak(&base(common::m("reference")));
    let none = leak(&base(common::m("none")));
    let sep_follow = leak(&base(common::m("separable")));
    let sep_no_follow = leak(
        &base(common::m("separable")).with(common::m("separable"), &[("follow-surface", "false")]),
    );
    let ssg = leak(&base(common::m("ssg")));
    let jittered = leak(&base(common::m("ss-jittered")));
    let poisson = leak(&base(common::m("poisson")));
    println!(
        "energy on the unlit wall: reference {reference:.4}, none {none:.4}, separable {sep_follow:.4} (no follow-surface {sep_no_follow:.4}), ssg {ssg:.4}, ss-jittered {jittered:.4}, poisson {poisson:.4}"
    );
    // The wall is unlit and the ball is beyond the profile's cut-off: nothing arrives.
    assert_eq!(none, 0.0);
    assert_eq!(reference, 0.0, "the reference leaks across the gap");
    // Measured on lavapipe at 96x64: separable 0.061 with follow-surface, 0.60
    // without; ssg 0.47 and ss-jittered 2.87 at their true scale (2.41 and 3.60
    // when their stretch was 18% too wide); poisson 0.013 (its mip levels average
    // ball and wall depths at the silhouette, so some samples pass the depth weight).
    // Follow-surface is what stops the separable blur crossing the step (10x measured).
    assert!(
        sep_no_follow > 0.0,
        "without follow-surface the blur crosses the depth step"
    );
    assert!(
        sep_follow < 0.2 * sep_no_follow,
        "follow-surface must cut the halo at least fivefold ({sep_follow} vs {sep_no_follow})"
    );
    // Poisson's depth weight keeps most of it out too.
    assert!(poisson < 0.2 * sep_no_follow, "poisson leaks {poisson}");
    // The chapter-4 methods have no depth test on their taps: the halo the thesis
    // reports (section 4.5) is there, several times what follow-surface leaves
    // (ssg's blurs are narrow at this size: its first Gaussians span under a
    // pixel; ss-jittered's wide ring reaches past the unguarded separable blur).
    assert!(
        ssg > 4.0 * sep_follow && jittered > sep_no_follow,
        "ssg {ssg}, ss-jittered {jittered}"
    );
}

/// Case 3: Thin parts: the procedural head lit from behind, so the ear flaps glow.
/// Screen space cannot see light arriving from the back; transmittance
/// (thesis ch. 5) adds it in the geometry pass. Errors are relative RMSE of the
/// diffuse after SSS against the reference over skin pixels.
#[test]
fn thin_parts_need_transmittance() {
    use dermis::eval::metrics::relative_rmse;
    let ctx = common::ctx();
    let scene = egg_scene();
    let backlit = |method: &'static MethodEntry, transmittance: bool| {
        let mut s = RenderSettings {
            width: 160,
            height: 96,
            shadow_size: 1024,
            method,
            transmittance,
            options: density(8.0),
            ambient: 0.0,
            distance_heads: 2.0,
            ..RenderSettings::study()
        };
        s.light.azimuth_deg = 165.0;
        s.light.elevation_deg = 5.0;
        s
    };
    let (direct, reference) = before_after(&ctx, &scene, &backlit(common::m("reference"), false));
    let skin: Vec<bool> = reference.iter().map(|p| p[3] > 0.0).collect();
    // Thin parts: where the reference receives light from behind, i.e. its red is
    // well above the unscattered direct light (transmittance off in its geometry pass).
    let thin: Vec<bool> = reference
        .iter()
        .zip(&direct)
        .map(|(r, d)| r[3] > 0.0 && r[0] > 1.5 * d[0] + 0.005)
        .collect();
    let n_thin = thin.iter().filter(|&&t| t).count();
    assert!(
        n_thin > 10,
        "the back-lit ears show transmission in the reference ({n_thin} pixels)"
    );
    // Mean red over the thin parts: what light came through the ears.
    let red = |img: &[[f32; 4]]| {
        img.iter()
            .zip(&thin)
            .filter(|(_, &t)| t)
            .map(|(p, _)| p[0] as f64)
            .sum::<f64>()
            / n_thin as f64
    };
    let (red_ref, red_direct) = (red(&reference), red(&direct));
    let mut report = Vec::new();
    let mut integral = Vec::new();
    let mut reds = Vec::new();
    for method in [
        common::m("separable"),
        common::m("ssg"),
        common::m("ss-jittered"),
        common::m("poisson"),
    ] {
        let (_, off) = before_after(&ctx, &scene, &backlit(method, false));
        let (_, on) = before_after(&ctx, &scene, &backlit(method, true));
        let e = |img: &[[f32; 4]], m: &[bool]| relative_rmse(img, &reference, m).unwrap();
        report.push((
            method,
            e(&off, &thin),
            e(&on, &thin),
            e(&off, &skin),
            e(&on, &skin),
        ));
        reds.push((method, red(&off), red(&on)));
        // The same with T(s) integrated from the profile (exp(-s^2 / 2v)).
        let s = RenderSettings {
            transmittance_profile: dermis::skin::transmittance::TransmittanceProfile::Integral,
            ..backlit(method, true)
        };
        let (_, on_integral) = before_after(&ctx, &scene, &s);
        integral.push((method, e(&on_integral, &thin), e(&on_integral, &skin)));
    }
    println!("with the integral T(s): (thin parts, all skin) {integral:?}");
    println!(
        "mean red over the thin parts: reference {red_ref:.4}, direct light {red_direct:.4}; (method, without, with transmittance) {reds:?}"
    );
    // The integral form over-transmits more than eq. 5.12 (measured thin-part error
    // 2.2-2.8 against 0.97-1.31): the published T(s) is the better real-time choice.
    for ((m, _, thesis_thin, _, _), (_, integral_thin, _)) in report.iter().zip(&integral) {
        assert!(
            thesis_thin < integral_thin,
            "{m:?}: eq. 5.12 {thesis_thin} vs integral {integral_thin}"
        );
    }
    println!("back-lit head, {n_thin} thin-part pixels; relative RMSE (thin without, thin with, all skin without, all skin with transmittance): {report:?}");
    for (&(method, thin_off, thin_on, _, _), &(_, red_off, red_on)) in report.iter().zip(&reds) {
        // Without transmittance the light through the ears is missing: the known
        // failure (measured 0.99-1.0 relative RMSE on the thin parts at 160x96).
        assert!(
            thin_off > 0.9,
            "{method:?} without transmittance on thin parts: {thin_off}"
        );
        // Transmittance adds light where the truth has it (every method's thin
        // parts brighter with it than without) ...
        assert!(
            red_on > red_off + 0.25 * (red_ref - red_off),
            "{method:?}: transmittance added too little light to the thin parts ({red_off} -> {red_on}, reference {red_ref})"
        );
        // ... but eq. 5.12 over-transmits against the energy-conserving ground
        // truth (each Gaussian returns the light it gathers, so a back-lit ear
        // splits its light between its two sides): mean red 0.041-0.048 against
        // the truth's 0.032 (measured), and a thin-part error 0.97-1.31x the error
        // without it, held below 1.5x.
        assert!(
            thin_on < 1.5 * thin_off,
            "{method:?}: transmittance made thin parts far worse ({thin_on} vs {thin_off})"
        );
    }
}

/// Case 1: Distance sweep: a dolly from 2 to 9 head heights in steps of 15%. Each
/// method's error against the reference, minus the unscattered frame's error at
/// the same step (what all methods share: the pixel footprint of a small frame),
/// must not jump between steps. Gaussian LOD and the stretch factors switch with
/// distance; a Gaussian switching on everywhere at once would show here.
#[test]
fn distance_sweep_does_not_pop() {
    use dermis::eval::metrics::relative_rmse;
    let ctx = common::ctx();
    let scene = egg_scene();
    let methods = [
        common::m("separable"),
        common::m("ssg"),
        common::m("ss-jittered"),
        common::m("poisson"),
    ];
    let mut curves: Vec<Vec<f64>> = vec![Vec::new(); methods.len()];
    for k in 0..11 {
        let s = |method| RenderSettings {
            width: 96,
            height: 64,
            distance_heads: 2.0 * 1.15f32.powi(k),
            options: density(8.0),
            ..small(method)
        };
        let (_, reference) = before_after(&ctx, &scene, &s(common::m("reference")));
        let mask: Vec<bool> = reference.iter().map(|p| p[3] > 0.0).collect();
        let e = |m: &'static MethodEntry| {
            relative_rmse(&before_after(&ctx, &scene, &s(m)).1, &reference, &mask).unwrap()
        };
        let none = e(common::m("none"));
        for (c, &m) in curves.iter_mut().zip(&methods) {
            c.push(e(m) - none);
        }
    }
    for (c, m) in curves.iter().zip(methods) {
        let jump = c
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        println!("{m:?}: error minus no-SSS error along the dolly {c:.4?}, largest jump {jump:.4}");
        // Measured on lavapipe: largest jumps separable 0.0004, ssg 0.0024 (its LOD
        // turns every Gaussian off by 3.5 head heights), poisson 0.0029, ss-jittered 0.0051.
        assert!(jump < 0.012, "{m:?} pops along the dolly: jump {jump}");
    }
}

/// Case 4: Temporal flicker: a slow orbit (1 degree per frame, light following the
/// camera); the method's frame-to-frame change minus the reference's.
#[test]
fn slow_orbit_does_not_flicker() {
    let ctx = common::ctx();
    let base = egg_scene();
    let frames: Vec<Scene> = (0..5)
        .map(|k| {
            let mut s = base.clone();
            s.forward = glam::Quat::from_rotation_y((k as f32).to_radians()) * glam::Vec3::Z;
            s
        })
        .collect();
    let change = |method: &'static MethodEntry| -> f64 {
        let imgs: Vec<Vec<[f32; 4]>> = frames
            .iter()
            .map(|sc| {
                before_after(
                    &ctx,
                    sc,
                    &RenderSettings {
                        width: 96,
                        height: 64,
                        options: density(8.0),
                        ..small(method)
                    },
                )
                .1
            })
            .collect();
        let mut total = 0.0;
        for w in imgs.windows(2) {
            let (d, n) = w[0]
                .iter()
                .zip(&w[1])
                .filter(|(a, b)| a[3] > 0.0 && b[3] > 0.0)
                .fold((0.0, 0usize), |(d, n), (a, b)| {
                    (
                        d + (0..3).map(|c| (a[c] - b[c]).abs() as f64).sum::<f64>(),
                        n + 1,
                    )
                });
            total += d / (3 * n.max(1)) as f64;
        }
        total / (imgs.len() - 1) as f64
    };
    let reference = change(common::m("reference"));
    let mut out = Vec::new();
    for method in [
        common::m("separable"),
        common::m("ssg"),
        common::m("ss-jittered"),
        common::m("poisson"),
    ] {
        out.push((method, change(method) - reference));
    }
    println!("mean frame-to-frame change minus the reference's ({reference:.5}): {out:?}");
    // Measured: every method within 0.0022 of the reference's own change (0.011);
    // the per-pixel jitter of ss-jittered is fixed to the screen, not animated.
    for (method, excess) in out {
        assert!(excess.abs() < 0.005, "{method:?} flickers: {excess}");
    }
}

/// Case 6: Banding: a hard shadow edge across the skin (key light from the side, the
/// nose's shadow); error in the penumbra band for 9, 17 and 33 separable samples.
#[test]
fn banding_at_a_hard_shadow_edge_shrinks_with_samples() {
    use dermis::eval::metrics::relative_rmse;
    let ctx = common::ctx();
    let scene = egg_scene();
    let side = |method: &'static MethodEntry, samples: usize| {
        let mut s = RenderSettings {
            width: 128,
            height: 80,
            shadow_size: 2048,
            method,
            options: density(8.0).with(&[("samples", &samples.to_string())]),
            ambient: 0.02,
            distance_heads: 2.5,
            ..small(method)
        };
        s.light.azimuth_deg = 80.0;
        s.light.elevation_deg = 10.0;
        s
    };
    let (direct, reference) = before_after(&ctx, &scene, &side(common::m("reference"), 17));
    // The penumbra band: skin pixels whose direct light differs strongly from a
    // horizontal neighbour's (the shadow edge), where banding shows.
    let w = 128;
    let band: Vec<bool> = (0..direct.len())
        .map(|i| {
            let x = i % w;
            direct[i][3] > 0.0
                && x + 1 < w
                && direct[i + 1][3] > 0.0
                && (direct[i][0] - direct[i + 1][0]).abs() > 0.05
        })
        .collect();
    let n = band.iter().filter(|&&b| b).count();
    assert!(n > 10, "the view has a shadow edge ({n} pixels)");
    let errors: Vec<(usize, f64)> = [9, 17, 33]
        .iter()
        .map(|&k| {
            (
                k,
                relative_rmse(
                    &before_after(&ctx, &scene, &side(common::m("separable"), k)).1,
                    &reference,
                    &band,
                )
                .unwrap(),
            )
        })
        .collect();
    println!("penumbra band ({n} pixels), separable error by sample count: {errors:?}");
    // More samples never make the band worse, and 33 beats 9.
    assert!(errors[2].1 <= errors[0].1, "{errors:?}");

    // The other methods have no sample-count knob: their band error at their
    // widest setting (ssg: all 6 Gaussians everywhere, no LOD).
    let others: Vec<(&str, f64)> = [
        ("ssg --no-lod", common::m("ssg")),
        ("ss-jittered", common::m("ss-jittered")),
        ("poisson", common::m("poisson")),
    ]
    .iter()
    .map(|&(name, m)| {
        let s = side(m, 17).with(m, &[("lod", "false")]);
        (
            name,
            relative_rmse(&before_after(&ctx, &scene, &s).1, &reference, &band).unwrap(),
        )
    })
    .collect();
    println!("penumbra band, other methods: {others:?}");
    // Measured 0.018-0.023, as close as separable's 0.022-0.023.
    for (name, e) in &others {
        assert!(e.is_finite() && *e < 0.035, "{name}: {e}");
    }

    // Banding proper, apart from the kernel's shape: separable at 3x the widest
    // preset width (9.7 mm, where stepping shows first) against itself at 63
    // samples, in the same band.
    let wide = |k: usize| {
        let mut s = side(common::m("separable"), k);
        let opts = common::m("separable").opts(&s.options);
        let width = dermis::method::separable::Config::parse(&opts)
            .unwrap()
            .params
            .width_mm;
        s.options.set("sss-width-mm", (3.0 * width).to_string());
        before_after(&ctx, &scene, &s).1
    };
    let converged = wide(63);
    let banding: Vec<(usize, f64)> = [9, 17, 33]
        .iter()
        .map(|&k| (k, relative_rmse(&wide(k), &converged, &band).unwrap()))
        .collect();
    println!("penumbra band, separable at 3x width against 63 samples: {banding:?}");
    // Measured 3.5e-3 / 1.0e-3 / 2.7e-4: the stepping falls ~3.5x per doubling.
    assert!(
        banding[0].1 > banding[1].1 && banding[1].1 > banding[2].1,
        "{banding:?}"
    );
    assert!(banding[2].1 < 1e-3, "{banding:?}");
}
