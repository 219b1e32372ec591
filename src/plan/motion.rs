//! `dermis plan-motion` (issue 16 item 6): a crowd walking toward a fixed
//! camera (`over_time`'s sequence: for the skin the same relative motion as
//! the camera dollying toward the crowd), re-planned every frame with
//! hysteresis, rendered frame by frame with the frame's plan and with the
//! ground truth, and every switch measured: the switching character's
//! frame-to-frame change over its pixels (the ground truth's character ids
//! of both frames) against the truth's own change over the same pixels at
//! the same frames. The plan's time per frame is reported, the solver's apart
//! from the inputs' (estimating the characters and pricing every setting).
//! With `--fade-frames F` (default 3) a switch on screen is cross-faded over
//! F frames (`over_time::fades`, rendered through the plan file's `fade`):
//! its change is then measured over the F + 1 frames it is spread over, and
//! the fades' extra cost is priced per frame beside the plan's.
//!
//! Writes DIR/plan-motion.json, DIR/plan-motion.png / .svg (each switching
//! character's change against the truth's, frame by frame) and every frame's
//! plan file, fades included, as DIR/plans/frame-KKK.json.

use std::path::Path;

use anyhow::{Context as _, Result};
use serde::Serialize;

use super::choose::Accuracy;
use super::cli::{
    load_models, plan_file, plan_frames_dir, reference_model, setting_options, NODE_LIMIT,
};
use super::fades::{fade_cost_ms, fades, largest_share_step, spreads, FadeAt};
use super::frame_inputs::FrameInputs;
use super::motion_chart::Line;
use super::over_time::{
    changes, mean_max, pops, replan, switch_counts, switches, Change, FrameInput, FramePlan, Pop,
    Replan, Walk, FLICKER_BOUND,
};
use super::truth::{render, Truth};
use crate::budget::profile::Profile;
use crate::output::write_json;
use crate::render::settings::Assignment;
use crate::render::RenderSettings;
use crate::scene::layout::Layout;
use crate::scene::Scene;
use crate::vk::context::Context;

/// A 60 Hz frame (ms): what "far below a frame" is measured against.
pub const FRAME_MS: f64 = 1000.0 / 60.0;

/// What the command needs besides the device.
pub struct MotionOptions<'a> {
    /// The scene options (size, heads, layout, distance, light; `--density`
    /// for the ground truth).
    pub base: RenderSettings,
    pub scene: &'a Scene,
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

/// A character fading at a frame.
#[derive(Clone, Debug, Serialize)]
pub struct FadeRow {
    pub character: usize,
    /// The setting it fades from ("method setting", "none").
    pub from: String,
    /// That setting's share of the character's result.
    pub weight: f64,
}

/// One frame of the sequence.
#[derive(Clone, Debug, Serialize)]
pub struct FrameRow {
    pub frame: usize,
    pub walk_heads: f32,
    /// The plan's groups ("method setting", "none").
    pub groups: Vec<String>,
    pub predicted_ms: f64,
    pub predicted_error: f64,
    /// The characters cross-fading at this frame.
    pub fades: Vec<FadeRow>,
    /// What the fades add to the modelled cost (`over_time::fade_cost_ms`;
    /// `None`: an old setting unpriced), beyond `predicted_ms` and the budget.
    pub fade_ms: Option<f64>,
    /// The plan's skin-weighted err/none against this frame's ground truth
    /// (as rendered: with its fades).
    pub measured_error: f64,
    pub solve_ms: f64,
    pub inputs_ms: f64,
    pub nodes: u64,
    pub optimal: bool,
}

/// One character over the sequence.
#[derive(Clone, Debug, Serialize)]
pub struct CharacterSeries {
    pub character: usize,
    /// Its setting at every frame (with the margin).
    pub settings: Vec<String>,
    pub px_per_mm: Vec<f64>,
    /// Change from the frame before (frame 0: none) of the plan and of the
    /// truth over its pixels (`None`: no pixel of it in both frames).
    pub plan_change: Vec<Option<f64>>,
    pub truth_change: Vec<Option<f64>>,
    pub switches_with_margin: usize,
    pub switches_without_margin: usize,
}

/// The plan's time per frame.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    pub solve_mean_ms: f64,
    pub solve_max_ms: f64,
    /// Estimating the characters and pricing every setting for each.
    pub inputs_mean_ms: f64,
    pub inputs_max_ms: f64,
    /// Of the inputs, pricing every setting for every character (mean).
    pub costs_mean_ms: f64,
    pub frame_ms: f64,
}

/// The command's report (DIR/plan-motion.json).
#[derive(Clone, Debug, Serialize)]
pub struct MotionReport {
    pub device: String,
    pub width: u32,
    pub height: u32,
    pub heads: u32,
    pub layout: Layout,
    pub distance_heads: f32,
    pub walk: Walk,
    pub profile: String,
    pub budget_ms: f64,
    pub switch_margin: f64,
    pub look_ahead: usize,
    pub fade_frames: usize,
    pub accuracy: String,
    /// The ground truth's `--density` (`None`: its default).
    pub truth_density: Option<String>,
    pub timing: Timing,
    pub switches_with_margin: usize,
    pub switches_without_margin: usize,
    pub frames: Vec<FrameRow>,
    pub characters: Vec<CharacterSeries>,
    /// Every switch of the plan with the margin that is on screen, measured.
    pub pops: Vec<Pop>,
    /// The flicker test's bound on a method's excess change.
    pub bound: f64,
    pub max_abs_excess_at_switches: Option<f64>,
    /// Largest |excess| of the switching characters at their other frames.
    pub max_abs_excess_elsewhere: Option<f64>,
    /// Switches that pop as rendered (with the fades, if any).
    pub popping: usize,
    /// Without fades (`fade_frames` 0): whether a switch pops, so a
    /// cross-fade is needed. With fades: not measured (`None`).
    pub cross_fade_needed: Option<bool>,
    /// Frames whose plan and fades together exceed the budget, and the
    /// largest excess (ms).
    pub frames_over_budget_with_fades: usize,
    pub max_over_budget_ms: f64,
    pub verdict: String,
}

fn group_label(l: &Option<(String, String)>) -> String {
    match l {
        Some((m, s)) => format!("{m} {s}"),
        None => crate::mix::Choice::none().method,
    }
}

/// The method and options of a setting label (`None`: no SSS), as a plan
/// file spells them.
fn setting_choice(
    l: &Option<(String, String)>,
) -> Result<(String, std::collections::BTreeMap<String, String>)> {
    Ok(match l {
        None => (crate::mix::Choice::none().method, Default::default()),
        Some((m, st)) => (
            m.clone(),
            setting_options(m, st)
                .with_context(|| format!("setting {m} '{st}' is not registered"))?,
        ),
    })
}

/// Where the frames' plan files go: DIR/plans/frame-KKK.json.
pub fn plans_dir(out: &Path) -> std::path::PathBuf {
    out.join("plans")
}

/// The frame before: the plan's diffuse, the truth's, the truth's ids.
type Previous = (Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<u32>);

/// Every frame's settings (the crowd walked `walk.at(k)`) and planning
/// input (its characters and every setting's costs, timed).
fn frame_inputs(o: &MotionOptions) -> Result<(Vec<RenderSettings>, Vec<FrameInput>)> {
    let (models, _) = load_models(&plan_frames_dir())?;
    let reference = reference_model(&models)?;
    let frame_settings: Vec<RenderSettings> = (0..o.walk.frames)
        .map(|k| {
            let mut s = o.base.clone();
            s.walk_heads = o.walk.at(k);
            s.assignment = None;
            s.character_ids = false;
            s
        })
        .collect();
    // Per frame the fast inputs (the skin patches and the price grid),
    // what a game re-planning every frame would run.
    let mut per_frame = FrameInputs::new(
        o.scene,
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
    crate::output::prepare_out_dir(&plans_dir(o.out))?;
    let progress = indicatif::ProgressBar::new(o.walk.frames as u64);
    for (k, s) in frame_settings.iter().enumerate() {
        let truth = Truth::render(ctx, o.scene, s).with_context(|| format!("frame {k}"))?;
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
        // Every frame's plan, for `render --plan` (with `--walk-heads`) and
        // `budget --plan` to draw or price that frame again.
        write_json(&plans_dir(o.out).join(format!("frame-{k:03}.json")), &file)?;
        let mut ps = s.clone();
        ps.assignment = Some(Assignment::Plan(file.clone()));
        let planned = render(ctx, o.scene, &ps).with_context(|| format!("frame {k}: the plan"))?;
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
                let kept = render(ctx, o.scene, &cs)
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

/// Runs the sequence (see the module doc) and writes its outputs.
pub fn run(ctx: &Context, o: &MotionOptions) -> Result<MotionReport> {
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
    let verdict = verdict(o, &measured_pops, (frames_over, max_over));
    let solve: Vec<f64> = with.iter().map(|f| f.solve_ms).collect();
    let inp: Vec<f64> = inputs.iter().map(|f| f.inputs_ms).collect();
    let ((sm, sx), (im, ix)) = (mean_max(&solve), mean_max(&inp));
    let report = MotionReport {
        device: ctx.facts.name.clone(),
        width: o.base.width,
        height: o.base.height,
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
    super::motion_chart::write(o.out, o.walk.frames, FLICKER_BOUND, &chart_lines(&report))?;
    Ok(report)
}

/// The run's verdict in words: whether a switch pops (`Pop::pops`: the
/// change it adds at one frame itself against the flicker test's bound; the
/// excess over the truth's change also holds each method's own change under
/// motion, which no fade removes), and the frames the fades take over the
/// budget (`over`: how many, by how much at most).
fn verdict(
    o: &MotionOptions,
    measured_pops: &[Pop],
    (frames_over, max_over): (usize, f64),
) -> String {
    let at = measured_pops
        .iter()
        .map(|p| p.excess.abs())
        .reduce(f64::max);
    let largest_step = measured_pops.iter().filter_map(|p| p.step).reduce(f64::max);
    let worst_pop = measured_pops
        .iter()
        .filter(|p| p.pops())
        .map(|p| p.step.unwrap_or(p.excess.abs()))
        .reduce(f64::max);
    let elsewhere = measured_pops
        .iter()
        .filter_map(|p| p.excess_elsewhere)
        .reduce(f64::max);
    let over_bound = measured_pops
        .iter()
        .filter(|p| p.excess.abs() > FLICKER_BOUND)
        .count();
    let faded = o.fade_frames > 0;
    let (no_pop, pop) = if faded {
        (
            format!("with {}-frame cross-fades no switch pops", o.fade_frames),
            format!(
                "a switch pops even with {}-frame cross-fades",
                o.fade_frames
            ),
        )
    } else {
        (
            "no cross-fade needed".to_string(),
            "a switch pops: a cross-fade is needed".to_string(),
        )
    };
    let steps = largest_step.map_or("-".to_string(), |x| format!("{x:.5}"));
    let mut verdict = match (at, worst_pop) {
        (None, _) => "no switch was on screen: nothing to measure".to_string(),
        (Some(_), Some(w)) => format!(
            "{pop}: the change a switch adds at one frame, {w:.5}, exceeds the flicker \
             test's bound {FLICKER_BOUND}"
        ),
        (Some(a), None) if over_bound > 0 => format!(
            "{no_pop}: the change a switch adds at one frame is at most {steps}, within the \
             flicker test's bound {FLICKER_BOUND}; {over_bound} switch(es) change their \
             character by more than the truth beyond the bound (at most {a:.5}), which is \
             the methods' own change under motion (the same characters at the frames they do \
             not switch: up to {})",
            elsewhere.map_or("-".to_string(), |e| format!("{e:.5}"))
        ),
        (Some(a), None) => format!(
            "{no_pop}: the change a switch adds at one frame is at most {steps} and its \
             excess over the truth's change at most {a:.5}, within the flicker test's bound \
             {FLICKER_BOUND}"
        ),
    };
    if frames_over > 0 {
        verdict.push_str(&format!(
            "; the fades take {frames_over} frame(s) over the {} ms budget, by up to {max_over:.4} ms",
            o.budget_ms
        ));
    }
    verdict
}

/// The chart's lines: every character that switches, its switches marked.
fn chart_lines(r: &MotionReport) -> Vec<Line> {
    r.characters
        .iter()
        .filter(|c| c.switches_with_margin > 0)
        .map(|c| Line {
            label: format!("character {}", c.character),
            plan: c.plan_change.clone(),
            truth: c.truth_change.clone(),
            switches: r
                .pops
                .iter()
                .filter(|p| p.character == c.character)
                .map(|p| (p.frame, p.plan_change))
                .collect(),
        })
        .collect()
}

/// The report as text: the frames, the switches, the times and the verdict.
pub fn summary(r: &MotionReport) -> String {
    let mut s = format!(
        "{} at {}x{}: {} characters ({:?}) {} head heights away, walking {} head heights \
         toward the camera over {} frames; {} at {} ms, margin {}, looking {} frames ahead, \
         fading over {} frames\n",
        r.device,
        r.width,
        r.height,
        r.heads,
        r.layout,
        r.distance_heads,
        r.walk.walk_heads,
        r.walk.frames,
        r.profile,
        r.budget_ms,
        r.switch_margin,
        r.look_ahead,
        r.fade_frames
    );
    s.push_str(&format!(
        "{:>5} {:>6}  {:<40} {:>9} {:>9} {:>9} {:>9} {:>9}\n",
        "frame", "walk", "groups", "pred ms", "fade ms", "pred err", "meas err", "solve ms"
    ));
    for f in &r.frames {
        s.push_str(&format!(
            "{:>5} {:>6.2}  {:<40} {:>9.4} {:>9} {:>9.4} {:>9.4} {:>9.3}\n",
            f.frame,
            f.walk_heads,
            f.groups.join(" + "),
            f.predicted_ms,
            match (f.fades.is_empty(), f.fade_ms) {
                (true, _) => "-".to_string(),
                (false, Some(ms)) => format!("{ms:.4}"),
                (false, None) => "unpriced".to_string(),
            },
            f.predicted_error,
            f.measured_error,
            f.solve_ms
        ));
        for fr in &f.fades {
            s.push_str(&format!(
                "{:>5} {:>6}  character {} fading from {} ({:.0}%)\n",
                "",
                "",
                fr.character,
                fr.from,
                100.0 * fr.weight
            ));
        }
    }
    s.push_str(&format!(
        "switches: {} with the margin, {} without\n",
        r.switches_with_margin, r.switches_without_margin
    ));
    for p in &r.pops {
        s.push_str(&format!(
            "switch at frame {} of character {} ({} -> {}){}, {} px: change {:.5}, truth's \
             {:.5}, excess {:+.5} ({:+.2}% of its level); the switch itself {}\n",
            p.frame,
            p.character,
            p.from,
            p.to,
            if p.spread_frames > 1 {
                format!(
                    " faded over {} steps, largest at frame {}",
                    p.spread_frames, p.measured_frame
                )
            } else {
                String::new()
            },
            p.pixels,
            p.plan_change,
            p.truth_change,
            p.excess,
            100.0 * p.relative_excess,
            match (p.jump, p.step) {
                (Some(j), Some(st)) => format!("{j:.5}, at most {st:.5} at one frame"),
                _ => "not measured".to_string(),
            }
        ));
    }
    let t = &r.timing;
    s.push_str(&format!(
        "plan time per frame: solve mean {:.3} ms, max {:.3} ms; inputs (characters and \
         costs) mean {:.1} ms, max {:.1} ms, of it pricing {:.1} ms; a 60 Hz frame is {:.1} ms\n",
        t.solve_mean_ms,
        t.solve_max_ms,
        t.inputs_mean_ms,
        t.inputs_max_ms,
        t.costs_mean_ms,
        t.frame_ms
    ));
    s.push_str(&format!("{}\n", r.verdict));
    s
}
