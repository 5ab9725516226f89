//! Collision layer (paper 4.2): simplified shapes that stand in for the skin when the hand
//! touches the scene, and the queries between them and the scene's objects.
//!
//! * [`proxy`](fit_proxies) — one convex proxy per bone, fitted to a skinned mesh;
//! * [`HandProxies`] and [`ObjectColliders`] — the hand's and the scene's shapes, built once;
//! * [`ContactConstraint`] — continuous collision detection of the hand's motion against the
//!   objects, which gives the rendered hand (it never sinks in) and its contacts;
//! * [`ProxyMeshQuery`] — a proxy against a triangle mesh (the nearest triangle, the time of
//!   impact), its own rather than parry's, whose GJK in metres is centimetres off there;
//!   a hull proxy's support points by hill climbing (`hull_support`), which parry's casts
//!   between hulls take through a dispatcher of their own (`support_pair`).
//! * [`simulated_hull`] — what the physics simulates a hull proxy as: fewer vertices, rounded
//!   to hold the whole proxy.
//! * [`TriangleTree`] — a mesh object's triangles in a tree of its own, built once, which
//!   those queries search.

mod contact_constraint;
mod hand_proxies;
mod hull_support;
mod object_colliders;
mod proxy;
mod proxy_mesh_query;
mod simulated_hull;
mod support_pair;
mod triangle_tree;

pub use contact_constraint::{Closure, Contact, ContactConstraint, CONTACT_DISTANCE, SNAP_AFTER_S, STOP_DISTANCE};
pub use crate::kinematics::{HandPart, FINGERS};
pub use hand_proxies::{pose_of, HandProxies, ProxyCollider};
pub use object_colliders::{ObjectCollider, ObjectColliders, TableTop};
pub use proxy::{fit_proxies, Proxy, ProxyShape, PROXY_MARGIN};
pub use proxy_mesh_query::{MeshNearest, ProxyMeshQuery};
pub use simulated_hull::{simulated_hull, MAX_SIMULATED_VERTICES};
pub use triangle_tree::{TreeNode, TreeTriangle, TriangleTree};
