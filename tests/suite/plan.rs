//! `dermis plan` and its cost model (issue 16, items 3 and 4), no device: the
//! per-character cost model reproduces `dermis budget`'s price of every stored
//! frame it was read from, its split is an upper bound within a measured
//! margin on every profile, the geometric skin estimate against lavapipe's
//! samples passed, a crowd's modelled cost against the priced frame of the
//! same crowd (frames no code of the planner produced), the plan's time for
//! 64 characters, and the command's one-line errors and its files, with no
//! Vulkan driver reachable.

use dermis::scene::gltf_load::fixture::TempDir;
use std::path::PathBuf;

use crate::common::{self, dermis};
use dermis::budget::frames::frames_dir;
use dermis::budget::model::{price_frame, Rescale};
use dermis::budget::params::ParamSet;
use dermis::budget::profile::{list_profiles, Profile};
use dermis::mix::plan_file::PlanFile;
use dermis::plan::choose::{plan, Accuracy, Ask};
use dermis::plan::cost::{reference_counts, CharacterLoad, CostModel, SettingModel};
use dermis::plan::pipeline::{
    characters, load_models, load_stored, plan_frames_dir, reference_setting, setting_costs,
};
use dermis::render::RenderSettings;
use dermis::scene::gltf_load::TextureOverrides;
use dermis::scene::load_gltf_scene;

fn tmp(name: &str) -> TempDir {
    dermis::scene::gltf_load::fixture::temp_dir(&format!("plan-{name}"))
}

fn models() -> Vec<SettingModel> {
    let (m, notes) = load_models().expect("the stored plan frames load");
    assert!(notes.is_empty(), "settings without frames: {notes:?}");
    m
}

fn reference(models: &[SettingModel]) -> &SettingModel {
    dermis::plan::pipeline::reference_model(models).unwrap()
}

/// The stored frame of the reference setting at `d` head heights.
fn reference_file(d: f64) -> PathBuf {
    let (rm, rs) = reference_setting().unwrap();
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(plan_frames_dir().join("index.json")).unwrap(),
    )
    .unwrap();
    let row = index["frames"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| {
            r["method"] == rm.as_str() && r["setting"] == rs.as_str() && r["distance_heads"] == d
        })
        .expect("a reference frame at every distance");
    plan_frames_dir().join(row["file"].as_str().unwrap())
}

/// `dermis plan` with no Vulkan driver to be found: whatever it does, it
/// cannot open a device.
fn plan_cmd(args: &[&str]) -> std::process::Output {
    dermis()
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .arg("plan")
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn command_errors_are_one_line_and_need_no_device() {
    let out = tmp("errors");
    let o = out.to_str().unwrap();
    for (args, want) in [
        (
            vec!["--profile", "xbox361", "--budget-ms", "2", "--out", o],
            "xbox361",
        ),
        (
            vec!["--profile", "xbox360", "--budget-ms", "0", "--out", o],
            "not a positive number",
        ),
        (
            vec!["--profile", "xbox360", "--budget-ms", "-1", "--out", o],
            "not a positive number",
        ),
        (
            vec!["--profile", "xbox360", "--budget-ms", "two", "--out", o],
            "is not a number",
        ),
        (
            vec!["--profile", "xbox360", "--budget-ms", "inf", "--out", o],
            "not a positive number",
        ),
        (
            vec![
                "--profile",
                "xbox360",
                "--budget-ms",
                "2",
                "--scene",
                "/nonexistent/head.glb",
                "--out",
                o,
            ],
            "/nonexistent/head.glb",
        ),
    ] {
        let r = plan_cmd(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        let last = err.lines().last().unwrap_or("");
        assert!(!r.status.success(), "{args:?} succeeded");
        assert!(
            last.starts_with("error: ") && last.contains(want),
            "{args:?}: {err}"
        );
        assert_eq!(
            err.lines().filter(|l| l.starts_with("error")).count(),
            1,
            "{args:?}: {err}"
        );
        assert!(!out.join("plan.json").exists(), "{args:?} wrote a plan");
    }
}

#[test]
fn a_plan_is_written_and_reads_back_as_a_mix_with_no_device() {
    let out = tmp("crowd");
    let r = plan_cmd(&[
        "--profile",
        "xbox360",
        "--budget-ms",
        "2",
        "--heads",
        "9",
        "--view",
        "study",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(
        r.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&r.stderr)
    );
    let p = PlanFile::load(&out.join("plan.json")).unwrap();
    assert_eq!(p.characters, 9);
    assert_eq!(p.profile.as_deref(), Some("xbox360"));
    assert!(p.predicted_ms.unwrap() <= 2.0 + 1e-9);
    let sum: f64 = p.assignments.iter().map(|a| a.predicted_ms.unwrap()).sum();
    assert!((sum - p.predicted_ms.unwrap()).abs() < 1e-6, "{sum}");
    for a in &p.assignments {
        assert!(a.setting.is_some() && a.px_per_mm.is_some() && a.skin_pixels.is_some());
        assert!(a.predicted_error.is_some());
    }
    assert!(!p.notes.is_empty());
    p.mix(9).unwrap();
    for f in ["plan.png", "plan.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(stdout.contains("skin-weighted err/none"), "{stdout}");
}

/// Each stored frame, priced by `dermis budget`'s model directly, and the
/// cost model's group of its one character (its exact counts) agree.
#[test]
fn the_cost_model_reproduces_every_stored_frame() {
    let models = models();
    let params = ParamSet::fitted();
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(plan_frames_dir().join("index.json")).unwrap(),
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for prof in ["xbox360", "switch-handheld", "steam-deck", "nvidia-h200"] {
        let prof = Profile::load(prof).unwrap();
        for row in index["frames"].as_array().unwrap() {
            let f = load_stored(&plan_frames_dir().join(row["file"].as_str().unwrap())).unwrap();
            let m = models
                .iter()
                .find(|m| m.method == row["method"] && m.setting == row["setting"])
                .unwrap();
            let d = row["distance_heads"].as_f64().unwrap();
            let x = 720.0 / (2.0 * 10f64.to_radians().tan() * 230.0 * d);
            // The reference frame at this distance gives the character's counts.
            let rf = load_stored(&reference_file(d)).unwrap();
            let r = reference_counts(&rf).unwrap();
            let load = CharacterLoad {
                px_per_mm: x,
                skin_pixels: r.skin,
                region_pixels: r.region,
                region_rects: r.rects,
            };
            let want = price_frame(&prof, &f, &params, Rescale::AsRun).sss_ms;
            let got = m
                .group_ms(&prof, &params, &[load], 1280, 720)
                .expect("priced");
            let rel = (got - want).abs() / want.max(1e-9);
            assert!(
                rel < 1e-3,
                "{} {} at {d}: model {got} ms, the stored frame {want} ms",
                m.method,
                m.setting
            );
            worst = worst.max(rel);
            n += 1;
        }
    }
    println!("{n} stored frames on 4 profiles: the model within {worst:.2e} of their price");
}

/// The 16-character crowd (study view) in one group, on every profile
/// and setting: the parts plus the fixed cost against the group's price.
/// Every unit time is linear in the counts and the max of sums is at most the
/// sum of maxes, so the parts bound the group from above, with one exception
/// the budget model makes: a depth-tested pass that passes no sample is
/// rejected at the hierarchical-Z rate, one that passes any at the per-pixel
/// rate, so a character whose LOD skips a Gaussian pass is cheaper alone than
/// in a group where another shades it. Both margins are printed and held
/// (over the study view's 16-character crowd, every profile and setting).
#[test]
fn the_split_against_the_group_within_a_measured_margin() {
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let refm = reference(&models);
    let crowd = RenderSettings {
        heads: 16,
        ..RenderSettings::study()
    };
    let loads: Vec<CharacterLoad> = characters(&scene, &crowd, refm)
        .iter()
        .map(dermis::plan::load_of)
        .collect();
    let mut over: (f64, String) = (0.0, String::new());
    let mut under: (f64, String) = (0.0, String::new());
    let mut n = 0;
    for name in list_profiles() {
        let prof = Profile::load(&name).unwrap();
        let cm = CostModel {
            profile: &prof,
            params: ParamSet::fitted(),
            width: 1280,
            height: 720,
        };
        for m in &models {
            let Some(s) = cm.split(m, &loads) else {
                continue;
            };
            n += 1;
            let e = (s.sum_ms() - s.total_ms) / s.total_ms.max(1e-12);
            let who = format!("{name} {} '{}'", m.method, m.setting);
            if e > over.0 {
                over = (e, who.clone());
            }
            if e < under.0 {
                under = (e, who);
            }
        }
    }
    println!(
        "16 characters, {n} profile x setting pairs: sum of parts + fixed is within \
         {:+.2}% ({}) and {:+.2}% ({}) of the group's price",
        100.0 * under.0,
        under.1,
        100.0 * over.0,
        over.1
    );
    assert!(n > 100, "{n}");
    // Measured: -5.2% (an ssg LOD pass, the hi-Z rule) to +6.0% (Poisson).
    assert!(over.0 < 0.07 && under.0 > -0.07, "{under:?} {over:?}");
}

fn lps_scene() -> Option<dermis::scene::Scene> {
    let p = common::lps_path()?;
    Some(load_gltf_scene(&p, &TextureOverrides::default(), None).unwrap())
}

/// The skin estimate of one head at the six stored distances against the
/// samples passed of lavapipe's frames.
#[test]
fn the_skin_estimate_against_lavapipe_counts() {
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let refm = reference(&models);
    let mut worst: f64 = 0.0;
    for d in [1.5, 3.0, 6.0, 12.0, 24.0, 48.0] {
        let s = RenderSettings {
            distance_heads: d,
            ..RenderSettings::study()
        };
        let c = &characters(&scene, &s, refm)[0];
        let f = load_stored(&reference_file(f64::from(d))).unwrap();
        let r = reference_counts(&f).unwrap();
        let e = c.skin_pixels / r.skin;
        println!(
            "{d:>5} head heights, {:.3} px/mm: estimate {:.0}, lavapipe {:.0} skin pixels ({:+.1}%)",
            c.px_per_mm,
            c.skin_pixels,
            r.skin,
            100.0 * (e - 1.0)
        );
        worst = worst.max((e - 1.0).abs());
    }
    assert!(worst < 1e-3, "{worst}");
}

/// docs/budget.md's 3- and 5-character crowd frames (rendered by `dermis
/// budget`, counts of lavapipe): their skin pixels and their priced skin-SSS
/// ms against the planner's estimate of the same crowd, every character
/// given the setting the frame rendered.
#[test]
fn a_crowd_predicted_against_its_priced_frame() {
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let refm = reference(&models);
    let params = ParamSet::fitted();
    let close = 0.5 / 10f64.to_radians().tan();
    let mut worst_cost: f64 = 0.0;
    for heads in [1u32, 3, 5] {
        for (shot, k) in [("close", 1.0), ("mid", 2.0), ("far", 5.0)] {
            let s = RenderSettings {
                heads,
                distance_heads: (close * k) as f32,
                ..RenderSettings::study()
            };
            let chars = characters(&scene, &s, refm);
            let f =
                load_stored(&frames_dir().join(format!("porting/h{heads}_{shot}_separable.json")))
                    .unwrap();
            let r = reference_counts(&f).unwrap();
            let est: f64 = chars.iter().map(|c| c.skin_pixels).sum();
            let loads: Vec<CharacterLoad> = chars.iter().map(dermis::plan::load_of).collect();
            let mut line = format!(
                "h{heads} {shot}: skin estimate {est:.0} vs {:.0} ({:+.1}%)",
                r.skin,
                100.0 * (est / r.skin - 1.0)
            );
            for p in ["xbox360", "steam-deck", "nvidia-h200"] {
                let prof = Profile::load(p).unwrap();
                let want = price_frame(&prof, &f, &params, Rescale::AsRun).sss_ms;
                let got = refm.group_ms(&prof, &params, &loads, 1280, 720).unwrap();
                let e = got / want - 1.0;
                worst_cost = worst_cost.max(e.abs());
                line.push_str(&format!(
                    "; {p} {got:.3} vs {want:.3} ms ({:+.1}%)",
                    100.0 * e
                ));
            }
            println!("{line}");
        }
    }
    println!("worst crowd cost error: {:.1}%", 100.0 * worst_cost);
    assert!(worst_cost < 0.15, "{worst_cost}");
}

/// A crowd whose characters' regions overlap: the 16-character crowd at 4
/// head heights (the H200 check's, key light 60/45) with ss-jittered on every
/// character, stored from `dermis budget` on lavapipe
/// (`profiles/frames/crowd/crowd16_ss-jittered.json`: the frame's own region,
/// 576 k pixels in 15 rectangles, built by the renderer, not by the planner).
/// Summed per character, the regions count 721 k pixels in 63 rectangles, and
/// the group over-prices the frame (measured: +26.8% on the H200, +10.6% on
/// the Xbox 360, +9.9% on the Steam Deck); merged as the frame draws them
/// (`Overlap`) it is within 8% on each (-5.5%, -7.7%, -4.4%: the reference
/// kernel's reach, wider than ss-jittered's, merges a little more than the
/// frame does) and closer than the sum.
#[test]
fn a_crowds_merged_regions_against_its_priced_frame() {
    use dermis::plan::cost::Overlap;
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let refm = reference(&models);
    let mut s = RenderSettings {
        heads: 16,
        distance_heads: 4.0,
        ..RenderSettings::default()
    };
    s.light.azimuth_deg = 60.0;
    s.light.elevation_deg = 45.0;
    let chars = characters(&scene, &s, refm);
    let f = load_stored(&frames_dir().join("crowd/crowd16_ss-jittered.json")).unwrap();
    let m = models
        .iter()
        .find(|m| m.method == "ss-jittered")
        .expect("ss-jittered's stored frames");
    let with_skin: Vec<_> = chars.iter().filter(|c| c.skin_pixels > 0.0).collect();
    let loads: Vec<CharacterLoad> = with_skin.iter().map(|c| dermis::plan::load_of(c)).collect();
    let regions: Vec<&[[u32; 4]]> = with_skin
        .iter()
        .map(|c| c.region_tiles.as_slice())
        .collect();
    let overlap = Overlap::of(&regions, s.width, s.height, s.sss_region_tile);
    println!("overlap of {} characters: {overlap:?}", loads.len());
    assert!(overlap.rects < 0.5 && overlap.pixels < 0.95, "{overlap:?}");
    let params = ParamSet::fitted();
    for p in ["nvidia-h200", "xbox360", "steam-deck"] {
        let prof = Profile::load(p).unwrap();
        let want = price_frame(&prof, &f, &params, Rescale::AsRun).sss_ms;
        let sum = m.group_ms(&prof, &params, &loads, 1280, 720).unwrap();
        let merged = m
            .group_ms(&prof, &params, &overlap.apply(&loads), 1280, 720)
            .unwrap();
        println!(
            "{p}: frame {want:.3} ms, regions summed {sum:.3} ({:+.1}%), merged {merged:.3} ({:+.1}%)",
            100.0 * (sum / want - 1.0),
            100.0 * (merged / want - 1.0)
        );
        assert!(
            (merged / want - 1.0).abs() < 0.08,
            "{p}: {merged} vs {want}"
        );
        assert!((merged - want).abs() < (sum - want).abs(), "{p}");
    }
}

/// A smooth synthetic accuracy model: error falls with px/mm for the
/// dearer settings, measured over 0.3-8 px/mm.
struct Smooth;
impl Accuracy for Smooth {
    fn predict(
        &self,
        method: &str,
        setting: &str,
        x: f64,
        _l: f64,
        _sh: f64,
    ) -> Option<(f64, f64)> {
        if !(0.3..=8.0).contains(&x) {
            return None;
        }
        let k = (method.len() + setting.len()) as f64 / 40.0;
        let e = (1.0 - k / (1.0 + 1.0 / x)).clamp(0.05, 0.98);
        Some((e, (e + 0.1).min(1.0)))
    }
}

/// The plan's time for 64 characters with the real cost model (printed):
/// estimating the characters and pricing every setting for each, and the
/// solver itself.
#[test]
fn plan_time_for_a_64_crowd() {
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let refm = reference(&models);
    let s = RenderSettings {
        heads: 64,
        ..RenderSettings::study()
    };
    for (p, budgets) in [
        ("xbox360", [1.0, 2.0, 4.0]),
        ("nvidia-h200", [0.25, 0.5, 1.0]),
    ] {
        let prof = Profile::load(p).unwrap();
        let t0 = std::time::Instant::now();
        let chars = characters(&scene, &s, refm);
        let costs = setting_costs(&models, &chars, &prof, 1280, 720, 500.0);
        let t1 = t0.elapsed().as_secs_f64() * 1e3;
        for b in budgets {
            let t = std::time::Instant::now();
            let plan = plan(&Ask {
                characters: &chars,
                settings: &costs,
                accuracy: &Smooth,
                budget_ms: b,
                previous: None,
                switch_margin: 0.0,
                node_limit: Some(dermis::plan::pipeline::NODE_LIMIT),
            });
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let sol = &plan.solution;
            println!(
                "64 characters on {p}, {b} ms: costs {t1:.1} ms, solve {ms:.2} ms ({} nodes, \
                 optimal {}), cost {:.3} ms, err/none {:.4}, bound {:.4}",
                sol.nodes,
                sol.optimal,
                sol.cost_ms,
                sol.error,
                sol.lower_bound.unwrap()
            );
            assert!(sol.cost_ms <= b + 1e-9);
        }
    }
}

/// `plan-check` on lavapipe at a small frame (issue 16 item 5's machinery;
/// the recorded check runs on the H200, docs/plan.md): no SSS scored against
/// itself is exactly 1 for every character (an invariant no code of the
/// planner produced), every plan fits its budget, the timed case times each
/// group alone, and the outputs are written.
#[test]
fn plan_check_scores_plans_against_the_ground_truth() {
    use dermis::app::plan_check::{check, CheckOptions};
    use dermis::budget::profile::Profile;
    use dermis::plan::check::{parse_cases, pick_scenes};
    use dermis::plan::measured::Measured;
    let ctx = common::ctx();
    let scene = dermis::scene::builtin_scene("face", &TextureOverrides::default(), None).unwrap();
    let mut base = RenderSettings::study();
    base.width = 160;
    base.height = 90;
    base.options.set("density", "1");
    let acc = Measured::load_default(Measured::asset_of(None)).unwrap();
    let out = tmp("check");
    let profile = |p: &str| (p.to_string(), Profile::load(p).unwrap());
    let r = check(
        &ctx,
        &CheckOptions {
            base,
            scene: &scene,
            accuracy: &acc,
            accuracy_source: acc.source(),
            scenes: pick_scenes("grid").unwrap(),
            cases: parse_cases("xbox360:2,nvidia-h200:0.5").unwrap(),
            profiles: vec![profile("xbox360"), profile("nvidia-h200")],
            timed_frames: 1,
            timed_profile: Some("nvidia-h200".into()),
            out: &out,
        },
    )
    .unwrap();
    assert_eq!(r.cases.len(), 2);
    for c in &r.cases {
        assert!(c.predicted_ms <= c.budget_ms + 1e-9, "{c:?}");
        assert!(c.measured_error.is_finite() && c.best_uniform_error.is_finite());
        assert_eq!(c.characters.len(), 16);
        // No SSS scored against itself: every character with a band is 1.
        for ch in c.characters.iter().filter(|ch| ch.setting == "none") {
            if ch.measured.interior.is_some() || ch.measured.silhouette.is_some() {
                assert!((ch.measured.error - 1.0).abs() < 1e-12, "{ch:?}");
            }
        }
        let timed = c.profile == "nvidia-h200";
        assert_eq!(c.measured_sss_ms.is_some(), timed);
        // The plan's frame is timed before and after its parts; the lower is kept.
        assert_eq!(c.measured_sss_runs_ms.len(), if timed { 2 } else { 0 });
        if let Some(m) = c.measured_sss_ms {
            let low = c
                .measured_sss_runs_ms
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            assert_eq!(m, low, "{c:?}");
        }
        let groups = c.plan_groups.iter().filter(|g| *g != "none").count();
        assert_eq!(
            c.parts_sss_ms.len(),
            if timed { groups } else { 0 },
            "{c:?}"
        );
    }
    let none = r.uniform[0].1.iter().find(|u| u.method == "none");
    assert!(
        none.is_none(),
        "none is the floor of every case, not a uniform row"
    );
    for f in [
        "plan-check.json",
        "plan-check.md",
        "error-vs-budget-xbox360.png",
        "error-vs-budget-nvidia-h200.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    // plan-check.json reads back typed, with its run header.
    let back: dermis::plan::check::CheckReport =
        serde_json::from_slice(&std::fs::read(out.join("plan-check.json")).unwrap()).unwrap();
    assert_eq!(back.cases.len(), 2);
    assert_eq!(back.run.width, 160);
    assert_eq!(back.timed_profile.as_deref(), Some("nvidia-h200"));
    assert_eq!(
        pick_scenes("crowd16,nope")
            .unwrap_err()
            .to_string()
            .lines()
            .count(),
        1
    );
    assert!(parse_cases("xbox360:-1").is_err() && parse_cases("xbox360").is_err());
}

/// Issue 28 item 5: each setting of a method with a compute path is offered on
/// both paths. The compute twin is priced from its own stored frames (its
/// dispatches, not its fragment twin's passes), takes its fragment twin's
/// accuracy rows, and is unpriced, so never chosen, on a profile without
/// compute; on the H100 the two twins of a setting cost differently.
#[test]
fn a_plan_chooses_the_path_per_group_where_the_profile_has_compute() {
    let Some(scene) = lps_scene() else { return };
    let models = models();
    let twins: Vec<&SettingModel> = models.iter().filter(|m| m.needs_compute).collect();
    // separable 5, ssg 3 (its branch mask has none), ss-jittered 1, poisson 1.
    assert_eq!(
        twins.len(),
        10,
        "{:?}",
        twins.iter().map(|m| &m.setting).collect::<Vec<_>>()
    );
    for t in &twins {
        let frag = models
            .iter()
            .find(|m| m.method == t.method && m.setting == t.eval)
            .unwrap_or_else(|| panic!("{} '{}' has no fragment twin", t.method, t.setting));
        assert!(!frag.needs_compute);
        assert_ne!(t.setting, frag.setting);
    }
    let refm = reference(&models);
    let s = RenderSettings {
        heads: 4,
        ..RenderSettings::study()
    };
    let chars = characters(&scene, &s, refm);
    for (p, has_compute) in [
        ("xbox360", false),
        ("ps3", false),
        ("nvidia-h100", true),
        ("switch-docked", true),
    ] {
        let prof = Profile::load(p).unwrap();
        let costs = setting_costs(&models, &chars, &prof, 1280, 720, 500.0);
        let compute: Vec<_> = costs
            .iter()
            .filter(|c| c.setting.ends_with(", compute"))
            .collect();
        assert_eq!(compute.len(), if has_compute { 10 } else { 0 }, "{p}");
        for c in &compute {
            let frag = costs
                .iter()
                .find(|f| f.method == c.method && f.setting == c.measured_as)
                .expect("the fragment twin is priced too");
            assert_eq!(frag.measured_as, c.measured_as);
            assert!(
                (c.fixed_ms - frag.fixed_ms).abs() > 1e-6,
                "{p} {} '{}': the twins cost alike, as if priced from one frame",
                c.method,
                c.setting
            );
        }
    }
}
