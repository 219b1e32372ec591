//! Micro-passes that measure the device's own ceilings in the same run as the
//! benchmark: bilinear and point fetch rates for each format the SSS passes
//! read (RGBA16F colour, R32F depth), and the fill rates of the writes the
//! frame makes (RGBA16F, RGBA16F blended, RGBA8), on the fragment path; the
//! same fetches and RGBA16F storage stores on the compute path
//! (probe_fetch.comp, in the compute blurs' 16x16 groups).

use anyhow::Result;
use ash::vk;

use super::floor::{Ceilings, ComputeCeilings};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{
    record_passes, Binding, ColorTarget, GraphSet, ImageDesc, Load, Pass, PassContext, Resources,
    Storage,
};
use crate::render::targets::LDR_FORMAT;
use crate::report::Stats;
use crate::shader_constants::SSS_TILE_SIDE;
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, Blend, DescriptorPool, GraphicsDesc, Pipeline, Samplers};
use crate::vk::profiler::Profiler;
use crate::vk::upload;

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
/// texture (fetch probes) or nothing (fill probes), or dispatched over the
/// target (compute probes: their set binds it as a storage image).
struct Probe<'p> {
    pipeline: &'p Pipeline,
    /// The source's set, and what a fetch of it is (the uploaded sources are
    /// not frame images: their barriers were made by the upload, and the set
    /// declares nothing).
    src: Option<(&'p GraphSet, (Format, Filter))>,
    /// The target as the probe's pass declares it (load op, blending);
    /// `None`: a dispatch.
    target: Option<ColorTarget>,
    /// Fetches per invocation (0: a fill or store probe).
    taps: i32,
}

// report.json's type: the schema lives in `report`.
pub use crate::report::ProbeResult;

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
    // Guarded: freed when this returns, after the wait-idle below.
    let src_rgba = Guard::new(
        ctx,
        upload::texture(
            ctx,
            "probe rgba16f",
            extent,
            vk::Format::R16G16B16A16_SFLOAT,
            bytemuck::cast_slice(&rgba),
        )?,
    );
    let src_r32 = Guard::new(
        ctx,
        upload::texture(
            ctx,
            "probe r32f",
            extent,
            vk::Format::R32_SFLOAT,
            bytemuck::cast_slice(&r32),
        )?,
    );
    let mut res = Guard::<Resources>::null(ctx);
    let result = probe_all(ctx, &mut res, extent, reps, [&src_rgba, &src_r32]);
    unsafe {
        let _ = ctx.device.device_wait_idle();
    }
    result
}

/// The probes proper, on the uploaded sources (rgba16f, r32f).
///
/// Long because every probe is stated here, once: its pipeline, its set and
/// its name beside the others of its kind (fragment fetches, fills, compute
/// fetches and stores), so the table of ceilings reads off one list.
fn probe_all(
    ctx: &Context,
    res: &mut Resources,
    extent: vk::Extent2D,
    reps: usize,
    sources: [&Image; 2],
) -> Result<(Ceilings, Vec<ProbeResult>)> {
    let n = (extent.width * extent.height) as u64;
    let id_target = res.declare(ImageDesc::new(
        "probe target",
        extent,
        vk::Format::R16G16B16A16_SFLOAT,
    ));
    // The tone map writes 32 bpp: ROPs fill those at their own rate.
    let id_ldr = res.declare(ImageDesc::new("probe target rgba8", extent, LDR_FORMAT));
    // Fills overwrite their target; the blend reads it (a read-modify-write).
    let overwrite = ColorTarget::new(id_target, Load::DontCare);
    let overwrite_ldr = ColorTarget::new(id_ldr, Load::DontCare);
    let blended = ColorTarget::new(id_target, Load::Keep).blended();
    res.allow(&[overwrite, blended, overwrite_ldr].map(|c| (c.image, c.access())));
    res.allow(&[(id_target, AccessKind::ComputeStorageWrite)]);
    res.create(ctx)?;
    let mut owned = Owned {
        ctx,
        samplers: Some(Samplers::new(ctx)?),
        pool: None,
        pipelines: Vec::new(),
    };
    owned.pool = Some(DescriptorPool::new(ctx, 8)?);
    let rgba16f = vk::Format::R16G16B16A16_SFLOAT;
    let mut blend = GraphicsDesc::fullscreen("probe blend", "probe_fill.frag", rgba16f);
    // The ssg vertical pass blends RTF (eq. 4.9): a read-modify-write per pixel.
    blend.blend = Blend::ConstantMix(0);
    for d in [
        GraphicsDesc::fullscreen("probe fetch", "probe_fetch.frag", rgba16f),
        GraphicsDesc::fullscreen("probe fill", "probe_fill.frag", rgba16f),
        GraphicsDesc::fullscreen("probe fill rgba8", "probe_fill.frag", LDR_FORMAT),
        blend,
    ] {
        let p = Pipeline::graphics(ctx, &d)?;
        owned.pipelines.push(p);
    }
    let p = Pipeline::compute(ctx, "probe fetch compute", "probe_fetch.comp")?;
    owned.pipelines.push(p);
    let samplers = owned.samplers.as_ref().expect("created above");
    let pool = owned.pool.as_ref().expect("created above");
    let [fetch, fill, fill_ldr, fill_blend, fetch_cs] =
        [0, 1, 2, 3, 4].map(|i| &owned.pipelines[i]);
    let set = |img: &Image, sampler| -> Result<GraphSet> {
        let binds = vec![
            ("srcTex", Binding::Fixed(Bind::Texture(img.view))),
            ("srcSampler", Binding::Fixed(Bind::Sampler(sampler))),
        ];
        let mut set = GraphSet::new(res, fetch, 0, binds);
        set.write(ctx, pool, res, fetch)?;
        Ok(set)
    };
    let [rgba, r32] = sources;
    let (linear, nearest) = (samplers.linear_clamp, samplers.nearest_clamp);
    let sets = [
        set(rgba, linear)?,
        set(rgba, nearest)?,
        set(r32, linear)?,
        set(r32, nearest)?,
    ];
    let cs_set = |img: &Image, sampler| -> Result<GraphSet> {
        let binds = vec![
            ("srcTex", Binding::Fixed(Bind::Texture(img.view))),
            ("srcSampler", Binding::Fixed(Bind::Sampler(sampler))),
            ("outImage", Binding::StorageImage(id_target, Storage::Write)),
        ];
        let mut set = GraphSet::new(res, fetch_cs, 0, binds);
        set.write(ctx, pool, res, fetch_cs)?;
        Ok(set)
    };
    let cs_sets = [
        cs_set(rgba, linear)?,
        cs_set(rgba, nearest)?,
        cs_set(r32, linear)?,
        cs_set(r32, nearest)?,
    ];
    let fetch_probe = |s, format| Probe {
        pipeline: fetch,
        src: Some((s, format)),
        target: Some(overwrite),
        taps: PROBE_TAPS,
    };
    let fill_probe = |pipeline, target| Probe {
        pipeline,
        src: None,
        target: Some(target),
        taps: 0,
    };
    let compute_probe = |s, format, taps| Probe {
        pipeline: fetch_cs,
        src: Some((s, format)),
        target: None,
        taps,
    };
    let probes: Vec<(&str, Probe)> = vec![
        (
            "bilinear rgba16f",
            fetch_probe(&sets[0], (Format::Rgba16Float, Filter::Bilinear)),
        ),
        (
            "point rgba16f",
            fetch_probe(&sets[1], (Format::Rgba16Float, Filter::Point)),
        ),
        (
            "bilinear r32f",
            fetch_probe(&sets[2], (Format::R32Float, Filter::Bilinear)),
        ),
        (
            "point r32f",
            fetch_probe(&sets[3], (Format::R32Float, Filter::Point)),
        ),
        ("fill rgba16f", fill_probe(fill, overwrite)),
        ("fill rgba8", fill_probe(fill_ldr, overwrite_ldr)),
        ("blend rgba16f", fill_probe(fill_blend, blended)),
        (
            "compute bilinear rgba16f",
            compute_probe(
                &cs_sets[0],
                (Format::Rgba16Float, Filter::Bilinear),
                PROBE_TAPS,
            ),
        ),
        (
            "compute point rgba16f",
            compute_probe(
                &cs_sets[1],
                (Format::Rgba16Float, Filter::Point),
                PROBE_TAPS,
            ),
        ),
        (
            "compute bilinear r32f",
            compute_probe(
                &cs_sets[2],
                (Format::R32Float, Filter::Bilinear),
                PROBE_TAPS,
            ),
        ),
        (
            "compute point r32f",
            compute_probe(&cs_sets[3], (Format::R32Float, Filter::Point), PROBE_TAPS),
        ),
        (
            "compute store rgba16f",
            compute_probe(&cs_sets[1], (Format::Rgba16Float, Filter::Point), 0),
        ),
    ];
    let texel = [1.0 / extent.width as f32, 1.0 / extent.height as f32];
    let mut passes = Vec::new();
    // One warm-up round, then `reps` measured rounds.
    for round in 0..=reps {
        for (name, probe) in &probes {
            passes.push(probe.pass(&format!("{name} #{round}"), texel, extent));
        }
    }
    let profiler = Profiler::new(ctx, passes.len() as u32)?;
    let run = ctx.one_shot("ceiling probes", |cmd| {
        record_passes(ctx, cmd, res, &passes, Some(&profiler))
    });
    let samples = run.and_then(|_| profiler.read(ctx, passes.len()));
    profiler.destroy(ctx);
    let samples = samples?;
    ctx.check_validation("during the ceiling probes")?;
    let with_src: Vec<(&str, bool)> = probes.iter().map(|(n, p)| (*n, p.taps > 0)).collect();
    Ok(ceilings_from(&samples, &with_src, reps, n))
}

/// The ceilings from the probes' timings: probe `i` of round `r` (round 0 is
/// the warm-up) is sample `r * probes + i`.
fn ceilings_from(
    samples: &[crate::vk::profiler::PassTiming],
    probes: &[(&str, bool)],
    reps: usize,
    n: u64,
) -> (Ceilings, Vec<ProbeResult>) {
    let mut results = Vec::new();
    for (pi, (name, fetches)) in probes.iter().enumerate() {
        let times: Vec<f64> = (1..=reps)
            .map(|r| samples[r * probes.len() + pi].gpu_ms)
            .collect();
        let stats = Stats::of(&times).expect("reps >= 1");
        let taps = if *fetches { PROBE_TAPS } else { 1 };
        let ops = n as f64 * taps as f64;
        results.push(ProbeResult {
            name: name.to_string(),
            taps_per_fragment: taps,
            fragments: n,
            gpu_ms: stats,
            rate_g_per_s: ops / (stats.median.max(1e-9) * 1e-3) / 1e9,
        });
    }
    let r = |i: usize| results[i].rate_g_per_s;
    (
        Ceilings {
            bilinear_rgba16f_gtaps: r(0),
            point_rgba16f_gtaps: r(1),
            bilinear_r32f_gtaps: r(2),
            point_r32f_gtaps: r(3),
            fill_rgba16f_gpix: r(4),
            fill_rgba8_gpix: Some(r(5)),
            blend_rgba16f_gpix: Some(r(6)),
            compute: Some(ComputeCeilings {
                bilinear_rgba16f_gtaps: r(7),
                point_rgba16f_gtaps: r(8),
                bilinear_r32f_gtaps: r(9),
                point_r32f_gtaps: r(10),
                store_rgba16f_gpix: r(11),
            }),
        },
        results,
    )
}

/// The probes' pipelines, pool and samplers, destroyed whatever happens.
struct Owned<'c> {
    ctx: &'c Context,
    samplers: Option<Samplers>,
    pool: Option<DescriptorPool>,
    pipelines: Vec<Pipeline>,
}

impl Drop for Owned<'_> {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
        }
        for p in &mut self.pipelines {
            p.destroy(self.ctx);
        }
        if let Some(mut p) = self.pool.take() {
            p.destroy(self.ctx);
        }
        if let Some(s) = self.samplers.take() {
            s.destroy(self.ctx);
        }
    }
}

impl<'p> Probe<'p> {
    fn pass(&self, name: &str, texel: [f32; 2], extent: vk::Extent2D) -> Pass<'p> {
        let (pipeline, set) = (self.pipeline, self.src.map(|(s, _)| s));
        let fetches = match self.src {
            Some((_, (format, filter))) if self.taps > 0 => vec![Fetch {
                texture: "srcTex".into(),
                format,
                filter,
                count: self.taps as f64,
                exact: true,
                coherent: true,
                spread: Vec::new(),
            }],
            _ => Vec::new(),
        };
        let push = ProbePush {
            texel,
            taps: self.taps,
            pad: 0,
        };
        let Some(target) = self.target else {
            let set = set.expect("a compute probe binds its target");
            let work = ShaderWork {
                shader: "probe_fetch.comp".into(),
                fetches,
                storage_write_bytes: 8.0,
                ..Default::default()
            };
            let mut pass = Pass::new(name, PassRole::Probe);
            let set = pass.set(set);
            let side = SSS_TILE_SIDE;
            let groups = [extent.width.div_ceil(side), extent.height.div_ceil(side), 1];
            return pass
                .dispatch(work, groups, side * side)
                .record(move |pc: &PassContext| {
                    pc.bind(pipeline, &[set]);
                    pipeline.push(pc.ctx, pc.cmd, &push);
                });
        };
        let work = ShaderWork {
            shader: if set.is_some() {
                "probe_fetch.frag"
            } else {
                "probe_fill.frag"
            }
            .into(),
            fetches,
            ..Default::default()
        };
        let mut pass = Pass::new(name, PassRole::Probe);
        let set = set.map(|s| pass.set(s));
        pass.color(target)
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, set.as_slice(), |c, cmd| {
                    unsafe {
                        if pipeline.has_blend_constants {
                            c.device.cmd_set_blend_constants(cmd, &[0.5; 4]);
                        }
                    }
                    if set.is_some() {
                        pipeline.push(c, cmd, &push);
                    }
                })
            })
    }
}
