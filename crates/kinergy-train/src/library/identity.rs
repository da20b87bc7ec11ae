//! What a library is made of and how it is fitted, as its shards record it: each take's
//! identity ([`TakeIdentity`]: its path from the library's root, size, content hash and
//! frames) and the run's [`Settings`] (every setting a result depends on). Two shards of
//! one library must agree on both; [`collect`](super::collect) refuses them otherwise,
//! naming what differs.
//!
//! Hashes are BLAKE3 (the `blake3` crate), written as 64 hexadecimal digits.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::table::LibraryError;
use crate::fit::FitJob;
use crate::source::{ArmRequest, ReachFrames, ReachQuery};
use crate::who::PersonRule;

/// The person rule's setting.
const PERSON: &str = "person";
/// The warm starts' setting (present only when they are on, so that the settings of a
/// library fitted without them read as before they existed).
const WARM_START: &str = "warm_start";

/// A take as a library knows it: two takes with the same identity are the same capture.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TakeIdentity {
    /// Its path from the library's root, `/`-separated (plain names, never `..`).
    pub path: String,
    /// Its size, bytes.
    pub bytes: u64,
    /// The BLAKE3 hash of its bytes.
    pub blake3: String,
    /// The frame count its header states (its weight when the takes are dealt), if read.
    pub frames: Option<usize>,
}

impl TakeIdentity {
    /// The identity of the take at `path`, named `relative` from the library's root.
    pub fn of(path: &Path, relative: &Path) -> Result<TakeIdentity, LibraryError> {
        let (bytes, blake3) = hash_file(path).map_err(|e| LibraryError::Input {
            path: path.to_path_buf(),
            why: format!("cannot read the take to record it: {e}"),
        })?;
        let frames = kinergy_motion::kinergy_bvh::header_frame_count(path)
            .ok()
            .flatten();
        Ok(TakeIdentity {
            path: slash_path(relative),
            bytes,
            blake3,
            frames,
        })
    }

    /// Its weight when the takes are dealt: its frames (1 where its header cannot be read:
    /// its fit says why).
    pub fn weight(&self) -> u64 {
        self.frames.unwrap_or(1).max(1) as u64
    }

    /// How `now` differs from this take (of the same path): `None` when it does not.
    pub fn change(&self, now: &TakeIdentity) -> Option<String> {
        if self.bytes == now.bytes && self.blake3 == now.blake3 {
            return None;
        }
        let (a, b) = (self.bytes, now.bytes);
        Some(match a.cmp(&b) {
            std::cmp::Ordering::Less => format!("{} grown ({a} → {b} bytes)", self.path),
            std::cmp::Ordering::Greater => format!("{} shrunk ({a} → {b} bytes)", self.path),
            std::cmp::Ordering::Equal => {
                format!("{} edited (same size, other content)", self.path)
            }
        })
    }
}

/// `relative` as a record writes it: its components joined by `/`.
pub fn slash_path(relative: &Path) -> String {
    relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
}

/// The changes from the takes `before` to the takes `now` (each list by path), in words:
/// each take added, removed, grown, shrunk or edited.
pub fn takes_changes(before: &[TakeIdentity], now: &[TakeIdentity]) -> Vec<String> {
    let old: BTreeMap<&str, &TakeIdentity> = before.iter().map(|t| (t.path.as_str(), t)).collect();
    let new: BTreeMap<&str, &TakeIdentity> = now.iter().map(|t| (t.path.as_str(), t)).collect();
    let mut out = Vec::new();
    for (path, take) in &old {
        match new.get(path) {
            None => out.push(format!("{path} removed")),
            Some(now) => out.extend(take.change(now)),
        }
    }
    out.extend(
        new.keys()
            .filter(|p| !old.contains_key(*p))
            .map(|p| format!("{p} added")),
    );
    out
}

/// The BLAKE3 hash of the file at `path` and its size, read in pieces (a take of any size
/// in little memory). Only a regular file is read.
pub fn hash_file(path: &Path) -> std::io::Result<(u64, String)> {
    let metadata = std::fs::metadata(path)?;
    if let Some(e) = kinergy_io::not_regular(&metadata) {
        return Err(e);
    }
    let mut hasher = blake3::Hasher::new();
    let bytes = std::io::copy(&mut std::fs::File::open(path)?, &mut hasher)?;
    Ok((bytes, hasher.finalize().to_hex().to_string()))
}

/// The BLAKE3 hash of `bytes`, as 64 hexadecimal digits.
pub fn hash_bytes(bytes: &[u8]) -> String {
    blake3::hash(bytes).to_hex().to_string()
}

/// Every setting a library's results depend on, by name (the CLI's flag names where there
/// is one): the seed, the models, the optimizer, the controller, the objective, the budget
/// and the other search settings, the refinement, and the query's arm, frames, selection,
/// base, reading options (`unit`, `up` and `positions`, as `--from-unit`, `--up` and
/// `--positions` spell them) and segments file (its hash), and the person rule
/// ([`Settings::with_person`]: it names the reaches' persons and changes no result). Shards
/// of one library must have the same; [`Settings::differences`] names the ones that differ.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Settings(Map<String, Value>);

impl Settings {
    /// The settings of a library fitted with `job`, its reaches found by `query` (with the
    /// segments file at `segments`, hashed, when there is one).
    pub fn of(
        job: &FitJob,
        query: &ReachQuery,
        segments: Option<&Path>,
    ) -> Result<Settings, LibraryError> {
        let json = |v: Result<Value, serde_json::Error>| v.unwrap_or(Value::Null);
        let anneal = &job.settings.anneal;
        let mut map = Map::new();
        let mut set = |name: &str, value: Value| {
            map.insert(name.to_string(), value);
        };
        set("seed", anneal.seed.into());
        set(
            "model",
            job.models
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .into(),
        );
        set("optimizer", json(serde_json::to_value(job.optimizer)));
        set("controller", query.controller.name().into());
        set(
            "objective",
            json(serde_json::to_value(job.settings.objective)),
        );
        set("budget", anneal.max_evaluations.into());
        set("population", anneal.population.into());
        set("temperature", anneal.temperature.into());
        set("cooling", anneal.cooling.into());
        set("stable_change", anneal.stable_tolerance.into());
        set("stable_window", anneal.stable_window.into());
        set("initial_step", anneal.initial_step.into());
        set("min_step", anneal.min_step.into());
        set("max_step", anneal.max_step.into());
        set("target_acceptance", anneal.target_acceptance.into());
        set("adapt_every", anneal.adapt_every.into());
        set("share_best_every", anneal.share_best_every.into());
        set("tolerance", job.settings.tolerance.into());
        set("bounds", json(serde_json::to_value(job.settings.bounds)));
        set("refine", job.refine.map_or(Value::Null, Value::from));
        set(
            "arm",
            match &query.arm {
                ArmRequest::Auto => "auto".into(),
                ArmRequest::Arm(arm) => match &arm.joints {
                    None => arm.side.to_string().into(),
                    Some(joints) => format!("{} ({})", arm.side, joints.join(", ")).into(),
                },
            },
        );
        let (frames, select) = match &query.frames {
            ReachFrames::Window(w) => (format!("{}..{}", w.start, w.end), Value::Null),
            ReachFrames::Segments(s) => ("segments".to_string(), s.to_string().into()),
        };
        set("frames", frames.into());
        set("select", select);
        set("base", format!("{:?}", query.base).to_lowercase().into());
        // How the captures are read, each as its flag spells it (`--from-unit`, `--up`,
        // `--positions`); the largest file read refuses a take, never changes its fit.
        set("unit", query.read.unit.name().into());
        set("up", query.read.up.name().into());
        set("positions", query.read.position_reading.name().into());
        let segments = match segments {
            None => Value::Null,
            Some(path) => {
                let (_, hash) = hash_file(path).map_err(|e| LibraryError::Input {
                    path: path.to_path_buf(),
                    why: format!("cannot read the segments file to record it: {e}"),
                })?;
                hash.into()
            }
        };
        set("segments", segments);
        Ok(Settings(map))
    }

    /// These settings with the person rule `rule`, the `person` setting as the rule's
    /// `Display` spells it (`auto`, `folder`, `file`, `regex:PATTERN`, `segments`,
    /// `map:HASH`). Records of older versions have none.
    pub fn with_person(mut self, rule: &PersonRule) -> Settings {
        self.0.insert(PERSON.to_string(), rule.to_string().into());
        self
    }

    /// The person rule recorded, if any (`None`: a record of an older version, whose
    /// persons are the takes' folder names or a segments file's `person` column).
    pub fn person(&self) -> Option<&str> {
        self.0.get(PERSON).and_then(Value::as_str)
    }

    /// These settings with warm starts (`fit --warm-start`: the setting `warm_start`, which
    /// is `person`, the reaches grouped by person, motion and arm), or without (no setting).
    pub fn with_warm_start(mut self, on: bool) -> Settings {
        if on {
            self.0.insert(WARM_START.to_string(), "person".into());
        } else {
            self.0.remove(WARM_START);
        }
        self
    }

    /// Whether these settings fit with warm starts.
    pub fn warm_start(&self) -> bool {
        self.0.contains_key(WARM_START)
    }

    /// Whether `other` fits every reach as these settings do: the same settings but for
    /// the person rule, which changes no result (a resume with another rule names the
    /// persons anew and fits nothing again) — unless warm starts are on: they group the
    /// reaches by person, so the rule is one of the fits' settings then.
    pub fn same_fits(&self, other: &Settings) -> bool {
        let fits = |s: &Settings| {
            let mut map = s.0.clone();
            if !s.warm_start() {
                map.remove(PERSON);
            }
            map
        };
        fits(self) == fits(other)
    }

    /// The settings in which `other` differs from these, each as `name VALUE (here: VALUE)`,
    /// in order.
    pub fn differences(&self, other: &Settings, here: &str) -> Vec<String> {
        let mut names: Vec<&String> = self.0.keys().collect();
        names.extend(other.0.keys().filter(|k| !self.0.contains_key(*k)));
        names
            .into_iter()
            .filter(|k| self.0.get(*k) != other.0.get(*k))
            .map(|k| {
                let show = |v: Option<&Value>| match v {
                    None => "(not recorded)".to_string(),
                    Some(Value::String(s)) => kinergy_io::clip_text(s, 80).into_owned(),
                    Some(v) => kinergy_io::clip_text(&v.to_string(), 80).into_owned(),
                };
                format!(
                    "{k} {} ({here}: {})",
                    show(other.0.get(k)),
                    show(self.0.get(k))
                )
            })
            .collect()
    }

    /// A short fingerprint of the settings (16 hexadecimal digits of their hash), the
    /// `settings` column of `library.csv`.
    pub fn fingerprint(&self) -> String {
        let text = serde_json::to_string(&self.0).unwrap_or_default();
        let mut out = String::with_capacity(16);
        for b in &blake3::hash(text.as_bytes()).as_bytes()[..8] {
            let _ = write!(out, "{b:02x}");
        }
        out
    }

    /// The settings by name (for the property test and tools).
    pub fn get(&self, name: &str) -> Option<&Value> {
        self.0.get(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn take(path: &str, bytes: u64, hash: &str) -> TakeIdentity {
        TakeIdentity {
            path: path.into(),
            bytes,
            blake3: hash.into(),
            frames: Some(10),
        }
    }

    #[test]
    fn takes_changes_name_each_take_added_removed_grown_shrunk_or_edited() {
        let before = [
            take("a.bvh", 10, "1"),
            take("b.bvh", 10, "2"),
            take("c.bvh", 10, "3"),
            take("d.bvh", 10, "4"),
            take("e.bvh", 10, "5"),
        ];
        let now = [
            take("a.bvh", 10, "1"),
            take("b.bvh", 12, "x"),
            take("c.bvh", 8, "y"),
            take("d.bvh", 10, "z"),
            take("f.bvh", 10, "6"),
        ];
        assert_eq!(
            takes_changes(&before, &now),
            [
                "b.bvh grown (10 → 12 bytes)",
                "c.bvh shrunk (10 → 8 bytes)",
                "d.bvh edited (same size, other content)",
                "e.bvh removed",
                "f.bvh added"
            ]
        );
        assert!(takes_changes(&before, &before).is_empty());
    }

    #[test]
    fn settings_name_what_differs_and_their_fingerprints_differ() {
        let job = FitJob {
            models: vec![kinergy_solver::Model::Sa],
            optimizer: Default::default(),
            settings: Default::default(),
            refine: None,
        };
        let mut job = job;
        job.settings.anneal.seed = 1;
        let query = ReachQuery::default();
        let a = Settings::of(&job, &query, None).unwrap();
        let mut other = job.clone();
        other.settings.anneal.seed = 7;
        other.models.push(kinergy_solver::Model::Sb);
        let b = Settings::of(&other, &query, None).unwrap();
        assert_eq!(a, Settings::of(&job, &query, None).unwrap());
        assert_eq!(
            a.differences(&b, "shard 1/2"),
            [
                "seed 7 (shard 1/2: 1)",
                "model [\"sa\",\"sb\"] (shard 1/2: [\"sa\"])"
            ]
        );
        assert_ne!(a.fingerprint(), b.fingerprint());
        assert_eq!(a.fingerprint().len(), 16);
        let paper = ReachQuery {
            controller: crate::source::ControllerKind::Paper,
            ..ReachQuery::default()
        };
        let c = Settings::of(&job, &paper, None).unwrap();
        assert_eq!(
            a.differences(&c, "here"),
            ["controller paper (here: smooth)"]
        );
        // The sweep's reading options, once printed as `read ImportOptions { unit: … }`:
        // each named as its flag spells it, with both values.
        let read = ReachQuery {
            read: kinergy_motion::ImportOptions {
                unit: kinergy_motion::UnitChoice::Fixed(kinergy_motion::LengthUnit::Centimeter),
                up: kinergy_motion::UpChoice::Fixed(kinergy_motion::UpAxis::NegZ),
                position_reading: kinergy_motion::PositionReadingChoice::Add,
                max_file_bytes: Some(7),
            },
            ..ReachQuery::default()
        };
        let d = Settings::of(&job, &read, None).unwrap();
        assert_eq!(
            a.differences(&d, "this run"),
            [
                "unit cm (this run: auto)",
                "up -z (this run: auto)",
                "positions add (this run: auto)"
            ]
        );
        // The largest file read is no setting of the fits.
        let big = ReachQuery {
            read: kinergy_motion::ImportOptions {
                max_file_bytes: Some(1 << 40),
                ..ReachQuery::default().read
            },
            ..ReachQuery::default()
        };
        assert_eq!(Settings::of(&job, &big, None).unwrap(), a);
        // The person rule: a setting of its own, named where it differs, but no fit's.
        let by_file = a.clone().with_person(&PersonRule::File);
        let by_folder = a.clone().with_person(&PersonRule::Folder);
        assert_eq!(
            by_file.differences(&by_folder, "this run"),
            ["person folder (this run: file)"]
        );
        assert_eq!(
            by_file.differences(&a, "this run"),
            ["person (not recorded) (this run: file)"]
        );
        assert_ne!(by_file.fingerprint(), by_folder.fingerprint());
        assert!(by_file.same_fits(&by_folder) && by_file.same_fits(&a));
        assert!(!by_file.same_fits(&b.with_person(&PersonRule::File)));
        assert_eq!((by_file.person(), a.person()), (Some("file"), None));
        // Warm starts: a setting of the fits, absent when off (the settings read as before
        // they existed); with them, the person rule groups the reaches, so it is one too.
        assert_eq!(a.clone().with_warm_start(false), a);
        let warm_file = by_file.clone().with_warm_start(true);
        let warm_folder = by_folder.clone().with_warm_start(true);
        assert!(warm_file.warm_start() && !by_file.warm_start());
        assert_eq!(
            warm_file.differences(&by_file, "this run"),
            ["warm_start (not recorded) (this run: person)"]
        );
        assert!(!warm_file.same_fits(&by_file) && !by_file.same_fits(&warm_file));
        assert!(!warm_file.same_fits(&warm_folder));
        assert!(warm_file.same_fits(&warm_file.clone()));
    }

    #[test]
    fn a_file_s_hash_is_blake3_of_its_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.bvh");
        std::fs::write(&path, b"abc").unwrap();
        let (bytes, hash) = hash_file(&path).unwrap();
        assert_eq!(bytes, 3);
        // BLAKE3's published test vector for "abc".
        assert_eq!(
            hash,
            "6437b3ac38465133ffb63b75273a8db548c558465d79db03fd359c6cd5bd9d85"
        );
        assert_eq!(hash_bytes(b"abc"), hash);
        assert!(hash_file(dir.path()).is_err(), "a folder is not hashed");
    }
}
