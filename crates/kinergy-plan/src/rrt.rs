//! Bidirectional RRT-Connect in the arm's configuration space — Kallmann's Algorithm 1 —
//! with his sampling routine, random-shortcut smoothing and the bell-shaped time warp.
//!
//! The space is the arm's 7 DoFs, and where the body moves ([`ArmSpace::moves_body`]) its
//! three too ([`crate::posture`]): "when spine DoFs and/or root translation DoFs (for knee
//! flexion) are used, they are sampled with very small variation" ([`Sampler`]).
//!
//! # Algorithm 1, as implemented
//! Two trees grow from the start and the goal. Each iteration samples a free posture
//! ([`Sampler`]), finds the node of each tree closest to it (linear search, Kallmann's
//! metric: the largest distance between corresponding tracked points,
//! [`ArmSpace::distance`]), and returns a path as soon as the interpolation between those
//! two nodes is free; otherwise the first tree grows one step of `step` meters from its
//! node toward the sample (the whole way when closer) if that interpolation is free, and the
//! new node is tried against the other tree's node. Then the trees swap roles.
//!
//! # Budget and reproducibility
//! Every random draw comes from one ChaCha8 stream seeded by [`RrtSettings::seed`], so the
//! same seed gives the same path on any machine and thread count — as long as the
//! *iteration* budget is what stops the search. A time budget ([`Budget::time`]) is a
//! safety net for interactive use; when it is what stops a search, the result depends on the
//! machine's speed.
//!
//! # The trees
//! [`search`] returns both trees as the search left them ([`SearchTree`]: each node's
//! configuration, wrist position and parent), for Kallmann's Fig. 4 — "the graph of a search
//! and the solution path, before smoothing" — which `plan --tree-svg` draws.
//!
//! # Smoothing
//! [`smooth`] repeatedly picks two random points along the path (not necessarily nodes) and
//! replaces the stretch between them by their straight interpolation when that is free and
//! shorter. The path never gets longer and never stops being valid (both are checked before
//! a shortcut is kept).

use std::time::{Duration, Instant};

use kinergy_io::InvalidSetting;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

use nalgebra::Point3;

use crate::error::{PlanError, Result};
use crate::posture::{BODY_DOFS, BodyDofs};
use crate::space::{self, ArmConfig, ArmSpace, Points, body_of, lerp};

/// When a search or a smoothing stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// At most this many iterations.
    pub iterations: usize,
    /// At most this much time (`None`: no limit).
    pub time: Option<Duration>,
}

/// Settings of the planner.
#[derive(Debug, Clone, PartialEq)]
pub struct RrtSettings {
    /// ε: how far a tree grows toward a sample per iteration, meters of the planner's
    /// distance.
    pub step: f64,
    /// The elbow flexion is first sampled within this fraction of its range below full
    /// flexion (Kallmann: 90–100 %, so 0.1) …
    pub elbow_start: f64,
    /// … and the interval widens linearly to the whole range over this many iterations.
    pub elbow_widening: usize,
    /// The wrist swing is sampled within this fraction of its ellipse.
    pub wrist_range: f64,
    /// Draws before a sampling gives up on finding a free posture for this iteration.
    pub sample_tries: usize,
    /// Where the body moves: how far its DoFs are sampled off the line between the start's
    /// and the goal's ([`Sampler`]).
    pub body_variation: BodyVariation,
    /// When to give up.
    pub budget: Budget,
    /// The random stream's seed.
    pub seed: u64,
}

impl Default for RrtSettings {
    fn default() -> RrtSettings {
        RrtSettings {
            step: 0.15,
            elbow_start: 0.1,
            elbow_widening: 300,
            wrist_range: 0.3,
            sample_tries: 50,
            body_variation: BodyVariation::default(),
            budget: Budget {
                iterations: 5000,
                time: Some(Duration::from_secs(10)),
            },
            seed: 0,
        }
    }
}

impl RrtSettings {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(
            self.step.is_finite() && self.step > 0.0,
            "rrt.step",
            "a finite number > 0",
        )?;
        InvalidSetting::require(
            (0.0..=1.0).contains(&self.elbow_start),
            "rrt.elbow_start",
            "a fraction in [0, 1]",
        )?;
        InvalidSetting::require(
            (0.0..=1.0).contains(&self.wrist_range),
            "rrt.wrist_range",
            "a fraction in [0, 1]",
        )?;
        InvalidSetting::require(self.sample_tries > 0, "rrt.sample_tries", "at least 1")?;
        self.body_variation.validate()
    }
}

/// How far the body's DoFs are sampled off the line between the start's and the goal's, each
/// by at most ± its value (Kallmann: the spine's and the root's DoFs "are sampled with very
/// small variation, only to give an overall human-like movement, and therefore these DoFs do
/// not augment the dimension of the considered search space").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyVariation {
    /// The spine's swing, radians.
    pub swing: f64,
    /// The spine's twist, radians.
    pub twist: f64,
    /// The squat, meters.
    pub squat: f64,
}

impl Default for BodyVariation {
    /// 3° of swing and of twist, 1 cm of squat.
    fn default() -> BodyVariation {
        BodyVariation {
            swing: 3f64.to_radians(),
            twist: 3f64.to_radians(),
            squat: 0.01,
        }
    }
}

impl BodyVariation {
    /// Checks every field: finite, ≥ 0, at most 30° (swing, twist) or 0.1 m (squat) — a small
    /// variation.
    pub fn validate(&self) -> Result<()> {
        for (name, v, most) in [
            ("rrt.body_variation.swing", self.swing, 30f64.to_radians()),
            ("rrt.body_variation.twist", self.twist, 30f64.to_radians()),
            ("rrt.body_variation.squat", self.squat, 0.1),
        ] {
            InvalidSetting::require(
                v.is_finite() && (0.0..=most).contains(&v),
                name,
                format!("a finite number from 0 to {most:.3}"),
            )?;
        }
        Ok(())
    }

    fn as_array(&self) -> BodyDofs {
        [self.swing, self.twist, self.squat]
    }
}

/// What a search did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanStats {
    /// Iterations of Algorithm 1.
    pub iterations: usize,
    /// Nodes in both trees at the end.
    pub nodes: usize,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Kallmann's sampling routine: valid joint values inside their limits, the elbow biased to
/// almost full flexion (widening with the iterations), the wrist swing within a narrowed
/// ellipse; a sample is kept only when collision-free.
///
/// Where the body moves ([`ArmSpace::moves_body`]), its DoFs are drawn after the arm's: a
/// point uniformly along the line from the start's body DoFs to the goal's ([`Sampler::body_line`];
/// by default from the reference posture to the space's goal posture), moved by at most
/// ± [`RrtSettings::body_variation`] each, within the stance's limits. Where it does not, no
/// draw is made for them: an arm-only search draws what it drew before the body could move.
#[derive(Debug, Clone)]
pub struct Sampler {
    settings: RrtSettings,
    body_line: Option<(BodyDofs, BodyDofs)>,
}

impl Sampler {
    /// A sampler with the settings' biases.
    pub fn new(settings: &RrtSettings) -> Sampler {
        Sampler {
            settings: settings.clone(),
            body_line: None,
        }
    }

    /// The same sampler drawing the body's DoFs about the line from `from` to `to`.
    pub fn body_line(mut self, from: BodyDofs, to: BodyDofs) -> Sampler {
        self.body_line = Some((from, to));
        self
    }

    /// One posture within the limits (not tested for collisions) at `iteration`.
    pub fn draw(&self, space: &ArmSpace, iteration: usize, rng: &mut ChaCha8Rng) -> ArmConfig {
        let l = space.ik().limits();
        let s = &self.settings;
        let (sx, sy) = in_ellipse(l.shoulder_swing, 1.0, rng);
        let twist = uniform(l.shoulder_twist, rng);
        let (lo, hi) = l.elbow_flexion;
        let widen = if s.elbow_widening == 0 {
            1.0
        } else {
            (iteration as f64 / s.elbow_widening as f64).min(1.0)
        };
        let width = s.elbow_start + (1.0 - s.elbow_start) * widen;
        let flex = uniform((hi - width * (hi - lo), hi), rng);
        let etwist = uniform(l.elbow_twist, rng);
        let (wx, wy) = in_ellipse(l.wrist_swing, s.wrist_range, rng);
        let arm = [sx, sy, twist, flex, etwist, wx, wy];
        let Some(motion) = space.body_motion() else {
            return space::join(&arm, &[0.0; BODY_DOFS]);
        };
        let (from, to) = self.body_line.unwrap_or(([0.0; BODY_DOFS], motion.goal()));
        let u: f64 = rng.random_range(0.0..=1.0);
        let spread = s.body_variation.as_array();
        let limits = motion.limits();
        let range = [
            (-limits.swing, limits.swing),
            (-limits.twist, limits.twist),
            (0.0, limits.squat),
        ];
        let body: BodyDofs = std::array::from_fn(|i| {
            let off = if spread[i] > 0.0 {
                rng.random_range(-spread[i]..=spread[i])
            } else {
                0.0
            };
            (from[i] + (to[i] - from[i]) * u + off).clamp(range[i].0, range[i].1)
        });
        space::join(&arm, &body)
    }

    /// A free posture, or `None` after [`RrtSettings::sample_tries`] draws.
    pub fn sample(
        &self,
        space: &ArmSpace,
        iteration: usize,
        rng: &mut ChaCha8Rng,
    ) -> Option<ArmConfig> {
        (0..self.settings.sample_tries)
            .map(|_| self.draw(space, iteration, rng))
            .find(|q| space.contact(q).is_none())
    }
}

fn uniform((lo, hi): (f64, f64), rng: &mut ChaCha8Rng) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

/// Uniform in the ellipse of radii `(rx, ry)` scaled by `scale` (by rejection).
fn in_ellipse((rx, ry): (f64, f64), scale: f64, rng: &mut ChaCha8Rng) -> (f64, f64) {
    loop {
        let u: f64 = rng.random_range(-1.0..1.0);
        let v: f64 = rng.random_range(-1.0..1.0);
        if u * u + v * v <= 1.0 {
            return (u * rx * scale, v * ry * scale);
        }
    }
}

#[derive(Debug, Clone)]
struct Node {
    q: ArmConfig,
    points: Points,
    parent: Option<usize>,
}

#[derive(Debug, Clone, Default)]
struct Tree {
    nodes: Vec<Node>,
}

impl Tree {
    fn add(&mut self, space: &ArmSpace, q: ArmConfig, parent: Option<usize>) -> usize {
        self.nodes.push(Node {
            q,
            points: space.points(&q),
            parent,
        });
        self.nodes.len() - 1
    }

    /// The closest node to `p` and its distance.
    fn nearest(&self, p: &Points) -> (usize, f64) {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = n.points.distance(p);
            if d < best.1 {
                best = (i, d);
            }
        }
        best
    }

    /// Configurations from the root to node `i`.
    fn branch(&self, mut i: usize) -> Vec<ArmConfig> {
        let mut out = vec![self.nodes[i].q];
        while let Some(p) = self.nodes[i].parent {
            out.push(self.nodes[p].q);
            i = p;
        }
        out.reverse();
        out
    }
}

/// One node of a [`SearchTree`].
#[derive(Debug, Clone, PartialEq)]
pub struct TreeNode {
    /// Its configuration.
    pub q: ArmConfig,
    /// The wrist's world position there, meters.
    pub wrist: Point3<f64>,
    /// Its parent's index in the tree (`None` for the root).
    pub parent: Option<usize>,
}

/// One of RRT-Connect's two trees as the search left it: the root first (the start for the
/// first tree, the goal for the second), every other node after its parent.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SearchTree {
    /// The nodes.
    pub nodes: Vec<TreeNode>,
}

impl SearchTree {
    fn of(tree: &Tree) -> SearchTree {
        SearchTree {
            nodes: tree
                .nodes
                .iter()
                .map(|n| TreeNode {
                    q: n.q,
                    wrist: n.points.wrist(),
                    parent: n.parent,
                })
                .collect(),
        }
    }

    /// Its edges, parent → child, as node indices: one per node but the root.
    pub fn edges(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .filter_map(|(i, n)| n.parent.map(|p| (p, i)))
    }
}

/// A search's outcome: the path found, what the search did, and both trees.
#[derive(Debug, Clone)]
pub struct Search {
    /// The path from the start to the goal, before smoothing.
    pub path: ArmPath,
    /// Iterations, nodes and time.
    pub stats: PlanStats,
    /// The tree grown from the start, and the one grown from the goal.
    pub trees: [SearchTree; 2],
}

/// A piecewise-linear path in configuration space, from the start to the goal.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmPath {
    /// The configurations; consecutive ones are joined by straight interpolations.
    pub configs: Vec<ArmConfig>,
}

impl ArmPath {
    /// Its length in the planner's distance, meters.
    pub fn length(&self, space: &ArmSpace) -> f64 {
        segment_lengths(space, &self.configs).iter().sum()
    }

    /// The path from its start to the point `at` meters (the planner's distance) along it,
    /// which ends it (the whole path for `at` ≥ its length). Within a segment the point lies
    /// at the fraction of the segment's length, interpolated as [`timed`] places frames.
    pub fn cut(&self, space: &ArmSpace, at: f64) -> ArmPath {
        let lengths = segment_lengths(space, &self.configs);
        let mut configs = Vec::with_capacity(self.configs.len());
        let mut left = at.max(0.0);
        for (i, &l) in lengths.iter().enumerate() {
            configs.push(self.configs[i]);
            if left < l {
                if left > 0.0 {
                    configs.push(lerp(&self.configs[i], &self.configs[i + 1], left / l));
                }
                return ArmPath { configs };
            }
            left -= l;
        }
        self.clone()
    }

    /// True when every configuration is free and every segment is free at the space's
    /// resolution.
    pub fn is_valid(&self, space: &ArmSpace) -> bool {
        self.configs.iter().all(|q| space.free(q))
            && self
                .configs
                .windows(2)
                .all(|w| space.edge_free(&w[0], &w[1]))
    }

    /// The wrist's world positions along the path: every configuration's, and between two
    /// the interpolation's at most `step` meters apart in the planner's distance (the
    /// wrist moves on a curve between nodes, the interpolation being linear in the joints).
    pub fn wrist_curve(&self, space: &ArmSpace, step: f64) -> Vec<Point3<f64>> {
        let step = if step.is_finite() && step > 0.0 {
            step
        } else {
            space.resolution()
        };
        let mut out = Vec::new();
        for (i, q) in self.configs.iter().enumerate() {
            if i > 0 {
                let a = &self.configs[i - 1];
                let n = (space.distance(a, q) / step).ceil().min(10_000.0) as usize;
                for k in 1..n {
                    out.push(space.points(&lerp(a, q, k as f64 / n as f64)).wrist());
                }
            }
            out.push(space.points(q).wrist());
        }
        out
    }

    /// The configuration at fraction `s` ∈ \[0, 1\] of the path's length (`None` for an
    /// empty path).
    pub fn at(&self, space: &ArmSpace, s: f64) -> Option<ArmConfig> {
        if self.configs.is_empty() {
            return None;
        }
        let lengths = segment_lengths(space, &self.configs);
        Some(sample_at(&self.configs, &lengths, s))
    }
}

/// `configs` must not be empty.
fn sample_at(configs: &[ArmConfig], lengths: &[f64], s: f64) -> ArmConfig {
    let total: f64 = lengths.iter().sum();
    if configs.len() == 1 || total <= 0.0 {
        return configs[0];
    }
    let mut left = s.clamp(0.0, 1.0) * total;
    for (i, &l) in lengths.iter().enumerate() {
        if left <= l || i + 1 == lengths.len() {
            let t = if l > 0.0 { (left / l).min(1.0) } else { 1.0 };
            return lerp(&configs[i], &configs[i + 1], t);
        }
        left -= l;
    }
    *configs.last().unwrap_or(&configs[0])
}

/// The planner's distance along each segment of a piecewise-linear path.
fn segment_lengths(space: &ArmSpace, configs: &[ArmConfig]) -> Vec<f64> {
    configs
        .windows(2)
        .map(|w| space.distance(&w[0], &w[1]))
        .collect()
}

/// Plans a collision-free motion of the arm from `start` to `goal` (both must be free).
pub fn plan(
    space: &ArmSpace,
    start: &ArmConfig,
    goal: &ArmConfig,
    settings: &RrtSettings,
) -> Result<(ArmPath, PlanStats)> {
    search(space, start, goal, settings).map(|s| (s.path, s.stats))
}

/// [`plan`], returning both trees too ([`Search`]).
pub fn search(
    space: &ArmSpace,
    start: &ArmConfig,
    goal: &ArmConfig,
    settings: &RrtSettings,
) -> Result<Search> {
    settings.validate()?;
    for (what, q) in [("start", start), ("goal", goal)] {
        if !q.iter().all(|v| v.is_finite()) {
            return Err(PlanError::NonFinite(format!("the {what} configuration")));
        }
    }
    if let Some(contact) = space.contact(start) {
        return Err(PlanError::StartInCollision { contact });
    }
    if let Some(contact) = space.contact(goal) {
        return Err(PlanError::GoalInCollision { tried: 1, contact });
    }
    if !space.within_limits(goal) {
        return Err(PlanError::GoalUnreachable {
            why: "the goal configuration is outside the joint limits".into(),
        });
    }
    let clock = Instant::now();
    let sampler = Sampler::new(settings).body_line(body_of(start), body_of(goal));
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut trees = [Tree::default(), Tree::default()];
    trees[0].add(space, *start, None);
    trees[1].add(space, *goal, None);
    // `a` is the tree that grows this iteration (T1), `1 − a` the other (T2).
    let mut a = 0;
    let mut gap = space.distance(start, goal);
    let stats = |trees: &[Tree; 2], iterations| PlanStats {
        iterations,
        nodes: trees[0].nodes.len() + trees[1].nodes.len(),
        seconds: clock.elapsed().as_secs_f64(),
    };
    let found = |trees: &[Tree; 2], path, iterations| Search {
        path,
        stats: stats(trees, iterations),
        trees: [SearchTree::of(&trees[0]), SearchTree::of(&trees[1])],
    };
    // Line 5 on the roots: a free straight line needs no tree.
    if space.edge_free(start, goal) {
        let path = ArmPath {
            configs: vec![*start, *goal],
        };
        return Ok(found(&trees, path, 0));
    }
    for iteration in 0..settings.budget.iterations {
        if settings.budget.time.is_some_and(|t| clock.elapsed() > t) {
            return Err(no_path(stats(&trees, iteration), gap));
        }
        let Some(sample) = sampler.sample(space, iteration, &mut rng) else {
            a = 1 - a;
            continue;
        };
        let sp = space.points(&sample);
        let (i1, d1) = trees[a].nearest(&sp);
        let (i2, _) = trees[1 - a].nearest(&sp);
        let (q1, q2) = (trees[a].nodes[i1].q, trees[1 - a].nodes[i2].q);
        gap = gap.min(
            trees[a].nodes[i1]
                .points
                .distance(&trees[1 - a].nodes[i2].points),
        );
        if space.edge_free(&q1, &q2) {
            return Ok(found(&trees, join(&trees, a, i1, i2), iteration + 1));
        }
        let q_exp = if d1 <= settings.step {
            sample
        } else {
            lerp(&q1, &sample, settings.step / d1)
        };
        if space.free(&q_exp) && space.edge_free(&q1, &q_exp) {
            let e = trees[a].add(space, q_exp, Some(i1));
            let pe = trees[a].nodes[e].points;
            gap = gap.min(pe.distance(&trees[1 - a].nodes[i2].points));
            if space.edge_free(&q_exp, &q2) {
                return Ok(found(&trees, join(&trees, a, e, i2), iteration + 1));
            }
        }
        a = 1 - a;
    }
    Err(no_path(stats(&trees, settings.budget.iterations), gap))
}

fn no_path(s: PlanStats, gap: f64) -> PlanError {
    PlanError::NoPath {
        iterations: s.iterations,
        elapsed_ms: s.seconds * 1e3,
        nodes: s.nodes,
        gap,
    }
}

/// MAKEPATH: the branch from the root of tree `a` to node `i`, then from node `j` of the
/// other tree to its root; oriented from the start (tree 0) to the goal (tree 1).
fn join(trees: &[Tree; 2], a: usize, i: usize, j: usize) -> ArmPath {
    let mut first = trees[a].branch(i);
    let mut second = trees[1 - a].branch(j);
    second.reverse();
    first.extend(second);
    if a == 1 {
        first.reverse();
    }
    ArmPath { configs: first }
}

/// What a smoothing did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SmoothStats {
    /// Shortcuts tried.
    pub tries: usize,
    /// Shortcuts kept.
    pub kept: usize,
    /// Length before and after, meters.
    pub length_before: f64,
    /// Length after, meters.
    pub length_after: f64,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Random-shortcut smoothing (see the [module docs](self#smoothing)); `seed` drives the
/// choice of the shortcuts.
pub fn smooth(
    space: &ArmSpace,
    path: &ArmPath,
    budget: &Budget,
    seed: u64,
) -> (ArmPath, SmoothStats) {
    let clock = Instant::now();
    let mut configs = path.configs.clone();
    let mut lengths = segment_lengths(space, &configs);
    let before: f64 = lengths.iter().sum();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_5eed_5eed_5eed);
    let mut stats = SmoothStats {
        length_before: before,
        ..SmoothStats::default()
    };
    for _ in 0..budget.iterations {
        if budget.time.is_some_and(|t| clock.elapsed() > t)
            || configs.len() < 3 && lengths.iter().sum::<f64>() == 0.0
        {
            break;
        }
        let total: f64 = lengths.iter().sum();
        if total <= 0.0 {
            break;
        }
        stats.tries += 1;
        let mut u: f64 = rng.random_range(0.0..total);
        let mut v: f64 = rng.random_range(0.0..total);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        let (ia, ta) = locate(&lengths, u);
        let (ib, tb) = locate(&lengths, v);
        if ia == ib {
            continue; // within one straight segment: nothing to cut
        }
        let qa = lerp(&configs[ia], &configs[ia + 1], ta);
        let qb = lerp(&configs[ib], &configs[ib + 1], tb);
        // The stretch being replaced: qa → configs[ia+1] … configs[ib] → qb.
        let old =
            lengths[ia] * (1.0 - ta) + lengths[ia + 1..ib].iter().sum::<f64>() + lengths[ib] * tb;
        let new = space.distance(&qa, &qb);
        if new >= old - 1e-9 {
            continue;
        }
        let whole = [(configs[ia], qa), (qa, qb), (qb, configs[ib + 1])];
        // All three pieces are checked: the end pieces lie on free segments, but a discrete
        // check of a piece samples other points than the check of the whole segment did.
        // The shortcut first: it is the piece likely to collide.
        if !space.free(&qa)
            || !space.free(&qb)
            || ![1, 0, 2]
                .iter()
                .all(|&k| space.edge_free(&whole[k].0, &whole[k].1))
        {
            continue;
        }
        let mut next: Vec<ArmConfig> = configs[..=ia].to_vec();
        for q in [qa, qb] {
            if next.last() != Some(&q) {
                next.push(q);
            }
        }
        next.extend_from_slice(&configs[ib + 1..]);
        let next_lengths = segment_lengths(space, &next);
        if next_lengths.iter().sum::<f64>() >= lengths.iter().sum::<f64>() {
            continue; // the metric is not a norm of q: pieces of a segment may not add up
        }
        configs = next;
        lengths = next_lengths;
        stats.kept += 1;
    }
    stats.length_after = lengths.iter().sum();
    stats.seconds = clock.elapsed().as_secs_f64();
    (ArmPath { configs }, stats)
}

/// The segment and fraction at arc length `s`.
fn locate(lengths: &[f64], s: f64) -> (usize, f64) {
    let mut left = s;
    for (i, &l) in lengths.iter().enumerate() {
        if left <= l {
            return (i, if l > 0.0 { left / l } else { 0.0 });
        }
        left -= l;
    }
    (lengths.len() - 1, 1.0)
}

/// Kallmann's bell-shaped time warp: `t = −2h³ + 3h²` for `h` ∈ \[0, 1\] at constant
/// speed gives a path parameter whose speed is a symmetric bell, zero at both ends.
pub fn bell(h: f64) -> f64 {
    let h = h.clamp(0.0, 1.0);
    h * h * (3.0 - 2.0 * h)
}

/// How a path is played over time: the fraction of its length reached at each fraction of
/// its duration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Warp {
    /// Kallmann's cubic bell ([`bell`]): symmetric, speed peaking half-way.
    Cubic,
    /// A person's bell: speed ∝ u^(α−1) (1−u)^(β−1) over the duration's fraction u (a Beta
    /// density; α = β = 2 is the cubic). Its mode is the peak time, its standard deviation
    /// the spread ([`Warp::from_mean_and_spread`], [`Warp::peak`], [`Warp::spread`]).
    Beta {
        /// α > 1.
        alpha: f64,
        /// β > 1.
        beta: f64,
    },
}

impl Warp {
    /// The bell whose speed has this `mean` fraction of the movement and standard deviation
    /// `spread` (method of moments); `None` when no bell with zero speed at both ends has
    /// them (α, β ≤ 1).
    pub fn from_mean_and_spread(mean: f64, spread: f64) -> Option<Warp> {
        if !(mean > 0.0 && mean < 1.0 && spread > 0.0) {
            return None;
        }
        let n = mean * (1.0 - mean) / (spread * spread) - 1.0;
        let (alpha, beta) = (mean * n, (1.0 - mean) * n);
        (alpha > 1.0 && beta > 1.0).then_some(Warp::Beta { alpha, beta })
    }

    /// [`Warp::from_mean_and_spread`] from a sampled speed profile (any positive scale), over
    /// evenly spaced instants from the movement's start to its end.
    pub fn from_speeds(speeds: &[f64]) -> Option<Warp> {
        let n = speeds.len();
        if n < 3 || speeds.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return None;
        }
        let total: f64 = speeds.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let u = |k: usize| k as f64 / (n - 1) as f64;
        let mean = speeds
            .iter()
            .enumerate()
            .map(|(k, v)| u(k) * v)
            .sum::<f64>()
            / total;
        let var = speeds
            .iter()
            .enumerate()
            .map(|(k, v)| (u(k) - mean).powi(2) * v)
            .sum::<f64>()
            / total;
        Warp::from_mean_and_spread(mean, var.sqrt())
    }

    /// When the speed peaks, as a fraction of the duration.
    pub fn peak(&self) -> f64 {
        match *self {
            Warp::Cubic => 0.5,
            Warp::Beta { alpha, beta } => (alpha - 1.0) / (alpha + beta - 2.0),
        }
    }

    /// The standard deviation of the speed over the duration's fraction.
    pub fn spread(&self) -> f64 {
        let (a, b) = match *self {
            Warp::Cubic => (2.0, 2.0),
            Warp::Beta { alpha, beta } => (alpha, beta),
        };
        (a * b / ((a + b).powi(2) * (a + b + 1.0))).sqrt()
    }

    /// The fraction of the path's length reached at each of `frames` (≥ 2) evenly spaced
    /// fractions of the duration: 0 first, 1 last, never decreasing.
    pub(crate) fn fractions(&self, frames: usize) -> Vec<f64> {
        let frames = frames.max(2);
        match *self {
            Warp::Cubic => (0..frames)
                .map(|k| bell(k as f64 / (frames - 1) as f64))
                .collect(),
            Warp::Beta { alpha, beta } => {
                // The cumulative speed, integrated finely (midpoint rule) between frames.
                const PER_FRAME: usize = 16;
                let density = |u: f64| u.powf(alpha - 1.0) * (1.0 - u).powf(beta - 1.0);
                let steps = (frames - 1) * PER_FRAME;
                let du = 1.0 / steps as f64;
                let mut out = Vec::with_capacity(frames);
                let mut sum = 0.0;
                out.push(0.0);
                for i in 0..steps {
                    sum += density((i as f64 + 0.5) * du) * du;
                    if (i + 1) % PER_FRAME == 0 {
                        out.push(sum);
                    }
                }
                let total = sum.max(f64::MIN_POSITIVE);
                out.iter_mut()
                    .for_each(|v| *v = (*v / total).clamp(0.0, 1.0));
                out
            }
        }
    }
}

/// The path played over `frames` frames (≥ 2) with the bell time warp: frame `k` is the
/// configuration at fraction `bell(k / (frames − 1))` of the path's length. The first frame
/// is exactly the start and the last exactly the goal. An empty path gives no frames.
pub fn timed(space: &ArmSpace, path: &ArmPath, frames: usize) -> Vec<ArmConfig> {
    timed_with(space, path, frames, &Warp::Cubic)
}

/// [`timed`] with the time `warp` (a person's bell instead of Kallmann's cubic).
pub fn timed_with(space: &ArmSpace, path: &ArmPath, frames: usize, warp: &Warp) -> Vec<ArmConfig> {
    if path.configs.is_empty() {
        return Vec::new();
    }
    let frames = frames.max(2);
    let lengths = segment_lengths(space, &path.configs);
    let mut out: Vec<ArmConfig> = warp
        .fractions(frames)
        .into_iter()
        .map(|f| sample_at(&path.configs, &lengths, f))
        .collect();
    out[0] = path.configs[0];
    out[frames - 1] = *path.configs.last().unwrap_or(&path.configs[0]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planner in a scene without objects.
    fn empty_planner() -> crate::task::Planner {
        crate::task::Planner::new(
            crate::scene::Scene::parse(
                r#"{"format_version": 1, "objects": []}"#,
                "t.json".as_ref(),
                ".".as_ref(),
            )
            .expect("scene"),
            crate::task::TaskSettings::default(),
        )
        .expect("planner")
    }

    /// A cut path begins where the path does, keeps its waypoints up to the cut and ends at
    /// the fraction of the cut segment's length (at a waypoint, exactly the length asked
    /// for); cut beyond its end, it is the whole path.
    #[test]
    fn a_cut_path_is_the_start_of_the_path() {
        let planner = empty_planner();
        let space = planner.space().expect("space");
        let a = space.config_of(planner.start_pose());
        let mut b = a;
        b[0] += 0.6;
        let mut c = b;
        c[3] += 0.8;
        let path = ArmPath {
            configs: vec![a, b, c],
        };
        let total = path.length(&space);
        let first = space.distance(&a, &b);
        let close = |x: &ArmPath, y: &[ArmConfig]| {
            x.configs.len() == y.len()
                && x.configs
                    .iter()
                    .zip(y)
                    .all(|(p, q)| p.iter().zip(q).all(|(u, v)| (u - v).abs() < 1e-12))
        };
        assert_eq!(path.cut(&space, 0.0).configs, vec![a]);
        assert!(close(
            &path.cut(&space, 0.3 * first),
            &[a, lerp(&a, &b, 0.3)]
        ));
        let at_b = path.cut(&space, first);
        assert_eq!(at_b.configs, vec![a, b]);
        assert!((at_b.length(&space) - first).abs() < 1e-12);
        let second = total - first;
        assert!(close(
            &path.cut(&space, first + 0.5 * second),
            &[a, b, lerp(&b, &c, 0.5)]
        ));
        assert_eq!(path.cut(&space, 2.0 * total), path);
    }

    /// Where the body moves, its DoFs are drawn along the line from the start's to the goal's,
    /// at most the variation off it; where it does not, they stay zero.
    #[test]
    fn the_body_is_sampled_in_a_small_band_about_its_line() {
        use crate::posture::{BodyMotion, body_dof};
        use kinergy_reach::controller::{ReachSettings, Stance};
        let planner = empty_planner();
        let settings = RrtSettings::default();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let arm_only = planner.space().expect("space");
        for i in 0..200 {
            let q = Sampler::new(&settings).draw(&arm_only, i, &mut rng);
            assert_eq!(body_of(&q), [0.0; BODY_DOFS]);
        }
        let goal = Stance {
            swing: -0.6,
            twist: 0.2,
            squat: 0.2,
            ..Stance::upright()
        };
        let motion = BodyMotion::new(
            planner.character(),
            planner.start_pose(),
            &goal,
            &ReachSettings::default(),
        )
        .expect("motion");
        let space = planner
            .space()
            .expect("space")
            .with_body(motion)
            .expect("body");
        let sampler = Sampler::new(&settings);
        let v = settings.body_variation.as_array();
        for i in 0..500 {
            let q = sampler.draw(&space, i, &mut rng);
            let b = body_of(&q);
            // One fraction u along the line explains all three within the variation.
            let u = ((b[2] - 0.0) / 0.2).clamp(0.0, 1.0);
            let line = [-0.6 * u, 0.2 * u, 0.2 * u];
            let slack = v.map(|x| x * (1.0 + 1e-9));
            assert!(
                (b[0] - line[0]).abs() <= slack[0] + 0.6 * v[2] / 0.2,
                "{b:?}"
            );
            assert!(
                (b[1] - line[1]).abs() <= slack[1] + 0.2 * v[2] / 0.2,
                "{b:?}"
            );
            assert!(space.body_motion().unwrap().within_limits(&b), "{b:?}");
            assert!(q[body_dof::SQUAT] >= 0.0);
        }
    }

    #[test]
    fn the_beta_two_two_warp_is_kallmanns_cubic() {
        let beta = Warp::Beta {
            alpha: 2.0,
            beta: 2.0,
        };
        let (a, b) = (beta.fractions(31), Warp::Cubic.fractions(31));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-4, "{x} vs {y}");
        }
        assert!((beta.peak() - 0.5).abs() < 1e-12);
        assert!((beta.spread() - Warp::Cubic.spread()).abs() < 1e-12);
    }

    #[test]
    fn a_warp_from_a_sampled_bell_recovers_its_peak_and_spread() {
        // Speeds of Beta(3, 5): peak at 2/6; the moments of the speed taken as a density.
        let (alpha, beta) = (3.0, 5.0);
        let speeds: Vec<f64> = (0..=400)
            .map(|k| {
                let u = k as f64 / 400.0;
                u.powf(alpha - 1.0) * (1.0 - u).powf(beta - 1.0)
            })
            .collect();
        let warp = Warp::from_speeds(&speeds).expect("a bell");
        let truth = Warp::Beta { alpha, beta };
        assert!((warp.peak() - truth.peak()).abs() < 1e-3, "{warp:?}");
        assert!((warp.spread() - truth.spread()).abs() < 1e-4, "{warp:?}");
        // Fractions start at 0, end at 1 and never decrease.
        let f = warp.fractions(50);
        assert_eq!((f[0], f[49]), (0.0, 1.0));
        assert!(f.windows(2).all(|w| w[1] >= w[0]));
        // A flat profile has no bell with zero speed at both ends.
        assert!(Warp::from_speeds(&[1.0; 20]).is_none());
    }
}
