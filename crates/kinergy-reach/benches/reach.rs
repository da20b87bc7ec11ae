//! The full-body controller's cost per character per frame, and the synthetic set.
//!
//! `cargo bench -p kinergy-reach --bench reach`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinergy_motion::nalgebra::Point3;
use kinergy_reach::character::Character;
use kinergy_reach::controller::{
    ArmDrive, ReachSettings, animate_reach, arm_dof_names, plan_reach, reach_full_body,
    reach_full_body_driven,
};

fn per_frame(c: &mut Criterion) {
    let character = Character::from_height(1.75).expect("character");
    let mut group = c.benchmark_group("reach");
    for (name, target, flexibility) in [
        ("near", [0.25, 1.1, 0.35], 1.0),
        ("step", [0.2, 1.0, 1.15], 1.0),
        ("squat", [0.2, 0.15, 0.8], 3.0),
    ] {
        let settings = ReachSettings {
            flexibility,
            ..ReachSettings::default()
        };
        let target = Point3::new(target[0], target[1], target[2]);
        let frames = reach_full_body(&character, target, &settings)
            .expect("reach")
            .poses
            .len();
        group.throughput(Throughput::Elements(frames as u64));
        group.sample_size(10);
        group.bench_function(name, |b| {
            b.iter(|| reach_full_body(black_box(&character), target, &settings).expect("reach"))
        });
        // The same reach in its two halves: the plan (posture search, step, balance checks,
        // once per reach) and the frames (per frame: the issue's ≤ 10 µs).
        let plan = plan_reach(&character, target, &settings).expect("plan");
        group.throughput(Throughput::Elements(1));
        group.bench_function(format!("{name}_plan"), |b| {
            b.iter(|| plan_reach(black_box(&character), target, &settings).expect("plan"))
        });
        group.throughput(Throughput::Elements(frames as u64));
        group.bench_function(format!("{name}_frames"), |b| {
            b.iter(|| {
                animate_reach(black_box(&character), &plan, &settings, &ArmDrive::Profile)
                    .expect("reach")
            })
        });
    }
    // The arm driven by a person's synergy (the synthetic character's own fit), no step and
    // a full step.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/params/synthetic-p01-r09-sc.json");
    let file = kinergy_solver::ParamsFile::read(&path).expect("params");
    let synergy = file
        .synergy_for(&arm_dof_names(&character))
        .expect("the arm's DoFs");
    let constant = ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy: synergy.clone(),
        tempo: None,
        controller: None,
    };
    // As `reach --params` drives it: under the person's tempo law for the distance (the
    // fixture carries no tempo, so a person's: 0.5 m in 0.8 s, T ∝ d, a minimum-jerk peak).
    let law = ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy,
        tempo: Some(kinergy_solver::PersonTempo {
            reference_m: 0.5,
            duration_s: 0.8,
            exponent: 1.0,
            shape: 1.875,
            arm_m: None,
        }),
        controller: None,
    };
    for (name, target, drive) in [
        ("near_synergy", [0.25, 1.1, 0.35], &constant),
        ("step_synergy", [0.2, 1.0, 1.15], &constant),
        ("near_synergy_law", [0.25, 1.1, 0.35], &law),
        ("step_synergy_law", [0.2, 1.0, 1.15], &law),
    ] {
        let settings = ReachSettings::default();
        let target = Point3::new(target[0], target[1], target[2]);
        let m = reach_full_body_driven(&character, target, &settings, drive).expect("reach");
        eprintln!(
            "{name}: {} frames, hand-over {:?}",
            m.poses.len(),
            m.report.hand_over
        );
        group.throughput(Throughput::Elements(m.poses.len() as u64));
        group.sample_size(10);
        group.bench_function(name, |b| {
            b.iter(|| {
                reach_full_body_driven(black_box(&character), target, &settings, drive)
                    .expect("reach")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, per_frame);
criterion_main!(benches);
