//! Skinning with optimized centres of rotation (CoR; Le and Hodgins 2016): the
//! rotation blended as quaternions, the translation by LB of each vertex's centre.
//!
//! `q = normalize(Σ wᵢ sᵢ qᵢ)`, `v' = q (v − p*) q* + Σ wᵢ Mᵢ p*` for the vertex's centre of
//! rotation `p*` (module `centres_of_rotation`), normals `n' = q n q*`. Like QB the blended
//! rotation is a true rotation; unlike QB it turns about `p*`, a point of the rest mesh
//! weighted like the vertex (near the joints it blends), not about the model origin, and LB
//! moves only that one point. At a bent joint this bulges less than DQB, which blends the
//! translations through the dual part (`dqhand metrics`: 1.15× the rest distance at 90° PIP
//! against 1.23); where LB of the centre itself collapses (a centre off a twist's axis) CoR
//! shrinks as well (docs/realism.md).

use glam::Affine3A;

use super::kernel::{dot, recip, rotate, Blend, Chunk};
use super::{linear_blend as lb, quaternion_blend as qb};

/// Blend parameters: the rotation `(x, y, z, w)`, then the rows of the 3×4 matrix `[R | t]`.
pub(crate) const W: usize = 16;

/// The rotation quaternion of a skinning matrix's rigid part (QB's), and the matrix's rows
/// (LB's).
pub(crate) fn params(m: &Affine3A) -> [f32; W] {
    let (q, rows) = (qb::params(m), lb::params(m));
    core::array::from_fn(|i| if i < 4 { q[i] } else { rows[i - 4] })
}

pub(crate) struct Cor;

impl Blend<W> for Cor {
    const SIGNED: usize = 4;
    const USED: usize = W;
    const CENTRED: bool = true;

    #[inline(always)]
    fn finish<const L: usize, const NORMALS: bool, const ISA: u8>(b: &[[f32; L]; W], rest: &Chunk<L>, out: &mut Chunk<L>) {
        for l in 0..L {
            let q = [b[0][l], b[1][l], b[2][l], b[3][l]];
            let inv_sq = recip(dot::<ISA, 4>(q, q));
            let c = [rest.c[0][l], rest.c[1][l], rest.c[2][l]];
            let turned = rotate::<ISA>(q, inv_sq, [0, 1, 2].map(|i| rest.p[i][l] - c[i]));
            for i in 0..3 {
                let row = [b[4 + 4 * i][l], b[5 + 4 * i][l], b[6 + 4 * i][l], b[7 + 4 * i][l]];
                out.p[i][l] = turned[i] + dot::<ISA, 4>(row, [c[0], c[1], c[2], 1.0]);
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
