//! A straightforward structure-of-arrays AVX-512 DQB kernel, written plainly for
//! `dqhand bench` to measure the engine's kernel against (issue 33): per block of 16
//! vertices and influence slot, each of the eight dual quaternion components gathered from
//! the bones' rows, the hemisphere sign from a dot product with the heaviest influence, one
//! fused multiply-add per component; then a square root and a division to normalise, the
//! textbook rotation of position and normal, and the lanes written out vertex by vertex.
//! None of the engine's tuning: every block blends every slot, and there is no lookup
//! table, sign table, approximate reciprocal or interleaving permute.

#[cfg(target_arch = "x86_64")]
use core::arch::x86_64::*;

use dqhand::math::DualQuat;
use dqhand::skin::SkinnedMesh;
use glam::Affine3A;

/// Vertices per block: one per lane of a 512-bit register.
const BLOCK: usize = 16;

/// The mesh in plain structure of arrays and the frame's dual quaternions.
pub struct PlainSoaKernel {
    vertex_count: usize,
    /// Rest positions and normals, x, y, z arrays padded to whole blocks.
    pos: [Vec<f32>; 3],
    nrm: [Vec<f32>; 3],
    /// Per influence slot, each vertex's joint and weight (padding: the heaviest joint,
    /// weight 0), padded to whole blocks.
    joints: Vec<Vec<i32>>,
    weights: Vec<Vec<f32>>,
    /// The frame's dual quaternion per joint.
    bones: Vec<[f32; 8]>,
}

impl PlainSoaKernel {
    /// The kernel for `mesh`, if this CPU has AVX-512.
    pub fn new(mesh: &SkinnedMesh) -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            let n = mesh.vertex_count();
            let padded = n.next_multiple_of(BLOCK);
            let slots = mesh.max_influences();
            let column = |f: &dyn Fn(usize) -> f32| (0..padded).map(|v| if v < n { f(v) } else { 0.0 }).collect::<Vec<f32>>();
            let influences: Vec<Vec<(usize, f32)>> = (0..padded).map(|v| if v < n { mesh.influences(v).collect() } else { vec![(0, 1.0)] }).collect();
            let slot = |s: usize, i: &[(usize, f32)]| i.get(s).copied().unwrap_or((i[0].0, 0.0));
            return Some(Self {
                vertex_count: n,
                pos: [0, 1, 2].map(|c| column(&|v| mesh.position(v)[c])),
                nrm: [0, 1, 2].map(|c| column(&|v| mesh.normal(v)[c])),
                joints: (0..slots).map(|s| influences.iter().map(|i| slot(s, i).0 as i32).collect()).collect(),
                weights: (0..slots).map(|s| influences.iter().map(|i| slot(s, i).1).collect()).collect(),
                bones: vec![[0.0; 8]; mesh.inverse_bind().len()],
            });
        }
        let _ = mesh;
        None
    }

    /// Deforms by the skinning transforms (#joints) into `positions` and `normals` (#V each).
    ///
    /// # Panics
    /// If the transforms or buffers do not match the mesh.
    pub fn deform(&mut self, skinning: &[Affine3A], positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        assert_eq!(skinning.len(), self.bones.len(), "one transform per joint");
        assert!(positions.len() == self.vertex_count && normals.len() == self.vertex_count, "#V outputs");
        for (b, m) in self.bones.iter_mut().zip(skinning) {
            *b = DualQuat::from_affine(m).to_array();
        }
        #[cfg(target_arch = "x86_64")]
        // SAFETY: made only where the CPU has AVX-512 F (`new`).
        unsafe {
            self.deform_avx512(positions, normals);
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn deform_avx512(&self, positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        let rows = self.bones.as_ptr().cast::<f32>();
        let zero = _mm512_setzero_ps();
        for base in (0..self.pos[0].len()).step_by(BLOCK) {
            let mut b = [zero; 8];
            let mut heaviest = [zero; 4];
            for (s, (joints, weights)) in self.joints.iter().zip(&self.weights).enumerate() {
                let offsets = _mm512_mullo_epi32(_mm512_loadu_si512(joints[base..].as_ptr().cast()), _mm512_set1_epi32(8));
                let w = _mm512_loadu_ps(weights[base..].as_ptr());
                let mut q = [zero; 8];
                for (c, q) in q.iter_mut().enumerate() {
                    *q = _mm512_i32gather_ps::<4>(_mm512_add_epi32(offsets, _mm512_set1_epi32(c as i32)), rows);
                }
                if s == 0 {
                    heaviest = [q[0], q[1], q[2], q[3]];
                }
                let mut dot = zero;
                for c in 0..4 {
                    dot = _mm512_fmadd_ps(heaviest[c], q[c], dot);
                }
                let sw = _mm512_mask_sub_ps(w, _mm512_cmp_ps_mask::<_CMP_LT_OQ>(dot, zero), zero, w);
                for c in 0..8 {
                    b[c] = _mm512_fmadd_ps(sw, q[c], b[c]);
                }
            }
            let mut sq = zero;
            for c in 0..4 {
                sq = _mm512_fmadd_ps(b[c], b[c], sq);
            }
            let inv = _mm512_div_ps(_mm512_set1_ps(1.0), _mm512_sqrt_ps(sq));
            for v in &mut b {
                *v = _mm512_mul_ps(*v, inv);
            }
            let (d, a0, de, ae) = ([b[0], b[1], b[2]], b[3], [b[4], b[5], b[6]], b[7]);
            let (mut rest_p, mut rest_n) = ([zero; 3], [zero; 3]);
            for i in 0..3 {
                rest_p[i] = _mm512_loadu_ps(self.pos[i][base..].as_ptr());
                rest_n[i] = _mm512_loadu_ps(self.nrm[i][base..].as_ptr());
            }
            let p = rotate(d, a0, rest_p);
            let n = rotate(d, a0, rest_n);
            // Translation 2 (a₀ d_ε − a_ε d₀ + d₀ × d_ε).
            let c = cross(d, de);
            let two = _mm512_set1_ps(2.0);
            let mut out = [[[0.0f32; BLOCK]; 3]; 2];
            for i in 0..3 {
                let t = _mm512_mul_ps(two, _mm512_add_ps(_mm512_sub_ps(_mm512_mul_ps(a0, de[i]), _mm512_mul_ps(ae, d[i])), c[i]));
                _mm512_storeu_ps(out[0][i].as_mut_ptr(), _mm512_add_ps(p[i], t));
                _mm512_storeu_ps(out[1][i].as_mut_ptr(), n[i]);
            }
            for l in 0..BLOCK.min(self.vertex_count.saturating_sub(base)) {
                positions[base + l] = [out[0][0][l], out[0][1][l], out[0][2][l]];
                normals[base + l] = [out[1][0][l], out[1][1][l], out[1][2][l]];
            }
        }
    }
}

/// `a × b`, lane-wise (plain loops, no closures: those would not inherit the caller's
/// features).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn cross(a: [__m512; 3], b: [__m512; 3]) -> [__m512; 3] {
    let mut c = [_mm512_setzero_ps(); 3];
    for (i, c) in c.iter_mut().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        *c = _mm512_sub_ps(_mm512_mul_ps(a[j], b[k]), _mm512_mul_ps(a[k], b[j]));
    }
    c
}

/// `v` rotated by the unit quaternion `(d, w)`: `v + 2 d × (d × v + w v)`, lane-wise.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn rotate(d: [__m512; 3], w: __m512, v: [__m512; 3]) -> [__m512; 3] {
    let mut c = cross(d, v);
    for i in 0..3 {
        c[i] = _mm512_add_ps(c[i], _mm512_mul_ps(w, v[i]));
    }
    let mut c = cross(d, c);
    for i in 0..3 {
        c[i] = _mm512_add_ps(v[i], _mm512_mul_ps(_mm512_set1_ps(2.0), c[i]));
    }
    c
}
