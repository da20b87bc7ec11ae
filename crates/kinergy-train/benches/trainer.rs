//! The trainer's speed: synthesized frames per second per core inside the objective, and the
//! paper's experiments on 14 reaches made by the controller itself (known S_C parameters,
//! the fixture's person): Fig. 3 (4 models, per-clip nested fits) and Fig. 4 (JT, NJT, SVD ×
//! S_A, S_C) wall time at the default budget, and the score against the budget.
//!
//! `cargo bench -p kinergy-train --bench trainer`
//!
//! The experiment timings and the budget curve are printed to stderr before criterion's
//! groups run.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinergy_motion::{ArmJoints, Clip, ImportOptions, Side, read_clip};
use kinergy_solver::{Model, OptimizerKind, ParamSpace};
use kinergy_train::anneal::AnnealSettings;
use kinergy_train::fit::{FitSettings, fit_nested};
use kinergy_train::synthetic::{MadeReach, made_set};
use kinergy_train::{CapturedReach, CostFunction, Objective};
use rayon::prelude::*;

const CLIPS: usize = 14;
const FRAMES: usize = 120;

fn fixture() -> (Clip, ArmJoints) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/006_14.bvh");
    let (clip, _) = read_clip(&path, &ImportOptions::default()).expect("fixture");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    (clip, arm)
}

fn made() -> Vec<MadeReach> {
    let (clip, arm) = fixture();
    made_set(
        &clip,
        &arm,
        CLIPS,
        FRAMES,
        OptimizerKind::Svd.default_optimizer(),
        2026,
    )
    .expect("made set")
}

/// A pool of one thread: a core's throughput.
fn one_core() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
}

/// Frames synthesized per second on one core, through the objective the trainer calls.
fn frames_per_second(c: &mut Criterion) {
    let set = made();
    let reach = set[0].reach.clone();
    let pool = one_core();
    let mut group = c.benchmark_group("objective_one_core");
    group.throughput(Throughput::Elements(reach.frame_count() as u64));
    for kind in OptimizerKind::ALL {
        let space =
            ParamSpace::new(Model::Sc, &reach.dof_names(), Default::default()).expect("space");
        let objective = Objective::new(vec![reach.clone()], space, kind.default_optimizer())
            .expect("objective");
        let x = set[0].truth.clone();
        group.bench_function(kind.name(), |b| {
            pool.install(|| b.iter(|| black_box(objective.cost(black_box(&x)))))
        });
    }
    // S_E's frame: the same truth carried into S_E with growth and tempo factors that are
    // not neutral (every DoF's gain growth e^{k(1 − e^{−t})} computed each frame).
    let names = reach.dof_names();
    let sc = ParamSpace::new(Model::Sc, &names, Default::default()).expect("space");
    let se = ParamSpace::new(Model::Se, &names, Default::default()).expect("space");
    let mut x = sc.extend_to(&set[0].truth, &se).expect("extend");
    let n = names.len();
    for (i, k) in x[3 * n..4 * n].iter_mut().enumerate() {
        *k = if i % 2 == 0 { 0.5 } else { -0.5 };
    }
    x[4 * n] = 1.2;
    x[4 * n + 1] = 0.8;
    let objective = Objective::new(
        vec![reach.clone()],
        se,
        OptimizerKind::Svd.default_optimizer(),
    )
    .expect("objective");
    group.bench_function("svd_se", |b| {
        pool.install(|| b.iter(|| black_box(objective.cost(black_box(&x)))))
    });
    group.finish();
}

fn settings(budget: usize) -> FitSettings {
    FitSettings {
        anneal: AnnealSettings {
            max_evaluations: budget,
            seed: 1,
            ..AnnealSettings::default()
        },
        ..FitSettings::default()
    }
}

/// Fig. 3: every clip, 4 nested models with SVD, clips in parallel. Returns the mean score
/// per model and the evaluations spent.
fn fig3(reaches: &[CapturedReach], budget: usize) -> (Vec<f64>, usize) {
    let fits: Vec<_> = reaches
        .par_iter()
        .map(|r| {
            fit_nested(
                std::slice::from_ref(r),
                &[Model::Sa, Model::Sb, Model::Sc, Model::Sd],
                OptimizerKind::Svd.default_optimizer(),
                &settings(budget),
            )
            .expect("fit")
        })
        .collect();
    let means = (0..4)
        .map(|m| fits.iter().map(|f| f.fits[m].score).sum::<f64>() / fits.len() as f64)
        .collect();
    let evaluations = fits
        .iter()
        .flat_map(|f| f.fits.iter().map(|x| x.evaluations))
        .sum();
    (means, evaluations)
}

/// Fig. 4: every clip, JT / NJT / SVD with S_A then S_C.
fn fig4(reaches: &[CapturedReach], budget: usize) -> Vec<(f64, f64)> {
    [OptimizerKind::Jt, OptimizerKind::Njt, OptimizerKind::Svd]
        .iter()
        .map(|kind| {
            let fits: Vec<_> = reaches
                .par_iter()
                .map(|r| {
                    fit_nested(
                        std::slice::from_ref(r),
                        &[Model::Sa, Model::Sc],
                        kind.default_optimizer(),
                        &settings(budget),
                    )
                    .expect("fit")
                })
                .collect();
            let mean = |m: usize| fits.iter().map(|f| f.fits[m].score).sum::<f64>() / 14.0;
            (mean(0), mean(1))
        })
        .collect()
}

fn experiments(_: &mut Criterion) {
    let set = made();
    let reaches: Vec<CapturedReach> = set.iter().map(|m| m.reach.clone()).collect();
    let budget = AnnealSettings::default().max_evaluations;
    eprintln!(
        "\n{CLIPS} reaches made by the controller (S_C truths, SVD, {FRAMES} frames at 60 Hz), {} threads:",
        rayon::current_num_threads()
    );
    let clock = Instant::now();
    let (means, evaluations) = fig3(&reaches, budget);
    let seconds = clock.elapsed().as_secs_f64();
    eprintln!(
        "  Fig. 3 (4 models nested, per clip, budget {budget}): {seconds:.2} s wall, {evaluations} evaluations ({:.2} M frames/s); mean mm S_A {:.3}  S_B {:.3}  S_C {:.3}  S_D {:.3}",
        evaluations as f64 * FRAMES as f64 / seconds / 1e6,
        means[0] * 1e3,
        means[1] * 1e3,
        means[2] * 1e3,
        means[3] * 1e3
    );
    let clock = Instant::now();
    let fig4 = fig4(&reaches, budget);
    eprintln!(
        "  Fig. 4 (JT, NJT, SVD × S_A, S_C, per clip, budget {budget}): {:.2} s wall; mean mm JT {:.3} → {:.3}, NJT {:.3} → {:.3}, SVD {:.3} → {:.3}",
        clock.elapsed().as_secs_f64(),
        fig4[0].0 * 1e3,
        fig4[0].1 * 1e3,
        fig4[1].0 * 1e3,
        fig4[1].1 * 1e3,
        fig4[2].0 * 1e3,
        fig4[2].1 * 1e3
    );
    eprintln!("  Fig. 3 mean distance (mm) against the budget per model fit:");
    eprintln!("    budget     S_A      S_B      S_C      S_D    seconds");
    for b in [250, 500, 1000, 2000, 4000, 8000, 16000] {
        let clock = Instant::now();
        let (m, _) = fig3(&reaches, b);
        eprintln!(
            "    {b:>6}  {:>7.3}  {:>7.3}  {:>7.3}  {:>7.3}  {:>7.2}",
            m[0] * 1e3,
            m[1] * 1e3,
            m[2] * 1e3,
            m[3] * 1e3,
            clock.elapsed().as_secs_f64()
        );
    }
}

/// A library's unit of work: one reach fitted S_A → S_D nested at the default
/// budget, on one core — the smooth controller's synthesis and the annealer's evaluations
/// together.
fn library_reach(c: &mut Criterion) {
    let set = made();
    let reach = set[0].reach.clone();
    let pool = one_core();
    let mut group = c.benchmark_group("library_reach");
    group.sample_size(10);
    let default = settings(AnnealSettings::default().max_evaluations);
    // The same reach as a library fits it (`fit --per clip --out-dir`): the library's
    // stopping rule (`AnnealSettings::for_library`).
    let library = FitSettings {
        anneal: default.anneal.for_library(),
        ..FitSettings::default()
    };
    let sd = [Model::Sa, Model::Sb, Model::Sc, Model::Sd];
    for (name, models, fit) in [
        ("nested_sd_svd", &sd[..], &default),
        ("nested_sd_svd_library_rule", &sd[..], &library),
        ("nested_se_svd", &Model::ALL[..], &default),
    ] {
        group.bench_function(name, |b| {
            pool.install(|| {
                b.iter(|| {
                    black_box(
                        fit_nested(
                            std::slice::from_ref(&reach),
                            models,
                            OptimizerKind::Svd.default_optimizer(),
                            fit,
                        )
                        .expect("fit"),
                    )
                })
            })
        });
    }
    group.finish();
}

criterion_group!(benches, experiments, frames_per_second, library_reach);
criterion_main!(benches);
