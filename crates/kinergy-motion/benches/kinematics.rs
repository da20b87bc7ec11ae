//! Forward kinematics and Jacobians: the 7-DoF arm chain and a 31-joint CMU skeleton.
//!
//! `cargo bench -p kinergy-motion --bench kinematics`

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3xX, Translation3, UnitQuaternion};
use kinergy_motion::{ArmJoints, Chain, ChainPose, ImportOptions, Side, read_clip};

fn arm_chain(c: &mut Criterion) {
    let arm = Chain::arm(0.30, 0.26, 0.09).expect("arm");
    let base = IsometryMatrix3::from_parts(
        Translation3::new(-0.2, 1.4, 0.0),
        UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3).to_rotation_matrix(),
    );
    let q = [0.3, -0.5, 0.2, 1.1, -0.4, 0.2, 0.1];
    let mut pose = ChainPose::default();
    c.bench_function("arm7/fk", |b| {
        b.iter(|| {
            arm.fk_into(black_box(&base), black_box(&q), &mut pose)
                .expect("fk");
            black_box(pose.end)
        })
    });
    c.bench_function("arm7/end_position", |b| {
        b.iter(|| {
            arm.end_position(black_box(&base), black_box(&q))
                .expect("fk")
        })
    });
    let mut jac = Matrix3xX::zeros(7);
    c.bench_function("arm7/jacobian", |b| {
        b.iter(|| {
            arm.jacobian_into(black_box(&base), black_box(&q), &mut jac)
                .expect("jacobian");
            black_box(jac[(0, 0)])
        })
    });
}

fn cmu_skeleton(c: &mut Criterion) {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/cmu_12_01_walk.bvh"
    ));
    let (clip, _) = read_clip(path, &ImportOptions::default()).expect("CMU fixture");
    let skeleton = clip.skeleton().clone();
    let pose = clip.frame(100).expect("frame").to_vec();
    let mut world = Vec::new();
    c.bench_function("cmu31/fk", |b| {
        b.iter(|| {
            skeleton.fk_into(black_box(&pose), &mut world).expect("fk");
            black_box(world[0].translation.x)
        })
    });
    let arm = ArmJoints::find(&skeleton, Side::Right).expect("arm");
    let dofs = skeleton
        .path_dofs(arm.clavicle.unwrap_or(arm.shoulder), arm.wrist)
        .expect("path");
    c.bench_function("cmu31/arm_jacobian", |b| {
        b.iter(|| {
            skeleton
                .jacobian(black_box(&pose), arm.end_effector(), &dofs)
                .expect("jacobian")
        })
    });
    c.bench_function("cmu31/trajectory_4_joints_524_frames", |b| {
        b.iter(|| {
            clip.trajectory(black_box(&arm.metric_joints()))
                .expect("trajectory")
        })
    });
}

criterion_group!(benches, arm_chain, cmu_skeleton);
criterion_main!(benches);
