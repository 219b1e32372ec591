//! What `dermis eval` sweeps and what it records (no device: the sweep
//! itself is `app::eval`'s): the registered methods' settings, the scene
//! sets' views, a row per (view, setting), the summary and eval.json's
//! schema, read back typed.
//!
//! A method joins the chart by adding its settings to [`registry`].

use std::path::PathBuf;

use anyhow::Result;
use serde::{Deserialize, Serialize};

use super::bands::{Band, BandErrors};
use super::pareto::EvalPoint;
use crate::header::RunHeader;
use crate::method::profile::Profile;
use crate::method::{EvalSetting, MethodEntry, METHODS};
use crate::render::settings::Texturing;
use crate::render::RenderSettings;
use crate::scene::gltf_load::TextureOverrides;
use crate::scene::{default_scene, load_gltf_scene, Scene};

/// One point of the sweep: a method at one quality setting.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    pub method: &'static MethodEntry,
    pub setting: &'static EvalSetting,
}

/// Every method's eval settings, in registry order (the ground truth is what
/// they are scored against, not a point).
pub fn registry() -> Vec<Config> {
    METHODS
        .iter()
        .filter(|m| !m.ground_truth)
        .flat_map(|m| {
            m.eval.iter().map(move |s| Config {
                method: m,
                setting: s,
            })
        })
        .collect()
}

/// The settings of `configs` that `only` names (`eval --only`): `METHOD`
/// takes every setting of the method (by name or alias), `METHOD/LABEL` the
/// one whose label is `LABEL`. Empty: all of them. A sweep over a few settings
/// costs minutes on lavapipe where the whole registry costs an hour; an entry
/// that names nothing is an error, not a silently empty sweep.
pub fn select(configs: Vec<Config>, only: &[String]) -> Result<Vec<Config>> {
    if only.is_empty() {
        return Ok(configs);
    }
    let mut wanted = Vec::with_capacity(only.len());
    for o in only {
        let (name, label) = match o.split_once('/') {
            Some((n, l)) => (n, Some(l.trim())),
            None => (o.as_str(), None),
        };
        let method = crate::method::lookup(name)?;
        if let Some(l) = label {
            if !method.eval.iter().any(|s| s.label == l) {
                anyhow::bail!(
                    "--only {o}: {} has no eval setting '{l}' (its settings: {})",
                    method.name,
                    method
                        .eval
                        .iter()
                        .map(|s| s.label)
                        .collect::<Vec<_>>()
                        .join("; ")
                );
            }
        }
        wanted.push((method.name, label));
    }
    Ok(configs
        .into_iter()
        .filter(|c| {
            wanted
                .iter()
                .any(|(m, l)| *m == c.method.name && l.is_none_or(|l| l == c.setting.label))
        })
        .collect())
}

/// The settings that approximate the six Gaussians (`method::profile::approximated`):
/// the ones the accuracy model measures and the planner chooses among (its
/// err/none is against the six Gaussians' truth; Burley's settings answer
/// to Burley's).
pub fn six_gaussian_registry() -> Vec<Config> {
    registry()
        .into_iter()
        .filter(|c| !UNMEASURED.iter().any(|(m, _)| *m == c.method.name))
        .filter(|c| {
            let given = crate::method::MethodOptions::default().with(c.setting.options);
            crate::method::profile::approximated(c.method, &given)
                .is_ok_and(|p| p.is_six_gaussian())
        })
        .collect()
}

/// Methods the accuracy model (`profiles/accuracy/`, `eval --scenes
/// accuracy`) has not measured yet, and why: it and the planner, which
/// prices a setting's error from it, leave them out until their rows are
/// measured.
pub const UNMEASURED: &[(&str, &str)] = &[(
    "gather",
    "added in issue 28; its accuracy-set rows (`eval --scenes accuracy` on both heads, hours on lavapipe) are still to be measured",
)];

/// A view of the scene set.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneSpec {
    pub name: String,
    /// `None`: the embedded procedural head.
    pub gltf: Option<PathBuf>,
    pub distance_heads: f32,
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    /// The scene set's own field of view (the accuracy set's narrowed frame);
    /// `None`: the run's `--fovy`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fovy_deg: Option<f32>,
    /// What the accuracy model's rows record (the accuracy set only).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<AccuracyPoint>,
}

/// What a row of the accuracy model records about its view.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyPoint {
    pub asset: String,
    /// Pixels per millimetre at the head centre's depth.
    pub px_per_mm: f64,
    /// Degrees between the key light's direction and the direction from the
    /// head to the camera.
    pub light_deg: f64,
    /// Width of a shadow-map texel at the head, mm (the run's --shadow-size
    /// over the map fitted to the head).
    pub shadow_mm: f64,
}

/// The thesis' perceptual study (section 4.3.2): zoom, near and far (28, 50 and
/// 132 units for a 27-unit head, so 1.04, 1.85 and 4.89 head heights) x light at
/// 0, 60, 110 and 150 degrees azimuth, 45 elevation, on the given head, plus the
/// procedural default scene.
pub fn thesis_scenes(head: Option<PathBuf>) -> Vec<SceneSpec> {
    let mut v = Vec::new();
    if let Some(h) = head {
        for (shot, d) in [
            ("zoom", 28.0 / 27.0),
            ("near", 50.0 / 27.0),
            ("far", 132.0 / 27.0),
        ] {
            for az in [0.0, 60.0, 110.0, 150.0] {
                v.push(SceneSpec {
                    name: format!("head {shot} {az:.0}deg"),
                    gltf: Some(h.clone()),
                    distance_heads: d,
                    azimuth_deg: az,
                    elevation_deg: 45.0,
                    fovy_deg: None,
                    accuracy: None,
                });
            }
        }
    }
    v.push(procedural_scene());
    v
}

/// A camera dolly on the given head from a close-up (1 head height) to a far
/// shot (24), in 12 steps of equal ratio, light at 60 degrees azimuth and 45
/// elevation: each method's error along it shows where a distance-driven
/// switch (Gaussian LOD, poisson's sample count) changes the image.
pub fn dolly_scenes(head: PathBuf) -> Vec<SceneSpec> {
    const STEPS: usize = 12;
    let (near, far) = (1.0f32, 24.0f32);
    (0..STEPS)
        .map(|i| {
            let d = near * (far / near).powf(i as f32 / (STEPS - 1) as f32);
            SceneSpec {
                name: format!("head dolly {d:.2}"),
                gltf: Some(head.clone()),
                distance_heads: d,
                azimuth_deg: 60.0,
                elevation_deg: 45.0,
                fovy_deg: None,
                accuracy: None,
            }
        })
        .collect()
}

/// The embedded scene at its default view.
pub fn procedural_scene() -> SceneSpec {
    let d = RenderSettings::study();
    SceneSpec {
        name: "procedural".into(),
        gltf: None,
        distance_heads: d.distance_heads,
        azimuth_deg: d.light.azimuth_deg,
        elevation_deg: d.light.elevation_deg,
        fovy_deg: None,
        accuracy: None,
    }
}

/// One row of the detailed report: `point.error` is the interior err/none.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EvalRow {
    #[serde(flatten)]
    pub point: EvalPoint,
    pub skin_pixels: usize,
    pub frame_ms: f64,
    /// Relative RMSE over all skin (what the chart ranked by before the bands).
    pub rel_rmse_all_skin: f64,
    /// err/none, gain, FLIP and relative RMSE per band.
    pub bands: BandErrors,
    /// The profile the setting approximates, whose ground truth it was scored
    /// against (`method::profile::approximated`); absent: the six Gaussians.
    #[serde(default, skip_serializing_if = "Profile::is_six_gaussian")]
    pub profile: Profile,
    /// Where the albedo entered, in the frame and its truth alike
    /// (`eval --compare-texturing`); absent: pre-scatter.
    #[serde(default, skip_serializing_if = "Texturing::is_pre")]
    pub texturing: Texturing,
}

impl EvalRow {
    /// eval.csv's header: every field eval.json writes for a row, the bands
    /// flattened (`interior_err_none`, `interior_gain_r`...). The first five are
    /// the columns eval.csv had before the bands joined it.
    pub fn csv_header() -> Vec<String> {
        let mut h: Vec<String> = [
            "method",
            "setting",
            "scene",
            "gpu_ms",
            "error",
            "skin_pixels",
            "frame_ms",
            "rel_rmse_all_skin",
        ]
        .map(String::from)
        .to_vec();
        for band in Band::ALL {
            let b = band_key(band);
            for f in [
                "pixels", "rel_rmse", "err_none", "gain_r", "gain_g", "gain_b", "flip",
            ] {
                h.push(format!("{b}_{f}"));
            }
        }
        h
    }

    /// The row's fields in [`EvalRow::csv_header`]'s order; numbers in Rust's
    /// shortest round-trip form, an absent value (no no-SSS frame) empty.
    pub fn csv_fields(&self) -> Vec<String> {
        let p = &self.point;
        let mut f = vec![
            p.method.clone(),
            p.setting.clone(),
            p.scene.clone(),
            p.gpu_ms.to_string(),
            p.error.to_string(),
            self.skin_pixels.to_string(),
            self.frame_ms.to_string(),
            self.rel_rmse_all_skin.to_string(),
        ];
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
        for band in Band::ALL {
            let e = self.bands.get(band);
            f.push(e.pixels.to_string());
            f.push(e.rel_rmse.to_string());
            f.push(opt(e.err_none));
            for c in 0..3 {
                f.push(opt(e.gain.map(|g| g[c])));
            }
            f.push(e.flip.to_string());
        }
        f
    }
}

/// A band's key in eval.json (and its prefix in eval.csv).
fn band_key(band: Band) -> &'static str {
    match band {
        Band::Interior => "interior",
        Band::Silhouette => "silhouette",
        Band::DepthStep => "depth_step",
    }
}

/// Writes eval.csv: one line per row, every column of eval.json's rows; a
/// last column `profile` when a row was scored against another truth than
/// the six Gaussians' (as eval.json writes the key only then).
pub fn write_csv(path: &std::path::Path, rows: &[EvalRow]) -> Result<()> {
    let profiles = rows.iter().any(|r| !r.profile.is_six_gaussian());
    let texturing = rows.iter().any(|r| !r.texturing.is_pre());
    let mut header = EvalRow::csv_header();
    let fields: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut f = r.csv_fields();
            if profiles {
                f.push(r.profile.name().to_string());
            }
            if texturing {
                f.push(r.texturing.name().to_string());
            }
            f
        })
        .collect();
    if profiles {
        header.push("profile".into());
    }
    if texturing {
        header.push("texturing".into());
    }
    super::pareto::write_table(path, &header, &fields)
}

/// What `err/none` means in eval.json.
pub const ERROR_DEFINITION: &str = "err/none over the interior band: the method's RMS error against the ground truth over the no-SSS frame's (0 perfect, 1 no better than no SSS)";

/// eval.json: the run, the views, every row, the summary and its Pareto
/// front (on the interior); written by `dermis eval`, read back typed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EvalReport {
    #[serde(flatten)]
    pub run: RunHeader,
    pub error: String,
    pub scenes: Vec<SceneSpec>,
    pub rows: Vec<EvalRow>,
    pub summary: Vec<SummaryRow>,
    pub pareto_front: Vec<SummaryRow>,
    /// `--compare-texturing`: the summary of the post-scatter sweep (`rows`
    /// holds its rows too, marked); `summary` is then the pre-scatter one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub post_scatter_summary: Vec<SummaryRow>,
}

/// A view's scene: the embedded face, or the file (no textures given).
pub fn load(spec: &SceneSpec) -> Result<Scene> {
    match &spec.gltf {
        None => Ok(default_scene()),
        Some(p) => load_gltf_scene(p, &TextureOverrides::default(), None),
    }
}

/// The summary as the CLI prints it: cost, then err/none per band and the
/// interior's per-channel gain and FLIP; when some setting approximates
/// another profile than the six Gaussians, each profile's settings apart under
/// a line naming the truth they were scored against.
pub fn summary_table(summary: &[SummaryRow]) -> String {
    if summary.iter().all(|r| r.profile.is_six_gaussian()) {
        return summary_rows(summary);
    }
    let mut s = String::new();
    for p in Profile::ALL {
        let mine: Vec<SummaryRow> = summary.iter().filter(|r| r.profile == p).cloned().collect();
        if mine.is_empty() {
            continue;
        }
        s.push_str(&format!(
            "profile {}: err/none against its own ground truth (reference profile={})\n",
            p.name(),
            p.name()
        ));
        s.push_str(&summary_rows(&mine));
    }
    s
}

/// [`summary_table`]'s table of `summary`'s rows.
fn summary_rows(summary: &[SummaryRow]) -> String {
    let mut s = format!(
        "{:<12} {:<26} {:>8} {:>9} {:>9} {:>9} {:>17} {:>7}\n",
        "method", "setting", "SSS ms", "interior", "silhou.", "d.step", "gain R/G/B", "FLIP"
    );
    s.push_str(&format!(
        "{:<12} {:<26} {:>8} {:>29} {:>17} {:>7}\n",
        "", "", "", "--- err/none ---", "-- interior --", "interior"
    ));
    for r in summary {
        let [i, si, d] = Band::ALL.map(|b| r.band(b).err_none);
        let g = r.interior.gain;
        s.push_str(&format!(
            "{:<12} {:<26} {:>8.4} {:>9.3} {:>9.3} {:>9.3} {:>5.2}/{:>5.2}/{:>5.2} {:>7.4}\n",
            r.method, r.setting, r.gpu_ms, i, si, d, g[0], g[1], g[2], r.interior.flip
        ));
    }
    s
}

/// A band's errors averaged over the scenes where the band has pixels.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct BandMean {
    /// Scenes in which the band had pixels.
    pub scenes: usize,
    pub err_none: f64,
    pub gain: [f64; 3],
    pub flip: f64,
    pub rel_rmse: f64,
}

/// One (method, setting) over the scene set.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SummaryRow {
    pub method: String,
    pub setting: String,
    pub gpu_ms: f64,
    pub interior: BandMean,
    pub silhouette: BandMean,
    pub depth_step: BandMean,
    /// The profile whose truth the setting was scored against (absent: the
    /// six Gaussians).
    #[serde(default, skip_serializing_if = "Profile::is_six_gaussian")]
    pub profile: Profile,
}

impl SummaryRow {
    pub fn band(&self, band: Band) -> &BandMean {
        match band {
            Band::Interior => &self.interior,
            Band::Silhouette => &self.silhouette,
            Band::DepthStep => &self.depth_step,
        }
    }

    /// The chart's point for `band`: mean cost against the band's err/none.
    pub fn point(&self, band: Band) -> EvalPoint {
        EvalPoint {
            method: self.method.clone(),
            setting: self.setting.clone(),
            scene: "mean over scenes".into(),
            gpu_ms: self.gpu_ms,
            error: self.band(band).err_none,
        }
    }
}

/// Mean cost and per-band errors of each (method, setting) over the scenes.
pub fn summarise(rows: &[EvalRow]) -> Vec<SummaryRow> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows {
        let k = (r.point.method.clone(), r.point.setting.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(method, setting)| {
            let sel: Vec<&EvalRow> = rows
                .iter()
                .filter(|r| r.point.method == method && r.point.setting == setting)
                .collect();
            let mean_band = |band: Band| {
                let with: Vec<_> = sel
                    .iter()
                    .map(|r| r.bands.get(band))
                    .filter(|e| e.pixels > 0)
                    .collect();
                let n = with.len().max(1) as f64;
                let sum = |f: &dyn Fn(&super::bands::BandError) -> f64| {
                    with.iter().map(|e| f(e)).sum::<f64>() / n
                };
                BandMean {
                    scenes: with.len(),
                    err_none: sum(&|e| e.err_none.unwrap_or(0.0)),
                    gain: [0, 1, 2].map(|c| sum(&|e| e.gain.map_or(0.0, |g| g[c]))),
                    flip: sum(&|e| e.flip),
                    rel_rmse: sum(&|e| e.rel_rmse),
                }
            };
            SummaryRow {
                gpu_ms: sel.iter().map(|r| r.point.gpu_ms).sum::<f64>() / sel.len() as f64,
                interior: mean_band(Band::Interior),
                silhouette: mean_band(Band::Silhouette),
                depth_step: mean_band(Band::DepthStep),
                profile: sel.first().map_or(Profile::SixGaussian, |r| r.profile),
                method,
                setting,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::bands::BandError;
    use super::*;

    #[test]
    fn only_selects_a_method_or_one_setting_and_rejects_what_names_nothing() {
        let all = registry();
        assert_eq!(select(all.clone(), &[]).unwrap().len(), all.len());
        let gather = select(all.clone(), &["gather".into()]).unwrap();
        assert!(!gather.is_empty() && gather.iter().all(|c| c.method.name == "gather"));
        let one = select(
            all.clone(),
            &["gather/40 samples".into(), "disk/80 samples".into()],
        )
        .unwrap();
        let labels: Vec<_> = one.iter().map(|c| c.setting.label).collect();
        assert_eq!(labels, ["40 samples", "80 samples"]);
        assert!(select(all.clone(), &["gather/41 samples".into()]).is_err());
        assert!(select(all, &["no-such-method".into()]).is_err());
    }

    /// The leaf keys of a JSON value, nested keys joined by `_` and array
    /// elements named r, g, b (a gain); the bands' columns go by their keys
    /// under `bands` (`bands.interior.flip` is `interior_flip`).
    fn leaves(v: &serde_json::Value, at: &str, out: &mut Vec<String>) {
        let join = |k: &str| {
            if at.is_empty() || at == "bands" {
                k.to_string()
            } else {
                format!("{at}_{k}")
            }
        };
        match v {
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    leaves(x, &join(k), out);
                }
            }
            serde_json::Value::Array(a) => {
                for (x, c) in a.iter().zip(["r", "g", "b"]) {
                    leaves(x, &join(c), out);
                }
            }
            _ => out.push(at.to_string()),
        }
    }

    // eval.csv carries every column eval.json writes for a row, and a value
    // that eval.json leaves null is an empty field.
    #[test]
    fn eval_csv_has_every_column_of_eval_json() {
        let band = |x: f64| BandError {
            pixels: 10,
            rel_rmse: x,
            err_none: Some(x / 2.0),
            gain: Some([x, x * 2.0, x * 3.0]),
            flip: 0.25,
        };
        let mut row = EvalRow {
            point: EvalPoint {
                method: "separable".into(),
                setting: "strength=1,2,3".into(),
                scene: "procedural".into(),
                gpu_ms: 0.125,
                error: 0.3,
            },
            skin_pixels: 1234,
            frame_ms: 2.5,
            rel_rmse_all_skin: 0.1,
            bands: BandErrors {
                interior: band(0.1),
                silhouette: band(0.2),
                depth_step: band(0.4),
            },
            profile: Profile::SixGaussian,
            texturing: Texturing::Pre,
        };
        let mut json_keys = Vec::new();
        leaves(&serde_json::to_value(&row).unwrap(), "", &mut json_keys);
        let mut header = EvalRow::csv_header();
        assert_eq!(header.len(), json_keys.len(), "{header:?} vs {json_keys:?}");
        json_keys.sort();
        header.sort();
        assert_eq!(header, json_keys);
        // Each field holds its own value, at its header's place.
        let fields = row.csv_fields();
        let header = EvalRow::csv_header();
        let at = |k: &str| &fields[header.iter().position(|h| h == k).unwrap()];
        assert_eq!(at("depth_step_gain_b"), &(0.4f64 * 3.0).to_string());
        assert_eq!(at("silhouette_err_none"), "0.1");
        assert_eq!(at("skin_pixels"), "1234");
        row.bands.interior.err_none = None;
        row.bands.interior.gain = None;
        let fields = row.csv_fields();
        assert_eq!(
            fields[header
                .iter()
                .position(|h| h == "interior_err_none")
                .unwrap()],
            ""
        );
        assert_eq!(
            fields[header.iter().position(|h| h == "interior_gain_g").unwrap()],
            ""
        );
    }

    #[test]
    fn registry_covers_every_method_but_the_ground_truth() {
        let r = registry();
        for m in METHODS {
            assert_eq!(
                r.iter().any(|c| c.method == *m),
                !m.ground_truth,
                "{}",
                m.name
            );
        }
        // The separable sample counts of the thesis are all there.
        for n in ["9", "17", "33"] {
            let c = r
                .iter()
                .find(|c| c.setting.label == format!("{n} samples"))
                .unwrap();
            let s = RenderSettings::study().with(c.method, c.setting.options);
            assert_eq!(s.method.opts(&s.options).raw("samples"), n);
        }
    }

    #[test]
    fn dolly_goes_from_one_to_twenty_four_head_heights_in_equal_ratios() {
        let d = dolly_scenes(PathBuf::from("head.glb"));
        assert_eq!(d.len(), 12);
        assert!((d[0].distance_heads - 1.0).abs() < 1e-6);
        assert!((d[11].distance_heads - 24.0).abs() < 1e-3);
        let r = d[1].distance_heads / d[0].distance_heads;
        for w in d.windows(2) {
            assert!((w[1].distance_heads / w[0].distance_heads - r).abs() < 1e-4);
        }
        let mut names: Vec<&str> = d.iter().map(|s| s.name.as_str()).collect();
        names.dedup();
        assert_eq!(
            names.len(),
            12,
            "scene names must be unique: rows are matched by name"
        );
    }

    #[test]
    fn thesis_scene_set_is_three_distances_by_four_lights_plus_default() {
        let s = thesis_scenes(Some(PathBuf::from("head.glb")));
        assert_eq!(s.len(), 13);
        assert!((s[0].distance_heads - 28.0 / 27.0).abs() < 1e-6);
        assert_eq!(s.iter().filter(|x| x.azimuth_deg == 110.0).count(), 3);
        assert!(s.iter().all(|x| x.gltf.is_some() || x.name == "procedural"));
        assert_eq!(thesis_scenes(None).len(), 1);
    }

    #[test]
    fn summary_averages_per_setting() {
        use super::super::bands::BandError;
        let band = |pixels, e: f64| BandError {
            pixels,
            err_none: Some(e),
            gain: Some([e, 1.0, 1.0]),
            ..Default::default()
        };
        let row = |scene: &str, ms: f64, e: f64, depth_step_pixels| EvalRow {
            point: EvalPoint {
                method: "m".into(),
                setting: "s".into(),
                scene: scene.into(),
                gpu_ms: ms,
                error: e,
            },
            skin_pixels: 1,
            frame_ms: 0.0,
            rel_rmse_all_skin: 0.0,
            bands: BandErrors {
                interior: band(10, e),
                silhouette: band(3, 2.0 * e),
                depth_step: band(depth_step_pixels, 5.0),
            },
            profile: Profile::SixGaussian,
            texturing: Texturing::Pre,
        };
        let s = summarise(&[row("a", 1.0, 0.1, 0), row("b", 3.0, 0.3, 2)]);
        assert_eq!(s.len(), 1);
        assert!((s[0].gpu_ms - 2.0).abs() < 1e-12);
        assert!((s[0].interior.err_none - 0.2).abs() < 1e-12);
        assert!((s[0].point(Band::Interior).error - 0.2).abs() < 1e-12);
        assert!((s[0].silhouette.err_none - 0.4).abs() < 1e-12);
        assert!((s[0].interior.gain[0] - 0.2).abs() < 1e-12);
        // A band without pixels in a scene does not pull its mean to zero.
        assert_eq!(s[0].depth_step.scenes, 1);
        assert!((s[0].depth_step.err_none - 5.0).abs() < 1e-12);
        assert!(summary_table(&s).contains("interior"));
        // Only the six Gaussians: the table and eval.json are as before
        // there were two profiles.
        assert!(!summary_table(&s).contains("profile"));
        assert!(!serde_json::to_string(&s[0]).unwrap().contains("profile"));
        // A Burley setting: each profile's rows apart, eval.json says which.
        let mut b = row("a", 1.0, 0.1, 0);
        b.point.setting = "t".into();
        b.profile = Profile::Burley;
        let s = summarise(&[row("a", 1.0, 0.1, 0), b]);
        assert_eq!(s[1].profile, Profile::Burley);
        let table = summary_table(&s);
        let (six, burley) = table.split_once("profile burley").unwrap();
        assert!(
            six.contains("profile six-gaussian") && six.contains(" s "),
            "{table}"
        );
        assert!(burley.contains(" t ") && !burley.contains(" s "), "{table}");
        let json = serde_json::to_string(&s[1]).unwrap();
        assert!(json.contains("\"profile\":\"burley\""), "{json}");
        let back: SummaryRow = serde_json::from_str(&json).unwrap();
        assert_eq!(back.profile, Profile::Burley);
    }
}
