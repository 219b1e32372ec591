//! The post chain after the composite: the bloom (`bloom`, with `--bloom`)
//! on the HDR composite, the tone map (`tonemap`, every
//! frame), then the anti-aliasing stage `--aa`
//! picks (thesis ch. 9-10; issue 17). Each AA stage is a module with its
//! declared images, pipelines and passes, like an SSS method (`crate::method`):
//! it reads the tone-mapped LDR frame (gamma-space luma, as MLAA and FXAA
//! define their edges) and writes a new LDR target that becomes the frame's
//! output image. `--aa none` adds no image, pipeline or pass: the frame is the
//! one it was before the chain existed, bit for bit; so does a frame without
//! `--bloom`.
//!
//! - `bloom`: a Gaussian pyramid on the HDR composite before the tone map
//!   (thesis ch. 3.1, 11.1); its numbers in `bloom_pyramid` (pure).
//! - `tonemap`: Hable's filmic curve, HDR composite -> LDR frame.
//! - `morphological`: the one stage MLAA and SMAA both are (edges writing
//!   the stencil, blending weights where it is set, neighbourhood blending),
//!   its variants given as data and their push constants:
//!   - `mlaa`: Jimenez's MLAA, luma or depth edges, the blend on edge pixels
//!     only after a copy of the frame;
//!   - `smaa`: SMAA 1x (thesis ch. 10.4.1-10.4.2), its presets: edges with
//!     local contrast adaptation, weights with diagonals, accurate searches
//!     and corners, the blend on every pixel.
//! - `fxaa`: FXAA's quality preset, one pass.
//!
//! The device-free parts (area texture, CPU references) live in `crate::aa`.

pub mod bloom;
pub mod bloom_pyramid;
pub mod fxaa;
pub mod mlaa;
pub mod morphological;
pub mod smaa;
pub mod tonemap;

use std::fmt;
use std::str::FromStr;

use anyhow::{bail, Result};
use ash::vk;

use crate::aa::edges::Preset;
use crate::graph::work::{Fetch, Filter};
use crate::graph::{GraphSet, ImageId, Pass, Resources};
use crate::vk::context::Context;
use crate::vk::pipeline::{DescriptorPool, Pipeline, Samplers};
use morphological::Morphological;

/// Which anti-aliasing the frame gets after the tone map (`--aa`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum AaMode {
    /// None: the tone-mapped frame is the output (the frame before issue 17).
    #[default]
    None,
    /// FXAA, quality preset: one full-screen pass.
    Fxaa,
    /// Jimenez's MLAA (thesis ch. 9): luma edges writing the stencil, then
    /// blending weights and neighbourhood blending on edge pixels only.
    Mlaa,
    /// SMAA 1x (thesis ch. 10.4.1-10.4.2), --smaa-preset (default high): edges with
    /// local contrast adaptation, diagonal patterns, accurate searches, sharp corners.
    Smaa,
}

impl AaMode {
    pub const ALL: [AaMode; 4] = [AaMode::None, AaMode::Fxaa, AaMode::Mlaa, AaMode::Smaa];

    /// The name `--aa` takes and reports print.
    pub fn name(self) -> &'static str {
        match self {
            AaMode::None => "none",
            AaMode::Fxaa => "fxaa",
            AaMode::Mlaa => "mlaa",
            AaMode::Smaa => "smaa",
        }
    }

    /// One line for `--help` and the docs.
    pub fn summary(self) -> &'static str {
        match self {
            AaMode::None => "no anti-aliasing: the tone-mapped frame is the output",
            AaMode::Fxaa => "FXAA, quality preset: one full-screen pass on gamma luma",
            AaMode::Mlaa => {
                "Jimenez's MLAA (thesis ch. 9): luma edges + stencil, blending weights, neighbourhood blending"
            }
            AaMode::Smaa => {
                "SMAA 1x (thesis ch. 10.4), --smaa-preset (default high): adapted luma or colour edges + stencil, weights with diagonals and corners, blending"
            }
        }
    }
}

impl fmt::Display for AaMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AaMode {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        match AaMode::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s))
        {
            Some(m) => Ok(m),
            None => bail!(
                "unknown anti-aliasing mode '{s}' (one of: {})",
                AaMode::ALL.map(AaMode::name).join(", ")
            ),
        }
    }
}

/// What MLAA's and SMAA's first pass finds edges in (`--aa-edges`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum EdgeSource {
    /// Luma of the gamma-encoded colour (eq. 9.2, ch. 9.3.1, 10.4.1): both
    /// modes' default.
    #[default]
    Luma,
    /// The frame's linear view depth, 10 mm threshold (MLAA only: ch. 9.3,
    /// Listing 9.1; `aa::edges::MLAA_DEPTH_THRESHOLD_MM`).
    Depth,
    /// The largest R, G or B difference (SMAA only: ch. 10.4.1).
    Color,
}

impl EdgeSource {
    pub const ALL: [EdgeSource; 3] = [EdgeSource::Luma, EdgeSource::Depth, EdgeSource::Color];

    /// The name `--aa-edges` takes and reports print.
    pub fn name(self) -> &'static str {
        match self {
            EdgeSource::Luma => "luma",
            EdgeSource::Depth => "depth",
            EdgeSource::Color => "color",
        }
    }

    /// Whether `mode` offers it.
    pub fn applies_to(self, mode: AaMode) -> bool {
        self.modes().contains(&mode)
    }

    /// The AA modes that offer it.
    fn modes(self) -> &'static [AaMode] {
        match self {
            EdgeSource::Luma => &[AaMode::Mlaa, AaMode::Smaa],
            EdgeSource::Depth => &[AaMode::Mlaa],
            EdgeSource::Color => &[AaMode::Smaa],
        }
    }
}

impl fmt::Display for EdgeSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The post chain's options besides `--aa` (`RenderSettings::post`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(default, deny_unknown_fields)]
pub struct PostOptions {
    /// The bloom on the HDR composite (`--bloom`; off: no bloom image, pipeline or pass).
    pub bloom: bool,
    /// Where MLAA or SMAA find edges (`--aa-edges`); `None`: luma, and a
    /// report that does not name it.
    pub aa_edges: Option<EdgeSource>,
    /// SMAA's preset (`--smaa-preset`); `None`: high, and a report that does
    /// not name it.
    pub smaa_preset: Option<Preset>,
}

impl PostOptions {
    /// The edge source the stage uses.
    pub fn edges(&self) -> EdgeSource {
        self.aa_edges.unwrap_or_default()
    }

    /// SMAA's preset.
    pub fn smaa_preset(&self) -> Preset {
        self.smaa_preset.unwrap_or(smaa::DEFAULT_PRESET)
    }

    /// These options as they apply to `aa`: the edge source where `aa`
    /// offers it, the SMAA preset with SMAA only (a sweep of every mode
    /// applies each option where it applies).
    pub fn for_mode(&self, aa: AaMode) -> PostOptions {
        PostOptions {
            bloom: self.bloom,
            aa_edges: self.aa_edges.filter(|e| e.applies_to(aa)),
            smaa_preset: self.smaa_preset.filter(|_| aa == AaMode::Smaa),
        }
    }

    /// Refuses, in one line, an option that `aa` does not use.
    pub fn check(&self, aa: AaMode) -> Result<()> {
        if let (Some(p), false) = (self.smaa_preset, aa == AaMode::Smaa) {
            bail!(
                "--smaa-preset {} applies to --aa smaa, not to --aa {aa}",
                p.name()
            );
        }
        if let Some(e) = self.aa_edges {
            if !e.modes().contains(&aa) {
                bail!(
                    "--aa-edges {e} applies to --aa {}, not to --aa {aa}",
                    e.modes()
                        .iter()
                        .map(|m| m.name())
                        .collect::<Vec<_>>()
                        .join(" or ")
                );
            }
        }
        Ok(())
    }
}

/// What a stage is built from (images are declared into `res` before they
/// exist, as every frame image is).
pub struct PostSetup<'a> {
    pub ctx: &'a Context,
    pub res: &'a mut Resources,
    /// The HDR composite the tone map reads.
    pub hdr: ImageId,
    /// The exposure the tone map applies (a factor on linear light).
    pub exposure: f32,
    /// The tone-mapped frame the anti-aliasing stage reads.
    pub input: ImageId,
    /// The frame's depth/stencil format (a stencil-culling stage's own
    /// stencil image takes it: the device renders and clears it).
    pub depth_stencil_format: vk::Format,
    /// The chain's options besides the AA mode.
    pub options: PostOptions,
    /// The frame's linear view depth (scene units): MLAA's depth edges read it.
    pub linear_depth: ImageId,
    /// Millimetres per scene unit (the depth threshold is in millimetres).
    pub mm_per_unit: f32,
    /// The frame's samplers (the stages' sets are stated when they are built).
    pub samplers: &'a Samplers,
}

/// What a stage's descriptor sets are written with, once the images exist.
pub struct PostBind<'a> {
    pub ctx: &'a Context,
    pub res: &'a Resources,
    pub pool: &'a DescriptorPool,
}

impl PostBind<'_> {
    /// Writes `set`, made for `pipeline`, from the frame's pool.
    pub fn write(&self, set: &mut GraphSet, pipeline: &Pipeline) -> Result<()> {
        set.write(self.ctx, self.pool, self.res, pipeline)
    }
}

/// One anti-aliasing stage of the chain.
pub trait AaStage {
    /// The stage's passes, in order, reading the tone-mapped frame.
    fn passes<'a>(&'a self, res: &Resources) -> Vec<Pass<'a>>;
    /// The image the stage leaves the anti-aliased frame in (LDR, sRGB).
    fn output(&self) -> ImageId;
    /// Writes the descriptor sets that read frame images.
    fn bind(&mut self, b: &PostBind) -> Result<()>;
    /// The stage's images by name (tests read intermediates back).
    fn images(&self) -> Vec<(&'static str, ImageId)>;
    fn destroy(&mut self, ctx: &Context);
}

/// The chain: the bloom (with `--bloom`), the tone map, then no stage
/// (`--aa none`) or one AA stage.
#[derive(Default)]
pub struct PostChain {
    bloom: Option<bloom::Bloom>,
    tonemap: tonemap::Tonemap,
    aa: Option<Box<dyn AaStage>>,
}

impl PostChain {
    /// The bloom if asked for, the tone map and the stage `mode` names,
    /// images declared and pipelines built. On an error, what was built is
    /// destroyed.
    pub fn new(mode: AaMode, s: &mut PostSetup) -> Result<Self> {
        let ctx = s.ctx;
        let mut chain = crate::vk::guard::Guard::new(ctx, PostChain::default());
        if s.options.bloom {
            chain.bloom = Some(bloom::Bloom::new(ctx, s.res, s.samplers, s.hdr)?);
        }
        // The tone map reads the bloomed composite when there is one.
        let hdr = chain.bloom.as_ref().map_or(s.hdr, bloom::Bloom::output);
        chain.tonemap = tonemap::Tonemap::new(ctx, &*s.res, hdr, s.input, s.exposure)?;
        chain.aa = match mode {
            AaMode::None => None,
            AaMode::Fxaa => Some(Box::new(fxaa::Fxaa::new(s)?)),
            AaMode::Mlaa => Some(Box::new(Morphological::new(
                s,
                Box::new(mlaa::Mlaa::new(s)),
            )?)),
            AaMode::Smaa => Some(Box::new(Morphological::new(
                s,
                Box::new(smaa::Smaa::new(s)),
            )?)),
        };
        Ok(chain.keep())
    }

    /// The bloom stage of the frame's recipe: from the HDR composite `hdr`
    /// to the bloomed composite it hands on (`hdr` itself without `--bloom`).
    pub fn bloom<'a>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        res: &Resources,
        hdr: ImageId,
    ) -> ImageId {
        match &self.bloom {
            Some(b) => {
                debug_assert_eq!(b.input(), hdr, "the bloom reads another image");
                passes.extend(b.passes(res));
                b.output()
            }
            None => hdr,
        }
    }

    /// The tone map stage: from `hdr` to the LDR frame.
    pub fn tonemap<'a>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        res: &Resources,
        hdr: ImageId,
    ) -> ImageId {
        debug_assert_eq!(
            self.tonemap.input(),
            hdr,
            "the tone map reads another image"
        );
        passes.push(self.tonemap.pass(res));
        self.tonemap.output()
    }

    /// The anti-aliasing stage: from the LDR frame `ldr` to the frame's
    /// output (`ldr` itself without a stage).
    pub fn anti_alias<'a>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        res: &Resources,
        ldr: ImageId,
    ) -> ImageId {
        match &self.aa {
            Some(a) => {
                debug_assert_eq!(self.tonemap.output(), ldr, "the stage reads another image");
                passes.extend(a.passes(res));
                a.output()
            }
            None => ldr,
        }
    }

    /// The anti-aliased frame, `None` without a stage.
    pub fn output(&self) -> Option<ImageId> {
        self.aa.as_ref().map(|a| a.output())
    }

    pub fn bind(&mut self, b: &PostBind) -> Result<()> {
        if let Some(bloom) = &mut self.bloom {
            bloom.bind(b)?;
        }
        self.tonemap.bind(b)?;
        match &mut self.aa {
            Some(a) => a.bind(b),
            None => Ok(()),
        }
    }

    /// The stage's image named `name` (see [`AaStage::images`]).
    pub fn image(&self, name: &str) -> Option<ImageId> {
        self.aa
            .as_ref()?
            .images()
            .into_iter()
            .find(|(n, _)| *n == name)
            .map(|(_, id)| id)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(a) = &mut self.aa {
            a.destroy(ctx);
        }
        self.tonemap.destroy(ctx);
        if let Some(b) = &mut self.bloom {
            b.destroy(ctx);
        }
    }
}

impl crate::vk::guard::Destroy for PostChain {
    fn destroy(&mut self, ctx: &Context) {
        PostChain::destroy(self, ctx)
    }
}

/// A coherent fetch of `image` (its texel format from the resources) as a
/// stage's declared work: what the AA passes' weight and blend shaders read.
pub(crate) fn fetch(
    res: &Resources,
    image: ImageId,
    texture: &str,
    filter: Filter,
    count: f64,
    exact: bool,
) -> Fetch {
    Fetch {
        texture: texture.into(),
        format: res.texel_format(image),
        filter,
        count,
        exact,
        coherent: true,
        spread: Vec::new(),
    }
}

/// Two-channel table bytes as RGBA8 texels (.rg; the work vocabulary has no
/// RG8 format yet, docs/aa.md).
pub(crate) fn rg8_as_rgba8(rg: &[u8]) -> Vec<u8> {
    rg.chunks_exact(2)
        .flat_map(|rg| [rg[0], rg[1], 0, 0])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_sources_apply_to_their_modes_only() {
        let with = |e| PostOptions {
            aa_edges: Some(e),
            ..PostOptions::default()
        };
        assert!(PostOptions::default().check(AaMode::Fxaa).is_ok());
        let low = PostOptions {
            smaa_preset: Some(Preset::Low),
            ..PostOptions::default()
        };
        assert!(low.check(AaMode::Smaa).is_ok());
        let e = low.check(AaMode::Mlaa).unwrap_err().to_string();
        assert!(e.contains("--smaa-preset low") && e.contains("mlaa"), "{e}");
        assert_eq!(PostOptions::default().smaa_preset(), Preset::High);
        assert_eq!(PostOptions::default().edges(), EdgeSource::Luma);
        for (e, ok) in [
            (EdgeSource::Luma, [false, false, true, true]),
            (EdgeSource::Depth, [false, false, true, false]),
            (EdgeSource::Color, [false, false, false, true]),
        ] {
            for (m, ok) in AaMode::ALL.into_iter().zip(ok) {
                let r = with(e).check(m);
                assert_eq!(r.is_ok(), ok, "{e} with {m}");
                if let Err(err) = r {
                    let err = err.to_string();
                    assert!(err.contains(e.name()) && !err.contains('\n'), "{err}");
                }
            }
        }
    }

    #[test]
    fn modes_parse_by_name_and_refuse_others_in_one_line() {
        for m in AaMode::ALL {
            assert_eq!(m.name().parse::<AaMode>().unwrap(), m);
            assert_eq!(m.name().to_uppercase().parse::<AaMode>().unwrap(), m);
        }
        let e = "smaa-t2x".parse::<AaMode>().unwrap_err().to_string();
        assert!(
            e.contains("none, fxaa, mlaa, smaa") && !e.contains('\n'),
            "{e}"
        );
        assert_eq!(AaMode::default(), AaMode::None);
    }
}
