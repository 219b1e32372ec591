//! The glTF loader's checks on values (finite attributes, texture coordinates a
//! sampler can address, precision left in the file, one texture-coordinate set)
//! and the labels its errors name elements by.

use anyhow::{bail, Result};
use glam::Vec3;
use gltf::mesh::Mode;

use crate::scene::gltf_source::short;

/// A primitive spanning fewer than this many f32 steps at its coordinates' magnitude
/// has lost its shape in the file itself (a head stored at 1e7, where f32 steps are one
/// unit): refused rather than drawn as a few points.
pub(super) const MIN_STEPS: f32 = 16.0;

pub(super) fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

pub(super) fn mesh_label(mesh: &gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh '{}'", short(n)),
        None => format!("mesh #{}", mesh.index()),
    }
}

pub(super) fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(n) => format!("node {} '{}'", node.index(), short(n)),
        None => format!("node {}", node.index()),
    }
}

/// Largest texture coordinate dermis samples with: at 2^24 an f32 keeps no
/// fraction to address a texel, and far beyond it the sampler's own arithmetic
/// (coordinate x texture size, the derivatives between pixels) overflows to
/// infinity and filters NaN into the frame (found by the fuzzer: a coordinate
/// accessor misread four bytes off gave 5e36).
pub(super) const MAX_TEXCOORD: f32 = 16_777_216.0;

/// A texture coordinate too large to sample, as an error naming it.
pub(super) fn check_texcoord_range(values: &[[f32; 2]], what: &str) -> Result<()> {
    if let Some(i) = values
        .iter()
        .position(|v| v.iter().any(|c| c.abs() >= MAX_TEXCOORD))
    {
        let [u, v] = values[i];
        bail!(
            "{what} of vertex {i} is ({u:e}, {v:e}): beyond {MAX_TEXCOORD:e} a coordinate has no fraction left to address a texel"
        );
    }
    Ok(())
}

/// The first non-finite value of an attribute, as an error naming it.
pub(super) fn check_finite<const N: usize>(values: &[[f32; N]], what: &str) -> Result<()> {
    if let Some(i) = values.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
        bail!(
            "{what} of vertex {i} is not finite ({})",
            values[i]
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

/// A primitive whose positions span fewer than [`MIN_STEPS`] f32 steps at their
/// magnitude: the shape was lost when the file was written.
pub(super) fn check_precision(positions: &[[f32; 3]], label: &str) -> Result<()> {
    // Precision lost in the file itself: a shape a few f32 steps wide is noise.
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p))),
    );
    let magnitude = lo.abs().max(hi.abs()).max_element();
    let extent = (hi - lo).max_element();
    let step = magnitude * f32::EPSILON;
    if extent > 0.0 && extent < MIN_STEPS * step {
        bail!(
        "{label}: POSITION values reach {magnitude:e} but span only {extent:e}, fewer than {MIN_STEPS} f32 steps ({step:e}) there: the shape was lost when the file was written (move the model near the origin before export)"
    );
    }
    Ok(())
}

/// Texture coordinates of a material's texture other than TEXCOORD_0 cannot be
/// honoured (the vertex format has one set).
pub(super) fn check_tex_coord(set: u32, what: &str) -> Result<()> {
    if set != 0 {
        bail!("the {what} texture uses TEXCOORD_{set}; dermis reads only TEXCOORD_0");
    }
    Ok(())
}
