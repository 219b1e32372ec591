//! Texture-space diffusion (d'Eon and Luebke's pipeline as seed 004 walks it,
//! Jimenez's thesis ch. 3, Gosselin et al.'s seed 002): the pure parts, so the
//! GPU passes of `method::tsd` can be held to them.
//!
//! - the chain of Gaussians: six of Table 4.2's fit, each blurring the previous
//!   one by the difference of variances (the first blurs the irradiance map by
//!   its own variance), accumulated with eq. 4.8's blend factors;
//! - the texture-space atlas: the unwrap the maps are rendered in (the mesh's
//!   own UVs when they do not overlap, else its UV islands packed apart);
//! - the stretch map: texels per millimetre along the map's axes, per triangle;
//! - the optimisations' geometry: eq. 3.1-3.2 (depth-sized map), eq. 3.3-3.4
//!   (clip planes), the 105 degree cull of section 3.2, the z pre-passes'
//!   0.3-biased backface test and object-level frustum and distance culling,
//!   and the refresh schedule of far characters.
//!
//! The CPU mirrors of its passes (which texels each optimisation keeps, the
//! convolution chain) are in [`super::tsd_mirror`].
//!
//! Seams: a tap that lands on a texel nobody wrote reads coverage 0 and so
//! adds nothing to either the sum or its weight; dividing by the weight keeps
//! only written texels in the average. That is Gosselin's own variant of his
//! dilation ("only samples that were written could be included in the filter
//! average"), applied by every convolution and by the final bilinear look-up.

use glam::{Mat4, Vec3, Vec4};

use super::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};
use super::ssg::{blend_weights, GaussianFit};
use crate::scene::mesh::{Aabb, Mesh};
use crate::view::{tan_half, ViewScale};

/// cos(105 degrees): the thesis' cull angle (Listing 3.2). A texel whose
/// interpolated eye-dot is below it is culled.
pub const CULL_COS: f32 = -0.258_819_04;
/// Gosselin's bias of the backface z pre-pass: kept while `N.V + 0.3 >= 0`.
pub const BACKFACE_BIAS: f32 = 0.3;
/// The thesis' reference distance for a 2048 map (section 3.3), in its units
/// (a head about one unit tall), at its 1920x1200 frame and 20 degree field of view.
pub const THESIS_D_REF: f32 = 4.5;
/// A human head, chin to crown (what one thesis unit stands for).
pub const HEAD_MM: f32 = 230.0;
/// The frame the thesis measured Table 3.1 at.
pub const THESIS_HEIGHT_PX: f32 = 1200.0;
pub const THESIS_FOVY_DEG: f32 = 20.0;
pub const THESIS_T_MAX: u32 = 2048;
/// Smallest depth-sized map side.
pub const MIN_MAP: u32 = 8;
/// A tap never reads the texel past the map's last one: bilinear weights are
/// quantised (8 bits on every device dermis met), and a weight-0 texel that
/// holds a NaN from memory nobody wrote would still poison the sum. So the
/// largest tap coordinate stops this fraction of a texel short of the last centre.
pub const EDGE_GUARD_TEXELS: f32 = 1.0 / 512.0;

/// One Gaussian of the texture-space chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TsdGaussian {
    /// 1..=6, as in Table 4.2.
    pub index: usize,
    /// Standard deviation this step adds (mm): `sqrt(v_i - v_{i-1})`, `v_0 = 0`.
    pub std_mm: f32,
    /// Blend factor `w'_i` of eq. 4.8 (1 for the first: it overwrites).
    pub blend: [f32; 3],
    /// The fit's weight `w_i`.
    pub weight: [f32; 3],
}

/// The six Gaussians of d'Eon's fit as the chain applies them: twelve
/// separable passes, the first blurring the irradiance map itself.
pub fn tsd_gaussians() -> Vec<TsdGaussian> {
    let v = SIX_GAUSSIAN_VARIANCES_MM2;
    let blend = blend_weights(GaussianFit::Six);
    (0..v.len())
        .map(|i| TsdGaussian {
            index: i + 1,
            std_mm: (v[i] - if i == 0 { 0.0 } else { v[i - 1] }).sqrt(),
            blend: blend[i],
            weight: SIX_GAUSSIAN_WEIGHTS_RGB[i],
        })
        .collect()
}

// --- Depth-sized maps (eq. 3.1-3.2) ---------------------------------------------------

/// Eq. 3.1: `s = min(d_ref / d, 1)` (1 for a camera inside or on the box).
pub fn depth_scale(d_ref: f32, d: f32) -> f32 {
    if d <= 0.0 || !d.is_finite() {
        return 1.0;
    }
    (d_ref / d).clamp(0.0, 1.0)
}

/// Eq. 3.2: `T = s T_max`, rounded to whole texels, at least [`MIN_MAP`].
pub fn map_size(s: f32, t_max: u32) -> u32 {
    ((s * t_max as f32).round() as u32).clamp(MIN_MAP.min(t_max), t_max)
}

/// The distance from `eye` to the nearest of the eight corners of `b` (Figure 3.3).
pub fn nearest_corner_distance(eye: Vec3, b: &Aabb) -> f32 {
    corners(b)
        .iter()
        .map(|c| c.distance(eye))
        .fold(f32::INFINITY, f32::min)
}

fn corners(b: &Aabb) -> [Vec3; 8] {
    let (l, h) = (b.min, b.max);
    [
        Vec3::new(l.x, l.y, l.z),
        Vec3::new(h.x, l.y, l.z),
        Vec3::new(l.x, h.y, l.z),
        Vec3::new(h.x, h.y, l.z),
        Vec3::new(l.x, l.y, h.z),
        Vec3::new(h.x, l.y, h.z),
        Vec3::new(l.x, h.y, h.z),
        Vec3::new(h.x, h.y, h.z),
    ]
}

/// `d_ref` in scene units for this view. The thesis' 4.5 units hold for its
/// 1920x1200 frame, 20 degree field of view and 2048 maps; the distance at
/// which a map of `t_max` texels has the thesis' texels per pixel grows with
/// the frame height and shrinks with the field of view and with `t_max`.
pub fn reference_distance(
    d_ref_thesis: f32,
    mm_per_unit: f32,
    height_px: u32,
    fovy_rad: f32,
    t_max: u32,
) -> f32 {
    let unit = HEAD_MM / mm_per_unit;
    let view = (height_px as f32 / THESIS_HEIGHT_PX)
        * (tan_half(THESIS_FOVY_DEG.to_radians()) / tan_half(fovy_rad));
    d_ref_thesis * unit * view * (THESIS_T_MAX as f32 / t_max as f32)
}

// --- Clipped maps (eq. 3.3-3.4) and object culling ------------------------------------

/// The six frustum planes of eq. 3.3 moved to world space by eq. 3.4 with the
/// view included (`Pi_world = (P V)^T Pi_clip`), so a vertex's clip distance
/// is one dot product with its world position. Vulkan's clip volume is
/// `-w <= x, y <= w` and `0 <= z <= w`: the near plane is `(0, 0, 1, 0)`
/// rather than OpenGL's `(0, 0, 1, 1)`.
pub fn clip_planes(view_proj: Mat4) -> [Vec4; 6] {
    let clip = [
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::new(-1.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::new(0.0, -1.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, 0.0),
        Vec4::new(0.0, 0.0, -1.0, 1.0),
    ];
    let t = view_proj.transpose();
    clip.map(|p| t * p)
}

/// Planes that clip nothing (clipping off): every distance is 1.
pub const NO_CLIP: [Vec4; 6] = [Vec4::W; 6];

/// Whether the box lies wholly outside one of the planes (the engine's
/// object-level frustum cull, Gosselin's frustum pre-pass).
pub fn box_outside(planes: &[Vec4; 6], b: &Aabb) -> bool {
    let cs = corners(b);
    planes
        .iter()
        .any(|p| cs.iter().all(|c| p.dot(c.extend(1.0)) < 0.0))
}

/// Projected height in pixels of something `size` units tall at distance `d`.
pub fn projected_px(size: f32, d: f32, height_px: u32, fovy_rad: f32) -> f32 {
    // A projected length needs no millimetres: any scale gives the same pixels.
    ViewScale::new(height_px, fovy_rad, 1.0).projected_px(size, d)
}

/// Whether far character `k` is refreshed on `frame` (0-based): once every
/// `period` frames, staggered so that each frame refreshes about `1/period` of
/// them. Its map is then at most `period - 1` frames old.
pub fn refreshes(frame: u64, k: usize, period: u32) -> bool {
    period <= 1 || (frame + k as u64) % period as u64 == 0
}

// --- The atlas ------------------------------------------------------------------------

/// Fraction of overlapping UV coverage above which the mesh's own UVs cannot
/// hold per-texel irradiance and its islands are packed apart.
pub const MAX_OVERLAP: f32 = 0.01;
/// Gap between packed islands, in millimetres of surface: more than the widest
/// Gaussian's reach (3 sigma of sqrt(7.41) mm = 8.2 mm), so no blur crosses.
pub const GUTTER_MM: f32 = 10.0;

/// The unwrap the texture-space maps use: per island a uniform scale and an
/// offset (`atlas = uv * scale + offset`), so a shader maps the material UV
/// into the atlas from the vertex's island alone.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    /// Per vertex, in [0, 1]^2.
    pub uv: Vec<[f32; 2]>,
    /// Per vertex, its island's index into `transforms` (0 when not repacked).
    pub island_of: Vec<u32>,
    /// Per island `[scale, offset u, offset v]` (one identity entry when not repacked).
    pub transforms: Vec<[f32; 3]>,
    /// Whether the islands were packed apart (the mesh's UVs overlap).
    pub repacked: bool,
    /// Overlapping fraction of the mesh's own UV coverage.
    pub overlap: f32,
    /// Number of islands (connected groups of triangles).
    pub islands: usize,
}

/// Signed double area of a UV triangle.
pub(crate) fn cross2(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> f32 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Texel centres of a `size` x `size` grid strictly inside each triangle, as
/// (texel index, triangle) pairs (points on an edge belong to no triangle, so
/// a shared edge is never counted twice).
fn strict_cover(uv: &[[f32; 2]], indices: &[u32], size: u32) -> Vec<(usize, usize)> {
    let n = size as f32;
    let mut out = Vec::new();
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [0, 1, 2].map(|i| uv[tri[i] as usize]);
        let area = cross2(a, b, c);
        if area == 0.0 {
            continue;
        }
        let (x0, x1) = span(a[0], b[0], c[0], size);
        let (y0, y1) = span(a[1], b[1], c[1], size);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = [(x as f32 + 0.5) / n, (y as f32 + 0.5) / n];
                let w = [cross2(b, c, p), cross2(c, a, p), cross2(a, b, p)];
                if w.iter().all(|&e| e * area.signum() > 0.0) {
                    out.push((y as usize * size as usize + x as usize, t));
                }
            }
        }
    }
    out
}

/// Texel range (half-open) whose centres may fall within `[min, max]` of three coordinates.
pub(crate) fn span(a: f32, b: f32, c: f32, size: u32) -> (u32, u32) {
    let n = size as f32;
    let lo = (a.min(b).min(c) * n - 0.5).floor().max(0.0) as u32;
    let hi = ((a.max(b).max(c) * n - 0.5).ceil() + 1.0).clamp(0.0, n) as u32;
    (lo.min(size), hi)
}

/// Fraction of the texels covered by the UV triangles (on a `grid`^2 grid)
/// that more than one triangle covers.
pub fn uv_overlap(uv: &[[f32; 2]], indices: &[u32], grid: u32) -> f32 {
    let mut count = vec![0u16; (grid * grid) as usize];
    for (i, _) in strict_cover(uv, indices, grid) {
        count[i] = count[i].saturating_add(1);
    }
    let covered = count.iter().filter(|&&c| c > 0).count();
    let twice = count.iter().filter(|&&c| c > 1).count();
    if covered == 0 {
        0.0
    } else {
        twice as f32 / covered as f32
    }
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Triangles grouped into islands (connected through shared vertex indices).
fn islands(mesh: &Mesh) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..mesh.vertices.len()).collect();
    for tri in mesh.indices.chunks_exact(3) {
        let a = find(&mut parent, tri[0] as usize);
        for &v in &tri[1..] {
            let b = find(&mut parent, v as usize);
            parent[b] = a;
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
        let r = find(&mut parent, tri[0] as usize);
        groups.entry(r).or_default().push(t);
    }
    groups.into_values().collect()
}

/// The atlas of `mesh`: its own UVs when they lie in [0, 1]^2 and overlap by
/// at most [`MAX_OVERLAP`] (a scan's unwrap), else its islands packed apart
/// on shelves, each scaled to the same texels per millimetre of surface, with
/// [`GUTTER_MM`] between them (the procedural heads: skull and ears each span
/// the whole square). An island that overlaps itself stays overlapped.
pub fn atlas(mesh: &Mesh, mm_per_unit: f32) -> Atlas {
    let uv: Vec<[f32; 2]> = mesh.vertices.iter().map(|v| v.uv).collect();
    let overlap = uv_overlap(&uv, &mesh.indices, 256);
    let inside = uv.iter().all(|t| t.iter().all(|c| (0.0..=1.0).contains(c)));
    let groups = islands(mesh);
    if overlap <= MAX_OVERLAP && inside {
        return Atlas {
            island_of: vec![0; uv.len()],
            uv,
            transforms: vec![[1.0, 0.0, 0.0]],
            repacked: false,
            overlap,
            islands: groups.len(),
        };
    }
    struct Island {
        tris: Vec<usize>,
        min: [f32; 2],
        scale: f32,
        size: [f32; 2],
        at: [f32; 2],
    }
    let pos = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
    let mut isl: Vec<Island> = groups
        .into_iter()
        .map(|tris| {
            let (mut min, mut max) = ([f32::MAX; 2], [f32::MIN; 2]);
            let (mut a3, mut a2) = (0.0f64, 0.0f64);
            for &t in &tris {
                let ix = &mesh.indices[3 * t..3 * t + 3];
                for &i in ix {
                    for c in 0..2 {
                        min[c] = min[c].min(uv[i as usize][c]);
                        max[c] = max[c].max(uv[i as usize][c]);
                    }
                }
                let (p0, p1, p2) = (pos(ix[0]), pos(ix[1]), pos(ix[2]));
                a3 += 0.5 * (p1 - p0).cross(p2 - p0).length() as f64;
                let t2 = [ix[0], ix[1], ix[2]].map(|i| uv[i as usize]);
                a2 += 0.5 * cross2(t2[0], t2[1], t2[2]).abs() as f64;
            }
            // Scene units of surface per UV unit, so every island gets the same
            // texel density.
            let scale = if a2 > 0.0 && a3 > 0.0 {
                (a3 / a2).sqrt() as f32
            } else {
                1.0
            };
            let size = [(max[0] - min[0]) * scale, (max[1] - min[1]) * scale];
            Island {
                tris,
                min,
                scale,
                size,
                at: [0.0; 2],
            }
        })
        .collect();
    let gutter = GUTTER_MM / mm_per_unit;
    // Shelf packing, tallest first, into a width near the square root of the
    // padded area; the atlas is the bounding square.
    let area: f32 = isl
        .iter()
        .map(|i| (i.size[0] + gutter) * (i.size[1] + gutter))
        .sum();
    let widest = isl.iter().map(|i| i.size[0] + gutter).fold(0.0, f32::max);
    let width = area.sqrt().max(widest);
    let mut order: Vec<usize> = (0..isl.len()).collect();
    order.sort_by(|&a, &b| isl[b].size[1].total_cmp(&isl[a].size[1]));
    let (mut x, mut y, mut shelf) = (gutter, gutter, 0.0f32);
    for &k in &order {
        let i = &mut isl[k];
        if x + i.size[0] + gutter > width + gutter && x > gutter {
            x = gutter;
            y += shelf + gutter;
            shelf = 0.0;
        }
        i.at = [x, y];
        x += i.size[0] + gutter;
        shelf = shelf.max(i.size[1]);
    }
    let extent = isl
        .iter()
        .map(|i| (i.at[0] + i.size[0]).max(i.at[1] + i.size[1]))
        .fold(0.0, f32::max)
        + gutter;
    let transforms: Vec<[f32; 3]> = isl
        .iter()
        .map(|i| {
            [
                i.scale / extent,
                (i.at[0] - i.min[0] * i.scale) / extent,
                (i.at[1] - i.min[1] * i.scale) / extent,
            ]
        })
        .collect();
    let mut island_of = vec![0u32; uv.len()];
    for (k, i) in isl.iter().enumerate() {
        for &t in &i.tris {
            for &v in &mesh.indices[3 * t..3 * t + 3] {
                island_of[v as usize] = k as u32;
            }
        }
    }
    let out = uv
        .iter()
        .zip(&island_of)
        .map(|(s, &k)| apply(transforms[k as usize], *s))
        .collect();
    Atlas {
        uv: out,
        island_of,
        transforms,
        repacked: true,
        overlap,
        islands: isl.len(),
    }
}

/// An island's transform applied to a material UV (as the shaders do it).
pub fn apply(t: [f32; 3], uv: [f32; 2]) -> [f32; 2] {
    [uv[0] * t[0] + t[1], uv[1] * t[0] + t[2]]
}

// --- The stretch map ------------------------------------------------------------------

/// Texels per millimetre along the map's x and y inside a triangle with world
/// positions `p` (scene units) and atlas coordinates `uv`, on a map whose UV
/// square spans `size_px` texels: `1 / |dP/dx|` with `x` in texels, as the
/// stretch pass computes it from the world position's derivatives.
pub fn triangle_stretch(
    p: [Vec3; 3],
    uv: [[f32; 2]; 3],
    size_px: f32,
    mm_per_unit: f32,
) -> [f32; 2] {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (du1, dv1) = (
        (uv[1][0] - uv[0][0]) * size_px,
        (uv[1][1] - uv[0][1]) * size_px,
    );
    let (du2, dv2) = (
        (uv[2][0] - uv[0][0]) * size_px,
        (uv[2][1] - uv[0][1]) * size_px,
    );
    let det = du1 * dv2 - du2 * dv1;
    if det == 0.0 {
        return [0.0; 2];
    }
    // [e1 e2] = [dP/dx dP/dy] [[du1 du2] [dv1 dv2]]
    let dpdx = (e1 * dv2 - e2 * dv1) / det;
    let dpdy = (e2 * du1 - e1 * du2) / det;
    [
        1.0 / (dpdx.length() * mm_per_unit).max(1e-4),
        1.0 / (dpdy.length() * mm_per_unit).max(1e-4),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::Vertex;

    #[test]
    fn six_gaussians_add_up_to_the_fit() {
        let g = tsd_gaussians();
        assert_eq!(g.len(), 6);
        assert!((g[0].std_mm - 0.08).abs() < 1e-6);
        let mut v = 0.0;
        for (i, gi) in g.iter().enumerate() {
            v += gi.std_mm * gi.std_mm;
            assert!((v - SIX_GAUSSIAN_VARIANCES_MM2[i]).abs() < 1e-5);
        }
        assert_eq!(g[0].blend, [1.0; 3]);
        assert!((g[1].blend[0] - 0.3).abs() < 2e-3, "{:?}", g[1].blend);
    }

    // Eq. 3.1-3.2: full size up to d_ref, then shrinking as 1/d; the thesis'
    // numbers at its own frame.
    #[test]
    fn depth_sized_maps_follow_eq_3_1_and_3_2() {
        assert_eq!(depth_scale(4.5, 2.0), 1.0);
        assert!((depth_scale(4.5, 9.0) - 0.5).abs() < 1e-6);
        assert_eq!(map_size(0.5, 2048), 1024);
        assert_eq!(map_size(1e-6, 2048), MIN_MAP);
        assert_eq!(map_size(1.0, 64), 64);
        let d = reference_distance(4.5, 10.0, 1200, 20f32.to_radians(), 2048);
        assert!((d - 4.5 * 23.0).abs() < 1e-3, "{d}");
        // Half the frame height: the same texel density is reached at half the distance.
        let h = reference_distance(4.5, 10.0, 600, 20f32.to_radians(), 2048);
        assert!((h - d / 2.0).abs() < 1e-3);
        let b = Aabb {
            min: Vec3::new(-1.0, -1.0, -1.0),
            max: Vec3::new(1.0, 1.0, 1.0),
        };
        let e = Vec3::new(0.0, 0.0, 11.0);
        assert!((nearest_corner_distance(e, &b) - (1.0f32 + 1.0 + 100.0).sqrt()).abs() < 1e-5);
    }

    // Eq. 3.4: a point's distance to each plane is its clip-space inequality.
    #[test]
    fn clip_planes_match_the_clip_volume() {
        let cam = crate::scene::camera::Camera::framing(Vec3::ZERO, Vec3::Z, 1.0, 3.0, 20.0);
        let vp = cam.view_proj(1.5);
        let planes = clip_planes(vp);
        for p in [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 0.5),
            Vec3::new(0.1, 0.1, 2.9),
            Vec3::new(0.0, 0.0, -30.0),
        ] {
            let c = vp * p.extend(1.0);
            let inside = c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w;
            let by_planes = planes.iter().all(|pl| pl.dot(p.extend(1.0)) >= 0.0);
            assert_eq!(inside, by_planes, "{p}");
        }
        let far_box = Aabb {
            min: Vec3::new(50.0, -1.0, -1.0),
            max: Vec3::new(52.0, 1.0, 1.0),
        };
        assert!(box_outside(&planes, &far_box));
        let near_box = Aabb {
            min: Vec3::splat(-0.5),
            max: Vec3::splat(0.5),
        };
        assert!(!box_outside(&planes, &near_box));
        assert!(!box_outside(&NO_CLIP, &far_box));
    }

    #[test]
    fn far_characters_refresh_once_per_period_staggered() {
        for k in 0..5 {
            let n = (0..12).filter(|&f| refreshes(f, k, 4)).count();
            assert_eq!(n, 3);
        }
        assert!((0..4).all(|f| refreshes(f, 0, 1)));
        // Four characters, period 4: one refresh per frame.
        for f in 0..8 {
            assert_eq!((0..4).filter(|&k| refreshes(f, k, 4)).count(), 1);
        }
    }

    fn quad(uv: [[f32; 2]; 4], z: f32, first: u32) -> (Vec<Vertex>, Vec<u32>) {
        let p = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let v = (0..4)
            .map(|i| Vertex {
                position: [p[i][0], p[i][1], z],
                normal: [0.0, 0.0, 1.0],
                uv: uv[i],
                tangent: [1.0, 0.0, 0.0, 1.0],
            })
            .collect();
        (
            v,
            vec![first, first + 1, first + 2, first, first + 2, first + 3],
        )
    }

    // Two islands on the same UV square overlap completely: they are packed
    // apart, at the same density, with the gutter between them.
    #[test]
    fn overlapping_islands_are_packed_apart() {
        let full = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let (mut v, mut i) = quad(full, 0.0, 0);
        let (v2, i2) = quad(full, 5.0, 4);
        v.extend(v2);
        i.extend(i2);
        let mesh = Mesh {
            vertices: v,
            indices: i,
        };
        assert!(
            uv_overlap(
                &mesh.vertices.iter().map(|v| v.uv).collect::<Vec<_>>(),
                &mesh.indices,
                64
            ) > 0.99
        );
        let a = atlas(&mesh, 1.0);
        assert!(a.repacked);
        assert_eq!(a.islands, 2);
        assert!(uv_overlap(&a.uv, &mesh.indices, 256) == 0.0);
        assert!(a
            .uv
            .iter()
            .all(|t| t.iter().all(|c| (0.0..=1.0).contains(c))));
        // Same size (same surface area), apart by at least the gutter.
        let w0 = a.uv[1][0] - a.uv[0][0];
        let w1 = a.uv[5][0] - a.uv[4][0];
        assert!((w0 - w1).abs() < 1e-6);
        let gap = (a.uv[4][0] - a.uv[1][0]).max(a.uv[4][1] - a.uv[3][1]);
        assert!(gap * (1.0 / w0) >= GUTTER_MM - 1e-3, "{gap}");
        // One island alone keeps its UVs.
        let (v, i) = quad(full, 0.0, 0);
        let single = atlas(
            &Mesh {
                vertices: v,
                indices: i,
            },
            1.0,
        );
        assert!(!single.repacked);
        assert_eq!(single.uv[2], [1.0, 1.0]);
    }

    // The stretch of a 100 x 50 mm rectangle mapped onto the unit square.
    #[test]
    fn stretch_is_texels_per_millimetre() {
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(10.0, 5.0, 0.0),
        ];
        let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
        let s = triangle_stretch(p, uv, 256.0, 10.0);
        assert!((s[0] - 2.56).abs() < 1e-4, "{s:?}");
        assert!((s[1] - 5.12).abs() < 1e-4, "{s:?}");
    }
}
