//! Hand-written fixtures in `tests/data/bvh-quirks/`: every valid quirk parsed with its
//! contents asserted, every malformed file rejected with the expected kind and line.

use std::collections::BTreeSet;
use std::path::Path;

use kinergy_bvh::{Bvh, Channel, Error, FrameCountPolicy, ParseError, ParseErrorKind, ReadOptions};

use crate::common::{QUIRKS_DIR, quirk, read};

use Channel::{Xposition, Xrotation, Yposition, Yrotation, Zposition, Zrotation};

const LENIENT: ReadOptions = ReadOptions {
    max_file_bytes: kinergy_bvh::MAX_FILE_BYTES,
    frame_count: FrameCountPolicy::AcceptCompleteFrames,
    bounded_values: false,
};

fn valid(name: &str) -> Bvh {
    let bvh = read(&quirk(&format!("valid/{name}")));
    bvh.validate().unwrap();
    bvh
}

fn names(bvh: &Bvh) -> Vec<&str> {
    bvh.joints.iter().map(|j| j.display_name()).collect()
}

/// The document every variant of `BASE` (the template most fixtures derive from) reads as.
fn assert_base(bvh: &Bvh) {
    assert_eq!(names(bvh), ["Hips", "Spine", "End Site"]);
    assert_eq!(bvh.joints[0].parent, None);
    assert_eq!(bvh.joints[1].parent, Some(0));
    assert_eq!(bvh.joints[2].parent, Some(1));
    assert!(bvh.joints[2].end_site);
    assert_eq!(bvh.joints[1].offset, [0.0, 10.0, 0.0]);
    assert_eq!(bvh.joints[2].offset, [0.0, 5.0, 0.0]);
    assert_eq!(bvh.joints[1].channels, [Zrotation, Yrotation, Xrotation]);
    assert_eq!(bvh.joints[1].first_channel, 6);
    assert_eq!(bvh.joints[2].first_channel, 9);
    assert_eq!(bvh.channel_count(), 9);
    assert_eq!(bvh.frame_count, 2);
    assert_eq!(
        bvh.frame(0).unwrap(),
        [0.0, 90.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0]
    );
    assert_eq!(
        bvh.frame(1).unwrap(),
        [1.0, 91.0, 0.0, 0.0, 0.0, 0.0, 4.0, 5.0, 6.0]
    );
}

fn assert_base_file(name: &str, frame_time: f64) {
    let bvh = valid(name);
    assert_base(&bvh);
    assert_eq!(bvh.frame_time, frame_time, "{name}");
    assert_eq!(
        bvh.joints[0].channels,
        [
            Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation
        ],
        "{name}"
    );
}

#[test]
fn line_ending_and_whitespace_variants_read_the_same() {
    for name in [
        "crlf.bvh",
        "mixed_line_endings.bvh",
        "tabs_blank_lines_trailing_spaces.bvh",
        "no_final_newline.bvh",
        "lowercase_keywords.bvh",
        "colon_spacing.bvh",
        "wrapped_values.bvh",
        "bom.bvh",
    ] {
        assert_base_file(name, 0.0333333);
    }
    assert_base_file("frames_tab.bvh", 0.0083333);
}

#[test]
fn lines_are_recorded_whatever_the_line_endings() {
    for name in ["crlf.bvh", "mixed_line_endings.bvh", "bom.bvh"] {
        let bvh = valid(name);
        let lines: Vec<usize> = bvh.joints.iter().map(|j| j.line).collect();
        assert_eq!(lines, [2, 6, 10], "{name}");
    }
    let bvh = valid("tabs_blank_lines_trailing_spaces.bvh");
    let lines: Vec<usize> = bvh.joints.iter().map(|j| j.line).collect();
    assert_eq!(lines, [3, 8, 13]);
}

#[test]
fn crlf_and_mixed_fixtures_really_have_those_endings() {
    let crlf = std::fs::read(quirk("valid/crlf.bvh")).unwrap();
    assert!(crlf.windows(2).filter(|w| w == b"\r\n").count() >= 20);
    let mixed = std::fs::read_to_string(quirk("valid/mixed_line_endings.bvh")).unwrap();
    let lf_only = mixed.matches('\n').count() - mixed.matches("\r\n").count();
    assert!(lf_only > 0 && mixed.contains("\r\n"));
    let no_newline = std::fs::read(quirk("valid/no_final_newline.bvh")).unwrap();
    assert_ne!(no_newline.last(), Some(&b'\n'));
    assert!(
        std::fs::read(quirk("valid/bom.bvh"))
            .unwrap()
            .starts_with(b"\xEF\xBB\xBF")
    );
}

#[test]
fn root_with_rotation_channels_first() {
    let bvh = valid("root_rotation_first.bvh");
    assert_base(&bvh);
    assert_eq!(
        bvh.joints[0].channels,
        [
            Zrotation, Xrotation, Yrotation, Xposition, Yposition, Zposition
        ]
    );
}

#[test]
fn rotation_orders_differ_per_joint() {
    let bvh = valid("per_joint_orders.bvh");
    assert_eq!(
        names(&bvh),
        ["Hips", "Chest", "Neck", "End Site", "Leg", "End Site"]
    );
    let parents: Vec<Option<usize>> = bvh.joints.iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(2), Some(0), Some(4)]);
    assert_eq!(
        bvh.joints[0].channels,
        [
            Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation
        ]
    );
    assert_eq!(bvh.joints[1].channels, [Zrotation, Xrotation, Yrotation]);
    assert_eq!(bvh.joints[2].channels, [Yrotation, Zrotation, Xrotation]);
    assert_eq!(bvh.joints[4].channels, [Xrotation, Zrotation, Yrotation]);
    let firsts: Vec<usize> = bvh.joints.iter().map(|j| j.first_channel).collect();
    assert_eq!(firsts, [0, 6, 9, 12, 12, 15]);
    assert_eq!(bvh.joints[4].offset, [5.0, -3.0, 0.0]);
    assert_eq!(bvh.joints[5].offset, [0.0, -40.0, 0.0]);
    assert_eq!(bvh.frame_time, 0.04);
    assert_eq!(bvh.frame(1).unwrap()[14], 30.0);
    assert_eq!(bvh.children(0).collect::<Vec<_>>(), [1, 4]);
}

#[test]
fn non_root_joints_with_0_to_6_channels() {
    let bvh = valid("non_root_channel_counts.bvh");
    let channels: Vec<&[Channel]> = bvh.joints.iter().map(|j| j.channels.as_slice()).collect();
    assert_eq!(
        channels,
        [
            &[Zrotation, Xrotation, Yrotation][..],
            &[
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation
            ],
            &[Xposition, Yposition, Zposition],
            &[],
            &[Zrotation],
            &[Xrotation, Yposition],
            &[],
            &[],
        ]
    );
    let firsts: Vec<usize> = bvh.joints.iter().map(|j| j.first_channel).collect();
    assert_eq!(firsts, [0, 3, 9, 12, 12, 13, 15, 15]);
    assert_eq!(bvh.channel_count(), 15);
    let expected: Vec<f64> = (1..=15).map(f64::from).collect();
    assert_eq!(bvh.frame(0).unwrap(), expected);
    assert_eq!(bvh.frame_count, 1);
}

#[test]
fn leaves_without_end_sites_and_several_children() {
    let bvh = valid("no_end_site.bvh");
    assert_eq!(names(&bvh), ["Pelvis", "LeftHip", "RightHip", "Spine"]);
    assert_eq!(bvh.end_site_count(), 0);
    assert_eq!(bvh.children(0).collect::<Vec<_>>(), [1, 2, 3]);
    assert_eq!(bvh.joints[2].offset, [-10.0, 0.0, 0.0]);
    assert_eq!(
        bvh.frame(0).unwrap()[6..],
        [1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0]
    );
}

#[test]
fn metre_values_are_kept_as_written() {
    let bvh = valid("metres.bvh");
    assert_eq!(bvh.joints[0].offset, [0.0, 0.9512, 0.0]);
    assert_eq!(bvh.joints[1].offset, [0.0912, -0.0651, 0.0]);
    assert_eq!(bvh.joints[2].offset, [0.0, -0.4215, 0.0]);
    assert_eq!(bvh.frame(1).unwrap()[..3], [0.025, 0.9498, -0.0061]);
}

#[test]
fn number_forms() {
    let bvh = valid("number_forms.bvh");
    let root = &bvh.joints[0];
    assert_eq!(root.offset[0].to_bits(), (-0.0f64).to_bits());
    assert_eq!(root.offset[1..], [1.0, 0.5]);
    assert_eq!(bvh.joints[1].offset, [5.0, 100.0, 5.1072e-06]);
    assert_eq!(bvh.frame_time, 3.33333e-2);
    let first = bvh.frame(0).unwrap();
    assert_eq!(first[0].to_bits(), (-0.0f64).to_bits());
    assert_eq!(first[1..], [1.0, 0.5, 5.0, 100.0, 5.1072e-06]);
    let second = bvh.frame(1).unwrap();
    assert_eq!(
        second,
        [
            -1.25e-3,
            2.5e3,
            1e-21,
            1.2345678901234568e29,
            -5e-324,
            1e-300
        ]
    );
}

/// With `bounded_values` (what a reader of captures asks for), the same long mantissa,
/// and the sweep's root position of 1e300, are refused at their line naming the joint and
/// channel; an OFFSET too. Without it they are kept, as the format allows.
#[test]
fn bounded_values_refuse_what_no_capture_holds() {
    let bounded = ReadOptions {
        bounded_values: true,
        ..ReadOptions::default()
    };
    let text = std::fs::read_to_string(quirk("valid/number_forms.bvh")).unwrap();
    let e = kinergy_bvh::parse_with(&text, &bounded).unwrap_err();
    assert_eq!(e.line, 15, "{e}");
    let said = e.to_string();
    assert!(
        said.contains("`123456789012345678901234567890` (Hips Zrotation) is beyond ±1e9"),
        "{said}"
    );
    let far = text.replace("-0 +1 .5 5. 1E+2", "1e300 +1 .5 5. 1E+2");
    let e = kinergy_bvh::parse_with(&far, &bounded).unwrap_err();
    assert!(
        e.line == 14
            && matches!(&e.kind, ParseErrorKind::ValueTooLarge { what, .. } if &**what == "Hips Xposition"),
        "{e}"
    );
    let offset = text.replace("OFFSET 5. 1E+2", "OFFSET 5. -2e9");
    let e = kinergy_bvh::parse_with(&offset, &bounded).unwrap_err();
    assert!(
        e.line == 8
            && e.to_string()
                .contains("(an OFFSET component of the End Site of Hips)"),
        "{e}"
    );
    // Up to the bound, kept.
    let edge = text.replace("123456789012345678901234567890", "-1e9");
    assert_eq!(
        kinergy_bvh::parse_with(&edge, &bounded)
            .unwrap()
            .frame(1)
            .unwrap()[3],
        -1e9
    );
    assert!(kinergy_bvh::parse(&far).is_ok());
}

#[test]
fn zero_frames() {
    let bvh = valid("zero_frames.bvh");
    assert_eq!(bvh.frame_count, 0);
    assert!(bvh.motion.is_empty());
    assert_eq!(bvh.frame(0), None);
}

/// Every malformed fixture, the kind it must be rejected with, and the line (and, where
/// it is fixed by the fixture, the column).
fn malformed() -> Vec<(&'static str, ParseErrorKind, usize, Option<usize>)> {
    use ParseErrorKind as K;
    let s = String::from;
    vec![
        (
            "absurd_channel_count.bvh",
            K::BadChannelCount {
                found: s("1000000000000000000"),
            },
            9,
            Some(12),
        ),
        (
            "absurd_frame_count.bvh",
            K::TooManyFrames {
                declared: 1_000_000_000_000,
                max_possible: 2,
            },
            17,
            Some(9),
        ),
        (
            "bad_offset_number.bvh",
            K::Expected {
                expected: "a number after OFFSET",
                found: s("abc"),
            },
            8,
            Some(12),
        ),
        (
            "channel_count_mismatch.bvh",
            K::ChannelCountMismatch {
                declared: 3,
                listed: 2,
            },
            9,
            Some(3),
        ),
        (
            "duplicate_channel.bvh",
            K::DuplicateChannel(Xrotation),
            9,
            Some(34),
        ),
        (
            "empty.bvh",
            K::UnexpectedEof {
                expected: "HIERARCHY",
            },
            1,
            Some(1),
        ),
        (
            "end_site_with_channels.bvh",
            K::EndSiteChannels,
            13,
            Some(4),
        ),
        (
            "end_site_with_children.bvh",
            K::EndSiteChildren,
            13,
            Some(4),
        ),
        (
            "extra_closing_brace.bvh",
            K::UnbalancedBraces { unclosed: 0 },
            16,
            Some(1),
        ),
        (
            "frame_count_above_data.bvh",
            K::FrameCountMismatch {
                declared: 3,
                found: 2,
            },
            17,
            Some(9),
        ),
        (
            "frame_count_below_data.bvh",
            K::FrameCountMismatch {
                declared: 1,
                found: 2,
            },
            17,
            Some(9),
        ),
        (
            "frame_time_nan.bvh",
            K::BadFrameTime { found: s("NaN") },
            18,
            Some(13),
        ),
        (
            "frame_time_negative.bvh",
            K::BadFrameTime {
                found: s("-0.0333333"),
            },
            18,
            Some(13),
        ),
        (
            "frame_time_zero.bvh",
            K::BadFrameTime { found: s("0") },
            18,
            Some(13),
        ),
        (
            "inf_offset.bvh",
            K::NonFinite { value: s("inf") },
            8,
            Some(12),
        ),
        (
            "letter_in_motion.bvh",
            K::Expected {
                expected: "a number (motion value)",
                found: s("O"),
            },
            20,
            Some(10),
        ),
        (
            "missing_closing_brace.bvh",
            K::UnbalancedBraces { unclosed: 1 },
            16,
            Some(1),
        ),
        (
            "missing_joint_name.bvh",
            K::MissingName { keyword: "JOINT" },
            6,
            Some(2),
        ),
        (
            "missing_offset.bvh",
            K::MissingOffset {
                joint: s("End Site"),
            },
            13,
            Some(3),
        ),
        (
            "missing_root_name.bvh",
            K::MissingName { keyword: "ROOT" },
            2,
            Some(1),
        ),
        (
            "nan_value.bvh",
            K::NonFinite { value: s("nan") },
            20,
            Some(8),
        ),
        (
            "negative_frame_count.bvh",
            K::BadFrameCount { found: s("-2") },
            17,
            Some(9),
        ),
        (
            "no_motion.bvh",
            K::UnexpectedEof { expected: "MOTION" },
            16,
            Some(1),
        ),
        ("not_utf8.bvh", K::InvalidUtf8, 6, Some(10)),
        (
            "overflowing_value.bvh",
            K::NonFinite { value: s("1e999") },
            19,
            Some(10),
        ),
        (
            "partial_frame.bvh",
            K::PartialFrame {
                values: 8,
                channels: 9,
            },
            20,
            Some(16),
        ),
        (
            "repeated_offset.bvh",
            K::Repeated { keyword: "OFFSET" },
            9,
            Some(3),
        ),
        ("second_hierarchy.bvh", K::DuplicateHierarchy, 21, Some(1)),
        ("second_root.bvh", K::MultipleRoots, 16, Some(1)),
        (
            "text_before_hierarchy.bvh",
            K::Expected {
                expected: "HIERARCHY",
                found: s("#"),
            },
            1,
            Some(1),
        ),
        (
            "trailing_garbage.bvh",
            K::TrailingGarbage { found: s("END") },
            21,
            Some(1),
        ),
        (
            "unknown_channel.bvh",
            K::UnknownChannel(s("Wrotation")),
            9,
            Some(24),
        ),
    ]
}

fn parse_error(path: &Path, options: &ReadOptions) -> ParseError {
    match kinergy_bvh::read_file(path, options) {
        Err(Error::Parse { path: p, source }) => {
            assert_eq!(p, path);
            source
        }
        other => panic!("{}: expected a parse error, got {other:?}", path.display()),
    }
}

#[test]
fn malformed_fixtures_are_rejected_with_kind_and_line() {
    for (name, kind, line, column) in malformed() {
        let path = quirk(&format!("invalid/{name}"));
        let error = parse_error(&path, &ReadOptions::default());
        assert_eq!(error.kind, kind, "{name}");
        assert_eq!(error.line, line, "{name}: {error}");
        if let Some(column) = column {
            assert_eq!(error.column, column, "{name}: {error}");
        }
    }
}

#[test]
fn every_malformed_fixture_is_in_the_table() {
    let on_disk: BTreeSet<String> = std::fs::read_dir(Path::new(QUIRKS_DIR).join("invalid"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    let listed: BTreeSet<String> = malformed()
        .into_iter()
        .map(|(n, ..)| n.to_owned())
        .collect();
    assert_eq!(on_disk, listed);
}

#[test]
fn every_valid_fixture_parses_and_is_tested() {
    let on_disk: BTreeSet<String> = std::fs::read_dir(Path::new(QUIRKS_DIR).join("valid"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    let source = include_str!("quirks.rs");
    for name in &on_disk {
        valid(name);
        assert!(
            source.contains(&format!("\"{name}\"")),
            "{name} has no test"
        );
    }
}

#[test]
fn lenient_mode_keeps_the_complete_frames_present() {
    for (name, declared) in [
        ("frame_count_above_data.bvh", 3u64),
        ("frame_count_below_data.bvh", 1),
        ("absurd_frame_count.bvh", 1_000_000_000_000),
    ] {
        let text = std::fs::read_to_string(quirk(&format!("invalid/{name}"))).unwrap();
        assert!(text.contains(&format!("Frames: {declared}")));
        let bvh = kinergy_bvh::parse_with(&text, &LENIENT).unwrap();
        assert_eq!(bvh.frame_count, 2, "{name}");
        assert_eq!(bvh.motion.len(), 18);
        assert_eq!(bvh.frame(1).unwrap()[1], 91.0);
    }
}

#[test]
fn lenient_mode_still_rejects_a_partial_frame_and_garbage() {
    for name in ["partial_frame.bvh", "trailing_garbage.bvh", "nan_value.bvh"] {
        let strict = parse_error(&quirk(&format!("invalid/{name}")), &ReadOptions::default());
        let lenient = parse_error(&quirk(&format!("invalid/{name}")), &LENIENT);
        assert_eq!(strict, lenient, "{name}");
    }
}

#[test]
fn error_messages_name_file_line_and_column() {
    let path = quirk("invalid/bad_offset_number.bvh");
    let message = kinergy_bvh::read_file(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        format!(
            "{}: line 8, column 12: expected a number after OFFSET, found `abc`",
            path.display()
        )
    );
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let path = quirk("valid/does_not_exist.bvh");
    match kinergy_bvh::read_file(&path, &ReadOptions::default()) {
        Err(e @ Error::Io { .. }) => {
            assert!(e.to_string().starts_with(&path.display().to_string()))
        }
        other => panic!("{other:?}"),
    }
}
