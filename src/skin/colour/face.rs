//! The procedural face's appearance rig (thesis ch. 7): its generated
//! chromophore maps (`scene::face_colour`) as a melanin map and the rig of
//! eq. 7.4-7.6 over its haemoglobin, and the skin colour of any blend of
//! its states through the lookup table (eq. 7.7).

use super::histogram::Map;
use super::lut::ColourTable;
use super::rig::AppearanceRig;
use crate::scene::face_colour::{face_chromophore_maps, ChromophoreMaps, STATES};

/// Eq. 7.1's window radius on the face's maps (texels; about 9 mm across
/// the cheeks at 512 texels a side): wider than the capillaries' texture,
/// narrower than the regions a state moves blood in.
pub const WINDOW_TEXELS: f32 = 8.0;

/// The face's melanin and its haemoglobin rig.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceAppearance {
    pub melanin: Map,
    pub rig: AppearanceRig,
}

impl FaceAppearance {
    /// The rig of `maps` (`scene::face_colour`).
    pub fn from_maps(maps: &ChromophoreMaps) -> FaceAppearance {
        let n = maps.size;
        let map = |d: &Vec<f32>| Map::new(n, n, d.clone()).expect("square chromophore maps");
        let states: Vec<(String, Map)> = STATES
            .iter()
            .zip(&maps.states)
            .map(|(name, m)| (name.to_string(), map(m)))
            .collect();
        FaceAppearance {
            melanin: map(&maps.melanin),
            rig: AppearanceRig::new(&map(&maps.haemoglobin), &states, WINDOW_TEXELS),
        }
    }

    /// The built-in face's, about a tone's `melanin` fraction.
    pub fn builtin(melanin: f32) -> FaceAppearance {
        FaceAppearance::from_maps(&face_chromophore_maps(
            crate::scene::face::skull_point_mm,
            melanin,
        ))
    }

    /// The skin's linear sRGB albedo at every texel for the states'
    /// `weights` (`STATES`' order): eq. 7.6's haemoglobin, then the table at
    /// eq. 7.7's coordinates.
    pub fn albedo(&self, weights: &[f32], table: &ColourTable) -> Vec<[f32; 3]> {
        let h = self.rig.haemoglobin(weights);
        self.melanin
            .data
            .iter()
            .zip(&h.data)
            .map(|(&m, &b)| table.skin(f64::from(m), f64::from(b)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::histogram::{correlation, local_stats};
    use super::*;
    use crate::scene::face_colour::COLOUR_SIZE;
    use std::sync::OnceLock;

    fn face() -> &'static FaceAppearance {
        static FACE: OnceLock<FaceAppearance> = OnceLock::new();
        FACE.get_or_init(|| FaceAppearance::from_maps(crate::scene::face_colour::tests::maps()))
    }

    fn weights(name: &str) -> Vec<f32> {
        STATES
            .iter()
            .map(|s| if *s == name { 1.0 } else { 0.0 })
            .collect()
    }

    // Every state of the face's rig, matched: each window of the result has
    // the state map's local mean and deviation (over the face's rectangle,
    // away from its edges), and the neutral capillaries stay where they are.
    #[test]
    fn each_state_matches_its_windows_and_keeps_the_capillaries() {
        let f = face();
        let maps = crate::scene::face_colour::tests::maps();
        let n = maps.size;
        let neutral = Map::new(n, n, maps.haemoglobin.clone()).unwrap();
        for (k, name) in STATES.iter().enumerate() {
            let out = f.rig.haemoglobin(&weights(name));
            let target = Map::new(n, n, maps.states[k].clone()).unwrap();
            let (got, want) = (
                local_stats(&out, WINDOW_TEXELS),
                local_stats(&target, WINDOW_TEXELS),
            );
            let (mut mean_off, mut dev_off, mut count) = (0.0f64, 0.0f64, 0usize);
            for y in (80..300).step_by(5) {
                for x in (130..380).step_by(5) {
                    let s = want.std.at(x, y).max(1e-5);
                    mean_off += f64::from((got.mean.at(x, y) - want.mean.at(x, y)).abs() / s);
                    dev_off += f64::from((got.std.at(x, y) / s - 1.0).abs());
                    count += 1;
                }
            }
            let (mean_off, dev_off) = (mean_off / count as f64, dev_off / count as f64);
            assert!(
                mean_off < 0.15,
                "{name}: means off by {mean_off} sigma on average"
            );
            assert!(
                dev_off < 0.15,
                "{name}: deviations off by {dev_off} on average"
            );
            let kept = correlation(&out, &neutral);
            assert!(kept > 0.8, "{name}: {kept}");
        }
    }

    // Blood absorbs green and blue far more than red (haemoglobin's bands
    // at 415, 542 and 577 nm, the table's spectral data): joy's cheeks turn
    // redder, fear's pallor less red, each against the neutral face. At light
    // melanin (1%), where the epidermis lets the dermis' colour through.
    #[test]
    fn joy_reddens_the_cheeks_and_fear_pales_them() {
        let f = FaceAppearance::builtin(0.01);
        let table = ColourTable::new(32);
        let (cy, cx) = crate::scene::face_colour::texel_nearest(
            crate::scene::face::skull_point_mm,
            glam::Vec2::new(42.0, -30.0),
        );
        let redness = |w: &[f32]| {
            let a = f.albedo(w, &table);
            // The right cheek's texels.
            let (mut r, mut g) = (0.0, 0.0);
            for y in cy - 8..cy + 8 {
                for x in cx - 8..cx + 8 {
                    r += a[y * COLOUR_SIZE + x][0];
                    g += a[y * COLOUR_SIZE + x][1];
                }
            }
            r / g
        };
        let neutral = redness(&[]);
        let (joy, blush, fear) = (
            redness(&weights("joy")),
            redness(&weights("blush")),
            redness(&weights("fear")),
        );
        assert!(joy > neutral * 1.005, "joy {}", joy / neutral);
        assert!(
            blush > joy,
            "blush {} joy {}",
            blush / neutral,
            joy / neutral
        );
        assert!(fear < neutral * 0.997, "fear {}", fear / neutral);
    }
}
