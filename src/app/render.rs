//! `dermis render`: one frame, measured, written into a folder (frame.png,
//! diffuse.exr, depth.exr, report.json; characters.png and groups.png where
//! the frame has them; every pass with `--dump`), its per-pass table printed.

use anyhow::Result;

use super::cli::RenderArgs;
use super::request::{self, Given};
use crate::header::command_line;
use crate::output::paths::OutputPaths;
use crate::render::request::CheckedSettings;
use crate::render::FrameRequest;
use crate::run::{header, render_to_dir, FrameCounts, RunOptions, RENDER_DUMPS, RENDER_FILES};

pub fn run(a: &RenderArgs, given: &Given) -> Result<()> {
    let frames = FrameCounts::new(a.frames.warmup, a.frames.frames)?;
    let (source, mut settings) = request::frame_settings(&a.frame, given)?;
    settings.character_ids |= a.character_ids;
    for n in super::notes::foreign(&settings) {
        eprintln!("note: {n}");
    }
    let settings = CheckedSettings::new(settings)?;
    let scene = request::load_scene(&source)?;
    let mut frame = FrameRequest::of(&scene, settings)?;
    // A frame of several methods also writes groups.png, which needs each
    // pixel's character: the id pass comes with it (it changes no image).
    if frame.mixed() && !frame.settings().character_ids {
        match frame.with_character_ids() {
            Some(f) => frame = f,
            None => eprintln!(
                "note: groups.png and characters.png are not written: the character-id pass \
                 cannot run with --msaa {} (it would draw against a depth resolved from one sample)",
                frame.settings().msaa
            ),
        }
    }
    let dumps = if a.dump { vec![RENDER_DUMPS] } else { vec![] };
    OutputPaths::new()
        .folder("--out", &a.out, &RENDER_FILES, &dumps)
        .file("--trace", a.trace.as_deref())
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let opts = RunOptions {
        frames,
        capture: true,
        dump: a.dump,
        ceilings: false,
        command: command_line(),
        progress: true,
    };
    let r = render_to_dir(&ctx, &frame, &a.out, &opts);
    let output = ctx.finish_with(r)?;
    if let Some(t) = &a.trace {
        crate::trace::write(t, &output.report, &output.frames)?;
    }
    let r = output.report;
    println!("{}", header(&r));
    print!("{}", crate::report::table(&r.passes, r.frame.as_ref()));
    print!("{}", crate::report::groups_table(&r.groups));
    println!(
        "wrote {}, {} and {}",
        a.out.join("frame.png").display(),
        a.out.join("diffuse.exr").display(),
        a.out.join("report.json").display()
    );
    if let Some(t) = &a.trace {
        println!("wrote {} (open it in ui.perfetto.dev)", t.display());
    }
    Ok(())
}
