//! Expression wrinkles on the GPU (thesis ch. 8, issue 30; lavapipe,
//! validation on):
//! - on the flat card of `accuracy`, with one wrinkle slope and one mask
//!   value per zone over the whole card, the lit frame over the unwrinkled
//!   one is the cosine of Listing 8.1's normal (the CPU's
//!   `skin::wrinkles::wrinkled_normal`, from the texels' own bytes) over the
//!   flat normal's, Table 8.1's sum clamped; the unclamped sum is far off;
//! - on the face, Table 8.1's cancellation: under surprise the forehead's
//!   zones crease the frame; under surprise and anger they add nothing (a
//!   frame whose masks have no forehead is the same, bit for bit), while the
//!   brows' zones between them crease it;
//! - a crowd's characters each weigh their own expression's zones, at every
//!   step of a stepping run.

use crate::accuracy::{card_scene, card_settings, render_card};
use crate::common;

use dermis::render::{RenderSettings, Renderer};
use dermis::scene::expressions::EXPRESSIONS;
use dermis::scene::face::face_scene;
use dermis::scene::mesh::{Texture, WrinkleMaps};
use dermis::scene::morph::{Morph, MorphTarget};
use dermis::scene::wrinkle_maps::{decode, encode};
use dermis::scene::Scene;
use dermis::skin::wrinkles::{expression_weights, wrinkled_normal, zone_weights};
use glam::{Vec2, Vec3};

fn texel(px: [u8; 4]) -> Texture {
    Texture {
        width: 1,
        height: 1,
        rgba8: px.to_vec(),
    }
}

/// The card with one wrinkle slope `d` and one value per zone everywhere,
/// and six morph targets named after Table 8.1's expressions that move
/// nothing: their weights drive the zones alone.
fn wrinkled_card(d: [f32; 2], masks: [[u8; 4]; 2]) -> Scene {
    let mut scene = card_scene();
    scene.head.material.wrinkles = Some(WrinkleMaps {
        wrinkle: texel([encode(d[0]), encode(d[1]), 0, 255]),
        masks: masks.map(texel),
    });
    let n = scene.head.mesh.vertices.len();
    let targets = EXPRESSIONS
        .iter()
        .map(|e| MorphTarget {
            name: Some(e.to_string()),
            first: 0,
            position: vec![[0.0; 3]; n],
            normal: Vec::new(),
            tangent: Vec::new(),
        })
        .collect();
    scene
        .head
        .set_morph(Morph {
            rest: Vec::new(),
            weights: vec![0.0; EXPRESSIONS.len()],
            targets,
            skin: None,
        })
        .unwrap();
    scene
}

fn weighed(scene: &Scene, weights: &[(&str, f32)]) -> Scene {
    let mut s = scene.clone();
    let w: Vec<(String, f32)> = weights.iter().map(|&(n, w)| (n.into(), w)).collect();
    s.set_morph_weights(&w).unwrap();
    s
}

#[test]
fn the_card_is_lit_by_listing_8_1s_normal() {
    let ctx = common::ctx();
    let d = [0.5, -0.3];
    let masks = [[255, 0, 128, 64], [0, 191, 255, 255]];
    let card = wrinkled_card(d, masks);
    let base = card_settings(&card, 2.0).with(common::m("none"), &[]);
    let l = base.light.direction_to_light(card.forward);
    // The flat normal map (128, 128, 255) as the shader decodes it.
    let flat = -1.0 + 2.0 * 128.0 / 255.0;
    let flat_n = Vec3::new(flat, flat, 1.0).normalize();
    let wrinkle = Vec2::new(decode(encode(d[0])), decode(encode(d[1])));
    let m: [f32; 8] = std::array::from_fn(|z| f32::from(masks[z / 4][z % 4]) / 255.0);
    let cases: [&[(&str, f32)]; 2] = [
        // Every row of Table 8.1 but two: anger's negative row cancels part
        // of joy's and surprise's.
        &[
            ("joy", 0.5),
            ("surprise", 0.5),
            ("anger", 0.5),
            ("sad", 0.3),
        ],
        // Joy and surprise together pass 1 on the eyes' zones: clamped.
        &[("joy", 1.0), ("surprise", 1.0)],
    ];
    for weights in cases {
        let scene = weighed(&card, weights);
        let mut plain = scene.clone();
        plain.head.material.wrinkles = None;
        let (out, _) = render_card(&ctx, &scene, &base);
        let (none, _) = render_card(&ctx, &plain, &base);
        let rows: Vec<f32> = EXPRESSIONS
            .iter()
            .map(|e| weights.iter().find(|w| w.0 == *e).map_or(0.0, |w| w.1))
            .collect();
        let z = zone_weights(&rows);
        let n = wrinkled_normal(Vec2::new(flat, flat), wrinkle, m, z);
        let want = n.dot(l).max(0.0) / flat_n.dot(l);
        // The sum without Table 8.1's clamp, and the listing without its
        // second mask: what the test tells apart.
        let mut raw = [0.0f32; 8];
        for (w, row) in rows.iter().zip(dermis::skin::wrinkles::TABLE_8_1) {
            for (r, t) in raw.iter_mut().zip(row) {
                *r += w * t;
            }
        }
        let unclamped =
            wrinkled_normal(Vec2::new(flat, flat), wrinkle, m, raw).dot(l) / flat_n.dot(l);
        let mut half = z;
        half[4..].fill(0.0);
        let one_mask =
            wrinkled_normal(Vec2::new(flat, flat), wrinkle, m, half).dot(l) / flat_n.dot(l);
        // The card's middle, away from its shadow's and its edges' pixels.
        let w = base.width as usize;
        let h = out.len() / w;
        let mut worst = 0.0f32;
        for y in h / 4..3 * h / 4 {
            for x in (w / 8..3 * w / 8).chain(5 * w / 8..7 * w / 8) {
                let i = y * w + x;
                for c in 0..3 {
                    worst = worst.max((out[i][c] / none[i][c] - want).abs());
                }
            }
        }
        println!("{weights:?}: zones {z:?}, lit {want:.4} of flat (unclamped {unclamped:.4}, one mask {one_mask:.4}), frame off by {worst:.2e}");
        assert!(worst < 2e-3, "{weights:?}: {worst}");
        assert!((want - unclamped).abs() > 0.01 || raw == z, "{weights:?}");
        assert!(
            (want - one_mask).abs() > 0.01 || z[4..].iter().all(|&v| v == 0.0),
            "{weights:?}"
        );
        assert!(
            want < 0.97,
            "{weights:?}: the wrinkles barely tilt the normal"
        );
    }
    // The zone weights the card's targets give are Table 8.1's (by name).
    let names = EXPRESSIONS.map(Some);
    assert_eq!(
        expression_weights(names, &[0.0, 1.0, 0.0, 1.0, 0.0, 0.0]),
        [0.0, 1.0, 0.0, 1.0, 0.0, 0.0]
    );
}

/// The face's frame (no SSS: the lit light alone) at `weights`, close up.
fn face_frame(ctx: &dermis::vk::context::Context, scene: &Scene) -> Vec<[f32; 4]> {
    let s = RenderSettings {
        width: 320,
        height: 240,
        shadow_size: 512,
        distance_heads: 1.2,
        ..RenderSettings::study()
    }
    .with(common::m("none"), &[]);
    let mut r = Renderer::new(ctx, scene, &s).unwrap();
    r.capture(false).unwrap().diffuse
}

fn differing(a: &[[f32; 4]], b: &[[f32; 4]]) -> usize {
    a.iter().zip(b).filter(|(p, q)| p != q).count()
}

#[test]
fn anger_cancels_surprises_forehead_on_the_gpu() {
    let ctx = common::ctx();
    let face = face_scene();
    // The same face with the forehead's two zones (mask 0's B and A) empty.
    let mut no_forehead = face.clone();
    let maps = no_forehead.head.material.wrinkles.as_mut().unwrap();
    for px in maps.masks[0].rgba8.chunks_exact_mut(4) {
        px[2] = 0;
        px[3] = 0;
    }
    let mut plain = face.clone();
    plain.head.material.wrinkles = None;
    let surprise = [("surprise", 1.0)];
    let both = [("surprise", 1.0), ("anger", 1.0)];
    let frame = |s: &Scene, w: &[(&str, f32)]| face_frame(&ctx, &weighed(s, w));
    let (s_full, s_cut, s_plain) = (
        frame(&face, &surprise),
        frame(&no_forehead, &surprise),
        frame(&plain, &surprise),
    );
    let forehead = differing(&s_full, &s_cut);
    println!(
        "surprise: {forehead} pixels creased by the forehead's zones, {} by any",
        differing(&s_full, &s_plain)
    );
    assert!(forehead > 500, "surprise creases the forehead: {forehead}");
    let (b_full, b_cut, b_plain) = (
        frame(&face, &both),
        frame(&no_forehead, &both),
        frame(&plain, &both),
    );
    let creased = differing(&b_full, &b_plain);
    println!(
        "surprise + anger: {} pixels from the forehead's zones, {creased} creased",
        differing(&b_full, &b_cut)
    );
    assert_eq!(b_full, b_cut, "anger cancels surprise's forehead wrinkles");
    assert!(creased > 200, "the brows' zones crease: {creased}");
}

#[test]
fn each_character_of_a_crowd_weighs_its_own_expression() {
    let ctx = common::ctx();
    let mut source = dermis::scene::source::SceneSource {
        time: Some(4.0),
        time_step: Some(0.9),
        ..Default::default()
    };
    let scene = source.load().unwrap();
    let s = RenderSettings {
        width: 192,
        height: 108,
        shadow_size: 256,
        heads: 4,
        ..RenderSettings::default()
    }
    .with(common::m("none"), &[]);
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let tracks = scene.tracks.clone().unwrap();
    let names: Vec<Option<&str>> = scene
        .head
        .morph
        .targets
        .iter()
        .map(|t| t.name.as_deref())
        .collect();
    let mut distinct = std::collections::BTreeSet::new();
    for frame in 0..3u64 {
        r.capture(false).unwrap();
        let t = tracks.at_frame(frame).unwrap();
        for (c, got) in r.frame.zones.iter().enumerate() {
            // Frame 0 is the scene as built (character 0 as posed); later
            // frames pose every character from the clip.
            let w = if frame == 0 {
                scene.character_weights(c)
            } else {
                t.head_weights(c, &scene.head.morph.weights)
            };
            let want = zone_weights(&expression_weights(names.iter().copied(), &w));
            assert_eq!(*got, want, "frame {frame}, character {c}");
            distinct.insert(got.map(f32::to_bits));
        }
    }
    println!(
        "{} distinct zone weightings over 3 frames of 4 characters",
        distinct.len()
    );
    assert!(distinct.len() >= 4, "the characters share one expression");
    source.no_wrinkles = true;
    let plain = source.load().unwrap();
    let r = Renderer::new(&ctx, &plain, &s).unwrap();
    assert!(r.frame.zones.iter().all(|z| *z == [0.0; 8]));
}
