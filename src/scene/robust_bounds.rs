//! Bounds that ignore far outliers. One corrupt vertex (a flipped exponent bit turns
//! 0.1 into 1e31) makes the plain bounding box useless for framing a camera or fitting
//! a shadow map, while the rest of the mesh is fine. These bounds keep every vertex
//! that lies within a generous fence around the bulk of the mesh and report how many
//! were left out, so the caller can frame the bulk and say what it ignored.
//!
//! The fence: per axis, the 5th and 95th percentiles of the coordinates, widened on both
//! sides by `FENCE` times the largest percentile span of the three axes (one isotropic
//! scale, so a flat mesh with a zero span on one axis does not reject its own relief).
//! The box is then the exact box of the points inside the fence, so a mesh without
//! outliers gets exactly its plain bounds. Non-finite points are always left out.
//! A mesh of fewer than `SMALL` points has no percentiles worth the name: its band is
//! the box of all but the point farthest from the median (fewer than four: all).

use super::mesh::Aabb;
use glam::{DVec3, Vec3};

/// How far beyond the 5th..95th percentile band a point may lie, in multiples of the
/// band's width, before it counts as an outlier. Two band widths keep every vertex of
/// any ordinary shape (a uniform box reaches only 0.06 widths past the band) while a
/// vertex ten times the model's size away is still caught.
pub const FENCE: f64 = 2.0;

/// Lower and upper percentile of the band the fence is built around.
const LOW_QUANTILE: f64 = 0.05;
const HIGH_QUANTILE: f64 = 0.95;

/// Below this many points the percentiles hold less than one point each
/// side: the band is built without them.
const SMALL: usize = 20;

/// A small mesh's fence, in band widths: its one suspect point must lie
/// this far out (a pyramid's apex three base widths up is its shape; a
/// flipped exponent is 1e30 away).
const SMALL_FENCE: f64 = 100.0;

/// Bounds of the points inside the fence, and how many were left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustBounds {
    pub aabb: Aabb,
    /// Points outside the fence plus non-finite points.
    pub ignored: usize,
}

/// The same in f64, for the loader's recentring (world positions are computed in f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustBounds64 {
    pub min: DVec3,
    pub max: DVec3,
    pub ignored: usize,
}

impl RobustBounds64 {
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }
}

/// Bounds of `points` ignoring far outliers (see the module comment); `None` when no
/// point is finite.
pub fn robust_bounds(points: impl IntoIterator<Item = Vec3>) -> Option<RobustBounds> {
    let points: Vec<DVec3> = points.into_iter().map(|p| p.as_dvec3()).collect();
    let b = robust_bounds_f64(&points)?;
    Some(RobustBounds {
        aabb: Aabb {
            min: b.min.as_vec3(),
            max: b.max.as_vec3(),
        },
        ignored: b.ignored,
    })
}

/// f64 version of [`robust_bounds`].
pub fn robust_bounds_f64(points: &[DVec3]) -> Option<RobustBounds64> {
    let finite: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
    let non_finite = points.len() - finite.len();
    if finite.is_empty() {
        return None;
    }
    let n = finite.len();
    let mut lo = DVec3::ZERO;
    let mut hi = DVec3::ZERO;
    if n < SMALL {
        // Too few points for percentiles (5% of them is not one point, and
        // the middle values of a small shape can coincide on every axis):
        // the band is the box of all but the one point farthest from the
        // per-axis median, which alone may be judged an outlier. Fewer than
        // four points are all kept (a triangle's third vertex is not an
        // outlier of the other two).
        if n < 4 {
            lo = finite.iter().copied().fold(DVec3::INFINITY, DVec3::min);
            hi = finite.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        } else {
            let mut median = DVec3::ZERO;
            let mut axis: Vec<f64> = Vec::with_capacity(n);
            for a in 0..3 {
                axis.clear();
                axis.extend(finite.iter().map(|p| p[a]));
                let (_, &mut m, _) = axis.select_nth_unstable_by(n / 2, f64::total_cmp);
                median[a] = m;
            }
            let far = (0..n)
                .max_by(|&i, &j| {
                    finite[i]
                        .distance_squared(median)
                        .total_cmp(&finite[j].distance_squared(median))
                })
                .unwrap_or(0);
            let rest = finite.iter().enumerate().filter(|(i, _)| *i != far);
            lo = rest.clone().fold(DVec3::INFINITY, |a, (_, p)| a.min(*p));
            hi = rest.fold(DVec3::NEG_INFINITY, |a, (_, p)| a.max(*p));
        }
    } else {
        let (lo_at, hi_at) = (
            ((n - 1) as f64 * LOW_QUANTILE) as usize,
            ((n - 1) as f64 * HIGH_QUANTILE) as usize,
        );
        let mut axis: Vec<f64> = Vec::with_capacity(n);
        for a in 0..3 {
            axis.clear();
            axis.extend(finite.iter().map(|p| p[a]));
            // Selection, not a sort: linear time on multi-million-vertex scans.
            let (_, &mut l, _) = axis.select_nth_unstable_by(lo_at, f64::total_cmp);
            let (_, &mut h, _) = axis.select_nth_unstable_by(hi_at, f64::total_cmp);
            lo[a] = l;
            hi[a] = h;
        }
    }
    let scale = (hi - lo).max_element();
    // When the band is a single point on every axis (most vertices coincide) there is
    // no scale to judge distance by: keep every finite point rather than guess.
    let fence = if n < SMALL { SMALL_FENCE } else { FENCE };
    let keep = |p: &DVec3| -> bool {
        if scale <= 0.0 {
            return true;
        }
        let margin = DVec3::splat(fence * scale);
        p.cmpge(lo - margin).all() && p.cmple(hi + margin).all()
    };
    let mut kept = finite.iter().filter(|p| keep(p));
    let first = *kept.next()?;
    let (mut min, mut max, mut count) = (first, first, 1usize);
    for p in kept {
        min = min.min(*p);
        max = max.max(*p);
        count += 1;
    }
    Some(RobustBounds64 {
        min,
        max,
        ignored: non_finite + (n - count),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10x10x10 grid of points spanning 0..1 on each axis.
    fn grid() -> Vec<Vec3> {
        let mut v = Vec::new();
        for x in 0..10 {
            for y in 0..10 {
                for z in 0..10 {
                    v.push(Vec3::new(x as f32, y as f32, z as f32) / 9.0);
                }
            }
        }
        v
    }

    #[test]
    fn no_points_no_bounds() {
        assert_eq!(robust_bounds(std::iter::empty()), None);
        assert_eq!(robust_bounds([Vec3::NAN, Vec3::INFINITY]), None);
    }

    #[test]
    fn clean_mesh_gets_its_exact_bounds() {
        let b = robust_bounds(grid()).unwrap();
        assert_eq!(b.ignored, 0);
        assert_eq!(b.aabb.min, Vec3::ZERO);
        assert_eq!(b.aabb.max, Vec3::ONE);
        // A single triangle: nothing to judge by, nothing ignored.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let b = robust_bounds(tri).unwrap();
        assert_eq!((b.ignored, b.aabb.max), (0, Vec3::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn one_flipped_exponent_is_ignored() {
        let mut pts = grid();
        pts[517].y = 1e31;
        let b = robust_bounds(pts.iter().copied()).unwrap();
        assert_eq!(b.ignored, 1);
        assert_eq!(b.aabb.max, Vec3::ONE);
        assert_eq!(b.aabb.min, Vec3::ZERO);
        // Also on the negative side and at 10x the model size.
        pts[3] = Vec3::new(-10.0, 0.5, 0.5);
        let b = robust_bounds(pts).unwrap();
        assert_eq!(b.ignored, 2);
        assert_eq!(b.aabb.min, Vec3::ZERO);
    }

    #[test]
    fn tiny_meshes_still_catch_a_far_vertex() {
        let b =
            robust_bounds([Vec3::ZERO, Vec3::ONE, Vec3::splat(0.5), Vec3::splat(1e30)]).unwrap();
        assert_eq!((b.ignored, b.aabb.max), (1, Vec3::ONE));
    }

    #[test]
    fn a_triangle_keeps_its_three_vertices() {
        // The Khronos SimpleMorph sample at its default weights: a tip three
        // base widths above its base is the triangle, not corrupt data.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1.5, 0.0)];
        let b = robust_bounds(tri).unwrap();
        assert_eq!((b.ignored, b.aabb.max), (0, Vec3::new(1.0, 1.5, 0.0)));
        let b = robust_bounds([Vec3::ZERO, Vec3::splat(1e30)]).unwrap();
        assert_eq!(b.ignored, 0);
        // A square pyramid's apex three base widths up is its shape too.
        let pyramid = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
            Vec3::new(0.5, 0.5, 3.0),
        ];
        assert_eq!(robust_bounds(pyramid).unwrap().ignored, 0);
    }

    #[test]
    fn non_finite_points_are_counted_and_skipped() {
        let mut pts = grid();
        pts.push(Vec3::new(f32::NAN, 0.0, 0.0));
        pts.push(Vec3::new(0.0, f32::INFINITY, 0.0));
        let b = robust_bounds(pts).unwrap();
        assert_eq!(b.ignored, 2);
        assert_eq!(b.aabb.max, Vec3::ONE);
    }

    #[test]
    fn flat_mesh_keeps_its_relief() {
        // A 1x1 plane at z = 0 with a bump rising 0.3: the z band is zero wide, the
        // isotropic scale keeps the bump.
        let mut pts: Vec<Vec3> = grid()
            .into_iter()
            .map(|p| p * Vec3::new(1.0, 1.0, 0.0))
            .collect();
        pts.push(Vec3::new(0.5, 0.5, 0.3));
        let b = robust_bounds(pts).unwrap();
        assert_eq!(b.ignored, 0);
        assert_eq!(b.aabb.max.z, 0.3);
    }

    #[test]
    fn a_dense_face_does_not_cut_off_the_rest_of_the_head() {
        // 85% of the vertices in a small dense patch, the rest spread over a 1-unit
        // sphere: everything is kept.
        let mut pts = Vec::new();
        for i in 0..850 {
            let t = i as f32 * 0.618;
            pts.push(Vec3::new(t.sin(), t.cos(), 1.0) * 0.05 + Vec3::Z);
        }
        for i in 0..150 {
            let (a, b) = (i as f32 * 0.37, i as f32 * 0.91);
            pts.push(Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos()));
        }
        let b = robust_bounds(pts.iter().copied()).unwrap();
        let plain = Aabb::from_points(pts).unwrap();
        assert_eq!(b.aabb, plain, "ignored {}", b.ignored);
    }
}
