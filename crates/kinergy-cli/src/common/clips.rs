//! Clip paths from the command line: files as given, folders expanded
//! ([`kinergy_train::source::capture_files`]).

use std::path::PathBuf;

use super::failure::Failure;

/// The BVH files named: files as given, folders expanded to the `*.bvh` files in them and
/// in their subfolders (sorted by path). An empty result, a missing path or one that is
/// neither a file nor a folder (a device, a FIFO) is bad input.
pub fn collect_clips(paths: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    kinergy_train::source::capture_files(paths).map_err(Failure::from)
}
