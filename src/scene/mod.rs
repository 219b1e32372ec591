//! What gets rendered: the head (procedural or loaded from glTF), the backdrop, the
//! camera and light placement, and multi-head layouts. Everything here is CPU-side and
//! independent of Vulkan so it can be tested without a GPU.

pub mod animation;
pub mod camera;
pub mod casters;
pub mod crossing;
pub mod crowd_geometry;
pub mod crowd_motion;
pub mod enclosed;
pub mod expressions;
pub mod eyes;
pub mod face;
pub mod face_colour;
pub mod face_surface;
pub mod face_wrinkles;
pub mod framing;
pub mod gltf_accessor;
pub mod gltf_load;
pub mod gltf_source;
pub mod head_measure;
pub mod layout;
pub mod light;
pub mod lines;
pub mod lod;
pub mod mesh;
pub mod morph;
pub mod procedural;
pub mod rig;
pub mod robust_bounds;
pub mod sdf;
pub mod skin;
pub mod skin_rule;
pub mod source;
pub mod texel_params;
pub mod vertex;
pub mod wrinkle_maps;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use std::path::Path;

/// A head and its surroundings, with the scale that ties scene units to millimetres
/// (subsurface scattering profiles are specified in mm).
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub mm_per_unit: f32,
    /// The character's skin: the one material scattered per character
    /// (`skin_rule`); every SSS method, the ground truth and the planner's
    /// skin estimate read it alone.
    pub head: mesh::Object,
    /// The character's other parts (eyes, teeth, hair, cloth), each with its
    /// own material: drawn and shadowed with every character, never
    /// scattered, kept out of the skin stencil.
    pub parts: Vec<mesh::Object>,
    pub backdrop: Option<mesh::Object>,
    /// Bounds of the whole character (head and parts), neck and shoulders included
    /// when a scan has them (what shadows must cover), far outlier vertices left out
    /// (a loaded scene says how many); frame the camera with
    /// `head_center`/`head_height_units`.
    pub head_bounds: mesh::Aabb,
    /// Unit vector from the head centre toward the face: where the camera goes.
    pub forward: Vec3,
    /// Where it came from (a built-in scene or a file, its textures and
    /// scale): what a report records to render the frame again. `None`: a
    /// scene built in code (tests).
    pub source: Option<source::SceneSource>,
    /// How a crowd of it moves at the scene's time (`--time`): each
    /// character its own phase (`crowd_motion`). `None`: every character
    /// as posed.
    pub tracks: Option<crowd_motion::Tracks>,
}

impl Scene {
    /// Chin-to-crown extent along +Y in scene units (a flat object's largest extent).
    /// Measured from the mesh on every call (a few milliseconds on a large scan): keep
    /// the result if you need it per frame.
    pub fn head_height_units(&self) -> f32 {
        self.head_size().height
    }

    /// Centre of the head from the chin up (not of a scan's shoulders): the camera target.
    pub fn head_center(&self) -> Vec3 {
        self.head_size().centre
    }

    /// Both measures in one pass over the mesh (a few milliseconds on a large
    /// scan): what a caller framing the same scene every frame keeps.
    pub fn head_size(&self) -> HeadSize {
        let (centre, height) = head_measure::framed_part(&self.head.mesh, self.forward);
        HeadSize { centre, height }
    }
}

impl Scene {
    /// Sets morph weights by the command line's `NAME=W` entries (`INDEX=W`:
    /// the head's targets by index), on every object with a target of that
    /// name, and poses the objects again. A name no object has is an error
    /// naming the targets there are.
    pub fn set_morph_weights(&mut self, entries: &[(String, f32)]) -> Result<()> {
        for (key, w) in entries {
            let by_index = key.parse::<usize>().is_ok();
            let mut found = false;
            for o in std::iter::once(&mut self.head).chain(&mut self.parts) {
                let has = o
                    .morph
                    .targets
                    .iter()
                    .any(|t| t.name.as_deref() == Some(key.as_str()));
                if has || (by_index && !found) {
                    o.morph.set_weights(&[(key.clone(), *w)])?;
                    found = true;
                }
            }
            if !found {
                let names: Vec<&str> = std::iter::once(&self.head)
                    .chain(&self.parts)
                    .flat_map(|o| o.morph.targets.iter().filter_map(|t| t.name.as_deref()))
                    .collect();
                bail!(
                    "--morph-weights {key}={w}: no morph target of '{}' is named '{key}' (named: {})",
                    self.name,
                    if names.is_empty() { "none".to_string() } else { names.join(", ") }
                );
            }
        }
        self.head.pose();
        for p in &mut self.parts {
            p.pose();
        }
        Ok(())
    }
}

impl Scene {
    /// A built-in scene at time `t`: the face's expressions
    /// (`expressions::expression_clip`), any other dermis's rigid turn and
    /// nod.
    pub fn play_builtin(&mut self, t: f32) {
        let clip = expressions::expression_clip();
        let face = self.head.morph.targets.len() == expressions::EXPRESSIONS.len();
        // The clip loops, for the first character as for the crowd's others.
        let looped = t.rem_euclid(clip.duration().max(f32::MIN_POSITIVE));
        let pivot = self.head_center();
        let motion = match animation::animated_weights(&clip, 0, looped).filter(|_| face) {
            Some(w) => {
                self.head.morph.weights = w;
                self.head.pose();
                crowd_motion::Motion::Weights(clip)
            }
            None => {
                self.rotate_character(animation::rigid_rotation(t));
                crowd_motion::Motion::Rigid
            }
        };
        self.tracks = Some(crowd_motion::Tracks {
            time: t,
            seed: crowd_motion::DEFAULT_SEED,
            motion,
            step: None,
            pivot,
        });
    }

    /// The head's morph weights for character `c` (frame index): a moving
    /// crowd's character at its own phase (a clip of weights, or a file's
    /// clip that moves the head), else the head's own; character 0 is the
    /// scene as posed. What its deformed copy and its wrinkles follow.
    pub fn character_weights(&self, c: usize) -> Vec<f32> {
        let own = &self.head.morph.weights;
        match self.tracks.as_ref().filter(|_| c > 0) {
            Some(t) => t.head_weights(c, own),
            None => own.clone(),
        }
    }

    /// Character `c`'s head as a crowd at the scene's time draws it: its
    /// own phase of a clip of weights (`tracks`), posed on the CPU as the
    /// deform pass poses its copy; `None` where it is the scene's head
    /// (character 0, a still or rigid crowd, a head without targets).
    pub fn character_head(&self, c: usize) -> Option<mesh::Mesh> {
        let t = self.tracks.as_ref().filter(|_| c > 0)?;
        if let crowd_motion::Motion::File(rig) = &t.motion {
            if !rig.moves(0) {
                return None;
            }
            let m = t.file_pose(c)?[0].applied(&self.head.morph);
            return Some(mesh::Mesh {
                vertices: morph::posed(&m.rest, &m),
                indices: self.head.mesh.indices.clone(),
            });
        }
        if !matches!(t.motion, crowd_motion::Motion::Weights(_))
            || self.head.morph.targets.is_empty()
        {
            return None;
        }
        let mut m = self.head.morph.clone();
        m.weights = t.weights(c)?;
        Some(mesh::Mesh {
            vertices: morph::posed(&m.rest, &m),
            indices: self.head.mesh.indices.clone(),
        })
    }

    /// Turns the character (its head and parts, their morphs' rest shapes and
    /// offsets too) by `q` about the head's centre, the camera and light
    /// left where they are (they were placed from the rest pose).
    pub fn rotate_character(&mut self, q: glam::Quat) {
        let c = self.head_center();
        let m = glam::Mat4::from_translation(c)
            * glam::Mat4::from_quat(q)
            * glam::Mat4::from_translation(-c);
        for o in std::iter::once(&mut self.head).chain(&mut self.parts) {
            o.mesh.transform(&m);
            o.morph.rotate(&m, q);
            // The drawn mesh from the moved rest (or joints), so it is the
            // deform pass's to the bit.
            o.pose();
        }
        self.head_bounds = character_bounds(&self.head, &self.parts);
    }
}

/// Bounds of a character's head and parts, far outlier vertices left out
/// (`Scene::head_bounds`).
fn character_bounds(head: &mesh::Object, parts: &[mesh::Object]) -> mesh::Aabb {
    parts
        .iter()
        .map(|p| head_measure::inlier_bounds(&p.mesh).0)
        .fold(head_measure::inlier_bounds(&head.mesh).0, |a, b| {
            a.union(&b)
        })
}

/// Parses `NAME=W[,NAME=W...]` (what `--morph-weights` takes).
pub fn parse_morph_weights(entries: &[String]) -> Result<Vec<(String, f32)>> {
    entries
        .iter()
        .map(|e| {
            let (k, v) = e
                .split_once('=')
                .with_context(|| format!("--morph-weights '{e}': not NAME=WEIGHT"))?;
            let w: f32 = v
                .trim()
                .parse()
                .ok()
                .filter(|w: &f32| w.is_finite())
                .with_context(|| format!("--morph-weights '{e}': '{v}' is not a finite number"))?;
            Ok((k.trim().to_string(), w))
        })
        .collect()
}

/// Where a scene's head is and how tall (`Scene::head_size`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadSize {
    /// Centre of the head from the chin up, scene units.
    pub centre: Vec3,
    /// Chin-to-crown extent, scene units.
    pub height: f32,
}

/// The built-in scenes, by the name `--scene builtin:NAME` takes.
pub const BUILTIN_SCENES: [&str; 3] = ["face", "egg", "lines"];

/// The default scene: the procedural face (`face.rs`), no files needed.
pub fn default_scene() -> Scene {
    face::face_scene()
}

/// A built-in scene by name (`face`, the default; `egg`, the first procedural
/// head, kept so outputs before and after the default changed can be compared
/// and the stability tests keep their calibrated scene; `lines`, thin bars
/// and a grid on a card, the anti-aliasing evaluation's synthetic scene).
pub fn builtin(name: &str) -> Result<Scene> {
    match name {
        "face" => Ok(face::face_scene()),
        "egg" => Ok(egg_scene()),
        "lines" => Ok(lines::lines_scene()),
        other => bail!(
            "unknown built-in scene '{other}' (valid: {})",
            BUILTIN_SCENES.join(", ")
        ),
    }
}

/// A built-in scene for the command line: `name`, scaled by `mm_per_unit` when
/// given. Texture overrides apply to a glTF scene only: given here, they are an
/// error rather than silently unused.
pub fn builtin_scene(
    name: &str,
    overrides: &gltf_load::TextureOverrides,
    mm_per_unit: Option<f32>,
) -> Result<Scene> {
    let o = overrides;
    if o.albedo.is_some()
        || o.normal_map.is_some()
        || o.specular_map.is_some()
        || o.roughness_map.is_some()
        || o.sss_map.is_some()
        || o.wrinkle_map.is_some()
        || o.wrinkle_masks.iter().any(Option::is_some)
        || o.sidecar_top_down
        || !o.skin.is_empty()
    {
        bail!("--albedo, --normal-map, --spec-map, --roughness-map, --sss-map, the --wrinkle-map and masks, --sidecar-top-down, --skin and --not-skin apply to a glTF --scene, not to builtin:{name}");
    }
    let mut s = builtin(name)?;
    if let Some(mm) = mm_per_unit {
        check_mm_per_unit(mm)?;
        s.mm_per_unit = mm;
        if let Some(src) = &mut s.source {
            src.mm_per_unit = Some(mm);
        }
    }
    Ok(s)
}

/// The first procedural scene: an egg-shaped head with disc ears and a flat
/// backdrop.
pub fn egg_scene() -> Scene {
    let head = procedural::head_mesh();
    let head_bounds = head.bounds();
    Scene {
        tracks: None,
        name: "procedural head".to_owned(),
        mm_per_unit: procedural::MM_PER_UNIT,
        head: mesh::Object {
            morph: Default::default(),
            mesh: head,
            material: mesh::Material::skin([0.62, 0.40, 0.32]),
        },
        parts: Vec::new(),
        backdrop: Some(backdrop(procedural::backdrop_mesh())),
        head_bounds,
        forward: Vec3::Z,
        source: Some(source::SceneSource::builtin_named("egg")),
    }
}

/// Matte grey, no subsurface: it only catches shadows and frames the silhouette.
fn backdrop(mesh: mesh::Mesh) -> mesh::Object {
    mesh::Object {
        morph: Default::default(),
        mesh,
        material: mesh::Material {
            skin: false,
            base_color_factor: [0.35; 3],
            base_color: None,
            normal_map: None,
            specular_map: None,
            roughness_map: None,
            sss_map: None,
            wrinkles: None,
            roughness: 0.6,
            specular_intensity: 0.02,
            sss_strength: 0.0,
        },
    }
}

/// Largest frame side and shadow map dermis accepts, and most characters a
/// scene may hold (`crate::ranges`, with every other range: a device may
/// allow less, checked once it is open). Millimetres per scene unit are
/// within `ranges::MM_PER_UNIT`, 1e-12..=1e12, given or derived from the
/// head: millimetres, their squares (the ground truth's areas) and their
/// inverses stay normal f32 numbers with room to spare. A file in any real
/// unit (a femtometre to a million kilometres) fits; outside, a scale is a
/// corrupt file or a typo.
pub use crate::ranges::{MAX_HEADS, MAX_IMAGE_SIDE};

/// Checks a scene scale (given with `--mm-per-unit` or derived from the head).
pub fn check_mm_per_unit(mm: f32) -> Result<()> {
    crate::ranges::MM_PER_UNIT.check(mm)
}

/// Loads a head scan. `mm_per_unit` defaults to 230 mm over the measured chin-to-crown
/// height, since a human head is ~230 mm tall and most scans carry no usable unit.
pub fn load_gltf_scene(
    path: &Path,
    overrides: &gltf_load::TextureOverrides,
    mm_per_unit: Option<f32>,
) -> Result<Scene> {
    if let Some(mm) = mm_per_unit {
        check_mm_per_unit(mm)?;
    }
    let loaded = gltf_load::load_head_with_notes(path, overrides)
        .with_context(|| format!("loading scene {}", path.display()))?;
    for n in &loaded.notes {
        eprintln!("note: {}: {n}", path.display());
    }
    for w in &loaded.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    // A posed clip is measured at its rest pose: one scale (the SSS's
    // millimetres) and one face direction for every time of the clip.
    let animated = loaded.animated();
    let rest = match (animated, mm_per_unit) {
        (true, None) => {
            let still = gltf_load::TextureOverrides {
                time: None,
                clip: None,
                ..overrides.clone()
            };
            let r = gltf_load::load_head_with_notes(path, &still)
                .with_context(|| format!("loading the rest pose of {}", path.display()))?;
            let forward = gltf_load::face_direction(&r.object.mesh);
            let (_, height) = head_measure::framed_part(&r.object.mesh, forward);
            (height.is_finite() && height > 0.0)
                .then(|| (head_measure::HEAD_HEIGHT_MM / height, forward))
        }
        _ => None,
    };
    let mm_per_unit = rest.map(|r| r.0).or(mm_per_unit);
    let mut scene = scene_from_character(&name, loaded.object, loaded.parts, mm_per_unit)
        .with_context(|| format!("framing the head in {}", path.display()))?;
    if let Some((_, forward)) = rest {
        scene.forward = forward;
    }
    if let Some(rig) = loaded.rig {
        let t = overrides.time.unwrap_or(0.0);
        // A crowd plays the file's clip at each character's phase, and a
        // run steps through it.
        scene.tracks = Some(crowd_motion::Tracks {
            time: t,
            seed: crowd_motion::DEFAULT_SEED,
            pivot: scene.head_center(),
            motion: crowd_motion::Motion::File(std::sync::Arc::new(rig)),
            step: None,
        });
    } else if let (Some(t), false) = (overrides.time, animated) {
        eprintln!(
            "note: {}: the file has no animation: --time {t} turns and nods it (dermis's rigid clip, {} s, looped)",
            path.display(),
            animation::RIGID_PERIOD_S
        );
        let pivot = scene.head_center();
        scene.rotate_character(animation::rigid_rotation(t));
        scene.tracks = Some(crowd_motion::Tracks {
            time: t,
            seed: crowd_motion::DEFAULT_SEED,
            motion: crowd_motion::Motion::Rigid,
            step: None,
            pivot,
        });
    }
    scene.source = Some(source::SceneSource {
        scene: Some(path.to_path_buf()),
        albedo: overrides.albedo.clone(),
        normal_map: overrides.normal_map.clone(),
        spec_map: overrides.specular_map.clone(),
        roughness_map: overrides.roughness_map.clone(),
        sss_map: overrides.sss_map.clone(),
        wrinkle_map: overrides.wrinkle_map.clone(),
        wrinkle_mask1: overrides.wrinkle_masks[0].clone(),
        wrinkle_mask2: overrides.wrinkle_masks[1].clone(),
        sidecar_top_down: overrides.sidecar_top_down,
        mm_per_unit,
        skin: overrides.skin.skin.clone(),
        not_skin: overrides.skin.not_skin.clone(),
        morph_weights: Vec::new(),
        time: overrides.time,
        clip: overrides.clip.clone(),
        crowd_seed: None,
        time_step: None,
        skin_tone: None,
        no_wrinkles: false,
    });
    Ok(scene)
}

/// A scene around a loaded head: which way it faces, its scale (given, or 230 mm
/// over its measured height), its bounds and a backdrop behind it. Far outlier
/// vertices are left out of every measurement; a flat object faces the camera
/// with its largest extent (`head_measure`).
pub fn scene_from_head(name: &str, head: mesh::Object, mm_per_unit: Option<f32>) -> Result<Scene> {
    scene_from_character(name, head, Vec::new(), mm_per_unit)
}

/// [`scene_from_head`] for a character with other parts: the head (its skin)
/// frames and scales it, the parts widen its bounds.
pub fn scene_from_character(
    name: &str,
    head: mesh::Object,
    parts: Vec<mesh::Object>,
    mm_per_unit: Option<f32>,
) -> Result<Scene> {
    let forward = gltf_load::face_direction(&head.mesh);
    let (center, height) = head_measure::framed_part(&head.mesh, forward);
    let mm_per_unit = match mm_per_unit {
        Some(mm) => mm,
        None if height.is_finite() && height > 0.0 => {
            let mm = head_measure::HEAD_HEIGHT_MM / height;
            check_mm_per_unit(mm).with_context(|| {
                format!(
                    "the head is {height:e} units tall, so 230 mm would make {mm:e} mm a unit; give --mm-per-unit"
                )
            })?;
            mm
        }
        // Say what was measured: an overflowing extent is not "no height".
        None if !height.is_finite() => bail!(
            "cannot derive mm_per_unit: the head is too large to measure in f32 (centre {center})"
        ),
        None => bail!(
            "cannot derive mm_per_unit: the head has no height above its chin (chin and crown both at y = {})",
            center.y
        ),
    };
    let head_bounds = character_bounds(&head, &parts);
    Ok(Scene {
        tracks: None,
        name: name.to_string(),
        mm_per_unit,
        head_bounds,
        parts,
        backdrop: Some(backdrop(procedural::backdrop_behind(
            center, forward, height,
        ))),
        head,
        forward,
        source: None,
    })
}

#[cfg(test)]
mod tests {
    use super::gltf_load::tests::{lps_path, temp_dir, tiny_gltf};
    use super::*;

    /// A moving crowd's character draws its own phase of the face's clip:
    /// its head is the CPU's blend at its weights, not the first's.
    #[test]
    fn a_moving_crowds_characters_have_their_own_heads() {
        let scene = source::SceneSource {
            time: Some(1.0),
            ..Default::default()
        }
        .load()
        .unwrap();
        assert!(
            scene.character_head(0).is_none(),
            "character 0 is the scene's head"
        );
        let t = scene.tracks.clone().unwrap();
        let (h1, h2) = (
            scene.character_head(1).unwrap(),
            scene.character_head(2).unwrap(),
        );
        assert_ne!(h1.vertices, h2.vertices);
        assert_ne!(h1.vertices, scene.head.mesh.vertices);
        let mut m = scene.head.morph.clone();
        m.weights = t.weights(1).unwrap();
        assert_eq!(h1.vertices, morph::posed(&m.rest, &m));
        // A still scene and a rigid crowd: the scene's head for everyone.
        assert!(default_scene().character_head(1).is_none());
        let egg = source::SceneSource {
            scene: Some("builtin:egg".into()),
            time: Some(1.0),
            ..Default::default()
        }
        .load()
        .unwrap();
        assert!(egg.character_head(1).is_none());
    }

    #[test]
    fn builtin_scenes_are_consistent() {
        for name in BUILTIN_SCENES {
            check_builtin(builtin(name).unwrap());
        }
        assert!(builtin("pear")
            .unwrap_err()
            .to_string()
            .contains("valid: face, egg, lines"));
        assert_eq!(default_scene().name, builtin("face").unwrap().name);
    }

    fn check_builtin(s: Scene) {
        s.head.mesh.validate().unwrap();
        assert!((s.head_height_units() * s.mm_per_unit - 230.0).abs() < 5.0);
        assert_eq!(s.forward, Vec3::Z);
        assert_eq!(gltf_load::face_direction(&s.head.mesh), s.forward);
        let m = &s.head.material;
        assert!(m.skin && m.roughness == 0.3 && m.specular_intensity == 0.18);
        let bd = s.backdrop.as_ref().unwrap();
        assert!(!bd.material.skin);
        assert!(bd.mesh.bounds().max.z < s.head_bounds.min.z);
    }

    #[test]
    fn bad_mm_per_unit_is_rejected() {
        let dir = temp_dir("mm");
        let p = tiny_gltf(&dir, true, true, [0.0; 3]);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = load_gltf_scene(&p, &Default::default(), Some(bad)).unwrap_err();
            assert!(format!("{e:#}").contains("mm_per_unit must be"), "{e:#}");
        }
        let s = load_gltf_scene(&p, &Default::default(), Some(2.5)).unwrap();
        assert_eq!(s.mm_per_unit, 2.5);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn head_far_from_the_origin_keeps_its_height() {
        // At 1e8 f32 steps are 8 units: transforming in f32 flattened the 1-unit
        // triangle and the scene was refused as having no height.
        let dir = temp_dir("far");
        let p = tiny_gltf(&dir, true, true, [1e8, -1e8, 1e8]);
        let s = load_gltf_scene(&p, &Default::default(), None).unwrap();
        assert_eq!(s.head_bounds.size(), Vec3::new(1.0, 1.0, 0.0));
        assert!((s.head_height_units() - 1.0).abs() < 1e-6);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn lee_perry_smith_loads() {
        let Some(path) = lps_path() else {
            eprintln!("skipping: LeePerrySmith.glb not found");
            return;
        };
        let s = load_gltf_scene(&path, &Default::default(), None).unwrap();
        let m = &s.head.mesh;
        assert_eq!(m.triangle_count(), 17_684);
        assert!(
            (9_000..=9_600).contains(&m.vertices.len()),
            "{}",
            m.vertices.len()
        );
        for v in &m.vertices {
            let t = glam::Vec4::from(v.tangent);
            assert!(t.is_finite() && (t.truncate().length() - 1.0).abs() < 1e-3);
            assert!(t.truncate().dot(Vec3::from(v.normal)).abs() < 1e-3);
        }
        let mat = &s.head.material;
        for t in [&mat.base_color, &mat.normal_map, &mat.specular_map] {
            let t = t.as_ref().expect("texture found beside the .glb");
            assert_eq!((t.width, t.height), (1024, 1024));
            assert_eq!(t.rgba8.len(), 1024 * 1024 * 4);
        }
        assert_eq!(mat.base_color_factor, [1.0; 3]);
        // Y up, face toward +Z, ~46 mm per unit (the scan includes neck and shoulders,
        // so the Y extent of 7.9 units is not the head height).
        assert_eq!(s.forward, Vec3::Z);
        let h = s.head_height_units();
        assert!((4.3..=5.6).contains(&h), "head height {h}");
        assert!((40.0..=55.0).contains(&s.mm_per_unit), "{}", s.mm_per_unit);
        let c = s.head_center();
        assert!(c.y > 1.0 && c.y < 2.2, "{c}");
        let bd = s.backdrop.unwrap().mesh.bounds();
        assert!(bd.max.z < s.head_bounds.min.z, "{bd:?}");
        eprintln!(
            "LPS: head {h:.3} units, {:.2} mm/unit, centre {c}, bounds {:?}",
            s.mm_per_unit, s.head_bounds
        );
    }
}
