//! Perspective camera in Vulkan conventions.

use glam::{Mat4, Vec3, Vec4Swizzles};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fovy_rad: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// Right-handed look-at: the camera looks down its -Z.
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye, self.target, self.up)
    }

    /// Vulkan clip space: NDC y points down (the viewport is not flipped, so the flip
    /// lives here) and depth runs 0..1 from near to far. Not reversed-Z: at head-scale
    /// depth ranges the precision is ample and the shadow/SSS passes compare raw depths.
    pub fn proj(&self, aspect: f32) -> Mat4 {
        let mut p = Mat4::perspective_rh(self.fovy_rad, aspect, self.near, self.far);
        p.y_axis.y = -p.y_axis.y;
        p
    }

    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.proj(aspect) * self.view()
    }

    /// Frames the head(s): looks at `target` from along `forward`, at `distance_heads`
    /// head heights from it. Near/far hug the subject (near = max(0.01 d, d - 3 h),
    /// far = d + 10 h) so depth precision goes where the skin is.
    pub fn framing(
        target: Vec3,
        forward: Vec3,
        head_height: f32,
        distance_heads: f32,
        fovy_deg: f32,
    ) -> Camera {
        let forward = forward.try_normalize().unwrap_or(Vec3::Z);
        let d = (distance_heads * head_height).abs().max(1e-4);
        let up = if forward.dot(Vec3::Y).abs() > 0.99 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        Camera {
            eye: target + forward * d,
            target,
            up,
            fovy_rad: fovy_deg.to_radians(),
            near: (0.01 * d).max(d - 3.0 * head_height),
            far: d + 10.0 * head_height,
        }
    }

    /// Distance, in head heights, at which one head height fills the screen height.
    pub fn close_up_distance_heads(fovy_deg: f32) -> f32 {
        0.5 / (0.5 * fovy_deg.to_radians()).tan()
    }
}

/// Projects a world point to NDC (x, y in -1..1, z depth 0..1).
pub fn project(view_proj: &Mat4, p: Vec3) -> Vec3 {
    let c = *view_proj * p.extend(1.0);
    c.xyz() / c.w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera::framing(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.3, 0.1, 1.0),
            23.0,
            3.0,
            30.0,
        )
    }

    #[test]
    fn target_projects_to_centre() {
        let c = cam();
        let ndc = project(&c.view_proj(1.5), c.target);
        assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5, "{ndc}");
    }

    #[test]
    fn near_and_far_map_to_depth_zero_and_one() {
        let c = cam();
        let dir = (c.target - c.eye).normalize();
        let vp = c.view_proj(1.0);
        assert!(project(&vp, c.eye + dir * c.near).z.abs() < 1e-5);
        assert!((project(&vp, c.eye + dir * c.far).z - 1.0).abs() < 1e-5);
        assert!(c.near > 0.0 && c.near < 69.0 && c.far > 69.0);
    }

    #[test]
    fn y_is_flipped_for_vulkan() {
        let c = cam();
        assert!(project(&c.view_proj(1.0), c.target + Vec3::Y).y < 0.0);
    }

    #[test]
    fn close_up_distance() {
        assert!((Camera::close_up_distance_heads(20.0) - 2.836).abs() < 1e-3);
        // At that distance one head height spans the full NDC height.
        let d = Camera::close_up_distance_heads(20.0);
        let c = Camera::framing(Vec3::ZERO, Vec3::Z, 2.0, d, 20.0);
        let top = project(&c.view_proj(1.0), Vec3::Y * 1.0);
        assert!((top.y + 1.0).abs() < 1e-4, "{top}");
    }

    #[test]
    fn looking_straight_down_still_works() {
        let c = Camera::framing(Vec3::ZERO, Vec3::Y, 1.0, 3.0, 30.0);
        assert!(c.view().is_finite());
    }
}
