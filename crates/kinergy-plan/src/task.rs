//! Manipulation tasks as sequences of hand targets (Kallmann 2005, "Scalable Specification
//! of Manipulations"): reach, grasp, relocate and push/pull, each made of
//!
//! - **planned** phases: IK with collision avoidance for the goal posture, RRT-Connect from
//!   the current posture, shortcut smoothing, played with the bell time warp;
//! - **straight** phases: the hand target interpolated (position lerp, orientation slerp)
//!   and the IK solved on every frame, its orbit search starting from the previous frame's
//!   orbit angle so the elbow moves continuously — the slower final approach of a grasp,
//!   the retreat after a release, a drawer's handle followed;
//! - **hand** phases: the arm still while the fingers close or open.
//!
//! The character stands in [`crate::body::reference_pose`]; only the acting arm moves — but
//! for a reach the arm alone cannot make, where the spine bends and twists and the legs
//! squat, the feet planted ([`crate::posture`], [`BodyUse`]).
//!
//! **Relocation** (the paper's Fig. 5): plan to the pre-grasp (the grasp pulled back
//! along its approach by its distance, hand opening), approach straight and close the
//! fingers, then plan *with the object held* from the grasp straight to the posture that
//! puts the object at its destination, open the fingers, back off straight along the
//! approach and plan the way back to the starting posture.
//!
//! **A reach** ([`Planner::reach_by`]) is computed at one of Kallmann's three levels — IK
//! along a straight hand line, the same with collision avoidance, or the planner — or by
//! escalating from one to the next ([`crate::level`]); [`Planner::reach`] is the planner's.
//!
//! **A person's reach** ([`TaskSettings::arm`] = [`ArmDrive::Synergy`]): a reach's planned
//! phase (the reach of [`Planner::reach`], the reach to a grasp's pre-grasp) is finished by
//! the person's synergy controller where its motion is free of obstacles, followed by a
//! straight `settle` to the planned grip ([`crate::approach`]). Transfers and returns, whose
//! goal is a posture rather than a reach target, stay planned.

use std::ops::Range;

use kinergy_io::InvalidSetting;
use kinergy_reach::character::{Character, Limb, Pose};
use kinergy_reach::controller::ArmDrive;
use nalgebra::{Isometry3, Point3, Translation3};

use crate::approach::SynergyApproach;
use crate::body::{BodyGeometry, reference_pose};
use crate::error::{PlanError, Result};
use crate::hand::{FingeredSkeleton, HandShape, Hands};
use crate::level::LevelTry;
use crate::rrt::{ArmPath, Budget, PlanStats, RrtSettings, SearchTree, SmoothStats, Warp};
use crate::scene::{Grasp, Scene};
use crate::space::{ArmConfig, ArmSpace, HandTarget};

mod body;
mod builder;
mod levels;
pub use body::{BodyUse, EXTRA_SWING_DEG, EXTRA_TWIST_DEG};
use builder::{Builder, PlannedPhase};

/// Settings of a task.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSettings {
    /// Which arm acts.
    pub limb: Limb,
    /// Frames per second of the motion.
    pub frame_rate: f64,
    /// Mean speed of the planned phases (the fastest tracked point), m/s.
    pub reach_speed: f64,
    /// Mean speed of the straight phases (approach, retreat, drawers), m/s.
    pub approach_speed: f64,
    /// Duration of closing or opening the fingers, seconds.
    pub finger_time: f64,
    /// Shortest planned phase, seconds.
    pub min_duration: f64,
    /// Clearance of the arm capsules during planning, meters.
    pub clearance: f64,
    /// Edge resolution, meters of the planner's distance.
    pub resolution: f64,
    /// The planner.
    pub rrt: RrtSettings,
    /// The smoothing's budget.
    pub smoothing: Budget,
    /// How planned phases are played over time: Kallmann's cubic bell, or a person's.
    pub warp: Warp,
    /// What ends a reach: the planned path ([`ArmDrive::Profile`], Kallmann's), or a
    /// person's synergy controller where its motion is free ([`ArmDrive::Synergy`],
    /// [`crate::approach`]).
    pub arm: ArmDrive,
}

impl Default for TaskSettings {
    fn default() -> TaskSettings {
        TaskSettings {
            limb: Limb::RightArm,
            frame_rate: 60.0,
            reach_speed: 0.5,
            approach_speed: 0.15,
            finger_time: 0.4,
            min_duration: 0.6,
            clearance: 0.01,
            resolution: 0.01,
            rrt: RrtSettings::default(),
            smoothing: Budget {
                iterations: 100,
                time: None,
            },
            warp: Warp::Cubic,
            arm: ArmDrive::Profile,
        }
    }
}

impl TaskSettings {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(self.limb.is_arm(), "limb", "an arm")?;
        for (name, v) in [
            ("frame_rate", self.frame_rate),
            ("reach_speed", self.reach_speed),
            ("approach_speed", self.approach_speed),
            ("finger_time", self.finger_time),
            ("min_duration", self.min_duration),
            ("resolution", self.resolution),
        ] {
            InvalidSetting::require(v.is_finite() && v > 0.0, name, "a finite number > 0")?;
        }
        InvalidSetting::require(
            self.frame_rate <= 1000.0,
            "frame_rate",
            "at most 1000 frames per second",
        )?;
        InvalidSetting::require(self.min_duration <= 60.0, "min_duration", "at most 60 s")?;
        if let Warp::Beta { alpha, beta } = self.warp {
            InvalidSetting::require(
                alpha.is_finite() && beta.is_finite() && alpha > 1.0 && beta > 1.0,
                "warp",
                "a bell with α > 1 and β > 1 (zero speed at both ends)",
            )?;
        }
        InvalidSetting::require(self.finger_time <= 60.0, "finger_time", "at most 60 s")?;
        for (name, v) in [
            ("reach_speed", self.reach_speed),
            ("approach_speed", self.approach_speed),
        ] {
            InvalidSetting::require(v >= 1e-3, name, "at least 1 mm/s")?;
        }
        InvalidSetting::require(
            self.clearance.is_finite() && self.clearance >= 0.0,
            "clearance",
            "a finite number ≥ 0",
        )?;
        self.rrt.validate()
    }
}

/// What one phase of a task did.
#[derive(Debug, Clone)]
pub struct Phase {
    /// `reach`, `approach`, `close`, `transfer`, `open`, `retreat`, `pull`, …
    pub name: String,
    /// Its frames in the motion (the first is shared with the previous phase's last).
    pub frames: Range<usize>,
    /// For planned phases: the search, the smoothing and the smoothed path.
    pub planned: Option<Planned>,
    /// For a planned reach a person's synergy finished: from where, and how.
    pub synergy: Option<SynergyApproach>,
}

/// A planned phase's search and smoothing.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The RRT-Connect search.
    pub search: PlanStats,
    /// The smoothing.
    pub smoothing: SmoothStats,
    /// The path as found.
    pub raw: ArmPath,
    /// The smoothed path the motion plays.
    pub path: ArmPath,
    /// The search's two trees (grown from the start and from the goal).
    pub trees: [SearchTree; 2],
    /// The space the phase was planned in (the held object, ignored objects).
    pub space: ArmSpace,
}

/// A moved object's pose on every frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectTrack {
    /// The scene object.
    pub name: String,
    /// Its world pose per frame.
    pub poses: Vec<Isometry3<f64>>,
}

/// A task's motion: body poses and hand shapes per frame, the phases and moved objects.
#[derive(Debug, Clone)]
pub struct Manipulation {
    /// Full-body poses (only the acting arm moves, but where [`Manipulation::body`] says).
    pub poses: Vec<Pose>,
    /// Hand shapes per frame.
    pub hands: Vec<Hands>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// The phases in order.
    pub phases: Vec<Phase>,
    /// Objects that moved.
    pub objects: Vec<ObjectTrack>,
    /// For a reach at a level ([`Planner::reach_by`]): every level tried, in order, the last
    /// the one that solved it. Empty otherwise.
    pub levels: Vec<LevelTry>,
    /// For a reach the arm alone could not make: how the body moved (`None`: it did not).
    pub body: Option<BodyUse>,
}

impl Manipulation {
    /// Its duration, seconds.
    pub fn duration(&self) -> f64 {
        (self.poses.len().saturating_sub(1)) as f64 * self.frame_time
    }

    /// The motion as a clip of the character with fingers ([`FingeredSkeleton`]).
    pub fn to_clip(&self, character: &Character) -> Result<kinergy_motion::Clip> {
        FingeredSkeleton::new(character)?.clip(character, &self.poses, &self.hands, self.frame_time)
    }
}

/// A planning problem: a space, a start and a goal configuration.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The arm's space (with what it holds and ignores).
    pub space: ArmSpace,
    /// The start configuration.
    pub start: ArmConfig,
    /// The goal configuration.
    pub goal: ArmConfig,
}

/// Plans manipulation tasks for one character in one scene.
#[derive(Debug, Clone)]
pub struct Planner {
    character: Character,
    scene: Scene,
    settings: TaskSettings,
    start: Pose,
    /// The arm's space at the start, built once (its scene colliders hold the meshes'
    /// bounding-volume hierarchies, whose construction dominated a short task); every task
    /// starts from a copy, which shares the shapes.
    space: ArmSpace,
}

impl Planner {
    /// A planner for the character of the scene's height standing at the origin in its
    /// reference posture.
    pub fn new(scene: Scene, settings: TaskSettings) -> Result<Planner> {
        settings.validate()?;
        let character = Character::from_height(scene.character_height)?;
        let body = BodyGeometry::new(&character)?;
        let start = reference_pose(&character);
        let space = ArmSpace::new(&character, &body, &start, settings.limb, &scene)?
            .with_clearance(settings.clearance)?
            .with_resolution(settings.resolution)?;
        Ok(Planner {
            character,
            scene,
            settings,
            start,
            space,
        })
    }

    /// The character.
    pub fn character(&self) -> &Character {
        &self.character
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The settings.
    pub fn settings(&self) -> &TaskSettings {
        &self.settings
    }

    /// The starting body pose.
    pub fn start_pose(&self) -> &Pose {
        &self.start
    }

    /// The arm's space in the scene as it is at the start (nothing held or ignored).
    pub fn space(&self) -> Result<ArmSpace> {
        Ok(self.space.clone())
    }

    fn builder(&self) -> Result<Builder<'_>> {
        self.builder_in(self.space()?, None)
    }

    /// A builder whose motion starts at the start pose in `space`, a reach's goal posture
    /// `goal` (orbit angle, configuration) given when it was found before.
    fn builder_in(&self, space: ArmSpace, goal: Option<(f64, ArmConfig)>) -> Result<Builder<'_>> {
        let q = space.config_of(&self.start);
        let alpha = space.alpha_of(&q);
        let hand = HandShape::relaxed();
        let mut b = Builder {
            planner: self,
            space,
            q,
            alpha,
            hand,
            out: Manipulation {
                poses: Vec::new(),
                hands: Vec::new(),
                frame_time: 1.0 / self.settings.frame_rate,
                phases: Vec::new(),
                objects: Vec::new(),
                levels: Vec::new(),
                body: None,
            },
            held: None,
            goal,
        };
        b.push_frame();
        Ok(b)
    }

    /// A collision-free reach to a hand target, the hand taking `shape` on the way: the
    /// planner's ([`crate::level::Level::Planner`]; [`Planner::reach_by`] for the others),
    /// the arm's alone ([`Planner::reach_by`] moves the body where the arm cannot reach).
    pub fn reach(&self, target: &HandTarget, shape: HandShape) -> Result<Manipulation> {
        let mut b = self.builder()?;
        b.planned_reach(target, shape)?;
        Ok(b.out)
    }

    /// Grasp the object `name`: plan to its pre-grasp, approach straight, close the hand.
    pub fn grasp(&self, name: &str) -> Result<Manipulation> {
        let mut b = self.builder()?;
        b.grasp(name)?;
        Ok(b.out)
    }

    /// Move the object `name` so that its origin ends at `to` (same orientation): grasp
    /// it, plan the transfer with it in the hand, release it and retreat. A place where it
    /// would not stand (floating, or inside another object) is refused first
    /// ([`check_placement`](crate::space::check_placement)).
    pub fn relocate(&self, name: &str, to: &Point3<f64>) -> Result<Manipulation> {
        if !to.iter().all(|v| v.is_finite()) {
            return Err(PlanError::NonFinite("the destination".into()));
        }
        // Refused before any planning: an object left floating or inside another.
        if let Some(object) = self.scene.object(name) {
            let dest = Isometry3::from_parts(Translation3::from(to.coords), object.pose.rotation);
            crate::space::check_placement(&self.scene, name, &dest)?;
        }
        let mut b = self.builder()?;
        let grasp = b.grasp(name)?;
        let object = &self.scene.objects[b.held.unwrap_or(0)];
        let dest = Isometry3::from_parts(Translation3::from(to.coords), object.pose.rotation);
        let target = grasp_target(&dest, &grasp, 0.0);
        let (alpha, place) = b
            .space
            .solve(&target)
            .map_err(|e| in_phase(e, "the placing posture"))?;
        b.planned(PlannedPhase::TRANSFER, &place, alpha, b.hand)?;
        b.hand_phase("open", HandShape::open());
        b.release();
        let back = grasp_target(&dest, &grasp, grasp.distance);
        b.space.set_ignored(name, true)?;
        b.straight("retreat", &back, HandShape::open())?;
        b.space.set_ignored(name, false)?;
        b.return_to_start()?;
        Ok(b.out)
    }

    /// The planning problem at the heart of a relocation, for benchmarks and tests: the
    /// space with object `name` held, the configuration grasping it where it stands (the
    /// IK with collision avoidance, the object ignored) and the one placing it at `to`.
    pub fn transfer_problem(&self, name: &str, to: &Point3<f64>) -> Result<Problem> {
        let index = self
            .scene
            .object_index(name)
            .ok_or_else(|| unknown_object(name))?;
        let object = &self.scene.objects[index];
        let grasp = object.grasp.clone().ok_or_else(|| {
            PlanError::Setting(InvalidSetting::new(
                "object",
                format!("`{name}` has no `grasp`: it cannot be grasped"),
            ))
        })?;
        let mut space = self.space()?;
        space.set_ignored(name, true)?;
        let (_, start) = space.solve(&grasp_target(&object.pose, &grasp, 0.0))?;
        space.attach(&self.scene, name, &start)?;
        let dest = Isometry3::from_parts(Translation3::from(to.coords), object.pose.rotation);
        let (_, goal) = space.solve(&grasp_target(&dest, &grasp, 0.0))?;
        Ok(Problem { space, start, goal })
    }

    /// Open (pull, `distance` > 0) or close (push, < 0) the drawer `name` by `distance`
    /// meters along its slide: grasp the handle, then the hand follows the handle with the
    /// IK on every frame.
    pub fn pull(&self, name: &str, distance: f64) -> Result<Manipulation> {
        let o = self
            .scene
            .object(name)
            .ok_or_else(|| unknown_object(name))?;
        let slide = o.slide.clone().ok_or_else(|| {
            PlanError::Setting(InvalidSetting::new(
                "object",
                format!("`{name}` has no `slide`: it is not a drawer"),
            ))
        })?;
        InvalidSetting::require(
            distance.is_finite() && distance.abs() <= slide.travel + 1e-12,
            "distance",
            format!("within ±{} m (the drawer's travel)", slide.travel),
        )?;
        let mut b = self.builder()?;
        let grasp = b.grasp(name)?;
        let start = o.pose;
        let axis = start.rotation * slide.axis;
        let frames = b.frames_for(distance.abs(), self.settings.approach_speed);
        let first = b.out.poses.len() - 1;
        let mut track = vec![start; b.out.poses.len()];
        for k in 1..frames {
            let s = crate::rrt::bell(k as f64 / (frames - 1) as f64) * distance;
            let pose = Isometry3::from_parts(
                Translation3::from(start.translation.vector + axis * s),
                start.rotation,
            );
            let target = grasp_target(&pose, &grasp, 0.0);
            b.follow(&target)
                .map_err(|e| in_phase(e, "pulling the drawer"))?;
            track.push(pose);
        }
        b.out.phases.push(Phase {
            name: if distance >= 0.0 { "pull" } else { "push" }.into(),
            frames: first..b.out.poses.len(),
            planned: None,
            synergy: None,
        });
        b.out.objects.push(ObjectTrack {
            name: name.to_string(),
            poses: track,
        });
        Ok(b.out)
    }
}

fn unknown_object(name: &str) -> PlanError {
    PlanError::Setting(InvalidSetting::new(
        "object",
        format!("the scene has no object `{name}`"),
    ))
}

/// The largest change of a joint value between two configurations, radians.
fn largest_change(a: &ArmConfig, b: &ArmConfig) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Names the phase in a goal failure.
fn in_phase(e: PlanError, what: &str) -> PlanError {
    match e {
        PlanError::GoalUnreachable { why } => PlanError::GoalUnreachable {
            why: format!("{what}: {why}"),
        },
        PlanError::GoalInCollision { tried, contact } => PlanError::GoalInCollision {
            tried,
            contact: format!("{contact} ({what})"),
        },
        other => other,
    }
}

/// The hand target of a grasp on an object at `pose`, pulled back along the approach by
/// `back` meters.
fn grasp_target(pose: &Isometry3<f64>, grasp: &Grasp, back: f64) -> HandTarget {
    let at = pose * (grasp.position - grasp.approach * back);
    HandTarget {
        position: at,
        orientation: Some(pose.rotation * grasp.rotation),
    }
}
