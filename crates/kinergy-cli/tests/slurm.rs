//! A library fitted on a real Slurm cluster: the example array script over the
//! synthetic set's first person in 3 tasks, then `collect`, gives what one machine gives.
//!
//! Needs a running cluster (`sinfo` answering with an idle node): CI installs Debian's
//! `slurm-wlm` and `munge` and starts a one-node cluster with `tools/slurm-up.sh`; run as
//! root, this test starts one itself. Where there is none it skips, saying so — unless
//! `KINERGY_REQUIRE_SLURM=1` (set in `.ci/run`), which turns the skip into a failure.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::{kinergy, repo, s, stderr};

/// Whether `sinfo` shows a node that takes jobs, within a few seconds.
fn cluster_up() -> bool {
    Command::new("timeout")
        .args(["5", "sinfo", "-h", "-o", "%t"])
        .output()
        .is_ok_and(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .any(|l| matches!(l.trim().trim_end_matches('*'), "idle" | "mix" | "alloc"))
        })
}

/// A cluster to submit to: the running one, or (as root) one started by
/// `tools/slurm-up.sh`; `None`, saying why, where there is none.
fn cluster() -> Option<()> {
    if cluster_up() {
        return Some(());
    }
    let up = Command::new(repo().join("tools/slurm-up.sh")).output();
    if cluster_up() {
        return Some(());
    }
    let why = match up {
        Ok(o) => String::from_utf8_lossy(&o.stderr).trim().to_string(),
        Err(e) => e.to_string(),
    };
    let message = format!("skipping: no Slurm cluster here ({why})");
    let required =
        std::env::var_os("KINERGY_REQUIRE_SLURM").is_some_and(|v| !v.is_empty() && v != "0");
    assert!(
        !required,
        "{message}\nKINERGY_REQUIRE_SLURM is set: the Slurm test must run (start a cluster \
         with tools/slurm-up.sh as root)"
    );
    eprintln!("{message}");
    None
}

/// The result files of a library folder, by name, with their bytes.
fn results(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(dir).expect("folder").flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|x| x == "json") {
            out.insert(path.clone(), std::fs::read(&path).expect("result"));
        }
    }
    out.into_iter()
        .map(|(p, b)| (p.strip_prefix(dir).expect("inside").to_path_buf(), b))
        .collect()
}

/// `library.csv` without the seconds column.
fn table(dir: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(dir.join("library.csv")).expect("library.csv");
    let header = reader.headers().expect("header").clone();
    let seconds = header.iter().position(|h| h == "seconds").expect("seconds");
    reader
        .records()
        .map(|r| {
            let r = r.expect("row");
            r.iter()
                .enumerate()
                .filter(|(i, _)| *i != seconds)
                .map(|(_, v)| v.to_string())
                .collect()
        })
        .collect()
}

#[test]
fn a_library_fitted_as_a_slurm_array_is_the_one_machine_library() {
    if cluster().is_none() {
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let takes = repo().join("data-synthetic/p01");
    let fit = ["--model", "sb", "--budget", "60"];
    let one = dir.path().join("one");
    let mut args = vec![
        "fit",
        s(&takes),
        "--per",
        "clip",
        "-q",
        "--out-dir",
        s(&one),
    ];
    args.extend(fit);
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let shards = dir.path().join("shards");
    let script = repo().join("examples/slurm/fit-library.sbatch");
    let mut sbatch = Command::new("timeout");
    sbatch
        .args(["600", "sbatch", "--wait", "--array=1-3", "--chdir"])
        .arg(dir.path())
        .arg(&script)
        .arg(&takes)
        .arg(&shards)
        .args(fit)
        .env("KINERGY", env!("CARGO_BIN_EXE_kinergy"));
    let o = sbatch.output().expect("sbatch");
    assert!(
        o.status.success(),
        "sbatch: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    // Three tasks, three records.
    for i in 1..=3 {
        let record = shards.join(format!("shards/{i}-of-3.csv"));
        assert!(record.is_file(), "{record:?}");
    }
    let o = kinergy(&["collect", s(&shards)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (a, b) = (results(&one), results(&shards));
    assert_eq!(a.len(), 14);
    assert_eq!(
        a, b,
        "a result differs between one machine and the Slurm array"
    );
    assert_eq!(table(&one), table(&shards));
}
