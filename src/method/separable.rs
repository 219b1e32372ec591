//! Separable subsurface scattering (thesis ch. 6): a seed copy of the diffuse
//! target into an intermediate, a horizontal pass diffuse -> intermediate and a
//! vertical pass intermediate -> diffuse, both stencil-tested on the skin bit.
//! The kernel (eq. 6.1) is `skin::kernel`.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::screen::{declare_intermediate, fetch, masked_pass, seed_copy, Masked};
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::work::Filter;
use crate::graph::{Binding, GraphSet, ImageId, Pass};
use crate::skin::kernel::{Preset, SeparableKernel, SssParams};
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};

const SHADER: &str = "separable_blur.frag";

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
        help: "kernel preset: table6.1 | demo (the sources' artists' presets) | physical (the profile's per-channel marginal)",
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
    ],
    ground_truth: false,
    dolly: &["17 samples", "physical, 17 samples"],
    needs: |_, _| Needs::PLAIN,
    check: |o| Config::parse(o).map(|_| ()),
    build: |s| Ok(Box::new(Separable::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
};

/// The method's options, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub samples: usize,
    pub preset: Preset,
    pub params: SssParams,
    pub follow_surface: bool,
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
}

impl Separable {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let config = Config::parse(&s.options)?;
        let kernel = SeparableKernel::build(config.params, config.samples)?;
        let diffuse = s.targets.diffuse;
        let tmp = declare_intermediate(s.res, diffuse, "sss intermediate");
        let mut desc = GraphicsDesc::fullscreen("sss blur", SHADER, s.res.format(diffuse));
        desc.depth_format = Some(s.depth_stencil_format);
        desc.stencil_format = Some(s.depth_stencil_format);
        desc.stencil = Some(skin_stencil_test());
        // Guarded until the method holds them: an error frees what exists.
        let pipeline = Guard::new(s.ctx, Pipeline::graphics(s.ctx, &desc)?);
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
        let set = |color: ImageId| {
            GraphSet::new(
                s.res,
                &pipeline,
                0,
                vec![
                    ("colorTex", Binding::Sampled(color)),
                    ("depthTex", Binding::Sampled(s.targets.linear_depth)),
                    (
                        "linearClamp",
                        Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                    ),
                    (
                        "kernel",
                        Binding::Fixed(Bind::Uniform {
                            buffer: kernel_buffer.raw,
                            size,
                        }),
                    ),
                ],
            )
        };
        let sets = [set(diffuse), set(tmp)];
        Ok(Separable {
            pipeline: pipeline.keep(),
            push: [push([1.0, 0.0]), push([0.0, 1.0])],
            kernel,
            config,
            kernel_buffer: kernel_buffer.keep(),
            tmp,
            diffuse,
            sets,
        })
    }

    fn follows_surface(&self) -> bool {
        self.push[0].follow_surface != 0
    }
}

impl SssMethod for Separable {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
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
        Ok(())
    }

    fn intermediates(&self) -> Vec<ImageId> {
        vec![self.tmp]
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "samples": self.config.samples,
            "preset": self.config.preset.name(),
            "sss_params": self.config.params,
            "follow_surface": self.follows_surface(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.kernel_buffer.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
