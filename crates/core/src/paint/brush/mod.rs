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
//! the viewport size in pixels, and the base snapshot. Every call writes through one
//! [`StoreWriter`] (per dab, fill or resolution change), which records the old values in the
//! open undo step and leaves the changes marked dirty in the store
//! ([`ColorStore::take_dirty`]); nothing in this module writes the store another way.
//!
//! # Files
//!
//! | file | what |
//! |---|---|
//! | `error.rs` | [`BrushError`] |
//! | `settings.rs` | [`BrushSettings`], [`Tool`], [`Falloff`], [`BlendMode`], [`BrushRadius`], [`ResolutionOp`], [`PressureResponse`], [`StrokePoint`], [`HardEdges`], validation |
//! | `footprint.rs` | where a dab reaches: the `Coverage` trait, the dab's spheres, fill's "everywhere", [`visible`] |
//! | `stencil.rs` | the blur's lattice stencils, one per face resolution (neighbours and holders of every lattice point) |
//! | `scratch.rs` | per-mesh scratch reused across dabs, mask accumulation (pass 1 of a dab) |
//! | `kernels.rs` | the colour kernels (interior rows, edges, vertices, one shared per-sample step), [`DabStats`] |
//! | `blur.rs` | the blur kernel |
//! | `painter.rs` | [`Painter`], [`PaintView`], [`Dab`], [`StrokeUpdate`]: strokes, dab placement, culling, the resolution dab |
//! | `tools.rs` | [`eyedropper`], [`fill`], [`connected_faces`], [`set_resolution`] |
//! | `replay.rs` | [`parse_hex_color`], [`parse_stroke`], [`replay_stroke`], [`samples_within`] |
//!
//! The files depend on each other one way, top to bottom of the table, skipping rows (e.g.
//! `kernels.rs` uses `footprint.rs` and `scratch.rs`, never `painter.rs`).
//!
//! # A stroke
//!
//! Cursor positions arrive as pixel coordinates (origin top-left, as
//! [`OrbitCamera::ray_through_pixel`] takes them), each a [`StrokePoint`] with a pen pressure
//! (1.0 from a mouse; `[x, y]` converts to one). The pressure is interpolated along each
//! segment and, as [`BrushSettings::pressure`] says, scales each dab's radius and / or
//! strength (winit has no tablet pressure yet: the editor passes 1.0, `meshpaint paint
//! --stroke x,y,p` replays it). Between two successive positions dabs
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
//!    over the spheres that see it); with occlusion on, only if nothing lies between the eye
//!    and the sample: tested against a depth map of the view
//!    ([`crate::paint::occlusion::DepthMap`], rasterised once per view and kept by the
//!    [`Painter`]; hidden means something is nearer by more than one pixel width at the
//!    sample's depth, and within about a pixel of a silhouette a hidden sample may count as
//!    visible), and with the segment from the eye to the sample cast into the BVH
//!    ([`visible`], the reference) where the map cannot tell (off screen, behind the near
//!    plane).
//! 5. Blending is in linear light: `new = old · (1 − w) + target · w` with target = the brush
//!    colour (Mix), `old + colour` (Add, RGB), `old × colour` (Multiply, RGB) or the base
//!    snapshot's colour at the sample (Erase to base).
//!
//! Before painting, resolution follows the brush (when on) raises the dab's faces that cannot
//! resolve a quarter of the radius, and a hard brush (constant falloff) raises those coarser
//! than a sixteenth of it, up to `R = 64` within the budget, textured documents too
//! ([`HardEdges`]; without it a hard rim is a staircase of samples, docs/PAINT_MODE.md "Hard
//! edges" has the measurement that chose it over anti-aliasing the rim, which stays an option).
//!
//! The blur brush moves each sample towards the mean of its lattice neighbours (the six
//! neighbours in every face whose lattice contains it, at that face's resolution) by `w`,
//! computed from the colours before the dab (each face's lattice gathered once, shared
//! samples summed per element; `blur.rs`). The resolution brush raises, lowers or sets `R`
//! of every face whose triangle intersects the brush sphere, each face at most once per
//! stroke, resampling as [`ColorStore::set_face_resolution`] defines.
//!
//! # Speed
//!
//! Measured with `meshpaint bench paint`; the current figures, with the command and the
//! machine, are in docs/BENCHMARKS.md (the scale table, and "Other rows" for the depth map).
//! Issue 13 made occlusion test a depth map of the view instead of casting one BVH ray per
//! sample, gathered the blur's lattices once per face and updated rows in place: occlusion
//! became an order of magnitude faster and blur about twice as fast, while paint without
//! occlusion did not change. The depth map is rasterised once per view change, not per dab:
//! on large meshes it takes far longer than a dab.
//!
//! The sphere query is a small share of a dab, at every brush size. The hot loop allocates
//! nothing and hashes nothing: positions come from the corners in `f64`, the row bounds from a
//! quadratic (skipped for faces entirely inside), the weight from one `f32` square root, the
//! undo record from a bit test. What remains per sample is mostly the store's own `get`/`set`
//! (two bounds-checked lookups and a dirty flag each); the first dab of a stroke also pays for
//! fresh undo memory (page faults).

mod blur;
mod error;
mod footprint;
mod kernels;
mod painter;
mod replay;
mod scratch;
mod settings;
mod stencil;
mod tools;

#[cfg(doc)]
use crate::colors::store::ColorStore;
#[cfg(doc)]
use crate::paint::undo::StoreWriter;
#[cfg(doc)]
use crate::{camera::OrbitCamera, paint::picking::MeshBvh};

pub use error::BrushError;
pub use footprint::{OCCLUSION_TOLERANCE, visible};
pub use kernels::DabStats;
pub use painter::{Dab, MAX_DABS_PER_SEGMENT, MIN_SPACING_PX, PaintView, Painter, StrokeUpdate};
pub use replay::{parse_hex_color, parse_stroke, replay_stroke, samples_within};
pub use settings::{
    BlendMode, BrushRadius, BrushSettings, FOLLOW_BRUSH_MAX_RESOLUTION, Falloff, HARD_EDGE_SPACINGS_PER_RADIUS,
    HardEdges, PressureResponse, ResolutionOp, StrokePoint, Tool, resolution_for_brush, resolution_for_spacing,
};
pub use tools::{FillScope, connected_faces, eyedropper, fill, set_resolution};
