//! `kinergy style`: runs and renders [`kinergy_reach::style`]: whether `reach --params` reaches
//! in the person's style. For
//! each of the person's captures, the full-body character (the capture's proportions) reaches
//! the capture's own target — the hand's last position of its main reach, carried over in the
//! arm's fitted base frame — once with the person's parameters and once with the default
//! profile; each motion's hand-speed profile (relative to the shoulder, from the reach's onset
//! to where, past its peak, it falls to the share of the peak at which the captured segment
//! ends — [`kinergy_reach::style::ended_like`] — time-normalized) is compared with the
//! captured one: Pearson correlation, and
//! the fraction of the movement at which the speed peaks; and each motion's arm path (elbow,
//! wrist and hand from the shoulder, time-normalized, in arm lengths,
//! [`kinergy_reach::style::arm_path`]) against the captured one. Where the synergy handed the
//! hand over, its own part (onset to hand-over) is scored too. With `-o DIR`: style.csv,
//! summary.md, and the pictures ([`kinergy_draw::style`]): `speed.svg|png` (every hand-speed
//! profile, captured and reached, on one chart), `realtime.svg|png` and `strip.svg|png` (the
//! first capture's reach as a film strip, the character over the capture).

use std::path::{Path, PathBuf};

use kinergy_motion::Clip;
use kinergy_reach::ReachError;
use kinergy_reach::style::{StyleCapture, StyleRow as Row, StyleRun, StyleSummary as Summary};
use kinergy_train::PersonParams;
use kinergy_train::TrainError;
use kinergy_train::fidelity::{PersonFidelity, Predictor, TakeFidelity};
use kinergy_train::style::StyleTake;
use serde::Serialize;

use crate::common::{ArmArgs, Failure, ReadArgs, emit, print_json};
use kinergy_train::source::names_clip;

/// Arguments of `kinergy style`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The person's captures (files or folders of .bvh).
    #[arg(required = true, value_name = "CLIPS")]
    pub clips: Vec<PathBuf>,
    /// The person's parameters (`kinergy fit --per person -o person.json`) or field
    /// (`--field`).
    #[arg(long, value_name = "person.json")]
    pub params: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also write style.csv (one row per capture), summary.md, view.html (the first capture
    /// and its two reaches in a browser, `kinergy view`'s page, with the charts), the
    /// pictures speed.svg|png (the hand-speed profiles) and strip.svg|png (the first capture's
    /// reach, the character over the capture), and each capture's two full-body reaches as
    /// BVH (NAME.params.bvh,
    /// NAME.profile.bvh) into this folder (made if missing).
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub arm: ArmArgs,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// A [`Row`] as one flat line of style.csv.
#[derive(Serialize)]
struct CsvRow<'a> {
    clip: &'a str,
    onset: usize,
    end: usize,
    target_x_m: f64,
    target_y_m: f64,
    target_z_m: f64,
    captured_peak: f64,
    params_correlation: f64,
    params_peak: f64,
    params_peak_error: f64,
    params_arm_path: f64,
    params_error_m: f64,
    params_hand_over: bool,
    synergy_correlation: f64,
    synergy_peak: f64,
    profile_correlation: f64,
    profile_peak: f64,
    profile_peak_error: f64,
    profile_arm_path: f64,
    capture_duration_s: f64,
    capture_peak_m_s: f64,
    capture_sparc: f64,
    capture_largest_change_m_s: f64,
    e_ceiling: Option<f64>,
    e_minimum_jerk: Option<f64>,
    e_arm: Option<f64>,
    e_body: Option<f64>,
    e_profile: Option<f64>,
    duration_ratio_arm: Option<f64>,
    duration_ratio_body: Option<f64>,
    duration_ratio_profile: Option<f64>,
    peak_ratio_arm: Option<f64>,
    peak_ratio_body: Option<f64>,
    peak_ratio_profile: Option<f64>,
    time_to_peak_arm_s: Option<f64>,
    time_to_peak_body_s: Option<f64>,
    sparc_arm: Option<f64>,
    sparc_body: Option<f64>,
    largest_change_arm_m_s: Option<f64>,
    largest_change_body_m_s: Option<f64>,
    jump_arm: Option<bool>,
    jump_body: Option<bool>,
}

impl<'a> CsvRow<'a> {
    /// The row of `r` with `t`'s real-time figures, a column per predictor and measure
    /// (`e_body`, `duration_ratio_arm`, …; empty where the predictor was not made).
    fn new(r: &'a Row, t: &TakeFidelity) -> CsvRow<'a> {
        let f = |p: Predictor| t.get(p).map(|x| x.fidelity);
        let any = t.predicted.first().map(|p| p.fidelity);
        CsvRow {
            capture_duration_s: t.capture_duration_s,
            capture_peak_m_s: t.capture_peak_m_s,
            capture_sparc: any.map_or(f64::NAN, |f| f.capture_sparc),
            capture_largest_change_m_s: any.map_or(f64::NAN, |f| f.capture_largest_change),
            e_ceiling: f(Predictor::Ceiling).map(|x| x.error),
            e_minimum_jerk: f(Predictor::MinimumJerk).map(|x| x.error),
            e_arm: f(Predictor::Arm).map(|x| x.error),
            e_body: f(Predictor::Body).map(|x| x.error),
            e_profile: f(Predictor::Profile).map(|x| x.error),
            duration_ratio_arm: f(Predictor::Arm).map(|x| x.duration_ratio),
            duration_ratio_body: f(Predictor::Body).map(|x| x.duration_ratio),
            duration_ratio_profile: f(Predictor::Profile).map(|x| x.duration_ratio),
            peak_ratio_arm: f(Predictor::Arm).map(|x| x.peak_ratio),
            peak_ratio_body: f(Predictor::Body).map(|x| x.peak_ratio),
            peak_ratio_profile: f(Predictor::Profile).map(|x| x.peak_ratio),
            time_to_peak_arm_s: f(Predictor::Arm).map(|x| x.time_to_peak_s),
            time_to_peak_body_s: f(Predictor::Body).map(|x| x.time_to_peak_s),
            sparc_arm: f(Predictor::Arm).map(|x| x.sparc),
            sparc_body: f(Predictor::Body).map(|x| x.sparc),
            largest_change_arm_m_s: f(Predictor::Arm).map(|x| x.largest_change),
            largest_change_body_m_s: f(Predictor::Body).map(|x| x.largest_change),
            jump_arm: f(Predictor::Arm).map(|x| x.jumps),
            jump_body: f(Predictor::Body).map(|x| x.jumps),
            clip: &r.clip,
            onset: r.frames[0],
            end: r.frames[1],
            target_x_m: r.target_in_base_m[0],
            target_y_m: r.target_in_base_m[1],
            target_z_m: r.target_in_base_m[2],
            captured_peak: r.captured_peak,
            params_correlation: r.params_correlation,
            params_peak: r.params_peak,
            params_peak_error: r.params_peak_error,
            params_arm_path: r.params_arm_path,
            params_error_m: r.params_error_m,
            params_hand_over: r.params_hand_over,
            synergy_correlation: r.synergy_correlation,
            synergy_peak: r.synergy_peak,
            profile_correlation: r.profile_correlation,
            profile_peak: r.profile_peak,
            profile_peak_error: r.profile_peak_error,
            profile_arm_path: r.profile_arm_path,
        }
    }
}

#[derive(Serialize)]
struct Report<'a> {
    params: String,
    /// The real-time figures ([`PersonFidelity`]): what judges the person's delivery.
    fidelity: &'a PersonFidelity,
    /// The time-normalized scores (secondary).
    summary: &'a Summary,
    rows: &'a [Row],
}

/// Runs `kinergy style`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    let clips = crate::common::collect_clips(&args.clips)?;
    // Each capture's two reaches, written into -o's folder, checked with the folder against
    // the inputs before any work.
    let reach_files: Vec<[PathBuf; 2]> = match &args.output {
        Some(dir) => reach_names(&clips)
            .into_iter()
            .map(|name| ["params", "profile"].map(|kind| dir.join(format!("{name}.{kind}.bvh"))))
            .collect(),
        None => Vec::new(),
    };
    if let Some(dir) = &args.output {
        let mut inputs: Vec<&Path> = clips.iter().map(PathBuf::as_path).collect();
        inputs.push(&args.params);
        let mut files: Vec<PathBuf> = reach_files.iter().flatten().cloned().collect();
        files.extend(
            ["style.csv", "summary.md", kinergy_draw::style::VIEW]
                .into_iter()
                .chain(kinergy_draw::style::FILES)
                .map(|name| dir.join(name)),
        );
        crate::common::check_outputs(&inputs, &[crate::common::Output::Folder("-o", dir, &files)])?;
    }
    let person = crate::common::read_person(&args.params)?;
    // The folder is made before the first file is written into it (a missing folder used
    // to end the run with an OS error about style.csv), not before: a run that fails on
    // its first capture or on the parameters leaves no empty folder.
    let made = std::cell::Cell::new(false);
    let make_folder = || match args.output.as_deref() {
        Some(dir) if !made.replace(true) => crate::common::make_folder(dir),
        _ => Ok(()),
    };
    let mut rows = Vec::with_capacity(clips.len());
    let mut runs = Vec::with_capacity(clips.len());
    let mut motions = Vec::with_capacity(clips.len());
    let mut first = None;
    for (k, path) in clips.iter().enumerate() {
        let (clip, take) = compare_one(args, &person, path)?;
        if let Some(files) = reach_files.get(k) {
            make_folder()?;
            write_reaches(files, &take.capture, &take.run)?;
        }
        rows.push(take.run.row.clone());
        motions.push(take.motions);
        runs.push(take.run);
        if first.is_none() {
            first = Some((clip, take.capture));
        }
    }
    let summary = Summary::of(&rows);
    let fidelity = PersonFidelity::of(&motions);
    let text = markdown(&args.params, &fidelity, &summary, &rows);
    if let Some(dir) = &args.output {
        let flat: Vec<CsvRow<'_>> = rows
            .iter()
            .zip(&fidelity.takes)
            .map(|(r, t)| CsvRow::new(r, t))
            .collect();
        make_folder()?;
        crate::common::write_csv(&dir.join("style.csv"), &flat)?;
        kinergy_io::write_atomic(&dir.join("summary.md"), text.as_bytes())
            .map_err(|e| Failure::task(&dir.join("summary.md"), e))?;
        if let Some((clip, capture)) = &first {
            let who = person_name(&args.params);
            let pictures = kinergy_draw::style::StylePictures {
                who: &who,
                summary: &summary,
                runs: &runs,
                fidelity: &fidelity,
                clip,
                capture,
                arm: args.arm.side()?,
            };
            pictures.save_all(dir)?;
            pictures.save_view(dir)?;
        }
    }
    if args.json {
        return print_json(&Report {
            params: args.params.display().to_string(),
            fidelity: &fidelity,
            summary: &summary,
            rows: &rows,
        });
    }
    emit(&text)
}

/// The person's name in the pictures' titles: the parameters file's stem.
fn person_name(params: &Path) -> String {
    params
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| params.display().to_string())
}

/// One capture: its main reach's profile and arm path against the two reaches toward its
/// target; the clip and the capture come back for the pictures.
fn compare_one(
    args: &Args,
    person: &PersonParams,
    path: &Path,
) -> Result<(Clip, StyleTake), Failure> {
    let (clip, _) = args.read.read(path)?;
    let joints = args.arm.find(&clip, path)?;
    let name = path.display().to_string();
    // As `synthesize` does: parameters fitted on another arm or skeleton say so (the
    // comparison still runs: a person's style may be tried on anyone).
    let record = person.record();
    let fitted = record
        .as_ref()
        .and_then(|r| r.arm(|clip| names_clip(clip, path)));
    if let Some(fitted) = fitted {
        let here =
            kinergy_train::measured_arm(&clip, &joints).map_err(|e| Failure::input(path, e))?;
        if let Some(warning) = kinergy_train::synthesize::arm_mismatch(fitted, &here) {
            eprintln!("warning: {name}: {warning}");
        }
    }
    let take =
        StyleTake::run(&clip, &joints, &name, person, args.arm.side()?).map_err(|e| match e {
            TrainError::Body(e @ ReachError::Params { .. }) => {
                crate::common::person_failure(&args.params, e)
            }
            TrainError::Body(e) if kinergy_io::Classify::kind(&e).is_input() => {
                Failure::input(path, e)
            }
            e @ TrainError::Reach { .. } => Failure::input(path, e),
            e => Failure::from(e).naming(&name),
        })?;
    Ok((clip, take))
}

/// Writes the capture's two full-body reaches (with the person's parameters, with the
/// default profile) to `files` (`DIR/NAME.params.bvh`, `DIR/NAME.profile.bvh`).
fn write_reaches(
    files: &[PathBuf; 2],
    capture: &StyleCapture,
    run: &StyleRun,
) -> Result<(), Failure> {
    for (out, motion) in files.iter().zip([&run.params_motion, &run.profile_motion]) {
        let clip = capture
            .character()
            .to_clip(&motion.poses, motion.frame_time)
            .map_err(|e| Failure::task(out, e))?;
        crate::common::write_clip(out, &clip, &Default::default())?;
    }
    Ok(())
}

/// Each capture's NAME for its reaches' files: its file stem, `-2`, `-3`, … after a stem
/// already taken.
fn reach_names(clips: &[PathBuf]) -> Vec<String> {
    let mut taken = std::collections::HashSet::new();
    clips
        .iter()
        .map(|path| {
            let stem = path
                .file_stem()
                .map_or_else(|| "reach".to_string(), |s| s.to_string_lossy().into_owned());
            let mut name = stem.clone();
            let mut n = 1;
            while !taken.insert(name.clone()) {
                n += 1;
                name = format!("{stem}-{n}");
            }
            name
        })
        .collect()
}

/// The real-time figures, then the time-normalized summary and rows, as markdown tables.
fn markdown(params: &Path, f: &PersonFidelity, s: &Summary, rows: &[Row]) -> String {
    let n = s.captures;
    let mut out = format!(
        "# Style: {} against {n} captures\n\n{}## Time-normalized (secondary)\n\nHand speed relative to the shoulder, from the \
         reach's onset to where, past its peak, it falls to the share of the peak at which \
         the captured segment ends, time-normalized: r is Pearson's correlation with the \
         captured profile, peak error |the fraction of the movement at which the speed peaks \
         − the captured one's|. Arm path: the RMS distance of elbow, wrist and hand from the \
         captured ones, each from the shoulder in the body's frame at the reach's start (y up, z from \
         the other shoulder to this one), \
         time-normalized, in arm lengths (0: the same path).\n\n\
         | reach | mean r | mean peak error | mean arm path |\n|---|---|---|---|\n\
         | with the person's parameters | {:.3} | {:.3} | {:.3} |\n\
         | its synergy's own part ({} of {n} handed over) | {:.3} | {:.3} | |\n\
         | default profile | {:.3} | {:.3} | {:.3} |\n\n\
         The person's parameters beat the default profile on {} of {n} captures for r, {} of \
         {n} for the peak error, {} of {n} for the arm path.\n\n",
        params.display(),
        realtime_markdown(f),
        s.params_correlation,
        s.params_peak_error,
        s.params_arm_path,
        s.hand_overs,
        s.synergy_correlation,
        s.synergy_peak_error,
        s.profile_correlation,
        s.profile_peak_error,
        s.profile_arm_path,
        s.params_better_correlation,
        s.params_better_peak,
        s.params_better_arm_path,
    );
    out.push_str(
        "| capture | frames | captured peak | r (params) | peak error (params) | arm path \
         (params) | r (profile) | peak error (profile) | arm path (profile) | hand-over |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {}..{} | {:.2} | {:.3} | {:.2} | {:.3} | {:.3} | {:.2} | {:.3} | {} |\n",
            r.clip,
            r.frames[0],
            r.frames[1],
            r.captured_peak,
            r.params_correlation,
            r.params_peak_error,
            r.params_arm_path,
            r.profile_correlation,
            r.profile_peak_error,
            r.profile_arm_path,
            if r.params_hand_over { "yes" } else { "no" }
        ));
    }
    out
}

/// The real-time tables: per predictor over the captures, then per capture.
fn realtime_markdown(f: &PersonFidelity) -> String {
    let mut out = format!(
        "## In real time\n\nHand speed relative to the shoulder from each motion's onset, in \
         seconds, against the capture's main reach: e = RMS over time of (v − v_capture) ÷ the \
         capture's peak speed, the shorter series padded with zeros. The ceiling predicts each \
         capture by the person's other captures' mean profile (leave-one-out), minimum jerk by \
         a bell over the capture's path lasting the others' mean duration. Captures: mean \
         duration {:.2} s, peak {:.2} m/s, SPARC {:.2}.\n\n\
         | predictor | mean e | × ceiling | beats minimum jerk | duration ÷ capture | peak ÷ \
         capture | time to peak (s) | SPARC | speed jumps |\n|---|---|---|---|---|---|---|---|---|\n",
        f.capture_duration_s, f.capture_peak_m_s, f.capture_sparc
    );
    // NaN where there is no ceiling to compare with (fidelity's documented value).
    let no_ceiling = f
        .summaries
        .iter()
        .any(|s| !s.error_over_ceiling.is_finite());
    for s in &f.summaries {
        let over_ceiling = if s.error_over_ceiling.is_finite() {
            format!("{:.2}", s.error_over_ceiling)
        } else {
            "—".to_string()
        };
        out.push_str(&format!(
            "| {} | {:.3} | {} | {} of {} | {:.2} | {:.2} | {:.2} | {:.2} | {} |\n",
            s.predictor.label(),
            s.error,
            over_ceiling,
            s.beats_minimum_jerk,
            s.takes,
            s.duration_ratio,
            s.peak_ratio,
            s.time_to_peak_s,
            s.sparc,
            s.jumps
        ));
    }
    if no_ceiling {
        out.push_str(
            "\n— in × ceiling: no ceiling to compare with on every capture. The ceiling predicts \
             a capture from the person's other captures, so it needs at least two of them.\n",
        );
    }
    out.push_str(
        "\n| capture | duration (s) | peak (m/s) | e ceiling | e minimum jerk | e arm | e body | \
         e profile | body duration ÷ capture | body peak ÷ capture | body jump |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let e = |t: &TakeFidelity, p: Predictor| {
        t.get(p)
            .map_or_else(|| "–".to_string(), |x| format!("{:.3}", x.fidelity.error))
    };
    for t in &f.takes {
        let body = t.get(Predictor::Body).map(|x| x.fidelity);
        out.push_str(&format!(
            "| {} | {:.2} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            t.name,
            t.capture_duration_s,
            t.capture_peak_m_s,
            e(t, Predictor::Ceiling),
            e(t, Predictor::MinimumJerk),
            e(t, Predictor::Arm),
            e(t, Predictor::Body),
            e(t, Predictor::Profile),
            body.map_or_else(|| "–".into(), |b| format!("{:.2}", b.duration_ratio)),
            body.map_or_else(|| "–".into(), |b| format!("{:.2}", b.peak_ratio)),
            body.map_or_else(
                || "–".into(),
                |b| if b.jumps { "yes" } else { "no" }.to_string()
            ),
        ));
    }
    out.push('\n');
    out
}
