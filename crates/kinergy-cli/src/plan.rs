//! `kinergy plan`: collision-free reaching and manipulation in a scene (Kallmann 2005),
//! written as BVH with fingers.

use std::path::{Path, PathBuf};
use std::time::Duration;

use kinergy_motion::Side;
use kinergy_plan::PlanError;
use kinergy_plan::hand::HandShape;
use kinergy_plan::report::ObjectReport;
use kinergy_plan::rrt::Warp;
use kinergy_plan::scene::Scene;
use kinergy_plan::space::HandTarget;
use kinergy_plan::task::{Manipulation, Planner, TaskSettings};
use kinergy_reach::character::Limb;
use kinergy_reach::controller::ArmDrive;
use kinergy_reach::drive::PersonArm;
use nalgebra::Point3;
use serde::Serialize;

use crate::common::{Failure, check_optional, check_range, emit, limits, print_json};

/// A manipulation task.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Task {
    /// Grasp `--object`, carry it so its origin ends at `--to`, let go and come back.
    Relocate,
    /// Reach, approach and close the hand on `--object`.
    Grasp,
    /// Grasp the drawer `--object` and pull it open by `--distance` meters.
    Pull,
    /// Grasp the drawer `--object` and push it in by `--distance` meters.
    Push,
}

/// Arguments of `kinergy plan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scene (JSON, see the bookshelf example in examples/bookshelf/).
    #[arg(long, value_name = "S.json")]
    pub scene: PathBuf,
    /// Reach a hand target: the grip point (palm centre) in world meters, optionally with the
    /// hand's rotation from its rest orientation as a quaternion.
    #[arg(
        long,
        value_name = "x,y,z[,qx,qy,qz,qw]",
        allow_hyphen_values = true,
        conflicts_with = "task",
        required_unless_present = "task"
    )]
    pub target: Option<String>,
    /// A manipulation task on a scene object.
    #[arg(long, value_enum, requires = "object")]
    pub task: Option<Task>,
    /// The object the task acts on.
    #[arg(long, value_name = "NAME")]
    pub object: Option<String>,
    /// Where a relocated object's origin goes, world meters.
    #[arg(long, value_name = "x,y,z", allow_hyphen_values = true)]
    pub to: Option<String>,
    /// How far a drawer moves, meters, -2 to 2.
    #[arg(long, default_value_t = 0.2, value_name = "D")]
    pub distance: f64,
    /// The acting arm: right or left.
    #[arg(long, default_value = "right", value_name = "SIDE")]
    pub arm: Side,
    /// Seed of the planner's random stream (same seed, same motion).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Time budget of each planned phase, milliseconds, 1 to 600000 (the iteration budget, 5000, applies
    /// too; a search stopped by time depends on the machine's speed).
    #[arg(long, value_name = "N")]
    pub budget_ms: Option<u64>,
    /// Where to write the motion (BVH with fingers, 60 Hz, centimeters, written atomically).
    #[arg(short, long, value_name = "OUT.bvh")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// A person's parameters (`kinergy fit -o person.json`, or a field, which gives the
    /// person's vector for the reach's target): the planned phases are played with the
    /// person's bell — the peak time and spread of their synergy's hand speed on a reach in
    /// front of the acting shoulder — instead of Kallmann's cubic, and a reach is finished by
    /// their synergy controller from the first waypoint of the planned path whose approach is
    /// free of obstacles (every frame checked), then settled onto the grip.
    #[arg(long, value_name = "person.json")]
    pub params: Option<PathBuf>,
}

#[derive(Serialize)]
struct PlannedReport {
    iterations: usize,
    nodes: usize,
    plan_ms: f64,
    smooth_ms: f64,
    length_before_m: f64,
    length_after_m: f64,
    configs_before: usize,
    configs_after: usize,
}

#[derive(Serialize)]
struct PhaseReport {
    name: String,
    first_frame: usize,
    last_frame: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    planned: Option<PlannedReport>,
    /// For a reach the person's synergy finished (`--params`).
    #[serde(skip_serializing_if = "Option::is_none")]
    synergy: Option<SynergyReport>,
}

/// How the person's synergy finished a planned reach.
#[derive(Serialize)]
struct SynergyReport {
    /// How far along the smoothed path it started, meters of the planner's distance (0: the
    /// whole reach).
    from_m: f64,
    /// The smoothed path's length, meters of the planner's distance.
    path_m: f64,
    /// Why approaches from earlier points were not used.
    rejected: Vec<String>,
    /// The frame in the motion where it takes over (the last of the planned path; it moves
    /// the arm from the next).
    first_frame: usize,
    /// Frames it drove.
    frames: usize,
    /// The frame in the motion from which plain IK drove after the synergy, if it did.
    plain_ik_from: Option<usize>,
    /// The hand's distance to the planned goal's when it arrived, meters.
    distance_m: f64,
}

#[derive(Serialize)]
struct Report {
    output: String,
    scene: String,
    triangles: usize,
    task: String,
    seed: u64,
    frames: usize,
    frame_time_s: f64,
    duration_s: f64,
    phases: Vec<PhaseReport>,
    objects: Vec<ObjectReport>,
    /// How the planned phases were played over time.
    timing: TimingReport,
}

/// The time warp of the planned phases.
#[derive(Serialize)]
struct TimingReport {
    /// `cubic` (Kallmann's) or `person` (`--params`).
    warp: &'static str,
    /// When the speed peaks, as a fraction of a phase.
    peak: f64,
    /// The speed's standard deviation over a phase's fraction.
    spread: f64,
}

/// `x,y,z` or `x,y,z,qx,qy,qz,qw` (finite numbers).
fn parse_target(text: &str) -> Result<HandTarget, Failure> {
    let bad = |why: &str| Failure::Input(format!("--target `{text}`: {why}"));
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad("expected comma-separated numbers x,y,z[,qx,qy,qz,qw]"))?;
    let target = HandTarget::from_values(&values).map_err(|why| bad(&why))?;
    crate::common::check_world_target(target.position, text, "--target")?;
    Ok(target)
}

fn person(
    path: &Path,
    height: f64,
    side: Side,
    target: &Point3<f64>,
) -> Result<(Warp, ArmDrive), Failure> {
    let person = crate::common::read_person(path)?;
    let character =
        kinergy_reach::character::Character::from_height(height).map_err(Failure::from)?;
    let arm = PersonArm::toward(&character, &person, target, Some(side))
        .map_err(|e| crate::common::person_failure(path, e))?;
    let warp = kinergy_plan::person::person_warp(&character, &arm).map_err(|e| match e {
        PlanError::NoBell { .. } => Failure::input(path, e),
        e => e.into(),
    })?;
    Ok((warp, arm.drive))
}

/// Where the task reaches first, in world: `--target`, or the grip point of `--object`'s
/// grasp (its origin when it has none).
fn reach_target(args: &Args, scene: &Scene) -> Result<Point3<f64>, Failure> {
    if let Some(t) = &args.target {
        return Ok(parse_target(t)?.position);
    }
    let object = args
        .object
        .as_deref()
        .and_then(|name| scene.object(name))
        .ok_or_else(|| Failure::Input("--task needs --object NAME".into()))?;
    Ok(match &object.grasp {
        Some(g) => object.pose * g.position,
        None => Point3::from(object.pose.translation.vector),
    })
}

/// Runs `kinergy plan`.
pub fn run(args: &Args) -> Result<(), Failure> {
    check_range("--distance", args.distance, limits::PLAN_DISTANCE)?;
    check_optional("--budget-ms", args.budget_ms, limits::PLAN_BUDGET_MS)?;
    // Read first (reading writes nothing): the meshes it names are inputs too. A scene that
    // cannot be read is reported after the outputs are checked, as every input is.
    let scene = Scene::read(&args.scene);
    let mut inputs = vec![args.scene.as_path()];
    inputs.extend(scene.iter().flat_map(Scene::mesh_files));
    inputs.extend(args.params.as_deref());
    crate::common::check_outputs(&inputs, &[crate::common::Output::File("-o", &args.output)])?;
    let scene = scene.map_err(|e| Failure::input(&args.scene, e))?;
    let limb = Limb::arm(args.arm);
    let mut settings = TaskSettings {
        limb,
        ..TaskSettings::default()
    };
    settings.rrt.seed = args.seed;
    if let (Some(name), Some(_)) = (&args.object, args.task)
        && scene.object(name).is_none()
    {
        let known: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        return Err(Failure::Input(format!(
            "--object: {} (in {})",
            crate::common::names::unknown("object", name, &known),
            args.scene.display()
        )));
    }
    if let Some(path) = &args.params {
        let target = reach_target(args, &scene)?;
        (settings.warp, settings.arm) = person(path, scene.character_height, args.arm, &target)?;
    }
    let timing = TimingReport {
        warp: match settings.warp {
            Warp::Cubic => "cubic",
            Warp::Beta { .. } => "person",
        },
        peak: settings.warp.peak(),
        spread: settings.warp.spread(),
    };
    if let Some(ms) = args.budget_ms {
        // Within PLAN_BUDGET_MS, checked on entry.
        settings.rrt.budget.time = Some(Duration::from_millis(ms));
    }
    let triangles = scene.triangle_count();
    let planner = Planner::new(scene, settings).map_err(Failure::from)?;
    let need_object = || {
        args.object
            .clone()
            .ok_or_else(|| Failure::Input("--task needs --object NAME".into()))
    };
    let (task, motion): (String, Result<Manipulation, PlanError>) = match (&args.target, args.task)
    {
        (Some(t), _) => {
            let target = parse_target(t)?;
            ("reach".into(), planner.reach(&target, HandShape::relaxed()))
        }
        (None, Some(Task::Relocate)) => {
            let object = need_object()?;
            let to = args
                .to
                .as_deref()
                .ok_or_else(|| Failure::Input("--task relocate needs --to x,y,z".into()))?;
            let to = crate::common::parse_world_target(to, "--to")?;
            (format!("relocate {object}"), planner.relocate(&object, &to))
        }
        (None, Some(Task::Grasp)) => {
            let object = need_object()?;
            (format!("grasp {object}"), planner.grasp(&object))
        }
        (None, Some(task @ (Task::Pull | Task::Push))) => {
            let object = need_object()?;
            if !args.distance.is_finite() || args.distance <= 0.0 {
                return Err(Failure::Input(format!(
                    "--distance {}: expected a number > 0",
                    args.distance
                )));
            }
            let signed = if task == Task::Pull {
                args.distance
            } else {
                -args.distance
            };
            (
                format!("{task:?} {object}").to_lowercase(),
                planner.pull(&object, signed),
            )
        }
        (None, None) => return Err(Failure::Input("give --target or --task".into())),
    };
    let motion = motion.map_err(Failure::from)?;
    let clip = motion.to_clip(planner.character()).map_err(Failure::from)?;
    crate::common::write_clip(&args.output, &clip, &Default::default())?;
    let report = Report {
        output: args.output.display().to_string(),
        scene: args.scene.display().to_string(),
        triangles,
        task,
        seed: args.seed,
        frames: motion.poses.len(),
        frame_time_s: motion.frame_time,
        duration_s: motion.duration(),
        phases: motion
            .phases
            .iter()
            .map(|p| PhaseReport {
                name: p.name.clone(),
                first_frame: p.frames.start,
                last_frame: p.frames.end.saturating_sub(1),
                planned: p.planned.as_ref().map(|pl| PlannedReport {
                    iterations: pl.search.iterations,
                    nodes: pl.search.nodes,
                    plan_ms: pl.search.seconds * 1e3,
                    smooth_ms: pl.smoothing.seconds * 1e3,
                    length_before_m: pl.smoothing.length_before,
                    length_after_m: pl.smoothing.length_after,
                    configs_before: pl.raw.configs.len(),
                    configs_after: pl.path.configs.len(),
                }),
                synergy: p.synergy.as_ref().map(|a| SynergyReport {
                    from_m: a.from_m,
                    path_m: a.path_m,
                    rejected: a.rejected.clone(),
                    first_frame: p.frames.start + a.first_frame,
                    frames: a.frames,
                    plain_ik_from: a.plain_ik_from.map(|k| p.frames.start + k),
                    distance_m: a.distance_m,
                }),
            })
            .collect(),
        objects: motion.objects.iter().filter_map(ObjectReport::of).collect(),
        timing,
    };
    if args.json {
        print_json(&report)?;
    } else {
        let mut text = format!(
            "{}: {} in {} ({} triangles), {} frames ({:.2} s)\n",
            report.output, report.task, report.scene, triangles, report.frames, report.duration_s
        );
        for p in &report.phases {
            text += &format!(
                "  {:<9} frames {:>4}–{:<4}",
                p.name, p.first_frame, p.last_frame
            );
            if let Some(pl) = &p.planned {
                text += &format!(
                    "  planned: {} iterations, {} nodes, {:.1} ms; smoothed {:.2} → {:.2} m in {:.1} ms",
                    pl.iterations,
                    pl.nodes,
                    pl.plan_ms,
                    pl.length_before_m,
                    pl.length_after_m,
                    pl.smooth_ms
                );
            }
            text.push('\n');
            if let Some(a) = &p.synergy {
                text += &format!(
                    "  {:<9} the person's synergy from {:.2} of {:.2} m (frame {}, {} frames{}), \
                     {:.1} mm from the planned hand\n",
                    "",
                    a.from_m,
                    a.path_m,
                    a.first_frame,
                    a.frames,
                    a.plain_ik_from
                        .map(|k| format!(", plain IK from frame {k}"))
                        .unwrap_or_default(),
                    a.distance_m * 1e3
                );
            }
        }
        for o in &report.objects {
            if let Some(end) = &o.end {
                let [x, y, z] = end.position_m;
                text += &format!("  {} ends at {x:.3},{y:.3},{z:.3}\n", o.name);
            }
        }
        emit(&text)?;
    }
    Ok(())
}
