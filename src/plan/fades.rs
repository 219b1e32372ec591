//! Cross-fading a re-planned sequence's switches (issue 16 item 6): which
//! characters fade at which frame and by how much ([`fades`]), over how many
//! frames a switch's change is then spread ([`spreads`]) and the largest share
//! of it one frame shows ([`largest_share_step`]), and what the fades add to
//! a frame's modelled cost ([`fade_cost_ms`]). The renderer draws a fade from
//! a plan file's `fade` (`mix::Fade`); `motion.rs` measures it.
//!
//! Pure: no device (tests/suite/layers.rs holds it to it).

use anyhow::{bail, Result};
use serde::Serialize;

use super::choose::SettingCosts;
use super::over_time::Switch;

/// The largest change of the old setting's share at one frame of a switch's
/// spread (1 before the switch, the fade's weights, 0 after), over the
/// frames `has_pixels` says show the character: 1 for a hard switch, 1/(F+1)
/// for a whole fade of F frames.
pub fn largest_share_step(
    s: &Switch<String>,
    spread: usize,
    fades: &[Vec<Option<FadeAt>>],
    has_pixels: impl Fn(usize) -> bool,
) -> f64 {
    let share = |k: usize| -> f64 {
        if k < s.frame {
            return 1.0;
        }
        fades
            .get(k)
            .and_then(|f| f.get(s.character))
            .and_then(|f| f.as_ref())
            .map_or(0.0, |f| f.weight)
    };
    (s.frame..s.frame + spread.max(1))
        .filter(|&k| has_pixels(k))
        .map(|k| share(k - 1) - share(k))
        .fold(0.0, f64::max)
}

/// The fade `dermis plan-motion` uses unless told: 3 frames (the old
/// setting's share 3/4, 1/2, 1/4), so a switch's change is spread over four
/// equal steps, a tenth of a second at 30 Hz.
pub const DEFAULT_FADE_FRAMES: usize = 3;

/// The most frames a fade may take.
pub const MAX_FADE_FRAMES: usize = 60;

/// Checks a fade length (`--fade-frames`).
pub fn check_fade_frames(f: usize) -> Result<()> {
    if f > MAX_FADE_FRAMES {
        bail!("--fade-frames must be within 0..={MAX_FADE_FRAMES}, got {f}");
    }
    Ok(())
}

/// A character fading at one frame: the setting it fades from (`None`: no
/// SSS) and that setting's share of its result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FadeAt {
    pub from: Option<(String, String)>,
    pub weight: f64,
}

/// Per frame and character, the cross-fades of a sequence's switches
/// (`labels[frame][character]`, the plan's settings) over `fade_frames`
/// frames: a switch at frame `j` of a character on screen at `j - 1`
/// (`on_screen`: the planner's estimate of its skin pixels, what a game
/// knows) keeps its old setting at `j..j + fade_frames` with the share
/// `(F - t) / (F + 1)` at frame `j + t` (3 frames: 3/4, 1/2, 1/4), so the
/// change is spread over `F + 1` equal steps. The fade runs its frames
/// whether or not the estimate still sees the character (it drops slivers
/// under 5% of a character's skin that the frame may show: a switch to none
/// for want of skin must fade too; a fade off screen has no pixel to work
/// on). Switching again starts a fade from the setting it had the frame
/// before (the old fade is dropped). A switch between two settings of one
/// method (separable's 33 and 17 samples) is not faded: measured on the
/// walks of docs/plan-over-time.md, such a switch changes its character by
/// under 0.0001 (the flicker bound is 0.005), while its fade would run the
/// old setting whole for F frames (up to 0.65 ms on the Xbox 360 there); the
/// switch is still measured and a pop would show. 0 frames: no fade.
pub fn fades(
    labels: &[Vec<Option<(String, String)>>],
    on_screen: &[Vec<bool>],
    fade_frames: usize,
) -> Vec<Vec<Option<FadeAt>>> {
    let n = labels.first().map_or(0, Vec::len);
    let mut out = vec![vec![None; n]; labels.len()];
    if fade_frames == 0 {
        return out;
    }
    let seen = |k: usize, c: usize| on_screen.get(k).and_then(|f| f.get(c)).copied() == Some(true);
    for c in 0..n {
        // (setting faded from, first frame of the fade)
        let mut current: Option<(Option<(String, String)>, usize)> = None;
        for k in 1..labels.len() {
            if labels[k][c] != labels[k - 1][c] {
                let (a, b) = (&labels[k - 1][c], &labels[k][c]);
                current = (seen(k - 1, c) && !same_method(a, b)).then(|| (a.clone(), k));
            }
            if let Some((from, j)) = &current {
                let t = k - j;
                if t < fade_frames {
                    out[k][c] = Some(FadeAt {
                        from: from.clone(),
                        weight: (fade_frames - t) as f64 / (fade_frames + 1) as f64,
                    });
                } else {
                    current = None;
                }
            }
        }
    }
    out
}

/// Whether two settings are of one method (neither none).
fn same_method(a: &Option<(String, String)>, b: &Option<(String, String)>) -> bool {
    matches!((a, b), (Some(a), Some(b)) if a.0 == b.0)
}

/// The frames each switch's change is spread over, for [`pops`]: 1 + the
/// frames of its fade (a fade cut short by another switch or by leaving the
/// screen counts the frames it ran).
pub fn spreads(switches: &[Switch<String>], fades: &[Vec<Option<FadeAt>>]) -> Vec<usize> {
    switches
        .iter()
        .map(|s| {
            let faded = (s.frame..fades.len())
                .take_while(|&k| {
                    fades[k].get(s.character).is_some_and(Option::is_some)
                        && (k == s.frame
                            || fades[k][s.character].as_ref().map(|f| f.weight)
                                < fades[k - 1][s.character].as_ref().map(|f| f.weight))
                })
                .count();
            // A fade's last step, its share to 0, is the frame after it.
            if faded > 0 {
                (faded + 1).min(fades.len() - s.frame)
            } else {
                1
            }
        })
        .collect()
}

/// What the fades of one frame add to its modelled cost (ms): per fading
/// character its old setting's part and fixed cost (an instance of its
/// own), and per setting the fixed cost of every instance beyond the one
/// the plan counted (a fading character's group is apart from the others
/// that run its new setting). A character off screen (`on_screen`, the
/// estimate) has no part: its old setting has no pixel to work on. `None`
/// when an old setting is unpriced for a character on screen.
pub fn fade_cost_ms(
    costs: &[SettingCosts],
    labels: &[Option<(String, String)>],
    fades: &[Option<FadeAt>],
    on_screen: &[bool],
) -> Option<f64> {
    let index = |l: &(String, String)| {
        costs
            .iter()
            .position(|s| s.method == l.0 && s.setting == l.1)
    };
    let mut ms = 0.0;
    for (c, f) in fades.iter().enumerate() {
        if let Some(old) = f.as_ref().and_then(|f| f.from.as_ref()) {
            let s = &costs[index(old)?];
            let part = if on_screen.get(c).copied().unwrap_or(false) {
                s.parts_ms.get(c).copied().flatten()?
            } else {
                0.0
            };
            ms += part + s.fixed_ms;
        }
    }
    for (si, s) in costs.iter().enumerate() {
        let runs = |c: usize| labels[c].as_ref().and_then(index) == Some(si);
        let fading = (0..labels.len())
            .filter(|&c| runs(c) && fades.get(c).is_some_and(Option::is_some))
            .count();
        let others =
            (0..labels.len()).any(|c| runs(c) && !fades.get(c).is_some_and(Option::is_some));
        let instances = fading + usize::from(others);
        ms += instances.saturating_sub(1) as f64 * s.fixed_ms;
    }
    Some(ms)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::over_time::switches;

    fn l(s: &str) -> Option<(String, String)> {
        (s != "-").then(|| (s.to_string(), "x".to_string()))
    }

    #[test]
    fn a_switch_fades_in_equal_steps_while_on_screen() {
        // One character: a -> b at frame 2 (on screen at frame 1 only: the
        // fade runs on), b -> - at frame 7 (off screen from frame 2 on, so
        // that switch is not faded).
        let seq = ["a", "a", "b", "b", "b", "b", "b", "-", "-"];
        let labels: Vec<_> = seq.iter().map(|x| vec![l(x)]).collect();
        let on: Vec<_> = (0..seq.len()).map(|k| vec![k < 2]).collect();
        let f = fades(&labels, &on, 3);
        let w: Vec<Option<f64>> = f.iter().map(|x| x[0].as_ref().map(|f| f.weight)).collect();
        assert_eq!(
            w,
            [
                None,
                None,
                Some(0.75),
                Some(0.5),
                Some(0.25),
                None,
                None,
                None,
                None
            ]
        );
        assert_eq!(f[2][0].as_ref().unwrap().from, l("a"));
        assert!(fades(&labels, &on, 0).iter().all(|x| x[0].is_none()));
        let sw = switches(&seq.iter().map(|x| vec![x.to_string()]).collect::<Vec<_>>());
        assert_eq!(spreads(&sw, &f), [4, 1]);
        // Shares 1, 3/4, 1/2, 1/4, 0: a quarter at each of the four frames.
        assert_eq!(largest_share_step(&sw[0], 4, &f, |_| true), 0.25);
        // The hard switch to none at frame 7: all of it at once.
        assert_eq!(largest_share_step(&sw[1], 1, &f, |_| true), 1.0);
        // Off screen after the first fade frame: only 1 -> 3/4 is seen.
        assert_eq!(largest_share_step(&sw[0], 4, &f, |k| k == 2), 0.25);
        assert_eq!(largest_share_step(&sw[0], 4, &f, |_| false), 0.0);
        // Switching again mid-fade starts a new fade from the setting before.
        let seq = ["a", "b", "c", "c", "c"];
        let labels: Vec<_> = seq.iter().map(|x| vec![l(x)]).collect();
        let on = vec![vec![true]; 5];
        let f = fades(&labels, &on, 2);
        let got: Vec<_> = f
            .iter()
            .map(|x| x[0].as_ref().map(|f| (f.from.clone(), f.weight)))
            .collect();
        let third = 1.0 / 3.0;
        assert_eq!(
            got,
            [
                None,
                Some((l("a"), 2.0 * third)),
                Some((l("b"), 2.0 * third)),
                Some((l("b"), third)),
                None
            ]
        );
        let sw = switches(&seq.iter().map(|x| vec![x.to_string()]).collect::<Vec<_>>());
        // The cut fade's rest (a's last third) goes at frame 2, with the new one.
        assert_eq!(spreads(&sw, &f), [2, 3]);
        // Two settings of one method: no fade.
        let one = |s: &str| Some(("a".to_string(), s.to_string()));
        let labels = vec![vec![one("17")], vec![one("33")], vec![one("33")]];
        let f = fades(&labels, &vec![vec![true]; 3], 2);
        assert!(f.iter().all(|x| x[0].is_none()), "{f:?}");
    }

    #[test]
    fn a_fade_costs_the_old_setting_and_the_new_setting_s_second_instance() {
        let setting = |m: &str, fixed: f64, parts: [f64; 3]| SettingCosts {
            method: m.to_string(),
            setting: "x".to_string(),
            measured_as: "x".to_string(),
            fixed_ms: fixed,
            parts_ms: parts.iter().map(|&p| Some(p)).collect(),
            texel_mm: vec![None; 3],
        };
        let costs = vec![
            setting("a", 0.1, [1.0, 2.0, 3.0]),
            setting("b", 0.2, [0.5, 0.6, 0.7]),
        ];
        let labels = vec![l("b"), l("b"), l("a")];
        let fade = |from: &str| {
            Some(FadeAt {
                from: l(from),
                weight: 0.5,
            })
        };
        // Character 0 fades a -> b: a's part and fixed, and b's fixed again
        // (character 1 runs b in a group of its own).
        let on = [true; 3];
        let ms = fade_cost_ms(&costs, &labels, &[fade("a"), None, None], &on).unwrap();
        assert!((ms - (1.0 + 0.1 + 0.2)).abs() < 1e-12, "{ms}");
        // Off screen: no part, the instances' fixed costs only.
        let ms = fade_cost_ms(
            &costs,
            &labels,
            &[fade("a"), None, None],
            &[false, true, true],
        );
        assert!((ms.unwrap() - (0.1 + 0.2)).abs() < 1e-12, "{ms:?}");
        // From no SSS: only the second instance of b.
        let ms = fade_cost_ms(&costs, &labels, &[fade("-"), None, None], &on).unwrap();
        assert!((ms - 0.2).abs() < 1e-12, "{ms}");
        // Both b characters fading: two instances of b where the plan
        // counted one.
        let ms = fade_cost_ms(&costs, &labels, &[fade("-"), fade("-"), None], &on).unwrap();
        assert!((ms - 0.2).abs() < 1e-12, "{ms}");
        // Character 2 (a, alone in its group) fading from b: b's part and
        // fixed, and no second instance of a.
        let ms = fade_cost_ms(&costs, &labels, &[None, None, fade("b")], &on).unwrap();
        assert!((ms - (0.7 + 0.2)).abs() < 1e-12, "{ms}");
        let mut unpriced = costs.clone();
        unpriced[0].parts_ms[0] = None;
        assert!(fade_cost_ms(&unpriced, &labels, &[fade("a"), None, None], &on).is_none());
    }
}
