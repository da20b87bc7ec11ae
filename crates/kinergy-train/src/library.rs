//! A library of captures shared among machines: which takes a shard fits, what its record
//! says, and the library's tables.
//!
//! A library's takes are dealt to shards by weight (their frame counts), the same way on
//! every machine, so that shards run anywhere — a Slurm array's tasks, or `--shard I/N` by
//! hand — fit disjoint shares that together are the library. Each shard records the
//! library's takes ([`TakeIdentity`]: path from the root, size, hash, frames), its
//! [`Settings`] and each result's hash ([`ShardHeader`], [`RecordRow`]); [`collect`] checks the shards' records against each
//! other, the takes and the result files, and writes the library's tables ([`LibraryRow`]:
//! `library.csv`, written and read by one type). Each reach's person and motion are named by
//! the library's person rule ([`crate::who`]), one of its settings.
//!
//! ## Warm starts
//!
//! With [`ShardRun::warm_start`] (`fit --warm-start`), a library of a person's repeats is
//! fitted from each gesture's first take.
//!
//! The reaches of one *group* — one person and motion as the library's person rule names
//! them ([`crate::who`]), one arm with the same DoFs — are fitted from the fit of the group's
//! first reach in the library's order (its *anchor*, fitted as without warm starts: every
//! model, nested). Each other reach of the group anneals the model asked for alone, from the
//! anchor's vector of that model; its parameters file records the anchor's result
//! (`fit.started_from`). Where a person repeats a gesture, the anchor's vector is near each
//! repeat's own and the poorer models' stages are not needed: on the shared people's raises
//! the library takes about a third of the evaluations at a like distance (BENCHMARKS.md,
//! "Warm starts"). Where a person's reaches go to different targets in different ways, it
//! is a poorer start than the nested models' and the fits are worse: warm starts are off by
//! default.
//!
//! **Shards.** Every shard that holds a reach of a group finds the group's anchor among all
//! the library's takes and fits it itself (the anchor's fit depends on its reach and the
//! settings only, so it is the same in every shard); it writes the anchor's result only where
//! the anchor is one of its own takes. A result so depends on its reach, its anchor and the
//! settings — never on the shards or the threads. A group's anchor is looked for among the
//! takes whose paths can be its person's and motion's, in order, until one holds a reach of
//! the group: an unreadable take on the way fails the shard, as it would fail its own.

mod collect;
mod identity;
pub(crate) mod names;
mod record;
mod shard;
mod table;

pub use collect::{Collected, collect, collect_with};
pub use identity::{Settings, TakeIdentity, hash_bytes, hash_file, takes_changes};
pub use names::{
    Takes, common_folder, names_of, relative_name, result_names, take_names, unique_takes,
};
pub use record::{
    COLUMNS, COLUMNS_WITHOUT_MOTION, FORMAT, RecordFile, RecordRow, ShardHeader, TakesList,
    header_path, parse_record_name, read_header, read_record, record_path,
};
pub use shard::{ShardEvent, ShardOutcome, ShardPlan, ShardRun};
pub use table::{
    LIBRARY, LibraryError, LibraryRow, LibraryTable, MotionLine, PersonLine, SHARDS, SKIPPED,
    SkippedRow, write_csv,
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
        let bad = || {
            format!("`{text}`: expected I/N, whole numbers with 1 ≤ I ≤ N ≤ {MAX_SHARDS}, e.g. 2/8")
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index = bounded(i.trim()).ok_or_else(bad)?;
        let count = bounded(n.trim()).ok_or_else(bad)?;
        if index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The shard a Slurm array task is: task `SLURM_ARRAY_TASK_ID` of the array's
    /// `SLURM_ARRAY_TASK_COUNT`, counted from `SLURM_ARRAY_TASK_MIN` (so `--array=0-7` and
    /// `--array=1-8` both make 8 shards). `None` outside an array job. Every variable is a
    /// whole number within bounds — the count at most 100,000 as `--shard`'s, the ID and
    /// the minimum at most [`MAX_TASK_ID`] — or the error names it.
    pub fn from_slurm_env() -> Result<Option<Shard>, String> {
        // Read as bytes: a value that is not UTF-8 is set, and refused by name (read with
        // `std::env::var` it looked unset, and the task fitted the whole library).
        Shard::from_slurm(|name| std::env::var_os(name).map(|v| v.to_string_lossy().into_owned()))
    }

    /// [`Shard::from_slurm_env`] with the variables from `env` (a test's, or the process's).
    pub fn from_slurm(env: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>, String> {
        const ID: &str = "SLURM_ARRAY_TASK_ID";
        const MIN: &str = "SLURM_ARRAY_TASK_MIN";
        const COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
        let Some(id) = env(ID) else {
            return Ok(None);
        };
        let number = |name: &str, text: String, low: usize, high: usize| {
            text.trim()
                .parse::<usize>()
                .ok()
                .filter(|n| (low..=high).contains(n))
                .ok_or_else(|| {
                    format!(
                        "{name}=`{}` is not a whole number from {low} to {high}",
                        kinergy_io::clip_text(&text, 40)
                    )
                })
        };
        let set = |name: &str| {
            env(name).ok_or_else(|| format!("{ID} is set but {name} is not: is this an array job?"))
        };
        let id = number(ID, id, 0, MAX_TASK_ID)?;
        let min = number(MIN, set(MIN)?, 0, MAX_TASK_ID)?;
        let count = number(COUNT, set(COUNT)?, 1, MAX_SHARDS)?;
        let index = id
            .checked_sub(min)
            .map(|k| k + 1)
            .filter(|&i| i <= count)
            .ok_or_else(|| {
                format!(
                    "{ID}={id} is outside the array (from {min}, {count} tasks): use a \
                     contiguous --array=A-B, or --shard I/N"
                )
            })?;
        Ok(Some(Shard { index, count }))
    }
}

/// `text` as a whole number from 1 to [`MAX_SHARDS`] (digits only): a shard's index or
/// count as `--shard` gives it.
fn bounded(text: &str) -> Option<usize> {
    let digits = !text.is_empty() && text.len() <= 20 && text.bytes().all(|b| b.is_ascii_digit());
    digits
        .then(|| text.parse().ok())
        .flatten()
        .filter(|n| (1..=MAX_SHARDS).contains(n))
}

/// `text` as a record's name spells a shard's index or count: [`bounded`], without a
/// leading zero (so that one shard has one name).
pub(crate) fn bounded_plain(text: &str) -> Option<usize> {
    bounded(text).filter(|_| !text.starts_with('0'))
}

/// The most shards a library is dealt to (`--shard`, Slurm's task count, a record's name).
pub const MAX_SHARDS: usize = 100_000;

/// The largest Slurm array task ID or minimum read (Slurm's own `MaxArraySize` is at most
/// 4,000,001).
pub const MAX_TASK_ID: usize = 4_000_000;

/// Deals `weights` (one per take, in the library's order) to `count` shards, heaviest first,
/// each to the lightest shard so far (ties: the lower shard, then the earlier take): every
/// shard gets about the same frames. The same takes and weights deal the same way on every
/// machine. Returns each take's shard, 1-based. Only the first `weights.len()` shards can be
/// dealt a take (each take goes to an empty shard while there is one), so nothing is
/// allocated per shard beyond the takes, whatever `count` is.
pub fn deal(weights: &[u64], count: usize) -> Vec<usize> {
    use std::cmp::Reverse;
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
    let used = count.clamp(1, weights.len().max(1));
    // The lightest shard, the lowest of equal loads, on top.
    let mut loads: std::collections::BinaryHeap<Reverse<(u64, usize)>> =
        (0..used).map(|s| Reverse((0, s))).collect();
    let mut shard_of = vec![0; weights.len()];
    for take in order {
        let Some(Reverse((load, lightest))) = loads.pop() else {
            break;
        };
        loads.push(Reverse((
            load.saturating_add(weights[take].max(1)),
            lightest,
        )));
        shard_of[take] = lightest + 1;
    }
    shard_of
}

#[cfg(test)]
mod tests {
    use super::{MAX_SHARDS, Shard, deal};
    use proptest::prelude::*;

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

    /// The sweep's Slurm variables: 2^63 ("capacity overflow"), 1e10 (an 80 GB allocation),
    /// one above the limit — each refused, naming the variable, before anything is dealt.
    #[test]
    fn absurd_slurm_variables_are_refused_naming_the_variable() {
        let slurm = |id: &str, min: &str, count: &str| {
            let vars = [
                ("SLURM_ARRAY_TASK_ID", id.to_string()),
                ("SLURM_ARRAY_TASK_MIN", min.to_string()),
                ("SLURM_ARRAY_TASK_COUNT", count.to_string()),
            ];
            Shard::from_slurm(move |name: &str| {
                vars.iter()
                    .find(|(k, _)| *k == name)
                    .map(|(_, v)| v.clone())
            })
        };
        for count in [
            "9223372036854775808",
            "1e10",
            "10000000000",
            "100001",
            "0",
            "-1",
            "x",
        ] {
            let e = slurm("1", "1", count).unwrap_err();
            assert_eq!(
                e,
                format!("SLURM_ARRAY_TASK_COUNT=`{count}` is not a whole number from 1 to 100000")
            );
        }
        assert_eq!(
            slurm("1", "1", "100000"),
            Ok(Some(Shard {
                index: 1,
                count: MAX_SHARDS
            }))
        );
        let e = slurm("18446744073709551616", "0", "4").unwrap_err();
        assert!(
            e.starts_with("SLURM_ARRAY_TASK_ID=`18446744073709551616`"),
            "{e}"
        );
        let e = slurm("5", "99999999999", "4").unwrap_err();
        assert!(e.starts_with("SLURM_ARRAY_TASK_MIN="), "{e}");
        assert!(
            slurm("9", "1", "4")
                .unwrap_err()
                .contains("outside the array")
        );
        // --shard has the same bound.
        assert!(Shard::parse("1/100001").unwrap_err().contains("≤ 100000"));
        assert!(Shard::parse("1/9223372036854775808").is_err());
        assert_eq!(
            Shard::parse("1/100000"),
            Ok(Shard {
                index: 1,
                count: 100_000
            })
        );
        assert_eq!(Shard::parse("02/8"), Ok(Shard { index: 2, count: 8 }));
    }

    /// The deal as it was first written: one load per shard, the lightest found by a scan.
    fn deal_by_scan(weights: &[u64], count: usize) -> Vec<usize> {
        let mut order: Vec<usize> = (0..weights.len()).collect();
        order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
        let mut load = vec![0u64; count.max(1)];
        let mut shard_of = vec![0; weights.len()];
        for take in order {
            let (lightest, _) = load
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.cmp(b.1).then(a.0.cmp(&b.0)))
                .unwrap();
            load[lightest] += weights[take].max(1);
            shard_of[take] = lightest + 1;
        }
        shard_of
    }

    proptest! {
        /// The deal allocates per take, not per shard, and deals as the scan over every
        /// shard did (libraries already sharded keep their shares).
        #[test]
        fn the_deal_is_the_scan_s_without_a_load_per_shard(
            weights in prop::collection::vec(0u64..500, 0..40),
            count in 1usize..60,
        ) {
            prop_assert_eq!(deal(&weights, count), deal_by_scan(&weights, count));
        }
    }

    #[test]
    fn a_huge_shard_count_deals_each_take_to_its_own_shard_at_once() {
        let weights = [5, 50, 20];
        assert_eq!(deal(&weights, usize::MAX), [3, 1, 2]);
        assert_eq!(deal(&weights, MAX_SHARDS), [3, 1, 2]);
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
