//! What moves in the frame: the deform pass of every object that morphs or
//! is skinned, a crowd's characters each at its own phase (their copies of
//! the head, their rigid turns), and a run stepping through the motion
//! frame by frame (`--time-step`: [`Stepping`]). A child of `frame`, whose
//! fields it sets.

use super::*;
use crate::render::deform::Lists;
use crate::scene::crowd_geometry::turned_by;
use crate::scene::crowd_geometry::{self, CharacterGeometry, GeometryView};
use crate::scene::crowd_motion::{Motion, Tracks};
use glam::Vec3;

impl Frame {
    /// Each character's level of detail and whether it casts into the
    /// shadow map (`crowd_geometry`): the frame's own choice (levels at
    /// `--lod-pixels`, casters whose shadow can reach a receiver in view),
    /// or under `--plan` the plan's levels, and its casters with every one
    /// the frame's own test keeps (a plan made for another framing or
    /// light never drops a shadow this frame shows); set per instance slot
    /// (after `set_skin_groups`).
    pub fn choose_geometry(&mut self, scene: &Scene) {
        let errors: Vec<Vec<f32>> = self
            .objects
            .iter()
            .filter(|o| o.kind.per_character() && !o.level_errors.is_empty())
            .map(|o| o.level_errors.clone())
            .collect();
        let own = crowd_geometry::choose(
            scene,
            &self.instances,
            &GeometryView {
                camera: &self.camera,
                width: self.extent.width,
                height: self.extent.height,
                light_view_proj: self.light_frame.view_proj,
                backdrop: self.backdrop,
                shadow_size: self.settings.shadow_size,
                reach_units: crate::reference::sampling::cutoff_mm() / self.mm_per_unit,
            },
            &errors,
            self.settings.lod_pixels,
        );
        self.geometry = match self
            .settings
            .planned_geometry()
            .filter(|g| g.len() == own.len())
        {
            Some(planned) => planned
                .iter()
                .zip(&own)
                .map(|(p, o)| CharacterGeometry {
                    level: p.level,
                    casts_shadow: p.casts_shadow || o.casts_shadow,
                })
                .collect(),
            None => own,
        };
        let slots = &self.instance_buffer.character_slots;
        let mut by_slot = vec![
            CharacterGeometry {
                level: 0,
                casts_shadow: true,
            };
            slots.len()
        ];
        for (c, &s) in slots.iter().enumerate() {
            by_slot[s as usize] = self.geometry[c];
        }
        self.casters = by_slot.iter().map(|g| g.casts_shadow).collect();
        // The head's level; every other mesh the coarsest of its own that
        // strays no more than the head's does.
        let head = errors.first().cloned().unwrap_or_default();
        for o in self
            .objects
            .iter_mut()
            .filter(|o| o.kind.per_character() && !o.level_errors.is_empty())
        {
            o.mesh.slot_levels = by_slot
                .iter()
                .map(|g| crowd_geometry::mesh_level(&o.level_errors, &head, g.level))
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
        // Stepping through a clip of weights: the head deforms every frame,
        // even from a pose whose weights are all 0.
        let steps_weights = self
            .stepping
            .as_ref()
            .is_some_and(|s| matches!(s.tracks.motion, Motion::Weights(_)));
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
            let stepped = steps_weights && obj.name == "head";
            if !morph.at_rest() || !copies.is_empty() || stepped {
                // A copy per character deforms its level's vertices only
                // (`choose_geometry` set the slots' levels); one shared
                // copy deforms every vertex.
                let lists = (!copies.is_empty() && !obj.level_vertices.is_empty()).then(|| Lists {
                    copy_levels: &obj.mesh.slot_levels,
                    level_vertices: &obj.level_vertices,
                });
                let id = self.deform.add(
                    ctx,
                    res,
                    (&obj.name, obj.mesh.vertices.raw),
                    morph,
                    copies,
                    lists,
                )?;
                obj.deformed = Some(id);
                if let (true, Some(st)) = (stepped, self.stepping.as_mut()) {
                    st.head = Some(self.deform.objects.len() - 1);
                    st.copy_characters = if copies.is_empty() {
                        vec![0]
                    } else {
                        by_slot.clone()
                    };
                    st.last = if copies.is_empty() {
                        vec![morph.weights.clone()]
                    } else {
                        copies.to_vec()
                    };
                }
            }
        }
        Ok(())
    }
}

/// A run stepping through the motion (`--time-step`): frame k is posed at
/// the scene's time + k * step, whatever ran before it. A clip of weights
/// rewrites each copy's weights (this frame's and the last's: the deform
/// pass's velocity); a rigid motion rewrites the models (every character,
/// the first too, turns from the pose its mesh was made at). The frame's
/// framing, levels and shadow casters stay those of frame 0.
pub struct Stepping {
    /// The motion at frame 0.
    pub tracks: Tracks,
    /// Frames run so far.
    frame: u64,
    /// The characters' models before any turn, and the turn's pivot.
    base: Vec<Mat4>,
    pivot: Vec3,
    /// The head's deform object, each of its copies' character and the
    /// weights it was last given.
    head: Option<usize>,
    copy_characters: Vec<usize>,
    last: Vec<Vec<f32>>,
}

impl Stepping {
    /// Stepping for `scene` when its motion has a step; `models` the
    /// characters' models before any turn.
    pub fn new(scene: &Scene, models: &[Mat4]) -> Option<Stepping> {
        let tracks = scene.tracks.clone().filter(|t| t.step.is_some())?;
        Some(Stepping {
            frame: 0,
            base: models.to_vec(),
            pivot: tracks.pivot,
            tracks,
            head: None,
            copy_characters: Vec::new(),
            last: Vec::new(),
        })
    }
}

impl Frame {
    /// Poses the next frame of a stepping run (nothing for frame 0, posed
    /// as the frame was built, or without a step). Between frames: no frame
    /// is in flight.
    pub fn advance(&mut self) -> Result<()> {
        let Some(mut st) = self.stepping.take() else {
            return Ok(());
        };
        let k = st.frame;
        st.frame += 1;
        let result = match st.tracks.at_frame(k).filter(|_| k > 0) {
            None => Ok(()),
            Some(t) => match (&t.motion, st.head) {
                (Motion::Weights(_), Some(head)) => {
                    let now: Vec<Vec<f32>> = st
                        .copy_characters
                        .iter()
                        .map(|&c| t.weights(c).unwrap_or_default())
                        .collect();
                    let r = self.deform.set_weights(head, &now, &st.last);
                    st.last = now;
                    r
                }
                (Motion::Rigid, _) => {
                    let posed = st.tracks.time;
                    let previous = std::mem::replace(
                        &mut self.instances,
                        turned_by(st.base.clone(), st.pivot, |i| t.turn_from(i, posed)),
                    );
                    self.instance_buffer.write_models(
                        &self.skin_groups,
                        (&self.instances, &previous),
                        self.backdrop,
                    )
                }
                _ => Ok(()),
            },
        };
        self.stepping = Some(st);
        result
    }
}

impl Frame {
    /// The instance buffer's models, slot by slot: this frame's and the
    /// previous frame's (tests).
    pub fn instance_models(&self) -> Result<(Vec<Mat4>, Vec<Mat4>)> {
        self.instance_buffer.read_models()
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
