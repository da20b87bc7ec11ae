//! Limits: absurd rates, durations, sizes and counts are refused before any work (exit 2,
//! the option and its range named, nothing written); input files are bounded in size and
//! must be regular files; BVH frame times are bounded; CR-only files read as LF ones; a
//! surplus value is reported on its line.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_bad_input, fixture, kinergy, repo, stderr, stdout};

fn clip() -> PathBuf {
    repo().join("data-synthetic/p01/r01.bvh")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

#[test]
fn absurd_rates_durations_sizes_and_counts_are_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = clip();
    let clip = s(&clip);
    let bvh = dir.path().join("out.bvh");
    let out = s(&bvh);
    let gif = dir.path().join("out.gif");
    let params = dir.path().join("p.json");
    let svg = dir.path().join("speed.svg");
    let set = dir.path().join("set");
    let cases: Vec<(Vec<&str>, &str, &Path)> = vec![
        (
            vec!["synth", "-o", s(&set), "--frame-rate", "1e7"],
            "--frame-rate",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--frame-rate", "0"],
            "--frame-rate",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--frame-rate", "NaN"],
            "--frame-rate",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--persons", "100000"],
            "--persons",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--reaches", "0"],
            "--reaches",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--both-hands", "1.5"],
            "--both-hands",
            &set,
        ),
        (
            vec!["synth", "-o", s(&set), "--both-hands", "NaN"],
            "--both-hands",
            &set,
        ),
        (
            vec![
                "synthesize",
                "--from",
                clip,
                "-o",
                out,
                "--max-seconds",
                "1e18",
            ],
            "--max-seconds",
            &bvh,
        ),
        (
            vec![
                "synthesize",
                "--from",
                clip,
                "-o",
                out,
                "--tolerance",
                "1e9",
            ],
            "--tolerance",
            &bvh,
        ),
        (
            vec![
                "synthesize",
                "--from",
                clip,
                "-o",
                out,
                "--max-input-mb",
                "0",
            ],
            "--max-input-mb",
            &bvh,
        ),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.4",
                "--timeout",
                "1e18",
                "-o",
                out,
            ],
            "--timeout",
            &bvh,
        ),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.4",
                "--height",
                "300",
                "-o",
                out,
            ],
            "--height",
            &bvh,
        ),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.4",
                "--flexibility",
                "1e300",
                "-o",
                out,
            ],
            "--flexibility",
            &bvh,
        ),
        (
            vec!["animate", clip, "-o", s(&gif), "--size", "4096x4096"],
            "--size",
            &gif,
        ),
        (
            vec!["animate", clip, "-o", s(&gif), "--fps", "1000"],
            "--fps",
            &gif,
        ),
        (
            vec!["animate", clip, "-o", s(&gif), "--strip-frames", "1000"],
            "--strip-frames",
            &gif,
        ),
        (
            // 3840x3840 at 100 fps over a 1.3 s clip: about 2 billion pixels.
            vec![
                "animate",
                clip,
                "-o",
                s(&gif),
                "--size",
                "3840x3840",
                "--fps",
                "100",
                "--strip-frames",
                "1",
            ],
            "lower --size or --fps",
            &gif,
        ),
        (
            vec!["plot", "speed", clip, "-o", s(&svg), "--size", "100000x100"],
            "--size",
            &svg,
        ),
        (
            vec!["plot", "speed", clip, "-o", s(&svg), "--smoothing", "1e9"],
            "--smoothing",
            &svg,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--budget",
                "1e19",
            ],
            "--budget",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--budget",
                "100000000",
            ],
            "--budget",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--threads",
                "100000",
            ],
            "--threads",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--population",
                "0",
            ],
            "--population",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--temperature",
                "inf",
            ],
            "--temperature",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--checkpoint-every",
                "0",
            ],
            "--checkpoint-every",
            &params,
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "-o",
                s(&params),
                "--stable-change",
                "NaN",
            ],
            "--stable-change",
            &params,
        ),
        (
            vec!["compare", clip, "-o", s(&set), "--stable-window", "0"],
            "--stable-window",
            &set,
        ),
        (
            vec![
                "compare",
                clip,
                "-o",
                s(&set),
                "--per",
                "person",
                "--holdout",
                "100000",
            ],
            "--holdout",
            &set,
        ),
        (
            vec!["segment", clip, "--min-peak-speed", "1e9"],
            "--min-peak-speed",
            &set,
        ),
        (
            vec![
                "plan",
                "--scene",
                "examples/bookshelf/scene.json",
                "--target",
                "-0.25,1.1,0.3",
                "--budget-ms",
                "100000000000",
                "-o",
                out,
            ],
            "--budget-ms",
            &bvh,
        ),
    ];
    for (args, needle, output) in cases {
        assert_bad_input(&args, needle, output);
        // The message states the range.
        let err = stderr(&kinergy(&args));
        assert!(
            err.contains("expected")
                || err.contains("must be")
                || err.contains("at most")
                || err.contains("invalid value"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn every_limited_option_states_its_range_in_help() {
    for (sub, needles) in [
        (vec!["synth"], vec!["1 to 100", "1 to 1000"]),
        (
            vec!["synthesize"],
            vec!["0.01 to 60", "0.00001 to 1", "1 to 4096"],
        ),
        (vec!["reach"], vec!["0.1 to 60", "0.5 to 2.5", "0.1 to 10"]),
        (vec!["animate"], vec!["1 to 100", "1 to 24", "64 to 3840"]),
        (vec!["plot", "speed"], vec!["64 to 3840", "0 to 10"]),
        (
            vec!["fit"],
            vec!["1 to 1024", "1 to 10000000", "1 to 1000000"],
        ),
        (vec!["plan"], vec!["1 to 600000", "-2 to 2"]),
    ] {
        let mut args = sub.clone();
        args.push("--help");
        let help = stdout(&kinergy(&args))
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        for n in needles {
            assert!(help.contains(n), "{sub:?} --help does not state `{n}`");
        }
    }
}

/// The committed clip with its frame time replaced.
fn with_frame_time(dir: &Path, frame_time: &str) -> PathBuf {
    let text = std::fs::read_to_string(clip()).expect("read clip");
    let line = text
        .lines()
        .find(|l| l.starts_with("Frame Time"))
        .expect("Frame Time line");
    let path = dir.join("ft.bvh");
    std::fs::write(
        &path,
        text.replace(line, &format!("Frame Time: {frame_time}")),
    )
    .expect("write");
    path
}

fn frame_time_line() -> usize {
    let text = std::fs::read_to_string(clip()).expect("read clip");
    text.lines()
        .position(|l| l.starts_with("Frame Time"))
        .expect("Frame Time line")
        + 1
}

#[test]
fn a_frame_time_of_1e_300_is_refused_on_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = with_frame_time(dir.path(), "1e-300");
    let out = dir.path().join("out.bvh");
    let line = format!("line {}", frame_time_line());
    assert_bad_input(
        &["synthesize", "--from", s(&path), "-o", s(&out)],
        &line,
        &out,
    );
    assert_bad_input(
        &["inspect", s(&path)],
        "frame time `1e-300` is out of range",
        &out,
    );
}

#[test]
fn a_file_over_max_input_mb_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().expect("tempdir");
    let big = dir.path().join("big.bvh");
    // A real clip padded past 1 MiB with trailing blank space (still a valid file).
    let mut text = std::fs::read_to_string(clip()).expect("read clip");
    text.push_str(&" ".repeat(1024 * 1024 + 1));
    std::fs::write(&big, &text).expect("write");
    let out = dir.path().join("out.bvh");
    assert_bad_input(
        &["convert", s(&big), "-o", s(&out), "--max-input-mb", "1"],
        "--max-input-mb",
        &out,
    );
    let err = stderr(&kinergy(&["inspect", s(&big), "--max-input-mb", "1"]));
    assert!(err.contains("1 MiB"), "{err}");
    // Raised, it reads.
    let o = kinergy(&["convert", s(&big), "-o", s(&out), "--max-input-mb", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[cfg(unix)]
#[test]
fn dev_zero_as_a_clip_says_what_it_is() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.bvh");
    let params = dir.path().join("p.json");
    let needle = "/dev/zero: not a regular file (a character device)";
    assert_bad_input(&["inspect", "/dev/zero"], needle, &out);
    assert_bad_input(&["convert", "/dev/zero", "-o", s(&out)], needle, &out);
    assert_bad_input(
        &["fit", "/dev/zero", "--model", "sa", "-o", s(&params)],
        needle,
        &params,
    );
    assert_bad_input(
        &["synthesize", "--from", "/dev/zero", "-o", s(&out)],
        needle,
        &out,
    );
    assert_bad_input(
        &[
            "synthesize",
            "--from",
            s(&clip()),
            "--params",
            "/dev/zero",
            "-o",
            s(&out),
        ],
        "not a regular file",
        &out,
    );
}

#[cfg(unix)]
#[test]
fn a_fifo_as_a_clip_is_refused_without_waiting_for_a_writer() {
    let dir = tempfile::tempdir().expect("tempdir");
    let fifo = dir.path().join("clip.bvh");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable: skipped");
        return;
    }
    let out = dir.path().join("out.bvh");
    // With no writer, opening the FIFO would block forever: the command must not open it.
    assert_bad_input(&["inspect", s(&fifo)], "not a regular file (a FIFO)", &out);
    assert_bad_input(
        &["fit", s(&fifo), "--model", "sa", "-o", s(&out)],
        "a FIFO",
        &out,
    );
    // In a folder, a FIFO named *.bvh is refused the same way.
    assert_bad_input(&["segment", s(dir.path())], "a FIFO", &out);
}

#[test]
fn a_cr_only_file_reads_as_its_lf_version() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(fixture("006_14.bvh")).expect("read");
    let text = text.replace("\r\n", "\n");
    let lf = dir.path().join("lf.bvh");
    let cr = dir.path().join("cr.bvh");
    std::fs::write(&lf, &text).expect("write");
    std::fs::write(&cr, text.replace('\n', "\r")).expect("write");
    let a = kinergy(&["inspect", s(&lf), "--json"]);
    let b = kinergy(&["inspect", s(&cr), "--json"]);
    assert_eq!(a.status.code(), Some(0), "{}", stderr(&a));
    assert_eq!(b.status.code(), Some(0), "{}", stderr(&b));
    let strip = |v: serde_json::Value| {
        let mut v = v;
        v.as_object_mut().expect("object").remove("file");
        v.as_object_mut().expect("object").remove("path");
        v
    };
    assert_eq!(strip(common::json(&a)), strip(common::json(&b)));
    // Written back, the same file.
    let (oa, ob) = (dir.path().join("a.bvh"), dir.path().join("b.bvh"));
    assert_eq!(
        kinergy(&["convert", s(&lf), "-o", s(&oa)]).status.code(),
        Some(0)
    );
    assert_eq!(
        kinergy(&["convert", s(&cr), "-o", s(&ob)]).status.code(),
        Some(0)
    );
    assert_eq!(
        std::fs::read(&oa).expect("a"),
        std::fs::read(&ob).expect("b")
    );
}

#[test]
fn a_surplus_value_is_reported_on_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(clip()).expect("read clip");
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let first = frame_time_line(); // 1-based: the first frame is at index `first`
    let target = first + 30; // 0-based index of the 31st frame line
    lines[target].push_str(" 7");
    let channels = lines[first].split_whitespace().count();
    let path = dir.path().join("surplus.bvh");
    std::fs::write(&path, lines.join("\n") + "\n").expect("write");
    let out = dir.path().join("out.bvh");
    let needle = format!("line {}, column", target + 1);
    assert_bad_input(&["convert", s(&path), "-o", s(&out)], &needle, &out);
    let err = stderr(&kinergy(&["inspect", s(&path)]));
    assert!(
        err.contains(&format!(
            "{} values on this line, but the skeleton has {channels} channels",
            channels + 1
        )),
        "{err}"
    );
}
