//! Hand poses other people recorded with Quest hand tracking, labelled with the built-in
//! gestures, played as joint recordings: the gesture benchmark's data the project did not
//! make. They come from the npm registry into `third_party/node_modules` (`make assets`):
//!
//! * handy-work 3.1.13 (Ada Rose Cannon, MIT): `poses/*.handpose`, 25 joint matrices of a left
//!   and a right hand relative to the wrist (a float count, then 16 floats per joint, left
//!   hand then right, then weights). fist → `fist`, point → `point`, horns → `rock`, shaka →
//!   `call_me`, flat → `open_palm`, vulcan (all fingers out, split in two) → `open_palm`,
//!   relax → no gesture or an open palm (`none|open_palm`: the left hand's relax has every
//!   finger straight, curl ≤ 0.1, which is an open palm by its definition);
//! * IWER 2.5.0 (Meta, MIT): `lib/device/configs/hand/*.js`, a left hand's 25 `offsetMatrix`
//!   arrays. pinch → `pinch`, point → `point`, relaxed → `none|open_palm` (as relax).
//!
//! Each pose is held 1.5 s after a 0.4 s move (joint positions lerped and orientations
//! slerped in the wrist's frame), the wrist turned up to 80° from palm-down, with 1.5 mm of
//! joint noise; "no gesture" holds are labelled `none`.

use std::path::Path;

use anyhow::Context;
use dqhand::hand::{HandParams, Side};
use dqhand::input::{HandData, JointSet, Record, TrackedJoint};
use dqhand::interaction::synthetic::{Label, Synthetic};
use dqhand::math::Rng;
use glam::{Affine3A, Mat4, Quat, Vec3};

/// One recorded pose: what it shows, which hand, and its 25 joints relative to the wrist
/// (WebXR order).
pub struct OutsidePose {
    pub gesture: &'static str,
    pub side: Side,
    pub joints: [(Vec3, Quat); 25],
}

const HANDY_WORK: [(&str, &str); 7] = [("fist", "fist"), ("point", "point"), ("horns", "rock"), ("shaka", "call_me"), ("flat", "open_palm"), ("vulcan", "open_palm"), ("relax", "none|open_palm")];
const IWER: [(&str, &str); 3] = [("pinch", "pinch"), ("point", "point"), ("relaxed", "none|open_palm")];

/// Reads every pose from `node_modules` (third_party's).
///
/// # Errors
/// A file that is missing (naming it and `make assets`) or not of its format.
pub fn load(node_modules: &Path) -> anyhow::Result<Vec<OutsidePose>> {
    let mut poses = Vec::new();
    for (file, gesture) in HANDY_WORK {
        let path = node_modules.join(format!("handy-work/poses/{file}.handpose"));
        let bytes = std::fs::read(&path).with_context(|| format!("{}: hand poses others recorded are missing; run `make assets`", path.display()))?;
        let floats: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        anyhow::ensure!(floats.first() == Some(&25.0) && floats.len() > 2 * 25 * 16, "{}: not a handy-work pose of 25 joints", path.display());
        for (k, side) in [(0, Side::Left), (1, Side::Right)] {
            let m = |j: usize| &floats[1 + (k * 25 + j) * 16..][..16];
            poses.push(OutsidePose { gesture, side, joints: joints(m)? });
        }
    }
    for (file, gesture) in IWER {
        let path = node_modules.join(format!("iwer/lib/device/configs/hand/{file}.js"));
        let text = std::fs::read_to_string(&path).with_context(|| format!("{}: hand poses others recorded are missing; run `make assets`", path.display()))?;
        let matrices: Vec<Vec<f32>> = text
            .split("offsetMatrix: [")
            .skip(1)
            .map(|rest| rest.split(']').next().unwrap_or("").split(',').filter_map(|v| v.trim().parse().ok()).collect())
            .collect();
        anyhow::ensure!(matrices.len() == 25 && matrices.iter().all(|m| m.len() == 16), "{}: expected 25 joint matrices of 16 numbers", path.display());
        poses.push(OutsidePose { gesture, side: Side::Left, joints: joints(|j| &matrices[j])? });
    }
    Ok(poses)
}

/// The 25 joints of column-major matrices, relative to the first (the wrist).
fn joints<'a>(matrix: impl Fn(usize) -> &'a [f32]) -> anyhow::Result<[(Vec3, Quat); 25]> {
    let wrist = Affine3A::from_mat4(Mat4::from_cols_slice(matrix(0))).inverse();
    let mut out = [(Vec3::ZERO, Quat::IDENTITY); 25];
    for (j, o) in out.iter_mut().enumerate() {
        let (_, rotation, translation) = (wrist * Affine3A::from_mat4(Mat4::from_cols_slice(matrix(j)))).to_scale_rotation_translation();
        anyhow::ensure!(translation.is_finite() && rotation.is_finite(), "joint {j} is not a finite transform");
        *o = (translation, rotation.normalize());
    }
    Ok(out)
}

/// The poses of one `side`, `repeats` times in shuffled orders, as a labelled joint
/// recording (module docs); seeded.
#[must_use]
pub fn sequence(poses: &[OutsidePose], side: Side, repeats: usize, seed: u64) -> Synthetic {
    const RATE_HZ: f64 = 60.0;
    const MOVE_S: f64 = 0.4;
    const HOLD_S: f64 = 1.5;
    let mut rng = Rng::new(seed);
    let mine: Vec<&OutsidePose> = poses.iter().filter(|p| p.side == side).collect();
    let mut order = Vec::new();
    for _ in 0..repeats {
        let mut round: Vec<usize> = (0..mine.len()).collect();
        for i in (1..round.len()).rev() {
            round.swap(i, rng.below(i + 1));
        }
        if order.last() == round.first() && round.len() > 1 {
            round.swap(0, 1);
        }
        order.extend(round);
    }
    // Palm down at chest height, turned up to 80° about a random axis per hold.
    let wrist_at = Vec3::new(0.0, 1.2, -0.35);
    let wrists: Vec<Quat> = order.iter().map(|_| Quat::from_axis_angle(rng.unit(), rng.uniform(-80.0, 80.0).to_radians() as f32)).collect();
    let (mut records, mut labels) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    for (h, &p) in order.iter().enumerate() {
        let from = h.checked_sub(1).map(|g| (mine[order[g]], wrists[g]));
        let reached = t + MOVE_S;
        labels.push(Label { gesture: mine[p].gesture.to_owned(), reached, until: reached + HOLD_S });
        while t < reached + HOLD_S {
            let s = (((t - reached + MOVE_S) / MOVE_S).clamp(0.0, 1.0)) as f32;
            let s = s * s * (3.0 - 2.0 * s);
            let mut set = JointSet::new();
            for j in 0..25 {
                let (to_p, to_q) = mine[p].joints[j];
                let (position, orientation) = match from {
                    Some((f, from_wrist)) => {
                        let (fp, fq) = f.joints[j];
                        let r = from_wrist.slerp(wrists[h], s);
                        (wrist_at + r * fp.lerp(to_p, s), r * fq.slerp(to_q, s))
                    }
                    None => (wrist_at + wrists[h] * to_p, wrists[h] * to_q),
                };
                let noise = rng.normal_vec3() * (0.0015 / 3f32.sqrt());
                set.set(j, TrackedJoint { position: position + noise, orientation: Some(orientation.normalize()), radius: 0.0 });
            }
            records.push(Record { time: t, side, hand: Some(HandData::Joints(set)), tracker: None, arrival: None });
            t += 1.0 / RATE_HZ;
        }
    }
    Synthetic { hand: HandParams { side, ..HandParams::default() }, records, truth: Vec::new(), labels, idle: (t, t) }
}
