//! The procedural face's chromophore maps (thesis ch. 7), made by code: a
//! neutral melanin map, a neutral haemoglobin map, and the haemoglobin map
//! of each basis state of the appearance rig (`skin::colour::rig` derives
//! the rig's scales and biases from their local statistics, as the thesis
//! derives them from its measured maps).
//!
//! The thesis' maps are measurements of a subject (7.3) and did not survive
//! as data, so these are dermis's own, written from what the chapter
//! observes and reports:
//! - blood lies where the vessels are: more in the cheeks, the nose, the
//!   lips and the chin than on the forehead (Figure 7.8's neutral map);
//! - its local histograms are near-Gaussian (Figure 7.7): the texture is a
//!   sum of lattice noises about each region's mean;
//! - an expression moves blood within its regions (joy's cheeks, anger's
//!   brow, disgust's nose), keeping the capillaries where they are: each
//!   state's map is the neutral texture, shifted by a texel or two (the
//!   thesis' maps were aligned by hand, not to the pixel: 7.4.2) and scaled
//!   about a moved mean;
//! - global states: anger at 127% of the neutral blood and fear at 81%
//!   (7.7's figures), exercise and alcohol (Figure 7.10), and a blush (the
//!   issue's animated state).
//!
//! The gains are tuned by eye, not measured; they are the rig's inputs, and
//! the rig is tested on any map (`skin::colour`).
//!
//! Every map is `COLOUR_SIZE` texels a side over the skull's UV square
//! (`face_surface`), volume fractions: melanin C_m and dermal haemoglobin
//! C_hd in Table 7.1's ranges (0-0.5, 0-0.32).

use glam::{Vec2, Vec3};

use super::face_surface::{in_parallel, Skull, SurfaceGrid};
use super::face_wrinkles::{front, U_RANGE, V_RANGE};
use super::procedural::smoothstep;

/// Texels a side of every chromophore map.
pub const COLOUR_SIZE: usize = 512;

/// The rig's basis states, in the order of their maps: the six expressions
/// (`expressions::EXPRESSIONS`' order), then the global states.
pub const STATES: [&str; 9] = [
    "joy", "surprise", "fear", "anger", "disgust", "sad", "exercise", "alcohol", "blush",
];

/// The neutral dermal haemoglobin away from the face's vascular regions: 1%
/// (a dermis carries 0.2-7% blood, Jacques, OMLC). Low in that range on
/// purpose: the skin model's colour saturates with blood (at 1% melanin,
/// green over red falls by 7% from 0.5% to 2% blood and by 2.6% from 2% to
/// 4.2%), so a face already full of blood could hardly blush.
const BASE_BLOOD: f32 = 0.01;

/// The maps.
#[derive(Clone, Debug, PartialEq)]
pub struct ChromophoreMaps {
    pub size: usize,
    pub melanin: Vec<f32>,
    pub haemoglobin: Vec<f32>,
    /// Each of `STATES`' haemoglobin map.
    pub states: Vec<Vec<f32>>,
}

/// A region of the face: a Gaussian blob at `centre` (mm, x mirrored to
/// both sides when `mirrored`) of standard deviations `radii` (mm).
#[derive(Clone, Copy)]
struct Region {
    centre: [f32; 2],
    radii: [f32; 2],
    mirrored: bool,
}

const fn region(centre: [f32; 2], radii: [f32; 2], mirrored: bool) -> Region {
    Region {
        centre,
        radii,
        mirrored,
    }
}

const CHEEKS: Region = region([40.0, -30.0], [14.0, 12.0], true);
const NOSE: Region = region([0.0, -28.0], [7.0, 11.0], false);
const LIPS: Region = region([0.0, -69.0], [16.0, 5.0], false);
const UPPER_LIP: Region = region([0.0, -60.0], [12.0, 4.5], false);
const CHIN: Region = region([0.0, -98.0], [12.0, 9.0], false);
const FOREHEAD: Region = region([0.0, 42.0], [36.0, 12.0], false);
const GLABELLA: Region = region([0.0, 12.0], [8.0, 7.0], false);
const UNDER_EYES: Region = region([32.0, -12.0], [10.0, 6.0], true);
const NASOLABIAL: Region = region([24.0, -55.0], [7.0, 9.0], true);

impl Region {
    /// The blob's weight at `p` (mm) on the face's front, 0..1.
    fn at(&self, p: Vec3) -> f32 {
        let x = if self.mirrored { p.x.abs() } else { p.x };
        let d = (Vec2::new(x, p.y) - Vec2::from(self.centre)) / Vec2::from(self.radii);
        front(p.z) * (-0.5 * d.length_squared()).exp()
    }
}

/// The neutral haemoglobin's regional mean: (region, added fraction).
const NEUTRAL_BLOOD: [(Region, f32); 5] = [
    (CHEEKS, 0.008),
    (NOSE, 0.007),
    (LIPS, 0.02),
    (CHIN, 0.003),
    (NASOLABIAL, 0.002),
];

/// A state: a global gain on the blood, regional gains (region, gain), the
/// texture's amplitude relative to the neutral's, and the texels its
/// texture is shifted by (alignment).
struct State {
    global: f32,
    regions: &'static [(Region, f32)],
    amplitude: f32,
    shift: [f32; 2],
}

/// `STATES`' definitions, in its order.
const STATE_GAINS: [State; 9] = [
    // joy: the cheeks raised and flushed (AU 6, 12).
    State {
        global: 1.0,
        regions: &[(CHEEKS, 1.45), (NASOLABIAL, 1.2)],
        amplitude: 1.1,
        shift: [1.0, 0.5],
    },
    // surprise: the forehead stretched and blanched.
    State {
        global: 1.0,
        regions: &[(FOREHEAD, 0.8)],
        amplitude: 1.0,
        shift: [-0.5, 1.0],
    },
    // fear: pallor, 81% of the neutral blood (7.7).
    State {
        global: 0.81,
        regions: &[],
        amplitude: 0.9,
        shift: [0.5, -1.0],
    },
    // anger: 127% (7.7), more on the brow.
    State {
        global: 1.27,
        regions: &[(FOREHEAD, 1.15), (GLABELLA, 1.25)],
        amplitude: 1.2,
        shift: [-1.0, -0.5],
    },
    // disgust: the nose wrinkled (AU 9) and the upper lip raised (AU 10).
    State {
        global: 1.0,
        regions: &[(NOSE, 1.35), (UPPER_LIP, 1.15)],
        amplitude: 1.1,
        shift: [1.5, 0.0],
    },
    // sadness: the eyes and nose reddened, the chin raised (AU 17).
    State {
        global: 1.0,
        regions: &[(UNDER_EYES, 1.25), (NOSE, 1.2), (CHIN, 1.2)],
        amplitude: 1.0,
        shift: [0.0, 1.5],
    },
    // exercise: flushed all over, most in the cheeks (Figure 7.10).
    State {
        global: 1.3,
        regions: &[(CHEEKS, 1.5), (FOREHEAD, 1.2)],
        amplitude: 1.2,
        shift: [-1.5, 0.5],
    },
    // alcohol: cheeks and nose, the capillaries showing (Figure 7.10).
    State {
        global: 1.1,
        regions: &[(CHEEKS, 1.45), (NOSE, 1.6)],
        amplitude: 1.4,
        shift: [0.5, 1.5],
    },
    // a blush: the cheeks, and a little the nose.
    State {
        global: 1.0,
        regions: &[(CHEEKS, 1.9), (NOSE, 1.25)],
        amplitude: 1.15,
        shift: [-0.5, -1.5],
    },
];

/// A lattice value noise in [-1, 1] with cells `cell` texels wide: smooth,
/// deterministic, the same on every machine.
fn value_noise(x: f32, y: f32, cell: f32, seed: u32) -> f32 {
    let (fx, fy) = (x / cell, y / cell);
    let (ix, iy) = (fx.floor(), fy.floor());
    let lattice = |i: f32, j: f32| {
        let mut k = (i as i32 as u32).wrapping_mul(0x8da6_b343)
            ^ (j as i32 as u32).wrapping_mul(0xd816_3841)
            ^ seed.wrapping_mul(0xcb1a_b31f);
        k ^= k >> 15;
        k = k.wrapping_mul(0x2c1b_3c6d);
        k ^= k >> 12;
        k = k.wrapping_mul(0x297a_2d39);
        k ^= k >> 15;
        k as f32 / u32::MAX as f32 * 2.0 - 1.0
    };
    let (tx, ty) = (smoothstep(0.0, 1.0, fx - ix), smoothstep(0.0, 1.0, fy - iy));
    let row = |j: f32| lattice(ix, j) + (lattice(ix + 1.0, j) - lattice(ix, j)) * tx;
    row(iy) + (row(iy + 1.0) - row(iy)) * ty
}

/// The capillaries' texture about 1: fine and middle-sized lattice noise,
/// near-Gaussian in every window (a sum of independent octaves).
fn capillaries(x: f32, y: f32) -> f32 {
    1.0 + 0.16 * value_noise(x, y, 1.7, 1)
        + 0.12 * value_noise(x, y, 4.3, 2)
        + 0.08 * value_noise(x, y, 11.0, 3)
}

/// The neutral blood's regional mean at surface point `p` (mm).
fn neutral_mean(p: Vec3) -> f32 {
    BASE_BLOOD
        + NEUTRAL_BLOOD
            .iter()
            .map(|(r, add)| r.at(p) * add)
            .sum::<f32>()
}

/// A state's gain on the regional mean at `p`.
fn state_gain(s: &State, p: Vec3) -> f32 {
    s.global
        * s.regions
            .iter()
            .fold(1.0, |g, (r, gain)| g * (1.0 + (gain - 1.0) * r.at(p)))
}

/// The face's chromophore maps over `skull` (`face::skull_point_mm`), its
/// melanin about `melanin` (a tone's fraction, `skin::colour::lut`).
pub fn face_chromophore_maps(skull: Skull, melanin: f32) -> ChromophoreMaps {
    let n = COLOUR_SIZE;
    let at = |k: usize| (k as f32 + 0.5) / n as f32;
    let inside = |k: usize, (lo, hi): (f32, f32)| (lo..=hi).contains(&at(k));
    let rows: Vec<usize> = (0..n).filter(|&i| inside(i, V_RANGE)).collect();
    let cols: Vec<usize> = (0..n).filter(|&j| inside(j, U_RANGE)).collect();
    let grid = SurfaceGrid::new(
        skull,
        n,
        (rows[0], rows[rows.len() - 1]),
        (cols[0], cols[cols.len() - 1]),
    );
    // Off the face's rectangle the regions are all 0: a point far behind
    // the face stands for every texel there.
    let behind = Vec3::new(0.0, 0.0, -100.0);
    let point = |i: usize, j: usize| {
        if inside(i, V_RANGE) && inside(j, U_RANGE) {
            grid.point(i, j)
        } else {
            behind
        }
    };
    let all_rows: Vec<usize> = (0..n).collect();
    let texels = in_parallel(&all_rows, |&i| {
        (0..n)
            .map(|j| {
                let p = point(i, j);
                let (x, y) = (j as f32, i as f32);
                let mean = neutral_mean(p);
                let texture = capillaries(x, y) - 1.0;
                let blood = mean * (1.0 + texture);
                let pigment = melanin
                    * (1.0 + 0.1 * value_noise(x, y, 9.0, 7) + 0.05 * value_noise(x, y, 2.5, 8));
                let states: Vec<f32> = STATE_GAINS
                    .iter()
                    .map(|s| {
                        let shifted = capillaries(x + s.shift[0], y + s.shift[1]) - 1.0;
                        mean * state_gain(s, p) * (1.0 + s.amplitude * shifted)
                    })
                    .collect();
                (pigment, blood, states)
            })
            .collect::<Vec<_>>()
    });
    let mut maps = ChromophoreMaps {
        size: n,
        melanin: Vec::with_capacity(n * n),
        haemoglobin: Vec::with_capacity(n * n),
        states: vec![Vec::with_capacity(n * n); STATES.len()],
    };
    for (pigment, blood, states) in texels.into_iter().flatten() {
        maps.melanin.push(pigment);
        maps.haemoglobin.push(blood);
        for (m, v) in maps.states.iter_mut().zip(states) {
            m.push(v);
        }
    }
    maps
}

/// The texel (row, column) of the chromophore maps whose surface point on
/// the face's front is nearest `p` (mm, the face's x and y): where tests and
/// pictures look at a feature.
pub fn texel_nearest(skull: Skull, p: Vec2) -> (usize, usize) {
    let n = COLOUR_SIZE;
    let at = |k: usize| (k as f32 + 0.5) / n as f32;
    let range = |(lo, hi): (f32, f32)| {
        let ks: Vec<usize> = (0..n).filter(|&k| (lo..=hi).contains(&at(k))).collect();
        (ks[0], ks[ks.len() - 1])
    };
    let (rows, cols) = (range(V_RANGE), range(U_RANGE));
    let grid = SurfaceGrid::new(skull, n, rows, cols);
    let mut best = (f32::MAX, (rows.0, cols.0));
    for i in rows.0..=rows.1 {
        for j in cols.0..=cols.1 {
            let q = grid.point(i, j);
            if front(q.z) < 1.0 {
                continue;
            }
            let d = Vec2::new(q.x, q.y).distance(p);
            if d < best.0 {
                best = (d, (i, j));
            }
        }
    }
    best.1
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::sync::OnceLock;

    /// The maps about 3.8% melanin, made once for every test that reads them.
    pub(crate) fn maps() -> &'static ChromophoreMaps {
        static MAPS: OnceLock<ChromophoreMaps> = OnceLock::new();
        MAPS.get_or_init(|| face_chromophore_maps(crate::scene::face::skull_point_mm, 0.038))
    }

    fn texel_at(p: Vec2) -> (usize, usize) {
        texel_nearest(crate::scene::face::skull_point_mm, p)
    }

    fn mean_around(m: &[f32], (i, j): (usize, usize)) -> f32 {
        let mut s = 0.0;
        for di in 0..9 {
            for dj in 0..9 {
                s += m[(i + di - 4) * COLOUR_SIZE + j + dj - 4];
            }
        }
        s / 81.0
    }

    #[test]
    fn the_maps_lie_in_table_7_1s_ranges() {
        let m = maps();
        assert_eq!(m.states.len(), STATES.len());
        for v in m.melanin.iter() {
            assert!((0.0..=0.5).contains(v), "melanin {v}");
        }
        for map in std::iter::once(&m.haemoglobin).chain(&m.states) {
            for v in map {
                assert!((0.0..=0.32).contains(v), "haemoglobin {v}");
            }
        }
    }

    // The neutral face carries more blood in its cheeks, nose and lips than
    // on its forehead; joy flushes the cheeks, fear pales all of it to 81%,
    // disgust reddens the nose, and the back of the head does not change
    // under a state without a global gain.
    #[test]
    fn blood_lies_where_the_states_put_it() {
        let m = maps();
        let (cheek, forehead, nose, lips) = (
            texel_at(Vec2::new(42.0, -30.0)),
            texel_at(Vec2::new(0.0, 42.0)),
            texel_at(Vec2::new(0.0, -28.0)),
            texel_at(Vec2::new(0.0, -66.0)),
        );
        let h = &m.haemoglobin;
        assert!(mean_around(h, cheek) > 1.4 * mean_around(h, forehead));
        assert!(mean_around(h, nose) > 1.3 * mean_around(h, forehead));
        assert!(mean_around(h, lips) > 2.0 * mean_around(h, forehead));
        let state = |name: &str| &m.states[STATES.iter().position(|s| *s == name).unwrap()];
        let ratio = |s: &[f32], at| mean_around(s, at) / mean_around(h, at);
        assert!(
            ratio(state("joy"), cheek) > 1.3,
            "{}",
            ratio(state("joy"), cheek)
        );
        assert!((ratio(state("joy"), forehead) - 1.0).abs() < 0.05);
        assert!((ratio(state("fear"), cheek) - 0.81).abs() < 0.03);
        assert!(ratio(state("disgust"), nose) > 1.15);
        // The back of the head (row 256, column 12: behind the ear).
        for s in ["joy", "blush", "disgust"] {
            let r = mean_around(state(s), (256, 12)) / mean_around(h, (256, 12));
            assert!((r - 1.0).abs() < 0.05, "{s}: {r}");
        }
    }
}
