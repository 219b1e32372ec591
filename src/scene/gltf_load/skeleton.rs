//! The node graph as the clip poses it again (`crate::scene::rig`): each
//! node's parent and rest transform, checked once, and which placements
//! can be moved from (a world with an inverse).

use anyhow::{bail, Result};
use glam::{DMat3, DMat4, DQuat, DVec3};

use super::checks::node_label;
use crate::scene::animation::{Clip, Path};
use crate::scene::rig::{Local, Skeleton};

/// A node's local transform in f64, refused when not finite. A TRS rotation is
/// normalised (exporters write slightly off unit quaternions); a zero one is refused.
pub(super) fn local_matrix(node: &gltf::Node) -> Result<DMat4> {
    let label = || node_label(node);
    let finite = |v: &[f32]| v.iter().all(|c| c.is_finite());
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            if !matrix.iter().all(|c| finite(c)) {
                bail!("{} has a non-finite matrix", label());
            }
            Ok(DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from))))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            for (what, ok) in [
                ("translation", finite(&translation)),
                ("rotation", finite(&rotation)),
                ("scale", finite(&scale)),
            ] {
                if !ok {
                    bail!("{} has a non-finite {what}", label());
                }
            }
            let q = DQuat::from_array(rotation.map(f64::from));
            let len = q.length();
            if len <= 1e-12 {
                bail!("{} has a zero rotation quaternion", label());
            }
            Ok(DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q / len,
                DVec3::from_array(translation.map(f64::from)),
            ))
        }
    }
}

/// The node graph as `rig::Skeleton` keeps it: each node's parent and rest
/// transform, checked (finite, a non-zero rotation), and a node `clip`
/// animates written as translation, rotation and scale (glTF animates no
/// other).
pub(super) fn skeleton(
    nodes: &[gltf::Node],
    parent: &[Option<usize>],
    clip: Option<&Clip>,
) -> Result<Skeleton> {
    let locals = nodes
        .iter()
        .map(|node| {
            // The rest transform checked as any node's is, whether or not
            // a channel replaces part of it.
            let matrix = local_matrix(node)?;
            let animates = clip.is_some_and(|clip| {
                clip.channels
                    .iter()
                    .any(|c| c.node == node.index() && c.path != Path::Weights)
            });
            match node.transform() {
                gltf::scene::Transform::Decomposed {
                    translation,
                    rotation,
                    scale,
                } => Ok(Local::Trs {
                    matrix,
                    trs: (
                        glam::Vec3::from(translation),
                        glam::Quat::from_array(rotation).normalize(),
                        glam::Vec3::from(scale),
                    ),
                }),
                gltf::scene::Transform::Matrix { .. } if animates => bail!(
                    "{} is animated but written as a matrix, which glTF forbids",
                    node_label(node)
                ),
                gltf::scene::Transform::Matrix { .. } => Ok(Local::Matrix(matrix)),
            }
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Skeleton {
        parent: parent.to_vec(),
        locals,
    })
}

/// Whether `m` has an inverse worth taking: finite, and its linear part's
/// determinant not vanishing against its columns' lengths (a node scaled to
/// zero, or nearly, by a clip).
pub(super) fn invertible(m: &DMat4) -> bool {
    let l = DMat3::from_mat4(*m);
    let scale = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
    m.is_finite() && scale > 0.0 && l.determinant().abs() > 1e-9 * scale && m.inverse().is_finite()
}
