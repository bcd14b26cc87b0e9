//! Paint mode laid over the compact packing the view shows (`PaintLayout::over_packed`, the
//! packing's bytes lent to the encoded copy) against the paint layout built from scratch
//! (`PaintLayout::new` + `packed`, how paint mode started before): after random strokes and
//! resolution changes, every level-0 lattice point of every face holds the same bytes in
//! both buffers, and both decode to the store's colour quantised to the format. Leaving paint
//! mode gives the lent bytes back to the packing, whose incremental repack or relayout must
//! then equal the serial reference packer byte for byte.

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, icosphere, octahedron};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, DirtyAccumulator, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::{EncodedBuffer, PaintLayout};
use meshpaint_core::packing::reference::pack_reference;
use meshpaint_core::packing::sampler::packed_sample_index;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// A store of random colours (HDR channels too) at `resolutions`.
fn random_store(topology: Topology, resolutions: Vec<Resolution>, seed: u64) -> ColorStore {
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| [rng.unit() * 1.5, rng.unit(), rng.unit() * 0.01, 0.5 + 0.5 * rng.unit()]);
    store.take_dirty();
    store
}

/// Mixed resolutions on an octahedron, and a sphere with random resolutions.
fn cases() -> Vec<(&'static str, Vec<[f32; 3]>, ColorStore)> {
    let (positions, topology) = octahedron();
    let mut out =
        vec![("octahedron mixed", positions, random_store(topology, [1, 2, 4, 8, 16, 4, 1, 32].map(r).to_vec(), 1))];
    let (positions, triangles) = icosphere(2);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut rng = Rng(4);
    let resolutions = (0..topology.face_count()).map(|_| r(1 << (rng.next() % 5))).collect();
    out.push(("icosphere random", positions, random_store(topology, resolutions, 5)));
    out
}

/// One paint buffer: its layout and its encoded bytes.
struct Buffer {
    layout: PaintLayout,
    encoded: EncodedBuffer,
}

impl Buffer {
    /// Brings the buffer up to date with `dirty` as the editor's `sync_gpu` does.
    fn sync(&mut self, store: &ColorStore, dirty: &meshpaint_core::colors::store::DirtyElements) {
        let plan = self.layout.sync(store, dirty);
        if plan.grown {
            self.encoded.grow(self.layout.capacity());
        }
        self.encoded.apply(&self.layout, store, dirty, &plan);
    }

    /// The bytes of level-0 lattice point `(i, j)` of `face`, addressed as the shaders do.
    fn lattice_bytes(&self, store: &ColorStore, vertex_levels: u32, face: u32, (i, j): (u32, u32)) -> Vec<u8> {
        let view = PackedMesh {
            positions: Vec::new(),
            indices: store.topology().face_vertices.clone(),
            vertex_levels,
            face_records: self.layout.records().to_vec(),
            format: self.encoded.format(),
            colors: Vec::new(),
        };
        let size = self.encoded.format().bytes_per_sample();
        let index = packed_sample_index(&view, face, 0, i, j).unwrap() as usize;
        self.encoded.bytes()[index * size..(index + 1) * size].to_vec()
    }
}

/// Every lattice point: the same bytes in both buffers, decoding to the store's colour.
fn assert_same(over: &Buffer, eager: &Buffer, store: &ColorStore, vertex_levels: u32, what: &str) {
    let format = over.encoded.format();
    for face in 0..store.topology().face_count() {
        let r = store.face_resolution(face).unwrap().get();
        for i in 0..=r {
            for j in 0..=r - i {
                let in_place = over.lattice_bytes(store, vertex_levels, face, (i, j));
                let built = eager.lattice_bytes(store, 1, face, (i, j));
                assert_eq!(in_place, built, "{what}: face {face} ({i}, {j})");
                let expected = format.quantize(store.face_sample(face, i, j).unwrap());
                assert_eq!(format.decode(&in_place), expected, "{what}: face {face} ({i}, {j}) against the store");
            }
        }
    }
}

/// A few faces painted whole (vertices, edges, interiors), as a dab does.
fn stroke(store: &mut ColorStore, rng: &mut Rng) {
    let topology = store.topology().clone();
    let faces = topology.face_count();
    let center = (rng.next() % u64::from(faces)) as u32;
    for n in 0..1 + rng.next() as u32 % 4 {
        let face = (center + n * 7) % faces;
        let color = [rng.unit(), rng.unit(), rng.unit(), 1.0];
        for &v in &topology.face_vertices[face as usize] {
            store.write_sample(SampleRef::Vertex(v), color);
        }
        for &edge in &topology.face_edges[face as usize] {
            for offset in 0..store.edge_samples(edge).len() as u32 {
                store.write_sample(SampleRef::Edge { edge, offset }, [rng.unit(), color[1], color[2], 1.0]);
            }
        }
        for offset in 0..store.interior_samples(face).len() as u32 {
            store.write_sample(SampleRef::Interior { face, offset }, [color[0], rng.unit(), color[2], 1.0]);
        }
    }
}

/// One paint session on `store` in `format`, with resolution changes or without: both
/// buffers compared after every dab, then the packing repacked from its lent bytes.
fn session(name: &str, positions: &[[f32; 3]], mut store: ColorStore, format: ColorFormat, resize: bool) -> u32 {
    let mut cache = PackCache::build(&store, positions, format).unwrap();
    let vertex_levels = cache.packed().vertex_levels;
    let layout = PaintLayout::over_packed(&store, cache.packed()).expect("the packing is the store's");
    let mut over = Buffer { layout, encoded: EncodedBuffer::from_bytes(format, cache.lend_colors()) };
    let layout = PaintLayout::new(&store);
    let mut eager =
        Buffer { encoded: EncodedBuffer::from_packed_owned(layout.packed(&store, positions, format)), layout };
    let what = format!("{name} {format:?} resize {resize}");
    assert_same(&over, &eager, &store, vertex_levels, &format!("{what} on entering"));
    let mut rng = Rng(7 + format.code() as u64);
    let mut accumulated = DirtyAccumulator::new(store.topology());
    let faces = u64::from(store.topology().face_count());
    let mut grown = 0;
    for dab in 0..12 {
        if resize && dab % 3 == 1 {
            let face = (rng.next() % faces) as u32;
            let new = r(1 << (rng.next() % 7));
            store.write_resolution(face, new).unwrap();
        }
        stroke(&mut store, &mut rng);
        let dirty = store.take_dirty();
        accumulated.add(&dirty);
        let capacity = over.layout.capacity();
        over.sync(&store, &dirty);
        grown += u32::from(over.layout.capacity() > capacity);
        eager.sync(&store, &dirty);
        assert_same(&over, &eager, &store, vertex_levels, &format!("{what} dab {dab}"));
    }
    // Leaving: the lent bytes back, then the repack the editor runs.
    cache.return_colors(over.encoded.into_bytes());
    let dirty = accumulated.take();
    let cache = match cache.update(&store, &dirty) {
        Some(_) => {
            assert!(!resize || dirty.resized_faces.is_empty(), "{what}: an update after resolution changes");
            cache
        }
        None => cache.relayout(&store, positions, &dirty).unwrap(),
    };
    let reference = pack_reference(&store, positions, format).unwrap();
    assert!(cache.packed().colors == reference.colors, "{what}: the repack from the lent bytes differs");
    assert_eq!(*cache.packed(), reference, "{what}");
    assert!(cache == PackCache::build(&store, positions, format).unwrap(), "{what}: the kept chains differ");
    grown
}

#[test]
fn painting_over_the_packing_equals_the_paint_layout_built_anew_and_repacks_exactly() {
    let mut grown = 0;
    for (name, positions, store) in cases() {
        for format in ColorFormat::ALL {
            for resize in [false, true] {
                grown += session(name, &positions, store.clone(), format, resize);
            }
        }
    }
    // Raised resolutions outgrow the packing's exact capacity: the growth path ran.
    assert!(grown > 0, "no session grew its buffer");
}

#[test]
fn a_layout_over_another_stores_packing_is_refused() {
    let (positions, topology) = octahedron();
    let store = random_store(topology.clone(), vec![r(4); 8], 1);
    let cache = PackCache::build(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let other = random_store(topology, vec![r(8); 8], 2);
    assert!(PaintLayout::over_packed(&other, cache.packed()).is_none(), "other resolutions");
    assert!(PaintLayout::over_packed(&store, cache.packed()).is_some());
}

#[test]
fn a_packing_without_its_lent_bytes_refuses_an_update_and_relays_out_in_full() {
    let (positions, topology) = octahedron();
    let mut store = random_store(topology, [1, 2, 4, 8, 16, 4, 1, 32].map(r).to_vec(), 3);
    let format = ColorFormat::Rgba16F;
    let mut cache = PackCache::build(&store, &positions, format).unwrap();
    let lent = cache.lend_colors();
    let mut rng = Rng(9);
    stroke(&mut store, &mut rng);
    let dirty = store.take_dirty();
    assert!(cache.update(&store, &dirty).is_none(), "an update without the colour bytes");
    let cache = cache.relayout(&store, &positions, &dirty).unwrap();
    assert!(*cache.packed() == pack_reference(&store, &positions, format).unwrap());
    drop(lent);
}
