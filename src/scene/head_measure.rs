//! Anatomical measurements of a head mesh: which way the face looks and where the chin and
//! crown are. The subsurface passes work in millimetres, so the scene's scale comes from
//! the chin-to-crown height (a human head is ~230 mm); scans often carry a neck and
//! shoulders, which is why the plain vertical extent is not good enough.

//!
//! Every measurement ignores far outlier vertices (`robust_bounds`: one flipped
//! exponent bit puts a vertex at 1e31, and the plain bounding box then frames a
//! universe with the head as one invisible point). A flat object (a card, a sheet)
//! has no face or chin: it is framed along its thin axis, its largest extent facing
//! the camera.

use super::mesh::{Aabb, Mesh};
use super::robust_bounds::robust_bounds;
use glam::Vec3;

/// Human chin-to-crown height in millimetres, used to derive `mm_per_unit`.
pub const HEAD_HEIGHT_MM: f32 = 230.0;

/// A mesh whose smallest extent is below this fraction of its largest is flat:
/// a head is never thinner than half its height, a card or a sheet is.
pub const FLAT_RATIO: f32 = 0.1;

/// Bounds of the mesh without its far outlier vertices, and how many were left
/// out (the plain bounds, and 0, when there is nothing to judge by).
pub fn inlier_bounds(mesh: &Mesh) -> (Aabb, usize) {
    match robust_bounds(mesh.vertices.iter().map(|v| Vec3::from(v.position))) {
        Some(r) => (r.aabb, r.ignored),
        None => (mesh.bounds(), 0),
    }
}

/// Whether `p` lies inside `b` (the inliers of `inlier_bounds`).
fn inside(b: &Aabb, p: Vec3) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

/// For a flat mesh, the unit axis it is thin along, pointing to the side its
/// triangles face (area-weighted normals; +axis when they cancel); `None` for
/// a solid.
pub fn flat_axis(mesh: &Mesh) -> Option<Vec3> {
    flat_axis_within(mesh, &inlier_bounds(mesh).0)
}

/// [`flat_axis`] of the mesh's inliers `b` (`inlier_bounds`, which sorts every
/// coordinate: measured once by the callers that ask several questions).
fn flat_axis_within(mesh: &Mesh, b: &Aabb) -> Option<Vec3> {
    let size = b.size();
    let largest = size.max_element();
    if !(largest > 0.0 && largest.is_finite()) || size.min_element() >= FLAT_RATIO * largest {
        return None;
    }
    let axis = if size.x <= size.y && size.x <= size.z {
        Vec3::X
    } else if size.y <= size.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    let mut facing = 0.0f64;
    for tri in mesh.indices.chunks_exact(3) {
        let Some(p) = triangle_within(mesh, tri, b) else {
            continue;
        };
        facing += f64::from((p[1] - p[0]).cross(p[2] - p[0]).dot(axis));
    }
    Some(if facing < 0.0 { -axis } else { axis })
}

/// Where the camera frames a head: the centre and height (scene units) of the
/// part from the chin up; for a flat mesh, its centre and largest extent.
///
/// Remembered by the mesh's contents (the last `REMEMBERED` meshes asked
/// about): framing asks it of one head every frame and for every view of a
/// crowd, and the measure walks every triangle of the head (milliseconds a
/// call on the built-in face in a test build), where the key reads each
/// coordinate and index once.
pub fn framed_part(mesh: &Mesh, forward: Vec3) -> (Vec3, f32) {
    use std::sync::Mutex;
    static MEMO: Mutex<Vec<(u64, (Vec3, f32))>> = Mutex::new(Vec::new());
    let key = contents_key(mesh, forward);
    let hit = MEMO
        .lock()
        .ok()
        .and_then(|m| m.iter().find(|(k, _)| *k == key).map(|e| e.1));
    if let Some(hit) = hit {
        return hit;
    }
    let measured = measure_framed_part(mesh, forward);
    if let Ok(mut m) = MEMO.lock() {
        if m.len() >= REMEMBERED {
            m.remove(0);
        }
        m.push((key, measured));
    }
    measured
}

/// How many meshes' framing `framed_part` remembers.
const REMEMBERED: usize = 8;

/// A 64-bit key of every bit of the mesh's positions and indices and of
/// `forward` (a multiply-rotate hash over 32-bit words, two lanes): two
/// meshes that differ anywhere get different keys but for a 2^-64 chance.
fn contents_key(mesh: &Mesh, forward: Vec3) -> u64 {
    let (mut a, mut b) = (0x243f_6a88_85a3_08d3u64, 0x1319_8a2e_0370_7344u64);
    let mut eat = |w: u32| {
        a = (a ^ u64::from(w))
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            .rotate_left(29);
        b = (b.rotate_left(17) ^ u64::from(w)).wrapping_mul(0xff51_afd7_ed55_8ccd);
    };
    for v in &mesh.vertices {
        v.position.iter().for_each(|c| eat(c.to_bits()));
    }
    eat(mesh.vertices.len() as u32);
    mesh.indices.iter().for_each(|&i| eat(i));
    eat(mesh.indices.len() as u32);
    forward.to_array().iter().for_each(|c| eat(c.to_bits()));
    a ^ b.rotate_left(32)
}

/// [`framed_part`], measured.
fn measure_framed_part(mesh: &Mesh, forward: Vec3) -> (Vec3, f32) {
    let (b, _) = inlier_bounds(mesh);
    if flat_axis_within(mesh, &b).is_some() {
        return (b.center(), b.size().max_element());
    }
    let (chin, crown) = chin_and_crown_within(mesh, forward, &b);
    (part_above(mesh, chin, &b).center(), crown - chin)
}

/// A triangle's corners when all three are vertices of the mesh inside `b`.
fn triangle_within(mesh: &Mesh, tri: &[u32], b: &Aabb) -> Option<[Vec3; 3]> {
    let ids = [tri[0], tri[1], tri[2]].map(|i| i as usize);
    if ids.iter().any(|&i| i >= mesh.vertices.len()) {
        return None;
    }
    let p = ids.map(|i| Vec3::from(mesh.vertices[i].position));
    p.iter().all(|&q| inside(b, q)).then_some(p)
}

/// Unit horizontal vector from the head's centre toward its face. Y is taken as up (glTF's
/// convention). The nose is the narrowest protrusion of a head: for each horizontal axis
/// direction, the vertices within 5% of the size of the mesh from its extreme plane are
/// collected and their sideways spread measured; the face is the direction whose extreme
/// is narrowest (the back of the skull, the shoulders, and the side of the skull are all
/// broad). Falls back to +Z, the glTF "front", for empty meshes. A flat mesh
/// faces along its thin axis (`flat_axis`), so its largest extent faces the
/// camera instead of its edge. Far outlier vertices are ignored.
pub fn face_direction(mesh: &Mesh) -> Vec3 {
    if let Some(axis) = flat_axis(mesh) {
        return axis;
    }
    let (bounds, _) = inlier_bounds(mesh);
    let delta = 0.05 * bounds.size().max_element();
    if mesh.vertices.is_empty() || delta <= 0.0 || !delta.is_finite() {
        return Vec3::Z;
    }
    let inliers: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .filter(|&p| inside(&bounds, p))
        .collect();
    let candidates = [Vec3::Z, Vec3::NEG_Z, Vec3::X, Vec3::NEG_X];
    let mut best = (f32::INFINITY, Vec3::Z);
    for dir in candidates {
        let side = dir.cross(Vec3::Y);
        let extreme = inliers
            .iter()
            .map(|p| p.dot(dir))
            .fold(f32::NEG_INFINITY, f32::max);
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for &p in &inliers {
            if p.dot(dir) >= extreme - delta {
                let s = p.dot(side);
                lo = lo.min(s);
                hi = hi.max(s);
            }
        }
        let spread = hi - lo;
        if spread < best.0 {
            best = (spread, dir);
        }
    }
    best.1
}

/// Chin and crown heights (Y) of a head looking along `forward`.
///
/// The front profile F(y) (most forward point of the triangles crossing each horizontal
/// slice) peaks at the nose
/// tip. Going down from there, the chin ends where the profile falls below 30% of the way
/// from the median profile value below the nose (the front of the neck) to the nose: the
/// underside of the chin is where the profile retreats fastest, and 30% lands at its
/// bottom (the menton) on the Lee Perry-Smith scan. A mesh whose bottom narrows to a
/// point (no neck, like the procedural head) has its chin at its lowest point.
pub fn chin_and_crown(mesh: &Mesh, forward: Vec3) -> (f32, f32) {
    chin_and_crown_within(mesh, forward, &inlier_bounds(mesh).0)
}

/// [`chin_and_crown`] of the mesh's inliers `b`.
fn chin_and_crown_within(mesh: &Mesh, forward: Vec3, b: &Aabb) -> (f32, f32) {
    let (bottom, crown) = (b.min.y, b.max.y);
    let extent = crown - bottom;
    if mesh.vertices.is_empty() || extent <= 0.0 || !extent.is_finite() {
        return (bottom, crown);
    }
    // A mesh that narrows to a point at the bottom was not cut through a neck: its
    // lowest point is the chin. Cut necks and busts end in a broad ring or cap.
    let band: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .filter(|&p| inside(b, p) && p.y <= bottom + 0.02 * extent)
        .collect();
    if let Some(bb) = Aabb::from_points(band) {
        let base = bb.size().x.max(bb.size().z);
        if base < 0.25 * b.size().x.max(b.size().z) {
            return (bottom, crown);
        }
    }
    const SLICES: usize = 200;
    // Triangles, not vertices, fill the slices: a slice between two vertex rings must
    // still see the surface crossing it, or other parts (ears) would speak for it.
    let mut front = [f32::NEG_INFINITY; SLICES];
    let slice_of = |y: f32| ((((y - bottom) / extent) * SLICES as f32) as usize).min(SLICES - 1);
    for tri in mesh.indices.chunks_exact(3) {
        let Some(p) = triangle_within(mesh, tri, b) else {
            continue;
        };
        let (lo, hi) = (
            p.iter().map(|p| p.y).fold(f32::INFINITY, f32::min),
            p.iter().map(|p| p.y).fold(f32::NEG_INFINITY, f32::max),
        );
        for (i, f) in front
            .iter_mut()
            .enumerate()
            .take(slice_of(hi) + 1)
            .skip(slice_of(lo))
        {
            let y0 = bottom + i as f32 / SLICES as f32 * extent;
            let y1 = y0 + extent / SLICES as f32;
            // The triangle's farthest reach within the slice is at a vertex inside it or
            // where an edge crosses the slice's top or bottom.
            for k in 0..3 {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                if (y0..=y1).contains(&a.y) {
                    *f = f.max(a.dot(forward));
                }
                for y in [y0, y1] {
                    if (a.y - y) * (b.y - y) < 0.0 {
                        let t = (y - a.y) / (b.y - a.y);
                        *f = f.max(a.lerp(b, t).dot(forward));
                    }
                }
            }
        }
    }
    let slice_y = |i: usize| bottom + (i as f32 + 0.5) / SLICES as f32 * extent;
    let Some(nose) = (0..SLICES).max_by(|&a, &b| front[a].total_cmp(&front[b])) else {
        return (bottom, crown);
    };
    // The typical profile below the nose: mostly neck and chest on a bust, which a
    // minimum would not be (the cut edge at the bottom of a bust reaches far back).
    let mut below: Vec<f32> = front[..=nose]
        .iter()
        .copied()
        .filter(|f| f.is_finite())
        .collect();
    below.sort_by(f32::total_cmp);
    let neck_front = below[below.len() / 2];
    let threshold = neck_front + 0.3 * (front[nose] - neck_front);
    let mut chin = nose;
    for i in (0..nose).rev() {
        if !front[i].is_finite() {
            continue; // an empty slice says nothing
        }
        if front[i] < threshold {
            break;
        }
        chin = i;
    }
    (slice_y(chin) - 0.5 / SLICES as f32 * extent, crown)
}

/// Bounds of the inliers (`b`) at or above `chin`.
fn part_above(mesh: &Mesh, chin: f32, b: &Aabb) -> Aabb {
    Aabb::from_points(
        mesh.vertices
            .iter()
            .map(|v| Vec3::from(v.position))
            .filter(|&p| inside(b, p) && p.y >= chin),
    )
    .unwrap_or(*b)
}

#[cfg(test)]
mod tests {
    use super::super::mesh::Vertex;
    use super::super::procedural;
    use super::*;
    use glam::Mat4;

    #[test]
    fn procedural_head_faces_plus_z_and_rotations_follow() {
        let head = procedural::head_mesh();
        assert_eq!(face_direction(&head), Vec3::Z);
        for (angle, expect) in [
            (std::f32::consts::PI, Vec3::NEG_Z),
            (std::f32::consts::FRAC_PI_2, Vec3::X),
            (-std::f32::consts::FRAC_PI_2, Vec3::NEG_X),
        ] {
            let mut m = head.clone();
            m.transform(&Mat4::from_rotation_y(angle));
            let got = face_direction(&m);
            assert!((got - expect).length() < 1e-4, "{angle}: {got}");
        }
    }

    // The remembered answer is the mesh's own: a mesh moved by one vertex or
    // as a whole is measured again, and asked again it answers the same.
    #[test]
    fn framing_is_remembered_by_the_meshs_contents() {
        let head = procedural::head_mesh();
        let first = framed_part(&head, Vec3::Z);
        assert_eq!(framed_part(&head, Vec3::Z), first);
        assert_eq!(first, measure_framed_part(&head, Vec3::Z));
        let mut moved = head.clone();
        moved.transform(&Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)));
        let (c, h) = framed_part(&moved, Vec3::Z);
        assert!((c.y - first.0.y - 2.0).abs() < 1e-4 && (h - first.1).abs() < 1e-4);
        let mut crown = head.clone();
        let top = crown
            .vertices
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.position[1].total_cmp(&b.1.position[1]))
            .map(|(k, _)| k)
            .unwrap();
        crown.vertices[top].position[1] += 0.01;
        assert!(framed_part(&crown, Vec3::Z).1 > first.1);
        assert_ne!(contents_key(&head, Vec3::Z), contents_key(&head, Vec3::X));
    }

    #[test]
    fn head_without_neck_measures_its_full_height() {
        let head = procedural::head_mesh();
        let (chin, crown) = chin_and_crown(&head, Vec3::Z);
        let b = head.bounds();
        assert_eq!((chin, crown), (b.min.y, b.max.y));
    }

    #[test]
    fn neck_and_shoulders_below_the_chin_are_excluded() {
        let mut m = procedural::head_mesh();
        let chin = m.bounds().min.y;
        // A neck tube and broad shoulders below it, as scans have.
        let base = m.vertices.len() as u32;
        const RING: u32 = 16;
        for k in 0..60 {
            let y = chin + 1.0 - k as f32 * 0.25;
            let (r, depth) = if k < 30 { (5.0, 0.6) } else { (18.0, 0.25) };
            for a in 0..RING {
                let t = a as f32 / RING as f32 * std::f32::consts::TAU;
                m.vertices.push(Vertex {
                    position: [r * t.cos(), y, depth * r * t.sin()],
                    ..Default::default()
                });
            }
        }
        for k in 0..59 {
            for a in 0..RING {
                let at = |k: u32, a: u32| base + k * RING + a % RING;
                m.indices.extend([at(k, a), at(k + 1, a), at(k + 1, a + 1)]);
            }
        }
        let (got, crown) = chin_and_crown(&m, Vec3::Z);
        assert!(
            (got - chin).abs() < 0.15 * (crown - chin),
            "chin {got} vs {chin}"
        );
        assert!(m.bounds().min.y < chin - 10.0);
    }
}
