//! The `dermis` command line: argument parsing and dispatch only; the work is
//! in the library (`dermis::run`, `dermis::eval::study`).
//!
//! Over 800 lines because the command line is one clap tree: the flags every
//! command shares, the value enums mirroring the library's, and the dispatch
//! of each command read best in one place (all of it argument handling).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use clap::{
    Arg, ArgAction, ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum,
};

use dermis::aa::edges::Preset as SmaaPreset;
use dermis::budget::run::BudgetOptions;
use dermis::budget::Rescale;
use dermis::eval::{study, sweep};
use dermis::method::region::RegionMode;
use dermis::method::{
    all_options, foreign_options, ground_truth, listing, listing_text, lookup, MethodOptions,
    OptKind,
};
use dermis::mix::plan_file::PlanFile;
use dermis::post::{AaMode, EdgeSource};
use dermis::render::settings::Assignment;
use dermis::render::RenderSettings;
use dermis::run::{bench_run, header, render_to_dir, RunOptions};
use dermis::scene::camera::Camera;
use dermis::scene::gltf_load::TextureOverrides;
use dermis::scene::layout::Layout;
use dermis::scene::{builtin_scene, load_gltf_scene, Scene};
use dermis::skin::kernel::{Preset, SeparableKernel};
use dermis::skin::transmittance::TransmittanceProfile;
use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

/// `--scene builtin:NAME` names a built-in scene instead of a file.
const BUILTIN: &str = "builtin:";

/// The frame's defaults: every render flag's default is read from here, so the
/// CLI and the library (tests, eval) cannot drift apart.
fn defaults() -> RenderSettings {
    RenderSettings::default()
}

#[derive(Parser)]
#[command(
    name = "dermis",
    version,
    about = "Real-time skin rendering (Vulkan) that measures every pass"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a frame: writes DIR/frame.png, DIR/diffuse.exr and DIR/report.json and prints the per-pass table.
    Render {
        #[command(flatten)]
        common: Common,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Also write every pass output as linear EXR under DIR/passes/.
        #[arg(long)]
        dump: bool,
        /// Also write DIR/characters.png (16-bit grey: 0 no skin, i+1 character i) from
        /// an extra pass after the frame (the frame's images are unchanged).
        #[arg(long)]
        character_ids: bool,
        /// Also write the measured frames' per-pass timeline (GPU timestamps, barriers
        /// as their own slices) as Chrome trace-event JSON, for Perfetto or chrome://tracing.
        #[arg(long, value_name = "FILE.json")]
        trace: Option<PathBuf>,
        #[arg(long, default_value_t = 3)]
        warmup: usize,
        #[arg(long, default_value_t = 10)]
        frames: usize,
    },
    /// Measure many frames and the device ceilings; writes the report only.
    Bench {
        #[command(flatten)]
        common: Common,
        /// Report path (JSON).
        #[arg(long, default_value = "out/bench.json")]
        report: PathBuf,
        /// Also write the measured frames' per-pass timeline (GPU timestamps, barriers
        /// as their own slices) as Chrome trace-event JSON, for Perfetto or chrome://tracing.
        #[arg(long, value_name = "FILE.json")]
        trace: Option<PathBuf>,
        #[arg(long, default_value_t = 20)]
        warmup: usize,
        #[arg(long, default_value_t = 100)]
        frames: usize,
    },
    /// Render the ground truth (brute-force integral over the skin surface): like
    /// `render --method reference`, writes frame.png, diffuse.exr and report.json.
    Reference {
        #[command(flatten)]
        common: Common,
        #[arg(long, default_value = "out/reference")]
        out: PathBuf,
    },
    /// Compare two render outputs (DIR with diffuse.exr, depth.exr, frame.png and
    /// report.json): relative RMSE of the linear diffuse over skin pixels (skin
    /// from B) and FLIP of the tone-mapped frames, over all skin and per band
    /// (interior, silhouette, depth steps); with --none also err/none and the
    /// per-channel gain. Writes error images, bands.png and compare.json into --out.
    Compare {
        /// The image under test.
        a: PathBuf,
        /// The reference.
        b: PathBuf,
        /// The no-SSS render of the same view (`render --method none`): err/none
        /// and the gains are relative to it.
        #[arg(long)]
        none: Option<PathBuf>,
        /// Where to write the error images (default: A).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Sweep every registered method and setting over a scene set against the
    /// ground truth: writes eval.csv, eval.json and the cost/error chart (PNG, SVG).
    Eval {
        #[command(flatten)]
        common: Common,
        #[arg(long, default_value = "out/eval")]
        out: PathBuf,
        /// Scene set: thesis (the Lee Perry-Smith head at the perceptual study's 3
        /// distances x 4 lights, plus the procedural scene), dolly (the head from 1 to
        /// 24 head heights in 12 steps; adds distance.png/svg, error against distance),
        /// quick (procedural only) or accuracy (the accuracy model's sweep: both heads at
        /// 8 scales x 4 lights; accuracy:scan, accuracy:procedural one head; writes
        /// ASSET.toml for profiles/accuracy/, the charts and the leave-one-scale-out error).
        #[arg(long, default_value = "thesis")]
        scenes: String,
        #[arg(long, default_value_t = 2)]
        warmup: usize,
        #[arg(long, default_value_t = 10)]
        frames: usize,
    },
    /// Score every anti-aliasing mode against a supersampled frame (issue 17, docs/aa.md):
    /// per view, the frame at FACTOR x FACTOR its size with the same camera and SSS method,
    /// tone-mapped and box-filtered in display-linear light, against each --aa mode's frame
    /// (relative RMSE and FLIP over the edge pixels and the whole frame). Writes
    /// aa-eval.json, aa-eval.csv, chart.png/svg (AA ms against error) and per view the
    /// reference, edge mask and frames as PNGs; prints the table.
    AaEval {
        #[command(flatten)]
        common: Common,
        #[arg(long, default_value = "out/aa-eval")]
        out: PathBuf,
        /// Views, comma-separated: head (the procedural face close and far; with --scene
        /// PATH.glb also that scan), crowd (--heads procedural faces, 9 when --heads is 1)
        /// and lines (builtin:lines, thin bars and a grid, at 1, 2 and 4 close-up distances).
        #[arg(long, default_value = "head,crowd,lines")]
        scenes: String,
        /// Samples per pixel per axis of the reference (1..=8).
        #[arg(long, default_value_t = dermis::eval::supersample::DEFAULT_FACTOR)]
        factor: u32,
        #[arg(long, default_value_t = 1)]
        warmup: usize,
        #[arg(long, default_value_t = 5)]
        frames: usize,
    },
    /// Price the frame on hardware budget profiles (profiles/*.toml): runs it on this
    /// device (lavapipe included) and again with the fetch-counting build, prints each
    /// pass's modelled ms, bound, eDRAM tiles and resolves, shares of the frame and of
    /// the skin budget beside the ms measured here, and writes DIR/budget.json,
    /// DIR/frames/METHOD.json and the stacked-bar chart DIR/budget.png and .svg.
    Budget {
        #[command(flatten)]
        common: Common,
        /// Profile name (profiles/NAME.toml) or path; several (repeated or comma-separated)
        /// price the same frame on each target side by side.
        #[arg(long = "profile", required = true, value_delimiter = ',')]
        profiles: Vec<String>,
        /// Run every registered method and chart their frames side by side.
        #[arg(long)]
        compare_methods: bool,
        #[arg(long, default_value = "out/budget")]
        out: PathBuf,
        /// Price at the run's resolution instead of rescaling the counts to the profile's.
        #[arg(long)]
        as_run: bool,
        /// Keep the declared fetch counts (skip the fetch-counting run).
        #[arg(long)]
        declared_fetches: bool,
        #[arg(long, default_value_t = 1)]
        warmup: usize,
        #[arg(long, default_value_t = 3)]
        frames: usize,
    },
    /// Choose a method setting per character under a skin-SSS budget on a profile (no
    /// device opens): prints the plan's table, writes DIR/plan.json (what `render --plan`
    /// reads) and a schematic of the plan, DIR/plan.png and .svg (docs/plan.md).
    Plan {
        #[command(flatten)]
        common: Common,
        /// Profile name (profiles/NAME.toml) or path.
        #[arg(long)]
        profile: String,
        /// The skin-SSS budget on the profile, in milliseconds.
        #[arg(long, allow_negative_numbers = true)]
        budget_ms: String,
        #[arg(long, default_value = "out/plan")]
        out: PathBuf,
    },
    /// Check plans against the ground truth (issue 16, docs/plan.md): for each scene and
    /// (profile, budget), plan, render the plan, the ground truth and every uniform
    /// assignment that fits, and score them; on a GPU also time each plan's skin SSS.
    /// Writes DIR/plan-check.json, .md and error-vs-budget charts.
    PlanCheck {
        #[command(flatten)]
        common: Common,
        /// Scenes, comma-separated: close (one close, eight in rows behind), crowd16,
        /// crowd64, grid, and single (the close character alone: the control).
        #[arg(long, default_value = "close,crowd16,crowd64,grid")]
        scenes: String,
        /// PROFILE:MS cases, comma-separated (default: 1, 2 and 4 ms on xbox360,
        /// switch-handheld and steam-deck; 0.25 and 0.5 ms on nvidia-h200).
        #[arg(long)]
        cases: Option<String>,
        /// Frames timed per plan after a warm-up (0: no timing, as on lavapipe), for the
        /// cases of --timed-profile; each plan's groups are also timed alone.
        #[arg(long, default_value_t = 0)]
        timed_frames: usize,
        /// The profile of the device the check runs on (whose predictions timing checks).
        #[arg(long, default_value = "nvidia-h200")]
        timed_profile: String,
        #[arg(long, default_value = "out/plan-check")]
        out: PathBuf,
    },
    /// Re-plan a crowd walking toward a fixed camera every frame, with hysteresis (issue 16
    /// item 6, docs/plan-over-time.md): renders each frame's plan and its ground truth,
    /// measures every switching character's frame-to-frame change against the truth's own,
    /// reports the plan's time per frame. Writes DIR/plan-motion.json, .png and .svg.
    PlanMotion {
        #[command(flatten)]
        common: Common,
        /// Profile name (profiles/NAME.toml) or path.
        #[arg(long)]
        profile: String,
        /// The skin-SSS budget on the profile, in milliseconds.
        #[arg(long, allow_negative_numbers = true)]
        budget_ms: String,
        /// Frames of the sequence (each renders the plan, the ground truth and no SSS).
        #[arg(long, default_value_t = 24)]
        frames: usize,
        /// Head heights the crowd walks toward the camera over the frames.
        #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
        walk_heads: f32,
        /// The err/none a character's switch must gain (0: no hysteresis).
        #[arg(long, default_value_t = dermis::plan::over_time::DEFAULT_MARGIN, allow_negative_numbers = true)]
        switch_margin: f64,
        /// Plan each frame against the costs of the next N frames too (0: its own).
        #[arg(long, default_value_t = 0)]
        look_ahead: usize,
        /// Cross-fade a switch on screen over N frames (0: switch at once).
        #[arg(long, default_value_t = dermis::plan::fades::DEFAULT_FADE_FRAMES)]
        fade_frames: usize,
        #[arg(long, default_value = "out/plan-motion")]
        out: PathBuf,
    },
    /// Print the separable SSS kernel (offsets in mm and RGB weights) as JSON.
    Kernel {
        #[arg(long, default_value_t = 17)]
        samples: usize,
        #[arg(long, value_enum, ignore_case = true, default_value_t = PresetArg::Table61)]
        preset: PresetArg,
        /// Override the preset's width (mm).
        #[arg(long)]
        width_mm: Option<f32>,
    },
    /// List the Vulkan devices.
    Devices {
        #[arg(long)]
        validate: bool,
    },
    /// List the SSS methods of the registry: names, aliases, summary, and each
    /// option's flag, default and help (what `--method` and the method flags take).
    Methods {
        /// Print the listing as JSON (what the scripts in tools/ read).
        #[arg(long)]
        json: bool,
    },
}

// The enum-like flags. Each mirrors a library enum, converted both ways by
// exhaustive matches (a variant added on either side fails to compile until
// the other has it); the defaults are the library's, read back through `From`.

/// `--aa`: the anti-aliasing after the tone map (`dermis::post`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum AaArg {
    /// None: the tone-mapped frame is the output.
    None,
    /// FXAA, quality preset: one full-screen pass.
    Fxaa,
    /// Jimenez's MLAA (thesis ch. 9): luma edges writing the stencil, then
    /// blending weights and neighbourhood blending on edge pixels only.
    Mlaa,
    /// SMAA 1x (thesis ch. 10.4.1-10.4.2), --smaa-preset (default high): edges with
    /// local contrast adaptation, diagonal patterns, accurate searches, sharp corners.
    Smaa,
}

impl From<AaArg> for AaMode {
    fn from(a: AaArg) -> Self {
        match a {
            AaArg::None => AaMode::None,
            AaArg::Fxaa => AaMode::Fxaa,
            AaArg::Mlaa => AaMode::Mlaa,
            AaArg::Smaa => AaMode::Smaa,
        }
    }
}

/// `--aa-edges`: what MLAA's or SMAA's first pass finds edges in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum AaEdgesArg {
    /// Luma of the gamma-encoded colour (both modes' default).
    Luma,
    /// The frame's linear view depth, 10 mm threshold (MLAA only: thesis ch. 9.3).
    Depth,
    /// The largest R, G or B difference (SMAA only: ch. 10.4.1).
    Color,
}

impl From<AaEdgesArg> for EdgeSource {
    fn from(a: AaEdgesArg) -> Self {
        match a {
            AaEdgesArg::Luma => EdgeSource::Luma,
            AaEdgesArg::Depth => EdgeSource::Depth,
            AaEdgesArg::Color => EdgeSource::Color,
        }
    }
}

/// `--smaa-preset`: SMAA's quality preset (SMAA.hlsl's).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum SmaaPresetArg {
    /// Threshold 0.15, 4 search steps, no diagonals or corners.
    Low,
    /// Threshold 0.1, 8 search steps, no diagonals or corners.
    Medium,
    /// Threshold 0.1, 16 search steps, diagonals 8, corner rounding 25 %.
    High,
    /// Threshold 0.05, 32 search steps, diagonals 16, corner rounding 25 %.
    Ultra,
}

impl From<SmaaPresetArg> for SmaaPreset {
    fn from(a: SmaaPresetArg) -> Self {
        match a {
            SmaaPresetArg::Low => SmaaPreset::Low,
            SmaaPresetArg::Medium => SmaaPreset::Medium,
            SmaaPresetArg::High => SmaaPreset::High,
            SmaaPresetArg::Ultra => SmaaPreset::Ultra,
        }
    }
}

/// `--sss-region`: where the SSS passes run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum SssRegionArg {
    /// The skin's projected bounds widened by the kernel's reach: seed copies
    /// and stencil-tested draws limited to them.
    Skin,
    /// The whole frame, as the demos run (kept to measure what the region
    /// saves). `screen`, its old name, is still accepted: "screen" names the
    /// screen-space methods.
    #[value(alias = "screen")]
    Frame,
}

impl From<SssRegionArg> for RegionMode {
    fn from(a: SssRegionArg) -> Self {
        match a {
            SssRegionArg::Skin => RegionMode::Skin,
            SssRegionArg::Frame => RegionMode::Screen,
        }
    }
}

impl From<RegionMode> for SssRegionArg {
    fn from(m: RegionMode) -> Self {
        match m {
            RegionMode::Skin => SssRegionArg::Skin,
            RegionMode::Screen => SssRegionArg::Frame,
        }
    }
}

/// `--layout`: how several characters stand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum LayoutArg {
    /// Rows receding from a fixed camera, as a game stages a crowd.
    Crowd,
    /// Side by side, the camera pulled back to fit them.
    Grid,
}

impl From<LayoutArg> for Layout {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Crowd => Layout::Crowd,
            LayoutArg::Grid => Layout::Grid,
        }
    }
}

impl From<Layout> for LayoutArg {
    fn from(l: Layout) -> Self {
        match l {
            Layout::Crowd => LayoutArg::Crowd,
            Layout::Grid => LayoutArg::Grid,
        }
    }
}

/// `--transmittance-profile`: which T(s) the transmittance term uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TransmittanceArg {
    /// Eq. 5.12 as published.
    #[value(alias = "eq5.12")]
    Thesis,
    /// The profile integrated over a plane: exp(-s^2 / 2v) (docs/accuracy.md).
    Integral,
}

impl From<TransmittanceArg> for TransmittanceProfile {
    fn from(a: TransmittanceArg) -> Self {
        match a {
            TransmittanceArg::Thesis => TransmittanceProfile::Thesis,
            TransmittanceArg::Integral => TransmittanceProfile::Integral,
        }
    }
}

impl From<TransmittanceProfile> for TransmittanceArg {
    fn from(p: TransmittanceProfile) -> Self {
        match p {
            TransmittanceProfile::Thesis => TransmittanceArg::Thesis,
            TransmittanceProfile::Integral => TransmittanceArg::Integral,
        }
    }
}

/// `dermis kernel --preset`: the separable kernel's named parameter sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum PresetArg {
    /// Table 6.1 of the thesis (width 3.22 mm).
    #[value(name = "table6.1", alias = "table61")]
    Table61,
    /// The original demo's look (width 2.76 mm).
    Demo,
    /// Each channel's marginal of the six-Gaussian profile (Table 4.2).
    Physical,
}

impl From<PresetArg> for Preset {
    fn from(a: PresetArg) -> Self {
        match a {
            PresetArg::Table61 => Preset::Table61,
            PresetArg::Demo => Preset::Demo,
            PresetArg::Physical => Preset::Physical,
        }
    }
}

impl From<Preset> for PresetArg {
    fn from(p: Preset) -> Self {
        match p {
            Preset::Table61 => PresetArg::Table61,
            Preset::Demo => PresetArg::Demo,
            Preset::Physical => PresetArg::Physical,
        }
    }
}

/// The views the shot, key light and ambient default to.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum View {
    /// The default picture: `RenderSettings::default()`, the portrait.
    Portrait,
    /// `RenderSettings::study()` at the mid shot: the tests' view and every
    /// recorded run's before issue 15.
    Study,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Shot {
    /// The default: a portrait, the head alone in frame with a little room
    /// (`render::settings::PORTRAIT_CLOSE_UPS` close-up distances).
    Portrait,
    /// The head fills the screen height.
    Close,
    /// Twice the close-up distance.
    Mid,
    /// Five times the close-up distance.
    Far,
}

#[derive(Args)]
struct Common {
    /// Vulkan device: index or case-insensitive name substring (default: first discrete GPU).
    #[arg(long)]
    device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation; any message fails the run.
    #[arg(long)]
    validate: bool,
    /// glTF/GLB scene, or builtin:face | builtin:egg | builtin:lines (default: the embedded procedural face).
    #[arg(long)]
    scene: Option<PathBuf>,
    #[arg(long)]
    albedo: Option<PathBuf>,
    #[arg(long)]
    normal_map: Option<PathBuf>,
    #[arg(long)]
    spec_map: Option<PathBuf>,
    /// Texture files beside the scene (or given above) are top-down; by default they
    /// are taken as bottom-up (OpenGL convention), as the Lee Perry-Smith head's are.
    #[arg(long)]
    sidecar_top_down: bool,
    /// Scene scale in millimetres per unit (default: from a 230 mm chin-to-crown head).
    #[arg(long)]
    mm_per_unit: Option<f32>,
    #[arg(long, default_value_t = defaults().width)]
    width: u32,
    #[arg(long, default_value_t = defaults().height)]
    height: u32,
    /// SSS method, by name or alias (`dermis methods` lists them with their options).
    #[arg(long, default_value_t = defaults().method.name.to_string())]
    method: String,
    /// A method per character: rules `SELECTOR=METHOD[:key=value...]`, comma-separated,
    /// the first match wins; SELECTOR is *, N, A-B (character indices) or dA-[B] (camera
    /// distance in head heights). E.g. 0=ssg:fit=4,1-8=separable:preset=physical,*=none.
    /// --method and the method flags are then ignored.
    #[arg(long, value_name = "RULES", conflicts_with = "plan")]
    assign: Option<String>,
    /// A method per character from a plan file (what `dermis plan` writes); --method and
    /// the method flags are then ignored.
    #[arg(long, value_name = "FILE.json")]
    plan: Option<PathBuf>,
    #[command(flatten)]
    method_options: MethodArgs,
    /// Transmittance T(s).
    #[arg(long, value_enum, ignore_case = true,
          default_value_t = TransmittanceArg::from(defaults().transmittance_profile))]
    transmittance_profile: TransmittanceArg,
    /// Where the SSS passes run.
    #[arg(long, value_enum, ignore_case = true,
          default_value_t = SssRegionArg::from(defaults().sss_region))]
    sss_region: SssRegionArg,
    /// Side of the SSS region's screen tiles in pixels (1..=1024): smaller hugs the
    /// skin closer but draws more rectangles.
    #[arg(long, default_value_t = defaults().sss_region_tile)]
    sss_region_tile: u32,
    #[arg(long)]
    no_transmittance: bool,
    /// Number of characters (multi-character stress).
    #[arg(long, default_value_t = defaults().heads)]
    heads: u32,
    /// How several characters stand.
    #[arg(long, value_enum, ignore_case = true,
          default_value_t = LayoutArg::from(defaults().layout))]
    layout: LayoutArg,
    /// The view the shot, key light and ambient default to: portrait (the
    /// default picture, `RenderSettings::default()`) or study (the fixed view of
    /// the tests and of every run recorded before issue 15,
    /// `RenderSettings::study()` at the mid shot). --shot, --light-azimuth,
    /// --light-elevation and --ambient override it.
    #[arg(long, value_enum, default_value_t = View::Portrait)]
    view: View,
    /// Camera shot (ignored when --distance is given) [default: portrait, or mid
    /// with --view study].
    #[arg(long, value_enum)]
    shot: Option<Shot>,
    /// Camera distance from the head centre in head heights.
    #[arg(long)]
    distance: Option<f32>,
    /// Move every character this many head heights toward the camera after the layout is
    /// placed at --distance (a frame of `plan-motion`'s walk: its plans/frame-KKK.json
    /// says how far; `plan-motion` walks its own).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    crowd_walked: f32,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = defaults().fovy_deg)]
    fovy: f32,
    /// Key light azimuth in degrees (0 = from the camera side, positive toward the
    /// viewer's right) [default: the --view's].
    #[arg(long, allow_negative_numbers = true)]
    light_azimuth: Option<f32>,
    /// Key light elevation in degrees above the horizon [default: the --view's].
    #[arg(long, allow_negative_numbers = true)]
    light_elevation: Option<f32>,
    #[arg(long, default_value_t = defaults().light.intensity)]
    light_intensity: f32,
    /// Constant ambient irradiance [default: the --view's].
    #[arg(long)]
    ambient: Option<f32>,
    #[arg(long, default_value_t = defaults().exposure)]
    exposure: f32,
    #[arg(long, default_value_t = defaults().shadow_size)]
    shadow_size: u32,
    /// Anti-aliasing of the tone-mapped frame (its passes are timed and priced like
    /// every other pass).
    #[arg(long, value_enum, ignore_case = true, default_value_t = AaArg::None)]
    aa: AaArg,
    /// Bloom on the HDR composite before the tone map: a 4-level Gaussian pyramid
    /// mixed in at 10 % (docs/aa.md, "Bloom"); off by default.
    #[arg(long)]
    bloom: bool,
    /// What MLAA's or SMAA's edge pass reads [default: luma]; an error with another
    /// --aa.
    #[arg(long, value_enum, ignore_case = true)]
    aa_edges: Option<AaEdgesArg>,
    /// SMAA's quality preset [default: high]; an error without --aa smaa.
    #[arg(long, value_enum, ignore_case = true)]
    smaa_preset: Option<SmaaPresetArg>,
    /// Multisampling of the geometry pass: 1, 2, 4 or 8 samples per pixel, resolved
    /// before the SSS passes (1: none; the device must support the count).
    #[arg(long, default_value_t = defaults().msaa)]
    msaa: u32,
}

/// The options every registered method declares, one flag each, added from the
/// registry: a new method's options appear here without touching this file.
struct MethodArgs(MethodOptions);

impl clap::FromArgMatches for MethodArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut o = MethodOptions::default();
        for (_, spec) in all_options() {
            match spec.kind {
                OptKind::Value => {
                    if let Some(v) = m.get_one::<String>(spec.key) {
                        o.set(spec.key, v.clone());
                    }
                }
                OptKind::NoFlag => {
                    if m.get_flag(spec.key) {
                        o.set(spec.key, "false");
                    }
                }
            }
        }
        Ok(MethodArgs(o))
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl Args for MethodArgs {
    fn augment_args(mut cmd: clap::Command) -> clap::Command {
        for (method, spec) in all_options() {
            let help = format!("[{}] {}", method.name, spec.help);
            let arg = Arg::new(spec.key).long(spec.flag()).help(help);
            cmd = cmd.arg(match spec.kind {
                OptKind::Value => arg
                    .action(ArgAction::Set)
                    .allow_negative_numbers(true)
                    .value_name("VALUE"),
                OptKind::NoFlag => arg.action(ArgAction::SetTrue),
            });
        }
        cmd
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl Common {
    fn settings(&self) -> Result<RenderSettings> {
        let close = Camera::close_up_distance_heads(self.fovy);
        let (base, base_shot) = match self.view {
            View::Portrait => (defaults(), Shot::Portrait),
            View::Study => (RenderSettings::study(), Shot::Mid),
        };
        let distance = self
            .distance
            .unwrap_or(match self.shot.unwrap_or(base_shot) {
                Shot::Portrait => dermis::render::settings::PORTRAIT_CLOSE_UPS * close,
                Shot::Close => close,
                Shot::Mid => 2.0 * close,
                Shot::Far => 5.0 * close,
            });
        let assignment = match (&self.assign, &self.plan) {
            (Some(rules), _) => Some(Assignment::Rules(rules.parse()?)),
            (None, Some(path)) => Some(Assignment::Plan(PlanFile::load(path)?)),
            (None, None) => None,
        };
        let mut s = RenderSettings {
            width: self.width,
            height: self.height,
            assignment,
            method: lookup(&self.method)?,
            options: self.method_options.0.clone(),
            transmittance: !self.no_transmittance,
            sss_region: self.sss_region.into(),
            sss_region_tile: self.sss_region_tile,
            transmittance_profile: self.transmittance_profile.into(),
            heads: self.heads,
            layout: self.layout.into(),
            distance_heads: distance,
            fovy_deg: self.fovy,
            walk_heads: self.crowd_walked,
            ..base.clone()
        };
        s.light.azimuth_deg = self.light_azimuth.unwrap_or(base.light.azimuth_deg);
        s.light.elevation_deg = self.light_elevation.unwrap_or(base.light.elevation_deg);
        s.light.intensity = self.light_intensity;
        s.ambient = self.ambient.unwrap_or(base.ambient);
        s.exposure = self.exposure;
        s.shadow_size = self.shadow_size;
        s.aa = self.aa.into();
        s.post.bloom = self.bloom;
        s.post.aa_edges = self.aa_edges.map(Into::into);
        s.post.smaa_preset = self.smaa_preset.map(Into::into);
        s.msaa = self.msaa;
        // Checked again against the device limits once a device is open.
        s.validate(u32::MAX)?;
        Ok(s)
    }

    fn scene(&self) -> Result<Scene> {
        let builtin_name = self
            .scene
            .as_ref()
            .and_then(|p| p.to_str())
            .and_then(|p| p.strip_prefix(BUILTIN));
        let overrides = TextureOverrides {
            albedo: self.albedo.clone(),
            normal_map: self.normal_map.clone(),
            specular_map: self.spec_map.clone(),
            sidecar_top_down: self.sidecar_top_down,
        };
        match (&self.scene, builtin_name) {
            (Some(p), None) => load_gltf_scene(p, &overrides, self.mm_per_unit),
            (_, name) => builtin_scene(name.unwrap_or("face"), &overrides, self.mm_per_unit),
        }
    }

    fn context_desc(&self) -> ContextDesc {
        ContextDesc {
            device: self
                .device
                .as_deref()
                .map(|d| d.parse::<DeviceChoice>().unwrap_or_default())
                .unwrap_or_default(),
            validate: self.validate,
            ..Default::default()
        }
    }

    fn context(&self) -> Result<Context> {
        Context::new(&self.context_desc())
    }
}

fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

/// Says which given options the chosen method does not read.
fn warn_foreign(s: &RenderSettings) {
    // With --assign/--plan no --method is read (ignored_options says so).
    if s.assignment.is_some() {
        return;
    }
    for f in foreign_options(s.method, &s.options) {
        eprintln!("note: {f} does not apply to --method {}", s.method.name);
    }
}

/// `dermis plan-motion`: every argument checked (one line each) before the
/// scene loads and the device opens.
fn plan_motion(
    common: &Common,
    profile: &str,
    budget_ms: &str,
    (frames, walk_heads): (usize, f32),
    (switch_margin, look_ahead, fade_frames): (f64, usize, usize),
    out: &Path,
) -> Result<()> {
    use dermis::plan::{cli::PlanArgs, measured::Measured, motion, over_time};
    let args = PlanArgs::parse(profile, budget_ms, out)?;
    let walk = over_time::Walk::new(frames, walk_heads)?;
    over_time::check_margin(switch_margin)?;
    dermis::plan::fades::check_fade_frames(fade_frames)?;
    if look_ahead >= frames {
        anyhow::bail!("--look-ahead {look_ahead} must be under --frames {frames}");
    }
    let base = common.settings()?;
    let scene = common.scene()?;
    dermis::output::prepare_out_dir(out)?;
    let acc = Measured::load_default(Measured::asset_of(common.scene.as_deref()))?;
    let ctx = common.context()?;
    let r = motion::run(
        &ctx,
        &motion::MotionOptions {
            base,
            scene: &scene,
            accuracy: &acc,
            accuracy_source: acc.source(),
            profile: args.profile,
            budget_ms: args.budget_ms,
            walk,
            switch_margin,
            look_ahead,
            fade_frames,
            out,
        },
    )?;
    print!("{}", motion::summary(&r));
    println!("wrote {}", out.join("plan-motion.json").display());
    Ok(())
}

// Long because it is the one dispatch of every subcommand: each arm
// destructures its options and makes one call or a few lines.
fn main_result() -> Result<()> {
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Some((name, sub)) = matches.subcommand() {
        for note in ignored_options(name, sub) {
            eprintln!("note: {note}");
        }
    }
    match cli.command {
        Command::Render {
            common,
            out,
            dump,
            character_ids,
            trace,
            warmup,
            frames,
        } => {
            dermis::run::check_frame_counts(warmup, frames)?;
            let settings = RenderSettings {
                character_ids,
                ..common.settings()?
            };
            warn_foreign(&settings);
            render(
                &common,
                settings,
                &out,
                dump,
                trace.as_deref(),
                warmup,
                frames,
            )?;
        }
        Command::Reference { common, out } => {
            let settings = RenderSettings {
                method: ground_truth(),
                // --assign/--plan are ignored here (a note says so).
                assignment: None,
                ..common.settings()?
            };
            warn_foreign(&settings);
            render(&common, settings, &out, false, None, 0, 1)?;
        }
        Command::Compare { a, b, none, out } => {
            let out = out.unwrap_or_else(|| a.clone());
            let c = study::compare(&a, &b, none.as_deref(), &out)?;
            print!("{}", study::comparison_table(&c));
            println!("error images and compare.json in {}", out.display());
        }
        Command::Eval {
            common,
            out,
            scenes,
            warmup,
            frames,
        } => eval(&common, &out, &scenes, warmup, frames)?,
        Command::AaEval {
            common,
            out,
            scenes,
            factor,
            warmup,
            frames,
        } => aa_eval(&common, &out, &scenes, factor, (warmup, frames))?,
        Command::Bench {
            common,
            report,
            trace,
            warmup,
            frames,
        } => bench(&common, &report, trace.as_deref(), warmup, frames)?,
        Command::Budget {
            common,
            profiles,
            compare_methods,
            out,
            as_run,
            declared_fetches,
            warmup,
            frames,
        } => {
            let opts = BudgetOptions {
                profiles,
                compare_methods,
                out,
                warmup,
                measured: frames,
                rescale: if as_run {
                    Rescale::AsRun
                } else {
                    Rescale::ToProfile
                },
                count_fetches: !declared_fetches,
                print: true,
                command: command_line(),
            };
            budget(&common, &opts)?;
        }
        Command::Plan {
            common,
            profile,
            budget_ms,
            out,
        } => dermis::plan::cli::command(
            &profile,
            &budget_ms,
            &out,
            common.scene.as_deref(),
            || common.settings(),
            || common.scene(),
        )?,
        Command::PlanCheck {
            common,
            scenes,
            cases,
            timed_frames,
            timed_profile,
            out,
        } => {
            use dermis::plan::{check, measured::Measured};
            let scenes = check::pick_scenes(&scenes)?;
            let cases = match cases {
                Some(c) => check::parse_cases(&c)?,
                None => check::cases(),
            };
            let base = common.settings()?;
            let scene = common.scene()?;
            dermis::output::prepare_out_dir(&out)?;
            let acc = Measured::load_default(Measured::asset_of(common.scene.as_deref()))?;
            let ctx = common.context()?;
            let r = check::run(
                &ctx,
                &check::CheckOptions {
                    base,
                    scene: &scene,
                    accuracy: &acc,
                    accuracy_source: acc.source(),
                    scenes,
                    cases,
                    timed_frames,
                    timed_profile,
                    out: &out,
                },
            )?;
            print!("{}", check::markdown(&r));
            println!("wrote {}", out.join("plan-check.json").display());
        }
        Command::PlanMotion {
            common,
            profile,
            budget_ms,
            frames,
            walk_heads,
            switch_margin,
            look_ahead,
            fade_frames,
            out,
        } => plan_motion(
            &common,
            &profile,
            &budget_ms,
            (frames, walk_heads),
            (switch_margin, look_ahead, fade_frames),
            &out,
        )?,
        Command::Kernel {
            samples,
            preset,
            width_mm,
        } => {
            let preset = Preset::from(preset);
            let mut params = preset.params();
            if let Some(w) = width_mm {
                params.width_mm = w;
            }
            params.validate()?;
            let k = SeparableKernel::build(params, samples)?;
            println!(
                "{}",
                serde_json::to_string_pretty(
                    &serde_json::json!({ "preset": preset.name(), "samples": samples, "kernel": k })
                )?
            );
        }
        Command::Devices { validate } => {
            let ctx = Context::new(&ContextDesc {
                device: DeviceChoice::Auto,
                validate,
                ..Default::default()
            })?;
            let devices = ctx.devices();
            for (i, name, kind) in ctx.finish_with(devices)? {
                println!("{i}: {name} ({kind})");
            }
        }
        Command::Methods { json } => {
            if json {
                println!("{}", serde_json::to_string_pretty(&listing())?);
            } else {
                print!("{}", listing_text());
            }
        }
    }
    Ok(())
}

/// `dermis eval`: the sweep, its summary table and the files it wrote.
fn eval(common: &Common, out: &Path, scenes: &str, warmup: usize, frames: usize) -> Result<()> {
    dermis::run::check_frame_counts(warmup, frames)?;
    // --assign/--plan are ignored by eval (a note says so).
    let base = RenderSettings {
        assignment: None,
        ..common.settings()?
    };
    let specs = study::scene_set(scenes, common.scene.as_deref(), &base)?;
    dermis::output::prepare_out_dir(out)?;
    let ctx = common.context()?;
    let opts = sweep::EvalOptions {
        base,
        warmup,
        measured: frames,
        progress: true,
    };
    let outcome = study::eval(&ctx, &specs, &opts, out, &command_line(), scenes == "dolly");
    let outcome = ctx.finish_with(outcome)?;
    print!("{}", sweep::summary_table(&outcome.summary));
    let names: Vec<String> = outcome
        .files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    println!("wrote {} in {}", names.join(", "), out.display());
    Ok(())
}

/// `dermis aa-eval`: every AA mode against the supersampled frame.
fn aa_eval(
    common: &Common,
    out: &Path,
    scenes: &str,
    factor: u32,
    (warmup, frames): (usize, usize),
) -> Result<()> {
    use dermis::eval::{aa_eval, supersample};
    dermis::run::check_frame_counts(warmup, frames)?;
    let base = RenderSettings {
        assignment: None,
        ..common.settings()?
    };
    warn_foreign(&base);
    // Checked against the device's limit too once it is open (`aa_eval::reference`).
    supersample::check_supersampled(
        base.width,
        base.height,
        factor,
        dermis::scene::MAX_IMAGE_SIDE,
    )?;
    // A glTF --scene is the scan the head views add; a built-in one adds nothing.
    let head = common
        .scene
        .as_deref()
        .filter(|p| !p.to_str().is_some_and(|s| s.starts_with(BUILTIN)));
    let crowd = if base.heads > 1 {
        base.heads
    } else {
        aa_eval::DEFAULT_CROWD
    };
    let specs = aa_eval::scene_set(scenes, head, crowd, base.fovy_deg)?;
    dermis::output::prepare_out_dir(out)?;
    let ctx = common.context()?;
    let opts = aa_eval::AaEvalOptions {
        base,
        factor,
        warmup,
        measured: frames,
        progress: true,
        images: Some(out.join("views")),
    };
    let result = aa_eval::sweep(&ctx, &specs, &opts).and_then(|rows| {
        let files = aa_eval::write(&ctx, &rows, &specs, &opts, &command_line(), out)?;
        Ok((rows, files))
    });
    let (rows, files) = ctx.finish_with(result)?;
    print!("{}", aa_eval::table(&rows));
    let names: Vec<String> = files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    println!("wrote {} and views/ in {}", names.join(", "), out.display());
    Ok(())
}

/// `dermis bench`: many frames and the device ceilings, the report only.
fn bench(
    common: &Common,
    report: &Path,
    trace: Option<&Path>,
    warmup: usize,
    frames: usize,
) -> Result<()> {
    dermis::run::check_frame_counts(warmup, frames)?;
    dermis::output::prepare_file(report)?;
    if let Some(t) = trace {
        dermis::output::prepare_file(t)?;
    }
    let settings = common.settings()?;
    warn_foreign(&settings);
    let scene = common.scene()?;
    dermis::render::groups::group_specs(&scene, &settings)?;
    let ctx = common.context()?;
    let opts = RunOptions {
        warmup,
        measured: frames,
        capture: false,
        dump: false,
        ceilings: true,
        command: command_line(),
        progress: true,
    };
    let r = bench_run(&ctx, &scene, &settings, &opts, report);
    let out = ctx.finish_with(r)?;
    if let Some(t) = trace {
        dermis::trace::write(t, &out.report, &out.frames)?;
    }
    let r = out.report;
    println!("{}", header(&r));
    print!("{}", dermis::report::table(&r.passes, r.frame.as_ref()));
    if let Some(c) = &r.ceilings {
        println!("{}", c.summary());
    }
    println!("wrote {}", report.display());
    if let Some(t) = trace {
        println!("wrote {} (open it in ui.perfetto.dev)", t.display());
    }
    Ok(())
}

fn render(
    common: &Common,
    settings: RenderSettings,
    out: &std::path::Path,
    dump: bool,
    trace: Option<&Path>,
    warmup: usize,
    frames: usize,
) -> Result<()> {
    dermis::output::prepare_render_dir(out, dump)?;
    if let Some(t) = trace {
        dermis::output::prepare_file(t)?;
    }
    let scene = common.scene()?;
    dermis::render::groups::group_specs(&scene, &settings)?;
    let ctx = common.context()?;
    let opts = RunOptions {
        warmup,
        measured: frames,
        capture: true,
        dump,
        ceilings: false,
        command: command_line(),
        progress: true,
    };
    let r = render_to_dir(&ctx, &scene, &settings, out, &opts);
    let output = ctx.finish_with(r)?;
    if let Some(t) = trace {
        dermis::trace::write(t, &output.report, &output.frames)?;
    }
    let r = output.report;
    println!("{}", header(&r));
    print!("{}", dermis::report::table(&r.passes, r.frame.as_ref()));
    print!("{}", dermis::report::groups_table(&r.groups));
    println!(
        "wrote {}, {} and {}",
        out.join("frame.png").display(),
        out.join("diffuse.exr").display(),
        out.join("report.json").display()
    );
    if let Some(t) = trace {
        println!("wrote {} (open it in ui.perfetto.dev)", t.display());
    }
    Ok(())
}

fn budget(common: &Common, opts: &BudgetOptions) -> Result<()> {
    let settings = common.settings()?;
    if !opts.compare_methods {
        warn_foreign(&settings);
    }
    let scene = common.scene()?;
    dermis::render::groups::group_specs(&scene, &settings)?;
    let r = dermis::budget::run::budget(&common.context_desc(), &scene, &settings, opts)?;
    println!(
        "priced {} method(s) on {} profile(s); wrote budget.json, frames/, budget.png and budget.svg in {}",
        r.runs.len(),
        r.profiles.len(),
        opts.out.display()
    );
    Ok(())
}

/// The options a command was given on its command line and does not read,
/// each named in a note (their values are still checked), so a command line
/// never silently means less than it says.
fn ignored_options(command: &str, m: &ArgMatches) -> Vec<String> {
    let given = |id: &str| {
        matches!(m.try_contains_id(id), Ok(true))
            && m.value_source(id) == Some(clap::parser::ValueSource::CommandLine)
    };
    let mut notes = Vec::new();
    if given("shot") && given("distance") {
        notes.push("--shot is ignored: --distance gives the camera distance".to_string());
    }
    let method_ignored = match command {
        "reference" => Some("reference renders the ground truth"),
        "eval" => Some("eval sweeps every registered method"),
        "budget" if given("compare_methods") => Some("--compare-methods prices every method"),
        _ => None,
    };
    if command == "aa-eval" && given("aa") {
        notes.push("--aa is ignored: aa-eval runs every mode".to_string());
    }
    if command == "aa-eval" && given("msaa") {
        notes.push(
            "--msaa is ignored: aa-eval scores every MSAA count the device renders".to_string(),
        );
    }
    if let (Some(why), true) = (method_ignored, given("method")) {
        notes.push(format!("--method is ignored: {why}"));
    }
    let assigned = ["assign", "plan"].into_iter().find(|a| given(a));
    let assign_ignored = match command {
        "reference" => Some("reference renders the ground truth"),
        "eval" => Some("eval sweeps every registered method"),
        "budget" if given("compare_methods") => Some("--compare-methods prices every method"),
        _ => None,
    };
    match (assigned, assign_ignored) {
        (Some(a), Some(why)) => notes.push(format!("--{a} is ignored: {why}")),
        (Some(a), None) => {
            let why = format!("--{a} gives each character its method");
            if given("method") {
                notes.push(format!("--method is ignored: {why}"));
            }
            for (_, o) in all_options() {
                if given(o.key) {
                    notes.push(format!("--{} is ignored: {why}", o.flag()));
                }
            }
        }
        _ => {}
    }
    notes
}

fn main() -> ExitCode {
    match main_result() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line: the error and its causes.
            eprintln!("error: {}", format!("{e:#}").replace('\n', " | "));
            ExitCode::FAILURE
        }
    }
}
