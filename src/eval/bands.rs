//! Where on the skin an error is: the interior, the band along the silhouette,
//! and the band along depth steps inside the skin (a nose over a cheek). One
//! RMSE over all skin lets a few rim pixels rank the methods: a screen-space
//! blur that reads the background at a back-lit rim loses a quarter of its red
//! there and is more accurate than any other inside the face. So every error is
//! reported per band, and relative to doing nothing:
//! - `err/none`: the method's RMS error over the no-SSS frame's (0: perfect,
//!   1: no better than no SSS at all, above 1: worse);
//! - per-channel gain: how much of the true scattering (reference - none) the
//!   method reproduces, the least-squares factor of (method - none) against it
//!   (below 1: too narrow, above 1: too wide);
//! - FLIP: the perceptual error of the tone-mapped frame, averaged over the band.
//!
//! Pure code on images read back from the GPU.

use serde::{Deserialize, Serialize};

/// Width of the silhouette and depth-step bands on the skin, mm: 2 mm is the
/// reach of the profile's Gaussians 1-4 (2-3 sigma), where a screen-space tap
/// crosses the edge.
pub const BAND_MM: f32 = 2.0;
/// A depth difference between neighbouring skin pixels counts as a step when it
/// exceeds this many times a pixel's width on the surface (a slope of 84 degrees)
/// and at least [`BAND_MM`].
pub const STEP_SLOPE: f32 = 10.0;

/// The band of a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Band {
    Interior,
    Silhouette,
    DepthStep,
}

impl Band {
    pub const ALL: [Band; 3] = [Band::Interior, Band::Silhouette, Band::DepthStep];

    pub fn name(self) -> &'static str {
        match self {
            Band::Interior => "interior",
            Band::Silhouette => "silhouette",
            Band::DepthStep => "depth step",
        }
    }
}

/// What the bands are computed from: the skin mask, the linear depth (scene
/// units) and the millimetres a pixel spans at unit depth.
pub struct BandInput<'a> {
    pub width: usize,
    pub height: usize,
    pub skin: &'a [bool],
    pub depth: &'a [f32],
    /// Millimetres one pixel spans on a surface facing the camera at depth 1
    /// (2 tan(fovy/2) mm_per_unit / height).
    pub mm_per_px_per_depth: f32,
    /// Millimetres per scene unit (depth differences are in scene units).
    pub mm_per_unit: f32,
}

impl<'a> BandInput<'a> {
    /// The input of a frame `height` pixels tall seen with a vertical field of
    /// view `fovy_deg`, in a scene of `mm_per_unit` millimetres per unit.
    pub fn for_view(
        (width, height): (usize, usize),
        skin: &'a [bool],
        depth: &'a [f32],
        fovy_deg: f32,
        mm_per_unit: f32,
    ) -> Self {
        let scale = crate::view::ViewScale::new(height as u32, fovy_deg.to_radians(), mm_per_unit);
        BandInput {
            width,
            height,
            skin,
            depth,
            mm_per_px_per_depth: scale.mm_per_px_per_depth(),
            mm_per_unit,
        }
    }
}

/// The band of every pixel (`None` off skin). A skin pixel is in the silhouette
/// band within [`BAND_MM`] (measured on the surface, pixel by pixel) of a skin
/// pixel next to a non-skin one, else in the depth-step band within
/// [`BAND_MM`] of a skin pixel next to a depth step, else in the interior.
pub fn bands(b: &BandInput) -> Vec<Option<Band>> {
    let (w, h) = (b.width, b.height);
    let n = w * h;
    assert!(b.skin.len() == n && b.depth.len() == n, "band input sizes");
    let px_mm = |i: usize| b.mm_per_px_per_depth * b.depth[i];
    let neighbours = |i: usize| {
        let (x, y) = (i % w, i / w);
        let mut v = Vec::with_capacity(4);
        if x > 0 {
            v.push(i - 1);
        }
        if x + 1 < w {
            v.push(i + 1);
        }
        if y > 0 {
            v.push(i - w);
        }
        if y + 1 < h {
            v.push(i + w);
        }
        v
    };
    let mut edge = vec![false; n];
    let mut step = vec![false; n];
    for i in 0..n {
        if !b.skin[i] {
            continue;
        }
        for j in neighbours(i) {
            if !b.skin[j] {
                edge[i] = true;
            } else {
                let dz_mm = (b.depth[i] - b.depth[j]).abs() * b.mm_per_unit;
                let threshold = (STEP_SLOPE * px_mm(i)).max(BAND_MM);
                if dz_mm > threshold {
                    step[i] = true;
                }
            }
        }
    }
    let near_edge = within(&edge, b, &neighbours);
    let near_step = within(&step, b, &neighbours);
    (0..n)
        .map(|i| {
            b.skin[i].then(|| {
                if near_edge[i] {
                    Band::Silhouette
                } else if near_step[i] {
                    Band::DepthStep
                } else {
                    Band::Interior
                }
            })
        })
        .collect()
}

/// Skin pixels within [`BAND_MM`] of a seed, the distance summed pixel by pixel
/// as each pixel's width on the surface (a multi-source shortest path).
fn within(seeds: &[bool], b: &BandInput, neighbours: &impl Fn(usize) -> Vec<usize>) -> Vec<bool> {
    let n = seeds.len();
    let mut dist = vec![f32::INFINITY; n];
    let mut queue = std::collections::BinaryHeap::new();
    for (i, &s) in seeds.iter().enumerate() {
        if s {
            dist[i] = 0.0;
            queue.push(std::cmp::Reverse((ordered(0.0), i)));
        }
    }
    while let Some(std::cmp::Reverse((d, i))) = queue.pop() {
        let d = f32::from_bits(d);
        if d > dist[i] || d > BAND_MM {
            continue;
        }
        for j in neighbours(i) {
            if !b.skin[j] {
                continue;
            }
            let nd = d + b.mm_per_px_per_depth * b.depth[j];
            if nd < dist[j] {
                dist[j] = nd;
                queue.push(std::cmp::Reverse((ordered(nd), j)));
            }
        }
    }
    dist.iter().map(|&d| d <= BAND_MM).collect()
}

/// A non-negative f32 as bits that order as the floats do.
fn ordered(v: f32) -> u32 {
    v.max(0.0).to_bits()
}

/// The errors of one method's image over one band.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BandError {
    pub pixels: usize,
    /// RMS error over the reference's RMS (energy-normalised relative RMSE).
    pub rel_rmse: f64,
    /// RMS error over the no-SSS frame's (0 perfect, 1 no better than none);
    /// `None` without a no-SSS frame.
    pub err_none: Option<f64>,
    /// Per channel: the least-squares factor of (method - none) on
    /// (reference - none); `None` without a no-SSS frame.
    pub gain: Option<[f64; 3]>,
    /// Mean FLIP over the band (tone-mapped frames).
    pub flip: f64,
}

/// A method's errors over each band.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BandErrors {
    pub interior: BandError,
    pub silhouette: BandError,
    pub depth_step: BandError,
}

impl BandErrors {
    /// The errors of `method` over every band (see [`band_error`]).
    pub fn of(
        method: &[[f32; 4]],
        reference: &[[f32; 4]],
        none: Option<&[[f32; 4]]>,
        flip: &[f32],
        bands: &[Option<Band>],
    ) -> Self {
        let e = |band| band_error(method, reference, none, flip, bands, band);
        BandErrors {
            interior: e(Band::Interior),
            silhouette: e(Band::Silhouette),
            depth_step: e(Band::DepthStep),
        }
    }

    pub fn get(&self, band: Band) -> &BandError {
        match band {
            Band::Interior => &self.interior,
            Band::Silhouette => &self.silhouette,
            Band::DepthStep => &self.depth_step,
        }
    }
}

/// The errors of `method` against `reference` over the pixels of `band`, with
/// `none` the no-SSS frame (for err/none and the gain) and `flip` the FLIP map
/// of method against reference. A band with no pixel scores all zeros.
pub fn band_error(
    method: &[[f32; 4]],
    reference: &[[f32; 4]],
    none: Option<&[[f32; 4]]>,
    flip: &[f32],
    bands: &[Option<Band>],
    band: Band,
) -> BandError {
    assert!(
        method.len() == reference.len()
            && bands.len() == reference.len()
            && flip.len() == reference.len()
            && none.is_none_or(|z| z.len() == reference.len()),
        "band error: image sizes differ"
    );
    let mut e = BandError::default();
    let (mut d2, mut r2, mut n2) = (0.0f64, 0.0f64, 0.0f64);
    let (mut num, mut den) = ([0.0f64; 3], [0.0f64; 3]);
    let mut flip_sum = 0.0;
    for i in 0..reference.len() {
        if bands[i] != Some(band) {
            continue;
        }
        e.pixels += 1;
        flip_sum += flip[i] as f64;
        for c in 0..3 {
            let (m, r) = (method[i][c] as f64, reference[i][c] as f64);
            d2 += (m - r) * (m - r);
            r2 += r * r;
            if let Some(none) = none {
                let z = none[i][c] as f64;
                n2 += (z - r) * (z - r);
                num[c] += (m - z) * (r - z);
                den[c] += (r - z) * (r - z);
            }
        }
    }
    if e.pixels > 0 {
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        e.rel_rmse = ratio(d2, r2).sqrt();
        if none.is_some() {
            e.err_none = Some(ratio(d2, n2).sqrt());
            e.gain = Some([0, 1, 2].map(|c| ratio(num[c], den[c])));
        }
        e.flip = flip_sum / e.pixels as f64;
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of skin on a background, flat at depth 10, with a raised block
    /// (depth 5) in its right half: the edge, the step and the interior.
    fn scene(w: usize, h: usize) -> (Vec<bool>, Vec<f32>) {
        let mut skin = vec![false; w * h];
        let mut depth = vec![100.0; w * h];
        for y in 4..h - 4 {
            for x in 4..w - 4 {
                skin[y * w + x] = true;
                depth[y * w + x] = if x >= w / 2 { 5.0 } else { 10.0 };
            }
        }
        (skin, depth)
    }

    #[test]
    fn bands_follow_the_silhouette_the_steps_and_their_width() {
        let (w, h) = (64, 40);
        let (skin, depth) = scene(w, h);
        // 0.05 mm per pixel at depth 1: 0.5 mm per pixel at depth 10, 0.25 at 5.
        let b = bands(&BandInput {
            width: w,
            height: h,
            skin: &skin,
            depth: &depth,
            mm_per_px_per_depth: 0.05,
            mm_per_unit: 2.0,
        });
        assert_eq!(b[0], None);
        // The outermost skin pixel and 2 mm (4 pixels at 0.5 mm) inward.
        assert_eq!(b[20 * w + 4], Some(Band::Silhouette));
        assert_eq!(b[20 * w + 8], Some(Band::Silhouette));
        assert_eq!(b[20 * w + 10], Some(Band::Interior));
        // Next to the step (x = 31 | 32) but far from the edge: the step band.
        assert_eq!(b[20 * w + 31], Some(Band::DepthStep));
        assert_eq!(b[20 * w + 32], Some(Band::DepthStep));
        assert_eq!(b[20 * w + 20], Some(Band::Interior));
    }

    #[test]
    fn pixel_scale_follows_the_field_of_view() {
        // 90 degrees: a 100-pixel-tall frame spans 2 units at depth 1.
        let b = BandInput::for_view((10, 100), &[], &[], 90.0, 3.0);
        assert!((b.mm_per_px_per_depth - 0.06).abs() < 1e-6);
        assert_eq!(b.mm_per_unit, 3.0);
    }

    #[test]
    fn err_none_and_gain_read_as_their_definitions() {
        let reference = vec![[2.0, 1.0, 1.0, 1.0]; 4];
        let none = vec![[1.0, 1.0, 1.0, 1.0]; 4];
        let bands = vec![Some(Band::Interior); 4];
        let flip = vec![0.1; 4];
        // Half of the scattering in red: gain 0.5, error half of none's.
        let half = vec![[1.5, 1.0, 1.0, 1.0]; 4];
        let score =
            |m: &[[f32; 4]]| band_error(m, &reference, Some(&none), &flip, &bands, Band::Interior);
        let e = score(&half);
        assert_eq!(e.pixels, 4);
        assert!((e.err_none.unwrap() - 0.5).abs() < 1e-12);
        assert!((e.gain.unwrap()[0] - 0.5).abs() < 1e-12);
        assert!((e.flip - 0.1).abs() < 1e-6);
        // sqrt(4 * 0.25 / (4 * (4 + 1 + 1))).
        assert!((e.rel_rmse - (1.0f64 / 24.0).sqrt()).abs() < 1e-12);
        // None itself scores 1, the reference 0.
        assert!((score(&none).err_none.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(score(&reference).err_none, Some(0.0));
        // Twice too wide: gain 2.
        let wide = vec![[3.0, 1.0, 1.0, 1.0]; 4];
        assert!((score(&wide).gain.unwrap()[0] - 2.0).abs() < 1e-12);
        // Without a no-SSS frame only the relative RMSE and FLIP.
        let e = band_error(&half, &reference, None, &flip, &bands, Band::Interior);
        assert_eq!((e.err_none, e.gain), (None, None));
        // Pixels of another band do not count.
        let e = band_error(&half, &reference, None, &flip, &bands, Band::Silhouette);
        assert_eq!(e, BandError::default());
    }
}
