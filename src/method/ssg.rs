//! Screen-space sum of Gaussians (`ssg`, thesis ch. 4, "SS Full"): for each
//! Gaussian after the first of Table 4.2's fit, a horizontal pass RT1 -> RT2 and a
//! vertical pass RT2 -> RT1 and RTF (MRT; RTF = the diffuse target, blended with
//! the constant w'_i of eq. 4.8-4.9), kernels scaled by the stretch factors of
//! eq. 4.1-4.4, and depth-based Gaussian skipping (4.2.1): each Gaussian's
//! triangle is drawn at the projected depth beyond which it spans under a
//! pixel, with depth test GREATER and early tests forced, so far pixels run no
//! shader. RT1 and RT2 are seeded with a copy of the diffuse target.
//!
//! `--path compute`: each pass a dispatch over its Gaussian's tile list
//! (`tiles`: one list per Gaussian, of the skin tiles holding a surface
//! nearer than its LOD depth, so the skipping is per tile), each pixel
//! tested as the fragment path's stencil and depth tests test it
//! (ssg_tiles_*.comp, the arithmetic shared in ssg_blur.glsl). The seed
//! copy stays: every Gaussian reads both intermediates at skin texels that
//! earlier Gaussians may have skipped, which hold what came before.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::path::{self, Path};
use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::screen::{
    declare_intermediate, fetch, fetch_at_most, masked_pass, seed_copy, source_set, Masked,
};
use super::tiles::{SkinTiles, TILE_INVOCATIONS};
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::work::{Fetch, Filter, ShaderWork};
use crate::graph::{Binding, GraphSet, ImageId, Pass, Storage};
use crate::skin::ssg::{lod_depth, ssg_gaussians, GaussianFit, SsgGaussian, Stretch};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::pipeline::{Bind, Blend, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

/// Taps per 1D Gaussian (Listing 4.1).
const TAPS: u32 = 7;

const OPTIONS: &[OptSpec] = &[
    OptSpec {
        key: "fit",
        kind: OptKind::Value,
        default: "6",
        help: "the Gaussian fit of thesis Table 4.2: 6 or 4",
    },
    OptSpec {
        key: "lod",
        kind: OptKind::NoFlag,
        default: "true",
        help: "draw every Gaussian everywhere (no depth-based level of detail)",
    },
    OptSpec {
        key: "mask",
        kind: OptKind::Value,
        default: "stencil",
        help: "keep non-skin pixels out with the stencil test or a shader branch: stencil | branch",
    },
    path::OPTION,
];

pub static ENTRY: MethodEntry = MethodEntry {
    name: "ssg",
    aliases: &[],
    summary: "screen-space sum of Gaussians (thesis ch. 4) with depth-based Gaussian LOD",
    options: OPTIONS,
    eval: &[
        EvalSetting {
            label: "6 Gaussians, LOD",
            options: &[("fit", "6")],
        },
        EvalSetting {
            label: "4 Gaussians, LOD",
            options: &[("fit", "4")],
        },
        EvalSetting {
            label: "6 Gaussians, no LOD",
            options: &[("fit", "6"), ("lod", "false")],
        },
        EvalSetting {
            label: "6 Gaussians, branch mask",
            options: &[("mask", "branch")],
        },
    ],
    ground_truth: false,
    dolly: &["6 Gaussians, LOD", "6 Gaussians, no LOD"],
    needs: |_, _| Needs::PLAIN,
    check: |o| Config::parse(o).map(|_| ()),
    build: |s| Ok(Box::new(Ssg::new(s)?)),
    no_msaa: None,
    no_mix,
    no_sss: false,
    poses_once: None,
};

/// The registry's `no_mix`: the shader's branch shades every pixel whose
/// alpha marks skin, the other groups' too; only the stencil keeps a group
/// to its own pixels.
fn no_mix(o: &Opts) -> Option<&'static str> {
    match Config::parse(o) {
        Ok(c) if c.mask == MaskMode::Branch => Some(
            "the branch mask shades every character's skin; \
             in a frame of several methods ssg needs mask=stencil",
        ),
        _ => None,
    }
}

/// How non-skin pixels are kept out of the SSS passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaskMode {
    /// Hardware stencil test on the skin bit (masked pixels run no shader).
    Stencil,
    /// A dynamic branch on the mask in the shader (every pixel of the quad runs it).
    Branch,
}

impl std::str::FromStr for MaskMode {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "stencil" => Ok(MaskMode::Stencil),
            "branch" => Ok(MaskMode::Branch),
            other => bail!("unknown mask mode '{other}' (valid: stencil, branch)"),
        }
    }
}

/// The method's options, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub fit: GaussianFit,
    pub lod: bool,
    pub mask: MaskMode,
    pub path: Path,
}

impl Config {
    pub fn parse(o: &Opts) -> Result<Self> {
        let c = Config {
            fit: o.parse("fit")?,
            lod: o.flag("lod")?,
            mask: o.parse("mask")?,
            path: o.parse("path")?,
        };
        if c.mask == MaskMode::Branch && c.path == Path::Compute {
            bail!(
                "--mask branch is the fragment path's alternative to the stencil test; \
                 the compute path tests each pixel's stencil (--mask stencil)"
            );
        }
        Ok(c)
    }
}

/// Push constants of screen_common.glsl (std430 layout, 96 bytes), shared with
/// ss-jittered.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ScreenPush {
    pub dir: [f32; 2],
    pub texel: [f32; 2],
    pub alpha: f32,
    pub beta: f32,
    pub gamma: f32,
    pub std_mm: f32,
    pub quad_depth: f32,
    pub mask_branch: i32,
    /// The compute path's stencil code (screen_common.glsl's `code`).
    pub code: u32,
    pub pad: f32,
    pub center: [f32; 4],
    pub mid: [f32; 4],
    pub wide: [f32; 4],
}

pub struct Ssg {
    horizontal: Pipeline,
    vertical: Pipeline,
    set_rt1: GraphSet,
    set_rt2: GraphSet,
    /// The compute path's tile lists (one per Gaussian) and each
    /// Gaussian's sets (horizontal, vertical: their lists differ);
    /// `horizontal` and `vertical` are then compute pipelines.
    tiles: Option<SkinTiles>,
    compute_sets: Vec<[GraphSet; 2]>,
    rt1: ImageId,
    rt2: ImageId,
    diffuse: ImageId,
    pub config: Config,
    pub gaussians: Vec<SsgGaussian>,
    pub stretch: Stretch,
    /// Depth-buffer value of each Gaussian's full-screen triangle (1 = no LOD).
    pub quad_depths: Vec<f32>,
    /// The LOD distance of each Gaussian in scene units (eq. 4.6 with 0.5).
    pub lod_distances: Vec<f32>,
}

impl Ssg {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let config = Config::parse(&s.options)?;
        if config.path == Path::Fragment && !s.ctx.facts.independent_blend {
            bail!(
                "device '{}' lacks independentBlend, which ssg's MRT pass needs",
                s.ctx.facts.name
            );
        }
        let diffuse = s.targets.diffuse;
        let rt1 = declare_intermediate(s.res, diffuse, "sss intermediate");
        let rt2 = declare_intermediate(s.res, diffuse, "sss intermediate 2");
        let format = s.res.format(diffuse);
        let ds_format = s.depth_stencil_format;
        let desc = |name: &str, frag: &'static str, colors: usize| {
            let mut d = GraphicsDesc::fullscreen(name, frag, format);
            d.vert = "fullscreen_depth.vert";
            d.color_formats = vec![format; colors];
            d.depth_format = Some(ds_format);
            d.stencil_format = Some(ds_format);
            // Gaussian LOD: shade only where the surface is nearer than the triangle.
            d.depth_test = true;
            d.depth_write = false;
            d.depth_compare = vk::CompareOp::GREATER;
            d.stencil = (config.mask == MaskMode::Stencil).then(skin_stencil_test);
            if colors == 2 {
                d.blend = Blend::ConstantMix(1);
            }
            d
        };
        // Guarded until the method holds them: an error frees what exists.
        let compute = config.path == Path::Compute;
        let horizontal = Guard::new(
            s.ctx,
            if compute {
                Pipeline::compute(s.ctx, "ssg horizontal", "ssg_tiles_horizontal.comp")?
            } else {
                Pipeline::graphics(s.ctx, &desc("ssg horizontal", "ssg_horizontal.frag", 1))?
            },
        );
        let vertical = Guard::new(
            s.ctx,
            if compute {
                Pipeline::compute(s.ctx, "ssg vertical", "ssg_tiles_vertical.comp")?
            } else {
                Pipeline::graphics(s.ctx, &desc("ssg vertical", "ssg_vertical.frag", 2))?
            },
        );
        let stretch = Stretch::for_view(
            s.view.extent.height,
            s.view.camera.fovy_rad,
            s.view.mm_per_unit,
        );
        let gaussians = ssg_gaussians(config.fit);
        let lod_distances: Vec<f32> = gaussians
            .iter()
            .map(|g| lod_depth(g.incremental_std_mm, stretch.alpha))
            .collect();
        let quad_depths: Vec<f32> = lod_distances
            .iter()
            .map(|&d| {
                if config.lod {
                    s.view.ndc_depth(d).clamp(0.0, 1.0)
                } else {
                    1.0
                }
            })
            .collect();
        let tiles = Guard::new(
            s.ctx,
            if compute {
                Some(SkinTiles::by_depth(s, &quad_depths)?)
            } else {
                None
            },
        );
        let mut compute_sets = Vec::new();
        if let Some(t) = tiles.as_ref() {
            let t_ = s.targets;
            for g in 0..gaussians.len() {
                let set = |pipeline: &Pipeline, src, out, final_image: Option<ImageId>| {
                    let mut binds = vec![
                        ("colorTex", Binding::Sampled(src)),
                        ("depthTex", Binding::Sampled(t_.linear_depth)),
                        (
                            "linearClamp",
                            Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                        ),
                        ("stencilTex", Binding::SampledStencil(t_.depth_stencil)),
                        ("dsDepthTex", Binding::SampledDepth(t_.depth_stencil)),
                        ("Tiles", t.list_binding(Storage::Read, g)),
                        // Written where this Gaussian shades: the rest keeps
                        // the seed or an earlier Gaussian's result.
                        ("outImage", Binding::StorageImage(out, Storage::ReadWrite)),
                    ];
                    if let Some(f) = final_image {
                        binds.push(("finalImage", Binding::StorageImage(f, Storage::ReadWrite)));
                    }
                    GraphSet::new(s.res, pipeline, 0, binds)
                };
                compute_sets.push([
                    set(&horizontal, rt1, rt2, None),
                    set(&vertical, rt2, rt1, Some(diffuse)),
                ]);
            }
        }
        let (set_rt1, set_rt2) = if compute {
            (GraphSet::default(), GraphSet::default())
        } else {
            (
                source_set(s, &horizontal, rt1),
                source_set(s, &vertical, rt2),
            )
        };
        Ok(Ssg {
            set_rt1,
            set_rt2,
            tiles: tiles.keep(),
            compute_sets,
            horizontal: horizontal.keep(),
            vertical: vertical.keep(),
            rt1,
            rt2,
            diffuse,
            config,
            gaussians,
            stretch,
            quad_depths,
            lod_distances,
        })
    }

    /// What one blur pass fetches: centre colour and depth and the two depth
    /// texels of the gradient by texel fetch, 7 bilinear colour taps. With the
    /// branch mask, non-skin fragments stop after the centre colour.
    fn fetches(&self, f: &FrameView<'_, '_>, src: ImageId) -> Vec<Fetch> {
        let (res, depth) = (f.res, f.targets.linear_depth);
        let branch = self.config.mask == MaskMode::Branch;
        let after_mask = |texture: &str, image, filter, count| {
            if branch {
                fetch_at_most(res, image, texture, filter, count)
            } else {
                fetch(res, image, texture, filter, count)
            }
        };
        vec![
            fetch(res, src, "colorTex", Filter::Point, 1.0),
            after_mask("depthTex", depth, Filter::Point, 3.0),
            after_mask("colorTex", src, Filter::Bilinear, TAPS as f64),
        ]
    }
}

impl SssMethod for Ssg {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let (rt1, rt2, diffuse) = (self.rt1, self.rt2, self.diffuse);
        let mut passes = vec![seed_copy(
            "ssg seed copy",
            f,
            diffuse,
            f.region,
            &[rt1, rt2],
        )];
        let extent = f.extent;
        let stencil = self.config.mask == MaskMode::Stencil;
        if let Some(tiles) = &self.tiles {
            passes.extend(tiles.passes(f));
        }
        for (gi, (g, &quad_depth)) in self.gaussians.iter().zip(&self.quad_depths).enumerate() {
            let base = ScreenPush {
                texel: [1.0 / extent.width as f32, 1.0 / extent.height as f32],
                alpha: self.stretch.alpha,
                beta: self.stretch.beta,
                gamma: self.stretch.gamma,
                std_mm: g.incremental_std_mm,
                quad_depth,
                mask_branch: !stencil as i32,
                ..Default::default()
            };
            let h = ScreenPush {
                dir: [1.0, 0.0],
                ..base
            };
            let v = ScreenPush {
                dir: [0.0, 1.0],
                ..base
            };
            let blend = [g.blend[0], g.blend[1], g.blend[2], 1.0];
            if let Some(tiles) = &self.tiles {
                for (k, (name, push)) in
                    [("horizontal", h), ("vertical", v)].into_iter().enumerate()
                {
                    let push = ScreenPush {
                        code: f.stencil,
                        // The blend constants of the fragment path's RTF.
                        center: blend,
                        ..push
                    };
                    let shader = ["ssg_tiles_horizontal.comp", "ssg_tiles_vertical.comp"][k];
                    let src = [rt1, rt2][k];
                    let mut fetches = self.fetches(f, src);
                    for name in ["stencilTex", "dsDepthTex"] {
                        fetches.push(fetch(
                            f.res,
                            f.targets.depth_stencil,
                            name,
                            Filter::Point,
                            1.0,
                        ));
                    }
                    // Invocations outside the image, the skin or the LOD fetch less.
                    for x in &mut fetches {
                        x.exact = false;
                    }
                    let work = ShaderWork {
                        shader: shader.into(),
                        fetches,
                        alu: alu_estimate(shader, &[TAPS]),
                        storage_read_bytes: 4.0 / TILE_INVOCATIONS as f64
                            + if k == 1 { 8.0 } else { 0.0 },
                        storage_write_bytes: if k == 1 { 16.0 } else { 8.0 },
                        shared_bytes: 0.0,
                    };
                    let pipeline = [&self.horizontal, &self.vertical][k];
                    let set = &self.compute_sets[gi][k];
                    let name = format!("ssg g{} {name}", g.index);
                    passes.push(tiles.pass(name, f, gi, work, pipeline, set, push));
                }
                continue;
            }
            let horizontal = &self.horizontal;
            passes.push(masked_pass(
                f,
                Masked {
                    name: format!("ssg g{} horizontal", g.index),
                    shader: "ssg_horizontal.frag",
                    loop_trips: vec![TAPS],
                    pipeline: horizontal,
                    set: &self.set_rt1,
                    fetches: self.fetches(f, rt1),
                    targets: vec![(rt2, false)],
                    stencil,
                    depth_test: true,
                },
                move |c, cmd| horizontal.push(c, cmd, &h),
            ));
            // RTF (the diffuse target) blends with the constant w'_i.
            let vertical = &self.vertical;
            passes.push(masked_pass(
                f,
                Masked {
                    name: format!("ssg g{} vertical", g.index),
                    shader: "ssg_vertical.frag",
                    loop_trips: vec![TAPS],
                    pipeline: vertical,
                    set: &self.set_rt2,
                    fetches: self.fetches(f, rt2),
                    targets: vec![(rt1, false), (diffuse, true)],
                    stencil,
                    depth_test: true,
                },
                move |c, cmd| {
                    vertical.push(c, cmd, &v);
                    unsafe { c.device.cmd_set_blend_constants(cmd, &blend) };
                },
            ));
        }
        passes
    }

    fn output(&self) -> ImageId {
        self.diffuse
    }

    /// 3 steps of std/3 stretched (eq. 4.1-4.4; the depth-gradient term only
    /// narrows it) for the widest Gaussian.
    fn reach_px(&self, depth: f32, scale: &ReachScale) -> Option<f32> {
        let widest = self
            .gaussians
            .iter()
            .map(|g| g.incremental_std_mm)
            .fold(0.0, f32::max);
        Some(self.stretch.alpha * scale.max_strength / depth * widest + BILINEAR_MARGIN_PX)
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        if let Some(t) = &mut self.tiles {
            t.bind(b)?;
            for [h, v] in &mut self.compute_sets {
                b.write(h, &self.horizontal)?;
                b.write(v, &self.vertical)?;
            }
            return Ok(());
        }
        b.write(&mut self.set_rt1, &self.horizontal)?;
        b.write(&mut self.set_rt2, &self.vertical)
    }

    fn intermediates(&self) -> Vec<ImageId> {
        vec![self.rt1, self.rt2]
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "fit": self.config.fit,
            "lod": self.config.lod,
            "mask": self.config.mask,
            "stretch": { "alpha": self.stretch.alpha, "beta": self.stretch.beta, "gamma": self.stretch.gamma },
            "lod_distances_units": self.lod_distances,
            "path": self.config.path.name(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.horizontal.destroy(ctx);
        self.vertical.destroy(ctx);
        self.tiles.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
