//! Why a record was refused, and the tally of refusals a stream reports at its end.
//!
//! A bad record never stops a stream: it is counted under its kind and the stream goes on;
//! the summary says, one line per kind, how many and what the first one was.

use core::fmt;

/// The kinds of bad record, one line each in a [`Rejections`] summary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RejectKind {
    /// Not parseable: truncated line, bad JSON, a value that is not a number.
    Malformed,
    /// A CSV row with another number of columns than its header.
    ColumnCount,
    /// A joint or sensor name the format does not have.
    UnknownName,
    /// A value that is NaN or infinite.
    NonFinite,
    /// A value outside its range (glove sensor outside 0–4095, quaternion not unit, time < 0).
    OutOfRange,
    /// A record whose time is not after the previous good record's.
    OutOfOrder,
    /// A live record that arrived later after its capture time than the stream allows.
    Late,
    /// Records arriving faster than the stream accepts (a flood).
    Flood,
    /// A message larger than the stream accepts.
    TooLarge,
    /// A record whose geometry cannot be a hand (coincident joints, degenerate palm).
    Unusable,
}

impl RejectKind {
    /// Every kind, in summary order.
    pub const ALL: [RejectKind; 10] = [
        RejectKind::Malformed,
        RejectKind::ColumnCount,
        RejectKind::UnknownName,
        RejectKind::NonFinite,
        RejectKind::OutOfRange,
        RejectKind::OutOfOrder,
        RejectKind::Late,
        RejectKind::Flood,
        RejectKind::TooLarge,
        RejectKind::Unusable,
    ];

    /// Short name for summaries: `malformed`, `column count`, ….
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            RejectKind::Malformed => "malformed",
            RejectKind::ColumnCount => "wrong column count",
            RejectKind::UnknownName => "unknown name",
            RejectKind::NonFinite => "not finite",
            RejectKind::OutOfRange => "out of range",
            RejectKind::OutOfOrder => "out of order",
            RejectKind::Late => "late",
            RejectKind::Flood => "flood",
            RejectKind::TooLarge => "too large",
            RejectKind::Unusable => "unusable",
        }
    }
}

impl fmt::Display for RejectKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One refused record: its kind and a one-line message that starts with where it was
/// (`line 12: …`, `datagram from 127.0.0.1:5000: …`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rejection {
    /// What kind of problem.
    pub kind: RejectKind,
    /// The message.
    pub message: String,
}

impl Rejection {
    /// A rejection of `kind` with `message`.
    pub fn new(kind: RejectKind, message: impl Into<String>) -> Self {
        Self { kind, message: message.into() }
    }

    /// The same rejection with `place` (`"line 12"`) in front of its message.
    #[must_use]
    pub fn at(self, place: impl fmt::Display) -> Self {
        Self { kind: self.kind, message: format!("{place}: {}", self.message) }
    }
}

impl fmt::Display for Rejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Rejection {}

/// Counts of refused records per kind, with the first message of each.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rejections {
    counts: [u64; RejectKind::ALL.len()],
    first: [Option<String>; RejectKind::ALL.len()],
}

impl Rejections {
    /// Counts `rejection` (keeps its message if it is the first of its kind).
    pub fn add(&mut self, rejection: Rejection) {
        let i = rejection.kind as usize;
        self.counts[i] += 1;
        self.first[i].get_or_insert(rejection.message);
    }

    /// Records refused for `kind`.
    #[must_use]
    pub fn count(&self, kind: RejectKind) -> u64 {
        self.counts[kind as usize]
    }

    /// Records refused in all.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// One line per kind that occurred: `12 records rejected (out of range), first: line 40: …`.
    pub fn summary(&self) -> impl Iterator<Item = String> + '_ {
        RejectKind::ALL.into_iter().filter(|k| self.count(*k) > 0).map(|k| {
            let n = self.count(k);
            let first = self.first[k as usize].as_deref().unwrap_or("");
            format!("{n} record{} rejected ({k}), first: {first}", if n == 1 { "" } else { "s" })
        })
    }
}
