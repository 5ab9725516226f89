//! The shared vertex loop of the four deformers.
//!
//! Each deformer turns a bone transform into `W` floats once per frame. Per chunk of
//! vertices the loop blends those floats per vertex (`Σ wᵢ pᵢ`, contiguous loads, one fused
//! vector operation per influence), transposes the chunk to one array per component, and
//! lets the deformer finish all lanes at once (normalise, transform position and, unless only
//! positions are asked for, normal) — plain lane loops that the compiler vectorises.
//!
//! The same code is compiled for three instruction sets and one is chosen at run time
//! ([`Kernel`]): portable; AVX2 + FMA, chunks of 8 vertices; AVX-512, blocks of 16 vertices
//! (two of the mesh's 8-vertex chunks) blended one vertex per lane from the start, with no
//! transpose, the bones' parameters found by the deformer's [`Strategy`] (module `avx512`),
//! and finished 16 lanes per register. In WebAssembly the
//! fourth, simd128, is compiled in or not (a module cannot detect features at run time: the
//! page loads the build its engine validates), and blends in 128-bit blocks (module
//! `simd128`).

#[cfg(target_arch = "x86_64")]
use super::skinned_mesh::BLOCK;
use super::skinned_mesh::{SkinnedMesh, LANES};
use super::strategy::Strategy;

/// Which compiled vertex loop runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// Plain Rust, any CPU.
    Portable,
    /// x86-64 with AVX2 and FMA.
    Avx2,
    /// x86-64 with AVX-512 (F, VL, DQ) besides AVX2 and FMA.
    Avx512,
    /// WebAssembly with 128-bit SIMD, in a build compiled for it (`make wasm`'s SIMD build).
    Simd128,
}

impl Kernel {
    /// Every kernel, slowest first (of those one CPU can run).
    pub const ALL: [Kernel; 4] = [Kernel::Portable, Kernel::Simd128, Kernel::Avx2, Kernel::Avx512];

    /// The fastest kernel this CPU runs.
    #[must_use]
    pub fn best() -> Self {
        Self::ALL.into_iter().rev().find(|k| k.available()).unwrap_or(Kernel::Portable)
    }

    /// Whether this CPU runs the kernel.
    #[must_use]
    pub fn available(self) -> bool {
        match self {
            Kernel::Portable => true,
            Kernel::Simd128 => cfg!(all(target_arch = "wasm32", target_feature = "simd128")),
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma"),
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                use std::arch::is_x86_feature_detected as has;
                Kernel::Avx2.available() && has!("avx512f") && has!("avx512vl") && has!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2 | Kernel::Avx512 => false,
        }
    }

    /// This kernel if this CPU runs it, else the fastest one it does.
    #[must_use]
    pub fn or_best(self) -> Self {
        if self.available() { self } else { Self::best() }
    }

    /// `portable`, `avx2`, `avx512` or `simd128`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Portable => "portable",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
            Kernel::Simd128 => "simd128",
        }
    }

    /// The kernel of [`Self::name`] `name`, if there is one.
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// The instruction set a loop is compiled for (a const parameter: one copy per set).
const PORTABLE: u8 = 0;
#[cfg(target_arch = "x86_64")]
const AVX2: u8 = 1;
/// The AVX-512 set (named off x86-64 too, where no loop is compiled for it, so that the
/// finishes can test for it).
pub(crate) const AVX512: u8 = 2;
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
const SIMD128: u8 = 3;

/// Stack data the vector loops load and store whole registers of, aligned to a cache line:
/// an unaligned 64-byte access straddles two lines, and where the stack happened to fall
/// that cost a fifth of the frame (DQB positions only, 7.2 or 9.4 µs by the caller's depth).
#[repr(C, align(64))]
pub(crate) struct Aligned<T>(pub T);

/// Rest or deformed geometry of one chunk of `L` vertices: positions, normals and (rest, for
/// the CoR method only) centres of rotation, x/y/z lanes each.
#[repr(C, align(64))]
pub(crate) struct Chunk<const L: usize> {
    pub p: [[f32; L]; 3],
    pub n: [[f32; L]; 3],
    pub c: [[f32; L]; 3],
}

impl<const L: usize> Chunk<L> {
    fn new() -> Self {
        Self { p: [[0.0; L]; 3], n: [[0.0; L]; 3], c: [[0.0; L]; 3] }
    }
}

/// What differs between LB, QB, DQB and CoR.
pub(crate) trait Blend<const W: usize> {
    /// How many leading parameters are sign-aligned to the heaviest influence before
    /// blending: the quaternion parts, since `q` and `−q` are the same rotation but blend
    /// differently. QB and CoR align their rotation (4) but not their translation or matrix
    /// rows, which are blended as they are; DQB aligns the whole dual quaternion (8), whose
    /// dual part changes sign with the real part; LB aligns nothing (0).
    const SIGNED: usize;
    /// How many leading parameters `finish` reads (the rest is padding the AVX-512 blend
    /// skips): LB 12, QB 7, DQB 8, CoR 16.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    const USED: usize;
    /// Whether `finish` reads the vertices' centres of rotation (`Chunk::c`, from
    /// [`Frame::centres`]).
    const CENTRED: bool = false;
    /// Finishes a chunk of `L` vertices from the blended parameters `b[component][lane]`:
    /// positions, and normals when `NORMALS` (else `out.n` is left alone); products summed
    /// by [`mad`] for instruction set `ISA`.
    fn finish<const L: usize, const NORMALS: bool, const ISA: u8>(b: &[[f32; L]; W], rest: &Chunk<L>, out: &mut Chunk<L>);
}

/// Per-frame inputs of the vertex loop.
pub(crate) struct Frame<'a, const W: usize> {
    /// Blend parameters per joint, #joints.
    pub params: &'a [[f32; W]],
    /// ±1 per sign index of `SkinnedMesh::slot_pairs` (unused when `SIGNED` is 0).
    pub signs: &'a [f32],
    /// The mesh's centres of rotation where the method reads them (`Blend::CENTRED`), else
    /// empty.
    pub centres: &'a [Vec<f32>],
    /// `params` and `signs` as the AVX-512 loop looks them up, updated for this frame.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub table: &'a FrameTable<W>,
    /// The loop to run (one this CPU does not run falls back to the best it does).
    pub kernel: Kernel,
    /// How the AVX-512 loop looks parameters up (permute falls back to gather where `table`
    /// is empty).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub strategy: Strategy,
}

/// The AVX-512 loop's lookup table of a frame's parameters and pair signs (module `avx512`),
/// kept by the deformer and updated once per frame that runs that loop, not once per piece
/// of a split frame. Empty unless the CPU has AVX-512 and the strategy is
/// [`Strategy::Permute`] for a skin it holds: that loop then uses another strategy.
#[derive(Clone, Debug, Default)]
pub(crate) struct FrameTable<const W: usize> {
    #[cfg(target_arch = "x86_64")]
    table: Option<Box<avx512::Table<W>>>,
}

impl<const W: usize> FrameTable<W> {
    /// A table for a skin of `joints` joints looked up by `strategy` (empty if it would not
    /// be used: none for the parameters a method does not use).
    pub(crate) fn new(joints: usize, strategy: Strategy) -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            Self { table: (joints > 0 && strategy == Strategy::Permute && strategy.serves(joints) && Kernel::Avx512.available()).then(Box::default) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (joints, strategy);
            Self {}
        }
    }

    /// Takes this frame's `params` and the `signs` of `pairs` (as in [`Frame`]; none for
    /// LB). Allocates nothing.
    pub(crate) fn update(&mut self, params: &[[f32; W]], pairs: &[(u16, u16)], signs: &[f32]) {
        #[cfg(target_arch = "x86_64")]
        if let Some(table) = &mut self.table {
            table.update(params, pairs, signs);
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (params, pairs, signs);
    }
}

/// Deforms the vertices of `mesh`'s chunks from `first` on (of [`LANES`] vertices), as many
/// as `positions` holds: writes `positions`, and `normals` unless it is empty (positions
/// only). Both hold whole chunks.
pub(crate) fn deform<const W: usize, B: Blend<W>>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    first: usize,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    match frame.kernel.or_best() {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports the features each function is compiled for.
        Kernel::Avx512 => unsafe { deform_avx512::<W, B>(mesh, frame, first, positions, normals) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Kernel::Avx2 => unsafe { deform_avx2::<W, B>(mesh, frame, first, positions, normals) },
        #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
        Kernel::Simd128 => deform_any::<W, B, SIMD128>(mesh, frame, first, positions, normals),
        _ => deform_any::<W, B, PORTABLE>(mesh, frame, first, positions, normals),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn deform_avx2<const W: usize, B: Blend<W>>(mesh: &SkinnedMesh, frame: &Frame<'_, W>, first: usize, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
    deform_any::<W, B, AVX2>(mesh, frame, first, positions, normals);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn deform_avx512<const W: usize, B: Blend<W>>(mesh: &SkinnedMesh, frame: &Frame<'_, W>, first: usize, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
    deform_any::<W, B, AVX512>(mesh, frame, first, positions, normals);
}

#[inline(always)]
fn deform_any<const W: usize, B: Blend<W>, const ISA: u8>(mesh: &SkinnedMesh, frame: &Frame<'_, W>, first: usize, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
    match (mesh.k, normals.is_empty()) {
        (4, false) => chunks::<W, 4, B, ISA, true>(mesh, frame, first, positions, normals),
        (4, true) => chunks::<W, 4, B, ISA, false>(mesh, frame, first, positions, normals),
        (_, false) => chunks::<W, 8, B, ISA, true>(mesh, frame, first, positions, normals),
        (_, true) => chunks::<W, 8, B, ISA, false>(mesh, frame, first, positions, normals),
    }
}

#[inline(always)]
fn chunks<const W: usize, const K: usize, B: Blend<W>, const ISA: u8, const NORMALS: bool>(
    mesh: &SkinnedMesh,
    frame: &Frame<'_, W>,
    first: usize,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let count = positions.len() / LANES;
    assert!(positions.len() % LANES == 0 && (!NORMALS || normals.len() == positions.len()), "output buffers: whole chunks");
    assert!((first + count) * LANES <= mesh.pos[0].len(), "chunks of the mesh");
    assert_eq!(mesh.k, K);
    // Every packed joint index is below the mesh's joint count and every sign index below
    // its pair count + 1 (both by construction), so these two checks make every parameter
    // and sign lookup in bounds.
    assert_eq!(frame.params.len(), mesh.inverse_bind().len(), "one parameter row per joint");
    assert!(B::SIGNED == 0 || frame.signs.len() == mesh.pairs.len() + 1, "one sign per joint pair");
    assert!(!B::CENTRED || frame.centres.len() == 3 && frame.centres.iter().all(|c| c.len() == mesh.pos[0].len()), "one centre per vertex");
    let mut c = 0;
    #[cfg(target_arch = "x86_64")]
    if ISA == AVX512 {
        // SAFETY: `ISA` is AVX512 only inside `deform_avx512`, entered after feature detection.
        c = unsafe {
            match (frame.strategy, frame.table.table.as_deref()) {
                (Strategy::Permute, Some(table)) => blocks::<W, K, B, NORMALS>(table, mesh, frame.centres, first, positions, normals),
                (Strategy::Broadcast, _) => blocks::<W, K, B, NORMALS>(&avx512::Runs { params: frame.params, signs: frame.signs }, mesh, frame.centres, first, positions, normals),
                _ => blocks::<W, K, B, NORMALS>(&avx512::Gather { params: frame.params, signs: frame.signs }, mesh, frame.centres, first, positions, normals),
            }
        };
    }
    let mut b = Aligned([[0.0f32; LANES]; W]);
    let (mut rest, mut out) = (Chunk::new(), Chunk::new());
    while c < count {
        let chunk = first + c;
        let kc = usize::from(mesh.chunk_influences[chunk]);
        blend::<W, K, B, ISA>(frame, kc, Slots::of(mesh, chunk * LANES), &mut b.0);
        run::<W, B, LANES, NORMALS, ISA>(mesh, frame.centres, &b.0, chunk * LANES, &mut rest, &mut out, positions, normals, c * LANES);
        c += 1;
    }
}

/// The AVX-512 part of `chunks`: as many whole blocks of [`BLOCK`] vertices as the outputs
/// hold, from chunk `first`; returns the chunks done.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn blocks<const W: usize, const K: usize, B: Blend<W>, const NORMALS: bool>(
    blender: &impl avx512::Blender<W>,
    mesh: &SkinnedMesh,
    centres: &[Vec<f32>],
    first: usize,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) -> usize {
    // Blocks of the slot-major arrays start at even chunks (the threads' spans are even).
    assert!(first % 2 == 0, "an AVX-512 run starts at a block");
    let count = positions.len() / LANES;
    let mut b = Aligned([[0.0f32; BLOCK]; W]);
    let (mut rest, mut out) = (Chunk::new(), Chunk::new());
    let mut c = 0;
    while c + 2 <= count {
        let chunk = first + c;
        let kc = mesh.chunk_influences[chunk].max(mesh.chunk_influences[chunk + 1]);
        // SAFETY: joint indices are below the parameter rows (asserted in `chunks`).
        blender.blend::<K, B>(mesh, chunk / 2, usize::from(kc), &mut b.0);
        run::<W, B, BLOCK, NORMALS, AVX512>(mesh, centres, &b.0, chunk * LANES, &mut rest, &mut out, positions, normals, c * LANES);
        c += 2;
    }
    c
}

/// Finishes `L` vertices from mesh vertex `base` (their `centres` of rotation, for a
/// method that reads them) and writes them at `at` of the outputs.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn run<const W: usize, B: Blend<W>, const L: usize, const NORMALS: bool, const ISA: u8>(
    mesh: &SkinnedMesh,
    centres: &[Vec<f32>],
    b: &[[f32; L]; W],
    base: usize,
    rest: &mut Chunk<L>,
    out: &mut Chunk<L>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
    at: usize,
) {
    let lanes = |a: &[f32]| -> [f32; L] { a[base..base + L].try_into().unwrap() };
    for c in 0..3 {
        rest.p[c] = lanes(&mesh.pos[c]);
        if NORMALS {
            rest.n[c] = lanes(&mesh.nrm[c]);
        }
        if B::CENTRED {
            rest.c[c] = lanes(&centres[c]);
        }
    }
    B::finish::<L, NORMALS, ISA>(b, rest, out);
    #[cfg(target_arch = "x86_64")]
    if ISA == AVX512 && L == 2 * LANES {
        // SAFETY: `ISA` is AVX512 only inside `deform_avx512`; each output holds `at + L`
        // vertices (asserted in `chunks`), 3 floats each.
        unsafe {
            avx512::store_interleaved(&out.p, positions[at..at + L].as_mut_ptr().cast());
            if NORMALS {
                avx512::store_interleaved(&out.n, normals[at..at + L].as_mut_ptr().cast());
            }
        }
        return;
    }
    for (l, p) in positions[at..at + L].iter_mut().enumerate() {
        *p = [out.p[0][l], out.p[1][l], out.p[2][l]];
    }
    if NORMALS {
        for (l, n) in normals[at..at + L].iter_mut().enumerate() {
            *n = [out.n[0][l], out.n[1][l], out.n[2][l]];
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

impl<'a, const K: usize> Slots<'a, K> {
    /// The slots of mesh vertices `base..base + LANES`.
    #[inline(always)]
    fn of(mesh: &'a SkinnedMesh, base: usize) -> Self {
        let (js, ws, ps) = (mesh.joints.as_chunks::<K>().0, mesh.weights.as_chunks::<K>().0, mesh.slot_pairs.as_chunks::<K>().0);
        Self { js: js[base..base + LANES].try_into().unwrap(), ws: ws[base..base + LANES].try_into().unwrap(), ps: ps[base..base + LANES].try_into().unwrap() }
    }
}

/// Blends the parameters of one chunk: `b[c][l] = Σₖ wₗₖ sₗₖ params[jₗₖ][c]` over the
/// first `kc` influence slots (the chunk's largest influence count), the sign `sₗₖ` applied
/// to the first `B::SIGNED` components only (1 for the rest), a constant of each method.
///
/// Per vertex the influences are summed as whole contiguous parameter rows, then the chunk
/// is transposed to one array per component.
#[inline(always)]
fn blend<const W: usize, const K: usize, B: Blend<W>, const ISA: u8>(frame: &Frame<'_, W>, kc: usize, slots: Slots<'_, K>, b: &mut [[f32; LANES]; W]) {
    #[cfg(target_arch = "x86_64")]
    if ISA != PORTABLE {
        // SAFETY: `ISA` is AVX2 or AVX512 only inside `deform_avx2` or `deform_avx512`,
        // entered after feature detection; joint indices are in bounds (see `chunks`).
        unsafe { avx2::blend::<W, K, B>(frame, kc, slots, b) };
        return;
    }
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    if ISA == SIMD128 {
        simd128::blend::<W, K, B>(frame, kc, slots, b);
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

/// `a·b + c` in one fused instruction on the x86 SIMD kernels (both have FMA: one rounding,
/// half the instructions of the finish's sums of products); plain on the portable one and on
/// simd128 (which has no fused multiply-add), where a fused multiply-add without the
/// instruction would be a library call per lane.
#[inline(always)]
pub(crate) fn mad<const ISA: u8>(a: f32, b: f32, c: f32) -> f32 {
    if ISA == PORTABLE || cfg!(not(target_arch = "x86_64")) { a * b + c } else { a.mul_add(b, c) }
}

/// `a · b`, by [`mad`].
#[inline(always)]
pub(crate) fn dot<const ISA: u8, const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    (1..N).fold(a[0] * b[0], |s, i| mad::<ISA>(a[i], b[i], s))
}

/// `a × b`, by [`mad`].
#[inline(always)]
pub(crate) fn cross<const ISA: u8>(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [mad::<ISA>(a[1], b[2], -a[2] * b[1]), mad::<ISA>(a[2], b[0], -a[0] * b[2]), mad::<ISA>(a[0], b[1], -a[1] * b[0])]
}

/// Rotates `v` by the quaternion `q = (x, y, z, w)` of squared norm `1 / inv_sq`, lane-wise:
/// `v + 2 d × (d × v + w v) / ‖q‖²` — the rotation part of paper eq. (5) and all of eq. (6)
/// for the normalised `q / ‖q‖`, without a square root.
#[inline(always)]
pub(crate) fn rotate<const ISA: u8>(q: [f32; 4], inv_sq: f32, v: [f32; 3]) -> [f32; 3] {
    let d = [q[0], q[1], q[2]];
    let c = cross::<ISA>(d, v);
    let c1 = [0, 1, 2].map(|i| mad::<ISA>(q[3], v[i], c[i]));
    let c2 = cross::<ISA>(d, c1);
    let k = 2.0 * inv_sq;
    [0, 1, 2].map(|i| mad::<ISA>(k, c2[i], v[i]))
}

/// `1 / x` with a floor that keeps a degenerate (all-cancelling) blend finite.
#[inline(always)]
pub(crate) fn recip(sq: f32) -> f32 {
    1.0 / sq.max(1e-30)
}

/// `1 / sqrt(x)` per lane, with a floor that keeps degenerate inputs finite. On the AVX-512
/// kernel an approximate one refined by one Newton step (relative error near the rounding
/// of the exact one): a 512-bit square root and division take ~20 cycles of the one divider
/// on Intel cores per 16 vertices, which made LB's normals cost more than DQB's.
#[inline(always)]
pub(crate) fn inv_len<const L: usize, const ISA: u8>(sq: [f32; L]) -> [f32; L] {
    #[cfg(target_arch = "x86_64")]
    if ISA == AVX512 && L == BLOCK {
        // SAFETY: `ISA` is AVX512 only inside `deform_avx512`; `sq` holds 16 floats.
        return unsafe { avx512::inv_len(sq) };
    }
    let mut r = sq;
    for x in &mut r {
        *x = 1.0 / x.max(1e-30).sqrt();
    }
    r
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! The blend step with AVX2 and FMA: one fused multiply-add per influence and block of
    //! eight parameters, then an in-register 8×8 transpose.

    use core::arch::x86_64::*;

    use super::{Blend, Frame, Slots, LANES};

    /// As the portable `blend`, for `W` = 8 or 16; inlined into `deform_avx2` (or
    /// `deform_avx512`), whose features it uses.
    #[inline(always)]
    pub(super) unsafe fn blend<const W: usize, const K: usize, B: Blend<W>>(
        frame: &Frame<'_, W>,
        kc: usize,
        slots: Slots<'_, K>,
        b: &mut [[f32; LANES]; W],
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
                // Slot 0 is the heaviest joint itself, whose sign is always +1.
                let sw = if signed > 0 && k > 0 { _mm256_mul_ps(w, _mm256_set1_ps(*frame.signs.get_unchecked(ps[l][k] as usize))) } else { w };
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

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod simd128 {
    //! The blend step with WebAssembly's 128-bit SIMD: per vertex and influence, the parameter
    //! row in blocks of four, one multiply and one add each (simd128 has no fused
    //! multiply-add), then 4×4 transposes to one array per component.

    use core::arch::wasm32::*;

    use super::{Blend, Frame, Slots, LANES};

    /// As the portable `blend`, for `W` a multiple of four up to 16 and methods whose signed
    /// parameters are whole blocks (LB 0, QB 4, DQB 8).
    #[inline(always)]
    pub(super) fn blend<const W: usize, const K: usize, B: Blend<W>>(frame: &Frame<'_, W>, kc: usize, slots: Slots<'_, K>, b: &mut [[f32; LANES]; W]) {
        const { assert!(W % 4 == 0 && W <= 16 && B::SIGNED % 4 == 0) };
        let Slots { js, ws, ps } = slots;
        let signed = B::SIGNED;
        let mut acc = [[f32x4_splat(0.0); 4]; LANES];
        for k in 0..kc.min(K) {
            for (l, acc) in acc.iter_mut().enumerate() {
                let w = ws[l][k];
                // Slot 0 is the heaviest joint itself, whose sign is always +1.
                let sw = if signed > 0 && k > 0 { w * frame.signs[ps[l][k] as usize] } else { w };
                let row = &frame.params[usize::from(js[l][k])];
                for (blk, a) in acc.iter_mut().enumerate().take(W / 4) {
                    let wv = f32x4_splat(if 4 * blk < signed { sw } else { w });
                    // SAFETY: `row` holds `W` floats and `4 * blk + 4 <= W`; wasm loads need no
                    // alignment.
                    let p = unsafe { v128_load(row.as_ptr().add(4 * blk).cast()) };
                    *a = f32x4_add(*a, f32x4_mul(wv, p));
                }
            }
        }
        for blk in 0..W / 4 {
            for g in 0..LANES / 4 {
                let r = [0, 1, 2, 3].map(|i| acc[4 * g + i][blk]);
                let t0 = i32x4_shuffle::<0, 4, 1, 5>(r[0], r[1]);
                let t1 = i32x4_shuffle::<0, 4, 1, 5>(r[2], r[3]);
                let t2 = i32x4_shuffle::<2, 6, 3, 7>(r[0], r[1]);
                let t3 = i32x4_shuffle::<2, 6, 3, 7>(r[2], r[3]);
                let columns = [i32x4_shuffle::<0, 1, 4, 5>(t0, t1), i32x4_shuffle::<2, 3, 6, 7>(t0, t1), i32x4_shuffle::<0, 1, 4, 5>(t2, t3), i32x4_shuffle::<2, 3, 6, 7>(t2, t3)];
                for (c, v) in columns.into_iter().enumerate() {
                    // SAFETY: lanes `4g..4g + 4` of a row of `LANES` floats.
                    unsafe { v128_store(b[4 * blk + c][4 * g..].as_mut_ptr().cast(), v) };
                }
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    //! The blend step with AVX-512, one vertex per lane from the start: per influence slot
    //! the block's 16 weights come in one load, and each parameter component of the 16 lanes'
    //! joints is found by the frame's [`Strategy`](super::Strategy) — a two-source permute
    //! from two registers ([`Table`]), a gather ([`Gather`]), or one broadcast per run of
    //! lanes that share a joint ([`Runs`]) — and blended by fused multiply-adds. The sum is
    //! already one register per component, as the finish wants it: no transpose.

    use core::arch::x86_64::*;

    use super::{Blend, SkinnedMesh, Strategy, BLOCK};

    /// Joints a [`Table`] holds: the 32 lanes of a two-source permute.
    const TABLE_JOINTS: usize = Strategy::PERMUTE_JOINTS;

    /// A way to blend a block: `b[c][lane] = Σₖ wₖ sₖ params[jₖ][c]` as the portable
    /// `blend`, for the 16 vertices of block `block` over its first `kc` slots.
    pub(super) trait Blender<const W: usize> {
        /// Inlined into `deform_avx512`, whose features it uses. Joint indices must be below
        /// the parameter rows and sign indices below the signs.
        unsafe fn blend<const K: usize, B: Blend<W>>(&self, mesh: &SkinnedMesh, block: usize, kc: usize, b: &mut [[f32; BLOCK]; W]);
    }

    /// How the blend finds a component of the 16 lanes' joints' parameters.
    pub(super) trait Lookup<const W: usize> {
        /// Per-slot work on the lanes' joint indices, done once for all components.
        unsafe fn offsets(&self, joints: __m512i) -> __m512i;
        /// Component `c` of the parameters at `offsets`.
        unsafe fn get(&self, offsets: __m512i, c: usize) -> __m512;
        /// The lanes whose influence the frame's pair signs negate beside its heaviest
        /// influence: `heaviest` and `joints` are the two joints' indices, `slot` the offset of
        /// the block's slot in the mesh's block arrays.
        unsafe fn opposite(&self, mesh: &SkinnedMesh, slot: usize, heaviest: __m512i, joints: __m512i) -> __mmask16;
    }

    /// The per-frame parameters component-major in two registers' worth per component,
    /// `rows[c][j]` = parameter `c` of joint `j`: one two-source permute looks a component up
    /// for 16 lanes, from registers or L1. For skins of at most [`TABLE_JOINTS`] joints.
    #[derive(Clone, Debug)]
    #[repr(C, align(64))]
    pub(super) struct Table<const W: usize> {
        rows: [[f32; TABLE_JOINTS]; W],
        /// The frame's pair signs as bits: bit `j` of `opposite[h]` is set when joint `j`
        /// is negated beside heaviest joint `h`. A permute and a shift find 16 lanes' signs,
        /// instead of a four-term dot product on the multiply-add ports.
        opposite: [u32; TABLE_JOINTS],
    }

    impl<const W: usize> Default for Table<W> {
        fn default() -> Self {
            Self { rows: [[0.0; TABLE_JOINTS]; W], opposite: [0; TABLE_JOINTS] }
        }
    }

    impl<const W: usize> Table<W> {
        /// Takes `params` and the `signs` of `pairs` (as in [`super::Frame`]; none for LB).
        ///
        /// # Panics
        /// If there are more than [`TABLE_JOINTS`] joints.
        pub(super) fn update(&mut self, params: &[[f32; W]], pairs: &[(u16, u16)], signs: &[f32]) {
            assert!(params.len() <= TABLE_JOINTS, "a table holds {TABLE_JOINTS} joints");
            for (j, p) in params.iter().enumerate() {
                for (c, row) in self.rows.iter_mut().enumerate() {
                    row[j] = p[c];
                }
            }
            self.opposite = [0; TABLE_JOINTS];
            // Sign 0 is the heaviest joint's own (+1); pair joints are below the joint count.
            for (&(h, j), &sign) in pairs.iter().zip(signs.get(1..).unwrap_or_default()) {
                if sign < 0.0 {
                    self.opposite[usize::from(h)] |= 1 << j;
                }
            }
        }
    }

    impl<const W: usize> Lookup<W> for Table<W> {
        #[inline(always)]
        unsafe fn offsets(&self, joints: __m512i) -> __m512i {
            joints
        }

        #[inline(always)]
        unsafe fn get(&self, joints: __m512i, c: usize) -> __m512 {
            let row = self.rows[c].as_ptr();
            _mm512_permutex2var_ps(_mm512_loadu_ps(row), joints, _mm512_loadu_ps(row.add(16)))
        }

        #[inline(always)]
        unsafe fn opposite(&self, _: &SkinnedMesh, _: usize, heaviest: __m512i, joints: __m512i) -> __mmask16 {
            let rows = self.opposite.as_ptr();
            let bits = _mm512_permutex2var_epi32(_mm512_loadu_si512(rows.cast()), heaviest, _mm512_loadu_si512(rows.add(16).cast()));
            // Joints are below 32 here; saying so spares the shift the compiler's checks
            // for counts of 32 or more (four instructions).
            let j = _mm512_and_si512(joints, _mm512_set1_epi32(TABLE_JOINTS as i32 - 1));
            _mm512_test_epi32_mask(bits, _mm512_sllv_epi32(_mm512_set1_epi32(1), j))
        }
    }

    /// Any number of joints: each component gathered from the parameter rows, each lane's
    /// sign from the frame's pair signs.
    pub(super) struct Gather<'a, const W: usize> {
        pub params: &'a [[f32; W]],
        pub signs: &'a [f32],
    }

    impl<const W: usize> Lookup<W> for Gather<'_, W> {
        #[inline(always)]
        unsafe fn offsets(&self, joints: __m512i) -> __m512i {
            _mm512_mullo_epi32(joints, _mm512_set1_epi32(W as i32))
        }

        #[inline(always)]
        unsafe fn get(&self, offsets: __m512i, c: usize) -> __m512 {
            _mm512_i32gather_ps::<4>(_mm512_add_epi32(offsets, _mm512_set1_epi32(c as i32)), self.params.as_ptr().cast())
        }

        /// One more gather, of the lanes' signs by their sign indices: the pair signs follow
        /// a twist past 180° (module `pair_signs`), which the rotations alone cannot tell.
        #[inline(always)]
        unsafe fn opposite(&self, mesh: &SkinnedMesh, slot: usize, _: __m512i, _: __m512i) -> __mmask16 {
            let pairs = _mm512_loadu_si512(mesh.block_pairs.as_ptr().add(slot).cast());
            let signs = _mm512_i32gather_ps::<4>(pairs, self.signs.as_ptr().cast());
            _mm512_cmp_ps_mask::<_CMP_LT_OQ>(signs, _mm512_setzero_ps())
        }
    }

    /// Each influence signed to its heaviest one's hemisphere by [`Lookup::opposite`].
    impl<const W: usize, L: Lookup<W>> Blender<W> for L {
        #[inline(always)]
        unsafe fn blend<const K: usize, B: Blend<W>>(&self, mesh: &SkinnedMesh, block: usize, kc: usize, b: &mut [[f32; BLOCK]; W]) {
            blend_lookup::<W, K, B>(self, mesh, block, kc, b);
        }
    }

    #[inline(always)]
    unsafe fn blend_lookup<const W: usize, const K: usize, B: Blend<W>>(lookup: &impl Lookup<W>, mesh: &SkinnedMesh, block: usize, kc: usize, b: &mut [[f32; BLOCK]; W]) {
        let slot = |k: usize| (block * K + k) * BLOCK;
        let zero = _mm512_setzero_ps();
        let mut acc = [zero; W];
        let mut heaviest = _mm512_setzero_si512();
        for k in 0..kc.min(K) {
            let joints = _mm512_cvtepu16_epi32(_mm256_loadu_si256(mesh.block_joints.as_ptr().add(slot(k)).cast()));
            let w = _mm512_loadu_ps(mesh.block_weights.as_ptr().add(slot(k)));
            let offsets = lookup.offsets(joints);
            // Plain loops, not closures: a closure would not inherit the function's features,
            // and its intrinsics would become calls.
            let mut v = [zero; W];
            for (c, v) in v.iter_mut().enumerate().take(B::USED) {
                *v = lookup.get(offsets, c);
            }
            let sw = if B::SIGNED == 0 {
                w
            } else if k == 0 {
                // Slot 0 is the heaviest joint itself, whose sign is always +1.
                heaviest = joints;
                w
            } else {
                let opposite = lookup.opposite(mesh, slot(k), heaviest, joints);
                _mm512_mask_sub_ps(w, opposite, zero, w)
            };
            for c in 0..B::USED {
                acc[c] = _mm512_fmadd_ps(if c < B::SIGNED { sw } else { w }, v[c], acc[c]);
            }
        }
        for c in 0..B::USED {
            _mm512_storeu_ps(b[c].as_mut_ptr(), acc[c]);
        }
    }

    /// The frame's parameter rows and pair signs, blended run by run (`SkinnedMesh::block_runs`):
    /// per run, the sign once and one broadcast and masked fused multiply-add per component.
    /// No permute: the broadcasts are loads, and a slot whose lanes share few joints (as
    /// neighbouring vertices do) costs few of them.
    pub(super) struct Runs<'a, const W: usize> {
        pub params: &'a [[f32; W]],
        pub signs: &'a [f32],
    }

    impl<const W: usize> Blender<W> for Runs<'_, W> {
        #[inline(always)]
        unsafe fn blend<const K: usize, B: Blend<W>>(&self, mesh: &SkinnedMesh, block: usize, kc: usize, b: &mut [[f32; BLOCK]; W]) {
            let mut acc = [_mm512_setzero_ps(); W];
            for k in 0..kc.min(K) {
                let s = block * K + k;
                let w = _mm512_loadu_ps(mesh.block_weights.as_ptr().add(s * BLOCK));
                let (start, end) = (*mesh.block_run_start.get_unchecked(s) as usize, *mesh.block_run_start.get_unchecked(s + 1) as usize);
                for run in mesh.block_runs.get_unchecked(start..end) {
                    let p = self.params.get_unchecked(usize::from(run.joint)).as_ptr();
                    // Pair 0 is the heaviest joint's own (sign +1).
                    let sw = if B::SIGNED == 0 || run.pair == 0 { w } else { _mm512_mul_ps(w, _mm512_set1_ps(*self.signs.get_unchecked(run.pair as usize))) };
                    for (c, a) in acc.iter_mut().enumerate().take(B::USED) {
                        *a = _mm512_mask3_fmadd_ps(if c < B::SIGNED { sw } else { w }, _mm512_set1_ps(*p.add(c)), *a, run.lanes);
                    }
                }
            }
            for c in 0..B::USED {
                _mm512_storeu_ps(b[c].as_mut_ptr(), acc[c]);
            }
        }
    }

    /// `1 / sqrt(max(x, 1e-30))` of 16 lanes: `rsqrt14` (relative error 2⁻¹⁴) and one
    /// Newton step `y (1.5 − ½ x y²)`. Inlined into `deform_avx512`, whose features it uses
    /// (no function pointer: called through one, it would be compiled without them and pay
    /// the AVX-to-SSE transition on Intel cores).
    #[inline(always)]
    pub(super) unsafe fn inv_len<const L: usize>(x: [f32; L]) -> [f32; L] {
        debug_assert_eq!(L, 16, "16 lanes");
        let x = _mm512_max_ps(_mm512_loadu_ps(x.as_ptr()), _mm512_set1_ps(1e-30));
        let y = _mm512_rsqrt14_ps(x);
        let half_xy = _mm512_mul_ps(_mm512_mul_ps(x, _mm512_set1_ps(0.5)), y);
        let mut out = [0.0; L];
        _mm512_storeu_ps(out.as_mut_ptr(), _mm512_mul_ps(y, _mm512_fnmadd_ps(half_xy, y, _mm512_set1_ps(1.5))));
        out
    }

    /// The permutes that interleave 16 lanes of x, y and z into 48 floats `x₀ y₀ z₀ x₁ …`:
    /// per output register `k`, first x and y into place (`XY`), then z (`Z`).
    const XY: [[i32; 16]; 3] = interleave(false);
    const Z: [[i32; 16]; 3] = interleave(true);

    const fn interleave(z: bool) -> [[i32; 16]; 3] {
        let mut idx = [[0; 16]; 3];
        let mut k = 0;
        while k < 3 {
            let mut j = 0;
            while j < 16 {
                let (v, c) = (((16 * k + j) / 3) as i32, (16 * k + j) % 3);
                idx[k][j] = match (z, c) {
                    (false, 0) => v,
                    (false, 1) => 16 + v,
                    (false, _) => 0,
                    (true, 2) => 16 + v,
                    (true, _) => j as i32,
                };
                j += 1;
            }
            k += 1;
        }
        idx
    }

    /// Writes 16 vertices' x, y, z lanes as 48 interleaved floats at `dst` (the `[f32; 3]`
    /// per vertex of the outputs): six two-source permutes and three stores instead of 48
    /// single-float stores.
    #[inline(always)]
    pub(super) unsafe fn store_interleaved<const L: usize>(lanes: &[[f32; L]; 3], dst: *mut f32) {
        debug_assert_eq!(L, 16, "16 lanes");
        let [x, y, z] = [0, 1, 2].map(|c| _mm512_loadu_ps(lanes[c].as_ptr()));
        for k in 0..3 {
            let xy = _mm512_permutex2var_ps(x, _mm512_loadu_si512(XY[k].as_ptr().cast()), y);
            _mm512_storeu_ps(dst.add(16 * k), _mm512_permutex2var_ps(xy, _mm512_loadu_si512(Z[k].as_ptr().cast()), z));
        }
    }
}
