//! The shoulder girdle: the sternoclavicular (SC) joint's elevation and retraction, driven by
//! the arm's humerothoracic elevation through the scapulohumeral rhythm. A pure function of
//! one angle; the [body](super::body) turns it into the clavicle's rotation.
//!
//! # The rhythm and its sources
//! `θ` is the humerothoracic elevation: the angle between the upper arm and the thorax's
//! downward axis (the hanging arm is 0°, the arm straight overhead 180°). For the character's
//! arm it is the magnitude of the shoulder swing `|(sx, sy)|` (the swing is measured from the
//! hanging arm in a frame fixed to the thorax, [layout](super::layout)), in any plane of
//! elevation.
//!
//! - **Glenohumeral : scapulothoracic.** Inman, Saunders & Abbott, *Observations on the
//!   function of the shoulder joint*, J Bone Joint Surg 26(1):1–30, 1944: after a setting
//!   phase of the first ~30° (scapula nearly still), the glenohumeral (GH) joint and the
//!   scapulothoracic (ST) joint share the elevation 2 : 1, so 180° of elevation is about
//!   120° GH + 60° ST. We take ST = ramp(θ − 30°)/3, GH = θ − ST. (Braman et al., J Shoulder
//!   Elbow Surg 18(6):960–967, 2009, measured 2.3 : 1 with bone pins while raising the arm.)
//! - **Sternoclavicular joint.** Ludewig et al., *Motion of the shoulder complex during
//!   multiplanar humeral elevation*, J Bone Joint Surg Am 91(2):378–389, 2009 (bone pins,
//!   flexion, scapular-plane abduction and abduction): from 20° to 120° of humerothoracic
//!   elevation the clavicle **retracts 15°–16°** and **elevates 6°–11°** (the range over the
//!   three planes). We take the middles, 15.5° and 8.5° per 100°, as linear rates beyond 20°:
//!   [`RETRACTION_RATE`] and [`ELEVATION_RATE`], extrapolated to 180° (24.8° and 13.6°).
//!
//! Checked against stored copies of the sources (2026-12-02): Inman's 2 : 1 beyond 30° and
//! 180° = 120° GH + 60° ST (textbook summaries of Inman 1944), Braman et al.'s 2.3 raising
//! and 2.7 lowering (their abstract, PMC2841046). Ludewig et al.'s clavicle ranges could not
//! be read here (the paper's text is not in the stored corpus): they are the values as
//! remembered from its abstract and must be checked against the paper.
//!
//! | θ (humerothoracic) | 0° | 20° | 60° | 90° | 120° | 180° |
//! |---|---|---|---|---|---|---|
//! | SC elevation (Ludewig) | 0 | 0 | 3.4° | 5.95° | 8.5° | 13.6° |
//! | SC retraction (Ludewig) | 0 | 0 | 6.2° | 10.85° | 15.5° | 24.8° |
//! | ST (Inman) | 0 | 0 | 10° | 20° | 30° | 50° |
//! | GH (Inman) | 0 | 20° | 50° | 70° | 90° | 130° |
//!
//! `ramp(x)` is `max(x, 0)` with its corner rounded over ±[`ROUNDING`] (a quadratic blend, so
//! the angles have a continuous first derivative: the girdle adds no jump to the shoulder's
//! speed when the arm passes 20° or 30°). Away from the corners the table holds exactly.
//!
//! # Ranges
//! The glenohumeral joint's swing ellipse is [`GLENOHUMERAL_MAX`] (130°, the arm chain's
//! flexion radius, [`kinergy_motion::Chain::arm`]); with the rhythm the arm's humerothoracic
//! elevation reaches [`Girdle::elevation_for_glenohumeral`]`(130°)` = 180°, the flexion and
//! abduction of the AAOS table (American Academy of Orthopaedic Surgeons, *Joint motion:
//! method of measuring and recording*, 1965; also NASA-STD-3000 vol. I §3.3.2, shoulder
//! flexion 188°, abduction 134° without the girdle's help in that table's definition). The
//! character's arm swing is therefore bounded at 180° in every plane
//! ([limits](super::limits)).

use std::f64::consts::PI;

use kinergy_motion::Side;
use kinergy_motion::rotation::{Axis, axis_rotation};
use nalgebra::{Rotation3, Vector3};

/// Clavicle elevation per degree of humerothoracic elevation beyond [`CLAVICLE_ONSET`]
/// (Ludewig et al. 2009: 6°–11° over 20°–120°, the middle).
pub const ELEVATION_RATE: f64 = 8.5 / 100.0;

/// Clavicle retraction per degree of humerothoracic elevation beyond [`CLAVICLE_ONSET`]
/// (Ludewig et al. 2009: 15°–16° over 20°–120°, the middle).
pub const RETRACTION_RATE: f64 = 15.5 / 100.0;

/// Where the clavicle starts to move, radians of humerothoracic elevation (Ludewig's first
/// angle, 20°).
pub const CLAVICLE_ONSET: f64 = 20.0 * PI / 180.0;

/// Inman's setting phase: the scapula starts to rotate beyond 30° of elevation.
pub const SETTING_PHASE: f64 = 30.0 * PI / 180.0;

/// Inman's glenohumeral : scapulothoracic ratio beyond the setting phase.
pub const GH_PER_ST: f64 = 2.0;

/// The largest glenohumeral swing, radians (130°).
pub const GLENOHUMERAL_MAX: f64 = 130.0 * PI / 180.0;

/// Half-width of the rounded corner of each onset, radians (10°).
pub const ROUNDING: f64 = 10.0 * PI / 180.0;

/// The girdle's angles at one arm elevation, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GirdleAngles {
    /// Sternoclavicular elevation: the clavicle's lateral end rises.
    pub elevation: f64,
    /// Sternoclavicular retraction: the lateral end moves backward (protraction < 0).
    pub retraction: f64,
    /// Scapulothoracic upward rotation, Inman's share of the elevation.
    pub scapulothoracic: f64,
    /// Glenohumeral elevation: the rest of the arm's elevation.
    pub glenohumeral: f64,
}

/// The scapulohumeral rhythm (module docs): stateless.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Girdle;

/// `max(x, 0)` with its corner rounded over ±`w`: C¹, exactly `x` beyond `w`, 0 below `−w`.
fn ramp(x: f64, w: f64) -> f64 {
    if x <= -w {
        0.0
    } else if x >= w {
        x
    } else {
        (x + w).powi(2) / (4.0 * w)
    }
}

/// The derivative of [`ramp`].
fn ramp_slope(x: f64, w: f64) -> f64 {
    if x <= -w {
        0.0
    } else if x >= w {
        1.0
    } else {
        (x + w) / (2.0 * w)
    }
}

impl Girdle {
    /// The girdle at humerothoracic elevation `elevation` (radians; negative values are taken
    /// as 0, the hanging arm).
    pub fn angles(elevation: f64) -> GirdleAngles {
        let e = elevation.max(0.0);
        let clavicle = ramp(e - CLAVICLE_ONSET, ROUNDING);
        let st = ramp(e - SETTING_PHASE, ROUNDING) / (GH_PER_ST + 1.0);
        GirdleAngles {
            elevation: ELEVATION_RATE * clavicle,
            retraction: RETRACTION_RATE * clavicle,
            scapulothoracic: st,
            glenohumeral: e - st,
        }
    }

    /// The sternoclavicular angles' rates of change per radian of arm elevation:
    /// `(d elevation/dθ, d retraction/dθ)`.
    pub fn rates(elevation: f64) -> (f64, f64) {
        let s = ramp_slope(elevation.max(0.0) - CLAVICLE_ONSET, ROUNDING);
        (ELEVATION_RATE * s, RETRACTION_RATE * s)
    }

    /// The humerothoracic elevation at which the glenohumeral share is `gh` radians: the
    /// inverse of [`GirdleAngles::glenohumeral`] (increasing, so a bisection finds it).
    pub fn elevation_for_glenohumeral(gh: f64) -> f64 {
        let (mut lo, mut hi) = (gh.max(0.0), gh.max(0.0) * (1.0 + 1.0 / GH_PER_ST) + 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if Girdle::angles(mid).glenohumeral < gh {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

/// One arm's girdle in the body: what moves its shoulder
/// ([`Character::arm_girdle`](super::Character::arm_girdle)). Small and `Copy`, so a planner
/// can place the shoulder for any arm configuration without the character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmGirdle {
    /// +1 for the left arm (its clavicle points along the thorax's +x), −1 for the right.
    side: f64,
    /// The shoulder's offset from the sternoclavicular joint, in the thorax's frame.
    clavicle: Vector3<f64>,
    /// The arm base frame's orientation in the thorax's frame.
    rest: Rotation3<f64>,
}

impl ArmGirdle {
    /// The girdle of the arm on `side` whose shoulder sits at `clavicle` from the
    /// sternoclavicular joint and whose base frame is turned by `rest`, both in the thorax's
    /// frame (x left, y back, z up).
    pub fn new(side: Side, clavicle: Vector3<f64>, rest: Rotation3<f64>) -> ArmGirdle {
        let side = match side {
            Side::Left => 1.0,
            Side::Right => -1.0,
        };
        ArmGirdle {
            side,
            clavicle,
            rest,
        }
    }

    /// The arm's humerothoracic elevation for its DoFs `q`: `|(sx, sy)|` of the shoulder swing.
    pub fn elevation(q: &[f64]) -> f64 {
        match q {
            [sx, sy, ..] => sx.hypot(*sy),
            _ => 0.0,
        }
    }

    /// The clavicle's rotation in the thorax's frame for the arm's DoFs `q`: retraction about
    /// the thorax's long axis after elevation about its forward axis, each turning the
    /// clavicle's lateral end (up, back).
    pub fn rotation(&self, q: &[f64]) -> Rotation3<f64> {
        let g = Girdle::angles(ArmGirdle::elevation(q));
        if g.elevation == 0.0 && g.retraction == 0.0 {
            return Rotation3::identity();
        }
        axis_rotation(Axis::Z, self.side * g.retraction)
            * axis_rotation(Axis::Y, -self.side * g.elevation)
    }

    /// The shoulder's displacement by the girdle for the arm's DoFs `q`, in the arm's base
    /// frame (which turns with the thorax only): `restᵀ (G − I) o`.
    pub fn shift(&self, q: &[f64]) -> Vector3<f64> {
        let g = self.rotation(q);
        self.rest.inverse() * (g * self.clavicle - self.clavicle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    /// The rhythm against the cited values, typed from the sources (module docs' table):
    /// Ludewig's clavicle over 20°–120° and Inman's 2 : 1 beyond 30°, at elevations away from
    /// the rounded corners (within ±10° of an onset the blend may differ by up to 2.5°
    /// times the rate).
    #[test]
    fn the_rhythm_follows_the_cited_values() {
        // (θ, SC elevation, SC retraction, ST, GH), degrees.
        let table: [(f64, f64, f64, f64, f64); 7] = [
            (0.0, 0.0, 0.0, 0.0, 0.0),
            (5.0, 0.0, 0.0, 0.0, 5.0),
            (60.0, 3.4, 6.2, 10.0, 50.0),
            (90.0, 5.95, 10.85, 20.0, 70.0),
            (120.0, 8.5, 15.5, 30.0, 90.0),
            (150.0, 11.05, 20.15, 40.0, 110.0),
            (180.0, 13.6, 24.8, 50.0, 130.0),
        ];
        for (theta, el, re, st, gh) in table {
            let g = Girdle::angles(theta.to_radians());
            assert_abs_diff_eq!(g.elevation.to_degrees(), el, epsilon = 0.05);
            assert_abs_diff_eq!(g.retraction.to_degrees(), re, epsilon = 0.05);
            assert_abs_diff_eq!(g.scapulothoracic.to_degrees(), st, epsilon = 0.05);
            assert_abs_diff_eq!(g.glenohumeral.to_degrees(), gh, epsilon = 0.05);
        }
        // Ludewig's span: 20° → 120° moves the clavicle by the middle of the cited ranges.
        let (a, b) = (Girdle::angles(0.35), Girdle::angles(120f64.to_radians()));
        assert!((6.0..=11.0).contains(&(b.elevation - a.elevation).to_degrees()));
        assert!((15.0..=16.0).contains(&(b.retraction - a.retraction).to_degrees()));
        // Inman's whole range: 180° is 120°–130° GH with 50°–60° ST.
        let top = Girdle::angles(PI);
        assert!((120.0..=130.0).contains(&top.glenohumeral.to_degrees()));
        assert!((50.0..=60.0).contains(&top.scapulothoracic.to_degrees()));
    }

    /// The angles are continuous with a continuous slope (no speed jump from the girdle):
    /// finite differences agree with [`Girdle::rates`] everywhere, corners included.
    #[test]
    fn the_girdle_moves_smoothly() {
        let h = 1e-6;
        for k in 0..=360 {
            let t = k as f64 * PI / 360.0;
            let (de, dr) = Girdle::rates(t);
            let (a, b) = (Girdle::angles(t - h), Girdle::angles(t + h));
            assert_abs_diff_eq!((b.elevation - a.elevation) / (2.0 * h), de, epsilon = 1e-4);
            assert_abs_diff_eq!(
                (b.retraction - a.retraction) / (2.0 * h),
                dr,
                epsilon = 1e-4
            );
            // The slope never jumps: one degree on, it changed by at most the rounding's rate.
            let (de2, _) = Girdle::rates(t + 1f64.to_radians());
            assert!((de2 - de).abs() <= ELEVATION_RATE * 0.051, "{t}");
        }
    }

    /// The glenohumeral limit and the rhythm give 180° of arm elevation (AAOS).
    #[test]
    fn the_glenohumeral_limit_gives_a_raised_arm() {
        let top = Girdle::elevation_for_glenohumeral(GLENOHUMERAL_MAX);
        assert_abs_diff_eq!(top.to_degrees(), 180.0, epsilon = 1e-6);
        let g = Girdle::angles(top);
        assert_abs_diff_eq!(g.glenohumeral, GLENOHUMERAL_MAX, epsilon = 1e-9);
    }
}
