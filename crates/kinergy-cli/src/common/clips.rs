//! Clip paths from the command line: files as given, folders expanded
//! ([`kinergy_train::source::walk_captures`]).

use std::path::PathBuf;

use super::failure::Failure;

/// How many links not followed stderr names.
const REPEATS_SHOWN: usize = 5;

/// The BVH files named: files as given, folders expanded to the `*.bvh` files in them and
/// in their subfolders (sorted by path), each folder and file once however many links lead
/// to it (the links not followed are said on stderr). An empty result, a missing path or one
/// that is neither a file nor a folder (a device, a FIFO) is bad input.
pub fn collect_clips(paths: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let walk = kinergy_train::source::walk_captures(paths).map_err(Failure::from)?;
    if !walk.repeats.is_empty() {
        eprintln!(
            "note: {} link{} to folders or files already taken, not followed:",
            walk.repeats.len(),
            if walk.repeats.len() == 1 { "" } else { "s" }
        );
        for repeat in walk.repeats.iter().take(REPEATS_SHOWN) {
            eprintln!("  {repeat}");
        }
        if walk.repeats.len() > REPEATS_SHOWN {
            eprintln!("  … and {} more", walk.repeats.len() - REPEATS_SHOWN);
        }
    }
    Ok(walk.files)
}
