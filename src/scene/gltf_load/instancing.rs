//! `EXT_mesh_gpu_instancing`: a node that draws its mesh many times, each
//! instance at its own translation, rotation and scale (in the node's space).
//! dermis draws every instance as a copy of the mesh placed by the node's
//! world times the instance's transform, so an instanced crowd of props or
//! characters is what the file describes; the vertex budget of the loader
//! counts every copy.

use anyhow::{bail, Context as _, Result};
use glam::{DMat4, DQuat, DVec3};

use super::checks::node_label;
use crate::scene::gltf_accessor::{read_attribute, Use};
use crate::scene::gltf_source::Source;

const EXTENSION: &str = "EXT_mesh_gpu_instancing";

/// Instances one node may draw: past this the copies would pass the
/// loader's vertex budget for any mesh worth instancing.
pub const MAX_INSTANCES: usize = 1 << 16;

/// The instances' local transforms of `node` (T * R * S each, as glTF
/// composes a node's), or `None` when it has no instancing.
pub fn instance_matrices(src: &Source, node: &gltf::Node) -> Result<Option<Vec<DMat4>>> {
    let Some(ext) = src
        .json
        .get("nodes")
        .and_then(|n| n.get(node.index()))
        .and_then(|n| n.get("extensions"))
        .and_then(|e| e.get(EXTENSION))
    else {
        return Ok(None);
    };
    let label = node_label(node);
    let attrs = ext
        .get("attributes")
        .and_then(|a| a.as_object())
        .with_context(|| format!("{label}: {EXTENSION} has no attributes"))?;
    let accessor = |name: &str| -> Result<Option<gltf::Accessor>> {
        let Some(v) = attrs.get(name) else {
            return Ok(None);
        };
        let i = v
            .as_u64()
            .with_context(|| format!("{label}: {EXTENSION} {name} is not an accessor index"))?;
        src.doc
            .accessors()
            .nth(i as usize)
            .map(Some)
            .with_context(|| format!("{label}: {EXTENSION} {name}: accessor {i} does not exist"))
    };
    let what = |name: &str| format!("{label}'s {EXTENSION} {name}");
    let translation = accessor("TRANSLATION")?
        .map(|a| read_attribute::<3>(src, &a, Use::KeyVec3, &what("TRANSLATION")))
        .transpose()?;
    let rotation = accessor("ROTATION")?
        .map(|a| read_attribute::<4>(src, &a, Use::KeyVec4, &what("ROTATION")))
        .transpose()?;
    let scale = accessor("SCALE")?
        .map(|a| read_attribute::<3>(src, &a, Use::KeyVec3, &what("SCALE")))
        .transpose()?;
    let counts: Vec<usize> = [
        translation.as_ref().map(Vec::len),
        rotation.as_ref().map(Vec::len),
        scale.as_ref().map(Vec::len),
    ]
    .into_iter()
    .flatten()
    .collect();
    let Some(&n) = counts.first() else {
        bail!("{label}: {EXTENSION} has none of TRANSLATION, ROTATION and SCALE");
    };
    if counts.iter().any(|&c| c != n) {
        bail!("{label}: {EXTENSION}'s attributes have different counts ({counts:?})");
    }
    if n > MAX_INSTANCES {
        bail!("{label}: {n} instances, more than the {MAX_INSTANCES} dermis draws");
    }
    (0..n)
        .map(|i| {
            let t = translation.as_ref().map_or([0.0; 3], |v| v[i]);
            let r = rotation.as_ref().map_or([0.0, 0.0, 0.0, 1.0], |v| v[i]);
            let s = scale.as_ref().map_or([1.0; 3], |v| v[i]);
            if !t.iter().chain(&r).chain(&s).all(|c| c.is_finite()) {
                bail!("{label}: {EXTENSION} instance {i} is not finite");
            }
            let q = DQuat::from_array(r.map(f64::from));
            if q.length() < 1e-6 {
                bail!("{label}: {EXTENSION} instance {i} has a zero rotation");
            }
            Ok(DMat4::from_scale_rotation_translation(
                DVec3::from_array(s.map(f64::from)),
                q.normalize(),
                DVec3::from_array(t.map(f64::from)),
            ))
        })
        .collect::<Result<Vec<_>>>()
        .map(Some)
}
