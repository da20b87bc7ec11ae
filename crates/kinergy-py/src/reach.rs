//! `kinergy.reach`: one full-body reach, the library's [`PersonReach`] from Python's
//! arguments.

use kinergy_motion::{ImportOptions, Side};
use kinergy_reach::character::Proportions;
use kinergy_reach::controller::ReachSettings;
use kinergy_reach::drive::{HuangKnobs, PersonReach, Profile, check_settings, check_target};
use kinergy_train::limits;
use pyo3::prelude::*;

use crate::args::{Arg, ClipArg, ParamsArg, parse};
use crate::clip::Clip;
use crate::errors;

/// One full-body reach of the 43-DoF character toward `target` (world meters, the
/// character standing at the origin facing +z), as `kinergy reach` makes it: stepping,
/// twisting, bending and squatting as needed. With `params` (a person's Params or its
/// file), the person's synergy drives the arm (their style); without, the speed profile.
///
/// height: the character's height in meters, default 1.75 (or `person`: a BVH whose skeleton gives the
/// proportions). flexibility, arm ("right"/"left", default: the nearer), profile
/// ("ease-out" or "minimum-jerk"), seed, timeout (seconds): as the CLI's options. check:
/// raise UnreachableError (its `clip` holds the motion) when the hand does not arrive.
/// Huang et al.'s knobs, each None for the paper's default (as the CLI's flags): v_s (m/s),
/// r_s, r_st, r_tw, comfortable_angle_deg, start_swing_distance_m, head_speed_deg_s, p_max,
/// p_min.
#[pyfunction]
#[pyo3(signature = (target, *, params = None, height = None, person = None, flexibility = 1.0, arm = None, profile = "ease-out", seed = 0, timeout = None, check = true, v_s = None, r_s = None, r_st = None, r_tw = None, comfortable_angle_deg = None, start_swing_distance_m = None, head_speed_deg_s = None, p_max = None, p_min = None))]
#[allow(clippy::too_many_arguments)]
pub fn reach<'py>(
    py: Python<'py>,
    target: [f64; 3],
    params: Option<Arg<ParamsArg>>,
    height: Option<f64>,
    person: Option<Arg<ClipArg>>,
    flexibility: f64,
    arm: Option<&str>,
    profile: &str,
    seed: u64,
    timeout: Option<f64>,
    check: bool,
    v_s: Option<f64>,
    r_s: Option<f64>,
    r_st: Option<f64>,
    r_tw: Option<f64>,
    comfortable_angle_deg: Option<f64>,
    start_swing_distance_m: Option<f64>,
    head_speed_deg_s: Option<f64>,
    p_max: Option<f64>,
    p_min: Option<f64>,
) -> PyResult<Clip> {
    let defaults = ReachSettings::default();
    let settings = ReachSettings {
        flexibility,
        seed,
        timeout: timeout.unwrap_or(defaults.timeout),
        arm: arm.map(|a| parse::<Side>("arm", a)).transpose()?,
        profile: profile
            .parse::<Profile>()
            .map_err(errors::raise)?
            .speed_profile(),
        ..defaults
    };
    let settings = HuangKnobs {
        v_s,
        r_s,
        r_st,
        r_tw,
        comfortable_angle_deg,
        start_swing_distance_m,
        head_speed_deg_s,
        p_max,
        p_min,
    }
    .apply(settings)
    .map_err(errors::raise)?;
    let target = kinergy_motion::nalgebra::Point3::new(target[0], target[1], target[2]);
    check_target(&target).map_err(errors::raise)?;
    check_settings(&settings).map_err(errors::raise)?;
    if person.is_some() && height.is_some() {
        return Err(errors::input(
            "height= and person= both give the body's size: give one (person= takes the \
             proportions of its skeleton)",
        ));
    }
    let height = height.unwrap_or(kinergy_reach::drive::DEFAULT_HEIGHT_M);
    errors::check_range("height", height, limits::REACH_HEIGHT)?;
    let proportions = match person {
        Some(p) => {
            let (clip, path) = p.0.load(py, &ImportOptions::default())?;
            Proportions::from_clip(&clip)
                .map_err(|e| errors::input(format!("{}: {e}", path.display())))?
        }
        None => Proportions::from_height(height)
            .map_err(|e| errors::input(format!("height={height}: {e}")))?,
    };
    let person = params.map(|p| p.0.load()).transpose()?;
    let request = PersonReach {
        target,
        proportions,
        settings,
        person: person
            .as_ref()
            .map(|p| p as &dyn kinergy_solver::PersonStyle),
    };
    let done = py.detach(|| request.run()).map_err(errors::raise)?;
    let arrived = done.arrived();
    let out = Clip::made(done.clip).with_report(&done.report);
    match arrived {
        Err(e) if check => Err(crate::clip::unreachable(py, e.to_string(), out)),
        _ => Ok(out),
    }
}
