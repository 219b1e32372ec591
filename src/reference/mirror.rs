//! The ground truth's CPU mirror: its integral in f64 on the CPU, by brute
//! force over every sample (no grid), an independent check of the GPU passes
//! (the narrow part's windowed sum over the supersampled surface, the wide
//! part's grid, cut-off, profile, position reconstruction, the tissue test) on
//! a tiny scene. Both profiles: the six Gaussians ([`gather_f64`]) and
//! Burley's ([`gather_f64_burley`], split as `super::burley` says).

use glam::{DMat4, DVec3, Mat4};

use super::burley;
use super::narrow::radius;
use super::sampling::{cutoff_mm, SurfaceSample, NARROW_GAUSSIANS};
use crate::skin::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};
use crate::skin::tissue::through_tissue;
use crate::view::ViewScale;

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

/// The supersampled visible skin surface (what reference_surface.frag writes).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceImages<'a> {
    /// Subsamples per pixel per axis.
    pub s: u32,
    /// Diffuse radiance (rgb).
    pub radiance: &'a [[f32; 4]],
    /// World position (xyz) and area in mm^2 (w; 0 where no skin).
    pub position: &'a [[f32; 4]],
    /// Unit normal (xyz).
    pub normal: &'a [[f32; 4]],
}

/// A skin pixel's point as both profiles' gathers see it: its position
/// reconstructed from the linear depth, the normal of the subsample under
/// its centre, and that subsample on the supersampled surface. Its SSS
/// strength t scales the profile's radius (eq. 4.3-4.4): distances are
/// measured in units of t mm, as the GPU passes measure them.
struct PixelPoint {
    /// Millimetres per scene unit over the strength (the tissue test keeps
    /// the view's own), and pixels per such millimetre at the pixel's depth,
    /// in the shaders' float order (the windows' radii follow it).
    mm_over_t: f64,
    px_per_mm: f32,
    x_o: DVec3,
    x_o32: [f32; 3],
    n_o: [f32; 3],
    /// The subsample under the pixel's centre: its index and coordinates.
    centre: usize,
    cx: usize,
    cy: usize,
}

impl PixelPoint {
    fn new(
        view: &GatherView,
        inv: &DMat4,
        surface: &SurfaceImages,
        (z, strength): (f32, f32),
        i: usize,
    ) -> Self {
        let (s, sw) = (surface.s as usize, view.width * surface.s as usize);
        let (x, y) = (i % view.width, i / view.width);
        let px_per_mm = ViewScale {
            mm_per_unit: view.mm_per_unit / strength,
            ..view_scale(view)
        }
        .px_per_mm(z);
        let z = z as f64;
        let ndc_x = (x as f64 + 0.5) / view.width as f64 * 2.0 - 1.0;
        let ndc_y = (y as f64 + 0.5) / view.height as f64 * 2.0 - 1.0;
        let t = view.tan_half_fovy as f64;
        let vp = DVec3::new(ndc_x * t * view.aspect as f64 * z, -ndc_y * t * z, -z);
        let x_o = inv.transform_point3(vp);
        let (cx, cy) = ((x * s + s / 2), (y * s + s / 2));
        let centre = cy * sw + cx;
        let n = surface.normal[centre];
        PixelPoint {
            mm_over_t: (view.mm_per_unit / strength) as f64,
            px_per_mm,
            x_o,
            x_o32: x_o.as_vec3().to_array(),
            n_o: [n[0], n[1], n[2]],
            centre,
            cx,
            cy,
        }
    }

    /// Calls `f(qx, qy, q, r2)` for every skin subsample within `r`
    /// subsamples (per axis) of the centre that light reaches through
    /// tissue, `r2` its squared distance in mm^2.
    fn near(
        &self,
        view: &GatherView,
        surface: &SurfaceImages,
        r: i64,
        mut f: impl FnMut(i64, i64, usize, f64),
    ) {
        let mm = self.mm_over_t;
        let s = surface.s as usize;
        let (sw, sh) = (view.width * s, view.height * s);
        for qy in (self.cy as i64 - r)..=(self.cy as i64 + r) {
            for qx in (self.cx as i64 - r)..=(self.cx as i64 + r) {
                if qx < 0 || qy < 0 || qx >= sw as i64 || qy >= sh as i64 {
                    continue;
                }
                let q = qy as usize * sw + qx as usize;
                let p = surface.position[q];
                let nq = [
                    surface.normal[q][0],
                    surface.normal[q][1],
                    surface.normal[q][2],
                ];
                if p[3] <= 0.0
                    || !through_tissue(
                        self.x_o32,
                        self.n_o,
                        [p[0], p[1], p[2]],
                        nq,
                        view.mm_per_unit,
                    )
                {
                    continue;
                }
                let r2 = ((DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) - self.x_o) * mm)
                    .length_squared();
                f(qx, qy, q, r2);
            }
        }
    }

    /// Calls `f(j, r2)` for every surface sample within the cut-off that
    /// light reaches through tissue, `r2` its squared distance in mm^2.
    fn far(&self, view: &GatherView, samples: &[SurfaceSample], mut f: impl FnMut(usize, f64)) {
        let mm = self.mm_over_t;
        let cutoff2 = (cutoff_mm() as f64).powi(2);
        for (j, smp) in samples.iter().enumerate() {
            let pa = smp.pos_area;
            let p = DVec3::new(pa[0] as f64, pa[1] as f64, pa[2] as f64);
            let r2 = ((p - self.x_o) * mm).length_squared();
            let n = smp.normal;
            if r2 > cutoff2
                || !through_tissue(
                    self.x_o32,
                    self.n_o,
                    p.as_vec3().to_array(),
                    [n[0], n[1], n[2]],
                    view.mm_per_unit,
                )
            {
                continue;
            }
            f(j, r2);
        }
    }
}

fn view_scale(view: &GatherView) -> ViewScale {
    ViewScale {
        height_px: view.height as u32,
        tan_half_fovy: view.tan_half_fovy,
        mm_per_unit: view.mm_per_unit,
    }
}

/// M(x_o) for every pixel: skin pixels (alpha > 0) take the narrow part from
/// `surface` and gather the wide part from `samples`, both through tissue only;
/// others keep `diffuse`.
pub fn gather_f64(
    view: &GatherView,
    diffuse: &[[f32; 4]],
    linear_depth: &[f32],
    surface: &SurfaceImages,
    samples: &[SurfaceSample],
    radiance: &[[f32; 4]],
) -> Vec<[f64; 4]> {
    let inv = DMat4::from_cols_array(&view.inv_view.to_cols_array().map(|v| v as f64));
    (0..view.width * view.height)
        .map(|i| {
            let d0 = diffuse[i];
            if d0[3] <= 0.0 {
                return d0.map(|v| v as f64);
            }
            let pt = PixelPoint::new(view, &inv, surface, (linear_depth[i], d0[3]), i);
            // Narrow part: windowed, weight-normalised sums per Gaussian.
            let px_per_mm = pt.px_per_mm;
            let r = radius(px_per_mm, surface.s) as i64;
            let mut sum = [[0.0f64; 3]; NARROW_GAUSSIANS];
            let mut norm = [0.0f64; NARROW_GAUSSIANS];
            pt.near(view, surface, r, |_, _, q, r2| {
                let area = surface.position[q][3] as f64;
                for g in 0..NARROW_GAUSSIANS {
                    let e = (-r2 / (2.0 * SIX_GAUSSIAN_VARIANCES_MM2[g] as f64)).exp() * area;
                    norm[g] += e;
                    for (s, &l) in sum[g].iter_mut().zip(&surface.radiance[q][..3]) {
                        *s += e * l as f64;
                    }
                }
            });
            let mut acc = [0.0f64; 3];
            for g in 0..NARROW_GAUSSIANS {
                for ch in 0..3 {
                    let m = if norm[g] > 0.0 {
                        sum[g][ch] / norm[g]
                    } else {
                        surface.radiance[pt.centre][ch] as f64
                    };
                    acc[ch] += SIX_GAUSSIAN_WEIGHTS_RGB[g][ch] as f64 * m;
                }
            }
            // Wide part: every sample within the cut-off, through tissue, each
            // Gaussian over its own weight.
            let mut wide = [[0.0f64; 4]; 6 - NARROW_GAUSSIANS];
            pt.far(view, samples, |j, r2| {
                for (g, w) in wide.iter_mut().enumerate() {
                    let v = SIX_GAUSSIAN_VARIANCES_MM2[NARROW_GAUSSIANS + g] as f64;
                    let e = samples[j].pos_area[3] as f64 * (-r2 / (2.0 * v)).exp()
                        / (2.0 * std::f64::consts::PI * v);
                    for ch in 0..3 {
                        w[ch] += e * radiance[j][ch] as f64;
                    }
                    w[3] += e;
                }
            });
            // A Gaussian no sample reached takes the pixel's own light
            // (reference_resolve.comp).
            for (g, w) in wide.iter().enumerate() {
                for ch in 0..3 {
                    let m = if w[3] > 0.0 {
                        w[ch] / w[3]
                    } else {
                        d0[ch] as f64
                    };
                    acc[ch] += SIX_GAUSSIAN_WEIGHTS_RGB[NARROW_GAUSSIANS + g][ch] as f64 * m;
                }
            }
            [acc[0], acc[1], acc[2], d0[3] as f64]
        })
        .collect()
}

/// [`gather_f64`] under Burley's profile: the near part (`r < r_c`, each
/// subsample weighted by its cell's integral within reach of the point, by
/// `R(r) A_q` beyond) from `surface`, the far part (`R(r) dA_j` out to the
/// cut-off) from `samples`, each normalised per channel (`super::burley`).
pub fn gather_f64_burley(
    view: &GatherView,
    diffuse: &[[f32; 4]],
    linear_depth: &[f32],
    surface: &SurfaceImages,
    samples: &[SurfaceSample],
    radiance: &[[f32; 4]],
) -> Vec<[f64; 4]> {
    let inv = DMat4::from_cols_array(&view.inv_view.to_cols_array().map(|v| v as f64));
    let near2 = f64::from(burley::BURLEY_NEAR_MM).powi(2);
    let (bs, w_near, w_far) = (
        burley::s_per_mm(),
        burley::near_weight(),
        burley::far_weight(),
    );
    let s = surface.s as usize;
    (0..view.width * view.height)
        .map(|i| {
            let d0 = diffuse[i];
            if d0[3] <= 0.0 {
                return d0.map(|v| v as f64);
            }
            let pt = PixelPoint::new(view, &inv, surface, (linear_depth[i], d0[3]), i);
            let (x, y) = (i % view.width, i / view.width);
            // The pixel's point on the subsample grid (continuous coordinates).
            let (gx, gy) = ((x as f64 + 0.5) * s as f64, (y as f64 + 0.5) * s as f64);
            let px_per_mm = pt.px_per_mm;
            let r = burley::radius(px_per_mm, surface.s) as i64;
            let mut sum = [0.0f64; 3];
            let mut norm = [0.0f64; 3];
            pt.near(view, surface, r, |qx, qy, q, r2| {
                if r2 >= near2 {
                    return;
                }
                let (du, dv) = (qx as f64 + 0.5 - gx, qy as f64 + 0.5 - gy);
                let area = surface.position[q][3] as f64;
                let w = if burley::in_cell_reach(du, dv) {
                    burley::cell_weight(bs, du, dv, area.sqrt() / d0[3] as f64)
                } else {
                    burley::ring_weight(bs, r2.sqrt(), area.sqrt() / d0[3] as f64)
                };
                for ch in 0..3 {
                    norm[ch] += w[ch];
                    sum[ch] += w[ch] * surface.radiance[q][ch] as f64;
                }
            });
            let near: [f64; 3] = std::array::from_fn(|ch| {
                if norm[ch] > 0.0 {
                    sum[ch] / norm[ch]
                } else {
                    surface.radiance[pt.centre][ch] as f64
                }
            });
            // Far part: every sample from r_c to the cut-off, through tissue.
            let mut far = [0.0f64; 3];
            let mut far_norm = [0.0f64; 3];
            pt.far(view, samples, |j, r2| {
                if r2 < near2 {
                    return;
                }
                let w = burley::profile(bs, r2.sqrt());
                for ch in 0..3 {
                    let e = samples[j].pos_area[3] as f64 * w[ch];
                    far_norm[ch] += e;
                    far[ch] += e * radiance[j][ch] as f64;
                }
            });
            // A channel with no far sample takes the near part's light for it
            // (the GPU's resolve does the same): nothing is lost.
            let acc: [f64; 3] = std::array::from_fn(|ch| {
                let f = if far_norm[ch] > 0.0 {
                    far[ch] / far_norm[ch]
                } else {
                    near[ch]
                };
                w_near[ch] * near[ch] + w_far[ch] * f
            });
            [acc[0], acc[1], acc[2], d0[3] as f64]
        })
        .collect()
}
