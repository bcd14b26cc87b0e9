//! The layout rules of `lib.rs`, checked on the source tree itself:
//!
//! - the core folders never import `wgpu`, `egui` or `winit`;
//! - modules depend on each other without cycles, both between the top-level folders and
//!   between the files of one folder (e.g. `app/`);
//! - no source file is longer than [`MAX_FILE_LINES`], no function longer than
//!   [`MAX_FN_LINES`] unless its doc comment says why (a line starting `Long:`).
//!
//! The checks read the files as text: `use`/path mentions of `crate::…` and `super::…`
//! are the dependency edges (doc comments and tests excluded).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const CORE: [&str; 9] = ["mesh", "colors", "packing", "paint", "io", "camera", "atomic_write", "memory", "threads"];
const MAX_FILE_LINES: usize = 800;
const MAX_FN_LINES: usize = 100;

fn source_files() -> Vec<PathBuf> {
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
    let mut files = Vec::new();
    walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut files);
    files.sort();
    files
}

/// The module path of a file below `src/` (`src/paint/brush/mod.rs` → `["paint", "brush"]`).
fn module_path(file: &Path) -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let relative = file.strip_prefix(&src).unwrap().with_extension("");
    let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
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

/// `crate::a::b…` mentions in `lines`, as module paths of at most `depth` parts.
fn crate_mentions(lines: &[String]) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    for line in lines {
        let mut rest = line.as_str();
        while let Some(at) = rest.find("crate::") {
            let tail = &rest[at + "crate::".len()..];
            let path: Vec<String> = tail
                .split("::")
                .map(|p| p.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect::<String>())
                .take_while(|p| !p.is_empty() && p.chars().next().is_some_and(|c| c.is_ascii_lowercase()))
                .collect();
            if !path.is_empty() {
                out.insert(path);
            }
            rest = tail;
        }
    }
    out
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

#[test]
fn core_never_imports_gpu_or_ui_crates() {
    let mut offenders = Vec::new();
    for file in source_files() {
        let module = module_path(&file);
        if !module.first().is_some_and(|top| CORE.contains(&top.as_str())) {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in code_lines(&text).iter().enumerate() {
            for forbidden in ["wgpu", "egui", "winit", "crate::render", "crate::app", "crate::bench"] {
                let word = line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'));
                if word.clone().any(|w| w == forbidden || w.starts_with(&format!("{forbidden}::"))) {
                    offenders.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(offenders.is_empty(), "the core imports GPU / UI code:\n{}", offenders.join("\n"));
}

#[test]
fn folders_depend_on_each_other_without_cycles() {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in source_files() {
        let module = module_path(&file);
        let Some(top) = module.first().cloned() else { continue };
        let text = std::fs::read_to_string(&file).unwrap();
        for mention in crate_mentions(&code_lines(&text)) {
            if mention[0] != top {
                graph.entry(top.clone()).or_default().insert(mention[0].clone());
            }
        }
        graph.entry(top).or_default();
    }
    assert!(graph.len() >= 8, "expected the folders of lib.rs, found {:?}", graph.keys().collect::<Vec<_>>());
    if let Some(cycle) = find_cycle(&graph) {
        panic!("folders import each other in a circle: {}\n{graph:#?}", cycle.join(" → "));
    }
}

#[test]
fn files_of_one_folder_depend_on_each_other_without_cycles() {
    // Per folder: file → sibling files it mentions through `super::x` or `crate::folder::x`.
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for file in source_files() {
        let module = module_path(&file);
        if file.file_name().is_some_and(|n| n == "mod.rs" || n == "lib.rs" || n == "main.rs") || module.len() < 2 {
            continue;
        }
        let (folder, name) = (module[..module.len() - 1].to_vec(), module[module.len() - 1].clone());
        let text = std::fs::read_to_string(&file).unwrap();
        let lines = code_lines(&text);
        let mut siblings = BTreeSet::new();
        for mention in crate_mentions(&lines) {
            if mention.len() > folder.len() && mention[..folder.len()] == folder[..] {
                siblings.insert(mention[folder.len()].clone());
            }
        }
        for line in &lines {
            let mut rest = line.as_str();
            while let Some(at) = rest.find("super::") {
                let tail = &rest[at + "super::".len()..];
                let word: String = tail.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                if !word.is_empty() && word.chars().next().is_some_and(|c| c.is_ascii_lowercase()) {
                    siblings.insert(word);
                }
                rest = tail;
            }
        }
        siblings.remove(&name);
        let graph = graphs.entry(folder).or_default();
        graph.entry(name).or_default().extend(siblings);
    }
    for (folder, mut graph) in graphs {
        let files: BTreeSet<String> = graph.keys().cloned().collect();
        for targets in graph.values_mut() {
            targets.retain(|t| files.contains(t));
        }
        if let Some(cycle) = find_cycle(&graph) {
            panic!("files of src/{} import each other in a circle: {}", folder.join("/"), cycle.join(" → "));
        }
    }
}

#[test]
fn files_and_functions_stay_short() {
    let mut long = Vec::new();
    for file in source_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        let count = text.lines().count();
        if count > MAX_FILE_LINES {
            long.push(format!("{}: {count} lines (limit {MAX_FILE_LINES})", file.display()));
        }
        let lines: Vec<&str> = text.lines().collect();
        for (start, line) in lines.iter().enumerate() {
            let trimmed = line.trim_start();
            let is_fn = ["fn ", "pub fn ", "pub(crate) fn ", "const fn ", "pub const fn ", "async fn ", "unsafe fn "]
                .iter()
                .any(|p| trimmed.starts_with(p));
            if !is_fn || trimmed.ends_with(';') {
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
                        file.display(),
                        start + 1,
                        trimmed.trim_end_matches('{').trim()
                    ));
                }
            }
        }
    }
    assert!(long.is_empty(), "too long:\n{}", long.join("\n"));
}
