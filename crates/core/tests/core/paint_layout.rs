//! The paint-mode layout against the store: after any sequence of edits and resolution
//! changes, a buffer updated only with the planned uploads samples exactly like the store,
//! and each upload is proportional to what changed.

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, octahedron};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::paint_layout::{EncodedBuffer, MAX_UPLOAD_GAP, PaintLayout};
use meshpaint_core::packing::sampler::MeshColorSource;

/// Every lattice point of every face reads the store's colour from the mirror buffer.
fn assert_mirror_matches(mirror: &PackedMesh, store: &ColorStore) {
    for face in 0..store.topology().face_count() {
        let r = store.face_resolution(face).unwrap();
        assert_eq!(mirror.face_resolution(face), Some(r));
        for i in 0..=r.get() {
            for j in 0..=r.get() - i {
                let expected = ColorFormat::Rgba32F.quantize(store.face_sample(face, i, j).unwrap());
                assert_eq!(mirror.lattice_color(face, 0, i, j), Some(expected), "face {face} ({i}, {j})");
            }
        }
    }
}

#[test]
fn partial_uploads_keep_the_gpu_buffer_equal_to_the_store() {
    let (positions, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, Resolution::new(4).unwrap(), [0.5; 4]);
    let format = ColorFormat::Rgba32F;
    let mut layout = PaintLayout::new(&store);
    let mut mirror = layout.packed(&store, &positions, format);
    store.take_dirty();
    assert_mirror_matches(&mirror, &store);
    let mut rng = Rng(5);
    let (mut grown, mut moved) = (0, 0);
    for step in 0..300 {
        if step % 5 == 0 {
            let face = (rng.next() % 8) as u32;
            let r = Resolution::from_log2((rng.next() % 7) as u32).unwrap();
            store.write_resolution(face, r).unwrap();
        } else {
            // A "dab": a few samples of one face.
            let face = (rng.next() % 8) as u32;
            let r = store.face_resolution(face).unwrap();
            for _ in 0..5 {
                let i = (rng.next() % u64::from(r.get() + 1)) as u32;
                let j = (rng.next() % u64::from(r.get() - i + 1)) as u32;
                let sample = store.face_sample_ref(face, i, j).unwrap();
                store.write_sample(sample, [rng.unit(), rng.unit(), rng.unit(), 1.0]);
            }
        }
        let dirty = store.take_dirty();
        let plan = layout.sync(&store, &dirty);
        if plan.grown {
            grown += 1;
            mirror = layout.packed(&store, &positions, format);
        } else {
            moved += plan.faces.len();
            let encoded = layout.encode_plan(&store, &dirty, &plan, format);
            let mut offset = 0;
            for &(first, count) in &plan.sample_ranges {
                let (start, len) =
                    (first as usize * format.bytes_per_sample(), count as usize * format.bytes_per_sample());
                mirror.colors[start..start + len].copy_from_slice(&encoded[offset..offset + len]);
                offset += len;
            }
            assert_eq!(offset, encoded.len());
            for &face in &plan.faces {
                mirror.face_records[face as usize] = layout.records()[face as usize];
            }
        }
        // Uploads are proportional to the change: never more than the dirty elements hold.
        let dirty_samples: u64 = dirty.vertices.len() as u64
            + dirty.edges.iter().map(|&e| store.edge_samples(e).len() as u64).sum::<u64>()
            + dirty.faces.iter().map(|&f| store.interior_samples(f).len() as u64).sum::<u64>();
        assert_eq!(plan.sample_count(), dirty_samples);
        assert_mirror_matches(&mirror, &store);
    }
    assert!(grown > 0 && moved > 0, "the test must exercise growth ({grown}) and record patches ({moved})");
}

#[test]
fn one_dab_uploads_only_the_painted_elements() {
    let topology = Topology::build(4, &[[0, 1, 2], [1, 0, 3]]).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(64).unwrap(), [0.0; 4]);
    let mut layout = PaintLayout::new(&store);
    store.take_dirty();
    store.write_sample(SampleRef::Interior { face: 1, offset: 10 }, [1.0; 4]);
    let dirty = store.take_dirty();
    let plan = layout.sync(&store, &dirty);
    assert_eq!(plan.sample_count(), u64::from(layout::interior_sample_count(Resolution::new(64).unwrap())));
    assert!(plan.faces.is_empty() && !plan.grown);
}

/// The CPU copy the editor uploads spans from: after random edits on a mesh large enough for
/// gaps wider than `MAX_UPLOAD_GAP`, it equals a full encode of the store (the packed paint
/// buffer, made from scratch), and the spans are sorted, disjoint, cover every planned range,
/// and are never closer than the gap they could have bridged.
#[test]
fn the_encoded_copy_equals_a_full_encode_and_its_spans_cover_the_plan() {
    let (positions, triangles) = common::icosphere(3);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(8).unwrap(), [0.5; 4]);
    let format = ColorFormat::Rgba8Srgb;
    let mut layout = PaintLayout::new(&store);
    let mut encoded = EncodedBuffer::from_packed(&layout.packed(&store, &positions, format));
    store.take_dirty();
    let mut rng = Rng(17);
    let mut sites = Vec::new();
    store.for_each_site(|site| sites.push(site.sample));
    let (mut bridged, mut separate) = (0, 0);
    for _ in 0..40 {
        for _ in 0..1 + rng.next() % 300 {
            let sample = sites[(rng.next() % sites.len() as u64) as usize];
            store.write_sample(sample, [rng.unit(), rng.unit(), rng.unit(), 1.0]);
        }
        let dirty = store.take_dirty();
        let plan = layout.sync(&store, &dirty);
        assert!(!plan.grown);
        let spans = encoded.apply(&layout, &store, &dirty, &plan);
        let full = layout.packed(&store, &positions, format);
        assert!(encoded.bytes() == full.colors.as_slice(), "the copy differs from a full encode");
        for pair in spans.windows(2) {
            let gap = pair[1].0 - (pair[0].0 + pair[0].1);
            assert!(gap > MAX_UPLOAD_GAP, "spans {pair:?} should have been merged");
            separate += 1;
        }
        for &(first, count) in &plan.sample_ranges {
            let k = spans.partition_point(|&(start, _)| start <= first) - 1;
            let (start, len) = spans[k];
            assert!(first + count <= start + len, "range ({first}, {count}) outside span ({start}, {len})");
        }
        bridged += plan.sample_ranges.len() - spans.len();
    }
    assert!(bridged > 100 && separate > 10, "bridged {bridged} ranges, {separate} separate spans");
}
