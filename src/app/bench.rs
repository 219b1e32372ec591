//! `dermis bench`: many frames and the device's ceilings, each pass's floor
//! from them; writes the report (and with `--trace` the timeline) only.

use anyhow::Result;

use super::cli::BenchArgs;
use super::request::{self, Given};
use crate::header::command_line;
use crate::output::paths::OutputPaths;
use crate::render::request::CheckedSettings;
use crate::render::FrameRequest;
use crate::run::{bench_run, header, FrameCounts, RunOptions};

pub fn run(a: &BenchArgs, given: &Given) -> Result<()> {
    let frames = FrameCounts::new(a.frames.warmup, a.frames.frames)?;
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    for n in super::notes::foreign(&settings) {
        eprintln!("note: {n}");
    }
    let settings = CheckedSettings::new(settings)?;
    let scene = request::load_scene(&source)?;
    let frame = FrameRequest::of(&scene, settings)?;
    OutputPaths::new()
        .file("--report", Some(&a.report))
        .file("--trace", a.trace.as_deref())
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let opts = RunOptions {
        frames,
        capture: false,
        dump: false,
        ceilings: true,
        command: command_line(),
        progress: true,
    };
    let r = bench_run(&ctx, &frame, &opts, &a.report);
    let out = ctx.finish_with(r)?;
    if let Some(t) = &a.trace {
        crate::trace::write(t, &out.report, &out.frames)?;
    }
    let r = out.report;
    println!("{}", header(&r));
    print!("{}", crate::report::table(&r.passes, r.frame.as_ref()));
    if let Some(c) = &r.ceilings {
        println!("{}", c.summary());
    }
    println!("wrote {}", a.report.display());
    if let Some(t) = &a.trace {
        println!("wrote {} (open it in ui.perfetto.dev)", t.display());
    }
    Ok(())
}
