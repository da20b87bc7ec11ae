//! Pictures: the embedded font, the palette, SVG / PNG / GIF output written atomically, and
//! the two chart kinds the commands draw (lines over time, means with min–max bars); in
//! [`bones`] which bones a stick figure draws, in [`shapes`] how scene objects are projected,
//! in [`strip`] a film strip of stick figures overlaid.

use std::error::Error;
use std::io::Write as _;
use std::path::Path;
use std::sync::Once;

use image::ImageEncoder as _;
use kinergy_io::AtomicFile;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::DrawingErrorKind;

use crate::common::Failure;

pub mod bones;
pub mod shapes;
pub mod strip;

/// A drawing error, boxed (plotters' errors are generic over the backend).
pub type DrawResult = Result<(), Box<dyn Error>>;

/// The font family every picture uses: DejaVu Sans, embedded, registered once.
pub const FONT: &str = "sans-serif";

/// Registers DejaVu Sans (regular and bold) with plotters; no system fonts are needed.
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Embedded, valid TrueType fonts: registration cannot fail, and a failure would only
        // mean text is not drawn.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Colour-blind-safe colours (Okabe & Ito), one per series, cycling.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// The colour of series `i`.
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// The picture formats, from the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// A PNG bitmap.
    Png,
}

impl Format {
    /// The format `path` asks for by its extension (`.svg` or `.png`).
    pub fn of(path: &Path, option: &str) -> Result<Format, Failure> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(Failure::Input(format!(
                "{option} {}: the file name must end in .svg or .png",
                path.display()
            ))),
        }
    }
}

/// Something that draws itself on any plotters backend.
pub trait Figure {
    /// Draws on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static;
}

/// A failure writing the picture `path`.
fn failed(path: &Path, e: impl std::fmt::Display) -> Failure {
    Failure::task(path, e)
}

/// A drawing failure writing the picture `path`, said without Rust's Debug text.
fn drawing_failed(path: &Path, e: &(dyn Error + 'static)) -> Failure {
    failed(path, plain(e))
}

/// The bitmap backend's error type (plotters does not export its name).
type BitmapError = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

/// A drawing error as people read it. plotters' bitmap backend displays its errors with
/// Rust's Debug formatting (`IOError(Os { code: 28, kind: StorageFull, … })`): say the I/O
/// error inside instead.
fn plain(e: &(dyn Error + 'static)) -> String {
    let bitmap = e.downcast_ref::<BitmapError>().or_else(|| {
        match e.downcast_ref::<DrawingAreaErrorKind<BitmapError>>() {
            Some(DrawingAreaErrorKind::BackendError(DrawingErrorKind::DrawingError(b))) => Some(b),
            _ => None,
        }
    });
    match bitmap {
        Some(BitmapError::IOError(io)) => io.to_string(),
        Some(BitmapError::InvalidBuffer) => "the picture's pixel buffer has the wrong size".into(),
        Some(other) => other.source().map_or_else(
            || "the picture could not be encoded".into(),
            |s| s.to_string(),
        ),
        None => e.to_string(),
    }
}

/// Starts the staged file of the picture `path`.
fn start(path: &Path) -> Result<AtomicFile, Failure> {
    AtomicFile::create(path).map_err(|e| failed(path, e))
}

/// Puts a staged picture in place.
pub fn commit(staged: AtomicFile) -> Result<(), Failure> {
    let path = staged.path().to_path_buf();
    staged.commit().map_err(|e| failed(&path, e))
}

/// Draws `figure` for `path` (SVG or PNG by its extension) into a temporary file beside it,
/// not yet in place: [`commit`] it, or drop it to leave `path` as it was.
pub fn stage(figure: &impl Figure, path: &Path, size: (u32, u32)) -> Result<AtomicFile, Failure> {
    register_fonts();
    let format = Format::of(path, "-o")?;
    let bytes = match format {
        Format::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                figure
                    .draw(&root)
                    .and_then(|()| root.present().map_err(|e| e.into()))
                    .map_err(|e| drawing_failed(path, &*e))?;
            }
            text.into_bytes()
        }
        Format::Png => {
            // Rendered in memory, encoded into the staged file: no encoder writes the path.
            let pixels = usize::try_from(u64::from(size.0) * u64::from(size.1) * 3)
                .map_err(|e| failed(path, e))?;
            let mut rgb = vec![0u8; pixels];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                figure
                    .draw(&root)
                    .and_then(|()| root.present().map_err(|e| e.into()))
                    .map_err(|e| drawing_failed(path, &*e))?;
            }
            let mut png = Vec::new();
            image::codecs::png::PngEncoder::new(&mut png)
                .write_image(&rgb, size.0, size.1, image::ColorType::Rgb8)
                .map_err(|e| failed(path, e))?;
            png
        }
    };
    let mut staged = start(path)?;
    staged.write_all(&bytes).map_err(|e| failed(path, e))?;
    Ok(staged)
}

/// Draws `figure` into `path` (SVG or PNG by its extension), written atomically.
pub fn save(figure: &impl Figure, path: &Path, size: (u32, u32)) -> Result<(), Failure> {
    commit(stage(figure, path, size)?)
}

/// Draws `frames` frames of an animated GIF for `path` (`delay_ms` per frame) into a
/// temporary file beside it, not yet in place (see [`stage`]); `frame(k, root)` draws frame
/// `k`.
pub fn stage_gif(
    path: &Path,
    size: (u32, u32),
    frames: usize,
    delay_ms: u32,
    frame: impl Fn(usize, &DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> Result<AtomicFile, Failure> {
    register_fonts();
    let staged = start(path)?;
    // The GIF encoder writes a path: it truncates and fills the staged temporary file.
    (|| -> DrawResult {
        let root = BitMapBackend::gif(staged.temp_path(), size, delay_ms)?.into_drawing_area();
        for k in 0..frames {
            frame(k, &root)?;
            root.present()?;
        }
        Ok(())
    })()
    .map_err(|e| drawing_failed(path, &*e))?;
    Ok(staged)
}

/// Text sizes grow with the picture's height (sizes below are for 500 pixels), so a large
/// chart is as readable as a small one.
fn font_scale<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>) -> f64 {
    (f64::from(root.dim_in_pixel().1) / 500.0).clamp(0.6, 4.0)
}

/// `px` pixels at a 500-pixel-high picture, scaled by `scale`.
fn scaled(px: f64, scale: f64) -> u32 {
    (px * scale).round().max(1.0) as u32
}

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

#[cfg(test)]
mod plain_tests {
    use super::{BitmapError, plain};
    use plotters::prelude::DrawingAreaErrorKind;
    use plotters_backend::DrawingErrorKind;

    #[test]
    fn a_full_disk_while_drawing_is_said_without_debug_text() {
        let io = || std::io::Error::from(std::io::ErrorKind::StorageFull);
        let direct: Box<dyn std::error::Error> = Box::new(BitmapError::IOError(io()));
        let wrapped: Box<dyn std::error::Error> = Box::new(DrawingAreaErrorKind::BackendError(
            DrawingErrorKind::DrawingError(BitmapError::IOError(io())),
        ));
        for e in [direct, wrapped] {
            let text = plain(&*e);
            assert!(
                !text.contains("IOError") && !text.contains("kind:"),
                "{text}"
            );
            assert_eq!(text, io().to_string());
        }
    }
}
