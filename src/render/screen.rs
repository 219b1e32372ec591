//! The chapter-4 screen-space methods on the GPU: `ssg`, the sum of Gaussians
//! with alpha-blended accumulation and depth-based Gaussian skipping (thesis
//! 4.2, 4.2.1), and `ss-jittered`, Hable et al.'s 13-tap kernel in screen space.
//! Both scale their kernels by the stretch factors of eq. 4.1-4.4.
//!
//! Targets: RT1 = `sss intermediate` (widest Gaussian so far), RT2 = `sss
//! intermediate 2` (ping-pong), RTF = the diffuse target itself. RT1 and RT2 are
//! seeded with a copy of the diffuse target so that taps landing on non-skin
//! texels read what a full-screen blur would have read.

use anyhow::{bail, Result};
use ash::vk;

use super::draw::fullscreen_stencil_draw;
use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::separable::{skin_stencil_test, STENCIL_SKIN};
use crate::graph::{ImageId, Pass, PassContext};
use crate::skin::jittered::JitteredKernel;
use crate::skin::ssg::{lod_depth, SsgGaussian, Stretch};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::Image;
use crate::vk::pipeline::{Bind, Blend, DescriptorPool, GraphicsDesc, Pipeline, Samplers};

/// How non-skin pixels are kept out of the SSS passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaskMode {
    /// Hardware stencil test on the skin bit (masked pixels run no shader).
    Stencil,
    /// A dynamic branch on the mask in the shader (every pixel of the quad runs it).
    Branch,
}

impl std::str::FromStr for MaskMode {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "stencil" => Ok(MaskMode::Stencil),
            "branch" => Ok(MaskMode::Branch),
            other => bail!("unknown mask mode '{other}' (valid: stencil, branch)"),
        }
    }
}

/// Push constants of screen_common.glsl (std430 layout, 96 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ScreenPush {
    pub dir: [f32; 2],
    pub texel: [f32; 2],
    pub alpha: f32,
    pub beta: f32,
    pub gamma: f32,
    pub std_mm: f32,
    pub quad_depth: f32,
    pub mask_branch: i32,
    pub pad: [f32; 2],
    pub center: [f32; 4],
    pub mid: [f32; 4],
    pub wide: [f32; 4],
}

/// Graph ids and handles of the targets the screen-space passes use, and where
/// on screen they have work.
#[derive(Clone, Copy, Debug)]
pub struct ScreenTargets<'a> {
    pub diffuse: (ImageId, vk::Image, vk::ImageView),
    pub rt1: (ImageId, vk::Image, vk::ImageView),
    pub rt2: (ImageId, vk::Image, vk::ImageView),
    pub linear_depth: ImageId,
    pub depth_stencil: (ImageId, vk::ImageView),
    pub extent: vk::Extent2D,
    /// Disjoint rectangles holding every skin pixel and every texel the method's
    /// taps read from one (see `region.rs`): the seed copies and the stencil-
    /// tested draws are limited to them.
    pub region: &'a [vk::Rect2D],
    /// One rectangle covering the screen.
    pub screen: &'a [vk::Rect2D],
}

/// A pass that copies `src` (the diffuse target) into each of `dsts` within
/// `region`: the seeds every method's intermediates start from, so taps on
/// non-skin texels read what a full-screen blur would have read.
pub fn seed_copy<'a>(
    name: &str,
    src: (ImageId, vk::Image),
    region: &'a [vk::Rect2D],
    extent: vk::Extent2D,
    dsts: &[(ImageId, vk::Image)],
) -> Pass<'a> {
    let whole = region.len() == 1
        && region[0].offset == vk::Offset2D::default()
        && region[0].extent == extent;
    // A copy of part of the image keeps the rest (the zeros written at set-up):
    // its barrier must not discard the old contents.
    let write = if whole {
        AccessKind::TransferWrite
    } else {
        AccessKind::TransferWritePartial
    };
    let mut pass = Pass::new(name).image(src.0, AccessKind::TransferRead);
    for d in dsts {
        pass = pass.image(d.0, write);
    }
    let src = src.1;
    let dsts: Vec<vk::Image> = dsts.iter().map(|d| d.1).collect();
    pass.record(move |pc: &PassContext| {
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let copies: Vec<vk::ImageCopy> = region
            .iter()
            .map(|r| {
                let offset = vk::Offset3D {
                    x: r.offset.x,
                    y: r.offset.y,
                    z: 0,
                };
                vk::ImageCopy::default()
                    .src_subresource(layers)
                    .dst_subresource(layers)
                    .src_offset(offset)
                    .dst_offset(offset)
                    .extent(vk::Extent3D {
                        width: r.extent.width,
                        height: r.extent.height,
                        depth: 1,
                    })
            })
            .collect();
        if copies.is_empty() {
            return; // no skin on screen: nothing reads the seeds
        }
        for &dst in &dsts {
            unsafe {
                pc.ctx.device.cmd_copy_image(
                    pc.cmd,
                    src,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    dst,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &copies,
                )
            };
        }
    })
}

fn source_set(
    ctx: &Context,
    pool: &DescriptorPool,
    pipeline: &Pipeline,
    samplers: &Samplers,
    color: &Image,
    depth: &Image,
) -> Result<vk::DescriptorSet> {
    pool.write_set(
        ctx,
        pipeline,
        0,
        &[
            ("colorTex", Bind::Texture(color.view)),
            ("depthTex", Bind::Texture(depth.view)),
            ("linearClamp", Bind::Sampler(samplers.linear_clamp)),
        ],
    )
}

/// Sum-of-Gaussians screen-space SSS.
pub struct SsgSss {
    horizontal: Pipeline,
    vertical: Pipeline,
    set_rt1: vk::DescriptorSet,
    set_rt2: vk::DescriptorSet,
    pub gaussians: Vec<SsgGaussian>,
    pub stretch: Stretch,
    /// Depth-buffer value of each Gaussian's full-screen triangle (1 = no LOD).
    pub quad_depths: Vec<f32>,
    /// The LOD distance of each Gaussian in scene units (eq. 4.6 with 0.5).
    pub lod_distances: Vec<f32>,
    pub mask: MaskMode,
}

pub struct SsgInit<'a> {
    pub gaussians: Vec<SsgGaussian>,
    pub stretch: Stretch,
    pub lod: bool,
    pub mask: MaskMode,
    /// Maps a linear view depth to the depth buffer's value (the camera's projection).
    pub to_ndc: &'a dyn Fn(f32) -> f32,
}

impl SsgSss {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        pool: &DescriptorPool,
        samplers: &Samplers,
        init: SsgInit,
        rt1: &Image,
        rt2: &Image,
        linear_depth: &Image,
        ds_format: vk::Format,
    ) -> Result<Self> {
        if !ctx.facts.independent_blend {
            bail!(
                "device '{}' lacks independentBlend, which ssg's MRT pass needs",
                ctx.facts.name
            );
        }
        let desc = |name: &str, frag: &'static str, colors: usize| {
            let mut d = GraphicsDesc::fullscreen(name, frag, rt1.format);
            d.vert = "fullscreen_depth.vert";
            d.color_formats = vec![rt1.format; colors];
            d.depth_format = Some(ds_format);
            d.stencil_format = Some(ds_format);
            // Gaussian LOD: shade only where the surface is nearer than the triangle.
            d.depth_test = true;
            d.depth_write = false;
            d.depth_compare = vk::CompareOp::GREATER;
            d.stencil = (init.mask == MaskMode::Stencil).then(skin_stencil_test);
            if colors == 2 {
                d.blend = Blend::ConstantMix(1);
            }
            d
        };
        let horizontal =
            Pipeline::graphics(ctx, &desc("ssg horizontal", "ssg_horizontal.frag", 1))?;
        let vertical = Pipeline::graphics(ctx, &desc("ssg vertical", "ssg_vertical.frag", 2))?;
        let set_rt1 = source_set(ctx, pool, &horizontal, samplers, rt1, linear_depth)?;
        let set_rt2 = source_set(ctx, pool, &vertical, samplers, rt2, linear_depth)?;
        let lod_distances: Vec<f32> = init
            .gaussians
            .iter()
            .map(|g| lod_depth(g.incremental_std_mm, init.stretch.alpha))
            .collect();
        let quad_depths = lod_distances
            .iter()
            .map(|&d| {
                if init.lod {
                    (init.to_ndc)(d).clamp(0.0, 1.0)
                } else {
                    1.0
                }
            })
            .collect();
        Ok(SsgSss {
            horizontal,
            vertical,
            set_rt1,
            set_rt2,
            gaussians: init.gaussians,
            stretch: init.stretch,
            quad_depths,
            lod_distances,
            mask: init.mask,
        })
    }

    /// How far (pixels) the taps of a skin pixel at view depth `depth` reach:
    /// 3 steps of std/3 stretched (eq. 4.1-4.4; the depth-gradient term only
    /// narrows it) for the widest Gaussian.
    pub fn reach_px(&self, depth: f32, scale: &ReachScale) -> f32 {
        let widest = self
            .gaussians
            .iter()
            .map(|g| g.incremental_std_mm)
            .fold(0.0, f32::max);
        self.stretch.alpha * scale.max_strength / depth * widest + BILINEAR_MARGIN_PX
    }

    pub fn passes<'a>(&'a self, t: ScreenTargets<'a>) -> Vec<Pass<'a>> {
        let mut passes = vec![seed_copy(
            "ssg seed copy",
            (t.diffuse.0, t.diffuse.1),
            t.region,
            t.extent,
            &[(t.rt1.0, t.rt1.1), (t.rt2.0, t.rt2.1)],
        )];
        let extent = t.extent;
        for (g, &quad_depth) in self.gaussians.iter().zip(&self.quad_depths) {
            let base = ScreenPush {
                texel: [1.0 / extent.width as f32, 1.0 / extent.height as f32],
                alpha: self.stretch.alpha,
                beta: self.stretch.beta,
                gamma: self.stretch.gamma,
                std_mm: g.incremental_std_mm,
                quad_depth,
                mask_branch: (self.mask == MaskMode::Branch) as i32,
                ..Default::default()
            };
            let h = ScreenPush {
                dir: [1.0, 0.0],
                ..base
            };
            let v = ScreenPush {
                dir: [0.0, 1.0],
                ..base
            };
            let blend = [g.blend[0], g.blend[1], g.blend[2], 1.0];
            let ds = t.depth_stencil;
            passes.push(
                Pass::new(format!("ssg g{} horizontal", g.index))
                    .image(t.rt1.0, AccessKind::FragmentSampledRead)
                    .image(t.linear_depth, AccessKind::FragmentSampledRead)
                    .image(ds.0, AccessKind::DepthStencilReadOnly)
                    .image(t.rt2.0, AccessKind::ColorAttachmentLoadWrite)
                    .record(move |pc: &PassContext| {
                        fullscreen_stencil_draw(
                            pc,
                            &self.horizontal,
                            self.set_rt1,
                            &[t.rt2.2],
                            ds.1,
                            extent,
                            t.region,
                            STENCIL_SKIN,
                            |c, cmd| self.horizontal.push(c, cmd, &h),
                        )
                    }),
            );
            passes.push(
                Pass::new(format!("ssg g{} vertical", g.index))
                    .image(t.rt2.0, AccessKind::FragmentSampledRead)
                    .image(t.linear_depth, AccessKind::FragmentSampledRead)
                    .image(ds.0, AccessKind::DepthStencilReadOnly)
                    .image(t.rt1.0, AccessKind::ColorAttachmentLoadWrite)
                    .image(t.diffuse.0, AccessKind::ColorAttachmentLoadWrite)
                    .record(move |pc: &PassContext| {
                        fullscreen_stencil_draw(
                            pc,
                            &self.vertical,
                            self.set_rt2,
                            &[t.rt1.2, t.diffuse.2],
                            ds.1,
                            extent,
                            t.region,
                            STENCIL_SKIN,
                            |c, cmd| {
                                self.vertical.push(c, cmd, &v);
                                unsafe { c.device.cmd_set_blend_constants(cmd, &blend) };
                            },
                        )
                    }),
            );
        }
        passes
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.horizontal.destroy(ctx);
        self.vertical.destroy(ctx);
    }
}

/// Hable et al.'s jittered 13-tap kernel in screen space ("SS Jittered").
pub struct JitteredSss {
    pipeline: Pipeline,
    set: vk::DescriptorSet,
    pub kernel: JitteredKernel,
    pub stretch: Stretch,
}

impl JitteredSss {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        pool: &DescriptorPool,
        samplers: &Samplers,
        kernel: JitteredKernel,
        stretch: Stretch,
        rt1: &Image,
        linear_depth: &Image,
        ds_format: vk::Format,
    ) -> Result<Self> {
        let mut d = GraphicsDesc::fullscreen("ss-jittered", "jittered.frag", rt1.format);
        d.depth_format = Some(ds_format);
        d.stencil_format = Some(ds_format);
        d.stencil = Some(skin_stencil_test());
        let pipeline = Pipeline::graphics(ctx, &d)?;
        let set = source_set(ctx, pool, &pipeline, samplers, rt1, linear_depth)?;
        Ok(JitteredSss {
            pipeline,
            set,
            kernel,
            stretch,
        })
    }

    /// How far (pixels) the taps of a skin pixel at view depth `depth` reach:
    /// the wider ring, stretched as the shader does (s / 3 pixels per mm).
    pub fn reach_px(&self, depth: f32, scale: &ReachScale) -> f32 {
        let ring = self.kernel.mid_radius_mm.max(self.kernel.wide_radius_mm);
        self.stretch.alpha * scale.max_strength / depth * ring / 3.0 + BILINEAR_MARGIN_PX
    }

    pub fn passes<'a>(&'a self, t: ScreenTargets<'a>) -> Vec<Pass<'a>> {
        let extent = t.extent;
        let k = self.kernel;
        let push = ScreenPush {
            texel: [1.0 / extent.width as f32, 1.0 / extent.height as f32],
            alpha: self.stretch.alpha,
            beta: self.stretch.beta,
            gamma: self.stretch.gamma,
            center: [k.center[0], k.center[1], k.center[2], 0.0],
            mid: [k.mid[0], k.mid[1], k.mid[2], 0.0],
            wide: [k.wide[0], k.mid_radius_mm, k.wide_radius_mm, 0.0],
            ..Default::default()
        };
        let ds = t.depth_stencil;
        vec![
            seed_copy(
                "ss-jittered seed copy",
                (t.diffuse.0, t.diffuse.1),
                t.region,
                t.extent,
                &[(t.rt1.0, t.rt1.1)],
            ),
            Pass::new("ss-jittered")
                .image(t.rt1.0, AccessKind::FragmentSampledRead)
                .image(t.linear_depth, AccessKind::FragmentSampledRead)
                .image(ds.0, AccessKind::DepthStencilReadOnly)
                .image(t.diffuse.0, AccessKind::ColorAttachmentLoadWrite)
                .record(move |pc: &PassContext| {
                    fullscreen_stencil_draw(
                        pc,
                        &self.pipeline,
                        self.set,
                        &[t.diffuse.2],
                        ds.1,
                        extent,
                        t.region,
                        STENCIL_SKIN,
                        |c, cmd| self.pipeline.push(c, cmd, &push),
                    )
                }),
        ]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
