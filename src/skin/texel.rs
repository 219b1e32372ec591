//! The device rules every CPU mirror follows, in one place: Vulkan's
//! bilinear filtering with CLAMP_TO_EDGE, 2x2 mip chains as the GPU's mip pass
//! builds them, and the rounding of f32 stores into 16-bit float targets.
//!
//! Conventions: images are row-major `width x height`; the uv of pixel
//! `(x, y)` is `((x + 0.5)/width, (y + 0.5)/height)`.

/// Bilinear taps along one axis, Vulkan's rule with CLAMP_TO_EDGE: the one
/// place every CPU mirror takes it from: `t = coord * size - 0.5`,
/// `i0 = floor(t)`, `frac = t - i0`, indices `i0`, `i0 + 1` clamped into `[0, size - 1]`.
fn axis_taps(coord: f32, size: usize) -> (usize, usize, f32) {
    let t = coord * size as f32 - 0.5;
    let t0 = t.floor();
    let frac = t - t0;
    let max = size as i64 - 1;
    // `as i64` saturates (NaN -> 0), so out-of-range coords stay in bounds.
    let i0 = t0 as i64;
    (
        i0.clamp(0, max) as usize,
        (i0 + 1).clamp(0, max) as usize,
        frac,
    )
}

/// `a + (b - a) * s`, the lerp form used by every mirror here.
pub fn lerp(a: f32, b: f32, s: f32) -> f32 {
    a + (b - a) * s
}

/// Bilinear fetch of `C` channels at `(u, v)`.
pub fn bilinear<const C: usize>(tex: &[[f32; C]], w: usize, h: usize, u: f32, v: f32) -> [f32; C] {
    let (x0, x1, fx) = axis_taps(u, w);
    let (y0, y1, fy) = axis_taps(v, h);
    let (t00, t10) = (tex[y0 * w + x0], tex[y0 * w + x1]);
    let (t01, t11) = (tex[y1 * w + x0], tex[y1 * w + x1]);
    let mut out = [0.0; C];
    for c in 0..C {
        out[c] = lerp(lerp(t00[c], t10[c], fx), lerp(t01[c], t11[c], fx), fy);
    }
    out
}

/// Bilinear RGBA fetch at `(u, v)` (Vulkan rule, CLAMP_TO_EDGE).
pub fn bilinear4(img: &[[f32; 4]], w: usize, h: usize, u: f32, v: f32) -> [f32; 4] {
    bilinear(img, w, h, u, v)
}

/// Bilinear single-channel fetch at `(u, v)` (Vulkan rule, CLAMP_TO_EDGE).
pub fn bilinear1(img: &[f32], w: usize, h: usize, u: f32, v: f32) -> f32 {
    // Same rule as bilinear4; a `[f32; 1]` view avoids a copy.
    let (x0, x1, fx) = axis_taps(u, w);
    let (y0, y1, fy) = axis_taps(v, h);
    lerp(
        lerp(img[y0 * w + x0], img[y0 * w + x1], fx),
        lerp(img[y1 * w + x0], img[y1 * w + x1], fx),
        fy,
    )
}

/// uv of the centre of pixel `(x, y)`.
pub fn pixel_uv(x: usize, y: usize, w: usize, h: usize) -> [f32; 2] {
    [(x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32]
}

/// One mip level: `(width, height, texels)`.
pub type MipLevel<T> = (usize, usize, Vec<T>);

/// Size of the level below a `w x h` level: halved with integer division,
/// at least 1 (Vulkan's rule).
fn next_size(w: usize, h: usize) -> (usize, usize) {
    ((w / 2).max(1), (h / 2).max(1))
}

/// Generic 2x2 box-filter mip chain; `avg(a, b, c, d)` must compute
/// `((a + b) + (c + d)) * 0.25` (the order the GPU shader uses).
fn mip_chain<T: Copy>(
    level0: &[T],
    w: usize,
    h: usize,
    levels: u32,
    first: impl Fn(T) -> T,
    avg: impl Fn(T, T, T, T) -> T,
) -> Vec<MipLevel<T>> {
    assert_eq!(level0.len(), w * h, "level0 size");
    assert!(levels >= 1, "a mip chain has at least level 0");
    let mut chain: Vec<MipLevel<T>> = vec![(w, h, level0.iter().map(|&t| first(t)).collect())];
    for _ in 1..levels {
        let (pw, ph, prev) = chain.last().expect("level 0 exists");
        let (pw, ph) = (*pw, *ph);
        let (nw, nh) = next_size(pw, ph);
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let (x0, x1) = ((2 * x).min(pw - 1), (2 * x + 1).min(pw - 1));
                let (y0, y1) = ((2 * y).min(ph - 1), (2 * y + 1).min(ph - 1));
                next.push(avg(
                    prev[y0 * pw + x0],
                    prev[y0 * pw + x1],
                    prev[y1 * pw + x0],
                    prev[y1 * pw + x1],
                ));
            }
        }
        chain.push((nw, nh, next));
    }
    chain
}

/// RGBA mip chain of `levels` levels (level 0 included).
///
/// Level `l` is `max(1, w_{l-1}/2) x max(1, h_{l-1}/2)`; texel `(x, y)` is
/// `((a + b) + (c + d)) * 0.25` of the source texels `a = (2x, 2y)`,
/// `b = (2x+1, 2y)`, `c = (2x, 2y+1)`, `d = (2x+1, 2y+1)`, each index clamped
/// to the source size (odd sizes drop the last row/column, as a compute
/// downsample with clamped fetches does). With `round_f16` every level
/// (level 0 too, a no-op for f16-exact input) is rounded as RGBA16F storage.
pub fn mip_chain4(
    level0: &[[f32; 4]],
    w: usize,
    h: usize,
    levels: u32,
    round_f16: bool,
) -> Vec<MipLevel<[f32; 4]>> {
    mip_chain4_with(
        level0,
        w,
        h,
        levels,
        round_f16.then_some(F16Rounding::NearestEven),
    )
}

/// [`mip_chain4`] with the device's f16 store rounding (`None`: no rounding).
pub fn mip_chain4_with(
    level0: &[[f32; 4]],
    w: usize,
    h: usize,
    levels: u32,
    rounding: Option<F16Rounding>,
) -> Vec<MipLevel<[f32; 4]>> {
    let store = move |t: [f32; 4]| match rounding {
        Some(mode) => round_f16_with(t, mode),
        None => t,
    };
    mip_chain(level0, w, h, levels, store, |a, b, c, d| {
        let mut o = [0.0f32; 4];
        for i in 0..4 {
            o[i] = ((a[i] + b[i]) + (c[i] + d[i])) * 0.25;
        }
        store(o)
    })
}

/// Single-channel f32 mip chain (same rule as [`mip_chain4`], no rounding:
/// the depth pyramid is R32F).
pub fn mip_chain1(level0: &[f32], w: usize, h: usize, levels: u32) -> Vec<MipLevel<f32>> {
    mip_chain(
        level0,
        w,
        h,
        levels,
        |t| t,
        |a, b, c, d| ((a + b) + (c + d)) * 0.25,
    )
}

/// Bilinear RGBA fetch on level `lod` of a chain (the level's own size
/// defines the texel grid; uv is shared by all levels).
pub fn bilinear_lod4(chain: &[MipLevel<[f32; 4]>], lod: u32, u: f32, v: f32) -> [f32; 4] {
    let (w, h, img) = &chain[lod as usize];
    bilinear4(img, *w, *h, u, v)
}

/// Bilinear single-channel fetch on level `lod` of a chain.
pub fn bilinear_lod1(chain: &[MipLevel<f32>], lod: u32, u: f32, v: f32) -> f32 {
    let (w, h, img) = &chain[lod as usize];
    bilinear1(img, *w, *h, u, v)
}

/// Rounds each component through IEEE half precision (RGBA16F storage).
pub fn round_f16(v: [f32; 4]) -> [f32; 4] {
    v.map(|c| half::f16::from_f32(c).to_f32())
}

/// How a device rounds f32 to a 16-bit float target. Vulkan allows either
/// round-to-nearest-even or round-toward-zero; lavapipe truncates (measured by
/// `tests/screen_gpu.rs`: its stores are never above the nearest-even values).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum F16Rounding {
    NearestEven,
    TowardZero,
}

/// `round_f16` with an explicit rounding mode.
pub fn round_f16_with(v: [f32; 4], mode: F16Rounding) -> [f32; 4] {
    v.map(|c| {
        let h = half::f16::from_f32(c);
        if mode == F16Rounding::NearestEven || !c.is_finite() || h.to_f32().abs() <= c.abs() {
            return h.to_f32();
        }
        // Rounded away from zero: step one ulp back toward zero (the magnitude
        // bits of an IEEE half are ordered, so the previous pattern is one ulp less).
        half::f16::from_bits(h.to_bits() - 1).to_f32()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_matches_the_vulkan_rule() {
        let (w, h) = (3, 2);
        let img: Vec<f32> = (0..6).map(|i| i as f32).collect();
        // Texel centres return the texel.
        for y in 0..h {
            for x in 0..w {
                let [u, v] = pixel_uv(x, y, w, h);
                assert_eq!(bilinear1(&img, w, h, u, v), img[y * w + x]);
            }
        }
        // Halfway between texels 0 and 1, and clamped beyond the edges.
        assert_eq!(bilinear1(&img, w, h, 1.0 / 3.0, 0.25), 0.5);
        assert_eq!(bilinear1(&img, w, h, -5.0, 0.25), 0.0);
        assert_eq!(bilinear1(&img, w, h, 9.0, 9.0), 5.0);
        let img4: Vec<[f32; 4]> = img.iter().map(|&t| [t, 2.0 * t, -t, 1.0]).collect();
        assert_eq!(
            bilinear4(&img4, w, h, 0.5, 0.5),
            // u = 0.5 is column 1's centre; v = 0.5 is halfway between rows.
            [2.5, 5.0, -2.5, 1.0]
        );
    }

    #[test]
    fn mip_chain_sizes_and_values() {
        let (w, h) = (7, 5);
        let img: Vec<f32> = (0..w * h).map(|i| i as f32).collect();
        let chain = mip_chain1(&img, w, h, 4);
        let sizes: Vec<(usize, usize)> = chain.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, [(7, 5), (3, 2), (1, 1), (1, 1)]);
        // Level 1 texel (2, 1): source texels (4,2), (5,2), (4,3), (5,3).
        let want = ((img[2 * 7 + 4] + img[2 * 7 + 5]) + (img[3 * 7 + 4] + img[3 * 7 + 5])) * 0.25;
        assert_eq!(chain[1].2[5], want);
        // Level 2 from the 3x2 level: (0,0), (1,0), (0,1), (1,1).
        let l1 = &chain[1].2;
        assert_eq!(chain[2].2[0], ((l1[0] + l1[1]) + (l1[3] + l1[4])) * 0.25);
        // A 1-wide source clamps the odd index.
        let col = mip_chain1(&[1.0, 3.0, 5.0, 7.0], 1, 4, 2);
        assert_eq!((col[1].0, col[1].1), (1, 2));
        assert_eq!(col[1].2, [2.0, 6.0]);
        // RGBA16F chains are rounded.
        let rgba: Vec<[f32; 4]> = (0..4).map(|i| [0.1 * i as f32 + 0.01; 4]).collect();
        let c4 = mip_chain4(&rgba, 2, 2, 2, true);
        assert_eq!(c4[1].2[0], round_f16(c4[1].2[0]));
        assert_eq!(c4[0].2[1], round_f16(rgba[1]));
        let raw = mip_chain4(&rgba, 2, 2, 2, false);
        assert_eq!(raw[0].2, rgba);
        assert_eq!(bilinear_lod1(&chain, 2, 0.3, 0.9), chain[2].2[0]);
        assert_eq!(bilinear_lod4(&c4, 1, 0.1, 0.1), c4[1].2[0]);
    }
}
