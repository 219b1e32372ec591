//! The frame's targets: declared once, with the levels and extra targets the
//! SSS method needs; their usage follows from the passes that use them.

use anyhow::{bail, Result};
use ash::vk;

use super::settings::RenderSettings;
use crate::graph::{ImageDesc, Resources};
use crate::method::{FrameTargets, MsaaTargets, Needs};
use crate::vk::context::Context;

/// Diffuse and specular light, the intermediates and the HDR composite.
pub const DIFFUSE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Linear view depth: f32 keeps the depth differences the SSS passes compare.
pub const LINEAR_DEPTH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
pub const SHADOW_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// The albedo of post-scatter texturing: half floats keep the material's
/// albedo (an 8-bit sRGB texture times a linear factor) within 0.05%, where
/// an 8-bit sRGB target would round it again, by up to 1.2% in the darks.
pub const ALBEDO_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

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

/// Refuses `samples` samples per pixel (`--msaa`) when the device cannot
/// render them into every attachment of the geometry pass, in one line that
/// names the counts it can.
pub fn check_msaa(ctx: &Context, samples: u32, formats: &[(vk::Format, bool)]) -> Result<()> {
    let f = &ctx.facts;
    let counts: Vec<String> = f
        .framebuffer_sample_counts
        .iter()
        .map(|n| format!("{n}x"))
        .collect();
    if !f.framebuffer_sample_counts.contains(&samples) {
        bail!(
            "device '{}' cannot render {samples}x MSAA: its framebuffers take {} samples per pixel",
            f.name,
            counts.join(", ")
        );
    }
    for &(format, depth) in formats {
        let usage = if depth {
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
        } else {
            vk::ImageUsageFlags::COLOR_ATTACHMENT
        };
        if !ctx.format_supports_samples(format, usage, samples) {
            bail!(
                "device '{}' cannot render {samples}x MSAA into {format:?} (a geometry-pass target)",
                f.name
            );
        }
    }
    Ok(())
}

/// Declares the frame's targets at the settings' size with what `needs` asks
/// for, and with `--msaa` > 1 the geometry pass's multisampled attachments.
pub fn declare(
    ctx: &Context,
    res: &mut Resources,
    settings: &RenderSettings,
    needs: Needs,
) -> Result<FrameTargets> {
    let extent = vk::Extent2D {
        width: settings.width,
        height: settings.height,
    };
    let (shadow_size, msaa) = (settings.shadow_size, settings.msaa);
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
    // In the order of the 1x frame before `--msaa` (shadow, specular, depth).
    let shadow = res.declare(ImageDesc::new("shadow map", shadow_extent, SHADOW_FORMAT));
    let specular = res.declare(ImageDesc::new("specular", extent, DIFFUSE_FORMAT));
    let depth_stencil = res.declare(ImageDesc::new("depth stencil", extent, ds_format));
    let post_scatter = !settings.texturing.is_pre();
    let albedo = post_scatter.then(|| res.declare(ImageDesc::new("albedo", extent, ALBEDO_FORMAT)));
    let multisampled = if msaa > 1 {
        let mut formats = vec![
            (DIFFUSE_FORMAT, false),
            (LINEAR_DEPTH_FORMAT, false),
            (ds_format, true),
        ];
        if post_scatter {
            formats.push((ALBEDO_FORMAT, false));
        }
        check_msaa(ctx, msaa, &formats)?;
        let mut ms = |name: &str, format| {
            res.declare(
                ImageDesc::new(&format!("{name} {msaa}x"), extent, format).with_samples(msaa),
            )
        };
        Some(MsaaTargets {
            samples: msaa,
            diffuse: ms("diffuse", DIFFUSE_FORMAT),
            specular: ms("specular", DIFFUSE_FORMAT),
            linear_depth: ms("linear depth", LINEAR_DEPTH_FORMAT),
            normals: normals.map(|_| ms("normals", DIFFUSE_FORMAT)),
            albedo: albedo.map(|_| ms("albedo", ALBEDO_FORMAT)),
            depth_stencil: ms("depth stencil", ds_format),
        })
    } else {
        None
    };
    Ok(FrameTargets {
        shadow,
        diffuse,
        specular,
        linear_depth,
        normals,
        albedo,
        depth_stencil,
        hdr: res.declare(ImageDesc::new("hdr", extent, DIFFUSE_FORMAT)),
        ldr: res.declare(ImageDesc::new("ldr", extent, LDR_FORMAT)),
        multisampled,
    })
}

/// The geometry pass's fragment shader: with the normal MRT when a method
/// needs it, and the albedo's with post-scatter texturing.
pub fn geometry_shader(t: &FrameTargets) -> &'static str {
    match (t.normals.is_some(), t.albedo.is_some()) {
        (false, false) => "geometry.frag",
        (true, false) => "geometry_normals.frag",
        (false, true) => "geometry_albedo.frag",
        (true, true) => "geometry_normals_albedo.frag",
    }
}

/// The composite's fragment shader: with post-scatter texturing it
/// multiplies the albedo target in.
pub fn composite_shader(t: &FrameTargets) -> &'static str {
    if t.albedo.is_some() {
        "composite_albedo.frag"
    } else {
        "composite.frag"
    }
}
