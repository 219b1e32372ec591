//! A procedural head that reads as a face, for the first picture a newcomer sees: brow,
//! open eyes (eyeballs, a part of their own: `eyes`), nose, cheekbones, lips, chin, jaw, ears thin enough to glow when lit from
//! behind, and a neck that leaves the frame, in front of a backdrop placed for the default
//! key light.
//!
//! Same conventions as `procedural`: 1 unit = 10 mm, Y up, the face looking toward +Z,
//! ~230 mm from chin to crown. The shapes are written in millimetres (anatomical sizes
//! read better that way) and scaled to units when the vertices are emitted.
//!
//! The head is a union of three closed shells, none of which can cross itself:
//! - skull, face and neck: a signed distance field (ellipsoids and tapered capsules
//!   joined by smooth unions, features carved by smooth subtractions) sampled once per
//!   ray, the rays leaving a tall thin ellipsoid inside the head along its outward
//!   normals. Normals of a convex body never meet outside it, so one point per ray gives
//!   a shell that cannot cross itself (a test also checks every triangle pair). Across
//!   the face those normals run nearly horizontally, so the tops of the lips and the
//!   undersides of nose, brow and chin all face the rays; the outermost crossing is taken
//!   where a ray would cross the field more than once.
//! - two ears: height fields over an ear-shaped outline, the outer and the inner side
//!   over the same points joined by a rounded rim, so the pinna is 2-4 mm thick like
//!   real cartilage; their front edge is pushed into the side of the skull.
//!
//! Over 800 lines because the skull, the features, the ears and the backdrop are
//! built from one set of measurements (about 720 lines) and their tests (about 430)
//! check those measurements against each other. The field's primitives
//! are `sdf`'s, the rays' root finding `crossing`'s.

use super::crossing::outermost_crossing;
use super::expressions::expression_morph;
use super::eyes::{self, EYEBALL_RADIUS_MM};
use super::mesh::{Material, Mesh, Object, Vertex};
use super::procedural::{plateau, smoothstep, MM_PER_UNIT};
use super::sdf::{cone, ellipse, ellipsoid, smax, smin};
use super::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// Linear skin albedo of the head: a light, slightly warm skin tone.
pub const SKIN_ALBEDO: [f32; 3] = [0.60, 0.39, 0.31];
/// Linear albedo of the backdrop: a light warm grey, so the head's shadow reads as a
/// shape on it rather than a hole.
pub const BACKDROP_ALBEDO: [f32; 3] = [0.50, 0.49, 0.47];

// --- Skull, face and neck (mm) -------------------------------------------------------

/// The skull's rays leave this ellipsoid along its outward normals. Normals of a convex
/// body never meet outside it, so one surface point per ray gives a shell that cannot
/// cross itself, as long as all of the surface lies outside the core (a test checks).
/// The core is tall and thin: across the face its normals run nearly horizontally, so
/// the upper sides of lips and nose wings face the rays as well as the undersides of
/// nose, brow and chin, and down the neck they stay horizontal, sampling it evenly.
const CORE_CENTER_MM: Vec3 = Vec3::new(0.0, -95.0, -5.0);
const CORE_RADII_MM: Vec3 = Vec3::new(40.0, 205.0, 45.0);
/// Longer than the distance from the core to any point of the skull's field.
const RAY_LENGTH_MM: f32 = 200.0;
/// Rows (crown to the base of the neck) and columns (around) of the skull's grid.
const HEAD_ROWS: usize = 190;
const HEAD_COLS: usize = 176;
/// Rows and columns are spread evenly over the surface's arc length, weighted: this
/// much denser between the hairline and below the chin and across the face (the
/// features need ~1 mm spacing, the back of the head does not), more again across the
/// nose, whose sides run almost along the rays, and sparser on the neck below the frame.
const FACE_ROW_WEIGHT: f32 = 2.6;
const FACE_COL_WEIGHT: f32 = 2.6;
const NOSE_COL_WEIGHT: f32 = 1.5;
const BELOW_FRAME_WEIGHT: f32 = 0.4;
/// Heights (mm) that bound the densely sampled face: the hairline, below the chin, and
/// the bottom of the mid shot's frame.
const HAIRLINE_MM: f32 = 70.0;
const UNDER_CHIN_MM: f32 = -135.0;
const FRAME_BOTTOM_MM: f32 = -245.0;
/// Heights (mm, at the front) of the parallels whose lengths spread the columns.
const PARALLELS_MM: [f32; 6] = [30.0, 0.0, -40.0, -70.0, -100.0, -180.0];

/// Squared half-width (mm^2) of the band around the midline over which mirrored
/// features are blended rather than folded.
const MIRROR_ROUNDING_MM2: f32 = 4.0;
/// Eyeball centre (right eye; the left mirrors it), the radius of the lid over it
/// and half the width of the opening between the lids.
const EYE_MM: Vec3 = Vec3::new(32.0, 1.0, 66.0);
const LID_RADIUS_MM: f32 = 13.0;
const EYE_HALF_WIDTH_MM: f32 = 12.0;
/// Height of the mouth line, where the lips overlap by 1 mm, half the mouth's width,
/// and the depth (along the dental arch) down to which the mouth line is grooved.
const MOUTH_Y_MM: f32 = -69.0;
const MOUTH_HALF_WIDTH_MM: f32 = 23.0;
const MOUTH_GROOVE_FLOOR_MM: f32 = 91.0;
/// The lips and the mouth line follow the dental arch: z drops by this times x^2 (mm).
const ARCH_PER_MM: f32 = 0.018;

// --- Neck (mm) -------------------------------------------------------------------------

/// The neck cylinder: axis depth, half-width (x) and half-depth (z).
const NECK_Z_MM: f32 = -8.0;
const NECK_HALF_WIDTH_MM: f32 = 56.0;
const NECK_HALF_DEPTH_MM: f32 = 54.0;
/// Where the neck cylinder is capped (inside the skull).
const NECK_TOP_MM: f32 = -40.0;
/// The neck's flat base, well below the frame of the mid shot, and the rounding of its
/// edge.
const NECK_BOTTOM_MM: f32 = -330.0;
const NECK_BASE_ROUND_MM: f32 = 5.0;
/// The neck widens toward the shoulders below this height.
const SHOULDER_START_MM: f32 = -160.0;

// --- Ears (mm) ---------------------------------------------------------------------------

/// Height and depth of an ear's centre (in the concha), and how far the back of the
/// ear turns away from the skull (the auriculocephalic angle is ~25-35 degrees).
const EAR_Y_MM: f32 = -15.0;
const EAR_Z_MM: f32 = -22.0;
const EAR_FLARE_DEG: f32 = 22.0;
/// How far the ear's front edge (the root of the helix and the tragus, `EAR_FRONT_MM`
/// ahead of its centre) sits inside the skull's surface: the front is attached, the
/// back stands free.
const EAR_EMBED_MM: f32 = 2.0;
const EAR_FRONT_MM: f32 = 14.0;
/// Cartilage thickness of the scapha and the fossae, the thin parts light crosses.
pub const EAR_THIN_MM: f32 = 2.4;
/// The helix rim rolls to about this thickness; the lobe is softer and thicker.
const HELIX_MM: f32 = 4.2;
const LOBE_MM: f32 = 5.0;
/// Rows per side of an ear (centre to rim) and columns around it.
const EAR_ROWS_PER_SIDE: usize = 20;
const EAR_COLS: usize = 64;
/// Rows of each side spent on the rounded rim.
const EAR_RIM_ROWS: usize = 5;

// --- Backdrop (units) --------------------------------------------------------------------

/// The backdrop is a shallow dome behind the head, bowing toward it: its middle, right
/// behind the head, sits `BACKDROP_Z` deep (4 units behind the back of the skull), and
/// it falls away faster downward than sideways. Under the default key light (60 degrees
/// to the viewer's right, 30 up) it faces the light less and less toward the lower left,
/// so it grades from light at the upper right to the ambient level in the lower left
/// corner, where the head's shadow goes: the shadow leaves the head as a crisp shape and
/// fades into that falloff, instead of ending as a black blob cut by the frame. The
/// renderer's shadows are hard; the falloff is what makes this one read as soft.
const BACKDROP_Z: f32 = -14.0;
/// Depth curvature (units of depth per unit^2) across and down the dome's middle.
const BACKDROP_CURVE_X: f32 = 0.006;
const BACKDROP_CURVE_Y: f32 = 0.012;
/// Beyond about this depth the dome's slope stops growing (a hyperbolic profile), so its
/// far parts stay within the camera's far plane at every shot.
const BACKDROP_DEPTH_SCALE: f32 = 30.0;
/// Large enough to fill the far shot (5x the close-up distance) at 16:9.
const BACKDROP_HALF_WIDTH: f32 = 180.0;
const BACKDROP_HALF_HEIGHT: f32 = 110.0;
const BACKDROP_COLS: usize = 120;
const BACKDROP_ROWS: usize = 80;

/// An ellipsoid's field at `p`, centred at `c` with radii `r` (mm): keeps the shapes
/// of `skull_field` one line each.
fn blob(p: Vec3, c: [f32; 3], r: [f32; 3]) -> f32 {
    ellipsoid(p - Vec3::from(c), Vec3::from(r))
}

/// Signed distance (roughly, in mm) to skull, face and neck; negative inside. Shapes are
/// added with `smin` (the last argument is the size of the fillet) and carved with
/// `smax` of a negated field. Centres and radii are anatomical sizes in mm, tuned by eye
/// on renders; the comment above each group names what it shapes.
fn skull_field(p: Vec3) -> f32 {
    // Bilateral features are written for the right side (+x) and mirrored, through a
    // rounded |x| so that features reaching the midline leave no crease along it.
    let q = Vec3::new((p.x * p.x + MIRROR_ROUNDING_MM2).sqrt(), p.y, p.z);
    let v = Vec3::new;

    // Cranium: a round vault over a longer braincase, with a fuller forehead.
    let mut d = smin(
        blob(p, [0.0, 40.0, -10.0], [76.0, 74.0, 92.0]),
        blob(p, [0.0, -5.0, -20.0], [68.0, 72.0, 88.0]),
        20.0,
    );
    d = smin(d, blob(p, [0.0, 30.0, 30.0], [60.0, 50.0, 60.0]), 10.0);
    // Glabella between the brows, and the brow ridge over each eye.
    d = smin(d, blob(p, [0.0, 10.0, 84.0], [16.0, 8.0, 8.0]), 8.0);
    d = smin(d, blob(q, [20.0, 12.0, 80.0], [18.0, 6.0, 9.0]), 12.0);
    // The mass of the face between the cheeks, and the cheekbones.
    d = smin(d, blob(p, [0.0, -35.0, 25.0], [64.0, 60.0, 58.0]), 16.0);
    d = smin(d, blob(q, [42.0, -10.0, 49.0], [21.0, 10.0, 15.0]), 20.0);
    // The jaw's ramus and the masseter in front of the ear.
    d = smin(d, blob(p, [0.0, -66.0, 5.0], [58.0, 36.0, 50.0]), 16.0);
    // Upper jaw under the nose; lower jaw; the base of the lower lip, which leaves a
    // fold above the chin; the jaw line from its angle to the chin; the chin.
    d = smin(d, blob(p, [0.0, -55.0, 55.0], [36.0, 30.0, 38.0]), 14.0);
    d = smin(d, blob(p, [0.0, -82.0, 38.0], [42.0, 30.0, 42.0]), 14.0);
    d = smin(d, blob(p, [0.0, -86.0, 54.0], [26.0, 16.0, 28.0]), 10.0);
    let jaw_line = cone(q, v(52.0, -78.0, -8.0), 10.0, v(20.0, -104.0, 56.0), 10.0);
    d = smin(d, jaw_line, 14.0);
    d = smin(d, blob(p, [0.0, -101.0, 71.0], [20.0, 14.0, 17.0]), 8.0);

    // Shallow eye sockets, then the lids over the eyeballs (`eyes`), open: an
    // almond between the upper lid's arc (4.5 mm above the centre) and the
    // lower's (3.5 below), 24 mm wide, carved from the lids' front down to
    // 1.5 mm inside the eyeball, which fills the opening.
    d = smax(d, -blob(q, [32.0, 4.0, 92.0], [18.0, 11.0, 14.0]), 8.0);
    let e = q - EYE_MM;
    d = smin(d, e.length() - LID_RADIUS_MM, 4.0);
    let w = (1.0 - (e.x / EYE_HALF_WIDTH_MM).powi(2)).max(0.0);
    let almond = (e.y - (4.0 * w + 0.5))
        .max(-(3.0 * w + 0.5) - e.y)
        .max(e.x.abs() - EYE_HALF_WIDTH_MM);
    let opening = almond.max(EYEBALL_RADIUS_MM - 1.5 - e.length()).max(-e.z);
    d = smax(d, -opening, 0.8);

    // Nose: a narrow bridge from the root to the tip, the tip, the wings.
    let narrow = Vec3::new(p.x * 1.4, p.y, p.z);
    let bridge = cone(narrow, v(0.0, 4.0, 81.0), 5.5, v(0.0, -30.0, 103.0), 8.5);
    let tip = blob(p, [0.0, -34.0, 102.0], [10.0, 9.5, 10.0]);
    let wing = blob(q, [13.0, -41.0, 92.0], [7.0, 6.5, 10.0]);
    d = smin(d, smin(smin(bridge, tip, 6.0), wing, 6.0), 5.0);

    // Lips, bent around the dental arch, meeting (a plain minimum) in a crease at the
    // mouth line, then a shallow groove along it (at most ~3 mm into the lips) so the
    // mouth reads under any light.
    let a = Vec3::new(p.x, p.y, p.z + ARCH_PER_MM * p.x * p.x);
    let upper = blob(a, [0.0, MOUTH_Y_MM + 4.5, 90.0], [22.0, 5.0, 5.5]);
    let lower = blob(a, [0.0, MOUTH_Y_MM - 5.0, 87.5], [20.0, 5.5, 6.0]);
    d = smin(d, upper.min(lower), 6.0);
    let slot = ((p.y - MOUTH_Y_MM).abs() - 0.4)
        .max(MOUTH_GROOVE_FLOOR_MM - a.z)
        .max(p.x.abs() - MOUTH_HALF_WIDTH_MM);
    d = smax(d, -slot, 1.2);

    // The neck, blended into jaw and skull, ending in a flat base below the frame.
    let neck = smax(neck_field(p), p.y - NECK_TOP_MM, 10.0);
    d = smin(d, neck, 14.0);
    smax(d, NECK_BOTTOM_MM - p.y, NECK_BASE_ROUND_MM)
}

/// The neck as an infinite vertical cylinder (mm), widening toward the shoulders.
fn neck_field(p: Vec3) -> f32 {
    let shoulders = smoothstep(SHOULDER_START_MM, NECK_BOTTOM_MM, p.y);
    let center = Vec2::new(0.0, NECK_Z_MM + 6.0 * shoulders);
    let radii = Vec2::new(
        NECK_HALF_WIDTH_MM + 50.0 * shoulders,
        NECK_HALF_DEPTH_MM + 6.0 * shoulders,
    );
    ellipse(Vec2::new(p.x, p.z) - center, radii)
}

/// Maps a uniform parameter in 0..1 to 0..1 so that samples crowd where a density is
/// high: the inverse of the normalised integral of a density given per equal cell.
struct Warp {
    cdf: Vec<f32>,
}

impl Warp {
    fn from_cells(density: &[f32]) -> Warp {
        let mut cdf = Vec::with_capacity(density.len() + 1);
        let mut sum = 0.0;
        cdf.push(0.0);
        for d in density {
            sum += d.max(0.0);
            cdf.push(sum);
        }
        if sum > 0.0 {
            for c in &mut cdf {
                *c /= sum;
            }
        }
        Warp { cdf }
    }

    fn map(&self, x: f32) -> f32 {
        let cells = self.cdf.len() - 1;
        if x <= 0.0 || cells == 0 {
            return 0.0;
        }
        if x >= 1.0 {
            return 1.0;
        }
        let i = self.cdf.partition_point(|&c| c < x).clamp(1, cells);
        let (c0, c1) = (self.cdf[i - 1], self.cdf[i]);
        let f = if c1 > c0 { (x - c0) / (c1 - c0) } else { 0.0 };
        (i as f32 - 1.0 + f) / cells as f32
    }
}

/// A closed grid with sphere topology: rows 0 and `rows` are poles, column `cols` repeats
/// column 0 (the UV seam). `pos(i, j)` must put every vertex of a pole row at one point
/// and must map rows and columns the way `(theta, phi) -> (sin t sin p, cos t, sin t cos p)`
/// does on the unit sphere (rows from +Y down, columns turning from +Z toward +X), which
/// makes the triangles counter-clockwise seen from outside. Positions are computed once
/// per distinct point, so seam and pole duplicates are bit-identical and the shell is
/// closed.
fn closed_grid(
    rows: usize,
    cols: usize,
    pos: impl Fn(usize, usize) -> Vec3,
    uv: impl Fn(usize, usize) -> [f32; 2],
) -> Mesh {
    let top = pos(0, 0);
    let bottom = pos(rows, 0);
    let ring: Vec<Vec<Vec3>> = (1..rows)
        .map(|i| (0..cols).map(|j| pos(i, j)).collect())
        .collect();
    let mut mesh = Mesh::default();
    for i in 0..=rows {
        for j in 0..=cols {
            let p = if i == 0 {
                top
            } else if i == rows {
                bottom
            } else {
                ring[i - 1][j % cols]
            };
            mesh.vertices.push(Vertex {
                position: p.into(),
                normal: [0.0, 1.0, 0.0],
                uv: uv(i, j),
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: usize, j: usize| (i * (cols + 1) + j) as u32;
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i != rows - 1 {
                mesh.indices.extend([a, b, c]);
            }
            if i != 0 {
                mesh.indices.extend([a, c, d]);
            }
        }
    }
    mesh
}

/// Unit direction for polar angle `theta` (from +Y) and azimuth `phi` (0 = +Z, the face).
fn direction(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * sp, ct, st * cp)
}

/// Where the core's ray for polar angle `theta` and azimuth `phi` leaves the core, and
/// its direction: the core's outward normal there.
fn core_ray(theta: f32, phi: f32) -> (Vec3, Vec3) {
    let u = direction(theta, phi);
    (
        CORE_CENTER_MM + u * CORE_RADII_MM,
        (u / CORE_RADII_MM).normalize(),
    )
}

/// The skull's surface point (mm) on the core's ray for `theta` and `phi`.
pub fn skull_point_mm(theta: f32, phi: f32) -> Vec3 {
    let (origin, dir) = core_ray(theta, phi);
    origin + dir * outermost_crossing(skull_field, origin, dir, RAY_LENGTH_MM)
}

/// Row and column warps: rows evenly spaced in weighted arc length down the front,
/// side and back of the head, columns in weighted arc length around it at several
/// heights of the face and neck.
fn skull_warps() -> (Warp, Warp) {
    const SAMPLES: usize = 720;
    let theta_at = |k: usize| k as f32 / SAMPLES as f32 * PI;
    let phi_at = |k: f32| k / SAMPLES as f32 * TAU - PI;
    let curve = |f: &dyn Fn(usize) -> Vec3| -> Vec<Vec3> { (0..=SAMPLES).map(f).collect() };
    let meridians: Vec<Vec<Vec3>> = [0.0, FRAC_PI_2, PI]
        .iter()
        .map(|&phi| curve(&|k| skull_point_mm(theta_at(k), phi)))
        .collect();
    let rows: Vec<f32> = (0..SAMPLES)
        .map(|k| {
            let length: f32 = meridians.iter().map(|m| m[k].distance(m[k + 1])).sum();
            let y = meridians[0][k].y;
            let weight = 1.0
                + (FACE_ROW_WEIGHT - 1.0) * plateau(y, UNDER_CHIN_MM, HAIRLINE_MM, 20.0)
                - (1.0 - BELOW_FRAME_WEIGHT)
                    * (1.0 - smoothstep(FRAME_BOTTOM_MM - 20.0, FRAME_BOTTOM_MM, y));
            length * weight
        })
        .collect();
    let parallels: Vec<Vec<Vec3>> = PARALLELS_MM
        .iter()
        .map(|&y| {
            let theta = ((y - CORE_CENTER_MM.y) / CORE_RADII_MM.y)
                .clamp(-1.0, 1.0)
                .acos();
            curve(&|k| skull_point_mm(theta, phi_at(k as f32)))
        })
        .collect();
    let cols: Vec<f32> = (0..SAMPLES)
        .map(|k| {
            let length: f32 = parallels.iter().map(|p| p[k].distance(p[k + 1])).sum();
            let phi_deg = phi_at(k as f32 + 0.5).to_degrees().abs();
            let weight = 1.0
                + (FACE_COL_WEIGHT - 1.0) * plateau(phi_deg, -1.0, 60.0, 20.0)
                + NOSE_COL_WEIGHT * plateau(phi_deg, -1.0, 12.0, 8.0);
            length * weight
        })
        .collect();
    (Warp::from_cells(&rows), Warp::from_cells(&cols))
}

/// The skull's angles for grid row `i` and column `j`; the seam is at the back.
fn skull_angles(rows: &Warp, cols: &Warp, i: usize, j: usize) -> (f32, f32) {
    let theta = rows.map(i as f32 / HEAD_ROWS as f32) * PI;
    let phi = cols.map(j as f32 / HEAD_COLS as f32) * TAU - PI;
    (theta, phi)
}

/// The skull shell, neck included: one point of the skull's field per core ray.
fn skull_shell() -> Mesh {
    let (rows, cols) = skull_warps();
    closed_grid(
        HEAD_ROWS,
        HEAD_COLS,
        |i, j| {
            let (theta, phi) = skull_angles(&rows, &cols, i, j);
            skull_point_mm(theta, phi) / MM_PER_UNIT
        },
        |i, j| {
            let (theta, phi) = skull_angles(&rows, &cols, i, j.min(HEAD_COLS - 1));
            // The seam column gets u = 1 rather than the u = 0 of its twin.
            let u = if j == HEAD_COLS {
                1.0
            } else {
                (phi + PI) / TAU
            };
            [u, theta / PI]
        },
    )
}

/// Where an ear sits, in scene units: `center` in the concha, `normal` pointing away from
/// the head (the outer face of the ear looks along it), `back` along the ear toward the
/// back of the head. Light travelling along `-normal` crosses the thin parts of the ear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ear {
    pub center: Vec3,
    pub normal: Vec3,
    pub back: Vec3,
}

impl Ear {
    /// A point of the ear's mid-plane, `s` mm toward the back and `t` mm up from the
    /// centre (before the cup shape and rim are added), in scene units.
    pub fn plane_point(&self, s: f32, t: f32) -> Vec3 {
        self.center + (self.back * s + Vec3::Y * t) / MM_PER_UNIT
    }

    /// A point in the scapha, the thin groove inside the helix rim at the upper back of
    /// the ear: where the thickness tests aim.
    pub fn scapha_point(&self) -> Vec3 {
        let psi = SCAPHA_PSI_DEG.to_radians();
        let r = ear_outline_mm(psi) * SCAPHA_RHO;
        self.plane_point(r * psi.sin(), r * psi.cos())
    }
}

/// Where an ear's UVs lie (both ears the same square): `[u, v, side]`. The
/// skull's parameterisation covers the whole unit square, so no square is the
/// ears' alone; this one is the back of the neck below the frame (theta
/// beyond 0.8 pi), which no texture of the face paints (the wrinkle maps'
/// zones are 0 there, `face_wrinkles`). Texture space packs every island
/// apart by its surface area, so the square's size does not change the
/// ears' share of its maps.
pub const EAR_UV: [f32; 3] = [0.0, 0.8, 0.2];

/// Where the tests and the scapha sit: angle from up toward the back, and the fraction of
/// the outline's radius.
const SCAPHA_PSI_DEG: f32 = 55.0;
const SCAPHA_RHO: f32 = 0.74;

/// Radius (mm) of the ear's outline at angle `psi` from up, turning toward the back:
/// a tall helix on top and behind, the lobe below, the tragus in front. Control radii
/// every 30 degrees, joined by a periodic Catmull-Rom spline.
fn ear_outline_mm(psi: f32) -> f32 {
    // up, then every 30 degrees toward the back, down, the front and up again.
    const RADII: [f32; 12] = [
        30.0, 28.0, 23.0, 20.0, 21.0, 27.0, 33.0, 29.0, 18.0, 14.0, 17.0, 25.0,
    ];
    let n = RADII.len();
    let x = psi.rem_euclid(TAU) / TAU * n as f32;
    let i = x.floor() as usize % n;
    let f = x - x.floor();
    let r = |k: isize| RADII[(i as isize + k).rem_euclid(n as isize) as usize];
    let (p0, p1, p2, p3) = (r(-1), r(0), r(1), r(2));
    0.5 * (2.0 * p1
        + (p2 - p0) * f
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * f * f
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * f * f * f)
}

/// Weight of angle `psi` within the arc from `from` to `to` (radians, turning toward the
/// back), with soft ends of width `soft`.
fn arc(psi: f32, from: f32, to: f32, soft: f32) -> f32 {
    let x = (psi - from).rem_euclid(TAU);
    let len = (to - from).rem_euclid(TAU);
    // Measure the part before `from` as negative so the soft start works.
    let x = if x > 0.5 * (len + TAU) { x - TAU } else { x };
    plateau(x, 0.0, len, soft)
}

/// Cartilage shape of the ear at normalised radius `rho` and angle `psi`: the offset of
/// its mid-surface along the ear's normal (mm, outward positive) and its thickness (mm).
fn ear_relief(rho: f32, psi: f32) -> (f32, f32) {
    let deg = |d: f32| d.to_radians();
    let helix = arc(psi, deg(-40.0), deg(150.0), deg(25.0));
    let lobe = arc(psi, deg(150.0), deg(225.0), deg(20.0));
    let antihelix = arc(psi, deg(0.0), deg(150.0), deg(30.0));
    let front = arc(psi, deg(200.0), deg(340.0), deg(40.0));
    // The whole ear is a shallow cup, the rim further out than the middle.
    let mut mid = 3.0 * rho * rho;
    // Concha: the bowl in front of the antihelix, toward the head.
    mid -= 5.0 * (1.0 - smoothstep(0.25, 0.6, rho));
    // Antihelix: a ridge inside the helix; the scapha is the groove between them.
    mid += 2.5 * antihelix * (-((rho - 0.56) / 0.09).powi(2)).exp();
    // Helix: the rim rolls outward.
    mid += 1.5 * helix * smoothstep(0.8, 0.95, rho);
    // Tragus: a small flap in front of the concha.
    let tragus = arc(psi, deg(250.0), deg(285.0), deg(20.0)) * plateau(rho, 0.6, 0.9, 0.15);
    mid += 2.0 * tragus;
    let mut thick = EAR_THIN_MM;
    thick += (HELIX_MM - EAR_THIN_MM) * helix * smoothstep(0.82, 0.95, rho);
    thick += (LOBE_MM - EAR_THIN_MM) * lobe * smoothstep(0.3, 0.7, rho);
    thick += 1.0 * front * (1.0 - rho);
    thick += 1.5 * tragus;
    (mid, thick)
}

/// The ear's two sides over a grid: rows from the outer side's centre to the rim and
/// back over the inner side, columns around the outline.
fn ear_shell(ear: &Ear) -> Mesh {
    let up = Vec3::Y;
    // (side, normal, up) is right-handed, like (x, y, z) of `closed_grid`'s unit sphere.
    let side = ear.normal.cross(up);
    // Columns turn from up toward `side`; `psi` turns from up toward the back.
    let mirror = side.dot(ear.back).signum();
    let flat_rows = EAR_ROWS_PER_SIDE - EAR_RIM_ROWS;
    let rows = 2 * EAR_ROWS_PER_SIDE;
    closed_grid(
        rows,
        EAR_COLS,
        |i, j| {
            let phi = j as f32 / EAR_COLS as f32 * TAU;
            let psi = mirror * phi;
            let outline = ear_outline_mm(psi);
            // Row within one side, counted from the centre, and which side.
            let (k, sign) = if i <= EAR_ROWS_PER_SIDE {
                (i, 1.0)
            } else {
                (rows - i, -1.0)
            };
            // The rim is a half round as wide as the ear is thick there.
            let rim_thickness = ear_relief(1.0, psi).1;
            let eps = (0.5 * rim_thickness / outline).min(0.2);
            let (rho, h) = if k <= flat_rows {
                (k as f32 / flat_rows as f32 * (1.0 - eps), 1.0)
            } else {
                let a = (k - flat_rows) as f32 / EAR_RIM_ROWS as f32 * FRAC_PI_2;
                (1.0 - eps + eps * a.sin(), a.cos())
            };
            let (mid, thick) = ear_relief(rho, psi);
            let r = rho * outline;
            let local = side * (r * phi.sin()) + up * (r * phi.cos());
            ear.center + (local + ear.normal * (mid + sign * 0.5 * thick * h)) / MM_PER_UNIT
        },
        |i, j| {
            let (u, v) = (j as f32 / EAR_COLS as f32, i as f32 / rows as f32);
            [EAR_UV[0] + EAR_UV[2] * u, EAR_UV[1] + EAR_UV[2] * v]
        },
    )
}

/// The skull's half-width (mm) at height `y` and depth `z`: where a ray along +x from
/// inside leaves the skull's field.
fn skull_half_width_mm(y: f32, z: f32) -> f32 {
    let origin = Vec3::new(0.0, y, z);
    outermost_crossing(skull_field, origin, Vec3::X, RAY_LENGTH_MM)
}

/// Right (+x) and left (-x) ear: flared back by `EAR_FLARE_DEG`, the front edge
/// `EAR_EMBED_MM` inside the side of the skull.
pub fn ears() -> [Ear; 2] {
    let flare = EAR_FLARE_DEG.to_radians();
    let (sin, cos) = flare.sin_cos();
    let front_z = EAR_Z_MM + EAR_FRONT_MM * cos;
    let x = skull_half_width_mm(EAR_Y_MM, front_z) - EAR_EMBED_MM + EAR_FRONT_MM * sin;
    [1.0f32, -1.0].map(|side| Ear {
        center: Vec3::new(side * x, EAR_Y_MM, EAR_Z_MM) / MM_PER_UNIT,
        normal: Vec3::new(side * cos, 0.0, sin),
        back: Vec3::new(side * sin, 0.0, -cos),
    })
}

/// The procedural face: skull, neck and both ears in one mesh (scene units), smooth
/// normals, tangents from the UVs.
pub fn head_mesh() -> Mesh {
    head_mesh_and_skull().0
}

/// [`head_mesh`] and how many of its first vertices are the skull's (the
/// ears follow): what the expressions move.
fn head_mesh_and_skull() -> (Mesh, usize) {
    let mut mesh = skull_shell();
    let skull = mesh.vertices.len();
    for ear in ears() {
        mesh.append(&ear_shell(&ear));
    }
    mesh.compute_normals();
    mesh.generate_tangents();
    (mesh, skull)
}

/// Depth of the backdrop below its middle at `(x, y)` (units): quadratic near the head,
/// growing only linearly far from it.
fn backdrop_sag(x: f32, y: f32) -> f32 {
    let q = BACKDROP_CURVE_X * x * x + BACKDROP_CURVE_Y * y * y;
    BACKDROP_DEPTH_SCALE * ((1.0 + 2.0 * q / BACKDROP_DEPTH_SCALE).sqrt() - 1.0)
}

/// The backdrop dome (scene units), facing +Z; its grid is finer near the middle.
pub fn backdrop_mesh() -> Mesh {
    let mut mesh = Mesh::default();
    // Squeezes a uniform -1..1 toward 0, so the middle gets smaller cells.
    let spread = |t: f32| t * (0.35 + 0.65 * t * t);
    for i in 0..=BACKDROP_ROWS {
        let v = i as f32 / BACKDROP_ROWS as f32;
        let y = BACKDROP_HALF_HEIGHT * spread(1.0 - 2.0 * v);
        for j in 0..=BACKDROP_COLS {
            let u = j as f32 / BACKDROP_COLS as f32;
            let x = BACKDROP_HALF_WIDTH * spread(2.0 * u - 1.0);
            mesh.vertices.push(Vertex {
                position: [x, y, BACKDROP_Z - backdrop_sag(x, y)],
                normal: [0.0, 0.0, 1.0],
                uv: [u, v],
                tangent: [1.0, 0.0, 0.0, 1.0],
            });
        }
    }
    let at = |i: usize, j: usize| (i * (BACKDROP_COLS + 1) + j) as u32;
    for i in 0..BACKDROP_ROWS {
        for j in 0..BACKDROP_COLS {
            // Rows run down and columns right, so (i, j), (i+1, j), (i+1, j+1) is
            // counter-clockwise seen from +Z.
            mesh.indices
                .extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            mesh.indices
                .extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh.compute_normals();
    mesh.generate_tangents();
    mesh
}

/// Matte, no subsurface: it catches the head's shadow and frames the silhouette.
fn backdrop_material() -> Material {
    Material {
        skin: false,
        base_color_factor: BACKDROP_ALBEDO,
        base_color: None,
        normal_map: None,
        specular_map: None,
        roughness_map: None,
        sss_map: None,
        wrinkles: None,
        roughness: 0.6,
        specular_intensity: 0.02,
        sss_strength: 0.0,
    }
}

/// The face scene: head, neck and ears in front of the backdrop, no files needed. The
/// renderer's default picture is its portrait (`RenderSettings::default()`: the head
/// alone in frame, key light 25 degrees to the right and 35 up, the cast shadow a soft
/// band behind the head's shaded side); the study view the tests pin (mid shot, light
/// 60 round and 30 up) throws the shadow to the lower left into the backdrop's
/// falloff. Light from behind (azimuth ~150) makes the ears' rims glow.
pub fn face_scene() -> Scene {
    // Built once a process (a second or two in a test build, the six
    // expressions' normals and tangents included); every caller gets a copy.
    static FACE: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    FACE.get_or_init(build_face_scene).clone()
}

fn build_face_scene() -> Scene {
    let (head, skull) = head_mesh_and_skull();
    let head_bounds = head.bounds();
    let expressions = expression_morph(&head, skull, MM_PER_UNIT);
    let mut scene = Scene {
        tracks: None,
        name: "procedural face".to_owned(),
        mm_per_unit: MM_PER_UNIT,
        head: Object {
            morph: Default::default(),
            mesh: head,
            // The expressions' wrinkles (thesis ch. 8), shown by their weights.
            material: Material {
                wrinkles: Some(super::face_wrinkles::face_wrinkle_maps(skull_point_mm)),
                ..Material::skin(SKIN_ALBEDO)
            },
        },
        parts: vec![eyes::eyes(EYE_MM, MM_PER_UNIT)],
        backdrop: Some(Object {
            morph: Default::default(),
            mesh: backdrop_mesh(),
            material: backdrop_material(),
        }),
        head_bounds,
        forward: Vec3::Z,
        source: Some(super::source::SceneSource::default()),
    };
    // Every weight 0: the neutral face, drawn without a deform pass.
    scene
        .head
        .set_morph(expressions)
        .expect("the expressions cover the skull's vertices");
    scene
}

#[cfg(test)]
mod tests {
    use super::super::{gltf_load, head_measure};
    use super::*;
    use std::collections::{HashMap, HashSet};
    use std::sync::OnceLock;

    /// The head takes a second or two to build in a test build: build it once.
    fn head() -> &'static Mesh {
        static HEAD: OnceLock<Mesh> = OnceLock::new();
        HEAD.get_or_init(head_mesh)
    }

    fn shells() -> Vec<Mesh> {
        let mut s = vec![skull_shell()];
        s.extend(ears().iter().map(ear_shell));
        s
    }

    fn key(m: &Mesh, i: u32) -> [u32; 3] {
        m.vertices[i as usize].position.map(f32::to_bits)
    }

    fn position(m: &Mesh, i: u32) -> Vec3 {
        Vec3::from(m.vertices[i as usize].position)
    }

    /// The march's long steps and secant find the crossing that careful steps (at most
    /// 6 mm, a tenth of the smallest fillet) and bisection find, on every third ray of
    /// the skull's grid and of a uniform grid over the wrinkle maps' angles: no step
    /// jumps over a thin part of the face (nose tip, lips, lids).
    #[test]
    fn the_march_finds_the_careful_marchs_crossings() {
        let careful = |origin: Vec3, dir: Vec3| {
            let mut outside = RAY_LENGTH_MM;
            let mut t = RAY_LENGTH_MM;
            while t > 0.0 {
                let d = skull_field(origin + dir * t);
                if d < 0.0 {
                    break;
                }
                outside = t;
                t = (t - (d * 0.5).clamp(0.1, 6.0)).max(0.0);
            }
            let mut inside = t;
            for _ in 0..20 {
                let mid = 0.5 * (inside + outside);
                if skull_field(origin + dir * mid) < 0.0 {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            0.5 * (inside + outside)
        };
        let (rows, cols) = skull_warps();
        let grid = (0..=HEAD_ROWS).flat_map(|i| (0..HEAD_COLS).map(move |j| (i, j)));
        let mut rays: Vec<(f32, f32)> = grid
            .map(|(i, j)| skull_angles(&rows, &cols, i, j))
            .collect();
        rays.extend((0..128 * 128).map(|k| {
            let (i, j) = ((k / 128) as f32 + 0.5, (k % 128) as f32 + 0.5);
            (i / 128.0 * PI, j / 128.0 * TAU - PI)
        }));
        let mut worst = 0.0f32;
        for &(theta, phi) in rays.iter().step_by(3) {
            let (origin, dir) = core_ray(theta, phi);
            let fast = outermost_crossing(skull_field, origin, dir, RAY_LENGTH_MM);
            let off = (fast - careful(origin, dir)).abs();
            assert!(off < 1e-3, "theta {theta} phi {phi}: {off} mm off");
            worst = worst.max(off);
        }
        assert!(worst > 0.0, "the two marches cannot agree to the bit");
    }

    /// Every directed edge (keyed by position, so seam and pole duplicates count as
    /// one) is used once and its reverse once: closed, consistently wound, manifold.
    fn assert_closed_and_consistent(m: &Mesh) {
        let mut directed = HashMap::new();
        for t in m.indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *directed.entry((key(m, a), key(m, b))).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            assert_ne!(a, b, "degenerate edge");
            assert_eq!(count, 1, "directed edge used {count} times");
            assert!(directed.contains_key(&(b, a)), "edge without a twin");
        }
    }

    /// Signed volume: positive when the triangles are counter-clockwise seen from
    /// outside.
    fn volume(m: &Mesh) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| position(m, t[0]).dot(position(m, t[1]).cross(position(m, t[2]))) / 6.0)
            .sum()
    }

    #[test]
    fn every_shell_is_closed_and_wound_outward() {
        for shell in shells() {
            assert_closed_and_consistent(&shell);
            assert!(volume(&shell) > 0.0);
        }
        assert_closed_and_consistent(head());
    }

    /// Where segment `p`-`q` crosses triangle `t` (Möller-Trumbore, strict interior).
    fn segment_hits_triangle(p: Vec3, q: Vec3, t: [Vec3; 3]) -> bool {
        let dir = q - p;
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let h = dir.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-12 {
            return false;
        }
        let s = p - t[0];
        let u = s.dot(h) / det;
        let r = s.cross(e1);
        let v = dir.dot(r) / det;
        let along = e2.dot(r) / det;
        u > 0.0 && v > 0.0 && u + v < 1.0 && along > 0.0 && along < 1.0
    }

    /// Pairs of triangles that cross each other, skipping pairs that share a corner
    /// (neighbours touch by construction). Triangles are binned into a uniform grid by
    /// their bounds so only nearby pairs are tested.
    fn self_intersections(m: &Mesh) -> usize {
        const CELL: f32 = 0.4;
        let tris: Vec<[u32; 3]> = m
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let corners = |t: &[u32; 3]| t.map(|i| position(m, i));
        let cell = |p: Vec3| (p / CELL).floor().as_ivec3();
        let mut grid: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
        for (n, t) in tris.iter().enumerate() {
            let c = corners(t);
            let (lo, hi) = (
                cell(c[0].min(c[1]).min(c[2])),
                cell(c[0].max(c[1]).max(c[2])),
            );
            for x in lo.x..=hi.x {
                for y in lo.y..=hi.y {
                    for z in lo.z..=hi.z {
                        grid.entry(glam::IVec3::new(x, y, z)).or_default().push(n);
                    }
                }
            }
        }
        let mut tested = HashSet::new();
        let mut crossings = 0;
        for bin in grid.values() {
            for (k, &a) in bin.iter().enumerate() {
                for &b in &bin[k + 1..] {
                    let pair = (a.min(b), a.max(b));
                    if !tested.insert(pair) {
                        continue;
                    }
                    let (ka, kb) = (tris[a].map(|i| key(m, i)), tris[b].map(|i| key(m, i)));
                    if ka.iter().any(|k| kb.contains(k)) {
                        continue;
                    }
                    let (ta, tb) = (corners(&tris[a]), corners(&tris[b]));
                    let crosses = |t: [Vec3; 3], other: [Vec3; 3]| {
                        (0..3).any(|e| segment_hits_triangle(t[e], t[(e + 1) % 3], other))
                    };
                    if crosses(ta, tb) || crosses(tb, ta) {
                        crossings += 1;
                    }
                }
            }
        }
        crossings
    }

    #[test]
    fn no_shell_crosses_itself() {
        for shell in shells() {
            assert_eq!(self_intersections(&shell), 0);
        }
    }

    #[test]
    fn the_core_is_inside_the_skull() {
        // The argument that the skull shell cannot cross itself needs every ray to start
        // inside the surface...
        for i in 0..=90 {
            for j in 0..180 {
                let (theta, phi) = (i as f32 / 90.0 * PI, j as f32 / 180.0 * TAU);
                let (origin, dir) = core_ray(theta, phi);
                assert!(skull_field(origin) < 0.0, "core point {origin} is outside");
                // ... and to end outside it, so the outermost crossing is on the ray.
                let end = origin + dir * RAY_LENGTH_MM;
                assert!(skull_field(end) > 0.0, "ray end {end} is inside");
            }
        }
    }

    #[test]
    fn valid_with_unit_normals_and_orthogonal_tangents() {
        let m = head();
        m.validate().unwrap();
        for v in &m.vertices {
            let n = Vec3::from(v.normal);
            let t = glam::Vec4::from(v.tangent);
            assert!((n.length() - 1.0).abs() < 1e-4);
            assert!((t.truncate().length() - 1.0).abs() < 1e-4);
            assert!(t.truncate().dot(n).abs() < 1e-4);
            assert!(t.w == 1.0 || t.w == -1.0);
            assert!(v.uv.iter().all(|c| (0.0..=1.0).contains(c)));
        }
        let tris = m.triangle_count();
        assert!((20_000..=80_000).contains(&tris), "{tris} triangles");
    }

    #[test]
    fn measures_as_a_230_mm_head_facing_plus_z() {
        let s = face_scene();
        let height_mm = s.head_height_units() * s.mm_per_unit;
        assert!((height_mm - 230.0).abs() < 3.0, "{height_mm} mm");
        assert_eq!(gltf_load::face_direction(&s.head.mesh), Vec3::Z);
        assert_eq!(s.forward, Vec3::Z);
        let (chin, _) = head_measure::chin_and_crown(&s.head.mesh, s.forward);
        // The neck leaves the frame of the mid shot: it reaches a head height below the
        // chin.
        assert!(s.head_bounds.min.y < chin - 0.9 * s.head_height_units());
        let m = &s.head.material;
        assert!(m.skin && m.sss_strength == 1.0);
        assert_eq!(s.mm_per_unit, MM_PER_UNIT);
    }

    /// Every distance along the ray at which it crosses a triangle, nearest first.
    fn ray_hits(m: &Mesh, origin: Vec3, dir: Vec3) -> Vec<f32> {
        let mut hits: Vec<f32> = m
            .indices
            .chunks_exact(3)
            .filter_map(|t| {
                let c = [position(m, t[0]), position(m, t[1]), position(m, t[2])];
                let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
                let h = dir.cross(e2);
                let det = e1.dot(h);
                if det.abs() < 1e-12 {
                    return None;
                }
                let s = origin - c[0];
                let (u, r) = (s.dot(h) / det, s.cross(e1));
                let v = dir.dot(r) / det;
                let along = e2.dot(r) / det;
                (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && along > 0.0).then_some(along)
            })
            .collect();
        hits.sort_by(f32::total_cmp);
        // A ray through a shared edge hits both triangles at one point.
        hits.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
        hits
    }

    /// The face's profile: how far forward (mm) the head reaches at height `y_mm` on
    /// the midline, from a ray coming from the front.
    fn profile_mm(m: &Mesh, y_mm: f32) -> f32 {
        let start = Vec3::new(0.0, y_mm, 300.0) / MM_PER_UNIT;
        let hits = ray_hits(m, start, Vec3::NEG_Z);
        300.0 - hits[0] * MM_PER_UNIT
    }

    #[test]
    fn profile_has_brow_nose_lips_and_chin_in_order() {
        let m = skull_shell();
        // Sample the midline every half millimetre from the hairline to under the chin.
        let ys: Vec<f32> = (0..=400).map(|k| 60.0 - 0.5 * k as f32).collect();
        let z: Vec<f32> = ys.iter().map(|&y| profile_mm(&m, y)).collect();
        // Local maxima: highest within 6 mm (strictly above the samples on one side, so
        // a flat top counts once), standing at least 0.5 mm above the lowest point
        // within 10 mm on either side.
        let peaks: Vec<(f32, f32)> = (20..z.len() - 20)
            .filter(|&k| {
                (k - 12..k).all(|j| z[j] < z[k])
                    && (k + 1..=k + 12).all(|j| z[j] <= z[k])
                    && z[k - 20..k].iter().any(|&w| w <= z[k] - 0.5)
                    && z[k + 1..=k + 20].iter().any(|&w| w <= z[k] - 0.5)
            })
            .map(|k| (ys[k], z[k]))
            .collect();
        let names = ["brow", "nose tip", "upper lip", "lower lip", "chin"];
        assert_eq!(peaks.len(), names.len(), "peaks (y, z) mm: {peaks:?}");
        let [brow, tip, upper, lower, chin] = [0, 1, 2, 3, 4].map(|k| peaks[k]);
        // The nose tip is the most forward point, well ahead of the lips and the chin.
        assert!(tip.1 > brow.1 + 15.0 && tip.1 > upper.1 + 10.0, "{peaks:?}");
        assert!(upper.1 > chin.1 && lower.1 > chin.1, "{peaks:?}");
        // The mouth line is a valley between the lips.
        let mouth = z
            .iter()
            .zip(&ys)
            .filter(|(_, &y)| y < upper.0 && y > lower.0)
            .map(|(z, _)| *z)
            .fold(f32::INFINITY, f32::min);
        assert!(mouth < lower.1 - 1.0, "mouth {mouth} mm, {peaks:?}");
        eprintln!("profile peaks (y, z) mm: {peaks:?}, mouth line at z = {mouth}");
    }

    #[test]
    fn nose_protrudes() {
        let m = skull_shell();
        let tip = profile_mm(&m, -34.0);
        // Subnasale: the deepest point of the profile between nose and upper lip.
        let subnasale = (0..=30)
            .map(|k| profile_mm(&m, -44.0 - 0.5 * k as f32))
            .fold(f32::INFINITY, f32::min);
        // The open eyes: the eyeball's front at the pupil, seen through the lids.
        let eyes = eyes::eyes(EYE_MM, MM_PER_UNIT).mesh;
        let front = |mesh: &Mesh, y_mm: f32| {
            300.0
                - ray_hits(
                    mesh,
                    Vec3::new(EYE_MM.x, y_mm, 300.0) / MM_PER_UNIT,
                    Vec3::NEG_Z,
                )[0] * MM_PER_UNIT
        };
        let pupil = front(&eyes, EYE_MM.y);
        eprintln!(
            "nose tip z {tip} mm: {} mm ahead of the subnasale, {} mm ahead of the pupils",
            tip - subnasale,
            tip - pupil
        );
        assert!(
            (14.0..=25.0).contains(&(tip - subnasale)),
            "{}",
            tip - subnasale
        );
        assert!((25.0..=45.0).contains(&(tip - pupil)), "{}", tip - pupil);
        // Through the opening the eyeball is in front of the skin; above and
        // below it the lids cover the eyeball.
        for (y, open) in [
            (0.0, true),
            (3.0, true),
            (-2.5, true),
            (8.0, false),
            (-7.0, false),
        ] {
            let y = EYE_MM.y + y;
            let (skin, ball) = (front(&m, y), front(&eyes, y));
            assert_eq!(ball > skin, open, "at {y} mm: skin {skin}, eyeball {ball}");
        }
    }

    #[test]
    fn ears_are_thin_where_light_crosses_them() {
        let head = head();
        for ear in ears() {
            let shell = ear_shell(&ear);
            // Across the scapha and the fossae inside the helix, along the ear's thin
            // axis (at angles off the grid's columns, so the rays miss its edges).
            for (psi_deg, rho) in [
                (SCAPHA_PSI_DEG, SCAPHA_RHO),
                (22.0, 0.69),
                (88.0, 0.71),
                (43.0, 0.47),
            ] {
                let psi = f32::to_radians(psi_deg);
                let r = ear_outline_mm(psi) * rho;
                let p = ear.plane_point(r * psi.sin(), r * psi.cos());
                let hits = ray_hits(&shell, p + ear.normal * 2.0, -ear.normal);
                assert_eq!(hits.len(), 2, "{psi_deg}: {hits:?}");
                let thickness_mm = (hits[1] - hits[0]) * MM_PER_UNIT;
                assert!(
                    (2.0..=4.0).contains(&thickness_mm),
                    "{psi_deg} deg: {thickness_mm} mm"
                );
                // Nothing of the skull lies between the light and that part of the ear.
                let all = ray_hits(head, p + ear.normal * 2.0, -ear.normal);
                assert!((all[0] - hits[0]).abs() < 1e-4 && (all[1] - hits[1]).abs() < 1e-4);
            }
            let p = ear.scapha_point();
            let hits = ray_hits(&shell, p + ear.normal * 2.0, -ear.normal);
            eprintln!(
                "ear at {}: scapha {} mm thick",
                ear.center,
                (hits[1] - hits[0]) * MM_PER_UNIT
            );
            // The front of the ear is attached: inside the skull.
            let front = ear.plane_point(-EAR_FRONT_MM, 0.0) * MM_PER_UNIT;
            assert!(skull_field(front) < 0.0, "{front}");
        }
    }

    #[test]
    fn backdrop_lies_behind_the_head_and_faces_it() {
        let s = face_scene();
        let bd = s.backdrop.as_ref().unwrap();
        bd.mesh.validate().unwrap();
        assert!(!bd.material.skin);
        let b = bd.mesh.bounds();
        assert!(
            b.max.z < s.head_bounds.min.z,
            "{b:?} vs {:?}",
            s.head_bounds
        );
        assert!(bd.mesh.vertices.iter().all(|v| v.normal[2] > 0.0));
        for t in bd.mesh.indices.chunks_exact(3) {
            let (a, b, c) = (
                position(&bd.mesh, t[0]),
                position(&bd.mesh, t[1]),
                position(&bd.mesh, t[2]),
            );
            assert!((b - a).cross(c - a).z > 0.0);
        }
        // It fills the far shot (5x the close-up distance, 16:9) around the head.
        let c = s.head_center();
        let d = 5.0
            * super::super::camera::Camera::close_up_distance_heads(20.0)
            * s.head_height_units();
        let half_h = (d + c.z - b.max.z) * 10f32.to_radians().tan();
        assert!(b.min.y < c.y - half_h && b.max.y > c.y + half_h);
        assert!(b.min.x < c.x - 16.0 / 9.0 * half_h && b.max.x > c.x + 16.0 / 9.0 * half_h);
    }

    #[test]
    fn built_the_same_every_time() {
        assert_eq!(&head_mesh(), head());
        assert_eq!(backdrop_mesh(), backdrop_mesh());
    }
}
