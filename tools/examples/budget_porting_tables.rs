//! Prints docs/budget.md's porting tables: the stored frames of the head
//! (`tools/budget_frames.sh porting`) priced on the Xbox 360 (summary), on each
//! console and handheld profile (compact), and pass by pass on the Xbox 360
//! for the mid shot of one head.
//!
//! ```sh
//! cargo run --release --features tools --example budget_porting_tables
//! ```
//! It was the ignored unit test `budget::porting::tests::print_porting_tables`:
//! it only prints, so it is a program, not a test.

use anyhow::{bail, Result};
use dermis::budget::porting::{compact_table, pass_table, porting_frames, summary_table};

fn main() -> Result<()> {
    let frames = porting_frames()?;
    if frames.is_empty() {
        bail!("no stored porting frames: run tools/budget_frames.sh porting first");
    }
    println!("### xbox360\n\n{}", summary_table("xbox360", &frames, 2.0)?);
    for p in ["xbox360", "switch-handheld", "switch-docked", "steam-deck"] {
        println!("### {p} (compact)\n\n{}", compact_table(p, &frames, 2.0)?);
    }
    for (config, method, f) in &frames {
        if config == "h1 mid" && method != "none" {
            println!(
                "#### xbox360, {config}, {method}\n\n{}",
                pass_table("xbox360", f)?
            );
        }
    }
    Ok(())
}
