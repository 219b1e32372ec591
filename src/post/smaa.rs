//! SMAA 1x (thesis ch. 10.4.1-10.4.2) as a post stage, the preset
//! `--smaa-preset` names (default high), three passes on the tone-mapped
//! frame.
//!
//! 1. `smaa edges` (ch. 10.4.1, Eq. 10.1): gamma luma (or, with `--aa-edges
//!    color`, the largest R, G or B difference), the preset's threshold, local
//!    contrast adaptation (factor 2, SMAA.hlsl's shared maximum:
//!    `aa::edges::LocalContrast::Shared`); pixels with neither a left nor a
//!    top edgel are discarded, so the stencil marks the pixels pass 2 runs on.
//! 2. `smaa weights` (ch. 10.4.2): stencil EQUAL 1, early tests: diagonal
//!    patterns, accurate distance searches (four edgels per bilinear fetch,
//!    decoded by the search texture), crossing edges, the orthogonal areas at
//!    `sqrt(d)`, sharp corners (rounding 25 %); the preset sets the search
//!    steps and switches diagonals and corners off (low, medium).
//! 3. `smaa blend`: every pixel, the larger of its horizontal and vertical
//!    weight pairs, two bilinear fetches.
//!
//! The area texture (160 x 560, `aa::smaa_area`) and the search texture (64 x
//! 16, `aa::smaa_search`) are uploaded as generated, no flip (docs/aa.md),
//! into RGBA8 unorm images (their channels in .rg and .r: the work vocabulary
//! names no R8 or R8G8 format), never sRGB.

use anyhow::Result;
use ash::vk;

use super::{fetch, rg8_as_rgba8, AaStage, EdgeSource, PostBind, PostSetup};
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
pub const EDGES_COLOR_SHADER: &str = "smaa_edges_color.frag";
pub const WEIGHTS_SHADER: &str = "smaa_weights.frag";
pub const BLEND_SHADER: &str = "smaa_blend.frag";
const TABLE_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// The stencil value of a pixel with an edgel.
pub const STENCIL_EDGE: u32 = 1;
/// The preset without `--smaa-preset` (what the stage ran before presets).
pub const DEFAULT_PRESET: Preset = Preset::High;
/// SMAA's local contrast adaptation factor (an edgel survives if its delta
/// is at least the largest around it over this).
pub const LOCAL_CONTRAST_FACTOR: f32 = 2.0;
/// The weights shader's search loops, in the order they are reached: four
/// diagonal (the preset's diagonal steps, none without diagonals), then
/// left, right, up and down (its orthogonal steps).
fn loop_trips(p: Preset) -> [u32; 8] {
    let (d, s) = (p.diag_search_steps().unwrap_or(0), p.search_steps());
    [d, d, d, d, s, s, s, s]
}

/// The bound on the weights pass's bilinear edge fetches per pixel: the top
/// edgel's diagonal searches (4 x steps, 6 crossing and test fetches) where
/// the preset has them, the four orthogonal searches of both edgels (4 x
/// steps), their 4 crossing fetches and, with corners, 8 corner fetches
/// (114 at high).
pub fn weights_bilinear_bound(p: Preset) -> f64 {
    let diag = p.diag_search_steps().map_or(0, |d| 4 * d + 6);
    let corners = if p.corner_rounding().is_some() { 8 } else { 0 };
    f64::from(diag + 4 * p.search_steps() + 4 + corners)
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct WeightsPush {
    max_search_steps: i32,
    max_search_steps_diag: i32,
    corner_rounding: f32,
    corners: i32,
}

impl WeightsPush {
    fn of(p: Preset) -> Self {
        WeightsPush {
            max_search_steps: p.search_steps() as i32,
            max_search_steps_diag: p.diag_search_steps().unwrap_or(0) as i32,
            corner_rounding: p.corner_rounding().unwrap_or(0.0),
            corners: i32::from(p.corner_rounding().is_some()),
        }
    }
}

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
    preset: Preset,
    /// Luma or colour edges (`--aa-edges`).
    color: bool,
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
        let preset = s.options.smaa_preset();
        let color = s.options.edges() == EdgeSource::Color;
        let edges_shader = if color {
            EDGES_COLOR_SHADER
        } else {
            EDGES_SHADER
        };
        // Pass 1 reads the frame's encoded values (gamma luma, or colour)
        // through a UNORM view.
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
            Pipeline::graphics(ctx, &with_stencil("smaa edges", edges_shader, write))?,
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
            preset,
            color,
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
        let shader = if self.color {
            EDGES_COLOR_SHADER
        } else {
            EDGES_SHADER
        };
        let work = ShaderWork {
            shader: shader.into(),
            fetches: vec![Fetch {
                texture: "colorTex".into(),
                format: Format::Rgba8Unorm,
                filter: Filter::Point,
                count: 7.0,
                exact: false,
                coherent: true,
                spread: Vec::new(),
            }],
            alu: alu_estimate(shader, &[]),
            ..Default::default()
        };
        let (pipeline, set) = (&self.edges_pipeline, self.sets[0]);
        let threshold = self.preset.threshold();
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
                        threshold,
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
                fetch(
                    res,
                    self.edges,
                    "edgesTex",
                    Filter::Bilinear,
                    weights_bilinear_bound(self.preset),
                    false,
                ),
                table("areaTex", Filter::Bilinear, 4.0),
                table("searchTex", Filter::Point, 4.0),
            ],
            alu: alu_estimate(WEIGHTS_SHADER, &loop_trips(self.preset)),
            ..Default::default()
        };
        let (pipeline, set) = (&self.weights_pipeline, self.sets[1]);
        let push = WeightsPush::of(self.preset);
        Pass::new("smaa weights", PassRole::Post)
            .sampled(self.edges)
            .color(ColorTarget::new(self.weights, Load::Clear([0.0; 4])))
            .depth_stencil(DepthStencil::test_only(self.stencil).stencil_test(Some(STENCIL_EDGE)))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, pipeline, &[set], |c, cmd| pipeline.push(c, cmd, &push))
            })
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

    // The high preset's bound is the one declared before presets (114), and
    // the presets' bounds rise with their steps.
    #[test]
    fn the_weights_bound_follows_the_preset() {
        assert_eq!(weights_bilinear_bound(DEFAULT_PRESET), 114.0);
        assert_eq!(loop_trips(DEFAULT_PRESET), [8, 8, 8, 8, 16, 16, 16, 16]);
        assert_eq!(weights_bilinear_bound(Preset::Low), 20.0);
        assert_eq!(weights_bilinear_bound(Preset::Medium), 36.0);
        assert_eq!(weights_bilinear_bound(Preset::Ultra), 210.0);
        let p = WeightsPush::of(Preset::High);
        assert_eq!(
            (p.max_search_steps, p.max_search_steps_diag, p.corners),
            (16, 8, 1)
        );
        assert_eq!(p.corner_rounding, 0.25);
        let p = WeightsPush::of(Preset::Low);
        assert_eq!(
            (p.max_search_steps, p.max_search_steps_diag, p.corners),
            (4, 0, 0)
        );
    }

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
