//! The one interface to the deformers: LB, QB and DQB (paper section 4.4), and CoR.

use glam::Affine3A;

use std::sync::Arc;

#[cfg(feature = "rayon")]
use rayon::prelude::*;

use super::crew::Crew;
use super::fastest_strategy::fastest_strategy;
use super::kernel::{self, Frame, FrameTable, Kernel};
use super::pair_signs::PairSigns;
use super::skinned_mesh::{SkinnedMesh, BLOCK, LANES};
use super::strategy::Strategy;
use super::Method;
use super::{centre_of_rotation_blend as cor, dual_quaternion_blend as dqb, linear_blend as lb, quaternion_blend as qb};
use crate::kinematics::KinematicsLayer;
use crate::math::DualQuat;

/// Deformed positions and normals of one frame, in the mesh's vertex order.
#[derive(Clone, Debug, PartialEq)]
pub struct Deformed {
    vertex_count: usize,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
}

impl Deformed {
    /// Buffers for `mesh`, positions and normals, allocated once and reused every frame.
    #[must_use]
    pub fn new(mesh: &SkinnedMesh) -> Self {
        let padded = mesh.pos[0].len();
        Self { vertex_count: mesh.vertex_count(), positions: vec![[0.0; 3]; padded], normals: vec![[0.0; 3]; padded] }
    }

    /// Buffers for positions only (collision queries, renderers that compute their own
    /// normals): the deformers then skip the normals' work.
    #[must_use]
    pub fn positions_only(mesh: &SkinnedMesh) -> Self {
        Self { normals: Vec::new(), ..Self::new(mesh) }
    }

    /// Deformed positions (m), #V.
    #[must_use]
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions[..self.vertex_count]
    }

    /// Positions and, unless [`Self::positions_only`], normals to change after the
    /// deformation (the contact pass), #V each.
    pub(crate) fn buffers_mut(&mut self) -> (&mut [[f32; 3]], Option<&mut [[f32; 3]]>) {
        let n = self.vertex_count;
        (&mut self.positions[..n], (!self.normals.is_empty()).then(|| &mut self.normals[..n]))
    }

    /// Deformed unit normals, #V; empty for [`Self::positions_only`] buffers.
    #[must_use]
    pub fn normals(&self) -> &[[f32; 3]] {
        &self.normals[..self.vertex_count.min(self.normals.len())]
    }
}

/// The bones' transforms a deformation reads: the skinning matrices and, where the
/// kinematics layer has made them, their unit dual quaternions (then not converted again).
#[derive(Clone, Copy, Debug)]
pub struct Bones<'a> {
    /// #joints skinning transforms `world · inverse_bind`.
    pub skinning: &'a [Affine3A],
    /// The same as unit dual quaternions (#joints), if already computed.
    pub dual_quats: Option<&'a [DualQuat]>,
}

impl<'a> From<&'a [Affine3A]> for Bones<'a> {
    fn from(skinning: &'a [Affine3A]) -> Self {
        Self { skinning, dual_quats: None }
    }
}

impl<'a> From<&'a Vec<Affine3A>> for Bones<'a> {
    fn from(skinning: &'a Vec<Affine3A>) -> Self {
        Self { skinning, dual_quats: None }
    }
}

impl<'a> From<&'a KinematicsLayer> for Bones<'a> {
    fn from(layer: &'a KinematicsLayer) -> Self {
        Self { skinning: layer.skinning(), dual_quats: Some(layer.dual_quats()) }
    }
}

/// The caller's memory a deformation writes ([`Deformer::deform_into`]): `f32` components
/// `[x, y, z]` per vertex, unpadded, in the mesh's vertex order.
#[derive(Debug)]
pub enum VertexBuffers<'a> {
    /// Positions (#V × 3, m) and, if given, unit normals (#V × 3); without normals their work
    /// is skipped.
    Separate {
        /// #V × 3 floats.
        positions: &'a mut [f32],
        /// #V × 3 floats, or none.
        normals: Option<&'a mut [f32]>,
    },
    /// `[px, py, pz, nx, ny, nz]` per vertex (#V × 6 floats), as many vertex buffers are laid out.
    Interleaved(&'a mut [f32]),
}

/// Parameters per joint of LB and CoR.
const WIDE: usize = lb::W;
const _: () = assert!(cor::W == WIDE && qb::W == dqb::W);

/// Vertices below which a deformation is not split across threads (a split costs a few µs
/// of waking and joining; the built-in hand's 8,668 vertices take ~10 µs on one core).
pub const MIN_VERTICES_PER_THREAD: usize = 2048;

/// A skinning method with its per-frame scratch: bone parameters, the sign table and the
/// AVX-512 loop's lookup table of both; the kernel it runs, that kernel's lookup
/// [`Strategy`] and, optionally, a crew of threads it splits each deformation across.
///
/// ```
/// use dqhand::glam::{Affine3A, Quat, Vec3};
/// use dqhand::skin::{Deformed, Deformer, MeshData, Method, SkinnedMesh};
///
/// // A triangle in the XY plane: two corners on bone 0, the third on bone 1 alone.
/// let (mesh, _warnings) = SkinnedMesh::new(MeshData {
///     positions: vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]], stride: 1,
///     joints: vec![0, 0, 1], weights: vec![1.0; 3], indices: vec![0, 1, 2],
///     inverse_bind: vec![Affine3A::IDENTITY; 2], ..MeshData::default()
/// })?;
/// let bone = Affine3A::from_rotation_translation(Quat::from_rotation_x(1.0), Vec3::new(0.0, 0.05, 0.02));
/// let skinning = vec![Affine3A::IDENTITY, bone]; // world · inverse_bind per joint
/// let mut out = Deformed::new(&mesh);
/// Deformer::new(Method::Dqb, &mesh).deform(&mesh, &skinning, &mut out);
/// // A vertex with one influence moves rigidly with its bone, its normal (+Z) turning with it.
/// assert!(Vec3::from(out.positions()[2]).abs_diff_eq(bone.transform_point3(Vec3::Y * 0.1), 1e-6));
/// assert!(Vec3::from(out.normals()[2]).abs_diff_eq(bone.transform_vector3(Vec3::Z), 1e-6));
/// assert_eq!(out.positions()[1], [0.1, 0.0, 0.0]);
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Deformer {
    method: Method,
    /// Sixteen parameters per joint: LB's matrix rows, or CoR's rotation and rows.
    wide: Vec<[f32; WIDE]>,
    /// Eight per joint: QB's rotation and translation, or DQB's dual quaternion.
    quat: Vec<[f32; dqb::W]>,
    signs: PairSigns,
    wide_table: FrameTable<WIDE>,
    quat_table: FrameTable<{ dqb::W }>,
    kernel: Kernel,
    strategy: Strategy,
    crew: Option<Arc<Crew>>,
}

impl Deformer {
    /// A deformer for `mesh` (and meshes with the same joints and influence pairs) on the
    /// fastest kernel this CPU runs, on the calling thread; all buffers are allocated here.
    ///
    /// On the AVX-512 kernel the lookup strategy is the one named by [`Strategy::ENV`] if
    /// that is set to a strategy's name (other values are ignored), else the fastest on this
    /// mesh: the first deformer of a method and mesh shape in the process times each
    /// strategy for a few frames (about a millisecond for the built-in hand), later ones
    /// reuse its choice. CoR's centres of rotation are computed here if the mesh does not
    /// have them yet (another mesh deformed by this deformer computes its own at its first
    /// deformation, which then allocates).
    #[must_use]
    pub fn new(method: Method, mesh: &SkinnedMesh) -> Self {
        if method == Method::Cor {
            mesh.centres();
        }
        let forced = std::env::var(Strategy::ENV).ok().and_then(|name| Strategy::named(&name));
        let strategy = forced.unwrap_or_else(|| if Kernel::best() == Kernel::Avx512 { fastest_strategy(method, mesh) } else { Strategy::Permute });
        let joints = mesh.inverse_bind().len();
        let pairs = mesh.pairs.len();
        let (wn, qn, pairs) = match method {
            Method::Lb => (joints, 0, 0),
            Method::Cor => (joints, 0, pairs),
            Method::Qb | Method::Dqb => (0, joints, pairs),
        };
        Self {
            method,
            wide: vec![[0.0; WIDE]; wn],
            quat: vec![[0.0; dqb::W]; qn],
            signs: PairSigns::new(pairs),
            wide_table: FrameTable::new(wn, strategy),
            quat_table: FrameTable::new(qn, strategy),
            kernel: Kernel::best(),
            strategy,
            crew: None,
        }
    }

    /// The same deformer on `kernel` (one this CPU does not run falls back to the best it
    /// does; results agree to rounding).
    #[must_use]
    pub fn with_kernel(self, kernel: Kernel) -> Self {
        Self { kernel, ..self }
    }

    /// The same deformer with the AVX-512 kernel's lookup `strategy` instead of the one
    /// chosen at construction (one that does not serve the skin, [`Strategy::Permute`] past
    /// 32 joints, gathers; every strategy gives the same bits: tests/skin.rs).
    #[must_use]
    pub fn with_strategy(self, strategy: Strategy) -> Self {
        let (wn, qn) = (self.wide.len(), self.quat.len());
        Self { strategy, wide_table: FrameTable::new(wn, strategy), quat_table: FrameTable::new(qn, strategy), ..self }
    }

    /// The same deformer splitting each deformation across `crew`'s threads (started once:
    /// no thread is started per frame), the calling thread included, for meshes of at least
    /// [`MIN_VERTICES_PER_THREAD`] vertices per thread.
    #[must_use]
    pub fn with_crew(self, crew: Arc<Crew>) -> Self {
        Self { crew: Some(crew), ..self }
    }

    /// The method.
    #[must_use]
    pub fn method(&self) -> Method {
        self.method
    }

    /// The kernel that runs.
    #[must_use]
    pub fn kernel(&self) -> Kernel {
        self.kernel.or_best()
    }

    /// The AVX-512 kernel's lookup strategy; `None` where another kernel runs (they have
    /// none).
    #[must_use]
    pub fn strategy(&self) -> Option<Strategy> {
        (self.kernel() == Kernel::Avx512).then(|| if self.strategy.serves(self.wide.len().max(self.quat.len())) { self.strategy } else { Strategy::Gather })
    }

    /// Deforms `mesh` by the bones' transforms into `out` (positions and normals, or
    /// positions only, as `out` was made).
    ///
    /// Step 1 of paper 4.4: each joint's transform is converted once (matrix rows, quaternion
    /// and translation, dual quaternion: the kinematics layer's own, where `bones` carries
    /// them, or quaternion and rows), and for the quaternion methods one sign per pair of
    /// joints that share a vertex, aligning the other joint's rotation to the hemisphere of
    /// the heaviest one: the nearer one, or, while their relative rotation moves less than
    /// 60° a frame, the one it had in the previous frame, so a joint twisted past 180° keeps
    /// the way it turned (up to 270°) instead of flipping. Steps 2–6:
    /// every vertex is blended, split across the crew's threads if there is one. Allocates
    /// nothing.
    ///
    /// * `bones` — #joints skinning transforms `world · inverse_bind`: a
    ///   [`KinematicsLayer`], or a slice of them ([`skinning_transforms`]).
    ///
    /// # Panics
    /// If `bones`, `out` or the deformer were made for a mesh with other joints or pairs.
    ///
    /// [`skinning_transforms`]: crate::kinematics::skinning_transforms
    pub fn deform<'a>(&mut self, mesh: &SkinnedMesh, bones: impl Into<Bones<'a>>, out: &mut Deformed) {
        assert_eq!(out.vertex_count, mesh.vertex_count(), "output buffers belong to another mesh");
        self.prepare(mesh, bones.into());
        self.blend(mesh, &mut out.positions, &mut out.normals);
    }

    /// [`Self::deform`] into the caller's own memory (a mapped GPU buffer, a NumPy array),
    /// unpadded, in the mesh's vertex order. Separate buffers are written directly by the
    /// vertex loop (the last vertices of a partial block through a small stack buffer); an
    /// interleaved buffer is written block by block through one. Allocates nothing.
    ///
    /// # Panics
    /// As [`Self::deform`]; if a buffer's length is not #V × 3 (#V × 6 interleaved).
    pub fn deform_into<'a>(&mut self, mesh: &SkinnedMesh, bones: impl Into<Bones<'a>>, out: VertexBuffers<'_>) {
        let n = mesh.vertex_count();
        let padded = mesh.pos[0].len();
        self.prepare(mesh, bones.into());
        let (mut tail_p, mut tail_n) = ([[0.0f32; 3]; BLOCK], [[0.0f32; 3]; BLOCK]);
        match out {
            VertexBuffers::Separate { positions, normals } => {
                assert_eq!(positions.len(), n * 3, "positions: #V × 3 floats");
                let (positions, _) = positions.as_chunks_mut::<3>();
                let mut normals = normals.map(|b| {
                    assert_eq!(b.len(), n * 3, "normals: #V × 3 floats");
                    b.as_chunks_mut::<3>().0
                });
                // Whole blocks in place, the rest (fewer than a block, padded) on the stack.
                let bulk = n / BLOCK * BLOCK;
                let tail_n = if normals.is_some() { &mut tail_n[..padded - bulk] } else { &mut [][..] };
                self.blend(mesh, &mut positions[..bulk], normals.as_deref_mut().map_or(&mut [], |b| &mut b[..bulk]));
                self.run(mesh, bulk / LANES, &mut tail_p[..padded - bulk], tail_n);
                positions[bulk..].copy_from_slice(&tail_p[..n - bulk]);
                if let Some(normals) = normals {
                    normals[bulk..].copy_from_slice(&tail_n[..n - bulk]);
                }
            }
            VertexBuffers::Interleaved(buffer) => {
                assert_eq!(buffer.len(), n * 6, "interleaved: #V × 6 floats");
                let (vertices, _) = buffer.as_chunks_mut::<6>();
                for (b, block) in vertices.chunks_mut(BLOCK).enumerate() {
                    let end = ((b + 1) * BLOCK).min(padded);
                    let len = end - b * BLOCK;
                    self.run(mesh, b * BLOCK / LANES, &mut tail_p[..len], &mut tail_n[..len]);
                    for ((v, p), nrm) in block.iter_mut().zip(&tail_p).zip(&tail_n) {
                        v[..3].copy_from_slice(p);
                        v[3..].copy_from_slice(nrm);
                    }
                }
            }
        }
    }

    /// The next deformation does not follow the last one (a seek, another clip, an unrelated
    /// pose): its hemisphere signs take the shortest path, as a new deformer's first frame.
    pub fn forget_previous_frame(&mut self) {
        self.signs.forget();
    }

    /// The next deformation follows the frames `other` deformed, as if this deformer had
    /// deformed them: QB, DQB and CoR of one mesh choose their signs from the same rotations.
    /// Nothing where either is LB (no signs).
    pub(crate) fn follow(&mut self, other: &Deformer) {
        if self.method != Method::Lb && other.method != Method::Lb {
            self.signs.follow(&other.signs);
        }
    }

    /// Step 1 of paper 4.4 for this frame: bone parameters, pair signs, lookup tables.
    fn prepare(&mut self, mesh: &SkinnedMesh, bones: Bones<'_>) {
        let skinning = bones.skinning;
        assert_eq!(skinning.len(), mesh.inverse_bind().len(), "one skinning transform per joint");
        // Only the AVX-512 loop reads the lookup table (the same choice as `kernel::deform`'s).
        let avx512 = self.kernel() == Kernel::Avx512;
        match self.method {
            Method::Lb | Method::Cor => {
                assert_eq!(self.wide.len(), skinning.len(), "deformer made for another joint count");
                let convert = if self.method == Method::Lb { lb::params } else { cor::params };
                for (d, m) in self.wide.iter_mut().zip(skinning) {
                    *d = convert(m);
                }
                let pairs: &[(u16, u16)] = if self.method == Method::Lb { &[] } else { &mesh.pairs };
                self.signs.update(&self.wide, pairs);
                if avx512 {
                    self.wide_table.update(&self.wide, pairs, self.signs.as_slice());
                }
            }
            Method::Qb | Method::Dqb => {
                assert_eq!(self.quat.len(), skinning.len(), "deformer made for another joint count");
                match bones.dual_quats {
                    Some(dqs) if self.method == Method::Dqb => {
                        assert_eq!(dqs.len(), skinning.len(), "one dual quaternion per joint");
                        for (d, q) in self.quat.iter_mut().zip(dqs) {
                            *d = q.to_array();
                        }
                    }
                    _ => {
                        let convert = if self.method == Method::Qb { qb::params } else { dqb::params };
                        for (d, m) in self.quat.iter_mut().zip(skinning) {
                            *d = convert(m);
                        }
                    }
                }
                self.signs.update(&self.quat, &mesh.pairs);
                if avx512 {
                    self.quat_table.update(&self.quat, &mesh.pairs, self.signs.as_slice());
                }
            }
        }
    }

    /// Steps 2–6 over the whole chunks from the first that `positions` holds, split across the
    /// crew if there is one.
    fn blend(&self, mesh: &SkinnedMesh, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        let threads = self.crew.as_ref().map_or(1, |c| c.threads()).min(positions.len() / MIN_VERTICES_PER_THREAD).max(1);
        match &self.crew {
            Some(crew) if threads > 1 => self.split(crew, threads, mesh, positions, normals),
            _ => self.run(mesh, 0, positions, normals),
        }
    }

    /// The vertex loop split into pieces claimed by `crew`'s threads: whole chunks per piece,
    /// an even number so the AVX-512 loop keeps its blocks, four pieces per thread so a
    /// helper that joins late still takes its share.
    fn split(&self, crew: &Crew, threads: usize, mesh: &SkinnedMesh, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        /// The output buffers, written piece by piece from several threads.
        struct Outputs {
            positions: *mut [f32; 3],
            normals: *mut [f32; 3],
            len: usize,
            with_normals: bool,
        }
        // SAFETY: the threads write disjoint pieces (below).
        unsafe impl Sync for Outputs {}
        let len = positions.len();
        let span = (len / LANES).div_ceil(4 * threads).next_multiple_of(2) * LANES;
        let o = Outputs { positions: positions.as_mut_ptr(), normals: normals.as_mut_ptr(), len, with_normals: !normals.is_empty() };
        let o = &o; // The whole struct, not its (non-Sync) fields, is captured.
        crew.run(len.div_ceil(span), &|i| {
            let (start, end) = (i * span, ((i + 1) * span).min(o.len));
            // SAFETY: the crew runs each piece once, pieces are disjoint ranges within the
            // buffers (normals as long as positions, or unused), and the buffers are
            // borrowed mutably until `run` returns, after every piece.
            let (p, n) = unsafe {
                (
                    core::slice::from_raw_parts_mut(o.positions.add(start), end - start),
                    if o.with_normals { core::slice::from_raw_parts_mut(o.normals.add(start), end - start) } else { &mut [] },
                )
            };
            self.run(mesh, start / LANES, p, n);
        });
    }

    /// The vertex loop over the chunks from `first` that `positions` holds.
    fn run(&self, mesh: &SkinnedMesh, first: usize, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        let (kernel, strategy) = (self.kernel, self.strategy);
        match self.method {
            Method::Lb => kernel::deform::<WIDE, lb::Lb>(mesh, &Frame { params: &self.wide, signs: &[], centres: &[], table: &self.wide_table, kernel, strategy }, first, positions, normals),
            Method::Qb => kernel::deform::<{ qb::W }, qb::Qb>(mesh, &Frame { params: &self.quat, signs: self.signs.as_slice(), centres: &[], table: &self.quat_table, kernel, strategy }, first, positions, normals),
            Method::Dqb => kernel::deform::<{ dqb::W }, dqb::Dqb>(mesh, &Frame { params: &self.quat, signs: self.signs.as_slice(), centres: &[], table: &self.quat_table, kernel, strategy }, first, positions, normals),
            Method::Cor => kernel::deform::<WIDE, cor::Cor>(mesh, &Frame { params: &self.wide, signs: self.signs.as_slice(), centres: mesh.centres(), table: &self.wide_table, kernel, strategy }, first, positions, normals),
        }
    }

    #[cfg(feature = "rayon")]
    /// Deforms `mesh` once per pose, the poses split across `pool`'s threads (each pose on
    /// one thread): `skinning` holds the poses' transforms one after another (#joints each),
    /// `out` one buffer per pose. For data sets of posed hands. Each thread's scratch is made
    /// once per call; each pose is deformed as a first frame (no pose follows another), so
    /// the result does not depend on which thread took which.
    ///
    /// # Panics
    /// As [`Self::deform`], or if `skinning` does not hold `out.len()` poses.
    pub fn deform_batch(&self, pool: &rayon::ThreadPool, mesh: &SkinnedMesh, skinning: &[Affine3A], out: &mut [Deformed]) {
        let joints = mesh.inverse_bind().len();
        assert_eq!(skinning.len(), joints * out.len(), "one pose's transforms per output");
        // CoR's centres, computed here, not by the first pose's job: that computation runs on
        // rayon too, and a thread waiting for its pieces may take up another pose's job,
        // which would then wait for the computation under way on that very thread.
        if self.method == Method::Cor {
            mesh.centres();
        }
        let single = Self { crew: None, ..self.clone() };
        pool.install(|| {
            out.par_iter_mut().zip(skinning.par_chunks(joints)).for_each_init(|| single.clone(), |d, (o, s)| {
                d.forget_previous_frame();
                d.deform(mesh, s, o);
            });
        });
    }
}

