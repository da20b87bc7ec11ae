//! The pictures of a style run ([`kinergy_reach::style`], `kinergy style -o DIR`), each as
//! .svg and .png ([`StylePictures`]):
//!
//! - `speed`: every capture's hand-speed profile and the character's reaches toward its
//!   target — with the person's parameters and with the default profile — over the fraction of
//!   the reach, one colour per kind (Okabe–Ito: black, blue, vermillion), the person's means
//!   (correlation, peak error, arm path) in the legend; lines faster than 1.5× the fastest
//!   capture are cut there, the title giving the cut and the highest speed;
//! - `realtime`: each capture's hand speed in real time beside every predictor's
//!   ([`StylePictures::realtime_chart`]);
//! - `strip`: the first capture's reach at 0, 25, 50, 75 and 100 % of it, seen from the side,
//!   the character's full body driven by the person's parameters over the captured pose (the
//!   capture carried onto the character by their reach frames at the reach's start, as the
//!   arm path compares them: shoulder on shoulder, the same up, the shoulders' line on the
//!   shoulders' line).

use std::path::Path;

use kinergy_motion::{Clip, Side};
use kinergy_reach::style::{SAMPLES, StyleCapture, StyleRun, StyleSummary};
use kinergy_train::fidelity::PersonFidelity;
use nalgebra::Point3;

use crate::bones::StickFigure;
use crate::strip::{FilmStrip, Pose2};
use crate::{DrawError, LineChart, Panels, Series, save_both};

/// Palette index ([`colour`](crate::colour)) of the captured motion.
pub const CAPTURED: usize = 6;
/// Palette index of the person's parameters (`reach --params`).
pub const PARAMS: usize = 0;
/// Palette index of the default profile.
pub const PROFILE: usize = 1;

/// Which of a run's time-normalized hand-speed profiles.
type Profile = fn(&StyleRun) -> &[f64];

/// The fractions of the reach the film strip shows.
pub const STRIP_AT: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// The page [`StylePictures::save_view`] writes.
pub const VIEW: &str = "view.html";

/// The files [`StylePictures::save_all`] writes into its folder (for an output check).
pub const FILES: [&str; 6] = [
    "speed.svg",
    "speed.png",
    "realtime.svg",
    "realtime.png",
    "strip.svg",
    "strip.png",
];

/// What a style run's pictures show: the person, the run's summary and motions, every
/// predictor's hand speed in real time, and the first capture (its clip and reach) for the
/// film strip.
#[derive(Debug, Clone, Copy)]
pub struct StylePictures<'a> {
    /// The person's name in titles (e.g. the parameters file's stem).
    pub who: &'a str,
    /// The run's means.
    pub summary: &'a StyleSummary,
    /// Each capture's run, in order; the first is the film strip's.
    pub runs: &'a [StyleRun],
    /// The captures judged in real time.
    pub fidelity: &'a PersonFidelity,
    /// The first capture's clip.
    pub clip: &'a Clip,
    /// The first capture's reach.
    pub capture: &'a StyleCapture,
    /// The arm that reaches.
    pub arm: Side,
}

impl StylePictures<'_> {
    /// Writes every picture ([`FILES`]) into `dir`: the speed chart, the real-time chart and
    /// the film strip, in this order.
    pub fn save_all(&self, dir: &Path) -> Result<(), DrawError> {
        self.speed_chart(dir)?;
        self.realtime_chart(dir)?;
        self.film_strip(dir)
    }

    /// `speed.svg|png`: every hand-speed profile of the runs on one chart (module docs).
    pub fn speed_chart(&self, dir: &Path) -> Result<(), DrawError> {
        speed_chart(dir, self.who, self.summary, self.runs)
    }

    /// `realtime.svg|png`: each capture's hand speed in real time beside every predictor's.
    pub fn realtime_chart(&self, dir: &Path) -> Result<(), DrawError> {
        realtime_chart(dir, self.who, self.fidelity)
    }

    /// `view.html` ([`VIEW`]): the first capture's reach from its onset (carried onto the
    /// character as the film strip carries it) and the character's two reaches of it — with
    /// the person's parameters and with the default profile — overlaid in the browser
    /// ([`crate::viewer`]), each hand's speed in the world on the chart, and the real-time and
    /// speed charts [`StylePictures::save_all`] wrote into `dir` under it. Nothing without a
    /// run.
    pub fn save_view(&self, dir: &Path) -> Result<(), DrawError> {
        use crate::viewer::{Hand, ViewerClip, ViewerPage, page_html};
        let Some(run) = self.runs.first() else {
            return Ok(());
        };
        let name = &run.row.clip;
        let character_failed = |source| DrawError::Character {
            name: name.clone(),
            source,
        };
        let pose_failed = |source| DrawError::Pose {
            name: name.clone(),
            source,
        };
        let to = self
            .capture
            .to_character(self.arm)
            .map_err(character_failed)?;
        let (figure, world) = StickFigure::of(self.clip).map_err(pose_failed)?;
        let joints = self.clip.skeleton().joint_count();
        let frames = self.clip.frame_count();
        let [onset, end] = self.capture.frames();
        let (onset, end) = (onset.min(frames - 1), end.min(frames - 1).max(onset));
        let positions: Vec<Point3<f64>> = world[onset * joints..(end + 1) * joints]
            .iter()
            .map(|p| to * p)
            .collect();
        let arm =
            kinergy_motion::ArmJoints::find(self.clip.skeleton(), self.arm).map_err(pose_failed)?;
        let speed = kinergy_motion::segment::hand_speed(
            self.clip,
            &arm,
            &kinergy_motion::segment::SegmentSettings::default(),
        )
        .map_err(pose_failed)?;
        let short = Path::new(name)
            .file_stem()
            .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned());
        let captured = ViewerClip::new(
            format!("{short} (captured)"),
            self.clip.frame_time(),
            self.clip
                .skeleton()
                .joints()
                .iter()
                .map(|j| j.name.clone())
                .collect(),
            figure
                .bones(&world[..joints])
                .map(|(p, c, _)| (p, c))
                .collect(),
            &positions,
            speed[onset..=end].to_vec(),
        )?;
        let mut clips = vec![captured];
        for (label, motion) in [
            ("the person's parameters", &run.params_motion),
            ("the default profile", &run.profile_motion),
        ] {
            let clip = self
                .capture
                .character()
                .to_clip(&motion.poses, motion.frame_time)
                .map_err(character_failed)?;
            clips.push(ViewerClip::of_clip(
                &clip,
                Path::new(name),
                format!("{short} ({label})"),
                Hand::Side(self.arm),
            )?);
        }
        let figures = [
            (
                "realtime.svg",
                "In real time, beside the person's own repeats",
            ),
            ("speed.svg", "Hand-speed profiles, time-normalized"),
        ]
        .iter()
        .filter_map(|(file, caption)| {
            let svg = std::fs::read_to_string(dir.join(file)).ok()?;
            Some((caption.to_string(), svg))
        })
        .collect();
        let page = ViewerPage {
            title: format!("{}: {short}", self.who),
            clips,
            figures,
            ..ViewerPage::default()
        };
        let html = page_html(&page)?;
        let out = dir.join(VIEW);
        kinergy_io::write_atomic(&out, html.as_bytes()).map_err(|e| DrawError::io(&out, e))
    }

    /// `strip.svg|png`: the first run's reach, the character over the capture (nothing
    /// without a run).
    pub fn film_strip(&self, dir: &Path) -> Result<(), DrawError> {
        match self.runs.first() {
            Some(run) => film_strip(dir, self.who, self.clip, self.capture, run, self.arm),
            None => Ok(()),
        }
    }
}

/// `realtime.svg|png`: one panel per capture, every motion's hand speed relative to the
/// shoulder over seconds from its onset — the capture (black), the person's own repeats (the
/// leave-one-out ceiling, sky blue), minimum jerk (yellow-orange), the arm on the captured
/// torso (green), the full body with the person's parameters (blue) and with the default
/// profile (vermillion) — each predictor's e in its panel's legend.
fn realtime_chart(dir: &Path, who: &str, f: &PersonFidelity) -> Result<(), DrawError> {
    use kinergy_train::fidelity::Predictor;
    let colour = |p: Predictor| match p {
        Predictor::Ceiling => 5,
        Predictor::MinimumJerk => 4,
        Predictor::Arm => 2,
        Predictor::Body => PARAMS,
        Predictor::Profile => PROFILE,
    };
    let line = |values: &[f64], dt: f64, until: f64| -> Vec<(f64, f64)> {
        values
            .iter()
            .enumerate()
            .map(|(k, &v)| (k as f64 * dt, v))
            .take_while(|(t, _)| *t <= until)
            .collect()
    };
    let charts = f
        .takes
        .iter()
        .map(|t| {
            // Every motion is drawn to twice the capture's duration at most: a synthesis that
            // creeps on for seconds would squeeze the bells.
            let until = 2.0 * t.capture_duration_s.max(0.1);
            let mut series = vec![Series {
                name: format!(
                    "capture: {:.2} s, peak {:.2} m/s",
                    t.capture_duration_s, t.capture_peak_m_s
                ),
                points: line(&t.capture.values, t.capture.frame_time, until),
                colour: Some(CAPTURED),
            }];
            for p in &t.predicted {
                series.push(Series {
                    name: format!(
                        "{}: e {:.3}, {:.2}× duration",
                        p.predictor.name(),
                        p.fidelity.error,
                        p.fidelity.duration_ratio
                    ),
                    points: line(&p.series.values, p.series.frame_time, until),
                    colour: Some(colour(p.predictor)),
                });
            }
            let name = Path::new(&t.name)
                .file_stem()
                .map_or_else(|| t.name.clone(), |s| s.to_string_lossy().into_owned());
            LineChart {
                title: name,
                x_label: "seconds from the onset".into(),
                y_label: "hand speed (m/s)".into(),
                series,
            }
        })
        .collect::<Vec<_>>();
    let columns = if charts.len() <= 4 { 2 } else { 3 };
    let rows = charts.len().div_ceil(columns).max(1) as u32;
    let body = f.summary(Predictor::Body);
    let ceiling = f.summary(Predictor::Ceiling);
    let title = format!(
        "{who}: hand speed in real time{}",
        match (body, ceiling) {
            (Some(b), Some(c)) if b.error_over_ceiling.is_finite() => format!(
                ": full body e {:.3}, {:.1}× their own repeats' {:.3}",
                b.error, b.error_over_ceiling, c.error
            ),
            _ => String::new(),
        }
    );
    let figure = Panels {
        title,
        columns,
        charts,
    };
    save_both(
        &figure,
        dir,
        "realtime",
        (700 * columns as u32, 60 + 420 * rows),
    )
}

/// `speed.svg|png`: every profile of `runs` on one chart.
fn speed_chart(
    dir: &Path,
    who: &str,
    s: &StyleSummary,
    runs: &[StyleRun],
) -> Result<(), DrawError> {
    // A synthesized spike (a first frame's jump) would flatten every bell: lines are cut at
    // 1.5× the fastest capture, and the title says so.
    let fastest = |f: fn(&StyleRun) -> &[f64]| {
        runs.iter()
            .flat_map(|r| f(r).iter().copied())
            .fold(0.0_f64, f64::max)
    };
    let cap = 1.5 * fastest(|r| &r.captured_speed);
    let highest = fastest(|r| &r.params_speed).max(fastest(|r| &r.profile_speed));
    let cut = cap > 0.0 && highest > cap;
    let line = |values: &[f64]| -> Vec<(f64, f64)> {
        values
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let v = if cut { v.min(cap) } else { v };
                (k as f64 / (SAMPLES - 1) as f64, v)
            })
            .collect()
    };
    let n = runs.len();
    let kinds: [(usize, String, Profile); 3] = [
        (CAPTURED, format!("captured ({n} takes)"), |r| {
            &r.captured_speed
        }),
        (
            PARAMS,
            format!(
                "reach --params: r {:.2} (better {}/{n}), peak error {:.2}, arm path {:.3} \
                 (better {}/{n}), {} hand-overs",
                s.params_correlation,
                s.params_better_correlation,
                s.params_peak_error,
                s.params_arm_path,
                s.params_better_arm_path,
                s.hand_overs
            ),
            |r| &r.params_speed,
        ),
        (
            PROFILE,
            format!(
                "default profile: r {:.2}, peak error {:.2}, arm path {:.3}",
                s.profile_correlation, s.profile_peak_error, s.profile_arm_path
            ),
            |r| &r.profile_speed,
        ),
    ];
    let mut series = Vec::with_capacity(3 * n);
    for (colour, name, values) in kinds {
        for (i, run) in runs.iter().enumerate() {
            series.push(Series {
                name: if i == 0 { name.clone() } else { String::new() },
                points: line(values(run)),
                colour: Some(colour),
            });
        }
    }
    let cut_note = if cut {
        format!(" (lines cut at {cap:.1} m/s; highest {highest:.1})")
    } else {
        String::new()
    };
    let chart = LineChart {
        title: format!("{who}: hand speed over the reach{cut_note}"),
        x_label: "fraction of the reach".into(),
        y_label: "hand speed relative to the shoulder (m/s)".into(),
        series,
    };
    save_both(&chart, dir, "speed", (1100, 600))
}

/// The side view: screen right = +Z (where the character faces), up = +Y.
fn side(p: &Point3<f64>) -> (f64, f64) {
    (p.z, p.y)
}

/// Frame `onset + τ (end − 1 − onset)`, rounded.
fn frame_at(onset: usize, end: usize, tau: f64) -> usize {
    let last = end.saturating_sub(1).max(onset);
    onset + ((last - onset) as f64 * tau).round() as usize
}

/// The poses of `clip` at `frames`, world positions moved by `to`, as the stick figure sees
/// them from the side.
fn poses_of(
    clip: &Clip,
    frames: &[usize],
    to: impl Fn(&Point3<f64>) -> Point3<f64>,
    name: &str,
) -> Result<Vec<Pose2>, DrawError> {
    let skeleton = clip.skeleton();
    let n = skeleton.joint_count();
    let mut world = Vec::with_capacity(n * frames.len());
    for &i in frames {
        let pose = clip.frame(i).ok_or_else(|| DrawError::NoFrame {
            name: name.to_string(),
            frame: i,
        })?;
        let w = skeleton
            .world_positions(pose)
            .map_err(|source| DrawError::Pose {
                name: name.to_string(),
                source,
            })?;
        world.extend(w.iter().map(&to));
    }
    let figure = StickFigure::new(skeleton, &world);
    Ok(world
        .chunks(n)
        .map(|w| {
            Pose2::new(
                &figure.world_segments(w),
                figure.dots().iter().map(|&j| w[j]),
                side,
            )
        })
        .collect())
}

/// `strip.svg|png`: the first capture's reach, the character over the capture.
fn film_strip(
    dir: &Path,
    who: &str,
    clip: &Clip,
    capture: &StyleCapture,
    run: &StyleRun,
    arm: Side,
) -> Result<(), DrawError> {
    let name = &run.row.clip;
    let character_failed = |source| DrawError::Character {
        name: name.clone(),
        source,
    };
    let [onset, end] = capture.frames();
    let to = capture.to_character(arm).map_err(character_failed)?;
    let frames: Vec<usize> = STRIP_AT.iter().map(|&t| frame_at(onset, end, t)).collect();
    let captured = poses_of(clip, &frames, |p| to * p, name)?;
    let motion = &run.params_motion;
    let start = motion.report.arm_onset_frame.min(motion.poses.len());
    let picked: Vec<_> = STRIP_AT
        .iter()
        .filter_map(|&t| motion.poses.get(frame_at(start, motion.poses.len(), t)))
        .cloned()
        .collect();
    let character = capture
        .character()
        .to_clip(&picked, motion.frame_time)
        .map_err(character_failed)?;
    let all: Vec<usize> = (0..picked.len()).collect();
    let reached = poses_of(&character, &all, |p| *p, name)?;
    let panels = captured
        .into_iter()
        .zip(reached)
        .map(|(c, r)| vec![c, r])
        .collect();
    let stem = Path::new(name)
        .file_stem()
        .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned());
    let strip = FilmStrip {
        title: format!(
            "{who}, {stem}: r {:.2}, peak error {:.2}, arm path {:.3}{} (side view)",
            run.row.params_correlation,
            run.row.params_peak_error,
            run.row.params_arm_path,
            if run.row.params_hand_over {
                ", handed over"
            } else {
                ""
            }
        ),
        figures: vec!["captured".into(), "reach --params (full body)".into()],
        colours: vec![CAPTURED, PARAMS],
        panels,
        labels: STRIP_AT
            .iter()
            .map(|t| format!("{:.0} % of the reach", t * 100.0))
            .collect(),
    };
    save_both(&strip, dir, "strip", (1250, 480))
}

#[cfg(test)]
mod tests {
    use super::frame_at;

    #[test]
    fn strip_frames_span_the_reach_from_onset_to_its_last_frame() {
        assert_eq!(frame_at(10, 31, 0.0), 10);
        assert_eq!(frame_at(10, 31, 1.0), 30);
        assert_eq!(frame_at(10, 31, 0.5), 20);
        assert_eq!(frame_at(5, 5, 1.0), 5);
    }
}
