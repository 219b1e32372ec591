//! Where the camera, the characters and the key light's shadow frustum go for a
//! scene, a layout and a shot. Pure CPU code.

use glam::{Mat4, Vec3};

use super::camera::Camera;
use super::layout::{crowd, grid_bounds, head_grid, Layout};
use super::light::{shadow_frame, LightFrame};
use super::mesh::Aabb;
use super::Scene;

/// What a shot needs to know beyond the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shot {
    pub layout: Layout,
    pub heads: u32,
    /// Camera distance from the (first) head's centre, in head heights.
    pub distance_heads: f32,
    pub fovy_deg: f32,
    pub aspect: f32,
    /// Unit vector toward the key light.
    pub light_dir: Vec3,
    /// Every character moved this many head heights toward the camera along
    /// the view after the layout is placed (a rigid crowd walking toward a
    /// fixed camera, issue 16 item 6; 0: where the layout puts them). The
    /// layout itself is placed for `distance_heads`, so the crowd keeps its
    /// rows and every character its index while it walks.
    pub walk_heads: f32,
}

/// The placed shot.
#[derive(Clone, Debug, PartialEq)]
pub struct Framing {
    pub camera: Camera,
    /// Model matrix of every character.
    pub instances: Vec<Mat4>,
    /// Bounds of every character (what the shadow map covers).
    pub bounds: Aabb,
    pub light: LightFrame,
    /// Model matrix of the backdrop: the identity, or, behind a crowd, the
    /// backdrop pushed back past the last row and scaled about the eye so it
    /// keeps its place on screen.
    pub backdrop: Mat4,
}

/// Frames `scene` for `shot`.
///
/// One head, and the crowd: the camera looks at the (first) head's centre from
/// `distance_heads` head heights along the face's forward; a crowd stands behind
/// that head, and the far plane reaches its last row. Grid: the camera pulls
/// back until the whole grid fills the old framing.
pub fn frame(scene: &Scene, shot: &Shot) -> Framing {
    frame_sized(scene, shot, &scene.head_size())
}

/// [`frame`] with the head's measures given (`Scene::head_size` of the same
/// scene): what re-framing every frame calls, the mesh measured once.
pub fn frame_sized(scene: &Scene, shot: &Shot, size: &crate::scene::HeadSize) -> Framing {
    let head_height = size.height;
    let center = size.centre;
    let local = scene.head_bounds;
    let heads = shot.heads.max(1);
    let (instances, mut camera) = match shot.layout {
        Layout::Grid => {
            let instances = head_grid(heads, &local);
            let gb = grid_bounds(heads, &local);
            let grid_h = gb.size().y.max(gb.size().x / shot.aspect);
            let (fit, target) = if heads > 1 {
                ((grid_h / head_height).max(1.0), gb.center())
            } else {
                (1.0, center)
            };
            let camera = Camera::framing(
                target,
                scene.forward,
                head_height,
                shot.distance_heads * fit,
                shot.fovy_deg,
            );
            (instances, camera)
        }
        Layout::Crowd => {
            let mut camera = Camera::framing(
                center,
                scene.forward,
                head_height,
                shot.distance_heads,
                shot.fovy_deg,
            );
            let half_width = (0.5 * shot.fovy_deg.to_radians()).tan() * shot.aspect;
            let eye_distance = shot.distance_heads * head_height;
            let instances = crowd(heads, head_height, scene.forward, eye_distance, half_width);
            if heads > 1 {
                // The last row must lie inside the far plane.
                let view = camera.view();
                let deepest = instances
                    .iter()
                    .flat_map(|m| corners(&local.transformed(m)))
                    .map(|p| -view.transform_point3(p).z)
                    .fold(0.0f32, f32::max);
                camera.far = camera.far.max(deepest + head_height);
            }
            (instances, camera)
        }
    };
    // The walk: the camera looks along -forward from in front of the first
    // head, so toward it is +forward. The far plane placed above still holds
    // (every character only comes nearer).
    let walk = scene.forward.try_normalize().unwrap_or(Vec3::Z) * shot.walk_heads * head_height;
    let instances: Vec<Mat4> = if shot.walk_heads == 0.0 {
        instances
    } else {
        instances
            .into_iter()
            .map(|m| Mat4::from_translation(walk) * m)
            .collect()
    };
    let bounds = instances
        .iter()
        .map(|m| local.transformed(m))
        .reduce(|a, b| a.union(&b))
        .unwrap_or(local);
    let light = shadow_frame(shot.light_dir, bounds.center(), bounds.bounding_radius());
    let backdrop = match &scene.backdrop {
        // A grid stands in the head's own plane: the backdrop stays where it is.
        Some(b) if shot.layout == Layout::Crowd && instances.len() > 1 => {
            behind(&camera, &b.mesh.bounds(), &bounds, head_height)
        }
        _ => Mat4::IDENTITY,
    };
    if backdrop != Mat4::IDENTITY {
        // The far plane must reach the moved backdrop too.
        let view = camera.view();
        let moved = scene
            .backdrop
            .as_ref()
            .map(|b| b.mesh.bounds().transformed(&backdrop))
            .expect("moved only when there is one");
        let deepest = corners(&moved)
            .iter()
            .map(|p| -view.transform_point3(*p).z)
            .fold(0.0f32, f32::max);
        camera.far = camera.far.max(deepest + head_height);
    }
    Framing {
        camera,
        instances,
        bounds,
        light,
        backdrop,
    }
}

/// A backdrop `bd` that `characters` would stand in: pushed back along the view
/// to `head_height` behind the deepest character, scaled about the eye by the
/// same ratio so it covers the same part of the screen. Identity when it is
/// already behind them.
fn behind(camera: &Camera, bd: &Aabb, characters: &Aabb, head_height: f32) -> Mat4 {
    let view = camera.view();
    let depth = |b: &Aabb, far: bool| {
        corners(b)
            .iter()
            .map(|p| -view.transform_point3(*p).z)
            .fold(if far { f32::MIN } else { f32::MAX }, |a, d| {
                if far {
                    a.max(d)
                } else {
                    a.min(d)
                }
            })
    };
    let (front, deepest) = (depth(bd, false), depth(characters, true));
    if front <= 0.0 || front >= deepest + head_height {
        return Mat4::IDENTITY;
    }
    let k = (deepest + head_height) / front;
    Mat4::from_translation(camera.eye)
        * Mat4::from_scale(glam::Vec3::splat(k))
        * Mat4::from_translation(-camera.eye)
}

fn corners(b: &Aabb) -> [Vec3; 8] {
    let (lo, hi) = (b.min, b.max);
    [0, 1, 2, 3, 4, 5, 6, 7].map(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::project;
    use crate::scene::default_scene;

    fn shot(layout: Layout, heads: u32) -> Shot {
        Shot {
            layout,
            heads,
            distance_heads: 5.67,
            fovy_deg: 20.0,
            aspect: 16.0 / 9.0,
            light_dir: Vec3::new(0.5, 0.5, 0.7).normalize(),
            walk_heads: 0.0,
        }
    }

    // One head frames the same in both layouts; a crowd keeps the camera and
    // fits every character between the near and far planes.
    #[test]
    fn crowd_keeps_the_camera_and_the_depth_range_covers_it() {
        let s = default_scene();
        let one = frame(&s, &shot(Layout::Crowd, 1));
        assert_eq!(one, frame(&s, &shot(Layout::Grid, 1)));
        let many = frame(&s, &shot(Layout::Crowd, 16));
        assert_eq!(many.camera.eye, one.camera.eye);
        assert_eq!(many.instances.len(), 16);
        let vp = many.camera.view_proj(16.0 / 9.0);
        for m in &many.instances {
            let c = s.head_bounds.transformed(m).center();
            let ndc = project(&vp, c);
            assert!((0.0..1.0).contains(&ndc.z), "{c} -> {ndc}");
        }
        // The backdrop moved behind the last row, and stays on screen.
        let bd = s.backdrop.as_ref().unwrap().mesh.bounds();
        let moved = bd.transformed(&many.backdrop);
        let deepest = many
            .instances
            .iter()
            .map(|m| s.head_bounds.transformed(m).min.z)
            .fold(f32::MAX, f32::min);
        assert!(moved.max.z < deepest, "{moved:?} vs {deepest}");
        assert!(project(&vp, moved.center()).z < 1.0);
        assert_eq!(one.backdrop, Mat4::IDENTITY);
        // The grid pulls the camera back instead.
        let grid = frame(&s, &shot(Layout::Grid, 16));
        assert!(
            grid.camera.eye.distance(grid.camera.target)
                > one.camera.eye.distance(one.camera.target)
        );
    }

    // Issue 11: a flat object was framed edge-on (only its shadow showed). It
    // now faces the camera with its largest extent, whichever way it lies.
    // A walking crowd keeps its camera and its rows: every character comes
    // `walk` head heights nearer the eye, its index unchanged.
    #[test]
    fn a_walk_moves_every_character_toward_the_fixed_camera() {
        let s = default_scene();
        let still = frame(&s, &shot(Layout::Crowd, 16));
        let walked = frame(
            &s,
            &Shot {
                walk_heads: 1.5,
                ..shot(Layout::Crowd, 16)
            },
        );
        assert_eq!(walked.camera.eye, still.camera.eye);
        let h = s.head_height_units();
        for (a, b) in still.instances.iter().zip(&walked.instances) {
            let (pa, pb) = (
                a.transform_point3(s.head_center()),
                b.transform_point3(s.head_center()),
            );
            let toward = s.forward.normalize() * 1.5 * h;
            assert!((pb - pa - toward).length() < 1e-3 * h, "{pa} -> {pb}");
        }
    }

    #[test]
    fn a_flat_object_faces_the_camera_with_its_largest_extent() {
        use std::f32::consts::{FRAC_PI_2, PI};
        for (m, facing) in [
            (Mat4::IDENTITY, Vec3::Z),
            (Mat4::from_rotation_y(PI), Vec3::NEG_Z),
            (Mat4::from_rotation_y(FRAC_PI_2), Vec3::X),
            (Mat4::from_rotation_x(-FRAC_PI_2), Vec3::Y),
        ] {
            let s = crate::scene::scene_from_head(
                "card",
                crate::scene::procedural::flat_card(2.0, 1.0, m, [0.6, 0.4, 0.3]),
                None,
            )
            .unwrap();
            assert!(
                (s.forward - facing).length() < 1e-5,
                "{facing}: {}",
                s.forward
            );
            assert!((s.head_height_units() - 2.0).abs() < 1e-5);
            let f = frame(&s, &shot(Layout::Crowd, 1));
            let vp = f.camera.view_proj(16.0 / 9.0);
            let ndc: Vec<Vec3> = s
                .head
                .mesh
                .vertices
                .iter()
                .map(|v| project(&vp, Vec3::from(v.position)))
                .collect();
            let lo = ndc.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
            let hi = ndc.iter().fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
            let size = hi - lo;
            // On screen, between the planes, and seen face on: its projection is
            // a rectangle of aspect about 2, not a line.
            assert!(
                lo.x > -1.0 && hi.x < 1.0 && lo.y > -1.0 && hi.y < 1.0,
                "{facing}: {lo} {hi}"
            );
            assert!(lo.z > 0.0 && hi.z < 1.0, "{facing}: {lo} {hi}");
            let (wide, tall) = (size.x * 16.0 / 9.0, size.y);
            assert!(
                wide.min(tall) > 0.2,
                "{facing}: seen edge-on ({wide} x {tall})"
            );
        }
    }

    // Issue 11: one vertex at 1e31 (one flipped exponent bit) made the plain
    // bounds a universe: the head was a point, the shadow map covered 1e31 and
    // the frame was black. The framing now leaves the vertex out.
    #[test]
    fn a_far_outlier_vertex_does_not_move_the_framing() {
        let clean = crate::scene::egg_scene();
        let good = crate::scene::scene_from_head("clean", clean.head.clone(), None).unwrap();
        assert_eq!(
            crate::scene::head_measure::inlier_bounds(&good.head.mesh).1,
            0
        );
        for far in [
            Vec3::new(0.0, 1e31, 0.0),
            Vec3::new(-3e30, 0.0, 1e31),
            Vec3::splat(1e4),
        ] {
            let mut head = clean.head.clone();
            head.mesh.vertices[100].position = far.into();
            let bad = crate::scene::scene_from_head("outlier", head, None).unwrap();
            assert_eq!(bad.forward, good.forward);
            let (a, b) = (
                frame(&good, &shot(Layout::Crowd, 1)),
                frame(&bad, &shot(Layout::Crowd, 1)),
            );
            let h = good.head_height_units();
            assert!((bad.head_height_units() - h).abs() < 0.02 * h, "{far}");
            assert!(
                (bad.mm_per_unit / good.mm_per_unit - 1.0).abs() < 0.02,
                "{far}"
            );
            assert!(a.camera.eye.distance(b.camera.eye) < 0.05 * h, "{far}");
            assert!(
                a.camera.target.distance(b.camera.target) < 0.05 * h,
                "{far}"
            );
            assert!(
                (b.bounds.size() - a.bounds.size()).length() < 0.05 * h,
                "{far}"
            );
            assert!((b.light.depth_range_units / a.light.depth_range_units - 1.0).abs() < 0.05);
        }
    }
}
