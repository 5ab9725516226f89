//! The realism report: LB, QB, DQB and CoR measured on the same sweeps of the same hand.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Vec3};
use serde_json::{json, Value};

use super::{count_self_intersections, edge_distortion, self_contact, JointRegion, SelfContact};
use crate::geometry::{check_closed, edges, enclosed_volume};
use crate::gesture::{gesture, GESTURES};
use crate::kinematics::{HandPart, HandRig, JointModel, KinematicsLayer, Limits, Pose, Transform};
use crate::model::Model;
use crate::skin::{Deformed, Deformer, Method, SelfContactPass};
use crate::{Error, Result};

/// What one sweep moves.
#[derive(Clone, Copy, Debug)]
enum Motion {
    /// One DOF of the `full` model, in degrees (limits off).
    Dof(&'static str),
    /// From the open hand to a gesture, in percent.
    Gesture(&'static str),
    /// The bones listed turned about the axis of the bone at the region's joint, through
    /// that joint, in degrees.
    Twist(&'static [&'static str]),
}

/// A named sweep: what moves, over which values, and the joint whose skin is measured.
struct SweepSpec {
    name: &'static str,
    parameter: &'static str,
    values: Vec<f32>,
    motion: Motion,
    joint: &'static str,
    next: &'static str,
    /// Whether each frame's [`self_contact`] is measured (where parts of the hand meet: it costs
    /// some 60 ms a frame and method).
    contact: bool,
}

fn specs() -> Vec<SweepSpec> {
    let range = |max: f32, step: f32| (0..=(max / step).round() as usize).map(|i| i as f32 * step).collect::<Vec<_>>();
    let index = ["index-finger-phalanx-intermediate", "index-finger-phalanx-distal"];
    vec![
        SweepSpec { name: "index-pip", parameter: "degrees", values: range(110.0, 5.0), motion: Motion::Dof("index-finger-phalanx-intermediate.flex"), joint: index[0], next: index[1], contact: false },
        SweepSpec { name: "index-mcp", parameter: "degrees", values: range(90.0, 5.0), motion: Motion::Dof("index-finger-phalanx-proximal.flex"), joint: "index-finger-phalanx-proximal", next: index[0], contact: false },
        SweepSpec { name: "fist", parameter: "percent", values: range(100.0, 10.0), motion: Motion::Gesture("fist"), joint: "middle-finger-phalanx-intermediate", next: "middle-finger-phalanx-distal", contact: true },
        SweepSpec { name: "index-pip-twist", parameter: "degrees", values: range(200.0, 10.0), motion: Motion::Twist(&["index-finger-phalanx-intermediate"]), joint: index[0], next: index[1], contact: false },
        SweepSpec {
            name: "wrist-twist",
            parameter: "degrees",
            values: range(200.0, 10.0),
            motion: Motion::Twist(&["thumb-metacarpal", "index-finger-metacarpal", "middle-finger-metacarpal", "ring-finger-metacarpal", "pinky-finger-metacarpal"]),
            joint: "middle-finger-metacarpal",
            next: "middle-finger-phalanx-proximal",
            contact: false,
        },
    ]
}

/// The measures of one frame under one method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameMetrics {
    /// Enclosed volume relative to rest; `None` if the mesh is not closed.
    pub volume: Option<f32>,
    /// Smallest distance-to-bones ratio in the joint region (< 1: collapse).
    pub min_distance: f32,
    /// Largest distance-to-bones ratio in the joint region (> 1: bulge).
    pub max_distance: f32,
    /// Smallest distance from the bone axis relative to the rest radius (candy wrapper).
    pub section_radius: f32,
    /// Mean relative edge-length change in the joint region.
    pub distortion_mean: f32,
    /// Largest relative edge-length change in the joint region.
    pub distortion_max: f32,
    /// Largest vertex displacement from the previous frame of the sweep (m), the deformer
    /// following the sweep frame by frame (its hemisphere signs kept along a twist).
    pub jump: f32,
    /// The same with each frame deformed alone (hemisphere signs by the shortest path, as a
    /// deformer's first frame): the flip at 180° of twist that following avoids.
    pub jump_alone: f32,
    /// Skin inside skin between the hand's parts, in the sweeps where they meet (the fist).
    pub self_contact: Option<SelfContact>,
}

/// One sweep measured under the four methods.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Sweep name (`index-pip`, …).
    pub name: &'static str,
    /// Unit of `values`.
    pub parameter: &'static str,
    /// The swept values.
    pub values: Vec<f32>,
    /// The joint whose skin is measured.
    pub joint: &'static str,
    /// Per method (in [`Method::ALL`] order), one entry per value.
    pub frames: [Vec<FrameMetrics>; 4],
}

/// Everything `dqhand metrics` reports.
#[derive(Clone, Debug)]
pub struct Report {
    /// Vertex count of the mesh.
    pub vertices: usize,
    /// `Ok` if the mesh is closed (volume defined), else why not.
    pub closed: std::result::Result<(), String>,
    /// The sweeps.
    pub sweeps: Vec<Sweep>,
    /// Intersecting triangle pairs of the rest mesh.
    pub rest_intersections: usize,
    /// Intersecting triangle pairs per gesture, per method (in [`Method::ALL`] order).
    pub intersections: Vec<(&'static str, [usize; 4])>,
    /// Skin inside skin between the fingers and the palm at rest (`None` for a mesh that is not
    /// closed, whose winding numbers mean nothing).
    pub rest_self_contact: Option<SelfContact>,
    /// The same in every gesture of the library, per method (none for a mesh not closed).
    pub self_contact: Vec<(&'static str, [SelfContact; 4])>,
    /// The same after the contact pass ([`SelfContactPass`]).
    pub self_contact_after_pass: Vec<(&'static str, [SelfContact; 4])>,
}

/// Each vertex's part of the hand, for [`self_contact`]: its heaviest joint's finger (0 the
/// thumb, its metacarpal included, which moves; to 4 the little finger), else 5, the palm (the
/// wrist and the finger metacarpals): [`HandPart`].
#[must_use]
pub fn hand_parts(model: &Model) -> Vec<u8> {
    let joints = model.skeleton.joints();
    (0..model.mesh.vertex_count())
        .map(|v| match model.mesh.influences(v).next().map(|(j, _)| HandPart::of(&joints[j].name)) {
            Some(HandPart::Finger(f)) => f as u8,
            _ => 5,
        })
        .collect()
}

/// The gestures whose self-intersections are counted, and whose self-contact is in the
/// headline (every gesture's is in the report).
const INTERSECTION_GESTURES: [&str; 5] = ["fist", "ok", "pinch", "victory", "thumbs_up"];

/// Measures LB, QB, DQB and CoR on every sweep, each frame posed once by the kinematics
/// layer and deformed by each method.
///
/// # Errors
/// [`Error::MissingJoint`] or [`Error::JointFrame`] if the model lacks the WebXR hand joints
/// the sweeps move; [`Error::NoSkin`] if no skin lies around a measured joint.
pub fn measure(model: Arc<Model>) -> Result<Report> {
    let mut hand = model.hand_kinematics(JointModel::Full)?;
    // The sweeps turn joints by local transforms of the rig's chain, the gestures by angles.
    let mut layer = KinematicsLayer::new(hand.skeleton().clone(), model.mesh.inverse_bind());
    let mut deformers = Method::ALL.map(|m| Deformer::new(m, &model.mesh));
    let mut alone = deformers.clone();
    let mut outputs = Method::ALL.map(|_| Deformed::new(&model.mesh));
    let mut outputs_alone = outputs.clone();
    // `follow`: the frame follows the last one deformed (within a sweep), else it is alone.
    let deform = |deformers: &mut [Deformer; 4], bones: &KinematicsLayer, follow: bool, outputs: &mut [Deformed; 4]| {
        for (d, o) in deformers.iter_mut().zip(outputs) {
            if !follow {
                d.forget_previous_frame();
            }
            d.deform(&model.mesh, bones, o);
        }
    };
    let rig = hand.rig().clone();
    let skeleton = rig.skeleton();
    let mesh = &model.mesh;
    let closed = check_closed(mesh.indices());
    let rest_positions = mesh.positions();
    let rest_volume = closed.is_ok().then(|| enclosed_volume(&rest_positions, mesh.indices()));
    let rest_world = skeleton.rest_world();
    let bind_world = model.bind_world();
    let all_edges = edges(mesh.indices());
    let mut locals = skeleton.rest_locals();
    let parts = hand_parts(&model);
    let mut sweeps = Vec::new();
    for spec in specs() {
        let region = JointRegion::new(skeleton, &bind_world, mesh, spec.joint, spec.next)?;
        let in_region = {
            let mut mark = vec![false; mesh.vertex_count()];
            region.vertices.iter().for_each(|&v| mark[v] = true);
            mark
        };
        let region_edges: Vec<[u32; 2]> = all_edges.iter().copied().filter(|e| e.iter().all(|&v| in_region[v as usize])).collect();
        let mut frames: [Vec<FrameMetrics>; 4] = Default::default();
        let mut previous: [Option<Vec<[f32; 3]>>; 4] = Default::default();
        let mut previous_alone: [Option<Vec<[f32; 3]>>; 4] = Default::default();
        let largest_move = |from: &Option<Vec<[f32; 3]>>, to: &[[f32; 3]]| {
            from.as_ref().map_or(0.0, |p| p.iter().zip(to).map(|(a, b)| Vec3::from(*a).distance(Vec3::from(*b))).fold(0.0, f32::max))
        };
        for (i, &value) in spec.values.iter().enumerate() {
            pose_sweep(&rig, &spec, value, &region, &rest_world, &mut locals)?;
            layer.pose_locals(&locals);
            deform(&mut deformers, &layer, i > 0, &mut outputs);
            deform(&mut alone, &layer, false, &mut outputs_alone);
            for m in Method::ALL {
                let posed = outputs[m.index()].positions();
                let world = layer.world();
                let (min_distance, max_distance) = region.distance_ratios(mesh, &bind_world, world, posed);
                let (distortion_mean, distortion_max) = edge_distortion(&rest_positions, posed, &region_edges);
                let jump = largest_move(&previous[m.index()], posed);
                let posed_alone = outputs_alone[m.index()].positions();
                let jump_alone = largest_move(&previous_alone[m.index()], posed_alone);
                frames[m.index()].push(FrameMetrics {
                    volume: rest_volume.map(|v0| (enclosed_volume(posed, mesh.indices()) / v0) as f32),
                    min_distance,
                    max_distance,
                    section_radius: region.section_radius(world, posed),
                    distortion_mean,
                    distortion_max,
                    jump,
                    jump_alone,
                    self_contact: (spec.contact && closed.is_ok()).then(|| self_contact(posed, mesh.indices(), &parts)),
                });
                previous[m.index()] = Some(posed.to_vec());
                previous_alone[m.index()] = Some(posed_alone.to_vec());
            }
        }
        sweeps.push(Sweep { name: spec.name, parameter: spec.parameter, values: spec.values, joint: spec.joint, frames });
    }
    let mut intersections = Vec::new();
    let (mut contact, mut after_pass) = (Vec::new(), Vec::new());
    let mut pass = SelfContactPass::new(mesh, &model.skeleton);
    for g in &GESTURES {
        hand.pose(&g.pose(JointModel::Full));
        deform(&mut deformers, hand.layer(), false, &mut outputs);
        let posed = |m: Method| outputs[m.index()].positions();
        if INTERSECTION_GESTURES.contains(&g.name) {
            intersections.push((g.name, Method::ALL.map(|m| count_self_intersections(posed(m), mesh.indices()))));
        }
        if closed.is_ok() {
            contact.push((g.name, Method::ALL.map(|m| self_contact(posed(m), mesh.indices(), &parts))));
            for o in &mut outputs {
                pass.apply(hand.layer().skinning(), o);
            }
            after_pass.push((g.name, Method::ALL.map(|m| self_contact(outputs[m.index()].positions(), mesh.indices(), &parts))));
        }
    }
    let rest_intersections = count_self_intersections(&rest_positions, mesh.indices());
    let rest_self_contact = closed.is_ok().then(|| self_contact(&rest_positions, mesh.indices(), &parts));
    Ok(Report { vertices: mesh.vertex_count(), closed, sweeps, rest_intersections, intersections, rest_self_contact, self_contact: contact, self_contact_after_pass: after_pass })
}

/// Writes the local transforms of one sweep value.
fn pose_sweep(rig: &HandRig, spec: &SweepSpec, value: f32, region: &JointRegion, rest_world: &[Affine3A], locals: &mut [Transform]) -> Result<()> {
    let model = JointModel::Full;
    let mut pose = Pose::rest(model.dof_count());
    match spec.motion {
        Motion::Dof(name) => pose.angles[model.dof_index(name)?] = value.to_radians(),
        Motion::Gesture(name) => {
            pose = pose.interpolate(&gesture(name)?.pose(model), value / 100.0, rig.rest_wrist());
        }
        Motion::Twist(_) => {}
    }
    rig.locals(&pose, Limits::Off, locals);
    if let Motion::Twist(bones) = spec.motion {
        // The axis of the bone J → C, through J, in world space at rest; each twisted bone's
        // parent is at rest, so turning it in world space is turning it in its parent's frame.
        let [_, j, c] = region.joints;
        let (pj, pc) = (Vec3::from(rest_world[j].translation), Vec3::from(rest_world[c].translation));
        let turn = Affine3A::from_translation(pj) * Affine3A::from_axis_angle((pc - pj).normalize(), value.to_radians()) * Affine3A::from_translation(-pj);
        let skeleton = rig.skeleton();
        for name in bones {
            let b = skeleton.index_of(name)?;
            let parent = skeleton.joints()[b].parent.map_or(Affine3A::IDENTITY, |p| rest_world[p]);
            let local = parent.inverse() * turn * parent * locals[b].to_affine();
            locals[b] = Transform { scale: locals[b].scale, ..Transform::from_affine(&local) };
        }
    }
    Ok(())
}

impl Report {
    /// The sweep called `name`.
    #[must_use]
    pub fn sweep(&self, name: &str) -> Option<&Sweep> {
        self.sweeps.iter().find(|s| s.name == name)
    }

    /// Everything as one JSON object: per sweep, per method, one array per measure.
    #[must_use]
    pub fn to_json(&self) -> Value {
        let sweeps: serde_json::Map<String, Value> = self
            .sweeps
            .iter()
            .map(|s| {
                let mut o = json!({ "parameter": s.parameter, "values": s.values, "joint": s.joint });
                for (m, frames) in Method::ALL.iter().zip(&s.frames) {
                    let col = |f: fn(&FrameMetrics) -> Value| Value::Array(frames.iter().map(f).collect());
                    o[m.as_str()] = json!({
                        "volume": col(|f| json!(f.volume)),
                        "min_distance": col(|f| json!(f.min_distance)),
                        "max_distance": col(|f| json!(f.max_distance)),
                        "section_radius": col(|f| json!(f.section_radius)),
                        "distortion_mean": col(|f| json!(f.distortion_mean)),
                        "distortion_max": col(|f| json!(f.distortion_max)),
                        "jump": col(|f| json!(f.jump)),
                        "jump_alone": col(|f| json!(f.jump_alone)),
                    });
                    if frames.iter().any(|f| f.self_contact.is_some()) {
                        o[m.as_str()]["self_contact"] = col(|f| f.self_contact.as_ref().map_or(Value::Null, contact_json));
                    }
                }
                (s.name.to_owned(), o)
            })
            .collect();
        json!({
            "vertices": self.vertices,
            "closed": self.closed.is_ok(),
            "volume_note": self.closed.as_ref().err().map(|why| format!("volume is undefined: the mesh is not closed ({why})")),
            "sweeps": sweeps,
            "self_intersections": {
                "rest": self.rest_intersections,
                "gestures": self.intersections.iter().map(|(g, c)| json!({ "gesture": g, "lb": c[0], "qb": c[1], "dqb": c[2], "cor": c[3] })).collect::<Vec<_>>(),
            },
            "self_contact": {
                "rest": self.rest_self_contact.as_ref().map(contact_json),
                "gestures": self.self_contact.iter().map(|(g, c)| json!({ "gesture": g, "lb": contact_json(&c[0]), "qb": contact_json(&c[1]), "dqb": contact_json(&c[2]), "cor": contact_json(&c[3]) })).collect::<Vec<_>>(),
                "after_contact_pass": self.self_contact_after_pass.iter().map(|(g, c)| json!({ "gesture": g, "lb": contact_json(&c[0]), "qb": contact_json(&c[1]), "dqb": contact_json(&c[2]), "cor": contact_json(&c[3]) })).collect::<Vec<_>>(),
            },
            "headline": self.headline().iter().map(|(label, v)| json!({ "measure": label, "lb": v[0], "qb": v[1], "dqb": v[2], "cor": v[3] })).collect::<Vec<_>>(),
        })
    }

    /// Writes one CSV per sweep into `dir`: value, method, then every measure.
    ///
    /// # Errors
    /// [`Error::Io`] if a file cannot be written.
    pub fn write_csv(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(Error::io(dir))?;
        for s in &self.sweeps {
            let mut text = format!("{},method,volume,min_distance,max_distance,section_radius,distortion_mean,distortion_max,jump_m,jump_alone_m,contact_depth_m,contact_volume_m3\n", s.parameter);
            for (m, frames) in Method::ALL.iter().zip(&s.frames) {
                for (v, f) in s.values.iter().zip(frames) {
                    let volume = f.volume.map_or(String::new(), |x| x.to_string());
                    let (depth, shared) = f.self_contact.map_or((String::new(), String::new()), |c| (c.depth_m.to_string(), c.volume_m3.to_string()));
                    let _ = writeln!(
                        text,
                        "{v},{m},{volume},{},{},{},{},{},{},{},{depth},{shared}",
                        f.min_distance, f.max_distance, f.section_radius, f.distortion_mean, f.distortion_max, f.jump, f.jump_alone
                    );
                }
            }
            let path = dir.join(format!("{}.csv", s.name));
            std::fs::write(&path, text).map_err(Error::io(&path))?;
        }
        Ok(())
    }

    /// The headline numbers: `(measure, [LB, QB, DQB, CoR])`, `None` where undefined.
    #[must_use]
    pub fn headline(&self) -> Vec<(String, [Option<f32>; 4])> {
        let at = |sweep: &str, value: f32, pick: fn(&FrameMetrics) -> Option<f32>| -> [Option<f32>; 4] {
            let s = self.sweep(sweep);
            let i = s.and_then(|s| s.values.iter().position(|&v| v == value));
            [0, 1, 2, 3].map(|m| s.zip(i).and_then(|(s, i)| pick(&s.frames[m][i])))
        };
        let worst = |sweep: &str, pick: fn(&FrameMetrics) -> f32| -> [Option<f32>; 4] {
            let s = self.sweep(sweep);
            [0, 1, 2, 3].map(|m| s.map(|s| s.frames[m].iter().map(pick).fold(0.0, f32::max)))
        };
        let mut rows: Vec<(String, [Option<f32>; 4])> = vec![
            ("volume at 90° index PIP flexion (rest = 1)".into(), at("index-pip", 90.0, |f| f.volume)),
            ("skin-to-bone distance at 90° PIP, smallest (collapse < 1)".into(), at("index-pip", 90.0, |f| Some(f.min_distance))),
            ("skin-to-bone distance at 90° PIP, largest (bulge > 1)".into(), at("index-pip", 90.0, |f| Some(f.max_distance))),
            ("largest edge-length change at 90° PIP".into(), at("index-pip", 90.0, |f| Some(f.distortion_max))),
            ("volume in a full fist".into(), at("fist", 100.0, |f| f.volume)),
            ("section radius at 180° PIP twist (candy wrapper < 1)".into(), at("index-pip-twist", 180.0, |f| Some(f.section_radius))),
            ("volume at 180° wrist twist".into(), at("wrist-twist", 180.0, |f| f.volume)),
            ("section radius at 180° wrist twist".into(), at("wrist-twist", 180.0, |f| Some(f.section_radius))),
            ("largest frame-to-frame jump, PIP twist 0–200° in 10° steps, followed (mm)".into(), {
                let j = worst("index-pip-twist", |f| f.jump);
                j.map(|x| x.map(|m| m * 1000.0))
            }),
            ("the same, each frame alone (mm)".into(), {
                let j = worst("index-pip-twist", |f| f.jump_alone);
                j.map(|x| x.map(|m| m * 1000.0))
            }),
        ];
        rows.extend(self.intersections.iter().map(|(g, c)| {
            (format!("intersecting triangle pairs, {g} (rest: {})", self.rest_intersections), c.map(|n| Some(n as f32)))
        }));
        for (g, c) in self.self_contact.iter().filter(|(g, _)| INTERSECTION_GESTURES.contains(g)) {
            let rest = self.rest_self_contact.unwrap_or_default();
            rows.push((format!("skin inside skin between parts, {g}: deepest (mm; rest {:.2})", rest.depth_m * 1000.0), c.map(|x| Some(x.depth_m * 1000.0))));
            rows.push((format!("skin inside skin between parts, {g}: shared volume (mm³; rest {:.1})", rest.volume_m3 * 1e9), c.map(|x| Some((x.volume_m3 * 1e9) as f32))));
        }
        for (g, c) in self.self_contact_after_pass.iter().filter(|(g, _)| INTERSECTION_GESTURES.contains(g)) {
            rows.push((format!("the same after the contact pass, {g}: deepest (mm)"), c.map(|x| Some(x.depth_m * 1000.0))));
            rows.push((format!("the same after the contact pass, {g}: shared volume (mm³)"), c.map(|x| Some((x.volume_m3 * 1e9) as f32))));
        }
        rows
    }

    /// The headline numbers as a markdown table.
    #[must_use]
    pub fn markdown(&self) -> String {
        let mut s = String::from("| measure | LB | QB | DQB | CoR |\n|---|---|---|---|---|\n");
        for (label, v) in self.headline() {
            let _ = writeln!(s, "| {label} | {} | {} | {} | {} |", format_value(v[0]), format_value(v[1]), format_value(v[2]), format_value(v[3]));
        }
        s
    }
}


/// One [`SelfContact`] in the report's JSON, in millimetres.
fn contact_json(x: &SelfContact) -> Value {
    json!({ "depth_mm": x.depth_m * 1000.0, "volume_mm3": x.volume_m3 * 1e9, "vertices": x.vertices })
}

/// A headline value as printed: `undefined`, a count, or three decimals.
#[must_use]
pub fn format_value(v: Option<f32>) -> String {
    match v {
        None => "undefined".to_owned(),
        Some(x) if x.fract() == 0.0 && x >= 1.0 => format!("{x}"),
        Some(x) => format!("{x:.3}"),
    }
}
