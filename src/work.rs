//! What a pass is for and what it costs, declared by the pass itself: its role in
//! the frame and its work per unit (per fragment of a draw, per invocation of a
//! dispatch, per texel of a copy): texture fetches by format and filter,
//! render-target writes by format and blending, depth/stencil use, and an
//! arithmetic estimate. Pure data, carried in every report: bench floors, the SSS
//! totals, readback filtering and the budget model read these declarations;
//! nothing in dermis matches a pass by its name.

use serde::{Deserialize, Serialize};

/// Why a pass is in the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PassRole {
    /// Depth from the key light.
    Shadow,
    /// The scene into the G-buffer-like targets (lighting, specular, depth, stencil).
    Geometry,
    /// Subsurface scattering: every pass an SSS method records (seed copies,
    /// blurs, mip chains, the ground truth's passes).
    Sss,
    /// After SSS: composite, tone map.
    Post,
    /// Copies of targets to the host (captures, dumps): bookkeeping, not frame cost.
    Readback,
    /// Micro-passes that measure the device (bench ceilings).
    Probe,
    /// One-time or test-only work outside the frame (uploads, fills).
    Setup,
}

impl PassRole {
    /// Whether the pass is part of the frame's cost (tables, totals, budgets).
    pub fn is_frame_cost(self) -> bool {
        !matches!(self, PassRole::Readback | PassRole::Probe | PassRole::Setup)
    }
}

/// Texel formats: their names are the work vocabulary, their facts (bytes,
/// aspects, readback decode) the one format table's (`crate::format`).
pub use crate::format::Format;

/// How a fetch filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Filter {
    /// `texelFetch` or a nearest sampler: one texel.
    Point,
    /// A linear sampler on one mip level: four texels weighted.
    Bilinear,
    /// A linear sampler across two mip levels (`textureLod` between levels, or
    /// mipmapped material textures).
    Trilinear,
    /// A depth-compare sampler (hardware 2x2 percentage-closer filtering).
    DepthCompare,
}

/// One kind of texture fetch a unit of work makes, `count` times per invocation
/// (where a shader branches, the count of the path every invocation may take:
/// an upper bound; `exact` says whether it is also the count every invocation makes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fetch {
    /// The shader's texture variable (what the fetch-counting build counts by).
    pub texture: String,
    pub format: Format,
    pub filter: Filter,
    pub count: f64,
    #[serde(default = "yes")]
    pub exact: bool,
    /// Neighbouring invocations fetch neighbouring texels (false: taps rotated
    /// or jittered per pixel, so a pixel's neighbours share no texels and the
    /// texture cache misses; the budget model charges such fetches more).
    #[serde(default = "yes")]
    pub coherent: bool,
    /// How far from their pixel an incoherent fetch's taps land (empty: not
    /// declared, priced as the farthest). Rotated taps a pixel apart share
    /// their bilinear texels with the neighbours' taps; taps several pixels
    /// apart share nothing, so the cache misses grow with the radius
    /// (`budget::units`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spread: Vec<Spread>,
}

impl Fetch {
    /// At most one bilinear fetch of a skin material's RGBA8 texture (level
    /// 0; `exact`: every invocation makes it). Texels are shaded in the
    /// surface's own order, so neighbours fetch neighbours.
    pub fn material(texture: &str, exact: bool) -> Fetch {
        Fetch {
            texture: texture.into(),
            format: Format::Rgba8Unorm,
            filter: Filter::Bilinear,
            count: 1.0,
            exact,
            coherent: true,
            spread: Vec::new(),
        }
    }
}

impl Fetch {
    /// The expression wrinkles' fetches (thesis ch. 8, Listing 8.1): the
    /// wrinkle map and the two zone masks, one bilinear fetch each where a
    /// skin pixel's character weighs a zone (Table 8.2's three memory
    /// accesses), none elsewhere.
    pub fn wrinkles() -> Vec<Fetch> {
        ["wrinkleTex", "wrinkleMask0", "wrinkleMask1"]
            .map(|t| Fetch::material(t, false))
            .to_vec()
    }
}

/// `share` of a pass's invocations tap within about `radius_px` pixels of
/// their own pixel (one character's kernel at its depth: a frame of several
/// characters has one entry per character and ring).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    pub share: f64,
    pub radius_px: f64,
}

impl Spread {
    /// The same taps in at most one entry per quarter octave of radius (the
    /// share-weighted mean radius of each): a crowd's hundreds of skin
    /// clusters in a few entries, shares summing as before.
    pub fn compact(spread: &[Spread]) -> Vec<Spread> {
        let mut bins: Vec<(i32, f64, f64)> = Vec::new();
        for s in spread.iter().filter(|s| s.share > 0.0 && s.radius_px > 0.0) {
            let k = (4.0 * s.radius_px.log2()).floor() as i32;
            match bins.iter_mut().find(|b| b.0 == k) {
                Some(b) => {
                    b.1 += s.share;
                    b.2 += s.share * s.radius_px;
                }
                None => bins.push((k, s.share, s.share * s.radius_px)),
            }
        }
        bins.sort_by_key(|b| b.0);
        bins.into_iter()
            .map(|(_, share, r)| Spread {
                share,
                radius_px: r / share,
            })
            .collect()
    }
}

fn yes() -> bool {
    true
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn one() -> u32 {
    1
}

/// One colour attachment written by every shaded fragment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColorWrite {
    pub format: Format,
    /// Blended (a read-modify-write of the target).
    pub blend: bool,
}

/// How a draw uses its depth/stencil attachment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepthStencilUse {
    pub format: Format,
    pub depth_test: bool,
    pub depth_write: bool,
    pub stencil_test: bool,
    pub stencil_write: bool,
}

/// What one shader invocation does.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ShaderWork {
    /// The shader file this describes (its fetch-counting build and its SPIR-V
    /// are what the declaration is tested against).
    pub shader: String,
    pub fetches: Vec<Fetch>,
    /// Arithmetic instructions executed per invocation (SPIR-V arithmetic, loops
    /// at their trip counts): an estimate, for ALU-bound pricing.
    pub alu: f64,
    /// Bytes read from and written to storage buffers/images per invocation.
    pub storage_read_bytes: f64,
    pub storage_write_bytes: f64,
    /// Bytes of workgroup shared memory every invocation reads or writes
    /// (a compute blur loading its tile and apron; the taps' reads behind
    /// the skin test are not in it, so a floor built on it stays a floor;
    /// 0 in reports from before issue 28, and left out of a report when 0,
    /// so older reports write back as they were).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub shared_bytes: f64,
}

/// The work of a pass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Work {
    /// Draws: `shader` runs per shaded fragment (`None`: depth-only), writing
    /// every colour attachment once.
    Raster {
        shader: Option<ShaderWork>,
        color: Vec<ColorWrite>,
        depth_stencil: Option<DepthStencilUse>,
        /// Render area in pixels.
        width: u32,
        height: u32,
        /// Triangles submitted per frame (3 vertices each; a full-screen pass
        /// draws one per rectangle of its region).
        triangles: u64,
        /// Samples per pixel.
        msaa: u32,
        /// Attachments the pass clears when it begins (load-op clears), by
        /// format: each clear writes the whole render area.
        #[serde(default)]
        clears: Vec<Format>,
    },
    /// Dispatches: `shader` runs `invocations` times per frame.
    Compute {
        shader: ShaderWork,
        invocations: u64,
    },
    /// Image or buffer copies: `texels` texels of `bytes_per_texel` per frame,
    /// in `rects` copy regions (rectangles; a region-limited seed copy has one
    /// per rectangle of the region and destination).
    Copy {
        texels: u64,
        bytes_per_texel: u32,
        #[serde(default = "one")]
        rects: u32,
    },
    /// Clears of `texels` texels of `bytes_per_texel`.
    Clear { texels: u64, bytes_per_texel: u32 },
}

impl Work {
    /// The shader it runs per fragment or per invocation (`None`: a
    /// depth-only draw, a copy or a clear).
    pub fn shader(&self) -> Option<&ShaderWork> {
        match self {
            Work::Raster { shader, .. } => shader.as_ref(),
            Work::Compute { shader, .. } => Some(shader),
            Work::Copy { .. } | Work::Clear { .. } => None,
        }
    }

    pub fn shader_mut(&mut self) -> Option<&mut ShaderWork> {
        match self {
            Work::Raster { shader, .. } => shader.as_mut(),
            Work::Compute { shader, .. } => Some(shader),
            Work::Copy { .. } | Work::Clear { .. } => None,
        }
    }
}

/// How a pass uses one image (derived from its declared access and the image's
/// description; what the budget model needs for render-target footprints and
/// the resolves a later read forces).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImageUseKind {
    /// Sampled or fetched by a shader.
    Sampled,
    /// Colour attachment, old contents discarded.
    ColorTarget,
    /// Colour attachment loaded (or blended): old contents kept.
    ColorTargetLoad,
    /// Depth/stencil attachment written.
    DepthTarget,
    /// Depth/stencil attachment tested only.
    DepthTest,
    /// Single-sample image a multisampled pass resolves into at its end
    /// (`--msaa`): every pixel written once from its samples.
    ResolveTarget,
    /// Storage image or buffer, read and/or written by a shader.
    Storage,
    CopySource,
    CopyDestination,
    /// Read by the host.
    Host,
}

/// One image a pass touches.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageUse {
    pub image: String,
    pub format: Format,
    pub width: u32,
    pub height: u32,
    pub kind: ImageUseKind,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roles_that_cost_frame_time() {
        for r in [
            PassRole::Shadow,
            PassRole::Geometry,
            PassRole::Sss,
            PassRole::Post,
        ] {
            assert!(r.is_frame_cost());
        }
        for r in [PassRole::Readback, PassRole::Probe, PassRole::Setup] {
            assert!(!r.is_frame_cost());
        }
    }

    #[test]
    fn a_compact_spread_keeps_its_shares_and_mean_radius() {
        let spread: Vec<Spread> = (0..200)
            .map(|i| Spread {
                share: 1.0 + (i % 7) as f64,
                radius_px: 0.3 * 1.03f64.powi(i),
            })
            .collect();
        let c = Spread::compact(&spread);
        assert!(c.len() < 40, "{}", c.len());
        let sum = |v: &[Spread], f: &dyn Fn(&Spread) -> f64| v.iter().map(f).sum::<f64>();
        let share = |v: &[Spread]| sum(v, &|s| s.share);
        let moment = |v: &[Spread]| sum(v, &|s| s.share * s.radius_px);
        assert!((share(&c) - share(&spread)).abs() < 1e-9);
        assert!((moment(&c) - moment(&spread)).abs() < 1e-9 * moment(&spread));
        // Every entry stays within its quarter octave: no radius moves more
        // than a factor 2^(1/4) from the taps it stands for.
        for s in &spread {
            let nearest = c
                .iter()
                .map(|x| (x.radius_px / s.radius_px).log2().abs())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest <= 0.25 + 1e-9, "{}", s.radius_px);
        }
        assert!(Spread::compact(&[]).is_empty());
    }

    #[test]
    fn work_round_trips_through_json() {
        let w = Work::Raster {
            shader: Some(ShaderWork {
                fetches: vec![Fetch {
                    texture: "colorTex".into(),
                    format: Format::Rgba16Float,
                    filter: Filter::Bilinear,
                    count: 16.0,
                    exact: true,
                    coherent: true,
                    spread: Vec::new(),
                }],
                alu: 120.0,
                ..Default::default()
            }),
            color: vec![ColorWrite {
                format: Format::Rgba16Float,
                blend: false,
            }],
            depth_stencil: None,
            width: 1280,
            height: 720,
            triangles: 1,
            msaa: 1,
            clears: vec![Format::Rgba16Float],
        };
        let json = serde_json::to_string(&w).unwrap();
        assert!(json.contains("\"kind\":\"raster\""), "{json}");
        assert_eq!(serde_json::from_str::<Work>(&json).unwrap(), w);
        assert_eq!(Format::Rgba16Float.bytes_per_texel(), 8);
        assert!(Format::D24UnormS8Uint.is_depth() && !Format::R32Float.is_depth());
        assert!(Format::D32FloatS8Uint.has_stencil() && !Format::D32Float.has_stencil());
    }

    #[test]
    fn fields_added_later_default_when_absent() {
        // Reports written before `coherent`, `clears` and `rects` existed still read.
        let f: Fetch = serde_json::from_str(
            r#"{"texture":"t","format":"r32-float","filter":"point","count":1.0}"#,
        )
        .unwrap();
        assert!(f.exact && f.coherent);
        let c: Work =
            serde_json::from_str(r#"{"kind":"copy","texels":10,"bytes_per_texel":8}"#).unwrap();
        assert_eq!(
            c,
            Work::Copy {
                texels: 10,
                bytes_per_texel: 8,
                rects: 1
            }
        );
        let r: Work = serde_json::from_str(
            r#"{"kind":"raster","shader":null,"color":[],"depth_stencil":null,"width":4,"height":4,"triangles":2,"msaa":1}"#,
        )
        .unwrap();
        assert!(matches!(r, Work::Raster { clears, .. } if clears.is_empty()));
    }
}
