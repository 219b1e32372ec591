//! The frame: shadow map -> geometry MRTs -> separable SSS (stencil-masked) ->
//! composite -> Hable tone map, recorded through the pass graph.

pub mod draw;
pub mod poisson;
pub mod readback;
pub mod reference;
pub mod region;
pub mod scene_gpu;
pub mod screen;
pub mod separable;
pub mod settings;
pub mod upload;

use anyhow::{bail, Context as _, Result};
use ash::vk;
use glam::Mat4;

use crate::graph::{record_passes, ImageId, Pass, PassContext, Resources};
use crate::scene::camera::Camera;
use crate::scene::instancing::{grid_bounds, head_grid};
use crate::scene::light::{shadow_frame, LightFrame};
use crate::scene::Scene;
use crate::skin::beckmann::beckmann_lut;
use crate::skin::jittered::hable_kernel;
use crate::skin::kernel::SeparableKernel;
use crate::skin::ssg::{ssg_gaussians, Stretch};
use crate::skin::transmittance::shrink_units;
use crate::vk::barrier::{AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline, Samplers, VertexInput};
use crate::vk::profiler::{PassSample, Profiler};
use draw::{begin_color_rendering, set_viewport};
use poisson::{levels_for, Chains, PoissonSss};
use readback::{DumpedImage, ReadbackPlan};
use reference::{ReferenceInit, ReferenceSss};
use scene_gpu::GpuObject;
use screen::{JitteredSss, ScreenTargets, SsgInit, SsgSss};
use separable::{SeparableSss, SssView, STENCIL_SKIN};
pub use settings::{Method, RenderSettings};

pub const DIFFUSE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
pub const LINEAR_DEPTH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
pub const SHADOW_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Cells per axis of the grid that clusters skin triangles for the SSS region:
/// 8^3 = at most 512 boxes per head, projected once per renderer.
const REGION_CLUSTER_CELLS: u32 = 8;

/// std140 layout of `FrameUniforms` (shaders/frame_uniforms.glsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub view: [[f32; 4]; 4],
    pub light_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    pub light_dir: [f32; 4],
    pub light_color: [f32; 4],
    pub ambient: [f32; 4],
    pub params: [f32; 4],
    pub shadow_params: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadowPush {
    model: [[f32; 4]; 4],
    light_view_proj: [[f32; 4]; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapPush {
    exposure: f32,
    white_point: f32,
}

/// The first depth/stencil format the device can render and copy.
pub fn depth_stencil_format(ctx: &Context) -> Result<vk::Format> {
    for f in [
        vk::Format::D32_SFLOAT_S8_UINT,
        vk::Format::D24_UNORM_S8_UINT,
    ] {
        if ctx.format_supports(
            f,
            vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
                | vk::FormatFeatureFlags::TRANSFER_SRC
                | vk::FormatFeatureFlags::TRANSFER_DST,
        ) {
            return Ok(f);
        }
    }
    bail!(
        "device '{}' supports no depth/stencil format dermis can use (D32S8 or D24S8)",
        ctx.facts.name
    )
}

/// Every target of the frame, with its id in the graph.
pub struct Targets {
    pub shadow: (ImageId, Image),
    pub diffuse: (ImageId, Image),
    pub specular: (ImageId, Image),
    pub linear_depth: (ImageId, Image),
    pub depth_stencil: (ImageId, Image),
    pub sss_tmp: (ImageId, Image),
    pub sss_tmp2: (ImageId, Image),
    pub hdr: (ImageId, Image),
    pub ldr: (ImageId, Image),
    /// View-space normals (only for methods that need them: poisson).
    pub normals: Option<(ImageId, Image)>,
    /// The ground truth's output (RGBA32F storage image; reference only).
    pub reference_out: Option<(ImageId, Image)>,
    /// Graph ids of mip levels 1.. of each mipped target (diffuse, linear depth,
    /// normals), keyed by the target's id: each level is tracked apart, since the
    /// mip passes read one level and write the next.
    pub mip_levels: std::collections::HashMap<ImageId, Vec<ImageId>>,
}

impl Targets {
    fn new(
        ctx: &Context,
        res: &mut Resources,
        extent: vk::Extent2D,
        shadow_size: u32,
        chain_levels: u32,
        reference: bool,
    ) -> Result<Self> {
        let color_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::TRANSFER_DST;
        if !ctx.format_supports(
            LINEAR_DEPTH_FORMAT,
            vk::FormatFeatureFlags::COLOR_ATTACHMENT
                | vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR,
        ) {
            bail!(
                "device '{}' cannot render to and linearly filter R32_SFLOAT (linear depth)",
                ctx.facts.name
            );
        }
        let ds_format = depth_stencil_format(ctx)?;
        let mut mip_levels = std::collections::HashMap::new();
        let mut add_levels = |name: &str,
                              ext: vk::Extent2D,
                              format: vk::Format,
                              usage: vk::ImageUsageFlags,
                              levels: u32|
         -> Result<(ImageId, Image)> {
            let img = Image::with_levels(ctx, name, ext, format, usage, levels)?;
            let id = res.add_image(name, img.raw, img.subresource_range());
            if img.levels > 1 {
                let ids = (1..img.levels)
                    .map(|l| res.add_image(&format!("{name} mip {l}"), img.raw, img.level_range(l)))
                    .collect::<Vec<_>>();
                mip_levels.insert(id, ids);
            }
            Ok((id, img))
        };
        let normals = if chain_levels > 1 {
            Some(add_levels(
                "normals",
                extent,
                DIFFUSE_FORMAT,
                color_usage,
                chain_levels,
            )?)
        } else {
            None
        };
        let diffuse = add_levels("diffuse", extent, DIFFUSE_FORMAT, color_usage, chain_levels)?;
        let linear_depth = add_levels(
            "linear depth",
            extent,
            LINEAR_DEPTH_FORMAT,
            color_usage,
            chain_levels,
        )?;
        let reference_out = if reference {
            Some(add_levels(
                "reference",
                extent,
                vk::Format::R32G32B32A32_SFLOAT,
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC,
                1,
            )?)
        } else {
            None
        };
        let mut add =
            |name: &str, ext: vk::Extent2D, format: vk::Format, usage: vk::ImageUsageFlags| {
                add_levels(name, ext, format, usage, 1)
            };
        let shadow_ext = vk::Extent2D {
            width: shadow_size,
            height: shadow_size,
        };
        Ok(Targets {
            shadow: add(
                "shadow map",
                shadow_ext,
                SHADOW_FORMAT,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            )?,
            diffuse,
            specular: add("specular", extent, DIFFUSE_FORMAT, color_usage)?,
            linear_depth,
            depth_stencil: add(
                "depth stencil",
                extent,
                ds_format,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )?,
            sss_tmp: add("sss intermediate", extent, DIFFUSE_FORMAT, color_usage)?,
            sss_tmp2: add("sss intermediate 2", extent, DIFFUSE_FORMAT, color_usage)?,
            hdr: add("hdr", extent, DIFFUSE_FORMAT, color_usage)?,
            ldr: add(
                "ldr",
                extent,
                LDR_FORMAT,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            )?,
            normals,
            reference_out,
            mip_levels,
        })
    }

    fn all_mut(&mut self) -> Vec<&mut Image> {
        let mut v: Vec<&mut Image> = self
            .normals
            .as_mut()
            .map(|n| &mut n.1)
            .into_iter()
            .collect();
        v.extend([
            &mut self.sss_tmp2.1,
            &mut self.shadow.1,
            &mut self.diffuse.1,
            &mut self.specular.1,
            &mut self.linear_depth.1,
            &mut self.depth_stencil.1,
            &mut self.sss_tmp.1,
            &mut self.hdr.1,
            &mut self.ldr.1,
        ]);
        v
    }

    /// Image by graph id (for dumps).
    pub fn by_id(&self, id: ImageId) -> Option<&Image> {
        let fixed = [
            &self.shadow,
            &self.diffuse,
            &self.specular,
            &self.linear_depth,
            &self.depth_stencil,
            &self.sss_tmp,
            &self.sss_tmp2,
            &self.hdr,
            &self.ldr,
        ];
        fixed
            .into_iter()
            .chain(self.normals.as_ref())
            .chain(self.reference_out.as_ref())
            .find(|(i, _)| *i == id)
            .map(|(_, img)| img)
    }
}

/// Everything the frame's passes read; immutable while a frame is recorded.
pub struct FrameGpu {
    pub settings: RenderSettings,
    pub extent: vk::Extent2D,
    pub mm_per_unit: f32,
    pub scene_name: String,
    pub targets: Targets,
    pub camera: Camera,
    pub light_frame: LightFrame,
    samplers: Samplers,
    pool: DescriptorPool,
    shadow_pipeline: Pipeline,
    geometry_pipeline: Pipeline,
    composite_pipeline: Pipeline,
    tonemap_pipeline: Pipeline,
    frame_set: vk::DescriptorSet,
    composite_set: vk::DescriptorSet,
    tonemap_set: vk::DescriptorSet,
    frame_ubo: Buffer,
    beckmann: Image,
    objects: Vec<GpuObject>,
    instances: Vec<Mat4>,
    pub sss: Option<SssMethod>,
    /// Where the SSS passes work (see `region.rs`); change it with `set_region`,
    /// which keeps the scissors that the passes read in step.
    pub region_px: Vec<region::PixelRect>,
    sss_region: Vec<vk::Rect2D>,
    screen_rect: Vec<vk::Rect2D>,
}

/// The SSS step of the frame, one variant per method.
pub enum SssMethod {
    Separable(SeparableSss),
    Ssg(SsgSss),
    Jittered(JitteredSss),
    Poisson(PoissonSss),
    Reference(ReferenceSss),
}

impl SssMethod {
    /// How far (pixels) the taps of a skin pixel at view depth `depth` reach
    /// into texels a seed copy must have written; `None` for a method that
    /// works on the whole screen (the reference gathers in compute).
    fn reach_px(&self, depth: f32, scale: &region::ReachScale) -> Option<f32> {
        match self {
            SssMethod::Separable(s) => Some(s.reach_px(depth, scale)),
            SssMethod::Ssg(s) => Some(s.reach_px(depth, scale)),
            SssMethod::Jittered(s) => Some(s.reach_px(depth, scale)),
            // Poisson reads the complete diffuse chain, never a seed: its region
            // only has to hold the skin pixels it shades.
            SssMethod::Poisson(_) => Some(0.0),
            SssMethod::Reference(_) => None,
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        match self {
            SssMethod::Separable(s) => s.destroy(ctx),
            SssMethod::Ssg(s) => s.destroy(ctx),
            SssMethod::Jittered(s) => s.destroy(ctx),
            SssMethod::Poisson(s) => s.destroy(ctx),
            SssMethod::Reference(s) => s.destroy(ctx),
        }
    }
}

pub struct Renderer<'c> {
    pub ctx: &'c Context,
    pub gpu: FrameGpu,
    pub resources: Resources,
    profiler: Profiler,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

/// A finished frame read back to the host.
pub struct Capture {
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub ldr: Vec<u8>,
    pub width: u32,
    pub height: u32,
    /// Every pass output (with `dump`), linear float.
    pub dumps: Vec<DumpedImage>,
    pub samples: Vec<PassSample>,
    /// The diffuse light after SSS (what the composite reads), linear float;
    /// alpha is the SSS strength, so alpha > 0 marks skin.
    pub diffuse: Vec<[f32; 4]>,
}

impl<'c> Renderer<'c> {
    pub fn new(ctx: &'c Context, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        settings.validate(ctx.facts.max_image_dimension_2d)?;
        let extent = vk::Extent2D {
            width: settings.width,
            height: settings.height,
        };
        let mut resources = Resources::default();
        let chain_levels = if settings.method == Method::Poisson {
            levels_for(extent)
        } else {
            1
        };
        let targets = Targets::new(
            ctx,
            &mut resources,
            extent,
            settings.shadow_size,
            chain_levels,
            settings.method == Method::Reference,
        )?;
        let samplers = Samplers::new(ctx)?;
        let pool = DescriptorPool::new(ctx, 64)?;
        let ds_format = targets.depth_stencil.1.format;

        let shadow_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "shadow".into(),
                vert: "shadow.vert",
                frag: None,
                color_formats: vec![],
                depth_format: Some(SHADOW_FORMAT),
                stencil_format: None,
                vertex_input: VertexInput::MeshPositionOnly,
                // No culling: thin parts (ears) must cast from both faces.
                cull: vk::CullModeFlags::NONE,
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::LESS,
                stencil: None,
                depth_bias: Some((0.0, 1.5)),
                blend: crate::vk::pipeline::Blend::None,
            },
        )?;
        let geometry_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "geometry".into(),
                vert: "geometry.vert",
                frag: Some(if targets.normals.is_some() {
                    "geometry_normals.frag"
                } else {
                    "geometry.frag"
                }),
                color_formats: if targets.normals.is_some() {
                    vec![
                        DIFFUSE_FORMAT,
                        DIFFUSE_FORMAT,
                        LINEAR_DEPTH_FORMAT,
                        DIFFUSE_FORMAT,
                    ]
                } else {
                    vec![DIFFUSE_FORMAT, DIFFUSE_FORMAT, LINEAR_DEPTH_FORMAT]
                },
                depth_format: Some(ds_format),
                stencil_format: Some(ds_format),
                vertex_input: VertexInput::Mesh,
                cull: vk::CullModeFlags::BACK,
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::LESS,
                // Every drawn pixel gets the object's skin bit (reference per draw).
                stencil: Some(vk::StencilOpState {
                    fail_op: vk::StencilOp::KEEP,
                    pass_op: vk::StencilOp::REPLACE,
                    depth_fail_op: vk::StencilOp::KEEP,
                    compare_op: vk::CompareOp::ALWAYS,
                    compare_mask: 0xff,
                    write_mask: STENCIL_SKIN,
                    reference: 0,
                }),
                depth_bias: None,
                blend: crate::vk::pipeline::Blend::None,
            },
        )?;
        let composite_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen("composite", "composite.frag", DIFFUSE_FORMAT),
        )?;
        let tonemap_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen("tonemap", "tonemap.frag", LDR_FORMAT),
        )?;

        // Beckmann texture for the specular lobe (seed 004).
        const BECKMANN_SIZE: usize = 256;
        let lut: Vec<u16> = beckmann_lut(BECKMANN_SIZE)
            .iter()
            .map(|&v| half::f16::from_f32(v).to_bits())
            .collect();
        let beckmann = upload::texture(
            ctx,
            "beckmann",
            vk::Extent2D {
                width: BECKMANN_SIZE as u32,
                height: BECKMANN_SIZE as u32,
            },
            vk::Format::R16_SFLOAT,
            bytemuck::cast_slice(&lut),
        )?;

        // Camera and light from the scene and the settings.
        let head_height = scene.head_height_units();
        let center = scene.head_center();
        let local_bounds = scene.head_bounds;
        let instances = head_grid(settings.heads, &local_bounds);
        let gb = grid_bounds(settings.heads, &local_bounds);
        let aspect = settings.width as f32 / settings.height as f32;
        // Many heads: pull back so the whole grid stays in view.
        let grid_h = gb.size().y.max(gb.size().x / aspect);
        let fit = if settings.heads > 1 {
            (grid_h / head_height).max(1.0)
        } else {
            1.0
        };
        let target = if settings.heads > 1 {
            gb.center()
        } else {
            center
        };
        let camera = Camera::framing(
            target,
            scene.forward,
            head_height,
            settings.distance_heads * fit,
            settings.fovy_deg,
        );
        let light_dir = settings.light.direction_to_light(scene.forward);
        let light_frame = shadow_frame(light_dir, gb.center(), gb.bounding_radius());

        let light = settings.light;
        let mm = scene.mm_per_unit;
        // Receiver bias: 0.5 mm along the light, in shadow-map depth units.
        let bias = 0.5 / mm / light_frame.depth_range_units;
        let uniforms = FrameUniforms {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            view: camera.view().to_cols_array_2d(),
            light_view_proj: light_frame.view_proj.to_cols_array_2d(),
            camera_pos: camera.eye.extend(1.0).to_array(),
            light_dir: light_dir.extend(0.0).to_array(),
            light_color: [
                light.color[0] * light.intensity,
                light.color[1] * light.intensity,
                light.color[2] * light.intensity,
                0.0,
            ],
            ambient: [settings.ambient; 4],
            params: [
                mm,
                light_frame.depth_range_units,
                shrink_units(mm),
                // The reference gets light through thin parts from the integral itself.
                if settings.transmittance && settings.method != Method::Reference {
                    1.0
                } else {
                    0.0
                },
            ],
            shadow_params: [
                1.0 / settings.shadow_size as f32,
                bias,
                settings.transmittance_profile.exponent_scale(),
                0.0,
            ],
        };
        let frame_ubo = Buffer::with_data(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let frame_binds = |binds_beckmann: vk::ImageView| -> Vec<(&'static str, Bind)> {
            vec![
                (
                    "frame",
                    Bind::Uniform {
                        buffer: frame_ubo.raw,
                        size: std::mem::size_of::<FrameUniforms>() as u64,
                    },
                ),
                ("shadowMap", Bind::Texture(targets.shadow.1.view)),
                ("shadowCompare", Bind::Sampler(samplers.shadow_compare)),
                ("nearestClamp", Bind::Sampler(samplers.nearest_clamp)),
                ("beckmannTex", Bind::Texture(binds_beckmann)),
                ("linearClamp", Bind::Sampler(samplers.linear_clamp)),
            ]
        };
        let frame_set = pool.write_set(ctx, &geometry_pipeline, 0, &frame_binds(beckmann.view))?;
        let composite_set = pool.write_set(
            ctx,
            &composite_pipeline,
            0,
            &[
                // Methods that read the diffuse mip chain leave their result in the intermediate.
                (
                    "diffuseTex",
                    Bind::Texture(if settings.method == Method::Poisson {
                        targets.sss_tmp.1.view
                    } else if let Some(r) = &targets.reference_out {
                        r.1.view
                    } else {
                        targets.diffuse.1.view
                    }),
                ),
                ("specularTex", Bind::Texture(targets.specular.1.view)),
            ],
        )?;
        let tonemap_set = pool.write_set(
            ctx,
            &tonemap_pipeline,
            0,
            &[("hdrTex", Bind::Texture(targets.hdr.1.view))],
        )?;

        let mut objects = Vec::new();
        if let Some(b) = &scene.backdrop {
            objects.push(GpuObject::new(
                ctx,
                "backdrop",
                b,
                &pool,
                &geometry_pipeline,
                &samplers,
            )?);
        }
        objects.push(GpuObject::new(
            ctx,
            "head",
            &scene.head,
            &pool,
            &geometry_pipeline,
            &samplers,
        )?);

        let stretch = Stretch::for_view(settings.height, settings.fovy_deg.to_radians(), mm);
        let proj = camera.proj(aspect);
        // The depth-buffer value of a surface at linear view depth d.
        let to_ndc = move |d: f32| {
            let c = proj * glam::Vec4::new(0.0, 0.0, -d, 1.0);
            c.z / c.w
        };
        let sss = match settings.method {
            Method::Separable => {
                let kernel = SeparableKernel::build(settings.params, settings.samples)?;
                Some(SssMethod::Separable(SeparableSss::new(
                    ctx,
                    &pool,
                    &samplers,
                    kernel,
                    &targets.diffuse.1,
                    &targets.sss_tmp.1,
                    &targets.linear_depth.1,
                    ds_format,
                )?))
            }
            Method::Ssg => Some(SssMethod::Ssg(SsgSss::new(
                ctx,
                &pool,
                &samplers,
                SsgInit {
                    gaussians: ssg_gaussians(settings.fit),
                    stretch,
                    lod: settings.lod,
                    mask: settings.mask,
                    to_ndc: &to_ndc,
                },
                &targets.sss_tmp.1,
                &targets.sss_tmp2.1,
                &targets.linear_depth.1,
                ds_format,
            )?)),
            Method::SsJittered => Some(SssMethod::Jittered(JitteredSss::new(
                ctx,
                &pool,
                &samplers,
                hable_kernel(),
                stretch,
                &targets.sss_tmp.1,
                &targets.linear_depth.1,
                ds_format,
            )?)),
            Method::Poisson => Some(SssMethod::Poisson(PoissonSss::new(
                ctx,
                &pool,
                &samplers,
                &targets.diffuse.1,
                &targets.linear_depth.1,
                &targets
                    .normals
                    .as_ref()
                    .context("poisson needs the normal target")?
                    .1,
                ds_format,
            )?)),
            Method::Reference => {
                let head = objects
                    .iter()
                    .find(|o| o.skin)
                    .context("the reference needs a skin object")?;
                Some(SssMethod::Reference(ReferenceSss::new(
                    ctx,
                    &pool,
                    &mut resources,
                    ReferenceInit {
                        head: &scene.head.mesh,
                        instances: &instances,
                        mm_per_unit: mm,
                        density: settings.reference_density,
                        inv_view: camera.view().inverse(),
                        tan_half_fovy: (0.5 * settings.fovy_deg.to_radians()).tan(),
                        aspect,
                        frame_binds: frame_binds(beckmann.view),
                        material_binds: head.material_binds(&samplers),
                    },
                    &targets.diffuse.1,
                    &targets.linear_depth.1,
                    &targets
                        .reference_out
                        .as_ref()
                        .context("the reference output target")?
                        .1,
                )?))
            }
            Method::None => None,
        };

        // Where the SSS passes have work: near the skin's projected bounds.
        let full = region::PixelRect::full(extent.width, extent.height);
        let region_px = match &sss {
            // The reference gathers in compute over the whole screen.
            Some(SssMethod::Reference(_)) | None => vec![full],
            Some(method) if settings.sss_region == region::RegionMode::Skin => {
                let view = region::RegionView {
                    view: camera.view(),
                    proj,
                    near: camera.near,
                    width: extent.width,
                    height: extent.height,
                };
                skin_region(scene, &instances, &view, settings, method)
            }
            _ => vec![full],
        };

        // Texels of the intermediates outside the region are never written: zero
        // them once so a dump of an intermediate shows black there, not old memory.
        if region_px != [full] {
            fill_intermediates(ctx, &targets, &mut resources, 0.0)?;
        }

        let profiler = Profiler::new(ctx, 64)?;
        let cmd = unsafe {
            ctx.device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(ctx.command_pool)
                    .command_buffer_count(1),
            )
        }?[0];
        ctx.name(cmd, "frame commands");
        let fence = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }?;
        ctx.name(fence, "frame fence");

        let mut gpu = FrameGpu {
            settings: settings.clone(),
            extent,
            mm_per_unit: mm,
            scene_name: scene.name.clone(),
            targets,
            camera,
            light_frame,
            samplers,
            pool,
            shadow_pipeline,
            geometry_pipeline,
            composite_pipeline,
            tonemap_pipeline,
            frame_set,
            composite_set,
            tonemap_set,
            frame_ubo,
            beckmann,
            objects,
            instances,
            sss,
            sss_region: Vec::new(),
            region_px: Vec::new(),
            screen_rect: draw::scissors(&[full]),
        };
        gpu.set_region(region_px);
        ctx.check_validation("while setting up the renderer")?;
        Ok(Renderer {
            ctx,
            gpu,
            resources,
            profiler,
            cmd,
            fence,
        })
    }

    /// Records, submits and waits for one frame; returns its per-pass samples and
    /// the dumps/readbacks the plan asked for.
    fn run_frame(&mut self, plan: Option<&mut ReadbackPlan>) -> Result<Vec<PassSample>> {
        let ctx = self.ctx;
        let mut passes = self.gpu.passes();
        if let Some(plan) = plan {
            passes = plan.interleave(ctx, &mut self.resources, passes, &self.gpu)?;
        }
        submit_passes(
            ctx,
            self.cmd,
            self.fence,
            &mut self.resources,
            &passes,
            Some(&self.profiler),
            "during the frame",
        )
    }

    /// Renders `n` frames and returns each frame's pass samples.
    pub fn frames(
        &mut self,
        n: usize,
        mut progress: impl FnMut(usize),
    ) -> Result<Vec<Vec<PassSample>>> {
        let mut all = Vec::with_capacity(n);
        for i in 0..n {
            all.push(self.run_frame(None)?);
            progress(i + 1);
        }
        Ok(all)
    }

    /// Renders one frame and reads back the tone-mapped image, and with `dump`
    /// every pass output.
    pub fn capture(&mut self, dump: bool) -> Result<Capture> {
        let mut plan = ReadbackPlan::new(dump, self.gpu.targets.ldr.0);
        let samples = self.run_frame(Some(&mut plan))?;
        let (ldr, dumps) = plan.finish(self.ctx, &mut self.resources, &self.gpu)?;
        // Readback passes are bookkeeping, not frame cost.
        let samples = samples
            .into_iter()
            .filter(|s| !ReadbackPlan::is_readback_pass(&s.name))
            .collect();
        let diffuse = self.read_back(self.gpu.final_diffuse().0)?;
        Ok(Capture {
            ldr,
            width: self.gpu.extent.width,
            height: self.gpu.extent.height,
            dumps,
            samples,
            diffuse,
        })
    }

    /// Fills the SSS intermediates with `value` (tests): texels the seed copies
    /// skip keep it, so a tap that reads one shows in the output.
    pub fn poison_intermediates(&mut self, value: f32) -> Result<()> {
        fill_intermediates(self.ctx, &self.gpu.targets, &mut self.resources, value)
    }

    /// Reads one frame image back as linear float RGBA (after a frame: its
    /// contents stay until the next frame writes them).
    pub fn read_back(&mut self, id: ImageId) -> Result<Vec<[f32; 4]>> {
        let ctx = self.ctx;
        let mut plan = ReadbackPlan::single(id);
        let passes = plan.interleave(ctx, &mut self.resources, Vec::new(), &self.gpu)?;
        submit_passes(
            ctx,
            self.cmd,
            self.fence,
            &mut self.resources,
            &passes,
            None,
            "while reading back an image",
        )?;
        drop(passes);
        plan.finish_single(ctx, &mut self.resources, &self.gpu)
    }

    /// The depth-buffer value of a surface at linear view depth `d` (this camera).
    pub fn ndc_depth(&self, d: f32) -> f32 {
        let aspect = self.gpu.extent.width as f32 / self.gpu.extent.height as f32;
        let c = self.gpu.camera.proj(aspect) * glam::Vec4::new(0.0, 0.0, -d, 1.0);
        c.z / c.w
    }

    /// Uploads synthetic inputs into the SSS targets (tests): diffuse RGBA as f16,
    /// linear depth (the depth buffer gets the matching projected depth), and the
    /// stencil skin bit. Leaves them ready for the SSS passes.
    pub fn upload_sss_inputs(
        &mut self,
        diffuse_f16: &[u16],
        depth: &[f32],
        skin: &[bool],
    ) -> Result<()> {
        let ndc: Vec<f32> = depth
            .iter()
            .map(|&d| self.ndc_depth(d).clamp(0.0, 1.0))
            .collect();
        let t = &self.gpu.targets;
        upload::fill_image(
            self.ctx,
            &t.diffuse.1,
            vk::ImageAspectFlags::COLOR,
            bytemuck::cast_slice(diffuse_f16),
            AccessKind::FragmentSampledRead,
        )?;
        upload::fill_image(
            self.ctx,
            &t.linear_depth.1,
            vk::ImageAspectFlags::COLOR,
            bytemuck::cast_slice(depth),
            AccessKind::FragmentSampledRead,
        )?;
        let stencil: Vec<u8> = skin
            .iter()
            .map(|&s| if s { STENCIL_SKIN as u8 } else { 0 })
            .collect();
        upload::fill_depth_stencil(
            self.ctx,
            &t.depth_stencil.1,
            &ndc,
            &stencil,
            AccessKind::DepthStencilReadOnly,
        )?;
        self.resources.images[t.diffuse.0 .0].state =
            ResourceState::uploaded(AccessKind::FragmentSampledRead);
        self.resources.images[t.linear_depth.0 .0].state =
            ResourceState::uploaded(AccessKind::FragmentSampledRead);
        self.resources.images[t.depth_stencil.0 .0].state =
            ResourceState::uploaded(AccessKind::DepthStencilReadOnly);
        // The skin is wherever the upload says, not where the scene's boxes project.
        let full = region::PixelRect::full(self.gpu.extent.width, self.gpu.extent.height);
        self.gpu.set_region(vec![full]);
        Ok(())
    }

    /// Uploads synthetic view-space normals (RGBA f16) into level 0 of the normal
    /// target (tests of methods that read normals).
    pub fn upload_normals(&mut self, normals_f16: &[u16]) -> Result<()> {
        let (id, img) = self
            .gpu
            .targets
            .normals
            .as_ref()
            .context("this method has no normal target")?;
        upload::fill_image(
            self.ctx,
            img,
            vk::ImageAspectFlags::COLOR,
            bytemuck::cast_slice(normals_f16),
            AccessKind::FragmentSampledRead,
        )?;
        self.resources.images[id.0].state =
            ResourceState::uploaded(AccessKind::FragmentSampledRead);
        Ok(())
    }

    /// Runs only the SSS passes on whatever the targets hold (tests) and reads
    /// back the diffuse target as f32 RGBA with the pass samples.
    pub fn run_sss_only(&mut self) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
        if self.gpu.sss.is_none() {
            bail!("the SSS-only run needs an SSS method");
        }
        let passes = self.gpu.sss_passes();
        let mut plan = ReadbackPlan::single(self.gpu.final_diffuse().0);
        let passes = plan.interleave(self.ctx, &mut self.resources, passes, &self.gpu)?;
        let ctx = self.ctx;
        let samples = submit_passes(
            ctx,
            self.cmd,
            self.fence,
            &mut self.resources,
            &passes,
            Some(&self.profiler),
            "during the SSS-only run",
        )?;
        drop(passes);
        let img = plan.finish_single(ctx, &mut self.resources, &self.gpu)?;
        Ok((
            img,
            samples
                .into_iter()
                .filter(|s| !ReadbackPlan::is_readback_pass(&s.name))
                .collect(),
        ))
    }
}

/// The SSS region of `method` in this scene and view (see `region.rs`): every
/// skin object's triangle clusters, once per instance, widened by the reach.
fn skin_region(
    scene: &Scene,
    instances: &[Mat4],
    view: &region::RegionView,
    settings: &RenderSettings,
    method: &SssMethod,
) -> Vec<region::PixelRect> {
    let skin: Vec<&crate::scene::mesh::Object> = scene
        .backdrop
        .iter()
        .chain(std::iter::once(&scene.head))
        .filter(|o| o.material.skin)
        .collect();
    let scale = region::ReachScale {
        height_px: view.height,
        tan_half_fovy: (0.5 * settings.fovy_deg.to_radians()).tan(),
        mm_per_unit: scene.mm_per_unit,
        max_strength: skin
            .iter()
            .map(|o| o.material.sss_strength)
            .fold(0.0, f32::max),
    };
    // Skin objects are drawn once per instance (see the geometry pass).
    let boxes: Vec<crate::scene::mesh::Aabb> = skin
        .iter()
        .flat_map(|o| {
            let clusters = region::cluster_bounds(&o.mesh, REGION_CLUSTER_CELLS);
            instances
                .iter()
                .flat_map(move |m| clusters.clone().into_iter().map(move |b| b.transformed(m)))
        })
        .collect();
    region::skin_region(
        view,
        boxes,
        |d| method.reach_px(d, &scale).unwrap_or(f32::INFINITY),
        settings.sss_region_tile,
    )
}

/// Fills both SSS intermediates with `value` in every channel.
fn fill_intermediates(
    ctx: &Context,
    targets: &Targets,
    resources: &mut Resources,
    value: f32,
) -> Result<()> {
    let e = targets.sss_tmp.1.extent;
    let texel = half::f16::from_f32(value).to_bits().to_le_bytes();
    let bytes: Vec<u8> = std::iter::repeat_n(texel, e.width as usize * e.height as usize * 4)
        .flatten()
        .collect();
    for (id, img) in [&targets.sss_tmp, &targets.sss_tmp2] {
        upload::fill_image(
            ctx,
            img,
            vk::ImageAspectFlags::COLOR,
            &bytes,
            AccessKind::FragmentSampledRead,
        )?;
        resources.images[id.0].state = ResourceState::uploaded(AccessKind::FragmentSampledRead);
    }
    Ok(())
}

/// Records `passes` into `cmd`, submits them, waits on `fence` and checks the
/// validation log: the one submission path of the renderer. Returns the pass
/// samples (empty without a profiler).
fn submit_passes(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    resources: &mut Resources,
    passes: &[Pass],
    profiler: Option<&Profiler>,
    when: &str,
) -> Result<Vec<PassSample>> {
    let names: Vec<String> = passes.iter().map(|p| p.name.clone()).collect();
    unsafe {
        ctx.device
            .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())?;
        ctx.device.begin_command_buffer(
            cmd,
            &vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
        )?;
    }
    record_passes(ctx, cmd, resources, passes, profiler);
    unsafe {
        ctx.device.end_command_buffer(cmd)?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        ctx.device
            .queue_submit2(ctx.queue, &submit, fence)
            .with_context(|| format!("submitting {when}"))?;
        ctx.device
            .wait_for_fences(&[fence], true, u64::MAX)
            .with_context(|| format!("waiting {when} (device lost?)"))?;
        ctx.device.reset_fences(&[fence])?;
    }
    ctx.check_validation(when)?;
    match profiler {
        Some(p) => p.read(ctx, &names),
        None => Ok(Vec::new()),
    }
}

impl FrameGpu {
    fn set_region(&mut self, px: Vec<region::PixelRect>) {
        self.sss_region = draw::scissors(&px);
        self.region_px = px;
    }

    /// Any image of the frame by graph id: the targets, and images a method owns.
    pub fn image_by_id(&self, id: ImageId) -> Option<&Image> {
        self.targets.by_id(id).or(match &self.sss {
            Some(SssMethod::Reference(r)) if r.radiance_id == id => Some(&r.radiance),
            _ => None,
        })
    }

    /// The per-level ids of the diffuse, depth and normal mip chains (poisson).
    pub fn chains(&self) -> Chains {
        let t = &self.targets;
        let chain = |main: &(ImageId, Image)| -> Vec<(ImageId, vk::ImageView)> {
            let above = t.mip_levels.get(&main.0).map(Vec::as_slice).unwrap_or(&[]);
            std::iter::once(main.0)
                .chain(above.iter().copied())
                .zip(main.1.level_views.iter().copied())
                .collect()
        };
        let normals = t
            .normals
            .as_ref()
            .expect("poisson allocates the normal target");
        Chains {
            color: chain(&t.diffuse),
            depth: chain(&t.linear_depth),
            normal: chain(normals),
            extents: (0..t.diffuse.1.levels)
                .map(|l| t.diffuse.1.level_extent(l))
                .collect(),
        }
    }

    /// The target holding the diffuse light after SSS: the diffuse target itself,
    /// or the intermediate for methods that read the diffuse mip chain.
    pub fn final_diffuse(&self) -> &(ImageId, Image) {
        match (&self.sss, &self.targets.reference_out) {
            (Some(SssMethod::Poisson(_)), _) => &self.targets.sss_tmp,
            (Some(SssMethod::Reference(_)), Some(r)) => r,
            _ => &self.targets.diffuse,
        }
    }

    pub fn screen_targets(&self) -> ScreenTargets<'_> {
        let t = &self.targets;
        ScreenTargets {
            diffuse: (t.diffuse.0, t.diffuse.1.raw, t.diffuse.1.view),
            rt1: (t.sss_tmp.0, t.sss_tmp.1.raw, t.sss_tmp.1.view),
            rt2: (t.sss_tmp2.0, t.sss_tmp2.1.raw, t.sss_tmp2.1.view),
            linear_depth: t.linear_depth.0,
            depth_stencil: (t.depth_stencil.0, t.depth_stencil.1.view),
            extent: self.extent,
            region: &self.sss_region,
            screen: &self.screen_rect,
        }
    }

    /// The SSS method's passes (none without a method).
    pub fn sss_passes(&self) -> Vec<Pass<'_>> {
        match &self.sss {
            Some(SssMethod::Separable(s)) => s.passes(self.screen_targets(), self.sss_view()),
            Some(SssMethod::Ssg(s)) => s.passes(self.screen_targets()),
            Some(SssMethod::Jittered(s)) => s.passes(self.screen_targets()),
            Some(SssMethod::Poisson(s)) => s.passes(
                self.screen_targets(),
                &self.chains(),
                self.settings.fovy_deg.to_radians(),
                self.mm_per_unit,
            ),
            Some(SssMethod::Reference(s)) => {
                let t = &self.targets;
                let out = t.reference_out.as_ref().expect("reference output target");
                s.passes(
                    t.shadow.0,
                    t.diffuse.0,
                    t.linear_depth.0,
                    out.0,
                    self.extent,
                )
            }
            None => Vec::new(),
        }
    }

    pub fn sss_view(&self) -> SssView {
        SssView {
            fovy_rad: self.settings.fovy_deg.to_radians(),
            mm_per_unit: self.mm_per_unit,
            follow_surface: self.settings.follow_surface,
        }
    }

    /// The frame's passes in order.
    pub fn passes(&self) -> Vec<Pass<'_>> {
        let mut passes = vec![self.shadow_pass(), self.geometry_pass()];
        passes.extend(self.sss_passes());
        passes.push(self.composite_pass());
        passes.push(self.tonemap_pass());
        passes
    }

    fn shadow_pass(&self) -> Pass<'_> {
        let (id, img) = &self.targets.shadow;
        let view = img.view;
        let extent = img.extent;
        Pass::new("shadow map")
            .image(*id, AccessKind::DepthStencilWrite)
            .record(move |pc: &PassContext| {
                let ctx = pc.ctx;
                let cmd = pc.cmd;
                let depth = vk::RenderingAttachmentInfo::default()
                    .image_view(view)
                    .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        depth_stencil: vk::ClearDepthStencilValue {
                            depth: 1.0,
                            stencil: 0,
                        },
                    });
                let info = vk::RenderingInfo::default()
                    .render_area(vk::Rect2D {
                        offset: vk::Offset2D::default(),
                        extent,
                    })
                    .layer_count(1)
                    .depth_attachment(&depth);
                unsafe {
                    ctx.device.cmd_begin_rendering(cmd, &info);
                    ctx.device.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.shadow_pipeline.raw,
                    );
                    set_viewport(ctx, cmd, extent);
                }
                // Heads only: the backdrop receives shadows but casts none worth a texel.
                for obj in self.objects.iter().filter(|o| o.skin) {
                    for m in &self.instances {
                        let push = ShadowPush {
                            model: m.to_cols_array_2d(),
                            light_view_proj: self.light_frame.view_proj.to_cols_array_2d(),
                        };
                        self.shadow_pipeline.push(ctx, cmd, &push);
                        obj.bind_and_draw(ctx, cmd);
                    }
                }
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            })
    }

    fn geometry_pass(&self) -> Pass<'_> {
        let t = &self.targets;
        let extent = self.extent;
        let mut views = vec![t.diffuse.1.view, t.specular.1.view, t.linear_depth.1.view];
        let ds_view = t.depth_stencil.1.view;
        let far = self.camera.far;
        let mut pass = Pass::new("geometry")
            .image(t.shadow.0, AccessKind::FragmentSampledRead)
            .image(t.diffuse.0, AccessKind::ColorAttachmentWrite)
            .image(t.specular.0, AccessKind::ColorAttachmentWrite)
            .image(t.linear_depth.0, AccessKind::ColorAttachmentWrite)
            .image(t.depth_stencil.0, AccessKind::DepthStencilWrite);
        if let Some(n) = &t.normals {
            views.push(n.1.view);
            pass = pass.image(n.0, AccessKind::ColorAttachmentWrite);
        }
        pass.record(move |pc: &PassContext| {
            let ctx = pc.ctx;
            let cmd = pc.cmd;
            let clears = [[0.0f32; 4], [0.0; 4], [far, 0.0, 0.0, 0.0], [0.0; 4]];
            let colors: Vec<vk::RenderingAttachmentInfo> = views
                .iter()
                .zip(clears)
                .map(|(&v, c)| {
                    vk::RenderingAttachmentInfo::default()
                        .image_view(v)
                        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                        .load_op(vk::AttachmentLoadOp::CLEAR)
                        .store_op(vk::AttachmentStoreOp::STORE)
                        .clear_value(vk::ClearValue {
                            color: vk::ClearColorValue { float32: c },
                        })
                })
                .collect();
            let ds = vk::RenderingAttachmentInfo::default()
                .image_view(ds_view)
                .image_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: 1.0,
                        stencil: 0,
                    },
                });
            let info = vk::RenderingInfo::default()
                .render_area(vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent,
                })
                .layer_count(1)
                .color_attachments(&colors)
                .depth_attachment(&ds)
                .stencil_attachment(&ds);
            let p = &self.geometry_pipeline;
            unsafe {
                ctx.device.cmd_begin_rendering(cmd, &info);
                ctx.device
                    .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, p.raw);
                set_viewport(ctx, cmd, extent);
                ctx.device.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    p.layout,
                    0,
                    &[self.frame_set],
                    &[],
                );
            }
            for obj in &self.objects {
                unsafe {
                    ctx.device.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        p.layout,
                        1,
                        &[obj.material_set],
                        &[],
                    );
                    ctx.device.cmd_set_stencil_reference(
                        cmd,
                        vk::StencilFaceFlags::FRONT_AND_BACK,
                        if obj.skin { STENCIL_SKIN } else { 0 },
                    );
                }
                let models: &[Mat4] = if obj.skin {
                    &self.instances
                } else {
                    &[Mat4::IDENTITY]
                };
                for m in models {
                    p.push(ctx, cmd, &m.to_cols_array_2d());
                    obj.bind_and_draw(ctx, cmd);
                }
            }
            unsafe { ctx.device.cmd_end_rendering(cmd) };
        })
    }

    fn fullscreen_pass<'a>(
        &'a self,
        name: &str,
        pipeline: &'a Pipeline,
        set: vk::DescriptorSet,
        reads: &[ImageId],
        target: (ImageId, vk::ImageView),
        push: Option<TonemapPush>,
    ) -> Pass<'a> {
        let extent = self.extent;
        let mut pass = Pass::new(name);
        for &r in reads {
            pass = pass.image(r, AccessKind::FragmentSampledRead);
        }
        pass.image(target.0, AccessKind::ColorAttachmentWrite)
            .record(move |pc: &PassContext| {
                let ctx = pc.ctx;
                let cmd = pc.cmd;
                begin_color_rendering(
                    ctx,
                    cmd,
                    &[target.1],
                    extent,
                    vk::AttachmentLoadOp::DONT_CARE,
                );
                unsafe {
                    ctx.device.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        pipeline.raw,
                    );
                    ctx.device.cmd_bind_descriptor_sets(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        pipeline.layout,
                        0,
                        &[set],
                        &[],
                    );
                }
                if let Some(p) = &push {
                    pipeline.push(ctx, cmd, p);
                }
                unsafe {
                    ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
                    ctx.device.cmd_end_rendering(cmd);
                }
            })
    }

    fn composite_pass(&self) -> Pass<'_> {
        let t = &self.targets;
        self.fullscreen_pass(
            "composite",
            &self.composite_pipeline,
            self.composite_set,
            &[self.final_diffuse().0, t.specular.0],
            (t.hdr.0, t.hdr.1.view),
            None,
        )
    }

    fn tonemap_pass(&self) -> Pass<'_> {
        let t = &self.targets;
        self.fullscreen_pass(
            "tonemap",
            &self.tonemap_pipeline,
            self.tonemap_set,
            &[t.hdr.0],
            (t.ldr.0, t.ldr.1.view),
            Some(TonemapPush {
                exposure: self.settings.exposure,
                white_point: 11.2,
            }),
        )
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        unsafe {
            let _ = ctx.device.device_wait_idle();
            ctx.device.destroy_fence(self.fence, None);
            ctx.device
                .free_command_buffers(ctx.command_pool, &[self.cmd]);
        }
        self.profiler.destroy(ctx);
        let g = &mut self.gpu;
        if let Some(s) = &mut g.sss {
            s.destroy(ctx);
        }
        for o in &mut g.objects {
            o.destroy(ctx);
        }
        g.beckmann.destroy(ctx);
        g.frame_ubo.destroy(ctx);
        for p in [
            &mut g.shadow_pipeline,
            &mut g.geometry_pipeline,
            &mut g.composite_pipeline,
            &mut g.tonemap_pipeline,
        ] {
            p.destroy(ctx);
        }
        g.pool.destroy(ctx);
        g.samplers.destroy(ctx);
        for img in g.targets.all_mut() {
            img.destroy(ctx);
        }
    }
}
