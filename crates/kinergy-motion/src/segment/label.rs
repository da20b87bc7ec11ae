//! Sub-movements grouped into movements and labelled (module docs, steps 3 to 6).

use nalgebra::{Point3, Vector3};

use super::motion::{Motion, Stroke};
use super::signal::Signal;
use super::types::{Label, Segment, SegmentSettings};

/// The cosine below which two sub-movements go opposite ways (135°).
const OPPOSITE_COS: f64 = -0.7;

/// A labelled segment and whether it is one directed movement (a chain of step 3, whatever
/// its label) rather than oscillation or the small sub-movements left over (dither, waving in
/// place), which are `other` whatever way they go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Labelled {
    pub segment: Segment,
    pub directed: bool,
}

/// The labelled segments of a clip's motions and sub-movements, in time order and disjoint.
pub(super) fn label(
    signal: &Signal,
    motions: &[Motion],
    strokes: &[Stroke],
    settings: &SegmentSettings,
) -> Vec<Labelled> {
    let c = Context {
        signal,
        motions,
        strokes,
        settings,
    };
    let big: Vec<usize> = (0..strokes.len()).filter(|&k| !c.small(k)).collect();
    let oscillating = c.oscillations(&big);
    let mut groups: Vec<(Vec<usize>, Option<Label>)> = Vec::new();
    for chain in c.chains(&big, &oscillating) {
        groups.extend(c.trim(chain).into_iter().map(|part| (part, None)));
    }
    // Each oscillation run is one `other` segment.
    let mut run: Vec<usize> = Vec::new();
    for &k in big.iter().filter(|&&k| oscillating[k]) {
        if run
            .last()
            .is_some_and(|&j| !c.reverses(j, k) || c.hold_between(j, k))
        {
            groups.push((std::mem::take(&mut run), Some(Label::Other)));
        }
        run.push(k);
    }
    groups.extend((!run.is_empty()).then_some((run, Some(Label::Other))));
    // A group spans the small sub-movements between its first and last one.
    let mut used = vec![false; strokes.len()];
    for (g, _) in &groups {
        used[g[0]..=g[g.len() - 1]]
            .iter_mut()
            .for_each(|u| *u = true);
    }
    // Small sub-movements left over (a hand that dithers, waves in place): `other`, one
    // segment per stretch without a hold.
    let mut stretch: Vec<usize> = Vec::new();
    for k in (0..strokes.len()).filter(|&k| !used[k]) {
        if stretch
            .last()
            .is_some_and(|&j| j + 1 != k || c.hold_between(j, k))
        {
            groups.push((std::mem::take(&mut stretch), Some(Label::Other)));
        }
        stretch.push(k);
    }
    groups.extend((!stretch.is_empty()).then_some((stretch, Some(Label::Other))));
    groups.sort_by_key(|(g, _)| strokes[g[0]].onset);

    let mut reach_starts: Vec<Point3<f64>> = Vec::new();
    let mut out: Vec<Labelled> = Vec::new();
    for (group, fixed) in groups {
        let label = fixed.unwrap_or_else(|| c.label_of(&group, &reach_starts));
        if label == Label::Reach {
            reach_starts.push(signal.path[strokes[group[0]].onset]);
        }
        out.push(Labelled {
            segment: c.segment(&group, label),
            directed: fixed.is_none(),
        });
    }
    // Two segments split at a speed minimum both hold its frame: it ends the first.
    for i in 1..out.len() {
        let previous_end = out[i - 1].segment.end;
        let s = &mut out[i].segment;
        if s.onset < previous_end {
            s.onset = previous_end.min(s.end - 1);
            s.peak = s.peak.max(s.onset);
            s.truncated_start = false;
        }
    }
    out.retain(|l| l.segment.duration(signal.frame_time) >= settings.min_duration);
    out
}

struct Context<'a> {
    signal: &'a Signal,
    motions: &'a [Motion],
    strokes: &'a [Stroke],
    settings: &'a SegmentSettings,
}

impl Context<'_> {
    /// The hand's displacement over sub-movement `k`, in the frame of the speed.
    fn d(&self, k: usize) -> Vector3<f64> {
        let s = &self.strokes[k];
        self.signal.path[s.end] - self.signal.path[s.onset]
    }

    fn small(&self, k: usize) -> bool {
        self.d(k).norm() < self.settings.small_move * self.signal.arm_length
    }

    /// Sub-movement `k` starts the clip already moving.
    fn cut_start(&self, k: usize) -> bool {
        let s = &self.strokes[k];
        s.onset == 0 && self.motions[s.motion].cut_start
    }

    /// Sub-movement `k` runs into the clip's end still moving.
    fn cut_end(&self, k: usize) -> bool {
        let s = &self.strokes[k];
        s.end + 1 == self.signal.len() && self.motions[s.motion].cut_end
    }

    /// Sub-movement `k` ends with the hand at rest (its motion's end), not at a speed minimum
    /// inside a motion nor at the clip's end.
    fn stops(&self, k: usize) -> bool {
        let s = &self.strokes[k];
        s.end == self.motions[s.motion].end && !self.cut_end(k)
    }

    /// The hand is held after sub-movement `k`: it comes to rest there, or nothing but small
    /// sub-movements (dither, waving in place) follows for at least `hold` seconds.
    fn held(&self, k: usize) -> bool {
        if self.stops(k) {
            return true;
        }
        !self.cut_end(k)
            && (k + 1..self.strokes.len())
                .find(|&j| !self.small(j))
                .is_none_or(|j| self.hold_between(k, j))
    }

    /// The hand rests at least `hold` seconds between sub-movements `j` and `k` (j before k).
    fn hold_between(&self, j: usize, k: usize) -> bool {
        let gap = self.strokes[k].onset.saturating_sub(self.strokes[j].end);
        gap as f64 * self.signal.frame_time >= self.settings.hold
    }

    /// `k` goes back the way `j` came: the two displacements are more than 135° apart and
    /// `k` undoes at least half of `j` (any part, when `k` runs into the clip's end).
    fn reverses(&self, j: usize, k: usize) -> bool {
        let (dj, dk) = (self.d(j), self.d(k));
        let (nj, nk) = (dj.norm(), dk.norm());
        if nj == 0.0 || nk == 0.0 {
            return false;
        }
        let back = -dk.dot(&dj) / nj;
        -back / nk <= OPPOSITE_COS && (back >= 0.5 * nj || self.cut_end(k))
    }

    /// The hand goes mostly one way from frame `a` to frame `b`: its displacement is at least
    /// half the length of its path (a correction does; dithering or waving in place does not).
    fn one_way(&self, a: usize, b: usize) -> bool {
        let path = &self.signal.path;
        let length: f64 = (a..b).map(|i| (path[i + 1] - path[i]).norm()).sum();
        (path[b] - path[a]).norm() >= 0.5 * length
    }

    /// Which of the sub-movements `big` (time order) oscillate: runs of at least 3, each
    /// reversing the one before without a hold between.
    fn oscillations(&self, big: &[usize]) -> Vec<bool> {
        let mut out = vec![false; self.strokes.len()];
        let mut i = 0;
        while i < big.len() {
            let mut j = i;
            while j + 1 < big.len()
                && !self.hold_between(big[j], big[j + 1])
                && self.reverses(big[j], big[j + 1])
            {
                j += 1;
            }
            if j + 1 - i >= 3 {
                big[i..=j].iter().for_each(|&k| out[k] = true);
            }
            i = j + 1;
        }
        out
    }

    /// The sub-movements `big` (time order) not oscillating, in chains: a chain ends at a
    /// hold, a reversal or an oscillation; it takes along the small sub-movements right after
    /// its last one, inside the same motion, when the hand comes to rest with them and they
    /// move it mostly one way (a final correction).
    fn chains(&self, big: &[usize], oscillating: &[bool]) -> Vec<Vec<usize>> {
        let mut chains: Vec<Vec<usize>> = Vec::new();
        let mut current: Vec<usize> = Vec::new();
        for &k in big {
            if oscillating[k] {
                chains.extend((!current.is_empty()).then(|| std::mem::take(&mut current)));
                continue;
            }
            if current
                .last()
                .is_some_and(|&j| self.hold_between(j, k) || self.reverses(j, k))
            {
                chains.push(std::mem::take(&mut current));
            }
            current.push(k);
        }
        chains.extend((!current.is_empty()).then_some(current));
        for chain in &mut chains {
            let last = chain[chain.len() - 1];
            let mut k = last + 1;
            while k < self.strokes.len() && self.small(k) && !self.hold_between(k - 1, k) {
                k += 1;
            }
            if k > last + 1
                && self.stops(k - 1)
                && self.one_way(self.strokes[last].end, self.strokes[k - 1].end)
            {
                chain.extend(last + 1..k);
            }
        }
        chains
    }

    /// A chain cut where the approach to its end begins (module docs, step 4): walking back
    /// from the last sub-movement, each one that brings the hand (in the world) closer to
    /// where the chain ends by at least half its own length belongs to the approach; the
    /// rest before it is cut off and cut the same way.
    fn trim(&self, mut chain: Vec<usize>) -> Vec<Vec<usize>> {
        let world = &self.signal.world;
        let mut parts = Vec::new();
        while let Some(&last) = chain.last() {
            // A final correction — shorter than half the sub-movement before it — is
            // judged with what it corrects: an overshoot it brings back, an undershoot it
            // completes. The approach is walked back from where the corrected one ends.
            let corrects = chain.len() >= 2
                && self.d(last).norm() < 0.5 * self.d(chain[chain.len() - 2]).norm();
            let mut t = chain.len() - 1 - usize::from(corrects);
            let target = world[self.strokes[chain[t]].end];
            while t > 0 {
                let s = &self.strokes[chain[t - 1]];
                let (from, to) = (world[s.onset], world[s.end]);
                let closer = (from - target).norm() - (to - target).norm();
                if self.small(chain[t - 1]) || closer >= 0.5 * (to - from).norm() {
                    t -= 1;
                } else {
                    break;
                }
            }
            parts.push(chain.split_off(t));
        }
        parts.reverse();
        parts
    }

    /// The label of a chain (module docs, step 5), given the onset positions of the reaches
    /// before it.
    fn label_of(&self, group: &[usize], reach_starts: &[Point3<f64>]) -> Label {
        let (first, last) = (group[0], group[group.len() - 1]);
        let onset = self.strokes[first].onset;
        let path = &self.signal.path;
        let (a, b) = (path[onset], path[self.strokes[last].end]);
        let cut_end = self.cut_end(last);
        let length = self.signal.arm_length;
        let hanging = [self.signal.hanging(onset)];
        let references: &[Point3<f64>] = if reach_starts.is_empty() {
            if (a - hanging[0]).norm() >= self.settings.small_move * length {
                &hanging
            } else {
                &[]
            }
        } else {
            reach_starts
        };
        // Below the standing body's resting hand by a reach's length, the hand has been
        // carried down to something: under a bent trunk it hangs as it does at rest, but it
        // is not back at rest.
        let lowered = self.signal.world[self.strokes[last].end].y
            < self.signal.rest_height() - self.settings.min_reach * length;
        if !lowered && references.iter().any(|&r| returns(a, b, r, cut_end)) {
            Label::Return
        } else if (b - a).norm() >= self.settings.min_reach * length && (self.held(last) || cut_end)
        {
            Label::Reach
        } else {
            Label::Other
        }
    }

    fn segment(&self, group: &[usize], label: Label) -> Segment {
        let (first, last) = (group[0], group[group.len() - 1]);
        let (onset, end) = (self.strokes[first].onset, self.strokes[last].end);
        let speed = &self.signal.speed;
        let peak = group
            .iter()
            .map(|&k| self.strokes[k].peak)
            .fold(
                onset,
                |best, i| if speed[i] > speed[best] { i } else { best },
            );
        Segment {
            onset,
            peak,
            end: end + 1,
            peak_speed: speed[peak],
            label,
            truncated_start: self.cut_start(first),
            truncated_end: self.cut_end(last),
            displacement: (self.signal.path[end] - self.signal.path[onset]).norm(),
            from_world: false,
        }
    }
}

/// The reaches of `segments` (one reading of the clip on `signal`, in time order and
/// disjoint) each with the hand's settle after it (module docs, step 6).
pub(super) fn settle(
    signal: &Signal,
    mut segments: Vec<Segment>,
    settings: &SegmentSettings,
) -> Vec<Segment> {
    for i in 0..segments.len() {
        if segments[i].label == Label::Reach {
            let next = segments.get(i + 1).map_or(signal.len(), |s| s.onset);
            segments[i] = settled(signal, &segments[i], next, settings);
        }
    }
    segments
}

/// `w` (a reach) with the hand's settle after it (module docs, step 8): where its motion ends
/// above `rest_speed` — the hand turns or slows, it does not rest — and the hand comes to rest
/// before frame `next` (the next segment's onset), within a small move, the reach ends where
/// it comes to rest: a squat's dip below the object and back up to it, a last correction too
/// short to be a motion. Unchanged otherwise.
pub(super) fn settled(
    signal: &Signal,
    w: &Segment,
    next: usize,
    settings: &SegmentSettings,
) -> Segment {
    let (speed, path) = (&signal.speed, &signal.path);
    let last = w.end - 1;
    if w.truncated_end || speed[last] < settings.rest_speed {
        return *w;
    }
    let mut i = last + 1;
    while i < next && speed[i] >= settings.rest_speed {
        i += 1;
    }
    if i >= next || (path[i] - path[last]).norm() >= settings.small_move * signal.arm_length {
        return *w;
    }
    Segment {
        end: i + 1,
        displacement: (path[i] - path[w.onset]).norm(),
        ..*w
    }
}

/// The hand goes from `a` to `b` back toward `r`: at least half of the way it moves is
/// toward `r`, it ends nearer to `r` than it started, and it covers at least half the
/// distance to `r` (unless the clip ends first).
fn returns(a: Point3<f64>, b: Point3<f64>, r: Point3<f64>, cut_end: bool) -> bool {
    let to_r = r - a;
    let distance = to_r.norm();
    if distance == 0.0 {
        return false;
    }
    let d = b - a;
    let toward = d.dot(&to_r) / distance;
    toward >= 0.5 * d.norm() && (b - r).norm() < distance && (cut_end || toward >= 0.5 * distance)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_return_goes_back_at_least_half_way() {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let start = p(0.0, -0.6);
        // Raised to (0, 0.2), then lowered most of the way back: a return.
        assert!(returns(p(0.0, 0.2), p(0.05, -0.5), start, false));
        // Lowered a quarter of the way only: not a return, unless the clip ends there.
        assert!(!returns(p(0.0, 0.2), p(0.0, 0.0), start, false));
        assert!(returns(p(0.0, 0.2), p(0.0, 0.0), start, true));
        // Swinging past the start to the other side, farther than it began: not a return.
        assert!(!returns(p(0.0, 0.2), p(0.0, -1.6), start, false));
        // Mostly sideways, though it ends a little nearer: not a return.
        assert!(!returns(p(0.0, 0.2), p(0.6, 0.1), start, false));
        // From the reference itself: nowhere to go back to.
        assert!(!returns(start, p(0.3, 0.0), start, false));
    }
}
