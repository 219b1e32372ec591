//! SMAA 1x (thesis ch. 10.4.1-10.4.2), high preset, as a post stage: three
//! passes on the tone-mapped frame.
//!
//! 1. `smaa edges` (ch. 10.4.1, Eq. 10.1): gamma luma, threshold 0.1, local
//!    contrast adaptation (factor 2, SMAA.hlsl's shared maximum:
//!    `aa::edges::LocalContrast::Shared`); pixels with neither a left nor a
//!    top edgel are discarded, so the stencil marks the pixels pass 2 runs on.
//! 2. `smaa weights` (ch. 10.4.2): stencil EQUAL 1, early tests: diagonal
//!    patterns, accurate distance searches (four edgels per bilinear fetch,
//!    decoded by the search texture), crossing edges, the orthogonal areas at
//!    `sqrt(d)`, sharp corners (rounding 25 %).
//! 3. `smaa blend`: every pixel, the larger of its horizontal and vertical
//!    weight pairs, two bilinear fetches.
//!
//! The area texture (160 x 560, `aa::smaa_area`) and the search texture (64 x
//! 16, `aa::smaa_search`) are uploaded as generated, no flip (docs/aa.md),
//! into RGBA8 unorm images (their channels in .rg and .r: the work vocabulary
//! names no R8 or R8G8 format), never sRGB.

use anyhow::Result;
use ash::vk;

use super::{fetch, rg8_as_rgba8, AaStage, PostBind, PostSetup};
use crate::aa::edges::Preset;
use crate::aa::{smaa_area, smaa_search};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{
    ColorTarget, DepthStencil, ImageDesc, ImageId, Load, Pass, PassContext, Resources,
};
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload;

pub const EDGES_SHADER: &str = "smaa_edges.frag";
pub const WEIGHTS_SHADER: &str = "smaa_weights.frag";
pub const BLEND_SHADER: &str = "smaa_blend.frag";
const TABLE_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// The stencil value of a pixel with an edgel.
pub const STENCIL_EDGE: u32 = 1;
/// The preset this stage runs (its threshold; the shader holds its search
/// steps, 16 orthogonal and 8 diagonal, and its corner rounding, 25 %).
pub const PRESET: Preset = Preset::High;
/// SMAA's local contrast adaptation factor (an edgel survives if its delta
/// is at least the largest around it over this).
pub const LOCAL_CONTRAST_FACTOR: f32 = 2.0;
/// The shader's search loops, in the order they are reached: four diagonal
/// (8 steps), then left, right, up and down (16 steps).
const LOOP_TRIPS: [u32; 8] = [8, 8, 8, 8, 16, 16, 16, 16];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EdgesPush {
    threshold: f32,
    adaptation: f32,
}

/// The SMAA 1x stage.
pub struct Smaa {
    edges_pipeline: Pipeline,
    weights_pipeline: Pipeline,
    blend_pipeline: Pipeline,
    area: Image,
    search: Image,
    input: ImageId,
    edges: ImageId,
    weights: ImageId,
    stencil: ImageId,
    output: ImageId,
    sets: [vk::DescriptorSet; 3],
}

/// The area texture as RGBA8 bytes (its two channels in .rg).
pub fn area_rgba8() -> Vec<u8> {
    rg8_as_rgba8(smaa_area::area_tex_rg8())
}

/// The search texture as RGBA8 bytes (its channel in .r).
pub fn search_rgba8() -> Vec<u8> {
    smaa_search::search_tex()
        .bytes
        .iter()
        .flat_map(|&r| [r, 0, 0, 0])
        .collect()
}

impl Smaa {
    pub fn new(s: &mut PostSetup) -> Result<Self> {
        let extent = s.res.extent(s.input);
        let ldr_format = s.res.format(s.input);
        let ds = s.depth_stencil_format;
        // Pass 1 reads the frame's encoded values (gamma luma) through a UNORM view.
        s.res.request_unorm_view(s.input);
        let edges = s
            .res
            .declare(ImageDesc::new("smaa edges", extent, TABLE_FORMAT));
        let weights = s
            .res
            .declare(ImageDesc::new("smaa weights", extent, TABLE_FORMAT));
        let stencil = s.res.declare(ImageDesc::new("smaa stencil", extent, ds));
        let output = s
            .res
            .declare(ImageDesc::new("smaa output", extent, ldr_format));
        let with_stencil = |name: &str, frag, op: vk::StencilOpState| {
            let mut d = GraphicsDesc::fullscreen(name, frag, TABLE_FORMAT);
            d.depth_format = Some(ds);
            d.stencil_format = Some(ds);
            d.stencil = Some(op);
            d
        };
        let write = vk::StencilOpState {
            fail_op: vk::StencilOp::KEEP,
            pass_op: vk::StencilOp::REPLACE,
            depth_fail_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::ALWAYS,
            compare_mask: 0xff,
            write_mask: 0xff,
            reference: STENCIL_EDGE,
        };
        let test = vk::StencilOpState {
            pass_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::EQUAL,
            write_mask: 0,
            ..write
        };
        let ctx = s.ctx;
        let p1 = Guard::new(
            ctx,
            Pipeline::graphics(ctx, &with_stencil("smaa edges", EDGES_SHADER, write))?,
        );
        let p2 = Guard::new(
            ctx,
            Pipeline::graphics(ctx, &with_stencil("smaa weights", WEIGHTS_SHADER, test))?,
        );
        let p3 = Guard::new(
            ctx,
            Pipeline::graphics(
                ctx,
                &GraphicsDesc::fullscreen("smaa blend", BLEND_SHADER, ldr_format),
            )?,
        );
        let area = Guard::new(
            ctx,
            upload::texture(
                ctx,
                "smaa area",
                vk::Extent2D {
                    width: smaa_area::WIDTH as u32,
                    height: smaa_area::HEIGHT as u32,
                },
                TABLE_FORMAT,
                &area_rgba8(),
            )?,
        );
        let search = upload::texture(
            ctx,
            "smaa search",
            vk::Extent2D {
                width: smaa_search::WIDTH as u32,
                height: smaa_search::HEIGHT as u32,
            },
            TABLE_FORMAT,
            &search_rgba8(),
        )?;
        Ok(Smaa {
            edges_pipeline: p1.keep(),
            weights_pipeline: p2.keep(),
            blend_pipeline: p3.keep(),
            area: area.keep(),
            search,
            input: s.input,
            edges,
            weights,
            stencil,
            output,
            sets: [vk::DescriptorSet::null(); 3],
        })
    }

    /// Pass 1: every pixel fetches itself, left and top; pixels kept also
    /// right, bottom and the two beyond left and top.
    fn edges_pass(&self) -> Pass<'_> {
        let work = ShaderWork {
            shader: EDGES_SHADER.into(),
            fetches: vec![Fetch {
                texture: "colorTex".into(),
                format: Format::Rgba8Unorm,
                filter: Filter::Point,
                count: 7.0,
                exact: false,
                coherent: true,
                spread: Vec::new(),
            }],
            alu: alu_estimate(EDGES_SHADER, &[]),
            ..Default::default()
        };
        let (pipeline, set) = (&self.edges_pipeline, self.sets[0]);
        Pass::new("smaa edges", PassRole::Post)
            .sampled(self.input)
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
                    let push = EdgesPush {
                        threshold: PRESET.threshold(),
                        adaptation: LOCAL_CONTRAST_FACTOR,
                    };
                    pipeline.push(c, cmd, &push);
                })
            })
    }

    /// Pass 2, pixels with an edgel only. Bounds: per edgel the diagonal
    /// searches (4 x 8 fetches, 5 crossing, 1 test) or the orthogonal ones
    /// (2 x 16, 2 crossing, 4 corner), two area and search fetches each.
    fn weights_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let table = |texture: &str, filter, count| Fetch {
            texture: texture.into(),
            format: Format::Rgba8Unorm,
            filter,
            count,
            exact: false,
            coherent: true,
            spread: Vec::new(),
        };
        let work = ShaderWork {
            shader: WEIGHTS_SHADER.into(),
            fetches: vec![
                fetch(res, self.edges, "edgesTex", Filter::Point, 1.0, true),
                fetch(res, self.edges, "edgesTex", Filter::Bilinear, 114.0, false),
                table("areaTex", Filter::Bilinear, 4.0),
                table("searchTex", Filter::Point, 4.0),
            ],
            alu: alu_estimate(WEIGHTS_SHADER, &LOOP_TRIPS),
            ..Default::default()
        };
        let (pipeline, set) = (&self.weights_pipeline, self.sets[1]);
        Pass::new("smaa weights", PassRole::Post)
            .sampled(self.edges)
            .color(ColorTarget::new(self.weights, Load::Clear([0.0; 4])))
            .depth_stencil(DepthStencil::test_only(self.stencil).stencil_test(Some(STENCIL_EDGE)))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {}))
    }

    /// Pass 3, every pixel: three weight texels, then two bilinear colour
    /// fetches (or one point fetch where every weight is zero).
    fn blend_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let work = ShaderWork {
            shader: BLEND_SHADER.into(),
            fetches: vec![
                fetch(res, self.weights, "weightsTex", Filter::Point, 3.0, true),
                fetch(res, self.input, "colorTex", Filter::Bilinear, 2.0, false),
                fetch(res, self.input, "colorTex", Filter::Point, 1.0, false),
            ],
            alu: alu_estimate(BLEND_SHADER, &[]),
            ..Default::default()
        };
        let (pipeline, set) = (&self.blend_pipeline, self.sets[2]);
        Pass::new("smaa blend", PassRole::Post)
            .sampled(self.input)
            .sampled(self.weights)
            .color(ColorTarget::new(self.output, Load::DontCare))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {}))
    }
}

impl AaStage for Smaa {
    fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>> {
        vec![
            self.edges_pass(),
            self.weights_pass(res),
            self.blend_pass(res),
        ]
    }

    fn output(&self) -> ImageId {
        self.output
    }

    fn bind(&mut self, b: &PostBind) -> Result<()> {
        let (ctx, res, linear) = (b.ctx, b.res, b.samplers.linear_clamp);
        self.sets = [
            b.pool.write_set(
                ctx,
                &self.edges_pipeline,
                0,
                &[("colorTex", Bind::Texture(res.unorm_view(self.input)))],
            )?,
            b.pool.write_set(
                ctx,
                &self.weights_pipeline,
                0,
                &[
                    ("edgesTex", Bind::Texture(res.view(self.edges))),
                    ("areaTex", Bind::Texture(self.area.view)),
                    ("searchTex", Bind::Texture(self.search.view)),
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
        self.search.destroy(ctx);
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
    fn the_tables_upload_their_channels_first() {
        let rg = smaa_area::area_tex_rg8();
        let a = area_rgba8();
        assert_eq!(a.len(), smaa_area::WIDTH * smaa_area::HEIGHT * 4);
        assert!(a
            .chunks_exact(4)
            .enumerate()
            .all(|(i, t)| t[..2] == rg[2 * i..2 * i + 2] && t[2..] == [0, 0]));
        let s = search_rgba8();
        let bytes = &smaa_search::search_tex().bytes;
        assert!(s
            .chunks_exact(4)
            .zip(bytes)
            .all(|(t, &b)| t == [b, 0, 0, 0]));
    }
}
