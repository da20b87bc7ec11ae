//! `kinergy inspect`: what a capture holds.

use std::path::PathBuf;

use kinergy_motion::{
    ArmJoints, Clip, GlitchOptions, ImportReport, PositionReading, RootReadingBasis, Side,
    UpDetection, find_glitches,
};
use serde::Serialize;

use std::fmt::Write as _;

use crate::common::{Failure, ReadArgs, emit, print_json};

/// Arguments of `kinergy inspect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The BVH file.
    file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    read: ReadArgs,
    /// The arm's joints by name (clavicle,shoulder,elbow,wrist), when the search fails.
    #[arg(long, value_delimiter = ',', value_name = "JOINTS")]
    chain: Option<Vec<String>>,
}

#[derive(Debug, Serialize)]
struct Report {
    file: String,
    joints: Vec<JointInfo>,
    joint_count: usize,
    end_site_count: usize,
    channel_count: usize,
    frame_count: usize,
    frame_time: f64,
    frame_rate: f64,
    duration: f64,
    unit: String,
    unit_guessed: bool,
    meters_per_unit: f64,
    extent_in_file_units: f64,
    root_reading: Option<&'static str>,
    /// Why the root's channels were read so: the lowest point's height under each reading.
    root_reading_reason: Option<RootReasonInfo>,
    position_readings: Vec<(String, &'static str)>,
    /// The file's up axis (`y`, `z`, `x`, `-y`, …); the clip is read into Y-up either way.
    up_axis: &'static str,
    up_detected: bool,
    /// `given`, `joint names`, `body shape` or `assumed`.
    up_basis: &'static str,
    #[serde(skip)]
    up_detection: UpDetection,
    /// Highest minus lowest joint along Y in the first frame, meters.
    first_frame_height_m: Option<f64>,
    /// The lowest joint's height in the first frame, meters.
    first_frame_lowest_m: Option<f64>,
    /// The thresholds glitches were found with.
    glitch_min_size_m: f64,
    glitch_min_ratio: f64,
    glitches: Vec<GlitchInfo>,
    arms: Vec<ArmInfo>,
}

#[derive(Debug, Serialize)]
struct RootReasonInfo {
    #[serde(skip)]
    kind: RootReadingBasis,
    /// `given`, `nearer the ground`, `tie` or `no frames`.
    basis: &'static str,
    lowest_if_added_m: f64,
    lowest_if_replaced_m: f64,
}

#[derive(Debug, Serialize)]
struct GlitchInfo {
    frame: usize,
    time_s: f64,
    joint: String,
    /// How far the joint is from the midpoint of its neighbours' positions, meters.
    size_m: f64,
    /// Joints of its subtree glitching with it (itself included), and the largest jump among them.
    joints: usize,
    largest_m: f64,
}

#[derive(Debug, Serialize)]
struct JointInfo {
    name: String,
    parent: Option<String>,
    end_site: bool,
    depth: usize,
    channels: Vec<&'static str>,
    offset_m: [f64; 3],
}

#[derive(Debug, Serialize)]
struct ArmInfo {
    side: String,
    found: bool,
    joints: Vec<String>,
    message: Option<String>,
    upper_arm_m: Option<f64>,
    forearm_m: Option<f64>,
    hand_m: Option<f64>,
    peak_hand_speed_m_s: Option<f64>,
    peak_hand_speed_time_s: Option<f64>,
}

/// Runs `kinergy inspect`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let (clip, import) = args.read.read(&args.file)?;
    let arms = match &args.chain {
        Some(names) => {
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            let arm = ArmJoints::from_names(clip.skeleton(), &names)
                .map_err(|e| crate::common::args::arm_failure(e, &clip, &args.file, None))?;
            let side = arm
                .side
                .map_or_else(|| "given".to_string(), |s| s.to_string());
            vec![arm_info(&clip, Ok(arm), side)]
        }
        None => [Side::Right, Side::Left]
            .into_iter()
            .map(|side| {
                arm_info(
                    &clip,
                    ArmJoints::find(clip.skeleton(), side),
                    side.to_string(),
                )
            })
            .collect(),
    };
    let glitches = find_glitches(&clip, &GlitchOptions::default())
        .map_err(|e| Failure::input(&args.file, e))?
        .into_iter()
        .map(|g| GlitchInfo {
            frame: g.frame,
            time_s: g.frame as f64 * clip.frame_time(),
            joint: clip.skeleton().joint(g.joint).name.clone(),
            size_m: g.size,
            joints: g.joints,
            largest_m: g.largest,
        })
        .collect();
    let report = report(args, &clip, &import, arms, glitches);
    if args.json {
        print_json(&report)
    } else {
        emit(&text(&report))
    }
}

fn arm_info(clip: &Clip, found: kinergy_motion::Result<ArmJoints>, side: String) -> ArmInfo {
    let arm = match found {
        Ok(arm) => arm,
        Err(e) => {
            return ArmInfo {
                side,
                found: false,
                joints: vec![],
                message: Some(e.to_string()),
                upper_arm_m: None,
                forearm_m: None,
                hand_m: None,
                peak_hand_speed_m_s: None,
                peak_hand_speed_time_s: None,
            };
        }
    };
    let lengths = arm.lengths(clip).ok();
    // One-frame glitches would make two spikes of speed: the peak ignores them.
    let peak = clip
        .trajectory(&[arm.end_effector()])
        .ok()
        .map(|t| t.speed_without_glitches(0, &GlitchOptions::default()))
        .and_then(|v| {
            v.iter()
                .copied()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(&b.1))
        });
    ArmInfo {
        side,
        found: true,
        joints: arm
            .names(clip.skeleton())
            .into_iter()
            .map(String::from)
            .collect(),
        message: None,
        upper_arm_m: lengths.map(|l| l.upper_arm),
        forearm_m: lengths.map(|l| l.forearm),
        hand_m: lengths.map(|l| l.hand),
        peak_hand_speed_m_s: peak.map(|(_, v)| v),
        peak_hand_speed_time_s: peak.map(|(i, _)| i as f64 * clip.frame_time()),
    }
}

fn report(
    args: &Args,
    clip: &Clip,
    import: &ImportReport,
    arms: Vec<ArmInfo>,
    glitches: Vec<GlitchInfo>,
) -> Report {
    let s = clip.skeleton();
    let reading = |r: PositionReading| match r {
        PositionReading::AddToOffset => "add",
        PositionReading::ReplaceOffset => "replace",
    };
    let root_has_positions = s
        .joint(0)
        .dofs
        .iter()
        .any(|d| matches!(d, kinergy_motion::Dof::Translation(_)));
    let first = clip
        .frame(0)
        .and_then(|pose| s.world_positions(pose).ok())
        .map(|p| {
            let ys = p.iter().map(|p| p.y);
            let lo = ys.clone().fold(f64::INFINITY, f64::min);
            (ys.fold(f64::NEG_INFINITY, f64::max) - lo, lo)
        });
    let glitch = GlitchOptions::default();
    Report {
        file: args.file.display().to_string(),
        joints: s
            .joints()
            .iter()
            .enumerate()
            .map(|(i, j)| JointInfo {
                name: j.name.clone(),
                parent: j.parent.map(|p| s.joint(p).name.clone()),
                end_site: j.end_site,
                depth: s.path(0, i).map_or(0, |p| p.len() - 1),
                channels: j.dofs.iter().map(|d| d.channel_name()).collect(),
                offset_m: j.offset.into(),
            })
            .collect(),
        joint_count: s.joints().iter().filter(|j| !j.end_site).count(),
        end_site_count: s.joints().iter().filter(|j| j.end_site).count(),
        channel_count: s.dof_count(),
        frame_count: clip.frame_count(),
        frame_time: clip.frame_time(),
        frame_rate: clip.frame_rate(),
        duration: clip.duration(),
        unit: import.unit.name().to_string(),
        unit_guessed: import.unit_guessed,
        meters_per_unit: import.unit.meters(),
        extent_in_file_units: import.extent_in_file_units,
        root_reading: root_has_positions.then(|| reading(s.joint(0).position_reading)),
        root_reading_reason: import.root.map(|r| RootReasonInfo {
            kind: r.basis,
            basis: r.basis.name(),
            lowest_if_added_m: r.lowest_if_added,
            lowest_if_replaced_m: r.lowest_if_replaced,
        }),
        position_readings: import
            .position_readings
            .iter()
            .map(|(n, r)| (n.clone(), reading(*r)))
            .collect(),
        up_axis: import.up.name(),
        up_detected: import.up_detected(),
        up_basis: import.up_detection.name(),
        up_detection: import.up_detection,
        first_frame_height_m: first.map(|(h, _)| h),
        first_frame_lowest_m: first.map(|(_, lo)| lo),
        glitch_min_size_m: glitch.min_size,
        glitch_min_ratio: glitch.min_ratio,
        glitches,
        arms,
    }
}

fn text(r: &Report) -> String {
    let mut out = String::new();
    let o = &mut out;
    let _ = writeln!(o, "{}", r.file);
    let _ = writeln!(
        o,
        "  joints     {} (+{} End Sites), {} channels",
        r.joint_count, r.end_site_count, r.channel_count
    );
    let _ = writeln!(
        o,
        "  frames     {} at {:.3} fps (frame time {} s), {:.3} s",
        r.frame_count, r.frame_rate, r.frame_time, r.duration
    );
    let _ = writeln!(
        o,
        "  unit       {} ({}; 1 unit = {:.6} m; first-frame extent {:.2} units = {:.3} m)",
        r.unit,
        if r.unit_guessed { "guessed" } else { "given" },
        r.meters_per_unit,
        r.extent_in_file_units,
        r.extent_in_file_units * r.meters_per_unit
    );
    let _ = writeln!(
        o,
        "  up         {} ({}; read into Y-up, --up to choose)",
        r.up_axis,
        match r.up_detection {
            UpDetection::Given => "given".to_string(),
            UpDetection::Assumed =>
                "assumed: neither joint names nor the body's shape told".to_string(),
            _ => format!("detected from the {}", r.up_basis),
        }
    );
    let _ = match r.root_reading {
        Some(reading) => writeln!(
            o,
            "  root       position channels {} the OFFSET{} (--positions to choose)",
            if reading == "add" {
                "add to"
            } else {
                "replace"
            },
            r.root_reading_reason
                .as_ref()
                .map_or_else(String::new, root_reason)
        ),
        None => writeln!(o, "  root       no position channels"),
    };
    let others: Vec<_> = r.position_readings.iter().skip(1).collect();
    if !others.is_empty() {
        let replaced = others.iter().filter(|(_, x)| *x == "replace").count();
        let _ = writeln!(
            o,
            "             {} other joints have position channels ({} replace, {} add to their OFFSET)",
            others.len(),
            replaced,
            others.len() - replaced
        );
    }
    if let (Some(h), Some(lo)) = (r.first_frame_height_m, r.first_frame_lowest_m) {
        let _ = writeln!(
            o,
            "  body       {h:.3} m from lowest to highest joint in the first frame; lowest {}",
            height(lo)
        );
    }
    glitches(o, r);
    arms(o, r);
    let _ = writeln!(o, "  hierarchy");
    for j in &r.joints {
        let pad = "  ".repeat(j.depth);
        if j.end_site {
            let _ = writeln!(o, "    {pad}End Site");
        } else {
            let _ = writeln!(o, "    {pad}{} [{}]", j.name, j.channels.join(" "));
        }
    }
    out
}

/// The glitch lines of [`text`].
fn glitches(o: &mut String, r: &Report) {
    let _ = match r.glitches.len() {
        0 => writeln!(
            o,
            "  glitches   none (one-frame jumps of {:.0} cm or more)",
            r.glitch_min_size_m * 100.0
        ),
        n => writeln!(
            o,
            "  glitches   {n} one-frame jump{} of {:.0} cm or more (hand speeds ignore them):",
            if n == 1 { "" } else { "s" },
            r.glitch_min_size_m * 100.0
        ),
    };
    const SHOWN: usize = 20;
    for g in r.glitches.iter().take(SHOWN) {
        let _ = write!(
            o,
            "             frame {} ({:.3} s) {} jumps {:.1} cm",
            g.frame,
            g.time_s,
            g.joint,
            g.size_m * 100.0
        );
        let _ = if g.joints > 1 {
            writeln!(
                o,
                ", with {} joints below it (up to {:.1} cm)",
                g.joints - 1,
                g.largest_m * 100.0
            )
        } else {
            writeln!(o)
        };
    }
    if r.glitches.len() > SHOWN {
        let _ = writeln!(
            o,
            "             … and {} more (--json lists them all)",
            r.glitches.len() - SHOWN
        );
    }
}

/// The arm lines of [`text`].
fn arms(o: &mut String, r: &Report) {
    for arm in &r.arms {
        if !arm.found {
            let _ = writeln!(
                o,
                "  {:<5} arm  not found: {}",
                arm.side,
                arm.message.as_deref().unwrap_or("")
            );
            continue;
        }
        let _ = writeln!(
            o,
            "  {:<5} arm  {}",
            arm.side.to_string(),
            arm.joints.join(" → ")
        );
        if let (Some(u), Some(f), Some(h)) = (arm.upper_arm_m, arm.forearm_m, arm.hand_m) {
            let _ = writeln!(
                o,
                "             upper arm {u:.3} m, forearm {f:.3} m, hand {h:.3} m"
            );
        }
        if let (Some(v), Some(t)) = (arm.peak_hand_speed_m_s, arm.peak_hand_speed_time_s) {
            let _ = writeln!(o, "             peak hand speed {v:.3} m/s at {t:.3} s");
            if t < 1.5 * r.frame_time && v > 5.0 {
                let _ = writeln!(
                    o,
                    "             (a jump at the first frames: the clip may start with a rest pose, as cgspeed conversions do)"
                );
            }
        }
    }
}

/// `"4.2 cm above y = 0"`, `"96.1 cm below y = 0"`.
fn height(y: f64) -> String {
    let cm = y * 100.0;
    if cm.abs() < 0.05 {
        "at y = 0".to_string()
    } else if cm > 0.0 {
        format!("{cm:.1} cm above y = 0")
    } else {
        format!("{:.1} cm below y = 0", -cm)
    }
}

/// Why the root reads as it does: the lowest point under each reading.
fn root_reason(r: &RootReasonInfo) -> String {
    match r.kind {
        RootReadingBasis::Given => " (given)".to_string(),
        RootReadingBasis::NoFrames => " (no frames to measure)".to_string(),
        RootReadingBasis::Tie => format!(
            " (either way the lowest joint is {})",
            height(r.lowest_if_added_m)
        ),
        _ => format!(
            ": the lowest joint is {} added, {} replaced",
            height(r.lowest_if_added_m),
            height(r.lowest_if_replaced_m)
        ),
    }
}
