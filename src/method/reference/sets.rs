//! The ground truth's descriptor sets: the radiance pass's (one per draw of
//! each chunk), the surface pass's, the narrow part's, the gather's (one per
//! chunk) and the resolve's.

use anyhow::Result;

use super::setup::{GatherParams, NarrowParams};
use super::Reference;
use crate::method::MethodBind;
use crate::reference::sampling::SurfaceSample;
use crate::vk::pipeline::Bind;

impl Reference {
    /// Writes every set of the method (`SssMethod::bind`).
    pub(super) fn write_sets(&mut self, b: &MethodBind) -> Result<()> {
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
}
