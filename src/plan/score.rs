//! How a plan's frame is scored against its ground truth (issue 16 items 5
//! and 6), pure: the ground truth of the same frame with its character ids,
//! the frame with no SSS, the eval's bands ([`Truth`]) and the per-character
//! err/none of a test frame ([`Truth::score`]). `app::truth` renders the
//! frames; `plan-check` and `plan-motion` score theirs with it.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::eval::bands::Band;

/// A frame's measured error (`check`'s module doc defines it: the eval's
/// err/none per character and band, blended, skin-weighted).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FrameError {
    /// Skin-weighted err/none of the characters' blended interior/silhouette error.
    pub weighted: f64,
    /// Per character.
    pub characters: Vec<CharacterScore>,
}

/// One character's measured error.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CharacterScore {
    /// Its skin pixels in the ground truth's frame.
    pub skin: usize,
    /// Interior and silhouette err/none (`None`: no pixel of the band, or
    /// no SSS is exact there), and the blend of the two by pixel count.
    pub interior: Option<f64>,
    pub silhouette: Option<f64>,
    pub silhouette_pixels: usize,
    pub error: f64,
}

/// What every frame of one scene is scored against (also `motion`'s, frame
/// by frame).
pub struct Truth {
    pub diffuse: Vec<[f32; 4]>,
    pub none: Vec<[f32; 4]>,
    pub bands: Vec<Option<Band>>,
    /// The ground truth's character ids (0: no character's skin).
    pub ids: Vec<u32>,
    pub characters: usize,
}

impl Truth {
    /// Per character and band (interior, silhouette): the sums of squared
    /// error of `test` and of no SSS against the truth, and the pixel count.
    pub fn score(&self, test: &[[f32; 4]]) -> Result<FrameError> {
        if test.len() != self.diffuse.len() {
            bail!("a frame of another size than the ground truth's");
        }
        // [character][band]: (d2, n2, pixels); band 0 interior, 1 silhouette.
        let mut acc = vec![[(0.0f64, 0.0f64, 0usize); 2]; self.characters];
        let mut skin = vec![0usize; self.characters];
        for (i, t) in test.iter().enumerate() {
            let id = self.ids[i] as usize;
            if id == 0 || id > self.characters {
                continue;
            }
            let c = id - 1;
            let b = match self.bands[i] {
                Some(Band::Interior) => 0,
                Some(Band::Silhouette) => 1,
                Some(Band::DepthStep) => {
                    skin[c] += 1;
                    continue;
                }
                None => continue,
            };
            skin[c] += 1;
            let a = &mut acc[c][b];
            for ((&t, &r), &z) in t.iter().zip(&self.diffuse[i]).zip(&self.none[i]).take(3) {
                let r = f64::from(r);
                let d = f64::from(t) - r;
                let z = f64::from(z) - r;
                a.0 += d * d;
                a.1 += z * z;
            }
            a.2 += 1;
        }
        let mut out = FrameError::default();
        let (mut num, mut den) = (0.0, 0.0);
        for c in 0..self.characters {
            // A band where no SSS is exact (nothing scatters at this scale)
            // holds no information: it is left out of the blend.
            let err = |(d2, n2, _): (f64, f64, usize)| (n2 > 0.0).then(|| (d2 / n2).sqrt());
            let (int, sil) = (err(acc[c][0]), err(acc[c][1]));
            let (pi, ps) = (acc[c][0].2 as f64, acc[c][1].2 as f64);
            let blended = match (int, sil) {
                (Some(i), Some(s)) => (pi * i + ps * s) / (pi + ps),
                (Some(i), None) => i,
                (None, Some(s)) => s,
                (None, None) => 1.0,
            };
            out.characters.push(CharacterScore {
                skin: skin[c],
                interior: int,
                silhouette: sil,
                silhouette_pixels: acc[c][1].2,
                error: blended,
            });
            if skin[c] > 0 {
                num += skin[c] as f64 * blended;
                den += skin[c] as f64;
            }
        }
        out.weighted = if den > 0.0 { num / den } else { 1.0 };
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Two characters: one exact, one as wrong as no SSS; the weighted error
    // is their skin-weighted mean; a band where none is exact is left out.
    #[test]
    fn the_frame_error_is_the_skin_weighted_mean_of_the_characters() {
        let r = [1.0f32, 0.5, 0.25, 1.0];
        let z = [0.5f32, 0.5, 0.25, 1.0];
        let n = 4;
        let truth = Truth {
            diffuse: vec![r; n],
            none: vec![z, z, z, r],
            bands: vec![Some(Band::Interior); n],
            ids: vec![1, 2, 2, 2],
            characters: 2,
        };
        let test = vec![r, z, z, [9.0, 9.0, 9.0, 1.0]];
        let e = truth.score(&test).unwrap();
        assert_eq!((e.characters[0].skin, e.characters[0].error), (1, 0.0));
        // Character 1: the last pixel's none is exact (n2 = 0 there) but its
        // error still counts in d2: sqrt((0 + 0 + d) / (0.25 + 0.25)).
        let d = 8.0f64 * 8.0 + 8.5 * 8.5 + 8.75 * 8.75;
        let want = ((0.5 + d) / 0.5).sqrt();
        assert!(
            (e.characters[1].error - want).abs() < 1e-9,
            "{:?}",
            e.characters
        );
        assert!((e.weighted - 3.0 * want / 4.0).abs() < 1e-9);
    }
}
