//! Synthetic motion capture: full-body reaching clips of several made-up persons, made by
//! the full-body reach controller, with a manifest of everything that made them.
//!
//! Each person gets, from the seed: a height (1.55–1.95 m), a leg flexibility (0.6–3), a
//! reaching speed (the hand follows a minimum-jerk bell, mean speed 0.35–0.6 m/s, because
//! human hand speed is bell-shaped), a step tendency (the half-step probabilities and the
//! step length spread) and scheduler ratios `r_st`, `r_tw` (0.3–0.7). Each reach's target is
//! drawn around one of fourteen kinds, scaled by the person's height and cycled through:
//! near and far in front, low (near the floor), high, to the left and to the right, across
//! the body, and combinations. A target the controller does not reach within 1 cm is drawn
//! again (up to 20 times), so every clip ends at its target. All reaches use the right arm,
//! so one `--arm` setting reads the whole set.
//!
//! Files: `DIR/pNN/rNN.bvh` (one folder per person, which `kinergy compare` reads as one
//! person) at [`SynthSettings::frame_rate`], written in centimeters with channel values
//! rounded to 4 decimals (0.001 mm, 0.0001°) to keep the set small, and `DIR/manifest.csv`.

use std::ops::Range;
use std::path::Path;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use serde::Serialize;

use crate::character::{Character, Proportions};
use crate::controller::{ArmDrive, ReachSettings, ReachStop, reach_full_body_driven};
use crate::error::{ReachError, Result, require};
use crate::profile::{BellTiming, SpeedProfile};
use crate::steps::StepSettings;

/// How many persons and reaches, and the seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthSettings {
    /// Persons.
    pub persons: usize,
    /// Reaches per person.
    pub reaches: usize,
    /// Seed of everything.
    pub seed: u64,
    /// Frames per second of the clips.
    pub frame_rate: f64,
}

impl Default for SynthSettings {
    fn default() -> SynthSettings {
        SynthSettings {
            persons: 4,
            reaches: 14,
            seed: 2026,
            frame_rate: 60.0,
        }
    }
}

/// One row of `manifest.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ManifestRow {
    /// The clip's path relative to the set's folder.
    pub clip: String,
    /// The person's id (`pNN`).
    pub person: String,
    /// The person's height, meters.
    pub height_m: f64,
    /// Leg flexibility.
    pub flexibility: f64,
    /// The hand's mean speed along its path, m/s.
    pub mean_speed_m_s: f64,
    /// Scheduler ratio `r_st`.
    pub r_st: f64,
    /// Scheduler ratio `r_tw`.
    pub r_tw: f64,
    /// Half-step probability at the CRR.
    pub p_max: f64,
    /// The kind of target.
    pub kind: &'static str,
    /// Target, world meters.
    pub target_x: f64,
    /// Target, world meters.
    pub target_y: f64,
    /// Target, world meters.
    pub target_z: f64,
    /// The step decision.
    pub step: String,
    /// Step length, meters.
    pub step_length_m: f64,
    /// Spine twist, degrees.
    pub twist_deg: f64,
    /// Spine swing, degrees.
    pub swing_deg: f64,
    /// Squat depth, meters.
    pub squat_m: f64,
    /// Hand–target distance at the end, meters.
    pub final_error_m: f64,
    /// Frames.
    pub frames: usize,
    /// The reach's own seed.
    pub seed: u64,
}

/// The fourteen kinds of target: (name, x, y, z) with y as a fraction of the height and x, z
/// in meters per meter of height; the character faces +Z and its left is +X.
const KINDS: [(&str, f64, f64, f64); 14] = [
    ("front_near", -0.10, 0.62, 0.20),
    ("front_far", -0.10, 0.55, 0.45),
    ("front_low", -0.10, 0.30, 0.30),
    ("floor_far", -0.10, 0.08, 0.42),
    ("high_front", -0.12, 0.95, 0.20),
    ("high_right", -0.30, 0.90, 0.08),
    ("right", -0.35, 0.60, 0.10),
    ("right_far", -0.45, 0.50, 0.30),
    ("left_across", 0.12, 0.65, 0.22),
    ("low_right", -0.25, 0.20, 0.25),
    ("step_far", -0.10, 0.50, 0.70),
    ("step_low", -0.10, 0.25, 0.62),
    ("chest_near", -0.05, 0.75, 0.18),
    ("behind_right", -0.25, 0.62, -0.12),
];

/// A made-up person.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Person {
    height: f64,
    flexibility: f64,
    mean_speed: f64,
    r_st: f64,
    r_tw: f64,
    p_max: f64,
}

/// The reach tolerance of a set made with a person's synergy, meters ([`make_set_driven`]):
/// 0.1 mm. The synergy arrives within half of it, so each clip the synergy finishes ends
/// within 0.05 mm of its target — where a fit, which takes the hand's last position for the
/// target, aims. (At 2 mm the clips ended up to 1 mm short, and the person's own vector,
/// aimed at the last hand position, retraced them to only 0.5–1 mm.)
pub const SYNERGY_TOLERANCE: f64 = 0.0001;

/// Writes the set into `dir` (created if needed). Returns the manifest rows.
pub fn make_set(dir: &Path, settings: &SynthSettings) -> Result<Vec<ManifestRow>> {
    Ok(make_set_driven(dir, settings, &ArmDrive::Profile)?
        .into_iter()
        .map(|(row, _)| row)
        .collect())
}

/// [`make_set`] with every reaching arm driven by `drive` — with [`ArmDrive::Synergy`], a set
/// in one person's style (the same persons' bodies and the same targets, drawn again only
/// where a reach is not reached). Returns each clip's manifest row and the frames its arm
/// was driven by the synergy (from the arm controller's start to the end, or to the
/// hand-over; the arm controller's frames for [`ArmDrive::Profile`]).
pub fn make_set_driven(
    dir: &Path,
    settings: &SynthSettings,
    drive: &ArmDrive,
) -> Result<Vec<(ManifestRow, Range<usize>)>> {
    require(settings.persons >= 1, "persons", "at least 1")?;
    require(settings.reaches >= 1, "reaches", "at least 1")?;
    require(
        settings.frame_rate > 0.0 && settings.frame_rate.is_finite(),
        "frame_rate",
        "a positive number of frames per second",
    )?;
    let io = |path: &Path, e: std::io::Error| ReachError::Io {
        path: path.to_path_buf(),
        source: kinergy_io::describe_full_disk(e),
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let mut rows = Vec::new();
    for p in 0..settings.persons {
        let mut rng = ChaCha8Rng::seed_from_u64(mix(settings.seed, p as u64, u64::MAX));
        let person = Person {
            height: rng.random_range(1.55..1.95),
            flexibility: rng.random_range(0.6..3.0),
            mean_speed: rng.random_range(0.35..0.6),
            r_st: rng.random_range(0.3..0.7),
            r_tw: rng.random_range(0.3..0.7),
            p_max: rng.random_range(0.6..0.95),
        };
        let character = Character::new(&Proportions::from_height(person.height)?)?;
        let id = format!("p{:02}", p + 1);
        let folder = dir.join(&id);
        std::fs::create_dir_all(&folder).map_err(|e| io(&folder, e))?;
        let arm = character.proportions().arm(Side::Right);
        let steps = StepSettings {
            p_max: person.p_max,
            ..StepSettings::for_arm_length(arm.upper_arm + arm.forearm + arm.hand)?
        };
        for r in 0..settings.reaches {
            let (kind, kx, ky, kz) = KINDS[r % KINDS.len()];
            let mut made = None;
            for attempt in 0..20u64 {
                let seed = mix(settings.seed, p as u64, (r as u64) << 8 | attempt);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let h = person.height;
                let jitter = |rng: &mut ChaCha8Rng| rng.random_range(-0.04..0.04);
                let target = Point3::new(
                    kx * h + jitter(&mut rng),
                    (ky * h + jitter(&mut rng)).max(0.03),
                    kz * h + jitter(&mut rng),
                );
                let reach_settings = ReachSettings {
                    frame_rate: settings.frame_rate,
                    profile: SpeedProfile::MinimumJerk {
                        timing: BellTiming::MeanSpeed {
                            speed: person.mean_speed,
                        },
                    },
                    steps: Some(steps),
                    flexibility: person.flexibility,
                    r_st: person.r_st,
                    r_tw: person.r_tw,
                    arm: Some(Side::Right),
                    seed,
                    // A synergy closes in asymptotically and stops within half the tolerance:
                    // 0.05 mm here, so that the clip ends where its target is (a fit takes the
                    // hand's last position for the target).
                    tolerance: match drive {
                        ArmDrive::Profile => ReachSettings::default().tolerance,
                        ArmDrive::Synergy { .. } => SYNERGY_TOLERANCE,
                    },
                    ..ReachSettings::default()
                };
                let motion = reach_full_body_driven(&character, target, &reach_settings, drive)?;
                if motion.report.stop == ReachStop::Reached {
                    made = Some((motion, target, seed));
                    break;
                }
            }
            let (motion, target, seed) = made.ok_or_else(|| ReachError::Setting {
                field: "synth".into(),
                why: format!("{id}: no `{kind}` target drawn in 20 tries was reached"),
            })?;
            let clip = character.to_clip(&motion.poses, motion.frame_time)?;
            let mut bvh = kinergy_motion::clip_to_bvh(&clip, &Default::default());
            for v in &mut bvh.motion {
                *v = (*v * 1e4).round() / 1e4;
                if *v == 0.0 {
                    *v = 0.0; // no "-0"
                }
            }
            let name = format!("r{:02}.bvh", r + 1);
            let path = folder.join(&name);
            let mut bytes = Vec::new();
            kinergy_bvh::write(&bvh, &mut bytes).map_err(|e| ReachError::Setting {
                field: "output".into(),
                why: e.to_string(),
            })?;
            kinergy_io::write_atomic(&path, &bytes).map_err(|e| io(&path, e))?;
            let rep = &motion.report;
            let driven_end = rep.hand_over.map_or(rep.frames, |h| {
                ((h.at_s * settings.frame_rate).round() as usize).min(rep.frames)
            });
            let driven = rep.arm_onset_frame.min(driven_end)..driven_end;
            rows.push((
                ManifestRow {
                    clip: format!("{id}/{name}"),
                    person: id.clone(),
                    height_m: person.height,
                    flexibility: person.flexibility,
                    mean_speed_m_s: person.mean_speed,
                    r_st: person.r_st,
                    r_tw: person.r_tw,
                    p_max: person.p_max,
                    kind,
                    target_x: target.x,
                    target_y: target.y,
                    target_z: target.z,
                    step: rep.step.name().to_string(),
                    step_length_m: rep.step_length,
                    twist_deg: rep.twist_deg,
                    swing_deg: rep.swing_deg,
                    squat_m: rep.squat_m,
                    final_error_m: rep.final_error,
                    frames: rep.frames,
                    seed,
                },
                driven,
            ));
        }
    }
    Ok(rows)
}

/// SplitMix64-style mixing of a seed with two indices.
fn mix(seed: u64, a: u64, b: u64) -> u64 {
    let mut z =
        seed ^ a.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ b.wrapping_mul(0xd1b5_4a32_d192_ed03);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
