//! Fits a person from a folder of their takes, then makes the full-body character reach a new
//! target in their style, written as BVH.
//!
//! `cargo run --release --example person_reach [FOLDER] [x,y,z] [OUT.bvh]`
//! (default: `data-synthetic/p01`, `-0.3,1.3,0.45`, `person_reach.bvh`).
use kinergy::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let folder = args.next().unwrap_or_else(|| "data-synthetic/p01".into());
    let target: Vec<f64> = (args.next().unwrap_or_else(|| "-0.3,1.3,0.45".into()))
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let out = args.next().unwrap_or_else(|| "person_reach.bvh".into());

    // Each take's main reach of the right arm, riding on the captured torso.
    let mut reaches = Vec::new();
    for path in capture_files(&[folder.into()])? {
        let take = Capture::read(&path, &ImportOptions::default())?;
        let main = ReachFrames::Segments(Selection::Main);
        reaches.extend(take.reaches(&ArmChoice::side(Side::Right), &main, BaseMode::Replay)?);
    }
    // One vector for the person: S_A, S_B, then S_C, each from the previous one's solution.
    let svd = OptimizerKind::Svd.default_optimizer();
    let models = [Model::Sa, Model::Sb, Model::Sc];
    let fits = fit_nested(&reaches, &models, svd, &FitSettings::default())?;
    let person = fits.params_file(&reaches, FitGrouping::Person)?;
    // The character reaches the new target in their style.
    let character = Character::from_height(1.75)?;
    let target = Point3::new(target[0], target[1], target[2]);
    let arm = PersonArm::toward(&character, &person, &target, None)?;
    let motion = reach_full_body_driven(&character, target, &ReachSettings::default(), &arm.drive)?;
    let clip = character.to_clip(&motion.poses, motion.frame_time)?;
    write_clip(out.as_ref(), &clip, &ExportOptions::default())?;

    let fit = fits.fits.last().map_or(f64::NAN, |f| f.score);
    println!(
        "{} reaches fitted (S_C {:.1} mm); {out}: {:?}, the hand {:.1} mm from the target",
        reaches.len(),
        fit * 1e3,
        Ending::of(&character, &motion),
        motion.report.final_error * 1e3
    );
    Ok(())
}
