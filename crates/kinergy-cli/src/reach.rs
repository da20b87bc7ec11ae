//! `kinergy reach`: one full-body reach toward a target, written as BVH.

use std::path::PathBuf;

use kinergy_motion::Side;
use kinergy_reach::character::Proportions;
use kinergy_reach::controller::{ArmDriveKind, Ending, ReachSettings};
use kinergy_reach::drive::{
    HEIGHT_M, HuangKnobs, PersonReach, PersonReachReport, Profile, check_settings,
};

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
    pub knobs: Knobs,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Huang, Kapadia & Terzopoulos's handles on varied motion; each one not given keeps the
/// paper's default ([`HuangKnobs`]).
#[derive(Debug, clap::Args)]
#[command(next_help_heading = "Huang et al.'s knobs (default: the paper's)")]
pub struct Knobs {
    /// v_s, the ease-out hand's start speed, m/s, 0.01 to 5 (0.20).
    #[arg(long = "v-s", value_name = "M/S")]
    pub v_s: Option<f64>,
    /// r_s, the ease-out's constant-speed share of its time, in (0, 1] (0.8).
    #[arg(long = "r-s", value_name = "SHARE")]
    pub r_s: Option<f64>,
    /// r_st, the share of the step after which the arm, head and twist start, 0 to 1 (0.5).
    #[arg(long = "r-st", value_name = "SHARE")]
    pub r_st: Option<f64>,
    /// r_tw, the share of the twist after which the swing, COM shift and squat start, 0 to 1
    /// (0.5).
    #[arg(long = "r-tw", value_name = "SHARE")]
    pub r_tw: Option<f64>,
    /// The comfortable reaching angle's half-width about the chest's forward direction,
    /// degrees, 1 to 179 (40): a target beyond it twists the spine.
    #[arg(long, value_name = "DEG")]
    pub comfortable_angle_deg: Option<f64>,
    /// The vertical shoulder–target distance beyond which the spine swings, meters, 0 to 2.5
    /// (0.35).
    #[arg(long, value_name = "M")]
    pub start_swing_distance_m: Option<f64>,
    /// The head's largest turning speed, degrees per second, 1 to 2000 (143).
    #[arg(long, value_name = "DEG/S")]
    pub head_speed_deg_s: Option<f64>,
    /// P_max, the half step's probability for a target at the convenient reaching range, 0
    /// to 1 (0.9).
    #[arg(long = "p-max", value_name = "P")]
    pub p_max: Option<f64>,
    /// P_min, the half step's probability for a target at the maximal reaching range, 0 to
    /// P_max (0.1).
    #[arg(long = "p-min", value_name = "P")]
    pub p_min: Option<f64>,
}

impl Knobs {
    /// The library's knobs.
    fn knobs(&self) -> HuangKnobs {
        HuangKnobs {
            v_s: self.v_s,
            r_s: self.r_s,
            r_st: self.r_st,
            r_tw: self.r_tw,
            comfortable_angle_deg: self.comfortable_angle_deg,
            start_swing_distance_m: self.start_swing_distance_m,
            head_speed_deg_s: self.head_speed_deg_s,
            p_max: self.p_max,
            p_min: self.p_min,
        }
    }
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
    let flag = |e: kinergy_io::InvalidSetting| {
        Failure::Input(format!("--{} {}", e.field.replace('_', "-"), e.why))
    };
    let settings = args.knobs.knobs().apply(settings).map_err(flag)?;
    check_settings(&settings).map_err(flag)?;
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
