//! The JSON settings a user hands the input commands: input configurations, glove mapping
//! tables, glove calibrations and gesture definitions. Any text gives settings or an error,
//! never a panic.
#![no_main]

use dqhand::gesture::GestureSet;
use dqhand::input::{Calibration, InputConfig, MappingTable};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let _ = InputConfig::from_json(text);
    let _ = MappingTable::from_json(text);
    let _ = Calibration::from_json(text);
    let _ = GestureSet::from_json(text, "fuzz.json");
});
