//! # meshpaint-core — mesh colors without a GPU
//!
//! Colour lives in *mesh colors* (Yuksel et al. 2010): samples on every vertex, edge and
//! face of each triangle at a per-face power-of-two resolution `R`, shared along edges so
//! that painting has no seams and needs no UV map. This crate is everything that is not
//! drawing: meshes, the mesh-colors layout and store, packing and the packed file, picking,
//! the brush and undo, conversion. It never depends on `wgpu`, `egui` or `winit`, so an
//! engine that reads packed files or a batch converter depends on it alone
//! (`examples/read_packed.rs`). Everything is exact, deterministic and tested against
//! independent truths (closed-form counts, brute force, a serial reference packer).
//!
//! ## Architecture
//!
//! | folder | holds |
//! |---|---|
//! | [`mesh`] | [`mesh::scene`] (imported data), [`mesh::import`] (glTF → scene, every bad input refused with a message), [`mesh::formats`] (OBJ / PLY / STL → scene, the same refusals), [`mesh::weld`] (one indexed mesh, bitwise-equal positions merged per instance), [`mesh::topology`] (edges, incidence, boundary / non-manifold, valence), [`mesh::orientation`] (winding consistency, signed volume of closed components) |
//! | [`colors`] | the mesh-colors core: [`colors::layout`] (sample counts, classification, MIP offsets, filtering), [`colors::format`] (linear RGBA, sRGB, RGBA8 / 16F / 32F), [`colors::store`] (the map-based store with per-face R and dirty tracking), [`colors::resample`] (exact 2× refine / reduce), [`colors::stats`] (the sample budget `info` prints), [`colors::budget`] (the limits every operation that creates samples checks first: counts, memory, packed format, GPU) |
//! | [`packing`] | [`packing::linear`] (16-byte face records, colour buffer with MIP chains), [`packing::canonical`] (where each chain starts), [`packing::packer`] (store ⇄ linear, eq. 2.5/2.6, rayon; `PackCache` repacks only the chains an edit reaches, lays out anew after resolution changes moving the chains no edit reached, or packs all of them into its old buffers), [`packing::reference`] (the serial packer both are tested against byte for byte), [`packing::unpack`] (linear → store), [`packing::paint_layout`] (paint-mode blocks with slack, dirty ranges), [`packing::sampler`] (the CPU reference sampler, the truth the GPU is tested against), [`packing::file`] (the packed file format) |
//! | [`paint`] | [`paint::picking`] (obvhs BVH, watertight rays), [`paint::occlusion`] (a CPU depth map of the view: brush occlusion without a ray per sample), [`paint::brush`] (colour / blur / resolution brushes, tools, replay), [`paint::undo`] (per stroke, memory cap; the one write path, `StoreWriter`), [`paint::split`] (that write path split per element for parallel dabs), [`paint::optimize`] (lower each face's R while the error stays within a bound) |
//! | [`layers`] | material layers (docs/LAYERS.md): [`layers::blend`] (normal, multiply, add, overlay over a backdrop, straight alpha), [`layers::layer`] (name, visibility, opacity, blend, content and paintable mask, each store with its own undo), [`layers::compose`] (the composite sample by sample, per face or per dirty element), [`layers::stack`] (painting the active layer through the one write path, keeping the composite current), [`layers::ops`] (add, delete, reorder, opacity, blend, visibility, rename, mask; undo and redo in one history with the paint steps) |
//! | [`mct`] | Mesh Color Textures (Yuksel 2017): packed mesh colors → one 2D atlas the GPU's bilinear sampler filters ([`mct::layout`]: pairs, tents and squares, 4-byte records; [`mct::build`]; [`mct::sample`]: the CPU evaluation the shader is tested against; [`mct::file`]: the MCT file, docs/MCT_FORMAT.md) |
//! | [`htex`] | Htex (Barbier & Dupuy 2022): packed mesh colors → one square texture per edge (halfedge + twin) in atlas pages with zero borders, three fetches with a border-normalisation channel ([`htex::halfedge`], [`htex::layout`], [`htex::build`], [`htex::sample`]: the CPU evaluation the shader is tested against, [`htex::jumps`]) |
//! | [`ptex`] | packed Ptex (Kim, Hillesland, Hensley 2011): per-pair square blocks with every MIP level, sorted by resolution into one texture with one-texel borders from the neighbours ([`ptex::layout`]: pairs, `nRes` / `nRow`; [`ptex::build`]; [`ptex::sample`]: the CPU evaluation of bilinear and trilinear) |
//! | [`convert`] | one signal into another: [`convert::bake`] (texture → mesh colors, point bake), [`convert::least_squares`] (the bake refined to the least-squares fit of the reconstruction), [`convert::adaptive`] (each face at the resolution its content needs), [`convert::bake_uv`] (mesh colors → the model's UV texture), [`convert::subdivide`] (1→4 midpoint split of a scene, budget first) |
//! | [`io`] | files only: [`io::document`] (open glTF, OBJ, PLY, STL or packed files into a store — the one open path; pack for export), [`io::export_gltf`], [`io::export_fit`], [`io::export_textured`], [`io::autosave`] |
//! | [`synth`] | synthetic inputs for tests, benchmarks and the fuzzer: the deterministic random sources and small meshes built in code (one copy each) |
//! | [`atomic_write`] | the one way files are written: temporary file, `sync_all`, rename, directory sync |
//! | [`memory`] | fresh buffers a document's bulk is written into once (the store's chunks on open, packed colours, the paint layout's bytes): transparent huge pages advised before the first write |
//! | [`progress`] | progress by phase and items done, and cooperative cancel, of long operations (open, convert, pack): the caller's [`progress::Reporter`], the operation's [`progress::Progress`] parts |
//! | [`threads`] | the main thread's pool (the editor's UI thread works in it, so a small parallel call does not wait for sleeping workers); background jobs use rayon's global pool |
//! | [`camera`] | the orbit camera: matrices, framing, pixel rays (shared by render, picking, replay) |
//!
//! Folders depend on each other without cycles, and so do the files of one folder
//! (`tests/app/architecture.rs` at the workspace root checks both).
//!
//! ## Data flow
//!
//! Data flows one way:
//!
//! ```text
//! load:   file ─ import ─▶ Scene ─ weld ─▶ WeldedMesh ─ topology ─▶ Topology
//!                                                         │
//! edit:                         store (maps: vertex / edge / face → samples)
//!                                                         │ pack (MIP chains)
//! show:                         linear buffers (face records + colours) ─▶ GPU / export
//!                                                         │ mct::build
//!                               Mesh Color Texture (atlas + 4-byte records) ─▶ GPU / export
//! paint:  cursor → ray → BVH → brush → StoreWriter → store → dirty ranges → GPU upload
//! ```
//!
//! The GPU renderer is the crate `meshpaint-render`; the editor, the command line and the
//! benchmarks are the crate `meshpaint`, the only place where everything meets.

pub mod atomic_write;
pub mod camera;
pub mod colors;
pub mod convert;
pub mod htex;
pub mod io;
pub mod layers;
pub mod mct;
pub mod memory;
pub mod mesh;
pub mod packing;
pub mod paint;
pub mod progress;
pub mod ptex;
pub mod synth;
pub mod threads;
