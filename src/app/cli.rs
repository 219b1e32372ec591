//! The command line, as one clap tree: every subcommand's options, the frame
//! options they share ([`FrameArgs`]) and the method options the registry
//! adds ([`MethodArgs`]). The value enums are the library's own (each derives
//! `clap::ValueEnum` where it is defined): no mirror of them lives here. Each
//! subcommand runs in its own file beside this one.

use std::path::PathBuf;

use clap::{Arg, ArgAction, ArgMatches, Args, Parser, Subcommand, ValueEnum};

use crate::aa::edges::Preset as SmaaPreset;
use crate::method::{all_options, MethodOptions, OptKind};
use crate::post::{AaMode, EdgeSource};
use crate::ranges;
use crate::render::settings::{ShotPreset, Texturing};
use crate::render::RenderSettings;
use crate::scene::layout::Layout;
use crate::skin::kernel::Preset;
use crate::skin::transmittance::TransmittanceProfile;
use crate::view::region::RegionMode;
use crate::vk::context::DeviceChoice;

/// The frame's defaults: every render flag's default is read from here, so the
/// CLI and the library (tests, eval) cannot drift apart.
fn defaults() -> RenderSettings {
    RenderSettings::default()
}

/// A flag's help followed by its valid range (`crate::ranges`, their one owner).
fn with_range(help: &str, r: &ranges::Range) -> String {
    format!("{help} [range: {r}]")
}

#[derive(Parser, Debug)]
#[command(
    name = "dermis",
    version,
    about = "Real-time skin rendering (Vulkan) that measures every pass"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a frame: writes DIR/frame.png, DIR/diffuse.exr and DIR/report.json and prints the per-pass table.
    Render(RenderArgs),
    /// Measure many frames and the device ceilings; writes the report only.
    Bench(BenchArgs),
    /// Render the ground truth (brute-force integral over the skin surface): like
    /// `render --method reference`, writes frame.png, diffuse.exr and report.json.
    Reference(ReferenceArgs),
    /// Compare two render outputs (DIR with diffuse.exr, depth.exr, frame.png and
    /// report.json): relative RMSE of the linear diffuse over skin pixels (skin
    /// from B) and FLIP of the tone-mapped frames, over all skin and per band
    /// (interior, silhouette, depth steps); with --none also err/none and the
    /// per-channel gain. Writes error images, bands.png and compare.json into --out.
    Compare(CompareArgs),
    /// Sweep every registered method and setting over a scene set against the
    /// ground truth: writes eval.csv, eval.json and the cost/error chart (PNG, SVG).
    Eval(EvalArgs),
    /// Score every anti-aliasing mode against a supersampled frame (docs/aa.md):
    /// per view, the frame at FACTOR x FACTOR its size with the same camera and SSS method,
    /// tone-mapped and box-filtered in display-linear light, against each --aa mode's frame
    /// (relative RMSE and FLIP over the edge pixels and the whole frame). Writes
    /// aa-eval.json, aa-eval.csv, chart.png/svg (AA ms against error) and per view the
    /// reference, edge mask and frames as PNGs; prints the table.
    AaEval(AaEvalArgs),
    /// Price the frame on hardware budget profiles (profiles/*.toml, built into the
    /// binary): runs it on this device (lavapipe included) and again with the
    /// fetch-counting build, prints each pass's modelled ms, bound, eDRAM tiles and
    /// resolves, shares of the frame and of the skin budget beside the ms measured here,
    /// and writes DIR/budget.json, DIR/frames/METHOD.json and the stacked-bar chart
    /// DIR/budget.png and .svg.
    Budget(BudgetArgs),
    /// Choose a method setting per character under a skin-SSS budget on a profile (no
    /// device opens): prints the plan's table, writes DIR/plan.json (what `render --plan`
    /// reads) and a schematic of the plan, DIR/plan.png and .svg (docs/plan.md).
    Plan(PlanArgs),
    /// Check plans against the ground truth (docs/plan.md): for each scene and
    /// (profile, budget), plan, render the plan, the ground truth and every uniform
    /// assignment that fits, and score them; on a GPU also time each plan's skin SSS.
    /// Writes DIR/plan-check.json, .md and error-vs-budget charts.
    PlanCheck(PlanCheckArgs),
    /// Re-plan a crowd walking toward a fixed camera every frame, with hysteresis
    /// (docs/plan-over-time.md): renders each frame's plan and its ground truth,
    /// measures every switching character's frame-to-frame change against the truth's own,
    /// reports the plan's time per frame. Writes DIR/plan-motion.json, .png, .svg and
    /// every frame's plan under DIR/plans/.
    PlanMotion(PlanMotionArgs),
    /// Print the separable SSS kernel (offsets in mm and RGB weights) as JSON.
    Kernel(KernelArgs),
    /// List the Vulkan devices.
    Devices(DevicesArgs),
    /// List the SSS methods of the registry: names, aliases, summary, and each
    /// option's flag, default and help (what `--method` and the method flags take).
    Methods(MethodsArgs),
}

impl Command {
    /// The subcommand's name as typed.
    pub fn name(&self) -> &'static str {
        match self {
            Command::Render(_) => "render",
            Command::Bench(_) => "bench",
            Command::Reference(_) => "reference",
            Command::Compare(_) => "compare",
            Command::Eval(_) => "eval",
            Command::AaEval(_) => "aa-eval",
            Command::Budget(_) => "budget",
            Command::Plan(_) => "plan",
            Command::PlanCheck(_) => "plan-check",
            Command::PlanMotion(_) => "plan-motion",
            Command::Kernel(_) => "kernel",
            Command::Devices(_) => "devices",
            Command::Methods(_) => "methods",
        }
    }
}

/// Warm-up and measured frames.
#[derive(Args, Clone, Copy, Debug)]
pub struct Frames<const WARMUP: usize, const FRAMES: usize> {
    /// Frames rendered before the measured ones.
    #[arg(long, default_value_t = WARMUP, help = with_range("Frames rendered before the measured ones", &ranges::WARMUP))]
    pub warmup: usize,
    /// Frames measured.
    #[arg(long, default_value_t = FRAMES, help = with_range("Frames measured", &ranges::FRAMES))]
    pub frames: usize,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Output directory.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Also write every pass output as linear EXR under DIR/passes/.
    #[arg(long)]
    pub dump: bool,
    /// Also write DIR/characters.png (16-bit grey: 0 no skin, i+1 character i) from
    /// an extra pass after the frame (the frame's images are unchanged).
    #[arg(long)]
    pub character_ids: bool,
    /// Also write the measured frames' per-pass timeline (GPU timestamps, barriers
    /// as their own slices) as Chrome trace-event JSON, for Perfetto or chrome://tracing.
    #[arg(long, value_name = "FILE.json")]
    pub trace: Option<PathBuf>,
    #[command(flatten)]
    pub frames: Frames<3, 10>,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Report path (JSON).
    #[arg(long, default_value = "out/bench.json")]
    pub report: PathBuf,
    /// Also write the measured frames' per-pass timeline (GPU timestamps, barriers
    /// as their own slices) as Chrome trace-event JSON, for Perfetto or chrome://tracing.
    #[arg(long, value_name = "FILE.json")]
    pub trace: Option<PathBuf>,
    #[command(flatten)]
    pub frames: Frames<20, 100>,
}

#[derive(Args, Debug)]
pub struct ReferenceArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    #[arg(long, default_value = "out/reference")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test.
    pub a: PathBuf,
    /// The reference.
    pub b: PathBuf,
    /// The no-SSS render of the same view (`render --method none`): err/none
    /// and the gains are relative to it.
    #[arg(long)]
    pub none: Option<PathBuf>,
    /// Where to write the error images (default: A).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct EvalArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    #[arg(long, default_value = "out/eval")]
    pub out: PathBuf,
    /// Scene set: thesis (the Lee Perry-Smith head at the perceptual study's 3
    /// distances x 4 lights, plus the procedural scene), dolly (the head from 1 to
    /// 24 head heights in 12 steps; adds distance.png/svg, error against distance),
    /// quick (procedural only) or accuracy (the accuracy model's sweep: both heads at
    /// 8 scales x 4 lights; accuracy:scan, accuracy:procedural one head; writes
    /// ASSET.toml for profiles/accuracy/, the charts and the leave-one-scale-out error).
    #[arg(long, default_value = "thesis")]
    pub scenes: String,
    /// Sweep only these settings: METHOD (every eval setting of it) or METHOD/LABEL
    /// (one, its label as `dermis methods` lists it); repeatable. The ground truths
    /// and the no-SSS frame they are scored with are rendered as always.
    #[arg(long)]
    pub only: Vec<String>,
    /// Sweep every setting twice, with pre- and post-scatter texturing (whatever
    /// --texturing says), each scored against a ground truth that applies the albedo
    /// the same way; adds texturing.png/svg, the two side by side.
    #[arg(long)]
    pub compare_texturing: bool,
    #[command(flatten)]
    pub frames: Frames<2, 10>,
}

#[derive(Args, Debug)]
pub struct AaEvalArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    #[arg(long, default_value = "out/aa-eval")]
    pub out: PathBuf,
    /// Views, comma-separated: head (the procedural face close and far; with --scene
    /// PATH.glb also that scan), crowd (--heads procedural faces, 9 when --heads is 1)
    /// and lines (builtin:lines, thin bars and a grid, at 1, 2 and 4 close-up distances).
    #[arg(long, default_value = "head,crowd,lines")]
    pub scenes: String,
    /// Samples per pixel per axis of the reference (1..=8).
    #[arg(long, default_value_t = crate::eval::supersample::DEFAULT_FACTOR)]
    pub factor: u32,
    #[command(flatten)]
    pub frames: Frames<1, 5>,
}

#[derive(Args, Debug)]
pub struct BudgetArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Profile name (built into the binary; an unknown name's error lists them) or a
    /// TOML file's path; several (repeated or comma-separated) price the same frame on
    /// each target side by side.
    #[arg(long = "profile", required = true, value_delimiter = ',')]
    pub profiles: Vec<String>,
    /// Run every registered method and chart their frames side by side.
    #[arg(long)]
    pub compare_methods: bool,
    #[arg(long, default_value = "out/budget")]
    pub out: PathBuf,
    /// Price at the run's resolution instead of rescaling the counts to the profile's.
    #[arg(long)]
    pub as_run: bool,
    /// Keep the declared fetch counts (skip the fetch-counting run).
    #[arg(long)]
    pub declared_fetches: bool,
    #[command(flatten)]
    pub frames: Frames<1, 3>,
}

#[derive(Args, Debug)]
pub struct PlanArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Profile name (built into the binary) or a TOML file's path.
    #[arg(long)]
    pub profile: String,
    /// The skin-SSS budget on the profile, in milliseconds.
    #[arg(long, allow_negative_numbers = true)]
    pub budget_ms: String,
    #[arg(long, default_value = "out/plan")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct PlanCheckArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Scenes, comma-separated: close (one close, eight in rows behind), crowd16,
    /// crowd64, grid, and single (the close character alone: the control).
    #[arg(long, default_value = "close,crowd16,crowd64,grid")]
    pub scenes: String,
    /// PROFILE:MS cases, comma-separated (default: 1, 2 and 4 ms on xbox360,
    /// switch-handheld and steam-deck; 0.25 and 0.5 ms on nvidia-h200).
    #[arg(long)]
    pub cases: Option<String>,
    /// Frames timed per plan after a warm-up (0: no timing, as on lavapipe), for the
    /// cases of --timed-profile; each plan's groups are also timed alone.
    #[arg(long, default_value_t = 0)]
    pub timed_frames: usize,
    /// The profile of the device the check runs on (whose predictions timing
    /// checks); required with --timed-frames above 0.
    #[arg(long)]
    pub timed_profile: Option<String>,
    #[arg(long, default_value = "out/plan-check")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct PlanMotionArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Profile name (built into the binary) or a TOML file's path.
    #[arg(long)]
    pub profile: String,
    /// The skin-SSS budget on the profile, in milliseconds.
    #[arg(long, allow_negative_numbers = true)]
    pub budget_ms: String,
    /// Frames of the sequence (each renders the plan, the ground truth and no SSS).
    #[arg(long, default_value_t = 24)]
    pub frames: usize,
    /// Head heights the crowd walks toward the camera over the frames.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub walk_heads: f32,
    /// The err/none a character's switch must gain (0: no hysteresis).
    #[arg(long, default_value_t = crate::plan::over_time::DEFAULT_MARGIN, allow_negative_numbers = true)]
    pub switch_margin: f64,
    /// Plan each frame against the costs of the next N frames too (0: its own).
    #[arg(long, default_value_t = 0)]
    pub look_ahead: usize,
    /// Cross-fade a switch on screen over N frames (0: switch at once).
    #[arg(long, default_value_t = crate::plan::fades::DEFAULT_FADE_FRAMES)]
    pub fade_frames: usize,
    #[arg(long, default_value = "out/plan-motion")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct KernelArgs {
    #[arg(long, default_value_t = 17)]
    pub samples: usize,
    #[arg(long, value_enum, ignore_case = true, default_value_t = Preset::Table61)]
    pub preset: Preset,
    /// Override the preset's width (mm).
    #[arg(long)]
    pub width_mm: Option<f32>,
}

#[derive(Args, Debug)]
pub struct DevicesArgs {
    #[arg(long)]
    pub validate: bool,
}

#[derive(Args, Debug)]
pub struct MethodsArgs {
    /// Print the listing as JSON (what the scripts in tools/ read).
    #[arg(long)]
    pub json: bool,
    /// List instead the settings `dermis plan` chooses among (each eval
    /// setting of the six Gaussians, once per path where a method has two),
    /// with their options: what tools/plan_frames.sh stores frames for.
    #[arg(long)]
    pub planned: bool,
}

/// The views the shot, key light and ambient default to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum View {
    /// The default picture: `RenderSettings::default()`, the portrait.
    Portrait,
    /// `RenderSettings::study()` at the mid shot: the tests' view and every
    /// recorded run's before issue 15.
    Study,
}

/// The options of a frame, shared by every command that renders or plans one.
#[derive(Args, Clone, Debug)]
pub struct FrameArgs {
    /// Vulkan device: index, `auto` or case-insensitive name substring (default: the
    /// first discrete GPU; `dermis devices` lists them).
    #[arg(long)]
    pub device: Option<DeviceChoice>,
    /// Enable the Khronos validation layer with synchronization validation; any message fails the run.
    #[arg(long)]
    pub validate: bool,
    /// Every frame setting from a file: a report.json (its `settings`) or a
    /// settings file of that shape. No other frame option may be given with it.
    #[arg(long, value_name = "FILE.json")]
    pub settings: Option<PathBuf>,
    /// glTF/GLB scene, or builtin:face | builtin:egg | builtin:lines (default: the embedded procedural face).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    #[arg(long)]
    pub albedo: Option<PathBuf>,
    #[arg(long)]
    pub normal_map: Option<PathBuf>,
    #[arg(long)]
    pub spec_map: Option<PathBuf>,
    /// The skin's albedo from the two-layer skin model (thesis ch. 7) at a tone of the
    /// melanin axis, for a skin without an albedo texture (the built-in face).
    #[arg(long, value_enum, ignore_case = true)]
    pub skin_tone: Option<crate::scene::source::SkinTone>,
    /// Draw the skin without its expression wrinkles (thesis ch. 8: the built-in face's
    /// wrinkle maps, shown by the expression weights; a file's from its wrinkle maps).
    #[arg(long)]
    pub no_wrinkles: bool,
    /// The skin's Beckmann roughness per texel, m in red (a glTF --scene only).
    #[arg(long)]
    pub roughness_map: Option<PathBuf>,
    /// The skin's SSS strength per texel, a factor in red: 0 scatters nothing, as
    /// under a beard (thesis eq. 4.3-4.4; a glTF --scene only).
    #[arg(long)]
    pub sss_map: Option<PathBuf>,
    /// The skin's expression wrinkles (thesis ch. 8): a partial-derivative wrinkle
    /// normal map (x/z, y/z in red and green, 0.5 + 0.5 d), given with its two zone
    /// masks (Table 8.1's eight zones, four a mask); a glTF --scene only.
    #[arg(long)]
    pub wrinkle_map: Option<PathBuf>,
    /// The first wrinkle mask: red, green, blue, brown zones of Table 8.1 in RGBA.
    #[arg(long)]
    pub wrinkle_mask1: Option<PathBuf>,
    /// The second wrinkle mask: cyan, magenta, orange, grey zones in RGBA.
    #[arg(long)]
    pub wrinkle_mask2: Option<PathBuf>,
    /// Texture files beside the scene (or given above) are top-down; by default they
    /// are taken as bottom-up (OpenGL convention), as the Lee Perry-Smith head's are.
    #[arg(long)]
    pub sidecar_top_down: bool,
    /// Materials of a glTF scene that scatter, whatever their names or extras say:
    /// names or indices, comma-separated (the rule: docs/usage.md, materials).
    #[arg(long, value_name = "MATERIALS", value_delimiter = ',')]
    pub skin: Vec<String>,
    /// Materials of a glTF scene drawn without scattering (eyes, teeth, cloth...).
    #[arg(long, value_name = "MATERIALS", value_delimiter = ',')]
    pub not_skin: Vec<String>,
    /// Morph target weights, NAME=W comma-separated (the built-in face's expressions:
    /// joy, surprise, fear, anger, disgust, sad; a glTF's targets by name or index).
    #[arg(long, value_name = "NAME=W", value_delimiter = ',')]
    pub morph_weights: Vec<String>,
    /// Pose the scene's animation at this time: a glTF's clip, the built-in face's
    /// expressions (neutral to each of Table 8.1's and back, 2.5 s each), or, for a
    /// scene without animation, dermis's rigid turn and nod (4 s, looped).
    #[arg(long, value_name = "SECONDS", help = with_range("Pose the scene's animation at this time (a glTF's clip, the face's expressions, else a rigid turn and nod)", &ranges::TIME))]
    pub time: Option<f32>,
    /// Advance the animation this many seconds every frame (warm-up, measured and
    /// captured frames alike), from --time or 0: frame k is posed at time + k * step.
    #[arg(long, value_name = "SECONDS", help = with_range("Advance the animation this much every frame, from --time (or 0): frame k at time + k * step", &ranges::TIME_STEP))]
    pub time_step: Option<f32>,
    /// The glTF animation --time plays (default: the file's first). Not `--clip`:
    /// tsd's option of that name clips its unwrapped meshes.
    #[arg(long, value_name = "NAME", requires = "time")]
    pub animation: Option<String>,
    /// With --time and --heads: the seed each character's phase is drawn from
    /// (every character but the first plays the motion at its own phase; the same
    /// seed, the same crowd).
    #[arg(long, value_name = "SEED", requires = "time")]
    pub crowd_seed: Option<u64>,
    #[arg(long, help = with_range("Scene scale in millimetres per unit (default: from a 230 mm chin-to-crown head)", &ranges::MM_PER_UNIT))]
    pub mm_per_unit: Option<f32>,
    #[arg(long, default_value_t = defaults().width, help = with_range("Frame width", &ranges::WIDTH))]
    pub width: u32,
    #[arg(long, default_value_t = defaults().height, help = with_range("Frame height", &ranges::HEIGHT))]
    pub height: u32,
    /// SSS method, by name or alias (`dermis methods` lists them with their options).
    #[arg(long, default_value_t = defaults().method.name.to_string())]
    pub method: String,
    /// A method per character: rules `SELECTOR=METHOD[:key=value...]`, comma-separated,
    /// the first match wins; SELECTOR is *, N, A-B (character indices) or dA-[B] (camera
    /// distance in head heights). E.g. 0=ssg:fit=4,1-8=separable:preset=physical,*=none.
    /// --method and the method flags are then ignored.
    #[arg(long, value_name = "RULES", conflicts_with = "plan")]
    pub assign: Option<String>,
    /// A method per character from a plan file (what `dermis plan` writes); --method and
    /// the method flags are then ignored.
    #[arg(long, value_name = "FILE.json")]
    pub plan: Option<PathBuf>,
    #[command(flatten)]
    pub method_options: MethodArgs,
    /// Transmittance T(s).
    #[arg(long, value_enum, ignore_case = true, default_value_t = defaults().transmittance_profile)]
    pub transmittance_profile: TransmittanceProfile,
    /// Where the SSS passes run.
    #[arg(long, value_enum, ignore_case = true, default_value_t = defaults().sss_region)]
    pub sss_region: RegionMode,
    #[arg(long, default_value_t = defaults().sss_region_tile, help = with_range(
        "Side of the SSS region's screen tiles: smaller hugs the skin closer but draws more rectangles",
        &ranges::SSS_REGION_TILE))]
    pub sss_region_tile: u32,
    #[arg(long)]
    pub no_transmittance: bool,
    #[arg(long, default_value_t = defaults().heads, help = with_range("Number of characters (multi-character stress)", &ranges::HEADS))]
    pub heads: u32,
    /// How several characters stand.
    #[arg(long, value_enum, ignore_case = true, default_value_t = defaults().layout)]
    pub layout: Layout,
    /// The view the shot, key light and ambient default to: portrait (the
    /// default picture, `RenderSettings::default()`) or study (the fixed view of
    /// the tests and of every run recorded before issue 15,
    /// `RenderSettings::study()` at the mid shot). --shot, --light-azimuth,
    /// --light-elevation and --ambient override it.
    #[arg(long, value_enum, default_value_t = View::Portrait)]
    pub view: View,
    /// Camera shot (ignored when --distance is given) [default: portrait, or mid
    /// with --view study].
    #[arg(long, value_enum)]
    pub shot: Option<ShotPreset>,
    #[arg(long, help = with_range("Camera distance from the head centre", &ranges::DISTANCE))]
    pub distance: Option<f32>,
    /// Move every character this many head heights toward the camera after the layout is
    /// placed at --distance (a frame of `plan-motion`'s walk: its plans/frame-KKK.json
    /// says how far; `plan-motion` walks its own).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, help = with_range(
        "Move every character this many head heights toward the camera after the layout is \
         placed at --distance (a frame of `plan-motion`'s walk: its plans/frame-KKK.json says how far)",
        &ranges::CROWD_WALKED))]
    pub crowd_walked: f32,
    #[arg(long, default_value_t = defaults().fovy_deg, help = with_range("Vertical field of view", &ranges::FOVY))]
    pub fovy: f32,
    #[arg(long, allow_negative_numbers = true, help = with_range(
        "Key light azimuth (0 = from the camera side, positive toward the viewer's right) [default: the --view's]",
        &ranges::LIGHT_AZIMUTH))]
    pub light_azimuth: Option<f32>,
    #[arg(long, allow_negative_numbers = true, help = with_range(
        "Key light elevation above the horizon [default: the --view's]", &ranges::LIGHT_ELEVATION))]
    pub light_elevation: Option<f32>,
    #[arg(long, default_value_t = defaults().light.intensity, help = with_range("Key light intensity", &ranges::LIGHT_INTENSITY))]
    pub light_intensity: f32,
    #[arg(long, help = with_range("Constant ambient irradiance [default: the --view's]", &ranges::AMBIENT))]
    pub ambient: Option<f32>,
    #[arg(long, default_value_t = defaults().exposure, help = with_range("Exposure: a factor on linear light before the tone curve", &ranges::EXPOSURE))]
    pub exposure: f32,
    #[arg(long, default_value_t = defaults().shadow_size, help = with_range("Shadow map side", &ranges::SHADOW_SIZE))]
    pub shadow_size: u32,
    /// Anti-aliasing of the tone-mapped frame (its passes are timed and priced like
    /// every other pass).
    #[arg(long, value_enum, ignore_case = true, default_value_t = AaMode::None)]
    pub aa: AaMode,
    /// Bloom on the HDR composite before the tone map: a 4-level Gaussian pyramid
    /// mixed in at 10 % (docs/aa.md, "Bloom"); off by default.
    #[arg(long)]
    pub bloom: bool,
    /// What MLAA's or SMAA's edge pass reads [default: luma]; an error with another
    /// --aa.
    #[arg(long, value_enum, ignore_case = true)]
    pub aa_edges: Option<EdgeSource>,
    /// SMAA's quality preset [default: high]; an error without --aa smaa.
    #[arg(long, value_enum, ignore_case = true)]
    pub smaa_preset: Option<SmaaPreset>,
    /// Multisampling of the geometry pass: 1, 2, 4 or 8 samples per pixel, resolved
    /// before the SSS passes (1: none; the device must support the count).
    #[arg(long, default_value_t = defaults().msaa)]
    pub msaa: u32,
    /// Levels of detail: each character drawn with the coarsest simplified level of
    /// its meshes whose measured error covers at most this many pixels at its
    /// distance (0: the full meshes).
    #[arg(long, default_value_t = defaults().lod_pixels, help = with_range("Levels of detail: the error a character's simplified meshes may cover on screen (0: full meshes)", &ranges::LOD_PIXELS))]
    pub lod_pixels: f32,
    /// Where the albedo enters: pre (scattered with the light) or post (the light
    /// scattered alone, the albedo applied after: d'Eon and Luebke, thesis ch. 7.6).
    #[arg(long, value_enum, ignore_case = true, default_value_t = defaults().texturing)]
    pub texturing: Texturing,
}

/// The options every registered method declares, one flag each, added from the
/// registry: a new method's options appear here without touching this file.
#[derive(Clone, Debug, Default)]
pub struct MethodArgs(pub MethodOptions);

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
                OptKind::Flagged(flag) => {
                    if let Some(v) = m.get_one::<String>(flag) {
                        o.set(spec.key, v.clone());
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
            // A flagged option's id is its flag: its key is some command's own.
            let id = match spec.kind {
                OptKind::Flagged(flag) => flag,
                _ => spec.key,
            };
            let arg = Arg::new(id).long(spec.flag()).help(help);
            cmd = cmd.arg(match spec.kind {
                OptKind::Value | OptKind::Flagged(_) => arg
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

/// The long flag of the frame option (or method option) with clap id `id`.
pub fn flag(id: &str) -> String {
    let cmd = <FrameArgs as Args>::augment_args(clap::Command::new("frame"));
    let long = cmd
        .get_arguments()
        .find(|a| a.get_id() == id)
        .and_then(|a| a.get_long())
        .map(str::to_string);
    format!("--{}", long.unwrap_or_else(|| id.replace('_', "-")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_tree_is_consistent() {
        Cli::command().debug_assert();
    }

    // The defaults are the library's, read back through the library enums.
    #[test]
    fn frame_defaults_are_render_settings_default() {
        let cli = Cli::try_parse_from(["dermis", "render"]).unwrap();
        let Command::Render(r) = cli.command else {
            panic!("not render")
        };
        let d = RenderSettings::default();
        assert_eq!(r.frame.width, d.width);
        assert_eq!(r.frame.sss_region, d.sss_region);
        assert_eq!(r.frame.layout, d.layout);
        assert_eq!(r.frame.transmittance_profile, d.transmittance_profile);
        assert_eq!(r.frame.aa, d.aa);
        assert_eq!((r.frames.warmup, r.frames.frames), (3, 10));
        // The old spellings still parse.
        let cli = Cli::try_parse_from([
            "dermis",
            "render",
            "--sss-region",
            "screen",
            "--transmittance-profile",
            "eq5.12",
        ])
        .unwrap();
        let Command::Render(r) = cli.command else {
            panic!("not render")
        };
        assert_eq!(r.frame.sss_region, RegionMode::Screen);
        assert_eq!(r.frame.transmittance_profile, TransmittanceProfile::Thesis);
    }
}
