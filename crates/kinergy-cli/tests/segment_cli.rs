//! End-to-end tests of `kinergy segment`: labels and truncation printed, `--select`,
//! `--manifest` over folders (read back by the library), frames that paste into `--frames`.

mod common;
use common::{assert_bad_input, fixture, json, kinergy, repo, stderr, stdout};

use std::path::{Path, PathBuf};

use kinergy_motion::segment::Label;
use kinergy_train::segments_file::SegmentsFile;

fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Two persons' folders of synthetic-set clips: ann/{r01,r02}.bvh and bob/r01.bvh.
fn persons() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let root = dir.path().join("people");
    for (person, from) in [
        ("ann", "p01/r01.bvh"),
        ("ann", "p01/r02.bvh"),
        ("bob", "p02/r01.bvh"),
    ] {
        let folder = root.join(person);
        std::fs::create_dir_all(&folder).expect("folder");
        let name = Path::new(from).file_name().expect("name");
        std::fs::copy(repo().join("data-synthetic").join(from), folder.join(name)).expect("copy");
    }
    (dir, root)
}

// The listing says each segment's label, whether it is cut by the clip's ends, which is the
// main reach, and the frame convention once.
#[test]
fn segment_prints_labels_truncation_and_the_convention() {
    let clip = fixture("006_14.bvh");
    let o = kinergy(&["segment", utf8(&clip)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    eprintln!("{text}");
    for needle in [
        "reach",
        "return",
        "cut at start",
        "cut at end",
        "← main reach",
        "end excluded, as --frames A..B takes them",
    ] {
        assert!(text.contains(needle), "no `{needle}` in\n{text}");
    }
    let report = json(&kinergy(&["segment", utf8(&clip), "--json"]));
    let segments = report["segments"].as_array().expect("segments");
    let main = report["main"].as_u64().expect("a main reach") as usize;
    assert_eq!(segments[main]["label"], "reach");
    assert_eq!(segments[main]["main"], true);
    for s in segments {
        let (a, b) = (
            s["onset"].as_u64().expect("onset"),
            s["end"].as_u64().expect("end"),
        );
        assert_eq!(s["frames"], format!("{a}..{b}"));
        assert_eq!(
            s["truncated"].as_bool(),
            Some(s["truncated_start"] == true || s["truncated_end"] == true)
        );
    }
}

// --select main|all|N: the main reach, every reach, the N-th segment counted from 0 (numbered
// as in the full list); past the end a task failure naming the clip; not a selection: bad
// input.
#[test]
fn select_takes_main_all_or_one_segment() {
    let clip = fixture("006_14.bvh");
    let clip = utf8(&clip);
    let listed = |extra: &[&str]| {
        let mut args = vec!["segment", clip, "--json"];
        args.extend(extra);
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", stderr(&o));
        json(&o)["segments"].as_array().expect("segments").clone()
    };
    let every = listed(&[]);
    assert!(every.len() >= 3, "{every:?}");

    let main = listed(&["--select", "main"]);
    assert_eq!(main.len(), 1);
    assert_eq!(main[0]["main"], true);

    let reaches = listed(&["--select", "all"]);
    let want: Vec<_> = every.iter().filter(|s| s["label"] == "reach").collect();
    assert_eq!(reaches.iter().collect::<Vec<_>>(), want);

    for (n, s) in every.iter().enumerate() {
        let one = listed(&["--select", &n.to_string()]);
        assert_eq!(one, std::slice::from_ref(s), "--select {n}");
        assert_eq!(one[0]["index"], n);
    }

    let past = every.len().to_string();
    let o = kinergy(&["segment", clip, "--select", &past]);
    // A capture without the segment asked for is bad input (exit 2), as in fit and compare.
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("no segment #{past}")) && stderr(&o).contains("006_14.bvh"),
        "{}",
        stderr(&o)
    );
    // A walk has no reach: `main` fails, saying what there is.
    let walk = fixture("cmu_12_01_walk.bvh");
    let o = kinergy(&["segment", utf8(&walk), "--select", "main"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no main reach"), "{}", stderr(&o));

    let nowhere = Path::new("/nonexistent/never.csv");
    assert_bad_input(
        &["segment", clip, "--select", "first"],
        "main, all or a segment number",
        nowhere,
    );
}

// `segment FOLDER --manifest F` writes every listed segment of every clip, with its person
// (the clip's folder); the library reads it back as printed, and the frames paste into
// `convert --frames A..B`.
#[test]
fn manifest_holds_what_segment_lists() {
    let (dir, root) = persons();
    let out = dir.path().join("segments.csv");
    let o = kinergy(&["segment", utf8(&root), "--manifest", utf8(&out), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let reports = json(&o);
    let reports = reports.as_array().expect("one report per clip");
    assert_eq!(reports.len(), 3);

    let manifest = SegmentsFile::read(&out).expect("the segments file reads back");
    let rows = manifest.rows();
    let listed: Vec<(String, String, String, String)> = reports
        .iter()
        .flat_map(|r| {
            let clip = std::fs::canonicalize(r["clip"].as_str().expect("clip"))
                .expect("clip")
                .display()
                .to_string();
            let person = r["person"].as_str().expect("person").to_string();
            r["segments"]
                .as_array()
                .expect("segments")
                .iter()
                .map(|s| {
                    (
                        clip.clone(),
                        s["frames"].as_str().expect("frames").to_string(),
                        s["label"].as_str().expect("label").to_string(),
                        person.clone(),
                    )
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let read: Vec<(String, String, String, String)> = rows
        .iter()
        .map(|r| {
            (
                std::fs::canonicalize(&r.clip)
                    .expect("clip")
                    .display()
                    .to_string(),
                format!("{}..{}", r.frames.start, r.frames.end),
                r.label.to_string(),
                r.person.clone(),
            )
        })
        .collect();
    assert_eq!(read, listed);
    let persons: Vec<&str> = rows.iter().map(|r| r.person.as_str()).collect();
    assert!(
        persons.contains(&"ann") && persons.contains(&"bob"),
        "{persons:?}"
    );
    // Clips are written relative to the file's folder.
    let text = std::fs::read_to_string(&out).expect("text");
    assert!(text.contains("people/ann/r01.bvh,"), "{text}");

    // What segment printed pastes into --frames: the main reach of ann/r01 converts to exactly
    // its frames.
    let main = rows
        .iter()
        .find(|r| r.label == Label::Reach && r.clip.ends_with("ann/r01.bvh"))
        .expect("a reach in ann/r01");
    let cut = dir.path().join("cut.bvh");
    let frames = format!("{}..{}", main.frames.start, main.frames.end);
    let o = kinergy(&[
        "convert",
        utf8(&main.clip),
        "--frames",
        &frames,
        "-o",
        utf8(&cut),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (clip, _) = kinergy_motion::read_clip(&cut, &Default::default()).expect("cut");
    assert_eq!(clip.frame_count(), main.frames.len());

    // --select main: one row per clip, each a reach.
    let main_only = dir.path().join("main.csv");
    let o = kinergy(&[
        "segment",
        utf8(&root),
        "--select",
        "main",
        "--manifest",
        utf8(&main_only),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("3 segments written to"),
        "{}",
        stdout(&o)
    );
    let m = SegmentsFile::read(&main_only).expect("read");
    assert_eq!(m.rows().len(), 3);
    assert!(m.rows().iter().all(|r| r.label == Label::Reach));
}

// Bad output paths and a clip without the arm are bad input, checked before any file is
// written; a selection that fails on one clip writes nothing.
#[test]
fn manifest_bad_input_writes_nothing() {
    let (dir, root) = persons();
    let clip = root.join("ann/r01.bvh");
    let no_folder = dir.path().join("none/segments.csv");
    assert_bad_input(
        &["segment", utf8(&clip), "--manifest", utf8(&no_folder)],
        "does not exist",
        &no_folder,
    );
    assert_bad_input(
        &["segment", utf8(&clip), "--manifest", utf8(dir.path())],
        "is a folder",
        &dir.path().join("never"),
    );
    let missing = dir.path().join("missing.bvh");
    let out = dir.path().join("segments.csv");
    assert_bad_input(
        &["segment", utf8(&missing), "--manifest", utf8(&out)],
        "missing.bvh",
        &out,
    );
    // A clip with no reach among others: `--select main` fails on it and writes no file.
    let walk = root.join("walk.bvh");
    std::fs::copy(fixture("cmu_12_01_walk.bvh"), &walk).expect("copy");
    let o = kinergy(&[
        "segment",
        utf8(&root),
        "--select",
        "main",
        "--manifest",
        utf8(&out),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("walk.bvh"), "{}", stderr(&o));
    assert!(!out.exists(), "a partial segments file was written");
}

// A reach down to the floor, generated: `kinergy synth` makes the takes and its manifest says
// where each target is. The main reach of every `floor_far` take, relative to the shoulder
// and with `--world`, is a whole reach whose last frame is within 6 frames (0.2 s) of the hand's
// arrival: the first frame from which the hand stays within 1 cm of the target. (Before pick-ups
// were read in the world, p07/r04 had no reach relative to the shoulder: the trunk carries the
// hand down, and the arm ends hanging as if going back to rest.)
#[test]
fn a_generated_reach_to_the_floor_ends_at_its_target() {
    let dir = tempfile::tempdir().expect("tempdir");
    let set = dir.path().join("set");
    let o = kinergy(&[
        "synth",
        "-o",
        utf8(&set),
        "--persons",
        "8",
        "--reaches",
        "4",
        "--frame-rate",
        "30",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let manifest = std::fs::read_to_string(set.join("manifest.csv")).expect("manifest");
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|&h| h == name)
            .unwrap_or_else(|| panic!("no `{name}` column in {header:?}"))
    };
    let (clip_at, kind_at, x_at) = (column("clip"), column("kind"), column("target_x"));
    let mut checked = 0;
    let mut wrong = Vec::new();
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        if cells[kind_at] != "floor_far" {
            continue;
        }
        let target = kinergy_motion::nalgebra::Point3::new(
            cells[x_at].parse::<f64>().expect("x"),
            cells[x_at + 1].parse::<f64>().expect("y"),
            cells[x_at + 2].parse::<f64>().expect("z"),
        );
        let path = set.join(cells[clip_at]);
        let (clip, _) = kinergy_motion::read_clip(&path, &Default::default()).expect("clip");
        let arm = kinergy_motion::ArmJoints::find(clip.skeleton(), kinergy_motion::Side::Right)
            .expect("right arm");
        let hand = clip
            .trajectory(&[arm.end_effector()])
            .expect("trajectory")
            .path(0);
        let mut arrival = hand.len();
        while arrival > 0 && (hand[arrival - 1] - target).norm() < 0.01 {
            arrival -= 1;
        }
        assert!(
            arrival < hand.len(),
            "{}: never at its target",
            cells[clip_at]
        );
        for world in [false, true] {
            let mut args = vec!["segment", utf8(&path), "--json"];
            if world {
                args.push("--world");
            }
            let report = json(&kinergy(&args));
            let main = report["main"]
                .as_u64()
                .map(|i| &report["segments"][i as usize]);
            let end = main
                .filter(|m| m["label"] == "reach" && m["truncated"] == false)
                .and_then(|m| m["end"].as_u64());
            match end {
                Some(end) if (end as usize - 1).abs_diff(arrival) <= 6 => {}
                _ => wrong.push(format!(
                    "{} (world: {world}): main {main:?}, the hand arrives on frame {arrival}",
                    cells[clip_at]
                )),
            }
        }
        checked += 1;
    }
    assert_eq!(checked, 8);
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

// Issue 43, item 8: a generated library's floor reaches (`kinergy synth`, 48 persons × 4
// reaches at 30 Hz: every person's fourth reach is `floor_far`, a stoop or a squat down to a
// target 8 % of the height above the floor) are all found by `segment --arm auto` — no take
// skipped — and the right arm's main reach ends within 3 frames of where the hand stops
// lowest. The truth is the hand's own: a generated clip ends at rest at its target, low on
// the floor, and the hand stops there on the first frame from which its speed (central
// differences) stays under 5 cm/s to the clip's end. Before the way down was judged in the
// world (the hand below where it hangs at rest is not going back to rest; a reach the trunk
// carries ends where the hand stops, and settles there), 7 of these 48 ended 5 to 9 frames
// early, at a dip or before a last correction. (In a 100-person set, p72/r04 still fails: the
// controller flings the hand 1.3 m up and forward before it goes down, and that fling is the
// larger reach.)
#[test]
fn every_generated_floor_reach_is_found_and_ends_where_the_hand_stops_lowest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let set = dir.path().join("set");
    let o = kinergy(&[
        "synth",
        "-o",
        utf8(&set),
        "--persons",
        "48",
        "--reaches",
        "4",
        "--frame-rate",
        "30",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let manifest = std::fs::read_to_string(set.join("manifest.csv")).expect("manifest");
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|&h| h == name)
            .unwrap_or_else(|| panic!("no `{name}` column in {header:?}"))
    };
    let (clip_at, kind_at) = (column("clip"), column("kind"));
    let floor: Vec<String> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|cells| cells[kind_at] == "floor_far")
        .map(|cells| cells[clip_at].to_string())
        .collect();
    assert_eq!(floor.len(), 48);
    let paths: Vec<PathBuf> = floor.iter().map(|c| set.join(c)).collect();
    let mut args = vec!["segment", "--arm", "auto", "--select", "main", "--json"];
    args.extend(paths.iter().map(|p| utf8(p)));
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("skipped"), "{}", stderr(&o));
    let listed = json(&o);
    let mut wrong = Vec::new();
    for (clip, path) in floor.iter().zip(&paths) {
        let right = listed
            .as_array()
            .expect("one listing per arm")
            .iter()
            .find(|r| r["side"] == "right" && path.ends_with(r["clip"].as_str().unwrap_or("-")));
        let Some(main) = right.map(|r| &r["segments"][0]) else {
            wrong.push(format!("{clip}: no right-arm reach"));
            continue;
        };
        let (c, _) = kinergy_motion::read_clip(path, &Default::default()).expect("clip");
        let arm = kinergy_motion::ArmJoints::find(c.skeleton(), kinergy_motion::Side::Right)
            .expect("right arm");
        let hand = c
            .trajectory(&[arm.end_effector()])
            .expect("trajectory")
            .path(0);
        let n = hand.len();
        let speed = |i: usize| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (hand[b] - hand[a]).norm() / ((b - a) as f64 * c.frame_time())
        };
        let mut stop = n;
        while stop > 0 && speed(stop - 1) < 0.05 {
            stop -= 1;
        }
        assert!(stop < n, "{clip}: the hand never comes to rest");
        let lowest = hand.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        assert!(
            hand[stop].y - lowest < 0.05,
            "{clip}: the hand stops {:.3} m above its lowest",
            hand[stop].y - lowest
        );
        let last = main["end"].as_u64().expect("end") as usize - 1;
        if main["label"] != "reach" || main["truncated_end"] != false || last.abs_diff(stop) > 3 {
            wrong.push(format!(
                "{clip}: main {} ({}), the hand stops lowest on frame {stop}",
                main["frames"], main["label"]
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// A folder with a link to itself and two folders linking to each other are walked once:
/// each capture is listed once, the links are said on stderr, nothing hangs.
#[cfg(unix)]
#[test]
fn link_loops_are_walked_once_and_said() {
    let (_dir, root) = persons();
    std::os::unix::fs::symlink(&root, root.join("ann").join("up")).expect("link");
    std::os::unix::fs::symlink(root.join("bob"), root.join("ann").join("to-bob")).expect("link");
    std::os::unix::fs::symlink(root.join("ann"), root.join("bob").join("to-ann")).expect("link");
    let o = kinergy(&["segment", utf8(&root), "--select", "main", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let listed = json(&o);
    let clips: Vec<&str> = listed
        .as_array()
        .expect("one listing per capture")
        .iter()
        .map(|r| r["clip"].as_str().expect("clip"))
        .collect();
    assert_eq!(clips.len(), 3, "{clips:?}");
    assert!(
        stderr(&o).contains("not followed") && stderr(&o).contains("the same folder as"),
        "{}",
        stderr(&o)
    );
}

/// `--min-peak-speed` takes its whole documented range, 0.001 to 50 m/s (the rest threshold
/// is lowered with it), and refuses what is outside it.
#[test]
fn the_documented_peak_speeds_are_all_taken() {
    let clip = fixture("006_14.bvh");
    for speed in ["0.001", "0.01", "0.05", "50"] {
        let o = kinergy(&["segment", utf8(&clip), "--min-peak-speed", speed]);
        assert_eq!(o.status.code(), Some(0), "{speed}: {}", stderr(&o));
    }
    for speed in ["0.0009", "50.0001"] {
        let o = kinergy(&["segment", utf8(&clip), "--min-peak-speed", speed]);
        assert_eq!(o.status.code(), Some(2), "{speed}: {}", stderr(&o));
    }
}

/// Issue 42, case 10: `--arm auto` finds the arms that reach as `fit --arm auto` does, by the
/// hand's speed relative to the shoulder; with `--world` (where a walk's swinging arms
/// "reach") it is refused, saying why, while one arm's world-speed segments are listed.
#[test]
fn world_speed_is_refused_for_the_arms_that_reach_and_listed_for_one_arm() {
    let clip = repo().join("data-synthetic/p01/r09.bvh");
    let clip = clip.to_str().expect("utf-8 path");
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("segments.csv");
    let out_s = out.to_str().expect("utf-8 path");
    assert_bad_input(
        &[
            "segment",
            clip,
            "--arm",
            "auto",
            "--world",
            "--manifest",
            out_s,
        ],
        "--world: the arms that reach are found as `fit --arm auto` finds them",
        &out,
    );
    let o = kinergy(&["segment", clip, "--arm", "right", "--world", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["speed"], "world", "{report}");
    assert!(
        !report["segments"].as_array().expect("segments").is_empty(),
        "{report}"
    );
}
