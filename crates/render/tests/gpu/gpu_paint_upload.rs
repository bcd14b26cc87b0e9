//! Paint mode's partial uploads checked on the GPU itself: after random edits and random
//! resolution changes, the editor's upload path (PaintLayout::sync → EncodedBuffer::apply →
//! write_paint_upload: the dirty ranges merged into spans across small gaps, the gaps' bytes
//! from the CPU copy, and write_face_records for moved blocks, or a full upload when the
//! layout grew) must leave the GPU's colour atlas and face records such that every lattice point of
//! every face, addressed as the shaders address it from the read-back records, holds the
//! store's colour (quantised to the format). The comparison is shown to fail on one
//! corrupted sample. wgpu errors outside the renderer's error scopes panic in these tests
//! (tests/common/gpu.rs), and that too is shown.

use crate::common;
use crate::common::WriteThrough;

use common::gpu::Gpu;
use common::{SplitMix64, icosphere};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::{EncodedBuffer, PaintLayout};
use meshpaint_core::packing::sampler::packed_sample_index;
use meshpaint_render::{GpuMesh, MeshUploadOptions};

/// Compares the GPU copy with the store at every level-0 lattice point; returns the
/// mismatches (face, i, j, GPU colour, store colour), at most 10.
fn mismatches(gpu: &Gpu, mesh: &GpuMesh, store: &ColorStore, format: ColorFormat) -> Vec<String> {
    let colors = mesh.read_samples(&gpu.ctx).unwrap();
    let face_records = mesh.read_face_records(&gpu.ctx).unwrap();
    let on_gpu = PackedMesh {
        positions: Vec::new(),
        indices: store.topology().face_vertices.clone(),
        vertex_levels: mesh.vertex_levels,
        face_records,
        format,
        colors,
    };
    let mut out = Vec::new();
    for face in 0..store.topology().face_count() {
        let r = store.face_resolution(face).unwrap().get();
        for i in 0..=r {
            for j in 0..=r - i {
                let expected = format.quantize(store.face_sample(face, i, j).unwrap());
                let found = packed_sample_index(&on_gpu, face, 0, i, j).and_then(|index| on_gpu.color(index));
                if found != Some(expected) && out.len() < 10 {
                    out.push(format!("face {face} ({i}, {j}): GPU {found:?}, store {expected:?}"));
                }
            }
        }
    }
    out
}

/// The editor's upload of the store's dirty elements (src/app/paint.rs `sync_gpu`): the
/// plan's ranges encoded into the CPU copy of the buffer and sent as merged spans, or a
/// full upload when the layout grew. Returns whether it was partial and how many face
/// records it rewrote.
fn upload_dirty(
    gpu: &Gpu,
    (mesh, encoded): (&mut GpuMesh, &mut EncodedBuffer),
    layout: &mut PaintLayout,
    store: &mut ColorStore,
    positions: &[[f32; 3]],
    format: ColorFormat,
) -> (bool, usize) {
    let dirty = store.take_dirty();
    let plan = layout.sync(store, &dirty);
    if plan.grown {
        let packed = layout.packed(store, positions, format);
        *mesh =
            GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions { atlas_width: Some(61) })
                .unwrap();
        *encoded = EncodedBuffer::from_packed(&packed);
        return (false, 0);
    }
    let spans = encoded.apply(layout, store, &dirty, &plan);
    assert!(spans.len() <= plan.sample_ranges.len());
    mesh.write_paint_upload(&gpu.ctx, &spans, encoded.bytes(), (&plan.faces, layout.records())).unwrap();
    (true, plan.faces.len())
}

#[test]
fn partial_uploads_after_random_edits_and_resolution_changes_match_the_store() {
    let gpu = Gpu::create();
    let (positions, triangles) = icosphere(1);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut rng = SplitMix64(0x5EED_0014);
    for format in ColorFormat::ALL {
        let mut store = ColorStore::uniform(topology.clone(), Resolution::new(4).unwrap(), [0.5, 0.5, 0.5, 1.0]);
        let mut sites = Vec::new();
        store.for_each_site(|site| sites.push(site.sample));
        for &sample in &sites {
            store.write_sample(sample, rng.color());
        }
        store.take_dirty();
        let mut layout = PaintLayout::new(&store);
        // A narrow atlas (61 texels) so uploads wrap rows at odd offsets.
        let packed = layout.packed(&store, &positions, format);
        let mut mesh =
            GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions { atlas_width: Some(61) })
                .unwrap();
        let mut encoded = EncodedBuffer::from_packed(&packed);
        let (mut partial, mut grown, mut records) = (0, 0, 0);
        for round in 0..16 {
            // A few resolution changes (some grow blocks beyond their slack), then edits.
            for _ in 0..rng.below(3) {
                let face = rng.below(u64::from(topology.face_count())) as u32;
                let r = Resolution::from_log2(rng.below(5) as u32).unwrap();
                store.write_resolution(face, r).unwrap();
            }
            let mut sites: Vec<SampleRef> = Vec::new();
            store.for_each_site(|site| sites.push(site.sample));
            for _ in 0..1 + rng.below(40) {
                let sample = sites[rng.below(sites.len() as u64) as usize];
                store.write_sample(sample, rng.color());
            }
            match upload_dirty(&gpu, (&mut mesh, &mut encoded), &mut layout, &mut store, &positions, format) {
                (true, faces) => {
                    partial += 1;
                    records += faces;
                }
                (false, _) => grown += 1,
            }
            let wrong = mismatches(&gpu, &mesh, &store, format);
            assert!(
                wrong.is_empty(),
                "{format:?} round {round}: the GPU copy differs from the store:\n{}",
                wrong.join("\n")
            );
        }
        eprintln!(
            "{format:?}: {partial} partial uploads ({records} face records rewritten), {grown} full re-uploads, \
             all equal to the store"
        );
        assert!(partial >= 8, "{format:?}: only {partial} of 16 rounds used partial uploads");
        assert!(records >= 1, "{format:?}: no partial upload rewrote a face record");

        // The comparison can fail: one corrupted sample on the GPU is found.
        let vertex_sample = 0u64;
        let garbage = vec![0x5Au8; format.bytes_per_sample()];
        mesh.write_samples(&gpu.ctx, vertex_sample, &garbage).unwrap();
        let wrong = mismatches(&gpu, &mesh, &store, format);
        assert!(!wrong.is_empty(), "{format:?}: a corrupted GPU sample went unnoticed");
    }
}

/// Paint mode on the packing the view shows (what Tab does when the view has it): the
/// paint layout laid over the compact packing on the GPU, its bytes lent to the CPU copy,
/// partial uploads after random edits, and raised resolutions growing the atlas on the GPU
/// (`GpuMesh::grow_atlas`: the old texels copied, nothing re-encoded). Every lattice point
/// read back as the shaders address it holds the store's colour; a narrow atlas (61 texels)
/// makes the copy and the uploads wrap rows at odd offsets.
#[test]
fn painting_the_packing_in_place_with_atlas_growth_matches_the_store() {
    let gpu = Gpu::create();
    let (positions, triangles) = icosphere(1);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut rng = SplitMix64(0x5EED_0046);
    for format in ColorFormat::ALL {
        let mut store = ColorStore::uniform(topology.clone(), Resolution::new(4).unwrap(), [0.5, 0.5, 0.5, 1.0]);
        let mut sites = Vec::new();
        store.for_each_site(|site| sites.push(site.sample));
        for &sample in &sites {
            store.write_sample(sample, rng.color());
        }
        store.take_dirty();
        let mut cache = PackCache::build(&store, &positions, format).unwrap();
        let mut mesh = GpuMesh::upload(
            &gpu.ctx,
            gpu.renderer.layouts(),
            cache.packed(),
            &MeshUploadOptions { atlas_width: Some(61) },
        )
        .unwrap();
        assert!(mesh.vertex_levels > 1, "the packing has MIP chains");
        let mut layout = PaintLayout::over_packed(&store, cache.packed()).unwrap();
        let mut encoded = EncodedBuffer::from_bytes(format, cache.lend_colors());
        let mut grown = 0;
        for round in 0..12 {
            if round % 3 == 1 {
                let face = rng.below(u64::from(topology.face_count())) as u32;
                store.write_resolution(face, Resolution::from_log2(3 + rng.below(2) as u32).unwrap()).unwrap();
            }
            let mut sites: Vec<SampleRef> = Vec::new();
            store.for_each_site(|site| sites.push(site.sample));
            for _ in 0..1 + rng.below(40) {
                let sample = sites[rng.below(sites.len() as u64) as usize];
                store.write_sample(sample, rng.color());
            }
            let dirty = store.take_dirty();
            let plan = layout.sync(&store, &dirty);
            if plan.grown {
                grown += 1;
                let samples = mesh.atlas.samples;
                mesh.grow_atlas(&gpu.ctx, gpu.renderer.layouts(), layout.capacity()).unwrap();
                assert!(mesh.atlas.samples > samples);
                encoded.grow(layout.capacity());
            }
            let spans = encoded.apply(&layout, &store, &dirty, &plan);
            mesh.write_paint_upload(&gpu.ctx, &spans, encoded.bytes(), (&plan.faces, layout.records())).unwrap();
            let wrong = mismatches(&gpu, &mesh, &store, format);
            assert!(wrong.is_empty(), "{format:?} round {round}: the GPU copy differs:\n{}", wrong.join("\n"));
        }
        assert!(grown > 0, "{format:?}: no raised resolution grew the atlas");
    }
}

#[test]
fn a_wgpu_error_outside_the_error_scopes_fails_the_test() {
    let gpu = Gpu::create();
    let buffer = gpu.ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("not a copy destination"),
        size: 16,
        usage: wgpu::BufferUsages::UNIFORM,
        mapped_at_creation: false,
    });
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        gpu.ctx.queue.write_buffer(&buffer, 0, &[0u8; 16]);
        gpu.ctx.queue.submit([]);
        let _ = gpu.ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }));
    let message = outcome.err().and_then(|p| p.downcast_ref::<String>().cloned()).expect("no panic on a wgpu error");
    assert!(message.contains("uncaptured wgpu error"), "{message}");
}
