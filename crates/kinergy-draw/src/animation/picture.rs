//! Drawing: the legend, one panel per instant with the scene's objects and the clips' stick
//! figures, and the film strip made of them.

use std::error::Error;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::objects::{Prop, Track};
use super::view::{Bounds, Mapping, View};
use crate::bones::BoneKind;
use crate::shapes::{Flat, clip_line, clip_polygon};
use crate::{DrawResult, FONT, Figure};

/// The length of a legend entry's colour line, pixels.
const SWATCH: i32 = 18;

/// Everything a picture needs: the clips' tracks, the scene's objects, their common box.
#[derive(Debug, Clone)]
pub struct Scene {
    tracks: Vec<Track>,
    props: Vec<Prop>,
    bounds: Bounds,
    view: View,
}

impl Scene {
    /// The clips' `tracks` (drawn in this order, one [`colour`](crate::colour) each) and the
    /// scene's objects seen from `view`, the view fitted to the drawn joints over all frames
    /// and to the moving objects.
    pub fn new(tracks: Vec<Track>, props: Vec<Prop>, view: View) -> Scene {
        let bounds = Bounds::around(
            tracks
                .iter()
                .flat_map(|t| t.drawn_points().map(|p| view.project(p)))
                .chain(props.iter().flat_map(|p| p.moving_points(view))),
        );
        Scene {
            tracks,
            props,
            bounds,
            view,
        }
    }

    /// The names of the objects a plan moves.
    pub fn moving_objects(&self) -> Vec<String> {
        self.props
            .iter()
            .filter(|p| p.moving())
            .map(|p| p.name().to_string())
            .collect()
    }
}

/// Text and line sizes of one picture, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Style {
    font_px: i32,
    line_px: u32,
}

impl Style {
    /// Sizes for panels `height` pixels high: text 1/`per_text` of it, lines 1/`per_line`.
    pub fn for_height(height: u32, per_text: u32, per_line: u32) -> Style {
        Style {
            font_px: i32::try_from(height / per_text)
                .unwrap_or(i32::MAX)
                .clamp(10, 64),
            line_px: (height / per_line).clamp(1, 8),
        }
    }
}

fn text_style(px: i32, colour: RGBColor) -> TextStyle<'static> {
    (FONT, f64::from(px)).into_font().color(&colour)
}

/// The legend's layout: entries in rows across the picture's width.
struct Legend {
    /// Each entry's top-left corner, pixels.
    spots: Vec<(i32, i32)>,
    /// The band's height, pixels.
    height: u32,
}

/// Lays the legend out in rows across `root`'s width.
fn layout_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
) -> Result<Legend, Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let width = i32::try_from(root.dim_in_pixel().0)?;
    let fs = style.font_px;
    let row = fs + fs / 2;
    let text = text_style(fs, BLACK);
    let swatch = SWATCH * fs / 16;
    let (mut x, mut y) = (8, 4);
    let mut spots = Vec::with_capacity(scene.tracks.len());
    for track in &scene.tracks {
        let (tw, _) = root.estimate_text_size(&track.label, &text)?;
        let entry = swatch + 5 + i32::try_from(tw)?;
        if x > 8 && x + entry > width - 8 {
            x = 8;
            y += row;
        }
        spots.push((x, y));
        x += entry + fs + 4;
    }
    Ok(Legend {
        spots,
        height: u32::try_from(y + row + 2)?,
    })
}

/// Draws the legend band and, below it, one panel per instant in `times`, side by side.
pub fn draw_scene<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
    times: &[f64],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let legend = layout_legend(root, scene, style)?;
    let (top, rest) = root.split_vertically(legend.height);
    let fs = style.font_px;
    let swatch = SWATCH * fs / 16;
    for (i, (track, &(x, y))) in scene.tracks.iter().zip(&legend.spots).enumerate() {
        let c = crate::colour(i);
        let mid = y + fs / 2 + 1;
        top.draw(&PathElement::new(
            vec![(x, mid), (x + swatch, mid)],
            c.stroke_width((style.line_px + 2).max(3)),
        ))?;
        top.draw(&Text::new(
            track.label.as_str(),
            (x + swatch + 5, y),
            text_style(fs, c),
        ))?;
    }
    let (_, height) = rest.dim_in_pixel();
    let height = i32::try_from(height)?;
    for (j, (panel, &t)) in rest
        .split_evenly((1, times.len()))
        .iter()
        .zip(times)
        .enumerate()
    {
        if j > 0 {
            panel.draw(&PathElement::new(
                vec![(0, 0), (0, height)],
                RGBColor(200, 200, 200).stroke_width(1),
            ))?;
        }
        draw_panel(panel, scene, style, t)?;
    }
    Ok(())
}

/// Light fills and darker edges of the scene's fixed and moving objects.
const FIXED_FILL: RGBColor = RGBColor(228, 228, 228);
const FIXED_EDGE: RGBColor = RGBColor(150, 150, 150);
const MOVING_FILL: RGBColor = RGBColor(240, 200, 120);
const MOVING_EDGE: RGBColor = RGBColor(150, 95, 0);

/// Draws the scene's objects at time `t`: fixed ones first, moving ones over them, each
/// clipped to the panel's figure area `(x0, y0, x1, y1)`, pixels.
fn draw_props<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    scene: &Scene,
    map: &Mapping,
    area: (f64, f64, f64, f64),
    t: f64,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let px = |p: Flat| map.pixel_f(p);
    let round = |p: Flat| (p.0.round() as i32, p.1.round() as i32);
    for moving in [false, true] {
        let (fill, edge) = if moving {
            (MOVING_FILL, MOVING_EDGE)
        } else {
            (FIXED_FILL, FIXED_EDGE)
        };
        for prop in scene.props.iter().filter(|p| p.moving() == moving) {
            let outline = prop.solid.outline(prop.pose(t), |p| scene.view.project(p));
            for polygon in &outline.fills {
                let pixels: Vec<Flat> = polygon.iter().map(|&p| px(p)).collect();
                let clipped = clip_polygon(&pixels, area);
                if clipped.len() >= 3 {
                    let points: Vec<(i32, i32)> = clipped.into_iter().map(round).collect();
                    panel.draw(&Polygon::new(points, fill.filled()))?;
                }
            }
            for line in &outline.lines {
                if let Some([a, b]) = clip_line([px(line[0]), px(line[1])], area) {
                    panel.draw(&PathElement::new(
                        vec![round(a), round(b)],
                        edge.stroke_width(1),
                    ))?;
                }
            }
        }
    }
    Ok(())
}

/// Draws the scene and every clip's stick figure at time `t` with the time in the
/// bottom-left corner.
fn draw_panel<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
    t: f64,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, h) = panel.dim_in_pixel();
    let (w, h) = (i32::try_from(w)?, i32::try_from(h)?);
    let fs = style.font_px;
    let label_band = fs + fs / 2;
    let figure_area = (4, 2, w - 4, h - label_band);
    let map = Mapping::fit(&scene.bounds, figure_area);
    let b = &scene.bounds;
    // The floor, where the box holds it.
    if scene.view != View::Top && b.v0 < 0.0 && 0.0 < b.v1 {
        let left = map.pixel((b.u0, 0.0));
        let right = map.pixel((b.u1, 0.0));
        if let (Some(l), Some(r)) = (left, right) {
            panel.draw(&PathElement::new(
                vec![l, r],
                RGBColor(190, 190, 190).stroke_width(1),
            ))?;
        }
    }
    if !scene.props.is_empty() {
        let area = (0.0, 0.0, f64::from(w - 1), f64::from(h - label_band));
        draw_props(panel, scene, &map, area, t)?;
    }
    let line = style.line_px;
    let dot = line as i32 + 1;
    for (i, track) in scene.tracks.iter().enumerate() {
        let c = crate::colour(i);
        let world = track.at(t);
        let pixels: Vec<Option<(i32, i32)>> = world
            .iter()
            .map(|p| map.pixel(scene.view.project(p)))
            .collect();
        for segment in track.figure.world_segments(world) {
            if let (Some(a), Some(b)) = (pixels[segment.parent], pixels[segment.child]) {
                let width = match segment.kind {
                    BoneKind::Body => line,
                    BoneKind::Finger => 1,
                };
                panel.draw(&PathElement::new(vec![a, b], c.stroke_width(width)))?;
            }
        }
        for &j in track.figure.dots() {
            if let Some(p) = pixels[j] {
                panel.draw(&Circle::new(p, dot, c.filled()))?;
            }
        }
    }
    panel.draw(&Text::new(
        format!("t = {t:.2} s"),
        (6, h - label_band + fs / 4),
        text_style(fs, BLACK),
    ))?;
    Ok(())
}

/// The film strip: snapshots side by side under one legend.
#[derive(Debug, Clone, Copy)]
pub struct Strip<'a> {
    /// What is drawn.
    pub scene: &'a Scene,
    /// Its text and line sizes.
    pub style: Style,
    /// The snapshots' times, seconds.
    pub times: &'a [f64],
}

impl Figure for Strip<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        draw_scene(root, self.scene, self.style, self.times)
    }
}
