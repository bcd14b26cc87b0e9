//! Large faces carrying fine detail: a box truck. The box's two sides are one quad (two
//! triangles) each and take 86 % of the texture: an off-white panel with a logo (a navy
//! disc, a white ring, orange and white stripes; sharp, anti-aliased edges) and three
//! lines of text down to ~6 texels per font pixel. The box's other faces are single quads
//! with a smooth texture; the cab, chassis and six wheels (one mesh placed six times) are
//! many small faces with a smooth, low-detail texture in the remaining strip.
//!
//! Faces 0–1 are the +z side, 2–3 the −z side (the importer keeps the file's order: the
//! body comes first). Y is up, the truck faces +x, units are metres.

use glam::{DVec3, Mat4, Vec3};

use super::builder::MeshBuilder;
use super::canvas::{Srgb, fractal_noise, mix, paint, scale, supersample};
use super::font::Text;
use super::{Asset, Region};
use crate::mesh::scene::{Instance, Material, Scene};

/// The texture height of one box side, as a fraction of the texture (the side's aspect).
const PANEL_V: f32 = 0.43;
/// The box: x from −3.5 to 2.5, y from 1.0 to 3.6, z from −1.25 to 1.25.
const BOX_MIN: DVec3 = DVec3::new(-3.5, 1.0, -1.25);
const BOX_MAX: DVec3 = DVec3::new(2.5, 3.6, 1.25);

/// Strip cells (v from 2·PANEL_V to 1): eight columns.
fn cell(k: u32) -> [f32; 4] {
    let v0 = 2.0 * PANEL_V + 0.005;
    [k as f32 / 8.0 + 0.002, v0, (k + 1) as f32 / 8.0 - 0.002, 0.998]
}

/// Sub-rectangle `(i, j)` of a 3 × 2 split of `rect` (cuboid faces).
fn sub(rect: [f32; 4], k: usize) -> [f32; 4] {
    let (i, j) = ((k % 3) as f32, (k / 3) as f32);
    let (w, h) = ((rect[2] - rect[0]) / 3.0, (rect[3] - rect[1]) / 2.0);
    // v runs from the face's bottom (t = 0) to its top: image rows grow downwards.
    [rect[0] + i * w + 0.002, rect[1] + (j + 1.0) * h - 0.002, rect[0] + (i + 1.0) * w - 0.002, rect[1] + j * h + 0.002]
}

/// The truck with about `triangles` triangles (at least ~500) and a `size`² texture.
pub fn truck(triangles: u32, size: u32) -> Asset {
    let t = f64::from(triangles.max(500));
    let segments = ((0.3 * t / 36.0).round() as u32).max(8);
    let cab_n = ((0.5 * t / 12.0).sqrt().round() as u32).max(2);
    let chassis_n = ((0.2 * t / 12.0).sqrt().round() as u32).max(1);
    let mut body = MeshBuilder::new("body");
    let (lo, hi) = (BOX_MIN, BOX_MAX);
    let d = hi - lo;
    let material = Some(0);
    // The sides, first: +z (faces 0, 1), then −z (faces 2, 3); the panel's top row is v = 0.
    body.quad(
        DVec3::new(lo.x, lo.y, hi.z),
        DVec3::X * d.x,
        DVec3::Y * d.y,
        (1, 1),
        [0.0, PANEL_V, 1.0, 0.0],
        material,
        None,
    );
    body.quad(
        DVec3::new(hi.x, lo.y, lo.z),
        DVec3::NEG_X * d.x,
        DVec3::Y * d.y,
        (1, 1),
        [0.0, 2.0 * PANEL_V, 1.0, PANEL_V],
        material,
        None,
    );
    // Top, bottom, front, back: one quad each, smooth texture.
    body.quad(DVec3::new(lo.x, hi.y, hi.z), DVec3::X * d.x, DVec3::NEG_Z * d.z, (1, 1), cell(0), material, None);
    body.quad(DVec3::new(lo.x, lo.y, lo.z), DVec3::X * d.x, DVec3::Z * d.z, (1, 1), cell(1), material, None);
    body.quad(DVec3::new(hi.x, lo.y, hi.z), DVec3::NEG_Z * d.z, DVec3::Y * d.y, (1, 1), cell(2), material, None);
    body.quad(DVec3::new(lo.x, lo.y, lo.z), DVec3::Z * d.z, DVec3::Y * d.y, (1, 1), cell(3), material, None);
    // Cab and chassis: many small faces.
    let cab = [cell(4)[0], cell(4)[1], cell(5)[2], cell(5)[3]];
    body.cuboid(DVec3::new(2.7, 0.9, -1.2), DVec3::new(4.5, 3.2, 1.2), cab_n, material, |k| sub(cab, k));
    body.cuboid(DVec3::new(-3.6, 0.55, -0.9), DVec3::new(4.4, 0.95, 0.9), chassis_n, material, |k| sub(cell(6), k));
    let wheel_cell = cell(7);
    let mid = (wheel_cell[0] + wheel_cell[2]) / 2.0;
    let mut wheel = MeshBuilder::new("wheel");
    wheel.cylinder(
        (DVec3::new(0.0, 0.0, -0.16), DVec3::new(0.0, 0.0, 0.16)),
        0.5,
        (segments, 2),
        [wheel_cell[0], wheel_cell[3], mid - 0.002, wheel_cell[1]],
        [mid + 0.002, wheel_cell[1], wheel_cell[2], wheel_cell[1] + (wheel_cell[2] - mid - 0.002)],
        material,
        &|_| None,
    );
    let wheels = [(-2.6, 1.05), (-1.5, 1.05), (3.6, 1.05)];
    let mut instances = vec![Instance { mesh: 0, world_from_local: Mat4::IDENTITY }];
    for (x, z) in wheels {
        for side in [1.0, -1.0] {
            let at = Vec3::new(x, 0.5, side * z);
            instances.push(Instance { mesh: 1, world_from_local: Mat4::from_translation(at) });
        }
    }
    let s = f64::from(size);
    let lines = text_lines(s, f64::from(PANEL_V) * s);
    let texture = paint(size, size, |x, y| texel(x / s, y / s, s, &lines));
    let scene = Scene {
        meshes: vec![body.finish(), wheel.finish()],
        instances,
        materials: vec![Material { base_color_factor: [1.0; 4], base_color_texture: Some(0) }],
        textures: vec![texture],
        warnings: Vec::new(),
    };
    Asset { scene, regions: regions() }
}

/// Panel layout, in panel units (x ∈ [0, 1] along the side, y ∈ [0, 1] top to bottom).
const LOGO_CENTRE: [f64; 2] = [0.16, 0.42];
/// The logo's radius as a fraction of the panel height.
const LOGO_RADIUS: f64 = 0.3;
/// The text block: x from 0.34 to 0.97, y from 0.10 to 0.72.
const TEXT_BOX: [f64; 4] = [0.34, 0.10, 0.97, 0.72];

/// The colour at `(u, v)` of the texture (`size` texels wide).
fn texel(u: f64, v: f64, size: f64, lines: &[Text; 3]) -> Srgb {
    let panel_v = f64::from(PANEL_V);
    if v < 2.0 * panel_v {
        // Both sides carry the same panel; texel units keep the text's scale in texels.
        let (w, h) = (size, panel_v * size);
        let (x, y) = (u * size, (v % panel_v) * size);
        return supersample(x, y, 4, |x, y| panel(x / w, y / h, h, lines));
    }
    smooth(u, v, size)
}

fn text_lines(w: f64, h: f64) -> [Text; 3] {
    let [x0, y0, x1, _] = TEXT_BOX;
    let width = (x1 - x0) * w;
    [
        Text::fit("MESHPAINT", [x0 * w, y0 * h], width, 0.30 * h),
        Text::fit("COLOUR LOGISTICS", [x0 * w, 0.46 * h], width, 0.14 * h),
        Text::fit("WWW.MESHPAINT.EXAMPLE - 0800 555 0142", [x0 * w, 0.66 * h], width, 0.06 * h),
    ]
}

/// The panel at `(px, py)` (panel units), `h` texels high.
fn panel(px: f64, py: f64, h: f64, lines: &[Text; 3]) -> Srgb {
    const NAVY: Srgb = [0.06, 0.12, 0.35];
    const WHITE: Srgb = [0.96, 0.96, 0.94];
    const ORANGE: Srgb = [0.98, 0.55, 0.08];
    const RED: Srgb = [0.75, 0.08, 0.07];
    let background = mix([0.92, 0.92, 0.89], [0.86, 0.87, 0.85], py as f32);
    let aspect = f64::from(1.0 / PANEL_V);
    // The logo, in units of the panel height.
    let (dx, dy) = ((px - LOGO_CENTRE[0]) * aspect, py - LOGO_CENTRE[1]);
    let r = (dx * dx + dy * dy).sqrt() / LOGO_RADIUS;
    if r < 1.0 {
        if r > 0.78 && r < 0.86 {
            return WHITE;
        }
        if r < 0.72 {
            let band = ((dy / LOGO_RADIUS + 0.72) / (1.44 / 7.0)).floor() as i64;
            let diagonal = (dx + dy) / LOGO_RADIUS;
            return if diagonal > 0.35 && diagonal < 0.5 {
                NAVY
            } else if band % 2 == 0 {
                ORANGE
            } else {
                WHITE
            };
        }
        return NAVY;
    }
    let (x, y) = (px * aspect * h, py * h);
    if lines[0].covers(x, y) {
        return NAVY;
    }
    if lines[1].covers(x, y) {
        return RED;
    }
    if lines[2].covers(x, y) {
        return [0.1, 0.1, 0.1];
    }
    if (0.80..0.90).contains(&py) {
        return RED;
    }
    if (0.915..0.93).contains(&py) {
        return NAVY;
    }
    background
}

/// The strip of small parts: a base colour per column with smooth, low-frequency variation.
fn smooth(u: f64, v: f64, size: f64) -> Srgb {
    let column = (u * 8.0).floor().clamp(0.0, 7.0) as usize;
    let base: Srgb = match column {
        0 | 1 => [0.80, 0.80, 0.78],
        2 | 3 => [0.85, 0.84, 0.80],
        4 | 5 => [0.70, 0.12, 0.10],
        6 => [0.18, 0.18, 0.20],
        _ => [0.12, 0.12, 0.12],
    };
    let p = [u * size / 96.0, v * size / 96.0, column as f64 * 7.0];
    let n = fractal_noise(p, 3, 7) as f32;
    let mut colour = scale(base, 0.85 + 0.3 * n);
    if column == 7 && u * 8.0 - 7.0 > 0.5 {
        // The wheel cap: a lighter hub with a soft edge.
        let rect = cell(7);
        let mid = (rect[0] + rect[2]) / 2.0;
        let radius = (rect[2] - mid - 0.002) / 2.0;
        let (cx, cy) = (f64::from(mid + 0.002 + radius), f64::from(rect[1] + radius));
        let r = ((u - cx).powi(2) + (v - cy).powi(2)).sqrt() / f64::from(radius);
        let hub = (1.0 - ((r - 0.45) / 0.15).clamp(0.0, 1.0)) as f32;
        colour = mix(colour, [0.6, 0.6, 0.62], hub);
    }
    colour
}

/// The +z side's logo and text, and both sides' panels (module docs).
fn regions() -> Vec<Region> {
    let d = BOX_MAX - BOX_MIN;
    let panel_v = f64::from(PANEL_V);
    // Panel units → world on the +z side (x along the box, y up) and → UV.
    let region = |name: &str, faces: Vec<u32>, rect: [f64; 4], normal: [f32; 3]| {
        let [x0, y0, x1, y1] = rect;
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let centre =
            DVec3::new(BOX_MIN.x + cx * d.x, BOX_MAX.y - cy * d.y, if normal[2] > 0.0 { BOX_MAX.z } else { BOX_MIN.z });
        let centre = if normal[2] > 0.0 { centre } else { DVec3::new(BOX_MAX.x - cx * d.x, centre.y, centre.z) };
        Region {
            name: name.to_owned(),
            faces,
            uv_rect: [x0 as f32, (y0 * panel_v) as f32, x1 as f32, (y1 * panel_v) as f32],
            center: centre.as_vec3().to_array(),
            normal,
            size: [((x1 - x0) * d.x) as f32, ((y1 - y0) * d.y) as f32],
        }
    };
    let logo_w = LOGO_RADIUS * panel_v;
    let logo =
        [LOGO_CENTRE[0] - logo_w, LOGO_CENTRE[1] - LOGO_RADIUS, LOGO_CENTRE[0] + logo_w, LOGO_CENTRE[1] + LOGO_RADIUS];
    let mut minus_z = region("panel -z", vec![2, 3], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, -1.0]);
    minus_z.uv_rect = [0.0, PANEL_V, 1.0, 2.0 * PANEL_V];
    vec![
        region("logo", vec![0, 1], logo, [0.0, 0.0, 1.0]),
        region("text", vec![0, 1], TEXT_BOX, [0.0, 0.0, 1.0]),
        region("panel +z", vec![0, 1], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 1.0]),
        minus_z,
    ]
}
