//! Scene files: any text gives a scene or an error, never a panic; and a scene read is one
//! whose every number is finite and in its range (the checks the manipulation loop relies on).
#![no_main]

use std::path::Path;

use dqhand::scene::{ObjectShape, Scene};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let Ok(scene) = Scene::from_json(text, "fuzz.json", Path::new("/nonexistent")) else { return };
    for o in &scene.objects {
        assert!(o.position.is_finite() && o.rotation.is_normalized() && o.mass > 0.0, "{o:?}");
        assert!(o.friction >= 0.0 && (0.0..=1.0).contains(&o.restitution), "{o:?}");
        match o.shape {
            ObjectShape::Sphere { radius } => assert!(radius > 0.0),
            ObjectShape::Box { size } => assert!(size.min_element() > 0.0 && size.is_finite()),
            ObjectShape::Cylinder { radius, height } => assert!(radius > 0.0 && height > 0.0 && radius.is_finite() && height.is_finite()),
            ObjectShape::Mesh { .. } => unreachable!("no mesh file exists under /nonexistent"),
        }
    }
});
