//! Material layers (docs/LAYERS.md) against independent truths: the composite against the
//! W3C compositing formulas evaluated here in `f64` for every blend mode, with masks,
//! opacity and hidden layers; a single normal layer composites to itself bit for bit;
//! the incremental composite (dirty elements) equals a full one bit for bit; undo and redo of
//! every layer operation and of paint steps restore every layer bit for bit.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use crate::common::{Rng, WriteThrough, octahedron};
use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::layers::{BlendMode, LayerStack, PaintTarget};

/// The octahedron at mixed resolutions (1, 2, 4, 8), every sample opaque grey.
fn mixed_store() -> ColorStore {
    let (_, topology) = octahedron();
    let faces = topology.face_count() as usize;
    let resolutions = (0..faces).map(|f| Resolution::new(1 << (f % 4)).unwrap()).collect();
    ColorStore::with_resolutions(topology, resolutions, [0.5, 0.5, 0.5, 1.0]).unwrap()
}

/// Every sample of `store` with its colour, in site order.
fn samples(store: &ColorStore) -> Vec<(SampleRef, Rgba)> {
    let mut all = Vec::new();
    store.for_each_site(|site| all.push((site.sample, store.get(site.sample).unwrap())));
    all
}

fn bits(samples: &[(SampleRef, Rgba)]) -> Vec<(SampleRef, [u32; 4])> {
    samples.iter().map(|&(s, c)| (s, c.map(f32::to_bits))).collect()
}

/// Paints `color_at` into the active layer's `target` through the stack's writer.
fn paint(stack: &mut LayerStack, target: PaintTarget, mut color_at: impl FnMut() -> Rgba) {
    stack.begin_paint(target, "paint").unwrap();
    stack.writer().unwrap().fill_with(|_| color_at());
    stack.end_paint().unwrap();
}

/// `B(Cb, Cs)` of the W3C spec, per component.
fn blend_f64(mode: BlendMode, cb: f64, cs: f64) -> f64 {
    match mode {
        BlendMode::Normal => cs,
        BlendMode::Multiply => cb * cs,
        BlendMode::Add => cb + cs,
        BlendMode::Overlay => {
            // Overlay(Cb, Cs) = HardLight(Cs, Cb): multiply for Cb ≤ 0.5, screen above.
            if cb <= 0.5 {
                cs * (2.0 * cb)
            } else {
                let t = 2.0 * cb - 1.0;
                cs + t - cs * t
            }
        }
    }
}

/// The composite of one sample in `f64`: source-over with blending (W3C Compositing and
/// Blending Level 1, §5.8 and §9.1.4, straight alpha), each result clamped to the store's
/// value rule (RGB ≥ 0, alpha in [0, 1]).
fn reference(stack: &LayerStack, sample: SampleRef) -> [f64; 4] {
    let (mut cb, mut ab) = ([0.0f64; 3], 0.0f64);
    for layer in stack.layers().iter().filter(|l| l.visible()) {
        let source = layer.content().get(sample).unwrap().map(f64::from);
        let mask = layer.mask().map_or(1.0, |m| f64::from(m.get(sample).unwrap()[0]).clamp(0.0, 1.0));
        let a_s = source[3] * f64::from(layer.opacity()) * mask;
        let a_o = a_s + ab * (1.0 - a_s);
        if a_o == 0.0 {
            // Undefined colour: docs/LAYERS.md keeps the upper layer's.
            (cb, ab) = ([source[0], source[1], source[2]], 0.0);
            continue;
        }
        let mut co = [0.0; 3];
        for c in 0..3 {
            let mixed = (1.0 - ab) * source[c] + ab * blend_f64(layer.blend(), cb[c], source[c]);
            let premultiplied = a_s * mixed + (1.0 - a_s) * ab * cb[c];
            co[c] = (premultiplied / a_o).max(0.0);
        }
        (cb, ab) = (co, a_o.clamp(0.0, 1.0));
    }
    [cb[0], cb[1], cb[2], ab]
}

/// A stack of four layers over a random base: every blend mode, random opacities, masks
/// on two layers, random coverage (some samples fully transparent or fully opaque).
fn random_stack(seed: u64, base: &ColorStore) -> LayerStack {
    let mut rng = Rng(seed);
    let mut stack = LayerStack::from_store(base);
    for (n, mode) in BlendMode::ALL.into_iter().enumerate() {
        stack.add_layer(&format!("layer {n}"), None).unwrap();
        let index = stack.active();
        paint(&mut stack, PaintTarget::Content, || {
            let mut color = rng.color();
            // Coverage 0 and 1 exactly on some samples; HDR values for add and multiply.
            match rng.next() % 5 {
                0 => color[3] = 0.0,
                1 => color[3] = 1.0,
                2 if matches!(mode, BlendMode::Add | BlendMode::Multiply) => color[0] *= 4.0,
                _ => {}
            }
            color
        });
        stack.set_blend(index, mode).unwrap();
        stack.set_opacity(index, [1.0, 0.8, 0.35, 0.6][n]).unwrap();
        if n % 2 == 1 {
            stack.add_mask(index, 1.0, None).unwrap();
            paint(&mut stack, PaintTarget::Mask, || {
                let m = if rng.next().is_multiple_of(4) { 0.0 } else { rng.unit() };
                [m, m, m, 1.0]
            });
        }
    }
    stack
}

fn assert_matches_reference(stack: &LayerStack, composite: &ColorStore, what: &str) {
    let mut worst = 0.0f64;
    for (sample, got) in samples(composite) {
        let want = reference(stack, sample);
        for c in 0..4 {
            let error = (f64::from(got[c]) - want[c]).abs() / want[c].abs().max(1.0);
            worst = worst.max(error);
            assert!(error < 1e-6, "{what}: {sample:?} channel {c}: composite {} vs f64 {}", got[c], want[c]);
        }
    }
    eprintln!("{what}: largest relative error against f64 {worst:.2e}");
}

#[test]
fn composite_matches_the_f64_blend_formulas_for_every_mode_with_masks_and_opacity() {
    let mut base = mixed_store();
    let mut rng = Rng(7);
    base.write_all(|_| rng.color());
    for seed in [1, 2, 3] {
        let mut stack = random_stack(seed, &base);
        let mut composite = base.clone();
        stack.sync(&mut composite);
        assert_matches_reference(&stack, &composite, &format!("seed {seed}"));
        // Each mode alone over the base, and with the base hidden (over transparent).
        for (index, mode) in BlendMode::ALL.into_iter().enumerate() {
            let mut only = stack.clone();
            for other in 1..only.layers().len() {
                only.set_visible(other, other == index + 1).unwrap();
            }
            only.sync(&mut composite);
            assert_matches_reference(&only, &composite, &format!("seed {seed}, {mode:?} over the base"));
            only.set_visible(0, false).unwrap();
            only.sync(&mut composite);
            assert_matches_reference(&only, &composite, &format!("seed {seed}, {mode:?} over nothing"));
        }
    }
}

#[test]
fn one_normal_layer_composites_bit_exactly() {
    let mut base = mixed_store();
    let mut rng = Rng(11);
    // Random colours with random alpha, HDR values and exact zeros.
    base.write_all(|_| {
        let mut c = rng.color();
        c[0] *= 100.0;
        if rng.next().is_multiple_of(3) {
            c[3] = 0.0;
        }
        c
    });
    let mut stack = LayerStack::from_store(&base);
    assert!(stack.is_single_layer());
    let mut composite = mixed_store();
    stack.sync(&mut composite);
    assert_eq!(bits(&samples(&composite)), bits(&samples(&base)));
}

#[test]
fn the_composite_kept_up_through_dirty_elements_equals_a_full_composite() {
    let mut base = mixed_store();
    let mut rng = Rng(5);
    base.write_all(|_| rng.color());
    let mut stack = random_stack(9, &base);
    let mut incremental = base.clone();
    stack.sync(&mut incremental);
    incremental.take_dirty();
    // A few strokes on one face's samples of the active layer and its mask.
    for (round, target) in [PaintTarget::Content, PaintTarget::Mask, PaintTarget::Content].into_iter().enumerate() {
        stack.begin_paint(target, "stroke").unwrap();
        let mut writer = stack.writer().unwrap();
        let face = 5 + round as u32;
        let r = writer.store().face_resolution(face).unwrap().get();
        for i in 0..=r {
            for j in 0..=r - i {
                let sample = writer.store().face_sample_ref(face, i, j).unwrap();
                writer.set(sample, rng.color());
            }
        }
        stack.end_paint().unwrap();
        let written = stack.sync(&mut incremental);
        assert!(written > 0, "round {round}: the stroke changed the composite");
        let dirty = incremental.take_dirty();
        assert!(!dirty.is_empty());
        let mut full = mixed_store();
        stack.composite_into(&mut full);
        assert_eq!(bits(&samples(&incremental)), bits(&samples(&full)), "round {round}");
    }
}

/// Everything that defines a stack, bit for bit (the history aside).
type Snapshot =
    Vec<(u64, String, bool, u32, BlendMode, Vec<(SampleRef, [u32; 4])>, Option<Vec<(SampleRef, [u32; 4])>>)>;

fn snapshot(stack: &LayerStack) -> Snapshot {
    stack
        .layers()
        .iter()
        .map(|l| {
            let mask = l.mask().map(|m| bits(&samples(m)));
            (
                l.id(),
                l.name().to_owned(),
                l.visible(),
                l.opacity().to_bits(),
                l.blend(),
                bits(&samples(l.content())),
                mask,
            )
        })
        .collect()
}

#[test]
fn undo_and_redo_of_layer_operations_and_paint_are_bit_exact() {
    let mut base = mixed_store();
    let mut rng = Rng(3);
    base.write_all(|_| rng.color());
    let mut stack = LayerStack::from_store(&base);
    let mut states = vec![snapshot(&stack)];
    let mut composites = Vec::new();
    let mut composite = base.clone();
    stack.sync(&mut composite);
    composites.push(bits(&samples(&composite)));
    type Action = Box<dyn Fn(&mut LayerStack, &mut Rng)>;
    let actions: Vec<Action> = vec![
        Box::new(|s, rng| paint(s, PaintTarget::Content, || rng.color())),
        Box::new(|s, _| {
            s.add_layer("dirt", None).unwrap();
        }),
        Box::new(|s, rng| paint(s, PaintTarget::Content, || rng.color())),
        Box::new(|s, _| s.add_mask(1, 1.0, None).unwrap()),
        Box::new(|s, rng| paint(s, PaintTarget::Mask, || [rng.unit(), 0.0, 0.0, 1.0])),
        Box::new(|s, _| s.set_opacity(1, 0.4).unwrap()),
        Box::new(|s, _| s.set_blend(1, BlendMode::Overlay).unwrap()),
        Box::new(|s, _| {
            s.add_layer("scratches", None).unwrap();
        }),
        Box::new(|s, rng| paint(s, PaintTarget::Content, || rng.color())),
        Box::new(|s, _| s.set_blend(2, BlendMode::Multiply).unwrap()),
        Box::new(|s, _| s.set_visible(0, false).unwrap()),
        Box::new(|s, _| s.rename(1, "rust").unwrap()),
        Box::new(|s, _| s.move_layer(2, 0).unwrap()),
        Box::new(|s, _| s.delete_layer(1).unwrap()),
        Box::new(|s, _| s.remove_mask(1).unwrap()),
        Box::new(|s, rng| {
            s.set_active(0).unwrap();
            paint(s, PaintTarget::Content, || rng.color());
        }),
    ];
    for action in &actions {
        action(&mut stack, &mut rng);
        stack.sync(&mut composite);
        states.push(snapshot(&stack));
        composites.push(bits(&samples(&composite)));
    }
    assert_eq!(stack.undo_len(), actions.len());
    for at in (0..actions.len()).rev() {
        assert!(stack.undo().unwrap());
        stack.sync(&mut composite);
        assert!(snapshot(&stack) == states[at], "undo back to state {at}");
        assert_eq!(bits(&samples(&composite)), composites[at], "composite after undo to state {at}");
    }
    assert!(!stack.undo().unwrap());
    for at in 1..=actions.len() {
        assert!(stack.redo().unwrap());
        stack.sync(&mut composite);
        assert!(snapshot(&stack) == states[at], "redo to state {at}");
        assert_eq!(bits(&samples(&composite)), composites[at], "composite after redo to state {at}");
    }
    assert!(!stack.redo().unwrap());
}

#[test]
fn the_active_layer_stays_the_same_layer_across_operations() {
    let mut stack = LayerStack::from_store(&mixed_store());
    for name in ["a", "b", "c"] {
        stack.add_layer(name, None).unwrap();
    }
    let name = |s: &LayerStack| s.layers()[s.active()].name().to_owned();
    stack.set_active(2).unwrap();
    assert_eq!(name(&stack), "b");
    stack.move_layer(3, 0).unwrap();
    assert_eq!(name(&stack), "b", "a reorder around it");
    stack.delete_layer(0).unwrap();
    assert_eq!(name(&stack), "b", "a delete below it");
    stack.delete_layer(stack.active()).unwrap();
    assert_eq!(name(&stack), "a", "deleting it (the top layer): the one below");
    stack.undo().unwrap();
    stack.undo().unwrap();
    stack.undo().unwrap();
    assert_eq!(stack.layers().len(), 4);
}

#[test]
fn layer_operations_refuse_what_they_cannot_do() {
    let mut stack = LayerStack::from_store(&mixed_store());
    assert!(stack.delete_layer(0).is_err(), "the last layer stays");
    assert!(stack.set_opacity(3, 0.5).is_err());
    assert!(stack.rename(0, &"x".repeat(257)).is_err());
    assert!(stack.begin_paint(PaintTarget::Mask, "mask").is_err(), "no mask to paint");
    stack.begin_paint(PaintTarget::Content, "stroke").unwrap();
    assert!(stack.add_layer("busy", None).is_err(), "no operation during a stroke");
    assert!(stack.undo().is_err());
    stack.end_paint();
    assert_eq!(stack.undo_len(), 0, "an empty stroke is no entry");
    let budget = meshpaint_core::colors::budget::Budget::with_memory(
        1000,
        meshpaint_core::colors::budget::MemorySource::Environment,
    );
    let format = meshpaint_core::colors::format::ColorFormat::Rgba8Srgb;
    assert!(stack.add_layer("too big", Some((&budget, format))).is_err(), "the budget counts every layer store");
    assert_eq!(stack.layers().len(), 1);
}
