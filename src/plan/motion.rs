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
//!
//! This module is the record (plan-motion.json's schema, read back typed),
//! its verdict and its summary; `app::plan_motion` renders the sequence.

use std::path::Path;

use anyhow::{Context as _, Result};
use serde::{Deserialize, Serialize};

use super::motion_chart::Line;
use super::over_time::{Pop, Walk, FLICKER_BOUND};
use super::pipeline::setting_options;
use crate::header::RunHeader;
use crate::scene::layout::Layout;

/// A 60 Hz frame (ms): what "far below a frame" is measured against.
pub const FRAME_MS: f64 = 1000.0 / 60.0;

/// A character fading at a frame.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FadeRow {
    pub character: usize,
    /// The setting it fades from ("method setting", "none").
    pub from: String,
    /// That setting's share of the character's result.
    pub weight: f64,
}

/// One frame of the sequence.
#[derive(Clone, Debug, Serialize, Deserialize)]
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
#[derive(Clone, Debug, Serialize, Deserialize)]
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
#[derive(Clone, Debug, Serialize, Deserialize)]
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

/// The command's report (DIR/plan-motion.json), read back typed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MotionReport {
    #[serde(flatten)]
    pub run: RunHeader,
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

pub fn group_label(l: &Option<(String, String)>) -> String {
    match l {
        Some((m, s)) => format!("{m} {s}"),
        None => crate::mix::Choice::none().method,
    }
}

/// The method and options of a setting label (`None`: no SSS), as a plan
/// file spells them.
pub fn setting_choice(
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

/// The run's verdict in words: whether a switch pops (`Pop::pops`: the
/// change it adds at one frame itself against the flicker test's bound; the
/// excess over the truth's change also holds each method's own change under
/// motion, which no fade removes), and the frames the fades take over the
/// budget (`over`: how many, by how much at most).
pub fn verdict(
    (fade_frames, budget_ms): (usize, f64),
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
    let faded = fade_frames > 0;
    let (no_pop, pop) = if faded {
        (
            format!("with {fade_frames}-frame cross-fades no switch pops"),
            format!("a switch pops even with {fade_frames}-frame cross-fades"),
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
            "; the fades take {frames_over} frame(s) over the {budget_ms} ms budget, by up to {max_over:.4} ms"
        ));
    }
    verdict
}

/// The chart's lines: every character that switches, its switches marked.
pub fn chart_lines(r: &MotionReport) -> Vec<Line> {
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
        r.run.device.device,
        r.run.width,
        r.run.height,
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
