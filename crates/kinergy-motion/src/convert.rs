//! BVH ↔ skeleton and clip: units, degrees ↔ radians, the up axis, and the reading of
//! position channels.
//!
//! # How position channels are read
//! The format does not say whether a joint's position channels *replace* its `OFFSET` or are
//! *added* to it, and real files do both. [`PositionReadingChoice::Auto`] reads them so:
//!
//! - **Non-root joints: the channels replace the OFFSET** on their axes (`t = channel −
//!   offset`), as Blender's importer reads them. Bandai Namco's files carry each joint's
//!   OFFSET in its channels, and their `Hips`, a non-root joint below `joint_Root`, has an
//!   OFFSET baked metres away from the origin (`0.85 93.98 −452.2`) while its channels hold
//!   where the hips really are (`−0.42 93.16 −8.09`): adding the two would float the body
//!   4.5 m away.
//! - **The root: the reading that stands the body on the ground.** In the first frame, with
//!   the up axis decided ([`crate::up`]), the lowest point of the body (the feet) is found
//!   along the up axis with the channels added to the OFFSET and with them replacing it;
//!   the reading whose lowest point is nearer the ground plane (height 0) wins, and a tie
//!   (as when the OFFSET is zero along the up axis, the usual case) reads **add**. Character
//!   Creator's root (`OFFSET 0 105 0`, channels Y ≈ 5) adds; a root whose channels repeat its
//!   OFFSET replaces. [`ImportReport::root`] records the choice and both heights.
//!
//! [`PositionReadingChoice::Add`] and [`PositionReadingChoice::Replace`] force every joint.
//! The reading is recorded on each joint ([`crate::PositionReading`]). Export writes
//! position channels the one way every reader agrees on ([`clip_to_bvh`]): the channels hold
//! the joint's whole translation and replace its OFFSET, and a root with position channels
//! gets a zero OFFSET, so reading it back (by Kinergy, Blender, or three.js for the root)
//! gives the same joint positions whichever way its channels are read.
//!
//! # Up axis
//! Z-up and X-up files (and upside-down ones) are detected from the first frame
//! ([`crate::up`]) or given ([`ImportOptions::up`]). The joint values stay the file's; the
//! skeleton turns the file's frame into Kinergy's Y-up world at the root
//! ([`crate::Skeleton::world_from_file`]). Export keeps the file's axis, so a round trip
//! writes the values it read; [`ExportUp::Y`] writes a Y-up file instead.

use std::path::Path;
use std::sync::Arc;

use kinergy_bvh::{Bvh, Channel};
use nalgebra::{Point3, Rotation3, Vector3};

use crate::clip::Clip;
use crate::error::{MotionError, Result};
use crate::rotation::{Axis, euler_angles, euler_rotation, nearest_euler};
use crate::skeleton::{Dof, Joint, PositionReading, Skeleton};
use crate::units::{LengthUnit, UnitChoice};
use crate::up::{UpAxis, UpChoice, UpDetection, detect_up};

/// How to read a joint's position channels relative to its `OFFSET`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PositionReadingChoice {
    /// Non-root joints replace; the root stands the body on the ground (see the
    /// [module docs](self)).
    #[default]
    Auto,
    /// Every joint: OFFSET + channels.
    Add,
    /// Every joint: the channels replace the OFFSET on their axes.
    Replace,
}

impl PositionReadingChoice {
    /// As `--positions` spells it: `auto`, `add` or `replace`.
    pub fn name(self) -> &'static str {
        match self {
            PositionReadingChoice::Auto => "auto",
            PositionReadingChoice::Add => "add",
            PositionReadingChoice::Replace => "replace",
        }
    }
}

impl std::str::FromStr for PositionReadingChoice {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(PositionReadingChoice::Auto),
            "add" => Ok(PositionReadingChoice::Add),
            "replace" => Ok(PositionReadingChoice::Replace),
            _ => Err(format!(
                "unknown position reading `{s}`: expected auto, add or replace"
            )),
        }
    }
}

/// Options for reading a BVH document into a [`Clip`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ImportOptions {
    /// The file's length unit, or a guess from the skeleton's size.
    pub unit: UnitChoice,
    /// How position channels combine with OFFSETs.
    pub position_reading: PositionReadingChoice,
    /// The file's up axis, or detected from its first frame.
    pub up: UpChoice,
    /// The largest file [`read_clip`] reads, bytes; `None`:
    /// [`kinergy_bvh::MAX_FILE_BYTES`] (256 MiB).
    pub max_file_bytes: Option<u64>,
}

/// Why the root's position channels were read as they were.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RootReadingBasis {
    /// Forced by [`ImportOptions::position_reading`].
    Given,
    /// Its lowest point of the body in the first frame is nearer the ground plane.
    NearerGround,
    /// Both readings put the lowest point equally near the ground (e.g. the OFFSET is zero
    /// along the up axis): add.
    Tie,
    /// The clip has no frames to measure: add.
    NoFrames,
}

impl RootReadingBasis {
    /// `"given"`, `"nearer the ground"`, `"tie"` or `"no frames"`.
    pub fn name(self) -> &'static str {
        match self {
            RootReadingBasis::Given => "given",
            RootReadingBasis::NearerGround => "nearer the ground",
            RootReadingBasis::Tie => "tie",
            RootReadingBasis::NoFrames => "no frames",
        }
    }
}

/// How the root's position channels were read, and the evidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootReading {
    /// The reading chosen.
    pub reading: PositionReading,
    /// Why.
    pub basis: RootReadingBasis,
    /// The height (meters, along the up axis, 0 = the ground plane) of the body's lowest
    /// point in the first frame with the root's channels added to its OFFSET.
    pub lowest_if_added: f64,
    /// The same with the channels replacing the OFFSET.
    pub lowest_if_replaced: f64,
}

/// What the import decided.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportReport {
    /// The unit the file was read in.
    pub unit: LengthUnit,
    /// True when [`ImportReport::unit`] was guessed.
    pub unit_guessed: bool,
    /// The largest extent of the skeleton along a world axis in the first frame, in the
    /// file's units (what the guess looked at).
    pub extent_in_file_units: f64,
    /// For every joint with position channels: its name and how they were read.
    pub position_readings: Vec<(String, PositionReading)>,
    /// How the root's position channels were read and why (`None` when it has none).
    pub root: Option<RootReading>,
    /// The file's up axis.
    pub up: UpAxis,
    /// How [`ImportReport::up`] was decided.
    pub up_detection: UpDetection,
}

impl ImportReport {
    /// How the root's position channels were read, if it has any.
    pub fn root_reading(&self) -> Option<PositionReading> {
        self.root.map(|r| r.reading)
    }

    /// True when the up axis was detected from the data (not given, not assumed).
    pub fn up_detected(&self) -> bool {
        self.up_detection.detected()
    }
}

fn channel_dof(c: Channel) -> Dof {
    let axis = Axis::from_index(c.axis());
    if c.is_rotation() {
        Dof::Rotation(axis)
    } else {
        Dof::Translation(axis)
    }
}

fn dof_channel(d: Dof) -> Channel {
    match d {
        Dof::Translation(Axis::X) => Channel::Xposition,
        Dof::Translation(Axis::Y) => Channel::Yposition,
        Dof::Translation(Axis::Z) => Channel::Zposition,
        Dof::Rotation(Axis::X) => Channel::Xrotation,
        Dof::Rotation(Axis::Y) => Channel::Yrotation,
        Dof::Rotation(Axis::Z) => Channel::Zrotation,
    }
}

/// Appends one frame's pose values (file units × `scale`, radians), positions made relative
/// to the OFFSET where the channels replace it.
fn push_pose(
    bvh: &Bvh,
    readings: &[PositionReading],
    frame: &[f64],
    scale: f64,
    out: &mut Vec<f64>,
) {
    for (bj, &reading) in bvh.joints.iter().zip(readings) {
        for (k, c) in bj.channels.iter().enumerate() {
            let v = frame.get(bj.first_channel + k).copied().unwrap_or(0.0);
            out.push(if c.is_rotation() {
                v.to_radians()
            } else if reading == PositionReading::ReplaceOffset {
                (v - bj.offset[c.axis()]) * scale
            } else {
                v * scale
            });
        }
    }
}

/// The lowest of `points` along `up`.
fn lowest(points: &[Point3<f64>], up: &Vector3<f64>) -> f64 {
    points
        .iter()
        .map(|p| p.coords.dot(up))
        .fold(f64::INFINITY, f64::min)
}

/// Two root heights closer than this (meters) are a tie.
const TIE: f64 = 1e-9;

/// Reads a BVH document as a clip in SI units (meters, radians), Y up.
pub fn clip_from_bvh(bvh: &Bvh, options: &ImportOptions) -> Result<(Clip, ImportReport)> {
    let first_frame = bvh.frame(0).unwrap_or(&[]);
    let mut names = std::collections::HashMap::new();
    let mut joints = Vec::with_capacity(bvh.joints.len());
    for (i, bj) in bvh.joints.iter().enumerate() {
        let name = match (&bj.name, bj.parent) {
            (Some(n), _) => n.clone(),
            (None, Some(p)) => {
                let parent = bvh.joints.get(p).map_or("joint", |j| j.display_name());
                let mut name = format!("{parent}_End");
                let mut k = 2;
                while names.contains_key(&name) {
                    name = format!("{parent}_End{k}");
                    k += 1;
                }
                name
            }
            (None, None) => format!("joint{i}"),
        };
        names.insert(name.clone(), i);
        // The root's Auto reading is decided below, once the body can be measured.
        let position_reading = match (options.position_reading, bj.parent) {
            (PositionReadingChoice::Add, _) | (PositionReadingChoice::Auto, None) => {
                PositionReading::AddToOffset
            }
            _ => PositionReading::ReplaceOffset,
        };
        joints.push(Joint {
            name,
            parent: bj.parent,
            offset: Vector3::from(bj.offset),
            dofs: bj.channels.iter().map(|&c| channel_dof(c)).collect(),
            end_site: bj.end_site,
            position_reading,
        });
    }

    // The first frame in file units, in the file's frame, the root's channels added.
    let file_skeleton = Skeleton::new(joints.clone())?;
    let mut readings: Vec<PositionReading> = joints.iter().map(|j| j.position_reading).collect();
    let mut first_pose = Vec::with_capacity(file_skeleton.dof_count());
    push_pose(bvh, &readings, first_frame, 1.0, &mut first_pose);
    let first_points = file_skeleton.world_positions(&first_pose)?;

    // Unit and up axis: both blind to where the root is, so to its reading.
    let extent = file_skeleton.extent(&first_pose)?;
    let (unit, guessed) = match options.unit {
        UnitChoice::Fixed(u) => (u, false),
        UnitChoice::Auto => (
            LengthUnit::guess_from_extent(extent).unwrap_or(LengthUnit::Centimeter),
            true,
        ),
    };
    let scale = unit.meters();
    let (up, up_detection) = match options.up {
        UpChoice::Fixed(u) => (u, UpDetection::Given),
        UpChoice::Auto => detect_up(&file_skeleton, &first_points),
    };

    // The root: the reading whose lowest point is nearer the ground.
    let root = &bvh.joints[0];
    let root_translates = root.channels.iter().any(|c| c.is_position());
    let root_reading = root_translates.then(|| {
        let mut replaced_shift = Vector3::zeros();
        for c in root.channels.iter().filter(|c| c.is_position()) {
            replaced_shift[c.axis()] = -root.offset[c.axis()];
        }
        let u = up.vector();
        let added = lowest(&first_points, &u) * scale;
        let replaced = added + replaced_shift.dot(&u) * scale;
        let (reading, basis) = match options.position_reading {
            PositionReadingChoice::Add => (PositionReading::AddToOffset, RootReadingBasis::Given),
            PositionReadingChoice::Replace => {
                (PositionReading::ReplaceOffset, RootReadingBasis::Given)
            }
            PositionReadingChoice::Auto if bvh.frame_count == 0 => {
                (PositionReading::AddToOffset, RootReadingBasis::NoFrames)
            }
            PositionReadingChoice::Auto if (added.abs() - replaced.abs()).abs() <= TIE => {
                (PositionReading::AddToOffset, RootReadingBasis::Tie)
            }
            PositionReadingChoice::Auto if replaced.abs() < added.abs() => (
                PositionReading::ReplaceOffset,
                RootReadingBasis::NearerGround,
            ),
            PositionReadingChoice::Auto => {
                (PositionReading::AddToOffset, RootReadingBasis::NearerGround)
            }
        };
        RootReading {
            reading,
            basis,
            lowest_if_added: added,
            lowest_if_replaced: replaced,
        }
    });
    if let Some(r) = root_reading {
        readings[0] = r.reading;
        joints[0].position_reading = r.reading;
    }
    let position_readings = joints
        .iter()
        .filter(|j| j.dofs.iter().any(|d| matches!(d, Dof::Translation(_))))
        .map(|j| (j.name.clone(), j.position_reading))
        .collect();

    for j in &mut joints {
        j.offset *= scale;
    }
    let skeleton = Arc::new(Skeleton::new(joints)?.with_world_from_file(up.world_from_file()));
    let mut values = Vec::with_capacity(bvh.frame_count * bvh.channel_count());
    for f in 0..bvh.frame_count {
        push_pose(
            bvh,
            &readings,
            bvh.frame(f).unwrap_or(&[]),
            scale,
            &mut values,
        );
    }
    let clip = Clip::new(skeleton, bvh.frame_time, values)?;
    Ok((
        clip,
        ImportReport {
            unit,
            unit_guessed: guessed,
            extent_in_file_units: extent,
            position_readings,
            root: root_reading,
            up,
            up_detection,
        },
    ))
}

/// Reads a BVH file as a clip; errors name the file (and line, for parse errors). Only
/// regular files up to [`ImportOptions::max_file_bytes`] are read (see
/// [`kinergy_bvh::read_file`]), and only values a capture can hold: an `OFFSET` component
/// or a channel value beyond ±[`kinergy_bvh::MAX_VALUE`] (1e9) is refused naming its line,
/// joint and channel ([`kinergy_bvh::ReadOptions::bounded_values`]), where it would have
/// made every distance of the clip infinite.
pub fn read_clip(path: &Path, options: &ImportOptions) -> Result<(Clip, ImportReport)> {
    let read = kinergy_bvh::ReadOptions {
        max_file_bytes: options
            .max_file_bytes
            .unwrap_or(kinergy_bvh::MAX_FILE_BYTES),
        bounded_values: true,
        ..kinergy_bvh::ReadOptions::default()
    };
    let bvh = kinergy_bvh::read_file(path, &read)?;
    clip_from_bvh(&bvh, options)
}

/// Which way up a written file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExportUp {
    /// The axis the file was read with: the joint values are written as read.
    #[default]
    AsRead,
    /// Y up: the rotation from the file's frame to the world
    /// ([`crate::Skeleton::world_from_file`]) is baked into the root's OFFSET, position
    /// channels and rotation channels (re-expressed in the root's own rotation order, the
    /// angles nearest the previous frame's). A root without three position channels (when it
    /// has any) or three distinct rotation channels is written with `Xposition Yposition
    /// Zposition` and its rotation order, or `Zrotation Xrotation Yrotation`, since a turned
    /// translation or rotation may need the channels it lacks.
    Y,
}

/// Options for writing a clip as BVH.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExportOptions {
    /// The length unit of the written file (centimeters unless told otherwise).
    pub unit: LengthUnit,
    /// Which way up the written file is (the file's own axis unless told otherwise).
    pub up: ExportUp,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            unit: LengthUnit::Centimeter,
            up: ExportUp::AsRead,
        }
    }
}

/// The three distinct rotation axes of `dofs`, in order, if it has exactly those.
fn three_rotations(dofs: &[Dof]) -> Option<[Axis; 3]> {
    let axes: Vec<Axis> = dofs
        .iter()
        .filter_map(|d| match d {
            Dof::Rotation(a) => Some(*a),
            Dof::Translation(_) => None,
        })
        .collect();
    match axes[..] {
        [a, b, c] if a != b && b != c && a != c => Some([a, b, c]),
        _ => None,
    }
}

/// The root's channels in a Y-up file (see [`ExportUp::Y`]).
fn y_up_root_dofs(dofs: &[Dof]) -> Vec<Dof> {
    let positions: Vec<Axis> = dofs
        .iter()
        .filter_map(|d| match d {
            Dof::Translation(a) => Some(*a),
            Dof::Rotation(_) => None,
        })
        .collect();
    let full_positions = positions.is_empty()
        || (positions.len() == 3
            && positions
                .iter()
                .all(|a| positions.iter().filter(|b| *b == a).count() == 1));
    if full_positions && three_rotations(dofs).is_some() {
        return dofs.to_vec();
    }
    let mut out = Vec::with_capacity(6);
    if !positions.is_empty() {
        out.extend([Axis::X, Axis::Y, Axis::Z].map(Dof::Translation));
    }
    let order = three_rotations(dofs).unwrap_or([Axis::Z, Axis::X, Axis::Y]);
    out.extend(order.map(Dof::Rotation));
    out
}

/// The channels a joint is written with, so that every reader (Kinergy's, Blender's,
/// three.js's) reads the same pose: no position channels or all three, and no rotation
/// channels or three about distinct axes (Blender's importer refuses any other count).
///
/// A joint already so is written as it is (a round trip keeps its channels). Otherwise its
/// positions become `Xposition Yposition Zposition`; one or two distinct rotation axes are
/// completed with the missing axes (written as zeros, so the rotation is unchanged); any
/// other rotation list (a repeated axis, more than three) becomes `Zrotation Xrotation
/// Yrotation`, the angles re-expressed frame by frame.
fn written_dofs(dofs: &[Dof]) -> (Vec<Dof>, RotationWriting) {
    let mut positions = Vec::with_capacity(3);
    let mut rotations = Vec::with_capacity(3);
    for d in dofs {
        match *d {
            Dof::Translation(a) => positions.push(a),
            Dof::Rotation(a) => rotations.push(a),
        }
    }
    let distinct = |axes: &[Axis]| axes.iter().enumerate().all(|(i, a)| !axes[..i].contains(a));
    let positions_ok = positions.is_empty() || (positions.len() == 3 && distinct(&positions));
    let rotations_ok = rotations.is_empty() || (rotations.len() == 3 && distinct(&rotations));
    if positions_ok && rotations_ok {
        return (dofs.to_vec(), RotationWriting::AsIs);
    }
    let mut out = Vec::with_capacity(6);
    if !positions.is_empty() {
        out.extend([Axis::X, Axis::Y, Axis::Z].map(Dof::Translation));
    }
    let writing = if rotations.is_empty() {
        RotationWriting::Completed
    } else if rotations.len() <= 3 && distinct(&rotations) {
        let mut order = rotations.clone();
        order.extend(
            [Axis::X, Axis::Y, Axis::Z]
                .into_iter()
                .filter(|a| !rotations.contains(a)),
        );
        out.extend(order.into_iter().map(Dof::Rotation));
        RotationWriting::Completed
    } else {
        out.extend([Axis::Z, Axis::X, Axis::Y].map(Dof::Rotation));
        RotationWriting::Reexpressed
    };
    (out, writing)
}

/// How a joint's rotation channel values are found from its DoF values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RotationWriting {
    /// The joint's own DoFs, in their order.
    AsIs,
    /// Each channel takes the value of the DoF about its axis, 0 where there is none.
    Completed,
    /// The joint's rotation re-expressed in the channels' order.
    Reexpressed,
}

/// The clip as a BVH document: degrees, `options.unit`, in the file's own up axis or Y up
/// ([`ExportOptions::up`]), read alike by Kinergy and Blender (and by three.js's
/// `BVHLoader`, which adds OFFSETs to position channels, when only the root has them):
///
/// - every joint has no rotation channels or three about distinct axes, and no position
///   channels or all three (one or two rotation axes are completed with zero channels; any
///   other rotation list is re-expressed as `Zrotation Xrotation Yrotation`);
/// - position channels hold the joint's whole translation (OFFSET + displacement), so they
///   *replace* the OFFSET, as Blender reads them; the root, whose channels
///   Kinergy may read either way ([`crate::PositionReading`]), is written with a zero OFFSET
///   when it has position channels, so both readings agree.
pub fn clip_to_bvh(clip: &Clip, options: &ExportOptions) -> Bvh {
    let s = clip.skeleton();
    let scale = 1.0 / options.unit.meters();
    let w = s.world_from_file();
    let bake = options.up == ExportUp::Y && w != Rotation3::identity();
    let layouts: Vec<(Vec<Dof>, RotationWriting)> = s
        .joints()
        .iter()
        .enumerate()
        .map(|(ji, j)| {
            if bake && ji == 0 {
                (y_up_root_dofs(&j.dofs), RotationWriting::AsIs)
            } else {
                written_dofs(&j.dofs)
            }
        })
        .collect();
    let mut first = 0;
    let joints: Vec<kinergy_bvh::Joint> = s
        .joints()
        .iter()
        .zip(&layouts)
        .enumerate()
        .map(|(ji, (j, (dofs, _)))| {
            let channels: Vec<Channel> = dofs.iter().map(|&d| dof_channel(d)).collect();
            let translates = dofs.iter().any(|d| matches!(d, Dof::Translation(_)));
            let offset = if ji == 0 && translates {
                Vector3::zeros()
            } else if bake && ji == 0 {
                w * j.offset
            } else {
                j.offset
            };
            let bj = kinergy_bvh::Joint {
                name: (!j.end_site).then(|| j.name.clone()),
                parent: j.parent,
                offset: (offset * scale).into(),
                first_channel: first,
                end_site: j.end_site,
                line: 0,
                channels,
            };
            first += bj.channels.len();
            bj
        })
        .collect();
    let mut previous: Vec<Option<[f64; 3]>> = vec![None; s.joint_count()];
    let mut motion = Vec::with_capacity(clip.frame_count() * first);
    for pose in clip.frames() {
        for (ji, (j, (dofs, writing))) in s.joints().iter().zip(&layouts).enumerate() {
            let values = &pose[s.dof_range(ji)];
            if bake && ji == 0 {
                previous[0] = Some(push_y_up_root(
                    j,
                    values,
                    dofs,
                    w,
                    scale,
                    previous[0],
                    &mut motion,
                ));
                continue;
            }
            let mut t = j.offset;
            for (d, &v) in j.dofs.iter().zip(values) {
                if let Dof::Translation(a) = d {
                    t[a.index()] += v;
                }
            }
            match writing {
                RotationWriting::AsIs => {
                    for (d, &v) in j.dofs.iter().zip(values) {
                        motion.push(match d {
                            Dof::Rotation(_) => v.to_degrees(),
                            Dof::Translation(a) => t[a.index()] * scale,
                        });
                    }
                }
                RotationWriting::Completed => {
                    for d in dofs {
                        motion.push(match d {
                            Dof::Translation(a) => t[a.index()] * scale,
                            Dof::Rotation(a) => j
                                .dofs
                                .iter()
                                .zip(values)
                                .find(|(dj, _)| **dj == Dof::Rotation(*a))
                                .map_or(0.0, |(_, v)| v.to_degrees()),
                        });
                    }
                }
                RotationWriting::Reexpressed => {
                    let (axes, angles): (Vec<Axis>, Vec<f64>) = j
                        .dofs
                        .iter()
                        .zip(values)
                        .filter_map(|(d, &v)| match d {
                            Dof::Rotation(a) => Some((*a, v)),
                            Dof::Translation(_) => None,
                        })
                        .unzip();
                    let r = euler_rotation(&axes, &angles);
                    let order = [Axis::Z, Axis::X, Axis::Y];
                    let near = previous[ji].unwrap_or([0.0; 3]);
                    let e = euler_angles(order, &r).map_or(near, |e| nearest_euler(e, near));
                    previous[ji] = Some(e);
                    let mut k = 0;
                    for d in dofs {
                        motion.push(match d {
                            Dof::Translation(a) => t[a.index()] * scale,
                            Dof::Rotation(_) => {
                                k += 1;
                                e[k - 1].to_degrees()
                            }
                        });
                    }
                }
            }
        }
    }
    Bvh {
        joints,
        frame_time: clip.frame_time(),
        frame_count: clip.frame_count(),
        motion,
    }
}

/// Writes the root's values of one frame turned Y up into `motion` (channels `dofs`); returns
/// its rotation angles (radians, in `dofs`' rotation order) for the next frame's continuity.
fn push_y_up_root(
    root: &Joint,
    values: &[f64],
    dofs: &[Dof],
    w: Rotation3<f64>,
    scale: f64,
    previous: Option<[f64; 3]>,
    motion: &mut Vec<f64>,
) -> [f64; 3] {
    let mut t = Vector3::zeros();
    let mut axes = Vec::with_capacity(3);
    let mut angles = Vec::with_capacity(3);
    for (d, &v) in root.dofs.iter().zip(values) {
        match d {
            Dof::Translation(a) => t[a.index()] += v,
            Dof::Rotation(a) => {
                axes.push(*a);
                angles.push(v);
            }
        }
    }
    let r = w * euler_rotation(&axes, &angles);
    let order = three_rotations(dofs).unwrap_or([Axis::Z, Axis::X, Axis::Y]);
    // The first frame stays near the file's own angles when the order is unchanged.
    let near = previous.unwrap_or_else(|| match angles[..] {
        [a, b, c] if axes[..] == order[..] => [a, b, c],
        _ => [0.0; 3],
    });
    let new_angles = euler_angles(order, &r).map_or(near, |e| nearest_euler(e, near));
    let t = w * t;
    let o = w * root.offset;
    let mut k = 0;
    for d in dofs {
        motion.push(match d {
            Dof::Rotation(_) => {
                k += 1;
                new_angles[k - 1].to_degrees()
            }
            // The whole translation: the root's OFFSET is written as zero.
            Dof::Translation(a) => (t[a.index()] + o[a.index()]) * scale,
        });
    }
    new_angles
}

/// Writes a clip as a BVH file ([`clip_to_bvh`]), atomically (a temporary file renamed into place).
pub fn write_clip(path: &Path, clip: &Clip, options: &ExportOptions) -> Result<()> {
    kinergy_bvh::write_file(path, &clip_to_bvh(clip, options)).map_err(MotionError::from)
}
