//! The compute path's skin tiles: the classification that lists, for one
//! method instance (one group of a mixed frame), the `SSS_TILE_SIDE`-square
//! tiles holding a pixel of its stencil code, and the indirect dispatch of
//! the blurs over that list only. The list is the compute path's early
//! culling, as the stencil test is the fragment path's (HDRP's coarse
//! stencil, Unreal's tile lists, `../shared/docs/ANCHORS.md`).
//!
//! Two passes a frame: `sss tiles reset` zeroes the dispatch's arguments
//! (`vkCmdFillBuffer`), `sss tiles` runs one workgroup per tile of the SSS
//! region's bounding box (the region is the fragment path's too: every skin
//! pixel lies in it) and appends each tile that holds skin. A blur then
//! dispatches one workgroup per listed tile (`vkCmdDispatchIndirect`). ssg
//! asks for one list per Gaussian, each of the tiles holding skin nearer
//! than that Gaussian's LOD depth ([`SkinTiles::by_depth`]): its depth-based
//! Gaussian skipping, per tile.
//!
//! Why no seed copy: the fragment path copies the diffuse target into its
//! intermediate so that the vertical pass's taps find the diffuse light at
//! texels that are not this group's skin. The compute blurs read the
//! stencil they load anyway and take the diffuse target there instead
//! (separable_blur.comp), so the copy (0.157 ms of the 1.656 ms separable
//! SSS at 1080p on the H100) has no counterpart.
//!
//! A blur whose taps read the diffuse target (ss-jittered, poisson) cannot
//! write it in the same dispatch (a workgroup would read texels another has
//! written): it writes an intermediate at skin pixels, and `sss merge`
//! copies those pixels into the diffuse target (16 bytes a skin pixel,
//! against the fragment path's seed copy of the whole region).
//!
//! Where the two paths differ: each tap filters its two texels in shared
//! memory in float, at the fraction the sampler computes, and the sums are
//! the fragment shader's, in its order. On lavapipe, whose sampler filters
//! half-float texels in float, the images agree within one half-float ulp
//! (the rounding of the filter's products and of the stores; most pixels
//! bit for bit: tests/suite/compute.rs). A sampler that rounds its filter
//! fraction to `subTexelPrecisionBits` (8 on NVIDIA) is less exact than the
//! compute path: there the fragment image differs by up to 2^-9 of the
//! contrast between neighbouring texels per tap, the fragment path's error,
//! not the compute path's.

use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::screen::fetch_at_most;
use super::{FrameView, MethodBind, MethodSetup};
use crate::graph::work::{Filter, PassRole, ShaderWork, Work};
use crate::graph::{Binding, BufferId, GraphSet, Pass, PassContext, Storage};
use crate::shader_constants::{SSS_MAX_TILE_LISTS, SSS_TILE_SIDE};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::Pipeline;
use crate::vk::shader_stats::alu_estimate;

const SHADER: &str = "tiles_classify.comp";
const MERGE_SHADER: &str = "tiles_merge.comp";

/// Invocations of one tile's workgroup.
pub const TILE_INVOCATIONS: u32 = SSS_TILE_SIDE * SSS_TILE_SIDE;

/// The tiles the rectangles of `region` touch, as the bounding box's first
/// tile and its size in tiles; `None` when the region is empty.
pub fn region_tiles(region: &[vk::Rect2D]) -> Option<([u32; 2], [u32; 2])> {
    let side = SSS_TILE_SIDE;
    let mut lo = [u32::MAX; 2];
    let mut hi = [0u32; 2];
    for r in region
        .iter()
        .filter(|r| r.extent.width > 0 && r.extent.height > 0)
    {
        let (x, y) = (r.offset.x.max(0) as u32, r.offset.y.max(0) as u32);
        lo = [lo[0].min(x / side), lo[1].min(y / side)];
        hi = [
            hi[0].max((x + r.extent.width).div_ceil(side)),
            hi[1].max((y + r.extent.height).div_ceil(side)),
        ];
    }
    (lo[0] < hi[0]).then(|| (lo, [hi[0] - lo[0], hi[1] - lo[1]]))
}

/// The tiles of a `width x height` mask holding a `true`: what the
/// classification lists (tests predict the GPU's count with it).
pub fn skin_tiles(mask: &[bool], width: usize, height: usize) -> usize {
    let side = SSS_TILE_SIDE as usize;
    let mut n = 0;
    for ty in 0..height.div_ceil(side) {
        for tx in 0..width.div_ceil(side) {
            let any = (ty * side..((ty + 1) * side).min(height))
                .any(|y| (tx * side..((tx + 1) * side).min(width)).any(|x| mask[y * width + x]));
            n += any as usize;
        }
    }
    n
}

/// Push constants of tiles_classify.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TilesPush {
    first_tile: [i32; 2],
    code: u32,
    lists: u32,
    capacity: u32,
    max_depth: [f32; SSS_MAX_TILE_LISTS],
}

/// A depth bound every depth-buffer value passes (values lie in 0..=1).
pub const EVERY_DEPTH: f32 = 2.0;

/// One instance's tile list: the classification's pipeline, the indirect
/// arguments and the list (tracked buffers: their barriers are derived).
#[derive(Default)]
pub struct SkinTiles {
    pipeline: Pipeline,
    args: Buffer,
    list: Buffer,
    args_id: BufferId,
    list_id: BufferId,
    set: GraphSet,
    /// Tiles of the whole frame: each list's capacity and the blurs' bound.
    capacity: u32,
    /// Entries from one list's start to the next: the capacity rounded up to
    /// 256 bytes, the largest `minStorageBufferOffsetAlignment` Vulkan
    /// allows (each blur binds its list at its start).
    stride: u32,
    /// List k takes the skin tiles with a depth-buffer value under
    /// `max_depth[k]` ([`EVERY_DEPTH`]: all of them).
    max_depth: Vec<f32>,
    /// The merge of a blur's intermediate into the diffuse target, where
    /// the method asked for one ([`SkinTiles::add_merge`]).
    merge: Option<(Pipeline, GraphSet)>,
}

impl SkinTiles {
    /// One list of every skin tile.
    pub fn new(s: &mut MethodSetup) -> Result<Self> {
        Self::by_depth(s, &[EVERY_DEPTH])
    }

    /// One list per bound of `max_depth` (at most `SSS_MAX_TILE_LISTS`):
    /// list k takes the skin tiles holding a depth-buffer value under
    /// `max_depth[k]`.
    pub fn by_depth(s: &mut MethodSetup, max_depth: &[f32]) -> Result<Self> {
        assert!(
            (1..=SSS_MAX_TILE_LISTS).contains(&max_depth.len()),
            "{} tile lists",
            max_depth.len()
        );
        let e = s.view.extent;
        let capacity = e.width.div_ceil(SSS_TILE_SIDE) * e.height.div_ceil(SSS_TILE_SIDE);
        let lists = max_depth.len() as u64;
        let stride = capacity.next_multiple_of(64);
        // Filled step by step: on an error the guard frees what exists.
        let mut t = Guard::new(
            s.ctx,
            SkinTiles {
                capacity,
                stride,
                max_depth: max_depth.to_vec(),
                ..Default::default()
            },
        );
        t.pipeline = Pipeline::compute(s.ctx, "sss tiles", SHADER)?;
        use vk::BufferUsageFlags as U;
        t.args = Buffer::new(
            s.ctx,
            "sss tile args",
            16 * lists,
            U::STORAGE_BUFFER | U::INDIRECT_BUFFER | U::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        t.list = Buffer::new(
            s.ctx,
            "sss tile list",
            4 * stride as u64 * lists,
            U::STORAGE_BUFFER,
            MemoryLocation::GpuOnly,
        )?;
        t.args_id = s.res.add_buffer("sss tile args", t.args.raw);
        t.list_id = s.res.add_buffer("sss tile list", t.list.raw);
        t.set = GraphSet::new(
            s.res,
            &t.pipeline,
            0,
            vec![
                (
                    "stencilTex",
                    Binding::SampledStencil(s.targets.depth_stencil),
                ),
                ("depthTex", Binding::SampledDepth(s.targets.depth_stencil)),
                (
                    "Args",
                    Binding::StorageBuffer {
                        id: t.args_id,
                        offset: 0,
                        size: 16 * lists,
                        storage: Storage::ReadWrite,
                    },
                ),
                (
                    "Tiles",
                    Binding::StorageBuffer {
                        id: t.list_id,
                        offset: 0,
                        size: 4 * stride as u64 * lists,
                        storage: Storage::Write,
                    },
                ),
            ],
        );
        Ok(t.keep())
    }

    /// Adds the merge of `src` (a blur's output at skin pixels) into `dst`
    /// (on an error, what exists is the caller's to destroy: hold the tiles
    /// in a guard).
    pub fn add_merge(
        &mut self,
        s: &MethodSetup,
        src: crate::graph::ImageId,
        dst: crate::graph::ImageId,
    ) -> Result<()> {
        let pipeline = Guard::new(s.ctx, Pipeline::compute(s.ctx, "sss merge", MERGE_SHADER)?);
        let set = GraphSet::new(
            s.res,
            &pipeline,
            0,
            vec![
                (
                    "stencilTex",
                    Binding::SampledStencil(s.targets.depth_stencil),
                ),
                ("Tiles", self.list_binding(Storage::Read, 0)),
                ("srcTex", Binding::Sampled(src)),
                // Written at skin pixels only: the rest keeps the diffuse light.
                ("outImage", Binding::StorageImage(dst, Storage::ReadWrite)),
            ],
        );
        self.merge = Some((pipeline.keep(), set));
        Ok(())
    }

    /// The merge pass (after the blur that wrote its source).
    pub fn merge_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Option<Pass<'a>> {
        let (pipeline, set) = self.merge.as_ref()?;
        let t = f.targets;
        let work = ShaderWork {
            shader: MERGE_SHADER.into(),
            fetches: vec![
                fetch_at_most(f.res, t.depth_stencil, "stencilTex", Filter::Point, 1.0),
                fetch_at_most(f.res, t.diffuse, "srcTex", Filter::Point, 1.0),
            ],
            alu: alu_estimate(MERGE_SHADER, &[]),
            storage_read_bytes: 4.0 / TILE_INVOCATIONS as f64,
            storage_write_bytes: 8.0,
            shared_bytes: 0.0,
        };
        Some(self.pass("sss merge", f, 0, work, pipeline, set, f.stencil))
    }

    /// The list as a blur's set binds it (`Tiles`).
    pub fn list_binding(&self, storage: Storage, k: usize) -> Binding {
        Binding::StorageBuffer {
            id: self.list_id,
            offset: 4 * self.stride as u64 * k as u64,
            size: 4 * self.capacity as u64,
            storage,
        }
    }

    /// The reset and the classification of this frame.
    pub fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> [Pass<'a>; 2] {
        let mut reset = Pass::new("sss tiles reset", PassRole::Sss);
        let args = reset.transfer_dst_buffer(self.args_id);
        // A fill of the four argument words: priced as a clear of four
        // 4-byte texels (the work vocabulary's nearest kind; it is tiny).
        let reset = reset
            .work(Work::Clear {
                texels: 4 * self.max_depth.len() as u64,
                bytes_per_texel: 4,
            })
            .record(move |pc: &PassContext| pc.fill_buffer(args, 0));

        let (first, groups) = region_tiles(f.region).unwrap_or(([0, 0], [0, 0]));
        let work = ShaderWork {
            shader: SHADER.into(),
            // Invocations outside the image fetch nothing, and only skin
            // pixels read their depth.
            fetches: ["stencilTex", "depthTex"]
                .map(|texture| {
                    fetch_at_most(f.res, f.targets.depth_stencil, texture, Filter::Point, 1.0)
                })
                .to_vec(),
            alu: alu_estimate(SHADER, &[self.max_depth.len() as u32; 2]),
            // One tile in a workgroup appends itself (and its count).
            storage_read_bytes: 0.0,
            storage_write_bytes: 8.0 / TILE_INVOCATIONS as f64,
            shared_bytes: 0.0,
        };
        let mut max_depth = [EVERY_DEPTH; SSS_MAX_TILE_LISTS];
        max_depth[..self.max_depth.len()].copy_from_slice(&self.max_depth);
        let push = TilesPush {
            first_tile: [first[0] as i32, first[1] as i32],
            code: f.stencil,
            lists: self.max_depth.len() as u32,
            capacity: self.stride,
            max_depth,
        };
        let mut classify = Pass::new("sss tiles", PassRole::Sss);
        let set = classify.set(&self.set);
        let classify = classify
            .dispatch(work, [groups[0], groups[1], 1], TILE_INVOCATIONS)
            .record(move |pc: &PassContext| {
                pc.bind(&self.pipeline, &[set]);
                self.pipeline.push(pc.ctx, pc.cmd, &push);
            });
        [reset, classify]
    }

    /// The pass `name` of a dispatch over list `k`, the one declaration of
    /// every compute blur and merge: it declares `set`, binds `pipeline`,
    /// pushes `push`, and dispatches from the list's indirect arguments,
    /// its work counted at their bound (every tile of the region's box).
    // Every argument is one fact of the pass that differs between callers.
    #[allow(clippy::too_many_arguments)]
    pub fn pass<'a, P: bytemuck::Pod>(
        &self,
        name: impl Into<String>,
        f: &FrameView,
        k: usize,
        work: ShaderWork,
        pipeline: &'a Pipeline,
        set: &GraphSet,
        push: P,
    ) -> Pass<'a> {
        let most = region_tiles(f.region).map_or(0, |(_, n)| n[0] * n[1]);
        let mut pass = Pass::new(name, PassRole::Sss);
        let set = pass.set(set);
        pass.dispatch_indirect(
            work,
            (self.args_id, 16 * k as u64),
            [most, 1, 1],
            TILE_INVOCATIONS,
        )
        .record(move |pc: &PassContext| {
            pc.bind(pipeline, &[set]);
            pipeline.push(pc.ctx, pc.cmd, &push);
        })
    }

    pub fn bind(&mut self, b: &MethodBind) -> Result<()> {
        b.write(&mut self.set, &self.pipeline)?;
        if let Some((pipeline, set)) = &mut self.merge {
            b.write(set, pipeline)?;
        }
        Ok(())
    }
}

impl Destroy for SkinTiles {
    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.args.destroy(ctx);
        self.list.destroy(ctx);
        if let Some((p, _)) = &mut self.merge {
            p.destroy(ctx);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x: i32, y: i32, w: u32, h: u32) -> vk::Rect2D {
        vk::Rect2D {
            offset: vk::Offset2D { x, y },
            extent: vk::Extent2D {
                width: w,
                height: h,
            },
        }
    }

    #[test]
    fn the_region_box_in_tiles() {
        assert_eq!(region_tiles(&[]), None);
        assert_eq!(region_tiles(&[rect(0, 0, 0, 5)]), None);
        // 17..=40 in x touches tiles 1 and 2; 0..=15 in y tile 0.
        assert_eq!(region_tiles(&[rect(17, 0, 24, 16)]), Some(([1, 0], [2, 1])));
        // Two rectangles: their box.
        assert_eq!(
            region_tiles(&[rect(0, 40, 8, 8), rect(50, 0, 20, 10)]),
            Some(([0, 0], [5, 3]))
        );
    }

    #[test]
    fn skin_tiles_count_tiles_with_any_pixel() {
        let (w, h) = (40, 20);
        let mut m = vec![false; w * h];
        assert_eq!(skin_tiles(&m, w, h), 0);
        m[0] = true; // tile (0,0)
        m[19 * w + 39] = true; // the partial corner tile (2,1)
        m[5 * w + 17] = true; // tile (1,0)
        m[6 * w + 18] = true; // the same tile
        assert_eq!(skin_tiles(&m, w, h), 3);
    }
}
