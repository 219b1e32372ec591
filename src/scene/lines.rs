//! `builtin:lines`: the synthetic scene of thin lines and a grid the
//! anti-aliasing evaluation scores on (issue 17 item 6, thesis Fig. 10.10's
//! case: geometry thinner than a pixel, which no post-process AA can rebuild
//! and a supersampled frame resolves).
//!
//! A flat card, 230 mm square like a head's chin-to-crown height so the
//! camera frames it as it frames a head, holds dark skin-material bars in
//! front of a light, matte backdrop:
//! - left half: near-vertical bars tilted by 4 degrees, their widths halving
//!   from 6 mm to under 0.2 mm (from a few pixels down to a fraction of one at
//!   the usual distances);
//! - top right: near-horizontal bars tilted by 3 degrees, the same widths;
//! - bottom right: a grid of 1.5 mm bars, 8 x 8 cells, turned by 10 degrees.
//!
//! The bars are skin, so the SSS method under evaluation runs on them (the
//! supersampled frame must use the same method); the card is not. "Several
//! distances" are camera distances: the evaluation views the card at more
//! than one (`eval::aa_eval`).

use glam::{Vec2, Vec3};

use super::mesh::{Material, Mesh, Object, Vertex};
use super::Scene;

/// Millimetres per scene unit: the procedural heads' scale.
pub const MM_PER_UNIT: f32 = 10.0;
/// Half the card's side in scene units (115 mm).
const HALF: f32 = 11.5;
/// Bar widths in scene units (6 mm halving to 0.1875 mm).
const WIDTHS: [f32; 6] = [0.6, 0.3, 0.15, 0.075, 0.0375, 0.01875];
/// The bars' albedo: dark, so their edges have a strong contrast.
const BAR_ALBEDO: [f32; 3] = [0.06, 0.045, 0.04];
/// The backdrop's albedo: light grey.
const CARD_ALBEDO: [f32; 3] = [0.75; 3];

/// One bar: the quad of width `w` around the segment `a`-`b` at depth `z`.
fn bar(mesh: &mut Mesh, a: Vec2, b: Vec2, w: f32, z: f32) {
    let d = (b - a).normalize_or_zero();
    let n = Vec2::new(-d.y, d.x) * (0.5 * w);
    let base = mesh.vertices.len() as u32;
    for p in [a - n, b - n, b + n, a + n] {
        mesh.vertices.push(Vertex {
            position: [p.x, p.y, z],
            normal: [0.0, 0.0, 1.0],
            uv: [(p.x + HALF) / (2.0 * HALF), (HALF - p.y) / (2.0 * HALF)],
            tangent: [1.0, 0.0, 0.0, 1.0],
        });
    }
    // Counter-clockwise seen from +Z (the camera's side).
    mesh.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// The bars of the card, all in the plane z = 0.
pub fn lines_mesh() -> Mesh {
    let mut m = Mesh {
        vertices: Vec::new(),
        indices: Vec::new(),
    };
    let rot = |v: Vec2, deg: f32| Vec2::from_angle(deg.to_radians()).rotate(v);
    // The frame's corners, so the card's framed extent is exactly 2 HALF.
    let edge = 0.3;
    for (a, b) in [
        (Vec2::new(-HALF, -HALF), Vec2::new(HALF, -HALF)),
        (Vec2::new(-HALF, HALF), Vec2::new(HALF, HALF)),
    ] {
        bar(&mut m, a, b, edge, 0.0);
    }
    // Left half: near-vertical bars, two of each width.
    for (i, &w) in WIDTHS.iter().enumerate() {
        for k in 0..2 {
            let x = -10.0 + 1.6 * (2 * i + k) as f32;
            let c = Vec2::new(x, 0.0);
            let h = Vec2::new(0.0, 10.0);
            bar(&mut m, c + rot(-h, 4.0), c + rot(h, 4.0), w, 0.0);
        }
    }
    // Top right: near-horizontal bars.
    for (i, &w) in WIDTHS.iter().enumerate() {
        let c = Vec2::new(5.75, 1.5 + 1.6 * i as f32);
        let h = Vec2::new(5.0, 0.0);
        bar(&mut m, c + rot(-h, 3.0), c + rot(h, 3.0), w, 0.0);
    }
    // Bottom right: a grid turned by 10 degrees.
    let (centre, half, cells, w) = (Vec2::new(5.75, -5.25), 4.5, 8, 0.15);
    for j in 0..=cells {
        let t = -half + 2.0 * half * j as f32 / cells as f32;
        for (a, b) in [
            (Vec2::new(t, -half), Vec2::new(t, half)),
            (Vec2::new(-half, t), Vec2::new(half, t)),
        ] {
            bar(&mut m, centre + rot(a, 10.0), centre + rot(b, 10.0), w, 0.0);
        }
    }
    m
}

/// The light card behind the bars (a unit behind them: 10 mm, so the bars'
/// shadows fall beside them, more edges of their own).
fn card_mesh() -> Mesh {
    let mut m = Mesh {
        vertices: Vec::new(),
        indices: Vec::new(),
    };
    let s = 3.0 * HALF;
    bar(&mut m, Vec2::new(-s, 0.0), Vec2::new(s, 0.0), 2.0 * s, -1.0);
    m
}

/// The scene `--scene builtin:lines` names.
pub fn lines_scene() -> Scene {
    let head = lines_mesh();
    let head_bounds = head.bounds();
    Scene {
        tracks: None,
        name: "thin lines and a grid".to_owned(),
        mm_per_unit: MM_PER_UNIT,
        head: Object {
            morph: Default::default(),
            mesh: head,
            material: Material::skin(BAR_ALBEDO),
        },
        parts: Vec::new(),
        backdrop: Some(Object {
            morph: Default::default(),
            mesh: card_mesh(),
            material: Material {
                skin: false,
                base_color_factor: CARD_ALBEDO,
                base_color: None,
                normal_map: None,
                specular_map: None,
                roughness_map: None,
                sss_map: None,
                wrinkles: None,
                roughness: 0.7,
                specular_intensity: 0.02,
                sss_strength: 0.0,
            },
        }),
        head_bounds,
        source: Some(super::source::SceneSource::builtin_named("lines")),
        forward: Vec3::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_card_is_flat_faces_the_camera_and_is_head_sized() {
        let s = lines_scene();
        s.head.mesh.validate().unwrap();
        assert!((s.head_height_units() * s.mm_per_unit - 230.0).abs() < 5.0);
        assert_eq!(
            super::super::head_measure::face_direction(&s.head.mesh),
            Vec3::Z
        );
        // Every bar faces +Z: counter-clockwise seen from the camera.
        let v = &s.head.mesh.vertices;
        for t in s.head.mesh.indices.chunks_exact(3) {
            let p: Vec<Vec3> = t
                .iter()
                .map(|&i| Vec3::from(v[i as usize].position))
                .collect();
            assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0);
        }
    }
}
