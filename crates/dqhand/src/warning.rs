//! What a loader repaired or found unusual and went on: typed, so that an application can
//! tell them apart, show them its own way or refuse a model that needed repairs.

use core::fmt;

/// A repair or an oddity of a loaded model, mesh or scene object; the work went on.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// Vertices whose weights did not sum to one (they were normalised).
    WeightsRenormalised {
        /// How many.
        vertices: usize,
    },
    /// Zero-length normals, replaced by the normals of the surrounding faces.
    NormalsReplaced {
        /// How many.
        normals: usize,
    },
    /// Mesh nodes of a glTF file bound to another skin than the one read.
    OtherSkinsIgnored {
        /// How many nodes.
        nodes: usize,
        /// The skin read.
        skin: usize,
    },
    /// A glTF node shares its name with another and was renamed.
    NodeRenamed {
        /// The node's index in the file.
        node: usize,
        /// Its name in the file.
        name: String,
        /// Its name here.
        renamed: String,
    },
    /// A glTF node's rotation was not of unit norm (it was normalised).
    RotationNormalised {
        /// The node's name.
        node: String,
        /// The norm it had.
        norm: f32,
    },
    /// Triangles of an object's mesh without area, dropped.
    DegenerateTriangles {
        /// How many.
        triangles: usize,
    },
    /// An object's mesh has no volume: it collides as a surface.
    FlatMesh,
    /// Primitives of an object's glTF mesh that are not triangles, skipped.
    NotTriangles {
        /// How many.
        primitives: usize,
    },
    /// A warning about one object of a scene.
    Object {
        /// The object's name.
        object: String,
        /// What about it.
        warning: Box<Warning>,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WeightsRenormalised { vertices } => write!(f, "weights of {vertices} vertices did not sum to one and were normalised"),
            Self::NormalsReplaced { normals } => write!(f, "{normals} zero-length normals were replaced by the normals of the surrounding faces"),
            Self::OtherSkinsIgnored { nodes, skin } => write!(f, "{nodes} mesh nodes bound to other skins were ignored; only skin {skin} is read"),
            Self::NodeRenamed { node, name, renamed } => write!(f, "node {node} is also called {name:?}; it is called {renamed:?} here"),
            Self::RotationNormalised { node, norm } => write!(f, "node {node:?} has a rotation of norm {norm}; it was normalised"),
            Self::DegenerateTriangles { triangles } => write!(f, "{triangles} triangles without area dropped"),
            Self::FlatMesh => f.write_str("flat (no volume): it collides as a surface"),
            Self::NotTriangles { primitives } => write!(f, "{primitives} primitives that are not triangles skipped"),
            Self::Object { object, warning } => write!(f, "{object}: {warning}"),
        }
    }
}
