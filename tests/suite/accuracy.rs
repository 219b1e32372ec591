//! The accuracy instrument checked against what no code of ours produced
//! (lavapipe, validation on):
//! - a flat skin card with an albedo step, lit evenly: every method's and the
//!   ground truth's edge response against the profile's closed form (the energy
//!   moved across the edge, E (a_L - a_R) sum_i w_i sigma_i / sqrt(2 pi), sampled
//!   at the pixel centres as any image is);
//! - the same card under Burley's truth (`profile=burley`) against Burley's
//!   closed form (`BurleyParams::edge_response`, Bickley-Naylor functions):
//!   its energy moved and its row pointwise;
//! - uniform light (white skin, ambient only): the ground truth must return its
//!   input (what light goes in comes out), thin parts apart; both profiles.

use crate::common;

use dermis::method::reference::Reference;
use dermis::render::{RenderSettings, Renderer};
use dermis::scene::mesh::{Material, Mesh, Object, Texture, Vertex};
use dermis::scene::{default_scene, Scene};
use dermis::skin::card::{edge_spread_mm, Card, Row};
use glam::Vec3;

/// The card: 200 x 120 mm in the z = 0 plane facing +Z, 1 unit = 1 mm, its
/// left half of albedo 1 and right half 0.25 (sRGB 137) times a skin tint. The
/// halves are two quads whose texture coordinates sit on the centres of the two
/// texels of a 2 x 1 texture: each half is one albedo, and the step is sharp
/// (a texture's bilinear ramp across the step would smear it).
pub(crate) fn card_scene() -> Scene {
    let mut scene = default_scene();
    let (w, h) = (200.0f32, 120.0f32);
    let v = |x: f32, y: f32, u: f32| Vertex {
        position: [x * w, y * h, 0.0],
        normal: [0.0, 0.0, 1.0],
        uv: [u, 0.5],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    let mesh = Mesh {
        vertices: vec![
            v(-0.5, -0.5, 0.25),
            v(0.0, -0.5, 0.25),
            v(0.0, 0.5, 0.25),
            v(-0.5, 0.5, 0.25),
            v(0.0, -0.5, 0.75),
            v(0.5, -0.5, 0.75),
            v(0.5, 0.5, 0.75),
            v(0.0, 0.5, 0.75),
        ],
        indices: vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7],
    };
    let mut material = Material::skin([0.8, 0.6, 0.5]);
    material.base_color = Some(Texture {
        width: 2,
        height: 1,
        rgba8: vec![255, 255, 255, 255, 137, 137, 137, 255],
    });
    material.specular_intensity = 0.0;
    scene.head_bounds = mesh.bounds();
    scene.head = Object {
        morph: Default::default(),
        mesh,
        material,
    };
    scene.parts.clear();
    scene.backdrop = None;
    scene.mm_per_unit = 1.0;
    scene.forward = Vec3::Z;
    scene.name = "card".into();
    scene
}

/// Settings that put `px_per_mm` pixels on a millimetre of the card, lit from
/// the camera's side (even irradiance, no back light, no ambient).
///
/// The frame is a band of 48 rows across the card's edge: the middle rows of
/// a 256 x 128 frame with a 20-degree field of view (the camera where that
/// frame puts it, the field narrowed to the band). The card is the same down
/// every column, so rows beyond the band add nothing the tests read (they
/// read the middle row, or every row alike), and the ground truths cost by
/// the pixel: a third of the rows is a third of the time.
pub(crate) fn card_settings(scene: &Scene, px_per_mm: f32) -> RenderSettings {
    let (width, height, full_height) = (256u32, 48u32, 128.0f32);
    let d = full_height / (2.0 * 10f32.to_radians().tan() * px_per_mm);
    let fovy = 2.0 * (height as f32 / (2.0 * d * px_per_mm)).atan().to_degrees();
    let mut s = RenderSettings {
        width,
        height,
        shadow_size: 512,
        fovy_deg: fovy,
        distance_heads: d / scene.head_height_units(),
        ambient: 0.0,
        ..RenderSettings::study()
    };
    s.light.azimuth_deg = 0.0;
    s.light.elevation_deg = 0.0;
    s
}

/// What a method's output samples: the exitance at pixel centres (the ground
/// truth evaluates the integral there), or a discrete filter of the pixel
/// irradiance (the screen-space methods). A filter applied to the pixel step
/// moves exactly what the continuous kernel moves (linear interpolation of a
/// step moves `d` for a tap at `d`), so its yardstick is the closed form's
/// integral; point samples of the exitance are summed by the midpoint rule,
/// which at 8.5 px/mm falls short of the integral by 0.3% (red), 2.3% (green)
/// and 4.5% (blue, whose profile moves 0.4 px), so theirs is that sum.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Output {
    PointSamples,
    PixelFilter,
}

/// Energy moved per channel over the closed form's, averaged over the rows.
/// The closed form takes its levels (E a) from the unscattered image far from
/// the edge; each rendered row is measured against its own far levels and
/// scaled to the unscattered contrast. (Measured against the unscattered
/// levels, a whole-card gain of 0.16%, what half-float rounding loses on one
/// GPU, showed as 14% of blue's moved energy: the dark half is 15 mm wide and
/// blue moves 0.05 mm of contrast. The energy a method keeps is checked apart,
/// as `out / in`.)
fn energy_ratio(
    out: &[[f32; 4]],
    diffuse: &[[f32; 4]],
    w: usize,
    mm_per_px: f64,
    kind: Output,
) -> [f64; 3] {
    energy_ratio_against(out, diffuse, w, mm_per_px, kind, edge_spread_mm())
}

/// [`energy_ratio`] against a profile of edge spread `spread` (mm per channel:
/// the energy it moves across an edge of unit contrast; Burley's is `2.5 /
/// (pi s)`). Pixel filters only for a profile other than the six Gaussians
/// (the point-sample yardstick is the six Gaussians' exitance).
pub(crate) fn energy_ratio_against(
    out: &[[f32; 4]],
    diffuse: &[[f32; 4]],
    w: usize,
    mm_per_px: f64,
    kind: Output,
    spread: [f64; 3],
) -> [f64; 3] {
    let rows = out.len() / w;
    let mut ratio = [0.0; 3];
    for c in 0..3 {
        let left = diffuse[rows / 2 * w + 2][c] as f64;
        let right = diffuse[rows / 2 * w + w - 3][c] as f64;
        let card = Card {
            albedo_left: [left; 3],
            albedo_right: [right; 3],
            irradiance: 1.0,
        };
        let exact: Vec<f64> = (0..w)
            .map(|x| card.exitance((x as f64 + 0.5 - (w / 2) as f64) * mm_per_px)[c])
            .collect();
        let exact = match kind {
            Output::PointSamples => Row {
                values: &exact,
                edge_px: w / 2,
                mm_per_px,
            }
            .energy_moved(right),
            Output::PixelFilter => (left - right) * spread[c],
        };
        for y in 0..rows {
            let (moved, ..) = row_moved(out, w, y, c, mm_per_px, left - right);
            ratio[c] += moved / exact / rows as f64;
        }
    }
    ratio
}

/// Row `y`'s energy moved across the step in channel `c`, measured against
/// its own far levels (the mean of 4 pixels 2 from each end) and scaled to
/// the unscattered `contrast`; also the row and its own levels, for
/// pointwise checks.
pub(crate) fn row_moved(
    out: &[[f32; 4]],
    w: usize,
    y: usize,
    c: usize,
    mm_per_px: f64,
    contrast: f64,
) -> (f64, Vec<f64>, [f64; 2]) {
    let row: Vec<f64> = (0..w).map(|x| out[y * w + x][c] as f64).collect();
    let mean = |r: std::ops::Range<usize>| r.clone().map(|x| row[x]).sum::<f64>() / r.len() as f64;
    let (own_left, own_right) = (mean(2..6), mean(w - 6..w - 2));
    let moved = Row {
        values: &row,
        edge_px: w / 2,
        mm_per_px,
    }
    .energy_moved(own_right)
        * contrast
        / (own_left - own_right);
    (moved, row, [own_left, own_right])
}

pub(crate) fn render_card(
    ctx: &dermis::vk::context::Context,
    scene: &Scene,
    s: &RenderSettings,
) -> (Vec<[f32; 4]>, f64) {
    let mut r = Renderer::new(ctx, scene, s).unwrap();
    let cap = r.capture(false).unwrap();
    let z = cap.depth[cap.depth.len() / 2] as f64;
    let mm_per_px =
        2.0 * z * (0.5 * s.fovy_deg.to_radians() as f64).tan() * scene.mm_per_unit as f64
            / s.height as f64;
    (cap.diffuse, mm_per_px)
}

/// Registered methods the card cannot score, and why.
const OFF_CARD: [(&str, &str); 2] = [
    (
        "tsd",
        "texture space: the card's UVs sit on two texel centres (so the albedo step is sharp), \
         so its UV triangles have no area to diffuse over; tests/suite/tsd.rs has its accuracy",
    ),
    ("tsd-opt", "as tsd"),
];

// The card at the eval's close-up scale (8.5 px/mm, the thesis' 720p zoom
// shot). The ground truth must move the profile's energy within a few percent
// in every channel; each method is held to what its design moves (see
// src/skin/card.rs and docs/accuracy.md for the per-method derivations).
#[test]
fn edge_response_of_every_method_against_the_closed_form() {
    let ctx = common::ctx();
    let scene = card_scene();
    let base = card_settings(&scene, 8.5);
    let mut report = Vec::new();
    // Geometry pass diffuse of a method is overwritten by SSS: the unscattered
    // levels come from `none`'s frame instead.
    let (none, _) = render_card(&ctx, &scene, &base.clone().with(common::m("none"), &[]));
    let mut run = |label: &str, s: RenderSettings| {
        let (out, mm_per_px) = render_card(&ctx, &scene, &s);
        let kind = if label == "reference" {
            Output::PointSamples
        } else {
            Output::PixelFilter
        };
        let r = energy_ratio(&out, &none, s.width as usize, mm_per_px, kind);
        // Energy kept over the whole card (what half-float rounding loses).
        let kept = [0, 1, 2].map(|c| {
            out.iter().map(|p| p[c] as f64).sum::<f64>()
                / none.iter().map(|p| p[c] as f64).sum::<f64>()
        });
        println!(
            "{label}: energy moved / closed form = {r:.3?} ({:.2} px/mm), out / in {kept:.4?}",
            1.0 / mm_per_px
        );
        // Half-float storage may round toward zero (one GPU loses 0.16% of
        // blue over the separable passes); more than half a percent is a leak.
        for k in kept {
            assert!((k - 1.0).abs() < 0.005, "{label}: out / in {kept:?}");
        }
        report.push((label.to_string(), r));
        r
    };
    let reference = run(
        "reference",
        base.clone()
            .with(common::m("reference"), &[("density", "16")]),
    );
    let physical = run(
        "separable physical 33",
        base.clone().with(
            common::m("separable"),
            &[("preset", "physical"), ("samples", "33")],
        ),
    );
    let table = run(
        "separable table6.1",
        base.clone().with(common::m("separable"), &[]),
    );
    let ssg = run(
        "ssg",
        base.clone().with(common::m("ssg"), &[("lod", "false")]),
    );
    let jittered = run(
        "ss-jittered",
        base.clone().with(common::m("ss-jittered"), &[]),
    );
    let poisson = run("poisson", base.clone().with(common::m("poisson"), &[]));
    let gather = run(
        "gather",
        base.clone()
            .with(common::m("gather"), &[("sample-budget", "80")]),
    );
    let none = run("none", base.clone().with(common::m("none"), &[]));
    // The card's method list is the registry's: a method added there fails
    // here until it is run on the card with a bound, or named off it with why.
    for m in dermis::method::METHODS {
        let on_card = report
            .iter()
            .any(|(label, _)| label.split(' ').next() == Some(m.name));
        let off_card = OFF_CARD.iter().any(|(name, _)| *name == m.name);
        assert!(
            on_card != off_card,
            "{}: run it on the card with its bound, or name it in OFF_CARD with the reason",
            m.name
        );
    }
    for c in 0..3 {
        // The ground truth: within 3% in every channel.
        assert!((reference[c] - 1.0).abs() < 0.03, "reference {reference:?}");
        // The physical preset is the profile's marginal: within 3% (measured
        // [0.998, 0.996, 0.994] on lavapipe, [0.993, 0.992, 1.012] on the H200,
        // whose sampler's 8-bit bilinear weights and f16 rounding move blue's
        // 0.4 px of moved contrast by 2%).
        assert!((physical[c] - 1.0).abs() < 0.03, "physical {physical:?}");
        assert_eq!(none[c], 0.0);
        // Table 6.1 is an artist's preset: far narrower than the profile.
        assert!(table[c] < 0.2, "table6.1 {table:?}");
    }
    // The screen-space sums at their true scale: red (wide Gaussians, where
    // their designs are exact up to their taps) within 6%; the stretch was 18%
    // too wide before.
    assert!((ssg[0] - 1.0).abs() < 0.06, "ssg {ssg:?}");
    assert!((jittered[0] - 1.0).abs() < 0.06, "ss-jittered {jittered:?}");
    // ssg leaves Gaussian 1 unblurred and builds the others on it: green and
    // blue move at most what sqrt(v_i - v_1) allows (0.79 and 0.57).
    assert!(ssg[1] < 0.85 && ssg[2] < 0.62, "ssg {ssg:?}");
    // The 2D gather samples the profile itself, its kept 99.7%: within 4% in
    // every channel (tests/suite/gather.rs holds both profiles to it).
    for c in 0..3 {
        assert!((gather[c] - 1.0).abs() < 0.04, "gather {gather:?}");
    }
    // Poisson's disk moves 0.88-1.1 of the closed form in every channel, by orientation.
    for c in 0..3 {
        assert!((0.8..1.15).contains(&poisson[c]), "poisson {poisson:?}");
    }
}

// Burley's truth on the card at the close-up scale, against Burley's own
// closed form (src/skin/burley.rs: the marginal's tail by Bickley-Naylor
// functions, which no code of the truth uses): the energy each channel moves
// across the edge within 3% (the six Gaussians' bound), the row within 2% of
// the contrast at every pixel, and the card's light kept.
#[test]
fn burley_truth_edge_response_against_its_closed_form() {
    let ctx = common::ctx();
    let scene = card_scene();
    let base = card_settings(&scene, 8.5);
    let (none, _) = render_card(&ctx, &scene, &base.clone().with(common::m("none"), &[]));
    let s = base.clone().with(
        common::m("reference"),
        &[("density", "16"), ("profile", "burley")],
    );
    let (out, mm_per_px) = render_card(&ctx, &scene, &s);
    let w = s.width as usize;
    let rows = out.len() / w;
    let burley = dermis::skin::kernel::burley_profile();
    let mut ratio = [0.0; 3];
    let mut worst = [0.0f64; 3];
    for c in 0..3 {
        let left = none[rows / 2 * w + 2][c] as f64;
        let right = none[rows / 2 * w + w - 3][c] as f64;
        // The closed form at the pixel centres, with the unscattered levels
        // (irradiance times albedo) as the card's albedos under unit light.
        // Burley's A (the six Gaussians' total, 1 - 1e-8) scales both.
        let exact: Vec<f64> = (0..w)
            .map(|x| {
                let xm = (x as f64 + 0.5 - (w / 2) as f64) * mm_per_px;
                burley.edge_response(xm, [left; 3], [right; 3])[c] * burley.albedo[c]
            })
            .collect();
        let want = Row {
            values: &exact,
            edge_px: w / 2,
            mm_per_px,
        }
        .energy_moved(right * burley.albedo[c]);
        for y in 0..rows {
            let (moved, row, [own_left, own_right]) =
                row_moved(&out, w, y, c, mm_per_px, left - right);
            ratio[c] += moved / want / rows as f64;
            // Pointwise, on rows away from the frame's top and bottom (where
            // the screen pass's window is cut off, as the six Gaussians' is):
            // the row over its own levels against the closed form.
            if y < rows / 4 || y >= 3 * rows / 4 {
                continue;
            }
            for x in w / 4..3 * w / 4 {
                let got = (row[x] - own_right) / (own_left - own_right);
                let ex = (exact[x] - exact[w - 3]) / (exact[2] - exact[w - 3]);
                worst[c] = worst[c].max((got - ex).abs());
            }
        }
    }
    let kept = [0, 1, 2].map(|c| {
        out.iter().map(|p| p[c] as f64).sum::<f64>() / none.iter().map(|p| p[c] as f64).sum::<f64>()
    });
    println!(
        "reference profile=burley: energy moved / Burley's closed form = {ratio:.4?}, worst pointwise |difference| / contrast {worst:.4?} ({:.2} px/mm), out / in {kept:.5?}",
        1.0 / mm_per_px
    );
    for c in 0..3 {
        assert!((ratio[c] - 1.0).abs() < 0.03, "energy moved {ratio:?}");
        assert!(worst[c] < 0.02, "pointwise {worst:?}");
        assert!((kept[c] - 1.0).abs() < 0.005, "out / in {kept:?}");
    }
}

/// Uniform light: white skin, ambient light only, no key light. Every surface
/// point is lit alike and the profile loses no light (its weights sum to one),
/// so the ground truth must return its input at every point, folds and thin
/// parts included: median within 2%, 99th percentile within 10% over skin
/// pixels that are not thin parts, thin parts reported apart. (Before the
/// ground truth gathered through tissue only and let each Gaussian conserve what
/// it gathers, seams returned up to 1.63 of their input.)
fn uniform_light(
    scene: &Scene,
    s: &RenderSettings,
    thin: impl Fn(Vec3) -> bool,
) -> (f64, f64, f64, usize) {
    let ctx = common::ctx();
    let mut r = Renderer::new(&ctx, scene, s).unwrap();
    let cap = r.capture(false).unwrap();
    let input = r.read_back(r.frame.targets.diffuse).unwrap();
    let depth = &cap.depth;
    let inv_view = r.frame.camera.view().inverse();
    assert!(r.method_as::<Reference>().is_some());
    let (w, h) = (s.width as usize, s.height as usize);
    let t = (0.5 * s.fovy_deg.to_radians()).tan();
    let aspect = w as f32 / h as f32;
    let mut ratios = Vec::new();
    let mut thin_ratios = Vec::new();
    let mut map = vec![0u8; w * h * 4];
    for (i, (o, d)) in cap.diffuse.iter().zip(&input).enumerate() {
        if d[3] <= 0.0 || d[0] <= 0.0 {
            continue;
        }
        let z = depth[i];
        let (x, y) = ((i % w) as f32, (i / w) as f32);
        let ndc = [
            (x + 0.5) / w as f32 * 2.0 - 1.0,
            (y + 0.5) / h as f32 * 2.0 - 1.0,
        ];
        let p = inv_view.transform_point3(Vec3::new(ndc[0] * t * aspect * z, -ndc[1] * t * z, -z));
        let q = (0..3)
            .map(|c| o[c] as f64 / d[c] as f64)
            .fold(0.0f64, |a, b| a.max((b - 1.0).abs()));
        let v = (q / 0.2 * 255.0).min(255.0) as u8;
        map[i * 4..i * 4 + 4].copy_from_slice(&[v, if thin(p) { 128 } else { 0 }, 255 - v, 255]);
        if thin(p) {
            thin_ratios.push(q);
        } else {
            ratios.push(q);
        }
    }
    if let Ok(path) = std::env::var("UNIFORM_MAP") {
        image::RgbaImage::from_raw(w as u32, h as u32, map)
            .unwrap()
            .save(format!("{path}-{}.png", scene.name))
            .unwrap();
    }
    ratios.sort_by(f64::total_cmp);
    thin_ratios.sort_by(f64::total_cmp);
    let pct = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p) as usize];
    let thin_median = if thin_ratios.is_empty() {
        0.0
    } else {
        pct(&thin_ratios, 0.5)
    };
    (
        pct(&ratios, 0.5),
        pct(&ratios, 0.99),
        thin_median,
        ratios.len(),
    )
}

fn white_ambient(scene: &mut Scene) -> RenderSettings {
    scene.head.material.base_color = None;
    scene.head.material.base_color_factor = [1.0; 3];
    let mut s = RenderSettings {
        width: 160,
        height: 120,
        shadow_size: 256,
        ambient: 1.0,
        ..RenderSettings::study()
    }
    .with(common::m("reference"), &[("density", "16")]);
    s.light.intensity = 0.0;
    s
}

#[test]
fn uniform_light_comes_out_as_it_went_in_on_the_face() {
    let mut scene = default_scene();
    let mut s = white_ambient(&mut scene);
    s.distance_heads = dermis::scene::camera::Camera::close_up_distance_heads(20.0);
    let ears = dermis::scene::face::ears();
    let mm = scene.mm_per_unit;
    let (median, p99, thin, n) = uniform_light(&scene, &s, |p| {
        ears.iter().any(|e| (p - e.center).length() * mm < 40.0)
    });
    println!("face, uniform light: |out/in - 1| median {median:.4}, p99 {p99:.4} over {n} pixels; thin parts (ears) median {thin:.4}");
    assert!(median < 0.02 && p99 < 0.10, "median {median}, p99 {p99}");
}

// Burley's truth under uniform light (its near and far parts each normalised
// per channel, A = 1 - 1e-8): the same bounds as the six Gaussians'.
#[test]
fn uniform_light_comes_out_as_it_went_in_under_burley() {
    let mut scene = default_scene();
    let mut s = white_ambient(&mut scene);
    s.options.set("profile", "burley");
    s.distance_heads = dermis::scene::camera::Camera::close_up_distance_heads(20.0);
    let ears = dermis::scene::face::ears();
    let mm = scene.mm_per_unit;
    let (median, p99, thin, n) = uniform_light(&scene, &s, |p| {
        ears.iter().any(|e| (p - e.center).length() * mm < 40.0)
    });
    println!("face, uniform light, profile=burley: |out/in - 1| median {median:.4}, p99 {p99:.4} over {n} pixels; thin parts (ears) median {thin:.4}");
    assert!(median < 0.02 && p99 < 0.10, "median {median}, p99 {p99}");
}

#[test]
fn uniform_light_comes_out_as_it_went_in_on_the_head_scan() {
    let Some(path) = common::lps_path() else {
        return;
    };
    let mut scene = dermis::scene::load_gltf_scene(&path, &Default::default(), None).unwrap();
    let mut s = white_ambient(&mut scene);
    s.distance_heads = dermis::scene::camera::Camera::close_up_distance_heads(20.0);
    s.options.set("density", "8");
    // The scan's ears: beyond 60 mm to either side of the head's centre line.
    let c = scene.head_center();
    let mm = scene.mm_per_unit;
    let (median, p99, thin, n) = uniform_light(&scene, &s, |p| ((p.x - c.x) * mm).abs() > 60.0);
    println!("head scan, uniform light: |out/in - 1| median {median:.4}, p99 {p99:.4} over {n} pixels; thin parts (ears) median {thin:.4}");
    assert!(median < 0.02 && p99 < 0.10, "median {median}, p99 {p99}");
}
