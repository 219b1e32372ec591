//! `dermis kernel`: the separable kernel of a preset (offsets in mm and RGB
//! weights) as JSON on standard output.

use anyhow::Result;

use super::cli::KernelArgs;
use crate::skin::kernel::SeparableKernel;

pub fn run(a: &KernelArgs) -> Result<()> {
    let mut params = a.preset.params();
    if let Some(w) = a.width_mm {
        params.width_mm = w;
    }
    params.validate()?;
    let k = SeparableKernel::build(params, a.samples)?;
    println!(
        "{}",
        serde_json::to_string_pretty(
            &serde_json::json!({ "preset": a.preset.name(), "samples": a.samples, "kernel": k })
        )?
    );
    Ok(())
}
