//! Live input for the viewers: one user's hand (a recording played in real time, a UDP
//! stream, the server's `/input` WebSocket) drives every connected viewer through one shared
//! [`GestureLoop`], or with a scene one shared [`ManipulationLoop`] (which wraps one). Each
//! viewer follows its pose (with a scene the rendered, contact-constrained one), applies its
//! gesture commands to its own view and is told the tracking state, the current gesture and
//! the events in `input` messages (`reset`: a scene's action):
//!
//! ```json
//! {"type": "input", "tracking": "tracking", "gesture": "fist", "side": "left", "mirrored": true,
//!  "events": [{"t": 1.25, "event": "start", "gesture": "fist"}],
//!  "actions": [{"t": 1.75, "gesture": "thumbs_up", "action": "next_method"}],
//!  "accepted": 120, "rejected": 0}
//! ```
//!
//! `side` is the tracked hand's (null before the first record); `mirrored`: our hand, of the
//! other side, shows it mirrored (x → −x in the world), which a viewer undoes to draw it where
//! the user's hand is.
//!
//! A scene's loop may have two hands ([`ManipulationLoop::two_handed`]): viewers are shown the
//! right one as their first hand and the left one as their second
//! ([`Session::follow_second`]). Then the top-level fields are the right hand's, `hands` gives
//! each hand's side, tracking and gesture (right first), each event names its `hand` (`both`
//! for a gesture of both hands, [`dqhand::gesture::TwoHandRecognizer`]), and the viewers'
//! actions and the gestures learned live are the right hand's:
//!
//! ```json
//! {"type": "input", "tracking": "tracking", "gesture": "open_palm", "side": "right", "mirrored": false,
//!  "hands": [{"side": "right", "tracking": "tracking", "gesture": "open_palm"},
//!            {"side": "left", "tracking": "tracking", "gesture": "open_palm"}],
//!  "events": [{"t": 3.5, "event": "start", "gesture": "both_palms_open", "hand": "both"}],
//!  "actions": [], "accepted": 480, "rejected": 0}
//! ```
//!
//! With a scene, viewers are also sent `scene` messages ([`super::frame::scene_message`]):
//! at once when the object held changes, otherwise at most every [`SCENE_PERIOD`] while the
//! scene moves.
//!
//! Sources push records from their own threads; viewers read at their frame rate. The lock
//! is held for one record or one frame's update, never across I/O. A scene's loop steps with
//! each record and, between records, in whichever viewer's update finds a step due
//! ([`STEP_PERIOD`]): objects fall and the hand's tracking is judged without a thread of its own.

use std::collections::VecDeque;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use web_time::Instant;

use glam::{Quat, Vec3};
use serde_json::{json, Value};

use crate::frame::{check_scene, scene_hello, scene_message};
use crate::{Action, Session, ViewerAction};
use dqhand::gesture::{Event, EventKind, Events, GestureSet, HandFeatures, TwoHandEvent};
use dqhand::hand::Side;
use dqhand::input::{Record, Rejection, Tracking};
use dqhand::interaction::{CommandTable, GestureLoop, ManipulationLoop};
use dqhand::kinematics::{JointModel, Pose};
use dqhand::scene::SceneCommand;
use crate::{Error, Result};

/// Log entries kept for viewers that have not read them yet; a viewer further behind misses
/// the oldest (its pose and state are still current).
const LOG_CAPACITY: usize = 256;
/// A change of the record counters alone is reported at most this often.
const COUNTER_PERIOD: Duration = Duration::from_millis(250);
/// A scene's loop steps at least this often (s) while viewers watch, records or not.
pub const STEP_PERIOD: f64 = 1.0 / 60.0;
/// How far behind its clock a replica's scene ([`LiveInput::following_arrivals`]) steps
/// between records (s): a relayed record delivered later than the first one by more than this
/// is stepped at the time already reached.
const RELAY_SLACK_S: f64 = 0.25;
/// A moving scene is reported at most this often (s); a grasp or release at once.
pub const SCENE_PERIOD: f64 = 1.0 / 30.0;

/// One user's hand shared by the viewers of a server.
pub struct LiveInput {
    source: String,
    announce: bool,
    joint_model: JointModel,
    /// The hello's `scene` (built once: a mesh's triangles are many).
    scene: Option<Value>,
    start: Instant,
    /// Records keep the arrival times another input gave them ([`Self::following_arrivals`]).
    follows: bool,
    state: Mutex<State>,
}

struct State {
    driver: Driver,
    /// The viewer's gesture actions (the input configuration's `actions`), with recognition on.
    actions: Option<CommandTable<ViewerAction>>,
    /// Poses taken or stepped: a viewer whose last one is older follows the new one.
    posed: u64,
    log: Log,
    /// The names of the gestures recognised, in the set's order.
    gestures: Vec<String>,
    /// The names of the gestures of both hands recognised (two hands with recognition on).
    two_hand: Vec<String>,
    /// The time of the last record taken (two-hand gesture events are logged at it).
    last_time: f64,
    /// Changes of the gestures recognised so far: a viewer told of fewer is sent a hello.
    gesture_changes: u64,
    /// The hand's features being recorded for learning a gesture ([`LiveInput::capture`]).
    capture: Option<Capture>,
    /// Following another input's arrival clock ([`LiveInput::following_arrivals`]): this
    /// clock less that one's at the first record, and that clock's last arrival; `None` until
    /// then, and for an input of its own.
    arrival_shift: Option<(f64, f64)>,
}

/// The virtual hand's features over a stretch of live input, with their record times.
struct Capture {
    /// The input's clock when the recording ends.
    until: f64,
    frames: Vec<(f64, HandFeatures)>,
}

/// Records kept per second of a capture, at most (a faster source's excess is not kept).
const CAPTURE_RATE: f64 = 240.0;

/// What the records drive.
enum Driver {
    Gestures(Box<GestureLoop>),
    Scene(Box<SceneState>),
}

/// A scene's loop and what its viewers have been told.
struct SceneState {
    manip: ManipulationLoop,
    /// The loop's hand shown first and the one shown second (the right and the left one of
    /// two; the only one, twice, of one).
    shown: [usize; 2],
    /// The input's clock at the last step.
    stepped: f64,
    /// Steps that changed what a scene message says.
    version: u64,
    /// The objects' poses, the contact count and each hand's object held as of `version`.
    poses: Vec<(Quat, Vec3)>,
    contacts: usize,
    held: [Option<usize>; 2],
    /// The scene message of `message.0`, built once for every viewer.
    message: (u64, String),
}

impl SceneState {
    /// One step of the loop at `now`, noting whether the scene message changed; returns the
    /// gestures of both hands begun or ended. Allocates nothing.
    fn step(&mut self, now: f64) -> [Option<TwoHandEvent>; 2] {
        // Never back in time (a replica's record delivered later than its slack).
        let now = now.max(self.stepped);
        let events = self.manip.step(now);
        self.stepped = now;
        let hands = self.manip.hands();
        let (poses, contacts) = (self.manip.poses(), hands.iter().map(|h| h.contacts().len()).sum());
        let mut held = [None; 2];
        for (h, hand) in held.iter_mut().zip(hands) {
            *h = hand.held();
        }
        let mut two = events.two_hand();
        let changed = [two.next(), two.next()];
        if poses != self.poses.as_slice() || contacts + self.contacts > 0 || held != self.held {
            self.poses.copy_from_slice(poses);
            (self.contacts, self.held) = (contacts, held);
            self.version += 1;
        }
        changed
    }

    /// Whether the loop has two hands.
    fn two(&self) -> bool {
        self.manip.hands().len() > 1
    }
}

impl Driver {
    /// The gesture loop of the hand shown first, or second (`k` = 1; a loop of one hand: the
    /// first) (a scene's: the one under its manipulation loop).
    fn gestures(&self, k: usize) -> &GestureLoop {
        match self {
            Driver::Gestures(g) => g,
            Driver::Scene(s) => s.manip.hands()[s.shown[k]].input(),
        }
    }

    /// Whether two hands are shown.
    fn two(&self) -> bool {
        matches!(self, Driver::Scene(s) if s.two())
    }

    /// The gesture loops of the hands shown (one or two).
    fn loops(&self) -> impl Iterator<Item = &GestureLoop> {
        (0..1 + usize::from(self.two())).map(|k| self.gestures(k))
    }

    /// Records taken and refused by every hand.
    fn counts(&self) -> (u64, u64) {
        self.loops().fold((0, 0), |(a, r), g| (a + g.pipeline().accepted(), r + g.pipeline().rejections().total()))
    }

    /// The hand shown a record of `side` drives (0 the first, 1 the second).
    fn shown_of(&self, side: Side) -> usize {
        match self {
            Driver::Scene(s) if s.two() => usize::from(s.manip.hand_of(side) == s.shown[1]),
            _ => 0,
        }
    }

    fn push(&mut self, record: &Record) -> std::result::Result<Events<'_>, Rejection> {
        match self {
            Driver::Gestures(g) => g.push(record),
            Driver::Scene(s) => s.manip.push(record),
        }
    }

    fn set_gestures(&mut self, set: GestureSet) -> Result<()> {
        match self {
            Driver::Gestures(g) => g.set_gestures(set),
            Driver::Scene(s) => s.manip.set_gestures(set)?,
        }
        Ok(())
    }

    /// The pose viewers show of the hand shown `k`-th: the tracked one, or with a scene the
    /// rendered one.
    fn pose(&self, k: usize) -> &Pose {
        match self {
            Driver::Gestures(g) => g.pipeline().pose(),
            Driver::Scene(s) => s.manip.hands()[s.shown[k]].constraint().rendered(),
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Entry {
    /// A gesture of the hand shown `hand`-th (0 or 1) begun or ended.
    Event { t: f64, event: EventKind, gesture: usize, hand: usize },
    /// A gesture of both hands begun or ended.
    TwoHand { t: f64, event: EventKind, gesture: usize },
    Action { t: f64, gesture: usize, action: Action },
    Scene { t: f64, gesture: usize, command: SceneCommand },
}

/// The latest entries for the viewers, and how many were ever logged.
struct Log {
    entries: VecDeque<Entry>,
    /// Entries ever logged: the sequence number of the next one.
    logged: u64,
}

impl Log {
    fn add(&mut self, entry: Entry) {
        if self.entries.len() == LOG_CAPACITY {
            self.entries.pop_front();
        }
        self.entries.push_back(entry);
        self.logged += 1;
    }

    /// The gestures of both hands that `step` began or ended, at `t`.
    fn two_hand(&mut self, t: f64, events: [Option<TwoHandEvent>; 2]) {
        for e in events.into_iter().flatten() {
            let (event, gesture) = match e {
                TwoHandEvent::Start(g) => (EventKind::Start, g),
                TwoHandEvent::End(g) => (EventKind::End, g),
            };
            self.add(Entry::TwoHand { t, event, gesture });
        }
    }
}

/// What one viewer has taken from the input so far.
#[derive(Debug)]
pub struct InputView {
    announced: bool,
    /// The input's gesture changes this viewer's hello knows of.
    gesture_changes: u64,
    /// The input's accepted-record count when the viewer last took its pose.
    version: u64,
    /// The next log entry to read.
    next: u64,
    sent: Option<Sent>,
    /// The scene version last sent, the objects held then, and when (the input's clock).
    scene: Option<(u64, [Option<usize>; 2], f64)>,
}

/// The state a viewer was last told, and when (the input's clock).
#[derive(Clone, Copy, Debug)]
struct Sent {
    tracking: Tracking,
    side: Option<Side>,
    gesture: Option<usize>,
    /// The second hand's tracking and gesture, with two hands.
    second: Option<(Tracking, Option<usize>)>,
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
    /// A `scene` message to send.
    pub scene: Option<String>,
}

impl LiveInput {
    /// The input of `gesture_loop` from `source` (for display: a path, `udp 127.0.0.1:9000`).
    /// With `announce` the viewers are told of it from the start; otherwise from its first
    /// record (the demo's `/input` WebSocket, open whether or not anyone uses it). With
    /// recognition on, the input configuration's `actions` are the viewers' commands.
    ///
    /// # Errors
    /// As [`ViewerAction::resolve`] and [`CommandTable::new`]: an action that is no viewer
    /// action, or names a gesture not recognised.
    pub fn new(gesture_loop: GestureLoop, source: impl Into<String>, announce: bool) -> Result<Self> {
        Self::driving(Driver::Gestures(Box::new(gesture_loop)), None, source.into(), announce)
    }

    /// The input of `manip`'s scene, as [`Self::new`]: viewers follow its rendered hand and
    /// are sent the scene.
    ///
    /// # Errors
    /// As [`check_scene`]: a scene too large to stream; as [`Self::new`].
    pub fn with_scene(manip: ManipulationLoop, source: impl Into<String>, announce: bool) -> Result<Self> {
        check_scene(&manip)?;
        let scene = Some(scene_hello(&manip));
        // (A loop of one hand drives it from either side.)
        let shown = [manip.hand_of(Side::Right), manip.hand_of(Side::Left)];
        let state = SceneState { poses: manip.poses().to_vec(), contacts: 0, held: [None; 2], stepped: 0.0, version: 0, message: (u64::MAX, String::new()), shown, manip };
        Self::driving(Driver::Scene(Box::new(state)), scene, source.into(), announce)
    }

    fn driving(driver: Driver, scene: Option<Value>, source: String, announce: bool) -> Result<Self> {
        let gesture_loop = driver.gestures(0);
        let gestures = gesture_loop.gestures().map_or_else(Vec::new, names);
        let two_hand = match &driver {
            Driver::Scene(s) => s.manip.two_hand_gestures().map_or_else(Vec::new, |r| r.gestures().iter().map(|g| g.name.clone()).collect()),
            Driver::Gestures(_) => Vec::new(),
        };
        let actions = match gesture_loop.gestures() {
            Some(set) => Some(CommandTable::new(&ViewerAction::resolve(&gesture_loop.pipeline().config().actions)?, set)?),
            None => None,
        };
        let joint_model = gesture_loop.pipeline().retargeter().rig().model();
        let log = Log { entries: VecDeque::with_capacity(LOG_CAPACITY), logged: 0 };
        let state = State { driver, actions, posed: 0, log, gestures, two_hand, last_time: 0.0, gesture_changes: 0, capture: None, arrival_shift: None };
        Ok(Self { source, announce, joint_model, scene, start: Instant::now(), follows: false, state: Mutex::new(state) })
    }

    /// This input as a replica of another live input whose records it is relayed (a page's
    /// engine following `dqhand demo`): a record keeps the arrival time that input gave it,
    /// shifted onto this input's clock at the first record, so lateness, dropouts and the
    /// gesture events are judged as that input judged them, not on when the relay delivered
    /// the record (a page's main thread busy with a camera frame delivers them in bursts).
    /// Records with no arrival time arrive now, as always. (A first record delivered late by D
    /// shifts the rest by D: between records the hand is judged lost D later than the other
    /// input judged it. A scene steps [`RELAY_SLACK_S`] behind this clock between records, and
    /// never back in time.)
    #[must_use]
    pub fn following_arrivals(mut self) -> Self {
        self.follows = true;
        self
    }

    /// The gestures recognised now (`None`: recognition is off).
    #[must_use]
    pub fn gesture_set(&self) -> Option<GestureSet> {
        self.lock().driver.gestures(0).gestures().cloned()
    }

    /// Recognises `set` from now on (a gesture learned live): the viewers' actions and a
    /// scene's are bound to its gestures by name, and every viewer is sent a new hello (its
    /// Input panel lists the gestures). Log entries not yet read by a viewer are dropped:
    /// they name gestures by their place in the old set.
    ///
    /// # Errors
    /// An action of the viewers or the scene naming a gesture `set` lacks; nothing changes then.
    pub fn set_gestures(&self, set: GestureSet) -> Result<()> {
        let mut state = self.lock();
        let actions = state.actions.as_ref().map(|t| t.rebind(&set)).transpose()?;
        let gestures = names(&set);
        state.driver.set_gestures(set)?;
        state.actions = actions;
        state.gestures = gestures;
        state.gesture_changes += 1;
        state.log.entries.clear();
        Ok(())
    }

    /// Starts recording the virtual hand's features for `seconds` from now, for learning a
    /// gesture; [`Self::captured`] hands them over once the time is up.
    ///
    /// # Errors
    /// `seconds` not in (0, 60], or a recording already going on.
    pub fn capture(&self, seconds: f64) -> Result<()> {
        if !(seconds > 0.0 && seconds <= 60.0) {
            return Err(Error::Command(format!("learn: {seconds} seconds to record (more than 0, at most 60)")));
        }
        let mut state = self.lock();
        if state.capture.is_some() {
            return Err(Error::Command("learn: the hand is already being recorded for learning".into()));
        }
        let until = self.clock() + seconds;
        state.capture = Some(Capture { until, frames: Vec::with_capacity((seconds * CAPTURE_RATE) as usize) });
        Ok(())
    }

    /// The features recorded since [`Self::capture`], with their record times, once its time
    /// is up (`None` before then, or with no recording).
    #[must_use]
    pub fn captured(&self) -> Option<Vec<(f64, HandFeatures)>> {
        let mut state = self.lock();
        let done = state.capture.as_ref().is_some_and(|c| self.clock() >= c.until);
        done.then(|| state.capture.take().map(|c| c.frames)).flatten()
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
        self.active().then(|| json!({ "source": self.source, "gestures": self.lock().gestures }))
    }

    /// The hello's `scene`: the table and the objects' shapes; `None` without a scene.
    #[must_use]
    pub fn scene(&self) -> Option<&Value> {
        self.scene.as_ref()
    }

    fn active(&self) -> bool {
        self.announce || {
            let (accepted, rejected) = self.lock().driver.counts();
            accepted + rejected > 0
        }
    }

    /// Whether the input drives two hands (viewers then show a second one).
    #[must_use]
    pub fn two_hands(&self) -> bool {
        self.lock().driver.two()
    }

    /// Takes one record arriving now (and steps a scene's loop); `taken` sees it, its
    /// [`Record::arrival`] set to now, once the loop has taken it, in the order records are
    /// taken (under the input's lock: recording it there keeps a recording in that order when
    /// several sources send at once, and a replay of it takes each record as it arrived).
    ///
    /// # Errors
    /// The record's refusal (counted, and reported to the viewers in the totals).
    pub fn push(&self, record: &Record, taken: impl FnOnce(&Record)) -> Result<(), Rejection> {
        let mut guard = self.lock();
        // Read under the lock, so that the records taken have increasing arrival times.
        let now = self.clock();
        let arrival = match record.arrival.filter(|_| self.follows) {
            Some(given) => {
                // Anchored at the first record, and again when the other clock starts over
                // (its input restarted): one shift keeps that clock's intervals exactly.
                let (shift, last) = guard.arrival_shift.get_or_insert((now - given, given));
                if given < *last {
                    *shift = now - given;
                }
                *last = given;
                given + *shift
            }
            None => now,
        };
        let record = &Record { arrival: Some(arrival), ..*record };
        let State { driver, actions, posed, log, capture, last_time, .. } = &mut *guard;
        let hand = driver.shown_of(record.side);
        let events = driver.push(record)?;
        for e in events.clone() {
            log.add(Entry::Event { t: e.t, event: e.event, gesture: e.index, hand });
        }
        // The viewers' actions and a capture for learning are the first hand's.
        let action = actions.as_mut().filter(|_| hand == 0).and_then(|table| table.update(record.time, events));
        taken(record);
        *posed += 1;
        *last_time = record.time;
        if let Some(c) = capture.as_mut().filter(|c| hand == 0 && arrival <= c.until && c.frames.len() < c.frames.capacity()) {
            c.frames.push((record.time, driver.gestures(0).features()));
        }
        if let (Some(action), Some(gesture)) = (action, driver.gestures(0).gesture_index()) {
            log.add(Entry::Action { t: record.time, gesture, action });
        }
        if let Driver::Scene(s) = driver {
            let pushed = s.manip.hands()[s.manip.hand_of(record.side)].input();
            if let (Some(command), Some(gesture)) = (s.manip.command(), pushed.gesture_index()) {
                log.add(Entry::Scene { t: record.time, gesture, command });
            }
            let two_hand = s.step(arrival);
            log.two_hand(record.time, two_hand);
        }
        Ok(())
    }

    /// Puts a scene's objects back where the scene file has them (a played recording starting
    /// over grasps them where they were); without a scene, nothing.
    pub fn reset_scene(&self) {
        if let Driver::Scene(s) = &mut self.lock().driver {
            s.manip.reset();
        }
    }

    /// Counts a record refused before it got here (unreadable, too large).
    pub fn reject(&self, rejection: Rejection) {
        match &mut self.lock().driver {
            Driver::Gestures(g) => g.reject(rejection),
            Driver::Scene(s) => s.manip.reject(rejection),
        }
    }

    /// The records taken so far, and the refusals, one line per kind (for a log).
    #[must_use]
    pub fn summary(&self) -> (u64, u64, Vec<String>) {
        let state = self.lock();
        let (accepted, rejected) = state.driver.counts();
        // With two hands, each line names its hand.
        let two = state.driver.two();
        let lines = state.driver.loops().flat_map(|g| {
            let side = g.pipeline().retargeter().side().name();
            g.pipeline().rejections().summary().map(move |line| if two { format!("{side} hand: {line}") } else { line })
        });
        (accepted, rejected, lines.collect())
    }

    /// A viewer's view of the input, from now on (earlier events are not replayed to it).
    #[must_use]
    pub fn view(&self) -> InputView {
        let announced = self.active();
        let state = self.lock();
        InputView { announced, gesture_changes: state.gesture_changes, version: 0, next: state.log.logged, sent: None, scene: None }
    }

    /// Brings one viewer up to date, once per frame: marks the hand lost after the grace
    /// time (steps a scene's loop when a step is due), gives `session` the newest pose and the
    /// gesture commands since its last update, and says what to send.
    pub fn update(&self, session: &mut Session, view: &mut InputView) -> InputUpdate {
        let mut guard = self.lock();
        let state = &mut *guard;
        // A replica's scene steps a slack behind its clock between records, so that records
        // the relay delivers late still come after the time it has stepped to.
        let slack = if self.follows && matches!(state.driver, Driver::Scene(_)) { RELAY_SLACK_S } else { 0.0 };
        let arrival = self.clock() - slack;
        match &mut state.driver {
            Driver::Gestures(g) => {
                if g.advance(arrival) {
                    state.posed += 1; // a lost hand relaxing: viewers follow it
                }
            }
            Driver::Scene(s) if arrival - s.stepped >= STEP_PERIOD => {
                let two_hand = s.step(arrival);
                state.log.two_hand(state.last_time, two_hand);
                state.posed += 1;
            }
            Driver::Scene(_) => {}
        }
        let gesture_loop = state.driver.gestures(0);
        let pipeline = gesture_loop.pipeline();
        let (accepted, rejected) = state.driver.counts();
        let two = state.driver.two();
        let mut update = InputUpdate::default();
        if !view.announced {
            if accepted + rejected == 0 {
                return update;
            }
            view.announced = true;
            update.hello = true;
        }
        if view.gesture_changes != state.gesture_changes {
            view.gesture_changes = state.gesture_changes;
            update.hello = true;
        }
        if state.posed != view.version {
            session.follow(state.driver.pose(0), self.joint_model);
            if two {
                session.follow_second(state.driver.pose(1), self.joint_model);
            }
            view.version = state.posed;
        }
        let first = state.log.logged - state.log.entries.len() as u64;
        let new = state.log.entries.iter().skip(view.next.saturating_sub(first) as usize);
        let (mut events, mut actions) = (Vec::new(), Vec::new());
        let side = |k: usize| state.driver.gestures(k).pipeline().retargeter().side().name();
        for entry in new {
            match *entry {
                Entry::Event { t, event, gesture, hand } => {
                    let mut e = json!(Event { t, event, gesture: &state.gestures[gesture], index: gesture });
                    if two {
                        e["hand"] = side(hand).into();
                    }
                    events.push(e);
                }
                Entry::TwoHand { t, event, gesture } => {
                    let mut e = json!(Event { t, event, gesture: &state.two_hand[gesture], index: gesture });
                    e["hand"] = "both".into();
                    events.push(e);
                }
                Entry::Action { t, gesture, action } => {
                    session.act(action);
                    actions.push(json!({ "t": t, "gesture": state.gestures[gesture], "action": action }));
                }
                Entry::Scene { t, gesture, command } => actions.push(json!({ "t": t, "gesture": state.gestures[gesture], "action": command })),
            }
        }
        view.next = state.log.logged;
        let gesture = gesture_loop.gesture_index();
        let second = two.then(|| state.driver.gestures(1)).map(|g| (g.pipeline().tracking(), g.gesture_index()));
        let sent = Sent { tracking: pipeline.tracking(), side: pipeline.side(), gesture, second, accepted, rejected, at: arrival };
        let due = match view.sent {
            None => true,
            Some(last) => {
                last.tracking != sent.tracking
                    || last.side != sent.side
                    || last.gesture != sent.gesture
                    || last.second != sent.second
                    || (last.accepted, last.rejected) != (accepted, rejected) && arrival - last.at >= COUNTER_PERIOD.as_secs_f64()
            }
        };
        if due || !events.is_empty() || !actions.is_empty() {
            let mut message = json!({
                "type": "input",
                "tracking": sent.tracking.as_str(),
                "gesture": gesture.map(|g| &state.gestures[g]),
                "side": sent.side.map(Side::name),
                "mirrored": sent.side.is_some_and(|s| s != pipeline.retargeter().side()),
                "events": events,
                "actions": actions,
                "accepted": accepted,
                "rejected": rejected,
            });
            if let Some((tracking, gesture)) = sent.second {
                message["hands"] = json!([
                    { "side": side(0), "tracking": sent.tracking.as_str(), "gesture": sent.gesture.map(|g| &state.gestures[g]) },
                    { "side": side(1), "tracking": tracking.as_str(), "gesture": gesture.map(|g| &state.gestures[g]) },
                ]);
            }
            update.message = Some(message.to_string());
            view.sent = Some(sent);
        }
        if let Driver::Scene(s) = &mut state.driver {
            let due = match view.scene {
                None => true,
                Some((version, held, at)) => version != s.version && (held != s.held || arrival - at >= SCENE_PERIOD),
            };
            if due {
                if s.message.0 != s.version {
                    s.message = (s.version, scene_message(&s.manip));
                }
                update.scene = Some(s.message.1.clone());
                view.scene = Some((s.version, s.held, arrival));
            }
        }
        update
    }
}

/// The names of `set`'s gestures, in its order.
fn names(set: &GestureSet) -> Vec<String> {
    set.gestures().iter().map(|g| g.name().to_owned()).collect()
}
