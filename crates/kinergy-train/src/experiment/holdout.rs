//! The per-person claim tested on held-out takes: does one vector fitted on some of a
//! person's reaches synthesize the person's *other* reaches better than neutral parameters,
//! and better than another person's vector?
//!
//! For each person, the takes are sorted by name and the **last K** are held out
//! ([`HoldoutSettings::holdout`]); the models are fitted on the rest, nested S_A → … → S_D
//! ([`crate::fit::fit_nested`], one vector for all the training takes). Every held-out take
//! (its own start posture and target) is then synthesized with:
//!
//! - the neutral parameters: S_A with gain 1, the identity synergy ([`Params::Neutral`]);
//! - each model fitted on its own person ([`Params::Fitted`]);
//! - the [`HoldoutSettings::cross_model`] vector of every *other* person, giving a person ×
//!   person table whose diagonal is the own-person result;
//! - with [`HoldoutSettings::field`], the person's parameter field ([`Params::Field`]): each
//!   training take fitted on its own (nested up to the cross model), the field of those
//!   vectors over their targets in the arm's base frame, anchored to the single cross-model
//!   vector fitted on the same takes ([`FieldFile::anchored`]), evaluated at each held-out
//!   take's own target — beside that single vector.
//!
//! The split is a fixed choice, not a K-fold rotation: a rotation would multiply the cost of
//! the fits by the number of folds. Takes come as a list of [`Take`]s (a person and a
//! reach), so the person may come from a folder, a file-name prefix or a segments file.
//! Persons are fitted in parallel; every number but the seconds is the same on any thread
//! count (each person's annealer draws from the user's seed, as [`crate::fit`] mixes it).

use std::collections::BTreeMap;
use std::time::Instant;

use kinergy_io::InvalidSetting;
use kinergy_solver::{Model, OptimizerKind, ParamSpace, PersonTempo};
use rayon::prelude::*;

use super::stats::Stats;
use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};
use crate::field::{FieldFile, FieldSettings};
use crate::fit::{FitSettings, fit_nested};
use crate::objective::Objective;

/// One take: the person it belongs to and its reach.
#[derive(Debug, Clone)]
pub struct Take {
    /// The person (a folder, a name prefix, a segments file's person column).
    pub person: String,
    /// The reach (named by its clip).
    pub reach: CapturedReach,
}

/// What the held-out experiment runs.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldoutSettings {
    /// Takes held out per person: the last K in name order (at least 1, fewer than the
    /// person's takes).
    pub holdout: usize,
    /// The models fitted per person (any order; fitted poorest first, nested).
    pub models: Vec<Model>,
    /// The optimizer the motions are synthesized with.
    pub optimizer: OptimizerKind,
    /// The model whose vector is tried on every person's held-out takes (the person ×
    /// person table); one of [`HoldoutSettings::models`].
    pub cross_model: Model,
    /// How every fit searches.
    pub fit: FitSettings,
    /// The parameter field of each person's training takes, fitted with these settings and
    /// scored on the held-out takes; `None` leaves it out (it fits every training take once
    /// more, on its own).
    pub field: Option<FieldSettings>,
    /// How fast a held-out take is synthesized ([`HeldOutTempo`]).
    pub tempo: HeldOutTempo,
}

/// One scoring job of the held-out takes: the person whose takes, the parameters, their
/// space, the vectors (one for all the takes, or one per take) and the tempo law they run
/// under.
type Job = (
    usize,
    Params,
    ParamSpace,
    Vec<Vec<f64>>,
    Option<PersonTempo>,
);

/// The smooth controller's bounds a held-out take is synthesized under.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum HeldOutTempo {
    /// The fitted person's tempo law for the take's distance ([`PersonFit::tempo_law`]):
    /// a prediction that knows nothing of the held-out take but its start and target, as
    /// `synthesize --params` and the full body deliver the person.
    #[default]
    Person,
    /// The held-out capture's own speed, which tells the synthesis how fast the held-out
    /// take moved.
    Capture,
}

impl HoldoutSettings {
    /// The cross model for `models`: S_C when it is fitted (the paper's best single clip,
    /// and the model the field predicts), otherwise the richest model fitted.
    pub fn default_cross_model(models: &[Model]) -> Option<Model> {
        if models.contains(&Model::Sc) {
            Some(Model::Sc)
        } else {
            models.iter().max().copied()
        }
    }
}

/// The parameters a held-out take was synthesized with.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Params {
    /// S_A with gain 1: the identity synergy, nothing learned.
    Neutral,
    /// `model` fitted on the training takes of `person`.
    Fitted {
        /// Whose training takes the vector was fitted on.
        person: String,
        /// The model.
        model: Model,
    },
    /// The vector the parameter field of `person`'s training takes predicts at the take's
    /// target.
    Field {
        /// Whose training takes the field was fitted on.
        person: String,
        /// The model of the field's vectors.
        model: Model,
    },
}

impl Params {
    /// The model (S_A for neutral).
    pub fn model(&self) -> Model {
        match self {
            Params::Neutral => Model::Sa,
            Params::Fitted { model, .. } | Params::Field { model, .. } => *model,
        }
    }

    /// Whose vector it is, `None` for neutral.
    pub fn fitted_on(&self) -> Option<&str> {
        match self {
            Params::Neutral => None,
            Params::Fitted { person, .. } | Params::Field { person, .. } => Some(person),
        }
    }

    /// `neutral`, `vector` (one fitted vector) or `field`.
    pub fn kind(&self) -> &'static str {
        match self {
            Params::Neutral => "neutral",
            Params::Fitted { .. } => "vector",
            Params::Field { .. } => "field",
        }
    }
}

/// One held-out take synthesized with one parameter vector.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldoutRow {
    /// The person the take belongs to.
    pub person: String,
    /// The take's clip name.
    pub clip: String,
    /// The reach's arm (a take may give one reach per arm).
    pub arm: Option<kinergy_motion::Side>,
    /// The reach's first frame in the clip.
    pub onset: usize,
    /// The frame after its last.
    pub end: usize,
    /// The parameters it was synthesized with.
    pub params: Params,
    /// Mean motion distance to the capture, meters.
    pub distance_m: f64,
    /// Frames of the reach.
    pub frames: usize,
}

/// One person's fit on its training takes.
#[derive(Debug, Clone, PartialEq)]
pub struct PersonFit {
    /// The person.
    pub person: String,
    /// The training takes' clip names, in name order.
    pub train: Vec<String>,
    /// The held-out takes' clip names, in name order.
    pub held_out: Vec<String>,
    /// Per model, poorest first: the vector and its mean distance on the training takes.
    pub models: Vec<(Model, Vec<f64>, f64)>,
    /// The parameter field of the training takes (with [`HoldoutSettings::field`]): each
    /// take's own fit, its target in the arm's base frame, the bandwidth chosen.
    pub field: Option<FieldFile>,
    /// The person's tempo law of the training takes ([`crate::person_tempo`]): the smooth
    /// controller's bounds the fits ran under and every held-out take is synthesized under
    /// with this person's vectors (a held-out target gets the person's tempo for its distance,
    /// not its own capture's). `None` under the paper's controller.
    pub tempo_law: Option<PersonTempo>,
    /// Evaluations spent over all models (the field's per-take fits included).
    pub evaluations: usize,
    /// Wall time of the person's fits, seconds.
    pub seconds: f64,
}

/// What the held-out experiment found.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldoutResults {
    /// Each person's fit, persons in name order.
    pub fits: Vec<PersonFit>,
    /// Every held-out take with every parameter vector: per person (in name order) its
    /// neutral rows, then per fitting person in name order its vectors — every model and the
    /// field (when fitted) when it is the take's own person, the cross model otherwise.
    pub rows: Vec<HoldoutRow>,
}

/// One person's held-out distances with neutral parameters and each own fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldoutLine {
    /// The person (`None`: all persons' held-out takes together).
    pub person: Option<String>,
    /// The neutral parameters' distances.
    pub neutral: Stats,
    /// Each model fitted on the person's own training takes, poorest first.
    pub models: Vec<(Model, Stats)>,
}

/// One person's held-out distances with their parameter field and with their single vector
/// of the same model, fitted on the same takes.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldLine {
    /// The person (`None`: all persons' held-out takes together).
    pub person: Option<String>,
    /// The model of the field's vectors and of the single vector.
    pub model: Model,
    /// The field's distances.
    pub field: Stats,
    /// The single vector's distances on the same takes.
    pub vector: Stats,
}

/// The tables of the held-out experiment, distances in meters.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldoutSummary {
    /// Per person, then all together: neutral against the own fitted models.
    pub own: Vec<HoldoutLine>,
    /// Per person with a field, then all together: the field against the single vector.
    pub field: Vec<FieldLine>,
    /// The cross model.
    pub cross_model: Model,
    /// The persons, in name order (the rows and the columns of [`HoldoutSummary::cross`]).
    pub persons: Vec<String>,
    /// `cross[i][j]`: the mean distance of person i's vector on person j's held-out takes.
    pub cross: Vec<Vec<f64>>,
}

impl HoldoutSummary {
    /// The tables of `results`.
    pub fn of(results: &HoldoutResults, settings: &HoldoutSettings) -> HoldoutSummary {
        let persons: Vec<String> = results.fits.iter().map(|f| f.person.clone()).collect();
        let mut models = settings.models.clone();
        models.sort();
        models.dedup();
        // Rows of the takes of `person` (all when `None`) with neutral parameters (`None`)
        // or with `model` fitted on the take's own person.
        let stats = |person: Option<&str>, model: Option<Model>| {
            Stats::of(
                results
                    .rows
                    .iter()
                    .filter(|r| person.is_none_or(|p| r.person == p))
                    .filter(|r| match (&r.params, model) {
                        (Params::Neutral, None) => true,
                        (Params::Fitted { person, model: m }, Some(model)) => {
                            *person == r.person && *m == model
                        }
                        _ => false,
                    })
                    .map(|r| r.distance_m),
            )
        };
        let line = |person: Option<&str>| {
            Some(HoldoutLine {
                person: person.map(str::to_string),
                neutral: stats(person, None)?,
                models: models
                    .iter()
                    .filter_map(|&m| stats(person, Some(m)).map(|s| (m, s)))
                    .collect(),
            })
        };
        let own = persons
            .iter()
            .map(|p| Some(p.as_str()))
            .chain([None])
            .filter_map(line)
            .collect();
        // The field rows of `person`'s takes (all when `None`), and the same takes' rows with
        // the single vector of the field's model fitted on the take's own person.
        let field_line = |person: Option<&str>| {
            let field: Vec<&HoldoutRow> = results
                .rows
                .iter()
                .filter(|r| person.is_none_or(|p| r.person == p))
                .filter(
                    |r| matches!(&r.params, Params::Field { person, .. } if *person == r.person),
                )
                .collect();
            let model = field.first()?.params.model();
            let vector = Stats::of(field.iter().filter_map(|f| {
                results
                    .rows
                    .iter()
                    .find(|r| {
                        r.clip == f.clip
                            && r.person == f.person
                            && r.params
                                == Params::Fitted {
                                    person: f.person.clone(),
                                    model,
                                }
                    })
                    .map(|r| r.distance_m)
            }))?;
            Some(FieldLine {
                person: person.map(str::to_string),
                model,
                field: Stats::of(field.iter().map(|r| r.distance_m))?,
                vector,
            })
        };
        let field = persons
            .iter()
            .map(|p| Some(p.as_str()))
            .chain([None])
            .filter_map(field_line)
            .collect();
        let cross = persons
            .iter()
            .map(|fitted| {
                let params = Params::Fitted {
                    person: fitted.clone(),
                    model: settings.cross_model,
                };
                persons
                    .iter()
                    .map(|taker| {
                        Stats::of(
                            results
                                .rows
                                .iter()
                                .filter(|r| &r.person == taker && r.params == params)
                                .map(|r| r.distance_m),
                        )
                        .map_or(f64::NAN, |s| s.mean)
                    })
                    .collect()
            })
            .collect();
        HoldoutSummary {
            own,
            field,
            cross_model: settings.cross_model,
            persons,
            cross,
        }
    }

    /// For each person (in order), whether its own vector has the smallest mean distance on
    /// its held-out takes among all persons' vectors (the column's minimum is the diagonal).
    pub fn own_vector_wins(&self) -> Vec<bool> {
        (0..self.persons.len())
            .map(|j| {
                let own = self.cross[j][j];
                (0..self.persons.len()).all(|i| i == j || own < self.cross[i][j])
            })
            .collect()
    }
}

/// The persons of `takes` in name order, each with its takes' indices in name order.
pub fn group_by_person(takes: &[Take]) -> Vec<(String, Vec<usize>)> {
    let mut groups: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, t) in takes.iter().enumerate() {
        groups.entry(&t.person).or_default().push(i);
    }
    groups
        .into_iter()
        .map(|(person, mut members)| {
            members.sort_by(|&a, &b| takes[a].reach.name().cmp(takes[b].reach.name()));
            (person.to_string(), members)
        })
        .collect()
}

/// Checks that every person has more than `holdout` takes (and `holdout` ≥ 1), naming the
/// first person that has too few: a bad input, found before any fit.
pub fn check_split(takes: &[Take], holdout: usize) -> Result<()> {
    InvalidSetting::require(!takes.is_empty(), "takes", "at least one take")?;
    InvalidSetting::require(
        holdout >= 1,
        "holdout",
        "at least 1 take held out per person",
    )?;
    for (person, members) in group_by_person(takes) {
        if members.len() <= holdout {
            return Err(TrainError::Setting(InvalidSetting::new(
                "holdout",
                format!(
                    "person `{person}` has {} take{}; holding out {holdout} leaves none to fit on (hold out fewer than {})",
                    members.len(),
                    if members.len() == 1 { "" } else { "s" },
                    members.len()
                ),
            )));
        }
    }
    Ok(())
}

/// Runs the held-out experiment on `takes`, calling `person_done` as each person's fits end
/// (from several threads).
pub fn run_holdout(
    takes: &[Take],
    settings: &HoldoutSettings,
    person_done: &(dyn Fn() + Sync),
) -> Result<HoldoutResults> {
    check_split(takes, settings.holdout)?;
    InvalidSetting::require(!settings.models.is_empty(), "models", "at least one model")?;
    InvalidSetting::require(
        settings.models.contains(&settings.cross_model),
        "cross_model",
        format!(
            "one of the fitted models (got {})",
            settings.cross_model.name()
        ),
    )?;
    let groups = group_by_person(takes);
    let optimizer = settings.optimizer.default_optimizer();
    let split = |members: &[usize]| {
        let at = members.len() - settings.holdout;
        let reaches = |ix: &[usize]| -> Vec<CapturedReach> {
            ix.iter().map(|&i| takes[i].reach.clone()).collect()
        };
        (reaches(&members[..at]), reaches(&members[at..]))
    };
    let fits: Vec<(PersonFit, Vec<ParamSpace>)> = groups
        .par_iter()
        .map(|(person, members)| {
            let (train, test) = split(members);
            let clock = Instant::now();
            let nested = fit_nested(&train, &settings.models, optimizer, &settings.fit)?;
            // A field holds one arm's reaches (its targets are in that arm's base frame): a
            // person whose takes reach with both arms gets the single vector only.
            let sides: std::collections::BTreeSet<_> = members
                .iter()
                .map(|&i| takes[i].reach.fitted_arm().side.map(|s| s.to_string()))
                .collect();
            let field = match &settings.field {
                Some(field) if sides.len() == 1 => {
                    let models: Vec<Model> = settings
                        .models
                        .iter()
                        .copied()
                        .filter(|&m| m <= settings.cross_model)
                        .collect();
                    let (file, fits) =
                        FieldFile::fit_reaches(&train, &models, optimizer, &settings.fit, field)?;
                    // Anchored to the single vector of the same model, fitted above.
                    let single = nested
                        .fits
                        .iter()
                        .find(|f| f.model() == file.model())
                        .map(|f| f.values.clone())
                        .ok_or_else(|| {
                            TrainError::Setting(InvalidSetting::new(
                                "cross_model",
                                "one of the models fitted",
                            ))
                        })?;
                    let file = file.anchored(single, &train, settings.fit.tolerance)?;
                    Some((file, fits))
                }
                _ => None,
            };
            let field_evaluations: usize = field
                .iter()
                .flat_map(|(_, fits)| fits)
                .flat_map(|n| &n.fits)
                .map(|f| f.evaluations)
                .sum();
            let fit = PersonFit {
                person: person.clone(),
                train: train.iter().map(|r| r.name().to_string()).collect(),
                held_out: test.iter().map(|r| r.name().to_string()).collect(),
                models: nested
                    .fits
                    .iter()
                    .map(|f| (f.model(), f.values.clone(), f.score))
                    .collect(),
                field: field.map(|(file, _)| file),
                tempo_law: crate::person_tempo(&train),
                evaluations: nested.fits.iter().map(|f| f.evaluations).sum::<usize>()
                    + field_evaluations,
                seconds: clock.elapsed().as_secs_f64(),
            };
            person_done();
            Ok((fit, nested.fits.into_iter().map(|f| f.space).collect()))
        })
        .collect::<Result<_>>()?;
    // Every held-out take with: neutral, its own models, its own field, the others' cross
    // model. A job's vectors: one for all of the person's held-out takes, or (the field) one
    // per take. The neutral vector runs under the take's own person's law, each fitted vector
    // under its person's (the law travels with the vector).
    let mut jobs: Vec<Job> = Vec::new();
    for j in 0..groups.len() {
        let dofs = fits[j].1[0].dof_names();
        let neutral = ParamSpace::new(Model::Sa, dofs, settings.fit.bounds)?;
        let law_of = |fit: &PersonFit| match settings.tempo {
            HeldOutTempo::Person => fit.tempo_law,
            HeldOutTempo::Capture => None,
        };
        let own_law = law_of(&fits[j].0);
        jobs.push((
            j,
            Params::Neutral,
            neutral.clone(),
            vec![neutral.neutral()],
            own_law,
        ));
        for (i, (fit, spaces)) in fits.iter().enumerate() {
            for ((model, values, _), space) in fit.models.iter().zip(spaces) {
                if i == j || *model == settings.cross_model {
                    let params = Params::Fitted {
                        person: fit.person.clone(),
                        model: *model,
                    };
                    jobs.push((j, params, space.clone(), vec![values.clone()], law_of(fit)));
                }
            }
            if let (true, Some(field)) = (i == j, &fit.field) {
                let (_, test) = split(&groups[j].1);
                let params = Params::Field {
                    person: fit.person.clone(),
                    model: field.model(),
                };
                let predicted = test
                    .iter()
                    .map(|r| field.field().evaluate(&r.local_target()))
                    .collect();
                let law = field
                    .tempo_law()
                    .copied()
                    .filter(|_| settings.tempo == HeldOutTempo::Person);
                jobs.push((j, params, field.field().space().clone(), predicted, law));
            }
        }
    }
    let tolerance = settings.fit.tolerance;
    let scored: Vec<Vec<HoldoutRow>> = jobs
        .into_par_iter()
        .map(|(j, params, space, values, law)| {
            let (_, test) = split(&groups[j].1);
            let test: Vec<CapturedReach> = test
                .iter()
                .map(|r| match &law {
                    Some(law) => r.clone().under_tempo(law),
                    None => r.clone(),
                })
                .collect();
            let distances = match values.as_slice() {
                [one] => Objective::new(test.clone(), space, optimizer)?
                    .with_tolerance(tolerance)?
                    .distances(one)?,
                per_take => test
                    .iter()
                    .zip(per_take)
                    .map(|(r, v)| {
                        Objective::new(vec![r.clone()], space.clone(), optimizer)?
                            .with_tolerance(tolerance)?
                            .score(v)
                    })
                    .collect::<Result<Vec<f64>>>()?,
            };
            Ok(test
                .iter()
                .zip(distances)
                .map(|(r, distance_m)| HoldoutRow {
                    person: groups[j].0.clone(),
                    clip: r.name().to_string(),
                    arm: r.fitted_arm().side,
                    onset: r.frames().start,
                    end: r.frames().end,
                    params: params.clone(),
                    distance_m,
                    frames: r.frame_count(),
                })
                .collect())
        })
        .collect::<Result<_>>()?;
    Ok(HoldoutResults {
        fits: fits.into_iter().map(|(f, _)| f).collect(),
        rows: scored.into_iter().flatten().collect(),
    })
}
