//! A moving crowd: every character plays the scene's motion at its own
//! phase, drawn from a seed, so no two are in step and a run repeats. The
//! first character (frame index 0) has phase 0: it is the scene as posed,
//! what every CPU consumer reads. Pure: the renderer asks each character's
//! morph weights and rigid turn of [`Tracks`].

use glam::{Quat, Vec3};

use std::sync::Arc;

use super::animation::{animated_weights, rigid_rotation, Clip, RIGID_PERIOD_S};
use super::rig::{clip_time, ObjectPose, Rig};

/// The seed a crowd's phases are drawn from unless `--crowd-seed` says.
pub const DEFAULT_SEED: u64 = 0x5EED_0029;

/// What moves in a crowd, and when.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// The head's morph weights along a clip (node 0's weight channel: the
    /// face's expressions), looped over its length.
    Weights(Clip),
    /// dermis's rigid turn and nod (a character without animation).
    Rigid,
    /// A glTF file's own clip: its skins' joints, the rigid parts under the
    /// nodes it moves, and its weight channels (`rig`), looped over its
    /// length.
    File(Arc<Rig>),
}

/// The crowd's motion at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct Tracks {
    /// The scene's time (`--time`): character 0's.
    pub time: f32,
    pub seed: u64,
    pub motion: Motion,
    /// The time each frame advances it (`--time-step`); `None`: every
    /// frame at `time`.
    pub step: Option<f32>,
    /// The point a rigid motion turns the character about (model space):
    /// the head's centre before the scene's own turn, so a turn beyond it
    /// composes with it exactly.
    pub pivot: Vec3,
}

/// SplitMix64's finaliser: a well-mixed 64-bit hash of `x`.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Character `c`'s phase in [0, 1) of the motion's period: 0 for the first,
/// a hash of the seed and `c` for the others (24 bits: exact in f32).
pub fn phase(seed: u64, c: usize) -> f32 {
    if c == 0 {
        return 0.0;
    }
    (mix(seed ^ mix(c as u64)) >> 40) as f32 / (1u64 << 24) as f32
}

impl Tracks {
    /// The motion's period (seconds): the clip's length, or the rigid
    /// clip's.
    pub fn period(&self) -> f32 {
        match &self.motion {
            Motion::Weights(clip) => clip.duration(),
            Motion::Rigid => RIGID_PERIOD_S,
            Motion::File(rig) => rig.duration(),
        }
    }

    /// Character `c`'s time: the scene's plus its phase of the period,
    /// wrapped into the period (so every character stays on its loop).
    pub fn time_of(&self, c: usize) -> f32 {
        let p = self.period();
        match (c, &self.motion) {
            // The rigid clip is periodic in itself.
            (0, Motion::Rigid) => self.time,
            _ if p <= 0.0 => self.time,
            // As the file was loaded: up to its end, then looped.
            (0, Motion::File(_)) => clip_time(self.time, p),
            (0, _) => self.time.rem_euclid(p),
            _ => (self.time + phase(self.seed, c) * p).rem_euclid(p),
        }
    }

    /// Character `c`'s morph weights (`None`: the scene's own, for a rigid
    /// motion).
    pub fn weights(&self, c: usize) -> Option<Vec<f32>> {
        match &self.motion {
            Motion::Weights(clip) => animated_weights(clip, 0, self.time_of(c)),
            Motion::Rigid | Motion::File(_) => None,
        }
    }

    /// Character `c`'s head weights at its own time, given the head's own
    /// `own` (those no channel drives): a clip of weights', or a file
    /// clip's over `own`; `own` under a rigid motion.
    pub fn head_weights(&self, c: usize, own: &[f32]) -> Vec<f32> {
        match &self.motion {
            Motion::Weights(_) => self.weights(c).unwrap_or_else(|| own.to_vec()),
            Motion::File(rig) if rig.moves(0) => self
                .file_pose(c)
                .and_then(|p| p.first().map(|h| h.weights_over(own)))
                .unwrap_or_else(|| own.to_vec()),
            _ => own.to_vec(),
        }
    }

    /// Character `c`'s objects (head, then parts) posed by a file's clip
    /// at its own time (`None`: another motion).
    pub fn file_pose(&self, c: usize) -> Option<Vec<ObjectPose>> {
        match &self.motion {
            Motion::File(rig) => Some(rig.pose(self.time_of(c))),
            _ => None,
        }
    }

    /// The motion `frame` frames on (`step` each), from `time`: what a
    /// renderer stepping through it draws at that frame (`None` without a
    /// step).
    pub fn at_frame(&self, frame: u64) -> Option<Tracks> {
        let step = self.step?;
        Some(Tracks {
            time: self.time + frame as f32 * step,
            ..self.clone()
        })
    }

    /// The turn character `c` makes beyond a pose made at `posed` (the
    /// scene's mesh turned at that time): its whole rigid pose at this time
    /// less that one (identity for a clip of weights).
    pub fn turn_from(&self, c: usize, posed: f32) -> Quat {
        match self.motion {
            Motion::Rigid => rigid_rotation(self.time_of(c)) * rigid_rotation(posed).inverse(),
            _ => Quat::IDENTITY,
        }
    }

    /// The turn character `c` makes beyond the scene's own pose (identity
    /// for character 0 and for a clip of weights).
    pub fn turn(&self, c: usize) -> Quat {
        match self.motion {
            Motion::Rigid if c > 0 => {
                rigid_rotation(self.time_of(c)) * rigid_rotation(self.time).inverse()
            }
            _ => Quat::IDENTITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::expressions::expression_clip;

    #[test]
    fn phases_are_seeded_spread_and_the_first_is_zero() {
        let a: Vec<f32> = (0..256).map(|c| phase(7, c)).collect();
        let b: Vec<f32> = (0..256).map(|c| phase(7, c)).collect();
        assert_eq!(a, b, "the same seed, the same phases");
        assert_eq!(a[0], 0.0);
        assert_ne!(a, (0..256).map(|c| phase(8, c)).collect::<Vec<_>>());
        assert!(a.iter().all(|&p| (0.0..1.0).contains(&p)));
        // No two in step.
        let mut s = a[1..].to_vec();
        s.sort_by(f32::total_cmp);
        assert!(s.windows(2).all(|w| w[0] < w[1]));
        // Spread over the period: every tenth holds some (255 draws, a
        // tenth expects 25.5; 8 would be 3.5 sigma low).
        for d in 0..10 {
            let n = s.iter().filter(|&&p| (p * 10.0) as usize == d).count();
            assert!(n >= 8, "decile {d}: {n}");
        }
    }

    #[test]
    fn each_character_plays_the_clip_at_its_own_time() {
        let t = Tracks {
            time: 1.0,
            seed: DEFAULT_SEED,
            motion: Motion::Weights(expression_clip()),
            step: None,
            pivot: Vec3::ZERO,
        };
        let clip = expression_clip();
        assert_eq!(t.weights(0), animated_weights(&clip, 0, 1.0));
        for c in 1..8 {
            let tc = t.time_of(c);
            assert!((0.0..clip.duration()).contains(&tc));
            assert_eq!(t.weights(c), animated_weights(&clip, 0, tc));
            assert_eq!(t.turn(c), Quat::IDENTITY);
        }
        let r = Tracks {
            motion: Motion::Rigid,
            ..t
        };
        assert_eq!(r.turn(0), Quat::IDENTITY);
        assert_eq!(r.weights(3), None);
        // Character c's turn on top of the scene's pose is its own pose.
        let c = 5;
        let whole = r.turn(c) * rigid_rotation(r.time);
        assert!(whole.angle_between(rigid_rotation(r.time_of(c))) < 1e-5);
        assert!(r.turn_from(c, r.time).angle_between(r.turn(c)) < 1e-6);
    }

    #[test]
    fn a_step_moves_every_character_along_its_own_track() {
        let t = Tracks {
            time: 1.0,
            seed: DEFAULT_SEED,
            motion: Motion::Rigid,
            step: Some(0.25),
            pivot: Vec3::ZERO,
        };
        assert_eq!(t.at_frame(0).unwrap(), t);
        let f3 = t.at_frame(3).unwrap();
        assert_eq!(f3.time, 1.75);
        // Character 0 turns from the posed mesh by the clip's change.
        let q = f3.turn_from(0, t.time) * rigid_rotation(1.0);
        assert!(q.angle_between(rigid_rotation(1.75)) < 1e-5);
        for c in 1..5 {
            let q = f3.turn_from(c, t.time) * rigid_rotation(1.0);
            assert!(q.angle_between(rigid_rotation(f3.time_of(c))) < 1e-5);
            // Each keeps its phase: its time moved by the step sum.
            let d = (f3.time_of(c) - t.time_of(c)).rem_euclid(RIGID_PERIOD_S);
            assert!((d - 0.75).abs() < 1e-4, "{d}");
        }
        assert!(Tracks { step: None, ..t }.at_frame(1).is_none());
    }

    /// A clip of weights loops for the first character too: past its end
    /// it plays from its start, as every other character does.
    #[test]
    fn the_first_character_loops_the_clip_as_the_others_do() {
        let clip = expression_clip();
        let p = clip.duration();
        let t = Tracks {
            time: p + 1.0,
            seed: DEFAULT_SEED,
            motion: Motion::Weights(clip.clone()),
            step: None,
            pivot: Vec3::ZERO,
        };
        assert!((t.time_of(0) - 1.0).abs() < 1e-5);
        assert_eq!(t.weights(0), animated_weights(&clip, 0, t.time_of(0)));
        let early = Tracks {
            time: 1.0,
            ..t.clone()
        };
        assert_eq!(early.time_of(0), 1.0);
    }
}
