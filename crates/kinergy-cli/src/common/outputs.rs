//! Outputs checked before any work: every subcommand that writes calls [`check_outputs`]
//! first, so a run that could only end in a lost input or an unwritable file stops at once
//! (exit 2), having written nothing.
//!
//! Refused:
//! - an output whose folder does not exist (or is not a folder);
//! - an output file that exists and is not a regular file (a folder, a device such as
//!   `/dev/null`, a FIFO, a socket): atomic replacement would put a file in its place;
//! - an output folder that exists and is not a folder;
//! - an output that is one of the inputs, however spelled (`./x/../a.bvh`, a symbolic or
//!   hard link): compared by canonical path and, where the file exists, by device and inode;
//!   for an output folder, every file the command will write into it is compared (a folder
//!   output names them all: `compare -o D` with `D/results.csv` as its segments file is
//!   refused, not run);
//! - two outputs that are the same file (`--checkpoint` equal to `-o`, or two reaches'
//!   results given one name). An output that is a symbolic link counts as the link itself:
//!   an atomic write replaces the link, never what it leads to, so a result replaced by a
//!   link to another result is written again in its own place (and one that is a link to an
//!   input is refused, to be safe).
//!
//! A file output `-` is standard output and passes.

use std::fs::{self, Metadata};
use std::path::{Path, PathBuf};

use super::failure::Failure;

/// One output of a command: the option that names it and its path.
#[derive(Debug, Clone, Copy)]
pub enum Output<'a> {
    /// A file, written (atomically) or replaced.
    File(&'a str, &'a Path),
    /// A folder the command writes files into (it may be created, its parent must exist)
    /// and every file it will write there, as paths (the folder joined with each name).
    Folder(&'a str, &'a Path, &'a [PathBuf]),
}

impl<'a> Output<'a> {
    fn option(&self) -> &'a str {
        match *self {
            Output::File(option, _) | Output::Folder(option, ..) => option,
        }
    }

    fn path(&self) -> &'a Path {
        match *self {
            Output::File(_, path) | Output::Folder(_, path, _) => path,
        }
    }
}

/// A file's identity: its canonical path (for a file still to be made, its folder's
/// canonical path and its name) and, when it exists, its device and inode.
#[derive(Debug, PartialEq)]
struct Identity {
    path: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn of(path: &Path) -> Option<Identity> {
        if let Ok(canonical) = fs::canonicalize(path) {
            let inode = fs::metadata(&canonical).ok().and_then(|m| inode(&m));
            return Some(Identity {
                path: canonical,
                inode,
            });
        }
        let name = path.file_name()?;
        let folder = fs::canonicalize(folder_of(path)).ok()?;
        Some(Identity {
            path: folder.join(name),
            inode: None,
        })
    }

    /// The identity of what writing `path` replaces: an atomic write renames its file over
    /// the name, so a symbolic link there is replaced itself, never what it leads to — its
    /// identity is the link's own (its folder's canonical path and its name). Anything
    /// else is [`Identity::of`].
    fn replaced(path: &Path) -> Option<Identity> {
        if !is_link(path) {
            return Identity::of(path);
        }
        let name = path.file_name()?;
        let folder = fs::canonicalize(folder_of(path)).ok()?;
        Some(Identity {
            path: folder.join(name),
            inode: None,
        })
    }

    fn same(&self, other: &Identity) -> bool {
        self.path == other.path || (self.inode.is_some() && self.inode == other.inode)
    }
}

#[cfg(unix)]
fn inode(m: &Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn inode(_: &Metadata) -> Option<(u64, u64)> {
    None
}

/// Whether `path` is a symbolic link (not followed).
fn is_link(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
}

/// The folder `path` is written in.
fn folder_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// What a file that is not a regular file is, for messages.
fn kind(m: &Metadata) -> &'static str {
    let t = m.file_type();
    if t.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// Checks `outputs` before any work (see the [module docs](self)): each one's folder
/// exists, an existing file output is a regular file (an existing folder output a folder),
/// none is one of `inputs` (files or folders, however spelled), no file a folder output
/// will hold is one of them, and no two outputs are the same file.
/// Inputs that do not exist are ignored here (reading them reports them).
pub fn check_outputs(inputs: &[&Path], outputs: &[Output<'_>]) -> Result<(), Failure> {
    let inputs: Vec<(&Path, Identity)> = inputs
        .iter()
        .filter_map(|p| Identity::of(p).map(|id| (*p, id)))
        .collect();
    // Whole outputs first (their folders must exist before their files can be compared),
    // then each file a folder output will hold, as if named with `-o` itself.
    let mut seen: Vec<(Output<'_>, Identity)> = Vec::with_capacity(outputs.len());
    check_each(&inputs, outputs.iter().copied(), &mut seen)?;
    let held = outputs.iter().flat_map(|output| match *output {
        Output::Folder(option, _, files) => files.iter().map(|f| Output::File(option, f)).collect(),
        Output::File(..) => Vec::new(),
    });
    // A file inside a folder still to be made cannot be an input; its name is compared
    // only with the other outputs.
    let mut within = Vec::new();
    for output in held {
        let path = output.path();
        if fs::metadata(folder_of(path)).is_ok_and(|m| m.is_dir()) {
            check_each(&inputs, std::iter::once(output), &mut seen)?;
        } else {
            within.push(output);
        }
    }
    let mut names: Vec<(&Path, &str)> = Vec::with_capacity(within.len());
    for output in within {
        let (option, path) = (output.option(), output.path());
        if let Some((_, first)) = names.iter().find(|(p, _)| *p == path) {
            let named = format!("{option} {}", path.display());
            return Err(Failure::Input(twice(&named, first, option)));
        }
        names.push((path, option));
    }
    Ok(())
}

/// The message for an output `named` that an earlier output (of option `first`) already
/// writes; `option` names its own.
fn twice(named: &str, first: &str, option: &str) -> String {
    if first == option {
        format!("{named}: would be written twice (two of its results have this name)")
    } else {
        format!("{named}: is also the {first} output: choose different files")
    }
}

/// The checks of [`check_outputs`] on `outputs`, each compared with `inputs` and with the
/// outputs already `seen` (to which it is added).
fn check_each<'a>(
    inputs: &[(&Path, Identity)],
    outputs: impl Iterator<Item = Output<'a>>,
    seen: &mut Vec<(Output<'a>, Identity)>,
) -> Result<(), Failure> {
    for output in outputs {
        let (option, path) = (output.option(), output.path());
        if let Output::File(..) = output
            && is_stdout(path)
        {
            continue; // `-o -`: standard output
        }
        let named = || format!("{option} {}", path.display());
        let folder = folder_of(path);
        match fs::metadata(folder) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(Failure::Input(format!(
                    "{}: {} is not a folder",
                    named(),
                    folder.display()
                )));
            }
            Err(_) => {
                return Err(Failure::Input(format!(
                    "{}: the folder {} does not exist",
                    named(),
                    folder.display()
                )));
            }
        }
        if let Ok(m) = fs::metadata(path) {
            match output {
                Output::File(..) if !m.is_file() => {
                    return Err(Failure::Input(format!(
                        "{}: exists and is {}, not a regular file: name a new or a regular file",
                        named(),
                        kind(&m)
                    )));
                }
                Output::Folder(..) if !m.is_dir() => {
                    return Err(Failure::Input(format!(
                        "{}: exists and is not a folder",
                        named()
                    )));
                }
                _ => {}
            }
        }
        let (Some(id), Some(replaced)) = (Identity::of(path), Identity::replaced(path)) else {
            return Err(Failure::Input(format!("{}: does not name a file", named())));
        };
        if let Output::File(..) = output
            && let Some((input, _)) = inputs.iter().find(|(_, i)| i.same(&id))
        {
            let also = if *input == path {
                String::new()
            } else {
                format!(" ({})", input.display())
            };
            if is_link(path) {
                // Written atomically the link itself would be replaced, but a link to an
                // input is no place for an output: refused, to be safe.
                return Err(Failure::Input(format!(
                    "{}: is a symbolic link to one of the inputs{also}: remove the link or \
                     choose another output",
                    named()
                )));
            }
            return Err(Failure::Input(format!(
                "{}: is one of the inputs{also}; writing it would replace it: choose another output",
                named()
            )));
        }
        // Two outputs are one when writing them replaces one name: a link is replaced
        // itself, so a result replaced by a link to another result is written again in its
        // own place (the link goes), never through the link onto the other.
        if let Some((first, _)) = seen.iter().find(|(_, i)| i.same(&replaced)) {
            return Err(Failure::Input(twice(&named(), first.option(), option)));
        }
        seen.push((output, replaced));
    }
    Ok(())
}

/// Makes the output folder `dir` (and its parents) once the outputs are checked, and
/// removes the temporaries that earlier runs killed while writing there left behind
/// ([`kinergy_io::remove_stale_temporaries_in`]), saying so on stderr.
pub fn make_folder(dir: &Path) -> Result<(), Failure> {
    kinergy_io::create_folder(dir)
        .map_err(|e| Failure::input(dir, format!("cannot create the folder: {e}")))?;
    clean_folder(dir);
    Ok(())
}

/// Removes the stale temporaries in `dir` (see [`make_folder`]), saying so on stderr.
pub fn clean_folder(dir: &Path) {
    let removed = kinergy_io::remove_stale_temporaries_in(dir);
    if !removed.is_empty() {
        let names: Vec<String> = removed.iter().map(|p| p.display().to_string()).collect();
        eprintln!(
            "note: removed {} temporary file{} that killed runs left in {}: {}",
            removed.len(),
            if removed.len() == 1 { "" } else { "s" },
            dir.display(),
            kinergy_io::list_some(&names, 5)
        );
    }
}

/// Whether `path` is `-`: standard output instead of a file.
pub fn is_stdout(path: &std::path::Path) -> bool {
    path.as_os_str() == "-"
}

#[cfg(test)]
mod tests {
    use super::{Failure, Output, check_outputs};

    fn refused(r: Result<(), Failure>) -> String {
        match r {
            Err(Failure::Input(m)) => m,
            other => panic!("expected bad input, got {other:?}"),
        }
    }

    #[test]
    fn a_new_file_in_an_existing_folder_is_fine() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.bvh");
        std::fs::write(&input, "x").unwrap();
        let out = dir.path().join("out.bvh");
        check_outputs(&[&input], &[Output::File("-o", &out)]).unwrap();
    }

    #[test]
    fn the_input_under_another_spelling_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("x")).unwrap();
        let input = dir.path().join("x").join("in.bvh");
        std::fs::write(&input, "x").unwrap();
        let other = dir.path().join("x").join("..").join("x").join("in.bvh");
        let m = refused(check_outputs(&[&input], &[Output::File("-o", &other)]));
        assert!(m.contains("is one of the inputs"), "{m}");
    }

    #[test]
    fn two_outputs_that_are_one_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("p.json");
        let b = dir.path().join(".").join("p.json");
        let m = refused(check_outputs(
            &[],
            &[Output::File("-o", &a), Output::File("--checkpoint", &b)],
        ));
        assert!(m.contains("is also the -o output"), "{m}");
    }

    /// The sweep's result replaced by a link to another result: the two are not one output
    /// (writing the link replaces the link), so `--resume` writes it again; a link to an
    /// input is still refused, naming the link.
    #[cfg(unix)]
    #[test]
    fn a_link_to_another_output_is_its_own_output() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.json"), dir.path().join("b.json"));
        std::fs::write(&a, "{}").unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let files = [a.clone(), b.clone()];
        check_outputs(&[], &[Output::Folder("--out-dir", dir.path(), &files)]).unwrap();
        // A folder of results that is a link to another is one folder: refused.
        std::fs::create_dir(dir.path().join("p1")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("p1"), dir.path().join("p2")).unwrap();
        let files = [dir.path().join("p1/r.json"), dir.path().join("p2/r.json")];
        let m = refused(check_outputs(
            &[],
            &[Output::Folder("--out-dir", dir.path(), &files)],
        ));
        assert!(m.contains("would be written twice"), "{m}");
        let input = dir.path().join("in.bvh");
        std::fs::write(&input, "x").unwrap();
        let link = dir.path().join("out.bvh");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let m = refused(check_outputs(&[&input], &[Output::File("-o", &link)]));
        assert!(m.contains("is a symbolic link to one of the inputs"), "{m}");
    }

    #[test]
    fn a_missing_folder_and_a_folder_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("nope").join("out.bvh");
        let m = refused(check_outputs(&[], &[Output::File("-o", &missing)]));
        assert!(m.contains("does not exist"), "{m}");
        let m = refused(check_outputs(&[], &[Output::File("-o", dir.path())]));
        assert!(m.contains("a folder"), "{m}");
        check_outputs(&[], &[Output::Folder("-o", dir.path(), &[])]).unwrap();
        check_outputs(&[], &[Output::Folder("-o", &dir.path().join("new"), &[])]).unwrap();
    }
}
