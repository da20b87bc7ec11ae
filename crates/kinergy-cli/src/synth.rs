//! `kinergy synth`: the synthetic motion-capture set.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use kinergy_reach::ReachError;
use kinergy_reach::drive::Driver;
use kinergy_reach::synth::{MANIFEST, SynthSettings, set_files, write_set};
use kinergy_train::synthetic::{SET_SEGMENTS, set_segments};

use crate::common::{ControllerKind, Failure, Output, check_outputs, check_range, emit, limits};

/// Arguments of `kinergy synth`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder: one subfolder per person, and manifest.csv.
    #[arg(short, long, default_value = "data-synthetic", value_name = "DIR")]
    pub output: PathBuf,
    /// Persons, 1 to 100.
    #[arg(long, default_value_t = SynthSettings::default().persons, value_name = "N")]
    pub persons: usize,
    /// Reaches per person, 1 to 100.
    #[arg(long, default_value_t = SynthSettings::default().reaches, value_name = "N")]
    pub reaches: usize,
    /// Seed of everything (the same seed writes the same files byte for byte).
    #[arg(long, default_value_t = SynthSettings::default().seed)]
    pub seed: u64,
    /// Frames per second, 1 to 1000.
    #[arg(long, default_value_t = SynthSettings::default().frame_rate, value_name = "HZ")]
    pub frame_rate: f64,
    /// A person's parameters (`kinergy fit -o person.json`) or field (`fit --field`, asked
    /// for each reach's target): every reaching arm is driven by their synergy controller
    /// (`reach --params`), a set in their style; DIR/segments.csv
    /// then lists the frames each clip's arm was driven by the synergy, the synergy's target
    /// and the tempo its smooth controller was bounded by, for `kinergy fit --segments` (which
    /// then runs the controller that made each clip: the person's vector retraces it).
    #[arg(long, value_name = "person.json")]
    pub params: Option<PathBuf>,
    /// With --params, the synergy controller of the person's arm: `smooth` or `paper` (the
    /// one `fit --controller paper` and `synthesize --controller paper` run, for sets whose
    /// truth a fit must recover exactly). Default: the one the parameters were fitted under
    /// (their file records it), else smooth.
    #[arg(long, value_parser = crate::common::named::<ControllerKind>(ControllerKind::ALL.map(ControllerKind::name)), requires = "params")]
    pub controller: Option<ControllerKind>,
    /// The share of each person's takes that reach with both hands, 0 to 1, spread evenly
    /// over the takes: the right hand reaches and returns, then the left hand reaches toward
    /// the mirrored target (two reaches in one take, one per arm for `fit --arm auto`; the
    /// manifest has a row per reach, with its arm and first frame).
    #[arg(long, default_value_t = SynthSettings::default().both_hands, value_name = "SHARE")]
    pub both_hands: f64,
}

/// Runs `kinergy synth`.
pub fn run(args: &Args) -> Result<(), Failure> {
    check_range("--persons", args.persons, limits::SYNTH_PERSONS)?;
    check_range("--reaches", args.reaches, limits::SYNTH_REACHES)?;
    check_range("--frame-rate", args.frame_rate, limits::SYNTH_FRAME_RATE)?;
    check_range("--both-hands", args.both_hands, limits::SYNTH_BOTH_HANDS)?;
    let inputs: Vec<&Path> = args.params.iter().map(PathBuf::as_path).collect();
    let mut names = set_files(&settings(args));
    if args.params.is_some() {
        names.push(SET_SEGMENTS.into());
    }
    let files: Vec<PathBuf> = names.iter().map(|name| args.output.join(name)).collect();
    check_outputs(&inputs, &[Output::Folder("-o", &args.output, &files)])?;
    let person = args
        .params
        .as_deref()
        .map(crate::common::read_person)
        .transpose()?;
    let drive = match &person {
        Some(person) => Driver::Person(person),
        None => Driver::Profile,
    };
    if args.output.is_dir() {
        crate::common::clean_folder(&args.output);
    }
    let before = Written::before(&args.output);
    let result = write(args, drive);
    if result.is_err() {
        before.undo(&args.output);
    }
    let reaches = result?;
    let clips = args.persons * args.reaches;
    let manifest = args.output.join(MANIFEST);
    emit(&format!(
        "{clips} clips{} of {} persons in {} (seed {}), manifest {}\n",
        if reaches > clips {
            format!(
                " ({reaches} reaches: {} takes with both hands)",
                reaches - clips
            )
        } else {
            String::new()
        },
        args.persons,
        args.output.display(),
        args.seed,
        manifest.display()
    ))
}

/// The set's settings from the command line.
fn settings(args: &Args) -> SynthSettings {
    SynthSettings {
        persons: args.persons,
        reaches: args.reaches,
        seed: args.seed,
        frame_rate: args.frame_rate,
        synergy_controller: args.controller,
        both_hands: args.both_hands,
    }
}

/// Writes the set (the clips and the manifest, by the library) and, with --params, the
/// segments file; the number of reaches.
fn write(args: &Args, drive: Driver<'_>) -> Result<usize, Failure> {
    let made =
        write_set(&args.output, &settings(args), drive).map_err(|e| match (e, &args.params) {
            (e @ ReachError::Params { .. }, Some(path)) => crate::common::person_failure(path, e),
            (e @ ReachError::Io { .. }, _) => Failure::Task(e.to_string()),
            (e, _) => Failure::Input(e.to_string()),
        })?;
    if drive.is_person() {
        // Written, not read: a segments file that cannot be written is a failed task.
        set_segments(&args.output, &made)
            .write()
            .map_err(|e| Failure::Task(e.to_string()))?;
    }
    Ok(made.len())
}

/// What was in the output folder before a run, so that a failed run removes what it
/// wrote and nothing else.
enum Written {
    /// The folder did not exist: a failed run removes it.
    NewFolder,
    /// The folder existed with these entries (its own and its subfolders').
    Existing(BTreeSet<PathBuf>),
}

impl Written {
    fn before(dir: &Path) -> Written {
        if !dir.exists() {
            return Written::NewFolder;
        }
        let mut found = BTreeSet::new();
        walk(dir, &mut found);
        Written::Existing(found)
    }

    /// Removes what the run added (best effort: the run's error is what gets reported).
    fn undo(&self, dir: &Path) {
        match self {
            Written::NewFolder => {
                let _ = std::fs::remove_dir_all(dir);
            }
            Written::Existing(before) => {
                let mut now = BTreeSet::new();
                walk(dir, &mut now);
                // Deepest first, so added folders are empty when their turn comes.
                let added: Vec<&PathBuf> = now.difference(before).collect();
                for path in added.into_iter().rev() {
                    if path.is_dir() {
                        let _ = std::fs::remove_dir(path);
                    } else {
                        let _ = std::fs::remove_file(path);
                    }
                }
            }
        }
    }
}

/// The entries of `dir` and of its subfolders one level down (the set's layout).
fn walk(dir: &Path, out: &mut BTreeSet<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if entry.file_type().is_ok_and(|t| t.is_dir())
            && let Ok(inner) = std::fs::read_dir(&path)
        {
            out.extend(inner.flatten().map(|e| e.path()));
        }
        out.insert(path);
    }
}
