//! What moves in the frame: the deform pass of every object that morphs or
//! is skinned, and a crowd's characters each at its own phase (their copies
//! of the head, their rigid turns). A child of `frame`, whose fields it sets.

use super::*;
use crate::scene::crowd_motion::Motion;
use crate::scene::lod;

impl Frame {
    /// Each character's level of detail (`--lod-pixels`): the coarsest level
    /// of each of its meshes whose error, projected at the view depth of its
    /// nearest point (its centre's less half its bounds' diagonal), covers at
    /// most that many pixels; set
    /// per instance slot (after `set_skin_groups`).
    pub fn choose_levels(&mut self, scene: &Scene) {
        let max_px = self.settings.lod_pixels;
        if max_px <= 0.0 {
            return;
        }
        let centre = scene.head_center();
        // The character's nearest point is about half its bounds' diagonal
        // nearer than its centre; an error is judged at the view depth there
        // (a lateral extent projects by depth, not by distance).
        let radius = 0.5 * scene.head_bounds.size().length();
        let forward = (self.camera.target - self.camera.eye).normalize_or_zero();
        let slots = &self.instance_buffer.character_slots;
        let mut px_per_unit = vec![0.0f32; slots.len()];
        for (c, &s) in slots.iter().enumerate() {
            let m = self.instances[c];
            let scale = m
                .x_axis
                .truncate()
                .length()
                .max(m.y_axis.truncate().length())
                .max(m.z_axis.truncate().length());
            let depth =
                (m.transform_point3(centre) - self.camera.eye).dot(forward) - radius * scale;
            px_per_unit[s as usize] = lod::pixels_per_unit(
                depth.max(self.camera.near),
                self.camera.fovy_rad,
                self.extent.height,
            ) * scale;
        }
        for o in self
            .objects
            .iter_mut()
            .filter(|o| !o.level_errors.is_empty())
        {
            o.mesh.slot_levels = px_per_unit
                .iter()
                .map(|&ppu| lod::choose(&o.level_errors, ppu, max_px) as u8)
                .collect();
        }
    }

    /// The deform pass of every object with a skin or morph weights not all
    /// 0 (`scene`'s, in the order `build` made the objects); a crowd playing
    /// a clip of weights deforms one copy of the head per character, each at
    /// its own phase, in instance-slot order (after `set_skin_groups`).
    pub fn enable_deform(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        res: &mut Resources,
    ) -> Result<()> {
        let slots = &self.instance_buffer.character_slots;
        let mut by_slot = vec![0usize; slots.len()];
        for (c, &s) in slots.iter().enumerate() {
            by_slot[s as usize] = c;
        }
        let copy_weights: Vec<Vec<f32>> = match &scene.tracks {
            Some(t) if head_copies(scene, slots.len()) > 1 => by_slot
                .iter()
                .map(|&c| match c {
                    0 => scene.head.morph.weights.clone(),
                    c => t
                        .weights(c)
                        .unwrap_or_else(|| scene.head.morph.weights.clone()),
                })
                .collect(),
            _ => Vec::new(),
        };
        let morphs = scene
            .backdrop
            .iter()
            .chain([&scene.head])
            .chain(&scene.parts)
            .map(|o| &o.morph);
        self.deform = Deform::new(ctx)?;
        for (obj, morph) in self.objects.iter_mut().zip(morphs) {
            let copies: &[Vec<f32>] = if obj.mesh.copies > 1 {
                &copy_weights
            } else {
                &[]
            };
            if !morph.at_rest() || !copies.is_empty() {
                let id =
                    self.deform
                        .add(ctx, res, &obj.name, obj.mesh.vertices.raw, morph, copies)?;
                obj.deformed = Some(id);
            }
        }
        Ok(())
    }
}

/// Copies of the head's vertices the frame deforms: one per character when
/// a crowd of it plays a clip of morph weights, each at its own phase
/// (`Scene::tracks`); else one shared by all.
pub fn head_copies(scene: &Scene, characters: usize) -> u32 {
    match &scene.tracks {
        Some(t)
            if characters > 1
                && matches!(t.motion, Motion::Weights(_))
                && !scene.head.morph.targets.is_empty() =>
        {
            characters as u32
        }
        _ => 1,
    }
}

/// The characters' models with each one's rigid turn beyond the scene's
/// pose (a crowd of characters without animation, `Scene::tracks`), about
/// the head's centre.
pub(super) fn turned(scene: &Scene, mut models: Vec<Mat4>) -> Vec<Mat4> {
    if let Some(t) = scene.tracks.as_ref().filter(|t| t.motion == Motion::Rigid) {
        if models.len() > 1 {
            let c = scene.head_center();
            for (i, m) in models.iter_mut().enumerate() {
                *m = *m
                    * Mat4::from_translation(c)
                    * Mat4::from_quat(t.turn(i))
                    * Mat4::from_translation(-c);
            }
        }
    }
    models
}
