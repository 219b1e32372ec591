//! What the model prices: a frame's passes as the renderer declared them
//! (role, work, images) with the counts of one run (`record` builds it from a
//! run's report, with the fetch-counting build's counts where there are some).

use serde::{Deserialize, Serialize};

use crate::work::{ImageUse, PassRole, Work};

/// One pass of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassInput {
    pub name: String,
    pub role: PassRole,
    pub work: Work,
    pub images: Vec<ImageUse>,
    /// Shaded fragments (see `record::FRAGMENTS_RULE` for where they come from).
    pub fragments: u64,
    /// Samples that passed the depth/stencil tests (precise occlusion).
    pub samples_passed: u64,
    /// Pixels the pass's triangles cover before the early tests (stencil- or
    /// depth-rejected ones cost the Z rate). `None`: nothing is rejected.
    pub rasterized_pixels: Option<u64>,
    /// Whether the work's fetch counts are the fetch-counting build's
    /// (fetches made / invocations) rather than the declared ones.
    #[serde(default)]
    pub fetches_counted: bool,
    /// GPU time measured for the pass, if the run measured it.
    pub measured_ms: Option<f64>,
}

impl PassInput {
    /// A pass with no counts yet.
    pub fn new(name: &str, role: PassRole, work: Work) -> PassInput {
        PassInput {
            name: name.to_string(),
            role,
            work,
            images: Vec::new(),
            fragments: 0,
            samples_passed: 0,
            rasterized_pixels: None,
            fetches_counted: false,
            measured_ms: None,
        }
    }
}

/// One run's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameInput {
    /// What the frame is (scene, shot, method).
    pub label: String,
    pub width: u32,
    pub height: u32,
    pub passes: Vec<PassInput>,
    /// Where the fragment counts and fetch counts come from (`record`).
    #[serde(default)]
    pub provenance: Vec<String>,
}

/// The rescaling rule, written out for reports.
pub const RESCALE_RULE: &str = "a pass whose render area (draws) or first image (copies, \
clears, dispatches) is the frame's size halved k >= 0 times follows the screen: its \
fragments, samples, rasterised pixels, texels and invocations scale by the pixel ratio \
(w'h')/(wh), its sizes (hence its clears) by w'/w and h'/h and its taps' spread radii by \
h'/h; other passes (shadow maps, \
LUTs) keep their counts; triangle and rectangle counts never scale";

fn follows_screen(w: u32, h: u32, fw: u32, fh: u32) -> bool {
    (0..=12).any(|k| w == fw.div_ceil(1 << k).max(1) && h == fh.div_ceil(1 << k).max(1))
}

impl FrameInput {
    /// Whether a pass's counts follow the screen size (see [`RESCALE_RULE`]).
    pub fn is_screen_sized(&self, p: &PassInput) -> bool {
        let (w, h) = match &p.work {
            Work::Raster { width, height, .. } => (*width, *height),
            _ => match p.images.first() {
                Some(i) => (i.width, i.height),
                // A copy or dispatch that names no image: assume it follows the screen.
                None => return true,
            },
        };
        follows_screen(w, h, self.width, self.height)
    }

    /// The frame at another resolution, by [`RESCALE_RULE`].
    pub fn rescaled(&self, width: u32, height: u32) -> FrameInput {
        if (width, height) == (self.width, self.height) {
            return self.clone();
        }
        let ratio =
            f64::from(width) * f64::from(height) / (f64::from(self.width) * f64::from(self.height));
        let sx = f64::from(width) / f64::from(self.width);
        let sy = f64::from(height) / f64::from(self.height);
        let n = |v: u64| (v as f64 * ratio).round() as u64;
        let sz = |v: u32, s: f64| ((f64::from(v) * s).round() as u32).max(1);
        let passes = self
            .passes
            .iter()
            .map(|p| {
                if !self.is_screen_sized(p) {
                    return p.clone();
                }
                let mut q = p.clone();
                q.fragments = n(p.fragments);
                q.samples_passed = n(p.samples_passed);
                q.rasterized_pixels = p.rasterized_pixels.map(n);
                match &mut q.work {
                    Work::Raster { width, height, .. } => {
                        *width = sz(*width, sx);
                        *height = sz(*height, sy);
                    }
                    Work::Compute { invocations, .. } => *invocations = n(*invocations),
                    Work::Copy { texels, .. } | Work::Clear { texels, .. } => *texels = n(*texels),
                }
                // A kernel's size on screen follows the view's height.
                if let Work::Raster {
                    shader: Some(s), ..
                }
                | Work::Compute { shader: s, .. } = &mut q.work
                {
                    for f in &mut s.fetches {
                        f.spread.iter_mut().for_each(|x| x.radius_px *= sy);
                    }
                }
                for i in &mut q.images {
                    if follows_screen(i.width, i.height, self.width, self.height) {
                        i.width = sz(i.width, sx);
                        i.height = sz(i.height, sy);
                    }
                }
                q
            })
            .collect();
        FrameInput {
            label: self.label.clone(),
            width,
            height,
            passes,
            provenance: self.provenance.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::work::{Format, ImageUseKind};

    fn raster(w: u32, h: u32) -> Work {
        Work::Raster {
            shader: None,
            color: vec![],
            depth_stencil: None,
            width: w,
            height: h,
            triangles: 100,
            msaa: 1,
            clears: vec![],
        }
    }

    #[test]
    fn spread_radii_follow_the_view_height() {
        use crate::work::{Fetch, Filter, ShaderWork, Spread};
        let mut p = PassInput::new("rings", PassRole::Sss, raster(1920, 1080));
        if let Work::Raster { shader, .. } = &mut p.work {
            *shader = Some(ShaderWork {
                fetches: vec![Fetch {
                    texture: "colorTex".into(),
                    format: Format::Rgba16Float,
                    filter: Filter::Bilinear,
                    count: 12.0,
                    exact: true,
                    coherent: false,
                    spread: vec![Spread {
                        share: 1.0,
                        radius_px: 9.0,
                    }],
                }],
                ..Default::default()
            });
        }
        let f = FrameInput {
            label: "t".into(),
            width: 1920,
            height: 1080,
            passes: vec![p],
            provenance: vec![],
        };
        let g = f.rescaled(1280, 720);
        let Work::Raster {
            shader: Some(s), ..
        } = &g.passes[0].work
        else {
            panic!("not a raster pass");
        };
        assert!((s.fetches[0].spread[0].radius_px - 6.0).abs() < 1e-12);
    }

    #[test]
    fn screen_passes_scale_fixed_ones_do_not() {
        let mut shadow = PassInput::new("shadow", PassRole::Shadow, raster(2048, 2048));
        shadow.samples_passed = 1000;
        let mut blur = PassInput::new("blur", PassRole::Sss, raster(1920, 1080));
        blur.fragments = 1_000_000;
        blur.rasterized_pixels = Some(2_000_000);
        let mut mip = PassInput::new("mip 1", PassRole::Sss, raster(960, 540));
        mip.fragments = 518_400;
        let mut copy = PassInput::new(
            "copy",
            PassRole::Sss,
            Work::Copy {
                texels: 2_073_600,
                bytes_per_texel: 8,
                rects: 1,
            },
        );
        copy.images.push(ImageUse {
            image: "diffuse".into(),
            format: Format::Rgba16Float,
            width: 1920,
            height: 1080,
            kind: ImageUseKind::CopySource,
        });
        let f = FrameInput {
            label: "t".into(),
            width: 1920,
            height: 1080,
            passes: vec![shadow, blur, mip, copy],
            provenance: vec![],
        };
        let g = f.rescaled(1280, 720);
        assert_eq!(g.passes[0], f.passes[0]);
        assert_eq!(g.passes[1].fragments, 444_444);
        assert_eq!(g.passes[1].rasterized_pixels, Some(888_889));
        assert!(matches!(
            g.passes[1].work,
            Work::Raster {
                width: 1280,
                height: 720,
                triangles: 100,
                ..
            }
        ));
        assert!(matches!(
            g.passes[2].work,
            Work::Raster {
                width: 640,
                height: 360,
                ..
            }
        ));
        assert!(matches!(
            g.passes[3].work,
            Work::Copy {
                texels: 921_600,
                ..
            }
        ));
        assert_eq!(g.passes[3].images[0].width, 1280);
    }
}
