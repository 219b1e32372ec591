//! `dermis eval`: every registered method and quality setting swept over a
//! scene set against the ground truth, timed by the same run's timestamps;
//! writes eval.csv, eval.json (`eval::sweep::EvalReport`, read back typed),
//! the cost/error charts, for a dolly the error against distance, for the
//! accuracy sets the accuracy model's data.
//!
//! Each setting is scored against the ground truth of the profile it
//! approximates (`method::profile::approximated`): the six Gaussians' truth
//! always (its skin mask and bands serve every setting), Burley's too when a
//! setting needs it; eval.json's rows and summary then name the profile, the
//! summary prints each profile's settings apart and the chart draws Burley's
//! hollow, "[burley]" in the legend.
//!
//! Every view's every frame is checked before the first renders: the scenes
//! are loaded once each, and each (view, setting) is a `FrameRequest` made
//! up front, so a setting the sweep cannot render is one line before any
//! device opens, not an error in the middle of the sweep.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};

use super::cli::EvalArgs;
use super::request::{self, Given};
use crate::accuracy::Asset;
use crate::eval::bands::{bands, Band, BandErrors, BandInput};
use crate::eval::metrics::{flip_ldr, relative_rmse};
use crate::eval::pareto::{self, EvalPoint};
use crate::eval::sweep::{self, Config, EvalReport, EvalRow, SceneSpec};
use crate::eval::{accuracy_set, chart};
use crate::header::{command_line, RunHeader};
use crate::method::profile::{self, Profile};
use crate::method::{ground_truth, lookup, none};
use crate::output::paths::OutputPaths;
use crate::output::write_json;
use crate::render::request::CheckedSettings;
use crate::render::settings::Texturing;
use crate::render::{FrameRequest, RenderSettings};
use crate::report::device_header;
use crate::run::{run_request, FrameCounts, RunOptions};
use crate::scene::source::SceneSource;
use crate::scene::{default_scene, Scene};
use crate::vk::context::Context;

/// The default head scan beside the project (never copied into it).
pub const DEFAULT_HEAD: &str = "../shared/assets/lee-perry-smith/LeePerrySmith.glb";

/// The scene sets `--scenes` takes.
pub const SCENE_SETS: [&str; 6] = [
    "thesis",
    "dolly",
    "quick",
    "accuracy",
    "accuracy:scan",
    "accuracy:procedural",
];

/// The files eval writes into its folder (the accuracy sets' own beside them).
const FILES: [&str; 8] = [
    "eval.csv",
    "eval.json",
    "chart.png",
    "chart.svg",
    "distance.png",
    "distance.svg",
    "texturing.png",
    "texturing.svg",
];

/// The named scene sets of `eval`.
pub fn scene_set(name: &str, head: Option<&Path>, base: &RenderSettings) -> Result<Vec<SceneSpec>> {
    let head = || -> Result<PathBuf> {
        let head = head.map_or_else(|| PathBuf::from(DEFAULT_HEAD), Path::to_path_buf);
        if !head.exists() {
            bail!("the '{name}' scene set needs the head scan: {} not found (give --scene PATH.glb, or --scenes quick)", head.display());
        }
        Ok(head)
    };
    Ok(match name {
        "thesis" => sweep::thesis_scenes(Some(head()?)),
        "dolly" => sweep::dolly_scenes(head()?),
        "quick" => vec![SceneSpec {
            distance_heads: base.distance_heads,
            ..sweep::procedural_scene()
        }],
        // The accuracy model's sweep: both heads, or one.
        "accuracy" => accuracy_set::accuracy_scenes(
            &[(Asset::Scan, Some(head()?)), (Asset::Procedural, None)],
            base,
        )?,
        "accuracy:scan" => accuracy_set::accuracy_scenes(&[(Asset::Scan, Some(head()?))], base)?,
        "accuracy:procedural" => accuracy_set::accuracy_scenes(&[(Asset::Procedural, None)], base)?,
        other => bail!(
            "unknown scene set '{other}' (valid: {})",
            SCENE_SETS.join(", ")
        ),
    })
}

/// `dermis eval`.
pub fn run(a: &EvalArgs, given: &Given) -> Result<()> {
    let counts = FrameCounts::new(a.frames.warmup, a.frames.frames)?;
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    // --assign/--plan are ignored by eval (a note says so).
    let base = RenderSettings {
        assignment: None,
        ..settings
    };
    // The base frame's numbers before any scene loads (each view's frames
    // are checked again as the frames they are, below).
    CheckedSettings::new(base.clone())?;
    // A glTF --scene is the head of the sets that take one.
    let head = source.gltf().map(Path::to_path_buf);
    let specs = scene_set(&a.scenes, head.as_deref(), &base)?;
    // The accuracy sets measure the heads as they are stored; the other
    // sets load the head with the given textures and scale.
    let head_source = if a.scenes.starts_with("accuracy") {
        SceneSource::default()
    } else {
        // The views keep their scenes' own colours (a note says so).
        SceneSource {
            skin_tone: None,
            ..source.clone()
        }
    };
    let scenes = load_scenes(&specs, &head_source)?;
    let configs = sweep::select(sweep::registry(), &a.only)?;
    // --compare-texturing: the sweep once per texturing, each frame and its
    // truth alike.
    let (base, post) = if a.compare_texturing {
        let with = |texturing| RenderSettings {
            texturing,
            ..base.clone()
        };
        (with(Texturing::Pre), Some(with(Texturing::Post)))
    } else {
        (base, None)
    };
    let plan = plan_sweep(&specs, &scenes, &base, &configs)?;
    let post_plan = post
        .as_ref()
        .map(|b| plan_sweep(&specs, &scenes, b, &configs))
        .transpose()?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[])
        .prepare()?;
    let ctx = request::context(&a.frame)?;
    let outcome = sweep_and_write(
        &ctx,
        (&plan, post_plan.as_deref()),
        &base,
        counts,
        &a.out,
        a.scenes == "dolly",
    );
    let (summary, post_summary, files) = ctx.finish_with(outcome)?;
    if post_plan.is_some() {
        println!("pre-scatter texturing:");
    }
    print!("{}", sweep::summary_table(&summary));
    if post_plan.is_some() {
        println!("post-scatter texturing (the light scattered, the albedo applied after):");
        print!("{}", sweep::summary_table(&post_summary));
    }
    let names: Vec<String> = files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    println!("wrote {} in {}", names.join(", "), a.out.display());
    Ok(())
}

/// Each distinct scene of `specs`, loaded once (`None` path: the embedded
/// face; a file with `head`'s textures and scale).
pub fn load_scenes(
    specs: &[SceneSpec],
    head: &SceneSource,
) -> Result<Vec<(Option<PathBuf>, Scene)>> {
    let mut scenes: Vec<(Option<PathBuf>, Scene)> = Vec::new();
    for s in specs {
        if scenes.iter().any(|(p, _)| *p == s.gltf) {
            continue;
        }
        let scene = match &s.gltf {
            None => default_scene(),
            Some(p) => request::load_scene(&SceneSource {
                scene: Some(p.clone()),
                ..head.clone()
            })
            .with_context(|| format!("loading scene '{}'", s.name))?,
        };
        scenes.push((s.gltf.clone(), scene));
    }
    Ok(scenes)
}

/// One view of the sweep, every frame of it checked.
pub struct ViewPlan<'s> {
    pub spec: &'s SceneSpec,
    /// The six Gaussians' ground truth (its mask and bands serve every setting).
    pub reference: FrameRequest<'s>,
    /// Burley's ground truth, when a setting approximates Burley's profile.
    pub burley: Option<FrameRequest<'s>>,
    /// The no-SSS frame every err/none is relative to, when `none` is not
    /// among the configs (whose measured run is used then).
    pub none: Option<FrameRequest<'s>>,
    /// Each setting, the profile whose truth scores it, its frame.
    pub configs: Vec<(Config, Profile, FrameRequest<'s>)>,
}

/// Every view's frames as checked requests (each a one-line error naming
/// the view and the setting), before anything renders.
pub fn plan_sweep<'s>(
    specs: &'s [SceneSpec],
    scenes: &'s [(Option<PathBuf>, Scene)],
    base: &RenderSettings,
    configs: &[Config],
) -> Result<Vec<ViewPlan<'s>>> {
    specs
        .iter()
        .map(|spec| {
            let scene = &scenes
                .iter()
                .find(|(p, _)| *p == spec.gltf)
                .context("a view's scene was not loaded")?
                .1;
            let mut view = base.clone();
            view.distance_heads = spec.distance_heads;
            view.light.azimuth_deg = spec.azimuth_deg;
            view.light.elevation_deg = spec.elevation_deg;
            if let Some(f) = spec.fovy_deg {
                view.fovy_deg = f;
            }
            let on = |what: &str| format!("{what} on '{}'", spec.name);
            let frame = |s: RenderSettings, what: &str| {
                FrameRequest::new(scene, s).with_context(|| on(what))
            };
            let truth = |p: Profile| RenderSettings {
                method: ground_truth(),
                options: view.options.with(&[(profile::OPTION.key, p.name())]),
                ..view.clone()
            };
            let reference = frame(truth(Profile::SixGaussian), "the ground truth")?;
            let swept_none = configs.iter().any(|c| std::ptr::eq(c.method, none()));
            let none_frame = if swept_none {
                None
            } else {
                Some(frame(
                    RenderSettings {
                        method: none(),
                        ..view.clone()
                    },
                    "no SSS",
                )?)
            };
            let configs: Vec<(Config, Profile, FrameRequest)> = configs
                .iter()
                .map(|c| {
                    let what = format!("{} {}", c.method.name, c.setting.label);
                    let s = view.clone().with(c.method, c.setting.options);
                    let p =
                        profile::approximated(c.method, &s.options).with_context(|| on(&what))?;
                    Ok((*c, p, frame(s, &what)?))
                })
                .collect::<Result<_>>()?;
            let burley = configs
                .iter()
                .any(|(_, p, _)| *p == Profile::Burley)
                .then(|| frame(truth(Profile::Burley), "Burley's ground truth"))
                .transpose()?;
            Ok(ViewPlan {
                spec,
                reference,
                burley,
                none: none_frame,
                configs,
            })
        })
        .collect()
}

/// The sweep's progress: a bar on a terminal; without one (a device run's
/// log) the bar draws nothing, so a line per step tells where it is.
struct Progress {
    bar: indicatif::ProgressBar,
    log: bool,
    started: std::time::Instant,
}

impl Progress {
    fn new(total: usize) -> Progress {
        let bar = indicatif::ProgressBar::new(total as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg:<40} [{bar:30}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Progress {
            bar,
            log: !std::io::IsTerminal::is_terminal(&std::io::stderr()),
            started: std::time::Instant::now(),
        }
    }

    fn step(&self, view: &str, what: &str) {
        self.bar.set_message(format!("{view}: {what}"));
        if self.log {
            eprintln!(
                "eval: {} s, {}/{}: {view}: {what}",
                self.started.elapsed().as_secs(),
                self.bar.position(),
                self.bar.length().unwrap_or(0)
            );
        }
    }

    fn inc(&self) {
        self.bar.inc(1);
    }
}

/// Renders the sweep; one row per (view, config).
pub fn sweep(
    ctx: &Context,
    plan: &[ViewPlan],
    counts: FrameCounts,
    progress: bool,
) -> Result<Vec<EvalRow>> {
    let total: usize = plan
        .iter()
        .map(|v| v.configs.len() + 1 + v.burley.is_some() as usize)
        .sum();
    let bar = progress.then(|| Progress::new(total));
    let once = RunOptions::capture_once("eval");
    let measured = RunOptions {
        frames: counts,
        ..once.clone()
    };
    let mut rows = Vec::new();
    for view in plan {
        let spec = view.spec;
        let step = |what: &str| {
            if let Some(b) = &bar {
                b.step(&spec.name, what);
            }
        };
        step("reference");
        let reference = run_request(ctx, &view.reference, &once)?;
        let (fovy, mm_per_unit) = (reference.report.fovy_deg, reference.report.mm_per_unit);
        let reference = reference.capture.context("reference capture")?;
        let burley = match &view.burley {
            Some(f) => {
                step("reference profile=burley");
                let c = run_request(ctx, f, &once)?
                    .capture
                    .context("Burley's reference capture")?;
                if let Some(b) = &bar {
                    b.inc();
                }
                Some(c)
            }
            None => None,
        };
        let measure = |c: &Config, f: &FrameRequest| {
            step(&format!("{} {}", c.method.name, c.setting.label));
            run_request(ctx, f, &measured).with_context(|| {
                format!("{} {} on '{}'", c.method.name, c.setting.label, spec.name)
            })
        };
        // The no-SSS frame every err/none and gain is relative to: the `none`
        // config's own measured run when it is swept (rendered once, used
        // twice), else one captured frame.
        let none_at = view
            .configs
            .iter()
            .position(|(c, ..)| std::ptr::eq(c.method, none()));
        let mut none_run = none_at
            .map(|i| measure(&view.configs[i].0, &view.configs[i].2))
            .transpose()?;
        let none_diffuse = match (&none_run, &view.none) {
            (Some(out), _) => out
                .capture
                .as_ref()
                .context("no-SSS capture")?
                .diffuse
                .clone(),
            (None, Some(f)) => {
                run_request(ctx, f, &once)?
                    .capture
                    .context("no-SSS capture")?
                    .diffuse
            }
            (None, None) => bail!("no no-SSS frame was planned for '{}'", spec.name),
        };
        let mask: Vec<bool> = reference.diffuse.iter().map(|p| p[3] > 0.0).collect();
        let skin = mask.iter().filter(|&&m| m).count();
        let band_of = bands(&BandInput::for_view(
            (reference.width as usize, reference.height as usize),
            &mask,
            &reference.depth,
            fovy,
            mm_per_unit,
        ));
        if let Some(b) = &bar {
            b.inc();
        }
        for (i, (c, p, f)) in view.configs.iter().enumerate() {
            let out = match (none_at == Some(i)).then(|| none_run.take()).flatten() {
                Some(out) => out,
                None => measure(c, f)?,
            };
            let cap = out.capture.context("capture")?;
            // The truth of the setting's own profile (planned with it).
            let reference = match p {
                Profile::SixGaussian => &reference,
                Profile::Burley => burley
                    .as_ref()
                    .context("no Burley ground truth was planned")?,
            };
            let flip = flip_ldr(&cap.ldr, &reference.ldr, cap.width, cap.height)?;
            let band_errors = BandErrors::of(
                &cap.diffuse,
                &reference.diffuse,
                Some(&none_diffuse),
                &flip.error_map,
                &band_of,
            );
            // With no skin in view there is nothing to score.
            let rel_rmse = if skin > 0 {
                relative_rmse(&cap.diffuse, &reference.diffuse, &mask)?
            } else {
                0.0
            };
            rows.push(EvalRow {
                point: EvalPoint {
                    method: c.method.name.to_string(),
                    setting: c.setting.label.to_string(),
                    scene: spec.name.clone(),
                    gpu_ms: out.report.sss_total_ms.map_or(0.0, |s| s.median),
                    error: band_errors.interior.err_none.unwrap_or(0.0),
                },
                skin_pixels: skin,
                frame_ms: out.report.frame.map_or(0.0, |f| f.gpu_ms.median),
                rel_rmse_all_skin: rel_rmse,
                bands: band_errors,
                profile: *p,
                texturing: f.settings().texturing,
            });
            if let Some(b) = &bar {
                b.inc();
            }
        }
    }
    if let Some(b) = bar {
        b.bar.finish_and_clear();
    }
    Ok(rows)
}

/// Runs the sweep of `plan` (and of `post`, its post-scatter twin, with
/// `--compare-texturing`) and writes eval.csv, eval.json, chart.png/svg (for
/// a dolly, distance.png/svg; for the accuracy sets their data; with `post`,
/// texturing.png/svg) into `out`; returns the summaries (the post-scatter
/// one empty without `post`) and the files written.
// Long because each output follows the sweep in turn.
pub fn sweep_and_write(
    ctx: &Context,
    (plan, post): (&[ViewPlan], Option<&[ViewPlan]>),
    base: &RenderSettings,
    counts: FrameCounts,
    out: &Path,
    dolly: bool,
) -> Result<SweepOutcome> {
    let rows = sweep(ctx, plan, counts, true)?;
    let post_rows = match post {
        Some(p) => sweep(ctx, p, counts, true)?,
        None => Vec::new(),
    };
    let post_summary = sweep::summarise(&post_rows);
    let specs: Vec<SceneSpec> = plan.iter().map(|v| v.spec.clone()).collect();
    let specs = &specs;
    let command = command_line();
    let mut files = vec![out.join("eval.csv"), out.join("eval.json")];
    let all_rows: Vec<EvalRow> = rows.iter().chain(&post_rows).cloned().collect();
    sweep::write_csv(&files[0], &all_rows)?;
    let summary = sweep::summarise(&rows);
    // The ranking is made on the interior: the bands are shown beside it.
    let interior: Vec<EvalPoint> = summary.iter().map(|r| r.point(Band::Interior)).collect();
    let report = EvalReport {
        run: RunHeader::new(
            &command,
            device_header(ctx),
            (base.width, base.height),
            (counts.warmup(), counts.measured()),
        ),
        error: sweep::ERROR_DEFINITION.to_string(),
        scenes: specs.clone(),
        pareto_front: pareto::pareto_front(&interior)
            .iter()
            .map(|&i| summary[i].clone())
            .collect(),
        rows: all_rows,
        summary: summary.clone(),
        post_scatter_summary: post_summary.clone(),
    };
    write_json(&files[1], &report)?;
    let point = |r: &sweep::SummaryRow, band: Band| {
        let mut p = r.point(band);
        // Burley's settings (scored against Burley's truth) are their own
        // legend entries, drawn hollow.
        if !r.profile.is_six_gaussian() {
            p.method = chart::profile_label(&p.method, r.profile.name());
        }
        p
    };
    let panels: Vec<chart::Panel> = Band::ALL
        .iter()
        .map(|&band| chart::Panel {
            title: match band {
                Band::Interior => "interior (ranking, Pareto front)".into(),
                b => b.name().into(),
            },
            y_label: format!("err/none, {}", band.name()),
            points: summary
                .iter()
                .filter(|r| r.band(band).scenes > 0)
                .map(|r| point(r, band))
                .collect(),
            front: band == Band::Interior,
        })
        .filter(|p| !p.points.is_empty())
        .collect();
    chart::panel_chart(
        &panels,
        &format!(
            "SSS cost vs error relative to no SSS ({}, {} scene(s))",
            ctx.facts.name,
            specs.len()
        ),
        "GPU ms (SSS passes, median)",
        &out.join("chart.png"),
        &out.join("chart.svg"),
    )?;
    files.extend([out.join("chart.png"), out.join("chart.svg")]);
    if post.is_some() {
        // Each method's cost and interior error with the albedo scattered
        // (left) and applied after (right), on the same axes and markers.
        let panel = |title: &str, s: &[sweep::SummaryRow]| chart::Panel {
            title: title.into(),
            y_label: "err/none, interior".into(),
            points: s
                .iter()
                .filter(|r| r.interior.scenes > 0)
                .map(|r| point(r, Band::Interior))
                .collect(),
            front: true,
        };
        chart::panel_chart(
            &[
                panel("pre-scatter texturing", &summary),
                panel("post-scatter texturing", &post_summary),
            ],
            &format!(
                "Pre- against post-scatter texturing, each against its own truth ({}, {} scene(s))",
                ctx.facts.name,
                specs.len()
            ),
            "GPU ms (SSS passes, median)",
            &out.join("texturing.png"),
            &out.join("texturing.svg"),
        )?;
        files.extend([out.join("texturing.png"), out.join("texturing.svg")]);
    }
    if dolly {
        // Error against distance: where a distance-driven switch changes the
        // image, the line steps.
        let mut series: Vec<chart::Series> = Vec::new();
        for r in &rows {
            let p = &r.point;
            // The registry names the lines (`MethodEntry::dolly`).
            let drawn = lookup(&p.method).is_ok_and(|m| m.dolly.contains(&p.setting.as_str()));
            if !drawn {
                continue;
            }
            let Some(spec) = specs.iter().find(|s| s.name == p.scene) else {
                continue;
            };
            let label = format!("{} {}", p.method, p.setting);
            let point = (spec.distance_heads as f64, p.error);
            match series.iter_mut().find(|s| s.label == label) {
                Some(s) => s.points.push(point),
                None => series.push(chart::Series {
                    label,
                    points: vec![point],
                }),
            }
        }
        chart::series_chart(
            &series,
            &format!("SSS error along a dolly ({})", ctx.facts.name),
            "camera distance (head heights)",
            "err/none over the interior",
            &out.join("distance.png"),
            &out.join("distance.svg"),
        )?;
        files.extend([out.join("distance.png"), out.join("distance.svg")]);
    }
    if specs.iter().any(|s| s.accuracy.is_some()) {
        // The accuracy model's data, chart and leave-one-scale-out error.
        let header = crate::accuracy::data::Header {
            command: command.clone(),
            device: format!("{} ({})", ctx.facts.name, ctx.facts.driver),
            frame: format!(
                "{}x{}, the centre of the {}-row frame at {} deg vertical field of view (this frame's: {:.4} deg)",
                base.width,
                base.height,
                accuracy_set::REFERENCE_HEIGHT_PX,
                base.fovy_deg,
                specs.iter().find_map(|s| s.fovy_deg).unwrap_or(base.fovy_deg)
            ),
        };
        let rows = accuracy_set::rows_of(specs, &rows)?;
        let (loso, written) = accuracy_set::write(&rows, &header, out)?;
        println!("leave-one-scale-out prediction error (absolute err/none):\n{loso}");
        files.extend(written);
    }
    Ok((summary, post_summary, files))
}

/// What [`sweep_and_write`] returns: the summary, the post-scatter one
/// (empty without `--compare-texturing`) and the files written.
pub type SweepOutcome = (Vec<sweep::SummaryRow>, Vec<sweep::SummaryRow>, Vec<PathBuf>);
