//! The planner (issue 16, item 4): per character the method setting that
//! minimises the skin-area-weighted predicted error, with the modelled
//! skin-SSS cost (each character's part plus the fixed cost of every group
//! used) within the budget.
//!
//! The problem is a multiple-choice knapsack with set-up costs (a setting's
//! fixed cost is paid once by the first character that uses it). The solver
//! is an exact branch and bound:
//! - characters are visited in descending order of what their choice can
//!   change (weight times the spread of their options' errors);
//! - at each node the remaining characters are bounded below by the LP
//!   relaxation of the multiple-choice knapsack (each character's options on
//!   their lower convex hull in (cost, error), the hull's segments taken in
//!   order of slope until the remaining budget is spent, the last one
//!   fractionally), with the fixed costs of the groups not yet opened
//!   relaxed to 0: every completion costs at least its parts, so this is a
//!   valid lower bound, and the LP of a multiple-choice knapsack is the best
//!   Lagrangian bound of it (one multiplier on the budget);
//! - options are tried best first by the root's Lagrangian price
//!   (`error + lambda cost`), so the first leaves reached are good
//!   incumbents; a node whose bound cannot beat the incumbent is cut.
//!
//! With no node limit it is exact (the unit tests hold it to brute force on
//! random instances of up to 8 characters, several budgets, fixed costs
//! included). With the limit ([`Problem::node_limit`]) reached, the best
//! plan found is returned with `optimal: false` and the root's LP bound, so
//! the gap to the optimum is known. Pure: no device.
//!
//! Hysteresis (re-planning frame to frame): with a previous assignment, an
//! option other than a character's previous one has `switch_margin` times
//! the character's weight added to its error, so a character switches only
//! when the switch gains more than the margin (the objective reported is the
//! error without the margin); and a setting other than its previous one
//! (none excepted: dropping frees time) must fit with `switch_margin` times
//! the budget left over, so what a frame takes on is not taken back the next
//! frame because every character's part grew a little (the crowd walking
//! nearer) or an estimate moved (the cost reported is without the reserve).
//! Without the reserve, a 16-character walk filled its last percent of
//! budget with a small character and dropped it the frame after, three
//! times over five frames (docs/plan-over-time.md).

use serde::Serialize;

/// One option of one character: a setting (index into the problem's
/// settings) or none (no SSS).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Opt {
    /// `None`: no SSS (cost 0, error 1 by the definition of err/none).
    pub setting: Option<usize>,
    /// The character's part of the cost (ms).
    pub cost_ms: f64,
    /// Predicted err/none over the character's skin.
    pub error: f64,
}

/// What the solver is given.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Per character: its weight (skin pixels) and options (none among them).
    pub weights: Vec<f64>,
    pub options: Vec<Vec<Opt>>,
    /// Per setting: the fixed cost of its group (ms).
    pub fixed_ms: Vec<f64>,
    pub budget_ms: f64,
    /// The previous frame's choice of every character (re-planning).
    pub previous: Option<Vec<Option<usize>>>,
    /// Error (err/none, per unit of weight) a switch must gain.
    pub switch_margin: f64,
    /// Nodes to explore before giving up proving optimality (`None`: exact).
    pub node_limit: Option<u64>,
}

/// The plan.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Solution {
    /// Per character, the setting chosen (`None`: no SSS).
    pub choice: Vec<Option<usize>>,
    /// Modelled cost: parts plus the used groups' fixed costs.
    pub cost_ms: f64,
    /// Skin-weighted mean predicted err/none (weights normalised).
    pub error: f64,
    /// The root's LP (Lagrangian) lower bound of `error` (`None` with a
    /// switching margin: the bound is then of the margined objective).
    pub lower_bound: Option<f64>,
    /// Whether the search finished (the plan is optimal).
    pub optimal: bool,
    pub nodes: u64,
}

const EPS: f64 = 1e-12;

/// The LP relaxation of some characters (group fixed costs relaxed to 0):
/// their cheapest options' error `base`, then their hull segments by slope
/// as cumulative cost and error (`cost[0] = err[0] = 0`).
#[derive(Clone, Debug, Default)]
struct LpTable {
    base: f64,
    cost: Vec<f64>,
    err: Vec<f64>,
}

impl LpTable {
    fn of(hulls: &[(f64, Vec<(f64, f64)>)]) -> LpTable {
        let mut segs: Vec<(f64, f64)> = hulls.iter().flat_map(|h| h.1.iter().copied()).collect();
        segs.sort_by(|a, b| (a.1 / a.0.max(EPS)).total_cmp(&(b.1 / b.0.max(EPS))));
        let mut t = LpTable {
            base: hulls.iter().map(|h| h.0).sum(),
            cost: vec![0.0],
            err: vec![0.0],
        };
        for (dc, de) in segs {
            let (c, e) = (t.cost[t.cost.len() - 1], t.err[t.err.len() - 1]);
            t.cost.push(c + dc);
            t.err.push(e + de);
        }
        t
    }
}

struct Search<'a> {
    p: &'a Problem,
    order: Vec<usize>,
    /// Per character, options sorted best first; costs and (weighted) errors.
    opts: Vec<Vec<(Option<usize>, f64, f64)>>,
    /// Per depth, the LP table of the characters from it on.
    tables: Vec<LpTable>,
    best: Option<(f64, Vec<Option<usize>>)>,
    nodes: u64,
    stopped: bool,
}

impl Search<'_> {
    /// LP bound of the characters at depth >= `d` with `budget` left: the
    /// prefix sums of their hull segments (by slope) searched for the budget,
    /// the last segment taken fractionally.
    fn bound(&self, d: usize, budget: f64) -> f64 {
        let t = &self.tables[d];
        // Segments [0, k) fit whole: the last k with cumulative cost <= budget.
        let k = t.cost.partition_point(|&c| c <= budget + EPS);
        let mut err = t.base + t.err[k - 1];
        if k < t.cost.len() {
            let (c0, c1) = (t.cost[k - 1], t.cost[k]);
            let (e0, e1) = (t.err[k - 1], t.err[k]);
            err += (e1 - e0) * ((budget - c0) / (c1 - c0)).clamp(0.0, 1.0);
        }
        err
    }

    fn go(
        &mut self,
        d: usize,
        cost: f64,
        err: f64,
        open: &mut Vec<bool>,
        pick: &mut Vec<Option<usize>>,
    ) {
        self.nodes += 1;
        if let Some(limit) = self.p.node_limit {
            if self.nodes > limit {
                self.stopped = true;
                return;
            }
        }
        if d == self.order.len() {
            if self.best.as_ref().is_none_or(|(b, _)| err < *b - EPS) {
                self.best = Some((err, pick.clone()));
            }
            return;
        }
        let c = self.order[d];
        for oi in 0..self.opts[c].len() {
            if self.stopped {
                return;
            }
            let (s, oc, oe) = self.opts[c][oi];
            let fixed = match s {
                Some(s) if !open[s] => self.p.fixed_ms[s],
                _ => 0.0,
            };
            let new_cost = cost + oc + fixed;
            if new_cost > self.p.budget_ms + EPS {
                continue;
            }
            let new_err = err + oe;
            if let Some((b, _)) = &self.best {
                let lb = new_err + self.bound(d + 1, self.p.budget_ms - new_cost);
                if lb >= *b - EPS {
                    continue;
                }
            }
            let opened = matches!(s, Some(s) if !open[s]);
            if let (true, Some(s)) = (opened, s) {
                open[s] = true;
            }
            pick[c] = s;
            self.go(d + 1, new_cost, new_err, open, pick);
            if let (true, Some(s)) = (opened, s) {
                open[s] = false;
            }
        }
    }
}

/// The lower convex hull of `(cost, error)` points from the cheapest, as
/// segments of decreasing error per ms (dominated points dropped).
fn hull(points: &[(f64, f64)]) -> (f64, Vec<(f64, f64)>) {
    let mut pts: Vec<(f64, f64)> = points.to_vec();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let start = pts[0];
    let mut h: Vec<(f64, f64)> = vec![start];
    for &q in &pts[1..] {
        if q.1 >= h[h.len() - 1].1 - EPS {
            continue; // costs more, no better
        }
        while h.len() >= 2 {
            let (a, b) = (h[h.len() - 2], h[h.len() - 1]);
            // b is above the segment a-q: drop it.
            let cross = (b.0 - a.0) * (q.1 - a.1) - (b.1 - a.1) * (q.0 - a.0);
            if cross <= 0.0 {
                h.pop();
            } else {
                break;
            }
        }
        h.push(q);
    }
    let segs = h
        .windows(2)
        .map(|w| (w[1].0 - w[0].0, w[1].1 - w[0].1))
        .collect();
    (start.1, segs)
}

/// The first incumbent: the best of no SSS and, for each setting, that
/// setting alone given greedily (most error saved per ms first) to every
/// character it fits within the budget: the plan is never worse than the
/// best uniform assignment the model can afford.
fn seed(p: &Problem, opts: &[Vec<(Option<usize>, f64, f64)>]) -> (f64, Vec<Option<usize>>) {
    let none =
        |o: &[(Option<usize>, f64, f64)]| o.iter().find(|x| x.0.is_none()).map_or(0.0, |x| x.2);
    let all_none: f64 = opts.iter().map(|o| none(o)).sum();
    let mut best = (all_none, vec![None; opts.len()]);
    for s in 0..p.fixed_ms.len() {
        let mut gains: Vec<(usize, f64, f64)> = opts
            .iter()
            .enumerate()
            .filter_map(|(c, o)| {
                let x = o.iter().find(|x| x.0 == Some(s))?;
                let g = none(o) - x.2;
                (g > 0.0).then_some((c, x.1, g))
            })
            .collect();
        gains.sort_by(|a, b| (b.2 / b.1.max(EPS)).total_cmp(&(a.2 / a.1.max(EPS))));
        let mut cost = p.fixed_ms[s];
        let mut err = all_none;
        let mut pick = vec![None; opts.len()];
        for (c, dc, g) in gains {
            if cost + dc <= p.budget_ms + EPS {
                cost += dc;
                err -= g;
                pick[c] = Some(s);
            }
        }
        if pick.iter().any(Option::is_some) && err < best.0 - EPS {
            best = (err, pick);
        }
    }
    best
}

/// Solves `p` (see the module docs). Characters with no option under the
/// budget keep none; the problem always has a solution (all none, cost 0).
pub fn solve(p: &Problem) -> Solution {
    let n = p.weights.len();
    let wsum: f64 = p.weights.iter().sum::<f64>().max(EPS);
    // Weighted errors, the switching margin added where it applies.
    let opts: Vec<Vec<(Option<usize>, f64, f64)>> = (0..n)
        .map(|c| {
            let w = p.weights[c] / wsum;
            let mut o: Vec<(Option<usize>, f64, f64)> = p.options[c]
                .iter()
                .filter(|o| o.cost_ms.is_finite() && o.error.is_finite())
                .map(|o| {
                    let switched = matches!(
                        &p.previous,
                        Some(prev) if prev.get(c).copied().flatten() != o.setting
                    );
                    let (switch, reserve) = if switched {
                        (p.switch_margin * w, p.switch_margin * p.budget_ms)
                    } else {
                        (0.0, 0.0)
                    };
                    (
                        o.setting,
                        o.cost_ms.max(0.0) + reserve,
                        o.error * w + switch,
                    )
                })
                .collect();
            if !o.iter().any(|x| x.0.is_none()) {
                let switch = match &p.previous {
                    Some(prev) if prev.get(c).copied().flatten().is_some() => p.switch_margin * w,
                    _ => 0.0,
                };
                o.push((None, 0.0, w + switch));
            }
            o
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    let spread = |c: usize| {
        let e = opts[c].iter().map(|x| x.2);
        e.clone().fold(f64::MIN, f64::max) - e.fold(f64::MAX, f64::min)
    };
    order.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)));
    let m = p.fixed_ms.len();
    let hulls: Vec<(f64, Vec<(f64, f64)>)> = opts
        .iter()
        .map(|o| hull(&o.iter().map(|x| (x.1, x.2)).collect::<Vec<_>>()))
        .collect();
    let ordered: Vec<(f64, Vec<(f64, f64)>)> = order.iter().map(|&c| hulls[c].clone()).collect();
    let tables: Vec<LpTable> = (0..=n).map(|d| LpTable::of(&ordered[d..])).collect();
    // The root's Lagrangian price: the slope where the root LP runs out of budget.
    let lambda = {
        let t = &tables[0];
        let k = t.cost.partition_point(|&c| c <= p.budget_ms + EPS);
        if k < t.cost.len() {
            -(t.err[k] - t.err[k - 1]) / (t.cost[k] - t.cost[k - 1]).max(EPS)
        } else {
            0.0
        }
    };
    let mut sorted = opts.clone();
    for o in &mut sorted {
        o.sort_by(|a, b| (a.2 + lambda * a.1).total_cmp(&(b.2 + lambda * b.1)));
    }
    let mut s = Search {
        p,
        order,
        opts: sorted,
        tables,
        best: None,
        nodes: 0,
        stopped: false,
    };
    s.best = Some(seed(p, &opts));
    let mut open = vec![false; m];
    let root_bound = s.bound(0, p.budget_ms);
    let mut pick = vec![None; n];
    s.go(0, 0.0, 0.0, &mut open, &mut pick);
    let choice = s.best.map(|b| b.1).unwrap_or_else(|| vec![None; n]);
    let evaluate = |choice: &[Option<usize>]| -> (f64, f64) {
        let mut cost = 0.0;
        let mut err = 0.0;
        let mut used = vec![false; p.fixed_ms.len()];
        for (c, &ch) in choice.iter().enumerate() {
            let o = p.options[c].iter().find(|o| o.setting == ch);
            cost += o.map_or(0.0, |o| o.cost_ms);
            err += o.map_or(1.0, |o| o.error) * p.weights[c] / wsum;
            if let Some(s) = ch {
                used[s] = true;
            }
        }
        cost += used
            .iter()
            .zip(&p.fixed_ms)
            .filter(|(u, _)| **u)
            .map(|(_, f)| f)
            .sum::<f64>();
        (cost, err)
    };
    let (cost_ms, error) = evaluate(&choice);
    Solution {
        choice,
        cost_ms,
        error,
        // Without a margin the LP bound is a bound of `error` itself.
        lower_bound: p.previous.is_none().then_some(root_bound),
        optimal: !s.stopped,
        nodes: s.nodes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64*: deterministic instances without a dependency.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn instance(r: &mut Rng, n: usize, m: usize) -> Problem {
        let mut options = Vec::new();
        for _ in 0..n {
            let mut o = vec![Opt {
                setting: None,
                cost_ms: 0.0,
                error: 1.0,
            }];
            for s in 0..m {
                if r.next() < 0.75 {
                    o.push(Opt {
                        setting: Some(s),
                        cost_ms: 0.05 + r.next(),
                        error: 0.1 + 0.9 * r.next(),
                    });
                }
            }
            options.push(o);
        }
        Problem {
            weights: (0..n).map(|_| 100.0 + 1e4 * r.next()).collect(),
            options,
            fixed_ms: (0..m).map(|_| 0.5 * r.next()).collect(),
            budget_ms: 0.0,
            previous: None,
            switch_margin: 0.0,
            node_limit: None,
        }
    }

    /// Every assignment: the optimum by enumeration.
    fn brute(p: &Problem) -> (f64, f64) {
        let n = p.weights.len();
        let wsum: f64 = p.weights.iter().sum();
        let mut idx = vec![0usize; n];
        let mut best = (f64::INFINITY, 0.0);
        loop {
            let mut cost = 0.0;
            let mut err = 0.0;
            let mut used = vec![false; p.fixed_ms.len()];
            for (c, &i) in idx.iter().enumerate() {
                let o = p.options[c][i];
                cost += o.cost_ms;
                err += o.error * p.weights[c] / wsum;
                if let Some(s) = o.setting {
                    used[s] = true;
                }
            }
            cost += (0..used.len())
                .filter(|&s| used[s])
                .map(|s| p.fixed_ms[s])
                .sum::<f64>();
            if cost <= p.budget_ms + 1e-12 && err < best.0 {
                best = (err, cost);
            }
            let mut c = 0;
            loop {
                if c == n {
                    return best;
                }
                idx[c] += 1;
                if idx[c] < p.options[c].len() {
                    break;
                }
                idx[c] = 0;
                c += 1;
            }
        }
    }

    #[test]
    fn exact_against_brute_force_up_to_8_characters() {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        let mut checked = 0;
        for n in 1..=8 {
            for _ in 0..12 {
                let mut p = instance(&mut r, n, 4);
                for frac in [0.0, 0.1, 0.3, 0.6, 1.0] {
                    // Budgets from nothing to enough for every character's dearest option.
                    p.budget_ms = frac * (n as f64 * 1.05 + 2.0);
                    let s = solve(&p);
                    let (want, _) = brute(&p);
                    assert!(s.optimal);
                    assert!(
                        (s.error - want).abs() < 1e-9,
                        "n {n} budget {}: solver {} brute force {want}",
                        p.budget_ms,
                        s.error
                    );
                    assert!(s.cost_ms <= p.budget_ms + 1e-9, "over budget");
                    let lb = s.lower_bound.unwrap();
                    assert!(
                        lb <= s.error + 1e-9,
                        "bound {lb} above the optimum {}",
                        s.error
                    );
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 8 * 12 * 5);
    }

    #[test]
    fn a_node_limit_keeps_the_budget_and_says_it_stopped() {
        let mut r = Rng(42);
        let mut p = instance(&mut r, 40, 8);
        p.budget_ms = 6.0;
        p.node_limit = Some(50);
        let s = solve(&p);
        assert!(!s.optimal);
        assert!(s.cost_ms <= p.budget_ms + 1e-9);
        assert!(s.lower_bound.unwrap() <= s.error + 1e-9);
    }

    /// One character with no SSS and `settings` as `(cost ms, err/none)`,
    /// settings indexed in order, no fixed costs, planned afresh.
    fn one_character(settings: &[(f64, f64)], budget_ms: f64) -> Problem {
        let none = Opt {
            setting: None,
            cost_ms: 0.0,
            error: 1.0,
        };
        let opts = settings
            .iter()
            .enumerate()
            .map(|(i, &(cost_ms, error))| Opt {
                setting: Some(i),
                cost_ms,
                error,
            });
        Problem {
            weights: vec![1.0],
            options: vec![std::iter::once(none).chain(opts).collect()],
            fixed_ms: vec![0.0; settings.len()],
            budget_ms,
            previous: None,
            switch_margin: 0.0,
            node_limit: None,
        }
    }

    #[test]
    fn a_new_setting_must_leave_the_margin_of_the_budget_free() {
        // One character whose only setting costs 0.99 of a 1 ms budget.
        let p = Problem {
            switch_margin: 0.02,
            ..one_character(&[(0.99, 0.5)], 1.0)
        };
        // Planned afresh it fits.
        assert_eq!(solve(&p).choice, vec![Some(0)]);
        // Taken on from none it must leave 2% of the budget: 0.99 + 0.02 > 1.
        let from_none = Problem {
            previous: Some(vec![None]),
            ..p.clone()
        };
        assert_eq!(solve(&from_none).choice, vec![None]);
        // Kept, it costs what it costs, reported without the reserve.
        let kept = solve(&Problem {
            previous: Some(vec![Some(0)]),
            ..p.clone()
        });
        assert_eq!(kept.choice, vec![Some(0)]);
        assert!((kept.cost_ms - 0.99).abs() < 1e-12, "{}", kept.cost_ms);
        // With room to spare it is taken on.
        let cheaper = Problem {
            budget_ms: 1.05,
            ..from_none
        };
        assert_eq!(solve(&cheaper).choice, vec![Some(0)]);
    }

    #[test]
    fn the_switching_margin_keeps_a_previous_choice_unless_the_gain_exceeds_it() {
        // One character: setting 0 (err 0.50) and setting 1 (err 0.45), both affordable.
        let p = one_character(&[(0.1, 0.50), (0.1, 0.45)], 1.0);
        assert_eq!(solve(&p).choice, vec![Some(1)]);
        let held = Problem {
            previous: Some(vec![Some(0)]),
            switch_margin: 0.1,
            ..p.clone()
        };
        let s = solve(&held);
        assert_eq!(
            s.choice,
            vec![Some(0)],
            "a 0.05 gain does not pay a 0.1 margin"
        );
        assert!(
            (s.error - 0.50).abs() < 1e-12,
            "the objective is reported without the margin"
        );
        let switch = Problem {
            switch_margin: 0.01,
            ..held
        };
        assert_eq!(
            solve(&switch).choice,
            vec![Some(1)],
            "a 0.05 gain pays a 0.01 margin"
        );
    }

    #[test]
    fn plan_time_for_64_characters() {
        // 64 characters, 15 settings: the size of `dermis plan` on a 64-crowd.
        let mut r = Rng(7);
        let mut p = instance(&mut r, 64, 15);
        for budget in [0.5, 2.0, 8.0] {
            p.budget_ms = budget;
            p.node_limit = Some(20_000);
            let t = std::time::Instant::now();
            let s = solve(&p);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            println!(
                "64 characters, 15 settings, budget {budget} ms: plan in {ms:.3} ms, {} nodes, \
                 optimal {}, err {:.4}, bound {:.4}",
                s.nodes,
                s.optimal,
                s.error,
                s.lower_bound.unwrap()
            );
            assert!(s.cost_ms <= budget + 1e-9);
        }
    }
}
