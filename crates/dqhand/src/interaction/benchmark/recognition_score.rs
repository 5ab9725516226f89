//! Gesture events scored against the labels of a sequence: was each held gesture recognised
//! within [`RECOGNITION_DEADLINE_S`] of its pose being reached, how long it took, what was
//! shown instead when it was not (the confusion matrix), and every start of a wrong gesture,
//! in moves, holds and idle motion alike (the spurious starts; each is a command the user did
//! not give). A hold labelled `none` (a pose that is no gesture) is recognised when nothing is
//! shown at its deadline; a label `a|b` accepts either (`none|open_palm`: a relaxed hand whose
//! fingers are straight).

use serde::{Deserialize, Serialize};

use crate::gesture::{Event, EventKind};
use crate::interaction::synthetic::Label;

/// Seconds after a pose is reached by which its gesture must have started (the gesture loop's target: 150 ms).
pub const RECOGNITION_DEADLINE_S: f64 = 0.15;

/// The label of a held pose that is no gesture.
pub const NO_GESTURE: &str = "none";

/// Slack on the deadline: label and record times are sums of decimal seconds, and a rounding
/// error of a nanosecond does not make a start late.
const TIME_ROUNDING_S: f64 = 1e-9;

/// A gesture event kept beyond the update that reported it; reads and writes the JSON of
/// [`Event`] (`{"t": 1.25, "event": "start", "gesture": "fist"}`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoggedEvent {
    /// Time of the update that reported it, seconds.
    pub t: f64,
    /// Start or end.
    pub event: EventKind,
    /// The gesture's name.
    pub gesture: String,
}

impl From<Event<'_>> for LoggedEvent {
    fn from(e: Event<'_>) -> Self {
        Self { t: e.t, event: e.event, gesture: e.gesture.to_owned() }
    }
}

/// What became of one labelled hold.
#[derive(Clone, Debug, PartialEq)]
pub struct HoldOutcome {
    /// The gesture held.
    pub gesture: String,
    /// When its pose was reached, seconds.
    pub reached: f64,
    /// Seconds from the pose being reached to the start event of its gesture: when the
    /// gesture is shown at the deadline, the start that made it current (negative when
    /// recognised during the move); otherwise the first start after the deadline and before
    /// the hold ended (late); `None` when neither.
    pub latency_s: Option<f64>,
    /// The gesture current at the deadline by the events, `None` for none: what was shown
    /// instead when it is not the hold's.
    pub shown_at_deadline: Option<String>,
}

impl HoldOutcome {
    /// Whether the gesture started by the deadline and is still shown then (a start that
    /// flickered off, or one replaced by another gesture, is not a recognition).
    #[must_use]
    pub fn in_time(&self) -> bool {
        if self.gesture.contains('|') || self.gesture == NO_GESTURE {
            return accepts(&self.gesture, self.shown_at_deadline.as_deref().unwrap_or(NO_GESTURE));
        }
        self.shown_at_deadline.as_deref() == Some(self.gesture.as_str()) && self.latency_s.is_some_and(|l| l <= RECOGNITION_DEADLINE_S + TIME_ROUNDING_S)
    }
}

/// One sequence's events scored against its labels.
#[derive(Clone, Debug, PartialEq)]
pub struct RecognitionScore {
    /// Each hold, in label order.
    pub holds: Vec<HoldOutcome>,
    /// Every start: the gesture, and whether it was right (during the move to or the hold of
    /// a label of that gesture).
    pub starts: Vec<(String, bool)>,
    /// Starts that were not right, anywhere in the sequence.
    pub spurious: usize,
    /// Seconds of idle motion.
    pub idle_s: f64,
    /// Seconds of the whole sequence (moves, holds, idle): the time spurious starts are
    /// counted over.
    pub seconds: f64,
}

impl RecognitionScore {
    /// Scores `events` (in time order) against the `labels` of a sequence (in time order; a
    /// hold's move begins where the previous hold ends) and its idle stretch `idle` (seconds
    /// from, to: from when the hand has settled into idle motion).
    #[must_use]
    pub fn new(labels: &[Label], idle: (f64, f64), events: &[LoggedEvent]) -> Self {
        let mut holds = Vec::with_capacity(labels.len());
        for label in labels {
            let deadline = label.reached + RECOGNITION_DEADLINE_S + TIME_ROUNDING_S;
            let shown = current_at(events, deadline);
            let starts = |e: &&LoggedEvent| e.event == EventKind::Start && e.gesture == label.gesture;
            let start = if shown == Some(label.gesture.as_str()) {
                events.iter().filter(starts).take_while(|e| e.t <= deadline).last()
            } else {
                events.iter().filter(starts).find(|e| e.t > deadline && e.t <= label.until)
            };
            holds.push(HoldOutcome {
                gesture: label.gesture.clone(),
                reached: label.reached,
                latency_s: start.map(|e| e.t - label.reached),
                shown_at_deadline: shown.map(str::to_owned),
            });
        }
        let starts: Vec<(String, bool)> = events
            .iter()
            .filter(|e| e.event == EventKind::Start)
            .map(|e| {
                // The label whose move or hold the start falls in: moves begin where the
                // previous hold ends.
                let label = labels.iter().find(|l| e.t <= l.until);
                (e.gesture.clone(), label.is_some_and(|l| accepts(&l.gesture, &e.gesture)))
            })
            .collect();
        let spurious = starts.iter().filter(|(_, right)| !right).count();
        Self { holds, starts, spurious, idle_s: idle.1 - idle.0, seconds: idle.1.max(labels.last().map_or(0.0, |l| l.until)) }
    }

    /// Holds whose gesture started by the deadline.
    #[must_use]
    pub fn in_time(&self) -> usize {
        self.holds.iter().filter(|h| h.in_time()).count()
    }
}

/// Whether a label (`a` or `a|b`) accepts `gesture` (`none` for nothing shown).
fn accepts(label: &str, gesture: &str) -> bool {
    label.split('|').any(|g| g == gesture)
}

/// The gesture current after the events up to `time`.
fn current_at(events: &[LoggedEvent], time: f64) -> Option<&str> {
    let mut current = None;
    for e in events.iter().take_while(|e| e.t <= time) {
        match e.event {
            EventKind::Start => current = Some(e.gesture.as_str()),
            EventKind::End if current == Some(e.gesture.as_str()) => current = None,
            EventKind::End => {}
        }
    }
    current
}
