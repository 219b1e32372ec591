//! The procedural skull's surface points at the texel centres of its UV
//! square (u = (phi + pi) / 2 pi, v = theta / pi: `face::skull_shell`), over
//! a rectangle of texels: what the face's generated maps (`face_wrinkles`,
//! `face_colour`) place their features by, in millimetres.
//!
//! The rays are the cost (a ray march a point): the skull is marched every
//! `MARCH_STRIDE` texels, on every core, and interpolated between. It is
//! smooth at that spacing (3.5 mm at 512 texels a side; the mesh's own
//! vertices are 1.5 to 8 mm apart).

use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// A skull's surface point (mm) for polar angle theta (from +Y) and azimuth
/// phi (0: the face, +Z).
pub type Skull = fn(f32, f32) -> Vec3;

/// Texels between the surface points marched.
const MARCH_STRIDE: usize = 4;

/// The surface points of texel rows `rows` and columns `cols` (inclusive) of
/// a map `n` texels a side.
pub struct SurfaceGrid {
    first: (usize, usize),
    coarse: (usize, usize),
    points: Vec<Vec<Vec3>>,
}

impl SurfaceGrid {
    pub fn new(skull: Skull, n: usize, rows: (usize, usize), cols: (usize, usize)) -> SurfaceGrid {
        let at = |k: usize| (k as f32 + 0.5) / n as f32;
        // At least two points a side: `point` interpolates between neighbours.
        let coarse = |(k0, k1): (usize, usize)| ((k1 - k0).div_ceil(MARCH_STRIDE) + 1).max(2);
        let (ci, cj) = (coarse(rows), coarse(cols));
        let coarse_rows: Vec<usize> = (0..ci).collect();
        let points = in_parallel(&coarse_rows, |&a| {
            (0..cj)
                .map(|b| {
                    let (i, j) = (rows.0 + a * MARCH_STRIDE, cols.0 + b * MARCH_STRIDE);
                    skull(at(i) * PI, at(j) * TAU - PI)
                })
                .collect::<Vec<Vec3>>()
        });
        SurfaceGrid {
            first: (rows.0, cols.0),
            coarse: (ci, cj),
            points,
        }
    }

    /// The surface point (mm) of texel row `i`, column `j` (inside the
    /// grid's rectangle; points beyond it are extrapolated).
    pub fn point(&self, i: usize, j: usize) -> Vec3 {
        let (y, x) = (
            i as f32 - self.first.0 as f32,
            j as f32 - self.first.1 as f32,
        );
        let s = MARCH_STRIDE as f32;
        let (ci, cj) = self.coarse;
        let (a, b) = (
            ((y / s).max(0.0) as usize).min(ci - 2),
            ((x / s).max(0.0) as usize).min(cj - 2),
        );
        let (fy, fx) = (y / s - a as f32, x / s - b as f32);
        let row = |r: usize| self.points[r][b].lerp(self.points[r][b + 1], fx);
        row(a).lerp(row(a + 1), fy)
    }
}

/// `f` of each item, on every core, in order.
pub fn in_parallel<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(16);
    let chunk = items.len().div_ceil(threads).max(1);
    std::thread::scope(|s| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|c| {
                let f = &f;
                s.spawn(move || c.iter().map(f).collect::<Vec<R>>())
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a face-map thread panicked"))
            .collect()
    })
}
