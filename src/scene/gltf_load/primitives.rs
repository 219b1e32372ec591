//! Primitives: one glTF primitive read into a triangle mesh in its own space
//! (attributes through the bounds-checked accessors, strips and fans made lists,
//! missing normals made flat, the material's texture transform baked in).

use anyhow::{anyhow, bail, Result};
use gltf::mesh::Mode;
use gltf::Semantic;

use super::checks::{
    check_finite, check_precision, check_tex_coord, check_texcoord_range, mode_name,
};
use super::{Warnings, MAX_TRIANGLES, MAX_VERTICES};
use crate::scene::gltf_accessor::{read_attribute, read_indices, read_joints, Use};
use crate::scene::gltf_source::Source;
use crate::scene::mesh::{Mesh, Vertex};
use crate::scene::morph::MorphTarget;
use crate::scene::skin::SLOTS;

/// Converts an index list of any triangle mode into a triangle list with the winding
/// glTF defines (3.7.2.1): strip triangle i is (i, i+1, i+2) for even i and
/// (i, i+2, i+1) for odd i, so every triangle keeps the first one's orientation; fan
/// triangle i is (i+1, i+2, 0). Triangles with a repeated vertex are the stitching of
/// strips and cover nothing: they are left out.
pub(super) fn triangulate(mode: Mode, idx: &[u32], label: &str) -> Result<Vec<u32>> {
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

/// One triangle primitive in its own space, as read once and shared by every node
/// that instances its mesh.
pub(super) struct Part {
    pub(super) mesh: Mesh,
    pub(super) has_uvs: bool,
    /// Its morph targets, in its own space (`first` 0).
    pub(super) targets: Vec<MorphTarget>,
    /// Its vertices' joints and weights (`JOINTS_0/1`, `WEIGHTS_0/1`).
    pub(super) influences: Option<Influences>,
}

impl Part {
    /// Refuses to append this primitive to `mesh` past the loader's vertex
    /// and triangle limits (`at`: where it is placed, for the message).
    pub(super) fn check_room(&self, mesh: &Mesh, at: &str) -> Result<()> {
        let (v, t) = (self.mesh.vertices.len(), self.mesh.triangle_count());
        if mesh.vertices.len() + v > MAX_VERTICES || mesh.triangle_count() + t > MAX_TRIANGLES {
            bail!("the scene has more than {MAX_VERTICES} vertices or {MAX_TRIANGLES} triangles (after instancing, at {at})");
        }
        Ok(())
    }
}

/// A primitive's skin attributes, both sets in one list of eight slots.
pub(super) struct Influences {
    pub(super) joints: Vec<[u32; SLOTS]>,
    pub(super) weights: Vec<[f32; SLOTS]>,
    /// 4 (one set) or 8 (two).
    pub(super) slots: usize,
}

/// Reads `JOINTS_0`/`WEIGHTS_0` and `JOINTS_1`/`WEIGHTS_1` (glTF 3.7.3.3):
/// each set's two attributes together, as long as POSITION. More sets than
/// two are refused (dermis's skins carry eight joints a vertex).
fn read_influences(
    src: &Source,
    label: &str,
    prim: &gltf::Primitive,
    n: usize,
) -> Result<Option<Influences>> {
    let mut out: Option<Influences> = None;
    for set in 0..3u32 {
        let j = prim.get(&Semantic::Joints(set));
        let w = prim.get(&Semantic::Weights(set));
        let (j, w) = match (j, w) {
            (None, None) => break,
            (Some(j), Some(w)) => (j, w),
            (j, _) => bail!(
                "{label} has {} without {}",
                if j.is_some() {
                    format!("JOINTS_{set}")
                } else {
                    format!("WEIGHTS_{set}")
                },
                if j.is_some() {
                    format!("WEIGHTS_{set}")
                } else {
                    format!("JOINTS_{set}")
                }
            ),
        };
        if set == 2 {
            bail!("{label} has a third set of joints (JOINTS_2): dermis skins with eight joints a vertex at most");
        }
        let joints = read_joints(src, &j, &format!("{label}: JOINTS_{set}"))?;
        let weights: Vec<[f32; 4]> =
            read_attribute(src, &w, Use::Weights, &format!("{label}: WEIGHTS_{set}"))?;
        for (name, len) in [("JOINTS", joints.len()), ("WEIGHTS", weights.len())] {
            if len != n {
                bail!("{label}: {name}_{set} has {len} elements but POSITION has {n}");
            }
        }
        let o = out.get_or_insert_with(|| Influences {
            joints: vec![[0; SLOTS]; n],
            weights: vec![[0.0; SLOTS]; n],
            slots: 0,
        });
        let base = 4 * set as usize;
        for k in 0..n {
            o.joints[k][base..base + 4].copy_from_slice(&joints[k]);
            o.weights[k][base..base + 4].copy_from_slice(&weights[k]);
        }
        o.slots = base + 4;
    }
    Ok(out)
}

/// A primitive's morph targets (POSITION, NORMAL, TANGENT offsets), each the
/// primitive's vertex count long and finite. Tangent offsets are dropped
/// where the primitive's tangents are generated (they offset tangents the
/// file did not give).
fn read_targets(
    src: &Source,
    label: &str,
    prim: &gltf::Primitive,
    n: usize,
    tangents_generated: bool,
) -> Result<Vec<MorphTarget>> {
    let mut out = Vec::new();
    for (i, t) in prim.morph_targets().enumerate() {
        let read = |acc: Option<gltf::Accessor>, what: &str| -> Result<Vec<[f32; 3]>> {
            let Some(acc) = acc else {
                return Ok(Vec::new());
            };
            let what = format!("{label}: morph target {i} {what}");
            let v: Vec<[f32; 3]> = read_attribute(src, &acc, Use::Offset, &what)?;
            if v.len() != n {
                bail!("{what} has {} offsets but POSITION has {n}", v.len());
            }
            check_finite(&v, &what)?;
            Ok(v)
        };
        let position = match t.positions() {
            Some(a) => read(Some(a), "POSITION")?,
            None => vec![[0.0; 3]; n],
        };
        let normal = read(t.normals(), "NORMAL")?;
        let tangent = read(t.tangents(), "TANGENT")?;
        out.push(MorphTarget {
            name: None,
            first: 0,
            position,
            normal,
            tangent: if tangents_generated {
                Vec::new()
            } else {
                tangent
            },
        });
    }
    Ok(out)
}

/// Reads one primitive into a triangle mesh in the primitive's own space; `None` when
/// it has no triangles. Missing normals become flat normals and missing texture
/// coordinates zeros (both with a warning), as glTF allows both to be absent.
pub(super) fn read_primitive(
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
            // A finite transform can still overflow (a scale of 1e38 on a
            // coordinate of 10): the file's fault, said here, not NaN
            // pixels at the writer.
            let what = format!("{label}: TEXCOORD_0 through the material's KHR_texture_transform");
            check_finite(v, &what)?;
            check_texcoord_range(v, &what)?;
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
    check_precision(&positions, label)?;
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
    let mut targets = read_targets(src, label, prim, n, tangents.is_none())?;
    let mut influences = read_influences(src, label, prim, n)?;
    if normals.is_none() {
        warn.push(format!(
            "{label} has no NORMAL: flat normals computed, as glTF specifies (it will look faceted)"
        ));
        // Flat normals give each triangle corner a vertex of its own: the
        // targets follow (corner k is vertex triangles[k]).
        let corners = mesh.indices.clone();
        mesh.make_flat_normals();
        if !targets.is_empty() {
            warn.push(format!(
                "{label} has morph targets and no NORMAL: its flat normals are the rest shape's"
            ));
        }
        for t in &mut targets {
            let pick = |v: &Vec<[f32; 3]>| -> Vec<[f32; 3]> {
                if v.is_empty() {
                    Vec::new()
                } else {
                    corners.iter().map(|&i| v[i as usize]).collect()
                }
            };
            t.position = pick(&t.position);
            t.normal = pick(&t.normal);
            t.tangent = pick(&t.tangent);
        }
        if let Some(inf) = &mut influences {
            inf.joints = corners.iter().map(|&i| inf.joints[i as usize]).collect();
            inf.weights = corners.iter().map(|&i| inf.weights[i as usize]).collect();
        }
    }
    if tangents.is_none() {
        mesh.generate_tangents();
    }
    Ok(Some(Part {
        mesh,
        has_uvs: uvs.is_some(),
        targets,
        influences,
    }))
}

/// KHR_texture_transform of a material's textures, as the affine map
/// uv' = T(offset) R(rotation) S(scale) uv of the extension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvTransform {
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
pub(super) fn texture_transform(
    src: &Source,
    material: Option<usize>,
) -> Result<Option<UvTransform>> {
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
