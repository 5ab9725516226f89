//! The built-in hand.
//!
//! For now a **procedural placeholder**: one tube per finger and an elliptic palm tube on the
//! anatomical 20-bone skeleton, 8,668 vertices like the paper's Table 2 so that benchmarks
//! run on the paper's workload. The parts are separate closed surfaces, not one watertight
//! anatomical skin; the anatomical hand replaces this module in its own issue.
//!
//! Proportions: segment lengths as fractions of hand length from Buchholz, Armstrong and
//! Goldstein 1992 ("Anthropometric data for describing the kinematics of the human hand",
//! Ergonomics 35:261), finger spacing and widths as fractions of hand breadth.

mod placeholder;

pub use placeholder::{build, HandParams, Side};
