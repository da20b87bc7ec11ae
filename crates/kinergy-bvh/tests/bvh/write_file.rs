//! `write_file` replaces files atomically and never leaves a temporary file behind.

use std::path::Path;

use kinergy_bvh::{Error, ReadOptions};

use crate::common::{QUIRKS_DIR, read};

fn sample() -> kinergy_bvh::Bvh {
    read(&Path::new(QUIRKS_DIR).join("valid/per_joint_orders.bvh"))
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn assert_io_error_naming(result: Result<(), Error>, path: &Path) {
    match result {
        Err(ref e @ Error::Io { path: ref p, .. }) => {
            assert_eq!(p, path);
            assert!(
                e.to_string().starts_with(&path.display().to_string()),
                "{e}"
            );
        }
        other => panic!(
            "expected an I/O error for {}, got {other:?}",
            path.display()
        ),
    }
}

#[test]
fn writes_and_replaces_leaving_only_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    let bvh = sample();
    kinergy_bvh::write_file(&path, &bvh).unwrap();
    assert!(
        kinergy_bvh::read_file(&path, &ReadOptions::default())
            .unwrap()
            .same_content(&bvh)
    );

    std::fs::write(&path, "old contents that are longer than nothing").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    kinergy_bvh::write_file(&path, &bvh).unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        kinergy_bvh::to_string(&bvh).unwrap()
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        assert_eq!(
            std::fs::metadata(&path).unwrap().permissions().mode() & 0o777,
            0o640
        );
    }
    assert_eq!(entries(dir.path()), ["walk.bvh"]);
}

#[test]
fn a_missing_directory_is_an_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no/such/dir/walk.bvh");
    assert_io_error_naming(kinergy_bvh::write_file(&path, &sample()), &path);
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn a_parent_that_is_a_file_is_an_error_naming_the_path() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("plain"), "x").unwrap();
    let path = dir.path().join("plain/walk.bvh");
    assert_io_error_naming(kinergy_bvh::write_file(&path, &sample()), &path);
    assert_eq!(entries(dir.path()), ["plain"]);
}

#[cfg(unix)]
#[test]
fn a_read_only_directory_is_an_error_naming_the_path() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root (as in CI containers) ignores directory permissions; /proc refuses new files to
    // everyone, so it stands in for a read-only directory there.
    let privileged = std::fs::write(locked.join("probe"), "").is_ok();
    let target_dir = if privileged {
        Path::new("/proc").to_path_buf()
    } else {
        locked.clone()
    };
    let path = target_dir.join("kinergy-bvh-test.bvh");
    assert_io_error_naming(kinergy_bvh::write_file(&path, &sample()), &path);
    assert!(!path.exists());
    if !privileged {
        assert!(entries(&locked).is_empty());
    }
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn a_failed_rename_removes_the_temporary_file() {
    // The destination is a directory: the temporary file is written, the rename fails.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    std::fs::create_dir(&path).unwrap();
    assert_io_error_naming(kinergy_bvh::write_file(&path, &sample()), &path);
    assert_eq!(entries(dir.path()), ["walk.bvh"]);
    assert!(path.is_dir());
}

#[test]
fn an_invalid_document_creates_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    let mut bvh = sample();
    bvh.frame_time = 0.0;
    match kinergy_bvh::write_file(&path, &bvh) {
        Err(e @ Error::Write { .. }) => {
            assert!(e.to_string().starts_with(&path.display().to_string()))
        }
        other => panic!("{other:?}"),
    }
    assert!(entries(dir.path()).is_empty());

    // An existing file is left untouched.
    std::fs::write(&path, "keep me").unwrap();
    assert!(kinergy_bvh::write_file(&path, &bvh).is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me");
    assert_eq!(entries(dir.path()), ["walk.bvh"]);
}

#[test]
fn a_path_without_a_file_name_is_an_error_naming_it() {
    for path in [Path::new("/"), Path::new("some/dir/..")] {
        assert_io_error_naming(kinergy_bvh::write_file(path, &sample()), path);
    }
}
