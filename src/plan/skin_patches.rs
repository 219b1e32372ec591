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
//! its size on screen, not the mesh.
//!
//! **Projected area.** A flat patch of vector area `A` at `p`, seen from the
//! eye at `e` by a pinhole of focal length `f` pixels, covers
//! `(A . (e - p)) f^2 / z^3` pixels, `z` its view depth: the solid angle
//! `A . v / |v|^3` times `f^2 / cos^3` of its angle off the axis, with
//! `cos = z / |v|`. Summed over the front-facing patches (`A . v > 0`) it is
//! the projected area of the front-facing skin, the count of pixel centres a
//! rasteriser finds, up to the pixel grid.
//!
//! **Occlusion.** One coarse buffer of the frame, [`OCCLUSION_TEXEL_PX`]
//! pixels a texel, holds the nearest patch and its character: every patch
//! splats its depth over the texels of its footprint (a square of its
//! projected area), then a patch counts if
//! the nearest patch at its centre's texel is its own character's (a nearer
//! character hides it). A face hiding part of itself (the far side of the
//! nose) is left to the facing test, which catches most of it.
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

/// The most patches a character is estimated with.
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
}

/// The skin of one mesh as patches at several cell widths.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinPatches {
    levels: Vec<Level>,
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

impl SkinPatches {
    /// The patches of `mesh` (every triangle is skin), `mm_per_unit` converting
    /// the level widths.
    pub fn of(mesh: &Mesh, mm_per_unit: f32) -> SkinPatches {
        let pos = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
        let tris: Vec<(Vec3, Vec3)> = mesh
            .indices
            .chunks_exact(3)
            .filter_map(|t| {
                let (a, b, c) = (pos(t[0]), pos(t[1]), pos(t[2]));
                // Half the cross product: the vector area (area times normal).
                let area = 0.5 * (b - a).cross(c - a);
                (area.length_squared() > 0.0).then(|| ((a + b + c) / 3.0, area))
            })
            .collect();
        let (lo, hi) = tris.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), (c, _)| (lo.min(*c), hi.max(*c)),
        );
        let centre = if lo.x.is_finite() {
            0.5 * (lo + hi)
        } else {
            Vec3::ZERO
        };
        let levels = LEVEL_CELLS_MM
            .iter()
            .map(|&mm| {
                let cell = mm / mm_per_unit.max(f32::MIN_POSITIVE);
                Level {
                    cell_units: cell,
                    patches: bin(&tris, lo, cell),
                }
            })
            .collect();
        SkinPatches { levels, centre }
    }

    /// Patches at each level (finest first).
    pub fn level_sizes(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.patches.len()).collect()
    }

    /// The level a character whose mesh centre lies at view depth `depth`
    /// (mesh units, after its model matrix's scale `scale`) uses: the
    /// coarsest whose cell spans at most [`TARGET_CELL_PX`], coarser still
    /// while it holds more than [`MAX_PATCHES`] (a close-up's patches are
    /// many pixels each already).
    fn level_for(&self, depth: f32, scale: f32, focal_px: f32) -> &Level {
        let px_per_unit = focal_px / depth.max(f32::MIN_POSITIVE);
        let fine = self
            .levels
            .iter()
            .rposition(|l| l.cell_units * scale * px_per_unit <= TARGET_CELL_PX)
            .unwrap_or(0);
        let capped = (fine..self.levels.len())
            .find(|&i| self.levels[i].patches.len() <= MAX_PATCHES)
            .unwrap_or(self.levels.len() - 1);
        &self.levels[capped]
    }

    /// Every instance's estimate in one frame.
    pub fn estimate(&self, instances: &[Mat4], v: &View) -> Vec<PatchEstimate> {
        let (w, h) = (v.width.max(1), v.height.max(1));
        let t = OCCLUSION_TEXEL_PX;
        let (gw, gh) = (w.div_ceil(t) as usize, h.div_ceil(t) as usize);
        let mut nearest = vec![(f32::INFINITY, u32::MAX); gw * gh];
        // Facing, on-screen patches: (character, x, y, depth, pixels).
        let mut seen: Vec<(u32, f32, f32, f32, f32)> = Vec::new();
        let mut looked = vec![0usize; instances.len()];
        // Each character's facing skin on screen before occlusion.
        let mut facing_px = vec![0.0f64; instances.len()];
        let f2 = v.focal_px * v.focal_px;
        let ts = t as f32;
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
            let c: Vec4 = mvp * self.centre.extend(1.0);
            let level = self.level_for(c.w, scale, v.focal_px);
            looked[k] = level.patches.len();
            let cell = level.cell_units * scale;
            for p in &level.patches {
                let facing = det * p.area.dot(eye - p.centre);
                if facing <= 0.0 {
                    continue;
                }
                let clip: Vec4 = mvp * p.centre.extend(1.0);
                let z = clip.w;
                if z <= 0.0 || clip.z < 0.0 || clip.z > z {
                    continue;
                }
                let x = (clip.x / z * 0.5 + 0.5) * w as f32;
                let y = (clip.y / z * 0.5 + 0.5) * h as f32;
                if !(0.0..w as f32).contains(&x) || !(0.0..h as f32).contains(&y) {
                    continue;
                }
                let pixels = facing * f2 / (z * z * z);
                // Splat over the texels whose centres lie in the patch's
                // footprint: a square of side SPLAT_SIDE times the side of
                // its projected area, and the texel under its centre.
                let r = 0.5 * SPLAT_SIDE * pixels.sqrt() / ts;
                let (u, w_) = (x / ts, y / ts);
                let first = |a: f32, n: usize| ((a - 0.5).ceil().max(0.0) as usize).min(n - 1);
                let last = |b: f32, n: usize| ((b - 0.5).floor().max(0.0) as usize).min(n - 1);
                let (cx, cy) = ((u as usize).min(gw - 1), (w_ as usize).min(gh - 1));
                let (x0, x1) = (first(u - r, gw).min(cx), last(u + r, gw).max(cx));
                let (y0, y1) = (first(w_ - r, gh).min(cy), last(w_ + r, gh).max(cy));
                for gy in y0..=y1 {
                    for gx in x0..=x1 {
                        let n = &mut nearest[gy * gw + gx];
                        if z < n.0 {
                            *n = (z, k as u32);
                        }
                    }
                }
                facing_px[k] += f64::from(pixels);
                seen.push((k as u32, x, y, z - SELF_DEPTH_CELLS * cell, pixels));
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
        for &(k, x, y, z_in_front, pixels) in &seen {
            let g =
                (y as usize / t as usize).min(gh - 1) * gw + (x as usize / t as usize).min(gw - 1);
            let (near_z, owner) = nearest[g];
            if owner != k || near_z < z_in_front {
                continue;
            }
            let o = &mut out[k as usize];
            o.0 += f64::from(pixels);
            // The patch's own extent on screen: a square of its area.
            let r = 0.5 * pixels.sqrt();
            o.1 = [
                o.1[0].min(x - r),
                o.1[1].min(y - r),
                o.1[2].max(x + r),
                o.1[3].max(y + r),
            ];
        }
        out.into_iter()
            .zip(looked)
            .zip(facing_px)
            .map(|(((pixels, r), patches), facing)| (pixels, r, patches, facing))
            // A character left with a sliver of its skin is at the occlusion
            // buffer's grain: counted as hidden (see `MIN_VISIBLE_SHARE`).
            .map(|(pixels, r, patches, facing)| {
                let pixels = if pixels < MIN_VISIBLE_SHARE * facing {
                    0.0
                } else {
                    pixels
                };
                (pixels, r, patches)
            })
            .map(|(pixels, r, patches)| PatchEstimate {
                pixels,
                rect: if pixels > 0.0 {
                    [
                        // The pixels whose centres fall inside.
                        r[0].round().clamp(0.0, w as f32) as u32,
                        r[1].round().clamp(0.0, h as f32) as u32,
                        r[2].round().clamp(0.0, w as f32) as u32,
                        r[3].round().clamp(0.0, h as f32) as u32,
                    ]
                } else {
                    [0; 4]
                },
                patches,
            })
            .collect()
    }
}

/// Triangles `(centroid, vector area)` binned into cells of `cell` units
/// (from `origin`) and by the dominant axis of their normal.
fn bin(tris: &[(Vec3, Vec3)], origin: Vec3, cell: f32) -> Vec<Patch> {
    // Per cell and normal bin: area-weighted centroid sum, area, vector area.
    type Key = (i32, i32, i32, u8);
    let mut cells: HashMap<Key, (Vec3, f32, Vec3)> = HashMap::new();
    for &(c, a) in tris {
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
        let key = (q.x as i32, q.y as i32, q.z as i32, 2 * axis as u8 + sign);
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
    // A fixed order, so that a frame's estimate does not depend on hashing.
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, p)| p).collect()
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
}
