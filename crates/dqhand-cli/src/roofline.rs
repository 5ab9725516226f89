//! The roofline of a skinning frame for `dqhand bench`: the bytes and flops a frame of a
//! method needs, counted from the mesh, against the bytes per second this core reads and
//! writes within its L2 cache and the flops per second of its fused multiply-adds, all
//! measured here by short microbenchmarks. The larger of the two times is what no kernel can
//! beat on one core, so the gap to it is printed, not guessed.

use std::hint::black_box;
use std::time::Instant;

use dqhand::skin::{Method, SkinnedMesh};

/// What a frame needs.
#[derive(Clone, Copy, Debug)]
pub struct Work {
    /// Bytes read: rest positions (and normals; CoR's centres), joints (u16) and weights (f32)
    /// of every slot.
    pub read: f64,
    /// Bytes written: deformed positions (and normals).
    pub written: f64,
    /// Floating-point operations (a fused multiply-add counts two): the blend of each
    /// non-zero influence and the method's finish.
    pub flops: f64,
}

impl Work {
    /// The work of one frame of `method` on `mesh`.
    pub fn of(mesh: &SkinnedMesh, method: Method, normals: bool) -> Self {
        let n = mesh.vertex_count() as f64;
        let components = if normals { 6.0 } else { 3.0 };
        let inputs = components + if method == Method::Cor { 3.0 } else { 0.0 };
        let (read, written) = (n * (inputs * 4.0 + mesh.influences_per_vertex() as f64 * 6.0), n * components * 4.0);
        let influences: f64 = mesh.influence_histogram().iter().enumerate().map(|(k, &count)| (k * count) as f64).sum();
        // Per influence: a multiply-add per parameter read (LB 12, QB 7, DQB 8, CoR 16), and
        // the quaternion methods' sign. Per vertex, the finish as the kernel computes it:
        // LB 3 four-term dots (21), its normal's cofactor rows (27), their products with the
        // normal (15), its length and the determinant (10), the scale (5); QB the norm (8), a
        // rotation (31) and the translation (3), a rotation per normal; DQB the norm (8), a
        // rotation, eq. (5)'s translation (28), a rotation per normal; CoR the norm (8), the
        // offset from the centre (3), a rotation, the blended matrix's 3 four-term dots at the
        // centre (21) and their sum (3), a rotation per normal.
        let (per_influence, finish, per_normal) = match method {
            Method::Lb => (24.0, 21.0, 57.0),
            Method::Qb => (15.0, 42.0, 31.0),
            Method::Dqb => (17.0, 67.0, 31.0),
            Method::Cor => (33.0, 66.0, 31.0),
        };
        Self { read, written, flops: influences * per_influence + n * (finish + if normals { per_normal } else { 0.0 }) }
    }

    /// The least time of a frame on `machine` (µs): bytes at its L2 bandwidths or flops at
    /// its peak, whichever takes longer.
    pub fn bound_us(&self, machine: &Machine) -> f64 {
        1e6 * (self.read / machine.l2_read_bytes_per_s + self.written / machine.l2_write_bytes_per_s).max(self.flops / machine.peak_flops)
    }
}

/// What this core does at best, measured.
#[derive(Clone, Copy, Debug)]
pub struct Machine {
    /// Bytes per second read from, and written to, a 256 KiB buffer (in L2, not L1).
    pub l2_read_bytes_per_s: f64,
    pub l2_write_bytes_per_s: f64,
    /// Floating-point operations per second of independent fused multiply-adds on the
    /// widest vectors this CPU has (512 or 256 bits).
    pub peak_flops: f64,
    /// That width.
    pub vector_bits: u32,
}

impl Machine {
    /// Measures this core: the best of many short repetitions of each microbenchmark (a few
    /// tens of milliseconds in all).
    pub fn measure() -> Self {
        let (peak_flops, vector_bits) = peak_flops();
        let mut buffer: Vec<f32> = (0..L2_FLOATS).map(|i| i as f32).collect();
        let read = best_of(|| read_all(black_box(&buffer)));
        let write = best_of(|| write_all(black_box(&mut buffer)));
        Self { l2_read_bytes_per_s: read, l2_write_bytes_per_s: write, peak_flops, vector_bits }
    }
}

/// Floats of the buffer the L2 bandwidths are measured on: 256 KiB, past any L1 and within
/// any L2 of an AVX-512 core.
const L2_FLOATS: usize = 64 * 1024;

/// Reads `buffer` with the widest loads there are; returns the bytes read.
fn read_all(buffer: &[f32]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU has AVX-512 F.
        black_box(unsafe { sum_avx512(buffer) });
        return (buffer.len() * 4) as f64;
    }
    black_box(buffer.iter().sum::<f32>());
    (buffer.len() * 4) as f64
}

/// Writes all of `buffer` with the widest stores there are; returns the bytes written.
fn write_all(buffer: &mut [f32]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU has AVX-512 F.
        unsafe { fill_avx512(buffer, black_box(1.0)) };
    } else {
        buffer.fill(black_box(1.0));
    }
    #[cfg(not(target_arch = "x86_64"))]
    buffer.fill(black_box(1.0));
    black_box(&buffer);
    (buffer.len() * 4) as f64
}

/// `a` (a multiple of 16 floats) set to `x` by 512-bit stores.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn fill_avx512(a: &mut [f32], x: f32) {
    use core::arch::x86_64::*;
    for v in a.chunks_exact_mut(16) {
        _mm512_storeu_ps(v.as_mut_ptr(), _mm512_set1_ps(x));
    }
}

/// Sum of `a` (a multiple of 128 floats) in eight 512-bit accumulators: two loads a cycle.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn sum_avx512(a: &[f32]) -> f32 {
    use core::arch::x86_64::*;
    let mut acc = [_mm512_setzero_ps(); 8];
    for block in a.chunks_exact(128) {
        for (k, v) in acc.iter_mut().enumerate() {
            *v = _mm512_add_ps(*v, _mm512_loadu_ps(block[16 * k..].as_ptr()));
        }
    }
    let mut s = acc[0];
    for v in &acc[1..] {
        s = _mm512_add_ps(s, *v);
    }
    _mm512_reduce_add_ps(s)
}

/// Peak flops per second and the vector width they were measured at (0 where neither
/// AVX-512 nor AVX2 with FMA is there: then 1 flop per cycle at 1 GHz, a floor).
fn peak_flops() -> (f64, u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx512f") {
            // SAFETY: the CPU has AVX-512 F.
            return (best_of(|| unsafe { fma_avx512(ITERATIONS) }), 512);
        }
        if has!("avx2") && has!("fma") {
            // SAFETY: the CPU has AVX2 and FMA.
            return (best_of(|| unsafe { fma_avx2(ITERATIONS) }), 256);
        }
    }
    (1e9, 0)
}

/// Iterations of a fused multiply-add chain per repetition.
const ITERATIONS: usize = 20_000;
/// Independent chains: enough to cover the latency of two FMA units (4 cycles × 2).
const CHAINS: usize = 16;

/// The best rate of 200 repetitions of `run`, which returns the work it did (flops, bytes).
fn best_of(mut run: impl FnMut() -> f64) -> f64 {
    (0..200)
        .map(|_| {
            let t = Instant::now();
            let flops = run();
            flops / t.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

/// `$name(iterations)`: [`CHAINS`] independent chains of fused multiply-adds on `$lanes`-float
/// vectors, for the features `$features`; returns the flops done.
macro_rules! fma_chains {
    ($name:ident, $features:literal, $lanes:literal, $set1:ident, $fmadd:ident) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        unsafe fn $name(iterations: usize) -> f64 {
            use core::arch::x86_64::*;
            let mut acc = [$set1(1.0); CHAINS];
            let (a, b) = ($set1(black_box(0.999_999)), $set1(black_box(1e-7)));
            for _ in 0..iterations {
                for v in &mut acc {
                    *v = $fmadd(*v, a, b);
                }
            }
            black_box(acc);
            (iterations * CHAINS * $lanes * 2) as f64
        }
    };
}

fma_chains!(fma_avx512, "avx512f", 16, _mm512_set1_ps, _mm512_fmadd_ps);
fma_chains!(fma_avx2, "avx2,fma", 8, _mm256_set1_ps, _mm256_fmadd_ps);
