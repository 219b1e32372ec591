//! The planner's pipeline (no device): estimates every character of a
//! scene (`character`), prices every registered eval setting per character
//! on a profile (`cost`, from the stored frames of `profiles/frames/plan/`,
//! built into the binary), plans (`choose`, `solve`), prices the plan as the
//! frame draws it, and makes its plan file (`mix::plan_file::PlanFile`) and
//! table. `dermis plan` (`app::plan`) prints and writes them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use serde::Deserialize;

use super::character::{estimate, CharacterInput};
use super::choose::{narrow_reach_mm, plan, scatter_reach_mm, Accuracy, Ask, Plan, SettingCosts};
use super::cost::{reference_counts, CostModel, Reference, Sample, SettingModel};
use super::geometry::{plan_geometry, PlannedGeometry};
use crate::budget::frames::check_frame;
use crate::budget::input::FrameInput;
use crate::budget::params::ParamSet;
use crate::budget::profile::Profile;
use crate::method::path::{self, Path as SssPath};
use crate::method::METHODS;
use crate::mix::plan_file::{
    PlanFile, PlannedCharacter, PlannedGeometry as PlannedGeometryFile, PredictedError,
    PLAN_VERSION,
};
use crate::mix::Choice;
use crate::render::RenderSettings;
use crate::scene::crowd_geometry::turned;
use crate::scene::framing::frame as frame_scene;
use crate::scene::Scene;
use crate::view::ViewScale;
use crate::work::Work;

/// A checked skin-SSS budget in milliseconds (`--budget-ms`): a positive,
/// finite number.
pub fn parse_budget_ms(budget_ms: &str) -> Result<f64> {
    let b: f64 = budget_ms
        .trim()
        .parse()
        .map_err(|_| anyhow::anyhow!("--budget-ms '{budget_ms}' is not a number"))?;
    if !(b.is_finite() && b > 0.0) {
        bail!("--budget-ms {budget_ms} is not a positive number of milliseconds");
    }
    Ok(b)
}

/// A registered method setting the planner may choose.
#[derive(Clone, Debug, PartialEq)]
pub struct Registered {
    pub method: &'static str,
    /// The planner's label (`method::path::planned_label`): the eval
    /// setting's, with the path named off the fragment path.
    pub setting: String,
    /// The eval setting whose accuracy rows price its error. A compute twin's
    /// is its fragment twin's: the two paths' images agree within one f16 ulp
    /// on lavapipe (`tests/suite/compute.rs`) and within a relative RMSE of
    /// 2e-4 on the H100 (docs/perf/issue28), far under the eval's bands.
    pub eval: &'static str,
    pub path: SssPath,
    pub options: BTreeMap<String, String>,
}

/// Every eval setting of every registered method but the ground truth and
/// none (none is always an option, cost 0), that approximates the six
/// Gaussians: the accuracy model the planner reads is measured against their
/// truth (`eval::sweep::six_gaussian_registry`), so a setting of another
/// profile (separable's Burley preset) is not the planner's to choose. A
/// method with a compute path (`--path`) has each setting twice, once per
/// path, so a plan may choose the path per group; a profile without compute
/// leaves the compute twins unpriced (`cost::CostModel::fixed_ms`).
pub fn registered() -> Vec<Registered> {
    METHODS
        .iter()
        .filter(|m| !m.ground_truth && Choice::none().method != m.name)
        // Not in the accuracy model yet: the planner cannot price its error.
        .filter(|m| {
            !crate::eval::sweep::UNMEASURED
                .iter()
                .any(|(u, _)| *u == m.name)
        })
        .flat_map(|m| {
            let has_paths = m.options.iter().any(|o| o.key == path::OPTION.key);
            m.eval
                .iter()
                .filter(move |e| {
                    let given = crate::method::MethodOptions::default().with(e.options);
                    crate::method::profile::approximated(m, &given)
                        .is_ok_and(|p| p.is_six_gaussian())
                })
                .flat_map(move |e| {
                    let pinned = e.options.iter().any(|(k, _)| *k == path::OPTION.key);
                    let paths: &[SssPath] = if has_paths && !pinned {
                        &[SssPath::Fragment, SssPath::Compute]
                    } else {
                        &[SssPath::Fragment]
                    };
                    paths.iter().filter_map(move |&p| {
                        let mut options: BTreeMap<String, String> = e
                            .options
                            .iter()
                            .map(|(k, v)| (k.to_string(), v.to_string()))
                            .collect();
                        if p != SssPath::Fragment {
                            options.insert(path::OPTION.key.to_string(), p.name().to_string());
                        }
                        // A twin the method refuses (ssg's branch mask is the
                        // fragment path's alternative to the stencil) is none.
                        Choice::new(m.name, options.clone()).ok()?;
                        Some(Registered {
                            method: m.name,
                            setting: path::planned_label(e.label, p),
                            eval: e.label,
                            path: p,
                            options,
                        })
                    })
                })
        })
        .collect()
}

/// The options of the registered eval setting `setting` of `method`.
pub fn setting_options(method: &str, setting: &str) -> Option<BTreeMap<String, String>> {
    registered()
        .into_iter()
        .find(|x| x.method == method && x.setting == setting)
        .map(|x| x.options)
}

/// The stored frames of the reference setting among `models`: what every
/// character's skin and region are estimated against.
pub fn reference_model(models: &[SettingModel]) -> Result<&SettingModel> {
    let (rm, rs) = reference_setting()?;
    models
        .iter()
        .find(|m| m.method == rm && m.setting == rs)
        .context("the reference setting has no stored frames")
}

/// The reference setting: the default method at its default options.
pub fn reference_setting() -> Result<(String, String)> {
    let d = RenderSettings::default();
    let c = Choice::new(d.method.name, BTreeMap::new())?;
    let s = c.eval_setting()?.with_context(|| {
        format!(
            "the default method {} has no eval setting at its defaults",
            c.method
        )
    })?;
    Ok((c.method, s.label.to_string()))
}

#[derive(Deserialize)]
struct IndexRow {
    method: String,
    setting: String,
    file: String,
    distance_heads: f64,
    height: u32,
    fovy_deg: f64,
}

#[derive(Deserialize)]
struct Index {
    frames: Vec<IndexRow>,
}

/// `profiles/frames/plan/` in the source tree (the tools that store frames;
/// the planner reads the copies built into the binary, [`load_models`]).
pub fn plan_frames_dir() -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/frames/plan")
}

/// The planner's stored frames as the binary holds them.
pub const PLAN_FRAMES: &str = "profiles/frames/plan";

/// The px/mm at the centre of a head `distance_heads` head heights away
/// (a 230 mm head: the stored frames' scenes are scaled to it).
fn stored_px_per_mm(height: u32, fovy_deg: f64, distance_heads: f64) -> f64 {
    let s = ViewScale::new(
        height,
        (fovy_deg as f32).to_radians(),
        crate::skin::tsd::HEAD_MM,
    );
    f64::from(s.px_per_mm(distance_heads as f32))
}

/// A stored frame, read through the one door and checked as `budget` checks
/// one, after one repair: the recorder gives a texture-space pass (render
/// area a map's, drawn once) the screen's SSS region as its rasterised
/// pixels, more than its triangle can cover; such a pass rasterises at most
/// its render area, which it is given instead.
pub fn load_stored(path: &Path) -> Result<FrameInput> {
    let text = crate::files::read_text(path, "stored frame", crate::files::MAX_TEXT_FILE)?;
    parse_stored(&text, &path.display().to_string())
}

/// [`load_stored`] of a stored frame's text (`name` names it in errors).
pub fn parse_stored(text: &str, name: &str) -> Result<FrameInput> {
    let mut f: FrameInput =
        serde_json::from_str(text).with_context(|| format!("parsing {name}"))?;
    for p in &mut f.passes {
        if let (
            Work::Raster {
                width,
                height,
                msaa,
                triangles: 1,
                ..
            },
            Some(r),
        ) = (&p.work, p.rasterized_pixels)
        {
            let area = u64::from(*width) * u64::from(*height) * u64::from(*msaa);
            if r > area {
                p.rasterized_pixels = Some(area);
            }
        }
    }
    check_frame(&f).with_context(|| format!("stored frame {name}"))?;
    Ok(f)
}

/// The embedded file `name` of [`PLAN_FRAMES`].
fn plan_frame_text(name: &str) -> Result<&'static str> {
    crate::embedded::file(&format!("{PLAN_FRAMES}/{name}"))
        .with_context(|| format!("{PLAN_FRAMES}/{name} is not built into this binary"))
}

/// The stored frames of every registered setting (built into the binary),
/// as cost models; settings without frames are named in the returned notes.
pub fn load_models() -> Result<(Vec<SettingModel>, Vec<String>)> {
    let dir = PLAN_FRAMES;
    let text = plan_frame_text("index.json")?;
    let index: Index = serde_json::from_str(text)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("{dir}/index.json: not an index of stored frames"))?;
    let samples_of = |method: &str, setting: &str| -> Result<Vec<Sample>> {
        index
            .frames
            .iter()
            .filter(|r| r.method == method && r.setting == setting)
            .map(|r| {
                Ok(Sample {
                    px_per_mm: stored_px_per_mm(r.height, r.fovy_deg, r.distance_heads),
                    frame: parse_stored(plan_frame_text(&r.file)?, &format!("{dir}/{}", r.file))?,
                })
            })
            .collect()
    };
    let (rm, rs) = reference_setting()?;
    let refs: Vec<(f64, Reference)> = samples_of(&rm, &rs)?
        .iter()
        .filter_map(|s| Some((s.px_per_mm, reference_counts(&s.frame)?)))
        .collect();
    if refs.is_empty() {
        bail!("{dir}: no stored frame of the reference setting {rm} '{rs}' (run tools/plan_frames.sh)");
    }
    let reference = |x: f64| {
        refs.iter()
            .find(|(p, _)| (p / x - 1.0).abs() < 1e-6)
            .map(|r| r.1)
    };
    let mut models = Vec::new();
    let mut notes = Vec::new();
    for r in registered() {
        let samples = samples_of(r.method, &r.setting)?;
        if samples.is_empty() {
            notes.push(format!(
                "{} '{}' has no stored frames in {dir} (tools/plan_frames.sh): not planned",
                r.method, r.setting,
            ));
            continue;
        }
        models.push(
            SettingModel::new(r.method, &r.setting, samples, reference)
                .map(|m| m.measured_as(r.eval, r.path == SssPath::Compute))
                .map_err(|e| anyhow::anyhow!("{dir}: {e}"))?,
        );
    }
    Ok((models, notes))
}

/// Millimetres of skin per unit of the texture-space atlas (area-weighted
/// over the triangles): a map of T texels has texels of this / T mm.
pub fn atlas_mm(scene: &Scene) -> f64 {
    let mesh = &scene.head.mesh;
    let a = crate::skin::tsd::atlas(mesh, scene.mm_per_unit);
    let mm = f64::from(scene.mm_per_unit);
    let (mut area3, mut area_uv) = (0.0, 0.0);
    for t in mesh.indices.chunks_exact(3) {
        let [i, j, k] = [t[0], t[1], t[2]].map(|x| x as usize);
        let p = |v: usize| glam::Vec3::from(mesh.vertices[v].position);
        area3 += f64::from(0.5 * (p(j) - p(i)).cross(p(k) - p(i)).length()) * mm * mm;
        let (u0, u1, u2) = (a.uv[i], a.uv[j], a.uv[k]);
        area_uv += 0.5
            * f64::from(
                ((u1[0] - u0[0]) * (u2[1] - u0[1]) - (u1[1] - u0[1]) * (u2[0] - u0[0])).abs(),
            );
    }
    if area_uv > 0.0 {
        (area3 / area_uv).sqrt()
    } else {
        f64::INFINITY
    }
}

/// The characters of a scene as `render` would place them, with the
/// reference region from the reference setting's stored frames.
pub fn characters(
    scene: &Scene,
    s: &RenderSettings,
    reference: &SettingModel,
) -> Vec<CharacterInput> {
    // render's own shot, so what is planned is what is rendered.
    let shot = crate::render::groups::shot(scene, s);
    let mut framing = frame_scene(scene, &shot);
    // The models the frame draws with (a crowd's rigid turns).
    framing.instances = turned(scene, framing.instances);
    let mut cs = estimate(
        scene,
        &framing,
        s.width,
        s.height,
        shot.light_dir,
        s.shadow_size,
    );
    with_regions(&mut cs, reference, reference_regions(scene, s, &framing));
    cs
}

/// Each character's reference region: its pixels and rectangles from the
/// reference setting's stored frames (`price_grid::reference_load`), its
/// tiles as the frame builds them (`tiles`, in the frame's order).
pub fn with_regions(
    cs: &mut [CharacterInput],
    reference: &SettingModel,
    tiles: Vec<Vec<crate::view::region::PixelRect>>,
) {
    for c in cs.iter_mut() {
        let l = super::price_grid::reference_load(reference, c.px_per_mm, c.skin_pixels);
        c.region_pixels = l.region_pixels;
        c.region_rects = l.region_rects;
    }
    for (c, tiles) in cs.iter_mut().zip(tiles) {
        c.region_tiles = tiles.iter().map(|r| [r.x0, r.y0, r.x1, r.y1]).collect();
    }
}

/// Each character's region alone as the frame builds it for the reference
/// setting (separable at its defaults: its kernel's reach, the frame's tiles),
/// so a group's region can be the cover of its characters' (`cost::Overlap`).
/// Empty where the frame draws no region (`--sss-region screen`) or the
/// reference is another method.
pub fn reference_regions(
    scene: &Scene,
    s: &RenderSettings,
    framing: &crate::scene::framing::Framing,
) -> Vec<Vec<crate::view::region::PixelRect>> {
    use crate::method::separable;
    use crate::view::region::{instance_regions, RegionMode, RegionView};
    let none = || vec![Vec::new(); framing.instances.len()];
    let d = RenderSettings::default();
    if s.sss_region == RegionMode::Screen || !std::ptr::eq(d.method, &separable::ENTRY) {
        return none();
    }
    let Ok(kernel) = separable::Config::parse(&d.method.opts(&d.options))
        .and_then(|c| crate::skin::kernel::SeparableKernel::build(c.params, c.samples))
    else {
        return none();
    };
    let cam = framing.camera;
    let rv = RegionView {
        view: cam.view(),
        proj: cam.proj(s.width as f32 / s.height as f32),
        near: cam.near,
        width: s.width,
        height: s.height,
    };
    instance_regions(
        scene,
        &framing.instances,
        &rv,
        (cam.fovy_rad / 2.0).tan(),
        s.sss_region_tile,
        |depth, scale| separable::reach_px(&kernel, depth, scale),
    )
}

/// Every setting's costs for `chars` on the profile.
pub fn setting_costs(
    models: &[SettingModel],
    chars: &[CharacterInput],
    prof: &Profile,
    width: u32,
    height: u32,
    atlas_mm: f64,
) -> Vec<SettingCosts> {
    let cm = CostModel {
        profile: prof,
        params: ParamSet::fitted(),
        width,
        height,
    };
    let loads: Vec<_> = chars.iter().map(super::load_of).collect();
    models
        .iter()
        .filter_map(|m| {
            let fixed = cm.fixed_ms(m)?;
            Some(SettingCosts {
                method: m.method.clone(),
                setting: m.setting.clone(),
                measured_as: m.eval.clone(),
                fixed_ms: fixed,
                parts_ms: loads.iter().map(|l| cm.part_ms(m, fixed, l)).collect(),
                texel_mm: chars
                    .iter()
                    .map(|c| m.map_side(c.px_per_mm).map(|t| atlas_mm / t.max(1.0)))
                    .collect(),
            })
        })
        .collect()
}

/// A plan's groups priced as the frame draws them: each group's characters'
/// regions merged (`cost::Overlap`: one tile cover, fewer rectangles than
/// their sum), each group one `price_frame`. The solver's additive parts count
/// every character's region whole, an upper bound; this is the plan's
/// prediction. Each row's part is scaled so that the rows and the groups'
/// fixed costs still sum to it.
pub fn price_merged(
    p: &mut Plan,
    chars: &[CharacterInput],
    costs: &[SettingCosts],
    models: &[SettingModel],
    prof: &Profile,
    (width, height, tile): (u32, u32, u32),
) {
    let cm = CostModel {
        profile: prof,
        params: ParamSet::fitted(),
        width,
        height,
    };
    let mut total = 0.0;
    for (g, fixed) in p.groups.clone() {
        let members: Vec<usize> = (0..p.rows.len())
            .filter(|&i| p.rows[i].setting == Some(g))
            .collect();
        let additive: f64 = members.iter().map(|&i| p.rows[i].part_ms).sum::<f64>() + fixed;
        let model = models
            .iter()
            .find(|m| m.method == costs[g].method && m.setting == costs[g].setting);
        let regions: Vec<&[[u32; 4]]> = members
            .iter()
            .map(|&i| chars[i].region_tiles.as_slice())
            .collect();
        let overlap = super::cost::Overlap::of(&regions, width, height, tile);
        let loads: Vec<_> = members.iter().map(|&i| super::load_of(&chars[i])).collect();
        let merged = model
            .and_then(|m| m.group_ms(prof, &cm.params, &overlap.apply(&loads), width, height))
            .unwrap_or(additive);
        let parts = additive - fixed;
        let k = if parts > 0.0 {
            ((merged - fixed) / parts).max(0.0)
        } else {
            1.0
        };
        for &i in &members {
            p.rows[i].part_ms *= k;
        }
        total += merged;
    }
    p.solution.cost_ms = total;
}

/// Plans, prices the plan as the frame draws it (`price_merged`) and, while
/// that leaves budget unused, plans again with the solver's budget stretched
/// by the additive over merged cost of the last plan, keeping a stretched
/// plan only where its merged cost fits the budget and its error is lower
/// (at most `REFILL_ROUNDS` rounds). The solver's optimality and bound are
/// those of the additive problem at the budget it was given.
pub fn plan_refilled(
    ask: &Ask,
    costs: &[SettingCosts],
    models: &[SettingModel],
    prof: &Profile,
    size: (u32, u32, u32),
) -> Plan {
    let priced = |budget: f64| {
        let mut p = plan(&Ask {
            budget_ms: budget,
            previous: ask.previous.clone(),
            ..*ask
        });
        let additive = p.solution.cost_ms;
        price_merged(&mut p, ask.characters, costs, models, prof, size);
        (p, additive)
    };
    let (mut best, mut additive) = priced(ask.budget_ms);
    let mut merged = best.solution.cost_ms;
    for _ in 0..REFILL_ROUNDS {
        if merged <= 0.0 || additive <= merged * (1.0 + 1e-6) {
            break;
        }
        let (p, a) = priced(ask.budget_ms * additive / merged);
        if p.solution.cost_ms > ask.budget_ms + 1e-9 || p.solution.error >= best.solution.error {
            break;
        }
        (additive, merged) = (a, p.solution.cost_ms);
        best = p;
    }
    best
}

/// Rounds of `plan_refilled` (each a solve and a pricing of its groups).
pub const REFILL_ROUNDS: usize = 4;

/// Node limit of the branch and bound in `dermis plan` (beyond it the plan
/// is the best found and the bound says how far from optimal it can be).
pub const NODE_LIMIT: u64 = 20_000;

/// A planned frame: its characters, every setting's costs, the plan and
/// its file.
pub struct Planned {
    pub characters: Vec<CharacterInput>,
    pub costs: Vec<SettingCosts>,
    pub plan: Plan,
    pub file: PlanFile,
    /// Each character's level and shadow casting, their triangles.
    pub geometry: PlannedGeometry,
}

/// Plans the frame `settings` describe in `scene` under `budget_ms` on
/// `profile` (module docs).
pub fn plan_frame(
    profile: &Profile,
    budget_ms: f64,
    settings: &RenderSettings,
    scene: &Scene,
    accuracy: &dyn Accuracy,
    accuracy_source: &str,
) -> Result<Planned> {
    let (models, mut notes) = load_models()?;
    let reference = reference_model(&models)?;
    let t0 = Instant::now();
    let chars = characters(scene, settings, reference);
    let costs = setting_costs(
        &models,
        &chars,
        profile,
        settings.width,
        settings.height,
        atlas_mm(scene),
    );
    let t1 = Instant::now();
    let p = plan_refilled(
        &Ask {
            characters: &chars,
            settings: &costs,
            accuracy,
            budget_ms,
            previous: None,
            switch_margin: 0.0,
            node_limit: Some(NODE_LIMIT),
        },
        &costs,
        &models,
        profile,
        (settings.width, settings.height, settings.sss_region_tile),
    );
    let t2 = Instant::now();
    notes.extend(plan_notes(&p, accuracy_source));
    notes.push(format!(
        "time: characters and costs {:.1} ms, solve {:.2} ms ({} nodes)",
        (t1 - t0).as_secs_f64() * 1e3,
        (t2 - t1).as_secs_f64() * 1e3,
        p.solution.nodes
    ));
    let shot = crate::render::groups::shot(scene, settings);
    let framing = frame_scene(scene, &shot);
    let models = turned(scene, framing.instances.clone());
    let geometry = plan_geometry(scene, settings, &framing, &models, profile);
    notes.extend(geometry.notes(&profile.profile.name, settings.lod_pixels));
    let mut file = plan_file(&profile.profile.name, budget_ms, &chars, &costs, &p, notes)?;
    for a in &mut file.assignments {
        let g = geometry.characters[a.character];
        a.geometry = Some(PlannedGeometryFile {
            level: g.level,
            casts_shadow: g.casts_shadow,
            triangles: Some(geometry.triangles[a.character]),
        });
    }
    file.check()?;
    Ok(Planned {
        characters: chars,
        costs,
        plan: p,
        file,
        geometry,
    })
}

/// What the plan says about itself (algorithm, bound, rules, sources).
pub fn plan_notes(p: &Plan, accuracy_source: &str) -> Vec<String> {
    let s = &p.solution;
    let mut n = vec![format!(
        "algorithm: branch and bound over characters with the LP (Lagrangian) bound of the \
         multiple-choice knapsack, group fixed costs exact; {}",
        if s.optimal {
            "search finished: the plan is optimal for the model".to_string()
        } else {
            format!("node limit {NODE_LIMIT} reached: best plan found")
        }
    )];
    if let Some(lb) = s.lower_bound {
        n.push(format!(
            "skin-weighted err/none {:.4}; the root's LP (Lagrangian) bound {:.4}, gap {:.4} \
             (the bound relaxes the groups' fixed costs to 0: loose where they matter)",
            s.error,
            lb,
            s.error - lb
        ));
    }
    n.push(format!(
        "rules: no SSS where the scattering's reach ({:.2} mm, 3 sigma of the profile's widest \
         Gaussian) spans under a pixel; no texture-space setting whose map texel exceeds the narrow reach \
         ({:.2} mm, Gaussian 3); no setting outside its accuracy model's measured range",
        scatter_reach_mm(),
        narrow_reach_mm()
    ));
    n.push(
        "costs: each character's part priced alone plus each used group's fixed cost (an \
         upper bound of the group's price, the max of sums being at most the sum of maxes, but \
         for the model's hi-Z rule: measured -5.2% to +6.0% of it on a 16-character crowd); \
         per-character ms in this file carry an equal share of their group's fixed cost"
            .to_string(),
    );
    n.push(format!("accuracy: {accuracy_source}"));
    n
}

fn label(costs: &[SettingCosts], s: Option<usize>) -> (String, String) {
    match s {
        Some(s) => (costs[s].method.clone(), costs[s].setting.clone()),
        None => (Choice::none().method, "-".to_string()),
    }
}

/// Per-character ms with an equal share of the group's fixed cost.
fn with_share(p: &Plan, ci: usize) -> f64 {
    let r = &p.rows[ci];
    let Some(s) = r.setting else { return 0.0 };
    let n = p
        .rows
        .iter()
        .filter(|x| x.setting == Some(s))
        .count()
        .max(1);
    let fixed = p.groups.iter().find(|g| g.0 == s).map_or(0.0, |g| g.1);
    r.part_ms + fixed / n as f64
}

/// The printed table.
pub fn table(chars: &[CharacterInput], costs: &[SettingCosts], p: &Plan, profile: &str) -> String {
    let mut s = format!(
        "{:>4} {:>7} {:>9}  {:<12} {:<24} {:>10} {:>9} {:>9}\n",
        "char", "px/mm", "skin px", "method", "setting", "ms", "interior", "silh."
    );
    s.push_str(&format!(
        "(ms on {profile}; err/none predicted, interior and silhouette bands)\n"
    ));
    if let Some(c) = chars.first() {
        s.push_str(&format!(
            "(shadow-map texel {:.3} mm at every character: one map fitted to all {})\n",
            c.shadow_mm,
            chars.len()
        ));
    }
    for (ci, (c, r)) in chars.iter().zip(&p.rows).enumerate() {
        let (m, st) = label(costs, r.setting);
        s.push_str(&format!(
            "{:>4} {:>7.3} {:>9.0}  {:<12} {:<24} {:>10.4} {:>9.3} {:>9.3}\n",
            c.index,
            c.px_per_mm,
            c.skin_pixels,
            m,
            st,
            with_share(p, ci),
            r.predicted.0,
            r.predicted.1
        ));
    }
    for (g, f) in &p.groups {
        s.push_str(&format!(
            "group {} '{}': fixed {:.4} ms (in the shares above)\n",
            costs[*g].method, costs[*g].setting, f
        ));
    }
    s.push_str(&format!(
        "skin SSS {:.4} ms; skin-weighted err/none {:.4}\n",
        p.solution.cost_ms, p.solution.error
    ));
    s
}

/// The plan as `mix::plan_file::PlanFile` (every field filled).
pub fn plan_file(
    profile: &str,
    budget_ms: f64,
    chars: &[CharacterInput],
    costs: &[SettingCosts],
    p: &Plan,
    notes: Vec<String>,
) -> Result<PlanFile> {
    let mut assignments = Vec::new();
    let (mut wi, mut ws, mut w) = (0.0, 0.0, 0.0);
    for (ci, (c, r)) in chars.iter().zip(&p.rows).enumerate() {
        let (method, setting) = label(costs, r.setting);
        let options = setting_options(&method, &setting).unwrap_or_default();
        // Checked as a plan file is checked on reading.
        let choice = Choice::new(&method, options.clone())?;
        wi += r.predicted.0 * c.skin_pixels;
        ws += r.predicted.1 * c.skin_pixels;
        w += c.skin_pixels;
        assignments.push(PlannedCharacter {
            character: c.index,
            method: choice.method.clone(),
            options,
            setting: Some(setting),
            px_per_mm: Some(c.px_per_mm),
            skin_pixels: Some(c.skin_pixels.round().max(0.0) as u64),
            predicted_ms: Some(with_share(p, ci)),
            predicted_error: Some(PredictedError {
                interior: r.predicted.0,
                silhouette: r.predicted.1,
            }),
            fade: None,
            geometry: None,
        });
    }
    let w = w.max(1e-12);
    let f = PlanFile {
        version: PLAN_VERSION,
        profile: Some(profile.to_string()),
        budget_ms: Some(budget_ms),
        characters: chars.len(),
        assignments,
        predicted_ms: Some(p.solution.cost_ms),
        predicted_error: Some(PredictedError {
            interior: wi / w,
            silhouette: ws / w,
        }),
        notes,
        run: None,
    };
    f.check()?;
    Ok(f)
}
