//! A planning task as `kinergy plan` and Python's `plan` ask for it: a scene, a goal — a hand
//! target, or a grasp, relocation, pull or push of one of its objects — the acting arm, the
//! level a reach is computed at ([`Level`]), the planner's seed and time budget, and a person
//! whose synergy finishes the reach and whose bell times the path; the motion, a report both
//! front ends serialize, and the planner's search trees ([`SearchTrace`], Kallmann's Fig. 4).

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{Clip, Side};
use kinergy_reach::character::{Character, Limb};
use kinergy_reach::drive::PersonArm;
use kinergy_solver::PersonStyle;
use serde::Serialize;

use crate::error::Result;
use crate::hand::HandShape;
use crate::level::{Level, LevelTry};
use crate::report::ObjectReport;
use crate::rrt::{SearchTree, Warp};
use crate::scene::Scene;
use crate::space::HandTarget;
use crate::task::{BodyUse, Manipulation, Planner, TaskSettings};

/// A drawer's travel range, meters (its sign: pulled or pushed).
pub const DISTANCE_M: (f64, f64) = (-2.0, 2.0);
/// Each planned phase's time budget range, milliseconds.
pub const BUDGET_MS: (u64, u64) = (1, 600_000);

/// A manipulation task on a scene object, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskKind {
    /// Grasp the object, carry it so its origin ends at a point, let go and come back.
    Relocate,
    /// Reach, approach and close the hand on the object.
    Grasp,
    /// Grasp a drawer and pull it open.
    Pull,
    /// Grasp a drawer and push it in.
    Push,
}

impl TaskKind {
    /// Every task, in the order the front ends list them.
    pub const ALL: [TaskKind; 4] = [
        TaskKind::Relocate,
        TaskKind::Grasp,
        TaskKind::Pull,
        TaskKind::Push,
    ];

    /// `relocate`, `grasp`, `pull` or `push`.
    pub fn name(self) -> &'static str {
        match self {
            TaskKind::Relocate => "relocate",
            TaskKind::Grasp => "grasp",
            TaskKind::Pull => "pull",
            TaskKind::Push => "push",
        }
    }
}

impl fmt::Display for TaskKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for TaskKind {
    type Err = InvalidSetting;
    fn from_str(s: &str) -> std::result::Result<TaskKind, InvalidSetting> {
        TaskKind::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| {
                InvalidSetting::new(
                    "task",
                    format!("`{s}`: expected relocate, grasp, pull or push"),
                )
            })
    }
}

/// What the task does.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// Reach a hand target (the grip point, optionally with the hand's rotation).
    Reach(HandTarget),
    /// Grasp the object.
    Grasp(String),
    /// Carry the object so its origin ends at `to` (world meters).
    Relocate {
        /// The object.
        object: String,
        /// Where its origin goes.
        to: Point3<f64>,
    },
    /// Pull (distance > 0) or push (< 0) the drawer `object` by `distance` meters.
    Slide {
        /// The drawer.
        object: String,
        /// Meters, pulled when positive.
        distance: f64,
    },
}

impl Goal {
    /// The goal of `task` on `object`: `to` for a relocation, the drawer's travel `distance`
    /// (> 0) for a pull or a push.
    pub fn task(
        task: TaskKind,
        object: String,
        to: Option<Point3<f64>>,
        distance: f64,
    ) -> std::result::Result<Goal, InvalidSetting> {
        Ok(match task {
            TaskKind::Grasp => Goal::Grasp(object),
            TaskKind::Relocate => Goal::Relocate {
                object,
                to: to.ok_or_else(|| {
                    InvalidSetting::new("to", "a relocation needs the point its object goes to")
                })?,
            },
            TaskKind::Pull | TaskKind::Push => {
                InvalidSetting::require(
                    distance.is_finite() && distance > 0.0,
                    "distance",
                    format!("{distance}: expected a number > 0"),
                )?;
                Goal::Slide {
                    object,
                    distance: if task == TaskKind::Pull {
                        distance
                    } else {
                        -distance
                    },
                }
            }
        })
    }

    /// The object the goal acts on.
    pub fn object(&self) -> Option<&str> {
        match self {
            Goal::Reach(_) => None,
            Goal::Grasp(o) | Goal::Relocate { object: o, .. } | Goal::Slide { object: o, .. } => {
                Some(o)
            }
        }
    }

    /// The task as reports name it: `reach`, `grasp NAME`, `relocate NAME`, `pull NAME`,
    /// `push NAME`.
    pub fn name(&self) -> String {
        match self {
            Goal::Reach(_) => "reach".into(),
            Goal::Grasp(o) => format!("grasp {o}"),
            Goal::Relocate { object, .. } => format!("relocate {object}"),
            Goal::Slide { object, distance } if *distance >= 0.0 => format!("pull {object}"),
            Goal::Slide { object, .. } => format!("push {object}"),
        }
    }
}

impl Scene {
    /// Where the hand grips the object `name`, world meters: its grasp's grip point, or its
    /// origin when it has no grasp. `None` when there is no such object.
    pub fn grip_point(&self, name: &str) -> Option<Point3<f64>> {
        let object = self.object(name)?;
        Some(match &object.grasp {
            Some(g) => object.pose * g.position,
            None => Point3::from(object.pose.translation.vector),
        })
    }
}

/// A planning task ([module docs](self)).
pub struct TaskRequest<'a> {
    /// The scene.
    pub scene: Scene,
    /// The scene's name in messages and the report (its file).
    pub scene_name: String,
    /// What to do.
    pub goal: Goal,
    /// The acting arm.
    pub side: Side,
    /// How a reach is computed ([`crate::level`]); a task takes only [`Level::Auto`] or
    /// [`Level::Planner`] (its moves are planned).
    pub level: Level,
    /// The planner's random stream.
    pub seed: u64,
    /// Each planned phase's time budget (the iteration budget applies too).
    pub budget: Option<Duration>,
    /// The person whose synergy finishes the reach and whose bell times the planned phases.
    pub person: Option<&'a dyn PersonStyle>,
}

/// How a planned task went (`kinergy plan --json`).
#[derive(Debug, Clone, Serialize)]
pub struct PlanReport {
    /// The file written (set by the front end that writes one).
    pub output: Option<String>,
    /// The scene.
    pub scene: String,
    /// Its triangles.
    pub triangles: usize,
    /// The task ([`Goal::name`]).
    pub task: String,
    /// The planner's seed.
    pub seed: u64,
    /// For a reach: the level that solved it (`ik`, `straight` or `planner`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level: Option<&'static str>,
    /// For a reach: every level tried, in order ([`crate::level`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub levels: Vec<LevelReport>,
    /// The body DoFs the motion moves besides the arm's ([`crate::posture::BODY_DOF_NAMES`]:
    /// `spine_swing`, `spine_twist`, `squat`); empty when the arm alone reached.
    pub body_dofs: Vec<&'static str>,
    /// For a reach the arm alone could not make: the body's goal posture and why it moved.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub body: Option<BodyReport>,
    /// Frames of the motion.
    pub frames: usize,
    /// Seconds a frame.
    pub frame_time_s: f64,
    /// The motion's duration, seconds.
    pub duration_s: f64,
    /// Its phases.
    pub phases: Vec<PhaseReport>,
    /// The objects moved.
    pub objects: Vec<ObjectReport>,
    /// How the planned phases were played over time.
    pub timing: TimingReport,
}

/// One level tried for a reach.
#[derive(Debug, Clone, Serialize)]
pub struct LevelReport {
    /// `ik`, `straight` or `planner`.
    pub level: &'static str,
    /// Whether it solved the reach.
    pub solved: bool,
    /// Its wall time, milliseconds (the goal posture's IK, the motion and its checks).
    pub ms: f64,
    /// Why it failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why: Option<String>,
    /// Whether its motion was checked for collisions (false only for a forced `ik`).
    pub motion_checked: bool,
}

impl LevelReport {
    fn of(t: &LevelTry) -> LevelReport {
        LevelReport {
            level: t.level.name(),
            solved: t.solved(),
            ms: t.seconds * 1e3,
            why: t.failure.clone(),
            motion_checked: t.motion_checked,
        }
    }
}

/// How a reach moved the body ([`crate::task::BodyUse`]).
#[derive(Debug, Clone, Serialize)]
pub struct BodyReport {
    /// The body DoFs it moves.
    pub dofs: Vec<&'static str>,
    /// The goal posture's spine swing toward the target, degrees (about `s = d × y`: negative
    /// bends toward the target).
    pub spine_swing_deg: f64,
    /// The goal posture's spine twist, degrees (> 0 turns left).
    pub spine_twist_deg: f64,
    /// How far the goal posture lowers the root, meters.
    pub squat_m: f64,
    /// Why the arm alone could not reach.
    pub arm_alone: String,
    /// Stances of the spine and legs tried, the one taken included.
    pub stances_tried: usize,
    /// The posture search's time, milliseconds.
    pub ms: f64,
}

impl BodyReport {
    fn of(b: &BodyUse) -> BodyReport {
        BodyReport {
            dofs: b.dofs.clone(),
            spine_swing_deg: b.goal[0].to_degrees(),
            spine_twist_deg: b.goal[1].to_degrees(),
            squat_m: b.goal[2],
            arm_alone: b.arm_alone.clone(),
            stances_tried: b.tried,
            ms: b.seconds * 1e3,
        }
    }
}

/// A phase of the motion.
#[derive(Debug, Clone, Serialize)]
pub struct PhaseReport {
    /// Its name (`reach`, `approach`, `carry` …).
    pub name: String,
    /// Its first frame.
    pub first_frame: usize,
    /// Its last frame.
    pub last_frame: usize,
    /// For a planned phase: the search and the smoothing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planned: Option<PlannedReport>,
    /// For a reach the person's synergy finished.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub synergy: Option<SynergyReport>,
}

/// A planned phase's search and smoothing.
#[derive(Debug, Clone, Serialize)]
pub struct PlannedReport {
    /// RRT-Connect's iterations.
    pub iterations: usize,
    /// Nodes in both trees.
    pub nodes: usize,
    /// Nodes in the tree grown from the start, and in the one grown from the goal.
    pub tree_nodes: [usize; 2],
    /// The search's time, milliseconds.
    pub plan_ms: f64,
    /// The smoothing's time, milliseconds.
    pub smooth_ms: f64,
    /// The path's length before smoothing (the planner's distance).
    pub length_before_m: f64,
    /// And after.
    pub length_after_m: f64,
    /// Configurations before smoothing.
    pub configs_before: usize,
    /// And after.
    pub configs_after: usize,
}

/// How the person's synergy finished a planned reach.
#[derive(Debug, Clone, Serialize)]
pub struct SynergyReport {
    /// How far along the smoothed path it started, meters of the planner's distance (0: the
    /// whole reach).
    pub from_m: f64,
    /// The smoothed path's length, meters of the planner's distance.
    pub path_m: f64,
    /// Why approaches from earlier points were not used.
    pub rejected: Vec<String>,
    /// The frame in the motion where it takes over (the last of the planned path; it moves
    /// the arm from the next).
    pub first_frame: usize,
    /// Frames it drove.
    pub frames: usize,
    /// The frame in the motion from which plain IK drove after the synergy, if it did.
    pub plain_ik_from: Option<usize>,
    /// The hand's distance to the planned goal's when it arrived, meters.
    pub distance_m: f64,
}

/// The time warp of the planned phases.
#[derive(Debug, Clone, Serialize)]
pub struct TimingReport {
    /// `cubic` (Kallmann's) or `person`.
    pub warp: &'static str,
    /// When the speed peaks, as a fraction of a phase.
    pub peak: f64,
    /// The speed's standard deviation over a phase's fraction.
    pub spread: f64,
}

/// A planned phase's search as Kallmann's Fig. 4 draws it (`plan --tree-svg`): both trees
/// and the wrist's path as found and as smoothed.
#[derive(Debug, Clone)]
pub struct SearchTrace {
    /// The phase (`reach`, `transfer`, `return`, `settle`).
    pub phase: String,
    /// The tree grown from the start, and the one grown from the goal.
    pub trees: [SearchTree; 2],
    /// The wrist's world positions along the path as found, meters (every configuration,
    /// and the interpolations between them every centimeter of the planner's distance).
    pub raw_wrist: Vec<Point3<f64>>,
    /// And along the smoothed path.
    pub smoothed_wrist: Vec<Point3<f64>>,
}

/// A planned task: the motion (the character with fingers, 60 Hz), its report and the
/// planner's searches.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The motion as a clip.
    pub clip: Clip,
    /// The report.
    pub report: PlanReport,
    /// Each planned phase's search, in the order of the phases (none when a reach was solved
    /// by the `ik` or `straight` level).
    pub searches: Vec<SearchTrace>,
}

impl TaskRequest<'_> {
    /// Checks the request before any work: the object the goal names is in the scene (an
    /// unknown name gets "did you mean …"), a drawer's travel and the budget within their
    /// ranges.
    pub fn validate(&self) -> std::result::Result<(), InvalidSetting> {
        if let Some(name) = self.goal.object()
            && self.scene.object(name).is_none()
        {
            let known: Vec<&str> = self.scene.objects.iter().map(|o| o.name.as_str()).collect();
            return Err(InvalidSetting::new(
                "object",
                format!(
                    "{} (in {})",
                    kinergy_io::names::unknown("object", name, &known),
                    self.scene_name
                ),
            ));
        }
        if let Goal::Slide { distance, .. } = self.goal {
            InvalidSetting::require(
                DISTANCE_M.0 <= distance && distance <= DISTANCE_M.1,
                "distance",
                format!(
                    "{}: a drawer moves at most {} m",
                    distance.abs(),
                    DISTANCE_M.1
                ),
            )?;
        }
        InvalidSetting::require(
            matches!(self.goal, Goal::Reach(_))
                || matches!(self.level, Level::Auto | Level::Planner),
            "level",
            format!(
                "`{}` applies to a reach (a hand target); a task's moves are planned: auto or planner",
                self.level
            ),
        )?;
        if let Some(budget) = self.budget {
            let ms = budget.as_millis();
            InvalidSetting::require(
                (u128::from(BUDGET_MS.0)..=u128::from(BUDGET_MS.1)).contains(&ms),
                "budget_ms",
                format!("{ms}: expected {} to {}", BUDGET_MS.0, BUDGET_MS.1),
            )?;
        }
        Ok(())
    }

    /// Where the task reaches first, world meters: the hand target, or the grip point of
    /// the goal's object.
    pub fn first_aim(&self) -> Option<Point3<f64>> {
        match &self.goal {
            Goal::Reach(target) => Some(target.position),
            goal => goal.object().and_then(|o| self.scene.grip_point(o)),
        }
    }

    /// The planner's settings: the acting arm, the seed, the budget and, with a person,
    /// their synergy and their bell's time warp (errors: the person's parameters on the
    /// scene's character, [`PlanError::NoBell`](crate::PlanError::NoBell)).
    pub fn settings(&self) -> Result<TaskSettings> {
        let mut settings = TaskSettings {
            limb: Limb::arm(self.side),
            ..TaskSettings::default()
        };
        settings.rrt.seed = self.seed;
        settings.rrt.budget.time = self.budget;
        if let (Some(person), Some(aim)) = (self.person, self.first_aim()) {
            let character = Character::from_height(self.scene.character_height)?;
            let arm = PersonArm::toward(&character, person, &aim, Some(self.side))?;
            settings.warp = crate::person::person_warp(&character, &arm)?;
            settings.arm = arm.drive;
        }
        Ok(settings)
    }

    /// Plans the task.
    pub fn run(self) -> Result<Planned> {
        let settings = self.settings()?;
        let timing = TimingReport {
            warp: match settings.warp {
                Warp::Cubic => "cubic",
                Warp::Beta { .. } => "person",
            },
            peak: settings.warp.peak(),
            spread: settings.warp.spread(),
        };
        let triangles = self.scene.triangle_count();
        let planner = Planner::new(self.scene, settings)?;
        let motion: Manipulation = match &self.goal {
            Goal::Reach(target) => {
                // A person's synergy finishes a planned reach (their style), not an IK line:
                // with a person, `auto` plans, as a person's reach was planned before the
                // levels; a level asked for by name is run as asked.
                let level = match (self.level, self.person) {
                    (Level::Auto, Some(_)) => Level::Planner,
                    (level, _) => level,
                };
                planner.reach_by(target, HandShape::relaxed(), level)
            }
            Goal::Grasp(object) => planner.grasp(object),
            Goal::Relocate { object, to } => planner.relocate(object, to),
            Goal::Slide { object, distance } => planner.pull(object, *distance),
        }?;
        let clip = motion.to_clip(planner.character())?;
        let report = PlanReport {
            output: None,
            scene: self.scene_name,
            triangles,
            task: self.goal.name(),
            seed: self.seed,
            level: motion
                .levels
                .iter()
                .find(|t| t.solved())
                .map(|t| t.level.name()),
            levels: motion.levels.iter().map(LevelReport::of).collect(),
            body_dofs: motion
                .body
                .as_ref()
                .map(|b| b.dofs.clone())
                .unwrap_or_default(),
            body: motion.body.as_ref().map(BodyReport::of),
            frames: motion.poses.len(),
            frame_time_s: motion.frame_time,
            duration_s: motion.duration(),
            phases: motion.phases.iter().map(phase_report).collect(),
            objects: motion.objects.iter().filter_map(ObjectReport::of).collect(),
            timing,
        };
        let searches = motion.phases.iter().filter_map(search_trace).collect();
        Ok(Planned {
            clip,
            report,
            searches,
        })
    }
}

/// A planned phase's search, for Kallmann's Fig. 4.
fn search_trace(p: &crate::task::Phase) -> Option<SearchTrace> {
    let pl = p.planned.as_ref()?;
    let step = pl.space.resolution();
    Some(SearchTrace {
        phase: p.name.clone(),
        trees: pl.trees.clone(),
        raw_wrist: pl.raw.wrist_curve(&pl.space, step),
        smoothed_wrist: pl.path.wrist_curve(&pl.space, step),
    })
}

/// A phase of a planned motion as the report says it.
fn phase_report(p: &crate::task::Phase) -> PhaseReport {
    PhaseReport {
        name: p.name.clone(),
        first_frame: p.frames.start,
        last_frame: p.frames.end.saturating_sub(1),
        planned: p.planned.as_ref().map(|pl| PlannedReport {
            iterations: pl.search.iterations,
            nodes: pl.search.nodes,
            tree_nodes: [pl.trees[0].nodes.len(), pl.trees[1].nodes.len()],
            plan_ms: pl.search.seconds * 1e3,
            smooth_ms: pl.smoothing.seconds * 1e3,
            length_before_m: pl.smoothing.length_before,
            length_after_m: pl.smoothing.length_after,
            configs_before: pl.raw.configs.len(),
            configs_after: pl.path.configs.len(),
        }),
        synergy: p.synergy.as_ref().map(|a| SynergyReport {
            from_m: a.from_m,
            path_m: a.path_m,
            rejected: a.rejected.clone(),
            first_frame: p.frames.start + a.first_frame,
            frames: a.frames,
            plain_ik_from: a.plain_ik_from.map(|k| p.frames.start + k),
            distance_m: a.distance_m,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn task_names_read_back_and_goals_name_their_object() {
        for t in TaskKind::ALL {
            assert_eq!(t.name().parse::<TaskKind>(), Ok(t));
        }
        assert_eq!("lift".parse::<TaskKind>().unwrap_err().field, "task");
        let push = Goal::task(TaskKind::Push, "drawer".into(), None, 0.2).expect("a push");
        assert_eq!(push.name(), "push drawer");
        assert_eq!(
            push,
            Goal::Slide {
                object: "drawer".into(),
                distance: -0.2
            }
        );
        assert_eq!(
            Goal::task(TaskKind::Pull, "drawer".into(), None, 0.0)
                .unwrap_err()
                .field,
            "distance"
        );
        assert_eq!(
            Goal::task(TaskKind::Relocate, "book".into(), None, 0.2)
                .unwrap_err()
                .field,
            "to"
        );
    }
}
