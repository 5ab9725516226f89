//! The scene's objects as persistent parry shapes: built once when a scene is loaded, moved
//! by pose each frame. A mesh has two: its true surface (a triangle mesh, which the hand
//! touches and penetration is measured against; it need not be closed, as the Utah teapot
//! is not) and a solid for the physics (its convex hull), because a triangle soup has no
//! volume to give a mass or to rest on a table with.

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, TriMeshFlags};

use crate::scene::{ObjectMesh, ObjectShape, Scene};
use crate::{Error, Result};

/// One object's shapes and where it is.
#[derive(Clone)]
pub struct ObjectCollider {
    /// The object's name in the scene.
    pub name: String,
    /// The true surface, in the object's frame.
    pub surface: SharedShape,
    /// The solid the physics simulates, in the object's frame.
    pub solid: SharedShape,
    /// The surface's triangles in the object's frame, for measuring penetration (a mesh's
    /// own; a primitive's are not needed: its surface is exact).
    pub mesh: Option<ObjectMesh>,
    /// The object's current world pose.
    pub pose: Pose,
    aabb: Aabb,
}

impl ObjectCollider {
    /// The world bounding box of the surface in the current pose.
    #[must_use]
    pub fn aabb(&self) -> &Aabb {
        &self.aabb
    }
}

/// Every object of a scene, in file order.
#[derive(Clone)]
pub struct ObjectColliders {
    objects: Vec<ObjectCollider>,
    warnings: Vec<String>,
}

impl ObjectColliders {
    /// The shapes of `scene`'s objects, at the poses the file gives them.
    ///
    /// # Errors
    /// As [`ObjectMesh::load`] for a mesh object: a file that cannot be read, or no usable
    /// triangle.
    pub fn new(scene: &Scene) -> Result<Self> {
        let mut warnings = Vec::new();
        let mut objects = Vec::with_capacity(scene.objects.len());
        for o in &scene.objects {
            let (surface, solid, mesh) = match &o.shape {
                ObjectShape::Sphere { radius } => (SharedShape::ball(*radius), SharedShape::ball(*radius), None),
                ObjectShape::Box { size } => {
                    let s = SharedShape::cuboid(size.x / 2.0, size.y / 2.0, size.z / 2.0);
                    (s.clone(), s, None)
                }
                ObjectShape::Cylinder { radius, height } => {
                    let s = SharedShape::cylinder(height / 2.0, *radius);
                    (s.clone(), s, None)
                }
                ObjectShape::Mesh { file, scale } => {
                    let mut mesh = ObjectMesh::load(file)?;
                    for v in &mut mesh.vertices {
                        *v *= *scale;
                    }
                    warnings.extend(mesh.warnings.iter().map(|w| format!("{}: {w}", o.name)));
                    let (surface, solid) = mesh_shapes(&mesh).map_err(|problem| Error::ObjectMesh(format!("{}: {}: {problem}", file.display(), o.name)))?;
                    (surface, solid, Some(mesh))
                }
            };
            let pose = Pose::from_parts(o.position, o.rotation);
            let aabb = surface.compute_aabb(&pose);
            objects.push(ObjectCollider { name: o.name.clone(), surface, solid, mesh, pose, aabb });
        }
        Ok(Self { objects, warnings })
    }

    /// The objects, in scene order.
    #[must_use]
    pub fn objects(&self) -> &[ObjectCollider] {
        &self.objects
    }

    /// What was accepted with a doubt (a flat mesh, dropped triangles), one line each.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Moves object `i` (allocates nothing).
    pub fn set_pose(&mut self, i: usize, rotation: Quat, translation: Vec3) {
        let o = &mut self.objects[i];
        o.pose = Pose::from_parts(translation, rotation);
        o.aabb = o.surface.compute_aabb(&o.pose);
    }

    /// The broad phase: the objects whose bounding box meets `aabb` (grown by `margin`),
    /// except `skip`.
    pub fn near(&self, aabb: &Aabb, margin: f32, skip: Option<usize>) -> impl Iterator<Item = (usize, &ObjectCollider)> {
        let aabb = aabb.loosened(margin);
        self.objects.iter().enumerate().filter(move |(i, o)| Some(*i) != skip && o.aabb.intersects(&aabb))
    }
}

/// A mesh's surface (triangles as they are: it may be open) and solid (its convex hull; a
/// flat mesh's box, 1 mm thick, since a plane has no hull).
fn mesh_shapes(mesh: &ObjectMesh) -> std::result::Result<(SharedShape, SharedShape), String> {
    let surface = SharedShape::trimesh_with_flags(mesh.vertices.clone(), mesh.triangles.clone(), TriMeshFlags::empty()).map_err(|e| e.to_string())?;
    let solid = SharedShape::convex_hull(&mesh.vertices).unwrap_or_else(|| {
        let aabb = Aabb::from_points(mesh.vertices.iter().copied());
        let half = (aabb.half_extents()).max(Vec3::splat(0.0005));
        SharedShape::compound(vec![(Pose::from_translation(aabb.center()), SharedShape::cuboid(half.x, half.y, half.z))])
    });
    Ok((surface, solid))
}
