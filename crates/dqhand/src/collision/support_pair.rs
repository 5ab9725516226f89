//! Two shapes' own support functions, as parry's nonlinear shape cast asks for them.
//!
//! parry's cast between two support-mapped shapes advances by the support functions it is
//! given, but measures each step's closest points through its query dispatcher, on the
//! shapes themselves: a convex polyhedron's support there tries every vertex (957 on the
//! wrist's proxy, hundreds on a mesh's hull), where [`HullSupport`](super::hull_support)
//! climbs to the same point in about twenty. [`SupportPair`] is a dispatcher that answers
//! those closest-point queries by GJK on the two support functions, so a cast of a hull proxy
//! against a mesh's hull (`ObjectCollider::misses_hull`) costs a few microseconds, not thirty.

use parry3d::math::{Pose, Real};
use parry3d::query::details::{self, NonlinearShapeCastMode};
use parry3d::query::{
    ClosestPoints, Contact, DefaultQueryDispatcher, NonlinearRigidMotion, QueryDispatcher, ShapeCastHit, ShapeCastOptions, ShapeDistance, ShapeIntersection,
    Unsupported,
};
use parry3d::shape::{Shape, SupportMap};

/// Two shapes and the support functions that stand for them: the one query dispatcher of a
/// cast between exactly these two (closest points of any other pair are parry's own; the cast
/// asks for nothing else).
pub struct SupportPair<'a> {
    pub shapes: [&'a dyn Shape; 2],
    pub supports: [&'a (dyn SupportMap + Sync); 2],
}

impl SupportPair<'_> {
    /// Whether `first` and `second` are this pair's shapes in its order (`Some(false)`), the
    /// other order (`Some(true)`), or not this pair (`None`): the cast may swap them.
    fn order(&self, first: &dyn Shape, second: &dyn Shape) -> Option<bool> {
        let is = |a: &dyn Shape, b: &dyn Shape| core::ptr::addr_eq(a, b);
        match (is(first, self.shapes[0]) && is(second, self.shapes[1]), is(first, self.shapes[1]) && is(second, self.shapes[0])) {
            (true, _) => Some(false),
            (_, true) => Some(true),
            _ => None,
        }
    }

    /// The first time in `[0, end]` at which `shapes[0]` moving by `motion` touches
    /// `shapes[1]` moving by `other` (starting in it is time 0), if any: parry's nonlinear
    /// cast between two support maps, stopping at penetration.
    #[must_use]
    pub fn time_of_impact(&self, motion: &NonlinearRigidMotion, other: &NonlinearRigidMotion, end: f32) -> Option<f32> {
        let [g1, g2] = self.shapes;
        let [s1, s2] = self.supports;
        details::cast_shapes_nonlinear_support_map_support_map(self, motion, s1, g1, other, s2, g2, 0.0, end, NonlinearShapeCastMode::StopAtPenetration)
            .map(|hit| hit.time_of_impact)
    }
}

impl QueryDispatcher for SupportPair<'_> {
    fn intersection_test(&self, _: &Pose, _: &dyn Shape, _: &dyn Shape) -> Result<ShapeIntersection, Unsupported> {
        Err(Unsupported)
    }

    fn distance(&self, _: &Pose, _: &dyn Shape, _: &dyn Shape) -> Result<ShapeDistance, Unsupported> {
        Err(Unsupported)
    }

    fn contact(&self, _: &Pose, _: &dyn Shape, _: &dyn Shape, _: Real) -> Result<Option<Contact>, Unsupported> {
        Err(Unsupported)
    }

    fn closest_points(&self, pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, max_dist: Real) -> Result<ClosestPoints, Unsupported> {
        let [s1, s2] = self.supports;
        // (An answer refused would end the cast as a miss.)
        match self.order(g1, g2) {
            Some(false) => Ok(details::closest_points_support_map_support_map(pos12, s1, s2, max_dist)),
            Some(true) => Ok(details::closest_points_support_map_support_map(pos12, s2, s1, max_dist)),
            None => DefaultQueryDispatcher.closest_points(pos12, g1, g2, max_dist),
        }
    }

    fn cast_shapes(&self, _: &Pose, _: parry3d::math::Vector, _: &dyn Shape, _: &dyn Shape, _: ShapeCastOptions) -> Result<Option<ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }

    fn cast_shapes_nonlinear(&self, _: &NonlinearRigidMotion, _: &dyn Shape, _: &NonlinearRigidMotion, _: &dyn Shape, _: Real, _: Real, _: bool) -> Result<Option<ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use parry3d::query::DefaultQueryDispatcher;
    use parry3d::shape::ConvexPolyhedron;

    use crate::collision::hull_support::HullSupport;

    /// A convex polyhedron of many vertices: the hull of a sphere's points, radius `r`.
    fn ball_hull(r: f32) -> ConvexPolyhedron {
        let mut points = Vec::new();
        for i in 0..24 {
            for j in 1..12 {
                let (theta, phi) = (i as f32 / 24.0 * core::f32::consts::TAU, j as f32 / 12.0 * core::f32::consts::PI);
                points.push(Vec3::new(phi.sin() * theta.cos(), phi.cos(), phi.sin() * theta.sin()) * r);
            }
        }
        points.extend([Vec3::Y * r, -Vec3::Y * r]);
        ConvexPolyhedron::from_convex_hull(&points).expect("a hull")
    }

    /// A lopsided hull: the ball's points stretched along x, sheared and moved off its origin.
    fn lopsided_hull(r: f32) -> ConvexPolyhedron {
        let points: Vec<Vec3> = ball_hull(r).points().iter().map(|p| Vec3::new(2.0 * p.x + 0.5 * p.y, p.y, 0.7 * p.z) + Vec3::new(0.01, -0.02, 0.005)).collect();
        ConvexPolyhedron::from_convex_hull(&points).expect("a hull")
    }

    #[test]
    fn the_cast_by_support_functions_meets_where_parrys_does() {
        let (a, b) = (lopsided_hull(0.03), ball_hull(0.05));
        let (sa, sb) = (HullSupport::new(&a, 1.0), HullSupport::new(&b, 1.0));
        let still = NonlinearRigidMotion::constant_position(Pose::identity());
        for (from, linvel, angvel, hits) in [
            (Vec3::new(0.2, 0.01, 0.0), Vec3::new(-0.3, 0.0, 0.0), Vec3::ZERO, true),
            (Vec3::new(0.0, 0.15, 0.02), Vec3::new(0.0, -0.2, 0.01), Vec3::new(0.0, 0.0, 3.0), true),
            (Vec3::new(0.12, 0.12, 0.0), Vec3::new(-0.1, -0.1, 0.0), Vec3::new(1.0, 2.0, 0.0), true),
            // Passing by, and starting in it.
            (Vec3::new(0.2, 0.1, 0.0), Vec3::new(-0.4, 0.0, 0.0), Vec3::ZERO, false),
            (Vec3::new(0.05, 0.0, 0.0), Vec3::new(0.1, 0.0, 0.0), Vec3::ZERO, true),
        ] {
            let motion = NonlinearRigidMotion::new(Pose::from_translation(from), Vec3::ZERO, linvel, angvel);
            // Either hull moving, either first: parry's cast swaps them by size.
            let (sa, sb): (&(dyn SupportMap + Sync), &(dyn SupportMap + Sync)) = (&sa, &sb);
            let cases: [(&ConvexPolyhedron, _, &ConvexPolyhedron, _); 2] = [(&a, sa, &b, sb), (&b, sb, &a, sa)];
            for (moving, moving_support, other, other_support) in cases {
                let ours = SupportPair { shapes: [moving, other], supports: [moving_support, other_support] }.time_of_impact(&motion, &still, 1.0);
                let parrys = details::cast_shapes_nonlinear_support_map_support_map(&DefaultQueryDispatcher, &motion, moving, moving, &still, other, other, 0.0, 1.0, NonlinearShapeCastMode::StopAtPenetration)
                    .map(|hit| hit.time_of_impact);
                assert_eq!(parrys.is_some(), hits, "from {from}: parry's {parrys:?}");
                match (ours, parrys) {
                    (Some(x), Some(y)) => assert!((x - y).abs() < 1e-4, "from {from}: {x} against parry's {y}"),
                    (x, y) => assert_eq!(x.is_some(), y.is_some(), "from {from}: {x:?} against parry's {y:?}"),
                }
            }
        }
        // Head on along x, where both balls' hulls have a vertex on their sphere: 12 cm apart,
        // closing at 0.3 a unit of time; starting in it is time 0.
        let (a, sa) = (ball_hull(0.03), HullSupport::new(&ball_hull(0.03), 1.0));
        let pair = SupportPair { shapes: [&a, &b], supports: [&sa, &sb] };
        let head_on = NonlinearRigidMotion::new(Pose::from_translation(Vec3::new(0.2, 0.0, 0.0)), Vec3::ZERO, Vec3::new(-0.3, 0.0, 0.0), Vec3::ZERO);
        let t = pair.time_of_impact(&head_on, &still, 1.0).expect("it hits");
        assert!((0.399..0.41).contains(&t), "{t}");
        let inside = NonlinearRigidMotion::new(Pose::from_translation(Vec3::new(0.05, 0.0, 0.0)), Vec3::ZERO, Vec3::X, Vec3::ZERO);
        assert_eq!(pair.time_of_impact(&inside, &still, 1.0), Some(0.0));
        // Another pair's closest points are parry's own.
        let apart = Pose::from_translation(Vec3::new(0.2, 0.0, 0.0));
        assert_eq!(pair.closest_points(&apart, &b, &b, 1.0).ok(), DefaultQueryDispatcher.closest_points(&apart, &b, &b, 1.0).ok());
    }
}
