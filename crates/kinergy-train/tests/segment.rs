//! Reach segmentation against independent truths: synthetic clips whose hand follows
//! minimum-jerk movements of known onset, end and direction; reference windows labelled by
//! hand on real captures (`tests/data/reach_labels.csv`, which says how); the committed
//! synthetic set, whose every clip is one reach to the hand's final position.
//!
//! The Bandai Namco captures (CC BY-NC) are read from `../shared/data/` and skipped, saying so,
//! where they are absent; they are never committed.

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinergy_motion::nalgebra::Vector3;
use kinergy_motion::rotation::Axis;
use kinergy_motion::segment::{
    Label, Segment, SegmentSettings, Selection, find_segments, hand_speed, main_index, main_segment,
};
use kinergy_motion::{
    ArmJoints, Clip, Dof, ImportOptions, Joint, MotionError, PositionReading, Side, Skeleton,
    read_clip,
};
use kinergy_train::source::Capture;

const FRAME_TIME: f64 = 1.0 / 60.0;

/// Hips (root, translating) → Spine → RightShoulder → RightArm → RightForeArm → RightHand
/// (translating, so the hand can follow any path relative to the shoulder) → End Site. At
/// rest the arm points along −X, 0.63 m from the shoulder (RightArm) to the hand point.
fn skeleton() -> Arc<Skeleton> {
    let translation = vec![
        Dof::Translation(Axis::X),
        Dof::Translation(Axis::Y),
        Dof::Translation(Axis::Z),
    ];
    let joint = |name: &str, parent: Option<usize>, offset: [f64; 3], dofs: Vec<Dof>| Joint {
        name: name.into(),
        parent,
        offset: Vector3::from(offset),
        end_site: name.ends_with("_End"),
        dofs,
        position_reading: PositionReading::AddToOffset,
    };
    Arc::new(
        Skeleton::new(vec![
            joint("Hips", None, [0.0, 1.0, 0.0], translation.clone()),
            joint("Spine", Some(0), [0.0, 0.3, 0.0], vec![]),
            joint("RightShoulder", Some(1), [-0.05, 0.2, 0.0], vec![]),
            joint("RightArm", Some(2), [-0.15, 0.0, 0.0], vec![]),
            joint("RightForeArm", Some(3), [-0.28, 0.0, 0.0], vec![]),
            joint("RightHand", Some(4), [-0.26, 0.0, 0.0], translation),
            joint("RightHand_End", Some(5), [-0.09, 0.0, 0.0], vec![]),
        ])
        .expect("valid skeleton"),
    )
}

/// The minimum-jerk position profile 10τ³ − 15τ⁴ + 6τ⁵ (0 before τ = 0, 1 after τ = 1).
fn min_jerk(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// A movement of `d` from frame `start` over `frames` frames.
#[derive(Clone, Copy)]
struct Move {
    start: usize,
    frames: usize,
    d: Vector3<f64>,
}

impl Move {
    fn at(&self, i: usize) -> Vector3<f64> {
        self.d * min_jerk((i as f64 - self.start as f64) / self.frames as f64)
    }
    fn end(&self) -> usize {
        self.start + self.frames
    }
    fn peak(&self) -> usize {
        self.start + self.frames / 2
    }
}

/// A clip of `frames` frames: the root follows `body` moves, the hand (relative to the
/// shoulder) follows `hand` moves plus `extra(i)`.
fn clip_with(
    frames: usize,
    body: &[Move],
    hand: &[Move],
    extra: impl Fn(usize) -> Vector3<f64>,
) -> Clip {
    let sum = |moves: &[Move], i: usize| moves.iter().map(|m| m.at(i)).sum::<Vector3<f64>>();
    let values = (0..frames)
        .flat_map(|i| {
            let (b, h) = (sum(body, i), sum(hand, i) + extra(i));
            [b.x, b.y, b.z, h.x, h.y, h.z]
        })
        .collect();
    Clip::new(skeleton(), FRAME_TIME, values).expect("valid clip")
}

fn clip(frames: usize, body: &[Move], hand: &[Move]) -> Clip {
    clip_with(frames, body, hand, |_| Vector3::zeros())
}

fn right_arm(clip: &Clip) -> ArmJoints {
    ArmJoints::find(clip.skeleton(), Side::Right).expect("right arm")
}

fn segments(c: &Clip) -> Vec<Segment> {
    let found = find_segments(c, &right_arm(c), &SegmentSettings::default()).expect("segments");
    assert_well_formed(&found, c.frame_count());
    found
}

fn labels(found: &[Segment]) -> Vec<Label> {
    found.iter().map(|s| s.label).collect()
}

/// Segments lie inside the clip, in time order, without sharing a frame; each peak is inside
/// its segment.
fn assert_well_formed(found: &[Segment], frames: usize) {
    for (i, s) in found.iter().enumerate() {
        assert!(
            s.onset < s.end && s.end <= frames && s.frames().contains(&s.peak),
            "{s:?}"
        );
        if i > 0 {
            assert!(s.onset >= found[i - 1].end, "overlap: {found:?}");
        }
    }
}

/// The fraction τ* of a minimum-jerk movement at which its speed, 30τ²(1 − τ)² times the
/// mean, first reaches `fraction` of its peak (1.875 times the mean): 16τ²(1 − τ)² = fraction.
fn crossing(fraction: f64) -> f64 {
    (1.0 - (1.0 - fraction.sqrt()).sqrt()) / 2.0
}

fn assert_near(what: &str, got: usize, want: f64, tolerance: f64) {
    assert!(
        (got as f64 - want).abs() <= tolerance,
        "{what}: frame {got}, expected {want:.1} ± {tolerance}"
    );
}

/// Checks that `s` detects `m`: onset and end where the speed crosses the absolute rest
/// speed (the motion's onset and end follow the speed down to it; within 2 frames; `end` is
/// one past that frame), peak at the midpoint (within 1), and the displacement.
fn assert_detects(s: &Segment, m: &Move, settings: &SegmentSettings) {
    let vmax = 1.875 * m.d.norm() / (m.frames as f64 * FRAME_TIME);
    let lag = crossing(settings.rest_speed / vmax) * m.frames as f64;
    assert_near("onset", s.onset, m.start as f64 + lag, 2.0);
    assert_near("end", s.end - 1, m.end() as f64 - lag, 2.0);
    assert_near("peak", s.peak, m.peak() as f64, 1.0);
    assert!(
        (s.peak_speed - vmax).abs() < 0.05 * vmax,
        "peak speed {} vs {vmax}",
        s.peak_speed
    );
    assert!(
        (s.displacement - m.d.norm()).abs() < 0.01,
        "displacement {} vs {}",
        s.displacement,
        m.d.norm()
    );
}

const REACH: Move = Move {
    start: 30,
    frames: 48,
    d: Vector3::new(0.3, 0.2, -0.1),
};

// Truth 1: a minimum-jerk reach between rests; with a tight rest threshold the onset and
// the end are the true ones, with the default one they are where the analytic speed crosses
// the rest speed. It is a reach, the main one, not truncated.
#[test]
fn a_minimum_jerk_reach_is_found_where_it_is() {
    let c = clip(110, &[], &[REACH]);
    let arm = right_arm(&c);
    let tight = SegmentSettings {
        rest_fraction: 0.01,
        rest_speed: 0.001,
        ..SegmentSettings::default()
    };
    let found = find_segments(&c, &arm, &tight).expect("segments");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_near("onset", found[0].onset, REACH.start as f64, 2.0);
    assert_near("end", found[0].end - 1, REACH.end() as f64, 2.0);
    assert_detects(&found[0], &REACH, &tight);

    let defaults = SegmentSettings::default();
    let found = segments(&c);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_detects(&found[0], &REACH, &defaults);
    assert_eq!(found[0].label, Label::Reach);
    assert!(!found[0].truncated(), "{:?}", found[0]);
    assert_eq!(
        main_segment(&c, &arm, &defaults, "synthetic").expect("main"),
        found[0]
    );
    eprintln!("one reach (true 30–54–78): {found:?}");

    let speed = hand_speed(&c, &arm, &defaults).expect("speed");
    assert_eq!(speed.len(), c.frame_count());
}

// Truth 2: a reach out, a rest, a longer reach elsewhere (not back toward the first one's
// start): two reaches in time order, the main one the longer.
#[test]
fn two_reaches_apart_are_two_segments_in_order() {
    let elsewhere = Move {
        start: 110,
        frames: 40,
        d: Vector3::new(-0.1, 0.4, 0.3),
    };
    let c = clip(180, &[], &[REACH, elsewhere]);
    let settings = SegmentSettings::default();
    let found = segments(&c);
    eprintln!("two reaches (true 30–54–78, 110–130–150): {found:?}");
    assert_eq!(labels(&found), [Label::Reach, Label::Reach], "{found:?}");
    assert_detects(&found[0], &REACH, &settings);
    assert_detects(&found[1], &elsewhere, &settings);
    assert_eq!(main_index(&found), Some(1));
}

// Truth 3: nothing moves, or there is nothing: no segment, and the main segment is an error
// that names the clip.
#[test]
fn a_clip_at_rest_has_no_reach() {
    let settings = SegmentSettings::default();
    for frames in [0, 1, 2, 100] {
        let c = clip(frames, &[], &[]);
        let arm = right_arm(&c);
        assert_eq!(find_segments(&c, &arm, &settings).expect("segments"), []);
        match main_segment(&c, &arm, &settings, "still.bvh") {
            Err(e @ MotionError::Reach { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.starts_with("still.bvh: ") && msg.contains("0.2 m/s"),
                    "{msg}"
                );
            }
            other => panic!("{frames} frames: {other:?}"),
        }
    }
    // A reach too slow (peak 0.1 m/s) is no reach either.
    let slow = Move {
        d: REACH.d.normalize() * 0.1 * REACH.frames as f64 * FRAME_TIME / 1.875,
        ..REACH
    };
    let c = clip(110, &[], &[slow]);
    assert_eq!(segments(&c), []);
}

// Truth 4: the whole body translating with the arm still is a reach of the world hand but
// not of the hand relative to the shoulder.
#[test]
fn walking_is_not_reaching_relative_to_the_shoulder() {
    let walk = Move {
        start: 20,
        frames: 60,
        d: Vector3::new(0.0, 0.0, 1.0),
    };
    let c = clip(100, &[walk], &[]);
    let arm = right_arm(&c);
    let relative = SegmentSettings::default();
    assert_eq!(find_segments(&c, &arm, &relative).expect("segments"), []);
    let world = SegmentSettings {
        relative_to_shoulder: false,
        ..relative
    };
    let found = find_segments(&c, &arm, &world).expect("segments");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_detects(&found[0], &walk, &world);
    // And a reach while walking is found, unchanged, relative to the shoulder.
    let c = clip(110, &[walk], &[REACH]);
    let found = segments(&c);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_detects(&found[0], &REACH, &relative);
    assert_eq!(found[0].label, Label::Reach);
}

// Truth 5: the trunk carrying the hand down while the arm reaches 10 cm forward (the body goes
// 0.5 m down in 0.8 s, holds, comes back up as the arm draws back): relative to the shoulder
// the arm moves too little for a reach, but the hand goes down to where it is held and back.
// The way down is a reach and the way up its return, found where they are in the world (the
// sum of the two minimum-jerk movements), and read in the world.
#[test]
fn a_stoop_is_a_reach_down_and_the_way_up_its_return() {
    let (start, back) = (20, 120);
    let body = |start, d| Move {
        start,
        frames: 48,
        d,
    };
    let (down, up) = (
        body(start, Vector3::new(0.0, -0.5, 0.0)),
        body(back, Vector3::new(0.0, 0.5, 0.0)),
    );
    let (out, home) = (
        body(start, Vector3::new(0.0, 0.0, 0.1)),
        body(back, Vector3::new(0.0, 0.0, -0.1)),
    );
    let c = clip(200, &[down, up], &[out, home]);
    let found = segments(&c);
    assert_eq!(labels(&found), [Label::Reach, Label::Return], "{found:?}");
    let world = SegmentSettings {
        relative_to_shoulder: false,
        ..SegmentSettings::default()
    };
    assert_detects(&found[0], &body(start, down.d + out.d), &world);
    assert_detects(&found[1], &body(back, up.d + home.d), &world);
    assert!(found.iter().all(|s| s.from_world), "{found:?}");
    assert_eq!(main_index(&found), Some(0));
    // With --world, the same segments.
    let in_world = find_segments(&c, &right_arm(&c), &world).expect("segments");
    assert_eq!(in_world.len(), 2, "{in_world:?}");
    for (a, b) in found.iter().zip(&in_world) {
        assert_eq!((a.onset, a.end, a.label), (b.onset, b.end, b.label));
        assert!(!b.from_world);
    }
    // An arm that does not move at all is a hand the body carries, not one that reaches (the
    // idle hand of a one-hand pick-up): relative to the shoulder, nothing.
    let idle = clip(200, &[down, up], &[]);
    assert_eq!(segments(&idle), []);
    let in_world = find_segments(&idle, &right_arm(&idle), &world).expect("segments");
    assert_eq!(labels(&in_world), [Label::Reach, Label::Return]);
}

// Truth 6: walking 2 m while the arm comes halfway down to the side from where it was held out.
// Relative to the shoulder that is the arm going back toward its rest; in the world the hand
// goes 2 m and is held: a reach, but one the walk makes, so relative to the shoulder there is
// still no reach.
#[test]
fn lowering_the_arm_while_walking_is_no_reach() {
    let walk = Move {
        start: 10,
        frames: 120,
        d: Vector3::new(0.0, 0.0, 2.0),
    };
    // At rest the hand is 0.63 m out along −X; hanging, 0.63 m below the shoulder.
    let lower = Move {
        start: 20,
        frames: 100,
        d: 0.6 * Vector3::new(0.63, -0.63, 0.0),
    };
    let c = clip(160, &[walk], &[lower]);
    let found = segments(&c);
    assert!(
        !found.is_empty() && found.iter().all(|s| s.label != Label::Reach),
        "{found:?}"
    );
    let world = SegmentSettings {
        relative_to_shoulder: false,
        ..SegmentSettings::default()
    };
    let in_world = find_segments(&c, &right_arm(&c), &world).expect("segments");
    assert!(
        in_world.iter().any(|s| s.label == Label::Reach),
        "{in_world:?}"
    );
}

/// REACH, a hold, and the way back, 10% past the start so the return moves farther than the
/// reach.
fn reach_and_return() -> (Clip, Move) {
    let back = Move {
        start: 110,
        frames: 50,
        d: -1.1 * REACH.d,
    };
    (clip(190, &[], &[REACH, back]), back)
}

// Labels 1: a reach, a hold, the return: reach then return, and the main reach is the
// reach although the return moves the hand farther (a rule taking the largest move would pick
// the return).
#[test]
fn a_reach_then_its_return() {
    let (c, back) = reach_and_return();
    let found = segments(&c);
    eprintln!("reach, return: {found:?}");
    assert_eq!(labels(&found), [Label::Reach, Label::Return], "{found:?}");
    assert!(found[1].displacement > found[0].displacement);
    assert_detects(&found[1], &back, &SegmentSettings::default());
    assert_eq!(main_index(&found), Some(0));
    // With no reach before it, lowering the arm toward where it hangs is a return too.
    let lower = Move {
        start: 20,
        frames: 50,
        d: Vector3::new(0.5, -0.55, 0.05),
    };
    let found = segments(&clip(100, &[], &[lower]));
    assert_eq!(labels(&found), [Label::Return], "{found:?}");
    assert_eq!(main_index(&found), None);
}

// Labels 2: a raise, then at once a wave in place (±2 cm, 3 Hz, 1.3 s), then the arm down: a
// reach that ends where the wave begins, the wave as other, the lowering a return.
#[test]
fn a_reach_then_a_wave() {
    let raise = Move {
        start: 20,
        frames: 40,
        d: Vector3::new(0.35, 0.3, 0.0),
    };
    let lower = Move {
        start: 160,
        frames: 40,
        d: -raise.d,
    };
    // Four turns of a small ellipse, as a waving hand draws: it never quite stops.
    let wave = |i: usize| {
        let t = (i as f64 - 62.0) * FRAME_TIME;
        let w = 6.0 * std::f64::consts::PI * t;
        if (0.0..4.0 / 3.0).contains(&t) {
            Vector3::new(0.01 * (w.cos() - 1.0), 0.0, 0.02 * w.sin())
        } else {
            Vector3::zeros()
        }
    };
    let c = clip_with(220, &[], &[raise, lower], wave);
    let found = segments(&c);
    eprintln!("raise, wave, lower: {found:?}");
    assert_eq!(
        labels(&found),
        [Label::Reach, Label::Other, Label::Return],
        "{found:?}"
    );
    assert_detects(&found[0], &raise, &SegmentSettings::default());
    assert!(found[1].onset >= 58 && found[1].end <= 155, "{found:?}");
    assert_eq!(main_index(&found), Some(0));
}

/// The hand swinging fore and aft, ±`amplitude` m at `hz`, from `phase` (radians).
fn swing(amplitude: f64, hz: f64, phase: f64) -> impl Fn(usize) -> Vector3<f64> {
    move |i| {
        let t = i as f64 * FRAME_TIME;
        Vector3::new(
            0.0,
            0.0,
            amplitude * (2.0 * std::f64::consts::PI * hz * t + phase).sin(),
        )
    }
}

// Labels 3: the arm swing of walking (the body walks; the hand swings ±12 cm at 0.9 Hz
// relative to the shoulder), starting mid-swing: no reach, only other.
#[test]
fn a_walking_swing_is_no_reach() {
    let walk = Move {
        start: 0,
        frames: 300,
        d: Vector3::new(0.0, 0.0, 4.0),
    };
    for phase in [0.0, 1.0, 2.5] {
        let c = clip_with(300, &[walk], &[], swing(0.12, 0.9, phase));
        let found = segments(&c);
        eprintln!("swing from phase {phase}: {found:?}");
        assert!(!found.is_empty());
        assert!(found.iter().all(|s| s.label == Label::Other), "{found:?}");
        assert!(main_segment(&c, &right_arm(&c), &SegmentSettings::default(), "walk").is_err());
    }
}

// Labels 4: clips cut inside a movement. Starting mid-reach: a reach truncated at the start,
// still the main one. Ending mid-reach: a reach truncated at the end, the main one only for
// want of a whole one. Ending mid-return: a return truncated at the end.
#[test]
fn truncated_segments_are_flagged() {
    let (whole, _) = reach_and_return();
    let late_start = whole.slice(45..190).expect("slice");
    let found = segments(&late_start);
    assert_eq!(labels(&found), [Label::Reach, Label::Return], "{found:?}");
    assert!(
        found[0].truncated_start && !found[0].truncated_end,
        "{found:?}"
    );
    assert_eq!(found[0].onset, 0);
    assert_eq!(main_index(&found), Some(0));

    let early_end = whole.slice(0..62).expect("slice");
    let found = segments(&early_end);
    assert_eq!(labels(&found), [Label::Reach], "{found:?}");
    assert!(
        found[0].truncated_end && !found[0].truncated_start,
        "{found:?}"
    );
    assert_eq!(found[0].end, 62);
    assert_eq!(main_index(&found), Some(0));

    let mid_return = whole.slice(0..138).expect("slice");
    let found = segments(&mid_return);
    assert_eq!(labels(&found), [Label::Reach, Label::Return], "{found:?}");
    assert!(found[1].truncated_end && !found[0].truncated(), "{found:?}");
    assert_eq!(main_index(&found), Some(0));
}

/// `c` with `offset` added to the hand's translation channels on frame `at`: the hand
/// teleports for one frame.
fn teleport(c: &Clip, at: usize, offset: Vector3<f64>) -> Clip {
    let mut values = c.values().to_vec();
    let hand = c
        .skeleton()
        .joint_index("RightHand")
        .expect("RightHand joint");
    let dofs = c.skeleton().dof_range(hand);
    let row = at * c.skeleton().dof_count();
    for (k, v) in dofs.zip(offset.iter()) {
        values[row + k] += v;
    }
    Clip::new(c.skeleton().clone(), c.frame_time(), values).expect("clip")
}

/// The same segments, up to where a speed peak falls and how fast it is (the median moves a
/// glitched frame onto a neighbour, which changes the speed by a hair mid-motion).
fn assert_same_segments(got: &[Segment], want: &[Segment], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(
            (g.onset, g.end, g.label, g.truncated_start, g.truncated_end),
            (w.onset, w.end, w.label, w.truncated_start, w.truncated_end),
            "{what}"
        );
        assert!(g.peak.abs_diff(w.peak) <= 1, "{what}: {g:?} vs {w:?}");
        assert!((g.displacement - w.displacement).abs() < 1e-3, "{what}");
    }
}

// Glitches: a joint teleporting 22 cm for one frame — in a rest, mid-reach, in the hold,
// mid-return, on the first and the last frame — changes no segment.
#[test]
fn a_one_frame_glitch_changes_no_segment() {
    let (c, _) = reach_and_return();
    let clean = segments(&c);
    let jump: Vector3<f64> = Vector3::new(0.13, -0.15, 0.09); // 22 cm
    assert!((jump.norm() - 0.22).abs() < 0.01);
    for at in [0, 12, 50, 95, 135, c.frame_count() - 1] {
        let glitched = teleport(&c, at, jump);
        assert_same_segments(&segments(&glitched), &clean, &format!("glitch at {at}"));
        // Without the median the glitch is a 13 m/s peak; with it, the speed barely moves.
        let arm = right_arm(&c);
        let settings = SegmentSettings::default();
        let fastest = |c: &Clip| {
            hand_speed(c, &arm, &settings)
                .expect("speed")
                .into_iter()
                .fold(0.0, f64::max)
        };
        assert!(
            (fastest(&glitched) - fastest(&c)).abs() < 0.05,
            "glitch at {at}"
        );
    }
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// A Bandai Namco capture from `../shared/data/`, or `None` (with a notice) where it is absent.
fn shared(name: &str) -> Option<PathBuf> {
    let root = repo("../shared/data");
    let found = ["bandai-raise-left", "real-bvh", "formats"]
        .iter()
        .map(|set| root.join(set).join(name))
        .find(|p| p.exists());
    if found.is_none() {
        require_shared::shared_absent(&format!(
            "skipping {name}: not in {}/{{bandai-raise-left,real-bvh,formats}} (the Bandai \
             Namco captures are never committed)",
            root.display()
        ));
    }
    found
}

fn read(path: &Path) -> Clip {
    read_clip(path, &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// Prints the segments of one arm of a clip and returns them.
fn report(c: &Clip, name: &str, side: Side, settings: &SegmentSettings) -> Vec<Segment> {
    let arm = ArmJoints::find(c.skeleton(), side).expect("arm");
    let found = find_segments(c, &arm, settings).expect("segments");
    assert_well_formed(&found, c.frame_count());
    let main = main_index(&found);
    eprintln!(
        "{name} {side} ({} frames at {:.0} Hz, relative: {}):",
        c.frame_count(),
        c.frame_rate(),
        settings.relative_to_shoulder
    );
    for (i, s) in found.iter().enumerate() {
        eprintln!(
            "  #{i} {:>3}..{:<3} peak {:>3} {:<6} {:.2} m, {:.2} m/s{}{}{}",
            s.onset,
            s.end,
            s.peak,
            s.label,
            s.displacement,
            s.peak_speed,
            if s.truncated_start {
                ", cut at start"
            } else {
                ""
            },
            if s.truncated_end { ", cut at end" } else { "" },
            if main == Some(i) { "  ← main" } else { "" }
        );
    }
    found
}

/// One row of `tests/data/reach_labels.csv`.
struct Reference {
    clip: String,
    arm: Side,
    onset: usize,
    end: usize,
}

fn references() -> Vec<Reference> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reach_labels.csv");
    let text = std::fs::read_to_string(&path).expect("reach_labels.csv");
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty());
    assert_eq!(lines.next(), Some("clip,arm,onset,end,note"));
    lines
        .map(|l| {
            let cells: Vec<&str> = l.splitn(5, ',').collect();
            Reference {
                clip: cells[0].to_string(),
                arm: cells[1].parse().expect("arm"),
                onset: cells[2].parse().expect("onset"),
                end: cells[3].parse().expect("end"),
            }
        })
        .collect()
}

// Real captures: on the 24 raise-left takes and the guide and bye gestures the main segment
// is the outward reach, its onset within 3 frames and its end within 5 frames of the
// windows labelled by hand.
#[test]
fn the_main_reach_is_the_labelled_one() {
    let references = references();
    assert_eq!(references.len(), 26);
    let settings = SegmentSettings::default();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for r in &references {
        let Some(path) = shared(&r.clip) else {
            continue;
        };
        let c = read(&path);
        let found = report(&c, &r.clip, r.arm, &settings);
        let arm = ArmJoints::find(c.skeleton(), r.arm).expect("arm");
        let main = main_segment(&c, &arm, &settings, &r.clip).expect("main");
        eprintln!(
            "  main {}..{} vs labelled {}..{}",
            main.onset, main.end, r.onset, r.end
        );
        checked += 1;
        if main.label != Label::Reach
            || main.onset.abs_diff(r.onset) > 3
            || main.end.abs_diff(r.end) > 5
        {
            wrong.push(format!(
                "{}: main {:?} {}..{} vs labelled {}..{}",
                r.clip, main.label, main.onset, main.end, r.onset, r.end
            ));
        }
        // And the rest of the clip: a raise-hand take or the guide gesture is the reach and
        // its return; the bye gesture waves in between.
        let want: &[Label] = if r.clip.contains("bye") {
            &[Label::Reach, Label::Other, Label::Return]
        } else {
            &[Label::Reach, Label::Return]
        };
        if labels(&found) != want {
            wrong.push(format!(
                "{}: labels {:?}, expected {want:?}",
                r.clip,
                labels(&found)
            ));
        }
    }
    eprintln!("{checked} of {} labelled clips checked", references.len());
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

// Raising a hand is the arm's own movement: on the 24 Bandai raise-left takes, neither arm
// has a segment read in the world (step 7 takes nothing: the shoulder barely rises or falls,
// and the relative reading has the reach; the idle right arm's small moves as the body sways
// stay small).
#[test]
fn raises_take_nothing_from_the_world() {
    let mut checked = 0;
    for r in references()
        .iter()
        .filter(|r| !r.clip.starts_with("dataset"))
    {
        let Some(path) = shared(&r.clip) else {
            continue;
        };
        let c = read(&path);
        for side in [Side::Right, Side::Left] {
            let arm = ArmJoints::find(c.skeleton(), side).expect("arm");
            let found = find_segments(&c, &arm, &SegmentSettings::default()).expect("segments");
            assert!(
                found.iter().all(|s| !s.from_world),
                "{} {side}: {found:?}",
                r.clip
            );
        }
        checked += 1;
    }
    eprintln!("{checked} raise-left takes checked");
}

// cmu_12_01 is a straight walk with the arms swinging: relative to the shoulder there is no
// reach on either arm (the swing is other).
#[test]
fn walking_arm_swing_is_no_reach() {
    let c = read(&repo("tests/data/cmu_12_01_walk.bvh"));
    for side in [Side::Right, Side::Left] {
        let found = report(&c, "cmu_12_01_walk.bvh", side, &SegmentSettings::default());
        assert!(
            found.iter().all(|s| s.label == Label::Other),
            "{side}: {found:?}"
        );
        let arm = ArmJoints::find(c.skeleton(), side).expect("arm");
        assert!(main_segment(&c, &arm, &SegmentSettings::default(), "walk").is_err());
    }
}

// 006_14 (a crossover dribble, then a shot): the main reach is the shot, not the dribble.
// From /work/shared/data/real-bvh/README.md (measured there on hand height, not on speed):
// the right hand is above 1.7 m at frames 132–169 and the arm fully extended at 136–173. The
// main reach is whole, peaks (the release) in the first window, and its last frame is in it
// with the hand above 1.7 m; it starts after the dribble's push down (frames 0–41).
#[test]
fn the_main_reach_of_006_14_is_the_shot() {
    let c = read(&repo("tests/data/006_14.bvh"));
    let settings = SegmentSettings::default();
    let found = report(&c, "006_14.bvh", Side::Right, &settings);
    let arm = ArmJoints::find(c.skeleton(), Side::Right).expect("arm");
    let shot = main_segment(&c, &arm, &settings, "006_14.bvh").expect("main");
    eprintln!("  shot: {shot:?}");
    assert!(found.contains(&shot));
    assert!(!shot.truncated(), "{shot:?}");
    assert!((132..=169).contains(&shot.peak), "{shot:?}");
    assert!((132..=169).contains(&(shot.end - 1)), "{shot:?}");
    assert!(shot.onset > 41, "{shot:?}");
    let hand = c
        .trajectory(&[arm.end_effector()])
        .expect("trajectory")
        .path(0);
    assert!(
        hand[shot.end - 1].y > 1.7,
        "hand at {:?}",
        hand[shot.end - 1]
    );
    report(&c, "006_14.bvh", Side::Left, &settings);
}

// 006_14 is right-arm motion to its last frame; some segment ends where the hand ends (within
// 5 cm), flagged as running into the clip's end.
#[test]
fn some_segment_of_006_14_ends_where_the_hand_ends() {
    let c = read(&repo("tests/data/006_14.bvh"));
    let found = report(&c, "006_14.bvh", Side::Right, &SegmentSettings::default());
    let arm = ArmJoints::find(c.skeleton(), Side::Right).expect("arm");
    let hand = c
        .trajectory(&[arm.end_effector()])
        .expect("trajectory")
        .path(0);
    let last = found.last().expect("segments");
    assert_eq!(last.end, c.frame_count());
    assert!(last.truncated_end, "{last:?}");
    assert!((hand[last.end - 1] - hand[c.frame_count() - 1]).norm() < 0.05);
}

/// A committed fixture of this crate (`tests/data/`).
fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}

/// Where an arm's hand goes down in a pick-up, from the hand's and shoulder's world heights
/// alone: (the frame the bend starts — the shoulder first 2 cm below its height on frame 1,
/// frame 0 being a T-pose; the first frame the hand is within 1 cm of its lowest; its lowest
/// height; its height on frame 1).
fn way_down(c: &Clip, arm: &ArmJoints) -> (usize, usize, f64, f64) {
    let t = c
        .trajectory(&[arm.end_effector(), arm.shoulder])
        .expect("trajectory");
    let (hand, shoulder) = (t.path(0), t.path(1));
    let lowest = hand.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let bottom = (1..hand.len())
        .find(|&i| hand[i].y <= lowest + 0.01)
        .expect("a lowest frame");
    let bend = (1..shoulder.len())
        .find(|&i| shoulder[i].y < shoulder[1].y - 0.02)
        .expect("a bend");
    (bend, bottom, lowest, hand[1].y)
}

// CMU 26_10 and 26_11 (bend, pick something up from the floor with both hands, lift it): for
// each arm, relative to the shoulder and in the world, the main reach is the way down. It
// starts before the bend does (the arms move first) but less than 1 s before, with the hand
// still within 3 cm of its height on frame 1; it ends when the hand has got down: its last
// frame within 6 frames (0.2 s) after the hand first comes within 1 cm of its lowest, and
// still within 1 cm of it. The lift that follows is the reach's return (the relative reading
// called it a reach: the arm moves more relative to the shoulder lifting than stooping).
#[test]
fn a_pick_up_reaches_down_to_the_object_with_both_hands() {
    let mut wrong = Vec::new();
    for name in ["26_10.bvh", "26_11.bvh"] {
        let c = read(&fixture(&format!("cmu-lift/{name}")));
        let rate = c.frame_rate();
        for side in [Side::Right, Side::Left] {
            let arm = ArmJoints::find(c.skeleton(), side).expect("arm");
            let (bend, bottom, lowest, start) = way_down(&c, &arm);
            let hand = c
                .trajectory(&[arm.end_effector()])
                .expect("trajectory")
                .path(0);
            eprintln!("{name} {side}: bend from {bend}, hand down on {bottom} at {lowest:.3} m");
            for relative in [true, false] {
                let settings = SegmentSettings {
                    relative_to_shoulder: relative,
                    ..SegmentSettings::default()
                };
                let found = report(&c, name, side, &settings);
                let Some(i) = main_index(&found) else {
                    wrong.push(format!("{name} {side} relative {relative}: no main reach"));
                    continue;
                };
                let main = found[i];
                let last = main.end - 1;
                let ok = !main.truncated()
                    && main.onset <= bend
                    && (bend - main.onset) as f64 <= rate
                    && (hand[main.onset].y - start).abs() <= 0.03
                    && (bottom..=bottom + 6).contains(&last)
                    && hand[last].y <= lowest + 0.01
                    && found.get(i + 1).is_some_and(|s| s.label == Label::Return);
                if !ok {
                    wrong.push(format!(
                        "{name} {side} relative {relative}: main {}..{} (hand at {:.3} m on its                          last frame), bend from {bend}, hand down on {bottom}; after it {:?}",
                        main.onset,
                        main.end,
                        hand[last].y,
                        found.get(i + 1).map(|s| s.label)
                    ));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

// `--arm auto` on a both-hands pick-up: each arm's main reach is the way down and both count
// (each moves the hand at least half as far as the other), one reach per arm.
#[test]
fn arm_auto_takes_both_hands_of_a_pick_up() {
    for name in ["26_10.bvh", "26_11.bvh"] {
        let path = fixture(&format!("cmu-lift/{name}"));
        let c = read(&path);
        let capture = Capture::from_clip(&path, c.clone());
        let arms = capture
            .reaching_segments(Selection::Main, &SegmentSettings::default())
            .expect("reaching arms");
        let sides: Vec<_> = arms.iter().map(|(joints, _)| joints.side).collect();
        assert_eq!(sides, [Some(Side::Right), Some(Side::Left)], "{name}");
        for (joints, segments) in &arms {
            assert_eq!(segments.len(), 1, "{name}: {segments:?}");
            let (_, bottom, _, _) = way_down(&c, joints);
            assert!(
                (bottom..=bottom + 6).contains(&(segments[0].end - 1)),
                "{name} {:?}: {:?}, hand down on {bottom}",
                joints.side,
                segments[0]
            );
        }
    }
}

// The Mixamo walk (`../shared/data/formats/mixamo_walk.bvh`) turns as it goes, the left arm
// swinging wide: relative to the shoulder that arm does nothing but swing (other); in the
// world the hand comes to rest after a stretch of the walk, a reach the walk makes. The swing
// is not a reach the relative reading missed: still no reach relative to the shoulder.
#[test]
fn a_turning_walk_s_arm_swing_is_no_reach() {
    let Some(path) = shared("mixamo_walk.bvh") else {
        return;
    };
    let c = read(&path);
    let world = SegmentSettings {
        relative_to_shoulder: false,
        ..SegmentSettings::default()
    };
    let in_world = report(&c, "mixamo_walk.bvh", Side::Left, &world);
    assert!(
        in_world.iter().any(|s| s.label == Label::Reach),
        "{in_world:?}"
    );
    let found = report(
        &c,
        "mixamo_walk.bvh",
        Side::Left,
        &SegmentSettings::default(),
    );
    assert!(
        !found.is_empty() && found.iter().all(|s| s.label == Label::Other),
        "{found:?}"
    );
}

// cmu_12_01 in world space: the walk never stops, so the hand never comes to rest: one
// segment to the last frame, over nearly the whole clip.
#[test]
fn a_walk_never_rests_in_world_space() {
    let c = read(&repo("tests/data/cmu_12_01_walk.bvh"));
    let world = SegmentSettings {
        relative_to_shoulder: false,
        ..SegmentSettings::default()
    };
    let found = report(&c, "cmu_12_01_walk.bvh", Side::Right, &world);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].end, c.frame_count());
    assert!(found[0].frames().len() as f64 > 0.9 * c.frame_count() as f64);
}

// The committed synthetic set: every clip is one reach to the hand's final position. The main
// segment is that reach: labelled reach, whole, its last frame within 2 cm of where the hand
// ends, and it covers at least half of the hand's way there (the rest is steps and torso
// motion before the arm moves).
#[test]
fn every_synthetic_clip_gives_its_reach_as_main() {
    let root = repo("data-synthetic");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("data-synthetic")
        .flat_map(|person| {
            let person = person.expect("entry").path();
            std::fs::read_dir(&person)
                .into_iter()
                .flatten()
                .map(|e| e.expect("entry").path())
                .filter(|p| p.extension().is_some_and(|x| x == "bvh"))
                .collect::<Vec<_>>()
        })
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 56);
    let settings = SegmentSettings::default();
    let mut wrong = Vec::new();
    for path in &paths {
        let c = read(path);
        let arm = right_arm(&c);
        let name = path
            .strip_prefix(&root)
            .unwrap_or(path)
            .display()
            .to_string();
        let hand = c
            .trajectory(&[arm.end_effector()])
            .expect("trajectory")
            .path(0);
        let target = hand[c.frame_count() - 1];
        match main_segment(&c, &arm, &settings, &name) {
            Ok(main) => {
                let arrival = (hand[main.end - 1] - target).norm();
                let covered = (hand[main.onset] - target).norm() / (hand[0] - target).norm();
                if main.label != Label::Reach || main.truncated() || arrival > 0.02 || covered < 0.5
                {
                    wrong.push(format!(
                        "{name}: {main:?}, ends {arrival:.3} m from the target, covers {covered:.2}"
                    ));
                }
            }
            Err(e) => wrong.push(e.to_string()),
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

// A one-frame glitch in a real capture: the upper arm of a synthetic-set clip turned half a
// radian for one frame (the hand jumps about 20 cm) changes no segment.
#[test]
fn a_glitch_in_a_capture_changes_no_segment() {
    let c = read(&repo("data-synthetic/p01/r01.bvh"));
    let arm = right_arm(&c);
    let clean = segments(&c);
    let hand = |c: &Clip| {
        c.trajectory(&[arm.end_effector()])
            .expect("trajectory")
            .path(0)
    };
    let turned = |at: usize, dof: usize| {
        let mut values = c.values().to_vec();
        values[at * c.skeleton().dof_count() + dof] += 0.5;
        let glitched = Clip::new(c.skeleton().clone(), c.frame_time(), values).expect("clip");
        let jump = (hand(&glitched)[at] - hand(&c)[at]).norm();
        (jump, glitched)
    };
    for at in [0, 3, 40, c.frame_count() - 1] {
        // The shoulder DoF that moves the hand most.
        let (jump, glitched) = c
            .skeleton()
            .dof_range(arm.shoulder)
            .map(|dof| turned(at, dof))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .expect("the shoulder has DoFs");
        assert!(
            (0.15..0.35).contains(&jump),
            "the glitch moves the hand {jump:.3} m"
        );
        assert_same_segments(&segments(&glitched), &clean, &format!("glitch at {at}"));
    }
}
