//! The skin's per-texel parameters in one texture: what the geometry pass
//! reads in a single fetch (the NVIDIA Human Head demo packs rho_s and the
//! roughness into one texture the same way; seed 004, "Varying Specular
//! Parameters over the face"). Each channel comes from its own optional map:
//!
//! | channel | from | read as |
//! | --- | --- | --- |
//! | R | the specular map's R | a factor of the material's rho_s |
//! | G | the roughness map's R | the Beckmann m itself (at least `MIN_ROUGHNESS_TEXEL`) |
//! | B | the SSS-strength map's R | a factor of the material's SSS strength (eq. 4.3-4.4) |
//!
//! A channel without its map holds 255 (a factor of exactly 1; for G the
//! material's own m is used, `Packed::roughness_from_map` false). Maps of
//! different sizes are resampled bilinearly, at texel centres and with
//! wrap-around as the material sampler repeats, to the largest width and
//! height among them: a map already at that size keeps its texels exactly.

use super::mesh::Texture;

/// The smallest m a roughness map packs to (8 bits: 20/255 = 0.078): the
/// Beckmann lookup has no mirror, as the glTF parts' floor of 0.08 says.
pub const MIN_ROUGHNESS_TEXEL: u8 = 20;

/// The texture and whether its G channel holds a roughness map.
#[derive(Clone, Debug, PartialEq)]
pub struct Packed {
    pub texture: Texture,
    pub roughness_from_map: bool,
}

/// Packs the three optional maps (module docs). `None` when no map is
/// given: the neutral 1 x 1 texel then serves.
pub fn pack(
    specular: Option<&Texture>,
    roughness: Option<&Texture>,
    strength: Option<&Texture>,
) -> Option<Packed> {
    let maps = [specular, roughness, strength];
    let present: Vec<&Texture> = maps.iter().flatten().copied().collect();
    if present.is_empty() {
        return None;
    }
    let width = present.iter().map(|t| t.width).max().unwrap_or(1).max(1);
    let height = present.iter().map(|t| t.height).max().unwrap_or(1).max(1);
    let mut rgba8 = vec![255u8; width as usize * height as usize * 4];
    for (channel, map) in maps.iter().enumerate() {
        let Some(map) = map else { continue };
        for y in 0..height {
            for x in 0..width {
                let u = (x as f64 + 0.5) / width as f64;
                let v = (y as f64 + 0.5) / height as f64;
                let mut value = red_at(map, u, v);
                if channel == 1 {
                    value = value.max(MIN_ROUGHNESS_TEXEL);
                }
                rgba8[(y * width + x) as usize * 4 + channel] = value;
            }
        }
    }
    Some(Packed {
        texture: Texture {
            width,
            height,
            rgba8,
        },
        roughness_from_map: roughness.is_some(),
    })
}

/// The red channel of `t` at (u, v), bilinear between texel centres with
/// wrap-around (the material sampler repeats), rounded to 8 bits.
fn red_at(t: &Texture, u: f64, v: f64) -> u8 {
    let (w, h) = (t.width.max(1) as i64, t.height.max(1) as i64);
    let x = u * w as f64 - 0.5;
    let y = v * h as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |xi: i64, yi: i64| {
        let (xi, yi) = (xi.rem_euclid(w), yi.rem_euclid(h));
        t.rgba8
            .get(((yi * w + xi) * 4) as usize)
            .copied()
            .unwrap_or(255) as f64
    };
    let (x0, y0) = (x0 as i64, y0 as i64);
    let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
    let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
    (top * (1.0 - fy) + bottom * fy).round().clamp(0.0, 255.0) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(width: u32, height: u32, f: impl Fn(u32, u32) -> u8) -> Texture {
        let mut rgba8 = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let r = f(x, y);
                rgba8.extend([r, 0, 0, 255]);
            }
        }
        Texture {
            width,
            height,
            rgba8,
        }
    }

    #[test]
    fn no_map_packs_nothing() {
        assert_eq!(pack(None, None, None), None);
    }

    #[test]
    fn each_map_lands_in_its_channel_and_the_rest_are_neutral() {
        let spec = grey(4, 2, |x, y| (x * 10 + y) as u8);
        let p = pack(Some(&spec), None, None).unwrap();
        assert!(!p.roughness_from_map);
        assert_eq!((p.texture.width, p.texture.height), (4, 2));
        for y in 0..2 {
            for x in 0..4 {
                let i = ((y * 4 + x) * 4) as usize;
                assert_eq!(
                    &p.texture.rgba8[i..i + 4],
                    &[(x * 10 + y) as u8, 255, 255, 255]
                );
            }
        }
        let sss = grey(4, 2, |x, _| if x < 2 { 255 } else { 0 });
        let rough = grey(4, 2, |_, _| 77);
        let p = pack(None, Some(&rough), Some(&sss)).unwrap();
        assert!(p.roughness_from_map);
        assert_eq!(&p.texture.rgba8[0..4], &[255, 77, 255, 255]);
        assert_eq!(&p.texture.rgba8[12..16], &[255, 77, 0, 255]);
        let mirror = grey(1, 1, |_, _| 0);
        let p = pack(None, Some(&mirror), None).unwrap();
        assert_eq!(p.texture.rgba8[1], MIN_ROUGHNESS_TEXEL);
    }

    #[test]
    fn the_least_scattering_strength_skips_texels_that_do_not_scatter() {
        use crate::scene::mesh::Material;
        let mut m = Material::skin([1.0; 3]);
        m.sss_strength = 0.5;
        assert_eq!(m.min_scattering_strength(), 0.5);
        m.sss_map = Some(grey(3, 1, |x, _| [0, 51, 255][x as usize]));
        assert!((m.min_scattering_strength() - 0.1).abs() < 1e-6);
        m.sss_map = Some(grey(1, 1, |_, _| 0));
        assert_eq!(m.min_scattering_strength(), 0.0);
    }

    // A 2 x 1 map under a 4 x 2 one: each of its texels covers two columns,
    // and the bilinear ramp between their centres (with wrap-around) gives
    // the quarter points 0.25 and 0.75 of the way.
    #[test]
    fn a_smaller_map_is_resampled_bilinearly_at_texel_centres() {
        let big = grey(4, 2, |_, _| 10);
        let small = grey(2, 1, |x, _| if x == 0 { 0 } else { 200 });
        let p = pack(Some(&big), None, Some(&small)).unwrap();
        let b: Vec<u8> = (0..4).map(|x| p.texture.rgba8[x * 4 + 2]).collect();
        // Centres at u = 1/8, 3/8, 5/8, 7/8 of the small map's x = -0.25,
        // 0.25, 0.75, 1.25 (texel units from its first centre).
        assert_eq!(b, vec![50, 50, 150, 150]);
        assert_eq!(p.texture.rgba8[4 * 4 + 2], 50, "second row as the first");
    }
}
