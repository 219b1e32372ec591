//! What the planner knows of each character (a plain struct, so exact counts
//! from a render can replace the estimates), and the pure estimate of it from
//! the scene's geometry: distance, pixels per millimetre at the character's
//! depth, the key light's angle to the camera, skin pixels and the screen
//! rectangle of its skin.
//!
//! Skin pixels are counted by rasterising every character's front-facing
//! triangles on the CPU into one depth buffer of the frame's size (pixel
//! centres inside a triangle, nearest depth wins), so a face hiding itself
//! and characters hiding each other are counted as the geometry pass counts
//! them (the backdrop, behind every character, is left out).
//! `tests/suite/plan.rs` holds the count to the skin pixels of the stored
//! lavapipe frames (samples passed).

use glam::{Mat4, Vec3, Vec4};
use serde::Serialize;

use crate::scene::framing::Framing;
use crate::scene::{HeadSize, Scene};
use crate::view::ViewScale;

/// Width of the eval's silhouette band on the skin, mm (`eval::bands`).
pub const SILHOUETTE_BAND_MM: f64 = 2.0;

/// One character as the planner sees it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CharacterInput {
    /// Frame index (`Framing::instances` order; 0 is the front character).
    pub index: usize,
    /// Camera distance in head heights.
    pub distance_heads: f64,
    /// Pixels per millimetre at the depth of the head's centre.
    pub px_per_mm: f64,
    /// Degrees between the direction to the key light and to the camera.
    pub light_deg: f64,
    /// Width of a shadow-map texel at the character, mm (one map fitted to
    /// every character: a crowd's is wider than one head's).
    pub shadow_mm: f64,
    /// Skin pixels (from a render: the samples a stencil-tested SSS pass passes).
    pub skin_pixels: f64,
    /// The reference setting's SSS region of this character: pixels, rectangles.
    pub region_pixels: f64,
    pub region_rects: f64,
    /// Share of the skin pixels in the eval's silhouette band.
    pub silhouette_share: f64,
    /// Screen rectangle of its skin `[x0, y0, x1, y1]` (pixels, half-open).
    pub screen_rect: [u32; 4],
    /// The reference setting's SSS region of this character alone, as the
    /// frame builds it (tiles, `[x0, y0, x1, y1]`; empty where unknown): a
    /// group's region is the tile cover of its characters' (they overlap).
    #[serde(skip)]
    pub region_tiles: Vec<[u32; 4]>,
}

impl CharacterInput {
    /// The share of a skin area of `skin` pixels within the silhouette band:
    /// the band along the perimeter of a disc of the same area, at most all
    /// of it.
    pub fn band_share(skin: f64, px_per_mm: f64) -> f64 {
        if skin <= 0.0 {
            return 0.0;
        }
        let perimeter = 2.0 * (std::f64::consts::PI * skin).sqrt();
        (perimeter * SILHOUETTE_BAND_MM * px_per_mm / skin).min(1.0)
    }
}

/// The geometric estimate of every character (region fields left at 0: the
/// cost model fills them from its reference frames), its skin counted by the
/// exact rasterisation.
pub fn estimate(
    scene: &Scene,
    framing: &Framing,
    width: u32,
    height: u32,
    light_dir: Vec3,
    shadow_size: u32,
) -> Vec<CharacterInput> {
    let cam = framing.camera;
    let vp = cam.view_proj(width as f32 / height as f32);
    let visible = if scene.head.material.skin {
        let mut meshes = vec![(&scene.head.mesh, true)];
        meshes.extend(scene.parts.iter().map(|p| (&p.mesh, false)));
        rasterise(&meshes, &framing.instances, &vp, cam.eye, width, height)
    } else {
        vec![(0.0, [0; 4]); framing.instances.len()]
    };
    let view = FrameView {
        framing,
        width,
        height,
        light_dir,
        shadow_size,
    };
    from_visible(scene, &scene.head_size(), &view, &visible)
}

/// The frame an estimate is made for.
pub struct FrameView<'a> {
    pub framing: &'a Framing,
    pub width: u32,
    pub height: u32,
    pub light_dir: Vec3,
    pub shadow_size: u32,
}

/// Every character of `v` given its visible skin pixels and screen rectangle
/// (`visible`, in the frame's order: the exact rasterisation's or
/// `skin_patches`'), `size` the scene's head measures.
pub fn from_visible(
    scene: &Scene,
    size: &HeadSize,
    v: &FrameView,
    visible: &[(f64, [u32; 4])],
) -> Vec<CharacterInput> {
    let framing = v.framing;
    let shadow_mm = framing.light.texel_mm(v.shadow_size, scene.mm_per_unit);
    let cam = framing.camera;
    let view = cam.view();
    let scale = ViewScale::new(v.height, cam.fovy_rad, scene.mm_per_unit);
    let head_h = size.height;
    let centre = size.centre;
    let light_dir = v.light_dir.normalize_or_zero();
    framing
        .instances
        .iter()
        .zip(visible)
        .enumerate()
        .map(|(index, (m, &(area, rect)))| {
            let c = m.transform_point3(centre);
            let depth = -view.transform_point3(c).z;
            let to_eye = (cam.eye - c).normalize_or_zero();
            let light_deg = f64::from(to_eye.dot(light_dir).clamp(-1.0, 1.0))
                .acos()
                .to_degrees();
            // Behind the eye (a camera passing through the crowd) a character
            // has no scale on screen: 0, which the planner's rules read as
            // under a pixel.
            let px_per_mm = if depth > 0.0 {
                f64::from(scale.px_per_mm(depth))
            } else {
                0.0
            };
            CharacterInput {
                index,
                distance_heads: f64::from(cam.eye.distance(c) / head_h),
                px_per_mm,
                light_deg,
                shadow_mm,
                skin_pixels: area,
                region_pixels: 0.0,
                region_rects: 0.0,
                silhouette_share: CharacterInput::band_share(area, px_per_mm),
                screen_rect: rect,
                region_tiles: Vec::new(),
            }
        })
        .collect()
}

/// Skin pixels of each instance left visible in one depth buffer of `width` x
/// `height` (front-facing triangles, pixel centres inside, the nearest depth
/// kept), with each instance's bounding rectangle: `meshes` are a
/// character's, `true` for its skin; the others (its parts) hide skin and
/// count for no one, as the geometry pass's stencil does.
fn rasterise(
    meshes: &[(&crate::scene::mesh::Mesh, bool)],
    instances: &[Mat4],
    vp: &Mat4,
    eye: Vec3,
    width: u32,
    height: u32,
) -> Vec<(f64, [u32; 4])> {
    let (w, h) = (width as usize, height as usize);
    let mut depth = vec![f32::INFINITY; w * h];
    let mut owner = vec![u32::MAX; w * h];
    // A part (not skin) hides the skin behind it and owns nothing.
    for (k, model, mesh, skin) in instances
        .iter()
        .enumerate()
        .flat_map(|(k, m)| meshes.iter().map(move |&(mesh, skin)| (k, m, mesh, skin)))
    {
        let world: Vec<Vec3> = mesh
            .vertices
            .iter()
            .map(|v| model.transform_point3(Vec3::from(v.position)))
            .collect();
        // Screen position (pixels) and depth (NDC z), behind the eye: None.
        let screen: Vec<Option<[f32; 3]>> = world
            .iter()
            .map(|p| {
                let c: Vec4 = *vp * p.extend(1.0);
                (c.w > 1e-6).then(|| {
                    [
                        (c.x / c.w * 0.5 + 0.5) * width as f32,
                        (c.y / c.w * 0.5 + 0.5) * height as f32,
                        c.z / c.w,
                    ]
                })
            })
            .collect();
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let (Some(pa), Some(pb), Some(pc)) = (screen[a], screen[b], screen[c]) else {
                continue;
            };
            let n = (world[b] - world[a]).cross(world[c] - world[a]);
            if n.dot(eye - world[a]) <= 0.0 {
                continue;
            }
            let area = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
            if area == 0.0 {
                continue;
            }
            let lo = |i: usize| pa[i].min(pb[i]).min(pc[i]);
            let hi = |i: usize| pa[i].max(pb[i]).max(pc[i]);
            let x0 = (lo(0) - 0.5).ceil().max(0.0) as usize;
            let y0 = (lo(1) - 0.5).ceil().max(0.0) as usize;
            let x1 = ((hi(0) - 0.5).floor() + 1.0).clamp(0.0, w as f32) as usize;
            let y1 = ((hi(1) - 0.5).floor() + 1.0).clamp(0.0, h as f32) as usize;
            for y in y0..y1 {
                for x in x0..x1 {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                    let e = |p: [f32; 3], q: [f32; 3]| {
                        ((q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0])) / area
                    };
                    let (wa, wb, wc) = (e(pb, pc), e(pc, pa), e(pa, pb));
                    if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                        continue;
                    }
                    let z = wa * pa[2] + wb * pb[2] + wc * pc[2];
                    let i = y * w + x;
                    if z < depth[i] && (0.0..=1.0).contains(&z) {
                        depth[i] = z;
                        owner[i] = if skin { k as u32 } else { u32::MAX };
                    }
                }
            }
        }
    }
    let mut out = vec![(0.0, [u32::MAX, u32::MAX, 0, 0]); instances.len()];
    for (i, &o) in owner.iter().enumerate() {
        if o == u32::MAX {
            continue;
        }
        let (x, y) = ((i % w) as u32, (i / w) as u32);
        let r = &mut out[o as usize];
        r.0 += 1.0;
        r.1 = [
            r.1[0].min(x),
            r.1[1].min(y),
            r.1[2].max(x + 1),
            r.1[3].max(y + 1),
        ];
    }
    for r in &mut out {
        if r.0 == 0.0 {
            r.1 = [0; 4];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_nearer_hides_one_behind() {
        use crate::scene::mesh::{Mesh, Vertex};
        // A unit square at z = 0 facing +z, seen from z = 5 with a 90 degree
        // view: it spans half the screen height, 50 x 50 of 100 x 100 pixels.
        let v = |x: f32, y: f32| Vertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            uv: [0.0, 0.0],
            tangent: [1.0, 0.0, 0.0, 1.0],
        };
        let mesh = Mesh {
            vertices: vec![v(-2.5, -2.5), v(2.5, -2.5), v(2.5, 2.5), v(-2.5, 2.5)],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        let cam = crate::scene::camera::Camera {
            eye: Vec3::new(0.0, 0.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_rad: 90f32.to_radians(),
            near: 0.1,
            far: 100.0,
        };
        let vp = cam.view_proj(1.0);
        let near = Mat4::IDENTITY;
        let behind = Mat4::from_translation(Vec3::new(6.0, 0.0, -5.0));
        let r = rasterise(&[(&mesh, true)], &[near, behind], &vp, cam.eye, 100, 100);
        assert_eq!(r[0].0, 2500.0, "{r:?}");
        assert_eq!(r[0].1, [25, 25, 75, 75]);
        // The one behind is half as large (twice as far) and half hidden.
        assert!(r[1].0 > 0.0 && r[1].0 < 625.0, "{r:?}");
        // A part (not skin) a unit nearer and half the size, inside the
        // square's outline, hides exactly its own pixels of the skin and
        // owns none.
        let mut part = mesh.clone();
        part.transform(
            &(Mat4::from_translation(Vec3::new(0.0, 0.0, 1.0))
                * Mat4::from_scale(Vec3::splat(0.5))),
        );
        let with = rasterise(
            &[(&mesh, true), (&part, false)],
            &[near],
            &vp,
            cam.eye,
            100,
            100,
        );
        let alone = rasterise(&[(&part, true)], &[near], &vp, cam.eye, 100, 100);
        assert!(alone[0].0 > 0.0);
        assert_eq!(with[0].0, 2500.0 - alone[0].0, "{with:?} {alone:?}");
    }

    #[test]
    fn the_band_share_of_a_disc() {
        // A disc of radius 100 px at 1 px/mm: band 2 px along a 628 px perimeter.
        let a = std::f64::consts::PI * 1e4;
        let s = CharacterInput::band_share(a, 1.0);
        assert!((s - 2.0 * 2.0 / 100.0).abs() < 1e-9, "{s}");
        assert_eq!(CharacterInput::band_share(10.0, 100.0), 1.0);
    }
}
