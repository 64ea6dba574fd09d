//! SVG charts with plotters' SVG backend (no system library): lines, points and labelled points
//! on linear or logarithmic axes, one or more panels per file.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::error::Error;
use std::path::Path;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A line through the points (dense series).
    Line,
    /// A line through the points with a marker on each.
    LinePoints,
    /// Markers only.
    Points,
    /// A thin dashed black line (references: analytic curves, `y = x`, fronts).
    Reference,
}

/// One named set of points.
pub struct Series {
    /// Legend entry; empty for none.
    pub name: String,
    /// The points; non-finite ones, and non-positive ones on a log axis, are skipped.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

impl Series {
    /// A series from anything iterable of points.
    pub fn new(
        name: impl Into<String>,
        style: Style,
        points: impl IntoIterator<Item = (f64, f64)>,
    ) -> Self {
        Self {
            name: name.into(),
            points: points.into_iter().collect(),
            style,
        }
    }
}

/// An axis: its label, whether it is logarithmic, and names for a categorical axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// The label, with units.
    pub label: String,
    /// Base-10 logarithmic when true.
    pub log: bool,
    /// When not empty, the axis is categorical: value `i` is labelled `categories[i]`.
    pub categories: Vec<String>,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: false,
            categories: Vec::new(),
        }
    }

    /// A logarithmic axis.
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            log: true,
            ..Self::linear(label)
        }
    }

    /// A categorical axis: points at `x = i` are labelled `names[i]`.
    pub fn categories(label: impl Into<String>, names: &[&str]) -> Self {
        Self {
            categories: names.iter().map(|n| n.to_string()).collect(),
            ..Self::linear(label)
        }
    }

    /// The label of tick `v`.
    fn tick(&self, v: &f64) -> String {
        if self.categories.is_empty() {
            return tick(v);
        }
        let i = v.round();
        match self.categories.get(i as usize) {
            Some(name) if (v - i).abs() < 1e-6 && i >= 0.0 => name.clone(),
            _ => String::new(),
        }
    }

    /// How many ticks to ask for: one per category, else few enough not to collide.
    fn tick_count(&self) -> usize {
        if self.categories.is_empty() {
            8
        } else {
            self.categories.len()
        }
    }
}

/// One panel.
pub struct Chart {
    /// Caption above the panel.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The lines and point sets.
    pub series: Vec<Series>,
    /// Text placed at data coordinates (e.g. a BV kind next to its point).
    pub labels: Vec<(f64, f64, String)>,
    /// Where the legend goes (away from the data).
    pub legend: SeriesLabelPosition,
    /// A fixed vertical range instead of the data's.
    pub y_range: Option<(f64, f64)>,
}

impl Chart {
    /// An empty panel.
    pub fn new(title: impl Into<String>, x: Axis, y: Axis) -> Self {
        Self {
            title: title.into(),
            x,
            y,
            series: Vec::new(),
            labels: Vec::new(),
            legend: SeriesLabelPosition::UpperLeft,
            y_range: None,
        }
    }

    /// The same panel with a fixed vertical range.
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// The same panel with its legend elsewhere.
    pub fn legend_at(mut self, at: SeriesLabelPosition) -> Self {
        self.legend = at;
        self
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// Distinct colours (Tableau 10), cycled.
const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Size of one panel in pixels.
const PANEL: (u32, u32) = (760, 500);

/// Writes `charts` to an SVG file, `columns` panels per row.
pub fn save_svg(path: &Path, charts: &[Chart], columns: usize) -> Result<(), Box<dyn Error>> {
    let columns = columns.clamp(1, charts.len().max(1));
    let rows = charts.len().div_ceil(columns).max(1);
    let size = (PANEL.0 * columns as u32, PANEL.1 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((rows, columns));
    for (chart, area) in charts.iter().zip(areas.iter()) {
        draw(area, chart)?;
    }
    root.present()?;
    Ok(())
}

/// True when `v` can be drawn on an axis (finite; positive on a log axis).
fn drawable(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// The points of `chart` that can be drawn.
fn visible(chart: &Chart) -> impl Iterator<Item = (f64, f64)> + '_ {
    let from_series = chart.series.iter().flat_map(|s| s.points.iter().copied());
    let from_labels = chart.labels.iter().map(|(x, y, _)| (*x, *y));
    from_series
        .chain(from_labels)
        .filter(|(x, y)| drawable(*x, chart.x.log) && drawable(*y, chart.y.log))
}

/// The axis range holding `values`, padded: by a factor on a log axis, by 5 % on a linear one.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (lo, hi) = if hi / lo < 10.0 {
            (lo / 2.0, hi * 2.0)
        } else {
            (lo, hi)
        };
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = ((hi - lo) * 0.05).max(hi.abs().max(1e-12) * 1e-3);
        (lo - pad, hi + pad)
    }
}

/// Tick labels: plain numbers in a readable range, scientific notation outside it.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&a) {
        format!("{v:.0e}")
    } else if a >= 10.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The body of [`draw`] for one pair of coordinate kinds (a macro because linear and log
/// coordinates are different types with the same drawing code).
macro_rules! draw_in {
    ($area:expr, $chart:expr, $x:expr, $y:expr) => {{
        let chart: &Chart = $chart;
        let mut cc = ChartBuilder::on($area)
            .caption(&chart.title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .build_cartesian_2d($x, $y)?;
        cc.configure_mesh()
            .x_desc(chart.x.label.as_str())
            .y_desc(chart.y.label.as_str())
            .x_label_formatter(&|v| chart.x.tick(v))
            .y_label_formatter(&|v| chart.y.tick(v))
            .x_labels(chart.x.tick_count())
            .y_labels(chart.y.tick_count())
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 13))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        let keep = |p: &&(f64, f64)| drawable(p.0, chart.x.log) && drawable(p.1, chart.y.log);
        let mut legend = false;
        for (i, s) in chart.series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let pts: Vec<(f64, f64)> = s.points.iter().filter(keep).copied().collect();
            let anno = match s.style {
                Style::Line => cc.draw_series(LineSeries::new(pts, color.stroke_width(2)))?,
                Style::LinePoints => {
                    cc.draw_series(PointSeries::of_element(
                        pts.clone(),
                        3,
                        color.filled(),
                        &|c, s, st| Circle::new(c, s, st),
                    ))?;
                    cc.draw_series(LineSeries::new(pts, color.stroke_width(2)))?
                }
                Style::Points => cc.draw_series(PointSeries::of_element(
                    pts,
                    5,
                    color.filled(),
                    &|c, s, st| Circle::new(c, s, st),
                ))?,
                Style::Reference => {
                    cc.draw_series(DashedLineSeries::new(pts, 6, 4, BLACK.stroke_width(1)))?
                }
            };
            if !s.name.is_empty() {
                legend = true;
                let style = if s.style == Style::Reference {
                    BLACK.stroke_width(1)
                } else {
                    color.stroke_width(3)
                };
                anno.label(s.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], style));
            }
        }
        let labels = chart
            .labels
            .iter()
            .filter(|(x, y, _)| drawable(*x, chart.x.log) && drawable(*y, chart.y.log));
        cc.draw_series(labels.map(|(x, y, t)| {
            Text::new(
                t.clone(),
                (*x, *y),
                ("sans-serif", 12).into_font().color(&BLACK),
            )
        }))?;
        if legend {
            cc.configure_series_labels()
                .position(chart.legend.clone())
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.5))
                .label_font(("sans-serif", 13))
                .draw()?;
        }
    }};
}

/// Draws one panel with the coordinate kinds its axes ask for.
fn draw(area: &DrawingArea<SVGBackend, Shift>, chart: &Chart) -> Result<(), Box<dyn Error>> {
    let (x0, x1) = if chart.x.categories.is_empty() {
        range(visible(chart).map(|p| p.0), chart.x.log)
    } else {
        (-0.5, chart.x.categories.len() as f64 - 0.5)
    };
    let (y0, y1) = chart
        .y_range
        .unwrap_or_else(|| range(visible(chart).map(|p| p.1), chart.y.log));
    match (chart.x.log, chart.y.log) {
        (false, false) => draw_in!(area, chart, x0..x1, y0..y1),
        (true, false) => draw_in!(area, chart, (x0..x1).log_scale(), y0..y1),
        (false, true) => draw_in!(area, chart, x0..x1, (y0..y1).log_scale()),
        (true, true) => draw_in!(area, chart, (x0..x1).log_scale(), (y0..y1).log_scale()),
    }
    Ok(())
}
