//! Shadow-caster culling and the plan's geometry (issue 29, item 7), on
//! lavapipe with validation on. A crowd walked toward the camera leaves
//! characters out of view; with the key light from the side, some of them
//! shade characters still in view and some shade nothing seen. The shadow
//! map draws only the first kind: not one pixel changes (the bits of the
//! frame against a frame whose shadow map draws everyone), and the input
//! assembler reads exactly the casters' triangles (pipeline statistics).
//! `dermis plan` writes each character's level and caster flag, and
//! `render --plan` draws exactly those.

use crate::common;

use dermis::mix::plan_file::{PlanFile, PlannedCharacter, PlannedGeometry, PLAN_VERSION};
use dermis::render::settings::Assignment;
use dermis::render::{Capture, RenderSettings, Renderer};

const HEADS: usize = 16;
/// Head heights the crowd walks toward the camera: its front rows pass it.
const WALKED: f32 = 12.0;
/// The key light from the viewer's right.
const AZIMUTH: f32 = 90.0;

/// Every character with the default method; `geometry` for each, or none
/// (the frame chooses).
fn plan(geometry: Option<PlannedGeometry>) -> PlanFile {
    PlanFile {
        version: PLAN_VERSION,
        profile: None,
        budget_ms: None,
        characters: HEADS,
        assignments: (0..HEADS)
            .map(|c| PlannedCharacter {
                character: c,
                method: "separable".into(),
                options: Default::default(),
                setting: None,
                px_per_mm: None,
                skin_pixels: None,
                predicted_ms: None,
                predicted_error: None,
                geometry,
                fade: None,
            })
            .collect(),
        predicted_ms: None,
        predicted_error: None,
        notes: Vec::new(),
        run: None,
    }
}

fn settings(plan: PlanFile) -> RenderSettings {
    let mut s = RenderSettings {
        width: 320,
        height: 180,
        heads: HEADS as u32,
        walk_heads: WALKED,
        assignment: Some(Assignment::Plan(plan)),
        ..RenderSettings::study()
    };
    s.light.azimuth_deg = AZIMUTH;
    s
}

/// Runs a command that must succeed, its standard error the message.
fn succeed(c: &mut std::process::Command) -> std::process::Output {
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn primitives(c: &Capture, pass: &str) -> u64 {
    c.samples
        .iter()
        .find(|p| p.name == pass)
        .and_then(|p| p.input_primitives)
        .unwrap_or_else(|| panic!("{pass}: no primitive count"))
}

#[test]
fn culled_casters_change_no_pixel_and_save_their_triangles() {
    let ctx = common::ctx();
    let scene = dermis::scene::default_scene();
    let every = Some(PlannedGeometry {
        level: 0,
        casts_shadow: true,
        triangles: None,
    });
    let mut culled = Renderer::new(&ctx, &scene, &settings(plan(None))).unwrap();
    let casts: Vec<bool> = culled
        .frame
        .geometry
        .iter()
        .map(|g| g.casts_shadow)
        .collect();
    let a = culled.capture(false).unwrap();
    drop(culled);
    let b = Renderer::new(&ctx, &scene, &settings(plan(every)))
        .unwrap()
        .capture(false)
        .unwrap();
    let n = casts.iter().filter(|&&c| c).count();
    eprintln!("{n} of {HEADS} characters cast");
    // The walk leaves characters whose shadows fall on nothing seen, and
    // the ones in view always cast.
    assert!((HEADS / 2..HEADS).contains(&n), "{casts:?}");
    // Not one pixel changes: the frame, the diffuse light, the depth.
    assert!(a.ldr == b.ldr, "the tone-mapped frame changed");
    assert!(a.diffuse == b.diffuse, "the diffuse light changed");
    assert!(a.depth == b.depth, "the depth changed");
    // The shadow map read the casters' triangles and no more: every
    // character draws the same meshes at level 0.
    let (pa, pb) = (primitives(&a, "shadow map"), primitives(&b, "shadow map"));
    assert_eq!(pb % HEADS as u64, 0, "{pb}");
    assert_eq!(pa, pb / HEADS as u64 * n as u64, "{pa} of {pb}");
    // The geometry pass is untouched.
    assert_eq!(primitives(&a, "geometry"), primitives(&b, "geometry"));
    // And the comparison means something: the culled characters do fall on
    // the shadow map (its depths differ), yet no pixel of the frame reads
    // where they fall.
    let map = |c: &Capture| {
        c.dumps
            .iter()
            .find(|d| d.pass == "shadow map")
            .map(|d| d.rgba.clone())
            .expect("the shadow map's dump")
    };
    let mut culled = Renderer::new(&ctx, &scene, &settings(plan(None))).unwrap();
    let a = culled.capture(true).unwrap();
    drop(culled);
    let b = Renderer::new(&ctx, &scene, &settings(plan(every)))
        .unwrap()
        .capture(true)
        .unwrap();
    assert!(map(&a) != map(&b), "the culled casters fall off the map");
    assert!(a.ldr == b.ldr);
}

/// `dermis plan` chooses every character's level and caster flag, and
/// `render --plan` draws them: the shadow map's and the geometry pass's
/// counted primitives are the plan's triangles (and the backdrop's).
#[test]
fn render_draws_the_plans_levels_and_casters() {
    let dir = tempfile::tempdir().unwrap();
    let frame = [
        "--heads",
        "16",
        "--view",
        "study",
        "--width",
        "320",
        "--height",
        "180",
        "--crowd-walked",
        "12",
        "--light-azimuth",
        "90",
    ];
    let plan_dir = dir.path().join("plan");
    let out = succeed(
        common::dermis()
            .args(["plan", "--profile", "xbox360", "--budget-ms", "2"])
            .args(frame)
            .args(["--lod-pixels", "1", "--out"])
            .arg(&plan_dir),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("cast onto a receiver in view"), "{stdout}");
    let file = PlanFile::load(&plan_dir.join("plan.json")).unwrap();
    let geometry: Vec<PlannedGeometry> = file
        .assignments
        .iter()
        .map(|a| {
            a.geometry
                .expect("the plan gives every character's geometry")
        })
        .collect();
    let tri = |g: &PlannedGeometry| g.triangles.unwrap();
    assert!(
        geometry.iter().any(|g| g.level > 0),
        "no character at a level"
    );
    assert!(
        geometry.iter().any(|g| !g.casts_shadow),
        "every character casts"
    );
    let render = |extra: &[&str], name: &str| -> serde_json::Value {
        let out_dir = dir.path().join(name);
        succeed(
            common::dermis()
                .arg("render")
                .args(frame)
                .args(extra)
                .args(["--frames", "1", "--warmup", "0", "--out"])
                .arg(&out_dir),
        );
        serde_json::from_slice(&std::fs::read(out_dir.join("report.json")).unwrap()).unwrap()
    };
    let prims = |r: &serde_json::Value, pass: &str| {
        r["passes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == pass)
            .and_then(|p| p["input_primitives"].as_u64())
            .unwrap_or_else(|| panic!("{pass}: no input_primitives"))
    };
    let plan_path = plan_dir.join("plan.json");
    let planned = render(&["--plan", plan_path.to_str().unwrap()], "planned");
    let casting: u64 = geometry.iter().filter(|g| g.casts_shadow).map(tri).sum();
    assert_eq!(prims(&planned, "shadow map"), casting);
    // The frame of full meshes (no plan) culls the same casters by the same
    // rule: its shadow map gives one full character's triangles, its
    // geometry pass those of 16 and the backdrop.
    let full = render(&[], "full");
    let casters = geometry.iter().filter(|g| g.casts_shadow).count() as u64;
    let shadow_full = prims(&full, "shadow map");
    assert_eq!(
        shadow_full % casters,
        0,
        "{shadow_full} over {casters} casters"
    );
    let full_character = shadow_full / casters;
    for g in geometry.iter().filter(|g| g.level == 0) {
        assert_eq!(tri(g), full_character);
    }
    let backdrop = prims(&full, "geometry") - HEADS as u64 * full_character;
    let drawn: u64 = geometry.iter().map(tri).sum();
    assert_eq!(prims(&planned, "geometry"), drawn + backdrop);
    assert!(drawn < HEADS as u64 * full_character);
}

/// A frame that would show none of its characters is refused with one
/// line before anything is written: a crowd walked past the camera.
#[test]
fn a_frame_with_no_character_in_view_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = common::dermis()
        .args(["render", "--heads", "4", "--crowd-walked", "200"])
        .args(["--width", "64", "--height", "36", "--out"])
        .arg(dir.path().join("r"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains("no character is in view"), "{err}");
    assert!(!dir.path().join("r").exists(), "something was written");
}
