//! Painting on the store: the colour, blur and resolution brushes, eyedropper and fill,
//! shared by the editor's paint mode, `meshpaint paint` (headless stroke replay) and
//! `meshpaint bench paint`.
//!
//! # How the editor drives it
//!
//! ```text
//! enter paint mode:  painter = Painter::new(&positions); history = UndoHistory::new(cap);
//!                    base = store.clone()            (for Erase-to-base)
//! button down:       painter.begin_stroke(&view, &mut store, &mut history, cursor_px)
//! pointer moved:     painter.stroke_to(&view, &mut store, &mut history, cursor_px)
//! button up:         painter.end_stroke(&mut history)         (closes the undo step)
//! every frame:       store.take_dirty() → upload the dirty elements
//! Ctrl+Z / Ctrl+Y:   history.undo(&mut store) / history.redo(&mut store)
//! ```
//!
//! [`PaintView`] bundles what the pointer is over: positions, the picking BVH, the camera and
//! the viewport size in pixels, and the base snapshot. Every call leaves its changes marked
//! dirty in the store ([`ColorStore::take_dirty`]) and recorded in the open undo step.
//!
//! # A stroke
//!
//! Cursor positions arrive as pixel coordinates (origin top-left, as
//! [`OrbitCamera::ray_through_pixel`] takes them). Between two successive positions dabs
//! are placed along the segment *in screen space* every `spacing_percent` % of the brush
//! radius in pixels (the remainder carries over to the next segment), so a fast stroke
//! whose events are far apart still paints a continuous band (ArmorPaint issue #937). Each
//! dab casts the pixel's ray into the BVH; a miss places no dab. The dab's world radius is
//! `radius_px` times the world size of a pixel at the hit's depth (or `radius_world`).
//!
//! # A dab
//!
//! 1. The faces with a point inside the brush sphere come from
//!    [`MeshBvh::faces_in_sphere`] (exact closest-point test), for the mirrored sphere too
//!    when X-mirror is on (plane `x =` centre of the mesh bounds; the mirrored dab is seen
//!    from the mirrored eye, so occlusion and culling mirror as well).
//! 2. Backface culling (optional) keeps, per sphere, the faces whose front (counter-clockwise)
//!    side faces the eye; a shared vertex or edge sample counts as front if any of its faces
//!    in the dab does.
//! 3. Every stored sample inside is updated exactly once per dab: interior samples per face,
//!    edge samples (all `R_e − 1` of them, at the edge's own resolution) and vertices once per
//!    element via per-element stamps (no hashing). Sample positions are computed from the
//!    corners on the fly; each lattice row's intersection with the sphere is solved in closed
//!    form so rows are only walked where the sphere is.
//! 4. A sample at distance `d` gets weight `w = strength · falloff(d / radius)` (the largest
//!    over the spheres that see it); with occlusion on, only if the segment from the eye to
//!    the sample hits nothing before the sample ([`MeshBvh::cast`]).
//! 5. Blending is in linear light: `new = old · (1 − w) + target · w` with target = the brush
//!    colour (Mix), `old + colour` (Add, RGB), `old × colour` (Multiply, RGB) or the base
//!    snapshot's colour at the sample (Erase to base).
//!
//! The blur brush moves each sample towards the mean of its lattice neighbours (the six
//! neighbours in every face whose lattice contains it, at that face's resolution) by `w`,
//! computed from the colours before the dab. The resolution brush raises, lowers or sets `R`
//! of every face whose triangle intersects the brush sphere, each face at most once per
//! stroke, resampling as [`ColorStore::set_face_resolution`] defines.
//!
//! # Speed
//!
//! `meshpaint bench paint` on Bunny144k at R = 8 (4.6 M samples), release build, one thread,
//! on a shared 2-core machine (best of 200 dabs; the median is within 2 % for the small and
//! medium brushes, up to 25 % lower for the large one):
//!
//! | brush | samples / dab | dab | samples / s |
//! |---|---|---|---|
//! | paint, later dab of a stroke (old colours recorded) | 1 k / 10 k / 100 k | 26 / 178 / 1640 µs | 38 / 56 / 61 M |
//! | paint, first dab of a stroke (records all) | 1 k / 10 k / 100 k | 30 / 223 / 3260 µs | 33 / 45 / 31 M |
//! | paint + backface culling | 10 k / 100 k | 179 / 1760 µs | 56 / 57 M |
//! | paint + culling + occlusion (one BVH ray per sample) | 1 k / 10 k | 282 / 3420 µs | 3.5 / 2.9 M |
//! | blur | 1 k / 10 k | 138 / 1500 µs | 7.2 / 6.7 M |
//!
//! The sphere query is a small share (1.9 / 8.5 / 75 µs for 55 / 356 / 3256 faces). The hot
//! loop allocates nothing and hashes nothing: positions come from the corners in `f64`, the
//! row bounds from a quadratic (skipped for faces entirely inside), the weight from one
//! `f32` square root, the undo record from a bit test. What remains per sample is mostly the
//! store's own `get`/`set` (two bounds-checked lookups and a dirty flag each); the first dab
//! of a stroke also pays for fresh undo memory (page faults). Blender's 2016 vertex paint
//! managed about 6 M vertices/s.

use glam::DVec3;
use thiserror::Error;

use crate::camera::OrbitCamera;
use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::{ColorStore, SampleRef, StoreError};
use crate::packing::sampler::{self, Filter};
use crate::paint::picking::{MeshBvh, RayHit};
use crate::paint::undo::{StepSummary, UndoError, UndoHistory};

/// Smallest distance between dabs along a stroke, pixels.
pub const MIN_SPACING_PX: f64 = 0.25;
/// Most dabs one [`Painter::stroke_to`] call places (a guard against absurd spacing).
pub const MAX_DABS_PER_SEGMENT: usize = 100_000;
/// Occlusion tolerance: a hit counts as hiding a sample only if it is nearer than
/// `distance · (1 − OCCLUSION_TOLERANCE)` (the sample's own face is hit at the distance).
pub const OCCLUSION_TOLERANCE: f64 = 1e-6;

/// Errors of the brushes.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BrushError {
    /// Erase-to-base without a base snapshot.
    #[error("erase to base needs the base colours (the snapshot taken when painting started)")]
    NoBase,
    /// The base snapshot belongs to another mesh.
    #[error("the base snapshot has {base_faces} faces but the mesh has {faces}")]
    BaseMismatch {
        /// Faces in the base.
        base_faces: u32,
        /// Faces in the store.
        faces: u32,
    },
    /// A brush setting out of range.
    #[error("invalid brush setting: {0}")]
    InvalidSetting(String),
    /// The positions do not match the store's mesh.
    #[error("{positions} positions for a mesh with {vertices} vertices")]
    PositionCount {
        /// Positions given.
        positions: usize,
        /// Vertices in the mesh.
        vertices: u32,
    },
    /// A face id past the face count.
    #[error("face {0} does not exist")]
    NoSuchFace(u32),
    /// Recording the undo step failed.
    #[error(transparent)]
    Undo(#[from] UndoError),
    /// The store refused a change.
    #[error(transparent)]
    Store(#[from] StoreError),
}

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
        let s = 1.0 - distance_fraction.max(0.0);
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

    /// `old · (1 − w) + target · w` with this mode's target; `base` is the base colour of
    /// the sample (used by [`BlendMode::EraseToBase`] only).
    #[inline]
    pub fn blend(self, old: Rgba, color: Rgba, base: Rgba, weight: f32) -> Rgba {
        let target = match self {
            BlendMode::Mix => color,
            BlendMode::Add => [old[0] + color[0], old[1] + color[1], old[2] + color[2], old[3]],
            BlendMode::Multiply => [old[0] * color[0], old[1] * color[1], old[2] * color[2], old[3]],
            BlendMode::EraseToBase => base,
        };
        let keep = 1.0 - weight;
        [
            old[0] * keep + target[0] * weight,
            old[1] * keep + target[1] * weight,
            old[2] * keep + target[2] * weight,
            old[3] * keep + target[3] * weight,
        ]
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

    fn label(&self) -> &'static str {
        match self.tool {
            Tool::Paint => "paint stroke",
            Tool::Blur => "blur stroke",
            Tool::Resolution(_) => "resolution stroke",
        }
    }
}

/// What the pointer paints on: the mesh, its BVH, the camera and the viewport.
#[derive(Debug, Clone, Copy)]
pub struct PaintView<'a> {
    /// Vertex positions (world space), one per store vertex.
    pub positions: &'a [[f32; 3]],
    /// The picking BVH built over `positions` and the store's triangles.
    pub bvh: &'a MeshBvh,
    /// The camera.
    pub camera: &'a OrbitCamera,
    /// Viewport width and height, pixels.
    pub viewport_px: [u32; 2],
    /// The colours when painting started (for Erase to base); may have other resolutions.
    pub base: Option<&'a ColorStore>,
}

impl PaintView<'_> {
    /// The ray through pixel `cursor_px` and its nearest hit.
    pub fn pick(&self, cursor_px: [f64; 2]) -> Option<RayHit> {
        let [width, height] = self.viewport_px;
        let (origin, direction) = self.camera.ray_through_pixel(cursor_px[0], cursor_px[1], width, height);
        self.bvh.cast(origin, direction, f64::INFINITY)
    }

    /// World units per pixel at the depth of `point` (perspective).
    pub fn world_per_px_at(&self, point: DVec3) -> f64 {
        let forward = -self.camera.eye_direction();
        let depth = (point - self.camera.eye()).dot(forward).max(0.0);
        2.0 * depth * (self.camera.fov_y_degrees.to_radians() * 0.5).tan() / f64::from(self.viewport_px[1].max(1))
    }
}

/// One dab placed by a stroke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dab {
    /// The cursor position it was placed at, pixels.
    pub cursor_px: [f64; 2],
    /// Brush centre: the ray's hit, world space.
    pub center_world: [f64; 3],
    /// Brush radius, world units.
    pub radius_world: f64,
    /// The face hit.
    pub face: u32,
}

/// Counts of one dab.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DabStats {
    /// Faces the BVH query returned (both spheres with mirror).
    pub faces: u32,
    /// Samples inside the footprint with a positive weight (each updated once).
    pub samples_covered: u64,
    /// Samples whose colour changed.
    pub samples_changed: u64,
    /// Faces whose resolution changed.
    pub faces_resized: u32,
}

impl DabStats {
    fn add(&mut self, other: DabStats) {
        self.faces += other.faces;
        self.samples_covered += other.samples_covered;
        self.samples_changed += other.samples_changed;
        self.faces_resized += other.faces_resized;
    }
}

/// What one stroke call did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StrokeUpdate {
    /// Dabs placed (cursor positions over the mesh).
    pub dabs: Vec<Dab>,
    /// Totals over the dabs.
    pub stats: DabStats,
}

/// The state of a stroke in progress.
#[derive(Debug, Clone, Copy)]
struct StrokeState {
    settings: BrushSettings,
    last_cursor_px: [f64; 2],
    /// Screen distance travelled since the last dab position.
    since_dab_px: f64,
    /// World units per pixel at the last hit.
    world_per_px: Option<f64>,
}

/// Per-element scratch, sized to the mesh, reused across dabs (no allocation per sample).
#[derive(Debug, Clone, Default)]
struct Scratch {
    faces: Vec<u32>,
    face_masks: Vec<u8>,
    vertex_stamp: Vec<u32>,
    vertex_mask: Vec<u8>,
    edge_stamp: Vec<u32>,
    edge_mask: Vec<u8>,
    /// Even; `stamp` marks "mask accumulated in this dab", `stamp + 1` "processed".
    stamp: u32,
    blur: Vec<BlurTerm>,
    /// Resolution tool: the stroke number in which each face was last changed.
    face_stroke: Vec<u32>,
    stroke: u32,
}

impl Scratch {
    fn fit(&mut self, store: &ColorStore) {
        let topology = store.topology();
        let (v, e, f) =
            (topology.vertex_count as usize, topology.edge_count() as usize, topology.face_count() as usize);
        if self.vertex_stamp.len() != v || self.edge_stamp.len() != e || self.face_stroke.len() != f {
            self.vertex_stamp = vec![0; v];
            self.vertex_mask = vec![0; v];
            self.edge_stamp = vec![0; e];
            self.edge_mask = vec![0; e];
            self.face_stroke = vec![0; f];
            self.stamp = 0;
            self.stroke = 0;
        }
    }

    fn next_stamp(&mut self) -> u32 {
        self.stamp = self.stamp.wrapping_add(2);
        if self.stamp == 0 {
            self.vertex_stamp.fill(0);
            self.edge_stamp.fill(0);
            self.stamp = 2;
        }
        self.stamp
    }

    fn next_stroke(&mut self) -> u32 {
        self.stroke = self.stroke.wrapping_add(1);
        if self.stroke == 0 {
            self.face_stroke.fill(0);
            self.stroke = 1;
        }
        self.stroke
    }
}

/// One sample's blur contribution from one face.
#[derive(Debug, Clone, Copy)]
struct BlurTerm {
    sample: SampleRef,
    sum: Rgba,
    count: u32,
    weight: f32,
}

/// Where the brush reaches and how strongly: the weight of a point and, for a lattice row
/// `a + b·k`, the range of `k` that can have a positive weight.
trait Coverage {
    /// The inclusive range of `k` in `lo..=hi` where `a + b·k` may be covered (a superset:
    /// [`Coverage::weight`] decides).
    fn row_range(&self, a: DVec3, b: DVec3, lo: u32, hi: u32, mask: u8) -> Option<(u32, u32)>;
    /// Weight at `p` for the spheres in `mask`.
    fn weight(&self, p: DVec3, mask: u8) -> f32;
    /// Whether every point of the segment or triangle with these corners is inside a sphere
    /// in `mask` (its rows then need no [`Coverage::row_range`]).
    fn covers(&self, corners: &[DVec3], mask: u8) -> bool;
}

/// The brush spheres of one dab (one, or two with mirror).
#[derive(Debug, Clone, Copy)]
struct Footprint<'a> {
    centers: [DVec3; 2],
    eyes: [DVec3; 2],
    count: usize,
    radius_sq: f64,
    inv_radius: f64,
    strength: f32,
    falloff: Falloff,
    occlusion: Option<&'a MeshBvh>,
}

impl<'a> Footprint<'a> {
    /// The footprint of spheres at `centers[..count]` seen from `eyes[..count]`.
    #[allow(clippy::too_many_arguments)]
    fn new(
        centers: [DVec3; 2],
        eyes: [DVec3; 2],
        count: usize,
        radius: f64,
        strength: f32,
        falloff: Falloff,
        occlusion: Option<&'a MeshBvh>,
    ) -> Self {
        Footprint {
            centers,
            eyes,
            count: count.clamp(1, 2),
            radius_sq: radius * radius,
            inv_radius: 1.0 / radius,
            strength,
            falloff,
            occlusion,
        }
    }

    /// The weight for one sphere and no occlusion: the common case, kept small to inline.
    #[inline(always)]
    fn weight_single(&self, p: DVec3) -> f32 {
        let d2 = (p - self.centers[0]).length_squared();
        if d2.is_nan() || d2 > self.radius_sq {
            return 0.0;
        }
        self.strength * self.falloff.weight_of_squared((d2 * self.inv_radius * self.inv_radius) as f32)
    }

    /// [`Coverage::weight`] with mirror or occlusion.
    #[inline(never)]
    fn weight_general(&self, p: DVec3, mask: u8) -> f32 {
        let mut best = 0.0f32;
        for k in 0..self.count {
            if mask & (1 << k) == 0 {
                continue;
            }
            let d2 = (p - self.centers[k]).length_squared();
            if d2.is_nan() || d2 > self.radius_sq {
                continue;
            }
            let w = self.strength * self.falloff.weight_of_squared((d2 * self.inv_radius * self.inv_radius) as f32);
            if w <= best {
                continue;
            }
            if let Some(bvh) = self.occlusion
                && !visible(bvh, self.eyes[k], p)
            {
                continue;
            }
            best = w;
        }
        best
    }
}

impl Coverage for Footprint<'_> {
    #[inline]
    fn row_range(&self, a: DVec3, b: DVec3, lo: u32, hi: u32, mask: u8) -> Option<(u32, u32)> {
        if lo > hi {
            return None;
        }
        let bb = b.length_squared();
        let mut range: Option<(f64, f64)> = None;
        for k in 0..self.count {
            if mask & (1 << k) == 0 {
                continue;
            }
            let d = a - self.centers[k];
            let db = d.dot(b);
            let excess = d.length_squared() - self.radius_sq;
            let (k0, k1) = if bb > 0.0 {
                let disc = db * db - bb * excess;
                if disc.is_nan() || disc < 0.0 {
                    continue;
                }
                let root = disc.sqrt();
                ((-db - root) / bb, (-db + root) / bb)
            } else if excess <= 0.0 {
                (f64::from(lo), f64::from(hi))
            } else {
                continue;
            };
            range = Some(range.map_or((k0, k1), |(r0, r1)| (r0.min(k0), r1.max(k1))));
        }
        let (k0, k1) = range?;
        let start = k0.floor().max(f64::from(lo));
        let end = k1.ceil().min(f64::from(hi));
        if start.is_nan() || end.is_nan() || start > end {
            return None;
        }
        Some((start as u32, end as u32))
    }

    #[inline(always)]
    fn weight(&self, p: DVec3, mask: u8) -> f32 {
        if self.count == 1 && self.occlusion.is_none() {
            return if mask & 1 != 0 { self.weight_single(p) } else { 0.0 };
        }
        self.weight_general(p, mask)
    }

    #[inline]
    fn covers(&self, corners: &[DVec3], mask: u8) -> bool {
        (0..self.count).any(|k| {
            mask & (1 << k) != 0 && corners.iter().all(|&c| (c - self.centers[k]).length_squared() <= self.radius_sq)
        })
    }
}

/// Everything, with one weight (fill).
#[derive(Debug, Clone, Copy)]
struct Everywhere(f32);

impl Coverage for Everywhere {
    fn row_range(&self, _: DVec3, _: DVec3, lo: u32, hi: u32, _: u8) -> Option<(u32, u32)> {
        (lo <= hi).then_some((lo, hi))
    }

    fn weight(&self, _: DVec3, _: u8) -> f32 {
        self.0
    }

    fn covers(&self, _: &[DVec3], _: u8) -> bool {
        true
    }
}

/// Whether nothing lies on the segment from `eye` to `point` (except near `point` itself).
pub fn visible(bvh: &MeshBvh, eye: DVec3, point: DVec3) -> bool {
    let to = point - eye;
    let distance = to.length();
    if distance.is_nan() || distance <= 0.0 {
        return true;
    }
    bvh.cast(eye, to / distance, distance * (1.0 - OCCLUSION_TOLERANCE)).is_none()
}

/// Whether two colours differ in any bit (one 128-bit comparison).
#[inline(always)]
fn differs(a: Rgba, b: Rgba) -> bool {
    bytemuck::cast::<Rgba, u128>(a) != bytemuck::cast::<Rgba, u128>(b)
}

fn position(positions: &[[f32; 3]], v: u32) -> DVec3 {
    positions.get(v as usize).map_or(DVec3::ZERO, |p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
}

/// What a paint dab writes.
#[derive(Debug, Clone, Copy)]
struct PaintOp<'a> {
    blend: BlendMode,
    color: Rgba,
    /// Required for Erase to base.
    base: Option<&'a ColorStore>,
}

impl PaintOp<'_> {
    /// The base colour at lattice point `(i, j)` of `face` at resolution `r`, sampled
    /// linearly when the base holds the face at another resolution.
    fn base_on_face(&self, face: u32, r: Resolution, i: u32, j: u32, fallback: Rgba) -> Rgba {
        let Some(base) = self.base else {
            return fallback;
        };
        let bary = layout::sample_barycentric(r, i, j).map(|w| w as f32);
        sampler::sample(base, face, bary, Filter::Linear, 0).unwrap_or(fallback)
    }
}

/// Counts of one element's update.
#[derive(Debug, Clone, Copy, Default)]
struct ElementCounts {
    covered: u64,
    changed: u64,
}

/// Paints the interior samples of `face` (mask `mask`).
#[allow(clippy::too_many_arguments)]
fn paint_interior<C: Coverage>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    store: &mut ColorStore,
    history: &mut UndoHistory,
    face: u32,
    mask: u8,
) -> ElementCounts {
    let mut counts = ElementCounts::default();
    let (Some(r), Some(corners)) = (store.face_resolution(face), store.topology().face_vertices.get(face as usize))
    else {
        return counts;
    };
    let res = r.get();
    if res < 3 {
        return counts;
    }
    let [p0, p1, p2] = corners.map(|v| position(positions, v));
    let inv = 1.0 / f64::from(res);
    let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
    let len = store.interior_samples(face).len();
    let mut log = history.interior_log(face, len);
    let base_same = op.base.and_then(|b| (b.face_resolution(face) == Some(r)).then(|| b.interior_samples(face)));
    let whole = coverage.covers(&[p0, p1, p2], mask);
    for i in 1..res - 1 {
        let a = p0 + e1 * f64::from(i);
        let range = if whole { Some((1, res - 1 - i)) } else { coverage.row_range(a, e2, 1, res - 1 - i, mask) };
        let Some((j0, j1)) = range else {
            continue;
        };
        let row_start = (i - 1) * (2 * res - 2 - i) / 2;
        for j in j0..=j1 {
            let w = coverage.weight(a + e2 * f64::from(j), mask);
            if w <= 0.0 {
                continue;
            }
            let offset = row_start + j - 1;
            let Some(&old) = store.interior_samples(face).get(offset as usize) else {
                continue;
            };
            counts.covered += 1;
            let base = match (op.blend, base_same) {
                (BlendMode::EraseToBase, Some(base)) => base.get(offset as usize).copied().unwrap_or(old),
                (BlendMode::EraseToBase, None) => op.base_on_face(face, r, i, j, old),
                _ => old,
            };
            let new = op.blend.blend(old, op.color, base, w);
            if differs(new, old) {
                log.record(offset, old);
                store.set(SampleRef::Interior { face, offset }, new);
                counts.changed += 1;
            }
        }
    }
    counts
}

/// Paints the samples of `edge` (at the edge's resolution).
#[allow(clippy::too_many_arguments)]
fn paint_edge<C: Coverage>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    store: &mut ColorStore,
    history: &mut UndoHistory,
    edge: u32,
    mask: u8,
) -> ElementCounts {
    let mut counts = ElementCounts::default();
    let (Some(r), Some(&[lo, hi])) = (store.edge_resolution(edge), store.topology().edge_vertices.get(edge as usize))
    else {
        return counts;
    };
    let res = r.get();
    if res < 2 {
        return counts;
    }
    let a = position(positions, lo);
    let end = position(positions, hi);
    let b = (end - a) / f64::from(res);
    let range =
        if coverage.covers(&[a, end], mask) { Some((1, res - 1)) } else { coverage.row_range(a, b, 1, res - 1, mask) };
    let Some((k0, k1)) = range else {
        return counts;
    };
    let mut log = history.edge_log(edge, store.edge_samples(edge).len());
    let base_same = op.base.and_then(|base| (base.edge_resolution(edge) == Some(r)).then(|| base.edge_samples(edge)));
    for k in k0..=k1 {
        let w = coverage.weight(a + b * f64::from(k), mask);
        if w <= 0.0 {
            continue;
        }
        let offset = k - 1;
        let Some(&old) = store.edge_samples(edge).get(offset as usize) else {
            continue;
        };
        counts.covered += 1;
        let base = match (op.blend, base_same) {
            (BlendMode::EraseToBase, Some(base)) => base.get(offset as usize).copied().unwrap_or(old),
            (BlendMode::EraseToBase, None) => base_on_edge(op, store, edge, r, k, old),
            _ => old,
        };
        let new = op.blend.blend(old, op.color, base, w);
        if differs(new, old) {
            log.record(offset, old);
            store.set(SampleRef::Edge { edge, offset }, new);
            counts.changed += 1;
        }
    }
    counts
}

/// The base colour at position `k` (from the lower vertex) of `edge` at resolution `r`, sampled
/// on the edge's first face when the base holds the edge at another resolution.
fn base_on_edge(op: &PaintOp, store: &ColorStore, edge: u32, r: Resolution, k: u32, fallback: Rgba) -> Rgba {
    let Some(base) = op.base else {
        return fallback;
    };
    let Some(&(face, face_edge)) = store.topology().faces_of_edge(edge).first() else {
        return fallback;
    };
    let t = k as f32 / r.get() as f32;
    let reversed = store.topology().is_reversed(face, usize::from(face_edge));
    let mut bary = [0.0f32; 3];
    let (start, end) = (usize::from(face_edge), (usize::from(face_edge) + 1) % 3);
    // Not reversed: the face edge starts at the lower vertex.
    let along = if reversed { 1.0 - t } else { t };
    bary[start] = 1.0 - along;
    bary[end] = along;
    sampler::sample(base, face, bary, Filter::Linear, 0).unwrap_or(fallback)
}

/// Paints vertex `v` (mask `mask`).
fn paint_vertex<C: Coverage>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    store: &mut ColorStore,
    history: &mut UndoHistory,
    v: u32,
    mask: u8,
) -> ElementCounts {
    let mut counts = ElementCounts::default();
    let w = coverage.weight(position(positions, v), mask);
    if w <= 0.0 {
        return counts;
    }
    let Some(old) = store.vertex_color(v) else {
        return counts;
    };
    counts.covered = 1;
    let base = match op.blend {
        BlendMode::EraseToBase => op.base.and_then(|base| base.vertex_color(v)).unwrap_or(old),
        _ => old,
    };
    let new = op.blend.blend(old, op.color, base, w);
    if differs(new, old) {
        history.vertex_log().record(v, old);
        store.set(SampleRef::Vertex(v), new);
        counts.changed = 1;
    }
    counts
}

/// Paints every sample of the faces in `scratch.faces` (masks in `scratch.face_masks`), each
/// shared vertex and edge once.
fn paint_faces<C: Coverage>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    store: &mut ColorStore,
    history: &mut UndoHistory,
    scratch: &mut Scratch,
) -> DabStats {
    let stamp = accumulate_masks(store, scratch);
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    let mut add = |counts: ElementCounts| {
        stats.samples_covered += counts.covered;
        stats.samples_changed += counts.changed;
    };
    let faces = std::mem::take(&mut scratch.faces);
    for (&face, &mask) in faces.iter().zip(&scratch.face_masks) {
        if mask != 0 {
            add(paint_interior(coverage, op, positions, store, history, face, mask));
        }
        let Some((&edges, &corners)) =
            store.topology().face_edges.get(face as usize).zip(store.topology().face_vertices.get(face as usize))
        else {
            continue;
        };
        for edge in edges {
            let e = edge as usize;
            if scratch.edge_stamp[e] == stamp {
                scratch.edge_stamp[e] = stamp + 1;
                let mask = scratch.edge_mask[e];
                if mask != 0 {
                    add(paint_edge(coverage, op, positions, store, history, edge, mask));
                }
            }
        }
        for v in corners {
            let i = v as usize;
            if scratch.vertex_stamp[i] == stamp {
                scratch.vertex_stamp[i] = stamp + 1;
                let mask = scratch.vertex_mask[i];
                if mask != 0 {
                    add(paint_vertex(coverage, op, positions, store, history, v, mask));
                }
            }
        }
    }
    scratch.faces = faces;
    stats
}

/// Pass 1 of a dab: ORs the face masks into the faces' vertices and edges. Returns the stamp.
fn accumulate_masks(store: &ColorStore, scratch: &mut Scratch) -> u32 {
    let stamp = scratch.next_stamp();
    let topology = store.topology();
    for (&face, &mask) in scratch.faces.iter().zip(&scratch.face_masks) {
        let (Some(edges), Some(corners)) =
            (topology.face_edges.get(face as usize), topology.face_vertices.get(face as usize))
        else {
            continue;
        };
        for &edge in edges {
            let e = edge as usize;
            if scratch.edge_stamp[e] != stamp {
                scratch.edge_stamp[e] = stamp;
                scratch.edge_mask[e] = mask;
            } else {
                scratch.edge_mask[e] |= mask;
            }
        }
        for &v in corners {
            let i = v as usize;
            if scratch.vertex_stamp[i] != stamp {
                scratch.vertex_stamp[i] = stamp;
                scratch.vertex_mask[i] = mask;
            } else {
                scratch.vertex_mask[i] |= mask;
            }
        }
    }
    stamp
}

/// The blur dab over `scratch.faces` (masks accumulated by the caller).
fn blur_faces<C: Coverage>(
    coverage: &C,
    positions: &[[f32; 3]],
    store: &mut ColorStore,
    history: &mut UndoHistory,
    scratch: &mut Scratch,
) -> DabStats {
    let stamp = accumulate_masks(store, scratch);
    let mut terms = std::mem::take(&mut scratch.blur);
    terms.clear();
    const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)];
    for (&face, &face_mask) in scratch.faces.iter().zip(&scratch.face_masks) {
        let topology = store.topology();
        let (Some(r), Some(&corners), Some(&edges)) = (
            store.face_resolution(face),
            topology.face_vertices.get(face as usize),
            topology.face_edges.get(face as usize),
        ) else {
            continue;
        };
        let res = r.get();
        let [p0, p1, p2] = corners.map(|v| position(positions, v));
        let inv = 1.0 / f64::from(res);
        let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
        // The mask of a lattice point: its element's (accumulated for shared elements).
        let vertex_mask = |k: usize| {
            let v = corners[k] as usize;
            if scratch.vertex_stamp[v] == stamp { scratch.vertex_mask[v] } else { 0 }
        };
        let edge_mask = |k: usize| {
            let e = edges[k] as usize;
            if scratch.edge_stamp[e] == stamp { scratch.edge_mask[e] } else { 0 }
        };
        let all =
            face_mask | vertex_mask(0) | vertex_mask(1) | vertex_mask(2) | edge_mask(0) | edge_mask(1) | edge_mask(2);
        if all == 0 {
            continue;
        }
        for i in 0..=res {
            let a = p0 + e1 * f64::from(i);
            let Some((j0, j1)) = coverage.row_range(a, e2, 0, res - i, all) else {
                continue;
            };
            for j in j0..=j1 {
                let mask = match (i, j) {
                    (0, 0) => vertex_mask(0),
                    (i, 0) if i == res => vertex_mask(1),
                    (0, j) if j == res => vertex_mask(2),
                    (_, 0) => edge_mask(0),
                    (i, j) if i + j == res => edge_mask(1),
                    (0, _) => edge_mask(2),
                    _ => face_mask,
                };
                if mask == 0 {
                    continue;
                }
                let weight = coverage.weight(a + e2 * f64::from(j), mask);
                if weight <= 0.0 {
                    continue;
                }
                let Some(sample) = store.face_sample_ref(face, i, j) else {
                    continue;
                };
                let mut sum = [0.0f32; 4];
                let mut count = 0;
                for (di, dj) in NEIGHBOURS {
                    let (ni, nj) = (i64::from(i) + di, i64::from(j) + dj);
                    if ni < 0 || nj < 0 || ni + nj > i64::from(res) {
                        continue;
                    }
                    if let Some(color) = store.face_sample(face, ni as u32, nj as u32) {
                        for c in 0..4 {
                            sum[c] += color[c];
                        }
                        count += 1;
                    }
                }
                terms.push(BlurTerm { sample, sum, count, weight });
            }
        }
    }
    // Merge the contributions of the faces sharing a sample, then write (Jacobi: every mean
    // was taken before any write).
    terms.sort_unstable_by_key(|term| term.sample);
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    let mut k = 0;
    while k < terms.len() {
        let mut merged = terms[k];
        let mut next = k + 1;
        while next < terms.len() && terms[next].sample == merged.sample {
            let term = terms[next];
            for c in 0..4 {
                merged.sum[c] += term.sum[c];
            }
            merged.count += term.count;
            merged.weight = merged.weight.max(term.weight);
            next += 1;
        }
        k = next;
        let Some(old) = store.get(merged.sample) else {
            continue;
        };
        stats.samples_covered += 1;
        if merged.count == 0 {
            continue;
        }
        let mean = merged.sum.map(|s| s / merged.count as f32);
        let new = BlendMode::Mix.blend(old, mean, old, merged.weight);
        if history.set_sample(store, merged.sample, new) && differs(new, old) {
            stats.samples_changed += 1;
        }
    }
    scratch.blur = terms;
    stats
}

/// Paints strokes on a store: the brush state and per-mesh scratch. See the module
/// documentation for the call sequence.
#[derive(Debug, Clone)]
pub struct Painter {
    settings: BrushSettings,
    mirror_plane_x: f64,
    stroke: Option<StrokeState>,
    scratch: Scratch,
}

impl Painter {
    /// A painter for the mesh with `positions` (the X-mirror plane is the centre of their
    /// bounds), with default settings.
    pub fn new(positions: &[[f32; 3]]) -> Self {
        let (min, max) = positions
            .iter()
            .map(|p| f64::from(p[0]))
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let mirror_plane_x = if min <= max { 0.5 * (min + max) } else { 0.0 };
        Painter { settings: BrushSettings::default(), mirror_plane_x, stroke: None, scratch: Scratch::default() }
    }

    /// The settings the next stroke uses.
    pub fn settings(&self) -> &BrushSettings {
        &self.settings
    }

    /// Changes the settings; a stroke in progress keeps the ones it began with.
    pub fn set_settings(&mut self, settings: BrushSettings) {
        self.settings = settings;
    }

    /// The X-mirror plane, `x =` this (world units).
    pub fn mirror_plane_x(&self) -> f64 {
        self.mirror_plane_x
    }

    /// Whether a stroke is in progress.
    pub fn is_stroking(&self) -> bool {
        self.stroke.is_some()
    }

    /// Starts a stroke at `cursor_px` with the current settings: opens an undo step and
    /// places the first dab (none when the cursor is off the mesh). A stroke in progress is
    /// ended first.
    pub fn begin_stroke(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        cursor_px: [f64; 2],
    ) -> Result<StrokeUpdate, BrushError> {
        self.end_stroke(history);
        let settings = self.settings;
        settings.validate()?;
        check_view(view, store, &settings)?;
        history.begin_step(store, settings.label())?;
        self.scratch.fit(store);
        self.scratch.next_stroke();
        self.stroke = Some(StrokeState { settings, last_cursor_px: cursor_px, since_dab_px: 0.0, world_per_px: None });
        let mut update = StrokeUpdate::default();
        if let Err(error) = self.dab_at_cursor(view, store, history, cursor_px, &mut update) {
            self.end_stroke(history);
            return Err(error);
        }
        Ok(update)
    }

    /// Extends the stroke to `cursor_px`, placing dabs every spacing along the screen
    /// segment from the previous position. Does nothing without a stroke.
    pub fn stroke_to(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        cursor_px: [f64; 2],
    ) -> Result<StrokeUpdate, BrushError> {
        let mut update = StrokeUpdate::default();
        let Some(state) = self.stroke else {
            return Ok(update);
        };
        let [x0, y0] = state.last_cursor_px;
        let (dx, dy) = (cursor_px[0] - x0, cursor_px[1] - y0);
        let length = dx.hypot(dy);
        if !length.is_finite() {
            return Ok(update);
        }
        let radius_px = match state.settings.radius {
            BrushRadius::Pixels { radius_px } => radius_px,
            BrushRadius::World { radius_world } => {
                let world_per_px =
                    state.world_per_px.unwrap_or_else(|| view.camera.world_per_pixel(f64::from(view.viewport_px[1])));
                radius_world / world_per_px.max(f64::MIN_POSITIVE)
            }
        };
        let spacing = (state.settings.spacing_percent / 100.0 * radius_px).max(MIN_SPACING_PX);
        // Distance along this segment to the next dab.
        let mut along = spacing - state.since_dab_px;
        let mut placed = 0;
        let mut last_along = -state.since_dab_px;
        while along <= length && placed < MAX_DABS_PER_SEGMENT {
            let t = along / length;
            self.dab_at_cursor(view, store, history, [x0 + dx * t, y0 + dy * t], &mut update)?;
            last_along = along;
            along += spacing;
            placed += 1;
        }
        if let Some(state) = self.stroke.as_mut() {
            state.last_cursor_px = cursor_px;
            state.since_dab_px = (length - last_along).max(0.0);
        }
        Ok(update)
    }

    /// Ends the stroke and closes its undo step. `None` when no stroke was in progress.
    pub fn end_stroke(&mut self, history: &mut UndoHistory) -> Option<StepSummary> {
        self.stroke.take()?;
        history.end_step()
    }

    /// One dab at the cursor (a stroke must be in progress).
    fn dab_at_cursor(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        cursor_px: [f64; 2],
        update: &mut StrokeUpdate,
    ) -> Result<(), BrushError> {
        let Some(state) = self.stroke else {
            return Ok(());
        };
        let Some(hit) = view.pick(cursor_px) else {
            return Ok(());
        };
        let center = DVec3::from_array(hit.position_world);
        let world_per_px = view.world_per_px_at(center);
        let radius_world = match state.settings.radius {
            BrushRadius::Pixels { radius_px } => radius_px * world_per_px,
            BrushRadius::World { radius_world } => radius_world,
        };
        if let Some(state) = self.stroke.as_mut()
            && world_per_px > 0.0
        {
            state.world_per_px = Some(world_per_px);
        }
        let stats = self.dab_with(&state.settings, view, store, history, center, radius_world)?;
        update.stats.add(stats);
        update.dabs.push(Dab { cursor_px, center_world: hit.position_world, radius_world, face: hit.face });
        Ok(())
    }

    /// One dab centred at `center_world` with radius `radius_world`, with the stroke's
    /// settings (the current settings outside a stroke). Records into the history's open
    /// step, if any. This is what every stroke dab runs; public for tests and benchmarks.
    /// Outside a stroke, each call counts as its own stroke for the resolution brush's
    /// "each face once per stroke" rule.
    pub fn dab_at(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        center_world: DVec3,
        radius_world: f64,
    ) -> Result<DabStats, BrushError> {
        let settings = self.stroke.map_or(self.settings, |state| state.settings);
        settings.validate()?;
        check_view(view, store, &settings)?;
        if self.stroke.is_none() {
            self.scratch.fit(store);
            self.scratch.next_stroke();
        }
        self.dab_with(&settings, view, store, history, center_world, radius_world)
    }

    fn dab_with(
        &mut self,
        settings: &BrushSettings,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        center: DVec3,
        radius_world: f64,
    ) -> Result<DabStats, BrushError> {
        if !(radius_world.is_finite() && radius_world > 0.0 && center.is_finite()) {
            return Ok(DabStats::default());
        }
        self.scratch.fit(store);
        let eye = view.camera.eye();
        let mirror = |p: DVec3| DVec3::new(2.0 * self.mirror_plane_x - p.x, p.y, p.z);
        let count = if settings.mirror_x { 2 } else { 1 };
        let footprint = Footprint::new(
            [center, mirror(center)],
            [eye, mirror(eye)],
            count,
            radius_world,
            settings.strength,
            settings.falloff,
            settings.occlusion.then_some(view.bvh),
        );
        // The faces of both spheres, sorted and unique.
        let mut faces = view.bvh.faces_in_sphere(center, radius_world);
        if count == 2 {
            faces.extend(view.bvh.faces_in_sphere(footprint.centers[1], radius_world));
            faces.sort_unstable();
            faces.dedup();
        }
        let all_mask = (1u8 << count) - 1;
        self.scratch.face_masks.clear();
        for &face in &faces {
            let mask = if settings.backface_culling {
                let corners = store.topology().face_vertices.get(face as usize).copied().unwrap_or_default();
                let [p0, p1, p2] = corners.map(|v| position(view.positions, v));
                let normal = (p1 - p0).cross(p2 - p0);
                (0..count).filter(|&k| normal.dot(footprint.eyes[k] - p0) > 0.0).fold(0u8, |m, k| m | 1 << k)
            } else {
                all_mask
            };
            self.scratch.face_masks.push(mask);
        }
        self.scratch.faces = faces;
        let stats = match settings.tool {
            Tool::Paint => {
                let op = PaintOp { blend: settings.blend, color: settings.color, base: view.base };
                paint_faces(&footprint, &op, view.positions, store, history, &mut self.scratch)
            }
            Tool::Blur => blur_faces(&footprint, view.positions, store, history, &mut self.scratch),
            Tool::Resolution(op) => {
                let stroke = self.scratch.stroke;
                let mut stats = DabStats { faces: self.scratch.faces.len() as u32, ..DabStats::default() };
                for &face in &self.scratch.faces {
                    let (Some(slot), Some(current)) =
                        (self.scratch.face_stroke.get_mut(face as usize), store.face_resolution(face))
                    else {
                        continue;
                    };
                    if *slot == stroke {
                        continue;
                    }
                    if let Some(target) = op.apply(current) {
                        *slot = stroke;
                        if history.set_face_resolution(store, face, target)? {
                            stats.faces_resized += 1;
                        }
                    }
                }
                stats
            }
        };
        Ok(stats)
    }
}

/// Checks the view matches the store (and the base, when the blend mode needs it).
fn check_view(view: &PaintView, store: &ColorStore, settings: &BrushSettings) -> Result<(), BrushError> {
    let vertices = store.topology().vertex_count;
    if view.positions.len() != vertices as usize {
        return Err(BrushError::PositionCount { positions: view.positions.len(), vertices });
    }
    if settings.tool == Tool::Paint && settings.blend == BlendMode::EraseToBase {
        check_base(view.base, store)?;
    }
    Ok(())
}

fn check_base(base: Option<&ColorStore>, store: &ColorStore) -> Result<(), BrushError> {
    let base = base.ok_or(BrushError::NoBase)?;
    if base.topology().face_vertices != store.topology().face_vertices {
        return Err(BrushError::BaseMismatch {
            base_faces: base.topology().face_count(),
            faces: store.topology().face_count(),
        });
    }
    Ok(())
}

/// The colour under the cursor: the store sampled linearly at the ray's hit (level 0), or
/// `None` off the mesh.
pub fn eyedropper(view: &PaintView, store: &ColorStore, cursor_px: [f64; 2]) -> Option<Rgba> {
    let hit = view.pick(cursor_px)?;
    sampler::sample(store, hit.face, hit.barycentric, Filter::Linear, 0)
}

/// Which faces a fill covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FillScope {
    /// Every face.
    All,
    /// The faces connected to `face` through shared edges.
    Connected {
        /// The seed face (e.g. the face under the cursor).
        face: u32,
    },
}

/// The faces connected to `seed` through shared edges (non-manifold edges connect all their
/// faces), sorted. Empty when `seed` does not exist.
pub fn connected_faces(store: &ColorStore, seed: u32) -> Vec<u32> {
    let topology = store.topology();
    let mut seen = vec![false; topology.face_count() as usize];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    if let Some(flag) = seen.get_mut(seed as usize) {
        *flag = true;
        stack.push(seed);
    }
    while let Some(face) = stack.pop() {
        out.push(face);
        for &edge in &topology.face_edges[face as usize] {
            for &(other, _) in topology.faces_of_edge(edge) {
                if let Some(flag) = seen.get_mut(other as usize)
                    && !*flag
                {
                    *flag = true;
                    stack.push(other);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

/// Fills the faces in `scope` (every sample, shared ones once) with `color` blended by
/// `blend` at weight `strength`, as one undo step labelled "fill".
pub fn fill(
    store: &mut ColorStore,
    history: &mut UndoHistory,
    scope: FillScope,
    color: Rgba,
    blend: BlendMode,
    strength: f32,
    base: Option<&ColorStore>,
) -> Result<DabStats, BrushError> {
    if !(0.0..=1.0).contains(&strength) {
        return Err(BrushError::InvalidSetting(format!("strength {strength} is not in 0..=1")));
    }
    if blend == BlendMode::EraseToBase {
        check_base(base, store)?;
    }
    let faces = match scope {
        FillScope::All => (0..store.topology().face_count()).collect(),
        FillScope::Connected { face } => {
            if face >= store.topology().face_count() {
                return Err(BrushError::NoSuchFace(face));
            }
            connected_faces(store, face)
        }
    };
    let mut scratch = Scratch::default();
    scratch.fit(store);
    scratch.face_masks = vec![1; faces.len()];
    scratch.faces = faces;
    // Positions do not matter: every point has the same weight.
    let positions = vec![[0.0f32; 3]; store.topology().vertex_count as usize];
    history.begin_step(store, "fill")?;
    let op = PaintOp { blend, color, base };
    let stats = paint_faces(&Everywhere(strength), &op, &positions, store, history, &mut scratch);
    history.end_step();
    Ok(stats)
}

/// Sets the resolution of `faces` (every face when `None`) to `resolution`, as one undo step
/// labelled "set resolution". Returns the number of faces changed.
pub fn set_resolution(
    store: &mut ColorStore,
    history: &mut UndoHistory,
    faces: Option<&[u32]>,
    resolution: Resolution,
) -> Result<u32, BrushError> {
    let face_count = store.topology().face_count();
    if let Some(&bad) = faces.and_then(|list| list.iter().find(|&&f| f >= face_count)) {
        return Err(BrushError::NoSuchFace(bad));
    }
    history.begin_step(store, "set resolution")?;
    let mut changed = 0;
    let mut run = |face: u32| -> Result<(), BrushError> {
        if history.set_face_resolution(store, face, resolution)? {
            changed += 1;
        }
        Ok(())
    };
    let result = match faces {
        Some(list) => list.iter().try_for_each(|&face| run(face)),
        None => (0..face_count).try_for_each(run),
    };
    history.end_step();
    result.map(|()| changed)
}

/// Parses `#rrggbb` (or `rrggbb`) as an sRGB colour and returns it in linear light, opaque.
pub fn parse_hex_color(text: &str) -> Option<Rgba> {
    let hex = text.strip_prefix('#').unwrap_or(text);
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let channel = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok();
    let (r, g, b) = (channel(0)?, channel(1)?, channel(2)?);
    Some([
        crate::colors::format::decode_srgb8(r),
        crate::colors::format::decode_srgb8(g),
        crate::colors::format::decode_srgb8(b),
        1.0,
    ])
}

/// Parses a stroke given as `"x0,y0 x1,y1 …"` (pixels).
pub fn parse_stroke(text: &str) -> Result<Vec<[f64; 2]>, String> {
    text.split_whitespace()
        .map(|pair| {
            let (x, y) = pair.split_once(',').ok_or_else(|| format!("'{pair}' is not x,y"))?;
            let x: f64 = x.trim().parse().map_err(|_| format!("'{x}' in '{pair}' is not a number"))?;
            let y: f64 = y.trim().parse().map_err(|_| format!("'{y}' in '{pair}' is not a number"))?;
            if !(x.is_finite() && y.is_finite()) {
                return Err(format!("'{pair}' is not finite"));
            }
            Ok([x, y])
        })
        .collect::<Result<Vec<_>, _>>()
        .and_then(|points| if points.is_empty() { Err("the stroke has no points".into()) } else { Ok(points) })
}

/// Replays one stroke through `cursor_px` positions: begin, extend, end. Returns the
/// combined update and the closed step's summary.
pub fn replay_stroke(
    painter: &mut Painter,
    view: &PaintView,
    store: &mut ColorStore,
    history: &mut UndoHistory,
    cursor_px: &[[f64; 2]],
) -> Result<(StrokeUpdate, Option<StepSummary>), BrushError> {
    let Some((&first, rest)) = cursor_px.split_first() else {
        return Ok((StrokeUpdate::default(), None));
    };
    let mut total = painter.begin_stroke(view, store, history, first)?;
    for &point in rest {
        let update = painter.stroke_to(view, store, history, point)?;
        total.dabs.extend(update.dabs);
        total.stats.add(update.stats);
    }
    let summary = painter.end_stroke(history);
    Ok((total, summary))
}

/// Samples within `radius` of `center` (what a constant-falloff dab without culling or
/// occlusion covers), counted without writing.
pub fn samples_within(view: &PaintView, store: &ColorStore, center: DVec3, radius: f64) -> u64 {
    let footprint = Footprint::new([center; 2], [center; 2], 1, radius, 1.0, Falloff::Constant, None);
    let mut scratch = Scratch::default();
    scratch.fit(store);
    scratch.faces = view.bvh.faces_in_sphere(center, radius);
    scratch.face_masks = vec![1; scratch.faces.len()];
    let stamp = accumulate_masks(store, &mut scratch);
    let topology = store.topology();
    let mut count = 0u64;
    let mut row = |a: DVec3, b: DVec3, lo: u32, hi: u32| {
        if let Some((k0, k1)) = footprint.row_range(a, b, lo, hi, 1) {
            count += (k0..=k1).filter(|&k| footprint.weight(a + b * f64::from(k), 1) > 0.0).count() as u64;
        }
    };
    for &face in &scratch.faces {
        let (Some(r), Some(&corners), Some(&edges)) = (
            store.face_resolution(face),
            topology.face_vertices.get(face as usize),
            topology.face_edges.get(face as usize),
        ) else {
            continue;
        };
        let res = r.get();
        let [p0, p1, p2] = corners.map(|v| position(view.positions, v));
        let inv = 1.0 / f64::from(res);
        for i in 1..res.saturating_sub(1) {
            row(p0 + (p1 - p0) * (f64::from(i) * inv), (p2 - p0) * inv, 1, res - 1 - i);
        }
        for edge in edges {
            if scratch.edge_stamp[edge as usize] == stamp {
                scratch.edge_stamp[edge as usize] = stamp + 1;
                let (Some(r), Some(&[lo, hi])) =
                    (store.edge_resolution(edge), topology.edge_vertices.get(edge as usize))
                else {
                    continue;
                };
                let a = position(view.positions, lo);
                row(a, (position(view.positions, hi) - a) / f64::from(r.get()), 1, r.get() - 1);
            }
        }
        for v in corners {
            if scratch.vertex_stamp[v as usize] == stamp {
                scratch.vertex_stamp[v as usize] = stamp + 1;
                row(position(view.positions, v), DVec3::ZERO, 0, 0);
            }
        }
    }
    count
}
