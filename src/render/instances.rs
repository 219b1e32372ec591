//! The characters' model matrices as the shadow, geometry and id passes draw
//! them: one buffer, group after group (so the geometry pass draws each
//! group's heads in one instanced draw with its stencil code), then the
//! backdrop's; and where each character's and each group's lie in it. The
//! previous frame's models follow, slot for slot (a rigid motion's velocity:
//! the temporal anti-aliasing's previous position of a vertex is the
//! previous model times it).

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
    /// Models of one frame in the buffer (the previous frame's follow).
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
        let (mut data, group_slots, character_slots) = layout(groups, models, backdrop);
        let backdrop_slot = data.len() as u32 - 1;
        // No frame before the first: the previous models are these.
        data.extend_from_within(..);
        let buffer = Buffer::with_data(
            ctx,
            "character instances",
            bytemuck::cast_slice(&data),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(Instances {
            buffer,
            count: data.len() / 2,
            group_slots,
            backdrop_slot,
            character_slots,
        })
    }

    /// Rewrites the models (the same groups: a frame stepping through a
    /// rigid motion, between frames: the buffer is host-visible and no
    /// frame is in flight).
    pub fn write_models(
        &mut self,
        groups: &[SkinGroup],
        (models, previous): (&[Mat4], &[Mat4]),
        backdrop: Mat4,
    ) -> Result<()> {
        let (mut data, _, _) = layout(groups, models, backdrop);
        data.extend(layout(groups, previous, backdrop).0);
        self.buffer.write(bytemuck::cast_slice(&data))
    }

    /// The models as the buffer holds them, slot by slot: this frame's and
    /// the previous frame's (tests).
    pub fn read_models(&self) -> Result<(Vec<Mat4>, Vec<Mat4>)> {
        let all: Vec<Mat4> = bytemuck::cast_slice::<u8, Model>(self.buffer.read()?)
            .iter()
            .map(Mat4::from_cols_array_2d)
            .collect();
        let (now, before) = all.split_at(self.count);
        Ok((now.to_vec(), before.to_vec()))
    }

    /// The buffer as the shaders' `Instances` binding.
    pub fn binding(&self) -> (&'static str, Bind) {
        (
            "Instances",
            Bind::Uniform {
                buffer: self.buffer.raw,
                // This frame's models and the previous frame's after them.
                size: (2 * self.count * std::mem::size_of::<[[f32; 4]; 4]>()) as u64,
            },
        )
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.buffer.destroy(ctx);
    }
}

/// A model matrix as the buffer holds it (columns).
type Model = [[f32; 4]; 4];

/// The buffer's models (group after group, then the backdrop), each
/// group's (first slot, count) and each character's slot.
fn layout(
    groups: &[SkinGroup],
    models: &[Mat4],
    backdrop: Mat4,
) -> (Vec<Model>, Vec<(u32, u32)>, Vec<u32>) {
    let mut data: Vec<Model> = Vec::new();
    let mut group_slots = Vec::new();
    let mut character_slots = vec![0; models.len()];
    for g in groups {
        group_slots.push((data.len() as u32, g.characters.len() as u32));
        for &c in &g.characters {
            character_slots[c] = data.len() as u32;
            data.push(models[c].to_cols_array_2d());
        }
    }
    data.push(backdrop.to_cols_array_2d());
    (data, group_slots, character_slots)
}
