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
        })
        .unwrap();
    scene
}

fn settings() -> RenderSettings {
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
    let differ = got[0]
        .vertices
        .iter()
        .zip(&want)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(got[0].vertices.len(), want.len());
    assert_eq!(
        differ,
        0,
        "{differ} of {} floats differ from the CPU's",
        want.len()
    );
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
    let names: Vec<&str> = face.head.morph.targets.iter().filter_map(|t| t.name.as_deref()).collect();
    assert_eq!(names, EXPRESSIONS);
    assert!(face.head.morph.at_rest());
    let src = |w: &[&str]| SceneSource {
        morph_weights: w.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    let joy = src(&["joy=1", "sad=0.25"]).load().unwrap();
    assert_eq!(joy.head.morph.weights, [1.0, 0.0, 0.0, 0.0, 0.0, 0.25]);
    assert_ne!(joy.head.mesh.vertices, face.head.mesh.vertices);
    assert_eq!(joy.source.as_ref().unwrap().morph_weights, ["joy=1", "sad=0.25"]);
    for (bad, says) in [
        ("smile=1", "no morph target of 'procedural face' is named 'smile' (named: joy, surprise"),
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
    face.set_morph_weights(&[("surprise".into(), 1.0), ("joy".into(), 0.5)]).unwrap();
    let mut still = face.clone();
    still.head.morph = Morph::default();
    let s = settings().with(common::m("reference"), &[]);
    let posed = Renderer::new(&ctx, &face, &s).unwrap().capture(false).unwrap();
    assert!(posed.samples.iter().any(|p| p.name == "deform head"));
    let drawn = Renderer::new(&ctx, &still, &s).unwrap().capture(false).unwrap();
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
