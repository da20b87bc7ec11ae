//! Clip paths from the command line: files as given, folders expanded.

use std::path::{Path, PathBuf};

use super::Failure;

/// The BVH files named: files as given, folders expanded to the `*.bvh` files in them and
/// in their subfolders (sorted by path). An empty result, a missing path or one that is
/// neither a file nor a folder (a device, a FIFO) is bad input.
pub fn collect_clips(paths: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found = Vec::new();
            walk(p, &mut found)?;
            found.sort();
            if found.is_empty() {
                return Err(Failure::Input(format!(
                    "{}: no .bvh files in this folder",
                    p.display()
                )));
            }
            out.extend(found);
        } else if p.is_file() {
            out.push(p.clone());
        } else if let Ok(metadata) = std::fs::metadata(p) {
            // A device or FIFO: say what it is (reading it could block or never end).
            return Err(Failure::Input(format!(
                "{}: not a regular file ({})",
                p.display(),
                kinergy_io::describe_file_type(&metadata)
            )));
        } else {
            return Err(Failure::Input(format!(
                "{}: no such file or folder",
                p.display()
            )));
        }
    }
    if out.is_empty() {
        return Err(Failure::Input("no clips given".into()));
    }
    Ok(out)
}

/// Every `*.bvh` file under `dir`.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), Failure> {
    let entries = std::fs::read_dir(dir).map_err(|e| Failure::input(dir, e))?;
    for entry in entries {
        let path = entry.map_err(|e| Failure::input(dir, e))?.path();
        if path.is_dir() {
            walk(&path, out)?;
        } else if path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("bvh"))
        {
            out.push(path);
        }
    }
    Ok(())
}
