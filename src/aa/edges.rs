//! CPU references of the edge-detection passes: MLAA's (thesis ch. 9.3,
//! Listing 9.1, Eq. 9.2) and SMAA's with local contrast adaptation (ch.
//! 10.4.1, Eq. 10.1). Each pixel gets two edgels, at its left and top
//! boundaries (the right and bottom ones are its neighbours' left and top).
//! The GPU edge passes are to match these exactly, so the rules are the
//! shaders': a threshold test is `delta >= threshold` (`step`), arithmetic is
//! `f32`, and reads past the image border clamp to the edge (a clamp-to-edge
//! point sampler), so the border pixels never see an edge toward the outside.

use anyhow::{bail, ensure, Result};

/// An RGBA float image, rows top to bottom (row 0 first, as Vulkan stores
/// and samples it).
#[derive(Clone, Copy, Debug)]
pub struct Image<'a> {
    width: usize,
    height: usize,
    pixels: &'a [[f32; 4]],
}

impl<'a> Image<'a> {
    pub fn new(width: usize, height: usize, pixels: &'a [[f32; 4]]) -> Result<Self> {
        ensure!(
            width > 0 && height > 0,
            "image of {width} x {height} pixels"
        );
        let want = width.checked_mul(height);
        ensure!(
            want == Some(pixels.len()),
            "image of {width} x {height} needs {} pixels, got {}",
            want.map_or_else(|| "too many".to_string(), |n| n.to_string()),
            pixels.len()
        );
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    fn at(&self, x: isize, y: isize) -> [f32; 4] {
        let (x, y) = clamp(x, y, self.width, self.height);
        self.pixels[y * self.width + x]
    }
}

fn clamp(x: isize, y: isize, w: usize, h: usize) -> (usize, usize) {
    (
        x.clamp(0, w as isize - 1) as usize,
        y.clamp(0, h as isize - 1) as usize,
    )
}

/// The edgels of one pixel: at its left and top boundaries (the edges
/// texture's `.r` and `.g`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Edgel {
    pub left: bool,
    pub top: bool,
}

/// Which edgels a bilinear fetch reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Left,
    Top,
}

/// The edges of an image, row-major, row 0 first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Edges {
    pub width: usize,
    pub height: usize,
    pub edgels: Vec<Edgel>,
}

impl Edges {
    pub fn at(&self, x: usize, y: usize) -> Edgel {
        self.edgels[y * self.width + x]
    }

    /// A bilinear fetch of one channel at pixel coordinates `(x, y)` (texel
    /// `i` centred at `i + 0.5`, clamp to edge): what the blending pass reads
    /// to get two or four edgels at once (ch. 9.4.1, 9.4.2, 10.4.2).
    pub fn bilinear(&self, channel: Channel, x: f32, y: f32) -> f32 {
        let (fx, fy) = (x - 0.5, y - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let v = |dx: isize, dy: isize| {
            let (cx, cy) = clamp(x0 as isize + dx, y0 as isize + dy, self.width, self.height);
            let e = self.at(cx, cy);
            f32::from(u8::from(match channel {
                Channel::Left => e.left,
                Channel::Top => e.top,
            }))
        };
        let top = v(0, 0) * (1.0 - tx) + v(1, 0) * tx;
        let bottom = v(0, 1) * (1.0 - tx) + v(1, 1) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

/// Luma of Eq. 9.2 (Rec. 709 weights; SMAA uses the same).
pub fn luma(c: [f32; 4]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// MLAA's luma threshold ("0.1 to be an adequate threshold for most cases",
/// ch. 9.3.1).
pub const MLAA_LUMA_THRESHOLD: f32 = 0.1;

/// MLAA's depth threshold, in millimetres of linear view depth (ch. 9.3:
/// the thesis gives none; it "varies with resolution"). One centimetre:
/// above the step between neighbouring pixels of one surface up to 87
/// degrees from the view at the portrait's pixels of about 0.4 mm (a head of
/// some 240 mm over 580 of 720 rows; 0.4 / tan 3 deg = 7.6 mm), below the depth steps where a face occludes
/// itself (the nose's side over the cheek, the ear, the chin over the neck:
/// 15 mm and more) and far below a silhouette against the background. The
/// depth pass compares linear depth, so the threshold is a length whatever
/// the distance (a projected depth's steps shrink with the square of it).
pub const MLAA_DEPTH_THRESHOLD_MM: f32 = 10.0;

/// SMAA's quality presets (`SMAA.hlsl`, ANCHORS.md): low (threshold 0.15,
/// 4 search steps, no diagonals or corners), medium (0.1, 8), high (0.1, 16,
/// diagonals 8, corner rounding 25 %), ultra (0.05, 32, 16, 25 %).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// Threshold 0.15, 4 search steps, no diagonals or corners.
    Low,
    /// Threshold 0.1, 8 search steps, no diagonals or corners.
    Medium,
    /// Threshold 0.1, 16 search steps, diagonals 8, corner rounding 25 %.
    High,
    /// Threshold 0.05, 32 search steps, diagonals 16, corner rounding 25 %.
    Ultra,
}

impl Preset {
    pub const ALL: [Preset; 4] = [Preset::Low, Preset::Medium, Preset::High, Preset::Ultra];

    /// The name `--smaa-preset` takes and reports print.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Low => "low",
            Preset::Medium => "medium",
            Preset::High => "high",
            Preset::Ultra => "ultra",
        }
    }

    /// Bilinear fetches per orthogonal search (`SMAA_MAX_SEARCH_STEPS`; two
    /// pixels each).
    pub fn search_steps(self) -> u32 {
        match self {
            Preset::Low => 4,
            Preset::Medium => 8,
            Preset::High => 16,
            Preset::Ultra => 32,
        }
    }

    /// Steps per diagonal search (`SMAA_MAX_SEARCH_STEPS_DIAG`); `None`: the
    /// preset has no diagonal patterns (`SMAA_DISABLE_DIAG_DETECTION`).
    pub fn diag_search_steps(self) -> Option<u32> {
        match self {
            Preset::Low | Preset::Medium => None,
            Preset::High => Some(8),
            Preset::Ultra => Some(16),
        }
    }

    /// The corner rounding (`SMAA_CORNER_ROUNDING` / 100); `None`: no
    /// corner detection (`SMAA_DISABLE_CORNER_DETECTION`).
    pub fn corner_rounding(self) -> Option<f32> {
        match self {
            Preset::Low | Preset::Medium => None,
            Preset::High | Preset::Ultra => Some(0.25),
        }
    }

    /// The colour / luma threshold.
    pub fn threshold(self) -> f32 {
        match self {
            Preset::Low => 0.15,
            Preset::Medium | Preset::High => 0.1,
            Preset::Ultra => 0.05,
        }
    }

    /// The depth threshold, a tenth of the colour one (`SMAA_DEPTH_THRESHOLD`).
    pub fn depth_threshold(self) -> f32 {
        0.1 * self.threshold()
    }
}

/// Which neighbours may mask an edgel in the local contrast test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LocalContrast {
    /// Eq. 10.1 as the thesis writes it: the left edgel against the pixel's
    /// four deltas and the left-left one (`c_l, c_r, c_b, c_t, c_2l`), the top
    /// edgel against the four and the top-top one.
    PerEdge,
    /// `SMAA.hlsl`'s cheaper form: one maximum of all six deltas for both
    /// edgels, so a strong top-top delta can mask a left edgel too.
    Shared,
}

fn check_threshold(t: f32) -> Result<()> {
    if !(t.is_finite() && t > 0.0) {
        bail!("edge threshold {t} is not a positive finite number");
    }
    Ok(())
}

/// Thresholded left and top deltas, without local contrast (Listing 9.1).
fn plain(w: usize, h: usize, delta: impl Fn(isize, isize, isize, isize) -> f32, t: f32) -> Edges {
    let mut edgels = Vec::with_capacity(w * h);
    for y in 0..h as isize {
        for x in 0..w as isize {
            edgels.push(Edgel {
                left: delta(x, y, x - 1, y) >= t,
                top: delta(x, y, x, y - 1) >= t,
            });
        }
    }
    Edges {
        width: w,
        height: h,
        edgels,
    }
}

/// MLAA's luma edges (ch. 9.3.1): `|L - L_left| >= t`, `|L - L_top| >= t`.
pub fn mlaa_luma_edges(img: &Image, threshold: f32) -> Result<Edges> {
    check_threshold(threshold)?;
    let d = |x0, y0, x1, y1| (luma(img.at(x0, y0)) - luma(img.at(x1, y1))).abs();
    Ok(plain(img.width, img.height, d, threshold))
}

/// Depth edges (Listing 9.1; SMAA's depth pass is the same test with
/// `Preset::depth_threshold`). `depth` is row-major, row 0 first. The thesis
/// gives no fixed depth threshold (it depends on the depth's scale and the
/// resolution, ch. 9.3), so the caller names it.
pub fn mlaa_depth_edges(
    depth: &[f32],
    width: usize,
    height: usize,
    threshold: f32,
) -> Result<Edges> {
    check_threshold(threshold)?;
    ensure!(
        width > 0 && height > 0,
        "depth of {width} x {height} pixels"
    );
    ensure!(
        width.checked_mul(height) == Some(depth.len()),
        "depth of {width} x {height} needs as many values, got {}",
        depth.len()
    );
    let at = |x: isize, y: isize| {
        let (x, y) = clamp(x, y, width, height);
        depth[y * width + x]
    };
    let d = |x0, y0, x1, y1| (at(x0, y0) - at(x1, y1)).abs();
    Ok(plain(width, height, d, threshold))
}

/// Ch. 10.4.1: the thresholded edgels, each kept only if its delta is at
/// least half the largest delta around it (`2 c >= c_max`, exact in binary
/// floating point, as the shader's `step(c_max, 2 c)`).
fn adapted(
    w: usize,
    h: usize,
    delta: impl Fn(isize, isize, isize, isize) -> f32,
    t: f32,
    mode: LocalContrast,
) -> Edges {
    let mut edgels = Vec::with_capacity(w * h);
    for y in 0..h as isize {
        for x in 0..w as isize {
            let c_l = delta(x, y, x - 1, y);
            let c_t = delta(x, y, x, y - 1);
            let (e_l, e_t) = (c_l >= t, c_t >= t);
            if !(e_l || e_t) {
                // The shader discards here: no edgel, nothing to adapt.
                edgels.push(Edgel::default());
                continue;
            }
            let c_r = delta(x, y, x + 1, y);
            let c_b = delta(x, y, x, y + 1);
            let c_2l = delta(x - 1, y, x - 2, y);
            let c_2t = delta(x, y - 1, x, y - 2);
            let around = c_l.max(c_r).max(c_b).max(c_t);
            let (max_l, max_t) = match mode {
                LocalContrast::PerEdge => (around.max(c_2l), around.max(c_2t)),
                LocalContrast::Shared => {
                    let m = around.max(c_2l).max(c_2t);
                    (m, m)
                }
            };
            edgels.push(Edgel {
                left: e_l && 2.0 * c_l >= max_l,
                top: e_t && 2.0 * c_t >= max_t,
            });
        }
    }
    Edges {
        width: w,
        height: h,
        edgels,
    }
}

/// SMAA's luma edges with local contrast adaptation.
pub fn smaa_luma_edges(img: &Image, threshold: f32, mode: LocalContrast) -> Result<Edges> {
    check_threshold(threshold)?;
    let d = |x0, y0, x1, y1| (luma(img.at(x0, y0)) - luma(img.at(x1, y1))).abs();
    Ok(adapted(img.width, img.height, d, threshold, mode))
}

/// SMAA's colour edges: the delta of two pixels is the largest of their
/// R, G and B differences; then as the luma edges.
pub fn smaa_color_edges(img: &Image, threshold: f32, mode: LocalContrast) -> Result<Edges> {
    check_threshold(threshold)?;
    let d = |x0, y0, x1, y1| {
        let (a, b) = (img.at(x0, y0), img.at(x1, y1));
        (a[0] - b[0])
            .abs()
            .max((a[1] - b[1]).abs())
            .max((a[2] - b[2]).abs())
    };
    Ok(adapted(img.width, img.height, d, threshold, mode))
}

#[cfg(test)]
#[path = "edges_tests.rs"]
mod tests;
