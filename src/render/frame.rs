//! The frame around the SSS methods: shadow map (key light, orthographic, so its
//! depth is linear) -> geometry pass into the targets (Lambert + transmittance,
//! Kelemen/Szirmay-Kalos specular, linear depth, each character's group code in
//! the stencil) -> each group's method's passes (one group in a single-method
//! frame) and, in a frame of several, the merges and fades (`groups/`) -> composite
//! (diffuse after SSS + specular) -> Hable tone map -> the post chain's
//! anti-aliasing stage (`crate::post`, `--aa`; none by default).
//!
//! Over 800 lines because every pass the frame itself records (shadow,
//! geometry, composite, tone map, the character ids) reads the private
//! pipelines, sets and instance slots of the one `Frame` they draw from: their
//! pipelines, descriptor sets and passes read best beside that struct.

use anyhow::Result;
use ash::vk;
use glam::Mat4;

use super::groups::merge::Merge;
use super::groups::region::scissors;
use super::groups::{passes as groups, GroupMethod};
use super::scene_gpu::GpuObject;
use super::settings::RenderSettings;
use super::targets::SHADOW_FORMAT;
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{ColorTarget, DepthStencil, ImageId, Load, Pass, PassContext, Resources};
use crate::method::region::PixelRect;
use crate::method::{FrameTargets, FrameView, ViewInfo, STENCIL_SKIN};
use crate::post::{PostBind, PostChain, PostSetup};
use crate::scene::camera::Camera;
use crate::scene::framing::Framing;
use crate::scene::light::LightFrame;
use crate::scene::Scene;
use crate::skin::beckmann::beckmann_lut;
use crate::skin::transmittance::shrink_units;
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{
    Bind, Blend, DescriptorPool, GraphicsDesc, Pipeline, Samplers, VertexInput,
};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload;

/// Descriptor sets the frame's pool holds: the frame's and the objects' few,
/// and every method's (the reference's sets grow with its sample chunks).
const DESCRIPTOR_SETS: u32 = 256;
/// Side of the Beckmann look-up texture (seed 004's specular): 256 x 256 R16F.
const BECKMANN_SIZE: u32 = 256;
/// Receiver bias of the shadow test along the light, in millimetres: half a
/// millimetre keeps skin from shadowing itself at the shadow map's resolution.
const SHADOW_BIAS_MM: f32 = 0.5;
/// Slope-scaled depth bias of the shadow pass (in units of the depth slope):
/// the usual 1.5 against acne on curved skin at grazing light.
const SHADOW_SLOPE_BIAS: f32 = 1.5;
const COMPOSITE_SHADER: &str = "composite.frag";
use crate::shader_constants::PCF_TRIPS;

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
    light_view_proj: [[f32; 4]; 4],
}

/// Push constants of the character-id pass: the id.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct IdPush {
    id: f32,
}

const IDS_SHADER: &str = "geometry_ids.frag";
/// The geometry pass's vertex shader: geometry.vert (what tsd's final pass and
/// the ground truth's surface pass draw one head with) with the model matrix
/// read per instance.
const GEOMETRY_VERT: &str = "geometry_instanced.vert";

/// A full-screen post pass: what it reads (image, shader variable), what it writes.
struct PostPass<'a, 'r> {
    name: &'r str,
    pipeline: &'a Pipeline,
    shader: &'static str,
    set: vk::DescriptorSet,
    reads: &'r [(ImageId, &'r str)],
    target: ImageId,
}

/// The frame's pipelines, uniforms, scene objects and placement.
pub struct Frame {
    pub settings: RenderSettings,
    pub extent: vk::Extent2D,
    pub mm_per_unit: f32,
    pub targets: FrameTargets,
    pub camera: Camera,
    pub light_frame: LightFrame,
    pub instances: Vec<Mat4>,
    /// Model matrix of the non-skin objects (the backdrop).
    backdrop: Mat4,
    pub samplers: Samplers,
    pub pool: DescriptorPool,
    shadow_pipeline: Pipeline,
    geometry_pipeline: Pipeline,
    composite_pipeline: Pipeline,
    /// `--character-ids` only: the pass that writes each head's index + 1
    /// into `character_ids` after the frame (null otherwise).
    ids_pipeline: Pipeline,
    ids_set: vk::DescriptorSet,
    pub character_ids: Option<ImageId>,
    frame_set: vk::DescriptorSet,
    composite_set: vk::DescriptorSet,
    frame_ubo: Buffer,
    beckmann: Image,
    pub objects: Vec<GpuObject>,
    /// The characters of each group with its stencil code, in group order:
    /// the geometry pass draws each group's heads with its code as the
    /// stencil reference (one group of every character, code 1, until
    /// `set_skin_groups`).
    pub skin_groups: Vec<SkinGroup>,
    /// Every character's model matrix, group after group, then the
    /// backdrop's: the shadow, geometry and id passes draw instances of it.
    instance_buffer: Buffer,
    /// Each group's first slot in it and count; the backdrop's slot; each
    /// character's slot.
    group_slots: Vec<(u32, u32)>,
    backdrop_slot: u32,
    character_slots: Vec<u32>,
    /// The instance buffer as the shadow pipeline's set 0 and the geometry
    /// and id pipelines' set 2.
    shadow_set: vk::DescriptorSet,
    instance_set: vk::DescriptorSet,
    ids_instance_set: vk::DescriptorSet,
    screen_rect: Vec<vk::Rect2D>,
    /// The stages after the tone map (`enable_post`; none with `--aa none`).
    pub post: PostChain,
}

/// The heads of one group as the geometry pass draws them.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinGroup {
    pub stencil: u32,
    /// Frame indices (into `Frame::instances`).
    pub characters: Vec<usize>,
}

impl Frame {
    /// Pipelines, uniforms and scene objects (no descriptor set that needs a
    /// frame image yet: `bind` writes those once the images exist).
    /// Pipelines, uniforms and scene objects (no descriptor set that needs a
    /// frame image yet: `bind` writes those once the images exist). On an
    /// error, whatever was made is destroyed.
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        settings: &RenderSettings,
        targets: FrameTargets,
        framing: Framing,
        res: &Resources,
        transmittance: bool,
    ) -> Result<Self> {
        let extent = vk::Extent2D {
            width: settings.width,
            height: settings.height,
        };
        let full = PixelRect::full(extent.width, extent.height);
        let every = (0..framing.instances.len()).collect();
        let f = Frame {
            settings: settings.clone(),
            extent,
            mm_per_unit: scene.mm_per_unit,
            targets,
            camera: framing.camera,
            light_frame: framing.light,
            instances: framing.instances,
            backdrop: framing.backdrop,
            samplers: Samplers::default(),
            pool: DescriptorPool::default(),
            shadow_pipeline: Pipeline::default(),
            geometry_pipeline: Pipeline::default(),
            composite_pipeline: Pipeline::default(),
            ids_pipeline: Pipeline::default(),
            ids_set: vk::DescriptorSet::null(),
            character_ids: None,
            frame_set: vk::DescriptorSet::null(),
            composite_set: vk::DescriptorSet::null(),
            frame_ubo: Buffer::default(),
            beckmann: Image::default(),
            objects: Vec::new(),
            skin_groups: vec![SkinGroup {
                stencil: STENCIL_SKIN,
                characters: every,
            }],
            instance_buffer: Buffer::default(),
            group_slots: Vec::new(),
            backdrop_slot: 0,
            character_slots: Vec::new(),
            shadow_set: vk::DescriptorSet::null(),
            instance_set: vk::DescriptorSet::null(),
            ids_instance_set: vk::DescriptorSet::null(),
            screen_rect: scissors(&[full]),
            post: PostChain::default(),
        };
        // Filled in by `build`: on an error, the guard frees what exists.
        let mut f = Guard::new(ctx, f);
        f.build(ctx, scene, res, transmittance)?;
        Ok(f.keep())
    }

    /// Fills in the frame's objects, each step on its own so a failure leaves
    /// only complete objects for `destroy`.
    fn build(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        res: &Resources,
        transmittance: bool,
    ) -> Result<()> {
        self.samplers = Samplers::new(ctx)?;
        self.pool = DescriptorPool::new(ctx, DESCRIPTOR_SETS)?;
        self.create_pipelines(ctx, res)?;
        let lut: Vec<u16> = beckmann_lut(BECKMANN_SIZE as usize)
            .iter()
            .map(|&v| half::f16::from_f32(v).to_bits())
            .collect();
        self.beckmann = upload::texture(
            ctx,
            "beckmann",
            vk::Extent2D {
                width: BECKMANN_SIZE,
                height: BECKMANN_SIZE,
            },
            vk::Format::R16_SFLOAT,
            bytemuck::cast_slice(&lut),
        )?;
        let uniforms = self.uniforms(scene, transmittance);
        self.frame_ubo = Buffer::with_data(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let objects = scene
            .backdrop
            .iter()
            .map(|b| ("backdrop", b))
            .chain(std::iter::once(("head", &scene.head)));
        for (name, o) in objects {
            let g = GpuObject::new(
                ctx,
                name,
                o,
                &self.pool,
                &self.geometry_pipeline,
                &self.samplers,
            )?;
            self.objects.push(g);
        }
        self.write_instances(ctx)
    }

    /// The instance buffer of `skin_groups` (group after group, then the
    /// backdrop) and the sets that read it.
    fn write_instances(&mut self, ctx: &Context) -> Result<()> {
        let mut models: Vec<[[f32; 4]; 4]> = Vec::new();
        self.group_slots.clear();
        self.character_slots = vec![0; self.instances.len()];
        for g in &self.skin_groups {
            self.group_slots
                .push((models.len() as u32, g.characters.len() as u32));
            for &c in &g.characters {
                self.character_slots[c] = models.len() as u32;
                models.push(self.instances[c].to_cols_array_2d());
            }
        }
        self.backdrop_slot = models.len() as u32;
        models.push(self.backdrop.to_cols_array_2d());
        self.instance_buffer.destroy(ctx);
        self.instance_buffer = Buffer::with_data(
            ctx,
            "character instances",
            bytemuck::cast_slice(&models),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let bind = [(
            "Instances",
            Bind::Uniform {
                buffer: self.instance_buffer.raw,
                size: (models.len() * std::mem::size_of::<[[f32; 4]; 4]>()) as u64,
            },
        )];
        self.shadow_set = self.pool.write_set(ctx, &self.shadow_pipeline, 0, &bind)?;
        self.instance_set = self
            .pool
            .write_set(ctx, &self.geometry_pipeline, 2, &bind)?;
        if self.character_ids.is_some() {
            self.ids_instance_set = self.pool.write_set(ctx, &self.ids_pipeline, 2, &bind)?;
        }
        Ok(())
    }

    fn create_pipelines(&mut self, ctx: &Context, res: &Resources) -> Result<()> {
        let targets = self.targets;
        let ds_format = res.format(targets.depth_stencil);
        self.shadow_pipeline = Pipeline::graphics(
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
                depth_bias: Some((0.0, SHADOW_SLOPE_BIAS)),
                blend: Blend::None,
            },
        )?;
        let color_formats: Vec<vk::Format> =
            [targets.diffuse, targets.specular, targets.linear_depth]
                .into_iter()
                .chain(targets.normals)
                .map(|t| res.format(t))
                .collect();
        // At `--msaa N` it rasterises N samples a pixel into the
        // multisampled attachments (shading stays once a pixel).
        let samples = targets.multisampled.map_or(1, |m| m.samples);
        self.geometry_pipeline = Pipeline::graphics_multisampled(
            ctx,
            &GraphicsDesc {
                name: "geometry".into(),
                vert: GEOMETRY_VERT,
                frag: Some(geometry_shader(&targets)),
                color_formats,
                depth_format: Some(ds_format),
                stencil_format: Some(ds_format),
                vertex_input: VertexInput::Mesh,
                cull: vk::CullModeFlags::BACK,
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::LESS,
                // Every drawn pixel gets its object's group code, all 8 bits
                // (reference per draw: 0 off skin, `mix::stencil_code` on it;
                // a single-method frame writes 0 and 1 as the skin bit did).
                stencil: Some(vk::StencilOpState {
                    fail_op: vk::StencilOp::KEEP,
                    pass_op: vk::StencilOp::REPLACE,
                    depth_fail_op: vk::StencilOp::KEEP,
                    compare_op: vk::CompareOp::ALWAYS,
                    compare_mask: 0xff,
                    write_mask: 0xff,
                    reference: 0,
                }),
                depth_bias: None,
                blend: Blend::None,
            },
            samples,
        )?;
        self.composite_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen("composite", COMPOSITE_SHADER, res.format(targets.hdr)),
        )?;
        Ok(())
    }

    /// Adds the character-id pass (`--character-ids`) writing into `ids`
    /// (before the usages are derived: the pass declares its target).
    pub fn enable_character_ids(
        &mut self,
        ctx: &Context,
        res: &Resources,
        ids: ImageId,
    ) -> Result<()> {
        let ds_format = res.format(self.targets.depth_stencil);
        // The geometry pass's vertex shader, so positions match its depth exactly.
        self.ids_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "character ids".into(),
                vert: GEOMETRY_VERT,
                frag: Some(IDS_SHADER),
                color_formats: vec![res.format(ids)],
                depth_format: Some(ds_format),
                stencil_format: Some(ds_format),
                vertex_input: VertexInput::Mesh,
                cull: vk::CullModeFlags::BACK,
                depth_test: true,
                depth_write: false,
                depth_compare: vk::CompareOp::EQUAL,
                stencil: None,
                depth_bias: None,
                blend: Blend::None,
            },
        )?;
        self.character_ids = Some(ids);
        self.write_instances(ctx)
    }

    /// Builds the post chain: the tone map, and the stage `settings.aa`
    /// names with its images declared (before the usages are derived: its
    /// passes declare them). Every frame needs it.
    pub fn enable_post(&mut self, ctx: &Context, res: &mut Resources) -> Result<()> {
        let depth_stencil_format = res.format(self.targets.depth_stencil);
        self.post = PostChain::new(
            self.settings.aa,
            &mut PostSetup {
                ctx,
                res,
                hdr: self.targets.hdr,
                exposure: self.settings.exposure,
                input: self.targets.ldr,
                depth_stencil_format,
                options: self.settings.post,
                linear_depth: self.targets.linear_depth,
                mm_per_unit: self.mm_per_unit,
            },
        )?;
        Ok(())
    }

    /// The frame's output image: the anti-aliased frame, or the tone-mapped
    /// one without a post stage.
    pub fn output(&self) -> ImageId {
        self.post.output().unwrap_or(self.targets.ldr)
    }

    /// The frame's uniforms: camera, key light, shadow and transmittance parameters.
    fn uniforms(&self, scene: &Scene, transmittance: bool) -> FrameUniforms {
        let settings = &self.settings;
        let aspect = settings.width as f32 / settings.height as f32;
        let (camera, light_frame) = (self.camera, self.light_frame);
        let light_dir = settings.light.direction_to_light(scene.forward);
        let light = settings.light;
        let mm = scene.mm_per_unit;
        let bias = SHADOW_BIAS_MM / mm / light_frame.depth_range_units;
        FrameUniforms {
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
                (settings.transmittance && transmittance) as u32 as f32,
            ],
            shadow_params: [
                1.0 / settings.shadow_size as f32,
                bias,
                settings.transmittance_profile.exponent_scale(),
                0.0,
            ],
        }
    }

    /// The frame's own view of its targets (the whole screen, the skin
    /// bit): what the groups' views narrow down.
    pub fn view<'a, 'r>(&'a self, res: &'r Resources) -> FrameView<'a, 'r> {
        FrameView {
            targets: &self.targets,
            res,
            extent: self.extent,
            region: &self.screen_rect,
            depths: &[],
            screen: &self.screen_rect,
            stencil: STENCIL_SKIN,
        }
    }

    /// The view the method is built for.
    pub fn view_info(&self) -> ViewInfo {
        ViewInfo {
            extent: self.extent,
            camera: self.camera,
            mm_per_unit: self.mm_per_unit,
        }
    }

    /// The groups' heads and codes the geometry pass draws (rewrites the
    /// instance buffer in group order).
    pub fn set_skin_groups(&mut self, ctx: &Context, groups: Vec<SkinGroup>) -> Result<()> {
        self.skin_groups = groups;
        self.write_instances(ctx)
    }

    /// The bindings of `lighting.glsl`'s set 0 (frame).
    pub fn frame_binds(&self, res: &Resources) -> Vec<(&'static str, Bind)> {
        vec![
            (
                "frame",
                Bind::Uniform {
                    buffer: self.frame_ubo.raw,
                    size: std::mem::size_of::<FrameUniforms>() as u64,
                },
            ),
            ("shadowMap", Bind::Texture(res.view(self.targets.shadow))),
            ("shadowCompare", Bind::Sampler(self.samplers.shadow_compare)),
            ("nearestClamp", Bind::Sampler(self.samplers.nearest_clamp)),
            ("beckmannTex", Bind::Texture(self.beckmann.view)),
            ("linearClamp", Bind::Sampler(self.samplers.linear_clamp)),
        ]
    }

    /// The descriptor sets that read frame images (after they exist); the
    /// composite reads `sss_output`: the method's output in a single-method
    /// frame, the (merged) diffuse target in a frame of several.
    pub fn bind(&mut self, ctx: &Context, res: &Resources, sss_output: ImageId) -> Result<()> {
        let t = self.targets;
        self.frame_set =
            self.pool
                .write_set(ctx, &self.geometry_pipeline, 0, &self.frame_binds(res))?;
        self.composite_set = self.pool.write_set(
            ctx,
            &self.composite_pipeline,
            0,
            &[
                ("diffuseTex", Bind::Texture(res.view(sss_output))),
                ("specularTex", Bind::Texture(res.view(t.specular))),
            ],
        )?;
        if self.character_ids.is_some() {
            self.ids_set =
                self.pool
                    .write_set(ctx, &self.ids_pipeline, 0, &self.frame_binds(res)[..1])?;
        }
        self.post.bind(&PostBind {
            ctx,
            res,
            pool: &self.pool,
            samplers: &self.samplers,
        })
    }

    /// The frame's passes in order, the groups' in the middle.
    pub fn passes<'a>(
        &'a self,
        groups: &'a [GroupMethod],
        merge: &'a Merge,
        res: &Resources,
    ) -> Vec<Pass<'a>> {
        let mut passes = vec![self.shadow_pass(), self.geometry_pass(res)];
        let diffuse = groups::sss(&mut passes, &self.view(res), groups, merge);
        passes.push(self.composite_pass(res, diffuse));
        passes.extend(self.post.passes(res));
        if let Some(ids) = self.character_ids {
            passes.push(self.character_ids_pass(ids));
        }
        passes
    }

    /// After the frame (`--character-ids`): every head again, depth-tested
    /// EQUAL against the frame's depth, writing its frame index + 1. Set-up
    /// work, not frame cost; only the flag adds it.
    fn character_ids_pass<'a>(&'a self, ids: ImageId) -> Pass<'a> {
        Pass::new("character ids", PassRole::Setup)
            .color(ColorTarget::new(ids, Load::Clear([0.0; 4])))
            .depth_stencil(DepthStencil::test_only(self.targets.depth_stencil).depth_test(true))
            .draws(None, self.triangles(true))
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.ids_pipeline;
                p.bind(ctx, cmd, &[self.ids_set]);
                p.bind_sets(ctx, cmd, 2, &[self.ids_instance_set]);
                for obj in self.objects.iter().filter(|o| o.skin) {
                    for (c, &slot) in self.character_slots.iter().enumerate() {
                        p.push(ctx, cmd, &IdPush { id: (c + 1) as f32 });
                        obj.draw_instances(ctx, cmd, slot, 1);
                    }
                }
            })
    }

    /// Triangles the skin objects submit per frame (every character), and all objects.
    fn triangles(&self, skin_only: bool) -> u64 {
        self.objects
            .iter()
            .filter(|o| o.skin || !skin_only)
            .map(|o| {
                let copies = if o.skin { self.instances.len() } else { 1 };
                o.mesh.triangles() * copies as u64
            })
            .sum()
    }

    fn shadow_pass<'a>(&'a self) -> Pass<'a> {
        Pass::new("shadow map", PassRole::Shadow)
            .depth_stencil(DepthStencil::cleared(self.targets.shadow, 1.0))
            .draws(None, self.triangles(true))
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                self.shadow_pipeline.bind(ctx, cmd, &[self.shadow_set]);
                let push = ShadowPush {
                    light_view_proj: self.light_frame.view_proj.to_cols_array_2d(),
                };
                self.shadow_pipeline.push(ctx, cmd, &push);
                // Heads only: the backdrop receives shadows but casts none worth
                // a texel. Every character in one instanced draw.
                let heads = self.backdrop_slot;
                for obj in self.objects.iter().filter(|o| o.skin) {
                    obj.draw_instances(ctx, cmd, 0, heads);
                }
            })
    }

    fn geometry_pass<'a>(&'a self, res: &Resources) -> Pass<'a> {
        let t = self.targets;
        let shader = geometry_shader(&t);
        let rgba8 = |texture: &str, exact| Fetch {
            texture: texture.into(),
            format: Format::Rgba8Unorm,
            filter: Filter::Bilinear,
            count: 1.0,
            exact,
            coherent: true,
            spread: Vec::new(),
        };
        let shadow_format = res.texel_format(t.shadow);
        // Per fragment: the 3x3 PCF, the three material maps (the normal map
        // only where the tangent frame is valid), the Beckmann lobe where
        // N.L > 0, and one shadow-map texel for transmittance on skin.
        let fetches = vec![
            Fetch {
                texture: "shadowMap".into(),
                format: shadow_format,
                filter: Filter::DepthCompare,
                count: 9.0,
                exact: true,
                coherent: true,
                spread: Vec::new(),
            },
            rgba8("normalTex", false),
            rgba8("albedoTex", true),
            Fetch {
                texture: "shadowMap".into(),
                format: shadow_format,
                filter: Filter::Point,
                count: 1.0,
                exact: false,
                coherent: true,
                spread: Vec::new(),
            },
            rgba8("specTex", true),
            Fetch {
                texture: "beckmannTex".into(),
                format: Format::R16Float,
                filter: Filter::Bilinear,
                count: 1.0,
                exact: false,
                coherent: true,
                spread: Vec::new(),
            },
        ];
        let work = ShaderWork {
            shader: shader.into(),
            fetches,
            alu: alu_estimate(shader, &PCF_TRIPS),
            ..Default::default()
        };
        // Every target starts cleared; linear depth clears to the far plane, so
        // no surface reads as "in front". Declared in the order the dumps number
        // them: the three targets, depth and stencil, then the normals a method
        // asked for (attachment order: the colours in the order given).
        // With `--msaa` each target is drawn multisampled and resolved into
        // the single-sample one the methods read: colours (and linear depth:
        // the thesis' average of the subsamples' depths, ch. 6.3) averaged,
        // depth and stencil from sample 0 (docs/aa.md).
        let ms = t.multisampled;
        let clear = |c: ImageId, multi: Option<ImageId>, v: [f32; 4]| match multi {
            Some(m) => ColorTarget::new(m, Load::Clear(v)).resolved_into(c),
            None => ColorTarget::new(c, Load::Clear(v)),
        };
        let depth = match ms {
            Some(m) => DepthStencil::cleared(m.depth_stencil, 1.0).resolved_into(t.depth_stencil),
            None => DepthStencil::cleared(t.depth_stencil, 1.0),
        };
        let mut pass = Pass::new("geometry", PassRole::Geometry)
            .sampled(t.shadow)
            .color(clear(t.diffuse, ms.map(|m| m.diffuse), [0.0; 4]))
            .color(clear(t.specular, ms.map(|m| m.specular), [0.0; 4]))
            .color(clear(
                t.linear_depth,
                ms.map(|m| m.linear_depth),
                [self.camera.far, 0.0, 0.0, 0.0],
            ))
            // Every drawn pixel gets its object's skin bit (the reference is set per draw).
            .depth_stencil(depth.stencil_write(true));
        if let Some(n) = t.normals {
            pass = pass.color(clear(n, ms.and_then(|m| m.normals), [0.0; 4]));
        }
        pass.draws(Some(work), self.triangles(false))
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.geometry_pipeline;
                p.bind(ctx, cmd, &[self.frame_set]);
                p.bind_sets(ctx, cmd, 2, &[self.instance_set]);
                let set_reference = |r: u32| unsafe {
                    ctx.device.cmd_set_stencil_reference(
                        cmd,
                        vk::StencilFaceFlags::FRONT_AND_BACK,
                        r,
                    );
                };
                for obj in &self.objects {
                    p.bind_sets(ctx, cmd, 1, &[obj.material_set]);
                    if !obj.skin {
                        set_reference(0);
                        obj.draw_instances(ctx, cmd, self.backdrop_slot, 1);
                        continue;
                    }
                    // Each group's heads in one instanced draw with its code
                    // (one group: every head in frame order, code 1, as
                    // before groups).
                    for (g, &(first, count)) in self.skin_groups.iter().zip(&self.group_slots) {
                        set_reference(g.stencil);
                        obj.draw_instances(ctx, cmd, first, count);
                    }
                }
            })
    }

    fn fullscreen_pass<'a>(&'a self, res: &Resources, p: PostPass<'a, '_>) -> Pass<'a> {
        let PostPass {
            name,
            pipeline,
            shader,
            set,
            reads,
            target,
        } = p;
        let work = ShaderWork {
            shader: shader.into(),
            fetches: reads
                .iter()
                .map(|&(id, texture)| Fetch {
                    texture: texture.into(),
                    format: res.texel_format(id),
                    filter: Filter::Point,
                    count: 1.0,
                    exact: true,
                    coherent: true,
                    spread: Vec::new(),
                })
                .collect(),
            alu: alu_estimate(shader, &[]),
            ..Default::default()
        };
        let mut pass = Pass::new(name, PassRole::Post);
        for &(r, _) in reads {
            pass = pass.sampled(r);
        }
        pass.color(ColorTarget::new(target, Load::DontCare))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {}))
    }

    fn composite_pass<'a>(&'a self, res: &Resources, sss_output: ImageId) -> Pass<'a> {
        let t = self.targets;
        self.fullscreen_pass(
            res,
            PostPass {
                name: "composite",
                pipeline: &self.composite_pipeline,
                shader: COMPOSITE_SHADER,
                set: self.composite_set,
                reads: &[(sss_output, "diffuseTex"), (t.specular, "specularTex")],
                target: t.hdr,
            },
        )
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for o in &mut self.objects {
            o.destroy(ctx);
        }
        self.post.destroy(ctx);
        self.beckmann.destroy(ctx);
        self.frame_ubo.destroy(ctx);
        self.instance_buffer.destroy(ctx);
        for p in [
            &mut self.shadow_pipeline,
            &mut self.geometry_pipeline,
            &mut self.composite_pipeline,
            &mut self.ids_pipeline,
        ] {
            p.destroy(ctx);
        }
        self.pool.destroy(ctx);
        self.samplers.destroy(ctx);
    }
}

/// The geometry pass's fragment shader: with the normal MRT when a method needs it.
fn geometry_shader(t: &FrameTargets) -> &'static str {
    if t.normals.is_some() {
        "geometry_normals.frag"
    } else {
        "geometry.frag"
    }
}

/// The skin object's material bindings (set 1 of lighting.glsl), for methods
/// that shade surfaces; none in a scene without skin.
pub fn skin_material_binds(frame: &Frame) -> Vec<(&'static str, Bind)> {
    frame
        .objects
        .iter()
        .find(|o| o.skin)
        .map(|o| o.material_binds(&frame.samplers))
        .unwrap_or_default()
}
