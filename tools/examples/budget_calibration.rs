//! Prints the budget model's calibration (docs/budget-calibration.md): every
//! stored point priced on its profile, the fit, the held-out scores, the
//! fitted parameters ready to paste into `src/budget/params.rs`, and the worst
//! held-out benchmark rows with their terms.
//!
//! ```sh
//! cargo run --release --features tools --example budget_calibration        # ALL_ROWS=1: every benchmark row too
//! ```
//! `WORST=N` prints the N worst rows (default 40). It was the ignored unit test
//! `budget::calibration::tests::print_calibration`: it only prints, so it is a
//! program, not a test.

use anyhow::Result;
use dermis::budget::calibration::{calibrate, markdown, priced_points, Priced, Row};
use dermis::budget::params::ModelParams;
use dermis::budget::points::{Group, Select};

fn main() -> Result<()> {
    let (pts, skipped) = priced_points()?;
    for s in &skipped {
        println!("skipped: {s}");
    }
    let c = calibrate(&pts);
    println!("{}", markdown(&c, std::env::var_os("ALL_ROWS").is_some()));
    // Ready to paste into params.rs when the points change.
    let f = |m: &ModelParams| {
        let v = m.to_vec();
        let names = [
            "texture_scale",
            "alu_scale",
            "fill_scale",
            "memory_scale",
            "reject_scale",
            "hiz_reject_scale",
            "incoherent_factor",
            "fixed_kpix_per_pass",
            "rect_kpix",
            "incoherent_radius_px",
            "fixed_kpix_per_dispatch",
            "compute_alu_scale",
            "compute_incoherent_factor",
            "shared_scale",
        ];
        let fields: Vec<String> = names
            .iter()
            .zip(v)
            .map(|(n, x)| format!("{n}: {x:.5}"))
            .collect();
        format!("ModelParams {{ {} }}", fields.join(", "))
    };
    println!(
        "pub const FITTED: ParamSet = ParamSet {{ peak: {}, probed: {} }};",
        f(&c.fitted_all.peak),
        f(&c.fitted_all.probed)
    );
    println!("fitted (probed, first benchmark half): {:?}", c.fitted_half);
    let mut worst: Vec<(&Row, &Priced)> = c
        .rows
        .iter()
        .zip(&pts)
        .filter(|(r, _)| r.group == Group::Benchmark && r.held_out_error.is_some())
        .collect();
    worst.sort_by(|a, b| {
        b.0.held_out_error
            .unwrap_or(0.0)
            .total_cmp(&a.0.held_out_error.unwrap_or(0.0))
    });
    let n: usize = std::env::var("WORST")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(40);
    for (r, p) in worst.into_iter().take(n) {
        let t = p.units[0].scaled(&c.fitted_half);
        let frags = match &p.point.select {
            Select::Pass(i) => p.point.frame.passes[*i].fragments,
            _ => 0,
        };
        println!(
            "{} {:.4} {:.4} {:.0}% | frags {} tex {:.4} inc {:.4} alu {:.4} fill {:.4} mem {:.4} rej {:.4} hiz {:.4} clr {:.4} fix {:.4} rect {:.4}",
            r.id,
            r.measured_ms,
            r.held_out_ms.unwrap_or(0.0),
            r.held_out_error.unwrap_or(0.0) * 100.0,
            frags, t.texture, t.texture_incoherent, t.alu, t.fill, t.memory, t.reject, t.reject_hiz, t.clear, t.fixed_unit, t.copy_rects
        );
    }
    Ok(())
}
