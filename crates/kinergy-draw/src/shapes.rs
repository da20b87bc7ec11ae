//! Scene objects as flat pictures: each shape's outline projected in a view.
//!
//! Pure (no drawing), so the picture tests can check what a scene puts on the screen.
//! Projections are orthographic ([`animation`](crate::animation)'s views): a box is drawn as
//! the convex hull of its projected corners, a sphere as a disc, a capsule as the hull of its
//! two end discs; a mesh as its projected triangles filled, with its *feature edges* (edges on
//! one triangle only, or between triangles meeting at more than [`FEATURE_ANGLE_DEG`]) as
//! lines — the boards of a shelf, not its tessellation.

use std::collections::HashMap;

use kinergy_plan::scene::Shape;
use nalgebra::{Isometry3, Point3, Vector3};

/// Triangles meeting at more than this angle (degrees) draw their shared edge.
pub const FEATURE_ANGLE_DEG: f64 = 20.0;
/// Points on each great circle of a sphere or a capsule's end.
const CIRCLE_POINTS: usize = 32;
/// Projected triangles smaller than this (square meters) are seen edge-on: not filled.
const MIN_AREA_M2: f64 = 1e-9;

/// A point on the screen, meters (right, up).
pub type Flat = (f64, f64);

/// A shape made ready to draw: its geometry in its own frame.
#[derive(Debug, Clone)]
pub enum Solid {
    /// A convex shape: the points whose projected hull is its outline.
    Convex(Vec<Point3<f64>>),
    /// A mesh: its triangles and feature edges.
    Mesh {
        /// The triangles' corners.
        triangles: Vec<[Point3<f64>; 3]>,
        /// The feature edges.
        edges: Vec<[Point3<f64>; 2]>,
    },
}

/// A shape projected on the screen.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outline {
    /// Polygons to fill (convex hulls, or a mesh's triangles).
    pub fills: Vec<Vec<Flat>>,
    /// Lines to draw: the polygons' borders for convex shapes, feature edges for meshes.
    pub lines: Vec<[Flat; 2]>,
}

impl Solid {
    /// Prepares `shape` (a mesh's feature edges are found here, once).
    pub fn new(shape: &Shape) -> Solid {
        match shape {
            Shape::Box { half_extents: h } => Solid::Convex(
                (0..8)
                    .map(|i| {
                        let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
                        Point3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
                    })
                    .collect(),
            ),
            Shape::Sphere { radius } => Solid::Convex(ball(Point3::origin(), *radius)),
            Shape::Capsule {
                half_height,
                radius,
            } => {
                let mut points = ball(Point3::new(0.0, *half_height, 0.0), *radius);
                points.extend(ball(Point3::new(0.0, -*half_height, 0.0), *radius));
                Solid::Convex(points)
            }
            Shape::Mesh { mesh, .. } => {
                let corner = |i: u32| mesh.vertices.get(i as usize).copied();
                let triangles: Vec<[Point3<f64>; 3]> = mesh
                    .triangles
                    .iter()
                    .filter_map(|t| Some([corner(t[0])?, corner(t[1])?, corner(t[2])?]))
                    .collect();
                let edges = feature_edges(&triangles);
                Solid::Mesh { triangles, edges }
            }
        }
    }

    /// The shape at `pose` seen through `project` (an orthographic view: world → screen).
    pub fn outline(
        &self,
        pose: &Isometry3<f64>,
        project: impl Fn(&Point3<f64>) -> Flat,
    ) -> Outline {
        let flat = |p: &Point3<f64>| project(&(pose * p));
        match self {
            Solid::Convex(points) => {
                let hull = convex_hull(points.iter().map(flat).collect());
                let lines = hull
                    .iter()
                    .zip(hull.iter().cycle().skip(1))
                    .map(|(&a, &b)| [a, b])
                    .collect();
                Outline {
                    fills: vec![hull],
                    lines,
                }
            }
            Solid::Mesh { triangles, edges } => Outline {
                fills: triangles
                    .iter()
                    .map(|t| t.map(|p| flat(&p)))
                    .filter(|[a, b, c]| {
                        ((b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)).abs() / 2.0
                            > MIN_AREA_M2
                    })
                    .map(|t| t.to_vec())
                    .collect(),
                lines: edges.iter().map(|e| e.map(|p| flat(&p))).collect(),
            },
        }
    }
}

/// Points on three great circles of a ball: any orthographic view along an axis sees its
/// disc exactly, and others nearly.
fn ball(centre: Point3<f64>, radius: f64) -> Vec<Point3<f64>> {
    let mut out = Vec::with_capacity(3 * CIRCLE_POINTS);
    for k in 0..CIRCLE_POINTS {
        let a = std::f64::consts::TAU * k as f64 / CIRCLE_POINTS as f64;
        let (s, c) = (radius * a.sin(), radius * a.cos());
        out.push(centre + Vector3::new(c, s, 0.0));
        out.push(centre + Vector3::new(0.0, c, s));
        out.push(centre + Vector3::new(s, 0.0, c));
    }
    out
}

/// Edges on one triangle only, on more than two, or between two triangles whose normals
/// differ by more than [`FEATURE_ANGLE_DEG`]. Corners are matched by position (to 0.1 mm),
/// so meshes that repeat vertices per face are read the same.
fn feature_edges(triangles: &[[Point3<f64>; 3]]) -> Vec<[Point3<f64>; 2]> {
    let key = |p: &Point3<f64>| {
        let q = |v: f64| (v * 1e4).round() as i64;
        (q(p.x), q(p.y), q(p.z))
    };
    // Per edge (by its corners' keys): how many triangles share it, their normals, the edge.
    type Sharing = (usize, Vec<Vector3<f64>>, [Point3<f64>; 2]);
    let mut normals: HashMap<_, Sharing> = HashMap::new();
    for t in triangles {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        let n = n.try_normalize(1e-15).unwrap_or_else(Vector3::zeros);
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (ka, kb) = (key(&a), key(&b));
            if ka == kb {
                continue;
            }
            let k = if ka < kb { (ka, kb) } else { (kb, ka) };
            let entry = normals.entry(k).or_insert((0, Vec::new(), [a, b]));
            entry.0 += 1;
            entry.1.push(n);
        }
    }
    let cos = FEATURE_ANGLE_DEG.to_radians().cos();
    let mut edges: Vec<_> = normals
        .into_values()
        .filter(|(count, n, _)| *count != 2 || n[0].dot(&n[1]) < cos)
        .map(|(_, _, e)| e)
        .collect();
    // HashMap order varies from run to run: sort so pictures are reproducible.
    edges.sort_by(|a, b| {
        let k = |e: &[Point3<f64>; 2]| [e[0].x, e[0].y, e[0].z, e[1].x, e[1].y, e[1].z];
        k(a).partial_cmp(&k(b)).unwrap_or(std::cmp::Ordering::Equal)
    });
    edges
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain); non-finite
/// points are dropped.
pub fn convex_hull(mut points: Vec<Flat>) -> Vec<Flat> {
    points.retain(|p| p.0.is_finite() && p.1.is_finite());
    points.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Flat, a: Flat, b: Flat| (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0);
    let mut hull: Vec<Flat> = Vec::with_capacity(points.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Flat>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Clips a polygon to the rectangle `[x0, x1] × [y0, y1]` (Sutherland–Hodgman).
pub fn clip_polygon(polygon: &[Flat], (x0, y0, x1, y1): (f64, f64, f64, f64)) -> Vec<Flat> {
    let mut out = polygon.to_vec();
    // Each edge of the rectangle: inside test and the crossing with a segment.
    let sides: [(usize, f64, bool); 4] =
        [(0, x0, true), (0, x1, false), (1, y0, true), (1, y1, false)];
    for (axis, at, keep_above) in sides {
        if out.is_empty() {
            break;
        }
        let coord = |p: &Flat| if axis == 0 { p.0 } else { p.1 };
        let inside = |p: &Flat| {
            if keep_above {
                coord(p) >= at
            } else {
                coord(p) <= at
            }
        };
        let input = std::mem::take(&mut out);
        for (i, cur) in input.iter().enumerate() {
            let prev = &input[(i + input.len() - 1) % input.len()];
            let crossing = || {
                let t = (at - coord(prev)) / (coord(cur) - coord(prev));
                (prev.0 + t * (cur.0 - prev.0), prev.1 + t * (cur.1 - prev.1))
            };
            match (inside(prev), inside(cur)) {
                (true, true) => out.push(*cur),
                (true, false) => out.push(crossing()),
                (false, true) => {
                    out.push(crossing());
                    out.push(*cur);
                }
                (false, false) => {}
            }
        }
    }
    out
}

/// Clips a segment to the rectangle `[x0, x1] × [y0, y1]` (Liang–Barsky); `None` outside.
pub fn clip_line([a, b]: [Flat; 2], (x0, y0, x1, y1): (f64, f64, f64, f64)) -> Option<[Flat; 2]> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some([
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ])
}
