//! The workspace's layering: inside each crate, no module imports another that imports it back,
//! directly or round a loop (a circle makes every change to one of them a change to all). Read
//! from the sources: every `crate::`, `super::` and `self::` path outside a file's test module
//! is an edge to the deepest module it names; a module's own descendants and ancestors are
//! structure, not imports, where the path only names them on the way.
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

/// The `.rs` files under `dir`, recursively.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module a file is, from its path under `src` (`a/mod.rs` and `a.rs` are both `a`).
fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Module = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        parts.pop();
    }
    parts
}

/// The paths starting `crate::`, `super::` or `self::` in `code`, as their segments.
fn paths(code: &str) -> Vec<Vec<String>> {
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut found = Vec::new();
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if !is_ident(chars[i]) || (i > 0 && (is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
            i += 1;
            continue;
        }
        let mut segments = Vec::new();
        let mut j = i;
        loop {
            let start = j;
            while j < chars.len() && is_ident(chars[j]) {
                j += 1;
            }
            segments.push(chars[start..j].iter().collect::<String>());
            if j + 2 < chars.len()
                && chars[j] == ':'
                && chars[j + 1] == ':'
                && is_ident(chars[j + 2])
            {
                j += 2;
            } else {
                break;
            }
        }
        if segments.len() > 1 && matches!(segments[0].as_str(), "crate" | "super" | "self") {
            found.push(segments);
        }
        i = j.max(i + 1);
    }
    found
}

/// The code of a file without its comments and without its test module (everything from the
/// first `#[cfg(test)]`).
fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// Each module's imports of other modules of the crate at `src`.
fn imports(src: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut files = Vec::new();
    sources(src, &mut files);
    let modules: BTreeMap<Module, PathBuf> =
        files.into_iter().map(|f| (module_of(src, &f), f)).collect();
    let mut graph = BTreeMap::new();
    for (module, file) in &modules {
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let mut targets = BTreeSet::new();
        for path in paths(&code) {
            let mut base: Module = match path[0].as_str() {
                "crate" => Vec::new(),
                "self" => module.clone(),
                _ => module[..module.len().saturating_sub(1)].to_vec(),
            };
            let mut rest = &path[1..];
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
            let mut deepest = None;
            for segment in rest {
                base.push(segment.clone());
                if modules.contains_key(&base) {
                    deepest = Some(base.clone());
                }
            }
            let Some(target) = deepest else { continue };
            let related = target.starts_with(module) || module.starts_with(&target);
            if !related {
                targets.insert(target);
            }
        }
        graph.insert(module.clone(), targets);
    }
    graph
}

/// A loop of imports in `graph`, if there is one.
fn a_circle(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Option<Vec<Module>> {
    fn visit(
        node: &Module,
        graph: &BTreeMap<Module, BTreeSet<Module>>,
        done: &mut BTreeSet<Module>,
        stack: &mut Vec<Module>,
    ) -> Option<Vec<Module>> {
        if let Some(at) = stack.iter().position(|m| m == node) {
            return Some(stack[at..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(circle) = visit(next, graph, done, stack) {
                return Some(circle);
            }
        }
        stack.pop();
        done.insert(node.clone());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|m| visit(m, graph, &mut done, &mut Vec::new()))
}

#[test]
fn no_crate_has_an_import_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let crates = ["data", "model", "eval", "render"].map(|c| format!("crates/deepbrdf-{c}/src"));
    for src in crates.iter().map(String::as_str).chain(["crates/experiments/src", "python/src"]) {
        let graph = imports(&root.join(src));
        assert!(graph.len() > 3, "{src}: no modules read");
        let circle = a_circle(&graph).map(|c| c.iter().map(|m| m.join("::")).collect::<Vec<_>>());
        assert_eq!(circle, None, "{src}: these modules import each other in a circle");
    }
}

#[test]
fn a_circle_is_found() {
    let m = |s: &str| s.split("::").map(str::to_string).collect::<Module>();
    let mut graph = BTreeMap::new();
    graph.insert(m("a"), BTreeSet::from([m("b")]));
    graph.insert(m("b"), BTreeSet::from([m("c::d")]));
    graph.insert(m("c::d"), BTreeSet::from([m("a")]));
    assert_eq!(a_circle(&graph).map(|c| c.len()), Some(3));
    graph.insert(m("c::d"), BTreeSet::new());
    assert_eq!(a_circle(&graph), None);
    let code = "use crate::a::{b, c};\nfn f() { super::super::x::y(); self::z::w }";
    let found = paths(code);
    assert_eq!(found[0], ["crate", "a"]);
    assert_eq!(found[1], ["super", "super", "x", "y"]);
    assert_eq!(found[2], ["self", "z", "w"]);
}
