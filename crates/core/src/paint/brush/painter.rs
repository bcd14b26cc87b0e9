//! The stroke driver: [`PaintView`] (what the pointer is over), [`Painter`] (brush state,
//! stroke spacing in screen space, one dab's footprint and culling), and what a stroke
//! reports ([`Dab`], [`StrokeUpdate`]).

use glam::DVec3;

use crate::camera::OrbitCamera;
use crate::colors::budget::{Budget, SampleTracker};
use crate::colors::format::ColorFormat;
use crate::colors::store::ColorStore;
use crate::paint::picking::{MeshBvh, RayHit};
use crate::paint::undo::{StepSummary, StoreWriter, UndoHistory};

use super::blur::blur_faces;
use super::error::BrushError;
use super::footprint::{Footprint, Occlusion, Rim};
use super::kernels::{DabStats, PaintOp, paint_faces};
use super::scratch::{Scratch, position};
use super::settings::{
    BlendMode, BrushRadius, BrushSettings, Falloff, HardEdges, ResolutionOp, StrokePoint, Tool, resolution_for_spacing,
};
use crate::colors::layout::Resolution;
use crate::paint::occlusion::DepthMap;

/// Smallest distance between dabs along a stroke, pixels.
pub const MIN_SPACING_PX: f64 = 0.25;
/// Most dabs one [`Painter::stroke_to`] call places (a guard against absurd spacing).
pub const MAX_DABS_PER_SEGMENT: usize = 100_000;

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
    /// Brush radius, world units (pen pressure applied).
    pub radius_world: f64,
    /// The face hit.
    pub face: u32,
    /// The pen pressure at the dab (interpolated between the stroke's points).
    pub pressure: f32,
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
    /// The pen pressure at the previous position.
    last_pressure: f32,
    /// Screen distance travelled since the last dab position.
    since_dab_px: f64,
    /// World units per pixel at the last hit.
    world_per_px: Option<f64>,
}

/// Paints strokes on a store: the brush state and per-mesh scratch. See the module
/// documentation for the call sequence.
#[derive(Debug, Clone)]
pub struct Painter {
    settings: BrushSettings,
    mirror_plane_x: f64,
    stroke: Option<StrokeState>,
    scratch: Scratch,
    /// The budget resolution changes are checked against, with the document's format.
    budget: Option<(Budget, ColorFormat)>,
    /// The sample counts during a resolution stroke (built at its first resize).
    tracker: Option<SampleTracker>,
    /// Occlusion depth maps of the view and of its mirror (built on the first dab that needs
    /// them after the view changed, see [`crate::paint::occlusion`]).
    depth_maps: [Option<DepthMap>; 2],
    /// Whether the last colour or blur dab ran on the thread pool (`None` before the
    /// first): a stroke keeps its radius, so the next one likely does too.
    last_dab_parallel: Option<bool>,
    /// What hard brushes do at their rim ([`Painter::set_hard_edges`]).
    hard_edges: HardEdges,
    /// The anti-aliased rims of the stroke's dabs so far (see [`Footprint::with_earlier`]).
    rims: Vec<Rim>,
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
        Painter {
            settings: BrushSettings::default(),
            mirror_plane_x,
            stroke: None,
            scratch: Scratch::default(),
            budget: None,
            tracker: None,
            last_dab_parallel: None,
            depth_maps: [None, None],
            hard_edges: HardEdges::default(),
            rims: Vec::new(),
        }
    }

    /// Makes sure the occlusion depth maps for `view` exist (the view's, and the mirrored
    /// view's when `mirror` is on), building those missing or built for another view.
    /// Returns how many were built. Dabs with occlusion call this themselves; it is public so
    /// a caller can build the maps ahead (e.g. when the view stops moving) and so the
    /// benchmark can time the build apart from the dabs.
    pub fn prepare_occlusion(&mut self, view: &PaintView, store: &ColorStore, mirror: bool) -> usize {
        let triangles = &store.topology().face_vertices;
        let eye = view.camera.eye();
        let target = DVec3::from_array(view.camera.target);
        let plane = self.mirror_plane_x;
        let mirrored = |p: DVec3| DVec3::new(2.0 * plane - p.x, p.y, p.z);
        let eyes = [(eye, target), (mirrored(eye), mirrored(target))];
        let mut built = 0;
        for (k, &(eye, target)) in eyes.iter().enumerate().take(if mirror { 2 } else { 1 }) {
            let current = self.depth_maps[k]
                .as_ref()
                .is_some_and(|map| map.is_for(view.positions, triangles, view.camera, eye, target, view.viewport_px));
            if !current {
                self.depth_maps[k] =
                    DepthMap::build(view.positions, triangles, view.camera, eye, target, view.viewport_px);
                built += 1;
            }
        }
        built
    }

    /// The budget the resolution brush checks each face's change against before making it
    /// (`None`: no check), with the colour format of the document.
    pub fn set_budget(&mut self, budget: Option<(Budget, ColorFormat)>) {
        self.budget = budget;
        self.tracker = None;
    }

    /// What hard brushes (paint with a constant falloff) do so that their rim is not a
    /// staircase of samples ([`HardEdges::default`]: raise the faces under them); applies
    /// from the next dab.
    pub fn set_hard_edges(&mut self, hard_edges: HardEdges) {
        self.hard_edges = hard_edges;
    }

    /// What hard brushes do at their rim ([`Painter::set_hard_edges`]).
    pub fn hard_edges(&self) -> HardEdges {
        self.hard_edges
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

    /// Starts a stroke at `point` (a cursor position in pixels, with its pen pressure; `[x, y]`
    /// is full pressure) with the current settings: opens an undo step and places the first
    /// dab (none when the cursor is off the mesh). A stroke in progress is ended first.
    pub fn begin_stroke(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        point: impl Into<StrokePoint>,
    ) -> Result<StrokeUpdate, BrushError> {
        self.end_stroke(history);
        let point = point.into();
        let settings = self.settings;
        settings.validate()?;
        point.validate()?;
        check_view(view, store, &settings)?;
        history.begin_step(store, settings.label())?;
        self.scratch.fit(store);
        self.scratch.next_stroke();
        self.tracker = None;
        self.rims.clear();
        self.stroke = Some(StrokeState {
            settings,
            last_cursor_px: point.px,
            last_pressure: point.pressure,
            since_dab_px: 0.0,
            world_per_px: None,
        });
        let mut update = StrokeUpdate::default();
        if let Err(error) = self.dab_at_cursor(view, store, history, point, &mut update) {
            self.end_stroke(history);
            return Err(error);
        }
        Ok(update)
    }

    /// Extends the stroke to `point`, placing dabs every spacing along the screen segment
    /// from the previous position, the pressure interpolated along it. Does nothing without
    /// a stroke.
    pub fn stroke_to(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        point: impl Into<StrokePoint>,
    ) -> Result<StrokeUpdate, BrushError> {
        let mut update = StrokeUpdate::default();
        let point = point.into();
        point.validate()?;
        let Some(state) = self.stroke else {
            return Ok(update);
        };
        let cursor_px = point.px;
        let (p0, p1) = (state.last_pressure, point.pressure);
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
        // Spacing follows the smaller radius of the segment's two ends.
        let (radius_factor, _) = state.settings.pressure.factors(p0.min(p1));
        let spacing = (state.settings.spacing_percent / 100.0 * radius_px * radius_factor).max(MIN_SPACING_PX);
        // Distance along this segment to the next dab.
        let mut along = spacing - state.since_dab_px;
        let mut placed = 0;
        let mut last_along = -state.since_dab_px;
        while along <= length && placed < MAX_DABS_PER_SEGMENT {
            let t = along / length;
            let at = StrokePoint { px: [x0 + dx * t, y0 + dy * t], pressure: p0 + (p1 - p0) * t as f32 };
            self.dab_at_cursor(view, store, history, at, &mut update)?;
            last_along = along;
            along += spacing;
            placed += 1;
        }
        if let Some(state) = self.stroke.as_mut() {
            state.last_cursor_px = cursor_px;
            state.last_pressure = p1;
            state.since_dab_px = (length - last_along).max(0.0);
        }
        Ok(update)
    }

    /// Ends the stroke and closes its undo step. `None` when no stroke was in progress.
    pub fn end_stroke(&mut self, history: &mut UndoHistory) -> Option<StepSummary> {
        self.stroke.take()?;
        self.tracker = None;
        history.end_step()
    }

    /// One dab at the cursor, radius and strength scaled by its pressure as the settings say
    /// (a stroke must be in progress).
    fn dab_at_cursor(
        &mut self,
        view: &PaintView,
        store: &mut ColorStore,
        history: &mut UndoHistory,
        point: StrokePoint,
        update: &mut StrokeUpdate,
    ) -> Result<(), BrushError> {
        let Some(state) = self.stroke else {
            return Ok(());
        };
        let cursor_px = point.px;
        let Some(hit) = view.pick(cursor_px) else {
            return Ok(());
        };
        let center = DVec3::from_array(hit.position_world);
        let world_per_px = view.world_per_px_at(center);
        let (radius_factor, strength_factor) = state.settings.pressure.factors(point.pressure);
        let radius_world = radius_factor
            * match state.settings.radius {
                BrushRadius::Pixels { radius_px } => radius_px * world_per_px,
                BrushRadius::World { radius_world } => radius_world,
            };
        let settings = BrushSettings { strength: state.settings.strength * strength_factor, ..state.settings };
        if let Some(state) = self.stroke.as_mut()
            && world_per_px > 0.0
        {
            state.world_per_px = Some(world_per_px);
        }
        let stats = self.dab_with(&settings, view, &mut StoreWriter::new(store, history), center, radius_world)?;
        update.stats.add(stats);
        update.dabs.push(Dab {
            cursor_px,
            center_world: hit.position_world,
            radius_world,
            face: hit.face,
            pressure: point.pressure,
        });
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
            self.tracker = None;
            self.rims.clear();
        }
        self.dab_with(&settings, view, &mut StoreWriter::new(store, history), center_world, radius_world)
    }

    /// One dab with `settings`, written through `writer`.
    fn dab_with(
        &mut self,
        settings: &BrushSettings,
        view: &PaintView,
        writer: &mut StoreWriter,
        center: DVec3,
        radius_world: f64,
    ) -> Result<DabStats, BrushError> {
        if !(radius_world.is_finite() && radius_world > 0.0 && center.is_finite()) {
            return Ok(DabStats::default());
        }
        let brush = matches!(settings.tool, Tool::Paint | Tool::Blur);
        if brush && self.last_dab_parallel.is_none_or(|parallel| parallel) {
            // Wake the pool now, so that its threads are up by the time the kernels' parallel
            // section starts, after the sphere query and the masks: between a stroke's dabs
            // (one a frame) they sleep, and a sleeping thread takes a while to wake on a
            // virtual machine. It raised `bench paint`'s `occlusion_frame_paced` row (2.3M
            // triangles, 100k-sample dabs) in both of two interleaved runs. Only when the last
            // dab ran in parallel (a stroke keeps its radius): a small dab runs on this thread,
            // and the woken threads spin for work on the cores it needs (`perf` of 10k-sample
            // blur dabs: about a third of the time in the scheduler and `sched_yield`).
            rayon::spawn(|| {});
        }
        let occlusion = settings.occlusion && matches!(settings.tool, Tool::Paint | Tool::Blur);
        if occlusion {
            self.prepare_occlusion(view, writer.store(), settings.mirror_x);
        }
        // The maps are lent to the dab (which needs `&mut self`) and put back after it.
        let maps = std::mem::take(&mut self.depth_maps);
        let result = self.dab_with_maps(settings, view, writer, center, radius_world, occlusion.then_some(&maps));
        self.depth_maps = maps;
        result
    }

    /// [`Painter::dab_with`] with the occlusion depth maps (`None`: no occlusion).
    fn dab_with_maps(
        &mut self,
        settings: &BrushSettings,
        view: &PaintView,
        writer: &mut StoreWriter,
        center: DVec3,
        radius_world: f64,
        maps: Option<&[Option<DepthMap>; 2]>,
    ) -> Result<DabStats, BrushError> {
        self.scratch.fit(writer.store());
        let eye = view.camera.eye();
        let mirror = |p: DVec3| DVec3::new(2.0 * self.mirror_plane_x - p.x, p.y, p.z);
        let count = if settings.mirror_x { 2 } else { 1 };
        let mut footprint = Footprint::new(
            [center, mirror(center)],
            [eye, mirror(eye)],
            count,
            radius_world,
            settings.strength,
            settings.falloff,
            maps.map(|maps| Occlusion {
                bvh: view.bvh,
                maps: [maps[0].as_ref(), maps[1].as_ref().filter(|_| count == 2)],
            }),
        );
        let raises = self.raises(settings, radius_world);
        self.collect_faces(view, writer.store(), &footprint, count, radius_world, settings.backface_culling);
        self.raise_faces(&raises, view, writer)?;
        let hard = settings.tool == Tool::Paint && settings.falloff == Falloff::Constant;
        if let (true, Some(spacings)) = (hard, self.hard_edges.antialias_spacings) {
            // The rim blends over the sample spacing of the faces it crosses (after they were
            // raised), so the faces the outer rim reaches are collected (and raised) again.
            footprint = footprint.with_edge(spacings * edge_width(&self.scratch, writer.store(), view.positions));
            let reach = footprint.reach();
            if reach > radius_world {
                self.collect_faces(view, writer.store(), &footprint, count, reach, settings.backface_culling);
                self.raise_faces(&raises, view, writer)?;
            }
        }
        let stats = match settings.tool {
            Tool::Paint => {
                let op = PaintOp { blend: settings.blend, color: settings.color, base: view.base };
                // The earlier rims this dab can reach, so the stroke's rim does not build up.
                let reach = footprint.reach();
                let earlier: Vec<Rim> = self
                    .rims
                    .iter()
                    .filter(|rim| footprint.centers.iter().take(count).any(|&c| rim.near(c, reach)))
                    .copied()
                    .collect();
                let footprint = footprint.with_earlier(&earlier);
                let stats = paint_faces(&footprint, &op, view.positions, writer, &mut self.scratch);
                self.rims.extend(footprint.rims());
                stats
            }
            Tool::Blur => blur_faces(&footprint, view.positions, writer, &mut self.scratch),
            Tool::Resolution(op) => {
                let budget = match &self.budget {
                    Some((budget, format)) => {
                        let tracker = self.tracker.get_or_insert_with(|| SampleTracker::new(writer.store()));
                        Some((budget, *format, tracker))
                    }
                    None => None,
                };
                resize_faces(op, writer, &mut self.scratch, budget)?
            }
        };
        if matches!(settings.tool, Tool::Paint | Tool::Blur) {
            self.last_dab_parallel = Some(stats.parallel);
        }
        Ok(stats)
    }
}

impl Painter {
    /// The faces within `radius` of the footprint's spheres (`count` of them), sorted and
    /// unique, into `scratch.faces`, with their sphere masks (with `culling`, only the spheres
    /// whose eye sees the face's front) into `scratch.face_masks`.
    fn collect_faces(
        &mut self,
        view: &PaintView,
        store: &ColorStore,
        footprint: &Footprint,
        count: usize,
        radius: f64,
        culling: bool,
    ) {
        let mut faces = view.bvh.faces_in_sphere(footprint.centers[0], radius);
        if count == 2 {
            faces.extend(view.bvh.faces_in_sphere(footprint.centers[1], radius));
            faces.sort_unstable();
            faces.dedup();
        }
        let all_mask = (1u8 << count) - 1;
        let mut masks = std::mem::take(&mut self.scratch.face_masks);
        masks.clear();
        if culling {
            // The side the ray hits is the front: faces are oriented consistently with their
            // component, then the hit face's side towards the eye decides (inside-out and
            // mixed-winding meshes paint what the cursor shows).
            let eye = footprint.eyes[0];
            let flips = self.scratch.face_flips(store);
            let hit = view.bvh.cast(eye, footprint.centers[0] - eye, f64::INFINITY);
            let hit_side = hit.map_or(1.0, |hit| {
                let flipped = flips.get(hit.face as usize).copied().unwrap_or(false);
                if hit.front_facing != flipped { 1.0 } else { -1.0 }
            });
            for &face in &faces {
                let corners = store.topology().face_vertices.get(face as usize).copied().unwrap_or_default();
                let [p0, p1, p2] = corners.map(|v| position(view.positions, v));
                let side = if flips.get(face as usize).copied().unwrap_or(false) { -hit_side } else { hit_side };
                let normal = (p1 - p0).cross(p2 - p0) * side;
                masks.push(
                    (0..count).filter(|&k| normal.dot(footprint.eyes[k] - p0) > 0.0).fold(0u8, |m, k| m | 1 << k),
                );
            }
        } else {
            masks.resize(faces.len(), all_mask);
        }
        self.scratch.face_masks = masks;
        self.scratch.faces = faces;
    }

    /// The raises a dab of `radius_world` makes before painting: resolution follows the brush
    /// ([`BrushSettings::follow_resolution`], paint and blur; over the budget stops the dab),
    /// then a hard brush's ([`HardEdges::raise_to`]; a face over the budget keeps its `R`).
    fn raises(&self, settings: &BrushSettings, radius_world: f64) -> [Option<Raise>; 2] {
        let follow = match (settings.follow_resolution, settings.tool) {
            (Some(max), Tool::Paint | Tool::Blur) => Some(Raise { max, spacing: radius_world / 4.0, strict: true }),
            _ => None,
        };
        let per_radius = self.hard_edges.spacings_per_radius;
        let hard = match (self.hard_edges.raise_to, settings.tool, settings.falloff) {
            (Some(max), Tool::Paint, Falloff::Constant) if per_radius.is_finite() && per_radius > 0.0 => {
                Some(Raise { max, spacing: radius_world / per_radius, strict: false })
            }
            _ => None,
        };
        [follow, hard]
    }

    /// Raises the faces of the dab (those facing the eye, `scratch.face_masks` ≠ 0) whose
    /// sample spacing is coarser than each raise's, each checked against the budget first.
    fn raise_faces(
        &mut self,
        raises: &[Option<Raise>; 2],
        view: &PaintView,
        writer: &mut StoreWriter,
    ) -> Result<(), BrushError> {
        for raise in raises.iter().flatten() {
            for (k, &face) in self.scratch.faces.iter().enumerate() {
                if self.scratch.face_masks.get(k).copied().unwrap_or(0) == 0 {
                    continue;
                }
                let store = writer.store();
                let Some(current) = store.face_resolution(face) else { continue };
                let corners = store.topology().face_vertices.get(face as usize).copied().unwrap_or_default();
                let [p0, p1, p2] = corners.map(|v| position(view.positions, v));
                let longest = (p1 - p0).length().max((p2 - p1).length()).max((p0 - p2).length());
                let target = resolution_for_spacing(longest, raise.spacing, raise.max);
                if target <= current {
                    continue;
                }
                if let Some((budget, format)) = &self.budget {
                    let tracker = self.tracker.get_or_insert_with(|| SampleTracker::new(writer.store()));
                    match tracker.admit(writer.store(), face, target, budget, *format) {
                        Ok(()) => {}
                        Err(error) if raise.strict => return Err(error.into()),
                        Err(_) => continue,
                    }
                }
                writer.set_face_resolution(face, target)?;
            }
        }
        // The sample scratch follows the resized store.
        self.scratch.fit(writer.store());
        Ok(())
    }
}

/// One rule that raises the faces under a dab: to the smallest power-of-two `R` whose spacing
/// (longest edge / R) is at most `spacing`, up to `max`; `strict`: a face over the budget
/// stops the dab (else it keeps its `R`).
#[derive(Debug, Clone, Copy)]
struct Raise {
    max: Resolution,
    spacing: f64,
    strict: bool,
}

/// The width a dab's anti-aliased rim blends over: the median sample spacing (longest edge /
/// R) of the faces in `scratch.faces` some sphere reaches (0 when there are none).
fn edge_width(scratch: &Scratch, store: &ColorStore, positions: &[[f32; 3]]) -> f64 {
    let topology = store.topology();
    let mut spacings: Vec<f64> = scratch
        .faces
        .iter()
        .zip(&scratch.face_masks)
        .filter(|&(_, &mask)| mask != 0)
        .filter_map(|(&face, _)| {
            let r = store.face_resolution(face)?;
            let corners = topology.face_vertices.get(face as usize)?;
            let [p0, p1, p2] = corners.map(|v| position(positions, v));
            let longest = (p1 - p0).length().max((p2 - p1).length()).max((p0 - p2).length());
            Some(longest / f64::from(r.get()))
        })
        .filter(|spacing| spacing.is_finite())
        .collect();
    if spacings.is_empty() {
        return 0.0;
    }
    let middle = spacings.len() / 2;
    let (_, median, _) = spacings.select_nth_unstable_by(middle, f64::total_cmp);
    *median
}

/// The resolution dab: applies `op` to every face in `scratch.faces` not yet changed in this
/// stroke; with a budget, each change is checked first (O(the face's edges)) and the first
/// one past it stops the dab with [`BrushError::Budget`].
fn resize_faces(
    op: ResolutionOp,
    writer: &mut StoreWriter,
    scratch: &mut Scratch,
    mut budget: Option<(&Budget, ColorFormat, &mut SampleTracker)>,
) -> Result<DabStats, BrushError> {
    let stroke = scratch.stroke;
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    for &face in &scratch.faces {
        let (Some(slot), Some(current)) =
            (scratch.face_stroke.get_mut(face as usize), writer.store().face_resolution(face))
        else {
            continue;
        };
        if *slot == stroke {
            continue;
        }
        if let Some(target) = op.apply(current) {
            if let Some((budget, format, tracker)) = budget.as_mut() {
                tracker.admit(writer.store(), face, target, budget, *format)?;
            }
            *slot = stroke;
            if writer.set_face_resolution(face, target)? {
                stats.faces_resized += 1;
            }
        }
    }
    Ok(stats)
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

/// Checks `base` exists and belongs to the mesh of `store`.
pub(super) fn check_base(base: Option<&ColorStore>, store: &ColorStore) -> Result<(), BrushError> {
    let base = base.ok_or(BrushError::NoBase)?;
    if base.topology().face_vertices != store.topology().face_vertices {
        return Err(BrushError::BaseMismatch {
            base_faces: base.topology().face_count(),
            faces: store.topology().face_count(),
        });
    }
    Ok(())
}
