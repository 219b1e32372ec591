//! Approximate local histogram matching (thesis ch. 7.4.1): a haemoglobin
//! map's histogram within a disc of radius r around each texel, taken as a
//! Gaussian, is its mean and standard deviation there (eq. 7.1); matching a
//! texel from one local Gaussian to another is then a scale and a bias
//! (eq. 7.3, the closed form of eq. 7.2's CDF and inverse CDF). Pure math on
//! scalar maps; `rig` builds the appearance rig of eq. 7.4-7.6 from it.

/// A scalar map (row-major, `width` x `height` texels): a chromophore's
/// volume fraction per texel, or a statistic of one.
#[derive(Clone, Debug, PartialEq)]
pub struct Map {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl Map {
    /// A map of `data` (one value a texel); `None` when the sizes disagree.
    pub fn new(width: usize, height: usize, data: Vec<f32>) -> Option<Map> {
        (width > 0 && height > 0 && data.len() == width * height).then_some(Map {
            width,
            height,
            data,
        })
    }

    pub fn filled(width: usize, height: usize, value: f32) -> Map {
        Map {
            width,
            height,
            data: vec![value; width * height],
        }
    }

    /// `f(x, y)` at every texel.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> Map {
        let data = (0..width * height)
            .map(|k| f(k % width, k / width))
            .collect();
        Map {
            width,
            height,
            data,
        }
    }

    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// Bilinear between texel centres at `(u, v)` in [0, 1]^2, clamped to the
    /// edge texels (a texture's clamp-to-edge linear filter).
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        crate::skin::texel::bilinear1(&self.data, self.width, self.height, u, v)
    }

    /// The map at `width` x `height`: each texel the mean of the texels under
    /// it when the sizes divide (a box filter, as a mip level is made);
    /// otherwise sampled bilinearly at its centre.
    pub fn resized(&self, width: usize, height: usize) -> Map {
        if width == 0 || height == 0 {
            return Map::filled(width.max(1), height.max(1), 0.0);
        }
        if self.width % width == 0 && self.height % height == 0 {
            let (fx, fy) = (self.width / width, self.height / height);
            return Map::from_fn(width, height, |x, y| {
                let mut sum = 0.0f64;
                for dy in 0..fy {
                    for dx in 0..fx {
                        sum += f64::from(self.at(x * fx + dx, y * fy + dy));
                    }
                }
                (sum / (fx * fy) as f64) as f32
            });
        }
        Map::from_fn(width, height, |x, y| {
            self.sample(
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            )
        })
    }

    /// Mean and standard deviation over every texel.
    pub fn moments(&self) -> (f64, f64) {
        let n = self.data.len().max(1) as f64;
        let mean = self.data.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let var = self
            .data
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n;
        (mean, var.sqrt())
    }
}

/// Each texel's local Gaussian: eq. 7.1's mean and standard deviation.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalStats {
    pub mean: Map,
    pub std: Map,
}

/// Eq. 7.1: the mean and standard deviation of `h` within a disc of
/// `radius` texels around each texel, `f` being the disc's normalised
/// indicator. Near the map's edges the disc's part inside the map is
/// averaged (there is no skin beyond it to count).
///
/// Summed along rows: each disc row is a span of one row's prefix sums, so a
/// texel costs 2r + 1 lookups rather than pi r^2.
pub fn local_stats(h: &Map, radius: f32) -> LocalStats {
    let (w, ht) = (h.width, h.height);
    let r = radius.max(0.0);
    let reach = r.floor() as isize;
    // Half-width of the disc's row dy: the texels whose centres lie within r.
    let spans: Vec<(isize, isize)> = (-reach..=reach)
        .map(|dy| {
            (
                dy,
                (r * r - (dy * dy) as f32).max(0.0).sqrt().floor() as isize,
            )
        })
        .collect();
    // Prefix sums per row, in f64: the squares' sum minus the squared mean
    // cancels, and f32 would leave its rounding in a small deviation.
    let mut sum = vec![0.0f64; (w + 1) * ht];
    let mut sq = vec![0.0f64; (w + 1) * ht];
    for y in 0..ht {
        for x in 0..w {
            let v = f64::from(h.at(x, y));
            let k = y * (w + 1) + x;
            sum[k + 1] = sum[k] + v;
            sq[k + 1] = sq[k] + v * v;
        }
    }
    let mut mean = Vec::with_capacity(w * ht);
    let mut std = Vec::with_capacity(w * ht);
    for y in 0..ht as isize {
        for x in 0..w as isize {
            let (mut s, mut s2, mut n) = (0.0f64, 0.0f64, 0usize);
            for &(dy, half) in &spans {
                let row = y + dy;
                if row < 0 || row >= ht as isize {
                    continue;
                }
                let (a, b) = ((x - half).max(0), (x + half).min(w as isize - 1));
                let base = row as usize * (w + 1);
                s += sum[base + b as usize + 1] - sum[base + a as usize];
                s2 += sq[base + b as usize + 1] - sq[base + a as usize];
                n += (b - a + 1) as usize;
            }
            let m = s / n as f64;
            mean.push(m as f32);
            std.push((s2 / n as f64 - m * m).max(0.0).sqrt() as f32);
        }
    }
    LocalStats {
        mean: Map {
            width: w,
            height: ht,
            data: mean,
        },
        std: Map {
            width: w,
            height: ht,
            data: std,
        },
    }
}

/// A local deviation below this (volume fraction) is a flat window: no
/// histogram to match a scale from, so its scale is 1 (`scale`). Haemoglobin
/// maps vary by 1e-3 and more within a few millimetres.
pub const FLAT_STD: f32 = 1e-6;

/// Eq. 7.3's scale, sigma / sigma_n, with a flat source window kept at 1.
pub fn scale(to_std: f32, from_std: f32) -> f32 {
    if from_std > FLAT_STD {
        to_std / from_std
    } else {
        1.0
    }
}

/// Eq. 7.3: `neutral` moved texel by texel from its local Gaussians `from`
/// to the target's `to`: mu + (sigma / sigma_n) (H_n - mu_n).
pub fn match_local(neutral: &Map, from: &LocalStats, to: &LocalStats) -> Map {
    Map::from_fn(neutral.width, neutral.height, |x, y| {
        let k = y * neutral.width + x;
        to.mean.data[k]
            + scale(to.std.data[k], from.std.data[k]) * (neutral.data[k] - from.mean.data[k])
    })
}

/// Traditional, global histogram matching (Heeger and Bergen 1995, which
/// ch. 7.4 localises): each texel of `source` takes the value at its own
/// percentile of `target`'s sorted values. Exact on any histogram; the
/// yardstick eq. 7.3 is held to where the histograms are Gaussian.
pub fn match_global_exact(source: &Map, target: &Map) -> Map {
    let mut order: Vec<usize> = (0..source.data.len()).collect();
    order.sort_by(|&a, &b| source.data[a].total_cmp(&source.data[b]));
    let mut sorted = target.data.clone();
    sorted.sort_by(f32::total_cmp);
    let mut out = vec![0.0; source.data.len()];
    let n = order.len().max(1);
    for (rank, &k) in order.iter().enumerate() {
        let q = (rank as f64 + 0.5) / n as f64;
        let at = ((q * sorted.len() as f64) as usize).min(sorted.len() - 1);
        out[k] = sorted[at];
    }
    Map {
        width: source.width,
        height: source.height,
        data: out,
    }
}

/// Pearson's correlation of two maps of one size: how much of `a`'s
/// structure `b` keeps.
pub fn correlation(a: &Map, b: &Map) -> f64 {
    let (ma, sa) = a.moments();
    let (mb, sb) = b.moments();
    let n = a.data.len().max(1) as f64;
    let cov = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(&x, &y)| (f64::from(x) - ma) * (f64::from(y) - mb))
        .sum::<f64>()
        / n;
    cov / (sa * sb).max(f64::MIN_POSITIVE)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A deterministic, roughly Gaussian field: the sum of four hashed
    /// uniforms per texel (Irwin-Hall), mean 0, deviation 1.
    pub(crate) fn gaussian_noise(w: usize, h: usize, seed: u32) -> Map {
        let hash = |mut k: u32| {
            k ^= k >> 16;
            k = k.wrapping_mul(0x7feb_352d);
            k ^= k >> 15;
            k = k.wrapping_mul(0x846c_a68b);
            k ^= k >> 16;
            k as f32 / u32::MAX as f32
        };
        Map::from_fn(w, h, |x, y| {
            let k = (y * w + x) as u32 * 4 + seed.wrapping_mul(0x9e37_79b9);
            let s: f32 = (0..4).map(|i| hash(k.wrapping_add(i))).sum();
            (s - 2.0) / (4.0f32 / 12.0).sqrt()
        })
    }

    #[test]
    fn local_stats_are_the_discs_own() {
        let h = gaussian_noise(23, 19, 7);
        let r = 3.6f32;
        let got = local_stats(&h, r);
        for y in 0..h.height {
            for x in 0..h.width {
                let mut v = Vec::new();
                for yy in 0..h.height {
                    for xx in 0..h.width {
                        let (dx, dy) = (xx as f32 - x as f32, yy as f32 - y as f32);
                        if dx * dx + dy * dy <= r * r {
                            v.push(f64::from(h.at(xx, yy)));
                        }
                    }
                }
                let m = v.iter().sum::<f64>() / v.len() as f64;
                let s = (v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
                assert!((got.mean.at(x, y) as f64 - m).abs() < 1e-5, "({x}, {y})");
                assert!((got.std.at(x, y) as f64 - s).abs() < 1e-5, "({x}, {y})");
            }
        }
    }

    // A ramp of slope a over a disc of radius r: the mean is the centre's
    // value and the deviation a r / 2 (the variance of x over a disc is
    // r^2 / 4), closed forms of eq. 7.1 no code here produced.
    #[test]
    fn a_ramps_window_has_the_discs_closed_form() {
        let (a, r) = (0.01f32, 12.0f32);
        let h = Map::from_fn(80, 60, |x, _| a * x as f32);
        let s = local_stats(&h, r);
        let (x, y) = (40, 30);
        assert!((s.mean.at(x, y) - a * x as f32).abs() < 1e-6);
        let want = a * r / 2.0;
        let got = s.std.at(x, y);
        assert!((got / want - 1.0).abs() < 0.03, "{got} against {want}");
        let flat = local_stats(&Map::filled(9, 9, 0.3), 4.0);
        assert!(flat.mean.data.iter().all(|&m| (m - 0.3).abs() < 1e-6));
        assert!(flat.std.data.iter().all(|&s| s < 1e-6));
    }

    // Between two maps whose histograms have one shape (here near-Gaussian,
    // the shape eq. 7.3 assumes), eq. 7.3 with global statistics is the
    // traditional percentile matching of eq. 7.2, computed by sorting.
    #[test]
    fn between_histograms_of_one_shape_the_scale_and_bias_is_percentile_matching() {
        let n = gaussian_noise(128, 128, 1);
        let other = gaussian_noise(128, 128, 2);
        let t = Map::from_fn(128, 128, |x, y| 0.05 + 0.012 * other.at(x, y));
        let src = Map::from_fn(128, 128, |x, y| 0.03 + 0.004 * n.at(x, y));
        let (ms, ss) = src.moments();
        let (mt, st) = t.moments();
        let global = |m: f64, s: f64| LocalStats {
            mean: Map::filled(128, 128, m as f32),
            std: Map::filled(128, 128, s as f32),
        };
        let affine = match_local(&src, &global(ms, ss), &global(mt, st));
        let exact = match_global_exact(&src, &t);
        let worst = affine
            .data
            .iter()
            .zip(&exact.data)
            .map(|(a, e)| (a - e).abs())
            .fold(0.0f32, f32::max);
        // Irwin-Hall's tails are lighter than a Gaussian's: the extremes
        // differ most, and the bulk within a few hundredths of sigma.
        assert!(worst < 0.35 * st as f32, "{worst} (sigma {st})");
        let mean_abs = affine
            .data
            .iter()
            .zip(&exact.data)
            .map(|(a, e)| (a - e).abs())
            .sum::<f32>()
            / affine.data.len() as f32;
        assert!(mean_abs < 0.05 * st as f32, "{mean_abs}");
    }

    // The test: matched to a target with its own structure and
    // local statistics that vary over the map, each window of the result has
    // the target's mean and deviation, and the result keeps the neutral
    // map's structure (the target's own texture is not copied).
    #[test]
    fn each_window_takes_the_targets_statistics_and_keeps_the_structure() {
        let (w, h, r) = (96usize, 96usize, 6.0f32);
        let n = gaussian_noise(w, h, 3);
        let other = gaussian_noise(w, h, 4);
        let neutral = Map::from_fn(w, h, |x, y| 0.02 + 0.004 * n.at(x, y));
        // A target whose mean rises from left to right and whose deviation
        // doubles from top to bottom (smooth against the window).
        let target = Map::from_fn(w, h, |x, y| {
            let mean = 0.02 + 0.02 * x as f32 / w as f32;
            let dev = 0.003 * (1.0 + y as f32 / h as f32);
            mean + dev * other.at(x, y)
        });
        let from = local_stats(&neutral, r);
        let to = local_stats(&target, r);
        let out = match_local(&neutral, &from, &to);
        let got = local_stats(&out, r);
        let margin = 2 * r as usize;
        let (mut worst_mean, mut worst_dev) = (0.0f32, 0.0f32);
        let (mut sum_mean, mut sum_dev, mut count) = (0.0f32, 0.0f32, 0.0f32);
        for y in margin..h - margin {
            for x in margin..w - margin {
                let (tm, ts) = (to.mean.at(x, y), to.std.at(x, y));
                let (m, d) = (
                    (got.mean.at(x, y) - tm).abs() / ts,
                    (got.std.at(x, y) / ts - 1.0).abs(),
                );
                (worst_mean, worst_dev) = (worst_mean.max(m), worst_dev.max(d));
                (sum_mean, sum_dev, count) = (sum_mean + m, sum_dev + d, count + 1.0);
            }
        }
        // The texels of a window were each matched by their own windows,
        // centred elsewhere: on average within a tenth of the local sigma
        // and of its size, every window within 40% and 25%.
        let (mean_mean, mean_dev) = (sum_mean / count, sum_dev / count);
        assert!(mean_mean < 0.1, "means off by {mean_mean} sigma on average");
        assert!(mean_dev < 0.1, "deviations off by {mean_dev} on average");
        assert!(worst_mean < 0.4, "means off by {worst_mean} sigma");
        assert!(worst_dev < 0.25, "deviations off by {worst_dev}");
        let kept = correlation(
            &Map::from_fn(w, h, |x, y| out.at(x, y) - to.mean.at(x, y)),
            &neutral,
        );
        let copied = correlation(&target, &neutral);
        assert!(kept > 0.9, "structure kept {kept}");
        assert!(
            copied.abs() < 0.1,
            "the target shares the structure ({copied})"
        );
    }

    #[test]
    fn sampling_and_resizing() {
        let m = Map::from_fn(4, 2, |x, y| (x + 10 * y) as f32);
        assert_eq!(m.sample(0.125, 0.25), 0.0);
        assert_eq!(m.sample(0.25, 0.25), 0.5);
        assert_eq!(m.sample(0.0, 1.0), 10.0);
        let half = m.resized(2, 1);
        assert_eq!(half.data, vec![5.5, 7.5]);
        assert!(Map::new(3, 3, vec![0.0; 8]).is_none());
    }
}
