//! The one vocabulary of resource accesses and the one table that maps each to
//! (pipeline stage, access mask, image layout).
//!
//! No call site in dermis writes a stage mask, an access mask, a layout or an
//! image usage flag by hand: passes declare *what* they do with a resource
//! ([`AccessKind`]); [`ResourceState::plan`] derives every barrier from what the
//! resource went through and the next access, [`AccessKind::info`] gives the
//! layout a pass records with, and [`AccessKind::image_usage`] the usage an image
//! is created with. The rules follow the Khronos synchronization examples and the
//! vk-sync idea that access masks are only made available after a *write*:
//! read-after-read needs nothing (unless the layout changes), write-after-read
//! needs only an execution dependency, and anything after a write flushes the
//! write's access mask.
//!
//! This module is pure data and is tested without a GPU.

use ash::vk;

/// What a pass does with a resource. Each kind names one stage/access/layout
/// triple in [`AccessKind::info`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccessKind {
    /// Not yet used (or contents irrelevant): the start of every resource's life.
    Nothing,
    /// Colour attachment written with LOAD_OP_CLEAR / DONT_CARE: old contents discarded.
    ColorAttachmentWrite,
    /// Colour attachment written with LOAD_OP_LOAD (or blended): old contents kept,
    /// so the load is a read that must see earlier writes.
    ColorAttachmentLoadWrite,
    /// Depth/stencil attachment cleared and written (depth test + write, stencil replace).
    DepthStencilWrite,
    /// Single-sample colour image written by the multisample resolve at the
    /// end of a render pass (`--msaa`): the colour-attachment row, named apart
    /// so reports and the budget tell a resolve from a draw.
    ColorResolveWrite,
    /// Single-sample depth/stencil image written by the multisample resolve at
    /// the end of a render pass (`--msaa`): resolves of depth/stencil happen in
    /// the colour-attachment-output stage with colour-attachment writes (the
    /// spec's "Multisample Resolve Operations"), in the attachment layout.
    DepthStencilResolveWrite,
    /// Depth/stencil attachment loaded for testing only (depth test or stencil test,
    /// no writes): read-only layout, so it could also be sampled at the same time.
    DepthStencilReadOnly,
    /// Sampled (texture fetch) in a fragment shader: colour or depth textures.
    FragmentSampledRead,
    /// Sampled in a compute shader.
    ComputeSampledRead,
    /// Sampled by fragment and compute shaders alike: static textures uploaded
    /// once and read by both the raster passes and the ground-truth compute passes.
    AnyShaderSampledRead,
    /// Written as a storage image/buffer by a compute shader (whole contents produced).
    ComputeStorageWrite,
    /// Read as a storage image/buffer by a compute shader.
    ComputeStorageRead,
    /// Read and written (accumulated into) as a storage image by a compute shader.
    ComputeStorageReadWrite,
    /// Read as a storage buffer by a fragment shader.
    FragmentStorageRead,
    /// Read and written (atomics) as a storage buffer by a fragment shader.
    FragmentStorageReadWrite,
    /// Source of a copy.
    TransferRead,
    /// Destination of a copy or clear (whole contents produced).
    TransferWrite,
    /// Destination of a copy into part of the resource: the rest keeps its
    /// contents, so neither they nor the layout may be discarded.
    TransferWritePartial,
    /// Cleared whole by `vkCmdClearColorImage` (the clear stage, not the copy one).
    ClearWrite,
    /// Read by the host after the GPU is done (buffers only).
    HostRead,
    /// Written by the host before the GPU uses it (buffers only).
    HostWrite,
    /// Read as a uniform buffer by vertex or fragment shaders.
    UniformRead,
    /// Read as vertex/index data by the input assembler.
    VertexInputRead,
    /// Read as the arguments of an indirect dispatch or draw (buffers only):
    /// a compute pass's workgroup counts written on the GPU by an earlier one.
    IndirectCommandRead,
}

/// Stage, access and layout of one access kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccessInfo {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
}

type S = vk::PipelineStageFlags2;
type A = vk::AccessFlags2;
type L = vk::ImageLayout;

impl AccessKind {
    /// The table. Every barrier in dermis is derived from these rows.
    pub fn info(self) -> AccessInfo {
        let (stage, access, layout) = match self {
            AccessKind::Nothing => (S::NONE, A::NONE, L::UNDEFINED),
            AccessKind::ColorAttachmentWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            AccessKind::ColorAttachmentLoadWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            // Clears and loads of depth/stencil happen in the early tests stage,
            // stores in the late one: both stages are named.
            AccessKind::DepthStencilWrite => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            ),
            AccessKind::ColorResolveWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            AccessKind::DepthStencilResolveWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            ),
            AccessKind::DepthStencilReadOnly => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            ),
            AccessKind::FragmentSampledRead => (
                S::FRAGMENT_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
            ),
            AccessKind::ComputeSampledRead => (
                S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
            ),
            AccessKind::AnyShaderSampledRead => (
                S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
            ),
            AccessKind::ComputeStorageWrite => {
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE, L::GENERAL)
            }
            AccessKind::ComputeStorageRead => {
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ, L::GENERAL)
            }
            AccessKind::ComputeStorageReadWrite => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                L::GENERAL,
            ),
            AccessKind::FragmentStorageRead => {
                (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ, L::GENERAL)
            }
            AccessKind::FragmentStorageReadWrite => (
                S::FRAGMENT_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                L::GENERAL,
            ),
            AccessKind::TransferRead => (S::COPY, A::TRANSFER_READ, L::TRANSFER_SRC_OPTIMAL),
            AccessKind::TransferWrite | AccessKind::TransferWritePartial => {
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL)
            }
            AccessKind::ClearWrite => (S::CLEAR, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
            AccessKind::HostRead => (S::HOST, A::HOST_READ, L::UNDEFINED),
            AccessKind::HostWrite => (S::HOST, A::HOST_WRITE, L::UNDEFINED),
            AccessKind::UniformRead => (
                S::VERTEX_SHADER | S::FRAGMENT_SHADER,
                A::UNIFORM_READ,
                L::UNDEFINED,
            ),
            AccessKind::VertexInputRead => (
                S::VERTEX_ATTRIBUTE_INPUT | S::INDEX_INPUT,
                A::VERTEX_ATTRIBUTE_READ | A::INDEX_READ,
                L::UNDEFINED,
            ),
            AccessKind::IndirectCommandRead => {
                (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ, L::UNDEFINED)
            }
        };
        AccessInfo {
            stage,
            access,
            layout,
        }
    }

    /// Whether this access writes the resource.
    pub fn is_write(self) -> bool {
        matches!(
            self,
            AccessKind::ColorAttachmentWrite
                | AccessKind::ColorAttachmentLoadWrite
                | AccessKind::DepthStencilWrite
                | AccessKind::DepthStencilResolveWrite
                | AccessKind::ColorResolveWrite
                | AccessKind::ComputeStorageWrite
                | AccessKind::ComputeStorageReadWrite
                | AccessKind::FragmentStorageReadWrite
                | AccessKind::TransferWrite
                | AccessKind::TransferWritePartial
                | AccessKind::ClearWrite
                | AccessKind::HostWrite
        )
    }

    /// Whether this access overwrites the whole resource without reading it, so
    /// the old contents (and layout) may be discarded.
    pub fn discards_contents(self) -> bool {
        matches!(
            self,
            AccessKind::ColorAttachmentWrite
                | AccessKind::DepthStencilWrite
                | AccessKind::DepthStencilResolveWrite
                | AccessKind::ColorResolveWrite
                | AccessKind::ComputeStorageWrite
                | AccessKind::TransferWrite
                | AccessKind::ClearWrite
        )
    }

    /// The image usage this access needs (images are created with the union of
    /// the usages of every access declared on them).
    pub fn image_usage(self) -> vk::ImageUsageFlags {
        type U = vk::ImageUsageFlags;
        match self {
            AccessKind::ColorAttachmentWrite
            | AccessKind::ColorAttachmentLoadWrite
            | AccessKind::ColorResolveWrite => U::COLOR_ATTACHMENT,
            AccessKind::DepthStencilWrite
            | AccessKind::DepthStencilResolveWrite
            | AccessKind::DepthStencilReadOnly => U::DEPTH_STENCIL_ATTACHMENT,
            AccessKind::FragmentSampledRead
            | AccessKind::ComputeSampledRead
            | AccessKind::AnyShaderSampledRead => U::SAMPLED,
            AccessKind::ComputeStorageWrite
            | AccessKind::ComputeStorageRead
            | AccessKind::ComputeStorageReadWrite
            | AccessKind::FragmentStorageRead
            | AccessKind::FragmentStorageReadWrite => U::STORAGE,
            AccessKind::TransferRead => U::TRANSFER_SRC,
            AccessKind::TransferWrite
            | AccessKind::TransferWritePartial
            | AccessKind::ClearWrite => U::TRANSFER_DST,
            AccessKind::Nothing
            | AccessKind::HostRead
            | AccessKind::HostWrite
            | AccessKind::UniformRead
            | AccessKind::VertexInputRead
            | AccessKind::IndirectCommandRead => U::empty(),
        }
    }

    /// The part of the access mask that is a write (what a later barrier must make available).
    fn write_access(self) -> vk::AccessFlags2 {
        let a = self.info().access;
        a & (A::COLOR_ATTACHMENT_WRITE
            | A::DEPTH_STENCIL_ATTACHMENT_WRITE
            | A::SHADER_STORAGE_WRITE
            | A::TRANSFER_WRITE
            | A::HOST_WRITE)
    }
}

/// A planned barrier, before it is bound to a concrete image or buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BarrierPlan {
    pub src_stage: vk::PipelineStageFlags2,
    pub src_access: vk::AccessFlags2,
    pub dst_stage: vk::PipelineStageFlags2,
    pub dst_access: vk::AccessFlags2,
    pub old_layout: vk::ImageLayout,
    pub new_layout: vk::ImageLayout,
}

/// The Vulkan barrier for `plan` on one subresource range of `image`: the one
/// place a plan becomes an `ImageMemoryBarrier2`.
pub fn image_barrier(
    plan: &BarrierPlan,
    image: vk::Image,
    range: vk::ImageSubresourceRange,
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(plan.src_stage)
        .src_access_mask(plan.src_access)
        .dst_stage_mask(plan.dst_stage)
        .dst_access_mask(plan.dst_access)
        .old_layout(plan.old_layout)
        .new_layout(plan.new_layout)
        .image(image)
        .subresource_range(range)
}

/// What the graph remembers of one resource between passes: its layout, the
/// last write, the stages that read it since, and the stages that write has been
/// made visible to. One "last access" is not enough: after a write, reads in two
/// different stages each need the write made visible to them, and the next write
/// must wait for every one of those reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResourceState {
    pub layout: vk::ImageLayout,
    pub last_write: Option<AccessKind>,
    pub read_stages: vk::PipelineStageFlags2,
    pub visible_stages: vk::PipelineStageFlags2,
    fresh: bool,
}

impl Default for ResourceState {
    fn default() -> Self {
        ResourceState {
            layout: L::UNDEFINED,
            last_write: None,
            read_stages: S::NONE,
            visible_stages: S::NONE,
            fresh: true,
        }
    }
}

impl ResourceState {
    /// A resource filled by a finished upload whose last barrier made a transfer
    /// write visible to `access` (and left it in `access`'s layout).
    pub fn uploaded(access: AccessKind) -> Self {
        let i = access.info();
        ResourceState {
            layout: i.layout,
            last_write: Some(AccessKind::TransferWrite),
            read_stages: i.stage,
            visible_stages: i.stage,
            fresh: false,
        }
    }

    /// The barrier `next` needs (if any), and the state after it.
    pub fn plan(&mut self, next: AccessKind, is_image: bool) -> Option<BarrierPlan> {
        let n = next.info();
        let (w_stage, w_access) = match self.last_write {
            Some(w) => (w.info().stage, w.write_access()),
            None => (S::NONE, A::NONE),
        };
        let new_layout = if is_image { n.layout } else { L::UNDEFINED };
        let discard = next.discards_contents() || self.fresh;
        let old_layout = if !is_image || discard {
            L::UNDEFINED
        } else {
            self.layout
        };
        let layout_change = is_image && old_layout != new_layout;
        let plan = if next.is_write() {
            // Wait for every read since the last write (WAR). When those reads were
            // themselves ordered after the write by a barrier, that chain also orders
            // this write after it; otherwise wait for the last write (WAW) directly.
            let (src_stage, src_access) =
                if !self.read_stages.is_empty() && !self.visible_stages.is_empty() {
                    (self.read_stages, A::NONE)
                } else {
                    (w_stage | self.read_stages, w_access)
                };
            (layout_change || !src_stage.is_empty()).then_some(BarrierPlan {
                src_stage,
                src_access,
                dst_stage: n.stage,
                dst_access: n.access,
                old_layout,
                new_layout,
            })
        } else if layout_change
            || (self.last_write.is_some() && !self.visible_stages.contains(n.stage))
        {
            // Make the write visible to this stage; a transition also waits for
            // the reads in the old layout.
            Some(BarrierPlan {
                src_stage: w_stage | self.read_stages,
                src_access: w_access,
                dst_stage: n.stage,
                dst_access: n.access,
                old_layout,
                new_layout,
            })
        } else {
            None
        };
        if next.is_write() {
            *self = ResourceState {
                layout: new_layout,
                last_write: Some(next),
                read_stages: S::NONE,
                visible_stages: S::NONE,
                fresh: false,
            };
        } else {
            if layout_change {
                self.visible_stages = n.stage;
            } else if plan.is_some() {
                self.visible_stages |= n.stage;
            }
            self.layout = new_layout;
            self.read_stages |= n.stage;
            self.fresh = false;
        }
        plan
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [AccessKind; 24] = [
        AccessKind::ColorResolveWrite,
        AccessKind::DepthStencilResolveWrite,
        AccessKind::FragmentStorageReadWrite,
        AccessKind::ClearWrite,
        AccessKind::ComputeStorageReadWrite,
        AccessKind::FragmentStorageRead,
        AccessKind::AnyShaderSampledRead,
        AccessKind::ComputeStorageRead,
        AccessKind::Nothing,
        AccessKind::ColorAttachmentWrite,
        AccessKind::ColorAttachmentLoadWrite,
        AccessKind::DepthStencilWrite,
        AccessKind::DepthStencilReadOnly,
        AccessKind::FragmentSampledRead,
        AccessKind::ComputeSampledRead,
        AccessKind::ComputeStorageWrite,
        AccessKind::TransferRead,
        AccessKind::TransferWrite,
        AccessKind::TransferWritePartial,
        AccessKind::HostRead,
        AccessKind::HostWrite,
        AccessKind::UniformRead,
        AccessKind::VertexInputRead,
        AccessKind::IndirectCommandRead,
    ];

    /// The barrier the renderer's planner emits for `next` on an image whose
    /// history is `before` (each access planned in turn, as the graph does).
    fn image_after(before: &[AccessKind], next: AccessKind) -> Option<BarrierPlan> {
        let mut st = ResourceState::default();
        for &a in before {
            st.plan(a, true);
        }
        st.plan(next, true)
    }

    fn buffer_after(before: &[AccessKind], next: AccessKind) -> Option<BarrierPlan> {
        let mut st = ResourceState::default();
        for &a in before {
            st.plan(a, false);
        }
        st.plan(next, false)
    }

    // A copy into part of an image after it was sampled: the layout moves from
    // the sampled one, not from UNDEFINED, so the texels outside the copy keep.
    #[test]
    fn partial_copy_keeps_the_rest() {
        let written_then_sampled = [
            AccessKind::ColorAttachmentWrite,
            AccessKind::FragmentSampledRead,
        ];
        let b = image_after(&written_then_sampled, AccessKind::TransferWritePartial).unwrap();
        assert_eq!(b.old_layout, L::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(b.new_layout, L::TRANSFER_DST_OPTIMAL);
        let whole = image_after(&written_then_sampled, AccessKind::TransferWrite).unwrap();
        assert_eq!(whole.old_layout, L::UNDEFINED);
    }

    // Khronos synchronization examples: "Render to a colour attachment, then
    // sample it in a fragment shader".
    #[test]
    fn color_write_then_fragment_sample() {
        let b = image_after(
            &[AccessKind::ColorAttachmentWrite],
            AccessKind::FragmentSampledRead,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(b.dst_stage, S::FRAGMENT_SHADER);
        assert_eq!(b.dst_access, A::SHADER_SAMPLED_READ);
        assert_eq!(b.old_layout, L::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(b.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
    }

    // "Render a shadow map (depth), then sample it".
    #[test]
    fn depth_write_then_fragment_sample() {
        let b = image_after(
            &[AccessKind::DepthStencilWrite],
            AccessKind::FragmentSampledRead,
        )
        .unwrap();
        assert_eq!(
            b.src_stage,
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS
        );
        assert_eq!(b.src_access, A::DEPTH_STENCIL_ATTACHMENT_WRITE);
        assert_eq!(b.dst_stage, S::FRAGMENT_SHADER);
        assert_eq!(b.old_layout, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        assert_eq!(b.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
    }

    // "Compute writes a storage image, a fragment shader samples it", and the
    // compute accumulation that reads its own earlier write.
    #[test]
    fn compute_write_then_fragment_sample_and_accumulate() {
        let b = image_after(
            &[AccessKind::ComputeStorageWrite],
            AccessKind::FragmentSampledRead,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::COMPUTE_SHADER);
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.old_layout, L::GENERAL);
        assert_eq!(b.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
        let b = image_after(
            &[AccessKind::ComputeStorageWrite],
            AccessKind::ComputeStorageReadWrite,
        )
        .unwrap();
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(
            b.dst_access,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE
        );
        assert_eq!(b.old_layout, L::GENERAL);
    }

    // Write-after-read: execution dependency only, no access made available.
    #[test]
    fn war_needs_no_src_access() {
        let b = image_after(
            &[
                AccessKind::ColorAttachmentWrite,
                AccessKind::FragmentSampledRead,
            ],
            AccessKind::ColorAttachmentLoadWrite,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::FRAGMENT_SHADER);
        assert_eq!(b.src_access, A::NONE);
        assert_eq!(
            b.dst_access,
            A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE
        );
        assert_eq!(b.old_layout, L::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(b.new_layout, L::COLOR_ATTACHMENT_OPTIMAL);
    }

    // "Write-after-write": two colour writes in a row wait for the first.
    #[test]
    fn waw_waits_for_the_write() {
        let b = image_after(
            &[AccessKind::ColorAttachmentWrite],
            AccessKind::ColorAttachmentLoadWrite,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(b.old_layout, L::COLOR_ATTACHMENT_OPTIMAL);
    }

    // A discarding write may drop the old layout: UNDEFINED avoids a useless
    // transition; the first use of a fresh image starts from UNDEFINED too.
    #[test]
    fn discarding_write_starts_from_undefined() {
        let b = image_after(
            &[
                AccessKind::ColorAttachmentWrite,
                AccessKind::FragmentSampledRead,
            ],
            AccessKind::ColorAttachmentWrite,
        )
        .unwrap();
        assert_eq!(b.old_layout, L::UNDEFINED);
        let b = image_after(&[], AccessKind::FragmentSampledRead).unwrap();
        assert_eq!(b.old_layout, L::UNDEFINED);
    }

    #[test]
    fn read_after_read_same_layout_is_free() {
        let w = AccessKind::ColorAttachmentWrite;
        let r = AccessKind::FragmentSampledRead;
        assert_eq!(image_after(&[w, r], r), None);
        let dw = AccessKind::DepthStencilWrite;
        let dr = AccessKind::DepthStencilReadOnly;
        assert_eq!(image_after(&[dw, dr], dr), None);
        // Different layouts: the transition is a barrier even between reads. It
        // waits for the reads in the old layout and flushes the last write again
        // (availability is idempotent, and the transition itself writes).
        let b = image_after(&[w, r], AccessKind::TransferRead).unwrap();
        assert_eq!(b.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(b.src_stage, S::FRAGMENT_SHADER | S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.new_layout, L::TRANSFER_SRC_OPTIMAL);
    }

    // Geometry pass writes depth+stencil; the SSS passes stencil-test against it.
    #[test]
    fn depth_write_then_stencil_test() {
        let b = image_after(
            &[AccessKind::DepthStencilWrite],
            AccessKind::DepthStencilReadOnly,
        )
        .unwrap();
        assert_eq!(b.src_access, A::DEPTH_STENCIL_ATTACHMENT_WRITE);
        assert_eq!(b.dst_access, A::DEPTH_STENCIL_ATTACHMENT_READ);
        assert_eq!(b.new_layout, L::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
    }

    // `--msaa`: the single-sample depth/stencil the geometry pass resolves
    // into is written in the colour-attachment-output stage (the spec's
    // resolve operations), then stencil-tested by the SSS passes.
    #[test]
    fn depth_resolve_then_stencil_test() {
        let b = image_after(
            &[AccessKind::DepthStencilResolveWrite],
            AccessKind::DepthStencilReadOnly,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(b.dst_access, A::DEPTH_STENCIL_ATTACHMENT_READ);
        assert_eq!(b.old_layout, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
        assert_eq!(b.new_layout, L::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        let c = image_after(
            &[AccessKind::ColorResolveWrite],
            AccessKind::FragmentSampledRead,
        )
        .unwrap();
        assert_eq!(c.src_access, A::COLOR_ATTACHMENT_WRITE);
        assert_eq!(c.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
    }

    // Khronos synchronization examples: "Compute write to storage buffer,
    // Dispatch-indirect read": the compute write made visible to the
    // draw-indirect stage's indirect command read.
    #[test]
    fn compute_write_then_indirect_dispatch_read() {
        let b = buffer_after(
            &[AccessKind::ComputeStorageWrite],
            AccessKind::IndirectCommandRead,
        )
        .unwrap();
        assert_eq!(b.src_stage, S::COMPUTE_SHADER);
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.dst_stage, S::DRAW_INDIRECT);
        assert_eq!(b.dst_access, A::INDIRECT_COMMAND_READ);
        // The next write of the arguments waits for the indirect read.
        let mut st = ResourceState::default();
        st.plan(AccessKind::ComputeStorageWrite, false);
        st.plan(AccessKind::IndirectCommandRead, false);
        let w = st.plan(AccessKind::ComputeStorageWrite, false).unwrap();
        assert_eq!(w.src_stage, S::DRAW_INDIRECT);
        assert_eq!(w.dst_stage, S::COMPUTE_SHADER);
    }

    // "Copy to a buffer, then read it on the host"; reads of a never-written
    // buffer and the first write of a fresh one need nothing.
    #[test]
    fn transfer_write_then_host_read() {
        let b = buffer_after(&[AccessKind::TransferWrite], AccessKind::HostRead).unwrap();
        assert_eq!(b.src_stage, S::COPY);
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
        assert_eq!(b.dst_stage, S::HOST);
        assert_eq!(b.dst_access, A::HOST_READ);
        assert_eq!(b.old_layout, L::UNDEFINED);
        assert_eq!(b.new_layout, L::UNDEFINED);
        assert_eq!(buffer_after(&[], AccessKind::UniformRead), None);
        assert_eq!(buffer_after(&[], AccessKind::TransferWrite), None);
    }

    // A shadow map written once, read by a fragment shader and then by a compute
    // shader: each reader stage needs its own visibility barrier from the write,
    // and the next frame's write waits for both readers.
    #[test]
    fn a_write_is_made_visible_to_every_reader_stage() {
        let mut st = ResourceState::default();
        let b = st.plan(AccessKind::DepthStencilWrite, true).unwrap();
        assert_eq!(b.old_layout, L::UNDEFINED);
        let b = st.plan(AccessKind::FragmentSampledRead, true).unwrap();
        assert_eq!(b.src_access, A::DEPTH_STENCIL_ATTACHMENT_WRITE);
        let b = st
            .plan(AccessKind::ComputeSampledRead, true)
            .expect("compute needs the write made visible too");
        assert_eq!(b.dst_stage, S::COMPUTE_SHADER);
        assert_eq!(b.src_access, A::DEPTH_STENCIL_ATTACHMENT_WRITE);
        assert_eq!(b.old_layout, b.new_layout);
        assert_eq!(st.plan(AccessKind::FragmentSampledRead, true), None);
        assert_eq!(st.plan(AccessKind::ComputeSampledRead, true), None);
        let b = st.plan(AccessKind::DepthStencilWrite, true).unwrap();
        assert!(b.src_stage.contains(S::FRAGMENT_SHADER | S::COMPUTE_SHADER));
        assert_eq!(b.src_access, A::NONE);
    }

    // The separable SSS chain as the frame declares it, two frames in a row:
    // every barrier follows from the previous access, and the second frame starts
    // from the first one's end state.
    #[test]
    fn the_sss_chain_carries_state_across_frames() {
        let (mut diffuse, mut tmp) = (ResourceState::default(), ResourceState::default());
        for frame in 0..2 {
            // geometry writes diffuse
            let b = diffuse
                .plan(AccessKind::ColorAttachmentWrite, true)
                .unwrap();
            assert_eq!(b.old_layout, L::UNDEFINED);
            if frame == 1 {
                // WAR against last frame's composite read: execution dependency only.
                assert_eq!(b.src_stage, S::FRAGMENT_SHADER);
                assert_eq!(b.src_access, A::NONE);
            }
            // seed: copy diffuse -> tmp
            assert!(diffuse.plan(AccessKind::TransferRead, true).is_some());
            assert!(tmp.plan(AccessKind::TransferWrite, true).is_some());
            // horizontal: sample diffuse, write tmp (keeping the seeded texels)
            assert!(diffuse
                .plan(AccessKind::FragmentSampledRead, true)
                .is_some());
            let b = tmp
                .plan(AccessKind::ColorAttachmentLoadWrite, true)
                .unwrap();
            assert_eq!(b.old_layout, L::TRANSFER_DST_OPTIMAL);
            assert_eq!(b.src_access, A::TRANSFER_WRITE);
            // vertical: sample tmp, write back into diffuse
            assert!(tmp.plan(AccessKind::FragmentSampledRead, true).is_some());
            let b = diffuse
                .plan(AccessKind::ColorAttachmentLoadWrite, true)
                .unwrap();
            assert_eq!(b.old_layout, L::SHADER_READ_ONLY_OPTIMAL);
            assert_eq!(b.src_access, A::NONE);
            // composite samples diffuse; a second read in that layout needs nothing
            assert!(diffuse
                .plan(AccessKind::FragmentSampledRead, true)
                .is_some());
            assert!(diffuse
                .plan(AccessKind::FragmentSampledRead, true)
                .is_none());
        }
    }

    #[test]
    fn uploaded_resources_need_visibility_for_new_stages_only() {
        let mut st = ResourceState::uploaded(AccessKind::FragmentSampledRead);
        assert_eq!(st.plan(AccessKind::FragmentSampledRead, true), None);
        let b = st.plan(AccessKind::ComputeSampledRead, true).unwrap();
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
    }

    #[test]
    fn table_is_consistent() {
        for k in ALL {
            let i = k.info();
            // Only writes carry write bits, and every write carries one.
            assert_eq!(k.is_write(), !k.write_access().is_empty(), "{k:?}");
            // A discarding access is a write.
            assert!(!k.discards_contents() || k.is_write(), "{k:?}");
            // No blanket stages or layouts in the table.
            assert!(!i.stage.contains(S::ALL_COMMANDS), "{k:?}");
            assert!(!i.stage.contains(S::ALL_GRAPHICS), "{k:?}");
            // Storage images live in GENERAL; nothing else does.
            if !matches!(
                k,
                AccessKind::ComputeStorageWrite
                    | AccessKind::ComputeStorageRead
                    | AccessKind::ComputeStorageReadWrite
                    | AccessKind::FragmentStorageRead
                    | AccessKind::FragmentStorageReadWrite
            ) {
                assert_ne!(i.layout, L::GENERAL, "{k:?}");
            }
            if k != AccessKind::Nothing {
                assert!(!i.stage.is_empty() && !i.access.is_empty(), "{k:?}");
            }
            // Every access that has an image layout needs an image usage.
            assert_eq!(
                i.layout != L::UNDEFINED,
                !k.image_usage().is_empty(),
                "{k:?}"
            );
        }
    }

    // Every pair of accesses after a write either needs no barrier (two reads
    // in one layout) or gets one that makes exactly the write available, waits
    // in the next access's stage and ends in its layout.
    #[test]
    fn all_pairs_after_a_write_are_well_formed() {
        for p in ALL {
            for n in ALL {
                let writer = AccessKind::ColorAttachmentWrite;
                let history = [writer, p];
                match image_after(&history, n) {
                    Some(b) => {
                        assert_eq!(b.dst_stage, n.info().stage, "{p:?} -> {n:?}");
                        assert_eq!(b.new_layout, n.info().layout, "{p:?} -> {n:?}");
                        let last_write = if p.is_write() { p } else { writer };
                        assert!(
                            b.src_access.is_empty() || b.src_access == last_write.write_access(),
                            "{p:?} -> {n:?}: {:?}",
                            b.src_access
                        );
                    }
                    None => assert!(!n.is_write(), "{p:?} -> {n:?}"),
                }
            }
        }
    }
}
