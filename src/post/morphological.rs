//! The morphological anti-aliasing stage that MLAA (`mlaa.rs`, thesis ch. 9)
//! and SMAA 1x (`smaa.rs`, ch. 10.4) both are (Granite's `post/aa` keeps them
//! as one stage too): three passes on the tone-mapped frame, named after the
//! variant (`mlaa ...`, `smaa ...`):
//!
//! 1. `edges`: every pixel runs; edgels into an RGBA8 target cleared every
//!    frame, and pixels with an edgel write the stencil (cleared to 0,
//!    REPLACE [`STENCIL_EDGE`]): the variant says what it reads (the frame's
//!    encoded values through its UNORM view, or the linear depth), its shader
//!    and its fetches.
//! 2. `weights`: only where the stencil marks an edge (EQUAL, early tests):
//!    the blending weights from the edges and the variant's tables (area
//!    texture, SMAA's search texture), uploaded as generated.
//! 3. `blend`: neighbourhood blending from the weights, either only on edge
//!    pixels (MLAA: a `copy` of the frame into the output first, so the other
//!    pixels keep their colour) or on every pixel (SMAA).
//!
//! Edges, weights and the tables are plain unorm, never sRGB (bevy's SMAA was
//! silently off when its tables loaded as sRGB); the stencil takes the
//! frame's depth/stencil format, the output the tone-mapped frame's.

use anyhow::Result;
use ash::vk;

use super::{fetch, AaStage, PostBind, PostSetup};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork, Work};
use crate::graph::{
    Binding, ColorTarget, DepthStencil, GraphSet, ImageDesc, ImageId, Load, Pass, PassContext,
    Resources,
};
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload;

/// Edges, weights and tables: plain unorm, four channels (the work vocabulary
/// names no one- or two-channel format; docs/aa.md).
pub const TABLE_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// The stencil value of a pixel with an edgel.
pub const STENCIL_EDGE: u32 = 1;

/// What pass 1 finds edges in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeInput {
    /// The tone-mapped frame's encoded values (luma or colour) through its
    /// UNORM view, as `colorTex`.
    Frame,
    /// The frame's linear view depth, as `depthTex` (MLAA's depth variant).
    Depth,
}

/// A table pass 2 samples beside the edges (an area or search texture):
/// uploaded once as RGBA8 unorm.
pub struct Table {
    /// The image's name (`mlaa area`, `smaa search`...).
    pub name: &'static str,
    /// The shader's texture.
    pub binding: &'static str,
    pub extent: vk::Extent2D,
    /// Its texels (dropped once uploaded).
    pub rgba8: Vec<u8>,
    /// What pass 2 fetches from it per pixel, at most.
    pub filter: Filter,
    pub count: f64,
}

/// Where pass 3 runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlendOn {
    /// Edge pixels only (stencil EQUAL): the output is a copy of the frame first.
    Edges,
    /// Every pixel: the output is written whole.
    Every,
}

/// What one variant (MLAA, SMAA) brings to the stage: the rest (images,
/// pipelines' stencil states, the passes' declarations) is the stage's.
pub struct Spec {
    /// The prefix of the stage's image, pipeline and pass names.
    pub name: &'static str,
    pub edges_shader: &'static str,
    pub edges_input: EdgeInput,
    /// Pass 1's point fetches per pixel: those every pixel makes, and at
    /// most how many more the pixels it keeps make (declared apart, so the
    /// first count floors the pass: `bench::floor`).
    pub edges_fetches: (f64, f64),
    pub weights_shader: &'static str,
    /// The most bilinear edge fetches pass 2 makes per pixel (its searches).
    pub weights_bilinear: f64,
    /// Pass 2's loop trip counts (the ALU estimate).
    pub weights_loops: Vec<u32>,
    pub tables: Vec<Table>,
    pub blend_shader: &'static str,
    pub blend_on: BlendOn,
    /// Pass 3's bilinear colour fetches where a weight is set.
    pub blend_taps: f64,
}

/// A variant: its [`Spec`] and its push constants, recorded after the
/// pass's pipeline is bound.
pub trait Variant {
    fn spec(&self) -> Spec;
    /// Pass 1's push constants; `last` is its input's last texel (size - 1),
    /// pushed rather than queried per fetch: a size query is a texture-unit
    /// instruction on NVIDIA (docs/perf/issue28/floors.md).
    fn push_edges(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pipeline: &Pipeline,
        last: [i32; 2],
    );
    fn push_weights(&self, _ctx: &Context, _cmd: vk::CommandBuffer, _pipeline: &Pipeline) {}
}

/// The stage: a variant, its pipelines, tables, images and sets.
pub struct Morphological {
    variant: Box<dyn Variant>,
    /// The variant's spec (its tables' bytes dropped once uploaded).
    spec: Spec,
    edges_pipeline: Pipeline,
    weights_pipeline: Pipeline,
    blend_pipeline: Pipeline,
    /// The uploaded tables, in the spec's order.
    tables: Vec<Image>,
    input: ImageId,
    depth: ImageId,
    edges: ImageId,
    weights: ImageId,
    stencil: ImageId,
    output: ImageId,
    /// Set 0 of the edges, weights and blend passes.
    sets: [GraphSet; 3],
}

impl Morphological {
    /// The stage of `variant`: images declared, pipelines built, tables
    /// uploaded (on an error, what exists is freed).
    pub fn new(s: &mut PostSetup, variant: Box<dyn Variant>) -> Result<Self> {
        let mut spec = variant.spec();
        let name = spec.name;
        let extent = s.res.extent(s.input);
        let ldr_format = s.res.format(s.input);
        let ds = s.depth_stencil_format;
        if spec.edges_input == EdgeInput::Frame {
            // Pass 1 reads the frame's encoded values (gamma luma, or colour)
            // through a UNORM view.
            s.res.request_unorm_view(s.input);
        }
        let mut declare = |what: &str, format| {
            s.res
                .declare(ImageDesc::new(&format!("{name} {what}"), extent, format))
        };
        let edges = declare("edges", TABLE_FORMAT);
        let weights = declare("weights", TABLE_FORMAT);
        let stencil = declare("stencil", ds);
        let output = declare("output", ldr_format);
        let with_stencil = |pass: &str, frag, format, op: vk::StencilOpState| {
            let mut d = GraphicsDesc::fullscreen(&format!("{name} {pass}"), frag, format);
            d.depth_format = Some(ds);
            d.stencil_format = Some(ds);
            d.stencil = Some(op);
            d
        };
        // Pass 1 writes the edge bit wherever a fragment survives its discard.
        let write = vk::StencilOpState {
            fail_op: vk::StencilOp::KEEP,
            pass_op: vk::StencilOp::REPLACE,
            depth_fail_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::ALWAYS,
            compare_mask: 0xff,
            write_mask: 0xff,
            reference: STENCIL_EDGE,
        };
        // Passes 2 (and 3 on edges only) run where it is set.
        let test = vk::StencilOpState {
            pass_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::EQUAL,
            write_mask: 0,
            ..write
        };
        let ctx = s.ctx;
        let build = |d: &GraphicsDesc| Pipeline::graphics(ctx, d).map(|p| Guard::new(ctx, p));
        let p1 = build(&with_stencil(
            "edges",
            spec.edges_shader,
            TABLE_FORMAT,
            write,
        ))?;
        let p2 = build(&with_stencil(
            "weights",
            spec.weights_shader,
            TABLE_FORMAT,
            test,
        ))?;
        let p3 = build(&match spec.blend_on {
            BlendOn::Edges => with_stencil("blend", spec.blend_shader, ldr_format, test),
            BlendOn::Every => {
                GraphicsDesc::fullscreen(&format!("{name} blend"), spec.blend_shader, ldr_format)
            }
        })?;
        let mut tables = Guard::new(ctx, Vec::<Image>::new());
        for t in &mut spec.tables {
            let rgba8 = std::mem::take(&mut t.rgba8);
            tables.push(upload::texture(
                ctx,
                t.name,
                t.extent,
                TABLE_FORMAT,
                &rgba8,
            )?);
        }
        let linear = (
            "linearClamp",
            Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
        );
        let edges_bind = match spec.edges_input {
            EdgeInput::Depth => ("depthTex", Binding::Sampled(s.linear_depth)),
            EdgeInput::Frame => ("colorTex", Binding::SampledUnorm(s.input)),
        };
        let mut weights_binds = vec![("edgesTex", Binding::Sampled(edges))];
        for (image, t) in tables.iter().zip(&spec.tables) {
            weights_binds.push((t.binding, Binding::Fixed(Bind::Texture(image.view))));
        }
        weights_binds.push(linear);
        let res = &*s.res;
        let sets = [
            GraphSet::new(res, &p1, 0, vec![edges_bind]),
            GraphSet::new(res, &p2, 0, weights_binds),
            GraphSet::new(
                res,
                &p3,
                0,
                vec![
                    ("colorTex", Binding::Sampled(s.input)),
                    ("weightsTex", Binding::Sampled(weights)),
                    linear,
                ],
            ),
        ];
        Ok(Morphological {
            variant,
            spec,
            edges_pipeline: p1.keep(),
            weights_pipeline: p2.keep(),
            blend_pipeline: p3.keep(),
            tables: tables.keep(),
            input: s.input,
            depth: s.linear_depth,
            edges,
            weights,
            stencil,
            output,
            sets,
        })
    }

    /// Pass 1: every pixel runs, edge pixels are written (colour and stencil).
    fn edges_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let (texture, format, input) = match self.spec.edges_input {
            EdgeInput::Depth => ("depthTex", res.texel_format(self.depth), self.depth),
            EdgeInput::Frame => ("colorTex", Format::Rgba8Unorm, self.input),
        };
        let e = res.extent(input);
        let last = [e.width as i32 - 1, e.height as i32 - 1];
        let (every, more) = self.spec.edges_fetches;
        let point = |count, exact| Fetch {
            texture: texture.into(),
            format,
            filter: Filter::Point,
            count,
            exact,
            coherent: true,
            spread: Vec::new(),
        };
        let mut fetches = vec![point(every, true)];
        if more > 0.0 {
            fetches.push(point(more, false));
        }
        let work = ShaderWork {
            shader: self.spec.edges_shader.into(),
            fetches,
            alu: alu_estimate(self.spec.edges_shader, &[]),
            ..Default::default()
        };
        let (pipeline, variant) = (&self.edges_pipeline, &self.variant);
        let mut pass = Pass::new(format!("{} edges", self.spec.name), PassRole::Post);
        // Reads the frame or its depth.
        let set = pass.set(&self.sets[0]);
        pass.color(ColorTarget::new(self.edges, Load::Clear([0.0; 4])))
            .depth_stencil(
                DepthStencil::cleared(self.stencil, 1.0)
                    .depth_test(false)
                    .depth_write(false)
                    .stencil_write(true),
            )
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, &[set], |c, cmd| {
                    unsafe {
                        c.device.cmd_set_stencil_reference(
                            cmd,
                            vk::StencilFaceFlags::FRONT_AND_BACK,
                            STENCIL_EDGE,
                        )
                    };
                    variant.push_edges(c, cmd, pipeline, last);
                })
            })
    }

    /// Pass 2, edge pixels only: one point fetch of the edges, the searches'
    /// bilinear ones and the tables' (bounds: the searches stop at a line's end).
    fn weights_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let mut fetches = vec![
            fetch(res, self.edges, "edgesTex", Filter::Point, 1.0, true),
            fetch(
                res,
                self.edges,
                "edgesTex",
                Filter::Bilinear,
                self.spec.weights_bilinear,
                false,
            ),
        ];
        fetches.extend(self.spec.tables.iter().map(|t| Fetch {
            texture: t.binding.into(),
            format: Format::Rgba8Unorm,
            filter: t.filter,
            count: t.count,
            exact: false,
            coherent: true,
            spread: Vec::new(),
        }));
        let work = ShaderWork {
            shader: self.spec.weights_shader.into(),
            fetches,
            alu: alu_estimate(self.spec.weights_shader, &self.spec.weights_loops),
            ..Default::default()
        };
        let (pipeline, variant) = (&self.weights_pipeline, &self.variant);
        let mut pass = Pass::new(format!("{} weights", self.spec.name), PassRole::Post);
        // Reads the edges (and the tables, which are no frame images).
        let set = pass.set(&self.sets[1]);
        pass.color(ColorTarget::new(self.weights, Load::Clear([0.0; 4])))
            .depth_stencil(self.stencil_test())
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, &[set], |c, cmd| {
                    variant.push_weights(c, cmd, pipeline)
                })
            })
    }

    /// The frame into the output before a blend on edge pixels only.
    fn copy_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let extent = res.extent(self.output);
        let mut pass = Pass::new(format!("{} copy", self.spec.name), PassRole::Post);
        let src = pass.transfer_src(self.input);
        let dst = pass.transfer_dst(self.output);
        pass.work(Work::Copy {
            texels: u64::from(extent.width) * u64::from(extent.height),
            bytes_per_texel: res.texel_format(self.input).bytes_per_texel(),
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

    /// Pass 3: three weight texels, then the variant's bilinear colour
    /// fetches (or one point fetch where every weight is zero).
    fn blend_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let shader = self.spec.blend_shader;
        let work = ShaderWork {
            shader: shader.into(),
            fetches: vec![
                fetch(res, self.weights, "weightsTex", Filter::Point, 3.0, true),
                fetch(
                    res,
                    self.input,
                    "colorTex",
                    Filter::Bilinear,
                    self.spec.blend_taps,
                    false,
                ),
                fetch(res, self.input, "colorTex", Filter::Point, 1.0, false),
            ],
            alu: alu_estimate(shader, &[]),
            ..Default::default()
        };
        let pipeline = &self.blend_pipeline;
        let mut pass = Pass::new(format!("{} blend", self.spec.name), PassRole::Post);
        // Reads the frame and the weights.
        let set = pass.set(&self.sets[2]);
        let pass = match self.spec.blend_on {
            BlendOn::Edges => pass
                .color(ColorTarget::new(self.output, Load::Keep))
                .depth_stencil(self.stencil_test()),
            BlendOn::Every => pass.color(ColorTarget::new(self.output, Load::DontCare)),
        };
        // The frame's last texel, pushed rather than queried per pixel (see
        // `Variant::push_edges`); the weights have the frame's size.
        let e = res.extent(self.input);
        debug_assert_eq!(e, res.extent(self.weights));
        let last = [e.width as i32 - 1, e.height as i32 - 1];
        pass.draws(Some(work), 1).record(move |pc: &PassContext| {
            fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &last))
        })
    }

    fn stencil_test(&self) -> DepthStencil {
        DepthStencil::test_only(self.stencil).stencil_test(Some(STENCIL_EDGE))
    }
}

impl AaStage for Morphological {
    fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>> {
        let mut passes = vec![self.edges_pass(res), self.weights_pass(res)];
        if self.spec.blend_on == BlendOn::Edges {
            passes.push(self.copy_pass(res));
        }
        passes.push(self.blend_pass(res));
        passes
    }

    fn output(&self) -> ImageId {
        self.output
    }

    fn bind(&mut self, b: &PostBind) -> Result<()> {
        let [edges, weights, blend] = &mut self.sets;
        b.write(edges, &self.edges_pipeline)?;
        b.write(weights, &self.weights_pipeline)?;
        b.write(blend, &self.blend_pipeline)
    }

    fn images(&self) -> Vec<(&'static str, ImageId)> {
        vec![
            ("edges", self.edges),
            ("weights", self.weights),
            ("stencil", self.stencil),
            ("output", self.output),
        ]
    }

    fn destroy(&mut self, ctx: &Context) {
        for t in &mut self.tables {
            t.destroy(ctx);
        }
        for p in [
            &mut self.edges_pipeline,
            &mut self.weights_pipeline,
            &mut self.blend_pipeline,
        ] {
            p.destroy(ctx);
        }
    }
}
