//! End-to-end tests of `kinergy animate`: the GIF's frames and size, the film strip, the
//! report, determinism, and bad input leaving no file behind.

mod common;
use common::{json, kinergy, repo, stderr, text};

use std::path::{Path, PathBuf};

/// Two committed clips of one person (r02 the longer: 109 frames at 60 Hz when written).
fn clips() -> [PathBuf; 2] {
    let p01 = repo().join("data-synthetic/p01");
    [p01.join("r01.bvh"), p01.join("r02.bvh")]
}

/// Each clip's frame count and duration (s), read here so that regenerating the synthetic
/// set does not break the tests.
fn lengths(clips: &[PathBuf]) -> Vec<(usize, f64)> {
    clips
        .iter()
        .map(|c| {
            let (clip, _) = kinergy_motion::read_clip(c, &Default::default()).expect("read");
            (clip.frame_count(), clip.duration())
        })
        .collect()
}

/// The GIF frames expected at `fps`: one per tick from 0 to the longest clip's end, both
/// included (with a tolerance for (frames − 1) · frame_time landing a hair short).
fn expected_frames(clips: &[PathBuf], fps: u32) -> usize {
    let longest = lengths(clips).iter().map(|l| l.1).fold(0.0, f64::max);
    (longest * f64::from(fps) + 1e-6).floor() as usize + 1
}

fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// What a GIF's block structure says: the logical screen's size and each frame's delay
/// (hundredths of a second; `None` without a graphic control extension).
#[derive(Debug)]
struct Gif {
    width: u16,
    height: u16,
    delays: Vec<Option<u16>>,
}

fn u16_le(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

/// Skips data sub-blocks (size byte, data, … up to a zero size) from `at`; returns the index
/// after the terminator.
fn skip_sub_blocks(b: &[u8], mut at: usize) -> usize {
    loop {
        let n = usize::from(b[at]);
        at += 1;
        if n == 0 {
            return at;
        }
        at += n;
    }
}

/// Walks a GIF's blocks: header, logical screen, optional global colour table, then
/// extensions (0x21) and images (0x2C) up to the trailer (0x3B).
fn parse_gif(b: &[u8]) -> Gif {
    assert_eq!(&b[..6], b"GIF89a", "GIF signature");
    let (width, height) = (u16_le(b, 6), u16_le(b, 8));
    let packed = b[10];
    let mut at = 13;
    if packed & 0x80 != 0 {
        at += 3 << ((packed & 7) + 1);
    }
    let mut delays = Vec::new();
    let mut pending_delay = None;
    loop {
        match b[at] {
            0x21 => {
                let label = b[at + 1];
                if label == 0xF9 {
                    // Graphic control: size 4, packed, delay (u16), transparent index.
                    assert_eq!(b[at + 2], 4, "graphic control block size");
                    pending_delay = Some(u16_le(b, at + 4));
                }
                at = skip_sub_blocks(b, at + 2);
            }
            0x2C => {
                let local = b[at + 9];
                at += 10;
                if local & 0x80 != 0 {
                    at += 3 << ((local & 7) + 1);
                }
                at += 1; // LZW minimum code size
                at = skip_sub_blocks(b, at);
                delays.push(pending_delay.take());
            }
            0x3B => {
                assert_eq!(at + 1, b.len(), "nothing after the trailer");
                break;
            }
            other => panic!("unexpected GIF block {other:#04x} at byte {at}"),
        }
    }
    Gif {
        width,
        height,
        delays,
    }
}

/// A PNG's width and height from its IHDR chunk.
fn png_size(b: &[u8]) -> (u32, u32) {
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&b[12..16], b"IHDR", "IHDR first");
    let be = |at: usize| u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    (be(16), be(20))
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn animate_writes_one_gif_frame_per_tick_and_a_png_strip_beside_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gif = dir.path().join("overlay.gif");
    let [a, b] = clips();
    let lengths = lengths(&[a.clone(), b.clone()]);
    let frames = expected_frames(&[a.clone(), b.clone()], 10);
    let longest = lengths[0].1.max(lengths[1].1);
    let o = kinergy(&[
        "animate",
        utf8(&a),
        utf8(&b),
        "-o",
        utf8(&gif),
        "--fps",
        "10",
        "--size",
        "160x120",
        "--strip-frames",
        "4",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = json(&o);

    // E.g. 109 frames at 60 Hz last 1.8 s: floor(1.8 · 10) + 1 = 19 frames of 100 ms.
    let g = parse_gif(&std::fs::read(&gif).expect("gif"));
    assert_eq!((g.width, g.height), (160, 120));
    assert_eq!(g.delays.len(), frames);
    assert!(g.delays.iter().all(|&d| d == Some(10)), "{:?}", g.delays);
    assert_eq!(report["frames"], frames);
    assert_eq!(report["fps"], 10);
    assert_eq!(report["view"], "front");

    // The strip defaults to the GIF's path with .png: 4 panels of 160 × 120 in one row.
    let strip = dir.path().join("overlay.png");
    assert_eq!(report["strip"], utf8(&strip));
    assert_eq!(png_size(&std::fs::read(&strip).expect("png")), (640, 120));
    assert_eq!(report["strip_size"], serde_json::json!([640, 120]));
    let times: Vec<f64> = report["strip_times_s"]
        .as_array()
        .expect("times")
        .iter()
        .map(|t| t.as_f64().expect("number"))
        .collect();
    assert_eq!(times.len(), 4);
    assert_eq!(times[0], 0.0);
    assert!((times[3] - longest).abs() < 1e-9, "{times:?}");

    let rows = report["clips"].as_array().expect("clips");
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["label"], "r01");
    for (row, (frames, duration)) in rows.iter().zip(&lengths) {
        assert_eq!(row["frames"], *frames);
        assert!((row["duration_s"].as_f64().expect("duration") - duration).abs() < 1e-9);
    }
    assert_eq!(listing(dir.path()), ["overlay.gif", "overlay.png"]);
}

#[test]
fn animate_svg_strip_has_the_legend_times_and_one_colour_per_clip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gif = dir.path().join("pair.gif");
    let svg = dir.path().join("pair.svg");
    let [a, b] = clips();
    let frames = expected_frames(&[a.clone(), b.clone()], 2);
    let longest = lengths(&[a.clone(), b.clone()])
        .iter()
        .map(|l| l.1)
        .fold(0.0, f64::max);
    let o = kinergy(&[
        "animate",
        utf8(&a),
        utf8(&b),
        "-o",
        utf8(&gif),
        "--fps",
        "2",
        "--size",
        "160x120",
        "--view",
        "side",
        "--strip",
        utf8(&svg),
        "--strip-frames",
        "3",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = text(&o.stdout);
    let expected = format!("2 clips, {frames} frames at 2 fps");
    assert!(summary.contains(&expected), "{summary}");
    assert!(summary.contains("side view"), "{summary}");
    let g = parse_gif(&std::fs::read(&gif).expect("gif"));
    assert_eq!(g.delays.len(), frames);

    let s = std::fs::read_to_string(&svg).expect("svg");
    assert!(s.contains(r#"width="480" height="120""#), "strip size");
    let (middle, end) = (
        format!("t = {:.2} s", longest / 2.0),
        format!("t = {longest:.2} s"),
    );
    for label in ["r01", "r02", "t = 0.00 s", &middle, &end] {
        assert!(s.contains(label), "{label} missing from the strip");
    }
    // The palette's first two colours draw the bones: one figure per clip and panel.
    for colour in ["#0072B2", "#D55E00"] {
        let bones = s.matches(&format!(r#"stroke="{colour}""#)).count();
        assert!(bones > 3 * 10, "{colour}: {bones} strokes");
    }
}

#[test]
fn animate_is_deterministic_and_views_differ() {
    let dir = tempfile::tempdir().expect("tempdir");
    let [a, b] = clips();
    let run = |name: &str, view: &str| -> (Vec<u8>, Vec<u8>) {
        let gif = dir.path().join(format!("{name}.gif"));
        let o = kinergy(&[
            "animate",
            utf8(&a),
            utf8(&b),
            "-o",
            utf8(&gif),
            "--fps",
            "4",
            "--size",
            "96x72",
            "--strip-frames",
            "2",
            "--view",
            view,
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        (
            std::fs::read(&gif).expect("gif"),
            std::fs::read(gif.with_extension("png")).expect("png"),
        )
    };
    let first = run("first", "front");
    let again = run("again", "front");
    assert!(first.0 == again.0, "the same inputs gave different GIFs");
    assert!(first.1 == again.1, "the same inputs gave different strips");
    let side = run("side", "side");
    let top = run("top", "top");
    assert!(first.0 != side.0 && first.0 != top.0 && side.0 != top.0);
}

#[test]
fn animate_bad_input_exits_2_naming_the_problem_and_leaves_no_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let broken = dir.path().join("broken.bvh");
    std::fs::write(&broken, "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0\n").expect("write");
    let missing = dir.path().join("nowhere.bvh");
    let gif = dir.path().join("out.gif");
    let [a, _] = clips();
    let (a, gif_s) = (utf8(&a), utf8(&gif));
    let p01 = repo().join("data-synthetic/p01");
    let (mp4, jpg) = (dir.path().join("out.mp4"), dir.path().join("s.jpg"));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![utf8(&missing), "-o", gif_s], "nowhere.bvh"),
        (vec![a, utf8(&broken), "-o", gif_s], "broken.bvh"),
        (vec![a, "-o", utf8(&mp4)], "must end in .gif"),
        (vec![a, "-o", gif_s, "--fps", "0"], "--fps"),
        (vec![a, "-o", gif_s, "--fps", "101"], "--fps"),
        (
            vec![a, "-o", gif_s, "--strip-frames", "25"],
            "--strip-frames",
        ),
        (vec![a, "-o", gif_s, "--size", "10x10"], "--size"),
        (vec![a, "-o", gif_s, "--size", "640"], "--size"),
        (vec![a, "-o", gif_s, "--strip", utf8(&jpg)], "--strip"),
        (vec![utf8(&p01), "-o", gif_s], "at most 8"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["animate"];
        all.extend(&args);
        let o = kinergy(&all);
        let message = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {message}");
        assert!(
            message.contains(needle),
            "{args:?}: `{needle}` not in {message}"
        );
        assert_eq!(listing(dir.path()), ["broken.bvh"], "{args:?} left a file");
    }

    // A strip that cannot be written is refused before any drawing (outputs are checked
    // first): bad input, and no GIF either.
    let nowhere = dir.path().join("no-such-folder/strip.png");
    let o = kinergy(&[
        "animate",
        a,
        "-o",
        gif_s,
        "--strip",
        utf8(&nowhere),
        "--fps",
        "2",
        "--size",
        "96x72",
    ]);
    let message = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{message}");
    assert!(message.contains(utf8(&nowhere)), "{message}");
    assert!(message.contains("does not exist"), "{message}");
    assert_eq!(
        listing(dir.path()),
        ["broken.bvh"],
        "a failed strip left a file"
    );
}
