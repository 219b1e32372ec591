//! The access-kind table's tests, without a GPU, against the Khronos
//! synchronization examples (each test names its example): `vk/barrier.rs`'s
//! own, in a file of their own as the table grew past 800 lines with them.
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

// A layout transition is a write (synchronization validation's
// SYNC_IMAGE_LAYOUT_TRANSITION): an image never written, moved into the
// sampled layout for the fragment stage, then sampled by a compute shader,
// needs the compute read ordered after the transition (the chain through the
// fragment reads); a second fragment read does not.
#[test]
fn a_transition_for_one_stage_is_ordered_before_reads_in_another() {
    let f = AccessKind::FragmentSampledRead;
    let c = AccessKind::ComputeSampledRead;
    assert_eq!(image_after(&[f], f), None);
    let b = image_after(&[f], c).expect("the compute read waits");
    assert_eq!(b.src_stage, S::FRAGMENT_SHADER);
    assert_eq!(b.src_access, A::NONE);
    assert_eq!(b.dst_stage, S::COMPUTE_SHADER);
    assert_eq!(
        (b.old_layout, b.new_layout),
        (L::SHADER_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL)
    );
    // Once both stages have seen it, reads in either are free.
    assert_eq!(image_after(&[f, c], f), None);
    assert_eq!(image_after(&[f, c], c), None);
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
