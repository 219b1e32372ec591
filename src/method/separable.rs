//! Separable subsurface scattering (thesis ch. 6): a seed copy of the diffuse
//! target into an intermediate, a horizontal pass diffuse -> intermediate and a
//! vertical pass intermediate -> diffuse, both stencil-tested on the skin bit.
//! The kernel (eq. 6.1) is `skin::kernel`.
//!
//! `--path compute` runs the same two blurs as compute dispatches over the
//! listed skin tiles (`tiles`, separable_blur.comp): no seed copy, the tile
//! and its apron in shared memory.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::path::Path;
use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::screen::{declare_intermediate, fetch, fetch_at_most, masked_pass, seed_copy, Masked};
use super::tiles::SkinTiles;
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::work::{Filter, ShaderWork};
use crate::graph::{Binding, GraphSet, ImageId, Pass, Storage};
use crate::shader_constants::{SSS_APRON_PX, SSS_TILE_SIDE};
use crate::skin::kernel::{Preset, SeparableKernel, SssParams};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

const SHADER: &str = "separable_blur.frag";
const COMPUTE_SHADER: &str = "separable_blur.comp";

const OPTIONS: &[OptSpec] = &[
    OptSpec {
        key: "samples",
        kind: OptKind::Value,
        default: "17",
        help: "kernel samples per pass: odd, 3..=63 (the thesis' 9, 17, 33)",
    },
    OptSpec {
        key: "preset",
        kind: OptKind::Value,
        default: "table6.1",
        help: "kernel preset: table6.1 | demo (the sources' artists' presets) | physical (the profile's per-channel marginal) | burley (Burley's normalized diffusion matched to the profile, its marginal)",
    },
    OptSpec {
        key: "sss-width-mm",
        kind: OptKind::Value,
        default: "",
        help: "override the preset's kernel half-width in millimetres",
    },
    OptSpec {
        key: "strength",
        kind: OptKind::Value,
        default: "",
        help: "override the per-channel strength: R,G,B in 0..=1",
    },
    OptSpec {
        key: "falloff",
        kind: OptKind::Value,
        default: "",
        help: "override the per-channel falloff: R,G,B > 0",
    },
    OptSpec {
        key: "follow-surface",
        kind: OptKind::NoFlag,
        default: "true",
        help: "turn off following the surface (taps across depth steps are kept)",
    },
    super::path::OPTION,
];

pub static ENTRY: MethodEntry = MethodEntry {
    name: "separable",
    aliases: &["ssss"],
    summary: "separable SSS (thesis ch. 6): two stencil-masked 1D passes",
    options: OPTIONS,
    eval: &[
        EvalSetting {
            label: "9 samples",
            options: &[("samples", "9")],
        },
        EvalSetting {
            label: "17 samples",
            options: &[("samples", "17")],
        },
        EvalSetting {
            label: "33 samples",
            options: &[("samples", "33")],
        },
        // The physically fitted preset (the profile's per-channel marginal)
        // beside the sources' artist preset.
        EvalSetting {
            label: "physical, 17 samples",
            options: &[("preset", "physical"), ("samples", "17")],
        },
        EvalSetting {
            label: "physical, 33 samples",
            options: &[("preset", "physical"), ("samples", "33")],
        },
        // Burley's marginal, scored against Burley's own truth
        // (`profile::approximated`).
        EvalSetting {
            label: "burley, 9 samples",
            options: &[("preset", "burley"), ("samples", "9")],
        },
        EvalSetting {
            label: "burley, 17 samples",
            options: &[("preset", "burley"), ("samples", "17")],
        },
        EvalSetting {
            label: "burley, 33 samples",
            options: &[("preset", "burley"), ("samples", "33")],
        },
    ],
    ground_truth: false,
    dolly: &["17 samples", "physical, 17 samples"],
    needs: |_, _| Needs::PLAIN,
    check: |o| Config::parse(o).map(|_| ()),
    build: |s| Ok(Box::new(Separable::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
    poses_once: None,
};

/// The method's options, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub samples: usize,
    pub preset: Preset,
    pub params: SssParams,
    pub follow_surface: bool,
    pub path: Path,
}

impl Config {
    pub fn parse(o: &Opts) -> Result<Self> {
        let samples: usize = o.parse("samples")?;
        if samples % 2 == 0 || !(3..=SeparableKernel::MAX_SAMPLES).contains(&samples) {
            bail!(
                "--samples must be odd and within 3..={}, got {samples}",
                SeparableKernel::MAX_SAMPLES
            );
        }
        let preset: Preset = o.parse("preset")?;
        let mut params = preset.params();
        if !o.raw("sss-width-mm").is_empty() {
            params.width_mm = o.parse("sss-width-mm")?;
        }
        if let Some(s) = o.rgb("strength")? {
            params.strength = s;
        }
        if let Some(f) = o.rgb("falloff")? {
            params.falloff = f;
        }
        params.validate()?;
        Ok(Config {
            samples,
            preset,
            params,
            follow_surface: o.flag("follow-surface")?,
            path: o.parse("path")?,
        })
    }
}

/// Push constants of separable_blur.frag.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SssPush {
    dir: [f32; 2],
    aspect: f32,
    tan_half_fovy: f32,
    mm_per_unit: f32,
    follow_tol_mm: f32,
    n_samples: i32,
    follow_surface: i32,
}

/// Push constants of separable_blur.comp: the fragment shader's, then the
/// group's stencil code and the direction as a switch.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ComputePush {
    base: SssPush,
    code: u32,
    vertical: i32,
}

/// How far the kernel's taps reach from a pixel at view depth `depth`: the
/// widest offset at the strongest strength, as the shader scales it (the
/// SSS region's margin; `plan::cli::characters` sizes the planner's regions
/// with it too, so both draw the same rectangles).
pub fn reach_px(kernel: &SeparableKernel, depth: f32, scale: &ReachScale) -> f32 {
    let widest_mm = kernel
        .samples
        .iter()
        .map(|s| s.offset_mm.abs())
        .fold(0.0, f32::max);
    widest_mm * scale.max_strength * scale.px_per_mm(depth) + BILINEAR_MARGIN_PX
}

pub struct Separable {
    pipeline: Pipeline,
    pub kernel: SeparableKernel,
    pub config: Config,
    kernel_buffer: Buffer,
    /// The intermediate the horizontal pass writes.
    tmp: ImageId,
    diffuse: ImageId,
    /// The horizontal pass's (reading the diffuse target) and the
    /// vertical's (reading the intermediate).
    sets: [GraphSet; 2],
    push: [SssPush; 2],
    /// The compute path's tile list (`pipeline` and `sets` are then the
    /// compute blur's).
    tiles: Option<SkinTiles>,
}

impl Separable {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let config = Config::parse(&s.options)?;
        let kernel = SeparableKernel::build(config.params, config.samples)?;
        let diffuse = s.targets.diffuse;
        let tmp = declare_intermediate(s.res, diffuse, "sss intermediate");
        // Guarded until the method holds them: an error frees what exists.
        let pipeline = Guard::new(
            s.ctx,
            match config.path {
                Path::Fragment => {
                    let mut desc =
                        GraphicsDesc::fullscreen("sss blur", SHADER, s.res.format(diffuse));
                    desc.depth_format = Some(s.depth_stencil_format);
                    desc.stencil_format = Some(s.depth_stencil_format);
                    desc.stencil = Some(skin_stencil_test());
                    Pipeline::graphics(s.ctx, &desc)?
                }
                Path::Compute => Pipeline::compute(s.ctx, "sss blur", COMPUTE_SHADER)?,
            },
        );
        let tiles = Guard::new(
            s.ctx,
            match config.path {
                Path::Fragment => None,
                Path::Compute => Some(SkinTiles::new(s)?),
            },
        );
        let mut data = kernel.gpu_data();
        data.resize(SeparableKernel::MAX_SAMPLES, [0.0; 4]);
        let kernel_buffer = Guard::new(
            s.ctx,
            Buffer::with_data(
                s.ctx,
                "sss kernel",
                bytemuck::cast_slice(&data),
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
        );
        let tol = config.params.width_mm;
        let push = |dir: [f32; 2]| SssPush {
            dir,
            aspect: s.view.aspect(),
            tan_half_fovy: s.view.tan_half_fovy(),
            mm_per_unit: s.view.mm_per_unit,
            follow_tol_mm: tol,
            n_samples: kernel.samples.len() as i32,
            // A zero-width kernel has no extent to compare depth steps against.
            follow_surface: (config.follow_surface && tol > 0.0) as i32,
        };
        let size = (SeparableKernel::MAX_SAMPLES * 16) as u64;
        let kernel_bind = (
            "kernel",
            Binding::Fixed(Bind::Uniform {
                buffer: kernel_buffer.raw,
                size,
            }),
        );
        let depth = ("depthTex", Binding::Sampled(s.targets.linear_depth));
        let set = |color: ImageId, out: Option<(ImageId, Storage)>| {
            let mut binds = vec![("colorTex", Binding::Sampled(color)), depth, kernel_bind];
            match (&*tiles, out) {
                (Some(t), Some((out, storage))) => binds.extend([
                    (
                        "stencilTex",
                        Binding::SampledStencil(s.targets.depth_stencil),
                    ),
                    ("Tiles", t.list_binding(Storage::Read, 0)),
                    ("outImage", Binding::StorageImage(out, storage)),
                ]),
                _ => binds.push((
                    "linearClamp",
                    Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                )),
            }
            GraphSet::new(s.res, &pipeline, 0, binds)
        };
        let sets = match config.path {
            Path::Fragment => [set(diffuse, None), set(tmp, None)],
            // The horizontal blur writes the intermediate at skin pixels (no
            // texel of it is read elsewhere); the vertical one reads the
            // diffuse target at other texels and writes it at skin pixels.
            Path::Compute => [
                set(diffuse, Some((tmp, Storage::Write))),
                set(tmp, Some((diffuse, Storage::ReadWrite))),
            ],
        };
        Ok(Separable {
            pipeline: pipeline.keep(),
            push: [push([1.0, 0.0]), push([0.0, 1.0])],
            kernel,
            config,
            kernel_buffer: kernel_buffer.keep(),
            tmp,
            diffuse,
            sets,
            tiles: tiles.keep(),
        })
    }

    /// The compute path's passes: the tile list, then the two blurs over it.
    fn compute_passes<'a>(&'a self, f: &FrameView<'a, '_>, tiles: &'a SkinTiles) -> Vec<Pass<'a>> {
        let t = f.targets;
        let n = self.kernel.samples.len();
        // Shared memory holds the tile and SSS_APRON_PX texels each side:
        // taps reaching further (a kernel that wide on screen at the
        // nearest skin) read their texels from the images.
        let side = SSS_TILE_SIDE as f64;
        let loads = (side + 2.0 * SSS_APRON_PX as f64) / side;
        // The kernel's reach at full strength, as the SSS region sizes it.
        let scale = ReachScale {
            height_px: f.extent.height,
            tan_half_fovy: self.push[0].tan_half_fovy,
            mm_per_unit: self.push[0].mm_per_unit,
            max_strength: 1.0,
        };
        let reach = f
            .depths
            .iter()
            .map(|&(_, d)| f64::from(reach_px(&self.kernel, d, &scale)))
            .fold(0.0, f64::max);
        let beyond = if reach > SSS_APRON_PX as f64 {
            2.0 * (n - 1) as f64
        } else {
            0.0
        };
        let blur = |name: &str, src: ImageId, pass: usize| {
            let vertical = pass == 1;
            let mut fetches = vec![
                fetch_at_most(f.res, src, "colorTex", Filter::Point, loads + beyond),
                fetch(f.res, t.linear_depth, "depthTex", Filter::Point, loads),
                fetch_at_most(
                    f.res,
                    t.depth_stencil,
                    "stencilTex",
                    Filter::Point,
                    1.0 + if vertical { loads + beyond } else { 0.0 },
                ),
            ];
            if beyond > 0.0 {
                fetches[1] = fetch_at_most(
                    f.res,
                    t.linear_depth,
                    "depthTex",
                    Filter::Point,
                    loads + beyond,
                );
            }
            let work = ShaderWork {
                shader: COMPUTE_SHADER.into(),
                fetches,
                alu: alu_estimate(COMPUTE_SHADER, &[loads.ceil() as u32, n as u32 - 1, 2]),
                // The tile's list entry, the diffuse target at texels that are
                // not skin (vertical), the store at skin pixels.
                storage_read_bytes: 4.0 / (side * side) + if vertical { 8.0 * loads } else { 0.0 },
                storage_write_bytes: 8.0,
                // Every invocation stores its `loads` texels of the tile and
                // apron (a packed RGBA16F and a depth, 12 bytes); its reads
                // (the centre, the taps) are behind the skin test.
                shared_bytes: 12.0 * loads,
            };
            let push = ComputePush {
                base: self.push[pass],
                code: f.stencil,
                vertical: vertical as i32,
            };
            tiles.pass(name, f, 0, work, &self.pipeline, &self.sets[pass], push)
        };
        let mut passes: Vec<Pass<'a>> = tiles.passes(f).into();
        passes.push(blur("sss horizontal", self.diffuse, 0));
        passes.push(blur("sss vertical", self.tmp, 1));
        passes
    }

    fn follows_surface(&self) -> bool {
        self.push[0].follow_surface != 0
    }
}

impl SssMethod for Separable {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        if let Some(tiles) = &self.tiles {
            return self.compute_passes(f, tiles);
        }
        let t = f.targets;
        let n = self.kernel.samples.len();
        let taps = (n - 1) as f64;
        let blur = |name: &str, src: ImageId, dst: ImageId, pass: usize| {
            let mut fetches = vec![
                fetch(f.res, src, "colorTex", Filter::Point, 1.0),
                fetch(f.res, t.linear_depth, "depthTex", Filter::Point, 1.0),
                fetch(f.res, src, "colorTex", Filter::Bilinear, taps),
            ];
            if self.follows_surface() {
                fetches.push(fetch(
                    f.res,
                    t.linear_depth,
                    "depthTex",
                    Filter::Bilinear,
                    taps,
                ));
            }
            let (push, pipeline) = (self.push[pass], &self.pipeline);
            masked_pass(
                f,
                Masked {
                    name: name.into(),
                    shader: SHADER,
                    loop_trips: vec![n as u32 - 1],
                    pipeline,
                    set: &self.sets[pass],
                    fetches,
                    targets: vec![(dst, false)],
                    stencil: true,
                    depth_test: false,
                },
                move |c, cmd| pipeline.push(c, cmd, &push),
            )
        };
        vec![
            seed_copy("sss seed copy", f, self.diffuse, f.region, &[self.tmp]),
            blur("sss horizontal", self.diffuse, self.tmp, 0),
            blur("sss vertical", self.tmp, self.diffuse, 1),
        ]
    }

    fn output(&self) -> ImageId {
        self.diffuse
    }

    fn reach_px(&self, depth: f32, scale: &ReachScale) -> Option<f32> {
        Some(reach_px(&self.kernel, depth, scale))
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        for set in &mut self.sets {
            b.write(set, &self.pipeline)?;
        }
        if let Some(t) = &mut self.tiles {
            t.bind(b)?;
        }
        Ok(())
    }

    fn intermediates(&self) -> Vec<ImageId> {
        match self.config.path {
            Path::Fragment => vec![self.tmp],
            // No seed copy fills it: every texel read is written first.
            Path::Compute => Vec::new(),
        }
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "samples": self.config.samples,
            "preset": self.config.preset.name(),
            "sss_params": self.config.params,
            "follow_surface": self.follows_surface(),
            "path": self.config.path.name(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.kernel_buffer.destroy(ctx);
        self.tiles.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
