//! `meshpaint convert`: `pack` over a library. Inputs are files, directories (searched
//! recursively for the formats the importer reads) and list files; each asset is opened
//! with the same rule flags as `pack` and written as a packed file under `--out`, at its
//! path relative to the directory it was found in (a named file: its relative path as
//! given, or its file name when absolute or climbing out with `..`), extension `.mpk`.
//!
//! - **Resumable**: an output that exists and is not older than its input is skipped.
//! - **Sharded**: `--shard I/N` takes every N-th asset from the I-th (assets sorted by path),
//!   so N jobs of any queue (Slurm arrays, Kubernetes indexed jobs, GNU parallel) split a
//!   library with no coordination.
//! - **Reported**: one JSON line per asset on stdout; a failed asset gets an `error` field and
//!   does not stop the others, and the exit status is non-zero when any failed. A progress
//!   bar ([`super::progress_bar`]) shows on stderr when it is a terminal.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::packing::file as packed_file;

use meshpaint_core::progress::Reporter;

use super::args::{ResolutionArg, budget, open_with, packed_format, parse_format};
use super::progress_bar::ProgressBar;

/// Extensions a directory is searched for (lower case).
const MESH_EXTENSIONS: [&str; 5] = ["glb", "gltf", "obj", "ply", "stl"];

/// Arguments of `meshpaint convert`.
#[derive(Debug, clap::Args)]
pub(super) struct ConvertArgs {
    /// Files (any format `pack` reads) and directories (searched recursively for .glb,
    /// .gltf, .obj, .ply and .stl).
    inputs: Vec<PathBuf>,
    /// A file listing inputs, one path per line (blank lines and lines starting with # are
    /// skipped; `-` reads standard input). May be repeated.
    #[arg(long, value_name = "FILE")]
    list: Vec<PathBuf>,
    /// Output directory: one packed file per asset, mirroring the inputs' relative paths.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Colour format: rgba8 (sRGB, default), rgba16f or rgba32f.
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    /// Convert only shard I of N (0 ≤ I < N): the assets at positions I, I + N, I + 2N, …
    /// of the list sorted by path.
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    shard: Option<(usize, usize)>,
    /// Convert even when the output exists and is newer than its input.
    #[arg(long)]
    force: bool,
}

fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let usage = || format!("--shard takes I/N with 0 ≤ I < N, got '{text}'");
    let (i, n) = text.split_once('/').ok_or_else(usage)?;
    let (i, n): (usize, usize) = (i.trim().parse().map_err(|_| usage())?, n.trim().parse().map_err(|_| usage())?);
    if n == 0 || i >= n {
        return Err(usage());
    }
    Ok((i, n))
}

/// One asset: its input and the output path relative to `--out`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Asset {
    input: PathBuf,
    relative: PathBuf,
}

pub(super) fn run(args: ConvertArgs) -> Result<()> {
    let assets = collect(&args.inputs, &args.list)?;
    anyhow::ensure!(!assets.is_empty(), "no assets to convert: name files, directories or --list files");
    let total_found = assets.len();
    let (index, count) = args.shard.unwrap_or((0, 1));
    let assets: Vec<Asset> = assets.into_iter().skip(index).step_by(count).collect();
    let bar = ProgressBar::new();
    let mut outputs: BTreeMap<PathBuf, PathBuf> = BTreeMap::new();
    let mut failed = 0usize;
    for (k, asset) in assets.iter().enumerate() {
        let output = args.out.join(&asset.relative);
        let at = |f: f32| (k as f32 + f) / assets.len() as f32;
        let name = asset.input.file_name().unwrap_or(asset.input.as_os_str()).to_string_lossy();
        let label = |stage: &str| format!("{}/{} {name}: {stage}", k + 1, assets.len());
        bar.set(at(0.0), &label("checking"));
        let started = Instant::now();
        let result = match outputs.insert(output.clone(), asset.input.clone()) {
            Some(first) => {
                Err(anyhow::anyhow!("its output {} is also the output of {}", output.display(), first.display()))
            }
            None => convert_one(&args, asset, &output, &|stage, f| bar.set(at(f), &label(stage))),
        };
        let mut line = serde_json::json!({
            "path": asset.input.display().to_string(),
            "output": output.display().to_string(),
        });
        match result {
            Ok(Outcome::UpToDate) => {
                line["status"] = "up to date".into();
            }
            Ok(Outcome::Converted(report)) => {
                line["status"] = "converted".into();
                line["rule"] = report.rule.into();
                line["faces"] = report.faces.into();
                line["samples"] = report.samples.into();
                line["samples_with_mips"] = report.samples_with_mips.into();
                line["bytes"] = report.bytes.into();
                // Against the texture over the textured surface (null without a texture or
                // when lossless: JSON has no infinity).
                line["psnr_db"] = report.texture_psnr_db.filter(|db| db.is_finite()).into();
                line["faces_held_by_budget"] = report.faces_held_by_budget.into();
            }
            Err(error) => {
                failed += 1;
                line["status"] = "failed".into();
                line["error"] = format!("{error:#}").into();
            }
        }
        line["seconds"] = started.elapsed().as_secs_f64().into();
        bar.println(&format!("{}: {}", asset.input.display(), line["status"].as_str().unwrap_or_default()));
        println!("{line}");
    }
    bar.finish();
    let shard = args.shard.map(|(i, n)| format!(" (shard {i}/{n} of {total_found})")).unwrap_or_default();
    anyhow::ensure!(failed == 0, "{failed} of {} assets failed{shard}", assets.len());
    Ok(())
}

/// What converting one asset did.
enum Outcome {
    UpToDate,
    Converted(Report),
}

struct Report {
    rule: String,
    faces: usize,
    samples: u64,
    samples_with_mips: u64,
    bytes: u64,
    texture_psnr_db: Option<f64>,
    faces_held_by_budget: u64,
}

fn convert_one(
    args: &ConvertArgs,
    asset: &Asset,
    output: &Path,
    progress: &(dyn Fn(&str, f32) + Sync),
) -> Result<Outcome> {
    if !args.force && up_to_date(&asset.input, output)? {
        return Ok(Outcome::UpToDate);
    }
    progress("opening", 0.05);
    let input = asset.input.clone();
    let resolution = args.resolution;
    let format = args.format;
    // The importers contain the panics they know of; any other stays within this asset.
    let opened = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || -> Result<_> {
        let reporter = Reporter::new(|fraction, stage: &str| progress(stage, 0.05 + 0.85 * fraction));
        let document = open_with(&input, resolution, &budget(format), reporter.progress())?;
        let format = packed_format(format, document.source);
        let packed = document.pack(format).with_context(|| format!("packing {}", input.display()))?;
        Ok((document.store.sample_count(), packed, document.conversion))
    }));
    let (samples, packed, conversion) = match opened {
        Ok(result) => result?,
        Err(panic) => anyhow::bail!("the conversion panicked: {}", panic_text(&panic)),
    };
    progress("writing", 0.9);
    if let Some(parent) = output.parent() {
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
    }
    packed_file::write_file(output, &packed)?;
    let bytes = std::fs::metadata(output).map(|m| m.len()).unwrap_or(0);
    progress("written", 1.0);
    Ok(Outcome::Converted(Report {
        rule: args.resolution.rule()?.describe(),
        faces: packed.face_records.len(),
        samples,
        samples_with_mips: packed.sample_count(),
        bytes,
        texture_psnr_db: conversion.as_ref().and_then(|c| c.texture_psnr_db),
        faces_held_by_budget: conversion.map_or(0, |c| c.faces_held_by_budget),
    }))
}

fn panic_text(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".to_owned())
}

/// Whether `output` exists and was modified no earlier than `input`.
fn up_to_date(input: &Path, output: &Path) -> Result<bool> {
    let Ok(out) = std::fs::metadata(output) else { return Ok(false) };
    let input_time =
        std::fs::metadata(input).and_then(|m| m.modified()).with_context(|| input.display().to_string())?;
    Ok(out.modified().is_ok_and(|t| t >= input_time))
}

/// Every asset of the inputs and list files, sorted by input path, each once.
fn collect(inputs: &[PathBuf], lists: &[PathBuf]) -> Result<Vec<Asset>> {
    let mut named: Vec<PathBuf> = inputs.to_vec();
    for list in lists {
        let text = if list.as_os_str() == "-" {
            std::io::read_to_string(std::io::stdin()).context("reading the list from standard input")?
        } else {
            std::fs::read_to_string(list).with_context(|| format!("reading the list {}", list.display()))?
        };
        named.extend(
            text.lines().map(str::trim).filter(|line| !line.is_empty() && !line.starts_with('#')).map(PathBuf::from),
        );
    }
    let mut assets = Vec::new();
    for path in named {
        if path.is_dir() {
            let mut found = Vec::new();
            walk(&path, &mut found).with_context(|| format!("searching {}", path.display()))?;
            for file in found {
                let relative = file.strip_prefix(&path).unwrap_or(&file).with_extension("mpk");
                assets.push(Asset { input: file, relative });
            }
        } else {
            let relative = relative_of_named(&path).with_extension("mpk");
            assets.push(Asset { input: path, relative });
        }
    }
    assets.sort();
    assets.dedup_by(|a, b| a.input == b.input);
    Ok(assets)
}

/// The output path of a file named on the command line or in a list (module docs).
fn relative_of_named(path: &Path) -> PathBuf {
    let climbs =
        path.components().any(|c| matches!(c, Component::ParentDir | Component::RootDir | Component::Prefix(_)));
    if climbs {
        return PathBuf::from(path.file_name().unwrap_or(path.as_os_str()));
    }
    path.components().filter(|c| matches!(c, Component::Normal(_))).collect()
}

/// Appends the mesh files under `dir` (recursively; symbolic links to directories are not
/// followed, so a link cycle cannot loop).
fn walk(dir: &Path, found: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        let kind = entry.file_type()?;
        if kind.is_dir() {
            walk(&path, found)?;
        } else if path.is_file() {
            let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            if extension.is_some_and(|e| MESH_EXTENSIONS.contains(&e.as_str())) {
                found.push(path);
            }
        }
    }
    Ok(())
}
