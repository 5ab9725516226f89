//! Both hands at once on poses other people recorded (`gesture-bench --outside`): handy-work
//! captured a left and a right hand together, and `outside_poses::both_hands` plays them into
//! one two-handed loop. At the end of every hold the bench reads what each hand shows and the
//! gesture of both hands (`hands_together`, `both_palms_open`), against what was held.

use std::sync::Arc;

use dqhand::engine::ModelSource;
use dqhand::gesture::GestureSet;
use dqhand::grasp::GraspParams;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::benchmark::NO_GESTURE;
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::scene::Scene;
use serde_json::{json, Value};

use crate::outside_poses::{both_hands, OutsidePose, PairHold};

/// What both hands showed at the ends of their holds.
pub struct BothHandsScore {
    pub holds: usize,
    /// Hands judged (two a hold) and those that showed their pose's gesture.
    pub hands: usize,
    pub hands_named: usize,
    /// Holds whose gesture of both hands is known (not with a pose that may or may not be an
    /// open palm), and those where the loop showed it (or, rightly, none).
    pub two_hand: usize,
    pub two_hand_named: usize,
    /// Every miss: `"left fist / right point: left showed none"`.
    pub misses: Vec<String>,
}

/// Whether `shown` is one of `label`'s gestures (`a|b`; `none` for no gesture).
fn named(label: &str, shown: Option<&str>) -> bool {
    label.split('|').any(|g| if g == NO_GESTURE { shown.is_none() } else { shown == Some(g) })
}

/// The gesture both hands make in `hold`: `Some(None)` none, `None` when a hand's pose may or
/// may not be an open palm (handy-work's relaxed hand).
fn expected(hold: &PairHold) -> Option<Option<&'static str>> {
    let open = |label: &str| (label == "open_palm", label.split('|').any(|g| g == "open_palm"));
    match (open(hold.left), open(hold.right)) {
        ((true, _), (true, _)) => Some(Some(if hold.together { "hands_together" } else { "both_palms_open" })),
        ((_, false), _) | (_, (_, false)) => Some(None),
        _ => None,
    }
}

impl BothHandsScore {
    /// Plays `poses`' pairs (`repeats` rounds, `seed`) into a two-handed loop of `right` (the
    /// bench's built-in hand) and the built-in left one, with `gestures` and the built-in
    /// two-hand gestures, and reads each hold's end.
    ///
    /// # Errors
    /// The left hand cannot be built, or the loop cannot be made.
    pub fn measure(right: &Arc<Model>, poses: &[OutsidePose], repeats: usize, seed: u64, gestures: &GestureSet) -> anyhow::Result<Self> {
        let left = Arc::new(ModelSource::Builtin(HandParams { side: Side::Left, ..HandParams::default() }).load()?);
        let nothing = Scene { table: None, objects: Vec::new(), actions: Vec::new() };
        let hands = [(left, None), (Arc::clone(right), None)];
        let mut manip = ManipulationLoop::two_handed(hands, JointModel::Full, InputConfig::default(), Some(gestures.clone()), &nothing, GraspParams::default())?;
        let (records, holds) = both_hands(poses, repeats, seed);
        let [left, right] = [Side::Left, Side::Right].map(|s| manip.hand_of(s));
        let mut score = Self { holds: holds.len(), hands: 0, hands_named: 0, two_hand: 0, two_hand_named: 0, misses: Vec::new() };
        let mut next = holds.iter().peekable();
        // Both hands' records of one time, then the frame.
        for frame in records.chunk_by(|a, b| a.time == b.time) {
            for record in frame {
                let _ = manip.push(record); // a refusal is the loop's to count; none are expected
            }
            let t = frame[0].time;
            manip.step(t);
            // The hold's last frame (or the one before: the frames' clock is a sum of steps).
            while let Some(hold) = next.next_if(|h| t + 1.5 / crate::outside_poses::RATE_HZ >= h.until) {
                let what = format!("left {} / right {}", hold.left, hold.right);
                for (name, k, label) in [("left", left, hold.left), ("right", right, hold.right)] {
                    let shown = manip.hands()[k].input().gesture();
                    score.hands += 1;
                    if named(label, shown) {
                        score.hands_named += 1;
                    } else {
                        score.misses.push(format!("{what}: {name} showed {}", shown.unwrap_or(NO_GESTURE)));
                    }
                }
                if let Some(want) = expected(hold) {
                    let shown = manip.two_hand_gestures().and_then(|r| r.current()).map(|g| g.name.as_str());
                    score.two_hand += 1;
                    if shown == want {
                        score.two_hand_named += 1;
                    } else {
                        let together = if hold.together { ", held together" } else { "" };
                        score.misses.push(format!("{what}{together}: both showed {} for {}", shown.unwrap_or(NO_GESTURE), want.unwrap_or(NO_GESTURE)));
                    }
                }
            }
        }
        Ok(score)
    }

    /// The score as the bench's JSON.
    pub fn to_json(&self, target: f64) -> Value {
        let rate = |part: usize, whole: usize| if whole == 0 { 0.0 } else { part as f64 / whole as f64 };
        json!({
            "poses": "handy-work's captures, each hand as recorded with the other, 40 cm apart palms down (and as many pairs of two captures), and its flat hands held together palms facing",
            "holds": self.holds,
            "hands": self.hands,
            "hands_named": self.hands_named,
            "hands_rate": rate(self.hands_named, self.hands),
            "target": target,
            "hands_pass": rate(self.hands_named, self.hands) >= target,
            "two_hand": self.two_hand,
            "two_hand_named": self.two_hand_named,
            "two_hand_rate": rate(self.two_hand_named, self.two_hand),
            "misses": self.misses,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hold(left: &'static str, right: &'static str, together: bool) -> PairHold {
        PairHold { left, right, together, until: 1.0 }
    }

    #[test]
    fn the_gesture_of_both_hands_is_known_unless_a_relaxed_hand_may_be_open() {
        assert_eq!(expected(&hold("open_palm", "open_palm", false)), Some(Some("both_palms_open")));
        assert_eq!(expected(&hold("open_palm", "open_palm", true)), Some(Some("hands_together")));
        assert_eq!(expected(&hold("fist", "open_palm", false)), Some(None));
        assert_eq!(expected(&hold("none|open_palm", "fist", false)), Some(None));
        assert_eq!(expected(&hold("none|open_palm", "open_palm", false)), None);
        assert!(named("none|open_palm", None) && named("none|open_palm", Some("open_palm")) && !named("fist", Some("point")));
    }
}
