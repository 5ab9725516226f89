//! Grasping heuristics: when the hand holds an object, where the held object goes, and when
//! it is let go (the paper's "grasping heuristics", after Jacobs and Froehlich 2011 and
//! Prachyabrued and Borst 2012, in the style of today's hand-tracking SDKs).
//!
//! * **Grasp.** The thumb (or the palm) and at least one other finger touch an object in
//!   the rendered pose with opposing surface normals (an angle of more than
//!   [`GraspParams::opposition_deg`] between them), and the user squeezes: each of those
//!   fingers is tracked closed past where its rendered copy stopped on the surface by
//!   [`GraspParams::press_deg`]. A pinch (thumb and index tips) is the same rule on a
//!   small object.
//! * **Hold.** The touching points are fixed in their rendered bones, with four points of
//!   the wrist's frame, and carried by the tracked wrist; each frame the object takes the
//!   best-fit rigid motion ([`crate::math::rigid_fit`]) of those points since the grasp.
//!   Rendered, not tracked, fingers: the tracked ones close on into the object after the
//!   grasp and would drag it 1–3 cm across the palm; the rendered ones stop on its surface.
//! * **Release.** The grasping fingers open past the tightest their rendered copies have
//!   wrapped the object since the grasp by [`GraspParams::release_deg`] each (hysteresis:
//!   between the two thresholds nothing changes). Not past their closure at the grasp: a
//!   grasp can begin with fingers resting on the object open, and they cannot open further.
//!   The object is then not grasped again for [`GraspParams::cooldown_s`]. It
//!   leaves with the hand's velocity over the last frames, so a throw flies.
//! * **Two hands.** Either hand grasps by itself; a hand may grasp what the other holds, and
//!   the object then follows the best rigid fit of both hands' holding points. A free pair of
//!   hands also grasps an object between them: a pressing contact of each (a palm, a
//!   squeezing finger, or any contact of a hand pushed into the object) with opposing normals
//!   ([`Grasp::find_two_handed`]); such a hold lets go
//!   when the hands draw [`GraspParams::apart_m`] apart. When one hand lets go, the other keeps
//!   the object if its own grasp holds it ([`Grasp::alone`]; a hand-over), else drops it too.
//! * **Tracking loss.** A held object stays where it is while tracking is lost, and drops
//!   after [`GraspParams::loss_grace_s`].

mod hand_grasp;

pub use hand_grasp::{Grasp, GraspEvent, GraspParams, TwoHanded, MAX_HOLDING_POINTS};
