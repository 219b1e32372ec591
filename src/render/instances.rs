//! The characters' model matrices as the shadow, geometry and id passes draw
//! them: one buffer, group after group (so the geometry pass draws each
//! group's heads in one instanced draw with its stencil code), then the
//! backdrop's; and where each character's and each group's lie in it.

use anyhow::Result;
use ash::vk;
use glam::Mat4;

use crate::vk::context::Context;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::Bind;

/// The heads of one group as the geometry pass draws them.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinGroup {
    pub stencil: u32,
    /// Frame indices (into `Frame::instances`).
    pub characters: Vec<usize>,
}

/// The instance buffer and its slots.
#[derive(Default)]
pub struct Instances {
    buffer: Buffer,
    /// Models in the buffer.
    count: usize,
    /// Each group's first slot and count, in group order.
    pub group_slots: Vec<(u32, u32)>,
    pub backdrop_slot: u32,
    /// Each character's slot, by frame index.
    pub character_slots: Vec<u32>,
}

impl Instances {
    /// The models of `groups` (frame indices into `models`), group after
    /// group, then `backdrop`.
    pub fn new(
        ctx: &Context,
        groups: &[SkinGroup],
        models: &[Mat4],
        backdrop: Mat4,
    ) -> Result<Self> {
        let mut data: Vec<[[f32; 4]; 4]> = Vec::new();
        let mut group_slots = Vec::new();
        let mut character_slots = vec![0; models.len()];
        for g in groups {
            group_slots.push((data.len() as u32, g.characters.len() as u32));
            for &c in &g.characters {
                character_slots[c] = data.len() as u32;
                data.push(models[c].to_cols_array_2d());
            }
        }
        let backdrop_slot = data.len() as u32;
        data.push(backdrop.to_cols_array_2d());
        let buffer = Buffer::with_data(
            ctx,
            "character instances",
            bytemuck::cast_slice(&data),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(Instances {
            buffer,
            count: data.len(),
            group_slots,
            backdrop_slot,
            character_slots,
        })
    }

    /// The buffer as the shaders' `Instances` binding.
    pub fn binding(&self) -> (&'static str, Bind) {
        (
            "Instances",
            Bind::Uniform {
                buffer: self.buffer.raw,
                size: (self.count * std::mem::size_of::<[[f32; 4]; 4]>()) as u64,
            },
        )
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.buffer.destroy(ctx);
    }
}
