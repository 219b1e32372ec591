//! Texture-space diffusion's descriptor sets: the frame's, the material's and
//! the blurs' (shared by every character), and each character's own (its
//! uniforms, the atlas, its map for the final pass).

use anyhow::Result;
use ash::vk;

use super::{CharacterUniforms, Cull, Tsd, CHARACTER_STRIDE, MAX_ISLANDS};
use crate::graph::ImageId;
use crate::method::MethodBind;
use crate::vk::pipeline::{Bind, Pipeline};

/// Descriptor sets shared by every character.
#[derive(Clone, Copy, Default)]
pub(super) struct SharedSets {
    /// Set 0 of the mask pipelines, the irradiance one and the final one.
    pub(super) frame: [vk::DescriptorSet; 5],
    pub(super) material: vk::DescriptorSet,
    /// u from the irradiance map, u from `pong`, v from `temp`.
    pub(super) blur: [vk::DescriptorSet; 3],
}

impl Tsd {
    /// Writes every set of the method (`SssMethod::bind`).
    pub(super) fn write_sets(&mut self, b: &MethodBind) -> Result<()> {
        let frame_set = |p: &Pipeline| -> Result<vk::DescriptorSet> {
            let binds: Vec<(&str, Bind)> = b
                .frame_binds
                .iter()
                .filter(|(n, _)| p.reflection.find(0, n).is_some())
                .copied()
                .collect();
            self.pool.write_set(b.ctx, p, 0, &binds)
        };
        let p = &self.pipelines;
        let mut frame = [vk::DescriptorSet::null(); 5];
        if self.config.z_prepass {
            frame[0] = frame_set(&p.mask_depth)?;
            frame[1] = frame_set(&p.mask_backface)?;
        }
        if self.config.cull == Cull::Stencil {
            frame[2] = frame_set(&p.mask_cull)?;
        }
        frame[3] = frame_set(&p.irradiance)?;
        frame[4] = frame_set(&p.final_pass)?;
        let material = self
            .pool
            .write_set(b.ctx, &p.irradiance, 1, &b.skin_material_binds)?;
        let m = self.maps;
        let blur_set = |pipe: &Pipeline, src: ImageId, stretch: ImageId| {
            self.pool.write_set(
                b.ctx,
                pipe,
                0,
                &[
                    ("srcTex", Bind::Texture(b.res.view(src))),
                    ("stretchTex", Bind::Texture(b.res.view(stretch))),
                    ("linearClamp", Bind::Sampler(b.samplers.linear_clamp)),
                ],
            )
        };
        let blur = [
            blur_set(&p.blur_u, m.irradiance, m.stretch_u)?,
            blur_set(&p.blur_u, m.pong, m.stretch_u)?,
            blur_set(&p.blur_v, m.temp, m.stretch_v)?,
        ];
        let size = std::mem::size_of::<CharacterUniforms>() as u64;
        let atlas = Bind::Uniform {
            buffer: self.atlas_ubo.raw,
            size: (MAX_ISLANDS * 16) as u64,
        };
        let mut sets = Vec::with_capacity(self.characters.len());
        for (k, c) in self.characters.iter().enumerate() {
            let ch = Bind::Range {
                buffer: self.character_ubo.raw,
                offset: k as u64 * CHARACTER_STRIDE,
                size,
            };
            let uv_set = |pipe: &Pipeline, used: bool| -> Result<vk::DescriptorSet> {
                if !used {
                    return Ok(vk::DescriptorSet::null());
                }
                let binds: Vec<(&str, Bind)> = [("ch", ch), ("atlas", atlas)]
                    .into_iter()
                    .filter(|(n, _)| pipe.reflection.find(2, n).is_some())
                    .collect();
                self.pool.write_set(b.ctx, pipe, 2, &binds)
            };
            let uv_sets = [
                uv_set(&p.mask_depth, self.config.z_prepass)?,
                uv_set(&p.mask_backface, self.config.z_prepass)?,
                uv_set(&p.mask_cull, self.config.cull == Cull::Stencil)?,
                uv_set(&p.irradiance, true)?,
            ];
            let final_set = self.pool.write_set(
                b.ctx,
                &p.final_pass,
                1,
                &[
                    ("mapTex", Bind::Texture(b.res.view(c.map))),
                    ("linearClamp", Bind::Sampler(b.samplers.linear_clamp)),
                    ("ch", ch),
                    ("atlas", atlas),
                ],
            )?;
            sets.push((uv_sets, final_set));
        }
        for (c, (uv_sets, final_set)) in self.characters.iter_mut().zip(sets) {
            c.uv_sets = uv_sets;
            c.final_set = final_set;
        }
        self.sets = SharedSets {
            frame,
            material,
            blur,
        };
        Ok(())
    }
}
