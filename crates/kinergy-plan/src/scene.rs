//! Scenes: the obstacles and the objects a character can grasp, read from JSON.
//!
//! # The format (`format_version` 1)
//! ```json
//! {
//!   "format_version": 1,
//!   "character": { "height": 1.75 },
//!   "objects": [
//!     { "name": "floor", "shape": { "type": "box", "half_extents": [2, 0.01, 2] },
//!       "position": [0, -0.01, 0] },
//!     { "name": "shelf", "shape": { "type": "mesh", "file": "shelf.obj" },
//!       "position": [-0.1, 0, 0.42], "rotation": [0, 0, 0, 1] },
//!     { "name": "ball", "shape": { "type": "sphere", "radius": 0.1 }, "position": [0.3, 1, 0.4] },
//!     { "name": "pole", "shape": { "type": "capsule", "half_height": 0.5, "radius": 0.03 },
//!       "position": [0.5, 0.5, 0.5] },
//!     { "name": "book", "shape": { "type": "box", "half_extents": [0.015, 0.11, 0.08] },
//!       "position": [-0.2, 1.11, 0.52],
//!       "grasp": { "position": [0, 0.05, -0.07], "rotation": [-0.7071068, 0, 0, 0.7071068],
//!                  "approach": [0, 0, 1], "distance": 0.15, "hand": "pinch" } },
//!     { "name": "drawer", "shape": { "type": "box", "half_extents": [0.2, 0.08, 0.02] },
//!       "position": [0, 0.8, 0.45],
//!       "grasp": { "position": [0, 0, -0.03], "rotation": [-0.7071068, 0, 0, 0.7071068],
//!                  "approach": [0, 0, 1], "distance": 0.1, "hand": "power" },
//!       "slide": { "axis": [0, 0, -1], "travel": 0.25 } }
//!   ]
//! }
//! ```
//! - Units are meters; world frame Y up, the character at the origin facing +Z
//!   (DESIGN §3). `character` is optional (default height 1.75 m).
//! - `position` is the object's origin in world; `rotation` an optional quaternion
//!   `[x, y, z, w]` (normalized on reading; default identity).
//! - Shapes, in the object's frame: `box` (`half_extents`), `sphere` (`radius`), `capsule`
//!   (`half_height`, `radius`, axis along y), `mesh` (`file`: a Wavefront OBJ, relative to
//!   the scene file, optional `scale`).
//! - `grasp` makes an object graspable: where the hand goes, in the object's frame —
//!   `position` of the hand's grip point ([`crate::hand`]), `rotation` of the hand relative
//!   to its rest orientation (hanging, palm facing the thigh), the `approach` direction the
//!   hand moves along for the final approach, the pre-grasp `distance` back along it, and
//!   the `hand` shape when closed: `"pinch"`, `"power"`, `"open"` or five finger curls in
//!   \[0, 1\] (thumb, index, middle, ring, little).
//! - `slide` makes it a drawer: it moves along `axis` (object frame) by up to `travel`.
//!
//! Unknown keys are errors. Every error names the file and the JSON path of the offending
//! value (e.g. `objects[2].shape.half_extents`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;

use crate::error::{PlanError, Result};
use crate::hand::HandShape;
use crate::obj::{Mesh, read_obj};

/// A scene: obstacles and graspable objects.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The character's standing height, meters.
    pub character_height: f64,
    /// The objects, in file order.
    pub objects: Vec<SceneObject>,
}

/// One object of a [`Scene`].
#[derive(Debug, Clone)]
pub struct SceneObject {
    /// Unique name.
    pub name: String,
    /// Its shape in its own frame.
    pub shape: Shape,
    /// Its frame in world.
    pub pose: Isometry3<f64>,
    /// How to grasp it, for graspable objects.
    pub grasp: Option<Grasp>,
    /// How it slides, for drawers.
    pub slide: Option<Slide>,
}

/// A shape in its object's frame.
#[derive(Debug, Clone)]
pub enum Shape {
    /// A box centred on the origin.
    Box {
        /// Half its size along x, y, z.
        half_extents: Vector3<f64>,
    },
    /// A sphere centred on the origin.
    Sphere {
        /// Its radius.
        radius: f64,
    },
    /// A capsule along y centred on the origin.
    Capsule {
        /// Half the length of its axis.
        half_height: f64,
        /// Its radius.
        radius: f64,
    },
    /// A triangle mesh (already scaled).
    Mesh {
        /// The file it came from (empty when built in code).
        file: PathBuf,
        /// The mesh.
        mesh: Arc<Mesh>,
    },
}

impl Shape {
    /// The number of triangles, for meshes; 0 for primitives.
    pub fn triangle_count(&self) -> usize {
        match self {
            Shape::Mesh { mesh, .. } => mesh.triangles.len(),
            _ => 0,
        }
    }
}

/// Where the hand goes to hold an object, in the object's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Grasp {
    /// The grip point's position.
    pub position: Point3<f64>,
    /// The hand's rotation from its rest orientation.
    pub rotation: UnitQuaternion<f64>,
    /// The unit direction of the final approach.
    pub approach: Vector3<f64>,
    /// How far back along `approach` the pre-grasp target is, meters.
    pub distance: f64,
    /// The hand shape when holding.
    pub hand: HandShape,
}

/// How a drawer slides, in its object's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Slide {
    /// The unit direction it opens along.
    pub axis: Vector3<f64>,
    /// How far it can open, meters.
    pub travel: f64,
}

impl Scene {
    /// An empty scene for a character of `height`.
    pub fn empty(height: f64) -> Scene {
        Scene {
            character_height: height,
            objects: Vec::new(),
        }
    }

    /// Reads a scene file (meshes relative to its folder).
    pub fn read(path: &Path) -> Result<Scene> {
        let text = kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(
            |source| PlanError::Io {
                path: path.to_path_buf(),
                source,
            },
        )?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Scene::parse(&text, path, dir)
    }

    /// Parses scene JSON; `path` names it in errors, `dir` is where mesh files are looked for.
    pub fn parse(text: &str, path: &Path, dir: &Path) -> Result<Scene> {
        let file: SceneFile =
            kinergy_io::parse_versioned(text, SCENE_FORMAT_VERSION).map_err(|e| {
                PlanError::Scene {
                    path: path.to_path_buf(),
                    field: match e.field() {
                        None | Some(".") => "(top level)".into(),
                        Some(field) => field.to_string(),
                    },
                    why: e.detail(),
                }
            })?;
        file.build(path, dir)
    }

    /// The object named `name`.
    pub fn object(&self, name: &str) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.name == name)
    }

    /// The index of the object named `name`.
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }

    /// The mesh files the scene was read from (its objects' `shape.file`, joined to the
    /// scene's folder): inputs as much as the scene file itself.
    pub fn mesh_files(&self) -> impl Iterator<Item = &Path> {
        self.objects.iter().filter_map(|o| match &o.shape {
            Shape::Mesh { file, .. } if !file.as_os_str().is_empty() => Some(file.as_path()),
            _ => None,
        })
    }

    /// Triangles in all meshes.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.shape.triangle_count()).sum()
    }
}

// ---------------------------------------------------------------------------------------
// The file's serde model and its validation
// ---------------------------------------------------------------------------------------

/// The scene format this build reads.
pub const SCENE_FORMAT_VERSION: u32 = 1;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    /// Checked by [`kinergy_io::parse_versioned`].
    #[allow(dead_code)]
    format_version: u32,
    #[serde(default)]
    character: Option<CharacterFile>,
    objects: Vec<ObjectFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CharacterFile {
    height: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectFile {
    name: String,
    shape: ShapeFile,
    position: [f64; 3],
    #[serde(default)]
    rotation: Option<[f64; 4]>,
    #[serde(default)]
    grasp: Option<GraspFile>,
    #[serde(default)]
    slide: Option<SlideFile>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum ShapeKind {
    Box,
    Sphere,
    Capsule,
    Mesh,
}

/// One struct for every shape (serde's internally tagged enums lose the path of errors).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShapeFile {
    #[serde(rename = "type")]
    kind: ShapeKind,
    #[serde(default)]
    half_extents: Option<[f64; 3]>,
    #[serde(default)]
    radius: Option<f64>,
    #[serde(default)]
    half_height: Option<f64>,
    #[serde(default)]
    file: Option<PathBuf>,
    #[serde(default)]
    scale: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GraspFile {
    position: [f64; 3],
    #[serde(default)]
    rotation: Option<[f64; 4]>,
    approach: [f64; 3],
    distance: f64,
    #[serde(default)]
    hand: Option<HandFile>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum HandFile {
    Preset(String),
    Curls([f64; 5]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SlideFile {
    axis: [f64; 3],
    travel: f64,
}

/// The largest coordinate and size a scene may hold, meters: a room is meters across, and
/// beyond this the collision checks' f32 arithmetic (parry3d) loses the centimeters a
/// reach needs — a box of half extent 1e100 would be silently missed.
pub const MAX_SCENE_EXTENT: f64 = 1000.0;

/// The most objects a scene may hold.
pub const MAX_SCENE_OBJECTS: usize = 10_000;

/// Validation errors name the file and the field.
struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn fail(&self, field: &str, why: impl Into<String>) -> PlanError {
        PlanError::Scene {
            path: self.path.to_path_buf(),
            field: field.to_string(),
            why: why.into(),
        }
    }

    fn finite(&self, field: &str, v: &[f64]) -> Result<()> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(self.fail(field, "expected finite numbers"))
        }
    }

    /// A point, meters: finite and within ±[`MAX_SCENE_EXTENT`].
    fn coordinates(&self, field: &str, v: &[f64]) -> Result<()> {
        self.finite(field, v)?;
        if v.iter().all(|x| x.abs() <= MAX_SCENE_EXTENT) {
            Ok(())
        } else {
            Err(self.fail(
                field,
                format!(
                    "expected coordinates within ±{MAX_SCENE_EXTENT} m, found {}",
                    v.iter()
                        .map(|&x| kinergy_io::Num(x).to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ))
        }
    }

    /// A size, meters: finite, > 0 and at most [`MAX_SCENE_EXTENT`].
    fn positive(&self, field: &str, v: f64) -> Result<f64> {
        if v.is_finite() && v > 0.0 && v <= MAX_SCENE_EXTENT {
            Ok(v)
        } else {
            Err(self.fail(
                field,
                format!(
                    "expected a number > 0 and ≤ {MAX_SCENE_EXTENT} (meters), found {}",
                    kinergy_io::Num(v)
                ),
            ))
        }
    }

    fn rotation(&self, field: &str, q: Option<[f64; 4]>) -> Result<UnitQuaternion<f64>> {
        let Some([x, y, z, w]) = q else {
            return Ok(UnitQuaternion::identity());
        };
        self.finite(field, &[x, y, z, w])?;
        let q = Quaternion::new(w, x, y, z);
        if q.norm() < 1e-9 {
            return Err(self.fail(field, "a quaternion [x, y, z, w] must not be zero"));
        }
        Ok(UnitQuaternion::from_quaternion(q))
    }

    fn direction(&self, field: &str, v: [f64; 3]) -> Result<Vector3<f64>> {
        self.finite(field, &v)?;
        let v = Vector3::from(v);
        if v.norm() < 1e-9 {
            return Err(self.fail(field, "a direction must not be zero"));
        }
        Ok(v.normalize())
    }
}

/// A shape from its file form: the fields its `type` needs, and no others.
fn build_shape(
    check: &Check<'_>,
    f: ShapeFile,
    at: &dyn Fn(&str) -> String,
    dir: &Path,
) -> Result<Shape> {
    let given = [
        ("half_extents", f.half_extents.is_some()),
        ("radius", f.radius.is_some()),
        ("half_height", f.half_height.is_some()),
        ("file", f.file.is_some()),
        ("scale", f.scale.is_some()),
    ];
    let (kind, needed): (&str, &[&str]) = match f.kind {
        ShapeKind::Box => ("box", &["half_extents"]),
        ShapeKind::Sphere => ("sphere", &["radius"]),
        ShapeKind::Capsule => ("capsule", &["half_height", "radius"]),
        ShapeKind::Mesh => ("mesh", &["file", "scale"]),
    };
    for (name, present) in given {
        if present && !needed.contains(&name) {
            return Err(check.fail(
                &at(&format!("shape.{name}")),
                format!("a {kind} has no `{name}` (it takes {})", needed.join(", ")),
            ));
        }
    }
    let need = |name: &str| {
        check.fail(
            &at(&format!("shape.{name}")),
            format!("a {kind} needs `{name}`"),
        )
    };
    Ok(match f.kind {
        ShapeKind::Box => {
            let half_extents = f.half_extents.ok_or_else(|| need("half_extents"))?;
            for (k, v) in half_extents.iter().enumerate() {
                check.positive(&at(&format!("shape.half_extents[{k}]")), *v)?;
            }
            Shape::Box {
                half_extents: Vector3::from(half_extents),
            }
        }
        ShapeKind::Sphere => Shape::Sphere {
            radius: check.positive(&at("shape.radius"), f.radius.ok_or_else(|| need("radius"))?)?,
        },
        ShapeKind::Capsule => {
            let half_height = f.half_height.ok_or_else(|| need("half_height"))?;
            if !(half_height.is_finite() && (0.0..=MAX_SCENE_EXTENT).contains(&half_height)) {
                return Err(check.fail(
                    &at("shape.half_height"),
                    format!(
                        "expected a number ≥ 0 and ≤ {MAX_SCENE_EXTENT} (meters), found {}",
                        kinergy_io::Num(half_height)
                    ),
                ));
            }
            Shape::Capsule {
                half_height,
                radius: check
                    .positive(&at("shape.radius"), f.radius.ok_or_else(|| need("radius"))?)?,
            }
        }
        ShapeKind::Mesh => {
            let file = f.file.ok_or_else(|| need("file"))?;
            let scale = match f.scale {
                Some(s) => check.positive(&at("shape.scale"), s)?,
                None => 1.0,
            };
            let full = dir.join(&file);
            let mut mesh = read_obj(&full)?;
            if scale != 1.0 {
                for v in &mut mesh.vertices {
                    *v = Point3::from(v.coords * scale);
                }
            }
            if let Some(k) = mesh
                .vertices
                .iter()
                .position(|v| v.coords.amax() > MAX_SCENE_EXTENT)
            {
                return Err(check.fail(
                    &at("shape.file"),
                    format!(
                        "vertex {} of {} lies beyond ±{MAX_SCENE_EXTENT} m (after scale {scale})",
                        k + 1,
                        full.display()
                    ),
                ));
            }
            Shape::Mesh {
                file: full,
                mesh: Arc::new(mesh),
            }
        }
    })
}

impl SceneFile {
    fn build(self, path: &Path, dir: &Path) -> Result<Scene> {
        let check = Check { path };
        let height = match self.character {
            Some(c) => check.positive("character.height", c.height)?,
            None => 1.75,
        };
        if self.objects.len() > MAX_SCENE_OBJECTS {
            return Err(check.fail(
                "objects",
                format!(
                    "{} objects: a scene holds at most {MAX_SCENE_OBJECTS}",
                    self.objects.len()
                ),
            ));
        }
        let mut objects: Vec<SceneObject> = Vec::with_capacity(self.objects.len());
        for (i, o) in self.objects.into_iter().enumerate() {
            let at = |f: &str| format!("objects[{i}].{f}");
            if o.name.trim().is_empty() {
                return Err(check.fail(&at("name"), "an object needs a name"));
            }
            if objects.iter().any(|p| p.name == o.name) {
                return Err(check.fail(
                    &at("name"),
                    format!(
                        "`{}` is used twice",
                        kinergy_io::clip_text(&o.name, kinergy_io::MAX_QUOTED_CHARS)
                    ),
                ));
            }
            check.coordinates(&at("position"), &o.position)?;
            let rotation = check.rotation(&at("rotation"), o.rotation)?;
            let pose =
                Isometry3::from_parts(Translation3::from(Vector3::from(o.position)), rotation);
            let shape = build_shape(&check, o.shape, &at, dir)?;
            let grasp = match o.grasp {
                None => None,
                Some(g) => {
                    check.coordinates(&at("grasp.position"), &g.position)?;
                    let hand = match g.hand {
                        None => HandShape::grip(),
                        Some(HandFile::Preset(name)) => HandShape::preset(&name).ok_or_else(|| {
                            check.fail(
                                &at("grasp.hand"),
                                format!("unknown hand shape `{name}`; expected pinch, power, open or five curls"),
                            )
                        })?,
                        Some(HandFile::Curls(c)) => {
                            if !c.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)) {
                                return Err(check.fail(&at("grasp.hand"), "curls must lie in [0, 1]"));
                            }
                            HandShape::from_curls(c)
                        }
                    };
                    Some(Grasp {
                        position: Point3::from(g.position),
                        rotation: check.rotation(&at("grasp.rotation"), g.rotation)?,
                        approach: check.direction(&at("grasp.approach"), g.approach)?,
                        distance: check.positive(&at("grasp.distance"), g.distance)?,
                        hand,
                    })
                }
            };
            let slide = match o.slide {
                None => None,
                Some(s) => Some(Slide {
                    axis: check.direction(&at("slide.axis"), s.axis)?,
                    travel: check.positive(&at("slide.travel"), s.travel)?,
                }),
            };
            if slide.is_some() && grasp.is_none() {
                return Err(check.fail(
                    &at("grasp"),
                    "a drawer (`slide`) needs a `grasp` for its handle",
                ));
            }
            objects.push(SceneObject {
                name: o.name,
                shape,
                pose,
                grasp,
                slide,
            });
        }
        Ok(Scene {
            character_height: height,
            objects,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Scene> {
        Scene::parse(text, Path::new("s.json"), Path::new("."))
    }

    fn field_of(e: PlanError) -> String {
        match e {
            PlanError::Scene { field, .. } => field,
            other => panic!("not a scene error: {other}"),
        }
    }

    const GOOD: &str = r#"{"format_version": 1, "objects": [
        {"name": "a", "shape": {"type": "box", "half_extents": [1, 2, 3]}, "position": [0, 1, 2]},
        {"name": "b", "shape": {"type": "sphere", "radius": 0.5}, "position": [0, 0, 0],
         "rotation": [0, 0, 0, 2],
         "grasp": {"position": [0, 0, 0], "approach": [0, 0, 2], "distance": 0.1, "hand": [0, 1, 1, 1, 1]}}
    ]}"#;

    #[test]
    fn reads_shapes_poses_and_grasps() {
        let s = parse(GOOD).unwrap();
        assert_eq!(s.objects.len(), 2);
        assert_eq!(s.character_height, 1.75);
        let b = s.object("b").unwrap();
        let g = b.grasp.as_ref().unwrap();
        assert!((g.approach - Vector3::z()).norm() < 1e-15);
        assert!((b.pose.rotation.angle()).abs() < 1e-15);
    }

    #[test]
    fn errors_name_the_field() {
        let cases = [
            (
                GOOD.replace("[1, 2, 3]", "[1, 2]"),
                "objects[0].shape.half_extents",
            ),
            (
                GOOD.replace("[1, 2, 3]", "[1, -2, 3]"),
                "objects[0].shape.half_extents[1]",
            ),
            // Sizes and coordinates a collision check in f32 could not honour.
            (
                GOOD.replace("[1, 2, 3]", "[1, 1e100, 3]"),
                "objects[0].shape.half_extents[1]",
            ),
            (
                GOOD.replace("[0, 1, 2]", "[0, 1, 2000]"),
                "objects[0].position",
            ),
            (
                GOOD.replace("\"radius\": 0.5", "\"radius\": 5e3"),
                "objects[1].shape.radius",
            ),
            (
                GOOD.replace("\"sphere\"", "\"cone\""),
                "objects[1].shape.type",
            ),
            (
                GOOD.replace("\"radius\"", "\"radious\""),
                "objects[1].shape.radious",
            ),
            (
                GOOD.replace(
                    "\"radius\": 0.5",
                    "\"radius\": 0.5, \"half_extents\": [1, 1, 1]",
                ),
                "objects[1].shape.half_extents",
            ),
            (
                GOOD.replace("\"radius\": 0.5", "\"scale\": 2"),
                "objects[1].shape.scale",
            ),
            (
                GOOD.replace("[0, 0, 0, 2]", "[0, 0, 0, 0]"),
                "objects[1].rotation",
            ),
            (
                GOOD.replace("[0, 0, 2]", "[0, 0, 0]"),
                "objects[1].grasp.approach",
            ),
            (
                GOOD.replace("[0, 1, 1, 1, 1]", "[0, 1, 1, 1, 2]"),
                "objects[1].grasp.hand",
            ),
            (GOOD.replace("\"b\"", "\"a\""), "objects[1].name"),
            (
                GOOD.replace("\"format_version\": 1", "\"format_version\": 2"),
                "format_version",
            ),
            (
                GOOD.replace(
                    "\"position\": [0, 1, 2]",
                    "\"position\": [0, 1, 2], \"colour\": 1",
                ),
                "objects[0].colour",
            ),
            (
                GOOD.replace("\"distance\": 0.1", "\"distance\": \"far\""),
                "objects[1].grasp.distance",
            ),
        ];
        for (text, field) in cases {
            let e = parse(&text).unwrap_err();
            let msg = e.to_string();
            assert!(msg.starts_with("s.json"), "{msg}");
            assert_eq!(field_of(e), field, "{msg}");
        }
    }

    /// The sweep's 33-digit size, once printed whole; and a far position, each short.
    #[test]
    fn numbers_out_of_range_are_printed_short() {
        for (text, said) in [
            (
                GOOD.replace("[1, 2, 3]", "[123456789012345678901234567890123, 2, 3]"),
                "found 1.2345678901234569e32",
            ),
            (
                GOOD.replace("[0, 1, 2]", "[0, 1, 1e300]"),
                "found 0, 1, 1e300",
            ),
        ] {
            let msg = parse(&text).unwrap_err().to_string();
            assert!(msg.ends_with(said), "{msg}");
        }
    }

    #[test]
    fn a_missing_mesh_names_the_file() {
        let text = r#"{"format_version": 1, "objects": [
            {"name": "m", "shape": {"type": "mesh", "file": "nope.obj"}, "position": [0, 0, 0]}]}"#;
        let e = Scene::parse(text, Path::new("s.json"), Path::new("/nonexistent")).unwrap_err();
        assert!(e.to_string().contains("nope.obj"), "{e}");
    }
}
