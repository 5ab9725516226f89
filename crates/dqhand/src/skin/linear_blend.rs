//! Linear blending (LB, "linear blend skinning"): `v' = Σ wᵢ Mᵢ v`.
//!
//! Cheapest of the three, and the reference for the paper's artifacts: blended matrices are
//! not rotations, so bent joints collapse and twisted ones pinch (the candy wrapper).

use glam::Affine3A;

use super::kernel::{cross, dot, inv_len, Blend, Chunk, AVX512};

/// Blend parameters: the rows of the 3×4 matrix `[R | t]`, padded to two blocks of eight.
pub(crate) const W: usize = 16;

/// The 3×4 rows of a skinning matrix.
pub(crate) fn params(m: &Affine3A) -> [f32; W] {
    let (c, t) = (m.matrix3, m.translation);
    [c.x_axis.x, c.y_axis.x, c.z_axis.x, t.x, c.x_axis.y, c.y_axis.y, c.z_axis.y, t.y, c.x_axis.z, c.y_axis.z, c.z_axis.z, t.z, 0.0, 0.0, 0.0, 0.0]
}

pub(crate) struct Lb;

impl Blend<W> for Lb {
    const SIGNED: usize = 0;
    const USED: usize = 12;

    /// Positions by the blended matrix; normals by its cofactor matrix (the inverse transpose
    /// up to the determinant), whose rows are cross products of the other two rows. On the
    /// AVX-512 kernel the normals are a second pass over the block, normalised all lanes at
    /// once by [`inv_len`]'s estimate instead of a square root and a division: on the Intel
    /// Xeon VM of docs/performance.md, LB's normals cost 9 µs a frame instead of 15.
    #[inline(always)]
    fn finish<const L: usize, const NORMALS: bool, const ISA: u8>(b: &[[f32; L]; W], rest: &Chunk<L>, out: &mut Chunk<L>) {
        let split = ISA == AVX512;
        for l in 0..L {
            let r = [[b[0][l], b[1][l], b[2][l]], [b[4][l], b[5][l], b[6][l]], [b[8][l], b[9][l], b[10][l]]];
            let t = [b[3][l], b[7][l], b[11][l]];
            let p = [rest.p[0][l], rest.p[1][l], rest.p[2][l]];
            for i in 0..3 {
                out.p[i][l] = dot::<ISA, 4>([r[i][0], r[i][1], r[i][2], t[i]], [p[0], p[1], p[2], 1.0]);
            }
            if !NORMALS || split {
                continue;
            }
            let (m, sq, det) = normal::<ISA>(r, [rest.n[0][l], rest.n[1][l], rest.n[2][l]]);
            // A mirroring blend (negative determinant) would turn the normal inside out.
            let s = inv_len::<1, ISA>([sq])[0].copysign(det);
            for (n, m) in out.n.iter_mut().zip(m) {
                n[l] = m * s;
            }
        }
        if !NORMALS || !split {
            return;
        }
        let (mut sq, mut det) = ([0.0; L], [0.0; L]);
        for l in 0..L {
            let r = [[b[0][l], b[1][l], b[2][l]], [b[4][l], b[5][l], b[6][l]], [b[8][l], b[9][l], b[10][l]]];
            let m;
            (m, sq[l], det[l]) = normal::<ISA>(r, [rest.n[0][l], rest.n[1][l], rest.n[2][l]]);
            for (n, m) in out.n.iter_mut().zip(m) {
                n[l] = m;
            }
        }
        let s = inv_len::<L, ISA>(sq);
        for l in 0..L {
            let s = s[l].copysign(det[l]);
            for i in 0..3 {
                out.n[i][l] *= s;
            }
        }
    }
}

/// The normal `n` transformed by the cofactor matrix of `r`, unnormalised, its squared length
/// and the determinant of `r`.
#[inline(always)]
fn normal<const ISA: u8>(r: [[f32; 3]; 3], n: [f32; 3]) -> ([f32; 3], f32, f32) {
    let cof = [cross::<ISA>(r[1], r[2]), cross::<ISA>(r[2], r[0]), cross::<ISA>(r[0], r[1])];
    let m = cof.map(|c| dot::<ISA, 3>(c, n));
    (m, dot::<ISA, 3>(m, m), dot::<ISA, 3>(r[0], cof[0]))
}
