//! Live input for the viewers: one user's hand (a recording played in real time, a UDP
//! stream, the server's `/input` WebSocket) drives every connected viewer through one shared
//! [`GestureLoop`]. Each viewer follows its pose, applies its gesture commands to its own view
//! and is told the tracking state, the current gesture and the events in `input` messages:
//!
//! ```json
//! {"type": "input", "tracking": "tracking", "gesture": "fist",
//!  "events": [{"t": 1.25, "event": "start", "gesture": "fist"}],
//!  "actions": [{"t": 1.75, "gesture": "thumbs_up", "action": "next_method"}],
//!  "accepted": 120, "rejected": 0}
//! ```
//!
//! Sources push records from their own threads; viewers read at their frame rate. The lock
//! is held for one record or one frame's update, never across I/O.

use std::collections::VecDeque;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use super::Session;
use crate::gesture::{Event, EventKind};
use crate::input::{Action, Record, Rejection, Tracking};
use crate::interaction::GestureLoop;
use crate::kinematics::JointModel;

/// Log entries kept for viewers that have not read them yet; a viewer further behind misses
/// the oldest (its pose and state are still current).
const LOG_CAPACITY: usize = 256;
/// A change of the record counters alone is reported at most this often.
const COUNTER_PERIOD: Duration = Duration::from_millis(250);

/// One user's hand shared by the viewers of a server.
pub struct LiveInput {
    source: String,
    announce: bool,
    gestures: Vec<String>,
    joint_model: JointModel,
    start: Instant,
    state: Mutex<State>,
}

struct State {
    gesture_loop: GestureLoop,
    log: VecDeque<Entry>,
    /// Entries ever logged: the sequence number of the next one.
    logged: u64,
}

#[derive(Clone, Copy, Debug)]
enum Entry {
    Event { t: f64, event: EventKind, gesture: usize },
    Action { t: f64, gesture: usize, action: Action },
}

/// What one viewer has taken from the input so far.
#[derive(Debug)]
pub struct InputView {
    announced: bool,
    /// The input's accepted-record count when the viewer last took its pose.
    version: u64,
    /// The next log entry to read.
    next: u64,
    sent: Option<Sent>,
}

/// The state a viewer was last told, and when (the input's clock).
#[derive(Clone, Copy, Debug)]
struct Sent {
    tracking: Tracking,
    gesture: Option<usize>,
    accepted: u64,
    rejected: u64,
    at: f64,
}

/// What a viewer's update produced for its transport.
#[derive(Debug, Default)]
pub struct InputUpdate {
    /// The input has just appeared (its first record): send the hello again, it now says so.
    pub hello: bool,
    /// An `input` message to send.
    pub message: Option<String>,
}

impl LiveInput {
    /// The input of `gesture_loop` from `source` (for display: a path, `udp 127.0.0.1:9000`).
    /// With `announce` the viewers are told of it from the start; otherwise from its first
    /// record (the demo's `/input` WebSocket, open whether or not anyone uses it).
    #[must_use]
    pub fn new(gesture_loop: GestureLoop, source: impl Into<String>, announce: bool) -> Self {
        let gestures = gesture_loop.gestures().map_or_else(Vec::new, |set| set.gestures().iter().map(|g| g.name().to_owned()).collect());
        let joint_model = gesture_loop.pipeline().retargeter().rig().model();
        let state = State { gesture_loop, log: VecDeque::with_capacity(LOG_CAPACITY), logged: 0 };
        Self { source: source.into(), announce, gestures, joint_model, start: Instant::now(), state: Mutex::new(state) }
    }

    /// The index of the gesture called `name` in the recognised set.
    fn index(&self, name: &str) -> Option<usize> {
        self.gestures.iter().position(|g| g == name)
    }

    /// Seconds since the input was made: the arrival clock of its records.
    fn clock(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic elsewhere cannot leave the state half-written: each update completes or
        // returns before any field changes. Keep serving.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The hello's `input`: the source and the gestures recognised, once there is an input
    /// to show.
    #[must_use]
    pub fn describe(&self) -> Option<Value> {
        self.active().then(|| json!({ "source": self.source, "gestures": self.gestures }))
    }

    fn active(&self) -> bool {
        self.announce || {
            let state = self.lock();
            let pipeline = state.gesture_loop.pipeline();
            pipeline.accepted() + pipeline.rejections().total() > 0
        }
    }

    /// Takes one record arriving now; `taken` sees it once the loop has taken it, in the order
    /// records are taken (under the input's lock: recording it there keeps a recording in
    /// that order when several sources send at once).
    ///
    /// # Errors
    /// The record's refusal (counted, and reported to the viewers in the totals).
    pub fn push(&self, record: &Record, taken: impl FnOnce(&Record)) -> Result<(), Rejection> {
        let arrival = self.clock();
        let mut guard = self.lock();
        let State { gesture_loop, log, logged } = &mut *guard;
        let mut add = |entry| {
            if log.len() == LOG_CAPACITY {
                log.pop_front();
            }
            log.push_back(entry);
            *logged += 1;
        };
        let index = |name: &str| self.index(name).expect("events name gestures of the set");
        for e in gesture_loop.push(record, Some(arrival))? {
            add(Entry::Event { t: e.t, event: e.event, gesture: index(e.gesture) });
        }
        taken(record);
        if let (Some(action), Some(gesture)) = (gesture_loop.action(), gesture_loop.gesture()) {
            add(Entry::Action { t: record.time, gesture: index(gesture), action });
        }
        Ok(())
    }

    /// Counts a record refused before it got here (unreadable, too large).
    pub fn reject(&self, rejection: Rejection) {
        self.lock().gesture_loop.reject(rejection);
    }

    /// The records taken so far, and the refusals, one line per kind (for a log).
    #[must_use]
    pub fn summary(&self) -> (u64, u64, Vec<String>) {
        let state = self.lock();
        let pipeline = state.gesture_loop.pipeline();
        (pipeline.accepted(), pipeline.rejections().total(), pipeline.rejections().summary().collect())
    }

    /// A viewer's view of the input, from now on (earlier events are not replayed to it).
    #[must_use]
    pub fn view(&self) -> InputView {
        InputView { announced: self.active(), version: 0, next: self.lock().logged, sent: None }
    }

    /// Brings one viewer up to date, once per frame: marks the hand lost after the grace
    /// time, gives `session` the newest pose and the gesture commands since its last update,
    /// and says what to send.
    pub fn update(&self, session: &mut Session, view: &mut InputView) -> InputUpdate {
        let arrival = self.clock();
        let mut state = self.lock();
        state.gesture_loop.advance(arrival);
        let pipeline = state.gesture_loop.pipeline();
        let (accepted, rejected) = (pipeline.accepted(), pipeline.rejections().total());
        let mut update = InputUpdate::default();
        if !view.announced {
            if accepted + rejected == 0 {
                return update;
            }
            view.announced = true;
            update.hello = true;
        }
        if accepted != view.version {
            session.follow(pipeline.pose(), self.joint_model);
            view.version = accepted;
        }
        let first = state.logged - state.log.len() as u64;
        let new = state.log.iter().skip(view.next.saturating_sub(first) as usize);
        let (mut events, mut actions) = (Vec::new(), Vec::new());
        for entry in new {
            match *entry {
                Entry::Event { t, event, gesture } => events.push(json!(Event { t, event, gesture: &self.gestures[gesture] })),
                Entry::Action { t, gesture, action } => {
                    session.act(action);
                    actions.push(json!({ "t": t, "gesture": self.gestures[gesture], "action": action }));
                }
            }
        }
        view.next = state.logged;
        let gesture = state.gesture_loop.gesture().and_then(|g| self.index(g));
        let sent = Sent { tracking: pipeline.tracking(), gesture, accepted, rejected, at: arrival };
        let due = match view.sent {
            None => true,
            Some(last) => {
                last.tracking != sent.tracking
                    || last.gesture != sent.gesture
                    || (last.accepted, last.rejected) != (accepted, rejected) && arrival - last.at >= COUNTER_PERIOD.as_secs_f64()
            }
        };
        if due || !events.is_empty() || !actions.is_empty() {
            update.message = Some(
                json!({
                    "type": "input",
                    "tracking": sent.tracking.as_str(),
                    "gesture": gesture.map(|g| &self.gestures[g]),
                    "events": events,
                    "actions": actions,
                    "accepted": accepted,
                    "rejected": rejected,
                })
                .to_string(),
            );
            view.sent = Some(sent);
        }
        update
    }
}
