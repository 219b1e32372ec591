//! Loads a head scan from glTF/GLB: every triangle primitive of the default scene, in world
//! space, merged into one mesh, plus its skin textures.
//!
//! Scans are often shipped as a bare mesh with textures lying next to it (the Lee
//! Perry-Smith head is), so textures the glTF does not reference are found by file name
//! beside it; the command line can override each one.

use super::mesh::{Material, Mesh, Object, Texture, Vertex};
use anyhow::{anyhow, bail, Context, Result};
use glam::Mat4;
use std::path::{Path, PathBuf};

pub use super::head_measure::face_direction;

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
    if !overrides.sidecar_top_down {
        let row = t.width as usize * 4;
        let rows: Vec<&[u8]> = t.rgba8.chunks_exact(row).rev().collect();
        t.rgba8 = rows.concat();
    }
    Ok(t)
}

/// The parsed file: document, its buffers, the raw JSON (for extensions the `gltf` crate
/// is not built to expose) and the directory relative URIs resolve against.
struct Source {
    doc: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
    json: Option<gltf::json::Value>,
    dir: PathBuf,
}

fn open(path: &Path) -> Result<Source> {
    if !path.is_file() {
        bail!("scene file not found: {}", path.display());
    }
    let bytes = std::fs::read(path)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| anyhow!("not a valid glTF file: {}: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let buffers = gltf::import_buffers(&gltf.document, Some(&dir), gltf.blob)
        .map_err(|e| anyhow!("cannot load the buffers of {}: {e}", path.display()))?;
    let json_bytes = if bytes.starts_with(b"glTF") {
        gltf::Glb::from_slice(&bytes)
            .ok()
            .map(|g| g.json.into_owned())
    } else {
        Some(bytes)
    };
    let json = json_bytes.and_then(|b| gltf::json::deserialize::from_slice(&b).ok());
    Ok(Source {
        doc: gltf.document,
        buffers,
        json,
        dir,
    })
}

/// Reads one triangle primitive into a mesh in the primitive's own space.
fn read_primitive(src: &Source, mesh_name: &str, prim: &gltf::Primitive) -> Result<Mesh> {
    let reader = prim.reader(|b| src.buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<[f32; 3]> = reader
        .read_positions()
        .ok_or_else(|| anyhow!("mesh '{mesh_name}' has no positions"))?
        .collect();
    let normals: Vec<[f32; 3]> = reader
        .read_normals()
        .ok_or_else(|| anyhow!("mesh '{mesh_name}' has no normals"))?
        .collect();
    let uvs: Vec<[f32; 2]> = reader
        .read_tex_coords(0)
        .ok_or_else(|| anyhow!("mesh '{mesh_name}' has no texture coordinates (TEXCOORD_0)"))?
        .into_f32()
        .collect();
    let tangents: Option<Vec<[f32; 4]>> = reader.read_tangents().map(|t| t.collect());
    let n = positions.len();
    if normals.len() != n || uvs.len() != n || tangents.as_ref().is_some_and(|t| t.len() != n) {
        bail!("mesh '{mesh_name}' has attributes of different lengths");
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    let mut mesh = Mesh {
        vertices: (0..n)
            .map(|i| Vertex {
                position: positions[i],
                normal: normals[i],
                uv: uvs[i],
                tangent: tangents.as_ref().map_or([0.0; 4], |t| t[i]),
            })
            .collect(),
        indices,
    };
    mesh.validate()
        .with_context(|| format!("mesh '{mesh_name}' is malformed"))?;
    if tangents.is_none() {
        mesh.generate_tangents();
    }
    Ok(mesh)
}

/// Walks the node tree, appending each triangle primitive in world space.
fn collect(
    src: &Source,
    node: gltf::Node,
    parent: Mat4,
    out: &mut Mesh,
    material: &mut Option<usize>,
) -> Result<()> {
    let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
    if let Some(mesh) = node.mesh() {
        let name = mesh
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("#{}", mesh.index()));
        for prim in mesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                continue; // lines and points are not skin
            }
            let mut part = read_primitive(src, &name, &prim)?;
            part.transform(&world);
            out.append(&part);
            if material.is_none() {
                *material = prim.material().index();
            }
        }
    }
    for child in node.children() {
        collect(src, child, world, out, material)?;
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
    if !path.is_file() {
        bail!("{what} texture not found: {}", path.display());
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

/// Expands whatever pixel layout the glTF image decoded to into RGBA8 (16-bit channels
/// keep their high byte, floats are clamped).
fn to_rgba8(data: gltf::image::Data) -> Result<Texture> {
    use gltf::image::Format as F;
    let (channels, bytes) = match data.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    let value = |px: &[u8], c: usize| -> u8 {
        let b = &px[c * bytes..(c + 1) * bytes];
        match bytes {
            1 => b[0],
            2 => (u16::from_ne_bytes([b[0], b[1]]) >> 8) as u8,
            _ => {
                let f = f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
                (f.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
            }
        }
    };
    let expected = data.width as usize * data.height as usize * channels * bytes;
    if data.pixels.len() != expected {
        bail!(
            "embedded image has {} bytes, expected {expected}",
            data.pixels.len()
        );
    }
    let mut rgba8 = Vec::with_capacity(data.width as usize * data.height as usize * 4);
    for px in data.pixels.chunks_exact(channels * bytes) {
        let rgba = match channels {
            1 => [value(px, 0), value(px, 0), value(px, 0), 255],
            2 => [value(px, 0), value(px, 0), value(px, 0), value(px, 1)],
            3 => [value(px, 0), value(px, 1), value(px, 2), 255],
            _ => [value(px, 0), value(px, 1), value(px, 2), value(px, 3)],
        };
        rgba8.extend_from_slice(&rgba);
    }
    Ok(Texture {
        width: data.width,
        height: data.height,
        rgba8,
    })
}

/// Loads the image behind a glTF texture index. External files go through
/// `load_texture` so errors name the file; embedded ones through the `gltf` decoder.
fn gltf_texture(src: &Source, texture_index: usize, what: &str) -> Result<Texture> {
    let texture = src
        .doc
        .textures()
        .nth(texture_index)
        .ok_or_else(|| anyhow!("{what} texture index {texture_index} does not exist"))?;
    let image = texture.source();
    match image.source() {
        gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
            load_texture(&src.dir.join(uri), what)
        }
        source => {
            let data = gltf::image::Data::from_source(source, Some(&src.dir), &src.buffers)
                .map_err(|e| {
                    anyhow!(
                        "cannot decode embedded {what} image #{}: {e}",
                        image.index()
                    )
                })?;
            to_rgba8(data).with_context(|| format!("embedded {what} image #{}", image.index()))
        }
    }
}

/// Texture index of KHR_materials_specular's specularTexture, read from the raw JSON
/// because the `gltf` crate exposes the extension only behind a feature we do not build.
fn specular_texture_index(src: &Source, material: usize) -> Option<usize> {
    src.json
        .as_ref()?
        .get("materials")?
        .get(material)?
        .get("extensions")?
        .get("KHR_materials_specular")?
        .get("specularTexture")?
        .get("index")?
        .as_u64()
        .map(|i| i as usize)
}

/// Loads the head object: merged world-space mesh and skin material.
pub fn load_head(path: &Path, overrides: &TextureOverrides) -> Result<Object> {
    let src = open(path)?;
    let roots: Vec<gltf::Node> = match src.doc.default_scene().or_else(|| src.doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => src.doc.nodes().collect(),
    };
    let mut mesh = Mesh::default();
    let mut material_index = None;
    for node in roots {
        collect(&src, node, Mat4::IDENTITY, &mut mesh, &mut material_index)
            .with_context(|| format!("in {}", path.display()))?;
    }
    if mesh.indices.is_empty() {
        bail!(
            "no triangle mesh in the default scene of {}",
            path.display()
        );
    }
    mesh.validate()
        .with_context(|| format!("merged mesh of {}", path.display()))?;

    let gltf_material = material_index.and_then(|i| src.doc.materials().nth(i));
    let from_gltf = |index: Option<usize>, what: &str| -> Result<Option<Texture>> {
        index.map(|i| gltf_texture(&src, i, what)).transpose()
    };
    let pbr = gltf_material.as_ref().map(|m| m.pbr_metallic_roughness());
    let mut base_color = from_gltf(
        pbr.as_ref()
            .and_then(|p| p.base_color_texture())
            .map(|t| t.texture().index()),
        "albedo",
    )?;
    let mut normal_map = from_gltf(
        gltf_material
            .as_ref()
            .and_then(|m| m.normal_texture())
            .map(|t| t.texture().index()),
        "normal map",
    )?;
    let mut specular_map = from_gltf(
        material_index.and_then(|m| specular_texture_index(&src, m)),
        "specular",
    )?;
    // The glTF's base colour factor tints the glTF's own texture (or is the colour when
    // there is none); a texture found beside the file was not authored against it (the
    // Lee Perry-Smith export carries a bluish Blender default), so it is not applied then.
    let mut factor = pbr.as_ref().map_or([1.0; 4], |p| p.base_color_factor());
    let beside = detect_beside(&src.dir);
    if base_color.is_none() {
        if let Some(p) = &beside[Slot::Albedo as usize] {
            base_color = Some(sidecar_texture(p, "albedo", overrides)?);
            factor = [1.0; 4];
        }
    }
    if normal_map.is_none() {
        if let Some(p) = &beside[Slot::Normal as usize] {
            normal_map = Some(sidecar_texture(p, "normal map", overrides)?);
        }
    }
    if specular_map.is_none() {
        if let Some(p) = &beside[Slot::Specular as usize] {
            specular_map = Some(sidecar_texture(p, "specular", overrides)?);
        }
    }
    if let Some(p) = &overrides.albedo {
        base_color = Some(sidecar_texture(p, "albedo", overrides)?);
        factor = [1.0; 4];
    }
    if let Some(p) = &overrides.normal_map {
        normal_map = Some(sidecar_texture(p, "normal map", overrides)?);
    }
    if let Some(p) = &overrides.specular_map {
        specular_map = Some(sidecar_texture(p, "specular", overrides)?);
    }
    Ok(Object {
        mesh,
        material: Material {
            base_color,
            normal_map,
            specular_map,
            ..Material::skin([factor[0], factor[1], factor[2]])
        },
    })
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
    fn missing_normals_and_uvs_are_named() {
        let dir = temp_dir("attrs");
        let e = err(load_head(
            &tiny_gltf(&dir, false, true, [0.0; 3]),
            &Default::default(),
        ));
        assert!(e.contains("mesh 'tri' has no normals"), "{e}");
        let e = err(load_head(
            &tiny_gltf(&dir, true, false, [0.0; 3]),
            &Default::default(),
        ));
        assert!(
            e.contains("mesh 'tri' has no texture coordinates (TEXCOORD_0)"),
            "{e}"
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
