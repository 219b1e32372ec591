//! Characters that move (issue 29), on lavapipe with validation on: morph
//! targets blended on the GPU by the deform pass exactly as the CPU blends
//! them, and a frame of a morphed head against the same head deformed on the
//! CPU and drawn as a still.

use crate::common;

use dermis::render::{RenderSettings, Renderer};
use dermis::scene::morph::{apply, posed, Morph, MorphTarget};
use dermis::scene::{egg_scene, Scene};
use glam::Vec3;

/// The egg's head with two targets: a swelling along the normals over every
/// vertex (with normal and tangent offsets), and a lift of the first half
/// of the vertices (positions only), at weights 0.7 and -0.3.
fn morphing_egg() -> Scene {
    let mut scene = egg_scene();
    let rest = scene.head.mesh.vertices.clone();
    let n = rest.len();
    let swell = MorphTarget {
        name: Some("swell".into()),
        first: 0,
        position: rest
            .iter()
            .map(|v| (Vec3::from(v.normal) * (0.1 + 0.05 * v.position[0].sin())).into())
            .collect(),
        normal: rest
            .iter()
            .map(|v| [0.0, 0.2 * v.position[1].cos(), 0.0])
            .collect(),
        tangent: rest.iter().map(|v| [0.0, 0.0, 0.1 * v.uv[0]]).collect(),
    };
    let lift = MorphTarget {
        name: Some("lift".into()),
        first: 0,
        position: vec![[0.0, 0.37, 0.0]; n / 2],
        ..Default::default()
    };
    scene
        .head
        .set_morph(Morph {
            rest: Vec::new(),
            targets: vec![swell, lift],
            weights: vec![0.7, -0.3],
            skin: None,
        })
        .unwrap();
    scene
}

/// The GPU's floats are the CPU's, bit for bit (as many, none differing).
fn assert_same_bits(got: &[f32], want: &[f32]) {
    assert_eq!(got.len(), want.len());
    let differ = got
        .iter()
        .zip(want)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ,
        0,
        "{differ} of {} floats differ from the CPU's",
        want.len()
    );
}

pub(crate) fn settings() -> RenderSettings {
    RenderSettings {
        width: 160,
        height: 90,
        ..RenderSettings::study()
    }
}

#[test]
fn the_deform_pass_blends_morph_targets_exactly_as_the_cpu_does() {
    let ctx = common::ctx();
    let scene = morphing_egg();
    let m = &scene.head.morph;
    let mut r = Renderer::new(&ctx, &scene, &settings()).unwrap();
    let cap = r.capture(false).unwrap();
    assert!(cap.samples.iter().any(|p| p.name == "deform head"));
    let got = r.deformed().unwrap();
    assert_eq!(got.len(), 1, "one morphing object");
    let want = apply(&m.rest, m);
    let want: Vec<f32> = bytemuck::cast_slice(&want).to_vec();
    assert_same_bits(&got[0].vertices, &want);
    // No frame before the first: the previous positions are this frame's,
    // so every velocity is 0.
    for (k, p) in got[0].previous.chunks_exact(3).enumerate() {
        assert_eq!(p, &want[12 * k..12 * k + 3], "vertex {k}");
    }
    // The CPU's consumers read the same positions with unit normals.
    let cpu = posed(&m.rest, m);
    assert_eq!(cpu.len(), scene.head.mesh.vertices.len());
    for (a, b) in cpu.iter().zip(&scene.head.mesh.vertices) {
        assert_eq!(a.position, b.position);
    }
}

#[test]
fn a_morphed_head_draws_as_the_same_mesh_deformed_on_the_cpu() {
    let ctx = common::ctx();
    let scene = morphing_egg();
    // The still: the posed mesh, no targets (no deform pass).
    let mut still = scene.clone();
    still.head.morph = Morph::default();
    let s = settings().with(common::m("separable"), &[]);
    let morphed = Renderer::new(&ctx, &scene, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    let drawn = Renderer::new(&ctx, &still, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert!(!drawn.samples.iter().any(|p| p.name.starts_with("deform")));
    // Positions are the same bits, so depth and coverage are; the normals
    // differ by the rounding of one normalisation (the still's are unit
    // before the vertex shader normalises them again).
    assert_eq!(morphed.depth, drawn.depth);
    let worst = morphed
        .diffuse
        .iter()
        .zip(&drawn.diffuse)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / b[c].abs().max(1e-3)))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "worst relative difference {worst}");
    // And the head moved: the lift and the swelling changed the frame.
    let rest = Renderer::new(&ctx, &egg_scene(), &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert_ne!(rest.depth, drawn.depth);
}

#[test]
fn the_face_has_table_8_1s_six_expressions_and_the_command_line_poses_them() {
    use dermis::scene::expressions::EXPRESSIONS;
    use dermis::scene::source::SceneSource;
    let face = dermis::scene::default_scene();
    let names: Vec<&str> = face
        .head
        .morph
        .targets
        .iter()
        .filter_map(|t| t.name.as_deref())
        .collect();
    assert_eq!(names, EXPRESSIONS);
    assert!(face.head.morph.at_rest());
    let src = |w: &[&str]| SceneSource {
        morph_weights: w.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    let joy = src(&["joy=1", "sad=0.25"]).load().unwrap();
    assert_eq!(joy.head.morph.weights, [1.0, 0.0, 0.0, 0.0, 0.0, 0.25]);
    assert_ne!(joy.head.mesh.vertices, face.head.mesh.vertices);
    assert_eq!(
        joy.source.as_ref().unwrap().morph_weights,
        ["joy=1", "sad=0.25"]
    );
    for (bad, says) in [
        (
            "smile=1",
            "no morph target of 'procedural face' is named 'smile' (named: joy, surprise",
        ),
        ("joy", "not NAME=WEIGHT"),
        ("joy=inf", "is not a finite number"),
    ] {
        let e = format!("{:#}", src(&[bad]).load().unwrap_err());
        assert!(e.contains(says) && !e.contains('\n'), "{bad}: {e}");
    }
}

#[test]
fn the_truth_of_a_posed_face_is_the_truth_of_the_same_mesh_as_a_still() {
    let ctx = common::ctx();
    let mut face = dermis::scene::default_scene();
    face.set_morph_weights(&[("surprise".into(), 1.0), ("joy".into(), 0.5)])
        .unwrap();
    // The mesh alone: the still has no expression weights to crease it by
    // (tests/suite/wrinkles.rs has the wrinkles).
    face.head.material.wrinkles = None;
    let mut still = face.clone();
    still.head.morph = Morph::default();
    let s = settings().with(common::m("reference"), &[]);
    let posed = Renderer::new(&ctx, &face, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert!(posed.samples.iter().any(|p| p.name == "deform head"));
    let drawn = Renderer::new(&ctx, &still, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert_eq!(posed.depth, drawn.depth);
    let worst = posed
        .diffuse
        .iter()
        .zip(&drawn.diffuse)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / b[c].abs().max(1e-3)))
        .fold(0.0f32, f32::max);
    println!("truth of the posed face against the still: worst relative difference {worst:e}");
    assert!(worst < 1e-3, "{worst}");
}

/// `--time` poses the face by its expression clip (rise 1 s, hold 0.5 s,
/// fall 1 s, each expression in turn), and the pose at a time is the same
/// whatever was loaded before it (the face is built once a process).
#[test]
fn time_poses_the_face_by_its_expression_clip_whatever_came_before() {
    use dermis::scene::expressions::{EXPRESSIONS, FALL_S, HOLD_S, RISE_S};
    use dermis::scene::source::SceneSource;
    let at = |t: f32| {
        SceneSource {
            time: Some(t),
            ..SceneSource::default()
        }
        .load()
        .unwrap()
    };
    let step = RISE_S + HOLD_S + FALL_S;
    for (e, name) in EXPRESSIONS.iter().enumerate() {
        // Held: the expression alone at weight 1, the same mesh as
        // --morph-weights NAME=1.
        let held = at(step * e as f32 + RISE_S + 0.5 * HOLD_S);
        let mut want = vec![0.0; EXPRESSIONS.len()];
        want[e] = 1.0;
        assert_eq!(held.head.morph.weights, want, "{name}");
        let mut by_weight = dermis::scene::default_scene();
        by_weight
            .set_morph_weights(&[(name.to_string(), 1.0)])
            .unwrap();
        assert_eq!(
            held.head.mesh.vertices, by_weight.head.mesh.vertices,
            "{name}"
        );
    }
    // Halfway up joy: half of it.
    assert_eq!(at(0.5 * RISE_S).head.morph.weights[0], 0.5);
    // The end of the clip is neutral, and neutral is the still face.
    let end = at(step * EXPRESSIONS.len() as f32);
    assert!(end.head.morph.at_rest());
    assert_eq!(
        end.head.mesh.vertices,
        dermis::scene::default_scene().head.mesh.vertices
    );
    // The same time after other times: the same bits.
    let first = at(3.9);
    let _ = at(7.2);
    let _ = at(0.3);
    assert_eq!(at(3.9).head.mesh.vertices, first.head.mesh.vertices);
    // Out of range, and a clip name for a built-in scene: one line each.
    let e = SceneSource {
        time: Some(-1.0),
        ..SceneSource::default()
    }
    .load()
    .unwrap_err();
    assert!(format!("{e:#}").contains("time"), "{e:#}");
    let e = SceneSource {
        clip: Some("walk".into()),
        ..SceneSource::default()
    }
    .load()
    .unwrap_err();
    assert!(format!("{e:#}").contains("--animation"), "{e:#}");
}

/// A character without animation turns and nods (dermis's rigid clip):
/// every vertex keeps its distance to the head's centre (a rotation), the
/// loop comes back to the rest pose, and the turn at a quarter period is
/// 25 degrees about the vertical.
fn assert_rigid_turn(rest: &Scene, at: impl Fn(f32) -> Scene) {
    use dermis::scene::animation::RIGID_PERIOD_S;
    let c = rest.head_center();
    let quarter = at(0.25 * RIGID_PERIOD_S);
    let mut worst_len = 0.0f32;
    let (mut yaw_sum, mut n) = (0.0f64, 0);
    for (a, b) in rest
        .head
        .mesh
        .vertices
        .iter()
        .zip(&quarter.head.mesh.vertices)
    {
        let (a, b) = (Vec3::from(a.position) - c, Vec3::from(b.position) - c);
        worst_len = worst_len.max((a.length() - b.length()).abs() / a.length().max(1.0));
        // Yaw seen from above, on vertices far from the vertical axis.
        if a.x.hypot(a.z) > 0.5 * a.length() {
            let d = (b.x.atan2(b.z) - a.x.atan2(a.z)).to_degrees();
            yaw_sum += f64::from((d + 540.0).rem_euclid(360.0) - 180.0);
            n += 1;
        }
    }
    assert!(worst_len < 1e-4, "lengths change by {worst_len}");
    // The nod of 8 degrees tilts the azimuths a little; on average the turn
    // is the clip's 25 degrees.
    let yaw = yaw_sum / n as f64;
    assert!((yaw - 25.0).abs() < 2.0, "mean yaw {yaw}");
    let looped = at(RIGID_PERIOD_S);
    for (a, b) in rest
        .head
        .mesh
        .vertices
        .iter()
        .zip(&looped.head.mesh.vertices)
    {
        assert!((Vec3::from(a.position) - Vec3::from(b.position)).length() < 1e-3);
    }
}

#[test]
fn time_turns_and_nods_a_character_without_animation() {
    use dermis::scene::source::SceneSource;
    let egg = SceneSource::builtin_named("egg");
    let at = |t: f32| {
        SceneSource {
            time: Some(t),
            ..egg.clone()
        }
        .load()
        .unwrap()
    };
    assert_rigid_turn(&egg_scene(), at);
    let Some(lps) = common::lps_path() else {
        return;
    };
    let src = SceneSource {
        scene: Some(lps),
        ..SceneSource::default()
    };
    let rest = src.load().unwrap();
    assert_rigid_turn(&rest, |t| {
        SceneSource {
            time: Some(t),
            ..src.clone()
        }
        .load()
        .unwrap()
    });
}

/// The egg with a skin of three joints: the lower half held by a still
/// joint, the upper half by one turned 0.4 rad about Z and lifted, a band
/// between weighted by height (two slots; a few vertices with the second
/// set), and its targets too: morph in bind space, then joints. The
/// previous pose is the joints before a step.
fn skinned_egg() -> Scene {
    use dermis::scene::skin::{Skin, SLOTS};
    let mut scene = morphing_egg();
    let rest = scene.head.morph.rest.clone();
    let (lo, hi) = rest.iter().fold((f32::MAX, f32::MIN), |(a, b), v| {
        (a.min(v.position[1]), b.max(v.position[1]))
    });
    let mut joints = Vec::new();
    let mut weights = Vec::new();
    for (k, v) in rest.iter().enumerate() {
        let h = ((v.position[1] - lo) / (hi - lo)).clamp(0.0, 1.0);
        let mut j = [0u32; SLOTS];
        let mut w = [0.0f32; SLOTS];
        j[0] = 0;
        j[1] = 1;
        w[0] = 1.0 - h;
        w[1] = h;
        if k % 7 == 0 {
            // Some weight on the third joint, in the second set.
            j[5] = 2;
            w[5] = 0.25 * w[1];
            w[1] -= w[5];
        }
        joints.push(j);
        weights.push(w);
    }
    let c = glam::Vec3::new(0.0, 0.5 * (lo + hi), 0.0);
    let turn = |a: f32, lift: f32| {
        glam::Mat4::from_translation(c + glam::Vec3::Y * lift)
            * glam::Mat4::from_rotation_z(a)
            * glam::Mat4::from_translation(-c)
    };
    let mut morph = scene.head.morph.clone();
    morph.skin = Some(Skin {
        joints,
        weights,
        slots: SLOTS,
        matrices: vec![glam::Mat4::IDENTITY, turn(0.4, 0.2), turn(-0.3, 0.0)],
        previous: vec![glam::Mat4::IDENTITY, turn(0.3, 0.1), turn(-0.2, 0.0)],
    });
    scene.head.mesh.vertices = rest;
    scene.head.set_morph(morph).unwrap();
    scene
}

#[test]
fn the_deform_pass_skins_exactly_as_the_cpu_does() {
    use dermis::scene::morph::deformed;
    use dermis::scene::skin::apply_previous;
    let ctx = common::ctx();
    let scene = skinned_egg();
    let m = &scene.head.morph;
    let mut r = Renderer::new(&ctx, &scene, &settings()).unwrap();
    r.capture(false).unwrap();
    let got = r.deformed().unwrap();
    let want = deformed(&m.rest, m);
    let want: Vec<f32> = bytemuck::cast_slice(&want).to_vec();
    assert_same_bits(&got[0].vertices, &want);
    // Previous positions: the previous joints over the targets at the
    // previous weights (the first frame's: these).
    let prev = apply_previous(&apply(&m.rest, m), m.skin.as_ref().unwrap());
    let prev: Vec<f32> = prev.iter().flatten().copied().collect();
    assert_eq!(got[0].previous, prev);
    // Skinning moved the head: the velocity is not zero where the turning
    // joint holds a vertex.
    assert!(got[0]
        .previous
        .chunks_exact(3)
        .zip(want.chunks_exact(12))
        .any(|(p, v)| (p[1] - v[1]).abs() > 1e-3));
    // And the frame draws the skinned mesh: the same depth as the CPU's
    // posed mesh drawn as a still.
    let mut still = scene.clone();
    still.head.morph = Morph::default();
    let s = settings();
    let a = Renderer::new(&ctx, &scene, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    let b = Renderer::new(&ctx, &still, &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert_eq!(a.depth, b.depth);
}

/// A crowd at --time: each character deforms its own copy of the face at
/// its own phase of the expression clip (the first at the scene's pose), each
/// copy exactly the CPU's blend at that character's weights, no two alike;
/// the same seed draws the same frame and another seed another.
#[test]
fn a_moving_crowd_deforms_each_character_at_its_own_phase() {
    use dermis::scene::source::SceneSource;
    let ctx = common::ctx();
    let load = |seed: Option<u64>| {
        SceneSource {
            time: Some(1.0),
            crowd_seed: seed,
            ..SceneSource::default()
        }
        .load()
        .unwrap()
    };
    let scene = load(None);
    let tracks = scene.tracks.clone().expect("a timed face has tracks");
    let s = RenderSettings {
        heads: 4,
        ..settings()
    };
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    let first = r.capture(false).unwrap();
    let got = r.deformed().unwrap();
    assert_eq!(got.len(), 1, "the head alone morphs");
    let v = 12 * scene.head.morph.rest.len();
    assert_eq!(got[0].vertices.len(), 4 * v);
    let copies: Vec<&[f32]> = got[0].vertices.chunks_exact(v).collect();
    // One group: instance slot k is character k.
    for (c, copy) in copies.iter().enumerate() {
        let mut m = scene.head.morph.clone();
        if c > 0 {
            m.weights = tracks.weights(c).unwrap();
        }
        let want = apply(&m.rest, &m);
        let want: &[f32] = bytemuck::cast_slice(&want);
        assert!(*copy == want, "character {c}'s copy is not the CPU's blend");
    }
    for a in 0..4 {
        for b in a + 1..4 {
            assert!(copies[a] != copies[b], "characters {a} and {b} in step");
        }
    }
    // The same seed: the same frame; another seed: another crowd.
    let again = Renderer::new(&ctx, &load(None), &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert_eq!(first.diffuse, again.diffuse);
    let other = Renderer::new(&ctx, &load(Some(7)), &s)
        .unwrap()
        .capture(false)
        .unwrap();
    assert_ne!(first.diffuse, other.diffuse);
}

/// A moving crowd drawn at levels of detail: each character's copy has
/// its level's vertices deformed as the CPU blends them (to the bit) and
/// every other vertex left as uploaded (the pass skipped it), and every
/// index of the character's level names a deformed vertex.
#[test]
fn a_crowd_at_levels_deforms_only_what_its_levels_draw() {
    use dermis::scene::source::SceneSource;
    let ctx = common::ctx();
    let scene = SceneSource {
        time: Some(1.0),
        ..SceneSource::default()
    }
    .load()
    .unwrap();
    let tracks = scene.tracks.clone().expect("a timed face has tracks");
    let heads = 9;
    let s = RenderSettings {
        heads,
        lod_pixels: 2.0,
        ..settings()
    };
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    r.capture(false).unwrap();
    let head = r
        .frame
        .objects
        .iter()
        .find(|o| o.name == "head")
        .expect("the head object");
    let levels = head.mesh.slot_levels.clone();
    let lists = head.level_vertices.clone();
    assert_eq!(levels.len(), heads as usize);
    assert!(
        levels.iter().any(|&l| l > 0),
        "no character at a level: {levels:?}"
    );
    let got = r.deformed().unwrap();
    let n = scene.head.morph.rest.len();
    let uploaded: &[f32] = bytemuck::cast_slice(&scene.head.mesh.vertices);
    let mut skipped = 0usize;
    for (c, copy) in got[0].vertices.chunks_exact(12 * n).enumerate() {
        let mut m = scene.head.morph.clone();
        if c > 0 {
            m.weights = tracks.weights(c).unwrap();
        }
        let want = apply(&m.rest, &m);
        let want: &[f32] = bytemuck::cast_slice(&want);
        let listed = &lists[levels[c] as usize];
        let mut is_listed = vec![false; n];
        for &v in listed {
            is_listed[v as usize] = true;
        }
        for v in 0..n {
            let (got, cpu, up) = (
                &copy[12 * v..12 * v + 12],
                &want[12 * v..12 * v + 12],
                &uploaded[12 * v..12 * v + 12],
            );
            if is_listed[v] {
                assert!(got == cpu, "character {c}, vertex {v}: not the CPU's blend");
            } else {
                assert!(
                    got == up,
                    "character {c}, vertex {v}: written though unlisted"
                );
                skipped += 1;
            }
        }
    }
    assert!(skipped > 0, "every vertex deformed");
    // A level's triangles name listed vertices only (what the draws read).
    let full = dermis::scene::lod::levels(&scene.head.mesh);
    for (l, level) in full.iter().enumerate() {
        assert!(level
            .indices
            .iter()
            .all(|i| lists[l].binary_search(i).is_ok()));
    }
    eprintln!("levels {levels:?}: {skipped} vertex copies skipped");
}

/// A public sample no code of ours wrote: the glTF tutorial's SimpleSkin
/// (tests/fixtures/khronos). At the 1 s key the upper joint (at y = 1) has
/// turned 90 degrees about +Z (the file's quaternion (0, 0, 0.707, 0.707)),
/// the lower joint is still; the strip's top corner (0.5, 2), held by the
/// upper joint alone, goes to (-1, 1.5), and the middle corner (0.5, 1),
/// held half and half, to the mean of (0.5, 1) and (0, 1.5). The GPU's
/// deform pass writes those vertices as the CPU does, to the bit.
#[test]
fn the_khronos_simple_skin_bends_as_its_file_states() {
    use dermis::scene::morph::deformed;
    use dermis::scene::source::SceneSource;
    let path = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/khronos/SimpleSkin.gltf"
    ));
    let src = SceneSource {
        scene: Some(path),
        time: Some(1.0),
        ..SceneSource::default()
    };
    let scene = src.load().unwrap();
    let m = &scene.head.morph;
    assert!(m.skin.is_some(), "the strip is skinned");
    let at = |bind: [f32; 3]| -> Vec<Vec3> {
        m.rest
            .iter()
            .zip(&scene.head.mesh.vertices)
            .filter(|(r, _)| r.position == bind)
            .map(|(_, v)| Vec3::from(v.position))
            .collect()
    };
    for (bind, want) in [
        ([0.5, 2.0, 0.0], Vec3::new(-1.0, 1.5, 0.0)),
        ([0.5, 1.0, 0.0], Vec3::new(0.25, 1.25, 0.0)),
        ([-0.5, 0.0, 0.0], Vec3::new(-0.5, 0.0, 0.0)),
    ] {
        let got = at(bind);
        assert!(!got.is_empty(), "no vertex at {bind:?}");
        for p in got {
            assert!(
                (p - want).length() < 1e-5,
                "{bind:?} went to {p}, not {want}"
            );
        }
    }
    // The GPU: the same vertices to the bit.
    let ctx = common::ctx();
    let mut r = Renderer::new(&ctx, &scene, &settings()).unwrap();
    r.capture(false).unwrap();
    let got = r.deformed().unwrap();
    let want = deformed(&m.rest, m);
    assert_eq!(got[0].vertices, bytemuck::cast_slice::<_, f32>(&want));
}
