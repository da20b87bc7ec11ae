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
//! again (up to 20 times), so every clip ends at its target. Reaches use the right arm, so
//! one `--arm` setting reads a set of one-hand takes; a [share](SynthSettings::both_hands) of
//! the takes may reach with both hands one after the other (the right hand reaches and
//! returns, then the left reaches toward the mirrored target), as a library's both-hands
//! raises do: two reaches in one take, which `--arm auto` reads as one reach per arm.
//!
//! The set is made in memory ([`SynthSet::make`]: each clip with its manifest row and the
//! frames its arm was driven) and written in one place ([`SynthSet::write`], or
//! [`write_set`], which makes and writes one person at a time). Files: `DIR/pNN/rNN.bvh`
//! (one folder per person, which `kinergy compare` reads as one person) at
//! [`SynthSettings::frame_rate`], written in centimeters with channel values rounded to 4
//! decimals (0.001 mm, 0.0001°) to keep the set small, and `DIR/manifest.csv`
//! ([`MANIFEST`]). The BVH text is kinergy-motion's ([`kinergy_motion::clip_to_bvh`]).

use std::ops::Range;
use std::path::{Path, PathBuf};

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{Clip, Side};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use serde::Serialize;

use crate::character::{Character, Proportions};
use crate::controller::{ReachSettings, ReachStop, SynergyTempo, reach_full_body_driven};
use crate::drive::Driver;
use crate::error::{ReachError, Result};
use crate::profile::{BellTiming, SpeedProfile};
use crate::steps::{self, StepDecision, StepSettings};
use kinergy_motion::seed::mix;

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
    /// A person's synergy arm's controller; `None` (the default): the one their parameters
    /// were fitted under ([`ReachSettings::synergy_controller`]).
    pub synergy_controller: Option<kinergy_solver::ControllerKind>,
    /// The share of each person's takes that reach with both hands (0 to 1, default 0),
    /// spread evenly over the takes ([`is_both_hands`]): the right hand reaches its target
    /// and returns the way it came, then the left hand reaches toward the target mirrored
    /// across the body (a redrawn one where the person does not reach it).
    pub both_hands: f64,
}

impl Default for SynthSettings {
    fn default() -> SynthSettings {
        SynthSettings {
            persons: 4,
            reaches: 14,
            seed: 2026,
            frame_rate: 60.0,
            synergy_controller: None,
            both_hands: 0.0,
        }
    }
}

/// The manifest's file name in the set's folder.
pub const MANIFEST: &str = "manifest.csv";

/// One row of `manifest.csv`: one reach (a one-hand take has one, a both-hands take two, the
/// right hand's first).
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
    /// The kind of target (where a person reaches none of 20 draws of it, the target is the
    /// first draw pulled toward `front_near` that they reach).
    pub kind: &'static str,
    /// Target, world meters.
    pub target_x: f64,
    /// Target, world meters.
    pub target_y: f64,
    /// Target, world meters.
    pub target_z: f64,
    /// The step decision, by its [name](StepDecision::name).
    #[serde(serialize_with = "steps::serialize_name")]
    pub step: StepDecision,
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
    /// The reach's frames (a one-hand take's whole clip).
    pub frames: usize,
    /// The reach's own seed.
    pub seed: u64,
    /// The arm that reaches.
    pub arm: Side,
    /// The clip's frame the reach starts on (0 but for a both-hands take's left reach, which
    /// starts where the right hand is back): the reach is frames `first_frame..first_frame +
    /// frames` of the clip.
    pub first_frame: usize,
}

/// Draws of a reach's target before they are pulled toward the first kind's (see
/// `make_person`).
const DRAWS: u64 = 20;

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

/// The reach tolerance of a set made with a person's synergy, meters ([`SynthSet::make`]):
/// 0.1 mm. The synergy arrives within half of it, so each clip the synergy finishes ends
/// within 0.05 mm of its target — where a fit, which takes the hand's last position for the
/// target, aims. (At 2 mm the clips ended up to 1 mm short, and the person's own vector,
/// aimed at the last hand position, retraced them to only 0.5–1 mm.)
pub const SYNERGY_TOLERANCE: f64 = 0.0001;

/// One reach of a synthetic set's clip: its manifest row and what a fit of it needs.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthReach {
    /// Its row of `manifest.csv`; [`ManifestRow::clip`] is where its clip is written in the
    /// set's folder.
    pub row: ManifestRow,
    /// The clip's frames its arm was driven by a person's synergy: from the arm controller's
    /// start to the end, or to the hand-over (the arm controller's frames with
    /// [`Driver::Profile`]).
    pub driven: Range<usize>,
    /// The tempo the person's synergy's smooth controller was bounded by
    /// ([`crate::controller::ReachReport::synergy_tempo`]).
    pub tempo: Option<SynergyTempo>,
}

/// One clip of a synthetic set, made in memory.
#[derive(Debug, Clone)]
pub struct SynthClip {
    /// Its reaches in time order: one, or a both-hands take's right then left.
    pub reaches: Vec<SynthReach>,
    /// The motion, at [`SynthSettings::frame_rate`].
    pub clip: Clip,
}

impl SynthClip {
    /// Where it is written in the set's folder (`pNN/rNN.bvh`).
    pub fn path(&self) -> &str {
        self.reaches.first().map_or("", |r| r.row.clip.as_str())
    }
}

/// A synthetic set made in memory: its clips in the manifest's order (person by person).
#[derive(Debug, Clone)]
pub struct SynthSet {
    /// The clips.
    pub clips: Vec<SynthClip>,
}

impl SynthSet {
    /// Makes the set in memory, every reaching arm driven by `drive` — with
    /// [`Driver::Person`], a set in one person's style (the same persons' bodies and the
    /// same targets, drawn again only where a reach is not reached).
    pub fn make(settings: &SynthSettings, drive: Driver<'_>) -> Result<SynthSet> {
        check(settings)?;
        let mut clips = Vec::new();
        for p in 0..settings.persons {
            clips.extend(make_person(settings, drive, p)?);
        }
        Ok(SynthSet { clips })
    }

    /// Its manifest rows, in order.
    pub fn rows(&self) -> impl Iterator<Item = &ManifestRow> {
        self.clips
            .iter()
            .flat_map(|c| c.reaches.iter().map(|r| &r.row))
    }

    /// Writes the set into `dir` (created if needed): the clips and `manifest.csv`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        create_dir(dir)?;
        for clip in &self.clips {
            write_clip(dir, clip)?;
        }
        write_manifest(dir, self.rows())
    }
}

/// Person `p`'s folder name in a set (0-based `p`): `p01`, `p02`, …
fn person_id(p: usize) -> String {
    format!("p{:02}", p + 1)
}

/// Reach `r` of person `p` (0-based) as the set names it: `p01/r01.bvh`, …
fn clip_name(p: usize, r: usize) -> String {
    format!("{}/r{:02}.bvh", person_id(p), r + 1)
}

/// Every file a set made with `settings` holds, relative to its folder: each clip
/// (`pNN/rNN.bvh`) and the manifest ([`MANIFEST`]). Known before the set is made, so that a
/// caller can check it replaces nothing it must keep.
pub fn set_files(settings: &SynthSettings) -> Vec<PathBuf> {
    let clips = (0..settings.persons)
        .flat_map(|p| (0..settings.reaches).map(move |r| PathBuf::from(clip_name(p, r))));
    clips.chain([PathBuf::from(MANIFEST)]).collect()
}

/// Makes the set ([`SynthSet::make`]) and writes it into `dir` ([`SynthSet::write`]) one
/// person at a time, so that only one person's clips are in memory at once (a large set at a
/// high frame rate need not fit). Returns what it wrote of each reach.
pub fn write_set(
    dir: &Path,
    settings: &SynthSettings,
    drive: Driver<'_>,
) -> Result<Vec<SynthReach>> {
    check(settings)?;
    create_dir(dir)?;
    let mut made = Vec::new();
    for p in 0..settings.persons {
        for clip in make_person(settings, drive, p)? {
            write_clip(dir, &clip)?;
            made.extend(clip.reaches);
        }
    }
    write_manifest(dir, made.iter().map(|c| &c.row))?;
    Ok(made)
}

/// The settings a set can be made with.
fn check(settings: &SynthSettings) -> Result<()> {
    InvalidSetting::require(settings.persons >= 1, "persons", "at least 1")?;
    InvalidSetting::require(settings.reaches >= 1, "reaches", "at least 1")?;
    InvalidSetting::require(
        settings.frame_rate > 0.0 && settings.frame_rate.is_finite(),
        "frame_rate",
        "a positive number of frames per second",
    )?;
    InvalidSetting::require(
        (0.0..=1.0).contains(&settings.both_hands),
        "both_hands",
        "a share from 0 to 1",
    )?;
    Ok(())
}

/// Whether take `r` (0-based) of a person is a both-hands take when a `share` of the takes
/// are: the takes where ⌊(r + 1)·share⌋ passes ⌊r·share⌋, spread evenly (every take for 1,
/// every second for 0.5, none for 0).
pub fn is_both_hands(r: usize, share: f64) -> bool {
    ((r + 1) as f64 * share).floor() > (r as f64 * share).floor()
}

/// Person `p`'s clips (`pNN/rNN.bvh`), in memory.
fn make_person(settings: &SynthSettings, drive: Driver<'_>, p: usize) -> Result<Vec<SynthClip>> {
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
    let id = person_id(p);
    let arm = character.proportions().arm(Side::Right);
    let steps = StepSettings {
        p_max: person.p_max,
        ..StepSettings::for_arm_length(arm.upper_arm + arm.forearm + arm.hand)?
    };
    let maker = ReachMaker {
        settings,
        drive,
        character: &character,
        person,
        steps,
        id: &id,
        p,
    };
    let mut clips = Vec::with_capacity(settings.reaches);
    for r in 0..settings.reaches {
        let (right, motion) = maker.reach(r, Side::Right, 0)?;
        if !is_both_hands(r, settings.both_hands) {
            let clip = character.to_clip(&motion.poses, motion.frame_time)?;
            clips.push(SynthClip {
                reaches: vec![right],
                clip,
            });
            continue;
        }
        // The right hand reaches and comes back the way it went (its first frame is the rest
        // posture every reach starts from), then the left hand reaches.
        let back = motion.poses.len() - 1;
        let first_frame = 2 * back;
        let (left, left_motion) = maker.reach(r, Side::Left, first_frame)?;
        let mut poses = motion.poses.clone();
        poses.extend(motion.poses.iter().rev().skip(1).cloned());
        poses.extend(left_motion.poses.iter().skip(1).cloned());
        let clip = character.to_clip(&poses, motion.frame_time)?;
        clips.push(SynthClip {
            reaches: vec![right, left],
            clip,
        });
    }
    Ok(clips)
}

/// What one person's reaches are made with.
struct ReachMaker<'a> {
    settings: &'a SynthSettings,
    drive: Driver<'a>,
    character: &'a Character,
    person: Person,
    steps: StepSettings,
    id: &'a str,
    p: usize,
}

/// The seed tag of a both-hands take's left reach (its right reach draws as a one-hand take's).
const LEFT_TAG: u64 = 1 << 40;

impl ReachMaker<'_> {
    /// Take `r`'s reach of the arm `side` (the left arm's target is the right's kind mirrored
    /// across the body), starting on the clip's frame `first_frame`: its manifest row and
    /// motion.
    fn reach(
        &self,
        r: usize,
        side: Side,
        first_frame: usize,
    ) -> Result<(SynthReach, crate::controller::ReachMotion)> {
        let (settings, person, p) = (self.settings, self.person, self.p);
        let (kind, kx, ky, kz) = KINDS[r % KINDS.len()];
        let mirror = match side {
            Side::Right => 1.0,
            Side::Left => -1.0,
        };
        let tag = match side {
            Side::Right => 0,
            Side::Left => LEFT_TAG,
        };
        let mut made = None;
        for attempt in 0..2 * DRAWS {
            let seed = mix(settings.seed, p as u64, ((r as u64) << 8 | attempt) | tag);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let h = person.height;
            let jitter = |rng: &mut ChaCha8Rng| rng.random_range(-0.04..0.04);
            // After DRAWS draws out of this person's reach (a stiff, tall person and a target
            // on the floor), each further draw is pulled toward the comfortable `front_near`
            // point by another 1/DRAWS of the way: the set is made, its target the nearest to
            // the kind's that the person reaches.
            let pull = attempt.saturating_sub(DRAWS - 1) as f64 / DRAWS as f64;
            let (_, nx, ny, nz) = KINDS[0];
            let toward = |k: f64, n: f64| k + pull * (n - k);
            let target = Point3::new(
                mirror * toward(kx, nx) * h + jitter(&mut rng),
                (toward(ky, ny) * h + jitter(&mut rng)).max(0.03),
                toward(kz, nz) * h + jitter(&mut rng),
            );
            let reach_settings = ReachSettings {
                frame_rate: settings.frame_rate,
                synergy_controller: settings.synergy_controller,
                profile: SpeedProfile::MinimumJerk {
                    timing: BellTiming::MeanSpeed {
                        speed: person.mean_speed,
                    },
                },
                steps: Some(self.steps),
                flexibility: person.flexibility,
                r_st: person.r_st,
                r_tw: person.r_tw,
                arm: Some(side),
                seed,
                // A synergy closes in asymptotically and stops within half the tolerance:
                // 0.05 mm here, so that the clip ends where its target is (a fit takes the
                // hand's last position for the target).
                tolerance: if self.drive.is_person() {
                    SYNERGY_TOLERANCE
                } else {
                    ReachSettings::default().tolerance
                },
                ..ReachSettings::default()
            };
            let arm = self.drive.toward(self.character, &target, Some(side))?;
            let motion = reach_full_body_driven(self.character, target, &reach_settings, &arm)?;
            if motion.report.stop == ReachStop::Reached {
                made = Some((motion, target, seed));
                break;
            }
        }
        let (motion, target, seed) = made.ok_or_else(|| {
            ReachError::Setting(InvalidSetting::new(
                "synth",
                format!(
                    "{}: no `{kind}` target of the {side} hand drawn in {} tries was reached, \
                     even pulled to `{}`",
                    self.id,
                    2 * DRAWS,
                    KINDS[0].0
                ),
            ))
        })?;
        let rep = &motion.report;
        // The frames the person's synergy drove alone: to a hand-over, or to the first frame
        // the character's limits held the arm off the synergy's step (a fit of later frames
        // could not retrace them).
        let frame_at = |s: f64| ((s * settings.frame_rate).round() as usize).min(rep.frames);
        let driven_end = [rep.hand_over.map(|h| h.at_s), rep.synergy_limited_at_s]
            .into_iter()
            .flatten()
            .map(frame_at)
            .fold(rep.frames, usize::min);
        let driven = first_frame + rep.arm_onset_frame.min(driven_end)..first_frame + driven_end;
        let reach = SynthReach {
            row: ManifestRow {
                clip: clip_name(p, r),
                person: self.id.to_string(),
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
                step: rep.step,
                step_length_m: rep.step_length,
                twist_deg: rep.twist_deg,
                swing_deg: rep.swing_deg,
                squat_m: rep.squat_m,
                final_error_m: rep.final_error,
                frames: rep.frames,
                seed,
                arm: side,
                first_frame,
            },
            driven,
            tempo: rep.synergy_tempo,
        };
        Ok((reach, motion))
    }
}

/// A file or folder that could not be written.
fn io_error(path: &Path, e: std::io::Error) -> ReachError {
    ReachError::Io {
        path: path.to_path_buf(),
        source: kinergy_io::describe_full_disk(e),
    }
}

/// Creates `dir` and its parents if needed.
fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))
}

/// Writes `clip` into the set's folder `dir` (its person's folder created if needed), in
/// centimeters with the channel values rounded to 4 decimals (0.001 mm, 0.0001°).
fn write_clip(dir: &Path, clip: &SynthClip) -> Result<()> {
    let path = dir.join(clip.path());
    if let Some(folder) = path.parent() {
        create_dir(folder)?;
    }
    let mut bvh = kinergy_motion::clip_to_bvh(&clip.clip, &Default::default());
    for v in &mut bvh.motion {
        *v = (*v * 1e4).round() / 1e4;
        if *v == 0.0 {
            *v = 0.0; // no "-0"
        }
    }
    let mut bytes = Vec::new();
    kinergy_motion::kinergy_bvh::write(&bvh, &mut bytes)
        .map_err(|e| ReachError::Setting(InvalidSetting::new("output", e.to_string())))?;
    kinergy_io::write_atomic(&path, &bytes).map_err(|e| io_error(&path, e))
}

/// Writes `dir/manifest.csv` with `rows`.
fn write_manifest<'a>(dir: &Path, rows: impl IntoIterator<Item = &'a ManifestRow>) -> Result<()> {
    let path = dir.join(MANIFEST);
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in rows {
        w.serialize(row)
            .map_err(|e| io_error(&path, std::io::Error::other(e)))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| io_error(&path, e.into_error()))?;
    kinergy_io::write_atomic(&path, &bytes).map_err(|e| io_error(&path, e))
}
