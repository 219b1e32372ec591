//! The cross-fade of a character switching settings (issue 16 item 6,
//! render/groups/fade.rs `FadeMethod`, render/groups/merge.rs): on lavapipe with
//! validation, a fading character's diffuse light is `w * old + (1 - w) *
//! new` of the single-method frames of its two settings, to the rounding of
//! the half-float blend; its old setting's passes and the blend pass exactly
//! its skin pixels; uniform light goes out as it came in (a physical
//! invariant no frame of ours produced: every method's kernel loses no light);
//! a bad fade in a plan file is one line before any device opens.

use std::collections::BTreeMap;

use crate::common;

use dermis::mix::assign::parse_choice;
use dermis::mix::plan_file::{PlanFile, PlannedCharacter, PlannedFade, PLAN_VERSION};
use dermis::render::settings::Assignment;
use dermis::render::{Capture, RenderSettings, Renderer};
use dermis::scene::default_scene;

fn one_head() -> RenderSettings {
    RenderSettings {
        width: 160,
        height: 90,
        heads: 1,
        shadow_size: 512,
        character_ids: true,
        ..RenderSettings::study()
    }
}

/// One character with `to`, fading from `from` at `weight`.
fn fading(to: &str, from: &str, weight: f64) -> RenderSettings {
    let (to, from) = (parse_choice(to).unwrap(), parse_choice(from).unwrap());
    let plan = PlanFile {
        version: PLAN_VERSION,
        profile: None,
        budget_ms: None,
        characters: 1,
        assignments: vec![PlannedCharacter {
            character: 0,
            method: to.method.clone(),
            options: to.options.clone(),
            setting: None,
            px_per_mm: None,
            skin_pixels: None,
            predicted_ms: None,
            predicted_error: None,
            geometry: None,
            fade: Some(PlannedFade {
                method: from.method.clone(),
                options: from.options.clone(),
                weight,
            }),
        }],
        predicted_ms: None,
        predicted_error: None,
        notes: Vec::new(),
        run: None,
    };
    plan.check().expect("a good plan");
    RenderSettings {
        assignment: Some(Assignment::Plan(plan)),
        ..one_head()
    }
}

fn single(choice: &str) -> RenderSettings {
    let c = parse_choice(choice).unwrap();
    RenderSettings {
        method: c.entry().unwrap(),
        options: c.method_options(),
        ..one_head()
    }
}

/// The spacing of half floats at `v` (normal range; the subnormal spacing below).
fn half_ulp(v: f32) -> f32 {
    let a = v.abs().max(6.1e-5);
    2f32.powi(a.log2().floor() as i32 - 10)
}

fn capture(s: &RenderSettings) -> Capture {
    let ctx = common::ctx();
    let mut r = Renderer::new(&ctx, &default_scene(), s).expect("renderer");
    r.capture(false).expect("frame")
}

/// The fades: (new, old, old's weight). From no SSS the old result is the
/// keep itself; to no SSS the new one is the light before SSS; poisson's
/// result lies apart (merged before the blend) and it builds its mip chain
/// on the keep; texture-space diffusion draws its result into the keep from
/// its own maps.
const CASES: [(&str, &str, f64); 5] = [
    ("separable:preset=physical", "ssg", 0.25),
    ("ssg", "none", 0.5),
    ("none", "ss-jittered", 0.75),
    ("separable", "poisson", 0.5),
    ("ssg:fit=4", "tsd-opt:irradiance-size=256", 0.5),
];

#[test]
fn a_fading_character_is_the_weighted_mix_of_its_two_settings() {
    let mut frames: BTreeMap<&str, Capture> = BTreeMap::new();
    for (to, from, _) in CASES {
        for c in [to, from] {
            if !frames.contains_key(c) {
                frames.insert(c, capture(&single(c)));
            }
        }
    }
    for (to, from, w) in CASES {
        let cap = capture(&fading(to, from, w));
        let ids = cap.character_ids.clone().unwrap();
        let (new, old) = (&frames[to], &frames[from]);
        assert_eq!(new.character_ids.as_ref().unwrap(), &ids, "same pixels");
        let mut worst = 0.0f32;
        let mut n = 0;
        for i in (0..ids.len()).filter(|&i| ids[i] == 1) {
            n += 1;
            for k in 0..3 {
                let want = w as f32 * old.diffuse[i][k] + (1.0 - w as f32) * new.diffuse[i][k];
                let got = cap.diffuse[i][k];
                worst = worst.max((got - want).abs() / half_ulp(want));
            }
        }
        assert!(n > 1000, "{n} skin pixels");
        // The blend unit works at the target's precision: each of its two
        // products and their sum may round, by at most half an ulp each.
        assert!(
            worst <= 1.5,
            "{from} -> {to} at {w}: {worst} half-float ulps off the weighted mix"
        );
        eprintln!(
            "{from} -> {to} at {w}: {n} skin pixels within {worst:.2} half-float ulps of the \
             weighted mix"
        );
        // The old setting's stencil-masked passes and the blend pass the
        // character's skin pixels, and nothing else.
        let skin = n as u64;
        assert_eq!(common::samples_passed(&cap.samples, "#0 fade blend"), skin);
        let names: Vec<&str> = cap.samples.iter().map(|p| p.name.as_str()).collect();
        let keep = names
            .iter()
            .position(|&p| p == "#0 fade keep")
            .expect("keep");
        let first_sss = names
            .iter()
            .position(|p| p.starts_with("#0 ") && !p.starts_with("#0 fade"));
        if let Some(first) = first_sss {
            assert!(
                keep < first,
                "the keep comes before the new setting's passes: {names:?}"
            );
        }
        // Every pass of the old setting passes what the same pass of its own
        // frame passes (the stencil and the depth LOD's test alike).
        let mut compared = 0;
        for p in cap.samples.iter() {
            let Some(name) = p.name.strip_prefix("#0 fade ") else {
                continue;
            };
            if name == "keep" || name == "blend" {
                continue;
            }
            assert_eq!(
                p.samples_passed,
                common::samples_passed(&old.samples, name),
                "{}: against {from}'s own frame",
                p.name
            );
            compared += 1;
        }
        assert_eq!(compared > 0, from != "none", "{from}: {names:?}");
    }
}

/// Uniform light (white skin, ambient only, no key light): every method's
/// kernel sums to one, so away from the silhouette each returns its input,
/// and so must a fade between two of them. Held on the skin pixels with no
/// background pixel within 6 pixels, against the frame with no SSS (the
/// light before SSS): median |out/in - 1| within 0.2%, the largest within
/// 0.5% (measured: at most 0.001, two half-float steps at 1.0).
/// A fade whose keep were not copied (the old setting blurring zeros) or
/// whose blend lost its weight would be off by the weight's share.
#[test]
fn a_fade_returns_uniform_light_as_it_came_in() {
    let ctx = common::ctx();
    let mut scene = default_scene();
    scene.head.material.base_color = None;
    scene.head.material.base_color_factor = [1.0; 3];
    let white = |mut s: RenderSettings| {
        s.ambient = 1.0;
        s.light.intensity = 0.0;
        s
    };
    let diffuse = |s: &RenderSettings| {
        let mut r = Renderer::new(&ctx, &scene, s).expect("renderer");
        r.capture(false).expect("frame")
    };
    let input = diffuse(&white(single("none")));
    let (w, h) = (input.width as usize, input.height as usize);
    let skin: Vec<bool> = input.diffuse.iter().map(|p| p[3] > 0.0).collect();
    let interior: Vec<usize> = (0..w * h)
        .filter(|&i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            (-6..=6i64).all(|dy| {
                (-6..=6i64).all(|dx| {
                    let (xx, yy) = (x + dx, y + dy);
                    xx >= 0
                        && yy >= 0
                        && xx < w as i64
                        && yy < h as i64
                        && skin[yy as usize * w + xx as usize]
                })
            })
        })
        .collect();
    assert!(interior.len() > 300, "{} interior pixels", interior.len());
    for (to, from, wgt) in CASES {
        let out = diffuse(&white(fading(to, from, wgt)));
        let mut q: Vec<f64> = interior
            .iter()
            .flat_map(|&i| (0..3).map(move |c| (i, c)))
            .map(|(i, c)| (out.diffuse[i][c] as f64 / input.diffuse[i][c] as f64 - 1.0).abs())
            .collect();
        q.sort_by(f64::total_cmp);
        let (median, max) = (q[q.len() / 2], q[q.len() - 1]);
        eprintln!(
            "{from} -> {to} at {wgt}, uniform light over {} interior pixels: |out/in - 1| \
             median {median:.5}, max {max:.5}",
            interior.len()
        );
        assert!(
            median < 0.002 && max < 0.005,
            "{from} -> {to}: median {median}, max {max}"
        );
    }
}

/// `render --plan` with a fade the registry or the frame refuses: one line,
/// before any device opens.
#[test]
fn a_bad_fade_is_one_line_before_any_device_opens() {
    let dir = dermis::scene::gltf_load::fixture::temp_dir("fade-plans");
    std::fs::create_dir_all(&dir).unwrap();
    let plan = |fade: &str| {
        format!(
            r#"{{"version":1,"characters":1,"assignments":[
            {{"character":0,"method":"separable","fade":{fade}}}]}}"#
        )
    };
    for (name, fade, phrase) in [
        (
            "weight",
            r#"{"method":"ssg","weight":1}"#,
            "fade weight 1 is not a share strictly between 0 and 1",
        ),
        (
            "method",
            r#"{"method":"ssgg","weight":0.5}"#,
            "unknown method 'ssgg'",
        ),
        (
            "same",
            r#"{"method":"separable","options":{"samples":"17"},"weight":0.5}"#,
            "fades from separable:samples=17 to the same setting",
        ),
        (
            "field",
            r#"{"method":"ssg","weight":0.5,"frames":3}"#,
            "unknown field",
        ),
        (
            "branch",
            r#"{"method":"ssg","options":{"mask":"branch"},"weight":0.5}"#,
            "needs mask=stencil",
        ),
    ] {
        let p = dir.join(format!("{name}.json"));
        std::fs::write(&p, plan(fade)).unwrap();
        let o = common::dermis()
            .args(["render", "--device", "no-such-device-opens", "--heads", "1"])
            .args(["--frames", "1", "--warmup", "0", "--plan"])
            .arg(&p)
            .arg("--out")
            .arg(dir.join("out"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{name} succeeded");
        assert_ne!(o.status.code(), Some(101), "{name} panicked: {stderr}");
        let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
        assert_eq!(errors.len(), 1, "{name}: {stderr}");
        assert!(errors[0].contains(phrase), "{name}: {stderr}");
        assert!(
            !stderr.contains("no-such-device"),
            "a device was looked for: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
