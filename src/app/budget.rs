//! `dermis budget`: runs the frame on whatever device is present (lavapipe
//! included), runs it again pass by pass with the fetch-counting build of its
//! shaders, builds the model's frame from the run's report (`record`), prices
//! it on every profile asked for, and writes `budget.json`, one frame file per
//! method (`frames/METHOD.json`: what calibration stores) and the stacked-bar
//! chart (`budget.png`, `budget.svg`). Counts (samples passed, fetches) do not
//! depend on the device's speed, so lavapipe prices a frame as well as a GPU.
//! The profiles are loaded and every frame priced is checked before any
//! device opens.

use std::path::PathBuf;

use anyhow::{Context as _, Result};
use serde::Serialize;

use super::cli::BudgetArgs;
use super::request::{self, Given};
use crate::header::{command_line, RunHeader};
use crate::output::paths::{OutputPaths, Owned};
use crate::render::request::CheckedSettings;
use crate::render::FrameRequest;
use crate::report::device_header;
use crate::run::{run_request, FrameCounts};

use crate::budget::chart::{budget_chart, Bar, Panel};
use crate::budget::input::{FrameInput, RESCALE_RULE};
use crate::budget::model::{price_frame, FrameBudget, Rescale, COMBINING_RULE};
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;
use crate::budget::record::{frame_from_record, CountedPass, FRAGMENTS_RULE};
use crate::budget::table::budget_table;
use crate::graph::work::Work;
use crate::method::METHODS;
use crate::output::write_json;
use crate::render::counting::{decode_site, PassCounts};
use crate::render::groups::MIX_NAME;
use crate::render::{RenderSettings, Renderer};
use crate::report::PassReport;
use crate::run::RunOptions;
use crate::vk::context::{Context, ContextDesc};
use crate::vk::shader::reflect;

/// What `dermis budget` does.
#[derive(Clone, Debug)]
pub struct BudgetOptions {
    /// The profiles to price on (at least one), loaded and checked.
    pub profiles: Vec<Profile>,
    pub out: PathBuf,
    pub frames: FrameCounts,
    /// Price at the profile's resolution (rescaling the counts) or as run.
    pub rescale: Rescale,
    /// Run the fetch-counting build (off: declared fetch counts).
    pub count_fetches: bool,
    /// Print the tables.
    pub print: bool,
    pub command: String,
}

/// `frames/METHOD.json`: a frame (read back as a `FrameInput`) and the run
/// that measured it.
#[derive(Serialize)]
struct FrameFile<'a> {
    run: &'a RunHeader,
    #[serde(flatten)]
    frame: &'a FrameInput,
}

/// One method's frame and its prices.
#[derive(Clone, Debug, Serialize)]
pub struct MethodBudget {
    pub method: String,
    pub frame: FrameInput,
    pub budgets: Vec<FrameBudget>,
}

/// `budget.json`.
#[derive(Clone, Debug, Serialize)]
pub struct BudgetReport {
    #[serde(flatten)]
    pub run: RunHeader,
    pub scene: String,
    pub heads: u32,
    pub distance_heads: f32,
    pub fragments_rule: &'static str,
    pub fetch_counts: String,
    pub rescale_rule: &'static str,
    pub combining_rule: &'static str,
    pub params: ParamSet,
    pub profiles: Vec<ProfileSummary>,
    pub runs: Vec<MethodBudget>,
}

/// A profile as the report names it.
#[derive(Clone, Debug, Serialize)]
pub struct ProfileSummary {
    pub name: String,
    pub description: String,
    pub target: [u32; 2],
    pub frame_ms: f64,
    pub skin_budget_ms: f64,
}

/// Turns one pass's counter sites into texture variables, by reflecting the
/// shader its work names (site = 1 + (set * 16 + binding) * 4 + filter kind,
/// shaders/fetch_count.glsl).
fn counted_pass(p: &PassReport, c: &PassCounts) -> Result<CountedPass> {
    let shader = match &p.work {
        Some(Work::Raster {
            shader: Some(s), ..
        }) => Some(s),
        Some(Work::Compute { shader, .. }) => Some(shader),
        _ => None,
    };
    let mut out = CountedPass {
        name: p.name.clone(),
        invocations: c.invocations,
        fetches: Vec::new(),
    };
    let Some(shader) = shader else {
        return Ok(out);
    };
    let refl = reflect(&[&shader.shader])
        .with_context(|| format!("reflecting {} of pass `{}`", shader.shader, p.name))?;
    for &(site, n) in &c.fetches {
        let (set, binding, filter) = decode_site(site);
        let name = refl
            .bindings
            .iter()
            .find(|b| b.set == set && b.binding == binding)
            .map(|b| b.name.clone())
            .with_context(|| {
                format!(
                    "pass `{}`: counter site {site} names set {set} binding {binding}, which {} lacks",
                    p.name, shader.shader
                )
            })?;
        out.fetches.push((name, filter, n));
    }
    Ok(out)
}

/// The frame of one run of a checked frame: the measured run on `ctx`, the
/// counting run on `counting` when given.
pub fn method_frame(
    ctx: &Context,
    counting: Option<&Context>,
    frame: &FrameRequest,
    opts: &BudgetOptions,
) -> Result<FrameInput> {
    let run_opts = RunOptions {
        frames: opts.frames,
        capture: false,
        dump: false,
        ceilings: false,
        command: opts.command.clone(),
        progress: false,
    };
    let report = run_request(ctx, frame, &run_opts)?.report;
    let counted = match counting {
        Some(c) => {
            let counts = Renderer::build(c, frame)?.count_fetches()?;
            let passes: Vec<CountedPass> = report
                .passes
                .iter()
                .zip(&counts)
                .map(|(p, c)| counted_pass(p, c))
                .collect::<Result<_>>()?;
            Some(passes)
        }
        None => None,
    };
    let label = format!(
        "{} {}x{}, {}, {} head(s) at {:.2} head heights",
        report.method,
        report.run.width,
        report.run.height,
        report.scene,
        report.heads,
        report.distance_heads
    );
    frame_from_record(&report, counted.as_deref(), &label)
}

/// The files budget writes into its folder, and the frames it owns.
const FILES: [&str; 3] = ["budget.json", "budget.png", "budget.svg"];
const FRAMES: Owned = Owned {
    sub: "frames",
    suffix: ".json",
};

/// `dermis budget`: the profiles loaded and every frame to price checked
/// (with `--compare-methods` one per registered method but the ground
/// truth) before the device opens.
pub fn run(a: &BudgetArgs, given: &Given) -> Result<()> {
    let frames = FrameCounts::new(a.frames.warmup, a.frames.frames)?;
    let profiles: Vec<Profile> = a
        .profiles
        .iter()
        .map(|p| Profile::load(p).with_context(|| format!("--profile {p}")))
        .collect::<Result<_>>()?;
    let (source, settings) = request::frame_settings(&a.frame, given)?;
    if !a.compare_methods {
        for n in super::notes::foreign(&settings) {
            eprintln!("note: {n}");
        }
    }
    let checked = CheckedSettings::new(settings.clone())?;
    let scene = request::load_scene(&source)?;
    // The ground truth is left out of the comparison: it is no real-time
    // method (on the Xbox 360 its brute-force gather models at about a
    // minute), and it alone takes minutes to run on lavapipe.
    let methods: Vec<CheckedSettings> = if a.compare_methods {
        METHODS
            .iter()
            .filter(|m| !m.ground_truth)
            .map(|m| RenderSettings {
                method: m,
                // --compare-methods prices each method on every character.
                assignment: None,
                ..settings.clone()
            })
            .map(|s| {
                let name = s.method.name;
                CheckedSettings::new(s).with_context(|| format!("method {name}"))
            })
            .collect::<Result<_>>()?
    } else {
        vec![checked]
    };
    let requests: Vec<FrameRequest> = methods
        .into_iter()
        .map(|s| {
            let name = s.get().method.name;
            FrameRequest::of(&scene, s).with_context(|| format!("method {name}"))
        })
        .collect::<Result<_>>()?;
    OutputPaths::new()
        .folder("--out", &a.out, &FILES, &[FRAMES])
        .prepare()?;
    let opts = BudgetOptions {
        profiles,
        out: a.out.clone(),
        frames,
        rescale: if a.as_run {
            Rescale::AsRun
        } else {
            Rescale::ToProfile
        },
        count_fetches: !a.declared_fetches,
        print: true,
        command: command_line(),
    };
    let r = budget(&request::context_desc(&a.frame), &requests, &opts)?;
    println!(
        "priced {} method(s) on {} profile(s); wrote budget.json, frames/, budget.png and budget.svg in {}",
        r.runs.len(),
        r.profiles.len(),
        opts.out.display()
    );
    Ok(())
}

/// Runs, counts, prices, prints and writes (module docs) the checked
/// frames (one per method priced).
pub fn budget(
    desc: &ContextDesc,
    frames: &[FrameRequest],
    opts: &BudgetOptions,
) -> Result<BudgetReport> {
    anyhow::ensure!(!opts.profiles.is_empty(), "give at least one --profile");
    let first = frames.first().context("no frame to price")?;
    let (scene, settings) = (first.scene(), first.settings());
    let ctx = Context::new(desc)?;
    let counting = if opts.count_fetches {
        Some(Context::new(&ContextDesc {
            count_fetches: true,
            ..desc.clone()
        })?)
    } else {
        None
    };
    let params = ParamSet::fitted();
    let header = RunHeader::new(
        &opts.command,
        device_header(&ctx),
        (settings.width, settings.height),
        (opts.frames.warmup(), opts.frames.measured()),
    );
    let mut runs = Vec::new();
    for f in frames {
        // A frame of several methods is priced as one frame: its passes carry
        // their group in their names (`#N ...`; the merges are marked,
        // `Pass::merge`).
        let name = if f.settings().assignment.is_some() {
            MIX_NAME
        } else {
            f.settings().method.name
        };
        let frame = method_frame(&ctx, counting.as_ref(), f, opts)
            .with_context(|| format!("method {name}"))?;
        let budgets: Vec<FrameBudget> = opts
            .profiles
            .iter()
            .map(|p| price_frame(p, &frame, &params, opts.rescale))
            .collect();
        if opts.print {
            for b in &budgets {
                println!("{}", budget_table(b, &ctx.facts.name));
            }
        }
        // The stored frame as calibration reads it (`FrameInput`), with the
        // run header beside its fields.
        write_json(
            &opts.out.join(FRAMES.sub).join(format!("{name}.json")),
            &FrameFile {
                run: &header,
                frame: &frame,
            },
        )?;
        runs.push(MethodBudget {
            method: name.to_string(),
            frame,
            budgets,
        });
    }
    let report = BudgetReport {
        run: header,
        scene: scene.name.clone(),
        heads: settings.heads,
        distance_heads: settings.distance_heads,
        fragments_rule: FRAGMENTS_RULE,
        fetch_counts: if opts.count_fetches {
            format!(
                "counted: each pass run alone with the fetch-counting build of its shaders on {} \
                 (a second context made with count_fetches); declared counts replaced by fetches \
                 made / invocations",
                ctx.facts.name
            )
        } else {
            "declared (upper bounds where a shader branches)".into()
        },
        rescale_rule: RESCALE_RULE,
        combining_rule: COMBINING_RULE,
        params,
        profiles: opts
            .profiles
            .iter()
            .map(|p| ProfileSummary {
                name: p.profile.name.clone(),
                description: p.profile.description.clone(),
                target: [p.target.width_px, p.target.height_px],
                frame_ms: p.target.frame_ms,
                skin_budget_ms: p.share_ms(p.budget.sss_share),
            })
            .collect(),
        runs,
    };
    write_json(&opts.out.join("budget.json"), &report)?;
    let panels = panels(&report);
    let title = format!(
        "dermis frame, {}x{} {} on each profile (modelled)",
        settings.width, settings.height, scene.name
    );
    budget_chart(
        &panels,
        &title,
        &opts.out.join("budget.png"),
        &opts.out.join("budget.svg"),
    )?;
    Ok(report)
}

/// One panel per profile, one bar per method.
pub fn panels(r: &BudgetReport) -> Vec<Panel> {
    r.profiles
        .iter()
        .enumerate()
        .map(|(i, p)| Panel {
            profile: p.name.clone(),
            frame_ms: p.frame_ms,
            skin_budget_ms: p.skin_budget_ms,
            bars: r
                .runs
                .iter()
                .map(|m| Bar::of(&m.method, &m.budgets[i]))
                .collect(),
        })
        .collect()
}
