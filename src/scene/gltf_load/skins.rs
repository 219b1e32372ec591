//! Skins: a skin's joint matrices from the posed node worlds and its
//! inverse bind matrices, and a skinned primitive appended in bind space
//! with its influences checked (`scene::skin` moves it).

use anyhow::{bail, Result};
use glam::{DMat4, DVec3};

use super::primitives::Part;
use crate::scene::gltf_accessor::{read_floats, Use};
use crate::scene::gltf_source::Source;
use crate::scene::mesh::Mesh;
use crate::scene::morph::{Morph, MorphTarget};
use crate::scene::rig::Joint;
use crate::scene::skin::{Skin, SLOTS};

/// A skinned primitive's influences and joint matrices (world times
/// inverse bind, in f64 until the scene is placed).
#[derive(Clone, Debug)]
pub(super) struct SpanSkin {
    pub(super) joints: Vec<[u32; SLOTS]>,
    pub(super) weights: Vec<[f32; SLOTS]>,
    pub(super) slots: usize,
    pub(super) matrices: Vec<DMat4>,
    /// Where each matrix comes from (what a `rig::Rig` poses again).
    pub(super) sources: Vec<Joint>,
}

/// A skin's joint matrices: each joint's world times its inverse bind
/// matrix (identity where the skin gives none), checked finite; and each
/// one's node and inverse bind matrix.
pub(super) fn skin_matrices(
    src: &Source,
    skin: &gltf::Skin,
    worlds: &[DMat4],
) -> Result<(Vec<DMat4>, Vec<Joint>)> {
    let label = format!(
        "skin {}{}",
        skin.index(),
        skin.name()
            .map(|n| format!(" '{}'", crate::scene::gltf_source::short(n)))
            .unwrap_or_default()
    );
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    if joints.is_empty() {
        bail!("{label} has no joints");
    }
    let inverse = match skin.inverse_bind_matrices() {
        None => vec![DMat4::IDENTITY; joints.len()],
        Some(acc) => {
            let what = format!("{label}: inverseBindMatrices");
            let flat = read_floats(src, &acc, Use::InverseBind, &what)?;
            if flat.iter().any(|v| !v.is_finite()) {
                bail!("{what} has a non-finite value");
            }
            let m: Vec<DMat4> = flat
                .chunks_exact(16)
                .map(|c| {
                    let mut a = [0.0f64; 16];
                    for (d, v) in a.iter_mut().zip(c) {
                        *d = f64::from(*v);
                    }
                    DMat4::from_cols_array(&a)
                })
                .collect();
            if m.len() != joints.len() {
                bail!(
                    "{what} has {} matrices for {} joints",
                    m.len(),
                    joints.len()
                );
            }
            m
        }
    };
    let out: Vec<DMat4> = joints
        .iter()
        .zip(&inverse)
        .map(|(&j, ibm)| worlds[j] * *ibm)
        .collect();
    if let Some(k) = out.iter().position(|m| {
        !m.is_finite() || m.abs().to_cols_array().iter().any(|v| *v > f32::MAX as f64)
    }) {
        bail!("{label}: joint {k}'s matrix is beyond the f32 range");
    }
    let sources = joints
        .iter()
        .zip(inverse)
        .map(|(&node, inverse_bind)| Joint::Skinned { node, inverse_bind })
        .collect();
    Ok((out, sources))
}

/// Appends a skinned primitive: its vertices in bind space (the deform pass
/// and `Object::pose` move them), its world positions where its default
/// targets and its joints put them (what the scene's bounds and recentring
/// read), after checking its influences.
pub(super) fn append_skinned(
    mesh: &mut Mesh,
    world_pos: &mut Vec<DVec3>,
    part: &Part,
    skin: &SpanSkin,
    targets: &[MorphTarget],
    weights: &[f32],
    label: &str,
) -> Result<()> {
    part.check_room(mesh, label)?;
    let v = part.mesh.vertices.len();
    let matrices: Vec<glam::Mat4> = skin.matrices.iter().map(|m| m.as_mat4()).collect();
    let check = Skin {
        joints: skin.joints.clone(),
        weights: skin.weights.clone(),
        slots: skin.slots,
        previous: matrices.clone(),
        matrices,
    };
    check
        .check(v)
        .map_err(|e| anyhow::anyhow!("{label}: {e:#}"))?;
    let morph = Morph {
        rest: Vec::new(),
        targets: targets.to_vec(),
        weights: weights.to_vec(),
        skin: None,
    };
    // The joints in f64, as a rigid primitive's node is: a skin far from
    // the origin (joints at 1e8) keeps its shape until `place` recentres it.
    let morphed = crate::scene::morph::apply(&part.mesh.vertices, &morph);
    for (v, (j, w)) in morphed.iter().zip(skin.joints.iter().zip(&skin.weights)) {
        let p = glam::Vec3::from(v.position).as_dvec3();
        let q = j
            .iter()
            .zip(w)
            .filter(|(_, &w)| w != 0.0)
            .map(|(&j, &w)| skin.matrices[j as usize].transform_point3(p) * f64::from(w))
            .sum::<DVec3>();
        world_pos.push(q);
    }
    mesh.append(&part.mesh);
    Ok(())
}
