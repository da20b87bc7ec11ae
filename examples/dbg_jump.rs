use kinergy::prelude::*;
use kinergy_solver::BaseMode;
use kinergy_train::CapturedReach;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let (clip_path, params, f0, f1) =
        (&a[1], &a[2], a[3].parse::<usize>()?, a[4].parse::<usize>()?);
    let (clip, _) = read_clip(std::path::Path::new(clip_path), &ImportOptions::default())?;
    let joints = ArmJoints::find(clip.skeleton(), Side::Right)?;
    let reach = CapturedReach::new("x", &clip, &joints, f0..f1, BaseMode::Replay)?;
    let file = ParamsFile::read(std::path::Path::new(params))?;
    let synergy = file.synergy_for(&reach.dof_names())?;
    let settings = reach.open_settings(0.005, 10.0, true);
    let controller = Controller::new(file.optimizer, synergy, settings)?;
    let s = controller.synthesize(&reach.task())?;
    let chain = reach.arm().chain();
    println!("dofs {:?}", reach.dof_names());
    for (i, m) in chain.joints().iter().flat_map(|j| &j.motions).enumerate() {
        println!("motion {i} {:?}", m);
    }
    let mut prev: Option<(Vec<f64>, kinergy_motion::nalgebra::Point3<f64>)> = None;
    for i in 0..s.frame_count() {
        let q = s.configuration(i).to_vec();
        let e = s.end(i);
        if let Some((pq, pe)) = &prev {
            let v = (e - pe).norm() / settings.frame_time;
            let dq: Vec<String> = q
                .iter()
                .zip(pq)
                .map(|(a, b)| format!("{:+.3}", (a - b)))
                .collect();
            let qs: Vec<String> = q.iter().map(|a| format!("{:+.3}", a)).collect();
            println!("{i:3} v={v:.3} dq=[{}] q=[{}]", dq.join(" "), qs.join(" "));
        }
        prev = Some((q, e));
        if i > 25 {
            break;
        }
    }
    Ok(())
}
