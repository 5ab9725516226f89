//! A skinned triangle mesh stored for speed: structure of arrays, influences packed per vertex.

use std::sync::OnceLock;

use glam::{Affine3A, Vec3};

use crate::Warning;
use crate::{Error, Result};

/// Vertices are processed in chunks of this many; arrays are padded to a multiple of it.
pub const LANES: usize = 8;
/// Vertices per block of the slot-major weights: two chunks, one AVX-512 step.
pub(crate) const BLOCK: usize = 2 * LANES;

/// Most influences a vertex may have (glTF's JOINTS_0 and JOINTS_1).
pub const MAX_INFLUENCES: usize = 8;

/// A named range of a mesh, one glTF primitive: its vertices and triangle indices.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Part {
    /// Name of the glTF mesh the primitive belongs to.
    pub name: String,
    /// First vertex and vertex count.
    pub vertices: core::ops::Range<usize>,
    /// Range in the flat triangle index array (a multiple of three long).
    pub indices: core::ops::Range<usize>,
}

/// A skinned mesh as read from a file or built by the hand generator, before validation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Rest positions (m), #V.
    pub positions: Vec<[f32; 3]>,
    /// Rest normals, #V, or empty to compute them from the triangles.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates, #V, or empty.
    pub uvs: Vec<[f32; 2]>,
    /// Influences per vertex in `joints` and `weights` (1 to 8).
    pub stride: usize,
    /// Joint index of each influence, #V × stride.
    pub joints: Vec<u32>,
    /// Weight of each influence, #V × stride.
    pub weights: Vec<f32>,
    /// Triangle vertex indices, #F × 3, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
    /// Primitives; empty means one part spanning everything.
    pub parts: Vec<Part>,
    /// Inverse bind matrix of each skeleton joint, #joints.
    pub inverse_bind: Vec<Affine3A>,
}

impl MeshData {
    /// Reorders the vertices by their number of influences (stable, within each part) and
    /// renumbers the triangles. The AVX-512 kernel blends each block of 16 vertices over the
    /// most influences of any of them, so blocks of alike vertices skip the padding slots:
    /// 23 % fewer on the built-in hand, which is built so. Changes nothing but the order.
    pub fn sort_by_influence_count(&mut self) {
        let n = self.positions.len();
        if self.stride == 0 || self.joints.len() != n * self.stride || self.weights.len() != n * self.stride {
            return; // Left for `SkinnedMesh::new` to report.
        }
        let count = |v: usize| self.weights[v * self.stride..][..self.stride].iter().filter(|&&w| w > 0.0).count();
        let ranges = if self.parts.is_empty() { vec![0..n] } else { self.parts.iter().map(|p| p.vertices.clone()).collect() };
        let mut order: Vec<usize> = (0..n).collect();
        for r in ranges.into_iter().filter(|r| r.start <= r.end && r.end <= n) {
            order[r].sort_by_key(|&v| count(v));
        }
        let mut new_index = vec![0u32; n];
        for (new, &old) in order.iter().enumerate() {
            new_index[old] = new as u32;
        }
        fn permute<T: Copy>(a: &mut Vec<T>, order: &[usize], per: usize) {
            if a.len() == order.len() * per {
                *a = order.iter().flat_map(|&v| a[v * per..][..per].iter().copied()).collect();
            }
        }
        permute(&mut self.positions, &order, 1);
        permute(&mut self.normals, &order, 1);
        permute(&mut self.uvs, &order, 1);
        permute(&mut self.joints, &order, self.stride);
        permute(&mut self.weights, &order, self.stride);
        for i in &mut self.indices {
            if let Some(&new) = new_index.get(*i as usize) {
                *i = new;
            }
        }
    }
}

/// The lanes of one block's slot that share a joint and a pair (whose sign they take: a
/// value of `SkinnedMesh::slot_pairs`, 0 for the heaviest joint's own): bit `l` of `lanes` is
/// vertex `l` of the block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Run {
    pub joint: u16,
    pub lanes: u16,
    pub pair: u32,
}

/// The runs of `blocks` full blocks of `k` slots, from the packed influences, and where each
/// slot's runs start (one more entry than slots).
fn runs(blocks: usize, k: usize, joints: &[u16], weights: &[f32], slot_pairs: &[u32]) -> (Vec<Run>, Vec<u32>) {
    let (mut runs, mut start) = (Vec::new(), vec![0u32]);
    for block in 0..blocks {
        for s in 0..k {
            let first = runs.len();
            for l in 0..BLOCK {
                let i = (block * BLOCK + l) * k + s;
                if weights[i] == 0.0 {
                    continue;
                }
                let (joint, pair) = (joints[i], slot_pairs[i]);
                match runs[first..].iter_mut().find(|r: &&mut Run| r.joint == joint && r.pair == pair) {
                    Some(r) => r.lanes |= 1 << l,
                    None => runs.push(Run { joint, lanes: 1 << l, pair }),
                }
            }
            start.push(runs.len() as u32);
        }
    }
    (runs, start)
}

/// A validated skinned mesh in structure-of-arrays layout.
///
/// Positions and normals are stored as separate `x`, `y`, `z` arrays padded to a multiple
/// of [`LANES`]; each vertex has exactly [`Self::influences_per_vertex`] (joint, weight) slots,
/// heaviest first, zero-weight padding pointing at the heaviest joint. Weights sum to one.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinnedMesh {
    vertex_count: usize,
    pub(crate) pos: [Vec<f32>; 3],
    pub(crate) nrm: [Vec<f32>; 3],
    pub(crate) k: usize,
    pub(crate) joints: Vec<u16>,
    pub(crate) weights: Vec<f32>,
    /// The distinct (heaviest joint, other joint) pairs that share a vertex, for the
    /// quaternion methods' sign alignment: one sign per pair per frame.
    pub(crate) pairs: Vec<(u16, u16)>,
    /// Per influence slot, the index of its pair's sign: 0 for the heaviest joint itself
    /// (always +1), else 1 + the index into `pairs`.
    pub(crate) slot_pairs: Vec<u32>,
    /// Per chunk of [`LANES`] vertices, the most non-zero influences of any of its vertices:
    /// the blend loop stops there (weights are sorted, so the rest are zero).
    pub(crate) chunk_influences: Vec<u8>,
    /// The joints and weights again, per block of [`BLOCK`] vertices slot-major
    /// (`[block][slot][vertex]`, full blocks only): one load gives a slot of the whole block,
    /// one vertex per lane (the AVX-512 blend, which works on lanes from the start and so
    /// needs no transpose).
    pub(crate) block_joints: Vec<u16>,
    pub(crate) block_weights: Vec<f32>,
    /// The slots' sign indices (`slot_pairs`) laid out as `block_joints`: the gather strategy
    /// of the AVX-512 blend gathers each lane's sign with them.
    pub(crate) block_pairs: Vec<u32>,
    /// Per block and slot, the lanes that share a joint and a pair sign, lanes of zero
    /// weight left out: `block_runs[block_run_start[s]..block_run_start[s + 1]]` for slot
    /// `s = block * k + slot` (the broadcast strategy of the AVX-512 blend, which blends each
    /// run with one broadcast of each parameter).
    pub(crate) block_runs: Vec<Run>,
    pub(crate) block_run_start: Vec<u32>,
    /// The optimized centres of rotation (module `centres_of_rotation`), x/y/z arrays padded
    /// like `pos`: computed on first use, or given with the mesh.
    pub(crate) centres: OnceLock<[Vec<f32>; 3]>,
    max_influences: usize,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
    parts: Vec<Part>,
    inverse_bind: Vec<Affine3A>,
}

impl SkinnedMesh {
    /// Validates and packs mesh data. Returns the mesh and warnings (weights renormalised).
    ///
    /// # Errors
    /// [`Error::Mesh`] for a non-finite value, a joint index out of range, a vertex with no
    /// positive weight or a negative weight, a triangle index out of range, a non-invertible
    /// inverse bind matrix, or inconsistent array lengths. The message names the vertex,
    /// triangle or joint.
    pub fn new(data: MeshData) -> Result<(Self, Vec<Warning>)> {
        let n = data.positions.len();
        let joint_count = data.inverse_bind.len();
        let bad = |m: String| Err(Error::Mesh(m));
        if n == 0 {
            return bad("mesh has no vertices".into());
        }
        if !(1..=MAX_INFLUENCES).contains(&data.stride) {
            return bad(format!("{} influences per vertex; 1 to {MAX_INFLUENCES} are supported", data.stride));
        }
        if data.joints.len() != n * data.stride || data.weights.len() != n * data.stride {
            return bad(format!("influence arrays do not match the {n} vertices"));
        }
        if !data.normals.is_empty() && data.normals.len() != n {
            return bad(format!("{} normals for {n} vertices", data.normals.len()));
        }
        if !data.uvs.is_empty() && data.uvs.len() != n {
            return bad(format!("{} texture coordinates for {n} vertices", data.uvs.len()));
        }
        if joint_count == 0 || joint_count > usize::from(u16::MAX) {
            return bad(format!("{joint_count} joints; 1 to 65535 are supported"));
        }
        if data.indices.len() % 3 != 0 {
            return bad(format!("{} triangle indices is not a multiple of three", data.indices.len()));
        }
        if let Some((t, &i)) = data.indices.iter().enumerate().find(|(_, &i)| i as usize >= n) {
            return bad(format!("triangle {} uses vertex {i}, but there are only {n} vertices", t / 3));
        }
        if let Some(v) = data.positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return bad(format!("vertex {v} has a non-finite position {:?}", data.positions[v]));
        }
        if let Some(v) = data.normals.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return bad(format!("vertex {v} has a non-finite normal {:?}", data.normals[v]));
        }
        if let Some(v) = data.uvs.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return bad(format!("vertex {v} has a non-finite texture coordinate {:?}", data.uvs[v]));
        }
        for (j, m) in data.inverse_bind.iter().enumerate() {
            let det = m.matrix3.determinant();
            if !m.is_finite() || det.abs() < 1e-12 {
                return bad(format!("inverse bind matrix of joint {j} is not invertible (determinant {det})"));
            }
        }

        let mut warnings = Vec::new();
        let mut renormalised = 0usize;
        let mut slots: Vec<Vec<(u16, f32)>> = Vec::with_capacity(n);
        for v in 0..n {
            let mut inf = Vec::with_capacity(data.stride);
            for s in 0..data.stride {
                let (j, w) = (data.joints[v * data.stride + s], data.weights[v * data.stride + s]);
                if !w.is_finite() || w < 0.0 {
                    return bad(format!("vertex {v} has an invalid weight {w}"));
                }
                if w == 0.0 {
                    continue;
                }
                if j as usize >= joint_count {
                    return bad(format!("vertex {v} is bound to joint {j}, but the skin has only {joint_count} joints"));
                }
                // A joint listed twice (as in JOINTS_0 and JOINTS_1) is one influence.
                match inf.iter_mut().find(|i: &&mut (u16, f32)| u32::from(i.0) == j) {
                    Some(i) => i.1 += w,
                    None => inf.push((j as u16, w)),
                }
            }
            // Summed in f64: f32 weights near f32::MAX would overflow to infinity.
            let sum: f64 = inf.iter().map(|i| f64::from(i.1)).sum();
            if inf.is_empty() || sum <= 0.0 {
                return bad(format!("vertex {v} has no positive weight"));
            }
            if (sum - 1.0).abs() > 1e-3 {
                renormalised += 1;
            }
            inf.iter_mut().for_each(|i| i.1 = (f64::from(i.1) / sum) as f32);
            inf.retain(|i| i.1 > 0.0);
            inf.sort_by(|a, b| b.1.total_cmp(&a.1));
            slots.push(inf);
        }
        if renormalised > 0 {
            warnings.push(Warning::WeightsRenormalised { vertices: renormalised });
        }

        let max_influences = slots.iter().map(Vec::len).max().unwrap_or(1);
        let k = if max_influences <= 4 { 4 } else { MAX_INFLUENCES };
        let padded = n.div_ceil(LANES) * LANES;
        let mut joints = vec![0u16; padded * k];
        let mut weights = vec![0f32; padded * k];
        for (v, inf) in slots.iter().enumerate() {
            for s in 0..k {
                let (j, w) = inf.get(s).copied().unwrap_or((inf[0].0, 0.0));
                joints[v * k + s] = j;
                weights[v * k + s] = w;
            }
        }
        // Padding vertices: full weight on joint 0 at the origin, outputs ignored.
        for v in n..padded {
            weights[v * k] = 1.0;
        }

        let mut pair_index = std::collections::HashMap::new();
        let mut pairs = Vec::new();
        let slot_pairs: Vec<u32> = joints
            .chunks_exact(k)
            .flat_map(|js| js.iter().map(move |&j| (js[0], j)))
            .map(|(h, j)| {
                if h == j {
                    return 0;
                }
                *pair_index.entry((h, j)).or_insert_with(|| {
                    pairs.push((h, j));
                    pairs.len() as u32
                })
            })
            .collect();
        let blocks = padded / BLOCK;
        let (mut block_joints, mut block_weights, mut block_pairs) = (vec![0u16; blocks * k * BLOCK], vec![0f32; blocks * k * BLOCK], vec![0u32; blocks * k * BLOCK]);
        for v in 0..blocks * BLOCK {
            for s in 0..k {
                let (at, i) = (((v / BLOCK) * k + s) * BLOCK + v % BLOCK, v * k + s);
                (block_joints[at], block_weights[at], block_pairs[at]) = (joints[i], weights[i], slot_pairs[i]);
            }
        }
        let (block_runs, block_run_start) = runs(blocks, k, &joints, &weights, &slot_pairs);
        let chunk_influences = slots
            .chunks(LANES)
            .map(|c| c.iter().map(Vec::len).max().unwrap_or(1) as u8)
            .collect();
        let normals = if data.normals.is_empty() {
            crate::geometry::vertex_normals(&data.positions, &data.indices)
        } else {
            let faces = crate::geometry::vertex_normals(&data.positions, &data.indices);
            let mut replaced = 0;
            let normals = data
                .normals
                .iter()
                .zip(&faces)
                .map(|(&n, &f)| {
                    Vec3::from(n).try_normalize().unwrap_or_else(|| {
                        replaced += 1;
                        Vec3::from(f)
                    })
                })
                .map(|n| n.to_array())
                .collect();
            if replaced > 0 {
                warnings.push(Warning::NormalsReplaced { normals: replaced });
            }
            normals
        };
        let parts = if data.parts.is_empty() {
            vec![Part { name: "mesh".into(), vertices: 0..n, indices: 0..data.indices.len() }]
        } else {
            data.parts
        };
        let mesh = Self {
            vertex_count: n,
            pos: columns(&data.positions, padded),
            nrm: columns(&normals, padded),
            k,
            joints,
            weights,
            pairs,
            slot_pairs,
            chunk_influences,
            block_joints,
            block_weights,
            block_pairs,
            block_runs,
            block_run_start,
            centres: OnceLock::new(),
            max_influences,
            uvs: data.uvs,
            indices: data.indices,
            parts,
            inverse_bind: data.inverse_bind,
        };
        Ok((mesh, warnings))
    }

    /// Number of vertices.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Influence slots per vertex in the packed arrays (4 or 8).
    #[must_use]
    pub fn influences_per_vertex(&self) -> usize {
        self.k
    }

    /// The largest number of non-zero influences of any vertex.
    #[must_use]
    pub fn max_influences(&self) -> usize {
        self.max_influences
    }

    /// Histogram: element `i` counts the vertices with `i` non-zero influences.
    #[must_use]
    pub fn influence_histogram(&self) -> Vec<usize> {
        let mut h = vec![0; self.k + 1];
        for v in 0..self.vertex_count {
            h[self.weights[v * self.k..][..self.k].iter().filter(|&&w| w > 0.0).count()] += 1;
        }
        h
    }

    /// The (joint, weight) influences of vertex `v`, heaviest first, zero weights omitted.
    pub fn influences(&self, v: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let s = v * self.k;
        self.joints[s..s + self.k].iter().zip(&self.weights[s..s + self.k]).filter(|p| *p.1 > 0.0).map(|(&j, &w)| (j as usize, w))
    }

    /// Number of vertices whose heaviest influence is each joint, #joints.
    #[must_use]
    pub fn vertices_per_joint(&self) -> Vec<usize> {
        let mut c = vec![0; self.inverse_bind.len()];
        for v in 0..self.vertex_count {
            c[self.joints[v * self.k] as usize] += 1;
        }
        c
    }

    /// Rest position of vertex `v` (m).
    #[must_use]
    pub fn position(&self, v: usize) -> Vec3 {
        Vec3::new(self.pos[0][v], self.pos[1][v], self.pos[2][v])
    }

    /// Rest normal of vertex `v` (unit).
    #[must_use]
    pub fn normal(&self, v: usize) -> Vec3 {
        Vec3::new(self.nrm[0][v], self.nrm[1][v], self.nrm[2][v])
    }

    /// Rest positions, #V.
    #[must_use]
    pub fn positions(&self) -> Vec<[f32; 3]> {
        (0..self.vertex_count).map(|v| self.position(v).to_array()).collect()
    }

    /// Rest normals, #V.
    #[must_use]
    pub fn normals(&self) -> Vec<[f32; 3]> {
        (0..self.vertex_count).map(|v| self.normal(v).to_array()).collect()
    }

    /// Texture coordinates, #V or empty.
    #[must_use]
    pub fn uvs(&self) -> &[[f32; 2]] {
        &self.uvs
    }

    /// Triangle vertex indices, #F × 3.
    #[must_use]
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The primitives the mesh was made of.
    #[must_use]
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Inverse bind matrix of each skeleton joint, #joints.
    #[must_use]
    pub fn inverse_bind(&self) -> &[Affine3A] {
        &self.inverse_bind
    }

    /// The centres of rotation of the `cor` method, x/y/z arrays padded to whole chunks: those
    /// given by [`Self::with_centres_of_rotation`], else computed here once (the built-in
    /// hand's in a fraction of a second, split across rayon's threads).
    pub(crate) fn centres(&self) -> &[Vec<f32>; 3] {
        self.centres.get_or_init(|| {
            let centres = super::centres_of_rotation::centres_of_rotation(self);
            columns(&centres, self.pos[0].len())
        })
    }

    /// Vertex `v`'s centre of rotation (bind space, m; computed on first use, as
    /// [`crate::skin::Method::Cor`] needs them).
    ///
    /// # Panics
    /// If `v` is not a vertex of the mesh.
    #[must_use]
    pub fn centre_of_rotation(&self, v: usize) -> Vec3 {
        assert!(v < self.vertex_count, "vertex {v} of {}", self.vertex_count);
        let c = self.centres();
        Vec3::new(c[0][v], c[1][v], c[2][v])
    }

    /// Whether the centres of rotation are known already (given, or computed by an earlier
    /// use). Part of the mesh's equality: a mesh whose centres are known is not equal to the
    /// same mesh before they were.
    #[must_use]
    pub fn has_centres_of_rotation(&self) -> bool {
        self.centres.get().is_some()
    }

    /// The same mesh with its centres of rotation given (read from a file that stored them),
    /// #V, not computed.
    ///
    /// # Errors
    /// [`Error::Mesh`] if there is not one finite centre per vertex.
    pub fn with_centres_of_rotation(self, centres: &[[f32; 3]]) -> Result<Self> {
        if centres.len() != self.vertex_count {
            return Err(Error::Mesh(format!("{} centres of rotation for {} vertices", centres.len(), self.vertex_count)));
        }
        if let Some(v) = centres.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::Mesh(format!("vertex {v} has a non-finite centre of rotation {:?}", centres[v])));
        }
        Ok(Self { centres: OnceLock::from(columns(centres, self.pos[0].len())), ..self })
    }

    /// Number of joints that influence at least one vertex (the paper's "bones").
    #[must_use]
    pub fn bone_count(&self) -> usize {
        let mut used = vec![false; self.inverse_bind.len()];
        for (&j, &w) in self.joints.iter().zip(&self.weights).take(self.vertex_count * self.k) {
            used[usize::from(j)] |= w > 0.0;
        }
        used.iter().filter(|&&u| u).count()
    }
}

/// Per-vertex triples as x, y and z arrays, padded with zeros to `padded` vertices (whole
/// chunks).
fn columns(values: &[[f32; 3]], padded: usize) -> [Vec<f32>; 3] {
    [0, 1, 2].map(|c| {
        let mut col: Vec<f32> = values.iter().map(|p| p[c]).collect();
        col.resize(padded, 0.0);
        col
    })
}
