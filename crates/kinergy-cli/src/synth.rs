//! `kinergy synth`: the synthetic motion-capture set.

use std::path::PathBuf;

use kinergy_reach::synth::{SynthSettings, make_set};

use crate::common::{Failure, check_range, emit, limits};

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
}

/// Runs `kinergy synth`.
pub fn run(args: &Args) -> Result<(), Failure> {
    check_range("--persons", args.persons, limits::SYNTH_PERSONS)?;
    check_range("--reaches", args.reaches, limits::SYNTH_REACHES)?;
    check_range("--frame-rate", args.frame_rate, limits::SYNTH_FRAME_RATE)?;
    let settings = SynthSettings {
        persons: args.persons,
        reaches: args.reaches,
        seed: args.seed,
        frame_rate: args.frame_rate,
    };
    let rows = make_set(&args.output, &settings).map_err(|e| Failure::Input(e.to_string()))?;
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in &rows {
        w.serialize(r)
            .map_err(|e| Failure::Task(format!("manifest.csv: {e}")))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Failure::Task(format!("manifest.csv: {e}")))?;
    let manifest = args.output.join("manifest.csv");
    kinergy_io::write_atomic(&manifest, &bytes)
        .map_err(|e| Failure::Task(format!("{}: {e}", manifest.display())))?;
    emit(&format!(
        "{} clips of {} persons in {} (seed {}), manifest {}\n",
        rows.len(),
        args.persons,
        args.output.display(),
        args.seed,
        manifest.display()
    ))
}
