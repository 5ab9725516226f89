//! glTF import: any bytes give a model or an error naming the input, never a panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    if let Err(e) = dqhand::io::load_gltf_slice(bytes, Path::new("fuzz.glb")) {
        assert!(e.to_string().starts_with("fuzz.glb: "), "{e}");
    }
});
