//! Which surface points light can diffuse between: only through tissue.
//!
//! The ground truth integrates the diffusion profile over the skin surface in
//! true 3D distances. Taken over every point within reach, it gathers across
//! air wherever the surface folds back on itself: at a closed lip or eyelid
//! seam, the facing surface is as close in 3D as the skin beside, so a fold
//! collects more surface than a flat patch and creates light (measured: output
//! over input 1.63 in red under uniform light at the seams).
//!
//! Light in skin travels below the surface. The straight path between a point
//! `x_o` (normal `n_o`) and a point `x_i` (normal `n_i`) stays on the tissue
//! side when `x_i` lies on or behind the tangent plane of `x_o`, and `x_o` on
//! or behind the tangent plane of `x_i`:
//! - flat skin: both offsets are 0 (in the plane), kept;
//! - convex skin (a nose, a cheek): each point lies behind the other's plane, kept;
//! - a thin part (an ear lit from behind): the far side lies behind the near
//!   side's plane and the normals are opposed, kept: light goes through;
//! - a fold (two lips, an eyelid on the eye): each point lies in front of the
//!   other's plane, in the air between them, dropped.
//!
//! A small tolerance keeps gentle concavities, where the chord dips into the air
//! by a fraction of its length while the light really runs through the tissue
//! below it: the offset may reach [`TISSUE_TOLERANCE`] times the distance. On a
//! concavity of curvature radius R_c a chord of length r sits r^2 / 2R_c in front
//! of the tangent plane, so points out to r = 2 x 0.25 x R_c = R_c / 2 are kept:
//! at r = 5 mm (half the profile's reach) any concavity gentler than a 10 mm
//! radius keeps everything. It is a local test (no marching through a voxelised
//! solid): O(1) per sample pair, so the gather stays as cheap as before; what it
//! cannot see is a straight path leaving and re-entering the body between two
//! points that each see the other on their tissue side (a surface that bulges
//! between them), which skin geometry within 11 mm (the profile's reach) does
//! not produce at folds.
//!
//! The GPU passes run the same test from shaders/tissue.glsl (its one copy,
//! with [`SAME_POINT_MM`] generated from the Rust constant; the tolerance
//! reaches it as a uniform).

/// Largest offset in front of a tangent plane, as a fraction of the distance,
/// that a path may have and still count as through tissue (see the module doc).
pub const TISSUE_TOLERANCE: f32 = 0.25;

/// Distance (mm) under which two points are one (shared with shaders/tissue.glsl
/// through `crate::shader_constants`).
pub use crate::shader_constants::SAME_POINT_MM;

/// Whether light can diffuse from `xi` (normal `ni`) to `xo` (normal `no`)
/// through tissue (see the module doc). Normals are unit, outward; positions
/// in scene units of `mm_per_unit` millimetres. Points closer than
/// [`SAME_POINT_MM`] count as connected.
pub fn through_tissue(
    xo: [f32; 3],
    no: [f32; 3],
    xi: [f32; 3],
    ni: [f32; 3],
    mm_per_unit: f32,
) -> bool {
    let d = [xi[0] - xo[0], xi[1] - xo[1], xi[2] - xo[2]];
    let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if r * mm_per_unit < SAME_POINT_MM {
        return true;
    }
    let lim = TISSUE_TOLERANCE * r;
    let front_of_o = d[0] * no[0] + d[1] * no[1] + d[2] * no[2];
    let front_of_i = -(d[0] * ni[0] + d[1] * ni[1] + d[2] * ni[2]);
    front_of_o <= lim && front_of_i <= lim
}

#[cfg(test)]
mod tests {
    use super::*;

    const UP: [f32; 3] = [0.0, 1.0, 0.0];
    const DOWN: [f32; 3] = [0.0, -1.0, 0.0];

    #[test]
    fn flat_and_convex_skin_connect() {
        // Two points of one plane.
        assert!(through_tissue([0.0; 3], UP, [5.0, 0.0, 0.0], UP, 1.0));
        // A sphere of radius 10 (a nose tip): points 60 degrees apart.
        let a = 60f32.to_radians();
        let p = [10.0 * a.sin(), 10.0 * a.cos(), 0.0];
        let n = [a.sin(), a.cos(), 0.0];
        assert!(through_tissue([0.0, 10.0, 0.0], UP, p, n, 1.0));
        assert!(through_tissue([0.0; 3], UP, [0.0; 3], UP, 1.0));
    }

    #[test]
    fn a_thin_part_transmits_and_a_fold_does_not() {
        // An ear 3 mm thick: front face normal up, back face normal down, 3 mm below.
        assert!(through_tissue([0.0; 3], UP, [1.0, -3.0, 0.0], DOWN, 1.0));
        // Two lips touching at a seam: the upper lip's surface faces down onto
        // the lower lip's, which faces up, 1 mm below: light would cross air.
        assert!(!through_tissue([0.0; 3], DOWN, [2.0, -1.0, 0.0], UP, 1.0));
        // A gentle concavity of radius 40 mm: a point 5 mm along dips 0.3 mm, kept.
        let a = (5.0f32 / 40.0).asin();
        let p = [40.0 * a.sin(), 40.0 - 40.0 * a.cos(), 0.0];
        let n = [-a.sin(), a.cos(), 0.0];
        assert!(through_tissue([0.0; 3], UP, p, n, 1.0));
        // A sharp crease (radius 2 mm) at 3 mm: dropped.
        let a = 1.2f32;
        let p = [2.0 * a.sin(), 2.0 - 2.0 * a.cos(), 0.0];
        let n = [-a.sin(), a.cos(), 0.0];
        assert!(!through_tissue([0.0; 3], UP, p, n, 1.0));
    }
}
