//! Signed-distance building blocks (mm in, mm out): the procedural face's
//! field is written with them (`face::skull_field`). Pure math.

use glam::{Vec2, Vec3};

/// Polynomial smooth minimum: the union of two fields with a fillet of size `k`.
pub(super) fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

/// Smooth maximum: intersection (or, with a negated field, subtraction) with a fillet.
pub(super) fn smax(a: f32, b: f32, k: f32) -> f32 {
    -smin(-a, -b, k)
}

/// Approximate distance to an axis-aligned ellipsoid centred on the origin (exact on the
/// surface, close nearby: good enough for blending and root finding).
pub(super) fn ellipsoid(p: Vec3, r: Vec3) -> f32 {
    let k0 = (p / r).length();
    let k1 = (p / (r * r)).length();
    if k1 <= f32::EPSILON {
        return -r.min_element();
    }
    k0 * (k0 - 1.0) / k1
}

/// The 2D version of `ellipsoid`.
pub(super) fn ellipse(p: Vec2, r: Vec2) -> f32 {
    let k0 = (p / r).length();
    let k1 = (p / (r * r)).length();
    if k1 <= f32::EPSILON {
        return -r.min_element();
    }
    k0 * (k0 - 1.0) / k1
}

/// Distance to a segment from `a` to `b` whose radius goes from `ra` to `rb`.
pub(super) fn cone(p: Vec3, a: Vec3, ra: f32, b: Vec3, rb: f32) -> f32 {
    let ab = b - a;
    let h = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (p - a - ab * h).length() - (ra + (rb - ra) * h)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Closed forms: a sphere's field is the exact distance; a tapered
    // capsule's is the distance to its axis minus its radius there; a
    // smooth union is never above the plain one and meets it a fillet away.
    #[test]
    fn the_primitives_against_their_closed_forms() {
        let p = Vec3::new(3.0, 4.0, 12.0);
        assert!((ellipsoid(p, Vec3::splat(5.0)) - 8.0).abs() < 1e-5);
        assert!(ellipsoid(Vec3::new(10.0, 0.0, 0.0), Vec3::new(10.0, 2.0, 3.0)).abs() < 1e-6);
        assert!((ellipse(Vec2::new(0.0, 7.0), Vec2::splat(4.0)) - 3.0).abs() < 1e-6);
        let c = cone(
            Vec3::new(0.0, 5.0, 3.0),
            Vec3::ZERO,
            1.0,
            Vec3::new(0.0, 10.0, 0.0),
            2.0,
        );
        assert!((c - 1.5).abs() < 1e-6, "{c}");
        assert!(smin(1.0, 1.5, 2.0) < 1.0);
        assert_eq!(smin(1.0, 4.0, 2.0), 1.0);
        assert_eq!(smax(1.0, 4.0, 2.0), 4.0);
    }
}
