//! `results.csv`, the one schema of an experiment's rows: what `kinergy compare` writes and
//! Python's `compare` returns, from one [`Serialize`] of [`Row`].

use serde::ser::{Serialize, SerializeStruct, Serializer};

use super::Row;

impl Row {
    /// results.csv's columns, in order: the fields [`Row`] serializes to.
    pub const COLUMNS: [&'static str; 11] = [
        "clip",
        "arm",
        "onset",
        "end",
        "model",
        "optimizer",
        "method",
        "distance_m",
        "frames",
        "evaluations",
        "seconds",
    ];
}

impl Serialize for Row {
    /// One row of results.csv: names for the model, optimizer and method (`sc`, `svd`,
    /// `sa_from_neutral`), the arm's side or empty.
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let [
            clip,
            arm,
            onset,
            end,
            model,
            optimizer,
            method,
            distance,
            frames,
            evaluations,
            seconds,
        ] = Row::COLUMNS;
        let mut row = serializer.serialize_struct("Row", Row::COLUMNS.len())?;
        row.serialize_field(clip, &self.clip)?;
        row.serialize_field(arm, &self.arm.map_or_else(String::new, |s| s.to_string()))?;
        row.serialize_field(onset, &self.onset)?;
        row.serialize_field(end, &self.end)?;
        row.serialize_field(model, self.model.name())?;
        row.serialize_field(optimizer, self.optimizer.name())?;
        row.serialize_field(method, self.method.name())?;
        row.serialize_field(distance, &self.distance_m)?;
        row.serialize_field(frames, &self.frames)?;
        row.serialize_field(evaluations, &self.evaluations)?;
        row.serialize_field(seconds, &self.seconds)?;
        row.end()
    }
}

#[cfg(test)]
mod tests {
    use kinergy_solver::{Model, OptimizerKind};

    use super::*;
    use crate::experiment::Method;

    #[test]
    fn a_row_serializes_to_the_columns_in_order_with_names() {
        let row = Row {
            clip: "p01/r01.bvh".into(),
            arm: Some(kinergy_motion::Side::Left),
            onset: 3,
            end: 40,
            model: Model::Sc,
            optimizer: OptimizerKind::Svd,
            method: Method::AnnealingFromNeutral,
            distance_m: 0.0125,
            frames: 37,
            evaluations: 900,
            seconds: 1.5,
        };
        let json = serde_json::to_value(&row).expect("serializes");
        let keys: Vec<&str> = json
            .as_object()
            .expect("an object")
            .keys()
            .map(String::as_str)
            .collect();
        let mut sorted = Row::COLUMNS.to_vec();
        sorted.sort_unstable();
        let mut seen = keys.clone();
        seen.sort_unstable();
        assert_eq!(seen, sorted);
        assert_eq!(json["arm"], "left");
        assert_eq!(json["model"], "sc");
        assert_eq!(json["method"], "sa_from_neutral");
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(&row).expect("writes");
        let text = String::from_utf8(w.into_inner().expect("flushes")).expect("utf-8");
        assert_eq!(text.lines().next(), Some(Row::COLUMNS.join(",").as_str()));
        assert_eq!(
            text.lines().nth(1),
            Some("p01/r01.bvh,left,3,40,sc,svd,sa_from_neutral,0.0125,37,900,1.5")
        );
    }
}
