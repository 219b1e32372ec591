//! Poisson-disk screen-space SSS (seed 003, Agni's Philosophy): mip chains of
//! the diffuse, linear-depth and normal targets (one 2x2-mean pass per level, all
//! three through MRT), then one pass of up to 32 disk samples read from the level
//! the kernel radius asks for, weighted by distance, depth and normal difference.
//!
//! The pass reads every level of the diffuse chain, so it writes into an
//! intermediate (seeded with a copy of level 0, so non-skin pixels keep their
//! colour) and the composite reads the intermediate.
//!
//! `--path compute`: the pass is a dispatch over the skin tiles
//! (poisson_tiles.comp, the arithmetic shared in poisson_body.glsl) writing
//! the intermediate at skin pixels only, and `sss merge` copies them into
//! level 0 of the diffuse chain, which the composite then reads: no seed
//! copy of the screen.

use std::any::Any;

use anyhow::{Context as _, Result};
use ash::vk;

use super::path::{self, Path};
use super::region::ReachScale;
use super::screen::{declare_intermediate, fetch, fetch_at_most, masked_pass, seed_copy, Masked};
use super::tiles::{SkinTiles, TILE_INVOCATIONS};
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    SssMethod,
};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Filter, PassRole, ShaderWork};
use crate::graph::{Binding, ColorTarget, GraphSet, ImageId, Load, Pass, PassContext, Storage};
use crate::skin::poisson::{poisson_disk_32, PoissonParams};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

const SHADER: &str = "poisson.frag";
const COMPUTE_SHADER: &str = "poisson_tiles.comp";
const MIP_SHADER: &str = "poisson_mip_down.frag";
/// Mip levels of the chains: enough for radii of 16 x 2^4 = 256 pixels.
pub const MAX_LEVELS: u32 = 5;
/// The most disk samples a pixel takes (8, 16 or 32 by its radius in pixels).
const MAX_TAPS: u32 = 32;

pub static ENTRY: MethodEntry = MethodEntry {
    name: "poisson",
    aliases: &[],
    summary: "Poisson-disk screen-space SSS over mip chains (seed 003, Agni's Philosophy)",
    options: &[path::OPTION],
    eval: &[EvalSetting {
        label: "8-32 taps",
        options: &[],
    }],
    ground_truth: false,
    dolly: &["8-32 taps"],
    needs: |_, extent| Needs {
        normals: true,
        mip_levels: levels_for(extent),
        geometry_transmittance: true,
    },
    check: |o| o.parse::<Path>("path").map(|_| ()),
    build: |s| Ok(Box::new(Poisson::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
    poses_once: None,
};

/// Levels for a target of `extent` (every level at least one texel).
pub fn levels_for(extent: vk::Extent2D) -> u32 {
    let full = 32 - extent.width.max(extent.height).max(1).leading_zeros();
    full.min(MAX_LEVELS)
}

/// Push constants of poisson_body.glsl (std430, 84 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PoissonPush {
    size: [f32; 2],
    tan_half_fovy: f32,
    mm_per_unit: f32,
    /// One row per tap count (8, 16, 32): rgb falloff, w unused.
    falloff: [[f32; 4]; 3],
    radius_mm: f32,
    depth_sensitivity: f32,
    normal_sensitivity: f32,
    max_level: i32,
    /// The compute path's stencil code (0 on the fragment path).
    code: u32,
}

pub struct Poisson {
    mip_pipeline: Pipeline,
    pipeline: Pipeline,
    /// The per-level ids of the colour, depth and normal chains.
    chains: [Vec<ImageId>; 3],
    /// Level `l + 1`'s pass reads level `l` of the three chains.
    mip_sets: Vec<GraphSet>,
    /// Every level of the three chains.
    set: GraphSet,
    disk_buffer: Buffer,
    /// The output (seeded with the diffuse target's level 0); on the compute
    /// path written at skin pixels only, then merged into the diffuse target.
    out: ImageId,
    diffuse: ImageId,
    /// The compute path's tile list and merge (`pipeline` and `set` are then
    /// the compute pass's).
    tiles: Option<SkinTiles>,
    push: PoissonPush,
    pub params: PoissonParams,
    pub levels: u32,
}

impl Poisson {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let t = s.targets;
        let normals = t
            .normals
            .context("the frame has no normal target, which poisson needs")?;
        let levels = s.res.levels(t.diffuse).len() as u32;
        let out = declare_intermediate(s.res, t.diffuse, "sss intermediate");
        let format = s.res.format(t.diffuse);
        let mut mip = GraphicsDesc::fullscreen("poisson mip", MIP_SHADER, format);
        mip.color_formats = vec![format, s.res.format(t.linear_depth), s.res.format(normals)];
        // Guarded until the method holds them: an error frees what exists.
        let mip_pipeline = Guard::new(s.ctx, Pipeline::graphics(s.ctx, &mip)?);
        let path: Path = s.options.parse("path")?;
        let pipeline = Guard::new(
            s.ctx,
            match path {
                Path::Fragment => {
                    let mut d = GraphicsDesc::fullscreen("poisson", SHADER, format);
                    d.depth_format = Some(s.depth_stencil_format);
                    d.stencil_format = Some(s.depth_stencil_format);
                    d.stencil = Some(skin_stencil_test());
                    Pipeline::graphics(s.ctx, &d)?
                }
                Path::Compute => Pipeline::compute(s.ctx, "poisson", COMPUTE_SHADER)?,
            },
        );
        let mut tiles = Guard::new(
            s.ctx,
            match path {
                Path::Fragment => None,
                Path::Compute => Some(SkinTiles::new(s)?),
            },
        );
        if let Some(t) = tiles.as_mut() {
            t.add_merge(s, out, s.targets.diffuse)?;
        }
        let disk: Vec<[f32; 4]> = poisson_disk_32()
            .iter()
            .map(|p| [p[0], p[1], 0.0, 0.0])
            .collect();
        let disk_buffer = Guard::new(
            s.ctx,
            Buffer::with_data(
                s.ctx,
                "poisson disk",
                bytemuck::cast_slice(&disk),
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
        );
        let p = PoissonParams::from_profile();
        let push = PoissonPush {
            size: [s.view.extent.width as f32, s.view.extent.height as f32],
            tan_half_fovy: s.view.tan_half_fovy(),
            mm_per_unit: s.view.mm_per_unit,
            falloff: p.falloff.map(|f| [f[0], f[1], f[2], 0.0]),
            radius_mm: p.radius_mm,
            depth_sensitivity: p.depth_sensitivity,
            normal_sensitivity: p.normal_sensitivity,
            max_level: levels as i32 - 1,
            code: 0,
        };
        let chains = [t.diffuse, t.linear_depth, normals].map(|c| s.res.levels(c));
        let [color, depth, normal] = &chains;
        let mip_sets = (1..levels as usize)
            .map(|l| {
                GraphSet::new(
                    s.res,
                    &mip_pipeline,
                    0,
                    vec![
                        ("srcColor", Binding::Sampled(color[l - 1])),
                        ("srcDepth", Binding::Sampled(depth[l - 1])),
                        ("srcNormal", Binding::Sampled(normal[l - 1])),
                    ],
                )
            })
            .collect();
        let mut binds = vec![
            ("colorChain", Binding::SampledLevels(t.diffuse)),
            ("depthChain", Binding::SampledLevels(t.linear_depth)),
            ("normalChain", Binding::SampledLevels(normals)),
            (
                "mipClamp",
                Binding::Fixed(Bind::Sampler(s.samplers.mip_clamp)),
            ),
            (
                "disk",
                Binding::Fixed(Bind::Uniform {
                    buffer: disk_buffer.raw,
                    size: (MAX_TAPS * 16) as u64,
                }),
            ),
        ];
        if let Some(tl) = tiles.as_ref() {
            binds.extend([
                ("stencilTex", Binding::SampledStencil(t.depth_stencil)),
                ("Tiles", tl.list_binding(Storage::Read, 0)),
                ("outImage", Binding::StorageImage(out, Storage::Write)),
            ]);
        }
        let set = GraphSet::new(s.res, &pipeline, 0, binds);
        Ok(Poisson {
            mip_pipeline: mip_pipeline.keep(),
            pipeline: pipeline.keep(),
            chains,
            mip_sets,
            set,
            disk_buffer: disk_buffer.keep(),
            out,
            diffuse: t.diffuse,
            tiles: tiles.keep(),
            push,
            params: p,
            levels,
        })
    }
}

impl SssMethod for Poisson {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let t = f.targets;
        let mut passes = match &self.tiles {
            // The composite reads the output on every pixel: seed all of it.
            None => vec![seed_copy(
                "poisson seed copy",
                f,
                t.diffuse,
                f.screen,
                &[self.out],
            )],
            Some(tiles) => tiles.passes(f).into(),
        };
        let chains = &self.chains;
        for l in 1..self.levels as usize {
            let mut fetches = Vec::new();
            let mut pass = Pass::new(format!("poisson mip {l}"), PassRole::Sss);
            for (c, texture) in chains.iter().zip(["srcColor", "srcDepth", "srcNormal"]) {
                fetches.push(fetch(f.res, c[l - 1], texture, Filter::Point, 4.0));
                pass = pass
                    .sampled(c[l - 1])
                    .color(ColorTarget::new(c[l], Load::DontCare));
            }
            let work = ShaderWork {
                shader: MIP_SHADER.into(),
                fetches,
                alu: alu_estimate(MIP_SHADER, &[]),
                ..Default::default()
            };
            // Its reads are declared above, in the order reports keep.
            let set = pass.set(&self.mip_sets[l - 1]);
            passes.push(pass.draws(Some(work), 1).record(move |pc: &PassContext| {
                fullscreen(pc, &self.mip_pipeline, &[set], |_, _| {})
            }));
        }
        // Every level of the three chains is read; the disk's size (8, 16 or
        // 32 taps) depends on each pixel's radius: the declared count is the most.
        let taps = MAX_TAPS as f64;
        let mut fetches = vec![];
        for (c, texture) in chains
            .iter()
            .zip(["colorChain", "depthChain", "normalChain"])
        {
            fetches.push(fetch(f.res, c[0], texture, Filter::Point, 1.0));
        }
        for (c, texture) in chains
            .iter()
            .zip(["colorChain", "depthChain", "normalChain"])
        {
            // Whole levels (`textureLod` at an integer level): bilinear.
            fetches.push(fetch_at_most(f.res, c[0], texture, Filter::Bilinear, taps));
        }
        let (push, pipeline) = (self.push, &self.pipeline);
        if let Some(tiles) = &self.tiles {
            fetches.push(fetch(
                f.res,
                t.depth_stencil,
                "stencilTex",
                Filter::Point,
                1.0,
            ));
            // Invocations outside the image or the skin fetch nothing.
            for x in &mut fetches {
                x.exact = false;
            }
            let work = ShaderWork {
                shader: COMPUTE_SHADER.into(),
                fetches,
                alu: alu_estimate(COMPUTE_SHADER, &[MAX_TAPS]),
                storage_read_bytes: 4.0 / TILE_INVOCATIONS as f64,
                storage_write_bytes: 8.0,
                shared_bytes: 0.0,
            };
            let push = PoissonPush {
                code: f.stencil,
                ..push
            };
            passes.push(tiles.pass("poisson", f, 0, work, pipeline, &self.set, push));
            passes.extend(tiles.merge_pass(f));
            return passes;
        }
        passes.push(masked_pass(
            f,
            Masked {
                name: "poisson".into(),
                shader: SHADER,
                loop_trips: vec![MAX_TAPS],
                pipeline,
                set: &self.set,
                fetches,
                targets: vec![(self.out, false)],
                stencil: true,
                depth_test: false,
            },
            move |c, cmd| pipeline.push(c, cmd, &push),
        ));
        passes
    }

    fn output(&self) -> ImageId {
        match self.tiles {
            None => self.out,
            // The merge wrote the skin pixels into the diffuse target.
            Some(_) => self.diffuse,
        }
    }

    /// Poisson reads the complete diffuse chain, never a seed: its region only
    /// has to hold the skin pixels it shades.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        Some(0.0)
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        for set in &mut self.mip_sets {
            b.write(set, &self.mip_pipeline)?;
        }
        b.write(&mut self.set, &self.pipeline)?;
        if let Some(t) = &mut self.tiles {
            t.bind(b)?;
        }
        Ok(())
    }

    fn intermediates(&self) -> Vec<ImageId> {
        match self.tiles {
            None => vec![self.out],
            // Only written and read at skin pixels.
            Some(_) => Vec::new(),
        }
    }

    fn details(&self) -> serde_json::Value {
        let path = if self.tiles.is_some() {
            Path::Compute
        } else {
            Path::Fragment
        };
        serde_json::json!({ "params": self.params, "levels": self.levels, "path": path.name() })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.mip_pipeline.destroy(ctx);
        self.pipeline.destroy(ctx);
        self.disk_buffer.destroy(ctx);
        self.tiles.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
