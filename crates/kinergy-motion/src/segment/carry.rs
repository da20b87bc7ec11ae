//! Reaches the trunk carries, read in the world (module docs, step 7).
//!
//! Relative to the shoulder, a stoop to the floor barely moves the hand, and a hand that ends
//! hanging straight down under a bent trunk looks like an arm going back to rest; in the
//! world both are the hand going down to where it stops. Where the world reading has a reach
//! the trunk carries, or one the relative reading missed, or a return the trunk carries, and
//! walking does not explain it, it replaces the relative segments over the same frames; a
//! relative reach that has all of a reach the trunk carries is measured in the world.

use nalgebra::Vector3;

use super::label::{Labelled, settle, settled};
use super::signal::Signal;
use super::types::{Label, Segment, SegmentSettings};

/// The shoulder's rise or fall over a segment, as a fraction of the hand's own way (its world
/// displacement without the body's travel over the ground), from which the trunk carries the
/// hand (a stoop, a squat, standing up).
const TRUNK_SHARE: f64 = 0.5;

/// The segments of the relative reading (`relative`, on `signal`) with what the world
/// segments (`world`, on `world_signal`, the same clip read in the world) change in it (module
/// docs, step 7); in time order and disjoint.
pub(super) fn merge(
    signal: &Signal,
    relative: Vec<Labelled>,
    world_signal: &Signal,
    world: &[Segment],
    settings: &SegmentSettings,
) -> Vec<Segment> {
    // Step 7's tests judge a world segment as its motion ends; the one taken ends where the
    // hand comes to rest (step 6).
    let mut taken: Vec<Segment> = Vec::new();
    let mut measured: Vec<Segment> = Vec::new();
    for (i, w) in world.iter().enumerate() {
        match verdict(world_signal, w, &relative, settings) {
            Verdict::Keep => {}
            Verdict::Measure => measured.push(*w),
            Verdict::Take => {
                let next = world.get(i + 1).map_or(world_signal.len(), |s| s.onset);
                let w = if w.label == Label::Reach {
                    settled(world_signal, w, next, settings)
                } else {
                    *w
                };
                taken.push(Segment {
                    from_world: true,
                    ..w
                });
            }
        }
    }
    let hand = &world_signal.world;
    let relative: Vec<Segment> = settle(
        signal,
        relative.into_iter().map(|l| l.segment).collect(),
        settings,
    )
    .into_iter()
    .map(|s| {
        if s.label == Label::Reach
            && measured
                .iter()
                .any(|w| covers(world_signal, &s, w, settings))
        {
            Segment {
                displacement: (hand[s.end - 1] - hand[s.onset]).norm(),
                from_world: true,
                ..s
            }
        } else {
            s
        }
    })
    .collect();
    if taken.is_empty() {
        return relative;
    }
    let mut out = taken.clone();
    for s in relative {
        // Which frames of `s` no taken segment holds.
        let free: Vec<bool> = s
            .frames()
            .map(|i| !taken.iter().any(|t| t.frames().contains(&i)))
            .collect();
        let kept = free.iter().filter(|&&f| f).count();
        if 2 * kept <= free.len() {
            // Mostly the world segment's frames: replaced.
            continue;
        }
        let (start, len) = longest_run(&free);
        let (onset, end) = (s.onset + start, s.onset + start + len);
        if (onset, end) == (s.onset, s.end) {
            out.push(s);
        } else if let Some(cut) = cut(signal, &s, onset, end) {
            out.push(cut);
        }
    }
    out.sort_by_key(|s| s.onset);
    out.retain(|s| s.duration(signal.frame_time) >= settings.min_duration);
    out
}

/// `r` (a relative reach) overlaps `w`, ends in its later half, and its hand stops where
/// `w`'s does (within a small move, in the world): it is the relative reading's arrival of
/// `w`. A relative reach that stops short — the arm done while the trunk still carries the
/// hand down — is not.
fn arrives(world: &Signal, r: &Segment, w: &Segment, settings: &SegmentSettings) -> bool {
    let hand = &world.world;
    r.onset < w.end
        && r.end > w.onset + (w.end - w.onset) / 2
        && (hand[r.end - 1] - hand[w.end - 1]).norm() <= settings.small_move * world.arm_length
}

/// `r` (a relative reach) [`arrives`] in `w` and starts no later: the relative reading has
/// all of `w`.
fn covers(world: &Signal, r: &Segment, w: &Segment, settings: &SegmentSettings) -> bool {
    r.onset <= w.onset && arrives(world, r, w, settings)
}

/// What a world segment does to the relative reading (module docs, step 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// Nothing.
    Keep,
    /// It replaces the relative segments over its frames.
    Take,
    /// The relative reach that has all of it is measured in the world.
    Measure,
}

/// Frames of `r` inside `w`.
fn inside(r: &Segment, w: &Segment) -> usize {
    r.end.min(w.end).saturating_sub(r.onset.max(w.onset))
}

/// What the world segment `w` does to the relative reading (module docs, step 7).
fn verdict(
    world: &Signal,
    w: &Segment,
    relative: &[Labelled],
    settings: &SegmentSettings,
) -> Verdict {
    let (a, b) = (w.onset, w.end.saturating_sub(1));
    if b <= a || b >= world.len() {
        return Verdict::Keep;
    }
    let length = world.arm_length;
    let hand = world.world[b] - world.world[a];
    let shoulder = world.shoulder[b] - world.shoulder[a];
    let ground = Vector3::new(shoulder.x, 0.0, shoulder.z);
    let own = (hand - ground).norm();
    // How far the shoulder goes over the ground, frame by frame (a walk that turns back on
    // itself goes far for a short displacement).
    let travel: f64 = (a..b)
        .map(|i| {
            let d = world.shoulder[i + 1] - world.shoulder[i];
            d.x.hypot(d.z)
        })
        .sum();
    if own < settings.min_reach * length || travel > own + length {
        return Verdict::Keep;
    }
    let span = w.end - w.onset;
    // The arm must move relative to the shoulder over most of `w`: otherwise the body
    // carries a resting hand (the idle hand of a one-hand pick-up).
    let moving: usize = relative.iter().map(|r| inside(&r.segment, w)).sum();
    if 2 * moving < span {
        return Verdict::Keep;
    }
    let trunk = shoulder.y.abs() >= (TRUNK_SHARE * own).max(settings.min_reach * length);
    match w.label {
        Label::Reach if !w.truncated_end => {
            let reach = |r: &&Labelled| r.segment.label == Label::Reach;
            if trunk {
                // The hand goes where the trunk takes it: the reach ends where the hand
                // stops in the world, not where the arm stops moving relative to the
                // shoulder — unless the relative reading has all of it.
                return if relative
                    .iter()
                    .filter(reach)
                    .any(|r| covers(world, &r.segment, w, settings))
                {
                    Verdict::Measure
                } else {
                    Verdict::Take
                };
            }
            if relative
                .iter()
                .filter(reach)
                .any(|r| arrives(world, &r.segment, w, settings))
            {
                // The relative reading has the reach.
                return Verdict::Keep;
            }
            // Or it cuts the same stretch into directed movements — those at least half
            // inside `w` cover at least half of it, none oscillating, one at least a reach's
            // length — and calls them other or return.
            let same: Vec<&Labelled> = relative
                .iter()
                .filter(|r| 2 * inside(&r.segment, w) >= r.segment.end - r.segment.onset)
                .collect();
            let seen: usize = same.iter().map(|r| inside(&r.segment, w)).sum();
            if 2 * seen >= span
                && same.iter().all(|r| r.directed)
                && same
                    .iter()
                    .any(|r| r.segment.displacement >= settings.min_reach * length)
            {
                Verdict::Take
            } else {
                Verdict::Keep
            }
        }
        Label::Return if trunk => Verdict::Take,
        _ => Verdict::Keep,
    }
}

/// The start and length of the longest run of `true` in `flags` (the first among equals).
fn longest_run(flags: &[bool]) -> (usize, usize) {
    let mut best = (0, 0);
    let mut start = 0;
    for (i, &f) in flags.iter().enumerate() {
        if !f {
            start = i + 1;
        } else if i + 1 - start > best.1 {
            best = (start, i + 1 - start);
        }
    }
    best
}

/// `s` (a relative segment) cut to frames `onset..end` (inside it, end excluded): its peak
/// and displacement taken again on `signal`; a cut side is no longer cut by the clip. `None`
/// when fewer than two frames are left.
fn cut(signal: &Signal, s: &Segment, onset: usize, end: usize) -> Option<Segment> {
    if end < onset + 2 || end > signal.len() {
        return None;
    }
    let speed = &signal.speed;
    let peak = (onset..end).fold(
        onset,
        |best, i| if speed[i] > speed[best] { i } else { best },
    );
    Some(Segment {
        onset,
        peak,
        end,
        peak_speed: speed[peak],
        truncated_start: s.truncated_start && onset == s.onset,
        truncated_end: s.truncated_end && end == s.end,
        displacement: (signal.path[end - 1] - signal.path[onset]).norm(),
        ..*s
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_run_is_found() {
        assert_eq!(longest_run(&[]), (0, 0));
        assert_eq!(longest_run(&[false, false]), (0, 0));
        assert_eq!(longest_run(&[true, true, false, true]), (0, 2));
        assert_eq!(longest_run(&[true, false, true, true, true]), (2, 3));
        assert_eq!(longest_run(&[false, true, true]), (1, 2));
    }
}
