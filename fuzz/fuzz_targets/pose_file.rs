//! Pose files: any text gives a pose file or an error, and resolving any pose file against the
//! built-in hand gives a target or an error, never a panic.
#![no_main]

use std::sync::LazyLock;

use dqhand::hand::{build, HandParams};
use dqhand::io::PoseFile;
use dqhand::model::Model;
use libfuzzer_sys::fuzz_target;

static HAND: LazyLock<Model> = LazyLock::new(|| build(&HandParams { vertices: 1000, ..HandParams::default() }).unwrap());

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    if let Ok(file) = serde_json::from_str::<PoseFile>(text) {
        let _ = file.resolve(&HAND.skeleton);
    }
});
