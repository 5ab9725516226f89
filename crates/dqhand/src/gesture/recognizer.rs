//! The gesture recogniser: turns a stream of [`HandFeatures`] into start and end events of
//! one current gesture, without flicker on noisy tracking.
//!
//! Two mechanisms keep it stable:
//! * hysteresis: a gesture starts only when every condition passes its strict threshold,
//!   and once it is current (or waiting to become current) it holds on the relaxed ones
//!   ([`Condition`](super::Condition)), so a feature trembling around a threshold does not
//!   toggle it;
//! * minimum time in state: a change (another gesture, or none) is reported only once it
//!   has lasted [`GestureSet::min_hold_s`] without interruption, so a pose passed through on
//!   the way to another, or a dropout of a few frames, produces no event.
//!
//! Latency: a start or end is reported at the first update at least `min_hold_s` after the
//! change was first seen, i.e. `min_hold_s` plus up to one frame (0.1 s + 11 ms at 90 Hz with
//! the built-in set); the events carry that update's time.

use serde::{Deserialize, Serialize};

use super::{ClassifierScratch, GestureSet, HandFeatures};

/// Whether a gesture started or ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EventKind {
    /// The gesture became current.
    Start,
    /// The gesture stopped being current.
    End,
}

/// A gesture starting or ending; serialises as `{"t": 1.25, "event": "start", "gesture": "fist"}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Event<'a> {
    /// Time of the update that reported it, seconds (the clock of [`Recognizer::update`]).
    pub t: f64,
    /// Start or end.
    pub event: EventKind,
    /// The gesture's name.
    pub gesture: &'a str,
    /// The gesture's index in the recogniser's [`GestureSet`]: its identity, which tables of
    /// commands and logs keep (the name is that gesture's, for people).
    #[serde(skip)]
    pub index: usize,
}

/// The events of one update: none, one, or an end followed by a start. Allocates nothing.
#[derive(Clone, Debug)]
pub struct Events<'a> {
    slots: [Option<Event<'a>>; 2],
    next: usize,
}

impl Events<'_> {
    /// No event (recognition off).
    #[must_use]
    pub fn none() -> Self {
        Self { slots: [None, None], next: 0 }
    }
}

impl<'a> Iterator for Events<'a> {
    type Item = Event<'a>;

    fn next(&mut self) -> Option<Event<'a>> {
        let event = self.slots.get_mut(self.next)?.take();
        self.next += 1;
        event.or_else(|| self.next())
    }
}

/// Recognises the gestures of a [`GestureSet`], one current gesture at a time.
///
/// ```
/// use dqhand::gesture::{gesture, EventKind, GestureSet, HandFeatures, Recognizer};
/// use dqhand::hand::{build, HandParams, Side};
/// use dqhand::kinematics::{JointModel, JointPositions};
///
/// // The built-in right hand showing the library's fist, and its features.
/// let hand = build(&HandParams { vertices: 2000, ..Default::default() })?;
/// let mut kinematics = hand.hand_kinematics(JointModel::Full)?;
/// kinematics.pose(&gesture("fist")?.pose(JointModel::Full));
/// let joints = JointPositions::new(kinematics.skeleton())?.read(kinematics.world());
/// let features = HandFeatures::from_positions(&joints, Side::Right);
///
/// let mut recognizer = Recognizer::new(GestureSet::builtin());
/// let mut events = Vec::new();
/// for frame in 0..18 { // 0.2 s at 90 Hz: a change is reported once it has lasted min_hold_s
///     events.extend(recognizer.update(f64::from(frame) / 90.0, &features).map(|e| (e.event, e.gesture.to_owned(), e.t)));
/// }
/// assert_eq!(events.len(), 1, "{events:?}");
/// assert_eq!((events[0].0, events[0].1.as_str()), (EventKind::Start, "fist"));
/// assert!(events[0].2 >= recognizer.set().min_hold_s());
/// assert_eq!(recognizer.current(), Some("fist"));
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Recognizer {
    set: GestureSet,
    /// Buffers of the set's classifier, and of each gesture's own model (empty without).
    shared: ClassifierScratch,
    own: Vec<ClassifierScratch>,
    /// Index of the current gesture.
    current: Option<usize>,
    /// The state seen instead of the current one (a gesture or none), since when.
    pending: Option<(Option<usize>, f64)>,
}

impl Recognizer {
    /// A recogniser of `set`'s gestures, with no current gesture.
    #[must_use]
    pub fn new(set: GestureSet) -> Self {
        let shared = set.classifier().map(super::Classifier::scratch).unwrap_or_default();
        let own = set.gestures().iter().map(|g| g.model().map(super::Classifier::scratch).unwrap_or_default()).collect();
        Self { set, shared, own, current: None, pending: None }
    }

    /// The definitions it recognises.
    #[must_use]
    pub fn set(&self) -> &GestureSet {
        &self.set
    }

    /// The current gesture's name.
    #[must_use]
    pub fn current(&self) -> Option<&str> {
        self.current.map(|i| self.set.gestures()[i].name())
    }

    /// The current gesture's index in [`Self::set`], if any.
    #[must_use]
    pub fn current_index(&self) -> Option<usize> {
        self.current
    }

    /// Takes one frame's features at `time_s` (seconds, non-decreasing) and returns what
    /// changed: the end of the previous gesture and/or the start of the next, once the new
    /// state has lasted `min_hold_s` (module docs). Allocates nothing.
    pub fn update(&mut self, time_s: f64, features: &HandFeatures) -> Events<'_> {
        let gestures = self.set.gestures();
        let shared = match self.set.classifier() {
            Some(c) => (c.classify(features, &mut self.shared), c.thresholds()),
            None => (&[][..], (1.0, 1.0)),
        };
        let own = &mut self.own;
        let mut holds = |i: Option<usize>| i.is_some_and(|i| gestures[i].matches(features, shared, &mut own[i], true));
        let seen = if holds(self.current) {
            self.current
        } else {
            match self.pending {
                Some((p @ Some(_), _)) if holds(p) => p,
                _ => gestures.iter().zip(own.iter_mut()).position(|(g, own)| g.matches(features, shared, own, false)),
            }
        };
        let mut events = Events::none();
        if seen == self.current {
            self.pending = None;
            return events;
        }
        let since = match self.pending {
            Some((p, since)) if p == seen => since,
            _ => time_s,
        };
        if time_s - since < self.set.min_hold_s() {
            self.pending = Some((seen, since));
            return events;
        }
        let event = |i: usize, event| Event { t: time_s, event, gesture: gestures[i].name(), index: i };
        events.slots = [self.current.map(|i| event(i, EventKind::End)), seen.map(|i| event(i, EventKind::Start))];
        self.current = seen;
        self.pending = None;
        events
    }
}
