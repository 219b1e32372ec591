//! Micro-passes that measure the device's own ceilings in the same run as the
//! benchmark: bilinear and point fetch rates for each format the frame's
//! passes read (RGBA16F colour, R32F depth, RGBA8 maps and LDR images) and
//! the depth-compare (PCF) rate of the shadow taps, and the fill rates of the
//! writes the frame makes (RGBA16F, RGBA16F blended, RGBA8, the geometry
//! pass's attachments at once, the shadow map's depth alone), on the fragment
//! path; the rasteriser's triangle rate in the shadow and the geometry pass's
//! states (probe_triangles.vert); the copy rate of an RGBA16F image; the same fetches, RGBA16F storage stores and
//! shared-memory loads on the compute path (probe_fetch.comp,
//! probe_shared.comp, in the compute blurs' 16x16 groups).

use anyhow::Result;
use ash::vk;

use super::floor::{Ceilings, ComputeCeilings};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork, Work};
use crate::graph::DepthStencil;
use crate::graph::{
    record_passes, Binding, ColorTarget, GraphSet, ImageDesc, ImageId, Load, Pass, PassContext,
    Resources, Storage,
};
use crate::render::targets::{depth_stencil_format, LDR_FORMAT, SHADOW_FORMAT};
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

/// Shared-memory loads per invocation in the shared-memory probe (16 bytes
/// each): enough that they, not its one fetch and one store, bound it.
pub const SHARED_TAPS: i32 = 64;

/// Bytes of one shared-memory load of probe_shared.comp (a vec4).
const SHARED_LOAD_BYTES: f64 = 16.0;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbePush {
    texel: [f32; 2],
    taps: i32,
    pad: i32,
}

/// What a probe draws or dispatches.
#[derive(Clone)]
enum Draw {
    /// A full-screen triangle into these attachments.
    Fullscreen(Vec<ColorTarget>, Option<DepthStencil>),
    /// One tiny triangle per pixel of the extent (probe_triangles.vert).
    Triangles(Vec<ColorTarget>, DepthStencil),
    /// One invocation per pixel in 16x16 groups (its set binds the target).
    Dispatch,
    /// One 16x16 group: a dispatch's cost before its work (launch, the
    /// barrier's drain and the timestamps around it), [`Unit::Pass`].
    DispatchOne,
    /// A copy of the whole first image into the second (as a seed copy).
    Copy(ImageId, ImageId),
}

/// What a probe's rate counts per pixel of the extent.
#[derive(Clone, Copy, PartialEq)]
enum Unit {
    /// Fetches (its `taps` per pixel) or, with no taps, pixels written.
    Taps,
    /// Triangles (one per pixel).
    Triangles,
    /// Shared-memory bytes (`taps` loads of 16 bytes per pixel).
    SharedBytes,
    /// Whole passes: the probe's median time is its result (ms).
    Pass,
}

/// One probe: a pipeline drawn into its targets, reading a source texture
/// (fetch probes) or nothing (fill and triangle probes), or dispatched over
/// the target (compute probes: their set binds it as a storage image).
struct Probe<'p> {
    pipeline: &'p Pipeline,
    shader: &'static str,
    /// The source's set, and what a fetch of it is (the uploaded sources are
    /// not frame images: their barriers were made by the upload, and the set
    /// declares nothing; the PCF probe's depth source is a frame image, and
    /// its set declares the read).
    src: Option<(&'p GraphSet, (Format, Filter))>,
    draw: Draw,
    /// Fetches (or shared loads) per invocation (0: a fill, store or triangle probe).
    taps: i32,
    unit: Unit,
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
    // The same pattern in 8 bits, as the AA passes and the maps are read.
    let rgba8: Vec<u8> = rgba
        .iter()
        .map(|&h| (half::f16::from_bits(h).to_f32() * 255.0) as u8)
        .collect();
    let src_rgba8 = Guard::new(
        ctx,
        upload::texture(
            ctx,
            "probe rgba8",
            extent,
            vk::Format::R8G8B8A8_UNORM,
            &rgba8,
        )?,
    );
    let mut res = Guard::<Resources>::null(ctx);
    let result = probe_all(
        ctx,
        &mut res,
        extent,
        reps,
        [&src_rgba, &src_r32, &src_rgba8],
    );
    unsafe {
        let _ = ctx.device.device_wait_idle();
    }
    result
}

/// The probes proper, on the uploaded sources (rgba16f, r32f, rgba8).
///
/// Long because every probe is stated here, once: its pipeline, its set and
/// its name beside the others of its kind (fragment fetches, fills, the
/// rasteriser's, compute fetches, stores and shared loads), so the table of
/// ceilings reads off one list.
fn probe_all(
    ctx: &Context,
    res: &mut Resources,
    extent: vk::Extent2D,
    reps: usize,
    sources: [&Image; 3],
) -> Result<(Ceilings, Vec<ProbeResult>)> {
    let n = (extent.width * extent.height) as u64;
    let rgba16f = vk::Format::R16G16B16A16_SFLOAT;
    let id_target = res.declare(ImageDesc::new("probe target", extent, rgba16f));
    // The tone map writes 32 bpp: ROPs fill those at their own rate.
    let id_ldr = res.declare(ImageDesc::new("probe target rgba8", extent, LDR_FORMAT));
    // The geometry pass's other attachments (its diffuse is `id_target`).
    let id_specular = res.declare(ImageDesc::new("probe target 2", extent, rgba16f));
    let id_r32 = res.declare(ImageDesc::new(
        "probe target r32f",
        extent,
        vk::Format::R32_SFLOAT,
    ));
    let ds_format = depth_stencil_format(ctx)?;
    let id_ds = res.declare(ImageDesc::new("probe depth stencil", extent, ds_format));
    // The shadow map's format: written by the depth-only probes, then the
    // PCF probe's source.
    let id_depth = res.declare(ImageDesc::new("probe depth", extent, SHADOW_FORMAT));
    // Fills overwrite their target; the blend reads it (a read-modify-write).
    let overwrite = ColorTarget::new(id_target, Load::DontCare);
    let overwrite_ldr = ColorTarget::new(id_ldr, Load::DontCare);
    let blended = ColorTarget::new(id_target, Load::Keep).blended();
    let mrt = vec![
        overwrite,
        ColorTarget::new(id_specular, Load::DontCare),
        ColorTarget::new(id_r32, Load::DontCare),
    ];
    // As the geometry pass: depth cleared, tested and written, stencil written.
    let mrt_ds = DepthStencil::cleared(id_ds, 1.0).stencil_write(true);
    let depth_only = DepthStencil::cleared(id_depth, 1.0);
    let mut allowed: Vec<(ImageId, AccessKind)> = [overwrite, blended, overwrite_ldr]
        .map(|c| (c.image, c.access()))
        .to_vec();
    allowed.extend(mrt.iter().map(|c| (c.image, c.access())));
    allowed.extend([
        (id_target, AccessKind::ComputeStorageWrite),
        (id_ds, AccessKind::DepthStencilWrite),
        (id_depth, AccessKind::DepthStencilWrite),
        (id_depth, AccessKind::FragmentSampledRead),
        (id_target, AccessKind::TransferRead),
        (id_specular, AccessKind::TransferWrite),
    ]);
    res.allow(&allowed);
    res.create(ctx)?;
    let mut owned = Owned {
        ctx,
        samplers: Some(Samplers::new(ctx)?),
        pool: None,
        pipelines: Vec::new(),
    };
    owned.pool = Some(DescriptorPool::new(ctx, 16)?);
    let mut blend = GraphicsDesc::fullscreen("probe blend", "probe_fill.frag", rgba16f);
    // The ssg vertical pass blends RTF (eq. 4.9): a read-modify-write per pixel.
    blend.blend = Blend::ConstantMix(0);
    let mrt_formats = vec![rgba16f, rgba16f, vk::Format::R32_SFLOAT];
    // The geometry pass's attachment state (render::frame), every test passing.
    let mut fill_mrt = GraphicsDesc::fullscreen("probe fill mrt", "probe_fill_mrt.frag", rgba16f);
    fill_mrt.color_formats = mrt_formats;
    fill_mrt.depth_format = Some(ds_format);
    fill_mrt.stencil_format = Some(ds_format);
    fill_mrt.depth_test = true;
    fill_mrt.depth_write = true;
    fill_mrt.stencil = Some(vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::REPLACE,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::ALWAYS,
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    });
    let mut triangles_mrt = fill_mrt.clone();
    triangles_mrt.name = "probe triangles mrt".into();
    triangles_mrt.vert = "probe_triangles.vert";
    // The shadow pass's state: depth only, no fragment shader.
    let mut fill_depth = GraphicsDesc::fullscreen("probe fill depth", "probe_fill.frag", rgba16f);
    fill_depth.frag = None;
    fill_depth.color_formats = vec![];
    fill_depth.depth_format = Some(SHADOW_FORMAT);
    fill_depth.depth_test = true;
    fill_depth.depth_write = true;
    let mut triangles_depth = fill_depth.clone();
    triangles_depth.name = "probe triangles depth".into();
    triangles_depth.vert = "probe_triangles.vert";
    for d in [
        GraphicsDesc::fullscreen("probe fetch", "probe_fetch.frag", rgba16f),
        GraphicsDesc::fullscreen("probe fill", "probe_fill.frag", rgba16f),
        GraphicsDesc::fullscreen("probe fill rgba8", "probe_fill.frag", LDR_FORMAT),
        blend,
        fill_mrt,
        fill_depth,
        triangles_mrt,
        triangles_depth,
        GraphicsDesc::fullscreen("probe pcf", "probe_pcf.frag", rgba16f),
    ] {
        let p = Pipeline::graphics(ctx, &d)?;
        owned.pipelines.push(p);
    }
    for (name, shader) in [
        ("probe fetch compute", "probe_fetch.comp"),
        ("probe shared compute", "probe_shared.comp"),
    ] {
        let p = Pipeline::compute(ctx, name, shader)?;
        owned.pipelines.push(p);
    }
    let samplers = owned.samplers.as_ref().expect("created above");
    let pool = owned.pool.as_ref().expect("created above");
    let [fetch, fill, fill_ldr, fill_blend, fill_mrt, fill_depth, tri_mrt, tri_depth, pcf, fetch_cs, shared_cs] =
        [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10].map(|i| &owned.pipelines[i]);
    let set = |img: &Image, sampler| -> Result<GraphSet> {
        let binds = vec![
            ("srcTex", Binding::Fixed(Bind::Texture(img.view))),
            ("srcSampler", Binding::Fixed(Bind::Sampler(sampler))),
        ];
        let mut set = GraphSet::new(res, fetch, 0, binds);
        set.write(ctx, pool, res, fetch)?;
        Ok(set)
    };
    let [rgba, r32, rgba8] = sources;
    let (linear, nearest) = (samplers.linear_clamp, samplers.nearest_clamp);
    let sets = [
        set(rgba, linear)?,
        set(rgba, nearest)?,
        set(r32, linear)?,
        set(r32, nearest)?,
        set(rgba8, linear)?,
        set(rgba8, nearest)?,
    ];
    // The depth the depth-only probes wrote, read through the shadow
    // sampler (a frame image: the set declares the read, the graph the barrier).
    let pcf_set = {
        let binds = vec![
            ("srcTex", Binding::Sampled(id_depth)),
            (
                "srcSampler",
                Binding::Fixed(Bind::Sampler(samplers.shadow_compare)),
            ),
        ];
        let mut set = GraphSet::new(res, pcf, 0, binds);
        set.write(ctx, pool, res, pcf)?;
        set
    };
    let cs_set = |p: &Pipeline, img: &Image, sampler| -> Result<GraphSet> {
        let binds = vec![
            ("srcTex", Binding::Fixed(Bind::Texture(img.view))),
            ("srcSampler", Binding::Fixed(Bind::Sampler(sampler))),
            ("outImage", Binding::StorageImage(id_target, Storage::Write)),
        ];
        let mut set = GraphSet::new(res, p, 0, binds);
        set.write(ctx, pool, res, p)?;
        Ok(set)
    };
    let cs_sets = [
        cs_set(fetch_cs, rgba, linear)?,
        cs_set(fetch_cs, rgba, nearest)?,
        cs_set(fetch_cs, r32, linear)?,
        cs_set(fetch_cs, r32, nearest)?,
        cs_set(shared_cs, rgba, nearest)?,
    ];
    let fetch_probe = |s, format| Probe {
        pipeline: fetch,
        shader: "probe_fetch.frag",
        src: Some((s, format)),
        draw: Draw::Fullscreen(vec![overwrite], None),
        taps: PROBE_TAPS,
        unit: Unit::Taps,
    };
    let fill_probe = |pipeline, shader, draw, unit| Probe {
        pipeline,
        shader,
        src: None,
        draw,
        taps: 0,
        unit,
    };
    let compute_probe = |s, format, taps| Probe {
        pipeline: fetch_cs,
        shader: "probe_fetch.comp",
        src: Some((s, format)),
        draw: Draw::Dispatch,
        taps,
        unit: Unit::Taps,
    };
    let color = |c: ColorTarget| Draw::Fullscreen(vec![c], None);
    let rgba16 = (Format::Rgba16Float, Filter::Bilinear);
    let point16 = (Format::Rgba16Float, Filter::Point);
    let probes: Vec<(&str, Probe)> = vec![
        ("bilinear rgba16f", fetch_probe(&sets[0], rgba16)),
        ("point rgba16f", fetch_probe(&sets[1], point16)),
        (
            "bilinear r32f",
            fetch_probe(&sets[2], (Format::R32Float, Filter::Bilinear)),
        ),
        (
            "point r32f",
            fetch_probe(&sets[3], (Format::R32Float, Filter::Point)),
        ),
        (
            "fill rgba16f",
            fill_probe(fill, "probe_fill.frag", color(overwrite), Unit::Taps),
        ),
        (
            "fill rgba8",
            fill_probe(
                fill_ldr,
                "probe_fill.frag",
                color(overwrite_ldr),
                Unit::Taps,
            ),
        ),
        (
            "blend rgba16f",
            fill_probe(fill_blend, "probe_fill.frag", color(blended), Unit::Taps),
        ),
        (
            "compute bilinear rgba16f",
            compute_probe(&cs_sets[0], rgba16, PROBE_TAPS),
        ),
        (
            "compute point rgba16f",
            compute_probe(&cs_sets[1], point16, PROBE_TAPS),
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
            compute_probe(&cs_sets[1], point16, 0),
        ),
        // Issue 28: the rest of the frame's kinds of work.
        (
            "bilinear rgba8",
            fetch_probe(&sets[4], (Format::Rgba8Unorm, Filter::Bilinear)),
        ),
        (
            "point rgba8",
            fetch_probe(&sets[5], (Format::Rgba8Unorm, Filter::Point)),
        ),
        (
            "fill geometry mrt",
            fill_probe(
                fill_mrt,
                "probe_fill_mrt.frag",
                Draw::Fullscreen(mrt.clone(), Some(mrt_ds)),
                Unit::Taps,
            ),
        ),
        (
            "fill depth d32",
            fill_probe(
                fill_depth,
                "",
                Draw::Fullscreen(vec![], Some(depth_only)),
                Unit::Taps,
            ),
        ),
        (
            "triangles geometry mrt",
            fill_probe(
                tri_mrt,
                "probe_fill_mrt.frag",
                Draw::Triangles(mrt.clone(), mrt_ds),
                Unit::Triangles,
            ),
        ),
        (
            "triangles depth d32",
            fill_probe(
                tri_depth,
                "",
                Draw::Triangles(vec![], depth_only),
                Unit::Triangles,
            ),
        ),
        (
            "pcf d32",
            Probe {
                pipeline: pcf,
                shader: "probe_pcf.frag",
                src: Some((&pcf_set, (Format::D32Float, Filter::DepthCompare))),
                draw: color(overwrite),
                taps: PROBE_TAPS,
                unit: Unit::Taps,
            },
        ),
        (
            "copy rgba16f",
            fill_probe(fill, "", Draw::Copy(id_target, id_specular), Unit::Taps),
        ),
        (
            "compute dispatch of one group",
            Probe {
                unit: Unit::Pass,
                draw: Draw::DispatchOne,
                ..compute_probe(&cs_sets[1], point16, 0)
            },
        ),
        (
            "compute shared loads",
            Probe {
                pipeline: shared_cs,
                shader: "probe_shared.comp",
                src: Some((&cs_sets[4], point16)),
                draw: Draw::Dispatch,
                taps: SHARED_TAPS,
                unit: Unit::SharedBytes,
            },
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
    let kinds: Vec<(&str, f64, i32)> = probes
        .iter()
        .map(|(name, p)| (*name, p.per_pixel(), p.taps))
        .collect();
    Ok(ceilings_from(&samples, &kinds, reps, n))
}

/// The ceilings from the probes' timings: probe `i` of round `r` (round 0 is
/// the warm-up) is sample `r * probes + i`; each probe counts `per_pixel`
/// operations per pixel of the `n`.
fn ceilings_from(
    samples: &[crate::vk::profiler::PassTiming],
    probes: &[(&str, f64, i32)],
    reps: usize,
    n: u64,
) -> (Ceilings, Vec<ProbeResult>) {
    let mut results = Vec::new();
    for (pi, (name, per_pixel, taps)) in probes.iter().enumerate() {
        let times: Vec<f64> = (1..=reps)
            .map(|r| samples[r * probes.len() + pi].gpu_ms)
            .collect();
        let stats = Stats::of(&times).expect("reps >= 1");
        // A pass probe (`per_pixel` 0) counts one operation: the pass.
        let ops = if *per_pixel > 0.0 {
            n as f64 * per_pixel
        } else {
            1.0
        };
        results.push(ProbeResult {
            name: name.to_string(),
            taps_per_fragment: (*taps).max(1),
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
                shared_load_gbytes: Some(r(21)),
                dispatch_ms: Some(results[20].gpu_ms.median),
            }),
            bilinear_rgba8_gtaps: Some(r(12)),
            point_rgba8_gtaps: Some(r(13)),
            fill_geometry_mrt_gpix: Some(r(14)),
            fill_depth_d32_gpix: Some(r(15)),
            triangles_geometry_gtris: Some(r(16)),
            triangles_depth_gtris: Some(r(17)),
            pcf_d32_gtaps: Some(r(18)),
            // Texels of 8 bytes a second, as bytes.
            copy_gbytes: Some(8.0 * r(19)),
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
    /// Operations its rate counts per pixel of the extent.
    fn per_pixel(&self) -> f64 {
        match self.unit {
            Unit::Taps => f64::from(self.taps.max(1)),
            Unit::Triangles => 1.0,
            Unit::SharedBytes => f64::from(self.taps) * SHARED_LOAD_BYTES,
            // One pass, whatever the extent: its rate is passes a second.
            Unit::Pass => 0.0,
        }
    }

    /// Long because the three kinds of probe (full-screen draws, triangle
    /// draws, dispatches) share their declared work and push constants and
    /// differ only in the tail that states their attachments and records them.
    fn pass(&self, name: &str, texel: [f32; 2], extent: vk::Extent2D) -> Pass<'p> {
        let (pipeline, set) = (self.pipeline, self.src.map(|(s, _)| s));
        let fetches = match self.src {
            Some((_, (format, filter))) => {
                // The shared-memory probe fetches its one texel; the store
                // probe (no taps) reads nothing.
                let count = match self.unit {
                    Unit::SharedBytes => 1.0,
                    _ => f64::from(self.taps),
                };
                if count > 0.0 {
                    vec![Fetch {
                        texture: "srcTex".into(),
                        format,
                        filter,
                        count,
                        exact: true,
                        coherent: true,
                        spread: Vec::new(),
                    }]
                } else {
                    Vec::new()
                }
            }
            None => Vec::new(),
        };
        let push = ProbePush {
            texel,
            taps: self.taps,
            pad: 0,
        };
        let shared_bytes = match self.unit {
            Unit::SharedBytes => SHARED_LOAD_BYTES * (1.0 + f64::from(self.taps)),
            _ => 0.0,
        };
        let work = ShaderWork {
            shader: self.shader.into(),
            fetches,
            storage_write_bytes: if matches!(self.draw, Draw::Dispatch | Draw::DispatchOne) {
                8.0
            } else {
                0.0
            },
            shared_bytes,
            ..Default::default()
        };
        let mut pass = Pass::new(name, PassRole::Probe);
        let set = set.map(|s| pass.set(s));
        let attach = |mut pass: Pass<'p>, colors: &[ColorTarget], ds: Option<DepthStencil>| {
            for &c in colors {
                pass = pass.color(c);
            }
            if let Some(ds) = ds {
                pass = pass.depth_stencil(ds);
            }
            pass
        };
        let stencil = |pipeline: &Pipeline, c: &Context, cmd| unsafe {
            if pipeline.has_stencil {
                c.device
                    .cmd_set_stencil_reference(cmd, vk::StencilFaceFlags::FRONT_AND_BACK, 1);
            }
        };
        let shaded = (!self.shader.is_empty()).then_some(work.clone());
        match &self.draw {
            &Draw::Copy(from, to) => {
                let src = pass.transfer_src(from);
                let dst = pass.transfer_dst(to);
                pass.work(Work::Copy {
                    texels: u64::from(extent.width) * u64::from(extent.height),
                    bytes_per_texel: 8,
                    rects: 1,
                })
                .record(move |pc: &PassContext| {
                    let layers = vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .layer_count(1);
                    let copy = vk::ImageCopy::default()
                        .src_subresource(layers)
                        .dst_subresource(layers)
                        .extent(vk::Extent3D {
                            width: extent.width,
                            height: extent.height,
                            depth: 1,
                        });
                    pc.copy_image(src, dst, &[copy]);
                })
            }
            Draw::Dispatch => {
                let set = set.expect("a compute probe binds its target");
                let side = SSS_TILE_SIDE;
                let groups = [extent.width.div_ceil(side), extent.height.div_ceil(side), 1];
                pass.dispatch(work, groups, side * side)
                    .record(move |pc: &PassContext| {
                        pc.bind(pipeline, &[set]);
                        pipeline.push(pc.ctx, pc.cmd, &push);
                    })
            }
            Draw::DispatchOne => {
                let set = set.expect("a compute probe binds its target");
                let side = SSS_TILE_SIDE;
                pass.dispatch(work, [1, 1, 1], side * side)
                    .record(move |pc: &PassContext| {
                        pc.bind(pipeline, &[set]);
                        pipeline.push(pc.ctx, pc.cmd, &push);
                    })
            }
            Draw::Fullscreen(colors, ds) => {
                attach(pass, colors, *ds)
                    .draws(shaded, 1)
                    .record(move |pc: &PassContext| {
                        fullscreen(pc, pipeline, set.as_slice(), |c, cmd| {
                            unsafe {
                                if pipeline.has_blend_constants {
                                    c.device.cmd_set_blend_constants(cmd, &[0.5; 4]);
                                }
                            }
                            stencil(pipeline, c, cmd);
                            if set.is_some() {
                                pipeline.push(c, cmd, &push);
                            }
                        })
                    })
            }
            Draw::Triangles(colors, ds) => {
                let triangles = u64::from(extent.width) * u64::from(extent.height);
                attach(pass, colors, Some(*ds))
                    .draws(shaded, triangles)
                    .record(move |pc: &PassContext| {
                        pc.bind(pipeline, &[]);
                        stencil(pipeline, pc.ctx, pc.cmd);
                        pipeline.push(pc.ctx, pc.cmd, &push);
                        unsafe {
                            pc.ctx
                                .device
                                .cmd_draw(pc.cmd, 3 * triangles as u32, 1, 0, 0);
                        }
                    })
            }
        }
    }
}
