//! Dual quaternion blending (DQB), the paper's pseudo-muscle layer (section 4.4).
//!
//! Paper eq. (3)/(4): `b̂ = Σ wᵢ q̂ᵢ`, each `q̂ᵢ` first sign-aligned to the heaviest
//! influence (Kavan et al. 2008, "Geometric skinning with approximate dual quaternion
//! blending", ACM TOG 27:105), then normalised by `‖b₀‖` — always, as the paper insists, since
//! only the normalised blend is a rigid transform free of collapse and candy wrapper.
//! Positions by eq. (5), normals by eq. (6). Both are quadratic in `b̂`, so the kernel
//! divides their rotation and translation terms by `‖b₀‖²` once instead of dividing `b̂` by
//! `‖b₀‖`: the same result without a square root.

use glam::Affine3A;

use super::kernel::{cross, dot, mad, recip, rotate, Blend, Chunk};
use crate::math::DualQuat;

/// Blend parameters: real part `(x, y, z, w)`, then dual part.
pub(crate) const W: usize = 8;

/// The unit dual quaternion of a skinning matrix's rigid part.
pub(crate) fn params(m: &Affine3A) -> [f32; W] {
    DualQuat::from_affine(m).to_array()
}

pub(crate) struct Dqb;

impl Blend<W> for Dqb {
    const SIGNED: usize = W;
    const USED: usize = W;

    #[inline(always)]
    fn finish<const L: usize, const NORMALS: bool, const ISA: u8>(b: &[[f32; L]; W], rest: &Chunk<L>, out: &mut Chunk<L>) {
        for l in 0..L {
            let q = [b[0][l], b[1][l], b[2][l], b[3][l]];
            let (d0, a0) = ([q[0], q[1], q[2]], q[3]);
            let (de, ae) = ([b[4][l], b[5][l], b[6][l]], b[7][l]);
            // Eq. (5) is quadratic in b̂, so dividing once by ‖b₀‖² normalises it exactly.
            let inv_sq = recip(dot::<ISA, 4>(q, q));
            let k = 2.0 * inv_sq;
            // Eq. (5): translation 2(a₀ d_ε − a_ε d₀ + d₀ × d_ε).
            let c = cross::<ISA>(d0, de);
            let p = rotate::<ISA>(q, inv_sq, [rest.p[0][l], rest.p[1][l], rest.p[2][l]]);
            for i in 0..3 {
                out.p[i][l] = mad::<ISA>(k, mad::<ISA>(a0, de[i], mad::<ISA>(-ae, d0[i], c[i])), p[i]);
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
