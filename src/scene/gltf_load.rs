//! Loads a character from glTF/GLB: every triangle primitive of the default scene, in world
//! space, merged per material: the head (its one scattered skin material, chosen by
//! `crate::scene::skin_rule`, each decision a note) and its other parts, each with its own
//! material and textures.
//!
//! Scans are often shipped as a bare mesh with textures lying next to it (the Lee
//! Perry-Smith head is), so textures the glTF does not reference are found beside it
//! by a naming rule (stated in `textures`), each one named in a note; the command
//! line can override each one.
//!
//! By concern: `nodes` (the node graph, world placement, recentring), `primitives`
//! (one primitive to a triangle mesh), `textures` (the material's images and the
//! naming rule), `checks` (value checks and the labels errors use); `fixture` builds
//! the glTF files the tests and the fuzzer load.
//!
//! Every input ends in a loaded head or one error line naming the file and the element
//! (the bytes are read with bounds by `gltf_source` and `gltf_accessor`, every file
//! through the one door, `crate::files`; the node graph is walked without recursion).
//! What glTF allows is loaded, what it forbids refused:
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
//!   address; the sampler's arithmetic overflows). Node transforms are composed in
//!   f64, and a model far from the origin for its size (a scan placed at 1e7) is moved
//!   to it, so f32 keeps its shape.
//! - Far outlier vertices (one flipped exponent bit) load with a warning; the framing
//!   (`head_measure`, the scene's bounds) leaves them out.

mod animations;
mod checks;
pub mod fixture;
mod instancing;
mod nodes;
mod primitives;
mod skeleton;
mod skins;
mod textures;

use super::mesh::Object;
use super::rig::{clip_time, ObjectRig, Rig};
use super::skin_rule;
use anyhow::{anyhow, bail, Result};
use std::path::Path;

pub use super::head_measure::face_direction;
pub use textures::{load_texture, TextureOverrides};

/// Most vertices and triangles the merged head may have. A mesh instanced by many
/// nodes multiplies what a small file holds; this keeps such a file from taking all
/// memory (a dense head scan has a few million).
pub const MAX_VERTICES: usize = 1 << 25;
pub const MAX_TRIANGLES: usize = 1 << 25;

/// Warnings beyond this many are counted, not listed.
const MAX_WARNINGS: usize = 20;

/// Warnings collected while loading, deduplicated (an instanced mesh would repeat
/// them) and capped.
#[derive(Default)]
struct Warnings {
    list: Vec<String>,
    dropped: usize,
    notes: Vec<String>,
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

    /// What was taken without being asked (never capped: one per texture role).
    fn note(&mut self, n: String) {
        self.notes.push(n);
    }

    fn finish(mut self, object: Object, parts: Vec<Object>) -> Loaded {
        if self.dropped > 0 {
            self.list
                .push(format!("... and {} more warnings", self.dropped));
        }
        Loaded {
            object,
            parts,
            rig: None,
            warnings: self.list,
            notes: self.notes,
        }
    }
}

/// Loads the head object: merged world-space mesh and skin material. Warnings (flat
/// normals computed, missing texture coordinates, a model moved to the origin...) go
/// to stderr; [`load_head_with_warnings`] returns them instead.
pub fn load_head(path: &Path, overrides: &TextureOverrides) -> Result<Object> {
    let l = load_head_with_notes(path, overrides)?;
    for n in l.notes {
        eprintln!("note: {}: {n}", path.display());
    }
    for w in l.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(l.object)
}

/// Loads the head object and says what it had to make up or change. Every error is one
/// line naming the file and the offending element.
pub fn load_head_with_warnings(
    path: &Path,
    overrides: &TextureOverrides,
) -> Result<(Object, Vec<String>)> {
    load_head_with_notes(path, overrides).map(|l| (l.object, l.warnings))
}

/// A loaded head, what the loader had to make up or change (warnings) and what
/// it took from where without being asked (notes: the textures found beside the
/// file).
pub struct Loaded {
    /// The character's head: its scattered skin material's primitives (or,
    /// when nothing is skin, its largest material's).
    pub object: Object,
    /// Its other materials' primitives, each with its own material.
    pub parts: Vec<Object>,
    /// The animation that posed it (`--time`, `--animation`), ready to pose
    /// again at any time (a crowd's phases, a run's steps): the head's
    /// sources first, then the parts'.
    pub rig: Option<Rig>,
    pub warnings: Vec<String>,
    pub notes: Vec<String>,
}

impl Loaded {
    /// Whether one of the file's animations posed it.
    pub fn animated(&self) -> bool {
        self.rig.is_some()
    }
}

/// [`load_head_with_warnings`] with the notes.
pub fn load_head_with_notes(path: &Path, overrides: &TextureOverrides) -> Result<Loaded> {
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

fn load(path: &Path, overrides: &TextureOverrides) -> Result<Loaded> {
    let src = super::gltf_source::open(path)?;
    let mut warn = Warnings::default();
    let clips = animations::clips(&src)?;
    let clip = match (&overrides.clip, overrides.time) {
        (Some(name), _) => Some(clips.iter().find(|c| &c.name == name).ok_or_else(|| {
            let names: Vec<&str> = clips.iter().map(|c| c.name.as_str()).collect();
            anyhow!(
                "--animation '{name}': the file has no animation of that name (it has: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        })?),
        (None, Some(_)) => clips.first(),
        (None, None) => None,
    };
    let asked = overrides.time.unwrap_or(0.0);
    // Past its end the clip loops, as every character of a crowd loops it.
    let time = clip.map_or(asked, |c| clip_time(asked, c.duration()));
    unsupported_features(&src, &mut warn);
    if let Some(c) = clip {
        let past = if time != asked {
            format!(" (past its end: looped, {time} s into it)")
        } else {
            String::new()
        };
        warn.note(format!(
            "animation '{}' ({:.3} s, {} channels) posed at {asked} s{past}",
            c.name,
            c.duration(),
            c.channels.len()
        ));
    } else if !clips.is_empty() {
        warn.note(format!(
            "{} animation(s) not played (the rest pose is drawn; --time plays the first, --animation chooses)",
            clips.len()
        ));
    }
    let mut c = nodes::collect(&src, &mut warn, clip.map(|c| (c, time)))?;
    if c.mesh.indices.is_empty() {
        bail!("no triangle mesh in the default scene");
    }
    nodes::place(&mut c, &mut warn)?;
    c.mesh
        .validate()
        .map_err(|e| anyhow!("merged mesh: {e:#}"))?;
    let groups = c.split();
    let facts = groups
        .iter()
        .map(|g| material_facts(&src, g.material, g.mesh.triangle_count()))
        .collect::<Result<Vec<_>>>()?;
    let decisions = skin_rule::decide(&facts, &overrides.skin)?;
    let scattered = skin_rule::scattered(&facts, &decisions);
    // With no skin, the head is the largest part (what the framing measures).
    let head = scattered.unwrap_or_else(|| {
        (0..facts.len())
            .max_by_key(|&i| (facts[i].triangles, std::cmp::Reverse(i)))
            .unwrap_or(0)
    });
    // One note per material when the model has several or the rule had to
    // choose; a lone unnamed material is a scan's skin, as it always was.
    let lone_default =
        facts.len() == 1 && decisions[0].reason == (skin_rule::Reason::Unnamed { alone: true });
    if !lone_default {
        for (f, d) in facts.iter().zip(&decisions) {
            warn.note(d.note(f));
        }
    }
    let also_skin: Vec<String> = (0..facts.len())
        .filter(|&i| decisions[i].skin && Some(i) != scattered)
        .map(|i| facts[i].label())
        .collect();
    if !also_skin.is_empty() {
        warn.push(format!(
            "{} also skin, but dermis scatters one material per character ({}, the largest): drawn in their own materials without scattering (--skin chooses)",
            also_skin.join(", ") + if also_skin.len() == 1 { " is" } else { " are" },
            facts[head].label()
        ));
    }
    let mut head_object = None;
    let mut parts = Vec::new();
    let (mut head_rig, mut part_rigs) = (ObjectRig::default(), Vec::new());
    for (i, g) in groups.into_iter().enumerate() {
        if g.with_uvs > 0 && !g.without_uvs.is_empty() {
            // Skin needs texture coordinates where it is textured; an eye or a tooth
            // without them still draws, in the colour of the texture's first texel.
            let n = g.without_uvs.len();
            let first = &g.without_uvs[0];
            let more = if n > 1 {
                format!(" and {} more", n - 1)
            } else {
                String::new()
            };
            warn.push(format!(
                "{first}{more} have no TEXCOORD_0: loaded with zero texture coordinates"
            ));
        }
        let role = textures::Role {
            head: i == head,
            skin: i == head && scattered.is_some(),
        };
        let material = textures::material(&src, &g, role, overrides, &mut warn).map_err(|e| {
            if facts.len() > 1 {
                anyhow!("{}: {e:#}", facts[i].label())
            } else {
                e
            }
        })?;
        let mut object = Object {
            morph: Default::default(),
            mesh: g.mesh,
            material,
        };
        object
            .set_morph(g.morph)
            .map_err(|e| anyhow!("{}: {e:#}", facts[i].label()))?;
        if role.head {
            head_object = Some(object);
            head_rig = g.rig;
        } else {
            parts.push(object);
            part_rigs.push(g.rig);
        }
    }
    let object = head_object.ok_or_else(|| anyhow!("no triangle mesh in the default scene"))?;
    let mut loaded = warn.finish(object, parts);
    loaded.rig = clip.map(|clip| {
        Rig::new(
            c.skeleton,
            clip.clone(),
            c.shift,
            time,
            std::iter::once(head_rig).chain(part_rigs).collect(),
        )
    });
    Ok(loaded)
}

/// What the file has that dermis does not draw, each said once: extensions
/// it uses without requiring them (a file that requires one is refused by
/// `gltf_source`), its cameras and its lights.
fn unsupported_features(src: &super::gltf_source::Source, warn: &mut Warnings) {
    let used = src
        .json
        .get("extensionsUsed")
        .and_then(|v| v.as_array())
        .into_iter()
        .flatten()
        .filter_map(|v| v.as_str());
    for e in used.filter(|e| !super::gltf_source::SUPPORTED_REQUIRED_EXTENSIONS.contains(e)) {
        let e = super::gltf_source::short(e);
        match e.as_ref() {
            "KHR_lights_punctual" => warn.note(format!(
                "{e}: the file's lights are not used (dermis lights every scene with its own key light)"
            )),
            _ => warn.push(format!("{e} is not supported: drawn without it")),
        }
    }
    let cameras = src.doc.cameras().count();
    if cameras > 0 {
        warn.note(format!(
            "the file's {cameras} camera(s) are not used (dermis frames the character: --shot, --distance)"
        ));
    }
    let colours = src
        .doc
        .meshes()
        .flat_map(|m| m.primitives())
        .filter(|p| p.get(&gltf::Semantic::Colors(0)).is_some())
        .count();
    if colours > 0 {
        warn.push(format!(
            "{colours} primitive(s) have vertex colours (COLOR_0), which dermis does not draw: their materials' colours are used"
        ));
    }
}

/// What the skin rule reads of one material: its name and its extras' `skin`.
fn material_facts(
    src: &super::gltf_source::Source,
    index: Option<usize>,
    triangles: usize,
) -> Result<skin_rule::MaterialFacts> {
    let json = index.and_then(|i| src.json.get("materials")?.get(i));
    let name = json
        .and_then(|j| j.get("name"))
        .and_then(|n| n.as_str())
        .map(|n| super::gltf_source::short(n).to_string());
    let extras_skin = match json.and_then(|j| j.pointer("/extras/skin")) {
        None => None,
        Some(v) => Some(v.as_bool().ok_or_else(|| {
            anyhow!(
                "material {}: extras \"skin\" is {v}, not true or false",
                index.unwrap_or(0)
            )
        })?),
    };
    Ok(skin_rule::MaterialFacts {
        index,
        name,
        extras_skin,
        triangles,
    })
}

#[cfg(test)]
mod motion_tests;
#[cfg(test)]
pub(super) mod tests;
