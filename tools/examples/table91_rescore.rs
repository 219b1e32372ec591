//! Table 9.1 re-scored (docs/aa.md, "Table 9.1 re-scored"; issue 17 item 7):
//! dermis's own MLAA passes, priced on the Xbox 360 and the 9800 GTX+ with
//! the model as it is now, against the table's ten games. Reads the frames
//! (`runs[0].frame`) of the `budget.json` of runs made with
//!
//! ```sh
//! dermis budget --device llvmpipe --as-run --aa mlaa \
//!   --profile xbox360,geforce-9800-gtx-plus --width 1280 --height 720 [scene] --out DIR
//! ```
//!
//! and prices them again here (no re-rendering after a model change), then
//! prints the markdown tables:
//!
//! ```sh
//! cargo run --release --features tools --example table91_rescore -- face=DIR/budget.json lines=DIR2/budget.json ...
//! ```
//!
//! MLAA's time on the 9800 GTX+ is its edges, weights and blend passes, without
//! this port's copy (the thesis' D3D10 version blends into the back buffer
//! that holds the frame). On the Xbox 360 the back buffer must be in eDRAM to
//! be blended into, and eDRAM cannot hold the frame, its depth/stencil and a
//! third 720p 32 bpp target (3 x 3,686,400 B > 10 MiB), so the edges and
//! weights targets displace the frame and the blend needs it drawn back
//! ([`xbox_port_ms`]). The edge pixels are the weights pass's samples passed
//! (the stencil the edges wrote).
//!
//! Last, a sensitivity table: what the candidate causes of the misfit that no
//! source settles would change (docs/aa.md says why none is applied).

use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use dermis::budget::model::{price_frame, FrameBudget, PassBudget, Rescale};
use dermis::budget::params::ParamSet;
use dermis::budget::profile::{Profile, Quantity};
use dermis::budget::table91::{fit_line, g92_floor_bound_ms, games_line, GRAND_AVERAGE_MS};
use dermis::budget::FrameInput;
use dermis::vk::shader_stats::stats;
use dermis::work::{Filter, Format, Work};

const PASSES: [&str; 3] = ["mlaa edges", "mlaa weights", "mlaa blend"];

/// One frame: its label, edge pixels, frame pixels and the frame itself.
struct Frame {
    label: String,
    edges: f64,
    pixels: f64,
    input: FrameInput,
}

fn read(label: &str, path: &PathBuf) -> Result<Frame> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let input: FrameInput = serde_json::from_value(v["runs"][0]["frame"].clone())
        .with_context(|| format!("{}: runs[0].frame", path.display()))?;
    let edges = input
        .passes
        .iter()
        .find(|p| p.name == "mlaa weights")
        .map(|p| p.samples_passed as f64)
        .with_context(|| {
            format!(
                "{}: no mlaa weights pass (run with --aa mlaa)",
                path.display()
            )
        })?;
    Ok(Frame {
        label: label.to_string(),
        edges,
        pixels: f64::from(input.width) * f64::from(input.height),
        input,
    })
}

fn pass<'a>(b: &'a FrameBudget, name: &str) -> Result<&'a PassBudget> {
    b.passes
        .iter()
        .find(|p| p.name == name)
        .with_context(|| format!("no pass {name} on {}", b.profile))
}

fn ms(b: &FrameBudget, name: &str) -> Result<f64> {
    pass(b, name)?
        .modelled_ms
        .with_context(|| format!("{name} unpriced on {}", b.profile))
}

/// Edges, weights and blend, ms.
fn passes_ms(b: &FrameBudget) -> Result<[f64; 3]> {
    Ok([ms(b, PASSES[0])?, ms(b, PASSES[1])?, ms(b, PASSES[2])?])
}

/// MLAA as the thesis' Xbox 360 port must run it, from the passes dermis runs:
/// its three passes plus drawing the frame back into eDRAM for the blend (this
/// port's copy is that draw: the frame read as a texture and drawn into
/// eDRAM), less what the copy makes dermis pay that the port does not: the
/// stencil's resolve and restore (the port's draw keeps the depth/stencil in
/// eDRAM: colour and depth/stencil take 7.4 of its 10.5 MB) and the blend's
/// restore of the frame (the draw put it there). The copy's resolve out
/// stands for the port's resolve of the blended frame (the frame's resolve
/// for display is MLAA's input now, so MLAA adds one: the same bytes).
fn xbox_port_ms(b: &FrameBudget) -> Result<f64> {
    let [e, w, bl] = passes_ms(b)?;
    let copy = ms(b, "mlaa copy")?;
    let stencil_resolves: f64 = b
        .passes
        .iter()
        .filter_map(|p| p.edram.as_ref())
        .flat_map(|e| e.resolves.iter())
        .filter(|t| t.image == "mlaa stencil")
        .filter_map(|t| t.ms)
        .sum();
    let blend_restores = pass(b, PASSES[2])?.terms_ms.restore;
    Ok(e + w + bl + copy - stencil_resolves - blend_restores)
}

/// A variant of the model: the profiles, parameters and frame it prices.
#[derive(Clone)]
struct Variant {
    name: &'static str,
    xbox: Profile,
    g92: Profile,
    params: ParamSet,
    /// The 9800 GTX+'s colour clears left out (a fast colour clear).
    free_colour_clears: bool,
    /// The weights pass's search ALU at the trips its counted fetches ran.
    searches_as_run: bool,
    /// On the Xbox 360, every scalar instruction paired with another
    /// instruction in one ALU clock: a shader takes max(vector, all / 2)
    /// issue slots ([`paired_alu`]).
    paired: bool,
}

/// MLAA ms on both profiles (Xbox 360 as its port runs it, 9800 GTX+'s three
/// passes) for one frame under a variant.
fn priced(f: &Frame, v: &Variant) -> Result<(FrameBudget, FrameBudget)> {
    let mut input = f.input.clone();
    if v.searches_as_run {
        searches_as_run(&mut input)?;
    }
    let x = if v.paired {
        let mut paired = input.clone();
        paired_alu(&mut paired)?;
        price_frame(&v.xbox, &paired, &v.params, Rescale::AsRun)
    } else {
        price_frame(&v.xbox, &input, &v.params, Rescale::AsRun)
    };
    if v.free_colour_clears {
        for p in &mut input.passes {
            if let Work::Raster { clears, .. } = &mut p.work {
                clears.retain(|c| {
                    matches!(
                        c,
                        Format::D24UnormS8Uint | Format::D32Float | Format::D32FloatS8Uint
                    )
                });
            }
        }
    }
    let g = price_frame(&v.g92, &input, &v.params, Rescale::AsRun);
    Ok((x, g))
}

/// The weights pass's ALU with its four search loops at the trips they ran:
/// each trip makes one bilinear edge fetch, so the counted bilinear fetches
/// (two crossing fetches per edgel among them: an upper bound of the trips)
/// replace the declared four trips per loop.
fn searches_as_run(f: &mut FrameInput) -> Result<()> {
    let s = stats("mlaa_weights.frag")?;
    let base = s.alu(&[0; 4])?;
    let body = (s.alu(&[1; 4])? - base) / 4.0;
    for p in &mut f.passes {
        if p.name != "mlaa weights" {
            continue;
        }
        if let Work::Raster {
            shader: Some(sh), ..
        } = &mut p.work
        {
            let trips: f64 = sh
                .fetches
                .iter()
                .filter(|x| x.filter == Filter::Bilinear)
                .map(|x| x.count)
                .sum();
            sh.alu = base + body * trips;
        }
    }
    Ok(())
}

/// Each pass's ALU as issue slots of a vec4 + scalar ALU that pairs every
/// scalar instruction it can: max(vector, all / 2) of its SPIR-V instructions
/// (`AluSplit`), the trips of its loops found from the declared count (every
/// loop of these shaders is declared with the same trips). The lower bound of the slots
/// a Xenos compiler could reach; the profile's rate is the upper, unpaired one.
fn paired_alu(f: &mut FrameInput) -> Result<()> {
    for p in &mut f.passes {
        let sh = match &mut p.work {
            Work::Raster {
                shader: Some(sh), ..
            } => sh,
            Work::Compute { shader, .. } => shader,
            _ => continue,
        };
        if sh.alu <= 0.0 {
            continue;
        }
        let st = stats(&sh.shader)?;
        // The number of loops is the first count alu_split accepts.
        let loops = (0..16)
            .find(|&k| st.alu_split(&vec![0; k]).is_ok())
            .with_context(|| format!("{}: loops", sh.shader))?;
        // Between the uniform trip counts n and n + 1 that bracket the
        // declared count (exact at a whole n; the searches as run give
        // fractional trips), the split taken linearly.
        let at = |n: u32| st.alu_split(&vec![n; loops]);
        let mut found = None;
        for n in 0..256 {
            let (a, b) = (at(n)?, at(n + 1)?);
            if a.total <= sh.alu + 1e-9 && sh.alu <= b.total + 1e-9 {
                let t = if b.total > a.total {
                    (sh.alu - a.total) / (b.total - a.total)
                } else {
                    0.0
                };
                found = Some(a.vector + t * (b.vector - a.vector));
                break;
            }
        }
        let vector = found.with_context(|| {
            format!(
                "{}: no trip count gives the declared {} instructions",
                sh.shader, sh.alu
            )
        })?;
        sh.alu = vector.max(sh.alu / 2.0);
    }
    Ok(())
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
    let base = Variant {
        name: "the model",
        xbox: Profile::load("xbox360")?,
        g92: Profile::load("geforce-9800-gtx-plus")?,
        params: ParamSet::fitted(),
        free_colour_clears: false,
        searches_as_run: false,
        paired: false,
    };
    println!("| frame | edge pixels (share) | Xbox 360: edges / weights / blend (+ frame back into eDRAM), MLAA ms | 9800 GTX+: edges / weights / blend, MLAA ms | Xbox 360 / 9800 GTX+ |");
    println!("|---|---|---|---|---|");
    let mut totals = Vec::new();
    for f in &frames {
        let (x, g) = priced(f, &base)?;
        let [xe, xw, xb] = passes_ms(&x)?;
        let port = xbox_port_ms(&x)?;
        let [ge, gw, gb] = passes_ms(&g)?;
        let g92 = ge + gw + gb;
        println!(
            "| {} | {} ({:.2}%) | {xe:.3} / {xw:.3} / {xb:.3} (three passes {:.3}), **{port:.3}** | {ge:.3} / {gw:.3} / {gb:.3}, **{g92:.3}** | {:.2} |",
            f.label,
            f.edges,
            100.0 * f.edges / f.pixels,
            xe + xw + xb,
            port / g92
        );
        totals.push((port, g92));
    }
    let games = games_line();
    println!();
    println!("| line | slope | intercept ms | r |");
    println!("|---|---|---|---|");
    println!(
        "| Table 9.1's ten games: Xbox 360 ms against 9800 GTX+ ms | {:.2} +- {:.2} | {:.2} +- {:.2} | {:.3} |",
        games.slope, games.slope_se, games.intercept, games.intercept_se, games.r
    );
    let pairs: Vec<(f64, f64)> = totals.iter().map(|t| (t.1, t.0)).collect();
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
    for (i, prof) in ["xbox360", "geforce-9800-gtx-plus"].iter().enumerate() {
        let pts: Vec<(f64, f64)> = frames
            .iter()
            .zip(&totals)
            .map(|(f, t)| (f.edges / f.pixels, if i == 0 { t.0 } else { t.1 }))
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
        println!(
            "| {prof} | {:.3} | {:.2} | {meets} |",
            l.intercept,
            1e6 * l.slope / frames[0].pixels
        );
    }
    println!();
    println!(
        "The 9800 GTX+'s content-independent MLAA work costs at most {:.2} ms (the table's fastest game).",
        g92_floor_bound_ms()
    );
    sensitivity(&frames, base)
}

/// Each unsourced candidate alone, then together: MLAA on the first frame and
/// the line through all of them.
fn sensitivity(frames: &[Frame], base: Variant) -> Result<()> {
    // The ALU issue rule's alternatives on the Xbox 360: the old lane rule
    // (gflops / 2: every lane of every ALU filled) and the profile's upper
    // bound (every instruction paired).
    let xbox_with = |issue: Option<Quantity>| -> Result<Profile> {
        let mut x = Profile::load("xbox360")?;
        x.alu.vector_ginstr = issue;
        Ok(x)
    };
    let bound = match base.xbox.alu.vector_ginstr {
        Some(Quantity::Param { max, .. }) => max,
        _ => bail!("xbox360.toml: alu.vector_ginstr is not a parameter"),
    };
    let mut coarse = ParamSet::fitted();
    coarse.peak.reject_scale = coarse.peak.hiz_reject_scale;
    let variants = vec![
        Variant {
            name: "Xenos ALU as lanes (gflops / 2 = 120 G instructions/s: the model before vector issue)",
            xbox: xbox_with(None)?,
            ..base.clone()
        },
        Variant {
            name: "Xenos ALU at the profile's bound, 48 G (every instruction paired with a scalar one)",
            xbox: xbox_with(Some(Quantity::Known(bound)))?,
            ..base.clone()
        },
        Variant {
            name: "Xenos ALU paired per shader: max(vector, all / 2) SPIR-V instructions at 24 G",
            paired: true,
            ..base.clone()
        },
        Variant {
            name: "9800 GTX+ colour clears free (a fast colour clear)",
            free_colour_clears: true,
            ..base.clone()
        },
        Variant {
            name: "stencil-culled pixels rejected by tiles (the hierarchical-Z scale)",
            params: coarse,
            ..base.clone()
        },
        Variant {
            name: "the searches' ALU at the trips they ran (counted fetches)",
            searches_as_run: true,
            ..base.clone()
        },
        Variant {
            name: "all of them, Xenos paired per shader",
            params: coarse,
            free_colour_clears: true,
            searches_as_run: true,
            paired: true,
            ..base.clone()
        },
    ];
    let first = &frames[0].label;
    let game = frames
        .iter()
        .max_by(|a, b| a.edges.total_cmp(&b.edges))
        .context("no frame")?;
    println!();
    println!("| variant (not applied) | Xbox 360 MLAA ms, {first} / {} | 9800 GTX+, the same | ratio on {} | model's line: slope, intercept ms |", game.label, game.label);
    println!("|---|---|---|---|---|");
    for v in std::iter::once(&base).chain(&variants) {
        let mut pts = Vec::new();
        let mut cells = Vec::new();
        for f in frames {
            let (x, g) = priced(f, v)?;
            let (xm, gm) = (xbox_port_ms(&x)?, passes_ms(&g)?.iter().sum::<f64>());
            pts.push((gm, xm));
            if f.label == *first || std::ptr::eq(f, game) {
                cells.push((xm, gm));
            }
        }
        let line = fit_line(&pts).context("a line needs three frames")?;
        let (a, b) = (cells[0], *cells.last().context("no cells")?);
        println!(
            "| {} | {:.3} / {:.3} | {:.3} / {:.3} | {:.2} | {:.2}, {:.2} |",
            v.name,
            a.0,
            b.0,
            a.1,
            b.1,
            b.0 / b.1,
            line.slope,
            line.intercept
        );
    }
    Ok(())
}
