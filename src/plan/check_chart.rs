//! The plan check's chart: measured err/none against the skin-SSS budget,
//! one panel per profile, the plan (solid) and the best uniform assignment
//! that fits the same budget (dashed) for each scene.

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::plot::{plot_err, write_png_svg, Plot, COLOURS};

/// One case on the chart: its own type, so this file needs nothing of
/// `check` (sibling files import each other in no cycle).
pub struct Point {
    pub profile: String,
    pub scene: String,
    pub budget_ms: f64,
    /// Measured err/none of the plan and of the best fitting uniform assignment.
    pub plan: f64,
    pub uniform: f64,
}

struct Panel<'a> {
    scenes: &'a [String],
    points: &'a [Point],
    profile: &'a str,
}

impl Plot for Panel<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let rows: Vec<_> = self
            .points
            .iter()
            .filter(|c| c.profile == self.profile)
            .collect();
        let (bmin, bmax) = rows.iter().fold((f64::INFINITY, 0.0f64), |(a, b), c| {
            (a.min(c.budget_ms), b.max(c.budget_ms))
        });
        let ymax = rows
            .iter()
            .map(|c| c.plan.max(c.uniform))
            .fold(1.0f64, f64::max)
            * 1.05;
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("{}: measured err/none against the budget", self.profile),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d((bmin * 0.8..bmax * 1.25).log_scale(), 0.0..ymax)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("skin-SSS budget (ms, log)")
            .y_desc("err/none (skin-weighted)")
            .draw()
            .map_err(plot_err)?;
        for (i, sc) in self.scenes.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            let mut pts: Vec<(f64, f64, f64)> = rows
                .iter()
                .filter(|c| &c.scene == sc)
                .map(|c| (c.budget_ms, c.plan, c.uniform))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.0, p.1)),
                    col.stroke_width(2),
                ))
                .map_err(plot_err)?
                .label(format!("{sc}: plan"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 3, col.filled())))
                .map_err(plot_err)?;
            chart
                .draw_series(DashedLineSeries::new(
                    pts.iter().map(|p| (p.0, p.2)),
                    6,
                    4,
                    col.stroke_width(1),
                ))
                .map_err(plot_err)?
                .label(format!("{sc}: best uniform"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(1))
                });
        }
        crate::plot::draw_legend(&mut chart, 12)?;
        Ok(())
    }
}

/// Writes DIR/error-vs-budget-PROFILE.png and .svg for every profile of `points`.
pub fn write(dir: &Path, scenes: &[String], points: &[Point]) -> Result<()> {
    let mut profiles: Vec<&str> = Vec::new();
    for c in points {
        if !profiles.contains(&c.profile.as_str()) {
            profiles.push(&c.profile);
        }
    }
    for p in profiles {
        let panel = Panel {
            scenes,
            points,
            profile: p,
        };
        write_png_svg(
            &panel,
            (900, 560),
            &dir.join(format!("error-vs-budget-{p}.png")),
            &dir.join(format!("error-vs-budget-{p}.svg")),
        )?;
    }
    Ok(())
}
