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
    /// Whether influences are sign-aligned to the heaviest one before blending (quaternion
    /// methods: `q` and `−q` are the same rotation but blend differently).
    const ALIGN: bool;
    /// Finishes a chunk from the blended parameters `b[component][lane]`.
    fn finish(b: &[Lanes; W], rest: &Chunk, out: &mut Chunk);
}

/// Per-frame inputs of the vertex loop.
pub(crate) struct Frame<'a, const W: usize> {
    /// Blend parameters per joint, #joints.
    pub params: &'a [[f32; W]],
    /// `signs[h * joints + j]`: ±1 aligning joint `j` to joint `h` (unused without `ALIGN`).
    pub signs: &'a [f32],
}

/// Deforms every vertex of `mesh`; writes `positions` and `normals` (each padded length).
pub(crate) fn deform<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports the features the function is compiled for.
        unsafe { deform_avx2::<W, B>(mesh, frame, positions, normals) };
        return;
    }
    deform_any::<W, B>(mesh, frame, positions, normals);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn deform_avx2<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    deform_any::<W, B>(mesh, frame, positions, normals);
}

#[inline(always)]
fn deform_any<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    match mesh.k {
        4 => chunks::<W, 4, B>(mesh, frame, positions, normals),
        _ => chunks::<W, 8, B>(mesh, frame, positions, normals),
    }
}

#[inline(always)]
fn chunks<const W: usize, const K: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let padded = mesh.pos[0].len();
    assert!(positions.len() == padded && normals.len() == padded, "output buffers: padded vertex count");
    assert_eq!(mesh.k, K);
    let joints = frame.params.len();
    assert!(!B::ALIGN || frame.signs.len() == joints * joints, "sign table: joints²");
    let lanes = |a: &[f32], base: usize| -> Lanes { a[base..base + LANES].try_into().unwrap() };
    let mut rest = Chunk { p: [[0.0; LANES]; 3], n: [[0.0; LANES]; 3] };
    let mut out = Chunk { p: [[0.0; LANES]; 3], n: [[0.0; LANES]; 3] };
    for base in (0..padded).step_by(LANES) {
        let mut acc = [[0.0f32; W]; LANES];
        for (l, acc) in acc.iter_mut().enumerate() {
            let s = (base + l) * K;
            let js: &[u16; K] = mesh.joints[s..s + K].try_into().unwrap();
            let ws: &[f32; K] = mesh.weights[s..s + K].try_into().unwrap();
            let h = js[0] as usize * joints;
            for k in 0..K {
                let j = js[k] as usize;
                let w = if B::ALIGN { ws[k] * frame.signs[h + j] } else { ws[k] };
                let p = &frame.params[j];
                for c in 0..W {
                    acc[c] += w * p[c];
                }
            }
        }
        let mut b = [[0.0f32; LANES]; W];
        for (c, bc) in b.iter_mut().enumerate() {
            for l in 0..LANES {
                bc[l] = acc[l][c];
            }
        }
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

/// Rotates `v` by the unit quaternion `(x, y, z, w)` lane-wise: `v + 2d × (d × v + w v)`,
/// the rotation part of paper eq. (5) and all of eq. (6).
#[inline(always)]
pub(crate) fn rotate(q: [f32; 4], v: [f32; 3]) -> [f32; 3] {
    let [x, y, z, w] = q;
    let c1 = [y * v[2] - z * v[1] + w * v[0], z * v[0] - x * v[2] + w * v[1], x * v[1] - y * v[0] + w * v[2]];
    [
        v[0] + 2.0 * (y * c1[2] - z * c1[1]),
        v[1] + 2.0 * (z * c1[0] - x * c1[2]),
        v[2] + 2.0 * (x * c1[1] - y * c1[0]),
    ]
}

/// `1 / sqrt(x)` with a floor that keeps degenerate inputs finite.
#[inline(always)]
pub(crate) fn inv_len(sq: f32) -> f32 {
    1.0 / sq.max(1e-30).sqrt()
}
