//! Which hand a skeleton, a record or a user's hand is.

/// Which hand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Side {
    /// Left hand: the thumb on +X when the palm faces down and the fingers point along −Z.
    Left,
    /// Right hand: the thumb on −X.
    #[default]
    Right,
}

impl Side {
    /// `"left"` or `"right"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}
