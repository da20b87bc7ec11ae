//! `kinergy reach`: one full-body reach toward a target, written as BVH.

use std::path::PathBuf;

use kinergy_motion::Side;
use kinergy_reach::character::{Character, Proportions};
use kinergy_reach::controller::{
    ArmDrive, ArmDriveKind, Ending, ReachSettings, reach_full_body_driven,
};
use kinergy_reach::drive::PersonArm;
use kinergy_reach::profile::{BellTiming, SpeedProfile};
use kinergy_solver::FieldUse;
use serde::Serialize;

use crate::common::{Failure, ReadArgs, check_range, emit, length, limits, print_json};

/// The hand's speed profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Profile {
    /// The paper's: constant speed, then constant deceleration (v_s = 20 cm/s, r_s = 0.8).
    EaseOut,
    /// A minimum-jerk bell, like human hand speed.
    MinimumJerk,
}

/// Arguments of `kinergy reach`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Target hand position, world meters `x,y,z` (the character stands at the origin,
    /// facing +Z, Y up, its left at +X).
    #[arg(long, value_name = "x,y,z", allow_hyphen_values = true)]
    pub target: String,
    /// A BVH capture whose skeleton gives the character's proportions.
    #[arg(long, value_name = "FILE", conflicts_with = "height")]
    pub person: Option<PathBuf>,
    /// The character's height, meters, 0.5 to 2.5 (proportions from anthropometric ratios).
    #[arg(long, default_value_t = 1.75, value_name = "H")]
    pub height: f64,
    /// Leg flexibility, 0.1 to 10: higher squats, lower stoops.
    #[arg(long, default_value_t = 1.0, value_name = "F")]
    pub flexibility: f64,
    /// The reaching arm (default: the one on the target's side).
    #[arg(long, value_name = "SIDE")]
    pub arm: Option<Side>,
    /// The hand's speed profile.
    #[arg(long, value_enum, default_value = "ease-out")]
    pub profile: Profile,
    /// Seed of the stepping decisions.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The longest reach, seconds, 0.1 to 60.
    #[arg(long, default_value_t = ReachSettings::default().timeout, value_name = "S")]
    pub timeout: f64,
    /// Where to write the clip (BVH at 120 Hz, centimeters, written atomically).
    #[arg(short, long, value_name = "OUT.bvh")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// A person's parameters (`kinergy fit -o person.json`, or a field from `kinergy fit
    /// --field`, which predicts their vector for this target): their synergy controller drives
    /// the reaching arm instead of --profile and the analytic IK, riding the body the
    /// scheduler moves; the analytic IK finishes the last centimeters where it cannot (the
    /// report says when).
    #[arg(long, value_name = "person.json")]
    pub params: Option<PathBuf>,
    #[command(flatten)]
    pub read: ReadArgs,
}

#[derive(Serialize)]
struct Report<'a> {
    output: String,
    height_m: f64,
    target_m: [f64; 3],
    /// With `--params field.json`: how the field was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    field: Option<FieldUse>,
    #[serde(flatten)]
    reach: &'a kinergy_reach::controller::ReachReport,
}

/// Runs `kinergy reach`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    check_range("--height", args.height, limits::REACH_HEIGHT)?;
    check_range("--flexibility", args.flexibility, limits::REACH_FLEXIBILITY)?;
    check_range("--timeout", args.timeout, limits::REACH_TIMEOUT)?;
    crate::common::check_outputs(
        &args
            .person
            .iter()
            .chain(&args.params)
            .map(|p| p.as_path())
            .collect::<Vec<_>>(),
        &[crate::common::Output::File("-o", &args.output)],
    )?;
    let target = crate::common::parse_world_target(&args.target, "--target")?;
    let proportions = match &args.person {
        Some(path) => {
            let (clip, _) = args.read.read(path)?;
            Proportions::from_clip(&clip).map_err(|e| Failure::input(path, e))?
        }
        None => Proportions::from_height(args.height)
            .map_err(|e| Failure::Input(format!("--height {}: {e}", args.height)))?,
    };
    let character = Character::new(&proportions).map_err(Failure::from)?;
    let settings = ReachSettings {
        flexibility: args.flexibility,
        seed: args.seed,
        timeout: args.timeout,
        arm: args.arm,
        profile: match args.profile {
            Profile::EaseOut => SpeedProfile::default(),
            Profile::MinimumJerk => SpeedProfile::MinimumJerk {
                timing: BellTiming::default(),
            },
        },
        ..ReachSettings::default()
    };
    let mut field = None;
    let drive = match &args.params {
        Some(path) => {
            let person = crate::common::read_person(path)?;
            let arm = PersonArm::toward(&character, &person, &target, args.arm)
                .map_err(|e| crate::common::person_failure(path, e))?;
            field = arm.field;
            arm.drive
        }
        None => ArmDrive::Profile,
    };
    let motion = reach_full_body_driven(&character, target, &settings, &drive)?;
    let clip = character
        .to_clip(&motion.poses, motion.frame_time)
        .map_err(Failure::from)?;
    crate::common::write_clip(&args.output, &clip, &Default::default())?;
    let r = &motion.report;
    let report = Report {
        output: args.output.display().to_string(),
        height_m: proportions.height(),
        target_m: [target.x, target.y, target.z],
        field,
        reach: r,
    };
    let ending = Ending::of(&character, &motion);
    if args.json {
        print_json(&report)?;
    } else {
        emit(&format!(
            "{}: {} ({} frames, {:.2} s), arm {}, step {} ({:.2} m), twist {:.0}°, swing {:.0}°, {} (squat {:.2} m), hand {} from the target\n",
            report.output,
            short(ending),
            r.frames,
            r.duration,
            r.arm,
            r.step,
            r.step_length,
            r.twist_deg,
            r.swing_deg,
            r.posture,
            r.squat_m,
            length(r.final_error)
        ))?;
        if let Some(h) = &r.hand_over {
            let finish = match h.analytic_at_s {
                None => "plain IK finished".to_string(),
                Some(at) => {
                    format!("plain IK stalled too, the analytic IK finished from {at:.2} s")
                }
            };
            emit(&format!(
                "the person's synergy arm drove the hand to {} of the target and handed it over \
                 at {:.2} s ({}); {finish}\n",
                length(h.distance_m),
                h.at_s,
                h.why.name().replace('_', " ")
            ))?;
        } else if r.arm_drive == ArmDriveKind::Synergy {
            emit("the person's synergy arm drove the hand all the way\n")?;
        }
    }
    match ending {
        Ending::Reached => Ok(()),
        Ending::Beyond(by) => Err(Failure::Task(format!(
            "the target is beyond reach by {}: the motion written to {} ends with the hand at \
             the nearest point it reaches",
            length(by),
            crate::common::shown(&args.output)
        ))),
        Ending::StillMoving => Err(Failure::Task(format!(
            "the hand was still moving when --timeout {} s ran out, {} from the target: the \
             motion written to {} stops there; raise --timeout",
            args.timeout,
            length(r.final_error),
            crate::common::shown(&args.output)
        ))),
    }
}

/// How a reach ended, in a few words.
fn short(ending: Ending) -> String {
    match ending {
        Ending::Reached => "reached".into(),
        Ending::Beyond(by) => format!("beyond reach by {}", length(by)),
        Ending::StillMoving => "timed out with the hand still moving".into(),
    }
}
