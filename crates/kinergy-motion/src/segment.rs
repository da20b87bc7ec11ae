//! Reach segmentation: where in a clip an arm reaches, comes back, or does something else,
//! from the hand's speed and direction (DESIGN §1.1).
//!
//! Aubry et al. (2009) fit synergy parameters to clips that each hold one seated reach; real
//! captures hold rests, the return of the arm after the reach, gestures and walking around it.
//! This module cuts a clip into labelled segments so a fit can take the reach (`kinergy
//! segment CLIP.bvh` prints them):
//!
//! - [`Label::Reach`]: the hand leaves where it was and ends held somewhere away from it,
//!   whether the arm carries it or the trunk (the reach of a pick-up ends at the object on the
//!   floor);
//! - [`Label::Return`]: the hand goes back toward where an earlier reach of the clip started
//!   — or, with no earlier reach, toward the arm's rest, hanging straight down;
//! - [`Label::Other`]: the rest: oscillation (waving, the arm swing of walking, dribbling),
//!   small moves, moves that do not end with the hand held.
//!
//! A segment that starts on the clip's first frame with the hand already moving, or runs into
//! its last frame still moving, is *truncated* ([`Segment::truncated_start`],
//! [`Segment::truncated_end`]). The clip's *main* reach ([`main_index`], [`main_segment`]) is
//! the reach whose hand moves farthest from onset to end ([`Segment::displacement`]: relative
//! to the shoulder, or in the world for a reach the trunk carries, step 7); a reach cut by the
//! clip's end (its target unseen) is the main one only when no reach is whole.
//!
//! # Frames
//!
//! One convention, used by [`Segment`], by `kinergy segment`'s text and JSON, by the segments
//! file (kinergy-train's `segments_file`) and by `--frames A..B`: frames are numbered from 0 and a segment
//! is the range `onset..end`, **end excluded** (Rust's `Range`, [`Segment::frames`]). The hand
//! starts leaving on frame `onset` and has arrived on frame `end − 1`. The `A..B` that
//! `kinergy segment` prints pastes into `--frames A..B` as it is.
//!
//! # The speed signal
//!
//! [`hand_speed`] is the speed of the arm's end effector ([`ArmJoints::end_effector`]), m/s,
//! one value per frame:
//!
//! 1. the path is the hand's world position minus the shoulder's
//!    ([`SegmentSettings::relative_to_shoulder`], the default) or the hand's world position;
//! 2. one-frame spikes are removed. An inner frame i is a spike when it stands more than
//!    1 cm off the per-coordinate median of itself and its two neighbours, turns back sharply
//!    — it leaves the chord of its neighbours by more than half the chord's length,
//!    |p_i − (p_{i−1} + p_{i+1})/2| > |p_{i+1} − p_{i−1}|/2 — and leaves it farther than either
//!    neighbour leaves theirs (a jump moves its neighbours' midpoints half as far as itself).
//!    It is replaced by the cubic through frames i ± 1 and i ± 2, (−p_{i−2} + 4p_{i−1} +
//!    4p_{i+1} − p_{i+2})/6 (the midpoint next to an end). The first frame is a spike when it
//!    stands more than 1 cm off the median of itself, the second frame and their linear
//!    extrapolation, and its step to the second frame is more than twice the next step plus
//!    1 cm; it is replaced by that extrapolation (the last frame likewise). A joint that
//!    jumps for one frame and comes back — a capture glitch, a marker swap — would otherwise
//!    read as a 13 m/s peak at 30 Hz for a 22 cm jump. Motion monotone in every coordinate
//!    over three frames is its own median and passes bit for bit, as does a path that turns
//!    by less than a right angle at every frame; the cubic puts a glitched frame back within
//!    a fraction of a millimetre of a smooth path, so the segments do not move (one frame
//!    that turns back sharply is indistinguishable from a glitch, and is treated as one);
//! 3. speed by central differences, |p_{i+1} − p_{i−1}| / 2Δt, one-sided at the two ends
//!    ([`speed_series`](crate::speed_series));
//! 4. a centred moving average over [`SegmentSettings::smoothing`] seconds (an odd number of
//!    frames, at least one; near the ends the window is cut to the frames that exist), a
//!    low-pass that removes capture jitter without moving a symmetric bell's peak.
//!
//! Relative to the shoulder, walking, stepping and the translation of the torso (sway,
//! bending) do not count as hand motion: only what the arm itself does moves the hand relative
//! to the shoulder. The difference is taken in world axes, so a rotation of the whole torso
//! about the shoulder still moves the hand (a torso twist is part of many reaches). The world
//! paths of the hand and the shoulder used below are despiked the same way, and the arm's
//! length L (shoulder → elbow → wrist → hand point) is the median over frames, so one bad
//! frame changes nothing. What the relative reading misses — a stoop or a squat carrying the
//! hand down to the floor while the arm moves little — step 7 takes from the world reading.
//!
//! # The rule
//!
//! With s the smoothed speed and p the despiked path:
//!
//! 1. **Motions** — stretches of frames between rests. Repeat, until no frame is left: the
//!    peak q is the fastest frame no motion holds yet; stop when s_q <
//!    [`SegmentSettings::min_peak_speed`] (when a neighbour of q is faster, q is the tail of a
//!    motion already taken and is set aside). The rest threshold is
//!    r = max([`rest_fraction`](SegmentSettings::rest_fraction) · s_q,
//!    [`rest_speed`](SegmentSettings::rest_speed)); walking back from q to the first frame
//!    with s < r gives the onset, walking forward the end, neither entering another motion.
//!    Below r the hand may still be slowing down (slow movers creep the last centimetres: in
//!    one Bandai "elderly" raise the hand still moves at 5–8 cm/s for eight frames after its
//!    speed fell below r), so each side then continues while s keeps falling and stays above
//!    `rest_speed`: the onset and end are where the hand has stopped accelerating or
//!    decelerating. With the defaults a minimum-jerk reach between rests is found from where
//!    its speed crosses 0.05 m/s to where it falls below it again. Motions shorter than
//!    [`min_duration`](SegmentSettings::min_duration) are dropped.
//! 2. **Sub-movements** — a motion is split at its deepest interior speed minimum m while
//!    s_m ≤ [`split_ratio`](SegmentSettings::split_ratio) · min(highest s before m, highest
//!    s after m), both of those being at least `min_peak_speed`: a reach made of a fast
//!    transport and a slower correction, a raise followed at once by a wave, a dribble's
//!    push and lift. A single bell has no interior minimum; wobbles shallower than half the
//!    slower peak are one movement. Each sub-movement k has the displacement d_k = p(end) −
//!    p(onset); it is *small* when |d_k| < [`small_move`](SegmentSettings::small_move) · L
//!    (a waving hand's strokes, a few centimetres; the dither of a hold).
//! 3. **Oscillation and chains** — among the sub-movements that are not small, k *reverses* j
//!    (its predecessor) when d_j and d_k are more than 135° apart and k undoes at least half
//!    of j along d_j (any part, when k runs into the clip's end). A run of at least 3
//!    sub-movements each reversing the one before, with no *hold* between them (a rest of at
//!    least [`hold`](SegmentSettings::hold) seconds), is oscillation: one `other` segment.
//!    Arm swing, waving and dribbling reverse almost exactly (near 180°); a reach and its
//!    return are two reversing sub-movements, so it takes a third to make an oscillation.
//!    The others form chains: consecutive sub-movements with no hold and no reversal between
//!    them are one movement (a brief stop — the gather and release of a basketball shot —
//!    does not end it; a return does). The small sub-movements right after a chain, with no
//!    hold before them (in the same motion or the next), join it when the hand comes to rest
//!    with them and they move it mostly one way, their displacement at least half their
//!    path's length (a final correction; dithering or waving in place goes nowhere).
//! 4. **Where a reach begins** — walking back from a chain's last sub-movement, a
//!    sub-movement belongs to the approach when it brings the hand, in the world, closer to
//!    where the chain ends by at least half its own length (small ones always belong). The
//!    sub-movements before the first that does not are cut off as a chain of their own, cut
//!    the same way. A last sub-movement shorter than half the one before it is a correction,
//!    judged with what it corrects: the walk back starts from where the corrected one ends
//!    (an approach that overshoots its target and comes back, or falls short and completes,
//!    is one reach). In the world because a reach's goal is a place: a step or a squat that
//!    carries the hand toward it is part of reaching it, while a dribble before a shot is
//!    not. The hand must still move relative to the shoulder (steps 1–2), or be carried up or
//!    down by the trunk (step 7), so walking alone is never a reach.
//! 5. **Labels**, in time order, for each chain from a to b (p at its first and last frame,
//!    d = b − a):
//!    - *return* when, for the onset position r of some earlier reach of the clip (with
//!      none, the hanging hand, r = shoulder + (0, −L, 0), provided |a − r| ≥ `small_move` ·
//!      L), at least half of |d| goes toward r, b is nearer to r than a, and the hand covers
//!      at least half of |r − a| toward r (waived when the chain runs into the clip's end) —
//!      unless the hand ends, in the world, more than `min_reach` · L below where it hangs
//!      from the standing body (the highest the shoulder gets in the clip, less L): carried
//!      down to something (the floor, a low shelf), under a bent trunk it hangs as it does at
//!      rest but is not back at rest;
//!    - else *reach* when |d| ≥ [`min_reach`](SegmentSettings::min_reach) · L and the hand
//!      is held after the chain — it comes to rest (the chain ends a motion), or only small
//!      sub-movements follow for at least `hold` seconds (a hand raised to wave) — or the
//!      chain runs into the clip's end;
//!    - else *other*.
//!
//!    Small sub-movements not taken by a chain or an oscillation are `other`, one segment per
//!    stretch without a hold.
//! 6. **Output** — segments in time order, disjoint: two segments split at a speed minimum
//!    share its frame, which goes to the first. Segments shorter than `min_duration` are
//!    dropped. The peak of a segment is its fastest frame. A reach ends where the hand comes
//!    to rest: where its motion ends with s still at least `rest_speed` (the hand turns or
//!    slows, it does not rest) and s falls below `rest_speed` before the next segment starts,
//!    less than `small_move` · L from where the motion ended, the reach ends on that frame (a
//!    last correction too short to be a motion of its own; a squat's dip below the object and
//!    back up to it).
//! 7. **Reaches the trunk carries** (relative to the shoulder only) — relative to the
//!    shoulder, a stoop to the floor barely moves the hand, and a hand that ends hanging
//!    straight down under a bent trunk looks like the arm going back to rest: a pick-up's way
//!    down to the object reads as `other` and `return`, and the lift after it as the reach.
//!    So the clip is also read in the world (steps 1–6 on the world path: what `--world`
//!    gives). Take a world segment w (a reach or a return), D the hand's world displacement
//!    over it, S the shoulder's, G = (S_x, 0, S_z) the shoulder's displacement over the
//!    ground and o = |D − G| the hand's *own way*, without the body's travel. It counts only
//!    when:
//!    - o ≥ `min_reach` · L, and the shoulder's path over the ground (frame to frame) is at
//!      most o + L: a step and a lean carry the hand toward what it reaches, walking carries
//!      it farther (walking alone is never a reach); and
//!    - the relative reading has segments on at least half of w's frames: the arm itself
//!      moves (a hand the body carries while the arm hangs still — the idle hand of a
//!      one-hand pick-up — reaches for nothing).
//!
//!    The *trunk carries* w when the shoulder rises or falls by at least half of o and by at
//!    least `min_reach` · L (a stoop, a squat, standing up). These tests take w as its motion
//!    ends, before step 6's settle. Then:
//!    - a relative reach *arrives* in w when it overlaps w, ends in its later half and stops
//!      within `small_move` · L of where w stops; it *has all of* w when it also starts no
//!      later than w;
//!    - a reach w that ends held (not cut by the clip's end) and that the trunk carries
//!      *replaces* the relative segments over its frames — the reach ends where the hand
//!      stops in the world, not where the arm stops moving relative to the shoulder — unless
//!      a relative reach has all of it: that one stays, its displacement measured in the
//!      world;
//!    - a reach w that ends held, not carried by the trunk, where a relative reach arrives
//!      (the relative reading has it): the relative reach stays;
//!    - a reach w that ends held, without such a relative reach, replaces the relative
//!      segments if the relative reading missed it: the relative segments at least half
//!      inside w cover at least half of it, each one directed movement (a chain of step 3, not
//!      oscillation nor dither — an arm swing is no reach missed) and one at least
//!      `min_reach` · L long, labelled `other` or `return`;
//!    - a return the trunk carries (the lift after a pick-up) replaces them too.
//!
//!    A relative segment with at least half of its frames inside replacing world segments is
//!    dropped; one with fewer is cut to its longest stretch outside them (peak and
//!    displacement taken again). A replacing segment is the world reading's: frames, label,
//!    peak, speed and displacement (a reach settled as in step 6, on the world path).
//!    Segments measured or replacing are marked [`Segment::from_world`]. The two hands of a both-hands pick-up — one arm's reach found
//!    relative to the shoulder, the other's only in the world — so compare alike (`--arm
//!    auto` keeps an arm by its reach's displacement). Raises, pointing and reaches at a
//!    table change nothing: the shoulder barely rises or falls and the relative reading has
//!    the reach.
//!
//! Empty, one-frame and motionless clips give no segment (never a panic).
//!
//! ```
//! use kinergy_motion::{clip_from_bvh, ArmJoints, ImportOptions, Side};
//! use kinergy_motion::segment::{find_segments, SegmentSettings};
//!
//! // A clip at rest: no segment.
//! let text = "HIERARCHY\nROOT Chest\n{\n OFFSET 0 140 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n \
//!     JOINT RightShoulder\n {\n  OFFSET -5 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
//!     JOINT RightArm\n  {\n   OFFSET -15 0 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
//!     JOINT RightForeArm\n   {\n    OFFSET -28 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    \
//!     JOINT RightHand\n    {\n     OFFSET -26 0 0\n     CHANNELS 3 Zrotation Xrotation Yrotation\n     \
//!     End Site\n     {\n      OFFSET -9 0 0\n     }\n    }\n   }\n  }\n }\n}\n\
//!     MOTION\nFrames: 2\nFrame Time: 0.0333333\n\
//!     0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";
//! let bvh = kinergy_motion::kinergy_bvh::parse(text)?;
//! let options = ImportOptions { unit: "cm".parse()?, ..Default::default() };
//! let (clip, _report) = clip_from_bvh(&bvh, &options)?;
//! let arm = ArmJoints::find(clip.skeleton(), Side::Right)?;
//! assert!(find_segments(&clip, &arm, &SegmentSettings::default())?.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod carry;
mod label;
mod motion;
mod signal;
mod types;

use std::fmt;
use std::str::FromStr;

use crate::error::{MotionError, Result};
use crate::{ArmJoints, Clip};

pub use types::{Label, Segment, SegmentSettings};

/// Which segments of a clip a command takes: `main`, `all` or a number, as `--select` reads
/// them.
///
/// - `main` ([`Selection::Main`], the default): the main reach;
/// - `all` ([`Selection::All`]): every segment labelled reach, in time order;
/// - `N` ([`Selection::Nth`]): segment number N of the list [`find_segments`] returns and
///   `kinergy segment` prints, **counted from 0** like frames, whatever its label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Selection {
    /// The main reach.
    #[default]
    Main,
    /// Every reach.
    All,
    /// One segment by its number in the list, from 0.
    Nth(usize),
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Selection::Main => f.write_str("main"),
            Selection::All => f.write_str("all"),
            Selection::Nth(n) => write!(f, "{n}"),
        }
    }
}

impl FromStr for Selection {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "main" => Ok(Selection::Main),
            "all" => Ok(Selection::All),
            t => t.parse().map(Selection::Nth).map_err(|_| {
                format!(
                    "`{s}` is not main, all or a segment number (0, 1, … as `kinergy segment` \
                     lists them)"
                )
            }),
        }
    }
}

/// The smoothed speed of the arm's hand (m/s), one value per frame of `clip`; empty for an
/// empty clip. See the [module docs](self) for the signal.
pub fn hand_speed(clip: &Clip, arm: &ArmJoints, settings: &SegmentSettings) -> Result<Vec<f64>> {
    settings.validate()?;
    Ok(signal::Signal::new(clip, arm, settings)?.speed)
}

/// Every segment of `arm` in `clip`, labelled, in time order and disjoint (see the
/// [module docs](self) for the rule). Empty when the hand never moves faster than
/// [`SegmentSettings::min_peak_speed`] for [`SegmentSettings::min_duration`].
pub fn find_segments(
    clip: &Clip,
    arm: &ArmJoints,
    settings: &SegmentSettings,
) -> Result<Vec<Segment>> {
    settings.validate()?;
    let signal = signal::Signal::new(clip, arm, settings)?;
    Ok(segments_of(&signal, settings))
}

/// The segments of `signal`; relative to the shoulder, with the world's in the stretches
/// step 7 takes them.
fn segments_of(signal: &signal::Signal, settings: &SegmentSettings) -> Vec<Segment> {
    let found = labelled(signal, settings);
    if !signal.relative {
        let found = found.into_iter().map(|l| l.segment).collect();
        return label::settle(signal, found, settings);
    }
    let world = signal.in_world(settings);
    let in_world: Vec<Segment> = labelled(&world, settings)
        .into_iter()
        .map(|l| l.segment)
        .collect();
    carry::merge(signal, found, &world, &in_world, settings)
}

/// Steps 1 to 6 on one signal.
fn labelled(signal: &signal::Signal, settings: &SegmentSettings) -> Vec<label::Labelled> {
    let motions = motion::motions(&signal.speed, signal.frame_time, settings);
    let strokes = motion::strokes(&signal.speed, &motions, settings);
    label::label(signal, &motions, &strokes, settings)
}

/// The index of the main reach among `segments` (as [`find_segments`] returns them): the
/// reach of largest displacement, among the reaches not cut by the clip's end if there are
/// any; `None` without a reach. Ties go to the earlier one.
pub fn main_index(segments: &[Segment]) -> Option<usize> {
    let whole = segments
        .iter()
        .any(|s| s.label == Label::Reach && !s.truncated_end);
    segments
        .iter()
        .enumerate()
        .filter(|(_, s)| s.label == Label::Reach && !(whole && s.truncated_end))
        .fold(None, |best: Option<(usize, f64)>, (i, s)| match best {
            Some((_, d)) if d >= s.displacement => best,
            _ => Some((i, s.displacement)),
        })
        .map(|(i, _)| i)
}

/// The clip's main reach (see [`main_index`]). [`MotionError::Reach`], naming `clip_name`, when
/// there is none.
pub fn main_segment(
    clip: &Clip,
    arm: &ArmJoints,
    settings: &SegmentSettings,
    clip_name: &str,
) -> Result<Segment> {
    settings.validate()?;
    let signal = signal::Signal::new(clip, arm, settings)?;
    let segments = segments_of(&signal, settings);
    if let Some(i) = main_index(&segments) {
        return Ok(segments[i]);
    }
    let why = if segments.is_empty() {
        let fastest = signal.speed.iter().copied().fold(0.0, f64::max);
        format!(
            "no hand motion faster than {} m/s lasting {} s (the {} hand's fastest is \
             {fastest:.3} m/s{})",
            settings.min_peak_speed,
            settings.min_duration,
            arm.side
                .map_or_else(|| "arm's".to_string(), |s| s.to_string()),
            if settings.relative_to_shoulder {
                " relative to the shoulder"
            } else {
                ""
            },
        )
    } else {
        format!(
            "no reach among its {} segments ({}): the hand never leaves a place to be held \
             somewhere else",
            segments.len(),
            segments
                .iter()
                .map(|s| format!("{} {}..{}", s.label, s.onset, s.end))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    Err(MotionError::Reach {
        clip: clip_name.to_string(),
        why,
    })
}

/// The segments `selection` takes from `segments` (as [`find_segments`] returns them), in
/// time order. [`MotionError::Reach`], naming `clip_name`, when it takes none: no reach for
/// `main` or `all`, a number past the list's end.
pub fn select(segments: &[Segment], selection: Selection, clip_name: &str) -> Result<Vec<Segment>> {
    let fail = |why: String| MotionError::Reach {
        clip: clip_name.to_string(),
        why,
    };
    let labels = || {
        if segments.is_empty() {
            "it has no segment".to_string()
        } else {
            format!(
                "its segments: {}",
                segments
                    .iter()
                    .enumerate()
                    .map(|(i, s)| format!("#{i} {} {}..{}", s.label, s.onset, s.end))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    };
    match selection {
        Selection::Main => main_index(segments)
            .map(|i| vec![segments[i]])
            .ok_or_else(|| fail(format!("no main reach ({})", labels()))),
        Selection::All => {
            let reaches: Vec<Segment> = segments
                .iter()
                .filter(|s| s.label == Label::Reach)
                .copied()
                .collect();
            if reaches.is_empty() {
                Err(fail(format!("no reach ({})", labels())))
            } else {
                Ok(reaches)
            }
        }
        Selection::Nth(n) => segments.get(n).map(|s| vec![*s]).ok_or_else(|| {
            fail(format!(
                "no segment #{n}: segments are numbered from 0 ({})",
                labels()
            ))
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> SegmentSettings {
        SegmentSettings::default()
    }

    fn seg(onset: usize, end: usize, label: Label, displacement: f64) -> Segment {
        Segment {
            onset,
            peak: onset,
            end,
            peak_speed: 1.0,
            label,
            truncated_start: false,
            truncated_end: false,
            displacement,
            from_world: false,
        }
    }

    #[test]
    fn the_main_reach_is_the_farthest_whole_one() {
        let mut list = vec![
            seg(0, 10, Label::Reach, 0.3),
            seg(10, 30, Label::Return, 0.9),
            seg(30, 40, Label::Reach, 0.5),
            seg(40, 50, Label::Reach, 0.8),
        ];
        list[3].truncated_end = true;
        assert_eq!(main_index(&list), Some(2));
        // Truncated at the start only: its target is seen, it counts.
        list[3].truncated_end = false;
        list[3].truncated_start = true;
        assert_eq!(main_index(&list), Some(3));
        // With no whole reach, a cut one is better than none.
        let cut = [Segment {
            truncated_end: true,
            ..seg(0, 10, Label::Reach, 0.3)
        }];
        assert_eq!(main_index(&cut), Some(0));
        assert_eq!(main_index(&[seg(0, 10, Label::Other, 1.0)]), None);
        assert_eq!(main_index(&[]), None);
    }

    #[test]
    fn selections_parse_and_take_what_they_say() {
        let list = [
            seg(0, 10, Label::Reach, 0.3),
            seg(10, 30, Label::Return, 0.9),
            seg(30, 40, Label::Reach, 0.5),
        ];
        for (text, want) in [
            ("main", Selection::Main),
            ("ALL", Selection::All),
            (" 2 ", Selection::Nth(2)),
        ] {
            let s: Selection = text.parse().expect("selection");
            assert_eq!(s, want);
            assert_eq!(s.to_string().parse::<Selection>(), Ok(s));
        }
        for bad in ["", "first", "-1", "1.5"] {
            let e = bad.parse::<Selection>().expect_err(bad);
            assert!(e.contains("main, all or a segment number"), "{e}");
        }
        let take = |s| select(&list, s, "c.bvh").expect("selection");
        assert_eq!(take(Selection::Main), [list[2]]);
        assert_eq!(take(Selection::All), [list[0], list[2]]);
        assert_eq!(take(Selection::Nth(1)), [list[1]]);
        let e = select(&list, Selection::Nth(3), "c.bvh").expect_err("past the end");
        let msg = e.to_string();
        assert!(msg.starts_with("c.bvh: no segment #3"), "{msg}");
        assert!(msg.contains("#1 return 10..30"), "{msg}");
        let others = [seg(0, 10, Label::Other, 1.0)];
        for s in [Selection::Main, Selection::All] {
            let msg = select(&others, s, "w.bvh")
                .expect_err("no reach")
                .to_string();
            assert!(
                msg.starts_with("w.bvh: no") && msg.contains("other 0..10"),
                "{msg}"
            );
        }
    }

    #[test]
    fn labels_read_back_what_they_write() {
        for l in [Label::Reach, Label::Return, Label::Other] {
            assert_eq!(l.to_string().parse::<Label>(), Ok(l));
        }
        assert!("wave".parse::<Label>().is_err());
    }

    #[test]
    fn frames_and_duration_follow_the_convention() {
        let s = seg(5, 12, Label::Reach, 0.3);
        assert_eq!(s.frames(), 5..12);
        assert_eq!(s.frames().len(), 7);
        approx::assert_relative_eq!(s.duration(0.5), 3.0);
    }

    #[test]
    fn bad_settings_name_their_field() {
        let bad = [
            SegmentSettings {
                smoothing: -1.0,
                ..settings()
            },
            SegmentSettings {
                rest_fraction: 1.0,
                ..settings()
            },
            SegmentSettings {
                rest_speed: f64::NAN,
                ..settings()
            },
            SegmentSettings {
                min_peak_speed: 0.01,
                ..settings()
            },
            SegmentSettings {
                min_duration: f64::INFINITY,
                ..settings()
            },
            SegmentSettings {
                split_ratio: 0.0,
                ..settings()
            },
            SegmentSettings {
                hold: -0.1,
                ..settings()
            },
            SegmentSettings {
                small_move: f64::NAN,
                ..settings()
            },
            SegmentSettings {
                min_reach: 0.05,
                ..settings()
            },
        ];
        let fields = [
            "smoothing",
            "rest_fraction",
            "rest_speed",
            "min_peak_speed",
            "min_duration",
            "split_ratio",
            "hold",
            "small_move",
            "min_reach",
        ];
        for (s, f) in bad.iter().zip(fields) {
            match s.validate() {
                Err(MotionError::Setting(e)) => {
                    assert_eq!(e.field, format!("segment.{f}"))
                }
                other => panic!("{f}: {other:?}"),
            }
        }
        settings().validate().expect("defaults are valid");
    }
}
