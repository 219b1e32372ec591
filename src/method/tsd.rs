//! Texture-space diffusion, per character (d'Eon and Luebke's pipeline as seed
//! 004 walks it), and the same with the culling tricks of the thesis' ch. 3 and
//! of Gosselin et al. (seed 002): `tsd` and `tsd-opt`, two registry rows over
//! one implementation.
//!
//! Per character, every frame: (a mask pass,) an irradiance pass that renders
//! the unwrapped mesh into its atlas (the frame's own shading code, shadow map
//! and transmittance, coverage in alpha) and d'Eon's stretch maps through MRT,
//! then the six Gaussians of Table 4.2's fit as twelve separable passes in
//! texture space, each step scaled by the stretch map, each v pass blending
//! `G_i / a_i` into the character's own map with eq. 4.8's `w'_i`. Last, one
//! pass draws every head with the frame's vertex shader, depth-tested against
//! the geometry pass's depth, writing its map's diffuse into the frame's
//! diffuse target (RGBA16F, alpha = SSS strength): non-skin pixels keep the
//! geometry pass's diffuse; the composite adds the frame's specular.
//!
//! The maps hold premultiplied coverage, so every blur is a normalised
//! convolution over written texels only (Gosselin's dilation at UV seams in
//! the variant he names: only samples that were written enter the average).
//! The pure parts (the chain, the atlas, eq. 3.1-3.4, the visibility
//! predictions) are in `skin::tsd`.
//!
//! `tsd-opt`'s switches, each measurable apart:
//! - `--cull stencil|alpha|off` (section 3.2): texels facing away beyond 105
//!   degrees are skipped by every convolution, by a stencil bit written in the
//!   mask pass and tested early, or by the thesis' alpha test in the shader;
//! - `--no-depth-sized` (section 3.3): the map works in `T = s T_max` texels,
//!   `s = min(d_ref / d, 1)`, through the viewport, taps limited to `0..s`;
//! - `--no-clip` (section 3.4): the unwrapped mesh is clipped by the six
//!   frustum planes as clip distances, so off-screen texels are never shaded
//!   nor (with a mask) blurred;
//! - `--no-z-prepass` (seed 002): the mask pass writes depth 0 where a texel is
//!   needed (object inside the frustum, not distance-culled, within the clip
//!   planes) and depth 1 where it faces away (`N.V + 0.3 < 0`); every later
//!   texture-space pass draws at depth 0 with the test EQUAL and early
//!   fragment tests. A character whose head is under `--far-px` pixels tall
//!   keeps its previous map and is refreshed once every `--refresh` frames,
//!   staggered: its map is at most `refresh - 1` frames old.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;
use glam::{Mat4, Vec4};

use super::region::ReachScale;
use super::screen::fetch;
use super::{
    EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs, OptKind, OptSpec, Opts,
    SssMethod,
};
use crate::graph::draw::fullscreen;
use crate::graph::mesh::GpuMesh;
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork};
use crate::graph::{
    ColorTarget, DepthStencil, ImageDesc, ImageId, Load, Pass, PassContext, Resources,
};
use crate::scene::mesh::Vertex;
use crate::skin::tsd::{
    self, atlas, box_outside, clip_planes, depth_scale, map_size, nearest_corner_distance,
    projected_px, reference_distance, refreshes, tsd_gaussians, Atlas, TsdGaussian, BACKFACE_BIAS,
    CULL_COS, EDGE_GUARD_TEXELS, NO_CLIP,
};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, Blend, DescriptorPool, GraphicsDesc, Pipeline, VertexInput};
use crate::vk::shader_stats::alu_estimate;

const UV_VERT: &str = "tsd_uv.vert";
const MASK_SHADER: &str = "tsd_mask.frag";
const IRRADIANCE_SHADER: &str = "tsd_irradiance.frag";
const BLUR_U_SHADER: &str = "tsd_blur_u.frag";
const BLUR_V_SHADER: &str = "tsd_blur_v.frag";
const FINAL_SHADER: &str = "tsd_final.frag";
/// Irradiance and every map of the chain: linear HDR light with coverage in
/// alpha. 16-bit float keeps 11 bits of mantissa over the whole range (8-bit
/// would band after twelve passes; 32-bit doubles every tap's bytes).
const MAP_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Stretch, one map per axis (each pass reads one): 32-bit float, since the
/// maps dermis can read back and dump have no two-channel 16-bit format.
const STRETCH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
use crate::shader_constants::PCF_TRIPS;
/// Loop trips of tsd_blur.glsl (three pairs of taps).
const BLUR_TRIPS: [u32; 1] = [3];
/// Bytes between characters in the uniform buffer (>= any device's
/// minUniformBufferOffsetAlignment).
const CHARACTER_STRIDE: u64 = 256;
/// Islands the atlas uniform buffer holds (tsd_character.glsl).
const MAX_ISLANDS: usize = crate::shader_constants::TSD_MAX_ISLANDS;
/// Depth bias of the final pass: it draws the geometry pass's own triangles
/// with the same vertex shader; a few units toward the eye absorb any
/// difference in how a driver compiles that shader in another pipeline.
const FINAL_DEPTH_BIAS: f32 = -8.0;

const SIZE_OPTION: OptSpec = OptSpec {
    key: "irradiance-size",
    kind: OptKind::Value,
    default: "2048",
    help: "side of the texture-space maps in texels (T_max): 16..=8192 (the thesis' 2048, Table 4.4's 1024)",
};

const PLAIN_OPTIONS: &[OptSpec] = &[SIZE_OPTION];

const OPT_OPTIONS: &[OptSpec] = &[
    SIZE_OPTION,
    OptSpec {
        key: "cull",
        kind: OptKind::Value,
        default: "stencil",
        help: "culled maps (thesis 3.2, texels facing away beyond 105 degrees): stencil (mask tested early) | alpha (the thesis' alpha test) | off",
    },
    OptSpec {
        key: "depth-sized",
        kind: OptKind::NoFlag,
        default: "true",
        help: "turn off depth-sized maps (thesis 3.3: T = s T_max, s = min(d_ref / d, 1))",
    },
    OptSpec {
        key: "d-ref",
        kind: OptKind::Value,
        default: "4.5",
        help: "eq. 3.1's d_ref in thesis units (head heights) at 1920x1200, 20 degrees, 2048 maps; scaled to the view, the scene's millimetres and --irradiance-size",
    },
    OptSpec {
        key: "clip",
        kind: OptKind::NoFlag,
        default: "true",
        help: "turn off clipped maps (thesis 3.4: the unwrapped mesh clipped by the six frustum planes)",
    },
    OptSpec {
        key: "z-prepass",
        kind: OptKind::NoFlag,
        default: "true",
        help: "turn off the texture-space z pre-passes (seed 002: frustum, backface at N.V + 0.3, distance; later passes test depth EQUAL early)",
    },
    OptSpec {
        key: "far-px",
        kind: OptKind::Value,
        default: "64",
        help: "with the z pre-passes: a head under this many pixels tall keeps its previous map (0: never)",
    },
    OptSpec {
        key: "refresh",
        kind: OptKind::Value,
        default: "4",
        help: "with the z pre-passes: a far character's map is refreshed once every this many frames (1..=64; staleness < this)",
    },
];

pub static ENTRY: MethodEntry = MethodEntry {
    name: "tsd",
    aliases: &["texture-space"],
    summary: "texture-space diffusion (d'Eon and Luebke): per character, irradiance and stretch maps in UV space, six Gaussians as twelve separable passes, a final mesh pass",
    options: PLAIN_OPTIONS,
    eval: &[
        EvalSetting {
            label: "1024 map",
            options: &[("irradiance-size", "1024")],
        },
        EvalSetting {
            label: "2048 map",
            options: &[("irradiance-size", "2048")],
        },
    ],
    ground_truth: false,
    dolly: &[],
    needs: |_, _| Needs::PLAIN,
    check: |o| Config::parse(o, false).map(|_| ()),
    build: |s| Ok(Box::new(Tsd::new(s, false)?)),
};

pub static OPT_ENTRY: MethodEntry = MethodEntry {
    name: "tsd-opt",
    aliases: &["tsd-optimized"],
    summary: "texture-space diffusion with the thesis' culled, depth-sized and clipped maps and seed 002's texture-space z pre-passes, each switchable",
    options: OPT_OPTIONS,
    eval: &[
        EvalSetting {
            label: "2048 map, all",
            options: &[("irradiance-size", "2048")],
        },
        EvalSetting {
            label: "2048 map, alpha test",
            options: &[("irradiance-size", "2048"), ("cull", "alpha")],
        },
    ],
    ground_truth: false,
    dolly: &[],
    needs: |_, _| Needs::PLAIN,
    check: |o| Config::parse(o, true).map(|_| ()),
    build: |s| Ok(Box::new(Tsd::new(s, true)?)),
};

/// How culled texels are skipped (thesis section 3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Cull {
    Off,
    /// The thesis' implementation: alpha 0 in the irradiance map, a branch in
    /// every convolution.
    Alpha,
    /// A stencil bit written by the mask pass, tested before the shaders run.
    Stencil,
}

/// The method's options, parsed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Config {
    /// T_max.
    pub size: u32,
    pub cull: Cull,
    pub depth_sized: bool,
    /// Eq. 3.1's d_ref in thesis units at the thesis' frame.
    pub d_ref: f32,
    pub clip: bool,
    pub z_prepass: bool,
    pub far_px: f32,
    pub refresh: u32,
}

impl Config {
    /// `tsd`'s configuration: no optimisation.
    pub const PLAIN: Config = Config {
        size: 2048,
        cull: Cull::Off,
        depth_sized: false,
        d_ref: tsd::THESIS_D_REF,
        clip: false,
        z_prepass: false,
        far_px: 0.0,
        refresh: 1,
    };

    pub fn parse(o: &Opts, optimised: bool) -> Result<Self> {
        let size: u32 = o.parse("irradiance-size")?;
        if !(16..=8192).contains(&size) {
            bail!("--irradiance-size must be within 16..=8192 texels, got {size}");
        }
        if !optimised {
            return Ok(Config {
                size,
                ..Self::PLAIN
            });
        }
        let cull = match o.raw("cull").trim() {
            "stencil" => Cull::Stencil,
            "alpha" => Cull::Alpha,
            "off" => Cull::Off,
            other => bail!("--cull takes stencil, alpha or off, got '{other}'"),
        };
        let d_ref: f32 = o.parse("d-ref")?;
        if !(d_ref.is_finite() && d_ref > 0.0) {
            bail!("--d-ref must be a positive number of thesis units, got {d_ref}");
        }
        let far_px: f32 = o.parse("far-px")?;
        if !(far_px.is_finite() && far_px >= 0.0) {
            bail!("--far-px must be a number of pixels >= 0, got {far_px}");
        }
        let refresh: u32 = o.parse("refresh")?;
        if !(1..=64).contains(&refresh) {
            bail!("--refresh must be within 1..=64 frames, got {refresh}");
        }
        Ok(Config {
            size,
            cull,
            depth_sized: o.flag("depth-sized")?,
            d_ref,
            clip: o.flag("clip")?,
            z_prepass: o.flag("z-prepass")?,
            far_px,
            refresh,
        })
    }

    /// Whether the texture-space passes are masked by a depth/stencil image
    /// (and so need the mask pass, and clears of what they write in part).
    pub fn masked(&self) -> bool {
        self.z_prepass || self.cull == Cull::Stencil
    }
}

/// std140 layout of `CharacterUniforms` (tsd_character.glsl, tsd_final.frag).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CharacterUniforms {
    model: [[f32; 4]; 4],
    planes: [[f32; 4]; 6],
    params: [f32; 4],
    map_info: [f32; 4],
}

/// Push constants of the UV-space draws (`TsdPush`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct UvPush {
    z: f32,
    threshold: f32,
    keep_above: f32,
}

/// Push constants of tsd_blur.glsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    dir: [f32; 2],
    std_mm: f32,
    inv_size: f32,
    uv_max: f32,
    alpha_test: i32,
}

/// One character: where it stands, what the optimisations decided for it, its map.
#[derive(Clone, Debug)]
pub struct Character {
    pub model: Mat4,
    /// Eq. 3.1 (1 without depth-sized maps).
    pub s: f32,
    /// The side its passes work in: eq. 3.2, `round(s T_max)`.
    pub size: u32,
    /// Distance from the eye to the nearest corner of its box (Figure 3.3).
    pub d_nearest: f32,
    /// Its head's height on screen at that distance, in pixels.
    pub head_px: f32,
    /// Its box lies outside the view frustum (the z pre-pass culls it).
    pub outside: bool,
    /// Under `--far-px`: refreshed once every `--refresh` frames.
    pub far: bool,
    /// Its map: the scattered diffuse light (alpha: coverage).
    pub map: ImageId,
    /// Set 2 of the mask pipelines (depth, backface, cull) and of the irradiance one.
    uv_sets: [vk::DescriptorSet; 4],
    /// Set 1 of the final pass.
    final_set: vk::DescriptorSet,
}

/// The shared texture-space images (one character's chain at a time).
#[derive(Clone, Copy, Debug)]
pub struct Maps {
    /// The irradiance map, then the chain's ping-pong partner of `pong`.
    pub irradiance: ImageId,
    /// Each Gaussian's u pass output.
    pub temp: ImageId,
    pub pong: ImageId,
    pub stretch_u: ImageId,
    pub stretch_v: ImageId,
    /// The depth/stencil mask (z pre-passes, stencil cull).
    pub mask: Option<ImageId>,
}

#[derive(Default)]
struct Pipelines {
    mask_depth: Pipeline,
    mask_backface: Pipeline,
    mask_cull: Pipeline,
    irradiance: Pipeline,
    blur_u: Pipeline,
    blur_v: Pipeline,
    final_pass: Pipeline,
}

impl Pipelines {
    fn all(&mut self) -> [&mut Pipeline; 7] {
        [
            &mut self.mask_depth,
            &mut self.mask_backface,
            &mut self.mask_cull,
            &mut self.irradiance,
            &mut self.blur_u,
            &mut self.blur_v,
            &mut self.final_pass,
        ]
    }
}

impl Destroy for Pipelines {
    fn destroy(&mut self, ctx: &Context) {
        for p in self.all() {
            p.destroy(ctx);
        }
    }
}

impl Destroy for Tsd {
    fn destroy(&mut self, ctx: &Context) {
        SssMethod::destroy(self, ctx)
    }
}

/// Descriptor sets shared by every character.
#[derive(Clone, Copy, Default)]
struct SharedSets {
    /// Set 0 of the mask pipelines, the irradiance one and the final one.
    frame: [vk::DescriptorSet; 5],
    material: vk::DescriptorSet,
    /// u from the irradiance map, u from `pong`, v from `temp`.
    blur: [vk::DescriptorSet; 3],
}

pub struct Tsd {
    pub config: Config,
    /// Whether this is `tsd-opt` (reported).
    pub optimised: bool,
    pub characters: Vec<Character>,
    pub maps: Maps,
    /// The atlas the maps use.
    pub atlas: Atlas,
    pub gaussians: Vec<TsdGaussian>,
    /// Eq. 3.1's d_ref in scene units for this view.
    pub d_ref_units: f32,
    pipelines: Pipelines,
    pool: DescriptorPool,
    /// The head with each tangent's w carrying its atlas island.
    mesh: GpuMesh,
    character_ubo: Buffer,
    atlas_ubo: Buffer,
    sets: SharedSets,
    diffuse: ImageId,
    shadow: ImageId,
    mask_format: vk::Format,
    /// Frames begun so far, and per character whether this frame updates its
    /// map and whether it has one (set by `begin_frame`, read by `passes`).
    frame: u64,
    updating: Vec<bool>,
    has_map: Vec<bool>,
}

impl Tsd {
    fn new(s: &mut MethodSetup, optimised: bool) -> Result<Self> {
        let config = Config::parse(&s.options, optimised)?;
        let head = &s.scene.head;
        if !head.material.skin {
            bail!("texture-space diffusion needs a skin head to unwrap");
        }
        let atlas = atlas(&head.mesh, s.view.mm_per_unit);
        if atlas.transforms.len() > MAX_ISLANDS {
            bail!(
                "the head's UVs overlap and it has {} islands; texture-space diffusion packs at most {MAX_ISLANDS}",
                atlas.transforms.len()
            );
        }
        let f = &s.ctx.facts;
        if !f.shader_clip_distance {
            bail!("texture-space diffusion clips its unwrapped meshes with clip distances, which device '{}' does not support", f.name);
        }
        if config.size > f.max_image_dimension_2d {
            bail!(
                "--irradiance-size {} exceeds this device's largest image ({})",
                config.size,
                f.max_image_dimension_2d
            );
        }
        let n = s.instances.len() as u64;
        let side = config.size as u64;
        let need = side * side * (8 * (n + 3) + 8 + 5);
        if need > f.device_local_bytes / 2 {
            bail!(
                "{n} characters' texture-space maps at {side}^2 need {:.1} GB, more than half of this device's memory ({:.1} GB); lower --irradiance-size or --heads",
                need as f64 / 1e9,
                f.device_local_bytes as f64 / 1e9
            );
        }
        let t = Tsd {
            config,
            optimised,
            characters: Vec::new(),
            maps: declare_maps(s.res, &config, s.depth_stencil_format),
            atlas,
            gaussians: tsd_gaussians(),
            d_ref_units: 0.0,
            pipelines: Pipelines::default(),
            pool: DescriptorPool::default(),
            mesh: GpuMesh::default(),
            character_ubo: Buffer::default(),
            atlas_ubo: Buffer::default(),
            sets: SharedSets::default(),
            diffuse: s.targets.diffuse,
            shadow: s.targets.shadow,
            mask_format: s.depth_stencil_format,
            frame: 0,
            updating: vec![true; s.instances.len()],
            has_map: vec![false; s.instances.len()],
        };
        // Filled in by `build`: on an error, the guard frees what exists.
        let mut t = Guard::new(s.ctx, t);
        t.build(s)?;
        Ok(t.keep())
    }

    /// Places the characters, uploads the mesh and uniforms, makes the pipelines.
    fn build(&mut self, s: &mut MethodSetup) -> Result<()> {
        let cfg = self.config;
        let view = &s.view;
        let h = view.extent.height;
        self.d_ref_units = reference_distance(
            cfg.d_ref,
            view.mm_per_unit,
            h,
            view.camera.fovy_rad,
            cfg.size,
        );
        let vp = view.camera.view_proj(view.aspect());
        let frustum = clip_planes(vp);
        let planes = if cfg.clip { frustum } else { NO_CLIP };
        let bounds = s.scene.head.mesh.bounds();
        let head_height = s.scene.head_height_units();
        let mut uniforms = vec![0u8; CHARACTER_STRIDE as usize * s.instances.len()];
        for (k, &model) in s.instances.iter().enumerate() {
            let b = bounds.transformed(&model);
            let d = nearest_corner_distance(view.camera.eye, &b);
            let sc = if cfg.depth_sized {
                depth_scale(self.d_ref_units, d)
            } else {
                1.0
            };
            let size = map_size(sc, cfg.size);
            let head_px = projected_px(head_height, d, h, view.camera.fovy_rad);
            let u = CharacterUniforms {
                model: model.to_cols_array_2d(),
                planes: planes.map(|p: Vec4| p.to_array()),
                params: [
                    size as f32 / cfg.size as f32,
                    s.scene.head.material.sss_strength,
                    if cfg.cull == Cull::Alpha {
                        CULL_COS
                    } else {
                        -2.0
                    },
                    0.0,
                ],
                map_info: [1.0 / cfg.size as f32, uv_max(size, cfg.size), 0.0, 0.0],
            };
            let at = k * CHARACTER_STRIDE as usize;
            uniforms[at..at + std::mem::size_of::<CharacterUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
            let map = s.res.declare(ImageDesc::new(
                &format!("tsd map c{k}"),
                square(cfg.size),
                MAP_FORMAT,
            ));
            self.characters.push(Character {
                model,
                s: size as f32 / cfg.size as f32,
                size,
                d_nearest: d,
                head_px,
                outside: cfg.z_prepass && box_outside(&frustum, &b),
                far: cfg.z_prepass && head_px < cfg.far_px,
                map,
                uv_sets: [vk::DescriptorSet::null(); 4],
                final_set: vk::DescriptorSet::null(),
            });
        }
        self.character_ubo = Buffer::with_data(
            s.ctx,
            "tsd characters",
            &uniforms,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let mut islands = vec![[0.0f32; 4]; MAX_ISLANDS];
        for (i, t) in self.atlas.transforms.iter().enumerate() {
            islands[i] = [t[0], t[1], t[2], 0.0];
        }
        self.atlas_ubo = Buffer::with_data(
            s.ctx,
            "tsd atlas",
            bytemuck::cast_slice(&islands),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        self.upload_mesh(s)?;
        self.pipelines = make_pipelines(s.ctx, &cfg, self.mask_format, s.res.format(self.diffuse))?;
        self.pool = DescriptorPool::new(s.ctx, 16 + 6 * s.instances.len() as u32)?;
        Ok(())
    }

    /// The head's vertices with each tangent's w carrying its atlas island.
    fn upload_mesh(&mut self, s: &MethodSetup) -> Result<()> {
        let mesh = &s.scene.head.mesh;
        let vertices: Vec<Vertex> = mesh
            .vertices
            .iter()
            .zip(&self.atlas.island_of)
            .map(|(v, &i)| {
                let hand = if v.tangent[3] < 0.0 { -1.0 } else { 1.0 };
                Vertex {
                    tangent: [
                        v.tangent[0],
                        v.tangent[1],
                        v.tangent[2],
                        hand * (1 + i) as f32,
                    ],
                    ..*v
                }
            })
            .collect();
        self.mesh = GpuMesh::upload(s.ctx, "tsd head", &vertices, &mesh.indices)?;
        Ok(())
    }

    fn updates(&self, k: usize) -> bool {
        self.updating[k]
    }

    /// Triangles of one draw of the head.
    fn triangles(&self) -> u64 {
        self.mesh.triangles()
    }

    fn draw_head(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.mesh.bind_and_draw(ctx, cmd);
    }

    /// The mask as the texture-space passes after the mask pass test it:
    /// depth EQUAL 0 with the z pre-passes, the cull bit with the stencil cull.
    fn mask_test(&self, mask: ImageId) -> DepthStencil {
        let cfg = self.config;
        DepthStencil::test_only(mask)
            .depth_test(cfg.z_prepass)
            .stencil_test((cfg.cull == Cull::Stencil).then_some(1))
    }

    /// The mask pass of character `k`: depth 1 and stencil 0 everywhere, then
    /// (when it is updated) the z pre-passes' draws (depth 0 on the unwrapped
    /// mesh, clipped; depth 1 where it faces away) and the cull mask's
    /// (stencil 1 where it faces the eye within 105 degrees).
    fn mask_pass<'a>(&'a self, k: usize) -> Pass<'a> {
        let cfg = self.config;
        let mask = self
            .maps
            .mask
            .expect("masked configurations declare a mask");
        let c = &self.characters[k];
        let draws = 2 * cfg.z_prepass as u64 + (cfg.cull == Cull::Stencil) as u64;
        let work = ShaderWork {
            shader: MASK_SHADER.into(),
            fetches: Vec::new(),
            alu: alu_estimate(MASK_SHADER, &[]),
            ..Default::default()
        };
        let up = self.updates(k);
        Pass::new(format!("tsd mask c{k}"), PassRole::Sss)
            .depth_stencil(
                DepthStencil::cleared(mask, 1.0)
                    .depth_test(cfg.z_prepass)
                    .depth_write(cfg.z_prepass)
                    .stencil_write(cfg.cull == Cull::Stencil),
            )
            .render_area(square(c.size))
            .draws(Some(work), self.triangles() * draws)
            .record(move |pc: &PassContext| {
                if !up {
                    return;
                }
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.pipelines;
                let c = &self.characters[k];
                if cfg.z_prepass {
                    p.mask_depth.bind(ctx, cmd, &[self.sets.frame[0]]);
                    p.mask_depth.bind_sets(ctx, cmd, 2, &[c.uv_sets[0]]);
                    p.mask_depth.push(ctx, cmd, &uv_push(0.0, 0.0, 0.0));
                    self.draw_head(ctx, cmd);
                    p.mask_backface.bind(ctx, cmd, &[self.sets.frame[1]]);
                    p.mask_backface.bind_sets(ctx, cmd, 2, &[c.uv_sets[1]]);
                    p.mask_backface
                        .push(ctx, cmd, &uv_push(1.0, -BACKFACE_BIAS, 0.0));
                    self.draw_head(ctx, cmd);
                }
                if cfg.cull == Cull::Stencil {
                    p.mask_cull.bind(ctx, cmd, &[self.sets.frame[2]]);
                    p.mask_cull.bind_sets(ctx, cmd, 2, &[c.uv_sets[2]]);
                    // Set after the bind: the pre-pass pipelines before it
                    // take no dynamic stencil reference.
                    unsafe {
                        ctx.device.cmd_set_stencil_reference(
                            cmd,
                            vk::StencilFaceFlags::FRONT_AND_BACK,
                            1,
                        )
                    };
                    p.mask_cull.push(ctx, cmd, &uv_push(0.0, CULL_COS, 1.0));
                    self.draw_head(ctx, cmd);
                }
            })
    }

    /// The irradiance pass of character `k` (MRT: irradiance, stretch u, stretch v).
    fn irradiance_pass<'a>(&'a self, k: usize, f: &FrameView<'a, '_>) -> Pass<'a> {
        let cfg = self.config;
        let m = self.maps;
        let c = &self.characters[k];
        let culls = cfg.cull == Cull::Alpha;
        let shadow = |filter, count, exact| Fetch {
            exact,
            ..fetch(f.res, self.shadow, "shadowMap", filter, count)
        };
        let fetches = vec![
            shadow(Filter::DepthCompare, 9.0, !culls),
            material_fetch("normalTex", false),
            material_fetch("albedoTex", !culls),
            shadow(Filter::Point, 1.0, false),
        ];
        let work = ShaderWork {
            shader: IRRADIANCE_SHADER.into(),
            fetches,
            alu: alu_estimate(IRRADIANCE_SHADER, &PCF_TRIPS),
            ..Default::default()
        };
        // An updated character's maps start cleared (coverage 0 off the mesh).
        let load = if self.updates(k) {
            Load::Clear([0.0; 4])
        } else {
            Load::DontCare
        };
        let mut pass = Pass::new(format!("tsd irradiance c{k}"), PassRole::Sss)
            .sampled(f.targets.shadow)
            .color(ColorTarget::new(m.irradiance, load))
            .color(ColorTarget::new(m.stretch_u, load))
            .color(ColorTarget::new(m.stretch_v, load));
        if let Some(mask) = m.mask {
            pass = pass.depth_stencil(self.mask_test(mask));
        }
        pass.render_area(square(c.size))
            .draws(Some(work), self.triangles())
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.pipelines.irradiance;
                p.bind(ctx, cmd, &[self.sets.frame[3], self.sets.material]);
                p.bind_sets(ctx, cmd, 2, &[self.characters[k].uv_sets[3]]);
                p.push(ctx, cmd, &uv_push(0.0, 0.0, 0.0));
                self.draw_head(ctx, cmd);
            })
    }

    /// Gaussian `g`'s pass along u (`v == false`: source -> temp) or v (temp ->
    /// next, and into character `k`'s map) for character `k`.
    fn blur_pass<'a>(&'a self, k: usize, g: usize, v: bool, f: &FrameView<'a, '_>) -> Pass<'a> {
        let cfg = self.config;
        let m = self.maps;
        let c = &self.characters[k];
        let gauss = self.gaussians[g];
        // G1 reads the irradiance map; the v passes alternate pong, irradiance.
        let (src, dst, stretch, shader) = if v {
            let next = if g % 2 == 0 { m.pong } else { m.irradiance };
            (m.temp, next, m.stretch_v, BLUR_V_SHADER)
        } else {
            let from = if g % 2 == 0 { m.irradiance } else { m.pong };
            (from, m.temp, m.stretch_u, BLUR_U_SHADER)
        };
        let tested = cfg.cull != Cull::Alpha;
        let fetches = vec![
            fetch(f.res, src, "srcTex", Filter::Point, 1.0),
            Fetch {
                exact: tested,
                ..fetch(f.res, stretch, "stretchTex", Filter::Point, 1.0)
            },
            Fetch {
                exact: tested,
                ..fetch(f.res, src, "srcTex", Filter::Bilinear, 6.0)
            },
        ];
        let work = ShaderWork {
            shader: shader.into(),
            fetches,
            alu: alu_estimate(shader, &BLUR_TRIPS),
            ..Default::default()
        };
        // Masked, only texels inside the mask are written: the first Gaussian
        // clears its target (when the character is updated) and later ones keep
        // the zeros outside the mask. Unmasked, every texel is overwritten.
        let up = self.updates(k);
        let masked = cfg.masked();
        let start = if g == 0 && masked && up {
            Load::Clear([0.0; 4])
        } else if g == 0 || !masked {
            Load::DontCare
        } else {
            Load::Keep
        };
        let axis = if v { "v" } else { "u" };
        let mut pass = Pass::new(format!("tsd g{} {axis} c{k}", gauss.index), PassRole::Sss)
            .sampled(src)
            .sampled(stretch)
            .color(ColorTarget::new(dst, start));
        if v {
            // A character not updated keeps its map. An updated one starts
            // from zeros: the first Gaussian blends with w' = 1, but a NaN in
            // memory nobody wrote would survive a factor of 0.
            let load = if g == 0 && up {
                Load::Clear([0.0; 4])
            } else {
                Load::Keep
            };
            pass = pass.color(ColorTarget::new(c.map, load).blended().persistent());
        }
        if let Some(mask) = m.mask {
            pass = pass.depth_stencil(self.mask_test(mask));
        }
        let set = self.sets.blur[if v {
            2
        } else if g % 2 == 0 {
            0
        } else {
            1
        }];
        let push = BlurPush {
            dir: if v { [0.0, 1.0] } else { [1.0, 0.0] },
            std_mm: gauss.std_mm,
            inv_size: 1.0 / cfg.size as f32,
            uv_max: uv_max(c.size, cfg.size),
            alpha_test: (cfg.cull == Cull::Alpha) as i32,
        };
        let blend = gauss.blend;
        let p = if v {
            &self.pipelines.blur_v
        } else {
            &self.pipelines.blur_u
        };
        pass.render_area(square(c.size))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, p, &[set], |ctx, cmd| {
                    p.push(ctx, cmd, &push);
                    if v {
                        unsafe {
                            ctx.device
                                .cmd_set_blend_constants(cmd, &[blend[0], blend[1], blend[2], 1.0])
                        };
                    }
                })
            })
    }

    /// Every head drawn with the frame's vertex shader, its map's diffuse
    /// written where the geometry pass's depth matches.
    fn final_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let ds = f.targets.depth_stencil;
        let first_map = self.characters[0].map;
        let work = ShaderWork {
            shader: FINAL_SHADER.into(),
            fetches: vec![fetch(f.res, first_map, "mapTex", Filter::Bilinear, 1.0)],
            alu: alu_estimate(FINAL_SHADER, &[]),
            ..Default::default()
        };
        let mut pass = Pass::new("tsd final", PassRole::Sss)
            .color(ColorTarget::new(self.diffuse, Load::Keep))
            .depth_stencil(DepthStencil::test_only(ds).depth_test(true));
        for c in &self.characters {
            pass = pass.sampled(c.map);
        }
        pass.draws(Some(work), self.triangles() * self.characters.len() as u64)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.pipelines.final_pass;
                p.bind(ctx, cmd, &[self.sets.frame[4]]);
                for c in &self.characters {
                    p.bind_sets(ctx, cmd, 1, &[c.final_set]);
                    p.push(ctx, cmd, &c.model.to_cols_array_2d());
                    self.draw_head(ctx, cmd);
                }
            })
    }
}

/// The largest tap coordinate of a map working in `size` of `t_max` texels.
fn uv_max(size: u32, t_max: u32) -> f32 {
    (size as f32 - 0.5 - EDGE_GUARD_TEXELS) / t_max as f32
}

fn square(side: u32) -> vk::Extent2D {
    vk::Extent2D {
        width: side,
        height: side,
    }
}

fn uv_push(z: f32, threshold: f32, keep_above: f32) -> UvPush {
    UvPush {
        z,
        threshold,
        keep_above,
    }
}

/// At most one fetch of a skin material's RGBA8 texture (bilinear, level 0).
fn material_fetch(texture: &str, exact: bool) -> Fetch {
    Fetch {
        texture: texture.into(),
        format: Format::Rgba8Unorm,
        filter: Filter::Bilinear,
        count: 1.0,
        exact,
        // Texels are shaded in the map's own order: neighbours fetch neighbours.
        coherent: true,
    }
}

fn declare_maps(res: &mut Resources, cfg: &Config, mask_format: vk::Format) -> Maps {
    let e = square(cfg.size);
    Maps {
        irradiance: res.declare(ImageDesc::new("tsd irradiance", e, MAP_FORMAT)),
        temp: res.declare(ImageDesc::new("tsd temp", e, MAP_FORMAT)),
        pong: res.declare(ImageDesc::new("tsd pong", e, MAP_FORMAT)),
        stretch_u: res.declare(ImageDesc::new("tsd stretch u", e, STRETCH_FORMAT)),
        stretch_v: res.declare(ImageDesc::new("tsd stretch v", e, STRETCH_FORMAT)),
        mask: cfg
            .masked()
            .then(|| res.declare(ImageDesc::new("tsd mask", e, mask_format))),
    }
}

/// The method's pipelines; the mask ones only where the configuration uses them.
fn make_pipelines(
    ctx: &Context,
    cfg: &Config,
    mask_format: vk::Format,
    diffuse_format: vk::Format,
) -> Result<Pipelines> {
    // On an error, the guard frees the pipelines made so far.
    let mut p = Guard::<Pipelines>::null(ctx);
    fill_pipelines(&mut p, ctx, cfg, mask_format, diffuse_format)?;
    Ok(p.keep())
}

fn uv_desc(name: &str, frag: Option<&'static str>, colors: Vec<vk::Format>) -> GraphicsDesc {
    GraphicsDesc {
        name: name.into(),
        vert: UV_VERT,
        frag,
        color_formats: colors,
        depth_format: None,
        stencil_format: None,
        vertex_input: VertexInput::Mesh,
        // Winding in UV space says nothing about facing.
        cull: vk::CullModeFlags::NONE,
        depth_test: false,
        depth_write: false,
        depth_compare: vk::CompareOp::ALWAYS,
        stencil: None,
        depth_bias: None,
        blend: Blend::None,
    }
}

/// The texture-space passes' test against the mask: depth EQUAL 0 (z
/// pre-passes) and/or the stencil cull bit.
fn masked(mut d: GraphicsDesc, cfg: &Config, mask_format: vk::Format) -> GraphicsDesc {
    if cfg.masked() {
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        if cfg.z_prepass {
            d.depth_test = true;
            d.depth_compare = vk::CompareOp::EQUAL;
        }
        if cfg.cull == Cull::Stencil {
            d.stencil = Some(stencil(vk::CompareOp::EQUAL, vk::StencilOp::KEEP, 0));
        }
    }
    d
}

fn stencil(compare: vk::CompareOp, pass: vk::StencilOp, write_mask: u32) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: compare,
        compare_mask: 1,
        write_mask,
        reference: 1,
    }
}

fn fill_pipelines(
    p: &mut Pipelines,
    ctx: &Context,
    cfg: &Config,
    mask_format: vk::Format,
    diffuse_format: vk::Format,
) -> Result<()> {
    if cfg.z_prepass {
        let mut d = uv_desc("tsd z frustum", None, Vec::new());
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        d.depth_test = true;
        d.depth_write = true;
        p.mask_depth = Pipeline::graphics(ctx, &d)?;
        d.name = "tsd z backface".into();
        d.frag = Some(MASK_SHADER);
        p.mask_backface = Pipeline::graphics(ctx, &d)?;
    }
    if cfg.cull == Cull::Stencil {
        let mut d = uv_desc("tsd cull mask", Some(MASK_SHADER), Vec::new());
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        d.stencil = Some(stencil(vk::CompareOp::ALWAYS, vk::StencilOp::REPLACE, 1));
        p.mask_cull = Pipeline::graphics(ctx, &d)?;
    }
    let irr = uv_desc(
        "tsd irradiance",
        Some(IRRADIANCE_SHADER),
        vec![MAP_FORMAT, STRETCH_FORMAT, STRETCH_FORMAT],
    );
    p.irradiance = Pipeline::graphics(ctx, &masked(irr, cfg, mask_format))?;
    let blur = |name: &str, frag: &'static str, colors: usize| {
        let mut d = GraphicsDesc::fullscreen(name, frag, MAP_FORMAT);
        d.color_formats = vec![MAP_FORMAT; colors];
        if colors == 2 {
            d.blend = Blend::ConstantMix(1);
        }
        masked(d, cfg, mask_format)
    };
    p.blur_u = Pipeline::graphics(ctx, &blur("tsd blur u", BLUR_U_SHADER, 1))?;
    p.blur_v = Pipeline::graphics(ctx, &blur("tsd blur v", BLUR_V_SHADER, 2))?;
    // The geometry pass's vertex shader on the geometry pass's triangles: the
    // same depths, tested LESS_OR_EQUAL (biased a hair toward the eye), no writes.
    p.final_pass = Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            name: "tsd final".into(),
            vert: "geometry.vert",
            frag: Some(FINAL_SHADER),
            color_formats: vec![diffuse_format],
            depth_format: Some(mask_format),
            stencil_format: Some(mask_format),
            vertex_input: VertexInput::Mesh,
            cull: vk::CullModeFlags::BACK,
            depth_test: true,
            depth_write: false,
            depth_compare: vk::CompareOp::LESS_OR_EQUAL,
            stencil: None,
            depth_bias: Some((FINAL_DEPTH_BIAS, 0.0)),
            blend: Blend::None,
        },
    )?;
    Ok(())
}

impl SssMethod for Tsd {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let mut passes = Vec::new();
        for k in 0..self.characters.len() {
            if self.config.masked() {
                passes.push(self.mask_pass(k));
            }
            passes.push(self.irradiance_pass(k, f));
            for g in 0..self.gaussians.len() {
                passes.push(self.blur_pass(k, g, false, f));
                passes.push(self.blur_pass(k, g, true, f));
            }
        }
        passes.push(self.final_pass(f));
        passes
    }

    /// Which characters this frame updates: all, unless the z pre-passes cull
    /// a character as outside the frustum, or as far and not due for its
    /// refresh (after it has a map).
    fn begin_frame(&mut self) {
        let f = self.frame;
        for (k, c) in self.characters.iter().enumerate() {
            let up =
                !c.outside && (!c.far || !self.has_map[k] || refreshes(f, k, self.config.refresh));
            self.updating[k] = up;
            self.has_map[k] |= up;
        }
        self.frame = f + 1;
    }

    fn output(&self) -> ImageId {
        self.diffuse
    }

    /// The final pass draws the heads themselves: no screen-space taps.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        None
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        let frame_set = |p: &Pipeline| -> Result<vk::DescriptorSet> {
            let binds: Vec<(&str, Bind)> = b
                .frame_binds
                .iter()
                .filter(|(n, _)| p.reflection.find(0, n).is_some())
                .copied()
                .collect();
            self.pool.write_set(b.ctx, p, 0, &binds)
        };
        let p = &self.pipelines;
        let mut frame = [vk::DescriptorSet::null(); 5];
        if self.config.z_prepass {
            frame[0] = frame_set(&p.mask_depth)?;
            frame[1] = frame_set(&p.mask_backface)?;
        }
        if self.config.cull == Cull::Stencil {
            frame[2] = frame_set(&p.mask_cull)?;
        }
        frame[3] = frame_set(&p.irradiance)?;
        frame[4] = frame_set(&p.final_pass)?;
        let material = self
            .pool
            .write_set(b.ctx, &p.irradiance, 1, &b.skin_material_binds)?;
        let m = self.maps;
        let blur_set = |pipe: &Pipeline, src: ImageId, stretch: ImageId| {
            self.pool.write_set(
                b.ctx,
                pipe,
                0,
                &[
                    ("srcTex", Bind::Texture(b.res.view(src))),
                    ("stretchTex", Bind::Texture(b.res.view(stretch))),
                    ("linearClamp", Bind::Sampler(b.samplers.linear_clamp)),
                ],
            )
        };
        let blur = [
            blur_set(&p.blur_u, m.irradiance, m.stretch_u)?,
            blur_set(&p.blur_u, m.pong, m.stretch_u)?,
            blur_set(&p.blur_v, m.temp, m.stretch_v)?,
        ];
        let size = std::mem::size_of::<CharacterUniforms>() as u64;
        let atlas = Bind::Uniform {
            buffer: self.atlas_ubo.raw,
            size: (MAX_ISLANDS * 16) as u64,
        };
        let mut sets = Vec::with_capacity(self.characters.len());
        for (k, c) in self.characters.iter().enumerate() {
            let ch = Bind::Range {
                buffer: self.character_ubo.raw,
                offset: k as u64 * CHARACTER_STRIDE,
                size,
            };
            let uv_set = |pipe: &Pipeline, used: bool| -> Result<vk::DescriptorSet> {
                if !used {
                    return Ok(vk::DescriptorSet::null());
                }
                let binds: Vec<(&str, Bind)> = [("ch", ch), ("atlas", atlas)]
                    .into_iter()
                    .filter(|(n, _)| pipe.reflection.find(2, n).is_some())
                    .collect();
                self.pool.write_set(b.ctx, pipe, 2, &binds)
            };
            let uv_sets = [
                uv_set(&p.mask_depth, self.config.z_prepass)?,
                uv_set(&p.mask_backface, self.config.z_prepass)?,
                uv_set(&p.mask_cull, self.config.cull == Cull::Stencil)?,
                uv_set(&p.irradiance, true)?,
            ];
            let final_set = self.pool.write_set(
                b.ctx,
                &p.final_pass,
                1,
                &[
                    ("mapTex", Bind::Texture(b.res.view(c.map))),
                    ("linearClamp", Bind::Sampler(b.samplers.linear_clamp)),
                    ("ch", ch),
                    ("atlas", atlas),
                ],
            )?;
            sets.push((uv_sets, final_set));
        }
        for (c, (uv_sets, final_set)) in self.characters.iter_mut().zip(sets) {
            c.uv_sets = uv_sets;
            c.final_set = final_set;
        }
        self.sets = SharedSets {
            frame,
            material,
            blur,
        };
        Ok(())
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "optimised": self.optimised,
            "config": self.config,
            "t_max": self.config.size,
            "d_ref_units": self.d_ref_units,
            "atlas": {
                "repacked": self.atlas.repacked,
                "islands": self.atlas.islands,
                "overlap": self.atlas.overlap,
            },
            "gaussians": self.gaussians.iter().map(|g| serde_json::json!({
                "index": g.index, "std_mm": g.std_mm, "blend": g.blend,
            })).collect::<Vec<_>>(),
            "characters": self.characters.iter().map(|c| serde_json::json!({
                "s": c.s, "size": c.size, "d_nearest": c.d_nearest,
                "head_px": c.head_px, "outside": c.outside, "far": c.far,
            })).collect::<Vec<_>>(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipelines.destroy(ctx);
        self.pool.destroy(ctx);
        self.mesh.destroy(ctx);
        self.character_ubo.destroy(ctx);
        self.atlas_ubo.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::MethodOptions;

    #[test]
    fn options_parse_and_plain_has_no_optimisation() {
        let none = MethodOptions::default();
        let plain = Config::parse(&ENTRY.opts(&none), false).unwrap();
        assert_eq!(plain, Config::PLAIN);
        assert!(!plain.masked());
        let opt = Config::parse(&OPT_ENTRY.opts(&none), true).unwrap();
        assert_eq!(opt.cull, Cull::Stencil);
        assert!(opt.depth_sized && opt.clip && opt.z_prepass && opt.masked());
        let off = none.with(&[
            ("cull", "off"),
            ("depth-sized", "false"),
            ("clip", "false"),
            ("z-prepass", "false"),
        ]);
        let c = Config::parse(&OPT_ENTRY.opts(&off), true).unwrap();
        assert_eq!(
            c,
            Config {
                far_px: 64.0,
                refresh: 4,
                ..Config::PLAIN
            }
        );
        for (k, v) in [
            ("cull", "maybe"),
            ("irradiance-size", "8"),
            ("d-ref", "-1"),
            ("refresh", "0"),
            ("far-px", "nan"),
        ] {
            let bad = none.with(&[(k, v)]);
            assert!(
                Config::parse(&OPT_ENTRY.opts(&bad), true).is_err(),
                "{k} {v}"
            );
        }
        assert_eq!(uv_max(64, 64), (63.5 - EDGE_GUARD_TEXELS) / 64.0);
    }
}
