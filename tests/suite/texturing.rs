//! Post-scatter texturing (`--texturing post`, issue 30; d'Eon and Luebke,
//! thesis ch. 7.6) on the flat card of `accuracy` (lavapipe, validation on):
//! - the card's albedo step under even light stays sharp: the light is all
//!   there is to scatter and it is even, so every method and both ground
//!   truths return the unscattered card (pre-scatter blurs the step by the
//!   closed form, accuracy.rs);
//! - a light step (a normal map tilted 60 degrees on one half) under the
//!   same albedo step: each method's frame is the white card's (the light
//!   scattered alone) times the albedo, pixel by pixel, where pre-scatter
//!   texturing is not; the ground truth's scattered light moves the energy
//!   of the profile's closed form for that light step.

use crate::accuracy::{card_scene, card_settings, render_card};
use crate::common;
use crate::texel_params::{methods, truth_ratio};

use dermis::render::settings::Texturing;
use dermis::render::RenderSettings;
use dermis::scene::mesh::Texture;
use dermis::scene::Scene;

fn post(s: &RenderSettings) -> RenderSettings {
    RenderSettings {
        texturing: Texturing::Post,
        ..s.clone()
    }
}

/// The card with its right half's normal tilted 60 degrees about the
/// tangent frame's y axis (texels under the halves' coordinates, as the
/// albedo's): under light along the card's normal, that half gets cos 60 =
/// half the irradiance, a sharp light step at the albedo's step.
fn with_light_step(mut scene: Scene) -> Scene {
    let tilt = 60f32.to_radians();
    let enc = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
    scene.head.material.normal_map = Some(Texture {
        width: 2,
        height: 1,
        rgba8: vec![
            128,
            128,
            255,
            255,
            enc(tilt.sin()),
            128,
            enc(tilt.cos()),
            255,
        ],
    });
    scene
}

/// The card in white: the same light, no albedo step.
fn white(mut scene: Scene) -> Scene {
    scene.head.material.base_color = None;
    scene.head.material.base_color_factor = [1.0; 3];
    scene
}

#[test]
fn post_scatter_keeps_the_albedo_step_sharp() {
    let ctx = common::ctx();
    let scene = card_scene();
    let base = card_settings(&scene, 8.5);
    let (none, _) = render_card(&ctx, &scene, &base.clone().with(common::m("none"), &[]));
    for (label, s) in methods(&base) {
        let (out, _) = render_card(&ctx, &scene, &post(&s));
        let off = |img: &[[f32; 4]]| {
            img.iter()
                .zip(&none)
                .flat_map(|(o, n)| (0..3).map(move |c| ((o[c] - n[c]) / n[c]).abs() as f64))
                .fold(0.0, f64::max)
        };
        let post_off = off(&out);
        println!("{label}: post-scatter off the unscattered card by {post_off:.2e} at most");
        // Half-float roundings: the light before and after the blur, the
        // albedo target, the unscattered card's product (2^-11 each).
        assert!(
            post_off < 3e-3,
            "{label}: post-scatter blurred the albedo ({post_off:.2e})"
        );
        if label == "separable" {
            // The check can fail: pre-scatter texturing blurs the same step.
            let (pre, _) = render_card(&ctx, &scene, &s);
            let pre_off = off(&pre);
            assert!(
                pre_off > 0.05,
                "{label}: pre-scatter did not blur ({pre_off})"
            );
        }
    }
}

#[test]
fn post_scatter_scatters_the_light_alone() {
    let ctx = common::ctx();
    let card = with_light_step(card_scene());
    let white_card = white(card.clone());
    let base = card_settings(&card, 8.5);
    let unscattered = |scene: &Scene| {
        render_card(
            &ctx,
            scene,
            &post(&base.clone().with(common::m("none"), &[])),
        )
        .0
    };
    let (none, none_white) = (unscattered(&card), unscattered(&white_card));
    let w = base.width as usize;
    for (label, s) in methods(&base) {
        let (out, mm_per_px) = render_card(&ctx, &card, &post(&s));
        let (light, _) = render_card(&ctx, &white_card, &post(&s));
        // out = light x albedo, the albedo being none / none_white.
        let mut worst = 0.0f64;
        for i in 0..out.len() {
            for c in 0..3 {
                let want = light[i][c] as f64 * none[i][c] as f64 / none_white[i][c] as f64;
                worst = worst.max((out[i][c] as f64 - want).abs() / want);
            }
        }
        println!(
            "{label}: post-scatter frame / (white card's x albedo) off by {worst:.2e} at most"
        );
        assert!(worst < 3e-3, "{label}: {worst:.2e}");
        if label == "separable" {
            // The check can fail: pre-scatter texturing blurs the albedo too.
            let (pre, _) = render_card(&ctx, &card, &s);
            let mut pre_worst = 0.0f64;
            for i in 0..out.len() {
                let want = light[i][0] as f64 * none[i][0] as f64 / none_white[i][0] as f64;
                pre_worst = pre_worst.max((pre[i][0] as f64 - want).abs() / want);
            }
            assert!(
                pre_worst > 0.02,
                "{label}: pre-scatter matched too ({pre_worst})"
            );
        }
        if label.starts_with("reference") {
            // The light step's closed form, sampled at the pixel centres as
            // the truth's exitance is, with the white card's unscattered
            // levels: within the 3% of the albedo step (accuracy.rs).
            let burley = label.ends_with("burley");
            let r = truth_ratio(&light, &none_white, w, mm_per_px, 1.0, burley);
            println!("{label}: the light step's moved energy / closed form {r:.3?}");
            for c in r {
                assert!((c - 1.0).abs() < 0.03, "{label}: {r:?}");
            }
        }
    }
}

// A skin of one albedo scatters the same either way: blur(L) a = blur(L a)
// when a is the same everywhere the blur reaches. On the face (its skin one
// colour), texture space (both variants), poisson (the normal target beside
// the albedo's) and separable at 4x MSAA (the albedo resolved with the
// others) keep the pre-scatter frame within half-float rounding over most
// skin; only where a blur reaches the eyes (another albedo) may they part.
#[test]
fn a_skin_of_one_albedo_scatters_the_same_either_way() {
    let ctx = common::ctx();
    let face = dermis::scene::default_scene();
    let base = RenderSettings {
        width: 128,
        height: 72,
        shadow_size: 512,
        ..Default::default()
    };
    let cases = [
        ("tsd", base.clone().with(common::m("tsd"), &[])),
        ("tsd-opt", base.clone().with(common::m("tsd-opt"), &[])),
        ("poisson", base.clone().with(common::m("poisson"), &[])),
        (
            "separable 4x",
            RenderSettings {
                msaa: 4,
                ..base.clone().with(common::m("separable"), &[])
            },
        ),
    ];
    for (label, s) in cases {
        let diffuse = |s: &RenderSettings| {
            let mut r = dermis::render::Renderer::new(&ctx, &face, s).unwrap();
            r.capture(false).unwrap().diffuse
        };
        let (pre, out) = (diffuse(&s), diffuse(&post(&s)));
        let mut off: Vec<f64> = pre
            .iter()
            .zip(&out)
            .filter(|(p, _)| p[3] > 0.0)
            .map(|(p, o)| {
                (0..3)
                    .map(|c| ((o[c] - p[c]) / p[c].max(1e-3)).abs() as f64)
                    .fold(0.0, f64::max)
            })
            .collect();
        off.sort_by(f64::total_cmp);
        let at = |q: f64| off[((off.len() - 1) as f64 * q) as usize];
        println!(
            "{label}: {} skin pixels, post against pre: median {:.1e}, 95th percentile {:.1e}",
            off.len(),
            at(0.5),
            at(0.95)
        );
        assert!(off.len() > 500, "{label}: {} skin pixels", off.len());
        // Half-float roundings (the light before and after the blur, the
        // albedo, the pre-scatter product): 3e-3 at the median.
        assert!(
            at(0.5) < 3e-3 && at(0.95) < 1e-2,
            "{label}: {:.2e} {:.2e}",
            at(0.5),
            at(0.95)
        );
    }
}
