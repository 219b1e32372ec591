//! The ground truth as a method of the frame (`--method reference`): the diffuse
//! radiant exitance M(x_o) = integral E(x_i) R(|x_i - x_o|) dA over the actual skin
//! surface, by brute force on the GPU. Two passes: the diffuse radiance of every
//! surface sample, lit by the geometry pass's own shading code (a fragment pass
//! over an image with one texel per sample, so the shadow test is the same
//! hardware compare), then a compute pass that sums, for every skin pixel, all
//! samples within the cut-off, found with a uniform grid. The geometry pass runs
//! with transmittance off for this method: light through thin parts arrives
//! through the integral itself, because samples on the far side of an ear are as
//! close in 3D as they really are.

use anyhow::{bail, Result};
use ash::vk;
use glam::Mat4;

use super::draw::begin_color_rendering;
use crate::graph::{BufferId, ImageId, Pass, PassContext, Resources};
use crate::reference::sampling::{build_grid, cutoff_mm, sample_surface, Grid, SurfaceSample};
use crate::scene::mesh::Mesh;
use crate::vk::barrier::{AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline};

/// Width of the radiance image: sample i is texel (i % width, i / width).
pub const RADIANCE_WIDTH: u32 = 2048;

/// std140 layout of `GatherParams` (reference_gather.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GatherParams {
    pub inv_view: [[f32; 4]; 4],
    pub grid_origin: [f32; 4],
    pub grid_dims: [u32; 4],
    pub view: [f32; 4],
}

/// Inputs of the reference, from the renderer's set-up.
pub struct ReferenceInit<'a> {
    pub head: &'a Mesh,
    pub instances: &'a [Mat4],
    pub mm_per_unit: f32,
    /// Surface samples per mm^2.
    pub density: f32,
    pub inv_view: Mat4,
    pub tan_half_fovy: f32,
    pub aspect: f32,
    /// Bindings of set 0 (frame) and set 1 (head material) of lighting.glsl.
    pub frame_binds: Vec<(&'static str, Bind)>,
    pub material_binds: Vec<(&'static str, Bind)>,
}

/// One draw of the irradiance pass: its set (with its range of the sample
/// buffer), its first row of the radiance image and its sample count.
struct Chunk {
    set: vk::DescriptorSet,
    first_row: u32,
    count: u32,
}

pub struct ReferenceSss {
    irradiance: Pipeline,
    gather: Pipeline,
    material_set: vk::DescriptorSet,
    chunks: Vec<Chunk>,
    gather_set: vk::DescriptorSet,
    samples: Buffer,
    positions: Buffer,
    cells: Buffer,
    params: Buffer,
    /// Per-sample diffuse radiance (RGBA32F, written by the fragment pass).
    pub radiance: Image,
    pub radiance_id: ImageId,
    /// Graph ids of the sample, position and cell buffers.
    buffer_ids: [BufferId; 3],
    pub sample_count: u32,
    pub grid: Grid,
    /// The samples in grid order (for CPU checks).
    pub surface: Vec<SurfaceSample>,
    pub density: f32,
}

impl ReferenceSss {
    pub fn new(
        ctx: &Context,
        pool: &DescriptorPool,
        resources: &mut Resources,
        init: ReferenceInit,
        diffuse: &Image,
        linear_depth: &Image,
        output: &Image,
    ) -> Result<Self> {
        if !(init.density > 0.0 && init.density <= 256.0) {
            bail!(
                "reference density must be within (0, 256] samples per mm^2, got {}",
                init.density
            );
        }
        let mut surface = sample_surface(init.head, init.instances, init.mm_per_unit, init.density);
        if surface.is_empty() {
            bail!("the reference found no skin surface to sample");
        }
        let grid = build_grid(&mut surface, cutoff_mm() / init.mm_per_unit);
        let count = surface.len() as u32;
        let limit = ctx.facts.max_storage_buffer_range as u64;
        let positions_data: Vec<[f32; 4]> = surface.iter().map(|s| s.pos_area).collect();
        let positions_bytes = positions_data.len() as u64 * 16;
        let rows = count.div_ceil(RADIANCE_WIDTH);
        if positions_bytes > limit || rows > ctx.facts.max_image_dimension_2d {
            bail!("{count} surface samples are more than this device can hold (storage range {limit} bytes); lower the reference density");
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let samples = super::upload::device_buffer(
            ctx,
            "reference samples",
            bytemuck::cast_slice(&surface),
            storage,
            AccessKind::FragmentStorageRead,
        )?;
        let positions = super::upload::device_buffer(
            ctx,
            "reference positions",
            bytemuck::cast_slice(&positions_data),
            storage,
            AccessKind::ComputeStorageRead,
        )?;
        let cells = super::upload::device_buffer(
            ctx,
            "reference grid cells",
            bytemuck::cast_slice(&grid.cell_start),
            storage,
            AccessKind::ComputeStorageRead,
        )?;
        let radiance = Image::new(
            ctx,
            "reference radiance",
            vk::Extent2D {
                width: RADIANCE_WIDTH,
                height: rows,
            },
            vk::Format::R32G32B32A32_SFLOAT,
            vk::ImageUsageFlags::COLOR_ATTACHMENT
                | vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_SRC,
        )?;
        let p = GatherParams {
            inv_view: init.inv_view.to_cols_array_2d(),
            grid_origin: grid.origin.extend(grid.cell).to_array(),
            grid_dims: [grid.dims[0], grid.dims[1], grid.dims[2], RADIANCE_WIDTH],
            view: [
                init.tan_half_fovy,
                init.aspect,
                init.mm_per_unit,
                cutoff_mm(),
            ],
        };
        let params = Buffer::with_data(
            ctx,
            "reference gather params",
            bytemuck::bytes_of(&p),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;

        let gather = Pipeline::compute(ctx, "reference gather", "reference_gather.comp")?;
        let irradiance = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen(
                "reference irradiance",
                "reference_irradiance.frag",
                radiance.format,
            ),
        )?;

        // The full samples (64 bytes each) may exceed the storage-buffer range:
        // bind them in chunks of whole radiance rows, each within the limit and at
        // an offset the device's alignment allows.
        let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
        let row_bytes = sample_bytes * RADIANCE_WIDTH as u64;
        let align = ctx.facts.min_storage_buffer_offset_alignment.max(1);
        if row_bytes % align != 0 {
            bail!("a radiance row ({row_bytes} bytes) is not aligned to the storage-buffer offset alignment ({align})");
        }
        let rows_per_chunk = (limit / row_bytes).max(1) as u32;
        let mut chunks = Vec::new();
        let mut row = 0;
        while row < rows {
            let first = row * RADIANCE_WIDTH;
            let n = (count - first).min(rows_per_chunk * RADIANCE_WIDTH);
            let mut binds = init.frame_binds.clone();
            binds.push((
                "Samples",
                Bind::Range {
                    buffer: samples.raw,
                    offset: first as u64 * sample_bytes,
                    size: n as u64 * sample_bytes,
                },
            ));
            chunks.push(Chunk {
                set: pool.write_set(ctx, &irradiance, 0, &binds)?,
                first_row: row,
                count: n,
            });
            row += rows_per_chunk;
        }
        let material_set = pool.write_set(ctx, &irradiance, 1, &init.material_binds)?;
        let gather_set = pool.write_set(
            ctx,
            &gather,
            0,
            &[
                ("diffuseTex", Bind::Texture(diffuse.view)),
                ("depthTex", Bind::Texture(linear_depth.view)),
                ("outImage", Bind::Texture(output.view)),
                (
                    "Positions",
                    Bind::Uniform {
                        buffer: positions.raw,
                        size: positions.size,
                    },
                ),
                ("radianceTex", Bind::Texture(radiance.view)),
                (
                    "Cells",
                    Bind::Uniform {
                        buffer: cells.raw,
                        size: cells.size,
                    },
                ),
                (
                    "params",
                    Bind::Uniform {
                        buffer: params.raw,
                        size: std::mem::size_of::<GatherParams>() as u64,
                    },
                ),
            ],
        )?;
        let ids = [
            resources.add_buffer("reference samples", samples.raw),
            resources.add_buffer("reference positions", positions.raw),
            resources.add_buffer("reference grid cells", cells.raw),
        ];
        resources.buffers[ids[0].0].state =
            ResourceState::uploaded(AccessKind::FragmentStorageRead);
        resources.buffers[ids[1].0].state = ResourceState::uploaded(AccessKind::ComputeStorageRead);
        resources.buffers[ids[2].0].state = ResourceState::uploaded(AccessKind::ComputeStorageRead);
        let radiance_id = resources.add_image(
            "reference radiance",
            radiance.raw,
            radiance.subresource_range(),
        );
        Ok(ReferenceSss {
            irradiance,
            gather,
            material_set,
            chunks,
            gather_set,
            samples,
            positions,
            cells,
            params,
            radiance,
            radiance_id,
            buffer_ids: ids,
            sample_count: count,
            grid,
            surface,
            density: init.density,
        })
    }

    pub fn passes<'a>(
        &'a self,
        shadow: ImageId,
        diffuse: ImageId,
        linear_depth: ImageId,
        output: ImageId,
        extent: vk::Extent2D,
    ) -> Vec<Pass<'a>> {
        let [s_id, p_id, c_id] = self.buffer_ids;
        let (r_view, r_extent) = (self.radiance.view, self.radiance.extent);
        let irradiance = Pass::new("reference irradiance")
            .image(shadow, AccessKind::FragmentSampledRead)
            .buffer(s_id, AccessKind::FragmentStorageRead)
            .image(self.radiance_id, AccessKind::ColorAttachmentWrite)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                begin_color_rendering(
                    ctx,
                    cmd,
                    &[r_view],
                    r_extent,
                    vk::AttachmentLoadOp::DONT_CARE,
                );
                let p = &self.irradiance;
                unsafe {
                    ctx.device
                        .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, p.raw);
                    ctx.device.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        p.layout,
                        1,
                        &[self.material_set],
                        &[],
                    );
                }
                for c in &self.chunks {
                    let rows = c.count.div_ceil(RADIANCE_WIDTH);
                    let scissor = vk::Rect2D {
                        offset: vk::Offset2D {
                            x: 0,
                            y: c.first_row as i32,
                        },
                        extent: vk::Extent2D {
                            width: RADIANCE_WIDTH,
                            height: rows,
                        },
                    };
                    unsafe {
                        ctx.device.cmd_bind_descriptor_sets(
                            cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            p.layout,
                            0,
                            &[c.set],
                            &[],
                        );
                        ctx.device.cmd_set_scissor(cmd, 0, &[scissor]);
                    }
                    p.push(ctx, cmd, &[c.count, RADIANCE_WIDTH, c.first_row]);
                    unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
                }
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            });
        let mut passes = vec![irradiance];
        for k in 0..9i32 {
            let cell_row = [k % 3 - 1, k / 3 - 1];
            // The first row of cells writes the output; the next ones add to it.
            let out_access = if k == 0 {
                AccessKind::ComputeStorageWrite
            } else {
                AccessKind::ComputeStorageReadWrite
            };
            passes.push(
                Pass::new(format!("reference gather {}/9", k + 1))
                    .image(diffuse, AccessKind::ComputeSampledRead)
                    .image(linear_depth, AccessKind::ComputeSampledRead)
                    .image(self.radiance_id, AccessKind::ComputeSampledRead)
                    .image(output, out_access)
                    .buffer(p_id, AccessKind::ComputeStorageRead)
                    .buffer(c_id, AccessKind::ComputeStorageRead)
                    .record(move |pc: &PassContext| {
                        let d = &pc.ctx.device;
                        unsafe {
                            d.cmd_bind_pipeline(
                                pc.cmd,
                                vk::PipelineBindPoint::COMPUTE,
                                self.gather.raw,
                            );
                            d.cmd_bind_descriptor_sets(
                                pc.cmd,
                                vk::PipelineBindPoint::COMPUTE,
                                self.gather.layout,
                                0,
                                &[self.gather_set],
                                &[],
                            );
                        }
                        self.gather.push(pc.ctx, pc.cmd, &cell_row);
                        unsafe {
                            d.cmd_dispatch(
                                pc.cmd,
                                extent.width.div_ceil(8),
                                extent.height.div_ceil(8),
                                1,
                            )
                        };
                    }),
            );
        }
        passes
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.irradiance.destroy(ctx);
        self.gather.destroy(ctx);
        for b in [
            &mut self.samples,
            &mut self.positions,
            &mut self.cells,
            &mut self.params,
        ] {
            b.destroy(ctx);
        }
        self.radiance.destroy(ctx);
    }
}
