//! The full-body controller's frames alone, for instruction counts that do not drift with the
//! machine's load (criterion's figures on a shared 2-core machine move ±50 %):
//!
//! ```text
//! cargo build --release -p kinergy-reach --example frame_cost
//! valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file=/dev/null \
//!     target/release/examples/frame_cost squat 0     # the plan alone
//! valgrind … target/release/examples/frame_cost squat 10  # the plan and 10 animations
//! ```
//!
//! The difference over 10 and the frame count printed give the instructions per frame. The
//! reaches are the bench's (`benches/reach.rs`): `near`, `step`, `squat`.

use kinergy_motion::nalgebra::Point3;
use kinergy_reach::character::Character;
use kinergy_reach::controller::{ArmDrive, ReachSettings, animate_reach, plan_reach};

fn main() {
    let mut args = std::env::args().skip(1);
    let kind = args.next().unwrap_or_else(|| "near".into());
    let times: usize = args.next().and_then(|n| n.parse().ok()).unwrap_or(1);
    let (target, flexibility) = match kind.as_str() {
        "near" => ([0.25, 1.1, 0.35], 1.0),
        "step" => ([0.2, 1.0, 1.15], 1.0),
        "squat" => ([0.2, 0.15, 0.8], 3.0),
        other => {
            eprintln!("frame_cost: unknown reach {other:?} (near, step or squat)");
            std::process::exit(2);
        }
    };
    let character = Character::from_height(1.75).expect("a 1.75 m character");
    let settings = ReachSettings {
        flexibility,
        ..ReachSettings::default()
    };
    let target = Point3::new(target[0], target[1], target[2]);
    let plan = plan_reach(&character, target, &settings).expect("plan");
    let mut frames = 0;
    for _ in 0..times {
        let motion =
            animate_reach(&character, &plan, &settings, &ArmDrive::Profile).expect("reach");
        frames = motion.poses.len();
    }
    println!("{kind}: {frames} frames × {times}");
}
