//! Every kind of BVH file Kinergy writes, imported by Blender's own importer
//! (`io_anim_bvh`, headless), puts every bone's head where Kinergy's forward kinematics of the
//! same file puts its joint, on every frame, to 1e-3 of the file's unit (see [`TOLERANCE`]).
//!
//! The files: `convert` of the shared captures (`../shared/data/`: `real-bvh/`, `formats/`,
//! two of `bandai-raise-left/`, cut to 20 frames), `convert --up-out y` of a Z-up file,
//! `synthesize` on a Bandai and a Character Creator capture, `reach` (one overhead, its
//! clavicle turned by the girdle), `plan --task relocate`
//! (the character with fingers), `plan --target` low between the shelves (the planner moves the
//! root, spine and legs) and `synth`. Blender is launched once for all of them
//! (`tests/blender/import_bvh.py`). Skipped, saying so, where `blender` is not on PATH.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{kinergy, repo, stderr};

/// Bone heads further from Kinergy's joints than this (file units) fail the test — unless Blender's own two readings of the file (native Euler and quaternion
/// rotations) already differ by more than a quarter of it: Blender evaluates poses in single
/// precision, and on Character Creator's 100-joint rig (centimeters) its two readings differ
/// by 1.7e-4 cm and its toes land up to 4.9e-4 cm from the exact (f64) joints. Such a file is
/// held to [`NOISE_FACTOR`] × Blender's own disagreement instead. A misread file (an OFFSET
/// added instead of replaced, a missing or misordered channel) is off by millimetres or more.
const TOLERANCE: f64 = 1e-4;

/// How many times Blender's own disagreement between its two readings of a file the bone
/// heads may lie from Kinergy's joints, where that is more than [`TOLERANCE`].
const NOISE_FACTOR: f64 = 4.0;

/// `blender` on PATH, if there is one.
fn blender() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("blender"))
        .find(|p| p.is_file())
}

fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs `kinergy args`, which must succeed.
fn run(args: &[&str]) {
    let o = kinergy(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
}

/// Runs `kinergy args`, which must write `out`: a motion ending short of its target (exit 1)
/// is still a file Kinergy writes.
fn run_writing(args: &[&str], out: &Path) {
    let o = kinergy(args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)) && out.is_file(),
        "{args:?}: {:?} {}",
        o.status.code(),
        stderr(&o)
    );
}

/// The `.bvh` files of `folder`, sorted; `None` (said on stderr) when it is absent.
fn bvh_files(folder: &Path) -> Option<Vec<PathBuf>> {
    let Ok(entries) = std::fs::read_dir(folder) else {
        common::require_shared::shared_absent(&format!(
            "blender test: {} is absent, skipped",
            folder.display()
        ));
        return None;
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    Some(files)
}

/// `kinergy convert` of `input` to `out`, cut to its first 20 frames.
fn convert(input: &Path, out: &Path, extra: &[&str]) {
    let bvh = kinergy_bvh::read_file(input, &Default::default()).expect("read the capture");
    let frames = format!("0..{}", bvh.frame_count.min(20));
    let mut args = vec!["convert", utf8(input), "-o", utf8(out), "--frames", &frames];
    args.extend(extra);
    run(&args);
}

/// Every kind of file Kinergy writes, in `dir`: (what made it, the file).
/// `kinergy from-positions` on `input`'s world positions (Kinergy's FK, as a long CSV), the
/// hierarchy from `input` itself: the BVH a position table becomes.
fn from_positions(input: &Path, out: &Path, extra: &[&str]) {
    use std::fmt::Write as _;
    let (clip, _) = kinergy_motion::read_clip(input, &Default::default()).expect("read");
    let names: Vec<String> = clip
        .skeleton()
        .joints()
        .iter()
        .map(|j| j.name.clone())
        .collect();
    let world = clip.world_positions().expect("fk");
    let mut csv = String::from("frame,joint,x,y,z\n");
    for (k, p) in world.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{},{},{},{},{}",
            k / names.len(),
            names[k % names.len()],
            p.x,
            p.y,
            p.z
        );
    }
    let table = out.with_extension("csv");
    std::fs::write(&table, csv).expect("write the table");
    let rate = format!("{}", 1.0 / clip.frame_time());
    let mut args = vec![
        "from-positions",
        utf8(&table),
        "--skeleton",
        utf8(input),
        "--frame-rate",
        &rate,
        "-o",
        utf8(out),
    ];
    args.extend(extra);
    run_writing(&args, out);
}

fn make_files(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut files = Vec::new();
    let shared = repo().join("../shared/data");
    let mut bandai = None;
    for (folder, take) in [
        ("real-bvh", usize::MAX),
        ("formats", usize::MAX),
        ("bandai-raise-left", 2),
    ] {
        let Some(inputs) = bvh_files(&shared.join(folder)) else {
            continue;
        };
        for input in inputs.into_iter().take(take) {
            let stem = input.file_stem().and_then(|s| s.to_str()).expect("name");
            let out = dir.join(format!("convert-{folder}-{stem}.bvh"));
            convert(&input, &out, &[]);
            files.push((format!("convert {folder}/{stem}"), out));
            if stem.contains("zup") {
                let out = dir.join(format!("convert-y-{stem}.bvh"));
                convert(&input, &out, &["--up-out", "y"]);
                files.push((format!("convert --up-out y {folder}/{stem}"), out));
            }
            let out = dir.join(format!("positions-{folder}-{stem}.bvh"));
            if folder != "bandai-raise-left" {
                from_positions(&input, &out, &[]);
                files.push((format!("from-positions {folder}/{stem}"), out));
            } else {
                // The Bandai takes' hips move away from their reference root: that bone kept
                // in position channels, every joint where the capture has it.
                from_positions(&input, &out, &["--stretch", "keep"]);
                files.push((
                    format!("from-positions --stretch keep {folder}/{stem}"),
                    out,
                ));
            }
            if folder == "real-bvh" && stem.starts_with("dataset-1") && bandai.is_none() {
                bandai = Some(input.clone());
            }
        }
    }

    let cc = repo().join("tests/data/006_14.bvh");
    let out = dir.join("positions-006_14.bvh");
    from_positions(&cc, &out, &[]);
    files.push(("from-positions tests/data/006_14".into(), out));
    // `kinergy retarget` between the committed rigs and onto every shared rig (each output
    // imported with Kinergy's joint positions, like every other file here).
    let walk = repo().join("tests/data/cmu_12_01_walk.bvh");
    let mut templates = vec![("cmu", walk.clone()), ("character-creator", cc.clone())];
    for (folder, stem) in [
        ("formats", "mixamo_walk"),
        ("formats", "zup_mixed_orders"),
        ("real-bvh", "dataset-1_bye_normal_001"),
    ] {
        let path = shared.join(folder).join(format!("{stem}.bvh"));
        if path.exists() {
            templates.push((stem, path));
        }
    }
    for (name, template) in &templates {
        let input = if *name == "cmu" { &cc } else { &walk };
        let out = dir.join(format!("retarget-{name}.bvh"));
        run_writing(
            &[
                "retarget",
                utf8(input),
                "--to",
                utf8(template),
                "-o",
                utf8(&out),
            ],
            &out,
        );
        files.push((format!("retarget onto {name}"), out));
    }
    // With the performer's arms: the template's hierarchy, its arm bones' offsets rescaled.
    let out = dir.join("retarget-character-creator-source-arms.bvh");
    run_writing(
        &[
            "retarget",
            utf8(&walk),
            "--to",
            utf8(&cc),
            "--arms",
            "source",
            "-o",
            utf8(&out),
        ],
        &out,
    );
    files.push(("retarget onto character-creator --arms source".into(), out));
    let mut captures = vec![("character-creator", cc)];
    match bandai {
        Some(b) => captures.push(("bandai", b)),
        None => common::require_shared::shared_absent(
            "blender test: no Bandai capture in ../shared/data/real-bvh, skipped",
        ),
    }
    for (name, input) in captures {
        let out = dir.join(format!("synthesize-{name}.bvh"));
        run_writing(
            &[
                "synthesize",
                "--from",
                utf8(&input),
                "--target",
                "0.35,1.2,0.2",
                "--stop-at-reach",
                "-o",
                utf8(&out),
            ],
            &out,
        );
        files.push((format!("synthesize {name}"), out));
    }

    let out = dir.join("reach.bvh");
    run(&["reach", "--target", "0.2,1.0,0.4", "-o", utf8(&out)]);
    files.push(("reach".into(), out));
    // Overhead: the shoulder girdle turns the left clavicle joint (up to ~10° on its
    // rotation channels), so the import follows a rotating clavicle too.
    let out = dir.join("reach-overhead.bvh");
    run(&["reach", "--target", "0.25,1.85,0.2", "-o", utf8(&out)]);
    files.push(("reach overhead".into(), out));

    let out = dir.join("plan.bvh");
    let scene = repo().join("examples/bookshelf/scene.json");
    run(&[
        "plan",
        "--scene",
        utf8(&scene),
        "--task",
        "relocate",
        "--object",
        "blue_book",
        "--to",
        "-0.22,1.49,0.50",
        "--seed",
        "3",
        "-o",
        utf8(&out),
    ]);
    files.push(("plan --task relocate (fingers)".into(), out));
    // A plan that moves the body (issue 43, item 5): the planner bends, twists and squats to a
    // low target between the shelves, so the root translates and the spine and knees turn.
    let out = dir.join("plan-body.bvh");
    run(&[
        "plan",
        "--scene",
        utf8(&scene),
        "--target=-0.25,0.45,0.4",
        "-o",
        utf8(&out),
    ]);
    files.push(("plan --target low (the body moves)".into(), out));

    let synth = dir.join("synth");
    run(&[
        "synth",
        "-o",
        utf8(&synth),
        "--persons",
        "1",
        "--reaches",
        "1",
        "--seed",
        "5",
    ]);
    let person = bvh_files(&synth.join("p01")).expect("synth wrote p01/");
    files.push(("synth".into(), person[0].clone()));
    files
}

/// What the script wrote for one file: bone names and heads (file units, file axes), from the
/// native and the quaternion import.
struct Imported {
    bones: Vec<String>,
    frames: Vec<Vec<[f64; 3]>>,
    frames_quaternion: Vec<Vec<[f64; 3]>>,
}

impl Imported {
    /// The largest distance between a bone head of the native and of the quaternion import.
    fn own_noise(&self) -> f64 {
        self.frames
            .iter()
            .zip(&self.frames_quaternion)
            .flat_map(|(a, b)| a.iter().zip(b))
            .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    }
}

fn imported(path: &Path) -> Imported {
    let text = std::fs::read_to_string(path).expect("the script's output");
    let v: serde_json::Value = serde_json::from_str(&text).expect("json");
    let bones = v["bones"]
        .as_array()
        .expect("bones")
        .iter()
        .map(|b| b.as_str().expect("name").to_owned())
        .collect();
    let point = |p: &serde_json::Value| -> [f64; 3] {
        [0, 1, 2].map(|k| p[k].as_f64().expect("coordinate"))
    };
    let frames = |key: &str| -> Vec<Vec<[f64; 3]>> {
        v[key]
            .as_array()
            .expect("frames")
            .iter()
            .map(|f| f.as_array().expect("frame").iter().map(point).collect())
            .collect()
    };
    Imported {
        bones,
        frames: frames("frames"),
        frames_quaternion: frames("frames_quaternion"),
    }
}

/// The largest distance between a bone head and its joint, and where.
#[derive(Debug, Default)]
struct Worst {
    /// File units.
    distance: f64,
    at: String,
}

/// The largest distance (file units) between Blender's bone heads and Kinergy's joints.
fn deviation(kind: &str, file: &Path, blender: &Imported) -> Worst {
    // As Kinergy reads what it wrote: every choice automatic (unit, up axis, positions).
    let (clip, report) = kinergy_motion::read_clip(file, &Default::default()).expect("read");
    let s = clip.skeleton();
    let to_file = s.world_from_file().inverse();
    let per_meter = 1.0 / report.unit.meters();
    let joints: Vec<usize> = (0..s.joint_count())
        .filter(|&j| !s.joint(j).end_site)
        .collect();
    assert_eq!(
        blender.bones.len(),
        joints.len(),
        "{kind}: Blender made {} bones of {} joints",
        blender.bones.len(),
        joints.len()
    );
    let index: Vec<usize> = blender
        .bones
        .iter()
        .map(|b| {
            s.joint_index(b)
                .unwrap_or_else(|| panic!("{kind}: Blender's bone `{b}` is no joint"))
        })
        .collect();
    assert_eq!(blender.frames.len(), clip.frame_count(), "{kind}: frames");
    let mut worst = Worst::default();
    for (f, heads) in blender.frames.iter().enumerate() {
        let p = s
            .world_positions(clip.frame(f).expect("frame"))
            .expect("fk");
        for (&j, head) in index.iter().zip(heads) {
            let ours = to_file * p[j].coords * per_meter;
            let theirs = nalgebra::Vector3::from(*head);
            let d = (ours - theirs).norm();
            if d > worst.distance {
                worst = Worst {
                    distance: d,
                    at: format!(
                        "frame {f}, `{}`: Kinergy {:?}, Blender {:?}",
                        s.joint(j).name,
                        ours.as_slice(),
                        theirs.as_slice()
                    ),
                };
            }
        }
    }
    worst
}

#[test]
fn blender_imports_every_file_kinergy_writes_with_kinergys_joint_positions() {
    let Some(blender) = blender() else {
        eprintln!("blender test: skipped, `blender` is not on PATH");
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let files = make_files(dir.path());
    let script = repo().join("crates/kinergy-cli/tests/blender/import_bvh.py");
    let outs: Vec<PathBuf> = (0..files.len())
        .map(|k| dir.path().join(format!("blender-{k}.json")))
        .collect();
    let mut cmd = Command::new(&blender);
    cmd.args(["-b", "--factory-startup", "--python", utf8(&script), "--"]);
    for ((_, file), out) in files.iter().zip(&outs) {
        cmd.args([utf8(file), utf8(out)]);
    }
    let o = cmd.output().expect("run blender");
    let log = format!("{}{}", common::text(&o.stdout), stderr(&o));
    assert!(o.status.success(), "blender failed:\n{log}");
    let mut failed = Vec::new();
    for ((kind, file), out) in files.iter().zip(&outs) {
        assert!(out.is_file(), "{kind}: Blender wrote nothing:\n{log}");
        let blender = imported(out);
        let worst = deviation(kind, file, &blender);
        let noise = blender.own_noise();
        let allowed = TOLERANCE.max(NOISE_FACTOR * noise);
        eprintln!(
            "blender test: {kind}: bone heads within {:.2e} of the file's unit \
             (Blender's own two readings differ by {noise:.2e}; allowed {allowed:.1e})",
            worst.distance
        );
        if worst.distance > allowed {
            failed.push(format!(
                "{kind}: {:.3e} (allowed {allowed:.1e}) at {}",
                worst.distance, worst.at
            ));
        }
    }
    assert!(
        failed.is_empty(),
        "bone heads further than allowed from Kinergy's joints:\n{}",
        failed.join("\n")
    );
}
