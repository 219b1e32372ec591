//! Jimenez's MLAA (thesis ch. 9): the variant of the morphological stage
//! (`morphological.rs`) with three passes on the tone-mapped frame and a copy:
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

use ash::vk;

use super::morphological::{BlendOn, EdgeInput, Spec, Table, Variant};
use super::{rg8_as_rgba8, EdgeSource, PostSetup};
use crate::aa::edges::{MLAA_DEPTH_THRESHOLD_MM, MLAA_LUMA_THRESHOLD};
use crate::aa::mlaa_area::{MlaaAreaTex, AREA_SIZE, MAX_DISTANCE, NUM_DISTANCES};
use crate::graph::work::Filter;
use crate::shader_constants::{MLAA_MAX_SEARCH_STEPS, MLAA_NUM_DISTANCES};
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

pub const EDGES_SHADER: &str = "mlaa_edges.frag";
pub const EDGES_DEPTH_SHADER: &str = "mlaa_edges_depth.frag";
pub const WEIGHTS_SHADER: &str = "mlaa_weights.frag";
pub const BLEND_SHADER: &str = "mlaa_blend.frag";
/// The distance searches' reach in pixels each way: 2 per fetch.
pub const SEARCH_DISTANCE: usize = 2 * MLAA_MAX_SEARCH_STEPS as usize;

// The shader's constants and the area texture's layout are one fact.
const _: () = assert!(MLAA_NUM_DISTANCES as usize == NUM_DISTANCES);
const _: () = assert!(SEARCH_DISTANCE == MAX_DISTANCE);
const _: () = assert!(MLAA_MAX_SEARCH_STEPS as usize == crate::aa::mlaa_weights::MAX_SEARCH_STEPS);
// The reach is the Xbox 360's tfetch2D offset (ch. 9.4.1; the constant's doc).
const _: () =
    assert!(SEARCH_DISTANCE as i32 == -crate::aa::mlaa_area::XBOX360_TFETCH2D_MIN_OFFSET_PX);
// The edges target has the Xbox 360's four channels (the stage's tables are RGBA8).
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
    /// std430 puts the ivec2 at offset 8.
    pad: f32,
    last: [i32; 2],
}

/// MLAA as the stage runs it: luma or depth edges and their threshold.
pub struct Mlaa {
    depth_edges: bool,
    threshold: f32,
}

/// The area texture as RGBA8 bytes: `MlaaAreaTex::rg8` in .rg, zeros in .ba.
pub fn area_rgba8() -> Vec<u8> {
    rg8_as_rgba8(&MlaaAreaTex::generate().rg8())
}

impl Mlaa {
    /// The variant the options of `s` ask for (`--aa-edges luma|depth`).
    pub fn new(s: &PostSetup) -> Self {
        match s.options.edges() {
            EdgeSource::Depth => Mlaa {
                depth_edges: true,
                threshold: depth_threshold(s.mm_per_unit),
            },
            _ => Mlaa {
                depth_edges: false,
                threshold: MLAA_LUMA_THRESHOLD,
            },
        }
    }
}

impl Variant for Mlaa {
    /// Pass 1 fetches the pixel and its four neighbours; pass 2 per edgel two
    /// searches of at most `MLAA_MAX_SEARCH_STEPS` bilinear fetches, two
    /// crossing-edge fetches and one area fetch; pass 3 (edge pixels only)
    /// four bilinear colour fetches, one per neighbour.
    fn spec(&self) -> Spec {
        let steps = MLAA_MAX_SEARCH_STEPS;
        let per_edgel = 2.0 * f64::from(steps) + 2.0;
        let side = AREA_SIZE as u32;
        Spec {
            name: "mlaa",
            edges_shader: if self.depth_edges {
                EDGES_DEPTH_SHADER
            } else {
                EDGES_SHADER
            },
            edges_input: if self.depth_edges {
                EdgeInput::Depth
            } else {
                EdgeInput::Frame
            },
            edges_fetches: (5.0, 0.0),
            weights_shader: WEIGHTS_SHADER,
            weights_bilinear: 2.0 * per_edgel,
            // Four searches (two per edgel), each loop at most `steps` trips.
            weights_loops: vec![steps; 4],
            tables: vec![Table {
                name: "mlaa area",
                binding: "areaTex",
                extent: vk::Extent2D {
                    width: side,
                    height: side,
                },
                rgba8: area_rgba8(),
                filter: Filter::Point,
                count: 2.0,
            }],
            blend_shader: BLEND_SHADER,
            blend_on: BlendOn::Edges,
            blend_taps: 4.0,
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
            threshold: self.threshold,
            pad: 0.0,
            last,
        };
        pipeline.push(ctx, cmd, &push);
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
