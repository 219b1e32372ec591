//! A whole run: render or bench a scene, aggregate the samples, attach floors,
//! and produce the report. The CLI and the tests both go through here.

use std::path::Path;

use anyhow::{Context as _, Result};
use serde::Serialize;

use crate::bench::ceilings::{self, ProbeResult};
use crate::bench::floor::{floor_ms, Ceilings};
use crate::graph::work::PassRole;
use crate::method::region::RegionMode;
use crate::render::readback::DumpedImage;
use crate::render::{Capture, RenderSettings, Renderer};
use crate::report::{aggregate, FrameReport, PassDecl, PassReport, Stats};
use crate::scene::layout::Layout;
use crate::scene::Scene;
use crate::skin::transmittance::TransmittanceProfile;
use crate::vk::context::Context;

#[derive(Clone, Debug, Serialize)]
pub struct LightReport {
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    pub intensity: f32,
}

/// The JSON report of `render` and `bench`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub dermis_version: &'static str,
    pub command: String,
    pub device: String,
    pub device_type: String,
    pub driver: String,
    pub vulkan_api: String,
    pub validation: bool,
    pub width: u32,
    pub height: u32,
    pub method: &'static str,
    /// Every option of the method, given or default.
    pub method_options: std::collections::BTreeMap<&'static str, String>,
    /// What the method reports of itself (kernel, fit, stretch, samples...).
    pub method_details: serde_json::Value,
    pub transmittance: bool,
    pub transmittance_profile: TransmittanceProfile,
    pub sss_region: RegionMode,
    /// Pixels inside the region the SSS passes worked in (the screen without one).
    pub sss_region_pixels: u64,
    pub sss_region_rects: usize,
    pub scene: String,
    pub mm_per_unit: f32,
    pub heads: u32,
    pub layout: Layout,
    pub distance_heads: f32,
    pub fovy_deg: f32,
    pub light: LightReport,
    pub warmup_frames: usize,
    pub measured_frames: usize,
    pub passes: Vec<PassReport>,
    pub frame: Option<FrameReport>,
    /// Sum of the SSS passes (every pass of role `sss`) per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sss_total_ms: Option<Stats>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ceilings: Option<Ceilings>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probes: Option<Vec<ProbeResult>>,
}

/// What a run produced.
pub struct RunOutput {
    pub report: Report,
    pub capture: Option<Capture>,
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
    let frames = renderer.frames(opts.measured, tick)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let capture = if opts.capture {
        Some(renderer.capture(opts.dump)?)
    } else {
        None
    };
    let decls: Vec<PassDecl> = renderer
        .passes()
        .iter()
        .map(|p| PassDecl {
            work: p.work.clone(),
            images: renderer.resources.image_uses(&p.images),
        })
        .collect();
    let (mut passes, frame) = aggregate(&frames, &decls);
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
    let region = &renderer.frame.region_px;
    let (sss_region_pixels, sss_region_rects) =
        (region.iter().map(|r| r.area()).sum(), region.len());
    let method_details = renderer.method.details();
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
    let m = settings.method;
    let report = Report {
        dermis_version: env!("CARGO_PKG_VERSION"),
        command: opts.command.clone(),
        device: f.name.clone(),
        device_type: f.device_type.clone(),
        driver: f.driver.clone(),
        vulkan_api: f.api_version.clone(),
        validation: ctx.validation,
        width: settings.width,
        height: settings.height,
        method: m.name,
        method_options: m.opts(&settings.options).resolved(),
        method_details,
        transmittance: settings.transmittance,
        transmittance_profile: settings.transmittance_profile,
        sss_region: settings.sss_region,
        sss_region_pixels,
        sss_region_rects,
        scene: scene.name.clone(),
        mm_per_unit,
        heads: settings.heads,
        layout: settings.layout,
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
    };
    Ok(RunOutput { report, capture })
}

/// Makes sure `dir` exists and can be written, before any GPU work: a bad
/// `--out` is reported at once, not after the render.
pub fn prepare_out_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("--out {} exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let probe = dir.join(".dermis-write-test");
    std::fs::write(&probe, b"").with_context(|| format!("{} is not writable", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The files `render_to_dir` writes into its folder.
pub const RENDER_OUTPUTS: [&str; 3] = ["frame.png", "diffuse.exr", "report.json"];

/// `prepare_out_dir`, and the files a render writes there (with `dump`, the
/// passes/ folder) can be written: each is checked before any GPU work, so a
/// bad `--out` never costs a render.
pub fn prepare_render_dir(dir: &Path, dump: bool) -> Result<()> {
    prepare_out_dir(dir)?;
    for name in RENDER_OUTPUTS {
        check_writable_file(&dir.join(name))?;
    }
    let passes = dir.join("passes");
    if dump && passes.exists() && !passes.is_dir() {
        anyhow::bail!("--out: {} exists and is not a directory", passes.display());
    }
    Ok(())
}

/// The report path of `bench`: its folder exists (or is made) and is
/// writable, and the path itself is not a folder. Checked before any GPU work.
pub fn prepare_report_path(path: &Path) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        prepare_out_dir(parent)?;
    }
    check_writable_file(path)
}

/// A file that is about to be (over)written: not a folder, and writable if
/// it exists (it is opened for appending, which changes nothing).
fn check_writable_file(path: &Path) -> Result<()> {
    if path.is_dir() {
        anyhow::bail!(
            "{} is a directory, not a file dermis can write",
            path.display()
        );
    }
    if path.exists() {
        std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .with_context(|| format!("{} is not writable", path.display()))?;
    }
    Ok(())
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
    let output = run(ctx, scene, settings, opts)?;
    let capture = output.capture.as_ref().context("no frame was captured")?;
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
    write_report(&out.join("report.json"), &output.report)?;
    Ok(output)
}

/// Measures many frames and the device ceilings, writes the report to `path`.
pub fn bench_run(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RunOptions,
    path: &Path,
) -> Result<Report> {
    prepare_report_path(path)?;
    let output = run(ctx, scene, settings, opts)?;
    write_report(path, &output.report)?;
    Ok(output.report)
}

/// Writes a report as pretty JSON, creating its folder.
pub fn write_report(path: &Path, report: &Report) -> Result<()> {
    write_json(path, report)
}

/// `value` as pretty JSON at `path`, its folder made first.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    std::fs::write(path, serde_json::to_string_pretty(value)?)
        .with_context(|| format!("writing {}", path.display()))
}

/// Where the first non-finite (NaN or infinite) texel of `rgba` is, and how
/// many there are.
pub fn first_nonfinite(rgba: &[[f32; 4]], width: u32) -> Option<(usize, u32, u32)> {
    let count = rgba
        .iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count();
    let at = rgba.iter().position(|p| !p.iter().all(|c| c.is_finite()))?;
    let w = width.max(1) as usize;
    Some((count, (at % w) as u32, (at / w) as u32))
}

/// Writes the tone-mapped frame as an sRGB PNG. Refuses a frame whose HDR
/// composite held NaN or infinite values (they would be black pixels).
pub fn write_png(path: &Path, c: &Capture) -> Result<()> {
    if c.hdr_nonfinite > 0 {
        anyhow::bail!(
            "not writing {}: {} pixel(s) of the frame before tone mapping are NaN or infinite (a renderer defect: please report it)",
            path.display(),
            c.hdr_nonfinite
        );
    }
    let mut rgba = c.ldr.clone();
    for px in rgba.chunks_exact_mut(4) {
        px[3] = 255;
    }
    let img = image::RgbaImage::from_raw(c.width, c.height, rgba).context("frame size mismatch")?;
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes one pass output as a linear float EXR. Refuses an image holding NaN
/// or infinite values: no output of dermis ever does.
pub fn write_exr(path: &Path, d: &DumpedImage) -> Result<()> {
    if let Some((n, x, y)) = first_nonfinite(&d.rgba, d.width) {
        anyhow::bail!(
            "not writing {}: {n} texel(s) of '{}' after '{}' are NaN or infinite, the first at ({x}, {y}) (a renderer defect: please report it)",
            path.display(),
            d.image,
            d.pass
        );
    }
    let data: Vec<f32> = d.rgba.iter().flatten().copied().collect();
    let img =
        image::Rgba32FImage::from_raw(d.width, d.height, data).context("dump size mismatch")?;
    image::DynamicImage::ImageRgba32F(img)
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes the diffuse light after SSS (linear, alpha = SSS strength) as EXR.
pub fn write_diffuse_exr(path: &Path, c: &Capture) -> Result<()> {
    write_exr(
        path,
        &DumpedImage {
            pass: "final".into(),
            image: "diffuse".into(),
            width: c.width,
            height: c.height,
            rgba: c.diffuse.clone(),
        },
    )
}

/// Writes the linear view depth (scene units, in R, G and B) as EXR: with
/// report.json's fovy_deg and mm_per_unit, what `compare` finds the accuracy
/// bands from.
pub fn write_depth_exr(path: &Path, c: &Capture) -> Result<()> {
    write_exr(
        path,
        &DumpedImage {
            pass: "final".into(),
            image: "linear depth".into(),
            width: c.width,
            height: c.height,
            rgba: c.depth.iter().map(|&d| [d, d, d, 1.0]).collect(),
        },
    )
}

/// Reads an RGBA EXR written by dermis.
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    // Its sides within the range `render` accepts for a frame's width and height.
    let img = crate::files::read_rgba32f(
        path,
        "EXR image",
        &crate::files::ImageBound::rgba32f(crate::render::settings::MAX_IMAGE_SIDE),
    )?;
    let (w, h) = img.dimensions();
    Ok((w, h, img.pixels().map(|p| p.0).collect()))
}

/// A file-name-safe version of a pass or image name.
pub fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect::<String>()
        .split('_')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-run-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    // Issue 11: NaN texture coordinates gave NaN pixels in diffuse.exr. The
    // writers refuse non-finite images with a clear error, and write nothing.
    #[test]
    fn writers_refuse_nan_and_inf() {
        let d = tmp("nan");
        let mut img = DumpedImage {
            pass: "final".into(),
            image: "diffuse".into(),
            width: 3,
            height: 2,
            rgba: vec![[0.5; 4]; 6],
        };
        write_exr(&d.join("ok.exr"), &img).unwrap();
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            img.rgba[4][1] = bad;
            let p = d.join("bad.exr");
            let e = write_exr(&p, &img).unwrap_err().to_string();
            assert!(e.contains("1 texel(s)") && e.contains("(1, 1)"), "{e}");
            assert!(!p.exists());
        }
        let mut c = Capture {
            ldr: vec![0; 6 * 4],
            width: 3,
            height: 2,
            dumps: Vec::new(),
            samples: Vec::new(),
            diffuse: vec![[0.0; 4]; 6],
            depth: vec![1.0; 6],
            hdr_nonfinite: 0,
        };
        write_png(&d.join("ok.png"), &c).unwrap();
        c.hdr_nonfinite = 2;
        let e = write_png(&d.join("bad.png"), &c).unwrap_err().to_string();
        assert!(e.contains("2 pixel(s)"), "{e}");
        assert!(!d.join("bad.png").exists());
        let _ = std::fs::remove_dir_all(d);
    }

    // Issue 11: `--out` problems were found only after the render.
    #[test]
    fn output_paths_are_checked_before_any_work() {
        let d = tmp("out");
        let file = d.join("a-file");
        std::fs::write(&file, b"x").unwrap();
        let e = prepare_render_dir(&file, false).unwrap_err().to_string();
        assert!(e.contains("not a directory"), "{e}");
        let e = prepare_render_dir(&file.join("below"), false).unwrap_err();
        assert!(format!("{e:#}").contains("creating"), "{e:#}");
        // An output name taken by a folder.
        let out = d.join("out");
        std::fs::create_dir_all(out.join("frame.png")).unwrap();
        let e = prepare_render_dir(&out, false).unwrap_err().to_string();
        assert!(e.contains("frame.png is a directory"), "{e}");
        prepare_render_dir(&d.join("fresh"), true).unwrap();
        // bench --report: a folder, or below a file.
        let e = prepare_report_path(&out).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        assert!(prepare_report_path(&file.join("r.json")).is_err());
        prepare_report_path(&d.join("new/r.json")).unwrap();
        let _ = std::fs::remove_dir_all(d);
    }

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

    #[test]
    fn slugs_are_file_safe() {
        assert_eq!(slug("sss horizontal -> diffuse"), "sss_horizontal_diffuse");
        assert_eq!(slug("Shadow Map"), "shadow_map");
    }
}
