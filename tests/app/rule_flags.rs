//! Every resolution-rule flag (`--texel-density`, `--samples N`, `--error E`) through every
//! command that takes it (`info`, `pack`, `export`, `render`): the sample count each command
//! reports or writes equals the count of the library's own conversion with that rule
//! (`Document::open_within`), so no command silently falls back to a uniform R (as `render`
//! once did).

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common;
use common::{TempDir, model};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::file as packed_file;

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

/// Runs `meshpaint args` and returns (stdout, stderr); panics with both if it failed.
fn run(args: &[&str]) -> (String, String) {
    let output = Command::new(BIN).args(args).output().expect("cannot start the meshpaint binary");
    let (stdout, stderr) =
        (String::from_utf8_lossy(&output.stdout).into_owned(), String::from_utf8_lossy(&output.stderr).into_owned());
    assert!(output.status.success(), "meshpaint {}\nstdout: {stdout}\nstderr: {stderr}", args.join(" "));
    (stdout, stderr)
}

/// The number before " samples" in a command's one-line report.
fn reported_samples(line: &str) -> u64 {
    let before = line.split(" samples").next().unwrap_or_default();
    let number = before.rsplit([' ', ',']).find(|word| !word.is_empty()).unwrap_or_default();
    number.parse().unwrap_or_else(|_| panic!("no sample count in {line:?}"))
}

/// Level-0 samples and samples with MIP chains of the library's conversion of `file`.
fn library_counts(file: &Path, rule: ResolutionRule) -> (u64, u64) {
    let document = Document::open_within(file, rule, &Budget::from_environment()).unwrap();
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    (document.store.sample_count(), packed.sample_count())
}

#[test]
fn every_rule_flag_gives_the_library_rules_sample_count_in_every_command() {
    // A small textured model keeps this test fast; the rules' quality is tested in adaptive.rs.
    let file = model("BoxTextured/BoxTextured.glb");
    let file_arg = file.to_str().unwrap();
    // The commands' default largest R: the layout's (each face stops at its content cap).
    let max = Resolution::MAX;
    let dir = TempDir::new("rule-flags");
    let uniform = library_counts(&file, ResolutionRule::Uniform(Resolution::new(8).unwrap()));
    let cases: [(&[&str], ResolutionRule); 3] = [
        (&["--texel-density"], ResolutionRule::TexelDensity { max }),
        (&["--samples", "2000"], ResolutionRule::Budget { samples: 2000, max }),
        (&["--error", "0.1"], ResolutionRule::ErrorBound { bound: 0.1, max }),
    ];
    for (flags, rule) in cases {
        let (samples, with_mips) = library_counts(&file, rule);
        assert_ne!((samples, with_mips), uniform, "{flags:?}: the rule must differ from uniform R = 8 here");
        let what = flags.join(" ");

        let mut args = vec!["info", file_arg, "--json"];
        args.extend_from_slice(flags);
        let info: Value = serde_json::from_str(run(&args).0.trim()).unwrap();
        assert_eq!(info["samples"].as_u64(), Some(samples), "info {what}: {info}");
        assert_eq!(info["samples_with_mips"].as_u64(), Some(with_mips), "info {what}: {info}");

        let packed = dir.join("pack.mpk");
        let mut args = vec!["pack", file_arg, "-o", packed.to_str().unwrap()];
        args.extend_from_slice(flags);
        let (_, stderr) = run(&args);
        assert_eq!(packed_file::read_file(&packed).unwrap().sample_count(), with_mips, "pack {what}");
        assert_eq!(reported_samples(&stderr), with_mips, "pack {what}: {stderr}");

        let exported = dir.join("export.mpk");
        let mut args = vec!["export", file_arg, "-o", exported.to_str().unwrap()];
        args.extend_from_slice(flags);
        run(&args);
        assert_eq!(packed_file::read_file(&exported).unwrap().sample_count(), with_mips, "export {what}");

        let image = dir.join("render.png");
        let mut args = vec!["render", file_arg, "-o", image.to_str().unwrap(), "--width", "64", "--height", "64"];
        args.extend_from_slice(flags);
        let (_, stderr) = run(&args);
        let line = stderr.lines().find(|line| line.contains(" samples")).unwrap_or_default();
        assert_eq!(reported_samples(line), with_mips, "render {what}: {stderr}");
    }
}
