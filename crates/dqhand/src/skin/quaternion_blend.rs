//! Quaternion blending (QB): rotations blended as quaternions, translations linearly.
//!
//! `q = normalize(Σ wᵢ sᵢ qᵢ)`, `t = Σ wᵢ tᵢ`, `v' = q v q* + t`. The blended rotation is a
//! true rotation, but about the model origin rather than the joint, which is what produces
//! the paper's Figure 5 artifacts away from the origin.

use glam::Affine3A;

use super::kernel::{dot, recip, rotate, Blend, Chunk};

/// Blend parameters: the rotation `(x, y, z, w)`, then the translation and a zero.
pub(crate) const W: usize = 8;

/// The rotation quaternion and translation of a skinning matrix's rigid part.
pub(crate) fn params(m: &Affine3A) -> [f32; W] {
    let (_, q, t) = m.to_scale_rotation_translation();
    let q = q.normalize();
    [q.x, q.y, q.z, q.w, t.x, t.y, t.z, 0.0]
}

pub(crate) struct Qb;

impl Blend<W> for Qb {
    const SIGNED: usize = 4;
    const USED: usize = 7;

    #[inline(always)]
    fn finish<const L: usize, const NORMALS: bool, const ISA: u8>(b: &[[f32; L]; W], rest: &Chunk<L>, out: &mut Chunk<L>) {
        for l in 0..L {
            let q = [b[0][l], b[1][l], b[2][l], b[3][l]];
            let inv_sq = recip(dot::<ISA, 4>(q, q));
            let p = rotate::<ISA>(q, inv_sq, [rest.p[0][l], rest.p[1][l], rest.p[2][l]]);
            for i in 0..3 {
                out.p[i][l] = p[i] + b[4 + i][l];
            }
            if NORMALS {
                let n = rotate::<ISA>(q, inv_sq, [rest.n[0][l], rest.n[1][l], rest.n[2][l]]);
                for i in 0..3 {
                    out.n[i][l] = n[i];
                }
            }
        }
    }
}
