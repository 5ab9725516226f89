//! The one interface to the three deformers: LB, QB and DQB (paper section 4.4).

use glam::Affine3A;

use std::sync::Arc;

use rayon::prelude::*;

use super::crew::Crew;
use super::kernel::{self, Frame, FrameTable, Kernel};
use super::skinned_mesh::{SkinnedMesh, LANES};
use super::Method;
use super::{dual_quaternion_blend as dqb, linear_blend as lb, quaternion_blend as qb};

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

    /// Deformed unit normals, #V; empty for [`Self::positions_only`] buffers.
    #[must_use]
    pub fn normals(&self) -> &[[f32; 3]] {
        &self.normals[..self.vertex_count.min(self.normals.len())]
    }
}

/// Vertices below which a deformation is not split across threads (a split costs a few µs
/// of waking and joining; the built-in hand's 8,668 vertices take ~10 µs on one core).
pub const MIN_VERTICES_PER_THREAD: usize = 2048;

/// A skinning method with its per-frame scratch: bone parameters, the sign table and the
/// AVX-512 loop's lookup table of both; the kernel it runs and, optionally, a crew of threads
/// it splits each deformation across.
#[derive(Clone, Debug)]
pub struct Deformer {
    method: Method,
    lb: Vec<[f32; lb::W]>,
    quat: Vec<[f32; dqb::W]>,
    signs: Vec<f32>,
    lb_table: FrameTable<{ lb::W }>,
    quat_table: FrameTable<{ dqb::W }>,
    kernel: Kernel,
    crew: Option<Arc<Crew>>,
}

impl Deformer {
    /// A deformer for `mesh` (and meshes with the same joints and influence pairs) on the
    /// fastest kernel this CPU runs, on the calling thread; all buffers are allocated here.
    #[must_use]
    pub fn new(method: Method, mesh: &SkinnedMesh) -> Self {
        let joints = mesh.inverse_bind().len();
        let (lbn, qn, sn) = if method == Method::Lb { (joints, 0, 0) } else { (0, joints, mesh.pairs.len() + 1) };
        Self {
            method,
            lb: vec![[0.0; lb::W]; lbn],
            quat: vec![[0.0; dqb::W]; qn],
            signs: vec![1.0; sn],
            lb_table: if lbn > 0 { FrameTable::new(lbn) } else { FrameTable::default() },
            quat_table: if qn > 0 { FrameTable::new(qn) } else { FrameTable::default() },
            kernel: Kernel::best(),
            crew: None,
        }
    }

    /// The same deformer on `kernel` (one this CPU does not run falls back to the best it
    /// does; results agree to rounding).
    #[must_use]
    pub fn with_kernel(self, kernel: Kernel) -> Self {
        Self { kernel, ..self }
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

    /// Deforms `mesh` by the skinning transforms into `out` (positions and normals, or
    /// positions only, as `out` was made).
    ///
    /// Step 1 of paper 4.4: each joint's transform is converted once (matrix rows, quaternion
    /// and translation, or dual quaternion), and for the quaternion methods one sign per pair
    /// of joints that share a vertex, aligning the other joint's rotation to the hemisphere
    /// of the heaviest one. Steps 2–6: every vertex is blended, split across the crew's
    /// threads if there is one. Allocates nothing.
    ///
    /// * `skinning` — #joints transforms `world · inverse_bind`, from [`skinning_transforms`].
    ///
    /// # Panics
    /// If `skinning`, `out` or the deformer were made for a mesh with other joints or pairs.
    pub fn deform(&mut self, mesh: &SkinnedMesh, skinning: &[Affine3A], out: &mut Deformed) {
        assert_eq!(out.vertex_count, mesh.vertex_count(), "output buffers belong to another mesh");
        assert_eq!(skinning.len(), mesh.inverse_bind().len(), "one skinning transform per joint");
        // Only the AVX-512 loop reads the lookup table (the same choice as `kernel::deform`'s).
        let avx512 = self.kernel() == Kernel::Avx512;
        match self.method {
            Method::Lb => {
                assert_eq!(self.lb.len(), skinning.len(), "deformer made for another joint count");
                for (d, m) in self.lb.iter_mut().zip(skinning) {
                    *d = lb::params(m);
                }
                if avx512 {
                    self.lb_table.update(&self.lb, &[], &[]);
                }
            }
            Method::Qb | Method::Dqb => {
                assert_eq!(self.quat.len(), skinning.len(), "deformer made for another joint count");
                let convert = if self.method == Method::Qb { qb::params } else { dqb::params };
                for (d, m) in self.quat.iter_mut().zip(skinning) {
                    *d = convert(m);
                }
                assert_eq!(self.signs.len(), mesh.pairs.len() + 1, "deformer made for another mesh");
                for (sign, &(h, j)) in self.signs[1..].iter_mut().zip(&mesh.pairs) {
                    let (a, b) = (&self.quat[usize::from(h)], &self.quat[usize::from(j)]);
                    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
                    *sign = if dot < 0.0 { -1.0 } else { 1.0 };
                }
                if avx512 {
                    self.quat_table.update(&self.quat, &mesh.pairs, &self.signs);
                }
            }
        }
        let threads = self.crew.as_ref().map_or(1, |c| c.threads()).min(mesh.vertex_count() / MIN_VERTICES_PER_THREAD).max(1);
        match &self.crew {
            Some(crew) if threads > 1 => self.split(crew, threads, mesh, out),
            _ => self.run(mesh, 0, &mut out.positions, &mut out.normals),
        }
    }

    /// The vertex loop split into pieces claimed by `crew`'s threads: whole chunks per piece,
    /// an even number so the AVX-512 loop keeps its blocks, four pieces per thread so a
    /// helper that joins late still takes its share.
    fn split(&self, crew: &Crew, threads: usize, mesh: &SkinnedMesh, out: &mut Deformed) {
        /// The output buffers, written piece by piece from several threads.
        struct Outputs {
            positions: *mut [f32; 3],
            normals: *mut [f32; 3],
            len: usize,
            with_normals: bool,
        }
        // SAFETY: the threads write disjoint pieces (below).
        unsafe impl Sync for Outputs {}
        let len = out.positions.len();
        let span = (len / LANES).div_ceil(4 * threads).next_multiple_of(2) * LANES;
        let o = Outputs { positions: out.positions.as_mut_ptr(), normals: out.normals.as_mut_ptr(), len, with_normals: !out.normals.is_empty() };
        let o = &o; // The whole struct, not its (non-Sync) fields, is captured.
        crew.run(len.div_ceil(span), &|i| {
            let (start, end) = (i * span, ((i + 1) * span).min(o.len));
            // SAFETY: the crew runs each piece once, pieces are disjoint ranges within the
            // buffers (normals as long as positions, or unused), and `out` is borrowed
            // mutably until `run` returns, after every piece.
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
        let kernel = self.kernel;
        match self.method {
            Method::Lb => kernel::deform::<{ lb::W }, lb::Lb>(mesh, &Frame { params: &self.lb, signs: &[], table: &self.lb_table, kernel }, first, positions, normals),
            Method::Qb => kernel::deform::<{ qb::W }, qb::Qb>(mesh, &Frame { params: &self.quat, signs: &self.signs, table: &self.quat_table, kernel }, first, positions, normals),
            Method::Dqb => kernel::deform::<{ dqb::W }, dqb::Dqb>(mesh, &Frame { params: &self.quat, signs: &self.signs, table: &self.quat_table, kernel }, first, positions, normals),
        }
    }

    /// Deforms `mesh` once per pose, the poses split across `pool`'s threads (each pose on
    /// one thread): `skinning` holds the poses' transforms one after another (#joints each),
    /// `out` one buffer per pose. For data sets of posed hands. Each thread's scratch is made
    /// once per call.
    ///
    /// # Panics
    /// As [`Self::deform`], or if `skinning` does not hold `out.len()` poses.
    pub fn deform_batch(&self, pool: &rayon::ThreadPool, mesh: &SkinnedMesh, skinning: &[Affine3A], out: &mut [Deformed]) {
        let joints = mesh.inverse_bind().len();
        assert_eq!(skinning.len(), joints * out.len(), "one pose's transforms per output");
        let single = Self { crew: None, ..self.clone() };
        pool.install(|| {
            out.par_iter_mut().zip(skinning.par_chunks(joints)).for_each_init(|| single.clone(), |d, (o, s)| d.deform(mesh, s, o));
        });
    }
}

/// The skinning transform of each joint, `world · inverse_bind` (design.md).
///
/// * `world` — #joints world transforms from forward kinematics;
/// * `inverse_bind` — #joints, from the mesh;
/// * `out` — #joints, overwritten.
///
/// # Panics
/// If the lengths differ.
pub fn skinning_transforms(world: &[Affine3A], inverse_bind: &[Affine3A], out: &mut [Affine3A]) {
    assert!(world.len() == inverse_bind.len() && out.len() == world.len(), "one transform per joint");
    for ((o, w), ib) in out.iter_mut().zip(world).zip(inverse_bind) {
        *o = *w * *ib;
    }
}
