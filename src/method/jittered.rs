//! `ss-jittered`: Hable et al.'s jittered 13-tap kernel in screen space ("SS
//! Jittered" of thesis ch. 4): one 2D pass with the centre, a ring of 6 mid
//! samples and a ring of 6 wide red-only samples, rotated per pixel, scaled by
//! the stretch factors of eq. 4.1-4.4. The kernel is `skin::jittered`.

use std::any::Any;

use anyhow::Result;

use super::path::{self, Path};
use super::region::{ReachScale, BILINEAR_MARGIN_PX};
use super::screen::{declare_intermediate, fetch, masked_pass, seed_copy, source_set, Masked};
use super::ssg::ScreenPush;
use super::tiles::SkinTiles;
use super::{
    skin_stencil_test, EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs,
    SssMethod,
};
use crate::graph::work::{Fetch, Filter, ShaderWork, Spread};
use crate::graph::{Binding, GraphSet, ImageId, Pass, Storage};
use crate::skin::jittered::{hable_kernel, JitteredKernel};
use crate::skin::ssg::Stretch;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::pipeline::{Bind, GraphicsDesc, Pipeline};
use crate::vk::shader_stats::alu_estimate;

const SHADER: &str = "jittered.frag";
const COMPUTE_SHADER: &str = "jittered_tiles.comp";
/// Samples per ring (the loop of the shader takes one mid and one wide per turn).
const RING: u32 = 6;

pub static ENTRY: MethodEntry = MethodEntry {
    name: "ss-jittered",
    aliases: &["jittered"],
    summary: "Hable et al.'s 13-tap jittered kernel in screen space (thesis ch. 4)",
    options: &[path::OPTION],
    eval: &[EvalSetting {
        label: "13 taps",
        options: &[],
    }],
    ground_truth: false,
    dolly: &["13 taps"],
    needs: |_, _| Needs::PLAIN,
    check: |o| o.parse::<Path>("path").map(|_| ()),
    build: |s| Ok(Box::new(Jittered::new(s)?)),
    no_msaa: None,
    no_mix: |_| None,
    no_sss: false,
    poses_once: None,
};

pub struct Jittered {
    pipeline: Pipeline,
    set: GraphSet,
    /// The seed the pass reads (the diffuse target is written); on the
    /// compute path, the blur's output at skin pixels (the pass reads the
    /// diffuse target, and `sss merge` writes these pixels back into it).
    src: ImageId,
    /// The compute path's tile list and merge (`pipeline` and `set` are
    /// then the compute blur's).
    tiles: Option<SkinTiles>,
    diffuse: ImageId,
    pub kernel: JitteredKernel,
    pub stretch: Stretch,
}

impl Jittered {
    fn new(s: &mut MethodSetup) -> Result<Self> {
        let diffuse = s.targets.diffuse;
        let src = declare_intermediate(s.res, diffuse, "sss intermediate");
        let path: Path = s.options.parse("path")?;
        let (pipeline, set, tiles) = match path {
            Path::Fragment => {
                let mut d = GraphicsDesc::fullscreen("ss-jittered", SHADER, s.res.format(diffuse));
                d.depth_format = Some(s.depth_stencil_format);
                d.stencil_format = Some(s.depth_stencil_format);
                d.stencil = Some(skin_stencil_test());
                let pipeline = Pipeline::graphics(s.ctx, &d)?;
                let set = source_set(s, &pipeline, src);
                (pipeline, set, None)
            }
            Path::Compute => {
                // Guarded until the method holds them: an error frees what exists.
                let pipeline = Guard::new(
                    s.ctx,
                    Pipeline::compute(s.ctx, "ss-jittered", COMPUTE_SHADER)?,
                );
                let mut tiles = Guard::new(s.ctx, SkinTiles::new(s)?);
                tiles.add_merge(s, src, diffuse)?;
                let set = GraphSet::new(
                    s.res,
                    &pipeline,
                    0,
                    vec![
                        ("colorTex", Binding::Sampled(diffuse)),
                        ("depthTex", Binding::Sampled(s.targets.linear_depth)),
                        (
                            "linearClamp",
                            Binding::Fixed(Bind::Sampler(s.samplers.linear_clamp)),
                        ),
                        (
                            "stencilTex",
                            Binding::SampledStencil(s.targets.depth_stencil),
                        ),
                        ("Tiles", tiles.list_binding(Storage::Read, 0)),
                        ("outImage", Binding::StorageImage(src, Storage::Write)),
                    ],
                );
                (pipeline.keep(), set, Some(tiles.keep()))
            }
        };
        Ok(Jittered {
            set,
            pipeline,
            src,
            tiles,
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

impl Jittered {
    /// The compute path's passes: the tile list, the blur over it into the
    /// intermediate, the merge back into the diffuse target.
    fn compute_passes<'a>(
        &'a self,
        f: &FrameView<'a, '_>,
        tiles: &'a SkinTiles,
        push: ScreenPush,
    ) -> Vec<Pass<'a>> {
        let t = f.targets;
        let push = ScreenPush {
            code: f.stencil,
            ..push
        };
        let fetches = vec![
            fetch(f.res, t.diffuse, "colorTex", Filter::Point, 1.0),
            fetch(f.res, t.linear_depth, "depthTex", Filter::Point, 5.0),
            Fetch {
                coherent: false,
                spread: ring_spread(&self.kernel, &self.stretch, f.depths),
                ..fetch(
                    f.res,
                    t.diffuse,
                    "colorTex",
                    Filter::Bilinear,
                    2.0 * RING as f64,
                )
            },
            fetch(f.res, t.depth_stencil, "stencilTex", Filter::Point, 1.0),
        ];
        // Invocations outside the image or the skin fetch nothing.
        let fetches = fetches
            .into_iter()
            .map(|f| Fetch { exact: false, ..f })
            .collect();
        let work = ShaderWork {
            shader: COMPUTE_SHADER.into(),
            fetches,
            alu: alu_estimate(COMPUTE_SHADER, &[RING]),
            storage_read_bytes: 4.0 / super::tiles::TILE_INVOCATIONS as f64,
            storage_write_bytes: 8.0,
            shared_bytes: 0.0,
        };
        let blur = tiles.pass("ss-jittered", f, 0, work, &self.pipeline, &self.set, push);
        let mut passes: Vec<Pass<'a>> = tiles.passes(f).into();
        passes.push(blur);
        passes.extend(tiles.merge_pass(f));
        passes
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
        if let Some(tiles) = &self.tiles {
            return self.compute_passes(f, tiles, push);
        }
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
        b.write(&mut self.set, &self.pipeline)?;
        if let Some(t) = &mut self.tiles {
            t.bind(b)?;
        }
        Ok(())
    }

    fn intermediates(&self) -> Vec<ImageId> {
        match self.tiles {
            None => vec![self.src],
            // Only written and read at skin pixels.
            Some(_) => Vec::new(),
        }
    }

    fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "kernel": {
                "center": self.kernel.center, "mid": self.kernel.mid, "wide_red": self.kernel.wide[0],
                "mid_radius_mm": self.kernel.mid_radius_mm, "wide_radius_mm": self.kernel.wide_radius_mm,
            },
            "stretch": { "alpha": self.stretch.alpha, "beta": self.stretch.beta, "gamma": self.stretch.gamma },
            "path": if self.tiles.is_some() { Path::Compute } else { Path::Fragment }.name(),
        })
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.tiles.destroy(ctx);
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
