//! The budget chart: one stacked bar per method (the frame's modelled ms on a
//! profile, split into shadow, geometry, skin SSS, eDRAM resolves/restores and
//! post), one panel per profile side by side, each with its frame-budget line
//! (the skin budget is written in the panel's caption: as a line on a stacked
//! bar it would sit at the wrong height). PNG and SVG through `crate::plot`.

use std::path::Path;

use anyhow::{ensure, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::budget::model::FrameBudget;
use crate::graph::work::PassRole;
use crate::plot::{plot_err, write_png_svg, Plot, COLOURS};

/// The stacked segments, bottom up.
const SEGMENTS: [&str; 5] = [
    "shadow",
    "geometry",
    "skin SSS",
    "eDRAM resolves/restores",
    "post",
];

/// One bar: a label and the ms of each segment.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    pub label: String,
    pub segments: [f64; 5],
}

impl Bar {
    /// A priced frame as a bar: each frame-cost pass's time by role, with the
    /// resolve and restore time of every pass in its own segment.
    pub fn of(label: &str, b: &FrameBudget) -> Bar {
        let mut segments = [0.0; 5];
        for p in b.passes.iter().filter(|p| p.role.is_frame_cost()) {
            let Some(m) = p.modelled_ms else { continue };
            let transfers = p.terms_ms.resolve + p.terms_ms.restore;
            let i = match p.role {
                PassRole::Shadow => 0,
                PassRole::Geometry => 1,
                PassRole::Sss => 2,
                _ => 4,
            };
            segments[i] += m - transfers;
            segments[3] += transfers;
        }
        Bar {
            label: label.to_string(),
            segments,
        }
    }

    pub fn total(&self) -> f64 {
        self.segments.iter().sum()
    }
}

/// One profile's panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub profile: String,
    pub frame_ms: f64,
    pub skin_budget_ms: f64,
    pub bars: Vec<Bar>,
}

/// Writes the chart of `panels` (side by side) as PNG and SVG.
pub fn budget_chart(panels: &[Panel], title: &str, png: &Path, svg: &Path) -> Result<()> {
    ensure!(!panels.is_empty(), "budget chart: no profile to draw");
    for p in panels {
        ensure!(!p.bars.is_empty(), "budget chart: {} has no bar", p.profile);
        for b in &p.bars {
            ensure!(
                b.segments.iter().all(|v| v.is_finite() && *v >= 0.0),
                "budget chart: {} / {} has a negative or non-finite segment",
                p.profile,
                b.label
            );
        }
    }
    let bars = panels.iter().map(|p| p.bars.len()).max().unwrap_or(1) as u32;
    let panel_width = (110 * bars + 140).max(420);
    let width = (panel_width * panels.len() as u32).clamp(900, 3200);
    write_png_svg(&BudgetPlot { panels, title }, (width, 800), png, svg)
}

struct BudgetPlot<'a> {
    panels: &'a [Panel],
    title: &'a str,
}

impl Plot for BudgetPlot<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let area = root
            .titled(self.title, ("sans-serif", 28))
            .map_err(plot_err)?;
        let cells = area.split_evenly((1, self.panels.len()));
        for (i, (panel, cell)) in self.panels.iter().zip(&cells).enumerate() {
            draw_panel(cell, panel, i == 0)?;
        }
        Ok(())
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    legend: bool,
) -> Result<()> {
    let n = panel.bars.len();
    let top = panel
        .bars
        .iter()
        .map(Bar::total)
        .fold(panel.frame_ms, f64::max)
        // Headroom for the totals and the legend above the bars.
        * 1.4;
    let caption = format!(
        "{} (skin budget {:.1} ms)",
        panel.profile, panel.skin_budget_ms
    );
    let labels: Vec<String> = panel.bars.iter().map(|b| b.label.clone()).collect();
    // Bar i is centred on x = i; the labels sit at the integers.
    let x = -0.5..(n as f64 - 0.5);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(70)
        .y_label_area_size(60)
        .build_cartesian_2d(x, 0.0..top)
        .map_err(plot_err)?;
    let fmt = move |v: &f64| {
        let i = v.round();
        if (v - i).abs() < 1e-6 && i >= 0.0 {
            labels.get(i as usize).cloned().unwrap_or_default()
        } else {
            String::new()
        }
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&fmt)
        .y_desc("modelled GPU ms")
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 15))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(plot_err)?;
    for (s, name) in SEGMENTS.iter().enumerate() {
        let colour = COLOURS[s % COLOURS.len()];
        let rects = panel.bars.iter().enumerate().map(|(i, b)| {
            let y0: f64 = b.segments[..s].iter().sum();
            let c = i as f64;
            Rectangle::new(
                [(c - 0.35, y0), (c + 0.35, y0 + b.segments[s])],
                colour.filled(),
            )
        });
        let series = chart.draw_series(rects).map_err(plot_err)?;
        if legend {
            series.label(*name).legend(move |(x, y)| {
                Rectangle::new([(x - 8, y - 6), (x + 8, y + 6)], colour.filled())
            });
        }
    }
    let totals = panel.bars.iter().enumerate().map(|(i, b)| {
        Text::new(
            format!("{:.2}", b.total()),
            (i as f64, b.total() + top * 0.01),
            ("sans-serif", 15)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Bottom)),
        )
    });
    chart.draw_series(totals).map_err(plot_err)?;
    let line = ShapeStyle::from(&RGBColor(200, 0, 0)).stroke_width(2);
    let budget = chart
        .draw_series(LineSeries::new(
            [(-0.5, panel.frame_ms), (n as f64 - 0.5, panel.frame_ms)],
            line,
        ))
        .map_err(plot_err)?;
    if legend {
        budget
            .label("frame budget")
            .legend(move |(x, y)| PathElement::new([(x - 10, y), (x + 10, y)], line));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(plot_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_png_and_svg_with_every_bar() {
        let dir = crate::scene::gltf_load::fixture::temp_dir("budget-chart");
        let bar = |label: &str, sss| Bar {
            label: label.into(),
            segments: [1.0, 8.0, sss, 0.9, 1.5],
        };
        let panel = |name: &str| Panel {
            profile: name.into(),
            frame_ms: 33.3,
            skin_budget_ms: 3.3,
            bars: vec![bar("separable", 1.2), bar("ssg", 6.0), bar("none", 0.0)],
        };
        let (png, svg) = (dir.join("b.png"), dir.join("b.svg"));
        budget_chart(
            &[panel("xbox360"), panel("switch-handheld")],
            "t",
            &png,
            &svg,
        )
        .unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("separable") && text.contains("switch-handheld"));
        assert!(text.contains("frame budget") && text.contains("eDRAM"));
        let img = image::open(&png).unwrap();
        assert_eq!((img.width(), img.height()), (2 * 470, 800));
        assert!(budget_chart(&[], "t", &png, &svg).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
