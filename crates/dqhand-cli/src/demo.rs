//! `dqhand demo`: the built-in hand posed through the gesture library with LB, QB and DQB.

use std::path::PathBuf;
use std::time::Instant;

use dqhand::gesture::GESTURES;
use dqhand::io::{PoseFile, PoseTarget};
use dqhand::kinematics::{JointModel, Limits};
use dqhand::skin::{Deformed, Deformer, Method};

/// Arguments of `dqhand demo`.
#[derive(clap::Args)]
pub struct Args {
    /// Directory for the posed meshes, the pose files and the rigged hand.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = dqhand::io::load_model("builtin")?;
    std::fs::create_dir_all(&args.out).map_err(|e| anyhow::anyhow!("{}: {e}", args.out.display()))?;
    let rigged = args.out.join("hand.glb");
    dqhand::io::write_skinned_glb(&model, &rigged)?;
    println!("{}", model.description);
    println!("rigged, skinned hand: {}", rigged.display());
    let mut deformers: Vec<Deformer> = Method::ALL.iter().map(|&m| Deformer::new(m, &model.mesh)).collect();
    let mut out = Deformed::new(&model.mesh);
    println!("{:<10} {:>9} {:>9} {:>9}  files", "gesture", "LB µs", "QB µs", "DQB µs");
    for (i, g) in GESTURES.iter().enumerate() {
        let pose = g.pose(JointModel::Full);
        let stem = format!("{i:02}-{}", g.name);
        let pose_path = args.out.join(format!("{stem}.pose.json"));
        let file = PoseFile::from_pose(JointModel::Full, &pose);
        std::fs::write(&pose_path, serde_json::to_string_pretty(&file)?).map_err(|e| anyhow::anyhow!("{}: {e}", pose_path.display()))?;
        let target = PoseTarget::Angles { model: JointModel::Full, pose };
        let (skinning, warnings) = model.pose_skinning(&target, Limits::Anatomical)?;
        crate::warn_all(&warnings);
        let mut times = Vec::new();
        for d in &mut deformers {
            let t = Instant::now();
            d.deform(&model.mesh, &skinning, &mut out);
            times.push(t.elapsed().as_secs_f64() * 1e6);
            let path = args.out.join(format!("{stem}.{}.glb", d.method()));
            dqhand::io::write_posed(&path, out.positions(), out.normals(), model.mesh.uvs(), model.mesh.indices())?;
        }
        println!("{:<10} {:>9.1} {:>9.1} {:>9.1}  {stem}.{{lb,qb,dqb}}.glb, {stem}.pose.json", g.name, times[0], times[1], times[2]);
    }
    println!("(single frames, cold; `dqhand bench` gives medians over many frames)");
    Ok(())
}
