//! Animation channels as glTF writes them (3.11): keyframe times and values
//! of a node's translation, rotation, scale or morph weights, interpolated
//! LINEAR (rotations by spherical interpolation), STEP or CUBICSPLINE (cubic
//! Hermite over in- and out-tangents, rotations normalised after). Sampled
//! at a time, never stepped: the pose at time t is the same whatever was
//! sampled before it, so a run at a fixed step repeats. Pure, no file.

use anyhow::{bail, Result};
use glam::{Quat, Vec3};

/// What a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    Translation,
    Rotation,
    Scale,
    /// Every morph weight of the node's mesh (`width` of them).
    Weights,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Linear,
    Step,
    CubicSpline,
}

/// One channel: `times` (seconds, strictly increasing) and per key `width`
/// values (three times that for CUBICSPLINE: in-tangent, value, out-tangent).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub node: usize,
    pub path: Path,
    pub interpolation: Interpolation,
    pub times: Vec<f32>,
    pub values: Vec<f32>,
    pub width: usize,
}

impl Channel {
    /// Checks what glTF requires of a sampler; errors name `what`.
    pub fn check(&self, what: &str) -> Result<()> {
        let n = self.times.len();
        if n == 0 {
            bail!("{what} has no keyframes");
        }
        if let Some(k) = self.times.iter().position(|t| !t.is_finite()) {
            bail!("{what}: keyframe time {k} is not finite");
        }
        if let Some(k) = (1..n).find(|&k| self.times[k] <= self.times[k - 1]) {
            bail!(
                "{what}: keyframe times are not increasing ({} at {} after {} at {})",
                self.times[k],
                k,
                self.times[k - 1],
                k - 1
            );
        }
        let per_key = self.width
            * if self.interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
        if self.width == 0 || self.values.len() != n * per_key {
            bail!(
                "{what}: {} values for {n} keyframes of {per_key} (the sampler's output does not match its input)",
                self.values.len()
            );
        }
        if let Some(k) = self.values.iter().position(|v| !v.is_finite()) {
            bail!("{what}: value {k} is not finite");
        }
        Ok(())
    }

    /// The last keyframe's time.
    pub fn end(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// Key `k`'s value (the middle third of a CUBICSPLINE key).
    fn value(&self, k: usize) -> &[f32] {
        let w = self.width;
        match self.interpolation {
            Interpolation::CubicSpline => &self.values[(3 * k + 1) * w..(3 * k + 2) * w],
            _ => &self.values[k * w..(k + 1) * w],
        }
    }

    /// The channel's value at `t`: the first key's before it, the last's
    /// after it (glTF clamps), interpolated between.
    pub fn sample(&self, t: f32) -> Vec<f32> {
        let n = self.times.len();
        if t <= self.times[0] {
            return self.value(0).to_vec();
        }
        if t >= self.times[n - 1] {
            return self.value(n - 1).to_vec();
        }
        // The key interval holding t: times[k] <= t < times[k + 1].
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let s = (t - t0) / dt;
        let (a, b) = (self.value(k), self.value(k + 1));
        match self.interpolation {
            Interpolation::Step => a.to_vec(),
            Interpolation::Linear if self.path == Path::Rotation => {
                let q = quat(a).slerp(quat(b), s);
                q.to_array().to_vec()
            }
            Interpolation::Linear => a.iter().zip(b).map(|(x, y)| x + (y - x) * s).collect(),
            Interpolation::CubicSpline => {
                let w = self.width;
                let out_tangent = &self.values[(3 * k + 2) * w..(3 * k + 3) * w];
                let in_tangent = &self.values[(3 * (k + 1)) * w..(3 * (k + 1) + 1) * w];
                let (s2, s3) = (s * s, s * s * s);
                let v: Vec<f32> = (0..w)
                    .map(|i| {
                        (2.0 * s3 - 3.0 * s2 + 1.0) * a[i]
                            + (s3 - 2.0 * s2 + s) * dt * out_tangent[i]
                            + (-2.0 * s3 + 3.0 * s2) * b[i]
                            + (s3 - s2) * dt * in_tangent[i]
                    })
                    .collect();
                if self.path == Path::Rotation {
                    quat(&v).normalize().to_array().to_vec()
                } else {
                    v
                }
            }
        }
    }
}

/// A quaternion from glTF's (x, y, z, w), normalised (glTF requires unit
/// quaternions; a file's rounding is forgiven).
fn quat(v: &[f32]) -> Quat {
    Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
}

/// A clip: the channels of one glTF animation, played from 0 to its end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Clip {
    pub name: String,
    pub channels: Vec<Channel>,
}

impl Clip {
    /// The last keyframe of any channel: the clip's length (seconds).
    pub fn duration(&self) -> f32 {
        self.channels.iter().map(Channel::end).fold(0.0, f32::max)
    }
}

/// A node's local transform with a clip's channels applied at `t` (the
/// node's own translation, rotation and scale where no channel animates
/// them).
pub fn animated_trs(
    clip: &Clip,
    node: usize,
    t: f32,
    (mut tr, mut rot, mut sc): (Vec3, Quat, Vec3),
) -> (Vec3, Quat, Vec3) {
    for c in clip.channels.iter().filter(|c| c.node == node) {
        let v = c.sample(t);
        match c.path {
            Path::Translation => tr = Vec3::new(v[0], v[1], v[2]),
            Path::Rotation => rot = quat(&v),
            Path::Scale => sc = Vec3::new(v[0], v[1], v[2]),
            Path::Weights => {}
        }
    }
    (tr, rot, sc)
}

/// A node's morph weights at `t`, when a channel animates them.
pub fn animated_weights(clip: &Clip, node: usize, t: f32) -> Option<Vec<f32>> {
    clip.channels
        .iter()
        .find(|c| c.node == node && c.path == Path::Weights)
        .map(|c| c.sample(t))
}

/// Length (seconds) of dermis's rigid clip, played in a loop.
pub const RIGID_PERIOD_S: f32 = 4.0;

/// dermis's rigid clip for a character without animation (the Lee
/// Perry-Smith head has none): a turn of 25 degrees each way with a nod of 8,
/// over [`RIGID_PERIOD_S`], on node 0 (the character as a whole), LINEAR.
pub fn rigid_turn_nod() -> Clip {
    let q = |yaw: f32, pitch: f32| {
        (Quat::from_rotation_y(yaw.to_radians()) * Quat::from_rotation_x(pitch.to_radians()))
            .to_array()
    };
    let keys = [
        q(0.0, 0.0),
        q(25.0, -8.0),
        q(0.0, 0.0),
        q(-25.0, 8.0),
        q(0.0, 0.0),
    ];
    Clip {
        name: "dermis turn and nod".into(),
        channels: vec![Channel {
            node: 0,
            path: Path::Rotation,
            interpolation: Interpolation::Linear,
            times: (0..keys.len())
                .map(|k| RIGID_PERIOD_S * k as f32 / 4.0)
                .collect(),
            values: keys.iter().flatten().copied().collect(),
            width: 4,
        }],
    }
}

/// The rigid clip's rotation at `t` (looped).
pub fn rigid_rotation(t: f32) -> Quat {
    quat(&rigid_turn_nod().channels[0].sample(t.rem_euclid(RIGID_PERIOD_S)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        path: Path,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
        width: usize,
    ) -> Channel {
        Channel {
            node: 0,
            path,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
            width,
        }
    }

    #[test]
    fn linear_step_and_clamping_at_the_ends() {
        let c = channel(
            Path::Translation,
            Interpolation::Linear,
            &[1.0, 3.0],
            &[0.0, 0.0, 0.0, 2.0, 4.0, 6.0],
            3,
        );
        c.check("c").unwrap();
        assert_eq!(c.sample(0.0), [0.0, 0.0, 0.0]);
        assert_eq!(c.sample(2.0), [1.0, 2.0, 3.0]);
        assert_eq!(c.sample(9.0), [2.0, 4.0, 6.0]);
        let s = Channel {
            interpolation: Interpolation::Step,
            ..c
        };
        assert_eq!(s.sample(2.9), [0.0, 0.0, 0.0]);
        assert_eq!(s.sample(3.0), [2.0, 4.0, 6.0]);
    }

    #[test]
    fn rotations_slerp_along_the_shortest_arc() {
        let a = Quat::IDENTITY;
        let b = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let mut values = a.to_array().to_vec();
        values.extend(b.to_array());
        let c = channel(
            Path::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &values,
            4,
        );
        let q = quat(&c.sample(0.5));
        let want = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(q.angle_between(want) < 1e-5, "{q:?}");
    }

    #[test]
    fn cubic_splines_pass_through_their_keys_with_their_tangents() {
        // y = t^3 on [0, 1]: values 0 and 1, slopes 0 and 3 (in-tangent at
        // key 1 is 3, out-tangent at key 0 is 0).
        let v = [9.0, 0.0, 0.0, 3.0, 1.0, 9.0];
        let c = channel(
            Path::Weights,
            Interpolation::CubicSpline,
            &[0.0, 1.0],
            &v,
            1,
        );
        c.check("c").unwrap();
        for t in [0.0f32, 0.25, 0.5, 0.9, 1.0] {
            assert!((c.sample(t)[0] - t * t * t).abs() < 1e-6, "{t}");
        }
        // A time after the end holds the last value, not its tangent.
        assert_eq!(c.sample(2.0), [1.0]);
    }

    #[test]
    fn malformed_channels_are_one_line_errors() {
        let ok = channel(
            Path::Scale,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[1.0; 6],
            3,
        );
        let bad = |c: Channel, says: &str| {
            let e = c.check("animation 0 channel 1").unwrap_err().to_string();
            assert!(
                e.contains(says) && e.starts_with("animation 0 channel 1"),
                "{e}"
            );
        };
        bad(
            Channel {
                times: vec![1.0, 1.0],
                ..ok.clone()
            },
            "not increasing",
        );
        bad(
            Channel {
                times: vec![0.0, f32::NAN],
                ..ok.clone()
            },
            "not finite",
        );
        bad(
            Channel {
                values: vec![1.0; 5],
                ..ok.clone()
            },
            "does not match",
        );
        bad(
            Channel {
                interpolation: Interpolation::CubicSpline,
                ..ok.clone()
            },
            "does not match",
        );
        bad(
            Channel {
                times: vec![],
                values: vec![],
                ..ok.clone()
            },
            "no keyframes",
        );
        bad(
            Channel {
                values: vec![1.0, 1.0, 1.0, 1.0, f32::INFINITY, 1.0],
                ..ok
            },
            "value 4 is not finite",
        );
    }

    #[test]
    fn the_rigid_clip_turns_both_ways_and_loops() {
        let yaw = |t: f32| {
            let f = rigid_rotation(t) * Vec3::Z;
            f.x.atan2(f.z).to_degrees()
        };
        assert!(yaw(0.0).abs() < 1e-4);
        assert!((yaw(1.0) - 25.0).abs() < 0.5, "{}", yaw(1.0));
        assert!((yaw(3.0) + 25.0).abs() < 0.5);
        assert!((yaw(5.0) - yaw(1.0)).abs() < 1e-3);
        rigid_turn_nod().channels[0].check("rigid").unwrap();
    }
}
