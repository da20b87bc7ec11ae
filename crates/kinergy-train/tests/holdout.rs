//! The per-person claim on held-out takes (`experiment::run_holdout`): on persons whose
//! reaches were made from known, different S_C parameters, each person's own fitted vector
//! beats the other's and the neutral parameters on its held-out reach; the split, the rows
//! and the tables are what the design says, the same on any thread count; a person with too
//! few takes is named. On the Bandai Namco captures (CC BY-NC, read from `../shared/data/`
//! and skipped, saying so, where absent), fitted S_C beats neutral on held-out takes and each
//! style's own vector beats the other's.

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::path::{Path, PathBuf};

use kinergy_motion::segment::{SegmentSettings, main_segment};
use kinergy_motion::{ArmJoints, Clip, ImportOptions, Side, read_clip};
use kinergy_solver::{BaseMode, Model, OptimizerKind};
use kinergy_train::anneal::AnnealSettings;
use kinergy_train::experiment::{
    HeldOutTempo, HoldoutResults, HoldoutSettings, HoldoutSummary, Params, Take, check_split,
    run_holdout,
};
use kinergy_train::field::FieldSettings;
use kinergy_train::fit::FitSettings;
use kinergy_train::synthetic::{Truth, made_reach};
use kinergy_train::{CapturedReach, Objective, TrainError};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Two persons with different true S_C vectors (gains and timing), three reaches each
/// toward different targets, made by the controller itself from the fixture's first frame.
fn made_persons() -> Vec<Take> {
    let (clip, _) =
        read_clip(&repo("tests/data/006_14.bvh"), &ImportOptions::default()).expect("fixture");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let truths = [
        ("quick", [1.4, 0.7, 1.1, 1.8, 0.6, 0.9, 1.2, 7.0, 1.5]),
        ("slow", [0.4, 1.6, 0.5, 0.6, 1.5, 0.3, 0.7, 2.0, 4.0]),
    ];
    let offsets: [[f64; 7]; 3] = [
        [0.35, -0.25, -0.3, -0.5, 0.2, 0.1, 0.05],
        [0.2, -0.4, 0.1, -0.7, 0.1, 0.0, 0.1],
        [0.45, -0.1, -0.2, -0.3, 0.3, 0.2, 0.0],
    ];
    let mut takes = Vec::new();
    for (person, truth) in truths {
        for (k, offset) in offsets.iter().enumerate() {
            let name = format!("{person}/r{k}");
            let made = made_reach(
                &name,
                &clip,
                &arm,
                45,
                Truth {
                    model: Model::Sc,
                    values: &truth,
                    optimizer: OptimizerKind::Svd.default_optimizer(),
                },
                offset,
            )
            .expect("made reach");
            let reach = made.reach;
            takes.push(Take {
                person: person.into(),
                reach,
            });
        }
    }
    // Not in name order: the split sorts.
    takes.reverse();
    takes
}

fn settings(models: Vec<Model>, budget: usize) -> HoldoutSettings {
    HoldoutSettings {
        holdout: 1,
        models,
        optimizer: OptimizerKind::Svd,
        cross_model: Model::Sc,
        fit: FitSettings {
            anneal: AnnealSettings {
                max_evaluations: budget,
                seed: 7,
                ..AnnealSettings::default()
            },
            ..FitSettings::default()
        },
        field: None,
        tempo: HeldOutTempo::default(),
    }
}

/// The distance of `person`'s take with `params`.
fn distance(results: &HoldoutResults, person: &str, params: &Params) -> f64 {
    let rows: Vec<_> = results
        .rows
        .iter()
        .filter(|r| r.person == person && &r.params == params)
        .collect();
    assert_eq!(rows.len(), 1, "{person} {params:?}");
    rows[0].distance_m
}

fn fitted(person: &str, model: Model) -> Params {
    Params::Fitted {
        person: person.into(),
        model,
    }
}

#[test]
fn own_vectors_beat_the_other_persons_and_neutral_on_held_out_reaches() {
    let takes = made_persons();
    let s = settings(vec![Model::Sa, Model::Sc], 600);
    let results = run_holdout(&takes, &s, &|| {}).expect("holdout");
    // The split: the last take in name order held out, the rest fitted.
    let persons: Vec<&str> = results.fits.iter().map(|f| f.person.as_str()).collect();
    assert_eq!(persons, ["quick", "slow"]);
    for f in &results.fits {
        let p = &f.person;
        assert_eq!(f.train, [format!("{p}/r0"), format!("{p}/r1")]);
        assert_eq!(f.held_out, [format!("{p}/r2")]);
        assert_eq!(f.models.len(), 2);
    }
    // Per person's take: neutral, own S_A and S_C, the other's S_C.
    assert_eq!(results.rows.len(), 2 * 4, "{:#?}", results.rows);
    for (own, other) in [("quick", "slow"), ("slow", "quick")] {
        let neutral = distance(&results, own, &Params::Neutral);
        let mine = distance(&results, own, &fitted(own, Model::Sc));
        let theirs = distance(&results, own, &fitted(other, Model::Sc));
        assert!(
            mine < theirs && mine < neutral,
            "{own}: own S_C {mine} m, {other}'s {theirs} m, neutral {neutral} m"
        );
    }
    let summary = HoldoutSummary::of(&results, &s);
    assert_eq!(summary.own_vector_wins(), [true, true]);
    // The diagonal is the own S_C row; the last line is every person together.
    for (i, p) in summary.persons.iter().enumerate() {
        assert_eq!(
            summary.cross[i][i],
            distance(&results, p, &fitted(p, Model::Sc))
        );
    }
    assert_eq!(summary.own.len(), 3);
    assert_eq!(summary.own[2].person, None);
    assert_eq!(summary.own[2].neutral.count, 2);
}

#[test]
fn the_field_of_the_training_takes_predicts_each_held_out_take_at_its_own_target() {
    let takes = made_persons();
    let s = HoldoutSettings {
        field: Some(FieldSettings::default()),
        ..settings(vec![Model::Sa, Model::Sc], 600)
    };
    let results = run_holdout(&takes, &s, &|| {}).expect("holdout");
    // Per person's take: neutral, own S_A and S_C, own field, the other's S_C.
    assert_eq!(results.rows.len(), 2 * 5, "{:#?}", results.rows);
    let summary = HoldoutSummary::of(&results, &s);
    assert_eq!(summary.field.len(), 3, "two persons and all");
    for (fit, line) in results.fits.iter().zip(&summary.field) {
        let p = &fit.person;
        let file = fit.field.as_ref().expect("a field per person");
        // The field is made of the training takes, each fitted on its own, up to S_C.
        assert_eq!(file.model(), Model::Sc);
        let clips: Vec<&str> = file.reaches().iter().map(|r| r.clip.as_str()).collect();
        assert_eq!(
            clips,
            fit.train.iter().map(String::as_str).collect::<Vec<_>>()
        );
        // Its row is the held-out take synthesized with the field's vector at the take's
        // target in the arm's base frame, under the person's tempo law (the field's, the
        // training takes' law), scored again here independently.
        let take = &takes
            .iter()
            .find(|t| t.reach.name() == fit.held_out[0])
            .expect("held-out take")
            .reach;
        let law = file
            .tempo_law()
            .copied()
            .expect("a law of the training takes");
        assert_eq!(Some(law), fit.tempo_law);
        let predicted = file.field().evaluate(&take.local_target());
        let again = Objective::new(
            vec![take.clone().under_tempo(&law)],
            file.field().space().clone(),
            file.optimizer(),
        )
        .expect("objective")
        .score(&predicted)
        .expect("score");
        let field_params = Params::Field {
            person: p.clone(),
            model: Model::Sc,
        };
        assert_eq!(distance(&results, p, &field_params), again);
        // The summary sets it beside the single S_C vector on the same take.
        assert_eq!(line.person.as_deref(), Some(p.as_str()));
        assert_eq!(line.field.mean, again);
        assert_eq!(
            line.vector.mean,
            distance(&results, p, &fitted(p, Model::Sc))
        );
        // Both persons' takes were made from one true vector per person: the field, made of
        // that person's fits, beats the neutral parameters.
        let neutral = distance(&results, p, &Params::Neutral);
        eprintln!(
            "{p}: field {:.2} mm, neutral {:.2} mm",
            again * 1e3,
            neutral * 1e3
        );
        assert!(again < neutral, "{p}: field {again} m, neutral {neutral} m");
    }
    assert_eq!(summary.field[2].person, None);
    assert_eq!(summary.field[2].field.count, 2);
}

#[test]
fn the_held_out_experiment_is_the_same_on_any_thread_count() {
    let takes = made_persons();
    let s = settings(vec![Model::Sa, Model::Sc], 150);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut r = pool
            .install(|| run_holdout(&takes, &s, &|| {}))
            .expect("holdout");
        for f in &mut r.fits {
            f.seconds = 0.0;
        }
        r
    };
    assert_eq!(on(1), on(3));
}

#[test]
fn holding_out_all_of_a_persons_takes_names_the_person() {
    let mut takes = made_persons();
    takes.retain(|t| t.person == "quick" || t.reach.name() == "slow/r0");
    for (holdout, person) in [(1, "slow"), (3, "quick")] {
        match check_split(&takes, holdout) {
            Err(TrainError::Setting(kinergy_io::InvalidSetting { field, why })) => {
                assert_eq!(field, "holdout");
                assert!(why.contains(&format!("`{person}`")), "{why}");
            }
            other => panic!("holdout {holdout}: {other:?}"),
        }
    }
    assert!(check_split(&takes, 0).is_err());
    let s = settings(vec![Model::Sc], 50);
    assert!(run_holdout(&takes, &s, &|| {}).is_err());
}

/// The Bandai Namco takes `<style>_<NNN>.bvh`, the main reach of the left arm, or `None`
/// (with a notice) where the folder is absent.
fn bandai(styles: &[&str], takes: usize) -> Option<Vec<Take>> {
    let root = repo("../shared/data/bandai-raise-left");
    if !root.is_dir() {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the Bandai Namco captures are never committed)",
            root.display()
        ));
        return None;
    }
    let mut out = Vec::new();
    for style in styles {
        for k in 1..=takes {
            let path = root.join(format!("{style}_{k:03}.bvh"));
            let (clip, _): (Clip, _) = read_clip(&path, &ImportOptions::default())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let arm = ArmJoints::find(clip.skeleton(), Side::Left).expect("left arm");
            let name = path.display().to_string();
            let frames = main_segment(&clip, &arm, &SegmentSettings::default(), &name)
                .expect("main reach")
                .frames();
            let reach =
                CapturedReach::new(&name, &clip, &arm, frames, BaseMode::Replay).expect("reach");
            out.push(Take {
                person: style.to_string(),
                reach,
            });
        }
    }
    Some(out)
}

#[test]
fn bandai_fitted_sc_beats_neutral_on_held_out_takes() {
    let Some(takes) = bandai(&["active", "elderly"], 3) else {
        return;
    };
    let s = settings(vec![Model::Sa, Model::Sc], 400);
    let results = run_holdout(&takes, &s, &|| {}).expect("holdout");
    let summary = HoldoutSummary::of(&results, &s);
    let all = summary.own.last().expect("all");
    let sc = all
        .models
        .iter()
        .find(|(m, _)| *m == Model::Sc)
        .expect("S_C")
        .1;
    eprintln!(
        "held out: neutral {:.1} mm, own S_C {:.1} mm; cross {:?}",
        all.neutral.mean * 1e3,
        sc.mean * 1e3,
        summary.cross
    );
    assert_eq!(all.neutral.count, 2);
    assert_eq!(
        summary.own_vector_wins(),
        [true, true],
        "{:?}",
        summary.cross
    );
    assert!(
        sc.mean < all.neutral.mean,
        "fitted S_C {} m, neutral {} m",
        sc.mean,
        all.neutral.mean
    );
    for r in &results.rows {
        assert!(r.distance_m.is_finite() && r.distance_m > 0.0, "{r:?}");
    }
}

/// A held-out take is synthesized under the fitted person's tempo law for its distance (the
/// default), or told its own capture's speed (`HeldOutTempo::Capture`): the same fitted vector
/// scored again here independently both ways.
#[test]
fn held_out_takes_run_under_the_persons_law_or_their_own_capture_speed() {
    let takes = made_persons();
    for tempo in [HeldOutTempo::Person, HeldOutTempo::Capture] {
        let s = HoldoutSettings {
            tempo,
            cross_model: Model::Sa,
            ..settings(vec![Model::Sa], 200)
        };
        let results = run_holdout(&takes, &s, &|| {}).expect("holdout");
        for fit in &results.fits {
            let law = fit.tempo_law.expect("a law of the training takes");
            let take = &takes
                .iter()
                .find(|t| t.reach.name() == fit.held_out[0])
                .expect("held-out take")
                .reach;
            let (model, values, _) = &fit.models[0];
            let space = kinergy_solver::ParamSpace::new(*model, &take.dof_names(), s.fit.bounds)
                .expect("space");
            let run = match tempo {
                HeldOutTempo::Person => take.clone().under_tempo(&law),
                HeldOutTempo::Capture => take.clone(),
            };
            let again = Objective::new(vec![run], space, s.optimizer.default_optimizer())
                .expect("objective")
                .score(values)
                .expect("score");
            assert_eq!(
                distance(&results, &fit.person, &fitted(&fit.person, *model)),
                again,
                "{tempo:?}"
            );
        }
    }
}
