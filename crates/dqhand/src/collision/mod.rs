//! Collision layer (paper 4.2): simplified shapes that stand in for the skin when the hand
//! touches the scene, and the queries between them and the scene's objects.
//!
//! * [`proxy`](fit_proxies) — one convex proxy per bone, fitted to a skinned mesh;
//! * [`HandProxies`] and [`ObjectColliders`] — the hand's and the scene's shapes, built once;
//! * [`ContactConstraint`] — continuous collision detection of the hand's motion against the
//!   objects, which gives the rendered hand (it never sinks in) and its contacts; against a
//!   mesh, its wrist stage advances each proxy over the triangles itself (`proxy_mesh_cast`).

mod contact_constraint;
mod hand_proxies;
mod object_colliders;
mod proxy;
mod proxy_mesh_cast;

pub use contact_constraint::{Closure, Contact, ContactConstraint, CONTACT_DISTANCE, SNAP_AFTER_S};
pub use hand_proxies::{pose_of, HandPart, HandProxies, ProxyCollider, FINGERS};
pub use object_colliders::{ObjectCollider, ObjectColliders, TableTop};
pub use proxy::{fit_proxies, Proxy, ProxyShape, PROXY_MARGIN};
