//! Retargeting: angles in → our forward kinematics (or another hand's) → tracked positions →
//! angles out. Ground truth is the angles put in; hands of other sizes and the left hand are
//! built by the hand builder, independent of the retargeter.

mod support;

use std::sync::OnceLock;

use dqhand::gesture::gesture;
use dqhand::hand::{HandParams, Side};
use dqhand::input::{Retargeter, JOINT_COUNT, CONTACT_FULL};
use dqhand::interaction::benchmark::{close_pinch, thumb_index_gap, AngleError};
use dqhand::kinematics::{webxr, HandRig, JointModel, Limits, Pose};
use dqhand::math::DualQuat;
use dqhand::model::Model;
use glam::{Quat, Vec3};
use proptest::prelude::*;

fn hand(length: f32, breadth: f32, side: Side) -> Model {
    dqhand::hand::build(&HandParams { length, breadth, side, vertices: 1_000 }).unwrap()
}

fn ours() -> &'static Model {
    static M: OnceLock<Model> = OnceLock::new();
    M.get_or_init(|| hand(0.19, 0.085, Side::Right))
}

/// The 25 WebXR joint positions of `model` posed by `pose` (the rig's own FK: the tracked hand).
fn positions(model: &Model, joint_model: JointModel, pose: &Pose) -> [Vec3; JOINT_COUNT] {
    let rig = HandRig::new(&model.skeleton, joint_model).unwrap();
    let world = support::world_of(&rig, pose, Limits::Anatomical);
    core::array::from_fn(|i| world[rig.skeleton().find(webxr::JOINT_NAMES[i]).unwrap()].translation.into())
}

fn retarget(joint_model: JointModel, tracked: &[Vec3; JOINT_COUNT], side: Side) -> Pose {
    let rig = HandRig::new(&ours().skeleton, joint_model).unwrap();
    let mut r = Retargeter::new(&rig).unwrap();
    let mut out = Pose::rest(joint_model.dof_count());
    r.solve(tracked, side, &mut out).unwrap();
    out
}

fn tip_gap(p: &[Vec3; JOINT_COUNT], finger_tip: usize) -> f32 {
    (p[4] - p[finger_tip]).length()
}

/// A random pose within the anatomical limits (fingers only, wrist at rest).
fn pose_in_limits(joint_model: JointModel) -> impl Strategy<Value = Pose> {
    let ranges: Vec<_> = joint_model.dofs().map(|d| (d.min_deg + 1.0)..(d.max_deg - 1.0)).collect();
    ranges.prop_map(|deg| Pose { wrist: None, angles: deg.into_iter().map(f32::to_radians).collect() })
}

/// Mean and largest angle error, degrees (the measure `dqhand gesture-bench` reports).
fn max_error_deg(truth: &Pose, solved: &Pose) -> (f64, f32) {
    let e = AngleError::between(truth, solved);
    (e.mean_deg(), e.max_deg())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Noise-free joints of our own hand give back the angles (≤ 1° mean, the bar),
    /// on both joint models, whenever no contact correction applies.
    #[test]
    fn own_hand_angles_come_back(full in any::<bool>(), pose in pose_in_limits(JointModel::Full)) {
        let joint_model = if full { JointModel::Full } else { JointModel::Paper };
        let mut pose = pose;
        if !full {
            pose.angles = JointModel::Paper.dofs().map(|d| pose.angles[JointModel::Full.dof_index(&d.name()).unwrap()]).collect();
        }
        let tracked = positions(ours(), joint_model, &pose);
        prop_assume!([9, 14, 19, 24].iter().all(|&t| tip_gap(&tracked, t) > 0.025));
        let solved = retarget(joint_model, &tracked, Side::Right);
        let (mean, max) = max_error_deg(&pose, &solved);
        prop_assert!(mean <= 0.1 && max <= 0.5, "mean {mean}°, max {max}°\n in {:?}\nout {:?}", pose.angles, solved.angles);
    }

    /// The wrist's pose is recovered from the positions alone.
    #[test]
    fn wrist_pose_comes_back(axis in support::vec3(1.0), angle in -3.0f32..3.0, t in support::vec3(0.5)) {
        prop_assume!(axis.length() > 0.1);
        let wrist = DualQuat::from_rotation_translation(Quat::from_axis_angle(axis.normalize(), angle), t);
        let mut pose = gesture("point").unwrap().pose(JointModel::Full);
        pose.wrist = Some(wrist);
        let solved = retarget(JointModel::Full, &positions(ours(), JointModel::Full, &pose), Side::Right);
        let (r0, t0) = wrist.to_rotation_translation();
        let (r1, t1) = solved.wrist.unwrap().to_rotation_translation();
        prop_assert!(r0.angle_between(r1).to_degrees() < 0.2, "rotation off by {}°", r0.angle_between(r1).to_degrees());
        prop_assert!((t0 - t1).length() < 1e-4);
        prop_assert!(max_error_deg(&gesture("point").unwrap().pose(JointModel::Full), &solved).0 < 0.1);
    }
}

/// A hand of another size but our proportions is the same shape: the same angles.
#[test]
fn a_scaled_hand_gives_the_same_angles() {
    let small = hand(0.15, 0.15 * 0.085 / 0.19, Side::Right);
    // (Not `ok` or `pinch`: their contact is kept at the user's gap, which on a smaller hand
    // needs other thumb angles.)
    for name in ["fist", "point", "victory", "three", "four"] {
        let pose = gesture(name).unwrap().pose(JointModel::Full);
        let solved = retarget(JointModel::Full, &positions(&small, JointModel::Full, &pose), Side::Right);
        let (mean, max) = max_error_deg(&pose, &solved);
        assert!(mean < 0.1 && max < 0.5, "{name}: mean {mean}°, max {max}°");
    }
}

/// A hand of other proportions (broader, longer) keeps its flexions; its bones' rest
/// directions differ from ours, so the angles are close rather than equal.
#[test]
fn other_proportions_keep_the_flexions() {
    for (length, breadth) in [(0.21, 0.10), (0.17, 0.068)] {
        let other = hand(length, breadth, Side::Right);
        for name in ["fist", "point", "victory", "three"] {
            let pose = gesture(name).unwrap().pose(JointModel::Full);
            let solved = retarget(JointModel::Full, &positions(&other, JointModel::Full, &pose), Side::Right);
            for (d, (a, b)) in JointModel::Full.dofs().zip(pose.angles.iter().zip(&solved.angles)) {
                let tolerance = if d.name().starts_with("thumb") || d.motion == dqhand::kinematics::Motion::Abd { 8.0 } else { 3.0 };
                assert!((a - b).abs().to_degrees() <= tolerance, "{length}×{breadth} {name} {}: {}° vs {}°", d.name(), a.to_degrees(), b.to_degrees());
            }
        }
    }
}

/// A left hand drives our right hand with the same angles (its mirror image).
#[test]
fn a_left_hand_gives_the_same_angles() {
    let left = hand(0.19, 0.085, Side::Left);
    for name in ["fist", "point", "victory", "ok", "three"] {
        let pose = gesture(name).unwrap().pose(JointModel::Full);
        let tracked = positions(&left, JointModel::Full, &pose);
        let solved = retarget(JointModel::Full, &tracked, Side::Left);
        let (mean, max) = max_error_deg(&pose, &solved);
        assert!(mean < 0.5 && max < 3.0, "{name}: mean {mean}°, max {max}°");
        // Told it is a right hand, the same data make another (wrong) shape: the side matters.
        let wrong = retarget(JointModel::Full, &tracked, Side::Right);
        assert!(max_error_deg(&pose, &wrong).1 > 5.0, "{name}: the side made no difference");
    }
}

/// MediaPipe's 21 landmarks (no finger metacarpals) of our own hand give back the finger angles.
#[test]
fn landmarks_give_the_angles() {
    let rig = HandRig::new(&ours().skeleton, JointModel::Full).unwrap();
    let mut r = Retargeter::new(&rig).unwrap();
    for name in ["fist", "point", "victory", "three", "four"] {
        let pose = gesture(name).unwrap().pose(JointModel::Full);
        let joints = positions(ours(), JointModel::Full, &pose);
        let landmarks = dqhand::input::mediapipe::WEBXR_INDEX.map(|w| joints[w]);
        let mut synthesised = [Vec3::ZERO; JOINT_COUNT];
        r.landmark_joints(&landmarks, &mut synthesised).unwrap();
        let mut out = Pose::rest(pose.angles.len());
        r.solve(&synthesised, Side::Right, &mut out).unwrap();
        let (mean, max) = max_error_deg(&pose, &out);
        assert!(mean < 1.0 && max < 5.0, "{name}: mean {mean}°, max {max}°");
    }
}

/// A pinch the user makes survives retargeting: with the tracked tips 0.5 to 5 mm apart,
/// ours are no further apart (and within a millimetre of it), on hands whose proportions put
/// the tips elsewhere.
#[test]
fn a_tracked_pinch_closes_the_virtual_pinch() {
    let rig = HandRig::new(&ours().skeleton, JointModel::Full).unwrap();
    for (length, breadth) in [(0.19, 0.085), (0.17, 0.09), (0.21, 0.08)] {
        let user = hand(length, breadth, Side::Right);
        let pose = gesture("pinch").unwrap().pose(JointModel::Full);
        for tracked_gap in [0.0005, 0.001, 0.003, 0.005] {
            let tracked = close_pinch(&positions(&user, JointModel::Full, &pose), tracked_gap);
            let solved = retarget(JointModel::Full, &tracked, Side::Right);
            let gap = thumb_index_gap(&positions(ours(), JointModel::Full, &solved));
            let (virtual_mm, tracked_mm) = (gap * 1e3, tracked_gap * 1e3);
            assert!(gap <= tracked_gap && gap >= tracked_gap - 0.001, "{length}×{breadth}: virtual gap {virtual_mm} mm for a tracked {tracked_mm} mm");
            assert!(rig.dofs().len() == solved.angles.len());
        }
    }
}

/// Far from a contact, no correction: the thumb keeps its solved angles.
#[test]
fn no_contact_no_correction() {
    let pose = gesture("victory").unwrap().pose(JointModel::Full);
    let tracked = positions(ours(), JointModel::Full, &pose);
    assert!(tip_gap(&tracked, 9) > 2.0 * CONTACT_FULL);
    let solved = retarget(JointModel::Full, &tracked, Side::Right);
    assert!(max_error_deg(&pose, &solved).1 < 0.5);
}

/// Degenerate data are refused, not solved into NaN.
#[test]
fn a_collapsed_hand_is_refused() {
    let rig = HandRig::new(&ours().skeleton, JointModel::Full).unwrap();
    let mut r = Retargeter::new(&rig).unwrap();
    let mut out = Pose::rest(JointModel::Full.dof_count());
    let e = r.solve(&[Vec3::ONE; JOINT_COUNT], Side::Right, &mut out).unwrap_err();
    assert_eq!(e.kind, dqhand::input::RejectKind::Unusable);
    let mut p = positions(ours(), JointModel::Full, &Pose::rest(JointModel::Full.dof_count()));
    p[8] = p[7];
    assert_eq!(r.solve(&p, Side::Right, &mut out).unwrap_err().kind, dqhand::input::RejectKind::Unusable);
}



/// The user's hand length and breadth come back from their joints, in any pose.
#[test]
fn hand_size_is_measured_from_joints() {
    for (length, breadth, side) in [(0.19, 0.085, Side::Right), (0.16, 0.075, Side::Left), (0.21, 0.10, Side::Right)] {
        let model = hand(length, breadth, side);
        for name in ["open_palm", "fist", "pinch"] {
            let (l, b) = dqhand::hand::measure(&positions(&model, JointModel::Full, &gesture(name).unwrap().pose(JointModel::Full))).unwrap();
            assert!((l - length).abs() < 0.002 && (b - breadth).abs() < 0.004, "{length}×{breadth} {name}: measured {l}×{b}");
        }
    }
}

#[test]
fn a_models_side_is_read_from_its_rest_geometry_as_its_retargeter_reads_it() {
    for side in [Side::Left, Side::Right] {
        let model = hand(0.17, 0.08, side);
        assert_eq!(dqhand::input::rest_side(&model.skeleton).unwrap(), side);
        let rig = HandRig::new(&model.skeleton, JointModel::Full).unwrap();
        assert_eq!(Retargeter::new(&rig).unwrap().side(), side);
    }
    // A skeleton without the WebXR joints has no side to read.
    let root = dqhand::kinematics::Joint { name: "root".into(), parent: None, rest: Default::default() };
    let bare = dqhand::kinematics::Skeleton::new(vec![root]).unwrap();
    let err = dqhand::input::rest_side(&bare).unwrap_err().to_string();
    assert!(err.contains("wrist"), "{err}");
}
