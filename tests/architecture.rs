//! The layout keeps its promises: data flows one way (no module imports another that imports it
//! back, directly or through others, among the modules of any one parent at any depth: the
//! library's top modules, `allan`'s, `allan::imu`'s, …), and every room stays small enough to
//! read (no source file of 450 lines or more).
//!
//! Every file and inline `mod name { … }` is a module whose path comes from the file's place
//! under `src/` (or its `#[path]` attribute). Its code, comments and strings left out, is read
//! for paths that start with `crate::`, `$crate::`, `super::` or `self::`, `use` trees with
//! `{…}` lists included; each is resolved against the module it appears in. A path from module
//! `p::a::…` to `p::b::…`, `a` and `b` both modules of `p`, is the edge `a → b` among `p`'s
//! modules; a path to an item of `p` itself (`super::Item`) or into one's own module is none. A
//! name re-exported by a parent counts as the parent's. The binary (`main.rs`, `cli`,
//! `commands`) is a crate of its own, checked the same way.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top modules of the binary, which sits above the library and is a crate of its own.
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

/// A module's path, its crate (`lib` or `bin`) first.
type ModPath = Vec<String>;

/// The tokens of code that paths are made of; everything else is [`Tok::Other`].
#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    /// `::`
    Sep,
    Open,
    Close,
    Comma,
    Star,
    Other,
}

/// The tokens of `text`, without comments, string and character literals and lifetimes.
fn tokens(text: &str) -> Vec<Tok> {
    let c: Vec<char> = text.chars().collect();
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    let ident_char = |x: char| x.is_alphanumeric() || x == '_';
    let (mut out, mut i) = (Vec::new(), 0);
    while i < c.len() {
        let x = c[i];
        if x.is_whitespace() {
            i += 1;
        } else if x == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if x == '/' && at(i + 1) == '*' {
            let (mut depth, mut j) = (1, i + 2);
            while j < c.len() && depth > 0 {
                match (c[j], at(j + 1)) {
                    ('/', '*') => (depth, j) = (depth + 1, j + 2),
                    ('*', '/') => (depth, j) = (depth - 1, j + 2),
                    _ => j += 1,
                }
            }
            i = j;
        } else if x == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if x == '\'' {
            // A character literal ('x', '\n', '\u{..}') or a lifetime ('a), which is skipped.
            if at(i + 1) == '\\' {
                // Past the escaped character, which may be a quote: '\''.
                i += 3;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(i + 2) == '\'' {
                i += 3;
            } else {
                i += 1;
            }
        } else if ident_char(x) || (x == '$' && ident_char(at(i + 1))) {
            let start = i;
            i += 1;
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            let hashes = (i..).take_while(|&k| at(k) == '#').count();
            if (word == "r" || word == "br") && at(i + hashes) == '"' {
                // A raw string: up to the quote followed by as many `#`.
                let mut j = i + hashes + 1;
                while j < c.len() && !(c[j] == '"' && (1..=hashes).all(|k| at(j + k) == '#')) {
                    j += 1;
                }
                i = j + 1 + hashes;
                continue;
            }
            out.push(Tok::Ident(word.trim_start_matches('$').to_string()));
        } else {
            out.push(match (x, at(i + 1)) {
                (':', ':') => {
                    i += 1;
                    Tok::Sep
                }
                ('{', _) => Tok::Open,
                ('}', _) => Tok::Close,
                (',', _) => Tok::Comma,
                ('*', _) => Tok::Star,
                _ => Tok::Other,
            });
            i += 1;
        }
    }
    out
}

/// The paths of the `use` tree or path starting at `t[i]` (each a list of segments, a `{…}`
/// list giving one path per item), and the index after it.
fn tree(t: &[Tok], mut i: usize) -> (Vec<Vec<String>>, usize) {
    let mut segments = Vec::new();
    let mut out = Vec::new();
    loop {
        match t.get(i) {
            Some(Tok::Ident(s)) => {
                segments.push(s.clone());
                i += 1;
            }
            Some(Tok::Open) => {
                i += 1;
                while i < t.len() && t[i] != Tok::Close {
                    if t[i] == Tok::Comma {
                        i += 1;
                        continue;
                    }
                    let (inner, j) = tree(t, i);
                    out.extend(inner.into_iter().map(|p| [segments.clone(), p].concat()));
                    // `x as y`: up to the next item.
                    i = j.max(i + 1);
                    while i < t.len() && !matches!(t[i], Tok::Comma | Tok::Close) {
                        i += 1;
                    }
                }
                return (out, i + 1);
            }
            Some(Tok::Star) => return (vec![segments], i + 1),
            _ => break,
        }
        if t.get(i) != Some(&Tok::Sep) {
            break;
        }
        i += 1;
    }
    out.push(segments);
    (out, i)
}

/// `path` read in the module `module`: `crate`, `super` and `self` resolved.
fn resolve(module: &[String], path: &[String]) -> ModPath {
    let mut out = module.to_vec();
    for (k, s) in path.iter().enumerate() {
        match s.as_str() {
            "crate" if k == 0 => out.truncate(1),
            "super" => {
                out.pop();
            }
            "self" => {}
            _ => out.push(s.clone()),
        }
    }
    out
}

/// What the code of the module `module` refers to, and the inline modules it declares:
/// (the module a path appears in, the path resolved) and the inline modules' paths.
fn references(module: &ModPath, text: &str) -> (Vec<(ModPath, ModPath)>, Vec<ModPath>) {
    let t = tokens(text);
    let (mut refs, mut inline) = (Vec::new(), Vec::new());
    // The inline modules open here, each with the brace depth outside it.
    let mut scopes: Vec<(ModPath, usize)> = vec![(module.clone(), 0)];
    let (mut depth, mut i) = (0usize, 0usize);
    while i < t.len() {
        let here = scopes.last().unwrap().0.clone();
        match &t[i] {
            Tok::Ident(m) if m == "mod" => {
                if let (Some(Tok::Ident(name)), Some(Tok::Open)) = (t.get(i + 1), t.get(i + 2)) {
                    let path = [here, vec![name.clone()]].concat();
                    inline.push(path.clone());
                    scopes.push((path, depth));
                    depth += 1;
                    i += 3;
                    continue;
                }
            }
            Tok::Ident(s)
                if matches!(s.as_str(), "crate" | "super" | "self")
                    && t.get(i + 1) == Some(&Tok::Sep)
                    && (i == 0 || t[i - 1] != Tok::Sep) =>
            {
                let (paths, j) = tree(&t, i);
                refs.extend(paths.iter().map(|p| (here.clone(), resolve(&here, p))));
                i = j;
                continue;
            }
            Tok::Open => depth += 1,
            Tok::Close => {
                depth = depth.saturating_sub(1);
                if scopes.len() > 1 && scopes.last().unwrap().1 == depth {
                    scopes.pop();
                }
            }
            _ => {}
        }
        i += 1;
    }
    (refs, inline)
}

/// The `#[path = "file"] mod name;` declarations of `text`: (file, name).
fn path_attributes(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut file: Option<String> = None;
    for line in text.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("#[path = \"") {
            file = rest.split('"').next().map(String::from);
        } else if let Some(f) = &file
            && let Some(decl) = line.split("mod ").nth(1)
            && line.ends_with(';')
        {
            out.push((f.clone(), decl.trim_end_matches(';').trim().to_string()));
            file = None;
        }
    }
    out
}

/// Every source file's module path and text.
fn modules() -> Vec<(ModPath, String)> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    let texts: Vec<(PathBuf, String)> = files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect();
    let mut placed: BTreeMap<PathBuf, ModPath> = BTreeMap::new();
    for (p, _) in &texts {
        let rel = p.strip_prefix(src()).unwrap();
        let mut parts: Vec<String> = rel
            .iter()
            .map(|c| c.to_str().unwrap().trim_end_matches(".rs").to_string())
            .collect();
        let krate = if BINARY.contains(&parts[0].as_str()) {
            "bin"
        } else {
            "lib"
        };
        if matches!(
            parts.last().map(String::as_str),
            Some("mod" | "lib" | "main")
        ) {
            parts.pop();
        }
        placed.insert(p.clone(), [vec![krate.to_string()], parts].concat());
    }
    for (p, text) in &texts {
        for (file, name) in path_attributes(text) {
            let module = [placed[p].clone(), vec![name]].concat();
            placed.insert(p.parent().unwrap().join(file), module);
        }
    }
    texts
        .into_iter()
        .map(|(p, t)| (placed[&p].clone(), t))
        .collect()
}

/// Per parent module, the import edges among its modules: `a → b` when code inside `a` names
/// something inside `b`.
type Graphs = BTreeMap<ModPath, BTreeMap<String, BTreeSet<String>>>;

fn sibling_graphs(sources: &[(ModPath, String)]) -> Graphs {
    let mut known: BTreeSet<ModPath> = sources.iter().map(|(m, _)| m.clone()).collect();
    let mut refs = Vec::new();
    for (module, text) in sources {
        let (r, inline) = references(module, text);
        refs.extend(r);
        known.extend(inline);
    }
    let mut graphs = Graphs::new();
    for m in &known {
        if let Some((_, parent)) = m.split_last()
            && !parent.is_empty()
        {
            let room = graphs.entry(parent.to_vec()).or_default();
            room.entry(m.last().unwrap().clone()).or_default();
        }
    }
    for (from, to) in refs {
        let d = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
        if d == 0 || d >= from.len() || d >= to.len() {
            continue;
        }
        if known.contains(&to[..=d]) {
            let room = graphs.entry(from[..d].to_vec()).or_default();
            room.entry(from[d].clone())
                .or_default()
                .insert(to[d].clone());
        }
    }
    graphs
}

/// One cycle through each strongly connected part of `graph` that has one, and the part's
/// modules.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<(Vec<String>, BTreeSet<String>)> {
    let reach = |from: &str| -> BTreeSet<String> {
        let (mut seen, mut todo) = (BTreeSet::new(), vec![from.to_string()]);
        while let Some(n) = todo.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    todo.push(m.clone());
                }
            }
        }
        seen
    };
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for n in graph.keys() {
        if done.contains(n) || !reach(n).contains(n) {
            continue;
        }
        // The shortest way back to n, by breadth first.
        let mut cycle = Vec::new();
        let mut back: BTreeMap<String, String> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([n.clone()]);
        'search: while let Some(a) = queue.pop_front() {
            for b in graph.get(&a).into_iter().flatten() {
                if b == n {
                    let mut c = vec![n.clone(), a.clone()];
                    while let Some(p) = back.get(c.last().unwrap()) {
                        c.push(p.clone());
                    }
                    c.reverse();
                    cycle = c;
                    break 'search;
                }
                if !back.contains_key(b) && b != n {
                    back.insert(b.clone(), a.clone());
                    queue.push_back(b.clone());
                }
            }
        }
        let part: BTreeSet<String> = reach(n)
            .into_iter()
            .filter(|m| reach(m).contains(n))
            .collect();
        done.extend(part.iter().cloned());
        out.push((cycle, part));
    }
    out
}

/// Every cycle among the modules of any parent, in words.
fn cycles_in(sources: &[(ModPath, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (parent, graph) in sibling_graphs(sources) {
        let room = match parent.as_slice() {
            [k] if k == "lib" => "the library's top modules".to_string(),
            [_] => "the binary's top modules".to_string(),
            [_, rest @ ..] => format!("the modules of {}", rest.join("::")),
            [] => unreachable!(),
        };
        for (c, part) in cycles(&graph) {
            let part: Vec<String> = part.into_iter().collect();
            found.push(format!(
                "{room}: {} (the circle's modules: {})",
                c.join(" → "),
                part.join(", ")
            ));
        }
    }
    found
}

#[test]
fn modules_depend_one_way_at_every_depth() {
    let sources = modules();
    let top = sibling_graphs(&sources)[&vec!["lib".to_string()]].len();
    assert!(top >= 10, "top modules found: {top}");
    let found = cycles_in(&sources);
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}

#[test]
fn the_resolver_and_the_cycle_finder_see_what_the_code_says() {
    let m = |s: &str| -> ModPath { s.split("::").map(String::from).collect() };
    let text = "use super::{b::{X, Y}, c, Item};\nuse crate::top::{self, d::Z as W};\n\
                // super::e::f in a comment\nlet s = \"super::e::f\"; let c = '{'; let q = '\\'';\n\
                fn f<'a>() { self::g::h(); super::super::k::l(); }\n\
                mod tests { use super::*; use super::super::c::T; }";
    let (refs, inline) = references(&m("lib::p::a"), text);
    let to: Vec<String> = refs.iter().map(|(_, p)| p.join("::")).collect();
    assert_eq!(
        to,
        [
            "lib::p::b::X",
            "lib::p::b::Y",
            "lib::p::c",
            "lib::p::Item",
            "lib::top",
            "lib::top::d::Z",
            "lib::p::a::g::h",
            "lib::k::l",
            "lib::p::a",
            "lib::p::c::T",
        ]
    );
    assert_eq!(refs[9].0, m("lib::p::a::tests"));
    assert_eq!(inline, [m("lib::p::a::tests")]);
    let sources = [
        (m("lib::p"), String::new()),
        (m("lib::p::a"), "use super::b::X;".to_string()),
        (m("lib::p::b"), "use super::{c::Y, Item};".to_string()),
        (m("lib::p::c"), "use crate::p::a::Z;".to_string()),
        (m("lib::q"), "fn f() { crate::p::Item; }".to_string()),
    ];
    assert_eq!(
        cycles_in(&sources),
        ["the modules of p: a → b → c → a (the circle's modules: a, b, c)"]
    );
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    assert!(cycles(&g).is_empty());
    g.entry("c".into()).or_default().insert("a".into());
    let (cycle, part) = &cycles(&g)[0];
    assert_eq!(cycle, &["a", "b", "c", "a"]);
    assert_eq!(part.len(), 3);
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
