//! `gather`: the 2D gather of the exact profile on the compute path (issue
//! 28): an importance-sampled disk per skin pixel (HDRP's, ANCHORS.md), of
//! the six Gaussians or of Burley's profile (`profile=`), its sample count
//! from the profile's radius in pixels and a budget (`samples=`). The
//! derivation and a CPU mirror are `skin::gather`; the shader is gather.comp.
//!
//! Compute only: one dispatch over the skin tiles (`tiles`) writes the
//! intermediate at this group's skin pixels and `sss merge` copies them into
//! the diffuse target. It reads the diffuse target directly (no seed), so its
//! region only has to hold the skin pixels it shades.

use std::any::Any;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use super::profile::{self, Profile};
use super::region::ReachScale;
use super::screen::{declare_intermediate, fetch, fetch_at_most};
use super::tiles::{SkinTiles, TILE_INVOCATIONS};
use super::{
    EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs, OptKind, OptSpec, Opts,
    SssMethod,
};
use crate::graph::work::{Fetch, Filter, ShaderWork, Spread};
use crate::graph::{Binding, GraphSet, ImageId, Pass, Storage};
use crate::skin::gather::{
    sample_count, GatherProfile, BUDGET_RANGE, GOLDEN_ANGLE, LUT_SIZE, LUT_VEC4S, MIN_SAMPLES,
    PIXELS_PER_SAMPLE,
};
use crate::skin::tissue::TISSUE_TOLERANCE;
use crate::view::ViewScale;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, Pipeline};
use crate::vk::shader_stats::alu_estimate;

const SHADER: &str = "gather.comp";

const OPTIONS: &[OptSpec] = &[
    OptSpec {
        key: "sample-budget",
        kind: OptKind::Value,
        default: "40",
        help: "the most samples a pixel takes, 4..=1000 (HDRP's budgets: 20 low, 40 medium, 80 high); fewer where the profile covers few pixels (pi r_px^2 / 4)",
    },
    profile::OPTION,
];

pub static ENTRY: MethodEntry = MethodEntry {
    name: "gather",
    aliases: &["gather2d", "disk"],
    summary:
        "2D importance-sampled gather of the exact profile (six Gaussians or Burley), compute only",
    options: OPTIONS,
    eval: &[
        EvalSetting {
            label: "20 samples",
            options: &[("sample-budget", "20")],
        },
        EvalSetting {
            label: "40 samples",
            options: &[("sample-budget", "40")],
        },
        EvalSetting {
            label: "80 samples",
            options: &[("sample-budget", "80")],
        },
        EvalSetting {
            label: "burley, 40 samples",
            options: &[("sample-budget", "40"), (profile::KEY, "burley")],
        },
    ],
    ground_truth: false,
    dolly: &["40 samples"],
    // The geometry pass's view-space normals: the tissue test of each tap.
    needs: |_, _| Needs {
        normals: true,
        ..Needs::PLAIN
    },
    check: |o| Config::parse(o).map(|_| ()),
    build: |s| Ok(Box::new(Gather::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
    poses_once: None,
};

/// The method's options, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub budget: u32,
    pub profile: Profile,
}

impl Config {
    pub fn parse(o: &Opts) -> Result<Self> {
        let budget: u32 = o.parse("sample-budget")?;
        if !BUDGET_RANGE.contains(&budget) {
            bail!(
                "sample-budget must be within {}..={}, got {budget}",
                BUDGET_RANGE.start(),
                BUDGET_RANGE.end()
            );
        }
        Ok(Config {
            budget,
            profile: o.parse(profile::KEY)?,
        })
    }
}

/// Push constants of gather.comp (std430, 64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherPush {
    burley_s: [f32; 4],
    height_px: f32,
    tan_half_fovy: f32,
    mm_per_unit: f32,
    max_radius_mm: f32,
    pixels_per_sample: f32,
    budget: u32,
    min_samples: u32,
    code: u32,
    golden_angle: f32,
    widest: u32,
    lut_size: u32,
    tissue_tolerance: f32,
}

pub struct Gather {
    pipeline: Pipeline,
    set: GraphSet,
    lut: Buffer,
    tiles: SkinTiles,
    diffuse: ImageId,
    normals: ImageId,
    push: GatherPush,
    scale: ViewScale,
    pub config: Config,
    pub profile: GatherProfile,
}

impl Gather {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let config = Config::parse(&s.options)?;
        let profile = GatherProfile::new(config.profile);
        let diffuse = s.targets.diffuse;
        let normals = s
            .targets
            .normals
            .context("the frame has no normal target, which gather's tissue test needs")?;
        let out = declare_intermediate(s.res, diffuse, "sss intermediate");
        // Guarded until the method holds them: an error frees what exists.
        let pipeline = Guard::new(s.ctx, Pipeline::compute(s.ctx, "gather", SHADER)?);
        let mut tiles = Guard::new(s.ctx, SkinTiles::new(s)?);
        tiles.add_merge(s, out, diffuse)?;
        let mut table = vec![0.0f32; LUT_VEC4S * 4];
        table[..=LUT_SIZE].copy_from_slice(&profile.lut_mm);
        let lut = Guard::new(
            s.ctx,
            Buffer::with_data(
                s.ctx,
                "gather table",
                bytemuck::cast_slice(&table),
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
        );
        let set = GraphSet::new(
            s.res,
            &pipeline,
            0,
            vec![
                ("colorTex", Binding::Sampled(diffuse)),
                ("depthTex", Binding::Sampled(s.targets.linear_depth)),
                ("normalTex", Binding::Sampled(normals)),
                (
                    "stencilTex",
                    Binding::SampledStencil(s.targets.depth_stencil),
                ),
                ("Tiles", tiles.list_binding(Storage::Read, 0)),
                ("outImage", Binding::StorageImage(out, Storage::Write)),
                (
                    "linearClamp",
                    Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                ),
                (
                    "nearestClamp",
                    Binding::Fixed(Bind::Sampler(s.samplers.nearest_clamp)),
                ),
                (
                    "Lut",
                    Binding::Fixed(Bind::Uniform {
                        buffer: lut.raw,
                        size: (table.len() * 4) as u64,
                    }),
                ),
            ],
        );
        let scale = s.view.scale();
        let b = profile.burley_s;
        let push = GatherPush {
            burley_s: [
                b[0],
                b[1],
                b[2],
                f32::from(u8::from(config.profile == Profile::Burley)),
            ],
            height_px: scale.height_px as f32,
            tan_half_fovy: scale.tan_half_fovy,
            mm_per_unit: scale.mm_per_unit,
            max_radius_mm: profile.max_radius_mm(),
            pixels_per_sample: PIXELS_PER_SAMPLE,
            budget: config.budget,
            min_samples: MIN_SAMPLES,
            code: 0,
            golden_angle: GOLDEN_ANGLE,
            widest: profile.widest as u32,
            lut_size: LUT_SIZE as u32,
            tissue_tolerance: TISSUE_TOLERANCE,
        };
        Ok(Gather {
            pipeline: pipeline.keep(),
            set,
            lut: lut.keep(),
            tiles: tiles.keep(),
            diffuse,
            normals,
            push,
            scale,
            config,
            profile,
        })
    }

    /// Samples per skin pixel at view depth `depth` (full strength).
    fn samples_at(&self, depth: f32) -> u32 {
        sample_count(
            self.profile.max_radius_mm() * self.scale.px_per_mm(depth),
            self.config.budget,
        )
    }
}

impl SssMethod for Gather {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let t = f.targets;
        // The most samples a skin pixel takes: the count at each skin
        // cluster's nearest depth (full strength), doubled for the pixels of
        // a cluster nearer than its box says (the count grows with the square
        // of the scale), within the budget. Each sample reads stencil, colour,
        // depth and normal (the tissue test).
        let clusters: Vec<(f64, f32)> =
            f.depths.iter().copied().filter(|&(_, d)| d > 0.0).collect();
        let total: f64 = clusters.iter().map(|c| c.0).sum();
        let nearest = clusters
            .iter()
            .map(|&(_, d)| self.samples_at(d))
            .max()
            .unwrap_or(0);
        let mean = f64::from((2 * nearest).min(self.config.budget.max(MIN_SAMPLES)));
        let spread: Vec<Spread> = clusters
            .iter()
            .map(|&(share, d)| Spread {
                share: share / total,
                radius_px: f64::from(self.profile.max_radius_mm() * self.scale.px_per_mm(d)) / 2.0,
            })
            .collect();
        let spread = Spread::compact(&spread);
        let taps = |image, texture: &str| Fetch {
            exact: false,
            coherent: false,
            spread: spread.clone(),
            ..fetch(f.res, image, texture, Filter::Point, mean)
        };
        // Invocations outside the image or the skin fetch nothing. Each
        // sample gathers the stencil of its 2x2 footprint and reads the light
        // bilinearly there, or at the skin's edge the nearest texel's
        // stencil and light (point: at most once a sample); the pixel's normal once.
        let fetches = vec![
            fetch_at_most(
                f.res,
                t.depth_stencil,
                "stencilTex",
                Filter::Point,
                1.0 + mean,
            ),
            fetch_at_most(f.res, t.diffuse, "colorTex", Filter::Point, 1.0 + mean),
            fetch_at_most(f.res, t.linear_depth, "depthTex", Filter::Point, 1.0),
            fetch_at_most(f.res, self.normals, "normalTex", Filter::Point, 1.0),
            Fetch {
                filter: Filter::Bilinear,
                ..taps(t.depth_stencil, "stencilTex")
            },
            Fetch {
                filter: Filter::Bilinear,
                ..taps(t.diffuse, "colorTex")
            },
            taps(t.linear_depth, "depthTex"),
            taps(self.normals, "normalTex"),
        ];
        let work = ShaderWork {
            shader: SHADER.into(),
            fetches,
            alu: alu_estimate(SHADER, &[mean as u32, 3]),
            storage_read_bytes: 4.0 / TILE_INVOCATIONS as f64,
            storage_write_bytes: 8.0,
            // No shared memory: the taps go through the texture units.
            shared_bytes: 0.0,
        };
        let push = GatherPush {
            code: f.stencil,
            ..self.push
        };
        let mut passes: Vec<Pass<'a>> = self.tiles.passes(f).into();
        passes.push(
            self.tiles
                .pass("gather", f, 0, work, &self.pipeline, &self.set, push),
        );
        passes.extend(self.tiles.merge_pass(f));
        passes
    }

    fn output(&self) -> ImageId {
        // The merge wrote the skin pixels into the diffuse target.
        self.diffuse
    }

    /// The gather reads the diffuse target itself, never a seed: its region
    /// only has to hold the skin pixels it shades.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        Some(0.0)
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        b.write(&mut self.set, &self.pipeline)?;
        self.tiles.bind(b)
    }

    fn intermediates(&self) -> Vec<ImageId> {
        // Only written and read at skin pixels.
        Vec::new()
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "profile": self.config.profile.name(),
            "budget": self.config.budget,
            "widest_channel": self.profile.widest,
            "kept_mass_radius_mm": self.profile.max_radius_mm(),
            "path": "compute",
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.lut.destroy(ctx);
        self.tiles.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
