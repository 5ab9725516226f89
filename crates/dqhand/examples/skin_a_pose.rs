//! Skin a pose and write a glTF: `cargo run -p dqhand --example skin_a_pose -- [OUT.glb]`.
//!
//! Builds the built-in anatomical hand, poses the library's "ok" gesture through the
//! kinematics layer (one forward kinematics pass), deforms it with dual quaternion blending
//! and writes the posed mesh as a GLB any glTF viewer opens.

use std::path::PathBuf;
use std::sync::Arc;

use dqhand::engine::Engine;
use dqhand::gesture::gesture;
use dqhand::hand::{build, HandParams};
use dqhand::kinematics::JointModel;
use dqhand::skin::Method;

fn main() -> Result<(), dqhand::Error> {
    let out = std::env::args_os().nth(1).map_or_else(|| std::env::temp_dir().join("dqhand-ok.glb"), PathBuf::from);
    let hand = Arc::new(build(&HandParams::default())?);
    println!("{}", hand.description);
    let mut engine = Engine::new(Arc::clone(&hand), JointModel::Full)?;
    engine.step(&gesture("ok")?.pose(JointModel::Full));
    let skin = engine.deformed(Method::Dqb).expect("an engine skins with DQB");
    dqhand::io::write_posed(&out, skin.positions(), skin.normals(), hand.mesh.uvs(), hand.mesh.indices())?;
    println!("wrote {} ({} vertices, {} triangles)", out.display(), hand.mesh.vertex_count(), hand.mesh.triangle_count());
    Ok(())
}
