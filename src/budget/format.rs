//! The formats a profile can name (render targets, textures, depth), what kind
//! of values each holds, and how near one is to another as a substitute when a
//! profile cannot render the format a pass wants. Pure.

use serde::{Deserialize, Serialize};

use crate::work::Format;

/// Render-target and texture formats a profile can name: the renderer's
/// [`Format`]s plus the console formats a port would substitute (7e3 float,
/// the Xenos fixed-point 16-bit formats, two-channel formats).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TargetFormat {
    Rgba8Unorm,
    Rgba8Srgb,
    Rgb10a2Unorm,
    /// Xenos 2_10_10_10_FLOAT: 7e3 floats in [0, 32), 2-bit alpha.
    Rgb10a2Float,
    R11g11b10Float,
    Rg16Unorm,
    /// Xenos 16_16_16_16: fixed point in [-32, 32].
    Rgba16Fixed,
    R16Float,
    Rg16Float,
    Rgba16Float,
    R32Float,
    Rg32Float,
    Rgba32Float,
    D24UnormS8Uint,
    /// Xenos D24FS8: 20e4 float depth.
    D24FloatS8Uint,
    D32Float,
    D32FloatS8Uint,
}

/// What kind of values a format holds (for choosing a substitute).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatClass {
    Unorm,
    /// Floating point or HDR fixed point (range beyond [0, 1]).
    Hdr,
    Depth,
}

impl TargetFormat {
    pub fn from_work(f: Format) -> TargetFormat {
        match f {
            Format::Rgba8Unorm => TargetFormat::Rgba8Unorm,
            Format::Rgba8Srgb => TargetFormat::Rgba8Srgb,
            Format::R16Float => TargetFormat::R16Float,
            Format::Rgba16Float => TargetFormat::Rgba16Float,
            Format::R32Float => TargetFormat::R32Float,
            Format::Rgba32Float => TargetFormat::Rgba32Float,
            Format::D32Float => TargetFormat::D32Float,
            Format::D24UnormS8Uint => TargetFormat::D24UnormS8Uint,
            Format::D32FloatS8Uint => TargetFormat::D32FloatS8Uint,
        }
    }

    /// The renderer's format this is (`None`: a console format only a port
    /// would substitute).
    pub fn to_work(self) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|&f| Self::from_work(f) == self)
    }

    /// Bytes per texel as stored: a renderer format's from the format table
    /// ([`Format::bytes_per_texel`]), a console format's own.
    pub fn bytes(self) -> u32 {
        use TargetFormat::*;
        match self.to_work() {
            Some(f) => f.bytes_per_texel(),
            None => match self {
                Rgba16Fixed | Rg32Float => 8,
                // Every other console format packs a texel into 32 bits.
                _ => 4,
            },
        }
    }

    pub fn channels(self) -> u32 {
        use TargetFormat::*;
        match self {
            R16Float | R32Float | D24UnormS8Uint | D24FloatS8Uint | D32Float | D32FloatS8Uint => 1,
            Rg16Unorm | Rg16Float | Rg32Float => 2,
            R11g11b10Float => 3,
            Rgba8Unorm | Rgba8Srgb | Rgb10a2Unorm | Rgb10a2Float | Rgba16Fixed | Rgba16Float
            | Rgba32Float => 4,
        }
    }

    /// Bits of the widest colour channel (depth: depth bits).
    pub fn channel_bits(self) -> u32 {
        use TargetFormat::*;
        match self {
            Rgba8Unorm | Rgba8Srgb => 8,
            Rgb10a2Unorm | Rgb10a2Float => 10,
            R11g11b10Float => 11,
            Rg16Unorm | Rgba16Fixed | R16Float | Rg16Float | Rgba16Float => 16,
            D24UnormS8Uint | D24FloatS8Uint => 24,
            R32Float | Rg32Float | Rgba32Float | D32Float | D32FloatS8Uint => 32,
        }
    }

    pub fn class(self) -> FormatClass {
        use TargetFormat::*;
        match self {
            Rgba8Unorm | Rgba8Srgb | Rgb10a2Unorm | Rg16Unorm => FormatClass::Unorm,
            D24UnormS8Uint | D24FloatS8Uint | D32Float | D32FloatS8Uint => FormatClass::Depth,
            _ => FormatClass::Hdr,
        }
    }

    /// How far `self` is from `wanted` as a substitute (smaller is nearer):
    /// another class or fewer channels cost most (the data would not fit),
    /// then lost precision, then extra bytes.
    pub fn distance_from(self, wanted: TargetFormat) -> f64 {
        let mut d = 0.0;
        if self.class() != wanted.class() {
            d += 1000.0;
        }
        if self.channels() < wanted.channels() {
            d += 100.0 * f64::from(wanted.channels() - self.channels());
        }
        if self.channel_bits() < wanted.channel_bits() {
            d += 10.0 * f64::from(wanted.channel_bits() - self.channel_bits()) / 8.0;
        }
        if self.is_float() != wanted.is_float() {
            d += 1.0;
        }
        d + (f64::from(self.bytes()) - f64::from(wanted.bytes())).abs() / 4.0
    }

    /// Floating-point channels.
    pub fn is_float(self) -> bool {
        use TargetFormat::*;
        matches!(
            self,
            Rgb10a2Float
                | R11g11b10Float
                | R16Float
                | Rg16Float
                | Rgba16Float
                | R32Float
                | Rg32Float
                | Rgba32Float
                | D24FloatS8Uint
                | D32Float
                | D32FloatS8Uint
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substitutes_keep_class_and_channels() {
        use TargetFormat::*;
        // RGBA16F wanted: another 4-channel HDR format is nearer than RG32F.
        assert!(Rgba16Fixed.distance_from(Rgba16Float) < Rg32Float.distance_from(Rgba16Float));
        assert!(Rgb10a2Float.distance_from(Rgba16Float) < Rgba8Unorm.distance_from(Rgba16Float));
        // R16F wanted: RG16F (one more channel, same bits) beats R32F? Both fit;
        // RG16F wastes 2 bytes, R32F 2 bytes and widens: equal bytes, so the
        // tie goes to either; both beat an 8-bit format.
        assert!(Rg16Float.distance_from(R16Float) < Rgba8Unorm.distance_from(R16Float));
        assert_eq!(TargetFormat::from_work(Format::Rgba16Float).bytes(), 8);
        for f in Format::ALL {
            assert_eq!(TargetFormat::from_work(f).to_work(), Some(f));
            assert_eq!(TargetFormat::from_work(f).bytes(), f.bytes_per_texel());
        }
    }

    // The console formats' own sizes (the renderer's come from the format table).
    #[test]
    fn console_formats_sizes() {
        use TargetFormat::*;
        for (f, bytes) in [
            (Rgb10a2Unorm, 4),
            (Rgb10a2Float, 4),
            (R11g11b10Float, 4),
            (Rg16Unorm, 4),
            (Rg16Float, 4),
            (D24FloatS8Uint, 4),
            (Rgba16Fixed, 8),
            (Rg32Float, 8),
        ] {
            assert_eq!((f.to_work(), f.bytes()), (None, bytes), "{f:?}");
        }
    }
}
