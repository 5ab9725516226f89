//! One frame of the manipulation loop as a JSON line: what `dqhand grasp --trace` writes and
//! the WebAssembly engine returns each frame, so that the two can be compared line by line.
//!
//! `{"t": s, "tracking": "ok"|"lost", "held": name|null, "contacts": [{"bone", "object",
//! "p": [x,y,z], "n": [x,y,z]}], "objects": {"<name>": {"p": [x,y,z], "q": [x,y,z,w]}}}`; with
//! two hands `tracking`, `held` and `contacts` are per hand: `{"left": …, "right": …}`.

use serde_json::{json, Map, Value};

use super::{ManipulatingHand, ManipulationLoop};
use crate::input::Tracking;

/// The frame of `manip` at time `t` (s), as [the module](self) says.
#[must_use]
pub fn frame_trace(t: f64, manip: &ManipulationLoop) -> Value {
    let names = manip.names();
    let per_hand = |f: &dyn Fn(&ManipulatingHand) -> Value| match manip.hands() {
        [one] => f(one),
        hands => Value::Object(hands.iter().map(|h| (h.side().name().to_owned(), f(h))).collect()),
    };
    let contacts = per_hand(&|h| {
        let joints = h.rendered().skeleton().joints();
        h.contacts().iter().map(|c| json!({"bone": joints[c.joint].name, "object": names[c.object], "p": c.point.to_array(), "n": c.normal.to_array()})).collect()
    });
    let objects: Map<String, Value> = names.iter().zip(manip.poses()).map(|(n, (q, p))| (n.clone(), json!({"p": p.to_array(), "q": q.to_array()}))).collect();
    let tracking = per_hand(&|h| json!(if h.tracking() == Tracking::Tracking { "ok" } else { "lost" }));
    let held = per_hand(&|h| json!(h.held().map(|i| &names[i])));
    json!({"t": t, "tracking": tracking, "held": held, "contacts": contacts, "objects": objects})
}
