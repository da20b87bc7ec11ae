//! Huang, Kapadia & Terzopoulos's handles on varied motion, as a user gives them (`kinergy
//! reach` flags, Python's `reach` keywords): the ease-out's start speed v_s and start-phase
//! ratio r_s (§3.3), the scheduler's r_st and r_tw (§4), the comfortable reaching angle and the
//! start swing distance (§3.4), the head's speed (§3.6) and the half step's probabilities
//! P_max and P_min (§3.5). Each one not given keeps the paper's default; each given one is
//! checked against its range here, once, for both front ends.

use kinergy_io::InvalidSetting;

use crate::controller::ReachSettings;
use crate::profile::SpeedProfile;

/// The knobs a user set; `None`: the paper's default.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HuangKnobs {
    /// v_s, the ease-out's start speed, m/s (the paper's 0.20), within [`V_S`].
    pub v_s: Option<f64>,
    /// r_s, the ease-out's constant-speed share of its time (the paper's 0.8), in (0, 1].
    pub r_s: Option<f64>,
    /// r_st, the share of the step after which the arm, head and twist start (0.5), in [0, 1].
    pub r_st: Option<f64>,
    /// r_tw, the share of the twist after which the swing, COM shift and squat start (0.5),
    /// in [0, 1].
    pub r_tw: Option<f64>,
    /// The comfortable reaching angle's half-width about the chest's forward direction,
    /// degrees (40), within [`COMFORTABLE_ANGLE_DEG`].
    pub comfortable_angle_deg: Option<f64>,
    /// The vertical shoulder–target distance beyond which the spine swings, meters (0.35),
    /// within [`START_SWING_DISTANCE_M`].
    pub start_swing_distance_m: Option<f64>,
    /// The head's largest turning speed, degrees per second (143, the 2.5 rad/s default),
    /// within [`HEAD_SPEED_DEG_S`].
    pub head_speed_deg_s: Option<f64>,
    /// P_max, the half step's probability for a target at the CRR (0.9), in [0, 1].
    pub p_max: Option<f64>,
    /// P_min, the half step's probability for a target at the MRR (0.1), in [0, P_max].
    pub p_min: Option<f64>,
}

/// v_s's range, m/s.
pub const V_S: (f64, f64) = (0.01, 5.0);
/// The comfortable angle's range, degrees.
pub const COMFORTABLE_ANGLE_DEG: (f64, f64) = (1.0, 179.0);
/// The start swing distance's range, meters.
pub const START_SWING_DISTANCE_M: (f64, f64) = (0.0, 2.5);
/// The head speed's range, degrees per second.
pub const HEAD_SPEED_DEG_S: (f64, f64) = (1.0, 2000.0);

impl HuangKnobs {
    /// `settings` with every knob given, each checked (errors name the knob as the Python
    /// keyword does: `v_s`, `comfortable_angle_deg`, …). v_s and r_s shape the ease-out
    /// profile: with another profile they are refused.
    pub fn apply(&self, settings: ReachSettings) -> Result<ReachSettings, InvalidSetting> {
        let mut s = settings;
        if self.v_s.is_some() || self.r_s.is_some() {
            let SpeedProfile::EaseOut { v_s, r_s } = s.profile else {
                let name = if self.v_s.is_some() { "v_s" } else { "r_s" };
                return Err(InvalidSetting::new(
                    name,
                    "shapes the ease-out profile only: drop it, or reach with the ease-out \
                     profile",
                ));
            };
            let v_s = match self.v_s {
                Some(v) => InvalidSetting::in_range("v_s", v, V_S).map(|()| v)?,
                None => v_s,
            };
            let r_s = match self.r_s {
                Some(r) => {
                    InvalidSetting::require(
                        r > 0.0 && r <= 1.0,
                        "r_s",
                        format!("{r}: expected a share in (0, 1]"),
                    )?;
                    r
                }
                None => r_s,
            };
            s.profile = SpeedProfile::EaseOut { v_s, r_s };
        }
        let share = |name: &str, v: f64| {
            InvalidSetting::require(
                (0.0..=1.0).contains(&v),
                name,
                format!("{v}: expected a share in [0, 1]"),
            )
            .map(|()| v)
        };
        if let Some(v) = self.r_st {
            s.r_st = share("r_st", v)?;
        }
        if let Some(v) = self.r_tw {
            s.r_tw = share("r_tw", v)?;
        }
        if let Some(v) = self.comfortable_angle_deg {
            InvalidSetting::in_range("comfortable_angle_deg", v, COMFORTABLE_ANGLE_DEG)?;
            s.comfortable_angle = v.to_radians();
        }
        if let Some(v) = self.start_swing_distance_m {
            InvalidSetting::in_range("start_swing_distance_m", v, START_SWING_DISTANCE_M)?;
            s.start_swing_distance = v;
        }
        if let Some(v) = self.head_speed_deg_s {
            InvalidSetting::in_range("head_speed_deg_s", v, HEAD_SPEED_DEG_S)?;
            s.head_speed = v.to_radians();
        }
        if self.p_max.is_some() || self.p_min.is_some() {
            let defaults = crate::steps::StepSettings::default();
            let p_max = share("p_max", self.p_max.unwrap_or(defaults.p_max))?;
            let p_min = share("p_min", self.p_min.unwrap_or(defaults.p_min))?;
            InvalidSetting::require(
                p_min <= p_max,
                "p_min",
                format!("{p_min}: expected at most p_max = {p_max}"),
            )?;
            s.half_step_probability = Some((p_max, p_min));
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_knob_lands_in_its_setting_and_none_changes_nothing() {
        let base = ReachSettings::default();
        assert_eq!(HuangKnobs::default().apply(base), Ok(base));
        let s = HuangKnobs {
            v_s: Some(0.3),
            r_s: Some(0.6),
            r_st: Some(0.2),
            r_tw: Some(0.9),
            comfortable_angle_deg: Some(30.0),
            start_swing_distance_m: Some(0.5),
            head_speed_deg_s: Some(90.0),
            p_max: Some(0.7),
            p_min: Some(0.2),
        }
        .apply(base)
        .expect("in range");
        assert_eq!(s.profile, SpeedProfile::EaseOut { v_s: 0.3, r_s: 0.6 });
        assert_eq!((s.r_st, s.r_tw), (0.2, 0.9));
        assert!((s.comfortable_angle - 30f64.to_radians()).abs() < 1e-15);
        assert_eq!(s.start_swing_distance, 0.5);
        assert!((s.head_speed - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(s.half_step_probability, Some((0.7, 0.2)));
        s.validate().expect("valid settings");
    }

    #[test]
    fn bad_values_are_refused_naming_the_knob() {
        let base = ReachSettings::default();
        for (knobs, field) in [
            (
                HuangKnobs {
                    v_s: Some(0.0),
                    ..Default::default()
                },
                "v_s",
            ),
            (
                HuangKnobs {
                    r_s: Some(1.5),
                    ..Default::default()
                },
                "r_s",
            ),
            (
                HuangKnobs {
                    r_st: Some(-0.1),
                    ..Default::default()
                },
                "r_st",
            ),
            (
                HuangKnobs {
                    r_tw: Some(f64::NAN),
                    ..Default::default()
                },
                "r_tw",
            ),
            (
                HuangKnobs {
                    comfortable_angle_deg: Some(180.0),
                    ..Default::default()
                },
                "comfortable_angle_deg",
            ),
            (
                HuangKnobs {
                    start_swing_distance_m: Some(-1.0),
                    ..Default::default()
                },
                "start_swing_distance_m",
            ),
            (
                HuangKnobs {
                    head_speed_deg_s: Some(f64::INFINITY),
                    ..Default::default()
                },
                "head_speed_deg_s",
            ),
            (
                HuangKnobs {
                    p_min: Some(0.95),
                    ..Default::default()
                },
                "p_min",
            ),
        ] {
            let e = knobs.apply(base).expect_err(field);
            assert_eq!(e.field, field, "{e}");
        }
        let bell = ReachSettings {
            profile: SpeedProfile::MinimumJerk {
                timing: Default::default(),
            },
            ..base
        };
        let e = HuangKnobs {
            v_s: Some(0.3),
            ..Default::default()
        }
        .apply(bell)
        .expect_err("v_s with a bell");
        assert_eq!(e.field, "v_s");
        assert!(e.to_string().contains("ease-out"), "{e}");
    }
}
