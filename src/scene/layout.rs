//! Where the characters of a many-character scene stand: a crowd receding in
//! depth from a fixed camera (what the multi-character benchmarks use), or the
//! old grid of heads side by side facing the camera (kept for comparisons).

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};
use serde::Serialize;

use super::mesh::Aabb;

/// How `--heads N` places the characters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// A crowd in rows receding from the camera, as a game would stage it: the
    /// first character where a single one would be, the others behind it,
    /// spaced like people standing, filling the view's width row by row.
    Crowd,
    /// Heads side by side in a grid facing the camera; the camera pulls back
    /// until the grid fills the frame.
    Grid,
}

impl std::str::FromStr for Layout {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "crowd" => Ok(Layout::Crowd),
            "grid" => Ok(Layout::Grid),
            other => bail!("unknown layout '{other}' (valid: crowd, grid)"),
        }
    }
}

/// Side-by-side distance between people standing in a crowd, in head heights:
/// about 0.7 m shoulder to shoulder for a 0.23 m head.
pub const CROWD_SPACING_HEADS: f32 = 3.0;
/// Front-to-back distance between rows of a crowd, in head heights (about 1.15 m).
pub const CROWD_ROW_HEADS: f32 = 5.0;

/// `n` model matrices for a crowd seen by a camera at `eye_distance` (scene
/// units) in front of the first character along `forward`, with a view
/// `half_width` (scene units per unit of distance: tan(fovy/2) x aspect)
/// across. Row r stands r x `CROWD_ROW_HEADS` head heights further back and
/// holds as many characters as fit across the view at its distance (at least
/// one more than the row before). Characters face the camera.
pub fn crowd(
    n: u32,
    head_height: f32,
    forward: Vec3,
    eye_distance: f32,
    half_width: f32,
) -> Vec<Mat4> {
    let forward = forward.try_normalize().unwrap_or(Vec3::Z);
    let side = Vec3::Y.cross(forward).try_normalize().unwrap_or(Vec3::X);
    let spacing = CROWD_SPACING_HEADS * head_height;
    let mut out = Vec::with_capacity(n as usize);
    let mut row = 0u32;
    let mut prev_count = 0u32;
    while (out.len() as u32) < n {
        let back = row as f32 * CROWD_ROW_HEADS * head_height;
        let width = 2.0 * half_width * (eye_distance + back);
        let fit = (width / spacing).floor() as u32;
        let count = fit.max(prev_count + 1).min(n - out.len() as u32);
        for i in 0..count {
            // Centred on the view axis; counts grow row by row, so neighbouring
            // rows alternate between odd and even counts and stand staggered.
            let lateral = (i as f32 - 0.5 * (count - 1) as f32) * spacing;
            out.push(Mat4::from_translation(side * lateral - forward * back));
        }
        prev_count = count;
        row += 1;
    }
    out
}

/// Spacing between neighbouring heads, in head widths/heights, so they never touch.
const SPACING: f32 = 1.3;

/// `n` model matrices placing heads in a grid in the plane facing +Z (the camera's view
/// of the face): columns = ceil(sqrt n) so the grid is as square as possible, centred on
/// the original head's centre. `n = 1` gives the identity.
pub fn head_grid(n: u32, head_bounds: &Aabb) -> Vec<Mat4> {
    let size = head_bounds.size();
    let cols = (n as f32).sqrt().ceil().max(1.0) as u32;
    let rows = n.div_ceil(cols).max(1);
    let (dx, dy) = (SPACING * size.x, SPACING * size.y);
    (0..n)
        .map(|i| {
            let (col, row) = ((i % cols) as f32, (i / cols) as f32);
            let x = (col - (cols - 1) as f32 * 0.5) * dx;
            let y = ((rows - 1) as f32 * 0.5 - row) * dy;
            Mat4::from_translation(Vec3::new(x, y, 0.0))
        })
        .collect()
}

/// Bounds of all `n` heads of `head_grid`, for the camera and the shadow frustum.
pub fn grid_bounds(n: u32, head_bounds: &Aabb) -> Aabb {
    head_grid(n, head_bounds)
        .iter()
        .map(|m| head_bounds.transformed(m))
        .reduce(|a, b| a.union(&b))
        .unwrap_or(*head_bounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head() -> Aabb {
        Aabb {
            min: Vec3::new(-8.0, -11.5, -10.0),
            max: Vec3::new(9.0, 11.5, 12.0),
        }
    }

    fn dist2(a: &Mat4, b: &Mat4) -> f32 {
        a.w_axis.truncate().distance(b.w_axis.truncate())
    }

    // A crowd: the first character where a single one stands, rows receding,
    // nobody closer to anyone than the spacing, everyone facing the camera and
    // within the view's width at their distance once rows can hold them.
    #[test]
    fn crowd_recedes_in_rows_within_the_view() {
        let h = 23.0;
        let d = 5.67 * h;
        let half_width = (10f32).to_radians().tan() * 16.0 / 9.0;
        assert_eq!(crowd(1, h, Vec3::Z, d, half_width), vec![Mat4::IDENTITY]);
        for n in [4, 16, 64] {
            let c = crowd(n, h, Vec3::Z, d, half_width);
            assert_eq!(c.len(), n as usize);
            assert_eq!(c[0], Mat4::IDENTITY);
            for i in 0..c.len() {
                for j in i + 1..c.len() {
                    assert!(
                        dist2(&c[i], &c[j]) >= CROWD_SPACING_HEADS * h - 1e-3,
                        "{n}: {i} {j}"
                    );
                }
                let p = c[i].w_axis.truncate();
                assert!(p.z <= 0.0 && p.y == 0.0, "{p}");
                // Within the view (with half a spacing of slack for the row ends).
                let at = d - p.z;
                assert!(
                    p.x.abs() <= half_width * at + 0.5 * CROWD_SPACING_HEADS * h,
                    "{n}: {p}"
                );
            }
            // Receding: depth never decreases along the list.
            for w in c.windows(2) {
                assert!(w[1].w_axis.z <= w[0].w_axis.z);
            }
        }
        // Most of a big crowd is far: more than half beyond 20 head heights.
        let c = crowd(64, h, Vec3::Z, d, half_width);
        let far = c.iter().filter(|m| d - m.w_axis.z > 20.0 * h).count();
        assert!(far > 32, "{far}");
    }

    #[test]
    fn layouts_parse() {
        assert_eq!("crowd".parse::<Layout>().unwrap(), Layout::Crowd);
        assert_eq!(" Grid".parse::<Layout>().unwrap(), Layout::Grid);
        assert!("ring"
            .parse::<Layout>()
            .unwrap_err()
            .to_string()
            .contains("valid: crowd, grid"));
    }

    #[test]
    fn one_head_is_identity() {
        assert_eq!(head_grid(1, &head()), vec![Mat4::IDENTITY]);
        assert_eq!(grid_bounds(1, &head()), head());
        assert!(head_grid(0, &head()).is_empty());
    }

    #[test]
    fn heads_never_overlap_and_grid_is_centred() {
        for n in [2, 3, 5, 9, 16, 17, 100] {
            let ms = head_grid(n, &head());
            assert_eq!(ms.len(), n as usize);
            let boxes: Vec<Aabb> = ms.iter().map(|m| head().transformed(m)).collect();
            for i in 0..boxes.len() {
                for j in i + 1..boxes.len() {
                    assert!(!boxes[i].overlaps(&boxes[j]), "n={n}: {i} and {j} overlap");
                }
            }
            assert_eq!(grid_bounds(n, &head()).size().z, head().size().z);
        }
        // A full square grid is exactly centred.
        let g = grid_bounds(9, &head());
        assert!((g.center() - head().center()).length() < 1e-3);
        let cols = grid_bounds(4, &head()).size();
        assert!((cols.x / cols.y - head().size().x / head().size().y).abs() < 1e-3);
    }
}
