//! The ground truth as a method of the frame (`--method reference`): the diffuse
//! radiant exitance M(x_o) = integral E(x_i) R(|x_i - x_o|) dA over the actual skin
//! surface, by brute force on the GPU. Two steps: the diffuse radiance of every
//! surface sample, lit by the geometry pass's own shading code (a fragment pass
//! over images with one texel per sample, so the shadow test is the same
//! hardware compare), then compute passes that sum, for every skin pixel, all
//! samples within the cut-off, found with a uniform grid. The geometry pass runs
//! with transmittance off for this method: light through thin parts arrives
//! through the integral itself, because samples on the far side of an ear are as
//! close in 3D as they really are.
//!
//! The sample set is split into chunks of whole radiance rows so that every
//! binding stays within the device's storage-buffer range and every radiance
//! image within its largest image: the default density works on any conforming
//! device, at any head count its memory holds. The pure parts (sampling, grid,
//! profile split, an f64 CPU gather) are in `crate::reference`.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::region::ReachScale;
use super::screen::fetch;
use super::{
    FrameView, MethodBind, MethodEntry, MethodSetup, Needs, OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::draw::{begin_rendering, Load};
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork, Work};
use crate::graph::{BufferId, ImageDesc, ImageId, Pass, PassContext};
use crate::reference::sampling::{
    build_grid, cutoff_mm, sample_surface_within, Grid, SurfaceSample,
};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload::device_buffer;

const IRRADIANCE_SHADER: &str = "reference_irradiance.frag";
const GATHER_SHADER: &str = "reference_gather.comp";
/// Width of the radiance images: sample i of a chunk is texel (i % width, i / width).
pub const RADIANCE_WIDTH: u32 = 2048;
/// Workgroup side of the gather (reference_gather.comp's local size).
const GROUP: u32 = 8;
/// The gather's 3x3x3 cell neighbourhood runs as 9 dispatches of one row of 3
/// cells each: llvmpipe cuts shader loops after 65,535 iterations.
const SLABS: i32 = 9;

const OPTIONS: &[OptSpec] = &[OptSpec {
    key: "density",
    kind: OptKind::Value,
    default: "32",
    help: "surface samples per mm^2, within (0, 256] (32 is converged: doubling it changes the image by 5e-4 relative RMSE)",
}];

pub static ENTRY: MethodEntry = MethodEntry {
    name: "reference",
    aliases: &["ground-truth"],
    summary: "the ground truth: brute-force integral of the profile over the skin surface",
    options: OPTIONS,
    eval: &[],
    ground_truth: true,
    needs: |_, _| Needs {
        geometry_transmittance: false,
        ..Needs::PLAIN
    },
    check: |o| density(o).map(|_| ()),
    build: |s| Ok(Box::new(Reference::new(s)?)),
};

fn density(o: &Opts) -> Result<f32> {
    let d: f32 = o.parse("density")?;
    if !(d > 0.0 && d <= 256.0) {
        bail!("--density must be within (0, 256] samples per mm^2, got {d}");
    }
    Ok(d)
}

/// std140 layout of `GatherParams` (reference_gather.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherParams {
    inv_view: [[f32; 4]; 4],
    grid_origin: [f32; 4],
    grid_dims: [u32; 4],
    view: [f32; 4],
}

/// Push constants of the gather: the slab, and the chunk's range of samples.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherPush {
    dy: i32,
    dz: i32,
    first: u32,
    count: u32,
}

/// The device limits the split follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChunkLimits {
    /// maxStorageBufferRange, bytes.
    pub storage_range: u64,
    /// maxImageDimension2D.
    pub max_image_dimension: u32,
}

/// How the samples are split.
#[derive(Clone, Debug, PartialEq)]
pub struct ChunkPlan {
    /// (first sample, count) of each gather chunk: positions bound whole,
    /// radiance image of `count.div_ceil(RADIANCE_WIDTH)` rows.
    pub chunks: Vec<(u32, u32)>,
    /// Samples per draw of the radiance pass (its 64-byte samples bound by range).
    pub draw_samples: u32,
}

/// Splits `count` samples into chunks of whole radiance rows within `limits`.
pub fn plan_chunks(count: u32, limits: ChunkLimits) -> Result<ChunkPlan> {
    let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
    let rows_by =
        |bytes_per_sample: u64| limits.storage_range / (bytes_per_sample * RADIANCE_WIDTH as u64);
    // Positions are vec4 (16 bytes) read by the gather; samples 64 bytes read
    // by the radiance pass, one range per draw.
    let chunk_rows = rows_by(16).min(limits.max_image_dimension as u64);
    let draw_rows = rows_by(sample_bytes);
    if chunk_rows == 0 || draw_rows == 0 {
        bail!(
            "this device's storage-buffer range ({} bytes) cannot hold one row of {RADIANCE_WIDTH} reference samples",
            limits.storage_range
        );
    }
    let per_chunk = (chunk_rows * RADIANCE_WIDTH as u64).min(u32::MAX as u64) as u32;
    let mut chunks = Vec::new();
    let mut first = 0u32;
    while first < count {
        let n = (count - first).min(per_chunk);
        chunks.push((first, n));
        first += n;
    }
    Ok(ChunkPlan {
        chunks,
        draw_samples: (draw_rows * RADIANCE_WIDTH as u64).min(u32::MAX as u64) as u32,
    })
}

/// The most samples one gather invocation visits in one slab: the largest sum of
/// the counts of a row of 3 neighbouring cells (an upper bound of its radiance
/// fetches, which are the visited samples within the cut-off).
fn max_slab_candidates(grid: &Grid) -> u32 {
    let [nx, ny, nz] = grid.dims.map(|d| d as i64);
    let count = |x: i64, y: i64, z: i64| -> u32 {
        if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
            return 0;
        }
        let i = ((z * ny + y) * nx + x) as usize;
        grid.cell_start[i + 1] - grid.cell_start[i]
    };
    let mut best = 0;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                best = best.max(count(x - 1, y, z) + count(x, y, z) + count(x + 1, y, z));
            }
        }
    }
    best
}

/// One chunk: its samples' buffers and radiance image, and its sets.
struct Chunk {
    first: u32,
    count: u32,
    samples: Buffer,
    positions: Buffer,
    buffer_ids: [BufferId; 2],
    radiance: ImageId,
    /// (set, first sample of the draw within the chunk, samples) per draw.
    draws: Vec<(vk::DescriptorSet, u32, u32)>,
    gather_set: vk::DescriptorSet,
}

impl Destroy for Chunk {
    fn destroy(&mut self, ctx: &Context) {
        self.samples.destroy(ctx);
        self.positions.destroy(ctx);
    }
}

pub struct Reference {
    irradiance: Pipeline,
    gather: Pipeline,
    material_set: vk::DescriptorSet,
    chunks: Vec<Chunk>,
    draw_samples: u32,
    cells: Buffer,
    cells_id: BufferId,
    params: Buffer,
    out: ImageId,
    max_candidates: u32,
    pub sample_count: u32,
    pub grid: Grid,
    /// The samples in grid order (for CPU checks).
    pub surface: Vec<SurfaceSample>,
    pub density: f32,
}

impl Reference {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let density = density(&s.options)?;
        let mm = s.view.mm_per_unit;
        let skin = [&s.scene.head]
            .into_iter()
            .chain(s.scene.backdrop.iter())
            .find(|o| o.material.skin);
        let Some(skin) = skin else {
            bail!("the reference found no skin surface to sample");
        };
        let budget = s.ctx.facts.device_local_bytes / 2 / 96; // 96 B a sample (below)
        let mut surface = sample_surface_within(&skin.mesh, s.instances, mm, density, budget)?;
        if surface.is_empty() {
            bail!("the reference found no skin surface to sample");
        }
        let grid = build_grid(&mut surface, cutoff_mm() / mm);
        let count = surface.len() as u32;
        let f = &s.ctx.facts;
        let plan = plan_chunks(
            count,
            ChunkLimits {
                storage_range: f.max_storage_buffer_range as u64,
                max_image_dimension: f.max_image_dimension_2d,
            },
        )?;
        // Samples (64 B), positions (16 B) and radiance (16 B) per sample.
        let need = count as u64 * 96;
        if need > f.device_local_bytes / 2 {
            bail!(
                "{count} reference samples ({:.1} GB at {density} per mm^2) are more than half of this device's memory ({:.1} GB); lower --density or the number of heads",
                need as f64 / 1e9,
                f.device_local_bytes as f64 / 1e9
            );
        }
        let cells_bytes = grid.cell_start.len() as u64 * 4;
        if cells_bytes > f.max_storage_buffer_range as u64 {
            bail!("the reference grid has {} cells, more than this device's storage-buffer range holds", grid.cell_start.len());
        }
        let irradiance = Pipeline::graphics(
            s.ctx,
            &GraphicsDesc::fullscreen(
                "reference irradiance",
                IRRADIANCE_SHADER,
                vk::Format::R32G32B32A32_SFLOAT,
            ),
        )?;
        let irradiance = Guard::new(s.ctx, irradiance); // freed if a later step fails
        let gather = Pipeline::compute(s.ctx, "reference gather", GATHER_SHADER)?;
        let gather = Guard::new(s.ctx, gather);
        let cam = &s.view.camera;
        let p = GatherParams {
            inv_view: cam.view().inverse().to_cols_array_2d(),
            grid_origin: grid.origin.extend(grid.cell).to_array(),
            grid_dims: [grid.dims[0], grid.dims[1], grid.dims[2], RADIANCE_WIDTH],
            view: [s.view.tan_half_fovy(), s.view.aspect(), mm, cutoff_mm()],
        };
        let params = Buffer::with_data(
            s.ctx,
            "reference gather params",
            bytemuck::bytes_of(&p),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let params = Guard::new(s.ctx, params);
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let cells = device_buffer(
            s.ctx,
            "reference grid cells",
            bytemuck::cast_slice(&grid.cell_start),
            storage,
            AccessKind::ComputeStorageRead,
        )?;
        let cells = Guard::new(s.ctx, cells);
        let cells_id = s.res.add_buffer("reference grid cells", cells.raw);
        s.res
            .set_buffer_uploaded(cells_id, AccessKind::ComputeStorageRead);
        let one = plan.chunks.len() == 1;
        let mut chunks = Guard::new(s.ctx, Vec::with_capacity(plan.chunks.len()));
        for (k, &(first, n)) in plan.chunks.iter().enumerate() {
            let name = |what: &str| {
                if one {
                    format!("reference {what}")
                } else {
                    format!("reference {what} {}", k + 1)
                }
            };
            let range = &surface[first as usize..(first + n) as usize];
            let samples = device_buffer(
                s.ctx,
                &name("samples"),
                bytemuck::cast_slice(range),
                storage,
                AccessKind::FragmentStorageRead,
            )?;
            let samples = Guard::new(s.ctx, samples);
            let pos: Vec<[f32; 4]> = range.iter().map(|s| s.pos_area).collect();
            let positions = device_buffer(
                s.ctx,
                &name("positions"),
                bytemuck::cast_slice(&pos),
                storage,
                AccessKind::ComputeStorageRead,
            )?;
            let buffer_ids = [
                s.res.add_buffer(&name("samples"), samples.raw),
                s.res.add_buffer(&name("positions"), positions.raw),
            ];
            s.res
                .set_buffer_uploaded(buffer_ids[0], AccessKind::FragmentStorageRead);
            s.res
                .set_buffer_uploaded(buffer_ids[1], AccessKind::ComputeStorageRead);
            let radiance = s.res.declare(ImageDesc::new(
                &name("radiance"),
                vk::Extent2D {
                    width: RADIANCE_WIDTH,
                    height: n.div_ceil(RADIANCE_WIDTH),
                },
                vk::Format::R32G32B32A32_SFLOAT,
            ));
            chunks.push(Chunk {
                first,
                count: n,
                samples: samples.keep(),
                positions,
                buffer_ids,
                radiance,
                draws: Vec::new(),
                gather_set: vk::DescriptorSet::null(),
            });
        }
        let out = s.res.declare(ImageDesc::new(
            "reference",
            s.view.extent,
            vk::Format::R32G32B32A32_SFLOAT,
        ));
        Ok(Reference {
            irradiance: irradiance.keep(),
            gather: gather.keep(),
            material_set: vk::DescriptorSet::null(),
            chunks: chunks.keep(),
            draw_samples: plan.draw_samples,
            max_candidates: max_slab_candidates(&grid),
            cells: cells.keep(),
            cells_id,
            params: params.keep(),
            out,
            sample_count: count,
            grid,
            surface,
            density,
        })
    }

    /// The radiance pass: every chunk's samples lit, one draw per range.
    fn irradiance_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let lit = "reference_irradiance.frag";
        let shader = ShaderWork {
            shader: lit.into(),
            // The texels past the last sample of a chunk's last row return
            // before shading: every count is a bound.
            fetches: vec![
                Fetch {
                    exact: false,
                    ..fetch(
                        f.res,
                        f.targets.shadow,
                        "shadowMap",
                        Filter::DepthCompare,
                        9.0,
                    )
                },
                // Material textures are not frame images: RGBA8 bilinear.
                material_fetch("normalTex"),
                material_fetch("albedoTex"),
            ],
            alu: alu_estimate(lit, &[3, 3]),
            storage_read_bytes: std::mem::size_of::<SurfaceSample>() as f64,
            storage_write_bytes: 0.0,
        };
        let texels: u64 = self
            .chunks
            .iter()
            .map(|c| c.count.div_ceil(RADIANCE_WIDTH) as u64 * RADIANCE_WIDTH as u64)
            .sum();
        let draws: u64 = self
            .chunks
            .iter()
            .map(|c| c.count.div_ceil(self.draw_samples) as u64)
            .sum();
        let mut pass = Pass::new("reference irradiance", PassRole::Sss)
            .image(f.targets.shadow, AccessKind::FragmentSampledRead)
            .work(Work::Raster {
                shader: Some(shader),
                color: vec![crate::graph::work::ColorWrite {
                    format: Format::Rgba32Float,
                    blend: false,
                }],
                depth_stencil: None,
                width: RADIANCE_WIDTH,
                height: (texels / RADIANCE_WIDTH as u64) as u32,
                triangles: draws,
                msaa: 1,
            });
        for c in &self.chunks {
            pass = pass
                .buffer(c.buffer_ids[0], AccessKind::FragmentStorageRead)
                .image(c.radiance, AccessKind::ColorAttachmentWrite);
        }
        pass.record(move |pc: &PassContext| {
            let (ctx, cmd) = (pc.ctx, pc.cmd);
            for c in &self.chunks {
                begin_rendering(pc, &[(c.radiance, Load::Discard)], None);
                let p = &self.irradiance;
                p.bind(ctx, cmd, &[]);
                p.bind_sets(ctx, cmd, 1, &[self.material_set]);
                for &(set, first, n) in &c.draws {
                    let first_row = first / RADIANCE_WIDTH;
                    let scissor = vk::Rect2D {
                        offset: vk::Offset2D {
                            x: 0,
                            y: first_row as i32,
                        },
                        extent: vk::Extent2D {
                            width: RADIANCE_WIDTH,
                            height: n.div_ceil(RADIANCE_WIDTH),
                        },
                    };
                    p.bind_sets(ctx, cmd, 0, &[set]);
                    unsafe { ctx.device.cmd_set_scissor(cmd, 0, &[scissor]) };
                    p.push(ctx, cmd, &[n, RADIANCE_WIDTH, first_row]);
                    unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
                }
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            }
        })
    }
}

/// At most one fetch of a skin material's RGBA8 texture (bilinear, level 0).
fn material_fetch(texture: &str) -> Fetch {
    Fetch {
        texture: texture.into(),
        format: Format::Rgba8Unorm,
        filter: Filter::Bilinear,
        count: 1.0,
        exact: false,
    }
}

impl SssMethod for Reference {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let t = f.targets;
        let mut passes = vec![self.irradiance_pass(f)];
        let extent = f.extent;
        let groups = (extent.width.div_ceil(GROUP), extent.height.div_ceil(GROUP));
        let invocations = (groups.0 * groups.1 * GROUP * GROUP) as u64;
        let one = self.chunks.len() == 1;
        let out = self.out;
        for (ci, c) in self.chunks.iter().enumerate() {
            for k in 0..SLABS {
                // The very first dispatch writes the output; the rest add to it.
                let out_access = if ci == 0 && k == 0 {
                    AccessKind::ComputeStorageWrite
                } else {
                    AccessKind::ComputeStorageReadWrite
                };
                let name = if one {
                    format!("reference gather {}/9", k + 1)
                } else {
                    format!(
                        "reference gather chunk {}/{} {}/9",
                        ci + 1,
                        self.chunks.len(),
                        k + 1
                    )
                };
                let candidates = self.max_candidates as f64;
                let work = Work::Compute {
                    shader: ShaderWork {
                        shader: GATHER_SHADER.into(),
                        fetches: vec![
                            fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0),
                            Fetch {
                                exact: false,
                                ..fetch(f.res, t.linear_depth, "depthTex", Filter::Point, 1.0)
                            },
                            Fetch {
                                exact: false,
                                ..fetch(f.res, c.radiance, "radianceTex", Filter::Point, candidates)
                            },
                        ],
                        alu: alu_estimate(GATHER_SHADER, &[3, self.max_candidates.div_ceil(3)]),
                        storage_read_bytes: 16.0 * (1.0 + candidates) + 8.0,
                        storage_write_bytes: 16.0,
                    },
                    invocations,
                };
                let push = GatherPush {
                    dy: k % 3 - 1,
                    dz: k / 3 - 1,
                    first: c.first,
                    count: c.count,
                };
                let set = c.gather_set;
                passes.push(
                    Pass::new(name, PassRole::Sss)
                        .image(t.diffuse, AccessKind::ComputeSampledRead)
                        .image(t.linear_depth, AccessKind::ComputeSampledRead)
                        .image(c.radiance, AccessKind::ComputeSampledRead)
                        .image(out, out_access)
                        .buffer(c.buffer_ids[1], AccessKind::ComputeStorageRead)
                        .buffer(self.cells_id, AccessKind::ComputeStorageRead)
                        .work(work)
                        .record(move |pc: &PassContext| {
                            self.gather.bind(pc.ctx, pc.cmd, &[set]);
                            self.gather.push(pc.ctx, pc.cmd, &push);
                            unsafe { pc.ctx.device.cmd_dispatch(pc.cmd, groups.0, groups.1, 1) };
                        }),
                );
            }
        }
        passes
    }

    fn output(&self) -> ImageId {
        self.out
    }

    /// The reference gathers in compute over the whole screen.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        None
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
        self.material_set = b
            .pool
            .write_set(b.ctx, &self.irradiance, 1, &b.skin_material_binds)?;
        let t = b.targets;
        for c in &mut self.chunks {
            c.draws.clear();
            let mut first = 0;
            while first < c.count {
                let n = (c.count - first).min(self.draw_samples);
                let mut binds = b.frame_binds.clone();
                binds.push((
                    "Samples",
                    Bind::Range {
                        buffer: c.samples.raw,
                        offset: first as u64 * sample_bytes,
                        size: n as u64 * sample_bytes,
                    },
                ));
                c.draws.push((
                    b.pool.write_set(b.ctx, &self.irradiance, 0, &binds)?,
                    first,
                    n,
                ));
                first += n;
            }
            c.gather_set = b.pool.write_set(
                b.ctx,
                &self.gather,
                0,
                &[
                    ("diffuseTex", Bind::Texture(b.res.view(t.diffuse))),
                    ("depthTex", Bind::Texture(b.res.view(t.linear_depth))),
                    ("outImage", Bind::Texture(b.res.view(self.out))),
                    (
                        "Positions",
                        Bind::Uniform {
                            buffer: c.positions.raw,
                            size: c.positions.size,
                        },
                    ),
                    ("radianceTex", Bind::Texture(b.res.view(c.radiance))),
                    (
                        "Cells",
                        Bind::Uniform {
                            buffer: self.cells.raw,
                            size: self.cells.size,
                        },
                    ),
                    (
                        "params",
                        Bind::Uniform {
                            buffer: self.params.raw,
                            size: std::mem::size_of::<GatherParams>() as u64,
                        },
                    ),
                ],
            )?;
        }
        Ok(())
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "density_per_mm2": self.density,
            "samples": self.sample_count,
            "chunks": self.chunks.len(),
            "grid_dims": self.grid.dims,
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.irradiance.destroy(ctx);
        self.gather.destroy(ctx);
        for c in &mut self.chunks {
            c.samples.destroy(ctx);
            c.positions.destroy(ctx);
        }
        self.cells.destroy(ctx);
        self.params.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // lavapipe: 128 MiB of storage range, 16384-texel images. The Lee
    // Perry-Smith bust at 32 samples per mm^2 is 10.9 M samples.
    #[test]
    fn chunks_stay_within_the_limits_and_cover_every_sample() {
        let lavapipe = ChunkLimits {
            storage_range: 134_217_728,
            max_image_dimension: 16384,
        };
        let plan = plan_chunks(10_885_671, lavapipe).unwrap();
        assert_eq!(plan.chunks.len(), 2);
        let mut next = 0;
        for &(first, n) in &plan.chunks {
            assert_eq!(first, next);
            assert!(n as u64 * 16 <= lavapipe.storage_range);
            assert!(n.div_ceil(RADIANCE_WIDTH) <= lavapipe.max_image_dimension);
            assert_eq!(first % RADIANCE_WIDTH, 0, "chunks start on whole rows");
            next = first + n;
        }
        assert_eq!(next, 10_885_671);
        assert!(plan.draw_samples as u64 * 64 <= lavapipe.storage_range);
        // A small image limit splits by rows instead.
        let small = ChunkLimits {
            storage_range: 1 << 40,
            max_image_dimension: 4096,
        };
        let plan = plan_chunks(10_885_671, small).unwrap();
        assert_eq!(plan.chunks[0].1, 4096 * RADIANCE_WIDTH);
        // Below one row of range: a clear error.
        let tiny = ChunkLimits {
            storage_range: 1024,
            max_image_dimension: 4096,
        };
        assert!(plan_chunks(10, tiny).is_err());
        assert!(plan_chunks(0, lavapipe).unwrap().chunks.is_empty());
    }

    #[test]
    fn slab_candidates_bound_the_visited_samples() {
        let grid = Grid {
            origin: glam::Vec3::ZERO,
            cell: 1.0,
            dims: [3, 1, 1],
            cell_start: vec![0, 5, 6, 10],
        };
        assert_eq!(max_slab_candidates(&grid), 10);
    }
}
