//! `dermis budget`: runs the frame on whatever device is present (lavapipe
//! included), runs it again pass by pass with the fetch-counting build of its
//! shaders, builds the model's frame from the run's report (`record`), prices
//! it on every profile asked for, and writes `budget.json`, one frame file per
//! method (`frames/METHOD.json`: what calibration stores) and the stacked-bar
//! chart (`budget.png`, `budget.svg`). Counts (samples passed, fetches) do not
//! depend on the device's speed, so lavapipe prices a frame as well as a GPU.

use std::path::PathBuf;

use anyhow::{Context as _, Result};
use serde::Serialize;

use crate::budget::chart::{budget_chart, Bar, Panel};
use crate::budget::input::{FrameInput, RESCALE_RULE};
use crate::budget::model::{price_frame, FrameBudget, Rescale, COMBINING_RULE};
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;
use crate::budget::record::{frame_from_record, CountedPass, FRAGMENTS_RULE};
use crate::budget::table::budget_table;
use crate::graph::work::Work;
use crate::method::METHODS;
use crate::output::{prepare_out_dir, write_json};
use crate::render::counting::{decode_site, PassCounts};
use crate::render::groups::MIX_NAME;
use crate::render::{RenderSettings, Renderer};
use crate::report::PassReport;
use crate::run::{run, RunOptions};
use crate::scene::Scene;
use crate::vk::context::{Context, ContextDesc};
use crate::vk::shader::reflect;

/// What `dermis budget` does.
#[derive(Clone, Debug)]
pub struct BudgetOptions {
    /// Profile names or paths (at least one).
    pub profiles: Vec<String>,
    /// Every registered method but the ground truth instead of the one in the settings.
    pub compare_methods: bool,
    pub out: PathBuf,
    pub warmup: usize,
    pub measured: usize,
    /// Price at the profile's resolution (rescaling the counts) or as run.
    pub rescale: Rescale,
    /// Run the fetch-counting build (off: declared fetch counts).
    pub count_fetches: bool,
    /// Print the tables.
    pub print: bool,
    pub command: String,
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
    pub dermis_version: &'static str,
    pub command: String,
    pub device: String,
    pub driver: String,
    pub width: u32,
    pub height: u32,
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

/// The frame of one run of `settings`: the measured run on `ctx`, the
/// counting run on `counting` when given.
pub fn method_frame(
    ctx: &Context,
    counting: Option<&Context>,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &BudgetOptions,
) -> Result<FrameInput> {
    let run_opts = RunOptions {
        warmup: opts.warmup,
        measured: opts.measured,
        capture: false,
        dump: false,
        ceilings: false,
        command: opts.command.clone(),
        progress: false,
    };
    let report = run(ctx, scene, settings, &run_opts)?.report;
    let counted = match counting {
        Some(c) => {
            let counts = Renderer::new(c, scene, settings)?.count_fetches()?;
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
        report.width,
        report.height,
        report.scene,
        report.heads,
        report.distance_heads
    );
    frame_from_record(&report, counted.as_deref(), &label)
}

/// Runs, counts, prices, prints and writes (module docs).
pub fn budget(
    desc: &ContextDesc,
    scene: &Scene,
    settings: &RenderSettings,
    opts: &BudgetOptions,
) -> Result<BudgetReport> {
    anyhow::ensure!(!opts.profiles.is_empty(), "give at least one --profile");
    let profiles: Vec<Profile> = opts
        .profiles
        .iter()
        .map(|p| Profile::load(p))
        .collect::<Result<_>>()?;
    prepare_out_dir(&opts.out)?;
    let ctx = Context::new(desc)?;
    let counting = if opts.count_fetches {
        Some(Context::new(&ContextDesc {
            count_fetches: true,
            ..desc.clone()
        })?)
    } else {
        None
    };
    // The ground truth is left out of the comparison: it is no real-time
    // method (on the Xbox 360 its brute-force gather models at about a
    // minute), and it alone takes minutes to run on lavapipe.
    let methods: Vec<RenderSettings> = if opts.compare_methods {
        METHODS
            .iter()
            .filter(|m| !m.ground_truth)
            .map(|m| RenderSettings {
                method: m,
                // --compare-methods prices each method on every character.
                assignment: None,
                ..settings.clone()
            })
            .collect()
    } else {
        vec![settings.clone()]
    };
    let params = ParamSet::fitted();
    let mut runs = Vec::new();
    for s in &methods {
        // A frame of several methods is priced as one frame: its passes carry
        // their group in their names (`#N ...`, the merges `mix merge #N`).
        let name = if s.assignment.is_some() {
            MIX_NAME
        } else {
            s.method.name
        };
        let frame = method_frame(&ctx, counting.as_ref(), scene, s, opts)
            .with_context(|| format!("method {name}"))?;
        let budgets: Vec<FrameBudget> = profiles
            .iter()
            .map(|p| price_frame(p, &frame, &params, opts.rescale))
            .collect();
        if opts.print {
            for b in &budgets {
                println!("{}", budget_table(b, &ctx.facts.name));
            }
        }
        write_json(
            &opts.out.join("frames").join(format!("{name}.json")),
            &frame,
        )?;
        runs.push(MethodBudget {
            method: name.to_string(),
            frame,
            budgets,
        });
    }
    let report = BudgetReport {
        dermis_version: env!("CARGO_PKG_VERSION"),
        command: opts.command.clone(),
        device: ctx.facts.name.clone(),
        driver: ctx.facts.driver.clone(),
        width: settings.width,
        height: settings.height,
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
        profiles: profiles
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
