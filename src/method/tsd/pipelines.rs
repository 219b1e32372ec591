//! Texture-space diffusion's pipelines: the mask passes' (z pre-passes,
//! stencil cull), the irradiance pass's, the blurs' and the final pass's, each
//! tested against the mask as the configuration asks.

use anyhow::Result;
use ash::vk;

use super::{
    Config, Cull, BLUR_U_SHADER, BLUR_V_SHADER, FINAL_DEPTH_BIAS, FINAL_SHADER, IRRADIANCE_SHADER,
    MAP_FORMAT, MASK_SHADER, STRETCH_FORMAT, UV_VERT,
};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::pipeline::{Blend, GraphicsDesc, Pipeline, VertexInput};

#[derive(Default)]
pub(super) struct Pipelines {
    pub(super) mask_depth: Pipeline,
    pub(super) mask_backface: Pipeline,
    pub(super) mask_cull: Pipeline,
    pub(super) irradiance: Pipeline,
    pub(super) blur_u: Pipeline,
    pub(super) blur_v: Pipeline,
    pub(super) final_pass: Pipeline,
}

impl Pipelines {
    fn all(&mut self) -> [&mut Pipeline; 7] {
        [
            &mut self.mask_depth,
            &mut self.mask_backface,
            &mut self.mask_cull,
            &mut self.irradiance,
            &mut self.blur_u,
            &mut self.blur_v,
            &mut self.final_pass,
        ]
    }
}

impl Destroy for Pipelines {
    fn destroy(&mut self, ctx: &Context) {
        for p in self.all() {
            p.destroy(ctx);
        }
    }
}

/// The method's pipelines; the mask ones only where the configuration uses them.
pub(super) fn make_pipelines(
    ctx: &Context,
    cfg: &Config,
    mask_format: vk::Format,
    diffuse_format: vk::Format,
) -> Result<Pipelines> {
    // On an error, the guard frees the pipelines made so far.
    let mut p = Guard::<Pipelines>::null(ctx);
    fill_pipelines(&mut p, ctx, cfg, mask_format, diffuse_format)?;
    Ok(p.keep())
}

fn uv_desc(name: &str, frag: Option<&'static str>, colors: Vec<vk::Format>) -> GraphicsDesc {
    GraphicsDesc {
        name: name.into(),
        vert: UV_VERT,
        frag,
        color_formats: colors,
        depth_format: None,
        stencil_format: None,
        vertex_input: VertexInput::Mesh,
        // Winding in UV space says nothing about facing.
        cull: vk::CullModeFlags::NONE,
        depth_test: false,
        depth_write: false,
        depth_compare: vk::CompareOp::ALWAYS,
        stencil: None,
        depth_bias: None,
        blend: Blend::None,
    }
}

/// The texture-space passes' test against the mask: depth EQUAL 0 (z
/// pre-passes) and/or the stencil cull bit.
fn masked(mut d: GraphicsDesc, cfg: &Config, mask_format: vk::Format) -> GraphicsDesc {
    if cfg.masked() {
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        if cfg.z_prepass {
            d.depth_test = true;
            d.depth_compare = vk::CompareOp::EQUAL;
        }
        if cfg.cull == Cull::Stencil {
            d.stencil = Some(stencil(vk::CompareOp::EQUAL, vk::StencilOp::KEEP, 0));
        }
    }
    d
}

fn stencil(compare: vk::CompareOp, pass: vk::StencilOp, write_mask: u32) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: compare,
        compare_mask: 1,
        write_mask,
        reference: 1,
    }
}

fn fill_pipelines(
    p: &mut Pipelines,
    ctx: &Context,
    cfg: &Config,
    mask_format: vk::Format,
    diffuse_format: vk::Format,
) -> Result<()> {
    if cfg.z_prepass {
        let mut d = uv_desc("tsd z frustum", None, Vec::new());
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        d.depth_test = true;
        d.depth_write = true;
        p.mask_depth = Pipeline::graphics(ctx, &d)?;
        d.name = "tsd z backface".into();
        d.frag = Some(MASK_SHADER);
        p.mask_backface = Pipeline::graphics(ctx, &d)?;
    }
    if cfg.cull == Cull::Stencil {
        let mut d = uv_desc("tsd cull mask", Some(MASK_SHADER), Vec::new());
        d.depth_format = Some(mask_format);
        d.stencil_format = Some(mask_format);
        d.stencil = Some(stencil(vk::CompareOp::ALWAYS, vk::StencilOp::REPLACE, 1));
        p.mask_cull = Pipeline::graphics(ctx, &d)?;
    }
    let irr = uv_desc(
        "tsd irradiance",
        Some(IRRADIANCE_SHADER),
        vec![MAP_FORMAT, STRETCH_FORMAT, STRETCH_FORMAT],
    );
    p.irradiance = Pipeline::graphics(ctx, &masked(irr, cfg, mask_format))?;
    let blur = |name: &str, frag: &'static str, colors: usize| {
        let mut d = GraphicsDesc::fullscreen(name, frag, MAP_FORMAT);
        d.color_formats = vec![MAP_FORMAT; colors];
        if colors == 2 {
            d.blend = Blend::ConstantMix(1);
        }
        masked(d, cfg, mask_format)
    };
    p.blur_u = Pipeline::graphics(ctx, &blur("tsd blur u", BLUR_U_SHADER, 1))?;
    p.blur_v = Pipeline::graphics(ctx, &blur("tsd blur v", BLUR_V_SHADER, 2))?;
    // The geometry pass's vertex shader on the geometry pass's triangles: the
    // same depths, tested LESS_OR_EQUAL (biased a hair toward the eye), no writes.
    p.final_pass = Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            name: "tsd final".into(),
            vert: "geometry.vert",
            frag: Some(FINAL_SHADER),
            color_formats: vec![diffuse_format],
            depth_format: Some(mask_format),
            stencil_format: Some(mask_format),
            vertex_input: VertexInput::Mesh,
            cull: vk::CullModeFlags::BACK,
            depth_test: true,
            depth_write: false,
            depth_compare: vk::CompareOp::LESS_OR_EQUAL,
            stencil: None,
            depth_bias: Some((FINAL_DEPTH_BIAS, 0.0)),
            // The texel's SSS strength mixes the blurred light with the
            // geometry pass's unblurred light (tsd_final.frag).
            blend: Blend::AlphaMix(0),
        },
    )?;
    Ok(())
}
