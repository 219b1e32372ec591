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
//!
//! The folder, by concern: this file holds the registry rows, the options
//! and their `Config`, the method's state and the frame's order of passes
//! (`begin_frame` decides which character's map updates); `setup` places the
//! characters and uploads the mesh and uniforms, `pipelines` makes the
//! pipelines, `sets` writes the descriptor sets, `passes` records the
//! per-frame passes.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;
use glam::Mat4;

use super::region::ReachScale;
use super::{
    EvalSetting, FrameView, MethodBind, MethodEntry, Needs, OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::mesh::GpuMesh;
use crate::graph::{GraphSet, ImageId, Pass};
use crate::skin::tsd::{self, refreshes, Atlas, TsdGaussian, EDGE_GUARD_TEXELS};
use crate::vk::context::Context;
use crate::vk::guard::Destroy;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::DescriptorPool;

mod passes;
mod pipelines;
mod sets;
mod setup;

use pipelines::Pipelines;
use sets::SharedSets;

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

/// The largest tap coordinate of a map working in `size` of `t_max` texels.
fn uv_max(size: u32, t_max: u32) -> f32 {
    (size as f32 - 0.5 - EDGE_GUARD_TEXELS) / t_max as f32
}

/// A square of `side` texels: every map's extent and render area.
fn square(side: u32) -> vk::Extent2D {
    vk::Extent2D {
        width: side,
        height: side,
    }
}

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

/// Why neither tsd entry runs with `--msaa` (docs/aa.md).
/// Why texture space cannot step through a motion (`--time-step`).
const POSES_ONCE: &str =
    "texture space unwraps each character's head, and places its maps, once, as it is built";

const NO_MSAA: Option<&str> = Some("texture-space diffusion shades in a second mesh pass, drawn depth-EQUAL against the frame's depth: with --msaa that depth is resolved from sample 0 and no single-sample redraw matches it (and the pass itself would alias)");

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
    no_msaa: NO_MSAA,
    no_mix: |_| None,
    no_sss: false,
    poses_once: Some(POSES_ONCE),
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
    no_msaa: NO_MSAA,
    no_mix: |_| None,
    no_sss: false,
    poses_once: Some(POSES_ONCE),
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
    /// The character's wrinkle zone weights (`skin::wrinkles`).
    zones: [[f32; 4]; 2],
}

/// One character: where it stands, what the optimisations decided for it, its map.
#[derive(Debug)]
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
    /// Its expression weighs a wrinkle zone: its irradiance pass reads the
    /// wrinkle maps.
    pub wrinkled: bool,
    /// Its map: the scattered diffuse light (alpha: coverage).
    pub map: ImageId,
    /// Set 2 of the mask pipelines (depth, backface, cull) and of the irradiance one.
    uv_sets: [vk::DescriptorSet; 4],
    /// Set 1 of the final pass.
    final_set: GraphSet,
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

impl Destroy for Tsd {
    fn destroy(&mut self, ctx: &Context) {
        SssMethod::destroy(self, ctx)
    }
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

    /// Every descriptor set of the method (`sets`).
    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        self.write_sets(b)
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
