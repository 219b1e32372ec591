//! Writes the default face as a skinned GLB: the device benchmark of a crowd
//! that skins (issue 29's skinning work per character; docs/perf/issue29,
//! "Skinned crowds"). dermis's own face has morph targets, no skin, and the
//! Lee Perry-Smith head neither; a skinned human head of this size is what a
//! game's crowd draws, so this file gives one without a download.
//!
//! ```sh
//! cargo run --release --features tools --example skinned_face -- out/skinned-face.glb
//! ```
//!
//! Two joints: the neck (30 mm below the chin) and the head (20 mm above it),
//! every vertex of the face weighted between them by its height (all neck
//! 40 mm below the chin, all head 10 mm above it, smoothstep between: a
//! neck that bends), the eyes on the head joint alone. The clip turns the
//! head 30 degrees each way with a nod of 10 over 4 s and the neck a third of
//! that (LINEAR, 17 keys each), looped. Materials are named so dermis's skin
//! rule reads them ("face skin", "eye"), in their base colours (no textures:
//! the benchmark times the deform pass and the draws, not the shading).

use std::path::PathBuf;

use anyhow::{Context, Result};
use dermis::scene::gltf_load::fixture::glb_bytes;
use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};

/// Millimetres to scene units at the face's scale.
fn mm(scene: &dermis::scene::Scene, v: f32) -> f32 {
    v / scene.mm_per_unit
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Appends `bytes` as a buffer view (4-byte aligned) and an accessor over it.
fn accessor(
    bin: &mut Vec<u8>,
    views: &mut Vec<Value>,
    accs: &mut Vec<Value>,
    bytes: &[u8],
    acc: Value,
) -> usize {
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
    bin.extend_from_slice(bytes);
    let mut a = acc;
    a["bufferView"] = json!(views.len() - 1);
    accs.push(a);
    accs.len() - 1
}

fn f32s(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(|f| f.to_le_bytes()).collect()
}

fn main() -> Result<()> {
    let out: PathBuf = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/skinned-face.glb".into())
        .into();
    let scene = dermis::scene::default_scene();
    let size = scene.head_size();
    let chin = size.centre.y - 0.5 * size.height;
    let neck = Vec3::new(size.centre.x, chin - mm(&scene, 30.0), size.centre.z);
    let head = Vec3::new(size.centre.x, chin + mm(&scene, 20.0), size.centre.z);
    let (mut bin, mut views, mut accs) = (Vec::new(), Vec::new(), Vec::new());
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    let objects = std::iter::once((&scene.head, "face skin", true))
        .chain(scene.parts.iter().map(|p| (p, "eye", false)));
    for (o, name, weighted) in objects {
        let v = &o.mesh.vertices;
        let lo = v
            .iter()
            .fold(Vec3::MAX, |m, x| m.min(Vec3::from(x.position)));
        let hi = v
            .iter()
            .fold(Vec3::MIN, |m, x| m.max(Vec3::from(x.position)));
        let pos = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &f32s(v.iter().flat_map(|x| x.position)),
            json!({"componentType": 5126, "count": v.len(), "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()}),
        );
        let nrm = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &f32s(v.iter().flat_map(|x| x.normal)),
            json!({"componentType": 5126, "count": v.len(), "type": "VEC3"}),
        );
        let uv = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &f32s(v.iter().flat_map(|x| x.uv)),
            json!({"componentType": 5126, "count": v.len(), "type": "VEC2"}),
        );
        let joints: Vec<u8> = v
            .iter()
            .flat_map(|_| [0u16, 1, 0, 0])
            .flat_map(|j| j.to_le_bytes())
            .collect();
        let jts = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &joints,
            json!({"componentType": 5123, "count": v.len(), "type": "VEC4"}),
        );
        let weights = v.iter().flat_map(|x| {
            let w = if weighted {
                smoothstep(
                    chin - mm(&scene, 40.0),
                    chin + mm(&scene, 10.0),
                    x.position[1],
                )
            } else {
                1.0
            };
            [1.0 - w, w, 0.0, 0.0]
        });
        let wts = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &f32s(weights),
            json!({"componentType": 5126, "count": v.len(), "type": "VEC4"}),
        );
        let idx: Vec<u8> = o
            .mesh
            .indices
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let ind = accessor(
            &mut bin,
            &mut views,
            &mut accs,
            &idx,
            json!({"componentType": 5125, "count": o.mesh.indices.len(), "type": "SCALAR"}),
        );
        let c = o.material.base_color_factor;
        materials.push(json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0}}));
        meshes.push(json!({
            "attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "JOINTS_0": jts, "WEIGHTS_0": wts},
            "indices": ind,
            "material": materials.len() - 1
        }));
    }
    let ibm = f32s(
        [Mat4::from_translation(-neck), Mat4::from_translation(-head)]
            .iter()
            .flat_map(|m| m.to_cols_array()),
    );
    let ibm = accessor(
        &mut bin,
        &mut views,
        &mut accs,
        &ibm,
        json!({"componentType": 5126, "count": 2, "type": "MAT4"}),
    );
    // 17 keys over 4 s: yaw 30 degrees each way, a nod of 10 (the neck a third).
    let keys = 17;
    let times: Vec<f32> = (0..keys)
        .map(|k| 4.0 * k as f32 / (keys - 1) as f32)
        .collect();
    let turn = |share: f32| -> Vec<f32> {
        times
            .iter()
            .flat_map(|t| {
                let a = std::f32::consts::TAU * t / 4.0;
                (Quat::from_rotation_y((30.0 * share * a.sin()).to_radians())
                    * Quat::from_rotation_x((10.0 * share * (2.0 * a).sin()).to_radians()))
                .to_array()
            })
            .collect()
    };
    let input = accessor(
        &mut bin,
        &mut views,
        &mut accs,
        &f32s(times.iter().copied()),
        json!({"componentType": 5126, "count": keys, "type": "SCALAR", "min": [0.0], "max": [4.0]}),
    );
    let neck_keys = accessor(
        &mut bin,
        &mut views,
        &mut accs,
        &f32s(turn(1.0 / 3.0)),
        json!({"componentType": 5126, "count": keys, "type": "VEC4"}),
    );
    let head_keys = accessor(
        &mut bin,
        &mut views,
        &mut accs,
        &f32s(turn(1.0)),
        json!({"componentType": 5126, "count": keys, "type": "VEC4"}),
    );
    let doc = json!({
        "asset": {"version": "2.0", "generator": "dermis tools/examples/skinned_face.rs"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "face", "mesh": 0, "skin": 0},
            {"name": "neck", "translation": neck.to_array(), "children": [2]},
            {"name": "head", "translation": (head - neck).to_array()}
        ],
        "meshes": [{"name": "face", "primitives": meshes}],
        "materials": materials,
        "skins": [{"joints": [1, 2], "inverseBindMatrices": ibm, "skeleton": 1}],
        "animations": [{
            "name": "turn and nod",
            "samplers": [
                {"input": input, "output": neck_keys, "interpolation": "LINEAR"},
                {"input": input, "output": head_keys, "interpolation": "LINEAR"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 2, "path": "rotation"}}
            ]
        }],
        "accessors": accs,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(&out, glb_bytes(&doc, Some(&bin)))
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "wrote {} ({} vertices, {} triangles, 2 joints, a 4 s clip)",
        out.display(),
        scene.head.mesh.vertices.len()
            + scene
                .parts
                .iter()
                .map(|p| p.mesh.vertices.len())
                .sum::<usize>(),
        scene.head.mesh.triangle_count()
            + scene
                .parts
                .iter()
                .map(|p| p.mesh.triangle_count())
                .sum::<usize>()
    );
    Ok(())
}
