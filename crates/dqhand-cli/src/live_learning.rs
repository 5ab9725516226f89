//! Gestures learned from the page's Input panel: the viewer names a gesture and holds it for
//! a few seconds (`{"type": "learn", "name": "gun"}`), optionally after recording what must
//! not trigger it (`"not": true`); the live hand's features over that time are learned as
//! `dqhand learn-gesture` learns a recording ([`crate::learn_gesture::learn`]) and the live
//! input recognises the gesture from then on. The definitions with it are saved beside the
//! viewers' recordings (`gestures-learned.json`, for `dqhand demo --gestures-file`). One job
//! at a time, on its own thread; every viewer is told its state in `learning` messages:
//!
//! ```json
//! {"type": "learning", "state": "learned", "name": "gun", "not": false, "seconds": 4,
//!  "report": {"frames": 160, "recall": 0.98, "checked": 70, "overlap": [{"gesture": "point", "rate": 0.01}],
//!             "already": {"gesture": "point", "rate": 0.2}, "verdict": "separable from the others",
//!             "not_frames": 0, "not_rate": null, "separable": true},
//!  "path": "recordings/gestures-learned.json", "error": null}
//! ```
//!
//! `state` is `recording`, `training`, `learned`, `noted` (counter-examples kept for `name`)
//! or `failed` (with `error`).

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock, PoisonError};
use std::time::Duration;

use dqhand::input::InputConfig;
use dqhand::model::Model;
use dqhand_stream::LearnRequest;
use serde_json::{json, Value};

use crate::feed::Feed;
use crate::learn_gesture::{learn, Frames, Generated, EDGE_S};

/// Name of the definitions file written beside the viewers' recordings.
pub const LEARNED_FILE: &str = "gestures-learned.json";
/// How often the job looks whether the recording is over.
const POLL: Duration = Duration::from_millis(50);
/// Most frames of counter-examples kept for one gesture (about a minute of recording at
/// 60 Hz): a page pressing Not it without end must not grow the server without end.
const MAX_NOT_FRAMES: usize = 4000;
/// Most gestures learned from the panel: each one is a classifier run on every record.
const MAX_LEARNED: usize = 16;

/// The viewers' gesture learning: the job now, and what every job reuses.
pub struct LiveLearning {
    model: Arc<Model>,
    config: InputConfig,
    /// Where the learned definitions are saved (`None`: not saved).
    directory: Option<PathBuf>,
    job: Mutex<Job>,
    /// Changes of the job so far: each viewer sends the state on a change.
    version: AtomicU64,
    /// The generated counter-examples, made by the first job (they take seconds).
    generated: OnceLock<Result<Generated, String>>,
    /// Counter-examples recorded for a gesture not yet learned: its name and frames.
    not: Mutex<Option<(String, Frames)>>,
}

/// The state of the last job.
enum Job {
    Idle,
    Recording(LearnRequest),
    Training(LearnRequest),
    Noted(LearnRequest),
    Learned(LearnRequest, Value, Option<PathBuf>),
    Failed(LearnRequest, String),
}

impl LiveLearning {
    /// Learning on `model` seen through `config`; definitions saved in `directory`.
    pub fn new(model: Arc<Model>, config: InputConfig, directory: Option<PathBuf>) -> Self {
        Self { model, config, directory, job: Mutex::new(Job::Idle), version: AtomicU64::new(0), generated: OnceLock::new(), not: Mutex::default() }
    }

    /// The number of changes of the job so far (a viewer that has sent the state of an older
    /// one sends [`Self::message`]).
    pub fn version(&self) -> u64 {
        self.version.load(Ordering::SeqCst)
    }

    fn set(&self, job: Job) {
        *lock(&self.job) = job;
        self.version.fetch_add(1, Ordering::SeqCst);
    }

    /// The generated counter-examples, made by the first caller (others wait for them).
    fn generated(&self) -> &Result<Generated, String> {
        self.generated.get_or_init(|| Generated::new(&self.model, &self.config).map_err(|e| format!("{e:#}")))
    }

    /// The job's state as a `learning` message for every viewer.
    pub fn message(&self) -> String {
        let job = lock(&self.job);
        let (state, request) = match &*job {
            Job::Idle => ("idle", None),
            Job::Recording(r) => ("recording", Some(r)),
            Job::Training(r) => ("training", Some(r)),
            Job::Noted(r) => ("noted", Some(r)),
            Job::Learned(r, ..) => ("learned", Some(r)),
            Job::Failed(r, _) => ("failed", Some(r)),
        };
        let (report, path) = match &*job {
            Job::Learned(_, report, path) => (Some(report), path.as_ref().map(|p| p.display().to_string())),
            _ => (None, None),
        };
        let error = match &*job {
            Job::Failed(_, e) => Some(e),
            _ => None,
        };
        json!({
            "type": "learning",
            "state": state,
            "name": request.map(|r| &r.name),
            "not": request.is_some_and(|r| r.not),
            "seconds": request.map(|r| r.seconds),
            "report": report,
            "path": path,
            "error": error,
        })
        .to_string()
    }
}

/// Starts a job on `feed`'s live input: records the hand now, then learns on a thread of
/// its own.
///
/// # Errors
/// A job going on, or a live input without recognition.
pub fn start(feed: &Arc<Feed>, request: LearnRequest) -> anyhow::Result<()> {
    let learning = &feed.learning;
    {
        let mut job = lock(&learning.job);
        if let Job::Recording(r) | Job::Training(r) = &*job {
            anyhow::bail!("learn: still learning {:?}; wait for it to finish", r.name);
        }
        let Some(set) = feed.input.gesture_set() else { anyhow::bail!("learn: this server does not recognise gestures") };
        let learned = set.gestures().iter().filter(|g| g.model().is_some()).count();
        let new = !set.gestures().iter().any(|g| g.name() == request.name);
        anyhow::ensure!(request.not || !new || learned < MAX_LEARNED, "learn: {learned} gestures learned already (at most {MAX_LEARNED}); learn one again under its name to replace it");
        feed.input.capture(f64::from(request.seconds))?;
        *job = Job::Recording(request.clone());
        learning.version.fetch_add(1, Ordering::SeqCst);
    }
    if learning.generated.get().is_none() {
        // Made while the hand is recorded (a call that needs them first waits for them).
        let feed = Arc::clone(feed);
        std::thread::spawn(move || {
            feed.learning.generated();
        });
    }
    let feed = Arc::clone(feed);
    std::thread::spawn(move || {
        let learning = &feed.learning;
        // A panic in the job must not leave it "recording" for ever (every later learn
        // would be refused): it fails like any error.
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(&feed, &request)))
            .unwrap_or_else(|_| Err(anyhow::anyhow!("learn {:?}: the job failed (an internal error; the server logged it)", request.name)));
        learning.set(match outcome {
            Ok(Some((report, path))) => Job::Learned(request, report, path),
            Ok(None) => Job::Noted(request),
            Err(e) => Job::Failed(request, format!("{e:#}")),
        });
    });
    Ok(())
}

/// The job: the frames recorded learned, or kept as counter-examples. Returns the report and
/// where the definitions were saved, or `None` for counter-examples.
fn run(feed: &Feed, request: &LearnRequest) -> anyhow::Result<Option<(Value, Option<PathBuf>)>> {
    let learning = &feed.learning;
    let frames = loop {
        if let Some(frames) = feed.input.captured() {
            break frames;
        }
        std::thread::sleep(POLL);
    };
    let no_hand = |e: anyhow::Error| anyhow::anyhow!("learn {:?}: {e} (was the hand tracked while recording?)", request.name);
    let set = feed.input.gesture_set().ok_or_else(|| anyhow::anyhow!("learn: this server does not recognise gestures"))?;
    let mut not = lock(&learning.not);
    if request.not {
        let mut kept = match not.take() {
            Some((name, frames)) if name == request.name => frames,
            _ => Frames::default(),
        };
        kept.add(frames, 0.0, &set).map_err(no_hand)?;
        anyhow::ensure!(kept.count() <= MAX_NOT_FRAMES, "learn {:?}: {} frames of what it is not already; press Learn", request.name, MAX_NOT_FRAMES);
        *not = Some((request.name.clone(), kept));
        return Ok(None);
    }
    learning.set(Job::Training(request.clone()));
    let mut gesture = Frames::default();
    gesture.add(frames, EDGE_S, &set).map_err(no_hand)?;
    let generated = learning.generated().as_ref().map_err(|e| anyhow::anyhow!("learn: {e}"))?;
    let counter = match not.take() {
        Some((name, frames)) if name == request.name => frames,
        _ => Frames::default(),
    };
    let (classifier, report) = learn(&request.name, &gesture, &counter, generated)?;
    let mut set = set;
    set.insert_learned(&request.name, classifier)?;
    let json = set.to_json() + "\n";
    // Taken first, saved after: the file never holds a set that is not in use.
    feed.input.set_gestures(set)?;
    let path = match &learning.directory {
        Some(dir) => {
            let path = dir.join(LEARNED_FILE);
            std::fs::create_dir_all(dir).and_then(|()| std::fs::write(&path, json)).map_err(|e| anyhow::anyhow!("{}: {e} (it is recognised, but not saved)", path.display()))?;
            Some(path)
        }
        None => None,
    };
    Ok(Some((report.json(), path)))
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}
