//! The colour-value extremes: RGBA16F at its largest finite value, HDR colours from the Add
//! blend, NaN and infinite colours (docs/FORMAT.md "Colour values": one rule everywhere).

use serde_json::json;

use meshpaint_core::colors::format::{ColorFormat, MAX_CHANNEL, Rgba, is_storable};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::file as packed_file;
use meshpaint_core::packing::linear::{FaceRecord, PackedMesh};
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::brush::{BlendMode, BrushSettings};
use meshpaint_core::paint::undo::UndoHistory;
use meshpaint_render::{FilterMode, Gpu};

use super::probe::{Rng, render};
use super::{ExtremeCase, ExtremesError};

const TEST: &str =
    "tests/app/extremes.rs; tests/app/budget.rs the_store_blends_and_encoders_never_hold_a_non_finite_colour";

/// One triangle facing the default camera, uniform `color` at R = `2^log2`.
fn triangle_store(color: Rgba, log2: u32) -> Result<(Vec<[f32; 3]>, ColorStore), ExtremesError> {
    let positions = vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
    let topology = Topology::build(3, &[[0, 1, 2]]).map_err(ExtremesError::setup)?;
    let r = Resolution::from_log2(log2).map_err(ExtremesError::setup)?;
    Ok((positions, ColorStore::uniform(topology, r, color)))
}

/// Every value case.
pub fn value_extremes(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let mut rows = rgba16f_max(gpu)?;
    rows.push(add_blend_hdr()?);
    rows.push(non_finite()?);
    Ok(rows)
}

/// 65504 in every colour channel, packed in RGBA16F: decoded exactly, and rendered as
/// full white (the sRGB8 target saturates; nothing becomes NaN or black).
fn rgba16f_max(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let top = [MAX_CHANNEL, MAX_CHANNEL, MAX_CHANNEL, 1.0];
    let (positions, store) = triangle_store(top, 3)?;
    let packed = pack(&store, &positions, ColorFormat::Rgba16F).map_err(ExtremesError::setup)?;
    let decode_error = (0..packed.sample_count())
        .filter_map(|k| packed.color(k))
        .map(|c| (0..4).map(|ch| f64::from((c[ch] - top[ch]).abs())).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    let mesh = gpu.upload(&packed)?;
    let camera = meshpaint_core::camera::OrbitCamera::framing(
        meshpaint_core::camera::BoundingSphere::of_points(&positions),
        0.0,
        0.0,
    );
    let mut render_error = 0u8;
    let mut covered = 0u32;
    for filter in [FilterMode::Linear, FilterMode::Trilinear] {
        let image = render(gpu, &mesh, camera, filter)?;
        for pixel in image.pixels().filter(|p| p.0[3] != 0) {
            covered += 1;
            render_error = render_error.max(pixel.0.iter().map(|&c| 255 - c).max().unwrap_or(0));
        }
    }
    Ok(vec![
        ExtremeCase {
            case: "rgba16f_max_finite_decode".into(),
            measured: decode_error,
            unit: "colour units (|decoded − 65504|, largest over the samples)",
            tolerance: 0.0,
            test: TEST,
            outcome: "measured: 65504 is RGBA16F's largest finite value, held exactly".into(),
            sound: packed.sample_count() > 0,
            detail: json!({ "samples": packed.sample_count() }),
        },
        ExtremeCase {
            case: "rgba16f_max_finite_render".into(),
            measured: f64::from(render_error),
            unit: "8-bit steps below full white (RGBA8 sRGB target), largest over covered pixels",
            tolerance: 0.0,
            test: TEST,
            outcome: "sanitised: the render target saturates at 1".into(),
            sound: covered > 1000,
            detail: json!({ "covered_px": covered, "filters": ["linear", "trilinear"] }),
        },
    ])
}

/// HDR colours from the Add blend: sums of random values up to 2·65504 stored and packed
/// in RGBA16F, against `min(a + b, 65504)` (relative error; binary16 rounds to 2⁻¹¹).
fn add_blend_hdr() -> Result<ExtremeCase, ExtremesError> {
    let (positions, mut store) = triangle_store([0.0, 0.0, 0.0, 1.0], 5)?;
    let mut rng = Rng(65504);
    let mut wanted = Vec::new();
    let mut sites = Vec::new();
    store.for_each_site(|site| sites.push(site));
    for (k, site) in sites.iter().enumerate() {
        // Magnitudes from 1e-3 to 2 · 65504 (log-uniform), so both rounding and saturation show.
        let magnitude = |rng: &mut Rng| 10f32.powf(-3.0 + 8.12 * (rng.unit_f64() as f32)).min(MAX_CHANNEL);
        let (a, b) = ([0; 3].map(|_| magnitude(&mut rng)), [0; 3].map(|_| magnitude(&mut rng)));
        let old = [a[0], a[1], a[2], 1.0];
        let color = [b[0], b[1], b[2], 1.0];
        let blended = BlendMode::Add.blend(old, color, old, 1.0);
        UndoHistory::new(0).set_sample(&mut store, site.sample, blended);
        wanted.push((k, [0, 1, 2].map(|c| (f64::from(a[c]) + f64::from(b[c])).min(f64::from(MAX_CHANNEL)))));
    }
    let packed = pack(&store, &positions, ColorFormat::Rgba16F).map_err(ExtremesError::setup)?;
    let mut worst = 0.0f64;
    let mut saturated = 0u32;
    for (k, want) in &wanted {
        let site = sites[*k];
        let Some(stored) = store.get(site.sample) else { continue };
        // Nearest at the sample's own lattice point reads exactly that sample.
        let Some(got) = sample(&packed, site.face, site.barycentric, Filter::Nearest, 0) else { continue };
        for c in 0..3 {
            worst = worst.max((f64::from(got[c]) - want[c]).abs() / want[c]);
            saturated += u32::from(stored[c] == MAX_CHANNEL);
        }
    }
    let top = [MAX_CHANNEL, MAX_CHANNEL, MAX_CHANNEL, 1.0];
    let at_top = BlendMode::Add.blend(top, top, top, 1.0);
    let mut rgba8 = Vec::new();
    ColorFormat::Rgba8Srgb.encode_into([1.5, 0.5, 1.0, 1.0], &mut rgba8);
    Ok(ExtremeCase {
        case: "add_blend_hdr_rgba16f".into(),
        measured: worst,
        unit: "relative error of the packed RGBA16F value against min(a + b, 65504)",
        tolerance: 2f64.powi(-11),
        test: "tests/app/extremes.rs",
        outcome: format!(
            "sanitised: Add saturates at 65504 (65504 + 65504 = {}), RGBA8 clamps HDR to 1 (1.5 → {:?})",
            at_top[0],
            ColorFormat::Rgba8Srgb.decode(&rgba8)[0]
        ),
        sound: at_top.iter().all(|c| c.is_finite()) && saturated > 0 && wanted.len() > 10,
        detail: json!({ "samples": wanted.len(), "channels_saturated": saturated }),
    })
}

/// NaN and infinite colours: written into the store, blended, encoded, given to a brush,
/// written to a packed file. Measured: how many non-finite or out-of-range values got
/// through (the store, blends and encoders sanitise; brushes and files refuse).
fn non_finite() -> Result<ExtremeCase, ExtremesError> {
    let (_, mut store) = triangle_store([0.5, 0.5, 0.5, 1.0], 3)?;
    let bad: [Rgba; 4] = [
        [f32::NAN, 0.5, 0.5, 1.0],
        [f32::INFINITY, f32::NEG_INFINITY, 0.5, f32::NAN],
        [0.5, 0.5, 0.5, f32::INFINITY],
        [f32::NAN; 4],
    ];
    let mut through = 0u32;
    let mut stored = Vec::new();
    for color in bad {
        UndoHistory::new(0).set_sample(&mut store, SampleRef::Vertex(0), color);
        let got = store.get(SampleRef::Vertex(0)).unwrap_or([f32::NAN; 4]);
        through += u32::from(!is_storable(got));
        stored.push(format!("{color:?} → {got:?}"));
        for mode in BlendMode::ALL {
            through += u32::from(!is_storable(mode.blend(got, color, color, 0.5)));
        }
        for format in ColorFormat::ALL {
            let mut bytes = Vec::new();
            format.encode_into(color, &mut bytes);
            through += u32::from(!is_storable(format.decode(&bytes)));
        }
    }
    let brush = BrushSettings { color: [f32::NAN, 0.0, 0.0, 1.0], ..BrushSettings::default() }.validate();
    through += u32::from(brush.is_ok());
    let mut colors = Vec::new();
    for channel in [0.5f32, 0.5, 0.5, 1.0, f32::NAN, 0.0, 0.0, 1.0, 0.25, 0.25, 0.25, 1.0] {
        colors.extend_from_slice(&channel.to_le_bytes());
    }
    let file = packed_file::to_bytes(&PackedMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        indices: vec![[0, 1, 2]],
        vertex_levels: 1,
        face_records: vec![FaceRecord { interior: 0, edges: [0; 3] }],
        format: ColorFormat::Rgba32F,
        colors,
    });
    through += u32::from(file.is_ok());
    let message = |result: Result<String, String>| result.unwrap_or_else(|e| e);
    Ok(ExtremeCase {
        case: "non_finite_colors".into(),
        measured: f64::from(through),
        unit: "non-finite or out-of-range values that reached the store, a blend, an encoder, a brush or a file",
        tolerance: 0.0,
        test: TEST,
        outcome: format!(
            "sanitised by the store, every blend and every encoder (NaN → 0, +∞ → 65504, −∞ → 0, alpha to [0, 1]); \
             refused by the brush (\"{}\") and by the packed writer and reader (\"{}\")",
            message(brush.map(|_| "accepted".into()).map_err(|e| e.to_string())),
            message(file.map(|_| "written".into()).map_err(|e| e.to_string())),
        ),
        sound: true,
        detail: json!({
            "store": stored,
            "gpu": "colours reach the GPU only from the packer (encoders clamp) or the packed reader (refuses); \
                    GpuMesh::upload itself does not check a hand-made PackedMesh",
        }),
    })
}
