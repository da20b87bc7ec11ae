//! The reader never panics, never allocates from a header count more than the file could
//! hold, and never recurses. Whatever it accepts, it can write back exactly.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use kinergy_bvh::{FrameCountPolicy, ParseErrorKind, ReadOptions};
use proptest::prelude::*;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

use crate::common::{QUIRKS_DIR, real_files, trimmed};

const LENIENT: ReadOptions = ReadOptions {
    max_file_bytes: kinergy_bvh::MAX_FILE_BYTES,
    frame_count: FrameCountPolicy::AcceptCompleteFrames,
    bounded_values: false,
};

/// Parses `bytes` in both modes. Anything accepted must validate and round-trip exactly.
fn check(bytes: &[u8]) -> bool {
    let mut accepted = false;
    for options in [ReadOptions::default(), LENIENT] {
        if let Ok(bvh) = kinergy_bvh::parse_bytes(bytes, &options) {
            accepted = true;
            if let Err(e) = bvh.validate() {
                panic!(
                    "accepted but invalid ({e}):\n{}",
                    String::from_utf8_lossy(bytes)
                );
            }
            let text = kinergy_bvh::to_string(&bvh).unwrap();
            let again = kinergy_bvh::parse(&text).unwrap();
            assert!(
                again.same_content(&bvh),
                "{}",
                String::from_utf8_lossy(bytes)
            );
        }
    }
    accepted
}

const INSERTS: &[&[u8]] = &[
    b"{",
    b"}",
    b" ",
    b"\n",
    b"\r\n",
    b"\t",
    b"-",
    b".",
    b"e",
    b"E+",
    b"0",
    b"9",
    b":",
    b"nan",
    b"inf",
    b"1e999",
    b"99999999999999999999",
    b"HIERARCHY",
    b"ROOT x",
    b"JOINT j",
    b"End Site",
    b"OFFSET 0 0 0",
    b"CHANNELS 3 Xrotation Yrotation Zrotation",
    b"CHANNELS 7",
    b"MOTION",
    b"Frames: 1000000000000",
    b"Frame Time: 0",
    b"\xff",
    b"\xef\xbb\xbf",
    b"\xc3",
];

fn lines(bytes: &[u8]) -> Vec<&[u8]> {
    bytes.split_inclusive(|&b| b == b'\n').collect()
}

/// One random mutation of the kinds a damaged or hand-edited file shows.
fn mutate(rng: &mut ChaCha8Rng, bytes: &mut Vec<u8>) {
    let len = bytes.len();
    match rng.random_range(0..9) {
        0 => bytes.truncate(rng.random_range(0..=len)),
        1 if len > 0 => {
            let at = rng.random_range(0..len);
            bytes[at] ^= rng.random_range(1..=255u8);
        }
        2 => {
            let at = rng.random_range(0..=len);
            let insert: Vec<u8> = if rng.random_bool(0.5) {
                INSERTS[rng.random_range(0..INSERTS.len())].to_vec()
            } else {
                (0..rng.random_range(1..4))
                    .map(|_| rng.random::<u8>())
                    .collect()
            };
            bytes.splice(at..at, insert);
        }
        3..=5 => {
            let mut ls: Vec<Vec<u8>> = lines(bytes).into_iter().map(<[u8]>::to_vec).collect();
            if ls.is_empty() {
                return;
            }
            let a = rng.random_range(0..ls.len());
            let b = rng.random_range(0..ls.len());
            match rng.random_range(0..3) {
                0 => {
                    ls.remove(a);
                }
                1 => {
                    let line = ls[a].clone();
                    ls.insert(b, line);
                }
                _ => ls.swap(a, b),
            }
            *bytes = ls.concat();
        }
        6 | 7 => {
            // A digit becomes a letter (or a sign or point), as in a corrupted number.
            let digits: Vec<usize> = (0..len).filter(|&i| bytes[i].is_ascii_digit()).collect();
            if let Some(&at) = digits.get(rng.random_range(0..digits.len().max(1))) {
                bytes[at] = b"aeEfinxO-+."[rng.random_range(0..11)];
            }
        }
        _ => {
            // A token replaced by another one: keywords, extremes, garbage.
            let starts: Vec<usize> = (0..len)
                .filter(|&i| {
                    !bytes[i].is_ascii_whitespace()
                        && (i == 0 || bytes[i - 1].is_ascii_whitespace())
                })
                .collect();
            if let Some(&at) = starts.get(rng.random_range(0..starts.len().max(1))) {
                let end = (at..len)
                    .find(|&i| bytes[i].is_ascii_whitespace())
                    .unwrap_or(len);
                let with = INSERTS[rng.random_range(0..INSERTS.len())];
                bytes.splice(at..end, with.iter().copied());
            }
        }
    }
}

fn seeds() -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = real_files()
        .iter()
        .map(|p| trimmed(&std::fs::read_to_string(p).unwrap(), 3).into_bytes())
        .collect();
    let mut quirks: Vec<_> = std::fs::read_dir(std::path::Path::new(QUIRKS_DIR).join("valid"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    quirks.sort();
    seeds.extend(quirks.iter().map(|p| std::fs::read(p).unwrap()));
    seeds
}

#[test]
fn trimmed_real_files_are_valid_seeds() {
    for path in real_files() {
        let text = trimmed(&std::fs::read_to_string(&path).unwrap(), 3);
        let bvh = kinergy_bvh::parse(&text).unwrap();
        assert_eq!(bvh.frame_count, 3);
        assert!(text.len() < 60_000, "{}: {}", path.display(), text.len());
    }
}

#[test]
fn a_hundred_thousand_mutated_real_files_never_panic() {
    const CASES: usize = 100_000;
    let seeds = seeds();
    let mut rng = ChaCha8Rng::seed_from_u64(0x006b_696e_6572_6779);
    let start = Instant::now();
    let mut accepted = 0;
    let mut kinds: BTreeMap<String, usize> = BTreeMap::new();
    for case in 0..CASES {
        let mut bytes = seeds[case % seeds.len()].clone();
        for _ in 0..rng.random_range(1..=3) {
            mutate(&mut rng, &mut bytes);
        }
        if check(&bytes) {
            accepted += 1;
        }
        if let Err(e) = kinergy_bvh::parse_bytes(&bytes, &ReadOptions::default()) {
            let kind = format!("{:?}", e.kind);
            let name = kind
                .split([' ', '(', '{'])
                .next()
                .unwrap_or_default()
                .to_owned();
            *kinds.entry(name).or_default() += 1;
        }
    }
    eprintln!(
        "{CASES} mutated inputs in {:?}, {accepted} accepted; errors: {kinds:?}",
        start.elapsed()
    );
    // Some mutations are harmless (a swapped motion line, a changed value): both branches run,
    // and the errors reach most of the grammar.
    assert!(
        accepted > CASES / 200 && accepted < CASES * 9 / 10,
        "accepted {accepted}"
    );
    assert!(
        kinds.len() >= 20,
        "only {} error kinds reached: {kinds:?}",
        kinds.len()
    );
}

#[test]
fn mutated_whole_real_files_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for path in real_files() {
        let original = std::fs::read(&path).unwrap();
        for _ in 0..20 {
            let mut bytes = original.clone();
            mutate(&mut rng, &mut bytes);
            check(&bytes);
        }
        // Every truncation point class: inside the hierarchy, the header, the motion.
        for cut in (0..original.len()).step_by(original.len() / 50 + 1) {
            check(&original[..cut]);
        }
    }
}

#[test]
fn absurd_frame_counts_fail_fast_without_allocating() {
    let base =
        std::fs::read_to_string(std::path::Path::new(QUIRKS_DIR).join("valid/crlf.bvh")).unwrap();
    for declared in [
        "1000000000000",
        "1000000000000000000",
        &usize::MAX.to_string(),
    ] {
        let text = base.replace("Frames: 2", &format!("Frames: {declared}"));
        let start = Instant::now();
        let error = kinergy_bvh::parse(&text).unwrap_err();
        assert!(start.elapsed() < Duration::from_secs(1));
        assert!(
            matches!(
                error.kind,
                ParseErrorKind::TooManyFrames {
                    max_possible: 2,
                    ..
                }
            ),
            "{error}"
        );
        assert_eq!(error.line, 17);
        // Lenient mode keeps what is there, with a buffer sized by the file, not the header.
        let bvh = kinergy_bvh::parse_with(&text, &LENIENT).unwrap();
        assert_eq!(bvh.frame_count, 2);
        assert!(bvh.motion.capacity() <= text.len());
    }
    let text = base.replace("Frames: 2", "Frames: 99999999999999999999999");
    assert!(matches!(
        kinergy_bvh::parse(&text).unwrap_err().kind,
        ParseErrorKind::BadFrameCount { .. }
    ));
}

#[test]
fn absurd_channel_counts_fail_fast() {
    let base =
        std::fs::read_to_string(std::path::Path::new(QUIRKS_DIR).join("valid/crlf.bvh")).unwrap();
    for count in [
        "1000000000000000000",
        "7",
        "-3",
        "18446744073709551616",
        "3.0",
    ] {
        let text = base.replacen("CHANNELS 6", &format!("CHANNELS {count}"), 1);
        let error = kinergy_bvh::parse(&text).unwrap_err();
        assert_eq!(
            error.kind,
            ParseErrorKind::BadChannelCount {
                found: count.to_owned()
            }
        );
        assert_eq!((error.line, error.column), (5, 11));
    }
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    for depth in [kinergy_bvh::MAX_DEPTH + 1, 200_000] {
        let mut text = String::from("HIERARCHY\n");
        for i in 0..depth {
            text.push_str(if i == 0 {
                "ROOT j\n{\nOFFSET 0 0 0\n"
            } else {
                "JOINT j\n{\nOFFSET 0 0 0\n"
            });
        }
        let error = kinergy_bvh::parse(&text).unwrap_err();
        assert_eq!(
            error.kind,
            ParseErrorKind::TooDeep {
                max: kinergy_bvh::MAX_DEPTH
            }
        );
        assert_eq!(error.line, 2 + 3 * kinergy_bvh::MAX_DEPTH);
    }
}

/// Tokens that steer random text into every corner of the grammar.
fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "HIERARCHY",
            "ROOT",
            "JOINT",
            "End",
            "Site",
            "OFFSET",
            "CHANNELS",
            "MOTION",
            "Frames:",
            "Frame",
            "Time:",
            "{",
            "}",
            "Xposition",
            "Yrotation",
            "zROTATION",
            "Hips",
            "0",
            "1",
            "3",
            "6",
            "-0",
            ".5",
            "1e999",
            "nan",
            "0.0333333",
            ":",
        ])
        .prop_map(str::to_owned),
        "[-+.eE0-9]{1,6}",
        "\\PC{1,4}",
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2048)) {
        check(&bytes);
    }

    #[test]
    fn token_soup_never_panics(
        tokens in prop::collection::vec((token(), prop::sample::select(vec![" ", "\n", "\t", "\r\n", "  "])), 0..120)
    ) {
        let text: String = tokens.iter().flat_map(|(t, s)| [t.as_str(), s]).collect();
        check(text.as_bytes());
    }

    #[test]
    fn a_valid_prefix_then_arbitrary_text_never_panics(cut in 0usize..400, tail in "\\PC{0,64}") {
        let base = std::fs::read_to_string(std::path::Path::new(QUIRKS_DIR).join("valid/per_joint_orders.bvh")).unwrap();
        let cut = base.char_indices().map(|(i, _)| i).nth(cut).unwrap_or(base.len());
        check(format!("{}{tail}", &base[..cut]).as_bytes());
    }
}
