//! What moves in the frame: the deform pass of every object that morphs or
//! is skinned, a crowd's characters each at its own phase (their copies of
//! the head, their rigid turns), and a run stepping through the motion
//! frame by frame (`--time-step`: [`Stepping`]). A child of `frame`, whose
//! fields it sets.

use super::*;
use crate::render::deform::{Copies, Deform, Lists};
use crate::scene::crowd_geometry::turned_by;
use crate::scene::crowd_geometry::{self, CharacterGeometry, GeometryView};
use crate::scene::crowd_motion::{Motion, Tracks};
use crate::scene::rig::ObjectPose;
use crate::skin::wrinkles;
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
    /// 0 (`scene`'s, in the order `build` made the objects). A crowd that
    /// moves deforms one copy of each moving object per character, each at
    /// its own phase, in instance-slot order (after `set_skin_groups`): the
    /// head's weights for a clip of weights, every object the file's clip
    /// moves (weights and joints) for a file's clip.
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
        // The backdrop's deform object (if any) comes first.
        let first = usize::from(scene.backdrop.is_some());
        let morphs = scene
            .backdrop
            .iter()
            .chain([&scene.head])
            .chain(&scene.parts)
            .map(|o| &o.morph);
        let file_poses: Vec<Vec<ObjectPose>> = match &scene.tracks {
            Some(t) if matches!(t.motion, Motion::File(_)) && slots.len() > 1 => by_slot
                .iter()
                .map(|&c| t.file_pose(c).unwrap_or_default())
                .collect(),
            _ => Vec::new(),
        };
        let stepping = self.stepping.as_ref().map(|s| s.tracks.motion.clone());
        self.deform = Deform::new(ctx)?;
        for (k, (obj, morph)) in self.objects.iter_mut().zip(morphs).enumerate() {
            // Which character object it is: 0 the head, then the parts. The
            // backdrop never deforms (a still mesh, made by dermis).
            let Some(i) = k.checked_sub(first) else {
                debug_assert!(morph.at_rest(), "the backdrop deforms");
                continue;
            };
            let copied = obj.mesh.copies > 1;
            let copies = match &scene.tracks {
                Some(t) if copied && matches!(t.motion, Motion::Weights(_)) => Copies {
                    weights: by_slot
                        .iter()
                        .map(|&c| match c {
                            0 => morph.weights.clone(),
                            c => t.weights(c).unwrap_or_else(|| morph.weights.clone()),
                        })
                        .collect(),
                    joints: Vec::new(),
                },
                Some(_) if copied && !file_poses.is_empty() => {
                    // Character 0 is the scene as loaded: its own bits.
                    let pose = |slot: usize| (by_slot[slot] > 0).then(|| &file_poses[slot][i]);
                    Copies {
                        weights: (0..by_slot.len())
                            .map(|s| match pose(s) {
                                Some(p) => p.weights_over(&morph.weights),
                                None => morph.weights.clone(),
                            })
                            .collect(),
                        joints: match &morph.skin {
                            Some(own) => (0..by_slot.len())
                                .map(|s| match pose(s) {
                                    Some(p) if p.joints.len() == own.matrices.len() => {
                                        p.joints.clone()
                                    }
                                    _ => own.matrices.clone(),
                                })
                                .collect(),
                            None => Vec::new(),
                        },
                    }
                }
                _ => Copies::default(),
            };
            // Stepping through a motion: what it moves deforms every frame,
            // even from a pose whose weights are all 0.
            let stepped = match &stepping {
                Some(Motion::Weights(_)) => i == 0,
                Some(Motion::File(rig)) => rig.moves(i),
                _ => false,
            };
            if morph.at_rest() && !copied && !stepped {
                continue;
            }
            // A copy per character deforms its level's vertices only
            // (`choose_geometry` set the slots' levels); one shared copy
            // deforms every vertex.
            let lists = (copied && !obj.level_vertices.is_empty()).then(|| Lists {
                copy_levels: &obj.mesh.slot_levels,
                level_vertices: &obj.level_vertices,
            });
            let id = self.deform.add(
                ctx,
                res,
                (&obj.name, obj.mesh.vertices.raw),
                morph,
                &copies,
                lists,
            )?;
            obj.deformed = Some(id);
            if let (true, Some(st)) = (stepped, self.stepping.as_mut()) {
                let own_joints = morph.skin.as_ref().map(|s| s.matrices.clone());
                st.objects.push(SteppedObject {
                    deform: self.deform.objects.len() - 1,
                    object: i,
                    characters: if copied { by_slot.clone() } else { vec![0] },
                    own_weights: morph.weights.clone(),
                    last_weights: if copies.weights.is_empty() {
                        vec![morph.weights.clone()]
                    } else {
                        copies.weights
                    },
                    last_joints: match own_joints {
                        Some(_) if !copies.joints.is_empty() => copies.joints,
                        Some(own) => vec![own],
                        None => Vec::new(),
                    },
                });
            }
        }
        Ok(())
    }
}

/// One object a stepping run poses again every frame: its deform object,
/// which character object it is (0 the head, then the parts), each copy's
/// character, its own weights (those no channel drives), and the weights
/// and joints each copy was last given.
struct SteppedObject {
    deform: usize,
    object: usize,
    characters: Vec<usize>,
    own_weights: Vec<f32>,
    last_weights: Vec<Vec<f32>>,
    last_joints: Vec<Vec<Mat4>>,
}

/// A run stepping through the motion (`--time-step`): frame k is posed at
/// the scene's time + k * step, whatever ran before it. A clip of weights
/// rewrites each copy's weights, a file's clip each moving object's weights
/// and joints (this frame's and the last's: the deform pass's velocity); a
/// rigid motion rewrites the models (every character, the first too, turns
/// from the pose its mesh was made at). The frame's framing, levels and
/// shadow casters stay those of frame 0.
pub struct Stepping {
    /// The motion at frame 0.
    pub tracks: Tracks,
    /// Frames run so far.
    frame: u64,
    /// The characters' models before any turn, and the turn's pivot.
    base: Vec<Mat4>,
    pivot: Vec3,
    /// The objects it poses.
    objects: Vec<SteppedObject>,
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
            objects: Vec::new(),
        })
    }

    /// Poses every stepped object at `t`: each copy's weights and joints
    /// now, with the last frame's beside them.
    fn pose(&mut self, deform: &mut Deform, t: &Tracks) -> Result<()> {
        // Each character's pose once, whatever objects it moves.
        let mut cache: std::collections::HashMap<usize, Option<Vec<ObjectPose>>> =
            Default::default();
        for o in &mut self.objects {
            let poses: Vec<Option<Vec<ObjectPose>>> = o
                .characters
                .iter()
                .map(|&c| cache.entry(c).or_insert_with(|| t.file_pose(c)).clone())
                .collect();
            let now: Vec<Vec<f32>> = o
                .characters
                .iter()
                .zip(&poses)
                .map(|(&c, pose)| match pose {
                    Some(p) => p[o.object].weights_over(&o.own_weights),
                    None => t.weights(c).unwrap_or_else(|| o.own_weights.clone()),
                })
                .collect();
            if !o.own_weights.is_empty() {
                deform.set_weights(o.deform, &now, &o.last_weights)?;
            }
            o.last_weights = now;
            if !o.last_joints.is_empty() {
                let now: Vec<Vec<Mat4>> = poses
                    .iter()
                    .take(o.last_joints.len())
                    .map(|p| p.as_ref().map(|p| p[o.object].joints.clone()))
                    .collect::<Option<_>>()
                    .unwrap_or_else(|| o.last_joints.clone());
                deform.set_joints(o.deform, &now, &o.last_joints)?;
                o.last_joints = now;
            }
        }
        Ok(())
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
            Some(t) => match &t.motion {
                Motion::Weights(_) | Motion::File(_) => st
                    .pose(&mut self.deform, &t)
                    .and_then(|()| self.pose_wrinkles(&t)),
                Motion::Rigid => {
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
            },
        };
        self.stepping = Some(st);
        result
    }
}

/// The head's morph target names and its own weights: what a stepping run
/// weighs each frame's pose by for the wrinkles.
pub(super) type WrinkleRig = (Vec<Option<String>>, Vec<f32>);

/// Each of `characters` characters' wrinkle zones (frame order), and the
/// rig a stepping run poses them by (`None`: a skin without wrinkle maps).
pub(super) fn wrinkle_state(
    scene: &Scene,
    characters: usize,
) -> (Vec<[f32; 8]>, Option<WrinkleRig>) {
    let zones = (0..characters)
        .map(|c| wrinkles::character_zones(scene, c))
        .collect();
    let rig = scene.head.material.wrinkles.as_ref().map(|_| {
        (
            wrinkles::head_target_names(scene),
            scene.head.morph.weights.clone(),
        )
    });
    (zones, rig)
}

impl Frame {
    /// Whether the skin's wrinkle maps are read this frame: the skin has
    /// them and a character's expression weighs a zone, or a stepping run
    /// may pose one that does.
    pub fn wrinkles_drawn(&self) -> bool {
        self.wrinkle_rig.is_some()
            && (self.stepping.is_some() || self.zones.iter().flatten().any(|&z| z > 0.0))
    }

    /// Each character's wrinkle zones at the stepping run's pose `t` (every
    /// character its head's weights there, character 0 too: stepping moves
    /// it), written to the instance buffer. Nothing without wrinkle maps.
    fn pose_wrinkles(&mut self, t: &Tracks) -> Result<()> {
        let Some((names, own)) = &self.wrinkle_rig else {
            return Ok(());
        };
        self.zones = (0..self.instances.len())
            .map(|c| wrinkles::zones_of(names, &t.head_weights(c, own)))
            .collect();
        self.instance_buffer.write_zones(&self.zones)
    }
}

impl Frame {
    /// The instance buffer's models, slot by slot: this frame's and the
    /// previous frame's (tests).
    pub fn instance_models(&self) -> Result<(Vec<Mat4>, Vec<Mat4>)> {
        self.instance_buffer.read_models()
    }
}

/// Copies of a character object's vertices (`object`: 0 the head, then
/// the parts) the frame deforms: one per character when a crowd moves it
/// at each one's phase (`Scene::tracks`: the head under a clip of weights,
/// every object a file's clip moves), else one shared by all.
pub fn object_copies(scene: &Scene, object: usize, characters: usize) -> u32 {
    let moved = match scene.tracks.as_ref().map(|t| &t.motion) {
        Some(Motion::Weights(_)) => object == 0 && !scene.head.morph.targets.is_empty(),
        Some(Motion::File(rig)) => rig.moves(object),
        _ => false,
    };
    if characters > 1 && moved {
        characters as u32
    } else {
        1
    }
}
