//! A synthetic set's both-hands takes (`kinergy synth --both-hands`): the right hand reaches
//! and returns, then the left reaches toward the mirrored target — two reaches in one take, each
//! where the manifest says, and `--arm auto` reads one reach per arm from it, as it does from a
//! library's both-hands raises.

use std::path::Path;

use kinergy_motion::Side;
use kinergy_motion::segment::Selection;
use kinergy_reach::drive::Driver;
use kinergy_reach::synth::{SynthSet, SynthSettings, is_both_hands};
use kinergy_solver::BaseMode;
use kinergy_train::source::Capture;

#[test]
fn the_share_of_both_hands_takes_is_spread_evenly() {
    let takes = |share: f64| {
        (0..10)
            .filter(|&r| is_both_hands(r, share))
            .collect::<Vec<_>>()
    };
    assert!(takes(0.0).is_empty());
    assert_eq!(takes(1.0), (0..10).collect::<Vec<_>>());
    assert_eq!(takes(0.5), [1, 3, 5, 7, 9]);
    assert_eq!(takes(0.3).len(), 3);
}

#[test]
fn a_both_hands_take_holds_each_reach_where_its_manifest_rows_say() {
    let settings = SynthSettings {
        persons: 1,
        reaches: 3,
        frame_rate: 30.0,
        both_hands: 0.5,
        ..SynthSettings::default()
    };
    let set = SynthSet::make(&settings, Driver::Profile).expect("set");
    let counts: Vec<usize> = set.clips.iter().map(|c| c.reaches.len()).collect();
    assert_eq!(counts, [1, 2, 1], "take 2 of 3 reaches with both hands");
    let take = &set.clips[1];
    let [right, left] = &take.reaches[..] else {
        unreachable!()
    };
    assert_eq!((right.row.arm, left.row.arm), (Side::Right, Side::Left));
    assert_eq!(
        (right.row.clip.as_str(), left.row.clip.as_str()),
        ("p01/r02.bvh", "p01/r02.bvh")
    );
    // The right hand goes and comes back; the left starts where the take began.
    assert_eq!(right.row.first_frame, 0);
    assert_eq!(left.row.first_frame, 2 * (right.row.frames - 1));
    assert_eq!(
        take.clip.frame_count(),
        left.row.first_frame + left.row.frames
    );
    let s = take.clip.skeleton();
    let world: Vec<_> = take
        .clip
        .frames()
        .map(|f| s.world_positions(f).expect("fk"))
        .collect();
    assert_eq!(
        world[0], world[left.row.first_frame],
        "at rest between the reaches"
    );
    let tip = |hand: &str| {
        s.children(s.joint_index(hand).expect("hand"))
            .next()
            .expect("the hand's end site")
    };
    for (reach, hand) in [(right, "RightHand"), (left, "LeftHand")] {
        let target = kinergy_motion::nalgebra::Point3::new(
            reach.row.target_x,
            reach.row.target_y,
            reach.row.target_z,
        );
        let end = reach.row.first_frame + reach.row.frames - 1;
        let off = (world[end][tip(hand)] - target).norm();
        assert!(off < 0.01, "{hand} ends {off:.4} m from its target");
        assert!(reach.driven.start >= reach.row.first_frame && reach.driven.end <= end + 1);
    }
    // Mirrored across the body (x is the character's left).
    assert!(right.row.target_x < 0.0 && left.row.target_x > 0.0);

    // `--arm auto`: one reach per arm, right first, each within its manifest frames.
    let capture = Capture::from_clip(Path::new("p01/r02.bvh"), take.clip.clone());
    let reaches = capture
        .reaches_of_reaching_arms(Selection::Main, BaseMode::Replay)
        .expect("both arms reach");
    assert_eq!(reaches.len(), 2);
    for (found, reach) in reaches.iter().zip([right, left]) {
        assert_eq!(found.fitted_arm().side, Some(reach.row.arm));
        let rows = reach.row.first_frame..reach.row.first_frame + reach.row.frames;
        let frames = found.frames();
        assert!(
            rows.contains(&frames.start) && frames.end <= rows.end,
            "{:?} reach {frames:?} outside its rows' {rows:?}",
            reach.row.arm
        );
    }
}
