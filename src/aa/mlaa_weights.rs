//! CPU mirror of MLAA's blending-weight pass (thesis ch. 9.4, Listings
//! 9.2-9.4; `shaders/mlaa_weights.frag`), what the GPU pass is checked
//! against: per edgel, the distances to the ends of its line found with
//! bilinear fetches that read two edgels each (`Edges::bilinear`, the GPU's
//! filter with clamp to edge), the crossing edges fetched a quarter pixel
//! across, and the line's areas. The searches stop where the *line* ends, not
//! at a crossing edge, and a fetch of 0.5 is taken as the nearer pixel of its
//! pair (ch. 9.4.1's two inaccuracies): the mirror makes the same choices.
//!
//! Frame: a top edgel's line runs left to right along the pixel's top
//! boundary, a left edgel's top to bottom along its left one; "left"/"right"
//! of `revector` are then up/down, and "above" the column to the left.

use super::edges::{Channel, Edges};
use super::revector::{Crossing, Pattern};

/// Bilinear fetches per search direction (Listing 9.3's `maxSearchSteps`;
/// `shader_constants::MLAA_MAX_SEARCH_STEPS`).
pub const MAX_SEARCH_STEPS: usize = 4;
/// The searches' reach each way, pixels: two per fetch.
pub const SEARCH_DISTANCE: usize = 2 * MAX_SEARCH_STEPS;

/// One edgel's line as the pass sees it: the crossing edges at both ends
/// (`None` for a fetched value no pair of edgels gives, which the shader's
/// `round(4 e)` sends to the area texture's empty code-2 texels) and the
/// distances to them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub pattern: Option<Pattern>,
    pub left: usize,
    pub right: usize,
}

/// Listing 9.3 in pixel units: from the pixel centred at `centre`, the
/// distance along `dir` to the end of its line in `channel`.
pub fn search_distance(edges: &Edges, centre: [f32; 2], dir: [f32; 2], channel: Channel) -> f32 {
    let mut at = [centre[0] + 1.5 * dir[0], centre[1] + 1.5 * dir[1]];
    let mut e = 0.0;
    let mut i = 0;
    while i < MAX_SEARCH_STEPS {
        e = edges.bilinear(channel, at[0], at[1]);
        if e < 0.9 {
            break;
        }
        at = [at[0] + 2.0 * dir[0], at[1] + 2.0 * dir[1]];
        i += 1;
    }
    (2.0 * i as f32 + 2.0 * e).min(SEARCH_DISTANCE as f32)
}

fn line(edges: &Edges, x: usize, y: usize, top: bool) -> Line {
    let c = [x as f32 + 0.5, y as f32 + 0.5];
    // Along the line, and which edgels it and its crossing edges are.
    let (along, line_ch, cross_ch) = if top {
        ([1.0, 0.0], Channel::Top, Channel::Left)
    } else {
        ([0.0, 1.0], Channel::Left, Channel::Top)
    };
    let back = [-along[0], -along[1]];
    let d_left = search_distance(edges, c, back, line_ch).round();
    let d_right = search_distance(edges, c, along, line_ch).round();
    // A quarter pixel toward the side the edgel does not belong to.
    let across = [-0.25 * along[1], -0.25 * along[0]];
    let fetch = |d: f32| {
        edges.bilinear(
            cross_ch,
            c[0] + d * along[0] + across[0],
            c[1] + d * along[1] + across[1],
        )
    };
    let e1 = Crossing::from_fetched(fetch(-d_left));
    let e2 = Crossing::from_fetched(fetch(d_right + 1.0));
    Line {
        pattern: e1.zip(e2).map(|(left, right)| Pattern { left, right }),
        left: d_left as usize,
        right: d_right as usize,
    }
}

/// The line of pixel `(x, y)`'s top edgel, `None` without one.
pub fn top_line(edges: &Edges, x: usize, y: usize) -> Option<Line> {
    edges.at(x, y).top.then(|| line(edges, x, y, true))
}

/// The line of pixel `(x, y)`'s left edgel, `None` without one.
pub fn left_line(edges: &Edges, x: usize, y: usize) -> Option<Line> {
    edges.at(x, y).left.then(|| line(edges, x, y, false))
}

/// The weights texture the pass writes: per pixel, its top edgel's two areas
/// in `[0..2]`, its left edgel's in `[2..4]`; `area` gives a line's areas.
pub fn weights(edges: &Edges, area: impl Fn(&Line) -> [f32; 2]) -> Vec<[f32; 4]> {
    let mut out = vec![[0.0; 4]; edges.width * edges.height];
    for y in 0..edges.height {
        for x in 0..edges.width {
            let w = &mut out[y * edges.width + x];
            if let Some(l) = top_line(edges, x, y) {
                [w[0], w[1]] = area(&l);
            }
            if let Some(l) = left_line(edges, x, y) {
                [w[2], w[3]] = area(&l);
            }
        }
    }
    out
}

/// The pixels passes 2 and 3 run on: an edgel on any of their four sides
/// (their own left and top, the right neighbour's left, the bottom one's top:
/// Listing 9.1's four deltas), which pass 1 marks in the stencil.
pub fn edge_pixels(edges: &Edges) -> Vec<bool> {
    let (w, h) = (edges.width, edges.height);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let e = edges.at(x, y);
            e.left
                || e.top
                || (x + 1 < w && edges.at(x + 1, y).left)
                || (y + 1 < h && edges.at(x, y + 1).top)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aa::edges::{mlaa_luma_edges, Image, MLAA_LUMA_THRESHOLD};
    use crate::aa::revector;

    /// A rising staircase: runs of `n` pixels, one row up per run (white
    /// below, black above), from row `y0` at the left.
    fn staircase(w: usize, h: usize, n: usize, y0: usize) -> Vec<[f32; 4]> {
        (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let v = if y + x / n >= y0 { 1.0 } else { 0.0 };
                [v, v, v, 1.0]
            })
            .collect()
    }

    // The chapter's Z: a run of n between a crossing edge below at its left end
    // and one above at its right is a line from height -1/2 to +1/2, whose two
    // triangles hold n/8 each: the run's weights sum to n/4 (ch. 9.2, Fig. 9.2).
    #[test]
    fn a_staircase_gets_z_lines_whose_areas_sum_to_a_quarter_of_the_run() {
        for n in [3, 5, 8, 9] {
            let (w, h) = (64, 24);
            let px = staircase(w, h, n, 20);
            let edges =
                mlaa_luma_edges(&Image::new(w, h, &px).unwrap(), MLAA_LUMA_THRESHOLD).unwrap();
            // An interior run: columns [k n, k n + n), its top edgels on row 20 - k.
            let k = 2;
            let row = 20 - k;
            let mut sum = 0.0;
            for x in k * n..k * n + n {
                let l = top_line(&edges, x, row).expect("a top edgel");
                let p = l.pattern.expect("a decodable pattern");
                assert_eq!(p.index(), 9, "n {n} x {x}: a rising Z");
                assert_eq!(
                    (l.left, l.right),
                    (x - k * n, k * n + n - 1 - x),
                    "n {n} x {x}"
                );
                let a = revector::area(p, l.left as f64, l.right as f64, 0.0, None);
                sum += a[0] + a[1];
            }
            assert!((sum - n as f64 / 4.0).abs() < 1e-9, "n {n}: {sum}");
        }
    }

    #[test]
    fn searches_stop_at_their_reach_and_at_the_lines_end() {
        // A white block under a black one, columns 0..37: a long top edge.
        let (w, h) = (40, 4);
        let px: Vec<[f32; 4]> = (0..w * h)
            .map(|i| {
                let white = i / w >= 2 && i % w < 37;
                if white {
                    [1.0; 4]
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                }
            })
            .collect();
        let edges = mlaa_luma_edges(&Image::new(w, h, &px).unwrap(), MLAA_LUMA_THRESHOLD).unwrap();
        // Every search runs its four fetches.
        let l = top_line(&edges, 20, 2).unwrap();
        assert_eq!((l.left, l.right), (SEARCH_DISTANCE, SEARCH_DISTANCE));
        // The last pair read holds one edgel (0.5): the line's last pixel is 36.
        let l = top_line(&edges, 33, 2).unwrap();
        assert_eq!(l.right, 3);
        // Rows 1 and 2 over columns 0..=36, and the block's right side (two
        // left edgels at column 37) adds (37, 2), (37, 3) and (36, 3).
        let counted = edge_pixels(&edges).iter().filter(|&&e| e).count();
        assert_eq!(counted, 2 * 37 + 3);
    }
}
