//! `dermis methods`: the method registry, as a table or JSON, or the
//! settings the planner chooses among (`--planned`).

use anyhow::Result;
use serde::Serialize;

use super::cli::MethodsArgs;
use crate::method::{listing, listing_text};
use crate::plan::pipeline::registered;

/// One setting the planner chooses among, as `--planned` lists it.
#[derive(Serialize)]
struct Planned {
    method: &'static str,
    /// The planner's label (the stored frames' and the plans' name for it).
    setting: String,
    /// The eval setting its accuracy rows come from.
    eval: &'static str,
    path: &'static str,
    /// Option key and value, as `dermis methods --json` lists the keys.
    options: Vec<(String, String)>,
}

pub fn run(a: &MethodsArgs) -> Result<()> {
    if a.planned {
        let rows: Vec<Planned> = registered()
            .into_iter()
            .map(|r| Planned {
                method: r.method,
                setting: r.setting,
                eval: r.eval,
                path: r.path.name(),
                options: r.options.into_iter().collect(),
            })
            .collect();
        if a.json {
            println!("{}", serde_json::to_string_pretty(&rows)?);
        } else {
            for r in rows {
                println!("{} '{}'", r.method, r.setting);
            }
        }
    } else if a.json {
        println!("{}", serde_json::to_string_pretty(&listing())?);
    } else {
        print!("{}", listing_text());
    }
    Ok(())
}
