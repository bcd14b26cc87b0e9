//! Measurements behind `meshpaint bench …`: every figure we report comes from here, and
//! each measures what the editor really does.

pub mod adaptive;
pub mod brush_edge;
pub mod extremes;
pub mod latency;
pub mod load;
pub mod pack;
pub mod paint;
pub mod plot;
pub mod render;
pub mod trade;

pub use load::{BenchLoadError, bench_load};
pub use pack::{Timing, bench_pack};
pub use paint::{PaintBenchOptions, bench_paint};
pub use render::{BenchRenderError, ModeTiming, RenderBench, bench_render};
