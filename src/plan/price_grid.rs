//! Every setting's per-character part ([`CostModel::part_ms`]) on a grid of
//! scale and skin pixels, priced lazily and interpolated: what re-planning
//! every frame (issue 16 item 6) reads instead of pricing each character
//! afresh (about 26 us a price, 25 ms for 15 settings x 64 characters).
//! Pure: no device.
//!
//! A character's load in the reference setting's terms is a function of its
//! px/mm `x` and skin pixels `s` alone ([`reference_load`]: its region is
//! `s` times the reference frames' region per skin pixel at `x`, its
//! rectangles theirs at `x`), so its part is a function `P(x, s)`. Along `s`
//! it is piecewise linear (every unit time of the budget model is linear in
//! the counts; a pass takes the max of its units), along `ln x` smooth (the
//! stored frames' ratios are interpolated in `ln x`, the taps' spread scales
//! with `x`). The grid holds `P` at `x = 2^(i / X_STEPS_PER_OCTAVE)` and
//! `s = 2^(j / SKIN_STEPS_PER_OCTAVE)`; a part is interpolated linearly in
//! `ln x` and in `s` between the four grid points around it. Grid points are
//! priced the first time a character lands next to them and kept, so a crowd
//! walking through a sequence prices only the scales it has not visited:
//! rows of a crowd share their scale, and a character moves a few percent a
//! frame. A test holds the interpolation to the direct price (within 1%).

use std::collections::HashMap;

use super::choose::SettingCosts;
use super::cost::{CharacterLoad, CostModel, SettingModel};
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;

/// Grid points per octave of px/mm (2^(1/8): 9% apart).
pub const X_STEPS_PER_OCTAVE: f64 = 8.0;
/// Grid points per octave of skin pixels (2^(1/2): 41% apart).
pub const SKIN_STEPS_PER_OCTAVE: f64 = 2.0;

/// The grid row of characters with no skin on screen.
const NO_SKIN: i32 = i32::MIN;

/// The load of a character of `skin` pixels at `x` px/mm in the reference
/// setting's terms (what `cli::characters` gives every character).
pub fn reference_load(reference: &SettingModel, x: f64, skin: f64) -> CharacterLoad {
    let (region, rects) = reference.region_of(x, skin);
    CharacterLoad {
        px_per_mm: x,
        skin_pixels: skin,
        region_pixels: region,
        region_rects: if skin > 0.0 { rects.max(1.0) } else { 0.0 },
    }
}

/// The grid of one profile and frame size.
pub struct PriceGrid<'a> {
    models: &'a [SettingModel],
    reference: &'a SettingModel,
    cost: CostModel<'a>,
    fixed: Vec<Option<f64>>,
    points: HashMap<(usize, usize, i32, i32), Option<f64>>,
    /// Grid points priced so far (the work the cache did not save).
    pub priced: usize,
}

impl<'a> PriceGrid<'a> {
    pub fn new(
        models: &'a [SettingModel],
        reference: &'a SettingModel,
        profile: &'a Profile,
        width: u32,
        height: u32,
    ) -> PriceGrid<'a> {
        let cost = CostModel {
            profile,
            params: ParamSet::fitted(),
            width,
            height,
        };
        let fixed = models.iter().map(|m| cost.fixed_ms(m)).collect();
        PriceGrid {
            models,
            reference,
            cost,
            fixed,
            points: HashMap::new(),
            priced: 0,
        }
    }

    /// Setting `k`'s group fixed cost (`None`: unpriceable on the profile).
    pub fn fixed_ms(&self, k: usize) -> Option<f64> {
        self.fixed[k]
    }

    /// Grid point `(i, j)` of setting `k` with its passes shaped on stored
    /// frame `near`.
    fn point(&mut self, k: usize, near: usize, i: i32, j: i32) -> Option<f64> {
        if let Some(p) = self.points.get(&(k, near, i, j)) {
            return *p;
        }
        let x = (f64::from(i) / X_STEPS_PER_OCTAVE).exp2();
        let s = if j == NO_SKIN {
            0.0
        } else {
            (f64::from(j) / SKIN_STEPS_PER_OCTAVE).exp2()
        };
        let load = reference_load(self.reference, x, s);
        let p = self.fixed[k].and_then(|f| {
            self.cost
                .part_ms_near(&self.models[k], f, &load, Some(near))
        });
        self.priced += 1;
        self.points.insert((k, near, i, j), p);
        p
    }

    /// Setting `k`'s part for a character of `skin` pixels at `x` px/mm
    /// (`None`: unpriceable). A character with no skin on screen still has a
    /// part where the setting works per character (texture space renders its
    /// map wherever it stands); under one pixel, the part of one pixel. The
    /// four grid points are shaped on the stored frame nearest the character
    /// (the one its direct price takes), so the interpolation never crosses
    /// the jump where that frame changes.
    pub fn part_ms(&mut self, k: usize, x: f64, skin: f64) -> Option<f64> {
        self.fixed[k]?;
        let near = self.models[k].nearest(x);
        let u = x.max(1e-9).log2() * X_STEPS_PER_OCTAVE;
        let i = u.floor() as i32;
        let tu = u - f64::from(i);
        if skin <= 0.0 {
            let a = self.point(k, near, i, NO_SKIN)?;
            let b = self.point(k, near, i + 1, NO_SKIN)?;
            return Some((a + (b - a) * tu).max(0.0));
        }
        let v = skin.max(1.0).log2() * SKIN_STEPS_PER_OCTAVE;
        let j = v.floor() as i32;
        // Linear in skin pixels between the two grid skins.
        let (s0, s1) = (
            (f64::from(j) / SKIN_STEPS_PER_OCTAVE).exp2(),
            (f64::from(j + 1) / SKIN_STEPS_PER_OCTAVE).exp2(),
        );
        let tv = ((skin.max(1.0) - s0) / (s1 - s0)).clamp(0.0, 1.0);
        let mut at = |di: i32, dj: i32| self.point(k, near, i + di, j + dj);
        let (a, b, c, d) = (at(0, 0)?, at(1, 0)?, at(0, 1)?, at(1, 1)?);
        let low = a + (b - a) * tu;
        let high = c + (d - c) * tu;
        Some((low + (high - low) * tv).max(0.0))
    }

    /// Prices every grid point a character of this scene can land on
    /// between `x_lo` and `x_hi` px/mm: per scale, skins from one pixel up
    /// to twice the square of a head `head_mm` tall at that scale, and no
    /// skin, each shaped on the stored frame nearest it (and the nearest of
    /// the next scale up, where the two differ). What a game does once at
    /// load, so that no frame prices anything.
    pub fn fill(&mut self, x_lo: f64, x_hi: f64, head_mm: f64) {
        let i0 = (x_lo.max(1e-9).log2() * X_STEPS_PER_OCTAVE).floor() as i32;
        let i1 = (x_hi.max(1e-9).log2() * X_STEPS_PER_OCTAVE).ceil() as i32;
        let grid_x = |i: i32| (f64::from(i) / X_STEPS_PER_OCTAVE).exp2();
        for k in 0..self.models.len() {
            if self.fixed[k].is_none() {
                continue;
            }
            for i in i0..=i1 {
                let (x0, x1) = (grid_x(i), grid_x(i + 1));
                let top = 2.0 * (head_mm * x1).powi(2);
                let j1 = (top.max(1.0).log2() * SKIN_STEPS_PER_OCTAVE).ceil() as i32;
                let mut nears = vec![self.models[k].nearest(x0)];
                nears.push(self.models[k].nearest(x1));
                nears.dedup();
                for &near in &nears {
                    for ii in [i, i + 1] {
                        let _ = self.point(k, near, ii, NO_SKIN);
                        for j in 0..=j1 + 1 {
                            let _ = self.point(k, near, ii, j);
                        }
                    }
                }
            }
        }
    }

    /// Every setting's costs for characters at `(px/mm, skin pixels)`, with
    /// each setting's texture-space texel (`atlas_mm` over its map side).
    pub fn costs(&mut self, chars: &[(f64, f64)], atlas_mm: f64) -> Vec<SettingCosts> {
        (0..self.models.len())
            .filter_map(|k| {
                let fixed = self.fixed[k]?;
                let m = &self.models[k];
                let texel_mm = chars
                    .iter()
                    .map(|&(x, _)| m.map_side(x).map(|t| atlas_mm / t.max(1.0)))
                    .collect();
                Some(SettingCosts {
                    method: m.method.clone(),
                    setting: m.setting.clone(),
                    measured_as: m.eval.clone(),
                    fixed_ms: fixed,
                    parts_ms: chars.iter().map(|&(x, s)| self.part_ms(k, x, s)).collect(),
                    texel_mm,
                })
            })
            .collect()
    }
}
