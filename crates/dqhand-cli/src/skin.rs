//! `dqhand skin`: pose a mesh and write it with normals.

use std::path::PathBuf;

use std::sync::Arc;

use dqhand::engine::{Engine, ModelSource};
use dqhand::io::PoseFile;
use dqhand::kinematics::Limits;
use dqhand::skin::Method;

/// Arguments of `dqhand skin`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: ModelSource,
    /// Pose file (JSON, see the README); the rest pose if omitted.
    #[arg(long)]
    pose: Option<PathBuf>,
    /// Skinning method.
    #[arg(long, default_value = "dqb")]
    method: Method,
    /// Output mesh: .ply, .obj or .glb (vertex order and count of the input).
    #[arg(long)]
    out: PathBuf,
    /// Use joint angles as given instead of clamping them to anatomical limits.
    #[arg(long)]
    no_limits: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = args.mesh.load()?;
    crate::warn_all(&model.warnings);
    let pose = match &args.pose {
        Some(p) => PoseFile::load(p)?,
        None => PoseFile::default(),
    };
    let origin = args.pose.clone().unwrap_or_else(|| "rest pose".into());
    let target = pose.resolve(&model.skeleton).map_err(|e| e.in_file(&origin))?;
    let model = Arc::new(model);
    let mut engine = Engine::for_target(model.clone(), &target).map_err(|e| e.in_file(&origin))?;
    engine.set_limits(if args.no_limits { Limits::Off } else { Limits::Anatomical });
    crate::warn_all(&engine.pose_target(&target));
    let out = engine.skin(args.method);
    dqhand::io::write_posed(&args.out, out.positions(), out.normals(), model.mesh.uvs(), model.mesh.indices())?;
    println!(
        "wrote {} ({} vertices, {} triangles, {})",
        args.out.display(),
        model.mesh.vertex_count(),
        model.mesh.triangle_count(),
        args.method
    );
    Ok(())
}
