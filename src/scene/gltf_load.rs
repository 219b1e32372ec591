//! Loads a head scan from glTF/GLB: every triangle primitive of the default scene, in world
//! space, merged into one mesh, plus its skin textures.
//!
//! Scans are often shipped as a bare mesh with textures lying next to it (the Lee
//! Perry-Smith head is), so textures the glTF does not reference are found by file name
//! beside it; the command line can override each one.
//!
//! Every input ends in a loaded head or one error line naming the file and the element
//! (the bytes are read with bounds by `gltf_source` and `gltf_accessor`; the node graph
//! is walked without recursion). What glTF allows is loaded, what it forbids refused:
//! - TRIANGLE_STRIP and TRIANGLE_FAN become triangle lists with glTF's winding;
//!   POINTS and LINES* are refused (drawing them as something else would be a lie).
//! - A primitive without NORMAL gets flat normals, as the spec requires (warning).
//! - Texture coordinates: skin needs them only where a texture is mapped. A primitive
//!   without TEXCOORD_0 loads with zero coordinates (warning). When no primitive has
//!   them, the head loads untextured in its base colour: textures found beside the file
//!   are dropped (warning), while a texture the glTF material or the command line asks
//!   for is an error, since it cannot be mapped.
//! - KHR_texture_transform of the material's textures is baked into the coordinates
//!   (gltfpack's quantized coordinates need it); KHR_mesh_quantization storage is read.
//!   Any other required extension is refused by name.
//! - Non-finite positions, normals, tangents, texture coordinates or node transforms
//!   are errors, and so are texture coordinates of 2^24 or more (no texel left to
//!   address; the sampler's arithmetic overflows). Node transforms are composed in f64, and a model far from the origin
//!   for its size (a scan placed at 1e7) is moved to it, so f32 keeps its shape.
//! - Far outlier vertices (one flipped exponent bit) load with a warning; the framing
//!   (`head_measure`, the scene's bounds) leaves them out.

use super::gltf_accessor::{read_attribute, read_indices, view_bytes, Use};
use super::gltf_source::{read_uri, short, Source};
use super::mesh::{Material, Mesh, Object, Texture, Vertex};
use super::robust_bounds::robust_bounds_f64;
use anyhow::{anyhow, bail, Result};
use glam::{DMat3, DMat4, DQuat, DVec3, Mat4, Vec3};
use gltf::mesh::Mode;
use gltf::Semantic;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

pub use super::head_measure::face_direction;

/// Most vertices and triangles the merged head may have. A mesh instanced by many
/// nodes multiplies what a small file holds; this keeps such a file from taking all
/// memory (a dense head scan has a few million).
pub const MAX_VERTICES: usize = 1 << 25;
pub const MAX_TRIANGLES: usize = 1 << 25;

/// Warnings beyond this many are counted, not listed.
const MAX_WARNINGS: usize = 20;

/// A model whose centre lies farther from the origin than this many times its size is
/// moved to the origin: f32 keeps 24 bits, and at 128 sizes away fewer than 16 of
/// them would be left across the model.
const RECENTRE_RATIO: f64 = 128.0;

/// A primitive spanning fewer than this many f32 steps at its coordinates' magnitude
/// has lost its shape in the file itself (a head stored at 1e7, where f32 steps are one
/// unit): refused rather than drawn as a few points.
const MIN_STEPS: f32 = 16.0;

/// Texture files that replace whatever the glTF or the auto-detection found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureOverrides {
    pub albedo: Option<PathBuf>,
    pub normal_map: Option<PathBuf>,
    pub specular_map: Option<PathBuf>,
    /// Textures found beside the file or given as overrides were not authored
    /// against the glTF's texture-coordinate convention (v = 0 at the top row).
    /// By default they are taken as bottom-up (OpenGL convention: the three.js
    /// example that distributes the Lee Perry-Smith head loads them with
    /// flipY = true); set this when such files are top-down.
    pub sidecar_top_down: bool,
}

/// Loads a texture that came from beside the scene file or the command line,
/// flipped into the glTF convention unless it is already top-down.
fn sidecar_texture(path: &Path, what: &str, overrides: &TextureOverrides) -> Result<Texture> {
    let mut t = load_texture(path, what)?;
    let row = t.width as usize * 4;
    if !overrides.sidecar_top_down && row > 0 {
        let rows: Vec<&[u8]> = t.rgba8.chunks_exact(row).rev().collect();
        t.rgba8 = rows.concat();
    }
    Ok(t)
}

/// Warnings collected while loading, deduplicated (an instanced mesh would repeat
/// them) and capped.
#[derive(Default)]
struct Warnings {
    list: Vec<String>,
    dropped: usize,
}

impl Warnings {
    fn push(&mut self, w: String) {
        if self.list.contains(&w) {
            return;
        }
        if self.list.len() < MAX_WARNINGS {
            self.list.push(w);
        } else {
            self.dropped += 1;
        }
    }

    fn finish(mut self) -> Vec<String> {
        if self.dropped > 0 {
            self.list
                .push(format!("... and {} more warnings", self.dropped));
        }
        self.list
    }
}

fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

fn mesh_label(mesh: &gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh '{}'", short(n)),
        None => format!("mesh #{}", mesh.index()),
    }
}

fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(n) => format!("node {} '{}'", node.index(), short(n)),
        None => format!("node {}", node.index()),
    }
}

/// Converts an index list of any triangle mode into a triangle list with the winding
/// glTF defines (3.7.2.1): strip triangle i is (i, i+1, i+2) for even i and
/// (i, i+2, i+1) for odd i, so every triangle keeps the first one's orientation; fan
/// triangle i is (i+1, i+2, 0). Triangles with a repeated vertex are the stitching of
/// strips and cover nothing: they are left out.
fn triangulate(mode: Mode, idx: &[u32], label: &str) -> Result<Vec<u32>> {
    let n = idx.len();
    let mut out = Vec::with_capacity(match mode {
        Mode::Triangles => n,
        _ => n.saturating_sub(2) * 3,
    });
    let mut push = |a: u32, b: u32, c: u32| {
        if a != b && b != c && a != c {
            out.extend([a, b, c]);
        }
    };
    match mode {
        Mode::Triangles => {
            // `% 3` rather than `is_multiple_of`: the crate's rust-version is 1.85.
            #[allow(clippy::manual_is_multiple_of)]
            if n % 3 != 0 {
                bail!("{label} has {n} indices, not a multiple of 3 (TRIANGLES)");
            }
            return Ok(idx.to_vec());
        }
        Mode::TriangleStrip => {
            for i in 0..n.saturating_sub(2) {
                if i % 2 == 0 {
                    push(idx[i], idx[i + 1], idx[i + 2]);
                } else {
                    push(idx[i], idx[i + 2], idx[i + 1]);
                }
            }
        }
        Mode::TriangleFan => {
            for i in 0..n.saturating_sub(2) {
                push(idx[i + 1], idx[i + 2], idx[0]);
            }
        }
        other => bail!(
            "{label} has mode {}: dermis draws only triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN)",
            mode_name(other)
        ),
    }
    Ok(out)
}

/// Largest texture coordinate dermis samples with: at 2^24 an f32 keeps no
/// fraction to address a texel, and far beyond it the sampler's own arithmetic
/// (coordinate x texture size, the derivatives between pixels) overflows to
/// infinity and filters NaN into the frame (found by the fuzzer: a coordinate
/// accessor misread four bytes off gave 5e36).
const MAX_TEXCOORD: f32 = 16_777_216.0;

/// A texture coordinate too large to sample, as an error naming it.
fn check_texcoord_range(values: &[[f32; 2]], what: &str) -> Result<()> {
    if let Some(i) = values
        .iter()
        .position(|v| v.iter().any(|c| c.abs() >= MAX_TEXCOORD))
    {
        let [u, v] = values[i];
        bail!(
            "{what} of vertex {i} is ({u:e}, {v:e}): beyond {MAX_TEXCOORD:e} a coordinate has no fraction left to address a texel"
        );
    }
    Ok(())
}

/// The first non-finite value of an attribute, as an error naming it.
fn check_finite<const N: usize>(values: &[[f32; N]], what: &str) -> Result<()> {
    if let Some(i) = values.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
        bail!(
            "{what} of vertex {i} is not finite ({})",
            values[i]
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

/// One triangle primitive in its own space, as read once and shared by every node
/// that instances its mesh.
struct Part {
    mesh: Mesh,
    has_uvs: bool,
}

/// Reads one primitive into a triangle mesh in the primitive's own space; `None` when
/// it has no triangles. Missing normals become flat normals and missing texture
/// coordinates zeros (both with a warning), as glTF allows both to be absent.
fn read_primitive(
    src: &Source,
    label: &str,
    prim: &gltf::Primitive,
    warn: &mut Warnings,
) -> Result<Option<Part>> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        bail!(
            "{label} has mode {}: dermis draws only triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN)",
            mode_name(mode)
        );
    }
    let attr = |sem: &Semantic| prim.get(sem);
    let pos_acc = attr(&Semantic::Positions).ok_or_else(|| anyhow!("{label} has no POSITION"))?;
    let positions: Vec<[f32; 3]> =
        read_attribute(src, &pos_acc, Use::Position, &format!("{label}: POSITION"))?;
    check_finite(&positions, &format!("{label}: POSITION"))?;
    let n = positions.len();
    let normals: Option<Vec<[f32; 3]>> = attr(&Semantic::Normals)
        .map(|a| read_attribute(src, &a, Use::Normal, &format!("{label}: NORMAL")))
        .transpose()?;
    // Without normals the spec says provided tangents must be ignored (they belong to
    // the smooth normals the file did not give).
    let tangents: Option<Vec<[f32; 4]>> = match normals {
        Some(_) => attr(&Semantic::Tangents)
            .map(|a| read_attribute(src, &a, Use::Tangent, &format!("{label}: TANGENT")))
            .transpose()?,
        None => None,
    };
    let mut uvs: Option<Vec<[f32; 2]>> = attr(&Semantic::TexCoords(0))
        .map(|a| read_attribute(src, &a, Use::TexCoord, &format!("{label}: TEXCOORD_0")))
        .transpose()?;
    for (name, len) in [
        ("NORMAL", normals.as_ref().map(Vec::len)),
        ("TANGENT", tangents.as_ref().map(Vec::len)),
        ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
    ] {
        if let Some(len) = len.filter(|&l| l != n) {
            bail!("{label}: {name} has {len} elements but POSITION has {n}");
        }
    }
    if let Some(v) = &normals {
        check_finite(v, &format!("{label}: NORMAL"))?;
    }
    if let Some(v) = &tangents {
        check_finite(v, &format!("{label}: TANGENT"))?;
    }
    if let Some(v) = &mut uvs {
        check_finite(v, &format!("{label}: TEXCOORD_0"))?;
        check_texcoord_range(v, &format!("{label}: TEXCOORD_0"))?;
        // Baked in here, where each primitive's own material is known; tangents are
        // then generated from the coordinates the textures are really sampled with.
        if let Some(t) = texture_transform(src, prim.material().index())? {
            for uv in v.iter_mut() {
                *uv = t.apply(*uv);
            }
        }
    }
    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => read_indices(src, &acc, &format!("{label}: indices"))?,
        None => (0..n as u32).collect(),
    };
    if let Some((k, &i)) = indices.iter().enumerate().find(|(_, &i)| i as usize >= n) {
        bail!("{label}: index {i} at position {k} is out of range ({n} vertices)");
    }
    let triangles = triangulate(mode, &indices, label)?;
    if triangles.is_empty() {
        warn.push(format!("{label} has no triangles; nothing to draw"));
        return Ok(None);
    }
    // Precision lost in the file itself: a shape a few f32 steps wide is noise.
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p))),
    );
    let magnitude = lo.abs().max(hi.abs()).max_element();
    let extent = (hi - lo).max_element();
    let step = magnitude * f32::EPSILON;
    if extent > 0.0 && extent < MIN_STEPS * step {
        bail!(
            "{label}: POSITION values reach {magnitude:e} but span only {extent:e}, fewer than {MIN_STEPS} f32 steps ({step:e}) there: the shape was lost when the file was written (move the model near the origin before export)"
        );
    }
    let vertices = (0..n)
        .map(|i| Vertex {
            position: positions[i],
            normal: normals.as_ref().map_or([0.0, 1.0, 0.0], |v| v[i]),
            uv: uvs.as_ref().map_or([0.0; 2], |v| v[i]),
            tangent: tangents.as_ref().map_or([0.0; 4], |t| t[i]),
        })
        .collect();
    let mut mesh = Mesh {
        vertices,
        indices: triangles,
    };
    if normals.is_none() {
        warn.push(format!(
            "{label} has no NORMAL: flat normals computed, as glTF specifies (it will look faceted)"
        ));
        mesh.make_flat_normals();
    }
    if tangents.is_none() {
        mesh.generate_tangents();
    }
    Ok(Some(Part {
        mesh,
        has_uvs: uvs.is_some(),
    }))
}

/// KHR_texture_transform of a material's textures, as the affine map
/// uv' = T(offset) R(rotation) S(scale) uv of the extension.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
}

impl UvTransform {
    fn apply(&self, [u, v]: [f32; 2]) -> [f32; 2] {
        let (sin, cos) = self.rotation.sin_cos();
        let (su, sv) = (self.scale[0] * u, self.scale[1] * v);
        [
            self.offset[0] + cos * su + sin * sv,
            self.offset[1] - sin * su + cos * sv,
        ]
    }
}

/// The texture transform of the material's textures dermis samples (albedo, normal
/// map, specular). They share one set of texture coordinates, so the transform is
/// baked into them, which needs every one of those textures to use the same one.
/// gltfpack writes quantized texture coordinates that only make sense through it.
fn texture_transform(src: &Source, material: Option<usize>) -> Result<Option<UvTransform>> {
    let Some(m) = material else {
        return Ok(None);
    };
    let Some(mat) = src.json.get("materials").and_then(|v| v.get(m)) else {
        return Ok(None);
    };
    let infos = [
        (
            "albedo",
            mat.pointer("/pbrMetallicRoughness/baseColorTexture"),
        ),
        ("normal map", mat.get("normalTexture")),
        (
            "specular",
            mat.pointer("/extensions/KHR_materials_specular/specularTexture"),
        ),
    ];
    let mut found: Option<(&str, Option<UvTransform>)> = None;
    for (what, info) in infos {
        let Some(info) = info else { continue };
        let t = match info.pointer("/extensions/KHR_texture_transform") {
            None => None,
            Some(ext) => {
                let num = |key: &str, i: usize, default: f64| -> Option<f32> {
                    match ext.get(key) {
                        None => Some(default as f32),
                        Some(v) if v.is_array() => v.get(i)?.as_f64().map(|f| f as f32),
                        Some(v) => v.as_f64().map(|f| f as f32),
                    }
                };
                let parsed = (|| {
                    Some(UvTransform {
                        offset: [num("offset", 0, 0.0)?, num("offset", 1, 0.0)?],
                        rotation: num("rotation", 0, 0.0)?,
                        scale: [num("scale", 0, 1.0)?, num("scale", 1, 1.0)?],
                    })
                })();
                let t = parsed
                    .filter(|t| t.offset.iter().chain(&t.scale).chain([&t.rotation]).all(|f| f.is_finite()))
                    .ok_or_else(|| {
                        anyhow!("material {m}: the {what} texture's KHR_texture_transform is malformed or not finite")
                    })?;
                if let Some(set) = ext.get("texCoord").and_then(|v| v.as_u64()) {
                    check_tex_coord(set as u32, what)?;
                }
                Some(t)
            }
        };
        match found {
            None => found = Some((what, t)),
            Some((first, ft)) if ft != t => bail!(
                "material {m}: the {first} and {what} textures use different KHR_texture_transforms; dermis has one set of texture coordinates"
            ),
            Some(_) => {}
        }
    }
    Ok(found.and_then(|(_, t)| t))
}

/// A node's local transform in f64, refused when not finite. A TRS rotation is
/// normalised (exporters write slightly off unit quaternions); a zero one is refused.
fn local_matrix(node: &gltf::Node) -> Result<DMat4> {
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

/// Each node's parent, after checking the hierarchy is what glTF requires (3.5.3):
/// disjoint strict trees, no node its own ancestor, no node with two parents. Checked
/// without recursion, so a chain of any depth is fine.
fn parents(nodes: &[gltf::Node]) -> Result<Vec<Option<usize>>> {
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
fn append_part(
    mesh: &mut Mesh,
    world_pos: &mut Vec<DVec3>,
    part: &Part,
    world: &DMat4,
    node: &gltf::Node,
) -> Result<()> {
    let (v, t) = (part.mesh.vertices.len(), part.mesh.triangle_count());
    if mesh.vertices.len() + v > MAX_VERTICES || mesh.triangle_count() + t > MAX_TRIANGLES {
        bail!(
            "the scene has more than {MAX_VERTICES} vertices or {MAX_TRIANGLES} triangles (after instancing, at {})",
            node_label(node)
        );
    }
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

/// What the walk over the scene collected.
struct Collected {
    mesh: Mesh,
    world_pos: Vec<DVec3>,
    material: Option<usize>,
    with_uvs: usize,
    without_uvs: Vec<String>,
}

/// Walks the default scene (or the first, or every root node when there is none)
/// without recursion, appending every triangle primitive in world space.
fn collect(src: &Source, warn: &mut Warnings) -> Result<Collected> {
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
        material: None,
        with_uvs: 0,
        without_uvs: Vec::new(),
    };
    let mut parts: HashMap<(usize, usize), Option<Rc<Part>>> = HashMap::new();
    let mut visited = vec![false; nodes.len()];
    let mut stack: Vec<(usize, DMat4)> =
        roots.iter().rev().map(|&r| (r, DMat4::IDENTITY)).collect();
    while let Some((ni, parent_world)) = stack.pop() {
        let node = &nodes[ni];
        if std::mem::replace(&mut visited[ni], true) {
            bail!(
                "{} is listed twice among the scene's roots",
                node_label(node)
            );
        }
        let world = parent_world * local_matrix(node)?;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                let label = format!("{} primitive {}", mesh_label(&mesh), prim.index());
                let part = match parts.get(&key) {
                    Some(p) => p.clone(),
                    None => {
                        let p = read_primitive(src, &label, &prim, warn)?.map(Rc::new);
                        parts.insert(key, p.clone());
                        p
                    }
                };
                let Some(part) = part else { continue };
                append_part(&mut out.mesh, &mut out.world_pos, &part, &world, node)?;
                if part.has_uvs {
                    out.with_uvs += 1;
                } else if !out.without_uvs.contains(&label) {
                    out.without_uvs.push(label);
                }
                if out.material.is_none() {
                    out.material = prim.material().index();
                }
            }
        }
        let children: Vec<usize> = node.children().map(|c| c.index()).collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(out)
}

/// Converts the f64 world positions into the mesh, moving the model to the origin when
/// it lies so far from it that f32 would lose its shape (a scan georeferenced at 1e7).
/// The centre and size come from robust bounds, so one corrupt far vertex neither
/// triggers nor steers the move.
fn place(c: &mut Collected, warn: &mut Warnings) -> Result<()> {
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
    for (v, p) in c.mesh.vertices.iter_mut().zip(&c.world_pos) {
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

/// Which slot a texture found beside the scene file fills, from its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    Albedo,
    Normal,
    Specular,
}

/// Classifies an image file name (case-insensitive). Displacement maps are skipped: they
/// would otherwise match nothing useful and are huge to decode.
fn classify(file_name: &str) -> Option<Slot> {
    let name = file_name.to_ascii_lowercase();
    let is_image = [".png", ".jpg", ".jpeg"].iter().any(|e| name.ends_with(e));
    if !is_image || name.contains("disp") {
        return None;
    }
    if name.contains("tangent") || name.contains("normal") {
        Some(Slot::Normal)
    } else if name.contains("spec") {
        Some(Slot::Specular)
    } else if ["col", "albedo", "basecolor", "diffuse"]
        .iter()
        .any(|k| name.contains(k))
    {
        Some(Slot::Albedo)
    } else {
        None
    }
}

/// First file (by name, for determinism) of each slot in `dir`.
fn detect_beside(dir: &Path) -> [Option<PathBuf>; 3] {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    names.sort();
    let mut found: [Option<PathBuf>; 3] = Default::default();
    for path in names.into_iter().filter(|p| p.is_file()) {
        let Some(slot) = path.file_name().and_then(|n| n.to_str()).and_then(classify) else {
            continue;
        };
        let i = slot as usize;
        if found[i].is_none() {
            found[i] = Some(path);
        }
    }
    found
}

/// Decodes an image file to RGBA8; the error names the file and the role it was for.
pub fn load_texture(path: &Path, what: &str) -> Result<Texture> {
    let meta = std::fs::metadata(path)
        .map_err(|_| anyhow!("{what} texture not found: {}", path.display()))?;
    if !meta.is_file() {
        bail!("{what} texture is not a regular file: {}", path.display());
    }
    let img = image::open(path)
        .map_err(|e| anyhow!("cannot decode {what} texture {}: {e}", path.display()))?
        .to_rgba8();
    Ok(Texture {
        width: img.width(),
        height: img.height(),
        rgba8: img.into_raw(),
    })
}

/// Decodes image bytes (PNG, JPEG; the format is read from the bytes, not the name
/// or MIME type) to RGBA8. The decoder's default limits bound its allocations.
fn decode_image(bytes: &[u8], label: &str) -> Result<Texture> {
    let img = image::load_from_memory(bytes)
        .map_err(|e| anyhow!("cannot decode {label}: {e}"))?
        .to_rgba8();
    Ok(Texture {
        width: img.width(),
        height: img.height(),
        rgba8: img.into_raw(),
    })
}

/// Loads the image behind a glTF texture index: from a buffer view, a data: URI or a
/// file beside the scene, each read with bounds (see `gltf_source::read_uri`).
fn gltf_texture(src: &Source, texture_index: usize, what: &str) -> Result<Texture> {
    let texture = src
        .doc
        .textures()
        .nth(texture_index)
        .ok_or_else(|| anyhow!("{what} texture index {texture_index} does not exist"))?;
    let image = texture.source();
    let label = format!("{what} image {}", image.index());
    // From the JSON, not `Image::source`, which panics on an image with neither a uri
    // nor a bufferView, or a bufferView without a mimeType (the format is read from
    // the bytes anyway).
    let json = src
        .doc
        .as_json()
        .images
        .get(image.index())
        .ok_or_else(|| anyhow!("{label} does not exist"))?;
    match (&json.buffer_view, &json.uri) {
        (Some(view), _) => {
            let view =
                src.doc.views().nth(view.value()).ok_or_else(|| {
                    anyhow!("{label}: bufferView {} does not exist", view.value())
                })?;
            let bytes = view_bytes(src, &view).map_err(|e| anyhow!("{label}: {e:#}"))?;
            decode_image(bytes, &label)
        }
        (None, Some(uri)) => {
            let label = format!("{label} ('{}')", short(uri));
            let bytes = read_uri(&src.dir, uri, None, &label)?;
            decode_image(&bytes, &label)
        }
        (None, None) => bail!("{label} has neither a uri nor a bufferView"),
    }
}

/// Texture index of KHR_materials_specular's specularTexture, read from the raw JSON
/// because the `gltf` crate exposes the extension only behind a feature we do not build.
fn specular_texture_index(src: &Source, material: usize) -> Option<usize> {
    src.json
        .get("materials")?
        .get(material)?
        .get("extensions")?
        .get("KHR_materials_specular")?
        .get("specularTexture")?
        .get("index")?
        .as_u64()
        .map(|i| i as usize)
}

/// Loads the head object: merged world-space mesh and skin material. Warnings (flat
/// normals computed, missing texture coordinates, a model moved to the origin...) go
/// to stderr; [`load_head_with_warnings`] returns them instead.
pub fn load_head(path: &Path, overrides: &TextureOverrides) -> Result<Object> {
    let (object, warnings) = load_head_with_warnings(path, overrides)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(object)
}

/// Loads the head object and says what it had to make up or change. Every error is one
/// line naming the file and the offending element.
pub fn load_head_with_warnings(
    path: &Path,
    overrides: &TextureOverrides,
) -> Result<(Object, Vec<String>)> {
    load(path, overrides).map_err(|e| {
        let msg = format!("{e:#}").replace(['\n', '\r'], " ");
        let file = path.display().to_string();
        if msg.contains(&file) {
            anyhow::Error::msg(msg)
        } else {
            anyhow!("{msg} (in {file})")
        }
    })
}

/// Texture coordinates of a material's texture other than TEXCOORD_0 cannot be
/// honoured (the vertex format has one set).
fn check_tex_coord(set: u32, what: &str) -> Result<()> {
    if set != 0 {
        bail!("the {what} texture uses TEXCOORD_{set}; dermis reads only TEXCOORD_0");
    }
    Ok(())
}

fn load(path: &Path, overrides: &TextureOverrides) -> Result<(Object, Vec<String>)> {
    let src = super::gltf_source::open(path)?;
    let mut warn = Warnings::default();
    let mut c = collect(&src, &mut warn)?;
    if c.mesh.indices.is_empty() {
        bail!("no triangle mesh in the default scene");
    }
    place(&mut c, &mut warn)?;
    c.mesh
        .validate()
        .map_err(|e| anyhow!("merged mesh: {e:#}"))?;
    let any_uvs = c.with_uvs > 0;
    if any_uvs && !c.without_uvs.is_empty() {
        // Skin needs texture coordinates where it is textured; an eye or a tooth
        // without them still draws, in the colour of the texture's first texel.
        let n = c.without_uvs.len();
        let first = &c.without_uvs[0];
        let more = if n > 1 {
            format!(" and {} more", n - 1)
        } else {
            String::new()
        };
        warn.push(format!(
            "{first}{more} have no TEXCOORD_0: loaded with zero texture coordinates"
        ));
    }
    let gltf_material = c.material.and_then(|i| src.doc.materials().nth(i));
    // A texture the file or the command line asks for cannot be mapped without
    // texture coordinates: that is an error. Textures merely found beside the file are
    // dropped with a warning, and the head is drawn in its base colour.
    let from_gltf = |info: Option<(usize, u32)>, what: &str| -> Result<Option<Texture>> {
        let Some((index, set)) = info else {
            return Ok(None);
        };
        check_tex_coord(set, what)?;
        if !any_uvs {
            bail!("no primitive has TEXCOORD_0, so the file's {what} texture cannot be mapped");
        }
        gltf_texture(&src, index, what).map(Some)
    };
    let pbr = gltf_material.as_ref().map(|m| m.pbr_metallic_roughness());
    let mut base_color = from_gltf(
        pbr.as_ref()
            .and_then(|p| p.base_color_texture())
            .map(|t| (t.texture().index(), t.tex_coord())),
        "albedo",
    )?;
    let mut normal_map = from_gltf(
        gltf_material
            .as_ref()
            .and_then(|m| m.normal_texture())
            .map(|t| (t.texture().index(), t.tex_coord())),
        "normal map",
    )?;
    let mut specular_map = from_gltf(
        c.material
            .and_then(|m| specular_texture_index(&src, m))
            .map(|i| (i, 0)),
        "specular",
    )?;
    // The glTF's base colour factor tints the glTF's own texture (or is the colour when
    // there is none); a texture found beside the file was not authored against it (the
    // Lee Perry-Smith export carries a bluish Blender default), so it is not applied then.
    let factor = pbr.as_ref().map_or([1.0; 4], |p| p.base_color_factor());
    let mut factor = if factor.iter().all(|f| f.is_finite()) {
        factor
    } else {
        bail!(
            "material {} has a non-finite baseColorFactor",
            c.material.unwrap_or(0)
        );
    };
    let beside = detect_beside(&src.dir);
    let mut skipped_beside = Vec::new();
    let mut take_beside = |slot: Slot, what: &str| -> Result<Option<Texture>> {
        let Some(p) = &beside[slot as usize] else {
            return Ok(None);
        };
        if !any_uvs {
            skipped_beside.push(p.display().to_string());
            return Ok(None);
        }
        sidecar_texture(p, what, overrides).map(Some)
    };
    if base_color.is_none() {
        base_color = take_beside(Slot::Albedo, "albedo")?;
        if base_color.is_some() {
            factor = [1.0; 4];
        }
    }
    if normal_map.is_none() {
        normal_map = take_beside(Slot::Normal, "normal map")?;
    }
    if specular_map.is_none() {
        specular_map = take_beside(Slot::Specular, "specular")?;
    }
    if !skipped_beside.is_empty() {
        warn.push(format!(
            "no primitive has TEXCOORD_0: textures beside the file are not used ({})",
            skipped_beside.join(", ")
        ));
    }
    let from_override = |p: &Option<PathBuf>, what: &str| -> Result<Option<Texture>> {
        let Some(p) = p else { return Ok(None) };
        if !any_uvs {
            bail!(
                "no primitive has TEXCOORD_0, so the {what} texture {} cannot be mapped",
                p.display()
            );
        }
        sidecar_texture(p, what, overrides).map(Some)
    };
    if let Some(t) = from_override(&overrides.albedo, "albedo")? {
        base_color = Some(t);
        factor = [1.0; 4];
    }
    if let Some(t) = from_override(&overrides.normal_map, "normal map")? {
        normal_map = Some(t);
    }
    if let Some(t) = from_override(&overrides.specular_map, "specular")? {
        specular_map = Some(t);
    }
    let object = Object {
        mesh: c.mesh,
        material: Material {
            base_color,
            normal_map,
            specular_map,
            ..Material::skin([factor[0], factor[1], factor[2]])
        },
    };
    Ok((object, warn.finish()))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU32, Ordering};

    /// The Lee Perry-Smith head: `DERMIS_ASSETS` (the .glb itself or its directory), then
    /// beside the crate, then the shared workspace. Under CI a missing asset is a failure,
    /// not a skip, so the real-data tests cannot silently stop running.
    pub fn lps_path() -> Option<PathBuf> {
        let mut candidates = Vec::new();
        if let Some(v) = std::env::var_os("DERMIS_ASSETS") {
            let p = PathBuf::from(v);
            candidates.push(p.join("lee-perry-smith/LeePerrySmith.glb"));
            candidates.push(p.join("LeePerrySmith.glb"));
            candidates.push(p);
        }
        candidates.push(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../shared/assets/lee-perry-smith/LeePerrySmith.glb"),
        );
        candidates.push(PathBuf::from(
            "/work/shared/assets/lee-perry-smith/LeePerrySmith.glb",
        ));
        let found = candidates.into_iter().find(|p| p.is_file());
        if found.is_none() && std::env::var_os("CI").is_some() {
            panic!("LeePerrySmith.glb not found (set DERMIS_ASSETS); required under CI");
        }
        found
    }

    /// A fresh empty directory under the system temp dir.
    pub fn temp_dir(tag: &str) -> PathBuf {
        static N: AtomicU32 = AtomicU32::new(0);
        let dir = std::env::temp_dir().join(format!(
            "dermis-scene-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create temp dir");
        dir
    }

    fn base64(bytes: &[u8]) -> String {
        const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in bytes.chunks(3) {
            let n = (c[0] as u32) << 16
                | (*c.get(1).unwrap_or(&0) as u32) << 8
                | *c.get(2).unwrap_or(&0) as u32;
            for k in 0..4 {
                if k <= c.len() {
                    s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    s.push('=');
                }
            }
        }
        s
    }

    /// Writes a one-triangle glTF with an embedded buffer; NORMAL and TEXCOORD_0 are
    /// optional so the loader's checks can be exercised. The node is moved by `offset`.
    pub fn tiny_gltf(dir: &Path, normals: bool, uvs: bool, offset: [f32; 3]) -> PathBuf {
        let pos: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let nrm: [f32; 9] = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let uv: [f32; 6] = [0.0, 1.0, 1.0, 1.0, 0.0, 0.0];
        let mut buf: Vec<u8> = Vec::new();
        for f in pos.iter().chain(&nrm).chain(&uv) {
            buf.extend_from_slice(&f.to_le_bytes());
        }
        let mut attrs = vec![r#""POSITION": 0"#];
        if normals {
            attrs.push(r#""NORMAL": 1"#);
        }
        if uvs {
            attrs.push(r#""TEXCOORD_0": 2"#);
        }
        let json = format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0, "name": "tri", "translation": [{}, {}, {}]}}],
  "meshes": [{{"name": "tri", "primitives": [{{"attributes": {{{}}}}}]}}],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 36, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 72, "byteLength": 24}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}}
  ]
}}"#,
            offset[0],
            offset[1],
            offset[2],
            attrs.join(", "),
            buf.len(),
            base64(&buf)
        );
        let path = dir.join("tri.gltf");
        std::fs::write(&path, json).expect("write tiny glTF");
        path
    }

    fn err(r: Result<Object>) -> String {
        match r {
            Ok(_) => panic!("expected an error"),
            Err(e) => format!("{e:#}"),
        }
    }

    #[test]
    fn tiny_gltf_loads_with_transform_and_tangents() {
        let dir = temp_dir("ok");
        let obj = load_head(
            &tiny_gltf(&dir, true, true, [2.0, 3.0, 4.0]),
            &Default::default(),
        )
        .unwrap();
        assert_eq!(obj.mesh.triangle_count(), 1);
        assert_eq!(obj.mesh.bounds().min, glam::Vec3::new(2.0, 3.0, 4.0));
        assert!(obj.mesh.vertices[0].tangent[0] > 0.99);
        assert!(obj.material.skin && obj.material.base_color.is_none());
        assert_eq!(obj.material.base_color_factor, [1.0; 3]);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn missing_file() {
        let p = temp_dir("missing").join("nope.glb");
        let e = err(load_head(&p, &Default::default()));
        assert!(e.contains("scene file not found"), "{e}");
        assert!(e.contains("nope.glb"), "{e}");
    }

    #[test]
    fn corrupt_file() {
        let dir = temp_dir("corrupt");
        let p = dir.join("bad.glb");
        std::fs::write(&p, b"glTF\x02\x00\x00\x00garbage that is not a glb").unwrap();
        let e = err(load_head(&p, &Default::default()));
        assert!(e.contains("not a valid glTF file"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn missing_normals_become_flat_and_missing_uvs_zero() {
        // glTF: without NORMAL the client computes flat normals; without TEXCOORD_0
        // the primitive still draws (zero texture coordinates, with a warning).
        let dir = temp_dir("attrs");
        let (obj, w) =
            load_head_with_warnings(&tiny_gltf(&dir, false, true, [0.0; 3]), &Default::default())
                .unwrap();
        assert!(obj
            .mesh
            .vertices
            .iter()
            .all(|v| v.normal == [0.0, 0.0, 1.0]));
        assert!(
            w.iter()
                .any(|w| w.contains("mesh 'tri' primitive 0 has no NORMAL: flat normals")),
            "{w:?}"
        );
        let (obj, w) =
            load_head_with_warnings(&tiny_gltf(&dir, true, false, [0.0; 3]), &Default::default())
                .unwrap();
        assert!(obj.mesh.vertices.iter().all(|v| v.uv == [0.0; 2]));
        assert!(obj.material.base_color.is_none());
        assert!(w.is_empty(), "{w:?}");
        let _ = std::fs::remove_dir_all(dir);
    }

    // ---- Hand-made files for the loader's defences -------------------------------

    fn bytes_f32(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|f| f.to_le_bytes()).collect()
    }

    /// Writes `json` as a .gltf with `buffer` embedded as buffer 0 (a data: URI).
    fn write_gltf(dir: &Path, name: &str, mut json: serde_json::Value, buffer: &[u8]) -> PathBuf {
        json["asset"] = serde_json::json!({"version": "2.0"});
        if json.get("buffers").is_none() {
            json["buffers"] = serde_json::json!([{
                "byteLength": buffer.len(),
                "uri": format!("data:application/octet-stream;base64,{}", base64(buffer)),
            }]);
        }
        let path = dir.join(name);
        std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
        path
    }

    /// A quad (4 vertices in z = 0, normals +Z, UVs) followed by `extra` bytes; the
    /// accessors are: 0 POSITION, 1 NORMAL, 2 TEXCOORD_0 (float), and views 0..2 over
    /// them, view 3 over `extra`. `prim` and the extra accessors are the test's.
    fn quad_file(
        dir: &Path,
        name: &str,
        prim: serde_json::Value,
        extra_accessors: serde_json::Value,
        extra: &[u8],
        nodes: Option<serde_json::Value>,
    ) -> PathBuf {
        let pos = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
        let nrm = [0.0, 0.0, 1.0].repeat(4);
        let uv = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
        let mut buf = bytes_f32(&pos);
        buf.extend(bytes_f32(&nrm));
        buf.extend(bytes_f32(&uv));
        buf.extend(extra);
        let mut accessors = vec![
            serde_json::json!({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}),
            serde_json::json!({"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}),
            serde_json::json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}),
        ];
        accessors.extend(extra_accessors.as_array().cloned().unwrap_or_default());
        // Without indices, the four vertices are drawn as a fan: the quad.
        let mut prim = prim;
        if prim.get("indices").is_none() && prim.get("mode").is_none() {
            prim["mode"] = serde_json::json!(6);
        }
        let json = serde_json::json!({
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": nodes.unwrap_or(serde_json::json!([{"mesh": 0}])),
            "meshes": [{"name": "quad", "primitives": [prim]}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                {"buffer": 0, "byteOffset": 96, "byteLength": 32},
                {"buffer": 0, "byteOffset": 128, "byteLength": extra.len().max(1)},
            ],
            "accessors": accessors,
        });
        if extra.is_empty() {
            buf.push(0);
        }
        write_gltf(dir, name, json, &buf)
    }

    fn attrs() -> serde_json::Value {
        serde_json::json!({"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2})
    }

    fn load_err(path: &Path) -> String {
        let e = err(load_head(path, &Default::default()));
        assert!(!e.contains('\n'), "not one line: {e}");
        e
    }

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
    fn index_storage_is_checked_before_reading() {
        let dir = temp_dir("indices");
        let idx = [0u8, 1, 2, 0, 2, 3];
        let with = |name: &str, ct: u32, normalized: bool| {
            quad_file(
                &dir,
                name,
                serde_json::json!({"attributes": attrs(), "indices": 3}),
                serde_json::json!([{"bufferView": 3, "componentType": ct, "count": 6, "type": "SCALAR", "normalized": normalized}]),
                &idx,
                None,
            )
        };
        // UNSIGNED_BYTE indices are glTF: they load.
        let obj = load_head(&with("u8.gltf", 5121, false), &Default::default()).unwrap();
        assert_eq!(obj.mesh.indices, vec![0, 1, 2, 0, 2, 3]);
        // BYTE indices panicked inside the gltf crate.
        let e = load_err(&with("i8.gltf", 5120, false));
        assert!(e.contains("mesh 'quad' primitive 0: indices accessor 3 is stored as BYTE, which glTF does not allow for indices"), "{e}");
        let e = load_err(&with("u8n.gltf", 5121, true));
        assert!(e.contains("normalized UNSIGNED_BYTE"), "{e}");
        // Indices pointing at the float POSITION accessor.
        let p = quad_file(
            &dir,
            "float.gltf",
            serde_json::json!({"attributes": attrs(), "indices": 0}),
            serde_json::json!([]),
            &[],
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("indices accessor 0 has type VEC3, expected SCALAR"),
            "{e}"
        );
        // An index accessor running past its data was dropped and the mesh drawn as
        // loose triangles.
        let p = quad_file(
            &dir,
            "short.gltf",
            serde_json::json!({"attributes": attrs(), "indices": 3}),
            serde_json::json!([{"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]),
            &[0, 0, 1, 0, 2, 0],
            None,
        );
        let e = load_err(&p);
        assert!(e.contains("indices accessor 3 (6 x 2 bytes, stride 2, offset 0) runs past the end of bufferView 3 (6 bytes)"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    // Found by the long fuzz run (seed 1, case json7324): a TEXCOORD_0 accessor
    // two bytes into its buffer read floats out of step (5e36), and the sampler's
    // arithmetic turned them into NaN pixels. Both the misalignment (a glTF MUST)
    // and such coordinates are now one-line errors.
    #[test]
    fn misaligned_accessors_and_huge_texcoords_are_refused() {
        let dir = temp_dir("align");
        let uv: Vec<u8> = [0u8, 0]
            .into_iter()
            .chain(bytes_f32(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]))
            .collect();
        let p = quad_file(
            &dir,
            "misaligned.gltf",
            serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3}}),
            serde_json::json!([{"bufferView": 3, "byteOffset": 2, "componentType": 5126, "count": 4, "type": "VEC2"}]),
            &uv,
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("TEXCOORD_0 accessor 3: its data starts at byte 130 of buffer 0, not a multiple of its 4-byte components"),
            "{e}"
        );
        let huge = bytes_f32(&[0.0, 1.0, 5e36, 1.0, 1.0, 0.0, 0.0, 0.0]);
        let p = quad_file(
            &dir,
            "huge.gltf",
            serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3}}),
            serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"}]),
            &huge,
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("TEXCOORD_0 of vertex 1 is (5e36, 1e0): beyond 1.6777216e7"),
            "{e}"
        );
        // Large but addressable coordinates (a tiling texture) still load.
        let tiled = bytes_f32(&[0.0, 1.0, 4096.0, 1.0, 4096.0, 0.0, 0.0, 0.0]);
        let p = quad_file(
            &dir,
            "tiled.gltf",
            serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3}}),
            serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"}]),
            &tiled,
            None,
        );
        assert!(load_head(&p, &Default::default()).is_ok());
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn texcoord_storage_and_strides() {
        let dir = temp_dir("uvs");
        let uv8: [u8; 8] = [0, 255, 255, 255, 255, 0, 0, 0];
        let with = |name: &str, ct: u32, normalized: bool| {
            quad_file(
                &dir,
                name,
                serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3}}),
                serde_json::json!([{"bufferView": 3, "componentType": ct, "count": 4, "type": "VEC2", "normalized": normalized}]),
                &uv8,
                None,
            )
        };
        let obj = load_head(&with("u8n.gltf", 5121, true), &Default::default()).unwrap();
        assert_eq!(obj.mesh.vertices[1].uv, [1.0, 1.0]);
        let obj = load_head(&with("i8n.gltf", 5120, true), &Default::default()).unwrap();
        assert_eq!(obj.mesh.vertices[0].uv, [0.0, -1.0 / 127.0]);
        // Plain BYTE texture coordinates panicked inside the gltf crate.
        let e = load_err(&with("i8.gltf", 5120, false));
        assert!(e.contains("TEXCOORD_0 accessor 3 is stored as BYTE, which glTF does not allow for texture coordinates (without KHR_mesh_quantization)"), "{e}");
        // A byteStride smaller than the element panicked too.
        let p = quad_file(
            &dir,
            "stride.gltf",
            serde_json::json!({"attributes": {"POSITION": 3, "NORMAL": 1}}),
            serde_json::json!([{"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,1]}]),
            &[],
            None,
        );
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        json["bufferViews"].as_array_mut().unwrap().push(
            serde_json::json!({"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 4}),
        );
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(e.contains("POSITION accessor 3: byteStride 4 of bufferView 4 is smaller than an element (12 bytes)"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn strips_and_fans_load_points_and_lines_are_refused() {
        let dir = temp_dir("modes");
        for (mode, name) in [(5, "strip"), (6, "fan")] {
            // Strip 0 1 3 2 and fan 0 1 2 3 both cover the quad counter-clockwise.
            let order: [u8; 4] = if mode == 5 {
                [0, 1, 3, 2]
            } else {
                [0, 1, 2, 3]
            };
            let p = quad_file(
                &dir,
                &format!("{name}.gltf"),
                serde_json::json!({"attributes": attrs(), "indices": 3, "mode": mode}),
                serde_json::json!([{"bufferView": 3, "componentType": 5121, "count": 4, "type": "SCALAR"}]),
                &order,
                None,
            );
            let obj = load_head(&p, &Default::default()).unwrap();
            let m = &obj.mesh;
            assert_eq!(m.triangle_count(), 2, "{name}");
            for t in m.indices.chunks_exact(3) {
                let q = |i: u32| Vec3::from(m.vertices[i as usize].position);
                let n = (q(t[1]) - q(t[0])).cross(q(t[2]) - q(t[0]));
                assert!(n.z > 0.0, "{name}: triangle {t:?} is clockwise");
            }
        }
        for (mode, name) in [
            (0, "POINTS"),
            (1, "LINES"),
            (2, "LINE_LOOP"),
            (3, "LINE_STRIP"),
        ] {
            let p = quad_file(
                &dir,
                "lines.gltf",
                serde_json::json!({"attributes": attrs(), "mode": mode}),
                serde_json::json!([]),
                &[],
                None,
            );
            let e = load_err(&p);
            assert!(
                e.contains(&format!(
                    "mesh 'quad' primitive 0 has mode {name}: dermis draws only triangles"
                )),
                "{e}"
            );
        }
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn non_finite_input_is_named() {
        let dir = temp_dir("nan");
        let bad = bytes_f32(&[
            0.0,
            f32::NAN,
            0.0,
            1.0,
            0.0,
            0.0,
            1.0,
            1.0,
            0.0,
            0.0,
            1.0,
            0.0,
        ]);
        for (attr, what) in [("POSITION", "POSITION"), ("NORMAL", "NORMAL")] {
            let mut a = attrs();
            a[attr] = serde_json::json!(3);
            let p = quad_file(
                &dir,
                "nan.gltf",
                serde_json::json!({"attributes": a}),
                serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}]),
                &bad,
                None,
            );
            let e = load_err(&p);
            assert!(
                e.contains(&format!(
                    "mesh 'quad' primitive 0: {what} of vertex 0 is not finite (0, NaN, 0)"
                )),
                "{e}"
            );
        }
        let uv = bytes_f32(&[0.0, 0.0, f32::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let p = quad_file(
            &dir,
            "inf.gltf",
            serde_json::json!({"attributes": {"POSITION": 0, "TEXCOORD_0": 3}}),
            serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"}]),
            &uv,
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("TEXCOORD_0 of vertex 1 is not finite (inf, 0)"),
            "{e}"
        );
        // JSON has no NaN, but 1e39 does not fit an f32: an infinite scale.
        let nodes = serde_json::json!([{"mesh": 0, "name": "head", "scale": [1.0, 1e39, 1.0]}]);
        let p = quad_file(
            &dir,
            "node.gltf",
            serde_json::json!({"attributes": attrs()}),
            serde_json::json!([]),
            &[],
            Some(nodes),
        );
        let e = load_err(&p);
        assert!(e.contains("node 0 'head' has a non-finite scale"), "{e}");
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

    #[test]
    fn required_extensions_are_named_first() {
        let dir = temp_dir("ext");
        let p = quad_file(
            &dir,
            "draco.gltf",
            serde_json::json!({"attributes": attrs()}),
            serde_json::json!([]),
            &[],
            None,
        );
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        json["extensionsUsed"] = serde_json::json!(["KHR_draco_mesh_compression"]);
        json["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"]);
        // Draco leaves accessors without a bufferView: the validator's complaints
        // about them must not bury the cause.
        for a in json["accessors"].as_array_mut().unwrap() {
            a.as_object_mut().unwrap().remove("bufferView");
        }
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(
            e.starts_with(
                "KHR_draco_mesh_compression is not supported (listed in extensionsRequired)"
            ),
            "{e}"
        );
        assert!(e.len() < 200, "{e}");
        json["extensionsRequired"] =
            serde_json::json!(["KHR_texture_basisu", "EXT_meshopt_compression"]);
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(
            e.starts_with("KHR_texture_basisu, EXT_meshopt_compression are not supported"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn buffers_are_read_only_as_far_as_declared() {
        let dir = temp_dir("bufs");
        let p = quad_file(
            &dir,
            "q.gltf",
            serde_json::json!({"attributes": attrs()}),
            serde_json::json!([]),
            &[],
            None,
        );
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        let with_buffer = |b: serde_json::Value| {
            let mut j = json.clone();
            j["buffers"] = serde_json::json!([b]);
            std::fs::write(&p, serde_json::to_vec(&j).unwrap()).unwrap();
            load_err(&p)
        };
        // /dev/zero was read until memory ran out.
        let e = with_buffer(serde_json::json!({"byteLength": 129, "uri": "/dev/zero"}));
        assert!(
            e.contains("buffer 0: /dev/zero is not a regular file"),
            "{e}"
        );
        let e = with_buffer(serde_json::json!({"byteLength": 129, "uri": "missing.bin"}));
        assert!(
            e.contains("buffer 0: cannot read") && e.contains("missing.bin"),
            "{e}"
        );
        std::fs::write(dir.join("small.bin"), [0u8; 16]).unwrap();
        let e = with_buffer(
            serde_json::json!({"byteLength": 1_000_000_000_000u64, "uri": "small.bin"}),
        );
        assert!(
            e.contains("buffer 0 declares 1000000000000 bytes but") && e.contains("has only 16"),
            "{e}"
        );
        let e = with_buffer(
            serde_json::json!({"byteLength": 1u64 << 50, "uri": "data:application/octet-stream;base64,AAAA"}),
        );
        assert!(e.contains("holds at most 3"), "{e}");
        let e = with_buffer(serde_json::json!({"byteLength": 129}));
        assert!(
            e.contains("buffer 0 has no uri and the file has no GLB BIN chunk"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn sparse_accessors_are_applied() {
        let dir = temp_dir("sparse");
        // Vertex 2 moved from (1, 1, 0) to (1, 2, 0) by a sparse substitution.
        let mut extra = vec![2u8, 0, 0, 0];
        extra.extend(bytes_f32(&[1.0, 2.0, 0.0]));
        let mut a = attrs();
        a["POSITION"] = serde_json::json!(3);
        let p = quad_file(
            &dir,
            "sparse.gltf",
            serde_json::json!({"attributes": a}),
            serde_json::json!([{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,2,0],
                "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5121}, "values": {"bufferView": 3, "byteOffset": 4}}}]),
            &extra,
            None,
        );
        let obj = load_head(&p, &Default::default()).unwrap();
        assert_eq!(obj.mesh.bounds().max, Vec3::new(1.0, 2.0, 0.0));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn quantized_uvs_go_through_the_texture_transform() {
        // What gltfpack writes: UNSIGNED_SHORT texture coordinates, not normalized,
        // with KHR_texture_transform scaling them back into 0..1.
        let dir = temp_dir("kht");
        image::RgbaImage::new(2, 2)
            .save(dir.join("albedo.png"))
            .unwrap();
        let uv16: Vec<u8> = [0u16, 4000, 4000, 4000, 4000, 0, 0, 0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let p = quad_file(
            &dir,
            "q.gltf",
            serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3}, "material": 0}),
            serde_json::json!([{"bufferView": 3, "componentType": 5123, "count": 4, "type": "VEC2"}]),
            &uv16,
            None,
        );
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        let kht = serde_json::json!({"KHR_texture_transform": {"offset": [0.5, 0.0], "scale": [0.00025, 0.00025]}});
        json["extensionsUsed"] =
            serde_json::json!(["KHR_mesh_quantization", "KHR_texture_transform"]);
        json["extensionsRequired"] = serde_json::json!(["KHR_mesh_quantization"]);
        json["images"] = serde_json::json!([{"uri": "albedo.png"}]);
        json["textures"] = serde_json::json!([{"source": 0}]);
        json["materials"] = serde_json::json!([{
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": kht}},
            "normalTexture": {"index": 0, "extensions": kht}
        }]);
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let obj = load_head(&p, &Default::default()).unwrap();
        assert_eq!(obj.mesh.vertices[1].uv, [1.5, 1.0]);
        assert_eq!(obj.mesh.vertices[3].uv, [0.5, 0.0]);
        assert!(obj.material.base_color.is_some());
        // Different transforms on the albedo and the normal map cannot share one set
        // of coordinates.
        json["materials"][0]["normalTexture"] = serde_json::json!({"index": 0});
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(e.contains("material 0: the albedo and normal map textures use different KHR_texture_transforms"), "{e}");
        // Without KHR_mesh_quantization plain UNSIGNED_SHORT coordinates are refused.
        json["extensionsUsed"] = serde_json::json!([]);
        json["extensionsRequired"] = serde_json::json!([]);
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(
            e.contains(
                "TEXCOORD_0 accessor 3 is stored as UNSIGNED_SHORT, which glTF does not allow"
            ),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn panics_the_fuzzer_found_in_the_gltf_crate() {
        let dir = temp_dir("crate");
        // The crate's validator indexed the accessors with POSITION's index unchecked.
        let p = quad_file(
            &dir,
            "pos.gltf",
            serde_json::json!({"attributes": {"POSITION": 99}}),
            serde_json::json!([]),
            &[],
            None,
        );
        let e = load_err(&p);
        assert!(
            e.contains("attributes.POSITION: accessor 99 does not exist"),
            "{e}"
        );
        // `Image::source` unwrapped a missing uri (and a bufferView's mimeType).
        let p = quad_file(
            &dir,
            "img.gltf",
            serde_json::json!({"attributes": attrs(), "material": 0}),
            serde_json::json!([]),
            &[],
            None,
        );
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        json["images"] = serde_json::json!([{"name": "nothing"}]);
        json["textures"] = serde_json::json!([{"source": 0}]);
        json["materials"] =
            serde_json::json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let e = load_err(&p);
        assert!(
            e.contains("albedo image 0 has neither a uri nor a bufferView"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn textures_without_texture_coordinates() {
        let dir = temp_dir("nouv");
        // No primitive has UVs: a texture lying beside the file is dropped (warning),
        // one the command line asks for is an error.
        let scene = tiny_gltf(&dir, true, false, [0.0; 3]);
        image::RgbaImage::new(2, 2)
            .save(dir.join("Head_Albedo.png"))
            .unwrap();
        let (obj, w) = load_head_with_warnings(&scene, &Default::default()).unwrap();
        assert!(obj.material.base_color.is_none());
        assert!(
            w.iter()
                .any(|w| w.contains("textures beside the file are not used")),
            "{w:?}"
        );
        let e = err(load_head(
            &scene,
            &TextureOverrides {
                albedo: Some(dir.join("Head_Albedo.png")),
                ..Default::default()
            },
        ));
        assert!(
            e.contains("no primitive has TEXCOORD_0, so the albedo texture"),
            "{e}"
        );
        // One primitive with UVs and one without: loads, with a warning naming it.
        let p = quad_file(
            &dir,
            "two.gltf",
            serde_json::json!({"attributes": attrs()}),
            serde_json::json!([]),
            &[],
            None,
        );
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        json["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": 6}));
        std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
        let (obj, w) = load_head_with_warnings(&p, &Default::default()).unwrap();
        assert_eq!(obj.mesh.triangle_count(), 4);
        assert!(obj.material.base_color.is_some());
        assert!(
            w.iter().any(|w| w.contains(
                "mesh 'quad' primitive 1 have no TEXCOORD_0: loaded with zero texture coordinates"
            )),
            "{w:?}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn override_textures_load_or_fail_naming_the_file() {
        let dir = temp_dir("tex");
        let scene = tiny_gltf(&dir, true, true, [0.0; 3]);
        let png = dir.join("custom.png");
        image::RgbaImage::from_pixel(3, 2, image::Rgba([10, 20, 30, 255]))
            .save(&png)
            .unwrap();
        let ok = load_head(
            &scene,
            &TextureOverrides {
                specular_map: Some(png.clone()),
                ..Default::default()
            },
        )
        .unwrap();
        let spec = ok.material.specular_map.unwrap();
        assert_eq!((spec.width, spec.height), (3, 2));
        assert_eq!(&spec.rgba8[..4], &[10, 20, 30, 255]);

        let missing = dir.join("absent.png");
        let e = err(load_head(
            &scene,
            &TextureOverrides {
                albedo: Some(missing.clone()),
                ..Default::default()
            },
        ));
        assert!(e.contains("albedo texture not found"), "{e}");
        assert!(e.contains("absent.png"), "{e}");

        let corrupt = dir.join("broken.jpg");
        std::fs::write(&corrupt, b"\xff\xd8\xff not really a jpeg").unwrap();
        let e = err(load_head(
            &scene,
            &TextureOverrides {
                normal_map: Some(corrupt),
                ..Default::default()
            },
        ));
        assert!(e.contains("cannot decode normal map texture"), "{e}");
        assert!(e.contains("broken.jpg"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn textures_beside_the_file_are_found_by_name() {
        assert_eq!(classify("Map-COL.jpg"), Some(Slot::Albedo));
        assert_eq!(
            classify("Infinite-Level_02_Tangent_SmoothUV.jpg"),
            Some(Slot::Normal)
        );
        assert_eq!(classify("Map-SPEC.jpg"), Some(Slot::Specular));
        assert_eq!(classify("Infinite-Level_02_Disp_NoSmoothUV-4096.jpg"), None);
        assert_eq!(classify("skin_BaseColor.PNG"), Some(Slot::Albedo));
        assert_eq!(classify("notes.txt"), None);
        let dir = temp_dir("beside");
        let scene = tiny_gltf(&dir, true, true, [0.0; 3]);
        image::RgbaImage::new(4, 4)
            .save(dir.join("Head_Albedo.png"))
            .unwrap();
        let obj = load_head(&scene, &Default::default()).unwrap();
        assert_eq!(obj.material.base_color.map(|t| t.width), Some(4));
        assert!(obj.material.normal_map.is_none());
        let _ = std::fs::remove_dir_all(dir);
    }
}
