//! The skeleton: named joints in a tree, with their rest (bind) transforms.
//!
//! A joint here is a node of the tree (glTF's term); the bone that starts at it carries its
//! name, as in WebXR, where the 25 hand joints name 20 bones plus five tip end sites.

use glam::Affine3A;

use super::Transform;
use crate::{Error, Result};

/// One node of the skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Unique name (WebXR joint names for hands).
    pub name: String,
    /// Index of the parent joint, `None` for a root.
    pub parent: Option<usize>,
    /// Rest transform relative to the parent (or to the world for a root).
    pub rest: Transform,
}

/// A tree of joints with a precomputed evaluation order (parents before children).
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    joints: Vec<Joint>,
    order: Vec<usize>,
}

impl Skeleton {
    /// Builds a skeleton, checking that names are unique, parents exist and form no cycle,
    /// and transforms are finite.
    ///
    /// # Errors
    /// [`Error::Skeleton`] naming the offending joint.
    pub fn new(joints: Vec<Joint>) -> Result<Self> {
        let n = joints.len();
        let mut seen = std::collections::HashSet::new();
        for (i, j) in joints.iter().enumerate() {
            if !seen.insert(j.name.as_str()) {
                return Err(Error::Skeleton(format!("joint name {:?} is used twice", j.name)));
            }
            if let Some(p) = j.parent {
                if p >= n || p == i {
                    return Err(Error::Skeleton(format!("joint {:?} has invalid parent index {p}", j.name)));
                }
            }
            if !j.rest.is_finite() {
                return Err(Error::Skeleton(format!("joint {:?} has a non-finite rest transform", j.name)));
            }
        }
        // Depth-first order from the roots; a joint never reached lies on a cycle.
        let mut children = vec![Vec::new(); n];
        for (i, j) in joints.iter().enumerate() {
            if let Some(p) = j.parent {
                children[p].push(i);
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut stack: Vec<usize> = (0..n).rev().filter(|&i| joints[i].parent.is_none()).collect();
        while let Some(i) = stack.pop() {
            order.push(i);
            stack.extend(children[i].iter().rev());
        }
        if order.len() != n {
            let stuck = (0..n).find(|i| !order.contains(i)).unwrap_or(0);
            return Err(Error::Skeleton(format!("joint {:?} is part of a parent cycle", joints[stuck].name)));
        }
        Ok(Self { joints, order })
    }

    /// Number of joints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether there are no joints.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// The joints, in the order they were given.
    #[must_use]
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Evaluation order: every parent comes before its children.
    #[must_use]
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Index of the joint called `name`.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Index of the joint called `name`, or an error listing the valid names.
    ///
    /// # Errors
    /// [`Error::UnknownName`].
    pub fn index_of(&self, name: &str) -> Result<usize> {
        self.find(name).ok_or_else(|| Error::UnknownName {
            kind: "joint",
            name: name.to_owned(),
            valid: self.names().collect::<Vec<_>>().join(", "),
        })
    }

    /// The joint names in index order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.joints.iter().map(|j| j.name.as_str())
    }

    /// The rest transforms relative to the parents, in index order (the input of
    /// [`forward_kinematics`](super::forward_kinematics) for the rest pose).
    #[must_use]
    pub fn rest_locals(&self) -> Vec<Transform> {
        self.joints.iter().map(|j| j.rest).collect()
    }

    /// World transforms of the rest pose.
    #[must_use]
    pub fn rest_world(&self) -> Vec<Affine3A> {
        let mut world = vec![Affine3A::IDENTITY; self.len()];
        super::forward_kinematics(self, &self.rest_locals(), &mut world);
        world
    }

    /// The same joints re-parented by `parent_of` (a joint name to its new parent's name, or
    /// `None` to keep it), with rest locals recomputed so every rest world transform is kept.
    ///
    /// # Errors
    /// [`Error::Skeleton`] if the new parents form a cycle.
    pub fn reparented(&self, parent_of: impl Fn(&str) -> Option<&'static str>) -> Result<Self> {
        let world = self.rest_world();
        let mut joints = self.joints.clone();
        for (i, joint) in joints.iter_mut().enumerate() {
            if let Some(p) = parent_of(&joint.name).and_then(|p| self.find(p)).filter(|&p| joint.parent != Some(p)) {
                joint.parent = Some(p);
                joint.rest = Transform::from_affine(&(world[p].inverse() * world[i]));
            }
        }
        Self::new(joints)
    }
}
