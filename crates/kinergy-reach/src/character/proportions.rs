//! The character's measurements: segment lengths as fractions of the height ([`Ratios`]), the
//! limbs' and spine's segments in meters, and [`Proportions`], made from a height or measured
//! on a capture ([`super::measure`]).
//!
//! # Proportions
//! [`Ratios::DRILLIS_CONTINI`] — segment lengths as fractions of the standing height H after
//! Drillis & Contini (1966), as reproduced in Winter, *Biomechanics and Motor Control of Human
//! Movement*, Fig. 4.1: upper arm 0.186, forearm 0.146, hand 0.108 (wrist to fingertip),
//! thigh 0.245, shank 0.246, ankle height 0.039, foot length 0.152, shoulder width 0.259,
//! hip width 0.191, shoulder height 0.818. Our choices on top: the widths are used as the
//! distances between the shoulder and hip joint centres (the figure's are breadths, so this
//! errs a few centimeters wide); the ankle lies a quarter of the foot length ahead of the
//! heel (heel 0.038, toe 0.114); the spine joints sit at vertebral landmarks — sacral root
//! 0.550 H (0.020 above the hips), lumbar L4–L5 0.595 H, thoracic T12–L1 0.700 H, cervical
//! C7–T1 0.845 H, skull base (ear canal) 0.930 H — and the clavicle joints at the shoulder
//! height 0.818 H, 0.027 H below the cervical joint.

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use serde::{Deserialize, Serialize};

use crate::error::Result;

/// Segment lengths and joint placements as fractions of the standing height (see the
/// [module docs](self) for the sources). The vertical ones — `ankle_height`,
/// `shank`, `thigh`, `pelvis_rise`, `sacrum`, `lumbar`, `thoracic`, `neck`, `head` — stack
/// from the floor to the top of the head and must sum to 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ratios {
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to fingertip.
    pub hand: f64,
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shank: f64,
    /// Ankle joint above the floor.
    pub ankle_height: f64,
    /// Toe tip ahead of the ankle.
    pub toe: f64,
    /// Heel behind the ankle.
    pub heel: f64,
    /// Between the shoulder joint centres.
    pub shoulder_width: f64,
    /// Between the hip joint centres.
    pub hip_width: f64,
    /// Sacral root above the hip joints.
    pub pelvis_rise: f64,
    /// Sacral root to lumbar joint.
    pub sacrum: f64,
    /// Lumbar to thoracic joint.
    pub lumbar: f64,
    /// Thoracic to cervical joint.
    pub thoracic: f64,
    /// Cervical joint to skull base.
    pub neck: f64,
    /// Skull base to the top of the head.
    pub head: f64,
    /// Clavicle (and shoulder) joints below the cervical joint.
    pub shoulder_drop: f64,
}

impl Ratios {
    /// Drillis & Contini's ratios (Winter, Fig. 4.1) with our spine landmarks.
    pub const DRILLIS_CONTINI: Ratios = Ratios {
        upper_arm: 0.186,
        forearm: 0.146,
        hand: 0.108,
        thigh: 0.245,
        shank: 0.246,
        ankle_height: 0.039,
        toe: 0.114,
        heel: 0.038,
        shoulder_width: 0.259,
        hip_width: 0.191,
        pelvis_rise: 0.020,
        sacrum: 0.045,
        lumbar: 0.105,
        thoracic: 0.145,
        neck: 0.085,
        head: 0.070,
        shoulder_drop: 0.027,
    };

    fn fields(&self) -> [(&'static str, f64); 17] {
        [
            ("upper_arm", self.upper_arm),
            ("forearm", self.forearm),
            ("hand", self.hand),
            ("thigh", self.thigh),
            ("shank", self.shank),
            ("ankle_height", self.ankle_height),
            ("toe", self.toe),
            ("heel", self.heel),
            ("shoulder_width", self.shoulder_width),
            ("hip_width", self.hip_width),
            ("pelvis_rise", self.pelvis_rise),
            ("sacrum", self.sacrum),
            ("lumbar", self.lumbar),
            ("thoracic", self.thoracic),
            ("neck", self.neck),
            ("head", self.head),
            ("shoulder_drop", self.shoulder_drop),
        ]
    }

    /// The sum of the vertical ratios (1 for a consistent set).
    pub fn vertical_sum(&self) -> f64 {
        self.ankle_height + self.shank + self.thigh + self.spine_sum()
    }

    pub(super) fn spine_sum(&self) -> f64 {
        self.pelvis_rise + self.sacrum + self.lumbar + self.thoracic + self.neck + self.head
    }

    /// Every ratio finite, in (0, 1); the vertical ones summing to 1 (±0.001); the clavicles
    /// on the thoracic bone. Errors name the field, e.g. `ratios.thigh`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in self.fields() {
            InvalidSetting::require(
                v.is_finite() && v > 0.0 && v < 1.0,
                &format!("ratios.{name}"),
                format!("{v} is not a fraction of the height in (0, 1)"),
            )?;
        }
        let sum = self.vertical_sum();
        InvalidSetting::require(
            (sum - 1.0).abs() <= 1e-3,
            "ratios",
            format!(
                "the vertical ratios (ankle_height + shank + thigh + pelvis_rise + sacrum + lumbar + thoracic + neck + head) sum to {sum}, not 1"
            ),
        )?;
        InvalidSetting::require(
            self.shoulder_drop < self.thoracic,
            "ratios.shoulder_drop",
            "the shoulders must lie on the thoracic bone (shoulder_drop < thoracic)",
        )?;
        Ok(())
    }
}

impl Default for Ratios {
    fn default() -> Ratios {
        Ratios::DRILLIS_CONTINI
    }
}

/// An arm's bone lengths, meters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ArmSegments {
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to fingertip (the arm's tip).
    pub hand: f64,
}

/// A leg's bone lengths and foot geometry, meters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LegSegments {
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shank: f64,
    /// Ankle joint above the sole.
    pub ankle_height: f64,
    /// Toe tip ahead of the ankle, along the sole.
    pub toe: f64,
    /// Heel behind the ankle, along the sole.
    pub heel: f64,
}

impl LegSegments {
    /// The hip joint's height above the floor when standing: ankle height + shank + thigh.
    pub fn hip_height(&self) -> f64 {
        self.ankle_height + self.shank + self.thigh
    }

    /// Ankle to toe tip, the foot bone's length.
    pub fn foot(&self) -> f64 {
        self.toe.hypot(self.ankle_height)
    }
}

/// The spine's segments, meters, from the hips up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpineSegments {
    /// Sacral root above the mid-point of the hip joints (≥ 0).
    pub pelvis_rise: f64,
    /// Sacral root to lumbar joint.
    pub sacrum: f64,
    /// Lumbar to thoracic joint.
    pub lumbar: f64,
    /// Thoracic to cervical joint.
    pub thoracic: f64,
    /// Cervical joint to skull base.
    pub neck: f64,
    /// Skull base to the top of the head.
    pub head: f64,
    /// The clavicle and shoulder joints below the cervical joint (in `[0, thoracic)`).
    pub shoulder_drop: f64,
}

impl SpineSegments {
    /// From the hips' mid-point to the top of the head.
    pub fn above_hips(&self) -> f64 {
        self.pelvis_rise + self.sacrum + self.lumbar + self.thoracic + self.neck + self.head
    }
}

/// The character's measurements, meters. Built from a height and [`Ratios`]
/// ([`Proportions::from_height`]) or measured on a capture skeleton
/// ([`Proportions::from_skeleton`], [`Proportions::from_clip`]); arms and legs may differ
/// between sides.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Proportions {
    /// The right arm.
    pub right_arm: ArmSegments,
    /// The left arm.
    pub left_arm: ArmSegments,
    /// The right leg.
    pub right_leg: LegSegments,
    /// The left leg.
    pub left_leg: LegSegments,
    /// The spine.
    pub spine: SpineSegments,
    /// Between the shoulder joint centres.
    pub shoulder_width: f64,
    /// Between the hip joint centres.
    pub hip_width: f64,
}

impl Proportions {
    /// The shortest standing height accepted, meters.
    pub const MIN_HEIGHT: f64 = 0.5;
    /// The tallest standing height accepted, meters.
    pub const MAX_HEIGHT: f64 = 2.5;

    /// A person `height` meters tall with Drillis & Contini's ratios.
    pub fn from_height(height: f64) -> Result<Proportions> {
        Proportions::from_ratios(height, &Ratios::default())
    }

    /// A person `height` meters tall with the given ratios (validated, errors naming the
    /// field: `height`, `ratios.<name>`). Every length is its ratio × `height`, so the
    /// standing height is `height` × [`Ratios::vertical_sum`].
    pub fn from_ratios(height: f64, ratios: &Ratios) -> Result<Proportions> {
        check_height(height)?;
        ratios.validate()?;
        let h = height;
        let arm = ArmSegments {
            upper_arm: ratios.upper_arm * h,
            forearm: ratios.forearm * h,
            hand: ratios.hand * h,
        };
        let leg = LegSegments {
            thigh: ratios.thigh * h,
            shank: ratios.shank * h,
            ankle_height: ratios.ankle_height * h,
            toe: ratios.toe * h,
            heel: ratios.heel * h,
        };
        let p = Proportions {
            right_arm: arm,
            left_arm: arm,
            right_leg: leg,
            left_leg: leg,
            spine: SpineSegments {
                pelvis_rise: ratios.pelvis_rise * h,
                sacrum: ratios.sacrum * h,
                lumbar: ratios.lumbar * h,
                thoracic: ratios.thoracic * h,
                neck: ratios.neck * h,
                head: ratios.head * h,
                shoulder_drop: ratios.shoulder_drop * h,
            },
            shoulder_width: ratios.shoulder_width * h,
            hip_width: ratios.hip_width * h,
        };
        p.validate()?;
        Ok(p)
    }

    /// The standing height: floor to the top of the head, `hip height + spine`, with the
    /// mean of the two legs' hip heights.
    pub fn height(&self) -> f64 {
        self.mean_hip_height() + self.spine.above_hips()
    }

    /// The sacral root's height when standing (the rest pose's `root_ty`).
    pub fn root_height(&self) -> f64 {
        self.mean_hip_height() + self.spine.pelvis_rise
    }

    fn mean_hip_height(&self) -> f64 {
        0.5 * (self.right_leg.hip_height() + self.left_leg.hip_height())
    }

    /// The arm on `side`.
    pub fn arm(&self, side: Side) -> &ArmSegments {
        match side {
            Side::Right => &self.right_arm,
            Side::Left => &self.left_arm,
        }
    }

    /// The leg on `side`.
    pub fn leg(&self, side: Side) -> &LegSegments {
        match side {
            Side::Right => &self.right_leg,
            Side::Left => &self.left_leg,
        }
    }

    /// Every length finite and positive (`pelvis_rise` and `shoulder_drop` may be 0,
    /// `shoulder_drop` below `spine.thoracic`), the height within
    /// [`MIN_HEIGHT`](Self::MIN_HEIGHT)–[`MAX_HEIGHT`](Self::MAX_HEIGHT), and each hip below
    /// the sacral root. Errors name the field, e.g. `right_leg.thigh`.
    pub fn validate(&self) -> Result<()> {
        for (side, arm) in [("right_arm", &self.right_arm), ("left_arm", &self.left_arm)] {
            check_length(arm.upper_arm, &format!("{side}.upper_arm"))?;
            check_length(arm.forearm, &format!("{side}.forearm"))?;
            check_length(arm.hand, &format!("{side}.hand"))?;
        }
        for (side, leg) in [("right_leg", &self.right_leg), ("left_leg", &self.left_leg)] {
            check_length(leg.thigh, &format!("{side}.thigh"))?;
            check_length(leg.shank, &format!("{side}.shank"))?;
            check_length(leg.ankle_height, &format!("{side}.ankle_height"))?;
            check_length(leg.toe, &format!("{side}.toe"))?;
            check_length(leg.heel, &format!("{side}.heel"))?;
        }
        let s = &self.spine;
        InvalidSetting::require(
            s.pelvis_rise.is_finite() && s.pelvis_rise >= 0.0,
            "spine.pelvis_rise",
            format!("{} m is not a length ≥ 0", s.pelvis_rise),
        )?;
        check_length(s.sacrum, "spine.sacrum")?;
        check_length(s.lumbar, "spine.lumbar")?;
        check_length(s.thoracic, "spine.thoracic")?;
        check_length(s.neck, "spine.neck")?;
        check_length(s.head, "spine.head")?;
        InvalidSetting::require(
            s.shoulder_drop.is_finite() && s.shoulder_drop >= 0.0 && s.shoulder_drop < s.thoracic,
            "spine.shoulder_drop",
            format!(
                "{} m does not put the shoulders on the thoracic bone (0 ≤ drop < {} m)",
                s.shoulder_drop, s.thoracic
            ),
        )?;
        check_length(self.shoulder_width, "shoulder_width")?;
        check_length(self.hip_width, "hip_width")?;
        // The height is a sum of segments: allow its rounding at the bounds.
        check_height_within(self.height(), 1e-12)?;
        let root = self.root_height();
        for (side, leg) in [("right_leg", &self.right_leg), ("left_leg", &self.left_leg)] {
            InvalidSetting::require(
                leg.hip_height() < root + s.sacrum,
                side,
                format!(
                    "its hip ({} m high) lies above the lumbar joint ({} m): the legs differ too much in length",
                    leg.hip_height(),
                    root + s.sacrum
                ),
            )?;
        }
        Ok(())
    }
}

pub(super) fn check_height(h: f64) -> Result<()> {
    check_height_within(h, 0.0)
}

/// The height check with a relative `slack` (for heights summed from segments).
fn check_height_within(h: f64, slack: f64) -> Result<()> {
    let range = Proportions::MIN_HEIGHT * (1.0 - slack)..=Proportions::MAX_HEIGHT * (1.0 + slack);
    InvalidSetting::require(
        h.is_finite() && range.contains(&h),
        "height",
        format!(
            "{h} m is not a standing height within {}–{} m",
            Proportions::MIN_HEIGHT,
            Proportions::MAX_HEIGHT
        ),
    )?;
    Ok(())
}

fn check_length(v: f64, field: &str) -> Result<()> {
    InvalidSetting::require(
        v.is_finite() && v > 0.0,
        field,
        format!("{v} m is not a positive length"),
    )?;
    Ok(())
}
