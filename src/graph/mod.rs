//! The pass graph, as render graphs do it: images are *declared* (name, extent,
//! format, levels) before they exist; a pass is a name, a role, its declared work,
//! the resources it reads and writes with their access kinds, and a record
//! closure that records only through the typed references its declaration
//! handed back (`refs.rs`; descriptor sets through [`GraphSet`]). The
//! usage flags every image is created with are derived from the accesses the
//! passes declare, every barrier from the previous and the next access (the one
//! table in `vk::barrier`), batched into one call per pass, and each pass is
//! wrapped in a debug label, timestamps and its queries. A pass declares its
//! attachments with their load ops once ([`ColorTarget`], [`DepthStencil`]):
//! their access kinds, the dynamic rendering around the record closure and the
//! pass's declared work all follow from that declaration.
//!
//! Set-up is therefore in three steps: declare images, build the pass lists once
//! to derive the usages ([`Resources::allow`]), then create the images
//! ([`Resources::create`]) and write the descriptor sets that need their views.

mod attach;
mod context;
pub mod draw;
pub mod mesh;
mod pass;
mod record;
mod refs;
mod resources;
mod set;
/// The pass work vocabulary is pure data (`crate::work`); the graph carries it.
pub use crate::work;

pub use attach::{ColorTarget, DepthStencil, Load};
pub use context::PassContext;
pub use pass::Pass;
pub use record::{record_passes, PassSample};
pub use refs::{BufferRef, ClearDst, ImageRef, SetRef, TransferDst, TransferSrc};
pub use resources::{BufferId, ImageDesc, ImageId, Resources};
pub use set::{Binding, GraphSet, Storage};
