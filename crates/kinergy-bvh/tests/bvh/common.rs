//! Locating the fixtures.

use std::path::{Path, PathBuf};

use kinergy_bvh::{Bvh, ReadOptions};

/// The committed real files (always present).
pub const COMMITTED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");
/// The shared real files (absent in some checkouts).
pub const SHARED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/real-bvh");
/// The hand-written quirk fixtures.
pub const QUIRKS_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/bvh-quirks");

pub const COMMITTED_FILES: [&str; 2] = ["cmu_12_01_walk.bvh", "006_14.bvh"];
pub const SHARED_FILES: [&str; 4] = [
    "dataset-1_guide_normal_001.bvh",
    "dataset-1_bye_normal_001.bvh",
    "006_14.bvh",
    "cmu_12_01_walk.bvh",
];

/// The shared folder, or `None` after saying that it is absent.
pub fn shared_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(SHARED_DIR);
    if dir.is_dir() {
        Some(dir)
    } else {
        crate::require_shared::shared_absent(&format!(
            "note: {} is absent; the shared real-BVH files are not tested",
            dir.display()
        ));
        None
    }
}

/// Every real file available: the committed ones, then the shared ones if present.
pub fn real_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = COMMITTED_FILES
        .iter()
        .map(|f| Path::new(COMMITTED_DIR).join(f))
        .collect();
    if let Some(dir) = shared_dir() {
        files.extend(SHARED_FILES.iter().map(|f| dir.join(f)));
    }
    files
}

pub fn read(path: &Path) -> Bvh {
    kinergy_bvh::read_file(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

pub fn quirk(name: &str) -> PathBuf {
    Path::new(QUIRKS_DIR).join(name)
}

/// `text` cut to its hierarchy and first `frames` frames, with the header's count fixed,
/// so mutation tests parse a few kilobytes instead of hundreds.
pub fn trimmed(text: &str, frames: usize) -> String {
    let mut out = String::new();
    let mut lines = text.split_inclusive('\n');
    for line in lines.by_ref() {
        let trimmed = line.trim_start();
        if trimmed.to_ascii_lowercase().starts_with("frames") {
            out.push_str(&format!("Frames: {frames}\n"));
            break;
        }
        out.push_str(line);
    }
    for line in lines.by_ref() {
        out.push_str(line);
        if line
            .trim_start()
            .to_ascii_lowercase()
            .starts_with("frame time")
        {
            break;
        }
    }
    for line in lines.take(frames) {
        out.push_str(line);
    }
    out
}
