//! Physics of the free objects (rapier3d): gravity, the table, friction and restitution. A
//! held object is moved by the hand (kinematically, so it pushes what it meets) and handed
//! back to the simulation with the hand's velocity when released; the rendered hand's proxies
//! are kinematic bodies too, so what falls or rolls onto the hand rests against it. The room
//! has a floor; what leaves its reach is put back and reported.

mod scene_physics;

pub use scene_physics::{ScenePhysics, FLOOR_Y, GRAVITY, REACH_M};
