//! The one glTF fixture builder, shared by the loader's unit tests,
//! `tests/suite/cli.rs` and the fuzzer (`tests/suite/gltf_fuzz.rs`): a document and its
//! one buffer, built up view by view and accessor by accessor, then written as
//! a .gltf with a data: URI, a .gltf beside a .bin, or a GLB.
//!
//! Public (integration tests link the library as users do) but used by no
//! command: it writes only where a test asks.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A glTF document and its one buffer (buffer 0), before it is written in
/// some container.
#[derive(Clone, Debug)]
pub struct Model {
    pub json: Value,
    pub buffer: Vec<u8>,
}

/// How a model's buffer 0 is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// A .gltf with the buffer as a base64 data: URI.
    DataUri,
    /// A .gltf and NAME.bin beside it.
    BinFile,
    /// A .glb with the buffer as its BIN chunk.
    Glb,
}

/// Little-endian bytes of f32 values.
pub fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

/// Standard base64 with padding (what a data: URI carries).
pub fn base64(bytes: &[u8]) -> String {
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

/// A data: URI holding `bytes`.
pub fn data_uri(bytes: &[u8]) -> String {
    format!("data:application/octet-stream;base64,{}", base64(bytes))
}

/// A GLB of `json` (padded to 4 bytes) and an optional BIN chunk.
pub fn glb_bytes(json: &Value, bin: Option<&[u8]>) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).expect("serialise glTF JSON");
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut v = b"glTF".to_vec();
    v.extend(2u32.to_le_bytes());
    v.extend(0u32.to_le_bytes());
    v.extend((j.len() as u32).to_le_bytes());
    v.extend(b"JSON");
    v.extend(&j);
    if let Some(bin) = bin {
        let mut b = bin.to_vec();
        while b.len() % 4 != 0 {
            b.push(0);
        }
        v.extend((b.len() as u32).to_le_bytes());
        v.extend(b"BIN\0");
        v.extend(b);
    }
    let n = v.len() as u32;
    v[8..12].copy_from_slice(&n.to_le_bytes());
    v
}

/// Writes `json` as `dir/name` (a .gltf), with `buffer` embedded as buffer 0
/// (a data: URI) unless the JSON lists its own buffers; sets the asset version.
pub fn write_gltf(dir: &Path, name: &str, mut json: Value, buffer: &[u8]) -> PathBuf {
    json["asset"] = json!({"version": "2.0"});
    if json.get("buffers").is_none() {
        json["buffers"] = json!([{"byteLength": buffer.len(), "uri": data_uri(buffer)}]);
    }
    let path = dir.join(name);
    std::fs::write(
        &path,
        serde_json::to_vec(&json).expect("serialise glTF JSON"),
    )
    .expect("write glTF fixture");
    path
}

/// A fresh empty directory under the system temporary folder, removed with
/// everything in it when dropped, so a test run leaves nothing behind; it
/// reads as its path (`dir.join(...)`, `&dir` where a `&Path` is taken).
pub struct TempDir(tempfile::TempDir);

impl TempDir {
    pub fn path(&self) -> &Path {
        self.0.path()
    }
}

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<std::ffi::OsStr> for TempDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.path().as_os_str()
    }
}

/// A fresh empty directory for a test (named `dermis-TAG-...`), gone when
/// the value is dropped.
pub fn temp_dir(tag: &str) -> TempDir {
    TempDir(
        tempfile::Builder::new()
            .prefix(&format!("dermis-{tag}-"))
            .tempdir()
            .expect("a temporary directory"),
    )
}

impl Model {
    /// One triangle in z = 0 (corners (0,0,0), (1,0,0), (0,1,0)), normals +Z
    /// and texture coordinates (0,1), (1,1), (0,0); NORMAL and TEXCOORD_0 are
    /// optional so the loader's checks can be exercised. Views and accessors:
    /// 0 POSITION, 1 NORMAL, 2 TEXCOORD_0. Node 0 ("tri") is moved by `offset`.
    pub fn triangle(normals: bool, uvs: bool, offset: [f32; 3]) -> Model {
        let mut buffer = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        buffer.extend(f32_bytes(&[0.0, 0.0, 1.0].repeat(3)));
        buffer.extend(f32_bytes(&[0.0, 1.0, 1.0, 1.0, 0.0, 0.0]));
        let mut attrs = json!({"POSITION": 0});
        if normals {
            attrs["NORMAL"] = json!(1);
        }
        if uvs {
            attrs["TEXCOORD_0"] = json!(2);
        }
        let json = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "name": "tri", "translation": offset}],
            "meshes": [{"name": "tri", "primitives": [{"attributes": attrs}]}],
            "buffers": [{"byteLength": buffer.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 36},
                {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                {"buffer": 0, "byteOffset": 72, "byteLength": 24}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}
            ]
        });
        Model { json, buffer }
    }

    /// A unit quad (4 vertices in z = 0, normals +Z, texture coordinates)
    /// followed by `extra` bytes. Accessors: 0 POSITION, 1 NORMAL, 2 TEXCOORD_0
    /// (float), then `extra_accessors`; views 0..2 over the quad, view 3 over
    /// `extra`. The primitive is `prim` (drawn as a fan of the four vertices
    /// when it sets neither indices nor a mode); `nodes` default to one node of
    /// mesh 0 ("quad").
    pub fn quad(prim: Value, extra_accessors: Value, extra: &[u8], nodes: Option<Value>) -> Model {
        let mut buffer = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
        buffer.extend(f32_bytes(&[0.0, 0.0, 1.0].repeat(4)));
        buffer.extend(f32_bytes(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]));
        buffer.extend(extra);
        let mut accessors = vec![
            json!({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}),
            json!({"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}),
            json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}),
        ];
        accessors.extend(extra_accessors.as_array().cloned().unwrap_or_default());
        let mut prim = prim;
        if prim.get("indices").is_none() && prim.get("mode").is_none() {
            prim["mode"] = json!(6);
        }
        if extra.is_empty() {
            buffer.push(0);
        }
        let json = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": nodes.unwrap_or(json!([{"mesh": 0}])),
            "meshes": [{"name": "quad", "primitives": [prim]}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                {"buffer": 0, "byteOffset": 96, "byteLength": 32},
                {"buffer": 0, "byteOffset": 128, "byteLength": extra.len().max(1)},
            ],
            "accessors": accessors,
        });
        Model { json, buffer }
    }

    /// A bumpy `n` x `n` grid facing +Z with normals, texture coordinates, u16
    /// indices and `png` as its embedded albedo. Views: 0 positions, 1 normals,
    /// 2 UVs, 3 indices, 4 image. Accessors: 0 POSITION, 1 NORMAL, 2 TEXCOORD_0,
    /// 3 indices. Buffer 0 has no URI yet (the container gives it one).
    pub fn grid(n: usize, png: Vec<u8>) -> Model {
        let (mut pos, mut nrm, mut uv, mut idx) = (vec![], vec![], vec![], vec![]);
        for j in 0..n {
            for i in 0..n {
                let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
                pos.extend([u - 0.5, v - 0.5, 0.1 * (u * 3.0).sin() * (v * 3.0).cos()]);
                nrm.extend([0.0, 0.0, 1.0]);
                uv.extend([u, 1.0 - v]);
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u16;
                let (b, c, d) = (a + 1, a + n as u16 + 1, a + n as u16);
                idx.extend([a, b, c, a, c, d]);
            }
        }
        let count = n * n;
        let mut m = Model {
            json: json!({
                "asset": {"version": "2.0"},
                "scene": 0,
                "scenes": [{"nodes": [0]}],
                "nodes": [{"mesh": 0, "name": "grid"}],
                "meshes": [{"name": "grid", "primitives": [{
                    "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                    "indices": 3,
                    "material": 0
                }]}],
                "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
                "textures": [{"source": 0}],
                "images": [{"bufferView": 4, "mimeType": "image/png"}],
                "accessors": [
                    {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                     "min": [-0.5, -0.5, -0.1], "max": [0.5, 0.5, 0.1]},
                    {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
                    {"bufferView": 2, "componentType": 5126, "count": count, "type": "VEC2"},
                    {"bufferView": 3, "componentType": 5123, "count": idx.len(), "type": "SCALAR"}
                ],
                "bufferViews": [],
                "buffers": [{"byteLength": 0}]
            }),
            buffer: Vec::new(),
        };
        m.add_view(&f32_bytes(&pos), None);
        m.add_view(&f32_bytes(&nrm), None);
        m.add_view(&f32_bytes(&uv), None);
        let idx: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        m.add_view(&idx, None);
        m.add_view(&png, None);
        m
    }

    /// Appends bytes to the buffer (4-byte aligned) as a new view; returns its index.
    pub fn add_view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while self.buffer.len() % 4 != 0 {
            self.buffer.push(0);
        }
        let mut v =
            json!({"buffer": 0, "byteOffset": self.buffer.len(), "byteLength": bytes.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.buffer.extend(bytes);
        // A model without buffers gets its one buffer when written
        // (`write_gltf` embeds it whole).
        if let Some(b) = self.json.pointer_mut("/buffers/0") {
            b["byteLength"] = json!(self.buffer.len());
        }
        let views = self.json["bufferViews"]
            .as_array_mut()
            .expect("bufferViews is an array");
        views.push(v);
        views.len() - 1
    }

    /// Appends an accessor; returns its index.
    pub fn add_accessor(&mut self, acc: Value) -> usize {
        let accs = self.json["accessors"]
            .as_array_mut()
            .expect("accessors is an array");
        accs.push(acc);
        accs.len() - 1
    }

    /// Sets the model's one animation `name`: node `node` turned from no
    /// rotation to 90 degrees about +Z over `seconds` (LINEAR, two keys).
    pub fn quarter_turn_clip(&mut self, name: &str, node: usize, seconds: f32) {
        let q = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2).to_array();
        let tv = self.add_view(&f32_bytes(&[0.0, seconds]), None);
        let ta = self.add_accessor(json!({"bufferView": tv, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [seconds]}));
        let rv = self.add_view(
            &f32_bytes(&[0.0, 0.0, 0.0, 1.0, q[0], q[1], q[2], q[3]]),
            None,
        );
        let ra = self.add_accessor(
            json!({"bufferView": rv, "componentType": 5126, "count": 2, "type": "VEC4"}),
        );
        self.json["animations"] = json!([{
            "name": name,
            "samplers": [{"input": ta, "output": ra, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": node, "path": "rotation"}}]
        }]);
    }

    /// Moves node 0 by `offset`.
    pub fn translated(mut self, offset: [f32; 3]) -> Model {
        self.json["nodes"][0]["translation"] = json!(offset);
        self
    }

    /// Writes the model as `dir/NAME.gltf` (or `.glb`); buffer 0 gets its URI
    /// from the container unless the JSON already gives one (a case that set
    /// its own). A JSON whose buffers lost their shape is written as it is.
    pub fn write(&self, c: Container, dir: &Path, name: &str) -> PathBuf {
        let mut json = self.json.clone();
        if let Some(b) = json
            .pointer_mut("/buffers/0")
            .and_then(Value::as_object_mut)
        {
            match c {
                Container::DataUri if !b.contains_key("uri") => {
                    b.insert("uri".into(), json!(data_uri(&self.buffer)));
                }
                Container::BinFile if !b.contains_key("uri") => {
                    std::fs::write(dir.join(format!("{name}.bin")), &self.buffer)
                        .expect("write .bin fixture");
                    b.insert("uri".into(), json!(format!("{name}.bin")));
                }
                _ => {}
            }
        }
        if c == Container::Glb {
            let path = dir.join(format!("{name}.glb"));
            std::fs::write(&path, glb_bytes(&json, Some(&self.buffer))).expect("write GLB fixture");
            path
        } else {
            let path = dir.join(format!("{name}.gltf"));
            std::fs::write(
                &path,
                serde_json::to_vec(&json).expect("serialise glTF JSON"),
            )
            .expect("write glTF fixture");
            path
        }
    }
}
