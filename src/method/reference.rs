//! The ground truth as a method of the frame (`--method reference`): the diffuse
//! radiant exitance M(x_o) = integral E(x_i) R(|x_i - x_o|) dA over the actual skin
//! surface, through tissue only (`crate::reference::tissue`), by brute force on
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
//! The sample set is split into chunks of whole radiance rows so that every
//! binding stays within the device's storage-buffer range and every radiance
//! image within its largest image: the default density works on any conforming
//! device, at any head count its memory holds. The pure parts (sampling, grid,
//! chunk plan, profile split, an f64 CPU gather) are in `crate::reference`.

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;

use super::region::ReachScale;
use super::screen::fetch;
use super::{
    FrameView, MethodBind, MethodEntry, MethodSetup, Needs, OptKind, OptSpec, Opts, SssMethod,
};
use crate::graph::work::{Fetch, Filter, Format, PassRole, ShaderWork, Work};
use crate::graph::{
    BufferId, ColorTarget, DepthStencil, ImageDesc, ImageId, Load, Pass, PassContext,
};
use crate::reference::chunks::{max_slab_candidates, plan_chunks, ChunkLimits, RADIANCE_WIDTH};
use crate::reference::narrow::{radius, supersampling};
use crate::reference::sampling::{build_grid, cutoff_mm, sample_surface_within, SurfaceSample};
use crate::reference::tissue::TISSUE_TOLERANCE;
use crate::shader_constants::{NARROW_GAUSSIANS as NARROW, PCF_TRIPS, WIDE_GAUSSIANS};
use crate::vk::barrier::AccessKind;
use crate::vk::context::{Context, DeviceFacts};
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline, VertexInput};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload::device_buffer;

const IRRADIANCE_SHADER: &str = "reference_irradiance.frag";
const SURFACE_SHADER: &str = "reference_surface.frag";
const NARROW_SHADER: &str = "reference_narrow.comp";
const GATHER_SHADER: &str = "reference_gather.comp";
const RESOLVE_SHADER: &str = "reference_resolve.comp";
/// The surface pass's targets: radiance, position + area, normal.
const SURFACE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
const SURFACE_DEPTH: vk::Format = vk::Format::D32_SFLOAT;
/// Workgroup side of the gather (reference_gather.comp's local size).
const GROUP: u32 = 8;
/// The gather's 3x3x3 cell neighbourhood runs as 9 dispatches of one row of 3
/// cells each: llvmpipe cuts shader loops after 65,535 iterations.
const SLABS: i32 = 9;

const OPTIONS: &[OptSpec] = &[OptSpec {
    key: "density",
    kind: OptKind::Value,
    default: "32",
    help: "surface samples per mm^2, within (0, 256] (32 is converged: doubling it changes the image by 1e-4 relative RMSE)",
}];

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
    check: |o| density(o).map(|_| ()),
    build: |s| Ok(Box::new(Reference::new(s)?)),
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

/// std140 layout of `GatherParams` (reference_gather.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherParams {
    inv_view: [[f32; 4]; 4],
    grid_origin: [f32; 4],
    grid_dims: [u32; 4],
    view: [f32; 4],
    /// x: tissue tolerance, y: subsamples per pixel per axis.
    tissue: [f32; 4],
}

/// std140 layout of `NarrowParams` (reference_narrow.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct NarrowParams {
    inv_view: [[f32; 4]; 4],
    view: [f32; 4],
    surface: [u32; 4],
}

/// Push constants of the surface pass (geometry.vert's model, then the frag's scale).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SurfacePush {
    model: [[f32; 4]; 4],
    mm_per_subsample_per_depth: f32,
}

/// Push constants of the gather: the slab, and the chunk's range of samples.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherPush {
    dy: i32,
    dz: i32,
    first: u32,
    count: u32,
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
    draws: Vec<(vk::DescriptorSet, u32, u32)>,
    gather_set: vk::DescriptorSet,
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
    resolve_set: vk::DescriptorSet,
    /// Per wide Gaussian: accumulated radiance (rgb) and weight (a).
    accum: [ImageId; 3],
    material_set: vk::DescriptorSet,
    frame_set: vk::DescriptorSet,
    surf_material: vk::DescriptorSet,
    narrow_set: vk::DescriptorSet,
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
    pub sample_count: u32,
    /// Cells of the sample grid along x, y, z (reported in `details`).
    pub grid_dims: [u32; 3],
    /// The samples in grid order (for CPU checks).
    pub surface: Vec<SurfaceSample>,
    pub density: f32,
}

impl Reference {
    /// Subsamples per pixel per axis of the narrow part's surface.
    pub fn supersampling(&self) -> u32 {
        self.surf.s
    }

    fn new(s: &mut MethodSetup) -> Result<Self> {
        let r = Reference {
            density: density(&s.options)?,
            instances: s.instances.to_vec(),
            ..Default::default()
        };
        // Filled in by `build`: on an error, the guard frees what exists.
        let mut r = Guard::new(s.ctx, r);
        r.build(s)?;
        Ok(r.keep())
    }

    /// Samples, grid, buffers, pipelines and images, step by step (on an error,
    /// `new`'s guard frees whatever exists).
    // Long because the set-up is one sequence of checks and creations over
    // shared state (the samples, the grid, the device limits).
    fn build(&mut self, s: &mut MethodSetup) -> Result<()> {
        let mm = s.view.mm_per_unit;
        let skin = [&s.scene.head]
            .into_iter()
            .chain(s.scene.backdrop.iter())
            .find(|o| o.material.skin);
        let Some(skin) = skin else {
            bail!("the reference found no skin surface to sample");
        };
        // Checked before any sample exists (a far outlier vertex would
        // otherwise ask for billions).
        let f = &s.ctx.facts;
        let budget = sample_budget(f);
        let mut surface = sample_surface_within(&skin.mesh, s.instances, mm, self.density, budget)?;
        if surface.is_empty() {
            bail!("the reference found no skin surface to sample");
        }
        let grid = build_grid(&mut surface, cutoff_mm() / mm);
        let count = surface.len() as u32;
        let plan = plan_chunks(
            count,
            ChunkLimits {
                storage_range: f.max_storage_buffer_range as u64,
                max_image_dimension: f.max_image_dimension_2d,
            },
        )?;
        let cells_bytes = grid.cell_start.len() as u64 * 4;
        if cells_bytes > f.max_storage_buffer_range as u64 {
            bail!("the reference grid has {} cells, more than this device's storage-buffer range holds", grid.cell_start.len());
        }
        self.plan_surface(s, skin)?;
        self.irradiance = Pipeline::graphics(
            s.ctx,
            &GraphicsDesc::fullscreen("reference irradiance", IRRADIANCE_SHADER, SURFACE_FORMAT),
        )?;
        self.surface_pipeline = Pipeline::graphics(
            s.ctx,
            &GraphicsDesc {
                name: "reference surface".into(),
                vert: "geometry.vert",
                frag: Some(SURFACE_SHADER),
                color_formats: vec![SURFACE_FORMAT; 3],
                depth_format: Some(SURFACE_DEPTH),
                stencil_format: None,
                vertex_input: VertexInput::Mesh,
                cull: vk::CullModeFlags::BACK,
                depth_test: true,
                depth_write: true,
                depth_compare: vk::CompareOp::LESS,
                stencil: None,
                depth_bias: None,
                blend: crate::vk::pipeline::Blend::None,
            },
        )?;
        self.narrow = Pipeline::compute(s.ctx, "reference narrow", NARROW_SHADER)?;
        self.gather = Pipeline::compute(s.ctx, "reference gather", GATHER_SHADER)?;
        self.resolve = Pipeline::compute(s.ctx, "reference resolve", RESOLVE_SHADER)?;
        let inv_view = s.view.camera.view().inverse().to_cols_array_2d();
        let view = [s.view.tan_half_fovy(), s.view.aspect(), mm, cutoff_mm()];
        let p = GatherParams {
            inv_view,
            grid_origin: grid.origin.extend(grid.cell).to_array(),
            grid_dims: [grid.dims[0], grid.dims[1], grid.dims[2], RADIANCE_WIDTH],
            view,
            tissue: [TISSUE_TOLERANCE, self.surf.s as f32, 0.0, 0.0],
        };
        let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
        self.params = Buffer::with_data(
            s.ctx,
            "reference gather params",
            bytemuck::bytes_of(&p),
            uniform,
        )?;
        let np = NarrowParams {
            inv_view,
            view: [view[0], view[1], mm, TISSUE_TOLERANCE],
            surface: [self.surf.s, crate::reference::narrow::MAX_RADIUS, 0, 0],
        };
        self.narrow_params = Buffer::with_data(
            s.ctx,
            "reference narrow params",
            bytemuck::bytes_of(&np),
            uniform,
        )?;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        self.cells = device_buffer(
            s.ctx,
            "reference grid cells",
            bytemuck::cast_slice(&grid.cell_start),
            storage,
            AccessKind::ComputeStorageRead,
        )?;
        let cells_id = s.res.add_buffer("reference grid cells", self.cells.raw);
        s.res
            .set_buffer_uploaded(cells_id, AccessKind::ComputeStorageRead);
        self.cells_id = cells_id;
        let one = plan.chunks.len() == 1;
        for (k, &(first, n)) in plan.chunks.iter().enumerate() {
            let name = |what: &str| {
                if one {
                    format!("reference {what}")
                } else {
                    format!("reference {what} {}", k + 1)
                }
            };
            let range = &surface[first as usize..(first + n) as usize];
            let c = Chunk {
                first,
                count: n,
                ..Default::default()
            };
            // Until the method holds it, an error frees the chunk's buffers.
            let mut c = Guard::new(s.ctx, c);
            let pos: Vec<[f32; 4]> = range.iter().map(|s| s.pos_area).collect();
            let nrm: Vec<[f32; 4]> = range.iter().map(|s| s.normal).collect();
            let uploads: [(&str, &[u8], AccessKind); 3] = [
                (
                    "samples",
                    bytemuck::cast_slice(range),
                    AccessKind::FragmentStorageRead,
                ),
                (
                    "positions",
                    bytemuck::cast_slice(&pos),
                    AccessKind::ComputeStorageRead,
                ),
                (
                    "normals",
                    bytemuck::cast_slice(&nrm),
                    AccessKind::ComputeStorageRead,
                ),
            ];
            for (i, (what, bytes, first_use)) in uploads.into_iter().enumerate() {
                let b = device_buffer(s.ctx, &name(what), bytes, storage, first_use)?;
                let id = s.res.add_buffer(&name(what), b.raw);
                s.res.set_buffer_uploaded(id, first_use);
                c.buffer_ids.push(id);
                match i {
                    0 => c.samples = b,
                    1 => c.positions = b,
                    _ => c.normals = b,
                }
            }
            c.radiance = s.res.declare(ImageDesc::new(
                &name("radiance"),
                vk::Extent2D {
                    width: RADIANCE_WIDTH,
                    height: n.div_ceil(RADIANCE_WIDTH),
                },
                vk::Format::R32G32B32A32_SFLOAT,
            ));
            self.chunks.push(c.keep());
        }
        self.out = s.res.declare(ImageDesc::new(
            "reference",
            s.view.extent,
            vk::Format::R32G32B32A32_SFLOAT,
        ));
        self.accum = [4, 5, 6].map(|g| {
            s.res.declare(ImageDesc::new(
                &format!("reference gaussian {g}"),
                s.view.extent,
                vk::Format::R32G32B32A32_SFLOAT,
            ))
        });
        self.draw_samples = plan.draw_samples;
        self.max_candidates = max_slab_candidates(&grid);
        self.sample_count = count;
        self.grid_dims = grid.dims;
        self.surface = surface;
        Ok(())
    }

    /// The supersampled surface: its factor from the nearest skin's scale on
    /// screen, its images, and the skin mesh uploaded for its pass.
    fn plan_surface(
        &mut self,
        s: &mut MethodSetup,
        skin: &crate::scene::mesh::Object,
    ) -> Result<()> {
        let eye = s.view.camera.eye;
        let bounds = skin.mesh.bounds();
        let nearest = s
            .instances
            .iter()
            .map(|m| {
                let b = bounds.transformed(m);
                (eye.clamp(b.min, b.max) - eye).length()
            })
            .fold(f32::INFINITY, f32::min)
            .max(s.view.camera.near);
        let px_per_mm = s.view.scale().px_per_mm(nearest);
        let ss = supersampling(px_per_mm);
        let extent = vk::Extent2D {
            width: s.view.extent.width * ss,
            height: s.view.extent.height * ss,
        };
        if extent.width.max(extent.height) > s.ctx.facts.max_image_dimension_2d {
            bail!(
                "the reference's {ss}x supersampled surface ({}x{}) exceeds this device's largest image",
                extent.width,
                extent.height
            );
        }
        let desc = |what: &str, format| {
            ImageDesc::new(&format!("reference surface {what}"), extent, format)
        };
        self.surf = Surface {
            s: ss,
            radiance: s.res.declare(desc("radiance", SURFACE_FORMAT)),
            position: s.res.declare(desc("position", SURFACE_FORMAT)),
            normal: s.res.declare(desc("normal", SURFACE_FORMAT)),
            depth: s.res.declare(desc("depth", SURFACE_DEPTH)),
            max_radius: radius(px_per_mm, ss),
            mm_per_subsample_per_depth: crate::view::ViewScale {
                height_px: extent.height,
                ..s.view.scale()
            }
            .mm_per_px_per_depth(),
            ..Default::default()
        };
        let mesh = &skin.mesh;
        self.surf.vertices = device_buffer(
            s.ctx,
            "reference surface vertices",
            bytemuck::cast_slice(&mesh.vertices),
            vk::BufferUsageFlags::VERTEX_BUFFER,
            AccessKind::VertexInputRead,
        )?;
        self.surf.indices = device_buffer(
            s.ctx,
            "reference surface indices",
            bytemuck::cast_slice(&mesh.indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
            AccessKind::VertexInputRead,
        )?;
        self.surf.index_count = mesh.indices.len() as u32;
        Ok(())
    }

    /// The radiance pass: every chunk's samples lit, one draw per range.
    fn irradiance_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let lit = "reference_irradiance.frag";
        let shader = ShaderWork {
            shader: lit.into(),
            // The texels past the last sample of a chunk's last row return
            // before shading: every count is a bound.
            fetches: vec![
                Fetch {
                    exact: false,
                    ..fetch(
                        f.res,
                        f.targets.shadow,
                        "shadowMap",
                        Filter::DepthCompare,
                        9.0,
                    )
                },
                // Material textures are not frame images: RGBA8 bilinear.
                material_fetch("normalTex"),
                material_fetch("albedoTex"),
            ],
            alu: alu_estimate(lit, &PCF_TRIPS),
            storage_read_bytes: std::mem::size_of::<SurfaceSample>() as f64,
            storage_write_bytes: 0.0,
        };
        let draws: u64 = self
            .chunks
            .iter()
            .map(|c| c.count.div_ceil(self.draw_samples) as u64)
            .sum();
        // Each chunk's radiance target is rendered alone (its rows stacked in
        // the work's area), every texel of it overwritten.
        let mut pass = Pass::new("reference irradiance", PassRole::Sss)
            .sampled(f.targets.shadow)
            .each_target_alone();
        for c in &self.chunks {
            pass = pass
                .buffer(c.buffer_ids[0], AccessKind::FragmentStorageRead)
                .color(ColorTarget::new(c.radiance, Load::DontCare));
        }
        pass.draws(Some(shader), draws)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let c = &self.chunks[pc.target];
                let p = &self.irradiance;
                p.bind(ctx, cmd, &[]);
                p.bind_sets(ctx, cmd, 1, &[self.material_set]);
                for &(set, first, n) in &c.draws {
                    let first_row = first / RADIANCE_WIDTH;
                    let scissor = vk::Rect2D {
                        offset: vk::Offset2D {
                            x: 0,
                            y: first_row as i32,
                        },
                        extent: vk::Extent2D {
                            width: RADIANCE_WIDTH,
                            height: n.div_ceil(RADIANCE_WIDTH),
                        },
                    };
                    p.bind_sets(ctx, cmd, 0, &[set]);
                    unsafe { ctx.device.cmd_set_scissor(cmd, 0, &[scissor]) };
                    p.push(ctx, cmd, &[n, RADIANCE_WIDTH, first_row]);
                    unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
                }
            })
    }
}

impl Reference {
    /// The visible skin at s x the frame's resolution: radiance, position and
    /// area, normal (the narrow part's input).
    fn surface_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let sf = &self.surf;
        let shadow = fetch(
            f.res,
            f.targets.shadow,
            "shadowMap",
            Filter::DepthCompare,
            9.0,
        );
        let albedo = Fetch {
            exact: true,
            ..material_fetch("albedoTex")
        };
        let work = ShaderWork {
            shader: SURFACE_SHADER.into(),
            fetches: vec![shadow, material_fetch("normalTex"), albedo],
            alu: alu_estimate(SURFACE_SHADER, &PCF_TRIPS),
            ..Default::default()
        };
        // The three subsample targets and the depth start cleared.
        let clear = |t| ColorTarget::new(t, Load::Clear([0.0; 4]));
        Pass::new("reference surface", PassRole::Sss)
            .sampled(f.targets.shadow)
            .color(clear(sf.radiance))
            .color(clear(sf.position))
            .color(clear(sf.normal))
            .depth_stencil(DepthStencil::cleared(sf.depth, 1.0))
            .draws(
                Some(work),
                sf.index_count as u64 / 3 * self.instances.len() as u64,
            )
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.surface_pipeline;
                p.bind(ctx, cmd, &[self.frame_set, self.surf_material]);
                unsafe {
                    ctx.device
                        .cmd_bind_vertex_buffers(cmd, 0, &[self.surf.vertices.raw], &[0]);
                    ctx.device.cmd_bind_index_buffer(
                        cmd,
                        self.surf.indices.raw,
                        0,
                        vk::IndexType::UINT32,
                    );
                }
                for m in &self.instances {
                    p.push(
                        ctx,
                        cmd,
                        &SurfacePush {
                            model: m.to_cols_array_2d(),
                            mm_per_subsample_per_depth: self.surf.mm_per_subsample_per_depth,
                        },
                    );
                    unsafe {
                        ctx.device
                            .cmd_draw_indexed(cmd, self.surf.index_count, 1, 0, 0, 0)
                    };
                }
            })
    }

    /// Zeroes the wide Gaussians' accumulators before the gather adds to them.
    fn clear_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let accum = self.accum;
        let e = f.extent;
        let mut pass = Pass::new("reference clear", PassRole::Sss).work(Work::Clear {
            texels: 3 * e.width as u64 * e.height as u64,
            bytes_per_texel: 16,
        });
        for a in accum {
            pass = pass.image(a, AccessKind::ClearWrite);
        }
        pass.record(move |pc: &PassContext| {
            let range = vk::ImageSubresourceRange::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .level_count(1)
                .layer_count(1);
            for a in accum {
                unsafe {
                    pc.ctx.device.cmd_clear_color_image(
                        pc.cmd,
                        pc.image(a).raw,
                        pc.layout(a),
                        &vk::ClearColorValue::default(),
                        &[range],
                    )
                };
            }
        })
    }

    /// The wide Gaussians, each over its weight, added to the narrow part.
    fn resolve_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let t = f.targets;
        let extent = f.extent;
        let work = ShaderWork {
            shader: RESOLVE_SHADER.into(),
            fetches: vec![fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0)],
            alu: alu_estimate(RESOLVE_SHADER, &[WIDE_GAUSSIANS as u32]),
            storage_read_bytes: 64.0,
            storage_write_bytes: 16.0,
        };
        let set = self.resolve_set;
        let mut pass = Pass::new("reference resolve", PassRole::Sss)
            .image(t.diffuse, AccessKind::ComputeSampledRead)
            .image(self.out, AccessKind::ComputeStorageReadWrite);
        for a in self.accum {
            pass = pass.image(a, AccessKind::ComputeStorageRead);
        }
        pass.dispatch(work, screen_groups(extent), GROUP * GROUP)
            .record(move |pc: &PassContext| self.resolve.bind(pc.ctx, pc.cmd, &[set]))
    }

    /// The narrow part, written into the output for every pixel.
    fn narrow_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let t = f.targets;
        let sf = &self.surf;
        let extent = f.extent;
        let side = (2 * sf.max_radius + 1) as f64;
        let window = side * side;
        let bound = |image, texture: &str, count| Fetch {
            exact: false,
            ..fetch(f.res, image, texture, Filter::Point, count)
        };
        let work = ShaderWork {
            shader: NARROW_SHADER.into(),
            fetches: vec![
                fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0),
                bound(t.linear_depth, "depthTex", 1.0),
                bound(sf.normal, "surfNormal", 1.0 + window),
                bound(sf.position, "surfPosition", window),
                bound(sf.radiance, "surfRadiance", window + 1.0),
            ],
            alu: alu_estimate(
                NARROW_SHADER,
                &[side as u32, side as u32, NARROW as u32, NARROW as u32],
            ),
            storage_write_bytes: 16.0,
            ..Default::default()
        };
        let set = self.narrow_set;
        Pass::new("reference narrow", PassRole::Sss)
            .image(t.diffuse, AccessKind::ComputeSampledRead)
            .image(t.linear_depth, AccessKind::ComputeSampledRead)
            .image(sf.radiance, AccessKind::ComputeSampledRead)
            .image(sf.position, AccessKind::ComputeSampledRead)
            .image(sf.normal, AccessKind::ComputeSampledRead)
            .image(self.out, AccessKind::ComputeStorageWrite)
            .dispatch(work, screen_groups(extent), GROUP * GROUP)
            .record(move |pc: &PassContext| self.narrow.bind(pc.ctx, pc.cmd, &[set]))
    }
}

/// The workgroups of a dispatch over every pixel of `extent`.
fn screen_groups(extent: vk::Extent2D) -> [u32; 3] {
    [
        extent.width.div_ceil(GROUP),
        extent.height.div_ceil(GROUP),
        1,
    ]
}

/// At most one fetch of a skin material's RGBA8 texture (bilinear, level 0).
fn material_fetch(texture: &str) -> Fetch {
    Fetch {
        texture: texture.into(),
        format: Format::Rgba8Unorm,
        filter: Filter::Bilinear,
        count: 1.0,
        exact: false,
        coherent: true,
    }
}

impl SssMethod for Reference {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let t = f.targets;
        let mut passes = vec![
            self.irradiance_pass(f),
            self.surface_pass(f),
            self.narrow_pass(f),
            self.clear_pass(f),
        ];
        let groups = screen_groups(f.extent);
        let one = self.chunks.len() == 1;
        for (ci, c) in self.chunks.iter().enumerate() {
            for k in 0..SLABS {
                // Every slab adds to the narrow part.
                let out_access = AccessKind::ComputeStorageReadWrite;
                let name = if one {
                    format!("reference gather {}/9", k + 1)
                } else {
                    format!(
                        "reference gather chunk {}/{} {}/9",
                        ci + 1,
                        self.chunks.len(),
                        k + 1
                    )
                };
                let candidates = self.max_candidates as f64;
                let work = ShaderWork {
                    shader: GATHER_SHADER.into(),
                    fetches: vec![
                        fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0),
                        Fetch {
                            exact: false,
                            ..fetch(f.res, t.linear_depth, "depthTex", Filter::Point, 1.0)
                        },
                        Fetch {
                            exact: false,
                            ..fetch(f.res, self.surf.normal, "surfNormal", Filter::Point, 1.0)
                        },
                        Fetch {
                            exact: false,
                            ..fetch(f.res, c.radiance, "radianceTex", Filter::Point, candidates)
                        },
                    ],
                    alu: alu_estimate(
                        GATHER_SHADER,
                        &[3, self.max_candidates.div_ceil(3), WIDE_GAUSSIANS as u32],
                    ),
                    // Positions and normals of the candidates, cell ranges, the output.
                    storage_read_bytes: 32.0 * candidates + 16.0 + 8.0,
                    storage_write_bytes: 48.0,
                };
                let push = GatherPush {
                    dy: k % 3 - 1,
                    dz: k / 3 - 1,
                    first: c.first,
                    count: c.count,
                };
                let set = c.gather_set;
                passes.push(
                    Pass::new(name, PassRole::Sss)
                        .image(t.diffuse, AccessKind::ComputeSampledRead)
                        .image(t.linear_depth, AccessKind::ComputeSampledRead)
                        .image(c.radiance, AccessKind::ComputeSampledRead)
                        .image(self.surf.normal, AccessKind::ComputeSampledRead)
                        .image(self.accum[0], out_access)
                        .image(self.accum[1], out_access)
                        .image(self.accum[2], out_access)
                        .buffer(c.buffer_ids[1], AccessKind::ComputeStorageRead)
                        .buffer(c.buffer_ids[2], AccessKind::ComputeStorageRead)
                        .buffer(self.cells_id, AccessKind::ComputeStorageRead)
                        .dispatch(work, groups, GROUP * GROUP)
                        .record(move |pc: &PassContext| {
                            self.gather.bind(pc.ctx, pc.cmd, &[set]);
                            self.gather.push(pc.ctx, pc.cmd, &push);
                        }),
                );
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

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
        self.material_set = b
            .pool
            .write_set(b.ctx, &self.irradiance, 1, &b.skin_material_binds)?;
        let t = b.targets;
        self.frame_set = b
            .pool
            .write_set(b.ctx, &self.surface_pipeline, 0, &b.frame_binds)?;
        let surface_material =
            b.pool
                .write_set(b.ctx, &self.surface_pipeline, 1, &b.skin_material_binds)?;
        self.surf_material = surface_material;
        let sz = |n: usize| n as u64;
        self.narrow_set = b.pool.write_set(
            b.ctx,
            &self.narrow,
            0,
            &[
                ("diffuseTex", Bind::Texture(b.res.view(t.diffuse))),
                ("depthTex", Bind::Texture(b.res.view(t.linear_depth))),
                ("outImage", Bind::Texture(b.res.view(self.out))),
                (
                    "surfRadiance",
                    Bind::Texture(b.res.view(self.surf.radiance)),
                ),
                (
                    "surfPosition",
                    Bind::Texture(b.res.view(self.surf.position)),
                ),
                ("surfNormal", Bind::Texture(b.res.view(self.surf.normal))),
                (
                    "params",
                    Bind::Uniform {
                        buffer: self.narrow_params.raw,
                        size: sz(std::mem::size_of::<NarrowParams>()),
                    },
                ),
            ],
        )?;
        self.resolve_set = b.pool.write_set(
            b.ctx,
            &self.resolve,
            0,
            &[
                ("diffuseTex", Bind::Texture(b.res.view(t.diffuse))),
                ("outImage", Bind::Texture(b.res.view(self.out))),
                ("accum4", Bind::Texture(b.res.view(self.accum[0]))),
                ("accum5", Bind::Texture(b.res.view(self.accum[1]))),
                ("accum6", Bind::Texture(b.res.view(self.accum[2]))),
            ],
        )?;
        for c in &mut self.chunks {
            c.draws.clear();
            let mut first = 0;
            while first < c.count {
                let n = (c.count - first).min(self.draw_samples);
                let mut binds = b.frame_binds.clone();
                binds.push((
                    "Samples",
                    Bind::Range {
                        buffer: c.samples.raw,
                        offset: first as u64 * sample_bytes,
                        size: n as u64 * sample_bytes,
                    },
                ));
                c.draws.push((
                    b.pool.write_set(b.ctx, &self.irradiance, 0, &binds)?,
                    first,
                    n,
                ));
                first += n;
            }
            c.gather_set = b.pool.write_set(
                b.ctx,
                &self.gather,
                0,
                &[
                    ("diffuseTex", Bind::Texture(b.res.view(t.diffuse))),
                    ("depthTex", Bind::Texture(b.res.view(t.linear_depth))),
                    ("accum4", Bind::Texture(b.res.view(self.accum[0]))),
                    ("accum5", Bind::Texture(b.res.view(self.accum[1]))),
                    ("accum6", Bind::Texture(b.res.view(self.accum[2]))),
                    (
                        "Positions",
                        Bind::Uniform {
                            buffer: c.positions.raw,
                            size: c.positions.size,
                        },
                    ),
                    ("radianceTex", Bind::Texture(b.res.view(c.radiance))),
                    (
                        "Normals",
                        Bind::Uniform {
                            buffer: c.normals.raw,
                            size: c.normals.size,
                        },
                    ),
                    ("surfNormal", Bind::Texture(b.res.view(self.surf.normal))),
                    (
                        "Cells",
                        Bind::Uniform {
                            buffer: self.cells.raw,
                            size: self.cells.size,
                        },
                    ),
                    (
                        "params",
                        Bind::Uniform {
                            buffer: self.params.raw,
                            size: std::mem::size_of::<GatherParams>() as u64,
                        },
                    ),
                ],
            )?;
        }
        Ok(())
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
