//! The core's tests in one binary (one link, no GPU or UI crate): each module is one
//! concern's tests against an independent truth.

mod common;

mod adaptive_extremes;
mod bake;
mod conversion_psnr;
mod examples;
mod follow_brush;
mod fuzz;
mod hard_edge;
mod htex;
mod import;
mod layers;
mod layers_file;
mod layout;
mod least_squares;
mod mct;
mod mct_file;
mod occlusion;
mod optimize;
mod packed_file;
mod packer;
mod paint_in_place;
mod paint_layout;
mod picking;
mod progress;
mod ptex;
mod ptex_file;
mod repack;
mod seams;
mod store;
mod topology;
mod undo;
mod unwrap;
