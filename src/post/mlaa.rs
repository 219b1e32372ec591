//! Jimenez's MLAA (thesis ch. 9) as a post stage, three passes on the
//! tone-mapped frame and a copy:
//!
//! 1. `mlaa edges` (ch. 9.3.1, Listing 9.1): Eq. 9.2 luma of the gamma-encoded
//!    colour, threshold 0.1 (or, with `--aa-edges depth`, the frame's linear
//!    view depth, threshold `MLAA_DEPTH_THRESHOLD_MM`: ch. 9.3), left and top
//!    edgels into an RGBA8 edges target
//!    cleared every frame; pixels with no edge on any of their four sides are
//!    discarded, so the stencil (cleared to 0, REPLACE 1) marks edge pixels.
//! 2. `mlaa weights` (ch. 9.4, Listings 9.2-9.4): stencil EQUAL 1, early
//!    tests: distance searches two edgels per bilinear fetch, crossing edges a
//!    quarter pixel across, areas from the 45 x 45 area texture of
//!    `aa::mlaa_area` (uploaded as generated, no flip: docs/aa.md).
//! 3. `mlaa copy`: the frame into the output, so pixels off every edge keep
//!    their colour (passes 2 and 3 never run there).
//! 4. `mlaa blend` (ch. 9.5, Listing 9.5): stencil EQUAL 1, four bilinear
//!    fetches, one per neighbour, averaged over the lines a pixel is on.
//!
//! Targets: edges and weights RGBA8 unorm (the work vocabulary names no
//! two-channel format; the Xbox 360 used a four-channel edges target too,
//! ch. 9.6: `aa::mlaa_area::XBOX360_EDGES_TARGET_CHANNELS`), the area texture RGBA8 unorm (its two channels in .rg), the
//! stencil in the frame's depth/stencil format, the output sRGB like the
//! tone-mapped frame.

use anyhow::Result;
use ash::vk;

use super::{fetch, rg8_as_rgba8, AaStage, EdgeSource, PostBind, PostSetup};
use crate::aa::edges::{MLAA_DEPTH_THRESHOLD_MM, MLAA_LUMA_THRESHOLD};
use crate::aa::mlaa_area::{MlaaAreaTex, AREA_SIZE, MAX_DISTANCE, NUM_DISTANCES};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork, Work};
use crate::graph::{
    ColorTarget, DepthStencil, ImageDesc, ImageId, Load, Pass, PassContext, Resources,
};
use crate::shader_constants::{MLAA_MAX_SEARCH_STEPS, MLAA_NUM_DISTANCES};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload;

pub const EDGES_SHADER: &str = "mlaa_edges.frag";
pub const EDGES_DEPTH_SHADER: &str = "mlaa_edges_depth.frag";
pub const WEIGHTS_SHADER: &str = "mlaa_weights.frag";
pub const BLEND_SHADER: &str = "mlaa_blend.frag";
/// Edges, weights and the area texture: plain unorm, never sRGB (bevy's SMAA
/// was silently off when its tables loaded as sRGB).
const TABLE_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// The stencil value of an edge pixel.
pub const STENCIL_EDGE: u32 = 1;
/// The distance searches' reach in pixels each way: 2 per fetch.
pub const SEARCH_DISTANCE: usize = 2 * MLAA_MAX_SEARCH_STEPS as usize;

// The shader's constants and the area texture's layout are one fact.
const _: () = assert!(MLAA_NUM_DISTANCES as usize == NUM_DISTANCES);
const _: () = assert!(SEARCH_DISTANCE == MAX_DISTANCE);
const _: () = assert!(MLAA_MAX_SEARCH_STEPS as usize == crate::aa::mlaa_weights::MAX_SEARCH_STEPS);
// The reach is the Xbox 360's tfetch2D offset (ch. 9.4.1; the constant's doc).
const _: () =
    assert!(SEARCH_DISTANCE as i32 == -crate::aa::mlaa_area::XBOX360_TFETCH2D_MIN_OFFSET_PX);
// The edges target has the Xbox 360's four channels (TABLE_FORMAT is RGBA8).
const _: () = assert!(crate::aa::mlaa_area::XBOX360_EDGES_TARGET_CHANNELS == 4);

/// The depth pass's threshold in scene units: `MLAA_DEPTH_THRESHOLD_MM` over
/// the scene's millimetres per unit (what the pass pushes; tests compare
/// with the CPU reference at the same f32).
pub fn depth_threshold(mm_per_unit: f32) -> f32 {
    MLAA_DEPTH_THRESHOLD_MM / mm_per_unit
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EdgesPush {
    threshold: f32,
}

/// The MLAA stage: its pipelines, area texture, images and sets.
pub struct Mlaa {
    edges_pipeline: Pipeline,
    weights_pipeline: Pipeline,
    blend_pipeline: Pipeline,
    area: Image,
    input: ImageId,
    /// What pass 1 reads: the frame's UNORM view (luma) or its linear depth.
    source: EdgeSource,
    depth: ImageId,
    threshold: f32,
    edges: ImageId,
    weights: ImageId,
    stencil: ImageId,
    output: ImageId,
    sets: [vk::DescriptorSet; 3],
}

/// The area texture as RGBA8 bytes: `MlaaAreaTex::rg8` in .rg, zeros in .ba.
pub fn area_rgba8() -> Vec<u8> {
    rg8_as_rgba8(&MlaaAreaTex::generate().rg8())
}

impl Mlaa {
    pub fn new(s: &mut PostSetup) -> Result<Self> {
        let extent = s.res.extent(s.input);
        let ldr_format = s.res.format(s.input);
        let source = s.options.edges();
        let (edges_shader, threshold) = match source {
            EdgeSource::Depth => (EDGES_DEPTH_SHADER, depth_threshold(s.mm_per_unit)),
            _ => {
                // Pass 1 reads the frame's encoded values (gamma luma) through a UNORM view.
                s.res.request_unorm_view(s.input);
                (EDGES_SHADER, MLAA_LUMA_THRESHOLD)
            }
        };
        let edges = s
            .res
            .declare(ImageDesc::new("mlaa edges", extent, TABLE_FORMAT));
        let weights = s
            .res
            .declare(ImageDesc::new("mlaa weights", extent, TABLE_FORMAT));
        let stencil = s.res.declare(ImageDesc::new(
            "mlaa stencil",
            extent,
            s.depth_stencil_format,
        ));
        let output = s
            .res
            .declare(ImageDesc::new("mlaa output", extent, ldr_format));
        let ds = s.depth_stencil_format;
        let with_stencil = |name: &str, frag, format, op: vk::StencilOpState| {
            let mut d = GraphicsDesc::fullscreen(name, frag, format);
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
        // Passes 2 and 3 run where it is set.
        let test = vk::StencilOpState {
            pass_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::EQUAL,
            write_mask: 0,
            ..write
        };
        let ctx = s.ctx;
        let p1 = Guard::new(
            ctx,
            Pipeline::graphics(
                ctx,
                &with_stencil("mlaa edges", edges_shader, TABLE_FORMAT, write),
            )?,
        );
        let p2 = Guard::new(
            ctx,
            Pipeline::graphics(
                ctx,
                &with_stencil("mlaa weights", WEIGHTS_SHADER, TABLE_FORMAT, test),
            )?,
        );
        let p3 = Guard::new(
            ctx,
            Pipeline::graphics(
                ctx,
                &with_stencil("mlaa blend", BLEND_SHADER, ldr_format, test),
            )?,
        );
        let side = AREA_SIZE as u32;
        let area = upload::texture(
            ctx,
            "mlaa area",
            vk::Extent2D {
                width: side,
                height: side,
            },
            TABLE_FORMAT,
            &area_rgba8(),
        )?;
        Ok(Mlaa {
            edges_pipeline: p1.keep(),
            weights_pipeline: p2.keep(),
            blend_pipeline: p3.keep(),
            area,
            input: s.input,
            source,
            depth: s.linear_depth,
            threshold,
            edges,
            weights,
            stencil,
            output,
            sets: [vk::DescriptorSet::null(); 3],
        })
    }

    /// Pass 1: every pixel runs, edge pixels are written (colour and stencil).
    fn edges_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let (shader, read, texture, format) = match self.source {
            EdgeSource::Depth => (
                EDGES_DEPTH_SHADER,
                self.depth,
                "depthTex",
                res.texel_format(self.depth),
            ),
            _ => (EDGES_SHADER, self.input, "colorTex", Format::Rgba8Unorm),
        };
        let work = ShaderWork {
            shader: shader.into(),
            fetches: vec![Fetch {
                texture: texture.into(),
                format,
                filter: Filter::Point,
                count: 5.0,
                exact: true,
                coherent: true,
                spread: Vec::new(),
            }],
            alu: alu_estimate(shader, &[]),
            ..Default::default()
        };
        let (pipeline, set, threshold) = (&self.edges_pipeline, self.sets[0], self.threshold);
        Pass::new("mlaa edges", PassRole::Post)
            .sampled(read)
            .color(ColorTarget::new(self.edges, Load::Clear([0.0; 4])))
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
                    pipeline.push(c, cmd, &EdgesPush { threshold });
                })
            })
    }

    /// Pass 2: edge pixels only. Per edgel, two searches of at most
    /// `MLAA_MAX_SEARCH_STEPS` bilinear fetches, two crossing-edge fetches and
    /// one area fetch: upper bounds (the searches stop at the line's end).
    fn weights_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let steps = MLAA_MAX_SEARCH_STEPS;
        let per_edgel = 2.0 * f64::from(steps) + 2.0;
        let work = ShaderWork {
            shader: WEIGHTS_SHADER.into(),
            fetches: vec![
                fetch(res, self.edges, "edgesTex", Filter::Point, 1.0, true),
                fetch(
                    res,
                    self.edges,
                    "edgesTex",
                    Filter::Bilinear,
                    2.0 * per_edgel,
                    false,
                ),
                Fetch {
                    texture: "areaTex".into(),
                    format: Format::Rgba8Unorm,
                    filter: Filter::Point,
                    count: 2.0,
                    exact: false,
                    coherent: true,
                    spread: Vec::new(),
                },
            ],
            // Four searches (two per edgel), each loop at most `steps` trips.
            alu: alu_estimate(WEIGHTS_SHADER, &[steps; 4]),
            ..Default::default()
        };
        let (pipeline, set) = (&self.weights_pipeline, self.sets[1]);
        Pass::new("mlaa weights", PassRole::Post)
            .sampled(self.edges)
            .color(ColorTarget::new(self.weights, Load::Clear([0.0; 4])))
            .depth_stencil(self.stencil_test())
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {}))
    }

    /// The frame into the output: the blend pass writes only edge pixels.
    fn copy_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let extent = res.extent(self.output);
        let (src, dst) = (self.input, self.output);
        Pass::new("mlaa copy", PassRole::Post)
            .image(src, AccessKind::TransferRead)
            .image(dst, AccessKind::TransferWrite)
            .work(Work::Copy {
                texels: u64::from(extent.width) * u64::from(extent.height),
                bytes_per_texel: res.texel_format(src).bytes_per_texel(),
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
                unsafe {
                    pc.ctx.device.cmd_copy_image(
                        pc.cmd,
                        pc.image(src).raw,
                        pc.layout(src),
                        pc.image(dst).raw,
                        pc.layout(dst),
                        &[copy],
                    )
                };
            })
    }

    /// Pass 3: edge pixels only: three weight texels, then four bilinear
    /// colour fetches (or one point fetch where every weight is zero).
    fn blend_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let work = ShaderWork {
            shader: BLEND_SHADER.into(),
            fetches: vec![
                fetch(res, self.weights, "weightsTex", Filter::Point, 3.0, true),
                fetch(res, self.input, "colorTex", Filter::Bilinear, 4.0, false),
                fetch(res, self.input, "colorTex", Filter::Point, 1.0, false),
            ],
            alu: alu_estimate(BLEND_SHADER, &[]),
            ..Default::default()
        };
        let (pipeline, set) = (&self.blend_pipeline, self.sets[2]);
        Pass::new("mlaa blend", PassRole::Post)
            .sampled(self.input)
            .sampled(self.weights)
            .color(ColorTarget::new(self.output, Load::Keep))
            .depth_stencil(self.stencil_test())
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {}))
    }

    fn stencil_test(&self) -> DepthStencil {
        DepthStencil::test_only(self.stencil).stencil_test(Some(STENCIL_EDGE))
    }
}

impl AaStage for Mlaa {
    fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>> {
        vec![
            self.edges_pass(res),
            self.weights_pass(res),
            self.copy_pass(res),
            self.blend_pass(res),
        ]
    }

    fn output(&self) -> ImageId {
        self.output
    }

    fn bind(&mut self, b: &PostBind) -> Result<()> {
        let (ctx, res, linear) = (b.ctx, b.res, b.samplers.linear_clamp);
        let edges_bind = match self.source {
            EdgeSource::Depth => ("depthTex", Bind::Texture(res.view(self.depth))),
            _ => ("colorTex", Bind::Texture(res.unorm_view(self.input))),
        };
        self.sets = [
            b.pool
                .write_set(ctx, &self.edges_pipeline, 0, &[edges_bind])?,
            b.pool.write_set(
                ctx,
                &self.weights_pipeline,
                0,
                &[
                    ("edgesTex", Bind::Texture(res.view(self.edges))),
                    ("areaTex", Bind::Texture(self.area.view)),
                    ("linearClamp", Bind::Sampler(linear)),
                ],
            )?,
            b.pool.write_set(
                ctx,
                &self.blend_pipeline,
                0,
                &[
                    ("colorTex", Bind::Texture(res.view(self.input))),
                    ("weightsTex", Bind::Texture(res.view(self.weights))),
                    ("linearClamp", Bind::Sampler(linear)),
                ],
            )?,
        ];
        Ok(())
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
        self.area.destroy(ctx);
        for p in [
            &mut self.edges_pipeline,
            &mut self.weights_pipeline,
            &mut self.blend_pipeline,
        ] {
            p.destroy(ctx);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_area_texture_uploads_its_two_channels_in_rg() {
        let rg = MlaaAreaTex::generate().rg8();
        let rgba = area_rgba8();
        assert_eq!(rgba.len(), AREA_SIZE * AREA_SIZE * 4);
        for (i, t) in rgba.chunks_exact(4).enumerate() {
            assert_eq!([t[0], t[1]], [rg[2 * i], rg[2 * i + 1]]);
            assert_eq!([t[2], t[3]], [0, 0]);
        }
    }
}
