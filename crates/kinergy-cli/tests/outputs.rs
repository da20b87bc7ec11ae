//! Outputs: refused before any work when they cannot or must not be written (a missing
//! folder, an input under any spelling, a device, a FIFO), written atomically when they are
//! (a killed `fit --log` leaves the old log or a whole new one, no debris), and a full disk
//! said as such.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{fixture, kinergy, repo, stderr};

/// A writing subcommand: its name and its command line for one input and one output.
struct Case {
    name: &'static str,
    /// The input's file name (some outputs must end in a given extension).
    input: &'static str,
    /// The input's content.
    source: PathBuf,
    /// Whether the output is a folder.
    folder: bool,
    args: fn(&str, &str, &Path) -> Vec<String>,
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| (*s).to_string()).collect()
}

fn cases() -> Vec<Case> {
    let bvh = fixture("006_14.bvh");
    let scene = repo().join("examples/bookshelf/scene.json");
    vec![
        Case {
            name: "convert",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["convert", i, "-o", o]),
        },
        Case {
            name: "synthesize",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["synthesize", "--from", i, "--model", "sa", "-o", o]),
        },
        Case {
            name: "fit",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["fit", i, "--model", "sa", "--budget", "50", "-o", o]),
        },
        Case {
            name: "fit --checkpoint",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, d| {
                let p = d.join("p.json");
                strings(&[
                    "fit",
                    i,
                    "--model",
                    "sa",
                    "--budget",
                    "50",
                    "-o",
                    p.to_str().unwrap(),
                    "--checkpoint",
                    o,
                ])
            },
        },
        Case {
            name: "fit --log",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, d| {
                let p = d.join("p.json");
                strings(&[
                    "fit",
                    i,
                    "--model",
                    "sa",
                    "--budget",
                    "50",
                    "-o",
                    p.to_str().unwrap(),
                    "--log",
                    o,
                ])
            },
        },
        Case {
            name: "compare",
            input: "in.bvh",
            source: bvh.clone(),
            folder: true,
            args: |i, o, _| strings(&["compare", i, "--budget", "50", "-o", o]),
        },
        Case {
            name: "reach",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["reach", "--target", "0.3,1.1,0.4", "--person", i, "-o", o]),
        },
        Case {
            name: "plan",
            input: "scene.json",
            source: scene,
            folder: false,
            args: |i, o, _| strings(&["plan", "--scene", i, "--target", "-0.25,1.1,0.3", "-o", o]),
        },
        Case {
            name: "plot",
            input: "in.svg",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["plot", "speed", i, "-o", o]),
        },
        Case {
            name: "plot --csv",
            input: "in.bvh",
            source: bvh.clone(),
            folder: false,
            args: |i, o, d| {
                let svg = d.join("speed.svg");
                strings(&["plot", "speed", i, "-o", svg.to_str().unwrap(), "--csv", o])
            },
        },
        Case {
            name: "animate",
            input: "in.gif",
            source: bvh.clone(),
            folder: false,
            args: |i, o, _| strings(&["animate", i, "-o", o]),
        },
        Case {
            name: "animate --strip",
            input: "in.png",
            source: bvh.clone(),
            folder: false,
            args: |i, o, d| {
                let gif = d.join("a.gif");
                strings(&["animate", i, "-o", gif.to_str().unwrap(), "--strip", o])
            },
        },
        Case {
            name: "segment --manifest",
            input: "in.bvh",
            source: bvh,
            folder: false,
            args: |i, o, _| strings(&["segment", i, "--manifest", o]),
        },
    ]
}

/// Runs `args`, expecting exit 2 with `needle` in the message and no panic.
fn refused(case: &str, args: &[String], needle: &str) {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = kinergy(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{case}: {args:?}: {err}");
    assert!(
        err.contains(needle),
        "{case}: `{err}` does not say {needle:?}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("Os {"),
        "{case}: {err}"
    );
}

/// A fresh folder with the case's input in `x/`; returns (folder, input).
fn setup(case: &Case) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("x")).unwrap();
    let input = dir.path().join("x").join(case.input);
    std::fs::copy(&case.source, &input).unwrap();
    (dir, input)
}

/// An output name of the right kind for the case, in `folder`.
fn output_in(case: &Case, folder: &Path) -> PathBuf {
    let ext = Path::new(case.input).extension().unwrap();
    if case.folder {
        folder.join("out")
    } else {
        folder.join("out").with_extension(ext)
    }
}

#[test]
fn an_output_in_a_missing_folder_is_refused_before_any_work() {
    for case in cases() {
        let (dir, input) = setup(&case);
        let out = output_in(&case, &dir.path().join("missing"));
        let args = (case.args)(input.to_str().unwrap(), out.to_str().unwrap(), dir.path());
        refused(case.name, &args, "does not exist");
        assert!(!dir.path().join("missing").exists(), "{}", case.name);
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "{}: wrote something", case.name);
    }
}

#[test]
fn an_output_that_is_an_input_is_refused_however_spelled() {
    for case in cases() {
        let (dir, input) = setup(&case);
        let before = std::fs::read(&input).unwrap();
        let respelled = dir.path().join("x").join("..").join("x").join(case.input);
        for out in [&input, &respelled] {
            let args = (case.args)(input.to_str().unwrap(), out.to_str().unwrap(), dir.path());
            let needle = if case.folder {
                "not a folder"
            } else {
                "is one of the inputs"
            };
            refused(case.name, &args, needle);
            assert_eq!(std::fs::read(&input).unwrap(), before, "{}", case.name);
        }
    }
}

#[test]
fn a_checkpoint_that_is_also_the_output_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let clip = fixture("006_14.bvh");
    let p = dir.path().join("p.json");
    let same = dir.path().join(".").join("p.json");
    let args = strings(&[
        "fit",
        clip.to_str().unwrap(),
        "--model",
        "sa",
        "-o",
        p.to_str().unwrap(),
        "--checkpoint",
        same.to_str().unwrap(),
    ]);
    refused("fit", &args, "is also the -o output");
    assert!(!p.exists());
}

#[cfg(unix)]
#[test]
fn an_output_onto_dev_null_is_refused_and_the_device_stays() {
    use std::os::unix::fs::FileTypeExt;
    let null = Path::new("/dev/null");
    if !std::fs::metadata(null).is_ok_and(|m| m.file_type().is_char_device()) {
        eprintln!("skipped: no /dev/null device here");
        return;
    }
    for case in cases() {
        let (dir, input) = setup(&case);
        let args = (case.args)(input.to_str().unwrap(), "/dev/null", dir.path());
        let o = kinergy(&args.iter().map(String::as_str).collect::<Vec<_>>());
        // Some commands refuse the name first (it must end in .gif, .svg…): exit 2 either way.
        assert_eq!(o.status.code(), Some(2), "{}: {}", case.name, stderr(&o));
        let m = std::fs::metadata(null).unwrap();
        assert!(
            m.file_type().is_char_device(),
            "{}: /dev/null replaced",
            case.name
        );
    }
}

#[cfg(unix)]
#[test]
fn an_output_onto_a_fifo_is_refused_and_the_fifo_stays() {
    use std::os::unix::fs::FileTypeExt;
    for case in cases() {
        let (dir, input) = setup(&case);
        let fifo = output_in(&case, dir.path());
        let made = Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: mkfifo is not available here");
            return;
        }
        let args = (case.args)(input.to_str().unwrap(), fifo.to_str().unwrap(), dir.path());
        let needle = if case.folder {
            "not a folder"
        } else {
            "a FIFO"
        };
        refused(case.name, &args, needle);
        let m = std::fs::symlink_metadata(&fifo).unwrap();
        assert!(
            m.file_type().is_fifo(),
            "{}: the FIFO was replaced",
            case.name
        );
    }
}

/// Whether `text` is a whole `fit --log`: the header, then complete rows.
fn is_whole_log(text: &str) -> bool {
    let mut lines = text.split_inclusive('\n');
    lines.next() == Some("iteration,evaluations,temperature,best_cost,mean_cost,acceptance\n")
        && lines.all(|l| l.ends_with('\n') && l.split(',').count() == 6)
}

/// Temporary files of `name` left in `dir`.
fn debris(dir: &Path, name: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&format!(".{name}.")) && n.ends_with(".tmp"))
        .collect()
}

#[test]
fn a_fit_log_killed_mid_run_is_the_old_log_or_a_whole_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("fit.csv");
    let old = "the previous log\n";
    let clip = fixture("006_14.bvh");
    let args = |budget: &str| {
        strings(&[
            "fit",
            clip.to_str().unwrap(),
            "--model",
            "sb",
            "--budget",
            budget,
            "--seed",
            "5",
            "-o",
            dir.path().join("p.json").to_str().unwrap(),
            "--log",
            log.to_str().unwrap(),
        ])
    };
    // Kill at several moments: before the log is started, while it grows, near the end.
    let seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(7, |d| d.subsec_nanos());
    for (k, base_ms) in [2u64, 15, 40, 120, 300].into_iter().enumerate() {
        std::fs::write(&log, old).unwrap();
        let jitter = u64::from(seed.rotate_left(k as u32 * 5) % 20);
        let mut child = Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args(args("4000"))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(base_ms + jitter));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(
            text == old || is_whole_log(&text),
            "killed after {} ms: a damaged log:\n{text}",
            base_ms + jitter
        );
        // The next run cleans up what the killed one left and leaves nothing of its own.
        let o = kinergy(&args("200").iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(is_whole_log(&std::fs::read_to_string(&log).unwrap()));
        assert_eq!(debris(dir.path(), "fit.csv"), Vec::<String>::new());
    }
}

#[test]
fn a_logged_fit_with_checkpoints_keeps_the_log_whole_and_resumes_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("fit.csv");
    let ckpt = dir.path().join("fit.ckpt");
    let clip = fixture("006_14.bvh");
    let run = |extra: &[&str]| {
        let mut args = strings(&[
            "fit",
            clip.to_str().unwrap(),
            "--model",
            "sa",
            "--no-nested",
            "--budget",
            "400",
            "--seed",
            "5",
            "-o",
            dir.path().join("p.json").to_str().unwrap(),
            "--log",
            log.to_str().unwrap(),
            "--checkpoint",
            ckpt.to_str().unwrap(),
            "--checkpoint-every",
            "5",
        ]);
        args.extend(strings(extra));
        kinergy(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let o = run(&["--interrupt-after", "12"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(is_whole_log(&text), "{text}");
    let o = run(&["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(is_whole_log(&text), "{text}");
    assert_eq!(text.matches("iteration,").count(), 1, "{text}");
    assert_eq!(debris(dir.path(), "fit.csv"), Vec::<String>::new());
}

/// A small tmpfs mounted for a test, unmounted when dropped.
struct SmallDisk {
    dir: tempfile::TempDir,
}

impl SmallDisk {
    fn mount() -> Result<SmallDisk, String> {
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        let o = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=256k", "tmpfs"])
            .arg(dir.path())
            .output()
            .map_err(|e| format!("mount: {e}"))?;
        if !o.status.success() {
            return Err(format!(
                "mount: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ));
        }
        Ok(SmallDisk { dir })
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).status();
    }
}

#[test]
fn a_full_disk_during_synth_says_disk_full_and_leaves_no_folder() {
    let disk = match SmallDisk::mount() {
        Ok(disk) => disk,
        Err(why) => {
            eprintln!("skipped: cannot mount a small tmpfs here ({why})");
            return;
        }
    };
    let set = disk.dir.path().join("set");
    let o = kinergy(&["synth", "-o", set.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("disk full"), "{err}");
    assert!(!err.contains("invalid"), "{err}");
    assert!(!set.exists(), "synth left its folder behind");
    assert_eq!(std::fs::read_dir(disk.dir.path()).unwrap().count(), 0);

    // Into a folder that was there: what was there stays, what synth wrote goes.
    std::fs::create_dir(&set).unwrap();
    std::fs::write(set.join("mine.txt"), "keep me").unwrap();
    let o = kinergy(&["synth", "-o", set.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let left: Vec<_> = std::fs::read_dir(&set).unwrap().collect();
    assert_eq!(left.len(), 1);
    assert_eq!(
        std::fs::read_to_string(set.join("mine.txt")).unwrap(),
        "keep me"
    );
}

/// A file inside an output folder is an output like `-o FILE`: every
/// command that writes into a folder refuses, before any work, a run whose files would
/// replace one of its inputs — a segments file, a params file, a clip, a scene's mesh — and
/// the input is left as it was.
#[test]
fn a_file_an_output_folder_would_replace_is_refused_as_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("D");
    std::fs::create_dir(&d).unwrap();
    let clip = d.join("p01").join("r01.bvh");
    std::fs::create_dir(d.join("p01")).unwrap();
    std::fs::copy(common::synthetic("r01.bvh"), &clip).unwrap();
    std::fs::copy(common::synthetic("r02.bvh"), d.join("p01/r02.bvh")).unwrap();
    let c = |p: &Path| p.to_str().unwrap().to_string();
    let segments = |name: &str| {
        let path = d.join(name);
        let o = kinergy(&["segment", &c(&clip), "--manifest", &c(&path)]);
        assert!(o.status.success(), "{}", stderr(&o));
        path
    };
    let copy = |from: &Path, name: &str| {
        let path = d.join(name);
        std::fs::copy(from, &path).unwrap();
        path
    };
    let shelf = dir.path().join("shelf");
    std::fs::create_dir(&shelf).unwrap();
    for name in ["scene.json", "shelf.obj"] {
        std::fs::copy(
            repo().join("examples/bookshelf").join(name),
            shelf.join(name),
        )
        .unwrap();
    }
    let people = repo().join("data-synthetic/manifest.csv");
    let sa = ["--model", "sa", "--budget", "50"];
    // Each case runs as soon as it is set up (two write files of one name).
    let check = |case: &str, input: PathBuf, args: Vec<String>| {
        let before = std::fs::read(&input).unwrap();
        refused(case, &args, "is one of the inputs");
        assert_eq!(
            std::fs::read(&input).unwrap(),
            before,
            "{case}: input replaced"
        );
    };
    for name in ["results.csv", "summary.md"] {
        let s = segments(name);
        let args = [
            "compare",
            "--segments",
            &c(&s),
            "--models",
            "sa",
            "-o",
            &c(&d),
        ];
        check(&format!("compare {name}"), s.clone(), strings(&args));
    }
    {
        let s = segments("holdout.csv");
        let args = [
            "compare",
            "--segments",
            &c(&s),
            "--per",
            "person",
            "--holdout",
            "1",
        ];
        let mut args = strings(&args);
        args.extend(strings(&["-o", &c(&d)]));
        check("compare --holdout holdout.csv", s.clone(), args);
    }
    {
        let f = copy(&clip, "fig3.svg");
        let args = ["compare", &c(&f), "--models", "sa", "-o", &c(&d)];
        check(
            "compare with a clip named fig3.svg",
            f.clone(),
            strings(&args),
        );
    }
    {
        let p = copy(&people, "summary.md");
        let args = ["style", &c(&clip), "--params", &c(&p), "-o", &c(&d)];
        check("style --params summary.md", p.clone(), strings(&args));
    }
    for name in ["manifest.csv", "segments.csv"] {
        let p = copy(&people, name);
        let args = ["synth", "--params", &c(&p), "-o", &c(&d)];
        check(&format!("synth --params {name}"), p.clone(), strings(&args));
    }
    {
        // Params named like one of the set's clips, p01/r03.bvh.
        let p = copy(&people, "p01/r03.bvh");
        let args = ["synth", "--params", &c(&p), "--persons", "1", "-o", &c(&d)];
        check("synth --params p01/r03.bvh", p.clone(), strings(&args));
    }
    {
        let s = segments("r01.bvh.json");
        let mut args = strings(&["fit", "--segments", &c(&s), "--per", "clip"]);
        args.extend(strings(&["--out-dir", &c(&d)]));
        args.extend(strings(&sa));
        check("fit --segments r01.bvh.json --out-dir", s.clone(), args);
    }
    {
        // A capture named like another capture's result: r09.bvh's is r09.bvh.json.
        let take = copy(&clip, "r09.bvh");
        let f = copy(&clip, "r09.bvh.json");
        let mut args = strings(&["fit", &c(&take), &c(&f), "--per", "clip"]);
        args.extend(strings(&["--out-dir", &c(&d)]));
        args.extend(strings(&sa));
        check(
            "fit a capture named r09.bvh.json --out-dir",
            f.clone(),
            args,
        );
    }
    {
        let mesh = shelf.join("shelf.obj");
        let scene = c(&shelf.join("scene.json"));
        let args = [
            "plan",
            "--scene",
            &scene,
            "--task",
            "grasp",
            "--object",
            "blue_book",
        ];
        let mut args = strings(&args);
        args.extend(strings(&["-o", &c(&mesh)]));
        check("plan -o the scene's mesh", mesh, args);
    }
    {
        let s = segments("both.csv");
        let other = d.join("p01/r02.bvh");
        let text = std::fs::read_to_string(&s).unwrap();
        let row = text
            .lines()
            .last()
            .unwrap()
            .replacen("r01.bvh", "r02.bvh", 1);
        std::fs::write(&s, format!("{text}{row}\n")).unwrap();
        let mut args = strings(&["fit", &c(&clip), "--segments", &c(&s), "-o", &c(&other)]);
        args.extend(strings(&sa));
        check("fit CLIP --segments S -o a clip S names", other, args);
    }
}
