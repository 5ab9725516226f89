//! Collision layer (paper 4.2): simplified shapes that stand in for the skin when the hand
//! touches the scene.
//!
//! For now the per-bone proxies, fitted to a skinned mesh and exported with it; the queries
//! against scene objects (continuous collision detection) build on them.

mod proxy;

pub use proxy::{fit_proxies, Proxy, ProxyShape, PROXY_MARGIN};
