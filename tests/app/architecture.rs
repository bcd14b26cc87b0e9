//! The layout rules of the workspace, checked on the source tree itself:
//!
//! - the core crate depends on no GPU or UI crate (its dependency tree, `cargo tree`) and
//!   its sources never name one; the renderer names no UI crate;
//! - modules depend on each other without cycles, between the top-level folders of each
//!   crate and between the files of one folder (`crate::…` and `super::…` paths, grouped
//!   `use` trees such as `use super::{a, b}` included);
//! - no source file is longer than [`MAX_FILE_LINES`], no function (whatever its
//!   visibility: `pub(super) fn`, `pub(crate) unsafe fn` …) longer than [`MAX_FN_LINES`]
//!   unless its doc comment says why (a line starting `Long:`).
//!
//! The checks read the files as text (doc comments, comments and `#[cfg(test)]` modules
//! excluded). Each check is a function over sources, and the `planted_*` tests prove that
//! it fails on a planted violation.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::common::workspace_root;

const MAX_FILE_LINES: usize = 800;
const MAX_FN_LINES: usize = 100;

/// The crates: name, source folder, and the crates their sources must not name.
const CRATES: [(&str, &str, &[&str]); 3] = [
    (
        "core",
        "crates/core/src",
        &["wgpu", "egui", "egui_wgpu", "egui_winit", "winit", "plotters", "nv_flip", "meshpaint_render", "meshpaint"],
    ),
    ("render", "crates/render/src", &["egui", "egui_wgpu", "egui_winit", "winit", "plotters", "nv_flip", "meshpaint"]),
    ("app", "src", &[]),
];

/// Packages the core's dependency tree must not contain.
const NOT_IN_CORE_TREE: [&str; 7] = ["wgpu", "egui", "egui-wgpu", "egui-winit", "winit", "plotters", "nv-flip"];

/// One source file: its crate, its module path in the crate (`paint/brush/mod.rs` →
/// `["paint", "brush"]`), whether it is a `mod.rs` / crate root, and its code lines.
struct Source {
    krate: String,
    path: String,
    module: Vec<String>,
    is_folder_root: bool,
    code: Vec<String>,
    text: String,
}

impl Source {
    fn new(krate: &str, relative: &Path, text: String) -> Source {
        let mut module: Vec<String> =
            relative.with_extension("").iter().map(|p| p.to_string_lossy().into_owned()).collect();
        let name = relative.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let is_folder_root = matches!(name.as_str(), "mod.rs" | "lib.rs" | "main.rs");
        if is_folder_root {
            module.pop();
        }
        Source {
            krate: krate.to_owned(),
            path: format!("{krate}/{}", relative.display()),
            module,
            is_folder_root,
            code: code_lines(&text),
            text,
        }
    }
}

fn workspace_sources() -> Vec<Source> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let root = workspace_root();
    let mut sources = Vec::new();
    for (krate, folder, _) in CRATES {
        let src = root.join(folder);
        let mut files = Vec::new();
        walk(&src, &mut files);
        files.sort();
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            sources.push(Source::new(krate, file.strip_prefix(&src).unwrap(), text));
        }
    }
    sources
}

/// The code lines of a file: doc and line comments stripped, `#[cfg(test)]` modules cut.
fn code_lines(text: &str) -> Vec<String> {
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.trim_start() == "#[cfg(test)]" {
            break;
        }
        let code = match line.find("//") {
            Some(at) if !line[..at].contains('"') => &line[..at],
            _ => line,
        };
        lines.push(code.to_owned());
    }
    lines
}

/// The paths named after each `prefix` followed by `separator` in `code` (lines joined, so
/// a `use` tree may span lines), grouped trees expanded: `super::{a, b::{c, d}}` → `a`,
/// `b::c`, `b::d`. Whole paths, item names included, `self` dropped.
fn trees_after(code: &[String], prefix: &str, separator: &str) -> BTreeSet<Vec<String>> {
    let joined: Vec<char> = code.join("\n").chars().collect();
    let needle: Vec<char> = format!("{prefix}{separator}").chars().collect();
    let mut out = BTreeSet::new();
    let mut at = 0;
    while at + needle.len() <= joined.len() {
        let preceded_by_word = at > 0 && (joined[at - 1].is_ascii_alphanumeric() || joined[at - 1] == '_');
        if joined[at..at + needle.len()] == needle[..] && !preceded_by_word {
            let mut i = at + needle.len();
            for path in parse_tree(&joined, &mut i) {
                let path: Vec<String> = path.into_iter().filter(|p| p != "self").collect();
                if !path.is_empty() {
                    out.insert(path);
                }
            }
            at = i.max(at + 1);
        } else {
            at += 1;
        }
    }
    out
}

/// [`trees_after`] `prefix::`, each path cut to its leading lowercase segments (modules)
/// and the one name after them, if any.
fn paths_after(code: &[String], prefix: &str) -> BTreeSet<Vec<String>> {
    trees_after(code, prefix, "::")
        .into_iter()
        .map(|path| {
            let modules = path.iter().take_while(|p| p.chars().next().is_some_and(|c| c.is_ascii_lowercase())).count();
            path.into_iter().take(modules + 1).collect::<Vec<_>>()
        })
        .collect()
}

/// The leading module segments of a path (lowercase names).
fn modules_of(path: &[String]) -> &[String] {
    let n = path.iter().take_while(|p| p.chars().next().is_some_and(|c| c.is_ascii_lowercase())).count();
    &path[..n]
}

/// Names a folder root re-exports from its children (`pub use child::{Name, …}` in a
/// `mod.rs` or `lib.rs`), keyed by the module path they are reached at (`["render",
/// "Renderer"]`) and naming the child module that defines them (`["render", "renderer"]`):
/// `use super::Renderer` in a sibling depends on that file, not on the folder.
fn reexports(sources: &[Source]) -> BTreeMap<(String, Vec<String>), Vec<String>> {
    let mut out = BTreeMap::new();
    for source in sources.iter().filter(|s| s.is_folder_root) {
        for path in trees_after(&source.code, "pub use", " ") {
            let (Some(name), modules) = (path.last(), modules_of(&path)) else { continue };
            if modules.is_empty() || modules[0] == "crate" || modules[0] == "super" || modules.len() == path.len() {
                continue;
            }
            let key: Vec<String> = source.module.iter().chain([name]).cloned().collect();
            let target: Vec<String> = source.module.iter().chain(modules.iter()).cloned().collect();
            out.insert((source.krate.clone(), key), target);
        }
    }
    out
}

/// One `use` tree starting at `chars[*i]`: `a::b`, `a::{b, c::d}`, `{a, b}`.
fn parse_tree(chars: &[char], i: &mut usize) -> Vec<Vec<String>> {
    let skip_space = |i: &mut usize| {
        while chars.get(*i).is_some_and(|c| c.is_whitespace()) {
            *i += 1;
        }
    };
    skip_space(i);
    if chars.get(*i) == Some(&'{') {
        *i += 1;
        let mut out = Vec::new();
        loop {
            skip_space(i);
            match chars.get(*i) {
                None => break,
                Some('}') => {
                    *i += 1;
                    break;
                }
                Some(',') => *i += 1,
                Some(_) => {
                    let before = *i;
                    out.extend(parse_tree(chars, i));
                    if *i == before {
                        *i += 1;
                    }
                }
            }
        }
        return out;
    }
    let start = *i;
    while chars.get(*i).is_some_and(|c| c.is_ascii_alphanumeric() || *c == '_') {
        *i += 1;
    }
    let ident: String = chars[start..*i].iter().collect();
    if ident.is_empty() {
        return Vec::new();
    }
    if chars.get(*i) == Some(&':') && chars.get(*i + 1) == Some(&':') {
        *i += 2;
        let rest = parse_tree(chars, i);
        if rest.is_empty() {
            return vec![vec![ident]];
        }
        return rest
            .into_iter()
            .map(|mut tail| {
                tail.insert(0, ident.clone());
                tail
            })
            .collect();
    }
    vec![vec![ident]]
}

fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_owned(), 1);
        stack.push(node.to_owned());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = stack.iter().position(|n| n == next).unwrap();
                    let mut cycle = stack[start..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(cycle) = visit(next, graph, state, stack) {
                        return Some(cycle);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.to_owned(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(cycle) = visit(node, graph, &mut state, &mut stack) {
                return Some(cycle);
            }
        }
    }
    None
}

/// Lines of `sources` that name a crate their crate must not name.
fn forbidden_names(sources: &[Source]) -> Vec<String> {
    let mut offenders = Vec::new();
    for source in sources {
        let Some((_, _, forbidden)) = CRATES.iter().find(|(krate, _, _)| *krate == source.krate) else { continue };
        for (n, line) in source.code.iter().enumerate() {
            let words = line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'));
            for word in words {
                let head = word.split("::").next().unwrap_or("");
                if forbidden.contains(&head) && (word.contains("::") || line.trim_start().starts_with("use ")) {
                    offenders.push(format!("{}:{}: {}", source.path, n + 1, line.trim()));
                }
            }
        }
    }
    offenders
}

/// Where each `crate::…`, `super::…` and (in the binary's modules) `meshpaint::…` path of
/// `source` points, as a module path from its crate's root; a name a folder root re-exports
/// resolves to the child that defines it.
fn absolute_mentions(
    source: &Source,
    reexported: &BTreeMap<(String, Vec<String>), Vec<String>>,
) -> BTreeSet<Vec<String>> {
    let mut paths = paths_after(&source.code, "crate");
    // The binary's modules (src/cli) reach the library as `meshpaint::`.
    paths.extend(paths_after(&source.code, "meshpaint"));
    // `super` of `a/b.rs` and of `a/b/mod.rs` (module `a::b`) is `a`.
    let parent = &source.module[..source.module.len().saturating_sub(1)];
    for path in paths_after(&source.code, "super") {
        paths.insert(parent.iter().cloned().chain(path).collect());
    }
    paths
        .into_iter()
        .map(|path| match reexported.get(&(source.krate.clone(), path.clone())) {
            Some(target) => target.clone(),
            None => modules_of(&path).to_vec(),
        })
        .filter(|path| !path.is_empty())
        .collect()
}

/// The first cycle found between the children (files and subfolders) of one folder, at the
/// folder depths `depths` selects (0: a crate's top-level folders).
fn cycle_at(sources: &[Source], depths: &dyn Fn(usize) -> bool) -> Option<String> {
    // (crate, folder) → child → children of the same folder it mentions.
    let mut graphs: BTreeMap<(String, Vec<String>), BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    let reexported = reexports(sources);
    for source in sources {
        let mentions = absolute_mentions(source, &reexported);
        // `a/b/c.rs` is node `a` of its crate's root, `b` of `a` and `c` of `a/b`; a folder
        // root (`a/b/mod.rs`, module `a::b`) belongs to node `b` of `a`, not to its children.
        for depth in (0..source.module.len()).filter(|&d| depths(d)) {
            let (folder, node) = (&source.module[..depth], &source.module[depth]);
            let graph = graphs.entry((source.krate.clone(), folder.to_vec())).or_default();
            let targets = graph.entry(node.clone()).or_default();
            for path in &mentions {
                if path.len() > depth && path[..depth] == folder[..] && path[depth] != *node {
                    targets.insert(path[depth].clone());
                }
            }
        }
    }
    for ((krate, folder), mut graph) in graphs {
        let nodes: BTreeSet<String> = graph.keys().cloned().collect();
        for targets in graph.values_mut() {
            targets.retain(|t| nodes.contains(t));
        }
        if let Some(cycle) = find_cycle(&graph) {
            let place = if folder.is_empty() { "the top-level folders".to_owned() } else { folder.join("/") };
            return Some(format!("{krate}: {place}: {}", cycle.join(" → ")));
        }
    }
    None
}

/// A cycle between the top-level folders of one crate, if any.
fn folder_cycle(sources: &[Source]) -> Option<String> {
    cycle_at(sources, &|depth| depth == 0)
}

/// A cycle between the files and subfolders of one folder, at any depth, if any.
fn file_cycle(sources: &[Source]) -> Option<String> {
    cycle_at(sources, &|depth| depth > 0)
}

/// Whether a trimmed line opens a function: any visibility (`pub`, `pub(crate)`,
/// `pub(super)`, `pub(in …)`), then any of `const`, `async`, `unsafe`, `extern "…"`, then `fn`.
fn opens_fn(trimmed: &str) -> bool {
    let mut rest = trimmed;
    if let Some(after) = rest.strip_prefix("pub") {
        rest = after;
        if rest.starts_with('(') {
            let Some(close) = rest.find(')') else { return false };
            rest = &rest[close + 1..];
        }
        if !rest.starts_with(' ') {
            return false;
        }
        rest = rest.trim_start();
    }
    loop {
        if let Some(after) = ["const ", "async ", "unsafe "].iter().find_map(|q| rest.strip_prefix(q)) {
            rest = after.trim_start();
        } else if let Some(after) = rest.strip_prefix("extern \"") {
            let Some(close) = after.find('"') else { return false };
            rest = after[close + 1..].trim_start();
        } else {
            break;
        }
    }
    rest.starts_with("fn ")
}

/// Files over [`MAX_FILE_LINES`] and functions over [`MAX_FN_LINES`] without a `Long:` doc line.
fn too_long(sources: &[Source]) -> Vec<String> {
    let mut long = Vec::new();
    for source in sources {
        let count = source.text.lines().count();
        if count > MAX_FILE_LINES {
            long.push(format!("{}: {count} lines (limit {MAX_FILE_LINES})", source.path));
        }
        let lines: Vec<&str> = source.text.lines().collect();
        for (start, line) in lines.iter().enumerate() {
            let trimmed = line.trim_start();
            if !opens_fn(trimmed) || trimmed.ends_with(';') || trimmed.ends_with('}') {
                continue;
            }
            let indent = line.len() - trimmed.len();
            let close = format!("{}}}", " ".repeat(indent));
            let Some(end) = lines[start..].iter().position(|l| *l == close || l.starts_with(&format!("{close} ")))
            else {
                continue;
            };
            if end > MAX_FN_LINES {
                let doc = lines[..start].iter().rev().take_while(|l| {
                    let t = l.trim_start();
                    t.starts_with("///") || t.starts_with("#[")
                });
                if !doc.clone().any(|l| l.trim_start().starts_with("/// Long:")) {
                    long.push(format!(
                        "{}:{}: `{}` is {end} lines (limit {MAX_FN_LINES}; say why in a `/// Long:` doc line)",
                        source.path,
                        start + 1,
                        trimmed.trim_end_matches('{').trim()
                    ));
                }
            }
        }
    }
    long
}

/// Packages of a `cargo tree --prefix none` listing that are in `forbidden`.
fn forbidden_packages(tree: &str, forbidden: &[&str]) -> Vec<String> {
    let mut found: Vec<String> = tree
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| forbidden.contains(name))
        .map(str::to_owned)
        .collect();
    found.sort();
    found.dedup();
    found
}

#[test]
fn the_core_depends_on_no_gpu_or_ui_crate() {
    let output = std::process::Command::new(env!("CARGO"))
        .args(["tree", "--offline", "--locked", "-p", "meshpaint-core", "-e", "normal,build", "--prefix", "none"])
        .current_dir(workspace_root())
        .output()
        .unwrap();
    assert!(output.status.success(), "cargo tree failed: {}", String::from_utf8_lossy(&output.stderr));
    let tree = String::from_utf8_lossy(&output.stdout);
    assert!(tree.lines().count() > 10, "cargo tree listed almost nothing:\n{tree}");
    let found = forbidden_packages(&tree, &NOT_IN_CORE_TREE);
    assert!(found.is_empty(), "meshpaint-core depends on {found:?}");
}

#[test]
fn no_crate_names_what_it_must_not() {
    let sources = workspace_sources();
    assert!(sources.iter().any(|s| s.krate == "core") && sources.iter().any(|s| s.krate == "render"));
    let offenders = forbidden_names(&sources);
    assert!(offenders.is_empty(), "GPU / UI code named where it must not be:\n{}", offenders.join("\n"));
}

#[test]
fn folders_depend_on_each_other_without_cycles() {
    let sources = workspace_sources();
    let folders: BTreeSet<(&str, &str)> =
        sources.iter().filter_map(|s| Some((s.krate.as_str(), s.module.first()?.as_str()))).collect();
    assert!(folders.len() >= 12, "expected the folders of the three crates, found {folders:?}");
    if let Some(cycle) = folder_cycle(&sources) {
        panic!("folders import each other in a circle: {cycle}");
    }
}

#[test]
fn files_of_one_folder_depend_on_each_other_without_cycles() {
    if let Some(cycle) = file_cycle(&workspace_sources()) {
        panic!("{cycle}");
    }
}

#[test]
fn files_and_functions_stay_short() {
    let long = too_long(&workspace_sources());
    assert!(long.is_empty(), "too long:\n{}", long.join("\n"));
}

fn planted(krate: &str, path: &str, text: &str) -> Source {
    Source::new(krate, Path::new(path), text.to_owned())
}

#[test]
fn planted_gpu_names_in_the_core_are_found() {
    let clean =
        planted("core", "paint/brush.rs", "use crate::colors::store::ColorStore;\n// wgpu::Device in a comment\n");
    assert!(forbidden_names(&[clean]).is_empty());
    let dirty = planted("core", "paint/brush.rs", "fn f(device: &wgpu::Device) {}\n");
    assert_eq!(forbidden_names(&[dirty]).len(), 1);
    let dirty = planted("render", "gpu.rs", "use egui;\n");
    assert_eq!(forbidden_names(&[dirty]).len(), 1);
    let tree = "meshpaint-core v0.1.0\nglam v0.34.2\nwgpu v30.0.1\n";
    assert_eq!(forbidden_packages(tree, &NOT_IN_CORE_TREE), ["wgpu"]);
}

#[test]
fn planted_folder_cycles_are_found() {
    let a = planted("core", "a/x.rs", "use crate::b::y::Y;\n");
    let b = planted("core", "b/y.rs", "pub struct Y;\n");
    assert_eq!(folder_cycle(&[a, b]), None);
    let a = planted("core", "a/x.rs", "use crate::{\n    b::y::Y,\n    colors::format,\n};\n");
    let b = planted("core", "b/y.rs", "use crate::a::x;\n");
    assert!(folder_cycle(&[a, b]).is_some_and(|c| c.contains("a → b → a") || c.contains("b → a → b")));
    // The same two folders in different crates are no cycle.
    let a = planted("core", "a/x.rs", "use crate::b::y::Y;\n");
    let b = planted("render", "b/y.rs", "use crate::a::x;\n");
    assert_eq!(folder_cycle(&[a, b]), None);
}

#[test]
fn planted_file_cycles_through_grouped_super_imports_are_found() {
    let x = planted("render", "render/x.rs", "use super::{y::Y, z};\n");
    let y = planted("render", "render/y.rs", "pub struct Y;\n");
    let z = planted("render", "render/z.rs", "pub struct Z;\n");
    assert_eq!(file_cycle(&[x, y, z]), None);
    let x = planted("render", "render/x.rs", "use super::{y::Y, z};\n");
    let y = planted("render", "render/y.rs", "pub(super) fn f() -> super::x::X { todo!() }\n");
    let z = planted("render", "render/z.rs", "pub struct Z;\n");
    assert!(file_cycle(&[x, y, z]).is_some_and(|c| c.contains("x → y → x") || c.contains("y → x → y")));
    let x = planted("app", "app/x.rs", "use super::{\n    self,\n    y::{A, B},\n};\n");
    let y = planted("app", "app/y.rs", "use crate::app::x::X;\n");
    assert!(file_cycle(&[x, y]).is_some());
}

#[test]
fn planted_cycles_between_a_folder_and_its_subfolder_are_found() {
    let panel = planted("app", "app/panels/view.rs", "use crate::app::state::ViewSettings;\n");
    let state = planted("app", "app/state.rs", "pub struct ViewSettings;\n");
    let root = planted("app", "app/panels/mod.rs", "pub mod view;\n");
    assert_eq!(file_cycle(&[panel, state, root]), None);
    let panel = planted("app", "app/panels/view.rs", "use crate::app::state::ViewSettings;\n");
    let state = planted("app", "app/state.rs", "use super::panels::view::ViewPanel;\n");
    assert!(
        file_cycle(&[panel, state])
            .is_some_and(|c| c.contains("panels → state → panels") || c.contains("state → panels → state"))
    );
}

#[test]
fn planted_cycles_through_a_folder_roots_reexports_are_found() {
    let root = planted(
        "render",
        "lib.rs",
        "mod baseline;\nmod renderer;\npub use baseline::BaselineMesh;\npub use renderer::{Renderer, RenderSettings};\n",
    );
    let baseline = planted("render", "baseline.rs", "use super::{GpuContext, Renderer};\n");
    let renderer = planted("render", "renderer.rs", "pub struct Renderer;\n");
    assert_eq!(folder_cycle(&[root, baseline, renderer]), None);
    let root = planted(
        "render",
        "lib.rs",
        "mod baseline;\nmod renderer;\npub use baseline::BaselineMesh;\npub use renderer::{Renderer, RenderSettings};\n",
    );
    let baseline = planted("render", "baseline.rs", "use super::{GpuContext, Renderer};\n");
    let renderer = planted("render", "renderer.rs", "use super::BaselineMesh;\n");
    assert!(
        folder_cycle(&[root, baseline, renderer]).is_some_and(
            |c| c.contains("baseline → renderer → baseline") || c.contains("renderer → baseline → renderer")
        )
    );
}

#[test]
fn planted_long_functions_are_found_whatever_their_visibility() {
    for header in [
        "fn run() {",
        "pub(super) fn run() {",
        "pub(crate) unsafe fn run() {",
        "pub const fn run() {",
        "async fn run() {",
    ] {
        let body = "    let x = 1;\n".repeat(MAX_FN_LINES);
        let text = format!("{header}\n{body}}}\n");
        assert_eq!(too_long(&[planted("app", "cli/bench.rs", &text)]).len(), 1, "{header}");
        let justified = format!("/// Long: one match over every command.\n{text}");
        assert!(too_long(&[planted("app", "cli/bench.rs", &justified)]).is_empty(), "{header}");
        let short = format!("{header}\n{}}}\n", "    let x = 1;\n".repeat(MAX_FN_LINES - 1));
        assert!(too_long(&[planted("app", "cli/bench.rs", &short)]).is_empty(), "{header}");
    }
    assert!(!opens_fn("pub struct Fn;") && !opens_fn("let fn_name = 1;") && !opens_fn("public fn x() {"));
}
