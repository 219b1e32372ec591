//! The procedural face's eyes: two eyeballs in the lids' openings, a part of
//! the character that is not skin (shaded, shadowed, never scattered; the
//! skin rule's first case, made by code).
//!
//! Sizes are an adult's (mm): an eyeball 24 mm across, an iris 11.5 mm and a
//! pupil 4 mm across at rest. The ball is a UV sphere whose poles are on its
//! optical axis, so the iris and pupil are rings of the texture's rows
//! (v = angle from the axis over pi) and need no more texels than a column.

use glam::Vec3;
use std::f32::consts::{PI, TAU};

use super::mesh::{Material, Mesh, Object, Texture, Vertex};

/// Eyeball radius (mm).
pub const EYEBALL_RADIUS_MM: f32 = 12.0;
/// Iris and pupil radii (mm) on the ball's front.
const IRIS_RADIUS_MM: f32 = 5.75;
const PUPIL_RADIUS_MM: f32 = 2.0;
/// Rings around the optical axis and segments around it.
const RINGS: usize = 24;
const SEGMENTS: usize = 36;
/// Rows of the eye texture (angle from the axis, 0..pi).
const TEXTURE_ROWS: usize = 128;

/// sRGB colours: the sclera's warm white, a brown iris darker at its rim,
/// the pupil.
const SCLERA: [u8; 3] = [226, 218, 208];
const IRIS: [u8; 3] = [104, 70, 44];
const IRIS_RIM: [u8; 3] = [52, 36, 26];
const PUPIL: [u8; 3] = [12, 10, 10];

/// One eyeball centred at `centre_mm`, looking along `axis` (unit), in scene
/// units of `mm_per_unit`. Outward normals, counter-clockwise seen from outside.
pub fn eyeball_mesh(centre_mm: Vec3, axis: Vec3, mm_per_unit: f32) -> Mesh {
    let axis = axis.normalize();
    let side = axis.any_orthonormal_vector();
    let up = axis.cross(side);
    let mut mesh = Mesh::default();
    // Each ring is its own row of vertices, the seam duplicated so u runs 0..1.
    // The seam's and the poles' vertices land on the same bits as their
    // twins (the angle of the last column is the first's, the poles' sine is
    // 0), so the ball is closed to the bit (`enclosed::is_closed`).
    for i in 0..=RINGS {
        let theta = PI * i as f32 / RINGS as f32;
        let (sin_t, cos_t) = match i {
            0 => (0.0, 1.0),
            _ if i == RINGS => (0.0, -1.0),
            _ => theta.sin_cos(),
        };
        for j in 0..=SEGMENTS {
            let phi = TAU * (j % SEGMENTS) as f32 / SEGMENTS as f32;
            let n = axis * cos_t + (side * phi.cos() + up * phi.sin()) * sin_t;
            let p = centre_mm + n * EYEBALL_RADIUS_MM;
            mesh.vertices.push(Vertex {
                position: (p / mm_per_unit).into(),
                normal: n.into(),
                uv: [j as f32 / SEGMENTS as f32, i as f32 / RINGS as f32],
                tangent: [0.0; 4],
            });
        }
    }
    let at = |i: usize, j: usize| (i * (SEGMENTS + 1) + j) as u32;
    for i in 0..RINGS {
        for j in 0..SEGMENTS {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Pole rings have one zero-area triangle each: left out.
            if i > 0 {
                mesh.indices.extend([a, c, d]);
            }
            if i + 1 < RINGS {
                mesh.indices.extend([a, b, c]);
            }
        }
    }
    mesh.generate_tangents();
    mesh
}

/// The eye's texture: one column of rings by angle from the optical axis.
fn eye_texture() -> Texture {
    let width = 4;
    let mut rgba8 = Vec::with_capacity(width * TEXTURE_ROWS * 4);
    let iris_angle = (IRIS_RADIUS_MM / EYEBALL_RADIUS_MM).asin();
    let pupil_angle = (PUPIL_RADIUS_MM / EYEBALL_RADIUS_MM).asin();
    for row in 0..TEXTURE_ROWS {
        let angle = PI * (row as f32 + 0.5) / TEXTURE_ROWS as f32;
        let c = if angle < pupil_angle {
            PUPIL
        } else if angle < iris_angle * 0.85 {
            IRIS
        } else if angle < iris_angle {
            IRIS_RIM
        } else {
            SCLERA
        };
        for _ in 0..width {
            rgba8.extend([c[0], c[1], c[2], 255]);
        }
    }
    Texture {
        width: width as u32,
        height: TEXTURE_ROWS as u32,
        rgba8,
    }
}

/// The eye's material: not skin; the wet cornea's sharp, bright highlight.
pub fn eye_material() -> Material {
    Material {
        skin: false,
        base_color_factor: [1.0; 3],
        base_color: Some(eye_texture()),
        normal_map: None,
        specular_map: None,
        roughness_map: None,
        sss_map: None,
        wrinkles: None,
        roughness: 0.12,
        specular_intensity: 0.35,
        sss_strength: 0.0,
    }
}

/// Both eyes, the right one at `right_mm` and the left mirrored, looking
/// along +Z: one object, one material.
pub fn eyes(right_mm: Vec3, mm_per_unit: f32) -> Object {
    let mut mesh = eyeball_mesh(right_mm, Vec3::Z, mm_per_unit);
    let left = Vec3::new(-right_mm.x, right_mm.y, right_mm.z);
    mesh.append(&eyeball_mesh(left, Vec3::Z, mm_per_unit));
    Object {
        morph: Default::default(),
        mesh,
        material: eye_material(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_eyeball_is_a_closed_sphere_of_its_radius_facing_out() {
        let m = eyeball_mesh(Vec3::new(3.0, 1.0, 6.0), Vec3::Z, 1.0);
        m.validate().unwrap();
        for v in &m.vertices {
            let p = Vec3::from(v.position) - Vec3::new(3.0, 1.0, 6.0);
            assert!((p.length() - EYEBALL_RADIUS_MM).abs() < 1e-4);
            assert!(Vec3::from(v.normal).dot(p) > 0.0);
        }
        // Outward winding: every face normal points away from the centre.
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(m.vertices[t[k] as usize].position));
            let n = (b - a).cross(c - a);
            assert!(n.length() > 0.0);
            assert!(n.dot(a + b + c - 3.0 * Vec3::new(3.0, 1.0, 6.0)) > 0.0);
        }
        // The front pole (v = 0) is on the axis: the pupil faces +Z.
        let front = m.vertices.iter().find(|v| v.uv[1] == 0.0).unwrap();
        assert!((Vec3::from(front.normal) - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn the_texture_has_a_pupil_an_iris_and_white_by_angle() {
        let t = eye_texture();
        let row = |angle: f32| {
            let r = ((angle / PI) * TEXTURE_ROWS as f32) as usize;
            let i = r * t.width as usize * 4;
            [t.rgba8[i], t.rgba8[i + 1], t.rgba8[i + 2]]
        };
        assert_eq!(row(0.05), PUPIL);
        assert_eq!(row(0.3), IRIS);
        assert_eq!(row(1.0), SCLERA);
        assert!(!eye_material().skin && eye_material().sss_strength == 0.0);
    }
}
