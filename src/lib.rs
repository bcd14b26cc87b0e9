//! # meshpaint — paint colour directly on triangle meshes with mesh colors
//!
//! Colour lives in *mesh colors* (Yuksel et al. 2010): samples on every vertex, edge
//! and face of each triangle at a per-face power-of-two resolution `R`, shared along
//! edges so that painting has no seams and needs no UV map.
//!
//! ## Architecture
//!
//! The crate is split into a GPU-free core and an application shell. Core modules never
//! import `wgpu`, `egui` or `winit`; they are exact, deterministic and tested against
//! independent truths (closed-form counts, brute-force enumeration).
//!
//! | module | responsibility |
//! |---|---|
//! | [`scene`] | imported data: source meshes, instances, materials, textures |
//! | [`import`] | glTF (.glb/.gltf) → [`scene::Scene`], every bad input refused with a message |
//! | [`weld`] | scene → one indexed mesh; vertices with bitwise-equal positions merged per mesh instance |
//! | [`topology`] | unique edges, face→edge incidence, boundary / non-manifold edges, valence |
//! | [`layout`] | mesh-colors layout math: sample counts, sample classification, MIP offsets, filtering |
//! | [`stats`] | the numbers `meshpaint info` prints |
//! | [`color`] | linear RGBA, sRGB transfer, packed colour formats (RGBA8 sRGB / 16F / 32F) |
//! | [`store`] | the editable map-based store: per-element samples, per-face resolution, dirty tracking |
//! | [`resample`] | exact-inverse 2× refinement / reduction used when a face's resolution changes |
//! | [`packed`] | the linear GPU layout: 16-byte face records and the colour buffer with MIP chains |
//! | [`packer`] | store → packed (MIP chains, eq. 2.5/2.6) and packed → store |
//! | [`paint_layout`] | the paint-mode GPU layout: level 0 in blocks with slack; dirty ranges and patched records |
//! | [`sampler`] | the CPU reference sampler (nearest, linear, MIP level) on the store and on packed buffers |
//! | [`document`] | open glTF or packed files into a store; pack for export |
//! | [`export_gltf`] | store → .glb tessellated at each face's resolution, one vertex (COLOR_0) per sample |
//! | [`camera`] | the orbit camera: matrices, framing, pixel rays (shared by render, picking, replay) |
//! | [`picking`] | obvhs BVH over the mesh, watertight ray casts with our own barycentrics |
//! | [`brush`] | painting: colour / blur / resolution brushes, stroke dabs, occlusion, mirror, eyedropper, fill |
//! | [`undo`] | undo / redo per stroke: changed samples and resolution changes only, memory cap |
//! | [`autosave`] | periodic atomic RGBA32F recovery files; find and load them after a crash |
//! | [`bake`] | base-colour texture → mesh colors (texture conversion) |
//! | [`render`] | **GPU**: wgpu context, packed buffers on the GPU, sampling pipelines, readback |
//! | [`bench`](mod@bench) | the measurements behind `meshpaint bench` (time and size, as JSON) |
//! | [`packed_file`] | the packed file format (docs/FORMAT.md): writer and hostile-input-proof reader |
//! | [`app`] | **GPU + UI**: the desktop editor (winit, egui, wgpu): window, panels, input, background jobs |
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
//! paint:  cursor → ray → BVH → brush → store → dirty ranges → GPU upload
//! ```
//!
//! The binary (`src/main.rs`) and the editor ([`app`]) are the only places where everything meets.

pub mod app;
pub mod autosave;
pub mod bake;
pub mod bench;
pub mod brush;
pub mod camera;
pub mod color;
pub mod document;
pub mod export_gltf;
pub mod import;
pub mod layout;
pub mod packed;
pub mod packed_file;
pub mod packer;
pub mod paint_layout;
pub mod picking;
pub mod render;
pub mod resample;
pub mod sampler;
pub mod scene;
pub mod stats;
pub mod store;
pub mod topology;
pub mod undo;
pub mod weld;
