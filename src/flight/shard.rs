//! A check split into shards that run anywhere and merge into the report
//! one process gives, bit for bit (`skyform fly --shard I/N --json PART`,
//! `skyform merge PART…`).
//!
//! Each flight is already a function of (seed, flight number), so shard I
//! of N flies a contiguous range of flight numbers and writes them, with
//! the mission it flew (as TOML), into its part. The merge checks that the
//! parts are one check's (the same mission, pipeline, seed and flights)
//! and cover every flight once, plans the mission again (plans are seeded:
//! the same plan), and builds the report from the flights in their order,
//! as `check` does. Which machine, scheduler or order ran the shards does
//! not matter; the engine that runs them is the user's (a Slurm array, a
//! Kubernetes Indexed Job, a Ray cluster: docs/flight-check.md).

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::{FlightError, Flown, Options, Setup, fly_range};
use crate::pipelines::{CancelToken, Kind};

/// What a part file says it is.
pub const PART_FORMAT: &str = "skyform flight-check part 1";

/// Shard `index` of `count` (0-based index; written `I/N` on the command
/// line with I from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// `"I/N"`, 0 ≤ I < N.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| format!("'{text}': write the shard as I/N (shard I of N, from 0)"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("'{text}': '{i}' is not a shard number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("'{text}': '{n}' is not a number of shards"))?;
        if count == 0 || index >= count {
            return Err(format!(
                "'{text}': shards are numbered 0 to N - 1 (N at least 1)"
            ));
        }
        Ok(Shard { index, count })
    }

    /// The flight numbers of this shard of `flights`: contiguous, the
    /// shards' ranges in order covering 0..flights once.
    pub fn range(self, flights: usize) -> Range<usize> {
        let at = |i: usize| i * flights / self.count;
        at(self.index)..at(self.index + 1)
    }
}

/// One shard's flights and what they belong to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Part {
    pub format: String,
    /// The mission flown, as TOML (the merge plans it again).
    pub mission: String,
    pub pipeline: Kind,
    pub seed: u64,
    /// Flights of the whole check.
    pub flights: usize,
    pub shard: Shard,
    /// This shard's flights, in flight order.
    pub flown: Vec<Flown>,
}

/// Numbered pieces gathered from parts into their order, each exactly
/// once: a check's flights here, a rare-event estimate's runs
/// (`odds::merge`).
struct Slots<T>(Vec<Option<T>>);

/// Why a piece does not go into its slot.
enum Misfit {
    /// Its number is past the count the first part gave.
    Outside,
    /// Another part holds it already.
    Twice,
}

impl<T> Slots<T> {
    /// `count` empty slots (a count read from a part: checked against its
    /// limit before).
    fn new(count: usize) -> Self {
        Slots(std::iter::repeat_with(|| None).take(count).collect())
    }

    /// Puts piece number `k`.
    fn put(&mut self, k: usize, piece: T) -> Result<(), Misfit> {
        let slot = self.0.get_mut(k).ok_or(Misfit::Outside)?;
        if slot.is_some() {
            return Err(Misfit::Twice);
        }
        *slot = Some(piece);
        Ok(())
    }

    /// Every piece in order, or the number of the first missing.
    fn complete(self) -> Result<Vec<T>, usize> {
        self.0
            .into_iter()
            .enumerate()
            .map(|(k, piece)| piece.ok_or(k))
            .collect()
    }
}

/// Flies shard `shard` of the check `options` of `setup`: its part.
pub fn fly_shard(
    setup: &Setup,
    mission_toml: String,
    pipeline: Kind,
    options: Options,
    shard: Shard,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Part, FlightError> {
    // A shard is one process's work: the budget bounds its own flights.
    let range = shard.range(options.flights);
    setup.within_budget(range.len())?;
    let flown = fly_range(setup, options, range, false, progress, cancel)?;
    Ok(Part {
        format: PART_FORMAT.to_owned(),
        mission: mission_toml,
        pipeline,
        seed: options.seed,
        flights: options.flights,
        shard,
        flown,
    })
}

/// What a kind of part is called in a merge's errors, and its limit: a
/// check's flights, a rare-event estimate's runs.
#[derive(Debug, PartialEq, Eq)]
pub struct PartWords {
    /// `flight-check` (its format's words).
    pub kind: &'static str,
    /// What the parts are parts of: `check`.
    pub whole: &'static str,
    /// One numbered piece of it: `flight`.
    pub piece: &'static str,
    /// The field that counts the pieces, as a mismatch names it.
    pub count: &'static str,
    /// The command whose shards merge: `skyform fly --shard`.
    pub command: &'static str,
    /// Most pieces a whole may have.
    pub most: usize,
}

/// Why parts do not merge, in the words of their kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.words())]
pub struct MergeError {
    pub kind: &'static PartWords,
    pub why: Misjoin,
}

/// What is wrong with the parts handed to a merge.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Misjoin {
    Empty,
    /// Part `.0` (from 1) is of format `.1`.
    Format(usize, String),
    /// Part `part` differs from the first in `what`.
    Mismatch {
        part: usize,
        what: &'static str,
    },
    /// The first part counts this many pieces, over the limit.
    TooMany(usize),
    /// Piece `.0` is in no part.
    Missing(usize),
    /// Piece `.0` is in two parts.
    Twice(usize),
}

impl MergeError {
    fn words(&self) -> String {
        let PartWords {
            kind,
            whole,
            piece,
            command,
            most,
            ..
        } = self.kind;
        match &self.why {
            Misjoin::Empty => "no part to merge".to_owned(),
            Misjoin::Format(part, format) => {
                format!("part {part}: not a skyform {kind} part (format '{format}')")
            }
            Misjoin::Mismatch { part, what } => format!(
                "part {part} is of another {whole} than part 1: its {what} differs \
                 (merge the parts of one `{command}` run)"
            ),
            Misjoin::TooMany(n) => {
                format!("part 1 says the {whole} has {n} {piece}s, over the limit of {most}")
            }
            Misjoin::Missing(k) => format!("{piece} {k} is in no part: a shard is missing"),
            Misjoin::Twice(k) => format!("{piece} {k} is in two parts: a shard is given twice"),
        }
    }
}

/// A part of a sharded whole, as [`merge_parts`] reads it.
pub(super) trait Sharded: Clone {
    type Piece;
    /// Its kind's words and limit.
    const WORDS: &'static PartWords;
    /// The format it says it is; [`Sharded::FORMAT`] when it is one.
    const FORMAT: &'static str;
    fn format(&self) -> &str;
    /// How many pieces the whole has.
    fn count(&self) -> usize;
    /// What makes it another whole's than `first`, in a word.
    fn differs(&self, first: &Self) -> Option<&'static str>;
    /// Its pieces, each with its number, taken out of it.
    fn take(&mut self) -> Vec<(usize, Self::Piece)>;
}

/// Every piece of `parts` in order, checked to be one whole's and to hold
/// every piece once; and the first part, emptied. Parts are numbered from 1
/// in errors, in the order given.
pub(super) fn merge_parts<P: Sharded>(parts: Vec<P>) -> Result<(P, Vec<P::Piece>), MergeError> {
    let refuse = |why| MergeError {
        kind: P::WORDS,
        why,
    };
    let mut first = parts.first().cloned().ok_or(refuse(Misjoin::Empty))?;
    // A part is a file anyone may hand in: its count is checked before it
    // sizes anything.
    if first.count() > P::WORDS.most {
        return Err(refuse(Misjoin::TooMany(first.count())));
    }
    let mut slots = Slots::new(first.count());
    for (i, mut part) in parts.into_iter().enumerate() {
        if part.format() != P::FORMAT {
            return Err(refuse(Misjoin::Format(i + 1, part.format().to_owned())));
        }
        if let Some(what) = part.differs(&first) {
            return Err(refuse(Misjoin::Mismatch { part: i + 1, what }));
        }
        for (k, piece) in part.take() {
            slots.put(k, piece).map_err(|misfit| {
                refuse(match misfit {
                    Misfit::Outside => Misjoin::Mismatch {
                        part: i + 1,
                        what: P::WORDS.count,
                    },
                    Misfit::Twice => Misjoin::Twice(k),
                })
            })?;
        }
    }
    let pieces = slots.complete().map_err(|k| refuse(Misjoin::Missing(k)))?;
    first.take();
    Ok((first, pieces))
}

/// A check's parts: its flights.
static CHECK_PARTS: PartWords = PartWords {
    kind: "flight-check",
    whole: "check",
    piece: "flight",
    count: "number of flights",
    command: "skyform fly --shard",
    most: crate::mission::MAX_FLIGHTS,
};

impl Sharded for Part {
    type Piece = Flown;
    const WORDS: &'static PartWords = &CHECK_PARTS;
    const FORMAT: &'static str = PART_FORMAT;

    fn format(&self) -> &str {
        &self.format
    }

    fn count(&self) -> usize {
        self.flights
    }

    fn differs(&self, first: &Self) -> Option<&'static str> {
        [
            ("mission", self.mission != first.mission),
            ("pipeline", self.pipeline != first.pipeline),
            ("seed", self.seed != first.seed),
            ("number of flights", self.flights != first.flights),
        ]
        .into_iter()
        .find_map(|(what, differs)| differs.then_some(what))
    }

    fn take(&mut self) -> Vec<(usize, Flown)> {
        std::mem::take(&mut self.flown)
            .into_iter()
            .map(|f| (f.flight, f))
            .collect()
    }
}

/// The flights of `parts`, checked to be one check's and complete, in
/// flight order; and the first part (its mission, pipeline, seed,
/// flights). Parts are numbered from 1 in errors, in the order given.
pub fn merge(parts: Vec<Part>) -> Result<(Part, Vec<Flown>), MergeError> {
    merge_parts(parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_every_flight_once_in_order() {
        for flights in [0, 1, 7, 1000, 1001] {
            for count in 1..=9 {
                let mut next = 0;
                for index in 0..count {
                    let r = Shard { index, count }.range(flights);
                    assert_eq!(r.start, next, "{flights} flights, shard {index}/{count}");
                    next = r.end;
                }
                assert_eq!(next, flights);
            }
        }
    }

    #[test]
    fn a_shard_is_written_i_of_n_from_zero() {
        assert_eq!(Shard::parse("2/4"), Ok(Shard { index: 2, count: 4 }));
        for bad in ["4/4", "1/0", "x/4", "3", "-1/4"] {
            let e = Shard::parse(bad).expect_err(bad);
            assert!(e.contains(bad), "{e}");
        }
    }
}
