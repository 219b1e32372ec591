//! SMAA 1x (thesis ch. 10.4.1-10.4.2): the variant of the morphological
//! stage (`morphological.rs`) with the preset `--smaa-preset` names (default
//! high), three passes on the tone-mapped frame.
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

use ash::vk;

use super::morphological::{BlendOn, EdgeInput, Spec, Table, Variant};
use super::{rg8_as_rgba8, EdgeSource, PostSetup};
use crate::aa::edges::Preset;
use crate::aa::{smaa_area, smaa_search};
use crate::graph::work::Filter;
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

pub const EDGES_SHADER: &str = "smaa_edges.frag";
pub const EDGES_COLOR_SHADER: &str = "smaa_edges_color.frag";
pub const WEIGHTS_SHADER: &str = "smaa_weights.frag";
pub const BLEND_SHADER: &str = "smaa_blend.frag";
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
    last: [i32; 2],
}

/// SMAA as the stage runs it: the preset and luma or colour edges.
pub struct Smaa {
    preset: Preset,
    color: bool,
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
    /// The variant the options of `s` ask for (`--smaa-preset`, `--aa-edges
    /// luma|color`).
    pub fn new(s: &PostSetup) -> Self {
        Smaa {
            preset: s.options.smaa_preset(),
            color: s.options.edges() == EdgeSource::Color,
        }
    }
}

impl Variant for Smaa {
    /// Pass 1: every pixel fetches itself, left and top; pixels kept also
    /// right, bottom and the two beyond left and top. Pass 2, pixels with an
    /// edgel only: per edgel the diagonal searches or the orthogonal ones
    /// (`weights_bilinear_bound`), up to four area and four search fetches.
    /// Pass 3, every pixel: two bilinear colour fetches where a weight is set.
    fn spec(&self) -> Spec {
        Spec {
            name: "smaa",
            edges_shader: if self.color {
                EDGES_COLOR_SHADER
            } else {
                EDGES_SHADER
            },
            edges_input: EdgeInput::Frame,
            edges_fetches: (3.0, 4.0),
            weights_shader: WEIGHTS_SHADER,
            weights_bilinear: weights_bilinear_bound(self.preset),
            weights_loops: loop_trips(self.preset).to_vec(),
            tables: vec![
                Table {
                    name: "smaa area",
                    binding: "areaTex",
                    extent: vk::Extent2D {
                        width: smaa_area::WIDTH as u32,
                        height: smaa_area::HEIGHT as u32,
                    },
                    rgba8: area_rgba8(),
                    filter: Filter::Bilinear,
                    count: 4.0,
                },
                Table {
                    name: "smaa search",
                    binding: "searchTex",
                    extent: vk::Extent2D {
                        width: smaa_search::WIDTH as u32,
                        height: smaa_search::HEIGHT as u32,
                    },
                    rgba8: search_rgba8(),
                    filter: Filter::Point,
                    count: 4.0,
                },
            ],
            blend_shader: BLEND_SHADER,
            blend_on: BlendOn::Every,
            blend_taps: 2.0,
        }
    }

    fn push_edges(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pipeline: &Pipeline,
        last: [i32; 2],
    ) {
        let push = EdgesPush {
            threshold: self.preset.threshold(),
            adaptation: LOCAL_CONTRAST_FACTOR,
            last,
        };
        pipeline.push(ctx, cmd, &push);
    }

    fn push_weights(&self, ctx: &Context, cmd: vk::CommandBuffer, pipeline: &Pipeline) {
        pipeline.push(ctx, cmd, &WeightsPush::of(self.preset));
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
