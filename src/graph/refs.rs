//! What a pass's declaration hands back (kajiya's `Ref<Image, GpuSrv>`):
//! typed references to the frame's images, buffers and descriptor sets, the
//! only things a record closure can record with.
//!
//! The guarantee is the compiler's. Outside `graph`, no code can name a frame
//! image's Vulkan handles: `Resources` keeps its images' views and raw
//! handles to the graph. A record closure reaches them only through
//! [`PassContext`](super::PassContext)'s commands, which take these
//! references and nothing else (no [`ImageId`]), and a reference can only be
//! made by declaring the use on a pass (its fields are private): so a pass
//! cannot record with an image it did not declare, nor in another way than
//! it declared it (a copy source is no clear destination). Sampled and
//! storage uses are bound through descriptor sets: a [`GraphSet`] states its
//! frame images and buffers when it is made, and declaring it on a pass
//! declares them all (the one fact written once) and hands back the
//! [`SetRef`] the closure binds.
//!
//! Attachments are no references: the executor binds them itself, from the
//! declaration, so no closure ever names one.
//!
//! A reference carried into another pass's closure would compile; the
//! context refuses it when recording (a panic naming the pass).
//!
//! [`GraphSet`]: super::GraphSet
//!
//! ```compile_fail,E0308
//! // A closure cannot record with an image id: only with a declared reference.
//! use dermis::graph::{ImageId, ImageRef, Pass, PassContext, TransferDst};
//! use dermis::graph::work::PassRole;
//!
//! fn copy<'a>(src: ImageId, mut pass: Pass<'a>, dst: ImageId) -> Pass<'a> {
//!     let dst: ImageRef<TransferDst> = pass.transfer_dst(dst);
//!     pass.record(move |pc: &PassContext| pc.copy_image(src, dst, &[]))
//! }
//! ```
//!
//! ```compile_fail,E0308
//! // Nor with a reference declared for another use: a clear is no copy.
//! use dermis::graph::{ImageId, Pass, PassContext};
//!
//! fn copy<'a>(mut pass: Pass<'a>, src: ImageId, dst: ImageId) -> Pass<'a> {
//!     let src = pass.clear_dst(src);
//!     let dst = pass.transfer_dst(dst);
//!     pass.record(move |pc: &PassContext| pc.copy_image(src, dst, &[]))
//! }
//! ```
//!
//! ```compile_fail,E0624
//! // Nor sample a frame image through a descriptor set of its own making:
//! // the graph keeps the images' views.
//! use dermis::graph::{ImageId, Resources};
//!
//! fn view(res: &Resources, id: ImageId) -> ash::vk::ImageView {
//!     res.view(id)
//! }
//! ```
//!
//! ```compile_fail,E0451
//! // And a reference is made by a declaration, never by hand.
//! use dermis::graph::{ImageId, ImageRef, TransferSrc};
//!
//! fn forge(id: ImageId) -> ImageRef<TransferSrc> {
//!     ImageRef { id, access: todo!(), how: std::marker::PhantomData }
//! }
//! ```
//!
//! What the same closures look like when the uses are declared: this one
//! compiles, so each failure above fails for the one expression it changes
//! (stable rustdoc does not check the error codes the fences name; they say
//! which error each is, as rustc gives them).
//!
//! ```no_run
//! use dermis::graph::{Binding, GraphSet, ImageId, Pass, PassContext};
//! use dermis::vk::pipeline::Pipeline;
//!
//! fn copy<'a>(mut pass: Pass<'a>, src: ImageId, dst: ImageId) -> Pass<'a> {
//!     let src = pass.transfer_src(src);
//!     let dst = pass.transfer_dst(dst);
//!     pass.record(move |pc: &PassContext| pc.copy_image(src, dst, &[]))
//! }
//!
//! fn sample<'a>(mut pass: Pass<'a>, set: &GraphSet, pipeline: &'a Pipeline) -> Pass<'a> {
//!     let set = pass.set(set);
//!     pass.record(move |pc: &PassContext| pc.bind(pipeline, &[set]))
//! }
//!
//! fn set_of(res: &dermis::graph::Resources, pipeline: &Pipeline, id: ImageId) -> GraphSet {
//!     GraphSet::new(res, pipeline, 0, vec![("colorTex", Binding::Sampled(id))])
//! }
//! # fn main() {}
//! ```

use std::marker::PhantomData;

use ash::vk;

use super::resources::{BufferId, ImageId};
use crate::vk::barrier::AccessKind;

/// The source of a copy (`TransferRead`).
pub enum TransferSrc {}
/// The destination of a copy or fill, whole or in part (`TransferWrite`,
/// `TransferWritePartial`).
pub enum TransferDst {}
/// The destination of `vkCmdClearColorImage` (`ClearWrite`).
pub enum ClearDst {}

/// A frame image a pass declared for a command, `A` saying which.
pub struct ImageRef<A> {
    pub(super) id: ImageId,
    pub(super) access: AccessKind,
    how: PhantomData<A>,
}

impl<A> ImageRef<A> {
    pub(super) fn new(id: ImageId, access: AccessKind) -> Self {
        ImageRef {
            id,
            access,
            how: PhantomData,
        }
    }

    /// The access it was declared with (what the image's usage and barriers
    /// follow from).
    pub fn access(&self) -> AccessKind {
        self.access
    }
}

impl<A> Clone for ImageRef<A> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<A> Copy for ImageRef<A> {}

/// A tracked buffer a pass declared for a command, `A` saying which.
pub struct BufferRef<A> {
    pub(super) id: BufferId,
    pub(super) access: AccessKind,
    how: PhantomData<A>,
}

impl<A> BufferRef<A> {
    pub(super) fn new(id: BufferId, access: AccessKind) -> Self {
        BufferRef {
            id,
            access,
            how: PhantomData,
        }
    }
}

impl<A> Clone for BufferRef<A> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<A> Copy for BufferRef<A> {}

/// A descriptor set a pass declared (and with it every frame image and
/// buffer it binds): what the record closure binds.
#[derive(Clone, Copy, Debug)]
pub struct SetRef {
    pub(super) raw: vk::DescriptorSet,
}
