//! What a pass's record closure records with: the device, the command
//! buffer, and commands that take only the typed references the pass's
//! declaration handed back (`refs.rs`), each checked against that
//! declaration.

use ash::vk;

use super::refs::{BufferRef, ClearDst, ImageRef, SetRef, TransferDst, TransferSrc};
use super::resources::{BufferId, ImageId, Resources};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::pipeline::Pipeline;

/// What a pass's record closure gets: the device, the command buffer, and
/// commands that take only the references the pass's declaration handed back
/// (`refs.rs`): the closure has no other way to a frame image.
pub struct PassContext<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    /// In a pass that renders each colour target alone: which one this call
    /// renders (0 otherwise).
    pub target: usize,
    pub(super) res: &'a Resources,
    /// The pass's declaration: its name, images, buffers and sets.
    pub(super) pass: Declared<'a>,
}

/// What a pass declared, as its record closure's commands check it.
#[derive(Clone, Copy)]
pub(super) struct Declared<'a> {
    pub(super) name: &'a str,
    pub(super) images: &'a [(ImageId, AccessKind)],
    pub(super) buffers: &'a [(BufferId, AccessKind)],
    pub(super) sets: &'a [vk::DescriptorSet],
}

impl PassContext<'_> {
    /// Checks that `id` was declared with `access` on this pass: a reference
    /// is made only by a declaration, but one carried into another pass's
    /// closure would record there without a barrier.
    fn declared(&self, id: ImageId, access: AccessKind) -> (vk::Image, vk::ImageLayout) {
        assert!(
            self.pass.images.contains(&(id, access)),
            "pass '{}' records with '{}', a reference another pass declared",
            self.pass.name,
            self.res.name(id)
        );
        (self.res.image(id).raw, access.info().layout)
    }

    fn declared_buffer(&self, id: BufferId, access: AccessKind) -> vk::Buffer {
        assert!(
            self.pass.buffers.contains(&(id, access)),
            "pass '{}' records with buffer '{}', a reference another pass declared",
            self.pass.name,
            self.res.buffer_name(id)
        );
        self.res.buffer(id)
    }

    fn raw_sets(&self, sets: &[SetRef]) -> Vec<vk::DescriptorSet> {
        sets.iter()
            .map(|s| {
                assert!(
                    self.pass.sets.contains(&s.raw),
                    "pass '{}' binds a set another pass declared",
                    self.pass.name
                );
                s.raw
            })
            .collect()
    }

    /// Binds `pipeline` and `sets` as its sets 0.. (what the executor does
    /// not: attachments are bound from the declaration).
    pub fn bind(&self, pipeline: &Pipeline, sets: &[SetRef]) {
        pipeline.bind(self.ctx, self.cmd, &self.raw_sets(sets));
    }

    /// Binds `sets` as `pipeline`'s sets from `first` on.
    pub fn bind_sets(&self, pipeline: &Pipeline, first: u32, sets: &[SetRef]) {
        pipeline.bind_sets(self.ctx, self.cmd, first, &self.raw_sets(sets));
    }

    /// Copies `regions` of `src` into `dst`.
    pub fn copy_image(
        &self,
        src: ImageRef<TransferSrc>,
        dst: ImageRef<TransferDst>,
        regions: &[vk::ImageCopy],
    ) {
        let (src, src_layout) = self.declared(src.id, src.access);
        let (dst, dst_layout) = self.declared(dst.id, dst.access);
        unsafe {
            self.ctx
                .device
                .cmd_copy_image(self.cmd, src, src_layout, dst, dst_layout, regions)
        };
    }

    /// Copies `regions` of `src` into the tracked buffer `dst`.
    pub fn copy_image_to_buffer(
        &self,
        src: ImageRef<TransferSrc>,
        dst: BufferRef<TransferDst>,
        regions: &[vk::BufferImageCopy],
    ) {
        let (src, layout) = self.declared(src.id, src.access);
        let dst = self.declared_buffer(dst.id, dst.access);
        unsafe {
            self.ctx
                .device
                .cmd_copy_image_to_buffer(self.cmd, src, layout, dst, regions)
        };
    }

    /// Copies `regions` of `staging` into `dst`. `staging` is a host-written
    /// buffer of this submission's own (no graph resource: the host wrote it
    /// before the submission, which makes its writes visible).
    pub fn copy_buffer_to_image(
        &self,
        staging: vk::Buffer,
        dst: ImageRef<TransferDst>,
        regions: &[vk::BufferImageCopy],
    ) {
        let (dst, layout) = self.declared(dst.id, dst.access);
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer_to_image(self.cmd, staging, dst, layout, regions)
        };
    }

    /// Clears `ranges` of `dst` to `value`.
    pub fn clear_color_image(
        &self,
        dst: ImageRef<ClearDst>,
        value: &vk::ClearColorValue,
        ranges: &[vk::ImageSubresourceRange],
    ) {
        let (dst, layout) = self.declared(dst.id, dst.access);
        unsafe {
            self.ctx
                .device
                .cmd_clear_color_image(self.cmd, dst, layout, value, ranges)
        };
    }

    /// Fills the whole tracked buffer `dst` with the word `value`.
    pub fn fill_buffer(&self, dst: BufferRef<TransferDst>, value: u32) {
        let dst = self.declared_buffer(dst.id, dst.access);
        unsafe {
            self.ctx
                .device
                .cmd_fill_buffer(self.cmd, dst, 0, vk::WHOLE_SIZE, value)
        };
    }

    /// The view and layout of an attachment of this pass (the executor's own
    /// binding of the attachments it declared).
    pub(super) fn attachment(&self, id: ImageId) -> (vk::ImageView, vk::ImageLayout) {
        let access = self
            .pass
            .images
            .iter()
            .find(|(i, _)| *i == id)
            .map(|(_, a)| *a)
            .unwrap_or_else(|| {
                panic!(
                    "pass '{}' renders to '{}' it did not declare",
                    self.pass.name,
                    self.res.name(id)
                )
            });
        (self.res.view(id), access.info().layout)
    }
}
