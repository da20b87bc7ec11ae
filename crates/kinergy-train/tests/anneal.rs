//! Simulated annealing on closed-form costs: known minima found, bounds never left, the same
//! result on any thread count, resume bit for bit, greedy never worse, Metropolis uphill.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kinergy_train::CostFunction;
use kinergy_train::anneal::{
    AnnealSettings, AnnealState, Annealer, Control, CsvLog, Observer, Progress, Status,
};

/// A shifted, scaled quadratic bowl within a box, counting its calls and checking bounds.
struct Bowl {
    center: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    calls: AtomicUsize,
    outside: AtomicUsize,
}

impl Bowl {
    fn new(center: Vec<f64>, lower: f64, upper: f64) -> Bowl {
        let n = center.len();
        Bowl {
            center,
            lower: vec![lower; n],
            upper: vec![upper; n],
            calls: AtomicUsize::new(0),
            outside: AtomicUsize::new(0),
        }
    }
}

impl CostFunction for Bowl {
    fn dimension(&self) -> usize {
        self.center.len()
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (self.lower.clone(), self.upper.clone())
    }
    fn cost(&self, x: &[f64]) -> f64 {
        self.calls.fetch_add(1, Ordering::SeqCst);
        if x.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .any(|(v, (l, u))| v < l || v > u)
        {
            self.outside.fetch_add(1, Ordering::SeqCst);
        }
        x.iter()
            .zip(&self.center)
            .enumerate()
            .map(|(i, (a, b))| (1.0 + i as f64) * (a - b).powi(2))
            .sum::<f64>()
            + 0.5
    }
}

/// Rastrigin-like: many local minima around a global one at 0.3 in every coordinate.
struct Bumpy;

impl CostFunction for Bumpy {
    fn dimension(&self) -> usize {
        3
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![-5.0; 3], vec![5.0; 3])
    }
    fn cost(&self, x: &[f64]) -> f64 {
        x.iter()
            .map(|v| {
                let d = v - 0.3;
                d * d + 1.0 - (2.0 * std::f64::consts::PI * d).cos()
            })
            .sum()
    }
}

fn settings(seed: u64) -> AnnealSettings {
    AnnealSettings {
        seed,
        max_evaluations: 8000,
        ..AnnealSettings::default()
    }
}

#[test]
fn finds_a_known_minimum_and_never_leaves_the_bounds() {
    let bowl = Bowl::new(vec![1.2, -3.0, 0.4, 2.5, -0.7], -5.0, 5.0);
    let annealer = Annealer::new(settings(1)).expect("annealer");
    let state = annealer.minimize(&bowl, &[0.0; 5]).expect("run");
    let error: f64 = state
        .best_x
        .iter()
        .zip(&bowl.center)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "bowl: {:?} after {} evaluations, best cost {} (minimum 0.5), max coordinate error {error}",
        state.status, state.evaluations, state.best_cost
    );
    assert!(error < 0.05, "max coordinate error {error}");
    assert!(state.best_cost - 0.5 < 1e-3);
    assert_eq!(bowl.outside.load(Ordering::SeqCst), 0, "left the bounds");
    assert_eq!(bowl.calls.load(Ordering::SeqCst), state.evaluations);
    assert!(state.evaluations <= 8000);
}

#[test]
fn a_minimum_outside_the_bounds_ends_on_the_boundary() {
    // The bowl's center is at 7 in the first coordinate, the box ends at 5.
    let bowl = Bowl::new(vec![7.0, 1.0], -5.0, 5.0);
    let state = Annealer::new(settings(2))
        .expect("annealer")
        .minimize(&bowl, &[0.0, 0.0])
        .expect("run");
    assert!(
        state.best_x[0] <= 5.0 && state.best_x[0] > 4.95,
        "{:?}",
        state.best_x
    );
    assert!((state.best_x[1] - 1.0).abs() < 0.05, "{:?}", state.best_x);
    assert_eq!(bowl.outside.load(Ordering::SeqCst), 0);
}

#[test]
fn annealing_escapes_local_minima_that_trap_greedy_more_often() {
    // From a start in a far local minimum, count how often each finds the global basin
    // (|x − 0.3| < 0.5 in every coordinate) over 20 seeds.
    let start = [-3.7, 4.3, -2.7];
    let found = |temperature: f64| {
        (0..20)
            .filter(|&seed| {
                let s = AnnealSettings {
                    temperature,
                    initial_step: 0.02,
                    population: 4,
                    ..settings(seed)
                };
                let state = Annealer::new(s)
                    .expect("annealer")
                    .minimize(&Bumpy, &start)
                    .expect("run");
                state.best_x.iter().all(|v| (v - 0.3).abs() < 0.5)
            })
            .count()
    };
    let (greedy, annealed) = (found(0.0), found(0.5));
    eprintln!("global basin found: greedy {greedy}/20, annealed {annealed}/20");
    assert!(annealed > greedy, "greedy {greedy}, annealed {annealed}");
}

/// Records each member's cost after every iteration, through the public state.
#[test]
fn greedy_members_never_get_worse_and_metropolis_goes_uphill() {
    let bowl = Bowl::new(vec![0.5; 4], -5.0, 5.0);
    for (temperature, uphill_expected) in [(0.0, false), (2.0, true)] {
        let annealer = Annealer::new(AnnealSettings {
            temperature,
            cooling: 1.0,
            ..settings(5)
        })
        .expect("annealer");
        let mut state = annealer.init(&bowl, &[3.0; 4], "bowl").expect("init");
        let mut uphill = 0;
        for _ in 0..200 {
            let before: Vec<f64> = state.members.iter().map(|m| m.cost).collect();
            annealer.iterate(&bowl, &mut state);
            for (b, m) in before.iter().zip(&state.members) {
                if m.cost > *b {
                    uphill += 1;
                }
            }
        }
        assert_eq!(
            uphill > 0,
            uphill_expected,
            "T = {temperature}: {uphill} uphill moves"
        );
        assert!(
            state.best_cost
                <= state
                    .members
                    .iter()
                    .map(|m| m.cost)
                    .fold(f64::MAX, f64::min)
        );
    }
}

#[test]
fn the_same_seed_gives_the_same_run_on_any_thread_count() {
    let run = |threads: usize, seed: u64| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let bowl = Bowl::new(vec![1.0, -2.0, 0.5], -5.0, 5.0);
            Annealer::new(AnnealSettings {
                max_evaluations: 2000,
                ..settings(seed)
            })
            .expect("annealer")
            .minimize(&bowl, &[0.0; 3])
            .expect("run")
        })
    };
    let one = run(1, 9);
    for threads in [2, 3, 8] {
        let other = run(threads, 9);
        assert_eq!(one, other, "{threads} threads differ from 1");
        // Bit for bit, not just within tolerance.
        assert_eq!(one.best_cost.to_bits(), other.best_cost.to_bits());
    }
    assert_ne!(one, run(1, 10), "another seed should give another run");
}

/// Sets the interrupt flag once the run reaches `at` iterations.
struct InterruptAt<'a> {
    at: usize,
    flag: &'a AtomicBool,
    checkpoints: Vec<usize>,
}

impl Observer for InterruptAt<'_> {
    fn on_iteration(&mut self, p: &Progress) {
        if p.iteration == self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
    fn on_checkpoint(&mut self, _: &std::path::Path, iteration: usize) {
        self.checkpoints.push(iteration);
    }
}

#[test]
fn a_resumed_run_ends_bit_for_bit_where_an_uninterrupted_one_does() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bowl = Bowl::new(vec![1.5, -0.5, 2.0, 0.1], -5.0, 5.0);
    let s = AnnealSettings {
        max_evaluations: 1600,
        stable_window: 1000, // run to the budget
        ..settings(17)
    };
    let annealer = Annealer::new(s).expect("annealer");
    let start = [0.0; 4];
    let whole = annealer.minimize(&bowl, &start).expect("run");
    assert_eq!(whole.status, Status::BudgetSpent);

    let path = dir.path().join("run.ckpt.json");
    let flag = AtomicBool::new(false);
    let mut observer = InterruptAt {
        at: 37,
        flag: &flag,
        checkpoints: Vec::new(),
    };
    let control = Control {
        checkpoint: Some(&path),
        checkpoint_every: 10,
        interrupt: Some(&flag),
    };
    let first = annealer
        .run(
            &bowl,
            annealer.init(&bowl, &start, "bowl").expect("init"),
            &mut observer,
            &control,
        )
        .expect("run");
    assert_eq!(first.status, Status::Interrupted);
    assert_eq!(first.iteration, 37);
    assert_eq!(observer.checkpoints, [10, 20, 30, 37]);

    let loaded = AnnealState::load(&path).expect("load");
    assert_eq!(loaded, first, "the checkpoint does not round-trip exactly");
    annealer
        .check_resume(&bowl, &loaded, "bowl", &path)
        .expect("same problem");
    assert!(
        annealer
            .check_resume(&bowl, &loaded, "other", &path)
            .is_err()
    );
    let resumed = annealer
        .run(&bowl, loaded, &mut (), &Control::default())
        .expect("resume");
    let mut whole_tagged = whole.clone();
    whole_tagged.tag = "bowl".into();
    assert_eq!(resumed, whole_tagged);
    assert_eq!(resumed.best_cost.to_bits(), whole.best_cost.to_bits());
}

#[test]
fn the_csv_log_has_a_row_per_iteration_and_appends_on_resume() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("log.csv");
    let bowl = Bowl::new(vec![1.0, 1.0], -5.0, 5.0);
    let annealer = Annealer::new(AnnealSettings {
        max_evaluations: 400,
        stable_window: 1000,
        ..settings(3)
    })
    .expect("annealer");
    let mut log = CsvLog::create(&path, false).expect("log");
    let state = annealer
        .run(
            &bowl,
            annealer.init(&bowl, &[0.0, 0.0], "").expect("init"),
            &mut log,
            &Control::default(),
        )
        .expect("run");
    log.finish().expect("flush");
    let text = std::fs::read_to_string(&path).expect("read");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "iteration,evaluations,temperature,best_cost,mean_cost,acceptance"
    );
    assert_eq!(lines.len() - 1, state.iteration);
    // The best cost in the log never increases.
    let best: Vec<f64> = lines[1..]
        .iter()
        .map(|l| {
            l.split(',')
                .nth(3)
                .expect("column")
                .parse()
                .expect("number")
        })
        .collect();
    assert!(best.windows(2).all(|w| w[1] <= w[0]));
    let mut again = CsvLog::create(&path, true).expect("append");
    again.on_iteration(&Progress {
        iteration: 99,
        evaluations: 0,
        max_evaluations: 0,
        temperature: 0.0,
        best_cost: 0.0,
        mean_cost: 0.0,
        acceptance: 0.0,
    });
    again.finish().expect("flush");
    let text = std::fs::read_to_string(&path).expect("read");
    assert_eq!(
        text.lines().count(),
        lines.len() + 1,
        "appended without a new header"
    );
}

#[test]
fn bad_settings_and_starts_name_the_field() {
    let bowl = Bowl::new(vec![0.0; 2], -1.0, 1.0);
    for (s, field) in [
        (
            AnnealSettings {
                population: 0,
                ..AnnealSettings::default()
            },
            "population",
        ),
        (
            AnnealSettings {
                cooling: 1.5,
                ..AnnealSettings::default()
            },
            "cooling",
        ),
        (
            AnnealSettings {
                temperature: f64::NAN,
                ..AnnealSettings::default()
            },
            "temperature",
        ),
    ] {
        let e = Annealer::new(s).expect_err("invalid").to_string();
        assert!(e.contains(field), "{e}");
    }
    let annealer = Annealer::new(AnnealSettings::default()).expect("annealer");
    let e = annealer
        .init(&bowl, &[2.0, 0.0], "")
        .expect_err("outside")
        .to_string();
    assert!(e.contains("start"), "{e}");
    let e = annealer
        .init(&bowl, &[0.0], "")
        .expect_err("short")
        .to_string();
    assert!(e.contains("start"), "{e}");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("broken.json");
    std::fs::write(&path, "{ \"format_version\": 1, ").expect("write");
    let e = AnnealState::load(&path).expect_err("broken").to_string();
    assert!(e.contains("broken.json") && e.contains("line"), "{e}");
}
