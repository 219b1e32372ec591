//! SMAA's diagonal areas (thesis ch. 10.4.2, "Diagonal patterns", Figs. 10.7
//! and 10.8): a near-45-degree line, found by diagonal searches, is classified
//! like an orthogonal one by its distances `d_l`, `d_r` to both ends and its
//! crossing edges `e_1`, `e_2`, and re-vectorised as a diagonal segment instead
//! of a staircase of L's.
//!
//! The frame is the one of SMAA's released table (so a shader following
//! `SMAA.hlsl` reads it unchanged): the line starts at the corner `(1, 0)` and
//! steps `(1, 1)` per pixel; the pixel at distance `left` from the left end is
//! `[1 + left, 2 + left] x [left, 1 + left]` and its opposite is the one above
//! it. The areas are the parts of those two pixels on either side of the
//! segment, computed exactly here by clipping the unit square with the line's
//! half-plane (the released script counts 30 x 30 point samples on a closed
//! grid, whose bias reaches 1/30 where a row of samples lies on the line: its
//! bytes differ from these by -8 .. +5, docs/aa.md).
//!
//! Each end of a diagonal line may be cut by a vertical or a horizontal
//! crossing edge (2 bits, codes 0..3): the segment's end moves one pixel left
//! (vertical) or up (horizontal), Fig. 10.8. Where the crossing edges do not
//! say which (no crossing edge, or only one end known), both candidate ends
//! are averaged, because the neighbouring pattern is unknown.

/// A point of the diagonal frame.
type P = (f64, f64);

/// The corner a diagonal line starts from, or, shifted by `(d, d)`, ends at.
const CORNER: P = (1.0, 0.0);
/// The end moved up a pixel: the line continues as a horizontal edge.
const UP: P = (1.0, 1.0);
/// The end moved left a pixel: the line continues as a vertical edge.
const LEFT: P = (0.0, 0.0);

/// The candidate (start, end - (d, d)) pairs of each of the 16 diagonal
/// patterns (index bits as in `Pattern::index`: 0 and 2 are the left end's
/// crossings, 1 and 3 the right end's), averaged when there are two.
const SHAPES: [&[(P, P)]; 16] = [
    &[(UP, UP), (CORNER, CORNER)],
    &[(CORNER, LEFT), (CORNER, CORNER)],
    &[(LEFT, CORNER), (CORNER, CORNER)],
    &[(CORNER, CORNER)],
    &[(UP, LEFT), (UP, CORNER)],
    &[(UP, LEFT), (CORNER, CORNER)],
    &[(UP, CORNER)],
    &[(UP, CORNER), (CORNER, CORNER)],
    &[(LEFT, UP), (CORNER, UP)],
    &[(CORNER, UP)],
    &[(LEFT, UP), (CORNER, CORNER)],
    &[(CORNER, UP), (CORNER, CORNER)],
    &[(UP, UP)],
    &[(UP, UP), (CORNER, UP)],
    &[(UP, UP), (UP, CORNER)],
    &[(UP, UP), (CORNER, CORNER)],
];

/// The subtexture (column, row) of a diagonal pattern in its 4 x 4 grid: the
/// crossing-edge codes `e_1`, `e_2` of `SMAAAreaDiag` (`2 x + y` of the two
/// decoded edges at each end).
pub fn tile(pattern: usize) -> (usize, usize) {
    let bit = |k: usize| pattern >> k & 1;
    (bit(0) + 2 * bit(2), bit(3) + 2 * bit(1))
}

/// The fraction of the unit pixel with lower-left corner `px` strictly on the
/// right of the directed line `p1 -> p2` (the side the line's normal
/// `(dy, -dx)` points to). A degenerate line covers the whole pixel.
fn right_of(p1: P, p2: P, px: P) -> f64 {
    let n = (p2.1 - p1.1, p1.0 - p2.0);
    if n == (0.0, 0.0) {
        return 1.0;
    }
    let m = (0.5 * (p1.0 + p2.0), 0.5 * (p1.1 + p2.1));
    let side = |q: P| n.0 * (q.0 - m.0) + n.1 * (q.1 - m.1);
    let square = [
        px,
        (px.0 + 1.0, px.1),
        (px.0 + 1.0, px.1 + 1.0),
        (px.0, px.1 + 1.0),
    ];
    // One Sutherland-Hodgman step: keep the square's part with side > 0.
    let mut poly: Vec<P> = Vec::with_capacity(5);
    for k in 0..4 {
        let (a, b) = (square[k], square[(k + 1) % 4]);
        let (sa, sb) = (side(a), side(b));
        if sa > 0.0 {
            poly.push(a);
        }
        if (sa > 0.0) != (sb > 0.0) && sa != sb {
            let t = sa / (sa - sb);
            poly.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
        }
    }
    let mut twice = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        twice += a.0 * b.1 - b.0 * a.1;
    }
    (0.5 * twice).abs()
}

/// The areas `[own pixel, opposite pixel]` of a diagonal `pattern` at distances
/// `left`, `right`, its crossing ends shifted by the subpixel `offset`
/// (`(0, 0)` for SMAA 1x).
pub fn area(pattern: usize, left: f64, right: f64, offset: P) -> [f64; 2] {
    let d = left + right + 1.0;
    let (e1, e2) = tile(pattern);
    let shapes = SHAPES[pattern & 15];
    let mut sum = [0.0, 0.0];
    for &(start, end) in shapes {
        // Only an end fixed by a crossing edge moves with the subsample.
        let shift = |p: P, e: usize| {
            if e > 0 {
                (p.0 + offset.0, p.1 + offset.1)
            } else {
                p
            }
        };
        let p1 = shift(start, e1);
        let p2 = shift((end.0 + d, end.1 + d), e2);
        let a1 = right_of(p1, p2, (1.0 + left, left));
        let a2 = right_of(p1, p2, (1.0 + left, 1.0 + left));
        sum[0] += 1.0 - a1;
        sum[1] += a2;
    }
    let n = shapes.len() as f64;
    sum.map(|v| v / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12
    }

    #[test]
    fn tiles_cover_the_grid_once() {
        let mut seen = [[false; 4]; 4];
        for p in 0..16 {
            let (x, y) = tile(p);
            assert!(!seen[y][x], "pattern {p}");
            seen[y][x] = true;
        }
        assert_eq!(tile(1), (1, 0));
        assert_eq!(tile(2), (0, 2));
    }

    #[test]
    fn half_plane_fractions_are_exact() {
        // The diagonal of a pixel halves it; a line along its edge leaves all
        // or nothing; an upward line at x = 0.25 leaves 3/4 on its right, a
        // downward one 1/4.
        assert!((right_of((0.0, 0.0), (1.0, 1.0), (0.0, 0.0)) - 0.5).abs() < 1e-12);
        assert!((right_of((0.0, 0.0), (1.0, 0.0), (0.0, 0.0))).abs() < 1e-12);
        assert!((right_of((0.0, 1.0), (1.0, 1.0), (0.0, 0.0)) - 1.0).abs() < 1e-12);
        assert!((right_of((0.25, 0.0), (0.25, 1.0), (0.0, 0.0)) - 0.75).abs() < 1e-12);
        assert!((right_of((0.25, 1.0), (0.25, 0.0), (0.0, 0.0)) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn a_clean_diagonal_splits_its_pixels_in_half() {
        // Pattern 3: both ends at the corners, the line runs along the
        // pixels' diagonals: half of the own pixel, none of the opposite one,
        // at every distance.
        for l in 0..20 {
            for r in 0..20 {
                assert!(close(area(3, l as f64, r as f64, (0.0, 0.0)), [0.5, 0.0]));
                // Pattern 12: both ends moved up, the line along the
                // opposite pixel's diagonal.
                assert!(close(area(12, l as f64, r as f64, (0.0, 0.0)), [0.0, 0.5]));
                // Pattern 0: unknown ends, the average of the two.
                assert!(close(area(0, l as f64, r as f64, (0.0, 0.0)), [0.25, 0.25]));
            }
        }
    }

    #[test]
    fn a_bent_end_fades_along_the_line() {
        // Pattern 6: starts a pixel up, ends at the corner: the segment from
        // (1, 1) to (1 + d, d) has slope (d - 1) / d, so the own pixel's area
        // grows from the left end to the right one.
        let (l, r) = (0.0, 9.0);
        let first = area(6, l, r, (0.0, 0.0));
        let last = area(6, r, l, (0.0, 0.0));
        assert!(first[0] < last[0], "{first:?} {last:?}");
        for p in 0..16 {
            for l in 0..20 {
                let a = area(p, l as f64, 3.0, (0.25, -0.25));
                assert!(a.iter().all(|v| (0.0..=1.0).contains(v)), "{p} {l} {a:?}");
            }
        }
    }
}
