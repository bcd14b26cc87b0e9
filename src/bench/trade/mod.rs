//! `meshpaint bench trade`: what every choice costs and what it buys, side by side —
//! representation (mesh colors with the shader's software filter, or the Mesh Color Texture
//! built from the same packed buffers and filtered by the GPU's sampler) × filter (nearest,
//! linear, fixed MIP level, trilinear) × resolution (uniform R and the content-driven
//! `--error` bounds) × colour format (RGBA8 / RGBA16F / RGBA32F), each seen from several
//! distances, plus BVH presets and the seam error across edges.
//!
//! # Representations
//!
//! Every `config` row names its `representation`: `mesh-colors` (all of [`FILTERS`]) or
//! `mct` (the [`MCT_FILTERS`]: linear = hardware bilinear at level 0, mip-k = level k,
//! trilinear = two hardware-bilinear levels at mesh colors' continuous level of detail; MCT
//! has no nearest filter). The MCT of a row is built ([`meshpaint_core::mct::build`]) from the
//! very packed mesh of the mesh-colors rows of the same resolution and format, and drawn with
//! its geometry. The `baseline` rows are `uv-texture`. A format whose MCT cannot be built or
//! uploaded (an RGBA32F atlas on a GPU without `FLOAT32_FILTERABLE`, an atlas over the largest
//! texture side) gets one `skipped` row saying why.
//!
//! # Error
//!
//! Each configuration is rendered unlit at the image size, as a user sees it (no
//! supersampling: MIP levels and trilinear exist to fight exactly that aliasing), and compared
//! with a reference rendered at 4× per side and box-filtered 4×4
//! ([`super::adaptive::render_supersampled`], the reference of `bench adaptive`):
//!
//! - a glTF with a base-colour texture: its UV-textured render (the baseline pipeline, every
//!   material's factor × texture, hardware trilinear);
//! - anything else (a painted packed file, an untextured mesh): the same document packed in
//!   RGBA32F, mesh colors' linear filter at level 0 — per resolution choice, so the figure
//!   isolates what the representation, the filter and the format lose (an untextured glTF is
//!   swept over uniform R like a textured one; a packed file is measured at its own
//!   resolutions). Frame ratios are then to `bench render`'s synthetic planar UV baseline.
//!
//! Both representations of a choice are compared with the same reference on the same pixels:
//! where the reference's 16 subsamples are all covered and the test render covers the pixel
//! (the silhouette, whose aliasing no colour setting changes, is left out). Reported: PSNR
//! over RGB of the 8-bit sRGB images, the largest absolute difference in 8-bit steps, and the
//! mean FLIP error (NVIDIA's perceptual metric, `nv-flip`, on the same pixels; 0 = identical,
//! 1 = maximal).
//!
//! # Cost
//!
//! Level-0 samples, samples with MIP chains, GPU bytes (`gpu_bytes`: everything the
//! representation needs on the GPU — the shared geometry textures plus, for mesh colors, the
//! face records and colour atlas, for MCT, its atlas, records and band table; each split out
//! as `geometry_bytes` and `color_gpu_bytes`), for MCT the ratio of its atlas + records + band
//! table to the packed face records + colours (`mct_bytes_over_mesh_colors`, CPU sizes without
//! atlas-row padding), pack time and MCT build time (best of three each), frame time as a
//! ratio to the UV-texture baseline (every configuration of both representations and the
//! baseline timed interleaved round by round in this one run, at the image size, per view;
//! [`super::render::FrameTimer`], the timer of `bench render`), and for mesh colors the
//! paint-mode dab throughput at that resolution ([`super::paint::dab_throughput`]; painting
//! edits mesh colors, an MCT is rebuilt from them).
//!
//! # Seams
//!
//! For every edge with two or more faces, each pair of its faces is evaluated at the same
//! points along the edge, `t = k/n` with `n = max(32, 2 · largest R)` (exact in `f32`, and
//! between the lattice points of every level), per filter and MIP level; a `seam` row
//! reports the largest and mean jump (colour units, 0..1, linear) between the two sides, with
//! the number of edges compared and how many of them join faces of different R. Mesh colors:
//! the CPU reference sampler on the RGBA32F pack (nearest, linear, trilinear at `level + 0.5`).
//! MCT: its CPU evaluation of the hardware filter ([`meshpaint_core::mct::sample`]: bilinear
//! at every level, trilinear at `level + 0.5`) in every measured format, so RGBA8's clamped
//! ring texels show.
//!
//! # BVH
//!
//! Per preset: build time, pick latency on rays through a 64 × 64 pixel grid that hit the mesh,
//! and how many of those picks agree with a brute-force Möller–Trumbore over every triangle
//! (same face, or the same `t` within 1e-9 relative where two faces tie on a shared edge).
//!
//! | file | holds |
//! |---|---|
//! | [`choices`] | the resolution choices, their packs, MCTs and dab throughput |
//! | [`study`] | per view: references, interleaved frame times, the `baseline` and `config` rows |
//! | [`run`] | [`bench_trade`]: the whole study in order |
//! | [`metrics`] | image error (PSNR, max error, FLIP) and JSON helpers |
//! | [`seams`] | the seam measurement of both representations |
//! | [`bvh`] | BVH presets against brute force |
//! | [`points`] | the plot points and [`write_plots`] |

pub mod bvh;
pub mod choices;
pub mod metrics;
pub mod points;
pub mod run;
pub mod seams;
pub mod study;

pub use crate::bench::plot::pareto_front;
pub use bvh::brute_force;
pub use metrics::{ImageError, compare};
pub use points::{plot_points, write_plots};
pub use run::{bench_trade, bench_trade_streaming};
pub use seams::{SeamEdges, SeamJump, mct_seam_jumps, ptex_seam_jumps, seam_jumps, seam_jumps_over};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_render::FilterMode;

/// What `bench trade` measures.
#[derive(Debug, Clone, PartialEq)]
pub struct TradeOptions {
    /// View directions (yaw 30° + k·360°/views, pitch 20°), each at every distance of [`DISTANCES`].
    pub views: u32,
    /// Image side, pixels (the reference is rendered at 4× this).
    pub size: u32,
    /// Uniform resolutions measured.
    pub uniform: Vec<Resolution>,
    /// `--error` bounds measured (textured glTF only).
    pub error_bounds: Vec<f32>,
    /// The largest R the error bounds give a face.
    pub max_resolution: Resolution,
    /// Colour formats measured.
    pub formats: Vec<ColorFormat>,
    /// Whether Mesh Color Texture rows are measured beside mesh colors.
    pub mct: bool,
    /// Whether Htex rows are measured beside mesh colors.
    pub htex: bool,
    /// Whether packed Ptex rows are measured beside mesh colors.
    pub ptex: bool,
    /// Interleaved timing rounds per view (the median frame is reported).
    pub frames: usize,
    /// Dabs per throughput measurement.
    pub dabs: usize,
}

impl Default for TradeOptions {
    fn default() -> Self {
        TradeOptions {
            views: 1,
            size: 256,
            uniform: (0..=5).filter_map(|l| Resolution::from_log2(l).ok()).collect(),
            error_bounds: vec![0.05, 0.02, 0.01, 0.005],
            max_resolution: Resolution::from_log2(6).unwrap_or(Resolution::MAX),
            formats: ColorFormat::ALL.to_vec(),
            mct: true,
            htex: true,
            ptex: true,
            frames: 5,
            dabs: 10,
        }
    }
}

/// Camera distances, as multiples of the framing distance (the whole bounding sphere in view):
/// near (the mesh overflows the image: magnification), mid, far and tiny (the mesh a few dozen
/// pixels across: minification, where MIP levels matter).
pub const DISTANCES: [(&str, f64); 4] = [("near", 0.5), ("mid", 1.0), ("far", 4.0), ("tiny", 12.0)];

/// The mesh-colors filters measured, with their names in the report.
pub const FILTERS: [(&str, FilterMode); 5] = [
    ("nearest", FilterMode::Nearest),
    ("linear", FilterMode::Linear),
    ("mip-1", FilterMode::MipLevel(1)),
    ("mip-2", FilterMode::MipLevel(2)),
    ("trilinear", FilterMode::Trilinear),
];

/// The Mesh Color Texture filters measured (MCT has no nearest filter: the renderer would
/// draw bilinear).
pub const MCT_FILTERS: [(&str, FilterMode); 4] = [
    ("linear", FilterMode::Linear),
    ("mip-1", FilterMode::MipLevel(1)),
    ("mip-2", FilterMode::MipLevel(2)),
    ("trilinear", FilterMode::Trilinear),
];
