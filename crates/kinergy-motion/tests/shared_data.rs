//! Every BVH file under the shared data folder (`../shared/data` beside the repository), read
//! with the default options: a human-sized body, standing on y = 0, Y up, rigid bones,
//! exact round trips, and no glitch but the one the data really has. The folder holds
//! non-commercial captures that are never committed; where it is absent these tests say so
//! and pass. The glitch-injection tests on the committed CMU walk always run.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use approx::assert_relative_eq;
use kinergy_motion::limbs::name_tokens;
use kinergy_motion::up::{up_by_names, up_by_shape};
use kinergy_motion::{
    Clip, ExportOptions, GlitchOptions, ImportOptions, PositionReading, RootReadingBasis, UpAxis,
    UpDetection, clip_from_bvh, clip_to_bvh, find_glitches, read_clip,
};
use nalgebra::Point3;
#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

fn shared_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Every `.bvh` one folder deep under the shared data folder, or `None` (with a notice)
/// where it is absent.
fn shared_files() -> Option<Vec<PathBuf>> {
    let dir = shared_dir();
    let Ok(folders) = std::fs::read_dir(&dir) else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the shared captures are never committed)",
            dir.display()
        ));
        return None;
    };
    let mut files = Vec::new();
    for folder in folders.flatten().map(|e| e.path()).filter(|p| p.is_dir()) {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        files.extend(
            entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh"))),
        );
    }
    files.sort();
    assert!(!files.is_empty(), "{} holds no BVH file", dir.display());
    Some(files)
}

fn name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn read(path: &Path) -> (Clip, kinergy_motion::ImportReport) {
    read_clip(path, &ImportOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// World positions of every joint in every frame, frame after frame.
fn world(clip: &Clip) -> Vec<Point3<f64>> {
    let all: Vec<usize> = (0..clip.skeleton().joint_count()).collect();
    clip.trajectory(&all)
        .expect("trajectory")
        .frames()
        .flatten()
        .copied()
        .collect()
}

/// Joints that are body points: not End Sites of zero length (they sit on their parent).
fn body_points(clip: &Clip) -> Vec<usize> {
    let s = clip.skeleton();
    (0..s.joint_count())
        .filter(|&j| !(s.joint(j).end_site && s.joint(j).offset.norm() == 0.0))
        .collect()
}

/// Feet by name (`foot`, `ankle`, `toe…`), their End Sites included.
fn feet(clip: &Clip) -> Vec<usize> {
    let s = clip.skeleton();
    let is_foot = |j: usize| {
        name_tokens(&s.joint(j).name)
            .iter()
            .any(|t| t == "foot" || t == "ankle" || t.starts_with("toe"))
    };
    (0..s.joint_count())
        .filter(|&j| is_foot(j) || s.joint(j).end_site && s.joint(j).parent.is_some_and(is_foot))
        .collect()
}

/// Files that do not stand on y = 0, and why.
const FLOATING: [(&str, &str); 1] = [(
    "006_14.bvh",
    "Character Creator's rig has no sole joint: its lowest joints (toe bases) are 7–10 cm \
     above y = 0 in every frame, with the root read as OFFSET + channels (replacing would \
     put them 96 cm below)",
)];

/// The lowest foot must be this near y = 0: the foot joints of the other files are 0–4.2 cm
/// above it in their first frame (the Z-up file's toes, 4.2 cm, the most; CMU's 2.1 cm).
const GROUND: f64 = 0.05;

/// The clip's world joint positions on frame 0, and its body's height there (lowest to
/// highest body point along Y).
fn first_frame(clip: &Clip) -> (Vec<Point3<f64>>, f64) {
    let p = clip
        .skeleton()
        .world_positions(clip.frame(0).expect("frame 0"))
        .expect("fk");
    let ys: Vec<f64> = body_points(clip).iter().map(|&j| p[j].y).collect();
    let height = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - ys.iter().copied().fold(f64::INFINITY, f64::min);
    (p, height)
}

#[test]
fn every_shared_file_stands_a_human_sized_body_on_the_ground_y_up() {
    let Some(files) = shared_files() else { return };
    for path in &files {
        let (clip, report) = read(path);
        let file = name(path);
        let (p, height) = first_frame(&clip);
        let feet = feet(&clip);
        assert!(!feet.is_empty(), "{file}: no foot joint");
        let lowest_foot = feet.iter().map(|&j| p[j].y).fold(f64::INFINITY, f64::min);
        eprintln!(
            "{file}: {} up ({}), root {:?}, unit {}, height {height:.3} m, lowest foot {lowest_foot:+.4} m",
            report.up,
            report.up_detection.name(),
            report.root.map(|r| (r.reading.name(), r.basis.name())),
            report.unit,
        );
        assert!(
            (1.2..=2.2).contains(&height),
            "{file}: first-frame height {height} m"
        );
        match FLOATING.iter().find(|(f, _)| *f == file) {
            Some((_, why)) => assert!(
                (GROUND..0.12).contains(&lowest_foot),
                "{file} ({why}): lowest foot {lowest_foot}"
            ),
            None if file == "74_07.bvh" || file == "74_08.bvh" => assert!(
                // CMU 74/07 and 74/08 start crouched, and the conversion's frame 0 is a T-pose
                // at the crouched hips' height: its feet are below the floor
                // (../shared/data/cmu-lift/README.md).
                (-0.5..-GROUND).contains(&lowest_foot),
                "{file} (a T-pose at crouched hips): lowest foot {lowest_foot} m"
            ),
            None => assert!(
                lowest_foot.abs() < GROUND,
                "{file}: lowest foot {lowest_foot} m"
            ),
        }
        // Every shared file is Y-up but one, detected by name, and the shape agrees.
        let expected = if file == "zup_mixed_orders.bvh" {
            UpAxis::Z
        } else {
            UpAxis::Y
        };
        assert_eq!(
            (report.up, report.up_detection),
            (expected, UpDetection::JointNames),
            "{file}"
        );
        let file_frame: Vec<Point3<f64>> = p
            .iter()
            .map(|q| clip.skeleton().world_from_file().inverse() * q)
            .collect();
        assert_eq!(up_by_names(clip.skeleton(), &file_frame), Some(expected));
        assert_eq!(up_by_shape(clip.skeleton(), &file_frame), Some(expected));
    }
}

#[test]
fn the_root_reading_of_every_shared_file_is_recorded_with_its_reason() {
    let Some(files) = shared_files() else { return };
    for path in &files {
        let (_, report) = read(path);
        let file = name(path);
        let root = report
            .root
            .expect("every shared root has position channels");
        // Character Creator's root needs OFFSET + channels; every other root has a zero
        // OFFSET along the up axis, so both readings agree and the tie reads add.
        let basis = if file == "006_14.bvh" {
            RootReadingBasis::NearerGround
        } else {
            RootReadingBasis::Tie
        };
        assert_eq!(
            (root.reading, root.basis),
            (PositionReading::AddToOffset, basis),
            "{file}: {root:?}"
        );
        // Non-root position channels (Bandai Namco's) replace their OFFSETs.
        assert!(
            report.position_readings[1..]
                .iter()
                .all(|(_, r)| *r == PositionReading::ReplaceOffset),
            "{file}"
        );
    }
}

#[test]
fn bones_of_every_shared_file_keep_their_length() {
    let Some(files) = shared_files() else { return };
    for path in &files {
        let (clip, _) = read(path);
        let file = name(path);
        let s = clip.skeleton();
        let n = s.joint_count();
        let p = world(&clip);
        // A joint whose position channels move it (Bandai Namco's Hips under the fixed
        // `joint_Root`) carries the body's translation: that link is no bone.
        let translating: Vec<bool> = (0..n)
            .map(|j| {
                let range = s.dof_range(j);
                s.joint(j).parent.is_some()
                    && range.clone().zip(&s.joint(j).dofs).any(|(d, dof)| {
                        matches!(dof, kinergy_motion::Dof::Translation(_))
                            && clip
                                .frames()
                                .any(|f| (f[d] - clip.values()[d]).abs() > 1e-3)
                    })
            })
            .collect();
        let mut checked = 0;
        for j in (1..n).filter(|&j| !translating[j]) {
            let parent = s.joint(j).parent.expect("not the root");
            let first = (p[j] - p[parent]).norm();
            for f in 1..clip.frame_count() {
                let len = (p[f * n + j] - p[f * n + parent]).norm();
                assert!(
                    (len - first).abs() < 1e-6,
                    "{file}: `{}` is {first} m from its parent in frame 0, {len} m in frame {f}",
                    s.joint(j).name
                );
            }
            checked += 1;
        }
        assert!(checked + 1 >= n - 1, "{file}: only {checked} bones checked");
    }
}

#[test]
fn every_shared_file_round_trips_its_world_positions() {
    let Some(files) = shared_files() else { return };
    for path in &files {
        let file = name(path);
        let bvh = kinergy_motion::kinergy_bvh::read_file(path, &Default::default()).expect("bvh");
        let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let written = clip_to_bvh(&clip, &ExportOptions::default());
        let text = kinergy_motion::kinergy_bvh::to_string(&written).expect("write");
        let again = kinergy_motion::kinergy_bvh::parse(&text).expect("parse");
        let (back, back_report) = clip_from_bvh(&again, &ImportOptions::default()).expect("clip");
        assert_eq!(back_report.up, report.up, "{file}");
        assert_eq!(back_report.root_reading(), report.root_reading(), "{file}");
        assert_eq!(back.frame_count(), clip.frame_count());
        for (a, b) in world(&clip).iter().zip(&world(&back)) {
            assert_relative_eq!(a, b, epsilon = 1e-12);
        }
        // Written Y up instead (the Z-up file turned, the others unchanged): read as Y-up,
        // the same world positions up to the re-expressed root angles.
        let y_up = ExportOptions {
            up: kinergy_motion::ExportUp::Y,
            ..Default::default()
        };
        let (back, back_report) =
            clip_from_bvh(&clip_to_bvh(&clip, &y_up), &ImportOptions::default()).expect("clip");
        assert_eq!(back_report.up, UpAxis::Y, "{file}");
        for (a, b) in world(&clip).iter().zip(&world(&back)) {
            assert_relative_eq!(a, b, epsilon = 1e-9);
        }
    }
}

#[test]
fn shared_files_have_no_glitch_but_the_character_creator_thumb() {
    let Some(files) = shared_files() else { return };
    for path in &files {
        let (clip, _) = read(path);
        let file = name(path);
        let found = find_glitches(&clip, &GlitchOptions::default()).expect("glitches");
        let named: Vec<(usize, &str)> = found
            .iter()
            .map(|g| (g.frame, clip.skeleton().joint(g.joint).name.as_str()))
            .collect();
        if file == "006_14.bvh" {
            // A real one: `CC_Base_L_Thumb1` turns from (−3.7°, 8.1°, 15.8°) to (7.7°,
            // 39.2°, −156.9°) for frame 76 alone, and back; its children jump 5.5–12.6 cm.
            assert_eq!(named, [(76, "CC_Base_L_Thumb2")], "{file}");
            assert!((0.12..0.13).contains(&found[0].largest), "{:?}", found[0]);
        } else if file == "74_07.bvh" {
            // A real one in CMU 74/07: the right toe jumps 11.9 cm for frame 45 alone.
            assert_eq!(named, [(45, "RightToeBase")], "{file}");
        } else {
            assert!(named.is_empty(), "{file}: {named:?}");
        }
    }
}

fn cmu_walk() -> Clip {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cmu_12_01_walk.bvh");
    read(&path).0
}

/// `clip` with `change` applied to frame `frame`'s pose.
fn edited(clip: &Clip, frame: usize, change: impl FnOnce(&mut [f64])) -> Clip {
    let n = clip.skeleton().dof_count();
    let mut values = clip.values().to_vec();
    change(&mut values[frame * n..(frame + 1) * n]);
    Clip::new(Arc::clone(clip.skeleton()), clip.frame_time(), values).expect("clip")
}

#[test]
fn a_22_cm_root_glitch_is_found_at_its_frame_and_drags_the_body() {
    let clip = cmu_walk();
    assert!(
        find_glitches(&clip, &GlitchOptions::default())
            .expect("glitches")
            .is_empty()
    );
    let s = clip.skeleton();
    // The root's Xposition, in meters in the file's (Y-up) frame.
    let bad = edited(&clip, 200, |pose| pose[0] += 0.22);
    let found = find_glitches(&bad, &GlitchOptions::default()).expect("glitches");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].frame, found[0].joint), (200, 0));
    assert_relative_eq!(found[0].size, 0.22, epsilon = 0.005);
    assert_eq!(found[0].joints, s.joint_count());
}

#[test]
fn a_22_cm_hand_glitch_is_found_at_the_hand_and_ignored_by_its_speed() {
    let clip = cmu_walk();
    let s = clip.skeleton();
    let elbow = s.require_joint("LeftForeArm").expect("elbow");
    let wrist = s.require_joint("LeftHand").expect("wrist");
    // Bend the elbow for frame 300 alone by the angle that moves the wrist 22 cm (its first
    // rotation channel is not quite square to the forearm: a few secant steps find it).
    let d = s.first_dof(elbow);
    let wrist_moved = |angle: f64| {
        let a = s
            .world_positions(clip.frame(300).expect("frame"))
            .expect("fk")[wrist];
        let mut pose = clip.frame(300).expect("frame").to_vec();
        pose[d] += angle;
        (s.world_positions(&pose).expect("fk")[wrist] - a).norm()
    };
    let (mut a0, mut a1) = (0.5, 1.0);
    for _ in 0..50 {
        let (m0, m1) = (wrist_moved(a0) - 0.22, wrist_moved(a1) - 0.22);
        if m1.abs() < 1e-12 || m1 == m0 {
            break;
        }
        (a0, a1) = (a1, a1 - m1 * (a1 - a0) / (m1 - m0));
    }
    let bad = edited(&clip, 300, |pose| pose[d] += a1);
    let moved = wrist_moved(a1);
    assert_relative_eq!(moved, 0.22, epsilon = 1e-9);
    let found = find_glitches(&bad, &GlitchOptions::default()).expect("glitches");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].frame, s.joint(found[0].joint).name.as_str()),
        (300, "LeftHand")
    );
    // The detour is measured from the neighbours' midpoint, within a few mm of the jump.
    assert_relative_eq!(found[0].size, 0.22, epsilon = 0.01);
    // The hand's speed without glitches is the clean clip's away from the glitch, and no
    // spike at it.
    let options = GlitchOptions::default();
    let clean = clip.trajectory(&[wrist]).expect("trajectory").speed(0);
    let raw = bad.trajectory(&[wrist]).expect("trajectory").speed(0);
    let repaired = bad
        .trajectory(&[wrist])
        .expect("trajectory")
        .speed_without_glitches(0, &options);
    let peak = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    assert!(
        peak(&raw) > 10.0,
        "the jump is a 13 m/s spike: {}",
        peak(&raw)
    );
    assert_relative_eq!(peak(&repaired), peak(&clean), max_relative = 0.05);
    for (f, (a, b)) in clean.iter().zip(&repaired).enumerate() {
        if !(299..=301).contains(&f) {
            assert_relative_eq!(a, b, epsilon = 1e-12);
        }
    }
}

#[test]
fn a_22_cm_glitch_in_a_bandai_hand_channel_is_found() {
    let path = shared_dir().join("bandai-raise-left/normal_001.bvh");
    if !path.exists() {
        eprintln!("skipping: {} is absent", path.display());
        return;
    }
    let (clip, _) = read(&path);
    let s = clip.skeleton();
    let hand = s.require_joint("Hand_L").expect("hand");
    // Bandai's non-root joints have position channels: teleport the hand 22 cm along its
    // parent's Z for frame 30.
    let z = s.first_dof(hand) + 2;
    let bad = edited(&clip, 30, |pose| pose[z] += 0.22);
    let found = find_glitches(&bad, &GlitchOptions::default()).expect("glitches");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].frame, found[0].joint), (30, hand));
    assert_relative_eq!(found[0].size, 0.22, epsilon = 0.01);
}

#[test]
fn a_glitch_does_not_make_the_next_frame_look_like_one() {
    // Character Creator's shot: with the body 22 cm off in frame 100, the thumb's own wobble
    // in frame 101, measured against the displaced frame 100, would pass for a glitch. Frames
    // are tested against their repaired predecessor.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/006_14.bvh");
    let (clip, _) = read(&path);
    let bad = edited(&clip, 100, |pose| pose[0] += 0.22);
    let s = bad.skeleton();
    let found: Vec<(usize, &str)> = find_glitches(&bad, &GlitchOptions::default())
        .expect("glitches")
        .iter()
        .map(|g| (g.frame, s.joint(g.joint).name.as_str()))
        .collect();
    assert_eq!(found, [(76, "CC_Base_L_Thumb2"), (100, "CC_Base_Hip")]);
}

// The rule CI relies on: with KINERGY_REQUIRE_SHARED set, a missing shared folder is a
// failure with a clear message; without it, a skip that says so. Tested on the decision
// itself, so the shared data need not be moved away.
#[test]
fn a_missing_shared_folder_fails_only_when_required() {
    let why = "skipping: ../shared/data is absent";
    assert_eq!(
        require_shared::absent_outcome(why, false),
        Ok(why.to_string())
    );
    let failure = require_shared::absent_outcome(why, true).expect_err("required");
    assert!(
        failure.starts_with(why) && failure.contains("KINERGY_REQUIRE_SHARED is set"),
        "{failure}"
    );
}

/// A take whose reference root stays at the origin while the performer starts 5.4 m away (the
/// Bandai library's walks and runs: `joint_Root` at 0, `Hips` at z = −543 cm) is read in
/// centimeters as a 1.2–2.0 m body: the unit guess measures the body, not the distance to the
/// reference joint (which reads as a 0.14 m body, in millimeters). Built from every shared
/// Bandai take, the hips' position channel moved 5.43 m away in every frame.
#[test]
fn a_reference_root_far_from_the_body_does_not_change_the_unit() {
    let dir = shared_dir().join("bandai-raise-left");
    if !dir.exists() {
        require_shared::shared_absent(&format!("skipping: {} is absent", dir.display()));
        return;
    }
    let mut takes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "bvh"))
        .collect();
    takes.sort();
    assert_eq!(takes.len(), 24);
    for path in &takes {
        let text = std::fs::read_to_string(path).expect("read");
        let mut bvh = kinergy_motion::kinergy_bvh::parse(&text).expect("parse");
        assert_eq!(
            (bvh.joints[0].name.as_deref(), bvh.joints[1].name.as_deref()),
            (Some("joint_Root"), Some("Hips"))
        );
        // The hips' channels: Xposition Yposition Zposition first.
        let z = bvh.joints[1].first_channel + 2;
        let channels = bvh.channel_count();
        for frame in 0..bvh.frame_count {
            bvh.motion[frame * channels + z] -= 543.0;
        }
        let (clip, report) =
            kinergy_motion::clip_from_bvh(&bvh, &ImportOptions::default()).expect("import");
        assert_eq!(
            report.unit,
            kinergy_motion::LengthUnit::Centimeter,
            "{path:?}"
        );
        assert_eq!(report.up, UpAxis::Y, "{path:?}");
        let (p, height) = first_frame(&clip);
        assert!(
            (1.2..=2.0).contains(&height),
            "{path:?}: a {height:.3} m body"
        );
        // The body is 5.4 m from the reference joint, as captured.
        let away = (p[1] - p[0]).norm();
        assert!(
            (5.0..6.0).contains(&away),
            "{path:?}: hips {away:.2} m from the root"
        );
    }
}
