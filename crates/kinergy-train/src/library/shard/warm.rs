//! Warm starts (`fit --warm-start`): the groups of a shard's reaches, their anchors found and
//! fitted (see the [library's documentation](crate::library#warm-starts)).

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::Ordering;
use std::time::Instant;

use rayon::prelude::*;

use super::{ShardPlan, ShardRun, TakeError};
use crate::CapturedReach;
use crate::error::TrainError;
use crate::fit::NestedFit;
use crate::library::identity::slash_path;
use crate::library::table::LibraryError;
use crate::source::Skipped;
use crate::who::{TakeAt, Who};

/// A take read: its reaches, each with the person a segments file lists for it, or why it has
/// none to fit.
pub(super) type ReadTake = Result<Result<Vec<(CapturedReach, Option<String>)>, Skipped>, TakeError>;

/// The reaches fitted from one anchor: one person and motion, one arm with the same DoFs.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(super) struct Group {
    person: String,
    motion: Option<String>,
    arm: String,
    dofs: Vec<String>,
}

impl Group {
    /// The group of `reach`, moved by `who`.
    pub(super) fn of(who: &Who, reach: &CapturedReach) -> Group {
        Group {
            person: who.person.clone(),
            motion: who.motion.clone(),
            arm: reach
                .fitted_arm()
                .side
                .map_or_else(String::new, |s| s.to_string()),
            dofs: reach.dof_names(),
        }
    }

    /// Whether a take moved by `who` can hold reaches of this group.
    fn may_hold(&self, who: &Who) -> bool {
        self.person == who.person && self.motion == who.motion
    }
}

/// A group's first reach in the library's order, and its fit.
pub(super) struct Anchor {
    /// Its take (an index into the library's takes).
    pub(super) take: usize,
    /// Its place among the take's reaches.
    pub(super) reach: usize,
    /// Its result's name in the library folder.
    pub(super) result: String,
    /// Its fit, every model nested.
    pub(super) fit: NestedFit,
    /// The seconds its fit took.
    pub(super) seconds: f64,
}

impl Anchor {
    /// The vector the group's other reaches start from: the anchor's of the model asked for.
    pub(super) fn start(&self) -> &[f64] {
        self.fit.fits.last().map_or(&[], |f| f.values.as_slice())
    }
}

/// The anchors of the groups of a shard's reaches.
pub(super) struct WarmStarts {
    anchors: HashMap<Group, Anchor>,
}

impl WarmStarts {
    /// The anchor of `group`, if the shard has reaches of it to fit.
    pub(super) fn anchor(&self, group: &Group) -> Option<&Anchor> {
        self.anchors.get(group)
    }
}

/// Why the warm starts could not be made: the library's own files, or a take (its reading,
/// its person, or its anchor's fit).
pub(super) enum WarmError {
    Library(LibraryError),
    Take(Box<(PathBuf, TrainError)>),
}

/// The shard's takes read, by their index in the library, each taken once by its fit.
pub(super) type ReadTakes = HashMap<usize, Mutex<Option<ReadTake>>>;

impl ShardRun<'_> {
    /// Reads the shard's takes, finds the anchors of the groups of their reaches still to be
    /// fitted, and fits them (in parallel).
    pub(super) fn warm_starts(
        &self,
        plan: &ShardPlan,
    ) -> Result<(ReadTakes, WarmStarts), WarmError> {
        let read: Vec<(usize, ReadTake)> = plan
            .mine
            .par_iter()
            .map(|&i| (i, self.read_take(i)))
            .collect();
        // The groups with a reach still to fit (the others' reaches fail in their take).
        let mut left: HashSet<Group> = HashSet::new();
        for (i, taken) in &read {
            let Ok(Ok(found)) = taken else { continue };
            let (at, clip) = self.at(plan, *i);
            for ((reach, listed), name) in found.iter().zip(self.names(*i, found)) {
                let Ok(who) = self.person.who(at, listed.as_deref()) else {
                    continue;
                };
                if self
                    .found_fitted_reach(plan, clip, reach, &who, &name)
                    .is_none()
                {
                    left.insert(Group::of(&who, reach));
                }
            }
        }
        // Each group's first reach in the library's order.
        let mut read: HashMap<usize, ReadTake> = read.into_iter().collect();
        let mut anchors: Vec<(Group, usize, usize, CapturedReach, String)> = Vec::new();
        for i in 0..self.takes.paths.len() {
            if left.is_empty() || self.interrupt.load(Ordering::SeqCst) {
                break;
            }
            let take = self.takes.paths[i].as_path();
            let (at, _) = self.at(plan, i);
            if self.takes.rows_of(take).is_none()
                && let Ok(who) = self.person.who(at, None)
                && !left.iter().any(|g| g.may_hold(&who))
            {
                continue;
            }
            // Another shard's take is read here; this shard's were read above.
            let other = (!read.contains_key(&i)).then(|| self.read_take(i));
            if matches!(other.as_ref().or_else(|| read.get(&i)), Some(Err(_))) {
                // An unreadable take before the anchor: the shard fails on it, as its own
                // shard does (a later fix of the take would change the anchor).
                let own = other.is_none();
                if let Some(Err(e)) = other.or_else(|| read.remove(&i)) {
                    return Err(self.take_failed(i, e, own));
                }
                continue;
            }
            let taken = match &other {
                Some(taken) => taken,
                None => match read.get(&i) {
                    Some(taken) => taken,
                    None => continue,
                },
            };
            let found = match taken {
                Ok(Ok(found)) => found,
                _ => continue,
            };
            for (j, ((reach, listed), name)) in found.iter().zip(self.names(i, found)).enumerate() {
                let who = self
                    .person
                    .who(at, listed.as_deref())
                    .map_err(|e| WarmError::Library(e.into()))?;
                let group = Group::of(&who, reach);
                if left.remove(&group) {
                    anchors.push((group, i, j, reach.clone(), slash_path(&name)));
                }
            }
        }
        let fits: Vec<(Result<NestedFit, TrainError>, f64)> = anchors
            .par_iter()
            .map(|(_, _, _, reach, _)| {
                let clock = Instant::now();
                let mut observer = (self.observer)();
                let fit = self.job.run_stoppable(
                    std::slice::from_ref(reach),
                    &mut *observer,
                    Some(self.interrupt),
                );
                (fit, clock.elapsed().as_secs_f64())
            })
            .collect();
        let mut made = HashMap::with_capacity(anchors.len());
        for ((group, take, reach, _, result), (fit, seconds)) in anchors.into_iter().zip(fits) {
            let fit =
                fit.map_err(|e| WarmError::Take(Box::new((self.takes.paths[take].clone(), e))))?;
            made.insert(
                group,
                Anchor {
                    take,
                    reach,
                    result,
                    fit,
                    seconds,
                },
            );
        }
        let read = read
            .into_iter()
            .map(|(i, taken)| (i, Mutex::new(Some(taken))))
            .collect();
        Ok((read, WarmStarts { anchors: made }))
    }

    /// Take `i` as the person rule sees it, and its name in the library.
    fn at<'s>(&'s self, plan: &'s ShardPlan, i: usize) -> (TakeAt<'s>, &'s str) {
        let clip = plan.identities[i].path.as_str();
        (TakeAt::new(&self.takes.common, Path::new(clip)), clip)
    }

    /// Take `i` could not be read: its error, as is where it is the shard's `own` take (its
    /// fit would fail on it the same way), else naming why another shard's take was read.
    fn take_failed(&self, i: usize, e: TakeError, own: bool) -> WarmError {
        let take = self.takes.paths[i].clone();
        let why = "read to find the warm start of this shard's reaches of its person";
        match e {
            TakeError::Library(e) if own => WarmError::Library(e),
            TakeError::Take(e) if own => WarmError::Take(Box::new((take, e))),
            TakeError::Library(e) => WarmError::Library(LibraryError::Input {
                path: take,
                why: format!("{why}: {e}"),
            }),
            TakeError::Take(e) => WarmError::Take(Box::new((
                take.clone(),
                TrainError::Reach {
                    clip: take.display().to_string(),
                    why: format!("{why}: {e}"),
                },
            ))),
        }
    }
}
