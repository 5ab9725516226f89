//! The shared vertex loop of the three deformers.
//!
//! Each deformer turns a bone transform into `W` floats once per frame. Per chunk of
//! [`LANES`] vertices the loop blends those floats per vertex (`Σ wᵢ pᵢ`, contiguous loads,
//! one fused vector operation per influence), transposes the chunk to one array per
//! component, and lets the deformer finish all lanes at once (normalise, transform position
//! and normal) — plain lane loops that the compiler vectorises. On x86-64 the same code is
//! compiled a second time with AVX2 and FMA enabled and chosen at run time.

use super::skinned_mesh::{SkinnedMesh, LANES};

/// One lane-wise array per component.
pub(crate) type Lanes = [f32; LANES];

/// Rest or deformed geometry of one chunk: positions then normals, x/y/z lanes each.
pub(crate) struct Chunk {
    pub p: [Lanes; 3],
    pub n: [Lanes; 3],
}

/// What differs between LB, QB and DQB.
pub(crate) trait Blend<const W: usize> {
    /// How many leading parameters are sign-aligned to the heaviest influence before
    /// blending: the quaternion parts, since `q` and `−q` are the same rotation but blend
    /// differently. QB aligns its rotation (4) but not its translation, which is blended as
    /// is; DQB aligns the whole dual quaternion (8), whose dual part changes sign with the
    /// real part; LB aligns nothing (0).
    const SIGNED: usize;
    /// Finishes a chunk from the blended parameters `b[component][lane]`.
    fn finish(b: &[Lanes; W], rest: &Chunk, out: &mut Chunk);
}

/// Per-frame inputs of the vertex loop.
pub(crate) struct Frame<'a, const W: usize> {
    /// Blend parameters per joint, #joints.
    pub params: &'a [[f32; W]],
    /// ±1 per sign index of `SkinnedMesh::slot_pairs` (unused when `SIGNED` is 0).
    pub signs: &'a [f32],
    /// Use the portable kernel even where the AVX2 one would run.
    pub portable: bool,
}

/// Deforms every vertex of `mesh`; writes `positions` and `normals` (each padded length).
pub(crate) fn deform<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    #[cfg(target_arch = "x86_64")]
    if !frame.portable && simd_available() {
        // SAFETY: the CPU supports the features the function is compiled for.
        unsafe { deform_avx2::<W, B>(mesh, frame, positions, normals) };
        return;
    }
    deform_any::<W, B, false>(mesh, frame, positions, normals);
}

/// Whether the AVX2 + FMA kernel runs on this CPU.
#[must_use]
pub fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn deform_avx2<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    deform_any::<W, B, true>(mesh, frame, positions, normals);
}

#[inline(always)]
fn deform_any<const W: usize, B: Blend<W>, const AVX: bool>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    match mesh.k {
        4 => chunks::<W, 4, B, AVX>(mesh, frame, positions, normals),
        _ => chunks::<W, 8, B, AVX>(mesh, frame, positions, normals),
    }
}

#[inline(always)]
fn chunks<const W: usize, const K: usize, B: Blend<W>, const AVX: bool>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let padded = mesh.pos[0].len();
    assert!(positions.len() == padded && normals.len() == padded, "output buffers: padded vertex count");
    assert_eq!(mesh.k, K);
    // Every packed joint index is below the mesh's joint count and every sign index below
    // its pair count + 1 (both by construction), so these two checks make every parameter
    // and sign lookup in bounds.
    let joints = frame.params.len();
    assert_eq!(joints, mesh.inverse_bind().len(), "one parameter row per joint");
    assert!(B::SIGNED == 0 || frame.signs.len() == mesh.pairs.len() + 1, "one sign per joint pair");
    let lanes = |a: &[f32], base: usize| -> Lanes { a[base..base + LANES].try_into().unwrap() };
    let mut rest = Chunk { p: [[0.0; LANES]; 3], n: [[0.0; LANES]; 3] };
    let mut out = Chunk { p: [[0.0; LANES]; 3], n: [[0.0; LANES]; 3] };
    let mut b = [[0.0f32; LANES]; W];
    let (all_js, all_ws) = (mesh.joints.as_chunks::<K>().0, mesh.weights.as_chunks::<K>().0);
    let all_ps = mesh.slot_pairs.as_chunks::<K>().0;
    for (base, &kc) in (0..padded).step_by(LANES).zip(&mesh.chunk_influences) {
        let js: &[[u16; K]; LANES] = all_js[base..base + LANES].try_into().unwrap();
        let ws: &[[f32; K]; LANES] = all_ws[base..base + LANES].try_into().unwrap();
        let ps: &[[u32; K]; LANES] = all_ps[base..base + LANES].try_into().unwrap();
        blend::<W, K, B, AVX>(frame, usize::from(kc), Slots { js, ws, ps }, &mut b);
        for c in 0..3 {
            rest.p[c] = lanes(&mesh.pos[c], base);
            rest.n[c] = lanes(&mesh.nrm[c], base);
        }
        B::finish(&b, &rest, &mut out);
        for l in 0..LANES {
            positions[base + l] = [out.p[0][l], out.p[1][l], out.p[2][l]];
            normals[base + l] = [out.n[0][l], out.n[1][l], out.n[2][l]];
        }
    }
}

/// The influence slots of one chunk: joints, weights and sign indices per vertex.
#[derive(Clone, Copy)]
pub(crate) struct Slots<'a, const K: usize> {
    js: &'a [[u16; K]; LANES],
    ws: &'a [[f32; K]; LANES],
    ps: &'a [[u32; K]; LANES],
}

/// Blends the parameters of one chunk: `b[c][l] = Σₖ wₗₖ sₗₖ params[jₗₖ][c]` over the
/// first `kc` influence slots (the chunk's largest influence count), the sign `sₗₖ` applied
/// to the first `B::SIGNED` components only (1 for the rest), a constant of each method.
///
/// Per vertex the influences are summed as whole contiguous parameter rows, then the chunk
/// is transposed to one array per component.
#[inline(always)]
fn blend<const W: usize, const K: usize, B: Blend<W>, const AVX: bool>(frame: &Frame<'_, W>, kc: usize, slots: Slots<'_, K>, b: &mut [Lanes; W]) {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is true only inside `deform_avx2`, entered after feature detection;
        // joint indices are in bounds (see `chunks`).
        unsafe { avx2::blend::<W, K, B>(frame, kc, slots, b) };
        return;
    }
    let Slots { js, ws, ps } = slots;
    let signed = B::SIGNED;
    let mut acc = [[0.0f32; W]; LANES];
    for (l, acc) in acc.iter_mut().enumerate() {
        for k in 0..kc.min(K) {
            let j = usize::from(js[l][k]);
            let w = ws[l][k];
            let sw = if signed > 0 { w * frame.signs[ps[l][k] as usize] } else { w };
            let p = &frame.params[j];
            for c in 0..W {
                acc[c] += if c < signed { sw } else { w } * p[c];
            }
        }
    }
    for (c, bc) in b.iter_mut().enumerate() {
        for l in 0..LANES {
            bc[l] = acc[l][c];
        }
    }
}

/// Rotates `v` by the quaternion `q = (x, y, z, w)` of squared norm `1 / inv_sq`, lane-wise:
/// `v + 2 d × (d × v + w v) / ‖q‖²` — the rotation part of paper eq. (5) and all of eq. (6)
/// for the normalised `q / ‖q‖`, without a square root.
#[inline(always)]
pub(crate) fn rotate(q: [f32; 4], inv_sq: f32, v: [f32; 3]) -> [f32; 3] {
    let [x, y, z, w] = q;
    let c1 = [y * v[2] - z * v[1] + w * v[0], z * v[0] - x * v[2] + w * v[1], x * v[1] - y * v[0] + w * v[2]];
    let k = 2.0 * inv_sq;
    [
        v[0] + k * (y * c1[2] - z * c1[1]),
        v[1] + k * (z * c1[0] - x * c1[2]),
        v[2] + k * (x * c1[1] - y * c1[0]),
    ]
}

/// `1 / x` with a floor that keeps a degenerate (all-cancelling) blend finite.
#[inline(always)]
pub(crate) fn recip(sq: f32) -> f32 {
    1.0 / sq.max(1e-30)
}

/// `1 / sqrt(x)` with a floor that keeps degenerate inputs finite.
#[inline(always)]
pub(crate) fn inv_len(sq: f32) -> f32 {
    1.0 / sq.max(1e-30).sqrt()
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! The blend step with AVX2 and FMA: one fused multiply-add per influence and block of
    //! eight parameters, then an in-register 8×8 transpose.

    use core::arch::x86_64::*;

    use super::{Blend, Frame, Lanes, Slots, LANES};

    /// As the portable `blend`, for `W` = 8 or 16.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn blend<const W: usize, const K: usize, B: Blend<W>>(
        frame: &Frame<'_, W>,
        kc: usize,
        slots: Slots<'_, K>,
        b: &mut [Lanes; W],
    ) {
        const { assert!(W == 8 || W == 16) };
        let Slots { js, ws, ps } = slots;
        let signed = B::SIGNED;
        let mut rows = [[_mm256_setzero_ps(); LANES]; 2];
        // Per block of eight parameters, which take the signed weight: all, none, or the
        // first few (QB's rotation), picked by a lane mask.
        let first = |blk: usize| _mm256_set1_epi32((signed as i32 - 8 * blk as i32).clamp(0, 8));
        let mask = |blk: usize| _mm256_castsi256_ps(_mm256_cmpgt_epi32(first(blk), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
        let masks = [mask(0), mask(1)];
        // Influence-major, lanes unrolled: the accumulators stay in registers.
        for k in 0..kc.min(K) {
            for l in 0..LANES {
                let j = usize::from(js[l][k]);
                let w = _mm256_set1_ps(ws[l][k]);
                let sw = if signed > 0 { _mm256_mul_ps(w, _mm256_set1_ps(*frame.signs.get_unchecked(ps[l][k] as usize))) } else { w };
                let p = frame.params.get_unchecked(j).as_ptr();
                for (blk, r) in rows.iter_mut().enumerate().take(W / 8) {
                    let wv = if signed >= 8 * (blk + 1) {
                        sw
                    } else if signed <= 8 * blk {
                        w
                    } else {
                        _mm256_blendv_ps(w, sw, masks[blk])
                    };
                    r[l] = _mm256_fmadd_ps(wv, _mm256_loadu_ps(p.add(8 * blk)), r[l]);
                }
            }
        }
        for (blk, r) in rows.iter().enumerate().take(W / 8) {
            let t = transpose(r);
            for (c, v) in t.iter().enumerate() {
                _mm256_storeu_ps(b[8 * blk + c].as_mut_ptr(), *v);
            }
        }
    }

    /// 8×8 transpose: row `l` of the input (a vertex) becomes lane `l` of every output.
    #[inline(always)]
    unsafe fn transpose(r: &[__m256; 8]) -> [__m256; 8] {
        let t0 = _mm256_unpacklo_ps(r[0], r[1]);
        let t1 = _mm256_unpackhi_ps(r[0], r[1]);
        let t2 = _mm256_unpacklo_ps(r[2], r[3]);
        let t3 = _mm256_unpackhi_ps(r[2], r[3]);
        let t4 = _mm256_unpacklo_ps(r[4], r[5]);
        let t5 = _mm256_unpackhi_ps(r[4], r[5]);
        let t6 = _mm256_unpacklo_ps(r[6], r[7]);
        let t7 = _mm256_unpackhi_ps(r[6], r[7]);
        let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
        let s1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
        let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
        let s3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
        let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
        let s5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
        let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
        let s7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
        [
            _mm256_permute2f128_ps::<0x20>(s0, s4),
            _mm256_permute2f128_ps::<0x20>(s1, s5),
            _mm256_permute2f128_ps::<0x20>(s2, s6),
            _mm256_permute2f128_ps::<0x20>(s3, s7),
            _mm256_permute2f128_ps::<0x31>(s0, s4),
            _mm256_permute2f128_ps::<0x31>(s1, s5),
            _mm256_permute2f128_ps::<0x31>(s2, s6),
            _mm256_permute2f128_ps::<0x31>(s3, s7),
        ]
    }
}
