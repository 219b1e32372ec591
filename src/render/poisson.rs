//! Poisson-disk screen-space SSS (seed 003, Agni's Philosophy) on the GPU: mip
//! chains of the diffuse, linear-depth and normal targets (one 2x2-mean pass per
//! level, all three through MRT), then one pass of up to 32 disk samples read from
//! the level the kernel radius asks for.
//!
//! The pass reads every level of the diffuse chain, so it writes into the
//! intermediate target (seeded with a copy of level 0, so non-skin pixels keep
//! their colour) and the composite reads the intermediate.

use anyhow::Result;
use ash::vk;

use super::draw::{begin_color_rendering, fullscreen_stencil_draw};
use super::screen::{seed_copy, ScreenTargets};
use super::separable::{skin_stencil_test, STENCIL_SKIN};
use crate::graph::{ImageId, Pass, PassContext};
use crate::skin::poisson::{poisson_disk_32, PoissonParams};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline, Samplers};

/// Mip levels of the chains: enough for radii of 16 x 2^4 = 256 pixels.
pub const MAX_LEVELS: u32 = 5;

/// Levels for a target of `extent` (every level at least one texel).
pub fn levels_for(extent: vk::Extent2D) -> u32 {
    let full = 32 - extent.width.max(extent.height).max(1).leading_zeros();
    full.min(MAX_LEVELS)
}

/// Push constants of poisson.frag (std430, 80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PoissonPush {
    pub size: [f32; 2],
    pub tan_half_fovy: f32,
    pub mm_per_unit: f32,
    /// One row per tap count (8, 16, 32): rgb falloff, w unused.
    pub falloff: [[f32; 4]; 3],
    pub radius_mm: f32,
    pub depth_sensitivity: f32,
    pub normal_sensitivity: f32,
    pub max_level: i32,
}

/// The per-level graph ids of the three chains (index = mip level).
#[derive(Clone, Debug)]
pub struct Chains {
    pub color: Vec<(ImageId, vk::ImageView)>,
    pub depth: Vec<(ImageId, vk::ImageView)>,
    pub normal: Vec<(ImageId, vk::ImageView)>,
    pub extents: Vec<vk::Extent2D>,
}

pub struct PoissonSss {
    mip_pipeline: Pipeline,
    pipeline: Pipeline,
    mip_sets: Vec<vk::DescriptorSet>,
    set: vk::DescriptorSet,
    disk_buffer: Buffer,
    pub params: PoissonParams,
    pub levels: u32,
}

impl PoissonSss {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        pool: &DescriptorPool,
        samplers: &Samplers,
        diffuse: &Image,
        depth: &Image,
        normal: &Image,
        ds_format: vk::Format,
    ) -> Result<Self> {
        let levels = diffuse.levels;
        let mut mip = GraphicsDesc::fullscreen("poisson mip", "mip_down.frag", diffuse.format);
        mip.color_formats = vec![diffuse.format, depth.format, normal.format];
        let mip_pipeline = Pipeline::graphics(ctx, &mip)?;
        let mip_sets = (1..levels)
            .map(|l| {
                let src = (l - 1) as usize;
                pool.write_set(
                    ctx,
                    &mip_pipeline,
                    0,
                    &[
                        ("srcColor", Bind::Texture(diffuse.level_views[src])),
                        ("srcDepth", Bind::Texture(depth.level_views[src])),
                        ("srcNormal", Bind::Texture(normal.level_views[src])),
                    ],
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let mut d = GraphicsDesc::fullscreen("poisson", "poisson.frag", diffuse.format);
        d.depth_format = Some(ds_format);
        d.stencil_format = Some(ds_format);
        d.stencil = Some(skin_stencil_test());
        let pipeline = Pipeline::graphics(ctx, &d)?;
        let disk: Vec<[f32; 4]> = poisson_disk_32()
            .iter()
            .map(|p| [p[0], p[1], 0.0, 0.0])
            .collect();
        let disk_buffer = Buffer::with_data(
            ctx,
            "poisson disk",
            bytemuck::cast_slice(&disk),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let set = pool.write_set(
            ctx,
            &pipeline,
            0,
            &[
                ("colorChain", Bind::Texture(diffuse.chain_view)),
                ("depthChain", Bind::Texture(depth.chain_view)),
                ("normalChain", Bind::Texture(normal.chain_view)),
                ("mipClamp", Bind::Sampler(samplers.mip_clamp)),
                (
                    "disk",
                    Bind::Uniform {
                        buffer: disk_buffer.raw,
                        size: (disk.len() * 16) as u64,
                    },
                ),
            ],
        )?;
        Ok(PoissonSss {
            mip_pipeline,
            pipeline,
            mip_sets,
            set,
            disk_buffer,
            params: PoissonParams::from_profile(),
            levels,
        })
    }

    pub fn passes<'a>(
        &'a self,
        t: ScreenTargets<'a>,
        chains: &Chains,
        fovy_rad: f32,
        mm_per_unit: f32,
    ) -> Vec<Pass<'a>> {
        let mut passes = vec![seed_copy(
            "poisson seed copy",
            (t.diffuse.0, t.diffuse.1),
            // The composite reads this target on every pixel: seed all of it.
            t.screen,
            t.extent,
            &[(t.rt1.0, t.rt1.1)],
        )];
        for l in 1..self.levels as usize {
            let extent = chains.extents[l];
            let targets = [chains.color[l].1, chains.depth[l].1, chains.normal[l].1];
            let set = self.mip_sets[l - 1];
            let mut pass = Pass::new(format!("poisson mip {l}"));
            for c in [&chains.color, &chains.depth, &chains.normal] {
                pass = pass
                    .image(c[l - 1].0, AccessKind::FragmentSampledRead)
                    .image(c[l].0, AccessKind::ColorAttachmentWrite);
            }
            passes.push(pass.record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                begin_color_rendering(ctx, cmd, &targets, extent, vk::AttachmentLoadOp::DONT_CARE);
                unsafe {
                    ctx.device.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.mip_pipeline.raw,
                    );
                    ctx.device.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.mip_pipeline.layout,
                        0,
                        &[set],
                        &[],
                    );
                    ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
                    ctx.device.cmd_end_rendering(cmd);
                }
            }));
        }
        let p = self.params;
        let push = PoissonPush {
            size: [t.extent.width as f32, t.extent.height as f32],
            tan_half_fovy: (0.5 * fovy_rad).tan(),
            mm_per_unit,
            falloff: p.falloff.map(|f| [f[0], f[1], f[2], 0.0]),
            radius_mm: p.radius_mm,
            depth_sensitivity: p.depth_sensitivity,
            normal_sensitivity: p.normal_sensitivity,
            max_level: self.levels as i32 - 1,
        };
        let mut pass = Pass::new("poisson");
        for c in [&chains.color, &chains.depth, &chains.normal] {
            for level in c {
                pass = pass.image(level.0, AccessKind::FragmentSampledRead);
            }
        }
        let (ds, extent) = (t.depth_stencil, t.extent);
        passes.push(
            pass.image(ds.0, AccessKind::DepthStencilReadOnly)
                .image(t.rt1.0, AccessKind::ColorAttachmentLoadWrite)
                .record(move |pc: &PassContext| {
                    fullscreen_stencil_draw(
                        pc,
                        &self.pipeline,
                        self.set,
                        &[t.rt1.2],
                        ds.1,
                        extent,
                        t.region,
                        STENCIL_SKIN,
                        |c, cmd| self.pipeline.push(c, cmd, &push),
                    )
                }),
        );
        passes
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.mip_pipeline.destroy(ctx);
        self.pipeline.destroy(ctx);
        self.disk_buffer.destroy(ctx);
    }
}
