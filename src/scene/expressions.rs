//! The procedural face's six expressions of the thesis' Table 8.1 (joy,
//! surprise, fear, anger, disgust, sadness) as morph targets built by code:
//! each a sum of smooth offsets over the face, written after the facial
//! action units that make the expression (Ekman and Friesen's FACS: joy is
//! the cheek raiser and the lip-corner puller, AU 6 + 12; surprise the brow
//! raisers and the jaw drop, AU 1 + 2 + 5 + 26; fear AU 1 + 2 + 4 + 5 + 20 +
//! 26; anger the brow lowerer and the lip presser, AU 4 + 5 + 7 + 23; disgust
//! the nose wrinkler and the upper-lip raiser, AU 9 + 10; sadness the inner
//! brow raiser and the lip-corner depressor, AU 1 + 4 + 15). Each target
//! carries the normal and tangent offsets of its own shape (normals and
//! tangents of the displaced mesh minus the rest mesh's), as a glTF file's
//! would.
//!
//! The mouth stays closed (the lips are one surface, grooved): the jaw drop
//! stretches it. Sizes are in millimetres, anatomical and tuned by eye.

use glam::Vec3;

use super::animation::{Channel, Clip, Interpolation, Path};
use super::mesh::Mesh;
use super::morph::{Morph, MorphTarget};

/// The expressions, in Table 8.1's order (their target names).
pub const EXPRESSIONS: [&str; 6] = ["joy", "surprise", "fear", "anger", "disgust", "sad"];

/// One smooth offset: `offset` (mm; x away from the midline on each side) at
/// `centre` (mm, right side; the left mirrors it), falling off as a Gaussian
/// of radii `radii` (mm).
struct Bump {
    centre: [f32; 3],
    radii: [f32; 3],
    offset: [f32; 3],
}

const fn b(centre: [f32; 3], radii: [f32; 3], offset: [f32; 3]) -> Bump {
    Bump {
        centre,
        radii,
        offset,
    }
}

/// The jaw dropping (surprise, fear at a third): chin and lower lip down.
const JAW: [f32; 3] = [0.0, -95.0, 65.0];
const JAW_RADII: [f32; 3] = [35.0, 22.0, 30.0];
/// The lip corners and the upper lids.
const CORNER: [f32; 3] = [23.0, -69.0, 85.0];
const CORNER_RADII: [f32; 3] = [9.0, 8.0, 10.0];
const UPPER_LID: [f32; 3] = [32.0, 6.0, 76.0];
const UPPER_LID_RADII: [f32; 3] = [11.0, 3.0, 5.0];

/// Each expression's offsets (module docs: the action units).
fn bumps(expression: usize) -> &'static [Bump] {
    const JOY: &[Bump] = &[
        b(CORNER, CORNER_RADII, [2.5, 4.0, -1.5]),
        b([33.0, -35.0, 70.0], [14.0, 12.0, 12.0], [0.5, 2.5, 1.5]),
        b([32.0, -8.0, 74.0], [10.0, 4.0, 6.0], [0.0, 1.2, 0.0]),
    ];
    const SURPRISE: &[Bump] = &[
        b([22.0, 14.0, 80.0], [22.0, 10.0, 14.0], [0.0, 5.0, 0.0]),
        b([0.0, 40.0, 75.0], [40.0, 25.0, 20.0], [0.0, 2.0, 0.0]),
        b(UPPER_LID, UPPER_LID_RADII, [0.0, 1.0, 0.0]),
        b(JAW, JAW_RADII, [0.0, -5.0, -1.0]),
    ];
    const FEAR: &[Bump] = &[
        b([12.0, 12.0, 82.0], [12.0, 8.0, 12.0], [-1.5, 4.0, 0.0]),
        b(UPPER_LID, UPPER_LID_RADII, [0.0, 1.2, 0.0]),
        b(CORNER, CORNER_RADII, [3.5, -1.0, -1.0]),
        b(JAW, JAW_RADII, [0.0, -2.5, 0.0]),
    ];
    const ANGER: &[Bump] = &[
        b([18.0, 11.0, 81.0], [14.0, 7.0, 12.0], [-2.5, -3.5, 0.5]),
        b([0.0, -64.0, 92.0], [20.0, 4.0, 8.0], [0.0, -0.8, -0.6]),
        b([0.0, -74.0, 90.0], [20.0, 4.0, 8.0], [0.0, 0.8, -0.6]),
        b([13.0, -41.0, 92.0], [6.0, 6.0, 8.0], [1.0, 0.0, 0.0]),
    ];
    const DISGUST: &[Bump] = &[
        b([13.0, -38.0, 92.0], [8.0, 8.0, 10.0], [0.0, 2.5, 0.0]),
        b([8.0, -63.0, 92.0], [14.0, 5.0, 8.0], [0.0, 2.5, 0.5]),
        b([20.0, 11.0, 81.0], [16.0, 7.0, 12.0], [-1.0, -2.0, 0.0]),
        b([30.0, -32.0, 72.0], [12.0, 10.0, 12.0], [0.0, 1.5, 0.5]),
    ];
    const SAD: &[Bump] = &[
        b([10.0, 12.0, 83.0], [9.0, 7.0, 12.0], [-1.0, 3.5, 0.0]),
        b([23.0, -71.0, 85.0], [8.0, 8.0, 10.0], [0.5, -3.5, -0.5]),
        b([0.0, -98.0, 72.0], [18.0, 12.0, 15.0], [0.0, 1.5, 1.0]),
    ];
    [JOY, SURPRISE, FEAR, ANGER, DISGUST, SAD][expression]
}

/// Squared half-width (mm^2) of the band around the midline over which the
/// mirrored offsets are blended (as the skull's field blends its features).
const MIRROR_ROUNDING_MM2: f32 = 4.0;

/// The offset (mm) of expression `e` at `p` (mm).
pub fn offset_mm(e: usize, p: Vec3) -> Vec3 {
    let q = (p.x * p.x + MIRROR_ROUNDING_MM2).sqrt();
    let side = p.x / q;
    bumps(e)
        .iter()
        .map(|k| {
            let d = Vec3::new(
                (q - k.centre[0]) / k.radii[0],
                (p.y - k.centre[1]) / k.radii[1],
                (p.z - k.centre[2]) / k.radii[2],
            );
            let w = (-d.length_squared()).exp();
            Vec3::new(k.offset[0] * side, k.offset[1], k.offset[2]) * w
        })
        .sum()
}

/// The six targets over the first `count` vertices of `head` (the face's
/// skull shell; the ears after it do not move), in scene units of
/// `mm_per_unit`, at weight 0.
pub fn expression_morph(head: &Mesh, count: usize, mm_per_unit: f32) -> Morph {
    let targets = (0..EXPRESSIONS.len())
        .map(|e| {
            let position: Vec<[f32; 3]> = head.vertices[..count]
                .iter()
                .map(|v| (offset_mm(e, Vec3::from(v.position) * mm_per_unit) / mm_per_unit).into())
                .collect();
            let mut moved = head.clone();
            for (v, d) in moved.vertices.iter_mut().zip(&position) {
                v.position = (Vec3::from(v.position) + Vec3::from(*d)).into();
            }
            moved.compute_normals();
            moved.generate_tangents();
            let diff = |f: &dyn Fn(&super::vertex::Vertex) -> Vec3| -> Vec<[f32; 3]> {
                moved.vertices[..count]
                    .iter()
                    .zip(&head.vertices)
                    .map(|(a, b)| (f(a) - f(b)).into())
                    .collect()
            };
            MorphTarget {
                name: Some(EXPRESSIONS[e].to_string()),
                first: 0,
                position,
                normal: diff(&|v| Vec3::from(v.normal)),
                tangent: diff(&|v| Vec3::from([v.tangent[0], v.tangent[1], v.tangent[2]])),
            }
        })
        .collect::<Vec<_>>();
    Morph {
        rest: Vec::new(),
        weights: vec![0.0; targets.len()],
        targets,
        skin: None,
    }
}

/// Seconds each expression takes: rising from neutral, held, falling back.
pub const RISE_S: f32 = 1.0;
pub const HOLD_S: f32 = 0.5;
pub const FALL_S: f32 = 1.0;

/// The face's clip: neutral to each expression of Table 8.1 and back, in
/// turn (15 s), as one LINEAR channel of the six weights on node 0.
pub fn expression_clip() -> Clip {
    let n = EXPRESSIONS.len();
    let step = RISE_S + HOLD_S + FALL_S;
    let mut times = Vec::new();
    let mut values = Vec::new();
    let mut key = |t: f32, on: Option<usize>| {
        times.push(t);
        values.extend((0..n).map(|i| if Some(i) == on { 1.0 } else { 0.0 }));
    };
    for e in 0..n {
        let t0 = step * e as f32;
        key(t0, None);
        key(t0 + RISE_S, Some(e));
        key(t0 + RISE_S + HOLD_S, Some(e));
    }
    key(step * n as f32, None);
    Clip {
        name: "dermis expressions".into(),
        channels: vec![Channel {
            node: 0,
            path: Path::Weights,
            interpolation: Interpolation::Linear,
            times,
            values,
            width: n,
        }],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clip_rises_to_each_expression_and_falls_back() {
        let c = &expression_clip().channels[0];
        c.check("face").unwrap();
        assert_eq!(c.sample(0.0), [0.0; 6]);
        assert_eq!(c.sample(1.0), [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(c.sample(0.5)[0], 0.5);
        // Surprise held from 3.5 to 4 s, sadness last, neutral at the end.
        assert_eq!(c.sample(3.75), [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(c.sample(13.75)[5], 1.0);
        assert_eq!(c.sample(15.0), [0.0; 6]);
    }

    #[test]
    fn each_expression_moves_what_its_action_units_move() {
        let at = |e: &str, p: [f32; 3]| {
            offset_mm(
                EXPRESSIONS.iter().position(|x| *x == e).unwrap(),
                Vec3::from(p),
            )
        };
        // Joy lifts the lip corners, sadness lowers them; both sides alike
        // (mirrored, x away from the midline).
        let (l, r) = (
            at("joy", [-23.0, -69.0, 85.0]),
            at("joy", [23.0, -69.0, 85.0]),
        );
        assert!(r.y > 3.0 && (l.y - r.y).abs() < 1e-5 && (l.x + r.x).abs() < 1e-5 && r.x > 0.0);
        assert!(at("sad", [23.0, -71.0, 85.0]).y < -3.0);
        // Surprise raises the brows and drops the jaw; anger lowers the brows
        // and draws them together.
        assert!(at("surprise", [22.0, 14.0, 80.0]).y > 4.0);
        assert!(at("surprise", [0.0, -95.0, 65.0]).y < -4.0);
        let anger = at("anger", [18.0, 11.0, 81.0]);
        assert!(anger.y < -3.0 && anger.x < -2.0);
        // Nothing moves at the back of the head or at the ears.
        for e in 0..EXPRESSIONS.len() {
            assert!(offset_mm(e, Vec3::new(0.0, 0.0, -90.0)).length() < 1e-6);
            assert!(offset_mm(e, Vec3::new(75.0, 0.0, 0.0)).length() < 1e-3);
        }
    }
}
