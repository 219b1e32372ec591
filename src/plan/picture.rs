//! The plan as a picture: the frame's outline with every character's skin
//! rectangle (from the same geometry the planner estimated) filled in its
//! method's colour, the front characters drawn last, and a legend. A
//! schematic, not a render: `render --plan` tints the rendered frame.

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::character::CharacterInput;
use super::choose::{Plan, SettingCosts};
use crate::plot::{plot_err, write_png_svg, Plot, COLOURS};

struct Schematic<'a> {
    width: u32,
    height: u32,
    chars: &'a [CharacterInput],
    plan: &'a Plan,
    costs: &'a [SettingCosts],
}

/// The legend's labels in order of first use (none last), each with its colour.
fn legend(plan: &Plan, costs: &[SettingCosts]) -> Vec<(Option<usize>, String, RGBColor)> {
    let mut out: Vec<(Option<usize>, String, RGBColor)> = Vec::new();
    for r in &plan.rows {
        if let Some(s) = r.setting {
            if !out.iter().any(|o| o.0 == Some(s)) {
                let c = COLOURS[out.len() % (COLOURS.len() - 1)];
                out.push((
                    Some(s),
                    format!("{} {}", costs[s].method, costs[s].setting),
                    c,
                ));
            }
        }
    }
    out.push((
        None,
        crate::method::none().name.into(),
        COLOURS[COLOURS.len() - 1],
    ));
    out
}

impl Plot for Schematic<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let (w, h) = root.dim_in_pixel();
        let margin = 10i32;
        let legend_h = 22i32;
        let sx = (w as f64 - 2.0 * margin as f64) / f64::from(self.width);
        let sy = (h as f64 - 2.0 * margin as f64 - legend_h as f64) / f64::from(self.height);
        let k = sx.min(sy);
        let at = |x: u32, y: u32| {
            (
                margin + (f64::from(x) * k) as i32,
                margin + legend_h + (f64::from(y) * k) as i32,
            )
        };
        root.draw(&Rectangle::new(
            [at(0, 0), at(self.width, self.height)],
            BLACK.stroke_width(1),
        ))
        .map_err(plot_err)?;
        let colours = legend(self.plan, self.costs);
        let colour = |s: Option<usize>| colours.iter().find(|c| c.0 == s).map_or(BLACK, |c| c.2);
        // Back to front: the last characters stand furthest.
        for (c, r) in self.chars.iter().zip(&self.plan.rows).rev() {
            let [x0, y0, x1, y1] = c.screen_rect;
            if x1 <= x0 || y1 <= y0 {
                continue;
            }
            let col = colour(r.setting);
            root.draw(&Rectangle::new(
                [at(x0, y0), at(x1, y1)],
                col.mix(0.6).filled(),
            ))
            .map_err(plot_err)?;
            root.draw(&Rectangle::new(
                [at(x0, y0), at(x1, y1)],
                col.stroke_width(1),
            ))
            .map_err(plot_err)?;
        }
        let mut x = margin;
        for (_, label, col) in &colours {
            root.draw(&Rectangle::new([(x, 4), (x + 12, 16)], col.filled()))
                .map_err(plot_err)?;
            let text = format!("{label}  ");
            root.draw(&Text::new(text.clone(), (x + 16, 4), ("sans-serif", 13)))
                .map_err(plot_err)?;
            x += 22 + 7 * text.len() as i32;
        }
        Ok(())
    }
}

/// Writes DIR/plan.png and DIR/plan.svg.
pub fn write(
    dir: &Path,
    width: u32,
    height: u32,
    chars: &[CharacterInput],
    plan: &Plan,
    costs: &[SettingCosts],
) -> Result<()> {
    let s = Schematic {
        width,
        height,
        chars,
        plan,
        costs,
    };
    let aspect = f64::from(height) / f64::from(width.max(1));
    let size = (960, (940.0 * aspect) as u32 + 42);
    write_png_svg(&s, size, &dir.join("plan.png"), &dir.join("plan.svg"))
}
