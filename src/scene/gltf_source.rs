//! Reads a glTF or GLB file and its buffers with every size bounded by what the file
//! declares, so that a hostile or broken file ends in one error line instead of a panic
//! in a third-party reader or a read that never ends (`/dev/zero` as a buffer URI).
//!
//! The `gltf` crate parses and validates the JSON (indices in range, enum values); the
//! bytes are read here: the GLB container, data: URIs, files beside the scene. Buffer
//! contents are then only ever reached through bounds-checked slices (see
//! `gltf_accessor`).

use anyhow::{anyhow, bail, Context, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};

use crate::files::{self, MAX_IMAGE_FILE, MAX_SCENE_FILE};

/// Extensions a file may list in `extensionsRequired` and still load. Quantized
/// geometry is read like any other accessor; the specular texture is what the skin
/// material takes; a texture transform is baked into the texture coordinates.
/// Everything else (Draco, meshopt, Basis textures...) changes how the data must be
/// read or drawn, so the file is refused.
pub const SUPPORTED_REQUIRED_EXTENSIONS: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_materials_specular",
    "KHR_texture_transform",
    // Drawn (`gltf_load::instancing`): gltfpack -mi requires it.
    "EXT_mesh_gpu_instancing",
];

/// The parsed file: document, the bytes of each buffer (exactly its declared
/// byteLength), the raw JSON (for extensions the `gltf` crate is not built to expose),
/// the directory relative URIs resolve against, and whether geometry may be quantized.
pub struct Source {
    pub doc: gltf::Document,
    pub buffers: Vec<Vec<u8>>,
    pub json: Value,
    pub dir: PathBuf,
    /// KHR_mesh_quantization is used: integer positions, normals, tangents and
    /// texture coordinates are allowed beyond the core set.
    pub quantization: bool,
}

/// A string from the file made safe for a one-line message: control characters
/// escaped, long strings (a data: URI can be megabytes) cut.
pub fn short(s: &str) -> String {
    const MAX: usize = 60;
    let mut out: String = s.chars().take(MAX).flat_map(char::escape_debug).collect();
    if s.chars().count() > MAX {
        out.push_str("...");
    }
    out
}

/// Opens a scene file: reads it (a regular file only), splits a GLB, checks required
/// extensions, validates the JSON and loads every buffer.
pub fn open(path: &Path) -> Result<Source> {
    let bytes = files::read_bounded(path, "scene file", MAX_SCENE_FILE)?;
    let (json_bytes, bin) = if bytes.starts_with(b"glTF") {
        let (json, bin) = split_glb(&bytes)
            .map_err(|e| anyhow!("not a valid glTF file: {}: {e:#}", path.display()))?;
        (json, bin)
    } else {
        (&bytes[..], None)
    };
    let mut json: Value = serde_json::from_slice(json_bytes)
        .map_err(|e| anyhow!("not a valid glTF file: {}: {e}", path.display()))?;
    if !json.is_object() {
        bail!(
            "not a valid glTF file: {}: the JSON is not an object",
            path.display()
        );
    }
    let quantization = check_extensions(&mut json)?;
    let doc = document(&json)?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let buffers = load_buffers(&doc, &dir, bin)?;
    Ok(Source {
        doc,
        buffers,
        json,
        dir,
        quantization,
    })
}

/// Splits a GLB into its JSON chunk and optional BIN chunk, every length checked
/// against the bytes actually present.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>)> {
    let u32_at = |at: usize| -> Option<u32> {
        bytes
            .get(at..at.checked_add(4)?)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let version = u32_at(4).ok_or_else(|| anyhow!("GLB header is cut short"))?;
    if version != 2 {
        bail!("GLB version {version} is not supported (only 2)");
    }
    let length = u32_at(8).ok_or_else(|| anyhow!("GLB header is cut short"))? as usize;
    if length > bytes.len() {
        bail!(
            "GLB header declares {length} bytes but the file has {}",
            bytes.len()
        );
    }
    // Trailing bytes beyond the declared length are not part of the GLB.
    let bytes = &bytes[..length];
    let chunk = |at: usize| -> Result<Option<(u32, &[u8], usize)>> {
        if at >= bytes.len() {
            return Ok(None);
        }
        let (Some(len), Some(kind)) = (u32_at(at), u32_at(at + 4)) else {
            bail!("GLB chunk header at byte {at} is cut short");
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                anyhow!(
                    "GLB chunk at byte {at} declares {len} bytes but only {} follow",
                    bytes.len().saturating_sub(start)
                )
            })?;
        Ok(Some((kind, &bytes[start..end], end)))
    };
    const JSON: u32 = 0x4E4F_534A;
    const BIN: u32 = 0x004E_4942;
    let Some((kind, json, mut next)) = chunk(12)? else {
        bail!("GLB has no JSON chunk");
    };
    if kind != JSON {
        bail!("the first GLB chunk is not JSON (type 0x{kind:08x})");
    }
    let mut bin = None;
    // Chunks of unknown type are skipped, as the GLB specification asks.
    while let Some((kind, data, end)) = chunk(next)? {
        if kind == BIN && bin.is_none() {
            bin = Some(data);
        }
        next = end;
    }
    Ok((json, bin))
}

/// Refuses required extensions dermis does not implement, with the extension's name
/// first (the `gltf` crate would instead report every accessor a Draco file leaves
/// without a bufferView). The supported ones are taken out of the list handed on,
/// since the `gltf` crate's validator knows none of them. Also drops
/// application-specific attributes (`_NAME`), which the spec allows and this build of
/// the crate would reject. Returns whether KHR_mesh_quantization is used.
fn check_extensions(json: &mut Value) -> Result<bool> {
    let names = |key: &str, json: &Value| -> Vec<String> {
        json.get(key)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(|v| v.as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default()
    };
    let required = names("extensionsRequired", json);
    let unsupported: Vec<String> = required
        .iter()
        .filter(|e| !SUPPORTED_REQUIRED_EXTENSIONS.contains(&e.as_str()))
        .map(|e| short(e))
        .collect();
    match unsupported.len() {
        0 => {}
        1 => bail!(
            "{} is not supported (listed in extensionsRequired)",
            unsupported[0]
        ),
        _ => bail!(
            "{} are not supported (listed in extensionsRequired)",
            unsupported.join(", ")
        ),
    }
    let quantization = names("extensionsUsed", json)
        .iter()
        .chain(&required)
        .any(|e| e == "KHR_mesh_quantization");
    if let Some(req) = json
        .get_mut("extensionsRequired")
        .and_then(Value::as_array_mut)
    {
        req.retain(|v| {
            !v.as_str()
                .is_some_and(|s| SUPPORTED_REQUIRED_EXTENSIONS.contains(&s))
        });
    }
    if let Some(meshes) = json.get_mut("meshes").and_then(Value::as_array_mut) {
        for prim in meshes
            .iter_mut()
            .filter_map(|m| m.get_mut("primitives").and_then(Value::as_array_mut))
            .flatten()
        {
            if let Some(attrs) = prim.get_mut("attributes").and_then(Value::as_object_mut) {
                attrs.retain(|k, _| !k.starts_with('_'));
            }
        }
    }
    Ok(quantization)
}

/// Deserialises and validates the document; of the validator's findings the first
/// is shown with a count of the rest, so the line stays short.
fn document(json: &Value) -> Result<gltf::Document> {
    let root: gltf::json::Root =
        serde_json::from_value(json.clone()).map_err(|e| anyhow!("not a valid glTF file: {e}"))?;
    // The crate's validator indexes the accessors with POSITION's index before checking
    // it (a panic on an out-of-range one): check that first.
    use gltf::json::validation::Checked;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let pos = prim
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions));
            if let Some(i) = pos.filter(|i| i.value() >= root.accessors.len()) {
                bail!(
                    "invalid glTF: meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not exist",
                    i.value()
                );
            }
        }
    }
    gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(errors) => {
            let more = match errors.len() {
                0 | 1 => String::new(),
                n => format!(" (and {} more problems)", n - 1),
            };
            match errors.first() {
                Some((path, err)) => {
                    anyhow!("invalid glTF: {}: {err}{more}", short(&path.to_string()))
                }
                None => anyhow!("invalid glTF"),
            }
        }
        other => anyhow!("invalid glTF: {other}"),
    })
}

/// The bytes of every buffer, exactly its declared byteLength: from the GLB BIN chunk,
/// a data: URI, or a regular file beside the scene, each checked to hold that much.
fn load_buffers(doc: &gltf::Document, dir: &Path, bin: Option<&[u8]>) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let i = b.index();
        let len = b.length();
        let data = match b.source() {
            gltf::buffer::Source::Bin => {
                let Some(bin) = bin else {
                    bail!("buffer {i} has no uri and the file has no GLB BIN chunk");
                };
                if i != 0 {
                    bail!("buffer {i} has no uri; only buffer 0 may refer to the GLB BIN chunk");
                }
                let data = bin.get(..len).ok_or_else(|| {
                    anyhow!(
                        "buffer {i} declares {len} bytes but the GLB BIN chunk holds {}",
                        bin.len()
                    )
                })?;
                data.to_vec()
            }
            gltf::buffer::Source::Uri(uri) => {
                read_uri(dir, uri, Some(len), &format!("buffer {i}"))?
            }
        };
        out.push(data);
    }
    Ok(out)
}

/// Reads what a URI points at: a base64 data: URI or a regular file relative to `dir`.
/// With `expected`, exactly that many bytes are returned and a source holding fewer is
/// an error; only `expected` bytes are ever read from a file. Without it (images) the
/// file's own size bounds the read.
pub fn read_uri(dir: &Path, uri: &str, expected: Option<usize>, what: &str) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            bail!("{what}: data URI has no ','");
        };
        if !header.ends_with(";base64") {
            bail!("{what}: data URI is not base64 (only base64 data URIs are supported)");
        }
        // Four characters carry three bytes: check the size before decoding anything.
        let at_most = payload.len() / 4 * 3 + payload.len() % 4 * 3 / 4;
        if let Some(len) = expected {
            if at_most < len {
                bail!("{what} declares {len} bytes but its data URI holds at most {at_most}");
            }
        }
        let mut bytes = base64_decode(payload).with_context(|| format!("{what}: data URI"))?;
        if let Some(len) = expected {
            if bytes.len() < len {
                bail!(
                    "{what} declares {len} bytes but its data URI holds {}",
                    bytes.len()
                );
            }
            bytes.truncate(len);
        }
        return Ok(bytes);
    }
    if let Some(scheme) = uri_scheme(uri) {
        bail!(
            "{what}: URI scheme '{}:' is not supported (only relative paths and data: URIs)",
            short(scheme)
        );
    }
    let rel = percent_decode(uri).with_context(|| format!("{what}: URI '{}'", short(uri)))?;
    let path = dir.join(rel);
    // Through the one door (`files`): a regular file only, read as far as the
    // declared length (a buffer) or its own size within the image bound.
    let data = match expected {
        Some(len) => files::read_prefix(&path, what, len as u64, MAX_SCENE_FILE)?,
        None => files::read_bounded(&path, what, MAX_IMAGE_FILE)?,
    };
    Ok(data)
}

/// The scheme of an absolute URI (`http` in `http://...`), or `None` for a relative
/// reference. RFC 3986: a letter, then letters, digits, '+', '-', '.', then ':'
/// before any '/', '?' or '#'.
fn uri_scheme(uri: &str) -> Option<&str> {
    let end = uri.find(':')?;
    let scheme = &uri[..end];
    let mut chars = scheme.chars();
    let first_ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic());
    let rest_ok = chars.all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    (first_ok && rest_ok).then_some(scheme)
}

/// Decodes %XX escapes; the result must be UTF-8.
fn percent_decode(s: &str) -> Result<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = |c: Option<&u8>| c.and_then(|c| (*c as char).to_digit(16));
            match (hex(b.get(i + 1)), hex(b.get(i + 2))) {
                (Some(h), Some(l)) => out.push((h * 16 + l) as u8),
                _ => bail!("invalid percent-encoding at character {i}"),
            }
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| anyhow!("percent-decoded path is not UTF-8"))
}

/// Standard base64 (RFC 4648 alphabet), padding optional.
pub fn base64_decode(s: &str) -> Result<Vec<u8>> {
    let s = s.trim_end_matches('=');
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for (i, c) in s.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => bail!("invalid base64 character at position {i}"),
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        bail!("base64 data ends in the middle of a byte");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_and_rejects_garbage() {
        assert_eq!(base64_decode("").unwrap(), b"");
        assert_eq!(base64_decode("Zg==").unwrap(), b"f");
        assert_eq!(base64_decode("Zm8=").unwrap(), b"fo");
        assert_eq!(base64_decode("Zm9v").unwrap(), b"foo");
        assert_eq!(base64_decode("Zm9vYg").unwrap(), b"foob");
        assert_eq!(base64_decode("AP8A/w==").unwrap(), [0, 255, 0, 255]);
        assert!(base64_decode("Zm9v!").is_err());
        assert!(base64_decode("Z").is_err());
    }

    #[test]
    fn uris_are_classified() {
        assert_eq!(uri_scheme("http://x/y.bin"), Some("http"));
        assert_eq!(uri_scheme("file:///dev/zero"), Some("file"));
        assert_eq!(uri_scheme("buffer.bin"), None);
        assert_eq!(uri_scheme("dir/a:b.bin"), None);
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("a%2").is_err());
        assert!(percent_decode("%FF").is_err());
    }

    #[test]
    fn reads_are_bounded_by_the_declared_length() {
        let dir = super::super::gltf_load::tests::temp_dir("uri");
        std::fs::write(dir.join("b.bin"), [1u8, 2, 3, 4, 5]).unwrap();
        assert_eq!(
            read_uri(&dir, "b.bin", Some(3), "buffer 0").unwrap(),
            [1, 2, 3]
        );
        let e = format!(
            "{:#}",
            read_uri(&dir, "b.bin", Some(9), "buffer 0").unwrap_err()
        );
        assert!(
            e.contains("declares 9 bytes but") && e.contains("has only 5"),
            "{e}"
        );
        // /dev/zero would never end: refused before it is opened.
        let e = format!(
            "{:#}",
            read_uri(&dir, "/dev/zero", Some(8), "buffer 1").unwrap_err()
        );
        assert!(e.contains("is not a regular file"), "{e}");
        let e = format!(
            "{:#}",
            read_uri(&dir, "http://x/b.bin", Some(8), "buffer 2").unwrap_err()
        );
        assert!(e.contains("scheme 'http:' is not supported"), "{e}");
        // A data: URI that cannot hold the declared length is refused before decoding.
        let e = format!(
            "{:#}",
            read_uri(
                &dir,
                "data:application/octet-stream;base64,AAAA",
                Some(1 << 40),
                "buffer 3"
            )
            .unwrap_err()
        );
        assert!(e.contains("holds at most 3"), "{e}");
        assert_eq!(
            read_uri(
                &dir,
                "data:application/octet-stream;base64,AQID",
                Some(2),
                "b"
            )
            .unwrap(),
            [1, 2]
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn glb_chunks_are_bounds_checked() {
        // The shared fixture's GLB writer (it pads the JSON chunk to 4 bytes).
        use super::super::gltf_load::fixture::glb_bytes;
        let ok = glb_bytes(&serde_json::json!({}), Some(&[1, 2, 3, 4]));
        let (j, b) = split_glb(&ok).unwrap();
        assert_eq!((j, b), (&b"{}  "[..], Some(&[1u8, 2, 3, 4][..])));
        // The BIN chunk's length field (after the 12-byte header and the 12-byte
        // JSON chunk) declaring more than follows.
        let mut bad = ok.clone();
        bad[24..28].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = format!("{:#}", split_glb(&bad).unwrap_err());
        assert!(
            e.contains("declares 4294967295 bytes but only 4 follow"),
            "{e}"
        );
        let mut long = ok.clone();
        long[8..12].copy_from_slice(&1000u32.to_le_bytes());
        assert!(format!("{:#}", split_glb(&long).unwrap_err()).contains("declares 1000 bytes"));
        assert!(split_glb(&ok[..10]).is_err());
        let mut v1 = ok.clone();
        v1[4] = 1;
        assert!(format!("{:#}", split_glb(&v1).unwrap_err()).contains("version 1"));
    }

    #[test]
    fn messages_stay_on_one_short_line() {
        assert_eq!(short("a\nb"), "a\\nb");
        assert_eq!(short(&"x".repeat(1000)).len(), 63);
    }
}
