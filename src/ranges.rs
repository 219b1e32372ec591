//! Every number a frame or a command takes, with its valid range, written
//! once (issue 27): the settings' checks (`RenderSettings::validate`, the
//! frame counts, the scale), the command line's help (each flag's help ends
//! with its range, from here) and docs/usage.md's "Valid ranges" (a test
//! holds the docs to this table) all read these. A file that brings the same
//! quantity (a report, a plan, a profile) is held to the same range.

use std::fmt;

use anyhow::{bail, Result};

/// One end of a range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    Incl(f64),
    Excl(f64),
}

/// A quantity's valid values: finite numbers between two ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// The flag that gives it (`--width`), as the docs name it.
    pub flag: &'static str,
    /// What it is, as an error names it ("width").
    pub what: &'static str,
    pub lo: End,
    pub hi: End,
    /// Its unit after the range ("pixels", "head heights"; empty: none).
    pub unit: &'static str,
}

/// A number a range checks, compared in its own precision (an f32 setting
/// against the ends rounded to f32, so `1e-12f32` is within `1e-12..`).
pub trait Checked: Copy + fmt::Display {
    fn value(self) -> f64;
    /// An end as this type holds it.
    fn end(e: f64) -> f64;
}

impl Checked for f32 {
    fn value(self) -> f64 {
        self as f64
    }
    fn end(e: f64) -> f64 {
        e as f32 as f64
    }
}

impl Checked for f64 {
    fn value(self) -> f64 {
        self
    }
    fn end(e: f64) -> f64 {
        e
    }
}

macro_rules! checked_int {
    ($($t:ty),*) => {$(
        impl Checked for $t {
            fn value(self) -> f64 {
                self as f64
            }
            fn end(e: f64) -> f64 {
                e
            }
        }
    )*};
}
checked_int!(u32, u64, usize);

impl Range {
    /// Whether `v` is finite and within both ends.
    pub fn contains<T: Checked>(&self, v: T) -> bool {
        let x = v.value();
        let lo = match self.lo {
            End::Incl(a) => x >= T::end(a),
            End::Excl(a) => x > T::end(a),
        };
        let hi = match self.hi {
            End::Incl(b) => x <= T::end(b),
            End::Excl(b) => x < T::end(b),
        };
        x.is_finite() && lo && hi
    }

    /// `v` within the range, or one line naming the quantity, the range and `v`.
    pub fn check<T: Checked>(&self, v: T) -> Result<()> {
        if !self.contains(v) {
            bail!("{} must be within {self}, got {v}", self.what);
        }
        Ok(())
    }

    /// `v` within the range, where a file names the same quantity `name`:
    /// the error names both (`characters must be within 1..=1024 (as
    /// --heads), got 0`).
    pub fn check_as<T: Checked>(&self, name: &str, v: T) -> Result<()> {
        if !self.contains(v) {
            bail!("{name} must be within {self} (as {}), got {v}", self.flag);
        }
        Ok(())
    }

    /// The same quantity with its upper end lowered to `hi` (a device's limit).
    pub fn up_to(&self, hi: f64) -> Range {
        Range {
            hi: End::Incl(hi),
            ..*self
        }
    }
}

/// A number as the docs write it: integers without a fraction, very large
/// and very small ones in exponent form.
fn num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{v:e}")
    } else if v.fract() == 0.0 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

impl fmt::Display for Range {
    /// `1..=16384 pixels`, `(0, 1000] head heights`, `(0.5, 170) degrees`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match (self.lo, self.hi) {
            (End::Incl(a), End::Incl(b)) => format!("{}..={}", num(a), num(b)),
            (End::Incl(a), End::Excl(b)) => format!("[{}, {})", num(a), num(b)),
            (End::Excl(a), End::Incl(b)) => format!("({}, {}]", num(a), num(b)),
            (End::Excl(a), End::Excl(b)) => format!("({}, {})", num(a), num(b)),
        };
        if self.unit.is_empty() {
            f.write_str(&text)
        } else {
            write!(f, "{text} {}", self.unit)
        }
    }
}

const fn range(
    flag: &'static str,
    what: &'static str,
    lo: End,
    hi: End,
    unit: &'static str,
) -> Range {
    Range {
        flag,
        what,
        lo,
        hi,
        unit,
    }
}

/// Largest side of any image dermis makes before a device says otherwise
/// (Vulkan's guaranteed maxImageDimension2D is 4096; 16384 is what desktop
/// GPUs and lavapipe give).
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most characters of a frame.
pub const MAX_HEADS: u32 = 1024;
/// Farthest camera, in head heights (the far shot is 14): at 1000 a head is a
/// few pixels high in a 4K frame, and f32 still separates near and far planes.
pub const MAX_DISTANCE_HEADS: f32 = 1000.0;
/// Largest ambient irradiance (default 0.08): like the key light's intensity
/// (`scene::light::MAX_INTENSITY`), bounded so RGBA16F targets cannot overflow.
pub const MAX_AMBIENT: f32 = 100.0;
/// Most measured frames a run takes statistics over: each keeps its pass
/// samples (about 1 KB) until the report is made, so 100,000 frames hold about
/// 100 MB. (A p95 over more frames says nothing new.)
pub const MAX_MEASURED_FRAMES: usize = 100_000;
/// Most warm-up frames (they keep nothing; the bound only catches a mistyped
/// count that would run for days).
pub const MAX_WARMUP_FRAMES: usize = 100_000;

pub const WIDTH: Range = range(
    "--width",
    "width",
    End::Incl(1.0),
    End::Incl(MAX_IMAGE_SIDE as f64),
    "pixels",
);
pub const HEIGHT: Range = range(
    "--height",
    "height",
    End::Incl(1.0),
    End::Incl(MAX_IMAGE_SIDE as f64),
    "pixels",
);
pub const SHADOW_SIZE: Range = range(
    "--shadow-size",
    "shadow map size",
    End::Incl(1.0),
    End::Incl(MAX_IMAGE_SIDE as f64),
    "texels",
);
pub const HEADS: Range = range(
    "--heads",
    "heads",
    End::Incl(1.0),
    End::Incl(MAX_HEADS as f64),
    "",
);
pub const DISTANCE: Range = range(
    "--distance",
    "camera distance",
    End::Excl(0.0),
    End::Incl(MAX_DISTANCE_HEADS as f64),
    "head heights",
);
pub const CROWD_WALKED: Range = range(
    "--crowd-walked",
    "the crowd's walk",
    End::Incl(-(MAX_DISTANCE_HEADS as f64)),
    End::Incl(MAX_DISTANCE_HEADS as f64),
    "head heights",
);
pub const FOVY: Range = range(
    "--fovy",
    "vertical field of view",
    End::Excl(0.5),
    End::Excl(170.0),
    "degrees",
);
pub const LIGHT_AZIMUTH: Range = range(
    "--light-azimuth",
    "light azimuth",
    End::Incl(-360.0),
    End::Incl(360.0),
    "degrees",
);
pub const LIGHT_ELEVATION: Range = range(
    "--light-elevation",
    "light elevation",
    End::Incl(-90.0),
    End::Incl(90.0),
    "degrees",
);
/// Up to `scene::light::MAX_INTENSITY`.
pub const LIGHT_INTENSITY: Range = range(
    "--light-intensity",
    "light intensity",
    End::Incl(0.0),
    End::Incl(100.0),
    "",
);
pub const AMBIENT: Range = range(
    "--ambient",
    "ambient",
    End::Incl(0.0),
    End::Incl(MAX_AMBIENT as f64),
    "",
);
/// A factor on linear light before the tone curve: 2^-10..=2^10 around the
/// default 2. Past it the frame is black or white whatever the scene.
pub const EXPOSURE: Range = range(
    "--exposure",
    "exposure",
    End::Incl(1.0 / 1024.0),
    End::Incl(1024.0),
    "",
);
pub const SSS_REGION_TILE: Range = range(
    "--sss-region-tile",
    "the SSS region's tile",
    End::Incl(1.0),
    End::Incl(1024.0),
    "pixels",
);
pub const MM_PER_UNIT: Range = range(
    "--mm-per-unit",
    "mm_per_unit",
    End::Incl(1e-12),
    End::Incl(1e12),
    "",
);
pub const FRAMES: Range = range(
    "--frames",
    "--frames",
    End::Incl(1.0),
    End::Incl(MAX_MEASURED_FRAMES as f64),
    "",
);
pub const WARMUP: Range = range(
    "--warmup",
    "--warmup",
    End::Incl(0.0),
    End::Incl(MAX_WARMUP_FRAMES as f64),
    "",
);

/// The time an animation is posed at: a day of clip is more than any file
/// holds, and keeps f32 time steps under 8 ms.
pub const TIME: Range = range(
    "--time",
    "time",
    End::Incl(0.0),
    End::Incl(86_400.0),
    "seconds",
);

/// The time a frame advances the animation (`--time-step`): above 0, at
/// most a second (a frame a second is already a slide show).
pub const TIME_STEP: Range = range(
    "--time-step",
    "time_step",
    End::Excl(0.0),
    End::Incl(1.0),
    "seconds",
);

/// The levels of detail's error budget: 0 (off) to 64 pixels (a level that
/// strays more is no longer the character).
pub const LOD_PIXELS: Range = range(
    "--lod-pixels",
    "lod_pixels",
    End::Incl(0.0),
    End::Incl(64.0),
    "pixels",
);

/// Every range above, in the order docs/usage.md lists them.
pub const ALL: [&Range; 19] = [
    &WIDTH,
    &HEIGHT,
    &SHADOW_SIZE,
    &HEADS,
    &DISTANCE,
    &CROWD_WALKED,
    &FOVY,
    &LIGHT_AZIMUTH,
    &LIGHT_ELEVATION,
    &LIGHT_INTENSITY,
    &AMBIENT,
    &EXPOSURE,
    &SSS_REGION_TILE,
    &MM_PER_UNIT,
    &FRAMES,
    &WARMUP,
    &TIME,
    &TIME_STEP,
    &LOD_PIXELS,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_their_text() {
        assert!(WIDTH.contains(1u32) && WIDTH.contains(16384u32));
        assert!(!WIDTH.contains(0u32) && !WIDTH.contains(16385u32));
        assert!(!DISTANCE.contains(0.0f32) && DISTANCE.contains(1000.0f32));
        assert!(!FOVY.contains(170.0f32) && FOVY.contains(169.9f32) && !FOVY.contains(0.5f32));
        assert!(!AMBIENT.contains(f32::NAN) && !AMBIENT.contains(f64::INFINITY));
        assert_eq!(WIDTH.to_string(), "1..=16384 pixels");
        assert_eq!(DISTANCE.to_string(), "(0, 1000] head heights");
        assert_eq!(FOVY.to_string(), "(0.5, 170) degrees");
        assert_eq!(EXPOSURE.to_string(), "9.765625e-4..=1024");
        assert_eq!(MM_PER_UNIT.to_string(), "1e-12..=1e12");
        assert_eq!(FRAMES.to_string(), "1..=100000");
        // Compared in the value's own precision.
        assert!(MM_PER_UNIT.contains(1e-12f32) && MM_PER_UNIT.contains(1e12f32));
        assert!(!MM_PER_UNIT.contains(1e13f32) && !MM_PER_UNIT.contains(0.0f32));
        let e = HEADS.check(0u32).unwrap_err().to_string();
        assert_eq!(e, "heads must be within 1..=1024, got 0");
        assert_eq!(WIDTH.up_to(4096.0).to_string(), "1..=4096 pixels");
    }

    // One range per flag.
    #[test]
    fn every_range_is_named_once() {
        let mut flags: Vec<&str> = ALL.iter().map(|r| r.flag).collect();
        flags.sort();
        flags.dedup();
        assert_eq!(flags.len(), ALL.len(), "{flags:?}");
    }
}

#[cfg(test)]
mod docs {
    use super::*;

    // docs/usage.md's "Valid ranges" names every range as this table does:
    // `--flag` followed by the range as it prints.
    #[test]
    fn the_usage_docs_give_every_range_as_the_table_does() {
        let usage = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/usage.md"),
        )
        .unwrap();
        // Wrapped lines read as one.
        let usage = usage.split_whitespace().collect::<Vec<_>>().join(" ");
        let missing: Vec<String> = ALL
            .iter()
            .map(|r| format!("`{}` {r}", r.flag))
            .filter(|t| !usage.contains(t.as_str()))
            .collect();
        assert!(missing.is_empty(), "docs/usage.md lacks: {missing:#?}");
    }
}
