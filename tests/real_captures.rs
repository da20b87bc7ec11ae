//! End-to-end checks of the foundation on real captures: units, root readings, arm chains,
//! bone lengths and round trips.
//!
//! The CMU-derived files are committed under `tests/data/`; the Bandai Namco files (CC BY-NC)
//! are read from `../shared/data/real-bvh/` and skipped, with a notice, where it is absent.

#[path = "support/require_shared.rs"]
mod require_shared;

use std::path::{Path, PathBuf};

use approx::assert_relative_eq;
use kinergy::motion::{
    ArmJoints, ExportOptions, ImportOptions, LengthUnit, PositionReading, Side, UnitChoice,
    clip_from_bvh, clip_to_bvh, motion_distance, read_clip,
};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn shared(name: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/real-bvh")
        .join(name);
    if p.exists() {
        Some(p)
    } else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the Bandai Namco captures are never committed)",
            p.display()
        ));
        None
    }
}

fn lowest_point(clip: &kinergy::motion::Clip, frame: usize) -> f64 {
    let p = clip
        .skeleton()
        .world_positions(clip.frame(frame).expect("frame"))
        .expect("fk");
    p.iter().map(|p| p.y).fold(f64::INFINITY, f64::min)
}

#[test]
fn cmu_walk_reads_in_cmu_units_with_a_t_pose_arm() {
    let (clip, report) =
        read_clip(&fixture("cmu_12_01_walk.bvh"), &ImportOptions::default()).expect("read");
    assert_eq!(report.unit, LengthUnit::Cmu);
    assert!(report.unit_guessed);
    assert_eq!(clip.frame_count(), 524);
    assert_relative_eq!(clip.frame_rate(), 120.0, max_relative = 1e-4);
    // Hips 16.2 units high = 0.91 m; the feet on the ground.
    let hips = clip
        .skeleton()
        .world_positions(clip.frame(0).expect("frame"))
        .expect("fk")[0];
    assert_relative_eq!(
        hips.y,
        16.2134 * LengthUnit::Cmu.meters(),
        max_relative = 1e-9
    );
    assert!(lowest_point(&clip, 0).abs() < 0.1, "feet near y = 0");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("right arm");
    assert_eq!(
        arm.names(clip.skeleton()),
        [
            "RightShoulder",
            "RightArm",
            "RightForeArm",
            "RightHand",
            "RightHandIndex1"
        ]
    );
    let left = ArmJoints::find(clip.skeleton(), Side::Left).expect("left arm");
    let lengths = left.lengths(&clip).expect("lengths");
    // README: upper arm 4.92 units, forearm 2.66 units (the cgspeed skeleton's proportions).
    assert_relative_eq!(
        lengths.upper_arm,
        4.92 * LengthUnit::Cmu.meters(),
        max_relative = 0.01
    );
    assert_relative_eq!(
        lengths.forearm,
        2.66 * LengthUnit::Cmu.meters(),
        max_relative = 0.01
    );
}

#[test]
fn character_creator_root_adds_channels_to_its_offset() {
    let (clip, report) =
        read_clip(&fixture("006_14.bvh"), &ImportOptions::default()).expect("read");
    assert_eq!(report.unit, LengthUnit::Centimeter);
    assert_eq!(report.root_reading(), Some(PositionReading::AddToOffset));
    // Read as OFFSET + channels the feet stand near the floor; read as absolute they would
    // be about 91 cm below it.
    assert!(
        lowest_point(&clip, 0).abs() < 0.15,
        "lowest {}",
        lowest_point(&clip, 0)
    );
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("right arm");
    assert_eq!(
        &arm.names(clip.skeleton())[..4],
        [
            "CC_Base_R_Clavicle",
            "CC_Base_R_Upperarm",
            "CC_Base_R_Forearm",
            "CC_Base_R_Hand"
        ]
    );
    let l = arm.lengths(&clip).expect("lengths");
    assert_relative_eq!(l.upper_arm, 0.252, max_relative = 0.02);
    assert_relative_eq!(l.forearm, 0.257, max_relative = 0.02);
    // The shot: the right hand is above 1.70 m at frames 132–169, highest at 140 (≈ 1.87 m).
    let hand = clip.trajectory(&[arm.wrist]).expect("trajectory").path(0);
    let (top, _) = hand
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.y.total_cmp(&b.1.y))
        .expect("frames");
    assert!((135..=145).contains(&top), "highest hand at frame {top}");
    assert!(hand[150].y > 1.7 && hand[100].y < 1.7);

    let forced = ImportOptions {
        position_reading: kinergy::motion::PositionReadingChoice::Replace,
        ..Default::default()
    };
    let (absolute, _) = read_clip(&fixture("006_14.bvh"), &forced).expect("read");
    assert!(lowest_point(&absolute, 0) < -0.8);
}

#[test]
fn bandai_non_root_channels_replace_their_offsets() {
    for (name, frames) in [
        ("dataset-1_guide_normal_001.bvh", 86),
        ("dataset-1_bye_normal_001.bvh", 111),
    ] {
        let Some(path) = shared(name) else { return };
        let (clip, report) = read_clip(&path, &ImportOptions::default()).expect("read");
        assert_eq!(clip.frame_count(), frames);
        assert_eq!(report.unit, LengthUnit::Centimeter);
        assert!(
            report
                .position_readings
                .iter()
                .skip(2)
                .all(|(_, r)| *r == PositionReading::ReplaceOffset),
            "non-root joints carry their OFFSET in their channels"
        );
        let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("right arm");
        assert_eq!(
            &arm.names(clip.skeleton())[..4],
            ["Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R"]
        );
        let l = arm.lengths(&clip).expect("lengths");
        assert_relative_eq!(l.upper_arm, 0.243, max_relative = 0.01);
        assert_relative_eq!(l.forearm, 0.223, max_relative = 0.01);
        assert!(lowest_point(&clip, 0).abs() < 0.1);
    }
}

#[test]
fn bandai_guide_reach_peaks_where_the_readme_says() {
    let Some(path) = shared("dataset-1_guide_normal_001.bvh") else {
        return;
    };
    let (clip, _) = read_clip(&path, &ImportOptions::default()).expect("read");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let speed = clip
        .trajectory(&[arm.end_effector()])
        .expect("trajectory")
        .speed(0);
    // README: reach 5–21–77 (start–peak–end of the hand's excursion); the hand is fastest on
    // the way out, between start and peak.
    let (fastest, _) = speed
        .iter()
        .enumerate()
        .take(40)
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("frames");
    assert!((5..=21).contains(&fastest), "fastest at {fastest}");
}

#[test]
fn round_trip_keeps_world_positions_on_every_fixture() {
    let mut files = vec![fixture("cmu_12_01_walk.bvh"), fixture("006_14.bvh")];
    files.extend(shared("dataset-1_guide_normal_001.bvh"));
    let dir = tempfile::tempdir().expect("tempdir");
    for path in files {
        let (clip, report) = read_clip(&path, &ImportOptions::default()).expect("read");
        for unit in [LengthUnit::Centimeter, LengthUnit::Meter, report.unit] {
            let out = dir.path().join("out.bvh");
            kinergy::motion::write_clip(
                &out,
                &clip,
                &ExportOptions {
                    unit,
                    ..Default::default()
                },
            )
            .expect("write");
            let options = ImportOptions {
                unit: UnitChoice::Fixed(unit),
                ..Default::default()
            };
            let (back, _) = read_clip(&out, &options).expect("read back");
            assert_eq!(back.frame_count(), clip.frame_count());
            let all: Vec<usize> = (0..clip.skeleton().joint_count()).collect();
            let a = clip.trajectory(&all).expect("trajectory");
            let b = back.trajectory(&all).expect("trajectory");
            let d = motion_distance(&a, &b).expect("distance");
            assert!(
                d < 1e-12,
                "{}: round trip in {unit} moved joints by {d} m",
                path.display()
            );
        }
        // In the file's own unit the written values equal the read ones, except the root's
        // position channels: written so that they replace the OFFSET (Blender's reading), they
        // hold the root OFFSET too, and the root OFFSET is written as zero.
        let bvh = kinergy::bvh::read_file(&path, &Default::default()).expect("bvh");
        let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let out = clip_to_bvh(
            &clip,
            &ExportOptions {
                unit: report.unit,
                ..Default::default()
            },
        );
        let channels = bvh.channel_count();
        let root = &bvh.joints[0];
        let root_position = |c: usize| {
            c >= root.first_channel
                && c < root.first_channel + root.channels.len()
                && root.channels[c - root.first_channel].is_position()
        };
        assert!(
            !root.channels.iter().any(|c| c.is_position()) || out.joints[0].offset == [0.0; 3],
            "{}: the root's OFFSET is written as zero when it has position channels",
            path.display()
        );
        for (i, (x, y)) in bvh.motion.iter().zip(&out.motion).enumerate() {
            if root_position(i % channels) {
                continue;
            }
            assert_relative_eq!(x, y, epsilon = 1e-9, max_relative = 1e-12);
        }
    }
}

fn cmu_walk() -> &'static kinergy::motion::Clip {
    static CLIP: std::sync::OnceLock<kinergy::motion::Clip> = std::sync::OnceLock::new();
    CLIP.get_or_init(|| {
        read_clip(&fixture("cmu_12_01_walk.bvh"), &ImportOptions::default())
            .expect("read")
            .0
    })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

    /// The positional Jacobian of any joint or End Site of the real 31-joint CMU skeleton,
    /// w.r.t. the DoFs of its chain from the root, equals central finite differences at
    /// captured poses perturbed at random.
    #[test]
    fn cmu_jacobian_matches_finite_differences(
        frame in 1usize..524,
        target in 0usize..38,
        noise in proptest::collection::vec(-0.3f64..0.3, 96),
    ) {
        let clip = cmu_walk();
        let s = clip.skeleton();
        let pose: Vec<f64> = clip.frame(frame).expect("frame").iter().zip(&noise).map(|(v, n)| v + n).collect();
        let dofs = s.path_dofs(0, target).expect("path from the root");
        let jac = s.jacobian(&pose, target, &dofs).expect("jacobian");
        let h = 1e-6;
        for (col, &d) in dofs.iter().enumerate() {
            let mut plus = pose.clone();
            let mut minus = pose.clone();
            plus[d] += h;
            minus[d] -= h;
            let fd = (s.world_positions(&plus).expect("fk")[target] - s.world_positions(&minus).expect("fk")[target]) / (2.0 * h);
            approx::assert_relative_eq!(jac.column(col).into_owned(), fd, epsilon = 1e-7);
        }
    }
}
