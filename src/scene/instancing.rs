//! Many-head layouts for the scaling benchmarks: copies of one head side by side.

use super::mesh::Aabb;
use glam::{Mat4, Vec3};

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
