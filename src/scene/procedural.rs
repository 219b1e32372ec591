//! The embedded default scene: a head-like shape built from formulas, so the renderer can
//! run (and its tests can check subsurface effects) without any asset files.
//!
//! Units: 1 unit = 10 mm. The head is ~23 units (230 mm) from chin to crown, Y up, the
//! face looking toward +Z, centred on the origin. It is a union of closed shells: the
//! skull (a tapered, displaced sphere with a nose) and two thin ear slabs ~3 mm thick that
//! poke into the side of the skull, so light visibly passes through them.

use super::mesh::{Material, Mesh, Object, Vertex};
use glam::{Mat4, Quat, Vec3};
use std::f32::consts::{PI, TAU};

/// Millimetres per unit of the procedural scene.
pub const MM_PER_UNIT: f32 = 10.0;
/// Half of the chin-to-crown height, in units.
const HALF_HEIGHT: f32 = 11.5;
/// Half of the cranium's width (x) and length (z), in units.
const HALF_WIDTH: f32 = 7.75;
const HALF_LENGTH: f32 = 9.75;
/// Ear slab thickness in units (3 mm): thin enough for strong transmitted light.
pub const EAR_THICKNESS: f32 = 0.3;
const EAR_HALF_HEIGHT: f32 = 3.1;
const EAR_HALF_WIDTH: f32 = 1.7;
/// How far the back of the ear flares away from the skull.
const EAR_FLARE_DEG: f32 = 20.0;
const EAR_Y: f32 = -1.5;
const EAR_Z: f32 = -0.8;

/// Where an ear slab sits: its centre and its thin axis, pointing away from the head.
/// Light travelling along `-normal` crosses the slab through its thinnest part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ear {
    pub center: Vec3,
    pub normal: Vec3,
}

pub(crate) fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// 1 inside `lo..hi`, 0 outside, with smooth shoulders `soft` wide.
pub(super) fn plateau(x: f32, lo: f32, hi: f32, soft: f32) -> f32 {
    smoothstep(lo - soft, lo, x) * (1.0 - smoothstep(hi, hi + soft, x))
}

/// Skull surface for polar angle `theta` (from +Y) and azimuth `phi` (0 = +Z, the face).
/// Every latitude ring keeps a single height and is only squeezed in x/z or pushed forward
/// on its front half, so the surface stays a stack of simple closed curves: it can never
/// intersect itself, whatever the bump sizes.
fn skull_point(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    let y = HALF_HEIGHT * ct;
    // Jaw narrower and shallower than the cranium.
    let jaw = smoothstep(-1.0, -10.0, y);
    let x = HALF_WIDTH * (1.0 - 0.32 * jaw) * st * sp;
    let mut z = HALF_LENGTH * (1.0 - 0.12 * jaw) * st * cp;
    let front = smoothstep(0.0, 0.5, st * cp);
    // Nose: a ridge from the brow (y ~ 1) to the tip (y = -4), ending at its base (y = -5).
    let nose_height = 2.3 * smoothstep(1.0, -4.0, y) * (1.0 - smoothstep(-4.0, -5.0, y));
    let nose_width = 0.7 + 0.3 * smoothstep(0.0, -4.0, y);
    let nose = nose_height * (-(x / nose_width).powi(2)).exp();
    // Eye sockets and a chin give the shading something to do.
    let eyes: f32 = [-3.0f32, 3.0]
        .iter()
        .map(|ex| -0.6 * (-((x - ex).powi(2) + (y - 0.3).powi(2)) / 1.96).exp())
        .sum();
    let chin = 0.8 * (-(x * x / 4.0 + (y + 9.5).powi(2) / 3.24)).exp();
    z += front * (nose + eyes + chin);
    Vec3::new(x, y, z)
}

/// A closed sphere-topology grid: `rings` bands from the pole at theta = 0 to the pole at
/// theta = pi, `segments` columns in phi starting at phi = -pi (the seam). `f(theta, phi)`
/// maps the parameters to a position with the same orientation as the unit sphere
/// `(sin t sin p, cos t, sin t cos p)`, which makes the triangles counter-clockwise seen
/// from outside. Seam and pole vertices are duplicated for UVs but computed from the same
/// parameters, so their positions are bit-identical and the shell is closed.
fn sphere_grid(rings: u32, segments: u32, f: impl Fn(f32, f32) -> Vec3) -> Mesh {
    let mut mesh = Mesh::default();
    for i in 0..=rings {
        let theta = i as f32 / rings as f32 * PI;
        for j in 0..=segments {
            // Poles use one phi for every column so they collapse to a single point.
            let jj = if i == 0 || i == rings {
                0
            } else {
                j % segments
            };
            let phi = jj as f32 / segments as f32 * TAU - PI;
            mesh.vertices.push(Vertex {
                position: f(theta, phi).into(),
                normal: [0.0, 1.0, 0.0],
                uv: [j as f32 / segments as f32, i as f32 / rings as f32],
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: u32, j: u32| i * (segments + 1) + j;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i != rings - 1 {
                mesh.indices.extend([a, b, c]);
            }
            if i != 0 {
                mesh.indices.extend([a, c, d]);
            }
        }
    }
    mesh
}

fn skull_shell() -> Mesh {
    sphere_grid(88, 128, skull_point)
}

/// The two ears: right (+X) and left (-X), flared back by `EAR_FLARE_DEG`, just outside
/// the skull at their centre so a ray along the normal crosses the slab before the skull.
pub fn ears() -> [Ear; 2] {
    let flare = EAR_FLARE_DEG.to_radians();
    [1.0f32, -1.0].map(|side| {
        // Skull half-width at the ear's height and depth, then 3.5 mm out.
        let skull_x = skull_half_width(EAR_Y, EAR_Z);
        Ear {
            center: Vec3::new(side * (skull_x + 0.35), EAR_Y, EAR_Z),
            normal: Vec3::new(side * flare.cos(), 0.0, flare.sin()),
        }
    })
}

/// Largest |x| of the skull surface near height `y` and depth `z`, found by sampling
/// (the surface is only given parametrically).
fn skull_half_width(y: f32, z: f32) -> f32 {
    let mut best = (f32::INFINITY, 0.0f32);
    for i in 1..400 {
        let theta = i as f32 / 400.0 * PI;
        for j in 0..200 {
            let phi = j as f32 / 200.0 * PI; // +x half
            let p = skull_point(theta, phi);
            let d = (p.y - y).powi(2) + (p.z - z).powi(2);
            if d < best.0 {
                best = (d, p.x);
            }
        }
    }
    best.1
}

/// A closed slab: a superellipsoid flattened along its normal, with flat faces (so the
/// thickness is `EAR_THICKNESS` over most of it) and a rounded rim.
fn ear_shell(ear: &Ear) -> Mesh {
    let n = ear.normal;
    let up = Vec3::Y;
    // Right-handed frame (side, n, up) mirrors (x, y, z) of the unit sphere, so the
    // sphere_grid orientation (outward CCW) carries over.
    let side = n.cross(up);
    let eps = 0.25;
    sphere_grid(24, 48, |theta, phi| {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let r = st.abs().powf(eps);
        let h = ct.signum() * ct.abs().powf(eps);
        ear.center
            + side * (EAR_HALF_WIDTH * r * sp)
            + n * (0.5 * EAR_THICKNESS * h)
            + up * (EAR_HALF_HEIGHT * r * cp)
    })
}

/// A flat `w` x `h` skin card of 8x4 quads in the XY plane, facing +Z, moved by
/// `m` (framing and hostile-input tests: a flat object must be seen face on).
pub fn flat_card(w: f32, h: f32, m: Mat4, albedo: [f32; 3]) -> Object {
    let (nx, ny) = (8u32, 4u32);
    let mut mesh = Mesh::default();
    for j in 0..=ny {
        for i in 0..=nx {
            let p = Vec3::new(
                (i as f32 / nx as f32 - 0.5) * w,
                (j as f32 / ny as f32 - 0.5) * h,
                0.0,
            );
            mesh.vertices.push(Vertex {
                position: m.transform_point3(p).into(),
                normal: m.transform_vector3(Vec3::Z).into(),
                uv: [i as f32 / nx as f32, j as f32 / ny as f32],
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    for j in 0..ny {
        for i in 0..nx {
            mesh.indices
                .extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            mesh.indices
                .extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Object {
        morph: Default::default(),
        mesh,
        material: Material::skin(albedo),
    }
}

/// The procedural head: skull plus both ears in one mesh, smooth normals, tangents from
/// the spherical UVs. About 25k triangles.
pub fn head_mesh() -> Mesh {
    let mut mesh = skull_shell();
    for ear in ears() {
        mesh.append(&ear_shell(&ear));
    }
    mesh.compute_normals();
    mesh.generate_tangents();
    mesh
}

/// A 120 x 120 unit backdrop quad at z = -25, facing +Z (toward the head and camera).
pub fn backdrop_mesh() -> Mesh {
    let h = 60.0;
    let z = -25.0;
    let corner = |x: f32, y: f32, u: f32, v: f32| Vertex {
        position: [x, y, z],
        normal: [0.0, 0.0, 1.0],
        uv: [u, v],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    Mesh {
        vertices: vec![
            corner(-h, -h, 0.0, 1.0),
            corner(h, -h, 1.0, 1.0),
            corner(h, h, 1.0, 0.0),
            corner(-h, h, 0.0, 0.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

/// The default backdrop moved to sit behind a head of any size and facing: scaled by
/// `head_height / 23` and turned about Y so that it faces `forward`, so it frames a loaded
/// scan the way it frames the procedural head.
pub fn backdrop_behind(center: Vec3, forward: Vec3, head_height: f32) -> Mesh {
    let scale = if head_height.is_finite() && head_height > 0.0 {
        head_height / (2.0 * HALF_HEIGHT)
    } else {
        1.0
    };
    let yaw = forward.x.atan2(forward.z);
    let m = Mat4::from_scale_rotation_translation(
        Vec3::splat(scale),
        Quat::from_rotation_y(if yaw.is_finite() { yaw } else { 0.0 }),
        center,
    );
    let mut mesh = backdrop_mesh();
    mesh.transform(&m);
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn key(m: &Mesh, i: u32) -> [u32; 3] {
        m.vertices[i as usize].position.map(f32::to_bits)
    }

    /// Directed edges keyed by position, so duplicated seam/pole vertices count as one.
    fn directed_edges(m: &Mesh) -> HashMap<([u32; 3], [u32; 3]), u32> {
        let mut e = HashMap::new();
        for t in m.indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *e.entry((key(m, a), key(m, b))).or_insert(0) += 1;
            }
        }
        e
    }

    fn assert_closed_and_consistent(m: &Mesh) {
        let directed = directed_edges(m);
        for (&(a, b), &count) in &directed {
            assert_ne!(a, b, "degenerate edge");
            assert_eq!(
                count, 1,
                "directed edge used {count} times: winding inconsistent"
            );
            assert!(
                directed.contains_key(&(b, a)),
                "edge without a twin: the shell is open"
            );
        }
    }

    fn outward_fraction(m: &Mesh) -> f32 {
        let c = m.bounds().center();
        let out = m
            .vertices
            .iter()
            .filter(|v| Vec3::from(v.normal).dot(Vec3::from(v.position) - c) > 0.0)
            .count();
        out as f32 / m.vertices.len() as f32
    }

    fn with_normals(mut m: Mesh) -> Mesh {
        m.compute_normals();
        m
    }

    #[test]
    fn every_shell_is_closed_with_consistent_winding() {
        assert_closed_and_consistent(&skull_shell());
        for ear in ears() {
            assert_closed_and_consistent(&ear_shell(&ear));
        }
        assert_closed_and_consistent(&head_mesh());
    }

    #[test]
    fn normals_point_outward() {
        assert!(outward_fraction(&with_normals(skull_shell())) > 0.99);
        for ear in ears() {
            assert!(outward_fraction(&with_normals(ear_shell(&ear))) > 0.99);
        }
        assert!(outward_fraction(&head_mesh()) > 0.85);
    }

    #[test]
    fn normals_are_unit_and_tangents_orthogonal() {
        let m = head_mesh();
        m.validate().unwrap();
        for v in &m.vertices {
            let n = Vec3::from(v.normal);
            let t = glam::Vec4::from(v.tangent);
            assert!((n.length() - 1.0).abs() < 1e-4);
            assert!((t.truncate().length() - 1.0).abs() < 1e-4);
            assert!(t.truncate().dot(n).abs() < 1e-4);
            assert!(t.w == 1.0 || t.w == -1.0);
        }
    }

    #[test]
    fn size_and_triangle_budget() {
        let m = head_mesh();
        let b = m.bounds();
        let height_mm = b.size().y * MM_PER_UNIT;
        assert!((height_mm - 230.0).abs() < 5.0, "{height_mm}");
        assert!(b.center().length() < 3.0, "head centre {:?}", b.center());
        // The nose makes +Z the longest reach from the centre.
        assert!(b.max.z > -b.min.z + 1.5);
        let tris = m.triangle_count();
        assert!((10_000..=30_000).contains(&tris), "{tris} triangles");
    }

    #[test]
    fn jaw_is_narrower_than_cranium() {
        let m = skull_shell();
        let width_at = |y0: f32| {
            m.vertices
                .iter()
                .filter(|v| (v.position[1] - y0).abs() < 0.5)
                .map(|v| v.position[0].abs())
                .fold(0.0f32, f32::max)
        };
        assert!(width_at(-8.0) < 0.8 * width_at(2.0));
    }

    /// Möller-Trumbore; returns every hit distance along the ray.
    fn ray_hits(m: &Mesh, origin: Vec3, dir: Vec3) -> Vec<f32> {
        let p = |i: u32| Vec3::from(m.vertices[i as usize].position);
        let mut hits = Vec::new();
        for t in m.indices.chunks_exact(3) {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let (e1, e2) = (b - a, c - a);
            let q = dir.cross(e2);
            let det = e1.dot(q);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = origin - a;
            let u = s.dot(q) / det;
            let r = s.cross(e1);
            let v = dir.dot(r) / det;
            let dist = e2.dot(r) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 {
                hits.push(dist);
            }
        }
        hits.sort_by(f32::total_cmp);
        // A ray through a shared vertex or edge hits several triangles at one point.
        hits.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
        hits
    }

    #[test]
    fn ears_are_thin_slabs_light_can_cross() {
        let head = head_mesh();
        for ear in ears() {
            let hits = ray_hits(&head, ear.center + ear.normal * 5.0, -ear.normal);
            assert!(hits.len() >= 2, "ray missed the ear: {hits:?}");
            let thickness_mm = (hits[1] - hits[0]) * MM_PER_UNIT;
            assert!(
                (2.0..=5.0).contains(&thickness_mm),
                "ear {thickness_mm} mm thick"
            );
            // The ear is attached: its front edge is inside the skull.
            let front_edge = ear.center
                + ear.normal.cross(Vec3::Y).normalize() * EAR_HALF_WIDTH * ear.normal.x.signum();
            assert!(front_edge.x.abs() < skull_half_width(EAR_Y, front_edge.z));
        }
    }

    #[test]
    fn backdrop_faces_the_head() {
        let b = backdrop_mesh();
        b.validate().unwrap();
        let p = |i: usize| Vec3::from(b.vertices[b.indices[i] as usize].position);
        let n = (p(1) - p(0)).cross(p(2) - p(0));
        assert!(n.z > 0.0);
        let placed = backdrop_behind(Vec3::new(1.0, 2.0, 3.0), Vec3::NEG_Z, 2.3);
        let pb = placed.bounds();
        assert!(
            (pb.center() - Vec3::new(1.0, 2.0, 5.5)).length() < 1e-3,
            "{pb:?}"
        );
        assert!((pb.size().x - 12.0).abs() < 1e-3);
        assert!(Vec3::from(placed.vertices[0].normal).dot(Vec3::NEG_Z) > 0.999);
    }
}
