//! Re-planning every frame (issue 16 item 6, "over time"): a sequence of
//! frames in which a rigid crowd walks toward a fixed camera (for the
//! characters' skin the same relative motion as the camera dollying toward
//! the crowd: the key light is directional and its shadow frustum is fitted
//! to the characters, so only a backdrop would tell the two apart), planned
//! frame by frame with the previous frame's choice and a switching margin
//! (`solve`'s hysteresis) and optionally against the costs of the frames
//! ahead (`planning_costs`), the switches it makes counted per character, and
//! the measure of a switch on screen: a character's frame-to-frame change
//! against the ground truth's own change over the same pixels at the same
//! frames (the measure of `tests/suite/stability.rs`'s flicker test).
//!
//! A switch on screen may be **cross-faded** over a few frames
//! (`super::fades`): the character's old setting keeps running beside the
//! new one and its share of the result falls to 0 in equal steps (the
//! renderer's `mix::Fade`); a faded switch's change is measured over every
//! frame it is spread over ([`pops`]).
//!
//! Pure: no device (tests/suite/layers.rs holds it to it); the renders are
//! `motion.rs`'s.

use std::time::Instant;

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use super::character::CharacterInput;
use super::choose::{plan, Accuracy, Ask, Plan, SettingCosts};

/// The most frames a sequence may have (each is two or three renders).
pub const MAX_FRAMES: usize = 1000;

/// The longest walk: `RenderSettings::validate`'s bound on it
/// (`render::settings::MAX_DISTANCE_HEADS`, held equal by
/// tests/suite/plan_motion.rs; not imported, as that module reaches Vulkan).
pub const MAX_WALK_HEADS: f32 = 1000.0;

/// What the flicker test (`tests/suite/stability.rs`,
/// `slow_orbit_does_not_flicker`) allows a method: its mean frame-to-frame
/// change over the skin within this of the ground truth's own change
/// (diffuse light, linear). A switch that changes a character by more than
/// this beyond the truth pops, and would need a cross-fade.
pub const FLICKER_BOUND: f64 = 0.005;

/// The switching margin `dermis plan-motion` uses unless told: a switch
/// must gain 0.02 of err/none, about the smallest difference the accuracy
/// table resolves between neighbouring settings at one scale, so a
/// character whose predictions cross by less (the table's interpolation
/// wobbling as it walks) keeps its method.
pub const DEFAULT_MARGIN: f64 = 0.02;

/// Checks a switching margin (a non-negative err/none).
pub fn check_margin(m: f64) -> Result<()> {
    if !(m.is_finite() && (0.0..=1.0).contains(&m)) {
        bail!("--switch-margin must be an err/none within 0..=1, got {m}");
    }
    Ok(())
}

/// The sequence: `frames` frames over which the crowd walks `walk_heads`
/// head heights toward the camera, at a constant speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Walk {
    pub frames: usize,
    pub walk_heads: f32,
}

impl Walk {
    /// Checks the frame count and the walk (one-line errors).
    pub fn new(frames: usize, walk_heads: f32) -> Result<Walk> {
        if !(2..=MAX_FRAMES).contains(&frames) {
            bail!("--frames must be within 2..={MAX_FRAMES}, got {frames}");
        }
        // Checked here before any character is estimated or a device opens.
        let max = MAX_WALK_HEADS;
        if !(walk_heads.is_finite() && walk_heads.abs() <= max) {
            bail!("--walk-heads must be within +-{max} head heights, got {walk_heads}");
        }
        Ok(Walk { frames, walk_heads })
    }

    /// How far the crowd has walked at frame `k` (0 at the first frame,
    /// `walk_heads` at the last).
    pub fn at(&self, k: usize) -> f32 {
        self.walk_heads * k as f32 / (self.frames - 1) as f32
    }
}

/// One frame's planning input: its characters and every setting's costs
/// for them (the same settings, in the same order, every frame).
#[derive(Clone, Debug)]
pub struct FrameInput {
    pub characters: Vec<CharacterInput>,
    pub costs: Vec<SettingCosts>,
    /// Time taken to estimate the characters and price the settings (ms).
    pub inputs_ms: f64,
    /// Of that, the pricing (ms).
    pub costs_ms: f64,
}

/// How the frames are re-planned.
pub struct Replan<'a> {
    pub accuracy: &'a dyn Accuracy,
    pub budget_ms: f64,
    /// The err/none a switch must gain (`solve`'s `switch_margin`); 0: no
    /// hysteresis (every frame planned afresh).
    pub switch_margin: f64,
    pub node_limit: Option<u64>,
    /// Frames looked ahead: each frame is planned against every setting's
    /// costs at their highest over it and the next `look_ahead` frames, so a
    /// choice made now still fits while the crowd keeps coming nearer (the
    /// sequence's own later frames stand for what a game would extrapolate
    /// from the characters' motion). 0: each frame's own costs.
    pub look_ahead: usize,
}

/// The costs frame `k` is planned against (see [`Replan::look_ahead`]):
/// per setting (matched by name) its fixed cost and every character's part
/// at their highest over frames `k..=k + look_ahead`; a part unpriced at
/// frame `k` stays unpriced; the texels are frame `k`'s.
pub fn planning_costs(frames: &[FrameInput], k: usize, look_ahead: usize) -> Vec<SettingCosts> {
    let mut costs = frames[k].costs.clone();
    let last = (k + look_ahead).min(frames.len().saturating_sub(1));
    for f in frames.iter().take(last + 1).skip(k + 1) {
        for s in &mut costs {
            let Some(later) = f
                .costs
                .iter()
                .find(|x| x.method == s.method && x.setting == s.setting)
            else {
                continue;
            };
            s.fixed_ms = s.fixed_ms.max(later.fixed_ms);
            for (p, q) in s.parts_ms.iter_mut().zip(&later.parts_ms) {
                if let (Some(p), Some(q)) = (p.as_mut(), q) {
                    *p = p.max(*q);
                }
            }
        }
    }
    costs
}

/// Times each frame's solve is run (the best one is its time).
pub const TIMING_RUNS: usize = 5;

/// One frame's plan and the solver's time for it (the best of
/// [`TIMING_RUNS`]).
#[derive(Clone, Debug)]
pub struct FramePlan {
    pub plan: Plan,
    /// Per character, the setting's label (`None`: no SSS).
    pub labels: Vec<Option<(String, String)>>,
    pub solve_ms: f64,
}

fn label(costs: &[SettingCosts], s: Option<usize>) -> Option<(String, String)> {
    s.map(|s| (costs[s].method.clone(), costs[s].setting.clone()))
}

/// Plans every frame in turn, each with the previous frame's choice as
/// `previous` (matched by setting name, so frames need not list the
/// settings in one order) when the margin is above 0.
pub fn replan(frames: &[FrameInput], r: &Replan) -> Vec<FramePlan> {
    let mut out: Vec<FramePlan> = Vec::with_capacity(frames.len());
    for (k, f) in frames.iter().enumerate() {
        let costs = planning_costs(frames, k, r.look_ahead);
        // The first frame takes every setting on from none: with a margin
        // it too keeps the margin's share of the budget free, so the frames
        // after it do not drop what it took on as soon as the crowd nears.
        let previous = (r.switch_margin > 0.0).then(|| match out.last() {
            Some(last) => (0..f.characters.len())
                .map(|c| {
                    let l = last.labels.get(c).cloned().flatten()?;
                    costs
                        .iter()
                        .position(|s| s.method == l.0 && s.setting == l.1)
                })
                .collect::<Vec<Option<usize>>>(),
            None => vec![None; f.characters.len()],
        });
        let ask = Ask {
            characters: &f.characters,
            settings: &costs,
            accuracy: r.accuracy,
            budget_ms: r.budget_ms,
            previous,
            switch_margin: r.switch_margin,
            node_limit: r.node_limit,
        };
        // The solve is deterministic: timed as the best of a few runs, so a
        // thread preempted on a busy machine (lavapipe's threads beside it)
        // does not stand for the plan's time.
        let mut solve_ms = f64::INFINITY;
        let mut p = None;
        for _ in 0..TIMING_RUNS {
            let t = Instant::now();
            let q = plan(&ask);
            solve_ms = solve_ms.min(t.elapsed().as_secs_f64() * 1e3);
            p = Some(q);
        }
        let p = p.expect("TIMING_RUNS >= 1");
        let labels = p
            .solution
            .choice
            .iter()
            .map(|&s| label(&costs, s))
            .collect();
        out.push(FramePlan {
            plan: p,
            labels,
            solve_ms,
        });
    }
    out
}

/// A character changing its method between two frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Switch<T> {
    /// The frame the new method is first used in (>= 1).
    pub frame: usize,
    pub character: usize,
    pub from: T,
    pub to: T,
}

/// Every switch of a sequence of per-frame choices (`choices[frame][character]`).
pub fn switches<T: PartialEq + Clone>(choices: &[Vec<T>]) -> Vec<Switch<T>> {
    let mut out = Vec::new();
    for (k, w) in choices.windows(2).enumerate() {
        for (c, (a, b)) in w[0].iter().zip(&w[1]).enumerate() {
            if a != b {
                out.push(Switch {
                    frame: k + 1,
                    character: c,
                    from: a.clone(),
                    to: b.clone(),
                });
            }
        }
    }
    out
}

/// Switches per character (`characters` long).
pub fn switch_counts<T: PartialEq + Clone>(choices: &[Vec<T>], characters: usize) -> Vec<usize> {
    let mut n = vec![0; characters];
    for s in switches(choices) {
        if let Some(x) = n.get_mut(s.character) {
            *x += 1;
        }
    }
    n
}

/// One character's change between two frames over its pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Pixels that are the character's in both frames (the ground truth's ids).
    pub pixels: usize,
    /// Mean absolute change per colour channel (RGB, linear diffuse), as
    /// the flicker test measures it.
    pub mean_abs: f64,
    /// Mean diffuse (per channel) of the later frame over those pixels: the
    /// scale `mean_abs` is relative to.
    pub mean_level: f64,
}

/// Per character (ids 1..=`characters`; 0 is no skin), the change from
/// `a` to `b` over the pixels whose id is the character's in both frames
/// (`ids_a`, `ids_b`: the ground truth's character ids of the two frames).
/// A character with no such pixel: `pixels` 0 and the means 0.
pub fn changes(
    a: &[[f32; 4]],
    b: &[[f32; 4]],
    ids_a: &[u32],
    ids_b: &[u32],
    characters: usize,
) -> Result<Vec<Change>> {
    let n = a.len();
    if b.len() != n || ids_a.len() != n || ids_b.len() != n {
        bail!(
            "frames of different sizes ({n}, {}) or ids of another size ({}, {})",
            b.len(),
            ids_a.len(),
            ids_b.len()
        );
    }
    let mut acc = vec![(0usize, 0.0f64, 0.0f64); characters];
    for i in 0..n {
        let id = ids_a[i] as usize;
        if id == 0 || id > characters || ids_b[i] as usize != id {
            continue;
        }
        let x = &mut acc[id - 1];
        x.0 += 1;
        for ch in 0..3 {
            x.1 += f64::from((b[i][ch] - a[i][ch]).abs());
            x.2 += f64::from(b[i][ch]);
        }
    }
    Ok(acc
        .into_iter()
        .map(|(p, d, l)| {
            let k = (3 * p.max(1)) as f64;
            Change {
                pixels: p,
                mean_abs: d / k,
                mean_level: l / k,
            }
        })
        .collect())
}

/// A switch measured: the plan's change of the character at the switch
/// against the truth's change over the same pixels at the same frames; for a
/// faded switch, at the frame of its fade where the excess is largest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pop {
    /// The frame the new setting is first used in.
    pub frame: usize,
    pub character: usize,
    pub from: String,
    pub to: String,
    /// Frames its change is spread over (1: a hard switch; a fade of F
    /// frames: F + 1, the last step being the old setting's share to 0).
    pub spread_frames: usize,
    /// The frame measured below (of `frame..frame + spread_frames`).
    pub measured_frame: usize,
    pub pixels: usize,
    pub plan_change: f64,
    pub truth_change: f64,
    /// `plan_change - truth_change` (what the flicker test bounds).
    pub excess: f64,
    /// `excess` over the truth's mean diffuse on those pixels.
    pub relative_excess: f64,
    /// The same character's largest |excess| at the frames it does not
    /// switch (its method's own change under motion): what the switch is
    /// told apart from. `None`: no such frame with pixels.
    pub excess_elsewhere: Option<f64>,
    /// The switch itself: mean absolute difference (per channel) between the
    /// new setting's and the old one's result for the character at the switch
    /// frame, both rendered (`None`: not measured). What a hard switch adds
    /// to the frame's change whatever the motion; the excess also holds each
    /// method's own change under motion.
    pub jump: Option<f64>,
    /// The most of `jump` that one frame shows: the whole of it for a hard
    /// switch, its largest share step for a fade ([`largest_share_step`]).
    pub step: Option<f64>,
}

impl Pop {
    /// Whether the switch pops: its own step at one frame exceeds what the
    /// flicker test allows a method's change beyond the truth's. Unmeasured
    /// (`step` `None`), the excess must exceed the bound and the character's
    /// own excess at the frames it does not switch.
    pub fn pops(&self) -> bool {
        match self.step {
            Some(s) => s > FLICKER_BOUND,
            None => {
                self.excess.abs() > FLICKER_BOUND
                    && self.excess_elsewhere.is_none_or(|e| self.excess.abs() > e)
            }
        }
    }
}

/// Pops of `switches` from the per-frame changes of the plan and of the
/// truth (`plan[k][c]`: the change from frame k-1 to k, `plan[0]` unused).
/// `spread[i]` is the number of frames switch `i`'s change is spread over (1
/// without a fade): its excess is the largest over those frames with pixels,
/// and they are not among the character's "other frames". `steps[i]` is the
/// switch's measured jump and largest share step (`None`: unmeasured). A
/// switch none of
/// whose frames has the character's pixels in both frames is left out
/// (nothing of it is on screen to pop).
pub fn pops(
    switches: &[Switch<String>],
    spread: &[usize],
    steps: &[Option<(f64, f64)>],
    plan: &[Vec<Change>],
    truth: &[Vec<Change>],
) -> Vec<Pop> {
    let span = |i: usize| {
        let s = &switches[i];
        s.frame..(s.frame + spread.get(i).copied().unwrap_or(1).max(1)).min(plan.len())
    };
    let switching = |k: usize, c: usize| {
        (0..switches.len()).any(|i| switches[i].character == c && span(i).contains(&k))
    };
    let at = |k: usize, c: usize| -> Option<(Change, Change)> {
        let (p, t) = (*plan.get(k)?.get(c)?, *truth.get(k)?.get(c)?);
        (p.pixels > 0).then_some((p, t))
    };
    switches
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let c = s.character;
            let (k, (p, t)) = span(i)
                .filter_map(|k| at(k, c).map(|x| (k, x)))
                .max_by(|a, b| {
                    let e = |x: &(Change, Change)| (x.0.mean_abs - x.1.mean_abs).abs();
                    e(&a.1).total_cmp(&e(&b.1))
                })?;
            let excess = p.mean_abs - t.mean_abs;
            let elsewhere = (1..plan.len())
                .filter(|&k| !switching(k, c))
                .filter_map(|k| at(k, c))
                .map(|(p, t)| (p.mean_abs - t.mean_abs).abs())
                .reduce(f64::max);
            Some(Pop {
                frame: s.frame,
                character: c,
                from: s.from.clone(),
                to: s.to.clone(),
                spread_frames: span(i).len(),
                measured_frame: k,
                pixels: p.pixels,
                plan_change: p.mean_abs,
                truth_change: t.mean_abs,
                excess,
                relative_excess: excess / t.mean_level.max(1e-12),
                excess_elsewhere: elsewhere,
                jump: steps.get(i).copied().flatten().map(|x| x.0),
                step: steps.get(i).copied().flatten().map(|x| x.0 * x.1),
            })
        })
        .collect()
}

/// Mean and max of a series (0 for none).
pub fn mean_max(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    (
        v.iter().sum::<f64>() / v.len() as f64,
        v.iter().copied().fold(f64::MIN, f64::max),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two settings: "steady" at err/none 0.50 everywhere, "wobbly" at 0.50
    /// +- 0.02, better on the frames whose px/mm ends in an odd hundredth
    /// (the character's scale wobbles by 0.01 px/mm from frame to frame):
    /// predictions that cross back and forth by less than a 0.05 margin.
    struct Crossing;
    impl Accuracy for Crossing {
        fn predict(
            &self,
            _m: &str,
            setting: &str,
            x: f64,
            _l: f64,
            _sh: f64,
        ) -> Option<(f64, f64)> {
            let odd = ((x * 100.0).round() as i64) % 2 == 1;
            let e = match setting {
                "steady" => 0.50,
                "wobbly" if odd => 0.48,
                "wobbly" => 0.52,
                _ => return None,
            };
            Some((e, e))
        }
    }

    fn frame(px_per_mm: f64) -> FrameInput {
        let c = CharacterInput {
            index: 0,
            distance_heads: 4.0,
            px_per_mm,
            light_deg: 60.0,
            shadow_mm: 0.2,
            skin_pixels: 1e4,
            region_pixels: 1e4,
            region_rects: 4.0,
            silhouette_share: 0.1,
            screen_rect: [0, 0, 100, 100],
            region_tiles: Vec::new(),
        };
        let s = |setting: &str| SettingCosts {
            method: "m".into(),
            setting: setting.into(),
            measured_as: setting.into(),
            fixed_ms: 0.01,
            parts_ms: vec![Some(0.01)],
            texel_mm: vec![None],
        };
        FrameInput {
            characters: vec![c],
            costs: vec![s("steady"), s("wobbly")],
            inputs_ms: 0.0,
            costs_ms: 0.0,
        }
    }

    fn run(frames: &[FrameInput], margin: f64) -> Vec<Vec<Option<(String, String)>>> {
        replan(
            frames,
            &Replan {
                accuracy: &Crossing,
                budget_ms: 1.0,
                switch_margin: margin,
                node_limit: None,
                look_ahead: 0,
            },
        )
        .into_iter()
        .map(|f| f.labels)
        .collect()
    }

    #[test]
    fn with_a_margin_a_character_whose_errors_cross_by_less_never_flips() {
        // 12 frames, the scale wobbling 2.00, 2.01, 2.00, ...: the better
        // setting alternates every frame, each better than the other by 0.02.
        let frames: Vec<FrameInput> = (0..12)
            .map(|k| frame(2.0 + 0.01 * (k % 2) as f64))
            .collect();
        let without = run(&frames, 0.0);
        let with = run(&frames, 0.05);
        assert_eq!(
            switch_counts(&without, 1),
            vec![11],
            "without hysteresis it flips every frame: {without:?}"
        );
        assert_eq!(
            switch_counts(&with, 1),
            vec![0],
            "a 0.02 gain does not pay a 0.05 margin: {with:?}"
        );
        // Under the crossing the margin does not hold: a 0.02 gain pays 0.01.
        let small = run(&frames, 0.01);
        assert_eq!(switch_counts(&small, 1), vec![11]);
    }

    #[test]
    fn a_gain_beyond_the_margin_switches_once() {
        // "wobbly" is better by 0.02 on odd frames only; from frame 6 on
        // "steady" is gone (its accuracy unmeasured there: error none's 1),
        // a gain of 0.48: one switch, then held.
        struct Drop;
        impl Accuracy for Drop {
            fn predict(&self, m: &str, s: &str, x: f64, l: f64, sh: f64) -> Option<(f64, f64)> {
                if s == "steady" && x > 2.5 {
                    return None;
                }
                Crossing.predict(m, s, x, l, sh)
            }
        }
        let frames: Vec<FrameInput> = (0..12)
            .map(|k| frame(if k < 6 { 2.0 } else { 3.01 }))
            .collect();
        let labels: Vec<Vec<Option<(String, String)>>> = replan(
            &frames,
            &Replan {
                accuracy: &Drop,
                budget_ms: 1.0,
                switch_margin: 0.05,
                node_limit: None,
                look_ahead: 0,
            },
        )
        .into_iter()
        .map(|f| f.labels)
        .collect();
        let s = switches(&labels);
        assert_eq!(s.len(), 1, "{labels:?}");
        assert_eq!(s[0].frame, 6);
        assert_eq!(s[0].to.as_ref().map(|l| l.1.as_str()), Some("wobbly"));
    }

    #[test]
    fn looking_ahead_a_choice_the_budget_takes_back_next_frame_is_not_made() {
        // "wobbly" (0.48 on odd frames, else 0.52: take frame 1 at 2.01
        // px/mm) fits the budget at frames 0-1 and not from frame 2 on, its
        // part growing; "steady" at 0.50 always fits. Frame 1 alone would
        // switch to "wobbly" (a 0.02 gain over a 0.01 margin) and the budget
        // would take it back at frame 2; looking one frame ahead, never.
        let frames: Vec<FrameInput> = (0..4)
            .map(|k| {
                let mut f = frame(if k == 1 { 2.01 } else { 2.0 });
                f.costs[1].parts_ms = vec![Some(if k < 2 { 0.5 } else { 2.0 })];
                f
            })
            .collect();
        let go = |look_ahead| -> Vec<Vec<Option<(String, String)>>> {
            replan(
                &frames,
                &Replan {
                    accuracy: &Crossing,
                    budget_ms: 1.0,
                    switch_margin: 0.01,
                    node_limit: None,
                    look_ahead,
                },
            )
            .into_iter()
            .map(|f| f.labels)
            .collect()
        };
        let (now, ahead) = (go(0), go(1));
        assert_eq!(switch_counts(&now, 1), vec![2], "{now:?}");
        assert_eq!(switch_counts(&ahead, 1), vec![0], "{ahead:?}");
        // The costs planned against: the highest over the frames looked at.
        let c = planning_costs(&frames, 1, 1);
        assert_eq!(c[1].parts_ms, vec![Some(2.0)]);
        assert_eq!(planning_costs(&frames, 3, 5)[1].parts_ms, vec![Some(2.0)]);
        assert_eq!(planning_costs(&frames, 0, 1)[1].parts_ms, vec![Some(0.5)]);
    }

    #[test]
    fn the_change_counts_only_pixels_of_the_character_in_both_frames() {
        let a = vec![
            [0.1, 0.1, 0.1, 1.0],
            [0.2, 0.2, 0.2, 1.0],
            [0.5, 0.5, 0.5, 1.0],
        ];
        let b = vec![
            [0.4, 0.1, 0.1, 1.0],
            [0.9, 0.9, 0.9, 1.0],
            [0.5, 0.5, 0.5, 1.0],
        ];
        // Pixel 1 changes owner (character 1 then 2): left out of both.
        let c = changes(&a, &b, &[1, 1, 2], &[1, 2, 2], 2).unwrap();
        assert_eq!(c[0].pixels, 1);
        assert!((c[0].mean_abs - 0.1).abs() < 1e-7, "{c:?}");
        assert_eq!((c[1].pixels, c[1].mean_abs), (1, 0.0));
        assert!(changes(&a, &b[..2], &[1, 1, 2], &[1, 2, 2], 2).is_err());
        // A switch's pop against the truth's change, and the character's
        // excess at its other frames.
        let ch = |pixels, mean_abs| Change {
            pixels,
            mean_abs,
            mean_level: 0.5,
        };
        let plan = vec![
            vec![],
            vec![ch(10, 0.010)],
            vec![ch(10, 0.030)],
            vec![ch(10, 0.012)],
        ];
        let truth = vec![
            vec![],
            vec![ch(10, 0.009)],
            vec![ch(10, 0.010)],
            vec![ch(10, 0.010)],
        ];
        let s = vec![Switch {
            frame: 2,
            character: 0,
            from: "a".to_string(),
            to: "b".to_string(),
        }];
        let p = pops(&s, &[1], &[None], &plan, &truth);
        assert_eq!(p.len(), 1);
        assert!((p[0].excess - 0.020).abs() < 1e-12);
        assert!((p[0].relative_excess - 0.04).abs() < 1e-12);
        assert!((p[0].excess_elsewhere.unwrap() - 0.002).abs() < 1e-12);
        assert_eq!((p[0].spread_frames, p[0].measured_frame), (1, 2));
        // Spread over frames 2 and 3 (a one-frame fade): the larger excess of
        // the two is the switch's, and only frame 1 is "elsewhere".
        let p = pops(&s, &[2], &[Some((0.008, 0.5))], &plan, &truth);
        assert_eq!((p[0].spread_frames, p[0].measured_frame), (2, 2));
        assert!((p[0].excess_elsewhere.unwrap() - 0.001).abs() < 1e-12);
        // Measured, the switch's own step decides: 0.004 at one frame is
        // within the bound though the excess (0.020) is not.
        assert_eq!((p[0].jump, p[0].step), (Some(0.008), Some(0.004)));
        assert!(!p[0].pops());
        let p = pops(&s, &[1], &[Some((0.008, 1.0))], &plan, &truth);
        assert!(p[0].pops());
        let p = pops(&s, &[1], &[None], &plan, &truth);
        assert!(
            p[0].pops(),
            "unmeasured: excess 0.020 over the bound and over 0.002"
        );
    }

    #[test]
    fn the_walk_goes_from_nothing_to_all_of_it() {
        let w = Walk::new(5, 2.0).unwrap();
        assert_eq!((w.at(0), w.at(2), w.at(4)), (0.0, 1.0, 2.0));
        assert!(Walk::new(1, 1.0).is_err() && Walk::new(4, f32::NAN).is_err());
        assert!(Walk::new(4, 1e30).is_err() && Walk::new(4, -1000.0).is_ok());
    }
}
