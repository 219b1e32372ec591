//! The procedural face's wrinkle maps (thesis ch. 8), made by code: the
//! creases of the six expressions as one height field over the face, its
//! slopes written as a partial-derivative normal map in the mesh's own
//! tangent frames, and Table 8.1's eight zones as two masks
//! (`wrinkle_maps`).
//!
//! The maps are baked in the skull's UV parameterisation: u = (phi + pi) /
//! 2 pi, v = theta / pi (`face::skull_shell`), so each texel's surface point
//! is the skull's point on the core's ray for its angles (the face passes
//! its skull in: `face_wrinkle_maps`). The ears' UVs sit
//! in a corner no zone reaches (`face::EAR_UV`).
//!
//! Sizes follow the chapter's proportions (8.3: a 256 x 256 wrinkle map and
//! 64 x 64 masks over a face filling the map): the skull's map spends about a
//! quarter of its area on the face, so both are twice as fine, 512 and 128,
//! which puts about 0.9 mm of face under a wrinkle texel. The creases are
//! anatomical (the muscles the chapter's Figure 8.6 names: frontalis on the
//! forehead, corrugator between the brows, nasalis on the nose's bridge,
//! orbicularis at the eyes' corners, the nasolabial fold, mentalis on the
//! chin), their depths and widths tuned by eye on renders (0.25-0.7 mm deep,
//! 0.7-1.6 mm wide): every slope stays inside the encoding's 45-degree cone.

use glam::{Vec2, Vec3};

use super::face_surface::{in_parallel, Skull, SurfaceGrid};
use super::mesh::{Texture, WrinkleMaps};
use super::procedural::{plateau, smoothstep};
use super::wrinkle_maps::{encode, MASKS, ZONES_PER_MASK};

/// Texels a side of the wrinkle map and of the masks.
pub const WRINKLE_SIZE: u32 = 512;
pub const MASK_SIZE: u32 = 128;

/// The UV rectangle the maps are computed over (the face, with a margin):
/// outside it the wrinkle map is flat and the masks 0.
pub(super) const U_RANGE: (f32, f32) = (0.21, 0.79);
pub(super) const V_RANGE: (f32, f32) = (0.12, 0.62);

/// Half-width (mm) of the soft split between a zone's right and left halves.
const SPLIT_MM: f32 = 3.0;
/// Squared half-width (mm^2) of the rounding of |x| at the midline (as the
/// skull's field mirrors its features).
const MIRROR_ROUNDING_MM2: f32 = 4.0;

/// One crease: a groove `depth` mm deep and `sigma` mm wide (a Gaussian
/// across it) along a polyline in the face's (x, y) plane (mm), fading in
/// and out over its first and last fifth. `mirrored`: written for the right
/// side (+x) and mirrored.
struct Crease {
    points: Vec<[f32; 2]>,
    depth: f32,
    sigma: f32,
    mirrored: bool,
}

fn crease(points: &[[f32; 2]], depth: f32, sigma: f32, mirrored: bool) -> Crease {
    Crease {
        points: points.to_vec(),
        depth,
        sigma,
        mirrored,
    }
}

/// The outer corner of the right eye (mm, x and y).
const CANTHUS: [f32; 2] = [44.0, 1.0];

/// A crow's foot: a ray fanning out from the canthus, 5 to 20 mm from it,
/// `angle_deg` from the horizontal.
fn ray(angle_deg: f32) -> [[f32; 2]; 2] {
    let (s, c) = angle_deg.to_radians().sin_cos();
    [
        [CANTHUS[0] + 5.0 * c, CANTHUS[1] + 5.0 * s],
        [CANTHUS[0] + 20.0 * c, CANTHUS[1] + 20.0 * s],
    ]
}

/// The forehead's lines, drooping 4 mm toward the temples.
const fn forehead(y: f32) -> [[f32; 2]; 5] {
    [
        [-42.0, y - 4.4],
        [-21.0, y - 1.1],
        [0.0, y],
        [21.0, y - 1.1],
        [42.0, y - 4.4],
    ]
}
const FOREHEAD_0: [[f32; 2]; 5] = forehead(29.0);
const FOREHEAD_1: [[f32; 2]; 5] = forehead(36.0);
const FOREHEAD_2: [[f32; 2]; 5] = forehead(43.0);
const FOREHEAD_3: [[f32; 2]; 5] = forehead(50.0);
/// The nasolabial fold, from the nose's wing past the mouth's corner.
const NASOLABIAL: [[f32; 2]; 4] = [[15.0, -36.0], [22.0, -48.0], [27.0, -60.0], [29.0, -72.0]];
/// The mentolabial sulcus over the chin.
const MENTOLABIAL: [[f32; 2]; 3] = [[-14.0, -87.0], [0.0, -85.0], [14.0, -87.0]];

/// Every crease of the face (made once: the crow's feet need trigonometry).
static CREASES: std::sync::LazyLock<[Crease; 16]> = std::sync::LazyLock::new(|| {
    [
        crease(&FOREHEAD_0, 0.35, 1.0, false),
        crease(&FOREHEAD_1, 0.4, 1.0, false),
        crease(&FOREHEAD_2, 0.4, 1.0, false),
        crease(&FOREHEAD_3, 0.3, 1.0, false),
        // The corrugator's vertical lines between the brows.
        crease(&[[5.0, 3.0], [8.0, 20.0]], 0.45, 0.8, true),
        crease(&[[10.0, 6.0], [12.0, 16.0]], 0.25, 0.7, true),
        // The nasalis' lines across the bridge.
        crease(&[[-9.0, -6.0], [9.0, -6.0]], 0.25, 0.7, false),
        crease(&[[-10.0, -10.5], [10.0, -10.5]], 0.3, 0.7, false),
        crease(&[[-10.0, -15.0], [10.0, -15.0]], 0.25, 0.7, false),
        crease(&ray(-40.0), 0.3, 0.7, true),
        crease(&ray(-15.0), 0.35, 0.7, true),
        crease(&ray(10.0), 0.35, 0.7, true),
        crease(&ray(35.0), 0.3, 0.7, true),
        crease(&NASOLABIAL, 0.7, 1.6, true),
        crease(&MENTOLABIAL, 0.5, 1.3, false),
        // The lower lip's crease under the mouth's corners.
        crease(&[[20.0, -74.0], [24.0, -84.0]], 0.3, 1.0, true),
    ]
});

/// The mentalis' dimples: pits over the chin (mm).
const DIMPLE_DEPTH_MM: f32 = 0.15;
const DIMPLE_SIGMA_MM: f32 = 0.9;

fn dimples() -> impl Iterator<Item = Vec2> {
    (0..7).flat_map(|i| {
        (0..4).map(move |j| {
            // A fixed, irregular lattice (no two rows aligned).
            let jitter = ((i * 7 + j * 13) % 5) as f32 * 0.6 - 1.2;
            Vec2::new(
                -12.0 + 4.0 * i as f32 + jitter,
                -106.0 + 4.5 * j as f32 - 0.5 * jitter,
            )
        })
    })
}

/// The face's front: creases and zones fade in between these depths (mm),
/// so nothing reaches the back of the head.
pub(super) fn front(z: f32) -> f32 {
    smoothstep(20.0, 40.0, z)
}

/// Distance from `p` to the polyline and where along it (0..1 of its length).
fn polyline_distance(points: &[[f32; 2]], p: Vec2) -> (f32, f32) {
    // Squared distances first; one square root and the lengths for the nearest
    // segment alone (the maps ask this of 16 creases six times a texel).
    let (mut best, mut nearest) = (f32::MAX, (0, 0.0));
    for (k, w) in points.windows(2).enumerate() {
        let (a, b) = (Vec2::from(w[0]), Vec2::from(w[1]));
        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        let d2 = p.distance_squared(a + (b - a) * t);
        if d2 < best {
            (best, nearest) = (d2, (k, t));
        }
    }
    let lengths = points
        .windows(2)
        .map(|w| Vec2::from(w[0]).distance(Vec2::from(w[1])));
    let before: f32 = lengths.clone().take(nearest.0).sum();
    let total: f32 = lengths.clone().sum();
    let along = before + nearest.1 * lengths.clone().nth(nearest.0).unwrap_or(0.0);
    (best.sqrt(), along / total)
}

/// The wrinkles' height (mm, creases negative) at surface point `p` (mm).
pub fn height_mm(p: Vec3) -> f32 {
    let gate = front(p.z);
    if gate == 0.0 {
        return 0.0;
    }
    let mirrored = Vec2::new((p.x * p.x + MIRROR_ROUNDING_MM2).sqrt(), p.y);
    let plain = Vec2::new(p.x, p.y);
    let mut h = 0.0;
    for c in CREASES.iter() {
        let q = if c.mirrored { mirrored } else { plain };
        let (d, s) = polyline_distance(&c.points, q);
        if d > 4.0 * c.sigma {
            continue;
        }
        let taper = smoothstep(0.0, 0.2, s) * smoothstep(1.0, 0.8, s);
        h -= c.depth * taper * (-0.5 * (d / c.sigma).powi(2)).exp();
    }
    for k in dimples() {
        let d2 = plain.distance_squared(k);
        // Beyond six sigma a dimple is 1e-8 of its depth (and its exponential
        // underflows, which costs glibc an error path per call).
        if d2 > (6.0 * DIMPLE_SIGMA_MM).powi(2) {
            continue;
        }
        h -= DIMPLE_DEPTH_MM * (-0.5 * d2 / (DIMPLE_SIGMA_MM * DIMPLE_SIGMA_MM)).exp();
    }
    h * gate
}

/// Table 8.1's eight zones (`skin::wrinkles::ZONES`' order) at surface
/// point `p` (mm), each in [0, 1].
pub fn zones(p: Vec3) -> [f32; 8] {
    let gate = front(p.z);
    let ax = p.x.abs();
    let right = smoothstep(-SPLIT_MM, SPLIT_MM, p.x);
    let left = 1.0 - right;
    let q = Vec2::new(ax, p.y);
    // The eye's corner and the cheek's fold down to the mouth.
    let corner = 1.0 - smoothstep(12.0, 20.0, q.distance(Vec2::new(56.0, 0.0)));
    let fold = 1.0 - smoothstep(5.0, 10.0, polyline_distance(&NASOLABIAL, q).0);
    let cheek = corner.max(fold);
    let forehead = plateau(p.y, 25.0, 58.0, 4.0) * (1.0 - smoothstep(46.0, 56.0, ax));
    let glabella = plateau(p.y, 0.0, 21.0, 3.0) * (1.0 - smoothstep(13.0, 17.0, ax));
    let nose = plateau(p.y, -18.0, -3.0, 2.5) * (1.0 - smoothstep(11.0, 15.0, ax));
    let chin = plateau(p.y, -110.0, -81.0, 4.0) * (1.0 - smoothstep(20.0, 26.0, ax));
    [
        cheek * right,
        cheek * left,
        forehead * right,
        forehead * left,
        glabella * right,
        glabella * left,
        nose,
        chin,
    ]
    .map(|z| z * gate)
}

/// The partial-derivative normal of the height field at `p` (mm) in the
/// tangent frame the mesh gives a point whose surface moves by `du`, `dv`
/// (mm per UV unit): T along du (made perpendicular to the normal), B =
/// cross(N, T) turned toward dv (`Mesh::generate_tangents`' handedness).
/// A height field's normal is N minus its surface gradient g, so the
/// partial derivatives are (-g.T, -g.B).
fn partial_derivative(p: Vec3, du: Vec3, dv: Vec3) -> Vec2 {
    let n = du.cross(dv).normalize();
    // The skull's UVs run counter-clockwise seen from outside: n points out.
    let t = (du - n * n.dot(du)).normalize();
    let mut b = n.cross(t);
    if b.dot(dv) < 0.0 {
        b = -b;
    }
    const H: f32 = 0.05;
    let g3 = Vec3::new(
        height_mm(p + Vec3::X * H) - height_mm(p - Vec3::X * H),
        height_mm(p + Vec3::Y * H) - height_mm(p - Vec3::Y * H),
        height_mm(p + Vec3::Z * H) - height_mm(p - Vec3::Z * H),
    ) / (2.0 * H);
    let g = g3 - n * n.dot(g3);
    Vec2::new(-g.dot(t), -g.dot(b))
}

/// The face's maps over `skull` (`face::skull_point_mm`): a second of ray
/// marching in a test build, made once with the face.
pub fn face_wrinkle_maps(skull: Skull) -> WrinkleMaps {
    let n = WRINKLE_SIZE as usize;
    let at = |k: usize| (k as f32 + 0.5) / n as f32;
    let cols: Vec<usize> = (0..n)
        .filter(|&j| (U_RANGE.0..=U_RANGE.1).contains(&at(j)))
        .collect();
    let rows: Vec<usize> = (0..n)
        .filter(|&i| (V_RANGE.0..=V_RANGE.1).contains(&at(i)))
        .collect();
    // Surface points over the rectangle and one texel around it.
    let (j0, j1) = (cols[0] - 1, cols[cols.len() - 1] + 1);
    let (i0, i1) = (rows[0] - 1, rows[rows.len() - 1] + 1);
    let grid = SurfaceGrid::new(skull, n, (i0, i1), (j0, j1));
    let p = |i: usize, j: usize| grid.point(i, j);
    let mut wrinkle = vec![0u8; 4 * n * n];
    for px in wrinkle.chunks_exact_mut(4) {
        px.copy_from_slice(&[encode(0.0), encode(0.0), 0, 255]);
    }
    let mut zone_fine = vec![[0.0f32; 8]; n * n];
    let texels = in_parallel(&rows, |&i| {
        cols.iter()
            .map(|&j| {
                // Mm per UV unit along u and v, by central differences.
                let du = (p(i, j + 1) - p(i, j - 1)) * (0.5 * n as f32);
                let dv = (p(i + 1, j) - p(i - 1, j)) * (0.5 * n as f32);
                let q = p(i, j);
                (partial_derivative(q, du, dv), zones(q))
            })
            .collect::<Vec<_>>()
    });
    for (&i, row) in rows.iter().zip(&texels) {
        for (&j, (d, z)) in cols.iter().zip(row) {
            let k = i * n + j;
            wrinkle[4 * k] = encode(d.x);
            wrinkle[4 * k + 1] = encode(d.y);
            zone_fine[k] = *z;
        }
    }
    WrinkleMaps {
        wrinkle: Texture {
            width: WRINKLE_SIZE,
            height: WRINKLE_SIZE,
            rgba8: wrinkle,
        },
        masks: masks_from(&zone_fine, n, MASK_SIZE as usize),
    }
}

/// The masks at `size` texels a side, each texel the mean of the fine
/// grid's texels under it (`fine` is `n` a side, a multiple of `size`).
fn masks_from(fine: &[[f32; 8]], n: usize, size: usize) -> [Texture; MASKS] {
    let f = n / size;
    let mut out = [(); MASKS].map(|_| vec![0u8; 4 * size * size]);
    for y in 0..size {
        for x in 0..size {
            let mut sum = [0.0f32; 8];
            for dy in 0..f {
                for dx in 0..f {
                    for (s, v) in sum.iter_mut().zip(&fine[(y * f + dy) * n + x * f + dx]) {
                        *s += v;
                    }
                }
            }
            for (z, s) in sum.iter().enumerate() {
                let mean = s / (f * f) as f32;
                out[z / ZONES_PER_MASK][4 * (y * size + x) + z % ZONES_PER_MASK] =
                    (mean.clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        }
    }
    out.map(|rgba8| Texture {
        width: size as u32,
        height: size as u32,
        rgba8,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::wrinkle_maps::decode;

    #[test]
    fn each_zone_covers_its_feature_and_nothing_else() {
        // Points on the face's skin (mm): each inside its own zone only.
        let cases: [(Vec3, usize); 8] = [
            (Vec3::new(56.0, 0.0, 60.0), 0),
            (Vec3::new(-56.0, 0.0, 60.0), 1),
            (Vec3::new(20.0, 40.0, 80.0), 2),
            (Vec3::new(-20.0, 40.0, 80.0), 3),
            (Vec3::new(8.0, 10.0, 85.0), 4),
            (Vec3::new(-8.0, 10.0, 85.0), 5),
            (Vec3::new(0.0, -10.0, 90.0), 6),
            (Vec3::new(0.0, -95.0, 75.0), 7),
        ];
        for (p, zone) in cases {
            let z = zones(p);
            assert!(z[zone] > 0.99, "{p}: zone {zone} is {}", z[zone]);
            for (k, v) in z.iter().enumerate().filter(|&(k, _)| k != zone) {
                assert!(*v < 0.01, "{p}: zone {k} is {v} (zone {zone}'s point)");
            }
        }
        // The back of the head: nothing.
        assert_eq!(zones(Vec3::new(0.0, 40.0, -80.0)), [0.0; 8]);
        assert_eq!(height_mm(Vec3::new(0.0, 40.0, -80.0)), 0.0);
    }

    #[test]
    fn a_crease_is_a_groove_of_its_depth() {
        // The middle of the forehead's second line, against beside it.
        let on = height_mm(Vec3::new(0.0, 36.0, 85.0));
        let off = height_mm(Vec3::new(0.0, 39.5, 85.0));
        assert!((on + 0.4).abs() < 0.02, "{on}");
        assert!(off.abs() < 0.05, "{off}");
    }

    #[test]
    fn the_maps_hold_the_creases_inside_the_encoding() {
        let m = crate::scene::face::face_scene()
            .head
            .material
            .wrinkles
            .expect("the face has its wrinkle maps");
        m.check().unwrap();
        assert_eq!((m.wrinkle.width, m.masks[0].width), (512, 128));
        // Across the face some slopes are steep, none saturates the cone.
        let mut steepest = 0.0f32;
        let mut saturated = 0;
        for y in 0..m.wrinkle.height {
            for x in 0..m.wrinkle.width {
                let [a, b] = m.wrinkle_texel(x, y);
                steepest = steepest.max(a.abs()).max(b.abs());
                saturated += usize::from(a.abs() >= 1.0 || b.abs() >= 1.0);
            }
        }
        assert_eq!(saturated, 0);
        assert!(steepest > 0.2, "{steepest}");
        // The forehead's lines run across: below the forehead's middle the
        // slope is along v (B), not u (T).
        let (u, v) = (0.5, forehead_v(36.0 + 0.7));
        let (x, y) = ((u * 512.0) as u32, (v * 512.0) as u32);
        let [a, b] = m.wrinkle_texel(x, y);
        assert!(b.abs() > 4.0 * a.abs().max(2.0 / 255.0), "({a}, {b})");
        // Outside the face: flat, no zone.
        assert_eq!(m.wrinkle_texel(0, 0), [decode(128); 2]);
        assert!((0..8).all(|z| m.mask_texel(z, 0, 0) == 0.0));
        assert!(m.bytes() < 1_200_000, "{}", m.bytes());
    }

    /// The skull's surface point (mm) at UV `(u, v)`.
    fn surface_mm(skull: Skull, u: f32, v: f32) -> Vec3 {
        use std::f32::consts::{PI, TAU};
        skull(v * PI, u * TAU - PI)
    }

    /// The v of the skull's midline point at height `y` (mm).
    fn forehead_v(y: f32) -> f32 {
        let n = 4096;
        (0..n)
            .map(|k| (k as f32 + 0.5) / n as f32)
            .min_by(|&a, &b| {
                let skull = crate::scene::face::skull_point_mm;
                (surface_mm(skull, 0.5, a).y - y)
                    .abs()
                    .total_cmp(&(surface_mm(skull, 0.5, b).y - y).abs())
            })
            .unwrap()
    }
}
