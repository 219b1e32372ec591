//! A whole run: render or bench a scene, aggregate the samples, attach floors,
//! and produce the report. The CLI and the tests both go through here.

use std::path::Path;

use anyhow::{Context as _, Result};
use serde::Serialize;

use crate::bench::ceilings::{self, ProbeResult};
use crate::bench::floor::{
    composite_cost, floor_ms, jittered_cost, separable_pass_cost, ssg_pass_cost, tonemap_cost,
    Ceilings, PassCost,
};
use crate::render::readback::DumpedImage;
use crate::render::{Capture, RenderSettings, Renderer};
use crate::report::{aggregate, FrameReport, PassReport, Stats};
use crate::scene::Scene;
use crate::skin::kernel::SssParams;
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
    pub samples: usize,
    pub preset: &'static str,
    pub sss_params: SssParams,
    pub follow_surface: bool,
    pub transmittance: bool,
    pub transmittance_profile: crate::skin::transmittance::TransmittanceProfile,
    /// ssg settings (reported for every method; only ssg reads them).
    pub fit: crate::skin::ssg::GaussianFit,
    pub lod: bool,
    pub mask: crate::render::screen::MaskMode,
    pub sss_region: crate::render::region::RegionMode,
    /// Pixels inside the region the SSS passes worked in (the screen without one).
    pub sss_region_pixels: u64,
    pub sss_region_rects: usize,
    pub scene: String,
    pub mm_per_unit: f32,
    pub heads: u32,
    pub distance_heads: f32,
    pub fovy_deg: f32,
    pub light: LightReport,
    pub warmup_frames: usize,
    pub measured_frames: usize,
    pub passes: Vec<PassReport>,
    pub frame: Option<FrameReport>,
    /// Sum of the SSS passes (seed copy, horizontal, vertical) per frame.
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

/// The passes of every SSS method (their names start with the method's prefix).
pub fn is_sss_pass(name: &str) -> bool {
    ["sss ", "ssg ", "ss-jittered", "poisson"]
        .iter()
        .any(|p| name.starts_with(p))
}

/// The cost model of a pass by name, where one exists.
fn pass_cost(name: &str, s: &RenderSettings) -> Option<PassCost> {
    match name {
        "sss horizontal" | "sss vertical" => Some(separable_pass_cost(s.samples, s.follow_surface)),
        "ss-jittered" => Some(jittered_cost()),
        n if n.starts_with("ssg g") => Some(ssg_pass_cost(n.ends_with("vertical"))),
        // poisson's sample count varies per pixel (8/16/32 by radius): no single floor.
        "composite" => Some(composite_cost()),
        "tonemap" => Some(tonemap_cost()),
        _ => None,
    }
}

pub fn run(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &RunOptions,
) -> Result<RunOutput> {
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
    renderer.frames(opts.warmup, tick)?;
    let frames = renderer.frames(opts.measured.max(1), tick)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let capture = if opts.capture {
        Some(renderer.capture(opts.dump)?)
    } else {
        None
    };
    let (mut passes, frame) = aggregate(&frames);
    let sss_totals: Vec<f64> = frames
        .iter()
        .map(|f| {
            f.iter()
                .filter(|s| is_sss_pass(&s.name))
                .map(|s| s.gpu_ms + s.barrier_ms)
                .sum()
        })
        .collect();
    let has_sss = frames
        .first()
        .map(|f| f.iter().any(|s| is_sss_pass(&s.name)))
        .unwrap_or(false);
    let extent = renderer.gpu.extent;
    let mm_per_unit = renderer.gpu.mm_per_unit;
    let region = &renderer.gpu.region_px;
    let (sss_region_pixels, sss_region_rects) =
        (region.iter().map(|r| r.area()).sum(), region.len());
    drop(renderer);

    let (ceilings, probes) = if opts.ceilings {
        let (c, p) = ceilings::measure(ctx, extent, 7).context("measuring device ceilings")?;
        for pass in &mut passes {
            if let (Some(cost), Some(inv)) =
                (pass_cost(&pass.name, settings), pass.fragment_invocations)
            {
                let f = floor_ms(&cost, inv, &c);
                pass.floor_ms = Some(f);
                pass.floor_ratio = (f > 0.0).then(|| pass.gpu_ms.median / f);
            }
        }
        (Some(c), Some(p))
    } else {
        (None, None)
    };

    let f = &ctx.facts;
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
        method: settings.method.name(),
        samples: settings.samples,
        preset: settings.preset.name(),
        sss_params: settings.params,
        follow_surface: settings.follow_surface,
        transmittance: settings.transmittance,
        transmittance_profile: settings.transmittance_profile,
        fit: settings.fit,
        lod: settings.lod,
        mask: settings.mask,
        sss_region: settings.sss_region,
        sss_region_pixels,
        sss_region_rects,
        scene: scene.name.clone(),
        mm_per_unit,
        heads: settings.heads,
        distance_heads: settings.distance_heads,
        fovy_deg: settings.fovy_deg,
        light: LightReport {
            azimuth_deg: settings.light.azimuth_deg,
            elevation_deg: settings.light.elevation_deg,
            intensity: settings.light.intensity,
        },
        warmup_frames: opts.warmup,
        measured_frames: opts.measured.max(1),
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

/// Writes the tone-mapped frame as an sRGB PNG.
pub fn write_png(path: &Path, c: &Capture) -> Result<()> {
    let mut rgba = c.ldr.clone();
    for px in rgba.chunks_exact_mut(4) {
        px[3] = 255;
    }
    let img = image::RgbaImage::from_raw(c.width, c.height, rgba).context("frame size mismatch")?;
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes one pass output as a linear float EXR.
pub fn write_exr(path: &Path, d: &DumpedImage) -> Result<()> {
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

/// Reads an RGBA EXR written by dermis.
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    let img = image::open(path)
        .with_context(|| format!("reading {}", path.display()))?
        .to_rgba32f();
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

    #[test]
    fn slugs_are_file_safe() {
        assert_eq!(slug("sss horizontal -> diffuse"), "sss_horizontal_diffuse");
        assert_eq!(slug("Shadow Map"), "shadow_map");
    }

    #[test]
    fn only_modelled_passes_get_floors() {
        let s = RenderSettings::default();
        assert!(pass_cost("sss horizontal", &s).is_some());
        assert!(pass_cost("geometry", &s).is_none());
    }
}
