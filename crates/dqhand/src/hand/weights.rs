//! Automatic skin weights from the hand's own parts.
//!
//! A vertex belongs to the bones whose parts it lies on. With `d_b` the distance from the
//! vertex to bone `b`'s parts (see [`HandShape::bone_distances`]), the raw weight is
//! `exp(−(d_b − min d) / σ_b)`: 1 for the nearest bone, falling off smoothly with how much
//! farther the others are. Across a joint, where the round cones of both phalanges meet, the
//! distances cross over within about a finger radius, which gives the blend region; over the
//! webs and the palm, where parts are blended, neighbouring bones share the skin. To keep at
//! most four influences without a jump where the fifth and fourth change places, the fifth
//! largest raw weight (and at least 1 % of the largest) is subtracted from the four kept
//! before they are normalised. Distant bones get nothing: a fingertip never moves with the
//! wrist.

use super::shape::HandShape;

/// Influences kept per vertex.
pub(crate) const INFLUENCES: usize = 4;
/// Weights below this fraction of the vertex's largest are dropped.
const CUTOFF: f32 = 0.01;

/// Joint indices and weights, [`INFLUENCES`] per vertex, heaviest first, summing to one.
///
/// `sigma` is each joint's falloff length σ: short on the fingers for a crease-like blend
/// across a joint, longer on the palm, whose bones share its skin over a wide area.
pub(crate) fn skin_weights(shape: &HandShape, positions: &[[f32; 3]], sigma: &[f32]) -> (Vec<u32>, Vec<f32>) {
    let joints = sigma.len();
    let mut out_joints = Vec::with_capacity(positions.len() * INFLUENCES);
    let mut out_weights = Vec::with_capacity(positions.len() * INFLUENCES);
    let mut d = vec![0.0f32; joints];
    let mut ranked: Vec<(f32, u32)> = Vec::with_capacity(joints);
    for &p in positions {
        shape.bone_distances(p.into(), &mut d);
        let nearest = d.iter().copied().fold(f32::INFINITY, f32::min);
        ranked.clear();
        ranked.extend(d.iter().enumerate().filter(|(_, x)| x.is_finite()).map(|(j, &x)| ((-(x - nearest) / sigma[j]).exp(), j as u32)));
        ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
        let floor = ranked.get(INFLUENCES).map_or(0.0, |r| r.0).max(CUTOFF * ranked[0].0);
        let kept = &ranked[..INFLUENCES.min(ranked.len())];
        let total: f32 = kept.iter().map(|r| (r.0 - floor).max(0.0)).sum();
        for slot in 0..INFLUENCES {
            let (w, j) = kept.get(slot).map_or((0.0, kept[0].1), |&(w, j)| ((w - floor).max(0.0) / total, j));
            out_joints.push(j);
            out_weights.push(w);
        }
    }
    (out_joints, out_weights)
}
