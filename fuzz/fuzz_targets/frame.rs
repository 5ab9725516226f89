//! The viewer stream's binary readers: any bytes give a frame or an error, never a panic, and
//! a frame that parses is written back byte for byte.
#![no_main]

use dqhand_stream::{FrameView, FrameWriter, Topology};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    if let Ok(frame) = FrameView::parse(bytes) {
        let mut out = Vec::new();
        let mut w = FrameWriter::begin(&mut out, frame.header);
        w.floats(&frame.angles).floats(&frame.joints);
        for [positions, normals, distortion] in &frame.meshes {
            w.floats(positions).floats(normals).floats(distortion);
        }
        w.finish();
        assert_eq!(out, bytes, "a parsed frame re-encodes to its bytes");
    }
    if let Ok(topology) = Topology::parse(bytes) {
        assert_eq!(topology.encode(), bytes, "a parsed topology re-encodes to its bytes");
    }
});
