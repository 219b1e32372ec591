//! What every chart shares: one PNG + SVG writer over a [`Plot`] (a chart that
//! draws itself on any plotters backend, so both files come from the same
//! code), the colour cycle, and the font. Text needs a font: plotters'
//! `ab_glyph` backend is used because it is pure Rust (no fontconfig or
//! freetype to link), with a TrueType font read from the system at run time
//! (`DERMIS_FONT`, or DejaVu Sans / Liberation Sans from their usual places)
//! rather than shipped in the repository. The charts themselves live with what
//! they show (`eval::chart`, `budget::chart`).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use anyhow::{anyhow, Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::output::{write_bytes, write_image};

/// Marker colours, one per series in order of first appearance (Okabe-Ito:
/// distinguishable with the common colour-vision deficiencies).
pub const COLOURS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
];

/// A chart that can draw itself on any plotters backend: the PNG and the SVG
/// of one chart come from the same code.
pub trait Plot {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// Draws `plot` into a PNG and an SVG of `size` pixels, creating their folders.
pub fn write_png_svg(
    plot: &impl Plot,
    size: (u32, u32),
    png_path: &Path,
    svg_path: &Path,
) -> Result<()> {
    ensure_font()?;
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        plot.draw_on(&root).context("drawing the PNG chart")?;
        root.present()
            .map_err(plot_err)
            .context("finishing the PNG chart")?;
    }
    let image = image::RgbImage::from_raw(size.0, size.1, rgb)
        .ok_or_else(|| anyhow!("chart buffer does not match {}x{}", size.0, size.1))?;
    write_image(
        png_path,
        &image::DynamicImage::ImageRgb8(image),
        image::ImageFormat::Png,
    )
    .context("writing the chart's PNG")?;

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        plot.draw_on(&root).context("drawing the SVG chart")?;
        root.present()
            .map_err(plot_err)
            .context("finishing the SVG chart")?;
    }
    write_bytes(svg_path, svg.as_bytes()).context("writing the chart's SVG")
}

/// The legend of the plan charts: top right, a white box with a black border.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    font_px: u32,
) -> Result<()> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", font_px))
        .draw()
        .map_err(plot_err)
}

/// plotters' errors borrow nothing but are not always `Send + Sync`: keep the text.
pub fn plot_err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("plotting: {e}")
}

/// Where to look for a sans-serif TrueType font, in order, after `DERMIS_FONT`.
const FONT_PATHS: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
];

/// Registers a font with plotters once per process. The bytes are leaked on
/// purpose: plotters keeps a `'static` reference, and it is one font file.
fn ensure_font() -> Result<()> {
    static FONT: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| register_system_font().map_err(|e| format!("{e:#}")))
        .clone()
        .map_err(|e| anyhow!(e))
}

/// The font file's bytes: `DERMIS_FONT` when it is set (that file or an error
/// naming it: a font the user names is never silently replaced by another),
/// else the first of [`FONT_PATHS`] there is; read through the one door
/// (`files`), so a FIFO or `/dev/zero` ends in an error line, not a hang.
fn font_bytes(given: Option<PathBuf>) -> Result<(PathBuf, Vec<u8>)> {
    let path = match given {
        Some(p) => p,
        None => FONT_PATHS
            .iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
            .ok_or_else(|| {
                anyhow!(
                    "no font for chart text: set DERMIS_FONT to a .ttf file or install \
                     fonts-dejavu-core (looked in {})",
                    FONT_PATHS.join(", ")
                )
            })?,
    };
    let bytes = crate::files::read_bounded(&path, "font", crate::files::MAX_FONT_FILE)
        .context("the chart font (DERMIS_FONT or the system's)")?;
    Ok((path, bytes))
}

fn register_system_font() -> Result<()> {
    let (path, bytes) = font_bytes(std::env::var_os("DERMIS_FONT").map(PathBuf::from))?;
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    for family in ["sans-serif", "serif", "monospace"] {
        plotters::style::register_font(family, FontStyle::Normal, bytes)
            .map_err(|_| anyhow!("{} is not a usable TrueType font", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    // Issue 15: the font is read through the one door. A FIFO or /dev/zero named
    // by DERMIS_FONT ends in one error line naming it (before, the FIFO was
    // skipped in silence for another font, and any size was read).
    #[test]
    fn a_font_the_user_names_is_read_through_the_door() {
        let dir = crate::scene::gltf_load::fixture::temp_dir("font");
        let fifo = dir.join("font.ttf");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        for p in [fifo, PathBuf::from("/dev/zero"), dir.join("absent.ttf")] {
            let e = format!("{:#}", font_bytes(Some(p.clone())).unwrap_err());
            assert!(!e.contains('\n') && e.contains("chart font"), "{e}");
            assert!(e.contains(&p.display().to_string()), "{e}");
        }
        let f = dir.join("small.ttf");
        std::fs::write(&f, b"0123").unwrap();
        assert_eq!(font_bytes(Some(f.clone())).unwrap(), (f, b"0123".to_vec()));
        let _ = std::fs::remove_dir_all(dir);
    }
}
