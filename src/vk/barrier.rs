//! The one vocabulary of resource accesses and the one table that maps each to
//! (pipeline stage, access mask, image layout).
//!
//! No call site in dermis writes a stage mask, an access mask or an old layout by
//! hand: passes declare *what* they do with a resource ([`AccessKind`]) and
//! [`plan_image`] / [`plan_buffer`] derive the barrier from the previous and the
//! next access. The rules follow the Khronos synchronization examples and the
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
    /// Depth/stencil attachment loaded for testing only (depth test or stencil test,
    /// no writes): read-only layout, so it could also be sampled at the same time.
    DepthStencilReadOnly,
    /// Sampled (texture fetch) in a fragment shader: colour or depth textures.
    FragmentSampledRead,
    /// Sampled in a compute shader.
    ComputeSampledRead,
    /// Written as a storage image/buffer by a compute shader (whole contents produced).
    ComputeStorageWrite,
    /// Source of a copy.
    TransferRead,
    /// Destination of a copy or clear (whole contents produced).
    TransferWrite,
    /// Read by the host after the GPU is done (buffers only).
    HostRead,
    /// Written by the host before the GPU uses it (buffers only).
    HostWrite,
    /// Read as a uniform buffer by vertex or fragment shaders.
    UniformRead,
    /// Read as vertex/index data by the input assembler.
    VertexInputRead,
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
            AccessKind::ComputeStorageWrite => {
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE, L::GENERAL)
            }
            AccessKind::TransferRead => (S::COPY, A::TRANSFER_READ, L::TRANSFER_SRC_OPTIMAL),
            AccessKind::TransferWrite => (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
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
                | AccessKind::ComputeStorageWrite
                | AccessKind::TransferWrite
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
                | AccessKind::ComputeStorageWrite
                | AccessKind::TransferWrite
        )
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

/// Plans the barrier an image needs between two accesses, or `None` when no
/// barrier is needed (read after read in the same layout).
pub fn plan_image(prev: AccessKind, next: AccessKind) -> Option<BarrierPlan> {
    let p = prev.info();
    let n = next.info();
    let discard = next.discards_contents() || prev == AccessKind::Nothing;
    let old_layout = if discard { L::UNDEFINED } else { p.layout };
    let layout_change = old_layout != n.layout;
    if !prev.is_write() && !next.is_write() && !layout_change {
        return None;
    }
    Some(BarrierPlan {
        src_stage: p.stage,
        // Only writes need to be made available; a read before a write needs only
        // the execution dependency the stage masks give.
        src_access: prev.write_access(),
        dst_stage: n.stage,
        dst_access: n.access,
        old_layout,
        new_layout: n.layout,
    })
}

/// Plans the barrier a buffer needs between two accesses (no layouts).
pub fn plan_buffer(prev: AccessKind, next: AccessKind) -> Option<BarrierPlan> {
    if prev == AccessKind::Nothing || (!prev.is_write() && !next.is_write()) {
        return None;
    }
    let p = prev.info();
    let n = next.info();
    Some(BarrierPlan {
        src_stage: p.stage,
        src_access: prev.write_access(),
        dst_stage: n.stage,
        dst_access: n.access,
        old_layout: L::UNDEFINED,
        new_layout: L::UNDEFINED,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [AccessKind; 14] = [
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
        AccessKind::HostRead,
        AccessKind::HostWrite,
        AccessKind::UniformRead,
        AccessKind::VertexInputRead,
    ];

    // Khronos synchronization examples: "Render to a colour attachment, then sample it
    // in a fragment shader".
    #[test]
    fn color_write_then_fragment_sample() {
        let b = plan_image(
            AccessKind::ColorAttachmentWrite,
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
        let b = plan_image(
            AccessKind::DepthStencilWrite,
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

    // Write-after-read: execution dependency only, no access made available.
    #[test]
    fn war_needs_no_src_access() {
        let b = plan_image(
            AccessKind::FragmentSampledRead,
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

    // A discarding write may drop the old layout: UNDEFINED avoids a useless transition.
    #[test]
    fn discarding_write_starts_from_undefined() {
        let b = plan_image(
            AccessKind::FragmentSampledRead,
            AccessKind::ColorAttachmentWrite,
        )
        .unwrap();
        assert_eq!(b.old_layout, L::UNDEFINED);
        let b = plan_image(AccessKind::Nothing, AccessKind::FragmentSampledRead).unwrap();
        assert_eq!(b.old_layout, L::UNDEFINED);
    }

    #[test]
    fn read_after_read_same_layout_is_free() {
        assert_eq!(
            plan_image(
                AccessKind::FragmentSampledRead,
                AccessKind::FragmentSampledRead
            ),
            None
        );
        assert_eq!(
            plan_image(
                AccessKind::DepthStencilReadOnly,
                AccessKind::DepthStencilReadOnly
            ),
            None
        );
        // Different layouts: the transition is a barrier even between reads.
        let b = plan_image(AccessKind::FragmentSampledRead, AccessKind::TransferRead).unwrap();
        assert_eq!(b.src_access, A::NONE);
        assert_eq!(b.new_layout, L::TRANSFER_SRC_OPTIMAL);
    }

    // Geometry pass writes depth+stencil; the SSS passes stencil-test against it.
    #[test]
    fn depth_write_then_stencil_test() {
        let b = plan_image(
            AccessKind::DepthStencilWrite,
            AccessKind::DepthStencilReadOnly,
        )
        .unwrap();
        assert_eq!(b.src_access, A::DEPTH_STENCIL_ATTACHMENT_WRITE);
        assert_eq!(b.dst_access, A::DEPTH_STENCIL_ATTACHMENT_READ);
        assert_eq!(b.new_layout, L::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
    }

    // "Copy to a buffer, then read it on the host".
    #[test]
    fn transfer_write_then_host_read() {
        let b = plan_buffer(AccessKind::TransferWrite, AccessKind::HostRead).unwrap();
        assert_eq!(b.src_stage, S::COPY);
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
        assert_eq!(b.dst_stage, S::HOST);
        assert_eq!(b.dst_access, A::HOST_READ);
        assert_eq!(
            plan_buffer(AccessKind::UniformRead, AccessKind::UniformRead),
            None
        );
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
            if k != AccessKind::ComputeStorageWrite {
                assert_ne!(i.layout, L::GENERAL, "{k:?}");
            }
            if k != AccessKind::Nothing {
                assert!(!i.stage.is_empty() && !i.access.is_empty(), "{k:?}");
            }
        }
    }

    // Every pair of accesses either needs no barrier or gets one whose source
    // access contains exactly the previous access's writes.
    #[test]
    fn all_pairs_are_well_formed() {
        for p in ALL {
            for n in ALL {
                if let Some(b) = plan_image(p, n) {
                    assert_eq!(b.src_access, p.write_access());
                    assert_eq!(b.dst_stage, n.info().stage);
                    assert_eq!(b.new_layout, n.info().layout);
                } else {
                    assert!(!p.is_write() && !n.is_write());
                }
            }
        }
    }
}
