//! Where on screen the SSS passes have work: the skin's projected bounds,
//! widened by how far a method's taps reach. Pure math, no Vulkan.
//!
//! Two costs of the screen-space methods do not depend on how much skin is on
//! screen, and this region removes both:
//! - the seed copies of the diffuse target into the intermediates (a full-screen
//!   copy each; the taps only ever read them near skin);
//! - the full-screen triangle of each stencil-tested pass, whose non-skin pixels
//!   are rejected by the stencil test one by one (measured on the H100: a 720p
//!   pass with 18% skin cost 1.7x its fetch floor, see docs/perf/README.md).
//!
//! The skin is bounded per cluster of triangles (a box around a whole scan
//! holds its shoulders), each cluster's footprint is widened by the method's
//! reach, and the union is covered by 32-pixel screen tiles and returned as
//! disjoint rectangles: disjoint so that a pass drawn once per rectangle never
//! blends a pixel twice. (The frame turns them into Vulkan scissors:
//! `render::groups::scissors`.)

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};

use super::ViewScale;
use crate::scene::mesh::{Aabb, Mesh};

/// Whether the SSS passes work only near skin (the default) or on the whole
/// screen (the demos' way; kept to measure what the region saves).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum RegionMode {
    /// The skin's projected bounds widened by the kernel's reach: seed copies
    /// and stencil-tested draws limited to them.
    Skin,
    /// The whole frame, as the demos run (kept to measure what the region
    /// saves). On the command line `frame`; `screen`, its old name (and the
    /// reports' spelling), is still accepted: "screen" names the screen-space
    /// methods.
    #[value(name = "frame", alias = "screen")]
    #[serde(alias = "frame")]
    Screen,
}

impl std::str::FromStr for RegionMode {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "skin" => Ok(RegionMode::Skin),
            "screen" => Ok(RegionMode::Screen),
            other => bail!("unknown SSS region '{other}' (valid: skin, screen)"),
        }
    }
}

/// Pixels added to every reach for the bilinear footprint of a tap (one texel
/// beyond its position) and rounding.
pub const BILINEAR_MARGIN_PX: f32 = 2.0;

/// What converts a kernel's millimetres into pixels at a depth.
#[derive(Clone, Copy, Debug)]
pub struct ReachScale {
    pub height_px: u32,
    pub tan_half_fovy: f32,
    pub mm_per_unit: f32,
    /// The largest per-pixel SSS strength any skin object writes (it scales
    /// every kernel's footprint).
    pub max_strength: f32,
}

impl ReachScale {
    /// The view's scale, without the strength.
    pub fn view(&self) -> ViewScale {
        ViewScale {
            height_px: self.height_px,
            tan_half_fovy: self.tan_half_fovy,
            mm_per_unit: self.mm_per_unit,
        }
    }

    /// Pixels per millimetre at view depth `depth` ([`ViewScale::px_per_mm`]).
    pub fn px_per_mm(&self, depth: f32) -> f32 {
        self.view().px_per_mm(depth)
    }
}

/// A half-open pixel rectangle `[x0, x1) x [y0, y1)`, row 0 at the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn full(width: u32, height: u32) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    pub fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    pub fn is_empty(&self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    pub fn overlaps(&self, o: &PixelRect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }
}

/// The camera as the region needs it.
#[derive(Clone, Copy, Debug)]
pub struct RegionView {
    pub view: Mat4,
    /// Projection with the renderer's conventions (y flipped: row 0 at the top).
    pub proj: Mat4,
    pub near: f32,
    pub width: u32,
    pub height: u32,
}

/// One skin object on screen: the pixel bounds of its projected box and the
/// nearest view depth of any of its points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub rect: PixelRect,
    pub nearest_depth: f32,
}

/// Projects a world-space box. `None` when it is entirely off screen. A box that
/// reaches the near plane, where projection breaks down, covers the whole screen
/// at the near depth: conservative, never wrong.
pub fn footprint(v: &RegionView, bounds: &Aabb) -> Option<Footprint> {
    let (w, h) = (v.width as f32, v.height as f32);
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut nearest = f32::INFINITY;
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 {
                bounds.min.x
            } else {
                bounds.max.x
            },
            if i & 2 == 0 {
                bounds.min.y
            } else {
                bounds.max.y
            },
            if i & 4 == 0 {
                bounds.min.z
            } else {
                bounds.max.z
            },
        );
        let depth = -(v.view * c.extend(1.0)).z;
        nearest = nearest.min(depth);
        if depth <= v.near {
            return Some(Footprint {
                rect: PixelRect::full(v.width, v.height),
                nearest_depth: v.near,
            });
        }
        let clip = v.proj * v.view * c.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let px = Vec3::new((ndc.x * 0.5 + 0.5) * w, (ndc.y * 0.5 + 0.5) * h, ndc.z);
        lo = lo.min(px);
        hi = hi.max(px);
    }
    // Outward to whole pixels; a pixel is covered when its centre is inside, so
    // floor/ceil of the exact bounds holds every covered pixel.
    let clamp = |x: f32, max: u32| x.clamp(0.0, max as f32) as u32;
    let rect = PixelRect {
        x0: clamp(lo.x.floor(), v.width),
        y0: clamp(lo.y.floor(), v.height),
        x1: clamp(hi.x.ceil(), v.width),
        y1: clamp(hi.y.ceil(), v.height),
    };
    (!rect.is_empty()).then_some(Footprint {
        rect,
        nearest_depth: nearest,
    })
}

/// Widens `f.rect` by `margin_px` pixels on every side (clamped to the screen).
pub fn widen(f: &Footprint, margin_px: f32, width: u32, height: u32) -> PixelRect {
    let m = if margin_px.is_finite() {
        margin_px.max(0.0).ceil().min(u32::MAX as f32) as u32
    } else {
        u32::MAX
    };
    PixelRect {
        x0: f.rect.x0.saturating_sub(m),
        y0: f.rect.y0.saturating_sub(m),
        x1: f.rect.x1.saturating_add(m).min(width),
        y1: f.rect.y1.saturating_add(m).min(height),
    }
}

/// Default side of the screen tiles a region is built from, in pixels: coarse
/// enough that a head is a few dozen rectangles (one draw each per pass).
pub const TILE_PX: u32 = 32;

/// Covers `rects` with screen tiles of `tile` pixels and returns the marked
/// tiles as disjoint rectangles: runs of tiles along each tile row, a run
/// extended downward while the next row has the same run. Bounding boxes of
/// overlapping rectangles would be simpler, but a head's clusters all overlap
/// and their bounding box spans the shoulders' width on every row; tiles
/// follow the silhouette, and rows of equal runs keep the count small.
pub fn tile_cover(rects: &[PixelRect], width: u32, height: u32, tile: u32) -> Vec<PixelRect> {
    let tile = tile.max(1);
    let (gw, gh) = (
        width.div_ceil(tile) as usize,
        height.div_ceil(tile) as usize,
    );
    let mut marked = vec![false; gw * gh];
    for r in rects.iter().filter(|r| !r.is_empty()) {
        let (tx0, ty0) = ((r.x0 / tile) as usize, (r.y0 / tile) as usize);
        let (tx1, ty1) = (r.x1.div_ceil(tile) as usize, r.y1.div_ceil(tile) as usize);
        for ty in ty0..ty1.min(gh) {
            marked[ty * gw + tx0..ty * gw + tx1.min(gw)].fill(true);
        }
    }
    let px = |t: usize, max: u32| (t as u32 * tile).min(max);
    let mut out: Vec<PixelRect> = Vec::new();
    // Rectangles still open at the previous tile row, by run.
    let mut open: Vec<(usize, usize, usize)> = Vec::new(); // (tx0, tx1, index in out)
    for ty in 0..gh {
        let row = &marked[ty * gw..(ty + 1) * gw];
        let mut next_open = Vec::new();
        let mut tx = 0;
        while tx < gw {
            if !row[tx] {
                tx += 1;
                continue;
            }
            let start = tx;
            while tx < gw && row[tx] {
                tx += 1;
            }
            let y1 = px(ty + 1, height);
            match open.iter().find(|&&(a, b, _)| a == start && b == tx) {
                Some(&(a, b, i)) => {
                    out[i].y1 = y1;
                    next_open.push((a, b, i));
                }
                None => {
                    out.push(PixelRect {
                        x0: px(start, width),
                        y0: px(ty, height),
                        x1: px(tx, width),
                        y1,
                    });
                    next_open.push((start, tx, out.len() - 1));
                }
            }
        }
        open = next_open;
    }
    out
}

/// The region of a set of skin boxes: each box's footprint widened by
/// `reach_px(nearest_depth)` (how far the method's taps reach, in pixels, from
/// a pixel at that depth; it must not grow with depth), covered by `tile`-pixel tiles.
pub fn skin_region(
    v: &RegionView,
    boxes: impl IntoIterator<Item = Aabb>,
    reach_px: impl Fn(f32) -> f32,
    tile: u32,
) -> Vec<PixelRect> {
    let widened: Vec<PixelRect> = boxes
        .into_iter()
        .filter_map(|b| footprint(v, &b))
        .map(|f| widen(&f, reach_px(f.nearest_depth), v.width, v.height))
        .collect();
    tile_cover(&widened, v.width, v.height, tile)
}

/// Boxes around the triangles of `mesh` grouped by a `cells`^3 grid over its
/// bounds (by centroid; each box holds its triangles whole). One box around a
/// whole scan would hold its shoulders too, and on screen their width spans the
/// face's rows; the union of the cells' footprints follows the silhouette.
pub fn cluster_bounds(mesh: &Mesh, cells: u32) -> Vec<Aabb> {
    let cells = cells.max(1);
    let Some(all) = Aabb::from_points(mesh.vertices.iter().map(|v| Vec3::from(v.position))) else {
        return Vec::new();
    };
    let size = all.size().max(Vec3::splat(1e-20));
    let n = cells as usize;
    let mut boxes: Vec<Option<Aabb>> = vec![None; n * n * n];
    for tri in mesh.indices.chunks_exact(3) {
        let p: [Vec3; 3] = [0, 1, 2].map(|k| Vec3::from(mesh.vertices[tri[k] as usize].position));
        let c = (p[0] + p[1] + p[2]) / 3.0;
        let cell = ((c - all.min) / size * cells as f32)
            .floor()
            .clamp(Vec3::ZERO, Vec3::splat((cells - 1) as f32));
        let k = cell.x as usize + n * (cell.y as usize + n * cell.z as usize);
        let t = Aabb::from_points(p).expect("three points");
        boxes[k] = Some(boxes[k].map_or(t, |b| b.union(&t)));
    }
    boxes.into_iter().flatten().collect()
}

/// Cells per axis of the grid that clusters skin triangles: 8^3 = at most 512
/// boxes per head, projected once per renderer.
pub const CLUSTER_CELLS: u32 = 8;

/// The scale a method's reach is measured in for `scene` seen through `v`.
fn reach_scale(scene: &crate::scene::Scene, v: &RegionView, tan_half_fovy: f32) -> ReachScale {
    ReachScale {
        height_px: v.height,
        tan_half_fovy,
        mm_per_unit: scene.mm_per_unit,
        max_strength: skin_objects(scene)
            .iter()
            .map(|o| o.material.sss_strength)
            .fold(0.0, f32::max),
    }
}

/// The SSS region of a method in a scene: every skin object's triangle
/// clusters, once per character (`instances`), widened by `reach` (the
/// method's reach in pixels at a depth; `None`: the whole screen).
pub fn scene_region(
    scene: &crate::scene::Scene,
    instances: &[Mat4],
    v: &RegionView,
    tan_half_fovy: f32,
    tile: u32,
    reach: impl Fn(f32, &ReachScale) -> Option<f32>,
) -> Vec<PixelRect> {
    let scale = reach_scale(scene, v, tan_half_fovy);
    skin_region(
        v,
        skin_boxes(scene, instances),
        |d| reach(d, &scale).unwrap_or(f32::INFINITY),
        tile,
    )
}

/// The region of each character alone (`scene_region` of one instance at a
/// time, the clusters computed once): what the planner unions per group
/// (`plan::cost::Overlap`), since characters' regions overlap and merge
/// into fewer rectangles than their sum.
pub fn instance_regions(
    scene: &crate::scene::Scene,
    instances: &[Mat4],
    v: &RegionView,
    tan_half_fovy: f32,
    tile: u32,
    reach: impl Fn(f32, &ReachScale) -> f32,
) -> Vec<Vec<PixelRect>> {
    let scale = reach_scale(scene, v, tan_half_fovy);
    let clusters: Vec<Aabb> = skin_objects(scene)
        .iter()
        .flat_map(|o| cluster_bounds(&o.mesh, CLUSTER_CELLS))
        .collect();
    instances
        .iter()
        .map(|m| {
            skin_region(
                v,
                clusters.iter().map(|b| b.transformed(m)),
                |d| reach(d, &scale),
                tile,
            )
        })
        .collect()
}

/// Where the skin of `instances` lies in depth: for each skin cluster on
/// screen, its share of the clusters' on-screen area and its nearest view
/// depth (what a method's per-pixel kernel size follows; clusters a face
/// hides count too, so a share is an estimate, not a pixel count).
pub fn skin_depths(
    scene: &crate::scene::Scene,
    instances: &[Mat4],
    v: &RegionView,
) -> Vec<(f64, f32)> {
    let on_screen: Vec<(f64, f32)> = skin_boxes(scene, instances)
        .iter()
        .filter_map(|b| footprint(v, b))
        .map(|f| {
            (
                f64::from(f.rect.width()) * f64::from(f.rect.height()),
                f.nearest_depth,
            )
        })
        .filter(|&(a, _)| a > 0.0)
        .collect();
    let total: f64 = on_screen.iter().map(|c| c.0).sum();
    if total <= 0.0 {
        return Vec::new();
    }
    on_screen.into_iter().map(|(a, d)| (a / total, d)).collect()
}

fn skin_objects(scene: &crate::scene::Scene) -> Vec<&crate::scene::mesh::Object> {
    scene
        .backdrop
        .iter()
        .chain(std::iter::once(&scene.head))
        .filter(|o| o.material.skin)
        .collect()
}

/// Every skin cluster's box, once per character (skin objects are drawn once
/// per character: see the geometry pass).
fn skin_boxes(scene: &crate::scene::Scene, instances: &[Mat4]) -> Vec<Aabb> {
    skin_objects(scene)
        .iter()
        .flat_map(|o| {
            let clusters = cluster_bounds(&o.mesh, CLUSTER_CELLS);
            instances
                .iter()
                .flat_map(move |m| clusters.clone().into_iter().map(move |b| b.transformed(m)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::Camera;

    fn view(width: u32, height: u32, distance: f32) -> RegionView {
        let cam = Camera::framing(Vec3::ZERO, Vec3::Z, 1.0, distance, 20.0);
        RegionView {
            view: cam.view(),
            proj: cam.proj(width as f32 / height as f32),
            near: cam.near,
            width,
            height,
        }
    }

    fn unit_box(center: Vec3) -> Aabb {
        Aabb {
            min: center - Vec3::splat(0.5),
            max: center + Vec3::splat(0.5),
        }
    }

    #[test]
    fn a_centred_box_projects_to_a_centred_rect_that_holds_its_corners() {
        let v = view(640, 360, 10.0);
        let f = footprint(&v, &unit_box(Vec3::ZERO)).unwrap();
        // Nearest face at 10 - 0.5 view units.
        assert!((f.nearest_depth - 9.5).abs() < 1e-4);
        // 1 unit at 9.5 units with a 20 degree fovy on 360 rows: 360 / (2 * 9.5 * tan 10) px.
        let ppu = 360.0 / (2.0 * 9.5 * 10f32.to_radians().tan());
        let r = f.rect;
        assert!((r.height() as f32 - ppu).abs() <= 2.0, "{r:?} vs {ppu}");
        assert!((r.width() as f32 - ppu).abs() <= 2.0, "{r:?} vs {ppu}");
        assert!(((r.x0 + r.x1) as i32 - 640).abs() <= 1);
        assert!(((r.y0 + r.y1) as i32 - 360).abs() <= 1);
    }

    #[test]
    fn up_in_the_world_is_up_on_screen() {
        let v = view(640, 360, 10.0);
        let up = footprint(&v, &unit_box(Vec3::new(0.0, 1.0, 0.0))).unwrap();
        let centre = footprint(&v, &unit_box(Vec3::ZERO)).unwrap();
        assert!(up.rect.y0 < centre.rect.y0, "row 0 is the top");
    }

    #[test]
    fn boxes_at_the_near_plane_take_the_screen_and_boxes_behind_or_aside_take_nothing() {
        let v = view(64, 36, 10.0);
        let touching = footprint(&v, &unit_box(Vec3::new(0.0, 0.0, 10.0))).unwrap();
        assert_eq!(touching.rect, PixelRect::full(64, 36));
        assert_eq!(touching.nearest_depth, v.near);
        assert!(footprint(&v, &unit_box(Vec3::new(100.0, 0.0, 0.0))).is_none());
    }

    #[test]
    fn widening_clamps_to_the_screen() {
        let f = Footprint {
            rect: PixelRect {
                x0: 2,
                y0: 3,
                x1: 10,
                y1: 12,
            },
            nearest_depth: 1.0,
        };
        let r = widen(&f, 4.2, 16, 14);
        assert_eq!(
            r,
            PixelRect {
                x0: 0,
                y0: 0,
                x1: 15,
                y1: 14
            }
        );
        assert_eq!(widen(&f, f32::INFINITY, 16, 14), PixelRect::full(16, 14));
        assert_eq!(widen(&f, f32::NAN, 16, 14), PixelRect::full(16, 14));
    }

    #[test]
    fn tiles_cover_every_input_pixel_exactly_once() {
        let r = |x0, y0, x1, y1| PixelRect { x0, y0, x1, y1 };
        let inputs = vec![
            r(0, 0, 10, 10),
            r(5, 5, 15, 15),
            r(20, 0, 30, 5),
            r(14, 14, 22, 16),
            r(40, 40, 40, 50), // empty
            r(50, 0, 60, 10),
            r(61, 61, 70, 70), // cut by the screen edge
        ];
        let out = tile_cover(&inputs, 64, 64, 8);
        for a in 0..out.len() {
            assert!(!out[a].is_empty() && out[a].x1 <= 64 && out[a].y1 <= 64);
            for b in a + 1..out.len() {
                assert!(!out[a].overlaps(&out[b]), "{:?} {:?}", out[a], out[b]);
            }
        }
        let mut covered = 0;
        for y in 0..64 {
            for x in 0..64 {
                let n = out.iter().filter(|o| o.contains(x, y)).count();
                assert!(n <= 1);
                covered += n;
                if inputs.iter().any(|i| i.contains(x, y)) {
                    assert_eq!(n, 1, "({x},{y})");
                }
            }
        }
        // Tile-rounded: no more than the tiles the inputs touch.
        assert!(covered <= 21 * 64, "{covered}");
        // Equal runs on consecutive tile rows make one rectangle.
        assert_eq!(
            tile_cover(&[r(0, 0, 64, 64)], 64, 64, 8),
            vec![r(0, 0, 64, 64)]
        );
        assert_eq!(
            tile_cover(&[r(0, 0, 100, 100)], 60, 50, 8),
            vec![r(0, 0, 60, 50)]
        );
        assert!(tile_cover(&[], 64, 64, 8).is_empty());
    }

    #[test]
    fn region_of_two_far_apart_heads_is_two_rects_and_nearer_means_wider() {
        let v = view(640, 360, 10.0);
        let boxes = [
            unit_box(Vec3::new(-2.0, 0.0, 0.0)),
            unit_box(Vec3::new(2.0, 0.0, 0.0)),
        ];
        let near = skin_region(&v, boxes, |d: f32| 30.0 / d, TILE_PX);
        let far = skin_region(&v, boxes, |_| 0.0, TILE_PX);
        let area = |rs: &[PixelRect]| rs.iter().map(|r| r.area()).sum::<u64>();
        // Two separate heads: separate rectangles, one block of rows each.
        assert_eq!(near.len(), 2, "{near:?}");
        assert!(!near[0].overlaps(&near[1]));
        // 30 / 9.5 = 3.2 -> 4 px more on each side, then rounded to tiles.
        for b in &boxes {
            let f = footprint(&v, b).unwrap();
            let w = widen(&f, 30.0 / f.nearest_depth, 640, 360);
            for (x, y) in [(w.x0, w.y0), (w.x1 - 1, w.y1 - 1)] {
                assert!(near.iter().any(|r| r.contains(x, y)), "({x},{y})");
            }
        }
        assert!(area(&near) >= area(&far));
    }

    #[test]
    fn clusters_hold_every_triangle_and_are_no_more_than_the_cells() {
        let mesh = crate::scene::procedural::head_mesh();
        let boxes = cluster_bounds(&mesh, 4);
        assert!(boxes.len() > 8 && boxes.len() <= 64, "{}", boxes.len());
        for tri in mesh.indices.chunks_exact(3) {
            let inside = |b: &Aabb| {
                tri.iter().all(|&i| {
                    let p = Vec3::from(mesh.vertices[i as usize].position);
                    p.cmpge(b.min).all() && p.cmple(b.max).all()
                })
            };
            assert!(boxes.iter().any(inside), "a triangle outside every cluster");
        }
        // One cell is the mesh's box.
        let one = cluster_bounds(&mesh, 1);
        assert_eq!(one.len(), 1);
        assert_eq!(one[0], mesh.bounds());
        assert!(cluster_bounds(&Mesh::default(), 4).is_empty());
    }
}
