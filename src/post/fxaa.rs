//! FXAA, quality preset (`shaders/fxaa.frag` says the algorithm): one
//! full-screen pass from the tone-mapped frame into a new sRGB target. The
//! baseline the morphological modes are charted against (issue 17).

use anyhow::Result;

use super::{AaStage, PostBind, PostSetup};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{
    Binding, ColorTarget, GraphSet, ImageDesc, ImageId, Load, Pass, PassContext, Resources,
};
use crate::vk::context::Context;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

pub const SHADER: &str = "fxaa.frag";
/// The quality preset's search steps each way (preset 12: 1, 1.5, 2, 4, 12
/// pixels), the shader's `STEPS`.
pub const SEARCH_STEPS: u32 = 5;

/// The FXAA stage.
pub struct Fxaa {
    pipeline: Pipeline,
    input: ImageId,
    output: ImageId,
    set: GraphSet,
}

impl Fxaa {
    pub fn new(s: &mut PostSetup) -> Result<Self> {
        let extent = s.res.extent(s.input);
        let format = s.res.format(s.input);
        let output = s.res.declare(ImageDesc::new("fxaa output", extent, format));
        // Luma reads the frame's encoded values through a UNORM view.
        s.res.request_unorm_view(s.input);
        let pipeline =
            Pipeline::graphics(s.ctx, &GraphicsDesc::fullscreen("fxaa", SHADER, format))?;
        let set = GraphSet::new(
            s.res,
            &pipeline,
            0,
            vec![
                ("colorTex", Binding::Sampled(s.input)),
                ("lumaTex", Binding::SampledUnorm(s.input)),
                (
                    "linearClamp",
                    Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                ),
            ],
        );
        Ok(Fxaa {
            pipeline,
            input: s.input,
            output,
            set,
        })
    }
}

impl AaStage for Fxaa {
    /// Every pixel fetches its colour, and the luma of itself and its
    /// 4-neighbourhood; past the contrast test also the corners' luma, up to
    /// two bilinear luma fetches per search step and the final colour fetch:
    /// bounds.
    fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>> {
        let f = |texture: &str, format, filter, count, exact| Fetch {
            texture: texture.into(),
            format,
            filter,
            count,
            exact,
            coherent: true,
            spread: Vec::new(),
        };
        let (srgb, unorm) = (res.texel_format(self.input), Format::Rgba8Unorm);
        let steps = f64::from(SEARCH_STEPS);
        let work = ShaderWork {
            shader: SHADER.into(),
            fetches: vec![
                f("colorTex", srgb, Filter::Point, 1.0, true),
                f("lumaTex", unorm, Filter::Point, 5.0, true),
                f("lumaTex", unorm, Filter::Point, 4.0, false),
                f("lumaTex", unorm, Filter::Bilinear, 2.0 * steps, false),
                f("colorTex", srgb, Filter::Bilinear, 1.0, false),
            ],
            alu: alu_estimate(SHADER, &[SEARCH_STEPS]),
            ..Default::default()
        };
        let pipeline = &self.pipeline;
        // The frame's last texel, pushed rather than queried per pixel (a
        // texture-unit instruction on NVIDIA: docs/perf/issue28/floors.md).
        let e = res.extent(self.input);
        let last = [e.width as i32 - 1, e.height as i32 - 1];
        let mut pass = Pass::new("fxaa", PassRole::Post);
        // Reads the tone-mapped frame (and its UNORM view).
        let set = pass.set(&self.set);
        vec![pass
            .color(ColorTarget::new(self.output, Load::DontCare))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &last))
            })]
    }

    fn output(&self) -> ImageId {
        self.output
    }

    fn bind(&mut self, b: &PostBind) -> Result<()> {
        b.write(&mut self.set, &self.pipeline)
    }

    fn images(&self) -> Vec<(&'static str, ImageId)> {
        vec![("output", self.output)]
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
