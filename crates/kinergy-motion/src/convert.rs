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
/// [`kinergy_bvh::read_file`]).
pub fn read_clip(path: &Path, options: &ImportOptions) -> Result<(Clip, ImportReport)> {
    let read = kinergy_bvh::ReadOptions {
        max_file_bytes: options
            .max_file_bytes
            .unwrap_or(kinergy_bvh::MAX_FILE_BYTES),
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

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A torso on a root whose channels add to its OFFSET (Y ≈ 2 cm on an OFFSET of 100), a
    /// child whose channels repeat its OFFSET, and a leg reaching down to the floor.
    const SMALL: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 100 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Chest
  {
    OFFSET 0 50 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT Head
    {
      OFFSET 0 60 0
      CHANNELS 3 Yrotation Xrotation Zrotation
      End Site
      {
        OFFSET 0 30 0
      }
    }
  }
  JOINT Leg
  {
    OFFSET 10 -5 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 -95 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
1 2 3 10 20 30 0 50 0 5 0 0 0 0 0 0 0 0
0 -1 0 0 0 0 0 50 0 0 0 0 90 0 0 0 0 0
";

    #[test]
    fn reads_add_root_and_replace_child_automatically() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        assert_eq!(report.unit, LengthUnit::Centimeter);
        assert!(report.unit_guessed);
        assert_eq!(
            report.position_readings,
            vec![
                ("Hips".to_string(), PositionReading::AddToOffset),
                ("Chest".to_string(), PositionReading::ReplaceOffset),
            ]
        );
        let root = report.root.expect("root reading");
        assert_eq!(root.basis, RootReadingBasis::NearerGround);
        // Added, the foot (tilted by the root's rotation) is 13 cm above the floor; replaced,
        // 87 cm below it.
        assert!(root.lowest_if_added.abs() < 0.15, "{root:?}");
        assert_relative_eq!(
            root.lowest_if_replaced,
            root.lowest_if_added - 1.0,
            epsilon = 1e-12
        );
        let p = clip
            .skeleton()
            .world_positions(clip.frame(1).expect("frame"))
            .expect("fk");
        // Root at OFFSET + channels = (0, 99, 0) cm; chest 50 cm above; head 60 more;
        // the head's 90° yaw leaves its End Site straight above.
        assert_relative_eq!(p[0].coords, Vector3::new(0.0, 0.99, 0.0), epsilon = 1e-12);
        assert_relative_eq!(p[3].coords, Vector3::new(0.0, 2.39, 0.0), epsilon = 1e-12);
        assert_eq!(clip.skeleton().joint(3).name, "Head_End");
        // No foot by name: the shape (torso above the leg) tells.
        assert_eq!(report.up, UpAxis::Y);
        assert_eq!(report.up_detection, UpDetection::BodyShape);
    }

    #[test]
    fn a_root_whose_channels_repeat_its_offset_replaces_it() {
        // Channels Y = 100 on an OFFSET of 100: added, the body would float a meter up.
        let text = SMALL.replace("1 2 3 10 20 30", "1 100 3 0 0 0");
        let bvh = kinergy_bvh::parse(&text).expect("parse");
        let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let root = report.root.expect("root reading");
        assert_eq!(root.reading, PositionReading::ReplaceOffset);
        assert_eq!(root.basis, RootReadingBasis::NearerGround);
        assert_relative_eq!(root.lowest_if_replaced, 0.0, epsilon = 1e-12);
        assert_relative_eq!(root.lowest_if_added, 1.0, epsilon = 1e-12);
        let p = clip
            .skeleton()
            .world_positions(clip.frame(0).expect("frame"))
            .expect("fk");
        assert_relative_eq!(p[0].coords, Vector3::new(0.01, 1.0, 0.03), epsilon = 1e-12);
    }

    #[test]
    fn a_zero_offset_root_is_a_tie_and_adds() {
        let text = SMALL.replace("OFFSET 0 100 0", "OFFSET 0 0 0");
        let bvh = kinergy_bvh::parse(&text).expect("parse");
        let (_, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let root = report.root.expect("root reading");
        assert_eq!(
            (root.reading, root.basis),
            (PositionReading::AddToOffset, RootReadingBasis::Tie)
        );
    }

    #[test]
    fn bandai_hips_far_from_the_origin_replace_their_offset() {
        // Bandai Namco's rig: a zero root, and `Hips` below it with an OFFSET baked 4.5 m
        // away while its channels hold where the hips are (issue: "Real captures as they come").
        let text = "HIERARCHY
ROOT joint_Root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Hips
  {
    OFFSET 0.85 93.98 -452.2
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT UpperLeg_L
    {
      OFFSET 0 -5 10
      CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 -88 0
      }
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.0333333
0 0 0 0 0 0 -0.42 93.16 -8.09 0 0 0 0 -5 10 0 0 0
";
        let bvh = kinergy_bvh::parse(text).expect("parse");
        let opts = ImportOptions {
            unit: UnitChoice::Fixed(LengthUnit::Centimeter),
            ..Default::default()
        };
        let (clip, report) = clip_from_bvh(&bvh, &opts).expect("clip");
        assert_eq!(
            report.position_readings[1..],
            [
                ("Hips".to_string(), PositionReading::ReplaceOffset),
                ("UpperLeg_L".to_string(), PositionReading::ReplaceOffset),
            ]
        );
        let p = clip
            .skeleton()
            .world_positions(clip.frame(0).expect("frame"))
            .expect("fk");
        assert_relative_eq!(
            p[1].coords,
            Vector3::new(-0.0042, 0.9316, -0.0809),
            epsilon = 1e-12
        );
        assert_relative_eq!(p[3].y, 0.0016, epsilon = 1e-12);
    }

    #[test]
    fn export_writes_positions_replacing_the_offset_and_a_zero_root_offset() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let (clip, _) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let out = clip_to_bvh(&clip, &ExportOptions::default());
        assert_eq!(out.joints[3].name, None);
        // The root's channels were added to `OFFSET 0 100 0`: written whole on a zero OFFSET,
        // which Blender's replacing and Kinergy's adding read alike.
        assert_eq!(out.joints[0].offset, [0.0; 3]);
        assert_eq!(out.joints[1].offset, bvh.joints[1].offset);
        for f in 0..2 {
            let (a, b) = (bvh.frame(f).expect("frame"), out.frame(f).expect("frame"));
            for k in 0..a.len() {
                let shift = if k < 3 { bvh.joints[0].offset[k] } else { 0.0 };
                assert_relative_eq!(a[k] + shift, b[k], epsilon = 1e-9);
            }
        }
        // Read back: the same joints where they were; written again: the same document.
        let (back, report) = clip_from_bvh(&out, &ImportOptions::default()).expect("clip");
        assert_eq!(report.root.map(|r| r.basis), Some(RootReadingBasis::Tie));
        for (a, b) in world(&clip).iter().zip(&world(&back)) {
            assert_relative_eq!(a, b, epsilon = 1e-12);
        }
        assert!(clip_to_bvh(&back, &ExportOptions::default()).same_content(&out));
    }

    #[test]
    fn joints_with_one_or_two_rotations_or_partial_positions_get_three_channels() {
        // A finger bending about Z only (Blender refused `CHANNELS 1`: "KeyError: (1, None,
        // None)"), a wrist with two axes, a knuckle translating along X only and a root
        // translating along Y only.
        let text = "HIERARCHY
ROOT Hips
{
  OFFSET 1 90 2
  CHANNELS 2 Yposition Yrotation
  JOINT Finger
  {
    OFFSET 0 10 0
    CHANNELS 1 Zrotation
    JOINT Wrist
    {
      OFFSET 0 8 1
      CHANNELS 2 Xrotation Zrotation
      JOINT Knuckle
      {
        OFFSET 0 4 0
        CHANNELS 3 Xposition Zrotation Xrotation
        End Site
        {
          OFFSET 0 3 0
        }
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
1 10 20 30 40 1 50 60
2 20 -30 40 -50 2 60 -70
3 30 40 -50 60 3 -70 80
";
        let bvh = kinergy_bvh::parse(text).expect("parse");
        let opts = ImportOptions {
            unit: UnitChoice::Fixed(LengthUnit::Centimeter),
            up: UpChoice::Fixed(UpAxis::Y),
            ..Default::default()
        };
        let (clip, _) = clip_from_bvh(&bvh, &opts).expect("clip");
        let out = clip_to_bvh(&clip, &ExportOptions::default());
        let names =
            |j: &kinergy_bvh::Joint| -> Vec<&str> { j.channels.iter().map(|c| c.name()).collect() };
        use Channel::*;
        let want: [&[Channel]; 4] = [
            &[
                Xposition, Yposition, Zposition, Yrotation, Xrotation, Zrotation,
            ],
            &[Zrotation, Xrotation, Yrotation],
            &[Xrotation, Zrotation, Yrotation],
            &[
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation,
            ],
        ];
        for (j, want) in out.joints.iter().zip(want) {
            assert_eq!(j.channels, want, "{:?}", names(j));
        }
        assert_eq!(out.joints[0].offset, [0.0; 3]);
        // The completed channels are zeros; the root's are its whole translation (its Y
        // channel replaced the OFFSET's 90 cm: that stands the body on the ground).
        let f0 = out.frame(0).expect("frame");
        let want = [1.0, 1.0, 2.0, 10.0, 0.0, 0.0, 20.0, 0.0, 0.0];
        for (a, b) in f0.iter().zip(want) {
            assert_relative_eq!(*a, b, epsilon = 1e-12);
        }
        let (back, _) = clip_from_bvh(&out, &opts).expect("clip");
        for (a, b) in world(&clip).iter().zip(&world(&back)) {
            assert_relative_eq!(a, b, epsilon = 1e-12);
        }
        // Round trip: the second writing is the first.
        assert!(clip_to_bvh(&back, &ExportOptions::default()).same_content(&out));
    }

    #[test]
    fn a_joint_rotating_twice_about_one_axis_is_written_in_three_distinct_axes() {
        let joint = |name: &str, parent, offset, dofs| Joint {
            name: String::from(name),
            parent,
            offset,
            dofs,
            end_site: false,
            position_reading: PositionReading::ReplaceOffset,
        };
        let z = Dof::Rotation(Axis::Z);
        let x = Dof::Rotation(Axis::X);
        let skeleton = Skeleton::new(vec![
            joint("Root", None, Vector3::new(0.0, 1.0, 0.0), vec![z, x, z]),
            Joint {
                end_site: true,
                ..joint("Root_End", Some(0), Vector3::new(0.0, 0.2, 0.1), vec![])
            },
        ])
        .expect("skeleton");
        let values = vec![0.3, 0.4, 0.5, 2.9, -0.2, 3.0, -3.0, 0.1, -2.9];
        let clip = Clip::new(Arc::new(skeleton), 0.1, values).expect("clip");
        let out = clip_to_bvh(&clip, &ExportOptions::default());
        use Channel::{Xrotation, Yrotation, Zrotation};
        assert_eq!(out.joints[0].channels, [Zrotation, Xrotation, Yrotation]);
        let opts = ImportOptions {
            unit: UnitChoice::Fixed(LengthUnit::Centimeter),
            up: UpChoice::Fixed(UpAxis::Y),
            ..Default::default()
        };
        let (back, _) = clip_from_bvh(&out, &opts).expect("clip");
        for (a, b) in world(&clip).iter().zip(&world(&back)) {
            assert_relative_eq!(a, b, epsilon = 1e-9);
        }
    }

    #[test]
    fn read_clip_honours_the_file_size_limit() {
        let dir = std::env::temp_dir().join(format!("kinergy-motion-limit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("small.bvh");
        std::fs::write(&path, SMALL).expect("write");
        let len = SMALL.len() as u64;
        let fits = ImportOptions {
            max_file_bytes: Some(len),
            ..ImportOptions::default()
        };
        assert!(read_clip(&path, &fits).is_ok());
        let over = ImportOptions {
            max_file_bytes: Some(len - 1),
            ..ImportOptions::default()
        };
        let e = read_clip(&path, &over).expect_err("over the limit");
        assert!(
            matches!(&e, MotionError::Bvh(kinergy_bvh::Error::Io { source, .. })
                if source.kind() == std::io::ErrorKind::FileTooLarge),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn forced_readings_and_units() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let opts = ImportOptions {
            unit: UnitChoice::Fixed(LengthUnit::Meter),
            position_reading: PositionReadingChoice::Replace,
            up: UpChoice::Fixed(UpAxis::Y),
            ..ImportOptions::default()
        };
        let (clip, report) = clip_from_bvh(&bvh, &opts).expect("clip");
        assert!(!report.unit_guessed);
        assert_eq!(report.up_detection, UpDetection::Given);
        assert_eq!(report.root.map(|r| r.basis), Some(RootReadingBasis::Given));
        let p = clip
            .skeleton()
            .world_positions(clip.frame(1).expect("frame"))
            .expect("fk");
        assert_relative_eq!(p[0].coords, Vector3::new(0.0, -1.0, 0.0), epsilon = 1e-12);
    }

    /// A standing figure (cm) written with `up` as its up axis: every OFFSET and the root's
    /// channels turned from Y-up into that frame, rotation channels arbitrary.
    fn figure_text(up: UpAxis, root_channels: &str) -> String {
        let to_file = up.world_from_file().inverse();
        let v = |x: f64, y: f64, z: f64| {
            let f = to_file * Vector3::new(x, y, z);
            format!("{} {} {}", f.x, f.y, f.z)
        };
        let rot = "CHANNELS 3 Zrotation Xrotation Yrotation";
        let t = to_file * Vector3::new(1.0, 2.0, 3.0);
        let root_offset = v(0.0, 90.0, 0.0);
        let mut text = format!(
            "HIERARCHY\nROOT Hips\n{{\nOFFSET {root_offset}\nCHANNELS {root_channels}\n\
             JOINT Spine\n{{\nOFFSET {}\n{rot}\nJOINT Head\n{{\nOFFSET {}\n{rot}\n\
             End Site\n{{\nOFFSET {}\n}}\n}}\n}}\n\
             JOINT LeftUpLeg\n{{\nOFFSET {}\n{rot}\nJOINT LeftFoot\n{{\nOFFSET {}\n{rot}\n\
             End Site\n{{\nOFFSET {}\n}}\n}}\n}}\n\
             JOINT RightUpLeg\n{{\nOFFSET {}\n{rot}\nJOINT RightFoot\n{{\nOFFSET {}\n{rot}\n\
             End Site\n{{\nOFFSET {}\n}}\n}}\n}}\n}}\nMOTION\nFrames: 3\nFrame Time: 0.0333333\n",
            v(0.0, 20.0, 0.0),
            v(0.0, 50.0, 0.0),
            v(0.0, 20.0, 0.0),
            v(10.0, -5.0, 0.0),
            v(0.0, -80.0, 0.0),
            v(0.0, -5.0, 10.0),
            v(-10.0, -5.0, 0.0),
            v(0.0, -80.0, 0.0),
            v(0.0, -5.0, 10.0),
        );
        let n_rot = root_channels
            .split_whitespace()
            .filter(|c| c.ends_with("rotation"))
            .count();
        for f in 0..3 {
            let mut row = Vec::new();
            for c in root_channels.split_whitespace().skip(1) {
                row.push(match c {
                    "Xposition" => t.x + f as f64,
                    "Yposition" => t.y,
                    "Zposition" => t.z,
                    _ => 5.0 + 3.0 * f as f64,
                });
            }
            debug_assert_eq!(row.len() - n_rot, root_channels.matches("position").count());
            row.extend((0..18).map(|k| (k as f64 * 7.0 + f as f64) % 23.0 - 11.0));
            let row: Vec<String> = row.iter().map(f64::to_string).collect();
            text.push_str(&row.join(" "));
            text.push('\n');
        }
        text
    }

    fn world(clip: &Clip) -> Vec<Point3<f64>> {
        let all: Vec<usize> = (0..clip.skeleton().joint_count()).collect();
        clip.trajectory(&all)
            .expect("trajectory")
            .frames()
            .flatten()
            .copied()
            .collect()
    }

    #[test]
    fn every_up_axis_is_detected_read_y_up_and_written_back_either_way() {
        let six = "6 Xposition Yposition Zposition Yrotation Xrotation Zrotation";
        for up in UpAxis::ALL {
            let bvh = kinergy_bvh::parse(&figure_text(up, six)).expect("parse");
            let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
            assert_eq!(
                (report.up, report.up_detection),
                (up, UpDetection::JointNames)
            );
            // The root's channels add (measured along the file's own up axis).
            let root = report.root.expect("root");
            assert_eq!(root.reading, PositionReading::AddToOffset, "{up}");
            // Y up: the head above the hips, the feet's End Sites 3 cm above y = 0 (the
            // root's own +2 cm of channels and its first-frame rotation aside).
            let p = world(&clip);
            assert!(p[2].y > p[0].y + 0.5, "{up}: head {:?}", p[2]);
            // The same values written back, in the file's axis.
            let same = clip_to_bvh(
                &clip,
                &ExportOptions {
                    unit: LengthUnit::Centimeter,
                    up: ExportUp::AsRead,
                },
            );
            // (The root's OFFSET moved into its position channels, the first three.)
            let n = bvh.channel_count();
            for (k, (a, b)) in bvh.motion.iter().zip(&same.motion).enumerate() {
                let shift = if k % n < 3 {
                    bvh.joints[0].offset[k % n]
                } else {
                    0.0
                };
                assert_relative_eq!(a + shift, b, epsilon = 1e-9);
            }
            // Written Y up, read again: Y up, the same world positions.
            let y = clip_to_bvh(
                &clip,
                &ExportOptions {
                    unit: LengthUnit::Centimeter,
                    up: ExportUp::Y,
                },
            );
            let (back, report) = clip_from_bvh(&y, &ImportOptions::default()).expect("clip");
            assert_eq!(report.up, UpAxis::Y, "{up}");
            assert_eq!(back.skeleton().world_from_file(), Rotation3::identity());
            for (a, b) in world(&clip).iter().zip(&world(&back)) {
                assert_relative_eq!(a, b, epsilon = 1e-9);
            }
        }
    }

    #[test]
    fn y_up_export_completes_a_root_with_partial_channels() {
        for channels in ["3 Xrotation Zrotation Yrotation", "2 Yposition Zrotation"] {
            let bvh = kinergy_bvh::parse(&figure_text(UpAxis::Z, channels)).expect("parse");
            let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
            assert_eq!(report.up, UpAxis::Z);
            let y = clip_to_bvh(
                &clip,
                &ExportOptions {
                    unit: LengthUnit::Meter,
                    up: ExportUp::Y,
                },
            );
            assert_eq!(y.joints[0].channels.len() % 3, 0, "{channels}");
            let opts = ImportOptions {
                unit: UnitChoice::Fixed(LengthUnit::Meter),
                ..Default::default()
            };
            let (back, _) = clip_from_bvh(&y, &opts).expect("clip");
            for (a, b) in world(&clip).iter().zip(&world(&back)) {
                assert_relative_eq!(a, b, epsilon = 1e-9);
            }
        }
    }

    #[test]
    fn the_up_axis_can_be_forced() {
        let six = "6 Xposition Yposition Zposition Yrotation Xrotation Zrotation";
        let bvh = kinergy_bvh::parse(&figure_text(UpAxis::Z, six)).expect("parse");
        let opts = ImportOptions {
            up: "y".parse().expect("axis"),
            ..Default::default()
        };
        let (clip, report) = clip_from_bvh(&bvh, &opts).expect("clip");
        assert_eq!(
            (report.up, report.up_detection),
            (UpAxis::Y, UpDetection::Given)
        );
        assert_eq!(clip.skeleton().world_from_file(), Rotation3::identity());
    }
}
