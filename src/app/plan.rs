//! `dermis plan --profile P --budget-ms B [frame options]`: loads the scene
//! (no device opens), plans a method setting per character under the budget
//! (`plan::pipeline`), prints the table, and writes DIR/plan.json (what
//! `render --plan` reads) and a schematic of the frame (DIR/plan.png and
//! .svg: every character's skin rectangle coloured by its method).

use anyhow::{Context as _, Result};

use super::cli::PlanArgs;
use super::request::{self, Given};
use crate::budget::profile::Profile;
use crate::header::{command_line, DeviceHeader, RunHeader};
use crate::output::paths::OutputPaths;
use crate::plan::measured::Measured;
use crate::plan::picture;
use crate::plan::pipeline::{parse_budget_ms, plan_frame, table};
use crate::render::request::CheckedSettings;
use crate::render::FrameRequest;

/// The files plan writes into its folder.
const FILES: [&str; 3] = ["plan.json", "plan.png", "plan.svg"];

/// The `plan` subcommand: checks the profile and the budget, then the
/// render settings and the scene (each a one-line error, before anything is
/// written; no device ever opens), and plans with the measured accuracy
/// table of the scene's head (the scan's for a loaded model, the procedural
/// face's for a built-in scene).
pub fn run(a: &PlanArgs, given: &Given) -> Result<()> {
    let budget_ms = parse_budget_ms(&a.budget_ms)?;
    let profile = Profile::load(&a.profile).with_context(|| format!("--profile {}", a.profile))?;
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    // The frame planned for is one render would accept.
    let settings = CheckedSettings::new(settings)?;
    let scene = request::load_scene(&source)?;
    let frame = FrameRequest::of(&scene, settings)?;
    let acc = Measured::load_default(Measured::asset_of(source.gltf()))?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[])
        .prepare()?;
    let s = frame.settings();
    let mut p = plan_frame(&profile, budget_ms, s, &scene, &acc, &acc.source())?;
    p.file.run = Some(RunHeader::new(
        &command_line(),
        DeviceHeader::none(),
        (s.width, s.height),
        (0, 0),
    ));
    print!(
        "{}",
        table(&p.characters, &p.costs, &p.plan, &profile.profile.name)
    );
    print!("{}", p.geometry.table());
    for n in &p.file.notes {
        println!("note: {n}");
    }
    crate::output::write_json(&a.out.join("plan.json"), &p.file)?;
    picture::write(&a.out, s.width, s.height, &p.characters, &p.plan, &p.costs)?;
    println!(
        "wrote {}, {} and {}",
        a.out.join("plan.json").display(),
        a.out.join("plan.png").display(),
        a.out.join("plan.svg").display()
    );
    Ok(())
}
