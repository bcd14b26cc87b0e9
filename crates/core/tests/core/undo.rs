//! Undo and redo against complete snapshots: after any sequence of strokes (paint, blur,
//! erase, resolution raise / lower / set, fill), undoing restores every sample and every face
//! and edge resolution bit for bit, redo reapplies exactly, a new step clears redo, the memory
//! cap drops the oldest steps, and a step stores only the samples that changed.

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::paint::brush::{
    self, BlendMode, BrushRadius, BrushSettings, Falloff, FillScope, PaintView, Painter,
};
use meshpaint_core::paint::brush::{ResolutionOp, Tool};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::{SAMPLE_RECORD_BYTES, UndoError, UndoHistory};

use crate::common;
use crate::common::WriteThrough;
use common::Rng;

const WIDTH: u32 = 800;
const HEIGHT: u32 = 600;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// A closed mesh: a UV sphere with `rings × segments` quads split in two.
fn uv_sphere(rings: u32, segments: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = vec![[0.0, 1.0, 0.0]];
    for ring in 1..rings {
        let theta = std::f64::consts::PI * f64::from(ring) / f64::from(rings);
        for s in 0..segments {
            let phi = std::f64::consts::TAU * f64::from(s) / f64::from(segments);
            positions.push([(theta.sin() * phi.cos()) as f32, theta.cos() as f32, (theta.sin() * phi.sin()) as f32]);
        }
    }
    positions.push([0.0, -1.0, 0.0]);
    let bottom = positions.len() as u32 - 1;
    let id = |ring: u32, s: u32| 1 + (ring - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, id(1, s + 1), id(1, s)]);
        triangles.push([bottom, id(rings - 1, s), id(rings - 1, s + 1)]);
    }
    for ring in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (id(ring, s), id(ring, s + 1), id(ring + 1, s + 1), id(ring + 1, s));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}

/// Everything undo must restore: every sample (bits), every face and edge resolution.
#[derive(Debug, PartialEq)]
struct Snapshot {
    faces: Vec<Resolution>,
    edges: Vec<Resolution>,
    samples: Vec<(SampleRef, [u32; 4])>,
}

fn snapshot(store: &ColorStore) -> Snapshot {
    let mut samples = Vec::new();
    store.for_each_site(|site| samples.push((site.sample, store.get(site.sample).unwrap().map(f32::to_bits))));
    samples.sort_by_key(|(s, _)| *s);
    Snapshot {
        faces: store.face_resolutions().to_vec(),
        edges: (0..store.topology().edge_count()).map(|e| store.edge_resolution(e).unwrap()).collect(),
        samples,
    }
}

struct Scene {
    positions: Vec<[f32; 3]>,
    bvh: MeshBvh,
    camera: OrbitCamera,
}

impl Scene {
    fn new(positions: Vec<[f32; 3]>, triangles: &[[u32; 3]]) -> Self {
        let bvh = MeshBvh::build(&positions, triangles, BvhPreset::FastBuild);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 30.0, 20.0);
        Scene { positions, bvh, camera }
    }

    fn view<'a>(&'a self, base: Option<&'a ColorStore>) -> PaintView<'a> {
        PaintView {
            positions: &self.positions,
            bvh: &self.bvh,
            camera: &self.camera,
            viewport_px: [WIDTH, HEIGHT],
            base,
        }
    }
}

fn settings(tool: Tool, blend: BlendMode, color: Rgba, radius_px: f64) -> BrushSettings {
    BrushSettings {
        tool,
        color,
        blend,
        radius: BrushRadius::Pixels { radius_px },
        strength: 0.7,
        falloff: Falloff::Smooth,
        spacing_percent: 15.0,
        occlusion: true,
        backface_culling: true,
        mirror_x: true,
        follow_resolution: None,
        pressure: meshpaint_core::paint::brush::PressureResponse::default(),
    }
}

/// A store with random colours and mixed resolutions on the UV sphere.
fn random_store(triangles: &[[u32; 3]], vertices: u32) -> ColorStore {
    let topology = Topology::build(vertices, triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| r([2, 4, 8][f % 3])).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(99);
    store.write_all(|_| rng.color());
    store.take_dirty();
    store
}

#[test]
fn undo_restores_bit_exactly_and_redo_reapplies() {
    let (positions, triangles) = uv_sphere(12, 24);
    let scene = Scene::new(positions, &triangles);
    let mut store = random_store(&triangles, scene.positions.len() as u32);
    let base = store.clone();
    let mut history = UndoHistory::default();
    let mut painter = Painter::new(&scene.positions);
    let view = scene.view(Some(&base));
    let strokes: Vec<(BrushSettings, Vec<[f64; 2]>)> = vec![
        (settings(Tool::Paint, BlendMode::Mix, [1.0, 0.0, 0.0, 1.0], 40.0), vec![[300.0, 250.0], [500.0, 350.0]]),
        (
            settings(Tool::Resolution(ResolutionOp::Raise), BlendMode::Mix, [0.0; 4], 50.0),
            vec![[400.0, 300.0], [450.0, 320.0]],
        ),
        (settings(Tool::Paint, BlendMode::Add, [0.2, 0.1, 0.0, 1.0], 60.0), vec![[420.0, 280.0], [380.0, 330.0]]),
        (settings(Tool::Blur, BlendMode::Mix, [0.0; 4], 45.0), vec![[390.0, 300.0], [470.0, 310.0]]),
        (settings(Tool::Resolution(ResolutionOp::Lower), BlendMode::Mix, [0.0; 4], 70.0), vec![[430.0, 300.0]]),
        (settings(Tool::Paint, BlendMode::Multiply, [0.5, 0.9, 0.3, 1.0], 35.0), vec![[350.0, 260.0], [520.0, 300.0]]),
        (settings(Tool::Resolution(ResolutionOp::Set(r(16))), BlendMode::Mix, [0.0; 4], 25.0), vec![[410.0, 310.0]]),
        (settings(Tool::Paint, BlendMode::EraseToBase, [0.0; 4], 50.0), vec![[400.0, 300.0], [440.0, 290.0]]),
        (settings(Tool::Paint, BlendMode::Mix, [0.0, 0.0, 1.0, 1.0], 30.0), vec![[405.0, 305.0], [415.0, 300.0]]),
    ];
    let mut states = vec![snapshot(&store)];
    for (brush_settings, points) in &strokes {
        painter.set_settings(*brush_settings);
        let (update, summary) = brush::replay_stroke(&mut painter, &view, &mut store, &mut history, points).unwrap();
        let summary = summary.unwrap();
        assert!(summary.kept, "{:?} changed nothing ({} dabs)", brush_settings.tool, update.dabs.len());
        states.push(snapshot(&store));
        assert_ne!(states[states.len() - 1], states[states.len() - 2]);
    }
    // Two non-stroke steps: a connected fill and a resolution change for a selection.
    brush::fill(
        &mut store,
        &mut history,
        FillScope::Connected { face: 7 },
        [0.3, 0.3, 0.3, 1.0],
        BlendMode::Mix,
        0.5,
        None,
    )
    .unwrap();
    states.push(snapshot(&store));
    brush::set_resolution(&mut store, &mut history, Some(&[0, 1, 2, 50, 51, 52]), r(32), None).unwrap();
    states.push(snapshot(&store));
    assert!(store.face_resolutions().contains(&r(16)) && store.face_resolutions().contains(&r(32)));
    let steps = states.len() - 1;
    assert_eq!(history.undo_len(), steps);

    for k in (0..steps).rev() {
        assert!(history.undo(&mut store).unwrap());
        assert!(snapshot(&store) == states[k], "undo to state {k} is not bit-exact");
    }
    assert!(!history.undo(&mut store).unwrap());
    assert_eq!(history.redo_len(), steps);
    for (k, state) in states.iter().enumerate().skip(1) {
        assert!(history.redo(&mut store).unwrap());
        assert!(snapshot(&store) == *state, "redo to state {k} is not bit-exact");
    }
    assert!(!history.redo(&mut store).unwrap());
    // Half-way back, then a new stroke: redo is gone, and undo still reaches that state.
    for _ in 0..3 {
        history.undo(&mut store).unwrap();
    }
    assert_eq!(snapshot(&store), states[steps - 3]);
    painter.set_settings(settings(Tool::Paint, BlendMode::Mix, [0.0, 1.0, 0.0, 1.0], 40.0));
    brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &[[400.0, 300.0]]).unwrap();
    assert_eq!(history.redo_len(), 0);
    history.undo(&mut store).unwrap();
    assert_eq!(snapshot(&store), states[steps - 3]);
}

#[test]
fn a_step_stores_only_changed_samples_first_write_winning() {
    let (positions, triangles) = uv_sphere(10, 20);
    let scene = Scene::new(positions, &triangles);
    let mut store = random_store(&triangles, scene.positions.len() as u32);
    let before = snapshot(&store);
    let mut history = UndoHistory::new(usize::MAX);
    let mut painter = Painter::new(&scene.positions);
    let view = scene.view(None);
    painter.set_settings(BrushSettings { mirror_x: false, ..settings(Tool::Paint, BlendMode::Mix, [1.0; 4], 40.0) });
    // Many overlapping dabs in one stroke.
    let points: Vec<[f64; 2]> =
        (0..20).map(|k| [380.0 + f64::from(k % 5) * 6.0, 290.0 + f64::from(k / 5) * 6.0]).collect();
    let (_, summary) = brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &points).unwrap();
    let summary = summary.unwrap();
    let after = snapshot(&store);
    let changed = before.samples.iter().zip(&after.samples).filter(|(a, b)| a != b).count() as u64;
    assert_eq!(summary.samples, changed, "one record per changed sample");
    assert_eq!(summary.bytes, changed as usize * SAMPLE_RECORD_BYTES);
    assert_eq!(history.bytes_used(), summary.bytes);
    history.undo(&mut store).unwrap();
    assert_eq!(snapshot(&store), before);
    // A stroke that changes nothing is not kept and does not clear redo.
    let (_, summary) =
        brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &[[2.0, 2.0], [4.0, 4.0]]).unwrap();
    assert!(!summary.unwrap().kept);
    assert_eq!(history.redo_len(), 1);
}

#[test]
fn the_memory_cap_drops_the_oldest_steps() {
    let (positions, triangles) = uv_sphere(10, 20);
    let scene = Scene::new(positions, &triangles);
    let mut store = random_store(&triangles, scene.positions.len() as u32);
    let mut painter = Painter::new(&scene.positions);
    let view = scene.view(None);
    let mut history = UndoHistory::new(usize::MAX);
    let mut states = vec![snapshot(&store)];
    let mut sizes = Vec::new();
    for k in 0..6 {
        let color = [k as f32 / 6.0, 0.5, 0.5, 1.0];
        painter.set_settings(BrushSettings { mirror_x: false, ..settings(Tool::Paint, BlendMode::Mix, color, 50.0) });
        let (_, summary) =
            brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &[[390.0 + 5.0 * f64::from(k), 300.0]])
                .unwrap();
        sizes.push(summary.unwrap().bytes);
        states.push(snapshot(&store));
    }
    assert_eq!(history.bytes_used(), sizes.iter().sum::<usize>());
    // A cap that holds the newest two steps only.
    let cap = sizes[4] + sizes[5] + sizes[3] / 2;
    history.set_cap_bytes(cap);
    assert_eq!(history.undo_len(), 2);
    assert!(history.bytes_used() <= cap);
    assert_eq!(history.dropped_steps(), 4);
    history.undo(&mut store).unwrap();
    history.undo(&mut store).unwrap();
    assert!(!history.undo(&mut store).unwrap());
    assert_eq!(snapshot(&store), states[4]);
    // A step larger than the cap on its own is not kept.
    history.set_cap_bytes(16);
    assert_eq!(history.undo_len(), 0);
    painter.set_settings(BrushSettings { mirror_x: false, ..settings(Tool::Paint, BlendMode::Mix, [0.0; 4], 50.0) });
    let (_, summary) = brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &[[400.0, 300.0]]).unwrap();
    let summary = summary.unwrap();
    assert!(!summary.kept && summary.bytes > 16);
    assert!(history.bytes_used() <= 16);
}

#[test]
fn undo_is_refused_during_a_stroke_and_outside_changes_are_detected() {
    let (positions, triangles) = uv_sphere(6, 10);
    let scene = Scene::new(positions, &triangles);
    let mut store = random_store(&triangles, scene.positions.len() as u32);
    let mut history = UndoHistory::default();
    let mut painter = Painter::new(&scene.positions);
    painter.set_settings(BrushSettings {
        mirror_x: false,
        ..settings(Tool::Resolution(ResolutionOp::Raise), BlendMode::Mix, [0.0; 4], 80.0)
    });
    let view = scene.view(None);
    painter.begin_stroke(&view, &mut store, &mut history, [400.0, 300.0]).unwrap();
    assert_eq!(history.undo(&mut store), Err(UndoError::Busy));
    assert!(matches!(history.begin_step(&store, "x"), Err(UndoError::StepOpen)));
    painter.end_stroke(&mut history).unwrap();
    // Someone changes a resolution behind the history's back: undo notices.
    let raised = (0..store.topology().face_count()).find(|&f| store.face_resolution(f) == Some(r(16))).unwrap();
    let neighbour_edge = store.topology().face_edges[raised as usize][0];
    let other = store.topology().faces_of_edge(neighbour_edge).iter().map(|&(f, _)| f).find(|&f| f != raised).unwrap();
    store.write_resolution(other, r(64)).unwrap();
    assert!(matches!(history.undo(&mut store), Err(UndoError::Mismatch(_))));
    assert_eq!(history.undo_len(), 0);
}

#[test]
fn the_generation_counts_changes() {
    let (positions, triangles) = uv_sphere(6, 10);
    let scene = Scene::new(positions, &triangles);
    let mut store = random_store(&triangles, scene.positions.len() as u32);
    let mut history = UndoHistory::default();
    assert_eq!(history.generation(), 0);
    history.begin_step(&store, "manual").unwrap();
    assert!(history.set_sample(&mut store, SampleRef::Vertex(3), [1.0; 4]));
    assert!(history.set_sample(&mut store, SampleRef::Vertex(3), [0.5; 4]));
    let summary = history.end_step().unwrap();
    assert_eq!(summary.samples, 1);
    assert_eq!(history.generation(), 1);
    history.undo(&mut store).unwrap();
    assert_eq!(history.generation(), 2);
    history.redo(&mut store).unwrap();
    assert_eq!(history.generation(), 3);
    assert_eq!(store.vertex_color(3), Some([0.5; 4]));
}

/// Writes through [`StoreWriter::split`] from parallel tasks: the refused element lists, then
/// writes to every second sample of many elements (some twice, some bit-identical) against a
/// map of the expected store; the changed elements are dirty, undo restores the snapshot and
/// redo the written state, bit for bit.
#[test]
fn split_writes_record_once_and_undo_exactly() {
    use meshpaint_core::paint::split::UndoLog;
    use meshpaint_core::paint::undo::{Element, StoreWriter};
    use rayon::prelude::*;
    let (positions, triangles) = uv_sphere(12, 16);
    let mut store = random_store(&triangles, positions.len() as u32);
    let before = snapshot(&store);
    let mut history = UndoHistory::default();
    history.begin_step(&store, "split").unwrap();
    let topology = store.topology().clone();
    let mut elements: Vec<Element> = (0..topology.face_count()).map(Element::Interior).collect();
    elements.extend((0..topology.edge_count()).map(Element::Edge));
    elements.reverse();
    let mut writer = StoreWriter::new(&mut store, &mut history);
    assert!(writer.split(&[Element::Edge(0), Element::Vertices]).is_none(), "vertices are refused");
    assert!(writer.split(&[Element::Edge(3), Element::Interior(0), Element::Edge(3)]).is_none(), "a repeat");
    assert!(writer.split(&[Element::Edge(topology.edge_count())]).is_none(), "past the end");
    // The expected colours, written by hand from the snapshot.
    let mut expected: std::collections::HashMap<SampleRef, [u32; 4]> = before.samples.iter().copied().collect();
    let new_color = |sample: SampleRef| -> Rgba {
        let id = match sample {
            SampleRef::Edge { edge, offset } => edge * 7 + offset,
            SampleRef::Interior { face, offset } => face * 5 + offset,
            SampleRef::Vertex(v) => v,
        };
        [(id % 13) as f32 / 13.0, 0.5, 0.25, 1.0]
    };
    let mut changed_elements = std::collections::HashSet::new();
    for &element in &elements {
        let count = match element {
            Element::Edge(edge) => writer.store().edge_samples(edge).len(),
            Element::Interior(face) => writer.store().interior_samples(face).len(),
            Element::Vertices => 0,
        };
        for index in (0..count as u32).step_by(2) {
            let sample = element.sample(index);
            let old = expected[&sample];
            let new = new_color(sample).map(f32::to_bits);
            if new != old {
                changed_elements.insert(element);
            }
            expected.insert(sample, new);
        }
    }
    let split = writer.split(&elements).unwrap();
    let mut slices = split.elements;
    let logs: Vec<UndoLog> = slices
        .par_chunks_mut(7)
        .map(|slices| {
            let mut log = UndoLog::default();
            for slice in slices.iter_mut() {
                let element = slice.element();
                for index in (0..slice.samples().len() as u32).step_by(2) {
                    // Twice: the second write changes nothing and records nothing.
                    let color = new_color(element.sample(index));
                    slice.write(index, color, &mut log);
                    assert!(!slice.write(index, color, &mut log));
                }
            }
            log
        })
        .collect();
    let changed: Vec<Element> = slices.iter().filter(|s| s.changed() > 0).map(|s| s.element()).collect();
    drop(slices);
    writer.commit(changed, logs);
    let dirty = store.take_dirty();
    for element in &changed_elements {
        let reported = match *element {
            Element::Edge(edge) => dirty.edges.contains(&edge),
            Element::Interior(face) => dirty.faces.contains(&face),
            Element::Vertices => true,
        };
        assert!(reported, "{element:?} changed but is not dirty");
    }
    let written = snapshot(&store);
    for (sample, bits) in &written.samples {
        assert_eq!(*bits, expected[sample], "{sample:?}");
    }
    let summary = history.end_step().unwrap();
    let differing = before.samples.iter().zip(&written.samples).filter(|(a, b)| a.1 != b.1).count() as u64;
    assert_eq!(summary.samples, differing, "one record per changed sample");
    assert!(history.undo(&mut store).unwrap());
    assert!(snapshot(&store) == before, "undo");
    assert!(history.redo(&mut store).unwrap());
    assert!(snapshot(&store) == written, "redo");
}
