//! A whole run: render or bench a scene, aggregate the samples, attach floors,
//! and produce the report. The CLI and the tests both go through here; the
//! report's types are `report`'s, the files are written by `output`.

use std::path::Path;

use anyhow::{Context as _, Result};

use crate::bench::ceilings;
use crate::bench::floor::{pass_floor, Counts};
use crate::graph::work::PassRole;
use crate::graph::PassSample;
use crate::header::RunHeader;
use crate::output::{
    method_tint, slug, tint_characters, write_character_ids_png, write_depth_exr,
    write_diffuse_exr, write_exr, write_json, write_png, write_rgba8_png,
};
use crate::render::groups::GroupMethod;
use crate::render::request::FrameSettings;
use crate::render::{Capture, FrameRequest, RenderSettings, Renderer};
use crate::report::{
    aggregate, device_header, FadeReport, GroupReport, LightReport, PassDecl, Stats,
};
use crate::scene::Scene;
use crate::vk::context::Context;

/// What `run` returns: the report's schema lives in `report`; named here too
/// because a run is where reports come from.
pub use crate::report::Report;

/// What a run produced.
pub struct RunOutput {
    pub report: Report,
    pub capture: Option<Capture>,
    /// Every measured frame's pass samples, in order (what the report's
    /// statistics were taken over; `trace` lays them out as a timeline).
    pub frames: Vec<Vec<PassSample>>,
}

/// How many frames a run renders before it measures, and measures: checked
/// once ([`FrameCounts::new`]), so a run never checks them again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameCounts {
    warmup: usize,
    measured: usize,
}

impl FrameCounts {
    /// One measured frame, no warm-up (comparisons, captures).
    pub const ONE: FrameCounts = FrameCounts {
        warmup: 0,
        measured: 1,
    };

    /// `--warmup` and `--frames`, within their ranges (one line each).
    pub fn new(warmup: usize, measured: usize) -> Result<Self> {
        check_frame_counts(warmup, measured)?;
        crate::checks::ran("frame counts");
        Ok(FrameCounts { warmup, measured })
    }

    pub fn warmup(self) -> usize {
        self.warmup
    }

    pub fn measured(self) -> usize {
        self.measured
    }
}

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub frames: FrameCounts,
    /// Read back the tone-mapped frame (and with `dump`, every pass output).
    pub capture: bool,
    pub dump: bool,
    /// Measure device ceilings and attach per-pass floors.
    pub ceilings: bool,
    pub command: String,
    pub progress: bool,
}

/// Most measured frames a run takes statistics over: each keeps its pass
/// samples (about 1 KB) until the report is made, so 100,000 frames hold about
/// 100 MB. (A p95 over more frames says nothing new.)
pub const MAX_MEASURED_FRAMES: usize = 100_000;
/// Most warm-up frames (they keep nothing; the bound only catches a mistyped
/// count that would run for days).
pub const MAX_WARMUP_FRAMES: usize = 100_000;

/// Checks `--warmup` and `--frames` (before any device opens).
fn check_frame_counts(warmup: usize, measured: usize) -> Result<()> {
    if warmup > MAX_WARMUP_FRAMES {
        anyhow::bail!("--warmup must be within 0..={MAX_WARMUP_FRAMES}, got {warmup}");
    }
    if !(1..=MAX_MEASURED_FRAMES).contains(&measured) {
        anyhow::bail!("--frames must be within 1..={MAX_MEASURED_FRAMES}, got {measured}");
    }
    Ok(())
}

impl RunOptions {
    /// One captured frame, no warm-up, quiet: what comparisons need.
    pub fn capture_once(command: &str) -> Self {
        RunOptions {
            frames: FrameCounts::ONE,
            capture: true,
            dump: false,
            ceilings: false,
            command: command.into(),
            progress: false,
        }
    }
}

/// Checks `settings` in `scene` ([`FrameRequest::new`]) and runs that frame
/// (tests and tools that hold no request).
pub fn run(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RunOptions,
) -> Result<RunOutput> {
    run_request(ctx, &FrameRequest::new(scene, settings.clone())?, opts)
}

/// The note of a run stepping through the motion (`--time-step`): which
/// time each frame is posed at, and the last one's (the image's).
fn step_note(scene: &Scene, warmup: usize, measured: usize, capture: bool) {
    if let Some((t0, dt)) = scene.tracks.as_ref().and_then(|t| Some((t.time, t.step?))) {
        let last = (warmup + measured).saturating_sub(usize::from(!capture));
        eprintln!(
            "note: --time-step {dt}: frame k is posed at {t0} + k * {dt} s ({warmup} warm-up, {measured} measured{}); the last, frame {last}, at {} s",
            if capture { ", then the captured one" } else { "" },
            t0 + last as f32 * dt
        );
    }
}

/// Renders a checked frame: warm-up, measured frames, the capture, the
/// report (with the frame's whole settings and the run header).
pub fn run_request(ctx: &Context, request: &FrameRequest, opts: &RunOptions) -> Result<RunOutput> {
    let (scene, settings) = (request.scene(), request.settings());
    let mut renderer = Renderer::build(ctx, request)?;
    let (warmup, measured) = (opts.frames.warmup(), opts.frames.measured());
    let total = warmup + measured;
    step_note(scene, warmup, measured, opts.capture);
    let bar = if opts.progress && total > 20 {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:>10} [{bar:40}] {pos}/{len} frames ({eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_message("frames");
        Some(b)
    } else {
        None
    };
    let tick = |_: usize| {
        if let Some(b) = &bar {
            b.inc(1)
        }
    };
    renderer.run_frames(warmup, tick)?;
    let (frames, record_ms) = renderer.frames_timed(measured, tick)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let capture = if opts.capture {
        Some(renderer.capture(opts.dump)?)
    } else {
        None
    };
    let decls = pass_decls(&renderer);
    let (mut passes, mut frame) = aggregate(&frames, &decls);
    if let Some(f) = &mut frame {
        f.cpu_record_ms = Stats::of(&record_ms);
    }
    let groups = group_reports(&renderer, capture.as_ref());
    let sss_totals: Vec<f64> = frames
        .iter()
        .map(|f| {
            f.iter()
                .filter(|s| s.role == PassRole::Sss)
                .map(|s| s.gpu_ms + s.barrier_ms)
                .sum()
        })
        .collect();
    let has_sss = frames
        .first()
        .is_some_and(|f| f.iter().any(|s| s.role == PassRole::Sss));
    let extent = renderer.frame.extent;
    let mm_per_unit = renderer.frame.mm_per_unit;
    let region = renderer.region_px();
    let (sss_region_pixels, sss_region_rects) =
        (region.iter().map(|r| r.area()).sum(), region.len() as u64);
    let method_details = renderer.groups[0].method.details();
    drop(renderer);

    let (ceilings, probes) = if opts.ceilings {
        let (c, p) = ceilings::measure(ctx, extent, 7).context("measuring device ceilings")?;
        for pass in &mut passes {
            // A dispatch is floored by its compute invocations at the compute
            // rates, a raster pass by its fragments, samples and triangles at
            // the fragment path's and the rasteriser's rates; a pass with no
            // floor says why.
            let counts = Counts {
                fragments: pass.fragment_invocations,
                compute: pass.compute_invocations,
                samples_passed: pass.samples_passed,
            };
            match pass_floor(pass.work.as_ref(), counts, &c) {
                Ok(f) => {
                    pass.floor_ms = Some(f);
                    pass.floor_ratio = (f > 0.0).then(|| pass.gpu_ms.median / f);
                }
                Err(why) => pass.no_floor = Some(why),
            }
        }
        (Some(c), Some(p))
    } else {
        (None, None)
    };

    // A frame of several methods names itself `mix`; its groups say the rest.
    let (method, method_options) = match &groups[..] {
        [one] => (
            one.method.clone(),
            one.options.clone().into_iter().collect(),
        ),
        _ => (
            crate::render::groups::MIX_NAME.to_string(),
            Default::default(),
        ),
    };
    let report = Report {
        run: RunHeader::new(
            &opts.command,
            device_header(ctx),
            (settings.width, settings.height),
            (warmup, measured),
        ),
        settings: Some(FrameSettings {
            scene: scene.source.clone(),
            render: settings.clone(),
        }),
        method,
        method_options,
        method_details,
        transmittance: settings.transmittance,
        transmittance_profile: settings.transmittance_profile,
        sss_region: Some(settings.sss_region),
        sss_region_pixels: Some(sss_region_pixels),
        sss_region_rects: Some(sss_region_rects),
        aa: (settings.aa != crate::post::AaMode::None).then(|| settings.aa.name().to_string()),
        bloom: settings.post.bloom,
        aa_edges: settings.post.aa_edges.map(|e| e.name().to_string()),
        smaa_preset: settings.post.smaa_preset.map(|p| p.name().to_string()),
        msaa: (settings.msaa > 1).then_some(settings.msaa),
        scene: scene.name.clone(),
        mm_per_unit,
        heads: settings.heads,
        layout: Some(settings.layout),
        distance_heads: settings.distance_heads,
        fovy_deg: settings.fovy_deg,
        light: LightReport {
            azimuth_deg: settings.light.azimuth_deg,
            elevation_deg: settings.light.elevation_deg,
            intensity: settings.light.intensity,
        },
        passes,
        frame,
        sss_total_ms: if has_sss {
            Stats::of(&sss_totals)
        } else {
            None
        },
        ceilings,
        probes,
        groups,
    };
    Ok(RunOutput {
        report,
        capture,
        frames,
    })
}

/// Each pass's declaration, with its group and that group's characters.
fn pass_decls(renderer: &Renderer) -> Vec<PassDecl> {
    renderer
        .passes()
        .iter()
        .map(|p| PassDecl {
            work: p.declared_work(&renderer.resources),
            images: renderer.resources.image_uses(&p.images),
            group: p.group,
            characters: p
                .group
                .and_then(|g| renderer.groups.iter().find(|m| m.spec.index == g))
                .map(|m| m.spec.characters.clone())
                .unwrap_or_default(),
        })
        .collect()
}

/// The report's groups (skin pixels counted when the capture has character ids).
fn group_reports(renderer: &Renderer, capture: Option<&Capture>) -> Vec<GroupReport> {
    let skin = capture.and_then(|c| group_skin_pixels(c, &renderer.groups));
    renderer
        .groups
        .iter()
        .enumerate()
        .map(|(i, g)| GroupReport {
            index: g.spec.index,
            choice: g.spec.label.clone(),
            method: g.spec.entry.name.to_string(),
            options: g
                .spec
                .entry
                .opts(&g.spec.options)
                .resolved()
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            stencil: g.spec.stencil(),
            characters: g.spec.characters.clone(),
            region_rects: g
                .region_px
                .iter()
                .map(|r| [r.x0, r.y0, r.x1, r.y1])
                .collect(),
            region_pixels: g.region_px.iter().map(|r| r.area()).sum(),
            skin_pixels: skin.as_ref().and_then(|s| s.get(i).copied()),
            tint: None,
            fade: g.fade.as_ref().map(|f| FadeReport {
                from: f.spec.label.clone(),
                weight: f.spec.weight,
                region_rects: f
                    .region_px
                    .iter()
                    .map(|r| [r.x0, r.y0, r.x1, r.y1])
                    .collect(),
                region_pixels: f.region_px.iter().map(|r| r.area()).sum(),
            }),
        })
        .collect()
}

/// Skin pixels of each group's characters in a captured frame with
/// character ids (`None` without them).
fn group_skin_pixels(c: &Capture, groups: &[GroupMethod]) -> Option<Vec<u64>> {
    let ids = c.character_ids.as_ref()?;
    let n = groups
        .iter()
        .map(|g| g.spec.characters.len())
        .sum::<usize>();
    let mut per_character = vec![0u64; n];
    for &id in ids {
        if let Some(p) = (id as usize)
            .checked_sub(1)
            .and_then(|i| per_character.get_mut(i))
        {
            *p += 1;
        }
    }
    Some(
        groups
            .iter()
            .map(|g| g.spec.characters.iter().map(|&c| per_character[c]).sum())
            .collect(),
    )
}

/// The one-line header of a run's table.
pub fn header(r: &Report) -> String {
    format!(
        "dermis {} | {} ({}) | {}x{} | method {} | scene '{}' ({:.1} mm/unit) | {} head(s) | {} measured frames",
        r.run.dermis_version,
        r.run.device.device,
        r.run.device.driver,
        r.run.width,
        r.run.height,
        r.method,
        r.scene,
        r.mm_per_unit,
        r.heads,
        r.run.measured_frames
    )
}

/// The files [`render_to_dir`] writes into its folder (`characters.png` and
/// `groups.png` when the frame has character ids and several methods), and
/// the dumps it owns there.
pub const RENDER_FILES: [&str; 6] = [
    "frame.png",
    "diffuse.exr",
    "depth.exr",
    "report.json",
    "characters.png",
    "groups.png",
];
/// With `--dump`: every pass output under `passes/`.
pub const RENDER_DUMPS: crate::output::paths::Owned = crate::output::paths::Owned {
    sub: "passes",
    suffix: ".exr",
};

/// Renders a checked frame and writes frame.png, diffuse.exr, depth.exr and
/// report.json (with `dump`, every pass output as EXR under passes/; with
/// character ids, characters.png, and in a frame of several methods
/// groups.png) into `out`, a folder prepared with [`RENDER_FILES`].
pub fn render_to_dir(
    ctx: &Context,
    request: &FrameRequest,
    out: &Path,
    opts: &RunOptions,
) -> Result<RunOutput> {
    let mut output = run_request(ctx, request, opts)?;
    let capture = output.capture.as_ref().context("no frame was captured")?;
    if let Some(ids) = &capture.character_ids {
        write_character_ids_png(
            &out.join("characters.png"),
            capture.width,
            capture.height,
            ids,
        )?;
        if request.mixed() {
            let mut tint_of = vec![
                [0u8; 3];
                output
                    .report
                    .groups
                    .iter()
                    .map(|g| g.characters.len())
                    .sum()
            ];
            for g in &mut output.report.groups {
                let t = method_tint(&g.method);
                g.tint = Some(t);
                for &c in &g.characters {
                    tint_of[c] = t;
                }
            }
            let rgba = tint_characters(&capture.ldr, ids, &tint_of);
            write_rgba8_png(&out.join("groups.png"), capture.width, capture.height, rgba)?;
        }
    }
    write_png(&out.join("frame.png"), capture)?;
    write_diffuse_exr(&out.join("diffuse.exr"), capture)?;
    write_depth_exr(&out.join("depth.exr"), capture)?;
    if opts.dump {
        let dir = out.join(RENDER_DUMPS.sub);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        for (i, d) in capture.dumps.iter().enumerate() {
            write_exr(
                &dir.join(format!("{:02}_{}_{}.exr", i, slug(&d.pass), slug(&d.image))),
                d,
            )?;
        }
    }
    write_json(&out.join("report.json"), &output.report)?;
    Ok(output)
}

/// Measures many frames and the device ceilings of a checked frame, writes
/// the report to `path` (prepared by the caller).
pub fn bench_run(
    ctx: &Context,
    request: &FrameRequest,
    opts: &RunOptions,
    path: &Path,
) -> Result<RunOutput> {
    let output = run_request(ctx, request, opts)?;
    write_json(path, &output.report)?;
    Ok(output)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Issue 11: huge --frames/--warmup aborted on a 100 GB allocation.
    #[test]
    fn frame_counts_are_bounded() {
        check_frame_counts(0, 1).unwrap();
        check_frame_counts(MAX_WARMUP_FRAMES, MAX_MEASURED_FRAMES).unwrap();
        for (w, m) in [
            (0, 0),
            (0, MAX_MEASURED_FRAMES + 1),
            (MAX_WARMUP_FRAMES + 1, 1),
            (usize::MAX, usize::MAX),
        ] {
            let e = check_frame_counts(w, m).unwrap_err().to_string();
            assert!(e.contains("must be within"), "{e}");
        }
    }
}
