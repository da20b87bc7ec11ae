//! Traps a new user fell into (issue 14, §3), each as it was met: the exit code, the
//! message, the inputs untouched and nothing left behind.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_bad_input, fixture, kinergy, stderr};

/// `count` copies of the test capture as `p1/r.bvh`, `p2/r.bvh`, … under `dir`.
fn same_named_clips(dir: &Path, count: usize) -> Vec<PathBuf> {
    (1..=count)
        .map(|i| {
            let folder = dir.join(format!("p{i}"));
            std::fs::create_dir_all(&folder).unwrap();
            let clip = folder.join("r.bvh");
            std::fs::copy(fixture("006_14.bvh"), &clip).unwrap();
            clip
        })
        .collect()
}

#[test]
fn fit_per_clip_keeps_every_result_of_clips_with_one_name() {
    let dir = tempfile::tempdir().unwrap();
    let clips = same_named_clips(dir.path(), 2);
    let before: Vec<Vec<u8>> = clips.iter().map(|c| std::fs::read(c).unwrap()).collect();
    let out = dir.path().join("fits");
    let out_arg = format!("{}/", out.display());
    let o = kinergy(&[
        "fit",
        clips[0].to_str().unwrap(),
        clips[1].to_str().unwrap(),
        "--model",
        "sa",
        "--per",
        "clip",
        "--budget",
        "20",
        "-o",
        &out_arg,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for p in ["p1/r.json", "p2/r.json"] {
        assert!(out.join(p).is_file(), "no {p}");
    }
    let after: Vec<Vec<u8>> = clips.iter().map(|c| std::fs::read(c).unwrap()).collect();
    assert_eq!(before, after);
}

#[test]
fn fit_per_clip_with_out_dir_names_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let clips = same_named_clips(dir.path(), 2);
    let out = dir.path().join("fits");
    let o = kinergy(&[
        "fit",
        dir.path().to_str().unwrap(),
        "--model",
        "sa",
        "--per",
        "clip",
        "--budget",
        "20",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.join("p1/r.json").is_file() && out.join("p2/r.json").is_file());
    assert_eq!(clips.len(), 2);
}

#[test]
fn fit_per_clip_onto_one_file_asks_for_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let clips = same_named_clips(dir.path(), 2);
    let out = dir.path().join("x.json");
    assert_bad_input(
        &[
            "fit",
            clips[0].to_str().unwrap(),
            clips[1].to_str().unwrap(),
            "--model",
            "sa",
            "--per",
            "clip",
            "--budget",
            "20",
            "-o",
            out.to_str().unwrap(),
        ],
        "trailing slash",
        &out,
    );
    assert!(!dir.path().join("x").exists());
}
