//! The chart kinds: lines over a shared x axis ([`LineChart`], side by side in [`Panels`]) and
//! groups of bars with min–max whiskers ([`BarChart`]).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::{DrawResult, FONT, Figure, colour, font_scale, scaled};

/// One line of a [`LineChart`].
#[derive(Debug, Clone)]
pub struct Series {
    /// Its legend entry (none when empty: a line of a group another series names).
    pub name: String,
    /// Its points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Its [`colour`] index; `None`: its own index in the chart.
    pub colour: Option<usize>,
}

impl Series {
    /// A line in a colour of its own.
    pub fn new(name: String, points: Vec<(f64, f64)>) -> Series {
        Series {
            name,
            points,
            colour: None,
        }
    }
}

/// Lines over a shared x axis, with a legend (e.g. hand speed over time).
#[derive(Debug, Clone)]
pub struct LineChart {
    /// The title.
    pub title: String,
    /// The x axis label, with its unit.
    pub x_label: String,
    /// The y axis label, with its unit.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
}

fn padded_range(values: impl Iterator<Item = f64>, floor_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if floor_zero {
        lo = lo.min(0.0);
    }
    if hi - lo < 1e-9 {
        hi = lo + 1.0;
    }
    let pad = 0.05 * (hi - lo);
    (
        if floor_zero && lo >= 0.0 {
            lo
        } else {
            lo - pad
        },
        hi + pad,
    )
}

impl Figure for LineChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let (x0, x1) = padded_range(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
            false,
        );
        let (y0, y1) = padded_range(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.1)),
            true,
        );
        let k = font_scale(root);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, scaled(22.0, k)))
            .margin(scaled(12.0, k))
            .x_label_area_size(scaled(44.0, k))
            .y_label_area_size(scaled(60.0, k))
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FONT, scaled(14.0, k)))
            .axis_desc_style((FONT, scaled(16.0, k)))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        for (i, s) in self.series.iter().enumerate() {
            let c = colour(s.colour.unwrap_or(i));
            let drawn = chart.draw_series(LineSeries::new(
                s.points.iter().copied(),
                c.stroke_width(scaled(2.0, k)),
            ))?;
            if !s.name.is_empty() {
                drawn.label(&s.name).legend(move |(x, y)| {
                    let w = scaled(20.0, k) as i32;
                    PathElement::new(vec![(x, y), (x + w, y)], c.stroke_width(scaled(2.0, k)))
                });
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font((FONT, scaled(14.0, k)))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        Ok(())
    }
}

/// Line charts side by side in a grid of `columns`, under one title (e.g. one panel per
/// capture).
#[derive(Debug, Clone)]
pub struct Panels {
    /// The title over all panels.
    pub title: String,
    /// Panels per row.
    pub columns: usize,
    /// The panels, row by row.
    pub charts: Vec<LineChart>,
}

impl Figure for Panels {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let k = font_scale(root);
        let (top, rest) = root.split_vertically(scaled(40.0, k));
        let (w, _) = top.dim_in_pixel();
        top.draw(&Text::new(
            self.title.clone(),
            (w as i32 / 2, scaled(10.0, k) as i32),
            (FONT, scaled(22.0, k))
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Top)),
        ))?;
        let columns = self.columns.max(1);
        let rows = self.charts.len().div_ceil(columns).max(1);
        for (area, chart) in rest.split_evenly((rows, columns)).iter().zip(&self.charts) {
            chart.draw(area)?;
        }
        Ok(())
    }
}

/// One bar: a mean with its minimum and maximum.
#[derive(Debug, Clone)]
pub struct Bar {
    /// Which series it belongs to (colour and legend).
    pub series: usize,
    /// The mean (the bar's height).
    pub mean: f64,
    /// The smallest value (the whisker's bottom).
    pub min: f64,
    /// The largest value (the whisker's top).
    pub max: f64,
}

/// Groups of bars with min–max whiskers (the paper's Fig. 3 and 4).
#[derive(Debug, Clone)]
pub struct BarChart {
    /// The title.
    pub title: String,
    /// The x axis title: what the groups are.
    pub x_label: String,
    /// The y axis label, with its unit.
    pub y_label: String,
    /// The series' legend entries (one colour each).
    pub series: Vec<String>,
    /// The groups along x: a label and its bars.
    pub groups: Vec<(String, Vec<Bar>)>,
}

impl Figure for BarChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let top = self
            .groups
            .iter()
            .flat_map(|(_, bars)| bars.iter().map(|b| b.max.max(b.mean)))
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max);
        let top = if top > 0.0 { top * 1.12 } else { 1.0 };
        let n = self.groups.len().max(1);
        let per = self.series.len().max(1) as f64;
        let k = font_scale(root);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, scaled(22.0, k)))
            .margin(scaled(12.0, k))
            .x_label_area_size(scaled(64.0, k))
            .y_label_area_size(scaled(60.0, k))
            .build_cartesian_2d(0.0..n as f64, 0.0..top)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FONT, scaled(14.0, k)))
            .axis_desc_style((FONT, scaled(16.0, k)))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        let width = 0.8 / per;
        for (s, name) in self.series.iter().enumerate() {
            let c = colour(s);
            let bars: Vec<(f64, &Bar)> = self
                .groups
                .iter()
                .enumerate()
                .flat_map(|(g, (_, bars))| {
                    bars.iter()
                        .filter(move |b| b.series == s)
                        .map(move |b| (g as f64 + 0.1 + width * s as f64, b))
                })
                .collect();
            chart
                .draw_series(bars.iter().map(|&(x, b)| {
                    Rectangle::new([(x, 0.0), (x + width * 0.9, b.mean)], c.mix(0.85).filled())
                }))?
                .label(name)
                .legend(move |(x, y)| {
                    let (w, h) = (scaled(14.0, k) as i32, scaled(5.0, k) as i32);
                    Rectangle::new([(x, y - h), (x + w, y + h)], c.filled())
                });
            chart.draw_series(bars.iter().map(|&(x, b)| {
                let mid = x + width * 0.45;
                PathElement::new(vec![(mid, b.min), (mid, b.max)], BLACK.stroke_width(1))
            }))?;
            chart.draw_series(bars.iter().flat_map(|&(x, b)| {
                let (l, r) = (x + width * 0.25, x + width * 0.65);
                [b.min, b.max]
                    .map(|y| PathElement::new(vec![(l, y), (r, y)], BLACK.stroke_width(1)))
            }))?;
        }
        // The group labels, centred under each group (plotters would place numeric ticks).
        let style = TextStyle::from((FONT, scaled(16.0, k)).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (g, (label, _)) in self.groups.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(g as f64 + 0.5, 0.0));
            let below = scaled(10.0, k) as i32;
            root.draw(&Text::new(label.clone(), (x, y + below), style.clone()))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font((FONT, scaled(14.0, k)))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        Ok(())
    }
}
