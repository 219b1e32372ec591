//! Surface samples for the ground truth: area-weighted points over every skin
//! triangle (visible or not), and the uniform grid that finds the ones within the
//! profile's cut-off of a shading point. Pure CPU code.

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::scene::mesh::Mesh;
use crate::skin::profile::SIX_GAUSSIAN_VARIANCES_MM2;

/// One surface sample as the compute shaders read it (std430, 64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SurfaceSample {
    /// World position (scene units) and the area it stands for (mm^2).
    pub pos_area: [f32; 4],
    pub normal: [f32; 4],
    pub tangent: [f32; 4],
    pub uv: [f32; 4],
}

/// Gaussians of the six-Gaussian fit integrated over the visible surface in
/// screen space rather than over the surface samples: the first three (sigma
/// 0.08, 0.22 and 0.43 mm, 99% of green's and blue's weight). A few pixels of
/// a close-up, they need the surface at sub-pixel resolution, which the
/// supersampled G-buffer of [`super::narrow`] gives and surface samples at a
/// usable density do not (8/16/32 samples per mm^2 changed the image by
/// 4.5e-3 and 2.4e-3). Taking them as w_i L_d(x_o) at the pixel instead (the
/// earlier definition) scatters almost no green or blue: on the card it moved
/// 6% of the exact green and blue energy across the edge.
/// (Shared with the ground truth's shaders through `crate::shader_constants`.)
pub use crate::shader_constants::NARROW_GAUSSIANS;

/// Cut-off radius of the gather: 4 standard deviations of the widest Gaussian
/// (7.41 mm^2). A 2D Gaussian keeps exp(-r^2 / 2 sigma^2) of its energy beyond r:
/// exp(-8) = 3.4e-4 of the widest one, whose red weight is 0.078, so at most
/// 2.6e-5 of the red exitance is dropped (the narrower ones lose far less).
pub fn cutoff_mm() -> f32 {
    4.0 * SIX_GAUSSIAN_VARIANCES_MM2[5].sqrt()
}

/// How many samples [`sample_surface`] makes (in f64: a corrupt mesh can ask
/// for more than any integer holds), so a caller can refuse before allocating.
pub fn sample_count(mesh: &Mesh, transforms: &[Mat4], mm_per_unit: f32, density: f32) -> f64 {
    let mut total = 0.0f64;
    for m in transforms {
        for tri in mesh.indices.chunks_exact(3) {
            let p = [tri[0], tri[1], tri[2]]
                .map(|i| m.transform_point3(Vec3::from(mesh.vertices[i as usize].position)));
            let area_mm2 = triangle_area_mm2(p, mm_per_unit);
            if area_mm2.is_nan() || area_mm2 <= 0.0 {
                continue;
            }
            total += (area_mm2 * f64::from(density)).round().max(1.0);
        }
    }
    total
}

/// `sample_surface` of each (mesh, transform) in turn (a moving crowd's
/// characters each with its own pose; the same samples, in the same order,
/// as one call with every transform when the meshes are one), refused when
/// it would make more than `max_samples` (counted first: a far, corrupt
/// vertex makes a triangle of astronomical area).
pub fn sample_characters_within(
    characters: &[(&Mesh, Mat4)],
    mm_per_unit: f32,
    density: f32,
    max_samples: u64,
) -> anyhow::Result<Vec<SurfaceSample>> {
    let wanted: f64 = characters
        .iter()
        .map(|(mesh, m)| sample_count(mesh, &[*m], mm_per_unit, density))
        .sum();
    if wanted > max_samples.min(u32::MAX as u64) as f64 {
        anyhow::bail!(
            "the reference would take {wanted:.3e} samples at {density} per mm^2, more than this device holds ({max_samples}); lower --density or the number of heads (or check the mesh for far outlier vertices)"
        );
    }
    Ok(characters
        .iter()
        .enumerate()
        .flat_map(|(k, (mesh, m))| {
            // uv.z: the sample's character (its wrinkle zones' index).
            sample_surface(mesh, &[*m], mm_per_unit, density)
                .into_iter()
                .map(move |mut s| {
                    s.uv[2] = k as f32;
                    s
                })
        })
        .collect())
}

/// Area of a triangle in mm^2, in f64 (f32 overflows on a far vertex).
fn triangle_area_mm2(p: [Vec3; 3], mm_per_unit: f32) -> f64 {
    let q = p.map(|v| v.as_dvec3());
    0.5 * (q[1] - q[0]).cross(q[2] - q[0]).length() * f64::from(mm_per_unit).powi(2)
}

/// Stratified samples over every triangle of `mesh` placed by each of
/// `transforms` (uniform scale and translation), about `density` samples per mm^2,
/// at least one per triangle; each carries the area it stands for. Deterministic:
/// the points of a triangle with n samples are a rank-1 lattice warped to the
/// triangle, so doubling the density refines, not reshuffles.
pub fn sample_surface(
    mesh: &Mesh,
    transforms: &[Mat4],
    mm_per_unit: f32,
    density: f32,
) -> Vec<SurfaceSample> {
    let mut out = Vec::new();
    for m in transforms {
        let normal_m = glam::Mat3::from_mat4(*m);
        for tri in mesh.indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]].map(|i| mesh.vertices[i as usize]);
            let p = v.map(|x| m.transform_point3(Vec3::from(x.position)));
            let area_units = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            let area_mm2 = area_units * mm_per_unit * mm_per_unit;
            // Degenerate (or non-finite) triangles stand for no surface. (Callers
            // bound the total with `sample_count` first: an infinite area would
            // otherwise ask for usize::MAX samples.)
            if !area_mm2.is_finite() || area_mm2 <= 0.0 {
                continue;
            }
            let n = ((area_mm2 * density).round() as usize).max(1);
            // Fibonacci lattice in the unit square, warped to uniform barycentrics.
            let golden = 0.618_034_f32;
            for k in 0..n {
                let r1 = (k as f32 + 0.5) / n as f32;
                let r2 = ((k as f32 + 0.5) * golden).fract();
                let s = r1.sqrt();
                let b = [1.0 - s, s * (1.0 - r2), s * r2];
                let lerp3 = |a: [Vec3; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                let pos = lerp3(p);
                let nrm = lerp3(v.map(|x| normal_m * Vec3::from(x.normal))).normalize_or_zero();
                let tan = lerp3(v.map(|x| normal_m * Vec3::from_slice(&x.tangent[..3])));
                let uv = v.map(|x| Vec2::from(x.uv));
                let uv = uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2];
                out.push(SurfaceSample {
                    pos_area: pos.extend(area_mm2 / n as f32).to_array(),
                    normal: nrm.extend(0.0).to_array(),
                    tangent: Vec4::new(tan.x, tan.y, tan.z, v[0].tangent[3]).to_array(),
                    uv: [uv.x, uv.y, 0.0, 0.0],
                });
            }
        }
    }
    out
}

/// A uniform grid over the samples with cells as wide as the cut-off, so the 27
/// cells around a point hold every sample within reach.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub origin: Vec3,
    pub cell: f32,
    pub dims: [u32; 3],
    /// Start index of each cell in the reordered samples, plus the end.
    pub cell_start: Vec<u32>,
}

impl Grid {
    fn cell_of(&self, p: Vec3) -> [u32; 3] {
        let c = ((p - self.origin) / self.cell).floor();
        [0, 1, 2].map(|i| (c[i].max(0.0) as u32).min(self.dims[i] - 1))
    }

    fn index(&self, c: [u32; 3]) -> usize {
        ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize
    }
}

/// Sorts `samples` (and `radiance`, if given, in step) by grid cell and returns
/// the grid. `cell` is in scene units.
pub fn build_grid(samples: &mut Vec<SurfaceSample>, cell: f32) -> Grid {
    let pts: Vec<Vec3> = samples
        .iter()
        .map(|s| Vec3::new(s.pos_area[0], s.pos_area[1], s.pos_area[2]))
        .collect();
    let (lo, hi) = pts.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let (lo, hi) = if pts.is_empty() {
        (Vec3::ZERO, Vec3::ZERO)
    } else {
        (lo, hi)
    };
    let dims = [0, 1, 2].map(|i| (((hi[i] - lo[i]) / cell).floor() as u32 + 1).max(1));
    let mut grid = Grid {
        origin: lo,
        cell,
        dims,
        cell_start: Vec::new(),
    };
    let n_cells = (dims[0] * dims[1] * dims[2]) as usize;
    let keys: Vec<usize> = pts.iter().map(|p| grid.index(grid.cell_of(*p))).collect();
    let mut counts = vec![0u32; n_cells + 1];
    for &k in &keys {
        counts[k + 1] += 1;
    }
    for i in 0..n_cells {
        counts[i + 1] += counts[i];
    }
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.sort_by_key(|&i| keys[i]);
    *samples = order.iter().map(|&i| samples[i]).collect();
    grid.cell_start = counts;
    grid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::Vertex;
    use crate::skin::profile::SIX_GAUSSIAN_WEIGHTS_RGB;

    fn quad(size: f32) -> Mesh {
        let v = |x: f32, y: f32| Vertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            uv: [x / size, y / size],
            tangent: [1.0, 0.0, 0.0, 1.0],
        };
        Mesh {
            vertices: vec![v(0.0, 0.0), v(size, 0.0), v(size, size), v(0.0, size)],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    #[test]
    fn areas_add_up_and_density_is_honoured() {
        let mesh = quad(2.0); // 2 x 2 units at 10 mm/unit = 400 mm^2
        let s = sample_surface(&mesh, &[Mat4::IDENTITY], 10.0, 4.0);
        let area: f32 = s.iter().map(|x| x.pos_area[3]).sum();
        assert!((area - 400.0).abs() < 1e-2, "{area}");
        assert!((s.len() as f32 - 1600.0).abs() <= 2.0, "{}", s.len());
        // Points stay inside the quad.
        assert!(s
            .iter()
            .all(|x| (0.0..=2.0).contains(&x.pos_area[0]) && (0.0..=2.0).contains(&x.pos_area[1])));
    }

    /// Characters sampled one by one are the samples of one call over
    /// every transform when their meshes are one (the same bits, the same
    /// order: a still crowd's truth is unchanged), and each character's
    /// samples lie on its own mesh when they differ.
    #[test]
    fn characters_sampled_in_turn_keep_their_own_meshes() {
        let (a, b) = (quad(2.0), quad(3.0));
        let moved = Mat4::from_translation(glam::Vec3::new(10.0, 0.0, 0.0));
        let one = sample_surface(&a, &[Mat4::IDENTITY, moved], 10.0, 4.0);
        let each =
            sample_characters_within(&[(&a, Mat4::IDENTITY), (&a, moved)], 10.0, 4.0, u64::MAX)
                .unwrap();
        // The same samples, each naming its character in uv.z (its wrinkle
        // zones' index).
        let own = |s: &SurfaceSample| SurfaceSample {
            uv: [s.uv[0], s.uv[1], 0.0, 0.0],
            ..*s
        };
        assert!(one == each.iter().map(own).collect::<Vec<_>>());
        assert!(each
            .iter()
            .all(|s| s.uv[2] == if s.pos_area[0] < 5.0 { 0.0 } else { 1.0 }));
        let mixed =
            sample_characters_within(&[(&a, Mat4::IDENTITY), (&b, moved)], 10.0, 4.0, u64::MAX)
                .unwrap();
        let (first, second): (Vec<_>, Vec<_>) = mixed.iter().partition(|x| x.pos_area[0] < 5.0);
        let area = |v: &[&SurfaceSample]| v.iter().map(|x| x.pos_area[3]).sum::<f32>();
        assert!((area(&first) - 400.0).abs() < 1e-2);
        assert!((area(&second) - 900.0).abs() < 1e-2, "{}", area(&second));
        assert!(second
            .iter()
            .all(|x| (10.0..=13.0).contains(&x.pos_area[0])));
        // Refused past the budget, before any sample is made.
        assert!(sample_characters_within(&[(&a, Mat4::IDENTITY)], 10.0, 4.0, 100).is_err());
    }

    /// The sampled (wide) part of the profile at squared distance `r2` (mm^2), f64
    /// (what the gather weighs a sample with, written out for the test below).
    pub fn wide_profile(r2_mm2: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (v, w) in SIX_GAUSSIAN_VARIANCES_MM2
            .iter()
            .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
            .skip(NARROW_GAUSSIANS)
        {
            let v = *v as f64;
            let g = (-r2_mm2 / (2.0 * v)).exp() / (2.0 * std::f64::consts::PI * v);
            for c in 0..3 {
                out[c] += w[c] as f64 * g;
            }
        }
        out
    }

    /// Weight of the analytic (narrow) part per channel.
    pub fn narrow_weight() -> [f64; 3] {
        let mut out = [0.0; 3];
        for w in SIX_GAUSSIAN_WEIGHTS_RGB.iter().take(NARROW_GAUSSIANS) {
            for c in 0..3 {
                out[c] += w[c] as f64;
            }
        }
        out
    }

    #[test]
    fn profile_integrates_to_one_over_a_flat_sampled_plane() {
        // The discrete sum of the wide part over a dense flat plane plus the
        // narrow weight is the profile's total, 1 per channel.
        let mesh = quad(4.0);
        let s = sample_surface(&mesh, &[Mat4::IDENTITY], 10.0, 16.0);
        let centre = Vec3::new(2.0, 2.0, 0.0);
        let mut m = narrow_weight();
        for x in &s {
            let d = (Vec3::new(x.pos_area[0], x.pos_area[1], x.pos_area[2]) - centre) * 10.0;
            let p = wide_profile(d.length_squared() as f64);
            for c in 0..3 {
                m[c] += x.pos_area[3] as f64 * p[c];
            }
        }
        for (c, mc) in m.iter().enumerate() {
            assert!((mc - 1.0).abs() < 2e-3, "channel {c}: {mc}");
        }
    }

    #[test]
    fn grid_finds_every_neighbour_within_the_cutoff() {
        let mesh = quad(6.0);
        let mut s = sample_surface(&mesh, &[Mat4::IDENTITY], 10.0, 2.0);
        let cell = cutoff_mm() / 10.0;
        let g = build_grid(&mut s, cell);
        assert_eq!(*g.cell_start.last().unwrap() as usize, s.len());
        // Every sample's cell holds it.
        for (i, x) in s.iter().enumerate() {
            let c = g.index(g.cell_of(Vec3::new(x.pos_area[0], x.pos_area[1], x.pos_area[2])));
            assert!((g.cell_start[c] as usize..g.cell_start[c + 1] as usize).contains(&i));
        }
        assert!(cutoff_mm() > 10.8 && cutoff_mm() < 11.0);
    }
}
