//! The layout keeps its promises: data flows one way (no module imports another that imports it
//! back, directly or through others, among the library's modules and among the files of each
//! module), and every room stays small enough to read (no source file of 450 lines or more).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Modules of the binary, which sits above the library and is not part of its graph.
const BINARY: [&str; 3] = ["main", "cli", "commands"];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of `text` without comments (line comments and doc comments).
fn code(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Module names that `code` reaches through `prefix` (`crate::` or `super::`): `prefix name::`,
/// `prefix name;` and the names inside `prefix {…}`.
fn reached(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let after = &rest[i + prefix.len()..];
        if let Some(list) = after.strip_prefix('{') {
            let end = list.find('}').unwrap_or(list.len());
            for item in list[..end].split(',') {
                let item = item.trim();
                if item.contains("::") {
                    out.insert(ident(item));
                }
            }
        } else {
            let name = ident(after);
            let next = &after[name.len()..];
            if !name.is_empty() && (next.starts_with("::") || next.starts_with(';')) {
                out.insert(name);
            }
        }
        rest = after;
    }
    out
}

/// Whether the graph has a cycle; returns one if so.
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(n) {
            Some(1) => {
                let start = path.iter().position(|p| p == n).unwrap();
                let mut c = path[start..].to_vec();
                c.push(n.to_string());
                return Some(c);
            }
            Some(2) => return None,
            _ => {}
        }
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, g, state, path) {
                return Some(c);
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
            return Some(c);
        }
    }
    None
}

fn library_files() -> Vec<(PathBuf, String)> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    files
        .into_iter()
        .filter(|p| {
            let top = p.strip_prefix(src()).unwrap();
            !(top.components().count() == 1 && BINARY.contains(&top.to_str().unwrap()))
        })
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect()
}

#[test]
fn modules_depend_one_way() {
    let mut top: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut rooms: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (path, text) in library_files() {
        let rel = path.strip_prefix(src()).unwrap();
        let parts: Vec<String> = rel
            .iter()
            .map(|c| c.to_str().unwrap().trim_end_matches(".rs").to_string())
            .collect();
        if parts == ["lib"] {
            continue;
        }
        let module = parts[0].clone();
        let code = code(&text);
        let deps = top.entry(module.clone()).or_default();
        for m in reached(&code, "crate::") {
            if m != module {
                deps.insert(m);
            }
        }
        // Files of a directory module: `super::sibling::…` is an edge between siblings.
        if parts.len() == 2 && parts[1] != "mod" {
            let room = rooms.entry(module.clone()).or_default();
            let deps = room.entry(parts[1].clone()).or_default();
            for m in reached(&code, "super::") {
                if m != parts[1] {
                    deps.insert(m);
                }
            }
        }
    }
    assert!(top.len() >= 10, "modules found: {:?}", top.keys());
    if let Some(c) = cycle(&top) {
        panic!("import cycle among modules: {}", c.join(" → "));
    }
    for (room, graph) in &rooms {
        // Only edges to siblings count; `super::Item` of the parent is not a sibling.
        let graph: BTreeMap<String, BTreeSet<String>> = graph
            .iter()
            .map(|(k, v)| {
                let v = v
                    .iter()
                    .filter(|m| graph.contains_key(*m))
                    .cloned()
                    .collect();
                (k.clone(), v)
            })
            .collect();
        if let Some(c) = cycle(&graph) {
            panic!("import cycle inside {room}: {}", c.join(" → "));
        }
    }
}

#[test]
fn the_cycle_finder_sees_a_cycle() {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    assert!(cycle(&g).is_none());
    g.entry("c".into()).or_default().insert("a".into());
    assert_eq!(cycle(&g).unwrap(), ["a", "b", "c", "a"]);
    assert_eq!(
        reached(
            "use crate::{checks::X, filter::{A, B}};\nlet x = crate::stats::f();",
            "crate::"
        ),
        ["checks", "filter", "stats"]
            .into_iter()
            .map(String::from)
            .collect()
    );
}

#[test]
fn every_source_file_is_under_450_lines() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let long: Vec<String> = files
        .iter()
        .map(|p| (p, std::fs::read_to_string(p).unwrap().lines().count()))
        .filter(|(_, n)| *n >= 450)
        .map(|(p, n)| format!("{} ({n} lines)", p.display()))
        .collect();
    assert!(long.is_empty(), "files of 450 lines or more: {long:?}");
}
