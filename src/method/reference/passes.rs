//! The ground truth's per-frame passes: the samples' radiance, the
//! supersampled surface, the narrow part, the accumulators' clear, the wide
//! Gaussians' gather (one pass per chunk and slab) and the resolve.

use ash::vk;

use super::{Reference, GROUP, SURFACE_SHADER};
use crate::graph::work::{Fetch, Filter, PassRole, ShaderWork, Work};
use crate::graph::{ColorTarget, DepthStencil, Load, Pass, PassContext, SetRef};
use crate::method::profile::Profile;
use crate::method::screen::fetch;
use crate::method::FrameView;
use crate::reference::chunks::RADIANCE_WIDTH;
use crate::reference::sampling::SurfaceSample;
use crate::shader_constants::{NARROW_GAUSSIANS as NARROW, PCF_TRIPS, WIDE_GAUSSIANS};
use crate::vk::shader_stats::alu_estimate;

/// Push constants of the surface pass (geometry.vert's model, then the
/// frag's scale and the character's wrinkle zones, std430: the zones at 80).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SurfacePush {
    model: [[f32; 4]; 4],
    mm_per_subsample_per_depth: f32,
    pad: [f32; 3],
    zones: [[f32; 4]; 2],
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

impl Reference {
    /// The radiance pass: every chunk's samples lit, one draw per range.
    pub(super) fn irradiance_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
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
                Fetch::material("normalTex", false),
                Fetch::material("albedoTex", false),
            ]
            .into_iter()
            .chain(self.wrinkle_fetches())
            .collect(),
            alu: alu_estimate(lit, &PCF_TRIPS),
            storage_read_bytes: std::mem::size_of::<SurfaceSample>() as f64,
            storage_write_bytes: 0.0,
            shared_bytes: 0.0,
        };
        let draws: u64 = self
            .chunks
            .iter()
            .map(|c| c.count.div_ceil(self.draw_samples) as u64)
            .sum();
        // Each chunk's radiance target is rendered alone (its rows stacked in
        // the work's area), every texel of it overwritten.
        let mut pass = Pass::new("reference irradiance", PassRole::Sss);
        // Each draw's set: the frame's (the shadow map) and its range of
        // the chunk's samples.
        let sets: Vec<Vec<SetRef>> = self
            .chunks
            .iter()
            .map(|c| c.draws.iter().map(|(set, ..)| pass.set(set)).collect())
            .collect();
        pass = pass.each_target_alone();
        for c in &self.chunks {
            pass = pass.color(ColorTarget::new(c.radiance, Load::DontCare));
        }
        pass.draws(Some(shader), draws)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let c = &self.chunks[pc.target];
                let p = &self.irradiance;
                pc.bind(p, &[]);
                p.bind_sets(ctx, cmd, 1, &[self.material_set]);
                for (&set, &(_, first, n)) in sets[pc.target].iter().zip(&c.draws) {
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
                    pc.bind_sets(p, 0, &[set]);
                    unsafe { ctx.device.cmd_set_scissor(cmd, 0, &[scissor]) };
                    p.push(ctx, cmd, &[n, RADIANCE_WIDTH, first_row]);
                    unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
                }
            })
    }

    /// The visible skin at s x the frame's resolution: radiance, position and
    /// area, normal (the narrow part's input).
    pub(super) fn surface_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let sf = &self.surf;
        let shadow = fetch(
            f.res,
            f.targets.shadow,
            "shadowMap",
            Filter::DepthCompare,
            9.0,
        );
        let albedo = Fetch::material("albedoTex", true);
        let work = ShaderWork {
            shader: SURFACE_SHADER.into(),
            fetches: [shadow, Fetch::material("normalTex", false), albedo]
                .into_iter()
                .chain(self.wrinkle_fetches())
                .collect(),
            alu: alu_estimate(SURFACE_SHADER, &PCF_TRIPS),
            ..Default::default()
        };
        // The three subsample targets and the depth start cleared.
        let clear = |t| ColorTarget::new(t, Load::Clear([0.0; 4]));
        let mut pass = Pass::new("reference surface", PassRole::Sss);
        // The frame's set samples the shadow map.
        let frame = pass.set(&self.frame_set);
        pass.color(clear(sf.radiance))
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
                pc.bind(p, &[frame]);
                p.bind_sets(ctx, cmd, 1, &[self.surf_material]);
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
                let (skin, all) = (self.surf.skin_index_count, self.surf.index_count);
                let characters = self.instances.iter().zip(&self.surf.copy_offsets);
                for ((m, &offset), &zones) in characters.zip(&self.zone_rows) {
                    // The skin with its subsamples' area and wrinkles; the
                    // parts with neither: occluders only.
                    for (first, count, scale, zones) in [
                        (0, skin, self.surf.mm_per_subsample_per_depth, zones),
                        (skin, all - skin, 0.0, [[0.0; 4]; 2]),
                    ] {
                        if count == 0 {
                            continue;
                        }
                        p.push(
                            ctx,
                            cmd,
                            &SurfacePush {
                                model: m.to_cols_array_2d(),
                                mm_per_subsample_per_depth: scale,
                                pad: [0.0; 3],
                                zones,
                            },
                        );
                        unsafe { ctx.device.cmd_draw_indexed(cmd, count, 1, first, offset, 0) };
                    }
                }
            })
    }

    /// The wrinkle maps' fetches where a character's expression weighs a
    /// zone (`Fetch::wrinkles`), else none.
    fn wrinkle_fetches(&self) -> Vec<Fetch> {
        if self.wrinkled {
            Fetch::wrinkles()
        } else {
            Vec::new()
        }
    }

    /// Zeroes the wide Gaussians' accumulators before the gather adds to them.
    pub(super) fn clear_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let accum = self.accum;
        let e = f.extent;
        let mut pass = Pass::new("reference clear", PassRole::Sss);
        let accum = accum.map(|a| pass.clear_dst(a));
        pass.work(Work::Clear {
            texels: 3 * e.width as u64 * e.height as u64,
            bytes_per_texel: 16,
        })
        .record(move |pc: &PassContext| {
            let range = vk::ImageSubresourceRange::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .level_count(1)
                .layer_count(1);
            for a in accum {
                pc.clear_color_image(a, &vk::ClearColorValue::default(), &[range]);
            }
        })
    }

    /// The wide Gaussians, each over its weight, added to the narrow part.
    pub(super) fn resolve_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let t = f.targets;
        let extent = f.extent;
        let shader = self.shaders()[2];
        // The six Gaussians' resolve loops over the wide ones; Burley's has no loop.
        let trips: &[u32] = match self.profile {
            Profile::SixGaussian => &[WIDE_GAUSSIANS as u32],
            Profile::Burley => &[],
        };
        let work = ShaderWork {
            shader: shader.into(),
            fetches: vec![fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0)],
            alu: alu_estimate(shader, trips),
            storage_read_bytes: 64.0,
            storage_write_bytes: 16.0,
            shared_bytes: 0.0,
        };
        let mut pass = Pass::new("reference resolve", PassRole::Sss);
        // Samples the diffuse target, reads the accumulators, adds to the output.
        let set = pass.set(&self.resolve_set);
        pass.dispatch(work, screen_groups(extent), GROUP * GROUP)
            .record(move |pc: &PassContext| pc.bind(&self.resolve, &[set]))
    }

    /// The narrow part, written into the output for every pixel.
    pub(super) fn narrow_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let t = f.targets;
        let sf = &self.surf;
        let extent = f.extent;
        let side = (2 * sf.max_radius + 1) as f64;
        let window = side * side;
        let bound = |image, texture: &str, count| Fetch {
            exact: false,
            ..fetch(f.res, image, texture, Filter::Point, count)
        };
        let shader = self.shaders()[0];
        // Burley's weight of a cell near the point loops over its 4x4 parts
        // (counted for every subsample of the window: a bound).
        let parts = crate::reference::burley::CELL_PARTS as u32;
        let trips = match self.profile {
            Profile::SixGaussian => vec![side as u32, side as u32, NARROW as u32, NARROW as u32],
            Profile::Burley => vec![side as u32, side as u32, parts, parts],
        };
        let work = ShaderWork {
            shader: shader.into(),
            fetches: vec![
                fetch(f.res, t.diffuse, "diffuseTex", Filter::Point, 1.0),
                bound(t.linear_depth, "depthTex", 1.0),
                bound(sf.normal, "surfNormal", 1.0 + window),
                bound(sf.position, "surfPosition", window),
                bound(sf.radiance, "surfRadiance", window + 1.0),
            ],
            alu: alu_estimate(shader, &trips),
            storage_write_bytes: 16.0,
            ..Default::default()
        };
        let mut pass = Pass::new("reference narrow", PassRole::Sss);
        // Samples the targets and the surface, writes the output.
        let set = pass.set(&self.narrow_set);
        pass.dispatch(work, screen_groups(extent), GROUP * GROUP)
            .record(move |pc: &PassContext| pc.bind(&self.narrow, &[set]))
    }

    /// Slab `k` (of the 9) of the wide Gaussians' gather over chunk `ci`'s
    /// samples, added to the accumulators.
    pub(super) fn gather_pass<'a>(&'a self, f: &FrameView<'a, '_>, ci: usize, k: i32) -> Pass<'a> {
        let t = f.targets;
        let groups = screen_groups(f.extent);
        let one = self.chunks.len() == 1;
        let c = &self.chunks[ci];
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
        let shader = self.shaders()[1];
        let per_slab = self.max_candidates.div_ceil(3);
        let trips = match self.profile {
            Profile::SixGaussian => vec![3, per_slab, WIDE_GAUSSIANS as u32],
            Profile::Burley => vec![3, per_slab],
        };
        let work = ShaderWork {
            shader: shader.into(),
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
            alu: alu_estimate(shader, &trips),
            // Positions and normals of the candidates, cell ranges, the output.
            storage_read_bytes: 32.0 * candidates + 16.0 + 8.0,
            storage_write_bytes: 48.0,
            shared_bytes: 0.0,
        };
        let push = GatherPush {
            dy: k % 3 - 1,
            dz: k / 3 - 1,
            first: c.first,
            count: c.count,
        };
        let mut pass = Pass::new(name, PassRole::Sss);
        // Samples the targets, the chunk's radiance and the surface normals,
        // reads the chunk's positions and normals and the grid, adds to the
        // accumulators.
        let set = pass.set(&c.gather_set);
        pass.dispatch(work, groups, GROUP * GROUP)
            .record(move |pc: &PassContext| {
                pc.bind(&self.gather, &[set]);
                self.gather.push(pc.ctx, pc.cmd, &push);
            })
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
