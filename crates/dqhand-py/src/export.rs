//! Files from Python through the engine's writers: the hand as the rigged, skinned GLB that
//! `dqhand hand` writes (three.js, Blender and `Hand.load` read it back), and one posed mesh
//! as `dqhand skin` writes it (PLY, OBJ or a static GLB, with normals).

use std::path::PathBuf;

use dqhand::io::{write_posed, write_skinned_glb};
use dqhand::skin::{Deformed, Deformer, Method};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::{numbers, to_py, wrists, Hand};

/// `Hand.export_gltf`: a binary glTF, so only a `.glb` name (a `.gltf` would promise JSON).
pub(crate) fn gltf(hand: &Hand, py: Python<'_>, path: PathBuf) -> PyResult<()> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb")) {
        return Err(PyValueError::new_err(format!("path: {}: the hand is written as binary glTF; name it .glb", path.display())));
    }
    py.detach(|| write_skinned_glb(&hand.model, &path)).map_err(to_py)
}

/// `Hand.export_posed`: one pose (angles (D,), wrist (4, 4) or None) posed, deformed with
/// normals and written by the format its name says.
pub(crate) fn posed(hand: &Hand, py: Python<'_>, path: PathBuf, angles: &Bound<'_, PyAny>, wrist: Option<&Bound<'_, PyAny>>, method: &str, limits: bool) -> PyResult<()> {
    let method: Method = method.parse().map_err(to_py)?;
    let dofs = hand.joint_model.dof_count();
    let angles = numbers(angles, "angles", &[Some(dofs)], &format!("one pose's joint angles in radians, in the order of dof_names, {} model", hand.joint_model))?;
    let wrist = match wrist.filter(|w| !w.is_none()) {
        Some(w) => {
            let one = numbers(w, "wrist", &[Some(4), Some(4)], "one rigid transform, or None")?;
            // The batch's check of a rigid transform, on a batch of one.
            let batch = one.as_array().to_owned().into_shape_with_order((1, 4, 4)).expect("16 values");
            let batch = numpy::PyArray::from_owned_array(py, batch).into_any();
            wrists(Some(&batch), 1).map_err(|e| PyValueError::new_err(e.value(py).to_string().replacen("wrist[0]", "wrist", 1)))?.remove(0)
        }
        None => None,
    };
    let (mut kinematics, mut pose) = hand.kinematics(limits);
    for (a, &x) in pose.angles.iter_mut().zip(angles.as_slice().expect("contiguous")) {
        *a = x as f32;
    }
    pose.wrist = wrist;
    let mesh = &hand.model.mesh;
    py.detach(|| {
        kinematics.pose(&pose);
        let mut out = Deformed::new(mesh);
        Deformer::new(method, mesh).deform(mesh, kinematics.layer(), &mut out);
        write_posed(&path, out.positions(), out.normals(), mesh.uvs(), mesh.indices())
    })
    .map_err(to_py)
}
