//! The realism metrics from Python: the engine's measures of `dqhand metrics` (volume against
//! rest, collapse and bulge near a bent joint, the candy wrapper of a twisted one, edge-length
//! distortion, self-intersections), for any batch of poses under one method instead of its
//! fixed sweeps; and the whole report of those sweeps.

use dqhand::geometry::{check_closed, edges, enclosed_volume};
use dqhand::kinematics::Pose;
use dqhand::metrics::{count_self_intersections, edge_distortion, measure, JointRegion};
use dqhand::skin::{Deformed, Deformer, Method};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::{to_py, Hand};

/// The measures of one pose, in the order of [`NAMES`], and its self-intersections.
type Measures = ([f32; 6], u64);

/// The per-pose measures, by name, as `FrameMetrics` calls them.
const NAMES: [&str; 6] = ["volume", "min_distance", "max_distance", "section_radius", "distortion_mean", "distortion_max"];

/// The region around `joint` ([`JointRegion`]): `next` the joint after it along its chain,
/// else its only child in the skeleton.
fn region(hand: &Hand, joint: &str, next: Option<&str>) -> PyResult<JointRegion> {
    let skeleton = hand.kinematics.skeleton();
    let next = match next {
        Some(next) => next.to_owned(),
        None => {
            let j = skeleton.index_of(joint).map_err(to_py)?;
            let children: Vec<&str> = skeleton.joints().iter().filter(|c| c.parent == Some(j)).map(|c| c.name.as_str()).collect();
            match children[..] {
                [only] => only.to_owned(),
                _ => return Err(PyValueError::new_err(format!("next: joint {joint:?} has {} children ({}); name the one its bone points to", children.len(), children.join(", ")))),
            }
        }
    };
    JointRegion::new(skeleton, &hand.model.bind_world(), &hand.model.mesh, joint, &next).map_err(to_py)
}

/// `Hand.joint_region`: the region's vertices, its joints (parent, joint, next) and radii.
pub(crate) fn joint_region<'py>(hand: &Hand, py: Python<'py>, joint: &str, next: Option<&str>) -> PyResult<Bound<'py, PyDict>> {
    let region = region(hand, joint, next)?;
    let out = PyDict::new(py);
    out.set_item("vertices", PyArray1::from_iter(py, region.vertices.iter().map(|&v| v as u32)))?;
    out.set_item("joints", PyArray1::from_iter(py, region.joints.iter().map(|&j| j as u32)))?;
    out.set_item("radius", region.radius)?;
    out.set_item("min_radius", region.min_radius)?;
    Ok(out)
}

/// `Hand.realism`'s arguments, as Python passes them.
pub(crate) struct RealismArgs<'a, 'py> {
    pub angles: &'a Bound<'py, PyAny>,
    pub wrist: Option<&'a Bound<'py, PyAny>>,
    pub method: &'a str,
    pub joint: &'a str,
    pub next: Option<&'a str>,
    pub self_intersections: bool,
    pub limits: bool,
}

/// `Hand.realism`: each pose posed, deformed and measured on every core, the GIL released.
pub(crate) fn realism<'py>(hand: &Hand, py: Python<'py>, args: &RealismArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let method: Method = args.method.parse().map_err(to_py)?;
    let region = region(hand, args.joint, args.next)?;
    let poses = hand.batch_of(args.angles, args.wrist)?;
    let source = poses.source();
    let (model, mesh) = (&hand.model, &hand.model.mesh);
    let (bind_world, rest) = (model.bind_world(), mesh.positions());
    let rest_volume = check_closed(mesh.indices()).is_ok().then(|| enclosed_volume(&rest, mesh.indices()));
    let mut inside = vec![false; mesh.vertex_count()];
    region.vertices.iter().for_each(|&v| inside[v] = true);
    let region_edges: Vec<[u32; 2]> = edges(mesh.indices()).into_iter().filter(|e| e.iter().all(|&v| inside[v as usize])).collect();
    let crossings_wanted = args.self_intersections;
    let start = (hand.kinematics(args.limits), Deformer::new(method, mesh), Deformed::positions_only(mesh));
    let measures: Vec<Measures> = py.detach(|| {
        (0..poses.count)
            .into_par_iter()
            .map_init(
                || start.clone(),
                |((k, pose), deformer, deformed): &mut (_, Deformer, Deformed), b| {
                    let pose: &Pose = source.read(b, pose);
                    k.pose(pose);
                    deformer.forget_previous_frame();
                    deformer.deform(mesh, k.layer(), deformed);
                    let posed = deformed.positions();
                    let (min_distance, max_distance) = region.distance_ratios(mesh, &bind_world, k.world(), posed);
                    let (distortion_mean, distortion_max) = edge_distortion(&rest, posed, &region_edges);
                    let volume = rest_volume.map_or(f32::NAN, |v0| (enclosed_volume(posed, mesh.indices()) / v0) as f32);
                    let crossings = if crossings_wanted { count_self_intersections(posed, mesh.indices()) as u64 } else { 0 };
                    ([volume, min_distance, max_distance, region.section_radius(k.world(), posed), distortion_mean, distortion_max], crossings)
                },
            )
            .collect()
    });
    let out = PyDict::new(py);
    for (i, name) in NAMES.iter().enumerate() {
        out.set_item(name, PyArray1::from_iter(py, measures.iter().map(|m| m.0[i])))?;
    }
    if args.self_intersections {
        out.set_item("self_intersections", PyArray1::from_iter(py, measures.iter().map(|m| m.1)))?;
    }
    Ok(out)
}

/// `Hand.realism_report`: `dqhand metrics --json` of this hand, as Python objects.
pub(crate) fn report<'py>(hand: &Hand, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
    let json = py.detach(|| measure(hand.model.clone()).map(|r| r.to_json().to_string())).map_err(to_py)?;
    py.import("json")?.call_method1("loads", (json,))
}
