//! Wavefront OBJ triangle meshes: a small, strict reader for the geometry (`v` and `f`)
//! and a writer whose output reads back bit for bit.
//!
//! The reader keeps only positions and faces: polygons are fan-triangulated, triangles
//! with a repeated vertex are dropped, and every other statement (`vt`, `vn`, `vp`, `o`,
//! `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, …) is ignored. Line continuations (a trailing
//! `\`) are not supported.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Point3;

use crate::error::{PlanError, Result};

/// A triangle mesh: vertices and counter-clockwise triangles (indices into `vertices`).
///
/// Counter-clockwise means seen from the side the triangle faces: for a closed mesh, from
/// outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// The vertex positions (meters).
    pub vertices: Vec<Point3<f64>>,
    /// The triangles, each three 0-based indices into [`Mesh::vertices`].
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounds (min, max) of all vertices, referenced by a triangle or not;
    /// `None` when there are no vertices.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let (first, rest) = self.vertices.split_first()?;
        Some(
            rest.iter()
                .fold((*first, *first), |(min, max), p| (min.inf(p), max.sup(p))),
        )
    }
}

/// Parse OBJ text. `path` only names the source in errors.
///
/// Reads `v x y z [w]` (exactly 3 or 4 finite numbers; `w` is ignored) and `f` with 3 or
/// more vertex references written `i`, `i/t`, `i//n` or `i/t/n`; a negative `i` counts
/// back from the last vertex defined before the face. Polygons are fan-triangulated and
/// triangles with a repeated vertex are dropped. Comments (`#` to the end of the line),
/// blank lines, CRLF line ends, tabs and a leading byte order mark are fine; any other
/// statement is ignored.
///
/// # Errors
///
/// [`PlanError::Obj`] naming the 1-based line for a malformed `v` or `f`, a vertex index 0
/// or out of range (positive indices are checked against the final vertex count, so
/// forward references are allowed), and line 0 when the mesh ends up with no triangles.
pub fn parse_obj(text: &str, path: &Path) -> Result<Mesh> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut reader = Reader::default();
    for (index, raw) in text.lines().enumerate() {
        let line = index.saturating_add(1);
        reader
            .statement(raw, line)
            .map_err(|why| obj_error(path, line, why))?;
    }
    reader.finish(path)
}

/// Read and parse an OBJ file (see [`parse_obj`]). Bytes that are not UTF-8 are
/// replaced, so they only matter inside `v` and `f` statements.
///
/// # Errors
///
/// [`PlanError::Io`] naming the path when the file cannot be read, otherwise the errors
/// of [`parse_obj`].
pub fn read_obj(path: &Path) -> Result<Mesh> {
    let bytes =
        kinergy_io::read_limited(path, kinergy_io::MAX_CAPTURE_BYTES).map_err(|source| {
            PlanError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
    parse_obj(&String::from_utf8_lossy(&bytes), path)
}

/// OBJ text for a mesh: optional comment lines (each prefixed `# `; a comment with line
/// breaks becomes several), then `v x y z` lines with full `f64` round-trip precision,
/// then `f a b c` lines with 1-based indices.
///
/// [`parse_obj`] reads the text back to an equal mesh, bit for bit, provided the
/// coordinates are finite, the indices are in range and no triangle repeats a vertex.
pub fn write_obj(mesh: &Mesh, comments: &[&str]) -> String {
    let mut out = String::new();
    for line in comments.iter().flat_map(|comment| comment.lines()) {
        push_line(&mut out, format_args!("# {line}"));
    }
    for p in &mesh.vertices {
        push_line(&mut out, format_args!("v {} {} {}", p.x, p.y, p.z));
    }
    for [a, b, c] in mesh.triangles.iter().map(|t| t.map(one_based)) {
        push_line(&mut out, format_args!("f {a} {b} {c}"));
    }
    out
}

/// Appends one formatted line and a line feed.
fn push_line(out: &mut String, line: std::fmt::Arguments<'_>) {
    // Writing to a `String` cannot fail.
    let _ = out.write_fmt(line);
    out.push('\n');
}

/// A 0-based index as the 1-based OBJ index.
fn one_based(index: u32) -> u64 {
    u64::from(index) + 1
}

/// A [`PlanError::Obj`].
fn obj_error(path: &Path, line: usize, why: String) -> PlanError {
    PlanError::Obj {
        path: path.to_path_buf(),
        line,
        why,
    }
}

/// What a vertex reference of a face may look like, for error messages.
const REFERENCE_FORMS: &str = "`i`, `i/t`, `i//n` or `i/t/n` with a nonzero integer `i`";

/// A positive index beyond the vertices defined before its face: checked at the end.
struct ForwardReference {
    /// The line of the face.
    line: usize,
    /// The 1-based index as written.
    index: u32,
}

/// The reader's state between lines.
#[derive(Default)]
struct Reader {
    vertices: Vec<Point3<f64>>,
    triangles: Vec<[u32; 3]>,
    /// The largest forward reference of each face that has one.
    forward: Vec<ForwardReference>,
    /// The current face's 0-based vertex indices (reused between faces).
    corners: Vec<u32>,
}

impl Reader {
    /// Reads one line; the error is the message for [`PlanError::Obj`].
    fn statement(&mut self, raw: &str, line: usize) -> Result<(), String> {
        let content = raw.split_once('#').map_or(raw, |(before, _)| before);
        let mut tokens = content.split_whitespace();
        match tokens.next() {
            Some("v") => self.vertex(tokens),
            Some("f") => self.face(tokens, line),
            _ => Ok(()),
        }
    }

    /// `v x y z [w]`.
    fn vertex<'a>(&mut self, tokens: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let numbers: Vec<&str> = tokens.collect();
        let [x, y, z, rest @ ..] = numbers.as_slice() else {
            return Err(coordinate_count(numbers.len()));
        };
        if rest.len() > 1 {
            return Err(coordinate_count(numbers.len()));
        }
        let point = Point3::new(
            coordinate(x, "x")?,
            coordinate(y, "y")?,
            coordinate(z, "z")?,
        );
        if let Some(w) = rest.first() {
            coordinate(w, "w")?;
        }
        self.vertices.push(point);
        Ok(())
    }

    /// `f v1 v2 v3 …`: resolves the references, then fans the polygon out.
    fn face<'a>(
        &mut self,
        tokens: impl Iterator<Item = &'a str>,
        line: usize,
    ) -> Result<(), String> {
        let mut corners = std::mem::take(&mut self.corners);
        corners.clear();
        let resolved = tokens
            .map(|token| self.resolve(token, line))
            .try_for_each(|index| index.map(|index| corners.push(index)));
        let result = resolved.and_then(|()| {
            if corners.len() < 3 {
                return Err(format!(
                    "expected a face with at least 3 vertices, found {}",
                    corners.len()
                ));
            }
            self.fan(&corners);
            Ok(())
        });
        self.corners = corners;
        result
    }

    /// The 0-based vertex index of one vertex reference of a face on `line`.
    fn resolve(&mut self, token: &str, line: usize) -> Result<u32, String> {
        let index = reference_index(token)?;
        let defined = self.vertices.len();
        match index {
            0 => Err("expected a nonzero vertex index, found 0 (OBJ indices start at 1)".into()),
            1.. => {
                let Ok(index) = u32::try_from(index) else {
                    return Err(format!(
                        "vertex index {index} is out of range: a mesh holds at most {} vertices",
                        u32::MAX
                    ));
                };
                if usize::try_from(index).unwrap_or(usize::MAX) > defined {
                    self.note_forward(line, index);
                }
                Ok(index - 1)
            }
            ..0 => {
                let back = usize::try_from(index.unsigned_abs()).unwrap_or(usize::MAX);
                defined
                    .checked_sub(back)
                    .and_then(|i| u32::try_from(i).ok())
                    .ok_or_else(|| {
                        format!(
                            "vertex index {index} is out of range: {defined} vertices are \
                             defined before this line"
                        )
                    })
            }
        }
    }

    /// Remembers a forward reference, keeping only the largest of each face.
    fn note_forward(&mut self, line: usize, index: u32) {
        match self.forward.last_mut() {
            Some(last) if last.line == line => last.index = last.index.max(index),
            _ => self.forward.push(ForwardReference { line, index }),
        }
    }

    /// Fan-triangulates a polygon, dropping triangles with a repeated vertex.
    fn fan(&mut self, corners: &[u32]) {
        let Some((&first, rest)) = corners.split_first() else {
            return;
        };
        let triangles = rest
            .windows(2)
            .filter_map(|pair| match *pair {
                [b, c] => Some([first, b, c]),
                _ => None,
            })
            .filter(|&[a, b, c]| a != b && b != c && a != c);
        self.triangles.extend(triangles);
    }

    /// Checks forward references against the final vertex count and that there are
    /// triangles.
    fn finish(self, path: &Path) -> Result<Mesh> {
        let count = self.vertices.len();
        let beyond = |r: &&ForwardReference| usize::try_from(r.index).unwrap_or(usize::MAX) > count;
        if let Some(bad) = self.forward.iter().find(beyond) {
            let why = format!(
                "vertex index {} is out of range: the file defines {count} vertices",
                bad.index
            );
            return Err(obj_error(path, bad.line, why));
        }
        if self.triangles.is_empty() {
            let why = "no faces: expected at least one `f` with 3 distinct vertices".into();
            return Err(obj_error(path, 0, why));
        }
        Ok(Mesh {
            vertices: self.vertices,
            triangles: self.triangles,
        })
    }
}

/// The message for a `v` with the wrong number of values.
fn coordinate_count(found: usize) -> String {
    format!("expected 3 or 4 numbers after `v` (x y z [w]), found {found}")
}

/// One finite coordinate of a `v`.
fn coordinate(token: &str, axis: &str) -> Result<f64, String> {
    match token.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        Ok(_) => Err(format!(
            "expected a finite {axis} coordinate, found `{token}`"
        )),
        Err(_) => Err(format!(
            "expected a number for the {axis} coordinate, found `{token}`"
        )),
    }
}

/// The vertex index (as written, 1-based or negative) of a face's vertex reference,
/// checking the reference's form.
fn reference_index(token: &str) -> Result<i64, String> {
    let malformed = || format!("expected a vertex reference {REFERENCE_FORMS}, found `{token}`");
    let mut parts = token.split('/');
    let index = parts
        .next()
        .and_then(|i| i.parse::<i64>().ok())
        .ok_or_else(malformed)?;
    let others: Vec<&str> = parts.collect();
    let well_formed = others.len() <= 2
        && others
            .iter()
            .all(|part| part.is_empty() || part.parse::<i64>().is_ok());
    if well_formed {
        Ok(index)
    } else {
        Err(malformed())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: &str = "\
# a unit cube
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vn 0 0 -1
vt 0 0
s off
usemtl wood
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 4 8 7 3
f 1 5 8 4
f 2 3 7 6
";

    fn parse(text: &str) -> Result<Mesh> {
        parse_obj(text, Path::new("test.obj"))
    }

    /// The line and message of an `Obj` error.
    fn obj_failure(text: &str) -> (usize, String) {
        match parse(text) {
            Err(PlanError::Obj { line, why, path }) => {
                assert_eq!(path, Path::new("test.obj"));
                (line, why)
            }
            other => panic!("expected an Obj error, got {other:?}"),
        }
    }

    /// Signed volume by the divergence theorem.
    fn signed_volume(mesh: &Mesh) -> f64 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.vertices[i as usize].coords);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn cube_with_quads_gives_12_outward_triangles() {
        let mesh = parse(CUBE).unwrap();
        assert_eq!(mesh.vertices.len(), 8);
        assert_eq!(mesh.triangle_count(), 12);
        assert!((signed_volume(&mesh) - 1.0).abs() < 1e-12);
        let (min, max) = mesh.bounds().unwrap();
        assert_eq!(min, Point3::new(0.0, 0.0, 0.0));
        assert_eq!(max, Point3::new(1.0, 1.0, 1.0));
    }

    #[test]
    fn quad_fans_from_its_first_vertex() {
        let mesh = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn all_reference_forms_including_negative() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n\
                    f 1 2 3\nf 1/1 2/1 4/1\nf 1//1 3//1 4//1\nf 2/1/1 3/1/1 4/1/1\n\
                    f -4 -3 -2\nf -4/1 -2/1/1 -1//1\nf 1/ 2 -1\n";
        let mesh = parse(text).unwrap();
        assert_eq!(
            mesh.triangles,
            vec![
                [0, 1, 2],
                [0, 1, 3],
                [0, 2, 3],
                [1, 2, 3],
                [0, 1, 2],
                [0, 2, 3],
                [0, 1, 3]
            ]
        );
    }

    #[test]
    fn negative_indices_count_from_the_vertices_defined_so_far() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -3 -1\n";
        let mesh = parse(text).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 1, 3]]);
    }

    #[test]
    fn forward_references_are_resolved_at_the_end() {
        let mesh = parse("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn ignores_other_statements_comments_crlf_tabs_and_bom() {
        let text = "\u{feff}# header\r\nmtllib a.mtl\r\ng  group\r\n\r\n\
                    v\t0 0 0 1 # with w\r\nv 1\t0 0\r\nv 0 1 0\r\nvp 0.5\r\n\
                    l 1 2\r\np 1\r\ncstype bspline\r\nf\t1 2 3\r\n";
        let mesh = parse(text).unwrap();
        assert_eq!(mesh.vertices.len(), 3);
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn drops_triangles_with_a_repeated_vertex() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\nf 1 2 -3\nf 1 2 3 3\n";
        let mesh = parse(text).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_name_the_line() {
        let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let cases: &[(&str, &str)] = &[
            ("v 1 x 0\nf 1 2 3\n", "number for the y coordinate"),
            ("v 1 2 inf\nf 1 2 3\n", "finite z coordinate"),
            ("v 1 2 NaN\nf 1 2 3\n", "finite z coordinate"),
            ("v 1 2 1e999\nf 1 2 3\n", "finite z coordinate"),
            ("v 1 2\nf 1 2 3\n", "3 or 4 numbers"),
            ("v 1 2 3 4 5\nf 1 2 3\n", "3 or 4 numbers"),
            ("v 1 2 3 w\nf 1 2 3\n", "number for the w coordinate"),
            ("f 0 1 2\nf 1 2 3\n", "nonzero vertex index"),
            ("f 1 2\nf 1 2 3\n", "at least 3 vertices"),
            ("f 1 2 x\nf 1 2 3\n", "vertex reference"),
            ("f 1/2/3/4 2 3\nf 1 2 3\n", "vertex reference"),
            ("f 1/x 2 3\nf 1 2 3\n", "vertex reference"),
            ("f /1 2 3\nf 1 2 3\n", "vertex reference"),
            ("f 1 2 -5\nf 1 2 3\n", "-5 is out of range: 3 vertices"),
        ];
        for (tail, expected) in cases {
            let (line, why) = obj_failure(&format!("{base}{tail}"));
            assert_eq!(line, 4, "{tail:?}: {why}");
            assert!(why.contains(expected), "{tail:?}: {why}");
        }
    }

    #[test]
    fn out_of_range_index_names_the_face_line_and_the_vertex_count() {
        let (line, why) = obj_failure("v 0 0 0\nv 1 0 0\nf 1 2 9\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(line, 3);
        assert!(why.contains('9') && why.contains("3 vertices"), "{why}");
        let (line, why) = obj_failure("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n");
        assert_eq!(line, 4);
        assert!(why.contains("out of range"), "{why}");
    }

    #[test]
    fn a_mesh_without_triangles_is_an_error_of_line_0() {
        for text in [
            "",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
            "v 0 0 0\nv 1 0 0\nf 1 2 2\n",
        ] {
            let (line, why) = obj_failure(text);
            assert_eq!(line, 0);
            assert!(why.contains("no faces"), "{why}");
        }
    }

    #[test]
    fn error_display_names_path_and_line() {
        let e = parse("v 0 0\n").unwrap_err();
        assert!(e.to_string().starts_with("test.obj:1: "), "{e}");
    }

    #[test]
    fn write_then_parse_is_bitwise_exact() {
        let values = [
            0.1,
            -0.0,
            1.0 / 3.0,
            -2.5e-300,
            f64::MIN_POSITIVE / 3.0,
            f64::MAX,
            f64::MIN,
            123_456.789_012_345_67,
            -1e22,
        ];
        let vertices = values
            .iter()
            .zip(values.iter().rev())
            .zip(values.iter().skip(2).chain(&values[..2]))
            .map(|((&x, &y), &z)| Point3::new(x, y, z))
            .collect();
        let mesh = Mesh {
            vertices,
            triangles: vec![[0, 1, 2], [8, 3, 5], [4, 6, 7]],
        };
        let text = write_obj(&mesh, &["first", "second\nthird"]);
        assert!(text.starts_with("# first\n# second\n# third\nv "), "{text}");
        let back = parse(&text).unwrap();
        assert_eq!(back.triangles, mesh.triangles);
        assert_eq!(back.vertices.len(), mesh.vertices.len());
        for (a, b) in back.vertices.iter().zip(&mesh.vertices) {
            for axis in 0..3 {
                assert_eq!(a[axis].to_bits(), b[axis].to_bits());
            }
        }
    }

    #[test]
    fn read_obj_reads_a_file_and_names_a_missing_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cube.obj");
        std::fs::write(&path, CUBE).unwrap();
        assert_eq!(read_obj(&path).unwrap().triangle_count(), 12);
        let missing = dir.path().join("missing.obj");
        match read_obj(&missing) {
            Err(PlanError::Io { path, .. }) => assert_eq!(path, missing),
            other => panic!("expected an Io error, got {other:?}"),
        }
    }

    #[test]
    fn empty_mesh_has_no_bounds() {
        let mesh = Mesh {
            vertices: Vec::new(),
            triangles: Vec::new(),
        };
        assert_eq!(mesh.bounds(), None);
        assert_eq!(mesh.triangle_count(), 0);
    }

    proptest::proptest! {
        #[test]
        fn parse_never_panics_on_arbitrary_text(text in "\\PC*") {
            let _ = parse(&text);
        }

        #[test]
        fn parse_never_panics_on_mutated_files(
            edits in proptest::collection::vec(
                (0usize..400, proptest::sample::select(
                    &['0', '1', '9', '-', '/', ' ', '\n', '\r', '.', 'e', 'v', 'f', '#', '\\'][..],
                ), proptest::bool::ANY),
                1..12,
            )
        ) {
            let mut text: Vec<char> = CUBE.chars().collect();
            for (at, c, insert) in edits {
                let at = at % (text.len() + 1);
                if insert || at == text.len() {
                    text.insert(at, c);
                } else {
                    text[at] = c;
                }
            }
            let text: String = text.into_iter().collect();
            if let Ok(mesh) = parse(&text) {
                let count = mesh.vertices.len();
                proptest::prop_assert!(
                    mesh.triangles.iter().flatten().all(|&i| (i as usize) < count)
                );
            }
        }

        #[test]
        fn write_parse_round_trips_finite_coordinates(
            coords in proptest::collection::vec(
                proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL
                    | proptest::num::f64::ZERO,
                9..30,
            )
        ) {
            let vertices: Vec<Point3<f64>> = coords
                .chunks_exact(3)
                .map(|c| Point3::new(c[0], c[1], c[2]))
                .collect();
            let mesh = Mesh { vertices, triangles: vec![[0, 1, 2]] };
            let back = parse(&write_obj(&mesh, &[])).unwrap();
            for (a, b) in back.vertices.iter().zip(&mesh.vertices) {
                for axis in 0..3 {
                    proptest::prop_assert_eq!(a[axis].to_bits(), b[axis].to_bits());
                }
            }
        }
    }
}
