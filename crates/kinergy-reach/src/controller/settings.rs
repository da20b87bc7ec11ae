//! The full-body reach's settings: every value it can be tuned with, the paper's where it
//! gives one.

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_solver::ControllerKind;
use serde::Serialize;

use crate::error::Result;
use crate::profile::SpeedProfile;
use crate::steps::StepSettings;

/// Everything a reach can be tuned with. Defaults follow the paper where it gives values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReachSettings {
    /// Frames per second of the output.
    pub frame_rate: f64,
    /// The hand's speed profile along its straight path.
    pub profile: SpeedProfile,
    /// Stepping parameters; `None`: [`StepSettings::for_arm_length`] of the reaching arm.
    pub steps: Option<StepSettings>,
    /// Leg flexibility: the stoop range is arm length / flexibility (higher squats sooner).
    pub flexibility: f64,
    /// Fraction of the step after which the arm, head and twist start (`r_st`).
    pub r_st: f64,
    /// Fraction of the twist after which the swing, COM adjustment and squat start (`r_tw`).
    pub r_tw: f64,
    /// Half-width of the comfortable reaching angle about the chest's forward direction, rad.
    pub comfortable_angle: f64,
    /// Vertical shoulder–target distance beyond which the spine swings, meters.
    pub start_swing_distance: f64,
    /// φ_max of eq. 8, rad (also the largest total swing).
    pub phi_max: f64,
    /// |r_max| of eq. 8, meters.
    pub r_max: f64,
    /// Seconds one foot takes to step.
    pub step_time: f64,
    /// Seconds the twist takes.
    pub twist_time: f64,
    /// Seconds the swing, COM adjustment and squat take.
    pub swing_time: f64,
    /// Largest head turning speed, rad/s.
    pub head_speed: f64,
    /// The hand counts as at the target within this distance, meters.
    pub tolerance: f64,
    /// The reach ends after this many seconds even if the hand is not there.
    pub timeout: f64,
    /// The COM projection is kept at least this far inside the support polygon, meters.
    pub balance_margin: f64,
    /// The reaching arm; `None`: the arm on the target's side.
    pub arm: Option<Side>,
    /// Seed of the stepping decisions.
    pub seed: u64,
    /// P_max and P_min, the half step's probability at the CRR and at the MRR (§3.5),
    /// replacing those of the step settings; `None`: theirs (0.9 and 0.1).
    pub half_step_probability: Option<(f64, f64)>,
    /// The synergy arm's (a person's parameters') controller: the smooth one
    /// (`kinergy_solver::smoothing`) or the paper's; `None` (the default): the one the person's
    /// parameters were fitted under ([`kinergy_solver::FitRecord::controller`]), as they were
    /// fitted.
    pub synergy_controller: Option<ControllerKind>,
    /// Where and how fast a person's synergy arm starts, in the fitted (capture) convention;
    /// `None` (the default): from the character's hanging arm, at rest. `style` starts it as
    /// the capture it compares with starts, as the fit did.
    pub synergy_start: Option<SynergyStart>,
}

/// The start of a person's synergy arm ([`ReachSettings::synergy_start`]): what a fit's replay
/// of a captured reach starts from ([`kinergy_solver::CaptureArm`]'s convention: the shoulder's
/// swing x, y and twist, the elbow's flexion and twist, the wrist's two swings).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SynergyStart {
    /// The arm's configuration, radians (7 DoFs).
    pub configuration: [f64; 7],
    /// Its joint velocity, rad/s.
    pub velocity: [f64; 7],
    /// The smooth controller's bounds, as the fit's replay of the same reach has them;
    /// `None`: the person's tempo over the hand's distance (the default).
    #[serde(skip)]
    pub smoothing: Option<kinergy_solver::Smoothing>,
    /// The point the synergy steers, meters beyond the wrist along the hand (0: the wrist, as
    /// a fit of captures without a hand bone steered it); `None`: the character's hand tip.
    pub hand_m: Option<f64>,
}

impl Default for ReachSettings {
    fn default() -> ReachSettings {
        ReachSettings {
            frame_rate: 120.0,
            profile: SpeedProfile::default(),
            steps: None,
            flexibility: 1.0,
            r_st: 0.5,
            r_tw: 0.5,
            comfortable_angle: 40f64.to_radians(),
            start_swing_distance: 0.35,
            phi_max: 120f64.to_radians(),
            r_max: 0.1,
            step_time: 0.6,
            twist_time: 0.7,
            swing_time: 0.9,
            head_speed: 2.5,
            tolerance: 0.01,
            timeout: 10.0,
            balance_margin: 0.01,
            arm: None,
            seed: 0,
            half_step_probability: None,
            synergy_controller: None,
            synergy_start: None,
        }
    }
}

impl ReachSettings {
    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        let positive = |v: f64| v > 0.0 && v.is_finite();
        let fraction = |v: f64| (0.0..=1.0).contains(&v);
        InvalidSetting::require(
            positive(self.frame_rate),
            "frame_rate",
            "a positive number of frames per second",
        )?;
        self.profile.validate()?;
        if let Some(s) = &self.steps {
            s.validate()?;
        }
        InvalidSetting::require(
            positive(self.flexibility),
            "flexibility",
            "a positive number",
        )?;
        InvalidSetting::require(fraction(self.r_st), "r_st", "within [0, 1]")?;
        InvalidSetting::require(fraction(self.r_tw), "r_tw", "within [0, 1]")?;
        InvalidSetting::require(
            self.comfortable_angle > 0.0 && self.comfortable_angle < std::f64::consts::PI,
            "comfortable_angle",
            "within (0, π) radians",
        )?;
        InvalidSetting::require(
            self.start_swing_distance >= 0.0 && self.start_swing_distance.is_finite(),
            "start_swing_distance",
            "≥ 0 meters",
        )?;
        InvalidSetting::require(positive(self.phi_max), "phi_max", "a positive angle")?;
        InvalidSetting::require(
            self.r_max >= 0.0 && self.r_max.is_finite(),
            "r_max",
            "≥ 0 meters",
        )?;
        for (v, f) in [
            (self.step_time, "step_time"),
            (self.twist_time, "twist_time"),
            (self.swing_time, "swing_time"),
            (self.head_speed, "head_speed"),
            (self.tolerance, "tolerance"),
            (self.timeout, "timeout"),
        ] {
            InvalidSetting::require(positive(v), f, "a positive number")?;
        }
        InvalidSetting::require(
            self.balance_margin >= 0.0 && self.balance_margin.is_finite(),
            "balance_margin",
            "≥ 0 meters",
        )?;
        if let Some((p_max, p_min)) = self.half_step_probability {
            let probability = |v: f64| (0.0..=1.0).contains(&v);
            InvalidSetting::require(probability(p_max), "p_max", "a probability in [0, 1]")?;
            InvalidSetting::require(
                probability(p_min) && p_min <= p_max,
                "p_min",
                format!("a probability in [0, p_max = {p_max}]"),
            )?;
        }
        Ok(())
    }
}
