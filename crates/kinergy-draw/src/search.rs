//! Kallmann's Fig. 4 — "the graph of a search and the solution path, before smoothing" — for
//! each planned phase of a plan ([`SearchTrace`], `kinergy plan --tree-svg`): both RRT-Connect
//! trees projected in a [`View`] (each node at its wrist position, an edge from parent to
//! child), the wrist's path as the search found it and as smoothing left it, the scene's
//! objects behind.
//!
//! One panel per planned phase, side by side, each fitted to its trees and paths. What is
//! drawn, so that a picture can be checked against the report:
//!
//! - every tree edge is one two-point line (an SVG `<polyline>`) in its tree's colour —
//!   [`START_TREE`] for the tree grown from the start, [`GOAL_TREE`] for the goal's — and
//!   nothing else is drawn as a line in those colours (the legend's swatches are filled
//!   rectangles): a tree of n nodes gives n − 1 such lines;
//! - each root is a filled disc in its tree's colour;
//! - the wrist path as found is a thin black line, the smoothed one a thick green line;
//! - scene objects are light grey: boxes, spheres and capsules filled, meshes by their
//!   feature edges only ([`shapes`](crate::shapes)).

use nalgebra::{Isometry3, Point3};
use plotters::coord::Shift;
use plotters::prelude::*;

use kinergy_plan::request::SearchTrace;
use kinergy_plan::scene::Scene;

use crate::animation::View;
use crate::animation::{Bounds, Mapping};
use crate::shapes::{Flat, Solid, clip_line, clip_polygon};
use crate::{DrawResult, FONT, Figure, font_scale, scaled};

/// The colour of the tree grown from the start (Okabe–Ito blue).
pub const START_TREE: RGBColor = RGBColor(0, 114, 178);
/// The colour of the tree grown from the goal (Okabe–Ito vermillion).
pub const GOAL_TREE: RGBColor = RGBColor(213, 94, 0);
/// The wrist path as the search found it.
pub const RAW_PATH: RGBColor = RGBColor(0, 0, 0);
/// The wrist path after smoothing (Okabe–Ito bluish green).
pub const SMOOTHED_PATH: RGBColor = RGBColor(0, 158, 115);

/// How much of the scene around the start's and the goal's wrist a panel shows at least,
/// meters.
const CONTEXT_M: f64 = 0.15;

const OBJECT_FILL: RGBColor = RGBColor(232, 232, 232);
const OBJECT_EDGE: RGBColor = RGBColor(165, 165, 165);

/// One planned phase's search, projected on the screen (meters, right and up).
#[derive(Debug, Clone)]
struct Panel {
    /// `reach: 12 + 9 nodes` and `wrist 0.9 → 0.7 m`, two lines.
    label: [String; 2],
    /// Each tree's edges, parent → child, and its root.
    trees: [(Vec<[Flat; 2]>, Flat); 2],
    raw: Vec<Flat>,
    smoothed: Vec<Flat>,
    bounds: Bounds,
}

/// Kallmann's Fig. 4 for a plan's searches ([module docs](self)).
#[derive(Debug, Clone)]
pub struct SearchFigure {
    title: String,
    panels: Vec<Panel>,
    /// The scene's objects: their shapes and poses.
    objects: Vec<(Solid, Isometry3<f64>)>,
    view: View,
    /// Said where there is no search to draw.
    note: String,
}

/// The length of a polyline, meters.
fn length(points: &[Point3<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

impl SearchFigure {
    /// The figure of `searches` seen from `view`, titled `title`, with `scene`'s objects
    /// behind (`None`: none); `note` is said in place of the panels when there is no search
    /// (a reach solved without the planner).
    pub fn new(
        title: String,
        searches: &[SearchTrace],
        scene: Option<&Scene>,
        view: View,
        note: String,
    ) -> SearchFigure {
        let project = |p: &Point3<f64>| view.project(p);
        let panels = searches
            .iter()
            .map(|s| {
                let trees = s.trees.each_ref().map(|t| {
                    let edges = t
                        .edges()
                        .map(|(a, b)| [project(&t.nodes[a].wrist), project(&t.nodes[b].wrist)])
                        .collect();
                    let root = t.nodes.first().map_or((0.0, 0.0), |n| project(&n.wrist));
                    (edges, root)
                });
                let raw: Vec<Flat> = s.raw_wrist.iter().map(project).collect();
                let smoothed: Vec<Flat> = s.smoothed_wrist.iter().map(project).collect();
                // The trees and paths, and what lies around the start and the goal.
                let around = trees.iter().flat_map(|(_, (u, v))| {
                    [(-1.0, -1.0), (1.0, 1.0)].map(|(a, b)| (u + a * CONTEXT_M, v + b * CONTEXT_M))
                });
                let bounds = Bounds::around(
                    s.trees
                        .iter()
                        .flat_map(|t| t.nodes.iter().map(|n| project(&n.wrist)))
                        .chain(raw.iter().copied())
                        .chain(smoothed.iter().copied())
                        .chain(around),
                );
                Panel {
                    label: [
                        format!(
                            "{}: {} + {} nodes",
                            s.phase,
                            s.trees[0].nodes.len(),
                            s.trees[1].nodes.len()
                        ),
                        format!(
                            "wrist {:.2} → {:.2} m",
                            length(&s.raw_wrist),
                            length(&s.smoothed_wrist)
                        ),
                    ],
                    trees,
                    raw,
                    smoothed,
                    bounds,
                }
            })
            .collect();
        let objects = scene
            .map(|s| {
                s.objects
                    .iter()
                    .map(|o| (Solid::new(&o.shape), o.pose))
                    .collect()
            })
            .unwrap_or_default();
        SearchFigure {
            title,
            panels,
            objects,
            view,
            note,
        }
    }

    /// The tree edges drawn: one line each.
    pub fn edge_count(&self) -> usize {
        self.panels
            .iter()
            .map(|p| p.trees[0].0.len() + p.trees[1].0.len())
            .sum()
    }
}

fn text_style(px: i32, colour: RGBColor) -> TextStyle<'static> {
    (FONT, f64::from(px)).into_font().color(&colour)
}

impl Figure for SearchFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let k = font_scale(root);
        let fs = i32::try_from(scaled(16.0, k))?;
        let (top, rest) = root.split_vertically(u32::try_from(3 * fs + fs / 2)?);
        top.draw(&Text::new(
            self.title.clone(),
            (8, 4),
            text_style(fs, BLACK),
        ))?;
        // The legend: filled swatches, so the only lines in the trees' colours are edges.
        let mut x = 8;
        let y = 4 + fs + fs / 2;
        for (name, c) in [
            ("tree from the start", START_TREE),
            ("tree from the goal", GOAL_TREE),
            ("wrist path found", RAW_PATH),
            ("smoothed", SMOOTHED_PATH),
        ] {
            top.draw(&Rectangle::new(
                [(x, y + fs / 3), (x + fs, y + 2 * fs / 3)],
                c.filled(),
            ))?;
            top.draw(&Text::new(name, (x + fs + 5, y), text_style(fs, c)))?;
            let (tw, _) = top.estimate_text_size(name, &text_style(fs, c))?;
            x += 2 * fs + 5 + i32::try_from(tw)?;
        }
        let (_, h) = rest.dim_in_pixel();
        if self.panels.is_empty() {
            rest.draw(&Text::new(
                self.note.clone(),
                (8, i32::try_from(h / 2)?),
                text_style(fs, BLACK),
            ))?;
            return Ok(());
        }
        let line = scaled(1.5, k);
        let dot = i32::try_from(scaled(5.0, k))?;
        let label_band = 2 * fs + fs / 2;
        let h = i32::try_from(h)?;
        for (j, (area, panel)) in rest
            .split_evenly((1, self.panels.len()))
            .iter()
            .zip(&self.panels)
            .enumerate()
        {
            let (pw, _) = area.dim_in_pixel();
            let pw = i32::try_from(pw)?;
            if j > 0 {
                area.draw(&PathElement::new(
                    vec![(0, 0), (0, h)],
                    RGBColor(200, 200, 200).stroke_width(1),
                ))?;
            }
            let map = Mapping::fit(&panel.bounds, (6, 4, pw - 6, h - label_band));
            let clip = (0.0, 0.0, f64::from(pw - 1), f64::from(h - label_band));
            let round = |p: Flat| (p.0.round() as i32, p.1.round() as i32);
            for (solid, pose) in &self.objects {
                let outline = solid.outline(pose, |p| self.view.project(p));
                // A mesh by its feature edges alone: its triangles would be most of the file.
                let fills = match solid {
                    Solid::Mesh { .. } => &[][..],
                    Solid::Convex(_) => &outline.fills[..],
                };
                for polygon in fills {
                    let pixels: Vec<Flat> = polygon.iter().map(|&p| map.pixel_f(p)).collect();
                    let clipped = clip_polygon(&pixels, clip);
                    if clipped.len() >= 3 {
                        let points: Vec<(i32, i32)> = clipped.into_iter().map(round).collect();
                        area.draw(&Polygon::new(points, OBJECT_FILL.filled()))?;
                    }
                }
                for l in &outline.lines {
                    if let Some([a, b]) = clip_line([map.pixel_f(l[0]), map.pixel_f(l[1])], clip) {
                        area.draw(&PathElement::new(
                            vec![round(a), round(b)],
                            OBJECT_EDGE.stroke_width(1),
                        ))?;
                    }
                }
            }
            let px = |p: Flat| round(map.pixel_f(p));
            for ((edges, _), c) in panel.trees.iter().zip([START_TREE, GOAL_TREE]) {
                for [a, b] in edges {
                    area.draw(&PathElement::new(
                        vec![px(*a), px(*b)],
                        c.stroke_width(line),
                    ))?;
                }
            }
            area.draw(&PathElement::new(
                panel.raw.iter().map(|&p| px(p)).collect::<Vec<_>>(),
                RAW_PATH.stroke_width(line + 1),
            ))?;
            area.draw(&PathElement::new(
                panel.smoothed.iter().map(|&p| px(p)).collect::<Vec<_>>(),
                SMOOTHED_PATH.stroke_width(line + 3),
            ))?;
            for ((_, root), c) in panel.trees.iter().zip([START_TREE, GOAL_TREE]) {
                area.draw(&Circle::new(px(*root), dot, c.filled()))?;
            }
            for (i, text) in (0..).zip(&panel.label) {
                area.draw(&Text::new(
                    text.clone(),
                    (6, h - label_band + fs / 4 + i * fs),
                    text_style(fs, BLACK),
                ))?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinergy_plan::rrt::{SearchTree, TreeNode};

    fn node(x: f64, parent: Option<usize>) -> TreeNode {
        TreeNode {
            q: [0.0; kinergy_plan::posture::CONFIG_DOFS],
            wrist: Point3::new(x, 1.0, 0.3 * x),
            parent,
        }
    }

    /// Every tree edge is one line in its tree's colour, and no other line has those colours.
    #[test]
    fn each_tree_edge_is_one_line_in_its_trees_colour() {
        let trace = SearchTrace {
            phase: "reach".into(),
            trees: [
                SearchTree {
                    nodes: vec![node(0.0, None), node(0.1, Some(0)), node(0.2, Some(0))],
                },
                SearchTree {
                    nodes: vec![node(0.5, None), node(0.4, Some(0))],
                },
            ],
            raw_wrist: vec![Point3::new(0.0, 1.0, 0.0), Point3::new(0.5, 1.0, 0.15)],
            smoothed_wrist: vec![Point3::new(0.0, 1.0, 0.0), Point3::new(0.5, 1.0, 0.15)],
        };
        let figure = SearchFigure::new("t".into(), &[trace], None, View::Front, String::new());
        assert_eq!(figure.edge_count(), 3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("trees.svg");
        crate::save(&figure, &path, (600, 400)).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap().to_ascii_uppercase();
        let lines = |c: RGBColor| {
            let stroke = format!("STROKE=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
            svg.lines()
                .filter(|l| l.contains("<POLYLINE") && l.contains(&stroke))
                .count()
        };
        assert_eq!((lines(START_TREE), lines(GOAL_TREE)), (2, 1));
    }
}
