//! Textures: the material's own (a buffer view, a data: URI or a file the glTF
//! names), the command line's overrides, and files found beside the scene by a
//! naming rule, each read through the one door (`crate::files`) with its
//! decoded size bounded before anything is allocated.
//!
//! # The naming rule for files beside the scene
//!
//! Scans are often shipped as a bare mesh with their textures next to it (the
//! Lee Perry-Smith head is: `Map-COL.jpg`, `Infinite-Level_02_Tangent_SmoothUV.jpg`,
//! `Map-SPEC.jpg`). A file in the scene's folder is taken as a texture when
//! 1. its extension is `.png`, `.jpg` or `.jpeg` (any case), and
//! 2. its name without the extension, cut into words at every character that
//!    is not an ASCII letter or digit, has words of exactly one role (any case):
//!    - albedo: `albedo`, `basecolor`, `col`, `color`, `colour`, `diffuse`;
//!    - normal map: `normal`, `tangent` (a tangent-space normal map);
//!    - specular: `spec`, `specular`;
//!    - roughness (the Beckmann m in red): `rough`, `roughness`;
//!    - SSS strength (red, a factor of the material's): `sss`, `scatter`,
//!      `scattering`, `subsurface`;
//!    - expression wrinkles (thesis ch. 8, `mesh::WrinkleMaps`): the wrinkle
//!      map (its partial-derivative normal in red and green) has the word
//!      `wrinkle` or `wrinkles`; its two zone masks have that word too and
//!      one of `mask1`, `maska` (the first: red, green, blue, brown of Table
//!      8.1) or `mask2`, `maskb` (the second: cyan, magenta, orange, grey),
//!      or the word `mask` followed by the word `1`, `a`, `2` or `b`. A
//!      file with `wrinkle` and `mask` but no number claims nothing. The three
//!      are taken together or not at all (a warning names what is missing);
//! 3. and no other file there claims the same role.
//!
//! Words are whole: `collar.png`, `Normalized.png` and a displacement map
//! (`..._Disp_...`) claim nothing. A file naming two roles (`col_normal.png`), or
//! two files claiming one role, is ambiguous: nothing is taken for that role and
//! a warning names the files (choose with `--albedo`, `--normal-map`,
//! `--spec-map`, `--roughness-map`, `--sss-map`). The roughness and strength
//! maps come only from beside the file or the command line: glTF has no such
//! roles (its metallic-roughness texture is a perceptual roughness for
//! another lobe). `crate::scene::texel_params` packs the specular, roughness
//! and strength maps into the one texture the geometry pass reads. A role the glTF material fills itself, or the command line
//! overrides, takes nothing from beside the file. Every file taken is named in
//! a note on stderr; one that cannot be read or decoded (a FIFO, a corrupt
//! file, an image too large to decode) is left out with a warning, so a file
//! beside a model never stops its render, and a file the rule does not match is
//! never opened.
//!
//! `--sidecar-top-down` (how files from beside the scene or the command line are
//! oriented) is named in a note as ignored when no texture came from either.
//!
//! Over 800 lines because the naming rule, its eight roles and the head
//! material's assembly from the file, the files beside it and the command
//! line are one sequence (590 lines), and their tests (265) load real files
//! for each role.

use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};

use super::checks::check_tex_coord;
use super::nodes::MaterialMesh;
use super::Warnings;
use crate::files::{self, ImageBound};
use crate::scene::gltf_accessor::view_bytes;
use crate::scene::gltf_source::{read_uri, short, Source};
use crate::scene::mesh::{Material, Texture, WrinkleMaps};

/// Texture files that replace whatever the glTF or the files beside it give.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureOverrides {
    pub albedo: Option<PathBuf>,
    pub normal_map: Option<PathBuf>,
    pub specular_map: Option<PathBuf>,
    pub roughness_map: Option<PathBuf>,
    pub sss_map: Option<PathBuf>,
    /// The wrinkle map and its two zone masks (`--wrinkle-map`,
    /// `--wrinkle-mask1`, `--wrinkle-mask2`).
    pub wrinkle_map: Option<PathBuf>,
    pub wrinkle_masks: [Option<PathBuf>; 2],
    /// Textures found beside the file or given as overrides were not authored
    /// against the glTF's texture-coordinate convention (v = 0 at the top row).
    /// By default they are taken as bottom-up (OpenGL convention: the three.js
    /// example that distributes the Lee Perry-Smith head loads them with
    /// flipY = true); set this when such files are top-down.
    pub sidecar_top_down: bool,
    /// The command line's choice of skin materials (`--skin`, `--not-skin`;
    /// `crate::scene::skin_rule`): beside the textures because it, too,
    /// replaces what the file says.
    pub skin: crate::scene::skin_rule::SkinChoice,
    /// The time (seconds) the file's animation is posed at (`--time`), and
    /// which clip (`--animation`; the first when none is named). No time: the
    /// file's rest pose.
    pub time: Option<f32>,
    pub clip: Option<String>,
}

/// A texture role of the skin material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Slot {
    Albedo,
    Normal,
    Specular,
    Roughness,
    Strength,
    Wrinkle,
    WrinkleMask1,
    WrinkleMask2,
}

/// How many texture roles a skin material has.
const SLOTS: usize = 8;
/// The roles whose words alone claim a file (the wrinkle roles are read
/// together: `classify`).
const WORD_SLOTS: usize = 5;

impl Slot {
    const ALL: [Slot; SLOTS] = [
        Slot::Albedo,
        Slot::Normal,
        Slot::Specular,
        Slot::Roughness,
        Slot::Strength,
        Slot::Wrinkle,
        Slot::WrinkleMask1,
        Slot::WrinkleMask2,
    ];

    /// The role's words in a file name (module docs).
    fn words(self) -> &'static [&'static str] {
        match self {
            Slot::Albedo => &["albedo", "basecolor", "col", "color", "colour", "diffuse"],
            Slot::Normal => &["normal", "tangent"],
            Slot::Specular => &["spec", "specular"],
            Slot::Roughness => &["rough", "roughness"],
            Slot::Strength => &["sss", "scatter", "scattering", "subsurface"],
            Slot::Wrinkle | Slot::WrinkleMask1 | Slot::WrinkleMask2 => &["wrinkle", "wrinkles"],
        }
    }

    fn what(self) -> &'static str {
        match self {
            Slot::Albedo => "albedo",
            Slot::Normal => "normal map",
            Slot::Specular => "specular",
            Slot::Roughness => "roughness",
            Slot::Strength => "SSS strength",
            Slot::Wrinkle => "wrinkle map",
            Slot::WrinkleMask1 => "first wrinkle mask",
            Slot::WrinkleMask2 => "second wrinkle mask",
        }
    }

    fn flag(self) -> &'static str {
        match self {
            Slot::Albedo => "--albedo",
            Slot::Normal => "--normal-map",
            Slot::Specular => "--spec-map",
            Slot::Roughness => "--roughness-map",
            Slot::Strength => "--sss-map",
            Slot::Wrinkle => "--wrinkle-map",
            Slot::WrinkleMask1 => "--wrinkle-mask1",
            Slot::WrinkleMask2 => "--wrinkle-mask2",
        }
    }
}

/// The roles a file name claims under the naming rule (module docs): none for a
/// file that is not a PNG or JPEG or names no role, several when it is ambiguous.
pub(super) fn classify(file_name: &str) -> Vec<Slot> {
    let Some((stem, ext)) = file_name.rsplit_once('.') else {
        return Vec::new();
    };
    if !["png", "jpg", "jpeg"].contains(&ext.to_ascii_lowercase().as_str()) {
        return Vec::new();
    }
    let words: Vec<String> = stem
        .split(|c: char| !c.is_ascii_alphanumeric())
        .map(str::to_ascii_lowercase)
        .collect();
    let mut roles: Vec<Slot> = Slot::ALL[..WORD_SLOTS]
        .iter()
        .copied()
        .filter(|s| words.iter().any(|w| s.words().contains(&w.as_str())))
        .collect();
    if words
        .iter()
        .any(|w| Slot::Wrinkle.words().contains(&w.as_str()))
    {
        let number = |w: &str| match w {
            "1" | "a" => Some(Slot::WrinkleMask1),
            "2" | "b" => Some(Slot::WrinkleMask2),
            _ => None,
        };
        let joined = words
            .iter()
            .find_map(|w| w.strip_prefix("mask").and_then(number));
        let apart = words
            .windows(2)
            .find_map(|p| (p[0] == "mask").then(|| number(&p[1])).flatten());
        let is_mask = words.iter().any(|w| w.starts_with("mask"));
        match joined.or(apart) {
            Some(mask) => roles.push(mask),
            None if !is_mask => roles.push(Slot::Wrinkle),
            None => {}
        }
    }
    roles
}

/// What the naming rule makes of the files in `dir`: for each role, the files
/// claiming it (sorted by name); files claiming several roles apart.
#[derive(Default)]
pub(super) struct Beside {
    pub(super) claims: [Vec<PathBuf>; SLOTS],
    pub(super) ambiguous: Vec<PathBuf>,
}

/// Applies the naming rule to the names in `dir` (nothing is opened).
pub(super) fn detect_beside(dir: &Path) -> Beside {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    names.sort();
    let mut out = Beside::default();
    for path in names {
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        match classify(name).as_slice() {
            [] => {}
            [slot] => out.claims[*slot as usize].push(path),
            _ => out.ambiguous.push(path),
        }
    }
    out
}

/// What a texture may be: its decoded RGBA8 size is the bound (a texture wider
/// than the device allows is downscaled later, so no side limit of its own).
const TEXTURE_BOUND: ImageBound = ImageBound::rgba8(u32::MAX);

fn texture(img: image::RgbaImage) -> Texture {
    Texture {
        width: img.width(),
        height: img.height(),
        rgba8: img.into_raw(),
    }
}

/// Decodes an image file to RGBA8 through the one door (`files`); the error names
/// the file and the role it was for.
pub fn load_texture(path: &Path, what: &str) -> Result<Texture> {
    files::read_rgba8(path, &format!("{what} texture"), &TEXTURE_BOUND).map(texture)
}

/// Decodes image bytes (PNG, JPEG; the format is read from the bytes, not the name
/// or MIME type) to RGBA8, the decoded size bounded before anything is allocated.
fn decode_image(bytes: &[u8], label: &str) -> Result<Texture> {
    files::decode_rgba8(bytes, label, &TEXTURE_BOUND).map(texture)
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
pub(super) fn specular_texture_index(src: &Source, material: usize) -> Option<usize> {
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

/// What a material group is to the character: its head (the scattered skin,
/// or the largest part when nothing is skin), which the files beside the scene
/// and the command line's textures are for, or one of its other parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Role {
    pub(super) head: bool,
    pub(super) skin: bool,
}

/// The material of one material group: the glTF material's textures, then,
/// for the head only, for each role it leaves empty the file beside the scene
/// the naming rule finds, then the command line's overrides over both. Notes
/// name every file taken from beside the scene. Skin keeps the project's skin
/// lobe (Beckmann 0.3, rho_s 0.18); another part takes the file's roughness
/// (glTF's perceptual roughness squared, as a Beckmann m) and
/// KHR_materials_specular's factor over the skin's rho_s.
pub(super) fn material(
    src: &Source,
    c: &MaterialMesh,
    role: Role,
    overrides: &TextureOverrides,
    warn: &mut Warnings,
) -> Result<Material> {
    let any_uvs = c.with_uvs > 0;
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
        gltf_texture(src, index, what).map(Some)
    };
    let pbr = gltf_material.as_ref().map(|m| m.pbr_metallic_roughness());
    let mut slots: [Option<Texture>; SLOTS] = [
        from_gltf(
            pbr.as_ref()
                .and_then(|p| p.base_color_texture())
                .map(|t| (t.texture().index(), t.tex_coord())),
            Slot::Albedo.what(),
        )?,
        from_gltf(
            gltf_material
                .as_ref()
                .and_then(|m| m.normal_texture())
                .map(|t| (t.texture().index(), t.tex_coord())),
            Slot::Normal.what(),
        )?,
        from_gltf(
            c.material
                .and_then(|m| specular_texture_index(src, m))
                .map(|i| (i, 0)),
            Slot::Specular.what(),
        )?,
        None,
        None,
        None,
        None,
        None,
    ];
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
    if !role.head {
        return Ok(part_material(
            src,
            c.material,
            role.skin,
            [factor[0], factor[1], factor[2]],
            slots,
        ));
    }
    let given = [
        &overrides.albedo,
        &overrides.normal_map,
        &overrides.specular_map,
        &overrides.roughness_map,
        &overrides.sss_map,
        &overrides.wrinkle_map,
        &overrides.wrinkle_masks[0],
        &overrides.wrinkle_masks[1],
    ];
    let beside = detect_beside(&src.dir);
    let name = |p: &Path| p.display().to_string();
    if !beside.ambiguous.is_empty() {
        let list: Vec<String> = beside.ambiguous.iter().map(|p| name(p)).collect();
        warn.push(format!(
            "files beside the scene whose names claim more than one texture role are not used: {}",
            list.join(", ")
        ));
    }
    let mut skipped_beside = Vec::new();
    let mut taken_beside = 0;
    for slot in Slot::ALL {
        let i = slot as usize;
        let claims = &beside.claims[i];
        let Some(first) = claims.first() else {
            continue;
        };
        let what = slot.what();
        if slots[i].is_some() || given[i].is_some() {
            let by = if slots[i].is_some() {
                "the glTF material has its own"
            } else {
                "the command line gives the"
            };
            warn.note(format!(
                "{} beside the scene not used: {by} {what} texture",
                name(first)
            ));
            continue;
        }
        if claims.len() > 1 {
            let list: Vec<String> = claims.iter().map(|p| name(p)).collect();
            warn.push(format!(
                "{} files beside the scene claim the {what} role ({}): none is used; choose one with {}",
                claims.len(),
                list.join(", "),
                slot.flag()
            ));
            continue;
        }
        if !any_uvs {
            skipped_beside.push(name(first));
            continue;
        }
        match sidecar_texture(first, what, overrides) {
            Ok(t) => {
                warn.note(format!(
                    "{what} texture: {} (beside the scene, taken by its name; {} overrides)",
                    name(first),
                    slot.flag()
                ));
                if slot == Slot::Albedo {
                    factor = [1.0; 4];
                }
                slots[i] = Some(t);
                taken_beside += 1;
            }
            Err(e) => warn.push(format!(
                "{} beside the scene not used as the {what} texture: {e:#}",
                name(first)
            )),
        }
    }
    if !skipped_beside.is_empty() {
        warn.push(format!(
            "no primitive has TEXCOORD_0: textures beside the file are not used ({})",
            skipped_beside.join(", ")
        ));
    }
    for slot in Slot::ALL {
        let Some(p) = given[slot as usize] else {
            continue;
        };
        let what = slot.what();
        if !any_uvs {
            bail!(
                "no primitive has TEXCOORD_0, so the {what} texture {} cannot be mapped",
                p.display()
            );
        }
        slots[slot as usize] = Some(sidecar_texture(p, what, overrides)?);
        if slot == Slot::Albedo {
            factor = [1.0; 4];
        }
    }
    // The wrinkle map and its masks work together: a partial set is named
    // and left out.
    let wrinkle = &mut slots[Slot::Wrinkle as usize..];
    let found = wrinkle.iter().filter(|t| t.is_some()).count();
    if found > 0 && found < wrinkle.len() {
        let missing: Vec<&str> = Slot::ALL[Slot::Wrinkle as usize..]
            .iter()
            .zip(wrinkle.iter())
            .filter(|(_, t)| t.is_none())
            .map(|(s, _)| s.what())
            .collect();
        warn.push(format!(
            "the wrinkle maps are not used: the {} is missing (beside the scene by the naming rule, or {}, {} and {})",
            missing.join(" and the "),
            Slot::Wrinkle.flag(),
            Slot::WrinkleMask1.flag(),
            Slot::WrinkleMask2.flag()
        ));
        wrinkle.fill(None);
    }
    // An option that changes nothing is named, not ignored in silence.
    let sidecars = taken_beside + given.iter().filter(|g| g.is_some()).count();
    if overrides.sidecar_top_down && sidecars == 0 {
        warn.note(
            "--sidecar-top-down is ignored: no texture came from beside the file or the command line"
                .to_string(),
        );
    }
    Ok(part_material(
        src,
        c.material,
        role.skin,
        [factor[0], factor[1], factor[2]],
        slots,
    ))
}

/// The lobe and textures of a material group (`material`'s docs).
fn part_material(
    src: &Source,
    index: Option<usize>,
    skin: bool,
    factor: [f32; 3],
    [base_color, normal_map, specular_map, roughness_map, sss_map, wrinkle, mask1, mask2]: [Option<
        Texture,
    >; SLOTS],
) -> Material {
    let wrinkles = match (wrinkle, mask1, mask2) {
        (Some(wrinkle), Some(m1), Some(m2)) => Some(WrinkleMaps {
            wrinkle,
            masks: [m1, m2],
        }),
        _ => None,
    };
    let mut m = Material {
        base_color,
        normal_map,
        specular_map,
        roughness_map,
        sss_map,
        wrinkles,
        ..Material::skin(factor)
    };
    if skin {
        return m;
    }
    let json = index.and_then(|i| src.json.get("materials")?.get(i));
    let num = |ptr: &str| {
        json.and_then(|j| j.pointer(ptr))
            .and_then(|v| v.as_f64())
            .filter(|f| f.is_finite())
            .map(|f| f as f32)
    };
    // glTF's default roughness is 1; its alpha is roughness squared, close
    // to a Beckmann m at the roughnesses materials use. Kept off 0: the
    // Beckmann lookup has no mirror.
    let r = num("/pbrMetallicRoughness/roughnessFactor")
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    m.skin = false;
    m.sss_strength = 0.0;
    m.roughness = (r * r).clamp(0.08, 1.0);
    m.specular_intensity = 0.18
        * num("/extensions/KHR_materials_specular/specularFactor")
            .unwrap_or(1.0)
            .clamp(0.0, 1.0);
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::gltf_load::tests::{attrs, err, quad_file, temp_dir, tiny_gltf};
    use crate::scene::gltf_load::{load_head, load_head_with_warnings};

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
    fn wrinkle_maps_beside_the_file_come_as_a_set() {
        use Slot::*;
        assert_eq!(classify("Head_Wrinkles.png"), [Wrinkle]);
        assert_eq!(classify("head_wrinkle_mask1.png"), [WrinkleMask1]);
        assert_eq!(classify("Wrinkle-Mask-B.PNG"), [WrinkleMask2]);
        assert_eq!(classify("wrinkles_maska.jpg"), [WrinkleMask1]);
        assert_eq!(classify("wrinkle_mask_2.png"), [WrinkleMask2]);
        for name in [
            "wrinkle_mask.png",
            "mask2.png",
            "wrinkled.png",
            "mask1_col.png",
        ] {
            assert!(
                !classify(name).iter().any(|s| *s as usize >= WORD_SLOTS),
                "{name}"
            );
        }
        let dir = temp_dir("wrinkles");
        let scene = tiny_gltf(&dir, true, true, [0.0; 3]);
        image::RgbaImage::new(8, 8)
            .save(dir.join("head_wrinkles.png"))
            .unwrap();
        image::RgbaImage::new(4, 4)
            .save(dir.join("head_wrinkle_mask1.png"))
            .unwrap();
        // Two of the three: none is used, and the warning names the third.
        let l = crate::scene::gltf_load::load_head_with_notes(&scene, &Default::default()).unwrap();
        assert!(l.object.material.wrinkles.is_none());
        assert!(
            l.warnings
                .iter()
                .any(|w| w.contains("second wrinkle mask is missing")
                    && w.contains("--wrinkle-mask2")),
            "{:?}",
            l.warnings
        );
        image::RgbaImage::new(4, 4)
            .save(dir.join("head_wrinkle_mask2.png"))
            .unwrap();
        let l = crate::scene::gltf_load::load_head_with_notes(&scene, &Default::default()).unwrap();
        let w = l
            .object
            .material
            .wrinkles
            .expect("the three files beside the scene");
        w.check().unwrap();
        assert_eq!(
            (w.wrinkle.width, w.masks[0].width, w.masks[1].width),
            (8, 4, 4)
        );
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        assert_eq!(l.notes.len(), 3, "{:?}", l.notes);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn textures_beside_the_file_are_found_by_name() {
        use Slot::*;
        // The Lee Perry-Smith head's files.
        assert_eq!(classify("Map-COL.jpg"), [Albedo]);
        assert_eq!(classify("Infinite-Level_02_Tangent_SmoothUV.jpg"), [Normal]);
        assert_eq!(classify("Map-SPEC.jpg"), [Specular]);
        assert!(classify("Infinite-Level_02_Disp_NoSmoothUV-4096.jpg").is_empty());
        assert_eq!(classify("skin_BaseColor.PNG"), [Albedo]);
        // Whole words only: these name no role (the old substring rule took them).
        for name in [
            "notes.txt",
            "collar.png",
            "Normalized.jpg",
            "inspector.png",
            "photo.jpeg",
        ] {
            assert!(classify(name).is_empty(), "{name}");
        }
        assert!(classify("Map-COL.tga").is_empty());
        assert_eq!(classify("col_normal.png"), [Albedo, Normal]);
        // The per-texel parameters' roles (issue 30).
        assert_eq!(classify("Head_Roughness.png"), [Roughness]);
        assert_eq!(classify("face-rough.jpg"), [Roughness]);
        assert_eq!(classify("Head_SSS.png"), [Strength]);
        assert_eq!(classify("subsurface_mask.PNG"), [Strength]);
        assert_eq!(classify("scatter.jpeg"), [Strength]);
        assert!(classify("Roughly.png").is_empty());
        assert_eq!(classify("spec_rough.png"), [Specular, Roughness]);
        let dir = temp_dir("beside");
        let scene = tiny_gltf(&dir, true, true, [0.0; 3]);
        image::RgbaImage::new(4, 4)
            .save(dir.join("Head_Albedo.png"))
            .unwrap();
        // Unrelated files beside it are never opened: a FIFO, a bomb, a broken file.
        image::RgbaImage::new(2, 2)
            .save(dir.join("photo.png"))
            .unwrap();
        std::fs::write(dir.join("notes.png"), b"not an image").unwrap();
        let l = crate::scene::gltf_load::load_head_with_notes(&scene, &Default::default()).unwrap();
        assert_eq!(l.object.material.base_color.map(|t| t.width), Some(4));
        assert!(l.object.material.normal_map.is_none());
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        assert_eq!(l.notes.len(), 1, "{:?}", l.notes);
        assert!(
            l.notes[0].starts_with("albedo texture: ") && l.notes[0].contains("Head_Albedo.png"),
            "{:?}",
            l.notes
        );
        // A matching file that cannot be decoded is left out with a warning.
        std::fs::write(dir.join("skin_spec.png"), b"not an image").unwrap();
        let l = crate::scene::gltf_load::load_head_with_notes(&scene, &Default::default()).unwrap();
        assert!(l.object.material.specular_map.is_none());
        assert!(
            l.warnings
                .iter()
                .any(|w| w
                    .contains("skin_spec.png beside the scene not used as the specular texture")),
            "{:?}",
            l.warnings
        );
        let top_down = TextureOverrides {
            sidecar_top_down: true,
            ..Default::default()
        };
        let l = crate::scene::gltf_load::load_head_with_notes(&scene, &top_down).unwrap();
        assert!(
            !l.notes.iter().any(|n| n.contains("--sidecar-top-down")),
            "{:?}",
            l.notes
        );
        // Two files claiming one role: neither is taken.
        image::RgbaImage::new(8, 8)
            .save(dir.join("other_diffuse.png"))
            .unwrap();
        let (obj, w) = load_head_with_warnings(&scene, &Default::default()).unwrap();
        assert!(obj.material.base_color.is_none());
        assert!(
            w.iter().any(
                |w| w.contains("2 files beside the scene claim the albedo role")
                    && w.contains("--albedo")
            ),
            "{w:?}"
        );
        // Nothing came from beside the file: --sidecar-top-down changes nothing, and says so.
        let bare = temp_dir("bare");
        let l = crate::scene::gltf_load::load_head_with_notes(
            &tiny_gltf(&bare, true, true, [0.0; 3]),
            &top_down,
        )
        .unwrap();
        assert!(
            l.notes
                .iter()
                .any(|n| n.contains("--sidecar-top-down is ignored")),
            "{:?}",
            l.notes
        );
        let _ = std::fs::remove_dir_all(bare);
        let _ = std::fs::remove_dir_all(dir);
    }
}
