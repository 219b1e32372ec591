//! Shadow-caster culling: which characters the shadow map must draw. A
//! character casts into the frame only when its shadow can land on a lit
//! receiver the camera sees: a character in view (itself included), or the
//! part of the backdrop in view. Everything else's shadow falls where no
//! pixel of the frame reads the map, so leaving it out changes no pixel
//! (`tests/suite/casters.rs` renders both and compares the bits).
//!
//! The test is conservative, on boxes in the key light's space (the shadow
//! map's orthographic projection: x, y across the map, z the depth from the
//! light). A caster's shadow is the set of points behind it along the light,
//! so it can reach a receiver only where their boxes overlap across the map
//! and the caster's nearest depth is in front of the receiver's farthest.
//! A receiver's box is its world box's light-space box, cut to the light
//! box of the view frustum (which no visible point leaves); the backdrop,
//! a wall larger than the view, is only ever that cut. Pure: no device.

use glam::{Mat4, Vec3, Vec4, Vec4Swizzles};

use super::mesh::Aabb;

/// The 8 corners of `b`.
fn corners(b: &Aabb) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// Whether any of `b` can be inside the frustum of `view_proj` (Vulkan clip
/// space: -w <= x, y <= w, 0 <= z <= w): false only when all eight corners
/// lie outside one plane. Conservative (a box across a frustum's corner
/// reads as in view).
pub fn in_view(view_proj: &Mat4, b: &Aabb) -> bool {
    let clip: Vec<Vec4> = corners(b)
        .iter()
        .map(|c| *view_proj * c.extend(1.0))
        .collect();
    let planes: [fn(&Vec4) -> bool; 6] = [
        |c| c.x < -c.w,
        |c| c.x > c.w,
        |c| c.y < -c.w,
        |c| c.y > c.w,
        |c| c.z < 0.0,
        |c| c.z > c.w,
    ];
    !planes.iter().any(|outside| clip.iter().all(outside))
}

/// Whether any of the triangles of `mesh`, placed by `model`, can reach
/// the frustum of `view_proj`: a vertex inside it, or else a triangle whose
/// box [`in_view`] passes (a large triangle can cross the view with every
/// corner outside). False only when nothing of the mesh can be seen.
pub fn mesh_in_view(view_proj: &Mat4, model: &Mat4, mesh: &super::mesh::Mesh) -> bool {
    let m = *view_proj * *model;
    let clip: Vec<Vec4> = mesh
        .vertices
        .iter()
        .map(|v| m * Vec3::from(v.position).extend(1.0))
        .collect();
    let inside =
        |c: &Vec4| c.w > 0.0 && c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w;
    if clip.iter().any(inside) {
        return true;
    }
    mesh.indices.chunks_exact(3).any(|t| {
        Aabb::from_points(
            t.iter()
                .map(|&i| Vec3::from(mesh.vertices[i as usize].position)),
        )
        .is_some_and(|b| in_view(&m, &b))
    })
}

/// The world points of the frustum of `view_proj` (its eight corners).
fn frustum_corners(view_proj: &Mat4) -> Option<[Vec3; 8]> {
    let inv = view_proj.inverse();
    let corners: [Vec3; 8] = std::array::from_fn(|i| {
        let ndc = Vec4::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { 0.0 } else { 1.0 },
            1.0,
        );
        let p = inv * ndc;
        p.xyz() / p.w
    });
    corners.iter().all(|c| c.is_finite()).then_some(corners)
}

/// A box in the light's space (map x, y and depth).
fn light_box(light: &Mat4, points: &[Vec3]) -> Option<Aabb> {
    Aabb::from_points(points.iter().map(|p| {
        let c = *light * p.extend(1.0);
        c.xyz() / c.w
    }))
}

fn intersect(a: &Aabb, b: &Aabb) -> Option<Aabb> {
    let (min, max) = (a.min.max(b.min), a.max.min(b.max));
    (min.cmple(max).all()).then_some(Aabb { min, max })
}

/// How far beyond the view and beyond a receiver a shadow still shows, in
/// the light's space (map x, y and depth, the projection's units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Margin {
    /// The reach of the scattering: a method that lights surface out of
    /// view (the ground truth's samples, texture space's maps) carries a
    /// shadow that far into the frame. The view is widened by it.
    pub reach: Vec3,
    /// The shadow filter's footprint on the map (the PCF's taps and their
    /// bilinear comparisons): each receiver is widened by it across the map.
    pub filter: Vec3,
}

impl Margin {
    pub const NONE: Margin = Margin {
        reach: Vec3::ZERO,
        filter: Vec3::ZERO,
    };

    /// The margin for a map of `light` (an orthographic projection) of
    /// `map_side` texels, with the shadow filter reaching `filter_texels`
    /// texels and the scattering `reach_world` world units.
    pub fn of(light: &Mat4, map_side: u32, filter_texels: f32, reach_world: f32) -> Margin {
        // Light-space units per world unit along each of its axes.
        let rows = Vec3::new(
            light.row(0).truncate().length(),
            light.row(1).truncate().length(),
            light.row(2).truncate().length(),
        );
        let texel = 2.0 / map_side.max(1) as f32;
        Margin {
            reach: rows * reach_world.max(0.0),
            filter: Vec3::new(filter_texels * texel, filter_texels * texel, 0.0),
        }
    }
}

fn grown(b: &Aabb, by: Vec3) -> Aabb {
    Aabb {
        min: b.min - by,
        max: b.max + by,
    }
}

/// Which of `characters` (world boxes, in frame order) cast a shadow the
/// frame can show, for a camera of `view_proj` and the key light's map
/// projection `light` (depth grows away from the light); `backdrop` is the
/// backdrop's world box, a receiver where the camera sees it (or within
/// `margin`'s reach of the view). A character in view always casts (onto
/// itself); every caster is kept when the frustum cannot be measured (a
/// degenerate projection).
pub fn casting(
    view_proj: &Mat4,
    light: &Mat4,
    characters: &[Aabb],
    backdrop: Option<&Aabb>,
    margin: &Margin,
) -> Vec<bool> {
    let everyone = vec![true; characters.len()];
    let Some(frustum) = frustum_corners(view_proj).and_then(|c| light_box(light, &c)) else {
        return everyone;
    };
    let frustum = grown(&frustum, margin.reach);
    let lit = |b: &Aabb| {
        light_box(light, &corners(b))
            .and_then(|l| intersect(&l, &frustum))
            .map(|r| grown(&r, margin.filter))
    };
    let receivers: Vec<Aabb> = characters
        .iter()
        .chain(backdrop)
        .filter(|b| in_view(view_proj, b))
        .filter_map(lit)
        .collect();
    characters
        .iter()
        .map(|c| {
            in_view(view_proj, c)
                || light_box(light, &corners(c)).is_some_and(|caster| {
                    receivers.iter().any(|r| {
                        caster.min.x <= r.max.x
                            && r.min.x <= caster.max.x
                            && caster.min.y <= r.max.y
                            && r.min.y <= caster.max.y
                            && caster.min.z <= r.max.z
                    })
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::Camera;
    use crate::scene::light::shadow_frame;

    fn unit_at(x: f32, y: f32, z: f32) -> Aabb {
        Aabb {
            min: Vec3::new(x - 0.5, y - 0.5, z - 0.5),
            max: Vec3::new(x + 0.5, y + 0.5, z + 0.5),
        }
    }

    /// A camera at +z looking down -z with a 40-degree field, square frame.
    fn camera() -> Mat4 {
        camera_to(100.0)
    }

    /// That camera with its far plane at `far`.
    fn camera_to(far: f32) -> Mat4 {
        Camera {
            eye: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_rad: 40f32.to_radians(),
            near: 0.1,
            far,
        }
        .view_proj(1.0)
    }

    #[test]
    fn boxes_in_view_and_out() {
        let vp = camera();
        assert!(in_view(&vp, &unit_at(0.0, 0.0, 0.0)));
        // Behind the camera, far to the side, past the far plane.
        assert!(!in_view(&vp, &unit_at(0.0, 0.0, 20.0)));
        assert!(!in_view(&vp, &unit_at(30.0, 0.0, 0.0)));
        assert!(!in_view(&vp, &unit_at(0.0, 0.0, -200.0)));
        // Across the left edge: part of it shows.
        let edge = 10.0 * 20f32.to_radians().tan();
        assert!(in_view(&vp, &unit_at(-edge - 0.4, 0.0, 0.0)));
    }

    /// The closed form of a light straight overhead: a box out of view casts
    /// exactly when it stands above a visible receiver.
    #[test]
    fn a_caster_out_of_view_casts_only_onto_what_is_below_it() {
        let vp = camera();
        let light = shadow_frame(Vec3::Y, Vec3::ZERO, 60.0).view_proj;
        let visible = unit_at(0.0, 0.0, 0.0);
        // Out of view above the frame's top edge (edge at y = 3.64 at z = 0),
        // straight over the visible box: its shadow falls on it.
        let above = unit_at(0.0, 8.0, 0.0);
        // Out of view above, but beside the visible box: shadow on nothing seen.
        let beside = unit_at(25.0, 8.0, 0.0);
        // Out of view below the visible box: the light is above, so its
        // shadow goes further down, away from everything seen.
        let below = unit_at(0.0, -8.0, 0.0);
        let c = casting(
            &vp,
            &light,
            &[visible, above, beside, below],
            None,
            &Margin::NONE,
        );
        assert_eq!(c, vec![true, true, false, false]);
        assert!(!in_view(&vp, &above) && !in_view(&vp, &beside) && !in_view(&vp, &below));
    }

    /// The backdrop is a receiver where it is seen: a caster over the seen
    /// floor casts, over a floor out of view does not.
    #[test]
    fn the_seen_backdrop_receives() {
        let vp = camera();
        let light = shadow_frame(Vec3::Y, Vec3::ZERO, 200.0).view_proj;
        let floor = Aabb {
            min: Vec3::new(-100.0, -3.1, -100.0),
            max: Vec3::new(100.0, -3.0, 100.0),
        };
        // Above the frame (out of view), over the seen floor.
        let over_seen = unit_at(0.0, 8.0, 0.0);
        // Out of view to the side, over floor no ray of the camera reaches.
        let over_unseen = unit_at(80.0, 8.0, 0.0);
        assert_eq!(
            casting(
                &vp,
                &light,
                &[over_seen, over_unseen],
                Some(&floor),
                &Margin::NONE
            ),
            vec![true, false]
        );
        // Without the floor, nothing seen is under either.
        assert_eq!(
            casting(&vp, &light, &[over_seen, over_unseen], None, &Margin::NONE),
            vec![false, false]
        );
    }

    /// A caster behind its receiver (further from the light) casts nothing
    /// onto it, whatever the overlap across the map.
    #[test]
    fn a_caster_behind_the_receiver_does_not_cast_onto_it() {
        let vp = camera();
        // Light from +x: depth grows toward -x.
        let light = shadow_frame(Vec3::X, Vec3::ZERO, 60.0).view_proj;
        let visible = unit_at(0.0, 0.0, 0.0);
        // Out of view at -x (the shadow side), in line with the visible box.
        let shadow_side = unit_at(-30.0, 0.0, 0.0);
        // Out of view at +x (toward the light), in line: it shades the box.
        let light_side = unit_at(30.0, 0.0, 0.0);
        assert_eq!(
            casting(
                &vp,
                &light,
                &[visible, shadow_side, light_side],
                None,
                &Margin::NONE
            ),
            vec![true, false, true]
        );
    }

    #[test]
    fn a_mesh_is_in_view_by_a_vertex_or_a_triangle_across_it() {
        use crate::scene::mesh::{Mesh, Vertex};
        let vp = camera();
        let tri = |p: [[f32; 3]; 3]| Mesh {
            vertices: p
                .iter()
                .map(|&position| Vertex {
                    position,
                    ..Default::default()
                })
                .collect(),
            indices: vec![0, 1, 2],
        };
        let id = Mat4::IDENTITY;
        assert!(mesh_in_view(
            &vp,
            &id,
            &tri([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        ));
        // Behind the camera (z > 10): nothing seen.
        let behind = tri([[0.0, 0.0, 20.0], [1.0, 0.0, 20.0], [0.0, 1.0, 20.0]]);
        assert!(!mesh_in_view(&vp, &id, &behind));
        // Moved in front by its model: seen.
        let forward = Mat4::from_translation(Vec3::new(0.0, 0.0, -20.0));
        assert!(mesh_in_view(&vp, &forward, &behind));
        // A triangle far larger than the view, every corner outside it.
        let huge = tri([
            [-100.0, -100.0, 0.0],
            [100.0, -100.0, 0.0],
            [0.0, 100.0, 0.0],
        ]);
        assert!(mesh_in_view(&vp, &id, &huge));
    }

    /// The margins: a caster whose shadow ends just beside a receiver is
    /// kept once the filter's footprint reaches it, and one beside the
    /// view once the scattering's reach does.
    #[test]
    fn margins_keep_shadows_the_filter_and_the_scattering_carry() {
        let vp = camera();
        let light = shadow_frame(Vec3::Y, Vec3::ZERO, 60.0).view_proj;
        let visible = unit_at(0.0, 0.0, 0.0);
        // Out of view above, its shadow ending 0.2 units beside the box.
        let near_miss = unit_at(1.2, 8.0, 0.0);
        assert_eq!(
            casting(&vp, &light, &[visible, near_miss], None, &Margin::NONE),
            vec![true, false]
        );
        // A 2048 map over 121 units: a texel is 0.059 units; 4 texels reach.
        let m = Margin::of(&light, 2048, 4.0, 0.0);
        assert_eq!(
            casting(&vp, &light, &[visible, near_miss], None, &m),
            vec![true, true]
        );
        // A camera whose far plane lies just past z = 0 sees a floor strip
        // there to x = 3.9: a caster over x = 5 casts onto unseen floor,
        // unless the scattering reaches 2 units into the view.
        let short = camera_to(10.6);
        let floor = Aabb {
            min: Vec3::new(-100.0, -1.1, -0.5),
            max: Vec3::new(100.0, -1.0, 0.5),
        };
        let over = unit_at(5.0, 8.0, 0.0);
        let seen_floor = Some(&floor);
        let none = casting(&short, &light, &[over], seen_floor, &Margin::NONE);
        let m = Margin::of(&light, 2048, 0.0, 2.0);
        let reach = casting(&short, &light, &[over], seen_floor, &m);
        assert_eq!((none, reach), (vec![false], vec![true]));
    }

    #[test]
    fn a_degenerate_camera_keeps_every_caster() {
        let light = shadow_frame(Vec3::Y, Vec3::ZERO, 60.0).view_proj;
        let b = [unit_at(0.0, 50.0, 0.0)];
        assert_eq!(
            casting(&Mat4::ZERO, &light, &b, None, &Margin::NONE),
            vec![true]
        );
    }
}
