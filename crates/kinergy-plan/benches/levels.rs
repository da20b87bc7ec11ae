//! Kallmann's three levels of a reach, timed (`Planner::reach_by`, the whole motion: the goal
//! posture's IK, every frame and its checks; for the planner, the search, the smoothing and the
//! timing):
//!
//! - `levels/made_for`: each level on the scene made for it (`examples/levels/`): `ik` on
//!   `open.json`, `straight` on `post.json`, `planner` on `board.json`, and `auto` on each
//!   (the cost of escalating through the levels that fail first);
//! - `levels/bookshelf`: the three levels forced on one reach into the bookshelf of Kallmann's
//!   Fig. 5 (11,900 triangles, 12 primitives), `--target -0.25,1.1,0.3`, which each solves.
//!
//! - `levels/body`: reaches the arm alone cannot make, so the body moves (issue 43, item 5):
//!   the low target between the bookshelf's boards (`--target=-0.25,0.45,0.4`) at
//!   each level and `auto`, and a target across the body (`--target=0.3,1.0,0.35` with the
//!   right arm) whose planner searches (the whole reach: the body's goal posture search, the
//!   levels tried, the motion); `body/contact` is one whole-body collision test of a
//!   configuration on the way to the low target, against `arm_contact`, the arm-only test's.
//!
//! Before criterion runs, each case's levels and their own times (`LevelTry::seconds`) are
//! printed to stderr.

use std::hint::black_box;
use std::path::Path;

use criterion::Criterion;
use kinergy_plan::hand::HandShape;
use kinergy_plan::level::Level;
use kinergy_plan::scene::Scene;
use kinergy_plan::space::HandTarget;
use kinergy_plan::task::{Planner, TaskSettings};
use nalgebra::Point3;

fn planner(file: &str) -> Planner {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(file);
    let scene = Scene::read(&path).expect("the scene");
    Planner::new(scene, TaskSettings::default()).expect("a planner")
}

fn target(x: f64, y: f64, z: f64) -> HandTarget {
    HandTarget {
        position: Point3::new(x, y, z),
        orientation: None,
    }
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let cases = [
        (
            "open",
            "levels/open.json",
            target(-0.2, 1.2, 0.4),
            Level::Ik,
        ),
        (
            "post",
            "levels/post.json",
            target(-0.2, 1.2, 0.4),
            Level::Straight,
        ),
        (
            "board",
            "levels/board.json",
            target(-0.2, 1.15, 0.35),
            Level::Planner,
        ),
    ];
    let shelf = planner("bookshelf/scene.json");
    let into_shelf = target(-0.25, 1.1, 0.3);
    let mut g = c.benchmark_group("levels");
    g.sample_size(20);
    for (name, file, t, level) in &cases {
        let p = planner(file);
        for level in [*level, Level::Auto] {
            let m = p
                .reach_by(t, HandShape::relaxed(), level)
                .expect("the scene's level solves it");
            eprintln!(
                "levels/made_for/{name}/{level}: {}",
                m.levels
                    .iter()
                    .map(|l| format!(
                        "{} {} in {:.3} ms",
                        l.level,
                        if l.solved() { "solved" } else { "failed" },
                        l.seconds * 1e3
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            g.bench_function(format!("made_for/{name}/{level}"), |b| {
                b.iter(|| {
                    p.reach_by(black_box(t), HandShape::relaxed(), level)
                        .expect("solved")
                })
            });
        }
    }
    for level in [Level::Ik, Level::Straight, Level::Planner] {
        let m = shelf
            .reach_by(&into_shelf, HandShape::relaxed(), level)
            .expect("each level solves it");
        eprintln!(
            "levels/bookshelf/{level}: {:.3} ms, {} frames",
            m.levels[0].seconds * 1e3,
            m.poses.len()
        );
        g.bench_function(format!("bookshelf/{level}"), |b| {
            b.iter(|| {
                shelf
                    .reach_by(black_box(&into_shelf), HandShape::relaxed(), level)
                    .expect("solved")
            })
        });
    }
    let body_cases = [
        ("low", target(-0.25, 0.45, 0.4), Level::Ik),
        ("low", target(-0.25, 0.45, 0.4), Level::Straight),
        ("low", target(-0.25, 0.45, 0.4), Level::Planner),
        ("low", target(-0.25, 0.45, 0.4), Level::Auto),
        ("across", target(0.3, 1.0, 0.35), Level::Auto),
    ];
    for (name, t, level) in &body_cases {
        let m = shelf
            .reach_by(t, HandShape::relaxed(), *level)
            .expect("the body's level solves it");
        let body = m.body.as_ref().expect("the body moves");
        let planned = m.phases[0].planned.as_ref();
        eprintln!(
            "levels/body/{name}/{level}: goal stance {:.0}° swing, {:.0}° twist, {:.3} m squat \
             ({} stances, {:.3} ms); {}; {} frames{}",
            body.goal[0].to_degrees(),
            body.goal[1].to_degrees(),
            body.goal[2],
            body.tried,
            body.seconds * 1e3,
            m.levels
                .iter()
                .map(|l| format!(
                    "{} {} in {:.3} ms",
                    l.level,
                    if l.solved() { "solved" } else { "failed" },
                    l.seconds * 1e3
                ))
                .collect::<Vec<_>>()
                .join(", "),
            m.poses.len(),
            planned
                .map(|p| format!(
                    "; planner {} iterations, {} nodes, search {:.3} ms, smoothing {:.3} ms",
                    p.search.iterations,
                    p.search.nodes,
                    p.search.seconds * 1e3,
                    p.smoothing.seconds * 1e3
                ))
                .unwrap_or_default()
        );
        g.bench_function(format!("body/{name}/{level}"), |b| {
            b.iter(|| {
                shelf
                    .reach_by(black_box(t), HandShape::relaxed(), *level)
                    .expect("solved")
            })
        });
    }
    // One collision test of a configuration half-way to the low target, the body moving,
    // against the arm-only space's test of the same arm.
    let m = shelf
        .reach_by(&body_cases[0].1, HandShape::relaxed(), Level::Ik)
        .expect("solved");
    let space = shelf
        .body_space(m.body.as_ref().expect("the body moves"))
        .expect("the body's space");
    let q = space.config_of(&m.poses[m.poses.len() / 2]);
    let arm_space = shelf.space().expect("the arm's space");
    let mut arm_q = q;
    arm_q[7..].fill(0.0);
    g.bench_function("body/contact", |b| b.iter(|| space.contact(black_box(&q))));
    g.bench_function("body/arm_contact", |b| {
        b.iter(|| arm_space.contact(black_box(&arm_q)))
    });
    g.finish();
    c.final_summary();
}
