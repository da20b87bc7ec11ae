//! `kinergy reach`: one full-body reach toward a target, written as BVH.

use std::path::PathBuf;

use kinergy_motion::Side;
use kinergy_reach::character::Proportions;
use kinergy_reach::controller::{ArmDriveKind, Ending, ReachSettings};
use kinergy_reach::drive::{HEIGHT_M, PersonReach, PersonReachReport, Profile, check_settings};

use crate::common::{Failure, ReadArgs, check_range, emit, length, print_json};

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
    #[arg(long, default_value_t = kinergy_reach::drive::DEFAULT_HEIGHT_M, value_name = "H")]
    pub height: f64,
    /// Leg flexibility, 0.1 to 10: higher squats, lower stoops.
    #[arg(long, default_value_t = 1.0, value_name = "F")]
    pub flexibility: f64,
    /// The reaching arm (default: the one on the target's side).
    #[arg(long, value_name = "SIDE")]
    pub arm: Option<Side>,
    /// The hand's speed profile: `ease-out` (Huang's: constant speed, then constant
    /// deceleration, v_s = 20 cm/s, r_s = 0.8) or `minimum-jerk` (a bell, like human hand
    /// speed).
    #[arg(long, default_value_t = Profile::EaseOut, value_parser = crate::common::named::<Profile>(Profile::ALL.map(Profile::name)))]
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

/// Runs `kinergy reach`: the request ([`PersonReach`]) from the flags, run, the motion
/// written and the report said.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    check_range("--height", args.height, HEIGHT_M)?;
    let settings = ReachSettings {
        flexibility: args.flexibility,
        seed: args.seed,
        timeout: args.timeout,
        arm: args.arm,
        profile: args.profile.speed_profile(),
        ..ReachSettings::default()
    };
    check_settings(&settings).map_err(|e| Failure::Input(format!("--{} {}", e.field, e.why)))?;
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
    let person = args
        .params
        .as_deref()
        .map(crate::common::read_person)
        .transpose()?;
    let request = PersonReach {
        target,
        proportions,
        settings,
        person: person
            .as_ref()
            .map(|p| p as &dyn kinergy_solver::PersonStyle),
    };
    let done = request.run().map_err(|e| match &args.params {
        Some(path) => crate::common::person_failure(path, e),
        None => e.into(),
    })?;
    crate::common::write_clip(&args.output, &done.clip, &Default::default())?;
    let report = PersonReachReport {
        output: Some(args.output.display().to_string()),
        ..done.report
    };
    let r = &report.reach;
    if args.json {
        print_json(&report)?;
    } else {
        emit(&format!(
            "{}: {} ({} frames, {:.2} s), arm {}, step {} ({:.2} m), twist {:.0}°, swing {:.0}°, {} (squat {:.2} m), hand {} from the target\n",
            args.output.display(),
            short(done.ending),
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
    match done.ending {
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
