//! What a model's skin looks like beyond its shape (issue 32, past the paper, whose hand is one
//! flat colour): which triangles are the back of the hand, the palm and the nails, and the skin
//! maps drawn on the mesh's UVs, albedo and tangent-space normals, one pair for the back and
//! one for the palm (the built-in hand's UVs are one projection onto the palm plane, seamless,
//! so the back and the palm read the same coordinates and need their own images).
//!
//! The maps are made when first asked for (a few hundred milliseconds for the built-in hand):
//! skinning, collision and the tests never need them; the glTF export and the viewer do.

use std::fmt;
use std::ops::Range;
use std::sync::OnceLock;

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

/// An 8-bit RGBA image, rows top to bottom (glTF's texture coordinates: v down).
#[derive(Clone, PartialEq, Eq)]
pub struct SkinImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `4 · width · height` bytes.
    pub rgba: Vec<u8>,
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
    /// Base colour, sRGB, opaque.
    pub albedo: SkinImage,
    /// Tangent-space normals, `0.5 · n + 0.5` per channel.
    pub normal: SkinImage,
}

/// The regions of a mesh's triangles and the maps of its two sides.
pub struct Appearance {
    /// Each region's triangles: a range of the mesh's flat index array (a multiple of three),
    /// in [`SurfaceRegion::ALL`] order, together the whole array.
    pub regions: Vec<(SurfaceRegion, Range<usize>)>,
    maps: OnceLock<[SkinMaps; 2]>,
    draw: Box<dyn Fn() -> [SkinMaps; 2] + Send + Sync>,
}

impl fmt::Debug for Appearance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Appearance").field("regions", &self.regions).field("maps drawn", &self.maps.get().is_some()).finish()
    }
}

impl Appearance {
    /// `regions` as [`Self::regions`]; `draw` makes the back's and the palm's maps, once, when
    /// first asked for.
    pub fn new(regions: Vec<(SurfaceRegion, Range<usize>)>, draw: impl Fn() -> [SkinMaps; 2] + Send + Sync + 'static) -> Self {
        Self { regions, maps: OnceLock::new(), draw: Box::new(draw) }
    }

    /// The back's maps (also the nails').
    pub fn back(&self) -> &SkinMaps {
        &self.maps()[0]
    }

    /// The palm's maps.
    pub fn palm(&self) -> &SkinMaps {
        &self.maps()[1]
    }

    fn maps(&self) -> &[SkinMaps; 2] {
        self.maps.get_or_init(|| (self.draw)())
    }
}
