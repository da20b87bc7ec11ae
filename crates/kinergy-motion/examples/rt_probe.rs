//! Probe.
use kinergy_motion::retarget::joint_paths;
use kinergy_motion::{BodyJoints, Retargeter, read_clip};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (src, _) = read_clip(Path::new(&args[1]), &Default::default()).unwrap();
    let (tpl, _) = read_clip(Path::new(&args[2]), &Default::default()).unwrap();
    let sb = BodyJoints::find(src.skeleton()).unwrap();
    let tb = BodyJoints::find(tpl.skeleton()).unwrap();
    let out = Retargeter::new(&src, sb.clone(), tpl.skeleton().clone(), tb.clone())
        .unwrap()
        .run(&src)
        .unwrap();
    let back = Retargeter::new(&out.clip, tb, src.skeleton().clone(), sb.clone())
        .unwrap()
        .run(&out.clip)
        .unwrap();
    println!(
        "drops {} {}",
        out.report.pelvis_drop_m, back.report.pelvis_drop_m
    );
    let mut j = vec![sb.pelvis];
    j.extend(sb.spine.iter().copied());
    j.extend(sb.neck.iter().copied());
    j.extend(sb.head);
    j.extend([
        sb.arms[0].clavicle.unwrap_or(0),
        sb.arms[0].shoulder,
        sb.arms[0].elbow,
        sb.arms[0].wrist,
    ]);
    let a = joint_paths(&src, &j).unwrap();
    let c = joint_paths(&back.clip, &j).unwrap();
    for (k, (x, y)) in a.iter().zip(&c).enumerate() {
        let m = x
            .iter()
            .zip(y)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max);
        println!("{:24} {:.4}", src.skeleton().joint(j[k]).name, m);
    }
}
