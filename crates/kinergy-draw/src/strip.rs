//! A film strip of stick figures overlaid: panels side by side, each showing every figure at
//! one instant in its own colour, one legend above ([`style`](crate::style): the character's
//! reach over the capture's, at a few fractions of the reach, seen from the side).

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::bones::{BoneKind, Segment};
use crate::{DrawResult, FONT, Figure, colour, font_scale, scaled};

/// One figure of a panel: its bones and dots, projected to the screen (meters, y up).
#[derive(Debug, Clone, Default)]
pub struct Pose2 {
    /// The bones: two screen points and how they are drawn.
    pub bones: Vec<([(f64, f64); 2], BoneKind)>,
    /// The joints drawn as dots.
    pub dots: Vec<(f64, f64)>,
}

impl Pose2 {
    /// The pose of `segments` and `dots` (world meters) seen through `project`.
    pub fn new(
        segments: &[Segment],
        dots: impl Iterator<Item = nalgebra::Point3<f64>>,
        project: impl Fn(&nalgebra::Point3<f64>) -> (f64, f64),
    ) -> Pose2 {
        Pose2 {
            bones: segments
                .iter()
                .map(|s| ([project(&s.from), project(&s.to)], s.kind))
                .collect(),
            dots: dots.map(|p| project(&p)).collect(),
        }
    }
}

/// A film strip: `panels[k][f]` is figure `f` in panel `k`, drawn in [`colour`]`(f)` and
/// named `figures[f]` in the legend; `labels[k]` under panel `k`.
#[derive(Debug, Clone)]
pub struct FilmStrip {
    /// The title.
    pub title: String,
    /// The figures' legend entries, in drawing order (the last drawn on top).
    pub figures: Vec<String>,
    /// The figures' [`colour`] indices (one per figure).
    pub colours: Vec<usize>,
    /// Each panel's figures.
    pub panels: Vec<Vec<Pose2>>,
    /// Each panel's label.
    pub labels: Vec<String>,
}

/// The box (u0, u1, v0, v1) around every finite point of every panel, with a margin.
fn bounds(panels: &[Vec<Pose2>]) -> (f64, f64, f64, f64) {
    let points = panels.iter().flatten().flat_map(|p| {
        p.bones
            .iter()
            .flat_map(|(ab, _)| ab.iter().copied())
            .chain(p.dots.iter().copied())
    });
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (u, v) in points.filter(|(u, v)| u.is_finite() && v.is_finite()) {
        (u0, u1, v0, v1) = (u0.min(u), u1.max(u), v0.min(v), v1.max(v));
    }
    if u0 > u1 {
        return (-1.0, 1.0, -1.0, 1.0);
    }
    let pad = 0.06 * (u1 - u0).max(v1 - v0).max(0.05);
    (u0 - pad, u1 + pad, v0 - pad, v1 + pad)
}

impl Figure for FilmStrip {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let k = font_scale(root);
        let fs = scaled(18.0, k) as i32;
        let (w, _) = root.dim_in_pixel();
        let band = u32::try_from(3 * fs)?;
        let (top, rest) = root.split_vertically(band);
        let text = |c: RGBColor| (FONT, f64::from(fs)).into_font().color(&c);
        top.draw(&Text::new(self.title.clone(), (8, 4), text(BLACK)))?;
        let mut x = 8;
        let y = 4 + fs + fs / 2;
        for (f, name) in self.figures.iter().enumerate() {
            let c = colour(self.colours.get(f).copied().unwrap_or(f));
            top.draw(&PathElement::new(
                vec![(x, y + fs / 2), (x + 2 * fs, y + fs / 2)],
                c.stroke_width(4),
            ))?;
            top.draw(&Text::new(name.clone(), (x + 2 * fs + 6, y), text(c)))?;
            let (tw, _) = top.estimate_text_size(name, &text(c))?;
            x += 3 * fs + i32::try_from(tw)?;
        }
        let (u0, u1, v0, v1) = bounds(&self.panels);
        let n = self.panels.len().max(1);
        let (_, h) = rest.dim_in_pixel();
        let panel_w = f64::from(w) / n as f64;
        let label_band = f64::from(fs) * 1.6;
        let area_h = f64::from(h) - label_band;
        let scale = ((panel_w - 8.0) / (u1 - u0)).min((area_h - 4.0) / (v1 - v0));
        let line = scaled(3.0, k);
        for (p, (figures, label)) in self.panels.iter().zip(&self.labels).enumerate() {
            let left = p as f64 * panel_w;
            let centre = (left + panel_w / 2.0, area_h / 2.0);
            let px = |(u, v): (f64, f64)| {
                (
                    (centre.0 + (u - (u0 + u1) / 2.0) * scale).round() as i32,
                    (centre.1 - (v - (v0 + v1) / 2.0) * scale).round() as i32,
                )
            };
            if p > 0 {
                let x = left.round() as i32;
                rest.draw(&PathElement::new(
                    vec![(x, 0), (x, h as i32)],
                    RGBColor(200, 200, 200).stroke_width(1),
                ))?;
            }
            if v0 < 0.0 && 0.0 < v1 {
                let floor = [px((u0, 0.0)), px((u1, 0.0))];
                rest.draw(&PathElement::new(
                    floor.to_vec(),
                    RGBColor(190, 190, 190).stroke_width(1),
                ))?;
            }
            for (f, pose) in figures.iter().enumerate() {
                let c = colour(self.colours.get(f).copied().unwrap_or(f));
                for ([a, b], kind) in &pose.bones {
                    let width = match kind {
                        BoneKind::Body => line,
                        BoneKind::Finger => 1,
                    };
                    rest.draw(&PathElement::new(
                        vec![px(*a), px(*b)],
                        c.stroke_width(width),
                    ))?;
                }
                for &d in &pose.dots {
                    rest.draw(&Circle::new(px(d), line as i32 + 1, c.filled()))?;
                }
            }
            rest.draw(&Text::new(
                label.clone(),
                ((left + 6.0) as i32, (area_h + label_band * 0.2) as i32),
                text(BLACK),
            ))?;
        }
        Ok(())
    }
}
