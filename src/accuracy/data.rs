//! The accuracy model's data file: what `dermis eval --scenes accuracy`
//! measured, one row per (asset, method, setting, scale, light, shadow
//! texel), as TOML.
//!
//! TOML because it carries comments (the command that regenerates the file
//! heads it) and the project's other data (`profiles/*.toml`) is TOML; one
//! inline table per row keeps a thousand rows a thousand lines.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use serde::Deserialize;

use super::Asset;

/// Largest data file read (the measured table is about 150 KB).
pub const MAX_BYTES: u64 = 16 << 20;

/// One measured point.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub asset: Asset,
    pub method: String,
    /// The eval setting's label (`method::METHODS[..].eval`).
    pub setting: String,
    /// Pixels per millimetre at the head centre's depth.
    pub px_per_mm: f64,
    /// Angle between the key light's direction and the direction from the
    /// character to the camera, 0..=180 degrees.
    pub light_deg: f64,
    /// Width of a shadow-map texel at the character, mm (the map is fitted to
    /// every character's bounds, so a crowd's texel is wider than one head's).
    pub shadow_mm: f64,
    /// err/none over the interior band.
    pub interior: f64,
    /// err/none over the silhouette band; `None` where the frame had no
    /// silhouette pixels (a close view's frame is all skin).
    pub silhouette: Option<f64>,
}

/// What heads a data file: how it was made.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Header {
    /// The command line that regenerates the rows.
    pub command: String,
    /// The device that ran it.
    pub device: String,
    /// The frame: size, field of view, how the scale was reached.
    pub frame: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileIn {
    command: String,
    device: String,
    frame: String,
    rows: Vec<RowIn>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RowIn {
    asset: String,
    method: String,
    setting: String,
    px_per_mm: f64,
    light_deg: f64,
    shadow_mm: f64,
    interior: f64,
    silhouette: Option<f64>,
}

/// Reads one data file through the files door.
pub fn read(path: &Path) -> Result<(Header, Vec<Row>)> {
    let text = crate::files::read_text(path, "accuracy data", MAX_BYTES)?;
    parse(&text, &path.display().to_string())
}

/// Parses a data file's text; `file` names it in errors (one line each).
pub fn parse(text: &str, file: &str) -> Result<(Header, Vec<Row>)> {
    let f: FileIn = toml::from_str(text).map_err(|e| anyhow!(one_line(file, text, &e)))?;
    let mut rows = Vec::with_capacity(f.rows.len());
    for (i, r) in f.rows.into_iter().enumerate() {
        let at = || format!("{file}: row {}", i + 1);
        let asset = Asset::parse(&r.asset).map_err(|e| anyhow!("{}: {e}", at()))?;
        if !(r.px_per_mm.is_finite() && r.px_per_mm > 0.0) {
            bail!(
                "{}: px_per_mm must be a positive number, got {}",
                at(),
                r.px_per_mm
            );
        }
        if !(0.0..=180.0).contains(&r.light_deg) {
            bail!(
                "{}: light_deg must be within 0..=180, got {}",
                at(),
                r.light_deg
            );
        }
        if !(r.shadow_mm.is_finite() && r.shadow_mm > 0.0) {
            bail!(
                "{}: shadow_mm must be a positive number, got {}",
                at(),
                r.shadow_mm
            );
        }
        for (band, v) in [("interior", Some(r.interior)), ("silhouette", r.silhouette)] {
            if let Some(v) = v {
                if !(v.is_finite() && v >= 0.0) {
                    bail!("{}: {band} err/none must be a number >= 0, got {v}", at());
                }
            }
        }
        rows.push(Row {
            asset,
            method: r.method,
            setting: r.setting,
            px_per_mm: r.px_per_mm,
            light_deg: r.light_deg,
            shadow_mm: r.shadow_mm,
            interior: r.interior,
            silhouette: r.silhouette,
        });
    }
    let header = Header {
        command: f.command,
        device: f.device,
        frame: f.frame,
    };
    Ok((header, rows))
}

/// The file's text: a comment saying what it is and how to regenerate it,
/// the header's fields, then one inline table per row. Numbers are written in
/// Rust's shortest round-trip form, so [`parse`] gives back the same values.
pub fn to_toml(header: &Header, rows: &[Row]) -> Result<String> {
    let mut s = String::new();
    s.push_str(
        "# The accuracy model's data (src/accuracy/, docs/accuracy.md \"The accuracy model\"):\n",
    );
    s.push_str(
        "# err/none (0 perfect, 1 no better than no SSS) per asset, method, eval setting,\n",
    );
    s.push_str(
        "# scale (px/mm at the head centre's depth) and key-light angle (degrees between the\n",
    );
    s.push_str(
        "# light and the direction to the camera) and shadow-map texel at the character (mm),\n",
    );
    s.push_str("# measured against the ground truth.\n");
    s.push_str("# Regenerate (the `command` below; then copy the file here):\n");
    s.push_str(&format!("#   {}\n", header.command));
    s.push_str(&format!("command = {}\n", quoted(&header.command)));
    s.push_str(&format!("device = {}\n", quoted(&header.device)));
    s.push_str(&format!("frame = {}\n", quoted(&header.frame)));
    s.push_str("rows = [\n");
    for r in rows {
        let nums = [r.px_per_mm, r.light_deg, r.shadow_mm, r.interior]
            .into_iter()
            .chain(r.silhouette);
        for v in nums {
            if !v.is_finite() {
                bail!(
                    "accuracy data: {} {} at {} px/mm has a non-finite value",
                    r.method,
                    r.setting,
                    r.px_per_mm
                );
            }
        }
        let sil = r
            .silhouette
            .map_or(String::new(), |v| format!(", silhouette = {v:?}"));
        s.push_str(&format!(
            "  {{ asset = {}, method = {}, setting = {}, px_per_mm = {:?}, light_deg = {:?}, shadow_mm = {:?}, interior = {:?}{sil} }},\n",
            quoted(r.asset.name()),
            quoted(&r.method),
            quoted(&r.setting),
            r.px_per_mm,
            r.light_deg,
            r.shadow_mm,
            r.interior,
        ));
    }
    s.push_str("]\n");
    Ok(s)
}

/// A TOML basic string.
fn quoted(s: &str) -> String {
    let mut o = String::with_capacity(s.len() + 2);
    o.push('"');
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if c.is_control() => o.push_str(&format!("\\u{:04X}", c as u32)),
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// A TOML error as one line: `file:line: message`.
fn one_line(file: &str, text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            format!("{file}:{line}: {msg}")
        }
        None => format!("{file}: {msg}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(setting: &str, sil: Option<f64>) -> Row {
        Row {
            asset: Asset::Scan,
            method: "ssg".into(),
            setting: setting.into(),
            px_per_mm: 0.1 * 3.0f64.sqrt(),
            light_deg: 69.29518894536457,
            shadow_mm: 0.16792,
            interior: 0.123456789012345,
            silhouette: sil,
        }
    }

    #[test]
    fn written_rows_read_back_exactly() {
        let h = Header {
            command: "dermis eval --scenes accuracy \"x\"".into(),
            device: "llvmpipe".into(),
            frame: "320x180".into(),
        };
        let rows = vec![row("4 Gaussians, LOD", Some(3.5)), row("a\\b", None)];
        let text = to_toml(&h, &rows).unwrap();
        assert!(text.contains("#   dermis eval --scenes accuracy"), "{text}");
        let (h2, back) = parse(&text, "t.toml").unwrap();
        assert_eq!(h2, h);
        assert_eq!(back, rows);
    }

    #[test]
    fn malformed_files_are_one_line_errors() {
        let ok = "command = \"c\"\ndevice = \"d\"\nframe = \"f\"\nrows = [\n";
        let cases = [
            ("command = \"c\"\nrows = [", "t.toml:"),
            (
                &format!("{ok}{{ asset = \"robot\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 0.0, shadow_mm = 0.2, interior = 0.5 }},\n]\n"),
                "row 1: unknown asset 'robot'",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = -1.0, light_deg = 0.0, shadow_mm = 0.2, interior = 0.5 }},\n]\n"),
                "px_per_mm must be a positive number",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 200.0, shadow_mm = 0.2, interior = 0.5 }},\n]\n"),
                "light_deg must be within 0..=180",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 0.0, shadow_mm = 0.0, interior = 0.5 }},\n]\n"),
                "shadow_mm must be a positive number",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 0.0, interior = 0.5 }},\n]\n"),
                "shadow_mm",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 0.0, shadow_mm = 0.2, interior = nan }},\n]\n"),
                "interior err/none must be a number >= 0",
            ),
            (
                &format!("{ok}{{ asset = \"scan\", method = \"m\", setting = \"s\", px_per_mm = 1.0, light_deg = 0.0, shadow_mm = 0.2, interior = 0.5, colour = 1 }},\n]\n"),
                "t.toml:5:",
            ),
        ];
        for (text, want) in cases {
            let e = parse(text, "t.toml").unwrap_err().to_string();
            assert!(e.contains(want), "{e} lacks {want}");
            assert!(!e.contains('\n'), "not one line: {e}");
            assert!(e.starts_with("t.toml"), "{e}");
        }
    }
}
