//! `dermis plan-check`: plans checked against the ground truth, not assumed
//! (`plan::check` says how, and holds the record and its summary). For each
//! scene and (profile, budget) it plans, renders the plan, the ground truth
//! and every uniform assignment that fits, scores them, and with
//! `--timed-frames` times the plans of `--timed-profile` on this device.
//! Every frame the check renders is checked before the device opens.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};

use super::cli::PlanCheckArgs;
use super::request::{self, Given};
use super::truth::{render, render_truth, truth_settings, with_method};
use crate::budget::profile::Profile;
use crate::header::{command_line, RunHeader};
use crate::mix::plan_file::PlanFile;
use crate::output::paths::OutputPaths;
use crate::output::write_json;
use crate::plan::character::CharacterInput;
use crate::plan::check::{
    cases, group_parts, markdown, parse_cases, pick_scenes, summarise, CaseCharacter, CaseRow,
    CheckReport, CheckScene, Summary, Uniform,
};
use crate::plan::choose::{Accuracy, Ask, SettingCosts};
use crate::plan::cost::SettingModel;
use crate::plan::measured::Measured;
use crate::plan::pipeline::{
    atlas_mm, characters, load_models, plan_file, plan_refilled, reference_model, registered,
    setting_costs, NODE_LIMIT,
};
use crate::plan::score::FrameError;
use crate::render::request::CheckedSettings;
use crate::render::settings::Assignment;
use crate::render::{FrameRequest, RenderSettings, Renderer};
use crate::report::device_header;
use crate::scene::Scene;
use crate::vk::context::Context;
use crate::work::PassRole;

/// The files plan-check writes into its folder (its charts beside them).
const FILES: [&str; 2] = ["plan-check.json", "plan-check.md"];

/// Most frames timed per plan (each keeps its pass samples until its
/// median is taken).
pub const MAX_TIMED_FRAMES: usize = crate::ranges::MAX_MEASURED_FRAMES;

/// `dermis plan-check`: every argument and every frame the check renders
/// checked (one line each) before the device opens.
pub fn run(a: &PlanCheckArgs, given: &Given) -> Result<()> {
    let scenes = pick_scenes(&a.scenes)?;
    let cases = match &a.cases {
        Some(c) => parse_cases(c)?,
        None => cases()?,
    };
    if a.timed_frames > MAX_TIMED_FRAMES {
        bail!(
            "--timed-frames must be within 0..={MAX_TIMED_FRAMES}, got {}",
            a.timed_frames
        );
    }
    let timed_profile = match (&a.timed_profile, a.timed_frames) {
        (Some(p), _) => {
            // A named profile that does not exist is an error, not a case
            // that never matches.
            Profile::load(p).with_context(|| format!("--timed-profile {p}"))?;
            if !cases.iter().any(|(c, _)| c == p) {
                bail!("--timed-profile {p} is the profile of none of the cases");
            }
            Some(p.clone())
        }
        (None, 0) => None,
        (None, _) => bail!(
            "--timed-frames {} needs --timed-profile: the profile of the device the check runs on (whose predictions the timings check)",
            a.timed_frames
        ),
    };
    let mut profiles: Vec<(String, Profile)> = Vec::new();
    for (p, _) in &cases {
        if !profiles.iter().any(|(n, _)| n == p) {
            profiles.push((
                p.to_string(),
                Profile::load(p).with_context(|| format!("--cases: profile {p}"))?,
            ));
        }
    }
    let (source, base) = request::frame_settings(&a.frame, given)?;
    // The base frame's numbers before the scene loads.
    let base = CheckedSettings::new(base)?.get().clone();
    let scene = request::load_scene(&source)?;
    for cs in &scenes {
        check_frames(&scene, &settings_for(&base, cs))
            .with_context(|| format!("scene {}", cs.name))?;
    }
    let acc = Measured::load_default(Measured::asset_of(source.gltf()))?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[])
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let o = CheckOptions {
        base,
        scene: &scene,
        accuracy: &acc,
        accuracy_source: acc.source(),
        scenes,
        cases,
        profiles,
        timed_frames: a.timed_frames,
        timed_profile,
        out: &a.out,
    };
    let r = check(&ctx, &o);
    let r = ctx.finish_with(r)?;
    print!("{}", markdown(&r));
    println!("wrote {}", a.out.join("plan-check.json").display());
    Ok(())
}

/// Every frame a scene of the check renders, checked: the scene's own, its
/// ground truth and no SSS, and every registered uniform setting.
fn check_frames(scene: &Scene, s: &RenderSettings) -> Result<()> {
    FrameRequest::new(scene, s.clone())?;
    FrameRequest::new(scene, truth_settings(s)?).context("the ground truth")?;
    FrameRequest::new(scene, with_method(s, crate::method::none().name, &[])?).context("no SSS")?;
    for r in registered() {
        let opts: Vec<(String, String)> = r.options.clone().into_iter().collect();
        FrameRequest::new(scene, with_method(s, r.method, &opts)?)
            .with_context(|| format!("uniform {} {}", r.method, r.setting))?;
    }
    Ok(())
}

/// What a plan renders: every character's method and options.
type PlanKey = Vec<(String, std::collections::BTreeMap<String, String>)>;

/// What the check needs besides the device.
pub struct CheckOptions<'a> {
    pub base: RenderSettings,
    pub scene: &'a Scene,
    pub accuracy: &'a dyn Accuracy,
    pub accuracy_source: String,
    pub scenes: Vec<CheckScene>,
    pub cases: Vec<(String, f64)>,
    /// Every profile of the cases, loaded.
    pub profiles: Vec<(String, Profile)>,
    /// Frames timed per plan (0: no timing, as on lavapipe), for the cases
    /// of `timed_profile` (the profile of the device the check runs on: the
    /// other profiles' predictions are not about it).
    pub timed_frames: usize,
    pub timed_profile: Option<String>,
    pub out: &'a Path,
}

fn settings_for(base: &RenderSettings, s: &CheckScene) -> RenderSettings {
    let mut r = base.clone();
    r.heads = s.heads;
    r.layout = s.layout;
    if let Some(d) = s.distance_heads {
        r.distance_heads = d;
    }
    r.assignment = None;
    r.character_ids = false;
    r
}

/// Frames rendered before timing.
pub const WARMUP_FRAMES: usize = 30;

/// Median skin-SSS ms (and of it the merges) over `n` timed frames after a warm-up.
fn time_sss(ctx: &Context, scene: &Scene, s: &RenderSettings, n: usize) -> Result<(f64, f64)> {
    let mut r = Renderer::new(ctx, scene, s)?;
    // Enough frames for the clocks to come up: the first timed case of the
    // first H200 check ran at 5x its group's time alone with 3.
    r.run_frames(WARMUP_FRAMES, |_| {})?;
    let (frames, _) = r.frames_timed(n, |_| {})?;
    let mut sss: Vec<f64> = Vec::new();
    let mut merge: Vec<f64> = Vec::new();
    for f in &frames {
        let on = f.iter().filter(|p| p.role == PassRole::Sss);
        sss.push(on.clone().map(|p| p.gpu_ms).sum());
        merge.push(on.filter(|p| p.merge).map(|p| p.gpu_ms).sum());
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        // An empty sum of f64 is -0.0: printed as 0.
        crate::report::median_of_sorted(v) + 0.0
    };
    Ok((med(&mut sss), med(&mut merge)))
}

/// The run with the lower skin-SSS median, with its merges: of two timings
/// of one frame, the one a transient (clocks, another process) did not slow.
fn lower_run(runs: &[(f64, f64)]) -> Option<(f64, f64)> {
    runs.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0))
}

/// A setting's modelled cost for every character with it: its fixed cost and
/// every part (`None` where a part is unpriced).
fn uniform_ms(c: &SettingCosts) -> Option<f64> {
    let parts: Option<Vec<f64>> = c.parts_ms.iter().copied().collect();
    parts.map(|p| c.fixed_ms + p.iter().sum::<f64>())
}

/// Runs the check and writes DIR/plan-check.json, DIR/plan-check.md and the
/// charts (DIR/error-vs-budget-PROFILE.png and .svg).
/// Long because one scene's truth, uniform renders and cases share its
/// characters and costs, and the outputs are rewritten after every scene.
pub fn check(ctx: &Context, o: &CheckOptions) -> Result<CheckReport> {
    let (models, _) = load_models()?;
    let reference: &SettingModel = reference_model(&models)?;
    let profiles = &o.profiles;
    let atlas = atlas_mm(o.scene);
    let mut report = CheckReport {
        run: RunHeader::new(
            &command_line(),
            device_header(ctx),
            (o.base.width, o.base.height),
            (
                WARMUP_FRAMES * usize::from(o.timed_frames > 0),
                o.timed_frames,
            ),
        ),
        timed_profile: o.timed_profile.clone(),
        accuracy: o.accuracy_source.clone(),
        scenes: o.scenes.clone(),
        uniform: Vec::new(),
        cases: Vec::new(),
        summary: Summary::default(),
    };
    let none = crate::method::none().name;
    let progress = indicatif::ProgressBar::new(o.scenes.len() as u64);
    for cs in &o.scenes {
        progress.set_message(cs.name.clone());
        let s = settings_for(&o.base, cs);
        let chars: Vec<CharacterInput> = characters(o.scene, &s, reference);
        let costs: Vec<(String, Vec<SettingCosts>)> = profiles
            .iter()
            .map(|(n, p)| {
                (
                    n.clone(),
                    setting_costs(&models, &chars, p, s.width, s.height, atlas),
                )
            })
            .collect();
        let truth =
            render_truth(ctx, o.scene, &s).with_context(|| format!("{}: ground truth", cs.name))?;
        // Uniform assignments: every registered setting, rendered where it
        // fits one of the budgets.
        let biggest = |p: &str| {
            o.cases
                .iter()
                .filter(|(q, _)| *q == p)
                .map(|(_, b)| *b)
                .fold(0.0, f64::max)
        };
        let mut uniforms = Vec::new();
        for r in registered() {
            let modelled: Vec<(String, Option<f64>)> = costs
                .iter()
                .map(|(p, c)| {
                    let ms = c
                        .iter()
                        .find(|x| x.method == r.method && x.setting == r.setting)
                        .and_then(uniform_ms);
                    (p.clone(), ms)
                })
                .collect();
            let fits_some = modelled
                .iter()
                .any(|(p, ms)| ms.is_some_and(|m| m <= biggest(p)));
            let (measured, per_character) = if fits_some {
                let opts: Vec<(String, String)> = r.options.clone().into_iter().collect();
                let f = render(ctx, o.scene, &with_method(&s, r.method, &opts)?)
                    .with_context(|| format!("{}: uniform {} {}", cs.name, r.method, r.setting))?;
                let e = truth.score(&f.diffuse)?;
                (Some(e.weighted), e.characters)
            } else {
                (None, Vec::new())
            };
            uniforms.push(Uniform {
                method: r.method.to_string(),
                setting: r.setting.to_string(),
                modelled_ms: modelled,
                measured,
                characters: per_character,
            });
        }
        let none_err = truth.score(&truth.none)?.weighted;
        // Cases often plan the same frame (a budget every setting fits): each
        // distinct assignment is rendered and scored once.
        let mut scored_plans: Vec<(PlanKey, FrameError)> = Vec::new();
        for (pname, budget) in &o.cases {
            let (pname, budget) = (pname.as_str(), *budget);
            let c = &costs.iter().find(|(n, _)| n == pname).expect("priced").1;
            let t0 = Instant::now();
            let prof = &profiles.iter().find(|(n, _)| n == pname).expect("loaded").1;
            let p = plan_refilled(
                &Ask {
                    characters: &chars,
                    settings: c,
                    accuracy: o.accuracy,
                    budget_ms: budget,
                    previous: None,
                    switch_margin: 0.0,
                    node_limit: Some(NODE_LIMIT),
                },
                c,
                &models,
                prof,
                (s.width, s.height, s.sss_region_tile),
            );
            let solve_ms = t0.elapsed().as_secs_f64() * 1e3;
            let file: PlanFile = plan_file(pname, budget, &chars, c, &p, Vec::new())?;
            let mut ps = s.clone();
            ps.assignment = Some(Assignment::Plan(file.clone()));
            let key: PlanKey = file
                .assignments
                .iter()
                .map(|a| (a.method.clone(), a.options.clone()))
                .collect();
            let scored = match scored_plans.iter().find(|(k, _)| *k == key) {
                Some((_, e)) => e.clone(),
                None => {
                    let f = render(ctx, o.scene, &ps)
                        .with_context(|| format!("{}: plan {pname} {budget} ms", cs.name))?;
                    let e = truth.score(&f.diffuse)?;
                    scored_plans.push((key, e.clone()));
                    e
                }
            };
            let measured = scored.weighted;
            let case_chars: Vec<CaseCharacter> = p
                .rows
                .iter()
                .zip(&chars)
                .zip(&scored.characters)
                .map(|((row, ch), m)| CaseCharacter {
                    character: ch.index,
                    px_per_mm: ch.px_per_mm,
                    light_deg: ch.light_deg,
                    shadow_mm: ch.shadow_mm,
                    setting: row.setting.map_or(none.to_string(), |si| {
                        format!("{} {}", c[si].method, c[si].setting)
                    }),
                    predicted_interior: row.predicted.0,
                    predicted_silhouette: row.predicted.1,
                    predicted_silhouette_share: ch.silhouette_share,
                    measured: *m,
                })
                .collect();
            let (mut best, mut best_err, mut fitting) = (none.to_string(), none_err, 1);
            for u in &uniforms {
                let fits = u
                    .modelled_ms
                    .iter()
                    .any(|(q, ms)| q == pname && ms.is_some_and(|m| m <= budget));
                if let (true, Some(e)) = (fits, u.measured) {
                    fitting += 1;
                    if e < best_err {
                        best_err = e;
                        best = format!("{} {}", u.method, u.setting);
                    }
                }
            }
            let timed = o.timed_frames > 0 && Some(pname) == o.timed_profile.as_deref();
            let mut runs: Vec<(f64, f64)> = Vec::new();
            let mut parts_sss_ms = Vec::new();
            if timed {
                runs.push(time_sss(ctx, o.scene, &ps, o.timed_frames)?);
                for (label, alone) in group_parts(&file) {
                    let mut gs = s.clone();
                    gs.assignment = Some(Assignment::Plan(alone));
                    parts_sss_ms.push((label, time_sss(ctx, o.scene, &gs, o.timed_frames)?.0));
                }
                runs.push(time_sss(ctx, o.scene, &ps, o.timed_frames)?);
            }
            let measured_sss_runs_ms: Vec<f64> = runs.iter().map(|r| r.0).collect();
            let (measured_sss_ms, measured_merge_ms) = match lower_run(&runs) {
                Some((a, b)) => (Some(a), Some(b)),
                None => (None, None),
            };
            let mut groups: Vec<String> = Vec::new();
            for a in &file.assignments {
                let l = match (a.method.as_str(), &a.setting) {
                    (m, Some(s)) if m != none => format!("{m} {s}"),
                    _ => a.method.clone(),
                };
                if !groups.contains(&l) {
                    groups.push(l);
                }
            }
            report.cases.push(CaseRow {
                scene: cs.name.to_string(),
                profile: pname.to_string(),
                budget_ms: budget,
                plan_groups: groups,
                predicted_ms: p.solution.cost_ms,
                predicted_error: p.solution.error,
                lower_bound: p.solution.lower_bound,
                optimal: p.solution.optimal,
                plan_ms_to_solve: solve_ms,
                measured_error: measured,
                best_uniform: best,
                best_uniform_error: best_err,
                uniform_fitting: fitting,
                measured_sss_ms,
                measured_merge_ms,
                measured_sss_runs_ms,
                parts_sss_ms,
                characters: case_chars,
            });
        }
        report.uniform.push((cs.name.to_string(), uniforms));
        // Written after every scene: a long check cut short keeps what it did.
        report.summary = summarise(&report.cases, o.timed_profile.as_deref());
        write_outputs(o.out, &report)?;
        progress.inc(1);
    }
    progress.finish_and_clear();
    Ok(report)
}

fn write_outputs(out: &Path, report: &CheckReport) -> Result<()> {
    write_json(&out.join("plan-check.json"), report)?;
    crate::output::write_bytes(&out.join("plan-check.md"), markdown(report).as_bytes())?;
    let points: Vec<crate::plan::check_chart::Point> = report
        .cases
        .iter()
        .map(|c| crate::plan::check_chart::Point {
            profile: c.profile.clone(),
            scene: c.scene.clone(),
            budget_ms: c.budget_ms,
            plan: c.measured_error,
            uniform: c.best_uniform_error,
        })
        .collect();
    let scenes: Vec<String> = report.scenes.iter().map(|s| s.name.to_string()).collect();
    crate::plan::check_chart::write(out, &scenes, &points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn of_two_timings_the_lower_is_kept_with_its_merges() {
        assert_eq!(lower_run(&[]), None);
        assert_eq!(
            lower_run(&[(0.352, 0.0), (0.209, 0.001)]),
            Some((0.209, 0.001))
        );
        assert_eq!(lower_run(&[(0.20, 0.02), (0.21, 0.0)]), Some((0.20, 0.02)));
    }
}
