//! Separable subsurface scattering on the GPU (thesis ch. 6): a seed copy of the
//! diffuse target into the intermediate, a horizontal pass diffuse -> tmp and a
//! vertical pass tmp -> diffuse, both stencil-tested on the skin bit.
//!
//! Why the seed copy: the passes only shade skin pixels, but a skin pixel's taps
//! may land on non-skin texels of the intermediate. Seeding it with the diffuse
//! image makes those texels hold what the horizontal pass would have read, so
//! the vertical pass sees the same neighbourhood as a full-screen blur would,
//! and non-skin pixels of the output are untouched, bit for bit.

use anyhow::Result;
use ash::vk;

use super::draw::fullscreen_stencil_draw;
use super::region::{px_per_mm, ReachScale, BILINEAR_MARGIN_PX};
use super::screen::ScreenTargets;
use crate::graph::{ImageId, Pass, PassContext};
use crate::skin::kernel::SeparableKernel;
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline, Samplers};

/// Push constants of sss_blur.frag.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SssPush {
    pub dir: [f32; 2],
    pub aspect: f32,
    pub tan_half_fovy: f32,
    pub mm_per_unit: f32,
    pub follow_tol_mm: f32,
    pub n_samples: i32,
    pub follow_surface: i32,
}

/// View-dependent inputs of the blur.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssView {
    pub fovy_rad: f32,
    pub mm_per_unit: f32,
    pub follow_surface: bool,
}

pub struct SeparableSss {
    pub pipeline: Pipeline,
    pub kernel: SeparableKernel,
    kernel_buffer: Buffer,
    set_h: vk::DescriptorSet,
    set_v: vk::DescriptorSet,
}

pub const STENCIL_SKIN: u32 = 1;

/// Stencil state of every SSS pass: shade only where the skin bit is set.
pub fn skin_stencil_test() -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::KEEP,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::EQUAL,
        compare_mask: STENCIL_SKIN,
        write_mask: 0,
        reference: STENCIL_SKIN,
    }
}

impl SeparableSss {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        pool: &DescriptorPool,
        samplers: &Samplers,
        kernel: SeparableKernel,
        diffuse: &Image,
        tmp: &Image,
        linear_depth: &Image,
        depth_stencil_format: vk::Format,
    ) -> Result<Self> {
        let mut desc = GraphicsDesc::fullscreen("sss blur", "sss_blur.frag", diffuse.format);
        desc.depth_format = Some(depth_stencil_format);
        desc.stencil_format = Some(depth_stencil_format);
        desc.stencil = Some(skin_stencil_test());
        let pipeline = Pipeline::graphics(ctx, &desc)?;
        let mut data = kernel.gpu_data();
        data.resize(SeparableKernel::MAX_SAMPLES, [0.0; 4]);
        let kernel_buffer = Buffer::with_data(
            ctx,
            "sss kernel",
            bytemuck::cast_slice(&data),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let size = (data.len() * 16) as u64;
        let set = |color: &Image| {
            pool.write_set(
                ctx,
                &pipeline,
                0,
                &[
                    ("colorTex", Bind::Texture(color.view)),
                    ("depthTex", Bind::Texture(linear_depth.view)),
                    ("linearClamp", Bind::Sampler(samplers.linear_clamp)),
                    (
                        "kernel",
                        Bind::Uniform {
                            buffer: kernel_buffer.raw,
                            size,
                        },
                    ),
                ],
            )
        };
        let set_h = set(diffuse)?;
        let set_v = set(tmp)?;
        Ok(SeparableSss {
            pipeline,
            kernel,
            kernel_buffer,
            set_h,
            set_v,
        })
    }

    fn push(&self, view: &SssView, extent: vk::Extent2D, dir: [f32; 2]) -> SssPush {
        let tol = self.kernel.params.width_mm;
        SssPush {
            dir,
            aspect: extent.width as f32 / extent.height as f32,
            tan_half_fovy: (view.fovy_rad * 0.5).tan(),
            mm_per_unit: view.mm_per_unit,
            follow_tol_mm: tol,
            n_samples: self.kernel.samples.len() as i32,
            // A zero-width kernel has no extent to compare depth steps against.
            follow_surface: (view.follow_surface && tol > 0.0) as i32,
        }
    }

    /// How far (pixels) the taps of a skin pixel at view depth `depth` reach:
    /// the widest offset at the strongest strength, as the shader scales it.
    pub fn reach_px(&self, depth: f32, scale: &ReachScale) -> f32 {
        let widest_mm = self
            .kernel
            .samples
            .iter()
            .map(|s| s.offset_mm.abs())
            .fold(0.0, f32::max);
        widest_mm
            * scale.max_strength
            * px_per_mm(
                depth,
                scale.height_px,
                scale.tan_half_fovy,
                scale.mm_per_unit,
            )
            + BILINEAR_MARGIN_PX
    }

    /// The three passes, in order: seed copy, horizontal, vertical.
    pub fn passes<'a>(&'a self, t: ScreenTargets<'a>, view: SssView) -> Vec<Pass<'a>> {
        let extent = t.extent;
        let seed = super::screen::seed_copy(
            "sss seed copy",
            (t.diffuse.0, t.diffuse.1),
            t.region,
            extent,
            &[(t.rt1.0, t.rt1.1)],
        );
        let blur = |name: &str,
                    src: ImageId,
                    dst: (ImageId, vk::Image, vk::ImageView),
                    set: vk::DescriptorSet,
                    dir: [f32; 2]| {
            let push = self.push(&view, extent, dir);
            Pass::new(name)
                .image(src, AccessKind::FragmentSampledRead)
                .image(t.linear_depth, AccessKind::FragmentSampledRead)
                .image(t.depth_stencil.0, AccessKind::DepthStencilReadOnly)
                .image(dst.0, AccessKind::ColorAttachmentLoadWrite)
                .record(move |pc: &PassContext| {
                    fullscreen_stencil_draw(
                        pc,
                        &self.pipeline,
                        set,
                        &[dst.2],
                        t.depth_stencil.1,
                        extent,
                        t.region,
                        STENCIL_SKIN,
                        |c, cmd| self.pipeline.push(c, cmd, &push),
                    );
                })
        };
        vec![
            seed,
            blur("sss horizontal", t.diffuse.0, t.rt1, self.set_h, [1.0, 0.0]),
            blur("sss vertical", t.rt1.0, t.diffuse, self.set_v, [0.0, 1.0]),
        ]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.kernel_buffer.destroy(ctx);
    }
}
