//! read → write → read is exact: on every real file, every valid quirk, and random
//! documents.

use kinergy_bvh::{Bvh, Channel, Joint, MAX_DEPTH};
use proptest::prelude::*;

use crate::common::{QUIRKS_DIR, read, real_files};

/// Writes, re-reads and compares; also checks that writing is idempotent.
pub fn assert_round_trip(bvh: &Bvh) {
    let text = kinergy_bvh::to_string(bvh).unwrap();
    let again = kinergy_bvh::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert!(
        again.same_content(bvh),
        "round trip changed the document:\n{text}"
    );
    assert_eq!(kinergy_bvh::to_string(&again).unwrap(), text);
}

#[test]
fn real_files_round_trip_exactly() {
    for path in real_files() {
        let bvh = read(&path);
        assert_round_trip(&bvh);
    }
}

#[test]
fn valid_quirks_round_trip_exactly() {
    for entry in std::fs::read_dir(std::path::Path::new(QUIRKS_DIR).join("valid")).unwrap() {
        assert_round_trip(&read(&entry.unwrap().path()));
    }
}

#[test]
fn the_writer_uses_the_standard_layout() {
    let bvh = read(&std::path::Path::new(QUIRKS_DIR).join("valid/no_end_site.bvh"));
    let text = kinergy_bvh::to_string(&bvh).unwrap();
    assert!(text.starts_with(
        "HIERARCHY\nROOT Pelvis\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT LeftHip\n\t{\n\t\tOFFSET 10 0 0\n"
    ));
    assert!(
        text.ends_with(
            "}\nMOTION\nFrames: 1\nFrame Time: 0.0333333\n0 0 0 0 0 0 1 1 1 2 2 2 3 3 3\n"
        )
    );
    assert!(!text.contains('\r'));
    let mut streamed = Vec::new();
    kinergy_bvh::write(&bvh, &mut streamed).unwrap();
    assert_eq!(streamed, text.as_bytes());
}

#[test]
fn deepest_accepted_nesting_round_trips_without_recursion() {
    let joints = (0..MAX_DEPTH)
        .map(|i| Joint {
            name: Some(format!("j{i}")),
            parent: i.checked_sub(1),
            offset: [0.0, 1.0, 0.0],
            channels: vec![Channel::Zrotation],
            first_channel: i,
            end_site: false,
            line: 0,
        })
        .collect();
    let bvh = Bvh {
        joints,
        frame_time: 0.01,
        frame_count: 1,
        motion: vec![0.5; MAX_DEPTH],
    };
    assert_round_trip(&bvh);
}

#[test]
fn the_writer_refuses_invalid_documents() {
    let mut bvh = read(&std::path::Path::new(QUIRKS_DIR).join("valid/crlf.bvh"));
    bvh.motion[3] = f64::NAN;
    assert!(matches!(
        kinergy_bvh::to_string(&bvh),
        Err(kinergy_bvh::WriteError::NonFiniteMotion {
            frame: 0,
            channel: 3
        })
    ));
    let mut out = Vec::new();
    assert!(matches!(
        kinergy_bvh::write(&bvh, &mut out),
        Err(kinergy_bvh::Error::Invalid { .. })
    ));
    assert!(out.is_empty());
}

/// Finite values of every kind: tiny, huge, subnormal, signed zeros, ordinary.
fn finite_f64() -> impl Strategy<Value = f64> {
    use proptest::num::f64 as f;
    prop_oneof![
        3 => -1000.0..1000.0f64,
        1 => f::NORMAL | f::SUBNORMAL | f::ZERO | f::POSITIVE | f::NEGATIVE,
        1 => prop::sample::select(vec![0.0, -0.0, 5e-324, -5e-324, f64::MAX, f64::MIN, f64::MIN_POSITIVE, 1e-5, 1e16, 0.1, 1.0 / 3.0]),
        1 => (-99_999i32..99_999, -30i32..30).prop_map(|(m, e)| f64::from(m) * 10f64.powi(e)),
    ]
}

fn positive_frame_time() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => prop::sample::select(vec![0.0083333, 0.016667, 0.0333333, 1.0 / 120.0, 0.04]),
        1 => prop::sample::select(vec![kinergy_bvh::MIN_FRAME_TIME, kinergy_bvh::MAX_FRAME_TIME]),
        1 => kinergy_bvh::MIN_FRAME_TIME..=kinergy_bvh::MAX_FRAME_TIME,
    ]
}

/// One joint's random choices; the document is built from a list of these.
#[derive(Debug, Clone)]
struct JointSeed {
    /// Which open ancestor becomes the parent.
    parent_pick: usize,
    end_site: bool,
    /// A permutation seed and a count for the channels.
    channel_order: u64,
    channel_count: usize,
    offset: [f64; 3],
    name: String,
}

fn joint_seed() -> impl Strategy<Value = JointSeed> {
    (
        any::<usize>(),
        prop::bool::weighted(0.25),
        any::<u64>(),
        0usize..=6,
        [finite_f64(), finite_f64(), finite_f64()],
        "[A-Za-z_][A-Za-z0-9_:.\\-é]{0,12}",
    )
        .prop_map(
            |(parent_pick, end_site, channel_order, channel_count, offset, name)| JointSeed {
                parent_pick,
                end_site,
                channel_order,
                channel_count,
                offset,
                name,
            },
        )
}

/// Builds a valid document: depth-first joints, distinct channels in a random order.
fn build(seeds: &[JointSeed], frame_count: usize, frame_time: f64, values: &[f64]) -> Bvh {
    let mut joints: Vec<Joint> = Vec::new();
    let mut path: Vec<usize> = Vec::new(); // open ancestors that may take children
    let mut channel_total = 0;
    for (index, seed) in seeds.iter().enumerate() {
        let parent = if index == 0 {
            None
        } else {
            if path.is_empty() {
                break;
            }
            let keep = 1 + seed.parent_pick % path.len();
            path.truncate(keep);
            path.last().copied()
        };
        let end_site = index > 0 && seed.end_site;
        let channels = if end_site {
            Vec::new()
        } else {
            let mut all = Channel::ALL.to_vec();
            let mut state = seed.channel_order;
            for i in (1..all.len()).rev() {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                all.swap(i, (state >> 33) as usize % (i + 1));
            }
            all.truncate(seed.channel_count);
            all
        };
        joints.push(Joint {
            name: (!end_site).then(|| seed.name.clone()),
            parent,
            offset: seed.offset,
            first_channel: channel_total,
            end_site,
            line: 0,
            channels,
        });
        channel_total += joints[index].channels.len();
        if !end_site {
            path.push(index);
        }
    }
    let motion = (0..frame_count * channel_total)
        .map(|i| values[i % values.len()])
        .collect();
    Bvh {
        joints,
        frame_time,
        frame_count,
        motion,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_documents_round_trip_exactly(
        seeds in prop::collection::vec(joint_seed(), 1..40),
        frame_count in 0usize..5,
        frame_time in positive_frame_time(),
        values in prop::collection::vec(finite_f64(), 1..64),
    ) {
        let bvh = build(&seeds, frame_count, frame_time, &values);
        prop_assert_eq!(bvh.validate(), Ok(()));
        assert_round_trip(&bvh);
    }
}
