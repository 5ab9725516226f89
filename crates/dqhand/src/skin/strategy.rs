//! How the AVX-512 kernel finds the bone parameters of a block's 16 vertices.
//!
//! Per influence slot the blend needs every parameter of each lane's joint. The ways to get
//! them cost different units on different cores: a two-source permute is one instruction per
//! parameter, cheap on AMD Zen 5 but issued on a single port on Intel cores (the port that
//! also runs half the 512-bit fused multiply-adds); a gather is sixteen loads; a broadcast of
//! one joint's parameter from memory runs on the load ports but is needed once per distinct
//! joint of the slot. None wins everywhere, so the deformer measures them on the mesh at hand
//! when it is built (`fastest_strategy`) and keeps the fastest.

/// A lookup strategy of the AVX-512 kernel (the other kernels blend whole parameter rows
/// per vertex and ignore it). Every strategy gives the same results to rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// One two-source permute per parameter from a component-major table of the frame's
    /// parameters, two registers per component: skins of at most 32 joints.
    Permute,
    /// One gather per parameter from the parameter rows, and one of the lanes' pair signs:
    /// any number of joints.
    Gather,
    /// Per slot, the mesh's pre-arranged runs of lanes that share a joint (and hemisphere
    /// sign): one broadcast from memory and one masked fused multiply-add per parameter and
    /// run. Any number of joints.
    Broadcast,
}

impl Strategy {
    /// Every strategy.
    pub const ALL: [Strategy; 3] = [Strategy::Permute, Strategy::Gather, Strategy::Broadcast];

    /// Environment variable that forces a strategy on every deformer built without
    /// [`Deformer::with_strategy`](super::Deformer::with_strategy) (for benchmarks): a
    /// [`Self::name`]. The library ignores any other value (it has no way to say so but a
    /// panic); `dqhand bench` refuses it.
    pub const ENV: &'static str = "DQHAND_STRATEGY";

    /// Most joints [`Strategy::Permute`] holds: the 32 lanes of a two-source permute.
    pub const PERMUTE_JOINTS: usize = 32;

    /// Whether the strategy serves a skin of `joints` joints.
    #[must_use]
    pub fn serves(self, joints: usize) -> bool {
        self != Strategy::Permute || joints <= Self::PERMUTE_JOINTS
    }

    /// `permute`, `gather` or `broadcast`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Permute => "permute",
            Strategy::Gather => "gather",
            Strategy::Broadcast => "broadcast",
        }
    }

    /// The strategy of [`Self::name`] `name`, if there is one.
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}
