//! Joint positions as files and hierarchies (what `kinergy from-positions` reads): a CSV table
//! of positions per frame and joint, and the joints' hierarchy — a built-in one (SMPL's 24
//! joints, Human3.6M's 17), a JSON map, or a BVH's skeleton.

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
}

/// The built-in hierarchies: (name, joints with their parents' names).
const BUILT_IN: [(&str, &[(&str, &str)]); 2] = [
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
];

impl JointMap {
    /// The names of the built-in hierarchies.
    pub fn built_in_names() -> Vec<&'static str> {
        BUILT_IN.iter().map(|(n, _)| *n).collect()
    }

    /// A built-in hierarchy by name (`smpl24`, `h36m17`).
    pub fn built_in(name: &str) -> Option<JointMap> {
        let (_, joints) = BUILT_IN.iter().find(|(n, _)| *n == name)?;
        JointMap::from_pairs(joints.iter().map(|(j, p)| (j.to_string(), p.to_string()))).ok()
    }

    /// The hierarchy of a BVH's skeleton.
    pub fn of_skeleton(skeleton: &Skeleton) -> JointMap {
        JointMap {
            names: skeleton.joints().iter().map(|j| j.name.clone()).collect(),
            parents: skeleton
                .joints()
                .iter()
                .map(|j| j.parent.map_or(-1, |p| p as i64))
                .collect(),
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
        }
        let file: File = serde_json::from_str(text).map_err(|e| MotionError::Invalid {
            what: "joint map",
            why: e.to_string(),
        })?;
        JointMap::from_pairs(
            file.joints
                .into_iter()
                .map(|e| (e.name, e.parent.unwrap_or_default())),
        )
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
        Ok(JointMap { names, parents })
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

impl PositionTable {
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
        for name in &map.names {
            match (column(name, "x"), column(name, "y"), column(name, "z")) {
                (Some(x), Some(y), Some(z)) => columns.push([x, y, z]),
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
            for (j, [x, y, z]) in columns.iter().enumerate() {
                let v = |c: usize, what: &str| number(record.get(c), line, what);
                table.0[k].1[j] = Some([v(*x, "x")?, v(*y, "y")?, v(*z, "z")?]);
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
                None => {
                    return Err(at(
                        1,
                        format!("joint `{}` has no position on frame {frame}", map.names[j]),
                    ));
                }
            }
        }
    }
    Ok(PositionTable {
        frames: rows.len(),
        positions,
    })
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
    }
}
