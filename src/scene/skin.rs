//! Skins (glTF 3.7.3): each vertex moved by up to eight joints (two sets of
//! `JOINTS_n`/`WEIGHTS_n`), the weighted sum of its joint matrices applied to
//! its bind-space position (after its morph targets, as glTF orders them).
//! Pure: the GPU's deform pass (`deform.comp`) computes [`apply`] exactly,
//! operation for operation, as it does `morph::apply`.
//!
//! A joint matrix is the joint's world transform at the pose times its
//! inverse bind matrix, in the scene's space: the loader's recentring and a
//! character's rigid turn multiply it on the left, and the bind-space rest
//! never changes.

use anyhow::{bail, Result};
use glam::{Mat4, Vec3, Vec4};

use super::vertex::Vertex;

/// Joint slots a vertex has at most (two glTF sets of four).
pub const SLOTS: usize = 8;

/// How far a vertex's weights may sum from 1. glTF requires normalised
/// weights; exporters write 8-bit ones whose sum is off by a few 1/255
/// (the validator allows the same: 2e-2 over four 8-bit weights).
pub const WEIGHT_SUM_TOLERANCE: f32 = 2e-2;

/// An object's joints and its vertices' influences.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skin {
    /// Per vertex: its joints (indices into `matrices`), unused slots 0.
    pub joints: Vec<[u32; SLOTS]>,
    /// Per vertex: the joints' weights, unused slots 0.
    pub weights: Vec<[f32; SLOTS]>,
    /// Slots in use: 4 (one set) or 8 (two).
    pub slots: usize,
    /// Each joint's matrix at the pose (scene space).
    pub matrices: Vec<Mat4>,
    /// Each joint's matrix at the previous frame's pose (velocity); the
    /// pose's own where there was no frame before.
    pub previous: Vec<Mat4>,
}

impl Skin {
    /// Checks the influences against an object of `vertices` vertices: one
    /// per vertex, joints in range, weights finite, not negative, summing to 1
    /// (within [`WEIGHT_SUM_TOLERANCE`]); matrices finite.
    pub fn check(&self, vertices: usize) -> Result<()> {
        if self.slots != 4 && self.slots != SLOTS {
            bail!("a skin has {} joint slots a vertex, not 4 or 8", self.slots);
        }
        if self.joints.len() != vertices || self.weights.len() != vertices {
            bail!(
                "a skin gives joints for {} and weights for {} vertices, but the mesh has {vertices}",
                self.joints.len(),
                self.weights.len()
            );
        }
        if self.matrices.is_empty() || self.previous.len() != self.matrices.len() {
            bail!(
                "a skin has {} joint matrices ({} previous)",
                self.matrices.len(),
                self.previous.len()
            );
        }
        if let Some(k) = self
            .matrices
            .iter()
            .chain(&self.previous)
            .position(|m| !m.is_finite())
        {
            bail!("joint {} has a non-finite matrix", k % self.matrices.len());
        }
        let count = self.matrices.len() as u32;
        for (v, (j, w)) in self.joints.iter().zip(&self.weights).enumerate() {
            let mut sum = 0.0f32;
            for s in 0..SLOTS {
                let (j, w) = (j[s], w[s]);
                if !w.is_finite() || w < 0.0 {
                    bail!("vertex {v}: joint weight {w} is not a finite number >= 0");
                }
                if s >= self.slots && w != 0.0 {
                    bail!(
                        "vertex {v}: weight in slot {s} of a {}-slot skin",
                        self.slots
                    );
                }
                if w > 0.0 && j >= count {
                    bail!("vertex {v}: joint {j} is out of range (the skin has {count} joints)");
                }
                sum += w;
            }
            if (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
                bail!(
                    "vertex {v}: joint weights sum to {sum}, not 1 (glTF requires normalised weights)"
                );
            }
        }
        Ok(())
    }

    /// Moves the scene under the skin by `m` (the skin's world with it):
    /// every joint matrix, current and previous, is `m` times it.
    pub fn transform(&mut self, m: &Mat4) {
        for j in self.matrices.iter_mut().chain(&mut self.previous) {
            *j = *m * *j;
        }
    }

    /// Sets a new pose: the current matrices become the previous.
    pub fn advance(&mut self, matrices: Vec<Mat4>) {
        self.previous = std::mem::replace(&mut self.matrices, matrices);
    }
}

/// `m`'s columns 0..3 times `v`'s x, y, z, plus `w` times column 3: each
/// product and sum rounded alone, in this order (the shader's `precise`).
fn transform(m: &Mat4, v: Vec3, w: f32) -> Vec3 {
    let c = |i: usize| m.col(i).truncate();
    let mut r = c(0) * v.x;
    r += c(1) * v.y;
    r += c(2) * v.z;
    if w != 0.0 {
        r += c(3) * w;
    }
    r
}

/// The vertex `v` moved by its influences `(joints, weights)` with
/// `matrices`: the weighted sum of each joint's transform of the position
/// (a point), normal and tangent (directions), slots in order, zero weights
/// skipped. Normals take the joint matrix itself, not its inverse transpose
/// (as glTF viewers do; exact for the rigid and uniformly scaled joints of
/// characters), and stay unnormalised.
fn skin_vertex(v: &Vertex, joints: &[u32], weights: &[f32], matrices: &[Mat4]) -> Vertex {
    let (p, n) = (Vec3::from(v.position), Vec3::from(v.normal));
    let t = Vec4::from(v.tangent).truncate();
    let (mut sp, mut sn, mut st) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for (&j, &w) in joints.iter().zip(weights) {
        if w == 0.0 {
            continue;
        }
        let m = &matrices[j as usize];
        sp += transform(m, p, 1.0) * w;
        sn += transform(m, n, 0.0) * w;
        st += transform(m, t, 0.0) * w;
    }
    Vertex {
        position: sp.into(),
        normal: sn.into(),
        uv: v.uv,
        tangent: [st.x, st.y, st.z, v.tangent[3]],
    }
}

/// `morphed` moved by `skin`'s influences with `matrices` (its pose's or
/// the previous pose's).
fn skinned<'a>(
    morphed: &'a [Vertex],
    skin: &'a Skin,
    matrices: &'a [Mat4],
) -> impl Iterator<Item = Vertex> + 'a {
    let s = skin.slots;
    morphed
        .iter()
        .zip(skin.joints.iter().zip(&skin.weights))
        .map(move |(v, (j, w))| skin_vertex(v, &j[..s], &w[..s], matrices))
}

/// The skinned vertices exactly as the deform pass writes them (normals and
/// tangents unnormalised), from `morphed` (the rest after its targets).
pub fn apply(morphed: &[Vertex], skin: &Skin) -> Vec<Vertex> {
    skinned(morphed, skin, &skin.matrices).collect()
}

/// The skinned positions at the previous pose (the deform pass's previous
/// positions), from the vertices morphed at the previous weights.
pub fn apply_previous(morphed: &[Vertex], skin: &Skin) -> Vec<[f32; 3]> {
    skinned(morphed, skin, &skin.previous)
        .map(|v| v.position)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn vertex(p: [f32; 3]) -> Vertex {
        Vertex {
            position: p,
            normal: [0.0, 0.0, 1.0],
            uv: [0.25, 0.5],
            tangent: [1.0, 0.0, 0.0, -1.0],
        }
    }

    fn one_joint(j: u32, n: usize) -> (Vec<[u32; SLOTS]>, Vec<[f32; SLOTS]>) {
        let mut w = [0.0; SLOTS];
        w[0] = 1.0;
        let mut js = [0; SLOTS];
        js[0] = j;
        (vec![js; n], vec![w; n])
    }

    fn skin(joints: Vec<[u32; SLOTS]>, weights: Vec<[f32; SLOTS]>, m: Vec<Mat4>) -> Skin {
        Skin {
            joints,
            weights,
            slots: 4,
            previous: m.clone(),
            matrices: m,
        }
    }

    #[test]
    fn identity_joints_leave_the_mesh_to_the_bit() {
        let rest: Vec<Vertex> = (0..5)
            .map(|i| vertex([0.1 * i as f32, -3.7, 1e-3 * i as f32]))
            .collect();
        let (j, w) = one_joint(0, rest.len());
        let s = skin(j, w, vec![Mat4::IDENTITY]);
        s.check(rest.len()).unwrap();
        assert_eq!(apply(&rest, &s), rest);
    }

    #[test]
    fn a_vertex_between_two_joints_moves_by_their_weights() {
        // Closed form: weights 0.25 / 0.75 between a still joint and one
        // moved by (4, 0, 0) put the vertex 3 along x; its normal, a
        // direction, does not move.
        let rest = vec![vertex([1.0, 2.0, 3.0])];
        let mut j = [0; SLOTS];
        j[1] = 1;
        let mut w = [0.0; SLOTS];
        w[0] = 0.25;
        w[1] = 0.75;
        let s = skin(
            vec![j],
            vec![w],
            vec![
                Mat4::IDENTITY,
                Mat4::from_translation(Vec3::new(4.0, 0.0, 0.0)),
            ],
        );
        s.check(1).unwrap();
        let out = apply(&rest, &s);
        assert_eq!(out[0].position, [4.0, 2.0, 3.0]);
        assert_eq!(out[0].normal, [0.0, 0.0, 1.0]);
        assert_eq!(out[0].uv, rest[0].uv);
        assert_eq!(out[0].tangent[3], -1.0);
    }

    #[test]
    fn a_rigid_joint_turns_positions_and_directions_alike() {
        let q = Quat::from_rotation_y(0.7);
        let m = Mat4::from_rotation_translation(q, Vec3::new(0.0, 5.0, 0.0));
        let rest = vec![vertex([1.0, 0.0, 0.0]), vertex([0.0, 1.0, -2.0])];
        let (j, w) = one_joint(0, 2);
        let out = apply(&rest, &skin(j, w, vec![m]));
        for (a, b) in rest.iter().zip(&out) {
            let want = m.transform_point3(Vec3::from(a.position));
            assert!((Vec3::from(b.position) - want).length() < 1e-6);
            let n = q * Vec3::from(a.normal);
            assert!((Vec3::from(b.normal) - n).length() < 1e-6);
        }
    }

    #[test]
    fn the_previous_pose_uses_the_previous_matrices() {
        let rest = vec![vertex([1.0, 0.0, 0.0])];
        let (j, w) = one_joint(0, 1);
        let mut s = skin(j, w, vec![Mat4::IDENTITY]);
        s.advance(vec![Mat4::from_translation(Vec3::Y)]);
        assert_eq!(apply(&rest, &s)[0].position, [1.0, 1.0, 0.0]);
        assert_eq!(apply_previous(&rest, &s)[0], [1.0, 0.0, 0.0]);
        // A move of the scene moves both poses.
        s.transform(&Mat4::from_translation(Vec3::Z));
        assert_eq!(apply(&rest, &s)[0].position, [1.0, 1.0, 1.0]);
        assert_eq!(apply_previous(&rest, &s)[0], [1.0, 0.0, 1.0]);
    }

    #[test]
    fn bad_influences_are_one_line_errors() {
        let (j, w) = one_joint(0, 2);
        let good = skin(j, w, vec![Mat4::IDENTITY, Mat4::IDENTITY]);
        good.check(2).unwrap();
        let err = |s: &Skin| format!("{:#}", s.check(2).unwrap_err());
        let mut s = good.clone();
        s.joints[1][0] = 2;
        assert!(err(&s).contains("joint 2 is out of range (the skin has 2 joints)"));
        let mut s = good.clone();
        s.weights[0][0] = 0.5;
        assert!(err(&s).contains("vertex 0: joint weights sum to 0.5, not 1"));
        let mut s = good.clone();
        s.weights[1][0] = f32::NAN;
        assert!(err(&s).contains("vertex 1: joint weight NaN"));
        let mut s = good.clone();
        s.weights[1] = [0.5, -0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(err(&s).contains("is not a finite number >= 0"));
        let mut s = good.clone();
        s.weights[1] = [0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0];
        assert!(err(&s).contains("slot 4 of a 4-slot skin"));
        let mut s = good.clone();
        s.matrices[1].x_axis.x = f32::INFINITY;
        assert!(err(&s).contains("joint 1 has a non-finite matrix"));
        let mut s = good.clone();
        s.joints.pop();
        assert!(err(&s).contains("joints for 1 and weights for 2 vertices"));
        // An 8-bit exporter's sum, off by 1/255, passes.
        let mut s = good;
        s.weights[0][0] = 254.0 / 255.0;
        s.check(2).unwrap();
    }
}
