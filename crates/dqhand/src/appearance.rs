//! What a model's skin looks like beyond its shape (issue 32, past the paper, whose hand is one
//! flat colour): which triangles are the back of the hand, the palm and the nails, and the skin
//! maps drawn on the mesh's UVs, albedo and tangent-space normals, one pair for the back and
//! one for the palm (the built-in hand's UVs are one projection onto the palm plane, seamless,
//! so the back and the palm read the same coordinates and need their own images).
//!
//! The maps are drawn when asked for (a few hundred milliseconds for the built-in hand), not
//! kept: skinning and collision never need them; the glTF export does, once per file.

use std::fmt;
use std::ops::Range;

/// Which part of the skin a triangle belongs to, each drawn with its own material.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SurfaceRegion {
    /// The dorsal skin: the back of the hand and of the fingers, knuckle wrinkles.
    Back,
    /// The palmar skin: palm and finger pads, the flexion creases and the palm's lines.
    Palm,
    /// The nail plates: harder and glossier, drawn with the back's maps (nail bed, lunula).
    Nail,
}

impl SurfaceRegion {
    /// Every region, in the order a mesh keeps their triangles.
    pub const ALL: [Self; 3] = [Self::Back, Self::Palm, Self::Nail];

    /// The region's name, as the glTF material is called.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Back => "skin-back",
            Self::Palm => "skin-palm",
            Self::Nail => "nail",
        }
    }
}

/// An 8-bit RGB image, rows top to bottom (glTF's texture coordinates: v down).
#[derive(Clone, PartialEq, Eq)]
pub struct SkinImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `3 · width · height` bytes.
    pub rgb: Vec<u8>,
}

impl fmt::Debug for SkinImage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SkinImage({}×{})", self.width, self.height)
    }
}

/// The albedo (sRGB) and the normal map (tangent space, glTF's convention: +Y up the image)
/// of one side of the hand.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SkinMaps {
    /// Base colour, sRGB.
    pub albedo: SkinImage,
    /// Tangent-space normals, `0.5 · n + 0.5` per channel.
    pub normal: SkinImage,
}

/// The regions of a mesh's triangles and the maps of its two sides.
pub struct Appearance {
    /// Each region's triangles: a range of the mesh's flat index array (a multiple of three),
    /// in [`SurfaceRegion::ALL`] order, together the whole array ([`Self::covers`]).
    pub regions: Vec<(SurfaceRegion, Range<usize>)>,
    draw: Box<dyn Fn() -> [SkinMaps; 2] + Send + Sync>,
}

impl fmt::Debug for Appearance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Appearance").field("regions", &self.regions).finish_non_exhaustive()
    }
}

impl Appearance {
    /// `regions` as [`Self::regions`]; `draw` draws the back's and the palm's maps.
    pub fn new(regions: Vec<(SurfaceRegion, Range<usize>)>, draw: impl Fn() -> [SkinMaps; 2] + Send + Sync + 'static) -> Self {
        Self { regions, draw: Box::new(draw) }
    }

    /// The back's maps (also the nails') and the palm's, drawn anew.
    #[must_use]
    pub fn maps(&self) -> [SkinMaps; 2] {
        (self.draw)()
    }

    /// Whether the regions are whole triangles that follow each other from the start of an
    /// index array of `len` entries to its end: what a mesh with this appearance must have.
    #[must_use]
    pub fn covers(&self, len: usize) -> bool {
        let mut end = 0;
        for (_, r) in &self.regions {
            if r.start != end || r.end < r.start || r.start % 3 != 0 || r.end % 3 != 0 {
                return false;
            }
            end = r.end;
        }
        end == len
    }
}
