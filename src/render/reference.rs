//! The ground truth as a method of the frame (`--method reference`): the diffuse
//! radiant exitance M(x_o) = integral E(x_i) R(|x_i - x_o|) dA over the actual skin
//! surface, by brute force on the GPU. Two compute passes: the diffuse radiance of
//! every surface sample (lit by the geometry pass's own shading code), then for
//! every skin pixel the sum over all samples within the cut-off, found with a
//! uniform grid. The geometry pass runs with transmittance off for this method:
//! light through thin parts arrives through the integral itself, because samples
//! on the far side of an ear are as close in 3D as they really are.

use anyhow::{bail, Result};
use ash::vk;
use glam::Mat4;

use super::separable::set_viewport;
use crate::graph::{BufferId, ImageId, Pass, PassContext, Resources};
use crate::reference::sampling::{build_grid, cutoff_mm, sample_surface, Grid, SurfaceSample};
use crate::scene::mesh::Mesh;
use crate::vk::barrier::{AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline};

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

/// Width of the radiance image: sample i is texel (i % width, i / width).
pub const RADIANCE_WIDTH: u32 = 2048;

pub struct ReferenceSss {
    irradiance: Pipeline,
    gather: Pipeline,
    irradiance_sets: [vk::DescriptorSet; 2],
    gather_set: vk::DescriptorSet,
    samples: Buffer,
    /// Per-sample diffuse radiance (RGBA32F, written by a fragment pass).
    pub radiance: Image,
    pub radiance_id: ImageId,
    cells: Buffer,
    params: Buffer,
    pub sample_ids: [BufferId; 2],
    pub sample_count: u32,
    pub grid: Grid,
    /// The samples in grid order (for CPU checks).
    pub surface: Vec<SurfaceSample>,
    pub density: f32,
}

impl ReferenceSss {
    #[allow(clippy::too_many_arguments)]
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
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let samples = super::upload::device_buffer(
            ctx,
            "reference samples",
            bytemuck::cast_slice(&surface),
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
        if count.div_ceil(RADIANCE_WIDTH) > ctx.facts.max_image_dimension_2d {
            bail!("{count} surface samples exceed the radiance image; lower the reference density");
        }
        let radiance = Image::new(
            ctx,
            "reference radiance",
            vk::Extent2D {
                width: RADIANCE_WIDTH,
                height: count.div_ceil(RADIANCE_WIDTH),
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
        let mut frame_binds = init.frame_binds;
        frame_binds.push((
            "Samples",
            Bind::Uniform {
                buffer: samples.raw,
                size: samples.size,
            },
        ));
        let irradiance_sets = [
            pool.write_set(ctx, &irradiance, 0, &frame_binds)?,
            pool.write_set(ctx, &irradiance, 1, &init.material_binds)?,
        ];
        let gather_set = pool.write_set(
            ctx,
            &gather,
            0,
            &[
                ("diffuseTex", Bind::Texture(diffuse.view)),
                ("depthTex", Bind::Texture(linear_depth.view)),
                ("outImage", Bind::Texture(output.view)),
                (
                    "Samples",
                    Bind::Uniform {
                        buffer: samples.raw,
                        size: samples.size,
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
        let s_id = resources.add_buffer("reference samples", samples.raw);
        let c_id = resources.add_buffer("reference grid cells", cells.raw);
        let radiance_id = resources.add_image(
            "reference radiance",
            radiance.raw,
            radiance.subresource_range(),
        );
        // Uploaded for the compute gather; the fragment pass's read gets its own
        // visibility barrier from the state.
        resources.buffers[s_id.0].state = ResourceState::uploaded(AccessKind::ComputeStorageRead);
        resources.buffers[c_id.0].state = ResourceState::uploaded(AccessKind::ComputeStorageRead);
        Ok(ReferenceSss {
            irradiance,
            gather,
            irradiance_sets,
            gather_set,
            samples,
            radiance,
            radiance_id,
            cells,
            params,
            sample_ids: [s_id, c_id],
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
        let [s_id, c_id] = self.sample_ids;
        let push = [self.sample_count, RADIANCE_WIDTH];
        let (r_view, r_extent) = (self.radiance.view, self.radiance.extent);
        let irradiance = Pass::new("reference irradiance")
            .image(shadow, AccessKind::FragmentSampledRead)
            .buffer(s_id, AccessKind::FragmentStorageRead)
            .image(self.radiance_id, AccessKind::ColorAttachmentWrite)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let att = [vk::RenderingAttachmentInfo::default()
                    .image_view(r_view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::DONT_CARE)
                    .store_op(vk::AttachmentStoreOp::STORE)];
                let info = vk::RenderingInfo::default()
                    .render_area(vk::Rect2D {
                        offset: vk::Offset2D::default(),
                        extent: r_extent,
                    })
                    .layer_count(1)
                    .color_attachments(&att);
                let p = &self.irradiance;
                unsafe {
                    ctx.device.cmd_begin_rendering(cmd, &info);
                    ctx.device
                        .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, p.raw);
                    set_viewport(ctx, cmd, r_extent);
                    ctx.device.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        p.layout,
                        0,
                        &self.irradiance_sets,
                        &[],
                    );
                }
                p.push(ctx, cmd, &push);
                unsafe {
                    ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
                    ctx.device.cmd_end_rendering(cmd);
                }
            });
        let gather = Pass::new("reference gather")
            .image(diffuse, AccessKind::ComputeSampledRead)
            .image(linear_depth, AccessKind::ComputeSampledRead)
            .image(self.radiance_id, AccessKind::ComputeSampledRead)
            .image(output, AccessKind::ComputeStorageWrite)
            .buffer(s_id, AccessKind::ComputeStorageRead)
            .buffer(c_id, AccessKind::ComputeStorageRead)
            .record(move |pc: &PassContext| unsafe {
                let d = &pc.ctx.device;
                d.cmd_bind_pipeline(pc.cmd, vk::PipelineBindPoint::COMPUTE, self.gather.raw);
                d.cmd_bind_descriptor_sets(
                    pc.cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    self.gather.layout,
                    0,
                    &[self.gather_set],
                    &[],
                );
                d.cmd_dispatch(
                    pc.cmd,
                    extent.width.div_ceil(8),
                    extent.height.div_ceil(8),
                    1,
                );
            });
        vec![irradiance, gather]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.irradiance.destroy(ctx);
        self.gather.destroy(ctx);
        for b in [&mut self.samples, &mut self.cells, &mut self.params] {
            b.destroy(ctx);
        }
        self.radiance.destroy(ctx);
    }
}
