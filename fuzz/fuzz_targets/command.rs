//! Viewer commands: any text gives a command or an error; applying any command either changes
//! the session or leaves it as it was, and the next frame is always well formed.
#![no_main]

use std::sync::{Arc, LazyLock};

use dqhand::hand::{build, HandParams};
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand_stream::{Command, FrameView, Session};
use libfuzzer_sys::fuzz_target;

static HAND: LazyLock<Arc<Model>> = LazyLock::new(|| Arc::new(build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap()));

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let mut session = Session::new(HAND.clone(), None, JointModel::Full).unwrap();
    for line in text.lines() {
        if let Ok(command) = Command::parse(line) {
            let before = session.pose().clone();
            if session.apply(&command).is_err() {
                assert_eq!(session.pose(), &before, "a refused command changes nothing");
            }
            session.advance(0.05);
        }
    }
    let mut frame = Vec::new();
    session.render(60.0, &mut frame);
    FrameView::parse(&frame).expect("the session writes frames its reader takes");
});
