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
            || ((self.last_write.is_some() || !self.visible_stages.is_empty())
                && !self.visible_stages.contains(n.stage))
        {
            // Make the write visible to this stage; a transition also waits for
            // the reads in the old layout. A layout transition is a write too:
            // an image never written but moved into a read layout for one
            // stage (visible there) is ordered before a read in another (the
            // barrier waits on the first reads, which waited on it).
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
#[path = "barrier_tests.rs"]
mod tests;
