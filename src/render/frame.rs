//! The frame around the SSS methods, and its recipe ([`Frame::passes`]):
//! shadow map (key light, orthographic, so its depth is linear) -> geometry
//! pass into the targets (Lambert + transmittance, Kelemen/Szirmay-Kalos
//! specular, linear depth, each character's group code in the stencil) ->
//! the groups' SSS (each group's method's passes, one group in a
//! single-method frame; in a frame of several the merges and fades:
//! `groups/`) -> composite (diffuse after SSS + specular) -> bloom -> Hable
//! tone map -> the anti-aliasing stage (`crate::post`) -> the character ids
//! (`--character-ids`). Each stage records its passes and hands the next
//! the images it wrote.
//!
//! The frame's own stages are here (geometry, composite) and in its
//! children (the shadow map `shadow.rs`, the character ids
//! `character_ids.rs`), beside the pipelines, sets and instance slots they
//! draw with; the instance buffer is `instances.rs`, the uniform block
//! `uniforms.rs`.

use anyhow::Result;
use ash::vk;
use glam::Mat4;

mod character_ids;
mod motion;
mod shadow;
pub use motion::object_copies;
use motion::Stepping;

use super::deform::Deform;
use super::groups::merge::Merge;
use super::groups::region::scissors;
use super::groups::{passes as groups, GroupMethod};
use super::instances::{Instances, SkinGroup};
use super::scene_gpu::{GpuObject, ObjectKind};
use super::settings::RenderSettings;
use super::targets::{composite_shader, geometry_shader, SHADOW_FORMAT};
use super::uniforms::FrameUniforms;
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{
    Binding, ColorTarget, DepthStencil, GraphSet, ImageId, Load, Pass, PassContext, Resources,
};
use crate::method::region::PixelRect;
use crate::method::{FrameTargets, FrameView, ViewInfo, STENCIL_SKIN};
use crate::post::{PostBind, PostChain, PostSetup};
use crate::scene::camera::Camera;
use crate::scene::crowd_geometry::{turned, CharacterGeometry};
use crate::scene::framing::Framing;
use crate::scene::light::LightFrame;
use crate::scene::Scene;
use crate::shader_constants::PCF_TRIPS;
use crate::skin::beckmann::beckmann_lut;
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
/// Slope-scaled depth bias of the shadow pass (in units of the depth slope):
/// the usual 1.5 against acne on curved skin at grazing light.
const SHADOW_SLOPE_BIAS: f32 = 1.5;

/// The geometry pass's vertex shader: geometry.vert (what tsd's final pass and
/// the ground truth's surface pass draw one head with) with the model matrix
/// read per instance.
const GEOMETRY_VERT: &str = "geometry_instanced.vert";

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
    ids_set: GraphSet,
    pub character_ids: Option<ImageId>,
    /// Set 0 of the geometry pass (`lighting.glsl`'s frame set: it samples
    /// the shadow map).
    frame_set: GraphSet,
    /// The composite's set: the diffuse light after SSS and the specular
    /// target (`composite_from`).
    composite_set: GraphSet,
    frame_ubo: Buffer,
    beckmann: Image,
    pub objects: Vec<GpuObject>,
    /// The morphing objects' deform passes (`enable_deform`).
    pub deform: Deform,
    /// Every character's level and caster flag, in frame order
    /// (`choose_geometry`); `casters` the flags per instance slot, what the
    /// shadow map draws by.
    pub geometry: Vec<CharacterGeometry>,
    casters: Vec<bool>,
    /// A frame stepping through the motion (`--time-step`): what each
    /// frame's pose is made from.
    stepping: Option<Stepping>,
    /// The characters of each group with its stencil code, in group order:
    /// the geometry pass draws each group's heads with its code as the
    /// stencil reference (one group of every character, code 1, until
    /// `set_skin_groups`).
    pub skin_groups: Vec<SkinGroup>,
    /// Every character's model matrix in `skin_groups`' order, then the
    /// backdrop's: the shadow, geometry and id passes draw instances of it.
    instance_buffer: Instances,
    /// Every character's wrinkle zone weights, in frame order
    /// (`skin::wrinkles::character_zones`), and the head's target names and
    /// own weights a stepping run weighs each frame's pose by (`None`: a
    /// skin without wrinkle maps).
    pub zones: Vec<[f32; 8]>,
    wrinkle_rig: Option<motion::WrinkleRig>,
    /// The instance buffer as the shadow pipeline's set 0 and the geometry
    /// and id pipelines' set 2 (no frame image: plain sets).
    shadow_set: vk::DescriptorSet,
    instance_set: vk::DescriptorSet,
    ids_instance_set: vk::DescriptorSet,
    screen_rect: Vec<vk::Rect2D>,
    /// The bloom, the tone map and the anti-aliasing stage (`enable_post`).
    pub post: PostChain,
}

impl Frame {
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
        let stepping = Stepping::new(scene, &framing.instances);
        let instances = turned(scene, framing.instances);
        let (zones, wrinkle_rig) = motion::wrinkle_state(scene, instances.len());
        let f = Frame {
            settings: settings.clone(),
            extent,
            mm_per_unit: scene.mm_per_unit,
            targets,
            camera: framing.camera,
            light_frame: framing.light,
            instances,
            backdrop: framing.backdrop,
            samplers: Samplers::default(),
            pool: DescriptorPool::default(),
            shadow_pipeline: Pipeline::default(),
            geometry_pipeline: Pipeline::default(),
            composite_pipeline: Pipeline::default(),
            ids_pipeline: Pipeline::default(),
            ids_set: GraphSet::default(),
            character_ids: None,
            frame_set: GraphSet::default(),
            composite_set: GraphSet::default(),
            frame_ubo: Buffer::default(),
            beckmann: Image::default(),
            objects: Vec::new(),
            deform: Deform::default(),
            geometry: Vec::new(),
            casters: Vec::new(),
            stepping,
            skin_groups: vec![SkinGroup {
                stencil: STENCIL_SKIN,
                characters: every,
            }],
            instance_buffer: Instances::default(),
            zones,
            wrinkle_rig,
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
        // One material set per object beyond the few the constant counts.
        self.pool = DescriptorPool::new(ctx, DESCRIPTOR_SETS + scene.parts.len() as u32)?;
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
        let uniforms = FrameUniforms::new(
            &self.settings,
            scene,
            self.camera,
            self.light_frame,
            transmittance,
        );
        self.frame_ubo = Buffer::with_data(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        self.frame_set = GraphSet::new(res, &self.geometry_pipeline, 0, self.frame_binds());
        let kind = |skin: bool| {
            if skin {
                ObjectKind::Skin
            } else {
                ObjectKind::Part
            }
        };
        let objects = scene
            .backdrop
            .iter()
            .map(|b| ("backdrop".to_string(), ObjectKind::Backdrop, b))
            .chain(std::iter::once((
                "head".to_string(),
                kind(scene.head.material.skin),
                &scene.head,
            )))
            .chain(
                scene
                    .parts
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (format!("part {i}"), ObjectKind::Part, p)),
            );
        let first = usize::from(scene.backdrop.is_some());
        // The wrinkle maps go up only where a zone is weighed (or may be:
        // a stepping run); otherwise nothing reads them.
        let wrinkled = self.wrinkles_drawn();
        for (k, (name, kind, o)) in objects.enumerate() {
            let copies = match k.checked_sub(first) {
                Some(i) => object_copies(scene, i, self.instances.len()),
                None => 1,
            };
            let g = GpuObject::new(
                ctx,
                &name,
                kind,
                (
                    o,
                    copies,
                    kind.per_character() && self.settings.wants_levels(),
                    wrinkled,
                ),
                &self.pool,
                &self.geometry_pipeline,
                &self.samplers,
            )?;
            self.objects.push(g);
        }
        self.write_instances(ctx)
    }

    /// The instance buffer of `skin_groups` and the sets that read it.
    fn write_instances(&mut self, ctx: &Context) -> Result<()> {
        self.instance_buffer.destroy(ctx);
        self.instance_buffer = Instances::new(
            ctx,
            &self.skin_groups,
            (&self.instances, &self.zones),
            self.backdrop,
        )?;
        let bind = [self.instance_buffer.binding()];
        self.shadow_set = self.pool.write_set(ctx, &self.shadow_pipeline, 0, &bind)?;
        // The geometry pass's vertex shader reads each slot's wrinkle zones too.
        let with_zones = [bind[0], self.instance_buffer.zones_binding()];
        self.instance_set = self
            .pool
            .write_set(ctx, &self.geometry_pipeline, 2, &with_zones)?;
        if self.character_ids.is_some() {
            self.ids_instance_set = self
                .pool
                .write_set(ctx, &self.ids_pipeline, 2, &with_zones)?;
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
                .chain(targets.albedo)
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
            &GraphicsDesc::fullscreen(
                "composite",
                composite_shader(&targets),
                res.format(targets.hdr),
            ),
        )?;
        Ok(())
    }

    /// Declares every deformed vertex buffer the frame's draws read.
    fn reads_vertices<'a>(&self, pass: Pass<'a>) -> Pass<'a> {
        self.objects
            .iter()
            .filter_map(|o| o.deformed)
            .fold(pass, |p, id| p.vertex_input(id))
    }

    /// Builds the post chain: the bloom with `--bloom`, the tone map, and
    /// the stage `settings.aa` names, with their images declared (before the
    /// usages are derived: their passes declare them). Every frame needs it.
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
                samplers: &self.samplers,
            },
        )?;
        Ok(())
    }

    /// The composite reads `diffuse` (what the groups' stage hands it: the
    /// method's output in a single-method frame, the merged diffuse target
    /// in a frame of several) and the specular target (before the usages are
    /// derived: its pass declares them through this set).
    pub fn composite_from(&mut self, res: &Resources, diffuse: ImageId) {
        self.composite_set = GraphSet::new(
            res,
            &self.composite_pipeline,
            0,
            [
                ("diffuseTex", Binding::Sampled(diffuse)),
                ("specularTex", Binding::Sampled(self.targets.specular)),
            ]
            .into_iter()
            .chain(
                self.targets
                    .albedo
                    .map(|a| ("albedoTex", Binding::Sampled(a))),
            )
            .collect(),
        );
    }

    /// The frame's output image: the anti-aliased frame, or the tone-mapped
    /// one without a post stage.
    pub fn output(&self) -> ImageId {
        self.post.output().unwrap_or(self.targets.ldr)
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

    /// The bindings of `lighting.glsl`'s set 0 (frame): its uniforms, the
    /// shadow map (a frame image: a pass binding them declares it), the
    /// samplers and the Beckmann table.
    pub fn frame_binds(&self) -> Vec<(&'static str, Binding)> {
        let fixed = |b| Binding::Fixed(b);
        vec![
            (
                "frame",
                fixed(Bind::Uniform {
                    buffer: self.frame_ubo.raw,
                    size: std::mem::size_of::<FrameUniforms>() as u64,
                }),
            ),
            ("shadowMap", Binding::Sampled(self.targets.shadow)),
            (
                "shadowCompare",
                fixed(Bind::Sampler(self.samplers.shadow_compare)),
            ),
            (
                "nearestClamp",
                fixed(Bind::Sampler(self.samplers.nearest_clamp)),
            ),
            ("beckmannTex", fixed(Bind::Texture(self.beckmann.view))),
            (
                "linearClamp",
                fixed(Bind::Sampler(self.samplers.linear_clamp)),
            ),
        ]
    }

    /// Writes the frame's and the post chain's descriptor sets (once the
    /// images exist).
    pub fn bind(&mut self, ctx: &Context, res: &Resources) -> Result<()> {
        let pool = &self.pool;
        self.frame_set
            .write(ctx, pool, res, &self.geometry_pipeline)?;
        self.composite_set
            .write(ctx, pool, res, &self.composite_pipeline)?;
        if self.character_ids.is_some() {
            self.ids_set.write(ctx, pool, res, &self.ids_pipeline)?;
        }
        self.deform.bind(ctx, pool, res)?;
        self.post.bind(&PostBind { ctx, res, pool })
    }

    /// The frame's recipe: each stage records its passes into `passes` and
    /// hands the next the images it wrote.
    pub fn passes<'a>(
        &'a self,
        groups: &'a [GroupMethod],
        merge: &'a Merge,
        res: &Resources,
    ) -> Vec<Pass<'a>> {
        let mut passes = Vec::new();
        self.deform.passes(&mut passes);
        let shadow = self.shadow_map(&mut passes);
        let gbuffer = self.geometry(&mut passes, res, shadow);
        let diffuse = groups::sss(&mut passes, &gbuffer, groups, merge);
        let hdr = self.composite(&mut passes, res, diffuse, gbuffer.targets.specular);
        let hdr = self.post.bloom(&mut passes, res, hdr);
        let ldr = self.post.tonemap(&mut passes, res, hdr);
        self.post.anti_alias(&mut passes, res, ldr);
        if let Some(ids) = self.character_ids {
            self.character_ids(&mut passes, ids, gbuffer.targets.depth_stencil);
        }
        passes
    }

    /// Every object lit by the key light through `shadow` into the targets:
    /// the frame's view of them (what the SSS methods read) is what it hands
    /// on.
    fn geometry<'a, 'r>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        res: &'r Resources,
        shadow: ImageId,
    ) -> FrameView<'a, 'r> {
        let t = self.targets;
        debug_assert!(self.frame_set.reads(shadow));
        let shader = geometry_shader(&t);
        let shadow_format = res.texel_format(shadow);
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
            Fetch::material("normalTex", false),
            Fetch::material("albedoTex", true),
            Fetch {
                texture: "shadowMap".into(),
                format: shadow_format,
                filter: Filter::Point,
                count: 1.0,
                exact: false,
                coherent: true,
                spread: Vec::new(),
            },
            Fetch::material("specTex", true),
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
        let mut fetches = fetches;
        if self.wrinkles_drawn() {
            fetches.extend(Fetch::wrinkles());
        }
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
        let mut pass = self.reads_vertices(Pass::new("geometry", PassRole::Geometry));
        // The frame's set samples the shadow map.
        let frame = pass.set(&self.frame_set);
        pass = pass
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
        if let Some(a) = t.albedo {
            pass = pass.color(clear(a, ms.and_then(|m| m.albedo), [0.0; 4]));
        }
        passes.push(pass.draws(Some(work), self.triangles(|_| true)).record(
            move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.geometry_pipeline;
                pc.bind(p, &[frame]);
                p.bind_sets(ctx, cmd, 2, &[self.instance_set]);
                let slots = &self.instance_buffer;
                let set_reference = |r: u32| unsafe {
                    ctx.device.cmd_set_stencil_reference(
                        cmd,
                        vk::StencilFaceFlags::FRONT_AND_BACK,
                        r,
                    );
                };
                // The characters first and the backdrop last: early depth
                // testing then rejects the backdrop's hidden pixels instead
                // of shading them and drawing over them (a crowd covers
                // half the screen). The nearest surface and its stencil code
                // win in either order (the same bits, but where a character
                // and the backdrop meet at exactly one depth).
                let order = self
                    .objects
                    .iter()
                    .filter(|o| o.kind != ObjectKind::Backdrop)
                    .chain(
                        self.objects
                            .iter()
                            .filter(|o| o.kind == ObjectKind::Backdrop),
                    );
                for obj in order {
                    p.bind_sets(ctx, cmd, 1, &[obj.material_set]);
                    // The backdrop once, a character's other parts with
                    // every character: no skin bit, so no SSS pass reads them.
                    if obj.kind != ObjectKind::Skin {
                        set_reference(0);
                        let (first, count) = match obj.kind {
                            ObjectKind::Backdrop => (slots.backdrop_slot, 1),
                            _ => (0, slots.backdrop_slot),
                        };
                        obj.draw_instances(ctx, cmd, first, count);
                        continue;
                    }
                    // Each group's heads in one instanced draw with its code
                    // (one group: every head in frame order, code 1, as
                    // before groups).
                    for (g, &(first, count)) in self.skin_groups.iter().zip(&slots.group_slots) {
                        set_reference(g.stencil);
                        obj.draw_instances(ctx, cmd, first, count);
                    }
                }
            },
        ));
        self.view(res)
    }

    /// The diffuse light after SSS plus the specular target, into the HDR
    /// target: one point fetch of each per pixel, every pixel written.
    fn composite<'a>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        res: &Resources,
        diffuse: ImageId,
        specular: ImageId,
    ) -> ImageId {
        debug_assert!(self.composite_set.reads(diffuse) && self.composite_set.reads(specular));
        let hdr = self.targets.hdr;
        let point = |image, texture: &str| Fetch {
            texture: texture.into(),
            format: res.texel_format(image),
            filter: Filter::Point,
            count: 1.0,
            exact: true,
            coherent: true,
            spread: Vec::new(),
        };
        let shader = composite_shader(&self.targets);
        let mut fetches = vec![point(diffuse, "diffuseTex"), point(specular, "specularTex")];
        fetches.extend(self.targets.albedo.map(|a| point(a, "albedoTex")));
        let work = ShaderWork {
            shader: shader.into(),
            fetches,
            alu: alu_estimate(shader, &[]),
            ..Default::default()
        };
        let pipeline = &self.composite_pipeline;
        let mut pass = Pass::new("composite", PassRole::Post);
        let set = pass.set(&self.composite_set);
        passes.push(
            pass.color(ColorTarget::new(hdr, Load::DontCare))
                .draws(Some(work), 1)
                .record(move |pc: &PassContext| fullscreen(pc, pipeline, &[set], |_, _| {})),
        );
        hdr
    }

    /// Triangles the objects `of` selects submit per frame (a character's
    /// objects once per character).
    fn triangles(&self, of: impl Fn(ObjectKind) -> bool) -> u64 {
        let copies = |k: ObjectKind| {
            if k.per_character() {
                self.instances.len() as u64
            } else {
                1
            }
        };
        self.objects
            .iter()
            .filter(|o| of(o.kind))
            .map(|o| {
                if o.kind.per_character() && !o.mesh.slot_levels.is_empty() {
                    (0..o.mesh.slot_levels.len())
                        .map(|s| o.mesh.slot_triangles(s))
                        .sum()
                } else {
                    o.mesh.triangles() * copies(o.kind)
                }
            })
            .sum()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for o in &mut self.objects {
            o.destroy(ctx);
        }
        self.deform.destroy(ctx);
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

/// The skin object's material bindings (set 1 of lighting.glsl), for methods
/// that shade surfaces; none in a scene without skin.
pub fn skin_material_binds(frame: &Frame) -> Vec<(&'static str, Bind)> {
    frame
        .objects
        .iter()
        .find(|o| o.kind == ObjectKind::Skin)
        .map(|o| o.material_binds(&frame.samplers))
        .unwrap_or_default()
}
