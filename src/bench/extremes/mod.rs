//! `meshpaint bench extremes`: the numerical extremes (issue 12, item 3), each measured
//! against an independent truth and reported with the tolerance its test enforces.
//!
//! One [`ExtremeCase`] per case: `case`, the `measured` error with its `unit`, the
//! `tolerance`, the `test` that enforces it, and the `outcome` (what the program does:
//! measured, sanitised or refused, with the message). `tests/app/extremes.rs` runs
//! [`extreme_cases`] and fails when any case is over its tolerance or unsound (too few
//! pixels compared, coverage errors), and runs `meshpaint bench extremes --json`.
//!
//! | case | truth | measured |
//! |---|---|---|
//! | `r4096_perspective_{linear,nearest}` | `f64` ray cast per pixel → face and barycentrics → CPU reference sampler | largest per-channel difference of the GPU render, 8-bit steps |
//! | `shader_index_precision_r4096` | the same, nearest, nothing skipped | the largest distance (lattice units) from a cell boundary of a pixel where the GPU reads another sample than `f64` says; and the `f32` lattice error of the index computation alone |
//! | `offset_1e5/1e6`, `scale_1e-4` `_render` / `_pick` / `_paint` | render: as above; pick: the unoffset mesh's hit, transformed in `f64`; paint: the unoffset mesh's painted samples | steps; ulps of `f32` at the mesh's coordinates; samples painted differently |
//! | `sliver_*`, `valence_200_*` | ray cast per pixel; brute-force ray cast for picks | steps; faces picked differently |
//! | `rgba16f_max_finite`, `add_blend_hdr` | the value written | decode error; render code |
//! | `non_finite_colors` | the rule of docs/FORMAT.md "Colour values" | non-finite values that got through |
//! | `grazing_brush_{deg}` | ray–plane hit in `f64`; the closed-form disc `|p − c| ≤ r` | pick error in pixels; samples painted differently |

mod geometry;
mod probe;
mod values;

use thiserror::Error;

use meshpaint_render::{Gpu, RenderError};

/// Largest per-channel GPU-vs-CPU difference the render cases allow, 8-bit steps (the
/// `MAX_STEPS` of `tests/app/gpu_render.rs`).
pub const MAX_STEPS: f64 = 1.0;
/// Nearest filtering: pixels within this many lattice units of a cell boundary cannot be
/// called (the `CELL_MARGIN` of `tests/app/gpu_render.rs`).
pub const CELL_MARGIN: f64 = 1e-3;

/// Errors of the extremes benchmark (a case that could not be set up, or the GPU).
#[derive(Debug, Error)]
pub enum ExtremesError {
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A case could not be built (store, packing, painting).
    #[error("{0}")]
    Setup(String),
}

impl ExtremesError {
    fn setup(error: impl std::fmt::Display) -> Self {
        ExtremesError::Setup(error.to_string())
    }
}

/// One measured extreme.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtremeCase {
    /// The case's name (stable, for scripts).
    pub case: String,
    /// The error measured.
    pub measured: f64,
    /// Its unit.
    pub unit: &'static str,
    /// The largest error the test allows.
    pub tolerance: f64,
    /// The test that enforces the tolerance.
    pub test: &'static str,
    /// What the program does at this extreme: `measured`, `sanitised: …`, `refused: …`.
    pub outcome: String,
    /// `false` when the measurement itself is not meaningful (too few pixels compared,
    /// coverage errors, a refusal that did not happen).
    pub sound: bool,
    /// The case's other numbers.
    pub detail: serde_json::Value,
}

impl ExtremeCase {
    /// Whether the case is sound and within its tolerance.
    pub fn passes(&self) -> bool {
        self.sound && self.measured <= self.tolerance
    }

    /// As one JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "bench": "extremes",
            "case": self.case,
            "measured": self.measured,
            "unit": self.unit,
            "tolerance": self.tolerance,
            "within_tolerance": self.passes(),
            "test": self.test,
            "outcome": self.outcome,
            "sound": self.sound,
            "detail": self.detail,
        })
    }
}

/// Every case, measured on `gpu`.
pub fn extreme_cases(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let mut cases = geometry::r4096_perspective(gpu)?;
    cases.extend(geometry::offsets(gpu)?);
    cases.extend(geometry::slivers_and_valence(gpu)?);
    cases.extend(geometry::grazing_brush()?);
    cases.extend(values::value_extremes(gpu)?);
    Ok(cases)
}

/// Every case as one JSON object (for `bench extremes` and for `bench trade` to include).
pub fn extremes_rows(gpu: &Gpu) -> Result<Vec<serde_json::Value>, ExtremesError> {
    Ok(extreme_cases(gpu)?.iter().map(ExtremeCase::to_json).collect())
}
