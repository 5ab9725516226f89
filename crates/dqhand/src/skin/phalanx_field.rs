//! One bone's skin as a field around its axis, for the contact pass ([`super::SelfContactPass`]):
//! the rest skin the bone carries, as its largest distance from the bone's axis per cell of
//! (position along the axis, direction round it). A point of another part's skin posed into
//! the bone's rest frame is inside that skin where it is nearer the axis than its cell's
//! radius; how much nearer says how far it must move out, radially.
//!
//! The per-phalanx distance fields of implicit skinning (Vaillant et al., "Implicit skinning:
//! real-time skin deformation with contact modeling", SIGGRAPH 2013) are HRBF fits to each
//! bone's skin, composed and marched along; a phalanx is a tube round its bone, for which a
//! height map over the tube is exact to its sampling and costs one cell lookup per point.
//! The cells are filled from points sampled over the bone's triangles, not its vertices only,
//! so a triangle crossing a cell with none of its corners there still fills it.

use glam::{Affine3A, Mat3A, Vec3, Vec3A};

/// Cells round the axis: 24, equal steps of a pseudo-angle ([`sector`]), 11–18° each (a 9 mm
/// finger's arc of 1.8–2.9 mm).
pub(crate) const SECTORS: usize = 24;
/// Cells along the axis are this long (m) at most.
const CELL_LENGTH: f32 = 0.002;
/// Samples per triangle edge (`n(n+1)/2` per triangle): the built-in hand's triangles are
/// 1–3 mm, its cells 2 mm by 11–18°.
const SAMPLES: usize = 4;

/// One bone's skin round its principal axis.
///
/// Points are read in the field's own coordinates: cells along the axis (from the skin's
/// first end), and metres across it in two fixed directions; one affine map from the world
/// per frame ([`Self::pose`]) takes a posed point there, the bone's inverse skinning
/// transform folded in.
#[derive(Clone, Debug)]
pub(crate) struct PhalanxField {
    /// The mesh's rest (bind) space to the field's coordinates and back, and this frame's
    /// world to them and back.
    from_rest: Affine3A,
    to_rest: Affine3A,
    from_world: Affine3A,
    to_world: Affine3A,
    /// Steps along the axis, and the length of one (m).
    cells: usize,
    step: f32,
    /// `cells × SECTORS` radii (m; 0 where no skin is): at rest, and this frame's
    /// ([`Self::grow`]).
    rest: Vec<f32>,
    radius: Vec<f32>,
    /// Per step along the axis, its largest radius: at rest and this frame.
    rest_rows: Vec<f32>,
    rows: Vec<f32>,
    /// This frame's world box round the rest skin (centre, half extents), grown by the
    /// largest rest radius of any step: a sphere outside it, by more than a slack, meets no
    /// step (the cheap test before [`Self::meets`]' transform).
    world_box: (Vec3A, Vec3A),
    /// The largest radius of any step at rest, and this frame.
    rest_reach: f32,
    reach: f32,
}

/// A point in a field's coordinates inside its skin's length: its cell, and its squared
/// distance from the axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisPoint {
    local: Vec3A,
    cell: usize,
    distance_squared: f32,
}

impl PhalanxField {
    /// The field of `triangles` (corner positions, rest frame) about their principal axis;
    /// none for no triangles.
    pub(crate) fn new(triangles: &[[Vec3; 3]]) -> Option<Self> {
        let points = || triangles.iter().flat_map(samples);
        let count = triangles.len() * SAMPLES * (SAMPLES + 1) / 2;
        if count == 0 {
            return None;
        }
        let centre = points().fold(Vec3::ZERO, |a, p| a + p) / count as f32;
        let axis = principal_axis(points().map(|p| p - centre));
        let (x, y) = axis.any_orthonormal_pair();
        let along = |p: Vec3| (p - centre).dot(axis);
        let (lo, hi) = points().map(along).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), t| (a.min(t), b.max(t)));
        let cells = (((hi - lo) / CELL_LENGTH).ceil() as usize).max(1);
        let length = ((hi - lo) / cells as f32).max(f32::MIN_POSITIVE);
        // Rows of the map: (axis / length, x, y) · (p − (centre + axis · lo)).
        let basis = Mat3A::from_cols(Vec3A::from(axis / length), Vec3A::from(x), Vec3A::from(y)).transpose();
        let from_rest = Affine3A { matrix3: basis, translation: -(basis * Vec3A::from(centre + axis * lo)) };
        let mut field = Self { from_rest, to_rest: from_rest.inverse(), from_world: from_rest, to_world: from_rest.inverse(), cells, step: length, rest: vec![0.0; cells * SECTORS], radius: Vec::new(), rest_rows: vec![0.0; cells], rows: Vec::new(), world_box: (Vec3A::ZERO, Vec3A::ZERO), rest_reach: 0.0, reach: 0.0 };
        for p in points() {
            let a = field.locate_rest(p);
            let r = &mut field.rest[a.cell];
            *r = r.max(a.distance());
        }
        field.settle();
        Some(field)
    }

    /// The field's coordinates of a point of the rest mesh.
    pub(crate) fn rest_local(&self, p: Vec3) -> Vec3A {
        self.from_rest.transform_point3a(Vec3A::from(p))
    }

    /// Where a point of the bone's own rest skin falls, its ends included (the farthest
    /// samples are at the end, or past it by rounding: in the last step).
    pub(crate) fn locate_rest(&self, p: Vec3) -> AxisPoint {
        let mut local = self.rest_local(p);
        local.x = local.x.clamp(0.0, self.cells as f32 * (1.0 - f32::EPSILON));
        AxisPoint::at(local, (local.x as usize).min(self.cells - 1))
    }

    /// Poses the field with its bone's skinning transform (`world · inverse_bind`) and
    /// brings it back to its rest skin, before this frame's [`Self::grow`]s.
    pub(crate) fn pose(&mut self, skinning: &Affine3A) {
        self.to_world = *skinning * self.to_rest;
        self.from_world = self.to_world.inverse();
        self.radius.copy_from_slice(&self.rest);
        self.rows.copy_from_slice(&self.rest_rows);
        self.reach = self.rest_reach;
        let (centre, half) = (Vec3A::new(self.cells as f32 * 0.5, 0.0, 0.0), Vec3A::new(self.cells as f32 * 0.5, self.rest_reach, self.rest_reach));
        let m = self.to_world.matrix3;
        let abs = Mat3A::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        self.world_box = (self.to_world.transform_point3a(centre), abs * half);
    }

    /// The field's coordinates of a posed point (world).
    pub(crate) fn local(&self, p: Vec3A) -> Vec3A {
        self.from_world.transform_point3a(p)
    }

    /// Where a point (field coordinates) falls: none beyond the skin's ends along the axis.
    pub(crate) fn locate(&self, local: Vec3A) -> Option<AxisPoint> {
        (0.0..self.cells as f32).contains(&local.x).then(|| AxisPoint::at(local, local.x as usize))
    }

    /// Whether a point (field coordinates) is farther than `clearance` outside the largest
    /// radius of its step (no cell of the step can hold it): the cheap test first.
    pub(crate) fn clear_of_step(&self, local: Vec3A, clearance: f32) -> bool {
        let r = self.rows[(local.x.max(0.0) as usize).min(self.cells - 1)] + clearance;
        local.y * local.y + local.z * local.z >= r * r
    }

    /// How far inside this frame's skin `a` is (m), where it is deeper than `-clearance`.
    pub(crate) fn inside(&self, a: &AxisPoint, clearance: f32) -> Option<f32> {
        let r = self.radius[a.cell] + clearance;
        (a.distance_squared < r * r).then(|| self.radius[a.cell] - a.distance_squared.sqrt())
    }

    /// The steps along the axis where a sphere (world centre, radius) may meet this frame's
    /// skin grown by `slack`, first and last; none where it cannot (against the largest radius
    /// of the steps it spans).
    pub(crate) fn meets(&self, centre: Vec3A, radius: f32, slack: f32) -> Option<(usize, usize)> {
        let (middle, half) = self.world_box;
        let gap = ((centre - middle).abs() - half).max(Vec3A::ZERO);
        // (Growth beyond the rest radius moves the box's sides out by at most twice as much.)
        let reach = radius + slack + 2.0 * (self.reach - self.rest_reach);
        if gap.length_squared() > reach * reach {
            return None;
        }
        let q = self.local(centre);
        let span = radius / self.step;
        // (Truncation is the floor here: both ends are cut to 0 and up first.)
        let (from, to) = (q.x - span, q.x + span);
        if to < 0.0 || from >= self.cells as f32 {
            return None;
        }
        let (first, last) = (from.max(0.0) as usize, (to as usize).min(self.cells - 1));
        let largest = self.rows[first..=last].iter().copied().fold(0.0, f32::max);
        let r = largest + slack + radius;
        (q.y * q.y + q.z * q.z <= r * r).then_some((first, last))
    }

    /// Steps along the axis.
    pub(crate) fn steps(&self) -> usize {
        self.cells
    }

    /// Narrows `a`'s cell (rest) so that it holds `a` `clearance` outside: a point known to be
    /// out of this skin (another part's skin at rest) where the cell's largest radius, across
    /// its sector, reached past it. [`Self::settle`] after the last.
    pub(crate) fn exclude(&mut self, a: &AxisPoint, clearance: f32) {
        let r = &mut self.rest[a.cell];
        *r = r.min((a.distance() - clearance).max(0.0));
    }

    /// Grows the cell of `a` (a vertex of this bone's skin as posed) to hold `by` more than
    /// at rest: the posed skin bulges where the blend moves it out (DQB at a bent joint), and
    /// another part's skin pushed onto the rest surface would be in it.
    pub(crate) fn grow(&mut self, a: &AxisPoint, by: f32) {
        let r = &mut self.radius[a.cell];
        *r = r.max(self.rest[a.cell] + by);
        let row = &mut self.rows[a.cell / SECTORS];
        *row = row.max(*r);
        self.reach = self.reach.max(*row);
    }

    /// The world position of `a` pushed `depth` out from the axis, and the unit vector out
    /// from the axis there (world).
    pub(crate) fn pushed(&self, a: &AxisPoint, depth: f32) -> (Vec3, Vec3) {
        let across = Vec3A::new(0.0, a.local.y, a.local.z);
        let out = across.normalize_or(Vec3A::Y);
        (Vec3::from(self.to_world.transform_point3a(a.local + out * depth)), Vec3::from(self.to_world.transform_vector3a(out)))
    }

    /// Takes the rest radii as they now are: each step's largest, and this frame's.
    pub(crate) fn settle(&mut self) {
        for (row, cells) in self.rest_rows.iter_mut().zip(self.rest.chunks_exact(SECTORS)) {
            *row = cells.iter().copied().fold(0.0, f32::max);
        }
        self.radius.clone_from(&self.rest);
        self.rows.clone_from(&self.rest_rows);
        self.rest_reach = self.rest_rows.iter().copied().fold(0.0, f32::max);
        self.reach = self.rest_reach;
    }
}

impl AxisPoint {
    /// The point at `local` (field coordinates) in step `step` along the axis.
    fn at(local: Vec3A, step: usize) -> Self {
        Self { local, cell: step * SECTORS + sector(local.y, local.z), distance_squared: local.y * local.y + local.z * local.z }
    }

    /// Its distance from the axis (m).
    pub(crate) fn distance(&self) -> f32 {
        self.distance_squared.sqrt()
    }

    /// Its step along the axis.
    pub(crate) fn step(&self) -> usize {
        self.cell / SECTORS
    }

    /// Its cell: `SECTORS` per step along the axis.
    pub(crate) fn cell(&self) -> usize {
        self.cell
    }
}

/// The sector of direction (x, y) round the axis, counted from −y through +x: by its
/// pseudo-angle (the position on the unit diamond |x| + |y| = 1, monotonic in the angle),
/// which needs no arctangent.
fn sector(x: f32, y: f32) -> usize {
    let s = x.abs() + y.abs();
    if s == 0.0 {
        return 0;
    }
    let p = y / s; // −1..1 along one half
    let turn = if x >= 0.0 { 1.0 + p } else { 3.0 - p }; // 0..4 round the whole
    ((turn * 0.25 * SECTORS as f32) as usize).min(SECTORS - 1)
}

/// Points spread evenly over a triangle, its corners included.
fn samples(t: &[Vec3; 3]) -> impl Iterator<Item = Vec3> + '_ {
    let n = (SAMPLES - 1) as f32;
    (0..SAMPLES).flat_map(move |i| (0..SAMPLES - i).map(move |j| t[0] + (t[1] - t[0]) * (i as f32 / n) + (t[2] - t[0]) * (j as f32 / n)))
}

/// The direction along which `offsets` (from their mean) spread the most: power iteration on
/// their covariance.
fn principal_axis(offsets: impl Iterator<Item = Vec3>) -> Vec3 {
    let c = offsets.fold(glam::Mat3::ZERO, |m, d| m + glam::Mat3::from_cols(d * d.x, d * d.y, d * d.z));
    let mut v = Vec3::new(1.0, 0.7, 0.3).normalize();
    for _ in 0..64 {
        v = (c * v).normalize_or(Vec3::X);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed cylinder of radius `r` along x from 0 to `l`, as triangles.
    fn cylinder(r: f32, l: f32) -> Vec<[Vec3; 3]> {
        let (n, m) = (48, 40);
        let at = |i: usize, j: usize| {
            let a = i as f32 / n as f32 * core::f32::consts::TAU;
            Vec3::new(l * j as f32 / m as f32, r * a.cos(), r * a.sin())
        };
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..m {
                t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        t
    }

    #[test]
    fn sectors_cover_the_turn_in_order() {
        // From straight down (−y) round through +x.
        let mut last = 0;
        for k in 0..360 {
            let a = (k as f32 - 89.5).to_radians();
            let s = sector(a.cos(), a.sin());
            assert!(s >= last && s < SECTORS, "{k}° → {s}");
            last = s;
        }
        assert_eq!(last, SECTORS - 1);
    }

    #[test]
    fn a_cylinders_field_holds_its_inside_and_not_its_outside() {
        let mut field = PhalanxField::new(&cylinder(0.009, 0.03)).unwrap();
        // Posed: turned a quarter about z and moved.
        let pose = Affine3A::from_rotation_translation(glam::Quat::from_rotation_z(1.5707964), Vec3::new(0.1, 0.2, 0.3));
        field.pose(&pose);
        let at = |p: Vec3| field.locate(field.local(Vec3A::from(pose.transform_point3(p))));
        for (p, inside) in [(Vec3::new(0.015, 0.0, 0.008), 0.001), (Vec3::new(0.01, -0.005, 0.0), 0.004)] {
            let depth = field.inside(&at(p).unwrap(), 0.0).unwrap();
            assert!((depth - inside).abs() < 2e-4, "{p}: {depth}");
        }
        assert!(field.inside(&at(Vec3::new(0.02, 0.0, -0.0095)).unwrap(), 0.0).is_none(), "outside");
        assert!(field.inside(&at(Vec3::new(0.02, 0.0, -0.0095)).unwrap(), 0.001).is_some(), "within the clearance");
        assert!(at(Vec3::new(0.031, 0.0, 0.0)).is_none(), "beyond its end");
        // Pushed out by its depth, a point is on the surface, and the way out is radial.
        let p = Vec3::new(0.012, 0.003, 0.004);
        let a = at(p).unwrap();
        let (out, normal) = field.pushed(&a, field.inside(&a, 0.0).unwrap());
        let back = pose.inverse().transform_point3(out);
        assert!((Vec3::new(0.0, back.y, back.z).length() - 0.009).abs() < 1e-4 && (back.x - 0.012).abs() < 1e-5, "{back}");
        assert!(pose.inverse().transform_vector3(normal).abs_diff_eq(Vec3::new(0.0, 0.6, 0.8), 1e-5), "{normal}");
        // A sphere near the surface may meet it; one beyond its largest radius may not.
        let meets = |p: Vec3, r: f32| field.meets(Vec3A::from(pose.transform_point3(p)), r, 0.0);
        let step = 0.03 / field.steps() as f32;
        let (first, last) = meets(Vec3::new(0.015, 0.0, 0.012), 0.0035).expect("it may meet");
        assert_eq!((first, last), (((0.015 - 0.0035) / step) as usize, ((0.015 + 0.0035) / step) as usize), "the steps it spans");
        assert_eq!(meets(Vec3::new(0.015, 0.0, 0.014), 0.0035), None);
        assert_eq!(meets(Vec3::new(0.036, 0.0, 0.0), 0.004), None, "beyond its end");
    }
}
