//! The chain's first stage: Hable's filmic tone map (his Uncharted 2 curve)
//! from the HDR composite into the LDR frame (RGBA8 sRGB: the attachment
//! encodes). Every frame has it, whatever `--aa` says.

use anyhow::Result;

use super::PostBind;
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, PassRole, ShaderWork};
use crate::graph::{Binding, ColorTarget, GraphSet, ImageId, Load, Pass, PassContext, Resources};
use crate::vk::context::Context;
use crate::vk::pipeline::{GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

pub const SHADER: &str = "tonemap.frag";
/// Linear white point of Hable's filmic curve (his Uncharted 2 value).
pub const WHITE_POINT: f32 = 11.2;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapPush {
    exposure: f32,
    white_point: f32,
}

/// The tone map: its pipeline and set, the HDR image it reads and the LDR
/// frame it writes.
#[derive(Default)]
pub struct Tonemap {
    pipeline: Pipeline,
    set: GraphSet,
    input: ImageId,
    output: ImageId,
    exposure: f32,
}

impl Tonemap {
    pub fn new(
        ctx: &Context,
        res: &Resources,
        input: ImageId,
        output: ImageId,
        exposure: f32,
    ) -> Result<Self> {
        let desc = GraphicsDesc::fullscreen("tonemap", SHADER, res.format(output));
        let pipeline = Pipeline::graphics(ctx, &desc)?;
        Ok(Tonemap {
            set: GraphSet::new(res, &pipeline, 0, vec![("hdrTex", Binding::Sampled(input))]),
            pipeline,
            input,
            output,
            exposure,
        })
    }

    /// The HDR image it reads.
    pub fn input(&self) -> ImageId {
        self.input
    }

    /// The LDR frame it writes.
    pub fn output(&self) -> ImageId {
        self.output
    }

    pub fn bind(&mut self, b: &PostBind) -> Result<()> {
        b.write(&mut self.set, &self.pipeline)
    }

    /// One point fetch of the HDR composite per pixel, every pixel written.
    pub fn pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let work = ShaderWork {
            shader: SHADER.into(),
            fetches: vec![Fetch {
                texture: "hdrTex".into(),
                format: res.texel_format(self.input),
                filter: Filter::Point,
                count: 1.0,
                exact: true,
                coherent: true,
                spread: Vec::new(),
            }],
            alu: alu_estimate(SHADER, &[]),
            ..Default::default()
        };
        let push = TonemapPush {
            exposure: self.exposure,
            white_point: WHITE_POINT,
        };
        let pipeline = &self.pipeline;
        let mut pass = Pass::new("tonemap", PassRole::Post);
        // Reads the HDR composite.
        let set = pass.set(&self.set);
        pass.color(ColorTarget::new(self.output, Load::DontCare))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &push))
            })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
