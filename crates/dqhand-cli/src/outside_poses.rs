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
//! joint noise; "no gesture" holds are labelled `none`. [`both_hands`] plays handy-work's
//! pairs (both hands of one capture, or of two) at once, for a two-handed loop.

use std::path::Path;

use anyhow::Context;
use dqhand::hand::{HandParams, Side};
use dqhand::input::{HandData, JointSet, Record, TrackedJoint};
use dqhand::interaction::synthetic::{Label, Synthetic};
use dqhand::math::Rng;
use glam::{Affine3A, Mat4, Quat, Vec3};

/// One recorded pose: what it shows, which hand, the capture it is a hand of (its source and
/// file: handy-work recorded both hands at once), and its 25 joints relative to the wrist
/// (WebXR order).
pub struct OutsidePose {
    pub gesture: &'static str,
    pub side: Side,
    pub capture: (&'static str, &'static str),
    pub joints: [(Vec3, Quat); 25],
}

/// The source whose captures hold both hands.
const HANDY_WORK_SOURCE: &str = "handy-work";
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
            poses.push(OutsidePose { gesture, side, capture: (HANDY_WORK_SOURCE, file), joints: joints(m)? });
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
        poses.push(OutsidePose { gesture, side: Side::Left, capture: ("iwer", file), joints: joints(|j| &matrices[j])? });
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

/// Records per second of the sequences.
pub const RATE_HZ: f64 = 60.0;
/// Seconds from one pose to the next.
const MOVE_S: f64 = 0.4;
/// Seconds each pose is held.
const HOLD_S: f64 = 1.5;
/// Joint noise, m RMS over the three axes.
const NOISE_M: f32 = 0.0015;

/// Where a hand is held: its wrist's position and rotation (palm down at identity).
#[derive(Clone, Copy)]
struct Placement {
    at: Vec3,
    turn: Quat,
}

/// The joints of `to` placed at `place`, eased from `from` (the previous pose and placement) by
/// `s` in 0..=1 (positions lerped and orientations slerped in the wrist's frame), with noise.
fn joints_at(from: Option<(&OutsidePose, Placement)>, to: (&OutsidePose, Placement), s: f32, rng: &mut Rng) -> JointSet {
    let s = s * s * (3.0 - 2.0 * s);
    let mut set = JointSet::new();
    for j in 0..25 {
        let (to_p, to_q) = to.0.joints[j];
        let (position, orientation) = match from {
            Some((f, from_place)) => {
                let (fp, fq) = f.joints[j];
                let r = from_place.turn.slerp(to.1.turn, s);
                (from_place.at + (to.1.at - from_place.at) * s + r * fp.lerp(to_p, s), r * fq.slerp(to_q, s))
            }
            None => (to.1.at + to.1.turn * to_p, to.1.turn * to_q),
        };
        let noise = rng.normal_vec3() * (NOISE_M / 3f32.sqrt());
        set.set(j, TrackedJoint { position: position + noise, orientation: Some(orientation.normalize()), radius: 0.0 });
    }
    set
}

/// `round` shuffled in place (seeded), its first not equal to `after`'s last.
fn shuffle<T: PartialEq>(round: &mut [T], after: Option<&T>, rng: &mut Rng) {
    for i in (1..round.len()).rev() {
        round.swap(i, rng.below(i + 1));
    }
    if after.is_some() && after == round.first() && round.len() > 1 {
        round.swap(0, 1);
    }
}

/// The poses of one `side`, `repeats` times in shuffled orders, as a labelled joint
/// recording (module docs); seeded.
#[must_use]
pub fn sequence(poses: &[OutsidePose], side: Side, repeats: usize, seed: u64) -> Synthetic {
    let mut rng = Rng::new(seed);
    let mine: Vec<&OutsidePose> = poses.iter().filter(|p| p.side == side).collect();
    let mut order = Vec::new();
    for _ in 0..repeats {
        let mut round: Vec<usize> = (0..mine.len()).collect();
        shuffle(&mut round, order.last(), &mut rng);
        order.extend(round);
    }
    // Palm down at chest height, turned up to 80° about a random axis per hold.
    let places: Vec<Placement> = order.iter().map(|_| Placement { at: Vec3::new(0.0, 1.2, -0.35), turn: Quat::from_axis_angle(rng.unit(), rng.uniform(-80.0, 80.0).to_radians() as f32) }).collect();
    let (mut records, mut labels) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    for (h, &p) in order.iter().enumerate() {
        let from = h.checked_sub(1).map(|g| (mine[order[g]], places[g]));
        let reached = t + MOVE_S;
        labels.push(Label { gesture: mine[p].gesture.to_owned(), reached, until: reached + HOLD_S });
        while t < reached + HOLD_S {
            let s = ((t - reached + MOVE_S) / MOVE_S).clamp(0.0, 1.0) as f32;
            let set = joints_at(from, (mine[p], places[h]), s, &mut rng);
            records.push(Record { time: t, side, hand: Some(HandData::Joints(set)), tracker: None, arrival: None });
            t += 1.0 / RATE_HZ;
        }
    }
    Synthetic { hand: HandParams { side, ..HandParams::default() }, records, truth: Vec::new(), labels, idle: (t, t) }
}

/// One hold of both hands: each hand's pose, and whether the hands are held together.
pub struct PairHold {
    pub left: &'static str,
    pub right: &'static str,
    /// Palms facing each other, the wrists 8 cm apart (else 40 cm apart, palms down).
    pub together: bool,
    /// When it ends (s): held from `HOLD_S` before.
    pub until: f64,
}

/// Both hands at once: each handy-work capture's left and right hand as they were recorded
/// together, 40 cm apart; as many pairs of one capture's left hand with another capture's
/// right one; and the flat hands held together, palms facing (a two-hand gesture). Each
/// round shuffled, `repeats` rounds, both hands' records at the same times; seeded.
#[must_use]
pub fn both_hands(poses: &[OutsidePose], repeats: usize, seed: u64) -> (Vec<Record>, Vec<PairHold>) {
    let mut rng = Rng::new(seed);
    let side = |s: Side| -> Vec<&OutsidePose> { poses.iter().filter(|p| p.side == s && p.capture.0 == HANDY_WORK_SOURCE).collect() };
    let (lefts, rights) = (side(Side::Left), side(Side::Right));
    let n = lefts.len().min(rights.len());
    let own = |i: usize| rights.iter().position(|r| r.capture == lefts[i].capture);
    let mut order: Vec<(usize, usize, bool)> = Vec::new();
    for _ in 0..repeats {
        let mut round: Vec<(usize, usize, bool)> = (0..lefts.len()).filter_map(|i| own(i).map(|r| (i, r, false))).collect();
        // Another capture's right hand for each left one: the captures turned by 1..n−1.
        if n > 1 {
            let turn = 1 + rng.below(n - 1);
            round.extend((0..n).filter_map(|i| own(i).map(|r| (i, (r + turn) % n, false))));
        }
        if let Some(flat) = lefts.iter().position(|p| p.capture.1 == "flat") {
            round.extend(own(flat).map(|r| (flat, r, true)));
        }
        shuffle(&mut round, order.last(), &mut rng);
        order.extend(round);
    }
    // Apart: palms down at chest height, each turned up to 40°; together: palms facing, the
    // left hand's towards +x.
    let place = |together: bool, sign: f32, rng: &mut Rng| {
        if together {
            Placement { at: Vec3::new(0.04 * sign, 1.2, -0.35), turn: Quat::from_rotation_z(-sign * std::f32::consts::FRAC_PI_2) }
        } else {
            Placement { at: Vec3::new(0.2 * sign, 1.2, -0.35), turn: Quat::from_axis_angle(rng.unit(), rng.uniform(-40.0, 40.0).to_radians() as f32) }
        }
    };
    let places: Vec<[Placement; 2]> = order.iter().map(|&(_, _, together)| [place(together, -1.0, &mut rng), place(together, 1.0, &mut rng)]).collect();
    let (mut records, mut holds) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    for (h, &(l, r, together)) in order.iter().enumerate() {
        let reached = t + MOVE_S;
        holds.push(PairHold { left: lefts[l].gesture, right: rights[r].gesture, together, until: reached + HOLD_S });
        while t < reached + HOLD_S {
            let s = ((t - reached + MOVE_S) / MOVE_S).clamp(0.0, 1.0) as f32;
            for (k, (hand, pose)) in [(Side::Left, lefts[l]), (Side::Right, rights[r])].into_iter().enumerate() {
                let from = h.checked_sub(1).map(|g| (if k == 0 { lefts[order[g].0] } else { rights[order[g].1] }, places[g][k]));
                let set = joints_at(from, (pose, places[h][k]), s, &mut rng);
                records.push(Record { time: t, side: hand, hand: Some(HandData::Joints(set)), tracker: None, arrival: None });
            }
            t += 1.0 / RATE_HZ;
        }
    }
    (records, holds)
}
