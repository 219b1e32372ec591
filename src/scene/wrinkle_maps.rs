//! A material's wrinkle maps (thesis ch. 8): one partial-derivative wrinkle
//! normal map over the whole face and two masks of four zones each (Table
//! 8.1's eight colours, in its column order: mask 0 holds red, green, blue,
//! brown in R, G, B, A; mask 1 cyan, magenta, orange, grey). The expression
//! weights pick how much of each zone shows (`skin::wrinkles`, Listing 8.1).
//!
//! The encoding is Listing 8.1's: a partial derivative d in [-1, 1] stored
//! as 0.5 + 0.5 d in an 8-bit UNORM channel (R: x, G: y), read back as
//! -1 + 2 c. (The listing reads `.gr` from a 3Dc texture, whose two
//! channels swap; an RGBA8 texture keeps them in R and G.) 8 bits cannot
//! hold 0 exactly: a flat texel reads 1/255 off (a tilt of 0.2 degrees),
//! which only shows where a zone's weight is not 0. The maps themselves are
//! `mesh::WrinkleMaps`, a material's.

/// Zones per mask texture and mask textures (Listing 8.1: two RGBA masks).
pub const ZONES_PER_MASK: usize = 4;
pub const MASKS: usize = 2;

/// A value in [-1, 1] as an 8-bit UNORM channel stores it (0.5 + 0.5 x).
pub fn encode(x: f32) -> u8 {
    ((0.5 + 0.5 * x.clamp(-1.0, 1.0)) * 255.0).round() as u8
}

/// Listing 8.1's decode: -1 + 2 c.
pub fn decode(c: u8) -> f32 {
    -1.0 + 2.0 * (f32::from(c) / 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::{Texture, WrinkleMaps};

    #[test]
    fn the_codec_is_listing_8_1s() {
        assert_eq!(encode(-1.0), 0);
        assert_eq!(encode(1.0), 255);
        assert_eq!(encode(0.0), 128);
        assert_eq!(decode(0), -1.0);
        assert_eq!(decode(255), 1.0);
        // The flat texel's offset: one step of 2/255, halved.
        assert!((decode(encode(0.0)) - 1.0 / 255.0).abs() < 1e-6);
        for x in [-0.9f32, -0.3, 0.2, 0.77] {
            assert!((decode(encode(x)) - x).abs() <= 1.0 / 255.0 + 1e-6);
        }
    }

    #[test]
    fn check_refuses_short_textures() {
        let t = |w: u32, n: usize| Texture {
            width: w,
            height: w,
            rgba8: vec![0; n],
        };
        let ok = WrinkleMaps {
            wrinkle: t(2, 16),
            masks: [t(1, 4), t(1, 4)],
        };
        assert!(ok.check().is_ok());
        assert_eq!(ok.bytes(), 24);
        let bad = WrinkleMaps {
            masks: [t(1, 4), t(2, 4)],
            ..ok
        };
        assert!(bad.check().unwrap_err().to_string().contains("mask 1"));
    }
}
