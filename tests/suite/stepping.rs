//! A run stepping through the motion (`--time-step`, issue 29 item 2) and
//! what sees each character of a moving crowd at its own pose (item 5), on
//! lavapipe with validation on: a frame depends only on its time, the
//! velocity is the frame before's, and texture space stretches each
//! character's own expression.

use crate::common;
use crate::motion::settings;

use dermis::render::{RenderSettings, Renderer};
use dermis::scene::morph::apply;

/// `scene` (a file, or the default face) loaded at `time`, stepping by `step`.
fn load_at(
    scene: Option<std::path::PathBuf>,
    time: f32,
    step: Option<f32>,
) -> dermis::scene::Scene {
    dermis::scene::source::SceneSource {
        scene,
        time: Some(time),
        time_step: step,
        ..Default::default()
    }
    .load()
    .unwrap()
}

/// `frames` frames of `scene`: the first's and the last's capture, and the
/// deform pass's vertices after the last.
fn run_steps(
    ctx: &dermis::vk::context::Context,
    scene: &dermis::scene::Scene,
    s: &RenderSettings,
    frames: usize,
) -> (
    dermis::render::Capture,
    dermis::render::Capture,
    Vec<dermis::render::deform::Deformed>,
) {
    let mut r = Renderer::new(ctx, scene, s).unwrap();
    let first = r.capture(false).unwrap();
    r.run_frames(frames - 1, |_| {}).unwrap();
    let last = r.capture(false).unwrap();
    (first, last, r.deformed().unwrap())
}

/// `--time-step`: frame k of a run is posed at time + k * step, whatever
/// ran before it. Two runs of a moving crowd with different histories
/// reach 1.75 s (three steps of 0.25 s, one of 0.75 s): the same frame, bit
/// for bit. Each copy of the head holds the CPU's blend at 1.75 s, and its
/// previous positions the blend at the run's frame before (1.5 s, 1 s):
/// the velocity the temporal anti-aliasing reads.
#[test]
fn stepping_poses_each_frame_at_its_time_whatever_came_before() {
    use dermis::scene::crowd_motion::Tracks;
    let ctx = common::ctx();
    let s = RenderSettings {
        heads: 4,
        ..settings()
    };
    let run = |step: f32, frames: usize| {
        let scene = load_at(None, 1.0, Some(step));
        let (first, last, deformed) = run_steps(&ctx, &scene, &s, frames);
        (scene, first, last, deformed)
    };
    let (scene, first, a, got_a) = run(0.25, 3);
    let (_, _, b, got_b) = run(0.75, 1);
    assert!(
        a.ldr == b.ldr && a.diffuse == b.diffuse,
        "1.75 s differs by history"
    );
    assert!(first.diffuse != a.diffuse, "the frames did not move");
    let at = |t: f32| Tracks {
        time: t,
        ..scene.tracks.clone().unwrap()
    };
    let blend = |t: f32, c: usize| {
        let mut m = scene.head.morph.clone();
        m.weights = at(t).weights(c).unwrap();
        apply(&m.rest, &m)
    };
    let n = scene.head.morph.rest.len();
    for (got, before) in [(&got_a, 1.5f32), (&got_b, 1.0)] {
        for c in 0..4 {
            let want = blend(1.75, c);
            let want: &[f32] = bytemuck::cast_slice(&want);
            let copy = &got[0].vertices[12 * n * c..12 * n * (c + 1)];
            assert!(copy == want, "character {c}: not the CPU's blend at 1.75 s");
            let prev: Vec<f32> = blend(before, c).iter().flat_map(|v| v.position).collect();
            let got_prev = &got[0].previous[3 * n * c..3 * n * (c + 1)];
            assert!(
                got_prev == &prev[..],
                "character {c}: previous not at {before} s"
            );
        }
    }
    // The velocity differs by history; the frame does not.
    assert_ne!(got_a[0].previous, got_b[0].previous);
}

/// A rigid motion steps too (a scene without animation: the egg): every
/// character, the first included, turns from the pose its mesh was made
/// at, and 1 s reached by two steps or by one is the same frame. The
/// instance buffer keeps the frame before's models beside (the velocity of
/// a rigid motion).
#[test]
fn stepping_turns_a_rigid_crowd_whatever_came_before() {
    use dermis::scene::animation::rigid_rotation;
    use dermis::scene::source::SceneSource;
    let ctx = common::ctx();
    let s = RenderSettings {
        heads: 3,
        ..settings()
    };
    let run = |step: f32, frames: usize| {
        let scene = SceneSource {
            scene: Some("builtin:egg".into()),
            time_step: Some(step),
            ..SceneSource::default()
        }
        .load()
        .unwrap();
        let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
        let base = r.frame.instances.clone();
        let first = r.capture(false).unwrap();
        r.run_frames(frames - 1, |_| {}).unwrap();
        let before = r.frame.instances.clone();
        let last = r.capture(false).unwrap();
        // The instance buffer holds this frame's models and, after them,
        // the frame before's (one group: slot k is character k).
        let (now, previous) = r.frame.instance_models().unwrap();
        assert_eq!(now[..3], r.frame.instances[..]);
        assert_eq!(previous[..3], before[..]);
        assert_ne!(now[..3], previous[..3]);
        (first, last, base, r.frame.instances.clone())
    };
    let (first, a, base, moved) = run(0.5, 2);
    let (_, b, _, _) = run(1.0, 1);
    assert!(
        a.ldr == b.ldr && a.diffuse == b.diffuse,
        "1 s differs by history"
    );
    assert!(first.diffuse != a.diffuse, "the frames did not move");
    // Character 0 has turned by the clip's change from 0 s to 1 s.
    let turn = (base[0].inverse() * moved[0])
        .to_scale_rotation_translation()
        .1;
    let want = rigid_rotation(1.0) * rigid_rotation(0.0).inverse();
    assert!(turn.angle_between(want) < 1e-4, "{turn} against {want}");
}

/// Texture space sees each character's own pose in a moving crowd: the
/// stretch maps (the mesh's own derivatives, so one mesh gives one map
/// wherever it stands) of two characters at different phases of the
/// expression clip differ, and those of the same pose (a still crowd) do not.
#[test]
fn texture_space_stretches_each_character_at_its_own_pose() {
    use dermis::scene::source::SceneSource;
    let ctx = common::ctx();
    let stretch = |time: Option<f32>| {
        let scene = SceneSource {
            time,
            ..SceneSource::default()
        }
        .load()
        .unwrap();
        let s = RenderSettings {
            heads: 3,
            width: 160,
            height: 90,
            shadow_size: 256,
            ..RenderSettings::study()
        }
        .with(common::m("tsd"), &[("irradiance-size", "256")]);
        let c = Renderer::new(&ctx, &scene, &s)
            .unwrap()
            .capture(true)
            .unwrap();
        // The stretch map each character's irradiance pass wrote, in order.
        let maps: Vec<Vec<[f32; 4]>> = c
            .dumps
            .iter()
            .filter(|d| d.image == "tsd stretch u")
            .map(|d| d.rgba.clone())
            .collect();
        assert_eq!(
            maps.len(),
            3,
            "{:?}",
            c.dumps
                .iter()
                .map(|d| (&d.pass, &d.image))
                .collect::<Vec<_>>()
        );
        maps
    };
    let diff = |a: &[[f32; 4]], b: &[[f32; 4]]| {
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for (p, q) in a.iter().zip(b) {
            num += f64::from(p[0] - q[0]).powi(2);
            den += f64::from(p[0]).powi(2);
        }
        (num / den.max(1e-30)).sqrt()
    };
    let moving = stretch(Some(1.0));
    let still = stretch(None);
    let (m12, s12) = (diff(&moving[1], &moving[2]), diff(&still[1], &still[2]));
    eprintln!("stretch maps of characters 1 and 2: moving {m12:.3e}, still {s12:.3e}");
    assert!(s12 < 1e-3, "one pose, two maps: {s12}");
    assert!(
        m12 > 10.0 * s12.max(1e-5),
        "the poses' maps are alike: {m12} against {s12}"
    );
}

/// A method that reads the characters' meshes once (texture space, the
/// ground truth) refuses a step in one line, before anything runs.
#[test]
fn methods_that_pose_once_refuse_a_step() {
    for method in ["tsd", "reference"] {
        let out = common::dermis()
            .args([
                "render",
                "--method",
                method,
                "--time",
                "1",
                "--time-step",
                "0.5",
            ])
            .args(["--width", "64", "--height", "36", "--out"])
            .arg(std::env::temp_dir().join(format!("dermis-step-{method}")))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{method}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("--time-step cannot be given with {method}")),
            "{method}: {err}"
        );
    }
}

/// A glTF file's own clip (the glTF tutorial's SimpleSkin, which no code of
/// ours wrote) plays at each character's phase and steps: two runs that
/// reach 1.75 s by different steps draw the same bits; each character's
/// copy holds the CPU's skinning at its own time (the file re-posed by the
/// kept skeleton), its previous positions the frame before's; character 0
/// at 1.75 s is the file loaded at 1.75 s, to the bit; and at the 1 s key,
/// reached by steps, the strip's top corner is where the file puts it.
#[test]
fn a_files_own_clip_plays_each_character_at_its_phase_and_steps() {
    use dermis::scene::morph::deformed;
    use glam::Vec3;
    let ctx = common::ctx();
    let path = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/khronos/SimpleSkin.gltf"
    ));
    let load = |time: f32, step: Option<f32>| load_at(Some(path.clone()), time, step);
    let s = RenderSettings {
        heads: 4,
        ..settings()
    };
    let run = |time: f32, step: f32, frames: usize| {
        let scene = load(time, Some(step));
        let (first, last, deformed) = run_steps(&ctx, &scene, &s, frames);
        (scene, first, last, deformed)
    };
    let (scene, first, a, got_a) = run(1.0, 0.25, 3);
    let (_, _, b, got_b) = run(1.0, 0.75, 1);
    assert!(
        a.ldr == b.ldr && a.diffuse == b.diffuse,
        "1.75 s differs by history"
    );
    assert!(first.depth != a.depth, "the frames did not move");
    let tracks = scene.tracks.clone().unwrap();
    let at = |t: f32| dermis::scene::crowd_motion::Tracks {
        time: t,
        ..tracks.clone()
    };
    let m = &scene.head.morph;
    let skinned = |t: f32, c: usize| {
        let pose = at(t).file_pose(c).unwrap();
        deformed(&m.rest, &pose[0].applied(m))
    };
    let n = m.rest.len();
    // Four phases: four different shapes.
    let shapes: Vec<Vec<f32>> = (0..4)
        .map(|c| got_a[0].vertices[12 * n * c..12 * n * (c + 1)].to_vec())
        .collect();
    for c in 1..4 {
        assert_ne!(shapes[0], shapes[c], "character {c} in step with 0");
    }
    for (got, before) in [(&got_a, 1.5f32), (&got_b, 1.0)] {
        for c in 0..4 {
            let want = skinned(1.75, c);
            let want: &[f32] = bytemuck::cast_slice(&want);
            let copy = &got[0].vertices[12 * n * c..12 * n * (c + 1)];
            assert!(
                copy == want,
                "character {c}: not the CPU's skinning at 1.75 s"
            );
            let prev: Vec<f32> = skinned(before, c).iter().flat_map(|v| v.position).collect();
            let got_prev = &got[0].previous[3 * n * c..3 * n * (c + 1)];
            assert!(
                got_prev == &prev[..],
                "character {c}: previous not at {before} s"
            );
        }
    }
    // Character 0 at 1.75 s is the file as the loader poses it at 1.75 s.
    let still = load(1.75, None);
    let sm = &still.head.morph;
    let want = deformed(&sm.rest, sm);
    assert!(
        got_a[0].vertices[..12 * n] == *bytemuck::cast_slice::<_, f32>(&want),
        "character 0 is not the file loaded at 1.75 s"
    );
    // The 1 s key reached by two steps from 0 s: the top corner (0.5, 2),
    // held by the upper joint alone, at (-1, 1.5) (the file's 90 degrees).
    let (scene0, _, _, got) = run(0.0, 0.5, 3);
    let rest = &scene0.head.morph.rest;
    let mut found = 0;
    for (k, v) in rest.iter().enumerate() {
        if v.position == [0.5, 2.0, 0.0] {
            let p = Vec3::from_slice(&got[0].vertices[12 * k..12 * k + 3]);
            assert!((p - Vec3::new(-1.0, 1.5, 0.0)).length() < 1e-5, "{p}");
            found += 1;
        }
    }
    assert!(found > 0, "no vertex at the top corner");
}

/// A file's clip that moves a rigid part (no skin): a skin quad that stands
/// still and an "eye" quad beside it that the clip turns 90 degrees about
/// +Z over 2 s. A crowd of three at 0.5 s deforms one copy of the eye per
/// character (the part rides a joint, the identity where it was loaded),
/// each the CPU's pose at its own phase, to the bit; the still skin is not
/// deformed at all; and each copy's eye stands where the clip puts it.
#[test]
fn a_files_clip_moves_a_rigid_part_per_character() {
    use dermis::scene::gltf_load::fixture::{temp_dir, Container, Model};
    use dermis::scene::morph::deformed;
    use dermis::scene::source::SceneSource;
    use glam::Vec3;
    let dir = temp_dir("rigid-part");
    let prim = |material: usize| serde_json::json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "material": material, "mode": 6});
    let mut m = Model::quad(
        prim(0),
        serde_json::json!([]),
        &[],
        Some(serde_json::json!([{"mesh": 0}, {"mesh": 1, "translation": [1.5, 0.0, 0.0]}])),
    );
    m.json["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
    m.json["meshes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"name": "prop", "primitives": [prim(1)]}));
    m.json["materials"] = serde_json::json!([{"name": "face skin"}, {"name": "eye"}]);
    m.quarter_turn_clip("spin", 1, 2.0);
    m.json["buffers"] = serde_json::json!([{"byteLength": m.buffer.len()}]);
    let path = m.write(Container::DataUri, dir.path(), "prop");
    let scene = SceneSource {
        scene: Some(path),
        time: Some(0.5),
        mm_per_unit: Some(100.0),
        ..SceneSource::default()
    }
    .load()
    .unwrap();
    assert_eq!(scene.parts.len(), 1, "the eye is a part");
    let tracks = scene.tracks.clone().unwrap();
    let ctx = common::ctx();
    let s = RenderSettings {
        heads: 3,
        ..settings()
    };
    let mut r = Renderer::new(&ctx, &scene, &s).unwrap();
    r.capture(false).unwrap();
    let got = r.deformed().unwrap();
    assert_eq!(got.len(), 1, "only the moving part deforms");
    assert_eq!(got[0].name, "part 0");
    let part = &scene.parts[0].morph;
    let n = part.rest.len();
    for c in 0..3 {
        let want = match c {
            0 => deformed(&part.rest, part),
            c => deformed(&part.rest, &tracks.file_pose(c).unwrap()[1].applied(part)),
        };
        let copy = &got[0].vertices[12 * n * c..12 * n * (c + 1)];
        assert!(
            copy == bytemuck::cast_slice::<_, f32>(&want),
            "character {c}: not the CPU's pose"
        );
        // The eye's node turns about its own origin (1.5, 0, 0): its first
        // corner stays there, its second, (2.5, 0, 0) at rest, turns by the
        // clip's angle at the character's time (45 degrees a second).
        let corner = |k: usize| Vec3::from_slice(&copy[12 * k..12 * k + 3]);
        let angle = std::f32::consts::FRAC_PI_4 * tracks.time_of(c);
        let want = Vec3::new(1.5 + angle.cos(), angle.sin(), 0.0) - Vec3::new(1.5, 0.0, 0.0);
        let d = corner(1) - corner(0);
        assert!(
            (d - want).length() < 1e-5,
            "character {c}: {d} against {want}"
        );
    }
}
