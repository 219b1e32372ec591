//! What each character of a frame draws: its level of detail (`lod`) and
//! whether it casts into the shadow map (`casters`). One rule, used by the
//! frame when it chooses for itself and by `dermis plan`, which writes the
//! choice into the plan file for `render --plan` to draw. Pure: no device.

use glam::{Mat4, Quat, Vec3};

use super::camera::Camera;
use super::casters;
use super::crowd_motion::Motion;
use super::lod;
use super::mesh::Aabb;
use super::morph::Morph;
use super::Scene;

/// One character's geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CharacterGeometry {
    /// Its level of detail: 0 the full meshes, `i` the head's `i`-th
    /// simplified level, each other mesh at [`mesh_level`].
    pub level: u8,
    /// Whether the shadow map draws it (its shadow can land on a receiver
    /// in view).
    pub casts_shadow: bool,
}

/// What the choice sees of the frame.
pub struct GeometryView<'a> {
    pub camera: &'a Camera,
    pub width: u32,
    pub height: u32,
    /// The key light's shadow-map projection.
    pub light_view_proj: Mat4,
    /// The backdrop's model matrix.
    pub backdrop: Mat4,
    /// The shadow map's side (texels) and how far (world units) the
    /// scattering carries a shadow: the caster test's margins.
    pub shadow_size: u32,
    pub reach_units: f32,
}

/// Texels the shadow filter reaches past its lookup: the PCF's taps
/// (`PCF_RADIUS` each side) with their 2 x 2 comparisons, and one more.
pub fn filter_texels() -> f32 {
    crate::shader_constants::PCF_RADIUS as f32 + 2.0
}

/// The characters' models with each one's rigid turn beyond the scene's
/// pose (a crowd of characters without animation, `Scene::tracks`), about
/// the point the scene's own turn was made about (`Tracks::pivot`): what
/// the frame draws them with.
pub fn turned(scene: &Scene, models: Vec<Mat4>) -> Vec<Mat4> {
    match scene.tracks.as_ref().filter(|t| t.motion == Motion::Rigid) {
        Some(t) if models.len() > 1 => turned_by(models, t.pivot, |i| t.turn(i)),
        _ => models,
    }
}

/// `models` each turned by `turn(i)` about `pivot` (model space).
pub fn turned_by(mut models: Vec<Mat4>, pivot: Vec3, turn: impl Fn(usize) -> Quat) -> Vec<Mat4> {
    for (i, m) in models.iter_mut().enumerate() {
        *m = *m
            * Mat4::from_translation(pivot)
            * Mat4::from_quat(turn(i))
            * Mat4::from_translation(-pivot);
    }
    models
}

/// How far a morph's targets can move a vertex, per axis: the sum over its
/// targets of each one's largest offset, times the largest weight it can
/// take (`max_weight`).
fn morph_reach(morph: &Morph, max_weight: f32) -> Vec3 {
    morph
        .targets
        .iter()
        .map(|t| {
            t.position
                .iter()
                .fold(Vec3::ZERO, |m, d| m.max(Vec3::from(*d).abs()))
        })
        .sum::<Vec3>()
        * max_weight
}

/// The largest weight a crowd's characters give a morph: the scene's own,
/// the crowd clip's keys (tangents included), and at least 1.
fn max_weight(scene: &Scene) -> f32 {
    let own = scene
        .head
        .morph
        .weights
        .iter()
        .fold(1.0f32, |m, w| m.max(w.abs()));
    match scene.tracks.as_ref().map(|t| &t.motion) {
        Some(Motion::Weights(clip)) => clip
            .channels
            .iter()
            .flat_map(|c| c.values.iter())
            .fold(own, |m, w| m.max(w.abs())),
        _ => own,
    }
}

/// The model-space box of everything a character draws: every vertex of
/// its head and parts as posed, and of their rest shapes widened by how
/// far the crowd's morph weights can move them (a character of a moving
/// crowd is at another phase than the posed one), and every turn of a
/// turning one, and every pose a file's clip gives it (`file_clip_bounds`).
pub fn drawn_bounds(scene: &Scene) -> Aabb {
    let w = max_weight(scene);
    let posed = std::iter::once(&scene.head)
        .chain(&scene.parts)
        .map(|o| {
            let b = o.mesh.bounds();
            // From the rest shape, which every weight in [-w, w] moves by
            // at most the reach (the posed shape is one such).
            let rest = Aabb::from_points(o.morph.rest.iter().map(|v| Vec3::from(v.position)));
            match rest.filter(|_| o.morph.skin.is_none()) {
                Some(r) => {
                    let reach = morph_reach(&o.morph, w);
                    b.union(&Aabb {
                        min: r.min - reach,
                        max: r.max + reach,
                    })
                }
                None => b,
            }
        })
        .reduce(|a, b| a.union(&b))
        .unwrap_or(scene.head_bounds);
    // A character that turns (dermis's rigid clip, at any phase or step)
    // sweeps its box about the head's centre: the cube around the sphere
    // that holds every turn of it.
    match scene.tracks.as_ref() {
        Some(t) if matches!(t.motion, Motion::File(_)) => posed.union(&file_clip_bounds(scene)),
        Some(t) if t.motion == Motion::Rigid => {
            let c = t.pivot;
            let r = (posed.min - c).abs().max((posed.max - c).abs()).length();
            Aabb {
                min: c - Vec3::splat(r),
                max: c + Vec3::splat(r),
            }
        }
        _ => posed,
    }
}

/// Samples of a file's clip between its keys (`rig::Rig::sample_times`).
const CLIP_SAMPLES: usize = 32;

/// A box's share added each side to what the clip's samples cover: between
/// two samples a joint turns by at most the keys' slerp, which can carry a
/// vertex a sliver past both.
const CLIP_MARGIN: f32 = 0.05;

/// The box of every object a file's clip moves, over the whole clip: each
/// one posed at every key and [`CLIP_SAMPLES`] between, widened by
/// [`CLIP_MARGIN`] of its size (no box without such a clip).
fn file_clip_bounds(scene: &Scene) -> Aabb {
    let objects: Vec<&super::mesh::Object> =
        std::iter::once(&scene.head).chain(&scene.parts).collect();
    let Some(Motion::File(rig)) = scene.tracks.as_ref().map(|t| &t.motion) else {
        return scene.head_bounds;
    };
    let mut out: Option<Aabb> = None;
    for t in rig.sample_times(CLIP_SAMPLES) {
        for (i, pose) in rig.pose(t).iter().enumerate() {
            let Some(o) = objects.get(i).filter(|_| rig.moves(i)) else {
                continue;
            };
            let m = pose.applied(&o.morph);
            let b = Aabb::from_points(
                super::morph::deformed(&m.rest, &m)
                    .iter()
                    .map(|v| Vec3::from(v.position)),
            );
            out = match (out, b) {
                (Some(a), Some(b)) => Some(a.union(&b)),
                (a, b) => a.or(b),
            };
        }
    }
    let b = out.unwrap_or(scene.head_bounds);
    let pad = b.size() * CLIP_MARGIN;
    Aabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}

/// Pixels an object unit covers at each character's nearest point (its
/// centre's view depth less half its bounds' diagonal, times its model's
/// largest axis scale): a level's error is judged there (a lateral extent
/// projects by depth, not by distance).
pub fn pixels_per_unit(scene: &Scene, models: &[Mat4], camera: &Camera, height: u32) -> Vec<f32> {
    let centre = scene.head_center();
    let radius = 0.5 * scene.head_bounds.size().length();
    let forward = (camera.target - camera.eye).normalize_or_zero();
    models
        .iter()
        .map(|m| {
            let scale = m
                .x_axis
                .truncate()
                .length()
                .max(m.y_axis.truncate().length())
                .max(m.z_axis.truncate().length());
            let depth = (m.transform_point3(centre) - camera.eye).dot(forward) - radius * scale;
            lod::pixels_per_unit(depth.max(camera.near), camera.fovy_rad, height) * scale
        })
        .collect()
}

/// A character's level: the coarsest level of its first mesh (its head:
/// `errors[0]`, that mesh's level errors, full mesh first) whose error
/// covers at most `max_pixels` on screen at `px_per_unit`; 0 when levels
/// are off (`max_pixels` 0) or it has none. Its other meshes take
/// [`mesh_level`] of that level's error.
pub fn character_level(errors: &[Vec<f32>], px_per_unit: f32, max_pixels: f32) -> u8 {
    match errors.first() {
        Some(head) if max_pixels > 0.0 => lod::choose(head, px_per_unit, max_pixels) as u8,
        _ => 0,
    }
}

/// The level a mesh of level errors `errors` takes in a character at
/// `level`: its coarsest whose error is at most the head's at that level
/// (`head`: the head's errors), so every mesh strays as little as the head
/// does (a small part, simplified alone, strays more at the same ratio).
pub fn mesh_level(errors: &[f32], head: &[f32], level: u8) -> u8 {
    let allowed = head
        .get(level as usize)
        .or(head.last())
        .copied()
        .unwrap_or(0.0);
    errors.iter().rposition(|&e| e <= allowed).unwrap_or(0) as u8
}

/// Every character's geometry: `models` are the characters' (turned) model
/// matrices in frame order; `errors` the level errors of each mesh a
/// character draws (empty when levels are off).
pub fn choose(
    scene: &Scene,
    models: &[Mat4],
    view: &GeometryView,
    errors: &[Vec<f32>],
    lod_pixels: f32,
) -> Vec<CharacterGeometry> {
    let drawn = drawn_bounds(scene);
    let boxes: Vec<Aabb> = models.iter().map(|m| drawn.transformed(m)).collect();
    let backdrop = scene
        .backdrop
        .as_ref()
        .map(|b| b.mesh.bounds().transformed(&view.backdrop));
    let aspect = view.width as f32 / view.height.max(1) as f32;
    let cast = casters::casting(
        &view.camera.view_proj(aspect),
        &view.light_view_proj,
        &boxes,
        backdrop.as_ref(),
        &casters::Margin::of(
            &view.light_view_proj,
            view.shadow_size,
            filter_texels(),
            view.reach_units,
        ),
    );
    let ppu = pixels_per_unit(scene, models, view.camera, view.height);
    ppu.iter()
        .zip(cast)
        .map(|(&p, casts_shadow)| CharacterGeometry {
            level: character_level(errors, p, lod_pixels),
            casts_shadow,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_character_takes_its_heads_level_and_its_parts_follow_its_error() {
        let head = vec![0.0, 0.01, 0.02, 0.04];
        let eyes = vec![0.0, 0.015, 0.05];
        // 100 px a unit, 2.5 px allowed: the head's 0.02 -> 2 px.
        assert_eq!(
            character_level(&[head.clone(), eyes.clone()], 100.0, 2.5),
            2
        );
        assert_eq!(character_level(std::slice::from_ref(&head), 100.0, 0.0), 0);
        assert_eq!(character_level(std::slice::from_ref(&head), 1.0, 1.0), 3);
        assert_eq!(character_level(&[], 1.0, 1.0), 0);
        // The eyes at the head's level 2 (0.02): their level 1 (0.015).
        assert_eq!(mesh_level(&eyes, &head, 2), 1);
        assert_eq!(mesh_level(&eyes, &head, 0), 0);
        assert_eq!(mesh_level(&eyes, &head, 3), 1);
        assert_eq!(mesh_level(&head, &head, 3), 3);
    }

    #[test]
    fn the_drawn_bounds_hold_every_target_at_full_weight() {
        let scene = crate::scene::default_scene();
        let b = drawn_bounds(&scene);
        let m = &scene.head.morph;
        assert!(!m.targets.is_empty(), "the face has its expressions");
        for t in &m.targets {
            for (i, d) in t.position.iter().enumerate() {
                let p = Vec3::from(m.rest[t.first + i].position) + Vec3::from(*d);
                assert!(p.cmpge(b.min).all() && p.cmple(b.max).all(), "{p}");
            }
        }
    }
}
