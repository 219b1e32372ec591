//! Prints docs/perf/issue28/calibration.md's tables: every pass of issue 28's
//! H100 runs (`points::ISSUE28_FIT`, the compute passes and the raster passes
//! of the same reports), the model against the measurement, in sample (the
//! fitted parameters, `ParamSet::fitted`) and held out (the probed set fitted
//! again without the gather's runs: the gather's rows are then out of that
//! fit); then the runs in no fit (`points::ISSUE28_HELD_OUT`: 1080p mid, 4K).
//!
//! ```sh
//! cargo run --release --features tools --example issue28_calibration
//! ```
//! `TERMS=1` adds each pass's terms (ms, fitted parameters applied).

use anyhow::Result;
use dermis::budget::calibration::{fit, price_point, priced_points, Priced};
use dermis::budget::params::{ModelParams, ParamSet};
use dermis::budget::points::{issue28_held_out, Select, ISSUE28_SET};
use dermis::budget::profile::{Profile, RateSource};

fn pass_name(p: &Priced) -> String {
    match p.point.select {
        Select::Pass(i) => p.point.frame.passes[i].name.clone(),
        _ => p.point.id.clone(),
    }
}

fn terms(p: &Priced, m: &ModelParams) -> String {
    let t = p.units[0].scaled(m);
    format!(
        " tex {:.4} inc {:.4} alu {:.4} fill {:.4} mem {:.4} shared {:.4} fixed {:.4} clear {:.4} rej {:.4} geo {:.4}",
        t.texture, t.texture_incoherent, t.alu, t.fill, t.memory, t.shared, t.fixed_unit, t.clear,
        t.reject, t.geometry
    )
}

fn main() -> Result<()> {
    let show_terms = std::env::var_os("TERMS").is_some();
    let (pts, skipped) = priced_points()?;
    for s in &skipped {
        println!("skipped: {s}");
    }
    let is_gather = |p: &Priced| p.point.set == ISSUE28_SET && p.point.file.contains("gather");
    let probed: Vec<&Priced> = pts
        .iter()
        .filter(|p| p.rates == RateSource::Probed)
        .collect();
    let without: Vec<&Priced> = probed.iter().copied().filter(|p| !is_gather(p)).collect();
    let all = ParamSet::fitted().probed;
    let held = fit(&without);
    println!("fitted (probed, every point): {all:?}");
    println!("fitted (probed, without the gather's runs): {held:?}\n");
    println!("| run | pass | measured ms | model ms | model / measured | without the gather: model ms | ratio | |");
    println!("|---|---|---|---|---|---|---|---|");
    for p in pts.iter().filter(|p| p.point.set == ISSUE28_SET) {
        let (m, h) = (p.predict(&all), p.predict(&held));
        let ms = p.point.measured_ms;
        println!(
            "| {} | {} | {:.4} | {:.4} | {:.2} | {:.4} | {:.2} | {} |{}",
            p.point.file,
            pass_name(p),
            ms,
            m,
            m / ms,
            h,
            h / ms,
            if is_gather(p) {
                "held out"
            } else {
                "in sample"
            },
            if show_terms {
                terms(p, &all)
            } else {
                String::new()
            }
        );
    }
    let prof = Profile::load("nvidia-h100")?;
    println!("\nIn no fit (out of sample):\n");
    println!("| run | pass | measured ms | model ms | model / measured |");
    println!("|---|---|---|---|---|");
    for point in issue28_held_out()? {
        let p = price_point(point, &prof);
        let (m, ms) = (p.predict(&all), p.point.measured_ms);
        println!(
            "| {} | {} | {:.4} | {:.4} | {:.2} |{}",
            p.point.file,
            pass_name(&p),
            ms,
            m,
            m / ms,
            if show_terms {
                terms(&p, &all)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}
