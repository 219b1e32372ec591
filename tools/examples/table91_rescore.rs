//! Table 9.1 re-scored (docs/aa.md, "Table 9.1 re-scored"; issue 17 item 7):
//! dermis's own MLAA passes, priced on the Xbox 360 and the 9800 GTX+ by
//! `dermis budget`, against the table's ten games. Reads the `budget.json` of
//! runs made with
//!
//! ```sh
//! dermis budget --device llvmpipe --as-run --aa mlaa \
//!   --profile xbox360,geforce-9800-gtx-plus --width 1280 --height 720 [scene] --out DIR
//! ```
//!
//! and prints the markdown tables:
//!
//! ```sh
//! cargo run --release --example table91_rescore -- face=DIR/budget.json lines=DIR2/budget.json ...
//! ```
//!
//! MLAA's time is its edges, weights and blend passes, without this port's copy
//! (the thesis blends into the back buffer that holds the frame); the edge
//! pixels are the weights pass's samples passed (the stencil the edges wrote).

use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use dermis::budget::table91::{fit_line, g92_floor_bound_ms, games_line, GRAND_AVERAGE_MS};
use serde_json::Value;

const PROFILES: [&str; 2] = ["xbox360", "geforce-9800-gtx-plus"];
const PASSES: [&str; 3] = ["mlaa edges", "mlaa weights", "mlaa blend"];

/// One priced frame: its label, edge pixels, frame pixels, and per profile
/// the three passes' ms and the copy's.
struct Frame {
    label: String,
    edges: f64,
    pixels: f64,
    ms: Vec<([f64; 3], f64)>,
}

fn read(label: &str, path: &PathBuf) -> Result<Frame> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let v: Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let run = &v["runs"][0];
    let frame = &run["frame"];
    let (w, h) = (frame["width"].as_f64(), frame["height"].as_f64());
    let pixels = w
        .zip(h)
        .map(|(w, h)| w * h)
        .context("the frame has no size")?;
    let passes = frame["passes"]
        .as_array()
        .context("the frame has no passes")?;
    let edges = passes
        .iter()
        .find(|p| p["name"] == "mlaa weights")
        .and_then(|p| p["samples_passed"].as_f64())
        .with_context(|| {
            format!(
                "{}: no mlaa weights pass (run with --aa mlaa)",
                path.display()
            )
        })?;
    let mut ms = Vec::new();
    for prof in PROFILES {
        let b = run["budgets"]
            .as_array()
            .and_then(|bs| bs.iter().find(|b| b["profile"] == prof))
            .with_context(|| format!("{}: not priced on {prof}", path.display()))?;
        let price = |name: &str| -> Result<f64> {
            b["passes"]
                .as_array()
                .and_then(|ps| ps.iter().find(|p| p["name"] == name))
                .and_then(|p| p["modelled_ms"].as_f64())
                .with_context(|| format!("{}: {name} unpriced on {prof}", path.display()))
        };
        ms.push((
            [price(PASSES[0])?, price(PASSES[1])?, price(PASSES[2])?],
            price("mlaa copy")?,
        ));
    }
    Ok(Frame {
        label: label.to_string(),
        edges,
        pixels,
        ms,
    })
}

fn main() -> Result<()> {
    let mut frames = Vec::new();
    for a in std::env::args().skip(1) {
        let Some((label, path)) = a.split_once('=') else {
            bail!("each argument is LABEL=budget.json, got {a:?}");
        };
        frames.push(read(label, &PathBuf::from(path))?);
    }
    if frames.len() < 3 {
        bail!("give at least three frames (LABEL=budget.json): a line needs them");
    }
    let total = |f: &Frame, i: usize| f.ms[i].0.iter().sum::<f64>();
    println!("| frame | edge pixels (share) | Xbox 360: edges / weights / blend, MLAA ms | 9800 GTX+: the same | Xbox 360 / 9800 GTX+ |");
    println!("|---|---|---|---|---|");
    for f in &frames {
        let cell = |i: usize| {
            let [e, w, b] = f.ms[i].0;
            format!(
                "{e:.3} / {w:.3} / {b:.3}, **{:.3}** (copy {:.3})",
                total(f, i),
                f.ms[i].1
            )
        };
        println!(
            "| {} | {} ({:.2}%) | {} | {} | {:.2} |",
            f.label,
            f.edges,
            100.0 * f.edges / f.pixels,
            cell(0),
            cell(1),
            total(f, 0) / total(f, 1)
        );
    }
    let games = games_line();
    println!();
    println!("| line | slope | intercept ms | r |");
    println!("|---|---|---|---|");
    println!(
        "| Table 9.1's ten games: Xbox 360 ms against 9800 GTX+ ms | {:.2} +- {:.2} | {:.2} +- {:.2} | {:.3} |",
        games.slope, games.slope_se, games.intercept, games.intercept_se, games.r
    );
    let pairs: Vec<(f64, f64)> = frames.iter().map(|f| (total(f, 1), total(f, 0))).collect();
    if let Some(m) = fit_line(&pairs) {
        println!(
            "| the model on these frames: the same | {:.2} | {:.2} | {:.3} |",
            m.slope, m.intercept, m.r
        );
    }
    println!();
    println!("| profile | modelled ms at no edge pixel | ns per edge pixel | edge share at the table's average |");
    println!("|---|---|---|---|");
    let published = [GRAND_AVERAGE_MS.0, GRAND_AVERAGE_MS.1];
    for (i, prof) in PROFILES.iter().enumerate() {
        let pts: Vec<(f64, f64)> = frames
            .iter()
            .map(|f| (f.edges / f.pixels, total(f, i)))
            .collect();
        let Some(l) = fit_line(&pts) else { continue };
        let meets = match l.reaches(published[i]) {
            Some(s) if s <= 1.0 => format!("{:.1}% for {:.2} ms", 100.0 * s, published[i]),
            Some(s) => format!(
                "none: {:.0}% of the pixels for {:.2} ms",
                100.0 * s,
                published[i]
            ),
            None => format!("none: above {:.2} ms at no edge", published[i]),
        };
        let px = frames[0].pixels;
        println!(
            "| {prof} | {:.3} | {:.2} | {meets} |",
            l.intercept,
            1e6 * l.slope / px
        );
    }
    println!();
    println!(
        "The 9800 GTX+'s content-independent MLAA work costs at most {:.2} ms (the table's fastest game).",
        g92_floor_bound_ms()
    );
    Ok(())
}
