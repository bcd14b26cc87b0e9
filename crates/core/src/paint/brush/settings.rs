//! Brush settings: the tool, falloff, blend mode, radius and resolution operation of a
//! stroke, and their validation.

use crate::colors::format::Rgba;
use crate::colors::layout::Resolution;

use super::error::BrushError;

/// How the brush weight falls off from the centre (`x = d / radius` in `[0, 1]`, `s = 1 − x`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Falloff {
    /// `s²(3 − 2s)`: smoothstep, flat at the centre and at the rim.
    #[default]
    Smooth,
    /// `s`.
    Linear,
    /// `1` everywhere inside.
    Constant,
    /// `s²`: a pointed centre.
    Sharp,
}

impl Falloff {
    /// Every falloff.
    pub const ALL: [Falloff; 4] = [Falloff::Smooth, Falloff::Linear, Falloff::Constant, Falloff::Sharp];

    /// The weight at `distance_fraction = d / radius`: in `[0, 1]`, and 0 outside the brush
    /// (`> 1`, or NaN).
    #[inline]
    pub fn weight(self, distance_fraction: f32) -> f32 {
        if distance_fraction.is_nan() || distance_fraction > 1.0 {
            return 0.0;
        }
        self.shape(1.0 - distance_fraction.max(0.0))
    }

    /// The weight as a function of `s = 1 − x` in `[0, 1]` (the formulas above).
    #[inline(always)]
    pub fn shape(self, s: f32) -> f32 {
        match self {
            Falloff::Smooth => s * s * (3.0 - 2.0 * s),
            Falloff::Linear => s,
            Falloff::Constant => 1.0,
            Falloff::Sharp => s * s,
        }
    }

    /// [`Falloff::weight`] of `sqrt(distance_fraction_sq)` (the square root taken in `f32`,
    /// and not at all for [`Falloff::Constant`]).
    #[inline]
    pub fn weight_of_squared(self, distance_fraction_sq: f32) -> f32 {
        if distance_fraction_sq.is_nan() || distance_fraction_sq > 1.0 {
            return 0.0;
        }
        if self == Falloff::Constant {
            return 1.0;
        }
        self.weight(distance_fraction_sq.max(0.0).sqrt())
    }

    /// The command-line name (`smooth`, `linear`, `constant`, `sharp`).
    pub fn name(self) -> &'static str {
        match self {
            Falloff::Smooth => "smooth",
            Falloff::Linear => "linear",
            Falloff::Constant => "constant",
            Falloff::Sharp => "sharp",
        }
    }

    /// Parses a name given by [`Falloff::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// How a painted colour combines with the sample's colour (linear light).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BlendMode {
    /// Towards the brush colour (alpha included).
    #[default]
    Mix,
    /// Adds the brush colour to RGB (alpha kept).
    Add,
    /// Multiplies RGB by the brush colour (alpha kept).
    Multiply,
    /// Towards the base snapshot (the colours when painting started).
    EraseToBase,
}

impl BlendMode {
    /// Every mode.
    pub const ALL: [BlendMode; 4] = [BlendMode::Mix, BlendMode::Add, BlendMode::Multiply, BlendMode::EraseToBase];

    /// The command-line name (`mix`, `add`, `multiply`, `erase`).
    pub fn name(self) -> &'static str {
        match self {
            BlendMode::Mix => "mix",
            BlendMode::Add => "add",
            BlendMode::Multiply => "multiply",
            BlendMode::EraseToBase => "erase",
        }
    }

    /// Parses a name given by [`BlendMode::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// `old · (1 − w) + target · w` with this mode's target, clamped by
    /// [`crate::colors::format::clamp_color`]; `base` is the base colour of the sample (used by
    /// [`BlendMode::EraseToBase`] only).
    #[inline]
    pub fn blend(self, old: Rgba, color: Rgba, base: Rgba, weight: f32) -> Rgba {
        let target = match self {
            BlendMode::Mix => color,
            BlendMode::Add => [old[0] + color[0], old[1] + color[1], old[2] + color[2], old[3]],
            BlendMode::Multiply => [old[0] * color[0], old[1] * color[1], old[2] * color[2], old[3]],
            BlendMode::EraseToBase => base,
        };
        let keep = 1.0 - weight;
        // Clamped to what the formats hold (`MAX_CHANNEL`, alpha 1): Add cannot make infinity.
        crate::colors::format::clamp_color([
            old[0] * keep + target[0] * weight,
            old[1] * keep + target[1] * weight,
            old[2] * keep + target[2] * weight,
            old[3] * keep + target[3] * weight,
        ])
    }
}

/// The brush size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BrushRadius {
    /// A radius on screen, converted to world units at each dab's hit depth.
    Pixels {
        /// Radius, pixels.
        radius_px: f64,
    },
    /// A radius in world units.
    World {
        /// Radius, world units.
        radius_world: f64,
    },
}

impl Default for BrushRadius {
    fn default() -> Self {
        BrushRadius::Pixels { radius_px: 30.0 }
    }
}

/// What the resolution brush does to each face it touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResolutionOp {
    /// Doubles `R` (up to the maximum).
    Raise,
    /// Halves `R` (down to 1).
    Lower,
    /// Sets `R`.
    Set(Resolution),
}

impl ResolutionOp {
    /// The new resolution of a face at `current`, or `None` when it stays.
    pub fn apply(self, current: Resolution) -> Option<Resolution> {
        let next = match self {
            ResolutionOp::Raise => current.doubled()?,
            ResolutionOp::Lower => current.halved()?,
            ResolutionOp::Set(r) => r,
        };
        (next != current).then_some(next)
    }
}

/// The active tool of a stroke.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tool {
    /// Paint colour with a blend mode.
    #[default]
    Paint,
    /// Blur: samples move towards the mean of their lattice neighbours.
    Blur,
    /// Change face resolutions.
    Resolution(ResolutionOp),
}

/// What a stroke point's pen pressure (`0..=1`, 1.0 from a mouse) feeds: each dab's radius
/// and / or strength is multiplied by the pressure where the dab is placed (interpolated
/// between the stroke's points).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PressureResponse {
    /// The radius follows the pressure (a dab at `p` has `p ·` the radius).
    pub radius: bool,
    /// The strength follows the pressure (a dab at `p` has `p ·` the strength).
    pub strength: bool,
}

impl Default for PressureResponse {
    /// Radius follows pressure (the common default of painting programs), strength does not.
    fn default() -> Self {
        PressureResponse { radius: true, strength: false }
    }
}

impl PressureResponse {
    /// Neither follows the pressure.
    pub const NONE: PressureResponse = PressureResponse { radius: false, strength: false };

    /// The command-line name (`none`, `radius`, `strength`, `both`).
    pub fn name(self) -> &'static str {
        match (self.radius, self.strength) {
            (false, false) => "none",
            (true, false) => "radius",
            (false, true) => "strength",
            (true, true) => "both",
        }
    }

    /// Parses a name given by [`PressureResponse::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "none" => Some(Self::NONE),
            "radius" => Some(PressureResponse { radius: true, strength: false }),
            "strength" => Some(PressureResponse { radius: false, strength: true }),
            "both" => Some(PressureResponse { radius: true, strength: true }),
            _ => None,
        }
    }

    /// The radius and strength factors of a dab at `pressure` (clamped to `0..=1`; NaN is 0).
    pub fn factors(self, pressure: f32) -> (f64, f32) {
        let p = if pressure.is_nan() { 0.0 } else { pressure.clamp(0.0, 1.0) };
        (if self.radius { f64::from(p) } else { 1.0 }, if self.strength { p } else { 1.0 })
    }
}

/// One point of a stroke: the cursor in pixels and the pen pressure there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrokePoint {
    /// Cursor position, pixels (origin top-left).
    pub px: [f64; 2],
    /// Pen pressure, `0..=1` (1.0 from a mouse).
    pub pressure: f32,
}

impl StrokePoint {
    /// A point at `px` with full pressure (a mouse, or a pen pressed fully).
    pub fn mouse(px: [f64; 2]) -> Self {
        StrokePoint { px, pressure: 1.0 }
    }

    /// Checks the pressure is a number in `0..=1`.
    pub fn validate(&self) -> Result<(), BrushError> {
        if (0.0..=1.0).contains(&self.pressure) {
            Ok(())
        } else {
            Err(BrushError::InvalidSetting(format!("pressure {} is not in 0..=1", self.pressure)))
        }
    }
}

impl From<[f64; 2]> for StrokePoint {
    fn from(px: [f64; 2]) -> Self {
        StrokePoint::mouse(px)
    }
}

/// The largest `R` resolution-follows-the-brush raises a face to (the editor's setting).
pub const FOLLOW_BRUSH_MAX_RESOLUTION: Resolution = Resolution::SIXTY_FOUR;

/// The sample spacing a hard brush raises its faces to, as a fraction of the radius: at most
/// `radius / HARD_EDGE_SPACINGS_PER_RADIUS` (the knee of docs/PAINT_MODE.md's "Hard edges"
/// table: 16 per radius at `R` up to 64 brings a hard stroke's rim from 21 to 36 dB on the
/// Duck; 32 adds 0.4 dB for half as many samples again).
pub const HARD_EDGE_SPACINGS_PER_RADIUS: f64 = 16.0;

/// What a hard brush (the paint tool with [`Falloff::Constant`]) does so that its rim is not
/// a staircase of samples: raise the faces under it (the default, chosen with `meshpaint bench
/// brush-edge`, docs/PAINT_MODE.md) and / or anti-alias the rim over the sample spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HardEdges {
    /// Before each hard dab, every face under it facing the eye whose sample spacing (longest
    /// edge / R) is coarser than `radius / spacings_per_radius` is raised to the smallest
    /// power of two that resolves it, up to this `R`, within the budget (a face the budget
    /// refuses keeps its `R`; the stroke goes on). Independent of
    /// [`BrushSettings::follow_resolution`], so textured documents too. `None`: off.
    pub raise_to: Option<Resolution>,
    /// See `raise_to`.
    pub spacings_per_radius: f64,
    /// Anti-alias the rim over this many sample spacings (the median spacing of the dab's
    /// faces): the weight ramps from the strength to 0 across the sphere, ½ on it, so one
    /// dab's paint integrates to its disc's area; within a stroke the rim keeps the largest
    /// coverage of its dabs instead of building up. `None`: off.
    pub antialias_spacings: Option<f64>,
}

impl Default for HardEdges {
    /// Raise to [`FOLLOW_BRUSH_MAX_RESOLUTION`] at [`HARD_EDGE_SPACINGS_PER_RADIUS`], no
    /// anti-aliasing.
    fn default() -> Self {
        HardEdges {
            raise_to: Some(FOLLOW_BRUSH_MAX_RESOLUTION),
            spacings_per_radius: HARD_EDGE_SPACINGS_PER_RADIUS,
            antialias_spacings: None,
        }
    }
}

impl HardEdges {
    /// Neither: every sample inside the sphere painted at full strength, none outside, at
    /// the faces' own `R` (the behaviour before issue 43).
    pub const SAMPLED: HardEdges =
        HardEdges { raise_to: None, spacings_per_radius: HARD_EDGE_SPACINGS_PER_RADIUS, antialias_spacings: None };
}

/// Brush settings. A stroke uses the settings it began with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrushSettings {
    /// The tool.
    pub tool: Tool,
    /// Paint colour, linear light, straight alpha.
    pub color: Rgba,
    /// Blend mode of the paint tool.
    pub blend: BlendMode,
    /// Brush radius.
    pub radius: BrushRadius,
    /// Weight at the centre, `0..=1`.
    pub strength: f32,
    /// Falloff curve.
    pub falloff: Falloff,
    /// Distance between dabs along a stroke, percent of the radius (`> 0`).
    pub spacing_percent: f64,
    /// Paint only samples visible from the eye.
    pub occlusion: bool,
    /// Paint only samples on faces facing the eye.
    pub backface_culling: bool,
    /// Also paint mirrored across the plane `x =` centre of the mesh bounds.
    pub mirror_x: bool,
    /// Resolution follows the brush (paint and blur): before a dab, each face under it whose
    /// sample spacing (longest edge / R) is coarser than a quarter of the radius is raised
    /// to the smallest power of two that resolves it, `R ≥ 4 · longest edge / radius`,
    /// capped at this value (`None`: off). Never lowers a face.
    pub follow_resolution: Option<Resolution>,
    /// What the stroke points' pen pressure feeds (nothing changes at pressure 1.0).
    pub pressure: PressureResponse,
}

/// The resolution a face needs to resolve a brush of `radius_world` (sample spacing at most a
/// quarter of the radius along its longest edge), capped at `max`.
pub fn resolution_for_brush(longest_edge: f64, radius_world: f64, max: Resolution) -> Resolution {
    resolution_for_spacing(longest_edge, radius_world / 4.0, max)
}

/// The smallest power-of-two resolution whose sample spacing along the longest edge
/// (`longest_edge / R`) is at most `spacing`, capped at `max`.
pub fn resolution_for_spacing(longest_edge: f64, spacing: f64, max: Resolution) -> Resolution {
    let wanted = longest_edge / spacing;
    if !(wanted.is_finite() && wanted > 1.0) {
        return if wanted.is_finite() { Resolution::ONE } else { max };
    }
    let log2 = (wanted.ceil() as u64).next_power_of_two().trailing_zeros().min(max.log2());
    Resolution::from_log2(log2).unwrap_or(max)
}

impl Default for BrushSettings {
    fn default() -> Self {
        BrushSettings {
            tool: Tool::Paint,
            color: [1.0, 0.0, 0.0, 1.0],
            blend: BlendMode::Mix,
            radius: BrushRadius::default(),
            strength: 1.0,
            falloff: Falloff::Smooth,
            spacing_percent: 10.0,
            occlusion: true,
            backface_culling: true,
            mirror_x: false,
            follow_resolution: None,
            pressure: PressureResponse::default(),
        }
    }
}

impl BrushSettings {
    /// Checks every value is in range.
    pub fn validate(&self) -> Result<(), BrushError> {
        let bad = |message: String| Err(BrushError::InvalidSetting(message));
        if !(0.0..=1.0).contains(&self.strength) {
            return bad(format!("strength {} is not in 0..=1", self.strength));
        }
        if !(self.spacing_percent.is_finite() && self.spacing_percent > 0.0) {
            return bad(format!("spacing {} % is not a positive number", self.spacing_percent));
        }
        match self.radius {
            BrushRadius::Pixels { radius_px } if !(radius_px.is_finite() && radius_px > 0.0) => {
                bad(format!("radius {radius_px} px is not a positive number"))
            }
            BrushRadius::World { radius_world } if !(radius_world.is_finite() && radius_world > 0.0) => {
                bad(format!("radius {radius_world} is not a positive number"))
            }
            _ if !self.color.iter().all(|c| c.is_finite()) => bad("the colour is not finite".into()),
            _ => Ok(()),
        }
    }

    pub(super) fn label(&self) -> &'static str {
        match self.tool {
            Tool::Paint => "paint stroke",
            Tool::Blur => "blur stroke",
            Tool::Resolution(_) => "resolution stroke",
        }
    }
}
