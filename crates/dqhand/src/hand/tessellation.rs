//! From the implicit hand to a triangle mesh of an exact vertex count.
//!
//! 1. The distance field is sampled on a regular grid, refined only near the surface (blocks
//!    whose centre is far from it take the centre's value), in parallel.
//! 2. Naive surface nets (crate `fast-surface-nets`) extracts a closed mesh at least three
//!    times denser than wanted (the spacing comes from a coarse trial run's vertex count) on a
//!    grid fine enough for the gaps between the fingers; where two sheets still share a cell,
//!    a slightly finer grid is tried.
//! 3. meshoptimizer's edge-collapse simplifier (crate `meshoptimizer-rs`, its pure-Rust port;
//!    regularised for even
//!    triangles) reduces it. Every collapse on a closed mesh removes one vertex and two
//!    triangles, so the triangle target `2 (n − χ)` lands on exactly `n` vertices.
//! 4. A few rounds of tangential relaxation even out the spacing; after each, every vertex is
//!    projected back onto the surface by Newton steps along the field's gradient.
//! 5. Normals are the field's gradient: smooth, with no facets from the triangulation.

use fast_surface_nets::ndshape::{RuntimeShape, Shape};
use fast_surface_nets::{surface_nets, SurfaceNetsBuffer};
use glam::Vec3;
use meshoptimizer_rs::{Positions, SimplifyOptions, SimplifySettings, Workspace};
use rayon::prelude::*;

use super::shape::HandShape;
use crate::geometry::{check_closed, enclosed_volume};
use crate::{Error, Result};

/// Surface-nets vertices per wanted vertex: enough for the simplifier to choose from.
const OVERSAMPLE: f32 = 3.0;
/// Grid samples along the longest side in the trial run that sets the spacing.
const TRIAL_SAMPLES: f32 = 96.0;
/// Samples per side of a refinement block.
const BLOCK: usize = 8;
/// Finer grids tried when surface nets leaves a non-manifold edge.
const RETRIES: usize = 8;
/// Rounds of tangential relaxation.
const RELAX_ROUNDS: usize = 4;

/// A closed, outward-oriented triangle mesh on the hand's surface.
#[derive(Clone, Debug, Default)]
pub(crate) struct Surface {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

/// Meshes `shape` with exactly `vertices` vertices.
///
/// # Errors
/// [`Error::Tessellation`] if the extracted surface is not closed, or cannot be simplified to
/// `vertices` (asked for fewer than the hand's shape can keep).
pub(crate) fn tessellate(shape: &HandShape, vertices: usize) -> Result<Surface> {
    let extent = shape.bounds[1] - shape.bounds[0];
    let trial_h = extent.max_element() / TRIAL_SAMPLES;
    let trial = sample(shape, trial_h);
    let h = (trial_h * (trial.positions.len() as f32 / (OVERSAMPLE * vertices as f32)).sqrt()).min(shape.finest_feature);
    let dense = closed_sample(shape, h)?;
    let mut surface = simplify(&dense, vertices)?;
    relax(shape, &mut surface, h);
    let eps = 1e-4 * extent.max_element();
    surface.normals = surface.positions.iter().map(|&p| shape.gradient(p.into(), eps).normalize_or_zero().to_array()).collect();
    Ok(surface)
}

/// Samples the field with spacing `h` and extracts its zero set with surface nets.
fn sample(shape: &HandShape, h: f32) -> Surface {
    let [lo, hi] = shape.bounds;
    // Whole blocks, plus one sample so the last block's far faces are sampled too.
    let blocks = ((hi - lo) / (h * BLOCK as f32)).ceil().as_uvec3().max(glam::UVec3::ONE);
    let dims = blocks * BLOCK as u32 + 1;
    let grid = RuntimeShape::<u32, 3>::new(dims.to_array());
    let at = |x: u32, y: u32, z: u32| lo + Vec3::new(x as f32, y as f32, z as f32) * h;
    let half_diagonal = 0.5 * (BLOCK as f32) * h * 3f32.sqrt();
    // Each block fills its samples (the first BLOCK along each axis, plus the far faces for
    // the last block of a row); blocks are computed in parallel, one z-slab each.
    let slab = (dims.x * dims.y) as usize * BLOCK;
    let mut sdf = vec![0.0f32; grid.size() as usize];
    sdf.par_chunks_mut(slab).enumerate().for_each(|(bz, chunk)| {
        let z0 = bz as u32 * BLOCK as u32;
        let nz = (chunk.len() / (dims.x * dims.y) as usize) as u32;
        for by in 0..blocks.y {
            for bx in 0..blocks.x {
                let (x0, y0) = (bx * BLOCK as u32, by * BLOCK as u32);
                let centre = at(x0, y0, z0) + Vec3::splat(0.5 * BLOCK as f32 * h);
                let d = shape.distance(centre);
                let far = d.abs() > 1.5 * half_diagonal + 2.0 * h;
                let x1 = if bx + 1 == blocks.x { dims.x } else { x0 + BLOCK as u32 };
                let y1 = if by + 1 == blocks.y { dims.y } else { y0 + BLOCK as u32 };
                for z in 0..nz {
                    for y in y0..y1 {
                        for x in x0..x1 {
                            let i = ((z * dims.y + y) * dims.x + x) as usize;
                            chunk[i] = if far { d } else { shape.distance(at(x, y, z0 + z)) };
                        }
                    }
                }
            }
        }
    });
    let mut buffer = SurfaceNetsBuffer::default();
    surface_nets(&sdf, &grid, [0; 3], (dims - 1).to_array(), &mut buffer);
    let positions = buffer.positions.iter().map(|&p| (lo + Vec3::from(p) * h).to_array()).collect();
    Surface { positions, normals: Vec::new(), indices: buffer.indices }
}

/// Surface nets at spacing `h`, closed and oriented outward. Where two sheets of the surface
/// pass through one grid cell, surface nets joins them in one vertex and the mesh is not a
/// manifold there; such coincidences depend on where the samples fall, so a slightly finer
/// grid is tried, up to [`RETRIES`] times.
fn closed_sample(shape: &HandShape, h: f32) -> Result<Surface> {
    let mut h = h;
    let mut tries = 0;
    loop {
        match closed(sample(shape, h), h) {
            Err(_) if tries < RETRIES => {
                tries += 1;
                h *= 0.985;
            }
            result => return result,
        }
    }
}

/// Checks that the extracted surface is closed and orients it outward.
fn closed(surface: Surface, h: f32) -> Result<Surface> {
    let Surface { positions, mut indices, .. } = surface;
    check_closed(&indices).map_err(|e| Error::Tessellation(format!("the hand's surface at grid spacing {h:.5} m is not closed: {e}")))?;
    if enclosed_volume(&positions, &indices) < 0.0 {
        indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
    }
    Ok(Surface { positions, normals: Vec::new(), indices })
}

/// Simplifies a closed mesh to exactly `vertices` vertices and drops the unused ones.
fn simplify(dense: &Surface, vertices: usize) -> Result<Surface> {
    let v = dense.positions.len() as i64;
    let f = (dense.indices.len() / 3) as i64;
    let euler = v - f / 2; // V − E + F with E = 3F/2 on a closed triangle mesh
    let target_triangles = 2 * (vertices as i64 - euler);
    if vertices as i64 > v || target_triangles < 4 {
        return Err(Error::Tessellation(format!("cannot mesh the hand with {vertices} vertices (its dense surface has {v})")));
    }
    let positions: Vec<[f32; 3]> = dense.positions.iter().map(|&p| p.into()).collect();
    let settings = SimplifySettings { target_index_count: 3 * target_triangles as usize, target_error: 1.0, options: SimplifyOptions::REGULARIZE };
    let simplified = meshoptimizer_rs::simplify(&dense.indices, Positions::from_packed(&positions), settings, &mut Workspace::default());
    let mut indices = simplified.map_err(|e| Error::Tessellation(format!("meshoptimizer: {e}")))?.indices;
    // Keep the vertices still referenced, in first-use order.
    let mut remap = vec![u32::MAX; dense.positions.len()];
    let mut positions = Vec::with_capacity(vertices);
    for i in &mut indices {
        let r = &mut remap[*i as usize];
        if *r == u32::MAX {
            *r = positions.len() as u32;
            positions.push(dense.positions[*i as usize]);
        }
        *i = *r;
    }
    if positions.len() != vertices {
        return Err(Error::Tessellation(format!(
            "the simplifier stopped at {} vertices instead of {vertices}; ask for more vertices",
            positions.len()
        )));
    }
    check_closed(&indices).map_err(|e| Error::Tessellation(format!("the simplified hand surface is not closed: {e}")))?;
    Ok(Surface { positions, normals: Vec::new(), indices })
}

/// Tangential relaxation (each vertex moves halfway toward its neighbours' centroid within
/// its tangent plane), then projection onto the surface, `RELAX_ROUNDS` times.
fn relax(shape: &HandShape, surface: &mut Surface, h: f32) {
    let n = surface.positions.len();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in surface.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !neighbours[a as usize].contains(&b) {
                neighbours[a as usize].push(b);
                neighbours[b as usize].push(a);
            }
        }
    }
    let eps = 0.05 * h;
    let project = |p: Vec3| {
        let mut p = p;
        for _ in 0..3 {
            let g = shape.gradient(p, eps);
            let g2 = g.length_squared();
            if g2 > 0.0 {
                p -= g * (shape.distance(p) / g2);
            }
        }
        p
    };
    let mut next = surface.positions.clone();
    for _ in 0..RELAX_ROUNDS {
        next.par_iter_mut().enumerate().for_each(|(v, out)| {
            let p = Vec3::from(surface.positions[v]);
            let ring = &neighbours[v];
            let centroid = ring.iter().map(|&u| Vec3::from(surface.positions[u as usize])).sum::<Vec3>() / ring.len() as f32;
            let normal = shape.gradient(p, eps).normalize_or_zero();
            let shift = centroid - p;
            *out = project(p + 0.5 * (shift - normal * shift.dot(normal))).to_array();
        });
        std::mem::swap(&mut surface.positions, &mut next);
    }
}
