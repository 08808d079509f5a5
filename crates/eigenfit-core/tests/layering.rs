//! Layering: no module imports a higher layer, no crate depends on a higher crate, and no crate's
//! modules import each other in a cycle.
//!
//! The source is read as text: every `crate::<name>` path outside a comment is an import of the
//! module `<name>` (a name re-exported at the crate root counts as the module it comes from).
//! A failure lists `file:line`, the layers involved and the offending line.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The core's layers, bottom first: each may use only those before it. `prelude` gathers items
/// from all of them, so it sits on top.
const CORE_LAYERS: &[&str] = &[
    "units",
    "testing",
    "names",
    "matrix",
    "model",
    "eigen",
    "sensitivity",
    "measurement",
    "problem",
    "update",
    "analysis",
    "discovery",
    "prelude",
];

/// Test support compiled only under `cfg(test)`, usable from any layer's unit tests.
const CORE_TEST_SUPPORT: &[&str] = &["test_chain"];

/// The workspace crates, bottom first: a crate may depend only on crates before it.
const CRATES: &[&str] = &[
    "eigenfit-core",
    "eigenfit-lapack",
    "eigenfit-rotor",
    "eigenfit-matrices",
    "eigenfit-rotordynamics",
    "eigenfit-workflow",
    "eigenfit-cli",
    "eigenfit",
    "eigenfit-python",
];

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

/// The text with `//` comments blanked (line numbers kept): doc links may point anywhere.
fn strip_comments(text: &str) -> String {
    text.lines()
        .map(|line| match line.find("//") {
            Some(i) if !line[..i].contains('"') => &line[..i],
            _ => line,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// One import of a module of the same crate.
struct Import {
    line: usize,
    module: String,
    text: String,
}

/// Every `crate::name` and `crate::{a::…, b::…}` (the first segment of each), and every
/// `super::super::` (which would climb out of a layer without naming it).
fn imports(text: &str) -> Vec<Import> {
    let code = strip_comments(text);
    let lines: Vec<&str> = text.lines().collect();
    let line_of = |offset: usize| code[..offset].matches('\n').count();
    let ident = |s: &str| -> String { s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    let mut out = Vec::new();
    let mut push = |offset: usize, module: String| {
        let line = line_of(offset);
        out.push(Import { line: line + 1, module, text: lines.get(line).unwrap_or(&"").trim().to_string() });
    };
    for (at, _) in code.match_indices("crate::") {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &code[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut item, mut names) = (0, String::new(), Vec::new());
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => names.push(std::mem::take(&mut item)),
                    _ => {}
                }
                if !(c == ',' && depth == 0) {
                    item.push(c);
                }
            }
            names.push(item);
            for name in names.iter().map(|n| ident(n.trim())).filter(|n| !n.is_empty()) {
                push(at, name);
            }
        } else {
            push(at, ident(rest));
        }
    }
    for (at, _) in code.match_indices("super::super::") {
        push(at, "super::super".to_string());
    }
    out
}

/// Root items of a crate: names the root re-exports, mapped to the module they come from.
/// Items defined in the root itself map to `""` (usable by every module).
fn root_items(lib: &str) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    for statement in strip_comments(lib).split(';') {
        let s = statement.trim();
        let Some(path) = s.strip_prefix("pub use ").or_else(|| s.strip_prefix("pub(crate) use ")) else {
            for keyword in
                ["pub fn ", "pub const ", "pub struct ", "pub enum ", "pub trait ", "fn ", "const "]
            {
                if let Some(i) = s.find(keyword) {
                    let name: String = s[i + keyword.len()..]
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    map.insert(name, String::new());
                }
            }
            continue;
        };
        let Some((module, items)) = path.split_once("::") else { continue };
        let items = items.trim().trim_start_matches('{').trim_end_matches('}');
        for item in items.split(',') {
            let name = item.rsplit(" as ").next().unwrap_or(item).rsplit("::").next().unwrap_or(item).trim();
            if !name.is_empty() {
                map.insert(name.to_string(), module.trim().to_string());
            }
        }
    }
    map
}

/// The module (first path component under `src/`) a file belongs to; `None` for the root.
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).expect("file under src");
    let first = rel.components().next()?.as_os_str().to_string_lossy().to_string();
    if rel.components().count() == 1 {
        let stem = first.trim_end_matches(".rs").to_string();
        return (stem != "lib" && stem != "main").then_some(stem);
    }
    Some(first)
}

/// The module-level imports of a crate: (importing module, imported module, where, line text).
fn module_edges(crate_dir: &Path) -> Vec<(String, String, String, String)> {
    let src = crate_dir.join("src");
    let lib = fs::read_to_string(src.join("lib.rs")).or_else(|_| fs::read_to_string(src.join("main.rs")));
    let roots = root_items(&lib.expect("lib.rs or main.rs"));
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut edges = Vec::new();
    for file in files {
        let Some(from) = module_of(&src, &file) else { continue };
        let text = fs::read_to_string(&file).expect("readable source");
        for import in imports(&text) {
            let to = roots.get(&import.module).cloned().unwrap_or(import.module);
            if to.is_empty() || to == from || to == "self" {
                continue;
            }
            let place =
                format!("{}:{}", file.strip_prefix(workspace()).unwrap_or(&file).display(), import.line);
            edges.push((from.clone(), to, place, import.text));
        }
    }
    edges
}

/// Violations of a declared bottom-first order of a crate's modules.
fn order_violations(crate_dir: &Path, order: &[&str], test_support: &[&str]) -> Vec<String> {
    let rank = |m: &str| order.iter().position(|l| *l == m);
    let mut bad = Vec::new();
    for (from, to, place, text) in module_edges(crate_dir) {
        if test_support.contains(&from.as_str()) || test_support.contains(&to.as_str()) {
            continue;
        }
        match (rank(&from), rank(&to)) {
            (Some(a), Some(b)) if b > a => {
                bad.push(format!("{place}: layer `{from}` imports the higher layer `{to}`: {text}"))
            }
            (Some(_), Some(_)) => {}
            (None, _) => {
                bad.push(format!("{place}: module `{from}` has no place in the layer order: {text}"))
            }
            (_, None) => bad.push(format!("{place}: `{to}` is not a layer (use crate::<layer>::…): {text}")),
        }
    }
    bad
}

/// Module cycles of a crate, each with the imports that close it.
fn cycles(crate_dir: &Path) -> Vec<String> {
    let edges = module_edges(crate_dir);
    let mut graph: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for (from, to, _, _) in &edges {
        graph.entry(from).or_default().insert(to);
    }
    let reaches = |a: &str, b: &str| {
        let (mut seen, mut stack) = (BTreeSet::new(), vec![a]);
        while let Some(m) = stack.pop() {
            if m == b {
                return true;
            }
            if seen.insert(m) {
                stack.extend(graph.get(m).into_iter().flatten().copied());
            }
        }
        false
    };
    edges
        .iter()
        .filter(|(from, to, _, _)| reaches(to, from))
        .map(|(from, to, place, text)| format!("{place}: `{from}` → `{to}` closes a cycle: {text}"))
        .collect()
}

fn report(what: &str, bad: &[String]) {
    assert!(bad.is_empty(), "{what}:\n  {}\n", bad.join("\n  "));
}

#[test]
fn core_layers_import_only_lower_layers() {
    let bad = order_violations(&workspace().join("crates/eigenfit-core"), CORE_LAYERS, CORE_TEST_SUPPORT);
    report("eigenfit-core imports a higher layer", &bad);
}

#[test]
fn every_core_module_is_a_declared_layer() {
    let src = workspace().join("crates/eigenfit-core/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let undeclared: BTreeSet<String> = files
        .iter()
        .filter_map(|f| module_of(&src, f))
        .filter(|m| !CORE_LAYERS.contains(&m.as_str()) && !CORE_TEST_SUPPORT.contains(&m.as_str()))
        .collect();
    assert!(undeclared.is_empty(), "modules without a place in CORE_LAYERS: {undeclared:?}");
}

/// The plugin crates and the workflow crate above them.
#[test]
fn plugin_crates_have_no_module_cycles() {
    for name in ["eigenfit-matrices", "eigenfit-rotordynamics", "eigenfit-lapack", "eigenfit-workflow"] {
        report(&format!("{name} has a module cycle"), &cycles(&workspace().join("crates").join(name)));
    }
}

#[test]
fn rotor_crate_has_no_module_cycles() {
    report("eigenfit-rotor has a module cycle", &cycles(&workspace().join("crates/eigenfit-rotor")));
}

/// The rotor crate's modules, bottom first: plain descriptions (`spec`) below the checked model,
/// the effects above the model they act on, construction (`builder`) above the effects it
/// applies, and the file reader, presets and extensions above the builder.
const ROTOR_LAYERS: &[&str] = &[
    "error",
    "element",
    "spec",
    "model",
    "pedestal",
    "effects",
    "structural",
    "builder",
    "file",
    "presets",
    "updatable",
    "layout",
    "mesh",
    "mirror",
    "discovery",
    "campaign",
];

#[test]
fn rotor_modules_import_only_lower_modules() {
    let bad = order_violations(&workspace().join("crates/eigenfit-rotor"), ROTOR_LAYERS, &[]);
    report("eigenfit-rotor imports a higher module", &bad);
}

/// The CLI only presents (issue #12 item 2): model loading lives in `eigenfit-workflow`, so the
/// former `any_model` ↔ `source` ↔ `commands::simulate` cycle is gone.
#[test]
fn cli_crate_has_no_module_cycles() {
    report("eigenfit-cli has a module cycle", &cycles(&workspace().join("crates/eigenfit-cli")));
}

/// `[dependencies]` (and optional ones) naming workspace crates, from a Cargo.toml.
fn crate_dependencies(manifest: &str) -> Vec<String> {
    let mut section = String::new();
    let mut deps = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line.to_string();
        } else if section == "[dependencies]" || section == "[build-dependencies]" {
            let name = line.split(['=', '.', ' ']).next().unwrap_or("").trim();
            if name.starts_with("eigenfit") {
                deps.push(name.to_string());
            }
        }
    }
    deps
}

#[test]
fn crates_depend_only_on_lower_crates() {
    let root = workspace();
    let mut manifests = vec![(String::from("eigenfit"), root.join("Cargo.toml"))];
    manifests.push(("eigenfit-python".into(), root.join("python/Cargo.toml")));
    for entry in fs::read_dir(root.join("crates")).expect("crates/") {
        let dir = entry.expect("entry").path();
        if dir.join("Cargo.toml").exists() {
            manifests.push((dir.file_name().unwrap().to_string_lossy().to_string(), dir.join("Cargo.toml")));
        }
    }
    let rank = |c: &str| CRATES.iter().position(|k| *k == c);
    let mut bad = Vec::new();
    for (name, manifest) in manifests {
        let text = fs::read_to_string(&manifest).expect("readable Cargo.toml");
        let Some(own) = rank(&name) else {
            bad.push(format!("{}: crate `{name}` has no place in CRATES", manifest.display()));
            continue;
        };
        for dep in crate_dependencies(&text) {
            match rank(&dep) {
                Some(r) if r < own => {}
                _ => bad.push(format!("{}: `{name}` depends on `{dep}`, not below it", manifest.display())),
            }
        }
    }
    report("a crate depends on a higher one", &bad);
}

/// The checks catch what they are for: an upward import in a made-up lower layer.
#[test]
fn an_upward_import_is_reported_with_its_place() {
    let found = imports("use crate::model::Fixed;\n// crate::discovery in a comment\nuse crate::{units::x, update::Driver};\n");
    let names: Vec<(usize, &str)> = found.iter().map(|i| (i.line, i.module.as_str())).collect();
    assert_eq!(names, vec![(1, "model"), (3, "units"), (3, "update")]);
    assert_eq!(found[2].text, "use crate::{units::x, update::Driver};");
}
