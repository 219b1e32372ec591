//! The ground truth's set-up: the skin sampled within the device's budget, the
//! grid, the chunks' buffers and radiance images, the supersampled surface,
//! the uniforms and the pipelines (`Reference::new`'s steps).

use anyhow::{bail, Result};
use ash::vk;

use super::{
    sample_budget, Chunk, Reference, Surface, IRRADIANCE_SHADER, SURFACE_DEPTH, SURFACE_FORMAT,
    SURFACE_SHADER,
};
use crate::graph::ImageDesc;
use crate::method::profile::Profile;
use crate::method::MethodSetup;
use crate::reference::chunks::{max_slab_candidates, plan_chunks, ChunkLimits, RADIANCE_WIDTH};
use crate::reference::narrow::{radius, supersampling};
use crate::reference::sampling::{build_grid, cutoff_mm, sample_characters_within};
use crate::scene::mesh::Mesh;
use crate::skin::tissue::TISSUE_TOLERANCE;
use crate::skin::wrinkles;
use crate::vk::barrier::AccessKind;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{GraphicsDesc, Pipeline, VertexInput};
use crate::vk::upload::device_buffer;

/// std140 layout of `GatherParams` (reference_gather.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GatherParams {
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
pub(super) struct NarrowParams {
    inv_view: [[f32; 4]; 4],
    view: [f32; 4],
    surface: [u32; 4],
}

impl Reference {
    /// Samples, grid, buffers, pipelines and images, step by step (on an error,
    /// `new`'s guard frees whatever exists).
    // Long because the set-up is one sequence of checks and creations over
    // shared state (the samples, the grid, the device limits).
    pub(super) fn build(&mut self, s: &mut MethodSetup) -> Result<()> {
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
        // Each character's own pose: a moving crowd's head copies
        // (`Scene::character_head`), else the scene's skin for all.
        let own: Vec<Option<Mesh>> = if std::ptr::eq(skin, &s.scene.head) {
            s.characters
                .iter()
                .map(|&c| s.scene.character_head(c))
                .collect()
        } else {
            Vec::new()
        };
        let meshes: Vec<&Mesh> = (0..s.instances.len())
            .map(|i| own.get(i).and_then(Option::as_ref).unwrap_or(&skin.mesh))
            .collect();
        let characters: Vec<(&Mesh, glam::Mat4)> = meshes
            .iter()
            .copied()
            .zip(s.instances.iter().copied())
            .collect();
        let mut surface = sample_characters_within(&characters, mm, self.density, budget)?;
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
        self.plan_surface(s, skin, &meshes)?;
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
        let [narrow, gather, resolve] = self.shaders();
        self.narrow = Pipeline::compute(s.ctx, "reference narrow", narrow)?;
        self.gather = Pipeline::compute(s.ctx, "reference gather", gather)?;
        self.resolve = Pipeline::compute(s.ctx, "reference resolve", resolve)?;
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
        // Each character's wrinkle zones (thesis ch. 8): its expression's.
        let zones: Vec<[f32; 8]> = s
            .characters
            .iter()
            .map(|&c| wrinkles::character_zones(s.scene, c))
            .collect();
        self.wrinkled = zones.iter().flatten().any(|&z| z > 0.0);
        self.zone_rows = zones.iter().map(|&z| wrinkles::zones_std430(z)).collect();
        self.zones = Buffer::with_data(
            s.ctx,
            "reference wrinkle zones",
            bytemuck::cast_slice(&self.zone_rows),
            storage,
        )?;
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
        self.describe_sets(s);
        Ok(())
    }

    /// The supersampled surface: its factor from the nearest skin's scale on
    /// screen, its images, and the skin mesh uploaded for its pass.
    fn plan_surface(
        &mut self,
        s: &mut MethodSetup,
        skin: &crate::scene::mesh::Object,
        // Each instance's skin mesh (its own pose in a moving crowd).
        meshes: &[&Mesh],
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
        // A strength below 1 narrows the profile as much as coming closer
        // by its inverse would widen the pixels' view of it.
        let strength = skin.material.min_scattering_strength();
        let px_per_mm = s.view.scale().px_per_mm(nearest);
        let t = if strength > 0.0 {
            strength.min(1.0)
        } else {
            1.0
        };
        let ss = supersampling(px_per_mm * t);
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
            max_radius: match self.profile {
                Profile::SixGaussian => radius(px_per_mm, ss),
                Profile::Burley => crate::reference::burley::radius(px_per_mm, ss),
            },
            mm_per_subsample_per_depth: crate::view::ViewScale {
                height_px: extent.height,
                ..s.view.scale()
            }
            .mm_per_px_per_depth(),
            ..Default::default()
        };
        // The skin, then the character's other parts: drawn with no area,
        // they hide the skin behind them (an eyeball in its socket) and are
        // no surface to the narrow part (area 0 is "none").
        // One copy of skin and parts per distinct pose: the first's for
        // every instance unless a moving crowd gives each its own, drawn
        // from its copy (`copy_offsets`, in vertices).
        let one = |skin: &Mesh| {
            let mut mesh = skin.clone();
            for part in &s.scene.parts {
                mesh.append(&part.mesh);
            }
            mesh
        };
        let shared = meshes.iter().all(|m| std::ptr::eq(*m, &skin.mesh));
        let mut mesh = one(&skin.mesh);
        let copy_vertices = mesh.vertices.len() as i32;
        self.surf.copy_offsets = vec![0; s.instances.len()];
        if !shared {
            mesh.vertices.clear();
            for (i, m) in meshes.iter().enumerate() {
                self.surf.copy_offsets[i] = i as i32 * copy_vertices;
                mesh.vertices.extend(one(m).vertices);
            }
        }
        self.surf.skin_index_count = skin.mesh.indices.len() as u32;
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
}
