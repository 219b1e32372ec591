//! MLAA's precomputed area texture (thesis ch. 9.4.3, Fig. 9.2 right,
//! Listing 9.4): a 4D table, area as a function of the crossing edges `e1`,
//! `e2` at both ends of a line and of the distances to them, laid out as 5 x 5
//! subtextures of 9 x 9 texels (distances 0..=8, the text's maximum). Each
//! texel holds two areas, for the edgel's own pixel and for its opposite.
//!
//! Addressing (Listing 9.4): the texel of `(e1, e2, d_left, d_right)` is
//! `9 * round(4 e) + d`, column from the left end, row from the right end;
//! codes 2 (`e = 0.5`) never occur, so their row and column stay empty.

use super::revector::{self, Pattern};

/// Distances 0..=8 per subtexture (Listing 9.4's `NUM_DISTANCES`).
pub const NUM_DISTANCES: usize = 9;
/// The texture's side, five subtextures (`AREA_SIZE`): 45.
pub const AREA_SIZE: usize = NUM_DISTANCES * 5;
/// The longest distance the texture holds: the search's reach (ch. 9.4.1:
/// the Xbox 360's `tfetch2D` offsets end at -8 / 7.5).
pub const MAX_DISTANCE: usize = NUM_DISTANCES - 1;

/// The Xbox 360's `tfetch2D` offsets, in pixels from the fetch's own
/// coordinate (ch. 9.4.1: "limited to offsets of -8 and 7.5, which
/// constrains the maximum distance that can be searched"; past eight pixels
/// the hardware is used less efficiently). The lower end, 8 pixels, is
/// MLAA's search reach: `MAX_DISTANCE`, `post::mlaa::SEARCH_DISTANCE`,
/// `shader_constants::MLAA_MAX_SEARCH_STEPS` (2 pixels per bilinear fetch)
/// and the budget's `frames::MLAA_MAX_SEARCH_TAPS` follow from it.
pub const XBOX360_TFETCH2D_MIN_OFFSET_PX: i32 = -8;
/// The upper end, 7.5 pixels, in half pixels (15): a search step lands on a
/// half pixel between two edgels, so 7.5 is the last one within reach.
pub const XBOX360_TFETCH2D_MAX_OFFSET_HALF_PX: i32 = 15;
/// Channels of MLAA's edges target on the Xbox 360 (ch. 9.6, Table 9.2's
/// note: the framework could not create two-channel 8-bit targets, so the
/// edges took four). This port's edges target is four-channel too
/// (`post::mlaa`), so the budget prices the Xbox 360's footprint.
pub const XBOX360_EDGES_TARGET_CHANNELS: usize = 4;

// The reach is the Xbox 360's: 8 pixels back, and 7.5 + 0.5 (the pixel's
// own half) forward.
const _: () = assert!(MAX_DISTANCE as i32 == -XBOX360_TFETCH2D_MIN_OFFSET_PX);
const _: () = assert!(MAX_DISTANCE as i32 == (XBOX360_TFETCH2D_MAX_OFFSET_HALF_PX + 1) / 2);

/// The area texture: `AREA_SIZE`^2 texels, row-major, row 0 first, two
/// channels each (own pixel, opposite pixel; see `revector`'s frame).
#[derive(Clone, Debug, PartialEq)]
pub struct MlaaAreaTex {
    pub texels: Vec<[f32; 2]>,
}

/// The texel (column, row) of a pattern and its distances, `None` past the
/// texture's reach.
pub fn texel(pattern: Pattern, d_left: usize, d_right: usize) -> Option<(usize, usize)> {
    if d_left > MAX_DISTANCE || d_right > MAX_DISTANCE {
        return None;
    }
    Some((
        NUM_DISTANCES * pattern.left.code() + d_left,
        NUM_DISTANCES * pattern.right.code() + d_right,
    ))
}

/// Listing 9.4's access done the way the GPU does it: `texcoord = (9 round(4
/// e) + d) / (AREA_SIZE - 1)` point-sampled with clamp-to-edge on a 45-texel
/// side, i.e. texel `floor(texcoord * 45)` clamped to 44. Its comment says
/// the division by 44 lands inside a texel; this is what `texel` is tested
/// against.
pub fn listing_9_4_texel(distance: [f32; 2], e1: f32, e2: f32) -> (usize, usize) {
    let axis = |e: f32, d: f32| {
        let pixcoord = NUM_DISTANCES as f32 * (4.0 * e).round() + d;
        let texcoord = pixcoord / (AREA_SIZE as f32 - 1.0);
        ((texcoord * AREA_SIZE as f32).floor().max(0.0) as usize).min(AREA_SIZE - 1)
    };
    (axis(e1, distance[0]), axis(e2, distance[1]))
}

impl MlaaAreaTex {
    /// The areas of ch. 9.2 (L, Z and U shapes from the crossing edges; no
    /// subpixel offset, no U smoothing, which SMAA added later).
    pub fn generate() -> Self {
        let mut texels = vec![[0.0f32; 2]; AREA_SIZE * AREA_SIZE];
        for i in 0..16 {
            let p = Pattern::from_index(i);
            for l in 0..=MAX_DISTANCE {
                for r in 0..=MAX_DISTANCE {
                    let Some((x, y)) = texel(p, l, r) else {
                        continue;
                    };
                    let a = revector::area(p, l as f64, r as f64, 0.0, None);
                    texels[y * AREA_SIZE + x] = a.map(|v| v as f32);
                }
            }
        }
        Self { texels }
    }

    /// The two areas at a texel.
    pub fn at(&self, x: usize, y: usize) -> [f32; 2] {
        self.texels[y * AREA_SIZE + x]
    }

    /// The areas of a pattern at its distances, `None` past the reach.
    pub fn area(&self, pattern: Pattern, d_left: usize, d_right: usize) -> Option<[f32; 2]> {
        texel(pattern, d_left, d_right).map(|(x, y)| self.at(x, y))
    }

    /// R8G8 unorm bytes, row 0 first, ready for upload.
    pub fn rg8(&self) -> Vec<u8> {
        self.texels
            .iter()
            .flat_map(|a| a.map(|v| revector::to_unorm8(f64::from(v))))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPS: f32 = 1e-6;

    fn p(i: usize) -> Pattern {
        Pattern::from_index(i)
    }

    fn near(a: [f32; 2], b: [f64; 2]) -> bool {
        (f64::from(a[0]) - b[0]).abs() < 1e-6 && (f64::from(a[1]) - b[1]).abs() < 1e-6
    }

    #[test]
    fn addressing_is_listing_9_4() {
        for i in 0..16 {
            let pat = p(i);
            for l in 0..=MAX_DISTANCE {
                for r in 0..=MAX_DISTANCE {
                    let want = texel(pat, l, r).expect("in reach");
                    let got = listing_9_4_texel(
                        [l as f32, r as f32],
                        pat.left.fetched(),
                        pat.right.fetched(),
                    );
                    assert_eq!(got, want, "pattern {i}, distances {l},{r}");
                }
            }
        }
        assert_eq!(texel(p(0), MAX_DISTANCE + 1, 0), None);
    }

    #[test]
    fn no_crossing_edge_no_area_and_code_2_stays_empty() {
        let t = MlaaAreaTex::generate();
        for l in 0..=MAX_DISTANCE {
            for r in 0..=MAX_DISTANCE {
                assert_eq!(t.area(p(0), l, r), Some([0.0, 0.0]));
            }
        }
        for k in 0..AREA_SIZE {
            for j in 2 * NUM_DISTANCES..3 * NUM_DISTANCES {
                assert_eq!(t.at(j, k), [0.0, 0.0]);
                assert_eq!(t.at(k, j), [0.0, 0.0]);
            }
        }
    }

    #[test]
    fn swapping_the_ends_mirrors_the_table() {
        let t = MlaaAreaTex::generate();
        for i in 0..16 {
            for l in 0..=MAX_DISTANCE {
                for r in 0..=MAX_DISTANCE {
                    let a = t.area(p(i), l, r).expect("in reach");
                    let m = t.area(p(i).mirrored(), r, l).expect("in reach");
                    assert!(near(a, m.map(f64::from)), "pattern {i} at {l},{r}");
                    // Swapping the sides swaps the two channels.
                    let f = t.area(p(i).flipped(), l, r).expect("in reach");
                    assert!(near(a, [f64::from(f[1]), f64::from(f[0])]));
                }
            }
        }
    }

    #[test]
    fn an_l_of_length_n_covers_a_half_pixel_triangle() {
        // Pattern 1: left end turns down. The segment runs from (0, -1/2) to
        // (n/2, 0), so the pixels of the left half hold a total area n/8 on
        // the owner's side, the pixel at distance k the trapezoid between
        // heights 1/2 - k/n and 1/2 - (k+1)/n, and the right half nothing.
        let t = MlaaAreaTex::generate();
        for n in [2usize, 4, 6, 8] {
            let mut total = 0.0;
            for k in 0..n {
                let a = t.area(p(1), k, n - 1 - k).expect("in reach");
                let h = |x: f64| (0.5 - x / n as f64).max(0.0);
                let want = 0.5 * (h(k as f64) + h(k as f64 + 1.0));
                assert!((f64::from(a[0]) - want).abs() < 1e-6, "n {n} k {k}");
                assert_eq!(a[1], 0.0);
                total += a[0];
            }
            assert!((total - n as f32 / 8.0).abs() < EPS);
        }
    }

    #[test]
    fn z_and_u_shapes_have_their_hand_computed_areas() {
        let t = MlaaAreaTex::generate();
        // Z (pattern 9: down at the left, up at the right), length 4: the line
        // from (0, -1/2) to (4, 1/2) is y = x/4 - 1/2.
        let want = [[0.375, 0.0], [0.125, 0.0], [0.0, 0.125], [0.0, 0.375]];
        for (k, w) in want.iter().enumerate() {
            assert!(near(t.area(p(9), k, 3 - k).unwrap(), *w), "z pixel {k}");
        }
        // U (pattern 3: down at both ends), length 4: two L's meeting at 2.
        let want = [[0.375, 0.0], [0.125, 0.0], [0.125, 0.0], [0.375, 0.0]];
        for (k, w) in want.iter().enumerate() {
            assert!(near(t.area(p(3), k, 3 - k).unwrap(), *w), "u pixel {k}");
        }
    }

    #[test]
    fn only_the_centre_of_an_odd_z_has_both_areas() {
        let t = MlaaAreaTex::generate();
        for n in [1usize, 3, 5, 7, 9] {
            for k in 0..n {
                let a = t.area(p(6), k, n - 1 - k).unwrap();
                let both = a[0] > 0.0 && a[1] > 0.0;
                assert_eq!(both, 2 * k + 1 == n, "n {n} k {k}: {a:?}");
                if 2 * k + 1 == n {
                    // Two triangles of half-width 1/2 and height 1/(2n).
                    let tri = 0.5 * 0.5 / (2.0 * n as f32);
                    assert!((a[0] - tri).abs() < EPS && (a[1] - tri).abs() < EPS);
                }
            }
        }
    }

    #[test]
    fn bytes_are_two_per_texel_row_major() {
        let t = MlaaAreaTex::generate();
        let b = t.rg8();
        assert_eq!(b.len(), 2 * AREA_SIZE * AREA_SIZE);
        let (x, y) = texel(p(9), 0, 3).unwrap();
        let i = 2 * (y * AREA_SIZE + x);
        // 0.375 * 255 = 95.6.
        assert_eq!((b[i], b[i + 1]), (96, 0));
    }
}
