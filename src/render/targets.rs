//! The frame's targets: declared once, with the levels and extra targets the
//! SSS method needs; their usage follows from the passes that use them.

use anyhow::{bail, Result};
use ash::vk;

use crate::graph::{ImageDesc, Resources};
use crate::method::{FrameTargets, Needs};
use crate::vk::context::Context;

/// Diffuse and specular light, the intermediates and the HDR composite.
pub const DIFFUSE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Linear view depth: f32 keeps the depth differences the SSS passes compare.
pub const LINEAR_DEPTH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
pub const SHADOW_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// The first depth/stencil format the device can render and copy.
pub fn depth_stencil_format(ctx: &Context) -> Result<vk::Format> {
    for f in [
        vk::Format::D32_SFLOAT_S8_UINT,
        vk::Format::D24_UNORM_S8_UINT,
    ] {
        if ctx.format_supports(
            f,
            vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
                | vk::FormatFeatureFlags::TRANSFER_SRC
                | vk::FormatFeatureFlags::TRANSFER_DST,
        ) {
            return Ok(f);
        }
    }
    bail!(
        "device '{}' supports no depth/stencil format dermis can use (D32S8 or D24S8)",
        ctx.facts.name
    )
}

/// Declares the frame's targets at `extent` with what `needs` asks for.
pub fn declare(
    ctx: &Context,
    res: &mut Resources,
    extent: vk::Extent2D,
    shadow_size: u32,
    needs: Needs,
) -> Result<FrameTargets> {
    if !ctx.format_supports(
        LINEAR_DEPTH_FORMAT,
        vk::FormatFeatureFlags::COLOR_ATTACHMENT
            | vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR,
    ) {
        bail!(
            "device '{}' cannot render to and linearly filter R32_SFLOAT (linear depth)",
            ctx.facts.name
        );
    }
    let ds_format = depth_stencil_format(ctx)?;
    let levels = needs.mip_levels;
    let normals = needs.normals.then(|| {
        res.declare(ImageDesc::new("normals", extent, DIFFUSE_FORMAT).with_levels(levels))
    });
    let diffuse =
        res.declare(ImageDesc::new("diffuse", extent, DIFFUSE_FORMAT).with_levels(levels));
    let linear_depth = res
        .declare(ImageDesc::new("linear depth", extent, LINEAR_DEPTH_FORMAT).with_levels(levels));
    let shadow_extent = vk::Extent2D {
        width: shadow_size,
        height: shadow_size,
    };
    Ok(FrameTargets {
        shadow: res.declare(ImageDesc::new("shadow map", shadow_extent, SHADOW_FORMAT)),
        diffuse,
        specular: res.declare(ImageDesc::new("specular", extent, DIFFUSE_FORMAT)),
        linear_depth,
        normals,
        depth_stencil: res.declare(ImageDesc::new("depth stencil", extent, ds_format)),
        hdr: res.declare(ImageDesc::new("hdr", extent, DIFFUSE_FORMAT)),
        ldr: res.declare(ImageDesc::new("ldr", extent, LDR_FORMAT)),
    })
}
