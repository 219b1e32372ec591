//! A whole run: render or bench a scene, aggregate the samples, attach floors,
//! and produce the report. The CLI and the tests both go through here; the
//! report's types are `report`'s, the files are written by `output`.

use std::path::Path;

use anyhow::{Context as _, Result};

use crate::bench::ceilings;
use crate::bench::floor::floor_ms;
use crate::graph::work::PassRole;
use crate::graph::PassSample;
use crate::output::{
    method_tint, prepare_file, prepare_render_dir, slug, tint_characters, write_character_ids_png,
    write_depth_exr, write_diffuse_exr, write_exr, write_json, write_png, write_rgba8_png,
};
use crate::render::groups::GroupMethod;
use crate::render::{Capture, RenderSettings, Renderer};
use crate::report::{aggregate, FadeReport, GroupReport, LightReport, PassDecl, Stats};
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

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub warmup: usize,
    pub measured: usize,
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
pub fn check_frame_counts(warmup: usize, measured: usize) -> Result<()> {
    if warmup > MAX_WARMUP_FRAMES {
        anyhow::bail!("--warmup must be within 0..={MAX_WARMUP_FRAMES}, got {warmup}");
    }
    if !(1..=MAX_MEASURED_FRAMES).contains(&measured) {
        anyhow::bail!("--frames must be within 1..={MAX_MEASURED_FRAMES}, got {measured}");
    }
    Ok(())
}

impl RunOptions {
    /// The frame counts' ranges (`check_frame_counts`).
    pub fn validate(&self) -> Result<()> {
        check_frame_counts(self.warmup, self.measured)
    }

    /// One captured frame, no warm-up, quiet: what comparisons need.
    pub fn capture_once(command: &str) -> Self {
        RunOptions {
            warmup: 0,
            measured: 1,
            capture: true,
            dump: false,
            ceilings: false,
            command: command.into(),
            progress: false,
        }
    }
}

pub fn run(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RunOptions,
) -> Result<RunOutput> {
    opts.validate()?;
    let mut renderer = Renderer::new(ctx, scene, settings)?;
    let total = opts.warmup + opts.measured;
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
    renderer.run_frames(opts.warmup, tick)?;
    let (frames, record_ms) = renderer.frames_timed(opts.measured, tick)?;
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
            if let (Some(work), Some(inv)) = (&pass.work, pass.fragment_invocations) {
                if let Some(f) = floor_ms(work, inv, &c) {
                    pass.floor_ms = Some(f);
                    pass.floor_ratio = (f > 0.0).then(|| pass.gpu_ms.median / f);
                }
            }
        }
        (Some(c), Some(p))
    } else {
        (None, None)
    };

    let f = &ctx.facts;
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
        dermis_version: env!("CARGO_PKG_VERSION").to_string(),
        command: opts.command.clone(),
        device: f.name.clone(),
        device_type: f.device_type.clone(),
        driver: f.driver.clone(),
        vulkan_api: f.api_version.clone(),
        validation: ctx.validation,
        width: settings.width,
        height: settings.height,
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
        warmup_frames: opts.warmup,
        measured_frames: opts.measured,
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
        r.dermis_version, r.device, r.driver, r.width, r.height, r.method, r.scene, r.mm_per_unit, r.heads, r.measured_frames
    )
}

/// Renders and writes frame.png, diffuse.exr, depth.exr and report.json (with `dump`,
/// every pass output as EXR under passes/) into `out`.
pub fn render_to_dir(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    out: &Path,
    opts: &RunOptions,
) -> Result<RunOutput> {
    prepare_render_dir(out, opts.dump)?;
    // A frame of several methods also writes groups.png, which needs each
    // pixel's character: the id pass comes with it (it changes no image).
    let mixed =
        crate::render::groups::specs_mixed(&crate::render::groups::group_specs(scene, settings)?);
    let with_ids;
    let settings = if mixed && !settings.character_ids {
        with_ids = RenderSettings {
            character_ids: true,
            ..settings.clone()
        };
        &with_ids
    } else {
        settings
    };
    let mut output = run(ctx, scene, settings, opts)?;
    let capture = output.capture.as_ref().context("no frame was captured")?;
    if let Some(ids) = &capture.character_ids {
        write_character_ids_png(
            &out.join("characters.png"),
            capture.width,
            capture.height,
            ids,
        )?;
        if mixed {
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
        let dir = out.join("passes");
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

/// Measures many frames and the device ceilings, writes the report to `path`.
pub fn bench_run(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RunOptions,
    path: &Path,
) -> Result<RunOutput> {
    prepare_file(path)?;
    let output = run(ctx, scene, settings, opts)?;
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
