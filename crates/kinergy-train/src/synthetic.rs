//! Reaches whose truth is known: motions synthesized by the synergy controller itself from
//! given parameters and written into a capture's skeleton as a new "capture". Fitting them
//! must find the parameters' motion again (known-parameter recovery), and a set of them makes
//! a benchmark workload with the shape of real data.
//!
//! The capture gives the person (bone lengths, limits), the start posture and the skeleton;
//! the shoulder stays where it is on the first frame; the target is the hand of a goal
//! posture (the start moved by a given offset, within the limits), so it is reachable and the
//! made motion ends on its own target — which is what a fit of the made capture aims at.

use kinergy_io::InvalidSetting;
use kinergy_motion::{ArmJoints, Clip};
use kinergy_solver::{
    ArmTask, BaseMode, Controller, Model, Optimizer, ParamSpace, Synergy, Synthesis, Task,
};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};

/// A made reach: the capture made, its reach, the parameters that made it.
#[derive(Debug, Clone)]
pub struct MadeReach {
    /// The made capture (the source skeleton, the arm moving as synthesized).
    pub clip: Clip,
    /// Its reach, ready to fit (fixed base, all frames).
    pub reach: CapturedReach,
    /// The parameter space of `truth`.
    pub space: ParamSpace,
    /// The parameters that made it.
    pub truth: Vec<f64>,
    /// How far the made motion ends from the target it was made for, meters.
    pub final_error: f64,
}

/// The controller a reach is made with, which a fit of the made reach must find again: the
/// true values of a synergy model, and the optimizer.
#[derive(Debug, Clone, Copy)]
pub struct Truth<'a> {
    /// The synergy model.
    pub model: Model,
    /// Its true parameter values.
    pub values: &'a [f64],
    /// The optimizer the motion is synthesized with.
    pub optimizer: Optimizer,
}

/// Makes one reach of `frames` frames from `clip`'s first frame with the controller of
/// `truth`, toward the hand of the start posture moved by `offset` (per DoF, radians; clamped
/// into the limits). `name` names the made reach.
pub fn made_reach(
    name: &str,
    clip: &Clip,
    arm: &ArmJoints,
    frames: usize,
    truth: Truth<'_>,
    offset: &[f64],
) -> Result<MadeReach> {
    let Truth {
        model,
        values: truth,
        optimizer,
    } = truth;
    let frames = frames.min(clip.frame_count());
    let segment = clip.slice(0..frames)?;
    let source = CapturedReach::new(name, &segment, arm, 0..frames, BaseMode::Fixed)?;
    let chain = source.arm().chain();
    let start = source.arm().start();
    if offset.len() != start.len() {
        return Err(TrainError::Setting(InvalidSetting::new(
            "offset",
            format!("one value per DoF ({})", start.len()),
        )));
    }
    let mut goal: Vec<f64> = start.iter().zip(offset).map(|(q, d)| q + d).collect();
    chain.clamp(&mut goal);
    let base = source.arm().base(BaseMode::Fixed);
    let target = chain.end_position(base.at(0), &goal)?;
    let space = ParamSpace::new(model, &source.dof_names(), Default::default())?;
    let controller = Controller::new(
        optimizer,
        Synergy::new(&space, truth)?,
        source.settings(crate::captured::DEFAULT_TOLERANCE),
    )?;
    let synthesis: Synthesis = controller.synthesize(&ArmTask {
        chain,
        base: &base,
        start,
        task: Task::Position(target),
        start_velocity: None,
    })?;
    let made = source
        .arm()
        .to_clip(&segment, &synthesis, BaseMode::Fixed)?;
    // The made reach is fitted with the controller that made it: the source's smoothing, from
    // rest.
    let reach = CapturedReach::new(name, &made, arm, 0..frames, BaseMode::Fixed)?
        .with_smoothing(source.smoothing())
        .from_rest();
    Ok(MadeReach {
        clip: made,
        reach,
        space,
        truth: truth.to_vec(),
        final_error: synthesis.final_error,
    })
}

/// `count` made reaches of S_C motions from `clip`: truths drawn with gains in [0.5, 2],
/// s in [3, 10], o in [0, 3]; goal offsets of up to ±0.5 rad per DoF; drawn from `seed`.
/// Made motions that end more than 1 mm from their target are drawn again (up to 20 times
/// per reach).
pub fn made_set(
    clip: &Clip,
    arm: &ArmJoints,
    count: usize,
    frames: usize,
    optimizer: Optimizer,
    seed: u64,
) -> Result<Vec<MadeReach>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(count);
    let dofs = 7;
    for k in 0..count {
        let mut tries = 0;
        loop {
            let mut truth: Vec<f64> = (0..dofs).map(|_| rng.random_range(0.5..2.0)).collect();
            truth.push(rng.random_range(3.0..10.0));
            truth.push(rng.random_range(0.0..3.0));
            let offset: Vec<f64> = (0..dofs).map(|_| rng.random_range(-0.5..0.5)).collect();
            let made = made_reach(
                &format!("made_{k:02}"),
                clip,
                arm,
                frames,
                Truth {
                    model: Model::Sc,
                    values: &truth,
                    optimizer,
                },
                &offset,
            )?;
            tries += 1;
            if made.final_error < 1e-3 {
                out.push(made);
                break;
            }
            if tries >= 20 {
                return Err(TrainError::Reach {
                    clip: format!("made_{k:02}"),
                    why: "no drawn motion ended within 1 mm of its target in 20 draws".into(),
                });
            }
        }
    }
    Ok(out)
}

/// The segments file of a set the full body made with a person's synergy
/// ([`kinergy_reach::synth::write_set`] with [`kinergy_reach::drive::Driver::Person`], what
/// `kinergy synth --params` writes beside the set in `dir`): one reach row per reach, the
/// frames the synergy drove alone, its target (where a fit must aim, also for a clip the
/// synergy handed over before it arrived) and the tempo its smooth controller was bounded
/// by, so that a fit of the set runs the controller that made it
/// ([`CapturedReach::with_known_tempo`]). The file is named `segments.csv` in `dir`.
pub fn set_segments(
    dir: &std::path::Path,
    made: &[kinergy_reach::synth::SynthReach],
) -> crate::segments_file::SegmentsFile {
    use crate::segments_file::{RowTempo, SegmentRow, SegmentsFile};
    let rows = made
        .iter()
        .map(|clip| {
            let row = &clip.row;
            let segment = SegmentRow {
                person: row.person.clone(),
                ..SegmentRow::new(
                    dir.join(&row.clip),
                    clip.driven.clone(),
                    row.arm,
                    kinergy_motion::segment::Label::Reach,
                )
            }
            .with_target([row.target_x, row.target_y, row.target_z]);
            match clip.tempo {
                Some(t) => segment.with_tempo(RowTempo {
                    peak_speed_m_s: t.peak_speed_m_s,
                    duration_s: t.duration_s,
                }),
                None => segment,
            }
        })
        .collect();
    SegmentsFile::new(dir.join(SET_SEGMENTS), rows)
}

/// The name of a set's segments file in its folder ([`set_segments`]).
pub const SET_SEGMENTS: &str = "segments.csv";
