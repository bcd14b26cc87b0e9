//! Headless strokes (`meshpaint paint`, tests, benchmarks): colour and stroke parsing,
//! stroke replay, and the count of samples a dab would cover.

use glam::DVec3;

use crate::colors::format::Rgba;
use crate::colors::store::ColorStore;
use crate::paint::undo::{StepSummary, UndoHistory};

use super::error::BrushError;
use super::footprint::{Coverage, Footprint};
use super::painter::{PaintView, Painter, StrokeUpdate};
use super::scratch::{Scratch, accumulate_masks, face_elements, position};
use super::settings::{Falloff, StrokePoint};

/// Parses `#rrggbb` or `#rgb` (the `#` optional, surrounding spaces ignored) as an sRGB
/// colour and returns it in linear light, opaque. `#rgb` is `#rrggbb` with each digit
/// doubled (CSS).
pub fn parse_hex_color(text: &str) -> Option<Rgba> {
    let text = text.trim();
    let hex = text.strip_prefix('#').unwrap_or(text);
    if !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let channel = |k: usize| match hex.len() {
        6 => u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok(),
        3 => u8::from_str_radix(&hex[k..k + 1], 16).ok().map(|d| d * 17),
        _ => None,
    };
    let (r, g, b) = (channel(0)?, channel(1)?, channel(2)?);
    Some([
        crate::colors::format::decode_srgb8(r),
        crate::colors::format::decode_srgb8(g),
        crate::colors::format::decode_srgb8(b),
        1.0,
    ])
}

/// Parses a stroke given as `"x0,y0 x1,y1,p1 …"`: pixels, each point with an optional pen
/// pressure `p` in `0..=1` (1.0 when left out, as from a mouse).
pub fn parse_stroke(text: &str) -> Result<Vec<StrokePoint>, String> {
    text.split_whitespace()
        .map(|point| {
            let parts: Vec<&str> = point.split(',').collect();
            let number = |part: &str| -> Result<f64, String> {
                let value: f64 = part.trim().parse().map_err(|_| format!("'{part}' in '{point}' is not a number"))?;
                if value.is_finite() { Ok(value) } else { Err(format!("'{point}' is not finite")) }
            };
            let (x, y, pressure) = match parts.as_slice() {
                [x, y] => (number(x)?, number(y)?, 1.0),
                [x, y, p] => (number(x)?, number(y)?, number(p)?),
                _ => return Err(format!("'{point}' is not x,y or x,y,pressure")),
            };
            if !(0.0..=1.0).contains(&pressure) {
                return Err(format!("pressure {pressure} in '{point}' is not in 0..=1"));
            }
            Ok(StrokePoint { px: [x, y], pressure: pressure as f32 })
        })
        .collect::<Result<Vec<_>, _>>()
        .and_then(|points| if points.is_empty() { Err("the stroke has no points".into()) } else { Ok(points) })
}

/// Replays one stroke through `points` (cursor positions `[x, y]` in pixels, or
/// [`StrokePoint`]s with their pressure): begin, extend, end. Returns the combined update and
/// the closed step's summary.
pub fn replay_stroke<P: Copy + Into<StrokePoint>>(
    painter: &mut Painter,
    view: &PaintView,
    store: &mut ColorStore,
    history: &mut UndoHistory,
    points: &[P],
) -> Result<(StrokeUpdate, Option<StepSummary>), BrushError> {
    let Some((&first, rest)) = points.split_first() else {
        return Ok((StrokeUpdate::default(), None));
    };
    let mut total = painter.begin_stroke(view, store, history, first)?;
    for &point in rest {
        let update = painter.stroke_to(view, store, history, point)?;
        total.dabs.extend(update.dabs);
        total.stats.add(update.stats);
    }
    let summary = painter.end_stroke(history);
    Ok((total, summary))
}

/// Samples within `radius` of `center` (what a constant-falloff dab without culling or
/// occlusion covers), counted without writing.
pub fn samples_within(view: &PaintView, store: &ColorStore, center: DVec3, radius: f64) -> u64 {
    let footprint = Footprint::new([center; 2], [center; 2], 1, radius, 1.0, Falloff::Constant, None);
    let mut scratch = Scratch::default();
    scratch.fit(store);
    scratch.faces = view.bvh.faces_in_sphere(center, radius);
    scratch.face_masks = vec![1; scratch.faces.len()];
    let stamp = accumulate_masks(store, &mut scratch);
    let topology = store.topology();
    let mut count = 0u64;
    let mut row = |a: DVec3, b: DVec3, lo: u32, hi: u32| {
        if let Some((k0, k1)) = footprint.row_range(a, b, lo, hi, 1) {
            count += (k0..=k1).filter(|&k| footprint.weight(a + b * f64::from(k), 1) > 0.0).count() as u64;
        }
    };
    for &face in &scratch.faces {
        let Some((r, corners, edges)) = face_elements(store, face) else {
            continue;
        };
        let res = r.get();
        let [p0, p1, p2] = corners.map(|v| position(view.positions, v));
        let inv = 1.0 / f64::from(res);
        for i in 1..res.saturating_sub(1) {
            row(p0 + (p1 - p0) * (f64::from(i) * inv), (p2 - p0) * inv, 1, res - 1 - i);
        }
        for edge in edges {
            if scratch.edge_stamp[edge as usize] == stamp {
                scratch.edge_stamp[edge as usize] = stamp + 1;
                let (Some(r), Some(&[lo, hi])) =
                    (store.edge_resolution(edge), topology.edge_vertices.get(edge as usize))
                else {
                    continue;
                };
                let a = position(view.positions, lo);
                row(a, (position(view.positions, hi) - a) / f64::from(r.get()), 1, r.get() - 1);
            }
        }
        for v in corners {
            if scratch.vertex_stamp[v as usize] == stamp {
                scratch.vertex_stamp[v as usize] = stamp + 1;
                row(position(view.positions, v), DVec3::ZERO, 0, 0);
            }
        }
    }
    count
}
