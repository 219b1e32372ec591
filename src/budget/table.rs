//! The printed form of a priced frame: one row per pass (modelled ms on the
//! profile, what bounds it, eDRAM tiles and resolves, its share of the frame
//! and of the skin budget, the ms measured on the device that ran it), the
//! frame against the profile's frame time, and every flag.

use std::fmt::Write;

use crate::budget::model::FrameBudget;
use crate::budget::units::Bound;
use crate::graph::work::PassRole;

fn bound_name(b: Option<Bound>) -> &'static str {
    match b {
        Some(Bound::Texture) => "texture",
        Some(Bound::Alu) => "ALU",
        Some(Bound::Fill) => "fill",
        Some(Bound::Memory) => "memory",
        Some(Bound::Shared) => "shared",
        Some(Bound::Resolve) => "resolve",
        Some(Bound::Overhead) => "overhead",
        None => "UNPRICED",
    }
}

fn role_name(r: PassRole) -> String {
    format!("{r:?}").to_lowercase()
}

fn pct(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{:.1}%", v * 100.0))
}

/// The table of one frame on one profile; `device` names where the
/// measured column was measured.
pub fn budget_table(b: &FrameBudget, device: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "profile {} ({} rates) | {} | priced at {}x{} (run {}x{}) | frame {:.1} ms, skin budget {:.2} ms",
        b.profile,
        format!("{:?}", b.rates).to_lowercase(),
        b.label,
        b.priced_size[0],
        b.priced_size[1],
        b.run_size[0],
        b.run_size[1],
        b.frame_ms,
        b.skin_budget_ms
    );
    let _ = writeln!(
        s,
        "{:<22} {:<9} {:>9} {:<9} {:>5} {:>14} {:>7} {:>7} {:>12}",
        "pass",
        "role",
        "model ms",
        "bound",
        "tiles",
        "resolves (ms)",
        "frame",
        "skin",
        "measured ms"
    );
    for p in b.passes.iter().filter(|p| p.role.is_frame_cost()) {
        let (tiles, resolves) = match &p.edram {
            Some(e) => {
                let ms: f64 = e
                    .resolves
                    .iter()
                    .chain(&e.restores)
                    .filter_map(|t| t.ms)
                    .sum();
                let n = e.resolves.len() + e.restores.len();
                (
                    e.screen_tiles.to_string(),
                    if n > 0 {
                        format!("{n} ({ms:.3})")
                    } else {
                        "0".into()
                    },
                )
            }
            None => ("-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "{:<22} {:<9} {:>9} {:<9} {:>5} {:>14} {:>7} {:>7} {:>12}",
            p.name,
            role_name(p.role),
            p.modelled_ms.map_or("-".into(), |m| format!("{m:.3}")),
            bound_name(p.bound),
            tiles,
            resolves,
            pct(p.share_of_frame),
            pct(p.share_of_skin_budget),
            p.measured_ms.map_or("-".into(), |m| format!("{m:.3}")),
        );
    }
    let _ = writeln!(
        s,
        "{:<22} {:<9} {:>9} of {:.1} ms ({:.0}%){}{}",
        "frame",
        "",
        format!("{:.3}", b.total_ms),
        b.frame_ms,
        b.total_ms / b.frame_ms * 100.0,
        if b.over_frame { "  OVER THE FRAME" } else { "" },
        b.measured_total_ms.map_or(String::new(), |m| format!(
            " | measured {m:.3} ms on {device}"
        )),
    );
    // A profile that gives skin SSS no share has no percentage of it.
    let of_budget = if b.skin_budget_ms > 0.0 {
        format!(
            "of {:.2} ms skin budget ({:.0}%)",
            b.skin_budget_ms,
            b.sss_ms / b.skin_budget_ms * 100.0
        )
    } else {
        "(the profile gives skin SSS no budget)".to_string()
    };
    let _ = writeln!(
        s,
        "{:<22} {:<9} {:>9} {of_budget}, of which eDRAM resolves/restores {:.3} ms{}",
        "skin SSS",
        "",
        format!("{:.3}", b.sss_ms),
        b.sss_transfer_ms,
        if b.over_skin_budget {
            "  OVER BUDGET"
        } else {
            ""
        },
    );
    for f in flags(b) {
        let _ = writeln!(s, "  ! {f}");
    }
    s
}

/// Every overrun, over-budget role, substitution and unpriced pass, one line each.
pub fn flags(b: &FrameBudget) -> Vec<String> {
    let mut out = Vec::new();
    for c in b.categories.iter().filter(|c| c.over) {
        out.push(format!(
            "over budget: {} {:.3} ms > {:.3} ms",
            role_name(c.role),
            c.modelled_ms,
            c.budget_ms
        ));
    }
    for o in &b.overruns {
        out.push(format!("overrun: {o}"));
    }
    for p in &b.passes {
        for sub in &p.substitutions {
            out.push(format!(
                "unsupported: {}: {} -> {} ({}{})",
                p.name,
                sub.wanted,
                sub.used.as_deref().unwrap_or("nothing"),
                sub.reason,
                sub.fill_ms
                    .map_or(String::new(), |f| format!("; substitute's fill {f:.3} ms"))
            ));
        }
    }
    for u in &b.unpriced_passes {
        out.push(format!("unpriced: {u}"));
    }
    out
}
