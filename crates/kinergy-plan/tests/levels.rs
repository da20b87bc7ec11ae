//! Kallmann's three levels against independent truths, on the scenes made for each
//! (`examples/levels/`): `auto` ends at the level each scene was made for, every motion it
//! accepts re-checked at 1 mm by the tests' own collision test; the `ik` and `straight`
//! levels keep the grip on the straight line to the target; a forced `ik` leaves its motion
//! unchecked (and the post scene's does collide, so `straight` has something to mend); a
//! forced level that fails names itself and why; the planner's trees are the ones its path
//! was made from.

use std::path::PathBuf;

use kinergy_io::{Classify, ErrorKind};
use kinergy_motion::Side;
use kinergy_plan::PlanError;
use kinergy_plan::hand::HandShape;
use kinergy_plan::level::Level;
use kinergy_plan::request::{Goal, TaskKind, TaskRequest};
use kinergy_plan::rrt::ArmPath;
use kinergy_plan::scene::Scene;
use kinergy_plan::space::{ArmConfig, HandTarget};
use kinergy_plan::task::{Manipulation, Planner, TaskSettings};
use nalgebra::Point3;

mod support;
use support::Verifier;

fn scene(name: &str) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/levels")
        .join(name);
    Scene::read(&path).unwrap()
}

fn planner(name: &str) -> Planner {
    Planner::new(scene(name), TaskSettings::default()).unwrap()
}

/// The target each scene was made for.
fn target(name: &str) -> HandTarget {
    let position = match name {
        "board.json" => Point3::new(-0.2, 1.15, 0.35),
        _ => Point3::new(-0.2, 1.2, 0.4),
    };
    HandTarget {
        position,
        orientation: None,
    }
}

/// The arm's configuration on every frame of a motion.
fn frames(planner: &Planner, m: &Manipulation) -> ArmPath {
    let space = planner.space().unwrap();
    ArmPath {
        configs: m.poses.iter().map(|p| space.config_of(p)).collect(),
    }
}

/// The grip point on every frame.
fn grips(planner: &Planner, m: &Manipulation) -> Vec<Point3<f64>> {
    let space = planner.space().unwrap();
    frames(planner, m)
        .configs
        .iter()
        .map(|q| Point3::from(space.grip_frame(q).translation.vector))
        .collect()
}

/// The first contact of the motion, the frames and the joint-space interpolation between
/// them re-checked every millimetre of the largest tracked-point displacement.
fn recheck(planner: &Planner, m: &Manipulation) -> Option<String> {
    let space = planner.space().unwrap();
    Verifier::new(planner, &[]).recheck(&space, &frames(planner, m), 1e-3, None)
}

fn levels_of(m: &Manipulation) -> Vec<(Level, bool)> {
    m.levels.iter().map(|t| (t.level, t.solved())).collect()
}

#[test]
fn auto_ends_at_the_level_each_scene_was_made_for_and_its_motion_is_free() {
    use Level::{Ik, Planner as Rrt, Straight};
    let cases: [(&str, &[(Level, bool)]); 3] = [
        ("open.json", &[(Ik, true)]),
        ("post.json", &[(Ik, false), (Straight, true)]),
        ("board.json", &[(Ik, false), (Straight, false), (Rrt, true)]),
    ];
    for (name, expected) in cases {
        let planner = planner(name);
        let t = target(name);
        let m = planner
            .reach_by(&t, HandShape::relaxed(), Level::Auto)
            .unwrap();
        assert_eq!(levels_of(&m), expected, "{name}");
        for failed in m.levels.iter().filter(|l| !l.solved()) {
            let why = failed.failure.as_deref().unwrap();
            let obstacle = if name == "post.json" { "post" } else { "board" };
            assert!(
                why.contains("blocked") && why.contains(obstacle),
                "{name}: {why}"
            );
        }
        assert!(m.levels.iter().all(|l| l.motion_checked && l.seconds > 0.0));
        assert_eq!(recheck(&planner, &m), None, "{name}");
        let end = *grips(&planner, &m).last().unwrap();
        assert!((end - t.position).norm() < 1e-3, "{name}: ends at {end}");
        // Deterministic: the same request, the same motion.
        let again = planner
            .reach_by(&t, HandShape::relaxed(), Level::Auto)
            .unwrap();
        assert_eq!(again.poses, m.poses, "{name}");
    }
}

#[test]
fn the_ik_and_straight_levels_keep_the_grip_on_the_straight_line() {
    for (name, level) in [
        ("open.json", Level::Ik),
        ("open.json", Level::Straight),
        ("post.json", Level::Straight),
    ] {
        let planner = planner(name);
        let t = target(name);
        let m = planner.reach_by(&t, HandShape::relaxed(), level).unwrap();
        assert_eq!(levels_of(&m), [(level, true)], "{name} {level}");
        let grips = grips(&planner, &m);
        let (p0, p1) = (grips[0], t.position);
        let axis = (p1 - p0).normalize();
        let mut along = 0.0;
        for (k, g) in grips.iter().enumerate() {
            let s = (g - p0).dot(&axis);
            let off = ((g - p0) - axis * s).norm();
            assert!(
                off < 1e-3,
                "{name} {level}: frame {k} is {off} m off the line"
            );
            assert!(s >= along - 1e-6, "{name} {level}: frame {k} goes back");
            along = s;
        }
        assert!((grips.last().unwrap() - p1).norm() < 1e-3);
        assert_eq!(m.phases.len(), 1);
        assert!(m.phases[0].planned.is_none());
    }
}

#[test]
fn a_forced_ik_does_not_check_its_motion_and_says_so() {
    // In the post scene the interpolated orbit swings the elbow into the post: forced, the ik
    // level returns that motion (the goal posture free), reported unchecked; the straight
    // level's motion in the same scene is free (the test above and the one before).
    let planner = planner("post.json");
    let m = planner
        .reach_by(&target("post.json"), HandShape::relaxed(), Level::Ik)
        .unwrap();
    assert_eq!(levels_of(&m), [(Level::Ik, true)]);
    assert!(!m.levels[0].motion_checked);
    let contact = recheck(&planner, &m).expect("the ik motion touches the post");
    assert!(contact.contains("post"), "{contact}");
    let space = planner.space().unwrap();
    let last: ArmConfig = space.config_of(m.poses.last().unwrap());
    assert_eq!(
        Verifier::new(&planner, &[]).contact(&space, &last, None),
        None
    );
}

#[test]
fn a_forced_level_that_fails_names_the_level_and_why() {
    let planner = planner("board.json");
    let e = planner
        .reach_by(&target("board.json"), HandShape::relaxed(), Level::Straight)
        .unwrap_err();
    let text = e.to_string();
    assert!(
        text.starts_with("level straight failed: the straight hand path is blocked"),
        "{text}"
    );
    assert!(text.contains("board"), "{text}");
    assert_eq!(e.kind(), ErrorKind::Unreachable);
    match e {
        PlanError::Level {
            asked,
            tried,
            cause,
        } => {
            assert_eq!(asked, Level::Straight);
            assert_eq!(tried.len(), 1);
            let PlanError::PathBlocked {
                frame,
                frames,
                fraction,
                ..
            } = *cause
            else {
                panic!("{cause}")
            };
            assert!(0 < frame && frame <= frames && (0.0..=1.0).contains(&fraction));
        }
        other => panic!("{other}"),
    }
    // A goal inside an obstacle: no level can mend it, so `auto` stops at the first.
    let inside = HandTarget {
        position: Point3::new(-0.2, 1.0, 0.3),
        orientation: None,
    };
    let e = planner
        .reach_by(&inside, HandShape::relaxed(), Level::Auto)
        .unwrap_err();
    assert!(
        e.to_string().starts_with(
            "level auto: stopped at ik, as no level can mend this: the goal is in collision"
        ),
        "{e}"
    );
    assert_eq!(e.kind(), ErrorKind::Unreachable);
    let e = planner
        .reach_by(&inside, HandShape::relaxed(), Level::Ik)
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("level ik failed: the goal is in collision"),
        "{e}"
    );
}

#[test]
fn the_planners_trees_are_the_ones_its_path_was_made_from() {
    let planner = planner("board.json");
    let m = planner
        .reach_by(&target("board.json"), HandShape::relaxed(), Level::Planner)
        .unwrap();
    let phase = &m.phases[0];
    let planned = phase.planned.as_ref().expect("a planned reach");
    let [from_start, from_goal] = &planned.trees;
    assert!(
        planned.search.iterations > 0,
        "the board blocks the straight line"
    );
    assert_eq!(
        from_start.nodes.len() + from_goal.nodes.len(),
        planned.search.nodes
    );
    assert_eq!(from_start.nodes[0].q, planned.raw.configs[0]);
    assert_eq!(from_goal.nodes[0].q, *planned.raw.configs.last().unwrap());
    let space = &planned.space;
    let verifier = Verifier::new(&planner, &[]);
    for tree in &planned.trees {
        assert_eq!(tree.nodes[0].parent, None);
        assert_eq!(tree.edges().count(), tree.nodes.len() - 1);
        for (parent, child) in tree.edges() {
            assert!(parent < child);
            let edge = ArmPath {
                configs: vec![tree.nodes[parent].q, tree.nodes[child].q],
            };
            assert_eq!(verifier.recheck(space, &edge, 1e-3, None), None);
        }
        for n in &tree.nodes {
            assert!((n.wrist - space.points(&n.q).wrist()).norm() < 1e-12);
        }
    }
    // The path as found runs along tree branches: every configuration is a node.
    for q in &planned.raw.configs {
        assert!(
            planned
                .trees
                .iter()
                .any(|t| t.nodes.iter().any(|n| n.q == *q)),
            "{q:?} is no node"
        );
    }
}

#[test]
fn a_request_reports_the_levels_and_the_searches() {
    let request = |goal, level| TaskRequest {
        scene: scene("board.json"),
        scene_name: "board.json".into(),
        goal,
        side: Side::Right,
        level,
        seed: 0,
        budget: None,
        person: None,
    };
    let planned = request(Goal::Reach(target("board.json")), Level::Auto)
        .run()
        .unwrap();
    assert_eq!(planned.report.level, Some("planner"));
    let names: Vec<(&str, bool)> = planned
        .report
        .levels
        .iter()
        .map(|l| (l.level, l.solved))
        .collect();
    assert_eq!(
        names,
        [("ik", false), ("straight", false), ("planner", true)]
    );
    assert_eq!(planned.searches.len(), 1);
    let search = &planned.searches[0];
    let nodes = planned.report.phases[0]
        .planned
        .as_ref()
        .unwrap()
        .tree_nodes;
    assert_eq!(
        nodes,
        [search.trees[0].nodes.len(), search.trees[1].nodes.len()]
    );
    assert!(search.raw_wrist.len() >= 2 && search.smoothed_wrist.len() >= 2);
    let json = serde_json::to_value(&planned.report).unwrap();
    assert_eq!(json["level"], "planner");
    assert_eq!(json["levels"][0]["motion_checked"], true);
    assert!(json["levels"][0]["why"].as_str().unwrap().contains("board"));
    // The levels are a reach's: a task is planned.
    let grasp = Goal::task(TaskKind::Grasp, "board".into(), None, 0.2).unwrap();
    let e = request(grasp, Level::Straight).validate().unwrap_err();
    assert_eq!(e.field, "level");
}
