//! BVH ↔ clip conversion (`kinergy_motion::convert`): units, the up axis, the reading of
//! position channels on import, and what export writes. Moved out of `src/convert.rs`.

use std::sync::Arc;

use approx::assert_relative_eq;
use kinergy_motion::kinergy_bvh::{self, Channel};
use kinergy_motion::nalgebra::{Point3, Rotation3, Vector3};
use kinergy_motion::rotation::Axis;
use kinergy_motion::{
    Clip, Dof, ExportOptions, ExportUp, ImportOptions, Joint, LengthUnit, MotionError,
    PositionReading, PositionReadingChoice, RootReadingBasis, Skeleton, UnitChoice, UpAxis,
    UpChoice, UpDetection, clip_from_bvh, clip_to_bvh, read_clip,
};

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
    // away while its channels hold where the hips are, as its captures come.
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

/// The sweep's capture whose root position is 1e300 or ±1e308 in one frame: `fit` printed
/// "sa inf mm" and `inspect` "Hips jumps inf cm". Reading it refuses the value, naming the
/// file, its line and the channel; a real capture's values are far below the bound.
#[test]
fn a_channel_value_no_capture_holds_is_refused_naming_the_file_line_and_channel() {
    let dir = std::env::temp_dir().join(format!("kinergy-huge-value-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("folder");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data-synthetic/p01/r01.bvh"),
    )
    .expect("capture");
    let motion = text
        .lines()
        .position(|l| l.starts_with("Frame Time"))
        .expect("motion")
        + 1;
    for value in [
        "1e300",
        "1e308",
        "-1e308",
        "123456789012345678901234567890123",
    ] {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let line = motion + 48;
        let mut fields: Vec<&str> = lines[line].split(' ').collect();
        fields[0] = value;
        lines[line] = fields.join(" ");
        let path = dir.join("t.bvh");
        std::fs::write(&path, lines.join("\n") + "\n").expect("write");
        let e = read_clip(&path, &ImportOptions::default()).expect_err(value);
        let said = e.to_string();
        assert!(
            said.contains("t.bvh")
                && said.contains(&format!("line {}", line + 1))
                && said.contains("(Hips Xposition) is beyond ±1e9"),
            "{value}: {said}"
        );
        assert!(matches!(e, MotionError::Bvh(_)), "{value}: {e:?}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
