//! `kinergy from-positions`: joint positions per frame (a CSV table or a NumPy `.npy` array) →
//! BVH, the rotations from [`kinergy_motion::Clip::from_positions`], the hierarchy built in
//! (SMPL's 24 joints, Human3.6M's 17, COCO's 17 keypoints), from a JSON map or from a BVH's
//! skeleton. The command reads, calls and
//! reports; the work is kinergy-motion's.

use std::path::{Path, PathBuf};

use kinergy_motion::units::UnitChoice;
use kinergy_motion::up::UpChoice;
use kinergy_motion::{
    Clip, JointMap, PositionArrays, Stretch, read_names, read_positions_csv, read_positions_npy,
};
use serde::Serialize;

use crate::common::{Failure, emit, print_json, write_clip};

/// Arguments of `kinergy from-positions`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The positions: CSV, long (`frame,joint,x,y,z`, a row per frame and joint) or wide
    /// (`frame,<joint>_x,<joint>_y,<joint>_z,…`, a row per frame), frames numbered without
    /// gaps; or a NumPy `.npy` array `(frames, joints, 3)` (float64 or float32), its joints
    /// named by --names or, for a built-in hierarchy, in its dataset's order.
    #[arg(value_name = "POSITIONS.csv|.npy")]
    pub positions: PathBuf,
    /// With a `.npy` array: a text file naming its joints in order, one per line.
    #[arg(long, value_name = "NAMES.txt")]
    pub names: Option<PathBuf>,
    /// Where to write the BVH (atomically; `-` for standard output).
    #[arg(short, long, value_name = "OUT.bvh")]
    pub output: PathBuf,
    /// The joints' hierarchy: a built-in one (smpl24, h36m17, coco17 — COCO's keypoints with
    /// a root at the hips' midpoint and a neck at the shoulders'), a JSON map (`{"joints":
    /// [{"name": …, "parent": … or null, "mean_of": [optional sources]}, …]}`, parents first),
    /// or a BVH whose skeleton gives the names and parents.
    #[arg(long, value_name = "smpl24|h36m17|coco17|MAP.json|T.bvh")]
    pub skeleton: String,
    /// The positions' length unit: m, cm, mm, in or cmu, or auto (guessed from the body's size
    /// on the first frame, as for BVH).
    #[arg(long, default_value = "auto", value_name = "UNIT")]
    pub unit: UnitChoice,
    /// The positions' up axis: y, z, x, -y, -z or -x, or auto (detected on the first frame from
    /// the joints' names or the body's shape, as for BVH). The BVH is written Y up.
    #[arg(
        long,
        default_value = "auto",
        value_name = "AXIS",
        allow_hyphen_values = true
    )]
    pub up: UpChoice,
    /// A bone whose length varies over the frames: `hold` it at its median length (rotations
    /// only; its joint is off by up to the variation, reported) or `keep` it, its child joint
    /// given position channels that carry each frame's length (every joint where the input
    /// puts it: a reference root the hips move away from, positions from video).
    #[arg(long, default_value = "hold", value_name = "hold|keep")]
    pub stretch: Stretch,
    /// Frames per second (0.1 to 10000).
    #[arg(long, default_value_t = 30.0, value_name = "HZ")]
    pub frame_rate: f64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report {
    output: String,
    frames: usize,
    joints: usize,
    frame_rate_hz: f64,
    /// The table's unit, and whether it was guessed.
    unit: &'static str,
    unit_guessed: bool,
    /// The table's up axis, and how it was found (given, joint names, body shape, assumed).
    up: String,
    up_detection: &'static str,
    /// The largest distance of any joint from its position, meters.
    max_error_m: f64,
    /// Each joint's largest distance from its positions, meters.
    joint_max_error_m: Vec<(String, f64)>,
    /// Joints whose twist the positions leave open (kept from frame to frame).
    undetermined: Vec<String>,
    /// Bones whose length varies over the frames, with the range, meters.
    stretched: Vec<(String, f64)>,
    /// The arms whose rotations leave the human limits of Kinergy's arm, with the DoFs past
    /// them ([`kinergy_solver::arms_beyond_limits`]).
    arms_beyond_limits: Vec<(kinergy_motion::Side, Vec<String>)>,
}

/// The hierarchy `--skeleton` names.
fn joint_map(text: &str) -> Result<JointMap, Failure> {
    if let Some(map) = JointMap::built_in(text) {
        return Ok(map);
    }
    let path = Path::new(text);
    let extension = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    match extension.as_deref() {
        Some("json") => {
            let json = std::fs::read_to_string(path).map_err(|e| Failure::input(path, e))?;
            JointMap::from_json(&json).map_err(|e| Failure::input(path, e))
        }
        Some("bvh") => {
            let (clip, _) = kinergy_motion::read_clip(path, &Default::default())
                .map_err(|e| Failure::input(path, e))?;
            Ok(JointMap::of_skeleton(clip.skeleton()))
        }
        _ => Err(Failure::Input(format!(
            "--skeleton {text}: a built-in hierarchy ({}), a .json map or a .bvh",
            JointMap::built_in_names().join(", ")
        ))),
    }
}

/// Runs `kinergy from-positions`.
pub fn run(args: &Args) -> Result<(), Failure> {
    if !(args.frame_rate.is_finite() && (0.1..=10_000.0).contains(&args.frame_rate)) {
        return Err(Failure::Input(format!(
            "--frame-rate {}: 0.1 to 10000 frames per second",
            args.frame_rate
        )));
    }
    let map = joint_map(&args.skeleton)?;
    {
        use crate::common::{Output, check_outputs};
        let mut inputs = vec![args.positions.as_path()];
        inputs.push(Path::new(&args.skeleton));
        inputs.extend(args.names.as_deref());
        check_outputs(&inputs, &[Output::File("-o", &args.output)])?;
    }
    let npy = args
        .positions
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    if args.names.is_some() && !npy {
        return Err(Failure::Input(
            "--names names the joints of a .npy array; a CSV table names its own".into(),
        ));
    }
    let table = if npy {
        let names = match &args.names {
            Some(path) => Some(read_names(
                &std::fs::read_to_string(path).map_err(|e| Failure::input(path, e))?,
            )),
            None => None,
        };
        let bytes =
            std::fs::read(&args.positions).map_err(|e| Failure::input(&args.positions, e))?;
        read_positions_npy(&args.positions, &bytes, &map, names.as_deref())
    } else {
        let text = std::fs::read_to_string(&args.positions)
            .map_err(|e| Failure::input(&args.positions, e))?;
        read_positions_csv(&args.positions, &text, &map)
    }
    .map_err(|e| Failure::input(&args.positions, e))?;
    let reading = table
        .reading(&map, args.unit, args.up)
        .map_err(|e| Failure::input(&args.positions, e))?;
    let positions = table.to_world(reading.unit, reading.up);
    let made = Clip::from_positions_with(
        PositionArrays {
            joint_names: &map.names,
            parents: &map.parents,
            positions: &positions,
            frame_time: 1.0 / args.frame_rate,
        },
        args.stretch,
    )
    .map_err(|e| Failure::input(&args.positions, e))?;
    let arms_beyond_limits = kinergy_solver::arms_beyond_limits(&made.clip)
        .map_err(|e| Failure::input(&args.positions, e))?;
    write_clip(&args.output, &made.clip, &Default::default())?;
    let n = map.names.len();
    let report = Report {
        output: args.output.display().to_string(),
        frames: table.frames,
        joints: n,
        frame_rate_hz: args.frame_rate,
        unit: reading.unit.name(),
        unit_guessed: reading.unit_guessed,
        up: reading.up.to_string(),
        up_detection: reading.up_detection.name(),
        max_error_m: made.max_error_m(),
        joint_max_error_m: made.joint_max_error_m(),
        undetermined: made.undetermined.clone(),
        stretched: made.stretched.clone(),
        arms_beyond_limits,
    };
    if args.json {
        return print_json(&report);
    }
    let mut text = format!(
        "{}: {} frames of {} joints at {} Hz; every joint within {:.2} mm of its position\n",
        report.output,
        report.frames,
        report.joints,
        report.frame_rate_hz,
        report.max_error_m * 1e3
    );
    text += &format!(
        "  read in {}{}, {} up ({})\n",
        report.unit,
        if report.unit_guessed {
            " (guessed from the body's size; --unit to choose)"
        } else {
            ""
        },
        report.up,
        report.up_detection
    );
    if !report.undetermined.is_empty() {
        text += &format!(
            "  twist left open by the positions (kept from frame to frame): {}\n",
            report.undetermined.join(", ")
        );
    }
    for (side, dofs) in &report.arms_beyond_limits {
        text += &format!(
            "  the {side} arm turns past a human range: {} (a pose estimate's error, or a \
             joint bent backward)\n",
            dofs.join(", ")
        );
    }
    let how = match args.stretch {
        Stretch::Hold => "held at its median; --stretch keep keeps it",
        Stretch::Keep => "kept in position channels",
    };
    for (name, range) in &report.stretched {
        text += &format!(
            "  the bone to {name} stretches by {:.1} mm over the take ({how})\n",
            range * 1e3
        );
    }
    emit(&text)
}
