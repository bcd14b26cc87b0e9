//! Which UVs a bake uses ([`choose_uvs`]): the model's own when every face has UV area and
//! no texel lies strictly inside two faces' UV triangles (a texel can hold one colour, so
//! mirrored or stacked islands lose paint), else a generated atlas ([`super::atlas`]). The
//! reason is kept for the user ([`UvChoice::reason`]).

use crate::convert::bake_uv::{UvCoverage, uv_coverage};

/// The own UVs, checked at the bake's texture size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OwnUvCheck {
    /// Faces of the mesh.
    pub faces: u64,
    /// How the UV triangles share the texture.
    pub coverage: UvCoverage,
}

impl OwnUvCheck {
    /// Whether a bake into these UVs keeps every face's colours.
    pub fn usable(&self) -> bool {
        self.faces > 0 && self.coverage.faces_without_uvs == 0 && self.coverage.overlapping_texels == 0
    }
}

/// Checks `corner_uvs` (one UV triangle per face) for a `size × size` bake.
pub fn check_own_uvs(corner_uvs: &[[[f32; 2]; 3]], size: u32) -> OwnUvCheck {
    OwnUvCheck { faces: corner_uvs.len() as u64, coverage: uv_coverage(corner_uvs, size) }
}

/// The UVs a bake uses and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UvChoice {
    /// The model's own UVs: every face has area, none overlap.
    Own(OwnUvCheck),
    /// The model's own UVs because they were asked for, whatever they are.
    OwnAsked(OwnUvCheck),
    /// Generated UVs, because the model has none (a packed file keeps none).
    NewNoSource,
    /// Generated UVs, because some faces of the model have no UV area (a scan: all of them).
    NewMissing(OwnUvCheck),
    /// Generated UVs, because the model's UV islands overlap.
    NewOverlapping(OwnUvCheck),
    /// Generated UVs, because they were asked for.
    NewAsked,
}

impl UvChoice {
    /// Whether the bake generates UVs.
    pub fn is_new(&self) -> bool {
        !matches!(self, UvChoice::Own(_) | UvChoice::OwnAsked(_))
    }

    /// The choice and its reason in a sentence, e.g. "new UVs: the model's UV islands
    /// overlap (118,139 texels lie in two faces' UVs), so a bake into them loses paint".
    pub fn reason(&self) -> String {
        match self {
            UvChoice::Own(check) => format!(
                "the model's own UVs: every face has UV area and no two overlap ({} texels in UV islands)",
                check.coverage.covered_texels
            ),
            UvChoice::OwnAsked(check) if check.usable() => {
                "the model's UVs, as asked (every face has UV area and no two overlap)".to_owned()
            }
            UvChoice::OwnAsked(check) => format!(
                "the model's UVs, as asked: {} of {} faces without UV area, {} texels strictly inside two faces' \
                 UVs (paint there is lost)",
                check.coverage.faces_without_uvs, check.faces, check.coverage.overlapping_texels
            ),
            UvChoice::NewNoSource => "new UVs: the document keeps no UVs (a packed file)".to_owned(),
            UvChoice::NewMissing(check) if check.coverage.faces_without_uvs == check.faces => {
                "new UVs: the model has no UVs (every face's UV triangle has no area)".to_owned()
            }
            UvChoice::NewMissing(check) => format!(
                "new UVs: {} of {} faces have no UV area, so their paint would be lost",
                check.coverage.faces_without_uvs, check.faces
            ),
            UvChoice::NewOverlapping(check) => format!(
                "new UVs: the model's UV islands overlap ({} texels lie strictly inside two faces' UVs), \
                 so a bake into them loses paint",
                check.coverage.overlapping_texels
            ),
            UvChoice::NewAsked => "new UVs, as asked".to_owned(),
        }
    }
}

/// The default choice for a `size × size` bake: `own` (the model's corner UVs, `None` when
/// the document keeps none) when they are usable ([`OwnUvCheck::usable`]), else new ones.
pub fn choose_uvs(own: Option<&[[[f32; 2]; 3]]>, size: u32) -> UvChoice {
    let Some(own) = own else {
        return UvChoice::NewNoSource;
    };
    let check = check_own_uvs(own, size);
    if check.coverage.faces_without_uvs > 0 || check.faces == 0 {
        UvChoice::NewMissing(check)
    } else if check.coverage.overlapping_texels > 0 {
        UvChoice::NewOverlapping(check)
    } else {
        UvChoice::Own(check)
    }
}
