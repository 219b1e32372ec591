//! `ss-jittered`: Hable et al.'s jittered 13-tap kernel in screen space ("SS
//! Jittered" of thesis ch. 4): one 2D pass with the centre, a ring of 6 mid
//! samples and a ring of 6 wide red-only samples, rotated per pixel, scaled by
//! the stretch factors of eq. 4.1-4.4. The kernel is `skin::jittered`.

use std::any::Any;

use anyhow::Result;

use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::screen::{declare_intermediate, fetch, masked_pass, seed_copy, source_set, Masked};
use super::ssg::ScreenPush;
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    SssMethod,
};
use crate::graph::work::{Fetch, Filter, Spread};
use crate::graph::{GraphSet, ImageId, Pass};
use crate::skin::jittered::{hable_kernel, JitteredKernel};
use crate::skin::ssg::Stretch;
use crate::vk::context::Context;
use crate::vk::pipeline::{GraphicsDesc, Pipeline};

const SHADER: &str = "jittered.frag";
/// Samples per ring (the loop of the shader takes one mid and one wide per turn).
const RING: u32 = 6;

pub static ENTRY: MethodEntry = MethodEntry {
    name: "ss-jittered",
    aliases: &["jittered"],
    summary: "Hable et al.'s 13-tap jittered kernel in screen space (thesis ch. 4)",
    options: &[],
    eval: &[EvalSetting {
        label: "13 taps",
        options: &[],
    }],
    ground_truth: false,
    dolly: &["13 taps"],
    needs: |_, _| Needs::PLAIN,
    check: |_| Ok(()),
    build: |s| Ok(Box::new(Jittered::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
};

pub struct Jittered {
    pipeline: Pipeline,
    set: GraphSet,
    /// The seed the pass reads (the diffuse target is written).
    src: ImageId,
    diffuse: ImageId,
    pub kernel: JitteredKernel,
    pub stretch: Stretch,
}

impl Jittered {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let diffuse = s.targets.diffuse;
        let src = declare_intermediate(s.res, diffuse, "sss intermediate");
        let mut d = GraphicsDesc::fullscreen("ss-jittered", SHADER, s.res.format(diffuse));
        d.depth_format = Some(s.depth_stencil_format);
        d.stencil_format = Some(s.depth_stencil_format);
        d.stencil = Some(skin_stencil_test());
        let pipeline = Pipeline::graphics(s.ctx, &d)?;
        Ok(Jittered {
            set: source_set(s, &pipeline, src),
            pipeline,
            src,
            diffuse,
            kernel: hable_kernel(),
            stretch: Stretch::for_view(
                s.view.extent.height,
                s.view.camera.fovy_rad,
                s.view.mm_per_unit,
            ),
        })
    }
}

/// Where the ring taps land, per skin cluster `(share, view depth)`: half
/// the taps on the mid ring, half on the wide one, each at its radius in
/// pixels at the cluster's depth (the shader's `s / 3` pixels per mm, at
/// full strength and no depth-gradient shrink), compacted.
fn ring_spread(k: &JitteredKernel, stretch: &Stretch, depths: &[(f64, f32)]) -> Vec<Spread> {
    let all: Vec<Spread> = depths
        .iter()
        .filter(|&&(_, d)| d > 0.0)
        .flat_map(|&(share, depth)| {
            let px_per_mm = f64::from(stretch.alpha / 3.0 / depth);
            [k.mid_radius_mm, k.wide_radius_mm].map(|r| Spread {
                share: share / 2.0,
                radius_px: px_per_mm * f64::from(r),
            })
        })
        .collect();
    Spread::compact(&all)
}

impl SssMethod for Jittered {
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        let extent = f.extent;
        let k = self.kernel;
        let push = ScreenPush {
            texel: [1.0 / extent.width as f32, 1.0 / extent.height as f32],
            alpha: self.stretch.alpha,
            beta: self.stretch.beta,
            gamma: self.stretch.gamma,
            center: [k.center[0], k.center[1], k.center[2], 0.0],
            mid: [k.mid[0], k.mid[1], k.mid[2], 0.0],
            wide: [k.wide[0], k.mid_radius_mm, k.wide_radius_mm, 0.0],
            ..Default::default()
        };
        let (t, src, diffuse, pipeline) = (f.targets, self.src, self.diffuse, &self.pipeline);
        // Centre colour and depth and two depth texels per stretch axis by
        // texel fetch, then both rings bilinear.
        let fetches = vec![
            fetch(f.res, src, "colorTex", Filter::Point, 1.0),
            fetch(f.res, t.linear_depth, "depthTex", Filter::Point, 5.0),
            // Rings rotated per pixel: neighbours share texels only where
            // the rings are about a pixel wide on screen.
            Fetch {
                coherent: false,
                spread: ring_spread(&self.kernel, &self.stretch, f.depths),
                ..fetch(f.res, src, "colorTex", Filter::Bilinear, 2.0 * RING as f64)
            },
        ];
        vec![
            seed_copy("ss-jittered seed copy", f, diffuse, f.region, &[src]),
            masked_pass(
                f,
                Masked {
                    name: "ss-jittered".into(),
                    shader: SHADER,
                    loop_trips: vec![RING],
                    pipeline,
                    set: &self.set,
                    fetches,
                    targets: vec![(diffuse, false)],
                    stencil: true,
                    depth_test: false,
                },
                move |c, cmd| pipeline.push(c, cmd, &push),
            ),
        ]
    }

    fn output(&self) -> ImageId {
        self.diffuse
    }

    /// The wider ring, stretched as the shader does (s / 3 pixels per mm).
    fn reach_px(&self, depth: f32, scale: &ReachScale) -> Option<f32> {
        let ring = self.kernel.mid_radius_mm.max(self.kernel.wide_radius_mm);
        Some(self.stretch.alpha * scale.max_strength / depth * ring / 3.0 + BILINEAR_MARGIN_PX)
    }

    fn bind(&mut self, b: &MethodBind) -> Result<()> {
        b.write(&mut self.set, &self.pipeline)
    }

    fn intermediates(&self) -> Vec<ImageId> {
        vec![self.src]
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "kernel": {
                "center": self.kernel.center, "mid": self.kernel.mid, "wide_red": self.kernel.wide[0],
                "mid_radius_mm": self.kernel.mid_radius_mm, "wide_radius_mm": self.kernel.wide_radius_mm,
            },
            "stretch": { "alpha": self.stretch.alpha, "beta": self.stretch.beta, "gamma": self.stretch.gamma },
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::ViewScale;

    #[test]
    fn ring_taps_land_at_the_rings_radius_on_screen() {
        // 720 rows, 20 degrees, a 230 mm head one unit tall: the view's own
        // pixels per mm at each depth, times the ring radii.
        let (h, fovy, mm) = (720, 20f32.to_radians(), 230.0);
        let k = hable_kernel();
        let stretch = Stretch::for_view(h, fovy, mm);
        let view = ViewScale::new(h, fovy, mm);
        let s = ring_spread(&k, &stretch, &[(0.25, 2.0), (0.75, 8.0)]);
        let expect = [
            (0.375, view.px_per_mm(8.0) * k.mid_radius_mm),
            (0.375, view.px_per_mm(8.0) * k.wide_radius_mm),
            (0.125, view.px_per_mm(2.0) * k.mid_radius_mm),
            (0.125, view.px_per_mm(2.0) * k.wide_radius_mm),
        ];
        assert_eq!(s.len(), 4);
        for (got, (share, r)) in s.iter().zip(expect) {
            assert!((got.share - share).abs() < 1e-12);
            assert!(
                (got.radius_px / f64::from(r) - 1.0).abs() < 1e-5,
                "{got:?} vs {r}"
            );
        }
    }
}
