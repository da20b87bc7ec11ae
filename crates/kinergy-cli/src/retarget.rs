//! `kinergy retarget`: a motion moved onto another skeleton ([`kinergy_motion::Retargeter`]):
//! joints matched by role (the finders, a built-in map or a JSON map), the root's path scaled
//! by leg length, hands and feet on their scaled paths, planted feet held; with `--params`, the
//! retargeted reach is then driven by that person's synergy on the new body
//! ([`kinergy_train::synthesize`]). The command reads, calls and reports.

use std::path::{Path, PathBuf};

use kinergy_motion::{
    BodyJoints, Clip, ExportOptions, RetargetReport, Retargeter, Side, Skeleton, TargetArms,
};
use kinergy_train::synthesize::{Drive, SynthesizeRequest};
use serde::Serialize;

use crate::common::{Failure, ReadArgs, emit, print_json, write_clip};

/// Arguments of `kinergy retarget`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The motion to move.
    #[arg(value_name = "IN.bvh")]
    pub input: PathBuf,
    /// The skeleton to move it onto: a BVH whose hierarchy (and zero pose) the output takes;
    /// its motion is not used.
    #[arg(long, value_name = "TEMPLATE.bvh")]
    pub to: PathBuf,
    /// Where to write the retargeted BVH (atomically; `-` for standard output), in the
    /// template's unit and up axis.
    #[arg(short, long, value_name = "OUT.bvh")]
    pub output: PathBuf,
    /// The input's roles: `auto` (found by joint names), a built-in map (cmu, bandai, mixamo,
    /// cc) or a JSON map of roles to joint names (`{"pelvis": "Hips", "spine": [...], ...}`).
    #[arg(long, default_value = "auto", value_name = "auto|NAME|MAP.json")]
    pub map: String,
    /// The template's roles, as `--map`.
    #[arg(long, default_value = "auto", value_name = "auto|NAME|MAP.json")]
    pub to_map: String,
    /// A person's parameters (`kinergy fit`): the retargeted reach is synthesized again on the
    /// new body, driven by their synergy (the main reach of the hand speed; the other arm and
    /// the body keep the retargeted motion).
    #[arg(long, value_name = "P.json")]
    pub params: Option<PathBuf>,
    /// With --params, which arm reaches (default: the one the parameters were fitted on).
    #[arg(long, value_name = "SIDE", requires = "params")]
    pub arm: Option<Side>,
    /// Whose arms the output has: the template's (`template`), or the source performer's
    /// upper arms and forearms scaled with the body (`source`: the template's skeleton with
    /// the performer's arm proportions, so a person's synergy replays on it as fitted).
    #[arg(long, default_value = "template", value_name = "template|source", value_parser = arms)]
    pub arms: TargetArms,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// `--arms`: [`TargetArms`]'s own parsing.
fn arms(s: &str) -> Result<TargetArms, String> {
    s.parse()
        .map_err(|e: kinergy_motion::MotionError| e.to_string())
}

#[derive(Serialize)]
struct Report {
    input: String,
    template: String,
    output: String,
    frames: usize,
    frame_rate_hz: f64,
    /// Whose arms the output has.
    arms: TargetArms,
    #[serde(flatten)]
    retarget: RetargetReport,
    /// With --params: the synthesized reach's frames and its final distance from the target.
    driven: Option<Driven>,
}

#[derive(Serialize)]
struct Driven {
    params: String,
    arm: Vec<String>,
    frames: usize,
    final_error_m: f64,
    stop: &'static str,
    /// The synthesized arm's motion distance from the retargeted capture's arm over the reach.
    distance_to_capture_m: Option<f64>,
}

/// The roles `choice` names on `skeleton` (read from `path`; `flag` names the option).
fn body(skeleton: &Skeleton, choice: &str, path: &Path, flag: &str) -> Result<BodyJoints, Failure> {
    BodyJoints::choose(skeleton, choice)
        .map_err(|e| Failure::Input(format!("{}: {e} ({flag} {choice})", path.display())))
}

/// Runs `kinergy retarget`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    {
        use crate::common::{Output, check_outputs};
        let mut inputs = vec![args.input.as_path(), args.to.as_path()];
        inputs.extend(args.params.as_deref());
        for map in [&args.map, &args.to_map] {
            if map.ends_with(".json") {
                inputs.push(Path::new(map));
            }
        }
        check_outputs(&inputs, &[Output::File("-o", &args.output)])?;
    }
    let person = args
        .params
        .as_deref()
        .map(crate::common::read_person)
        .transpose()?;
    let (clip, _) = args.read.read(&args.input)?;
    let (template, template_report) = kinergy_motion::read_clip(&args.to, &Default::default())
        .map_err(|e| Failure::input(&args.to, e))?;
    let from = body(clip.skeleton(), &args.map, &args.input, "--map")?;
    let to = body(template.skeleton(), &args.to_map, &args.to, "--to-map")?;
    let onto = |e: kinergy_motion::MotionError| {
        Failure::Input(format!(
            "{} → {}: {e}",
            args.input.display(),
            args.to.display()
        ))
    };
    let target = args
        .arms
        .skeleton(&clip, &from, template.skeleton().clone(), &to)
        .map_err(onto)?;
    let retargeter = Retargeter::new(&clip, from, target, to).map_err(onto)?;
    let done = retargeter.run(&clip)?;
    let mut out: Clip = done.clip;
    let mut driven = None;
    if let (Some(person), Some(path)) = (person, &args.params) {
        let request = SynthesizeRequest::main_reach(
            Drive::Person {
                params: Box::new(person),
                path: Some(path.clone()),
            },
            args.arm,
        );
        let synthesized = request.run(&out, &args.input).map_err(|e| {
            Failure::Task(format!(
                "{}: the retargeted reach driven by {}: {}",
                args.input.display(),
                path.display(),
                e.source
            ))
        })?;
        if let Some(warning) = &synthesized.warning {
            eprintln!("warning: {warning}");
        }
        let r = &synthesized.report;
        driven = Some(Driven {
            params: path.display().to_string(),
            arm: r.arm.clone(),
            frames: r.frames,
            final_error_m: r.final_error_m,
            stop: r.stop,
            distance_to_capture_m: r.distance_to_capture_m,
        });
        out = synthesized.clip;
    }
    let options = ExportOptions {
        unit: template_report.unit,
        ..Default::default()
    };
    write_clip(&args.output, &out, &options)?;
    let report = Report {
        input: args.input.display().to_string(),
        template: args.to.display().to_string(),
        output: args.output.display().to_string(),
        frames: out.frame_count(),
        frame_rate_hz: out.frame_rate(),
        arms: args.arms,
        retarget: done.report,
        driven,
    };
    if args.json {
        return print_json(&report);
    }
    let r = &report.retarget;
    let mm = |m: f64| m * 1e3;
    let mut text = format!(
        "{}: {} frames at {:.4} Hz onto {} ({} roles matched)\n  root's path × {:.3} \
         (standing pelvis heights), arms × {:.3} right, {:.3} left\n  feet: {} and {} plants \
         held (slide ≤ {:.2} mm); farthest from their goals {:.1} / {:.1} mm; hands {:.1} / \
         {:.1} mm\n",
        report.output,
        report.frames,
        report.frame_rate_hz,
        report.template,
        r.roles.len(),
        r.leg_scale,
        r.arm_scale[0],
        r.arm_scale[1],
        r.plants[0].len(),
        r.plants[1].len(),
        mm(r.foot_slide_m),
        mm(r.foot_error_m[0]),
        mm(r.foot_error_m[1]),
        mm(r.hand_error_m[0]),
        mm(r.hand_error_m[1]),
    );
    if args.arms == TargetArms::Source {
        text += "  arms: the source performer's upper arms and forearms, scaled with the body\n";
    }
    if r.pelvis_drop_m > 0.0 {
        text += &format!(
            "  the pelvis came down up to {:.1} mm where a foot was beyond the leg's reach\n",
            mm(r.pelvis_drop_m)
        );
    }
    if r.bend_limited_frames > 0 {
        text += &format!(
            "  a knee or elbow held straight or at {}° on {} frames\n",
            kinergy_motion::retarget::MAX_BEND_DEG,
            r.bend_limited_frames
        );
    }
    if !r.unmapped.is_empty() {
        let shown = r
            .unmapped
            .iter()
            .take(8)
            .cloned()
            .collect::<Vec<_>>()
            .join(", ");
        let more = match r.unmapped.len() {
            n if n > 8 => format!(", … ({n} in all; --json lists them)"),
            _ => String::new(),
        };
        text += &format!(
            "  joints of no role (their parent's turn, or the source's by name): {shown}{more}\n"
        );
    }
    if let Some(d) = &report.driven {
        text += &format!(
            "  the reach driven by {} ({}): {} frames, {:.1} mm from its target ({})\n",
            d.params,
            d.arm.join(", "),
            d.frames,
            mm(d.final_error_m),
            d.stop
        );
    }
    emit(&text)
}
