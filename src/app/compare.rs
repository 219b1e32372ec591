//! `dermis compare`: two render outputs compared (no device opens): the
//! comparison itself is `eval::compare`'s.

use anyhow::Result;

use super::cli::CompareArgs;
use crate::eval::compare::{compare, comparison_table};
use crate::header::command_line;
use crate::output::paths::OutputPaths;

/// The files compare writes into its folder.
const FILES: [&str; 4] = [
    "error_diffuse.png",
    "error_flip.png",
    "bands.png",
    "compare.json",
];

pub fn run(a: &CompareArgs) -> Result<()> {
    let out = a.out.clone().unwrap_or_else(|| a.a.clone());
    OutputPaths::new()
        .folder("--out", &out, &FILES, &[])
        .prepare()?;
    let c = compare(&a.a, &a.b, a.none.as_deref(), &out, &command_line())?;
    print!("{}", comparison_table(&c));
    println!("error images and compare.json in {}", out.display());
    Ok(())
}
