//! Micro-passes that measure the device's own fragment-shader ceilings in the
//! same run as the benchmark: bilinear and point fetch rates for each format the
//! SSS passes read (RGBA16F colour, R32F depth), and the fill rates of the writes
//! the frame makes (RGBA16F, RGBA16F blended, RGBA8).

use anyhow::Result;
use ash::vk;
use serde::Serialize;

use super::floor::Ceilings;
use crate::graph::{record_passes, ImageId, Pass, PassContext, Resources};
use crate::render::draw::begin_color_rendering;
use crate::render::upload;
use crate::render::LDR_FORMAT;
use crate::report::Stats;
use crate::vk::barrier::{AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, Blend, DescriptorPool, GraphicsDesc, Pipeline, Samplers};
use crate::vk::profiler::Profiler;

/// Fetches per fragment in the fetch probes: enough that fetches, not fill, bound them.
pub const PROBE_TAPS: i32 = 16;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbePush {
    texel: [f32; 2],
    taps: i32,
    pad: i32,
}

/// One probe: a pipeline drawn full-screen into a target, reading a source
/// texture (fetch probes) or nothing (fill probes).
struct Probe<'p> {
    pipeline: &'p Pipeline,
    src: Option<(vk::DescriptorSet, ImageId)>,
    target: (ImageId, vk::ImageView),
    access: AccessKind,
}

/// One probe's measurement.
#[derive(Clone, Debug, Serialize)]
pub struct ProbeResult {
    pub name: String,
    pub taps_per_fragment: i32,
    pub fragments: u64,
    pub gpu_ms: Stats,
    /// Giga-taps (or giga-pixels for the fill probe) per second at the median.
    pub rate_g_per_s: f64,
}

/// Measures the ceilings at `extent` with `reps` repetitions of each probe.
pub fn measure(
    ctx: &Context,
    extent: vk::Extent2D,
    reps: usize,
) -> Result<(Ceilings, Vec<ProbeResult>)> {
    let reps = reps.clamp(1, 12);
    let n = (extent.width * extent.height) as usize;
    // A smooth pattern: fetch rates, not cache misses on noise, are what SSS sees.
    let rgba: Vec<u16> = (0..n)
        .flat_map(|i| {
            let v = half::f16::from_f32(0.25 + 0.5 * ((i % 97) as f32 / 97.0)).to_bits();
            [v, v, v, v]
        })
        .collect();
    let r32: Vec<f32> = (0..n).map(|i| 10.0 + (i % 89) as f32 * 0.01).collect();
    let mut src_rgba = upload::texture(
        ctx,
        "probe rgba16f",
        extent,
        vk::Format::R16G16B16A16_SFLOAT,
        bytemuck::cast_slice(&rgba),
    )?;
    let mut src_r32 = upload::texture(
        ctx,
        "probe r32f",
        extent,
        vk::Format::R32_SFLOAT,
        bytemuck::cast_slice(&r32),
    )?;
    let mut target = Image::new(
        ctx,
        "probe target",
        extent,
        vk::Format::R16G16B16A16_SFLOAT,
        vk::ImageUsageFlags::COLOR_ATTACHMENT,
    )?;
    // The tone map writes 32 bpp: ROPs fill those at their own rate.
    let mut target_ldr = Image::new(
        ctx,
        "probe target rgba8",
        extent,
        LDR_FORMAT,
        vk::ImageUsageFlags::COLOR_ATTACHMENT,
    )?;
    let samplers = Samplers::new(ctx)?;
    let mut pool = DescriptorPool::new(ctx, 8)?;
    let mut fetch = Pipeline::graphics(
        ctx,
        &GraphicsDesc::fullscreen(
            "probe fetch",
            "probe_fetch.frag",
            vk::Format::R16G16B16A16_SFLOAT,
        ),
    )?;
    let mut fill = Pipeline::graphics(
        ctx,
        &GraphicsDesc::fullscreen(
            "probe fill",
            "probe_fill.frag",
            vk::Format::R16G16B16A16_SFLOAT,
        ),
    )?;
    let mut fill_ldr = Pipeline::graphics(
        ctx,
        &GraphicsDesc::fullscreen("probe fill rgba8", "probe_fill.frag", LDR_FORMAT),
    )?;
    // The ssg vertical pass blends RTF (eq. 4.9): a read-modify-write per pixel.
    let mut fill_blend = Pipeline::graphics(ctx, &{
        let mut d = GraphicsDesc::fullscreen(
            "probe blend",
            "probe_fill.frag",
            vk::Format::R16G16B16A16_SFLOAT,
        );
        d.blend = Blend::ConstantMix(0);
        d
    })?;

    let result = (|| -> Result<(Ceilings, Vec<ProbeResult>)> {
        let mut res = Resources::default();
        let id_rgba = res.add_image("probe rgba16f", src_rgba.raw, src_rgba.subresource_range());
        let id_r32 = res.add_image("probe r32f", src_r32.raw, src_r32.subresource_range());
        let id_target = res.add_image("probe target", target.raw, target.subresource_range());
        let id_ldr = res.add_image(
            "probe target rgba8",
            target_ldr.raw,
            target_ldr.subresource_range(),
        );
        res.images[id_rgba.0].state = ResourceState::uploaded(AccessKind::FragmentSampledRead);
        res.images[id_r32.0].state = ResourceState::uploaded(AccessKind::FragmentSampledRead);
        let set = |img: &Image, sampler| {
            pool.write_set(
                ctx,
                &fetch,
                0,
                &[
                    ("srcTex", Bind::Texture(img.view)),
                    ("srcSampler", Bind::Sampler(sampler)),
                ],
            )
        };
        let fetch_probe = |s, id| Probe {
            pipeline: &fetch,
            src: Some((s, id)),
            target: (id_target, target.view),
            access: AccessKind::ColorAttachmentWrite,
        };
        let fill_probe = |pipeline, target, access| Probe {
            pipeline,
            src: None,
            target,
            access,
        };
        let probes: Vec<(&str, Probe)> = vec![
            (
                "bilinear rgba16f",
                fetch_probe(set(&src_rgba, samplers.linear_clamp)?, id_rgba),
            ),
            (
                "point rgba16f",
                fetch_probe(set(&src_rgba, samplers.nearest_clamp)?, id_rgba),
            ),
            (
                "bilinear r32f",
                fetch_probe(set(&src_r32, samplers.linear_clamp)?, id_r32),
            ),
            (
                "point r32f",
                fetch_probe(set(&src_r32, samplers.nearest_clamp)?, id_r32),
            ),
            (
                "fill rgba16f",
                fill_probe(
                    &fill,
                    (id_target, target.view),
                    AccessKind::ColorAttachmentWrite,
                ),
            ),
            (
                "fill rgba8",
                fill_probe(
                    &fill_ldr,
                    (id_ldr, target_ldr.view),
                    AccessKind::ColorAttachmentWrite,
                ),
            ),
            (
                "blend rgba16f",
                fill_probe(
                    &fill_blend,
                    (id_target, target.view),
                    AccessKind::ColorAttachmentLoadWrite,
                ),
            ),
        ];
        let texel = [1.0 / extent.width as f32, 1.0 / extent.height as f32];
        let mut passes = Vec::new();
        // One untimed-in-effect warm-up round, then `reps` measured rounds.
        for round in 0..=reps {
            for (name, probe) in &probes {
                let (pipeline, set) = (probe.pipeline, probe.src.map(|(s, _)| s));
                let (target_id, target_view) = probe.target;
                let load = if probe.access == AccessKind::ColorAttachmentLoadWrite {
                    vk::AttachmentLoadOp::LOAD
                } else {
                    vk::AttachmentLoadOp::DONT_CARE
                };
                let mut pass = Pass::new(format!("{name} #{round}"));
                if let Some((_, id)) = probe.src {
                    pass = pass.image(id, AccessKind::FragmentSampledRead);
                }
                pass = pass
                    .image(target_id, probe.access)
                    .record(move |pc: &PassContext| {
                        let (c, cmd) = (pc.ctx, pc.cmd);
                        begin_color_rendering(c, cmd, &[target_view], extent, load);
                        unsafe {
                            c.device.cmd_bind_pipeline(
                                cmd,
                                vk::PipelineBindPoint::GRAPHICS,
                                pipeline.raw,
                            );
                            if pipeline.has_blend_constants {
                                c.device.cmd_set_blend_constants(cmd, &[0.5; 4]);
                            }
                            if let Some(s) = set {
                                c.device.cmd_bind_descriptor_sets(
                                    cmd,
                                    vk::PipelineBindPoint::GRAPHICS,
                                    pipeline.layout,
                                    0,
                                    &[s],
                                    &[],
                                );
                                pipeline.push(
                                    c,
                                    cmd,
                                    &ProbePush {
                                        texel,
                                        taps: PROBE_TAPS,
                                        pad: 0,
                                    },
                                );
                            }
                            c.device.cmd_draw(cmd, 3, 1, 0, 0);
                            c.device.cmd_end_rendering(cmd);
                        }
                    });
                passes.push(pass);
            }
        }
        let profiler = Profiler::new(ctx, passes.len() as u32)?;
        let names: Vec<String> = passes.iter().map(|p| p.name.clone()).collect();
        let run = ctx.one_shot("ceiling probes", |cmd| {
            record_passes(ctx, cmd, &mut res, &passes, Some(&profiler))
        });
        let samples = run.and_then(|_| profiler.read(ctx, &names));
        profiler.destroy(ctx);
        let samples = samples?;
        ctx.check_validation("during the ceiling probes")?;
        let mut results = Vec::new();
        for (pi, (name, probe)) in probes.iter().enumerate() {
            let times: Vec<f64> = (1..=reps)
                .map(|r| samples[r * probes.len() + pi].gpu_ms)
                .collect();
            let stats = Stats::of(&times).expect("reps >= 1");
            let taps = if probe.src.is_some() { PROBE_TAPS } else { 1 };
            let ops = n as f64 * taps as f64;
            results.push(ProbeResult {
                name: name.to_string(),
                taps_per_fragment: taps,
                fragments: n as u64,
                gpu_ms: stats,
                rate_g_per_s: ops / (stats.median.max(1e-9) * 1e-3) / 1e9,
            });
        }
        let r = |i: usize| results[i].rate_g_per_s;
        Ok((
            Ceilings {
                bilinear_rgba16f_gtaps: r(0),
                point_rgba16f_gtaps: r(1),
                bilinear_r32f_gtaps: r(2),
                point_r32f_gtaps: r(3),
                fill_rgba16f_gpix: r(4),
                fill_rgba8_gpix: r(5),
                blend_rgba16f_gpix: r(6),
            },
            results,
        ))
    })();
    unsafe {
        let _ = ctx.device.device_wait_idle();
    }
    fetch.destroy(ctx);
    fill.destroy(ctx);
    fill_ldr.destroy(ctx);
    fill_blend.destroy(ctx);
    pool.destroy(ctx);
    samplers.destroy(ctx);
    src_rgba.destroy(ctx);
    src_r32.destroy(ctx);
    target.destroy(ctx);
    target_ldr.destroy(ctx);
    result
}
