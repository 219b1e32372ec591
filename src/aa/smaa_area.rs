//! SMAA's area texture (thesis ch. 10.4.2, 10.4.3): the orthogonal table of
//! MLAA (ch. 9.4.3) extended to longer lines, subpixel offsets and diagonal
//! patterns, at the size and layout `SMAA.hlsl` addresses (ANCHORS.md):
//! 160 x 560 texels, two channels.
//!
//! Layout, rows top to bottom (row 0 is the first in memory, the one Vulkan
//! samples at `v = 0`; no flip, see `tests::vulkan_rows_hold_the_*`):
//! - columns 0..80, the orthogonal half: for each of the 7 subpixel offsets
//!   (`ORTHO_OFFSETS`, offset index `k` in rows `80 k .. 80 k + 80`) a 5 x 5
//!   grid of 16 x 16 tiles, tile (column, row) = the crossing-edge codes
//!   `round(4 e1)`, `round(4 e2)` (0, 1, 3, 4; tiles of code 2 stay empty as in
//!   MLAA). Inside a tile, texel `(x, y)` holds the areas for distances
//!   `(x^2, y^2)`: the quadratic compression, so 16 texels reach 225 pixels
//!   and the shader reads `sqrt(d)` with bilinear filtering.
//! - columns 80..160, the diagonal half: for each of the 5 diagonal offsets
//!   (`DIAG_OFFSETS`, rows `80 k ..`) a 4 x 4 grid of 20 x 20 tiles, distances
//!   stored linearly. Rows 400..560 of this half are unused (zero).
//!
//! Channel 0 (`.r`) is the weight with which the edgel's pixel takes the
//! colour across the edge, channel 1 (`.g`) the weight with which the pixel
//! across takes the edgel's colour (`revector`'s frame).

use std::sync::OnceLock;

use super::revector::{self, Pattern, USmoothing};
use super::smaa_diag;

/// Texture width: two halves of 80.
pub const WIDTH: usize = 160;
/// Texture height: 7 offsets x 80.
pub const HEIGHT: usize = 560;
/// Orthogonal tile side (`SMAA_AREATEX_MAX_DISTANCE`).
pub const ORTHO_TILE: usize = 16;
/// Diagonal tile side (`SMAA_AREATEX_MAX_DISTANCE_DIAG`).
pub const DIAG_TILE: usize = 20;
/// Rows per subpixel offset (`SMAA_AREATEX_SUBTEX_SIZE = 1/7` of the height).
pub const SUBTEX_ROWS: usize = HEIGHT / 7;

/// The orthogonal subpixel offsets by index (`subsampleIndices.y`): 0 for
/// SMAA 1x, +-0.25 for S2x/T2x (Fig. 10.11), +-0.125 and +-0.375 for 4x.
pub const ORTHO_OFFSETS: [f64; 7] = [0.0, -0.25, 0.25, -0.125, 0.125, -0.375, 0.375];
/// The diagonal subpixel offsets by index (`subsampleIndices.z`).
pub const DIAG_OFFSETS: [(f64, f64); 5] = [
    (0.0, 0.0),
    (0.25, -0.25),
    (-0.25, 0.25),
    (0.125, -0.125),
    (-0.125, 0.125),
];

/// U shapes shorter than this are softened (SMAA's released table).
pub const U_SMOOTHING: USmoothing = USmoothing { max_distance: 32.0 };

/// The area texture, `WIDTH x HEIGHT` texels, row-major, row 0 first.
#[derive(Clone, Debug, PartialEq)]
pub struct SmaaAreaTex {
    pub texels: Vec<[f32; 2]>,
}

/// The orthogonal tile of a pattern: (column, row) = (left, right) codes.
pub fn ortho_tile(pattern: Pattern) -> (usize, usize) {
    (pattern.left.code(), pattern.right.code())
}

/// The texel of an orthogonal pattern at tile texel `(x, y)`, i.e. distances
/// `(x^2, y^2)`, for offset index `k`.
pub fn ortho_texel(pattern: Pattern, x: usize, y: usize, k: usize) -> (usize, usize) {
    let (tx, ty) = ortho_tile(pattern);
    (tx * ORTHO_TILE + x, SUBTEX_ROWS * k + ty * ORTHO_TILE + y)
}

/// The texel of a diagonal pattern at distances `(l, r)`, offset index `k`.
pub fn diag_texel(pattern: usize, l: usize, r: usize, k: usize) -> (usize, usize) {
    let (tx, ty) = smaa_diag::tile(pattern);
    (
        WIDTH / 2 + tx * DIAG_TILE + l,
        SUBTEX_ROWS * k + ty * DIAG_TILE + r,
    )
}

/// `SMAAArea`'s texture coordinate: `16 round(4 e) + sqrt(d)`, scaled to the
/// texture with a half-texel bias, moved down `k / 7` for offset index `k`.
/// Coordinates as Vulkan (and D3D) read them: `v = 0` is row 0.
pub fn ortho_texcoord(sqrt_d: [f32; 2], e1: f32, e2: f32, k: usize) -> [f32; 2] {
    let t = [
        ORTHO_TILE as f32 * (4.0 * e1).round() + sqrt_d[0],
        ORTHO_TILE as f32 * (4.0 * e2).round() + sqrt_d[1],
    ];
    [
        (t[0] + 0.5) / WIDTH as f32,
        (t[1] + 0.5) / HEIGHT as f32 + k as f32 / 7.0,
    ]
}

/// `SMAAAreaDiag`'s texture coordinate: `20 e + d` (e the crossing codes
/// 0..3), half-texel bias, the right half of the texture, offset index `k`.
pub fn diag_texcoord(d: [f32; 2], e: [f32; 2], k: usize) -> [f32; 2] {
    let t = [
        DIAG_TILE as f32 * e[0] + d[0],
        DIAG_TILE as f32 * e[1] + d[1],
    ];
    [
        (t[0] + 0.5) / WIDTH as f32 + 0.5,
        (t[1] + 0.5) / HEIGHT as f32 + k as f32 / 7.0,
    ]
}

impl SmaaAreaTex {
    /// Every orthogonal and diagonal offset (they cost little: see docs/aa.md
    /// for the measured time), so the multi-sample modes find their tables.
    pub fn generate() -> Self {
        let mut texels = vec![[0.0f32; 2]; WIDTH * HEIGHT];
        for (k, &offset) in ORTHO_OFFSETS.iter().enumerate() {
            for i in 0..16 {
                let p = Pattern::from_index(i);
                for y in 0..ORTHO_TILE {
                    for x in 0..ORTHO_TILE {
                        let (l, r) = ((x * x) as f64, (y * y) as f64);
                        let a = revector::area(p, l, r, offset, Some(U_SMOOTHING));
                        let (cx, cy) = ortho_texel(p, x, y, k);
                        texels[cy * WIDTH + cx] = a.map(|v| v as f32);
                    }
                }
            }
        }
        for (k, &offset) in DIAG_OFFSETS.iter().enumerate() {
            for p in 0..16 {
                for r in 0..DIAG_TILE {
                    for l in 0..DIAG_TILE {
                        let a = smaa_diag::area(p, l as f64, r as f64, offset);
                        let (cx, cy) = diag_texel(p, l, r, k);
                        texels[cy * WIDTH + cx] = a.map(|v| v as f32);
                    }
                }
            }
        }
        Self { texels }
    }

    /// The two areas at a texel.
    pub fn at(&self, x: usize, y: usize) -> [f32; 2] {
        self.texels[y * WIDTH + x]
    }

    /// The areas of an orthogonal pattern at tile texel `(x, y)` (distances
    /// `x^2`, `y^2`), offset index `k`.
    pub fn ortho_at(&self, pattern: Pattern, x: usize, y: usize, k: usize) -> [f32; 2] {
        let (cx, cy) = ortho_texel(pattern, x, y, k);
        self.at(cx, cy)
    }

    /// R8G8 unorm bytes, row 0 first: the upload for a `R8G8_UNORM` image
    /// sampled with the coordinates above.
    pub fn rg8(&self) -> Vec<u8> {
        self.texels
            .iter()
            .flat_map(|a| a.map(|v| revector::to_unorm8(f64::from(v))))
            .collect()
    }
}

/// The table, generated once per process.
pub fn area_tex() -> &'static SmaaAreaTex {
    static TEX: OnceLock<SmaaAreaTex> = OnceLock::new();
    TEX.get_or_init(SmaaAreaTex::generate)
}

/// Its upload bytes, converted once per process.
pub fn area_tex_rg8() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| area_tex().rg8())
}

#[cfg(test)]
#[path = "smaa_area_tests.rs"]
mod tests;
