//! Depth maps of posed meshes seen by pinhole cameras: a z-buffer triangle rasterizer. The
//! synthetic data sets (`dqhand.synth`) need a hand mask and a depth map per sample, nothing
//! shaded, so a few dozen lines on the CPU do where a GPU renderer would be a heavy
//! dependency; a batch is rendered on every core with the GIL released.

use numpy::{PyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::{batch_one, numbers};

/// The nearest a triangle's corner may be to the camera (m): a triangle reaching nearer, or
/// behind the camera, is dropped rather than clipped (the data sets' cameras stay ≥ 0.1 m
/// from the hand).
const NEAR: f64 = 1e-3;

/// The largest image side taken, so that a wrong argument is an error, not a gigabyte array.
const MAX_SIDE: usize = 8192;

/// `faces` as triangles of vertex indices, each checked to name one of `vertices` vertices.
fn triangles(faces: &Bound<'_, PyAny>, vertices: usize) -> PyResult<Vec<[usize; 3]>> {
    let numpy = faces.py().import("numpy")?;
    // Integers only: a float index would be truncated to another vertex without a word.
    let dtype = numpy.call_method1("asarray", (faces,))?.getattr("dtype")?;
    if !numpy.call_method1("issubdtype", (&dtype, numpy.getattr("integer")?))?.is_truthy()? {
        return Err(PyValueError::new_err(format!("faces: expected integers of shape (F, 3) (vertex indices), got {dtype}")));
    }
    let converted = numpy
        .call_method1("ascontiguousarray", (faces, "int64"))
        .map_err(|e| PyValueError::new_err(format!("faces: expected integers of shape (F, 3) (vertex indices): {e}")))?;
    let converted = converted.cast_into::<PyArrayDyn<i64>>().map_err(PyErr::from)?.readonly();
    if converted.ndim() != 2 || converted.shape()[1] != 3 {
        let got = converted.shape().iter().map(ToString::to_string).collect::<Vec<_>>().join(", ");
        return Err(PyValueError::new_err(format!("faces: expected an array of shape (F, 3) (vertex indices), got shape ({got})")));
    }
    converted
        .as_slice()
        .expect("ascontiguousarray's result is contiguous")
        .chunks_exact(3)
        .enumerate()
        .map(|(t, corners)| {
            let mut triangle = [0; 3];
            for (slot, &i) in triangle.iter_mut().zip(corners) {
                *slot = usize::try_from(i).ok().filter(|&i| i < vertices).ok_or_else(|| PyValueError::new_err(format!("faces: index {i} of triangle {t} is not a vertex (there are {vertices})")))?;
            }
            Ok(triangle)
        })
        .collect()
}

/// Checks that each of the 3 × 3 (or 4 × 4) matrices in `values` ends in the row 0 … 0 1, as
/// intrinsics (extrinsics) do.
fn check_last_rows(values: &[f64], n: usize, argument: &str, what: &str) -> PyResult<()> {
    for (b, m) in values.chunks_exact(n * n).enumerate() {
        let row = &m[n * (n - 1)..];
        if row.iter().enumerate().any(|(i, &x)| x != if i == n - 1 { 1.0 } else { 0.0 }) {
            return Err(PyValueError::new_err(format!("{argument}[{b}]: not {what}: its last row is {row:?}")));
        }
    }
    Ok(())
}

/// The depth map of each mesh of a batch seen by its own pinhole camera (OpenCV's
/// conventions: x right, y down, z forward; pixel (i, j) centred on image point (i, j)):
/// `vertices` (B, V, 3) in metres, `faces` (F, 3) their triangles (either winding, none
/// culled), `intrinsics` (B, 3, 3) the camera matrices K (pixels), `extrinsics` (B, 4, 4)
/// world to camera. Returns (B, height, width) float32: each pixel's nearest surface depth
/// along the camera's z (m), 0 where no triangle covers its centre, so `depth > 0` is the mask.
/// Depth is interpolated as 1/z across a triangle's image, which is exact for a plane.
#[pyfunction]
#[pyo3(signature = (vertices, faces, intrinsics, extrinsics, width, height))]
pub(crate) fn render_depth<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    intrinsics: &Bound<'py, PyAny>,
    extrinsics: &Bound<'py, PyAny>,
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyArray<f32, numpy::Ix3>>> {
    for (argument, side) in [("width", width), ("height", height)] {
        if !(1..=MAX_SIDE).contains(&side) {
            return Err(PyValueError::new_err(format!("{argument}: {side} pixels is not an image side (1 to {MAX_SIDE})")));
        }
    }
    let vertices = numbers(vertices, "vertices", &[None, None, Some(3)], "each mesh's vertex positions, m")?;
    let (count, per_mesh) = (vertices.shape()[0], vertices.shape()[1]);
    let triangles = triangles(faces, per_mesh)?;
    let intrinsics = numbers(intrinsics, "intrinsics", &[Some(count), Some(3), Some(3)], "each camera's matrix K, pixels")?;
    let extrinsics = numbers(extrinsics, "extrinsics", &[Some(count), Some(4), Some(4)], "each camera's world-to-camera transform")?;
    let (points, cameras, poses) = (vertices.as_slice().expect("contiguous"), intrinsics.as_slice().expect("contiguous"), extrinsics.as_slice().expect("contiguous"));
    check_last_rows(cameras, 3, "intrinsics", "a camera matrix")?;
    check_last_rows(poses, 4, "extrinsics", "a rigid or affine transform")?;
    let projected = Vec::with_capacity(per_mesh);
    batch_one(py, &[count, height, width], projected, |projected, b, depth| {
        let view = Camera { k: &cameras[9 * b..9 * (b + 1)], pose: &poses[16 * b..16 * (b + 1)] };
        projected.clear();
        projected.extend(points[3 * per_mesh * b..3 * per_mesh * (b + 1)].chunks_exact(3).map(|p| view.project(p)));
        for t in &triangles {
            draw(t.map(|i| projected[i]), width, height, depth);
        }
    })
}

/// One camera of the batch: its K and world-to-camera transform, row-major.
struct Camera<'a> {
    k: &'a [f64],
    pose: &'a [f64],
}

impl Camera<'_> {
    /// A world point's image point and inverse depth (u, v, 1/z); 1/z is 0 when z < [`NEAR`].
    fn project(&self, p: &[f64]) -> [f64; 3] {
        let (m, k) = (self.pose, self.k);
        let [x, y, z] = [0, 4, 8].map(|r| m[r] * p[0] + m[r + 1] * p[1] + m[r + 2] * p[2] + m[r + 3]);
        if z < NEAR {
            return [0.0, 0.0, 0.0];
        }
        let (x, y) = (x / z, y / z);
        [k[0] * x + k[1] * y + k[2], k[3] * x + k[4] * y + k[5], 1.0 / z]
    }
}

/// Twice the signed area of the triangle (a, b, p) in the image.
fn edge(a: [f64; 3], b: [f64; 3], p: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Draws the projected triangle `corners` into `depth` (row-major, `width` × `height`),
/// keeping each covered pixel's nearest depth; pixels on an edge count as covered.
fn draw(corners: [[f64; 3]; 3], width: usize, height: usize, depth: &mut [f32]) {
    let [a, b, c] = corners;
    if corners.iter().any(|p| p[2] <= 0.0) {
        return;
    }
    let area = edge(a, b, [c[0], c[1]]);
    if area.abs() < 1e-12 {
        return;
    }
    let span = |axis: usize, size: usize| {
        let low = a[axis].min(b[axis]).min(c[axis]).ceil().max(0.0);
        let high = a[axis].max(b[axis]).max(c[axis]).floor().min(size as f64 - 1.0);
        (low <= high).then_some((low as usize, high as usize))
    };
    let (Some((x0, x1)), Some((y0, y1))) = (span(0, width), span(1, height)) else { return };
    for y in y0..=y1 {
        for x in x0..=x1 {
            let p = [x as f64, y as f64];
            // Barycentric weights of a, b and c; each ≥ 0 inside, whatever the winding.
            let (wa, wb) = (edge(b, c, p) / area, edge(c, a, p) / area);
            let wc = 1.0 - wa - wb;
            if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                let z = (1.0 / (wa * a[2] + wb * b[2] + wc * c[2])) as f32;
                let pixel = &mut depth[y * width + x];
                if *pixel == 0.0 || z < *pixel {
                    *pixel = z;
                }
            }
        }
    }
}
