//! Tidy checks of the source tree (after rust-analyzer's tidy test): every Rust file opens with
//! a `//!` line; dependencies between our crates point the way docs/architecture.md draws them;
//! nothing prints outside the driver and the xtask; the core crate reads and writes no file; no
//! module of a crate imports another that imports it back.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n == "target" || n == "fixtures") {
                continue;
            }
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn every_file_opens_with_a_module_doc() {
    let mut files = vec![];
    for d in ["crates", "xtask", "tests"] {
        rust_files(&root().join(d), &mut files);
    }
    assert!(files.len() > 20);
    let bad: Vec<_> = files
        .iter()
        .filter(|f| !std::fs::read_to_string(f).unwrap().starts_with("//!"))
        .collect();
    assert!(bad.is_empty(), "files without a leading //! line: {bad:?}");
}

/// The library crates (the application, `driver`, aside).
const LIBRARIES: [&str; 8] = [
    "mesh",
    "fe-assembly",
    "linalg",
    "contact",
    "problem",
    "petsc-sys",
    "petsc",
    "distributed",
];

#[test]
fn crate_dependencies_point_one_way() {
    // crate -> the crates of ours it may depend on (normal dependencies)
    let allowed: &[(&str, &[&str])] = &[
        ("mesh", &[]),
        ("linalg", &[]),
        ("contact", &[]),
        ("fe-assembly", &["mesh"]),
        ("problem", &["mesh", "fe-assembly", "linalg", "contact"]),
        // the PETSc layer knows no finite elements, as linalg does not
        ("petsc-sys", &[]),
        ("petsc", &["petsc-sys"]),
        ("distributed", &["mesh", "fe-assembly", "contact", "problem", "petsc"]),
        ("driver", &["mesh", "contact", "problem", "distributed", "petsc"]),
        // the Python package is a layer over the application, as the command line is
        ("python", &["mesh", "fe-assembly", "contact", "problem", "driver"]),
    ];
    for (krate, may) in allowed {
        let manifest = std::fs::read_to_string(root().join("crates").join(krate).join("Cargo.toml")).unwrap();
        let deps = manifest
            .split("[dependencies]")
            .nth(1)
            .unwrap_or("")
            .split("\n[")
            .next()
            .unwrap();
        for &other in LIBRARIES.iter().chain(&["driver"]) {
            let uses = deps.lines().any(|l| {
                l.trim_start().starts_with(&format!("{other}.")) || l.trim_start().starts_with(&format!("{other} "))
            });
            if uses {
                assert!(
                    may.contains(&other),
                    "`{krate}` depends on `{other}`, which the architecture forbids"
                );
            }
        }
    }
}

#[test]
fn no_printing_outside_the_driver() {
    let mut files = vec![];
    for k in LIBRARIES {
        rust_files(&root().join("crates").join(k).join("src"), &mut files);
    }
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for mac in ["println!", "eprintln!", "print!(", "dbg!("] {
            assert!(
                !text.contains(mac),
                "{} uses {mac}: libraries report through return values",
                f.display()
            );
        }
    }
}

#[test]
fn the_core_crate_does_no_file_io() {
    let mut files = vec![];
    rust_files(&root().join("crates/problem/src"), &mut files);
    assert!(files.len() > 5);
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for io in ["std::fs", "File::", "std::io", "std::env", "read_msh("] {
            assert!(
                !text.contains(io),
                "{} uses {io}: the problem crate does no IO (the application reads and writes)",
                f.display()
            );
        }
    }
}

/// The top-level module of the crate a file belongs to (`crates/X/src/a/b.rs` -> `a`; `lib.rs`
/// and `main.rs` -> the crate root, left out).
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_string_lossy().into_owned();
    let name = first.trim_end_matches(".rs").to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// The first segments of the paths after each `crate::` in `text`: `crate::a::b` gives `a`,
/// `crate::{a::b, c}` gives `a` and `c`.
fn crate_paths(text: &str) -> Vec<String> {
    let ident = |s: &str| -> String { s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    let mut out = vec![];
    for (at, _) in text.match_indices("crate::") {
        let rest = text[at + 7..].trim_start();
        if let Some(group) = rest.strip_prefix('{') {
            // the top-level items of the group
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.push(ident(group[start..].trim_start()));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.push(ident(group[start..].trim_start()));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            out.push(ident(rest));
        }
    }
    out
}

#[test]
fn no_import_cycle_between_the_modules_of_a_crate() {
    for krate in ["mesh", "fe-assembly", "linalg", "contact", "problem", "driver"] {
        let src = root().join("crates").join(krate).join("src");
        let mut files = vec![];
        rust_files(&src, &mut files);
        let mut modules: Vec<String> = files.iter().filter_map(|f| top_module(&src, f)).collect();
        modules.sort();
        modules.dedup();
        // edges between top-level modules (a module's own sub-modules are part of it)
        let mut edges: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> = Default::default();
        for f in &files {
            let Some(from) = top_module(&src, f) else { continue };
            let text = std::fs::read_to_string(f).unwrap();
            for to in crate_paths(&text) {
                if to != from && modules.contains(&to) {
                    edges.entry(from.clone()).or_default().insert(to);
                }
            }
        }
        // a depth-first search for a back edge
        fn visit(
            m: &str,
            edges: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
            path: &mut Vec<String>,
            done: &mut std::collections::BTreeSet<String>,
        ) -> Option<Vec<String>> {
            if let Some(at) = path.iter().position(|p| p == m) {
                let mut cycle = path[at..].to_vec();
                cycle.push(m.to_string());
                return Some(cycle);
            }
            if done.contains(m) {
                return None;
            }
            path.push(m.to_string());
            for next in edges.get(m).into_iter().flatten() {
                if let Some(c) = visit(next, edges, path, done) {
                    return Some(c);
                }
            }
            path.pop();
            done.insert(m.to_string());
            None
        }
        let mut done = Default::default();
        for m in &modules {
            if let Some(cycle) = visit(m, &edges, &mut vec![], &mut done) {
                panic!(
                    "crate `{krate}`: an import cycle between modules: {}",
                    cycle.join(" -> ")
                );
            }
        }
    }
}
