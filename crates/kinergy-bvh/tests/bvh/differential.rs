//! The same files read by `bvh_anim` 0.4 (which stores `f32`): same joints, channels,
//! offsets and motion, to `f32` precision.

use approx::{assert_abs_diff_eq, assert_ulps_eq};
use kinergy_bvh::Bvh;

use crate::common::{read, real_files};

fn compare(path: &std::path::Path, ours: &Bvh, theirs: &bvh_anim::Bvh) {
    let file = path.display();
    let our_joints: Vec<usize> = (0..ours.joints.len())
        .filter(|&i| !ours.joints[i].end_site)
        .collect();
    let their_joints: Vec<bvh_anim::JointData> =
        theirs.joints().map(|j| j.data().clone()).collect();
    assert_eq!(our_joints.len(), their_joints.len(), "{file}");

    for (&index, theirs) in our_joints.iter().zip(&their_joints) {
        let joint = &ours.joints[index];
        let name = joint.display_name();
        assert_eq!(name.as_bytes(), theirs.name().as_ref() as &[u8], "{file}");
        let offset = theirs.offset();
        for (ours, theirs) in joint.offset.iter().zip([offset.x, offset.y, offset.z]) {
            assert_ulps_eq!(*ours as f32, theirs, max_ulps = 1);
        }
        let channels: Vec<&str> = theirs
            .channels()
            .iter()
            .map(|c| c.channel_type().as_str())
            .collect();
        let our_channels: Vec<&str> = joint.channels.iter().map(|c| c.name()).collect();
        assert_eq!(our_channels, channels, "{file}: {name}");
        for (k, channel) in theirs.channels().iter().enumerate() {
            assert_eq!(
                channel.motion_index(),
                joint.first_channel + k,
                "{file}: {name}"
            );
        }
        // bvh_anim keeps a joint's End Site as an optional offset on the joint.
        let end_site = ours.children(index).find(|&c| ours.joints[c].end_site);
        match (end_site, theirs.end_site()) {
            (Some(e), Some(offset)) => {
                for (ours, theirs) in ours.joints[e]
                    .offset
                    .iter()
                    .zip([offset.x, offset.y, offset.z])
                {
                    assert_ulps_eq!(*ours as f32, theirs, max_ulps = 1);
                }
            }
            (None, None) => {}
            other => panic!("{file}: {name}: End Sites differ: {other:?}"),
        }
    }

    assert_eq!(ours.frame_count, theirs.num_frames(), "{file}");
    assert_eq!(ours.channel_count(), theirs.num_channels(), "{file}");
    // bvh_anim keeps the frame time as a whole number of nanoseconds.
    assert_abs_diff_eq!(
        ours.frame_time,
        theirs.frame_time().as_secs_f64(),
        epsilon = 1e-9
    );
    let mut compared = 0;
    for (f, frame) in theirs.frames().enumerate() {
        let our_frame = ours.frame(f).unwrap();
        assert_eq!(our_frame.len(), frame.len());
        for (ours, theirs) in our_frame.iter().zip(frame.as_slice()) {
            assert_ulps_eq!(*ours as f32, *theirs, max_ulps = 1);
            compared += 1;
        }
    }
    assert_eq!(compared, ours.motion.len(), "{file}");
}

#[test]
fn agrees_with_bvh_anim_on_real_files() {
    for path in real_files() {
        let bytes = std::fs::read(&path).unwrap();
        let theirs =
            bvh_anim::from_bytes(&bytes[..]).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        compare(&path, &read(&path), &theirs);
    }
}
