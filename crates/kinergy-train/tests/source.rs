//! One path from a capture file to its reaches: the arm, the frames (a window, the labelled
//! segments, a segments-file row), the frame choice of a single reach, and errors that say at
//! which step a clip failed.

use std::path::{Path, PathBuf};

use kinergy_motion::segment::{SegmentSettings, Selection, find_segments, main_index};
use kinergy_motion::{ArmJoints, ImportOptions, MotionError, Side};
use kinergy_solver::BaseMode;
use kinergy_train::TrainError;
use kinergy_train::segments_file::SegmentsFile;
use kinergy_train::source::{
    ArmChoice, Capture, FrameChoice, ReachFrames, names_clip, segment_clips, segment_reaches,
};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/006_14.bvh")
}

fn capture() -> Capture {
    Capture::read(&fixture(), &ImportOptions::default()).expect("fixture")
}

#[test]
fn a_window_and_the_main_segment_give_the_reaches_of_the_clip() {
    let capture = capture();
    let arm = ArmChoice::side(Side::Right);
    let window = capture
        .reaches(&arm, &ReachFrames::Window(10..60), BaseMode::Replay)
        .expect("window");
    assert_eq!(window.len(), 1);
    assert_eq!(window[0].frames(), 10..60);
    assert_eq!(window[0].name(), fixture().display().to_string());

    let joints = ArmJoints::find(capture.clip().skeleton(), Side::Right).expect("arm");
    let segments =
        find_segments(capture.clip(), &joints, &SegmentSettings::default()).expect("segments");
    let main = segments[main_index(&segments).expect("a main reach")].frames();
    let reaches = capture
        .reaches(
            &arm,
            &ReachFrames::Segments(Selection::Main),
            BaseMode::Replay,
        )
        .expect("main");
    assert_eq!(reaches[0].frames(), main);
    // The frame choice of a single reach agrees.
    let single = capture
        .reach(&joints, &FrameChoice::Main, None, BaseMode::Replay)
        .expect("main");
    assert_eq!(single.frames(), main);
}

#[test]
fn frame_choices_resolve_and_refuse_windows_outside_the_clip() {
    let capture = capture();
    let clip = capture.clip();
    let n = clip.frame_count();
    let joints = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let resolve = |choice: FrameChoice| choice.resolve(clip, capture.path(), &joints, None);
    // Without a fit record, `Fitted` is every frame.
    assert_eq!(resolve(FrameChoice::Fitted).expect("fitted"), 0..n);
    assert_eq!(resolve(FrameChoice::All).expect("all"), 0..n);
    assert_eq!(resolve(FrameChoice::Window(3..9)).expect("window"), 3..9);
    for bad in [n - 1..n + 4, 5..6] {
        match resolve(FrameChoice::Window(bad.clone())) {
            Err(TrainError::Frames {
                frames, available, ..
            }) => assert_eq!((frames, available), (bad, n)),
            other => panic!("{bad:?}: {other:?}"),
        }
    }
    assert!(matches!(
        resolve(FrameChoice::Nth(10_000)),
        Err(TrainError::Motion(MotionError::Reach { .. }))
    ));
    assert!(names_clip(
        &capture.path().display().to_string(),
        capture.path()
    ));
    assert!(!names_clip("elsewhere.bvh", capture.path()));
}

#[test]
fn an_arm_not_there_says_whether_the_other_side_has_one() {
    let capture = capture();
    let named = ArmChoice {
        side: Side::Left,
        joints: Some(vec!["nope".into(), "elbow".into(), "wrist".into()]),
    };
    match named.find(capture.clip(), capture.path()) {
        Err(TrainError::Arm {
            other_side: None, ..
        }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn segments_file_rows_are_read_once_per_clip_with_their_targets() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = dir.path().join("take.bvh");
    std::fs::copy(fixture(), &clip).expect("copy");
    let path = dir.path().join("segments.csv");
    std::fs::write(
        &path,
        "clip,onset,end,arm,target_x,target_y,target_z\n\
         take.bvh,0,40,right,,,\n\
         take.bvh,40,90,right,0.1,1.2,0.3\n",
    )
    .expect("write");
    let file = SegmentsFile::read(&path).expect("segments");
    let clips = segment_clips(&file);
    assert_eq!(clips.len(), 1);
    let reaches = segment_reaches(&file, &clips, &ImportOptions::default(), BaseMode::Replay)
        .expect("reaches");
    assert_eq!(reaches.len(), 2);
    assert_eq!(reaches[0].0.frames(), 0..40);
    assert_eq!(reaches[1].0.frames(), 40..90);
    let t = reaches[1].0.target();
    assert_eq!([t.x, t.y, t.z], [0.1, 1.2, 0.3]);
    assert_eq!(reaches[1].1.line, Some(3));

    // A clip no row names gives nothing; none at all is an error naming the file.
    let other = dir.path().join("other.bvh");
    std::fs::copy(fixture(), &other).expect("copy");
    match segment_reaches(&file, &[other], &ImportOptions::default(), BaseMode::Replay) {
        Err(e @ TrainError::NoRows { .. }) => {
            assert!(e.to_string().contains("segments.csv"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}
