//! Benchmarks of the planner on the bookshelf example (`examples/bookshelf/scene.json`):
//! relocating the blue book to the upper shelf, as `Planner::transfer_problem` poses it.
//!
//! - `ik_collision`: IK with collision avoidance for the pre-grasp and the placing targets,
//!   one collision test of a configuration, one edge test of a free ~0.15 m edge;
//! - `rrt_relocation`: RRT-Connect on the transfer, seeds 0..100 in turn;
//! - `smoothing`: shortcut smoothing of those seeds' raw paths;
//! - `rrt_crate`: openrr's `rrt` crate (dual RRT-Connect) on the same problem with the same
//!   collision test and sampler, at two extend lengths.
//!
//! Before criterion measures a group, it prints a summary over the 100 seeds (success,
//! median / p90 / max time, …) to stderr. Summaries run only when benchmarking
//! (`cargo bench`), and when a filter is given, only for the groups whose name contains it
//! (or that it starts with).

use std::cell::{Cell, RefCell};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, SamplingMode};
use kinergy_plan::PlanError;
use kinergy_plan::rrt::{ArmPath, RrtSettings, Sampler, plan, smooth};
use kinergy_plan::scene::{Grasp, Scene};
use kinergy_plan::space::{ArmConfig, ArmSpace, HandTarget, lerp};
use kinergy_plan::task::{Planner, Problem, TaskSettings};
use nalgebra::{Isometry3, Point3, Translation3};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;

/// Seeds every seeded benchmark goes through.
const SEEDS: u64 = 100;

/// The object relocated and where its origin goes.
const OBJECT: &str = "blue_book";

/// A summary of the `rrt` crate stops at the first seed taking longer than this.
const CRATE_CAP: Duration = Duration::from_secs(2);

/// The iteration budget of both planners (ours: `RrtSettings::default()`).
const TRIES: usize = 5000;

fn destination() -> Point3<f64> {
    Point3::new(-0.22, 1.49, 0.50)
}

/// The hand target of a grasp on an object at `pose`, pulled back along the approach by
/// `back` meters (as the task planner computes it).
fn grasp_target(pose: &Isometry3<f64>, grasp: &Grasp, back: f64) -> HandTarget {
    HandTarget {
        position: pose * (grasp.position - grasp.approach * back),
        orientation: Some(pose.rotation * grasp.rotation),
    }
}

fn to_array(q: &[f64]) -> ArmConfig {
    std::array::from_fn(|i| q[i])
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The median of `v` (sorted in place); NaN when empty.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The nearest-rank `p`-quantile of `v` (sorted in place); NaN when empty.
fn quantile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let rank = (p * v.len() as f64).ceil() as usize;
    v[rank.clamp(1, v.len()) - 1]
}

/// "median … ms, p90 … ms, max … ms" of times in milliseconds.
fn times(t: &[f64]) -> String {
    let mut t = t.to_vec();
    format!(
        "median {:.2} ms, p90 {:.2} ms, max {:.2} ms",
        median(&mut t),
        quantile(&mut t, 0.9),
        quantile(&mut t, 1.0)
    )
}

/// Which summaries to print: only when benchmarking, and only for the groups a filter
/// (a positional argument) names.
struct Summaries {
    on: bool,
    filters: Vec<String>,
}

impl Summaries {
    fn from_args() -> Summaries {
        // Criterion's options that take a value (the value is not a filter).
        const VALUED: &[&str] = &[
            "-c",
            "--color",
            "-s",
            "--save-baseline",
            "-b",
            "--baseline",
            "--baseline-lenient",
            "--load-baseline",
            "--sample-size",
            "--warm-up-time",
            "--measurement-time",
            "--nresamples",
            "--noise-threshold",
            "--confidence-level",
            "--significance-level",
            "--profile-time",
            "--plotting-backend",
            "--output-format",
            "--format",
        ];
        let args: Vec<String> = std::env::args().skip(1).collect();
        let flag = |f: &str| args.iter().any(|a| a == f);
        let on = flag("--bench") && !flag("--test") && !flag("--list") && !flag("--ignored");
        let mut filters = Vec::new();
        let mut skip = false;
        for a in &args {
            if skip {
                skip = false;
            } else if a.starts_with('-') {
                skip = VALUED.contains(&a.as_str());
            } else {
                filters.push(a.clone());
            }
        }
        Summaries { on, filters }
    }

    fn wanted(&self, group: &str) -> bool {
        self.on
            && (self.filters.is_empty()
                || self
                    .filters
                    .iter()
                    .any(|f| group.contains(f.as_str()) || f.starts_with(group)))
    }
}

/// What every benchmark uses.
struct Fixture {
    planner: Planner,
    problem: Problem,
}

impl Fixture {
    fn new() -> Fixture {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/bookshelf/scene.json");
        let scene = Scene::read(&path).expect("the bookshelf scene");
        let planner = Planner::new(scene, TaskSettings::default()).expect("a planner");
        let problem = planner
            .transfer_problem(OBJECT, &destination())
            .expect("the transfer problem");
        Fixture { planner, problem }
    }
}

/// One of our searches: the path (on success), iterations and nodes.
struct Search {
    path: Option<ArmPath>,
    iterations: usize,
    nodes: usize,
}

fn our_search(problem: &Problem, seed: u64) -> Search {
    let settings = RrtSettings {
        seed,
        ..RrtSettings::default()
    };
    match plan(&problem.space, &problem.start, &problem.goal, &settings) {
        Ok((path, stats)) => Search {
            path: Some(path),
            iterations: stats.iterations,
            nodes: stats.nodes,
        },
        Err(PlanError::NoPath {
            iterations, nodes, ..
        }) => Search {
            path: None,
            iterations,
            nodes,
        },
        Err(e) => panic!("seed {seed}: {e}"),
    }
}

/// One run of the `rrt` crate: its path, or `None` when it failed or was stopped at
/// `deadline` (then `stopped` is true).
struct CrateRun {
    path: Option<Vec<Vec<f64>>>,
    stopped: bool,
}

/// `rrt::dual_rrt_connect` on the problem with our collision test and our sampler (seeded
/// by `seed`), stopped after `cap` when given.
fn crate_search(problem: &Problem, extend: f64, seed: u64, cap: Option<Duration>) -> CrateRun {
    let space = &problem.space;
    let sampler = Sampler::new(&RrtSettings::default());
    let rng = RefCell::new(ChaCha8Rng::seed_from_u64(seed));
    let iteration = Cell::new(0);
    let clock = Instant::now();
    let stopped = Cell::new(false);
    let over = || {
        if !stopped.get() && cap.is_some_and(|c| clock.elapsed() > c) {
            stopped.set(true);
        }
        stopped.get()
    };
    let is_free = |q: &[f64]| !over() && space.free(&to_array(q));
    // Once stopped, every sample is the start: the remaining tries end at once.
    let random_sample = || {
        if over() {
            return problem.start.to_vec();
        }
        let i = iteration.get();
        iteration.set(i + 1);
        let mut rng = rng.borrow_mut();
        sampler
            .sample(space, i, &mut rng)
            .unwrap_or_else(|| sampler.draw(space, i, &mut rng))
            .to_vec()
    };
    let result = rrt::dual_rrt_connect(
        &problem.start,
        &problem.goal,
        is_free,
        random_sample,
        extend,
        TRIES,
    );
    let stopped = stopped.get();
    CrateRun {
        path: result.ok().filter(|_| !stopped),
        stopped,
    }
}

fn ik_collision(c: &mut Criterion, f: &Fixture, summaries: &Summaries) {
    let scene = f.planner.scene();
    let object = scene.object(OBJECT).expect("the blue book");
    let grasp = object.grasp.clone().expect("the blue book's grasp");
    let start_space = f.planner.space().expect("the start space");
    let pre_grasp = grasp_target(&object.pose, &grasp, grasp.distance);
    let dest = Isometry3::from_parts(
        Translation3::from(destination().coords),
        object.pose.rotation,
    );
    let place = grasp_target(&dest, &grasp, 0.0);
    let space = &f.problem.space;
    start_space
        .solve(&pre_grasp)
        .expect("the pre-grasp posture");
    space.solve(&place).expect("the placing posture");
    let (a, b) = free_edge(space, &f.problem.start, 0.15);
    if summaries.wanted("ik_collision") {
        eprintln!(
            "ik_collision: edge_free edge {:.3} m from the grasp posture ({} configurations tested at {} m)",
            space.distance(&a, &b),
            (space.distance(&a, &b) / space.resolution()).ceil() as usize - 1,
            space.resolution()
        );
    }

    let mut g = c.benchmark_group("ik_collision");
    g.sample_size(50).measurement_time(Duration::from_secs(3));
    g.bench_function("pre_grasp", |bench| {
        bench.iter(|| start_space.solve(black_box(&pre_grasp)))
    });
    g.bench_function("place_held", |bench| {
        bench.iter(|| space.solve(black_box(&place)))
    });
    g.bench_function("contact", |bench| {
        bench.iter(|| space.contact(black_box(&f.problem.start)))
    });
    g.bench_function("edge_free_15cm", |bench| {
        bench.iter(|| space.edge_free(black_box(&a), black_box(&b)))
    });
    g.finish();
}

/// A free edge from `from` of about `length` meters (the planner's distance), toward
/// seeded samples: the first whose end and interpolation are free.
fn free_edge(space: &ArmSpace, from: &ArmConfig, length: f64) -> (ArmConfig, ArmConfig) {
    let sampler = Sampler::new(&RrtSettings::default());
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..10_000 {
        let q = sampler.draw(space, 10_000, &mut rng);
        if space.distance(from, &q) < length {
            continue;
        }
        // Bisection on the fraction toward `q` for a distance of `length`.
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..40 {
            let t = 0.5 * (lo + hi);
            if space.distance(from, &lerp(from, &q, t)) < length {
                lo = t;
            } else {
                hi = t;
            }
        }
        let b = lerp(from, &q, hi);
        if space.free(&b) && space.edge_free(from, &b) {
            return (*from, b);
        }
    }
    panic!("no free edge of {length} m found");
}

/// Criterion's mean over seeds 0..100 taken in turn: `run(seed)` is timed per call.
fn cycle_seeds(bench: &mut criterion::Bencher<'_>, seeds: &[u64], mut run: impl FnMut(u64)) {
    let mut next = 0;
    bench.iter_custom(|iters| {
        let mut total = Duration::ZERO;
        for _ in 0..iters {
            let seed = seeds[next % seeds.len()];
            next += 1;
            let clock = Instant::now();
            run(seed);
            total += clock.elapsed();
        }
        total
    });
}

fn rrt_relocation(c: &mut Criterion, f: &Fixture, summaries: &Summaries) -> Vec<(u64, ArmPath)> {
    let mut raw = Vec::new();
    if summaries.wanted("rrt_relocation") || summaries.wanted("smoothing") {
        let mut t = Vec::new();
        let mut iterations = Vec::new();
        let mut nodes = Vec::new();
        for seed in 0..SEEDS {
            let clock = Instant::now();
            let s = our_search(&f.problem, seed);
            t.push(ms(clock.elapsed()));
            iterations.push(s.iterations as f64);
            nodes.push(s.nodes as f64);
            raw.extend(s.path.map(|p| (seed, p)));
        }
        if summaries.wanted("rrt_relocation") {
            eprintln!(
                "rrt_relocation summary: {}/{SEEDS} succeeded; {}; median {} iterations, {} nodes",
                raw.len(),
                times(&t),
                median(&mut iterations),
                median(&mut nodes)
            );
        }
    }

    let seeds: Vec<u64> = (0..SEEDS).collect();
    let mut g = c.benchmark_group("rrt_relocation");
    g.sample_size(20)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10));
    g.bench_function("plan_seeds_0_100", |bench| {
        cycle_seeds(bench, &seeds, |seed| {
            black_box(our_search(&f.problem, seed));
        })
    });
    g.finish();
    raw
}

fn smoothing(c: &mut Criterion, f: &Fixture, summaries: &Summaries, raw: Vec<(u64, ArmPath)>) {
    let space = &f.problem.space;
    let budget = TaskSettings::default().smoothing;
    // Raw paths of seeds 0..100 (those that succeeded), with their seeds.
    let raw: Vec<(u64, ArmPath)> = if raw.is_empty() {
        (0..SEEDS)
            .filter_map(|seed| our_search(&f.problem, seed).path.map(|p| (seed, p)))
            .collect()
    } else {
        raw
    };
    if summaries.wanted("smoothing") {
        let mut t = Vec::new();
        let mut before = Vec::new();
        let mut after = Vec::new();
        for (seed, path) in &raw {
            let clock = Instant::now();
            let (_, stats) = smooth(space, path, &budget, *seed);
            t.push(ms(clock.elapsed()));
            before.push(stats.length_before);
            after.push(stats.length_after);
        }
        eprintln!(
            "smoothing summary: {} raw paths; {}; median length {:.3} m before, {:.3} m after",
            raw.len(),
            times(&t),
            median(&mut before),
            median(&mut after)
        );
    }

    let mut g = c.benchmark_group("smoothing");
    g.sample_size(20)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(5));
    let index: Vec<u64> = (0..raw.len() as u64).collect();
    g.bench_function("shortcuts_100", |bench| {
        cycle_seeds(bench, &index, |i| {
            let (seed, path) = &raw[i as usize];
            black_box(smooth(space, path, &budget, *seed));
        })
    });
    g.finish();
}

fn rrt_crate(c: &mut Criterion, f: &Fixture, summaries: &Summaries) {
    let variants = [
        ("extend_0.014_equal_density", 0.014),
        ("extend_0.1_sparse", 0.1),
    ];
    // The seeds each criterion benchmark goes through: those its summary completed.
    let mut seeds: Vec<Vec<u64>> = vec![(0..SEEDS).collect(); variants.len()];
    if summaries.wanted("rrt_crate") {
        for (v, (name, extend)) in variants.iter().enumerate() {
            let mut t = Vec::new();
            let mut succeeded = 0;
            let mut valid = 0;
            let mut waypoints = Vec::new();
            let mut stopped = None;
            for seed in 0..SEEDS {
                let clock = Instant::now();
                let run = crate_search(&f.problem, *extend, seed, Some(CRATE_CAP));
                let elapsed = clock.elapsed();
                if run.stopped {
                    stopped = Some((seed, elapsed));
                    break;
                }
                t.push(ms(elapsed));
                if let Some(path) = run.path {
                    succeeded += 1;
                    waypoints.push(path.len() as f64);
                    let path = ArmPath {
                        configs: path.iter().map(|q| to_array(q)).collect(),
                    };
                    valid += usize::from(path.is_valid(&f.problem.space));
                }
            }
            let done = t.len();
            let head = match stopped {
                None => format!("{succeeded}/{SEEDS} succeeded"),
                Some((seed, elapsed)) => format!(
                    "STOPPED at seed {seed} (> {:.0} s, stopped after {:.0} ms): \
                     {succeeded}/{done} of seeds 0..{seed} succeeded",
                    CRATE_CAP.as_secs_f64(),
                    ms(elapsed)
                ),
            };
            let paths = if waypoints.is_empty() {
                "no path found".to_string()
            } else {
                format!(
                    "median {} waypoints; {valid}/{succeeded} paths valid under our 1 cm edge check",
                    median(&mut waypoints)
                )
            };
            eprintln!(
                "rrt_crate {name} summary: {head} (budget {TRIES} tries); {}; {paths}",
                times(&t)
            );
            if stopped.is_some() {
                seeds[v].truncate(done);
            }
        }
    }

    let mut g = c.benchmark_group("rrt_crate");
    g.sample_size(20)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10));
    for ((name, extend), seeds) in variants.iter().zip(&seeds) {
        if seeds.is_empty() {
            eprintln!("rrt_crate/{name}: no seed completed within the cap, not measured");
            continue;
        }
        g.bench_function(*name, |bench| {
            cycle_seeds(bench, seeds, |seed| {
                black_box(crate_search(&f.problem, *extend, seed, None));
            })
        });
    }
    g.finish();
}

/// A grasp of the book (plan to the pre-grasp, approach, close) as Kallmann plays it and with
/// the reach finished by a person's synergy (`tests/data/params/synthetic-p01-r09-sc.json`):
/// what the synergy's runs from the points along the path and their per-frame collision
/// checks cost.
fn persons_grasp(c: &mut Criterion, summaries: &Summaries) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/bookshelf/scene.json");
    let scene = Scene::read(&path).expect("the bookshelf scene");
    let params = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/params/synthetic-p01-r09-sc.json");
    let file = kinergy_solver::ParamsFile::read(&params).expect("params");
    let plain = Planner::new(scene.clone(), TaskSettings::default()).expect("a planner");
    let drive = kinergy_reach::controller::ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy: file
            .synergy_for(&kinergy_reach::controller::arm_dof_names(plain.character()))
            .expect("the arm's DoFs"),
        tempo: None,
        controller: None,
    };
    let person = Planner::new(
        scene,
        TaskSettings {
            arm: drive,
            ..TaskSettings::default()
        },
    )
    .expect("a planner");
    if summaries.wanted("person") {
        for (name, planner) in [("planned", &plain), ("synergy", &person)] {
            let m = planner.grasp(OBJECT).expect("grasp");
            let reach = &m.phases[0];
            eprintln!(
                "person/{name}: {} frames, the reach {} frames, {:?}",
                m.poses.len(),
                reach.frames.len(),
                reach
                    .synergy
                    .as_ref()
                    .map(|a| (a.from_m, a.rejected.len(), a.frames))
            );
        }
    }
    let mut g = c.benchmark_group("person");
    g.sample_size(10);
    g.bench_function("grasp_planned", |bench| {
        bench.iter(|| plain.grasp(black_box(OBJECT)).expect("grasp"))
    });
    g.bench_function("grasp_synergy", |bench| {
        bench.iter(|| person.grasp(black_box(OBJECT)).expect("grasp"))
    });
    g.finish();
}

fn main() {
    let summaries = Summaries::from_args();
    let fixture = Fixture::new();
    let mut c = Criterion::default().configure_from_args();
    ik_collision(&mut c, &fixture, &summaries);
    let raw = rrt_relocation(&mut c, &fixture, &summaries);
    smoothing(&mut c, &fixture, &summaries, raw);
    rrt_crate(&mut c, &fixture, &summaries);
    persons_grasp(&mut c, &summaries);
    c.final_summary();
}
