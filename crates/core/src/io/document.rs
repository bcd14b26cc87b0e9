//! A document: one mesh with its mesh colors, opened from glTF, OBJ, PLY, STL or a packed file.
//!
//! Opening chooses the loader by content (the packed magic, PLY's magic line), then by
//! extension for OBJ and STL, else glTF. An imported mesh is welded, given a uniform
//! resolution, and coloured: from its texture, material colour or vertex colours, else a
//! neutral light grey to paint on. A packed file is unpacked into the editable store.
//!
//! [`open_for_display`] is the one way to open a document for display (the editor, `render`,
//! `bench render`, the examples): open the [`Source`], refuse a mesh without triangles, pack
//! it in its [`Document::display_format`].

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::colors::budget::{BYTES_PER_NODE, BYTES_PER_TEXEL, Budget, BudgetError, SampleCounts};
use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;
use crate::colors::store::{ColorStore, StoreError};
use crate::convert::adaptive::ResolutionRule;
use crate::convert::least_squares::BakeFit;
use crate::mesh::formats::{FormatError, MeshFormat, import_mesh_file};
use crate::mesh::import::{ImportError, ImportLimits, import_gltf_slice_within, import_gltf_within};
use crate::mesh::scene::Scene;
use crate::mesh::topology::{Topology, TopologyError};
use crate::mesh::weld::weld_scene;
use crate::packing::file::{self as packed_file, PackedFileError};
use crate::packing::linear::PackedMesh;
use crate::packing::packer::{self, PackError};

/// Errors of opening or saving a document; each names the file.
#[derive(Debug, Error)]
pub enum DocumentError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The glTF importer refused the file.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// The OBJ / PLY / STL importer refused the file.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The packed-file reader or writer refused the file.
    #[error(transparent)]
    PackedFile(#[from] PackedFileError),
    /// The mesh has no valid topology.
    #[error("{path}: {source}")]
    Topology {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: TopologyError,
    },
    /// A vertex lands at an infinite or NaN world position once its node transforms apply
    /// (finite file values whose product overflows `f32`).
    #[error("{path}: vertex {vertex} has a non-finite world position {position:?} after its node transforms")]
    NonFiniteWorldPosition {
        /// The file.
        path: PathBuf,
        /// The welded vertex.
        vertex: u64,
        /// Its world position.
        position: [f32; 3],
    },
    /// The mesh has no triangles to show or paint.
    #[error("{path}: the file holds no triangles to paint")]
    NoTriangles {
        /// The file.
        path: PathBuf,
    },
    /// The store refused the per-face resolutions.
    #[error("{path}: {source}")]
    Store {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: StoreError,
    },
    /// The request is past a limit of the budget (checked before anything is allocated).
    #[error("{path}: {source}")]
    Budget {
        /// The file.
        path: PathBuf,
        /// The limit and the counts.
        source: BudgetError,
    },
    /// Packing or unpacking failed.
    #[error("{path}: {source}")]
    Pack {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: PackError,
    },
    /// The saved layers do not fit the document or the budget.
    #[error("{path}: {source}")]
    Layers {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: crate::layers::LayerError,
    },
    /// The caller cancelled the conversion ([`crate::progress::Reporter::cancel`]).
    #[error("{path}: cancelled")]
    Cancelled {
        /// The file.
        path: PathBuf,
    },
}

/// What to open: the built-in scene or a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// The Duck embedded in the binary ([`BUILT_IN_GLB`]).
    BuiltIn,
    /// A .glb / .gltf, .obj, .ply, .stl or packed file.
    File(PathBuf),
}

/// The built-in scene (Khronos Duck, see assets/SOURCES.md), embedded in the binary.
pub const BUILT_IN_GLB: &[u8] = include_bytes!("../../../../assets/models/Duck/Duck.glb");
/// How the built-in scene is named in titles and messages.
pub const BUILT_IN_NAME: &str = "Duck (built-in)";

impl Source {
    /// The name shown in messages: the path, or [`BUILT_IN_NAME`].
    pub fn name(&self) -> String {
        match self {
            Source::BuiltIn => BUILT_IN_NAME.to_owned(),
            Source::File(path) => path.display().to_string(),
        }
    }

    /// The file name for titles (the whole name when it has no file name part).
    pub fn title(&self) -> String {
        match self {
            Source::BuiltIn => BUILT_IN_NAME.to_owned(),
            Source::File(path) => path.file_name().map_or_else(|| self.name(), |n| n.to_string_lossy().into_owned()),
        }
    }
}

/// Where a document came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceKind {
    /// A .glb / .gltf file.
    Gltf,
    /// An OBJ, PLY or STL file.
    Mesh(MeshFormat),
    /// A packed file, in this colour format.
    Packed(ColorFormat),
}

/// How long the phases of [`Document::from_scene_phased`] took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OpenPhases {
    /// Welding the scene into one indexed mesh.
    pub weld: Duration,
    /// Building the topology (edges, incidence).
    pub topology: Duration,
    /// Choosing the face resolutions of a content-driven rule, by phase.
    pub rule: crate::convert::adaptive::RulePhases,
    /// Baking the texture into the store (and fitting it; an error bound's verification
    /// rounds included).
    pub bake: Duration,
    /// Allocating and colouring the store (budget check, resolutions, bake or fill, vertex
    /// colours, the measure below): the phases above and the rest.
    pub store: Duration,
    /// Measuring the converted store against the texture ([`Self::texture_psnr_db`]).
    pub measure: Duration,
    /// The converted colours' PSNR against the base-colour texture over the textured surface
    /// ([`crate::convert::adaptive::texture_psnr`]); `None` without a texture (or for a
    /// packed file), `+∞` when lossless.
    pub texture_psnr_db: Option<f64>,
}

/// An open mesh with its editable colours.
#[derive(Debug, Clone)]
pub struct Document {
    /// World-space vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Topology and colours.
    pub store: ColorStore,
    /// Triangles dropped by welding (0 for packed files).
    pub degenerate_triangles_dropped: u64,
    /// Where it came from.
    pub source: SourceKind,
    /// Importer notes (skipped primitives, ignored features).
    pub warnings: Vec<String>,
    /// Whether some face's material has a base-colour texture (false for packed files: they
    /// keep no texture). The editor turns "resolution follows the brush" on for untextured
    /// documents.
    pub textured: bool,
    /// The layers (docs/LAYERS.md) when the document has them: `store` is then their
    /// composite. `None`: the store is the document's only colour (as before layers).
    pub layers: Option<crate::layers::LayerStack>,
    /// What the conversion that made it showed (a glTF mesh; `None` for a packed file).
    pub conversion: Option<ConversionReport>,
}

/// What a conversion from a mesh shows when it ends: the rule and how well the colours
/// follow the texture.
#[derive(Debug, Clone, PartialEq)]
pub struct ConversionReport {
    /// The rule, as [`ResolutionRule::describe`] says it.
    pub rule: String,
    /// The colours' PSNR against the base-colour texture over the textured surface
    /// ([`crate::convert::adaptive::texture_psnr`], before vertex colours multiply in);
    /// `None` without a texture, `+∞` when lossless.
    pub texture_psnr_db: Option<f64>,
    /// Faces a sample budget held below what their texels could use (zero for other rules).
    pub faces_held_by_budget: u64,
}

impl ConversionReport {
    /// One line for a status bar or log: the rule, the PSNR, the faces the budget held.
    pub fn summary(&self) -> String {
        let mut line = self.rule.clone();
        match self.texture_psnr_db {
            Some(db) if db.is_finite() => line += &format!(", {db:.1} dB against the texture"),
            Some(_) => line += ", lossless against the texture",
            None => {}
        }
        if self.faces_held_by_budget > 0 {
            line += &format!(
                ", {} face{} held below {} texels by the budget",
                self.faces_held_by_budget,
                if self.faces_held_by_budget == 1 { "" } else { "s" },
                if self.faces_held_by_budget == 1 { "its" } else { "their" }
            );
        }
        line
    }
}

/// Bakes the texture into `store` (fitted by `fit`, verified for an error bound) and measures
/// the result against the texture, recording both in `phases`.
fn bake_and_measure(
    store: &mut ColorStore,
    welded: &crate::mesh::weld::WeldedMesh,
    scene: &Scene,
    (rule, fit): (ResolutionRule, BakeFit),
    phases: &mut OpenPhases,
    progress: crate::progress::Progress<'_>,
) -> Result<(), crate::progress::Cancelled> {
    let baking = Instant::now();
    crate::convert::adaptive::bake_and_verify_with(store, welded, scene, rule, fit, progress.part(0.0, 0.9))?;
    phases.bake = baking.elapsed();
    let measuring = Instant::now();
    phases.texture_psnr_db = crate::convert::adaptive::texture_psnr(store, welded, scene, progress.part(0.9, 1.0))?;
    phases.measure = measuring.elapsed();
    Ok(())
}

/// A smooth, deterministic colour field over the bounding box that shows the shape and the
/// resolution of a mesh: three sine waves of different frequency per channel
/// ([`position_colored`]; a view option, untextured meshes open in a neutral colour).
pub fn position_color(position: [f32; 3], bounds_min: [f32; 3], bounds_size: [f32; 3]) -> Rgba {
    let t: [f32; 3] = std::array::from_fn(|a| {
        let size = if bounds_size[a] > 0.0 { bounds_size[a] } else { 1.0 };
        (position[a] - bounds_min[a]) / size
    });
    let wave = |x: f32, phase: f32| 0.5 + 0.5 * (std::f32::consts::TAU * x + phase).sin();
    [wave(1.5 * t[0] + 0.5 * t[1], 0.0), wave(2.0 * t[1] + 0.7 * t[2], 2.0), wave(1.0 * t[2] + 1.3 * t[0], 4.0), 1.0]
}

/// Axis-aligned bounds `(min, size)` of `positions` (zeros when empty).
pub fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in positions {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    if positions.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    (min, std::array::from_fn(|a| max[a] - min[a]))
}

/// The colour an untextured mesh opens in where its faces have no material (the glTF
/// default material is white, which is too bright to paint on): a light grey, linear RGBA
/// (8-bit sRGB 203).
pub const NEUTRAL_BASE_COLOR: Rgba = [0.6, 0.6, 0.6, 1.0];

/// Colours every sample of a mesh without textures or vertex colours: its owner face's
/// material base colour factor, or [`NEUTRAL_BASE_COLOR`] for faces without a material.
fn fill_neutral(store: &mut ColorStore, triangle_materials: &[Option<u32>], scene: &Scene) {
    store.fill_with(|site| {
        triangle_materials
            .get(site.face as usize)
            .copied()
            .flatten()
            .and_then(|m| scene.materials.get(m as usize))
            .map_or(NEUTRAL_BASE_COLOR, |material| material.base_color_factor)
    });
}

/// The colour [`fill_neutral`] gives every sample when it gives all the same one: every face
/// has the same colour (bit for bit) and every vertex belongs to a face (a vertex without
/// faces keeps the store's initial colour there). `None` otherwise.
fn uniform_neutral_color(topology: &Topology, triangle_materials: &[Option<u32>], scene: &Scene) -> Option<Rgba> {
    let color_of = |face: usize| {
        triangle_materials
            .get(face)
            .copied()
            .flatten()
            .and_then(|m| scene.materials.get(m as usize))
            .map_or(NEUTRAL_BASE_COLOR, |material| material.base_color_factor)
    };
    let first = color_of(0);
    let bits = |c: Rgba| c.map(f32::to_bits);
    if (1..topology.face_count() as usize).any(|f| bits(color_of(f)) != bits(first)) {
        return None;
    }
    let mut used = vec![false; topology.vertex_count as usize];
    for corners in &topology.face_vertices {
        for &v in corners {
            used[v as usize] = true;
        }
    }
    used.iter().all(|&u| u).then_some(first)
}

/// `store` with every sample coloured by [`position_color`] at its position on `positions`:
/// a view of the geometry (`render --position-colors`), not a document's content.
pub fn position_colored(store: &ColorStore, positions: &[[f32; 3]]) -> ColorStore {
    let mut out = store.clone();
    fill_with_position_colors(&mut out, positions);
    out.take_dirty();
    out
}

/// Colours every sample of `store` with [`position_color`] at its position on `positions`.
fn fill_with_position_colors(store: &mut ColorStore, positions: &[[f32; 3]]) {
    let (min, size) = bounds(positions);
    let corners = store.topology().face_vertices.clone();
    store.fill_with(|site| {
        let Some(face) = corners.get(site.face as usize) else {
            return [1.0; 4];
        };
        let corner = |k: usize| positions.get(face[k] as usize).copied().unwrap_or([0.0; 3]);
        let (p0, p1, p2) = (corner(0), corner(1), corner(2));
        let p: [f32; 3] = std::array::from_fn(|a| {
            site.barycentric[0] * p0[a] + site.barycentric[1] * p1[a] + site.barycentric[2] * p2[a]
        });
        position_color(p, min, size)
    });
}

/// Colours every sample with the vertex colours (COLOR_0) interpolated across its owner
/// face — exact at the vertices, and exactly what a glTF viewer shows between them. With a
/// base colour already baked, multiplies it (glTF: COLOR_0 scales the base colour).
fn apply_vertex_colors(store: &mut ColorStore, vertex_colors: &[[f32; 4]], multiply: bool) {
    let corners = store.topology().face_vertices.clone();
    // The colours before are needed only to multiply (a copy of the whole store otherwise).
    let current = multiply.then(|| store.clone());
    store.fill_with(|site| {
        let face = corners[site.face as usize];
        let w = site.barycentric;
        let color = |k: usize| vertex_colors.get(face[k] as usize).copied().unwrap_or([1.0; 4]);
        let (c0, c1, c2) = (color(0), color(1), color(2));
        // A weight of exactly 1 returns that corner's colour bit for bit.
        let interpolated: Rgba = match w {
            [1.0, _, _] => c0,
            [_, 1.0, _] => c1,
            [_, _, 1.0] => c2,
            _ => std::array::from_fn(|c| w[0] * c0[c] + w[1] * c1[c] + w[2] * c2[c]),
        };
        match &current {
            Some(current) => {
                let base = current.get(site.sample).unwrap_or([1.0; 4]);
                std::array::from_fn(|c| base[c] * interpolated[c])
            }
            None => interpolated,
        }
    });
}

/// The importer's limits within `budget`: triangles after instancing, nodes and texels.
pub fn import_limits(budget: &Budget) -> ImportLimits {
    let (max_triangles, reason) = budget.triangle_limit();
    ImportLimits {
        max_triangles,
        max_nodes: (budget.memory_bytes / BYTES_PER_NODE).min(1 << 24),
        max_texels: budget.memory_bytes / BYTES_PER_TEXEL,
        reason,
    }
}

/// The first bytes of `path` (fewer when the file is shorter).
pub(super) fn read_head(path: &Path) -> Result<Vec<u8>, DocumentError> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16);
    let file = std::fs::File::open(path).map_err(|source| DocumentError::Io { path: path.to_owned(), source })?;
    file.take(16).read_to_end(&mut head).map_err(|source| DocumentError::Io { path: path.to_owned(), source })?;
    Ok(head)
}

/// Imports a mesh file that is not packed: OBJ / PLY / STL ([`MeshFormat::detect`]) or
/// glTF. The one import path of `Document::open`, `info` and `render --baseline-uv`.
pub fn import_scene(path: &Path) -> Result<(Scene, SourceKind), DocumentError> {
    import_scene_within(path, &Budget::from_environment())
}

/// The scene of `source` (the built-in Duck or a mesh file) within `budget`, as it was
/// imported before conversion to mesh colors: what the UV-textured view of the editor
/// draws. `None` for a packed file, which keeps no source scene.
pub fn import_source_scene(source: &Source, budget: &Budget) -> Result<Option<Scene>, DocumentError> {
    match source {
        Source::BuiltIn => Ok(Some(import_gltf_slice_within(BUILT_IN_GLB, None, "Duck.glb", &import_limits(budget))?)),
        Source::File(path) => {
            let head = read_head(path)?;
            if packed_file::looks_like_packed(&head) {
                return Ok(None);
            }
            Ok(Some(import_scene_after(path, &head, budget)?.0))
        }
    }
}

/// [`import_scene`] within `budget` (a glTF file's triangles after instancing, nodes and
/// texels are checked while it is read).
pub fn import_scene_within(path: &Path, budget: &Budget) -> Result<(Scene, SourceKind), DocumentError> {
    let head = read_head(path)?;
    import_scene_after(path, &head, budget)
}

fn import_scene_after(path: &Path, head: &[u8], budget: &Budget) -> Result<(Scene, SourceKind), DocumentError> {
    match MeshFormat::detect(path, head) {
        Some(format) => Ok((import_mesh_file(path, format)?, SourceKind::Mesh(format))),
        None => Ok((import_gltf_within(path, &import_limits(budget))?, SourceKind::Gltf)),
    }
}

impl Document {
    /// Opens `path`: a packed file (by magic), an OBJ / PLY / STL file
    /// ([`MeshFormat::detect`]) or glTF, meshes at uniform `gltf_resolution`, within
    /// [`Budget::from_environment`].
    ///
    /// A mesh whose materials carry a base-colour texture or a non-white factor is
    /// baked from them ([`crate::convert::bake::bake_texture`]); otherwise each face gets its
    /// material's base colour factor, or [`NEUTRAL_BASE_COLOR`] without a material. Vertex
    /// colours (glTF COLOR_0, OBJ and PLY colours) are applied.
    pub fn open(path: &Path, gltf_resolution: Resolution) -> Result<Self, DocumentError> {
        Self::open_within(path, gltf_resolution, &Budget::from_environment())
    }

    /// [`Document::open`] within `budget`, a mesh at the per-face resolutions of `rule`
    /// (a [`Resolution`] is uniform; [`crate::convert::adaptive`]): a glTF file's triangles (after
    /// instancing), nodes and textures are checked while it is read, its samples before the
    /// store is allocated; a packed file's samples before it is unpacked.
    pub fn open_within(path: &Path, rule: impl Into<ResolutionRule>, budget: &Budget) -> Result<Self, DocumentError> {
        let reporter = crate::progress::Reporter::silent();
        Self::open_reporting(path, rule, budget, reporter.progress())
    }

    /// [`Document::open_within`], reporting the conversion's progress to `progress`
    /// ([`DocumentError::Cancelled`] once it is cancelled).
    pub fn open_reporting(
        path: &Path,
        rule: impl Into<ResolutionRule>,
        budget: &Budget,
        progress: crate::progress::Progress<'_>,
    ) -> Result<Self, DocumentError> {
        let rule = rule.into();
        progress.report(0.0, "reading and importing");
        let head = read_head(path)?;
        if packed_file::looks_like_packed(&head) {
            let (packed, layers) = packed_file::read_file_with_layers(path)?;
            let mut document = Self::from_packed_within(&packed, budget).map_err(|source| match source {
                PackError::Budget(source) => DocumentError::Budget { path: path.to_owned(), source },
                source => DocumentError::Pack { path: path.to_owned(), source },
            })?;
            if let Some(section) = layers {
                document
                    .attach_layers(&section, budget)
                    .map_err(|source| DocumentError::Layers { path: path.to_owned(), source })?;
            }
            return Ok(document);
        }
        let (scene, kind) = import_scene_after(path, &head, budget)?;
        let mut document = Self::from_scene_phased(
            scene,
            rule,
            BakeFit::default(),
            path,
            budget,
            &mut OpenPhases::default(),
            progress.part(0.05, 1.0),
        )?;
        document.source = kind;
        Ok(document)
    }

    /// Opens `source`: the built-in scene or a file, as [`Document::open`] does.
    pub fn open_source(source: &Source, rule: impl Into<ResolutionRule>) -> Result<Self, DocumentError> {
        Self::open_source_within(source, rule, &Budget::from_environment())
    }

    /// [`Document::open_source`] within `budget`.
    pub fn open_source_within(
        source: &Source,
        rule: impl Into<ResolutionRule>,
        budget: &Budget,
    ) -> Result<Self, DocumentError> {
        match source {
            Source::BuiltIn => {
                let scene = import_gltf_slice_within(BUILT_IN_GLB, None, "Duck.glb", &import_limits(budget))?;
                Self::from_scene_within(scene, rule, Path::new(BUILT_IN_NAME), budget)
            }
            Source::File(path) => Self::open_within(path, rule, budget),
        }
    }

    /// The colour format the document is shown and saved in by default: a packed file's own
    /// format, RGBA8 sRGB for glTF.
    pub fn display_format(&self) -> ColorFormat {
        match self.source {
            SourceKind::Packed(format) => format,
            SourceKind::Gltf | SourceKind::Mesh(_) => ColorFormat::default(),
        }
    }

    /// A document from a glTF scene already in memory (e.g. a model embedded in the binary and
    /// read with [`crate::mesh::import::import_gltf_slice`]) at uniform `gltf_resolution`, coloured
    /// as [`Document::open`] colours glTF files; `name` stands for the file in errors.
    pub fn from_scene(scene: Scene, gltf_resolution: Resolution, name: &Path) -> Result<Self, DocumentError> {
        Self::from_scene_within(scene, gltf_resolution, name, &Budget::from_environment())
    }

    /// [`Document::from_scene`] within `budget`: the triangles are checked before welding,
    /// the samples at `gltf_resolution` before the store is allocated.
    pub fn from_scene_within(
        scene: Scene,
        rule: impl Into<ResolutionRule>,
        name: &Path,
        budget: &Budget,
    ) -> Result<Self, DocumentError> {
        let reporter = crate::progress::Reporter::silent();
        Self::from_scene_phased(
            scene,
            rule,
            BakeFit::default(),
            name,
            budget,
            &mut OpenPhases::default(),
            reporter.progress(),
        )
    }

    /// [`Document::from_scene_within`] with the texture baked by `fit` (the default is the
    /// least-squares fit, [`crate::convert::least_squares`]), recording how long each phase took in
    /// `phases` (`meshpaint bench load`, `bench adaptive`) and reporting to `progress`
    /// (choosing the resolutions, then baking; [`DocumentError::Cancelled`] once cancelled).
    pub fn from_scene_phased(
        scene: Scene,
        rule: impl Into<ResolutionRule>,
        fit: BakeFit,
        name: &Path,
        budget: &Budget,
        phases: &mut OpenPhases,
        progress: crate::progress::Progress<'_>,
    ) -> Result<Self, DocumentError> {
        let rule = rule.into();
        let budget_error = |source| DocumentError::Budget { path: name.to_owned(), source };
        let cancelled = |_| DocumentError::Cancelled { path: name.to_owned() };
        // Where the time goes: a content-driven rule's choice, then the bake and fit.
        let (choose, bake) = match rule {
            ResolutionRule::Uniform(_) | ResolutionRule::WhereTextured(_) => {
                (progress.part(0.0, 0.05), progress.part(0.05, 1.0))
            }
            _ => (progress.part(0.0, 0.6), progress.part(0.6, 1.0)),
        };
        progress.report(0.0, "welding");
        budget.check_triangles("the scene", scene.instanced_triangle_count() as u64).map_err(budget_error)?;
        let started = Instant::now();
        let welded = weld_scene(&scene);
        phases.weld = started.elapsed();
        let started = Instant::now();
        if let Some((vertex, position)) =
            (0u64..).zip(&welded.positions_world).find(|(_, p)| !p.iter().all(|c| c.is_finite()))
        {
            return Err(DocumentError::NonFiniteWorldPosition { path: name.to_owned(), vertex, position: *position });
        }
        let topology = Topology::build(welded.positions_world.len() as u32, &welded.triangles)
            .map_err(|source| DocumentError::Topology { path: name.to_owned(), source })?;
        phases.topology = started.elapsed();
        let started = Instant::now();
        let resolutions = match rule {
            ResolutionRule::Uniform(r) => {
                let counts = SampleCounts::uniform_on(&topology, r);
                budget
                    .check(&format!("R = {r} on every face"), &counts, ColorFormat::default())
                    .map_err(budget_error)?;
                vec![r; topology.face_count() as usize]
            }
            rule => {
                // The budget rule stays within the packed limit by construction; every rule's
                // result is checked before the store is allocated.
                let resolutions = crate::convert::adaptive::face_resolutions_phased(
                    &welded,
                    &scene,
                    topology.face_count() as usize,
                    rule,
                    fit,
                    &mut phases.rule,
                    choose,
                )
                .map_err(cancelled)?;
                let counts = SampleCounts::of_resolutions(&topology, |f| resolutions[f as usize]);
                budget.check(&rule.describe(), &counts, ColorFormat::default()).map_err(budget_error)?;
                resolutions
            }
        };
        let has_base_color = crate::convert::bake::has_base_color(&welded, &scene);
        let neutral = !has_base_color && welded.vertex_colors.is_empty();
        // One colour on every face and no unused vertex: the neutral fill is that colour
        // everywhere, so the store is built with it and not filled a second time.
        let uniform = if neutral { uniform_neutral_color(&topology, &welded.triangle_materials, &scene) } else { None };
        let mut store = ColorStore::with_resolutions(topology, resolutions, uniform.unwrap_or([1.0; 4]))
            .map_err(|source| DocumentError::Store { path: name.to_owned(), source })?;
        if has_base_color {
            bake_and_measure(&mut store, &welded, &scene, (rule, fit), phases, bake).map_err(cancelled)?;
        } else if neutral && uniform.is_none() {
            fill_neutral(&mut store, &welded.triangle_materials, &scene);
        }
        if !welded.vertex_colors.is_empty() {
            apply_vertex_colors(&mut store, &welded.vertex_colors, has_base_color);
        }
        store.take_dirty();
        let textured = welded
            .triangle_materials
            .iter()
            .any(|m| m.and_then(|m| scene.materials.get(m as usize)).is_some_and(|m| m.base_color_texture.is_some()));
        phases.store = started.elapsed();
        progress.report(1.0, "converted");
        let conversion = ConversionReport {
            rule: rule.describe(),
            texture_psnr_db: phases.texture_psnr_db,
            faces_held_by_budget: phases.rule.faces_held_by_budget,
        };
        Ok(Document {
            textured,
            conversion: Some(conversion),
            positions: welded.positions_world,
            store,
            degenerate_triangles_dropped: welded.degenerate_triangles_dropped,
            source: SourceKind::Gltf,
            warnings: scene.warnings,
            layers: None,
        })
    }

    /// A document from packed buffers (level 0 becomes the store).
    pub fn from_packed(packed: &PackedMesh) -> Result<Self, PackError> {
        Self::from_packed_within(packed, &Budget::from_environment())
    }

    /// [`Document::from_packed`] within `budget` (checked before the store is allocated).
    pub fn from_packed_within(packed: &PackedMesh, budget: &Budget) -> Result<Self, PackError> {
        Ok(Document {
            positions: packed.positions.clone(),
            store: crate::packing::unpack::unpack_within(packed, budget)?,
            degenerate_triangles_dropped: 0,
            source: SourceKind::Packed(packed.format),
            warnings: Vec::new(),
            textured: false,
            conversion: None,
            layers: None,
        })
    }

    /// Gives the document the layers of a saved layers section (its store becomes their
    /// composite, recomputed from the layers: they are the source).
    pub fn attach_layers(
        &mut self,
        section: &packed_file::LayersSection,
        budget: &Budget,
    ) -> Result<(), crate::layers::LayerError> {
        let mut stack = crate::layers::file::from_section(section, &self.store, self.display_format(), budget)?;
        stack.sync(&mut self.store);
        self.store.take_dirty();
        self.layers = Some(stack);
        Ok(())
    }

    /// Whether the store is exactly its layers' composite (true without layers). False when
    /// the store was changed without going through the layers (e.g. painted by a tool that
    /// does not know them yet): saving the layers would then lose that change.
    pub fn layers_in_sync(&self) -> bool {
        let Some(stack) = &self.layers else {
            return true;
        };
        let mut composite = self.store.clone();
        stack.composite_into(&mut composite) == 0
    }

    /// The layers section a save in `format` writes (`None` without layers: a version-1 file).
    pub fn layers_section(&self, format: ColorFormat) -> Option<packed_file::LayersSection> {
        self.layers.as_ref().map(|stack| crate::layers::file::to_section(stack, format))
    }

    /// Packs the document and writes it to `path` as a packed file in `format`, with its
    /// layers when it has them (atomically, [`packed_file::write_file_with_layers`]).
    pub fn write_packed(&self, path: &Path, format: ColorFormat) -> Result<PackedMesh, DocumentError> {
        let packed = self.pack(format).map_err(|source| DocumentError::Pack { path: path.to_owned(), source })?;
        packed_file::write_file_with_layers(path, &packed, self.layers_section(format).as_ref())?;
        Ok(packed)
    }

    /// Packs the document into linear buffers in `format`.
    pub fn pack(&self, format: ColorFormat) -> Result<PackedMesh, PackError> {
        packer::pack(&self.store, &self.positions, format)
    }
}
