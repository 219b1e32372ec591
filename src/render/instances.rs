//! The characters' model matrices as the shadow, geometry and id passes draw
//! them: one buffer, group after group (so the geometry pass draws each
//! group's heads in one instanced draw with its stencil code), then the
//! backdrop's; and where each character's and each group's lie in it. The
//! previous frame's models follow, slot for slot (a rigid motion's velocity:
//! the temporal anti-aliasing's previous position of a vertex is the
//! previous model times it). Beside them, each slot's wrinkle zone weights
//! (thesis ch. 8: every character's own expression creases its own face).

use anyhow::Result;
use ash::vk;
use glam::Mat4;

use crate::vk::context::Context;
use crate::vk::guard::Guard;
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
    /// Per slot, the character's eight zone weights (the backdrop's 0).
    zones: Buffer,
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
        (models, zones): (&[Mat4], &[[f32; 8]]),
        backdrop: Mat4,
    ) -> Result<Self> {
        let (mut data, group_slots, character_slots) = layout(groups, models, backdrop);
        let backdrop_slot = data.len() as u32 - 1;
        // No frame before the first: the previous models are these.
        data.extend_from_within(..);
        // The models' buffer goes if the zones' cannot be made.
        let buffer = Guard::new(
            ctx,
            Buffer::with_data(
                ctx,
                "character instances",
                bytemuck::cast_slice(&data),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
        );
        let zones = Buffer::with_data(
            ctx,
            "character wrinkle zones",
            bytemuck::cast_slice(&zone_layout(&character_slots, zones)),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(Instances {
            buffer: buffer.keep(),
            zones,
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

    /// Rewrites each character's zone weights (frame index order; between
    /// frames, as `write_models`).
    pub fn write_zones(&mut self, zones: &[[f32; 8]]) -> Result<()> {
        self.zones.write(bytemuck::cast_slice(&zone_layout(
            &self.character_slots,
            zones,
        )))
    }

    /// The zone buffer as the shaders' `Zones` binding (two vec4 a slot).
    pub fn zones_binding(&self) -> (&'static str, Bind) {
        (
            "Zones",
            Bind::Uniform {
                buffer: self.zones.raw,
                size: self.zones.size,
            },
        )
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
        self.zones.destroy(ctx);
    }
}

/// A model matrix as the buffer holds it (columns).
type Model = [[f32; 4]; 4];

/// Each slot's zone weights from each character's (by frame index), the
/// backdrop's slot (the last) 0.
fn zone_layout(character_slots: &[u32], zones: &[[f32; 8]]) -> Vec<[f32; 8]> {
    let mut out = vec![[0.0; 8]; character_slots.len() + 1];
    for (&slot, z) in character_slots.iter().zip(zones) {
        out[slot as usize] = *z;
    }
    out
}

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
