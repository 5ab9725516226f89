//! The contact pass after skinning: skin of one part of the hand that a deformer has put
//! inside another part's skin (a fingertip in the palm, the thumb in the index finger of a
//! fist) is moved out of it, onto its surface. (Pushes run field after field: one may put a
//! vertex back into a field it left; the self-contact metric measures what is left.)
//!
//! Each bone's rest skin is a field round its axis ([`PhalanxField`]); a vertex inside
//! another part's bone there is pushed out along that bone's radius to its surface plus
//! [`CLEARANCE`]. Of two parts in contact one yields, by a fixed order (every finger to the
//! palm, the thumb to every finger, and between the others the one farther from the thumb):
//! the skin that stays is then the one the fields describe, and the yielding skin ends on it,
//! flattened against it as a pad presses on a finger (Vaillant et al. 2013 meet at a
//! contact surface between both fields; here one side gives, which needs no composition).
//! A pushed vertex only ever moves from the inside of the other part's skin towards its
//! surface, so it stays where the posed skin already was, or within [`CLEARANCE`] and a
//! field's sampling of it: the pass puts no skin more than that into an object the skin was
//! clear of (the manipulation loop's contact constraint holds).
//!
//! Pressed skin's normal is the surface it rests on, turned to face it. The volume a pushed
//! part loses is not given back (no bulge round the contact): `dqhand metrics` reports it.
//!
//! Per frame the pass poses each field once, bounds each cluster of a yielding bone's posed
//! vertices by a sphere, and reads the fields only for vertices of clusters whose sphere may
//! meet a field (within the largest radius of the steps along its axis it spans); it
//! allocates nothing.

use glam::{Affine3A, Vec3, Vec3A};

use super::deformer::Deformed;
use super::phalanx_field::{PhalanxField, SECTORS};
use super::SkinnedMesh;
use crate::kinematics::{HandPart, Skeleton};

/// How far outside the skin it yields to a pushed vertex ends (m).
pub const CLEARANCE: f32 = 0.0002;

/// The most a bone's posed skin is taken to bulge out of its rest field (m): a cluster
/// farther than that from a field's rest skin cannot reach it.
const MAX_BULGE: f32 = 0.005;

/// A vertex with at least this weight on a bone is skin of that bone too (the web between two
/// fingers, a knuckle's skin on its metacarpal): it does not yield to it. Less is the blend's
/// tail, which reaches a knuckle pressed on the next finger.
const SHARED_WEIGHT: f32 = 0.02;

/// Bones past this are not fields (the vertices' weights are kept as a 64-bit mask); a hand
/// has 25 joints.
const MAX_JOINTS: usize = 64;

/// No step of a field needed this frame.
const NOT_NEEDED: (usize, usize) = (usize::MAX, 0);

/// Sectors per cluster round a bone, and cells per cluster along it.
const CLUSTER_SECTORS: usize = SECTORS / 4;
const CLUSTER_CELLS: usize = 3;

/// What one pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPassReport {
    /// Pushes: vertices moved, once per skin each left.
    pub pushed: usize,
    /// The farthest one moved (m).
    pub deepest_m: f32,
}

/// Some vertices of one bone, near each other at rest: `members[start..end]`.
#[derive(Clone, Debug)]
struct Cluster {
    start: u32,
    end: u32,
}

/// One bone whose skin yields: its clusters (`clusters[first..end]`) and the fields they
/// yield to (indices into `fields`: `yields[yield_start..yield_end]`).
#[derive(Clone, Debug)]
struct YieldingBone {
    first: u32,
    end: u32,
    yield_start: u32,
    yield_end: u32,
}

/// The contact pass for one skinned hand mesh; build once, apply after every deformation.
///
/// ```
/// # #[cfg(feature = "interaction")] {
/// use dqhand::gesture::gesture;
/// use dqhand::hand::{build, HandParams};
/// use dqhand::kinematics::JointModel;
/// use dqhand::skin::{Deformed, Deformer, Method, SelfContactPass};
///
/// let model = build(&HandParams { vertices: 2000, ..HandParams::default() })?;
/// let mut hand = model.hand_kinematics(JointModel::Full)?;
/// hand.pose(&gesture("fist")?.pose(JointModel::Full));
/// let mut out = Deformed::new(&model.mesh);
/// Deformer::new(Method::Dqb, &model.mesh).deform(&model.mesh, hand.layer(), &mut out);
/// // The fist's fingertips are in the palm: the pass moves them out onto it.
/// let mut pass = SelfContactPass::new(&model.mesh, &model.skeleton);
/// let report = pass.apply(hand.layer().skinning(), &mut out);
/// assert!(report.pushed > 0 && report.deepest_m < 0.01, "{report:?}");
/// # }
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SelfContactPass {
    /// Per bone that carries skin of a part that others yield to: its joint and field.
    fields: Vec<(usize, PhalanxField)>,
    /// Per field, whether its skin bends with a finger's joints, and so is grown as posed
    /// (the palm's is taken to move with its bones, the wrist and the metacarpals; where it
    /// blends with a finger at a knuckle, that finger's skin is the one grown).
    bends: Vec<bool>,
    /// Per field, the steps along its axis that a cluster may reach this frame (first, last;
    /// empty where first > last).
    needed: Vec<(usize, usize)>,
    /// Per field, its bone's own vertices (heaviest there) and their rest distances from
    /// its axis, step by step along it at rest: step `s` of field `f` has
    /// `own[own_steps[own_start[f] + s]..own_steps[own_start[f] + s + 1]]`.
    own: Vec<(u32, f32)>,
    own_steps: Vec<u32>,
    own_start: Vec<u32>,
    /// Vertex indices, cluster by cluster, and per member the joints it is skinned to with at
    /// least [`SHARED_WEIGHT`] (bit `j` for joint `j` < 64).
    members: Vec<u32>,
    skinned_to: Vec<u64>,
    clusters: Vec<Cluster>,
    yields: Vec<u32>,
    bones: Vec<YieldingBone>,
    /// Per cluster, the sphere round its posed vertices this frame (centre, radius); per
    /// yielding bone, the sphere round its clusters'.
    spheres: Vec<(Vec3A, f32)>,
    bone_spheres: Vec<(Vec3A, f32)>,
    /// This frame's (cluster, field) pairs that may meet, the fields grown by [`MAX_BULGE`],
    /// and the most there can be.
    candidates: Vec<(u32, u32)>,
    most_candidates: usize,
}

/// The part order of who yields to whom: a part yields to every part later in it.
fn rank(part: HandPart) -> usize {
    match part {
        HandPart::Finger(0) => 0,
        HandPart::Finger(f) => 5 - f,
        HandPart::Palm => 5,
    }
}

impl SelfContactPass {
    /// The pass for `mesh` on `skeleton` (a WebXR hand: its joints' names give the parts),
    /// built from the rest skin: the fields of the bones skin may yield to, each narrowed
    /// where it would hold another part's rest skin (a field's cell is a sector of 11–18°,
    /// wider than a concave skin there), so a hand at rest is left as it is. Bones past the
    /// 64th are no fields.
    ///
    /// # Panics
    /// If `skeleton` has fewer joints than the mesh's influences name.
    #[must_use]
    pub fn new(mesh: &SkinnedMesh, skeleton: &Skeleton) -> Self {
        let joints = skeleton.joints();
        let n = mesh.vertex_count();
        let heaviest: Vec<usize> = (0..n).map(|v| mesh.influences(v).next().map_or(0, |(j, _)| j)).collect();
        let part: Vec<HandPart> = joints.iter().map(|j| HandPart::of(&j.name)).collect();
        let rest: Vec<Vec3> = (0..n).map(|v| mesh.position(v)).collect();
        // A joint yields to `b` where `b`'s part ranks above its own and `b` is not its parent
        // (a proximal phalanx's skin runs on into its metacarpal's).
        let yields_to = |a: usize, b: usize| rank(part[b]) > rank(part[a]) && joints[a].parent != Some(b);
        let mut triangles: Vec<Vec<[Vec3; 3]>> = vec![Vec::new(); joints.len()];
        for t in mesh.indices().chunks_exact(3) {
            let corners = [0, 1, 2].map(|k| rest[t[k] as usize]);
            let owners = [0, 1, 2].map(|k| heaviest[t[k] as usize]);
            for (k, &o) in owners.iter().enumerate() {
                if !owners[..k].contains(&o) {
                    triangles[o].push(corners);
                }
            }
        }
        // Every bone's field: the ones others yield to are kept, the rest cluster their own.
        let own_fields: Vec<Option<PhalanxField>> = triangles.iter().map(|t| PhalanxField::new(t)).collect();
        let mut fields: Vec<(usize, PhalanxField)> =
            own_fields.iter().enumerate().filter(|&(b, _)| b < MAX_JOINTS && (0..joints.len()).any(|a| yields_to(a, b))).filter_map(|(b, f)| f.clone().map(|f| (b, f))).collect();
        // Clusters: each yielding bone's vertices by where they sit round its own axis at rest.
        let mask = |v: usize| mesh.influences(v).filter(|&(j, w)| j < MAX_JOINTS && w >= SHARED_WEIGHT).fold(0u64, |m, (j, _)| m | 1 << j);
        let (mut members, mut clusters, mut yields, mut bones) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (a, own_field) in own_fields.iter().enumerate() {
            let targets: Vec<u32> = fields.iter().enumerate().filter(|(_, (b, _))| yields_to(a, *b)).map(|(i, _)| i as u32).collect();
            let Some(field) = own_field.as_ref().filter(|_| !targets.is_empty()) else { continue };
            let mut keyed: Vec<(usize, u32)> = (0..n).filter(|&v| heaviest[v] == a).map(|v| (cluster_of(field.locate_rest(rest[v]).cell()), v as u32)).collect();
            keyed.sort_unstable();
            let yield_start = yields.len() as u32;
            yields.extend_from_slice(&targets);
            let first = clusters.len() as u32;
            for run in keyed.chunk_by(|x, y| x.0 == y.0) {
                let start = members.len() as u32;
                members.extend(run.iter().map(|&(_, v)| v));
                clusters.push(Cluster { start, end: members.len() as u32 });
            }
            bones.push(YieldingBone { first, end: clusters.len() as u32, yield_start, yield_end: yields.len() as u32 });
        }
        let skinned_to: Vec<u64> = members.iter().map(|&v| mask(v as usize)).collect();
        // At rest no skin is inside another part's: narrow each field where it says otherwise.
        for bone in &bones {
            let range = clusters[bone.first as usize].start as usize..clusters[bone.end as usize - 1].end as usize;
            for (&v, &to) in members[range.clone()].iter().zip(&skinned_to[range]) {
                for &f in &yields[bone.yield_start as usize..bone.yield_end as usize] {
                    let (b, field) = &mut fields[f as usize];
                    if skinned(to, *b) {
                        continue;
                    }
                    if let Some(p) = field.locate(field.rest_local(rest[v as usize])).filter(|p| field.inside(p, 2.0 * CLEARANCE).is_some()) {
                        field.exclude(&p, 2.0 * CLEARANCE);
                    }
                }
            }
        }
        for (_, field) in &mut fields {
            field.settle();
        }
        let (mut own, mut own_steps, mut own_start) = (Vec::new(), Vec::new(), Vec::new());
        for (b, field) in &fields {
            let mut located: Vec<(usize, u32, f32)> = (0..n).filter(|&v| heaviest[v] == *b).map(|v| {
                let p = field.locate_rest(rest[v]);
                (p.step(), v as u32, p.distance())
            }).collect();
            located.sort_unstable_by_key(|&(s, v, _)| (s, v));
            own_start.push(own_steps.len() as u32);
            let base = own.len();
            for s in 0..=field.steps() {
                own_steps.push((base + located.partition_point(|l| l.0 < s)) as u32);
            }
            own.extend(located.iter().map(|&(_, v, d)| (v, d)));
        }
        let most_candidates = bones.iter().map(|b| ((b.end - b.first) * (b.yield_end - b.yield_start)) as usize).sum();
        let bends = fields.iter().map(|(b, _)| matches!(part[*b], HandPart::Finger(_))).collect();
        Self {
            bends,
            needed: vec![NOT_NEEDED; fields.len()],
            fields,
            own,
            own_steps,
            own_start,
            members,
            skinned_to,
            spheres: vec![(Vec3A::ZERO, 0.0); clusters.len()],
            most_candidates,
            candidates: Vec::with_capacity(most_candidates),
            clusters,
            yields,
            bone_spheres: vec![(Vec3A::ZERO, 0.0); bones.len()],
            bones,
        }
    }

    /// Moves the skin `out` that `skinning` (one transform per joint, `world · inverse_bind`)
    /// deformed out of the other parts' skin; its normals, where it has them, face what it
    /// rests on. Allocates nothing.
    ///
    /// # Panics
    /// If `skinning` has fewer transforms than the skeleton the pass was built on has joints
    /// with skin, or `out` is not of the pass's mesh.
    pub fn apply(&mut self, skinning: &[Affine3A], out: &mut Deformed) -> ContactPassReport {
        let (positions, normals) = out.buffers_mut();
        self.apply_to(skinning, positions, normals)
    }

    /// [`Self::apply`] on the caller's buffers: the mesh's positions (#V, m) and, if given, its
    /// unit normals (#V), in its vertex order.
    ///
    /// # Panics
    /// As [`Self::apply`], and if a buffer is shorter than the mesh.
    pub fn apply_to(&mut self, skinning: &[Affine3A], positions: &mut [[f32; 3]], mut normals: Option<&mut [[f32; 3]]>) -> ContactPassReport {
        let at = |v: u32| Vec3A::from(positions[v as usize]);
        for (bone, sphere_of_bone) in self.bones.iter().zip(&mut self.bone_spheres) {
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            let clusters = bone.first as usize..bone.end as usize;
            for (c, sphere) in self.clusters[clusters.clone()].iter().zip(&mut self.spheres[clusters]) {
                let (l, h) = self.members[c.start as usize..c.end as usize].iter().map(|&v| at(v)).fold((Vec3A::INFINITY, Vec3A::NEG_INFINITY), |(l, h), p| (l.min(p), h.max(p)));
                *sphere = ((l + h) * 0.5, (h - l).length() * 0.5);
                (lo, hi) = (lo.min(l), hi.max(h));
            }
            *sphere_of_bone = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
        }
        for ((b, field), needed) in self.fields.iter_mut().zip(&mut self.needed) {
            field.pose(&skinning[*b]);
            *needed = NOT_NEEDED;
        }
        // The pairs that may meet, as the fields were at rest and grown by the most bulge.
        self.candidates.clear();
        // (A clone's buffer has its length's capacity, none: the most a frame has, once.)
        self.candidates.reserve(self.most_candidates);
        for (bone, &(centre, radius)) in self.bones.iter().zip(&self.bone_spheres) {
            for &f in &self.yields[bone.yield_start as usize..bone.yield_end as usize] {
                let field = &self.fields[f as usize].1;
                if field.meets(centre, radius, MAX_BULGE).is_none() {
                    continue;
                }
                for k in bone.first..bone.end {
                    let (centre, radius) = self.spheres[k as usize];
                    if let Some((lo, hi)) = field.meets(centre, radius, MAX_BULGE) {
                        self.candidates.push((k, f));
                        let needed = &mut self.needed[f as usize];
                        *needed = (needed.0.min(lo), needed.1.max(hi));
                    }
                }
            }
        }
        // The steps of the fields they may meet, grown with their own skin as posed there (and
        // a step either side: skin slides along a bent joint).
        for (f, (_, field)) in self.fields.iter_mut().enumerate() {
            let (lo, hi) = self.needed[f];
            if lo > hi || !self.bends[f] {
                continue;
            }
            let steps = &self.own_steps[self.own_start[f] as usize..];
            let (lo, hi) = (lo.saturating_sub(1), (hi + 1).min(field.steps() - 1));
            for &(v, rest) in &self.own[steps[lo] as usize..steps[hi + 1] as usize] {
                if let Some(a) = field.locate(field.local(at(v))) {
                    field.grow(&a, (a.distance() - rest).min(MAX_BULGE));
                }
            }
        }
        let mut report = ContactPassReport::default();
        for &(k, f) in &self.candidates {
            let (c, (centre, radius)) = (&self.clusters[k as usize], self.spheres[k as usize]);
            let (joint, field) = &self.fields[f as usize];
            if field.meets(centre, radius, 0.0).is_none() {
                continue;
            }
            let range = c.start as usize..c.end as usize;
            for (&v, &to) in self.members[range.clone()].iter().zip(&self.skinned_to[range]) {
                if skinned(to, *joint) {
                    continue;
                }
                let local = field.local(Vec3A::from(positions[v as usize]));
                if field.clear_of_step(local, CLEARANCE) {
                    continue;
                }
                let Some(a) = field.locate(local) else { continue };
                let Some(depth) = field.inside(&a, CLEARANCE) else { continue };
                let (moved, outward) = field.pushed(&a, depth + CLEARANCE);
                positions[v as usize] = moved.to_array();
                if let Some(n) = normals.as_deref_mut().map(|n| &mut n[v as usize]) {
                    *n = (-outward).normalize_or_zero().to_array();
                }
                report.pushed += 1;
                report.deepest_m = report.deepest_m.max(depth + CLEARANCE);
            }
        }
        report
    }
}

/// Whether a vertex skinned to the joints of bit mask `to` is skinned to joint `j`.
fn skinned(to: u64, j: usize) -> bool {
    j < MAX_JOINTS && to & 1 << j != 0
}

/// The cluster of a cell of a bone's own field.
fn cluster_of(cell: usize) -> usize {
    let (along, round) = (cell / SECTORS, cell % SECTORS);
    (along / CLUSTER_CELLS) * (SECTORS / CLUSTER_SECTORS) + round / CLUSTER_SECTORS
}
