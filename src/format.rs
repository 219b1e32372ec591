//! The texel formats dermis uses and what it knows about each, in one table
//! keyed by format ([`Format::info`], as `vk::barrier` keys its table by access
//! kind): the Vulkan format it is, its aspects with the bytes a copy moves per
//! texel of each, the bytes the cost model prices a texel at, the bytes the
//! memory estimate counts, and how a texel read back decodes to linear float.
//! [`Format`]'s names are the work vocabulary (`work::Format`, the names pass
//! declarations, reports and budget profiles use). The sRGB transfer
//! functions live here too: the decode of an sRGB texel is the one every
//! caller uses.
//!
//! Pure: the pure core names no `ash` type, so a row names its Vulkan format
//! by the registry's name and value; `vk::format` turns that into ash's type
//! and its tests check the two agree. Tested without a device, here and there.
//!
//! Three byte figures, because three uses ask three questions (each is what
//! the code computed before the table existed, so every output keeps its
//! numbers):
//! - [`FormatInfo::stored_bytes`], a texel as the GPU stores it: the cost
//!   model's traffic and the declared work of copies (report.json, budgets).
//!   D24S8 packs into 4 bytes; D32S8 is taken as 4 + 1, as most hardware
//!   stores the stencil plane apart.
//! - [`FormatInfo::memory_bytes`], a texel as the device-memory estimate
//!   counts it (`graph::Resources::declared_bytes`, which refuses a frame
//!   before any image exists): depth/stencil counts 8, a plane each padded
//!   to 32 bits, an estimate that errs high.
//! - [`FormatInfo::aspects`]' copy sizes, what `vkCmdCopyImageToBuffer` moves
//!   per texel of one aspect (the spec's rules for depth/stencil copies: a
//!   32-bit depth 4 bytes, D24's depth 4 with 8 bits unused, stencil 1): the
//!   readback buffers and the readback passes' declared work.

use serde::{Deserialize, Serialize};

/// Texel formats the passes read and write: the work vocabulary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Format {
    Rgba8Unorm,
    Rgba8Srgb,
    R16Float,
    Rgba16Float,
    R32Float,
    Rgba32Float,
    D32Float,
    D24UnormS8Uint,
    D32FloatS8Uint,
}

/// One aspect of an image, as a copy to or from a buffer addresses it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aspect {
    Color,
    Depth,
    Stencil,
}

/// How the bytes of a texel read back become linear float RGBA. Single
/// channels are replicated to RGB with alpha 1, so a depth or a scalar
/// target dumps as grey.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decode {
    /// Four 8-bit unsigned normalised channels.
    Unorm8x4,
    /// Three sRGB-encoded 8-bit channels ([`srgb_to_linear`]) and a linear
    /// 8-bit alpha.
    Srgb8x4,
    /// One half float.
    Half,
    /// Four half floats.
    Half4,
    /// One f32 (a colour channel or a 32-bit depth).
    Float,
    /// Four f32.
    Float4,
}

/// One row of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FormatInfo {
    /// The Vulkan format, as `VK_FORMAT_` + this.
    pub vulkan: &'static str,
    /// Its `VkFormat` value in the Vulkan registry.
    pub vulkan_value: i32,
    /// Every aspect of the format with the bytes a buffer copy of it moves
    /// per texel; colour or depth first, then stencil.
    pub aspects: &'static [(Aspect, u32)],
    /// Bytes a texel takes as the GPU stores it, as the cost model prices
    /// its traffic and pass declarations count copies.
    pub stored_bytes: u32,
    /// Bytes a texel counts in the device-memory estimate of the declared
    /// images (at least `stored_bytes`).
    pub memory_bytes: u32,
    /// How the first aspect, read back, decodes (`None`: dermis does not read
    /// it back: a dump skips such an image, a final read of one is an error).
    pub decode: Option<Decode>,
}

impl Format {
    /// Every format, in declaration order (a new format goes here too, and
    /// into [`Format::info`]'s match, which the compiler holds complete;
    /// `vk::format::from_vk` finds formats through this list).
    pub const ALL: [Format; 9] = [
        Format::Rgba8Unorm,
        Format::Rgba8Srgb,
        Format::R16Float,
        Format::Rgba16Float,
        Format::R32Float,
        Format::Rgba32Float,
        Format::D32Float,
        Format::D24UnormS8Uint,
        Format::D32FloatS8Uint,
    ];

    /// The table. Every per-format fact in dermis is read from these rows.
    pub fn info(self) -> FormatInfo {
        use Aspect::{Color, Depth, Stencil};
        match self {
            Format::Rgba8Unorm => FormatInfo {
                vulkan: "R8G8B8A8_UNORM",
                vulkan_value: 37,
                aspects: &[(Color, 4)],
                stored_bytes: 4,
                memory_bytes: 4,
                decode: Some(Decode::Unorm8x4),
            },
            Format::Rgba8Srgb => FormatInfo {
                vulkan: "R8G8B8A8_SRGB",
                vulkan_value: 43,
                aspects: &[(Color, 4)],
                stored_bytes: 4,
                memory_bytes: 4,
                decode: Some(Decode::Srgb8x4),
            },
            Format::R16Float => FormatInfo {
                vulkan: "R16_SFLOAT",
                vulkan_value: 76,
                aspects: &[(Color, 2)],
                stored_bytes: 2,
                memory_bytes: 2,
                decode: Some(Decode::Half),
            },
            Format::Rgba16Float => FormatInfo {
                vulkan: "R16G16B16A16_SFLOAT",
                vulkan_value: 97,
                aspects: &[(Color, 8)],
                stored_bytes: 8,
                memory_bytes: 8,
                decode: Some(Decode::Half4),
            },
            Format::R32Float => FormatInfo {
                vulkan: "R32_SFLOAT",
                vulkan_value: 100,
                aspects: &[(Color, 4)],
                stored_bytes: 4,
                memory_bytes: 4,
                decode: Some(Decode::Float),
            },
            Format::Rgba32Float => FormatInfo {
                vulkan: "R32G32B32A32_SFLOAT",
                vulkan_value: 109,
                aspects: &[(Color, 16)],
                stored_bytes: 16,
                memory_bytes: 16,
                decode: Some(Decode::Float4),
            },
            Format::D32Float => FormatInfo {
                vulkan: "D32_SFLOAT",
                vulkan_value: 126,
                aspects: &[(Depth, 4)],
                stored_bytes: 4,
                memory_bytes: 4,
                decode: Some(Decode::Float),
            },
            // Its depth (24-bit unorm in a 32-bit word) is not read back: the
            // frame's depth/stencil target is read as its stencil, the depth
            // the passes compare is a colour target, and lavapipe gives D32S8.
            Format::D24UnormS8Uint => FormatInfo {
                vulkan: "D24_UNORM_S8_UINT",
                vulkan_value: 129,
                aspects: &[(Depth, 4), (Stencil, 1)],
                stored_bytes: 4,
                memory_bytes: 8,
                decode: None,
            },
            // Priced 4 + 1 (the planes apart); read back as its depth.
            Format::D32FloatS8Uint => FormatInfo {
                vulkan: "D32_SFLOAT_S8_UINT",
                vulkan_value: 130,
                aspects: &[(Depth, 4), (Stencil, 1)],
                stored_bytes: 5,
                memory_bytes: 8,
                decode: Some(Decode::Float),
            },
        }
    }

    /// Bytes of one texel as stored ([`FormatInfo::stored_bytes`]: the cost
    /// model's figure; D32S8 is 5).
    pub fn bytes_per_texel(self) -> u32 {
        self.info().stored_bytes
    }

    /// Whether a depth format also has a stencil aspect.
    pub fn has_stencil(self) -> bool {
        self.copy_bytes(Aspect::Stencil).is_some()
    }

    pub fn is_depth(self) -> bool {
        self.copy_bytes(Aspect::Depth).is_some()
    }

    /// Bytes a buffer copy of `aspect` moves per texel (`None`: the format
    /// has no such aspect).
    pub fn copy_bytes(self, aspect: Aspect) -> Option<u32> {
        let info = self.info();
        info.aspects
            .iter()
            .find(|(a, _)| *a == aspect)
            .map(|&(_, bytes)| bytes)
    }

    /// What a readback of this format copies, the aspect and its bytes per
    /// texel, and how it decodes (`None`: not read back).
    pub fn readback(self) -> Option<(Aspect, u32, Decode)> {
        let info = self.info();
        let decode = info.decode?;
        let &(aspect, bytes) = info.aspects.first()?;
        Some((aspect, bytes, decode))
    }
}

impl Decode {
    /// Texels of this kind as linear float RGBA (a trailing partial texel is
    /// dropped).
    pub fn to_rgba(self, bytes: &[u8]) -> Vec<[f32; 4]> {
        let half = |c: &[u8], i: usize| {
            half::f16::from_bits(u16::from_le_bytes([c[i], c[i + 1]])).to_f32()
        };
        let float = |c: &[u8], i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
        let unorm = |v: u8| v as f32 / 255.0;
        match self {
            Decode::Unorm8x4 => bytes
                .chunks_exact(4)
                .map(|c| [unorm(c[0]), unorm(c[1]), unorm(c[2]), unorm(c[3])])
                .collect(),
            Decode::Srgb8x4 => bytes
                .chunks_exact(4)
                .map(|c| {
                    [
                        srgb_to_linear(c[0]),
                        srgb_to_linear(c[1]),
                        srgb_to_linear(c[2]),
                        unorm(c[3]),
                    ]
                })
                .collect(),
            Decode::Half => bytes
                .chunks_exact(2)
                .map(|c| {
                    let v = half(c, 0);
                    [v, v, v, 1.0]
                })
                .collect(),
            Decode::Half4 => bytes
                .chunks_exact(8)
                .map(|c| [half(c, 0), half(c, 2), half(c, 4), half(c, 6)])
                .collect(),
            Decode::Float => bytes
                .chunks_exact(4)
                .map(|c| {
                    let v = float(c, 0);
                    [v, v, v, 1.0]
                })
                .collect(),
            Decode::Float4 => bytes
                .chunks_exact(16)
                .map(|c| [float(c, 0), float(c, 4), float(c, 8), float(c, 12)])
                .collect(),
        }
    }
}

/// An sRGB-encoded byte as linear light (IEC 61966-2-1): the one decode of
/// sRGB in dermis (readbacks, the supersampled reference's filter, AA scores).
pub fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light as the nearest sRGB byte (clamped to 0..=1, NaN to 0): the
/// inverse of [`srgb_to_linear`] on every byte.
pub fn linear_to_srgb(l: f32) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let c = if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round().clamp(0.0, 255.0) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_is_listed_once_in_order() {
        for (i, f) in Format::ALL.into_iter().enumerate() {
            assert_eq!(f as usize, i, "{f:?}");
        }
        let mut names: Vec<_> = Format::ALL.iter().map(|f| f.info().vulkan).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), Format::ALL.len());
    }

    // The byte figures each use depends on, as they were before the table:
    // report.json's copies, the budgets and the memory refusal keep their
    // numbers.
    #[test]
    fn the_byte_figures_of_each_use() {
        let stored: Vec<u32> = Format::ALL.iter().map(|f| f.bytes_per_texel()).collect();
        assert_eq!(stored, [4, 4, 2, 8, 4, 16, 4, 4, 5]);
        let memory: Vec<u32> = Format::ALL.iter().map(|f| f.info().memory_bytes).collect();
        assert_eq!(memory, [4, 4, 2, 8, 4, 16, 4, 8, 8]);
        for f in Format::ALL {
            let i = f.info();
            // The estimate errs high, never below what the GPU stores.
            assert!(i.memory_bytes >= i.stored_bytes, "{f:?}");
            // A colour texel is the same bytes in memory, priced and copied.
            if let Some(c) = f.copy_bytes(Aspect::Color) {
                assert_eq!(
                    (c, i.memory_bytes),
                    (i.stored_bytes, i.stored_bytes),
                    "{f:?}"
                );
            }
        }
        // D32S8 is priced as its two planes' copies; D24S8 packs both into one word.
        let planes = |f: Format| f.info().aspects.iter().map(|a| a.1).sum::<u32>();
        assert_eq!(
            planes(Format::D32FloatS8Uint),
            Format::D32FloatS8Uint.bytes_per_texel()
        );
        assert_eq!(Format::D24UnormS8Uint.bytes_per_texel(), 4);
    }

    // The spec's buffer-copy sizes of depth/stencil aspects (vkCmdCopyImageToBuffer:
    // D32's depth 4 bytes, D24's depth 4 with 8 bits unused, stencil 1).
    #[test]
    fn depth_and_stencil_aspects_copy_as_the_spec_says() {
        use Aspect::*;
        assert_eq!(Format::D32Float.info().aspects, &[(Depth, 4)]);
        for f in [Format::D24UnormS8Uint, Format::D32FloatS8Uint] {
            assert_eq!(f.info().aspects, &[(Depth, 4), (Stencil, 1)], "{f:?}");
            assert!(f.is_depth() && f.has_stencil());
        }
        for f in [Format::Rgba8Srgb, Format::R16Float, Format::Rgba32Float] {
            assert!(!f.is_depth() && !f.has_stencil() && f.copy_bytes(Color).is_some());
        }
        assert!(Format::D32Float.is_depth() && !Format::D32Float.has_stencil());
    }

    // A readback copies the first aspect, and its decode reads exactly that
    // many bytes a texel.
    #[test]
    fn a_readback_decodes_the_bytes_it_copies() {
        for f in Format::ALL {
            let Some((aspect, bytes, decode)) = f.readback() else {
                assert_eq!(f, Format::D24UnormS8Uint);
                continue;
            };
            assert_eq!(f.copy_bytes(aspect), Some(bytes), "{f:?}");
            assert_eq!(
                decode.to_rgba(&vec![0; bytes as usize * 3]).len(),
                3,
                "{f:?}"
            );
            assert_eq!(
                decode.to_rgba(&vec![0; bytes as usize * 3 - 1]).len(),
                2,
                "{f:?}"
            );
        }
        // D32S8 reads back its depth, as D32 does.
        assert_eq!(
            Format::D32FloatS8Uint.readback(),
            Some((Aspect::Depth, 4, Decode::Float))
        );
    }

    #[test]
    fn decodes_to_linear_float() {
        let h = |v: f32| half::f16::from_f32(v).to_bits().to_le_bytes();
        let b: Vec<u8> = [1.5, -2.0, 0.25, 1.0].iter().flat_map(|&v| h(v)).collect();
        assert_eq!(Decode::Half4.to_rgba(&b), [[1.5, -2.0, 0.25, 1.0]]);
        assert_eq!(Decode::Half.to_rgba(&h(0.5)), [[0.5, 0.5, 0.5, 1.0]]);
        assert_eq!(
            Decode::Float.to_rgba(&0.75f32.to_le_bytes()),
            [[0.75, 0.75, 0.75, 1.0]]
        );
        let f4: Vec<u8> = [1.0f32, 2.0, 3.0, 4.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(Decode::Float4.to_rgba(&f4), [[1.0, 2.0, 3.0, 4.0]]);
        assert_eq!(
            Decode::Unorm8x4.to_rgba(&[255, 0, 51, 255]),
            [[1.0, 0.0, 0.2, 1.0]]
        );
        // sRGB 188 is linear 0.5 (not 188/255); alpha stays linear.
        let px = Decode::Srgb8x4.to_rgba(&[255, 0, 188, 51])[0];
        assert!((px[0] - 1.0).abs() < 1e-6 && px[1] == 0.0, "{px:?}");
        assert!((px[2] - 0.5).abs() < 0.01 && px[3] == 0.2, "{px:?}");
    }

    #[test]
    fn srgb_round_trips_every_byte() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb(srgb_to_linear(c)), c);
        }
        assert_eq!(linear_to_srgb(-1.0), 0);
        assert_eq!(linear_to_srgb(2.0), 255);
        assert_eq!(linear_to_srgb(f32::NAN), 0);
        // IEC 61966-2-1's linear segment below 0.04045 (10/255 is on it).
        assert_eq!(srgb_to_linear(10), 10.0 / 255.0 / 12.92);
        assert_eq!(srgb_to_linear(0), 0.0);
        assert!((srgb_to_linear(255) - 1.0).abs() < 1e-6);
    }
}
