//! The plots of `bench trade` from its rows: one point per configuration (representation,
//! resolution, format, filter), PSNR the mean over the views, against GPU bytes and against
//! the frame-time ratio; the Pareto front runs across both representations.

use std::path::{Path, PathBuf};

use crate::bench::plot::{PlotError, PlotPoint, plot_tradeoff};

/// (representation, resolution, format, filter) of a `config` row.
type Key = (String, String, String, String);

/// Per configuration (representation, resolution, format, filter): the means over the views
/// of PSNR and frame ratio, with GPU bytes — the points of the plots. Returns `(bytes points,
/// frame points, baseline (bytes, mean PSNR))`.
pub fn plot_points(rows: &[serde_json::Value]) -> (Vec<PlotPoint>, Vec<PlotPoint>, Option<(f64, f64)>) {
    let mut groups: Vec<(Key, f64, Vec<f64>, Vec<f64>)> = Vec::new();
    let (mut baseline_psnr, mut baseline_bytes) = (Vec::new(), f64::NAN);
    for row in rows {
        let text = |k: &str| match &row[k] {
            serde_json::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        let number = |k: &str| row[k].as_f64().unwrap_or(f64::NAN);
        match row["kind"].as_str() {
            Some("config") => {
                // Rows from before the representation axis are mesh colors.
                let representation = row["representation"].as_str().unwrap_or("mesh-colors").to_owned();
                let key = (representation, text("resolution"), text("format"), text("filter"));
                let index = match groups.iter().position(|g| g.0 == key) {
                    Some(index) => index,
                    None => {
                        groups.push((key, number("gpu_bytes"), Vec::new(), Vec::new()));
                        groups.len() - 1
                    }
                };
                groups[index].2.push(number("psnr_db"));
                groups[index].3.push(number("frame_ratio"));
            }
            Some("baseline") => {
                baseline_psnr.push(number("psnr_db"));
                baseline_bytes = number("gpu_bytes");
            }
            _ => {}
        }
    }
    let mut bytes = Vec::new();
    let mut frames = Vec::new();
    for (key, gpu_bytes, psnr, ratio) in &groups {
        let point = |cost: f64| PlotPoint {
            cost,
            quality: mean(psnr),
            filter: key.3.clone(),
            format: key.2.clone(),
            representation: key.0.clone(),
            label: short(key),
        };
        bytes.push(point(*gpu_bytes));
        frames.push(point(mean(ratio)));
    }
    let baseline = (!baseline_psnr.is_empty()).then(|| (baseline_bytes, mean(&baseline_psnr)));
    (bytes, frames, baseline)
}

/// The mean of the finite values (views where nothing was compared — the mesh smaller than a
/// pixel — have no PSNR); NaN when there is none.
fn mean(values: &[f64]) -> f64 {
    let finite: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if finite.is_empty() { f64::NAN } else { finite.iter().sum::<f64>() / finite.len() as f64 }
}

/// The label of a Pareto point: `R16 8 lin`, `MCT e0.01 16f tri`.
fn short((representation, resolution, format, filter): &Key) -> String {
    let r = match resolution.strip_prefix("error<=") {
        Some(bound) => format!("e{bound}"),
        None => format!("R{resolution}"),
    };
    let f = match format.as_str() {
        "rgba8" => "8",
        "rgba16f" => "16f",
        _ => "32f",
    };
    let filter = match filter.as_str() {
        "nearest" => "near",
        "linear" => "lin",
        "trilinear" => "tri",
        other => other,
    };
    let prefix = match representation.as_str() {
        "mct" => "MCT ",
        "htex" => "Htex ",
        "ptex" => "Ptex ",
        _ => "",
    };
    format!("{prefix}{r} {f} {filter}")
}

/// Writes `trade_<stem>_bytes.png` and `trade_<stem>_frame.png` into `dir` from `rows`;
/// returns their paths.
pub fn write_plots(rows: &[serde_json::Value], dir: &Path, stem: &str) -> Result<Vec<PathBuf>, PlotError> {
    let (bytes, frames, baseline) = plot_points(rows);
    let name = |what: &str| dir.join(format!("trade_{stem}_{what}.png"));
    let (bytes_path, frame_path) = (name("bytes"), name("frame"));
    plot_tradeoff(
        &bytes_path,
        &format!("{stem}: error vs GPU memory (mesh colors, MCT, packed Ptex, Htex × filter × resolution × format)"),
        "GPU bytes in total: geometry + colours (log scale)",
        true,
        &bytes,
        baseline.map(|(b, p)| (b, p, "UV texture")),
    )?;
    plot_tradeoff(
        &frame_path,
        &format!("{stem}: error vs frame time (ratio to the UV-texture baseline, interleaved)"),
        "frame time / UV-texture frame time (mean over views)",
        false,
        &frames,
        baseline.map(|(_, p)| (1.0, p, "UV texture")),
    )?;
    Ok(vec![bytes_path, frame_path])
}
