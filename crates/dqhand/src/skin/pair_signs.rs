//! The hemisphere sign per pair of joints sharing a vertex (Kavan et al. 2008, section 4.2's
//! antipodality), chosen so the skin follows a joint that twists past 180° instead of
//! flipping to the other side.
//!
//! A rotation has two quaternions, `q` and `−q`; before QB, DQB or CoR blend a vertex's
//! influences, each is signed to the heaviest influence's hemisphere (paper eq. 5 assumes
//! it). Taking the nearer sign every frame (the shortest path) is right for any single pose,
//! but as one bone turns past 180° against its neighbour the nearer sign switches and the
//! blend jumps to the other way round (21 mm at the index PIP of the built-in hand). Here
//! each pair's relative rotation keeps the sign it had last frame while it moved little
//! since, so a joint twisted 190° is blended the way it turned; a pose far from the last one
//! (a seek, a new clip, the first frame) takes the shortest path.

/// Largest change of a pair's relative rotation between two frames that is still followed,
/// as the cosine of half that angle (60°): far past any hand's motion at 60 frames a second,
/// and far below the 180° at which the previous frame says nothing.
const FOLLOW: f32 = 0.866_025_4;
/// The longest way round that is followed, as the cosine of half that relative rotation
/// (270°): past it the shortest path is taken again, before the two quaternions become
/// antipodal (360°), where their blend has no rotation left.
const LONGEST: f32 = -0.707_106_8;

/// One sign per pair of joints sharing a vertex and the pairs' relative rotations last
/// frame, signed as they were blended.
#[derive(Clone, Debug)]
pub(crate) struct PairSigns {
    /// `signs[0]` the heaviest joint's own (+1), `signs[1 + i]` for pair `i`.
    signs: Vec<f32>,
    /// Per pair, `conj(q_heaviest) · s q_other` of the last frame, `[x, y, z, w]` (the
    /// identity when none).
    last: Vec<[f32; 4]>,
}

impl PairSigns {
    /// Signs for `pairs` pairs, with no previous frame.
    pub(crate) fn new(pairs: usize) -> Self {
        Self { signs: vec![1.0; pairs + 1], last: vec![IDENTITY; pairs] }
    }

    /// The signs of the last [`Self::update`], heaviest joint's first.
    pub(crate) fn as_slice(&self) -> &[f32] {
        &self.signs
    }

    /// The next frame does not follow the last: it takes the shortest path.
    pub(crate) fn forget(&mut self) {
        self.last.fill(IDENTITY);
    }

    /// This frame's signs from the joints' parameters (a rotation `[x, y, z, w]` first) and
    /// the pairs `(heaviest, other)`. Allocates nothing; the product is written out in plain
    /// `f32` (no library's SIMD), so that every target decides a threshold alike.
    ///
    /// # Panics
    /// If made for another number of pairs.
    pub(crate) fn update<const W: usize>(&mut self, params: &[[f32; W]], pairs: &[(u16, u16)]) {
        assert_eq!(self.last.len(), pairs.len(), "deformer made for another mesh");
        for ((sign, last), &(h, j)) in self.signs[1..].iter_mut().zip(&mut self.last).zip(pairs) {
            let ([ax, ay, az, aw], [bx, by, bz, bw]) = (first4(&params[usize::from(h)]), first4(&params[usize::from(j)]));
            // conj(a) · b; its w is the hemisphere test of the shortest path.
            let dot = ax * bx + ay * by + az * bz + aw * bw;
            let relative = [aw * bx - ax * bw - ay * bz + az * by, aw * by + ax * bz - ay * bw - az * bx, aw * bz - ax * by + ay * bx - az * bw, dot];
            let along = relative[0] * last[0] + relative[1] * last[1] + relative[2] * last[2] + relative[3] * last[3];
            let followed = if along < 0.0 { -1.0 } else { 1.0 };
            *sign = if along.abs() >= FOLLOW && followed * dot >= LONGEST {
                followed
            } else if dot < 0.0 {
                -1.0
            } else {
                1.0
            };
            *last = relative.map(|c| c * *sign);
        }
    }

    /// Takes `other`'s last frame, as if this one had deformed the frames `other` did (QB, DQB
    /// and CoR of one mesh share the rotations the signs are chosen from); the signs
    /// themselves are the next [`Self::update`]'s. Allocates nothing when made for the same
    /// mesh.
    pub(crate) fn follow(&mut self, other: &Self) {
        self.last.clone_from(&other.last);
    }
}

/// The identity rotation, `[x, y, z, w]`.
const IDENTITY: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

fn first4<const W: usize>(p: &[f32; W]) -> [f32; 4] {
    [p[0], p[1], p[2], p[3]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    /// Joint 0 still, joint 1 twisted by `degrees` about X, each as `[x, y, z, w]` with w ≥ 0
    /// (the sign a matrix conversion gives, whatever the way it turned).
    fn params(degrees: f32) -> [[f32; 4]; 2] {
        let q = Quat::from_axis_angle(Vec3::X, degrees.to_radians());
        let q = if q.w < 0.0 { -q } else { q };
        [[0.0, 0.0, 0.0, 1.0], q.to_array()]
    }

    #[test]
    fn a_twist_is_followed_past_180_degrees_and_not_past_270() {
        let mut s = PairSigns::new(1);
        let mut signs = Vec::new();
        for step in 0..36 {
            s.update(&params(5.0 + step as f32 * 10.0), &[(0, 1)]);
            signs.push(s.as_slice()[1]);
        }
        // w ≥ 0 always here, so the shortest path's sign is +1 at every step: the −1 from
        // 185° to 265° is the followed twist, and from 275° the shortest path is back.
        let expected: Vec<f32> = (0..36).map(|step| if (18..=26).contains(&step) { -1.0 } else { 1.0 }).collect();
        assert_eq!(signs, expected);
    }

    #[test]
    fn a_jump_or_a_forgotten_frame_takes_the_shortest_path() {
        let mut s = PairSigns::new(1);
        for degrees in [165.0, 175.0, 185.0] {
            s.update(&params(degrees), &[(0, 1)]);
        }
        assert_eq!(s.as_slice()[1], -1.0, "followed to 185°");
        s.update(&params(60.0), &[(0, 1)]);
        assert_eq!(s.as_slice()[1], 1.0, "a jump back to 60° takes the shortest path");
        // A step of 70° past 180°: following would keep −1 (255° the way it turned); the
        // jump takes the shortest path, −105°. A step of 55° is followed.
        for degrees in [175.0, 185.0, 255.0] {
            s.update(&params(degrees), &[(0, 1)]);
        }
        assert_eq!(s.as_slice()[1], 1.0, "a jump of 70° from 185° to 255° takes the shortest path");
        for degrees in [175.0, 185.0, 240.0] {
            s.update(&params(degrees), &[(0, 1)]);
        }
        assert_eq!(s.as_slice()[1], -1.0, "a step of 55° from 185° to 240° is followed");
        for degrees in [175.0, 185.0] {
            s.update(&params(degrees), &[(0, 1)]);
        }
        s.forget();
        s.update(&params(185.0), &[(0, 1)]);
        assert_eq!(s.as_slice()[1], 1.0, "without a previous frame, 185° is the shortest path's 175° the other way");
    }

    #[test]
    fn the_heaviest_joints_sign_does_not_matter() {
        // The same relative twist with the heaviest joint's quaternion negated every other
        // frame: the other's sign flips with it, so their blend is the same rotation.
        let mut s = PairSigns::new(1);
        for step in 0..=25 {
            let mut p = params(5.0 + step as f32 * 10.0);
            let flip = if step % 2 == 1 { -1.0 } else { 1.0 };
            p[0] = p[0].map(|x| x * flip);
            s.update(&p, &[(0, 1)]);
            let expected = if step >= 18 { -1.0 } else { 1.0 } * flip;
            assert_eq!(s.as_slice()[1], expected, "step {step}");
        }
    }
}
