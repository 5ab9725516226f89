//! Which part of the hand a joint belongs to: the palm, which the wrist moves, or one finger,
//! which closes on its own. The contact constraint closes each finger alone, and the skin's
//! contact pass and the self-contact metric tell skin of one part inside another.

/// The five fingers, in WebXR name order (the thumb first).
pub const FINGERS: [&str; 5] = ["thumb", "index", "middle", "ring", "pinky"];

/// The part of the hand a joint (and its proxy, and its skin) belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandPart {
    /// The wrist and the four finger metacarpals: they move with the wrist (the ring and little
    /// ones also turn a little at their CMC joints as those fingers close).
    Palm,
    /// A finger's phalanges and tip (index into [`FINGERS`]); the thumb's include its
    /// metacarpal, which moves at the CMC joint.
    Finger(usize),
}

impl HandPart {
    /// The part of the joint called `name` (a WebXR name).
    #[must_use]
    pub fn of(name: &str) -> Self {
        match FINGERS.iter().position(|f| name.starts_with(f)) {
            Some(0) => HandPart::Finger(0),
            Some(f) if name.contains("phalanx") || name.ends_with("-tip") => HandPart::Finger(f),
            _ => HandPart::Palm,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_follow_webxr_names() {
        assert_eq!(HandPart::of("wrist"), HandPart::Palm);
        assert_eq!(HandPart::of("index-finger-metacarpal"), HandPart::Palm);
        assert_eq!(HandPart::of("thumb-metacarpal"), HandPart::Finger(0));
        assert_eq!(HandPart::of("thumb-phalanx-distal"), HandPart::Finger(0));
        assert_eq!(HandPart::of("ring-finger-phalanx-intermediate"), HandPart::Finger(3));
        assert_eq!(HandPart::of("pinky-finger-phalanx-distal"), HandPart::Finger(4));
        assert_eq!(HandPart::of("index-finger-tip"), HandPart::Finger(1), "a tip is its finger's, as the thumb's is");
    }
}
