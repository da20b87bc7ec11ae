//! The motion of a task being assembled phase by phase ([`Builder`]): planned phases, with the
//! person's synergy finishing a reach where its motion is free, straight phases and hand
//! phases, each appended to the manipulation as it is made.

use kinergy_io::InvalidSetting;
use kinergy_reach::character::Limb;
use kinergy_reach::controller::ArmDrive;
use kinergy_solver::analytic::OrbitSearch;
use nalgebra::{Isometry3, Point3, UnitQuaternion};

use super::{
    Manipulation, ObjectTrack, Phase, Planned, Planner, grasp_target, in_phase, largest_change,
    unknown_object,
};
use crate::approach::{CANDIDATE_STEP, PersonArm, Run, SynergyApproach};
use crate::error::{PlanError, Result};
use crate::hand::{HandShape, Hands};
use crate::rrt::{ArmPath, search, smooth, timed_with};
use crate::scene::Grasp;
use crate::space::{ArmConfig, ArmSpace, HandTarget};

/// A kind of planned phase: its name (in the motion and in errors), the salt that gives its
/// search a seed of its own, and whether the person's synergy finishes it where its motion is
/// free (a reach's: [`crate::approach`]; not where the body moves, whose synergy drives the
/// arm alone).
#[derive(Debug, Clone, Copy)]
pub(super) struct PlannedPhase {
    pub(super) name: &'static str,
    pub(super) salt: u64,
    pub(super) synergy_finish: bool,
}

impl PlannedPhase {
    /// To the grasp or the hand's target, finished by the person's synergy.
    pub(super) const REACH: PlannedPhase = PlannedPhase {
        name: "reach",
        salt: 0,
        synergy_finish: true,
    };
    /// Carrying the held object to its place.
    pub(super) const TRANSFER: PlannedPhase = PlannedPhase {
        name: "transfer",
        salt: 1,
        synergy_finish: false,
    };
    /// Back to the start posture.
    pub(super) const RETURN: PlannedPhase = PlannedPhase {
        name: "return",
        salt: 2,
        synergy_finish: false,
    };
    /// To a reach's goal posture, where the straight settle after its synergy is blocked.
    pub(super) const SETTLE: PlannedPhase = PlannedPhase {
        name: "settle",
        salt: 3,
        synergy_finish: false,
    };
}

/// The motion being assembled.
pub(super) struct Builder<'a> {
    pub(super) planner: &'a Planner,
    pub(super) space: ArmSpace,
    pub(super) q: ArmConfig,
    pub(super) alpha: f64,
    pub(super) hand: HandShape,
    pub(super) out: Manipulation,
    pub(super) held: Option<usize>,
    /// A reach's goal posture (orbit angle, configuration) when it was found before the
    /// motion (the body's posture search); `None`: the IK with collision avoidance finds it.
    pub(super) goal: Option<(f64, ArmConfig)>,
}

impl Builder<'_> {
    pub(super) fn push_frame(&mut self) {
        let pose = self.space.pose_with(&self.planner.start, &self.q);
        self.out.poses.push(pose);
        let mut hands = Hands::default();
        match self.planner.settings.limb {
            Limb::LeftArm => hands.left = self.hand,
            _ => hands.right = self.hand,
        }
        self.out.hands.push(hands);
        if let Some(i) = self.held
            && let Some(pose) = self.space.held_pose(&self.q)
        {
            let name = &self.planner.scene.objects[i].name;
            if let Some(t) = self.out.objects.iter_mut().find(|t| &t.name == name) {
                t.poses.push(pose);
            }
        }
        let n = self.out.poses.len();
        for t in &mut self.out.objects {
            while t.poses.len() < n {
                let last = *t.poses.last().unwrap_or(&Isometry3::identity());
                t.poses.push(last);
            }
        }
    }

    pub(super) fn frames_for(&self, length: f64, speed: f64) -> usize {
        let s = &self.planner.settings;
        let seconds = (length / speed).max(s.min_duration);
        (seconds * s.frame_rate).ceil() as usize + 1
    }

    /// The goal posture of a reach to `target`: the one found before, or the IK with
    /// collision avoidance's.
    pub(super) fn reach_goal(&self, target: &HandTarget) -> Result<(f64, ArmConfig)> {
        match self.goal {
            Some(goal) => Ok(goal),
            None => self.space.solve(target),
        }
    }

    /// The planner's reach to `target`: the goal posture ([`Builder::reach_goal`]), a planned
    /// phase to it, settled onto the target where the person's synergy finished it.
    pub(super) fn planned_reach(&mut self, target: &HandTarget, shape: HandShape) -> Result<()> {
        let (alpha, goal) = self.reach_goal(target)?;
        self.planned(PlannedPhase::REACH, &goal, alpha, shape)?;
        self.settle(target, (&goal, alpha), shape)
    }

    /// A planned `phase` to `goal` (orbit angle `alpha`), the hand's shape blended to `shape`
    /// over its frames.
    pub(super) fn planned(
        &mut self,
        phase: PlannedPhase,
        goal: &ArmConfig,
        alpha: f64,
        shape: HandShape,
    ) -> Result<()> {
        let PlannedPhase {
            name,
            salt,
            synergy_finish,
        } = phase;
        let s = &self.planner.settings;
        let mut rrt = s.rrt.clone();
        // The phase's seed: `salt` moved `seed` steps along SplitMix64's Weyl sequence.
        rrt.seed = kinergy_motion::seed::weyl(salt, s.rrt.seed);
        let found = search(&self.space, &self.q, goal, &rrt).map_err(|e| in_phase(e, name))?;
        let (raw, search, trees) = (found.path, found.stats, found.trees);
        let (path, smoothing) = smooth(&self.space, &raw, &s.smoothing, rrt.seed);
        let (configs, synergy) = match &s.arm {
            ArmDrive::Synergy {
                optimizer,
                synergy,
                controller,
                ..
            } if synergy_finish && !self.space.moves_body() => {
                let person = PersonArm {
                    character: &self.planner.character,
                    body: &self.planner.start,
                    space: &self.space,
                    optimizer,
                    synergy,
                    frame_rate: s.frame_rate,
                    reach_speed: s.reach_speed,
                    min_duration: s.min_duration,
                    controller: *controller,
                };
                self.synergy_finish(&person, &path, goal)?
            }
            _ => {
                let frames = self.frames_for(path.length(&self.space), s.reach_speed);
                (timed_with(&self.space, &path, frames, &s.warp), None)
            }
        };
        let first = self.out.poses.len() - 1;
        let from = self.hand;
        let last = (configs.len() - 1).max(1) as f64;
        for (k, q) in configs.iter().enumerate().skip(1) {
            self.q = *q;
            self.hand = from.lerp(&shape, k as f64 / last);
            self.push_frame();
        }
        self.alpha = if synergy.is_some() {
            self.space.alpha_of(&self.q)
        } else {
            alpha
        };
        self.out.phases.push(Phase {
            name: name.into(),
            frames: first..self.out.poses.len(),
            planned: Some(Planned {
                search,
                smoothing,
                raw,
                path,
                trees,
                space: self.space.clone(),
            }),
            synergy,
        });
        Ok(())
    }

    /// The frames of a planned reach finished by the person's synergy from the first point
    /// along `path` (every [`CANDIDATE_STEP`]) whose synergy motion is free: the path timed to
    /// that point, then the synergy's frames. The whole path, timed, when no point's is.
    pub(super) fn synergy_finish(
        &self,
        person: &PersonArm<'_>,
        path: &ArmPath,
        goal: &ArmConfig,
    ) -> Result<(Vec<ArmConfig>, Option<SynergyApproach>)> {
        let s = &self.planner.settings;
        let length = path.length(&self.space);
        let mut rejected = Vec::new();
        let candidates = (length / CANDIDATE_STEP).ceil() as usize;
        for k in 0..candidates {
            let at = k as f64 * CANDIDATE_STEP;
            let prefix = path.cut(&self.space, at);
            let from = *prefix.configs.last().unwrap_or(goal);
            let (tail, plain_ik_from, distance) = match person.run(&from, goal)? {
                Run::Arrived {
                    configs,
                    plain_ik_from,
                    distance,
                } => (configs, plain_ik_from, distance),
                Run::Rejected(why) => {
                    rejected.push(format!("from {at:.2} m: {why}"));
                    continue;
                }
            };
            let mut configs = if k == 0 {
                vec![from]
            } else {
                let frames = self.frames_for(at, s.reach_speed);
                timed_with(&self.space, &prefix, frames, &s.warp)
            };
            let first_frame = configs.len() - 1;
            // The synergy's first frame is the point's, its elbow relaxed at most
            // (`RELAXED_ELBOW`): played only when it differs.
            let skip = usize::from(largest_change(&tail[0], &from) < 1e-9);
            let frames = tail.len() - skip;
            configs.extend_from_slice(&tail[skip..]);
            let approach = SynergyApproach {
                from_m: at,
                path_m: length,
                rejected,
                first_frame,
                frames,
                // The synergy's frame k is the phase's frame first_frame + 1 + k − skip.
                plain_ik_from: plain_ik_from.map(|k| first_frame + 1 + k - skip),
                distance_m: distance,
            };
            return Ok((configs, Some(approach)));
        }
        let frames = self.frames_for(length, s.reach_speed);
        Ok((timed_with(&self.space, path, frames, &s.warp), None))
    }

    /// After a reach the person's synergy finished: a straight phase taking the grip to
    /// `target` (its position and orientation; the hand's own orientation kept where it has
    /// none), when it is more than 1 mm or 1° away. Where the straight line is blocked (no
    /// free posture on some frame), a planned phase to the reach's `goal` (configuration,
    /// orbit angle) instead.
    pub(super) fn settle(
        &mut self,
        target: &HandTarget,
        goal: (&ArmConfig, f64),
        shape: HandShape,
    ) -> Result<()> {
        if self.out.phases.last().is_none_or(|p| p.synergy.is_none()) {
            return Ok(());
        }
        let grip = self.space.grip_frame(&self.q);
        let off = (Point3::from(grip.translation.vector) - target.position).norm();
        let turned = target.orientation.map_or(0.0, |o| {
            let now = UnitQuaternion::from_rotation_matrix(
                &(grip.rotation * self.rest_rotation().inverse()),
            );
            now.angle_to(&o)
        });
        if off <= 1e-3 && turned <= 1f64.to_radians() {
            return Ok(());
        }
        let (q, alpha, hand) = (self.q, self.alpha, self.hand);
        let frames = self.out.poses.len();
        match self.straight("settle", target, shape) {
            Err(PlanError::GoalInCollision { .. } | PlanError::GoalUnreachable { .. }) => {
                // The straight's frames are dropped: the planned phase starts where it did.
                self.out.poses.truncate(frames);
                self.out.hands.truncate(frames);
                for t in &mut self.out.objects {
                    t.poses.truncate(frames);
                }
                (self.q, self.alpha, self.hand) = (q, alpha, hand);
                self.planned(PlannedPhase::SETTLE, goal.0, goal.1, shape)
            }
            other => other,
        }
    }

    /// The arm still while the hand takes `shape`.
    pub(super) fn hand_phase(&mut self, name: &str, shape: HandShape) {
        let s = &self.planner.settings;
        let frames = ((s.finger_time * s.frame_rate).ceil() as usize).max(1) + 1;
        let first = self.out.poses.len() - 1;
        let from = self.hand;
        for k in 1..frames {
            self.hand = from.lerp(&shape, k as f64 / (frames - 1) as f64);
            self.push_frame();
        }
        self.out.phases.push(Phase {
            name: name.into(),
            frames: first..self.out.poses.len(),
            planned: None,
            synergy: None,
        });
    }

    /// One frame of a followed target: the IK with collision avoidance, its orbit search
    /// starting at the previous orbit angle.
    pub(super) fn follow(&mut self, target: &HandTarget) -> Result<()> {
        let orbit = OrbitSearch {
            start: self
                .alpha
                .clamp(OrbitSearch::default().min, OrbitSearch::default().max),
            step: 2f64.to_radians(),
            ..OrbitSearch::default()
        };
        let (alpha, q) = self.space.solve_from(target, &orbit)?;
        self.alpha = alpha;
        self.q = q;
        self.push_frame();
        Ok(())
    }

    /// A straight phase: the grip frame from where it is to `target` (lerp + slerp) at the
    /// approach speed, the hand taking `shape`.
    pub(super) fn straight(
        &mut self,
        name: &str,
        target: &HandTarget,
        shape: HandShape,
    ) -> Result<()> {
        let from = self.space.grip_frame(&self.q);
        let p0 = Point3::from(from.translation.vector);
        let rest = self.rest_rotation();
        let r0 = UnitQuaternion::from_rotation_matrix(&(from.rotation * rest.inverse()));
        let r1 = target.orientation.unwrap_or(r0);
        let length = (target.position - p0).norm();
        let frames = self.frames_for(length, self.planner.settings.approach_speed);
        let first = self.out.poses.len() - 1;
        let hand0 = self.hand;
        for k in 1..frames {
            let t = crate::rrt::bell(k as f64 / (frames - 1) as f64);
            let step = HandTarget {
                position: p0 + (target.position - p0) * t,
                orientation: Some(r0.slerp(&r1, t)),
            };
            self.hand = hand0.lerp(&shape, k as f64 / (frames - 1) as f64);
            self.follow(&step).map_err(|e| in_phase(e, name))?;
        }
        self.out.phases.push(Phase {
            name: name.into(),
            frames: first..self.out.poses.len(),
            planned: None,
            synergy: None,
        });
        Ok(())
    }

    /// The hand's rest orientation in world.
    pub(super) fn rest_rotation(&self) -> nalgebra::Rotation3<f64> {
        let c = &self.planner.character;
        c.limb_base_frame(self.planner.settings.limb, &c.rest_pose())
            .rotation
    }

    /// Reach, approach and close on object `name`; it is held afterwards.
    pub(super) fn grasp(&mut self, name: &str) -> Result<Grasp> {
        let scene = &self.planner.scene;
        let index = scene
            .object_index(name)
            .ok_or_else(|| unknown_object(name))?;
        let object = &scene.objects[index];
        let grasp = object.grasp.clone().ok_or_else(|| {
            PlanError::Setting(InvalidSetting::new(
                "object",
                format!("`{name}` has no `grasp`: it cannot be grasped"),
            ))
        })?;
        let pre = grasp_target(&object.pose, &grasp, grasp.distance);
        let (alpha, goal) = self
            .space
            .solve(&pre)
            .map_err(|e| in_phase(e, "the pre-grasp"))?;
        self.planned(PlannedPhase::REACH, &goal, alpha, HandShape::open())?;
        self.settle(&pre, (&goal, alpha), HandShape::open())?;
        self.space.set_ignored(name, true)?;
        let at = grasp_target(&object.pose, &grasp, 0.0);
        self.straight("approach", &at, HandShape::open())?;
        self.hand_phase("close", grasp.hand);
        self.space.attach(scene, name, &self.q)?;
        self.held = Some(index);
        self.out.objects.push(ObjectTrack {
            name: name.to_string(),
            poses: vec![object.pose; self.out.poses.len()],
        });
        Ok(grasp)
    }

    /// A planned phase back to the starting posture, the hand relaxing.
    pub(super) fn return_to_start(&mut self) -> Result<()> {
        let goal = self.space.config_of(&self.planner.start);
        let alpha = self.space.alpha_of(&goal);
        self.planned(PlannedPhase::RETURN, &goal, alpha, HandShape::relaxed())
    }

    pub(super) fn release(&mut self) {
        self.space.release(&self.q);
        self.held = None;
    }
}
