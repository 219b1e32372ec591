//! The appearance rig of thesis ch. 7.4.2 (eq. 7.4-7.6): a neutral
//! haemoglobin map made mean-free, and per basis state (an expression, or a
//! global state such as exercise) a scale and a bias map, so that any affine
//! blend of the states is
//!
//!   H = sum_i w_i bias_i + H_0 sum_i w_i scale_i,  sum_i w_i = 1,
//!
//! with bias_0 = mu_n, scale_0 = 1 (the neutral state), bias_i = mu_i and
//! scale_i = sigma_i / sigma_n (eq. 7.5, from each state's local statistics,
//! eq. 7.1). The scales and biases are low-frequency, so they are kept at
//! `RIG_SIZE` texels a side (ch. 7.6: 256 x 256) while H_0 keeps the neutral
//! map's resolution.

use super::histogram::{local_stats, scale, LocalStats, Map};

/// Texels a side of every scale and bias map (ch. 7.6).
pub const RIG_SIZE: usize = 256;

/// One basis state's maps (eq. 7.5), at `RIG_SIZE`.
#[derive(Clone, Debug, PartialEq)]
pub struct Basis {
    pub name: String,
    pub scale: Map,
    pub bias: Map,
}

/// The rig: H_0 at the neutral map's resolution, bias_0 and the bases'
/// maps at `RIG_SIZE`.
#[derive(Clone, Debug, PartialEq)]
pub struct AppearanceRig {
    /// H_0 = H_n - mu_n (eq. 7.4), mu_n being bias_0 as stored and sampled:
    /// so the neutral state gives H_n back to the rounding.
    pub base: Map,
    /// bias_0 = mu_n.
    pub neutral_bias: Map,
    pub bases: Vec<Basis>,
}

impl AppearanceRig {
    /// The rig of `neutral` (H_n) and the states' haemoglobin maps (H_i, each
    /// the neutral map's size), their local statistics within `radius` texels
    /// of the neutral map (eq. 7.1).
    pub fn new(neutral: &Map, states: &[(String, Map)], radius: f32) -> AppearanceRig {
        let at_rig = |m: &Map| m.resized(RIG_SIZE, RIG_SIZE);
        let n = local_stats(neutral, radius);
        let neutral_bias = at_rig(&n.mean);
        let bases = states
            .iter()
            .map(|(name, h)| {
                let s = local_stats(h, radius);
                Basis {
                    name: name.clone(),
                    scale: at_rig(&scale_map(&s, &n)),
                    bias: at_rig(&s.mean),
                }
            })
            .collect();
        let (w, h) = (neutral.width, neutral.height);
        let base = Map::from_fn(w, h, |x, y| {
            let (u, v) = texel_centre(x, y, w, h);
            neutral.at(x, y) - neutral_bias.sample(u, v)
        });
        AppearanceRig {
            base,
            neutral_bias,
            bases,
        }
    }

    /// Eq. 7.6 at every texel of H_0 for the bases' `weights` (in `bases`'
    /// order; missing ones 0), the neutral state taking the rest of 1 (w_0 =
    /// 1 - sum w_i, negative when the states add to more than 1: an affine
    /// blend). Concentrations below 0 are clamped to 0 (a pallor scaled past
    /// the texture's own dip has no blood left, not less than none).
    pub fn haemoglobin(&self, weights: &[f32]) -> Map {
        let (w, h) = (self.base.width, self.base.height);
        Map::from_fn(w, h, |x, y| {
            let (u, v) = texel_centre(x, y, w, h);
            self.haemoglobin_at(weights, u, v, self.base.at(x, y))
        })
    }

    /// Eq. 7.6 at one texel: `base` is H_0 there, `(u, v)` its centre.
    pub fn haemoglobin_at(&self, weights: &[f32], u: f32, v: f32, base: f32) -> f32 {
        let w0 = 1.0 - weights.iter().take(self.bases.len()).sum::<f32>();
        let (mut bias, mut scale) = (w0 * self.neutral_bias.sample(u, v), w0);
        for (b, &wi) in self.bases.iter().zip(weights) {
            if wi != 0.0 {
                bias += wi * b.bias.sample(u, v);
                scale += wi * b.scale.sample(u, v);
            }
        }
        (bias + base * scale).max(0.0)
    }

    /// The basis named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.bases
            .iter()
            .position(|b| b.name.eq_ignore_ascii_case(name))
    }
}

/// Eq. 7.5's scale map at full resolution: sigma_i / sigma_n per texel.
fn scale_map(state: &LocalStats, neutral: &LocalStats) -> Map {
    let (w, h) = (state.std.width, state.std.height);
    Map::from_fn(w, h, |x, y| scale(state.std.at(x, y), neutral.std.at(x, y)))
}

fn texel_centre(x: usize, y: usize, w: usize, h: usize) -> (f32, f32) {
    let [u, v] = crate::skin::texel::pixel_uv(x, y, w, h);
    (u, v)
}

/// A colour state's weight `t` seconds after it began, rising over `rise`
/// seconds (a smoothstep: no jump at either end) and held at 1 after: the
/// blush of issue 30's item 5 rises over a second.
pub fn rising_weight(t: f32, rise: f32) -> f32 {
    if rise <= 0.0 {
        return if t >= 0.0 { 1.0 } else { 0.0 };
    }
    crate::scene::procedural::smoothstep(0.0, rise, t)
}

#[cfg(test)]
mod tests {
    use super::super::histogram::match_local;
    use super::*;

    fn noise(w: usize, h: usize, seed: u32) -> Map {
        super::super::histogram::tests::gaussian_noise(w, h, seed)
    }

    /// A neutral map at 512 (the face's) and two states: one whose blood
    /// rises to the right with the same texture's amplitude doubled, one a
    /// uniform 81% (ch. 7.7's fear).
    fn rig() -> (Map, Vec<(String, Map)>, AppearanceRig) {
        let (w, h) = (512, 512);
        let n = noise(w, h, 11);
        let neutral = Map::from_fn(w, h, |x, y| 0.03 + 0.005 * n.at(x, y));
        let other = noise(w, h, 12);
        let flush = Map::from_fn(w, h, |x, y| {
            0.03 * (1.0 + x as f32 / w as f32) + 0.01 * other.at(x, y)
        });
        let fear = Map::from_fn(w, h, |x, y| 0.81 * neutral.at(x, y));
        let states = vec![("flush".to_string(), flush), ("fear".to_string(), fear)];
        let rig = AppearanceRig::new(&neutral, &states, 8.0);
        (neutral, states, rig)
    }

    #[test]
    fn the_neutral_state_is_the_neutral_map() {
        let (neutral, _, rig) = rig();
        let h = rig.haemoglobin(&[]);
        let worst = h
            .data
            .iter()
            .zip(&neutral.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-7, "{worst}");
        assert_eq!(rig.index_of("FEAR"), Some(1));
    }

    // A state at weight 1 is eq. 7.3's match to it, to the rig's
    // downsampling of its low-frequency maps; a uniform 81% state scales the
    // whole map by 0.81 (ch. 7.7's fear), its texture included.
    #[test]
    fn a_full_state_is_the_local_match_and_fear_is_81_percent() {
        let (neutral, states, rig) = rig();
        let full = rig.haemoglobin(&[1.0, 0.0]);
        let exact = match_local(
            &neutral,
            &local_stats(&neutral, 8.0),
            &local_stats(&states[0].1, 8.0),
        );
        let (_, sigma) = neutral.moments();
        let (mut worst, mut sum) = (0.0f64, 0.0f64);
        for y in 16..496 {
            for x in 16..496 {
                let d = f64::from((full.at(x, y) - exact.at(x, y)).abs());
                worst = worst.max(d);
                sum += d;
            }
        }
        // The scales are ratios of windowed deviations, noisy texel to texel;
        // the rig keeps them at half the resolution (ch. 7.6), so a texel
        // far out in its window's tail moves by up to half a sigma.
        let mean = sum / (480.0 * 480.0);
        assert!(
            mean < 0.08 * sigma,
            "{mean} on average against sigma {sigma}"
        );
        assert!(worst < 0.8 * sigma, "{worst} against sigma {sigma}");
        let fear = rig.haemoglobin(&[0.0, 1.0]);
        let (mn, _) = neutral.moments();
        let (mf, _) = fear.moments();
        assert!((mf / mn - 0.81).abs() < 1e-3, "{}", mf / mn);
        let c = super::super::histogram::correlation(&fear, &neutral);
        assert!(c > 0.99, "{c}");
    }

    // Eq. 7.6 is affine in the weights: half a state is the mean of none
    // and all of it, and two states add their changes.
    #[test]
    fn blends_are_affine() {
        let (neutral, _, rig) = rig();
        let (none, full, half) = (
            rig.haemoglobin(&[0.0, 0.0]),
            rig.haemoglobin(&[1.0, 0.0]),
            rig.haemoglobin(&[0.5, 0.0]),
        );
        for k in (0..none.data.len()).step_by(97) {
            let want = 0.5 * (none.data[k] + full.data[k]);
            assert!((half.data[k] - want).abs() < 1e-6, "{k}");
        }
        let fear = rig.haemoglobin(&[0.0, 1.0]);
        let both = rig.haemoglobin(&[1.0, 1.0]);
        for k in (0..none.data.len()).step_by(97) {
            let want = full.data[k] + fear.data[k] - neutral.data[k];
            assert!((both.data[k] - want.max(0.0)).abs() < 1e-6, "{k}");
        }
    }

    #[test]
    fn a_blush_rises_over_its_second() {
        assert_eq!(rising_weight(-0.1, 1.0), 0.0);
        assert_eq!(rising_weight(0.0, 1.0), 0.0);
        assert_eq!(rising_weight(0.5, 1.0), 0.5);
        assert_eq!(rising_weight(1.0, 1.0), 1.0);
        assert_eq!(rising_weight(3.0, 1.0), 1.0);
        let steps: Vec<f32> = (0..=20)
            .map(|k| rising_weight(k as f32 * 0.05, 1.0))
            .collect();
        assert!(steps.windows(2).all(|s| s[1] >= s[0]));
        assert_eq!(rising_weight(0.0, 0.0), 1.0);
    }
}
