//! Glove CSV recordings: any bytes give a header error or rows that are records or
//! rejections, never a panic, and a row that parses is written by `GloveCsvWriter` as a row
//! that reads back bit for bit (what the writer promises).
#![no_main]

use std::sync::LazyLock;

use dqhand::hand::Side;
use dqhand::input::{GloveCsvReader, GloveCsvWriter, MappingTable, Record};
use libfuzzer_sys::fuzz_target;

static TABLE: LazyLock<MappingTable> = LazyLock::new(|| MappingTable::builtin("5dt-14").unwrap());

fuzz_target!(|bytes: &[u8]| {
    let Ok(mut reader) = GloveCsvReader::new(bytes, &TABLE, Side::Right) else { return };
    let mut record = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
    while let Some(read) = reader.next_record(&mut record) {
        if read.is_err() {
            continue;
        }
        let mut written = Vec::new();
        let mut writer = GloveCsvWriter::new(&mut written, &TABLE, record.tracker.is_some(), true).unwrap();
        if let Err(e) = writer.write(&record) {
            panic!("{record:?} is refused by the writer: {e}");
        }
        // The other default side: the written row must say its hand.
        let mut back_reader = GloveCsvReader::new(&written[..], &TABLE, Side::Left).unwrap();
        let mut back = Record { time: -1.0, side: Side::Left, hand: None, tracker: None, arrival: None };
        let text = String::from_utf8_lossy(&written);
        match back_reader.next_record(&mut back) {
            Some(Ok(())) => assert_eq!(back, record, "written as {text}"),
            other => panic!("{record:?} written as {text} reads back as {other:?}"),
        }
    }
});
