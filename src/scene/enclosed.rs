//! Skin that no camera can see: triangles inside a closed part of the
//! character (the procedural face's eye sockets, behind its eyeballs). The
//! planner's per-frame skin estimate leaves them out, as the frame's depth
//! test does. Pure geometry, no GPU.

use glam::Vec3;

use super::mesh::{Aabb, Mesh};

/// Whether every edge of `mesh` (by vertex position) is shared by exactly two
/// triangles: a closed surface, whose inside is well defined.
pub fn is_closed(mesh: &Mesh) -> bool {
    use std::collections::HashMap;
    let key = |i: u32| mesh.vertices[i as usize].position.map(f32::to_bits);
    let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    for t in mesh.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (ka, kb) = (key(a), key(b));
            let e = if ka < kb { (ka, kb) } else { (kb, ka) };
            *edges.entry(e).or_insert(0) += 1;
        }
    }
    !edges.is_empty() && edges.values().all(|&n| n == 2)
}

/// Crossings of the ray from `o` along `d` with the triangles of `mesh`
/// (Moller-Trumbore, both faces).
fn crossings(mesh: &Mesh, o: Vec3, d: Vec3) -> usize {
    let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
    mesh.indices
        .chunks_exact(3)
        .filter(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let (e1, e2) = (b - a, c - a);
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-12 {
                return false;
            }
            let s = o - a;
            let u = s.dot(h) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && t > 0.0
        })
        .count()
}

/// For each triangle of `skin`, whether its centroid lies inside one of the
/// closed meshes of `parts` (an odd number of crossings along a ray; open
/// parts hide skin only from some views, and are left out).
pub fn enclosed_triangles(skin: &Mesh, parts: &[&Mesh]) -> Vec<bool> {
    let closed: Vec<(&Mesh, Aabb)> = parts
        .iter()
        .filter(|m| is_closed(m))
        .map(|m| (*m, m.bounds()))
        .collect();
    // A direction along no axis, so rays meet edges and vertices only by chance.
    let d = Vec3::new(1.0, 0.000_713, 0.001_31).normalize();
    let p = |i: u32| Vec3::from(skin.vertices[i as usize].position);
    skin.indices
        .chunks_exact(3)
        .map(|t| {
            let c = (p(t[0]) + p(t[1]) + p(t[2])) / 3.0;
            closed.iter().any(|(m, b)| {
                c.cmpge(b.min).all() && c.cmple(b.max).all() && crossings(m, c, d) % 2 == 1
            })
        })
        .collect()
}

/// `skin` without the triangles `enclosed_triangles` finds.
pub fn visible_skin(skin: &Mesh, parts: &[&Mesh]) -> Mesh {
    let hidden = enclosed_triangles(skin, parts);
    let mut out = skin.clone();
    out.indices = skin
        .indices
        .chunks_exact(3)
        .zip(&hidden)
        .filter(|(_, &h)| !h)
        .flat_map(|(t, _)| t.iter().copied())
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::eyes::eyeball_mesh;

    #[test]
    fn skin_inside_a_closed_part_is_hidden_and_outside_it_is_not() {
        let ball = eyeball_mesh(Vec3::ZERO, Vec3::Z, 1.0);
        assert!(is_closed(&ball));
        // Two small triangles: one at the ball's centre, one outside it.
        let tri = |c: Vec3| {
            [c, c + Vec3::X * 0.1, c + Vec3::Y * 0.1].map(|p| crate::scene::mesh::Vertex {
                position: p.into(),
                ..Default::default()
            })
        };
        let mut skin = Mesh::default();
        skin.vertices.extend(tri(Vec3::new(0.0, 0.0, 3.0)));
        skin.vertices.extend(tri(Vec3::new(0.0, 0.0, 20.0)));
        skin.indices = vec![0, 1, 2, 3, 4, 5];
        assert_eq!(enclosed_triangles(&skin, &[&ball]), [true, false]);
        assert_eq!(visible_skin(&skin, &[&ball]).indices, [3, 4, 5]);
        // An open part (half the ball) hides nothing.
        let mut open = ball.clone();
        open.indices.truncate(open.indices.len() / 2);
        assert!(!is_closed(&open));
        assert_eq!(enclosed_triangles(&skin, &[&open]), [false, false]);
    }
}

#[cfg(test)]
mod face_tests {
    #[test]
    fn the_faces_eye_sockets_are_hidden_behind_its_eyeballs() {
        let s = crate::scene::default_scene();
        let parts: Vec<&crate::scene::mesh::Mesh> = s.parts.iter().map(|p| &p.mesh).collect();
        let hidden = super::enclosed_triangles(&s.head.mesh, &parts);
        let n = hidden.iter().filter(|&&h| h).count();
        eprintln!("{n} of {} skin triangles inside the eyeballs", hidden.len());
        assert!(n > 100, "{n}");
    }
}
