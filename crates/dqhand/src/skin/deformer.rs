//! The one interface to the three deformers: LB, QB and DQB (paper section 4.4).

use glam::Affine3A;

use super::kernel::{self, Frame};
use super::skinned_mesh::SkinnedMesh;
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
    /// Buffers for `mesh`, allocated once and reused every frame.
    #[must_use]
    pub fn new(mesh: &SkinnedMesh) -> Self {
        let padded = mesh.pos[0].len();
        Self { vertex_count: mesh.vertex_count(), positions: vec![[0.0; 3]; padded], normals: vec![[0.0; 3]; padded] }
    }

    /// Deformed positions (m), #V.
    #[must_use]
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions[..self.vertex_count]
    }

    /// Deformed unit normals, #V.
    #[must_use]
    pub fn normals(&self) -> &[[f32; 3]] {
        &self.normals[..self.vertex_count]
    }
}

/// A skinning method with its per-frame scratch: bone parameters and the sign table.
#[derive(Clone, Debug)]
pub struct Deformer {
    method: Method,
    lb: Vec<[f32; lb::W]>,
    quat: Vec<[f32; dqb::W]>,
    signs: Vec<f32>,
    portable: bool,
}

impl Deformer {
    /// A deformer for `mesh` (and meshes with the same joints and influence pairs); all
    /// buffers are allocated here.
    #[must_use]
    pub fn new(method: Method, mesh: &SkinnedMesh) -> Self {
        let joints = mesh.inverse_bind().len();
        let (lbn, qn, sn) = if method == Method::Lb { (joints, 0, 0) } else { (0, joints, mesh.pairs.len() + 1) };
        Self { method, lb: vec![[0.0; lb::W]; lbn], quat: vec![[0.0; dqb::W]; qn], signs: vec![1.0; sn], portable: false }
    }

    /// The same deformer on the portable kernel, even where the AVX2 + FMA one would run
    /// (for comparing the two; results agree to rounding).
    #[must_use]
    pub fn portable(self) -> Self {
        Self { portable: true, ..self }
    }

    /// The method.
    #[must_use]
    pub fn method(&self) -> Method {
        self.method
    }

    /// Deforms `mesh` by the skinning transforms into `out`.
    ///
    /// Step 1 of paper 4.4: each joint's transform is converted once (matrix rows, quaternion
    /// and translation, or dual quaternion), and for the quaternion methods one sign per pair
    /// of joints that share a vertex, aligning the other joint's rotation to the hemisphere
    /// of the heaviest one. Steps 2–6: every vertex is blended. Allocates nothing.
    ///
    /// * `skinning` — #joints transforms `world · inverse_bind`, from [`skinning_transforms`].
    ///
    /// # Panics
    /// If `skinning`, `out` or the deformer were made for a mesh with other joints or pairs.
    pub fn deform(&mut self, mesh: &SkinnedMesh, skinning: &[Affine3A], out: &mut Deformed) {
        assert_eq!(out.vertex_count, mesh.vertex_count(), "output buffers belong to another mesh");
        assert_eq!(skinning.len(), mesh.inverse_bind().len(), "one skinning transform per joint");
        let (p, n) = (&mut out.positions, &mut out.normals);
        match self.method {
            Method::Lb => {
                assert_eq!(self.lb.len(), skinning.len(), "deformer made for another joint count");
                for (d, m) in self.lb.iter_mut().zip(skinning) {
                    *d = lb::params(m);
                }
                kernel::deform::<{ lb::W }, lb::Lb>(mesh, &Frame { params: &self.lb, signs: &[], portable: self.portable }, p, n);
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
                let frame = Frame { params: &self.quat, signs: &self.signs, portable: self.portable };
                if self.method == Method::Qb {
                    kernel::deform::<{ qb::W }, qb::Qb>(mesh, &frame, p, n);
                } else {
                    kernel::deform::<{ dqb::W }, dqb::Dqb>(mesh, &frame, p, n);
                }
            }
        }
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
