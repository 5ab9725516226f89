//! The JSON settings a user hands the input commands: input configurations, glove mapping
//! tables, glove calibrations and gesture definitions; and the engine settings a page reads
//! from `dqhand demo`'s `engine.json` (with the table, mapper and gestures they name). Any
//! text gives settings or an error, never a panic.
#![no_main]

use dqhand::gesture::GestureSet;
use dqhand::input::{Calibration, InputConfig, MappingTable};
use dqhand_stream::EngineSettings;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let _ = InputConfig::from_json(text);
    let _ = MappingTable::from_json(text);
    let _ = Calibration::from_json(text);
    let _ = GestureSet::from_json(text, "fuzz.json");
    if let Ok(settings) = EngineSettings::from_json(text) {
        let _ = (settings.mapper(), settings.sensors(), settings.gesture_set());
    }
});
