//! The ground truth as a method of the frame (`--method reference`): the diffuse
//! radiant exitance M(x_o) = integral E(x_i) R(|x_i - x_o|) dA over the actual skin
//! surface, through tissue only (`crate::skin::tissue`), by brute force on
//! the GPU. The narrow Gaussians (sigma <= 0.43 mm) are summed over the visible
//! surface rendered at s x the frame's resolution (`crate::reference::narrow`);
//! the wide ones over area-weighted samples of the whole skin surface: their
//! diffuse radiance, lit by the geometry pass's own shading code (a fragment
//! pass over images with one texel per sample, so the shadow test is the same
//! hardware compare), then compute passes that sum, for every skin pixel, all
//! samples within the cut-off, found with a uniform grid. The geometry pass runs
//! with transmittance off for this method: light through thin parts arrives
//! through the integral itself, because samples on the far side of an ear are as
//! close in 3D as they really are.
//!
//! Either profile (`profile=`, `method::profile`): the six Gaussians split by
//! Gaussian (1-3 on the screen, 4-6 from the samples), Burley's by distance
//! (`r < 1 mm` on the screen, the rest from the samples; `crate::reference::burley`
//! says why), each part normalised by its sampled weights. Burley's passes are
//! shaders of their own with the six Gaussians' bindings, so the six Gaussians'
//! truth runs the very code it ran before.
//!
//! The sample set is split into chunks of whole radiance rows so that every
//! binding stays within the device's storage-buffer range and every radiance
//! image within its largest image: the default density works on any conforming
//! device, at any head count its memory holds. The pure parts (sampling, grid,
//! chunk plan, profile split, an f64 CPU gather) are in `crate::reference`.
//!
//! The folder, by concern: this file holds the registry row, the option, the
//! sample budget, the method's state and the frame's order of passes;
//! `setup` samples the skin, builds the grid, uploads the chunks and makes the
//! pipelines and images, `sets` writes the descriptor sets, `passes` records
//! the per-frame passes.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::profile::{self, Profile};
use super::region::ReachScale;
use super::{
    FrameView, MethodBind, MethodEntry, MethodSetup, Needs, OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::{BufferId, GraphSet, ImageId, Pass};
use crate::reference::sampling::SurfaceSample;
use crate::skin::tissue::TISSUE_TOLERANCE;
use crate::vk::context::{Context, DeviceFacts};
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::Pipeline;

mod passes;
mod sets;
mod setup;

const IRRADIANCE_SHADER: &str = "reference_irradiance.frag";
const SURFACE_SHADER: &str = "reference_surface.frag";
const NARROW_SHADER: &str = "reference_narrow.comp";
const GATHER_SHADER: &str = "reference_gather.comp";
const RESOLVE_SHADER: &str = "reference_resolve.comp";
const BURLEY_NARROW_SHADER: &str = "reference_burley_narrow.comp";
const BURLEY_GATHER_SHADER: &str = "reference_burley_gather.comp";
const BURLEY_RESOLVE_SHADER: &str = "reference_burley_resolve.comp";
/// The surface pass's targets: radiance, position + area, normal.
const SURFACE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
const SURFACE_DEPTH: vk::Format = vk::Format::D32_SFLOAT;
/// Workgroup side of the compute passes (their shaders' local size).
const GROUP: u32 = crate::shader_constants::COMPUTE_GROUP_SIDE;
/// The gather's 3x3x3 cell neighbourhood runs as 9 dispatches of one row of 3
/// cells each: llvmpipe cuts shader loops after 65,535 iterations.
const SLABS: i32 = 9;

const OPTIONS: &[OptSpec] = &[
    OptSpec {
        key: "density",
        kind: OptKind::Value,
        default: "32",
        help: "surface samples per mm^2, within (0, 256] (32 is converged: doubling it changes the image by 1e-4 relative RMSE)",
    },
    profile::OPTION,
];

/// Why the ground truth cannot step through a motion (`--time-step`).
const POSES_ONCE: &str = "the ground truth samples each character's surface once, as it is built";

pub static ENTRY: MethodEntry = MethodEntry {
    name: "reference",
    aliases: &["ground-truth"],
    summary: "the ground truth: brute-force integral of the profile over the skin surface",
    options: OPTIONS,
    eval: &[],
    ground_truth: true,
    dolly: &[],
    needs: |_, _| Needs {
        geometry_transmittance: false,
        ..Needs::PLAIN
    },
    check: |o| {
        density(o)?;
        o.parse::<Profile>("profile").map(|_| ())
    },
    build: |s| Ok(Box::new(Reference::new(s)?)),
    no_msaa: Some("the ground truth renders its own single-sample surface and gathers over it, so its frame would alias whatever --msaa says; it is the reference, not a mode to antialias"),
    no_mix: |_| None,
    no_sss: false,
    poses_once: Some(POSES_ONCE),
};

fn density(o: &Opts) -> Result<f32> {
    let d: f32 = o.parse("density")?;
    if !(d > 0.0 && d <= 256.0) {
        bail!("--density must be within (0, 256] samples per mm^2, got {d}");
    }
    Ok(d)
}

/// Bytes the ground truth keeps per surface sample: the sample (64 B),
/// positions (16 B), normals (16 B) and radiance (16 B).
const BYTES_PER_SAMPLE: u64 = 112;

/// The most surface samples the ground truth takes on a device: three quarters
/// of its memory. Not the frame's half: the ground truth is a run of its own
/// beside a few frame-sized images, and the Lee Perry-Smith bust at the default
/// density (1.09e7 samples, 1.2 GB) must fit lavapipe's 2 GiB heap.
pub fn sample_budget(facts: &DeviceFacts) -> u64 {
    facts.device_local_bytes / 4 * 3 / BYTES_PER_SAMPLE
}

/// One chunk: its samples' buffers and radiance image, and its sets.
#[derive(Default)]
struct Chunk {
    first: u32,
    count: u32,
    samples: Buffer,
    positions: Buffer,
    normals: Buffer,
    /// Graph ids of the samples, positions and normals buffers.
    buffer_ids: Vec<BufferId>,
    radiance: ImageId,
    /// (set, first sample of the draw within the chunk, samples) per draw.
    draws: Vec<(GraphSet, u32, u32)>,
    gather_set: GraphSet,
}

impl Destroy for Chunk {
    fn destroy(&mut self, ctx: &Context) {
        self.samples.destroy(ctx);
        self.positions.destroy(ctx);
        self.normals.destroy(ctx);
    }
}

/// The supersampled visible surface (the narrow part's input).
#[derive(Default)]
struct Surface {
    s: u32,
    radiance: ImageId,
    position: ImageId,
    normal: ImageId,
    depth: ImageId,
    /// The skin mesh, uploaded (the frame's copies are the renderer's).
    vertices: Buffer,
    indices: Buffer,
    index_count: u32,
    /// The skin's indices, first in `indices` (the parts' follow).
    skin_index_count: u32,
    /// Each instance's first vertex in `vertices` (0 for all but in a
    /// moving crowd, where each has its own posed copy).
    copy_offsets: Vec<i32>,
    /// The largest narrow window radius (subsamples) any skin pixel uses.
    max_radius: u32,
    mm_per_subsample_per_depth: f32,
}

impl Destroy for Reference {
    fn destroy(&mut self, ctx: &Context) {
        SssMethod::destroy(self, ctx)
    }
}

#[derive(Default)]
pub struct Reference {
    irradiance: Pipeline,
    surface_pipeline: Pipeline,
    narrow: Pipeline,
    gather: Pipeline,
    resolve: Pipeline,
    resolve_set: GraphSet,
    /// Per wide Gaussian: accumulated radiance (rgb) and weight (a).
    accum: [ImageId; 3],
    material_set: vk::DescriptorSet,
    frame_set: GraphSet,
    surf_material: vk::DescriptorSet,
    narrow_set: GraphSet,
    chunks: Vec<Chunk>,
    draw_samples: u32,
    cells: Buffer,
    cells_id: BufferId,
    params: Buffer,
    narrow_params: Buffer,
    out: ImageId,
    max_candidates: u32,
    surf: Surface,
    instances: Vec<glam::Mat4>,
    /// Each instance's wrinkle zone weights (two vec4: the surface pass
    /// pushes them, the irradiance pass reads `zones` by the sample's
    /// character), and whether any zone is weighed (its fetches declared).
    zone_rows: Vec<[[f32; 4]; 2]>,
    zones: Buffer,
    wrinkled: bool,
    pub sample_count: u32,
    /// Cells of the sample grid along x, y, z (reported in `details`).
    pub grid_dims: [u32; 3],
    /// The samples in grid order (for CPU checks).
    pub surface: Vec<SurfaceSample>,
    pub density: f32,
    /// The profile integrated.
    pub profile: Profile,
}

impl Reference {
    /// The narrow, gather and resolve shaders of the profile.
    fn shaders(&self) -> [&'static str; 3] {
        match self.profile {
            Profile::SixGaussian => [NARROW_SHADER, GATHER_SHADER, RESOLVE_SHADER],
            Profile::Burley => [
                BURLEY_NARROW_SHADER,
                BURLEY_GATHER_SHADER,
                BURLEY_RESOLVE_SHADER,
            ],
        }
    }

    /// Subsamples per pixel per axis of the narrow part's surface.
    pub fn supersampling(&self) -> u32 {
        self.surf.s
    }

    fn new(s: &mut MethodSetup) -> Result<Self> {
        let r = Reference {
            density: density(&s.options)?,
            profile: s.options.parse("profile")?,
            instances: s.instances.to_vec(),
            ..Default::default()
        };
        // Filled in by `build`: on an error, the guard frees what exists.
        let mut r = Guard::new(s.ctx, r);
        r.build(s)?;
        Ok(r.keep())
    }
}

impl SssMethod for Reference {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let mut passes = vec![
            self.irradiance_pass(f),
            self.surface_pass(f),
            self.narrow_pass(f),
            self.clear_pass(f),
        ];
        for ci in 0..self.chunks.len() {
            for k in 0..SLABS {
                passes.push(self.gather_pass(f, ci, k));
            }
        }
        passes.push(self.resolve_pass(f));
        passes
    }

    fn output(&self) -> ImageId {
        self.out
    }

    /// The reference gathers in compute over the whole screen.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        None
    }

    /// Every descriptor set of the method (`sets`).
    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        self.write_sets(b)
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "density_per_mm2": self.density,
            "samples": self.sample_count,
            "chunks": self.chunks.len(),
            "grid_dims": self.grid_dims,
            "supersampling": self.surf.s,
            "narrow_window_radius": self.surf.max_radius,
            "tissue_tolerance": TISSUE_TOLERANCE,
            "profile": self.profile.name(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        for p in [
            &mut self.irradiance,
            &mut self.surface_pipeline,
            &mut self.narrow,
            &mut self.gather,
            &mut self.resolve,
        ] {
            p.destroy(ctx);
        }
        for c in &mut self.chunks {
            c.destroy(ctx);
        }
        for b in [
            &mut self.cells,
            &mut self.params,
            &mut self.narrow_params,
            &mut self.zones,
            &mut self.surf.vertices,
            &mut self.surf.indices,
        ] {
            b.destroy(ctx);
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
