//! The shadow map: the key light's depth from every character that casts
//! onto a receiver in view (`Frame::choose_geometry`), each at its level.
//! A child of `frame`, whose fields it reads.

use super::*;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadowPush {
    light_view_proj: [[f32; 4]; 4],
}

impl Frame {
    /// The key light's depth from every casting character (the backdrop
    /// receives shadows but casts none worth a texel): the shadow map.
    pub(super) fn shadow_map<'a>(&'a self, passes: &mut Vec<Pass<'a>>) -> ImageId {
        let shadow = self.targets.shadow;
        passes.push(
            self.reads_vertices(Pass::new("shadow map", PassRole::Shadow))
                .depth_stencil(DepthStencil::cleared(shadow, 1.0))
                .draws(None, self.shadow_triangles())
                .record(move |pc: &PassContext| {
                    let (ctx, cmd) = (pc.ctx, pc.cmd);
                    self.shadow_pipeline.bind(ctx, cmd, &[self.shadow_set]);
                    let push = ShadowPush {
                        light_view_proj: self.light_frame.view_proj.to_cols_array_2d(),
                    };
                    self.shadow_pipeline.push(ctx, cmd, &push);
                    // Every casting character (its skin and its parts):
                    // one instanced draw per run of casting slots.
                    let runs = self.caster_runs();
                    for obj in self.objects.iter().filter(|o| o.kind.per_character()) {
                        for &(first, count) in &runs {
                            obj.draw_instances(ctx, cmd, first, count);
                        }
                    }
                }),
        );
        shadow
    }

    /// The runs of consecutive instance slots whose characters cast
    /// (`choose_geometry`; every character before it).
    fn caster_runs(&self) -> Vec<(u32, u32)> {
        let heads = self.instance_buffer.backdrop_slot;
        let casts = |s: u32| self.casters.get(s as usize).copied().unwrap_or(true);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for s in (0..heads).filter(|&s| casts(s)) {
            match runs.last_mut() {
                Some((first, count)) if *first + *count == s => *count += 1,
                _ => runs.push((s, 1)),
            }
        }
        runs
    }

    /// Triangles the shadow map submits: every casting character's objects
    /// at its level.
    fn shadow_triangles(&self) -> u64 {
        let runs = self.caster_runs();
        self.objects
            .iter()
            .filter(|o| o.kind.per_character())
            .map(|o| {
                runs.iter()
                    .flat_map(|&(first, count)| first..first + count)
                    .map(|s| o.mesh.slot_triangles(s as usize))
                    .sum::<u64>()
            })
            .sum()
    }
}
