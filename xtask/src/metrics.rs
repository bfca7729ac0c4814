//! `cargo xtask metrics`: the size of the code as the design reviews measure it: lines of Rust
//! per crate (sources, and everything with tests and examples), the longest functions with
//! their lengths, and two smells counted outside tests: string comparisons (`== "…"`,
//! `.as_str() {`, `starts_with("…")`, …) and reads of a JSON value by key (`["key"]`).
//!
//! Function lengths come from a small lexer that skips comments, strings and character
//! literals, so braces inside them are not counted; a function runs from its `fn` line to the
//! line of its closing brace.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "target") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The source with comments, strings and character literals blanked out (newlines kept), so
/// that braces and keywords can be counted on what is left.
fn code_only(src: &str) -> String {
    let b: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !prev_is_ident(&b, i) {
            // a raw string r"…" or r#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            while j < b.len() {
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push('"');
            for &x in &b[i + 1..j.min(b.len()) - 1] {
                out.push(blank(x));
            }
            out.push('"');
            i = j;
        } else if c == '"' {
            out.push('"');
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            out.push('"');
            i += 1;
        } else if c == '\'' {
            // a character literal ('x', '\n', '{'), or a lifetime ('a)
            if next == Some('\\') {
                let mut j = i + 2;
                while j < b.len() && b[j] != '\'' {
                    j += 1;
                }
                out.push_str(&" ".repeat(j + 1 - i));
                i = j + 1;
            } else if b.get(i + 2) == Some(&'\'') {
                out.push_str("   ");
                i += 3;
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

/// `(name, first line, length in lines)` of every function with a body.
pub fn functions(src: &str) -> Vec<(String, usize, usize)> {
    let code = code_only(src);
    let lines: Vec<&str> = code.lines().collect();
    let mut out = vec![];
    for (start, line) in lines.iter().enumerate() {
        let Some(pos) = find_fn(line) else { continue };
        let name: String = line[pos + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // the body: the first `{` before any `;` at depth 0 of parentheses, then its match
        let mut depth = 0i64;
        let mut paren = 0i64;
        let mut opened = false;
        'scan: for (k, l) in lines[start..].iter().enumerate() {
            let from = if k == 0 { pos } else { 0 };
            for ch in l[from..].chars() {
                match ch {
                    '(' | '[' | '<' if !opened => paren += i64::from(ch == '('),
                    ')' if !opened => paren -= 1,
                    ';' if !opened && paren == 0 => break 'scan,
                    '{' => {
                        opened = true;
                        depth += 1;
                    }
                    '}' if opened => {
                        depth -= 1;
                        if depth == 0 {
                            out.push((name.clone(), start + 1, k + 1));
                            break 'scan;
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    out
}

/// The position of an `fn` keyword that starts a function item on the line.
fn find_fn(line: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(p) = line[from..].find("fn ") {
        let at = from + p;
        let before = line[..at].chars().last();
        if before.is_none_or(|c| !(c.is_alphanumeric() || c == '_')) {
            let rest = &line[at + 3..];
            if rest.chars().next().is_some_and(|c| c.is_alphabetic() || c == '_') {
                return Some(at);
            }
        }
        from = at + 3;
    }
    None
}

/// The part of a file before its `#[cfg(test)]` module (tests are not counted as smells).
fn non_test(code: &str) -> &str {
    code.find("#[cfg(test)]").map_or(code, |p| &code[..p])
}

/// String comparisons on choices: lines of non-test code comparing against a literal string.
fn string_comparisons(src: &str) -> Vec<String> {
    let patterns = [
        "== \"",
        "!= \"",
        ".as_str() {",
        ".starts_with(\"",
        ".ends_with(\"",
        "== &\"",
    ];
    non_test(src)
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .filter(|l| patterns.iter().any(|p| l.contains(p)))
        .map(|l| l.trim().to_string())
        .collect()
}

/// Reads of a JSON value by key: `["key"]` in non-test code.
fn json_reads(src: &str) -> usize {
    let code = non_test(src);
    code.match_indices("[\"")
        .filter(|(p, _)| {
            let rest = &code[p + 2..];
            let key: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            !key.is_empty() && rest[key.len()..].starts_with("\"]")
        })
        .count()
}

/// Prints the metrics of the workspace at `root`.
pub fn run(root: &Path) -> bool {
    let mut crates: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    crates.sort();
    crates.push(root.join("xtask"));
    crates.push(root.join("tests"));
    let mut all_fns = vec![];
    let (mut total_src, mut total_all) = (0, 0);
    println!("lines of Rust per crate (src/ | with tests and examples):");
    for c in &crates {
        let name = c
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let (mut src_files, mut all_files) = (vec![], vec![]);
        rust_files(&c.join("src"), &mut src_files);
        rust_files(c, &mut all_files);
        let count = |files: &[PathBuf]| -> usize {
            files
                .iter()
                .map(|f| std::fs::read_to_string(f).map_or(0, |s| s.lines().count()))
                .sum()
        };
        let (s, a) = (count(&src_files), count(&all_files));
        total_src += s;
        total_all += a;
        println!("  {name:14} {s:6} | {a:6}");
        let mut comparisons = vec![];
        let mut reads = 0;
        for f in &src_files {
            let Ok(text) = std::fs::read_to_string(f) else { continue };
            let rel = f.strip_prefix(root).unwrap_or(f).display().to_string();
            for (fname, line, len) in functions(&text) {
                all_fns.push((len, format!("{rel}:{line} {fname}")));
            }
            comparisons.extend(string_comparisons(&code_only_keep_strings(&text)));
            reads += json_reads(&text);
        }
        if !comparisons.is_empty() || reads > 0 {
            println!(
                "  {:14} string comparisons {}, JSON reads by key {reads}",
                "",
                comparisons.len()
            );
            for l in &comparisons {
                println!("  {:16} {l}", "");
            }
        }
    }
    println!("  {:14} {total_src:6} | {total_all:6}", "total");
    all_fns.sort_by_key(|f| std::cmp::Reverse(f.0));
    println!("\nthe ten longest functions in src/ (lines):");
    for (len, at) in all_fns.iter().take(10) {
        println!("  {len:4}  {at}");
    }
    true
}

/// The source with comments removed but strings kept (the comparisons are with literals).
fn code_only_keep_strings(src: &str) -> String {
    src.lines()
        .map(|l| match l.find("//") {
            Some(p) if !l[..p].contains('"') => &l[..p],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}
