//! What the planner knows of each character (a plain struct, so exact counts
//! from a render can replace the estimates), and the pure estimate of it from
//! the scene's geometry: distance, pixels per millimetre at the character's
//! depth, the key light's angle to the camera, skin pixels and the screen
//! rectangle of its skin.
//!
//! Skin pixels are estimated as the projected area of the skin mesh's
//! front-facing triangles, clipped to the screen: exact for a convex head,
//! an overestimate where the face hides itself (nose over cheek, ears) and
//! where characters hide each other (not modelled; it only makes the plan's
//! costs conservative). `tests/suite/plan.rs` holds the estimate to the skin
//! pixels of the stored lavapipe frames (samples passed).

use glam::{Mat4, Vec3, Vec4};
use serde::Serialize;

use crate::scene::framing::Framing;
use crate::scene::Scene;
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
    /// Skin pixels (from a render: the samples a stencil-tested SSS pass passes).
    pub skin_pixels: f64,
    /// The reference setting's SSS region of this character: pixels, rectangles.
    pub region_pixels: f64,
    pub region_rects: f64,
    /// Share of the skin pixels in the eval's silhouette band.
    pub silhouette_share: f64,
    /// Screen rectangle of its skin `[x0, y0, x1, y1]` (pixels, half-open).
    pub screen_rect: [u32; 4],
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

/// The geometric estimate of one character (region fields left at 0: the
/// cost model fills them from its reference frames).
pub fn estimate(
    scene: &Scene,
    framing: &Framing,
    width: u32,
    height: u32,
    light_dir: Vec3,
) -> Vec<CharacterInput> {
    let cam = framing.camera;
    let aspect = width as f32 / height as f32;
    let view = cam.view();
    let vp = cam.view_proj(aspect);
    let scale = ViewScale::new(height, cam.fovy_rad, scene.mm_per_unit);
    let head_h = scene.head_height_units();
    let centre = scene.head_center();
    let mesh = &scene.head.mesh;
    let skin = scene.head.material.skin;
    framing
        .instances
        .iter()
        .enumerate()
        .map(|(index, m)| {
            let c = m.transform_point3(centre);
            let depth = -view.transform_point3(c).z;
            let to_eye = (cam.eye - c).normalize_or_zero();
            let light_deg = f64::from(to_eye.dot(light_dir.normalize_or_zero()).clamp(-1.0, 1.0))
                .acos()
                .to_degrees();
            let (area, rect) = if skin {
                projected_skin(mesh, m, &vp, cam.eye, width, height)
            } else {
                (0.0, [0, 0, 0, 0])
            };
            let px_per_mm = f64::from(scale.px_per_mm(depth.max(1e-6)));
            CharacterInput {
                index,
                distance_heads: f64::from(cam.eye.distance(c) / head_h),
                px_per_mm,
                light_deg,
                skin_pixels: area,
                region_pixels: 0.0,
                region_rects: 0.0,
                silhouette_share: CharacterInput::band_share(area, px_per_mm),
                screen_rect: rect,
            }
        })
        .collect()
}

/// Screen area (pixels) of the front-facing triangles of `mesh` placed by
/// `model`, clipped to the screen, and their bounding rectangle.
fn projected_skin(
    mesh: &crate::scene::mesh::Mesh,
    model: &Mat4,
    vp: &Mat4,
    eye: Vec3,
    width: u32,
    height: u32,
) -> (f64, [u32; 4]) {
    let (w, h) = (width as f64, height as f64);
    let world: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| model.transform_point3(Vec3::from(v.position)))
        .collect();
    let screen: Vec<Option<[f64; 2]>> = world
        .iter()
        .map(|p| {
            let c: Vec4 = *vp * p.extend(1.0);
            (c.w > 1e-6).then(|| {
                let x = f64::from(c.x / c.w);
                let y = f64::from(c.y / c.w);
                [(x * 0.5 + 0.5) * w, (y * 0.5 + 0.5) * h]
            })
        })
        .collect();
    let mut area = 0.0;
    let mut bounds = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let (Some(pa), Some(pb), Some(pc)) = (screen[a], screen[b], screen[c]) else {
            continue;
        };
        // Front-facing: the face's normal toward the eye.
        let n = (world[b] - world[a]).cross(world[c] - world[a]);
        if n.dot(eye - world[a]) <= 0.0 {
            continue;
        }
        let poly = clip(&[pa, pb, pc], w, h);
        if poly.len() < 3 {
            continue;
        }
        area += polygon_area(&poly);
        for p in &poly {
            bounds[0] = bounds[0].min(p[0]);
            bounds[1] = bounds[1].min(p[1]);
            bounds[2] = bounds[2].max(p[0]);
            bounds[3] = bounds[3].max(p[1]);
        }
    }
    let rect = if area > 0.0 {
        [
            bounds[0].floor() as u32,
            bounds[1].floor() as u32,
            (bounds[2].ceil() as u32).min(width),
            (bounds[3].ceil() as u32).min(height),
        ]
    } else {
        [0, 0, 0, 0]
    };
    (area, rect)
}

fn polygon_area(p: &[[f64; 2]]) -> f64 {
    let mut s = 0.0;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        s += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * s.abs()
}

/// Sutherland-Hodgman clipping of a polygon to `[0, w] x [0, h]`.
fn clip(poly: &[[f64; 2]], w: f64, h: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = poly.to_vec();
    // (axis, bound, keep below)
    for (axis, bound, below) in [(0, 0.0, false), (0, w, true), (1, 0.0, false), (1, h, true)] {
        let inside = |p: &[f64; 2]| {
            if below {
                p[axis] <= bound
            } else {
                p[axis] >= bound
            }
        };
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (cur, prev) = (input[i], input[(i + input.len() - 1) % input.len()]);
            let cross = |a: [f64; 2], b: [f64; 2]| {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
            };
            match (inside(&cur), inside(&prev)) {
                (true, true) => out.push(cur),
                (true, false) => {
                    out.push(cross(prev, cur));
                    out.push(cur);
                }
                (false, true) => out.push(cross(prev, cur)),
                (false, false) => {}
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_the_inside_area() {
        // A triangle half off the left edge: area 50 of 100 x 2 / 2... a right
        // triangle (-10,0) (10,0) (-10,20): area 200, the part x >= 0 is the
        // triangle (0,0) (10,0) (0,10): 50.
        let p = clip(&[[-10.0, 0.0], [10.0, 0.0], [-10.0, 20.0]], 100.0, 100.0);
        assert!((polygon_area(&p) - 50.0).abs() < 1e-9, "{p:?}");
        assert!(clip(&[[-3.0, 1.0], [-1.0, 1.0], [-2.0, 5.0]], 10.0, 10.0).len() < 3);
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
