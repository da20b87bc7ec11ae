//! Joint positions as files and hierarchies (what `kinergy from-positions` reads): a CSV table
//! of positions per frame and joint or a NumPy `.npy` array `(frames, joints, 3)`, and the
//! joints' hierarchy — a built-in one (SMPL's 24 joints, Human3.6M's 17, COCO's 17 keypoints),
//! a JSON map, or a BVH's skeleton. A hierarchy may hold *derived* joints, the mean of others
//! (COCO's keypoints have no pelvis: its map roots the body at the hips' midpoint).

use std::collections::HashMap;
use std::path::Path;

use crate::error::{MotionError, Result};
use crate::skeleton::Skeleton;

/// The joints' names and parents (`-1` for the root, parents before children).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JointMap {
    /// The joints' names.
    pub names: Vec<String>,
    /// Each joint's parent index, `-1` for the root.
    pub parents: Vec<i64>,
    /// Each joint's sources where it is derived (the mean of their positions), empty for a
    /// joint read from the input.
    pub derived: Vec<Vec<usize>>,
    /// The joints the input holds, in the order an array without names lists them (a
    /// dataset's own keypoint order): indices into `names`, no derived joint.
    pub input_order: Vec<usize>,
}

/// The built-in hierarchies: (name, joints with their parents' names).
const BUILT_IN: [(&str, &[(&str, &str)]); 3] = [
    // SMPL's 24 joints in SMPL's order (the kinematic tree of the SMPL model).
    (
        "smpl24",
        &[
            ("pelvis", ""),
            ("left_hip", "pelvis"),
            ("right_hip", "pelvis"),
            ("spine1", "pelvis"),
            ("left_knee", "left_hip"),
            ("right_knee", "right_hip"),
            ("spine2", "spine1"),
            ("left_ankle", "left_knee"),
            ("right_ankle", "right_knee"),
            ("spine3", "spine2"),
            ("left_foot", "left_ankle"),
            ("right_foot", "right_ankle"),
            ("neck", "spine3"),
            ("left_collar", "spine3"),
            ("right_collar", "spine3"),
            ("head", "neck"),
            ("left_shoulder", "left_collar"),
            ("right_shoulder", "right_collar"),
            ("left_elbow", "left_shoulder"),
            ("right_elbow", "right_shoulder"),
            ("left_wrist", "left_elbow"),
            ("right_wrist", "right_elbow"),
            ("left_hand", "left_wrist"),
            ("right_hand", "right_wrist"),
        ],
    ),
    // Human3.6M's 17 joints in the order of its 3-D pose benchmarks.
    (
        "h36m17",
        &[
            ("hip", ""),
            ("right_hip", "hip"),
            ("right_knee", "right_hip"),
            ("right_foot", "right_knee"),
            ("left_hip", "hip"),
            ("left_knee", "left_hip"),
            ("left_foot", "left_knee"),
            ("spine", "hip"),
            ("thorax", "spine"),
            ("neck", "thorax"),
            ("head", "neck"),
            ("left_shoulder", "thorax"),
            ("left_elbow", "left_shoulder"),
            ("left_wrist", "left_elbow"),
            ("right_shoulder", "thorax"),
            ("right_elbow", "right_shoulder"),
            ("right_wrist", "right_elbow"),
        ],
    ),
    // COCO's 17 keypoints (3-D lifts of them), with two derived joints: the root at the hips'
    // midpoint and a neck at the shoulders' ([`COCO_DERIVED`]); arrays list COCO's order
    // ([`COCO_ORDER`]).
    (
        "coco17",
        &[
            ("mid_hip", ""),
            ("left_hip", "mid_hip"),
            ("left_knee", "left_hip"),
            ("left_ankle", "left_knee"),
            ("right_hip", "mid_hip"),
            ("right_knee", "right_hip"),
            ("right_ankle", "right_knee"),
            ("neck", "mid_hip"),
            ("nose", "neck"),
            ("left_eye", "nose"),
            ("left_ear", "left_eye"),
            ("right_eye", "nose"),
            ("right_ear", "right_eye"),
            ("left_shoulder", "neck"),
            ("left_elbow", "left_shoulder"),
            ("left_wrist", "left_elbow"),
            ("right_shoulder", "neck"),
            ("right_elbow", "right_shoulder"),
            ("right_wrist", "right_elbow"),
        ],
    ),
];

/// COCO's derived joints: (joint, the joints it is the mean of).
const COCO_DERIVED: [(&str, [&str; 2]); 2] = [
    ("mid_hip", ["left_hip", "right_hip"]),
    ("neck", ["left_shoulder", "right_shoulder"]),
];

/// COCO's keypoint order.
const COCO_ORDER: [&str; 17] = [
    "nose",
    "left_eye",
    "right_eye",
    "left_ear",
    "right_ear",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
];

impl JointMap {
    /// The names of the built-in hierarchies.
    pub fn built_in_names() -> Vec<&'static str> {
        BUILT_IN.iter().map(|(n, _)| *n).collect()
    }

    /// A built-in hierarchy by name (`smpl24`, `h36m17`, `coco17`).
    pub fn built_in(name: &str) -> Option<JointMap> {
        let (_, joints) = BUILT_IN.iter().find(|(n, _)| *n == name)?;
        let pairs = joints.iter().map(|(j, p)| (j.to_string(), p.to_string()));
        if name != "coco17" {
            return JointMap::from_pairs(pairs).ok();
        }
        let derived = COCO_DERIVED
            .iter()
            .map(|(j, from)| (j.to_string(), from.iter().map(|f| f.to_string()).collect()))
            .collect();
        let order: Vec<String> = COCO_ORDER.iter().map(|j| j.to_string()).collect();
        JointMap::from_parts(pairs, derived, Some(&order)).ok()
    }

    /// The hierarchy of a BVH's skeleton.
    pub fn of_skeleton(skeleton: &Skeleton) -> JointMap {
        let n = skeleton.joint_count();
        JointMap {
            names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
            parents: skeleton
                .joints()
                .iter()
                .map(|j| j.parent.map_or(-1, |p| p as i64))
                .collect(),
            derived: vec![Vec::new(); n],
            input_order: (0..n).collect(),
        }
    }

    /// The names of the joints the input holds, in [`JointMap::input_order`].
    pub fn input_names(&self) -> Vec<&str> {
        self.input_order
            .iter()
            .map(|&j| self.names[j].as_str())
            .collect()
    }

    /// Fills each derived joint of `positions` (frames of the map's joints) with the mean of
    /// its sources.
    pub fn fill_derived(&self, positions: &mut [[f64; 3]]) {
        let n = self.names.len();
        for frame in positions.chunks_mut(n) {
            for (j, from) in self.derived.iter().enumerate() {
                if from.is_empty() {
                    continue;
                }
                let mut sum = [0.0; 3];
                for &k in from {
                    for (s, v) in sum.iter_mut().zip(frame[k]) {
                        *s += v;
                    }
                }
                frame[j] = sum.map(|s| s / from.len() as f64);
            }
        }
    }

    /// A JSON map: `{"joints": [{"name": "pelvis", "parent": null}, {"name": "left_hip",
    /// "parent": "pelvis"}, …]}`, parents before their children, one root.
    pub fn from_json(text: &str) -> Result<JointMap> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct File {
            joints: Vec<Entry>,
        }
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Entry {
            name: String,
            parent: Option<String>,
            #[serde(default)]
            mean_of: Vec<String>,
        }
        let file: File = serde_json::from_str(text).map_err(|e| MotionError::Invalid {
            what: "joint map",
            why: e.to_string(),
        })?;
        let derived = file
            .joints
            .iter()
            .filter(|e| !e.mean_of.is_empty())
            .map(|e| (e.name.clone(), e.mean_of.clone()))
            .collect();
        JointMap::from_parts(
            file.joints
                .into_iter()
                .map(|e| (e.name, e.parent.unwrap_or_default())),
            derived,
            None,
        )
    }

    /// From (joint, parent) names (the root's parent empty), the derived joints with their
    /// sources' names, and the input order by name (`None`: the map's order less the derived).
    fn from_parts(
        pairs: impl IntoIterator<Item = (String, String)>,
        derived: Vec<(String, Vec<String>)>,
        order: Option<&[String]>,
    ) -> Result<JointMap> {
        let mut map = JointMap::from_pairs(pairs)?;
        let bad = |why: String| MotionError::Invalid {
            what: "joint map",
            why,
        };
        let index = |map: &JointMap, name: &str, of: &str| {
            map.names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| bad(format!("`{of}`: no joint `{name}` in the map")))
        };
        for (joint, from) in &derived {
            let j = index(&map, joint, joint)?;
            let sources = from
                .iter()
                .map(|f| index(&map, f, joint))
                .collect::<Result<Vec<usize>>>()?;
            map.derived[j] = sources;
        }
        for (j, from) in map.derived.iter().enumerate() {
            if let Some(&k) = from.iter().find(|&&k| !map.derived[k].is_empty()) {
                return Err(bad(format!(
                    "`{}` is the mean of `{}`, itself derived: a derived joint's sources are read",
                    map.names[j], map.names[k]
                )));
            }
        }
        map.input_order = match order {
            Some(names) => names
                .iter()
                .map(|n| index(&map, n, "input order"))
                .collect::<Result<_>>()?,
            None => (0..map.names.len())
                .filter(|&j| map.derived[j].is_empty())
                .collect(),
        };
        Ok(map)
    }

    /// From (joint, parent) names, the root's parent empty.
    fn from_pairs(pairs: impl IntoIterator<Item = (String, String)>) -> Result<JointMap> {
        let bad = |why: String| MotionError::Invalid {
            what: "joint map",
            why,
        };
        let mut names: Vec<String> = Vec::new();
        let mut parents = Vec::new();
        for (name, parent) in pairs {
            if names.contains(&name) {
                return Err(bad(format!("joint `{name}` is named twice")));
            }
            let p = if parent.is_empty() {
                if !names.is_empty() {
                    return Err(bad(format!(
                        "joint `{name}` has no parent: only the first joint is the root"
                    )));
                }
                -1
            } else {
                match names.iter().position(|n| *n == parent) {
                    Some(p) => p as i64,
                    None => {
                        return Err(bad(format!(
                            "joint `{name}`: its parent `{parent}` is not named before it"
                        )));
                    }
                }
            };
            names.push(name);
            parents.push(p);
        }
        if names.is_empty() {
            return Err(bad("no joints".into()));
        }
        let n = names.len();
        Ok(JointMap {
            names,
            parents,
            derived: vec![Vec::new(); n],
            input_order: (0..n).collect(),
        })
    }
}

/// Positions read from a CSV file, per frame in the map's joint order, meters as written.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionTable {
    /// Frames in the file.
    pub frames: usize,
    /// Each frame's positions, joint after joint, in the map's order.
    pub positions: Vec<[f64; 3]>,
}

/// How a table's unit and up axis were read ([`PositionTable::reading`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableReading {
    /// The table's length unit.
    pub unit: crate::units::LengthUnit,
    /// Whether the unit was guessed (from the body's size) rather than given.
    pub unit_guessed: bool,
    /// The table's up axis.
    pub up: crate::up::UpAxis,
    /// How the up axis was found: given, by joint names, by the body's shape, or assumed.
    pub up_detection: crate::up::UpDetection,
}

impl PositionTable {
    /// The table's unit and up axis (its frames hold `map`'s joints): as given, or detected
    /// from the first frame as a BVH's are — the unit from the body's largest extent along an
    /// axis, the reference joints above the hips left out ([`LengthUnit::guess_from_extent`],
    /// [`Skeleton::reference_joints`]), the up axis from the joints' names or the body's shape
    /// ([`crate::up::detect_up`]).
    ///
    /// [`LengthUnit::guess_from_extent`]: crate::units::LengthUnit::guess_from_extent
    pub fn reading(
        &self,
        map: &JointMap,
        unit: crate::units::UnitChoice,
        up: crate::up::UpChoice,
    ) -> Result<TableReading> {
        use crate::skeleton::{Joint, PositionReading};
        use crate::units::UnitChoice;
        use crate::up::{UpChoice, UpDetection, detect_up};
        use nalgebra::{Point3, Vector3};
        let n = map.names.len();
        let first: Vec<Point3<f64>> = self
            .positions
            .iter()
            .take(n)
            .map(|p| Point3::from(*p))
            .collect();
        if first.len() < n {
            return Err(MotionError::EmptyClip);
        }
        // The joints as a skeleton of the first frame, for the names and the shape.
        let joints = (0..n)
            .map(|j| {
                let parent = usize::try_from(map.parents[j]).ok();
                Joint {
                    name: map.names[j].clone(),
                    parent,
                    offset: parent.map_or(first[j].coords, |p| first[j] - first[p]),
                    dofs: Vec::new(),
                    end_site: false,
                    position_reading: PositionReading::default(),
                }
            })
            .collect();
        let skeleton = Skeleton::new(joints)?;
        let (unit, unit_guessed) = match unit {
            UnitChoice::Fixed(u) => (u, false),
            UnitChoice::Auto => {
                let skip = skeleton.reference_joints();
                let mut lo = Vector3::repeat(f64::INFINITY);
                let mut hi = Vector3::repeat(f64::NEG_INFINITY);
                for p in &first[skip.min(n - 1)..] {
                    lo = lo.inf(&p.coords);
                    hi = hi.sup(&p.coords);
                }
                let extent = (hi - lo).max();
                let guess =
                    crate::units::LengthUnit::guess_from_extent(extent).ok_or_else(|| {
                        MotionError::Invalid {
                            what: "positions",
                            why: format!(
                                "the first frame's joints span {extent} units: no unit to guess \
                             (give one)"
                            ),
                        }
                    })?;
                (guess, true)
            }
        };
        let (up, up_detection) = match up {
            UpChoice::Fixed(a) => (a, UpDetection::Given),
            UpChoice::Auto => detect_up(&skeleton, &first),
        };
        Ok(TableReading {
            unit,
            unit_guessed,
            up,
            up_detection,
        })
    }

    /// The positions in meters, Y up: each read in `unit`, with `up` the file's up axis.
    pub fn to_world(&self, unit: crate::units::LengthUnit, up: crate::up::UpAxis) -> Vec<[f64; 3]> {
        let (scale, turn) = (unit.meters(), up.world_from_file());
        self.positions
            .iter()
            .map(|p| (turn * (nalgebra::Vector3::from(*p) * scale)).into())
            .collect()
    }
}

/// Reads positions for the joints of `map` from CSV `text` (the file `path`, named in
/// errors with the line): either long, one row per frame and joint (`frame,joint,x,y,z`), or
/// wide, one row per frame (`frame,<joint>_x,<joint>_y,<joint>_z,…`). Frames are numbered
/// 0, 1, … (or from 1) without gaps; every joint of the map must be there on every frame
/// (other joints in the file are ignored).
pub fn read_positions_csv(path: &Path, text: &str, map: &JointMap) -> Result<PositionTable> {
    let at = |line: u64, why: String| MotionError::Invalid {
        what: "positions",
        why: format!("{}:{line}: {why}", path.display()),
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| at(1, e.to_string()))?
        .iter()
        .map(str::to_lowercase)
        .collect();
    let n = map.names.len();
    let number = |field: Option<&str>, line: u64, what: &str| -> Result<f64> {
        let field = field.ok_or_else(|| at(line, format!("no {what}")))?;
        let v: f64 = field
            .parse()
            .map_err(|_| at(line, format!("{what} `{field}` is not a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(at(line, format!("{what} `{field}` is not finite")))
        }
    };
    let mut table: Rows = (Vec::new(), HashMap::new());
    // A frame number: whole and not negative.
    let whole = |frame: f64, line: u64| -> Result<i64> {
        if frame.fract() != 0.0 || frame < 0.0 {
            return Err(at(line, format!("frame {frame} is not a whole number ≥ 0")));
        }
        Ok(frame as i64)
    };
    let long = header == ["frame", "joint", "x", "y", "z"];
    if long {
        for (i, record) in reader.records().enumerate() {
            let line = i as u64 + 2;
            let record = record.map_err(|e| at(line, e.to_string()))?;
            let frame = whole(number(record.get(0), line, "frame")?, line)?;
            let joint = record.get(1).unwrap_or_default();
            let Some(j) = map.names.iter().position(|n| n == joint) else {
                continue;
            };
            if !map.derived[j].is_empty() {
                continue; // made from its sources, whatever the file says
            }
            let p = [
                number(record.get(2), line, "x")?,
                number(record.get(3), line, "y")?,
                number(record.get(4), line, "z")?,
            ];
            let k = slot(&mut table, frame, n);
            if table.0[k].1[j].replace(p).is_some() {
                return Err(at(line, format!("joint `{joint}` twice on frame {frame}")));
            }
        }
    } else {
        if header.first().map(String::as_str) != Some("frame") {
            return Err(at(
                1,
                "the header is neither `frame,joint,x,y,z` (long) nor `frame,<joint>_x,\
                 <joint>_y,<joint>_z,…` (wide)"
                    .into(),
            ));
        }
        let column = |name: &str, axis: &str| {
            let want = format!("{}_{axis}", name.to_lowercase());
            header.iter().position(|h| *h == want)
        };
        let mut columns = Vec::with_capacity(n);
        for (j, name) in map.names.iter().enumerate() {
            if !map.derived[j].is_empty() {
                columns.push(None);
                continue;
            }
            match (column(name, "x"), column(name, "y"), column(name, "z")) {
                (Some(x), Some(y), Some(z)) => columns.push(Some([x, y, z])),
                _ => {
                    return Err(at(
                        1,
                        format!("no columns {name}_x, {name}_y, {name}_z for joint `{name}`"),
                    ));
                }
            }
        }
        for (i, record) in reader.records().enumerate() {
            let line = i as u64 + 2;
            let record = record.map_err(|e| at(line, e.to_string()))?;
            let frame = whole(number(record.get(0), line, "frame")?, line)?;
            let k = slot(&mut table, frame, n);
            if table.0[k].1.iter().any(Option::is_some) {
                return Err(at(line, format!("frame {frame} twice")));
            }
            for (j, column) in columns.iter().enumerate() {
                let v = |c: usize, what: &str| number(record.get(c), line, what);
                table.0[k].1[j] = match column {
                    Some([x, y, z]) => Some([v(*x, "x")?, v(*y, "y")?, v(*z, "z")?]),
                    None => Some([0.0; 3]), // derived, filled below
                };
            }
        }
    }
    let mut rows = table.0;
    rows.sort_by_key(|(f, _)| *f);
    if rows.is_empty() {
        return Err(at(2, "no frames".into()));
    }
    let first = rows[0].0;
    let mut positions = Vec::with_capacity(rows.len() * n);
    for (k, (frame, joints)) in rows.iter().enumerate() {
        if *frame != first + k as i64 {
            return Err(at(
                1,
                format!(
                    "frame {} is missing (frames must follow each other)",
                    first + k as i64
                ),
            ));
        }
        for (j, p) in joints.iter().enumerate() {
            match p {
                Some(p) => positions.push(*p),
                None if !map.derived[j].is_empty() => positions.push([0.0; 3]),
                None => {
                    return Err(at(
                        1,
                        format!("joint `{}` has no position on frame {frame}", map.names[j]),
                    ));
                }
            }
        }
    }
    map.fill_derived(&mut positions);
    Ok(PositionTable {
        frames: rows.len(),
        positions,
    })
}

/// Reads positions for the joints of `map` from the bytes of a NumPy `.npy` file (`path`,
/// named in errors): a little-endian `float64` or `float32` array in C order, shaped `(frames,
/// joints, 3)` or `(frames, joints × 3)`. `names` lists the array's joints in order (a names
/// file); without it the array holds the map's [`JointMap::input_order`] (a built-in dataset's
/// own keypoint order). Every joint the map reads must be named (other joints are ignored);
/// derived joints are made from their sources.
pub fn read_positions_npy(
    path: &Path,
    bytes: &[u8],
    map: &JointMap,
    names: Option<&[String]>,
) -> Result<PositionTable> {
    let bad = |why: String| MotionError::Invalid {
        what: "positions",
        why: format!("{}: {why}", path.display()),
    };
    let array = npy::parse(bytes).map_err(bad)?;
    let default: Vec<String> = map.input_names().iter().map(|s| s.to_string()).collect();
    let names = names.unwrap_or(&default);
    let (frames, width) = match array.shape[..] {
        [f, j, 3] => (f, j),
        [f, k] if k % 3 == 0 => (f, k / 3),
        _ => {
            return Err(bad(format!(
                "an array shaped {:?}: positions are (frames, joints, 3) or (frames, joints × 3)",
                array.shape
            )));
        }
    };
    if width != names.len() {
        return Err(bad(format!(
            "{width} joints per frame, but {} names ({})",
            names.len(),
            names.join(", ")
        )));
    }
    if frames == 0 {
        return Err(bad("no frames".into()));
    }
    let n = map.names.len();
    let mut column = vec![None; n];
    for (j, name) in map.names.iter().enumerate() {
        if map.derived[j].is_empty() {
            let k = names.iter().position(|m| m == name).ok_or_else(|| {
                bad(format!(
                    "no joint `{name}` among the array's ({})",
                    names.join(", ")
                ))
            })?;
            column[j] = Some(k);
        }
    }
    let mut positions = Vec::with_capacity(frames * n);
    for f in 0..frames {
        for (j, k) in column.iter().enumerate() {
            let p = match k {
                Some(k) => {
                    let at = (f * width + k) * 3;
                    [array.values[at], array.values[at + 1], array.values[at + 2]]
                }
                None => [0.0; 3],
            };
            if !p.iter().all(|v| v.is_finite()) {
                return Err(bad(format!(
                    "joint `{}` has no finite position on frame {f}",
                    map.names[j]
                )));
            }
            positions.push(p);
        }
    }
    map.fill_derived(&mut positions);
    Ok(PositionTable { frames, positions })
}

/// A names file: one joint name per line (blank lines and `#` comments skipped).
pub fn read_names(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_owned)
        .collect()
}

/// The NumPy `.npy` format, version 1–3: the header's dictionary (`descr`, `fortran_order`,
/// `shape`) and the data, read strictly (what this crate reads; no pickles, no objects).
mod npy {
    /// An array of numbers in C order.
    pub struct Array {
        pub shape: Vec<usize>,
        pub values: Vec<f64>,
    }

    pub fn parse(bytes: &[u8]) -> Result<Array, String> {
        const MAGIC: &[u8] = b"\x93NUMPY";
        if bytes.len() < 10 || &bytes[..6] != MAGIC {
            return Err("not a NumPy .npy file (no \\x93NUMPY magic)".into());
        }
        let major = bytes[6];
        let (len, start) = match major {
            1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
            2 | 3 if bytes.len() >= 12 => (
                u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
                12,
            ),
            _ => return Err(format!("a .npy version {major} header, not read")),
        };
        let header = bytes
            .get(start..start + len)
            .ok_or("the .npy header runs past the end of the file")?;
        let header = std::str::from_utf8(header).map_err(|_| "the .npy header is not text")?;
        let field = |key: &str| -> Result<&str, String> {
            let at = header
                .find(&format!("'{key}'"))
                .ok_or_else(|| format!("the .npy header has no '{key}'"))?;
            let rest = &header[at + key.len() + 2..];
            let colon = rest.find(':').ok_or("a malformed .npy header")?;
            Ok(rest[colon + 1..].trim_start())
        };
        let descr = field("descr")?;
        let descr = descr
            .strip_prefix('\'')
            .and_then(|d| d.split('\'').next())
            .ok_or("a malformed 'descr' in the .npy header")?;
        let width = match descr {
            "<f8" | "=f8" => 8,
            "<f4" | "=f4" => 4,
            other => {
                return Err(format!(
                    "numbers of type '{other}': float64 or float32, little-endian, are read"
                ));
            }
        };
        if field("fortran_order")?.starts_with("True") {
            return Err(
                "a Fortran-ordered array: save it in C order (np.ascontiguousarray)".into(),
            );
        }
        let shape = field("shape")?;
        let shape = shape
            .strip_prefix('(')
            .and_then(|s| s.split(')').next())
            .ok_or("a malformed 'shape' in the .npy header")?;
        let shape: Vec<usize> = shape
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse()
                    .map_err(|_| format!("a shape entry `{s}` is not a size"))
            })
            .collect::<Result<_, String>>()?;
        let count = shape
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .ok_or("an array too large")?;
        let data = &bytes[start + len..];
        if data.len() != count * width {
            return Err(format!(
                "{} bytes of data for an array of shape {shape:?} ({} expected)",
                data.len(),
                count * width
            ));
        }
        let values = if width == 8 {
            data.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                .collect()
        } else {
            data.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap_or([0; 4])) as f64)
                .collect()
        };
        Ok(Array { shape, values })
    }
}

/// Rows of positions by frame, in the order first met.
type Rows = (Vec<(i64, Vec<Option<[f64; 3]>>)>, HashMap<i64, usize>);

/// The index of `frame`'s row, a new row of `n` joints where it has none.
fn slot((rows, index): &mut Rows, frame: i64, n: usize) -> usize {
    *index.entry(frame).or_insert_with(|| {
        rows.push((frame, vec![None; n]));
        rows.len() - 1
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two() -> JointMap {
        JointMap::from_json(
            r#"{"joints": [{"name": "root", "parent": null}, {"name": "tip", "parent": "root"}]}"#,
        )
        .expect("map")
    }

    #[test]
    fn long_and_wide_tables_read_the_same_positions() {
        let long = "frame,joint,x,y,z\n0,root,0,1,0\n0,tip,0,2,0\n1,tip,1,2,0\n1,root,0,1,0\n0,other,9,9,9\n";
        let wide = "frame,root_x,root_y,root_z,tip_x,tip_y,tip_z\n1,0,1,0,1,2,0\n0,0,1,0,0,2,0\n";
        let p = Path::new("p.csv");
        let a = read_positions_csv(p, long, &two()).expect("long");
        let b = read_positions_csv(p, wide, &two()).expect("wide");
        assert_eq!(a, b);
        assert_eq!(a.frames, 2);
        assert_eq!(a.positions[3], [1.0, 2.0, 0.0]);
    }

    /// The bytes of a `.npy` file of `values` shaped `shape` (float64, or float32).
    pub(crate) fn npy_bytes(shape: &[usize], values: &[f64], float32: bool) -> Vec<u8> {
        let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
        let shape = match dims.len() {
            1 => format!("({},)", dims[0]),
            _ => format!("({})", dims.join(", ")),
        };
        let descr = if float32 { "<f4" } else { "<f8" };
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.as_bytes());
        for v in values {
            if float32 {
                out.extend((*v as f32).to_le_bytes());
            } else {
                out.extend(v.to_le_bytes());
            }
        }
        out
    }

    #[test]
    fn npy_arrays_read_like_tables_in_either_width_and_named_order() {
        let p = Path::new("p.npy");
        // Two frames of (tip, root), the file's order, against the map's (root, tip).
        let values = [0.0, 2.0, 0.0, 0.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 1.0, 0.0];
        let names = vec!["tip".to_string(), "root".to_string()];
        let csv = "frame,joint,x,y,z\n0,root,0,1,0\n0,tip,0,2,0\n1,root,0,1,0\n1,tip,1,2,0\n";
        let table = read_positions_csv(p, csv, &two()).expect("csv");
        for (shape, f32) in [(&[2, 2, 3][..], false), (&[2, 6][..], true)] {
            let bytes = npy_bytes(shape, &values, f32);
            let read = read_positions_npy(p, &bytes, &two(), Some(&names)).expect("npy");
            assert_eq!(read, table, "{shape:?}");
        }
        // Without names, the map's input order (root, tip).
        let ordered = [0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 1.0, 0.0, 1.0, 2.0, 0.0];
        let bytes = npy_bytes(&[2, 2, 3], &ordered, false);
        assert_eq!(
            read_positions_npy(p, &bytes, &two(), None).expect("npy"),
            table
        );
        // Refusals name the file and what is wrong.
        let e = read_positions_npy(p, b"PK\x03\x04", &two(), None).expect_err("zip");
        assert!(
            e.to_string().contains("p.npy") && e.to_string().contains("magic"),
            "{e}"
        );
        let e = read_positions_npy(p, &npy_bytes(&[2, 3, 3], &[0.0; 18], false), &two(), None)
            .expect_err("width");
        assert!(e.to_string().contains("3 joints per frame"), "{e}");
        let mut short = npy_bytes(&[2, 2, 3], &ordered, false);
        short.truncate(short.len() - 8);
        let e = read_positions_npy(p, &short, &two(), None).expect_err("short");
        assert!(e.to_string().contains("bytes of data"), "{e}");
        let wrong = vec!["a".to_string(), "b".to_string()];
        let e = read_positions_npy(p, &bytes, &two(), Some(&wrong)).expect_err("names");
        assert!(e.to_string().contains("no joint `root`"), "{e}");
        assert_eq!(read_names("# joints\nroot\n\n tip \n"), ["root", "tip"]);
    }

    #[test]
    fn coco_keypoints_get_a_root_at_the_hips_midpoint_and_a_neck() {
        let map = JointMap::built_in("coco17").expect("coco");
        assert_eq!(map.names.len(), 19);
        assert_eq!(map.input_order.len(), 17);
        assert_eq!(map.input_names()[0], "nose");
        assert_eq!(map.input_names()[16], "right_ankle");
        // Keypoint k of frame 0 at (k, 2k, 0): the root is the hips' mean, the neck the
        // shoulders'.
        let values: Vec<f64> = (0..17)
            .flat_map(|k| [k as f64, 2.0 * k as f64, 0.0])
            .collect();
        let bytes = tests::npy_bytes(&[1, 17, 3], &values, false);
        let table = read_positions_npy(Path::new("c.npy"), &bytes, &map, None).expect("npy");
        let at =
            |name: &str| table.positions[map.names.iter().position(|n| n == name).expect(name)];
        assert_eq!(at("mid_hip"), [11.5, 23.0, 0.0]);
        assert_eq!(at("neck"), [5.5, 11.0, 0.0]);
        assert_eq!(at("nose"), [0.0, 0.0, 0.0]);
        // A JSON map derives the same way; a derived source must itself be read.
        let json = r#"{"joints": [{"name": "mid", "parent": null, "mean_of": ["a", "b"]},
            {"name": "a", "parent": "mid"}, {"name": "b", "parent": "mid"}]}"#;
        let m = JointMap::from_json(json).expect("map");
        assert_eq!(m.derived[0], vec![1, 2]);
        assert_eq!(m.input_names(), ["a", "b"]);
        let csv = "frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,0,0,0,2,4,6\n";
        let t = read_positions_csv(Path::new("m.csv"), csv, &m).expect("csv");
        assert_eq!(t.positions[0], [1.0, 2.0, 3.0]);
        let json = r#"{"joints": [{"name": "mid", "parent": null, "mean_of": ["a", "mid"]},
            {"name": "a", "parent": "mid"}]}"#;
        assert!(JointMap::from_json(json).is_err());
    }

    #[test]
    fn bad_tables_and_maps_say_where() {
        let p = Path::new("p.csv");
        let e = read_positions_csv(p, "frame,joint,x,y,z\n0,root,0,1,0\n0,tip,0,x,0\n", &two())
            .expect_err("not a number");
        assert!(
            e.to_string().contains("p.csv:3") && e.to_string().contains("`x`"),
            "{e}"
        );
        let e = read_positions_csv(p, "frame,joint,x,y,z\n0,root,0,1,0\n", &two())
            .expect_err("missing joint");
        assert!(e.to_string().contains("`tip`"), "{e}");
        let e = read_positions_csv(
            p,
            "frame,joint,x,y,z\n0,root,0,1,0\n0,tip,0,1,0\n2,root,0,1,0\n2,tip,0,1,0\n",
            &two(),
        )
        .expect_err("gap");
        assert!(e.to_string().contains("frame 1 is missing"), "{e}");
        let e = JointMap::from_json(r#"{"joints": [{"name": "a", "parent": "b"}]}"#)
            .expect_err("parent");
        assert!(e.to_string().contains("`b`"), "{e}");
        for name in JointMap::built_in_names() {
            let map = JointMap::built_in(name).expect("built in");
            assert_eq!(map.parents[0], -1);
        }
        assert_eq!(JointMap::built_in("smpl24").expect("smpl").names.len(), 24);
        assert_eq!(JointMap::built_in("h36m17").expect("h36m").names.len(), 17);
        assert!(JointMap::built_in_names().contains(&"coco17"));
    }
}
