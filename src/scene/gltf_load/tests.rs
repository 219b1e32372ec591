//! The loader's tests end to end (files in, a head or one error line out), on
//! files from the shared fixture builder (`fixture`); the node graph's and the
//! textures' own tests are in `nodes` and `textures`.

pub(crate) use super::fixture::temp_dir;
use super::fixture::{f32_bytes, write_gltf, Container, Model};
use super::*;
use glam::Vec3;
use std::path::PathBuf;

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

/// The loader's error as one string.
pub(crate) fn err(r: Result<Object>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => format!("{e:#}"),
    }
}

/// Writes the fixture's one-triangle glTF as `dir/tri.gltf` (see
/// [`Model::triangle`]).
pub(crate) fn tiny_gltf(dir: &Path, normals: bool, uvs: bool, offset: [f32; 3]) -> PathBuf {
    Model::triangle(normals, uvs, offset).write(Container::DataUri, dir, "tri")
}

/// Writes the fixture's quad as `dir/name` with its buffer as a data: URI
/// (see [`Model::quad`]).
pub(crate) fn quad_file(
    dir: &Path,
    name: &str,
    prim: serde_json::Value,
    extra_accessors: serde_json::Value,
    extra: &[u8],
    nodes: Option<serde_json::Value>,
) -> PathBuf {
    let m = Model::quad(prim, extra_accessors, extra, nodes);
    write_gltf(dir, name, m.json, &m.buffer)
}

pub(crate) fn bytes_f32(v: &[f32]) -> Vec<u8> {
    f32_bytes(v)
}

pub(crate) fn attrs() -> serde_json::Value {
    serde_json::json!({"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2})
}

pub(crate) fn load_err(path: &Path) -> String {
    let e = err(load_head(path, &Default::default()));
    assert!(!e.contains('\n'), "not one line: {e}");
    e
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
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    json["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 4}));
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
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
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
        e.starts_with("KHR_draco_mesh_compression is not supported (listed in extensionsRequired)"),
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
        e.contains("buffer 0 is not a regular file: /dev/zero"),
        "{e}"
    );
    let e = with_buffer(serde_json::json!({"byteLength": 129, "uri": "missing.bin"}));
    assert!(
        e.contains("buffer 0 not found") && e.contains("missing.bin"),
        "{e}"
    );
    std::fs::write(dir.join("small.bin"), [0u8; 16]).unwrap();
    let e =
        with_buffer(serde_json::json!({"byteLength": 1_000_000_000_000u64, "uri": "small.bin"}));
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

// Issue 27: a finite transform that overflows the coordinates (a scale of
// 1e38 on a coordinate of 4000) is the file's fault, named at load, not NaN
// pixels blamed on the renderer when the frame is written.
#[test]
fn a_texture_transform_that_overflows_is_refused_at_load() {
    let dir = temp_dir("kht-overflow");
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
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let kht = serde_json::json!({"KHR_texture_transform": {"scale": [1e38, 1e38]}});
    json["extensionsUsed"] = serde_json::json!(["KHR_mesh_quantization", "KHR_texture_transform"]);
    json["extensionsRequired"] = serde_json::json!(["KHR_mesh_quantization"]);
    json["images"] = serde_json::json!([{"uri": "albedo.png"}]);
    json["textures"] = serde_json::json!([{"source": 0}]);
    json["materials"] = serde_json::json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": kht}}}]);
    std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
    let e = load_err(&p);
    assert!(
        e.contains("TEXCOORD_0 through the material's KHR_texture_transform")
            && e.contains("not finite")
            && !e.contains('\n'),
        "{e}"
    );
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
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let kht = serde_json::json!({"KHR_texture_transform": {"offset": [0.5, 0.0], "scale": [0.00025, 0.00025]}});
    json["extensionsUsed"] = serde_json::json!(["KHR_mesh_quantization", "KHR_texture_transform"]);
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
    assert!(
        e.contains(
            "material 0: the albedo and normal map textures use different KHR_texture_transforms"
        ),
        "{e}"
    );
    // Without KHR_mesh_quantization plain UNSIGNED_SHORT coordinates are refused.
    json["extensionsUsed"] = serde_json::json!([]);
    json["extensionsRequired"] = serde_json::json!([]);
    std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
    let e = load_err(&p);
    assert!(
        e.contains("TEXCOORD_0 accessor 3 is stored as UNSIGNED_SHORT, which glTF does not allow"),
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
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
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

/// Three primitives of one quad, each its own material: a skin named by its
/// name, an eye (not skin by its name) and one named nothing useful.
fn three_material_quad(dir: &Path, extras_skin: Option<bool>) -> PathBuf {
    let mut m = Model::quad(
        serde_json::json!({"attributes": attrs()}),
        serde_json::json!([]),
        &[],
        None,
    );
    let prim = |material: usize| serde_json::json!({"attributes": attrs(), "mode": 6, "material": material});
    m.json["meshes"][0]["primitives"] = serde_json::json!([prim(0), prim(1), prim(2)]);
    let mut third = serde_json::json!({"name": "mat_03", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.3, 1.0], "roughnessFactor": 0.5}});
    if let Some(s) = extras_skin {
        third["extras"] = serde_json::json!({"skin": s});
    }
    m.json["materials"] = serde_json::json!([
        {"name": "Head_Skin", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.5, 1.0]}},
        {"name": "EyeBall_L", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "roughnessFactor": 0.2}},
        third
    ]);
    write_gltf(dir, "three", m.json, &m.buffer)
}

#[test]
fn each_primitive_keeps_its_material_and_the_rule_says_which_is_skin() {
    let dir = temp_dir("materials");
    let l = load_head_with_notes(&three_material_quad(&dir, None), &Default::default()).unwrap();
    assert!(l.object.material.skin);
    assert_eq!(l.object.material.base_color_factor, [0.9, 0.6, 0.5]);
    assert_eq!(l.object.mesh.triangle_count(), 2);
    assert_eq!(l.parts.len(), 2);
    let eye = &l.parts[0].material;
    assert!(!eye.skin && eye.sss_strength == 0.0);
    assert_eq!(eye.base_color_factor, [1.0; 3]);
    assert!(
        (eye.roughness - 0.08).abs() < 1e-6,
        "0.2^2 kept off the mirror: {}",
        eye.roughness
    );
    assert_eq!(l.parts[1].material.base_color_factor, [0.1, 0.2, 0.3]);
    assert!((l.parts[1].material.roughness - 0.25).abs() < 1e-6);
    for (n, want) in [
        ("material 0 'Head_Skin' is skin (scattered) by its name (the word 'head')", true),
        ("material 1 'EyeBall_L' is not skin (drawn without scattering) by its name (the word 'eye')", true),
        ("material 2 'mat_03' is not skin (drawn without scattering) as another material is skin", true),
    ] {
        assert_eq!(l.notes.iter().any(|x| x.contains(n)), want, "{n}: {:?}", l.notes);
    }
    // The command line moves the skin to the third material: the largest
    // skin (ties: the first) is scattered, the other skin named in a warning.
    let o = TextureOverrides {
        skin: crate::scene::skin_rule::SkinChoice::parse(Some("mat_03"), Some("Head_Skin"))
            .unwrap(),
        ..Default::default()
    };
    let l = load_head_with_notes(&three_material_quad(&dir, None), &o).unwrap();
    assert_eq!(l.object.material.base_color_factor, [0.1, 0.2, 0.3]);
    assert!(l.object.material.skin && l.object.material.roughness == 0.3);
    assert!(l.parts.iter().all(|p| !p.material.skin));
    // Extras beat the name; two skins: one scattered, the other warned about.
    let l =
        load_head_with_notes(&three_material_quad(&dir, Some(true)), &Default::default()).unwrap();
    assert_eq!(l.object.material.base_color_factor, [0.9, 0.6, 0.5]);
    assert!(
        l.warnings.iter().any(|w| w.contains(
            "material 2 'mat_03' is also skin, but dermis scatters one material per character"
        )),
        "{:?}",
        l.warnings
    );
    // A name that matches nothing, and extras of the wrong type, are one line.
    let o = TextureOverrides {
        skin: crate::scene::skin_rule::SkinChoice::parse(Some("Hed"), None).unwrap(),
        ..Default::default()
    };
    let e = format!(
        "{:#}",
        load_head_with_notes(&three_material_quad(&dir, None), &o)
            .err()
            .unwrap()
    );
    assert!(
        e.contains("'Hed' names no material") && !e.contains('\n'),
        "{e}"
    );
    let path = three_material_quad(&dir, None);
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "\"name\":\"mat_03\"",
        "\"name\":\"mat_03\",\"extras\":{\"skin\":\"yes\"}",
    );
    std::fs::write(&path, text).unwrap();
    let e = load_err(&path);
    assert!(
        e.contains("extras \"skin\" is \"yes\", not true or false"),
        "{e}"
    );
}

#[test]
fn a_scene_draws_every_part_and_scales_by_the_skin() {
    let dir = temp_dir("parts");
    let s =
        crate::scene::load_gltf_scene(&three_material_quad(&dir, None), &Default::default(), None)
            .unwrap();
    assert_eq!(s.parts.len(), 2);
    assert!(s.head.material.skin);
    assert_eq!(s.source.as_ref().unwrap().skin, Vec::<String>::new());
}
