//! Skeleton, joint models, limits and forward kinematics (paper 4.3).

mod support;

use dqhand::hand::{build, HandParams, Side};
use dqhand::kinematics::{forward_kinematics, HandRig, Joint, JointModel, Limits, Motion, Pose, Skeleton, Transform};
use dqhand::Error;
use glam::{Affine3A, Quat, Vec3};
use proptest::prelude::*;

/// Paper eq. (1): the fingertip of a planar finger, x toward the palm, y along the finger.
fn equation_1(l: [f32; 3], t: [f32; 3]) -> (f32, f32) {
    let (a, b, c) = (t[0], t[0] + t[1], t[0] + t[1] + t[2]);
    (l[2] * c.sin() + l[1] * b.sin() + l[0] * a.sin(), l[2] * c.cos() + l[1] * b.cos() + l[0] * a.cos())
}

/// A planar finger: MCP at the origin, bones along −Z, flexion about −X (the joint models'
/// convention), so eq. (1)'s y is −Z and its x is −Y.
fn finger(l: [f32; 3]) -> Skeleton {
    let names = ["mcp", "pip", "dip", "tip"];
    let joints = names
        .iter()
        .enumerate()
        .map(|(i, n)| Joint {
            name: (*n).into(),
            parent: i.checked_sub(1),
            rest: Transform::from_rotation_translation(Quat::IDENTITY, if i == 0 { Vec3::ZERO } else { Vec3::NEG_Z * l[i - 1] }),
        })
        .collect();
    Skeleton::new(joints).unwrap()
}

fn tip_in_finger_plane(world: &[Affine3A], tip: usize) -> (f32, f32) {
    let p = world[tip].translation;
    (-p.y, -p.z)
}

/// The built-in hand, built once for the property test's many cases.
static BUILT_IN: std::sync::LazyLock<dqhand::model::Model> = std::sync::LazyLock::new(|| build(&HandParams::default()).unwrap());

proptest! {
    #[test]
    fn fingertip_matches_paper_equation_1(
        l in (0.01f32..0.08, 0.01f32..0.05, 0.01f32..0.04),
        t in (-0.5f32..1.6, 0.0f32..1.9, -0.2f32..1.6),
    ) {
        let (l, t) = ([l.0, l.1, l.2], [t.0, t.1, t.2]);
        let skeleton = finger(l);
        let mut locals = skeleton.rest_locals();
        for (j, &angle) in t.iter().enumerate() {
            locals[j].rotation = Quat::from_axis_angle(Vec3::NEG_X, angle);
        }
        let mut world = vec![Affine3A::IDENTITY; 4];
        forward_kinematics(&skeleton, &locals, &mut world);
        let (x, y) = tip_in_finger_plane(&world, 3);
        let (ex, ey) = equation_1(l, t);
        assert_close!(x, ex, 1e-5);
        assert_close!(y, ey, 1e-5);
    }

    #[test]
    fn built_in_index_finger_matches_equation_1(t in (0.0f32..1.5, 0.0f32..1.9, 0.0f32..1.5)) {
        let model = &*BUILT_IN;
        let rig = HandRig::new(&model.skeleton, JointModel::Paper).unwrap();
        let names = ["index-finger-phalanx-proximal", "index-finger-phalanx-intermediate", "index-finger-phalanx-distal", "index-finger-tip"];
        let idx: Vec<usize> = names.iter().map(|n| model.skeleton.find(n).unwrap()).collect();
        let rest = model.skeleton.rest_world();
        let l = [0, 1, 2].map(|i| Vec3::from(rest[idx[i + 1]].translation).distance(rest[idx[i]].translation.into()));
        let mut pose = Pose::rest(JointModel::Paper.dof_count());
        for (i, n) in names[..3].iter().enumerate() {
            pose.angles[JointModel::Paper.dof_index(&format!("{n}.flex")).unwrap()] = [t.0, t.1, t.2][i];
        }
        let world = support::world_of(&rig, &pose, Limits::Off);
        // The tip in the MCP's rest frame, which is where eq. (1) is written.
        let tip = rest[idx[0]].inverse().transform_point3(world[idx[3]].translation.into());
        let (ex, ey) = equation_1(l, [t.0, t.1, t.2]);
        assert_close!(-tip.y, ex, 1e-5);
        assert_close!(-tip.z, ey, 1e-5);
        assert_close!(tip.x, 0.0, 1e-5);
    }
}

#[test]
fn paper_model_has_table_1_dofs_and_full_adds_the_thumb() {
    let paper: Vec<_> = JointModel::Paper.dofs().collect();
    assert_eq!(paper.len(), 18);
    // Table 1: TDIP 1, TPIP 1, DIP 4, PIP 4, MCP 2 × 4.
    let count = |suffix: &str, m: Motion| paper.iter().filter(|d| d.bone.ends_with(suffix) && d.motion == m).count();
    assert_eq!(count("phalanx-distal", Motion::Flex), 5);
    assert_eq!(count("phalanx-intermediate", Motion::Flex), 4);
    assert_eq!(count("phalanx-proximal", Motion::Flex), 5);
    assert_eq!(count("phalanx-proximal", Motion::Abd), 4);
    assert!(paper.iter().all(|d| !d.bone.ends_with("metacarpal")), "palm joints and thumb root are fixed");
    assert_eq!(JointModel::Full.dof_count(), 23);
    assert!(JointModel::Full.dof_index("thumb-metacarpal.flex").is_ok());
    assert!(JointModel::Full.dof_index("thumb-metacarpal.abd").is_ok());
    for d in JointModel::Full.dofs() {
        assert!(d.min_deg < d.max_deg && d.min_deg <= 0.0 && d.max_deg > 0.0, "{} range", d.name());
    }
    match JointModel::Paper.dof_index("thumb-metacarpal.flex") {
        Err(Error::UnknownName { valid, .. }) => assert!(valid.contains("index-finger-phalanx-proximal.abd")),
        other => panic!("expected UnknownName, got {other:?}"),
    }
}

#[test]
fn limits_clamp_by_default_and_can_be_switched_off() {
    let model = build(&HandParams::default()).unwrap();
    let rig = HandRig::new(&model.skeleton, JointModel::Paper).unwrap();
    let pip = JointModel::Paper.dof_index("index-finger-phalanx-intermediate.flex").unwrap();
    let mut pose = Pose::rest(18);
    pose.angles[pip] = 150f32.to_radians();
    let mut clamped = pose.clone();
    assert_eq!(rig.clamp(&mut clamped), vec![pip]);
    assert_close!(clamped.angles[pip], 110f32.to_radians(), 1e-6);
    let locals = |limits| {
        let mut l = model.skeleton.rest_locals();
        rig.locals(&pose, limits, &mut l);
        l
    };
    let j = model.skeleton.find("index-finger-phalanx-intermediate").unwrap();
    let angle = |l: &[Transform]| (model.skeleton.joints()[j].rest.rotation.inverse() * l[j].rotation).angle_between(Quat::IDENTITY);
    assert_close!(angle(&locals(Limits::Anatomical)), 110f32.to_radians(), 1e-4);
    assert_close!(angle(&locals(Limits::Off)), 150f32.to_radians(), 1e-4);
}

#[test]
fn flexion_curls_toward_the_palm_and_abduction_spreads_on_both_sides() {
    for side in [Side::Left, Side::Right] {
        let model = build(&HandParams { side, ..HandParams::default() }).unwrap();
        let rig = HandRig::new(&model.skeleton, JointModel::Full).unwrap();
        let tips = |pose: &Pose| {
            let world = support::world_of(&rig, pose, Limits::Anatomical);
            let at = |n: &str| Vec3::from(world[model.skeleton.find(n).unwrap()].translation);
            (at("index-finger-tip"), at("middle-finger-tip"), at("pinky-finger-tip"), at("ring-finger-tip"))
        };
        let rest = tips(&Pose::rest(23));
        let mut pose = Pose::rest(23);
        pose.angles[JointModel::Full.dof_index("index-finger-phalanx-intermediate.flex").unwrap()] = 1.0;
        pose.angles[JointModel::Full.dof_index("index-finger-phalanx-proximal.abd").unwrap()] = 0.3;
        pose.angles[JointModel::Full.dof_index("pinky-finger-phalanx-proximal.abd").unwrap()] = 0.3;
        let moved = tips(&pose);
        // Palm down (+Y dorsal): flexion moves the index tip down.
        assert!(moved.0.y < rest.0.y - 0.01, "{side:?}: index tip {:?} -> {:?}", rest.0, moved.0);
        assert!(moved.0.distance(moved.1) > rest.0.distance(rest.1), "{side:?}: index spreads from middle");
        assert!(moved.2.distance(moved.3) > rest.2.distance(rest.3), "{side:?}: pinky spreads from ring");
        assert_eq!(moved.1, rest.1, "{side:?}: the middle finger does not move");
    }
}

#[test]
fn wrist_pose_places_the_hand() {
    let model = build(&HandParams::default()).unwrap();
    let rig = HandRig::new(&model.skeleton, JointModel::Paper).unwrap();
    let wrist = dqhand::math::DualQuat::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(0.1, 1.2, -0.3));
    let world = support::world_of(&rig, &Pose { wrist: Some(wrist), angles: vec![0.0; 18] }, Limits::Anatomical);
    let rest = model.skeleton.rest_world();
    for (j, w) in world.iter().enumerate() {
        assert_close!(Vec3::from(w.translation), wrist.transform_point3(rest[j].translation.into()), 1e-5);
    }
}

#[test]
fn reparenting_keeps_rest_world_transforms() {
    let model = build(&HandParams::default()).unwrap();
    let flat = model.skeleton.reparented(|n| (n != "wrist").then_some("wrist")).unwrap();
    assert!(flat.joints().iter().skip(1).all(|j| j.parent == Some(0)));
    for (a, b) in flat.rest_world().iter().zip(model.skeleton.rest_world()) {
        assert!(a.abs_diff_eq(b, 1e-5));
    }
    let back = flat.reparented(dqhand::kinematics::webxr::anatomical_parent).unwrap();
    assert_eq!(back.joints().iter().map(|j| j.parent).collect::<Vec<_>>(), model.skeleton.joints().iter().map(|j| j.parent).collect::<Vec<_>>());
}

#[test]
fn malformed_skeletons_are_rejected() {
    let j = |name: &str, parent| Joint { name: name.into(), parent, rest: Transform::IDENTITY };
    let err = |joints| Skeleton::new(joints).unwrap_err().to_string();
    assert!(err(vec![j("a", None), j("a", Some(0))]).contains("\"a\" is used twice"));
    assert!(err(vec![j("a", Some(1)), j("b", Some(0))]).contains("cycle"));
    assert!(err(vec![j("a", Some(7))]).contains("invalid parent"));
    let mut nan = j("n", None);
    nan.rest.translation.x = f32::NAN;
    assert!(err(vec![nan]).contains("non-finite"));
    assert!(HandRig::new(&finger([0.1; 3]), JointModel::Paper).unwrap_err().to_string().contains("wrist"));
}

#[test]
fn a_flat_hand_missing_a_metacarpal_still_follows_the_wrist() {
    // Every joint a sibling under the wrist (as WebXR stores them), without
    // index-finger-metacarpal: the index proximal phalanx must hang from the wrist.
    let model = build(&HandParams::default()).unwrap();
    let world = model.skeleton.rest_world();
    let keep: Vec<usize> = (0..model.skeleton.len()).filter(|&j| model.skeleton.joints()[j].name != "index-finger-metacarpal").collect();
    let joints = keep
        .iter()
        .map(|&j| {
            let name = model.skeleton.joints()[j].name.clone();
            let (parent, rest) = if j == 0 { (None, world[0]) } else { (Some(0), world[0].inverse() * world[j]) };
            Joint { name, parent, rest: Transform::from_affine(&rest) }
        })
        .collect();
    let flat = Skeleton::new(joints).unwrap();
    let rig = HandRig::new(&flat, JointModel::Paper).unwrap();
    let tip = flat.find("index-finger-tip").unwrap();
    let proximal = flat.find("index-finger-phalanx-proximal").unwrap();
    assert_eq!(rig.skeleton().joints()[proximal].parent, flat.find("wrist"));
    let lift = dqhand::math::DualQuat::from_translation(Vec3::Y * 0.5);
    let world = support::world_of(&rig, &Pose { wrist: Some(lift), angles: vec![0.0; 18] }, Limits::Anatomical);
    let rest_tip = flat.rest_world()[tip].translation;
    assert_close!(Vec3::from(world[tip].translation), Vec3::from(rest_tip) + Vec3::Y * 0.5, 1e-5);
}

/// The built-in hand's skeleton with every joint's world frame turned by `turn` (children
/// keep their world positions), as another tool's convention would store it.
fn reframed(skeleton: &Skeleton, turn: Quat, shift: Vec3) -> Skeleton {
    let world: Vec<Affine3A> = skeleton
        .rest_world()
        .iter()
        .map(|w| Affine3A::from_translation(shift) * *w * Affine3A::from_quat(turn))
        .collect();
    let joints = skeleton
        .joints()
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let parent = j.parent.map_or(Affine3A::IDENTITY, |p| world[p]);
            Joint { rest: Transform::from_affine(&(parent.inverse() * world[i])), ..j.clone() }
        })
        .collect();
    Skeleton::new(joints).unwrap()
}

/// Issue 9 bug 6: flexion turns about −X, right only in WebXR joint frames. A rig whose
/// bones run along +Y (Blender's convention) is refused, naming a joint, instead of flexing
/// sideways.
#[test]
fn a_rig_in_another_bone_axis_convention_is_refused() {
    let model = build(&HandParams::default()).unwrap();
    let blender = reframed(&model.skeleton, Quat::from_rotation_x(std::f32::consts::FRAC_PI_2), Vec3::ZERO);
    for joint_model in JointModel::ALL {
        match HandRig::new(&blender, joint_model) {
            Err(Error::JointFrame { joint, problem }) => assert!(problem.contains("90°"), "{joint}: {problem}"),
            other => panic!("expected a joint frame error, got {other:?}"),
        }
    }
    let message = HandRig::new(&blender, JointModel::Paper).unwrap_err().to_string();
    assert!(message.contains("WebXR joint frames"), "{message}");
    // The WebXR convention itself, anywhere in space, is accepted.
    HandRig::new(&reframed(&model.skeleton, Quat::IDENTITY, Vec3::new(0.3, 1.2, -0.4)), JointModel::Full).unwrap();
}

/// Issue 9 bug 3: a missing wrist means the rest wrist when posing, so interpolating from no
/// wrist to the rest wrist must not move a hand whose rest wrist is away from the origin.
#[test]
fn interpolating_from_no_wrist_to_the_rest_wrist_keeps_the_hand_still() {
    let model = build(&HandParams::default()).unwrap();
    let moved = reframed(&model.skeleton, Quat::IDENTITY, Vec3::new(0.3, 1.2, -0.4));
    let rig = HandRig::new(&moved, JointModel::Full).unwrap();
    let rest_wrist = rig.rest_wrist();
    assert_close!(rest_wrist.translation(), Vec3::new(0.3, 1.2, -0.4), 1e-5);
    let none = Pose::rest(JointModel::Full.dof_count());
    let at_rest = Pose { wrist: Some(rest_wrist), ..none.clone() };
    let still = support::world_of(&rig, &none, Limits::Anatomical);
    for t in [0.25, 0.5, 0.75] {
        for (a, b) in [(&none, &at_rest), (&at_rest, &none)] {
            let world = support::world_of(&rig, &a.interpolate(b, t, rest_wrist), Limits::Anatomical);
            for (w, s) in world.iter().zip(&still) {
                assert_close!(Vec3::from(w.translation), Vec3::from(s.translation), 1e-5);
            }
        }
    }
    assert_eq!(none.interpolate(&none, 0.5, rest_wrist).wrist, None, "no wrist on either side stays none");
}
