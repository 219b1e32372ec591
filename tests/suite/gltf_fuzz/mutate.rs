//! The fuzzer's inputs: a deterministic PRNG, the valid base models (the shared
//! fixture's grid) and the mutations applied to them, each returning what it did.

use dermis::scene::gltf_load::fixture::{base64, f32_bytes, glb_bytes, Model};
use serde_json::{json, Value};
use std::path::Path;

// ---- Deterministic PRNG (SplitMix64: tiny, good enough to pick mutations) -------------

pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    pub fn pick<T: Clone>(&mut self, v: &[T]) -> T {
        v[self.below(v.len())].clone()
    }
}

// ---- Generated models -----------------------------------------------------------------

/// A small PNG for the embedded texture.
pub fn png(rng: &mut Rng) -> Vec<u8> {
    let (w, h) = (1 + rng.below(6) as u32, 1 + rng.below(6) as u32);
    let img = image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba([(x * 40) as u8, (y * 40) as u8, 150, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encode PNG");
    out.into_inner()
}

/// A valid model: the shared fixture's grid (`Model::grid`) of 2..=8 vertices a
/// side with a small PNG albedo.
pub fn base_model(rng: &mut Rng) -> Model {
    let n = 2 + rng.below(7);
    Model::grid(n, png(rng))
}

pub fn vertex_count(m: &Model) -> usize {
    m.json["accessors"][0]["count"].as_u64().unwrap_or(0) as usize
}

// ---- Mutations --------------------------------------------------------------------------

pub const COMPONENT_TYPES: &[u64] = &[5120, 5121, 5122, 5123, 5125, 5126, 5124, 9999];
pub const TYPES: &[&str] = &["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT4", "BOGUS"];

pub fn interesting_count(rng: &mut Rng, real: u64) -> Value {
    json!(rng.pick(&[
        0,
        1,
        real.saturating_sub(1),
        real,
        real + 1,
        real * 2,
        1 << 31,
        1 << 40,
        u64::MAX >> 11
    ]))
}

pub fn interesting_offset(rng: &mut Rng, real: u64) -> Value {
    json!(rng.pick(&[0, 1, 2, 3, 4, 8, real, real + 4, 1 << 32, 1 << 50]))
}

/// Accessor storage and layout: component type, normalized, type, count, offsets,
/// strides, buffer lengths, sparse storage, index values.
pub fn mutate_accessors(m: &mut Model, rng: &mut Rng) -> String {
    let mut what = Vec::new();
    for _ in 0..1 + rng.below(3) {
        let a = rng.below(4);
        match rng.below(11) {
            0 => {
                let ct = rng.pick(COMPONENT_TYPES);
                m.json["accessors"][a]["componentType"] = json!(ct);
                what.push(format!("acc{a}.componentType={ct}"));
            }
            1 => {
                m.json["accessors"][a]["normalized"] = json!(true);
                let ct = rng.pick(COMPONENT_TYPES);
                m.json["accessors"][a]["componentType"] = json!(ct);
                what.push(format!("acc{a}.normalized ct={ct}"));
            }
            2 => {
                let t = rng.pick(TYPES);
                m.json["accessors"][a]["type"] = json!(t);
                what.push(format!("acc{a}.type={t}"));
            }
            3 => {
                let real = m.json["accessors"][a]["count"].as_u64().unwrap_or(1);
                let c = interesting_count(rng, real);
                what.push(format!("acc{a}.count={c}"));
                m.json["accessors"][a]["count"] = c;
            }
            4 => {
                let o = interesting_offset(rng, 4);
                what.push(format!("acc{a}.byteOffset={o}"));
                m.json["accessors"][a]["byteOffset"] = o;
            }
            5 => {
                let v = rng.below(5);
                let s = rng.pick(&[0u64, 1, 2, 3, 4, 6, 8, 12, 16, 252, 256, 1 << 33]);
                m.json["bufferViews"][v]["byteStride"] = json!(s);
                what.push(format!("view{v}.byteStride={s}"));
            }
            6 => {
                let v = rng.below(5);
                let real = m.json["bufferViews"][v]["byteLength"].as_u64().unwrap_or(0);
                let key = rng.pick(&["byteLength", "byteOffset"]);
                let val = interesting_offset(rng, real);
                what.push(format!("view{v}.{key}={val}"));
                m.json["bufferViews"][v][key] = val;
            }
            7 => {
                let real = m.buffer.len() as u64;
                let l = rng.pick(&[0, real - 1, real + 1, 1 << 40, u64::MAX >> 11]);
                m.json["buffers"][0]["byteLength"] = json!(l);
                what.push(format!("buffer.byteLength={l}"));
            }
            8 => {
                // Sparse storage: random substitutions, sometimes out of order or range.
                let count = m.json["accessors"][a]["count"].as_u64().unwrap_or(1);
                let n = 1 + rng.below(4);
                let mut ids: Vec<u32> = (0..n)
                    .map(|_| rng.below(count as usize + 2) as u32)
                    .collect();
                if rng.chance(0.7) {
                    ids.sort();
                    ids.dedup();
                }
                let ibytes: Vec<u8> = ids.iter().flat_map(|i| i.to_le_bytes()).collect();
                let iv = m.add_view(&ibytes, None);
                let vals: Vec<f32> = (0..ids.len() * 4).map(|k| k as f32 * 0.01).collect();
                let vv = m.add_view(&f32_bytes(&vals), None);
                let sc = if rng.chance(0.9) {
                    ids.len()
                } else {
                    ids.len() + 3
                };
                m.json["accessors"][a]["sparse"] = json!({
                    "count": sc,
                    "indices": {"bufferView": iv, "componentType": 5125},
                    "values": {"bufferView": vv}
                });
                if rng.chance(0.3) {
                    m.json["accessors"][a]
                        .as_object_mut()
                        .expect("accessor")
                        .remove("bufferView");
                }
                what.push(format!("acc{a}.sparse {ids:?} count {sc}"));
            }
            9 => {
                // Index values: one random index replaced (out of range, restart value).
                let n = vertex_count(m) as u16;
                let at = rng.below(6);
                let val = rng.pick(&[n, n.wrapping_add(1), 0xffff, 0]);
                let off =
                    m.json["bufferViews"][3]["byteOffset"].as_u64().unwrap_or(0) as usize + at * 2;
                if off + 2 <= m.buffer.len() {
                    m.buffer[off..off + 2].copy_from_slice(&val.to_le_bytes());
                }
                what.push(format!("index[{at}]={val}"));
            }
            _ => {
                // Attributes removed, pointed elsewhere, or added.
                let attrs = &mut m.json["meshes"][0]["primitives"][0]["attributes"];
                match rng.below(5) {
                    0 => {
                        attrs.as_object_mut().expect("attrs").remove("NORMAL");
                        what.push("no NORMAL".into());
                    }
                    1 => {
                        attrs.as_object_mut().expect("attrs").remove("TEXCOORD_0");
                        what.push("no TEXCOORD_0".into());
                    }
                    2 => {
                        let t = rng.below(5);
                        attrs["TANGENT"] = json!(t);
                        what.push(format!("TANGENT=acc{t}"));
                    }
                    3 => {
                        let k = rng.pick(&["POSITION", "NORMAL", "TEXCOORD_0"]);
                        let t = rng.below(5);
                        attrs[k] = json!(t);
                        what.push(format!("{k}=acc{t}"));
                    }
                    _ => {
                        attrs["_CUSTOM"] = json!(0);
                        attrs["TEXCOORD_x"] = json!(0);
                        what.push("odd attribute names".into());
                    }
                }
            }
        }
    }
    what.join(", ")
}

/// Quantized and small-integer storage written for real (not just relabelled), so the
/// allowed combinations load.
pub fn quantized(m: &mut Model, rng: &mut Rng) -> String {
    let n = vertex_count(m);
    let uvs: Vec<[f32; 2]> = (0..n)
        .map(|i| [(i % 7) as f32 / 6.0, (i % 5) as f32 / 4.0])
        .collect();
    let (ct, normalized, bytes): (u64, bool, Vec<u8>) = match rng.below(5) {
        0 => (
            5121,
            true,
            uvs.iter()
                .flat_map(|u| [(u[0] * 255.0) as u8, (u[1] * 255.0) as u8, 0, 0])
                .collect(),
        ),
        1 => (
            5123,
            true,
            uvs.iter()
                .flat_map(|u| {
                    [
                        ((u[0] * 65535.0) as u16).to_le_bytes(),
                        ((u[1] * 65535.0) as u16).to_le_bytes(),
                    ]
                })
                .flatten()
                .collect(),
        ),
        2 => (
            5120,
            true,
            uvs.iter()
                .flat_map(|u| [(u[0] * 127.0) as i8 as u8, (u[1] * 127.0) as i8 as u8, 0, 0])
                .collect(),
        ),
        3 => (
            5122,
            rng.chance(0.5),
            uvs.iter()
                .flat_map(|u| {
                    [
                        ((u[0] * 32767.0) as i16).to_le_bytes(),
                        ((u[1] * 32767.0) as i16).to_le_bytes(),
                    ]
                })
                .flatten()
                .collect(),
        ),
        _ => (
            5120,
            false,
            uvs.iter()
                .flat_map(|u| [u[0] as i8 as u8, u[1] as i8 as u8, 0, 0])
                .collect(),
        ),
    };
    let stride = if matches!(ct, 5121 | 5120) {
        Some(4)
    } else {
        None
    };
    let v = m.add_view(&bytes, stride);
    let a = m.add_accessor(
        json!({"bufferView": v, "componentType": ct, "normalized": normalized, "count": n, "type": "VEC2"}),
    );
    m.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(a);
    let mut what = format!("TEXCOORD_0 ct={ct} normalized={normalized}");
    if rng.chance(0.3) {
        m.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
        m.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
        what.push_str(" +KHR_mesh_quantization");
    }
    if rng.chance(0.3) {
        // u8 indices.
        let idx: Vec<u8> = (0..6)
            .map(|k| [0u8, 1, 2, 0, 2, 3][k].min(n as u8 - 1))
            .collect();
        let v = m.add_view(&idx, None);
        let a = m.add_accessor(
            json!({"bufferView": v, "componentType": 5121, "count": 6, "type": "SCALAR"}),
        );
        m.json["meshes"][0]["primitives"][0]["indices"] = json!(a);
        what.push_str(" u8 indices");
    }
    what
}

/// Node graphs: random children (self, cycles, two parents, out of range), scene roots,
/// deep chains, odd transforms.
pub fn mutate_nodes(m: &mut Model, rng: &mut Rng) -> String {
    if rng.chance(0.15) {
        let depth = 1000 + rng.below(19_000);
        let nodes: Vec<Value> = (0..depth)
            .map(|i| {
                if i + 1 < depth {
                    json!({"children": [i + 1], "translation": [0.0, 1e-4, 0.0]})
                } else {
                    json!({"mesh": 0})
                }
            })
            .collect();
        m.json["nodes"] = json!(nodes);
        let mut what = format!("chain of {depth}");
        if rng.chance(0.5) {
            let at = rng.below(depth);
            let to = rng.below(at + 1);
            m.json["nodes"][at]["children"] = json!([to]);
            what.push_str(&format!(", node {at} -> {to}"));
        }
        return what;
    }
    let n = 1 + rng.below(6);
    let mut nodes = Vec::new();
    for _ in 0..n {
        let mut node = json!({});
        if rng.chance(0.6) {
            node["mesh"] = json!(0);
        }
        if rng.chance(0.6) {
            let k = rng.below(3);
            let children: Vec<usize> = (0..k).map(|_| rng.below(n + 1)).collect();
            node["children"] = json!(children);
        }
        match rng.below(8) {
            0 => {
                node["matrix"] = json!([
                    1,
                    0,
                    0,
                    0,
                    0,
                    1,
                    0,
                    0,
                    0,
                    0,
                    1,
                    0,
                    rng.pick(&[0.0, 1e8, 1e39, -1e39]),
                    0,
                    0,
                    1
                ])
            }
            1 => {
                node["rotation"] = json!(rng.pick(&[
                    [0.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 0.0, 2.0],
                    [1e39, 0.0, 0.0, 1.0]
                ]))
            }
            2 => {
                node["scale"] = json!(rng.pick(&[
                    [0.0, 0.0, 0.0],
                    [-1.0, 1.0, 1.0],
                    [1e30, 1e30, 1e30],
                    [1e39, 1.0, 1.0]
                ]))
            }
            3 => {
                node["translation"] =
                    json!(rng.pick(&[[1e7, 0.0, 0.0], [1e8, -1e8, 1e8], [3e38, 0.0, 0.0]]))
            }
            _ => {}
        }
        nodes.push(node);
    }
    let roots: Vec<usize> = (0..1 + rng.below(3)).map(|_| rng.below(n + 1)).collect();
    let what = format!(
        "{n} nodes {} roots {roots:?}",
        serde_json::to_string(&nodes).unwrap_or_default()
    );
    m.json["nodes"] = json!(nodes);
    match rng.below(6) {
        0 => {
            m.json.as_object_mut().expect("root").remove("scene");
            m.json.as_object_mut().expect("root").remove("scenes");
        }
        _ => m.json["scenes"] = json!([{"nodes": roots}]),
    }
    what
}

/// Primitive modes with index lists of random lengths.
pub fn mutate_mode(m: &mut Model, rng: &mut Rng) -> String {
    let mode = rng.below(8);
    let n = vertex_count(m);
    let k = rng.pick(&[0, 1, 2, 3, 4, 5, 6, 7, 12, 13]);
    let idx: Vec<u16> = (0..k).map(|_| rng.below(n) as u16).collect();
    let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
    let prim = &mut m.json["meshes"][0]["primitives"][0];
    prim["mode"] = json!(mode);
    if k == 0 {
        prim.as_object_mut().expect("prim").remove("indices");
    } else {
        let v = m.add_view(&bytes, None);
        let a = m.add_accessor(
            json!({"bufferView": v, "componentType": 5123, "count": k, "type": "SCALAR"}),
        );
        m.json["meshes"][0]["primitives"][0]["indices"] = json!(a);
    }
    format!("mode {mode} with {k} indices")
}

/// Buffer and image URIs: devices, missing files, directories, data: URIs good and bad,
/// other schemes, percent-encoding, declared lengths.
pub fn mutate_uri(m: &mut Model, rng: &mut Rng, dir: &Path, name: &str) -> String {
    let good = format!("data:application/octet-stream;base64,{}", base64(&m.buffer));
    let ext = format!("{name}-ext.bin");
    std::fs::write(dir.join(&ext), &m.buffer).expect("write");
    let abs = dir.join(&ext).display().to_string();
    let subdir = format!("{name}-dir");
    let _ = std::fs::create_dir_all(dir.join(&subdir));
    let uris = [
        "/dev/zero".to_string(),
        "/dev/null".into(),
        "/dev/urandom".into(),
        "missing.bin".into(),
        subdir,
        ".".into(),
        good.clone(),
        format!("{}!!", &good[..good.len() / 2]),
        good[..good.len() * 2 / 3].to_string(),
        "data:text/plain,hello".into(),
        "data:application/octet-stream;base64".into(),
        "http://example.com/b.bin".into(),
        "file:///dev/zero".into(),
        "%zz.bin".into(),
        "%FF%FE.bin".into(),
        ext.replace('-', "%2D"),
        abs,
        format!(
            "../{}/{ext}",
            dir.file_name().and_then(|f| f.to_str()).unwrap_or("x")
        ),
    ];
    let uri = rng.pick(&uris);
    let target = rng.below(3);
    let real = m.buffer.len() as u64;
    let shown = if uri.len() > 40 {
        format!("{}...", &uri[..40])
    } else {
        uri.clone()
    };
    if target < 2 {
        m.json["buffers"][0]["uri"] = json!(uri);
        let l = rng.pick(&[real, real, real + 1, 1 << 40, u64::MAX >> 11]);
        m.json["buffers"][0]["byteLength"] = json!(l);
        format!("buffer uri {shown} byteLength {l}")
    } else {
        m.json["images"][0] = json!({"uri": uri});
        format!("image uri {shown}")
    }
}

/// Non-finite or absurd numbers: NaN/inf in positions, normals, UVs; 1e31 outliers.
pub fn mutate_values(m: &mut Model, rng: &mut Rng) -> String {
    let n = vertex_count(m);
    let view = rng.below(3);
    let comps = [3, 3, 2][view];
    let at = rng.below(n * comps);
    let val = rng.pick(&[
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1e31,
        -1e31,
        f32::MAX,
        1e-45,
    ]);
    let off = m.json["bufferViews"][view]["byteOffset"]
        .as_u64()
        .unwrap_or(0) as usize
        + at * 4;
    m.buffer[off..off + 4].copy_from_slice(&val.to_le_bytes());
    format!("view {view} component {at} = {val}")
}

/// A GLB with a damaged container.
pub fn corrupt_glb(m: &Model, rng: &mut Rng) -> (Vec<u8>, String) {
    let mut b = glb_bytes(&m.json, Some(&m.buffer));
    let json_len = u32::from_le_bytes([b[12], b[13], b[14], b[15]]) as usize;
    let bin_at = 20 + json_len;
    let what = match rng.below(8) {
        0 => {
            let v = rng.pick(&[0u32, 1, 3, u32::MAX]);
            b[4..8].copy_from_slice(&v.to_le_bytes());
            format!("version {v}")
        }
        1 => {
            let v = rng.pick(&[0u32, 12, b.len() as u32 - 1, b.len() as u32 + 1, u32::MAX]);
            b[8..12].copy_from_slice(&v.to_le_bytes());
            format!("length {v}")
        }
        2 => {
            let v = rng.pick(&[0u32, 1, json_len as u32 + 8, u32::MAX]);
            b[12..16].copy_from_slice(&v.to_le_bytes());
            format!("JSON chunk length {v}")
        }
        3 => {
            b[16..20].copy_from_slice(b"BIN\0");
            "first chunk is BIN".into()
        }
        4 => {
            let v = rng.pick(&[0u32, 1, (m.buffer.len() / 2) as u32, u32::MAX]);
            b[bin_at..bin_at + 4].copy_from_slice(&v.to_le_bytes());
            format!("BIN chunk length {v}")
        }
        5 => {
            b[bin_at + 4..bin_at + 8].copy_from_slice(b"XYZW");
            "BIN chunk type unknown".into()
        }
        6 => {
            let cut = rng.below(b.len());
            b.truncate(cut);
            let n = b.len() as u32;
            if n >= 12 && rng.chance(0.5) {
                b[8..12].copy_from_slice(&n.to_le_bytes());
            }
            format!("cut at {cut}")
        }
        _ => {
            let k = 1 + rng.below(4);
            for _ in 0..k {
                let at = rng.below(b.len().min(64));
                b[at] ^= 1 << rng.below(8);
            }
            format!("{k} bit flips in the first 64 bytes")
        }
    };
    (b, what)
}

/// Every JSON pointer in a document (for generic mutations).
pub fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    out.push(at.clone());
    match v {
        Value::Object(o) => {
            for (k, c) in o {
                pointers(
                    c,
                    format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")),
                    out,
                );
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate().take(64) {
                pointers(c, format!("{at}/{i}"), out);
            }
        }
        _ => {}
    }
}

/// A generic JSON mutation: a random element replaced by an interesting value or
/// removed.
pub fn mutate_json(json: &mut Value, rng: &mut Rng) -> String {
    let mut ptrs = Vec::new();
    pointers(json, String::new(), &mut ptrs);
    let p = rng.pick(&ptrs[1..]);
    let values = [
        json!(0),
        json!(-1),
        json!(1),
        json!(2),
        json!(3),
        json!(4294967295u64),
        json!(1u64 << 53),
        json!(1e39),
        json!(-1e39),
        json!(0.5),
        json!("x"),
        json!(null),
        json!([]),
        json!({}),
        json!([0, 0, 0]),
    ];
    if rng.chance(0.2) {
        let (parent, key) = p.rsplit_once('/').unwrap_or(("", ""));
        if let Some(Value::Object(o)) = json.pointer_mut(parent) {
            o.remove(key);
            return format!("removed {p}");
        }
    }
    let v = rng.pick(&values);
    if let Some(slot) = json.pointer_mut(&p) {
        *slot = v.clone();
    }
    format!("{p} = {v}")
}
