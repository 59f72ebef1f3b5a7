//! Every citation of a doc section in the code (a path under `docs/`, then `§` and the section's name, in
//! `src/`, `python/src/`, `tests/`, `benches/` and `examples/`) names a file that exists and a section it has: a heading (`## 8. Near-specular scatter`,
//! by its words, its number or the words before a parenthesis) or a paragraph's bold lead (`**Bounded
//! work.**`). A citation is read from the `§` to the first `)`, `(`, `]`, `,`, `;`, `:`, backquote, quote or
//! line end; it matches a section whose name it starts with (then a word ends), or that starts with it (a
//! comment may wrap a long name).
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|e| e == ext) {
            out.push(p);
        }
    }
}

/// The names a doc's sections go by.
fn sections(text: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in text.lines() {
        if line.starts_with('#') {
            let h = line.trim_start_matches('#').trim().replace('`', "");
            names.insert(h.split(" (").next().unwrap_or("").to_string());
            // `5.2 Title` or `8. Title`: the number and the title each name it.
            let number: String = h.chars().take_while(|c| c.is_ascii_digit() || *c == '.').collect();
            if !number.is_empty() && h[number.len()..].starts_with(' ') {
                names.insert(number.trim_end_matches('.').to_string());
                let title = h[number.len()..].trim();
                names.insert(title.split(" (").next().unwrap_or("").to_string());
                names.insert(title.to_string());
            }
            names.insert(h);
        }
        let mut rest = line;
        while let Some(at) = rest.find("**") {
            let after = &rest[at + 2..];
            let Some(end) = after.find("**") else { break };
            let lead = &after[..end];
            if let Some(name) = lead.strip_suffix('.').or_else(|| lead.strip_suffix(':')) {
                names.insert(name.replace('`', ""));
            }
            rest = &after[end + 2..];
        }
    }
    names.retain(|n| !n.is_empty());
    names
}

fn cites(cited: &str, name: &str) -> bool {
    (cited.starts_with(name) && !cited[name.len()..].starts_with(|c: char| c.is_alphanumeric()))
        || name.starts_with(cited)
}

/// Every `(doc, section)` cited in `text`.
fn citations(text: &str) -> Vec<(String, String)> {
    let mut out = vec![];
    let mut rest = text;
    while let Some(at) = rest.find("docs/") {
        let tail = &rest[at..];
        rest = &rest[at + 5..];
        let Some(md) = tail.find(".md") else { break };
        let doc = &tail[..md + 3];
        if !doc[5..].chars().all(|c| c.is_alphanumeric() || "_-./".contains(c)) {
            continue;
        }
        let after = tail[md + 3..].trim_start_matches('`').trim_start();
        let Some(section) = after.strip_prefix('§') else { continue };
        let end = section.find(|c: char| ")(],;:`\"\n".contains(c)).unwrap_or(section.len());
        let cited = section[..end].trim().trim_end_matches('.').trim().to_string();
        out.push((doc.to_string(), cited));
    }
    out
}

#[test]
fn every_cited_doc_section_exists() {
    let mut docs: Vec<PathBuf> = vec![];
    files(Path::new("docs"), "md", &mut docs);
    let names: BTreeMap<String, BTreeSet<String>> = docs
        .iter()
        .map(|d| (d.to_string_lossy().replace('\\', "/"), sections(&std::fs::read_to_string(d).unwrap())))
        .collect();
    let mut code = vec![];
    for dir in ["src", "python/src", "tests", "benches", "examples"] {
        files(Path::new(dir), "rs", &mut code);
    }
    let (mut checked, mut broken) = (0, vec![]);
    for f in &code {
        for (doc, cited) in citations(&std::fs::read_to_string(f).unwrap()) {
            checked += 1;
            let ok = match names.get(&doc) {
                None => false,
                Some(n) => cited.is_empty() || n.iter().any(|name| cites(&cited, name)),
            };
            if !ok {
                broken.push(format!("{}: {doc} §{cited}", f.display()));
            }
        }
    }
    // A check that checked nothing does not pass.
    assert!(checked > 200, "only {checked} citations found: is the reader broken?");
    assert!(broken.is_empty(), "citations of sections that do not exist:\n{}", broken.join("\n"));
}

#[test]
fn the_reader_finds_sections_and_citations() {
    let s = sections("# T\n## 8. Near-specular scatter (`scatter.rs`)\n**Bounded work.** Two limits\n");
    assert!(s.contains("Near-specular scatter") && s.contains("8") && s.contains("Bounded work"), "{s:?}");
    let c = citations("see docs/accuracy.md §5.2: N₁ and `docs/serve.md` §Safety) or docs/model.md.");
    assert_eq!(c, [("docs/accuracy.md".into(), "5.2".into()), ("docs/serve.md".into(), "Safety".into())]);
    assert!(cites("Sheets has the full table", "Sheets"));
    assert!(!cites("Sheetsy", "Sheets"));
    assert!(cites("Goodness of", "Goodness of fit"));
    assert!(!cites("Sphere readings", "Safety"));
}
