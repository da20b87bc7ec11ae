//! Straight arms: reaches to the edge of the reach sphere, where the Jacobian loses rank in
//! the radial direction (`kinergy_solver::reachability`). With neutral S_A every optimizer,
//! at its default settings, must end within 1% of the arm's length of any target the arm
//! can reach — fully extended included — and, for a target beyond reach, at the reachable
//! point nearest it, reporting `Stalled`. Checked on synthetic reaches and on real captured
//! ones (the hand's end point of captured reaches, which the person's own arm reached).
//!
//! Every synthetic case is drawn from a seeded generator, so a failure names a case that
//! reproduces. The controller's ε is half the asserted 1% (the default 5 mm is 1.07% of the
//! Bandai arm).

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Translation3, Vector3};
use kinergy_motion::rotation::swing_rotation;
use kinergy_motion::{ArmJoints, Chain, Clip, ImportOptions, Motion, Side, read_clip};
use kinergy_solver::{
    ArmTask, Base, BaseMode, CaptureArm, Controller, ControllerSettings, OptimizerKind, StopReason,
    Synergy, Synthesis, Task,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

type Rng = Xoshiro256PlusPlus;

/// The capture rates the controller meets: 120 Hz (CMU) and 30 Hz (Bandai).
const FRAME_TIMES: [f64; 2] = [1.0 / 120.0, 1.0 / 30.0];

/// Start postures, in `CaptureArm`'s base convention (a positive `shoulder_swing_x` lowers
/// the arm): hanging perfectly straight (singular), hanging relaxed, and bent at the elbow.
const STARTS: [(&str, [f64; 7]); 3] = [
    (
        "hanging straight",
        [std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ),
    ("hanging", [1.45, 0.1, 0.0, 0.2, 0.0, 0.0, 0.0]),
    ("bent elbow", [0.9, 0.4, 0.3, 1.6, 0.2, 0.1, 0.0]),
];

/// Upper arm + forearm + hand: the reach of the straight arm.
fn arm_length(chain: &Chain) -> f64 {
    chain.joints()[1..]
        .iter()
        .map(|j| j.offset.norm())
        .sum::<f64>()
        + chain.end_effector().norm()
}

/// An arm with a random adult's bone lengths and the default limits.
fn random_arm(rng: &mut Rng) -> Chain {
    Chain::arm(
        rng.random_range(0.25..0.36),
        rng.random_range(0.22..0.30),
        rng.random_range(0.05..0.11),
    )
    .expect("arm")
}

/// A random rigid frame: any rotation, its origin within a 2 m cube.
fn random_base(rng: &mut Rng) -> IsometryMatrix3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let rotation =
        Rotation3::from_scaled_axis(axis.normalize() * rng.random_range(0.0..std::f64::consts::PI));
    IsometryMatrix3::from_parts(
        Translation3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ),
        rotation,
    )
}

/// A shoulder swing drawn uniformly inside `fraction` of its limit ellipse.
fn random_swing(chain: &Chain, fraction: f64, rng: &mut Rng) -> (f64, f64) {
    let Motion::Swing { rx, ry } = chain.joints()[0].motions[0] else {
        panic!("the arm's shoulder starts with a swing")
    };
    loop {
        let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if a * a + b * b <= 1.0 {
            return (a * rx * fraction, b * ry * fraction);
        }
    }
}

fn synthesize(
    chain: &Chain,
    base: &Base,
    start: &[f64],
    target: Point3<f64>,
    kind: OptimizerKind,
    settings: ControllerSettings,
) -> Synthesis {
    Controller::new(kind.default_optimizer(), Synergy::identity(7), settings)
        .expect("controller")
        .synthesize(&ArmTask {
            chain,
            base,
            start,
            task: Task::Position(target),
            start_velocity: None,
        })
        .expect("synthesize")
}

fn last_hand(m: &Synthesis) -> Point3<f64> {
    m.end(m.frame_count() - 1)
}

fn assert_within_limits(chain: &Chain, m: &Synthesis, what: &str) {
    for i in 0..m.frame_count() {
        assert!(
            chain.within_limits(m.configuration(i)),
            "{what}: frame {i} {:?} is outside the limits",
            m.configuration(i)
        );
    }
}

/// How one group of reaches went: worst miss (fraction of the arm's length), stop reasons,
/// mean frame count, failed cases.
#[derive(Default)]
struct Tally {
    cases: usize,
    worst: f64,
    stops: BTreeMap<&'static str, usize>,
    frames: usize,
    failed: Vec<(usize, StopReason, f64)>,
}

impl Tally {
    fn add(&mut self, case: usize, m: &Synthesis, miss: f64, ok: bool) {
        self.cases += 1;
        self.worst = self.worst.max(miss);
        *self.stops.entry(m.stop.name()).or_default() += 1;
        self.frames += m.frame_count();
        if !ok {
            self.failed.push((case, m.stop, miss));
        }
    }

    fn report(&self, what: &str) -> String {
        format!(
            "{what}: {} of {} failed, worst {:.2}% of the arm, stops {:?}, {:.0} frames on average{}",
            self.failed.len(),
            self.cases,
            100.0 * self.worst,
            self.stops,
            self.frames as f64 / self.cases.max(1) as f64,
            if self.failed.is_empty() {
                String::new()
            } else {
                format!(
                    "; failed (case, stop, miss): {:?}",
                    self.failed
                        .iter()
                        .map(|&(c, s, m)| (c, s.name(), format!("{:.2}%", 100.0 * m)))
                        .collect::<Vec<_>>()
                )
            }
        )
    }
}

/// Runs `each` for every optimizer, frame time and start, collects the tallies, prints them
/// and fails with every failed group.
fn for_every_reach(what: &str, mut each: impl FnMut(OptimizerKind, f64, &[f64; 7], &mut Tally)) {
    let mut failures = Vec::new();
    for kind in OptimizerKind::ALL {
        for dt in FRAME_TIMES {
            for (name, start) in &STARTS {
                let mut tally = Tally::default();
                each(kind, dt, start, &mut tally);
                let line =
                    tally.report(&format!("{what}, {kind} at {:.0} Hz from {name}", 1.0 / dt));
                eprintln!("{line}");
                if !tally.failed.is_empty() {
                    failures.push(line);
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// (a) Targets at 97–100% of the full reach, in directions anywhere inside 90% of the
// shoulder's swing ellipse (so behind the start hand too), made by FK of a configuration
// whose elbow flexion gives that distance by the law of cosines (every tenth exactly at
// full extension, the elbow on its 0 limit); from a perfectly straight hanging arm, a
// relaxed one and a bent elbow; random bone lengths and base frames. Every optimizer at
// 120 and 30 Hz must stop Reached, within 1% of the arm's length, inside the limits.
//
// Measured before `reachability` (600 reaches per optimizer): JT failed 500 — 431 stopped
// short by at most 4.8% of the arm (out of frames crawling toward an extended elbow, or
// stalled with the elbow on its 0 limit and the wrist bent: the elbow's radial column is
// ∝ sin φ), 69 folded on targets behind the hand (up to 90% of the arm away); NJT 88 (37
// short by ≤ 2.3%, 51 folded); SVD 86 (41 short by ≤ 2.8%, 45 folded or thrashing as the
// radial singular value crossed its threshold, up to 194%); DLS 29 (all folded, up to
// 189%). Since: none (worst 0.50% of the arm, the ε).
#[test]
fn every_optimizer_reaches_targets_at_the_edge_of_reach() {
    for_every_reach("97–100% of reach", |kind, dt, start, tally| {
        let mut rng = Rng::seed_from_u64(7);
        for case in 0..100 {
            let chain = random_arm(&mut rng);
            let base = random_base(&mut rng);
            let length = arm_length(&chain);
            let (sx, sy) = random_swing(&chain, 0.9, &mut rng);
            let twist = rng.random_range(-1.4..1.4);
            let pronation = rng.random_range(-1.4..1.4);
            let fraction: f64 = if case % 10 == 0 {
                1.0
            } else {
                rng.random_range(0.97..1.0)
            };
            // r² = u² + ℓ² + 2uℓ cos φ with the wrist straight.
            let upper = chain.joints()[1].offset.norm();
            let rest = length - upper;
            let cos =
                ((fraction * length).powi(2) - upper * upper - rest * rest) / (2.0 * upper * rest);
            let flexion = cos.clamp(-1.0, 1.0).acos();
            let goal = [sx, sy, twist, flexion, pronation, 0.0, 0.0];
            let target = chain.end_position(&base, &goal).expect("fk");
            let settings = ControllerSettings {
                tolerance: 0.005 * length,
                ..ControllerSettings::at_frame_time(dt)
            };
            let m = synthesize(&chain, &Base::Fixed(base), start, target, kind, settings);
            assert_within_limits(&chain, &m, &format!("{kind} case {case}"));
            let miss = (last_hand(&m) - target).norm() / length;
            tally.add(
                case,
                &m,
                miss,
                m.stop == StopReason::Reached && miss <= 0.01,
            );
        }
    });
}

// (a) Targets 100.5–110% of the full reach away along a direction the straight arm can point
// to (inside 85% of the swing ellipse): the nearest reachable point is the straight arm
// along it, c = shoulder + L·direction. Every optimizer must end within 1% of the arm's
// length of c, stopped as Stalled (out of reach, at the closest point), never closer to the
// target than the gap.
//
// Measured before `reachability` (300 per optimizer): JT failed 214 (202 out of frames,
// still straightening, 183 of them within 3.8% of c; 31 folded), NJT 82 (52 out of frames
// within 0.6% of c, chattering; 30 folded, up to 90% of the arm away), SVD 49 and DLS 26
// (folded, up to 191%). Since: all Stalled within 0.03% of the arm of c.
#[test]
fn targets_beyond_reach_end_stretched_toward_them() {
    for_every_reach("100.5–110% of reach", |kind, dt, start, tally| {
        let mut rng = Rng::seed_from_u64(8);
        for case in 0..50 {
            let chain = random_arm(&mut rng);
            let base = random_base(&mut rng);
            let length = arm_length(&chain);
            let (sx, sy) = random_swing(&chain, 0.85, &mut rng);
            let direction = base.rotation * (swing_rotation(sx, sy) * Vector3::z());
            let shoulder = Point3::from(base.translation.vector);
            let beyond = rng.random_range(1.005..1.1);
            let target = shoulder + direction * (beyond * length);
            let nearest = shoulder + direction * length;
            let settings = ControllerSettings {
                tolerance: 0.005 * length,
                ..ControllerSettings::at_frame_time(dt)
            };
            let m = synthesize(&chain, &Base::Fixed(base), start, target, kind, settings);
            assert_within_limits(&chain, &m, &format!("{kind} case {case}"));
            let gap = (beyond - 1.0) * length;
            assert!(m.final_error >= gap - 1e-9, "{kind} case {case}");
            let miss = (last_hand(&m) - nearest).norm() / length;
            tally.add(
                case,
                &m,
                miss,
                m.stop == StopReason::Stalled && miss <= 0.01,
            );
        }
    });
}

/// The shared data folder (`../shared/data` beside the workspace), or `None` after saying
/// why the real captures are not tested.
fn shared(folder: &str) -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(folder);
    if dir.is_dir() {
        Some(dir)
    } else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the Bandai Namco captures, CC BY-NC, are never committed)",
            dir.display()
        ));
        None
    }
}

fn read(path: &Path) -> Clip {
    read_clip(path, &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// One captured reach: its name, the clip, the arm and the reach's frames (inclusive).
struct Captured {
    name: String,
    clip: Clip,
    joints: ArmJoints,
    frames: (usize, usize),
}

/// The captured reaches available: the 24 Bandai raises of the left hand (onset the first
/// frame, end the frame where the hand is highest — the actor raises it from hanging to
/// above the head) and the Bandai right-arm "guide" gesture, frames 5–21 (its README).
fn captured_reaches() -> Vec<Captured> {
    let mut out = Vec::new();
    if let Some(dir) = shared("bandai-raise-left") {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("read the folder")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
            .collect();
        files.sort();
        assert_eq!(files.len(), 24, "{}: 3 styles × 8 takes", dir.display());
        for path in files {
            let clip = read(&path);
            let joints = ArmJoints::find(clip.skeleton(), Side::Left).expect("left arm");
            let height = |pose: &[f64]| {
                clip.skeleton().world_positions(pose).expect("fk")[joints.end_effector()].y
            };
            let highest = (0..clip.frame_count())
                .max_by(|&a, &b| {
                    let (a, b) = (clip.frame(a).expect("frame"), clip.frame(b).expect("frame"));
                    height(a).total_cmp(&height(b))
                })
                .expect("frames");
            out.push(Captured {
                name: path.file_name().expect("name").to_string_lossy().into(),
                clip,
                joints,
                frames: (0, highest),
            });
        }
    }
    if let Some(dir) = shared("real-bvh") {
        let clip = read(&dir.join("dataset-1_guide_normal_001.bvh"));
        let joints = ArmJoints::find(clip.skeleton(), Side::Right).expect("right arm");
        out.push(Captured {
            name: "dataset-1_guide_normal_001.bvh".into(),
            clip,
            joints,
            frames: (5, 21),
        });
    }
    out
}

// (b) The end point of real captured reaches, which the person's own arm reached: the
// synthesis starts in the captured first posture, its shoulder rides on the captured one
// (`BaseMode::Replay`), and with neutral S_A every optimizer must end within 1% of the arm's
// length of the captured end of the hand. With the shoulder held where it starts
// (`BaseMode::Fixed`) the raised hand of the "active" takes is 118–127% of the arm's length
// away: the synthesis must end Stalled within 1% of the reachable point nearest it (the
// straight arm pointing at it), and reach every other target. The budget is 60 s: plain JT
// takes 33 s on the guide reach at ε = 0.5% of the arm, crawling along a valley of its
// bent-arm Jacobian (an ordinary reach, left as the paper has it).
//
// Measured without `reachability`: on the 8 "active" raises (the hand ends at 95–97% of the
// arm's length from the shoulder, above the head; the start hanging) JT missed 7 (57–67% of
// the arm away, stalled with the elbow folded and the shoulder on its limits; the eighth ran
// out of its 60 s 0.8% short), NJT 7 (58–67%), DLS 1 (58%), SVD none; with the shoulder held,
// JT and NJT missed the nearest point on all 8 (71–83%), DLS on 7 (71–78%), SVD on 4
// (10–85%). The 16 "normal" and "elderly" raises (ending at 58–64%, the elbow bent 100–110°)
// and the guide reach are reached by all, with it as without, frame for frame.
#[test]
fn captured_reaches_end_where_the_person_reached() {
    let reaches = captured_reaches();
    let mut failures = Vec::new();
    for r in &reaches {
        let (first, last) = r.frames;
        let segment = r.clip.slice(first..last + 1).expect("slice");
        let arm = CaptureArm::new(&segment, &r.joints).expect("capture arm");
        let captured = arm.captured_trajectory(&segment).expect("trajectory");
        let end = captured.frame(captured.frame_count() - 1);
        let (shoulder, target) = (end[0], end[end.len() - 1]);
        let length = arm_length(arm.chain());
        let base = arm.base(BaseMode::Replay);
        let settings = ControllerSettings {
            tolerance: 0.005 * length,
            max_frames: (60.0 / r.clip.frame_time()).ceil() as usize,
            ..ControllerSettings::at_frame_time(r.clip.frame_time())
        };
        let mut line = format!(
            "{} frames {first}–{last}: the hand ends {:.1}% of the arm's length from the shoulder;",
            r.name,
            100.0 * (target - shoulder).norm() / length
        );
        for kind in OptimizerKind::ALL {
            let m = synthesize(arm.chain(), &base, arm.start(), target, kind, settings);
            assert_within_limits(arm.chain(), &m, &format!("{} {kind}", r.name));
            let miss = (last_hand(&m) - target).norm() / length;
            line += &format!(
                " {kind} {:.2}% {} after {} frames;",
                100.0 * miss,
                m.stop,
                m.frame_count()
            );
            if miss > 0.01 {
                failures.push(format!(
                    "{} {kind}: {:.2}% ({})",
                    r.name,
                    100.0 * miss,
                    m.stop
                ));
            }
        }
        // The shoulder held where it starts: the raised targets lie beyond reach from there.
        let fixed = arm.base(BaseMode::Fixed);
        let shoulder = Point3::from(fixed.at(0).translation.vector);
        let (distance, direction) = ((target - shoulder).norm(), (target - shoulder).normalize());
        let goal = if distance > length {
            shoulder + direction * length
        } else {
            target
        };
        line += &format!(
            " fixed shoulder, target at {:.1}%:",
            100.0 * distance / length
        );
        for kind in OptimizerKind::ALL {
            let m = synthesize(arm.chain(), &fixed, arm.start(), target, kind, settings);
            let miss = (last_hand(&m) - goal).norm() / length;
            line += &format!(" {kind} {:.2}% {};", 100.0 * miss, m.stop);
            let stop_ok = distance <= length || m.stop == StopReason::Stalled;
            if miss > 0.01 || !stop_ok {
                failures.push(format!(
                    "{} fixed {kind}: {:.2}% ({})",
                    r.name,
                    100.0 * miss,
                    m.stop
                ));
            }
        }
        eprintln!("{line}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
