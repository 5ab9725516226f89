//! The manipulation loop end to end: scripted recordings grasp, carry and set down objects;
//! the rendered skin stays out of them (checked against each object's analytic surface, not
//! the collision code); a hand striking a thin plate at 10 m/s does not pass through it; the
//! physics drops, rests and throws.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use dqhand::collision::ObjectColliders;
use dqhand::grasp::{GraspEvent, GraspParams};
use dqhand::interaction::benchmark;
use dqhand::hand::{HandParams, Side};
use dqhand::input::InputConfig;
use dqhand::interaction::grasp_script::{self, GraspTask, Script};
use dqhand::interaction::ManipulationLoop;
use dqhand::kinematics::JointModel;
use dqhand::model::Model;
use dqhand::physics::ScenePhysics;
use dqhand::scene::{ObjectShape, Scene};
use dqhand::skin::{Deformed, Method, MethodSet, SkinLayer};
use glam::Vec3;

fn model() -> Arc<Model> {
    static MODEL: OnceLock<Arc<Model>> = OnceLock::new();
    MODEL.get_or_init(|| Arc::new(dqhand::hand::build(&HandParams::default()).unwrap())).clone()
}

fn scene(name: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes").join(format!("{name}.json"))).unwrap()
}

/// How deep `p` is inside a primitive object at `centre` (axis-aligned: these scenes do not
/// turn their primitives before they are touched); 0 outside.
fn depth(shape: &ObjectShape, centre: Vec3, p: Vec3) -> f32 {
    let d = p - centre;
    match shape {
        ObjectShape::Sphere { radius } => (radius - d.length()).max(0.0),
        ObjectShape::Box { size } => {
            let inside = size / 2.0 - d.abs();
            if inside.min_element() > 0.0 { inside.min_element() } else { 0.0 }
        }
        _ => unreachable!("primitives only"),
    }
}

/// Runs `script` in `scene`, calling `each` after every frame.
fn run(scene: &Scene, script: &Script, mut each: impl FnMut(&mut ManipulationLoop, f64, Option<GraspEvent>)) {
    let mut manip = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, scene, GraspParams::default()).unwrap();
    for r in &script.records {
        manip.push(r).unwrap();
        let e = manip.step(r.time).of(0);
        each(&mut manip, r.time, e);
    }
}

/// The rendered hand of `m`'s last frame, skinned with DQB by `skin`.
fn dqb<'a>(skin: &'a mut SkinLayer, m: &ManipulationLoop) -> &'a Deformed {
    skin.deform(m.hands()[0].rendered().layer());
    skin.deformed(Method::Dqb).expect("DQB is the set")
}

/// `name` of the `objects` scene alone on its table, where `grasp-bench` puts it.
fn alone_on_table(name: &str) -> Scene {
    let all = scene("objects");
    let mut object = all.object(name).unwrap().clone();
    object.position = Vec3::new(-0.25, object.position.y, -0.3);
    Scene { table: all.table, objects: vec![object], actions: Vec::new() }
}

fn script(scene: &Scene, task: &GraspTask) -> Script {
    let objects = ObjectColliders::new(scene).unwrap();
    grasp_script::grasp(model(), "test", &objects, task, Side::Right).unwrap()
}

#[test]
fn ball_and_teapot_are_picked_up_carried_and_set_down() {
    let scene = scene("grasp");
    for (i, name) in ["ball", "teapot"].into_iter().enumerate() {
        let task = GraspTask::from_above(name);
        let s = script(&scene, &task);
        let start = scene.objects[i].position;
        let mut held_during_carry = true;
        let mut final_pose = start;
        run(&scene, &s, |m, t, _| {
            if t > s.times.carry_start && t < s.times.carry_end {
                held_during_carry &= m.hands()[0].held() == Some(i);
            }
            if t > s.times.release + 0.6 {
                assert_eq!(m.hands()[0].held(), None, "{name} let go at {t}");
            }
            final_pose = m.poses()[i].1;
        });
        assert!(held_during_carry, "{name} held through the carry");
        let moved = final_pose - start;
        assert!((moved - task.carry).length() < 0.03, "{name} set down {moved} from where it was, carried {}", task.carry);
    }
}

#[test]
fn rendered_skin_stays_out_of_the_ball_the_tracked_hand_does_not() {
    let mut skin_layer = SkinLayer::new(Arc::clone(&model().mesh), MethodSet::DQB);
    let scene = scene("grasp");
    let ball = &scene.objects[0];
    let s = script(&scene, &GraspTask::from_above("ball"));
    let (mut rendered, mut tracked) = (0.0f32, 0.0f32);
    run(&scene, &s, |m, t, _| {
        if t > s.times.carry_start {
            return;
        }
        let centre = m.poses()[0].1;
        let skin = dqb(&mut skin_layer, m);
        for p in skin.positions() {
            rendered = rendered.max(depth(&ball.shape, centre, Vec3::from(*p)));
        }
        let world = m.hands()[0].constraint().tracked_world();
        for w in world {
            tracked = tracked.max(depth(&ball.shape, centre, Vec3::from(w.translation)));
        }
    });
    assert!(tracked > 0.01, "the tracked joints go {tracked} m into the ball");
    assert!(rendered <= 0.001, "the rendered skin goes {rendered} m into the ball");
}

/// Joints stopped on the teapot, followed from one frame to the next, that the grip test must
/// see at least (about half of the 545 measured): a grip that never stops on the teapot would
/// pass its slide check with nothing to check.
const STOPPED_ON_AT_LEAST: usize = 250;

#[test]
fn the_teapot_is_held_still_in_a_grip_that_stays_out_of_it() {
    let mut skin_layer = SkinLayer::new(Arc::clone(&model().mesh), MethodSet::DQB);
    // Alone on the table, where the benchmark puts it: taken from above, its handle under the
    // ring and little fingers, which arch the palm (CMC flexion) as they close.
    let mut scene = scene("objects");
    scene.objects.retain(|o| o.name == "teapot");
    scene.objects[0].position = Vec3::new(-0.25, scene.objects[0].position.y, -0.3);
    let s = script(&scene, &GraspTask::from_above("teapot"));
    let objects = ObjectColliders::new(&scene).unwrap();
    let m = objects.objects()[0].mesh.as_ref().unwrap();
    let flat: benchmark::FlatMesh = (m.vertices.iter().map(|v| v.to_array()).collect(), m.triangles.iter().flatten().copied().collect());
    let (mut deepest, mut turned, mut held_frames, mut slid, mut off_surface, mut turned_normal) = (0.0f32, 0.0f32, 0, 0.0f32, 0.0f32, 0.0f32);
    // Joints (per frame) that stopped on the teapot and were followed to the next frame.
    let mut stopped_on = 0;
    let proxies = dqhand::collision::HandProxies::new(&dqhand::collision::fit_proxies(&model(), dqhand::collision::PROXY_MARGIN), &model().skeleton);
    let mut query = dqhand::collision::ProxyMeshQuery::new(&proxies);
    let mut in_wrist: Option<glam::Quat> = None;
    // Where each joint touching the held teapot was last frame and the teapot's normal there,
    // in the teapot's frame.
    let mut touching: Vec<(usize, Vec3, Vec3)> = Vec::new();
    run(&scene, &s, |m, t, _| {
        let skin = dqb(&mut skin_layer, m).positions().to_vec();
        let teapot = &m.objects().objects()[0];
        for p in skin {
            deepest = deepest.max(benchmark::depth(teapot, Some(&flat), Vec3::from(p)));
        }
        if m.hands()[0].held().is_some_and(|i| m.names()[i] == "teapot") {
            held_frames += 1;
            // The teapot's orientation in the tracked wrist's frame: the grip must not turn it.
            let wrist = m.hands()[0].constraint().tracked_world()[m.hands()[0].rendered().rig().wrist()];
            let (_, r, _) = wrist.to_scale_rotation_translation();
            let here = r.inverse() * m.poses()[0].0;
            let first = *in_wrist.get_or_insert(here);
            turned = turned.max(first.angle_between(here));
            // Until the fingers open to let go, the joints that stopped on it (within the stop
            // distance: one farther off, though within the contact distance, is still closing
            // onto it) do not slide over it.
            let (q, p) = m.poses()[0];
            let on_teapot = |j: usize| q.inverse() * (Vec3::from(m.hands()[0].constraint().world()[j].translation) - p);
            for &(j, was, normal) in touching.iter().filter(|_| t < s.times.release) {
                let moved = on_teapot(j) - was;
                slid = slid.max((moved - normal * moved.dot(normal)).length());
                stopped_on += 1;
            }
            touching = m.hands()[0].contacts().iter().filter(|c| c.object == 0 && c.distance <= dqhand::collision::STOP_DISTANCE).map(|c| (c.joint, on_teapot(c.joint), q.inverse() * c.normal)).collect();
            // Its contacts (kept from frame to frame while the grip holds still) are what a
            // fresh query of the joint's proxies finds: the same point and normal.
            let teapot = &m.objects().objects()[0];
            let mesh = teapot.triangles().expect("the teapot is a mesh");
            for c in m.hands()[0].contacts() {
                let fresh = proxies.colliders().iter().enumerate().filter(|(_, p)| p.joint == c.joint).filter_map(|(k, p)| {
                    let pose = dqhand::collision::pose_of(&m.hands()[0].constraint().world()[p.joint]);
                    query.nearest(k, &pose, mesh, &teapot.pose, dqhand::collision::CONTACT_DISTANCE)
                });
                let miss = fresh.map(|f| (f.point.distance(c.point), f.normal.angle_between(c.normal))).fold((f32::INFINITY, f32::INFINITY), |a, b| if b.0 < a.0 { b } else { a });
                off_surface = off_surface.max(miss.0);
                turned_normal = turned_normal.max(miss.1);
            }
        } else {
            in_wrist = None;
            touching.clear();
        }
    });
    assert!(held_frames > 60, "held for {held_frames} frames");
    assert!(deepest <= 0.001, "the rendered skin went {deepest} m into the teapot");
    assert!(turned.to_degrees() < 2.0, "the teapot turned {}° in the hand", turned.to_degrees());
    assert!(stopped_on > STOPPED_ON_AT_LEAST, "only {stopped_on} joints stopped on the teapot were followed");
    assert!(slid < 0.0005, "a joint touching the teapot slid {slid} m over it");
    assert!(off_surface < 1e-4, "a contact point kept while held is {off_surface} m from a fresh query's");
    assert!(turned_normal < 1e-3, "a contact normal kept while held is {turned_normal} rad from a fresh query's");
}

#[test]
fn a_strike_at_10_m_s_does_not_pass_through_a_thin_plate() {
    let mut skin_layer = SkinLayer::new(Arc::clone(&model().mesh), MethodSet::DQB);
    let scene = scene("objects");
    let plate = scene.object("plate").unwrap();
    let ObjectShape::Box { size } = plate.shape else { panic!("the plate is a box") };
    // 10 m/s at 60 Hz: 17 cm a frame, 20 times the plate's thickness; the tracked palm ends
    // 1 cm into the plate, past its far side.
    let task = GraspTask { speed: 10.0, ..GraspTask::from_above("plate") };
    let s = script(&scene, &task);
    let mut deepest = 0.0f32;
    run(&scene, &s, |m, t, _| {
        if t > s.times.closed {
            return;
        }
        let centre = m.poses()[scene.objects.iter().position(|o| o.name == "plate").unwrap()].1;
        let skin = dqb(&mut skin_layer, m);
        for p in skin.positions() {
            let p = Vec3::from(*p);
            if (p.x - centre.x).abs() < size.x / 2.0 && (p.z - centre.z).abs() < size.z / 2.0 {
                // Below the plate's top over its footprint: inside it or through it.
                deepest = deepest.max(centre.y + size.y / 2.0 - p.y);
            }
        }
    });
    assert!(deepest < 0.002, "the rendered skin went {deepest} m below the plate's top");
}

#[test]
fn a_dropped_ball_bounces_and_rests_on_the_table_a_thrown_one_flies() {
    let scene = Scene::from_json(
        r#"{"table": {"height": 0.7}, "objects": [{"name": "ball", "shape": "sphere", "radius": 0.05, "position": [0, 0.9, 0], "mass": 0.2, "restitution": 0.6}]}"#,
        "drop.json",
        Path::new("."),
    )
    .unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let mut physics = ScenePhysics::new(&scene, &objects);
    let (mut lowest, mut bounced, mut falling) = (f32::INFINITY, 0.0f32, true);
    for _ in 0..240 {
        physics.step(1.0 / 60.0);
        let y = physics.pose(0).1.y;
        let vy = physics.velocity(0).0.y;
        lowest = lowest.min(y);
        if falling && vy > 0.0 {
            falling = false;
        }
        if !falling {
            bounced = bounced.max(y);
        }
    }
    let rest = physics.pose(0).1.y;
    assert!((rest - 0.75).abs() < 0.003, "rests with its bottom on the table top: centre at {rest}");
    assert!(lowest > 0.74, "never sinks into the table: {lowest}");
    assert!(bounced > 0.76, "restitution 0.6 bounces it: up to {bounced}");
    // Held 20 cm above the table and thrown sideways at 2 m/s.
    physics.hold(0, glam::Quat::IDENTITY, Vec3::new(0.0, 0.95, 0.0));
    physics.step(1.0 / 60.0);
    physics.release(0, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO, &[]);
    physics.step(1.0 / 60.0);
    let (p, v) = (physics.pose(0).1, physics.velocity(0).0);
    assert!((v.x - 2.0).abs() < 0.05 && p.x > 0.02, "keeps the hand's velocity: {v} at {p}");
}

/// A 4 cm ball on a table 70 cm high, its colliders, and the built-in hand's proxies.
fn ball_on_table_and_proxies() -> (Scene, ObjectColliders, dqhand::collision::HandProxies) {
    use dqhand::collision::{fit_proxies, HandProxies, PROXY_MARGIN};
    let scene = Scene::from_json(
        r#"{"table": {"height": 0.7}, "objects": [{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 0.74, 0], "mass": 0.15}]}"#,
        "ball.json",
        Path::new("."),
    )
    .unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let model = model();
    let proxies = HandProxies::new(&fit_proxies(&model, PROXY_MARGIN), &model.skeleton);
    (scene, objects, proxies)
}

#[test]
fn a_rolling_ball_stops_at_the_hand_lying_on_the_table() {
    use dqhand::collision::pose_of;
    use parry3d::bounding_volume::BoundingVolume;
    let (scene, objects, proxies) = ball_on_table_and_proxies();
    let model = model();
    // The hand at rest (flat), moved to lie on the table 10 cm along +X from the ball.
    let rest = model.skeleton.rest_world();
    let boxes = proxies.colliders().iter().map(|p| p.shape.compute_aabb(&pose_of(&rest[p.joint])));
    let b = boxes.reduce(|a, b| a.merged(&b)).unwrap();
    let shift = Vec3::new(0.04 + 0.1 - b.mins.x, 0.7 + 0.001 - b.mins.y, -b.center().z);
    let world: Vec<glam::Affine3A> = rest.iter().map(|w| glam::Affine3A::from_translation(shift) * *w).collect();
    let ball = parry3d::shape::Ball::new(0.04);
    // Rolled at the hand at 1.5 m/s, with the hand in the world and without: how deep the
    // ball goes into the hand's proxies.
    let roll = |with_hand: bool| {
        let mut physics = ScenePhysics::new(&scene, &objects);
        if with_hand {
            physics.add_hand(&proxies);
            physics.move_hand(0, Some(&world));
        }
        physics.hold(0, glam::Quat::IDENTITY, Vec3::new(0.0, 0.74, 0.0));
        physics.step(1.0 / 60.0);
        physics.release(0, Vec3::new(1.5, 0.0, 0.0), Vec3::ZERO, &[]);
        let mut deepest = 0.0f32;
        for _ in 0..60 {
            if with_hand {
                physics.move_hand(0, Some(&world));
            }
            physics.step(1.0 / 60.0);
            let at = parry3d::math::Pose::from_translation(physics.pose(0).1);
            for p in proxies.colliders() {
                if let Ok(Some(c)) = parry3d::query::contact(&at, &ball, &pose_of(&world[p.joint]), &*p.shape, 0.0) {
                    deepest = deepest.max(-c.dist);
                }
            }
        }
        deepest
    };
    assert!(roll(false) > 0.02, "without the hand the ball rolls through where it lies");
    let deepest = roll(true);
    assert!(deepest < 0.002, "the ball went {deepest} m into the hand");
}

#[test]
fn skin_depth_is_measured_against_the_true_surface_of_primitives_and_meshes() {
    // A closed cube mesh, 10 cm, and a 4 cm ball, against plain geometry (mesh depths within
    // MESH_DEPTH_RANGE_M of the surface, as measured).
    let dir = std::env::temp_dir().join(format!("dqhand-depth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let h = 0.05;
    let mut obj = String::new();
    for i in 0..8 {
        let c = |bit: i32| if i & bit == 0 { -h } else { h };
        obj += &format!("v {} {} {}\n", c(1), c(2), c(4));
    }
    // Outward counter-clockwise faces of the cube (1-based OBJ indices).
    for f in ["1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6"] {
        let v: Vec<&str> = f.split(' ').collect();
        obj += &format!("f {} {} {}\nf {} {} {}\n", v[0], v[1], v[2], v[0], v[2], v[3]);
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    std::fs::write(
        dir.join("scene.json"),
        r#"{"objects": [{"name": "cube", "shape": "mesh", "file": "cube.obj", "position": [1, 0, 0], "mass": 1},
                        {"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 1, 0], "mass": 1}]}"#,
    )
    .unwrap();
    let scene = Scene::load(&dir.join("scene.json")).unwrap();
    let objects = ObjectColliders::new(&scene).unwrap();
    let (cube, ball) = (&objects.objects()[0], &objects.objects()[1]);
    let m = cube.mesh.as_ref().unwrap();
    let flat = (m.vertices.iter().map(|v| v.to_array()).collect::<Vec<_>>(), m.triangles.iter().flatten().copied().collect::<Vec<_>>());
    for (p, want) in [(Vec3::new(1.0, 0.042, 0.0), 0.008), (Vec3::new(1.045, 0.0, 0.01), 0.005), (Vec3::new(1.0, 0.06, 0.0), 0.0), (Vec3::new(0.9, 0.0, 0.0), 0.0)] {
        let got = benchmark::depth(cube, Some(&flat), p);
        assert!((got - want).abs() < 1e-5, "cube mesh: depth of {p} is {got}, not {want}");
    }
    for (p, want) in [(Vec3::new(0.0, 1.01, 0.0), 0.03), (Vec3::new(0.0, 1.0, 0.039), 0.001), (Vec3::new(0.03, 1.03, 0.0), 0.0)] {
        let got = benchmark::depth(ball, None, p);
        assert!((got - want).abs() < 1e-5, "ball: depth of {p} is {got}, not {want}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn each_record_poses_the_tracked_and_the_rendered_hand_once() {
    // Pose once: per record and frame, one forward kinematics pass of the tracked hand (the
    // gesture loop's, which the contact constraint and the grasp logic read) and one of the
    // rendered hand (the constraint's, which the skin layer reads); nothing posed again.
    let scene = scene("grasp");
    let s = script(&scene, &GraspTask::from_above("ball"));
    let mut m = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
    let passes = |m: &ManipulationLoop| (m.hands()[0].input().kinematics().layer().passes(), m.hands()[0].rendered().layer().passes());
    let mut held = 0;
    for r in &s.records {
        let before = passes(&m);
        m.push(r).unwrap();
        m.step(r.time);
        let after = passes(&m);
        assert_eq!((after.0 - before.0, after.1 - before.1), (1, 1), "passes (tracked, rendered) for the record at {} s", r.time);
        held += usize::from(m.hands()[0].held().is_some());
    }
    assert!(held > 30, "the ball was held in {held} frames: the count covers grasping too");
}

/// The rendered hand against the true one (issue 28's targets): a free hand swept at 0.5 m/s
/// is at most 5 mm behind, a still one trembles under 0.5 mm RMS, on 1.5 mm joint noise; and
/// the lag grows with speed while the delay shrinks (the One Euro filter's cutoff rises).
#[test]
fn a_free_hand_lags_at_most_5_mm_at_half_a_metre_a_second_and_a_still_one_barely_trembles() {
    let scene = Scene { objects: Vec::new(), actions: Vec::new(), ..scene("grasp") };
    let height = scene.table.map_or(0.0, |t| t.height);
    let scores: Vec<benchmark::LagScore> = [0.1f32, 0.5, 2.0]
        .iter()
        .map(|&speed| {
            let sweep = grasp_script::sweep(&model(), Vec3::new(-0.8, height + 0.35, 0.0), Vec3::X, speed, Side::Right, 3).unwrap();
            let mut manip = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
            benchmark::lag(&mut manip, &sweep)
        })
        .collect();
    let at_half = scores[1];
    assert!(at_half.lag_m > 0.0 && at_half.lag_m <= 0.005, "{at_half:?}");
    for s in &scores {
        assert!(s.jitter_m > 0.0 && s.jitter_m <= 0.0005, "{s:?}");
    }
    assert!(scores[0].lag_m < scores[1].lag_m && scores[1].lag_m < scores[2].lag_m, "{scores:?}");
    assert!(scores[0].lag_s > scores[1].lag_s && scores[1].lag_s > scores[2].lag_s, "{scores:?}");
}

/// Issue 28: a ball let go by a still hand above the table, tracked as a headset tracks (2 mm
/// joint jitter, lost records, 30 ms behind), falls straight: no more than 1 cm across by
/// half way down, the opening fingers do not bat it away, and it lands where it was let go.
/// Issue 28: a ball let go on an upturned palm, 30 cm above the table, stays on it: the palm
/// under it holds it up. Before, every proxy within 2 mm of an object let go passed through
/// it (so that opening fingers do not bat it away), the palm too, and the ball fell through
/// the hand onto the table.
#[test]
fn a_ball_let_go_on_an_upturned_palm_stays_on_it() {
    use dqhand::collision::{pose_of, HandPart};
    use parry3d::bounding_volume::BoundingVolume;
    let (scene, objects, proxies) = ball_on_table_and_proxies();
    let model = model();
    // The rest hand (flat, palm down, fingers along −Z) turned palm up about its length, the
    // palm 30 cm above the table.
    let rest = model.skeleton.rest_world();
    let palm_box = |world: &[glam::Affine3A]| {
        let boxes = proxies.colliders().iter().filter(|p| p.part == HandPart::Palm).map(|p| p.shape.compute_aabb(&pose_of(&world[p.joint])));
        boxes.reduce(|a, b| a.merged(&b)).unwrap()
    };
    let upturned: Vec<glam::Affine3A> = rest.iter().map(|w| glam::Affine3A::from_rotation_z(core::f32::consts::PI) * *w).collect();
    let palm = palm_box(&upturned);
    let lift = Vec3::new(-palm.center().x, 1.0 - palm.mins.y, -palm.center().z);
    let world: Vec<glam::Affine3A> = upturned.iter().map(|w| glam::Affine3A::from_translation(lift) * *w).collect();
    let palm = palm_box(&world);
    let ball = parry3d::shape::Ball::new(0.04);
    // On the palm where the grasp left it (a fraction of a millimetre in, as held), over the
    // middle of the palm's box.
    let above = Vec3::new(0.0, palm.maxs.y + 0.05, 0.0);
    let gap = proxies
        .colliders()
        .iter()
        .filter(|p| p.part == HandPart::Palm)
        .filter_map(|p| parry3d::query::distance(&parry3d::math::Pose::from_translation(above), &ball, &pose_of(&world[p.joint]), &*p.shape).ok().map(|d| d.distance))
        .fold(f32::INFINITY, f32::min);
    let start = above - Vec3::Y * (gap + 0.0003);
    let mut physics = ScenePhysics::new(&scene, &objects);
    physics.add_hand(&proxies);
    physics.move_hand(0, Some(&world));
    physics.hold(0, glam::Quat::IDENTITY, start);
    physics.step(1.0 / 60.0);
    physics.release(0, Vec3::ZERO, Vec3::ZERO, &[0]);
    // A quarter of a second on the palm: a flat palm is no cup, and after that the ball rolls
    // off it over the wrist.
    let mut lowest = start.y;
    for _ in 0..15 {
        physics.move_hand(0, Some(&world));
        physics.step(1.0 / 60.0);
        lowest = lowest.min(physics.pose(0).1.y);
    }
    assert!(start.y - lowest < 0.002, "the ball fell {} mm from the palm in a quarter of a second", (start.y - lowest) * 1e3);
}

#[test]
fn a_ball_let_go_by_a_still_jittering_hand_falls_straight() {
    let scene = scene("grasp");
    let task = GraspTask { drop: 0.1, ..GraspTask::from_above("ball") };
    let exact = script(&scene, &task);
    for seed in 1..=3 {
        let s = grasp_script::HeadsetTracking::QUEST_LIKE.track(&exact, seed);
        assert!(s.records.len() < exact.records.len(), "some records are lost");
        let mut manip = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
        let carried_to = scene.objects[0].position + task.carry;
        let r = benchmark::score(&mut manip, &s, 0, carried_to);
        assert!(r.release_frames.is_some(), "seed {seed}: released");
        assert!(r.release_drift_m <= 0.01, "seed {seed}: {} mm across while falling", r.release_drift_m * 1e3);
        let rest = manip.poses()[0].1;
        let across = Vec3::new(rest.x - carried_to.x, 0.0, rest.z - carried_to.z).length();
        assert!(across <= 0.02, "seed {seed}: came to rest {} mm across from where it was carried", across * 1e3);
    }
}

/// The room has a floor: a ball rolled off the table lands on it and stays; one thrown out
/// of reach is put back where the scene file has it, and the step says so.
#[test]
fn the_floor_stops_a_falling_ball_and_one_thrown_out_of_reach_is_put_back() {
    let scene = scene("grasp");
    let objects = ObjectColliders::new(&scene).unwrap();
    let radius = 0.04;
    let mut physics = ScenePhysics::new(&scene, &objects);
    physics.hold(0, glam::Quat::IDENTITY, scene.objects[0].position + Vec3::Y * 0.05);
    physics.step(1.0 / 60.0);
    physics.release(0, Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, &[]); // off the table's front edge
    for _ in 0..180 {
        physics.step(1.0 / 60.0);
        assert!(physics.returned().is_empty());
    }
    let (_, p) = physics.pose(0);
    assert!((p.y - (dqhand::physics::FLOOR_Y + radius)).abs() < 0.005, "rests on the floor: {p:?}");

    let mut physics = ScenePhysics::new(&scene, &objects);
    physics.hold(0, glam::Quat::IDENTITY, scene.objects[0].position + Vec3::Y * 0.05);
    physics.step(1.0 / 60.0);
    physics.release(0, Vec3::new(30.0, 3.0, 0.0), Vec3::ZERO, &[]);
    let returned = (0..120).find(|_| {
        physics.step(1.0 / 60.0);
        physics.returned() == [0]
    });
    assert!(returned.is_some(), "put back once out of reach");
    let (_, p) = physics.pose(0);
    assert!(p.distance(scene.objects[0].position) < 1e-4, "where the scene file has it: {p:?}");
    assert_eq!(physics.velocity(0).0, Vec3::ZERO);
}

/// Issue 28: a marble pinched, carried and set down by a jittering hand stays where it was
/// set when the fingers open round it. With these seeds it rolled 10–26 cm away when the
/// release gave it the wrist's velocity measured over 4 frames (tracking noise and the
/// opening fingers' pull on the retargeted wrist, 16 cm/s and 2 rad/s): it is measured over 8
/// frames now, and a release slower than a toss gives none.
#[test]
fn a_marble_set_down_stays_when_the_fingers_open_round_it() {
    let scene = alone_on_table("marble");
    let task = GraspTask { object: "marble".into(), approach: Vec3::NEG_Y, fingers: Vec3::NEG_Z, speed: 0.5, lift: 0.12, carry: Vec3::new(0.5, 0.0, 0.0), pinch: true, drop: 0.0, aim: Vec3::ZERO };
    let exact = script(&scene, &task);
    for seed in [49, 60, 62, 64, 73] {
        let s = grasp_script::HeadsetTracking::QUEST_LIKE.track(&exact, seed);
        let mut manip = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
        let r = benchmark::score(&mut manip, &s, 0, scene.objects[0].position + task.carry);
        assert!(r.release_frames.is_some(), "seed {seed}: released");
        assert!(r.release_drift_m <= 0.01, "seed {seed}: rolled {} mm from where it was let go", r.release_drift_m * 1e3);
    }
}

/// Issue 28: the 4 cm ball alone on the table, taken from the side (thumb up) and from the
/// front at 2 m/s as `grasp-bench` takes it, is grasped, carried and set down without the
/// rendered hand passing into anything, and the tracked hand's skin stays out of the table.
/// Before, the script lifted the whole hand until its splayed little finger's joints were
/// 1 cm up: the palm was 3 cm above the ball's middle, the thumb closed past it and nothing
/// was grasped.
#[test]
fn a_ball_on_the_table_is_taken_from_the_side_and_the_front() {
    use dqhand::collision::{fit_proxies, pose_of, HandProxies};
    let scene = alone_on_table("ball");
    let table = scene.table.unwrap().height;
    // The skin's bounds, as the script keeps them off the table.
    let mut hand = model().hand_kinematics(JointModel::Full).unwrap();
    let skin = HandProxies::new(&fit_proxies(&model(), 0.0), hand.skeleton());
    for (palm, fingers) in [(Vec3::NEG_X, Vec3::NEG_Z), (Vec3::NEG_Z, Vec3::X)] {
        let task = GraspTask { object: "ball".into(), approach: palm, fingers, speed: 2.0, lift: 0.12, carry: Vec3::new(0.5, 0.0, 0.0), pinch: false, drop: 0.0, aim: Vec3::ZERO };
        let s = script(&scene, &task);
        for pose in &s.truth {
            hand.pose(pose);
            for p in skin.colliders() {
                let aabb = p.shape.compute_aabb(&pose_of(&hand.world()[p.joint]));
                assert!(aabb.mins.y >= table, "{palm}: the tracked skin {} mm into the table", (table - aabb.mins.y) * 1e3);
            }
        }
        let mut manip = ManipulationLoop::new(model(), JointModel::Full, None, InputConfig::default(), None, &scene, GraspParams::default()).unwrap();
        let r = benchmark::score(&mut manip, &s, 0, scene.objects[0].position + task.carry);
        assert!(r.success, "{palm}: {r:?}");
        assert!(!r.tunnelled, "{palm}: the rendered hand passed into the table or the ball");
        // Set down by a still hand, it stays where the hand let it go: the fingers round it
        // as it is let go pass through it (`ScenePhysics::release`), not push it (21 mm before).
        assert!(r.release_drift_m <= 0.01, "{palm}: the ball moved {} mm from where it was let go", r.release_drift_m * 1e3);
    }
}
