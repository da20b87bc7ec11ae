//! Pictures of motion: charts, stick figures, film strips and animated GIFs of captured and
//! synthesized reaches, for the front ends (the `kinergy` command, and any program that wants
//! the same pictures) to draw what the library crates computed.
//!
//! - [`LineChart`], [`Panels`], [`BarChart`]: lines over time (hand speed, the paper's Fig. 5)
//!   and means with min–max whiskers (Fig. 3 and 4, [`experiment`]);
//! - [`bones`]: which bones of a skeleton a stick figure draws; [`shapes`]: scene objects as
//!   flat outlines; [`strip`]: a film strip of stick figures overlaid;
//! - [`animation`]: clips as superposed stick figures synchronized by time, in a scene, as an
//!   animated GIF and a film strip (the paper's Fig. 6);
//! - [`search`]: a planner's two search trees and the wrist's path before and after
//!   smoothing (Kallmann's Fig. 4);
//! - [`style`]: the pictures of a style run (hand-speed profiles, the character over the
//!   capture);
//! - [`viewer`]: clips in a browser, one self-contained HTML page (three.js, inlined), the
//!   hand-speed chart synced to the scrubber;
//! - [`save`], [`stage`], [`stage_gif`], [`commit`]: SVG, PNG and GIF files written atomically,
//!   in the embedded DejaVu font (no system fonts) and a colour-blind-safe [`PALETTE`].
//!
//! Nothing here prints or exits; failures are [`DrawError`]s, which say whether the input or
//! the task is at fault ([`kinergy_io::Classify`]).
//!
//! ```
//! use kinergy_draw::{LineChart, Series, save};
//!
//! let dir = tempfile::tempdir()?;
//! let chart = LineChart {
//!     title: "Hand speed".into(),
//!     x_label: "time (s)".into(),
//!     y_label: "hand speed (m/s)".into(),
//!     series: vec![Series::new("r01".into(), vec![(0.0, 0.0), (0.5, 1.2), (1.0, 0.1)])],
//! };
//! save(&chart, &dir.path().join("speed.svg"), (900, 500))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::error::Error;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

pub mod animation;
pub mod bones;
mod chart;
mod error;
pub mod experiment;
mod output;
pub mod search;
pub mod shapes;
pub mod strip;
pub mod style;
pub mod viewer;

pub use chart::{Bar, BarChart, LineChart, Panels, Series};
pub use error::DrawError;
pub use output::{Format, commit, save, save_both, stage, stage_gif};

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

/// Something that draws itself on any plotters backend.
pub trait Figure {
    /// Draws on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static;
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
