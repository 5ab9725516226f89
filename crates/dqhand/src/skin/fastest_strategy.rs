//! The run-time choice of the AVX-512 kernel's lookup [`Strategy`]: each one that serves the
//! skin is timed on the mesh at hand, interleaved, for a few frames, and the fastest kept —
//! once per process for each method and mesh shape, since which one wins depends on the core
//! (permutes on Zen 5, loads on Intel cores) and on how many joints a block's lanes share.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use glam::Affine3A;

use super::kernel::{self, Blend, Frame, FrameTable, Kernel};
use super::skinned_mesh::SkinnedMesh;
use super::strategy::Strategy;
use super::Method;
use super::{centre_of_rotation_blend as cor, dual_quaternion_blend as dqb, linear_blend as lb, quaternion_blend as qb};

/// What the choice depends on: the method and the mesh's vertices, joints, slots and pairs.
type Key = (Method, usize, usize, usize, usize);

/// Rounds of timing: each strategy deforms one frame per round, the order rotating; the
/// first round warms caches and is not counted.
const ROUNDS: usize = 8;

/// The strategy that deformed `mesh` by `method` fastest here (positions and normals, the rest
/// pose), measured by the first call for the method and mesh shape, remembered after.
pub(crate) fn fastest_strategy(method: Method, mesh: &SkinnedMesh) -> Strategy {
    static CHOSEN: OnceLock<Mutex<HashMap<Key, Arc<OnceLock<Strategy>>>>> = OnceLock::new();
    let key = (method, mesh.vertex_count(), mesh.inverse_bind().len(), mesh.k, mesh.pairs.len());
    // The map is locked only to find the key's cell; a second deformer of the same mesh shape
    // waits in the cell for the first's measurement, others of other shapes do not.
    let cell = Arc::clone(CHOSEN.get_or_init(Mutex::default).lock().unwrap_or_else(std::sync::PoisonError::into_inner).entry(key).or_default());
    *cell.get_or_init(|| match method {
        Method::Lb => measure::<{ lb::W }, lb::Lb>(mesh, lb::params),
        Method::Qb => measure::<{ qb::W }, qb::Qb>(mesh, qb::params),
        Method::Dqb => measure::<{ dqb::W }, dqb::Dqb>(mesh, dqb::params),
        Method::Cor => measure::<{ cor::W }, cor::Cor>(mesh, cor::params),
    })
}

/// Times every strategy serving `mesh` on the AVX-512 kernel and returns the one of least
/// time (the least of its rounds: noise only adds).
fn measure<const W: usize, B: Blend<W>>(mesh: &SkinnedMesh, params: fn(&Affine3A) -> [f32; W]) -> Strategy {
    let joints = mesh.inverse_bind().len();
    let rows = vec![params(&Affine3A::IDENTITY); joints];
    let signs = vec![1.0; mesh.pairs.len() + 1];
    let padded = mesh.pos[0].len();
    let (mut positions, mut normals) = (vec![[0.0f32; 3]; padded], vec![[0.0f32; 3]; padded]);
    let candidates: Vec<(Strategy, FrameTable<W>)> = Strategy::ALL
        .into_iter()
        .filter(|s| s.serves(joints))
        .map(|s| {
            let mut table = FrameTable::new(joints, s);
            table.update(&rows, &mesh.pairs, &signs);
            (s, table)
        })
        .collect();
    let mut best = vec![f64::INFINITY; candidates.len()];
    for round in 0..ROUNDS {
        for i in 0..candidates.len() {
            let (strategy, table) = &candidates[(round + i) % candidates.len()];
            let centres = if B::CENTRED { &mesh.centres()[..] } else { &[] };
            let frame = Frame { params: &rows, signs: &signs, centres, table, kernel: Kernel::Avx512, strategy: *strategy };
            let t = Instant::now();
            kernel::deform::<W, B>(mesh, &frame, 0, &mut positions, &mut normals);
            let seconds = t.elapsed().as_secs_f64();
            if round > 0 {
                let b = &mut best[(round + i) % candidates.len()];
                *b = b.min(seconds);
            }
        }
    }
    let fastest = best.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |(i, _)| i);
    candidates[fastest].0
}
