//! Hardware budget profiles: what a target GPU can do, read from `profiles/*.toml`.
//!
//! Every number is a [`Quantity`]: a plain number (its source is a comment in the
//! file), a parameter `{ value, min, max }` for a number no public source
//! confirms (HARDWARE.md's "(?)"), or the word `"unknown"`, in which case the
//! model names each pass it could not price for want of it. Parsing is strict:
//! a missing, misspelt or negative field is a one-line error naming the file,
//! the line, the table and the field.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use serde::{Deserialize, Serialize};

pub use crate::budget::format::{FormatClass, TargetFormat};

/// A number of a profile.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawQuantity", into = "RawQuantity")]
pub enum Quantity {
    /// A published number (the file names its source).
    Known(f64),
    /// A number with no confirmed source: modelled with `value`, plausible
    /// within `[min, max]`.
    Param { value: f64, min: f64, max: f64 },
    /// Not known: the passes that need it are reported unpriced.
    Unknown,
}

impl Quantity {
    /// The number the model uses, if there is one.
    pub fn value(self) -> Option<f64> {
        match self {
            Quantity::Known(v) | Quantity::Param { value: v, .. } => Some(v),
            Quantity::Unknown => None,
        }
    }

    pub fn is_param(self) -> bool {
        matches!(self, Quantity::Param { .. })
    }
}

/// How a quantity is spelt in TOML: `8.0`, `{ value = 16.0, min = 5.6, max = 22.4 }`
/// or `"unknown"`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
enum RawQuantity {
    Number(f64),
    Param(RawParam),
    Word(String),
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParam {
    value: f64,
    min: f64,
    max: f64,
}

impl TryFrom<RawQuantity> for Quantity {
    type Error = String;
    fn try_from(r: RawQuantity) -> Result<Self, String> {
        match r {
            RawQuantity::Number(v) => Ok(Quantity::Known(v)),
            RawQuantity::Param(p) => Ok(Quantity::Param {
                value: p.value,
                min: p.min,
                max: p.max,
            }),
            RawQuantity::Word(w) if w == "unknown" => Ok(Quantity::Unknown),
            RawQuantity::Word(w) => Err(format!(
                "'{w}' is not a quantity (a number, {{ value, min, max }} or \"unknown\")"
            )),
        }
    }
}

impl From<Quantity> for RawQuantity {
    fn from(q: Quantity) -> Self {
        match q {
            Quantity::Known(v) => RawQuantity::Number(v),
            Quantity::Param { value, min, max } => RawQuantity::Param(RawParam { value, min, max }),
            Quantity::Unknown => RawQuantity::Word("unknown".into()),
        }
    }
}

/// Identity and kind of a target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    /// Short name (the file's stem).
    pub name: String,
    pub description: String,
    pub kind: ProfileKind,
    /// Where the rates come from: the model's efficiency parameters are
    /// fitted apart for the two (a spec sheet's peak is not reached, a probe is).
    pub rates: RateSource,
}

/// Where a profile's rates come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RateSource {
    /// Spec sheets and unit counts: peak rates (the consoles, the sources' GPUs).
    Peak,
    /// Measured by `dermis bench`'s probes (the benchmark GPUs).
    Probed,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProfileKind {
    Console,
    Handheld,
    Desktop,
    Laptop,
    Datacenter,
}

/// The frame a port aims at.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    pub width_px: u32,
    pub height_px: u32,
    /// The whole frame's GPU time (33.3 ms at 30 fps).
    pub frame_ms: f64,
}

/// The frame's time split by pass role, as fractions of `frame_ms` (design
/// defaults a port edits, not measurements; they need not sum to 1: the rest
/// is left to what dermis does not render, e.g. UI, particles).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetShares {
    pub shadow_share: f64,
    pub geometry_share: f64,
    /// The default skin-SSS budget.
    pub sss_share: f64,
    pub post_share: f64,
    /// The skin-SSS budgets (ms) `dermis plan-check` checks plans at on this
    /// profile by default (empty: none; the profiles name their own cases,
    /// no code names a profile).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plan_check_ms: Vec<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Alu {
    /// Peak FP32 rate of the pixel/unified shaders, counting a multiply-add
    /// as two operations.
    pub gflops: Quantity,
    /// Peak rate reachable by compute dispatches (`"unknown"` where the GPU
    /// has no compute path).
    pub compute_gflops: Quantity,
    /// Workgroup shared-memory bandwidth of compute dispatches, GB/s (what
    /// `ShaderWork::shared_bytes` moves): probed on the benchmark GPUs,
    /// per-SM bytes a clock x SMs x clock elsewhere; `"unknown"` where the
    /// GPU has no compute path (a dispatch is then priced as a pixel shader,
    /// which has no shared memory).
    pub compute_shared_gbytes: Quantity,
    /// How the ALUs issue ([`Alu::issue`]): instructions per second, 1e9, of a
    /// GPU whose ALUs issue whole vector instructions (Xenos: a vec4 and a
    /// scalar slot per ALU per clock; RSX: two vec4 units per pixel pipe).
    /// One shader instruction takes an issue slot whatever its width, so a
    /// vec3 multiply leaves a vec4 ALU's fourth lane (and its scalar slot)
    /// idle, and `gflops`, which counts every lane, overstates the rate.
    /// Absent on SIMT GPUs (G80 on), whose lanes each run one scalar
    /// instruction a clock.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vector_ginstr: Option<Quantity>,
}

/// How a profile's shader instructions are issued (see [`Alu::vector_ginstr`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AluIssue {
    /// One lane-instruction per lane per clock: `gflops / 2` of them a
    /// second (a multiply-add counts two flops).
    Lanes,
    /// Whole vector instructions at this many 1e9 a second.
    Vector(Quantity),
}

impl Alu {
    /// Whether the GPU runs compute dispatches at all (`compute_gflops`
    /// known): the Xbox 360 and the PS3 do not.
    pub fn has_compute(&self) -> bool {
        self.compute_gflops.value().is_some()
    }

    pub fn issue(&self) -> AluIssue {
        self.vector_ginstr.map_or(AluIssue::Lanes, AluIssue::Vector)
    }

    /// Shader instructions (`ShaderWork::alu`: SPIR-V arithmetic, a vector
    /// instruction counted once) executed per second, 1e9: on SIMT lanes one
    /// per lane per clock, `gflops / 2`; on vector-issue ALUs `vector_ginstr`,
    /// whatever each instruction's width, a compute dispatch at the compute
    /// path's share of the peak. `Err` names the quantity the profile lacks.
    pub fn ginstr(&self, compute: bool) -> Result<f64, &'static str> {
        let pixel = self.gflops.value().ok_or("alu.gflops");
        let gflops = if compute {
            self.compute_gflops.value().ok_or("alu.compute_gflops")?
        } else {
            pixel?
        };
        match self.issue() {
            AluIssue::Lanes => Ok(gflops / 2.0),
            AluIssue::Vector(q) => {
                let v = q.value().ok_or("alu.vector_ginstr")?;
                Ok(if compute { v * gflops / pixel? } else { v })
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Texture {
    /// Bilinear fetches of 32-bit texels per second from fragment shaders.
    pub bilinear_gtexels: Quantity,
    /// Cost of one point (nearest) fetch in bilinear-fetch units.
    pub point_cost: Quantity,
    /// Cost of one trilinear fetch in bilinear-fetch units.
    pub trilinear_cost: Quantity,
    /// Cost of one depth-compare (2x2 PCF) fetch in bilinear-fetch units.
    pub depth_compare_cost: Quantity,
    /// Cost multiplier for 64-bit texels (RGBA16F) over 32-bit ones.
    pub texel_64bpp_cost: Quantity,
    /// Cost multiplier for 128-bit texels (RGBA32F).
    pub texel_128bpp_cost: Quantity,
    /// Bilinear fetches per second from compute dispatches.
    pub compute_bilinear_gtexels: Quantity,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Raster {
    /// Triangles set up per second.
    pub triangles_gtris: Quantity,
    /// Depth/stencil-only samples per second (Z-only passes, early rejection).
    pub z_only_gsamples: Quantity,
    /// Colour samples written per second with MSAA on, at 32 bpp (wider
    /// formats at the ratio of their fill rate to RGBA8's); with compression,
    /// the rate of the samples that are stored uncompressed.
    pub msaa_gsamples: Quantity,
    /// What MSAA colour and Z compression saves ([`MsaaCompression`]).
    pub msaa_compression: MsaaCompression,
    /// Depth/stencil clears set per-tile state instead of writing every
    /// sample (NVIDIA's "Fast Z-Clear"): they cost no fill and no bandwidth.
    pub fast_depth_clear: bool,
    /// Most colour targets one pass may write.
    pub max_color_targets: u32,
    /// Most samples per pixel.
    pub max_msaa: u32,
}

/// What a GPU's lossless MSAA compression saves. MSAA shades once per pixel,
/// so the samples of a pixel one fragment covers whole hold one colour and
/// one depth plane: compression stores them once. A pixel that triangle edges
/// cross holds samples of two or more fragments and is stored whole
/// (`budget::msaa`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MsaaCompression {
    /// Every sample is written, stored and resolved (eDRAM, or no source).
    None,
    /// Fully covered pixels are stored (colour and Z) and resolved as one
    /// sample; the ROPs still process every sample at `msaa_gsamples`.
    Storage,
    /// As `Storage`, and a fully covered pixel also passes the ROPs as one
    /// pixel (at the fill rate): only partly covered pixels cost their
    /// samples at `msaa_gsamples`.
    StorageAndRop,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Memory {
    /// Bandwidth of the memory that holds textures and (without eDRAM)
    /// render targets.
    pub bandwidth_gbps: Quantity,
    /// Whether the CPU shares it (its traffic is not modelled).
    pub shared_with_cpu: bool,
    /// A second pool the GPU can reach (PS3: XDR through FlexIO); not used
    /// for render targets by the model.
    pub second_pool_gbps: Quantity,
}

/// Embedded frame-buffer memory (Xbox 360): render targets live there while
/// drawn and reach textures only through a resolve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Edram {
    pub size_mib: f64,
    /// Tiles available to one screen tile's colour and depth.
    pub tiles: u32,
    pub tile_width_samples: u32,
    pub tile_height_samples: u32,
    /// Bytes of one tile at 32 bpp (a 64 bpp format takes twice the tiles).
    pub tile_bytes: u32,
    /// eDRAM-internal bandwidth (blending, clears, MSAA).
    pub internal_gbps: Quantity,
    /// GPU-to-eDRAM link.
    pub link_gbps: Quantity,
    /// Rate of a resolve (eDRAM to main memory); no public number: a
    /// parameter whose upper bound is main-memory bandwidth.
    pub resolve_gbps: Quantity,
    /// Geometry cost multiplier of a predicated-tiled pass.
    pub tiled_geometry_factor: Quantity,
}

/// What the profile can do with one format as a render target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormatCaps {
    pub format: TargetFormat,
    /// Can be a render target.
    pub render: bool,
    /// Can be blended into.
    pub blend: bool,
    /// Pixels written per second (depth formats: samples per second).
    pub fill_gpix: Quantity,
    /// Pixels blended per second (`"unknown"` where `blend` is false).
    pub blend_gpix: Quantity,
}

/// A hardware budget profile.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    pub profile: Meta,
    pub target: Target,
    pub budget: BudgetShares,
    pub alu: Alu,
    pub texture: Texture,
    pub raster: Raster,
    pub memory: Memory,
    #[serde(default)]
    pub edram: Option<Edram>,
    pub formats: Vec<FormatCaps>,
}

/// The folder `profiles/` of the source tree (the tools that write
/// profiles and stored frames; a command reads the embedded copies).
pub fn profiles_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles")
}

/// Names of the profiles built into the binary, sorted.
pub fn list_profiles() -> Vec<String> {
    crate::embedded::files_in("profiles", ".toml")
        .into_iter()
        .filter_map(|(name, _)| name.strip_suffix(".toml").map(str::to_string))
        .collect()
}

/// Every built-in profile, parsed, sorted by name.
pub fn builtin_profiles() -> Result<Vec<Profile>> {
    list_profiles().iter().map(|n| Profile::load(n)).collect()
}

impl Profile {
    /// A profile by name (`xbox360`: `profiles/xbox360.toml`, built into the
    /// binary) or by path (anything with a `/` or ending in `.toml`: a
    /// user's own profile, read through the bounded reader). An unknown
    /// name is an error listing the built-in ones.
    pub fn load(name_or_path: &str) -> Result<Profile> {
        if name_or_path.contains('/') || name_or_path.ends_with(".toml") {
            let path = PathBuf::from(name_or_path);
            let text = crate::files::read_text(&path, "profile", crate::files::MAX_TEXT_FILE)?;
            return Profile::parse(&text, &path.display().to_string());
        }
        let file = format!("profiles/{name_or_path}.toml");
        let text = crate::embedded::file(&file).ok_or_else(|| {
            anyhow!(
                "no profile '{name_or_path}' (built in: {}; or give a TOML file's path)",
                list_profiles().join(", ")
            )
        })?;
        Profile::parse(text, &file)
    }

    /// Parses and checks a profile; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Profile> {
        let p: Profile = toml::from_str(text).map_err(|e| anyhow!(one_line(file, text, &e)))?;
        p.check().map_err(|e| anyhow!("{file}: {e}"))?;
        Ok(p)
    }

    /// What the profile says about `f` as a render target.
    pub fn caps(&self, f: TargetFormat) -> Option<&FormatCaps> {
        self.formats.iter().find(|c| c.format == f)
    }

    /// The budget in ms of a share of the frame.
    pub fn share_ms(&self, share: f64) -> f64 {
        share * self.target.frame_ms
    }

    /// Range and consistency checks serde cannot express; errors name the field.
    fn check(&self) -> Result<()> {
        let pos = |path: &str, v: f64| -> Result<()> {
            if !(v.is_finite() && v > 0.0) {
                bail!("field `{path}` must be a positive number, got {v}");
            }
            Ok(())
        };
        let q = |path: &str, q: Quantity| -> Result<()> {
            match q {
                Quantity::Known(v) => pos(path, v),
                Quantity::Param { value, min, max } => {
                    pos(path, value)?;
                    pos(&format!("{path}.min"), min)?;
                    if !(min <= value && value <= max) {
                        bail!("field `{path}`: value {value} is outside [min {min}, max {max}]");
                    }
                    Ok(())
                }
                Quantity::Unknown => Ok(()),
            }
        };
        // The frame sizes `render` accepts (`--width`/`--height`), whoever wrote the file.
        let side = crate::scene::MAX_IMAGE_SIDE;
        for (n, v) in [
            ("target.width_px", self.target.width_px),
            ("target.height_px", self.target.height_px),
        ] {
            if !(1..=side).contains(&v) {
                bail!("field `{n}` must be within 1..={side} pixels (as render's --width/--height), got {v}");
            }
        }
        pos("target.frame_ms", self.target.frame_ms)?;
        let b = &self.budget;
        let shares = [
            ("budget.shadow_share", b.shadow_share),
            ("budget.geometry_share", b.geometry_share),
            ("budget.sss_share", b.sss_share),
            ("budget.post_share", b.post_share),
        ];
        for (n, s) in shares {
            if !(0.0..=1.0).contains(&s) {
                bail!("field `{n}` must be a fraction in [0, 1], got {s}");
            }
        }
        let sum: f64 = shares.iter().map(|s| s.1).sum();
        if sum > 1.0 + 1e-9 {
            bail!("fields `budget.*_share` add up to {sum}, more than the frame");
        }
        for &ms in &b.plan_check_ms {
            pos("budget.plan_check_ms", ms)?;
        }
        q("alu.gflops", self.alu.gflops)?;
        q("alu.compute_gflops", self.alu.compute_gflops)?;
        q("alu.compute_shared_gbytes", self.alu.compute_shared_gbytes)?;
        if let Some(v) = self.alu.vector_ginstr {
            q("alu.vector_ginstr", v)?;
            // An instruction fills at least one lane: a vector-issue rate above
            // the lanes' (gflops / 2) contradicts the profile's own gflops.
            let top = match v {
                Quantity::Param { max, .. } => Some(max),
                other => other.value(),
            };
            if let (Some(top), Some(g)) = (top, self.alu.gflops.value()) {
                if top > g / 2.0 {
                    bail!(
                        "field `alu.vector_ginstr`: {top} G instructions/s is more than \
                         alu.gflops / 2 = {} G lane-instructions/s",
                        g / 2.0
                    );
                }
            }
        }
        let t = &self.texture;
        q("texture.bilinear_gtexels", t.bilinear_gtexels)?;
        q("texture.point_cost", t.point_cost)?;
        q("texture.trilinear_cost", t.trilinear_cost)?;
        q("texture.depth_compare_cost", t.depth_compare_cost)?;
        q("texture.texel_64bpp_cost", t.texel_64bpp_cost)?;
        q("texture.texel_128bpp_cost", t.texel_128bpp_cost)?;
        q(
            "texture.compute_bilinear_gtexels",
            t.compute_bilinear_gtexels,
        )?;
        let r = &self.raster;
        q("raster.triangles_gtris", r.triangles_gtris)?;
        q("raster.z_only_gsamples", r.z_only_gsamples)?;
        q("raster.msaa_gsamples", r.msaa_gsamples)?;
        if r.max_color_targets == 0 || r.max_msaa == 0 {
            bail!("field `raster.max_color_targets`/`raster.max_msaa` must be at least 1");
        }
        q("memory.bandwidth_gbps", self.memory.bandwidth_gbps)?;
        q("memory.second_pool_gbps", self.memory.second_pool_gbps)?;
        if let Some(e) = &self.edram {
            pos("edram.size_mib", e.size_mib)?;
            for (n, v) in [
                ("edram.tiles", e.tiles),
                ("edram.tile_width_samples", e.tile_width_samples),
                ("edram.tile_height_samples", e.tile_height_samples),
                ("edram.tile_bytes", e.tile_bytes),
            ] {
                if v == 0 {
                    bail!("field `{n}` must be positive");
                }
            }
            q("edram.internal_gbps", e.internal_gbps)?;
            q("edram.link_gbps", e.link_gbps)?;
            q("edram.resolve_gbps", e.resolve_gbps)?;
            q("edram.tiled_geometry_factor", e.tiled_geometry_factor)?;
        }
        for (i, f) in self.formats.iter().enumerate() {
            let n = format!("formats[{i}] ({})", kebab(f.format));
            q(&format!("{n}.fill_gpix"), f.fill_gpix)?;
            q(&format!("{n}.blend_gpix"), f.blend_gpix)?;
            if self.formats[..i].iter().any(|g| g.format == f.format) {
                bail!("field `{n}.format` is listed twice");
            }
        }
        Ok(())
    }
}

/// A format's TOML spelling.
pub fn kebab(f: TargetFormat) -> String {
    serde_json::to_value(f)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{f:?}"))
}

/// A TOML error as one line: `file:line: in [table]: message`.
fn one_line(file: &str, text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    let Some(span) = e.span() else {
        return format!("{file}: {msg}");
    };
    let start = span.start.min(text.len());
    let line = text[..start].matches('\n').count() + 1;
    // The innermost table header at or above the error's line names where the
    // field sits (a missing field's span is its table's header).
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let table = text[..line_end]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| format!(" in {l}"))
        .unwrap_or_default();
    format!("{file}:{line}:{table}: {msg}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_profile_parses() {
        let names = list_profiles();
        for want in [
            "xbox360",
            "ps3",
            "switch-docked",
            "switch-handheld",
            "steam-deck",
            "geforce-8800-gtx",
            "geforce-8600m-gs",
            "geforce-9800-gtx-plus",
            "geforce-gtx-470",
            "geforce-gtx-580",
            "geforce-gt-130m",
            "geforce-gtx-970m",
            "nvidia-h100",
            "nvidia-h200",
        ] {
            assert!(
                names.iter().any(|n| n == want),
                "profiles/{want}.toml missing"
            );
        }
        for n in &names {
            let p = Profile::load(n).unwrap_or_else(|e| panic!("{e:#}"));
            assert_eq!(&p.profile.name, n, "profile name must match its file stem");
        }
    }

    #[test]
    fn load_by_path_too() {
        let path = profiles_dir().join("xbox360.toml");
        let p = Profile::load(path.to_str().unwrap()).unwrap();
        assert_eq!(p.target.width_px, 1280);
        assert!(p.edram.is_some());
        assert!(Profile::load("no-such-gpu").is_err());
    }

    fn xbox_text() -> String {
        std::fs::read_to_string(profiles_dir().join("xbox360.toml")).unwrap()
    }

    fn err_of(text: &str) -> String {
        let e = Profile::parse(text, "profiles/test.toml")
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\n'), "error must be one line: {e}");
        assert!(
            e.starts_with("profiles/test.toml"),
            "error must name the file: {e}"
        );
        e
    }

    #[test]
    fn missing_field_is_one_line_naming_it() {
        let t = xbox_text().replace("frame_ms = 33.3", "");
        let e = err_of(&t);
        assert!(e.contains("frame_ms") && e.contains("[target]"), "{e}");
    }

    #[test]
    fn misspelt_field_is_one_line_naming_it() {
        let t = xbox_text().replace("frame_ms = 33.3", "frame_msec = 33.3");
        let e = err_of(&t);
        assert!(e.contains("frame_msec"), "{e}");
    }

    #[test]
    fn negative_field_is_one_line_naming_it() {
        let t = xbox_text().replace("bandwidth_gbps = 22.4", "bandwidth_gbps = -22.4");
        let e = err_of(&t);
        assert!(e.contains("memory.bandwidth_gbps"), "{e}");
        let t = xbox_text().replace("width_px = 1280", "width_px = -1280");
        let e = err_of(&t);
        assert!(e.contains("-1280") && e.contains("[target]"), "{e}");
    }

    #[test]
    fn quantities_parse_all_three_ways() {
        let p = Profile::load("xbox360").unwrap();
        let e = p.edram.unwrap();
        assert!(e.resolve_gbps.is_param());
        assert_eq!(p.texture.compute_bilinear_gtexels, Quantity::Unknown);
        assert_eq!(p.texture.bilinear_gtexels, Quantity::Known(8.0));
        let t = xbox_text().replace("max_msaa = 4", "max_msaa = \"four\"");
        err_of(&t);
        let t = xbox_text().replacen("z_only_gsamples = 32.0", "z_only_gsamples = \"maybe\"", 1);
        let e = err_of(&t);
        assert!(e.contains("[raster]"), "{e}");
    }

    #[test]
    fn param_outside_its_bounds_is_an_error() {
        let t = xbox_text();
        let start = t.find("resolve_gbps =").unwrap();
        let end = start + t[start..].find('\n').unwrap();
        let t = format!(
            "{}resolve_gbps = {{ value = 40.0, min = 5.6, max = 22.4 }}{}",
            &t[..start],
            &t[end..]
        );
        let e = err_of(&t);
        assert!(e.contains("edram.resolve_gbps"), "{e}");
    }

    /// The Xbox 360's profile with its `vector_ginstr` line replaced.
    fn with_issue(line: &str) -> String {
        let t = xbox_text();
        let start = t.find("vector_ginstr =").unwrap();
        let end = start + t[start..].find('\n').unwrap();
        format!("{}{line}{}", &t[..start], &t[end..])
    }

    #[test]
    fn vector_issue_is_read_where_given_and_lanes_elsewhere() {
        let x = Profile::load("xbox360").unwrap();
        assert_eq!(
            x.alu.issue(),
            AluIssue::Vector(Quantity::Param {
                value: 24.0,
                min: 24.0,
                max: 48.0
            })
        );
        assert_eq!(
            Profile::load("geforce-9800-gtx-plus").unwrap().alu.issue(),
            AluIssue::Lanes
        );
        // Absent (SIMT), a plain number and "unknown" all parse.
        let p = Profile::parse(&with_issue(""), "t.toml").unwrap();
        assert_eq!(p.alu.issue(), AluIssue::Lanes);
        let p = Profile::parse(&with_issue("vector_ginstr = 30.0"), "t.toml").unwrap();
        assert_eq!(p.alu.issue(), AluIssue::Vector(Quantity::Known(30.0)));
        let p = Profile::parse(&with_issue("vector_ginstr = \"unknown\""), "t.toml").unwrap();
        assert_eq!(p.alu.issue(), AluIssue::Vector(Quantity::Unknown));
    }

    #[test]
    fn a_bad_issue_rate_is_one_line_naming_it() {
        let e = err_of(&with_issue("vector_ginstr = \"fast\""));
        assert!(e.contains("[alu]") && e.contains("fast"), "{e}");
        let e = err_of(&with_issue("vector_ginstr = -24.0"));
        assert!(e.contains("alu.vector_ginstr"), "{e}");
        let e = err_of(&with_issue("vector_ginstrs = 24.0"));
        assert!(e.contains("vector_ginstrs"), "{e}");
        // More instructions than lanes (240 GFLOPS: 120 G lane-instructions).
        let e = err_of(&with_issue(
            "vector_ginstr = { value = 24.0, min = 24.0, max = 121.0 }",
        ));
        assert!(e.contains("alu.vector_ginstr") && e.contains("120"), "{e}");
        let e = err_of(&with_issue(
            "vector_ginstr = { value = 50.0, min = 24.0, max = 48.0 }",
        ));
        assert!(
            e.contains("alu.vector_ginstr") && e.contains("outside"),
            "{e}"
        );
    }
}
