//! `dermis reference`: the ground truth of the frame (`render --method
//! reference` with one measured frame): frame.png, diffuse.exr, depth.exr
//! and report.json.

use anyhow::Result;

use super::cli::ReferenceArgs;
use super::request::{self, Given};
use crate::header::command_line;
use crate::method::ground_truth;
use crate::output::paths::OutputPaths;
use crate::render::request::CheckedSettings;
use crate::render::{FrameRequest, RenderSettings};
use crate::run::{header, render_to_dir, FrameCounts, RunOptions, RENDER_FILES};

pub fn run(a: &ReferenceArgs, given: &Given) -> Result<()> {
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    let settings = RenderSettings {
        method: ground_truth(),
        // --assign/--plan are ignored here (a note says so).
        assignment: None,
        ..settings
    };
    for n in super::notes::foreign(&settings) {
        eprintln!("note: {n}");
    }
    let settings = CheckedSettings::new(settings)?;
    let scene = request::load_scene(&source)?;
    let frame = FrameRequest::of(&scene, settings)?;
    OutputPaths::new()
        .folder("--out", &a.out, &RENDER_FILES, &[])
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let opts = RunOptions {
        frames: FrameCounts::ONE,
        capture: true,
        dump: false,
        ceilings: false,
        command: command_line(),
        progress: true,
    };
    let r = render_to_dir(&ctx, &frame, &a.out, &opts);
    let r = ctx.finish_with(r)?.report;
    println!("{}", header(&r));
    print!("{}", crate::report::table(&r.passes, r.frame.as_ref()));
    println!(
        "wrote {}, {} and {}",
        a.out.join("frame.png").display(),
        a.out.join("diffuse.exr").display(),
        a.out.join("report.json").display()
    );
    Ok(())
}
