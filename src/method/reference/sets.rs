//! The ground truth's descriptor sets: the radiance pass's (one per draw of
//! each chunk), the surface pass's, the narrow part's, the gather's (one per
//! chunk) and the resolve's. Those that bind frame images or the samples'
//! buffers are graph sets, stated once everything they bind exists
//! ([`Reference::describe_sets`]), each in the order its pass declared its
//! resources before (reports keep that order), and written at bind time.

use anyhow::Result;

use super::setup::{GatherParams, NarrowParams};
use super::Reference;
use crate::graph::{Binding, GraphSet, Storage};
use crate::method::{MethodBind, MethodSetup};
use crate::reference::sampling::SurfaceSample;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::Bind;

/// A uniform buffer, whole.
fn uniform(buffer: &Buffer, size: u64) -> Binding {
    Binding::Fixed(Bind::Uniform {
        buffer: buffer.raw,
        size,
    })
}

impl Reference {
    /// The graph sets of the method (at the end of `build`).
    pub(super) fn describe_sets(&mut self, s: &MethodSetup) {
        let (res, t) = (&*s.res, s.targets);
        let sample_bytes = std::mem::size_of::<SurfaceSample>() as u64;
        self.frame_set = GraphSet::new(res, &self.surface_pipeline, 0, s.frame_binds.clone());
        let sf = &self.surf;
        self.narrow_set = GraphSet::new(
            res,
            &self.narrow,
            0,
            vec![
                ("diffuseTex", Binding::Sampled(t.diffuse)),
                ("depthTex", Binding::Sampled(t.linear_depth)),
                ("surfRadiance", Binding::Sampled(sf.radiance)),
                ("surfPosition", Binding::Sampled(sf.position)),
                ("surfNormal", Binding::Sampled(sf.normal)),
                ("outImage", Binding::StorageImage(self.out, Storage::Write)),
                (
                    "params",
                    uniform(
                        &self.narrow_params,
                        std::mem::size_of::<NarrowParams>() as u64,
                    ),
                ),
            ],
        );
        let mut resolve = vec![
            ("diffuseTex", Binding::Sampled(t.diffuse)),
            (
                "outImage",
                Binding::StorageImage(self.out, Storage::ReadWrite),
            ),
        ];
        for (name, a) in ["accum4", "accum5", "accum6"].into_iter().zip(self.accum) {
            resolve.push((name, Binding::StorageImage(a, Storage::Read)));
        }
        self.resolve_set = GraphSet::new(res, &self.resolve, 0, resolve);
        let mut frame_binds = s.frame_binds.clone();
        frame_binds.push((
            "Zones",
            Binding::Fixed(Bind::Uniform {
                buffer: self.zones.raw,
                size: self.zones.size,
            }),
        ));
        for c in &mut self.chunks {
            c.draws.clear();
            let mut first = 0;
            while first < c.count {
                let n = (c.count - first).min(self.draw_samples);
                let mut binds = frame_binds.clone();
                binds.push((
                    "Samples",
                    Binding::StorageBuffer {
                        id: c.buffer_ids[0],
                        offset: first as u64 * sample_bytes,
                        size: n as u64 * sample_bytes,
                        storage: Storage::Read,
                    },
                ));
                c.draws
                    .push((GraphSet::new(res, &self.irradiance, 0, binds), first, n));
                first += n;
            }
            let read = |id, size| Binding::StorageBuffer {
                id,
                offset: 0,
                size,
                storage: Storage::Read,
            };
            let mut gather = vec![
                ("diffuseTex", Binding::Sampled(t.diffuse)),
                ("depthTex", Binding::Sampled(t.linear_depth)),
                ("radianceTex", Binding::Sampled(c.radiance)),
                ("surfNormal", Binding::Sampled(self.surf.normal)),
            ];
            for (name, a) in ["accum4", "accum5", "accum6"].into_iter().zip(self.accum) {
                gather.push((name, Binding::StorageImage(a, Storage::ReadWrite)));
            }
            gather.extend([
                ("Positions", read(c.buffer_ids[1], c.positions.size)),
                ("Normals", read(c.buffer_ids[2], c.normals.size)),
                ("Cells", read(self.cells_id, self.cells.size)),
                (
                    "params",
                    uniform(&self.params, std::mem::size_of::<GatherParams>() as u64),
                ),
            ]);
            c.gather_set = GraphSet::new(res, &self.gather, 0, gather);
        }
    }

    /// Writes every set of the method (`SssMethod::bind`).
    pub(super) fn write_sets(&mut self, b: &MethodBind) -> Result<()> {
        self.material_set = b
            .pool
            .write_set(b.ctx, &self.irradiance, 1, &b.skin_material_binds)?;
        b.write(&mut self.frame_set, &self.surface_pipeline)?;
        self.surf_material =
            b.pool
                .write_set(b.ctx, &self.surface_pipeline, 1, &b.skin_material_binds)?;
        b.write(&mut self.narrow_set, &self.narrow)?;
        b.write(&mut self.resolve_set, &self.resolve)?;
        for c in &mut self.chunks {
            for (set, ..) in &mut c.draws {
                b.write(set, &self.irradiance)?;
            }
            b.write(&mut c.gather_set, &self.gather)?;
        }
        Ok(())
    }
}
