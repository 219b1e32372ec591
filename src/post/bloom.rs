//! The bloom (`--bloom`; thesis ch. 3.1, 4.2 and 11.1: d'Eon and Luebke's
//! bloom after Pharr and Humphreys): a small Gaussian pyramid on the HDR
//! composite before the tone map, which then reads the bloomed image. The
//! parameters, the closed form of the halo and a CPU mirror are in
//! `post::bloom_pyramid`; this module declares the images and passes:
//!
//! - `bloom down K` (K = 1..=4): level K from level K - 1 (the composite for
//!   K = 1), `[1, 2, 1] / 4` per axis in four bilinear fetches.
//! - `bloom blur h K`, `bloom blur v K`: the one-texel Gaussian of level K,
//!   7 point taps per axis.
//! - `bloom combine`: `(1 - s) hdr + s sum w_K level_K`, each level read
//!   bilinearly, into `bloomed hdr` (the tone map's input).
//!
//! Every pass writes every texel of its target (no clear needed) and reads
//! clamped, so borders never read outside. Targets are the composite's RGBA
//! f16. Without `--bloom` nothing here is declared or built.

use anyhow::Result;
use ash::vk;

use super::bloom_pyramid::{
    blur_weights, level_extent, BLUR_RADIUS, LEVELS, LEVEL_WEIGHTS, STRENGTH,
};
use super::{fetch, PostBind};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Filter, PassRole, ShaderWork};
use crate::graph::{
    Binding, ColorTarget, GraphSet, ImageDesc, ImageId, Load, Pass, PassContext, Resources,
};
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline, Samplers};
use crate::vk::shader_stats::alu_estimate;

pub const DOWN_SHADER: &str = "bloom_down.frag";
pub const BLUR_SHADER: &str = "bloom_blur.frag";
pub const COMBINE_SHADER: &str = "bloom_combine.frag";

/// Taps of one blur pass (the shader's loop trips).
const BLUR_TAPS: u32 = 2 * BLUR_RADIUS as u32 + 1;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    weights: [f32; BLUR_RADIUS + 1],
    dir: [i32; 2],
    /// The source's last texel (its size - 1).
    hi: [i32; 2],
}

/// The reduction's source size in texels.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DownPush {
    src_size: [f32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CombinePush {
    level_weights: [f32; LEVELS],
    /// Each level's size in texels, two levels a vec4.
    sizes: [[f32; 2]; LEVELS],
    strength: f32,
}

// Every shader here is handed its images' sizes rather than asking
// `textureSize` per pixel: a size query runs on the texture unit on NVIDIA
// (TXQ) and four of them cost the combine more than its fetches (issue 28;
// docs/perf/issue28/floors.md). The pushed values are the queried ones, so
// no coordinate changes.
fn size_of(res: &Resources, id: ImageId) -> [f32; 2] {
    let e = res.extent(id);
    [e.width as f32, e.height as f32]
}

/// One level: its reduction, the horizontal pass's result and the blurred level.
#[derive(Clone, Copy)]
struct Level {
    down: ImageId,
    across: ImageId,
    blurred: ImageId,
}

/// The bloom stage: pipelines, the levels' images, the output and the sets.
#[derive(Default)]
pub struct Bloom {
    down_pipeline: Pipeline,
    blur_pipeline: Pipeline,
    combine_pipeline: Pipeline,
    input: ImageId,
    output: ImageId,
    levels: Vec<Level>,
    /// Per level: reduction, horizontal blur, vertical blur (written by
    /// `bind`: the passes are first built to derive the images' usages).
    level_sets: Vec<[GraphSet; 3]>,
    combine_set: GraphSet,
}

impl Bloom {
    /// Declares the pyramid's images for the composite `input` and builds the
    /// pipelines; on an error what was built is destroyed.
    pub fn new(
        ctx: &Context,
        res: &mut Resources,
        samplers: &Samplers,
        input: ImageId,
    ) -> Result<Self> {
        let extent = res.extent(input);
        let format = res.format(input);
        let levels = (1..=LEVELS)
            .map(|k| {
                let (width, height) = level_extent(extent.width, extent.height, k);
                let e = vk::Extent2D { width, height };
                Level {
                    down: res.declare(ImageDesc::new(&format!("bloom level {k}"), e, format)),
                    across: res.declare(ImageDesc::new(&format!("bloom level {k} h"), e, format)),
                    blurred: res.declare(ImageDesc::new(
                        &format!("bloom level {k} blurred"),
                        e,
                        format,
                    )),
                }
            })
            .collect::<Vec<Level>>();
        let output = res.declare(ImageDesc::new("bloomed hdr", extent, format));
        let build = |name, frag| {
            Pipeline::graphics(ctx, &GraphicsDesc::fullscreen(name, frag, format))
                .map(|p| Guard::new(ctx, p))
        };
        let down = build("bloom down", DOWN_SHADER)?;
        let blur = build("bloom blur", BLUR_SHADER)?;
        let combine = build("bloom combine", COMBINE_SHADER)?;
        let linear = (
            "linearClamp",
            Binding::Fixed(Bind::Sampler(samplers.linear_clamp)),
        );
        let res = &*res;
        let src = |p: &Pipeline, id, sampler: bool| {
            let mut binds = vec![("srcTex", Binding::Sampled(id))];
            binds.extend(sampler.then_some(linear));
            GraphSet::new(res, p, 0, binds)
        };
        let mut below = input;
        let mut level_sets = Vec::with_capacity(LEVELS);
        for l in &levels {
            level_sets.push([
                src(&down, below, true),
                src(&blur, l.down, false),
                src(&blur, l.across, false),
            ]);
            below = l.down;
        }
        let names = ["level1Tex", "level2Tex", "level3Tex", "level4Tex"];
        let mut binds = vec![("hdrTex", Binding::Sampled(input)), linear];
        for (name, l) in names.into_iter().zip(&levels) {
            binds.push((name, Binding::Sampled(l.blurred)));
        }
        let combine_set = GraphSet::new(res, &combine, 0, binds);
        Ok(Bloom {
            down_pipeline: down.keep(),
            blur_pipeline: blur.keep(),
            combine_pipeline: combine.keep(),
            input,
            output,
            levels,
            level_sets,
            combine_set,
        })
    }

    /// The HDR composite it reads.
    pub fn input(&self) -> ImageId {
        self.input
    }

    /// The bloomed HDR image the tone map reads.
    pub fn output(&self) -> ImageId {
        self.output
    }

    pub fn bind(&mut self, b: &PostBind) -> Result<()> {
        for sets in &mut self.level_sets {
            let [down, across, blurred] = sets;
            b.write(down, &self.down_pipeline)?;
            b.write(across, &self.blur_pipeline)?;
            b.write(blurred, &self.blur_pipeline)?;
        }
        b.write(&mut self.combine_set, &self.combine_pipeline)
    }

    /// The reductions, each level's two blurs, then the combine. Every fetch
    /// count is exact: no shader here branches.
    pub fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>> {
        let mut passes = Vec::with_capacity(3 * LEVELS + 1);
        let mut below = self.input;
        for (i, l) in self.levels.iter().enumerate() {
            let work = ShaderWork {
                shader: DOWN_SHADER.into(),
                fetches: vec![fetch(res, below, "srcTex", Filter::Bilinear, 4.0, true)],
                alu: alu_estimate(DOWN_SHADER, &[]),
                ..Default::default()
            };
            let pipeline = &self.down_pipeline;
            let push = DownPush {
                src_size: size_of(res, below),
            };
            let mut pass = Pass::new(format!("bloom down {}", i + 1), PassRole::Post);
            // Reads the level below (the composite for the first).
            let set = pass.set(&self.level_sets[i][0]);
            passes.push(
                pass.color(ColorTarget::new(l.down, Load::DontCare))
                    .draws(Some(work), 1)
                    .record(move |pc: &PassContext| {
                        fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &push))
                    }),
            );
            below = l.down;
        }
        let weights = blur_weights();
        for (i, l) in self.levels.iter().enumerate() {
            for (axis, src, dst, dir, set) in [
                ("h", l.down, l.across, [1, 0], &self.level_sets[i][1]),
                ("v", l.across, l.blurred, [0, 1], &self.level_sets[i][2]),
            ] {
                let work = ShaderWork {
                    shader: BLUR_SHADER.into(),
                    fetches: vec![fetch(
                        res,
                        src,
                        "srcTex",
                        Filter::Point,
                        f64::from(BLUR_TAPS),
                        true,
                    )],
                    alu: alu_estimate(BLUR_SHADER, &[BLUR_TAPS]),
                    ..Default::default()
                };
                let pipeline = &self.blur_pipeline;
                let e = res.extent(src);
                let hi = [e.width as i32 - 1, e.height as i32 - 1];
                let push = BlurPush { weights, dir, hi };
                let mut pass = Pass::new(format!("bloom blur {axis} {}", i + 1), PassRole::Post);
                // Reads `src`.
                let set = pass.set(set);
                passes.push(
                    pass.color(ColorTarget::new(dst, Load::DontCare))
                        .draws(Some(work), 1)
                        .record(move |pc: &PassContext| {
                            fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &push))
                        }),
                );
            }
        }
        let mut fetches = vec![fetch(res, self.input, "hdrTex", Filter::Point, 1.0, true)];
        let names = ["level1Tex", "level2Tex", "level3Tex", "level4Tex"];
        for (name, l) in names.into_iter().zip(&self.levels) {
            fetches.push(fetch(res, l.blurred, name, Filter::Bilinear, 1.0, true));
        }
        let work = ShaderWork {
            shader: COMBINE_SHADER.into(),
            fetches,
            alu: alu_estimate(COMBINE_SHADER, &[]),
            ..Default::default()
        };
        let push = CombinePush {
            level_weights: LEVEL_WEIGHTS,
            sizes: std::array::from_fn(|k| size_of(res, self.levels[k].blurred)),
            strength: STRENGTH,
        };
        let pipeline = &self.combine_pipeline;
        let mut combine = Pass::new("bloom combine", PassRole::Post);
        // Reads the composite and every blurred level.
        let set = combine.set(&self.combine_set);
        passes.push(
            combine
                .color(ColorTarget::new(self.output, Load::DontCare))
                .draws(Some(work), 1)
                .record(move |pc: &PassContext| {
                    fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &push))
                }),
        );
        passes
    }

    /// The stage's images by name (tests read them back).
    pub fn images(&self) -> Vec<(String, ImageId)> {
        let mut v = vec![("bloomed".to_string(), self.output)];
        for (i, l) in self.levels.iter().enumerate() {
            v.push((format!("bloom level {}", i + 1), l.blurred));
        }
        v
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for p in [
            &mut self.down_pipeline,
            &mut self.blur_pipeline,
            &mut self.combine_pipeline,
        ] {
            p.destroy(ctx);
        }
    }
}

impl crate::vk::guard::Destroy for Bloom {
    fn destroy(&mut self, ctx: &Context) {
        Bloom::destroy(self, ctx)
    }
}

// The combine shader binds one texture per level.
const _: () = assert!(LEVELS == 4);
