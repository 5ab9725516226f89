//! How people actually make each gesture, as a generator of varied hand shapes: the
//! evaluation a recogniser is not fitted to. The library's poses are one way to make each
//! gesture; people tuck the thumb over the fingers, along the index or across the palm, curl
//! a fist anywhere from loose to tight and unevenly, spread their fingers more or less. Every
//! gesture here is drawn from ranges of joint angles (degrees, `full` joint model), per finger:
//!
//! | finger state | MCP flexion | PIP | DIP |
//! |---|---|---|---|
//! | extended (as real hands hold them: rarely straight) | −10…35 | 0…45 | 0…35 |
//! | curled (a fist's depth d ∈ 0…1 per hand, ±10° per finger) | 60 + 30d | 75 + 35d | 35 + 45d |
//! | half (a pinch's others, half of the time) | 30…85 | 35…105 | 15…70 |
//!
//! and the thumb in one of the placements each gesture allows ([`Thumb`]). The ambiguous pairs
//! are told apart by what the definitions say (`docs/gestures.md`): a point is a point wherever
//! its thumb is (tucked, or out to the side as the Quest poses others recorded hold it), so
//! there is no built-in gun (learn one: `dqhand learn-gesture`); a three's little finger is
//! curled, a four's thumb is folded across the palm (an open palm's is out or alongside the index). OK and pinch
//! both touch the thumb and index tips: in an OK the index curls round (a ring: MCP 40–55°,
//! PIP 65–80°, DIP 30–45°) and the other three stand extended; in a pinch the index stays
//! flatter (MCP 25–50°, PIP 25–50°, DIP 5–25°) and the others are extended or half curled, as
//! XR's select pinch and a precision grip make it.
//!
//! The splits: every random choice comes from the sequence's seed mixed with its [`Split`], so
//! the sequences a classifier is trained on ([`Split::Tune`]) and those it is measured on
//! ([`Split::HeldOut`]) never share a hand, a shape or a noise draw.

use crate::kinematics::{JointModel, Pose};
use crate::math::Rng;
use crate::Result;

/// Which part of the varied sequences: tune on one, report on the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Training and tuning thresholds.
    Tune,
    /// Reporting only: never trained or tuned on.
    HeldOut,
}

impl Split {
    /// Mixes the split into a sequence's seed.
    #[must_use]
    pub fn seed(self, seed: u64) -> u64 {
        match self {
            Split::Tune => seed,
            Split::HeldOut => seed ^ 0xA5A5_5A5A_D00D_F00D,
        }
    }

    /// `tune` or `held-out`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Split::Tune => "tune",
            Split::HeldOut => "held-out",
        }
    }
}

impl core::str::FromStr for Split {
    type Err = String;

    /// The split [`Split::name`] names.
    fn from_str(s: &str) -> Result<Self, String> {
        [Split::Tune, Split::HeldOut].into_iter().find(|split| split.name() == s).ok_or_else(|| format!("{s:?}: expected held-out or tune"))
    }
}

/// The gestures the generator makes: the built-in set's (`data/gestures.json`).
pub const VARIED_GESTURES: [&str; 12] = ["open_palm", "fist", "point", "victory", "three", "four", "rock", "call_me", "thumbs_up", "thumbs_down", "ok", "pinch"];

/// Where the thumb is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Thumb {
    /// Folded over the middle phalanges of curled fingers.
    Over,
    /// Straight along the side of the index.
    Along,
    /// Folded across the palm.
    Across,
    /// Out: to the side in the palm's plane, or away from the palm (thumbs up, call me).
    Out,
    /// Touching the index's pad (OK, pinch): solved on the hand.
    OnIndex,
}

/// The placements a gesture allows.
fn thumbs(name: &str) -> &'static [Thumb] {
    match name {
        "fist" => &[Thumb::Over, Thumb::Along, Thumb::Across],
        "point" | "victory" | "rock" => &[Thumb::Over, Thumb::Along, Thumb::Across, Thumb::Out],
        "three" => &[Thumb::Over, Thumb::Across],
        "four" => &[Thumb::Across],
        "open_palm" => &[Thumb::Out, Thumb::Along],
        "ok" | "pinch" => &[Thumb::OnIndex],
        _ => &[Thumb::Out],
    }
}

/// Which fingers (index, middle, ring, little) are extended.
fn extended(name: &str) -> [bool; 4] {
    match name {
        "open_palm" | "four" | "ok" => [true; 4],
        "point" => [true, false, false, false],
        "victory" => [true, true, false, false],
        "three" => [true, true, true, false],
        "rock" => [true, false, false, true],
        "call_me" => [false, false, false, true],
        _ => [false; 4],
    }
}

const FINGERS: [&str; 4] = ["index-finger", "middle-finger", "ring-finger", "pinky-finger"];

/// A varied pose of gesture `name` (one of [`VARIED_GESTURES`]) with the wrist at rest, and
/// the thumb placement drawn. `gap` measures the thumb tip to index tip distance of a pose on
/// the user's hand (m), for the placements that touch.
///
/// # Errors
/// [`crate::Error::UnknownName`] for a gesture the generator does not make.
pub fn varied_pose(name: &str, rng: &mut Rng, mut gap: impl FnMut(&Pose) -> f32) -> Result<(Pose, Thumb)> {
    if !VARIED_GESTURES.contains(&name) {
        return Err(crate::Error::UnknownName { kind: "gesture (varied)", name: name.to_owned(), valid: VARIED_GESTURES.join(", ") });
    }
    let model = JointModel::Full;
    let mut pose = Pose::rest(model.dof_count());
    let mut set = |dof: &str, deg: f64| {
        let i = model.dof_index(dof).expect("the generator names DOFs of the full model");
        pose.angles[i] = (deg as f32).to_radians();
    };
    let depth = rng.next_f64();
    let relaxed_pinch = rng.next_f64() < 0.5;
    let open = extended(name);
    for (f, finger) in FINGERS.iter().enumerate() {
        let (mcp, pip, dip) = if open[f] || (name == "pinch" && relaxed_pinch) {
            (rng.uniform(-10.0, 35.0), rng.uniform(0.0, 45.0), rng.uniform(0.0, 35.0))
        } else if name == "pinch" {
            (rng.uniform(30.0, 85.0), rng.uniform(35.0, 105.0), rng.uniform(15.0, 70.0))
        } else {
            (60.0 + 30.0 * depth + rng.uniform(-10.0, 10.0), 75.0 + 35.0 * depth + rng.uniform(-10.0, 10.0), 35.0 + 45.0 * depth + rng.uniform(-10.0, 10.0))
        };
        set(&format!("{finger}-phalanx-proximal.flex"), mcp);
        set(&format!("{finger}-phalanx-intermediate.flex"), pip);
        set(&format!("{finger}-phalanx-distal.flex"), dip);
        let spread = match (f, open[f]) {
            (0, true) if name == "victory" => rng.uniform(8.0, 20.0),
            (1, true) if name == "victory" => rng.uniform(-15.0, -5.0),
            (0, true) => rng.uniform(-5.0, 20.0),
            (1, true) => rng.uniform(-10.0, 10.0),
            (2, true) => rng.uniform(-8.0, 15.0),
            (3, true) => rng.uniform(0.0, 30.0),
            _ => rng.uniform(-3.0, 3.0),
        };
        set(&format!("{finger}-phalanx-proximal.abd"), spread);
    }
    set("ring-finger-metacarpal.flex", rng.uniform(0.0, 10.0));
    set("pinky-finger-metacarpal.flex", rng.uniform(0.0, 20.0));
    if name == "ok" || name == "pinch" {
        // The index bent to meet the thumb: a round OK, a flatter pinch.
        let (mcp, pip, dip) = if name == "ok" { (rng.uniform(40.0, 55.0), rng.uniform(65.0, 80.0), rng.uniform(30.0, 45.0)) } else { (rng.uniform(25.0, 50.0), rng.uniform(25.0, 50.0), rng.uniform(5.0, 25.0)) };
        set("index-finger-phalanx-proximal.flex", mcp);
        set("index-finger-phalanx-intermediate.flex", pip);
        set("index-finger-phalanx-distal.flex", dip);
    }
    let placements = thumbs(name);
    let thumb = placements[rng.below(placements.len())];
    // CMC abduction and flexion, MCP abduction (real thumbs turn it −5…−13° out: the Quest
    // poses retargeted) and flexion, IP flexion.
    let thumb_dofs = ["thumb-metacarpal.abd", "thumb-metacarpal.flex", "thumb-phalanx-proximal.abd", "thumb-phalanx-proximal.flex", "thumb-phalanx-distal.flex"];
    let ranges: [(f64, f64); 5] = match thumb {
        Thumb::Over => [(0.0, 20.0), (0.0, 20.0), (-10.0, 10.0), (20.0, 45.0), (50.0, 80.0)],
        Thumb::Along => [(-10.0, 5.0), (-5.0, 10.0), (-15.0, 5.0), (0.0, 25.0), (0.0, 30.0)],
        Thumb::Across => [(-10.0, 5.0), (25.0, 45.0), (-10.0, 10.0), (40.0, 60.0), (40.0, 75.0)],
        Thumb::Out => [(0.0, 50.0), (-20.0, 0.0), (-15.0, 5.0), (-10.0, 15.0), (-15.0, 15.0)],
        Thumb::OnIndex => [(0.0, 40.0), (10.0, 45.0), (-10.0, 10.0), (-10.0, 30.0), (0.0, 60.0)],
    };
    let draw = |rng: &mut Rng, pose: &mut Pose| {
        for (dof, (lo, hi)) in thumb_dofs.iter().zip(ranges) {
            pose.angles[model.dof_index(dof).expect("a thumb DOF of the full model")] = (rng.uniform(lo, hi) as f32).to_radians();
        }
    };
    draw(rng, &mut pose);
    if thumb == Thumb::OnIndex {
        // The pads touch: tip joints (the fingertips' ends) 10–18 mm apart. The best of a random
        // search over the thumb's range, as a person finds the index by feel.
        let target = rng.uniform(0.010, 0.018) as f32;
        let mut best = (f32::INFINITY, pose.clone());
        let mut trial = pose.clone();
        for _ in 0..80 {
            draw(rng, &mut trial);
            let miss = (gap(&trial) - target).abs();
            if miss < best.0 {
                best = (miss, trial.clone());
            }
        }
        pose = best.1;
    }
    Ok((pose, thumb))
}
