//! What every CPU mirror of a screen-space SSS pass reads: the frame's diffuse
//! light, its linear depth and its skin mask, one struct for all of them
//! (`separable_mirror`, `ssg_mirror`, `screen_mirror`; the card harness and
//! the GPU tests build it once per image).
//!
//! A mirror repeats a GPU pass operation by operation so that a test can hold
//! the pass to it per pixel; "reference" is kept for the ground truth.

/// The frame a mirror works on (all slices row-major, `width * height`).
#[derive(Clone, Copy, Debug)]
pub struct MirrorInput<'a> {
    pub width: usize,
    pub height: usize,
    /// Diffuse light RGBA (RGBA16F-exact where the GPU's is); alpha is the
    /// per-pixel SSS strength (0 on non-skin).
    pub diffuse: &'a [[f32; 4]],
    /// View depth along the view axis, scene units, > 0 on skin.
    pub linear_depth: &'a [f32],
    /// Stencil skin bit per pixel.
    pub skin: &'a [bool],
}

impl MirrorInput<'_> {
    /// Panics on a size mismatch: a caller bug, not user input.
    pub fn check(&self) {
        let n = self.width * self.height;
        assert!(self.width > 0 && self.height > 0, "empty image");
        assert_eq!(self.diffuse.len(), n, "diffuse size");
        assert_eq!(self.linear_depth.len(), n, "linear_depth size");
        assert_eq!(self.skin.len(), n, "skin mask size");
    }
}
