//! The plots of `bench trade`: error against a cost (GPU bytes, frame time), one point per
//! configuration of either representation (colour = filter, shape = representation, fill =
//! colour format), the Pareto front drawn through the points no other beats on both axes,
//! whichever representation they belong to.
//!
//! Drawn with `plotters` into PNGs (bitmap backend, no system libraries): text uses the
//! Ubuntu Light font egui already ships (`epaint_default_fonts`), registered with plotters'
//! `ab_glyph` renderer, so no fontconfig or freetype is needed.

use std::path::Path;

use plotters::prelude::*;

/// One configuration on a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotPoint {
    /// The cost (x).
    pub cost: f64,
    /// The quality (y, higher is better): PSNR in dB.
    pub quality: f64,
    /// Colour group (the filter).
    pub filter: String,
    /// Fill of the marker (the colour format: rgba8 filled, rgba16f hollow, rgba32f hollow
    /// with a dot).
    pub format: String,
    /// Shape of the marker (`mesh-colors`: circle, `mct`: square, `ptex`: triangle).
    pub representation: String,
    /// Short name written next to Pareto points.
    pub label: String,
}

/// Errors of drawing a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The font could not be registered.
    #[error("registering the plot font failed")]
    Font,
    /// Drawing or encoding failed.
    #[error("drawing {path}: {reason}")]
    Draw {
        /// The PNG being written.
        path: String,
        /// What plotters said.
        reason: String,
    },
    /// Nothing to plot.
    #[error("no finite points to plot")]
    Empty,
}

const FONT: &str = "sans-serif";

fn register_font() -> Result<(), PlotError> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// `x` bytes as B, KiB, MiB or GiB with about three significant digits.
fn human_bytes(x: f64) -> String {
    let units = ["B", "KiB", "MiB", "GiB"];
    let mut value = x;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < units.len() {
        value /= 1024.0;
        unit += 1;
    }
    let digits = if value >= 100.0 {
        0
    } else if value >= 10.0 {
        1
    } else {
        2
    };
    format!("{value:.digits$} {}", units[unit])
}

/// Colour of a filter's points.
fn filter_color(filter: &str) -> RGBColor {
    match filter {
        "nearest" => RGBColor(214, 39, 40),
        "linear" => RGBColor(31, 119, 180),
        "mip-1" => RGBColor(44, 160, 44),
        "mip-2" => RGBColor(148, 103, 189),
        "trilinear" => RGBColor(255, 127, 14),
        _ => RGBColor(60, 60, 60),
    }
}

/// Writes a PNG of `points` (`x_label` on a log axis when `log_x`) with the Pareto front
/// (least cost, most quality) as a black line and labelled points; `reference`, if given, is
/// drawn as a black star (the UV-texture baseline).
/// Long: one plotters chart (axes, front, points, labels, legend) whose builder calls
/// share the drawing area and coordinate system; split, each part would take them all.
pub fn plot_tradeoff(
    path: &Path,
    title: &str,
    x_label: &str,
    log_x: bool,
    points: &[PlotPoint],
    reference: Option<(f64, f64, &str)>,
) -> Result<(), PlotError> {
    register_font()?;
    let finite: Vec<&PlotPoint> =
        points.iter().filter(|p| p.cost.is_finite() && p.quality.is_finite() && p.cost > 0.0).collect();
    if finite.is_empty() {
        return Err(PlotError::Empty);
    }
    let draw_error = |reason: String| PlotError::Draw { path: path.display().to_string(), reason };
    let mut xs: Vec<f64> = finite.iter().map(|p| p.cost).collect();
    let mut ys: Vec<f64> = finite.iter().map(|p| p.quality).collect();
    if let Some((x, y, _)) = reference
        && x.is_finite()
        && y.is_finite()
        && x > 0.0
    {
        xs.push(x);
        ys.push(y);
    }
    let (x_min, x_max) = (xs.iter().copied().fold(f64::INFINITY, f64::min), xs.iter().copied().fold(0.0, f64::max));
    let (y_min, y_max) =
        (ys.iter().copied().fold(f64::INFINITY, f64::min), ys.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    let (y_lo, y_hi) = ((y_min - 1.0).floor(), (y_max + 1.0).ceil());

    let root = BitMapBackend::new(path, (1280, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| draw_error(e.to_string()))?;
    let front_points: Vec<(f64, f64)> = finite.iter().map(|p| (p.cost, p.quality)).collect();
    let front = pareto_front(&front_points);
    // One label per front position: exact duplicates (e.g. every filter of R = 1, which has
    // one level) are named once, with how many more share the point.
    let mut front_labels: Vec<(&PlotPoint, String)> = Vec::new();
    for &i in &front {
        let p = finite[i];
        let same = front.iter().filter(|&&j| finite[j].cost == p.cost && finite[j].quality == p.quality).count();
        if !front_labels.iter().any(|(q, _)| q.cost == p.cost && q.quality == p.quality) {
            let label = if same > 1 { format!("{} (+{} more)", p.label, same - 1) } else { p.label.clone() };
            front_labels.push((p, label));
        }
    }

    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_label_formatter(&|x: &f64| if log_x { human_bytes(*x) } else { format!("{x:.2}") })
                .x_labels(12)
                .x_desc(x_label)
                .y_desc("PSNR against the reference, dB (mean over views)")
                .label_style((FONT, 18))
                .axis_desc_style((FONT, 20))
                .draw()
                .map_err(|e| draw_error(e.to_string()))?;
            for filter in ["nearest", "linear", "mip-1", "mip-2", "trilinear"] {
                let color = filter_color(filter);
                // Filled rgba8, hollow rgba16f, hollow with a dot rgba32f.
                let style =
                    |p: &PlotPoint| if p.format == "rgba8" { color.mix(0.85).filled() } else { color.stroke_width(2) };
                let dot =
                    |p: &PlotPoint| Circle::new((0, 0), if p.format == "rgba32f" { 2 } else { 0 }, color.filled());
                let mut labelled = false;
                for representation in ["mesh-colors", "mct", "ptex"] {
                    let group: Vec<&PlotPoint> = finite
                        .iter()
                        .copied()
                        .filter(|p| p.filter == filter && p.representation == representation)
                        .collect();
                    if group.is_empty() {
                        continue;
                    }
                    let at = |p: &PlotPoint| EmptyElement::at((p.cost, p.quality));
                    let drawn = if representation == "mct" {
                        chart.draw_series(
                            group.iter().map(|p| at(p) + Rectangle::new([(-5, -5), (5, 5)], style(p)) + dot(p)),
                        )
                    } else if representation == "ptex" {
                        chart.draw_series(
                            group.iter().map(|p| at(p) + TriangleMarker::new((0, 0), 7, style(p)) + dot(p)),
                        )
                    } else {
                        chart.draw_series(group.iter().map(|p| at(p) + Circle::new((0, 0), 5, style(p)) + dot(p)))
                    }
                    .map_err(|e| draw_error(e.to_string()))?;
                    if !labelled {
                        drawn.label(filter).legend(move |(x, y)| Circle::new((x, y), 5, color.filled()));
                        labelled = true;
                    }
                }
            }
            if finite.iter().any(|p| p.representation == "mesh-colors") {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(|e| draw_error(e.to_string()))?
                    .label("mesh colors (software filter)")
                    .legend(|(x, y)| Circle::new((x, y), 5, BLACK.filled()));
            }
            if finite.iter().any(|p| p.representation == "mct") {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(|e| draw_error(e.to_string()))?
                    .label("Mesh Color Texture (hardware filter)")
                    .legend(|(x, y)| Rectangle::new([(x - 5, y - 5), (x + 5, y + 5)], BLACK.filled()));
            }
            if finite.iter().any(|p| p.representation == "ptex") {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(|e| draw_error(e.to_string()))?
                    .label("packed Ptex (hardware filter)")
                    .legend(|(x, y)| TriangleMarker::new((x, y), 7, BLACK.filled()));
            }
            let line: Vec<(f64, f64)> = front.iter().map(|&i| (finite[i].cost, finite[i].quality)).collect();
            chart
                .draw_series(LineSeries::new(line.clone(), BLACK.stroke_width(2)))
                .map_err(|e| draw_error(e.to_string()))?
                .label("Pareto front")
                .legend(|(x, y)| PathElement::new(vec![(x - 10, y), (x + 10, y)], BLACK.stroke_width(2)));
            chart
                .draw_series(front_labels.iter().enumerate().map(|(k, (p, label))| {
                    // Labels alternate above and below the point: neighbours on the front
                    // are often close.
                    let dy = if k % 2 == 0 { -20 } else { 6 };
                    EmptyElement::at((p.cost, p.quality))
                        + Circle::new((0, 0), 8, BLACK.stroke_width(1))
                        + Text::new(label.clone(), (10, dy), (FONT, 15).into_font())
                }))
                .map_err(|e| draw_error(e.to_string()))?;
            if let Some((x, y, name)) = reference
                && x.is_finite()
                && y.is_finite()
                && x > 0.0
            {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((x, y))
                            + Rectangle::new([(-6, -6), (6, 6)], BLACK.filled())
                            + Text::new(name.to_owned(), (10, 4), (FONT, 16).into_font()),
                    ))
                    .map_err(|e| draw_error(e.to_string()))?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .label_font((FONT, 18))
                .background_style(WHITE.mix(0.85))
                .border_style(&BLACK)
                .draw()
                .map_err(|e| draw_error(e.to_string()))?;
        }};
    }
    let mut builder = ChartBuilder::on(&root);
    builder.caption(title, (FONT, 26)).margin(20).margin_bottom(40).x_label_area_size(60).y_label_area_size(70);
    if log_x {
        // At least a decade, so that the axis has labelled ticks.
        let lo = (x_min / 1.5).min(10f64.powf(x_min.log10().floor()));
        let hi = (x_max * 1.5).max(10f64.powf(x_max.log10().ceil()));
        draw!(builder.build_cartesian_2d((lo..hi).log_scale(), y_lo..y_hi).map_err(|e| draw_error(e.to_string()))?);
    } else {
        let pad = (x_max - x_min).max(1e-3) * 0.08;
        draw!(
            builder
                .build_cartesian_2d((x_min - pad)..(x_max + pad), y_lo..y_hi)
                .map_err(|e| draw_error(e.to_string()))?
        );
    }
    root.draw(&Text::new(
        "colour: filter · circle: mesh colors, square: MCT, triangle: packed Ptex · filled rgba8, hollow rgba16f, \
         hollow with a dot rgba32f · labelled: the Pareto front of all",
        (90, 872),
        (FONT, 17).into_font(),
    ))
    .map_err(|e| draw_error(e.to_string()))?;
    root.present().map_err(|e| draw_error(e.to_string()))?;
    Ok(())
}

/// Indices of the points of `points` (`(cost, quality)`) on the Pareto front: no other point
/// costs at most as much with at least the quality, one of the two strictly. Sorted by cost.
/// Points with a NaN coordinate are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan()).collect();
    // Cheapest first; among equal costs the best quality first.
    order.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0).then(points[b].1.total_cmp(&points[a].1)));
    let mut front = Vec::new();
    let mut best = f64::NEG_INFINITY;
    let mut last_cost = f64::NAN;
    for i in order {
        let (cost, quality) = points[i];
        if quality > best {
            front.push(i);
            best = quality;
            last_cost = cost;
        } else if quality == best && cost == last_cost {
            // An exact duplicate of a front point is not dominated either.
            front.push(i);
        }
    }
    front
}
