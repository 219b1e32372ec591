//! SMAA's search texture (thesis ch. 10.4.2, "Accurate distances search",
//! Eqs. 10.4 and 10.5, Fig. 10.9): the line searches step two pixels at a
//! time with one bilinear fetch of the edges texture at `(-0.25, -0.125)`
//! from a pixel centre, which blends four edgels of each channel with weights
//! 1/32, 3/32, 7/32 and 21/32 (Eq. 10.5 with `y = x / 2`). The sixteen sums
//! are distinct, so the fetch can be decoded; the search texture does the
//! decoding for the last fetch of a search and gives how many of its two
//! pixels still belong to the line (0, 1 or 2), stored as `127 n` to use the
//! 8-bit range.
//!
//! The four edgels of a fetch, in the order of the weights (ch. 10.4.2 and
//! SMAA's reference): `[0]` the far pixel of the pair on the row above, `[1]`
//! the near pixel on the row above, `[2]` the far pixel on the search's row,
//! `[3]` the near pixel on it ("near": weight 3/4 along the search, the pixel
//! the fetch is closest to; "far": the next pixel in the search direction).
//! The `.r` fetch reads the crossing (left) edgels, `.g` the line's (top) ones.
//!
//! Layout: computed 66 x 33 (x: 33 `.r` values for the left search, then 33
//! for the right one; y: 33 `.g` values), cropped to rows 17..33 and columns
//! 0..64 (everything outside is zero: a last fetch without the near top
//! edgel, `.g < 21/32`, means zero), then flipped vertically, as `SMAA.hlsl`'s
//! `SMAASearchLength` addresses it: 64 x 16, one channel, row 0 first.

use std::sync::OnceLock;

/// Stored width and height.
pub const WIDTH: usize = 64;
pub const HEIGHT: usize = 16;
/// The computed table before the crop.
const FULL_WIDTH: usize = 66;
const FULL_HEIGHT: usize = 33;
/// Weights of the four edgels in 32nds (Eq. 10.5 at x = 3/4, y = 7/8).
const WEIGHTS: [usize; 4] = [1, 3, 7, 21];
/// The value per pixel kept (127 x 2 = 254 fits a byte).
pub const STEP: u8 = 127;

/// A fetch's value in 32nds for four edgels.
pub fn fetch_code(e: [bool; 4]) -> usize {
    (0..4).map(|i| WEIGHTS[i] * usize::from(e[i])).sum()
}

/// The edgels a fetch's value (in 32nds) encodes, `None` for a value no
/// combination gives.
pub fn decode(code: usize) -> Option<[bool; 4]> {
    (0..16usize)
        .map(|b| [b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0])
        .find(|&e| fetch_code(e) == code)
}

/// Pixels of the last fetch that still belong to a line searched leftward:
/// the near pixel if it has the line's edgel; then the far one too if it has
/// the edgel and no crossing edgel separates the two (the near pixel's left
/// edgels, on either row).
fn delta_left(cross: [bool; 4], line: [bool; 4]) -> u8 {
    let near = line[3];
    let far = near && line[2] && !cross[1] && !cross[3];
    u8::from(near) + u8::from(far)
}

/// The same for a rightward search, where the crossing edgels sit on the
/// left of each pixel: the near pixel needs no crossing edgel on its own
/// left (between it and the line so far), the far one none on its left.
fn delta_right(cross: [bool; 4], line: [bool; 4]) -> u8 {
    let near = line[3] && !cross[1] && !cross[3];
    let far = near && line[2] && !cross[0] && !cross[2];
    u8::from(near) + u8::from(far)
}

/// The search texture, `WIDTH x HEIGHT` bytes, row 0 first (`R8_UNORM`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SmaaSearchTex {
    pub bytes: Vec<u8>,
}

/// The table before the crop, `FULL_WIDTH x FULL_HEIGHT`, row `y` holding the
/// `.g` value `y / 32`.
fn computed() -> Vec<u8> {
    let mut full = vec![0u8; FULL_WIDTH * FULL_HEIGHT];
    let half = FULL_WIDTH / 2;
    for y in 0..FULL_HEIGHT {
        let Some(line) = decode(y) else { continue };
        for x in 0..half {
            let Some(cross) = decode(x) else { continue };
            full[y * FULL_WIDTH + x] = STEP * delta_left(cross, line);
            full[y * FULL_WIDTH + half + x] = STEP * delta_right(cross, line);
        }
    }
    full
}

impl SmaaSearchTex {
    /// Computed, cropped and flipped. The crop drops only zeros (tested):
    /// rows under 17 have no near line edgel (that needs 21/32), columns 64
    /// and 65 are right-search values 31/32 and 1, whose near crossing edgel
    /// stops the line at once.
    pub fn generate() -> Self {
        let full = computed();
        let mut bytes = Vec::with_capacity(WIDTH * HEIGHT);
        for row in 0..HEIGHT {
            let y = FULL_HEIGHT - 1 - row;
            bytes.extend_from_slice(&full[y * FULL_WIDTH..y * FULL_WIDTH + WIDTH]);
        }
        Self { bytes }
    }

    /// `SMAASearchLength`'s lookup: texel `(32 e.r + 33 [right], 32 - 32 e.g)`
    /// (its scale and bias land on texel centres), clamped to the texture;
    /// the value is the pixel count times `STEP`.
    pub fn lookup(&self, e_r: f32, e_g: f32, right: bool) -> u8 {
        let (x, y) = texel(e_r, e_g, right);
        self.bytes[y * WIDTH + x]
    }
}

/// The texel `SMAASearchLength` samples for a fetch `(e.r, e.g)`, its
/// texture coordinate `scale e + bias` with scale `(66 / 2 - 1, -33 + 1)` and
/// bias `(66 offset + 0.5, 33 - 0.5)` in texels (offset 0 left, 0.5 right),
/// point-sampled with clamp to edge.
pub fn texel(e_r: f32, e_g: f32, right: bool) -> (usize, usize) {
    let offset = if right { 0.5 } else { 0.0 };
    let half = FULL_WIDTH as f32 / 2.0;
    let x = (half - 1.0) * e_r + FULL_WIDTH as f32 * offset + 0.5;
    let y = (1.0 - FULL_HEIGHT as f32) * e_g + FULL_HEIGHT as f32 - 0.5;
    let c = |v: f32, n: usize| (v.floor().max(0.0) as usize).min(n - 1);
    (c(x, WIDTH), c(y, HEIGHT))
}

/// The table, generated once per process.
pub fn search_tex() -> &'static SmaaSearchTex {
    static TEX: OnceLock<SmaaSearchTex> = OnceLock::new();
    TEX.get_or_init(SmaaSearchTex::generate)
}

#[cfg(test)]
#[path = "smaa_search_tests.rs"]
mod tests;
