//! The loader's tests of motion: morph targets, animations and skins, each
//! against values its glTF file states (a key's rotation, an inverse bind
//! matrix), and malformed files as one line each.

use super::fixture::{f32_bytes, temp_dir, write_gltf, Model};
use super::tests::{attrs, load_err};
use super::*;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The quad with one morph target lifting its vertices along +Z by 1, 2, 3
/// and 4 (accessor 3), `weights` its mesh's default weights.
fn morph_quad(dir: &Path, weights: serde_json::Value, offsets: usize) -> PathBuf {
    let d: Vec<f32> = (0..offsets)
        .flat_map(|i| [0.0, 0.0, (i + 1) as f32])
        .collect();
    let acc = serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": offsets, "type": "VEC3"}]);
    let prim = serde_json::json!({"attributes": attrs(), "targets": [{"POSITION": 3}]});
    let mut m = Model::quad(prim, acc, &f32_bytes(&d), None);
    m.json["meshes"][0]["weights"] = weights;
    m.json["meshes"][0]["extras"] = serde_json::json!({"targetNames": ["lift"]});
    write_gltf(dir, "morph", m.json, &m.buffer)
}

#[test]
fn morph_targets_load_posed_by_the_files_default_weights() {
    let dir = temp_dir("morph");
    let o = load_head(
        &morph_quad(&dir, serde_json::json!([0.5]), 4),
        &Default::default(),
    )
    .unwrap();
    let m = &o.morph;
    assert_eq!(m.targets.len(), 1);
    assert_eq!(m.targets[0].name.as_deref(), Some("lift"));
    assert_eq!(m.weights, [0.5]);
    // Drawn posed: half of each offset (the fan's vertices in file order).
    let z: Vec<f32> = o.mesh.vertices.iter().map(|v| v.position[2]).collect();
    assert_eq!(z, [0.5, 1.0, 1.5, 2.0]);
    assert!(m.rest.iter().all(|v| v.position[2] == 0.0));
    // Malformed: a weight count that is not the target count, and offsets
    // that are not one per vertex, are one line each.
    let e = load_err(&morph_quad(&dir, serde_json::json!([0.5, 1.0]), 4));
    assert!(
        e.contains("has 1 morph targets but mesh 'quad' gives 2 default weights"),
        "{e}"
    );
    let e = load_err(&morph_quad(&dir, serde_json::json!([0.5]), 3));
    assert!(
        e.contains("morph target 0 POSITION has 3 offsets but POSITION has 4"),
        "{e}"
    );
}

/// `morph_quad` with an animation: node 0 turns 90 degrees about +Z from 0
/// to 2 s (LINEAR), and the lift's weight steps 0 -> 1 at 1 s (STEP).
fn animated_quad(dir: &Path, times: &[f32]) -> PathBuf {
    let d: Vec<f32> = (0..4).flat_map(|i| [0.0, 0.0, (i + 1) as f32]).collect();
    let acc =
        serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3"}]);
    let prim = serde_json::json!({"attributes": attrs(), "targets": [{"POSITION": 3}]});
    let mut m = Model::quad(prim, acc, &f32_bytes(&d), None);
    let q = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2).to_array();
    let tv = m.add_view(&f32_bytes(times), None);
    let ta = m.add_accessor(serde_json::json!({"bufferView": tv, "componentType": 5126, "count": times.len(), "type": "SCALAR", "min": [times[0]], "max": [times[times.len() - 1]]}));
    let rv = m.add_view(
        &f32_bytes(&[0.0, 0.0, 0.0, 1.0, q[0], q[1], q[2], q[3]]),
        None,
    );
    let ra = m.add_accessor(
        serde_json::json!({"bufferView": rv, "componentType": 5126, "count": 2, "type": "VEC4"}),
    );
    let wv = m.add_view(&f32_bytes(&[0.0, 1.0]), None);
    let wa = m.add_accessor(
        serde_json::json!({"bufferView": wv, "componentType": 5126, "count": 2, "type": "SCALAR"}),
    );
    let step_times = m.add_view(&f32_bytes(&[0.0, 1.0]), None);
    let sa = m.add_accessor(serde_json::json!({"bufferView": step_times, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [1.0]}));
    m.json["animations"] = serde_json::json!([{
        "name": "turn",
        "samplers": [
            {"input": ta, "output": ra, "interpolation": "LINEAR"},
            {"input": sa, "output": wa, "interpolation": "STEP"}
        ],
        "channels": [
            {"sampler": 0, "target": {"node": 0, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 0, "path": "weights"}}
        ]
    }]);
    write_gltf(dir, "animated", m.json, &m.buffer)
}

#[test]
fn animations_pose_nodes_and_weights_at_the_time_asked() {
    let dir = temp_dir("anim");
    let path = animated_quad(&dir, &[0.0, 2.0]);
    let at = |t: Option<f32>| {
        let o = TextureOverrides {
            time: t,
            ..Default::default()
        };
        load_head_with_notes(&path, &o).unwrap()
    };
    // No time: the rest pose, the animation named in a note.
    let rest = at(None);
    assert!(
        rest.notes
            .iter()
            .any(|n| n.contains("1 animation(s) not played")),
        "{:?}",
        rest.notes
    );
    assert_eq!(rest.object.mesh.vertices[1].position, [1.0, 0.0, 0.0]);
    // At 1 s: turned 45 degrees (the file states 0 and 90 at 0 and 2 s), the
    // weight stepped to 1 (its key at 1 s), so vertex 1 (1, 0, 0) lifted by 2.
    let l = at(Some(1.0));
    assert!(l.animated());
    let p = glam::Vec3::from(l.object.mesh.vertices[1].position);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert!((p - glam::Vec3::new(h, h, 2.0)).length() < 1e-5, "{p}");
    assert_eq!(l.object.morph.weights, [1.0]);
    // Just before: the weight is still 0 (STEP).
    assert_eq!(at(Some(0.999)).object.morph.weights, [0.0]);
    // At its end: the last key (90 degrees); past it, looped (5 s of a
    // 2 s clip is 1 s into it), as a crowd's characters loop it.
    let p = glam::Vec3::from(at(Some(2.0)).object.mesh.vertices[1].position);
    assert!((p - glam::Vec3::new(0.0, 1.0, 2.0)).length() < 1e-5, "{p}");
    let looped = at(Some(5.0));
    let p = glam::Vec3::from(looped.object.mesh.vertices[1].position);
    assert!((p - glam::Vec3::new(h, h, 2.0)).length() < 1e-5, "{p}");
    assert!(
        looped
            .notes
            .iter()
            .any(|n| n.contains("posed at 5 s (past its end: looped, 1 s into it)")),
        "{:?}",
        looped.notes
    );
    // A clip that does not exist, and times that do not increase, are one line.
    let o = TextureOverrides {
        time: Some(1.0),
        clip: Some("walk".into()),
        ..Default::default()
    };
    let e = format!("{:#}", load_head_with_notes(&path, &o).err().unwrap());
    assert!(
        e.contains("--animation 'walk': the file has no animation of that name (it has: turn)"),
        "{e}"
    );
    let e = load_err(&animated_quad(&dir, &[2.0, 2.0]));
    assert!(
        e.contains("animation 'turn' channel 0: keyframe times are not increasing"),
        "{e}"
    );
}

/// A quad skinned by two joints: "root" at the origin holds vertices 0 and 1
/// (y = 0), "tip" at (0, 1, 0) holds 2 and 3 (y = 1), with the inverse bind
/// matrices the file states (identity, and a move by (0, -1, 0)); the mesh's
/// node is moved by (5, 0, 0), which a skinned mesh ignores. "bend" turns
/// the tip 90 degrees about +Z over 1 s (LINEAR). `joints`, `weights` and
/// `binds` (inverse bind matrices given) override the good file's.
fn skinned_quad(
    dir: &Path,
    name: &str,
    joints: [u8; 16],
    weights: [f32; 16],
    binds: usize,
    with_weights: bool,
) -> PathBuf {
    let prim = serde_json::json!({"attributes": attrs()});
    let mut m = Model::quad(
        prim,
        serde_json::json!([]),
        &[],
        Some(serde_json::json!([
            {"mesh": 0, "skin": 0, "translation": [5.0, 0.0, 0.0]},
            {"name": "root", "children": [2]},
            {"name": "tip", "translation": [0.0, 1.0, 0.0]}
        ])),
    );
    m.json["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
    let jv = m.add_view(&joints, None);
    let ja = m.add_accessor(
        serde_json::json!({"bufferView": jv, "componentType": 5121, "count": 4, "type": "VEC4"}),
    );
    let wv = m.add_view(&f32_bytes(&weights), None);
    let wa = m.add_accessor(
        serde_json::json!({"bufferView": wv, "componentType": 5126, "count": 4, "type": "VEC4"}),
    );
    let p = &mut m.json["meshes"][0]["primitives"][0]["attributes"];
    p["JOINTS_0"] = serde_json::json!(ja);
    if with_weights {
        p["WEIGHTS_0"] = serde_json::json!(wa);
    }
    let ibm: Vec<f32> = [
        glam::Mat4::IDENTITY,
        glam::Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0)),
    ]
    .iter()
    .take(binds)
    .flat_map(|m| m.to_cols_array())
    .collect();
    let bv = m.add_view(&f32_bytes(&ibm), None);
    let ba = m.add_accessor(serde_json::json!({"bufferView": bv, "componentType": 5126, "count": binds, "type": "MAT4"}));
    m.json["skins"] =
        serde_json::json!([{"name": "arm", "joints": [1, 2], "inverseBindMatrices": ba}]);
    m.quarter_turn_clip("bend", 2, 1.0);
    write_gltf(dir, name, m.json, &m.buffer)
}

const QUAD_JOINTS: [u8; 16] = [0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0];
const QUAD_WEIGHTS: [f32; 16] = [
    1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
];

#[test]
fn skins_place_vertices_by_their_joints_at_the_time_asked() {
    let dir = temp_dir("skin");
    let path = skinned_quad(&dir, "skinned.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 2, true);
    let at = |t: Option<f32>| {
        let o = TextureOverrides {
            time: t,
            ..Default::default()
        };
        load_head_with_notes(&path, &o).unwrap().object
    };
    let pos = |o: &crate::scene::mesh::Object, k: usize| Vec3::from(o.mesh.vertices[k].position);
    // The bind pose: the joints' worlds undo their inverse binds, and the
    // node's (5, 0, 0) is not applied.
    let rest = at(None);
    assert!(rest.morph.skin.is_some());
    assert_eq!(pos(&rest, 2), Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(pos(&rest, 1), Vec3::new(1.0, 0.0, 0.0));
    // At 1 s the tip has turned 90 degrees about its joint at (0, 1, 0):
    // (1, 1, 0) goes to (0, 2, 0); the root's vertices stay.
    let bent = at(Some(1.0));
    assert!(
        (pos(&bent, 2) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6,
        "{}",
        pos(&bent, 2)
    );
    assert!((pos(&bent, 3) - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6);
    assert_eq!(pos(&bent, 1), Vec3::new(1.0, 0.0, 0.0));
    // The rest is kept in bind space for the GPU; the normal turns too.
    assert_eq!(bent.morph.rest[2].position, [1.0, 1.0, 0.0]);
    let n = Vec3::from(bent.mesh.vertices[2].normal);
    assert!((n - Vec3::Z).length() < 1e-6, "{n}");
    // Halfway: 45 degrees.
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let half = at(Some(0.5));
    assert!((pos(&half, 2) - Vec3::new(h, 1.0 + h, 0.0)).length() < 1e-6);
    // Malformed skins are one line each.
    let bad = |name: &str, j: [u8; 16], w: [f32; 16], binds: usize, with_w: bool| {
        load_err(&skinned_quad(&dir, name, j, w, binds, with_w))
    };
    let mut j = QUAD_JOINTS;
    j[12] = 2;
    let e = bad("j.gltf", j, QUAD_WEIGHTS, 2, true);
    assert!(
        e.contains(
            "mesh 'quad' primitive 0: vertex 3: joint 2 is out of range (the skin has 2 joints)"
        ),
        "{e}"
    );
    let mut w = QUAD_WEIGHTS;
    w[4] = 0.5;
    let e = bad("w.gltf", QUAD_JOINTS, w, 2, true);
    assert!(
        e.contains("vertex 1: joint weights sum to 0.5, not 1"),
        "{e}"
    );
    w[4] = f32::NAN;
    let e = bad("n.gltf", QUAD_JOINTS, w, 2, true);
    assert!(e.contains("not finite") || e.contains("NaN"), "{e}");
    let e = bad("b.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 1, true);
    assert!(
        e.contains("skin 0 'arm': inverseBindMatrices has 1 matrices for 2 joints"),
        "{e}"
    );
    let e = bad("x.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 2, false);
    assert!(
        e.contains("mesh 'quad' primitive 0 has JOINTS_0 without WEIGHTS_0"),
        "{e}"
    );
}

/// A clip is measured at its rest pose: the scale (the SSS's millimetres)
/// and the face direction are the same at every time, though the bend
/// changes the mesh's height.
#[test]
fn a_clip_keeps_the_scale_of_its_rest_pose() {
    let dir = temp_dir("skin-scale");
    let path = skinned_quad(&dir, "scale.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 2, true);
    let at = |t: Option<f32>| {
        let o = TextureOverrides {
            time: t,
            ..Default::default()
        };
        crate::scene::load_gltf_scene(&path, &o, None).unwrap()
    };
    let rest = at(None);
    for t in [0.25, 0.5, 1.0] {
        let s = at(Some(t));
        assert_eq!(s.mm_per_unit, rest.mm_per_unit, "at {t} s");
        assert_eq!(s.forward, rest.forward, "at {t} s");
        assert_ne!(s.head.mesh.vertices, rest.head.mesh.vertices);
    }
}

/// What a file has that dermis does not draw is said: vertex colours,
/// cameras, lights, other extensions.
#[test]
fn what_is_not_drawn_is_said() {
    let dir = temp_dir("unsaid");
    let colours = f32_bytes(&[1.0; 16]);
    let prim = serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3}});
    let acc =
        serde_json::json!([{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}]);
    let mut m = Model::quad(prim, acc, &colours, None);
    m.json["extensionsUsed"] = serde_json::json!([
        "EXT_mesh_gpu_instancing",
        "KHR_lights_punctual",
        "KHR_materials_sheen"
    ]);
    m.json["cameras"] =
        serde_json::json!([{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}]);
    let path = write_gltf(&dir, "unsaid.gltf", m.json, &m.buffer);
    let l = load_head_with_notes(&path, &TextureOverrides::default()).unwrap();
    let all: Vec<&String> = l.warnings.iter().chain(&l.notes).collect();
    for says in [
        "KHR_lights_punctual: the file's lights are not used",
        "KHR_materials_sheen is not supported: drawn without it",
        "the file's 1 camera(s) are not used",
        "1 primitive(s) have vertex colours (COLOR_0)",
    ] {
        assert!(all.iter().any(|w| w.contains(says)), "{says}: {all:?}");
    }
}

/// EXT_mesh_gpu_instancing draws every instance: a quad of three instances
/// (at the origin; 5 along x, turned a quarter about z; 5 up, scaled 2)
/// places its corners where T * R * S of the file's values puts them.
#[test]
fn an_instanced_node_draws_every_instance_where_the_file_puts_it() {
    let dir = temp_dir("instanced");
    let q = std::f32::consts::FRAC_1_SQRT_2;
    let t = [0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 5.0, 0.0];
    let r = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, q, q, 0.0, 0.0, 0.0, 1.0];
    let sc = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0];
    let prim = serde_json::json!({"attributes": attrs()});
    let mut m = Model::quad(prim, serde_json::json!([]), &[], None);
    let mut add = |vals: &[f32], ty: &str, n: usize| {
        let view = m.add_view(&f32_bytes(vals), None);
        m.add_accessor(
            serde_json::json!({"bufferView": view, "componentType": 5126, "count": n, "type": ty}),
        )
    };
    let (ta, ra, sa) = (add(&t, "VEC3", 3), add(&r, "VEC4", 3), add(&sc, "VEC3", 3));
    m.json["extensionsUsed"] = serde_json::json!(["EXT_mesh_gpu_instancing"]);
    m.json["nodes"][0]["extensions"] = serde_json::json!({"EXT_mesh_gpu_instancing":
        {"attributes": {"TRANSLATION": ta, "ROTATION": ra, "SCALE": sa}}});
    let path = write_gltf(&dir, "instanced.gltf", m.json.clone(), &m.buffer);
    let l = load_head_with_notes(&path, &TextureOverrides::default()).unwrap();
    assert!(
        l.notes
            .iter()
            .any(|n| n.contains("its 3 instances drawn as copies")),
        "{:?}",
        l.notes
    );
    let got: Vec<Vec3> = l
        .object
        .mesh
        .vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .collect();
    assert_eq!(got.len(), 12, "three quads of four corners");
    let corners = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    // The closed forms: instance 1 turns (x, y) to (-y, x) then moves 5
    // along x; instance 2 doubles then moves 5 up.
    let want: Vec<Vec3> = corners
        .iter()
        .copied()
        .chain(corners.iter().map(|p| Vec3::new(5.0 - p.y, p.x, 0.0)))
        .chain(corners.iter().map(|p| Vec3::new(0.0, 5.0, 0.0) + 2.0 * *p))
        .collect();
    for w in &want {
        assert!(
            got.iter().any(|g| (*g - *w).length() < 1e-5),
            "no vertex at {w}: {got:?}"
        );
    }
    // Mismatched counts are one line.
    let mut bad = m.json.clone();
    bad["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] =
        serde_json::json!(0);
    let path = write_gltf(&dir, "bad.gltf", bad, &m.buffer);
    let e = format!(
        "{:#}",
        load_head_with_notes(&path, &TextureOverrides::default())
            .err()
            .unwrap()
    );
    assert!(e.contains("different counts"), "{e}");
}

/// The kept skeleton poses the file again at any time as the loader poses
/// it: a rigid primitive under the turning node (carried by a joint, the
/// identity where it was loaded) and the weight channel, loaded at 0.5 s
/// and posed at 1.5 s, give the mesh loaded at 1.5 s; a skin posed at its
/// loaded time gives the loaded joint matrices to the bit.
#[test]
fn the_kept_skeleton_poses_the_clip_as_the_loader_does() {
    let dir = temp_dir("rig");
    let posed = |path: &Path, t: f32| {
        let o = TextureOverrides {
            time: Some(t),
            ..Default::default()
        };
        load_head_with_notes(path, &o).unwrap()
    };
    let path = animated_quad(&dir, &[0.0, 2.0]);
    let early = posed(&path, 0.5);
    let rig = early.rig.as_ref().expect("a played clip keeps its rig");
    assert!(rig.moves(0));
    let obj = &early.object;
    let skin = obj
        .morph
        .skin
        .as_ref()
        .expect("a moving rigid quad has a joint");
    assert_eq!(skin.matrices, [glam::Mat4::IDENTITY]);
    assert_eq!(rig.pose(0.5)[0].joints, [glam::Mat4::IDENTITY]);
    let m = rig.pose(1.5)[0].applied(&obj.morph);
    let got = crate::scene::morph::posed(&m.rest, &m);
    let late = posed(&path, 1.5);
    assert_eq!(late.object.morph.weights, m.weights);
    for (g, w) in got.iter().zip(&late.object.mesh.vertices) {
        let d = Vec3::from(g.position) - Vec3::from(w.position);
        assert!(
            d.length() < 1e-5,
            "{:?} against {:?}",
            g.position,
            w.position
        );
    }
    // Not played: no rig, no joint.
    let rest = load_head_with_notes(&path, &Default::default()).unwrap();
    assert!(rest.rig.is_none() && rest.object.morph.skin.is_none());
    // A skin at its loaded time: the loaded matrices, bit for bit.
    let path = skinned_quad(&dir, "rig.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 2, true);
    let l = posed(&path, 0.3);
    let rig = l.rig.unwrap();
    let skin = l.object.morph.skin.unwrap();
    assert_eq!(rig.pose(0.3)[0].joints, skin.matrices);
    assert_ne!(rig.pose(0.6)[0].joints, skin.matrices);
}

/// Far from the origin (a model at 1e8, moved to the origin as it loads):
/// the kept skeleton applies the same recentring, so a skin posed at its
/// loaded time is the loaded matrices to the bit, and a rigid part posed at
/// another time is the file loaded at that time.
#[test]
fn the_kept_skeleton_recentres_as_the_loader_does() {
    let dir = temp_dir("rig-far");
    let far = |path: PathBuf, node: usize| {
        let mut json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        json["nodes"][node]["translation"] = serde_json::json!([1e8, -2e8, 3e8]);
        std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
        path
    };
    let posed = |path: &Path, t: f32| {
        let o = TextureOverrides {
            time: Some(t),
            ..Default::default()
        };
        load_head_with_notes(path, &o).unwrap()
    };
    let path = far(
        skinned_quad(&dir, "far.gltf", QUAD_JOINTS, QUAD_WEIGHTS, 2, true),
        1,
    );
    let l = posed(&path, 0.3);
    assert!(
        l.warnings.iter().any(|w| w.contains("moved to the origin")),
        "{:?}",
        l.warnings
    );
    let rig = l.rig.unwrap();
    assert_ne!(rig.shift, glam::DVec3::ZERO);
    assert_eq!(
        rig.pose(0.3)[0].joints,
        l.object.morph.skin.unwrap().matrices
    );
    let path = far(animated_quad(&dir, &[0.0, 2.0]), 0);
    let early = posed(&path, 0.5);
    let rig = early.rig.as_ref().unwrap();
    let m = rig.pose(1.5)[0].applied(&early.object.morph);
    let got = crate::scene::morph::posed(&m.rest, &m);
    let late = posed(&path, 1.5);
    // Each load recentres by its own pose's centre: compare in the file's
    // space.
    let (s0, s1) = (rig.shift, late.rig.as_ref().unwrap().shift);
    assert_ne!(s0, s1);
    for (g, w) in got.iter().zip(&late.object.mesh.vertices) {
        let at = |p: [f32; 3], s: glam::DVec3| Vec3::from(p).as_dvec3() + s;
        let d = at(g.position, s0) - at(w.position, s1);
        assert!(
            d.length() < 1e-4,
            "{:?} against {:?}",
            g.position,
            w.position
        );
    }
}
