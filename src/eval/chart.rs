//! The cost-versus-error chart: every measured (method, setting) as a marker,
//! with the Pareto front drawn through the settings worth using.
//!
//! Written as PNG (for a quick look and for reports that embed bitmaps) and SVG
//! (sharp at any size, for papers), through `crate::plot` (the writer and the
//! font every chart shares).

use std::path::Path;

use anyhow::{ensure, Context as _, Result};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::pareto::{pareto_front, EvalPoint};
use crate::plot::{plot_err, write_png_svg, Plot, COLOURS};

/// Pixel size of both outputs.
const SIZE: (u32, u32) = (1200, 800);

/// Marker shapes, cycled with the colours so methods differ also in grey print.
#[derive(Clone, Copy)]
enum Shape {
    Circle,
    Triangle,
    Square,
    Diamond,
}
const SHAPES: [Shape; 4] = [
    Shape::Circle,
    Shape::Triangle,
    Shape::Square,
    Shape::Diamond,
];

/// Draws `points` as GPU ms (x, linear from 0) against error (y; logarithmic
/// when the positive errors span more than a decade, so both a coarse and a
/// near-exact method stay readable, else linear from 0), one marker per method
/// with a legend, and the Pareto front as a line in cost order. Writes
/// `png_path` (1200x800) and `svg_path`, creating their folders.
///
/// Errors on an empty point set, a negative or non-finite cost or error, a
/// missing font, or a path that cannot be written.
pub fn cost_error_chart(
    points: &[EvalPoint],
    title: &str,
    x_label: &str,
    png_path: &Path,
    svg_path: &Path,
) -> Result<()> {
    let layout = Layout::new(points)?;
    let plot = CostErrorPlot {
        points,
        layout: &layout,
        title,
        x_label,
    };
    write_png_svg(&plot, SIZE, png_path, svg_path)
}

/// The legend label of a method's settings scored against another profile's
/// ground truth than the six Gaussians' (`separable [burley]`): its own
/// legend entry, its markers drawn hollow ([`is_profile_label`]).
pub fn profile_label(method: &str, profile: &str) -> String {
    format!("{method} [{profile}]")
}

/// Whether a point's method label is a [`profile_label`].
pub fn is_profile_label(label: &str) -> bool {
    label.ends_with(']') && label.contains(" [")
}

/// One panel of a [`panel_chart`].
pub struct Panel {
    pub title: String,
    pub y_label: String,
    pub points: Vec<EvalPoint>,
    /// Whether the Pareto front is drawn (it is computed on one panel only: the
    /// one the ranking is made on).
    pub front: bool,
}

/// Cost/error panels side by side, sharing the x axis range and the method
/// markers: e.g. the interior's err/none (with the Pareto front) beside the
/// silhouette's and the depth steps'. Writes `png_path` (600 x 800 per panel)
/// and `svg_path`.
pub fn panel_chart(
    panels: &[Panel],
    title: &str,
    x_label: &str,
    png_path: &Path,
    svg_path: &Path,
) -> Result<()> {
    ensure!(!panels.is_empty(), "panel chart: no panels");
    let layouts = panels
        .iter()
        .map(|p| Layout::new(&p.points).with_context(|| format!("panel '{}'", p.title)))
        .collect::<Result<Vec<_>>>()?;
    let x_max = layouts.iter().map(|l| l.x_max).fold(0.0, f64::max);
    let layouts: Vec<Layout> = layouts.into_iter().map(|l| Layout { x_max, ..l }).collect();
    let plot = PanelPlot {
        panels,
        layouts: &layouts,
        title,
        x_label,
    };
    let size = (600 * panels.len() as u32, SIZE.1);
    write_png_svg(&plot, size, png_path, svg_path)
}

struct PanelPlot<'a> {
    panels: &'a [Panel],
    layouts: &'a [Layout],
    title: &'a str,
    x_label: &'a str,
}

impl Plot for PanelPlot<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let inner = root
            .titled(self.title, ("sans-serif", 30))
            .map_err(plot_err)?;
        let areas = inner.split_evenly((1, self.panels.len()));
        for ((area, panel), layout) in areas.iter().zip(self.panels).zip(self.layouts) {
            let labels = Labels {
                title: &panel.title,
                x: self.x_label,
                y: &panel.y_label,
                front: panel.front,
            };
            draw(area, &panel.points, layout, &labels)?;
        }
        Ok(())
    }
}

/// The texts of one cost/error chart, and whether it shows the Pareto front.
struct Labels<'a> {
    title: &'a str,
    x: &'a str,
    y: &'a str,
    front: bool,
}

struct CostErrorPlot<'a> {
    points: &'a [EvalPoint],
    layout: &'a Layout,
    title: &'a str,
    x_label: &'a str,
}

impl Plot for CostErrorPlot<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        root.fill(&WHITE).map_err(plot_err)?;
        let labels = Labels {
            title: self.title,
            x: self.x_label,
            y: "error",
            front: true,
        };
        draw(root, self.points, self.layout, &labels)
    }
}

/// Axis ranges and scale, decided once so PNG and SVG show the same chart.
struct Layout {
    x_max: f64,
    y: (f64, f64),
    log_y: bool,
}

impl Layout {
    fn new(points: &[EvalPoint]) -> Result<Self> {
        ensure!(!points.is_empty(), "cost/error chart: no points to draw");
        for p in points {
            ensure!(
                p.gpu_ms.is_finite() && p.gpu_ms >= 0.0 && p.error.is_finite() && p.error >= 0.0,
                "cost/error chart: point {}/{}/{} has gpu_ms {} and error {}; both must be finite and >= 0",
                p.method,
                p.setting,
                p.scene,
                p.gpu_ms,
                p.error
            );
        }
        let max_of = |f: fn(&EvalPoint) -> f64| points.iter().map(f).fold(0.0f64, f64::max);
        let x_max = max_of(|p| p.gpu_ms);
        let x_max = if x_max > 0.0 { x_max * 1.1 } else { 1.0 };
        let e_max = max_of(|p| p.error);
        let e_min = points.iter().map(|p| p.error).fold(f64::INFINITY, f64::min);
        // A log axis cannot show 0, so an exact point keeps the axis linear.
        let log_y = e_min > 0.0 && e_max / e_min > 10.0;
        let y = if log_y {
            (e_min / 1.5, e_max * 1.5)
        } else if e_max > 0.0 {
            (0.0, e_max * 1.1)
        } else {
            (0.0, 1.0)
        };
        Ok(Self { x_max, y, log_y })
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[EvalPoint],
    layout: &Layout,
    labels: &Labels,
) -> Result<()> {
    let mut builder = ChartBuilder::on(root);
    builder
        .caption(labels.title, ("sans-serif", 30))
        .margin(24)
        .x_label_area_size(60)
        .y_label_area_size(100);
    let x = 0.0..layout.x_max;
    let (lo, hi) = layout.y;
    if layout.log_y {
        let chart = builder
            .build_cartesian_2d(x, (lo..hi).log_scale())
            .map_err(plot_err)?;
        draw_in(chart, points, labels)
    } else {
        let chart = builder.build_cartesian_2d(x, lo..hi).map_err(plot_err)?;
        draw_in(chart, points, labels)
    }
}

/// Everything inside the axes; generic over the y coordinate so the linear and
/// logarithmic charts share one drawing path.
fn draw_in<'a, DB, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    points: &[EvalPoint],
    labels: &Labels,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(plot_err)?;

    if labels.front {
        let front: Vec<(f64, f64)> = pareto_front(points)
            .into_iter()
            .map(|i| (points[i].gpu_ms, points[i].error))
            .collect();
        let front_style = ShapeStyle::from(&RGBColor(40, 40, 40)).stroke_width(2);
        chart
            .draw_series(LineSeries::new(front, front_style))
            .map_err(plot_err)?
            .label("Pareto front")
            .legend(move |(x, y)| PathElement::new([(x - 12, y), (x + 12, y)], front_style));
    }

    let mut methods: Vec<&str> = Vec::new();
    for p in points {
        if !methods.contains(&p.method.as_str()) {
            methods.push(&p.method);
        }
    }
    for (m, method) in methods.iter().enumerate() {
        let colour = COLOURS[m % COLOURS.len()];
        let shape = outline(SHAPES[m % SHAPES.len()]);
        let mine = points.iter().filter(|p| p.method == *method);
        if is_profile_label(method) {
            // Another profile's settings: the same shapes, hollow.
            let mut ring = shape.clone();
            ring.push(shape[0]);
            let stroke = colour.stroke_width(2);
            let legend_ring = ring.clone();
            chart
                .draw_series(mine.map(|p| {
                    EmptyElement::at((p.gpu_ms, p.error)) + PathElement::new(ring.clone(), stroke)
                }))
                .map_err(plot_err)?
                .label(*method)
                .legend(move |c| {
                    EmptyElement::at(c) + PathElement::new(legend_ring.clone(), stroke)
                });
            continue;
        }
        let fill = colour.filled();
        let legend_shape = shape.clone();
        chart
            .draw_series(
                mine.map(|p| {
                    EmptyElement::at((p.gpu_ms, p.error)) + Polygon::new(shape.clone(), fill)
                }),
            )
            .map_err(plot_err)?
            .label(*method)
            .legend(move |c| EmptyElement::at(c) + Polygon::new(legend_shape.clone(), fill));
    }

    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 18))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

/// One line of a [`series_chart`]: a label and its (x, y) points.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Lines of y against x (x logarithmic, y linear from 0), one colour and marker
/// per series, with a legend: e.g. each method's error along a camera dolly,
/// where a distance-driven switch (Gaussian LOD) would show as a step. Writes
/// `png_path` and `svg_path` like [`cost_error_chart`].
///
/// Errors on no series, an empty series, a non-positive or non-finite x, a
/// negative or non-finite y, a missing font, or a path that cannot be written.
pub fn series_chart(
    series: &[Series],
    title: &str,
    x_label: &str,
    y_label: &str,
    png_path: &Path,
    svg_path: &Path,
) -> Result<()> {
    ensure!(!series.is_empty(), "line chart: no series to draw");
    for s in series {
        ensure!(
            !s.points.is_empty(),
            "line chart: series '{}' has no points",
            s.label
        );
        for &(x, y) in &s.points {
            ensure!(
                x.is_finite() && x > 0.0 && y.is_finite() && y >= 0.0,
                "line chart: series '{}' has the point ({x}, {y}); x must be > 0 and y >= 0",
                s.label
            );
        }
    }
    let all = series.iter().flat_map(|s| s.points.iter());
    let (x_lo, x_hi, y_hi) = all.fold((f64::INFINITY, 0.0f64, 0.0f64), |(a, b, c), &(x, y)| {
        (a.min(x), b.max(x), c.max(y))
    });
    let plot = LinePlot {
        series,
        labels: (title, x_label, y_label),
        x: (x_lo / 1.05)..(x_hi * 1.05),
        y: 0.0..(if y_hi > 0.0 { y_hi * 1.1 } else { 1.0 }),
    };
    write_png_svg(&plot, SIZE, png_path, svg_path)
}

struct LinePlot<'a> {
    series: &'a [Series],
    labels: (&'a str, &'a str, &'a str),
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
}

impl Plot for LinePlot<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        draw_lines(
            root,
            self.series,
            self.labels,
            self.x.clone(),
            self.y.clone(),
        )
    }
}

/// Everything of a [`series_chart`] on one backend.
fn draw_lines<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    series: &[Series],
    (title, x_label, y_label): (&str, &str, &str),
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 30))
        .margin(24)
        .x_label_area_size(60)
        .y_label_area_size(100)
        .build_cartesian_2d(x.clone().log_scale(), y.clone())
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(plot_err)?;
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        let shape = outline(SHAPES[i % SHAPES.len()]);
        let legend_shape = shape.clone();
        chart
            .draw_series(LineSeries::new(s.points.iter().copied(), style))
            .map_err(plot_err)?;
        chart
            .draw_series(
                s.points
                    .iter()
                    .map(|&p| EmptyElement::at(p) + Polygon::new(shape.clone(), colour.filled())),
            )
            .map_err(plot_err)?
            .label(s.label.as_str())
            .legend(move |c| {
                EmptyElement::at(c) + Polygon::new(legend_shape.clone(), colour.filled())
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 18))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

/// The outline of a marker in pixels around its point. Every shape is a polygon
/// so that all markers share one element type and one drawing path, in the plot
/// and in the legend alike.
fn outline(shape: Shape) -> Vec<(i32, i32)> {
    match shape {
        Shape::Circle => (0..16)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::TAU / 16.0;
                (
                    (7.0 * a.cos()).round() as i32,
                    (7.0 * a.sin()).round() as i32,
                )
            })
            .collect(),
        Shape::Triangle => vec![(0, -8), (8, 6), (-8, 6)],
        Shape::Square => vec![(-6, -6), (6, -6), (6, 6), (-6, 6)],
        Shape::Diamond => vec![(0, -8), (8, 0), (0, 8), (-8, 0)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn pt(method: &str, gpu_ms: f64, error: f64) -> EvalPoint {
        EvalPoint {
            method: method.into(),
            setting: format!("{gpu_ms}"),
            scene: "head".into(),
            gpu_ms,
            error,
        }
    }

    fn temp_dir(tag: &str) -> crate::scene::gltf_load::fixture::TempDir {
        crate::scene::gltf_load::fixture::temp_dir(&format!("chart-{tag}"))
    }

    /// Checks the PNG decodes at full size and is not blank: its luminance
    /// varies, and the caption band holds dark (text) pixels.
    fn assert_png_has_content(path: &Path) {
        let img = image::open(path).unwrap().into_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let luma: Vec<f64> = img
            .pixels()
            .map(|p| (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0)
            .collect();
        let mean = luma.iter().sum::<f64>() / luma.len() as f64;
        let var = luma.iter().map(|l| (l - mean) * (l - mean)).sum::<f64>() / luma.len() as f64;
        assert!(var > 50.0, "PNG looks blank: luminance variance {var}");
        let caption_dark = (0..SIZE.0)
            .flat_map(|x| (0..60).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y)[0] < 100)
            .count();
        assert!(
            caption_dark > 100,
            "no caption text drawn ({caption_dark} dark pixels)"
        );
    }

    // Both profiles in one chart: Burley's settings are their own legend
    // entry, drawn hollow (a polyline, where the six Gaussians' are filled
    // polygons).
    #[test]
    fn both_profiles_share_one_chart() {
        let dir = temp_dir("profiles");
        let burley = profile_label("separable", "burley");
        assert!(is_profile_label(&burley) && !is_profile_label("separable"));
        let points = vec![
            pt("separable", 0.4, 0.08),
            pt("separable", 0.7, 0.03),
            pt(&burley, 0.45, 0.06),
            pt(&burley, 0.75, 0.02),
        ];
        let (png, svg) = (dir.join("c.png"), dir.join("c.svg"));
        cost_error_chart(&points, "Both profiles", "GPU ms", &png, &svg).unwrap();
        assert_png_has_content(&png);
        let text = fs::read_to_string(&svg).unwrap();
        assert!(
            text.contains("separable [burley]"),
            "no legend entry for Burley"
        );
        assert!(text.contains("<polyline"), "no hollow marker");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writes_png_and_svg_log_scale() {
        let dir = temp_dir("log");
        let points = vec![
            pt("separable", 0.4, 0.08),
            pt("separable", 0.7, 0.03),
            pt("ssg", 0.9, 0.02),
            pt("ss-jittered", 0.5, 0.2),
            pt("poisson", 2.0, 0.001),
            pt("poisson", 1.2, 0.004),
        ];
        let (png, svg) = (dir.join("c.png"), dir.join("sub/c.svg"));
        cost_error_chart(&points, "Skin SSS: cost vs error", "GPU ms", &png, &svg).unwrap();
        assert_png_has_content(&png);
        let text = fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg"));
        assert!(text.contains("ss-jittered") && text.contains("Pareto front"));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn single_point_and_linear_scale() {
        let dir = temp_dir("one");
        let (png, svg) = (dir.join("c.png"), dir.join("c.svg"));
        cost_error_chart(&[pt("separable", 0.5, 0.05)], "one", "GPU ms", &png, &svg).unwrap();
        assert_png_has_content(&png);
        assert!(fs::read_to_string(&svg).unwrap().contains("<svg"));
        // Zero cost and zero error still give a drawable (linear) chart.
        cost_error_chart(&[pt("gt", 0.0, 0.0)], "zero", "GPU ms", &png, &svg).unwrap();
        assert!(
            !Layout::new(&[pt("a", 1.0, 0.05), pt("b", 2.0, 0.1)])
                .unwrap()
                .log_y
        );
        assert!(
            Layout::new(&[pt("a", 1.0, 0.005), pt("b", 2.0, 0.1)])
                .unwrap()
                .log_y
        );
        assert!(
            !Layout::new(&[pt("a", 1.0, 0.0), pt("b", 2.0, 0.1)])
                .unwrap()
                .log_y
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn line_chart_writes_png_and_svg_and_rejects_bad_points() {
        let dir = temp_dir("lines");
        let (png, svg) = (dir.join("d.png"), dir.join("d.svg"));
        let series = vec![
            Series {
                label: "separable 17".into(),
                points: vec![(1.0, 0.03), (2.0, 0.025), (4.0, 0.02), (8.0, 0.018)],
            },
            Series {
                label: "ssg 6, LOD".into(),
                points: vec![(1.0, 0.02), (2.0, 0.03), (4.0, 0.05), (8.0, 0.02)],
            },
        ];
        series_chart(
            &series,
            "error along a dolly",
            "head heights",
            "error",
            &png,
            &svg,
        )
        .unwrap();
        assert_png_has_content(&png);
        let text = fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg") && text.contains("ssg 6, LOD"));
        let bad = |points: Vec<(f64, f64)>| {
            series_chart(
                &[Series {
                    label: "x".into(),
                    points,
                }],
                "t",
                "x",
                "y",
                &png,
                &svg,
            )
            .is_err()
        };
        assert!(bad(vec![]));
        assert!(bad(vec![(0.0, 0.1)]), "log x needs x > 0");
        assert!(bad(vec![(1.0, f64::NAN)]));
        assert!(bad(vec![(1.0, -0.1)]));
        assert!(series_chart(&[], "t", "x", "y", &png, &svg).is_err());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn panel_chart_puts_panels_side_by_side() {
        let dir = temp_dir("panels");
        let (png, svg) = (dir.join("p.png"), dir.join("p.svg"));
        let panel = |t: &str, front| Panel {
            title: t.into(),
            y_label: "err/none".into(),
            points: vec![pt("none", 0.0, 1.0), pt("separable", 0.5, 0.3)],
            front,
        };
        panel_chart(
            &[
                panel("interior", true),
                panel("silhouette", false),
                panel("depth step", false),
            ],
            "bands",
            "GPU ms",
            &png,
            &svg,
        )
        .unwrap();
        assert_eq!(image::image_dimensions(&png).unwrap(), (1800, 800));
        let svg = fs::read_to_string(&svg).unwrap();
        assert!(svg.contains("silhouette") && svg.contains("Pareto front"));
        assert!(panel_chart(&[], "t", "x", &png, &dir.join("q.svg")).is_err());
    }

    #[test]
    fn errors_cleanly() {
        let dir = temp_dir("err");
        let (png, svg) = (dir.join("c.png"), dir.join("c.svg"));
        assert!(cost_error_chart(&[], "t", "x", &png, &svg).is_err());
        assert!(cost_error_chart(&[pt("a", f64::NAN, 0.1)], "t", "x", &png, &svg).is_err());
        assert!(cost_error_chart(&[pt("a", 1.0, -0.1)], "t", "x", &png, &svg).is_err());
        // Under a regular file nothing can be created.
        fs::create_dir_all(&dir).unwrap();
        let file = dir.join("file");
        fs::write(&file, "x").unwrap();
        let points = [pt("a", 1.0, 0.1)];
        assert!(cost_error_chart(&points, "t", "x", &file.join("c.png"), &svg).is_err());
        assert!(cost_error_chart(&points, "t", "x", &png, &file.join("c.svg")).is_err());
        fs::remove_dir_all(&dir).unwrap();
    }
}
