//! `plan-motion`'s chart: for every character that switches method, its
//! frame-to-frame change under the plan (solid) and the ground truth's own
//! change over the same pixels (dashed), frame by frame, its switches marked.

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::plot::{plot_err, write_png_svg, Plot, COLOURS};

/// One switching character: its change per frame under the plan and the
/// truth's (`None`: no pixel of it in both frames), and its switches
/// (frame, the plan's change there). Its own type, so this file needs
/// nothing of `motion` (sibling files import each other in no cycle).
pub struct Line {
    pub label: String,
    pub plan: Vec<Option<f64>>,
    pub truth: Vec<Option<f64>>,
    pub switches: Vec<(usize, f64)>,
}

struct Chart<'a> {
    frames: usize,
    bound: f64,
    lines: &'a [Line],
}

impl Plot for Chart<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let shown = &self.lines[..self.lines.len().min(COLOURS.len())];
        let ymax = shown
            .iter()
            .flat_map(|c| c.plan.iter().chain(&c.truth).flatten())
            .copied()
            .fold(1e-4f64, f64::max)
            * 1.1;
        let frames = self.frames.max(2) as f64;
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!(
                    "switching characters: change per frame (plan solid, truth dashed, \
                     switches marked); bound {}",
                    self.bound
                ),
                ("sans-serif", 16),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..frames - 1.0, 0.0..ymax)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("frame")
            .y_desc("mean |I_k - I_k-1| (linear diffuse)")
            .draw()
            .map_err(plot_err)?;
        for (i, c) in shown.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            let pts = |v: &[Option<f64>]| -> Vec<(f64, f64)> {
                v.iter()
                    .enumerate()
                    .filter_map(|(k, x)| x.map(|x| (k as f64, x)))
                    .collect()
            };
            let plan = pts(&c.plan);
            chart
                .draw_series(LineSeries::new(plan.clone(), col.stroke_width(2)))
                .map_err(plot_err)?
                .label(c.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(2))
                });
            chart
                .draw_series(DashedLineSeries::new(
                    pts(&c.truth),
                    6,
                    4,
                    col.stroke_width(1),
                ))
                .map_err(plot_err)?;
            let marks: Vec<(f64, f64)> = c.switches.iter().map(|&(k, y)| (k as f64, y)).collect();
            chart
                .draw_series(marks.iter().map(|p| Circle::new(*p, 5, col.filled())))
                .map_err(plot_err)?;
        }
        if !shown.is_empty() {
            crate::plot::draw_legend(&mut chart, 12)?;
        }
        Ok(())
    }
}

/// Writes DIR/plan-motion.png and .svg: `lines` over `frames` frames, the
/// flicker bound in the caption.
pub fn write(dir: &Path, frames: usize, bound: f64, lines: &[Line]) -> Result<()> {
    write_png_svg(
        &Chart {
            frames,
            bound,
            lines,
        },
        (900, 560),
        &dir.join("plan-motion.png"),
        &dir.join("plan-motion.svg"),
    )
}
