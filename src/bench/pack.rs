//! Measurements behind `meshpaint bench …`: every figure we report comes from here.
//!
//! Timings take the best of several runs (the least-disturbed one on a shared machine)
//! and report the median too. Comparisons are made inside one run, as ratios.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::{PackCache, PackError};
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};

/// Best and median of repeated timings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Fastest run, seconds.
    pub best_seconds: f64,
    /// Median run, seconds.
    pub median_seconds: f64,
    /// Number of runs.
    pub runs: usize,
}

impl Timing {
    /// Times `run` `runs` times (at least once).
    pub fn measure<T>(runs: usize, mut run: impl FnMut() -> T) -> (Timing, T) {
        Self::measure_prepared(runs, || (), |()| run())
    }

    /// Times `run` on what `prepare` makes, `runs` times (at least once); neither `prepare`
    /// nor dropping the previous run's result is timed.
    pub fn measure_prepared<I, T>(
        runs: usize,
        mut prepare: impl FnMut() -> I,
        mut run: impl FnMut(I) -> T,
    ) -> (Timing, T) {
        let mut times: Vec<Duration> = Vec::new();
        let mut last;
        loop {
            let input = prepare();
            let start = Instant::now();
            let result = run(input);
            times.push(start.elapsed());
            last = result;
            if times.len() >= runs.max(1) {
                break;
            }
        }
        times.sort();
        let timing = Timing {
            best_seconds: times[0].as_secs_f64(),
            median_seconds: times[times.len() / 2].as_secs_f64(),
            runs: times.len(),
        };
        (timing, last)
    }

    /// As a JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "best_seconds": self.best_seconds,
            "median_seconds": self.median_seconds,
            "runs": self.runs,
        })
    }
}

/// Result of the repack benchmark.
#[derive(Debug, Clone, PartialEq)]
pub struct PackBench {
    /// Colour format packed.
    pub format: ColorFormat,
    /// Level-0 samples in the store.
    pub store_samples: u64,
    /// Samples written, MIP chains included.
    pub packed_samples: u64,
    /// Bytes of face records plus colours written.
    pub bytes_written: u64,
    /// Repack (store → packed buffers) timing.
    pub pack: Timing,
    /// `memcpy` of the same number of bytes, same run.
    pub memcpy: Timing,
    /// The same full repack into the buffers of the previous one (`PackCache::rebuild`,
    /// what leaving paint mode runs after a change of format; after a resolution change it
    /// runs [`bench_relayout`]'s relayout).
    pub rebuild: Timing,
    /// Reading every level-0 sample of the store once, on the packer's threads, and
    /// nothing else: the least any repack does (its input is `f32`, 16 bytes a sample).
    pub store_read: Timing,
}

impl PackBench {
    /// Bytes written per second by the packer (best run).
    pub fn pack_bytes_per_second(&self) -> f64 {
        self.bytes_written as f64 / self.pack.best_seconds
    }

    /// Bytes copied per second by `memcpy` (best run).
    pub fn memcpy_bytes_per_second(&self) -> f64 {
        self.bytes_written as f64 / self.memcpy.best_seconds
    }

    /// How many times slower than a plain copy of the output the repack is.
    pub fn ratio_to_memcpy(&self) -> f64 {
        self.pack.best_seconds / self.memcpy.best_seconds
    }

    /// How many times slower than a plain copy of the output the repack into reused buffers is.
    pub fn rebuild_ratio_to_memcpy(&self) -> f64 {
        self.rebuild.best_seconds / self.memcpy.best_seconds
    }

    /// How many times slower than a plain copy of the output reading the input alone is.
    pub fn store_read_ratio_to_memcpy(&self) -> f64 {
        self.store_read.best_seconds / self.memcpy.best_seconds
    }

    /// As a JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "format": self.format.name(),
            "store_samples": self.store_samples,
            "packed_samples": self.packed_samples,
            "bytes_written": self.bytes_written,
            "pack": self.pack.to_json(),
            "memcpy": self.memcpy.to_json(),
            "pack_bytes_per_second": self.pack_bytes_per_second(),
            "memcpy_bytes_per_second": self.memcpy_bytes_per_second(),
            "ratio_to_memcpy": self.ratio_to_memcpy(),
            "rebuild": self.rebuild.to_json(),
            "rebuild_ratio_to_memcpy": self.rebuild_ratio_to_memcpy(),
            "store_read": self.store_read.to_json(),
            "store_read_ratio_to_memcpy": self.store_read_ratio_to_memcpy(),
        })
    }
}

/// Times repacking `document` in `format` against a `memcpy` of the output size.
pub fn bench_pack(document: &Document, format: ColorFormat, runs: usize) -> Result<PackBench, PackError> {
    let (pack_timing, packed) = Timing::measure(runs, || document.pack(format));
    let packed: PackedMesh = packed?;
    let bytes_written = packed.face_record_bytes() + packed.color_bytes();
    let source = vec![0x5Au8; bytes_written as usize];
    let mut destination = vec![0u8; bytes_written as usize];
    let (memcpy_timing, ()) = Timing::measure(runs.max(5), || {
        destination.copy_from_slice(std::hint::black_box(&source));
        std::hint::black_box(&mut destination);
    });
    let mut cache = Some(PackCache::build(&document.store, &document.positions, format)?);
    let mut failure = None;
    let (rebuild, ()) = Timing::measure(runs, || {
        if let Some(previous) = cache.take() {
            match previous.rebuild(&document.store, &document.positions, format) {
                Ok(next) => cache = Some(next),
                Err(error) => failure = Some(error),
            }
        }
    });
    if let Some(error) = failure {
        return Err(error);
    }
    if cache.as_ref().map(PackCache::packed) != Some(&packed) {
        return Err(PackError::NotCanonical("the repack into reused buffers differs from a fresh pack".into()));
    }
    drop(cache);
    let (store_read, _) = Timing::measure(runs.max(5), || read_store(std::hint::black_box(&document.store)));
    Ok(PackBench {
        rebuild,
        format,
        store_samples: document.store.sample_count(),
        packed_samples: packed.sample_count(),
        bytes_written,
        pack: pack_timing,
        memcpy: memcpy_timing,
        store_read,
    })
}

/// Reads every level-0 sample of `store` (vertices, edges, interiors, in the packer's
/// order and on its threads) into a checksum of their bits: integer sums, so the loop
/// vectorises and is bound by memory, not by adds.
fn read_store(store: &ColorStore) -> u32 {
    let topology = store.topology();
    let sum =
        |samples: &[Rgba]| bytemuck::cast_slice::<Rgba, u32>(samples).iter().fold(0u32, |a, &b| a.wrapping_add(b));
    let vertices = (0..topology.vertex_count)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| sum(&[store.vertex_color(v).unwrap_or_default()]))
        .reduce(|| 0, u32::wrapping_add);
    let edges = (0..topology.edge_count())
        .into_par_iter()
        .with_min_len(4096)
        .map(|e| sum(store.edge_samples(e)))
        .reduce(|| 0, u32::wrapping_add);
    let interiors = (0..topology.face_count())
        .into_par_iter()
        .with_min_len(4096)
        .map(|f| sum(store.interior_samples(f)))
        .reduce(|| 0, u32::wrapping_add);
    vertices.wrapping_add(edges).wrapping_add(interiors)
}

/// Result of the incremental-repack benchmark: a stroke painted, then leaving paint mode.
#[derive(Debug, Clone, PartialEq)]
pub struct IncrementalBench {
    /// Faces the stroke covered (every sample of each: vertices, edges, interior).
    pub faces_painted: u64,
    /// Level-0 samples the stroke wrote.
    pub samples_changed: u64,
    /// Samples the incremental repack rewrote (MIP levels and neighbours included).
    pub samples_rewritten: u64,
    /// Incremental repack timing.
    pub repack: Timing,
    /// A full repack of the same store, same run.
    pub full: Timing,
    /// Whether the incremental result is byte-equal to the full repack.
    pub equal_to_full_pack: bool,
}

impl IncrementalBench {
    /// As a JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "faces_painted": self.faces_painted,
            "samples_changed": self.samples_changed,
            "samples_rewritten": self.samples_rewritten,
            "repack": self.repack.to_json(),
            "full_repack": self.full.to_json(),
            "speedup": self.full.best_seconds / self.repack.best_seconds.max(1e-12),
            "equal_to_full_pack": self.equal_to_full_pack,
        })
    }
}

/// Paints every sample of the faces nearest to the middle face's centroid until about
/// `target_samples` samples changed (a stroke), then times the incremental repack that
/// leaving paint mode runs, against a full repack of the result.
pub fn bench_incremental(
    document: &Document,
    format: ColorFormat,
    runs: usize,
    target_samples: u64,
) -> Result<IncrementalBench, PackError> {
    use meshpaint_core::colors::store::SampleRef;
    let mut store = document.store.clone();
    let positions = &document.positions;
    let topology = store.topology().clone();
    let mut cache = meshpaint_core::packing::packer::PackCache::build(&store, positions, format)?;
    let (mut samples_changed, mut faces_painted) = (0u64, 0u64);
    let color = [0.8, 0.1, 0.3, 1.0];
    // Through the one write path, as the editor's tools write (no undo step open).
    let mut history = UndoHistory::new(0);
    let mut writer = StoreWriter::new(&mut store, &mut history);
    for face in faces_around_the_middle(document) {
        if samples_changed >= target_samples {
            break;
        }
        faces_painted += 1;
        for &v in &topology.face_vertices[face as usize] {
            samples_changed += u64::from(writer.set(SampleRef::Vertex(v), color));
        }
        for &edge in &topology.face_edges[face as usize] {
            for offset in 0..writer.store().edge_samples(edge).len() as u32 {
                samples_changed += u64::from(writer.set(SampleRef::Edge { edge, offset }, color));
            }
        }
        for offset in 0..writer.store().interior_samples(face).len() as u32 {
            samples_changed += u64::from(writer.set(SampleRef::Interior { face, offset }, color));
        }
    }
    let dirty = store.take_dirty();
    // Repeated updates with the same edit redo the same work (the result is the same).
    let (repack, ranges) = Timing::measure(runs, || cache.update(&store, &dirty));
    let samples_rewritten = ranges.unwrap_or_default().iter().map(|&(_, n)| n).sum();
    let (full, packed) =
        Timing::measure(runs.min(3), || meshpaint_core::packing::packer::pack(&store, positions, format));
    Ok(IncrementalBench {
        faces_painted,
        samples_changed,
        samples_rewritten,
        repack,
        full,
        equal_to_full_pack: packed? == *cache.packed(),
    })
}

/// Every face, nearest to the middle face's centroid first (where the bench's strokes go).
fn faces_around_the_middle(document: &Document) -> Vec<u32> {
    let (positions, topology) = (&document.positions, document.store.topology());
    let centroid = |f: usize| {
        let [a, b, c] = topology.face_vertices[f].map(|v| positions[v as usize]);
        std::array::from_fn::<f32, 3, _>(|k| (a[k] + b[k] + c[k]) / 3.0)
    };
    let middle = centroid(topology.face_vertices.len() / 2);
    let mut order: Vec<(f32, u32)> = (0..topology.face_vertices.len())
        .map(|f| {
            let p = centroid(f);
            ((0..3).map(|k| (p[k] - middle[k]).powi(2)).sum(), f as u32)
        })
        .collect();
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    order.into_iter().map(|(_, face)| face).collect()
}

/// Result of the relayout benchmark: a resolution stroke (faces raised to twice their
/// resolution), then leaving paint mode.
#[derive(Debug, Clone, PartialEq)]
pub struct RelayoutBench {
    /// Faces whose resolution the stroke doubled.
    pub faces_resized: u64,
    /// Level-0 samples the stroke added.
    pub samples_added: u64,
    /// The relayout (what leaving paint mode runs after a resolution change).
    pub relayout: Timing,
    /// The full repack into the previous pack's buffers (what it ran before), same run.
    pub rebuild: Timing,
    /// `memcpy` of the new colour buffer's bytes, same run.
    pub memcpy: Timing,
    /// Whether the relayout is byte-equal to a full pack of the same store.
    pub equal_to_full_pack: bool,
}

impl RelayoutBench {
    /// As a JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "faces_resized": self.faces_resized,
            "samples_added": self.samples_added,
            "relayout": self.relayout.to_json(),
            "rebuild": self.rebuild.to_json(),
            "memcpy": self.memcpy.to_json(),
            "ratio_to_memcpy": self.relayout.best_seconds / self.memcpy.best_seconds.max(1e-12),
            "speedup_over_rebuild": self.rebuild.best_seconds / self.relayout.best_seconds.max(1e-12),
            "equal_to_full_pack": self.equal_to_full_pack,
        })
    }
}

/// Doubles the resolution of the faces nearest to the middle face's centroid until about
/// `target_samples` level-0 samples were added (a stroke of the resolution brush), then
/// times the relayout that leaving paint mode runs, against the full repack into the old
/// buffers it replaces and a `memcpy` of the output.
pub fn bench_relayout(
    document: &Document,
    format: ColorFormat,
    runs: usize,
    target_samples: u64,
) -> Result<RelayoutBench, PackError> {
    let mut store = document.store.clone();
    let positions = &document.positions;
    let cache = PackCache::build(&store, positions, format)?;
    let before = store.sample_count();
    let mut faces_resized = 0u64;
    let mut history = UndoHistory::new(0);
    let mut writer = StoreWriter::new(&mut store, &mut history);
    for face in faces_around_the_middle(document) {
        if writer.store().sample_count() - before >= target_samples {
            break;
        }
        let raised = writer.store().face_resolution(face).and_then(|r| r.doubled());
        if raised.is_some_and(|r| writer.set_face_resolution(face, r).is_ok()) {
            faces_resized += 1;
        }
    }
    let samples_added = store.sample_count() - before;
    let dirty = store.take_dirty();
    let (relayout, relaid) =
        Timing::measure_prepared(runs, || cache.clone(), |old| old.relayout(&store, positions, &dirty));
    let (rebuild, _) = Timing::measure_prepared(runs, || cache.clone(), |old| old.rebuild(&store, positions, format));
    let relaid = relaid?;
    let source = relaid.packed().colors.clone();
    let mut target = vec![0u8; source.len()];
    let (memcpy, ()) = Timing::measure(runs.max(5), || {
        target.copy_from_slice(std::hint::black_box(&source));
        std::hint::black_box(&mut target);
    });
    let full = meshpaint_core::packing::packer::pack(&store, positions, format)?;
    Ok(RelayoutBench {
        faces_resized,
        samples_added,
        relayout,
        rebuild,
        memcpy,
        equal_to_full_pack: full == *relaid.packed(),
    })
}
