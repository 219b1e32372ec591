//! `dermis plan-motion`: a crowd walking toward a fixed camera re-planned
//! every frame with hysteresis, each frame rendered with its plan and its
//! ground truth, every switch measured (`plan::motion` says how and holds
//! the record). Every argument, and every frame's settings, checked before
//! the device opens; the folder's plans/ holds this run's frames only.

use std::path::Path;

use anyhow::{bail, Context as _, Result};

use super::cli::PlanMotionArgs;
use super::request::{self, Given};
use super::truth::{render, render_truth, truth_settings, with_method};
use crate::budget::profile::Profile;
use crate::header::{command_line, RunHeader};
use crate::output::paths::{OutputPaths, Owned};
use crate::output::write_json;
use crate::plan::choose::Accuracy;
use crate::plan::fades::{
    check_fade_frames, fade_cost_ms, fades, largest_share_step, spreads, FadeAt,
};
use crate::plan::frame_inputs::FrameInputs;
use crate::plan::measured::Measured;
use crate::plan::motion::{
    chart_lines, group_label, plans_dir, setting_choice, verdict, CharacterSeries, FadeRow,
    FrameRow, MotionReport, Timing, FRAME_MS,
};
use crate::plan::over_time::{
    changes, check_margin, mean_max, pops, replan, switch_counts, switches, Change, FrameInput,
    FramePlan, Replan, Walk, FLICKER_BOUND,
};
use crate::plan::pipeline::{load_models, parse_budget_ms, plan_file, reference_model, NODE_LIMIT};
use crate::render::request::CheckedSettings;
use crate::render::settings::Assignment;
use crate::render::{FrameRequest, RenderSettings};
use crate::report::device_header;
use crate::scene::source::SceneSource;
use crate::scene::Scene;
use crate::vk::context::Context;

/// The files plan-motion writes into its folder, and its frames' plans.
const FILES: [&str; 3] = ["plan-motion.json", "plan-motion.png", "plan-motion.svg"];
const PLANS: Owned = Owned {
    sub: "plans",
    suffix: ".json",
};

/// `dermis plan-motion`: every argument checked (one line each) before the
/// scene loads and the device opens.
pub fn run(a: &PlanMotionArgs, given: &Given) -> Result<()> {
    let budget_ms = parse_budget_ms(&a.budget_ms)?;
    let profile = Profile::load(&a.profile).with_context(|| format!("--profile {}", a.profile))?;
    let walk = Walk::new(a.frames, a.walk_heads)?;
    check_margin(a.switch_margin)?;
    check_fade_frames(a.fade_frames)?;
    if a.look_ahead >= a.frames {
        bail!(
            "--look-ahead must be under --frames {}, got {}",
            a.frames,
            a.look_ahead
        );
    }
    let (source, base) = request::frame_settings(&a.frame, given)?;
    // The base frame's numbers before the scene loads.
    let base = CheckedSettings::new(base)?.get().clone();
    let scenes = frame_scenes(&source, walk.frames)?;
    // Every frame of the walk, its truth and no SSS: checked before any renders.
    for k in 0..walk.frames {
        let scene = scene_of(&scenes, k);
        let s = frame_settings(&base, walk.at(k));
        FrameRequest::new(scene, s.clone()).with_context(|| format!("frame {k}"))?;
        FrameRequest::new(scene, truth_settings(&s)?)
            .with_context(|| format!("frame {k}: the ground truth"))?;
        FrameRequest::new(scene, with_method(&s, crate::method::none().name, &[])?)
            .with_context(|| format!("frame {k}: no SSS"))?;
    }
    let acc = Measured::load_default(Measured::asset_of(source.gltf()))?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[PLANS])
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let o = MotionOptions {
        base,
        scenes: &scenes,
        accuracy: &acc,
        accuracy_source: acc.source(),
        profile,
        budget_ms,
        walk,
        switch_margin: a.switch_margin,
        look_ahead: a.look_ahead,
        fade_frames: a.fade_frames,
        out: &a.out,
    };
    let r = sequence(&ctx, &o);
    let r = ctx.finish_with(r)?;
    print!("{}", crate::plan::motion::summary(&r));
    println!("wrote {}", a.out.join("plan-motion.json").display());
    Ok(())
}

/// Each frame's scene: with a step, frame k's loaded at `--time` + k * step
/// (a frame depends only on its time: no step carried, so the ground truth,
/// which reads the meshes once, draws each); else the one scene.
fn frame_scenes(source: &SceneSource, frames: usize) -> Result<Vec<Scene>> {
    let Some(dt) = source.time_step else {
        return Ok(vec![request::load_scene(source)?]);
    };
    crate::ranges::TIME_STEP.check(dt)?;
    let t0 = source.time.unwrap_or(0.0);
    let scenes = (0..frames)
        .map(|k| {
            let t = t0 + k as f32 * dt;
            request::load_scene(&SceneSource {
                time: Some(t),
                time_step: None,
                ..source.clone()
            })
            .with_context(|| format!("frame {k} at {t} s"))
        })
        .collect::<Result<Vec<_>>>()?;
    eprintln!(
        "note: --time-step {dt}: frame k of the sequence is posed at {t0} + k * {dt} s (the last, frame {}, at {} s)",
        frames - 1,
        t0 + (frames - 1) as f32 * dt
    );
    Ok(scenes)
}

/// Frame `k`'s scene.
fn scene_of(scenes: &[Scene], k: usize) -> &Scene {
    &scenes[k.min(scenes.len() - 1)]
}

/// A frame of the walk: the crowd walked `walk_heads`, one method for all
/// (the frame's plan is given per frame).
fn frame_settings(base: &RenderSettings, walk_heads: f32) -> RenderSettings {
    let mut s = base.clone();
    s.walk_heads = walk_heads;
    s.assignment = None;
    s.character_ids = false;
    s
}

/// What the command needs besides the device.
pub struct MotionOptions<'a> {
    /// The scene options (size, heads, layout, distance, light; `--density`
    /// for the ground truth).
    pub base: RenderSettings,
    /// Each frame's scene (one: every frame's), posed at its time: with
    /// `--time-step` frame k is the scene at `--time` + k * step, every
    /// character at its own phase, as `render --time-step` draws it.
    pub scenes: &'a [Scene],
    pub accuracy: &'a dyn Accuracy,
    pub accuracy_source: String,
    pub profile: Profile,
    pub budget_ms: f64,
    pub walk: Walk,
    pub switch_margin: f64,
    /// Frames looked ahead (`over_time::Replan::look_ahead`).
    pub look_ahead: usize,
    /// Frames a switch on screen is cross-faded over (0: none).
    pub fade_frames: usize,
    pub out: &'a Path,
}

/// The frame before: the plan's diffuse, the truth's, the truth's ids.
type Previous = (Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<u32>);

/// Every frame's settings (the crowd walked `walk.at(k)`) and planning
/// input (its characters and every setting's costs, timed).
fn frame_inputs(o: &MotionOptions) -> Result<(Vec<RenderSettings>, Vec<FrameInput>)> {
    let (models, _) = load_models()?;
    let reference = reference_model(&models)?;
    let frame_settings: Vec<RenderSettings> = (0..o.walk.frames)
        .map(|k| frame_settings(&o.base, o.walk.at(k)))
        .collect();
    // Per frame the fast inputs (the skin patches and the price grid),
    // what a game re-planning every frame would run.
    let mut per_frame = FrameInputs::new(
        scene_of(o.scenes, 0),
        &models,
        reference,
        &o.profile,
        o.base.width,
        o.base.height,
    );
    // Every scale priced once, before the first frame (a game's load).
    per_frame.fill_scene();
    let inputs: Vec<FrameInput> = frame_settings.iter().map(|s| per_frame.frame(s)).collect();
    Ok((frame_settings, inputs))
}

/// Every frame's row, per frame (from frame 1) every character's change
/// under the plan and the truth's, and every switch's jump by (frame,
/// character).
type Rendered = (
    Vec<FrameRow>,
    Vec<Vec<Change>>,
    Vec<Vec<Change>>,
    std::collections::BTreeMap<(usize, usize), f64>,
);

/// Renders frame by frame the truth, no SSS and the frame's plan `with[k]`
/// (`labels[k]` its groups), keeping only the frame before.
fn render_frames(
    ctx: &Context,
    o: &MotionOptions,
    frame_settings: &[RenderSettings],
    inputs: &[FrameInput],
    with: &[FramePlan],
    labels: &[Vec<String>],
    fading: &[Vec<Option<FadeAt>>],
) -> Result<Rendered> {
    let n = o.base.heads as usize;
    let mut plan_changes: Vec<Vec<Change>> = vec![Vec::new()];
    let mut truth_changes: Vec<Vec<Change>> = vec![Vec::new()];
    let mut rows = Vec::new();
    let mut jumps = std::collections::BTreeMap::new();
    let mut before: Option<Previous> = None;
    let progress = indicatif::ProgressBar::new(o.walk.frames as u64);
    for (k, s) in frame_settings.iter().enumerate() {
        let scene = scene_of(o.scenes, k);
        let truth = render_truth(ctx, scene, s).with_context(|| format!("frame {k}"))?;
        let fp = &with[k];
        let inp = &inputs[k];
        let mut file = plan_file(
            &o.profile.profile.name,
            o.budget_ms,
            &inp.characters,
            &inp.costs,
            &fp.plan,
            vec![format!(
                "frame {k} of a plan-motion sequence: the crowd walked {} head heights (render \
                 it with --crowd-walked {} and the sequence's scene options)",
                s.walk_heads, s.walk_heads
            )],
        )?;
        let mut fade_rows = Vec::new();
        for (c, f) in fading[k].iter().enumerate() {
            let Some(f) = f else { continue };
            let (method, options) = setting_choice(&f.from)?;
            let a = file
                .assignments
                .iter_mut()
                .find(|a| a.character == c)
                .context("a fading character has no assignment")?;
            a.fade = Some(crate::mix::plan_file::PlannedFade {
                method,
                options,
                weight: f.weight,
            });
            fade_rows.push(FadeRow {
                character: c,
                from: group_label(&f.from),
                weight: f.weight,
            });
        }
        file.check()
            .with_context(|| format!("frame {k}: the plan with its fades"))?;
        // Every frame's plan, for `render --plan` (with `--crowd-walked`) and
        // `budget --plan` to draw or price that frame again.
        file.run = Some(header(ctx, o));
        write_json(&plans_dir(o.out).join(format!("frame-{k:03}.json")), &file)?;
        let mut ps = s.clone();
        ps.assignment = Some(Assignment::Plan(file.clone()));
        let planned = render(ctx, scene, &ps).with_context(|| format!("frame {k}: the plan"))?;
        let measured = truth.score(&planned.diffuse)?.weighted;
        // Each switch of this frame on screen: the frame again with the
        // character on its old setting, so the switch's own jump is told
        // apart from each method's change under motion.
        if k > 0 {
            for (c, fade) in fading[k].iter().enumerate() {
                let (old, new) = (&with[k - 1].labels[c], &fp.labels[c]);
                let mine = |i: &usize| truth.ids[*i] as usize == c + 1;
                if old == new || !(0..truth.ids.len()).any(|i| mine(&i)) {
                    continue;
                }
                let mut f = file.clone();
                let (method, options) = setting_choice(old)?;
                let a = f
                    .assignments
                    .iter_mut()
                    .find(|a| a.character == c)
                    .context("a switching character has no assignment")?;
                (a.method, a.options, a.fade) = (method, options, None);
                let mut cs = s.clone();
                cs.assignment = Some(Assignment::Plan(f));
                let kept = render(ctx, scene, &cs)
                    .with_context(|| format!("frame {k}: character {c} on its old setting"))?;
                // The rendered frame holds (1 - w) of the new setting's
                // difference from the old (w: the fade's weight, 0 without).
                let w = fade.as_ref().map_or(0.0, |f| f.weight);
                let (mut sum, mut px) = (0.0f64, 0usize);
                for i in (0..truth.ids.len()).filter(mine) {
                    px += 1;
                    for ch in 0..3 {
                        sum += f64::from((planned.diffuse[i][ch] - kept.diffuse[i][ch]).abs());
                    }
                }
                jumps.insert((k, c), sum / (3 * px) as f64 / (1.0 - w));
            }
        }
        if let Some((pb, tb, ib)) = &before {
            plan_changes.push(changes(pb, &planned.diffuse, ib, &truth.ids, n)?);
            truth_changes.push(changes(tb, &truth.diffuse, ib, &truth.ids, n)?);
        }
        let mut groups: Vec<String> = Vec::new();
        for l in &labels[k] {
            if !groups.contains(l) {
                groups.push(l.clone());
            }
        }
        rows.push(FrameRow {
            frame: k,
            walk_heads: s.walk_heads,
            groups,
            predicted_ms: fp.plan.solution.cost_ms,
            predicted_error: fp.plan.solution.error,
            fades: fade_rows,
            fade_ms: fade_cost_ms(
                &inp.costs,
                &fp.labels,
                &fading[k],
                &inp.characters
                    .iter()
                    .map(|c| c.skin_pixels > 0.0)
                    .collect::<Vec<_>>(),
            ),
            measured_error: measured,
            solve_ms: fp.solve_ms,
            inputs_ms: inp.inputs_ms,
            nodes: fp.plan.solution.nodes,
            optimal: fp.plan.solution.optimal,
        });
        before = Some((planned.diffuse, truth.diffuse, truth.ids));
        progress.inc(1);
    }
    progress.finish_and_clear();
    Ok((rows, plan_changes, truth_changes, jumps))
}

/// The run header of plan-motion's files.
fn header(ctx: &Context, o: &MotionOptions) -> RunHeader {
    RunHeader::new(
        &command_line(),
        device_header(ctx),
        (o.base.width, o.base.height),
        (0, 1),
    )
}

/// Runs the sequence (see the module doc) and writes its outputs.
pub fn sequence(ctx: &Context, o: &MotionOptions) -> Result<MotionReport> {
    let n = o.base.heads as usize;
    let (frame_settings, inputs) = frame_inputs(o)?;
    let ask = |margin: f64| Replan {
        accuracy: o.accuracy,
        budget_ms: o.budget_ms,
        switch_margin: margin,
        node_limit: Some(NODE_LIMIT),
        look_ahead: o.look_ahead,
    };
    let with = replan(&inputs, &ask(o.switch_margin));
    let without = replan(&inputs, &ask(0.0));
    let labels = |plans: &[FramePlan]| -> Vec<Vec<String>> {
        plans
            .iter()
            .map(|p| p.labels.iter().map(group_label).collect())
            .collect()
    };
    let (lw, lwo) = (labels(&with), labels(&without));
    let (cw, cwo) = (switch_counts(&lw, n), switch_counts(&lwo, n));

    let on_screen: Vec<Vec<bool>> = inputs
        .iter()
        .map(|f| f.characters.iter().map(|c| c.skin_pixels > 0.0).collect())
        .collect();
    let plan_labels: Vec<Vec<Option<(String, String)>>> =
        with.iter().map(|p| p.labels.clone()).collect();
    let fading = fades(&plan_labels, &on_screen, o.fade_frames);
    let (rows, plan_changes, truth_changes, jumps) =
        render_frames(ctx, o, &frame_settings, &inputs, &with, &lw, &fading)?;
    let sw = switches(&lw);
    let spread = spreads(&sw, &fading);
    let steps: Vec<Option<(f64, f64)>> = sw
        .iter()
        .zip(&spread)
        .map(|(x, &sp)| {
            let j = *jumps.get(&(x.frame, x.character))?;
            let seen = |k: usize| {
                plan_changes
                    .get(k)
                    .and_then(|f| f.get(x.character))
                    .is_some_and(|c| c.pixels > 0)
            };
            Some((j, largest_share_step(x, sp, &fading, seen)))
        })
        .collect();
    let measured_pops = pops(&sw, &spread, &steps, &plan_changes, &truth_changes);
    let series: Vec<CharacterSeries> = (0..n)
        .map(|c| {
            let pick = |v: &[Vec<Change>], k: usize| {
                v.get(k)
                    .and_then(|f| f.get(c))
                    .filter(|x| x.pixels > 0)
                    .map(|x| x.mean_abs)
            };
            CharacterSeries {
                character: c,
                settings: lw.iter().map(|f| f[c].clone()).collect(),
                px_per_mm: inputs.iter().map(|f| f.characters[c].px_per_mm).collect(),
                plan_change: (0..o.walk.frames).map(|k| pick(&plan_changes, k)).collect(),
                truth_change: (0..o.walk.frames)
                    .map(|k| pick(&truth_changes, k))
                    .collect(),
                switches_with_margin: cw[c],
                switches_without_margin: cwo[c],
            }
        })
        .collect();
    // A switch pops when the change it adds at one frame itself (its
    // measured jump, times the largest share of it one frame shows) exceeds
    // the flicker test's bound (`Pop::pops`). Its excess over the truth's
    // change is reported too, but holds each method's own change under
    // motion besides the switch, which no fade removes (a face rushing past
    // the lens).
    let at = measured_pops
        .iter()
        .map(|p| p.excess.abs())
        .reduce(f64::max);
    let elsewhere = measured_pops
        .iter()
        .filter_map(|p| p.excess_elsewhere)
        .reduce(f64::max);
    let popping = measured_pops.iter().filter(|p| p.pops()).count();
    let over: Vec<f64> = rows
        .iter()
        .map(|f| f.predicted_ms + f.fade_ms.unwrap_or(0.0) - o.budget_ms)
        .collect();
    let frames_over = over.iter().filter(|&&x| x > 1e-9).count();
    let max_over = over.iter().copied().fold(0.0, f64::max);
    let verdict = verdict(
        (o.fade_frames, o.budget_ms),
        &measured_pops,
        (frames_over, max_over),
    );
    let solve: Vec<f64> = with.iter().map(|f| f.solve_ms).collect();
    let inp: Vec<f64> = inputs.iter().map(|f| f.inputs_ms).collect();
    let ((sm, sx), (im, ix)) = (mean_max(&solve), mean_max(&inp));
    let report = MotionReport {
        run: header(ctx, o),
        heads: o.base.heads,
        layout: o.base.layout,
        distance_heads: o.base.distance_heads,
        walk: o.walk,
        profile: o.profile.profile.name.clone(),
        budget_ms: o.budget_ms,
        switch_margin: o.switch_margin,
        look_ahead: o.look_ahead,
        fade_frames: o.fade_frames,
        accuracy: o.accuracy_source.clone(),
        truth_density: o.base.options.given("density").map(|d| d.to_string()),
        timing: Timing {
            solve_mean_ms: sm,
            solve_max_ms: sx,
            inputs_mean_ms: im,
            inputs_max_ms: ix,
            costs_mean_ms: mean_max(&inputs.iter().map(|f| f.costs_ms).collect::<Vec<_>>()).0,
            frame_ms: FRAME_MS,
        },
        switches_with_margin: cw.iter().sum(),
        switches_without_margin: cwo.iter().sum(),
        frames: rows,
        characters: series,
        pops: measured_pops,
        bound: FLICKER_BOUND,
        max_abs_excess_at_switches: at,
        max_abs_excess_elsewhere: elsewhere,
        popping,
        cross_fade_needed: (o.fade_frames == 0).then_some(popping > 0),
        frames_over_budget_with_fades: frames_over,
        max_over_budget_ms: max_over,
        verdict,
    };
    write_json(&o.out.join("plan-motion.json"), &report)?;
    crate::plan::motion_chart::write(o.out, o.walk.frames, FLICKER_BOUND, &chart_lines(&report))?;
    Ok(report)
}
