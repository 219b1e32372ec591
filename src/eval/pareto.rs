//! Cost/error points of every (method, setting, scene) run, their Pareto front,
//! and CSV export (eval.csv's writer).
//!
//! Why a front: no single SSS method wins on both GPU time and accuracy; the
//! useful answer is which settings are worth using at all (those no other
//! setting beats on both), and the front is exactly that set.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

/// One measured configuration: what it cost on the GPU and how far it is from
/// the ground truth.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct EvalPoint {
    /// SSS method, e.g. `separable`, `ssg`, `ss-jittered`, `poisson`.
    pub method: String,
    /// The method's quality setting, e.g. `17 samples`.
    pub setting: String,
    /// Scene or shot the point was measured on.
    pub scene: String,
    /// GPU time of the method's passes, milliseconds.
    pub gpu_ms: f64,
    /// Error against the ground truth (e.g. relative RMSE or mean FLIP).
    pub error: f64,
}

/// Indices of the points no other point dominates, sorted by cost (then error,
/// then index, so the order is deterministic).
///
/// `a` dominates `b` when `a.gpu_ms <= b.gpu_ms`, `a.error <= b.error` and at
/// least one is strictly less. Exact ties therefore dominate neither way and
/// both stay on the front: two settings that measure the same are equally
/// worth reporting. Points with a NaN cost or error cannot be compared and are
/// left off the front (they also dominate nothing).
///
/// Quadratic, which is fine for the tens of points an evaluation produces and
/// keeps the rule readable.
pub fn pareto_front(points: &[EvalPoint]) -> Vec<usize> {
    let comparable = |p: &EvalPoint| !p.gpu_ms.is_nan() && !p.error.is_nan();
    let dominates = |a: &EvalPoint, b: &EvalPoint| {
        a.gpu_ms <= b.gpu_ms && a.error <= b.error && (a.gpu_ms < b.gpu_ms || a.error < b.error)
    };
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| comparable(&points[i]))
        .filter(|&i| {
            !points
                .iter()
                .any(|other| comparable(other) && dominates(other, &points[i]))
        })
        .collect();
    front.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        pa.gpu_ms
            .total_cmp(&pb.gpu_ms)
            .then(pa.error.total_cmp(&pb.error))
            .then(a.cmp(&b))
    });
    front
}

/// Writes a header and rows of fields as CSV, creating the parent folder if
/// needed.
///
/// Fields holding a comma, a double quote or a line break are quoted
/// (RFC 4180, quotes doubled), so settings such as `strength=0.48,0.41,0.28`
/// survive a spreadsheet. Callers format numbers with Rust's shortest
/// round-trip form (`to_string`), so reading the file back gives the same f64s.
pub fn write_table<H: AsRef<str>>(path: &Path, header: &[H], rows: &[Vec<String>]) -> Result<()> {
    let line = |fields: &mut dyn Iterator<Item = &str>| {
        fields.map(csv_field).collect::<Vec<_>>().join(",")
    };
    let mut out = line(&mut header.iter().map(|h| h.as_ref()));
    out.push('\n');
    for r in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(out, "{}", line(&mut r.iter().map(String::as_str)));
    }
    crate::output::write_bytes(path, out.as_bytes())
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(method: &str, gpu_ms: f64, error: f64) -> EvalPoint {
        EvalPoint {
            method: method.into(),
            setting: "s".into(),
            scene: "head".into(),
            gpu_ms,
            error,
        }
    }

    #[test]
    fn dominated_point_is_excluded_and_front_sorted_by_cost() {
        let points = vec![
            pt("slow-good", 3.0, 0.01),
            pt("dominated", 2.0, 0.2), // beaten by "mid" on both
            pt("fast-bad", 0.5, 0.3),
            pt("mid", 1.5, 0.1),
            pt("same-cost-worse", 1.5, 0.15), // equal cost, worse error
        ];
        assert_eq!(pareto_front(&points), vec![2, 3, 0]);
    }

    #[test]
    fn exact_ties_both_stay() {
        let points = vec![pt("a", 1.0, 0.1), pt("b", 1.0, 0.1), pt("c", 2.0, 0.1)];
        // c has equal error but higher cost: dominated.
        assert_eq!(pareto_front(&points), vec![0, 1]);
    }

    #[test]
    fn nan_points_and_empty_input() {
        assert!(pareto_front(&[]).is_empty());
        let points = vec![pt("nan", f64::NAN, 0.0), pt("ok", 1.0, 0.5)];
        assert_eq!(pareto_front(&points), vec![1]);
        assert_eq!(pareto_front(&[pt("only", 1.0, 1.0)]), vec![0]);
    }

    /// Minimal RFC 4180 reader, enough to check what `write_table` wrote.
    fn parse_csv(text: &str) -> Vec<Vec<String>> {
        let mut rows = Vec::new();
        let (mut row, mut field) = (Vec::new(), String::new());
        let mut chars = text.chars().peekable();
        let mut quoted = false;
        while let Some(c) = chars.next() {
            match (quoted, c) {
                (true, '"') if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                (true, '"') => quoted = false,
                (true, c) => field.push(c),
                (false, '"') => quoted = true,
                (false, ',') => row.push(std::mem::take(&mut field)),
                (false, '\n') => {
                    row.push(std::mem::take(&mut field));
                    rows.push(std::mem::take(&mut row));
                }
                (false, c) => field.push(c),
            }
        }
        rows
    }

    #[test]
    fn csv_round_trips() {
        let dir = crate::scene::gltf_load::fixture::temp_dir("pareto");
        let path = dir.join("sub").join("points.csv");
        let mut points = vec![
            pt("separable", 0.125, 0.0123456789),
            pt("poisson", 1e-3, 2.5),
        ];
        points[0].setting = "strength=0.48,0.41,0.28".into();
        points[1].scene = "lps \"close\"".into();
        let fields: Vec<Vec<String>> = points
            .iter()
            .map(|p| {
                let n = [p.gpu_ms, p.error].map(|v| v.to_string());
                vec![
                    p.method.clone(),
                    p.setting.clone(),
                    p.scene.clone(),
                    n[0].clone(),
                    n[1].clone(),
                ]
            })
            .collect();
        write_table(
            &path,
            &["method", "setting", "scene", "gpu_ms", "error"],
            &fields,
        )
        .unwrap();
        let rows = parse_csv(&std::fs::read_to_string(&path).unwrap());
        assert_eq!(rows[0], ["method", "setting", "scene", "gpu_ms", "error"]);
        assert_eq!(rows.len(), 3);
        for (row, p) in rows[1..].iter().zip(&points) {
            assert_eq!(row.len(), 5);
            assert_eq!(row[0], p.method);
            assert_eq!(row[1], p.setting);
            assert_eq!(row[2], p.scene);
            assert_eq!(row[3].parse::<f64>().unwrap(), p.gpu_ms);
            assert_eq!(row[4].parse::<f64>().unwrap(), p.error);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_unwritable_path_errors() {
        let dir = crate::scene::gltf_load::fixture::temp_dir("pareto-nw");
        // A path whose "parent" is a regular file cannot be created.
        let file = dir.join("file");
        std::fs::write(&file, "x").unwrap();
        let err = write_table(&file.join("points.csv"), &["a"], &[]).unwrap_err();
        assert!(format!("{err:#}").contains("file"), "{err:#}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
