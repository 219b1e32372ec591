//! What a raster pass declares of each attachment, once: a colour target with
//! its load op and blending, a depth/stencil use (cleared and written, or
//! tested only, with its stencil reference). The access kinds (so barriers and
//! layouts) follow from these; the executor (`pass.rs`) turns them into
//! dynamic rendering and the pass's declared work.

use super::resources::ImageId;
use crate::vk::barrier::AccessKind;

/// How a render pass treats one colour attachment's old contents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// Keep them (blending, partial draws): loaded, so the barrier keeps them too.
    Keep,
    /// Every pixel of the render area is overwritten: the old contents need not be read.
    DontCare,
    /// Cleared to this colour when the pass begins (a clear of the render area
    /// the pass's work counts).
    Clear([f32; 4]),
}

/// A colour attachment: its image, its load op (the store op is STORE: every
/// colour a pass draws is read later; DONT_CARE for a multisampled target the
/// pass resolves, whose samples nothing reads), and whether the draws blend
/// into it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorTarget {
    pub image: ImageId,
    pub load: Load,
    pub blend: bool,
    /// Its contents outlive the pass whatever the load op (a character's map a
    /// later frame may keep): its barrier never discards them.
    pub persistent: bool,
    /// A multisampled target's single-sample image, which the pass resolves
    /// it into (the average of its samples) when it ends (`--msaa`).
    pub resolve: Option<ImageId>,
}

impl ColorTarget {
    pub fn new(image: ImageId, load: Load) -> Self {
        ColorTarget {
            image,
            load,
            blend: false,
            persistent: false,
            resolve: None,
        }
    }

    /// Resolved into `single` when the pass ends (see [`ColorTarget::resolve`]).
    pub fn resolved_into(self, single: ImageId) -> Self {
        ColorTarget {
            resolve: Some(single),
            ..self
        }
    }

    /// The draws blend into it (a read-modify-write: its old contents are kept).
    pub fn blended(self) -> Self {
        ColorTarget {
            blend: true,
            ..self
        }
    }

    /// See [`ColorTarget::persistent`].
    pub fn persistent(self) -> Self {
        ColorTarget {
            persistent: true,
            ..self
        }
    }

    /// The access the load op implies: a loaded or persistent target keeps its
    /// old contents through the barrier, a cleared or overwritten one need not.
    pub fn access(&self) -> AccessKind {
        if self.load == Load::Keep || self.persistent {
            AccessKind::ColorAttachmentLoadWrite
        } else {
            AccessKind::ColorAttachmentWrite
        }
    }
}

/// A depth/stencil attachment and how the pass's draws use it. Its stencil
/// aspect is attached when the image's format has one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthStencil {
    pub image: ImageId,
    /// `Some((depth, stencil))`: cleared to these when the pass begins, and
    /// stored; `None`: loaded for testing only, never written nor stored.
    pub clear: Option<(f32, u32)>,
    pub depth_test: bool,
    pub depth_write: bool,
    /// The stencil test's reference (dynamic state the executor sets before the
    /// record closure); `None`: no stencil test.
    pub stencil_ref: Option<u32>,
    /// Draws write stencil (their reference is set per draw by the closure).
    pub stencil_write: bool,
    /// A multisampled attachment's single-sample image, which the pass
    /// resolves depth and stencil into, both from sample 0, when it ends
    /// (`--msaa`; docs/aa.md, "MSAA with the SSS pipeline").
    pub resolve: Option<ImageId>,
}

impl DepthStencil {
    /// Cleared to `depth` (stencil 0), depth tested and written.
    pub fn cleared(image: ImageId, depth: f32) -> Self {
        DepthStencil {
            image,
            clear: Some((depth, 0)),
            depth_test: true,
            depth_write: true,
            stencil_ref: None,
            stencil_write: false,
            resolve: None,
        }
    }

    /// Resolved into `single` when the pass ends (see [`DepthStencil::resolve`]).
    pub fn resolved_into(self, single: ImageId) -> Self {
        DepthStencil {
            resolve: Some(single),
            ..self
        }
    }

    /// Loaded, tested only (read-only layout), never stored; no test until one
    /// is switched on.
    pub fn test_only(image: ImageId) -> Self {
        DepthStencil {
            image,
            clear: None,
            depth_test: false,
            depth_write: false,
            stencil_ref: None,
            stencil_write: false,
            resolve: None,
        }
    }

    pub fn depth_test(self, on: bool) -> Self {
        DepthStencil {
            depth_test: on,
            ..self
        }
    }

    pub fn depth_write(self, on: bool) -> Self {
        DepthStencil {
            depth_write: on,
            ..self
        }
    }

    /// Tests stencil against `reference` (`None`: no stencil test).
    pub fn stencil_test(self, reference: Option<u32>) -> Self {
        DepthStencil {
            stencil_ref: reference,
            ..self
        }
    }

    pub fn stencil_write(self, on: bool) -> Self {
        DepthStencil {
            stencil_write: on,
            ..self
        }
    }

    pub(super) fn access(&self) -> AccessKind {
        match self.clear {
            Some(_) => AccessKind::DepthStencilWrite,
            None => AccessKind::DepthStencilReadOnly,
        }
    }
}
