//! Nodes: the scene's node graph checked to be trees and walked without
//! recursion, every primitive placed in world space in f64, and a model far
//! from the origin for its size moved to it.

use anyhow::{bail, Result};
use glam::{DMat3, DMat4, DVec3, Mat4};
use std::collections::HashMap;
use std::rc::Rc;

use super::checks::{mesh_label, node_label};
use super::instancing::instance_matrices;
use super::primitives::{read_primitive, Part};
use super::skeleton::{invertible, skeleton};
use super::skins::{append_skinned, skin_matrices, SpanSkin};
use super::Warnings;
use crate::scene::animation::{animated_weights, Clip};
use crate::scene::gltf_source::Source;
use crate::scene::mesh::Mesh;
use crate::scene::morph::{Morph, MorphTarget};
use crate::scene::rig::{Joint, ObjectRig, Skeleton};
use crate::scene::robust_bounds::robust_bounds_f64;
use crate::scene::skin::{Skin, SLOTS};

/// A model whose centre lies farther from the origin than this many times its size is
/// moved to the origin: f32 keeps 24 bits, and at 128 sizes away fewer than 16 of
/// them would be left across the model.
pub(super) const RECENTRE_RATIO: f64 = 128.0;

/// Each node's parent, after checking the hierarchy is what glTF requires (3.5.3):
/// disjoint strict trees, no node its own ancestor, no node with two parents. Checked
/// without recursion, so a chain of any depth is fine.
pub(super) fn parents(nodes: &[gltf::Node]) -> Result<Vec<Option<usize>>> {
    let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
    for node in nodes {
        for child in node.children() {
            let c = child.index();
            if c == node.index() {
                bail!(
                    "{} is its own child: the node graph has a cycle",
                    node_label(node)
                );
            }
            if let Some(p) = parent[c] {
                bail!(
                    "{} is a child of both node {p} and node {}: glTF node hierarchies must be trees",
                    node_label(&child),
                    node.index()
                );
            }
            parent[c] = Some(node.index());
        }
    }
    // With at most one parent each, a cycle is a parent chain that comes back to
    // itself. 0: not seen, 1: on the chain being walked, 2: known to end at a root.
    let mut state = vec![0u8; nodes.len()];
    let mut walk = Vec::new();
    for start in 0..nodes.len() {
        walk.clear();
        let mut cur = Some(start);
        while let Some(c) = cur {
            match state[c] {
                2 => break,
                1 => bail!(
                    "{} is its own ancestor: the node graph has a cycle",
                    node_label(&nodes[c])
                ),
                _ => {}
            }
            state[c] = 1;
            walk.push(c);
            cur = parent[c];
        }
        for &w in &walk {
            state[w] = 2;
        }
    }
    Ok(parent)
}

/// Appends a primitive placed by `world`: positions in f64 (kept apart for the
/// recentring), normals, tangents and winding through the f32 linear part.
pub(super) fn append_part(
    mesh: &mut Mesh,
    world_pos: &mut Vec<DVec3>,
    part: &Part,
    world: &DMat4,
    node: &gltf::Node,
) -> Result<()> {
    part.check_room(mesh, &node_label(node))?;
    let start = world_pos.len();
    for vert in &part.mesh.vertices {
        let p = world.transform_point3(DVec3::from_array(vert.position.map(f64::from)));
        if !p.is_finite() || p.abs().max_element() > f32::MAX as f64 {
            world_pos.truncate(start);
            bail!(
                "{}: its transform takes vertices beyond the f32 range",
                node_label(node)
            );
        }
        world_pos.push(p);
    }
    let linear = Mat4::from_mat3(DMat3::from_mat4(*world).as_mat3());
    let mut placed = part.mesh.clone();
    placed.transform(&linear);
    mesh.append(&placed);
    Ok(())
}

/// A primitive's morph targets placed by `world` (offsets are directions:
/// the linear part moves positions' and tangents', its inverse transpose
/// normals', none normalised), named by the mesh's `extras.targetNames`, with
/// their default weights: the node's, else the mesh's, else 0.
fn placed_targets(
    src: &Source,
    part: &Part,
    world: &DMat4,
    node: &gltf::Node,
    mesh: &gltf::Mesh,
    label: &str,
) -> Result<(Vec<MorphTarget>, Vec<f32>)> {
    let n = part.targets.len();
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let defaults = node.weights().or_else(|| mesh.weights());
    let weights = match defaults {
        None => vec![0.0; n],
        Some(w) if w.len() == n => w.to_vec(),
        Some(w) => bail!(
            "{label} has {n} morph targets but {} gives {} default weights",
            if node.weights().is_some() {
                node_label(node)
            } else {
                mesh_label(mesh)
            },
            w.len()
        ),
    };
    if let Some(w) = weights.iter().find(|w| !w.is_finite()) {
        bail!("{label}: default morph weight {w} is not finite");
    }
    let names = src
        .json
        .pointer(&format!("/meshes/{}/extras/targetNames", mesh.index()))
        .and_then(|v| v.as_array());
    let lin = DMat3::from_mat4(*world).as_mat3();
    let normal_m = lin.inverse().transpose();
    let map = |m: &glam::Mat3, v: &[[f32; 3]]| -> Vec<[f32; 3]> {
        v.iter()
            .map(|d| (*m * glam::Vec3::from(*d)).into())
            .collect()
    };
    let targets = part
        .targets
        .iter()
        .enumerate()
        .map(|(i, t)| MorphTarget {
            name: names
                .and_then(|a| a.get(i))
                .and_then(|v| v.as_str())
                .map(crate::scene::gltf_source::short),
            first: 0,
            position: map(&lin, &t.position),
            normal: map(&normal_m, &t.normal),
            tangent: map(&lin, &t.tangent),
        })
        .collect::<Vec<_>>();
    for t in &targets {
        let all = t.position.iter().chain(&t.normal).chain(&t.tangent);
        if all.flatten().any(|c| !c.is_finite()) {
            bail!(
                "{}: its transform takes {label}'s morph offsets beyond the f32 range",
                node_label(node)
            );
        }
    }
    Ok((targets, weights))
}

/// What the walk over the scene collected: one merged mesh, and which of its
/// vertices and indices each placed primitive wrote (`split` cuts it by material).
pub(super) struct Collected {
    pub(super) mesh: Mesh,
    pub(super) world_pos: Vec<DVec3>,
    pub(super) spans: Vec<Span>,
    /// The node graph (what a `rig::Rig` poses again), and the shift
    /// `place` moved the model by.
    pub(super) skeleton: Skeleton,
    pub(super) shift: DVec3,
}

/// One placed primitive in the merged mesh.
#[derive(Clone, Debug)]
pub(super) struct Span {
    /// The glTF material (`None`: the default material).
    pub(super) material: Option<usize>,
    pub(super) vertices: std::ops::Range<usize>,
    pub(super) indices: std::ops::Range<usize>,
    pub(super) has_uvs: bool,
    pub(super) label: String,
    /// Its morph targets placed in world space (`first` 0: the span's first
    /// vertex; in bind space when skinned) and their default weights (the
    /// node's, else the mesh's, else 0).
    pub(super) targets: Vec<MorphTarget>,
    pub(super) weights: Vec<f32>,
    /// Its skin: its vertices stay in bind space, its joints place them.
    pub(super) skin: Option<SpanSkin>,
    /// Its node, and (rigid, under a node the played clip moves) that
    /// node's world at the loaded time: the clip moves it from there.
    pub(super) node: usize,
    pub(super) moved_from: Option<DMat4>,
}

/// The primitives of one material, merged: a mesh of its own (indices from 0).
pub(super) struct MaterialMesh {
    pub(super) material: Option<usize>,
    pub(super) mesh: Mesh,
    pub(super) with_uvs: usize,
    pub(super) without_uvs: Vec<String>,
    /// Its primitives' targets, each over its own vertices (rest: none yet).
    pub(super) morph: Morph,
    /// Where the played clip takes its joints and weights from.
    pub(super) rig: ObjectRig,
}

impl Collected {
    /// The merged mesh cut by material, in the order materials are first met.
    pub(super) fn split(&self) -> Vec<MaterialMesh> {
        let mut out: Vec<MaterialMesh> = Vec::new();
        // Where each material's rigid primitives' one identity joint is
        // (a material with a skinned primitive is skinned as a whole).
        let mut rigid_joint: Vec<Option<u32>> = Vec::new();
        // Each material's joint per moving node of its rigid primitives.
        let mut moving_joint: Vec<HashMap<usize, u32>> = Vec::new();
        for span in &self.spans {
            let k = match out.iter().position(|m| m.material == span.material) {
                Some(k) => k,
                None => {
                    out.push(MaterialMesh {
                        material: span.material,
                        mesh: Mesh::default(),
                        with_uvs: 0,
                        without_uvs: Vec::new(),
                        morph: Morph::default(),
                        rig: ObjectRig::default(),
                    });
                    rigid_joint.push(None);
                    moving_joint.push(HashMap::new());
                    // Skinned when a primitive has a skin or the clip moves
                    // one (a joint carries it); 4 slots where none has one.
                    let same = || self.spans.iter().filter(|s| s.material == span.material);
                    let skinned = same()
                        .filter_map(|s| s.skin.as_ref())
                        .map(|s| s.slots)
                        .max()
                        .or_else(|| same().any(|s| s.moved_from.is_some()).then_some(4));
                    if let Some(slots) = skinned {
                        out.last_mut().expect("just pushed").morph.skin = Some(Skin {
                            slots,
                            ..Skin::default()
                        });
                    }
                    out.len() - 1
                }
            };
            let m = &mut out[k];
            if let Some(skin) = &mut m.morph.skin {
                let n = span.vertices.len();
                let joints = &mut m.rig.joints;
                match &span.skin {
                    Some(s) => {
                        let base = skin.matrices.len() as u32;
                        skin.matrices.extend(s.matrices.iter().map(|j| j.as_mat4()));
                        joints.extend(s.sources.iter().cloned());
                        skin.joints
                            .extend(s.joints.iter().map(|j| j.map(|i| i + base)));
                        skin.weights.extend_from_slice(&s.weights);
                    }
                    None => {
                        // Placed in world space already: one identity joint,
                        // one per node the clip moves (the identity at the
                        // loaded time).
                        let j = match span.moved_from {
                            Some(loaded) => {
                                *moving_joint[k].entry(span.node).or_insert_with(|| {
                                    skin.matrices.push(glam::Mat4::IDENTITY);
                                    joints.push(Joint::Rigid {
                                        node: span.node,
                                        loaded,
                                    });
                                    skin.matrices.len() as u32 - 1
                                })
                            }
                            None => *rigid_joint[k].get_or_insert_with(|| {
                                skin.matrices.push(glam::Mat4::IDENTITY);
                                joints.push(Joint::Fixed);
                                skin.matrices.len() as u32 - 1
                            }),
                        };
                        let mut joints = [0; SLOTS];
                        joints[0] = j;
                        let mut weights = [0.0; SLOTS];
                        weights[0] = 1.0;
                        skin.joints.extend(std::iter::repeat_n(joints, n));
                        skin.weights.extend(std::iter::repeat_n(weights, n));
                    }
                }
                skin.previous = skin.matrices.clone();
            }
            let base = m.mesh.vertices.len() as u32;
            let first = span.vertices.start as u32;
            m.mesh
                .vertices
                .extend_from_slice(&self.mesh.vertices[span.vertices.clone()]);
            m.mesh.indices.extend(
                self.mesh.indices[span.indices.clone()]
                    .iter()
                    .map(|&i| i - first + base),
            );
            for (i, (t, &w)) in span.targets.iter().zip(&span.weights).enumerate() {
                m.morph.targets.push(MorphTarget {
                    first: t.first + base as usize,
                    ..t.clone()
                });
                m.morph.weights.push(w);
                m.rig.weights.push((span.node, i));
            }
            if span.has_uvs {
                m.with_uvs += 1;
            } else if !m.without_uvs.contains(&span.label) {
                m.without_uvs.push(span.label.clone());
            }
        }
        out
    }
}

/// Walks the default scene (or the first, or every root node when there is none)
/// without recursion, appending every triangle primitive in world space.
pub(super) fn collect(
    src: &Source,
    warn: &mut Warnings,
    pose: Option<(&Clip, f32)>,
) -> Result<Collected> {
    let nodes: Vec<gltf::Node> = src.doc.nodes().collect();
    let parent = parents(&nodes)?;
    let roots: Vec<usize> = match src.doc.default_scene().or_else(|| src.doc.scenes().next()) {
        Some(scene) => {
            let roots: Vec<usize> = scene.nodes().map(|n| n.index()).collect();
            if let Some((&r, p)) = roots.iter().find_map(|r| parent[*r].map(|p| (r, p))) {
                bail!(
                    "scene {} lists {} as a root, but it is a child of node {p}",
                    scene.index(),
                    node_label(&nodes[r])
                );
            }
            roots
        }
        None => (0..nodes.len()).filter(|&i| parent[i].is_none()).collect(),
    };
    let mut out = Collected {
        mesh: Mesh::default(),
        world_pos: Vec::new(),
        spans: Vec::new(),
        skeleton: Skeleton::default(),
        shift: DVec3::ZERO,
    };
    let mut parts: HashMap<(usize, usize), Option<Rc<Part>>> = HashMap::new();
    let mut visited = vec![false; nodes.len()];
    // Every node's world matrix first: a skin's joints may lie anywhere in
    // the hierarchy, before or after the meshes they move.
    let skeleton = skeleton(&nodes, &parent, pose.map(|p| p.0))?;
    let worlds = skeleton.worlds(pose);
    let moved = pose.map(|(clip, _)| skeleton.moved_by(clip));
    let mut stack: Vec<usize> = roots.iter().rev().copied().collect();
    let mut said_unskinned = false;
    let mut said_degenerate = false;
    while let Some(ni) = stack.pop() {
        let node = &nodes[ni];
        if std::mem::replace(&mut visited[ni], true) {
            bail!(
                "{} is listed twice among the scene's roots",
                node_label(node)
            );
        }
        let world = worlds[ni];
        let skin = node
            .skin()
            .filter(|_| node.mesh().is_some())
            .map(|sk| skin_matrices(src, &sk, &worlds))
            .transpose()?;
        // An instanced node (EXT_mesh_gpu_instancing) draws its mesh once
        // per instance, placed by the node's world times the instance's.
        let placements: Vec<DMat4> = match instance_matrices(src, node)? {
            Some(list) if skin.is_some() => {
                warn.push(format!(
                    "{}: the {} instances of a skinned mesh are not drawn: it is drawn once, by its joints",
                    node_label(node),
                    list.len()
                ));
                vec![world]
            }
            Some(list) => {
                warn.note(format!(
                    "{}: EXT_mesh_gpu_instancing: its {} instances drawn as copies of its mesh",
                    node_label(node),
                    list.len()
                ));
                list.iter().map(|m| world * *m).collect()
            }
            None => vec![world],
        };
        for (instance, &world) in placements.iter().enumerate() {
            let Some(mesh) = node.mesh() else { break };
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                let label = match placements.len() {
                    1 => format!("{} primitive {}", mesh_label(&mesh), prim.index()),
                    _ => format!(
                        "{} primitive {} instance {instance}",
                        mesh_label(&mesh),
                        prim.index()
                    ),
                };
                let part = match parts.get(&key) {
                    Some(p) => p.clone(),
                    None => {
                        let p = read_primitive(src, &label, &prim, warn)?.map(Rc::new);
                        parts.insert(key, p.clone());
                        p
                    }
                };
                let Some(part) = part else { continue };
                let (v0, i0) = (out.mesh.vertices.len(), out.mesh.indices.len());
                // A skinned mesh ignores its node's transform (glTF
                // 3.7.3.1): its joints place it.
                let placing = if skin.is_some() {
                    DMat4::IDENTITY
                } else {
                    world
                };
                let (targets, mut weights) =
                    placed_targets(src, &part, &placing, node, &mesh, &label)?;
                if let Some(w) = pose.and_then(|(clip, t)| animated_weights(clip, node.index(), t))
                {
                    // A mesh's primitives share its weights; one with fewer
                    // targets takes the first of them.
                    for (d, v) in weights.iter_mut().zip(w) {
                        *d = v;
                    }
                }
                let span_skin = match (&skin, &part.influences) {
                    (None, inf) => {
                        if inf.is_some() && !std::mem::replace(&mut said_unskinned, true) {
                            warn.note(format!(
                                "{label} has joints and weights but {} has no skin: placed by its node",
                                node_label(node)
                            ));
                        }
                        append_part(&mut out.mesh, &mut out.world_pos, &part, &world, node)?;
                        None
                    }
                    (Some(_), None) => bail!(
                        "{} has a skin but {label} has no JOINTS_0 and WEIGHTS_0",
                        node_label(node)
                    ),
                    (Some((matrices, sources)), Some(inf)) => {
                        let span_skin = SpanSkin {
                            joints: inf.joints.clone(),
                            weights: inf.weights.clone(),
                            slots: inf.slots,
                            matrices: matrices.clone(),
                            sources: sources.clone(),
                        };
                        append_skinned(
                            &mut out.mesh,
                            &mut out.world_pos,
                            &part,
                            &span_skin,
                            &targets,
                            &weights,
                            &label,
                        )?;
                        Some(span_skin)
                    }
                };
                let moved_from = (span_skin.is_none()
                        && moved.as_ref().is_some_and(|m| m[node.index()]))
                    .then_some(worlds[node.index()])
                    .filter(|w| {
                        // A part the clip has scaled to nothing at the loaded
                        // time is loaded as a point: no move can restore it.
                        let ok = invertible(w);
                        if !ok && !std::mem::replace(&mut said_degenerate, true) {
                            warn.push(format!(
                                "{label}: its node's transform has no inverse at the loaded time (scaled to nothing): it stays as loaded while the clip plays"
                            ));
                        }
                        ok
                    });
                out.spans.push(Span {
                    material: prim.material().index(),
                    vertices: v0..out.mesh.vertices.len(),
                    indices: i0..out.mesh.indices.len(),
                    has_uvs: part.has_uvs,
                    label,
                    targets,
                    weights,
                    moved_from,
                    skin: span_skin,
                    node: node.index(),
                });
            }
        }
        stack.extend(
            node.children()
                .map(|c| c.index())
                .collect::<Vec<_>>()
                .into_iter()
                .rev(),
        );
    }
    out.skeleton = skeleton;
    Ok(out)
}

/// Converts the f64 world positions into the mesh, moving the model to the origin when
/// it lies so far from it that f32 would lose its shape (a scan georeferenced at 1e7).
/// The centre and size come from robust bounds, so one corrupt far vertex neither
/// triggers nor steers the move.
pub(super) fn place(c: &mut Collected, warn: &mut Warnings) -> Result<()> {
    let Some(rb) = robust_bounds_f64(&c.world_pos) else {
        bail!("no vertices");
    };
    let size = rb.size().max_element();
    if size == 0.0 {
        let p = rb.min;
        bail!(
            "all {} vertices lie at one point ({}, {}, {}): nothing to draw",
            c.world_pos.len(),
            p.x,
            p.y,
            p.z
        );
    }
    let centre = rb.center();
    let shift = if centre.abs().max_element() > RECENTRE_RATIO * size {
        warn.push(format!(
            "the model lies at ({:e}, {:e}, {:e}), far from the origin for its size ({size:e}): moved to the origin to keep f32 precision",
            centre.x, centre.y, centre.z
        ));
        centre
    } else {
        DVec3::ZERO
    };
    c.shift = shift;
    let mut bind = vec![false; c.mesh.vertices.len()];
    for span in c.spans.iter_mut() {
        if let Some(skin) = &mut span.skin {
            bind[span.vertices.clone()].fill(true);
            let m = DMat4::from_translation(-shift);
            for j in &mut skin.matrices {
                *j = m * *j;
            }
        }
    }
    for ((v, p), bind) in c.mesh.vertices.iter_mut().zip(&c.world_pos).zip(bind) {
        if bind {
            continue;
        }
        let q = (*p - shift).as_vec3();
        if !q.is_finite() {
            bail!("vertex positions exceed the f32 range");
        }
        v.position = q.into();
    }
    if rb.ignored > 0 {
        let far = c
            .world_pos
            .iter()
            .position(|p| p.cmplt(rb.min).any() || p.cmpgt(rb.max).any())
            .unwrap_or(0);
        let p = c.world_pos[far];
        warn.push(format!(
            "{} vertices lie far outside the rest of the mesh (vertex {far} at ({:e}, {:e}, {:e})): corrupt data? Left out of the camera's and the shadow map's framing",
            rb.ignored, p.x, p.y, p.z
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scene::gltf_load::tests::{attrs, bytes_f32, load_err, quad_file, temp_dir};
    use crate::scene::gltf_load::{load_head, load_head_with_warnings};
    use glam::Vec3;

    #[test]
    fn node_cycles_are_refused_and_deep_chains_load() {
        let dir = temp_dir("nodes");
        let prim = serde_json::json!({"attributes": attrs()});
        let own_child = serde_json::json!([{"mesh": 0, "children": [0]}]);
        let p = quad_file(
            &dir,
            "own.gltf",
            prim.clone(),
            serde_json::json!([]),
            &[],
            Some(own_child),
        );
        let e = load_err(&p);
        assert!(
            e.contains("node 0 is its own child: the node graph has a cycle"),
            "{e}"
        );
        // A loop of two: 0 -> 1 -> 0.
        let cycle = serde_json::json!([{"children": [1]}, {"mesh": 0, "children": [0]}]);
        let p = quad_file(
            &dir,
            "cycle.gltf",
            prim.clone(),
            serde_json::json!([]),
            &[],
            Some(cycle),
        );
        let e = load_err(&p);
        assert!(
            e.contains("node 0 is its own ancestor: the node graph has a cycle"),
            "{e}"
        );
        // A 17,500-deep chain overflowed the stack of the recursive walk.
        const DEPTH: usize = 17_500;
        let chain: Vec<serde_json::Value> = (0..DEPTH)
            .map(|i| {
                if i + 1 < DEPTH {
                    serde_json::json!({"children": [i + 1], "translation": [0.0, 0.001, 0.0]})
                } else {
                    serde_json::json!({"mesh": 0})
                }
            })
            .collect();
        let p = quad_file(
            &dir,
            "deep.gltf",
            prim,
            serde_json::json!([]),
            &[],
            Some(chain.into()),
        );
        let obj = load_head(&p, &Default::default()).unwrap();
        assert!((obj.mesh.bounds().min.y - 0.001 * (DEPTH - 1) as f32).abs() < 1e-2);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn far_from_origin_is_recentred_and_lost_precision_refused() {
        let dir = temp_dir("far");
        // A node translation of 1e8 (f32 steps of 8 there) used to collapse the quad.
        let nodes = serde_json::json!([{"mesh": 0, "translation": [1e8, 1e8, -1e8]}]);
        let p = quad_file(
            &dir,
            "node.gltf",
            serde_json::json!({"attributes": attrs()}),
            serde_json::json!([]),
            &[],
            Some(nodes),
        );
        let (obj, w) = load_head_with_warnings(&p, &Default::default()).unwrap();
        let b = obj.mesh.bounds();
        assert_eq!(b.size(), Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(b.center(), Vec3::ZERO);
        assert!(w.iter().any(|w| w.contains("moved to the origin")), "{w:?}");
        // Positions stored at 1e7 in the buffer: the shape is gone in the file itself.
        let far = bytes_f32(&[
            1e7,
            1e7,
            0.0,
            1e7 + 1.0,
            1e7,
            0.0,
            1e7 + 1.0,
            1e7 + 1.0,
            0.0,
            1e7,
            1e7 + 1.0,
            0.0,
        ]);
        let mut a = attrs();
        a["POSITION"] = serde_json::json!(3);
        let p = quad_file(
            &dir,
            "buf.gltf",
            serde_json::json!({"attributes": a}),
            serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}]),
            &far,
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("but span only 1e0, fewer than 16 f32 steps"),
            "{e}"
        );
        // One vertex at 1e31 (a flipped exponent bit) loads, with a warning.
        let out = bytes_f32(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1e31, 0.0]);
        let p = quad_file(
            &dir,
            "outlier.gltf",
            serde_json::json!({"attributes": a}),
            serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}]),
            &out,
            None,
        );
        let (_, w) = load_head_with_warnings(&p, &Default::default()).unwrap();
        assert!(
            w.iter().any(|w| w.contains("1 vertices lie far outside")),
            "{w:?}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }
}
