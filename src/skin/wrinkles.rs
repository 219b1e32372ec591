//! Expression wrinkles (thesis ch. 8): partial-derivative normal maps, eight
//! wrinkle zones weighted per expression (Table 8.1), and the weighted sum of
//! Listing 8.1; also the normal-difference alternative of 8.2.1. Pure: the
//! geometry pass computes [`wrinkled_normal`] per pixel, and these are what it
//! is held to.
//!
//! A partial-derivative normal stores (n_x / n_z, n_y / n_z) instead of
//! (n_x, n_y, n_z): reconstructing is a normalisation of (d_x, d_y, 1), and
//! combining maps is adding their (d_x, d_y) (8.2, after Acton 2008, without
//! the minus sign in either step, as the chapter drops it). It holds normals
//! within 45 degrees of the surface normal at 8 bits (|d| <= 1).
//!
//! The zones are Table 8.1's colours. The mask figure (8.3) did not survive
//! the text, so which part of the face each colour is comes from the
//! expressions that crease it (their action units, FACS): red and green take
//! joy most (AU 6, the cheek raiser) and are the crow's feet and the cheeks'
//! folds down to the nasolabial fold, left and right; blue and brown take
//! surprise, fear and sadness and are cancelled by anger (8.2: anger cancels
//! surprise's forehead wrinkles) and are the forehead, left and right; cyan
//! and magenta take anger and disgust (AU 4, 9) and are the glabella, left
//! and right; orange is the nose's bridge (AU 9, the nose wrinkler: anger,
//! disgust); grey takes sadness most and is the chin (AU 17, the mentalis).

use glam::{Vec2, Vec3};

/// Table 8.1's zones, in its column order.
pub const ZONES: [&str; 8] = [
    "red: crow's feet and cheek, right",
    "green: crow's feet and cheek, left",
    "blue: forehead, right",
    "brown: forehead, left",
    "cyan: glabella, right",
    "magenta: glabella, left",
    "orange: nose bridge",
    "grey: chin",
];

/// Table 8.1: each expression's weight per zone (rows in
/// `scene::expressions::EXPRESSIONS`' order: joy, surprise, fear, anger,
/// disgust, sad).
pub const TABLE_8_1: [[f32; 8]; 6] = [
    [1.0, 1.0, 0.2, 0.2, 0.0, 0.0, 0.0, 0.0],
    [0.8, 0.8, 0.8, 0.8, 0.0, 0.0, 0.0, 0.0],
    [0.2, 0.2, 0.75, 0.75, 0.3, 0.3, 0.0, 0.6],
    [-0.6, -0.6, -0.8, -0.8, 0.8, 0.8, 1.0, 0.0],
    [0.0, 0.0, -0.1, -0.1, 1.0, 1.0, 1.0, 0.5],
    [0.2, 0.2, 0.75, 0.75, 0.0, 0.0, 0.1, 1.0],
];

/// Each zone's weight for the expression weights `expressions` (one per
/// row of [`TABLE_8_1`]; missing ones 0): the sum of each expression's
/// weight times its row, clamped to [0, 1] (8.2: past a limit the summed
/// wrinkles show artefacts). Negative rows cancel positive ones before the
/// clamp.
pub fn zone_weights(expressions: &[f32]) -> [f32; 8] {
    let mut z = [0.0f32; 8];
    for (w, row) in expressions.iter().zip(&TABLE_8_1) {
        for (zi, r) in z.iter_mut().zip(row) {
            *zi += w * r;
        }
    }
    z.map(|v| v.clamp(0.0, 1.0))
}

/// The zone weights of a head whose morph targets are named `names`
/// ([`expression_weights`]) at `weights`: what its draws' wrinkles show.
pub fn zones_of(names: &[Option<String>], weights: &[f32]) -> [f32; 8] {
    zone_weights(&expression_weights(
        names.iter().map(Option::as_deref),
        weights,
    ))
}

/// Character `c`'s zone weights (frame index; `Scene::character_weights`);
/// all 0 for a skin without wrinkle maps (nothing to weigh).
pub fn character_zones(scene: &crate::scene::Scene, c: usize) -> [f32; 8] {
    if scene.head.material.wrinkles.is_none() {
        return [0.0; 8];
    }
    zones_of(&head_target_names(scene), &scene.character_weights(c))
}

/// The head's morph targets' names, in order.
pub fn head_target_names(scene: &crate::scene::Scene) -> Vec<Option<String>> {
    scene
        .head
        .morph
        .targets
        .iter()
        .map(|t| t.name.clone())
        .collect()
}

/// Zone weights as the shaders read them: two vec4 (Listing 8.1's
/// `weights[2]`).
pub fn zones_std430(z: [f32; 8]) -> [[f32; 4]; 2] {
    [[z[0], z[1], z[2], z[3]], [z[4], z[5], z[6], z[7]]]
}

/// A normal (z > 0, the tangent-space hemisphere) as a partial-derivative
/// normal: (n_x / n_z, n_y / n_z).
pub fn to_partial_derivative(n: Vec3) -> Vec2 {
    Vec2::new(n.x / n.z, n.y / n.z)
}

/// A partial-derivative normal back to a unit normal: (d_x, d_y, 1)
/// normalised.
pub fn from_partial_derivative(d: Vec2) -> Vec3 {
    d.extend(1.0).normalize()
}

/// Listing 8.1's 8-bit encoding (`scene::wrinkle_maps`, where the maps are
/// made): 0.5 + 0.5 x, read back as -1 + 2 c.
pub use crate::scene::wrinkle_maps::{decode, encode};

/// The expression weights Table 8.1's rows take from a morph's targets:
/// each target named after an expression (`scene::expressions::EXPRESSIONS`,
/// any case; "sadness" for "sad") gives its row its weight. Targets of
/// other names drive no wrinkles.
pub fn expression_weights<'a>(
    names: impl IntoIterator<Item = Option<&'a str>>,
    weights: &[f32],
) -> [f32; 6] {
    let mut out = [0.0; 6];
    for (name, w) in names.into_iter().zip(weights) {
        let Some(name) = name.map(str::to_ascii_lowercase) else {
            continue;
        };
        let name = if name == "sadness" {
            "sad".into()
        } else {
            name
        };
        if let Some(row) = crate::scene::expressions::EXPRESSIONS
            .iter()
            .position(|e| *e == name)
        {
            out[row] += w;
        }
    }
    out
}

/// Listing 8.1: the base partial-derivative normal plus the wrinkle map's,
/// once per zone, weighted by the zone's mask times its weight, in zone
/// order, then normalised.
pub fn wrinkled_normal(base: Vec2, wrinkle: Vec2, masks: [f32; 8], weights: [f32; 8]) -> Vec3 {
    let mut d = base;
    for (m, w) in masks.iter().zip(&weights) {
        d += (m * w) * wrinkle;
    }
    from_partial_derivative(d)
}

/// 8.2.1's alternative: a conventional wrinkle normal `w` stored as its
/// difference from the base `b`, scaled and biased into [0, 1]
/// (0.5 + 0.5 (w - b)).
pub fn difference(w: Vec3, b: Vec3) -> Vec3 {
    Vec3::splat(0.5) + 0.5 * (w - b)
}

/// The base `b` plus the masked, weighted differences `d` (each decoded
/// as 2 d - 1), renormalised (8.2.1: needed after compression, and after
/// any sum of differences).
pub fn with_differences(b: Vec3, d: Vec3, masks: [f32; 8], weights: [f32; 8]) -> Vec3 {
    let delta = 2.0 * d - Vec3::ONE;
    let k: f32 = masks.iter().zip(&weights).map(|(m, w)| m * w).sum();
    (b + k * delta).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_derivatives_round_trip_within_the_cone() {
        for (x, y) in [(0.0, 0.0), (0.3, -0.2), (-0.6, 0.5), (0.7, 0.7)] {
            let n = Vec3::new(x, y, 1.0).normalize();
            let d = to_partial_derivative(n);
            assert!((from_partial_derivative(d) - n).length() < 1e-6);
            // Through 8 bits: within a step's angle.
            let q = Vec2::new(decode(encode(d.x)), decode(encode(d.y)));
            assert!(from_partial_derivative(q).angle_between(n) < 0.006, "{n}");
        }
        // 45 degrees is the edge of what 8 bits hold; past it, clamped.
        let n = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert_eq!(encode(to_partial_derivative(n).x), 255);
        let steep = Vec3::new(2.0, 0.0, 1.0).normalize();
        let q = decode(encode(to_partial_derivative(steep).x));
        assert_eq!(q, 1.0);
    }

    #[test]
    fn adding_partial_derivatives_adds_the_height_fields() {
        // A plane z = a x + b y: its normal from the cross product of its
        // tangents (1, 0, a) and (0, 1, b). Two planes' partial derivatives
        // add to the summed plane's, which a sum of conventional normals
        // does not give.
        let normal = |a: f32, b: f32| {
            Vec3::new(1.0, 0.0, a)
                .cross(Vec3::new(0.0, 1.0, b))
                .normalize()
        };
        let (n1, n2) = (normal(0.2, -0.1), normal(-0.5, 0.3));
        let sum = to_partial_derivative(n1) + to_partial_derivative(n2);
        let want = normal(0.2 - 0.5, -0.1 + 0.3);
        assert!((from_partial_derivative(sum) - want).length() < 1e-6);
        let naive = (n1 + n2 - Vec3::Z).normalize();
        assert!(
            (naive - want).length() > 1e-3,
            "the test cannot tell them apart"
        );
    }

    #[test]
    fn table_8_1_anger_cancels_surprises_forehead() {
        let surprise = zone_weights(&[0.0, 1.0]);
        assert_eq!(surprise[2], 0.8);
        assert_eq!(surprise[3], 0.8);
        // Surprise then anger: the forehead zones cancel to 0 (the clamp
        // keeps anger alone from going negative), the glabella creases.
        let both = zone_weights(&[0.0, 1.0, 0.0, 1.0]);
        assert_eq!(both[2], 0.0);
        assert_eq!(both[3], 0.0);
        assert_eq!(both[4], 0.8);
        assert_eq!(zone_weights(&[0.0, 0.0, 0.0, 1.0])[2], 0.0);
        // The sum clamps at 1: joy and surprise on the crow's feet.
        assert_eq!(zone_weights(&[1.0, 1.0])[0], 1.0);
        assert_eq!(zone_weights(&[]), [0.0; 8]);
    }

    #[test]
    fn targets_drive_the_rows_they_are_named_after() {
        let names = [
            Some("Anger"),
            None,
            Some("blink"),
            Some("sadness"),
            Some("joy"),
        ];
        let w = expression_weights(names, &[0.5, 1.0, 1.0, 0.25, 0.75]);
        assert_eq!(w, [0.75, 0.0, 0.0, 0.5, 0.0, 0.25]);
    }

    #[test]
    fn listing_8_1_is_the_weighted_sum_of_zones() {
        let base = Vec2::new(0.1, -0.05);
        let wrinkle = Vec2::new(0.4, 0.2);
        let masks = [1.0, 0.0, 0.5, 0.0, 0.0, 0.25, 0.0, 1.0];
        let weights = zone_weights(&[0.3, 0.6, 0.0, 0.0, 0.0, 0.5]);
        let k: f32 = masks.iter().zip(&weights).map(|(m, w)| m * w).sum();
        let want = from_partial_derivative(base + k * wrinkle);
        let got = wrinkled_normal(base, wrinkle, masks, weights);
        assert!((got - want).length() < 1e-6);
        // No weight, no wrinkle: the base normal.
        assert_eq!(
            wrinkled_normal(base, wrinkle, masks, [0.0; 8]),
            from_partial_derivative(base)
        );
    }

    #[test]
    fn differences_add_back_the_wrinkle_at_full_weight() {
        let b = Vec3::new(0.1, 0.0, 1.0).normalize();
        let w = Vec3::new(-0.3, 0.2, 1.0).normalize();
        let d = difference(w, b);
        let mut masks = [0.0; 8];
        masks[2] = 1.0;
        let mut weights = [0.0; 8];
        weights[2] = 1.0;
        assert!((with_differences(b, d, masks, weights) - w).length() < 1e-6);
        assert!((with_differences(b, d, masks, [0.0; 8]) - b).length() < 1e-6);
    }
}
