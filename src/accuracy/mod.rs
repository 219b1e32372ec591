//! The accuracy model: how wrong each method setting is (err/none over the
//! interior and silhouette bands, as `dermis eval` scores it) as a function of
//! the character's scale on screen (pixels per millimetre at its depth), the
//! key light's angle and the shadow map's texel at the character (a crowd's
//! map spans every character, so its texel is wider than one head's), read
//! from the table `dermis eval --scenes accuracy` measured against the ground
//! truth (`profiles/accuracy/`).
//!
//! Between measured scales the model is linear in log px/mm, between measured
//! light angles linear in degrees, between measured shadow texels linear in
//! log mm; outside the measured scales or beyond the widest measured texel it
//! predicts nothing (a planner must not pick a setting where it was never
//! measured), outside the measured light angles it holds the nearest one, and
//! below the finest texel the finest. Pure: no
//! Vulkan, no graph, no registry (the data names methods and settings; the
//! tests check that it covers the registry).

pub mod data;
pub mod loso;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};

pub use data::Row;

/// Predicted err/none of a setting at a scale and light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Predicted {
    pub interior: f64,
    pub silhouette: f64,
}

/// Which head the table was measured on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Asset {
    /// The Lee Perry-Smith head scan.
    Scan,
    /// The embedded procedural face.
    Procedural,
}

impl Asset {
    pub const ALL: [Asset; 2] = [Asset::Scan, Asset::Procedural];

    /// Its name in the data file.
    pub fn name(self) -> &'static str {
        match self {
            Asset::Scan => "scan",
            Asset::Procedural => "procedural",
        }
    }

    pub fn parse(s: &str) -> Result<Asset> {
        match s {
            "scan" => Ok(Asset::Scan),
            "procedural" => Ok(Asset::Procedural),
            other => bail!("unknown asset '{other}' (valid: scan, procedural)"),
        }
    }
}

/// Relative tolerance within which two scales or angles are the same point
/// (the sweep writes each scene's value once, so equal points are equal bits;
/// the tolerance only forgives a hand-edited file's rounding).
const SAME: f64 = 1e-9;

/// One setting's measured grid: every scale at every light and shadow texel.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub asset: Asset,
    pub method: String,
    pub setting: String,
    /// Measured scales, ascending.
    pub scales: Vec<f64>,
    /// Measured light angles, ascending.
    pub lights: Vec<f64>,
    /// Measured shadow-map texels at the character (mm), ascending.
    pub shadows: Vec<f64>,
    /// `interior[shadow][light][scale]`.
    pub interior: Vec<Vec<Vec<f64>>>,
    /// `silhouette[shadow][light][scale]`: where a frame had no silhouette
    /// pixels, the value at the nearest scale of the same light and shadow
    /// that had (marked in `silhouette_measured`).
    pub silhouette: Vec<Vec<Vec<f64>>>,
    pub silhouette_measured: Vec<Vec<Vec<bool>>>,
}

impl Curve {
    /// The grid of one setting's rows; every (scale, light, shadow) triple
    /// exactly once.
    fn from_rows(rows: &[&Row]) -> Result<Curve> {
        let first = rows.first().context("a setting without rows")?;
        let name = format!(
            "{} {} '{}'",
            first.asset.name(),
            first.method,
            first.setting
        );
        let scales = distinct(rows.iter().map(|r| r.px_per_mm));
        let lights = distinct(rows.iter().map(|r| r.light_deg));
        let shadows = distinct(rows.iter().map(|r| r.shadow_mm));
        let (ns, nl, nk) = (scales.len(), lights.len(), shadows.len());
        let mut interior = vec![vec![vec![None; ns]; nl]; nk];
        let mut sil = vec![vec![vec![None; ns]; nl]; nk];
        for r in rows {
            let (i, j, k) = (
                index(&scales, r.px_per_mm),
                index(&lights, r.light_deg),
                index(&shadows, r.shadow_mm),
            );
            if interior[k][j][i].is_some() {
                bail!(
                    "accuracy data: {name} has two rows at {} px/mm, light {} deg, shadow texel {} mm",
                    r.px_per_mm,
                    r.light_deg,
                    r.shadow_mm
                );
            }
            interior[k][j][i] = Some(r.interior);
            sil[k][j][i] = r.silhouette;
        }
        let mut measured = vec![vec![vec![false; ns]; nl]; nk];
        let mut silhouette = vec![vec![vec![0.0; ns]; nl]; nk];
        for k in 0..nk {
            for j in 0..nl {
                for i in 0..ns {
                    if interior[k][j][i].is_none() {
                        bail!(
                            "accuracy data: {name} has no row at {} px/mm, light {} deg, shadow texel {} mm (every scale needs every light and shadow)",
                            scales[i],
                            lights[j],
                            shadows[k]
                        );
                    }
                    measured[k][j][i] = sil[k][j][i].is_some();
                }
                // The nearest measured scale (in log px/mm) of the same light and shadow.
                for i in 0..ns {
                    let nearest = (0..ns)
                        .filter(|&q| sil[k][j][q].is_some())
                        .min_by(|&a, &b| {
                            let d = |q: usize| (scales[q] / scales[i]).ln().abs();
                            d(a).total_cmp(&d(b))
                        })
                        .with_context(|| {
                            format!(
                                "accuracy data: {name} has no silhouette at any scale at light {} deg, shadow texel {} mm",
                                lights[j], shadows[k]
                            )
                        })?;
                    silhouette[k][j][i] = sil[k][j][nearest].unwrap_or_default();
                }
            }
        }
        let unwrap = |g: Vec<Vec<Vec<Option<f64>>>>| -> Vec<Vec<Vec<f64>>> {
            g.into_iter()
                .map(|l| {
                    l.into_iter()
                        .map(|v| v.into_iter().map(Option::unwrap_or_default).collect())
                        .collect()
                })
                .collect()
        };
        Ok(Curve {
            asset: first.asset,
            method: first.method.clone(),
            setting: first.setting.clone(),
            scales,
            lights,
            shadows,
            interior: unwrap(interior),
            silhouette,
            silhouette_measured: measured,
        })
    }

    /// The interpolated errors at `px_per_mm`, `light_deg` and a shadow texel
    /// of `shadow_mm`; `None` outside the measured scales, beyond the widest
    /// measured shadow texel, or for a value that is not a number. A texel
    /// finer than the finest measured takes the finest's errors: a sharper
    /// shadow only leaves SSS more to do, so the held value errs on the
    /// pessimistic side (measured: docs/accuracy.md, "The shadow axis").
    pub fn predict(&self, px_per_mm: f64, light_deg: f64, shadow_mm: f64) -> Option<Predicted> {
        let (i, wi) = scale_weight(&self.scales, px_per_mm)?;
        let (j, wj) = light_weight(&self.lights, light_deg)?;
        let (k, wk) = shadow_weight(&self.shadows, shadow_mm)?;
        let at = |g: &Vec<Vec<Vec<f64>>>| {
            let up = |n: usize, x: usize| (x + 1).min(n - 1);
            let row = |k: usize, j: usize| {
                let r = &g[k][j];
                lerp(r[i], r[up(r.len(), i)], wi)
            };
            let plane = |k: usize| lerp(row(k, j), row(k, up(g[k].len(), j)), wj);
            lerp(plane(k), plane(up(g.len(), k)), wk)
        };
        Some(Predicted {
            interior: at(&self.interior),
            silhouette: at(&self.silhouette),
        })
    }

    /// This curve without scale `q` (the leave-one-scale-out test).
    pub fn without_scale(&self, q: usize) -> Curve {
        let drop = |v: &Vec<Vec<Vec<f64>>>| -> Vec<Vec<Vec<f64>>> {
            v.iter()
                .map(|k| {
                    k.iter()
                        .map(|l| {
                            l.iter()
                                .enumerate()
                                .filter(|&(i, _)| i != q)
                                .map(|(_, &x)| x)
                                .collect()
                        })
                        .collect()
                })
                .collect()
        };
        let mut c = self.clone();
        c.scales.remove(q);
        c.interior = drop(&self.interior);
        c.silhouette = drop(&self.silhouette);
        for k in &mut c.silhouette_measured {
            for l in k {
                l.remove(q);
            }
        }
        c
    }

    /// This curve without shadow texel `q` (the leave-one-shadow-out test).
    pub fn without_shadow(&self, q: usize) -> Curve {
        let mut c = self.clone();
        c.shadows.remove(q);
        c.interior.remove(q);
        c.silhouette.remove(q);
        c.silhouette_measured.remove(q);
        c
    }
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    if t == 0.0 {
        a
    } else {
        a + (b - a) * t
    }
}

/// The distinct values, ascending (equal within [`SAME`]).
fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| same(*a, *b));
    v
}

fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME * a.abs().max(b.abs()).max(1.0)
}

fn index(grid: &[f64], x: f64) -> usize {
    grid.iter().position(|&g| same(g, x)).unwrap_or(0)
}

/// The measured scale at or below `p` and the weight of the next one, linear
/// in log px/mm; `None` outside the measured range.
fn scale_weight(scales: &[f64], p: f64) -> Option<(usize, f64)> {
    let (&lo, &hi) = (scales.first()?, scales.last()?);
    if !p.is_finite() || p <= 0.0 {
        return None;
    }
    if let Some(i) = scales.iter().position(|&s| same(s, p)) {
        return Some((i, 0.0));
    }
    if p < lo || p > hi {
        return None;
    }
    let i = scales.iter().rposition(|&s| s < p)?;
    let (a, b) = (scales[i], scales[i + 1]);
    Some((i, (p / a).ln() / (b / a).ln()))
}

/// The light angle folded into 0..=180 (an angle is the same either way
/// round), held at the measured ends, and its bracket's weight.
fn light_weight(lights: &[f64], deg: f64) -> Option<(usize, f64)> {
    if !deg.is_finite() {
        return None;
    }
    let mut a = deg.abs() % 360.0;
    if a > 180.0 {
        a = 360.0 - a;
    }
    let (&lo, &hi) = (lights.first()?, lights.last()?);
    let a = a.clamp(lo, hi);
    if let Some(j) = lights.iter().position(|&l| same(l, a)) {
        return Some((j, 0.0));
    }
    let j = lights.iter().rposition(|&l| l < a)?;
    Some((j, (a - lights[j]) / (lights[j + 1] - lights[j])))
}

/// The measured shadow texel at or below `mm` and the weight of the next one,
/// linear in log mm; finer than the finest measured holds it, wider than the
/// widest is `None`.
fn shadow_weight(shadows: &[f64], mm: f64) -> Option<(usize, f64)> {
    let (&lo, &hi) = (shadows.first()?, shadows.last()?);
    if !mm.is_finite() || mm <= 0.0 {
        return None;
    }
    if let Some(k) = shadows.iter().position(|&s| same(s, mm)) {
        return Some((k, 0.0));
    }
    if mm < lo {
        return Some((0, 0.0));
    }
    if mm > hi {
        return None;
    }
    let k = shadows.iter().rposition(|&s| s < mm)?;
    let (a, b) = (shadows[k], shadows[k + 1]);
    Some((k, (mm / a).ln() / (b / a).ln()))
}

/// The measured table, one [`Curve`] per (asset, method, setting).
#[derive(Clone, Debug)]
pub struct AccuracyModel {
    pub curves: Vec<Curve>,
    /// The header of each file read (command, device, frame).
    pub headers: Vec<data::Header>,
}

/// The project's data in the source tree: `profiles/accuracy/` beside
/// Cargo.toml (where `eval --scenes accuracy`'s files are copied to; the
/// commands read the copies built into the binary).
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/accuracy")
}

/// The embedded folder of the project's data.
const EMBEDDED_DIR: &str = "profiles/accuracy";

impl AccuracyModel {
    /// The project's data file(s) as built into the binary: every `*.toml`
    /// of `profiles/accuracy/`, by name.
    pub fn load_default() -> Result<AccuracyModel> {
        let files = crate::embedded::files_in(EMBEDDED_DIR, ".toml");
        if files.is_empty() {
            bail!("accuracy data: no *.toml in the binary's {EMBEDDED_DIR}");
        }
        let mut rows = Vec::new();
        let mut headers = Vec::new();
        for (name, text) in files {
            let (h, r) = data::parse(text, &format!("{EMBEDDED_DIR}/{name}"))?;
            headers.push(h);
            rows.extend(r);
        }
        let mut m = AccuracyModel::from_rows(&rows)
            .with_context(|| format!("reading the binary's {EMBEDDED_DIR}"))?;
        m.headers = headers;
        Ok(m)
    }

    /// A data file, or a folder of them (every `*.toml` in it, by name).
    pub fn load(path: &Path) -> Result<AccuracyModel> {
        let files: Vec<PathBuf> = if path.is_dir() {
            let mut v: Vec<PathBuf> = std::fs::read_dir(path)
                .with_context(|| format!("listing {}", path.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect();
            v.sort();
            if v.is_empty() {
                bail!("accuracy data: no *.toml in {}", path.display());
            }
            v
        } else {
            vec![path.to_path_buf()]
        };
        let mut rows = Vec::new();
        let mut headers = Vec::new();
        for f in &files {
            let (h, r) = data::read(f)?;
            headers.push(h);
            rows.extend(r);
        }
        let mut m = AccuracyModel::from_rows(&rows)
            .with_context(|| format!("reading {}", path.display()))?;
        m.headers = headers;
        Ok(m)
    }

    /// The model of measured rows (in any order; settings keep their first
    /// row's order).
    pub fn from_rows(rows: &[Row]) -> Result<AccuracyModel> {
        let mut keys: Vec<(Asset, &str, &str)> = Vec::new();
        for r in rows {
            let k = (r.asset, r.method.as_str(), r.setting.as_str());
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        let curves = keys
            .iter()
            .map(|&(a, m, s)| {
                let sel: Vec<&Row> = rows
                    .iter()
                    .filter(|r| r.asset == a && r.method == m && r.setting == s)
                    .collect();
                Curve::from_rows(&sel)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(AccuracyModel {
            curves,
            headers: Vec::new(),
        })
    }

    pub fn curve(&self, asset: Asset, method: &str, setting: &str) -> Option<&Curve> {
        self.curves
            .iter()
            .find(|c| c.asset == asset && c.method == method && c.setting == setting)
    }

    /// Predicted err/none; `None` for a setting not measured on `asset`, a
    /// scale outside its measured range or a shadow texel wider than measured.
    pub fn predict(
        &self,
        asset: Asset,
        method: &str,
        setting: &str,
        px_per_mm: f64,
        light_deg: f64,
        shadow_mm: f64,
    ) -> Option<Predicted> {
        self.curve(asset, method, setting)?
            .predict(px_per_mm, light_deg, shadow_mm)
    }

    /// The widest shadow texel (mm) measured for a setting.
    pub fn widest_shadow_mm(&self, asset: Asset, method: &str, setting: &str) -> Option<f64> {
        self.curve(asset, method, setting)?.shadows.last().copied()
    }

    /// The measured px/mm range (smallest, largest) of a setting.
    pub fn range(&self, asset: Asset, method: &str, setting: &str) -> Option<(f64, f64)> {
        let c = self.curve(asset, method, setting)?;
        Some((*c.scales.first()?, *c.scales.last()?))
    }

    /// Every (method, setting label) measured on `asset`, in the data's order.
    pub fn settings(&self, asset: Asset) -> Vec<(String, String)> {
        self.curves
            .iter()
            .filter(|c| c.asset == asset)
            .map(|c| (c.method.clone(), c.setting.clone()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The finest of the two measured shadow texels (mm); the other is 4x.
    const FINE: f64 = 0.25;

    /// A setting measured at 1, 2, 4 px/mm, lights 30 and 90 degrees and
    /// shadow texels 0.25 and 1 mm: interior = scale index + light / 100
    /// (+ 100 at the wide texel, + 10 on the procedural face), silhouette
    /// measured only below 4 px/mm.
    fn rows() -> Vec<Row> {
        let mut v = Vec::new();
        for asset in Asset::ALL {
            for (k, sh) in [FINE, 4.0 * FINE].into_iter().enumerate() {
                for (i, p) in [1.0, 2.0, 4.0].into_iter().enumerate() {
                    for l in [30.0, 90.0] {
                        let base = if asset == Asset::Procedural {
                            10.0
                        } else {
                            0.0
                        } + 100.0 * k as f64;
                        v.push(Row {
                            asset,
                            method: "ssg".into(),
                            setting: "4 Gaussians, LOD".into(),
                            px_per_mm: p,
                            light_deg: l,
                            shadow_mm: sh,
                            interior: base + i as f64 + l / 100.0,
                            silhouette: (p < 3.0).then_some(5.0 + i as f64),
                        });
                    }
                }
            }
        }
        v
    }

    fn model() -> AccuracyModel {
        AccuracyModel::from_rows(&rows()).unwrap()
    }

    #[test]
    fn exact_at_measured_points() {
        let m = model();
        for r in rows() {
            let p = m
                .predict(
                    r.asset,
                    &r.method,
                    &r.setting,
                    r.px_per_mm,
                    r.light_deg,
                    r.shadow_mm,
                )
                .unwrap();
            assert_eq!(p.interior, r.interior, "{r:?}");
            if let Some(s) = r.silhouette {
                assert_eq!(p.silhouette, s);
            }
        }
    }

    #[test]
    fn linear_in_log_scale_and_in_angle_between() {
        let m = model();
        let p = |px: f64, l: f64| {
            m.predict(Asset::Scan, "ssg", "4 Gaussians, LOD", px, l, FINE)
                .unwrap()
        };
        // sqrt(2) is halfway between 1 and 2 in log px/mm.
        assert!((p(2f64.sqrt(), 30.0).interior - 0.8).abs() < 1e-12);
        // 2^(1/4): a quarter of the way.
        assert!((p(2f64.powf(0.25), 30.0).interior - 0.55).abs() < 1e-12);
        // 60 degrees: halfway between 30 and 90 (0.3 and 0.9).
        assert!((p(1.0, 60.0).interior - 0.6).abs() < 1e-12);
        // Both at once: bilinear.
        assert!((p(2f64.sqrt() * 2.0, 45.0).interior - (1.5 + 0.45)).abs() < 1e-12);
        // The procedural face has its own curve.
        let q = m
            .predict(
                Asset::Procedural,
                "ssg",
                "4 Gaussians, LOD",
                1.0,
                30.0,
                FINE,
            )
            .unwrap();
        assert!((q.interior - 10.3).abs() < 1e-12);
    }

    #[test]
    fn linear_in_log_shadow_texel_held_below_and_nothing_beyond() {
        let m = model();
        let p = |sh: f64| {
            m.predict(Asset::Scan, "ssg", "4 Gaussians, LOD", 1.0, 30.0, sh)
                .map(|p| p.interior)
        };
        // 0.5 mm is halfway between 0.25 and 1 in log mm: 0.3 and 100.3.
        assert!((p(0.5).unwrap() - 50.3).abs() < 1e-9);
        // Sharper than measured: the finest texel's value.
        assert_eq!(p(0.01), p(FINE));
        // Wider than measured: no prediction.
        assert!(p(1.001).is_none());
        assert!(p(0.0).is_none() && p(f64::NAN).is_none());
        assert_eq!(
            m.widest_shadow_mm(Asset::Scan, "ssg", "4 Gaussians, LOD"),
            Some(1.0)
        );
        let c = m.curve(Asset::Scan, "ssg", "4 Gaussians, LOD").unwrap();
        let one = c.without_shadow(1);
        assert_eq!(one.shadows, vec![FINE]);
        assert!(one.predict(1.0, 30.0, 1.0).is_none());
        assert!((one.predict(1.0, 30.0, 0.1).unwrap().interior - 0.3).abs() < 1e-12);
    }

    #[test]
    fn nothing_outside_the_measured_scales() {
        let m = model();
        let p = |px: f64| m.predict(Asset::Scan, "ssg", "4 Gaussians, LOD", px, 30.0, FINE);
        assert!(p(0.999).is_none());
        assert!(p(4.001).is_none());
        assert!(p(0.0).is_none() && p(-1.0).is_none() && p(f64::NAN).is_none());
        assert!(p(f64::INFINITY).is_none());
        assert!(p(1.0).is_some() && p(4.0).is_some());
        assert_eq!(
            m.range(Asset::Scan, "ssg", "4 Gaussians, LOD"),
            Some((1.0, 4.0))
        );
        assert!(m
            .predict(Asset::Scan, "ssg", "6 Gaussians", 2.0, 30.0, FINE)
            .is_none());
        assert!(m.range(Asset::Scan, "tsd", "-").is_none());
    }

    #[test]
    fn light_angles_fold_and_clamp() {
        let m = model();
        let p = |l: f64| {
            m.predict(Asset::Scan, "ssg", "4 Gaussians, LOD", 2.0, l, FINE)
                .unwrap()
                .interior
        };
        // Either way round, and a full turn, is the same angle.
        assert_eq!(p(-60.0), p(60.0));
        assert_eq!(p(300.0), p(60.0));
        assert_eq!(p(420.0), p(60.0));
        // Beyond the measured angles: the nearest one.
        assert_eq!(p(0.0), p(30.0));
        assert_eq!(p(180.0), p(90.0));
        assert!(m
            .predict(Asset::Scan, "ssg", "4 Gaussians, LOD", 2.0, f64::NAN, FINE)
            .is_none());
    }

    #[test]
    fn a_missing_silhouette_takes_the_nearest_measured_scale() {
        let m = model();
        let c = m.curve(Asset::Scan, "ssg", "4 Gaussians, LOD").unwrap();
        assert_eq!(c.silhouette_measured[0][0], vec![true, true, false]);
        let p = m
            .predict(Asset::Scan, "ssg", "4 Gaussians, LOD", 4.0, 30.0, FINE)
            .unwrap();
        assert_eq!(p.silhouette, 6.0);
    }

    #[test]
    fn settings_are_listed_per_asset_and_grids_must_be_whole() {
        let m = model();
        assert_eq!(
            m.settings(Asset::Scan),
            vec![("ssg".to_string(), "4 Gaussians, LOD".to_string())]
        );
        let mut r = rows();
        r.remove(3);
        let e = AccuracyModel::from_rows(&r).unwrap_err().to_string();
        assert!(
            e.contains("no row at 2 px/mm, light 90 deg, shadow texel 0.25 mm"),
            "{e}"
        );
        let mut r = rows();
        r.push(r[0].clone());
        let e = AccuracyModel::from_rows(&r).unwrap_err().to_string();
        assert!(e.contains("two rows"), "{e}");
    }

    #[test]
    fn a_malformed_file_is_a_one_line_error() {
        let dir = crate::scene::gltf_load::fixture::temp_dir("accuracy");
        let f = dir.join("bad.toml");
        std::fs::write(&f, "command = \"c\"\nrows = [ { asset = \"scan\" ").unwrap();
        let e = format!("{:#}", AccuracyModel::load(&f).unwrap_err());
        assert!(e.contains("bad.toml"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        assert!(AccuracyModel::load(&dir.join("absent.toml")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
