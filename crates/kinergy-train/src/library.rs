//! A library of captures shared among machines: which takes a shard fits.
//!
//! A library's takes are dealt to shards by weight (their frame counts), the same way on
//! every machine, so that shards run anywhere — a Slurm array's tasks, or `--shard I/N` by
//! hand — fit disjoint shares that together are the library. [`collect`] checks the shards'
//! records against the result files and writes the library's tables ([`LibraryRow`]:
//! `library.csv`, written and read by one type).

mod names;
mod shard;
mod table;

pub use names::{Takes, common_folder, names_of, relative_name, take_names, unique_takes};
pub use shard::{ShardEvent, ShardOutcome, ShardRun};
pub use table::{
    Collected, LIBRARY, LibraryError, LibraryRow, LibraryTable, PersonLine, RecordRow, SHARDS,
    SKIPPED, SkippedRow, collect, is_complete, read_record, record_path, write_csv,
};

/// Which share of a library's takes this run fits: shard `index` (1-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 1 to `count`.
    pub index: usize,
    /// How many shards share the library.
    pub count: usize,
}

impl Shard {
    /// The whole library.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// `--shard I/N` (1 ≤ I ≤ N ≤ 100,000).
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("`{text}`: expected I/N with 1 ≤ I ≤ N, e.g. 2/8");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count || count > MAX_SHARDS {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The shard a Slurm array task is: task `SLURM_ARRAY_TASK_ID` of the array's
    /// `SLURM_ARRAY_TASK_COUNT`, counted from `SLURM_ARRAY_TASK_MIN` (so `--array=0-7` and
    /// `--array=1-8` both make 8 shards). `None` outside an array job.
    pub fn from_slurm(env: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>, String> {
        let Some(id) = env("SLURM_ARRAY_TASK_ID") else {
            return Ok(None);
        };
        let number = |name: &str| -> Result<usize, String> {
            let text = env(name).ok_or_else(|| {
                format!("SLURM_ARRAY_TASK_ID is set but {name} is not: is this an array job?")
            })?;
            text.trim()
                .parse()
                .map_err(|_| format!("{name}=`{text}` is not a whole number"))
        };
        let id: usize = id
            .trim()
            .parse()
            .map_err(|_| format!("SLURM_ARRAY_TASK_ID=`{id}` is not a whole number"))?;
        let (min, count) = (
            number("SLURM_ARRAY_TASK_MIN")?,
            number("SLURM_ARRAY_TASK_COUNT")?,
        );
        let index = id
            .checked_sub(min)
            .map(|k| k + 1)
            .filter(|&i| i <= count)
            .ok_or_else(|| {
                format!(
                    "SLURM_ARRAY_TASK_ID={id} is outside the array (from {min}, {count} tasks): \
                     use a contiguous --array=A-B, or --shard I/N"
                )
            })?;
        Ok(Some(Shard { index, count }))
    }
}

/// The takes of `paths` (the library's, in its order) dealt to `shard`, each weighed by the
/// frame count its header declares (1 where it cannot be read: its fit reports why).
pub fn dealt_to(shard: Shard, paths: &[std::path::PathBuf]) -> Vec<&std::path::PathBuf> {
    let weights: Vec<u64> = paths
        .iter()
        .map(|t| {
            kinergy_motion::kinergy_bvh::header_frame_count(t)
                .ok()
                .flatten()
                .unwrap_or(1) as u64
        })
        .collect();
    paths
        .iter()
        .zip(deal(&weights, shard.count))
        .filter(|(_, s)| *s == shard.index)
        .map(|(t, _)| t)
        .collect()
}

/// The most shards a library is dealt to.
const MAX_SHARDS: usize = 100_000;

/// Deals `weights` (one per take, in the library's order) to `count` shards, heaviest first,
/// each to the lightest shard so far (ties: the lower shard, then the earlier take): every
/// shard gets about the same frames. The same takes and weights deal the same way on every
/// machine. Returns each take's shard, 1-based.
pub fn deal(weights: &[u64], count: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
    let mut load = vec![0u64; count.max(1)];
    let mut shard_of = vec![0; weights.len()];
    for take in order {
        let (lightest, _) = load
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.cmp(b.1).then(a.0.cmp(&b.0)))
            .unwrap_or((0, &0));
        load[lightest] += weights[take].max(1);
        shard_of[take] = lightest + 1;
    }
    shard_of
}

#[cfg(test)]
mod tests {
    use super::{Shard, deal};

    #[test]
    fn shards_parse_and_come_from_slurm() {
        assert_eq!(Shard::parse("2/8"), Ok(Shard { index: 2, count: 8 }));
        for bad in ["0/3", "4/3", "x/3", "3", "1/0", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let env = |vars: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                vars.iter()
                    .find(|(k, _)| *k == name)
                    .map(|(_, v)| (*v).to_string())
            }
        };
        assert_eq!(Shard::from_slurm(env(&[])), Ok(None));
        const ZERO_BASED: [(&str, &str); 3] = [
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        assert_eq!(
            Shard::from_slurm(env(&ZERO_BASED)),
            Ok(Some(Shard { index: 1, count: 3 }))
        );
        const ONE_BASED: [(&str, &str); 3] = [
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        assert_eq!(
            Shard::from_slurm(env(&ONE_BASED)),
            Ok(Some(Shard { index: 3, count: 3 }))
        );
        assert!(Shard::from_slurm(env(&[("SLURM_ARRAY_TASK_ID", "3")])).is_err());
    }

    #[test]
    fn takes_are_dealt_by_weight_to_balanced_shards() {
        let weights = [100, 10, 90, 20, 80, 30, 70, 40, 60, 50];
        let shards = deal(&weights, 3);
        let mut load = [0u64; 3];
        for (w, s) in weights.iter().zip(&shards) {
            load[s - 1] += w;
        }
        let (lo, hi) = (load.iter().min().unwrap(), load.iter().max().unwrap());
        assert!(hi - lo <= 20, "{load:?}");
        assert_eq!(deal(&weights, 3), shards, "deterministic");
        assert!(deal(&weights, 1).iter().all(|&s| s == 1));
        assert_eq!(deal(&[], 4), Vec::<usize>::new());
    }
}
