//! Joint positions → a clip ([`Clip::from_positions`]), round trip on every shared capture
//! (all rigs: CMU, Bandai, Mixamo, Z-up, the bend-and-lift takes) and the committed fixtures:
//! each capture's world positions, made into a clip, come back within 1 mm at every joint on
//! every frame, and the clip has the capture's joints, frames and rate; where a capture's bone
//! stretches (Bandai Namco's reference root), kept in position channels ([`Stretch::Keep`]),
//! within 1 mm too, through a BVH file.

use std::path::{Path, PathBuf};

use kinergy_motion::{Clip, JointMap, PositionArrays, Stretch, read_clip};
#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "bvh"));
    files.sort();
    files
}

/// Every capture: the fixtures, and each folder of `../shared/data` (skipping, saying so,
/// where it is absent unless required).
fn captures() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = bvh_files(&root.join("tests/data"));
    // The synthetic character: an idle hand hangs straight below its forearm.
    files.push(root.join("data-synthetic/p01/r09.bvh"));
    let shared = root.join("../shared/data");
    match std::fs::read_dir(&shared) {
        Ok(folders) => {
            let mut folders: Vec<PathBuf> = folders.flatten().map(|e| e.path()).collect();
            folders.sort();
            for folder in folders.iter().filter(|p| p.is_dir()) {
                files.extend(bvh_files(folder));
            }
        }
        Err(_) => require_shared::shared_absent(&format!(
            "skipping the shared captures: {} is absent (never committed)",
            shared.display()
        )),
    }
    files
}

#[test]
fn every_captures_positions_come_back_within_a_millimetre() {
    let mut worst = Vec::new();
    let (mut rigid, mut stretchy) = (0, Vec::new());
    let files = captures();
    assert!(files.len() >= 2, "{files:?}");
    for path in &files {
        let (clip, _) = read_clip(path, &Default::default()).expect("read");
        let JointMap { names, parents, .. } = JointMap::of_skeleton(clip.skeleton());
        let positions: Vec<[f64; 3]> = clip
            .world_positions()
            .expect("fk")
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect();
        let made = Clip::from_positions(PositionArrays {
            joint_names: &names,
            parents: &parents,
            positions: &positions,
            frame_time: clip.frame_time(),
        })
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(made.clip.frame_count(), clip.frame_count());
        assert_eq!(made.clip.skeleton().joint_count(), names.len());
        assert_eq!(made.clip.frame_time(), clip.frame_time());
        // Independently of the report: the new clip's own FK against the input.
        let again = made.clip.world_positions().expect("fk");
        let max = again
            .iter()
            .zip(&positions)
            .map(|(a, p)| (a.coords - nalgebra::Vector3::from(*p)).norm())
            .fold(0.0, f64::max);
        assert!((max - made.max_error_m()).abs() < 1e-12);
        worst.push((path.file_name().unwrap_or_default().to_owned(), max));
        // A rigid skeleton's positions come back; bones that stretch over the take (reported)
        // are held at their median lengths, and no joint is further off than all of their
        // ranges together.
        let stretch: f64 = made.stretched.iter().map(|s| s.1).sum();
        assert!(
            max < 1e-3 + stretch,
            "{}: a joint {max} m from its position ({:?} stretch)",
            path.display(),
            made.stretched
        );
        if made.stretched.is_empty() {
            rigid += 1;
        } else {
            stretchy.push((path.clone(), made.stretched.clone()));
            // Kept, the stretching bones carry their length in position channels: every joint
            // comes back within 1 mm, through a BVH file too.
            let kept = Clip::from_positions_with(
                PositionArrays {
                    joint_names: &names,
                    parents: &parents,
                    positions: &positions,
                    frame_time: clip.frame_time(),
                },
                Stretch::Keep,
            )
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(
                kept.max_error_m() < 1e-3,
                "{}: {}",
                path.display(),
                kept.max_error_m()
            );
            let dir = tempfile::tempdir().expect("tmp");
            let file = dir.path().join("kept.bvh");
            kinergy_motion::write_clip(&file, &kept.clip, &Default::default()).expect("write");
            let (back, _) = read_clip(&file, &Default::default()).expect("read back");
            let far = back
                .world_positions()
                .expect("fk")
                .iter()
                .zip(&positions)
                .map(|(a, p)| (a.coords - nalgebra::Vector3::from(*p)).norm())
                .fold(0.0, f64::max);
            assert!(far < 1e-3, "{}: {far} m through the file", path.display());
        }
    }
    eprintln!("{worst:?}");
    eprintln!("{rigid} rigid; with stretching bones: {stretchy:?}");
    assert!(rigid >= 2, "the fixtures are rigid");
}

/// Every built-in hierarchy (SMPL's order is not BVH's depth-first one; COCO's has derived
/// joints): a rigid body's positions in the map's joints become a BVH that reads back with
/// each joint, by name, where it was.
#[test]
fn every_built_in_hierarchy_writes_a_bvh_that_reads_back_by_name() {
    for name in JointMap::built_in_names() {
        let map = JointMap::built_in(name).expect("built in");
        let n = map.names.len();
        // Joint k at a fixed place, the body turned a little and moved each frame.
        let rest: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let k = k as f64;
                [0.1 * (k * 1.3).sin(), 1.0 + 0.05 * k, 0.1 * (k * 0.7).cos()]
            })
            .collect();
        let mut positions = Vec::new();
        for f in 0..10 {
            let a = 0.03 * f as f64;
            let (s, c) = a.sin_cos();
            positions.extend(rest.iter().map(|p| {
                [
                    c * p[0] + s * p[2] + 0.01 * f as f64,
                    p[1],
                    -s * p[0] + c * p[2],
                ]
            }));
        }
        map.fill_derived(&mut positions);
        let made = Clip::from_positions(PositionArrays {
            joint_names: &map.names,
            parents: &map.parents,
            positions: &positions,
            frame_time: 1.0 / 30.0,
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join(format!("{name}.bvh"));
        kinergy_motion::write_clip(&path, &made.clip, &Default::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        // Written in centimetres (read so: this toy body, 0.8 m tall, would be guessed inches).
        let options = kinergy_motion::ImportOptions {
            unit: "cm".parse().expect("unit"),
            ..Default::default()
        };
        let (back, _) = read_clip(&path, &options).expect("read back");
        let world = back.world_positions().expect("fk");
        let m = back.skeleton().joint_count();
        for (j, joint) in map.names.iter().enumerate() {
            // A leaf is an End Site, which BVH cannot name: it reads back as `<parent>_End`.
            let leaf = || {
                let parent = map.names[map.parents[j] as usize].clone();
                back.skeleton().joint_index(&format!("{parent}_End"))
            };
            let k = back
                .skeleton()
                .joint_index(joint)
                .or_else(leaf)
                .unwrap_or_else(|| panic!("{name}: no {joint}"));
            for f in 0..10 {
                let (p, q) = (world[f * m + k], positions[f * n + j]);
                let d = ((p.x - q[0]).powi(2) + (p.y - q[1]).powi(2) + (p.z - q[2]).powi(2)).sqrt();
                assert!(d < 1e-3, "{name}: {joint} on frame {f} off by {d} m");
            }
        }
    }
}
