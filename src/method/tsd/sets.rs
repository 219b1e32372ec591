//! Texture-space diffusion's descriptor sets: the frame's, the material's and
//! the blurs' (shared by every character), and each character's own (its
//! uniforms, the atlas, its map for the final pass). The sets that bind frame
//! images (the shadow map, the maps) are graph sets, stated when the method
//! is built ([`Tsd::describe_sets`]) and written once the images exist.

use anyhow::Result;
use ash::vk;

use super::{CharacterUniforms, Cull, Tsd, CHARACTER_STRIDE, MAX_ISLANDS};
use crate::graph::{Binding, GraphSet, ImageId};
use crate::method::{MethodBind, MethodSetup};
use crate::vk::pipeline::{Bind, Pipeline};

/// Descriptor sets shared by every character.
#[derive(Default)]
pub(super) struct SharedSets {
    /// Set 0 of the mask pipelines, the irradiance one and the final one
    /// (the frame's bindings each reads; `None`: a pipeline not built).
    pub(super) frame: [Option<GraphSet>; 5],
    pub(super) material: vk::DescriptorSet,
    /// Set 2 of the final pass: the skin material's per-texel parameters
    /// (its strength mixes the map in, tsd_final.frag).
    pub(super) texel: vk::DescriptorSet,
    /// u from the irradiance map, u from `pong`, v from `temp`.
    pub(super) blur: [GraphSet; 3],
}

impl Tsd {
    /// The sets that bind frame images or buffers, stated once the
    /// pipelines and maps exist (`build`): what the passes binding them
    /// declare.
    pub(super) fn describe_sets(&mut self, s: &MethodSetup) {
        let frame_set = |p: &Pipeline| {
            let binds = s
                .frame_binds
                .iter()
                .filter(|(n, _)| p.reflection.find(0, n).is_some())
                .copied()
                .collect();
            Some(GraphSet::new(s.res, p, 0, binds))
        };
        let p = &self.pipelines;
        let cfg = self.config;
        let mut frame: [Option<GraphSet>; 5] = Default::default();
        if cfg.z_prepass {
            frame[0] = frame_set(&p.mask_depth);
            frame[1] = frame_set(&p.mask_backface);
        }
        if cfg.cull == Cull::Stencil {
            frame[2] = frame_set(&p.mask_cull);
        }
        frame[3] = frame_set(&p.irradiance);
        frame[4] = frame_set(&p.final_pass);
        let m = self.maps;
        let linear = Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp));
        let blur_set = |pipe: &Pipeline, src: ImageId, stretch: ImageId| {
            GraphSet::new(
                s.res,
                pipe,
                0,
                vec![
                    ("srcTex", Binding::Sampled(src)),
                    ("stretchTex", Binding::Sampled(stretch)),
                    ("linearClamp", linear),
                ],
            )
        };
        let blur = [
            blur_set(&p.blur_u, m.irradiance, m.stretch_u),
            blur_set(&p.blur_u, m.pong, m.stretch_u),
            blur_set(&p.blur_v, m.temp, m.stretch_v),
        ];
        let finals: Vec<GraphSet> = (0..self.characters.len())
            .map(|k| {
                let (ch, atlas) = self.uniform_binds(k);
                GraphSet::new(
                    s.res,
                    &p.final_pass,
                    1,
                    vec![
                        ("mapTex", Binding::Sampled(self.characters[k].map)),
                        ("linearClamp", linear),
                        ("ch", Binding::Fixed(ch)),
                        ("atlas", Binding::Fixed(atlas)),
                    ],
                )
            })
            .collect();
        for (c, f) in self.characters.iter_mut().zip(finals) {
            c.final_set = f;
        }
        self.sets = SharedSets {
            frame,
            material: vk::DescriptorSet::null(),
            texel: vk::DescriptorSet::null(),
            blur,
        };
    }

    /// Character `k`'s uniforms and the atlas, as bound.
    fn uniform_binds(&self, k: usize) -> (Bind, Bind) {
        let size = std::mem::size_of::<CharacterUniforms>() as u64;
        let ch = Bind::Range {
            buffer: self.character_ubo.raw,
            offset: k as u64 * CHARACTER_STRIDE,
            size,
        };
        let atlas = Bind::Uniform {
            buffer: self.atlas_ubo.raw,
            size: (MAX_ISLANDS * 16) as u64,
        };
        (ch, atlas)
    }

    /// Writes every set of the method (`SssMethod::bind`).
    pub(super) fn write_sets(&mut self, b: &MethodBind) -> Result<()> {
        let (ctx, res, pool) = (b.ctx, b.res, &self.pool);
        let p = &self.pipelines;
        let pipes = [
            &p.mask_depth,
            &p.mask_backface,
            &p.mask_cull,
            &p.irradiance,
            &p.final_pass,
        ];
        for (set, pipe) in self.sets.frame.iter_mut().zip(pipes) {
            if let Some(set) = set {
                set.write(ctx, pool, res, pipe)?;
            }
        }
        self.sets.material = pool.write_set(ctx, &p.irradiance, 1, &b.skin_material_binds)?;
        let texel: Vec<(&str, Bind)> = b
            .skin_material_binds
            .iter()
            .filter(|(n, _)| p.final_pass.reflection.find(2, n).is_some())
            .copied()
            .collect();
        self.sets.texel = pool.write_set(ctx, &p.final_pass, 2, &texel)?;
        for (set, pipe) in self
            .sets
            .blur
            .iter_mut()
            .zip([&p.blur_u, &p.blur_u, &p.blur_v])
        {
            set.write(ctx, pool, res, pipe)?;
        }
        let cull = self.config.cull == Cull::Stencil;
        let z = self.config.z_prepass;
        for k in 0..self.characters.len() {
            let (ch, atlas) = self.uniform_binds(k);
            let uv_set = |pipe: &Pipeline, used: bool| -> Result<vk::DescriptorSet> {
                if !used {
                    return Ok(vk::DescriptorSet::null());
                }
                let binds: Vec<(&str, Bind)> = [("ch", ch), ("atlas", atlas)]
                    .into_iter()
                    .filter(|(n, _)| pipe.reflection.find(2, n).is_some())
                    .collect();
                pool.write_set(ctx, pipe, 2, &binds)
            };
            let uv_sets = [
                uv_set(&p.mask_depth, z)?,
                uv_set(&p.mask_backface, z)?,
                uv_set(&p.mask_cull, cull)?,
                uv_set(&p.irradiance, true)?,
            ];
            let c = &mut self.characters[k];
            c.uv_sets = uv_sets;
            c.final_set.write(ctx, pool, res, &p.final_pass)?;
        }
        Ok(())
    }
}
