//! The porting answer (docs/budget.md): dermis's frames of the Lee Perry-Smith
//! head at 1280x720, 1/3/5 characters at the close, mid and far shots, every
//! real-time method (stored by `tools/budget_frames.sh porting` in
//! `profiles/frames/porting/`), priced on the console and handheld profiles
//! and summarised as Markdown tables: per configuration the frame, the skin
//! SSS time and how much of it is eDRAM resolves, whether it fits a skin
//! budget; per pass of one configuration the tiles, resolves and ms.

use std::fmt::Write;

use anyhow::{Context, Result};

use crate::budget::frames::{frames_dir, json_files, load_frame};
use crate::budget::input::FrameInput;
use crate::budget::model::{price_frame, FrameBudget, Rescale};
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;

/// The stored frames of the porting runs: (configuration, method, frame),
/// named `h{heads}_{shot}_{method}.json`.
pub fn porting_frames() -> Result<Vec<(String, String, FrameInput)>> {
    let mut out = Vec::new();
    for path in json_files(&frames_dir().join("porting"))? {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .context("frame file name")?
            .to_string();
        let mut parts = stem.splitn(3, '_');
        let (h, shot, method) = (parts.next(), parts.next(), parts.next());
        let (Some(h), Some(shot), Some(method)) = (h, shot, method) else {
            continue;
        };
        out.push((
            format!("{h} {shot}"),
            method.to_string(),
            load_frame(&path)?,
        ));
    }
    Ok(out)
}

fn resolves(b: &FrameBudget) -> (usize, f64) {
    let mut n = 0;
    let mut ms = 0.0;
    for p in b.passes.iter().filter(|p| p.role.is_frame_cost()) {
        if let Some(e) = &p.edram {
            n += e.resolves.len() + e.restores.len();
        }
        ms += p.terms_ms.resolve + p.terms_ms.restore;
    }
    (n, ms)
}

/// One row per configuration and method on `profile`: frame ms, skin SSS ms,
/// its resolves and restores, the most screen tiles of a pass, and whether the
/// skin fits `skin_budget_ms`.
pub fn summary_table(
    profile: &str,
    frames: &[(String, String, FrameInput)],
    skin_budget_ms: f64,
) -> Result<String> {
    let prof = Profile::load(profile)?;
    let set = ParamSet::fitted();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| characters, shot | method | SSS passes | frame ms | skin SSS ms | of it resolves/restores ms | transfers (frame) | max tiles | fits {skin_budget_ms} ms |"
    );
    s.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for (config, method, f) in frames {
        if method == crate::method::none().name {
            continue;
        }
        let b = price_frame(&prof, f, &set, Rescale::ToProfile);
        let sss_passes = b
            .passes
            .iter()
            .filter(|p| p.role == crate::graph::work::PassRole::Sss)
            .count();
        let tiles = b
            .passes
            .iter()
            .filter_map(|p| p.edram.as_ref().map(|e| e.screen_tiles))
            .max()
            .map_or("-".to_string(), |t| t.to_string());
        let (n, _) = resolves(&b);
        let _ = writeln!(
            s,
            "| {config} | {method} | {sss_passes} | {:.2} | {:.2} | {:.2} | {} | {tiles} | {} |",
            b.total_ms,
            b.sss_ms,
            b.sss_transfer_ms,
            if prof.edram.is_some() {
                n.to_string()
            } else {
                "-".into()
            },
            if b.sss_ms <= skin_budget_ms {
                "yes"
            } else {
                "**no**"
            }
        );
    }
    Ok(s)
}

/// One row per configuration, one column per method: skin SSS ms (frame ms),
/// marked when the skin fits `skin_budget_ms`.
pub fn compact_table(
    profile: &str,
    frames: &[(String, String, FrameInput)],
    skin_budget_ms: f64,
) -> Result<String> {
    let prof = Profile::load(profile)?;
    let set = ParamSet::fitted();
    let mut methods: Vec<&str> = Vec::new();
    let mut configs: Vec<&str> = Vec::new();
    for (c, m, _) in frames.iter().filter(|f| f.1 != crate::method::none().name) {
        if !methods.contains(&m.as_str()) {
            methods.push(m);
        }
        if !configs.contains(&c.as_str()) {
            configs.push(c);
        }
    }
    let mut s = format!("| characters, shot | {} |\n", methods.join(" | "));
    s.push_str(&format!("|---|{}\n", "---|".repeat(methods.len())));
    for c in &configs {
        let mut row = format!("| {c} |");
        for m in &methods {
            let cell = match frames.iter().find(|f| f.0 == *c && f.1 == *m) {
                Some((_, _, f)) => {
                    let b = price_frame(&prof, f, &set, Rescale::ToProfile);
                    let fits = if b.sss_ms <= skin_budget_ms {
                        " ok"
                    } else {
                        ""
                    };
                    format!(" {:.2} ({:.1}){fits} |", b.sss_ms, b.total_ms)
                }
                None => " - |".into(),
            };
            row.push_str(&cell);
        }
        s.push_str(&row);
        s.push('\n');
    }
    Ok(s)
}

/// Per pass of one frame on `profile`: role, ms, bound, tiles, resolves.
pub fn pass_table(profile: &str, f: &FrameInput) -> Result<String> {
    let prof = Profile::load(profile)?;
    let b = price_frame(&prof, f, &ParamSet::fitted(), Rescale::ToProfile);
    let mut s = String::new();
    s.push_str("| pass | role | ms | bound | screen tiles | resolves / restores (MB, ms) |\n");
    s.push_str("|---|---|---|---|---|---|\n");
    for p in b.passes.iter().filter(|p| p.role.is_frame_cost()) {
        let (tiles, tr) = match &p.edram {
            Some(e) => {
                let t: Vec<String> = e
                    .resolves
                    .iter()
                    .map(|t| ("resolve", t))
                    .chain(e.restores.iter().map(|t| ("restore", t)))
                    .map(|(k, t)| {
                        format!(
                            "{k} {} {:.1} MB {:.3} ms",
                            t.image,
                            t.bytes as f64 / 1e6,
                            t.ms.unwrap_or(0.0)
                        )
                    })
                    .collect();
                (e.screen_tiles.to_string(), t.join("; "))
            }
            None => ("-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {} | {tiles} | {tr} |",
            p.name,
            format!("{:?}", p.role).to_lowercase(),
            p.modelled_ms.unwrap_or(f64::NAN),
            p.bound
                .map_or("-".into(), |b| format!("{b:?}").to_lowercase()),
        );
    }
    let _ = writeln!(
        s,
        "| **frame** | | **{:.3}** | | | skin SSS {:.3} ms, of which resolves/restores {:.3} ms |",
        b.total_ms, b.sss_ms, b.sss_transfer_ms
    );
    Ok(s)
}
