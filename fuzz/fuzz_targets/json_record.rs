//! JSON records (recordings, live messages): any bytes read as a recording give records or
//! rejections, never a panic, and a record that parses is written by `write_record` as a line
//! that parses back to the same record (its documented inverse).
#![no_main]

use std::sync::LazyLock;

use dqhand::hand::Side;
use dqhand::input::json_record::{parse_record, write_record, JsonRecordReader};
use dqhand::input::{MappingTable, Record};
use libfuzzer_sys::fuzz_target;

/// The sensors of the 5DT 14 glove, so that glove records are parsed too.
static SENSORS: LazyLock<Vec<String>> =
    LazyLock::new(|| MappingTable::builtin("5dt-14").unwrap().layout().sensors().iter().map(|s| s.name.clone()).collect());

fuzz_target!(|bytes: &[u8]| {
    let mut reader = JsonRecordReader::new(bytes, Side::Right, SENSORS.clone());
    let mut record = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
    while let Ok(Some(read)) = reader.next_record(&mut record) {
        if read.is_err() {
            continue;
        }
        let mut line = Vec::new();
        write_record(&mut line, &record, &SENSORS).unwrap();
        let text = std::str::from_utf8(&line).unwrap();
        // The other default side: the written line must say its hand.
        let mut back = Record { time: -1.0, side: Side::Left, hand: None, tracker: None, arrival: None };
        if let Err(r) = parse_record(text.trim_end(), Side::Left, &SENSORS, &mut back) {
            panic!("{record:?} written as {text} is refused: {}", r.message);
        }
        assert_eq!(back, record, "written as {text}");
    }
});
