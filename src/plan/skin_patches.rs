//! The planner's per-frame skin estimate: each character's skin pixels and
//! screen rectangle from a few thousand surface patches instead of the whole
//! mesh, so that re-planning every frame (issue 16 item 6) costs about 2 ms
//! of estimate for a 64-character crowd at 720p where the exact
//! rasterisation of [`super::character`] costs about 125 ms (76 k triangles a
//! head). Pure: no device.
//!
//! **Patches.** The skin mesh's triangles are binned once per scene by their
//! centroid into cubic cells, and within a cell by the dominant axis of their
//! normal (six bins, so that a cell on a silhouette keeps its front and back
//! apart). A patch holds its triangles' area-weighted centroid and their
//! vector area `sum(a n)`. Levels of cells 2, 4, ... 64 mm wide are kept; a
//! character uses the coarsest level whose cell spans at most
//! [`TARGET_CELL_PX`] pixels at its depth, so the work per character follows
//! its size on screen, not the mesh, and at most [`MAX_PATCHES`] patches.
//! A close-up shows a small part of the head: a character crossing the
//! frame's edge or near plane whose whole head would be held coarser by that
//! cap counts the patches of the blocks ([`BLOCK_MM`] cells, bounded by
//! spheres) in view, looks at those only, and is capped by their count.
//! (Held to the whole head's count, a face 0.5 head heights from a
//! 12-degree camera, about 11 x 6 mm of skin filling a 320x180 frame, took
//! 8 mm cells some 270 px wide, which cannot tile the frame: 40 207 of its
//! 57 600 pixels with the footprints clipped as below.)
//!
//! **Projected area.** A flat patch of vector area `A` at `p`, seen from the
//! eye at `e` by a pinhole of focal length `f` pixels, covers
//! `(A . (e - p)) f^2 / z^3` pixels, `z` its view depth: the solid angle
//! `A . v / |v|^3` times `f^2 / cos^3` of its angle off the axis, with
//! `cos = z / |v|`. Summed over the front-facing patches (`A . v > 0`) it is
//! the projected area of the front-facing skin, the count of pixel centres a
//! rasteriser finds, up to the pixel grid. A patch's footprint is a square
//! of that area about its centre, and it counts the part of it inside the
//! frame: a close-up's patches lie across the frame's edge with their
//! centres outside, or are larger than the frame. (Dropping the first and
//! counting the second whole, a face filling a 320x180 frame, 57 600
//! pixels, was counted at 61 602 one head height from the camera and at
//! 49 649 at 0.75.)
//!
//! **Occlusion.** One coarse buffer of the frame, [`OCCLUSION_TEXEL_PX`]
//! pixels a texel, holds the nearest patch and its character: every patch
//! splats its depth over the texels of its footprint (grown by
//! [`SPLAT_SIDE`], clipped to the frame), then a patch counts if the nearest
//! patch at its centre's texel (or the frame's texel nearest its centre) is
//! its own character's (a nearer character hides it) and no more than
//! [`SELF_DEPTH_CELLS`] cells in front of it. A face hiding part of itself
//! (the far side of the nose) is otherwise left to the facing test, which
//! catches most of it.
//!
//! `tests/suite/plan_motion.rs` measures the estimate against the exact
//! rasterisation on the crowds and distances of the plan checks.

use std::collections::HashMap;

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::scene::mesh::Mesh;

/// Cell widths of the levels, millimetres (finest first).
pub const LEVEL_CELLS_MM: [f32; 6] = [2.0, 4.0, 8.0, 16.0, 32.0, 64.0];

/// A character uses the coarsest level whose cell spans at most this many
/// pixels at its centre's depth (or the finest level).
pub const TARGET_CELL_PX: f32 = 12.0;

/// A patch is hidden by its own character's surface when the nearest patch
/// at its texel lies more than this many cells in front of it (the nose
/// before a cheek); nearer than that it is the same surface.
pub const SELF_DEPTH_CELLS: f32 = 2.0;

/// The most patches a character is estimated with (of the blocks in view,
/// for one crossing the frame's edge or near plane: see [`BLOCK_MM`]).
pub const MAX_PATCHES: usize = 6000;

/// A character whose visible skin is under this share of its facing skin on
/// screen counts as hidden: a sliver peeking past a nearer character is
/// below what the occlusion buffer resolves (a hidden character was counted
/// at 108 pixels where the exact count is 0), and a count that comes and goes
/// from frame to frame made the re-planned crowd give such a character a
/// setting and take it back every few frames (docs/plan-over-time.md).
pub const MIN_VISIBLE_SHARE: f64 = 0.05;

/// Pixels per side of a texel of the occlusion buffer.
pub const OCCLUSION_TEXEL_PX: u32 = 2;

/// An occluding patch covers a square this many times the side of its
/// projected area. Patches are not squares and their centroids are not evenly
/// spaced, so squares of their own area leave holes between them that let
/// hidden characters through (a 16-character crowd then counted 931-pixel
/// characters at 3 000); 1.5 closes them while a silhouette grows by only a
/// quarter of a patch (measured against the exact rasterisation, module doc).
pub const SPLAT_SIDE: f32 = 1.5;

/// Width of the blocks, mm: the cells of this level, bounded by a sphere, by
/// which a character crossing the frame's edge or near plane culls the
/// patches of the levels at most this wide (a close-up shows a small part of
/// the head, whose fine patches are few; a [`MAX_PATCHES`] count over the
/// whole head would take them coarser than the frame). One of
/// [`LEVEL_CELLS_MM`].
pub const BLOCK_MM: f32 = 16.0;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Patch {
    /// Area-weighted centroid, mesh units.
    centre: Vec3,
    /// Sum of its triangles' area times unit normal, mesh units squared.
    area: Vec3,
}

#[derive(Clone, Debug, PartialEq)]
struct Level {
    cell_units: f32,
    patches: Vec<Patch>,
    /// A level at most [`BLOCK_MM`] wide is grouped by block: block `b`'s
    /// patches are `patches[starts[b]..starts[b + 1]]`.
    starts: Option<Vec<usize>>,
}

/// A bounding sphere, mesh units.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sphere {
    centre: Vec3,
    radius: f32,
}

/// The skin of one mesh as patches at several cell widths.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinPatches {
    levels: Vec<Level>,
    /// The cells [`BLOCK_MM`] wide, bounding their triangles: a character
    /// crossing the frame's edge or near plane looks only at the patches of
    /// the blocks in view.
    blocks: Vec<Sphere>,
    /// Bounds of every triangle.
    bound: Sphere,
    /// Centre of the mesh's bounds, mesh units: where a character's depth is
    /// taken to choose its level.
    centre: Vec3,
}

/// One character's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchEstimate {
    /// Front-facing skin pixels not hidden by a nearer character.
    pub pixels: f64,
    /// Their screen rectangle `[x0, y0, x1, y1]` (half-open; zero when none).
    pub rect: [u32; 4],
    /// Patches looked at (the work done for it).
    pub patches: usize,
}

/// The camera of a frame as the estimate needs it.
#[derive(Clone, Copy, Debug)]
pub struct View {
    pub view_proj: Mat4,
    pub eye: Vec3,
    pub width: u32,
    pub height: u32,
    /// Focal length in pixels: `height / (2 tan(fovy / 2))`.
    pub focal_px: f32,
}

/// A triangle as the binning needs it: centroid, vector area, and the
/// corners of its bounds.
type Tri = (Vec3, Vec3, Vec3, Vec3);

impl SkinPatches {
    /// The patches of `mesh` (every triangle is skin), `mm_per_unit` converting
    /// the level widths.
    pub fn of(mesh: &Mesh, mm_per_unit: f32) -> SkinPatches {
        let pos = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
        let tris: Vec<Tri> = mesh
            .indices
            .chunks_exact(3)
            .filter_map(|t| {
                let (a, b, c) = (pos(t[0]), pos(t[1]), pos(t[2]));
                // Half the cross product: the vector area (area times normal).
                let area = 0.5 * (b - a).cross(c - a);
                (area.length_squared() > 0.0)
                    .then(|| ((a + b + c) / 3.0, area, a.min(b).min(c), a.max(b).max(c)))
            })
            .collect();
        let (lo, hi) = tris.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), t| (lo.min(t.0), hi.max(t.0)),
        );
        let centre = if lo.x.is_finite() {
            0.5 * (lo + hi)
        } else {
            Vec3::ZERO
        };
        let cell_of = |mm: f32| mm / mm_per_unit.max(f32::MIN_POSITIVE);
        // Blocks: cells BLOCK_MM wide (normal bins together), numbered in
        // the order of their cell.
        let block_cell = cell_of(BLOCK_MM);
        let block_key = |c: Vec3| {
            let q = ((c - lo) / block_cell).floor();
            (q.x as i32, q.y as i32, q.z as i32)
        };
        let mut keys: Vec<(i32, i32, i32)> = tris.iter().map(|t| block_key(t.0)).collect();
        keys.sort_unstable();
        keys.dedup();
        let ids: HashMap<(i32, i32, i32), u32> = keys
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, i as u32))
            .collect();
        let block_of: Vec<u32> = tris.iter().map(|t| ids[&block_key(t.0)]).collect();
        let sphere = |lo: Vec3, hi: Vec3| Sphere {
            centre: 0.5 * (lo + hi),
            radius: 0.5 * (hi - lo).length(),
        };
        let empty = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let mut extent = vec![empty; keys.len()];
        for (t, &b) in tris.iter().zip(&block_of) {
            let e = &mut extent[b as usize];
            *e = (e.0.min(t.2), e.1.max(t.3));
        }
        let all = extent
            .iter()
            .fold(empty, |a, e| (a.0.min(e.0), a.1.max(e.1)));
        let bound = if all.0.x.is_finite() {
            sphere(all.0, all.1)
        } else {
            Sphere {
                centre: Vec3::ZERO,
                radius: 0.0,
            }
        };
        let blocks = extent.iter().map(|e| sphere(e.0, e.1)).collect();
        let levels = LEVEL_CELLS_MM
            .iter()
            .map(|&mm| {
                let cell = cell_of(mm);
                let blocks = (mm <= BLOCK_MM).then_some((block_of.as_slice(), keys.len()));
                let (patches, starts) = bin(&tris, blocks, lo, cell);
                Level {
                    cell_units: cell,
                    patches,
                    starts,
                }
            })
            .collect();
        SkinPatches {
            levels,
            blocks,
            bound,
            centre,
        }
    }

    /// Patches at each level (finest first).
    pub fn level_sizes(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.patches.len()).collect()
    }

    /// The level a character whose mesh centre lies at view depth `depth`
    /// (mesh units, after its model matrix's scale `scale`) would use: the
    /// coarsest whose cell spans at most [`TARGET_CELL_PX`] (or the finest).
    fn fine_level(&self, depth: f32, scale: f32, focal_px: f32) -> usize {
        let px_per_unit = focal_px / depth.max(f32::MIN_POSITIVE);
        self.levels
            .iter()
            .rposition(|l| l.cell_units * scale * px_per_unit <= TARGET_CELL_PX)
            .unwrap_or(0)
    }

    /// The level it uses: `fine`, coarser still while it holds more than
    /// [`MAX_PATCHES`] in the blocks looked at (`None`: all; a close-up's
    /// patches are many pixels each already, but one that shows a small
    /// part of the head looks at that part only).
    fn capped_level(&self, fine: usize, blocks: Option<&[u32]>) -> usize {
        let count = |l: &Level| match (blocks, &l.starts) {
            (Some(b), Some(starts)) => b
                .iter()
                .map(|&b| starts[b as usize + 1] - starts[b as usize])
                .sum(),
            _ => l.patches.len(),
        };
        (fine..self.levels.len())
            .find(|&i| count(&self.levels[i]) <= MAX_PATCHES)
            .unwrap_or(self.levels.len() - 1)
    }

    /// The level a character drawn by `mvp` (model scale `scale`) uses, and
    /// the runs of its patches it looks at, left in `runs` (`in_view` is
    /// scratch); `None` when it lies wholly outside the view.
    fn patches_for(
        &self,
        mvp: &Mat4,
        scale: f32,
        focal_px: f32,
        in_view: &mut Vec<u32>,
        runs: &mut Vec<(usize, usize)>,
    ) -> Option<&Level> {
        let frustum = Frustum::of(mvp);
        let crossed = frustum.crossed(self.bound, ALL_PLANES)?;
        let c: Vec4 = *mvp * self.centre.extend(1.0);
        let fine = self.fine_level(c.w, scale, focal_px);
        let whole = self.capped_level(fine, None);
        // A character across the frame's edge or near plane, held coarser
        // than it would be by its patches off screen: the blocks in view of
        // the planes it crosses, and its level from their patches.
        let blocks = (whole > fine && crossed != 0).then(|| {
            in_view.clear();
            in_view.extend(
                (0..self.blocks.len() as u32)
                    .filter(|&b| frustum.crossed(self.blocks[b as usize], crossed).is_some()),
            );
            in_view.as_slice()
        });
        let level = &self.levels[match blocks {
            Some(_) => self.capped_level(fine, blocks),
            None => whole,
        }];
        runs.clear();
        match (blocks, &level.starts) {
            (Some(bs), Some(starts)) => {
                for &b in bs {
                    let (s, e) = (starts[b as usize], starts[b as usize + 1]);
                    match runs.last_mut() {
                        Some(r) if r.1 == s => r.1 = e,
                        _ => runs.push((s, e)),
                    }
                }
            }
            _ => runs.push((0, level.patches.len())),
        }
        Some(level)
    }

    /// Every instance's estimate in one frame.
    pub fn estimate(&self, instances: &[Mat4], v: &View) -> Vec<PatchEstimate> {
        let (w, h) = (v.width.max(1), v.height.max(1));
        let (wf, hf) = (w as f32, h as f32);
        let t = OCCLUSION_TEXEL_PX;
        let (gw, gh) = (w.div_ceil(t) as usize, h.div_ceil(t) as usize);
        let mut nearest = vec![(f32::INFINITY, u32::MAX); gw * gh];
        // Facing patches on screen: (character, the texel it is tested at,
        // the nearest its own character's surface there may lie without
        // hiding it, its footprint clipped to the frame).
        let mut seen: Vec<(u32, u32, f32, [f32; 4])> = Vec::new();
        let mut looked = vec![0usize; instances.len()];
        // Each character's facing skin on screen before occlusion.
        let mut facing_px = vec![0.0f64; instances.len()];
        let f2 = v.focal_px * v.focal_px;
        let ts = t as f32;
        // The blocks in view and the runs of patches looked at (reused).
        let mut in_view: Vec<u32> = Vec::new();
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for (k, m) in instances.iter().enumerate() {
            let det = Mat3::from_mat4(*m).determinant();
            if det.abs() <= f32::MIN_POSITIVE {
                continue;
            }
            // In the model's frame: a vector area A at p faces the eye e when
            // (cof(M) A) . (e - M p) = det(M) A . (M^-1 e - p) > 0, and it is
            // that many units squared times the distance.
            let eye = m.inverse().transform_point3(v.eye);
            let mvp = v.view_proj * *m;
            let scale = det.abs().cbrt();
            let Some(level) = self.patches_for(&mvp, scale, v.focal_px, &mut in_view, &mut runs)
            else {
                continue;
            };
            let cell = level.cell_units * scale;
            for &(s, e) in &runs {
                looked[k] += e - s;
                for p in &level.patches[s..e] {
                    let facing = det * p.area.dot(eye - p.centre);
                    if facing <= 0.0 {
                        continue;
                    }
                    let clip: Vec4 = mvp * p.centre.extend(1.0);
                    let z = clip.w;
                    if z <= 0.0 || clip.z < 0.0 || clip.z > z {
                        continue;
                    }
                    let x = (clip.x / z * 0.5 + 0.5) * wf;
                    let y = (clip.y / z * 0.5 + 0.5) * hf;
                    let projected = facing * f2 / (z * z * z);
                    // Its footprint, a square of its projected area, clipped
                    // to the frame: a close-up's patch can lie across the
                    // frame's edge with its centre outside, or be larger
                    // than the frame.
                    let half = 0.5 * projected.sqrt();
                    let foot = [
                        (x - half).max(0.0),
                        (y - half).max(0.0),
                        (x + half).min(wf),
                        (y + half).min(hf),
                    ];
                    if foot[2] <= foot[0] || foot[3] <= foot[1] {
                        continue;
                    }
                    // It is tested for occlusion at its centre, or the
                    // nearest point of the frame to it.
                    let (cx, cy) = (
                        ((x.clamp(foot[0], foot[2]) / ts) as usize).min(gw - 1),
                        ((y.clamp(foot[1], foot[3]) / ts) as usize).min(gh - 1),
                    );
                    // Splat over the texels whose centres lie in the patch's
                    // footprint grown to a square of side SPLAT_SIDE times
                    // the side of its projected area, and the texel it is
                    // tested at.
                    let r = SPLAT_SIDE * half / ts;
                    let at = (x / ts, y / ts);
                    splat(&mut nearest, (gw, gh), at, r, (cx, cy), (z, k as u32));
                    facing_px[k] += f64::from((foot[2] - foot[0]) * (foot[3] - foot[1]));
                    seen.push((
                        k as u32,
                        (cy * gw + cx) as u32,
                        z - SELF_DEPTH_CELLS * cell,
                        foot,
                    ));
                }
            }
        }
        let mut out: Vec<(f64, [f32; 4])> = vec![
            (
                0.0,
                [
                    f32::INFINITY,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                    f32::NEG_INFINITY
                ]
            );
            instances.len()
        ];
        for &(k, g, z_in_front, f) in &seen {
            let (near_z, owner) = nearest[g as usize];
            if owner != k || near_z < z_in_front {
                continue;
            }
            let o = &mut out[k as usize];
            o.0 += f64::from((f[2] - f[0]) * (f[3] - f[1]));
            o.1 = [
                o.1[0].min(f[0]),
                o.1[1].min(f[1]),
                o.1[2].max(f[2]),
                o.1[3].max(f[3]),
            ];
        }
        out.into_iter()
            .zip(looked)
            .zip(facing_px)
            .map(|(((pixels, r), patches), facing)| {
                // A character left with a sliver of its skin is at the
                // occlusion buffer's grain: counted as hidden (see
                // `MIN_VISIBLE_SHARE`).
                let pixels = if pixels < MIN_VISIBLE_SHARE * facing {
                    0.0
                } else {
                    pixels
                };
                PatchEstimate {
                    pixels,
                    rect: if pixels > 0.0 {
                        [
                            // The pixels whose centres fall inside.
                            r[0].round().clamp(0.0, wf) as u32,
                            r[1].round().clamp(0.0, hf) as u32,
                            r[2].round().clamp(0.0, wf) as u32,
                            r[3].round().clamp(0.0, hf) as u32,
                        ]
                    } else {
                        [0; 4]
                    },
                    patches,
                }
            })
            .collect()
    }
}

/// Writes the depth `z` of character `k` over the texels of `nearest` (`gw`
/// x `gh`) where it is nearer: those whose centres lie within `r` texels of
/// `(u, v)` each way (in texels), and the texel `(cx, cy)`.
fn splat(
    nearest: &mut [(f32, u32)],
    (gw, gh): (usize, usize),
    (u, v): (f32, f32),
    r: f32,
    (cx, cy): (usize, usize),
    (z, k): (f32, u32),
) {
    let first = |a: f32, n: usize| ((a - 0.5).ceil().max(0.0) as usize).min(n - 1);
    let last = |b: f32, n: usize| ((b - 0.5).floor().max(0.0) as usize).min(n - 1);
    let (x0, x1) = (first(u - r, gw).min(cx), last(u + r, gw).max(cx));
    let (y0, y1) = (first(v - r, gh).min(cy), last(v + r, gh).max(cy));
    for gy in y0..=y1 {
        for n in &mut nearest[gy * gw + x0..=gy * gw + x1] {
            if z < n.0 {
                *n = (z, k);
            }
        }
    }
}

/// Every plane of a [`Frustum`], as a mask.
const ALL_PLANES: u8 = 0b11_1111;

/// The planes of the clip volume (`-w <= x, y <= w`, `0 <= z <= w`) in a
/// model's frame, each scaled to a unit normal pointing in.
struct Frustum([Vec4; 6]);

impl Frustum {
    fn of(mvp: &Mat4) -> Frustum {
        let r = |i: usize| mvp.row(i);
        let planes = [
            r(3) + r(0),
            r(3) - r(0),
            r(3) + r(1),
            r(3) - r(1),
            r(2),
            r(3) - r(2),
        ]
        .map(|p| p / p.truncate().length().max(f32::MIN_POSITIVE));
        Frustum(planes)
    }

    /// Where `s` lies against the planes of the mask `planes`: `None`
    /// wholly outside one, else the mask of those it crosses (0: inside).
    fn crossed(&self, s: Sphere, planes: u8) -> Option<u8> {
        let mut crossed = 0;
        for (i, p) in self.0.iter().enumerate() {
            if planes & (1 << i) == 0 {
                continue;
            }
            let d = p.truncate().dot(s.centre) + p.w;
            if d < -s.radius {
                return None;
            }
            if d < s.radius {
                crossed |= 1 << i;
            }
        }
        Some(crossed)
    }
}

/// Triangles binned into cells of `cell` units (from `origin`) and by the
/// dominant axis of their normal; with `blocks` (each triangle's block, and
/// how many), within their block, the patches in block order and where each
/// block's start.
fn bin(
    tris: &[Tri],
    blocks: Option<(&[u32], usize)>,
    origin: Vec3,
    cell: f32,
) -> (Vec<Patch>, Option<Vec<usize>>) {
    // Per cell and normal bin: area-weighted centroid sum, area, vector area.
    type Key = (u32, i32, i32, i32, u8);
    let mut cells: HashMap<Key, (Vec3, f32, Vec3)> = HashMap::new();
    for (i, &(c, a, _, _)) in tris.iter().enumerate() {
        let block = blocks.map_or(0, |(b, _)| b[i]);
        let q = ((c - origin) / cell).floor();
        let n = a.abs();
        let axis = if n.x >= n.y && n.x >= n.z {
            0
        } else if n.y >= n.z {
            1
        } else {
            2
        };
        let sign = u8::from(a[axis] < 0.0);
        let key = (
            block,
            q.x as i32,
            q.y as i32,
            q.z as i32,
            2 * axis as u8 + sign,
        );
        let e = cells.entry(key).or_insert((Vec3::ZERO, 0.0, Vec3::ZERO));
        let w = a.length();
        e.0 += w * c;
        e.1 += w;
        e.2 += a;
    }
    let mut out: Vec<(_, Patch)> = cells
        .into_iter()
        .map(|(k, (sum, w, area))| {
            (
                k,
                Patch {
                    centre: sum / w,
                    area,
                },
            )
        })
        .collect();
    // A fixed order, so that a frame's estimate does not depend on hashing,
    // and each block's patches together.
    out.sort_by_key(|(k, _)| *k);
    let starts = blocks.map(|(_, n)| {
        let mut starts = vec![0usize; n + 1];
        for (k, _) in &out {
            starts[k.0 as usize + 1] += 1;
        }
        for b in 0..n {
            starts[b + 1] += starts[b];
        }
        starts
    });
    (out.into_iter().map(|(_, p)| p).collect(), starts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::Vertex;

    fn vertex(p: Vec3) -> Vertex {
        Vertex {
            position: p.into(),
            normal: [0.0, 0.0, 1.0],
            uv: [0.0, 0.0],
            tangent: [1.0, 0.0, 0.0, 1.0],
        }
    }

    /// A square of side `side` in the z = 0 plane facing +z, split into
    /// `n` x `n` quads.
    fn square(side: f32, n: u32) -> Mesh {
        let mut vertices = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let s = side / n as f32;
                vertices.push(vertex(Vec3::new(
                    -0.5 * side + i as f32 * s,
                    -0.5 * side + j as f32 * s,
                    0.0,
                )));
            }
        }
        let mut indices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = j * (n + 1) + i;
                indices.extend([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]);
            }
        }
        Mesh { vertices, indices }
    }

    fn camera_at(z: f32, fovy_deg: f32, w: u32, h: u32) -> View {
        let cam = crate::scene::camera::Camera {
            eye: Vec3::new(0.0, 0.0, z),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_rad: fovy_deg.to_radians(),
            near: 0.1,
            far: 100.0,
        };
        View {
            view_proj: cam.view_proj(w as f32 / h as f32),
            eye: cam.eye,
            width: w,
            height: h,
            focal_px: h as f32 / (2.0 * (0.5 * cam.fovy_rad).tan()),
        }
    }

    #[test]
    fn a_square_facing_the_camera_covers_its_projected_area() {
        // Side 2 at distance 5 with a 90 degree view of 400 rows: f = 200 px,
        // the square spans 2 x 200 / 5 = 80 px a side, 6400 pixels. The patch
        // formula is exact for a plane seen head-on at its centre's depth.
        let mesh = square(2.0, 20);
        let p = SkinPatches::of(&mesh, 1.0);
        let v = camera_at(5.0, 90.0, 400, 400);
        let e = p.estimate(&[Mat4::IDENTITY], &v)[0];
        assert!((e.pixels - 6400.0).abs() < 0.1, "{e:?}");
        assert_eq!(e.rect, [160, 160, 240, 240], "{e:?}");
        // Turned away it has no front-facing skin.
        let away = Mat4::from_rotation_y(std::f32::consts::PI);
        assert_eq!(p.estimate(&[away], &v)[0].pixels, 0.0);
    }

    #[test]
    fn a_tilted_square_covers_its_foreshortened_area() {
        // Turned 60 degrees about y: half the area faces the camera, and a
        // plane off-centre in depth is still within a few percent of it.
        let mesh = square(1.0, 40);
        let p = SkinPatches::of(&mesh, 0.05);
        let v = camera_at(10.0, 30.0, 600, 600);
        let f = v.focal_px;
        let tilt = Mat4::from_rotation_y(60f32.to_radians());
        let e = p.estimate(&[tilt], &v)[0];
        let want = 0.5 * f64::from(f * f / 100.0);
        assert!(
            (e.pixels / want - 1.0).abs() < 0.01,
            "{} vs {want}",
            e.pixels
        );
    }

    #[test]
    fn a_nearer_character_hides_the_one_behind() {
        // The same square twice on the axis, the second twice as far: it is
        // a quarter the size and wholly behind the first.
        let mesh = square(2.0, 40);
        let p = SkinPatches::of(&mesh, 0.05);
        let v = camera_at(5.0, 90.0, 400, 400);
        let behind = Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0));
        let e = p.estimate(&[Mat4::IDENTITY, behind], &v);
        assert!((e[0].pixels - 6400.0).abs() < 1.0, "{e:?}");
        assert_eq!(e[1].pixels, 0.0, "{e:?}");
        // Moved aside it shows whole: 40 x 40 pixels.
        let aside = Mat4::from_translation(Vec3::new(5.0, 0.0, -5.0));
        let e = p.estimate(&[Mat4::IDENTITY, aside], &v);
        assert!((e[1].pixels / 1600.0 - 1.0).abs() < 0.01, "{e:?}");
    }

    #[test]
    fn levels_follow_the_characters_size_on_screen() {
        let mesh = square(2.0, 64);
        let p = SkinPatches::of(&mesh, 10.0);
        let sizes = p.level_sizes();
        assert!(sizes.windows(2).all(|w| w[0] >= w[1]), "{sizes:?}");
        let v = camera_at(5.0, 90.0, 400, 400);
        let near = p.estimate(&[Mat4::IDENTITY], &v)[0];
        let far = p.estimate(&[Mat4::from_translation(Vec3::new(0.0, 0.0, -95.0))], &v)[0];
        assert!(far.patches < near.patches, "{near:?} {far:?}");
        // Far away it is still its projected area: 2 x 200 / 100 = 4 px a side.
        assert!((far.pixels - 16.0).abs() < 0.5, "{far:?}");
    }

    #[test]
    fn a_square_larger_than_the_frame_counts_the_frame_it_covers() {
        // Side 4 at distance 1 with a 90 degree view of 400 rows (f = 200 px):
        // 800 px a side, one patch, moved 1.5 aside so that its centre
        // projects at x = 500, off the frame. It covers x 100 to 400 of it,
        // all its rows: 300 x 400 pixels.
        let p = SkinPatches::of(&square(4.0, 4), 0.5);
        assert_eq!(p.level_sizes()[0], 1);
        let v = camera_at(1.0, 90.0, 400, 400);
        let aside = Mat4::from_translation(Vec3::new(1.5, 0.0, 0.0));
        let e = p.estimate(&[aside], &v)[0];
        assert!((e.pixels - 120_000.0).abs() < 1.0, "{e:?}");
        assert_eq!(e.rect, [100, 0, 400, 400], "{e:?}");
        // It hides a square behind it in its footprint: side 2 at 6 from the
        // eye, 67 px a side around x = 217, seen alone.
        let behind =
            Mat4::from_translation(Vec3::new(0.5, 0.0, -5.0)) * Mat4::from_scale(Vec3::splat(0.5));
        let alone = p.estimate(&[behind], &v)[0];
        assert!(
            (alone.pixels / (400.0f64 / 6.0).powi(2) - 1.0).abs() < 0.01,
            "{alone:?}"
        );
        let e = p.estimate(&[aside, behind], &v);
        assert!((e[0].pixels - 120_000.0).abs() < 1.0, "{e:?}");
        assert_eq!(e[1].pixels, 0.0, "{e:?}");
    }

    #[test]
    fn a_close_up_takes_its_level_from_the_patches_in_view() {
        // Side 2 with 0.02-unit cells at the finest level (10 000 patches,
        // over MAX_PATCHES: the whole square would take the next, 2 500),
        // seen from 0.2 with a 90 degree view of 400 rows: a cell spans 20
        // px and the frame shows 0.4 x 0.4 units of it, 400 cells. The
        // level is the finest, from the blocks in view only, and the frame
        // is covered.
        let p = SkinPatches::of(&square(2.0, 200), 100.0);
        let sizes = p.level_sizes();
        assert!(
            sizes[0] > MAX_PATCHES && sizes[1] <= MAX_PATCHES,
            "{sizes:?}"
        );
        let v = camera_at(0.2, 90.0, 400, 400);
        let e = p.estimate(&[Mat4::IDENTITY], &v)[0];
        assert!(e.patches >= 400 && e.patches < sizes[1], "{e:?} {sizes:?}");
        assert!((e.pixels / 160_000.0 - 1.0).abs() < 0.01, "{e:?}");
        assert_eq!(e.rect, [0, 0, 400, 400], "{e:?}");
    }
}
