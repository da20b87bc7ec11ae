//! The default profile in real time (issue 43, item 4): the paper's ease-out hand (Huang,
//! Kapadia & Terzopoulos §3.3, eqs. 1–4, Algorithm 1) measured in m/s against seconds on the
//! full-body character, never time-normalized.
//!
//! - From rest the hand takes up v_s within [`RAMP`] seconds, then holds it within 5 % until the
//!   deceleration, and never runs faster than 1.05 v_s; where a step carries the hand at the
//!   arm's onset, its speed comes down to v_s within [`CARRIED_RAMP`] and stays within 5 %.
//! - A stepping reach keeps its hand within 2 cm of Huang's world-frame straight line (from
//!   where the hand is at the arm's onset to the target) wherever the arm can reach the line
//!   from where the body has carried the shoulder; where the line passes out of the arm's reach
//!   the hand is at the nearest reachable point, as the paper's controller puts it.
//! - No jump: the hand's speed changes by at most [`LARGEST_CHANGE`] a frame, and once the hand
//!   has come to rest it stays at rest — after a reach, after a held-out raise of the shared
//!   captures (`../shared/data/bandai-raise-left`, which `style` reaches with the default
//!   profile), and where a person's synergy hands the hand over.
//!
//! What these replaced, measured before the change (`reach --target …`, 120 Hz): the ease-out
//! hand rose from 0.01 m/s and overshot to 0.35 m/s at 0.26 s (1.75 v_s); the stepping reach
//! toward `0.2,1.0,1.15` left the line by 17.5 cm; `style`'s default-profile reach of the
//! held-out raise `normal_005` stopped 0.38 m short at 2.4 s and jumped to 1.25 m/s at 4.05 s.

use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, ImportOptions, Side, read_clip};
use kinergy_reach::character::Character;
use kinergy_reach::controller::{
    ArmDrive, ReachMotion, ReachSettings, ReachStop, arm_dof_names, reach_full_body,
    reach_full_body_driven,
};
use kinergy_reach::drive::PersonArm;
use kinergy_reach::profile::{BellTiming, PAPER_START_RATIO, PAPER_START_SPEED, SpeedProfile};
use kinergy_reach::steps::StepDecision;
use kinergy_reach::style::StyleCapture;
use kinergy_solver::ParamsFile;

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

/// From rest, the hand is at 95 % of v_s within this many seconds of the arm's onset.
const RAMP: f64 = 0.1;

/// Carried by a step at the arm's onset, the hand's speed is within 5 % of v_s this many
/// seconds after it.
const CARRIED_RAMP: f64 = 0.2;

/// The largest change of the hand's speed between frames, m/s at 120 Hz (24 m/s²: a fast
/// human hand's acceleration).
const LARGEST_CHANGE: f64 = 0.2;

/// Below this speed, m/s, the hand is at rest.
const AT_REST: f64 = 0.05;

/// Reaches toward these, by the default character (`reach --target x,y,z`): mid-height, high,
/// low, behind, and far enough to step.
const GRID: [[f64; 3]; 14] = [
    [0.3, 1.1, 0.4],
    [0.25, 1.1, 0.35],
    [-0.4, 1.0, 0.5],
    [0.1, 0.9, 0.5],
    [0.0, 1.5, 0.45],
    [0.0, 1.9, 0.3],
    [0.5, 1.4, 0.1],
    [0.6, 1.0, -0.4],
    [-0.5, 1.0, -0.3],
    [0.2, 0.6, 0.45],
    [0.2, 1.0, 1.15],
    [-0.2, 1.0, 1.15],
    [0.2, 0.15, 0.8],
    [0.6, 1.0, 1.0],
];

fn character() -> Character {
    Character::from_height(1.75).expect("character")
}

/// Within this distance, meters, of the arm's full reach the hand itself is at the reach's edge
/// (the relaxed arm hangs 4 mm short of it).
const STRETCHED: f64 = 0.002;

/// How long, seconds, the hand takes to rejoin its line and profile once the line comes back
/// into the arm's reach.
const REJOIN: f64 = 0.1;

/// The most the hand leaves its straight line where the arm can reach the line, meters.
const OFF_LINE: f64 = 0.02;

/// A reach seen in the world: its reaching hand's tip and shoulder on every frame.
struct Seen {
    motion: ReachMotion,
    hand: Vec<Point3<f64>>,
    shoulder: Vec<Point3<f64>>,
    /// The arm's full reach from the shoulder to the hand's tip, meters.
    arm: f64,
    /// The reach's speed profile.
    profile: SpeedProfile,
}

impl Seen {
    fn of(c: &Character, motion: ReachMotion, profile: SpeedProfile) -> Seen {
        let [shoulder, _, _, tip] = motion.report.arm.joints();
        let world: Vec<_> = motion.poses.iter().map(|p| c.world_positions(p)).collect();
        // The rest pose's arms hang straight: its hand is the arm's full reach away.
        let rest = c.world_positions(&c.rest_pose());
        Seen {
            hand: world.iter().map(|w| w[tip]).collect(),
            shoulder: world.iter().map(|w| w[shoulder]).collect(),
            arm: (rest[tip] - rest[shoulder]).norm(),
            motion,
            profile,
        }
    }

    /// Whether the line is out of the arm's reach on frame `k`: the paper's own goal — Algorithm
    /// 1's hand on the line toward `target` with the reach's profile from the arm's onset (no
    /// ramp, no waiting) — lies beyond the arm's full reach from where the body has carried the
    /// shoulder, where the paper's analytic arm, too, puts the hand at the nearest reachable
    /// point; or the hand is within [`STRETCHED`] of that reach (the clock's goal, run a little
    /// off the paper's, out of reach).
    fn stretched(&self, k: usize, target: &Point3<f64>) -> bool {
        let onset = self.onset();
        let start = self.hand[onset];
        let t = k.saturating_sub(onset) as f64 * self.dt();
        let paper = self.profile.position(&start, target, t);
        (paper - self.shoulder[k]).norm() > self.arm
            || (self.hand[k] - self.shoulder[k]).norm() >= self.arm - STRETCHED
    }

    /// Whether the paper's goal is out of the arm's reach within [`REJOIN`] seconds of frame
    /// `k` (the clock that ramps and waits runs a little off the paper's).
    fn off_reach(&self, k: usize, target: &Point3<f64>) -> bool {
        let window = (REJOIN / self.dt()).ceil() as usize;
        let last = (k + window).min(self.hand.len() - 1);
        (k.saturating_sub(window)..=last).any(|j| self.stretched(j, target))
    }

    /// The hand's distance from Huang's line (from the hand at the arm's onset to `target`) on
    /// every frame from the onset.
    fn off_line(&self, target: &Point3<f64>) -> Vec<f64> {
        let start = self.hand[self.onset()];
        let along = (target - start).normalize();
        self.hand[self.onset()..]
            .iter()
            .map(|h| {
                let d = h - start;
                (d - along * d.dot(&along)).norm()
            })
            .collect()
    }

    fn dt(&self) -> f64 {
        self.motion.frame_time
    }

    fn onset(&self) -> usize {
        self.motion.report.arm_onset_frame
    }

    /// The hand's world speed from frame k to k + 1, m/s, from the arm's onset on: entry i is
    /// the speed over the frame that ends i + 1 frames after the onset.
    fn speeds(&self) -> Vec<f64> {
        self.hand[self.onset()..]
            .windows(2)
            .map(|w| (w[1] - w[0]).norm() / self.dt())
            .collect()
    }

    /// The hand relative to the shoulder, its speeds from the arm's onset (what `style`'s jump
    /// check reads).
    fn relative_speeds(&self) -> Vec<f64> {
        let rel: Vec<_> = self.hand[self.onset()..]
            .iter()
            .zip(&self.shoulder[self.onset()..])
            .map(|(h, s)| h - s)
            .collect();
        rel.windows(2)
            .map(|w| (w[1] - w[0]).norm() / self.dt())
            .collect()
    }

    fn steps(&self) -> bool {
        self.motion.report.step != StepDecision::NoStep
    }
}

fn reach(c: &Character, t: [f64; 3]) -> Seen {
    let m = reach_full_body(c, Point3::new(t[0], t[1], t[2]), &ReachSettings::default())
        .expect("reach");
    Seen::of(c, m, SpeedProfile::default())
}

/// The largest change of speed between consecutive frames, and where (seconds into `speeds`).
fn largest_change(speeds: &[f64], dt: f64) -> (f64, f64) {
    speeds
        .windows(2)
        .enumerate()
        .map(|(i, w)| ((w[1] - w[0]).abs(), (i + 1) as f64 * dt))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Where, after the hand has been at rest for a quarter second, it moves again (seconds into
/// `speeds`, and the speed).
fn moves_after_rest(speeds: &[f64], dt: f64) -> Option<(f64, f64)> {
    let window = (0.25 / dt).ceil() as usize;
    let rested = speeds
        .windows(window)
        .position(|w| w.iter().all(|&v| v < AT_REST))?;
    speeds
        .iter()
        .enumerate()
        .skip(rested + window)
        .find(|(_, v)| **v >= AT_REST)
        .map(|(i, v)| (i as f64 * dt, *v))
}

#[test]
fn the_ease_out_hand_takes_up_v_s_and_holds_it() {
    let c = character();
    let v_s = PAPER_START_SPEED;
    let profile = SpeedProfile::default();
    let mut failures = Vec::new();
    for t in GRID {
        let seen = reach(&c, t);
        let dt = seen.dt();
        let speeds = seen.speeds();
        let onset = seen.onset();
        let target = Point3::new(t[0], t[1], t[2]);
        let start = seen.hand[onset];
        let path = (target - start).norm();
        let along = (target - start) / path;
        // The cruise ends where the hand has covered v_s r_s t_t of its path (eq. 4); the clock
        // that ramps and waits shifts it in time.
        let cruise = v_s * PAPER_START_RATIO * profile.duration(path) - v_s * dt;
        let cruise_end = seen.hand[onset..]
            .iter()
            .position(|h| (h - start).dot(&along) >= cruise)
            .unwrap_or(speeds.len())
            .min(speeds.len());
        // Where the line has passed out of the arm's reach, the hand is at the nearest
        // reachable point (the paper's rule too) and has no speed of the profile's to hold.
        let free: Vec<f64> = speeds
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if seen.off_reach(onset + i + 1, &target) {
                    v_s
                } else {
                    v
                }
            })
            .collect();
        let stretched = free.iter().zip(&speeds).filter(|(f, v)| f != v).count();
        let speeds = free;
        // The ramp ends with the last frame of the cruise outside 5 % of v_s.
        let ramp = speeds[..cruise_end]
            .iter()
            .rposition(|v| (v - v_s).abs() > 0.05 * v_s)
            .map_or(0, |i| i + 1);
        let ramp_s = (ramp + 1) as f64 * dt;
        let after = &speeds[ramp..];
        let at = |v: &[f64], f: fn(f64, f64) -> bool| {
            v.iter()
                .enumerate()
                .fold((v.first().copied().unwrap_or(v_s), 0), |a, (i, &x)| {
                    if f(x, a.0) { (x, i) } else { a }
                })
        };
        let (fastest, fastest_at) = at(after, |x, best| x > best);
        let (slowest, slowest_at) = at(&speeds[ramp..cruise_end.max(ramp)], |x, best| x < best);
        let line = format!(
            "{t:?} ({:?}, {:?}): ramp {ramp_s:.3} s, then {slowest:.3} m/s at {:.3} s .. \
             {fastest:.3} m/s at {:.3} s (cruise to {:.2} s; {stretched} frames stretched)",
            seen.motion.report.step,
            seen.motion.report.stop,
            (ramp + slowest_at + 1) as f64 * dt,
            (ramp + fastest_at + 1) as f64 * dt,
            cruise_end as f64 * dt
        );
        eprintln!("{line}");
        let limit = if seen.steps() { CARRIED_RAMP } else { RAMP };
        if ramp_s > limit || fastest > 1.05 * v_s || slowest < 0.95 * v_s {
            failures.push(line);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_stepping_hand_keeps_to_huangs_line_where_the_arm_can_reach_it() {
    let c = character();
    let mut failures = Vec::new();
    let mut stepping = 0;
    for t in GRID {
        let seen = reach(&c, t);
        let target = Point3::new(t[0], t[1], t[2]);
        let onset = seen.onset();
        let off = seen.off_line(&target);
        let (worst, at) = off
            .iter()
            .enumerate()
            .filter(|(i, _)| !seen.off_reach(onset + i, &target))
            .fold((0.0, 0), |a, (i, &d)| if d > a.0 { (d, i) } else { a });
        let beyond = off
            .iter()
            .enumerate()
            .filter(|(i, _)| seen.off_reach(onset + i, &target))
            .fold(0.0f64, |a, (_, &d)| a.max(d));
        let line = format!(
            "{t:?} ({:?}): {:.1} cm off the line at {:.3} s; {:.1} cm where out of reach",
            seen.motion.report.step,
            100.0 * worst,
            at as f64 * seen.dt(),
            100.0 * beyond
        );
        eprintln!("{line}");
        stepping += usize::from(seen.steps());
        if worst > OFF_LINE {
            failures.push(line);
        }
    }
    assert!(stepping >= 4, "{stepping} stepping reaches on the grid");
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Checks a hand's speeds for jumps: no change above [`LARGEST_CHANGE`] a frame (scaled to the
/// frame rate from 120 Hz) and no motion after rest. `None` when none, else what broke.
fn jump(speeds: &[f64], dt: f64) -> Option<String> {
    let largest = LARGEST_CHANGE * 120.0 * dt;
    let (change, at) = largest_change(speeds, dt);
    if change > largest {
        return Some(format!(
            "its speed changed by {change:.3} m/s in a frame at {at:.3} s"
        ));
    }
    moves_after_rest(speeds, dt)
        .map(|(at, v)| format!("at rest, its hand moved again at {v:.3} m/s at {at:.3} s"))
}

#[test]
fn no_hand_jumps_after_it_settles_on_the_grid() {
    let c = character();
    let mut failures = Vec::new();
    for t in GRID {
        let seen = reach(&c, t);
        let dt = seen.dt();
        let world = seen.speeds();
        let relative = seen.relative_speeds();
        let (change, at) = largest_change(&world, dt);
        eprintln!("{t:?}: largest change {change:.3} m/s a frame at {at:.3} s");
        for (what, v) in [("world", &world), ("relative", &relative)] {
            if let Some(why) = jump(v, dt) {
                failures.push(format!("{t:?} ({what}): {why}"));
            }
        }
        assert_eq!(seen.motion.report.stop, ReachStop::Reached, "{t:?}");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

fn shared_raises() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/bandai-raise-left")
}

/// `style`'s default-profile reach of each held-out raise (`kinergy style … --arm left`): the
/// character of the capture's proportions reaches the capture's target with the left arm.
/// Measured before: `normal_005`'s hand stopped 0.38 m short at 2.4 s (every solve failed
/// while the straight line passed too close to the shoulder for the elbow) and, the line
/// clear of the shoulder again, jumped to 1.25 m/s at 4.05 s; all four held-out normal raises
/// (1.2 m/s at 4.0–4.1 s) and all four active ones (1.9 m/s at 4.8 s) did the same.
#[test]
fn a_held_out_raises_default_reach_does_not_jump_after_it_settles() {
    let dir = shared_raises();
    let Ok(entries) = std::fs::read_dir(&dir) else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the shared captures are never committed)",
            dir.display()
        ));
        return;
    };
    let mut files: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "bvh"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{} holds no BVH file", dir.display());
    let settings = ReachSettings {
        arm: Some(Side::Left),
        ..ReachSettings::default()
    };
    let mut failures = Vec::new();
    for path in &files {
        let name = path.display().to_string();
        let (clip, _) = read_clip(path, &ImportOptions::default()).expect("raise");
        let joints = ArmJoints::find(clip.skeleton(), Side::Left).expect("left arm");
        let capture = StyleCapture::new(&clip, &joints, &name).expect("capture");
        let c = capture.character();
        let target =
            PersonArm::world_target(c, &capture.target_in_base(), Side::Left).expect("target");
        let m = reach_full_body_driven(c, target, &settings, &ArmDrive::Profile).expect("reach");
        let seen = Seen::of(c, m, SpeedProfile::default());
        let dt = seen.dt();
        let relative = seen.relative_speeds();
        let fastest = relative.iter().copied().fold(0.0, f64::max);
        eprintln!(
            "{}: {:?} in {:.2} s, fastest {fastest:.3} m/s relative to the shoulder",
            path.file_name().unwrap_or_default().to_string_lossy(),
            seen.motion.report.stop,
            seen.motion.report.duration
        );
        for (what, v) in [("world", &seen.speeds()), ("relative", &relative)] {
            if let Some(why) = jump(v, dt) {
                failures.push(format!("{name} ({what}): {why}"));
            }
        }
        if fastest > 1.05 * PAPER_START_SPEED {
            failures.push(format!("{name}: the hand ran at {fastest:.3} m/s"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Where a person's synergy hands the hand over (plain IK, then the analytic IK on a
/// minimum-jerk path from where the hand is), the hand's speed does not jump: a real capture's
/// parameters (`tests/data/params/006_14-sc.json`), which hand over on half the grid.
#[test]
fn no_hand_jumps_at_a_hand_over() {
    let c = character();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/params/006_14-sc.json");
    let file = ParamsFile::read(&path).expect("params");
    let drive = ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy: file
            .synergy_for(&arm_dof_names(&c))
            .expect("the arm's DoFs"),
        tempo: None,
        controller: None,
    };
    let mut handed = 0;
    let mut failures = Vec::new();
    for t in GRID {
        let target = Point3::new(t[0], t[1], t[2]);
        let m =
            reach_full_body_driven(&c, target, &ReachSettings::default(), &drive).expect("reach");
        let Some(h) = m.report.hand_over else {
            continue;
        };
        handed += 1;
        let seen = Seen::of(&c, m, SpeedProfile::default());
        let dt = seen.dt();
        let relative = seen.relative_speeds();
        let (change, at) = largest_change(&relative, dt);
        eprintln!(
            "{t:?}: hand-over at {:.2} s ({:?}, analytic at {:?}); largest change {change:.3} \
             m/s a frame at {at:.3} s",
            h.at_s, h.why, h.analytic_at_s
        );
        for (what, v) in [("world", &seen.speeds()), ("relative", &relative)] {
            if let Some(why) = jump(v, dt) {
                failures.push(format!("{t:?} ({what}): {why}"));
            }
        }
    }
    assert!(handed >= 3, "{handed} hand-overs on the grid");
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The bells keep one bump: with the minimum-jerk and the cubic profile the hand's world speed
/// rises to a single peak and falls from it (within 1 % of the peak a frame, rounding and the
/// body's own motion), on every reach of the grid that does not step, but where the line passes
/// out of the arm's reach. (There a trunk twisting away from a bell's slow start pulls the arm
/// straight, the goal's elbow stops dead on its limit, and the hand's speed kinks: 0.28 m/s for
/// a frame toward `[0.6, 1.0, -0.4]`. Before this change the bells bumped on all four reaches
/// behind, at 0.05–0.13 s.)
#[test]
fn the_bells_keep_a_single_bump() {
    let c = character();
    let mut failures = Vec::new();
    for profile in [
        SpeedProfile::minimum_jerk(BellTiming::default()).expect("profile"),
        SpeedProfile::cubic(BellTiming::default()).expect("profile"),
    ] {
        let settings = ReachSettings {
            profile,
            ..ReachSettings::default()
        };
        for t in GRID {
            let target = Point3::new(t[0], t[1], t[2]);
            let m = reach_full_body(&c, target, &settings).expect("reach");
            let seen = Seen::of(&c, m, profile);
            let onset = seen.onset();
            if seen.steps() {
                continue;
            }
            let speeds = seen.speeds();
            let (peak, top) = speeds
                .iter()
                .enumerate()
                .fold((0, 0.0), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
            let tolerance = 0.01 * top;
            let bump = speeds.windows(2).enumerate().find(|(i, w)| {
                if seen.off_reach(onset + i + 2, &target) {
                    false
                } else if *i < peak {
                    w[1] < w[0] - tolerance
                } else {
                    w[1] > w[0] + tolerance
                }
            });
            let dt = seen.dt();
            eprintln!(
                "{profile:?} {t:?}: peak {top:.3} m/s at {:.2} s{}",
                peak as f64 * dt,
                bump.map_or(String::new(), |(i, _)| format!(
                    ", bump at {:.3} s",
                    i as f64 * dt
                ))
            );
            if let Some((i, w)) = bump {
                failures.push(format!(
                    "{profile:?} {t:?}: {:.3} → {:.3} m/s at {:.3} s (peak {top:.3} at {:.2} s)",
                    w[0],
                    w[1],
                    i as f64 * dt,
                    peak as f64 * dt
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
