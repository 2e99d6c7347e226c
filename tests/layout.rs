//! The layout the one-tracer design promises (README, "Layout"), read from the
//! source files themselves: which file refers to which.
//!
//! - the book's modules never refer to the fast engine, the files in and out,
//!   the commands, or the one place that picks an engine;
//! - the fast engine depends on the book and never on the files or the commands;
//! - no file depends, through any chain of others, on itself.
//!
//! A file depends on another when its code (comments and strings aside, and its
//! own `#[cfg(test)] mod tests` aside) names a path into that file's module:
//! `crate::a::b`, `super::b`, or `b::` for a child module it declares.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

/// The modules of the book: what the chapters teach.
const BOOK: [&str; 16] = [
    "camera",
    "scene",
    "ray",
    "real",
    "sphere",
    "shade",
    "shade::shadow",
    "shade::blinn_phong",
    "shade::reflection",
    "plane",
    "aov",
    "render",
    "stages",
    "accel",
    "bvh",
    "samples",
];

/// What serves the book and that the book must not know of.
const NOT_FOR_THE_BOOK: [&str; 4] = ["fast", "io", "tools", "engine"];

/// Every module of the library in `src/` (`a::b` for `src/a/b.rs` or
/// `src/a/b/mod.rs`; the crate root as `crate`) and its file's text. (`main.rs`
/// is the binary, a crate of its own that calls the library.)
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, into: &mut BTreeMap<String, String>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, into);
            } else if path.extension().is_some_and(|e| e == "rs") && !path.ends_with("main.rs") {
                let relative = path.strip_prefix("src").unwrap().with_extension("");
                let relative = relative.to_str().unwrap().replace('\\', "/");
                let module = match relative.as_str() {
                    "lib" => "crate".to_string(),
                    r => r.trim_end_matches("/mod").replace('/', "::"),
                };
                into.insert(module, fs::read_to_string(&path).unwrap());
            }
        }
    }
    let mut modules = BTreeMap::new();
    walk(Path::new("src"), &mut modules);
    modules
}

/// `source` with comments, string and character literals blanked, and its unit
/// tests (`#[cfg(test)] mod tests { … }`, at the end of a file) cut off.
fn code(source: &str) -> String {
    let source = match source.find("#[cfg(test)]\nmod tests") {
        Some(at) => &source[..at],
        None => source,
    };
    let b = source.as_bytes();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let rest = &source[i..];
        let word_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").map_or(rest.len(), |e| e + 2);
        } else if !word_before && (rest.starts_with("r\"") || rest.starts_with("r#")) {
            let hashes = rest[1..].bytes().take_while(|&c| c == b'#').count();
            let close = format!("\"{}", "#".repeat(hashes));
            let open = 2 + hashes;
            i += open + rest[open..].find(&close).unwrap() + close.len();
            out.push_str("\"\"");
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            i = j + 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && !word_before {
            // A character literal ('x', '\n', '"'), or a lifetime ('a), left as is.
            let close = if rest[1..].starts_with('\\') {
                rest[2..].find('\'').map(|e| e + 2)
            } else {
                rest[1..]
                    .char_indices()
                    .nth(1)
                    .filter(|&(_, c)| c == '\'')
                    .map(|(k, _)| k + 1)
            };
            match close {
                Some(e) => {
                    i += e + 1;
                    out.push_str("' '");
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The paths that start at `at` in `code` (just after `crate::` or `super::`):
/// `a::b::c`, or with braces `a::{b, c::{d}}`, each as a list of segments.
fn paths_at(code: &str, at: usize) -> Vec<Vec<String>> {
    fn parse(s: &[u8], i: &mut usize, prefix: &[String], out: &mut Vec<Vec<String>>) {
        let mut path = prefix.to_vec();
        loop {
            while *i < s.len() && s[*i].is_ascii_whitespace() {
                *i += 1;
            }
            if *i < s.len() && s[*i] == b'{' {
                *i += 1;
                loop {
                    parse(s, i, &path, out);
                    while *i < s.len() && s[*i].is_ascii_whitespace() {
                        *i += 1;
                    }
                    match s.get(*i) {
                        Some(b',') => *i += 1,
                        Some(b'}') => {
                            *i += 1;
                            return;
                        }
                        _ => return,
                    }
                    while *i < s.len() && s[*i].is_ascii_whitespace() {
                        *i += 1;
                    }
                    if s.get(*i) == Some(&b'}') {
                        *i += 1;
                        return;
                    }
                }
            }
            let start = *i;
            while *i < s.len() && (s[*i].is_ascii_alphanumeric() || s[*i] == b'_') {
                *i += 1;
            }
            if start == *i {
                break;
            }
            path.push(String::from_utf8_lossy(&s[start..*i]).into_owned());
            if s[*i..].starts_with(b"::") {
                *i += 2;
            } else {
                break;
            }
        }
        out.push(path);
    }
    let mut out = Vec::new();
    parse(code.as_bytes(), &mut at.clone(), &[], &mut out);
    out
}

/// Each module and the other modules its file refers to.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let modules = modules();
    let resolve = |segments: &[String]| -> Option<String> {
        (1..=segments.len())
            .rev()
            .map(|k| segments[..k].join("::"))
            .find(|m| modules.contains_key(m))
    };
    let mut graph = BTreeMap::new();
    for (module, source) in &modules {
        let code = code(source);
        let parent: Vec<String> = match module.rsplit_once("::") {
            Some((p, _)) => p.split("::").map(String::from).collect(),
            None => Vec::new(),
        };
        let own: Vec<String> = if module == "crate" {
            Vec::new()
        } else {
            module.split("::").map(String::from).collect()
        };
        let mut starts: Vec<(usize, Vec<String>)> = Vec::new();
        let word = |at: usize| {
            at > 0 && {
                let c = code.as_bytes()[at - 1];
                c.is_ascii_alphanumeric() || c == b'_' || c == b':'
            }
        };
        for (at, _) in code.match_indices("crate::").filter(|&(at, _)| !word(at)) {
            starts.push((at + 7, Vec::new()));
        }
        for (at, _) in code.match_indices("super::").filter(|&(at, _)| !word(at)) {
            starts.push((at + 7, parent.clone()));
        }
        // Child modules declared here (`mod api;`), named by their own name.
        for line in code.lines() {
            let line = line.trim();
            let line = line.strip_prefix("pub ").unwrap_or(line);
            if let Some(child) = line.strip_prefix("mod ").and_then(|l| l.strip_suffix(';')) {
                let needle = format!("{child}::");
                for (at, _) in code.match_indices(&needle).filter(|&(at, _)| !word(at)) {
                    starts.push((at, own.clone()));
                }
            }
        }
        let mut deps = BTreeSet::new();
        for (at, base) in starts {
            for path in paths_at(&code, at) {
                let full: Vec<String> = base.iter().cloned().chain(path).collect();
                if let Some(target) = resolve(&full) {
                    if &target != module && target != "crate" {
                        deps.insert(target);
                    }
                }
            }
        }
        graph.insert(module.clone(), deps);
    }
    graph
}

fn top(module: &str) -> &str {
    module.split("::").next().unwrap()
}

#[test]
fn the_reader_finds_what_a_file_refers_to() {
    let code = code(
        "// crate::fast in a comment\nuse crate::{aov::Frame, shade::{shadow, blinn_phong::Terms}};\n\
         let s = \"crate::io\"; let c = '\"'; let d = crate::render::render(x);\n\
         #[cfg(test)]\nmod tests { use crate::tools; }",
    );
    let mut found: Vec<String> = code
        .match_indices("crate::")
        .flat_map(|(at, _)| paths_at(&code, at + 7))
        .map(|p| p.join("::"))
        .collect();
    found.sort();
    assert_eq!(
        found,
        [
            "aov::Frame",
            "render::render",
            "shade::blinn_phong::Terms",
            "shade::shadow"
        ]
    );
}

#[test]
fn the_books_modules_never_refer_to_the_fast_engine_the_files_or_the_commands() {
    let graph = graph();
    for book in BOOK {
        let deps = graph
            .get(book)
            .unwrap_or_else(|| panic!("no module {book} in src/"));
        let wrong: Vec<&String> = deps
            .iter()
            .filter(|d| NOT_FOR_THE_BOOK.contains(&top(d)))
            .collect();
        assert!(wrong.is_empty(), "the book's {book} refers to {wrong:?}");
    }
    // And the reader sees references at all: render.rs uses the sphere and the shading.
    assert!(graph["render"].contains("sphere") && graph["render"].contains("shade::shadow"));
}

#[test]
fn the_fast_engine_depends_on_the_book_and_never_on_files_or_commands() {
    let graph = graph();
    let fast: Vec<(&String, &BTreeSet<String>)> =
        graph.iter().filter(|(m, _)| top(m) == "fast").collect();
    assert!(fast.len() > 1, "no fast engine found");
    for (module, deps) in fast {
        let wrong: Vec<&String> = deps
            .iter()
            .filter(|d| ["io", "tools", "engine"].contains(&top(d)))
            .collect();
        assert!(wrong.is_empty(), "{module} refers to {wrong:?}");
    }
    assert!(
        graph["fast"].contains("render"),
        "the fast engine is built on the book's tracer"
    );
}

#[test]
fn no_file_depends_on_itself_through_others() {
    let graph = graph();
    // Depth-first search; a module met again while still on the stack closes a circle.
    fn visit<'a>(
        m: &'a str,
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        stack: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
        circles: &mut Vec<String>,
    ) {
        if let Some(k) = stack.iter().position(|&s| s == m) {
            let mut circle: Vec<&str> = stack[k..].to_vec();
            circle.push(m);
            circles.push(circle.join(" → "));
            return;
        }
        if !done.insert(m) {
            return;
        }
        stack.push(m);
        for d in &graph[m] {
            visit(d, graph, stack, done, circles);
        }
        stack.pop();
    }
    let (mut done, mut circles) = (BTreeSet::new(), Vec::new());
    for m in graph.keys() {
        visit(m, &graph, &mut Vec::new(), &mut done, &mut circles);
    }
    assert!(circles.is_empty(), "circles of files: {circles:#?}");
}
