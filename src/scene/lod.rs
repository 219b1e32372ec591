//! Levels of detail: a character's meshes simplified once (meshoptimizer's
//! edge collapse, `meshopt::simplify`) into index lists over the same
//! vertices, so a level draws from whatever vertex buffer the full mesh
//! does: the deform pass's morphed and skinned vertices carry to every level
//! with no work of their own. Each level knows its geometric error (object
//! units); a character takes the coarsest level whose error, projected at
//! its distance, stays under `--lod-pixels`. Pure: the frame uploads the
//! levels and picks one per character.

use glam::Vec3;

use super::mesh::Mesh;
use super::vertex::Vertex;

/// Fractions of the full mesh's triangles the levels aim at, after the full
/// mesh itself (level 0).
/// The coarsest, 1/64, is what a crowd's far rows take at a pixel of
/// error: an 80 000-triangle head a few dozen pixels tall.
pub const LEVEL_RATIOS: [f32; 6] = [0.5, 0.25, 0.125, 0.0625, 0.03125, 0.015625];

/// A level stops the chain when it saves less than this fraction of the
/// level before (the simplifier is stuck at locked borders).
const MIN_SAVING: f32 = 0.1;

/// One level: its triangles (indices into the full mesh's vertices) and the
/// largest distance (object units) its surface strays from the full one's.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub indices: Vec<u32>,
    pub error: f32,
}

/// The levels of `mesh`, the full mesh first (error 0). Borders are locked
/// (an open mesh's rim, and the seams where texture coordinates split a
/// vertex, keep their place, so no crack opens between levels or at a seam).
pub fn levels(mesh: &Mesh) -> Vec<Level> {
    let mut out = vec![Level {
        indices: mesh.indices.clone(),
        error: 0.0,
    }];
    if mesh.indices.is_empty() {
        return out;
    }
    let bytes: &[u8] = bytemuck::cast_slice(&mesh.vertices);
    let Ok(adapter) = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<Vertex>(), 0)
    else {
        return out;
    };
    // The simplifier's errors are relative to the mesh's extent.
    let scale = meshopt::simplify_scale(&adapter);
    let full = mesh.indices.len();
    for ratio in LEVEL_RATIOS {
        let target = ((full as f32 * ratio) as usize / 3).max(1) * 3;
        let mut error = 0.0f32;
        let indices = meshopt::simplify(
            &mesh.indices,
            &adapter,
            target,
            f32::MAX,
            meshopt::SimplifyOptions::LockBorder,
            Some(&mut error),
        );
        let before = out.last().map_or(full, |l| l.indices.len());
        if indices.is_empty() || indices.len() as f32 > before as f32 * (1.0 - MIN_SAVING) {
            break;
        }
        // The error a frame chooses by: the measured one (the simplifier's
        // is an estimate), never below the estimate.
        let measured = measured_error(mesh, &indices);
        out.push(Level {
            error: measured.max(error * scale),
            indices,
        });
    }
    out
}

/// Pixels a unit of object space covers at `distance` from a camera of
/// vertical field `fovy_rad` over `height_px` rows.
pub fn pixels_per_unit(distance: f32, fovy_rad: f32, height_px: u32) -> f32 {
    height_px as f32 / (2.0 * (0.5 * fovy_rad).tan() * distance.max(f32::MIN_POSITIVE))
}

/// The coarsest level whose error covers at most `max_pixels` at
/// `px_per_unit` (0 when `max_pixels` is 0: levels off).
pub fn choose(errors: &[f32], px_per_unit: f32, max_pixels: f32) -> usize {
    if max_pixels <= 0.0 {
        return 0;
    }
    errors
        .iter()
        .rposition(|&e| e * px_per_unit <= max_pixels)
        .unwrap_or(0)
}

/// The largest distance from a vertex of `mesh` to the surface of `level`:
/// the level's error as measured (the simplifier's own figure is a quadric
/// estimate, which on the face runs under this by up to 2.5x). Triangles are
/// binned in a grid by their boxes widened by a margin; a vertex farther than
/// the margin from every triangle in its cell doubles the margin and looks
/// again, so the answer is exact.
pub fn measured_error(mesh: &Mesh, level: &[u32]) -> f32 {
    let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
    // The vertices the full mesh draws (a mesh may hold others).
    let mut used = vec![false; mesh.vertices.len()];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    let drawn: Vec<Vec3> = mesh
        .vertices
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(v, _)| Vec3::from(v.position))
        .collect();
    let tris: Vec<[Vec3; 3]> = level
        .chunks_exact(3)
        .map(|t| [p(t[0]), p(t[1]), p(t[2])])
        .collect();
    if tris.is_empty() || mesh.vertices.is_empty() {
        return 0.0;
    }
    let b = mesh.bounds();
    let size = b.size().max_element().max(f32::MIN_POSITIVE);
    // About 32 cells across the mesh, the margin a tenth of a cell to start.
    let cell = size / 32.0;
    let mut margin = 0.1 * cell;
    let key = |q: Vec3| ((q - b.min) / cell).floor().as_ivec3();
    loop {
        if margin > 0.25 * size {
            break;
        }
        let mut grid: std::collections::HashMap<glam::IVec3, Vec<u32>> =
            std::collections::HashMap::new();
        for (i, t) in tris.iter().enumerate() {
            let lo = key(t[0].min(t[1]).min(t[2]) - Vec3::splat(margin));
            let hi = key(t[0].max(t[1]).max(t[2]) + Vec3::splat(margin));
            for x in lo.x..=hi.x {
                for y in lo.y..=hi.y {
                    for z in lo.z..=hi.z {
                        grid.entry(glam::IVec3::new(x, y, z))
                            .or_default()
                            .push(i as u32);
                    }
                }
            }
        }
        let mut worst = 0.0f32;
        let mut missed = false;
        for &q in &drawn {
            let d = grid
                .get(&key(q))
                .into_iter()
                .flatten()
                .map(|&i| point_triangle_distance(q, &tris[i as usize]))
                .fold(f32::MAX, f32::min);
            if d > margin {
                missed = true;
                break;
            }
            worst = worst.max(d);
        }
        if !missed {
            return worst;
        }
        margin *= 2.0;
    }
    // Far from everything (a level that lost a part): brute force, before
    // a grid of wide margins grows past its use.
    drawn
        .iter()
        .map(|&q| {
            tris.iter()
                .map(|t| point_triangle_distance(q, t))
                .fold(f32::MAX, f32::min)
        })
        .fold(0.0, f32::max)
}

/// Distance from `p` to triangle `t` (Ericson's closest point, 5.1.5).
fn point_triangle_distance(p: Vec3, [a, b, c]: &[Vec3; 3]) -> f32 {
    let (ab, ac, ap) = (*b - *a, *c - *a, p - *a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(*a);
    }
    let bp = p - *b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(*b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(*a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - *c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(*c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(*a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p.distance(*b + (*c - *b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(*a + ab * (vb * denom) + ac * (vc * denom))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::procedural::head_mesh;

    #[test]
    fn levels_halve_the_triangles_and_bound_their_error() {
        // A coarse head: the brute-force check stays quick.
        let mut mesh = head_mesh();
        mesh.indices = levels(&mesh)[2].indices.clone();
        let size = mesh.bounds().size().max_element();
        let lv = levels(&mesh);
        assert!(lv.len() >= 4, "{} levels", lv.len());
        for w in lv.windows(2) {
            assert!(w[1].indices.len() < w[0].indices.len());
            assert!(w[1].error >= w[0].error);
        }
        // A level's error is at least the distance from every full vertex
        // to its surface (brute force here), and the coarse levels stray by
        // more the fewer triangles they keep.
        for l in &lv[1..] {
            let brute = mesh
                .indices
                .iter()
                .map(|&i| &mesh.vertices[i as usize])
                .map(|v| {
                    l.indices
                        .chunks_exact(3)
                        .map(|t| {
                            let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
                            point_triangle_distance(
                                Vec3::from(v.position),
                                &[p(t[0]), p(t[1]), p(t[2])],
                            )
                        })
                        .fold(f32::MAX, f32::min)
                })
                .fold(0.0f32, f32::max);
            assert!(
                brute <= l.error,
                "measured {brute} over the level's {}",
                l.error
            );
        }
        // Half the triangles stray by a small fraction of the head.
        assert!(lv[1].error < 0.02 * size, "{} of {size}", lv[1].error);
        for l in &lv[1..] {
            assert!(l.error > 0.0);
        }
    }

    #[test]
    fn a_level_is_chosen_by_its_projected_error() {
        let errors = [0.0, 0.001, 0.004, 0.016];
        // 1000 px a unit: 0.001 is a pixel, 0.004 four.
        assert_eq!(choose(&errors, 1000.0, 1.0), 1);
        assert_eq!(choose(&errors, 1000.0, 4.0), 2);
        assert_eq!(choose(&errors, 10.0, 1.0), 3);
        assert_eq!(choose(&errors, 1e6, 1.0), 0);
        assert_eq!(choose(&errors, 10.0, 0.0), 0, "0 pixels: levels off");
        // A 1080-row view of 20 degrees at 10 units: 306 px a unit.
        let ppu = pixels_per_unit(10.0, 20f32.to_radians(), 1080);
        assert!((ppu - 1080.0 / (2.0 * 10f32.to_radians().tan() * 10.0)).abs() < 1e-3);
    }

    #[test]
    fn point_triangle_distances_are_the_closed_forms() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(point_triangle_distance(Vec3::new(0.2, 0.2, 3.0), &t), 3.0);
        assert_eq!(point_triangle_distance(Vec3::new(-1.0, 0.0, 0.0), &t), 1.0);
        let d = point_triangle_distance(Vec3::new(1.0, 1.0, 0.0), &t);
        assert!((d - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
    }
}
