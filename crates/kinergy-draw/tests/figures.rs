//! What the stick figures and scene outlines decide to draw, on real captures and the example
//! scene: no reference root, no zero-length bone, fingers thin, face not drawn; boxes, spheres
//! and meshes projected to their outlines.

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::path::{Path, PathBuf};

use approx::assert_relative_eq;
use kinergy_draw::bones::{BoneKind, MIN_BONE_M, Role, Segment, StickFigure};
use kinergy_draw::shapes::Solid;
use kinergy_motion::Clip;
use kinergy_plan::scene::Shape;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The repository's root.
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(path: &Path) -> Clip {
    kinergy_motion::read_clip(path, &Default::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// Every frame's drawn segments.
fn all_segments(clip: &Clip) -> (StickFigure, Vec<Vec<Segment>>) {
    let (figure, world) = StickFigure::of(clip).expect("fk");
    let n = clip.skeleton().joint_count();
    let frames = world.chunks(n).map(|w| figure.world_segments(w)).collect();
    (figure, frames)
}

fn name(clip: &Clip, j: usize) -> String {
    clip.skeleton().joint(j).name.to_ascii_lowercase()
}

fn says_finger(name: &str) -> bool {
    ["finger", "thumb", "index", "middle", "ring", "pinky"]
        .iter()
        .any(|p| name.contains(p))
}

/// No segment shorter than [`MIN_BONE_M`].
fn assert_no_zero_length(frames: &[Vec<Segment>], what: &str) {
    for (k, segments) in frames.iter().enumerate() {
        for s in segments {
            let length = nalgebra::distance(&s.from, &s.to);
            assert!(
                length >= MIN_BONE_M,
                "{what} frame {k}: {s:?} is {length} m long"
            );
        }
    }
}

fn bandai_clips() -> Option<Vec<PathBuf>> {
    let dir = repo().join("../shared/data/bandai-raise-left");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        require_shared::shared_absent(&format!(
            "skipped: {} is absent (Bandai Namco captures are not committed)",
            dir.display()
        ));
        return None;
    };
    let mut clips: Vec<PathBuf> = entries
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    clips.sort();
    clips.truncate(3);
    Some(clips)
}

#[test]
fn bandai_reference_root_and_zero_length_end_sites_are_not_drawn() {
    let Some(clips) = bandai_clips() else { return };
    assert!(!clips.is_empty(), "no Bandai captures found");
    for path in &clips {
        let clip = read(path);
        let what = path.display().to_string();
        let (figure, frames) = all_segments(&clip);
        assert_eq!(figure.roles()[0], Role::Reference, "{what}: joint_Root");
        assert!(
            !figure.dots().contains(&0),
            "{what}: the root's dot is drawn"
        );
        assert_no_zero_length(&frames, &what);
        for (k, segments) in frames.iter().enumerate() {
            // 21 joints below joint_Root: 20 bones between them; the 5 End Sites have zero
            // offsets.
            assert_eq!(segments.len(), 20, "{what} frame {k}");
            for s in segments {
                assert!(s.parent != 0 && s.child != 0, "{what} frame {k}: {s:?}");
                assert_eq!(s.kind, BoneKind::Body);
                for end in [s.from, s.to] {
                    assert!(
                        end.coords.norm() > 0.1,
                        "{what} frame {k}: a segment touches the origin: {s:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn cmu_fixtures_draw_fingers_thin_and_no_zero_length_bone() {
    let mut seen_fingers = 0;
    let dir = repo().join("tests/data");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/data")
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty());
    for path in &paths {
        let clip = read(path);
        let what = path.display().to_string();
        let (figure, frames) = all_segments(&clip);
        assert!(
            !figure.roles().contains(&Role::Reference),
            "{what}: a body root taken for a reference"
        );
        assert_no_zero_length(&frames, &what);
        let body = frames[0]
            .iter()
            .filter(|s| s.kind == BoneKind::Body)
            .count();
        assert!(body >= 15, "{what}: only {body} body bones");
        for s in &frames[0] {
            let child = name(&clip, s.child);
            let expected = if says_finger(&child) {
                BoneKind::Finger
            } else {
                BoneKind::Body
            };
            // A finger's End Site inherits its parent's role.
            if s.kind == BoneKind::Finger {
                seen_fingers += 1;
                let parent = name(&clip, s.parent);
                assert!(
                    says_finger(&child) || says_finger(&parent),
                    "{what}: {child}"
                );
            } else {
                assert_eq!(s.kind, expected, "{what}: {child}");
            }
        }
        for &d in figure.dots() {
            assert!(!says_finger(&name(&clip, d)), "{what}: a finger dot");
        }
    }
    assert!(
        seen_fingers > 0,
        "the CMU fixtures have finger joints (LeftFingerBase, LThumb)"
    );
}

#[test]
fn a_box_projects_to_its_side_and_a_mesh_to_its_feature_edges() {
    let side = |p: &Point3<f64>| (p.z, p.y);
    let pose = Isometry3::from_parts(Translation3::new(0.0, 1.0, 0.5), UnitQuaternion::identity());
    let b = Solid::new(&Shape::Box {
        half_extents: Vector3::new(0.1, 0.2, 0.3),
    });
    let outline = b.outline(&pose, side);
    assert_eq!(outline.fills.len(), 1);
    let hull = &outline.fills[0];
    assert_eq!(hull.len(), 4, "{hull:?}");
    for &(u, v) in hull {
        assert_relative_eq!((u - 0.5).abs(), 0.3, epsilon = 1e-12);
        assert_relative_eq!((v - 1.0).abs(), 0.2, epsilon = 1e-12);
    }
    assert_eq!(outline.lines.len(), 4);

    let sphere = Solid::new(&Shape::Sphere { radius: 0.1 }).outline(&pose, side);
    for &(u, v) in &sphere.fills[0] {
        assert_relative_eq!(
            ((u - 0.5).powi(2) + (v - 1.0).powi(2)).sqrt(),
            0.1,
            epsilon = 1e-9
        );
    }

    let scene = kinergy_plan::scene::Scene::read(&repo().join("examples/bookshelf/scene.json"))
        .expect("scene");
    let shelf = scene.object("shelf").expect("shelf");
    let outline = Solid::new(&shelf.shape).outline(&shelf.pose, side);
    let triangles = shelf.shape.triangle_count();
    assert!(!outline.lines.is_empty());
    assert!(
        outline.lines.len() < triangles,
        "{} feature edges for {triangles} triangles: the tessellation is drawn",
        outline.lines.len()
    );
    // Seen from the side the shelf spans its depth (z 0.40–0.70) and height (0–1.9 m).
    let (mut lo, mut hi) = (
        (f64::INFINITY, f64::INFINITY),
        (f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for &(u, v) in outline.fills.iter().flatten() {
        lo = (lo.0.min(u), lo.1.min(v));
        hi = (hi.0.max(u), hi.1.max(v));
    }
    assert_relative_eq!(lo.0, 0.40, epsilon = 1e-6);
    assert_relative_eq!(hi.0, 0.70, epsilon = 1e-6);
    assert_relative_eq!(lo.1, 0.0, epsilon = 1e-6);
    assert_relative_eq!(hi.1, 1.9, epsilon = 1e-6);
}
