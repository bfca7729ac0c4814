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
const LIBRARIES: [&str; 9] = [
    "mesh",
    "fe-assembly",
    "linalg",
    "contact",
    "problem",
    "files",
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
        (
            "distributed",
            &["mesh", "fe-assembly", "linalg", "contact", "problem", "petsc"],
        ),
        // the files of a run (scenes, meshes, outputs) over the core, for every user of it
        ("files", &["mesh", "contact", "problem"]),
        (
            "driver",
            &["mesh", "contact", "problem", "files", "distributed", "petsc"],
        ),
        // the Python package is a layer over the core and its files, as the command line is
        // (and, as it does, asks the PETSc backend what it solves); not over the command line
        (
            "python",
            &["mesh", "fe-assembly", "contact", "problem", "files", "distributed"],
        ),
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

/// The core's public surface is deliberate: the scene, the plan, the run and its solution,
/// the report, the errors and the reporter at its root, and two public modules, the report's
/// types and what a backend implements.
#[test]
fn the_core_crate_has_two_public_modules() {
    let lib = std::fs::read_to_string(root().join("crates/problem/src/lib.rs")).unwrap();
    let public: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|m| m.trim_end_matches(';'))
        .collect();
    assert_eq!(public, ["backend", "report"], "problem's public modules");
}

/// The scene's validation knows no backend: what a backend does not solve is its own
/// `Backend::supports` (the PETSc backend's in `distributed::supports`), so that a scene is
/// valid or not whatever solves it.
#[test]
fn the_validation_names_no_backend() {
    let path = root().join("crates/problem/src/scene/validate.rs");
    let text = std::fs::read_to_string(&path).unwrap().to_lowercase();
    for name in BACKEND_NAMES.iter().chain(&["backend"]) {
        assert!(
            !text.contains(name),
            "{} names `{name}`: a backend's limits are its Backend::supports",
            path.display()
        );
    }
}

/// The backends' names and their libraries', lower-cased.
const BACKEND_NAMES: [&str; 5] = ["petsc", "faer", "sharedmemory", "shared_memory", "distributedmemory"];

/// The run, the load path, the capacitance, the outer unknowns and the bed's fixed point are
/// written once for every backend: outside their tests they call a `Backend` and name none (a
/// backend's own section of the report, `petsc`, is carried through as data).
/// A static scene is a path of one instant: one trait a backend implements, whose per-instant
/// steps every run takes, and no second run a backend could be handed (a `run_path`) or a
/// second trait for paths.
#[test]
fn a_static_run_and_a_path_are_one_loop() {
    let text = std::fs::read_to_string(root().join("crates/problem/src/backend.rs")).unwrap();
    let traits = text.matches("pub trait ").count();
    assert_eq!(
        traits, 1,
        "crates/problem/src/backend.rs defines {traits} traits: one Backend"
    );
    for second in ["fn run_path", "fn solve_instant", "PathBackend"] {
        assert!(
            !text.contains(second),
            "crates/problem/src/backend.rs has `{second}`: a second way through the run"
        );
    }
}

#[test]
fn the_run_names_no_backend() {
    for file in ["run.rs", "path.rs", "capacitance.rs", "outer.rs", "bed.rs"] {
        let path = root().join("crates/problem/src").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let code = text.split("#[cfg(test)]").next().unwrap().to_lowercase();
        for name in [
            "faer",
            "sharedmemory",
            "shared_memory",
            "distributedmemory",
            "backendchoice::",
        ] {
            assert!(
                !code.contains(name),
                "{} names `{name}`: the run is written once for every backend",
                path.display()
            );
        }
    }
}

/// A scene error is the validation's verdict on the scene's own values: every other failure
/// has its kind (`SetupError` for data that do not fit the mesh, `NoSolution`, `Unsupported`,
/// ...), so a `SceneError` is built in `problem/src/scene/` alone.
#[test]
fn scene_errors_are_built_by_the_validation_only() {
    let mut files = vec![];
    for k in LIBRARIES.iter().chain(&["driver", "python"]) {
        rust_files(&root().join("crates").join(k).join("src"), &mut files);
    }
    let scene = root().join("crates/problem/src/scene");
    for f in files.iter().filter(|f| !f.starts_with(&scene)) {
        let text = std::fs::read_to_string(f).unwrap();
        for built in ["SceneError::new(", "SceneError {"] {
            assert!(
                !text.contains(built),
                "{} builds a SceneError (`{built}`): only the scene's validation does",
                f.display()
            );
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

/// The module path of a file of a crate's `src`: `a/b.rs` -> `[a, b]`, `a/mod.rs` -> `[a]`,
/// `lib.rs` and `main.rs` -> `[]` (the crate root).
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap();
    let mut out: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let last = out.pop().unwrap();
    let last = last.trim_end_matches(".rs");
    if !(last == "mod" || (out.is_empty() && (last == "lib" || last == "main"))) {
        out.push(last.to_string());
    }
    out
}

/// The paths of a use tree starting at `text` (just after `crate::` or `super::`), each as its
/// segments: `a::b` gives `[a, b]`, `a::{b::c, d}` gives `[a, b, c]` and `[a, d]`.
fn use_tree(text: &str) -> Vec<Vec<String>> {
    fn tree(chars: &[char], at: &mut usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
        let mut path = prefix;
        loop {
            while *at < chars.len() && chars[*at].is_whitespace() {
                *at += 1;
            }
            if *at < chars.len() && chars[*at] == '{' {
                *at += 1;
                loop {
                    tree(chars, at, path.clone(), out);
                    while *at < chars.len() && chars[*at].is_whitespace() {
                        *at += 1;
                    }
                    match chars.get(*at) {
                        Some(',') => *at += 1,
                        Some('}') => {
                            *at += 1;
                            return;
                        }
                        _ => return,
                    }
                    while *at < chars.len() && chars[*at].is_whitespace() {
                        *at += 1;
                    }
                    if chars.get(*at) == Some(&'}') {
                        *at += 1;
                        return;
                    }
                }
            }
            let start = *at;
            while *at < chars.len() && (chars[*at].is_alphanumeric() || chars[*at] == '_') {
                *at += 1;
            }
            if *at == start {
                out.push(path);
                return;
            }
            path.push(chars[start..*at].iter().collect());
            if chars.get(*at) == Some(&':') && chars.get(*at + 1) == Some(&':') {
                *at += 2;
            } else {
                out.push(path);
                return;
            }
        }
    }
    let chars: Vec<char> = text.chars().take(2000).collect();
    let mut out = vec![];
    tree(&chars, &mut 0, vec![], &mut out);
    out
}

/// The absolute module paths `text` (the file of module `here`) refers to through `crate::`
/// and `super::` (its inline test module left out: its `super` is the file's module).
fn referenced_paths(text: &str, here: &[String]) -> Vec<Vec<String>> {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap();
    let mut out = vec![];
    for (at, _) in text.match_indices("crate::") {
        if text[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        out.extend(use_tree(&text[at + 7..]));
    }
    for (at, _) in text.match_indices("super::") {
        if text[..at].ends_with("super::") || text[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let mut rest = &text[at..];
        let mut base = here.to_vec();
        // a file `a/b.rs` is module a::b, whose super is a; `a/mod.rs` is module a, whose
        // super is the root
        while let Some(r) = rest.strip_prefix("super::") {
            base.pop();
            rest = r;
        }
        for p in use_tree(rest) {
            let mut full = base.clone();
            full.extend(p);
            out.push(full);
        }
    }
    out
}

#[test]
fn no_import_cycle_between_the_modules_of_a_crate() {
    use std::collections::{BTreeMap, BTreeSet};
    for krate in [
        "mesh",
        "fe-assembly",
        "linalg",
        "contact",
        "problem",
        "files",
        "driver",
        "distributed",
        "petsc",
        "python",
    ] {
        let src = root().join("crates").join(krate).join("src");
        let mut files = vec![];
        rust_files(&src, &mut files);
        let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_path(&src, f)).collect();
        // edges between sibling modules, at every level: a reference from a::b::x to a::c::y is
        // an edge b -> c among the children of a (a module's own sub-modules are part of it)
        let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = Default::default();
        for f in &files {
            let from = module_path(&src, f);
            let text = std::fs::read_to_string(f).unwrap();
            for path in referenced_paths(&text, &from) {
                // the longest prefix of the path that is a module
                let to = (0..=path.len())
                    .rev()
                    .map(|n| path[..n].to_vec())
                    .find(|p| modules.contains(p))
                    .unwrap_or_default();
                let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
                if common < from.len() && common < to.len() {
                    edges
                        .entry(from[..=common].to_vec())
                        .or_default()
                        .insert(to[..=common].to_vec());
                }
            }
        }
        // a depth-first search for a back edge
        fn visit(
            m: &[String],
            edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
            path: &mut Vec<Vec<String>>,
            done: &mut BTreeSet<Vec<String>>,
        ) -> Option<Vec<Vec<String>>> {
            if let Some(at) = path.iter().position(|p| p == m) {
                let mut cycle = path[at..].to_vec();
                cycle.push(m.to_vec());
                return Some(cycle);
            }
            if done.contains(m) {
                return None;
            }
            path.push(m.to_vec());
            for next in edges.get(m).into_iter().flatten() {
                if let Some(c) = visit(next, edges, path, done) {
                    return Some(c);
                }
            }
            path.pop();
            done.insert(m.to_vec());
            None
        }
        let mut done = Default::default();
        for m in &modules {
            if let Some(cycle) = visit(m, &edges, &mut vec![], &mut done) {
                let names: Vec<String> = cycle.iter().map(|p| p.join("::")).collect();
                panic!(
                    "crate `{krate}`: an import cycle between modules: {}",
                    names.join(" -> ")
                );
            }
        }
    }
}

/// The cycle check sees nested modules and `super::` paths: a circle between two modules of
/// one directory is found.
#[test]
fn the_cycle_check_reads_nested_paths() {
    let here = vec!["studies".to_string(), "inputs".to_string()];
    let paths = referenced_paths(
        "use super::stability::run_with_limit;\nuse crate::{a::{b, c::d}, e};",
        &here,
    );
    assert!(
        paths.contains(&vec!["studies".into(), "stability".into(), "run_with_limit".into()]),
        "{paths:?}"
    );
    assert!(paths.contains(&vec!["a".into(), "c".into(), "d".into()]), "{paths:?}");
    assert!(paths.contains(&vec!["e".into()]), "{paths:?}");
}

/// The function lengths of `cargo xtask metrics`, from its own lexer (comments and strings
/// skipped).
#[allow(dead_code)]
#[path = "../xtask/src/metrics.rs"]
mod metrics;

/// No function of a crate's sources runs over 100 lines: a longer one is several steps that
/// want their names (a table of data is a `const`, not a function).
#[test]
fn no_function_over_a_hundred_lines() {
    let mut long = vec![];
    for entry in std::fs::read_dir(root().join("crates")).unwrap() {
        let src = entry.unwrap().path().join("src");
        let mut files = vec![];
        rust_files(&src, &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (name, line, len) in metrics::functions(&text) {
                if len > 100 {
                    long.push(format!(
                        "{}:{line} {name} ({len} lines)",
                        f.strip_prefix(root()).unwrap().display()
                    ));
                }
            }
        }
    }
    long.sort();
    assert!(long.is_empty(), "functions over 100 lines:\n{}", long.join("\n"));
}
