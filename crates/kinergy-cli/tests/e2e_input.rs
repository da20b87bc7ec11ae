//! End-to-end tests of bad input and the terminal: each kind of bad input exiting 2 with a
//! message naming the problem and leaving nothing behind; every subcommand's help carrying an
//! example; no colour or progress bar when not on a terminal.

mod common;
mod e2e_support;
use e2e_support::*;

/// One bad invocation: what must be said, and what must not be written.
struct Case {
    what: &'static str,
    args: Vec<String>,
    /// Each must appear in the message.
    needles: Vec<String>,
    /// Must not exist afterwards.
    output: PathBuf,
}

// Each kind of bad input, on every subcommand it applies to: exit code 2, a message naming
// the problem, no output file, nothing at all left in the output folder.
#[test]
fn bad_input_exits_2_names_the_problem_and_leaves_nothing() {
    let set = synth_set();
    let inputs = set.dir.path().join("in");
    let out = set.dir.path().join("out");
    std::fs::create_dir(&inputs).expect("mkdir");
    std::fs::create_dir(&out).expect("mkdir");
    let good = set.clips[0].to_str().expect("utf-8").to_string();
    let put = |name: &str, bytes: &[u8]| {
        let p = inputs.join(name);
        std::fs::write(&p, bytes).expect("write");
        p.to_str().expect("utf-8").to_string()
    };

    // A clip with a word in place of a number on its second frame, and one cut in half.
    let source = std::fs::read_to_string(&set.clips[0]).expect("clip");
    let mut lines: Vec<String> = source.lines().map(String::from).collect();
    let frame_time = lines
        .iter()
        .position(|l| l.starts_with("Frame Time"))
        .expect("Frame Time");
    let garbled_line = frame_time + 3; // 1-based: the second frame
    let mut cells: Vec<&str> = lines[garbled_line - 1].split_whitespace().collect();
    cells[2] = "zz";
    lines[garbled_line - 1] = cells.join(" ");
    let garbled = put("garbled.bvh", (lines.join("\n") + "\n").as_bytes());
    let truncated = put("truncated.bvh", &source.as_bytes()[..source.len() / 2]);
    let missing = inputs
        .join("missing.bvh")
        .to_str()
        .expect("utf-8")
        .to_string();
    let missing_json = inputs
        .join("missing.json")
        .to_str()
        .expect("utf-8")
        .to_string();
    let not_json = put("not_json.json", b"{ \"format_version\": 1,\n  \"model\": ");
    let v99 = put(
        "v99.json",
        br#"{"format_version": 99, "model": "sa", "optimizer": {"kind": "svd", "rate": 4.0, "threshold": 0.01}, "dof_names": ["shoulder_swing_x", "shoulder_swing_y", "shoulder_twist", "elbow_flexion", "elbow_twist", "wrist_swing_x", "wrist_swing_y"], "bounds": {"gain": {"lower": -5, "upper": 5}, "slope": {"lower": 1, "upper": 10}, "offset": {"lower": 0, "upper": 20}}, "values": {"g": 1.0}}"#,
    );
    let bad_scene = put("scene.json", b"{\"format_version\": 1, \"objects\": [");
    let scene = repo()
        .join("examples/bookshelf/scene.json")
        .to_str()
        .expect("utf-8")
        .to_string();
    let inputs_before = listing(&inputs);

    let o_bvh = out.join("o.bvh");
    let o_json = out.join("p.json");
    let o_svg = out.join("speed.svg");
    let o_gif = out.join("ov.gif");
    let o_dir = out.join("cmp");
    let o_set = out.join("set");
    let chain = "Nope,Nada,Zip";
    let file_name = |p: &str| {
        Path::new(p)
            .file_name()
            .expect("name")
            .to_string_lossy()
            .into_owned()
    };
    let line = format!("line {garbled_line}");

    let mut cases: Vec<Case> = Vec::new();
    let mut add = |what: &'static str, args: &[&str], needles: &[&str], output: &Path| {
        cases.push(Case {
            what,
            args: args.iter().map(|s| s.to_string()).collect(),
            needles: needles.iter().map(|s| s.to_string()).collect(),
            output: output.to_path_buf(),
        });
    };
    let (b, j, s, g, d) = (
        utf8(&o_bvh),
        utf8(&o_json),
        utf8(&o_svg),
        utf8(&o_gif),
        utf8(&o_dir),
    );
    let (gb, tr, mi) = (garbled.as_str(), truncated.as_str(), missing.as_str());
    let (gn, tn) = (file_name(gb), file_name(tr));
    let (gn, tn) = (gn.as_str(), tn.as_str());
    let cmp = ["--budget", "40", "--no-baselines", "-o", d];

    // Missing files: the message gives the path.
    add("inspect missing", &["inspect", mi], &[mi], &o_bvh);
    add("convert missing", &["convert", mi, "-o", b], &[mi], &o_bvh);
    add("segment missing", &["segment", mi], &[mi], &o_bvh);
    add(
        "fit missing",
        &["fit", mi, "--model", "sa", "-o", j],
        &[mi],
        &o_json,
    );
    add(
        "synthesize missing",
        &["synthesize", "--from", mi, "-o", b],
        &[mi],
        &o_bvh,
    );
    add(
        "compare missing",
        &[&["compare", mi][..], &cmp].concat(),
        &[mi],
        &o_dir,
    );
    add(
        "plot missing",
        &["plot", "speed", mi, "-o", s],
        &[mi],
        &o_svg,
    );
    add("animate missing", &["animate", mi, "-o", g], &[mi], &o_gif);
    add(
        "reach --person missing",
        &["reach", "--target", "0.2,1,0.4", "--person", mi, "-o", b],
        &[mi],
        &o_bvh,
    );
    add(
        "plan --scene missing",
        &[
            "plan",
            "--scene",
            &missing_json,
            "--target",
            "-0.25,1.1,0.3",
            "-o",
            b,
        ],
        &[&missing_json],
        &o_bvh,
    );
    add(
        "synthesize --params missing",
        &[
            "synthesize",
            "--from",
            &good,
            "--params",
            &missing_json,
            "-o",
            b,
        ],
        &[&missing_json],
        &o_bvh,
    );

    // Malformed BVH: the message names the file and the line.
    add("inspect garbled", &["inspect", gb], &[gn, &line], &o_bvh);
    add("inspect truncated", &["inspect", tr], &[tn, "line"], &o_bvh);
    add(
        "convert garbled",
        &["convert", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "convert truncated",
        &["convert", tr, "-o", b],
        &[tn, "line"],
        &o_bvh,
    );
    add("segment garbled", &["segment", gb], &[gn, &line], &o_bvh);
    add(
        "fit garbled",
        &["fit", gb, "--model", "sa", "-o", j],
        &[gn, &line],
        &o_json,
    );
    add(
        "fit truncated",
        &["fit", tr, "--model", "sa", "-o", j],
        &[tn, "line"],
        &o_json,
    );
    add(
        "synthesize garbled",
        &["synthesize", "--from", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "compare garbled",
        &[&["compare", &good, gb][..], &cmp].concat(),
        &[gn, &line],
        &o_dir,
    );
    add(
        "plot garbled second",
        &["plot", "speed", &good, gb, "-o", s],
        &[gn, &line],
        &o_svg,
    );
    add(
        "animate garbled second",
        &["animate", &good, gb, "-o", g],
        &[gn, &line],
        &o_gif,
    );
    add(
        "animate truncated",
        &["animate", tr, "-o", g],
        &[tn, "line"],
        &o_gif,
    );
    add(
        "reach --person garbled",
        &["reach", "--target", "0.2,1,0.4", "--person", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "plan --scene not JSON",
        &[
            "plan",
            "--scene",
            &bad_scene,
            "--target",
            "-0.25,1.1,0.3",
            "-o",
            b,
        ],
        &["scene.json"],
        &o_bvh,
    );

    // Unknown joints: the message names the first unknown one.
    add(
        "inspect --chain",
        &["inspect", &good, "--chain", chain],
        &["Nope"],
        &o_bvh,
    );
    add(
        "segment --chain",
        &["segment", &good, "--chain", chain],
        &["Nope"],
        &o_bvh,
    );
    add(
        "fit --chain",
        &["fit", &good, "--model", "sa", "--chain", chain, "-o", j],
        &["Nope"],
        &o_json,
    );
    add(
        "synthesize --chain",
        &["synthesize", "--from", &good, "--chain", chain, "-o", b],
        &["Nope"],
        &o_bvh,
    );
    add(
        "compare --chain",
        &[&["compare", &good, "--chain", chain][..], &cmp].concat(),
        &["Nope"],
        &o_dir,
    );
    add(
        "plot --chain",
        &["plot", "speed", &good, "--chain", chain, "-o", s],
        &["Nope"],
        &o_svg,
    );

    // Bad parameters files: the message names the file (and the field for a wrong version).
    add(
        "synthesize --params wrong version",
        &["synthesize", "--from", &good, "--params", &v99, "-o", b],
        &["v99.json", "format_version"],
        &o_bvh,
    );
    add(
        "synthesize --params not JSON",
        &[
            "synthesize",
            "--from",
            &good,
            "--params",
            &not_json,
            "-o",
            b,
        ],
        &["not_json.json"],
        &o_bvh,
    );

    // Targets with NaN.
    add(
        "synthesize --target NaN",
        &[
            "synthesize",
            "--from",
            &good,
            "--target",
            "nan,1,0",
            "-o",
            b,
        ],
        &["--target", "nan"],
        &o_bvh,
    );
    add(
        "reach --target NaN",
        &["reach", "--target", "0,nan,0", "-o", b],
        &["--target", "nan"],
        &o_bvh,
    );
    add(
        "plan --target NaN",
        &["plan", "--scene", &scene, "--target", "nan,1,0.3", "-o", b],
        &["--target", "nan"],
        &o_bvh,
    );

    // Wrong output extensions for pictures.
    let jpg = out.join("speed.jpg");
    let bare = out.join("speed");
    let mp4 = out.join("ov.mp4");
    add(
        "plot -o .jpg",
        &["plot", "speed", &good, "-o", utf8(&jpg)],
        &["speed.jpg", ".svg or .png"],
        &jpg,
    );
    add(
        "plot -o without extension",
        &["plot", "speed", &good, "-o", utf8(&bare)],
        &[".svg or .png"],
        &bare,
    );
    add(
        "animate -o .mp4",
        &["animate", &good, "-o", utf8(&mp4)],
        &["ov.mp4", ".gif"],
        &mp4,
    );
    add(
        "animate --strip .jpg",
        &["animate", &good, "-o", g, "--strip", utf8(&jpg)],
        &["--strip", "speed.jpg"],
        &o_gif,
    );

    // synth's own settings.
    add(
        "synth --persons 0",
        &["synth", "-o", utf8(&o_set), "--persons", "0"],
        &["persons"],
        &o_set,
    );

    let mut problems = Vec::new();
    for case in &cases {
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let o = kinergy(&args);
        let err = stderr(&o);
        let what = case.what;
        if o.status.code() != Some(2) {
            problems.push(format!(
                "{what}: exit code {:?}, not 2: {err}",
                o.status.code()
            ));
        }
        for needle in &case.needles {
            if !err.contains(needle.as_str()) {
                problems.push(format!(
                    "{what}: the message does not name `{needle}`: {err}"
                ));
            }
        }
        if err.contains("panicked") {
            problems.push(format!("{what}: panicked: {err}"));
        }
        if !o.stdout.is_empty() {
            problems.push(format!("{what}: printed on stdout: {}", text(&o.stdout)));
        }
        if case.output.exists() {
            problems.push(format!("{what}: {} exists", case.output.display()));
        }
        let left = listing(&out);
        if !left.is_empty() {
            let temporary = left.iter().any(|n| n.contains(".tmp"));
            problems.push(format!(
                "{what}: left {left:?} in the output folder{}",
                if temporary { " (temporary files)" } else { "" }
            ));
            for name in left {
                let p = out.join(name);
                let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
            }
        }
        if listing(&inputs) != inputs_before {
            problems.push(format!(
                "{what}: the input folder changed: {:?}",
                listing(&inputs)
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "{} of {} bad inputs misbehaved:\n{}",
        problems.len(),
        cases.len(),
        problems.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// 3. Help and terminal behaviour
// ---------------------------------------------------------------------------------------------

/// The subcommands a `--help` output lists under `Commands:` (without `help`).
fn listed_commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(String::from)
        .collect()
}

/// Every leaf subcommand, as its words (`["plot", "speed"]`), found from the help output.
fn every_subcommand() -> Vec<Vec<String>> {
    let mut leaves = Vec::new();
    let mut stack = vec![Vec::<String>::new()];
    while let Some(path) = stack.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let children = listed_commands(&stdout(&o));
        if children.is_empty() {
            leaves.push(path);
        } else {
            for c in children {
                let mut p = path.clone();
                p.push(c);
                stack.push(p);
            }
        }
    }
    leaves.sort();
    leaves
}

// Every subcommand's help ends with an example of itself, in the short and the long help.
#[test]
fn every_subcommand_help_has_an_example() {
    let subcommands = every_subcommand();
    let names: BTreeSet<String> = subcommands.iter().map(|p| p.join(" ")).collect();
    for expected in [
        "inspect",
        "convert",
        "segment",
        "synth",
        "fit",
        "compare",
        "synthesize",
        "reach",
        "plan",
        "plot speed",
        "animate",
    ] {
        assert!(
            names.contains(expected),
            "`{expected}` not listed: {names:?}"
        );
    }
    let mut missing = Vec::new();
    let mut groups: Vec<Vec<String>> = subcommands
        .iter()
        .filter(|p| p.len() > 1)
        .map(|p| p[..p.len() - 1].to_vec())
        .collect();
    groups.dedup();
    for path in subcommands.iter().chain(&groups) {
        let command = format!("kinergy {}", path.join(" "));
        for flag in ["--help", "-h"] {
            let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
            args.push(flag);
            let o = kinergy(&args);
            let help = stdout(&o);
            let example = help
                .find("Example")
                .map(|at| &help[at..])
                .filter(|tail| tail.contains(&command));
            if o.status.code() != Some(0) || example.is_none() {
                missing.push(format!("{command} {flag}"));
            }
        }
    }
    assert!(missing.is_empty(), "no example of itself in: {missing:?}");
}

// With NO_COLOR set (even beside CLICOLOR_FORCE), neither help nor errors hold ANSI escapes.
#[test]
fn no_color_means_no_ansi_escapes_in_help_or_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("missing.bvh");
    let mut invocations: Vec<Vec<String>> = vec![vec!["--help".into()], vec![]];
    for path in every_subcommand() {
        let mut help = path.clone();
        help.push("--help".into());
        invocations.push(help);
        let mut short = path.clone();
        short.push("-h".into());
        invocations.push(short);
        // A usage error (clap's own message) for each.
        let mut wrong = path.clone();
        wrong.push("--no-such-flag".into());
        invocations.push(wrong);
    }
    let m = utf8(&missing).to_string();
    for args in [
        vec!["inspect", &m],
        vec!["fit", &m, "--model", "sa", "-o", "x.json"],
        vec!["plot", "speed", &m, "-o", "x.svg"],
        vec!["animate", &m, "-o", "x.gif"],
        vec!["reach", "--target", "0,nan,0", "-o", "x.bvh"],
        vec!["synth", "--persons", "many"],
        vec!["frobnicate"],
    ] {
        invocations.push(args.into_iter().map(String::from).collect());
    }
    let mut coloured = Vec::new();
    for env in [
        &[("NO_COLOR", "1")][..],
        &[
            ("NO_COLOR", "1"),
            ("CLICOLOR_FORCE", "1"),
            ("TERM", "xterm-256color"),
        ][..],
    ] {
        for args in &invocations {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = kinergy_env(&args, env, &["CLICOLOR_FORCE"]);
            for (stream, bytes) in [("stdout", &o.stdout), ("stderr", &o.stderr)] {
                if text(bytes).contains("\x1b[") {
                    coloured.push(format!("{env:?} kinergy {}: {stream}", args.join(" ")));
                }
            }
        }
    }
    assert!(coloured.is_empty(), "ANSI escapes in: {coloured:#?}");
    // The invocations above touch nothing: no x.json etc. in the working directory.
    for name in ["x.json", "x.svg", "x.gif", "x.bvh"] {
        assert!(!Path::new(env!("CARGO_MANIFEST_DIR")).join(name).exists());
    }
}

// stderr is not a terminal here: a fit (and a compare) long enough to draw a progress bar
// leaves no bar, carriage return or escape on it, even with a colour terminal's TERM.
#[test]
fn progress_bars_stay_off_stderr_when_it_is_not_a_terminal() {
    let set = synth_set();
    let params = set.dir.path().join("p.json");
    let env = [("TERM", "xterm-256color")];
    let unset = ["NO_COLOR", "CLICOLOR_FORCE", "CLICOLOR"];
    let o = kinergy_env(
        &[
            "fit",
            utf8(&set.root),
            "--model",
            "sc",
            "--budget",
            "200",
            "-o",
            utf8(&params),
        ],
        &env,
        &unset,
    );
    succeed(&o, "fit");
    assert!(params.exists());
    let said = stdout(&o);
    assert!(!said.contains("\x1b[") && !said.contains('\r'), "{said:?}");
    let out = set.dir.path().join("cmp");
    let o = kinergy_env(
        &[
            "compare",
            utf8(&set.clips[0]),
            "--budget",
            "30",
            "--no-baselines",
            "--optimizers",
            "svd",
            "-o",
            utf8(&out),
        ],
        &env,
        &unset,
    );
    succeed(&o, "compare");
}
