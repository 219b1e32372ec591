//! The gather of the ground truth in f64 on the CPU, by brute force over every
//! sample (no grid): an independent check of the GPU gather (grid, cut-off,
//! profile, position reconstruction) on a tiny scene.

use glam::{DMat4, DVec3, Mat4};

use super::sampling::{cutoff_mm, narrow_weight, wide_profile, SurfaceSample};

/// What the gather needs of the view.
#[derive(Clone, Copy, Debug)]
pub struct GatherView {
    pub width: usize,
    pub height: usize,
    pub inv_view: Mat4,
    pub tan_half_fovy: f32,
    pub aspect: f32,
    pub mm_per_unit: f32,
}

/// M(x_o) for every pixel: skin pixels (alpha > 0) gather, others keep `diffuse`.
pub fn gather_f64(
    view: &GatherView,
    diffuse: &[[f32; 4]],
    linear_depth: &[f32],
    samples: &[SurfaceSample],
    radiance: &[[f32; 4]],
) -> Vec<[f64; 4]> {
    let inv = DMat4::from_cols_array(&view.inv_view.to_cols_array().map(|v| v as f64));
    let mm = view.mm_per_unit as f64;
    let cutoff2 = (cutoff_mm() as f64).powi(2);
    let narrow = narrow_weight();
    let pts: Vec<DVec3> = samples
        .iter()
        .map(|s| {
            DVec3::new(
                s.pos_area[0] as f64,
                s.pos_area[1] as f64,
                s.pos_area[2] as f64,
            )
        })
        .collect();
    (0..view.width * view.height)
        .map(|i| {
            let d0 = diffuse[i];
            if d0[3] <= 0.0 {
                return d0.map(|v| v as f64);
            }
            let (x, y) = (i % view.width, i / view.width);
            let z = linear_depth[i] as f64;
            let ndc_x = (x as f64 + 0.5) / view.width as f64 * 2.0 - 1.0;
            let ndc_y = (y as f64 + 0.5) / view.height as f64 * 2.0 - 1.0;
            let t = view.tan_half_fovy as f64;
            let vp = DVec3::new(ndc_x * t * view.aspect as f64 * z, -ndc_y * t * z, -z);
            let xo = inv.transform_point3(vp);
            let mut acc = [
                narrow[0] * d0[0] as f64,
                narrow[1] * d0[1] as f64,
                narrow[2] * d0[2] as f64,
            ];
            for (j, p) in pts.iter().enumerate() {
                let r2 = ((*p - xo) * mm).length_squared();
                if r2 > cutoff2 {
                    continue;
                }
                let prof = wide_profile(r2);
                for c in 0..3 {
                    acc[c] += samples[j].pos_area[3] as f64 * radiance[j][c] as f64 * prof[c];
                }
            }
            [acc[0], acc[1], acc[2], d0[3] as f64]
        })
        .collect()
}
