//! `dqhand export-skinning`: one posed frame of the built-in hand, written for other skinning
//! implementations to run on (`make bench-peers`, bench/peers), with dqhand's own output and
//! timing of that frame to compare them with.
//!
//! Files written to `--out`:
//! * `rig.bin` — little-endian arrays, back to back, each 4-byte aligned;
//! * `rig.json` — counts, the pose, and per array its dtype (`float32` or `uint32`), shape and
//!   byte offset in `rig.bin`:
//!   `rest_positions`, `rest_normals` (#V×3), `joints` and `weights` (#V×4, heaviest first,
//!   zero-padded), `triangles` (#F×3), `skinning` (#joints×16: world · inverse bind, 4×4
//!   column-major, exactly what LB blends), and dqhand's own `lb_positions`, `lb_normals`,
//!   `dqb_positions`, `dqb_normals` (#V×3) for this pose;
//! * `dqhand.json` — µs per frame of LB and DQB (positions and normals, one thread).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use dqhand::engine::ModelSource;
use dqhand::gesture::gesture;
use dqhand::hand::HandParams;
use dqhand::io::PoseFile;
use dqhand::kinematics::{JointModel, Limits, Pose};
use dqhand::math::DualQuat;
use dqhand::skin::{Deformed, Deformer, Method, SkinnedMesh};
use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Map, Value};

/// Influence slots per vertex in the export: what three.js's `skinIndex`/`skinWeight` hold.
const SLOTS: usize = 4;

/// What the default pose is, for rig.json.
const DEFAULT_POSE: &str = "gesture fist (full joint model), wrist turned 50° about an oblique axis";

/// Arguments of `dqhand export-skinning`.
#[derive(clap::Args)]
pub struct Args {
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Pose file (JSON, see the README); default: the library's fist with the wrist turned.
    #[arg(long)]
    pose: Option<PathBuf>,
    /// Frames timed per method.
    #[arg(long, default_value_t = 2000)]
    frames: usize,
    /// Use the pose file's joint angles as given instead of clamping them to anatomical limits.
    #[arg(long)]
    no_limits: bool,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.frames > 0, "--frames must be at least 1");
    let model = Arc::new(ModelSource::Builtin(HandParams::default()).load()?);
    crate::warn_all(&model.warnings);
    let (layer, pose) = match &args.pose {
        Some(path) => {
            let target = PoseFile::load(path)?.resolve(&model.skeleton).map_err(|e| e.in_file(path))?;
            let limits = if args.no_limits { Limits::Off } else { Limits::Anatomical };
            let (layer, clamped) = model.pose_target(&target, limits).map_err(|e| e.in_file(path))?;
            crate::warn_clamped(&path.display().to_string(), &clamped);
            (layer, path.display().to_string())
        }
        None => {
            let mut hand = model.hand_kinematics(JointModel::Full)?;
            let pose = default_pose(hand.rig().rest_wrist())?;
            hand.pose(&pose);
            (hand.into_layer(), DEFAULT_POSE.to_owned())
        }
    };
    let mesh = &model.mesh;
    anyhow::ensure!(mesh.max_influences() <= SLOTS, "the hand has vertices with more than {SLOTS} influences");
    let skinning = layer.skinning();

    // Same timing as `dqhand bench` (warm-up, then LB and DQB alternating frame by frame), but
    // on this one pose and through the public deformer, as the peers are timed.
    let mut runs = [Method::Lb, Method::Dqb].map(|m| (m, Deformer::new(m, mesh), Deformed::new(mesh), Vec::with_capacity(args.frames)));
    for _ in 0..100 {
        for (_, deformer, out, _) in &mut runs {
            deformer.deform(mesh, skinning, out);
        }
    }
    for f in 0..args.frames {
        for k in 0..2 {
            let (_, deformer, out, samples) = &mut runs[(f + k) % 2];
            let t = Instant::now();
            deformer.deform(mesh, skinning, out);
            samples.push(t.elapsed().as_secs_f64() * 1e6);
            std::hint::black_box(out.positions());
        }
    }

    let mut bin = Bin::default();
    bin.f32("rest_positions", 3, mesh.positions().as_flattened());
    bin.f32("rest_normals", 3, mesh.normals().as_flattened());
    let (joints, weights) = influences(mesh);
    bin.u32("joints", SLOTS, &joints);
    bin.f32("weights", SLOTS, &weights);
    bin.u32("triangles", 3, mesh.indices());
    let matrices: Vec<f32> = skinning.iter().flat_map(|m| Mat4::from(*m).to_cols_array()).collect();
    bin.f32("skinning", 16, &matrices);
    let mut timings = Map::new();
    for (method, _, out, samples) in &mut runs {
        bin.f32(&format!("{method}_positions"), 3, out.positions().as_flattened());
        bin.f32(&format!("{method}_normals"), 3, out.normals().as_flattened());
        let q = |s: &mut Vec<f64>, q| dqhand::math::quantile(s, q).expect("frames were timed");
        timings.insert(method.to_string(), json!({ "us_per_frame": q(samples, 0.5), "p10_us": q(samples, 0.1), "p90_us": q(samples, 0.9) }));
    }

    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let rig = json!({
        "mesh": "builtin",
        "pose": pose,
        "vertices": mesh.vertex_count(),
        "triangles": mesh.triangle_count(),
        "joints": skinning.len(),
        "influences": SLOTS,
        "byte_order": "little",
        "arrays": bin.arrays,
    });
    let kernel = dqhand::skin::Kernel::best().name();
    let timing = json!({ "frames": args.frames, "threads": 1, "kernel": kernel, "computes": "positions and normals", "methods": timings });
    write(&args.out.join("rig.bin"), &bin.bytes)?;
    write(&args.out.join("rig.json"), serde_json::to_string_pretty(&rig)?.as_bytes())?;
    write(&args.out.join("dqhand.json"), serde_json::to_string_pretty(&timing)?.as_bytes())?;
    println!("wrote {} ({} vertices, {} joints; {pose})", args.out.display(), mesh.vertex_count(), skinning.len());
    Ok(())
}

/// The fist, with the wrist turned about an oblique axis so that no bone's rotation is axis
/// aligned (a quaternion conversion then meets the general case, not a special one).
fn default_pose(rest_wrist: DualQuat) -> anyhow::Result<Pose> {
    let mut pose = gesture("fist")?.pose(JointModel::Full);
    let (rotation, translation) = rest_wrist.to_rotation_translation();
    let turn = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 50f32.to_radians());
    pose.wrist = Some(DualQuat::from_rotation_translation(turn * rotation, translation));
    Ok(pose)
}

/// Joint indices and weights, [`SLOTS`] per vertex as the mesh blends them (heaviest first),
/// unused slots joint 0 with weight 0.
fn influences(mesh: &SkinnedMesh) -> (Vec<u32>, Vec<f32>) {
    let n = mesh.vertex_count();
    let (mut joints, mut weights) = (vec![0u32; n * SLOTS], vec![0f32; n * SLOTS]);
    for v in 0..n {
        for (s, (j, w)) in mesh.influences(v).enumerate() {
            joints[v * SLOTS + s] = j as u32;
            weights[v * SLOTS + s] = w;
        }
    }
    (joints, weights)
}

/// rig.bin being built, and its table of contents for rig.json.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    arrays: Map<String, Value>,
}

impl Bin {
    fn f32(&mut self, name: &str, columns: usize, values: &[f32]) {
        self.push(name, "float32", columns, values.iter().flat_map(|v| v.to_le_bytes()), values.len());
    }

    fn u32(&mut self, name: &str, columns: usize, values: &[u32]) {
        self.push(name, "uint32", columns, values.iter().flat_map(|v| v.to_le_bytes()), values.len());
    }

    fn push(&mut self, name: &str, dtype: &str, columns: usize, bytes: impl Iterator<Item = u8>, len: usize) {
        let offset = self.bytes.len();
        self.bytes.extend(bytes);
        self.arrays.insert(name.to_owned(), json!({ "dtype": dtype, "shape": [len / columns, columns], "offset": offset }));
    }
}

fn write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}
