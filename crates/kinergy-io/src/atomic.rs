//! Atomic file replacement, and the rule for its temporary files.
//!
//! Every file Kinergy writes is first written under a temporary name in the same folder,
//! `.<name>.<pid>.<n>.tmp` (`<pid>` the writing process, `<n>` a counter), synced, then
//! renamed over `<name>`: readers see the old file or the new one, never a part. A failure
//! removes the temporary file and leaves `<name>` untouched.
//!
//! **Long names.** A `<name>` longer than [`TEMP_NAME_KEPT`] bytes is shortened in its
//! temporaries' names to its first 160 bytes, `~` and 16 hexadecimal digits of a hash of the
//! whole name, so that every target whose own name fits the file system's limit (255 bytes
//! on most) has temporaries that fit too: a temporary's name is at most 237 bytes.
//!
//! **No debris.** A process killed mid-write cannot remove its temporary file. So before
//! writing `<name>`, a writer removes the *stale* temporaries of `<name>`: files named
//! exactly `.<name>.<pid>.<n>.tmp` whose process is gone. On Linux (where `/proc` is
//! mounted) "gone" means `/proc/<pid>` does not exist; elsewhere, and where `/proc` is not
//! available, a temporary file counts as stale once it has not been modified for an hour
//! ([`STALE_AFTER`]). Files of another name, of a live process, and this process's own are
//! never touched, so concurrent writers of one file do not disturb each other.
//!
//! **Full disk.** An error because the file system is full (`ENOSPC`) is reported with the
//! kind [`io::ErrorKind::StorageFull`] and the text "disk full (no space left on device)",
//! see [`describe_full_disk`].
//!
//! Whole files go through [`write_atomic`]; files made piece by piece (logs, pictures an
//! encoder writes to a path) through [`AtomicFile`].

use std::ffi::{OsStr, OsString};
use std::fs::{self, File, OpenOptions};
use std::io::{self, Read as _, Seek as _, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Where a process's liveness cannot be checked, a temporary file untouched for this long
/// is taken to be a killed writer's and removed.
pub const STALE_AFTER: Duration = Duration::from_secs(3600);

/// What a full disk is called in every message.
const DISK_FULL: &str = "disk full (no space left on device)";

/// Replaces `path` atomically: write a temporary file in the same directory, sync it,
/// rename it over `path` (keeping an existing file's permissions), then sync the directory
/// (best effort). Readers see the old file or the new one, never a part; on failure the
/// temporary file is removed and `path` is untouched. Stale temporaries of `path` are
/// removed first (see the [module docs](self)).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes).map_err(describe_full_disk)?;
    file.commit()
}

/// The error with a clear message when it says the disk is full (`ENOSPC`, or the kind
/// [`io::ErrorKind::StorageFull`]): kind `StorageFull`, text "disk full (no space left on
/// device)". Other errors are returned as they are.
pub fn describe_full_disk(e: io::Error) -> io::Error {
    if is_disk_full(&e) && e.to_string() != DISK_FULL {
        io::Error::new(io::ErrorKind::StorageFull, DISK_FULL)
    } else {
        e
    }
}

/// Whether `e` says the file system is full.
pub fn is_disk_full(e: &io::Error) -> bool {
    // ENOSPC is 28 on Linux, the BSDs and macOS.
    e.kind() == io::ErrorKind::StorageFull || (cfg!(unix) && e.raw_os_error() == Some(28))
}

/// A file being written under a temporary name next to its destination; it appears at the
/// destination, complete, on [`commit`](AtomicFile::commit) (or at each
/// [`publish`](AtomicFile::publish)). Dropped uncommitted, the temporary file is removed
/// and the destination is left as it was.
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    dir: PathBuf,
    file_name: OsString,
    temp: PathBuf,
    file: Option<File>,
}

impl AtomicFile {
    /// Starts writing `path`: removes stale temporaries of `path`, then creates a new, empty
    /// temporary file beside it. Fails if `path` names no file, its folder is missing, or
    /// it is something other than a regular file (a folder, a device, a FIFO, a socket),
    /// which is never replaced.
    pub fn create(path: &Path) -> io::Result<AtomicFile> {
        let dir = match path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let Some(file_name) = path.file_name() else {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "the path does not name a file",
            ));
        };
        refuse_special(path)?;
        remove_stale_temporaries(&dir, file_name);
        let (temp, file) = create_temp(&dir, file_name).map_err(describe_full_disk)?;
        if let Ok(existing) = fs::metadata(path) {
            // Keep the replaced file's permissions; a failure here is not worth failing for.
            let _ = file.set_permissions(existing.permissions());
        }
        Ok(AtomicFile {
            target: path.to_path_buf(),
            dir,
            file_name: file_name.to_os_string(),
            temp,
            file: Some(file),
        })
    }

    /// The temporary file, for encoders that insist on a path (they may truncate and
    /// rewrite it; the file stays the same).
    pub fn temp_path(&self) -> &Path {
        &self.temp
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Syncs the temporary file and renames it over the destination, then syncs the folder
    /// (best effort).
    pub fn commit(mut self) -> io::Result<()> {
        self.rename_into_place()?;
        Ok(())
    }

    /// Makes what was written so far appear at the destination, complete, and goes on
    /// writing after it (into a new temporary file holding a copy): for logs that must be
    /// whole at each checkpoint. Costs a copy of the file.
    pub fn publish(&mut self) -> io::Result<()> {
        let mut published = self.rename_into_place()?;
        let (temp, mut next) =
            create_temp(&self.dir, &self.file_name).map_err(describe_full_disk)?;
        self.temp = temp;
        let copied = published
            .seek(io::SeekFrom::Start(0))
            .and_then(|_| io::copy(&mut published, &mut next))
            .map_err(describe_full_disk);
        self.file = Some(next);
        copied.map(|_| ())
    }

    fn rename_into_place(&mut self) -> io::Result<File> {
        let Some(mut file) = self.file.take() else {
            return Err(io::Error::other("the file was already committed"));
        };
        let result = file
            .flush()
            .and_then(|()| file.sync_all())
            // Checked again: something else may have appeared there while this was written.
            .and_then(|()| refuse_special(&self.target))
            .and_then(|()| fs::rename(&self.temp, &self.target))
            .map_err(describe_full_disk);
        if let Err(e) = result {
            let _ = fs::remove_file(&self.temp);
            return Err(e);
        }
        sync_dir(&self.dir);
        Ok(file)
    }

    /// Appends the content of the existing destination (if any) to the temporary file:
    /// to continue a log. Returns whether there was one.
    pub fn copy_existing(&mut self) -> io::Result<bool> {
        let Some(file) = self.file.as_mut() else {
            return Err(io::Error::other("the file was already committed"));
        };
        match File::open(&self.target) {
            Ok(mut existing) => {
                let mut bytes = Vec::new();
                existing.read_to_end(&mut bytes)?;
                file.write_all(&bytes).map_err(describe_full_disk)?;
                Ok(true)
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(false),
            Err(e) => Err(e),
        }
    }
}

/// Creates the folder `dir` and its parents (nothing to do when it is one), saying what is
/// in the way otherwise: a symbolic link to a missing folder, or a file.
pub fn create_folder(dir: &Path) -> io::Result<()> {
    // Without a trailing separator, which would make the link be followed.
    let dir: PathBuf = dir.components().collect();
    let dir = dir.as_path();
    if fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink())
        && fs::metadata(dir).is_err()
    {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            "a symbolic link to a missing folder: make the folder it names, or name another",
        ));
    }
    match fs::metadata(dir) {
        Ok(meta) if !meta.is_dir() => Err(io::Error::new(
            io::ErrorKind::AlreadyExists,
            format!("{}, not a folder", file_kind_or_file(&meta.file_type())),
        )),
        _ => fs::create_dir_all(dir),
    }
}

/// "a file", or what [`file_kind`] says of a special file.
fn file_kind_or_file(kind: &fs::FileType) -> &'static str {
    if kind.is_file() {
        "a file"
    } else {
        file_kind(kind)
    }
}

/// Refuses a destination that exists and is not a regular file (followed through links):
/// renaming a file over a device, a FIFO, a socket or a folder would replace it.
fn refuse_special(path: &Path) -> io::Result<()> {
    match fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a regular file: it is not replaced",
                path.display(),
                file_kind(&meta.file_type())
            ),
        )),
        _ => Ok(()),
    }
}

/// "a folder", "a FIFO", "a device", "a socket" or "not a regular file".
fn file_kind(kind: &fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.file.as_mut() {
            Some(file) => file.write(buf).map_err(describe_full_disk),
            None => Err(io::Error::other("the file was already committed")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self.file.as_mut() {
            Some(file) => file.flush().map_err(describe_full_disk),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = fs::remove_file(&self.temp);
        }
    }
}

/// The longest target name a temporary's name keeps whole, bytes (see the
/// [module docs](self)): with `.`, the process (at most 10 digits), the counter (at most 20)
/// and `.tmp`, a temporary's name stays within 237 bytes.
pub const TEMP_NAME_KEPT: usize = 200;

/// The bytes of a longer name that its temporaries keep, before `~` and the hash.
const TEMP_NAME_PREFIX: usize = 160;

/// `file_name` as its temporaries' names spell it: whole up to [`TEMP_NAME_KEPT`] bytes,
/// otherwise its first 160 bytes (whole characters), `~` and 16 hexadecimal digits of a
/// hash of the whole name (64-bit FNV-1a, the same on every platform and run).
fn temp_stem(file_name: &OsStr) -> OsString {
    let bytes = file_name.as_encoded_bytes();
    if bytes.len() <= TEMP_NAME_KEPT {
        return file_name.to_os_string();
    }
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    let text = file_name.to_string_lossy();
    let mut cut = TEMP_NAME_PREFIX.min(text.len());
    while !text.is_char_boundary(cut) {
        cut -= 1;
    }
    OsString::from(format!("{}~{hash:016x}", &text[..cut]))
}

/// The name of a temporary file of `file_name` written by process `pid`.
fn temp_name(file_name: &OsStr, pid: u32, n: u64) -> OsString {
    let mut name = OsString::from(".");
    name.push(temp_stem(file_name));
    name.push(format!(".{pid}.{n}.tmp"));
    name
}

/// The process that wrote `name`, if it is a temporary file of `file_name` by our rule.
fn temp_owner(name: &OsStr, file_name: &OsStr) -> Option<u32> {
    let name = name.to_str()?;
    let stem = temp_stem(file_name);
    let file_name = stem.to_str()?;
    let rest = name
        .strip_prefix('.')?
        .strip_prefix(file_name)?
        .strip_prefix('.')?
        .strip_suffix(".tmp")?;
    let (pid, n) = rest.split_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (digits(pid) && digits(n)).then(|| pid.parse().ok())?
}

/// Whether process `pid` is known to be gone; `None` where this cannot be told.
fn process_gone(pid: u32) -> Option<bool> {
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        Some(!Path::new("/proc").join(pid.to_string()).exists())
    } else {
        None
    }
}

/// Removes the temporaries of `file_name` in `dir` left by killed writers (best effort).
fn remove_stale_temporaries(dir: &Path, file_name: &OsStr) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let me = std::process::id();
    for entry in entries.flatten() {
        let Some(pid) = temp_owner(&entry.file_name(), file_name) else {
            continue;
        };
        if pid == me {
            continue;
        }
        let stale = is_stale(&entry, pid);
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if stale && is_file {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// The process that wrote `name`, if it is a temporary file of any name by our rule
/// (`.<name>.<pid>.<n>.tmp`, `<name>` not empty).
fn any_temp_owner(name: &OsStr) -> Option<u32> {
    let rest = name.to_str()?.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (rest, n) = rest.rsplit_once('.')?;
    let (file_name, pid) = rest.rsplit_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (!file_name.is_empty() && digits(pid) && digits(n)).then(|| pid.parse().ok())?
}

/// How deep [`remove_stale_temporaries_in`] looks into a folder's subfolders.
const CLEAN_DEPTH: usize = 8;

/// Removes the stale temporaries of *every* name in `dir` and its subfolders (up to 8
/// levels, symbolic links not followed): the debris of earlier runs killed while writing
/// there, by the rule of the [module docs](self) (their process gone, or untouched for
/// [`STALE_AFTER`] where that cannot be told). A command that writes many files into a
/// folder calls it once at its start, so that a killed run's temporaries of names the next
/// run does not write are cleaned too. Returns the files removed; a folder that cannot be
/// read is skipped (best effort, like the cleaning before each write).
pub fn remove_stale_temporaries_in(dir: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    clean(dir, CLEAN_DEPTH, &mut removed);
    removed.sort();
    removed
}

fn clean(dir: &Path, depth: usize, removed: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let me = std::process::id();
    for entry in entries.flatten() {
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() {
            if depth > 0 {
                clean(&entry.path(), depth - 1, removed);
            }
            continue;
        }
        let Some(pid) = any_temp_owner(&entry.file_name()) else {
            continue;
        };
        if kind.is_file()
            && pid != me
            && is_stale(&entry, pid)
            && fs::remove_file(entry.path()).is_ok()
        {
            removed.push(entry.path());
        }
    }
}

/// Whether the temporary `entry` of process `pid` is a killed writer's.
fn is_stale(entry: &fs::DirEntry, pid: u32) -> bool {
    match process_gone(pid) {
        Some(gone) => gone,
        None => entry
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age >= STALE_AFTER),
    }
}

/// Creates a new, unique temporary file `.<name>.<pid>.<n>.tmp` in `dir`.
fn create_temp(dir: &Path, file_name: &OsStr) -> io::Result<(PathBuf, File)> {
    let mut attempts = 0u32;
    loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp_path = dir.join(temp_name(file_name, std::process::id(), n));
        match OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&temp_path)
        {
            Ok(file) => return Ok((temp_path, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempts < 100 => {
                attempts = attempts.saturating_add(1);
            }
            Err(e) => return Err(e),
        }
    }
}

/// Makes the rename durable where the platform allows syncing a directory. The file is
/// already in place, so a failure here (some file systems refuse) is not reported.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(handle) = File::open(dir) {
        let _ = handle.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

#[cfg(test)]
mod tests {

    /// A FIFO, a socket and a folder that the test makes in its own folder (and a device
    /// node where the test may make one) are refused before anything is written, and stay
    /// what they were; a regular file and a link to one are replaced.
    #[cfg(unix)]
    #[test]
    fn only_regular_files_are_replaced() {
        use std::fs;
        use std::os::unix::fs::FileTypeExt as _;
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        let socket = dir.path().join("socket");
        let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
        let folder = dir.path().join("folder");
        fs::create_dir(&folder).unwrap();
        let device = dir.path().join("null");
        let _ = std::process::Command::new("mknod")
            .args(["-m", "666"])
            .arg(&device)
            .args(["c", "1", "3"])
            .stderr(std::process::Stdio::null())
            .status();
        let mut special = vec![(socket, "a socket"), (folder, "a folder")];
        if made.is_ok_and(|s| s.success()) {
            special.push((fifo, "a FIFO"));
        }
        if fs::metadata(&device).is_ok_and(|m| m.file_type().is_char_device()) {
            special.push((device, "a device"));
        }
        for (path, kind) in &special {
            let e = write_atomic(path, b"x").unwrap_err();
            assert!(e.to_string().contains(kind), "{}: {e}", path.display());
            let still = fs::metadata(path).unwrap();
            assert!(!still.is_file(), "{} became a regular file", path.display());
        }
        let file = dir.path().join("file");
        write_atomic(&file, b"old").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert_eq!(fs::read(&link).unwrap(), b"new");
        // Nothing left behind by the refusals.
        let debris: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(debris.is_empty(), "{debris:?}");
    }
    use super::{
        AtomicFile, describe_full_disk, is_disk_full, temp_name, temp_owner, write_atomic,
    };
    use std::ffi::OsStr;
    use std::io::Write as _;

    fn names(dir: &std::path::Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_stale_temporary_of_a_dead_process_is_removed_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        // PIDs on Linux stay below 2^22, so 999999 is free unless pid_max was raised.
        assert!(!std::path::Path::new("/proc/999999").exists());
        std::fs::write(dir.path().join(".out.bvh.999999.0.tmp"), b"half a file").unwrap();
        write_atomic(&dir.path().join("out.bvh"), b"whole").unwrap();
        assert_eq!(names(dir.path()), ["out.bvh"]);
    }

    /// The sweep's 240-character take: its result's temporary passed 255 bytes ("File name
    /// too long"). A target of any name that fits has a temporary that fits, found again
    /// as its own when stale.
    #[test]
    fn a_target_of_a_long_name_has_a_temporary_that_fits() {
        let dir = tempfile::tempdir().unwrap();
        for len in [200, 201, 250, 255] {
            let name = format!("{}.json", "L".repeat(len - 5));
            let target = dir.path().join(&name);
            write_atomic(&target, b"whole").unwrap();
            assert_eq!(std::fs::read(&target).unwrap(), b"whole");
            let temp = temp_name(OsStr::new(&name), u32::MAX, u64::MAX);
            assert!(temp.len() <= 237, "{len}: {} bytes", temp.len());
            assert_eq!(temp_owner(&temp, OsStr::new(&name)), Some(u32::MAX));
            // Another long name of the same first bytes has other temporaries.
            let other = format!("{}.jsoN", "L".repeat(len - 5));
            assert_eq!(temp_owner(&temp, OsStr::new(&other)), None, "{len}");
        }
        // A name of multi-byte characters is cut between characters.
        let name = "ü".repeat(127);
        let temp = temp_name(OsStr::new(&name), 1, 2);
        assert!(temp.to_str().is_some() && temp.len() <= 237, "{temp:?}");
        #[cfg(target_os = "linux")]
        {
            let name = "L".repeat(240) + ".bvh.json";
            let stale = temp_name(OsStr::new(&name), 999_999, 0);
            std::fs::write(dir.path().join(&stale), b"half a file").unwrap();
            write_atomic(&dir.path().join(&name), b"whole").unwrap();
            assert!(!dir.path().join(&stale).exists(), "{stale:?} stayed");
        }
        assert!(!names(dir.path()).iter().any(|n| n.ends_with(".tmp")));
    }

    #[test]
    fn temporaries_of_live_processes_and_other_names_are_kept() {
        let dir = tempfile::tempdir().unwrap();
        let live = format!(".out.bvh.{}.77.tmp", std::process::id());
        for name in [live.as_str(), ".other.bvh.999999.0.tmp", ".out.bvh.x.0.tmp"] {
            std::fs::write(dir.path().join(name), b"keep").unwrap();
        }
        write_atomic(&dir.path().join("out.bvh"), b"whole").unwrap();
        assert_eq!(names(dir.path()).len(), 4);
    }

    #[test]
    fn a_folder_is_cleaned_of_every_stale_temporary_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("p01");
        std::fs::create_dir(&sub).unwrap();
        let live = format!(".r01.json.{}.3.tmp", std::process::id());
        let keep = [
            dir.path().join(&live),
            dir.path().join(".x.json.999999.tmp"),
            dir.path().join("r01.json"),
            dir.path().join("..999999.0.tmp"),
        ];
        let stale = [
            dir.path().join(".r01.json.999999.0.tmp"),
            dir.path().join(".a.b.c.999998.12.tmp"),
            sub.join(".r02.bvh.999997.1.tmp"),
        ];
        for p in keep.iter().chain(&stale) {
            std::fs::write(p, b"x").unwrap();
        }
        let mut expected = stale.to_vec();
        expected.sort();
        assert_eq!(super::remove_stale_temporaries_in(dir.path()), expected);
        assert!(keep.iter().all(|p| p.exists()));
        assert!(stale.iter().all(|p| !p.exists()));
        assert!(super::remove_stale_temporaries_in(&dir.path().join("missing")).is_empty());
    }

    #[test]
    fn temporary_names_are_parsed_exactly() {
        let name = OsStr::new("out.bvh");
        assert_eq!(temp_owner(OsStr::new(".out.bvh.12.3.tmp"), name), Some(12));
        assert_eq!(temp_owner(OsStr::new(".out.bvh.12.tmp"), name), None);
        assert_eq!(temp_owner(OsStr::new(".out.bvh.x.12.3.tmp"), name), None);
        assert_eq!(temp_owner(OsStr::new(".out.bvhh.12.3.tmp"), name), None);
        assert_eq!(temp_owner(OsStr::new("out.bvh.12.3.tmp"), name), None);
    }

    #[test]
    fn an_uncommitted_file_leaves_the_destination_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.csv");
        std::fs::write(&path, b"old").unwrap();
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"new, unfinished").unwrap();
        drop(file);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["log.csv"]);
    }

    #[test]
    fn publish_shows_what_was_written_and_writing_goes_on() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.csv");
        std::fs::write(&path, b"a\n").unwrap();
        let mut file = AtomicFile::create(&path).unwrap();
        assert!(file.copy_existing().unwrap());
        file.write_all(b"b\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"a\n");
        file.publish().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"a\nb\n");
        file.write_all(b"c\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"a\nb\n");
        file.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"a\nb\nc\n");
        assert_eq!(names(dir.path()), ["log.csv"]);
    }

    #[test]
    fn a_full_disk_is_called_so() {
        let e = describe_full_disk(std::io::Error::from_raw_os_error(28));
        assert!(is_disk_full(&e));
        assert_eq!(e.kind(), std::io::ErrorKind::StorageFull);
        assert_eq!(e.to_string(), "disk full (no space left on device)");
        let other = describe_full_disk(std::io::Error::from_raw_os_error(2));
        assert_eq!(other.kind(), std::io::ErrorKind::NotFound);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn writing_to_dev_full_says_disk_full() {
        let Ok(mut f) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
            return;
        };
        let e = f.write_all(b"x").and_then(|()| f.flush()).unwrap_err();
        assert_eq!(
            describe_full_disk(e).to_string(),
            "disk full (no space left on device)"
        );
    }

    #[test]
    fn replaces_content_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_missing_folder_fails_and_creates_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nope").join("out.txt");
        assert!(write_atomic(&path, b"x").is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_path_without_a_file_name_is_refused() {
        let e = write_atomic(std::path::Path::new("/"), b"x").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
    }

    #[cfg(unix)]
    #[test]
    fn keeps_the_replaced_files_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.txt");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&path, b"new").unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }
}
