//! Texture-space diffusion's per-frame passes, per character: the mask pass,
//! the irradiance pass (MRT with the stretch maps), the twelve separable
//! blurs, then one final pass that draws every head.

use ash::vk;

use super::{
    square, uv_max, Cull, Tsd, BLUR_TRIPS, BLUR_U_SHADER, BLUR_V_SHADER, FINAL_SHADER,
    IRRADIANCE_SHADER, MASK_SHADER,
};
use crate::graph::draw::fullscreen;
use crate::graph::work::{Fetch, Filter, PassRole, ShaderWork};
use crate::graph::{ColorTarget, DepthStencil, ImageId, Load, Pass, PassContext};
use crate::method::screen::fetch;
use crate::method::FrameView;
use crate::shader_constants::PCF_TRIPS;
use crate::skin::tsd::{BACKFACE_BIAS, CULL_COS};
use crate::vk::context::Context;
use crate::vk::shader_stats::alu_estimate;

/// Push constants of the UV-space draws (`TsdPush`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct UvPush {
    z: f32,
    threshold: f32,
    keep_above: f32,
}

/// Push constants of tsd_blur.glsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    dir: [f32; 2],
    std_mm: f32,
    inv_size: f32,
    uv_max: f32,
    alpha_test: i32,
}

impl Tsd {
    fn updates(&self, k: usize) -> bool {
        self.updating[k]
    }

    /// Triangles of one draw of the head.
    fn triangles(&self) -> u64 {
        self.mesh.triangles()
    }

    /// Character `k`'s head: its own posed copy in a moving crowd, else
    /// the one mesh.
    fn draw_head(&self, ctx: &Context, cmd: vk::CommandBuffer, k: usize) {
        self.mesh.bind_and_draw_copy(ctx, cmd, k as u32);
    }

    /// The mask as the texture-space passes after the mask pass test it:
    /// depth EQUAL 0 with the z pre-passes, the cull bit with the stencil cull.
    fn mask_test(&self, mask: ImageId) -> DepthStencil {
        let cfg = self.config;
        DepthStencil::test_only(mask)
            .depth_test(cfg.z_prepass)
            .stencil_test((cfg.cull == Cull::Stencil).then_some(1))
    }

    /// The mask pass of character `k`: depth 1 and stencil 0 everywhere, then
    /// (when it is updated) the z pre-passes' draws (depth 0 on the unwrapped
    /// mesh, clipped; depth 1 where it faces away) and the cull mask's
    /// (stencil 1 where it faces the eye within 105 degrees).
    pub(super) fn mask_pass<'a>(&'a self, k: usize) -> Pass<'a> {
        let cfg = self.config;
        let mask = self
            .maps
            .mask
            .expect("masked configurations declare a mask");
        let c = &self.characters[k];
        let draws = 2 * cfg.z_prepass as u64 + (cfg.cull == Cull::Stencil) as u64;
        let work = ShaderWork {
            shader: MASK_SHADER.into(),
            fetches: Vec::new(),
            alu: alu_estimate(MASK_SHADER, &[]),
            ..Default::default()
        };
        let up = self.updates(k);
        let mut pass = Pass::new(format!("tsd mask c{k}"), PassRole::Sss);
        let frame = [0, 1, 2].map(|i| self.sets.frame[i].as_ref().map(|s| pass.set(s)));
        pass.depth_stencil(
            DepthStencil::cleared(mask, 1.0)
                .depth_test(cfg.z_prepass)
                .depth_write(cfg.z_prepass)
                .stencil_write(cfg.cull == Cull::Stencil),
        )
        .render_area(square(c.size))
        .draws(Some(work), self.triangles() * draws)
        .record(move |pc: &PassContext| {
            if !up {
                return;
            }
            let (ctx, cmd) = (pc.ctx, pc.cmd);
            let p = &self.pipelines;
            let c = &self.characters[k];
            if cfg.z_prepass {
                pc.bind(&p.mask_depth, frame[0].as_slice());
                p.mask_depth.bind_sets(ctx, cmd, 2, &[c.uv_sets[0]]);
                p.mask_depth.push(ctx, cmd, &uv_push(0.0, 0.0, 0.0));
                self.draw_head(ctx, cmd, k);
                pc.bind(&p.mask_backface, frame[1].as_slice());
                p.mask_backface.bind_sets(ctx, cmd, 2, &[c.uv_sets[1]]);
                p.mask_backface
                    .push(ctx, cmd, &uv_push(1.0, -BACKFACE_BIAS, 0.0));
                self.draw_head(ctx, cmd, k);
            }
            if cfg.cull == Cull::Stencil {
                pc.bind(&p.mask_cull, frame[2].as_slice());
                p.mask_cull.bind_sets(ctx, cmd, 2, &[c.uv_sets[2]]);
                // Set after the bind: the pre-pass pipelines before it
                // take no dynamic stencil reference.
                unsafe {
                    ctx.device.cmd_set_stencil_reference(
                        cmd,
                        vk::StencilFaceFlags::FRONT_AND_BACK,
                        1,
                    )
                };
                p.mask_cull.push(ctx, cmd, &uv_push(0.0, CULL_COS, 1.0));
                self.draw_head(ctx, cmd, k);
            }
        })
    }

    /// The irradiance pass of character `k` (MRT: irradiance, stretch u, stretch v).
    pub(super) fn irradiance_pass<'a>(&'a self, k: usize, f: &FrameView<'a, '_>) -> Pass<'a> {
        let cfg = self.config;
        let m = self.maps;
        let c = &self.characters[k];
        let culls = cfg.cull == Cull::Alpha;
        let shadow = |filter, count, exact| Fetch {
            exact,
            ..fetch(f.res, self.shadow, "shadowMap", filter, count)
        };
        let mut fetches = vec![
            shadow(Filter::DepthCompare, 9.0, !culls),
            Fetch::material("normalTex", false),
            Fetch::material("albedoTex", !culls),
            shadow(Filter::Point, 1.0, false),
        ];
        if c.wrinkled {
            fetches.extend(Fetch::wrinkles());
        }
        let work = ShaderWork {
            shader: IRRADIANCE_SHADER.into(),
            fetches,
            alu: alu_estimate(IRRADIANCE_SHADER, &PCF_TRIPS),
            ..Default::default()
        };
        // An updated character's maps start cleared (coverage 0 off the mesh).
        let load = if self.updates(k) {
            Load::Clear([0.0; 4])
        } else {
            Load::DontCare
        };
        let mut pass = Pass::new(format!("tsd irradiance c{k}"), PassRole::Sss);
        // The frame's set samples the shadow map.
        let frame = self.sets.frame[3].as_ref().map(|s| pass.set(s));
        pass = pass
            .color(ColorTarget::new(m.irradiance, load))
            .color(ColorTarget::new(m.stretch_u, load))
            .color(ColorTarget::new(m.stretch_v, load));
        if let Some(mask) = m.mask {
            pass = pass.depth_stencil(self.mask_test(mask));
        }
        pass.render_area(square(c.size))
            .draws(Some(work), self.triangles())
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.pipelines.irradiance;
                pc.bind(p, frame.as_slice());
                p.bind_sets(ctx, cmd, 1, &[self.sets.material]);
                p.bind_sets(ctx, cmd, 2, &[self.characters[k].uv_sets[3]]);
                p.push(ctx, cmd, &uv_push(0.0, 0.0, 0.0));
                self.draw_head(ctx, cmd, k);
            })
    }

    /// Gaussian `g`'s pass along u (`v == false`: source -> temp) or v (temp ->
    /// next, and into character `k`'s map) for character `k`.
    pub(super) fn blur_pass<'a>(
        &'a self,
        k: usize,
        g: usize,
        v: bool,
        f: &FrameView<'a, '_>,
    ) -> Pass<'a> {
        let cfg = self.config;
        let m = self.maps;
        let c = &self.characters[k];
        let gauss = self.gaussians[g];
        // G1 reads the irradiance map; the v passes alternate pong, irradiance.
        let (src, dst, stretch, shader) = if v {
            let next = if g % 2 == 0 { m.pong } else { m.irradiance };
            (m.temp, next, m.stretch_v, BLUR_V_SHADER)
        } else {
            let from = if g % 2 == 0 { m.irradiance } else { m.pong };
            (from, m.temp, m.stretch_u, BLUR_U_SHADER)
        };
        let tested = cfg.cull != Cull::Alpha;
        let fetches = vec![
            fetch(f.res, src, "srcTex", Filter::Point, 1.0),
            Fetch {
                exact: tested,
                ..fetch(f.res, stretch, "stretchTex", Filter::Point, 1.0)
            },
            Fetch {
                exact: tested,
                ..fetch(f.res, src, "srcTex", Filter::Bilinear, 6.0)
            },
        ];
        let work = ShaderWork {
            shader: shader.into(),
            fetches,
            alu: alu_estimate(shader, &BLUR_TRIPS),
            ..Default::default()
        };
        // Masked, only texels inside the mask are written: the first Gaussian
        // clears its target (when the character is updated) and later ones keep
        // the zeros outside the mask. Unmasked, every texel is overwritten.
        let up = self.updates(k);
        let masked = cfg.masked();
        let start = if g == 0 && masked && up {
            Load::Clear([0.0; 4])
        } else if g == 0 || !masked {
            Load::DontCare
        } else {
            Load::Keep
        };
        let axis = if v { "v" } else { "u" };
        let mut pass = Pass::new(format!("tsd g{} {axis} c{k}", gauss.index), PassRole::Sss);
        // Reads `src` and `stretch`.
        let set = pass.set(
            &self.sets.blur[if v {
                2
            } else if g % 2 == 0 {
                0
            } else {
                1
            }],
        );
        pass = pass.color(ColorTarget::new(dst, start));
        if v {
            // A character not updated keeps its map. An updated one starts
            // from zeros: the first Gaussian blends with w' = 1, but a NaN in
            // memory nobody wrote would survive a factor of 0.
            let load = if g == 0 && up {
                Load::Clear([0.0; 4])
            } else {
                Load::Keep
            };
            pass = pass.color(ColorTarget::new(c.map, load).blended().persistent());
        }
        if let Some(mask) = m.mask {
            pass = pass.depth_stencil(self.mask_test(mask));
        }
        let push = BlurPush {
            dir: if v { [0.0, 1.0] } else { [1.0, 0.0] },
            std_mm: gauss.std_mm,
            inv_size: 1.0 / cfg.size as f32,
            uv_max: uv_max(c.size, cfg.size),
            alpha_test: (cfg.cull == Cull::Alpha) as i32,
        };
        let blend = gauss.blend;
        let p = if v {
            &self.pipelines.blur_v
        } else {
            &self.pipelines.blur_u
        };
        pass.render_area(square(c.size))
            .draws(Some(work), 1)
            .record(move |pc: &PassContext| {
                fullscreen(pc, p, &[set], |ctx, cmd| {
                    p.push(ctx, cmd, &push);
                    if v {
                        unsafe {
                            ctx.device
                                .cmd_set_blend_constants(cmd, &[blend[0], blend[1], blend[2], 1.0])
                        };
                    }
                })
            })
    }

    /// Every head drawn with the frame's vertex shader, its map's diffuse
    /// written where the geometry pass's depth matches.
    pub(super) fn final_pass<'a>(&'a self, f: &FrameView<'a, '_>) -> Pass<'a> {
        let ds = f.targets.depth_stencil;
        let first_map = self.characters[0].map;
        let work = ShaderWork {
            shader: FINAL_SHADER.into(),
            fetches: vec![
                fetch(f.res, first_map, "mapTex", Filter::Bilinear, 1.0),
                // The strength of the material's per-texel parameters, after
                // the discard where no map is near: at most one a fragment.
                Fetch::material("specTex", false),
            ],
            alu: alu_estimate(FINAL_SHADER, &[]),
            ..Default::default()
        };
        let mut pass = Pass::new("tsd final", PassRole::Sss)
            .color(ColorTarget::new(self.diffuse, Load::Keep).blended())
            .depth_stencil(DepthStencil::test_only(ds).depth_test(true));
        let frame = self.sets.frame[4].as_ref().map(|s| pass.set(s));
        // Each character's set samples its map.
        let maps: Vec<_> = self
            .characters
            .iter()
            .map(|c| pass.set(&c.final_set))
            .collect();
        pass.draws(Some(work), self.triangles() * self.characters.len() as u64)
            .record(move |pc: &PassContext| {
                let (ctx, cmd) = (pc.ctx, pc.cmd);
                let p = &self.pipelines.final_pass;
                pc.bind(p, frame.as_slice());
                p.bind_sets(ctx, cmd, 2, &[self.sets.texel]);
                for (k, (c, &map)) in self.characters.iter().zip(&maps).enumerate() {
                    pc.bind_sets(p, 1, &[map]);
                    p.push(ctx, cmd, &c.model.to_cols_array_2d());
                    self.draw_head(ctx, cmd, k);
                }
            })
    }
}

fn uv_push(z: f32, threshold: f32, keep_above: f32) -> UvPush {
    UvPush {
        z,
        threshold,
        keep_above,
    }
}
