//! What a render is asked to do, validated before any GPU work: the frame's
//! settings, the SSS method (a registry entry) and the options given to it.

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

use crate::method::region::{RegionMode, TILE_PX};
use crate::method::{default_method, MethodEntry, MethodOptions};
use crate::mix::assign::Rules;
use crate::mix::plan_file::PlanFile;
use crate::post::{AaMode, PostOptions};
use crate::scene::crowd_geometry::CharacterGeometry;
use crate::scene::layout::Layout;
use crate::scene::light::KeyLight;
use crate::skin::transmittance::TransmittanceProfile;

use crate::ranges;
/// The ranges every reader of a frame holds it to (`crate::ranges`, their
/// one owner), re-exported where the settings are checked.
pub use crate::ranges::{MAX_AMBIENT, MAX_DISTANCE_HEADS, MAX_HEADS, MAX_IMAGE_SIDE};

/// The vertical field of view's range, (0.5, 170) degrees: `--fovy`, and the
/// `fovy_deg` of a report `compare` reads.
pub fn check_fovy(fovy_deg: f32) -> Result<()> {
    ranges::FOVY.check(fovy_deg)
}

/// Where the methods of a frame of several come from (`render --assign` or
/// `--plan`): resolved against the frame's characters by
/// `render::groups::group_specs`. Serialised as `{"rules": "0=ssg,*=none"}`
/// or `{"plan": {...the plan file...}}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
// A frame's settings are made a few times a command, never in a loop of
// frames: the plan's size inline costs nothing measurable.
#[allow(clippy::large_enum_variant)]
pub enum Assignment {
    Rules(Rules),
    Plan(#[serde(deserialize_with = "checked_plan")] PlanFile),
}

/// A plan read from settings is checked as a plan file is (`PlanFile::load`).
fn checked_plan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<PlanFile, D::Error> {
    let plan = PlanFile::deserialize(d)?;
    plan.check()
        .map_err(|e| serde::de::Error::custom(format!("plan: {e:#}")))?;
    Ok(plan)
}

/// The method as its registry name (`--method`'s spelling); read back
/// through the registry, aliases included.
mod method_by_name {
    use serde::{Deserialize, Deserializer, Serializer};

    use crate::method::MethodEntry;

    pub fn serialize<S: Serializer>(
        m: &&'static MethodEntry,
        s: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(m.name)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> std::result::Result<&'static MethodEntry, D::Error> {
        let name = String::deserialize(d)?;
        crate::method::lookup(&name).map_err(|e| serde::de::Error::custom(format!("{e:#}")))
    }
}

/// Everything a frame is rendered from but its scene: serialised whole into
/// every report (`report.json`'s `settings`), so a report renders its frame
/// again (`dermis render --settings report.json`). A new field reaches the
/// reports through this derive, with no hand copy.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    #[serde(with = "method_by_name")]
    pub method: &'static MethodEntry,
    /// Options given to the methods (each reads its own; see `method::options`).
    pub options: MethodOptions,
    /// A method per character (`None`: every character gets `method` with
    /// `options`, the single-method frame); `method` and `options` are then
    /// not read.
    pub assignment: Option<Assignment>,
    /// Also write each character's skin pixels (`render --character-ids`: an
    /// extra pass after the frame; the frame itself is unchanged).
    pub character_ids: bool,
    pub transmittance: bool,
    /// Which T(s) transmittance uses (eq. 5.12 as published, or the plane integral).
    pub transmittance_profile: TransmittanceProfile,
    /// Limit the SSS passes to the skin's neighbourhood, or run them on the screen.
    pub sss_region: RegionMode,
    /// Side of the region's screen tiles in pixels (smaller: tighter, more draws).
    pub sss_region_tile: u32,
    pub heads: u32,
    /// How the characters stand when there are several.
    pub layout: Layout,
    /// Camera distance from the (first) head's centre, in head heights.
    pub distance_heads: f32,
    /// The characters walked this many head heights toward the camera, the
    /// layout kept as `distance_heads` places it (`scene::framing::Shot`;
    /// `dermis plan-motion`'s sequence). 0 everywhere else.
    pub walk_heads: f32,
    pub fovy_deg: f32,
    pub light: KeyLight,
    /// Constant ambient irradiance (white), so unlit skin is not black.
    pub ambient: f32,
    pub exposure: f32,
    pub shadow_size: u32,
    /// Anti-aliasing after the tone map (`--aa`; `crate::post`). `None` leaves
    /// the frame as it was before the post chain, bit for bit.
    pub aa: AaMode,
    /// The post chain's other options (`--bloom`; `crate::post::PostOptions`).
    /// The default adds nothing to the frame.
    pub post: PostOptions,
    /// Samples per pixel of the geometry pass (`--msaa`: 1, 2, 4 or 8),
    /// resolved before the SSS passes (docs/aa.md, "MSAA with the SSS
    /// pipeline"). 1 is the frame as it was before, bit for bit.
    pub msaa: u32,
    /// Levels of detail (`--lod-pixels`): each character drawn with the
    /// coarsest level of its meshes whose error covers at most this many
    /// pixels at its distance (`scene::lod`); 0: the full meshes.
    /// Left out of a report when 0, so the reports written before the
    /// levels existed read back as the files they are.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub lod_pixels: f32,
    /// Pre- or post-scatter texturing (`--texturing`; [`Texturing`]). Left
    /// out of a report when pre, as reports before it were.
    #[serde(default, skip_serializing_if = "Texturing::is_pre")]
    pub texturing: Texturing,
}

fn is_zero(x: &f32) -> bool {
    *x == 0.0
}

/// Where the albedo enters the skin's light (d'Eon and Luebke 2007; thesis
/// ch. 7.6, `--texturing`). Pre-scatter: the geometry pass multiplies the
/// light by the albedo and the SSS blurs both, so the albedo is blurred too.
/// Post-scatter: the SSS blurs the light alone and the composite multiplies
/// the pixel's albedo in afterwards (a scanned albedo holds its own blur
/// already; the thesis' ch. 7 renders so), from a target the geometry pass
/// writes beside the others.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Texturing {
    /// The albedo is scattered with the light (the default, every chapter
    /// before 7).
    #[default]
    Pre,
    /// The light is scattered, the albedo applied after.
    Post,
}

impl Texturing {
    pub fn is_pre(&self) -> bool {
        *self == Texturing::Pre
    }

    /// Its name on the command line and in the files (`pre`, `post`).
    pub fn name(self) -> &'static str {
        match self {
            Texturing::Pre => "pre",
            Texturing::Post => "post",
        }
    }
}

/// The sample counts `--msaa` takes.
pub const MSAA_COUNTS: [u32; 4] = [1, 2, 4, 8];

/// Refuses a sample count `--msaa` does not take, and a method that cannot
/// run multisampled (`MethodEntry::no_msaa`), in one line.
pub fn check_msaa(msaa: u32, method: Option<&MethodEntry>) -> Result<()> {
    if !MSAA_COUNTS.contains(&msaa) {
        bail!("--msaa must be 1, 2, 4 or 8 samples per pixel, got {msaa}");
    }
    if let (true, Some(method)) = (msaa > 1, method) {
        if let Some(why) = method.no_msaa {
            bail!(
                "method {} cannot run with --msaa {msaa}: {why}",
                method.name
            );
        }
    }
    Ok(())
}

/// The default view is a portrait (issue 15): the head alone in frame at
/// [`PORTRAIT_CLOSE_UPS`] close-up distances, a key light from the front-side
/// and above (25 degrees round, 35 up: the loop lighting of a portrait), its
/// cast shadow falling behind the head and softened by the ambient. It is the
/// CLI's default (`dermis render` with no flags).
impl Default for RenderSettings {
    fn default() -> Self {
        let study = RenderSettings::study();
        RenderSettings {
            distance_heads: PORTRAIT_CLOSE_UPS
                * crate::scene::camera::Camera::close_up_distance_heads(study.fovy_deg),
            light: KeyLight {
                azimuth_deg: 25.0,
                elevation_deg: 35.0,
                ..study.light
            },
            ambient: 0.2,
            ..study
        }
    }
}

/// Camera distance of the default portrait in close-up distances (1: the head
/// fills the screen height): the head alone in frame with a little room.
pub const PORTRAIT_CLOSE_UPS: f32 = 1.25;

/// The named camera distances (`--shot`; the views of `aa-eval` and the
/// plan check), each a multiple of the close-up distance at the frame's
/// field of view: the one place they are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShotPreset {
    /// The default: a portrait, the head alone in frame with a little room
    /// ([`PORTRAIT_CLOSE_UPS`] close-up distances).
    Portrait,
    /// The head fills the screen height.
    Close,
    /// Twice the close-up distance.
    Mid,
    /// Five times the close-up distance.
    Far,
}

impl ShotPreset {
    /// Close-up distances (1: the head fills the screen height).
    pub fn close_ups(self) -> f32 {
        match self {
            ShotPreset::Portrait => PORTRAIT_CLOSE_UPS,
            ShotPreset::Close => 1.0,
            ShotPreset::Mid => 2.0,
            ShotPreset::Far => 5.0,
        }
    }

    /// Camera distance in head heights at a vertical field of view of `fovy_deg`.
    pub fn distance_heads(self, fovy_deg: f32) -> f32 {
        self.close_ups() * crate::scene::camera::Camera::close_up_distance_heads(fovy_deg)
    }
}

impl RenderSettings {
    /// The fixed view every test, the eval's procedural scene and every run
    /// recorded before issue 15 use: 4 head heights away, the key light 60
    /// degrees round and 30 up, ambient 0.08 (the default view until the
    /// portrait replaced it; the CLI reaches it with
    /// `--shot mid --light-azimuth 60 --light-elevation 30 --ambient 0.08`,
    /// the mid shot being the CLI's own distance then). Pinned, so changing
    /// the default picture changes no test and no recorded figure.
    pub fn study() -> Self {
        RenderSettings {
            width: 1280,
            height: 720,
            method: default_method(),
            options: MethodOptions::default(),
            assignment: None,
            character_ids: false,
            transmittance: true,
            transmittance_profile: TransmittanceProfile::Thesis,
            sss_region: RegionMode::Skin,
            sss_region_tile: TILE_PX,
            heads: 1,
            layout: Layout::Crowd,
            distance_heads: 4.0,
            walk_heads: 0.0,
            fovy_deg: 20.0,
            light: KeyLight {
                azimuth_deg: 60.0,
                elevation_deg: 30.0,
                color: [1.0, 0.96, 0.92],
                intensity: 2.5,
            },
            ambient: 0.08,
            exposure: 2.0,
            shadow_size: 2048,
            aa: AaMode::None,
            post: PostOptions::default(),
            msaa: 1,
            lod_pixels: 0.0,
            texturing: Texturing::Pre,
        }
    }

    /// These settings with `method` and option `key` set to `value` (tests, eval).
    pub fn with(mut self, method: &'static MethodEntry, options: &[(&str, &str)]) -> Self {
        self.method = method;
        self.options = self.options.with(options);
        self
    }

    /// Rejects settings that would give a bad frame or a driver error, with one
    /// clear message each, before any device opens. Every number has a range
    /// (docs/usage.md, "Valid ranges"): width, height, shadow map
    /// 1..=`MAX_IMAGE_SIDE`; heads 1..=1024; distance (0, 1000] head
    /// heights; field of view (0.5, 170) degrees; light azimuth -360..=360,
    /// elevation -90..=90, intensity 0..=100; ambient 0..=100; exposure
    /// 2^-10..=2^10; SSS region tile 1..=1024; the method's own options in
    /// its `Config::parse`. What only the device knows (its largest image)
    /// is [`RenderSettings::check_device_limits`], checked once it is open.
    /// Called once per frame, by `render::request::FrameRequest::new`.
    pub fn validate(&self) -> Result<()> {
        self.check_sizes(MAX_IMAGE_SIDE, "the limit")?;
        (self.method.check)(&self.method.opts(&self.options))
            .with_context(|| format!("method {}", self.method.name))?;
        // A frame of several is checked per group once its methods are known
        // (`render::groups::group_specs`).
        check_msaa(self.msaa, self.assignment.is_none().then_some(self.method))?;
        if self.msaa > 1 && self.character_ids {
            bail!(
                "--character-ids cannot run with --msaa {}: its pass redraws the heads depth-EQUAL against the frame's depth, which is resolved from sample 0",
                self.msaa
            );
        }
        // An option of another method is ignored (the CLI says so), but its
        // value must still be one it would accept: no NaN slips through unread.
        for m in crate::method::METHODS {
            let given = m
                .options
                .iter()
                .any(|o| self.options.given(o.key).is_some());
            if m.name != self.method.name && given {
                (m.check)(&m.opts(&self.options))
                    .with_context(|| format!("method {} (an option of it was given)", m.name))?;
            }
        }
        ranges::SSS_REGION_TILE.check(self.sss_region_tile)?;
        ranges::HEADS.check(self.heads)?;
        ranges::LOD_PIXELS.check(self.lod_pixels)?;
        ranges::DISTANCE.check(self.distance_heads)?;
        // Walking past the camera is allowed (a character behind it shows no
        // pixel), but not without bound.
        ranges::CROWD_WALKED.check(self.walk_heads)?;
        self.post.check(self.aa)?;
        check_fovy(self.fovy_deg)?;
        self.light.validate()?;
        ranges::AMBIENT.check(self.ambient)?;
        ranges::EXPOSURE.check(self.exposure)?;
        Ok(())
    }
}

impl RenderSettings {
    /// Every character's level and caster flag when `--plan` gives them.
    pub fn planned_geometry(&self) -> Option<Vec<CharacterGeometry>> {
        match &self.assignment {
            Some(Assignment::Plan(p)) => p.geometry(),
            _ => None,
        }
    }

    /// Whether the frame needs its characters' levels of detail: at
    /// `--lod-pixels` above 0, or a plan that draws some character at a
    /// level.
    pub fn wants_levels(&self) -> bool {
        self.lod_pixels > 0.0
            || self
                .planned_geometry()
                .is_some_and(|g| g.iter().any(|c| c.level > 0))
    }

    /// The frame's and the shadow map's sides against the largest image the
    /// device takes (`maxImageDimension2D`): the one check of the settings
    /// that needs a device, made once it is open.
    pub fn check_device_limits(&self, max_image_dimension: u32) -> Result<()> {
        if max_image_dimension < MAX_IMAGE_SIDE {
            self.check_sizes(max_image_dimension, "the device limit")?;
        }
        Ok(())
    }

    fn check_sizes(&self, limit: u32, whose: &str) -> Result<()> {
        for (r, v) in [(ranges::WIDTH, self.width), (ranges::HEIGHT, self.height)] {
            if v == 0 {
                bail!("{} must be at least 1 pixel", r.what);
            }
            if v > limit {
                bail!("{} {v} exceeds {whose} of {limit} pixels", r.what);
            }
        }
        ranges::SHADOW_SIZE
            .up_to(limit as f64)
            .check(self.shadow_size)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::{default_method, lookup};

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        let s = RenderSettings::default();
        s.validate().unwrap();
        let mut b = s.clone();
        b.width = 0;
        assert!(b.validate().unwrap_err().to_string().contains("width"));
        let mut b = s.clone();
        b.height = 20000;
        assert!(b.validate().unwrap_err().to_string().contains("the limit"));
        // The device's own limit, once it is open.
        let mut b = s.clone();
        b.width = 5000;
        b.validate().unwrap();
        b.check_device_limits(16384).unwrap();
        let e = b.check_device_limits(4096).unwrap_err().to_string();
        assert!(e.contains("exceeds the device limit of 4096"), "{e}");
        for tile in [0, 2000] {
            let mut b = s.clone();
            b.sss_region_tile = tile;
            assert!(b.validate().unwrap_err().to_string().contains("tile"));
        }
        let mut b = s.clone();
        b.distance_heads = f32::NAN;
        assert!(b.validate().unwrap_err().to_string().contains("distance"));
        let sep = lookup("separable").unwrap();
        let b = s.clone().with(sep, &[("sss-width-mm", "-1")]);
        assert!(b.validate().is_err());
        let b = s.clone().with(sep, &[("samples", "16")]);
        let e = format!("{:#}", b.validate().unwrap_err());
        assert!(e.contains("odd"), "{e}");
        // An option of another method is checked too, though not read.
        let b = s.clone().with(lookup("ssg").unwrap(), &[("samples", "16")]);
        let e = format!("{:#}", b.validate().unwrap_err());
        assert!(e.contains("method separable") && e.contains("odd"), "{e}");
        let mut b = s.clone();
        b.light.intensity = f32::NAN;
        assert!(b.validate().is_err());
    }

    // `--msaa` takes 1, 2, 4 or 8; the methods that cannot run multisampled
    // say so in one line naming themselves, the others pass.
    #[test]
    fn msaa_counts_and_the_methods_that_refuse_it() {
        for n in MSAA_COUNTS {
            check_msaa(n, Some(default_method())).unwrap();
        }
        for n in [0, 3, 16] {
            let e = check_msaa(n, None).unwrap_err().to_string();
            assert!(
                e.contains("1, 2, 4 or 8") && e.contains(&n.to_string()),
                "{e}"
            );
        }
        for m in crate::method::METHODS {
            check_msaa(1, Some(m)).unwrap();
            match (m.no_msaa, check_msaa(4, Some(m))) {
                (None, r) => r.unwrap(),
                (Some(_), r) => {
                    let e = r.unwrap_err().to_string();
                    assert!(e.contains(m.name) && !e.contains('\n'), "{e}");
                }
            }
        }
        let mut s = RenderSettings {
            msaa: 4,
            ..RenderSettings::default()
        };
        s.validate().unwrap();
        s.character_ids = true;
        assert!(s.validate().is_err());
    }

    // Issue 11: every number has an upper bound too; huge values gave black
    // frames (exposure 1e30) or NaN pixels (falloff 1e30, light 1e30).
    #[test]
    fn huge_values_are_refused_before_a_device_opens() {
        let s = RenderSettings::default();
        let refused = |f: &dyn Fn(&mut RenderSettings), what: &str| {
            let mut b = s.clone();
            f(&mut b);
            let e = format!("{:#}", b.validate().unwrap_err());
            assert!(e.contains(what), "{e}");
        };
        for v in [1e30, f32::INFINITY, 1025.0, 0.0, -1.0, 1e-4] {
            refused(&|b| b.exposure = v, "exposure must be within");
        }
        for v in [1e30, 100.5, -0.1, f32::NAN] {
            refused(&|b| b.ambient = v, "ambient must be within");
            refused(&|b| b.light.intensity = v, "intensity must be within");
        }
        refused(&|b| b.distance_heads = 1e30, "distance");
        refused(&|b| b.light.azimuth_deg = 1e30, "azimuth");
        refused(&|b| b.width = u32::MAX, "exceeds");
        let sep = lookup("separable").unwrap();
        let b = s.clone().with(sep, &[("falloff", "1e30,0.5,0.5")]);
        let e = format!("{:#}", b.validate().unwrap_err());
        assert!(e.contains("falloff"), "{e}");
        // The bounds themselves are accepted.
        let mut b = s;
        b.exposure = 1024.0;
        b.ambient = MAX_AMBIENT;
        b.light.intensity = crate::scene::light::MAX_INTENSITY;
        b.distance_heads = MAX_DISTANCE_HEADS;
        b.validate().unwrap();
    }
}
