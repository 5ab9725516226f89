//! Scene object meshes from glTF: any bytes give a mesh or an error naming the input, never a
//! panic or a hang.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    if let Err(e) = dqhand::scene::ObjectMesh::from_gltf_slice(bytes, Path::new("fuzz.glb")) {
        assert!(e.to_string().starts_with("fuzz.glb: "), "{e}");
    }
});
