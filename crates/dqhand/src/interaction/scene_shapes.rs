//! The scene of a manipulation loop as JSON, for whatever draws it (the viewer's hello, the
//! WebAssembly engine's pages): the table's top and each object's shape in its own frame,
//! metres, +Y up, a mesh's triangles scaled as the physics has them.
//!
//! `{"table": {"height", "centre": [x, z], "half": [x, z]} | null, "objects": [{"name",
//! "shape": "sphere", "radius"} | {"shape": "box", "size": [x, y, z]} | {"shape": "cylinder",
//! "radius", "height"} | {"shape": "mesh", "positions": [x, y, z, …], "indices": […],
//! "simplified": bool}]}`

use glam::Vec3;
use serde_json::{json, Value};

use super::ManipulationLoop;

/// The shapes of `manip`'s scene, as [the module](self) says, with at most `max_triangles`
/// mesh triangles in all: a mesh past that is its bounding box (12 triangles, `simplified`).
#[must_use]
pub fn scene_shapes(manip: &ManipulationLoop, max_triangles: usize) -> Value {
    let table = manip.objects().table().map(|t| json!({ "height": t.height, "centre": t.centre, "half": t.half }));
    let mut budget = max_triangles;
    let objects: Vec<Value> = manip
        .objects()
        .objects()
        .iter()
        .map(|o| {
            let (name, s) = (&o.name, &o.surface);
            if let Some(mesh) = &o.mesh {
                let simplified = mesh.triangles.len() > budget;
                let (positions, indices): (Vec<f32>, Vec<u32>) = if simplified {
                    let (lo, hi) = mesh.vertices.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
                    let corners = (0..8).flat_map(|k| [if k & 1 == 0 { lo.x } else { hi.x }, if k & 2 == 0 { lo.y } else { hi.y }, if k & 4 == 0 { lo.z } else { hi.z }]);
                    (corners.collect(), BOX_TRIANGLES.to_vec())
                } else {
                    budget -= mesh.triangles.len();
                    (mesh.vertices.iter().flat_map(|v| v.to_array()).collect(), mesh.triangles.as_flattened().to_vec())
                };
                json!({ "name": name, "shape": "mesh", "positions": positions, "indices": indices, "simplified": simplified })
            } else if let Some(ball) = s.as_ball() {
                json!({ "name": name, "shape": "sphere", "radius": ball.radius })
            } else if let Some(cuboid) = s.as_cuboid() {
                json!({ "name": name, "shape": "box", "size": (2.0 * cuboid.half_extents).to_array() })
            } else {
                let cylinder = s.as_cylinder().expect("an object is a mesh, ball, cuboid or cylinder (ObjectColliders::new)");
                json!({ "name": name, "shape": "cylinder", "radius": cylinder.radius, "height": 2.0 * cylinder.half_height })
            }
        })
        .collect();
    json!({ "table": table, "objects": objects })
}

/// The 12 outward triangles of a box whose corner `k` has bit 0, 1, 2 set for the high x, y, z.
const BOX_TRIANGLES: [u32; 36] = [
    0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, // −z, +z
    0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, // −y, +y
    0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5, // −x, +x
];
