//! The supersampled ground truth of the anti-aliasing evaluation (issue 17
//! item 6), device-free: the box filter that takes an N x N-supersampled
//! frame down to the output size, the edge mask, and the scores of an AA
//! mode's frame against the filtered one.
//!
//! Where the filter runs. The AA modes run on the tone-mapped LDR frame and
//! leave an sRGB-encoded RGBA8 image, blending in linear light (their blend
//! passes read the sRGB view, so fetches decode before they filter, and the
//! sRGB target encodes the result). The reference is brought into that same
//! space: the supersampled frame is tone-mapped at its own resolution (each
//! sample goes through the curve, as each pixel of the 1x frame does), then
//! every N x N block is decoded from sRGB, averaged in that display-linear
//! light and encoded back to sRGB8, rounding to nearest. This is what an
//! MSAA resolve of an sRGB target does, and it is the only order in which
//! "a pixel covered half by black and half by white" gets the value a
//! display shows for that coverage: averaging the encoded bytes instead
//! would make every edge too dark, averaging HDR radiance before the curve
//! would let one bright sample dominate a block.
//!
//! The scores are then taken in that space too: relative RMSE
//! (`metrics::relative_rmse`) on the decoded display-linear RGB of both
//! frames, FLIP (`metrics::flip_ldr`) on the sRGB bytes, each over the edge
//! pixels and over the whole frame.

use anyhow::{ensure, Result};

use super::metrics::{flip_ldr, relative_rmse};
use crate::format::{linear_to_srgb, srgb_to_linear};

/// The default supersampling factor per axis (4 x 4 = 16 samples per pixel,
/// the minimum).
pub const DEFAULT_FACTOR: u32 = 4;
/// The largest factor accepted (8 x 8 = 64 samples per pixel).
pub const MAX_FACTOR: u32 = 8;
/// Most pixels of a supersampled frame: 4 x 4 of 1920 x 1080 (33.2 M). The
/// frame's targets take a few hundred bytes a pixel on the device and a
/// capture reads 16-byte float images back, so this is several GiB already.
pub const MAX_SUPERSAMPLED_PIXELS: u64 = 4 * 4 * 1920 * 1080;
/// An 8-bit channel difference (sRGB bytes) between the filtered reference
/// and the 1x no-AA frame from which a pixel is an edge pixel: 8/255, above
/// the few steps the interior moves by when the SSS kernel and the textures
/// are sampled at N times the rate, below any partly covered edge pixel of
/// contrast over 3% that the 1x frame gets wrong.
pub const EDGE_THRESHOLD: u8 = 8;

/// Checks that an `n` x `n` supersampled frame of `width` x `height` can be
/// rendered: a factor of 1..=MAX_FACTOR, each side within `max_side` (the
/// device's `maxImageDimension2D` or dermis's own limit, whichever is less),
/// and no more than [`MAX_SUPERSAMPLED_PIXELS`]. The error is one line
/// naming the sizes.
pub fn check_supersampled(width: u32, height: u32, n: u32, max_side: u32) -> Result<(u32, u32)> {
    ensure!(
        (1..=MAX_FACTOR).contains(&n),
        "the supersampling factor must be within 1..={MAX_FACTOR}, got {n}"
    );
    let (w, h) = (
        u64::from(width) * u64::from(n),
        u64::from(height) * u64::from(n),
    );
    ensure!(
        w <= u64::from(max_side) && h <= u64::from(max_side),
        "the {n}x{n} supersampled reference of {width}x{height} is {w}x{h}, over the image side limit of {max_side} pixels (lower --factor or the frame size)"
    );
    ensure!(
        w * h <= MAX_SUPERSAMPLED_PIXELS,
        "the {n}x{n} supersampled reference of {width}x{height} is {w}x{h} = {:.1} M pixels, over the {:.1} M a supersampled frame may take (lower --factor or the frame size)",
        (w * h) as f64 / 1e6,
        MAX_SUPERSAMPLED_PIXELS as f64 / 1e6
    );
    // Both fit in u32: each is at most `max_side`.
    Ok((w as u32, h as u32))
}

/// Box-filters an sRGB-encoded RGBA8 image of `n width` x `n height` down to
/// `width` x `height`: each output pixel is the encoded mean of the decoded
/// (linear) values of its `n` x `n` block; alpha is averaged as is. Rows top
/// to bottom.
pub fn box_filter_srgb8(src: &[u8], width: u32, height: u32, n: u32) -> Result<Vec<u8>> {
    ensure!(n >= 1, "box filter: factor 0");
    let (w, h, n) = (width as usize, height as usize, n as usize);
    let sw = w * n;
    ensure!(
        src.len() == sw * h * n * 4,
        "box filter: {} bytes, a {}x{} RGBA8 image needs {}",
        src.len(),
        sw,
        h * n,
        sw * h * n * 4
    );
    let lut: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let inv = 1.0 / (n * n) as f64;
    let mut out = vec![0u8; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0.0f64; 4];
            for sy in y * n..(y + 1) * n {
                let row = &src[(sy * sw + x * n) * 4..(sy * sw + (x + 1) * n) * 4];
                for p in row.chunks_exact(4) {
                    for c in 0..3 {
                        acc[c] += f64::from(lut[p[c] as usize]);
                    }
                    acc[3] += f64::from(p[3]);
                }
            }
            let o = &mut out[(y * w + x) * 4..(y * w + x + 1) * 4];
            for c in 0..3 {
                o[c] = linear_to_srgb((acc[c] * inv) as f32);
            }
            o[3] = (acc[3] * inv).round() as u8;
        }
    }
    Ok(out)
}

/// The edge pixels: where the filtered reference and the 1x frame without AA
/// differ by at least [`EDGE_THRESHOLD`] in some colour channel (sRGB bytes).
///
/// Defined from the two frames, not from geometry or from any AA mode's own
/// edge detection: it is exactly where aliasing (or a sub-pixel feature the
/// 1x raster missed, which a depth or luma edge test cannot see) changes the
/// picture, and no mode's detector decides what it is scored on.
pub fn edge_mask(reference: &[u8], none: &[u8]) -> Result<Vec<bool>> {
    ensure!(
        reference.len() == none.len(),
        "edge mask: images of {} and {} bytes",
        reference.len(),
        none.len()
    );
    Ok(reference
        .chunks_exact(4)
        .zip(none.chunks_exact(4))
        .map(|(r, t)| (0..3).any(|c| r[c].abs_diff(t[c]) >= EDGE_THRESHOLD))
        .collect())
}

/// An sRGB8 image's display-linear RGBA (alpha 1: `relative_rmse` ignores it).
pub fn linear(srgb8: &[u8]) -> Vec<[f32; 4]> {
    let lut: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    srgb8
        .chunks_exact(4)
        .map(|p| {
            [
                lut[p[0] as usize],
                lut[p[1] as usize],
                lut[p[2] as usize],
                1.0,
            ]
        })
        .collect()
}

/// One frame's error against the filtered reference.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct AaError {
    /// Relative RMSE over the edge pixels (`None`: no edge pixel).
    pub rmse_edges: Option<f64>,
    /// Relative RMSE over the whole frame.
    pub rmse_frame: f64,
    /// Mean FLIP over the edge pixels (`None`: no edge pixel).
    pub flip_edges: Option<f64>,
    /// Mean FLIP over the whole frame.
    pub flip_frame: f64,
}

/// Scores `test` (sRGB8, `width` x `height`) against `reference` over the
/// edge `mask` and the whole frame.
pub fn score(
    test: &[u8],
    reference: &[u8],
    mask: &[bool],
    width: u32,
    height: u32,
) -> Result<AaError> {
    let (t, r) = (linear(test), linear(reference));
    ensure!(
        mask.len() == r.len(),
        "score: mask of {} pixels for a frame of {}",
        mask.len(),
        r.len()
    );
    let all = vec![true; r.len()];
    let flip = flip_ldr(test, reference, width, height)?;
    let edges = mask.iter().filter(|&&m| m).count();
    let flip_edges = (edges > 0).then(|| {
        flip.error_map
            .iter()
            .zip(mask)
            .filter(|(_, &m)| m)
            .map(|(&e, _)| f64::from(e))
            .sum::<f64>()
            / edges as f64
    });
    let rmse_edges = if edges > 0 {
        // A black reference over the edges leaves the measure undefined.
        relative_rmse(&t, &r, mask).ok()
    } else {
        None
    };
    Ok(AaError {
        rmse_edges,
        rmse_frame: relative_rmse(&t, &r, &all)?,
        flip_edges,
        flip_frame: flip.mean,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_filter_averages_in_linear_light() {
        // A 2x2 block half black, half white: linear 0.5, sRGB 188 (not 128).
        let src = [
            0, 0, 0, 255, 255, 255, 255, 255, //
            255, 255, 255, 255, 0, 0, 0, 255,
        ];
        let out = box_filter_srgb8(&src, 1, 1, 2).unwrap();
        assert_eq!(out, vec![188, 188, 188, 255]);
        assert_eq!(linear_to_srgb(0.5), 188);
    }

    #[test]
    fn box_filter_of_a_uniform_image_is_that_image() {
        let px = [37u8, 120, 201, 255];
        let src: Vec<u8> = px.repeat(12 * 8 * 16);
        let out = box_filter_srgb8(&src, 12, 8, 4).unwrap();
        assert_eq!(out, px.repeat(12 * 8));
        // Factor 1 is the identity.
        let img: Vec<u8> = (0..6 * 4 * 4).map(|i| (i * 7 % 256) as u8).collect();
        assert_eq!(box_filter_srgb8(&img, 6, 4, 1).unwrap(), img);
    }

    #[test]
    fn box_filter_picks_each_block() {
        // 3x2 output of 3x3 blocks, each block one value: out = that value.
        let (w, h, n) = (3usize, 2usize, 3usize);
        let val = |x: usize, y: usize| (40 * x + 90 * y + 5) as u8;
        let mut src = vec![0u8; w * n * h * n * 4];
        for sy in 0..h * n {
            for sx in 0..w * n {
                let v = val(sx / n, sy / n);
                src[(sy * w * n + sx) * 4..][..4].copy_from_slice(&[v, v, 255 - v, 255]);
            }
        }
        let out = box_filter_srgb8(&src, w as u32, h as u32, n as u32).unwrap();
        for y in 0..h {
            for x in 0..w {
                let v = val(x, y);
                assert_eq!(&out[(y * w + x) * 4..][..4], &[v, v, 255 - v, 255]);
            }
        }
        assert!(box_filter_srgb8(&src, 3, 3, 3).is_err());
    }

    #[test]
    fn supersampled_size_is_checked_in_one_line() {
        assert_eq!(
            check_supersampled(1280, 720, 4, 16384).unwrap(),
            (5120, 2880)
        );
        let e = check_supersampled(1280, 720, 4, 4096)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("5120x2880") && e.contains("4096") && !e.contains('\n'),
            "{e}"
        );
        let e = check_supersampled(3840, 2160, 4, 16384)
            .unwrap_err()
            .to_string();
        assert!(e.contains("M pixels"), "{e}");
        assert!(check_supersampled(64, 64, 0, 16384).is_err());
        assert!(check_supersampled(64, 64, MAX_FACTOR + 1, 16384).is_err());
    }

    #[test]
    fn edge_mask_and_scores() {
        let (w, h) = (16u32, 16u32);
        let grey = [128u8, 128, 128, 255].repeat((w * h) as usize);
        let mut off = grey.clone();
        // One pixel 7 steps off (not an edge), one 8 (an edge).
        off[0] = 135;
        off[4] = 136;
        let mask = edge_mask(&grey, &off).unwrap();
        assert_eq!(mask.iter().filter(|&&m| m).count(), 1);
        assert!(mask[1]);
        let s = score(&grey, &grey, &mask, w, h).unwrap();
        assert_eq!(s.rmse_frame, 0.0);
        assert_eq!(s.rmse_edges, Some(0.0));
        assert_eq!(s.flip_frame, 0.0);
        let s = score(&off, &grey, &mask, w, h).unwrap();
        assert!(s.rmse_edges.unwrap() > s.rmse_frame);
        assert!(s.flip_edges.unwrap() > s.flip_frame);
        let none = score(&off, &grey, &vec![false; (w * h) as usize], w, h).unwrap();
        assert_eq!((none.rmse_edges, none.flip_edges), (None, None));
    }
}
