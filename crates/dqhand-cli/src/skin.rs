//! `dqhand skin`: pose a mesh and write it with normals.

use std::path::PathBuf;

use dqhand::io::PoseFile;
use dqhand::kinematics::Limits;
use dqhand::skin::{Deformed, Deformer, Method};

/// Arguments of `dqhand skin`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: String,
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
    let model = dqhand::io::load_model(&args.mesh)?;
    crate::warn_all(&model.warnings);
    let pose = match &args.pose {
        Some(p) => PoseFile::load(p)?,
        None => PoseFile::default(),
    };
    let origin = args.pose.clone().unwrap_or_else(|| "rest pose".into());
    let target = pose.resolve(&model).map_err(|e| e.in_file(&origin))?;
    let limits = if args.no_limits { Limits::Off } else { Limits::Anatomical };
    let (skinning, warnings) = model.pose_skinning(&target, limits).map_err(|e| e.in_file(&origin))?;
    crate::warn_all(&warnings);
    let mut out = Deformed::new(&model.mesh);
    Deformer::new(args.method, &model.mesh).deform(&model.mesh, &skinning, &mut out);
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
