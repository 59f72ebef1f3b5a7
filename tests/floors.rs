//! The floors of the house (docs/architecture.md §Floors): no import circle between the files of `src/`.
//!
//! This test reads every `src/**/*.rs` as text, the way `tests/golden.rs` guards the bits: it strips comments,
//! string and character literals and `#[cfg(test)]` modules, collects every path the code names through
//! `crate::`, `super::`, `self::` or a child module (in `use` trees and inline), and resolves each to the file
//! that defines the item. A `pub use` is a re-export, not a dependency: resolving a path through a folder's
//! `mod.rs` (or the crate root) follows the re-export to the file that defines the item, and the re-export line
//! itself adds no edge. An edge A → B means that code in A names an item of B. The test fails on every cycle
//! of that graph and prints it, file by file.
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source file of the crate: its module path (`["instrument", "plan"]`) and its code with comments, literals
/// and test modules removed.
struct File {
    path: String,
    module: Vec<String>,
    code: String,
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `src/a/b.rs` → `[a, b]`; `src/a/mod.rs` → `[a]`; `src/lib.rs` → `[]`. `src/main.rs` (the binary) is left out.
fn module_of(rel: &Path) -> Option<Vec<String>> {
    let mut parts: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
    let last = parts.pop()?;
    let stem = last.strip_suffix(".rs")?;
    match stem {
        "main" if parts.is_empty() => None,
        "lib" if parts.is_empty() => Some(parts),
        "mod" => Some(parts),
        s => {
            parts.push(s.to_string());
            Some(parts)
        }
    }
}

/// The code without comments and without the contents of string and character literals (so that a message
/// or a doc that names `crate::x` is not an import).
fn strip(src: &str) -> String {
    let b: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c == 'r'
            && (next == Some('"') || (next == Some('#') && !prev_is_ident(&b, i)))
            && !prev_is_ident(&b, i)
        {
            // Raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == '#' {
                hashes += 1;
                j += 1;
            }
            if j < b.len() && b[j] == '"' {
                j += 1;
                'raw: while j < b.len() {
                    if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                        j += 1 + hashes;
                        break 'raw;
                    }
                    j += 1;
                }
                out.push_str("\"\"");
                i = j;
            } else {
                out.push(c);
                i += 1;
            }
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{…}') or a lifetime ('a): only the literal is skipped.
            if next == Some('\\') {
                let mut j = i + 2;
                while j < b.len() && b[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
                out.push_str("' '");
            } else if b.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push(c);
                i += 1;
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn prev_is_ident(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// Removes every `#[cfg(test)]` item (tests travel with the code they test and are not part of the floors). A
/// `#[cfg(doc)]` import stays: it is an import like any other, and a doc link that must not make one names its
/// target by path instead (`[`X`](super::X)`).
fn drop_test_items(code: &str) -> String {
    let mut out = code.to_string();
    while let Some(at) = out.find("#[cfg(test)]") {
        let rest = &out[at..];
        let end = match (rest.find('{'), rest.find(';')) {
            (Some(brace), semi) if semi.is_none_or(|s| brace < s) => {
                let mut depth = 0;
                let mut end = rest.len();
                for (k, ch) in rest[brace..].char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = brace + k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                end
            }
            (_, Some(semi)) => semi + 1,
            _ => rest.len(),
        };
        out.replace_range(at..at + end, " ");
    }
    out
}

/// A `use` tree expanded into its paths (`a::{b, c::d as e}` → `a::b`, `a::c::d`), each with its last segment.
fn expand_use(tree: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    if tree.is_empty() {
        return;
    }
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = split_path(&tree[..open]);
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let mut base = prefix.to_vec();
        base.extend(head);
        let mut depth = 0;
        let mut start = 0;
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_use(&inner[start..k], &base, out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        expand_use(&inner[start..], &base, out);
    } else {
        let path_part = tree.split(" as ").next().unwrap_or(tree);
        let mut p = prefix.to_vec();
        p.extend(split_path(path_part));
        out.push(p);
    }
}

fn split_path(s: &str) -> Vec<String> {
    s.split("::").map(|x| x.trim().to_string()).filter(|x| !x.is_empty()).collect()
}

/// The statements `[pub[(…)]] use …;` of a file: (is a re-export, the expanded paths), and the code with
/// them removed.
/// A `use` statement: whether it is a re-export, and its expanded paths.
type Use = (bool, Vec<Vec<String>>);

fn use_statements(code: &str) -> (Vec<Use>, String) {
    let mut uses = Vec::new();
    let mut rest = String::with_capacity(code.len());
    let bytes = code.as_bytes();
    let mut i = 0;
    while i < code.len() {
        let at_word = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if at_word && code[i..].starts_with("use ") {
            let end = code[i..].find(';').map_or(code.len(), |e| i + e);
            let tree = &code[i + 4..end];
            // A `pub`, `pub(crate)` or `pub(super)` just before: a re-export.
            let before = rest.trim_end();
            let public = before.ends_with("pub")
                || (before.ends_with(')')
                    && before
                        .rfind("pub(")
                        .is_some_and(|p| before[p..].find(')').map(|q| p + q + 1) == Some(before.len())));
            let mut paths = Vec::new();
            expand_use(tree, &[], &mut paths);
            uses.push((public, paths));
            i = end + 1;
        } else {
            let ch = code[i..].chars().next().unwrap();
            rest.push(ch);
            i += ch.len_utf8();
        }
    }
    (uses, rest)
}

/// Inline paths in code: `crate::a::b`, `super::x`, `self::y`, and `child::z` for the file's child modules.
fn inline_paths(code: &str, children: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let heads: Vec<String> = ["crate", "super", "self"]
        .iter()
        .map(|h| h.to_string())
        .chain(children.iter().cloned())
        .map(|h| h + "::")
        .collect();
    for head in &heads {
        let mut from = 0;
        while let Some(k) = code[from..].find(head) {
            let at = from + k;
            from = at + head.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_' || bytes[at - 1] == b':') {
                continue;
            }
            let mut end = at;
            while end < code.len() {
                let c = bytes[end];
                if c.is_ascii_alphanumeric() || c == b'_' || c == b':' {
                    end += 1;
                } else {
                    break;
                }
            }
            out.push(split_path(&code[at..end]));
        }
    }
    out
}

struct Crate {
    files: Vec<File>,
    by_module: BTreeMap<Vec<String>, usize>,
    /// Per file: its `pub use` re-exports, name → absolute path of the target; and its glob re-exports.
    reexports: Vec<BTreeMap<String, Vec<String>>>,
    globs: Vec<Vec<Vec<String>>>,
    uses: Vec<Vec<Use>>,
    body: Vec<String>,
}

impl Crate {
    fn load() -> Crate {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut paths = Vec::new();
        rust_files(&root, &mut paths);
        let mut files = Vec::new();
        for p in paths {
            let rel = p.strip_prefix(&root).unwrap();
            let Some(module) = module_of(rel) else { continue };
            let code = drop_test_items(&strip(&std::fs::read_to_string(&p).unwrap()));
            files.push(File { path: format!("src/{}", rel.display()), module, code });
        }
        let by_module = files.iter().enumerate().map(|(i, f)| (f.module.clone(), i)).collect();
        let mut c = Crate { files, by_module, reexports: vec![], globs: vec![], uses: vec![], body: vec![] };
        for i in 0..c.files.len() {
            let (uses, body) = use_statements(&c.files[i].code);
            let mut names = BTreeMap::new();
            let mut globs = Vec::new();
            for (public, paths) in &uses {
                if !public {
                    continue;
                }
                for p in paths {
                    let abs = c.absolute(i, p);
                    match p.last().map(String::as_str) {
                        Some("*") => globs.push(abs[..abs.len() - 1].to_vec()),
                        Some(name) => {
                            names.insert(name.to_string(), abs);
                        }
                        None => {}
                    }
                }
            }
            c.reexports.push(names);
            c.globs.push(globs);
            c.uses.push(uses);
            c.body.push(body);
        }
        c
    }

    /// A path as written in file `i`, made absolute from the crate root.
    fn absolute(&self, i: usize, p: &[String]) -> Vec<String> {
        let here = &self.files[i].module;
        let mut p = p.to_vec();
        let mut base: Vec<String> = match p.first().map(String::as_str) {
            Some("crate") => {
                p.remove(0);
                vec![]
            }
            Some("self") => {
                p.remove(0);
                here.clone()
            }
            Some("super") => {
                let mut b = here.clone();
                while p.first().map(String::as_str) == Some("super") {
                    p.remove(0);
                    b.pop();
                }
                b
            }
            Some(first) => {
                // A child module named without `self::` (edition 2018+), else an outside crate.
                let mut child = here.clone();
                child.push(first.to_string());
                if self.by_module.contains_key(&child) {
                    here.clone()
                } else {
                    return vec![];
                }
            }
            None => return vec![],
        };
        base.extend(p);
        base
    }

    /// The file that defines what an absolute path names, following `pub use` re-exports.
    fn resolve(&self, abs: &[String], depth: usize) -> Option<usize> {
        if depth > 16 {
            return None;
        }
        // The longest prefix that is a module with a file of its own.
        let mut k = abs.len();
        while k > 0 && !self.by_module.contains_key(&abs[..k]) {
            k -= 1;
        }
        let file = *self.by_module.get(&abs[..k])?;
        let Some(name) = abs.get(k) else { return Some(file) };
        if let Some(target) = self.reexports[file].get(name) {
            let mut t = target.clone();
            t.extend_from_slice(&abs[k + 1..]);
            return self.resolve(&t, depth + 1).or(Some(file));
        }
        for g in &self.globs[file] {
            let mut t = g.clone();
            t.extend_from_slice(&abs[k..]);
            if let Some(f) = self.resolve(&t, depth + 1) {
                if f != file && self.defines(f, name) {
                    return Some(f);
                }
            }
        }
        Some(file)
    }

    fn defines(&self, f: usize, name: &str) -> bool {
        let code = &self.body[f];
        ["fn ", "struct ", "enum ", "trait ", "type ", "const ", "static ", "mod "].iter().any(|kw| {
            code.match_indices(&format!("{kw}{name}")).any(|(at, _)| {
                let after = code[at + kw.len() + name.len()..].chars().next();
                !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
            })
        }) || self.reexports[f].contains_key(name)
    }

    /// Edges A → B with one example path each.
    fn edges(&self) -> BTreeMap<(usize, usize), String> {
        let mut edges = BTreeMap::new();
        for i in 0..self.files.len() {
            let mut paths: Vec<Vec<String>> = Vec::new();
            for (public, ps) in &self.uses[i] {
                for p in ps {
                    // A re-export is a dependency only where the file's own code uses the name it brings in.
                    let used = |name: &str| {
                        self.body[i].match_indices(name).any(|(at, _)| {
                            let before = self.body[i][..at].chars().next_back();
                            let after = self.body[i][at + name.len()..].chars().next();
                            let ident = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
                            !ident(before) && !ident(after)
                        })
                    };
                    if !public || p.last().is_some_and(|n| n != "*" && used(n)) {
                        paths.push(p.clone());
                    }
                }
            }
            let here = &self.files[i].module;
            let children: Vec<String> = self
                .by_module
                .keys()
                .filter(|m| m.len() == here.len() + 1 && m.starts_with(here))
                .map(|m| m[here.len()].clone())
                .collect();
            paths.extend(inline_paths(&self.body[i], &children));
            for p in paths {
                let abs = self.absolute(i, &p);
                if abs.is_empty() && p.first().map(String::as_str) != Some("crate") {
                    continue;
                }
                let abs: Vec<String> = abs.into_iter().filter(|s| s != "*").collect();
                if let Some(j) = self.resolve(&abs, 0) {
                    if j != i {
                        edges.entry((i, j)).or_insert_with(|| p.join("::"));
                    }
                }
            }
        }
        edges
    }
}

/// Every elementary cycle's strongly connected component (Tarjan), as file lists.
fn components(n: usize, edges: &BTreeMap<(usize, usize), String>) -> Vec<Vec<usize>> {
    let mut adj = vec![Vec::new(); n];
    for &(a, b) in edges.keys() {
        adj[a].push(b);
    }
    struct T<'a> {
        adj: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(t: &mut T, v: usize) {
        t.index[v] = Some(t.next);
        t.low[v] = t.next;
        t.next += 1;
        t.stack.push(v);
        t.on[v] = true;
        for &w in &t.adj[v].clone() {
            if t.index[w].is_none() {
                visit(t, w);
                t.low[v] = t.low[v].min(t.low[w]);
            } else if t.on[w] {
                t.low[v] = t.low[v].min(t.index[w].unwrap());
            }
        }
        if Some(t.low[v]) == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t =
        T { adj: &adj, index: vec![None; n], low: vec![0; n], on: vec![false; n], stack: vec![], next: 0, out: vec![] };
    for v in 0..n {
        if t.index[v].is_none() {
            visit(&mut t, v);
        }
    }
    t.out
}

#[test]
fn no_import_circle_between_the_files_of_src() {
    let c = Crate::load();
    assert!(c.files.len() > 50, "the test read {} files of src/: is it looking in the right place?", c.files.len());
    let edges = c.edges();
    assert!(edges.len() > 100, "only {} import edges found: the parser is broken", edges.len());
    let comps = components(c.files.len(), &edges);
    let mut report = String::new();
    for comp in &comps {
        let set: BTreeSet<usize> = comp.iter().copied().collect();
        report.push_str("circle:\n");
        for (&(a, b), example) in &edges {
            if set.contains(&a) && set.contains(&b) {
                report.push_str(&format!("  {} → {}  (`{}`)\n", c.files[a].path, c.files[b].path, example));
            }
        }
    }
    assert!(comps.is_empty(), "{} import circle(s) between files of src/:\n{report}", comps.len());
}

/// The parser itself: a known edge is found, and a path in a comment or a string is not one.
#[test]
fn the_import_parser_sees_uses_and_ignores_comments_and_strings() {
    let code =
        strip("use crate::a::{b, c::d as e};\n// use crate::z;\nlet s = \"crate::y\"; let t = 'x'; crate::f::g();\n");
    let (uses, body) = use_statements(&code);
    assert_eq!(uses.len(), 1);
    assert_eq!(uses[0].1, vec![split_path("crate::a::b"), split_path("crate::a::c::d")]);
    assert_eq!(inline_paths(&body, &[]), vec![split_path("crate::f::g")]);
    assert_eq!(inline_paths("x = kid::run();", &["kid".to_string()]), vec![split_path("kid::run")]);
    let tested = drop_test_items("fn a() {}\n#[cfg(test)]\nmod tests { use crate::x; fn b() { {} } }\nfn c() {}");
    assert!(!tested.contains("crate::x") && tested.contains("fn c()"));
    let (uses, _) = use_statements("pub use child::Thing;\npub(crate) use other::X;");
    assert!(uses.iter().all(|(public, _)| *public));
}
