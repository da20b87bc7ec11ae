//! The bookshelf example's shelf unit (the scene of Kallmann 2005, Fig. 5): side panels,
//! horizontal boards and a back panel, tessellated as densely as a modelled asset.

use std::collections::HashMap;

use kinergy_io::InvalidSetting;
use nalgebra::Point3;

use crate::error::Result;
use crate::obj::Mesh;

/// The most grid squares along one edge of a box that [`ShelfUnit::mesh`] makes, whatever
/// the `cell`, so that an unvalidated tiny cell cannot ask for unbounded memory.
const MAX_DIVISIONS: usize = 1000;

/// The most triangles [`ShelfUnit::validate`] accepts.
const MAX_TRIANGLES: usize = 1_000_000;

/// Dimensions of a shelf unit (meters).
///
/// Its frame: the origin is on the floor at the centre of the unit's front edge; x runs
/// across the width (the unit spans `−width/2..width/2`), y up (`0..height`), z toward the
/// back (`0..depth`): the open front is the plane z = 0 and faces −z.
///
/// The parts, each a closed box:
/// - two side panels, `board` thick, full height, from the front (z = 0) to the back
///   panel;
/// - a back panel, `board` thick, full width and height, at `depth − board..depth`;
/// - a horizontal board, `board` thick, for each entry of `shelf_tops` (the first is the
///   bottom board) and a top board whose top is at `height`; the boards span the inside
///   between the side panels ([`ShelfUnit::inner_x`]) and from the front to the back panel
///   ([`ShelfUnit::inner_z`]).
///
/// Parts touch but do not overlap.
#[derive(Debug, Clone, PartialEq)]
pub struct ShelfUnit {
    /// Outer width, along x.
    pub width: f64,
    /// Outer height, along y (the top of the top board).
    pub height: f64,
    /// Outer depth, along z (the back of the back panel).
    pub depth: f64,
    /// Thickness of every panel and board.
    pub board: f64,
    /// Heights (y) of the top surfaces of the horizontal boards below the top board,
    /// bottom first, increasing.
    pub shelf_tops: Vec<f64>,
    /// Tessellation cell size: box faces are cut into a grid of squares of side ≈ `cell`.
    pub cell: f64,
}

impl Default for ShelfUnit {
    /// A 0.80 m wide, 1.90 m high, 0.30 m deep unit of 2 cm boards with boards whose tops
    /// are at 0.10, 0.55, 1.00, 1.38 and 1.76 m plus the top board, tessellated with a
    /// 3.75 cm cell: 11,900 triangles, the density of the paper's 12K-triangle scene.
    fn default() -> ShelfUnit {
        ShelfUnit {
            width: 0.80,
            height: 1.90,
            depth: 0.30,
            board: 0.02,
            shelf_tops: vec![0.10, 0.55, 1.00, 1.38, 1.76],
            cell: 0.0375,
        }
    }
}

impl ShelfUnit {
    /// The unit as a closed triangle mesh: the boxes of [`ShelfUnit::boxes`], each face cut
    /// into a grid of squares of side ≈ `cell` (at least one per edge), each square two
    /// triangles wound counter-clockwise seen from outside. Each box is closed on its own:
    /// it shares vertices between its faces, not with other boxes.
    ///
    /// Meant for a unit that passes [`ShelfUnit::validate`]; otherwise the mesh is still
    /// made (without panicking) but may be meaningless.
    pub fn mesh(&self) -> Mesh {
        let mut mesh = Mesh {
            vertices: Vec::new(),
            triangles: Vec::with_capacity(self.triangle_count()),
        };
        for (min, max) in self.boxes() {
            BoxGrid::new(min, max, self.cell).tessellate(&mut mesh);
        }
        mesh
    }

    /// The unit's parts as axis-aligned boxes (min corner, max corner) in the unit frame:
    /// the left (−x) and right side panels, the back panel, then the horizontal boards from
    /// the bottom up, the top board last.
    pub fn boxes(&self) -> Vec<(Point3<f64>, Point3<f64>)> {
        let (w, h, d, b) = (self.width / 2.0, self.height, self.depth, self.board);
        let (x0, x1) = self.inner_x();
        let (z0, z1) = self.inner_z();
        let mut boxes = vec![
            (Point3::new(-w, 0.0, z0), Point3::new(x0, h, z1)),
            (Point3::new(x1, 0.0, z0), Point3::new(w, h, z1)),
            (Point3::new(-w, 0.0, z1), Point3::new(w, h, d)),
        ];
        let tops = self.shelf_tops.iter().copied().chain([h]);
        boxes.extend(tops.map(|top| (Point3::new(x0, top - b, z0), Point3::new(x1, top, z1))));
        boxes
    }

    /// Checks that the sizes are positive and finite, that the panels leave room inside,
    /// that every shelf top is finite, inside the unit (its board above the floor and
    /// below the top board) and at least `board` above the previous one, and that `cell`
    /// gives at most 1,000,000 triangles.
    ///
    /// # Errors
    ///
    /// [`PlanError::Setting`](crate::error::PlanError::Setting) naming the offending field
    /// (`width`, `height`, `depth`, `board`, `shelf_tops` or `cell`).
    pub fn validate(&self) -> Result<()> {
        for (field, value) in [
            ("width", self.width),
            ("height", self.height),
            ("depth", self.depth),
            ("board", self.board),
            ("cell", self.cell),
        ] {
            InvalidSetting::require(
                value.is_finite() && value > 0.0,
                field,
                format!(
                    "expected a positive finite length in meters, found {}",
                    kinergy_io::Num(value)
                ),
            )?;
        }
        self.validate_board()?;
        self.validate_shelf_tops()?;
        let triangles = self.triangle_count();
        InvalidSetting::require(
            triangles <= MAX_TRIANGLES,
            "cell",
            format!(
                "a cell of {} m gives {triangles} triangles, more than {MAX_TRIANGLES}; \
                 expected a larger cell",
                self.cell
            ),
        )?;
        Ok(())
    }

    /// The inner surface heights one can stand objects on: each board's top y (in the unit
    /// frame), bottom first; the top of the top board (`height`) is not included.
    pub fn shelf_tops(&self) -> &[f64] {
        &self.shelf_tops
    }

    /// The x range inside the side panels (the boards' extent across the unit).
    pub fn inner_x(&self) -> (f64, f64) {
        let half = self.width / 2.0;
        (-half + self.board, half - self.board)
    }

    /// The z range of the boards: from the front edge (z = 0) to the back panel.
    pub fn inner_z(&self) -> (f64, f64) {
        (0.0, self.depth - self.board)
    }

    /// The panels leave room between them, in front of the back panel and below the top.
    fn validate_board(&self) -> Result<()> {
        let b = self.board;
        InvalidSetting::require(
            2.0 * b < self.width && b < self.depth && b < self.height,
            "board",
            format!(
                "expected a thickness below half the width ({} m), the depth ({} m) and the \
                 height ({} m), found {}",
                kinergy_io::Num(self.width / 2.0),
                kinergy_io::Num(self.depth),
                kinergy_io::Num(self.height),
                kinergy_io::Num(b)
            ),
        )?;
        Ok(())
    }

    /// Every shelf top is finite, inside the unit and a board above the previous one.
    fn validate_shelf_tops(&self) -> Result<()> {
        let (lowest, highest) = (self.board, self.height - self.board);
        let mut previous: Option<f64> = None;
        for (i, &top) in self.shelf_tops.iter().enumerate() {
            InvalidSetting::require(
                top.is_finite() && (lowest..=highest).contains(&top),
                "shelf_tops",
                format!(
                    "shelf_tops[{i}] = {top}: expected a height from {lowest} m (the board \
                     on the floor) to {highest} m (under the top board)"
                ),
            )?;
            if let Some(below) = previous {
                InvalidSetting::require(
                    top - below >= self.board,
                    "shelf_tops",
                    format!(
                        "shelf_tops[{i}] = {top}: expected increasing heights at least a \
                         board ({} m) apart, but the previous one is {below}",
                        self.board
                    ),
                )?;
            }
            previous = Some(top);
        }
        Ok(())
    }

    /// The number of triangles [`ShelfUnit::mesh`] makes.
    fn triangle_count(&self) -> usize {
        self.boxes()
            .iter()
            .map(|(min, max)| BoxGrid::new(*min, *max, self.cell).triangle_count())
            .fold(0, usize::saturating_add)
    }
}

/// The grid squares along an edge of `length`: `length / cell` rounded, at least 1 and at
/// most [`MAX_DIVISIONS`].
fn divisions(length: f64, cell: f64) -> usize {
    let ratio = (length / cell).round();
    if ratio.is_finite() && ratio > 1.0 {
        // In 2..=MAX_DIVISIONS, so the conversion is exact.
        ratio.min(MAX_DIVISIONS as f64) as usize
    } else {
        1
    }
}

/// The surface lattice of one box: `divisions[a] + 1` points along each axis `a`, of
/// which the tessellation uses those on the surface.
struct BoxGrid {
    min: Point3<f64>,
    max: Point3<f64>,
    divisions: [usize; 3],
}

impl BoxGrid {
    fn new(min: Point3<f64>, max: Point3<f64>, cell: f64) -> BoxGrid {
        let divisions = [0, 1, 2].map(|axis| divisions(max[axis] - min[axis], cell));
        BoxGrid {
            min,
            max,
            divisions,
        }
    }

    /// Two triangles per grid square of the six faces.
    fn triangle_count(&self) -> usize {
        let [a, b, c] = self.divisions;
        let squares = a
            .saturating_mul(b)
            .saturating_add(b.saturating_mul(c))
            .saturating_add(a.saturating_mul(c));
        squares.saturating_mul(4)
    }

    /// Appends the box's six faces to `mesh`.
    fn tessellate(&self, mesh: &mut Mesh) {
        let mut indices = HashMap::new();
        for axis in 0..3 {
            for at_max in [false, true] {
                self.face(axis, at_max, mesh, &mut indices);
            }
        }
    }

    /// The face normal to `axis` at the box's min or max side, wound so that its normal
    /// points out of the box.
    fn face(
        &self,
        axis: usize,
        at_max: bool,
        mesh: &mut Mesh,
        indices: &mut HashMap<[usize; 3], u32>,
    ) {
        // (u, v, axis) is right-handed, so u × v points along +axis: swap at the min side.
        let (u, v) = if at_max {
            ((axis + 1) % 3, (axis + 2) % 3)
        } else {
            ((axis + 2) % 3, (axis + 1) % 3)
        };
        let mut key = [0; 3];
        key[axis] = if at_max { self.divisions[axis] } else { 0 };
        for i in 0..self.divisions[u] {
            for j in 0..self.divisions[v] {
                let mut corner = |di: usize, dj: usize| {
                    key[u] = i + di;
                    key[v] = j + dj;
                    self.vertex(key, mesh, indices)
                };
                let [p00, p10, p11, p01] = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                mesh.triangles.push([p00, p10, p11]);
                mesh.triangles.push([p00, p11, p01]);
            }
        }
    }

    /// The mesh index of the lattice point `key`, adding the vertex on first use.
    fn vertex(
        &self,
        key: [usize; 3],
        mesh: &mut Mesh,
        indices: &mut HashMap<[usize; 3], u32>,
    ) -> u32 {
        *indices.entry(key).or_insert_with(|| {
            let index = u32::try_from(mesh.vertices.len()).unwrap_or(u32::MAX);
            let coordinate = |axis: usize| {
                lerp(
                    self.min[axis],
                    self.max[axis],
                    key[axis],
                    self.divisions[axis],
                )
            };
            mesh.vertices
                .push(Point3::new(coordinate(0), coordinate(1), coordinate(2)));
            index
        })
    }
}

/// The `step`-th of `steps` equal steps from `min` to `max`, exactly `min` and `max` at
/// the ends.
fn lerp(min: f64, max: f64, step: usize, steps: usize) -> f64 {
    if step == 0 {
        min
    } else if step >= steps {
        max
    } else {
        min + (max - min) * (step as f64 / steps as f64)
    }
}

/// The comment lines of the bookshelf example's `shelf.obj`.
pub const OBJ_HEADER: [&str; 3] = [
    "Kinergy bookshelf example: ShelfUnit::default() (kinergy-plan/src/shelf.rs).",
    "Frame: origin on the floor at the centre of the front edge, x across, y up, z to the back; meters.",
    "Regenerate: cargo run -p kinergy-plan --example make_bookshelf -- examples/bookshelf/shelf.obj",
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::PlanError;
    use crate::obj::{parse_obj, write_obj};
    use std::path::Path;

    fn corners(mesh: &Mesh, t: &[u32; 3]) -> [nalgebra::Vector3<f64>; 3] {
        t.map(|i| mesh.vertices[i as usize].coords)
    }

    /// An edit of a unit.
    type Change = fn(&mut ShelfUnit);

    /// The setting error's field.
    fn failed_field(unit: &ShelfUnit) -> String {
        match unit.validate() {
            Err(PlanError::Setting(e)) => e.field,
            other => panic!("expected a Setting error, got {other:?}"),
        }
    }

    #[test]
    fn default_is_valid() {
        ShelfUnit::default().validate().unwrap();
    }

    #[test]
    fn default_mesh_has_about_12k_triangles() {
        let unit = ShelfUnit::default();
        let mesh = unit.mesh();
        let count = mesh.triangle_count();
        assert!((11_500..=12_500).contains(&count), "{count}");
        assert_eq!(count, unit.triangle_count());
        assert_eq!(count, 11_900);
    }

    #[test]
    fn every_triangle_has_positive_area() {
        let mesh = ShelfUnit::default().mesh();
        for t in &mesh.triangles {
            let [a, b, c] = corners(&mesh, t);
            let area = (b - a).cross(&(c - a)).norm() / 2.0;
            assert!(area > 1e-6, "{t:?}: {area}");
        }
    }

    #[test]
    fn signed_volume_equals_the_sum_of_box_volumes() {
        let unit = ShelfUnit::default();
        let mesh = unit.mesh();
        let volume: f64 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = corners(&mesh, t);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum();
        let (w, h, d, b) = (unit.width, unit.height, unit.depth, unit.board);
        let boards = (unit.shelf_tops.len() + 1) as f64;
        let expected = 2.0 * b * h * (d - b) + w * h * b + boards * (w - 2.0 * b) * b * (d - b);
        assert!((volume - expected).abs() < 1e-9, "{volume} vs {expected}");
    }

    #[test]
    fn every_edge_is_shared_by_two_oppositely_wound_triangles() {
        let mesh = ShelfUnit::default().mesh();
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for &[a, b, c] in &mesh.triangles {
            for edge in [(a, b), (b, c), (c, a)] {
                *directed.entry(edge).or_default() += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "edge {a}->{b} used {count} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}->{b} has no twin");
        }
    }

    #[test]
    fn bounds_are_the_outer_dimensions() {
        let unit = ShelfUnit::default();
        let (min, max) = unit.mesh().bounds().unwrap();
        assert_eq!(min, Point3::new(-unit.width / 2.0, 0.0, 0.0));
        assert_eq!(max, Point3::new(unit.width / 2.0, unit.height, unit.depth));
    }

    #[test]
    fn boards_span_the_inside_and_touch_the_side_and_back_panels() {
        let unit = ShelfUnit::default();
        assert_eq!(unit.inner_x(), (-0.38, 0.38));
        assert_eq!(unit.inner_z(), (0.0, unit.depth - unit.board));
        assert_eq!(unit.shelf_tops(), &[0.10, 0.55, 1.00, 1.38, 1.76]);
        let boxes = unit.boxes();
        assert_eq!(boxes.len(), 3 + 6);
        let (left, right, back) = (boxes[0], boxes[1], boxes[2]);
        assert_eq!(left.1.x, unit.inner_x().0);
        assert_eq!(right.0.x, unit.inner_x().1);
        assert_eq!(back.0.z, unit.inner_z().1);
        for (board, top) in boxes[3..]
            .iter()
            .zip(unit.shelf_tops().iter().chain([&unit.height]))
        {
            assert_eq!((board.0.x, board.1.x), unit.inner_x());
            assert_eq!((board.0.z, board.1.z), unit.inner_z());
            assert_eq!(board.1.y, *top);
        }
    }

    #[test]
    fn mesh_round_trips_through_obj_exactly() {
        let mesh = ShelfUnit::default().mesh();
        let text = write_obj(&mesh, &["shelf unit"]);
        let back = parse_obj(&text, Path::new("shelf.obj")).unwrap();
        assert_eq!(back, mesh);
    }

    #[test]
    fn validate_rejects_a_shelf_top_above_the_height() {
        let mut unit = ShelfUnit::default();
        unit.shelf_tops.push(2.5);
        assert_eq!(failed_field(&unit), "shelf_tops");
    }

    #[test]
    fn validate_rejects_bad_settings() {
        let cases: [(&str, Change); 9] = [
            ("width", |u| u.width = f64::NAN),
            ("height", |u| u.height = 0.0),
            ("depth", |u| u.depth = -0.3),
            ("cell", |u| u.cell = f64::INFINITY),
            ("cell", |u| u.cell = 1e-4),
            ("board", |u| u.board = 0.5),
            ("shelf_tops", |u| u.shelf_tops = vec![0.5, 0.4]),
            ("shelf_tops", |u| u.shelf_tops = vec![0.5, 0.51]),
            ("shelf_tops", |u| u.shelf_tops = vec![0.01]),
        ];
        for (field, change) in cases {
            let mut unit = ShelfUnit::default();
            change(&mut unit);
            assert_eq!(failed_field(&unit), field, "{unit:?}");
        }
    }

    #[test]
    fn unvalidated_units_still_mesh_without_panicking() {
        let unit = ShelfUnit {
            width: f64::NAN,
            cell: 0.0,
            shelf_tops: vec![],
            ..ShelfUnit::default()
        };
        assert_eq!(unit.mesh().triangle_count(), unit.triangle_count());
    }
}
