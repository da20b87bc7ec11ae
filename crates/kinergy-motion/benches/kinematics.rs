//! Forward kinematics and Jacobians: the 7-DoF arm chain and a 31-joint CMU skeleton; and
//! joint positions made into a clip (`kinergy from-positions`' work); a walk retargeted onto
//! another rig (`kinergy retarget`'s).
//!
//! `cargo bench -p kinergy-motion --bench kinematics`

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3xX, Translation3, UnitQuaternion};
use kinergy_motion::{
    ArmJoints, BodyJoints, Chain, ChainPose, Clip, ImportOptions, JointMap, PositionArrays,
    Retargeter, Side, read_clip,
};

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

/// 10,000 frames of 24 joints (the synthetic r09 played back and forth) made into a clip:
/// the floor is 10,000 frames per second on one core.
fn from_positions(c: &mut Criterion) {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data-synthetic/p01/r09.bvh"
    ));
    let (clip, _) = read_clip(path, &ImportOptions::default()).expect("r09");
    let skeleton = clip.skeleton();
    let n = skeleton.joint_count();
    let JointMap { names, parents, .. } = JointMap::of_skeleton(skeleton);
    let world: Vec<[f64; 3]> = clip
        .world_positions()
        .expect("fk")
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect();
    let frames = world.len() / n;
    let order: Vec<usize> = (0..frames).chain((0..frames).rev()).collect();
    let positions: Vec<[f64; 3]> = (0..10_000)
        .flat_map(|k| {
            let f = order[k % order.len()];
            world[f * n..(f + 1) * n].to_vec()
        })
        .collect();
    let mut group = c.benchmark_group("positions");
    group.throughput(Throughput::Elements(10_000));
    group.sample_size(10);
    group.bench_function("from_positions_24_joints_10000_frames", |b| {
        b.iter(|| {
            Clip::from_positions(PositionArrays {
                joint_names: &names,
                parents: &parents,
                positions: black_box(&positions),
                frame_time: clip.frame_time(),
            })
            .expect("clip")
        })
    });
    group.finish();
}

/// A CMU walk (31 joints, 524 frames at 120 Hz) retargeted onto the Character Creator rig
/// (its 100 joints), the retargeter made once: the floor is 5,000 frames per second on
/// one core.
fn retarget(c: &mut Criterion) {
    let data = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data"));
    let (walk, _) =
        read_clip(&data.join("cmu_12_01_walk.bvh"), &ImportOptions::default()).expect("walk");
    let (cc, _) = read_clip(&data.join("006_14.bvh"), &ImportOptions::default()).expect("cc");
    let from = BodyJoints::find(walk.skeleton()).expect("walk body");
    let to = BodyJoints::find(cc.skeleton()).expect("cc body");
    let retargeter = Retargeter::new(&walk, from, cc.skeleton().clone(), to).expect("retargeter");
    let mut group = c.benchmark_group("retarget");
    group.throughput(Throughput::Elements(walk.frame_count() as u64));
    group.sample_size(20);
    group.bench_function("cmu_walk_onto_character_creator", |b| {
        b.iter(|| retargeter.run(black_box(&walk)).expect("run"))
    });
    group.finish();
}

criterion_group!(benches, arm_chain, cmu_skeleton, from_positions, retarget);
criterion_main!(benches);
