//! `dqhand skin`: pose a mesh and write it with normals; or, with `--poses`, a batch of poses
//! deformed across all cores and written one file each.

use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use dqhand::engine::ModelSource;
use dqhand::io::PoseFile;
use dqhand::kinematics::Limits;
use dqhand::skin::{Deformed, Deformer, Method, SelfContactPass};

/// Arguments of `dqhand skin`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file, or `builtin` for the built-in hand.
    #[arg(long, default_value = "builtin")]
    mesh: ModelSource,
    /// Pose file (JSON, see the README); the rest pose if omitted.
    #[arg(long, conflicts_with = "poses")]
    pose: Option<PathBuf>,
    /// Many poses, one pose file object per line (JSON lines; `dqhand replay --out` writes
    /// them: their `t` and `tracking` are ignored): each is deformed, the poses split across
    /// all cores, and written into the directory `--out` as `pose-00000.<format>`, ….
    #[arg(long)]
    poses: Option<PathBuf>,
    /// The files' format with `--poses`.
    #[arg(long, default_value = "glb", value_parser = ["glb", "ply", "obj"], requires = "poses")]
    format: String,
    /// Skinning method.
    #[arg(long, default_value = "dqb")]
    method: Method,
    /// Output mesh: .ply, .obj or .glb (vertex order and count of the input); with
    /// `--poses`, a directory.
    #[arg(long)]
    out: PathBuf,
    /// Use joint angles as given instead of clamping them to anatomical limits.
    #[arg(long)]
    no_limits: bool,
    /// Move the skin of each part of the hand out of the others' after skinning (the contact
    /// pass: a fist's fingertips lie on the palm, not in it).
    #[arg(long)]
    contact_pass: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = args.mesh.load()?;
    crate::warn_all(&model.warnings);
    if let Some(poses) = &args.poses {
        return batch(args, model, poses);
    }
    let pose = match &args.pose {
        Some(p) => PoseFile::load(p)?,
        None => PoseFile::default(),
    };
    let origin = args.pose.clone().unwrap_or_else(|| "rest pose".into());
    let target = pose.resolve(&model.skeleton).map_err(|e| e.in_file(&origin))?;
    let model = Arc::new(model);
    let (layer, clamped) = model.pose_target(&target, limits(args)).map_err(|e| e.in_file(&origin))?;
    crate::warn_clamped(&origin.display().to_string(), &clamped);
    let mut out = Deformed::new(&model.mesh);
    Deformer::new(args.method, &model.mesh).deform(&model.mesh, &layer, &mut out);
    let pushed = args.contact_pass.then(|| SelfContactPass::new(&model.mesh, &model.skeleton).apply(layer.skinning(), &mut out).pushed);
    dqhand::io::write_posed(&args.out, out.positions(), out.normals(), model.mesh.uvs(), model.mesh.indices())?;
    println!(
        "wrote {} ({} vertices, {} triangles, {}{})",
        args.out.display(),
        model.mesh.vertex_count(),
        model.mesh.triangle_count(),
        args.method,
        pushed.map_or_else(String::new, |n| format!("; the contact pass moved {n} vertices out of other skin"))
    );
    Ok(())
}

/// `--poses`: every pose's skinning transforms by the kinematics (one thread), then one
/// batch deformation across all cores ([`Deformer::deform_batch`]), then the files.
fn batch(args: &Args, model: dqhand::model::Model, path: &Path) -> anyhow::Result<()> {
    let poses = read_poses(path)?;
    anyhow::ensure!(!poses.is_empty(), "{}: no pose", path.display());
    let model = Arc::new(model);
    let mut skinning = Vec::with_capacity(poses.len() * model.mesh.inverse_bind().len());
    for (i, pose) in poses.iter().enumerate() {
        let at = |e: dqhand::Error| anyhow::anyhow!("{}: line {}: {e}", path.display(), i + 1);
        let target = pose.resolve(&model.skeleton).map_err(at)?;
        // Each line may use another joint model, or local rotations.
        let (layer, clamped) = model.pose_target(&target, limits(args)).map_err(at)?;
        crate::warn_clamped(&format!("{}: line {}", path.display(), i + 1), &clamped);
        skinning.extend_from_slice(layer.skinning());
    }
    let mesh = &model.mesh;
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cores).build()?;
    let mut out = vec![Deformed::new(mesh); poses.len()];
    let deformer = Deformer::new(args.method, mesh);
    let t = Instant::now();
    deformer.deform_batch(&pool, mesh, &skinning, &mut out);
    let seconds = t.elapsed().as_secs_f64();
    if args.contact_pass {
        let mut pass = SelfContactPass::new(mesh, &model.skeleton);
        let joints = mesh.inverse_bind().len();
        for (o, skinning) in out.iter_mut().zip(skinning.chunks_exact(joints)) {
            pass.apply(skinning, o);
        }
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create the directory", args.out.display()))?;
    for (i, o) in out.iter().enumerate() {
        let file = args.out.join(format!("pose-{i:05}.{}", args.format));
        dqhand::io::write_posed(&file, o.positions(), o.normals(), mesh.uvs(), mesh.indices())?;
    }
    println!(
        "deformed {} poses of {} vertices with {} on {cores} threads ({} kernel) in {:.1} ms: {:.0} frames/s; wrote {}/pose-*.{}",
        poses.len(),
        mesh.vertex_count(),
        args.method,
        deformer.kernel().name(),
        seconds * 1e3,
        poses.len() as f64 / seconds,
        args.out.display(),
        args.format
    );
    Ok(())
}

/// The pose files of a JSON lines file; a bad line is an error naming the file and line.
fn read_poses(path: &Path) -> anyhow::Result<Vec<PoseFile>> {
    let file = std::fs::File::open(path).with_context(|| format!("{}: cannot open", path.display()))?;
    let mut poses = Vec::new();
    for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line = line.with_context(|| format!("{}: line {}", path.display(), i + 1))?;
        if line.trim().is_empty() {
            continue;
        }
        let bad = |e: serde_json::Error| anyhow::anyhow!("{}: line {}: not a pose: {e}", path.display(), i + 1);
        let mut value: serde_json::Value = serde_json::from_str(&line).map_err(bad)?;
        if let Some(object) = value.as_object_mut() {
            object.remove("t");
            object.remove("tracking");
        }
        poses.push(serde_json::from_value(value).map_err(bad)?);
    }
    Ok(poses)
}

/// The limits `--no-limits` asks for.
fn limits(args: &Args) -> Limits {
    if args.no_limits {
        Limits::Off
    } else {
        Limits::Anatomical
    }
}
