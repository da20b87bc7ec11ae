//! The synergy parameters file (DESIGN §3): JSON with a `format_version`, the model, the
//! optimizer with its settings, the chain's DoF names, the bounds, the values by name, and
//! (when it was fitted) a record of the fit ([`FitRecord`]).
//!
//! ```json
//! {
//!   "format_version": 1,
//!   "model": "sc",
//!   "optimizer": { "kind": "svd", "rate": 4.0, "threshold": 0.01 },
//!   "dof_names": ["shoulder_swing_x", "…"],
//!   "bounds": { "gain": { "lower": -5.0, "upper": 5.0 }, "slope": { … }, "offset": { … } },
//!   "values": { "g_shoulder_swing_x": 1.3, "…": 0.0, "s": 4.2, "o": 1.7 },
//!   "fit": { "method": "simulated_annealing", "score_m": 0.021, "…": "…" }
//! }
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Result, SolverError};
use crate::fit_record::FitRecord;
use crate::optimizer::Optimizer;
use crate::synergy::{Bounds, Model, ParamSpace, Synergy};

/// The format version this crate writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// A parameters file's content.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamsFile {
    /// Always [`FORMAT_VERSION`].
    pub format_version: u32,
    /// The synergy model.
    pub model: Model,
    /// The optimizer and its settings.
    pub optimizer: Optimizer,
    /// The chain's DoF names, in configuration order.
    pub dof_names: Vec<String>,
    /// Bounds of the parameters by kind.
    pub bounds: Bounds,
    /// Every parameter by name, in vector order (a name given twice is refused, as a
    /// top-level field given twice is).
    #[serde(deserialize_with = "unique_values")]
    pub values: serde_json::Map<String, serde_json::Value>,
    /// How the values were fitted (method, scores, seed, the reaches and their frames).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitRecord>,
}

impl ParamsFile {
    /// A file for `values` of `space` with `optimizer`, validated.
    pub fn new(space: &ParamSpace, optimizer: Optimizer, values: &[f64]) -> Result<ParamsFile> {
        space.validate(values)?;
        optimizer.validate()?;
        Ok(ParamsFile {
            format_version: FORMAT_VERSION,
            model: space.model(),
            optimizer,
            dof_names: space.dof_names().to_vec(),
            bounds: *space.bounds(),
            values: space
                .names()
                .iter()
                .zip(values)
                .map(|(n, &v)| (n.clone(), serde_json::Value::from(v)))
                .collect(),
            fit: None,
        })
    }

    /// Parses and checks a file's text; errors name the line and column, or the field.
    pub fn from_json(text: &str) -> Result<ParamsFile> {
        let file: ParamsFile = kinergy_io::parse_versioned(text, FORMAT_VERSION)
            .map_err(|e| SolverError::ParamsFile(e.to_string()))?;
        file.optimizer.validate()?;
        file.space()?;
        file.values()?;
        if let Some(record) = &file.fit {
            record
                .check()
                .map_err(|(field, why)| SolverError::ParamsFile(format!("`{field}` {why}")))?;
        }
        Ok(file)
    }

    /// Reads and checks a file.
    pub fn read(path: &Path) -> Result<ParamsFile> {
        let text = kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES)
            .map_err(|e| SolverError::ParamsFile(format!("cannot read {}: {e}", path.display())))?;
        ParamsFile::from_json(&text).map_err(|e| match e {
            SolverError::ParamsFile(m) => {
                SolverError::ParamsFile(format!("{}: {m}", path.display()))
            }
            other => SolverError::ParamsFile(format!("{}: {other}", path.display())),
        })
    }

    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        kinergy_io::to_pretty_json(self).unwrap_or_default()
    }

    /// Writes the file atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        kinergy_io::write_json_text(path, &self.to_json())
            .map_err(|e| SolverError::ParamsFile(format!("cannot write {}: {e}", path.display())))
    }

    /// The parameter space the file describes.
    pub fn space(&self) -> Result<ParamSpace> {
        ParamSpace::new(self.model, &self.dof_names, self.bounds)
    }

    /// The values in vector order, checked: every name of the model present, none
    /// unknown, each a number within its bounds.
    pub fn values(&self) -> Result<Vec<f64>> {
        let space = self.space()?;
        // Linear in the parameter count: a linear search per key takes 41 s to check a DoF
        // list of 200,000 names.
        let known: std::collections::HashSet<&str> =
            space.names().iter().map(String::as_str).collect();
        if let Some(extra) = self.values.keys().find(|k| !known.contains(k.as_str())) {
            return Err(SolverError::ParamsFile(format!(
                "`values.{extra}` is not a parameter of {} on these DoFs; expected: {}",
                self.model,
                kinergy_io::list_some(space.names(), 8)
            )));
        }
        let values = space
            .names()
            .iter()
            .map(|n| match self.values.get(n) {
                Some(v) => v.as_f64().ok_or_else(|| {
                    SolverError::ParamsFile(format!("`values.{n}` is {v}, not a number"))
                }),
                None => Err(SolverError::ParamsFile(format!("`values.{n}` is missing"))),
            })
            .collect::<Result<Vec<f64>>>()?;
        space.validate(&values)?;
        Ok(values)
    }

    /// The synergy, checked against a chain's DoF names.
    pub fn synergy_for(&self, dof_names: &[String]) -> Result<Synergy> {
        if dof_names != self.dof_names.as_slice() {
            return Err(SolverError::ParamsFile(format!(
                "`dof_names` are [{}] but the chain's are [{}]",
                kinergy_io::list_some(&self.dof_names, 8),
                kinergy_io::list_some(dof_names, 8)
            )));
        }
        Synergy::new(&self.space()?, &self.values()?)
    }
}

/// Deserializes `values`, refusing a name given twice (serde_json's map keeps the last).
fn unique_values<'de, D>(
    deserializer: D,
) -> std::result::Result<serde_json::Map<String, serde_json::Value>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    struct Unique;
    impl<'de> serde::de::Visitor<'de> for Unique {
        type Value = serde_json::Map<String, serde_json::Value>;

        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("an object of parameter values")
        }

        fn visit_map<A>(self, mut map: A) -> std::result::Result<Self::Value, A::Error>
        where
            A: serde::de::MapAccess<'de>,
        {
            let mut out = serde_json::Map::new();
            while let Some((name, value)) = map.next_entry::<String, serde_json::Value>()? {
                if out.contains_key(&name) {
                    return Err(serde::de::Error::custom(format_args!(
                        "`values.{name}` is given twice"
                    )));
                }
                out.insert(name, value);
            }
            Ok(out)
        }
    }
    deserializer.deserialize_map(Unique)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimizer::OptimizerKind;

    fn space() -> ParamSpace {
        let dofs: Vec<String> = ["a", "b"].map(String::from).to_vec();
        ParamSpace::new(Model::Sc, &dofs, Bounds::default()).expect("space")
    }

    /// An S_C file on [`space`]'s DoFs.
    fn sample() -> ParamsFile {
        ParamsFile::new(
            &space(),
            OptimizerKind::Svd.default_optimizer(),
            &[1.0, 1.0, 2.0, 0.0],
        )
        .expect("file")
    }

    /// An S_B file on `n` DoFs named `dof_0` … with every gain 1.
    fn sb_file(n: usize) -> ParamsFile {
        let names: Vec<String> = (0..n).map(|i| format!("dof_{i}")).collect();
        let space = ParamSpace::new(Model::Sb, &names, Bounds::default()).expect("space");
        ParamsFile::new(
            &space,
            OptimizerKind::Svd.default_optimizer(),
            &vec![1.0; n],
        )
        .expect("file")
    }

    #[test]
    fn round_trips_exactly() {
        let values = [1.25, -0.1, 3.0, 0.3];
        let file = ParamsFile::new(&space(), OptimizerKind::Njt.default_optimizer(), &values)
            .expect("file");
        let back = ParamsFile::from_json(&file.to_json()).expect("back");
        assert_eq!(back, file);
        assert_eq!(back.values().expect("values"), values);
    }

    #[test]
    fn errors_name_the_field() {
        let file = sample();
        let json = file.to_json();
        let cases = [
            (json.replace("\"s\": 2.0", "\"s\": 20.0"), "`s` = 20"),
            (json.replace("\"g_b\"", "\"g_c\""), "values.g_c"),
            (json.replace("\"sc\"", "\"sx\""), "line"),
            (
                json.replace("\"format_version\": 1", "\"format_version\": 7"),
                "format_version",
            ),
            (
                json.replace("\"threshold\": 0.01", "\"threshold\": -1.0"),
                "optimizer.threshold",
            ),
            (json.replace("\"o\": 0.0", "\"o\": \"soon\""), "values.o"),
        ];
        for (text, expected) in cases {
            let err = ParamsFile::from_json(&text).expect_err(expected);
            assert!(err.to_string().contains(expected), "{expected}: {err}");
        }
        // A fit record's frames and lengths are checked too.
        let record = |frames: &str, upper: &str| {
            let mut v: serde_json::Value = serde_json::from_str(&json).expect("json");
            v["fit"] = serde_json::from_str(&format!(
                r#"{{"method": "simulated_annealing", "score_m": 0.01, "start_score_m": 0.02,
                    "evaluations": 8, "iterations": 0, "status": "converged", "seed": 1,
                    "reaches": [{{"clip": "a.bvh", "frames": {frames}, "distance_m": 0.01,
                      "arm": {{"joints": ["s", "e", "w"], "upper_arm_m": {upper},
                               "forearm_m": 0.25, "hand_m": 0.0}}}}]}}"#
            ))
            .expect("record");
            v.to_string()
        };
        assert!(ParamsFile::from_json(&record("[3, 40]", "0.3")).is_ok());
        for (text, expected) in [
            (
                record("[40, 3]", "0.3"),
                "`fit.reaches[0].frames` is [40, 3]",
            ),
            (record("[5, 5]", "0.3"), "`fit.reaches[0].frames`"),
            (record("[-1, 10]", "0.3"), "fit.reaches[0].frames"),
            (record("[1.5, 20]", "0.3"), "fit.reaches[0].frames"),
            (
                record("[3, 40]", "0.0"),
                "`fit.reaches[0].arm.upper_arm_m` is 0",
            ),
            (record("[3, 40]", "-2"), "arm.upper_arm_m"),
        ] {
            let err = ParamsFile::from_json(&text).expect_err(expected);
            assert!(err.to_string().contains(expected), "{expected}: {err}");
        }
        let err = file.synergy_for(&["a".into()]).expect_err("other chain");
        assert!(err.to_string().contains("dof_names"), "{err}");
    }

    /// A parameter named twice inside `values` is refused, as a top-level field given twice
    /// is (serde_json's map would keep the last), with the line of the second.
    #[test]
    fn a_value_named_twice_is_refused() {
        let file = sample();
        let json = file.to_json();
        let twice = json.replace("\"g_b\": 1.0", "\"g_b\": 1.0,\n    \"g_b\": 3.0");
        assert_ne!(twice, json);
        let err = ParamsFile::from_json(&twice).expect_err("twice");
        let text = err.to_string();
        assert!(text.contains("`values.g_b` is given twice"), "{text}");
        assert!(text.contains("line"), "{text}");
        // Top-level fields given twice are refused too.
        let top = json.replacen(
            "\"model\": \"sc\",",
            "\"model\": \"sc\",\n  \"model\": \"sb\",",
            1,
        );
        assert_ne!(top, json);
        assert!(ParamsFile::from_json(&top).is_err());
    }

    /// A file no reader would accept is not written (what Kinergy writes, it reads back): the
    /// error says so and no file or temporary is left.
    #[test]
    fn a_file_over_the_readers_cap_is_not_written() {
        let file = sb_file(700_000);
        let dir = std::env::temp_dir().join(format!("kinergy-params-cap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("p.json");
        let err = file.write(&path).expect_err("over the cap");
        assert!(err.to_string().contains("16 MiB"), "{err}");
        assert_eq!(std::fs::read_dir(&dir).expect("dir").count(), 0);
        std::fs::remove_dir_all(&dir).expect("clean");
    }

    /// A file with 200,000 DoF names (a value each) is checked in one pass over its values
    /// (a linear search per name takes 41 s; the whole `synthesize` takes 0.4 s), and the
    /// messages that name its lists stay short.
    #[test]
    fn a_huge_dof_list_is_checked_in_one_pass_and_named_briefly() {
        let file = sb_file(200_000);
        let mut text = file.to_json();
        let back = ParamsFile::from_json(&text).expect("a huge file reads");
        assert_eq!(back.values().expect("values").len(), 200_000);
        let err = back.synergy_for(&["a".into()]).expect_err("other chain");
        assert!(err.to_string().len() < 400, "{}", err.to_string().len());
        text = text.replace("\"g_dof_7\"", "\"g_nothing\"");
        let err = ParamsFile::from_json(&text).expect_err("an unknown name");
        let message = err.to_string();
        assert!(message.contains("values.g_nothing"), "{message}");
        assert!(message.len() < 400, "{}", message.len());
    }
}
