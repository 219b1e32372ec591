//! The skin-SSS cost of a method setting per character (issue 16, item 3):
//! the budget model's pass costs (`budget::model::price_frame`, so the
//! planner's costs are `dermis budget`'s) split by what each character puts
//! into each pass, plus the fixed per-pass costs a group of characters shares.
//!
//! Where the per-unit work comes from: the stored frames of
//! `profiles/frames/plan/` (`tools/plan_frames.sh`): every eval setting of
//! every method rendered with one character (the Lee Perry-Smith head) at six
//! camera distances on lavapipe with the fetch-counting build, so each pass's
//! declared work, counted fetches and exact counts (shaded fragments, samples
//! passed, rasterised pixels, rectangles, copied texels). Each SSS pass of a
//! setting is read as one of:
//! - **shared** (its render area follows the screen: one pass per group): each
//!   count is either fixed (a full-screen pass, a full-image copy, a
//!   full-screen stencil rejection) or per character: fragments and samples
//!   per skin pixel, rasterised pixels and copied texels per region pixel,
//!   triangles per region rectangle (one draw per rectangle) or per character
//!   (a pass that draws every head's mesh). The ratios are those of the
//!   stored frames, interpolated in ln(px/mm) between the two bracketing
//!   distances (clamped beyond them), so depth-dependent work (the sum of
//!   Gaussians' depth LOD skipping a narrow Gaussian, Poisson's tap count by
//!   screen radius) follows the character's scale;
//! - **per character** (texture space: its render area is a map's, one pass
//!   per character): the whole pass, fixed cost included, is the character's,
//!   its counts interpolated the same way (depth-sized maps shrink with it).
//!
//! The character's skin pixels and region (pixels, rectangles) are counted in
//! the reference setting's terms (the registry's default method at its default
//! options): a setting's own region is the reference's times the ratio of the
//! two settings' stored regions at that scale.
//!
//! **The split.** A group's cost is `price_frame` of a frame holding the
//! template's shadow, geometry and post passes (the eDRAM transfers of the SSS
//! passes depend on them) and the group's SSS passes with every character's
//! counts summed: `total`. `fixed` is the same frame with no character;
//! a character's `part` is the frame with it alone, less `fixed`. Every unit
//! time of the combining rule is linear in the counts and a pass takes the max
//! of its shading units, and the max of sums is at most the sum of maxes, so
//! `fixed + sum(parts) >= total`: the parts are an upper bound, with one
//! exception the budget model makes (a depth-tested pass that passes no
//! sample is rejected at the cheaper hierarchical-Z rate, so a character
//! whose depth LOD skips a pass is cheaper alone than in a group). Measured
//! on the 16-character crowd over every profile and setting
//! (`tests/suite/plan.rs`): `fixed + sum(parts)` is within -5.2% and +6.0%
//! of `total`. Pure: no device.

use serde::Serialize;

use crate::budget::input::{FrameInput, PassInput};
use crate::budget::model::{price_frame, Rescale};
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;
use crate::work::{PassRole, Spread, Work};

use super::log_interp::{bracket, lerp};

/// One stored frame of a setting: one character at a known scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Pixels per millimetre at the character's depth.
    pub px_per_mm: f64,
    pub frame: FrameInput,
}

/// What one character puts into a frame, in the reference setting's terms.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CharacterLoad {
    pub px_per_mm: f64,
    /// Skin pixels (the samples a stencil-tested SSS pass passes).
    pub skin_pixels: f64,
    /// The SSS region of the reference setting: pixels and rectangles.
    pub region_pixels: f64,
    pub region_rects: f64,
}

/// The reference counts of one stored frame: its skin pixels and region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    pub skin: f64,
    pub region: f64,
    pub rects: f64,
}

/// The reference counts of a frame: the stencil-tested SSS draw that passes
/// the most samples (its samples are the skin pixels, its rasterised pixels
/// the region, its triangles the rectangles: one per rectangle).
pub fn reference_counts(f: &FrameInput) -> Option<Reference> {
    f.passes
        .iter()
        .filter(|p| p.role == PassRole::Sss)
        .filter_map(|p| match &p.work {
            Work::Raster {
                depth_stencil: Some(ds),
                triangles,
                ..
            } if ds.stencil_test => Some((p, *triangles)),
            _ => None,
        })
        .max_by_key(|(p, _)| p.samples_passed)
        .and_then(|(p, t)| {
            Some(Reference {
                skin: p.samples_passed as f64,
                region: p.rasterized_pixels? as f64,
                rects: t as f64,
            })
        })
        .filter(|r| r.skin > 0.0 && r.region > 0.0 && r.rects > 0.0)
}

/// How one count of a shared pass grows with the characters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Per {
    Fixed,
    Skin,
    Region,
    Rects,
    Character,
}

/// How a setting's pass is priced in a group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PassKind {
    /// Not an SSS pass: the frame around the group (kept for the transfers).
    Context,
    /// One pass per group. `shade`: fragments and samples; `raster`:
    /// rasterised pixels; `tris`: triangles; `texels`, `rects`: copies.
    Shared {
        shade: Per,
        raster: Per,
        tris: Per,
        texels: Per,
        rects: Per,
    },
    /// One pass per character (texture space).
    PerCharacter,
}

fn area(w: &Work) -> Option<u64> {
    match w {
        Work::Raster { width, height, .. } => Some(u64::from(*width) * u64::from(*height)),
        _ => None,
    }
}

/// Reads the kind of pass `k` from every sample (fixed only where fixed in all).
fn pass_kind(samples: &[Sample], k: usize) -> PassKind {
    let p0 = &samples[0].frame.passes[k];
    if p0.role != PassRole::Sss {
        return PassKind::Context;
    }
    if !samples[0].frame.is_screen_sized(p0) {
        return PassKind::PerCharacter;
    }
    let all = |f: &dyn Fn(&PassInput) -> bool| samples.iter().all(|s| f(&s.frame.passes[k]));
    let full_shade = all(&|p| {
        p.rasterized_pixels.is_none()
            && area(&p.work).is_some_and(|a| p.fragments >= a && p.samples_passed >= a)
    });
    let full_raster = all(&|p| match (p.rasterized_pixels, area(&p.work)) {
        (Some(r), Some(a)) => r >= a,
        _ => true,
    });
    let region_drawn = p0.rasterized_pixels.is_some() && !full_raster;
    let many_tris = all(&|p| matches!(p.work, Work::Raster { triangles, .. } if triangles > 2));
    let full_copy = all(&|p| match (&p.work, p.images.first()) {
        (Work::Copy { texels, .. }, Some(i)) => *texels >= u64::from(i.width) * u64::from(i.height),
        (Work::Copy { .. }, None) => false,
        _ => true,
    });
    let shade = if full_shade { Per::Fixed } else { Per::Skin };
    PassKind::Shared {
        shade,
        raster: if region_drawn {
            Per::Region
        } else {
            Per::Fixed
        },
        tris: if region_drawn {
            Per::Rects
        } else if many_tris && shade == Per::Skin {
            Per::Character
        } else {
            Per::Fixed
        },
        texels: if full_copy { Per::Fixed } else { Per::Region },
        rects: if full_copy { Per::Fixed } else { Per::Rects },
    }
}

/// One method setting's stored frames, read for pricing.
#[derive(Clone, Debug)]
pub struct SettingModel {
    /// Registry name and eval setting label.
    pub method: String,
    pub setting: String,
    /// The eval setting the accuracy model measured for it (its own label but
    /// for a compute twin: `pipeline::Registered::eval`).
    pub eval: String,
    /// Whether its blurs are dispatches (a compute twin,
    /// `pipeline::Registered::path`): unpriced on a profile without compute
    /// ([`CostModel::fixed_ms`]).
    pub needs_compute: bool,
    /// Ascending in px/mm; every frame has the same passes.
    samples: Vec<Sample>,
    /// The reference counts at each sample's scale.
    refs: Vec<Reference>,
    kinds: Vec<PassKind>,
}

impl SettingModel {
    /// A setting from its stored frames and the reference counts at each
    /// frame's scale (`reference(px_per_mm)`: the reference setting's frame of
    /// the same scale). Errors name what does not fit.
    pub fn new(
        method: &str,
        setting: &str,
        mut samples: Vec<Sample>,
        reference: impl Fn(f64) -> Option<Reference>,
    ) -> Result<SettingModel, String> {
        let who = format!("{method} '{setting}'");
        if samples.is_empty() {
            return Err(format!("{who}: no stored frames"));
        }
        samples.sort_by(|a, b| a.px_per_mm.total_cmp(&b.px_per_mm));
        let n = samples[0].frame.passes.len();
        for s in &samples {
            if !(s.px_per_mm.is_finite() && s.px_per_mm > 0.0) {
                return Err(format!("{who}: a frame's px/mm is {}", s.px_per_mm));
            }
            let same = s.frame.passes.len() == n
                && s.frame
                    .passes
                    .iter()
                    .zip(&samples[0].frame.passes)
                    .all(|(a, b)| a.role == b.role && a.name == b.name);
            if !same {
                return Err(format!(
                    "{who}: the stored frames at {} and {} px/mm have different passes",
                    samples[0].px_per_mm, s.px_per_mm
                ));
            }
        }
        let refs = samples
            .iter()
            .map(|s| {
                reference(s.px_per_mm).ok_or_else(|| {
                    format!(
                        "{who}: no reference frame at {:.3} px/mm (skin pixels and region)",
                        s.px_per_mm
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let kinds = (0..n).map(|k| pass_kind(&samples, k)).collect();
        Ok(SettingModel {
            method: method.to_string(),
            setting: setting.to_string(),
            eval: setting.to_string(),
            needs_compute: false,
            samples,
            refs,
            kinds,
        })
    }

    /// This setting as the twin of eval setting `eval`, its blurs
    /// dispatches or not.
    pub fn measured_as(self, eval: &str, needs_compute: bool) -> SettingModel {
        SettingModel {
            eval: eval.to_string(),
            needs_compute,
            ..self
        }
    }

    /// The px/mm range of the stored frames.
    pub fn scale_range(&self) -> (f64, f64) {
        (
            self.samples[0].px_per_mm,
            self.samples[self.samples.len() - 1].px_per_mm,
        )
    }

    fn xs(&self) -> Vec<f64> {
        self.samples.iter().map(|s| s.px_per_mm).collect()
    }

    /// A count of pass `k` per unit of `per`, interpolated at `x` px/mm.
    fn ratio(&self, k: usize, x: f64, per: Per, count: impl Fn(&PassInput) -> f64) -> f64 {
        let (i, j, t) = bracket(&self.xs(), x);
        let r = |s: usize| {
            let c = count(&self.samples[s].frame.passes[k]);
            let rf = &self.refs[s];
            match per {
                Per::Fixed => 0.0,
                Per::Skin => c / rf.skin,
                Per::Region => c / rf.region,
                Per::Rects => c / rf.rects,
                Per::Character => c,
            }
        };
        lerp(r(i), r(j), t)
    }

    /// The stored frame nearest `x` px/mm (in ln x): the one a group's frame
    /// takes its passes' shapes from, so a part jumps where it changes.
    pub fn nearest(&self, x: f64) -> usize {
        let (i, j, t) = bracket(&self.xs(), x);
        if t < 0.5 {
            i
        } else {
            j
        }
    }

    /// The texture-space map side (texels) a character at `x` px/mm gets:
    /// the render area of the per-character passes of the nearest stored
    /// frame, interpolated (`None`: the setting works in screen space).
    pub fn map_side(&self, x: f64) -> Option<f64> {
        let k = self
            .kinds
            .iter()
            .position(|k| *k == PassKind::PerCharacter)?;
        let side = |s: usize| match &self.samples[s].frame.passes[k].work {
            Work::Raster { width, height, .. } => f64::from((*width).max(*height)),
            _ => 0.0,
        };
        let (i, j, t) = bracket(&self.xs(), x);
        Some(lerp(side(i), side(j), t))
    }

    /// The frame of a group of characters with this setting at `width` x
    /// `height` (see the module docs).
    pub fn group_frame(&self, loads: &[CharacterLoad], width: u32, height: u32) -> FrameInput {
        self.group_frame_near(loads, width, height, None)
    }

    /// [`SettingModel::group_frame`] with every pass shaped on stored frame
    /// `near` instead of the one nearest each character (`None`: nearest):
    /// a part priced this way is smooth in px/mm, which `price_grid`
    /// interpolates.
    pub fn group_frame_near(
        &self,
        loads: &[CharacterLoad],
        width: u32,
        height: u32,
        near: Option<usize>,
    ) -> FrameInput {
        let mid = loads.iter().map(|l| l.px_per_mm).fold(f64::NAN, f64::max);
        let base_i = match near {
            Some(n) => n.min(self.samples.len() - 1),
            None if mid.is_finite() => self.nearest(mid),
            None => 0,
        };
        let base = self.samples[base_i].frame.rescaled(width, height);
        let mut passes = Vec::with_capacity(base.passes.len());
        let mut k = 0;
        while k < self.kinds.len() {
            match self.kinds[k] {
                PassKind::Context => passes.push(base.passes[k].clone()),
                PassKind::PerCharacter => {
                    // A run of per-character passes is one character's chain:
                    // every character runs the whole chain in turn.
                    let end = (k..self.kinds.len())
                        .find(|&j| self.kinds[j] != PassKind::PerCharacter)
                        .unwrap_or(self.kinds.len());
                    for l in loads {
                        for j in k..end {
                            passes.push(self.own_pass(j, l, near));
                        }
                    }
                    k = end;
                    continue;
                }
                PassKind::Shared {
                    shade,
                    raster,
                    tris,
                    texels,
                    rects,
                } => {
                    let mut q = base.passes[k].clone();
                    let sum = |per: Per, f: &dyn Fn(&PassInput) -> f64| -> f64 {
                        loads
                            .iter()
                            .map(|l| {
                                let unit = match per {
                                    Per::Fixed => 0.0,
                                    Per::Skin => l.skin_pixels,
                                    Per::Region => l.region_pixels,
                                    Per::Rects => l.region_rects,
                                    Per::Character => 1.0,
                                };
                                unit * self.ratio(k, l.px_per_mm, per, f)
                            })
                            .sum()
                    };
                    let n = |v: f64| v.round().max(0.0) as u64;
                    if shade != Per::Fixed {
                        q.fragments = n(sum(shade, &|p| p.fragments as f64));
                        q.samples_passed = n(sum(shade, &|p| p.samples_passed as f64));
                        self.mix_fetches(k, &mut q, loads, near);
                    }
                    if raster != Per::Fixed {
                        q.rasterized_pixels =
                            Some(n(sum(raster, &|p| p.rasterized_pixels.unwrap_or(0) as f64)));
                    }
                    let tri = |p: &PassInput| match p.work {
                        Work::Raster { triangles, .. } => triangles as f64,
                        _ => 0.0,
                    };
                    let copy = |p: &PassInput| match p.work {
                        Work::Copy { texels, rects, .. } => (texels as f64, f64::from(rects)),
                        _ => (0.0, 0.0),
                    };
                    let t_sum = (tris != Per::Fixed).then(|| n(sum(tris, &tri)));
                    let x_sum = (texels != Per::Fixed).then(|| n(sum(texels, &|p| copy(p).0)));
                    let r_sum = (rects != Per::Fixed).then(|| n(sum(rects, &|p| copy(p).1)));
                    match &mut q.work {
                        Work::Raster { triangles, .. } => {
                            if let Some(t) = t_sum {
                                *triangles = t;
                            }
                        }
                        // A dispatch's invocations are its fragments (one
                        // per listed tile's pixel): they follow the skin.
                        Work::Compute { invocations, .. } if shade != Per::Fixed => {
                            *invocations = q.fragments;
                        }
                        Work::Copy {
                            texels: tx,
                            rects: rc,
                            ..
                        } => {
                            if let Some(x) = x_sum {
                                *tx = x;
                            }
                            if let Some(r) = r_sum {
                                *rc = u32::try_from(r).unwrap_or(u32::MAX);
                            }
                        }
                        _ => {}
                    }
                    q.measured_ms = None;
                    passes.push(q);
                }
            }
            k += 1;
        }
        FrameInput {
            label: format!(
                "{} '{}', {} character(s)",
                self.method,
                self.setting,
                loads.len()
            ),
            width,
            height,
            passes,
            provenance: vec![format!(
                "plan::cost: stored frames of {} '{}' (profiles/frames/plan/), counts per character",
                self.method, self.setting
            )],
        }
    }

    /// Pass `k` of one character (texture space): the nearest frame's pass
    /// with its counts interpolated at the character's scale.
    fn own_pass(&self, k: usize, l: &CharacterLoad, near: Option<usize>) -> PassInput {
        let (i, j, t) = bracket(&self.xs(), l.px_per_mm);
        let (a, b) = (
            &self.samples[i].frame.passes[k],
            &self.samples[j].frame.passes[k],
        );
        let shape = near.map_or_else(
            || self.nearest(l.px_per_mm),
            |n| n.min(self.samples.len() - 1),
        );
        let mut q = self.samples[shape].frame.passes[k].clone();
        let n = |x: u64, y: u64| lerp(x as f64, y as f64, t).round().max(0.0) as u64;
        q.fragments = n(a.fragments, b.fragments);
        q.samples_passed = n(a.samples_passed, b.samples_passed);
        q.rasterized_pixels = match (a.rasterized_pixels, b.rasterized_pixels) {
            (Some(x), Some(y)) => Some(n(x, y)),
            (x, _) => x,
        };
        q.measured_ms = None;
        q
    }

    /// A shared pass's fetches per invocation: each character's (interpolated
    /// at its scale) weighted by the fragments it shades.
    fn mix_fetches(
        &self,
        k: usize,
        q: &mut PassInput,
        loads: &[CharacterLoad],
        forced: Option<usize>,
    ) {
        let fetches = |p: &PassInput| -> Vec<f64> {
            p.work
                .shader()
                .map_or_else(Vec::new, |s| s.fetches.iter().map(|f| f.count).collect())
        };
        let Some(sh) = q.work.shader_mut() else {
            return;
        };
        let xs = self.xs();
        let mut total = vec![0.0; sh.fetches.len()];
        let mut spreads: Vec<Vec<Spread>> = vec![Vec::new(); sh.fetches.len()];
        let mut weight = 0.0;
        for l in loads {
            let w = l.skin_pixels
                * self.ratio(k, l.px_per_mm, Per::Skin, |p: &PassInput| {
                    p.fragments as f64
                });
            let (i, j, t) = bracket(&xs, l.px_per_mm);
            let (a, b) = (
                fetches(&self.samples[i].frame.passes[k]),
                fetches(&self.samples[j].frame.passes[k]),
            );
            if a.len() != total.len() || b.len() != total.len() {
                return;
            }
            for (f, (x, y)) in total.iter_mut().zip(a.iter().zip(&b)) {
                *f += w * lerp(*x, *y, t);
            }
            // Where the taps land: the nearer sample's, its radii scaled to
            // this character's px/mm (a kernel's size on screen is linear in it).
            let near = forced.map_or(if t < 0.5 { i } else { j }, |n| n.min(xs.len() - 1));
            if let Some(s) = self.samples[near].frame.passes[k].work.shader() {
                let scale = l.px_per_mm / xs[near];
                for (out, f) in spreads.iter_mut().zip(&s.fetches) {
                    out.extend(f.spread.iter().map(|x| Spread {
                        share: w * x.share,
                        radius_px: x.radius_px * scale,
                    }));
                }
            }
            weight += w;
        }
        if weight > 0.0 {
            for ((f, t), s) in sh.fetches.iter_mut().zip(&total).zip(&spreads) {
                f.count = t / weight;
                f.spread = Spread::compact(s);
            }
        }
    }

    /// The skin-SSS ms of a group on `prof` (`None`: an SSS pass the profile
    /// cannot price).
    pub fn group_ms(
        &self,
        prof: &Profile,
        params: &ParamSet,
        loads: &[CharacterLoad],
        width: u32,
        height: u32,
    ) -> Option<f64> {
        self.group_ms_near(prof, params, loads, width, height, None)
    }

    /// [`SettingModel::group_ms`] of [`SettingModel::group_frame_near`].
    pub fn group_ms_near(
        &self,
        prof: &Profile,
        params: &ParamSet,
        loads: &[CharacterLoad],
        width: u32,
        height: u32,
        near: Option<usize>,
    ) -> Option<f64> {
        let f = self.group_frame_near(loads, width, height, near);
        let b = price_frame(prof, &f, params, Rescale::AsRun);
        let unpriced = b
            .passes
            .iter()
            .any(|p| p.role == PassRole::Sss && p.modelled_ms.is_none());
        (!unpriced).then_some(b.sss_ms)
    }

    /// The region (pixels, rectangles) of a character of `skin` pixels at `x`
    /// px/mm, as this setting's stored frames have it (the reference
    /// setting's stored frames give a character's reference region).
    pub fn region_of(&self, x: f64, skin: f64) -> (f64, f64) {
        let (i, j, t) = bracket(&self.xs(), x);
        let per_skin = |s: usize| self.refs[s].region / self.refs[s].skin;
        let rects = |s: usize| self.refs[s].rects;
        (
            skin * lerp(per_skin(i), per_skin(j), t),
            lerp(rects(i), rects(j), t),
        )
    }

    /// Skin pixels of the stored frame nearest `x` px/mm.
    pub fn skin_at(&self, x: f64) -> f64 {
        self.refs[self.nearest(x)].skin
    }
}

/// How the regions of a group's characters merge: characters overlap on
/// screen, and the frame draws (and copies) the tile cover of their regions
/// once, in fewer rectangles than their sum (`view::region::tile_cover` joins
/// runs across characters). Factors on the sum of the characters' own region
/// pixels and rectangles. Measured on the H200 check's 16-character crowd:
/// 13 characters' regions are 721 k pixels in 59 rectangles each alone and
/// 576 k in 15 as one frame, and the rectangles' cost made the sum over-price
/// the group by a quarter (docs/plan.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Overlap {
    pub pixels: f64,
    pub rects: f64,
}

impl Overlap {
    /// No merging (a character alone, or regions unknown).
    pub const NONE: Overlap = Overlap {
        pixels: 1.0,
        rects: 1.0,
    };

    /// The overlap of characters whose regions alone are `regions` (tile
    /// rectangles `[x0, y0, x1, y1]`, each character's disjoint), in a
    /// `width` x `height` frame of `tile`-pixel tiles. A character with no
    /// known region leaves the factors at 1.
    pub fn of(regions: &[&[[u32; 4]]], width: u32, height: u32, tile: u32) -> Overlap {
        use crate::view::region::{tile_cover, PixelRect};
        if regions.iter().any(|r| r.is_empty()) || regions.len() < 2 {
            return Overlap::NONE;
        }
        let rects: Vec<PixelRect> = regions
            .iter()
            .flat_map(|r| r.iter())
            .map(|&[x0, y0, x1, y1]| PixelRect { x0, y0, x1, y1 })
            .collect();
        let alone_px: f64 = rects.iter().map(|r| r.area() as f64).sum();
        let alone_n = rects.len() as f64;
        let cover = tile_cover(&rects, width, height, tile);
        let px: f64 = cover.iter().map(|r| r.area() as f64).sum();
        if alone_px <= 0.0 {
            return Overlap::NONE;
        }
        Overlap {
            pixels: (px / alone_px).min(1.0),
            rects: (cover.len() as f64 / alone_n).min(1.0),
        }
    }

    /// `loads` with their regions merged by these factors.
    pub fn apply(&self, loads: &[CharacterLoad]) -> Vec<CharacterLoad> {
        loads
            .iter()
            .map(|l| CharacterLoad {
                region_pixels: l.region_pixels * self.pixels,
                region_rects: l.region_rects * self.rects,
                ..*l
            })
            .collect()
    }
}

/// A group's cost split per character.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Split {
    /// The group's passes with no character in them.
    pub fixed_ms: f64,
    /// Each character priced alone, less the fixed cost.
    pub parts_ms: Vec<f64>,
    /// The whole group priced at once.
    pub total_ms: f64,
}

impl Split {
    /// `fixed + sum(parts)`, an upper bound of `total`.
    pub fn sum_ms(&self) -> f64 {
        self.fixed_ms + self.parts_ms.iter().sum::<f64>()
    }
}

/// Prices settings per character on one profile at one frame size.
pub struct CostModel<'a> {
    pub profile: &'a Profile,
    pub params: ParamSet,
    pub width: u32,
    pub height: u32,
}

impl CostModel<'_> {
    /// The fixed cost of a group of setting `s` (`None`: unpriceable here).
    pub fn fixed_ms(&self, s: &SettingModel) -> Option<f64> {
        // A compute twin is no choice where there is no compute: the budget
        // model would price its dispatches as pixel shaders, a frame no
        // renderer of that GPU draws (its fragment twin is the choice).
        if s.needs_compute && !self.profile.alu.has_compute() {
            return None;
        }
        s.group_ms(self.profile, &self.params, &[], self.width, self.height)
    }

    /// One character's part (alone, less the fixed cost).
    pub fn part_ms(&self, s: &SettingModel, fixed_ms: f64, l: &CharacterLoad) -> Option<f64> {
        self.part_ms_near(s, fixed_ms, l, None)
    }

    /// [`CostModel::part_ms`] with the passes shaped on stored frame `near`
    /// (see [`SettingModel::group_frame_near`]; `None`: the nearest).
    pub fn part_ms_near(
        &self,
        s: &SettingModel,
        fixed_ms: f64,
        l: &CharacterLoad,
        near: Option<usize>,
    ) -> Option<f64> {
        let one = s.group_ms_near(
            self.profile,
            &self.params,
            std::slice::from_ref(l),
            self.width,
            self.height,
            near,
        )?;
        Some((one - fixed_ms).max(0.0))
    }

    /// The whole group and its split.
    pub fn split(&self, s: &SettingModel, loads: &[CharacterLoad]) -> Option<Split> {
        let fixed = self.fixed_ms(s)?;
        let parts = loads
            .iter()
            .map(|l| self.part_ms(s, fixed, l))
            .collect::<Option<Vec<_>>>()?;
        let total = s.group_ms(self.profile, &self.params, loads, self.width, self.height)?;
        Some(Split {
            fixed_ms: fixed,
            parts_ms: parts,
            total_ms: total,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_regions_merge_and_disjoint_ones_do_not() {
        // Two characters on the same 64x32 tiles: one region, drawn once.
        let a = [[0, 0, 64, 32]];
        let same = Overlap::of(&[&a, &a], 256, 128, 32);
        assert_eq!(
            same,
            Overlap {
                pixels: 0.5,
                rects: 0.5
            }
        );
        // Side by side on the same tile rows: the cover joins them into one run.
        let b = [[64, 0, 128, 32]];
        let joined = Overlap::of(&[&a, &b], 256, 128, 32);
        assert_eq!(
            joined,
            Overlap {
                pixels: 1.0,
                rects: 0.5
            }
        );
        // Apart: nothing merges.
        let c = [[0, 64, 64, 96]];
        let c2 = [[128, 0, 192, 32]];
        assert_eq!(Overlap::of(&[&c, &c2], 256, 128, 32), Overlap::NONE);
        // One character, or one of unknown region: the factors stay at 1.
        assert_eq!(Overlap::of(&[&a], 256, 128, 32), Overlap::NONE);
        assert_eq!(Overlap::of(&[&a, &[]], 256, 128, 32), Overlap::NONE);
        let l = CharacterLoad {
            px_per_mm: 1.0,
            skin_pixels: 100.0,
            region_pixels: 400.0,
            region_rects: 4.0,
        };
        let m = same.apply(&[l])[0];
        assert_eq!(
            (m.region_pixels, m.region_rects, m.skin_pixels),
            (200.0, 2.0, 100.0)
        );
    }
}
