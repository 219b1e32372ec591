//! Pipelines described by plain values, with layouts from reflection, and
//! descriptor sets written by binding *name*.

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;

use super::barrier::AccessKind;
use super::context::Context;
use super::error::Error;
use super::guard::{Destroy, Guard};
use super::shader::{create_module, reflect, Reflection};

/// Vertex layout of `scene::mesh::Vertex` (position, normal, uv, tangent; 48 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexInput {
    None,
    Mesh,
    /// Position only (shadow pass), from the same vertex buffer.
    MeshPositionOnly,
}

/// Blending of the colour attachments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    None,
    /// Attachment `n` mixes `src * c + dst * (1 - c)` per channel with the dynamic
    /// blend constant `c` (thesis eq. 4.9; alpha takes the source: constant alpha 1);
    /// the other attachments are written unblended.
    ConstantMix(usize),
    /// Attachment `n` mixes `src * a + dst * (1 - a)` with the source's own
    /// alpha `a`, which it keeps; the others are written unblended.
    AlphaMix(usize),
}

#[derive(Clone, Debug)]
pub struct GraphicsDesc {
    pub name: String,
    pub vert: &'static str,
    pub frag: Option<&'static str>,
    pub color_formats: Vec<vk::Format>,
    pub depth_format: Option<vk::Format>,
    pub stencil_format: Option<vk::Format>,
    pub vertex_input: VertexInput,
    pub cull: vk::CullModeFlags,
    pub depth_test: bool,
    pub depth_write: bool,
    pub depth_compare: vk::CompareOp,
    /// Stencil op state for both faces; the reference is dynamic.
    pub stencil: Option<vk::StencilOpState>,
    pub depth_bias: Option<(f32, f32)>,
    pub blend: Blend,
}

impl GraphicsDesc {
    pub fn fullscreen(name: &str, frag: &'static str, color: vk::Format) -> Self {
        GraphicsDesc {
            name: name.into(),
            vert: "fullscreen.vert",
            frag: Some(frag),
            color_formats: vec![color],
            depth_format: None,
            stencil_format: None,
            vertex_input: VertexInput::None,
            cull: vk::CullModeFlags::NONE,
            depth_test: false,
            depth_write: false,
            depth_compare: vk::CompareOp::ALWAYS,
            stencil: None,
            depth_bias: None,
            blend: Blend::None,
        }
    }
}

/// `Default` is the null object: destroying it does nothing (set-up fills
/// fields one by one in a `Guard`, which destroys whatever exists when a step
/// fails).
#[derive(Default)]
pub struct Pipeline {
    pub raw: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layouts: Vec<vk::DescriptorSetLayout>,
    pub reflection: Reflection,
    pub bind_point: vk::PipelineBindPoint,
    pub name: String,
    /// Whether the pipeline tests stencil (its reference is dynamic state).
    pub has_stencil: bool,
    /// Whether it blends with a constant (the constant is dynamic state).
    pub has_blend_constants: bool,
    /// The fetch-counting build's counter set (set 3) and its pool.
    count_set: Option<(vk::DescriptorPool, vk::DescriptorSet)>,
}

/// Set number of the fetch counters in the counting build (fetch_count.glsl).
const COUNT_SET: u32 = 3;

/// The shader to build a pipeline from: its fetch-counting build when the
/// context counts fetches and the shader has one.
fn variant(ctx: &Context, name: &str) -> String {
    let counted = format!("{name}#count");
    if ctx.fetch_counts.is_some() && super::shader::spirv(&counted).is_ok() {
        counted
    } else {
        name.to_string()
    }
}

/// Allocates and writes the counter set of a counting pipeline (none otherwise).
fn count_set(
    ctx: &Context,
    reflection: &Reflection,
    set_layouts: &[vk::DescriptorSetLayout],
) -> Result<Option<(vk::DescriptorPool, vk::DescriptorSet)>> {
    let (Some(buffer), Some(b)) = (&ctx.fetch_counts, reflection.find(COUNT_SET, "FetchCounts"))
    else {
        return Ok(None);
    };
    let sizes = [vk::DescriptorPoolSize {
        ty: b.descriptor_type,
        descriptor_count: 1,
    }];
    let pool = ctx.create("the fetch counters' descriptor pool", |d| unsafe {
        d.create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default()
                .max_sets(1)
                .pool_sizes(&sizes),
            None,
        )
    })?;
    let pool = Guard::new(ctx, pool);
    let set = unsafe {
        ctx.device.allocate_descriptor_sets(
            &vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(*pool)
                .set_layouts(&set_layouts[COUNT_SET as usize..=COUNT_SET as usize]),
        )
    }
    .map_err(Error::from)?[0];
    let info = [vk::DescriptorBufferInfo {
        buffer: buffer.raw,
        offset: 0,
        range: vk::WHOLE_SIZE,
    }];
    let write = vk::WriteDescriptorSet::default()
        .dst_set(set)
        .dst_binding(b.binding)
        .descriptor_type(b.descriptor_type)
        .buffer_info(&info);
    unsafe { ctx.device.update_descriptor_sets(&[write], &[]) };
    Ok(Some((pool.keep(), set)))
}

fn make_layout(
    ctx: &Context,
    name: &str,
    r: &Reflection,
) -> Result<(vk::PipelineLayout, Vec<vk::DescriptorSetLayout>)> {
    let set_layouts = Guard::new(ctx, r.create_set_layouts(ctx, name)?);
    let ranges: Vec<vk::PushConstantRange> = r
        .push_constants
        .iter()
        .map(|&(offset, size, stages)| vk::PushConstantRange {
            stage_flags: stages,
            offset,
            size,
        })
        .collect();
    let layout = ctx.create(&format!("pipeline layout of '{name}'"), |d| unsafe {
        d.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default()
                .set_layouts(&set_layouts)
                .push_constant_ranges(&ranges),
            None,
        )
    })?;
    ctx.name(layout, &format!("{name} layout"));
    Ok((layout, set_layouts.keep()))
}

impl Pipeline {
    pub fn graphics(ctx: &Context, d: &GraphicsDesc) -> Result<Self> {
        Self::graphics_multisampled(ctx, d, 1)
    }

    /// A graphics pipeline that rasterises `samples` samples per pixel (the
    /// multisampled geometry pass, `--msaa`; 1 is [`Pipeline::graphics`]).
    /// Shading stays per pixel: no sample shading.
    pub fn graphics_multisampled(ctx: &Context, d: &GraphicsDesc, samples: u32) -> Result<Self> {
        let frag = d.frag.map(|f| variant(ctx, f));
        let mut stages_names = vec![d.vert];
        if let Some(f) = &frag {
            stages_names.push(f);
        }
        let reflection =
            reflect(&stages_names).with_context(|| format!("pipeline '{}'", d.name))?;
        let (layout, set_layouts) = make_layout(ctx, &d.name, &reflection)?;
        // Filled in step by step: on an error, the guard frees what exists.
        let mut p = Guard::new(
            ctx,
            Pipeline {
                layout,
                set_layouts,
                reflection,
                bind_point: vk::PipelineBindPoint::GRAPHICS,
                name: d.name.clone(),
                has_stencil: d.stencil.is_some(),
                has_blend_constants: matches!(d.blend, Blend::ConstantMix(_)),
                ..Default::default()
            },
        );
        p.build_graphics(ctx, d, frag.as_deref(), samples)?;
        Ok(p.keep())
    }

    /// The shader modules, the pipeline and the counter set of `graphics`.
    // Long because it is one Vulkan create-info, state block by state block, in
    // the order the structure nests them.
    fn build_graphics(
        &mut self,
        ctx: &Context,
        d: &GraphicsDesc,
        frag: Option<&str>,
        samples: u32,
    ) -> Result<()> {
        let layout = self.layout;
        // The modules go when this returns: the pipeline does not need them.
        let vs = Guard::new(ctx, create_module(ctx, d.vert)?);
        let fs = Guard::new(ctx, frag.map(|f| create_module(ctx, f)).transpose()?);
        let entry = c"main";
        let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(*vs)
            .name(entry)];
        if let Some(fs) = *fs {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(fs)
                    .name(entry),
            );
        }
        let stride = 48u32;
        let vb = [vk::VertexInputBindingDescription {
            binding: 0,
            stride,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        let attrs_full = [
            (0, vk::Format::R32G32B32_SFLOAT, 0),
            (1, vk::Format::R32G32B32_SFLOAT, 12),
            (2, vk::Format::R32G32_SFLOAT, 24),
            (3, vk::Format::R32G32B32A32_SFLOAT, 32),
        ]
        .map(
            |(location, format, offset)| vk::VertexInputAttributeDescription {
                location,
                binding: 0,
                format,
                offset,
            },
        );
        let vi = match d.vertex_input {
            VertexInput::None => vk::PipelineVertexInputStateCreateInfo::default(),
            VertexInput::Mesh => vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&vb)
                .vertex_attribute_descriptions(&attrs_full),
            VertexInput::MeshPositionOnly => vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&vb)
                .vertex_attribute_descriptions(&attrs_full[..1]),
        };
        let ia = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let vp = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let mut rs = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(d.cull)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        if let Some((constant, slope)) = d.depth_bias {
            rs = rs
                .depth_bias_enable(true)
                .depth_bias_constant_factor(constant)
                .depth_bias_slope_factor(slope);
        }
        let ms = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(crate::vk::memory::sample_count(samples)?);
        let mut ds = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(d.depth_test)
            .depth_write_enable(d.depth_write)
            .depth_compare_op(d.depth_compare);
        if let Some(s) = d.stencil {
            ds = ds.stencil_test_enable(true).front(s).back(s);
        }
        let attachments: Vec<vk::PipelineColorBlendAttachmentState> = d
            .color_formats
            .iter()
            .enumerate()
            .map(|(i, _)| match d.blend {
                Blend::ConstantMix(n) if n == i => vk::PipelineColorBlendAttachmentState::default()
                    .blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::CONSTANT_COLOR)
                    .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_CONSTANT_COLOR)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::CONSTANT_ALPHA)
                    .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_CONSTANT_ALPHA)
                    .alpha_blend_op(vk::BlendOp::ADD)
                    .color_write_mask(vk::ColorComponentFlags::RGBA),
                Blend::AlphaMix(n) if n == i => vk::PipelineColorBlendAttachmentState::default()
                    .blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
                    .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ONE)
                    .dst_alpha_blend_factor(vk::BlendFactor::ZERO)
                    .alpha_blend_op(vk::BlendOp::ADD)
                    .color_write_mask(vk::ColorComponentFlags::RGBA),
                _ => vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA),
            })
            .collect();
        let cb = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let mut dynamic = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if d.stencil.is_some() {
            dynamic.push(vk::DynamicState::STENCIL_REFERENCE);
        }
        if matches!(d.blend, Blend::ConstantMix(_)) {
            dynamic.push(vk::DynamicState::BLEND_CONSTANTS);
        }
        let dyn_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&d.color_formats)
            .depth_attachment_format(d.depth_format.unwrap_or(vk::Format::UNDEFINED))
            .stencil_attachment_format(d.stencil_format.unwrap_or(vk::Format::UNDEFINED));
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vi)
            .input_assembly_state(&ia)
            .viewport_state(&vp)
            .rasterization_state(&rs)
            .multisample_state(&ms)
            .depth_stencil_state(&ds)
            .color_blend_state(&cb)
            .dynamic_state(&dyn_state)
            .layout(layout)
            .push_next(&mut rendering);
        ctx.creation_step(&format!("pipeline '{}'", d.name))?;
        self.raw = unsafe {
            ctx.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| Error::from(e))
        .with_context(|| format!("creating pipeline '{}'", d.name))?[0];
        ctx.name(self.raw, &d.name);
        self.count_set = count_set(ctx, &self.reflection, &self.set_layouts)?;
        Ok(())
    }

    /// A compute pipeline from one shader, its layout reflected.
    pub fn compute(ctx: &Context, name: &str, shader: &'static str) -> Result<Self> {
        let shader = variant(ctx, shader);
        let reflection = reflect(&[&shader]).with_context(|| format!("pipeline '{name}'"))?;
        let (layout, set_layouts) = make_layout(ctx, name, &reflection)?;
        // Filled in step by step: on an error, the guard frees what exists.
        let mut p = Guard::new(
            ctx,
            Pipeline {
                layout,
                set_layouts,
                reflection,
                bind_point: vk::PipelineBindPoint::COMPUTE,
                name: name.to_string(),
                ..Default::default()
            },
        );
        // Goes when this returns: the pipeline does not need it.
        let module = Guard::new(ctx, create_module(ctx, &shader)?);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(*module)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        ctx.creation_step(&format!("compute pipeline '{name}'"))?;
        p.raw = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| Error::from(e))
        .with_context(|| format!("creating compute pipeline '{name}'"))?[0];
        ctx.name(p.raw, name);
        p.count_set = count_set(ctx, &p.reflection, &p.set_layouts)?;
        Ok(p.keep())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            ctx.device
                .destroy_pipeline(std::mem::take(&mut self.raw), None);
            ctx.device
                .destroy_pipeline_layout(std::mem::take(&mut self.layout), None);
            if let Some((pool, _)) = self.count_set.take() {
                ctx.device.destroy_descriptor_pool(pool, None);
            }
            for l in self.set_layouts.drain(..) {
                ctx.device.destroy_descriptor_set_layout(l, None);
            }
        }
    }

    /// Binds the pipeline and `sets` as sets 0.. (the one place passes bind).
    pub fn bind(&self, ctx: &Context, cmd: vk::CommandBuffer, sets: &[vk::DescriptorSet]) {
        unsafe {
            ctx.device.cmd_bind_pipeline(cmd, self.bind_point, self.raw);
        }
        self.bind_sets(ctx, cmd, 0, sets);
        if let Some((_, set)) = self.count_set {
            self.bind_sets(ctx, cmd, COUNT_SET, &[set]);
        }
    }

    /// Binds `sets` from set number `first` on.
    pub fn bind_sets(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        first: u32,
        sets: &[vk::DescriptorSet],
    ) {
        if sets.is_empty() {
            return;
        }
        unsafe {
            ctx.device
                .cmd_bind_descriptor_sets(cmd, self.bind_point, self.layout, first, sets, &[])
        };
    }

    /// Pushes constants to every stage of the reflected range.
    pub fn push<T: bytemuck::Pod>(&self, ctx: &Context, cmd: vk::CommandBuffer, value: &T) {
        let (offset, size, stages) = self
            .reflection
            .push_constants
            .unwrap_or_else(|| panic!("pipeline '{}' declares no push constants", self.name));
        let bytes = bytemuck::bytes_of(value);
        // Reflection reports the block's size rounded up to 16 bytes; only that
        // tail padding may be missing from the Rust struct.
        assert!(
            bytes.len() as u32 + 15 >= size,
            "pipeline '{}': push constant struct is {} bytes, shaders use {size}",
            self.name,
            bytes.len()
        );
        let len = (bytes.len() as u32).min(size);
        unsafe {
            ctx.device.cmd_push_constants(
                cmd,
                self.layout,
                stages,
                offset,
                &bytes[offset as usize..len as usize],
            )
        };
    }
}

/// A resource to bind, by the shader's variable name. Textures and samplers are
/// separate objects (`texture2D` + `sampler` in GLSL): naga's SPIR-V reader, which
/// validates every module, does not take combined image samplers.
#[derive(Clone, Copy, Debug)]
pub enum Bind {
    Texture(vk::ImageView),
    Sampler(vk::Sampler),
    /// A whole buffer (uniform or storage, as the shader declares it).
    Uniform {
        buffer: vk::Buffer,
        size: u64,
    },
    /// A range of a buffer (uniform or storage).
    Range {
        buffer: vk::Buffer,
        offset: u64,
        size: u64,
    },
}

/// A descriptor pool sized for the whole renderer (everything is allocated once).
/// `Default` is the null object: destroying it does nothing (set-up fills
/// fields one by one in a `Guard`, which destroys whatever exists when a step
/// fails).
#[derive(Default)]
pub struct DescriptorPool {
    pub raw: vk::DescriptorPool,
}

impl DescriptorPool {
    pub fn new(ctx: &Context, max_sets: u32) -> Result<Self> {
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::SAMPLED_IMAGE,
                descriptor_count: max_sets * 8,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::SAMPLER,
                descriptor_count: max_sets * 4,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                descriptor_count: max_sets * 2,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_IMAGE,
                descriptor_count: max_sets * 2,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: max_sets * 4,
            },
        ];
        ctx.creation_step("descriptor pool")?;
        let raw = unsafe {
            ctx.device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(max_sets)
                    .pool_sizes(&sizes),
                None,
            )
        }
        .map_err(Error::from)
        .context("creating the descriptor pool")?;
        ctx.name(raw, "descriptor pool");
        Ok(DescriptorPool { raw })
    }

    /// Allocates set `set` of `pipeline` and writes every binding from `binds`.
    /// Each binding the shader declares must be given, and each name given must exist.
    pub fn write_set(
        &self,
        ctx: &Context,
        pipeline: &Pipeline,
        set: u32,
        binds: &[(&str, Bind)],
    ) -> Result<vk::DescriptorSet> {
        let layout = *pipeline
            .set_layouts
            .get(set as usize)
            .ok_or_else(|| anyhow!("pipeline '{}' has no descriptor set {set}", pipeline.name))?;
        ctx.creation_step(&format!("set {set} of '{}'", pipeline.name))?;
        let ds = unsafe {
            ctx.device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(self.raw)
                    .set_layouts(&[layout]),
            )
        }
        .map_err(Error::from)
        .with_context(|| format!("allocating set {set} of '{}'", pipeline.name))?[0];
        ctx.name(ds, &format!("{} set {set}", pipeline.name));
        let declared: Vec<_> = pipeline
            .reflection
            .bindings
            .iter()
            .filter(|b| b.set == set)
            .collect();
        for b in &declared {
            if !binds.iter().any(|(n, _)| *n == b.name) {
                bail!(
                    "pipeline '{}': binding '{}' (set {set}) was not given a resource",
                    pipeline.name,
                    b.name
                );
            }
        }
        let mut image_infos = Vec::new();
        let mut buffer_infos = Vec::new();
        let mut targets = Vec::new();
        for (name, bind) in binds {
            let info = pipeline.reflection.find(set, name).ok_or_else(|| {
                anyhow!(
                    "pipeline '{}' has no binding named '{name}' in set {set}",
                    pipeline.name
                )
            })?;
            match bind {
                Bind::Texture(view) => {
                    image_infos.push((
                        info.binding,
                        info.descriptor_type,
                        vk::DescriptorImageInfo {
                            sampler: vk::Sampler::null(),
                            image_view: *view,
                            // The layout the access table gives the kind of
                            // access this descriptor makes (stated once there).
                            image_layout: if info.descriptor_type
                                == vk::DescriptorType::STORAGE_IMAGE
                            {
                                AccessKind::ComputeStorageReadWrite.info().layout
                            } else {
                                AccessKind::FragmentSampledRead.info().layout
                            },
                        },
                    ));
                }
                Bind::Sampler(sampler) => {
                    image_infos.push((
                        info.binding,
                        info.descriptor_type,
                        vk::DescriptorImageInfo {
                            sampler: *sampler,
                            image_view: vk::ImageView::null(),
                            image_layout: vk::ImageLayout::UNDEFINED,
                        },
                    ));
                }
                Bind::Uniform { buffer, size } => {
                    buffer_infos.push((
                        info.binding,
                        info.descriptor_type,
                        vk::DescriptorBufferInfo {
                            buffer: *buffer,
                            offset: 0,
                            range: *size,
                        },
                    ));
                }
                Bind::Range {
                    buffer,
                    offset,
                    size,
                } => {
                    buffer_infos.push((
                        info.binding,
                        info.descriptor_type,
                        vk::DescriptorBufferInfo {
                            buffer: *buffer,
                            offset: *offset,
                            range: *size,
                        },
                    ));
                }
            }
            targets.push(info.binding);
        }
        let mut writes = Vec::new();
        for (binding, ty, info) in &image_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(ds)
                    .dst_binding(*binding)
                    .descriptor_type(*ty)
                    .image_info(std::slice::from_ref(info)),
            );
        }
        for (binding, ty, info) in &buffer_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(ds)
                    .dst_binding(*binding)
                    .descriptor_type(*ty)
                    .buffer_info(std::slice::from_ref(info)),
            );
        }
        unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(ds)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            ctx.device
                .destroy_descriptor_pool(std::mem::take(&mut self.raw), None)
        };
    }
}

/// Samplers used across the renderer.
/// `Default` is the null object: destroying it does nothing (set-up fills
/// fields one by one in a `Guard`, which destroys whatever exists when a step
/// fails).
#[derive(Default)]
pub struct Samplers {
    pub linear_clamp: vk::Sampler,
    pub nearest_clamp: vk::Sampler,
    pub linear_repeat: vk::Sampler,
    /// Depth comparison (LESS_OR_EQUAL) with linear filtering: 2x2 PCF in hardware.
    pub shadow_compare: vk::Sampler,
    /// Bilinear within the mip level `textureLod` names (nearest between levels).
    pub mip_clamp: vk::Sampler,
}

impl Samplers {
    pub fn new(ctx: &Context) -> Result<Self> {
        let make = |name: &str,
                    filter: vk::Filter,
                    mode: vk::SamplerAddressMode,
                    compare: bool,
                    max_lod: f32|
         -> Result<vk::Sampler> {
            let mut info = vk::SamplerCreateInfo::default()
                .mag_filter(filter)
                .min_filter(filter)
                .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
                .address_mode_u(mode)
                .address_mode_v(mode)
                .address_mode_w(mode)
                .max_lod(max_lod)
                .border_color(vk::BorderColor::FLOAT_OPAQUE_WHITE);
            if compare {
                info = info
                    .compare_enable(true)
                    .compare_op(vk::CompareOp::LESS_OR_EQUAL);
            }
            ctx.creation_step(&format!("sampler '{name}'"))?;
            let s = unsafe { ctx.device.create_sampler(&info, None) }
                .map_err(Error::from)
                .with_context(|| format!("creating sampler '{name}'"))?;
            ctx.name(s, name);
            Ok(s)
        };
        use vk::Filter as F;
        use vk::SamplerAddressMode as M;
        // On an error, the guard frees the samplers made so far.
        let mut s = Guard::<Samplers>::null(ctx);
        s.linear_clamp = make("linear clamp", F::LINEAR, M::CLAMP_TO_EDGE, false, 0.0)?;
        s.nearest_clamp = make("nearest clamp", F::NEAREST, M::CLAMP_TO_EDGE, false, 0.0)?;
        s.linear_repeat = make("linear repeat", F::LINEAR, M::REPEAT, false, 0.0)?;
        s.shadow_compare = make("shadow compare", F::LINEAR, M::CLAMP_TO_BORDER, true, 0.0)?;
        s.mip_clamp = make("mip clamp", F::LINEAR, M::CLAMP_TO_EDGE, false, 16.0)?;
        Ok(s.keep())
    }

    pub fn destroy(&self, ctx: &Context) {
        unsafe {
            for s in [
                self.mip_clamp,
                self.linear_clamp,
                self.nearest_clamp,
                self.linear_repeat,
                self.shadow_compare,
            ] {
                ctx.device.destroy_sampler(s, None);
            }
        }
    }
}

impl Destroy for Pipeline {
    fn destroy(&mut self, ctx: &Context) {
        Pipeline::destroy(self, ctx)
    }
}

impl Destroy for DescriptorPool {
    fn destroy(&mut self, ctx: &Context) {
        DescriptorPool::destroy(self, ctx)
    }
}

impl Destroy for Samplers {
    fn destroy(&mut self, ctx: &Context) {
        Samplers::destroy(self, ctx);
        *self = Samplers::default();
    }
}
