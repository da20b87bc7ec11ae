//! A pick-up's reach ends at the object (issue 43, item 8): on the CMU bend-and-lift takes
//! (`../shared/data/cmu-lift`), each arm's main reach ends within 3 frames of where the hand
//! stops lowest. The truth is read from the hand's world path alone, not from the
//! segmentation: the hand has stopped lowest on the first frame it is within 1 cm of its
//! lowest height and slower than 10 cm/s (central differences, unsmoothed) — a grasping hand
//! does not rest still: it creeps there by millimetres, then lifts. 74_07 and 74_08 start
//! crouched at the object and only lift (their README says so): they have no way down, and
//! their main reach is the lift.

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::path::{Path, PathBuf};

use kinergy_motion::segment::{SegmentSettings, find_segments, main_index};
use kinergy_motion::{ArmJoints, ImportOptions, Side, read_clip};

/// How far the main reach's last frame may be from where the hand stops lowest, frames.
const TOLERANCE: usize = 3;
/// The band above its lowest height where the hand's descent has stopped, meters.
const BOTTOM: f64 = 0.01;
/// A hand slower than this has stopped, m/s.
const STOPPED: f64 = 0.1;
/// The takes that start crouched at the object (`cmu-lift/README.md`).
const CROUCHED: [&str; 2] = ["74_07.bvh", "74_08.bvh"];

fn takes() -> Option<Vec<PathBuf>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/cmu-lift");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the shared captures are never committed)",
            dir.display()
        ));
        return None;
    };
    let mut files: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    assert_eq!(files.len(), 4, "{files:?}");
    Some(files)
}

#[test]
fn a_pick_up_s_main_reach_ends_where_the_hand_stops_lowest() {
    let Some(files) = takes() else { return };
    let settings = SegmentSettings::default();
    let mut wrong = Vec::new();
    let mut reached_down = 0;
    for path in &files {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let (clip, _) = read_clip(path, &ImportOptions::default()).expect("take");
        for side in [Side::Right, Side::Left] {
            let arm = ArmJoints::find(clip.skeleton(), side).expect("arm");
            let t = clip
                .trajectory(&[arm.end_effector(), arm.shoulder, arm.elbow, arm.wrist])
                .expect("trajectory");
            // Frame 0 of a CMU conversion is a synthetic T-pose: the take starts on frame 1.
            let hand = &t.path(0)[1..];
            let mut lengths: Vec<f64> = t
                .frames()
                .map(|f| (f[1] - f[2]).norm() + (f[2] - f[3]).norm() + (f[3] - f[0]).norm())
                .collect();
            lengths.sort_by(f64::total_cmp);
            let reach = settings.min_reach * lengths[lengths.len() / 2];
            let lowest = hand.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
            let speed = |i: usize| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(hand.len() - 1));
                (hand[b] - hand[a]).norm() / ((b - a) as f64 * clip.frame_time())
            };
            let bottom = (0..hand.len())
                .find(|&i| hand[i].y <= lowest + BOTTOM && speed(i) < STOPPED)
                .map(|i| i + 1);
            let found = find_segments(&clip, &arm, &settings).expect("segments");
            let Some(main) = main_index(&found).map(|i| found[i]) else {
                wrong.push(format!("{name} {side}: no main reach ({found:?})"));
                continue;
            };
            let last = main.end - 1;
            eprintln!(
                "{name} {side}: from {:.3} m down to {lowest:.3} m, stopped there on frame \
                 {bottom:?}; main {}..{}",
                hand[0].y, main.onset, main.end
            );
            if CROUCHED.contains(&name.as_ref()) {
                // No way down: the main reach is the lift, a reach's length up.
                let all = t.path(0);
                if all[last].y - all[main.onset.max(1)].y < reach {
                    wrong.push(format!(
                        "{name} {side}: starts at the object, yet the main reach {}..{} is no \
                         lift",
                        main.onset, main.end
                    ));
                }
                continue;
            }
            reached_down += 1;
            let Some(bottom) = bottom else {
                wrong.push(format!("{name} {side}: the hand never stops at its lowest"));
                continue;
            };
            if main.truncated() || last.abs_diff(bottom) > TOLERANCE {
                wrong.push(format!(
                    "{name} {side}: main reach {}..{} (last frame {last}), the hand stops \
                     lowest on frame {bottom}",
                    main.onset, main.end
                ));
            }
        }
    }
    // Both hands of both bend-and-lift takes go down to the object.
    assert_eq!(reached_down, 4, "{}", wrong.join("\n"));
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
