//! The planner against independent truths: paths re-checked at 10× finer resolution by a
//! separate collision test (full-body FK, every triangle on its own), exact endpoints, the
//! same seed giving the same path, every failure reason from a scene built for it, and
//! smoothing that never lengthens or invalidates a path.

use std::path::PathBuf;

use kinergy_plan::PlanError;
use kinergy_plan::hand::HandShape;
use kinergy_plan::rrt::{ArmPath, Budget, RrtSettings, Warp, plan, smooth, timed};
use kinergy_plan::scene::{Scene, Shape};
use kinergy_plan::space::{ArmConfig, ArmSpace, HandTarget};
use kinergy_plan::task::{Manipulation, Phase, Planner, Problem, TaskSettings};
use kinergy_reach::controller::{ArmDrive, arm_dof_names};
use kinergy_solver::ParamsFile;
use nalgebra::{Point3, UnitQuaternion, Vector3};

fn bookshelf() -> Scene {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/bookshelf/scene.json");
    Scene::read(&path).unwrap()
}

const DESTINATION: [f64; 3] = [-0.22, 1.49, 0.50];

fn transfer(seed: u64) -> (Planner, Problem) {
    let settings = TaskSettings {
        rrt: RrtSettings {
            seed,
            ..RrtSettings::default()
        },
        ..TaskSettings::default()
    };
    let planner = Planner::new(bookshelf(), settings).unwrap();
    let problem = planner
        .transfer_problem("blue_book", &Point3::from(DESTINATION))
        .unwrap();
    (planner, problem)
}

mod support;
use support::Verifier;

fn book_half(planner: &Planner) -> Vector3<f64> {
    match planner.scene().object("blue_book").unwrap().shape {
        Shape::Box { half_extents } => half_extents,
        _ => unreachable!(),
    }
}

#[test]
fn transfer_paths_are_free_at_ten_times_finer_resolution_with_exact_endpoints() {
    let (planner, _) = transfer(0);
    let verifier = Verifier::new(&planner, &["blue_book"]);
    let half = book_half(&planner);
    for seed in 0..4 {
        let (_, p) = transfer(seed);
        let rrt = RrtSettings {
            seed,
            ..RrtSettings::default()
        };
        let (raw, stats) = plan(&p.space, &p.start, &p.goal, &rrt).unwrap();
        assert!(
            stats.iterations > 0,
            "the straight line is blocked by the board"
        );
        assert_eq!(raw.configs[0], p.start);
        assert_eq!(*raw.configs.last().unwrap(), p.goal);
        let fine = p.space.resolution() / 10.0;
        assert_eq!(
            verifier.recheck(&p.space, &raw, fine, Some(half)),
            None,
            "seed {seed}"
        );
        let (smooth_path, s) = smooth(&p.space, &raw, &TaskSettings::default().smoothing, seed);
        assert!(s.length_after <= s.length_before);
        assert_eq!(smooth_path.configs[0], p.start);
        assert_eq!(*smooth_path.configs.last().unwrap(), p.goal);
        assert_eq!(
            verifier.recheck(&p.space, &smooth_path, fine, Some(half)),
            None,
            "smoothed, seed {seed}"
        );
        let frames = timed(&p.space, &smooth_path, 90);
        assert_eq!(frames[0], p.start);
        assert_eq!(frames[89], p.goal);
    }
}

#[test]
fn the_verifier_sees_what_the_planner_avoids() {
    // The straight interpolation from grasp to place drives the book through the board:
    // both checkers must say so, or the re-check above proves nothing.
    let (planner, p) = transfer(0);
    let verifier = Verifier::new(&planner, &["blue_book"]);
    let straight = ArmPath {
        configs: vec![p.start, p.goal],
    };
    assert!(!p.space.edge_free(&p.start, &p.goal));
    assert!(
        verifier
            .recheck(&p.space, &straight, 0.001, Some(book_half(&planner)))
            .is_some()
    );
}

#[test]
fn the_same_seed_gives_the_same_path() {
    let (_, p) = transfer(7);
    let rrt = RrtSettings {
        seed: 7,
        ..RrtSettings::default()
    };
    let a = plan(&p.space, &p.start, &p.goal, &rrt).unwrap().0;
    let b = plan(&p.space, &p.start, &p.goal, &rrt).unwrap().0;
    assert_eq!(a, b);
    let budget = TaskSettings::default().smoothing;
    assert_eq!(
        smooth(&p.space, &a, &budget, 3).0,
        smooth(&p.space, &b, &budget, 3).0
    );
    let others: Vec<ArmPath> = (8..12)
        .map(|seed| {
            plan(
                &p.space,
                &p.start,
                &p.goal,
                &RrtSettings {
                    seed,
                    ..rrt.clone()
                },
            )
            .unwrap()
            .0
        })
        .collect();
    assert!(others.iter().any(|o| *o != a), "seeds change the search");
}

#[test]
fn smoothing_never_lengthens_or_invalidates() {
    for seed in 0..12 {
        let (_, p) = transfer(seed);
        let rrt = RrtSettings {
            seed,
            ..RrtSettings::default()
        };
        let (raw, _) = plan(&p.space, &p.start, &p.goal, &rrt).unwrap();
        for budget in [1, 10, 200] {
            let b = Budget {
                iterations: budget,
                time: None,
            };
            let (s, stats) = smooth(&p.space, &raw, &b, seed);
            assert!(s.length(&p.space) <= raw.length(&p.space) + 1e-12);
            assert!((stats.length_after - s.length(&p.space)).abs() < 1e-9);
            assert!(s.is_valid(&p.space), "seed {seed} budget {budget}");
        }
    }
}

fn empty_planner(objects: &str) -> Planner {
    let text = format!(r#"{{"format_version": 1, "objects": [{objects}]}}"#);
    let scene = Scene::parse(&text, "t.json".as_ref(), ".".as_ref()).unwrap();
    Planner::new(scene, TaskSettings::default()).unwrap()
}

#[test]
fn start_in_collision() {
    // A box around the resting right hand (at about x = −0.33, y = 0.7).
    let planner = empty_planner(
        r#"{"name": "crate", "shape": {"type": "box", "half_extents": [0.1, 0.1, 0.1]}, "position": [-0.33, 0.75, 0]}"#,
    );
    let target = HandTarget {
        position: Point3::new(-0.2, 1.2, 0.4),
        orientation: None,
    };
    match planner.reach(&target, kinergy_plan::hand::HandShape::open()) {
        Err(PlanError::StartInCollision { contact }) => {
            assert!(contact.contains("crate"), "{contact}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn goal_unreachable() {
    let planner = empty_planner("");
    let target = HandTarget {
        position: Point3::new(-0.2, 1.3, 1.5),
        orientation: None,
    };
    let e = planner
        .reach(&target, kinergy_plan::hand::HandShape::open())
        .unwrap_err();
    assert!(matches!(e, PlanError::GoalUnreachable { .. }), "{e}");
    assert_eq!(
        kinergy_io::Classify::kind(&e),
        kinergy_io::ErrorKind::Unreachable
    );
}

#[test]
fn goal_in_collision() {
    let planner = empty_planner(
        r#"{"name": "block", "shape": {"type": "box", "half_extents": [0.15, 0.15, 0.15]}, "position": [-0.2, 1.2, 0.45]}"#,
    );
    let target = HandTarget {
        position: Point3::new(-0.2, 1.2, 0.45),
        orientation: None,
    };
    match planner.reach(&target, kinergy_plan::hand::HandShape::open()) {
        Err(PlanError::GoalInCollision { tried, contact }) => {
            assert!(tried > 0);
            assert!(contact.contains("block"), "{contact}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn no_path_within_the_budget_reports_progress() {
    let (_, p) = transfer(0);
    let rrt = RrtSettings {
        budget: Budget {
            iterations: 2,
            time: None,
        },
        ..RrtSettings::default()
    };
    match plan(&p.space, &p.start, &p.goal, &rrt) {
        Err(PlanError::NoPath {
            iterations,
            nodes,
            gap,
            ..
        }) => {
            assert_eq!(iterations, 2);
            assert!(nodes >= 2);
            assert!(gap > 0.0 && gap <= p.space.distance(&p.start, &p.goal) + 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn collision_aware_ik_moves_the_elbow_away_from_an_obstacle() {
    // Kallmann's Fig. 3: the first orbit angle's posture puts the elbow into an obstacle;
    // the search finds another angle whose posture is free and still reaches the target.
    let free = empty_planner("");
    let space = free.space().unwrap();
    let target = HandTarget {
        position: Point3::new(-0.25, 1.15, 0.35),
        orientation: Some(UnitQuaternion::from_scaled_axis(Vector3::x() * -1.6)),
    };
    let (alpha0, q0) = space.solve(&target).unwrap();
    let elbow = space.frames(&q0)[1].translation.vector;
    let obstacle = format!(
        r#"{{"name": "post", "shape": {{"type": "sphere", "radius": 0.05}}, "position": [{}, {}, {}]}}"#,
        elbow.x, elbow.y, elbow.z
    );
    let blocked = empty_planner(&obstacle);
    let space = blocked.space().unwrap();
    assert!(space.contact(&q0).is_some());
    let (alpha, q) = space.solve(&target).unwrap();
    assert!((alpha - alpha0).abs() > 1e-3);
    assert!(space.free(&q));
    let grip = space.grip_frame(&q);
    assert!((Point3::from(grip.translation.vector) - target.position).norm() < 1e-9);
}

#[test]
fn relocation_puts_the_book_where_asked() {
    let (planner, _) = transfer(1);
    let m = planner
        .relocate("blue_book", &Point3::from(DESTINATION))
        .unwrap();
    let names: Vec<&str> = m.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "reach", "approach", "close", "transfer", "open", "retreat", "return"
        ]
    );
    let track = &m.objects[0];
    assert_eq!(track.poses.len(), m.poses.len());
    let start = planner.scene().object("blue_book").unwrap().pose;
    assert_eq!(track.poses[0], start);
    let end = track.poses.last().unwrap();
    assert!((end.translation.vector - Vector3::from(DESTINATION)).norm() < 1e-9);
    assert!(end.rotation.angle_to(&start.rotation) < 1e-9);
    assert_eq!(m.poses[0], *planner.start_pose());
    assert_eq!(m.poses.last().unwrap(), planner.start_pose());
    // Every frame of every phase is collision-free for the separate checker, the book
    // included while held.
    let verifier = Verifier::new(&planner, &["blue_book"]);
    let space = planner.space().unwrap();
    for p in &m.phases {
        let Some(pl) = &p.planned else { continue };
        let half = pl.space.held().map(|_| book_half(&planner));
        assert_eq!(
            verifier.recheck(&pl.space, &pl.path, 0.001, half),
            None,
            "{}",
            p.name
        );
    }
    for (k, pose) in m.poses.iter().enumerate() {
        assert!(
            planner.character().joint_limits_ok(pose).is_ok(),
            "frame {k}"
        );
    }
    let clip = m.to_clip(planner.character()).unwrap();
    assert_eq!(clip.frame_count(), m.poses.len());
    let _ = space;
}

#[test]
fn the_hand_follows_a_drawer() {
    let planner = empty_planner(
        r#"{"name": "drawer", "shape": {"type": "box", "half_extents": [0.2, 0.06, 0.02]},
            "position": [-0.22, 1.08, 0.5],
            "grasp": {"position": [0, 0, -0.06], "rotation": [-0.90630779, 0, 0, 0.42261826],
                      "approach": [0, 0, 1], "distance": 0.1, "hand": "power"},
            "slide": {"axis": [0, 0, -1], "travel": 0.3}}"#,
    );
    let m = planner.pull("drawer", 0.2).unwrap();
    let track = &m.objects[0];
    let start = track.poses[0];
    let end = track.poses.last().unwrap();
    assert!(
        (end.translation.vector - start.translation.vector - Vector3::new(0.0, 0.0, -0.2)).norm()
            < 1e-12
    );
    let pull = m.phases.iter().find(|p| p.name == "pull").unwrap();
    let space = planner.space().unwrap();
    let grasp = planner
        .scene()
        .object("drawer")
        .unwrap()
        .grasp
        .clone()
        .unwrap();
    for k in pull.frames.clone() {
        let q = space.config_of(&m.poses[k]);
        let grip = Point3::from(space.grip_frame(&q).translation.vector);
        let handle = track.poses[k] * grasp.position;
        assert!(
            (grip - handle).norm() < 1e-9,
            "frame {k}: {}",
            (grip - handle).norm()
        );
    }
    assert!(planner.pull("drawer", 0.5).is_err(), "beyond the travel");
}

/// Played with a person's bell instead of the cubic, the relocation follows the same
/// collision-free paths (re-checked at 1 mm, 10× finer than planned, by the separate checker),
/// and each planned phase's hand speed peaks where the bell says, not half-way.
#[test]
fn a_persons_bell_times_the_same_collision_free_paths() {
    let warp = Warp::Beta {
        alpha: 2.5,
        beta: 4.0,
    };
    let settings = TaskSettings {
        rrt: RrtSettings {
            seed: 1,
            ..RrtSettings::default()
        },
        warp,
        ..TaskSettings::default()
    };
    let planner = Planner::new(bookshelf(), settings).unwrap();
    let m = planner
        .relocate("blue_book", &Point3::from(DESTINATION))
        .unwrap();
    let verifier = Verifier::new(&planner, &["blue_book"]);
    let mut checked = 0;
    for p in &m.phases {
        let Some(pl) = &p.planned else { continue };
        let half = pl.space.held().map(|_| book_half(&planner));
        assert_eq!(
            verifier.recheck(&pl.space, &pl.path, 0.001, half),
            None,
            "{}",
            p.name
        );
        // The phase's speed peaks near the bell's peak (0.33 here; the cubic's is 0.5), within
        // 0.1. The speed is measured as the bell distributes the path: by the planner's
        // distance (the largest displacement of the tracked points). The grip point alone is
        // not that measure: with the girdle the transfer's path has segments where the grip
        // moves fast while the held book's corners barely move, and its grip speed peaks at
        // 0.21 while the planner's distance peaks at 0.33 (measured: reach, transfer, return
        // 0.32, 0.33, 0.32; the 0-DoF clavicle's grip speed: 0.32, 0.28, 0.31).
        let configs: Vec<_> = m.poses[p.frames.clone()]
            .iter()
            .map(|pose| pl.space.config_of(pose))
            .collect();
        let speeds: Vec<f64> = configs
            .windows(2)
            .map(|w| pl.space.distance(&w[0], &w[1]))
            .collect();
        let at = speeds
            .iter()
            .enumerate()
            .fold((0, 0.0), |a, (i, &v)| if v > a.1 { (i, v) } else { a })
            .0;
        let peak = (at as f64 + 0.5) / speeds.len() as f64;
        assert!(
            (peak - warp.peak()).abs() < 0.1,
            "{}: the speed peaks at {peak:.2} of the phase, the bell at {:.2}",
            p.name,
            warp.peak()
        );
        checked += 1;
    }
    assert!(checked >= 2);
}

/// The person whose parameters are in the workspace's `tests/data/params/NAME.json`, as the
/// arm drive of a plan.
fn person(name: &str, planner: &Planner) -> ArmDrive {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/params")
        .join(format!("{name}.json"));
    let file = ParamsFile::read(&path).unwrap();
    ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy: file
            .synergy_for(&arm_dof_names(planner.character()))
            .unwrap(),
        tempo: None,
        controller: None,
    }
}

/// The configurations of the phase's frames, as a path the verifier re-checks.
fn frames_of(m: &Manipulation, space: &ArmSpace, phase: &Phase) -> ArmPath {
    ArmPath {
        configs: m.poses[phase.frames.clone()]
            .iter()
            .map(|p| space.config_of(p))
            .collect(),
    }
}

/// The person's synergy finishes a planned reach from the first point along the path whose
/// approach is free, every frame of it re-checked here at 1 mm (10× finer than planned) by the
/// separate checker; the pre-grasp is reached; the rest of the relocation still puts the book
/// where asked.
#[test]
fn a_persons_synergy_finishes_the_reach_where_its_approach_is_free() {
    for params in ["synthetic-p01-r09-sc", "006_14-sc"] {
        let base = Planner::new(bookshelf(), TaskSettings::default()).unwrap();
        let settings = TaskSettings {
            arm: person(params, &base),
            ..TaskSettings::default()
        };
        let planner = Planner::new(bookshelf(), settings).unwrap();
        let m = planner
            .relocate("blue_book", &Point3::from(DESTINATION))
            .unwrap();
        let reach = &m.phases[0];
        let approach = reach
            .synergy
            .as_ref()
            .expect("the synergy finished the reach");
        println!("{params}: {approach:?}");
        assert!(approach.frames > 10 && approach.distance_m <= kinergy_plan::approach::ARRIVED);
        assert!(approach.from_m < approach.path_m);
        // The synergy's frames follow the switch point, plain IK's (if any) among them.
        assert_eq!(
            reach.frames.len(),
            approach.first_frame + 1 + approach.frames,
            "{params}"
        );
        if let Some(k) = approach.plain_ik_from {
            assert!(
                k > approach.first_frame + 1 && k < approach.first_frame + 1 + approach.frames,
                "{params}: plain IK from frame {k}"
            );
        }
        let space = &reach.planned.as_ref().unwrap().space;
        let verifier = Verifier::new(&planner, &[]);
        for phase in &m.phases[..2] {
            assert_eq!(
                verifier.recheck(space, &frames_of(&m, space, phase), 0.001, None),
                None,
                "{params}: {}",
                phase.name
            );
        }
        // The grip never faster than a person's hand (natural.rs holds the full-body reach to
        // 3 m/s).
        let grips: Vec<_> = m.poses[..m.phases[1].frames.end]
            .iter()
            .map(|p| space.grip_frame(&space.config_of(p)).translation.vector)
            .collect();
        let fastest = grips
            .windows(2)
            .map(|w| (w[1] - w[0]).norm() / m.frame_time)
            .fold(0.0, f64::max);
        println!("{params}: fastest grip {fastest:.2} m/s");
        assert!(fastest <= 3.0, "{params}: {fastest} m/s");
        // The settle ends on the pre-grasp: the approach starts where it does without a
        // person.
        assert_eq!(m.phases[1].name, "settle");
        let grasp = planner.scene().object("blue_book").unwrap();
        let g = grasp.grasp.as_ref().unwrap();
        let pre = grasp.pose * (g.position - g.approach * g.distance);
        let settled = space.config_of(&m.poses[m.phases[1].frames.end - 1]);
        let grip = space.grip_frame(&settled).translation.vector;
        assert!((Point3::from(grip) - pre).norm() < 1e-6, "{params}: {grip}");
        let book = m.objects.iter().find(|t| t.name == "blue_book").unwrap();
        let end = book.poses.last().unwrap().translation.vector;
        assert!((end - Vector3::from(DESTINATION)).norm() < 1e-6);
        // Transfers and returns stay planned.
        assert!(m.phases.iter().skip(1).all(|p| p.synergy.is_none()));
    }
}

/// Where the synergy's approach collides — a post where the person's elbow ends, far from
/// the planned goal's — the approaches from the first points along the path are refused for
/// the post, the planned path is in force up to the point the synergy starts from (the same
/// configurations, timed), and every frame played is free at 1 mm by the separate checker.
#[test]
fn the_planned_path_stays_where_the_synergy_would_collide() {
    let target = HandTarget {
        position: Point3::new(-0.4, 1.3, 0.2),
        orientation: None,
    };
    let open = empty_planner("");
    let settings = TaskSettings {
        arm: person("synthetic-p01-r09-sc", &open),
        ..TaskSettings::default()
    };
    let with_person = |scene: Scene| Planner::new(scene, settings.clone()).unwrap();
    let m = with_person(open.scene().clone())
        .reach(&target, HandShape::open())
        .unwrap();
    let free = m.phases[0].synergy.clone().unwrap();
    assert_eq!((free.from_m, free.rejected.len()), (0.0, 0));
    let space = open.space().unwrap();
    let end = space.config_of(&m.poses[m.phases[0].frames.end - 1]);
    let elbow = space.frames(&end)[1].translation.vector;
    let post = format!(
        r#"{{"name": "post", "shape": {{"type": "sphere", "radius": 0.08}}, "position": [{}, {}, {}]}}"#,
        elbow.x, elbow.y, elbow.z
    );
    let planner = with_person(empty_planner(&post).scene().clone());
    let m = planner.reach(&target, HandShape::open()).unwrap();
    let reach = &m.phases[0];
    let approach = reach.synergy.as_ref().unwrap();
    assert!(approach.from_m > 0.0 && approach.from_m < approach.path_m);
    assert!(!approach.rejected.is_empty());
    // Every refusal is a collision, with the post on all but one (measured: 11 of 12; since
    // the synergy arm brakes before the character's shoulder limits, its approach from 0.10 m
    // meets the chest with the upper arm first).
    for why in &approach.rejected {
        assert!(why.contains(" × "), "{why}");
    }
    let at_post = approach
        .rejected
        .iter()
        .filter(|why| why.contains("post"))
        .count();
    assert!(
        at_post + 1 >= approach.rejected.len(),
        "{:?}",
        approach.rejected
    );
    let planned = reach.planned.as_ref().unwrap();
    let prefix = planned.path.cut(&planned.space, approach.from_m);
    let played: Vec<ArmConfig> = m.poses[..=approach.first_frame]
        .iter()
        .map(|p| planned.space.config_of(p))
        .collect();
    assert_eq!(
        played,
        timed(&planned.space, &prefix, approach.first_frame + 1)
    );
    let verifier = Verifier::new(&planner, &[]);
    for phase in &m.phases {
        assert_eq!(
            verifier.recheck(
                &planned.space,
                &frames_of(&m, &planned.space, phase),
                0.001,
                None
            ),
            None,
            "{}",
            phase.name
        );
    }
}

#[test]
fn a_hand_target_from_its_numbers() {
    let t = HandTarget::from_values(&[0.1, 1.2, 0.4]).expect("a point");
    assert_eq!(t.position, Point3::new(0.1, 1.2, 0.4));
    assert!(t.orientation.is_none());
    // A quarter turn about y, given unnormalized (qx, qy, qz, qw) = (0, 2, 0, 2).
    let t = HandTarget::from_values(&[0.1, 1.2, 0.4, 0.0, 2.0, 0.0, 2.0]).expect("a pose");
    let q = t.orientation.expect("turned");
    let expected = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
    assert!(q.angle_to(&expected) < 1e-12);
    for (values, says) in [
        (&[0.1, 1.2][..], "found 2"),
        (&[0.1, f64::NAN, 0.4][..], "finite"),
        (&[0.1, 1.2, 0.4, 0.0, 0.0, 0.0, 0.0][..], "zero"),
    ] {
        let why = HandTarget::from_values(values).expect_err("refused");
        assert!(why.contains(says), "{why}");
    }
}
