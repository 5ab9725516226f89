//! `dqhand info`: what a skinned file (or the built-in hand) contains.

use dqhand::engine::ModelSource;
use dqhand::kinematics::{webxr, JointModel};
use dqhand::model::Model;

/// Arguments of `dqhand info`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(default_value = "builtin")]
    file: ModelSource,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = args.file.load()?;
    crate::warn_all(&model.warnings);
    print!("{}", describe(&args.file.to_string(), &model));
    Ok(())
}

fn describe(file: &str, model: &Model) -> String {
    use std::fmt::Write;
    let mesh = &model.mesh;
    let mut s = String::new();
    let _ = writeln!(s, "{file}: {}", model.description);
    let _ = writeln!(s, "meshes: {} primitive(s)", mesh.parts().len());
    for (k, p) in mesh.parts().iter().enumerate() {
        // Primitives over the same vertices (one mesh in several materials) say so.
        let _ = match mesh.parts()[..k].iter().position(|q| q.vertices == p.vertices) {
            Some(first) => writeln!(s, "  {:?}: {} triangles, over primitive {first}'s vertices", p.name, p.indices.len() / 3),
            None => writeln!(s, "  {:?}: {} vertices, {} triangles", p.name, p.vertices.len(), p.indices.len() / 3),
        };
    }
    let _ = writeln!(s, "total: {} vertices, {} triangles", mesh.vertex_count(), mesh.triangle_count());
    let per_joint = mesh.vertices_per_joint();
    let skeleton = &model.skeleton;
    let _ = writeln!(s, "skeleton: {} joints, {} bones with influences", skeleton.len(), mesh.bone_count());
    let joints = skeleton.joints();
    let depth = |mut j: usize| {
        let mut d = 0;
        while let Some(p) = joints[j].parent {
            d += 1;
            j = p;
        }
        d
    };
    for &j in skeleton.order() {
        let role = if per_joint[j] > 0 { format!("{} vertices", per_joint[j]) } else { "no vertices".into() };
        let _ = writeln!(s, "  {}{} ({role})", "  ".repeat(depth(j)), joints[j].name);
    }
    let hist = mesh.influence_histogram();
    let counts: Vec<String> = hist.iter().enumerate().skip(1).map(|(i, n)| format!("{i}: {n}")).collect();
    let _ = writeln!(s, "influences per vertex: at most {} (vertices with 1..{}: {})", mesh.max_influences(), hist.len() - 1, counts.join(", "));
    let present = webxr::JOINT_NAMES.iter().filter(|n| skeleton.find(n).is_some()).count();
    if present == webxr::JOINT_NAMES.len() {
        let flat = webxr::JOINT_NAMES.iter().skip(1).any(|n| {
            let j = skeleton.find(n).expect("present");
            joints[j].parent.map(|p| joints[p].name.as_str()) != webxr::anatomical_parent(n)
        });
        let chain = if flat { "stored flat; joint angles pose it on the anatomical chain wrist → metacarpal → phalanges" } else { "anatomical chain" };
        let models: Vec<String> = JointModel::ALL.iter().map(|m| format!("{m} ({} DOF)", m.dof_count())).collect();
        let _ = writeln!(s, "WebXR hand joints: all 25 ({chain}); joint models: {}", models.join(", "));
    } else {
        let _ = writeln!(s, "WebXR hand joints: {present} of 25; pose it with local_rotations");
    }
    s
}
