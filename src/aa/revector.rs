//! The orthogonal re-vectorisation shared by MLAA (thesis ch. 9.2, 9.4.3) and
//! SMAA (ch. 10.3, 10.4.2): a line of edgels is classified by its *crossing
//! edges* at both ends, and the silhouette it stands for is rebuilt as one or
//! two straight segments whose area over each pixel is the blending weight `a`
//! of Eq. 9.1, `c_new = (1 - a) c_old + a c_opp`.
//!
//! Frame (the same for every texture built from it): `x` runs along the line,
//! from 0 at the left edge of its leftmost pixel to `d = left + right + 1` at
//! the right edge of its rightmost one, so the pixel at distance `left` from
//! the left end is `[left, left + 1]`. `y` is measured in pixels from the edge,
//! positive toward the side the edgel does not belong to ("above": the row
//! above for a top edgel, the column to the left for a left edgel). Area under
//! the edge (`y < 0`) is the part of the edgel's own pixel that the other side
//! covers: channel 0, the weight with which that pixel takes the other's colour
//! (SMAA's `.r` / `.b`). Area above (`y > 0`) is the weight with which the
//! pixel across the edge takes the owner's colour: channel 1 (`.g` / `.a`).
//! At offset 0 both are non-zero only for the centre pixel of a Z of odd length
//! (ch. 9.4); a subpixel offset moves that crossing point along the line.

/// Crossing edges at one end of a line (ch. 9.4.2, Fig. 9.4): the edgels
/// perpendicular to the line at the boundary just past its last pixel, on the
/// edgel owner's side (`below`) and on the other side (`above`). For a vertical
/// line "below" is the owner's column (right of the edge), "above" the column
/// to its left.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Crossing {
    pub below: bool,
    pub above: bool,
}

impl Crossing {
    /// All four, in the order of their codes 0, 1, 3, 4.
    pub const ALL: [Crossing; 4] = [
        Crossing::new(false, false),
        Crossing::new(false, true),
        Crossing::new(true, false),
        Crossing::new(true, true),
    ];

    pub const fn new(below: bool, above: bool) -> Self {
        Self { below, above }
    }

    /// The value of the bilinear fetch the blending pass makes a quarter pixel
    /// toward the "above" side (Listing 9.2's `-0.25`): the owner's row weighs
    /// 0.75 and the other 0.25, so the four cases give four distinct values
    /// (Fig. 9.4) and 0.5 never occurs.
    pub fn fetched(self) -> f32 {
        0.75 * f32::from(u8::from(self.below)) + 0.25 * f32::from(u8::from(self.above))
    }

    /// Listing 9.4's `round(4 e)`: 0, 1, 3 or 4, the subtexture column (left
    /// end) or row (right end). 2 would be `e = 0.5`, which cannot occur.
    pub fn code(self) -> usize {
        3 * usize::from(self.below) + usize::from(self.above)
    }

    /// The crossing edges a fetched value encodes, as the shaders decode it
    /// (round to the nearest quarter, which absorbs filtering error); `None`
    /// for a value no pair of edgels produces.
    pub fn from_fetched(e: f32) -> Option<Self> {
        if !e.is_finite() {
            return None;
        }
        let code = (4.0 * e).round();
        Self::ALL.into_iter().find(|c| c.code() as f32 == code)
    }
}

/// One of the 16 orthogonal patterns: the crossing edges at both ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Pattern {
    pub left: Crossing,
    pub right: Crossing,
}

impl Pattern {
    /// The index SMAA's reference and this crate use to list the patterns:
    /// bit 0 left end below, bit 1 right end below, bit 2 left end above,
    /// bit 3 right end above (so 6 and 9 are the two Z shapes, 3 and 12 the U's).
    pub fn index(self) -> usize {
        usize::from(self.left.below)
            | usize::from(self.right.below) << 1
            | usize::from(self.left.above) << 2
            | usize::from(self.right.above) << 3
    }

    /// The pattern of an index (only its low four bits are read).
    pub fn from_index(i: usize) -> Self {
        let bit = |k: usize| i >> k & 1 == 1;
        Self {
            left: Crossing::new(bit(0), bit(2)),
            right: Crossing::new(bit(1), bit(3)),
        }
    }

    /// The same line seen from its other end (left and right swapped).
    pub fn mirrored(self) -> Self {
        Self {
            left: self.right,
            right: self.left,
        }
    }

    /// The same line seen from its other side (above and below swapped).
    pub fn flipped(self) -> Self {
        let f = |c: Crossing| Crossing::new(c.above, c.below);
        Self {
            left: f(self.left),
            right: f(self.right),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Below,
    Above,
}

/// Which way the silhouette leaves the line at one end, and whether that was
/// read off a crossing edge on both sides.
fn end_side(this: Crossing, other: Crossing) -> Option<(Side, bool)> {
    match (this.below, this.above) {
        (false, false) => None,
        (true, false) => Some((Side::Below, false)),
        (false, true) => Some((Side::Above, false)),
        // A crossing line on both sides says nothing by itself; beside a
        // one-sided other end the shape is the Z through it (the silhouette
        // cannot leave on the same side twice without a U's second crossing).
        (true, true) => match (other.below, other.above) {
            (true, false) => Some((Side::Above, true)),
            (false, true) => Some((Side::Below, true)),
            _ => None,
        },
    }
}

/// A straight piece of the re-vectorised silhouette, `x0 < x1`.
#[derive(Clone, Copy, Debug)]
struct Segment {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Segment {
    fn y(&self, x: f64) -> f64 {
        self.y0 + (self.y1 - self.y0) * (x - self.x0) / (self.x1 - self.x0)
    }

    /// The exact areas between the segment and the edge over the pixel column
    /// `[x, x + 1]`, split by side: `[under the edge, over the edge]`. Only the
    /// part of the column the segment spans counts.
    fn areas(&self, x: f64) -> [f64; 2] {
        let a = x.max(self.x0);
        let b = (x + 1.0).min(self.x1);
        if b <= a {
            return [0.0, 0.0];
        }
        let (ya, yb) = (self.y(a), self.y(b));
        let mut out = [0.0, 0.0];
        let mut add = |y0: f64, y1: f64, w: f64| {
            // One sign over the piece: a trapezoid.
            let m = 0.5 * (y0 + y1) * w;
            if m < 0.0 {
                out[0] -= m;
            } else {
                out[1] += m;
            }
        };
        if ya * yb < 0.0 {
            // The segment crosses the edge inside the column: two triangles.
            let t = a + (b - a) * ya / (ya - yb);
            add(ya, 0.0, t - a);
            add(0.0, yb, b - t);
        } else {
            add(ya, yb, b - a);
        }
        out
    }
}

fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

/// How U shapes are softened (SMAA's released area texture, not in the thesis):
/// a short U is a thin feature that a full re-vectorisation would over-blur, so
/// each half's area `a` is pulled toward `sqrt(2 a) / 2` for lines shorter than
/// `max_distance`, blending linearly back to `a` at that length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct USmoothing {
    pub max_distance: f64,
}

fn smooth(a: [f64; 2], d: f64, s: Option<USmoothing>) -> [f64; 2] {
    let Some(s) = s else { return a };
    let p = (d / s.max_distance).clamp(0.0, 1.0);
    a.map(|v| {
        let b = (2.0 * v).sqrt() * 0.5;
        b + (v - b) * p
    })
}

/// The blending areas `[own pixel, pixel across]` of the pixel at distances
/// `left` and `right` from the ends of a line with crossing edges `pattern`,
/// its silhouette shifted by a subpixel `offset` along `y` (0 for MLAA and
/// SMAA 1x; SMAA's multi-sample modes use +-0.125 .. +-0.375, ch. 10.4.3).
///
/// The shapes (ch. 9.2, Fig. 9.2; Reshetov's L, Z and U): a segment from the
/// middle of each crossing edge (height +-1/2 at the end) to the middle of the
/// line (`d / 2`, height 0) for an L; one segment from end to end for a Z; two
/// halves for a U. A Z of a multi-sample mode is averaged with its two halves
/// so that its middle pixels agree with the L's its ends see when the search
/// stops short (SMAA's reference does the same).
pub fn area(
    pattern: Pattern,
    left: f64,
    right: f64,
    offset: f64,
    smoothing: Option<USmoothing>,
) -> [f64; 2] {
    let d = left + right + 1.0;
    let height = |s: Side| match s {
        Side::Above => 0.5 + offset,
        Side::Below => offset - 0.5,
    };
    let to_middle = |s: Side| Segment {
        x0: 0.0,
        y0: height(s),
        x1: d / 2.0,
        y1: 0.0,
    };
    let from_middle = |s: Side| Segment {
        x0: d / 2.0,
        y0: 0.0,
        x1: d,
        y1: height(s),
    };
    match (
        end_side(pattern.left, pattern.right),
        end_side(pattern.right, pattern.left),
    ) {
        (None, None) => [0.0, 0.0],
        (Some((l, _)), None) => to_middle(l).areas(left),
        (None, Some((r, _))) => from_middle(r).areas(left),
        (Some((l, _)), Some((r, _))) if l == r => {
            let a1 = smooth(to_middle(l).areas(left), d, smoothing);
            let a2 = smooth(from_middle(r).areas(left), d, smoothing);
            add(a1, a2)
        }
        (Some((l, lb)), Some((r, rb))) => {
            let z = Segment {
                x0: 0.0,
                y0: height(l),
                x1: d,
                y1: height(r),
            }
            .areas(left);
            if offset == 0.0 || lb || rb {
                z
            } else {
                let halves = add(to_middle(l).areas(left), from_middle(r).areas(left));
                add(z, halves).map(|v| v / 2.0)
            }
        }
    }
}

/// An area in [0, 1] as an 8-bit unorm, rounded to nearest as Vulkan's
/// float-to-unorm conversion does (iryoku's script truncates instead; the
/// values then differ by at most one step).
pub fn to_unorm8(a: f64) -> u8 {
    (a.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPS: f64 = 1e-12;

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < EPS && (a[1] - b[1]).abs() < EPS
    }

    #[test]
    fn codes_and_fetches_are_the_listings() {
        let codes: Vec<usize> = Crossing::ALL.iter().map(|c| c.code()).collect();
        assert_eq!(codes, vec![0, 1, 3, 4]);
        for c in Crossing::ALL {
            assert_eq!((4.0 * c.fetched()).round() as usize, c.code());
            assert_eq!(Crossing::from_fetched(c.fetched()), Some(c));
            // A filtering error under an eighth still decodes.
            assert_eq!(Crossing::from_fetched(c.fetched() + 0.1), Some(c));
        }
        assert_eq!(Crossing::from_fetched(0.5), None);
        assert_eq!(Crossing::from_fetched(f32::NAN), None);
    }

    #[test]
    fn pattern_indices_round_trip_and_name_the_shapes() {
        for i in 0..16 {
            assert_eq!(Pattern::from_index(i).index(), i);
        }
        // 1: left end turns down; 8: right end turns up.
        assert_eq!(Pattern::from_index(1).left, Crossing::new(true, false));
        assert_eq!(Pattern::from_index(8).right, Crossing::new(false, true));
        assert_eq!(Pattern::from_index(6).mirrored().index(), 9);
        assert_eq!(Pattern::from_index(3).flipped().index(), 12);
    }

    #[test]
    fn segment_areas_are_exact_trapezoids_and_triangles() {
        let s = Segment {
            x0: 0.0,
            y0: -0.5,
            x1: 4.0,
            y1: 0.5,
        };
        // Pixel 0: y from -0.5 to -0.25, all under the edge.
        assert!(close(s.areas(0.0), [0.375, 0.0]));
        // Pixel 1: -0.25 .. 0, a triangle under.
        assert!(close(s.areas(1.0), [0.125, 0.0]));
        assert!(close(s.areas(2.0), [0.0, 0.125]));
        // Outside the segment: nothing.
        assert!(close(s.areas(4.0), [0.0, 0.0]));
        // A crossing inside a column splits it.
        let t = Segment {
            x0: 0.0,
            y0: -0.5,
            x1: 3.0,
            y1: 0.5,
        };
        let a = t.areas(1.0);
        assert!(close(a, [0.5 * 0.5 / 6.0, 0.5 * 0.5 / 6.0]));
    }

    #[test]
    fn no_crossing_or_crossings_on_both_sides_do_nothing() {
        for &(l, r) in &[(0.0, 0.0), (3.0, 5.0), (7.0, 0.0)] {
            for i in [0, 5, 10, 15] {
                let a = area(Pattern::from_index(i), l, r, 0.0, None);
                assert_eq!(a, [0.0, 0.0], "pattern {i} at {l},{r}");
            }
        }
    }
}
