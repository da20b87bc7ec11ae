//! `kinergy plan`: collision-free reaching and manipulation in a scene (Kallmann 2005),
//! written as BVH with fingers.

use std::path::PathBuf;
use std::time::Duration;

use clap::builder::PossibleValue;
use kinergy_draw::animation::View;
use kinergy_draw::search::SearchFigure;
use kinergy_motion::Side;
use kinergy_plan::PlanError;
use kinergy_plan::level::Level;
use kinergy_plan::request::{BUDGET_MS, DISTANCE_M, Goal, PlanReport, TaskKind, TaskRequest};
use kinergy_plan::scene::Scene;
use kinergy_plan::space::HandTarget;

use crate::common::{Failure, check_optional, check_range, emit, print_json};

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
    /// A manipulation task on a scene object: `relocate` (grasp `--object`, carry it so its
    /// origin ends at `--to`, let go and come back), `grasp` (reach, approach and close the
    /// hand on it), `pull` or `push` (grasp the drawer `--object` and pull it open or push it
    /// in by `--distance` meters).
    #[arg(long, requires = "object", value_parser = crate::common::named::<TaskKind>(TaskKind::ALL.map(TaskKind::name)))]
    pub task: Option<TaskKind>,
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
    /// How a reach (`--target`) is computed, after Kallmann's three levels: `ik` (the hand on
    /// a straight line, IK on every frame; only the goal posture is checked for collisions,
    /// the motion is not), `straight` (the same line, IK with collision avoidance on every
    /// frame, every frame and the motion between frames checked), `planner` (RRT-Connect and
    /// smoothing) or `auto` (ik, then straight, then planner, until one's motion is
    /// collision-free). A task (`--task`) takes auto or planner. Where the arm alone cannot
    /// reach the target (beyond reach, or colliding at every orbit angle), every level also
    /// bends and twists the spine and squats, the feet planted (the report's `body_dofs`).
    #[arg(long, default_value = "auto", value_name = "LEVEL", value_parser = crate::common::named::<Level>(Level::ALL.map(Level::name)))]
    pub level: Level,
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
    /// Kallmann's Fig. 4: each planned phase's two RRT-Connect trees (their nodes at the
    /// wrist's position, parent to child), the wrist's path as found and as smoothed, and the
    /// scene behind, one panel per planned phase (SVG or PNG by the extension, written
    /// atomically). A reach solved without the planner draws a note saying so.
    #[arg(long, value_name = "FILE.svg")]
    pub tree_svg: Option<PathBuf>,
    /// Where `--tree-svg` looks from (the character faces +Z, Y up, its left at +X).
    #[arg(long, default_value = "side", value_parser = crate::common::named::<View>(View::ALL.map(|v| PossibleValue::new(v.name()).help(v.description()))))]
    pub tree_view: View,
    /// A person's parameters (`kinergy fit -o person.json`, or a field, which gives the
    /// person's vector for the reach's target): the planned phases are played with the
    /// person's bell — the peak time and spread of their synergy's hand speed on a reach in
    /// front of the acting shoulder — instead of Kallmann's cubic, and a reach is finished by
    /// their synergy controller from the first waypoint of the planned path whose approach is
    /// free of obstacles (every frame checked), then settled onto the grip.
    #[arg(long, value_name = "person.json")]
    pub params: Option<PathBuf>,
}

/// The size of `--tree-svg`'s picture, pixels.
const TREE_PICTURE: (u32, u32) = (900, 700);

/// The goal the flags give: `--target`, or `--task` on `--object`.
fn goal(args: &Args) -> Result<Goal, Failure> {
    match (&args.target, args.task) {
        (Some(t), _) => Ok(Goal::Reach(parse_target(t)?)),
        (None, Some(task)) => {
            let object = args
                .object
                .clone()
                .ok_or_else(|| Failure::Input("--task needs --object NAME".into()))?;
            let to = match (task, args.to.as_deref()) {
                (TaskKind::Relocate, None) => {
                    return Err(Failure::Input("--task relocate needs --to x,y,z".into()));
                }
                (TaskKind::Relocate, Some(to)) => {
                    Some(crate::common::parse_world_target(to, "--to")?)
                }
                _ => None,
            };
            Goal::task(task, object, to, args.distance)
                .map_err(|e| Failure::Input(format!("--{} {}", e.field, e.why)))
        }
        (None, None) => Err(Failure::Input("give --target or --task".into())),
    }
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

/// Runs `kinergy plan`: the request ([`TaskRequest`]) from the flags, run, the motion
/// written and the report said.
pub fn run(args: &Args) -> Result<(), Failure> {
    check_range("--distance", args.distance, DISTANCE_M)?;
    check_optional("--budget-ms", args.budget_ms, BUDGET_MS)?;
    // Read first (reading writes nothing): the meshes it names are inputs too. A scene that
    // cannot be read is reported after the outputs are checked, as every input is.
    let scene = Scene::read(&args.scene);
    let mut inputs = vec![args.scene.as_path()];
    inputs.extend(scene.iter().flat_map(Scene::mesh_files));
    inputs.extend(args.params.as_deref());
    let mut outputs = vec![crate::common::Output::File("-o", &args.output)];
    if let Some(path) = &args.tree_svg {
        crate::common::picture_format(path, "--tree-svg")?;
        outputs.push(crate::common::Output::File("--tree-svg", path));
    }
    crate::common::check_outputs(&inputs, &outputs)?;
    let scene = scene.map_err(|e| Failure::input(&args.scene, e))?;
    let goal = goal(args)?;
    let person = args
        .params
        .as_deref()
        .map(crate::common::read_person)
        .transpose()?;
    // The picture draws the scene behind the trees.
    let drawn_scene = args.tree_svg.as_ref().map(|_| scene.clone());
    let request = TaskRequest {
        scene,
        scene_name: args.scene.display().to_string(),
        goal,
        side: args.arm,
        level: args.level,
        seed: args.seed,
        // Within BUDGET_MS, checked on entry.
        budget: args.budget_ms.map(Duration::from_millis),
        person: person
            .as_ref()
            .map(|p| p as &dyn kinergy_solver::PersonStyle),
    };
    request
        .validate()
        .map_err(|e| Failure::Input(format!("--{}: {}", e.field.replace('_', "-"), e.why)))?;
    let planned = request.run().map_err(|e| match (&args.params, e) {
        // The person's parameters on the scene's character, or a synergy with no bell.
        (Some(path), PlanError::Reach(e)) => crate::common::person_failure(path, e),
        (Some(path), e @ PlanError::NoBell { .. }) => Failure::input(path, e),
        (_, e) => e.into(),
    })?;
    // The picture is drawn first and put in place after the motion: both or neither.
    let picture = match &args.tree_svg {
        Some(path) => {
            let figure = SearchFigure::new(
                format!(
                    "RRT-Connect's trees: {} in {}, seed {} ({} view)",
                    planned.report.task,
                    args.scene.file_name().unwrap_or_default().to_string_lossy(),
                    planned.report.seed,
                    args.tree_view
                ),
                &planned.searches,
                drawn_scene.as_ref(),
                args.tree_view,
                format!(
                    "no search to draw: the reach was solved by the {} level",
                    planned.report.level.unwrap_or("planner")
                ),
            );
            Some(kinergy_draw::stage(&figure, path, TREE_PICTURE)?)
        }
        None => None,
    };
    crate::common::write_clip(&args.output, &planned.clip, &Default::default())?;
    if let Some(staged) = picture {
        kinergy_draw::commit(staged)?;
    }
    let report = PlanReport {
        output: Some(args.output.display().to_string()),
        ..planned.report
    };
    if args.json {
        print_json(&report)?;
    } else {
        let mut text = format!(
            "{}: {} in {} ({} triangles), {} frames ({:.2} s)\n",
            args.output.display(),
            report.task,
            report.scene,
            report.triangles,
            report.frames,
            report.duration_s
        );
        for l in &report.levels {
            text += &match &l.why {
                None => format!(
                    "  level {:<8} solved in {:.1} ms{}\n",
                    l.level,
                    l.ms,
                    if l.motion_checked {
                        ""
                    } else {
                        " (the motion to the goal posture not checked for collisions)"
                    }
                ),
                Some(why) => format!("  level {:<8} failed in {:.1} ms: {why}\n", l.level, l.ms),
            };
        }
        if let Some(b) = &report.body {
            text += &format!(
                "  body      moves {}: spine swing {:.0}°, twist {:.0}°, squat {:.2} m ({} stances \
                 tried in {:.1} ms), as the arm alone could not: {}\n",
                b.dofs.join(", "),
                b.spine_swing_deg,
                b.spine_twist_deg,
                b.squat_m,
                b.stances_tried,
                b.ms,
                b.arm_alone
            );
        }
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
