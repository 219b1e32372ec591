//! A glTF file's skeleton, kept so its clip can be posed at any time after
//! loading: every character of a crowd at its own phase, and a run stepping
//! through the clip frame by frame. Pure: the loader builds it once (its
//! checks done), and posing is arithmetic on it alone.
//!
//! What it poses is what the loader poses, in the same operations, so the
//! clip at the loaded time gives the loaded joint matrices to the bit:
//! - a skinned primitive's joint: the recentring shift times the joint's
//!   world times its inverse bind matrix (as `gltf_load::skins` and
//!   `gltf_load::nodes::place` compute it);
//! - a rigid primitive under a node the clip moves: its vertices were placed
//!   by that node's world at the loaded time, so its joint is the move from
//!   there to the node's world at the asked time, in the recentred space
//!   (the identity when the node is where it was loaded);
//! - a morph weight a channel animates: the channel's value at the time (the
//!   weights no channel animates keep the object's own, command line's
//!   included).

use glam::{DMat4, DVec3, Mat4, Quat, Vec3};

use super::animation::{animated_trs, animated_weights, Clip, Path};
use super::morph::Morph;

/// A node's local transform at rest: as written (a matrix, which glTF
/// does not let a clip animate), or translation, rotation and scale.
#[derive(Clone, Debug, PartialEq)]
pub enum Local {
    Matrix(DMat4),
    /// The rest matrix (the rotation normalised in f64) and the f32
    /// translation, rotation (normalised) and scale a channel replaces parts
    /// of.
    Trs {
        matrix: DMat4,
        trs: (Vec3, Quat, Vec3),
    },
}

/// The node graph: each node's parent and rest transform.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skeleton {
    pub parent: Vec<Option<usize>>,
    pub locals: Vec<Local>,
}

impl Skeleton {
    /// Node `k`'s local matrix with `pose`'s channels at its time where
    /// `animated[k]` (a channel moves its translation, rotation or scale),
    /// its rest otherwise.
    fn local(&self, k: usize, pose: Option<(&Clip, f32)>, animated: &[bool]) -> DMat4 {
        match (&self.locals[k], pose) {
            (Local::Trs { trs, .. }, Some((clip, t))) if animated[k] => {
                let (tr, rot, sc) = animated_trs(clip, k, t, *trs);
                DMat4::from_scale_rotation_translation(sc.as_dvec3(), rot.as_dquat(), tr.as_dvec3())
            }
            (Local::Matrix(m), _) | (Local::Trs { matrix: m, .. }, _) => *m,
        }
    }

    /// Every node's world matrix posed by `pose`: which nodes its channels
    /// move found once, each local computed once, each parent chain walked
    /// once (no recursion: a chain of any depth).
    pub fn worlds(&self, pose: Option<(&Clip, f32)>) -> Vec<DMat4> {
        let n = self.locals.len();
        let animated = match pose {
            Some((clip, _)) => self.channel_nodes(clip),
            None => vec![false; n],
        };
        let mut world: Vec<Option<DMat4>> = vec![None; n];
        let mut chain = Vec::new();
        for i in 0..n {
            chain.clear();
            let mut c = Some(i);
            while let Some(k) = c.filter(|&k| world[k].is_none()) {
                chain.push(k);
                c = self.parent[k];
            }
            let mut acc = c.and_then(|k| world[k]).unwrap_or(DMat4::IDENTITY);
            for &k in chain.iter().rev() {
                acc *= self.local(k, pose, &animated);
                world[k] = Some(acc);
            }
        }
        world
            .into_iter()
            .map(|w| w.unwrap_or(DMat4::IDENTITY))
            .collect()
    }

    /// The nodes a channel of `clip` moves itself (translation, rotation
    /// or scale).
    fn channel_nodes(&self, clip: &Clip) -> Vec<bool> {
        let mut own = vec![false; self.locals.len()];
        for c in clip.channels.iter().filter(|c| c.path != Path::Weights) {
            if let Some(o) = own.get_mut(c.node) {
                *o = true;
            }
        }
        own
    }

    /// Which nodes the clip moves: those with a translation, rotation or
    /// scale channel, and every node under one.
    pub fn moved_by(&self, clip: &Clip) -> Vec<bool> {
        let own = self.channel_nodes(clip);
        (0..own.len())
            .map(|i| {
                let mut c = Some(i);
                while let Some(k) = c {
                    if own[k] {
                        return true;
                    }
                    c = self.parent[k];
                }
                false
            })
            .collect()
    }
}

/// Where one joint matrix of an object's skin comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Joint {
    /// Placed once (a rigid primitive no channel moves): the identity.
    Fixed,
    /// A skin's joint: its node's world times its inverse bind matrix.
    Skinned { node: usize, inverse_bind: DMat4 },
    /// A rigid primitive under a moving node, placed by `loaded`, the
    /// node's world at the time it was loaded.
    Rigid { node: usize, loaded: DMat4 },
}

/// What the clip moves of one object (the head or a part): its skin's
/// joints in the skin's order, and per morph target the node whose weight
/// channel drives it and which of that node's weights it takes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectRig {
    pub joints: Vec<Joint>,
    pub weights: Vec<(usize, usize)>,
}

/// One object at one time: its joint matrices (empty without a skin), and
/// per target the animated weight (`None`: the object's own).
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectPose {
    pub joints: Vec<Mat4>,
    pub weights: Vec<Option<f32>>,
}

impl ObjectPose {
    /// `morph` at this pose: its weights where a channel drives them, its
    /// skin's matrices (the last pose's become the previous).
    pub fn applied(&self, morph: &Morph) -> Morph {
        let mut m = morph.clone();
        m.weights = self.weights_over(&morph.weights);
        if let Some(skin) = &mut m.skin {
            if skin.matrices.len() == self.joints.len() {
                skin.advance(self.joints.clone());
            }
        }
        m
    }

    /// The weights this pose gives an object whose own are `own`.
    pub fn weights_over(&self, own: &[f32]) -> Vec<f32> {
        own.iter()
            .zip(&self.weights)
            .map(|(&o, w)| w.unwrap_or(o))
            .collect()
    }
}

/// A character's file clip, ready to pose: the skeleton, the clip, the
/// loader's recentring shift, the time it was loaded at, and each object's
/// sources (the head first, then the parts in the scene's order).
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    pub skeleton: Skeleton,
    pub clip: Clip,
    pub shift: DVec3,
    pub loaded_time: f32,
    pub objects: Vec<ObjectRig>,
    /// Computed once ([`Rig::new`]): every node's world at the loaded time,
    /// and which nodes the clip moves.
    loaded: Vec<DMat4>,
    moved: Vec<bool>,
}

/// The time a clip of length `duration` plays at scene time `t`: `t` up to
/// its end, then looped (as a crowd's characters loop it).
pub fn clip_time(t: f32, duration: f32) -> f32 {
    if duration > 0.0 && t > duration {
        t.rem_euclid(duration)
    } else {
        t
    }
}

impl Rig {
    /// A rig of `objects` posing `clip` over `skeleton`, loaded at
    /// `loaded_time` and moved by `-shift` (the loader's recentring).
    pub fn new(
        skeleton: Skeleton,
        clip: Clip,
        shift: DVec3,
        loaded_time: f32,
        objects: Vec<ObjectRig>,
    ) -> Rig {
        let loaded = skeleton.worlds(Some((&clip, loaded_time)));
        let moved = skeleton.moved_by(&clip);
        Rig {
            skeleton,
            clip,
            shift,
            loaded_time,
            objects,
            loaded,
            moved,
        }
    }

    /// The clip's length (seconds).
    pub fn duration(&self) -> f32 {
        self.clip.duration()
    }

    /// Whether the clip moves object `i` at all (a joint that moves, or a
    /// weight a channel drives).
    pub fn moves(&self, i: usize) -> bool {
        let Some(o) = self.objects.get(i) else {
            return false;
        };
        let moved = |n: usize| self.moved.get(n).copied().unwrap_or(false);
        o.joints.iter().any(|j| match j {
            Joint::Fixed => false,
            Joint::Skinned { node, .. } | Joint::Rigid { node, .. } => moved(*node),
        }) || o.weights.iter().any(|&(node, _)| {
            self.clip
                .channels
                .iter()
                .any(|c| c.node == node && c.path == Path::Weights)
        })
    }

    /// Every object at clip time `t` (already in the clip: [`clip_time`]).
    pub fn pose(&self, t: f32) -> Vec<ObjectPose> {
        let worlds = self.skeleton.worlds(Some((&self.clip, t)));
        let loaded = &self.loaded;
        let to_scene = DMat4::from_translation(-self.shift);
        let from_scene = DMat4::from_translation(self.shift);
        self.objects
            .iter()
            .map(|o| ObjectPose {
                joints: o
                    .joints
                    .iter()
                    .map(|j| match j {
                        Joint::Fixed => Mat4::IDENTITY,
                        Joint::Skinned { node, inverse_bind } => {
                            (to_scene * (worlds[*node] * *inverse_bind)).as_mat4()
                        }
                        // Exactly the identity where the node has not moved
                        // (the loaded pose's bits).
                        Joint::Rigid { node, .. } if worlds[*node] == loaded[*node] => {
                            Mat4::IDENTITY
                        }
                        Joint::Rigid { node, loaded } => {
                            let m = to_scene * worlds[*node] * loaded.inverse() * from_scene;
                            // The loader keeps no part placed by a world without
                            // an inverse (`gltf_load::nodes`); f32's range checked.
                            let m = m.as_mat4();
                            if m.is_finite() {
                                m
                            } else {
                                Mat4::IDENTITY
                            }
                        }
                    })
                    .collect(),
                weights: o
                    .weights
                    .iter()
                    .map(|&(node, k)| {
                        animated_weights(&self.clip, node, t).and_then(|w| w.get(k).copied())
                    })
                    .collect(),
            })
            .collect()
    }

    /// The times a pose is sampled at to bound the whole clip: every key of
    /// every channel and `between` evenly spaced over its length.
    pub fn sample_times(&self, between: usize) -> Vec<f32> {
        let d = self.duration();
        let mut t: Vec<f32> = self
            .clip
            .channels
            .iter()
            .flat_map(|c| c.times.iter().copied())
            .chain((0..=between).map(|k| d * k as f32 / between.max(1) as f32))
            .filter(|t| t.is_finite() && *t >= 0.0)
            .collect();
        t.sort_by(f32::total_cmp);
        t.dedup();
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::animation::{Channel, Interpolation};

    /// Node 0 (root) turns about +Z from 0 to 90 degrees over 1 s; node 1
    /// sits under it at (0, 1, 0); node 2 is a separate root.
    fn skeleton_and_clip() -> (Skeleton, Clip) {
        let trs = |t: Vec3| Local::Trs {
            matrix: DMat4::from_translation(t.as_dvec3()),
            trs: (t, Quat::IDENTITY, Vec3::ONE),
        };
        let s = Skeleton {
            parent: vec![None, Some(0), None],
            locals: vec![trs(Vec3::ZERO), trs(Vec3::Y), trs(Vec3::X)],
        };
        let q = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2).to_array();
        let clip = Clip {
            name: "turn".into(),
            channels: vec![
                Channel {
                    node: 0,
                    path: Path::Rotation,
                    interpolation: Interpolation::Linear,
                    times: vec![0.0, 1.0],
                    values: [[0.0, 0.0, 0.0, 1.0], q].concat(),
                    width: 4,
                },
                Channel {
                    node: 2,
                    path: Path::Weights,
                    interpolation: Interpolation::Linear,
                    times: vec![0.0, 1.0],
                    values: vec![0.0, 0.5, 1.0, 1.5],
                    width: 2,
                },
            ],
        };
        (s, clip)
    }

    #[test]
    fn a_skinned_joint_is_its_world_times_its_inverse_bind() {
        let (skeleton, clip) = skeleton_and_clip();
        // Joint 1's bind pose: at (0, 1, 0), under the root that turns.
        let rig = Rig::new(
            skeleton,
            clip,
            DVec3::new(0.0, 0.0, 2.0),
            0.0,
            vec![ObjectRig {
                joints: vec![Joint::Skinned {
                    node: 1,
                    inverse_bind: DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0)),
                }],
                weights: vec![(2, 1), (0, 0)],
            }],
        );
        let p = rig.pose(1.0);
        let v = p[0].joints[0].transform_point3(Vec3::new(1.0, 1.0, 0.0));
        // The inverse bind cancels the joint's own offset, so the vertex
        // turns with the root: (1, 1, 0) to (-1, 1, 0), less the shift's z.
        assert!((v - Vec3::new(-1.0, 1.0, -2.0)).length() < 1e-5, "{v}");
        // Node 2's second weight at 1 s is 1.5; node 0 has no weight channel.
        assert_eq!(p[0].weights, [Some(1.5), None]);
        assert_eq!(p[0].weights_over(&[7.0, 8.0]), [1.5, 8.0]);
        assert!(rig.moves(0));
    }

    #[test]
    fn a_rigid_primitive_moves_from_where_it_was_loaded() {
        let (skeleton, clip) = skeleton_and_clip();
        let loaded_at = 0.5;
        let loaded = skeleton.worlds(Some((&clip, loaded_at)));
        let rig = Rig::new(
            skeleton,
            clip,
            DVec3::ZERO,
            loaded_at,
            vec![ObjectRig {
                joints: vec![
                    Joint::Rigid {
                        node: 1,
                        loaded: loaded[1],
                    },
                    Joint::Fixed,
                ],
                weights: Vec::new(),
            }],
        );
        // At the loaded time: exactly the identity.
        assert_eq!(rig.pose(loaded_at)[0].joints[0], Mat4::IDENTITY);
        // At 1 s: a point placed at 0.5 s (node 1's origin, turned 45
        // degrees) is where node 1's origin is at 1 s: (-1, 0, 0).
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let placed = Vec3::new(-h, h, 0.0);
        let moved = rig.pose(1.0)[0].joints[0].transform_point3(placed);
        assert!(
            (moved - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6,
            "{moved}"
        );
        assert_eq!(rig.pose(1.0)[0].joints[1], Mat4::IDENTITY);
    }

    #[test]
    fn the_clip_moves_the_nodes_under_a_channel_and_loops_past_its_end() {
        let (skeleton, clip) = skeleton_and_clip();
        assert_eq!(skeleton.moved_by(&clip), [true, true, false]);
        assert_eq!(clip_time(0.25, 1.0), 0.25);
        assert_eq!(clip_time(1.0, 1.0), 1.0);
        assert_eq!(clip_time(2.5, 1.0), 0.5);
        assert_eq!(clip_time(3.0, 0.0), 3.0);
        let rig = Rig::new(
            skeleton,
            clip,
            DVec3::ZERO,
            0.0,
            vec![ObjectRig {
                // A skin's joint on node 2, which the clip does not move.
                joints: vec![
                    Joint::Fixed,
                    Joint::Skinned {
                        node: 2,
                        inverse_bind: DMat4::IDENTITY,
                    },
                ],
                weights: Vec::new(),
            }],
        );
        assert!(!rig.moves(0));
        let t = rig.sample_times(4);
        assert_eq!(t, [0.0, 0.25, 0.5, 0.75, 1.0]);
    }
}
