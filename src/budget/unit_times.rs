//! The unit times of one pass (texture, ALU, fill, memory, shared memory and
//! the costs that add) and their combination by the fitted parameters
//! ([`UnitTimes::combine`], the rule `units` states), with the bound a pass
//! is limited by: the arithmetic of the combining rule, apart from how
//! `units` prices a pass's work into them.

use serde::Serialize;

use crate::budget::params::ModelParams;

/// Bins of tap radius: half-octaves from 1/8 to 128 pixels.
pub const SPREAD_BINS: usize = 21;

/// The radius (pixels) of spread bin `b`.
pub fn spread_bin_radius(b: usize) -> f64 {
    0.125 * 2f64.powf(b as f64 / 2.0)
}

/// Adds `ms` of taps landing `radius_px` away to the two bins around it
/// (linear in the radius's logarithm; clamped to the end bins).
pub(crate) fn add_spread(bins: &mut [f64; SPREAD_BINS], radius_px: f64, ms: f64) {
    let x = (2.0 * (radius_px.max(1e-9) / 0.125).log2()).clamp(0.0, (SPREAD_BINS - 1) as f64);
    let i = (x.floor() as usize).min(SPREAD_BINS - 2);
    let t = x - i as f64;
    bins[i] += ms * (1.0 - t);
    bins[i + 1] += ms * t;
}

/// Which unit bounds a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Bound {
    Texture,
    Alu,
    Fill,
    Memory,
    /// Workgroup shared memory (dispatches).
    Shared,
    /// eDRAM resolves and restores outweigh the shading.
    Resolve,
    /// Clears, rejection, set-up or the fixed costs outweigh the shading.
    Overhead,
}

/// Unit times of a pass before the parameters apply, in ms (after
/// [`UnitTimes::scaled`]: each term as it enters the sum).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UnitTimes {
    pub texture: f64,
    /// Texture time of incoherent taps of no declared spread (scaled by
    /// `incoherent_factor` too; after `scaled`, every incoherent tap's).
    pub texture_incoherent: f64,
    /// Texture time of incoherent taps by how far they land from their pixel
    /// (bin `b` at [`spread_bin_radius`]`(b)` pixels; scaled by
    /// [`ModelParams::incoherence`] of its radius; 0 after `scaled`).
    pub texture_incoherent_by_radius: [f64; SPREAD_BINS],
    pub alu: f64,
    pub fill: f64,
    pub memory: f64,
    /// Pixels rejected one by one (stencil, depth) at the Z-only rate.
    pub reject: f64,
    /// Pixels of a depth-tested pass that passes nothing, at the Z-only rate
    /// (hierarchical Z rejects them by tiles: `hiz_reject_scale`).
    pub reject_hiz: f64,
    pub clear: f64,
    pub geometry: f64,
    pub resolve: f64,
    pub restore: f64,
    /// ms of 1000 pixels at the profile's 32 bpp fill rate (the unit of the
    /// fixed costs; after `scaled`, the fixed cost of the pass).
    pub fixed_unit: f64,
    /// Copy rectangles (after `scaled`: their cost in ms).
    pub copy_rects: f64,
    /// Workgroup shared-memory bytes over the profile's shared-memory rate
    /// (`alu.compute_shared_gbytes`; dispatches only).
    pub shared: f64,
    /// A dispatch or a transfer outside a render pass: the compute
    /// parameters apply (module docs).
    pub dispatch: bool,
}

impl UnitTimes {
    /// The combining rule (module docs), over the scaled terms.
    pub fn combine(&self, p: &ModelParams) -> f64 {
        let s = self.scaled(p);
        s.overhead() + s.shading().0 + s.resolve + s.restore
    }

    /// Each term as it enters the sum (parameters applied).
    pub fn scaled(&self, p: &ModelParams) -> UnitTimes {
        let (factor, alu_scale, fixed) = if self.dispatch {
            (
                p.compute_incoherent_factor,
                p.compute_alu_scale,
                p.fixed_kpix_per_dispatch,
            )
        } else {
            (p.incoherent_factor, p.alu_scale, p.fixed_kpix_per_pass)
        };
        let incoherence = |r: f64| {
            if self.dispatch {
                p.compute_incoherence(r)
            } else {
                p.incoherence(r)
            }
        };
        UnitTimes {
            texture: p.texture_scale * self.texture,
            texture_incoherent: p.texture_scale
                * (factor * self.texture_incoherent
                    + (0..SPREAD_BINS)
                        .map(|b| {
                            self.texture_incoherent_by_radius[b] * incoherence(spread_bin_radius(b))
                        })
                        .sum::<f64>()),
            texture_incoherent_by_radius: [0.0; SPREAD_BINS],
            alu: alu_scale * self.alu,
            fill: p.fill_scale * self.fill,
            memory: p.memory_scale * self.memory,
            reject: p.reject_scale * self.reject,
            reject_hiz: p.hiz_reject_scale * self.reject_hiz,
            clear: p.fill_scale * self.clear,
            geometry: self.geometry,
            resolve: self.resolve,
            restore: self.restore,
            fixed_unit: fixed * self.fixed_unit,
            copy_rects: p.rect_kpix * self.fixed_unit * self.copy_rects,
            shared: p.shared_scale * self.shared,
            dispatch: self.dispatch,
        }
    }

    /// The per-pass costs that add to the shading (on scaled terms).
    fn overhead(&self) -> f64 {
        self.fixed_unit
            + self.copy_rects
            + self.clear
            + self.reject
            + self.reject_hiz
            + self.geometry
    }

    /// The busiest shading unit and its time (on scaled terms).
    fn shading(&self) -> (f64, Bound) {
        let units = [
            (self.texture + self.texture_incoherent, Bound::Texture),
            (self.alu, Bound::Alu),
            (self.fill, Bound::Fill),
            (self.memory, Bound::Memory),
            (self.shared, Bound::Shared),
        ];
        units
            .into_iter()
            .fold((0.0, Bound::Fill), |a, u| if u.0 > a.0 { u } else { a })
    }

    /// The largest of shading, overhead and eDRAM transfers.
    pub fn bound(&self, p: &ModelParams) -> Bound {
        let s = self.scaled(p);
        let (shading, b) = s.shading();
        let overhead = s.overhead();
        let resolve = s.resolve + s.restore;
        if resolve > shading && resolve >= overhead {
            Bound::Resolve
        } else if overhead > shading {
            Bound::Overhead
        } else {
            b
        }
    }
}
