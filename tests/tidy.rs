//! Tidy checks of the source tree (after rust-analyzer's tidy test): every Rust file opens with
//! a `//!` line; dependencies between our crates point the way docs/architecture.md draws them;
//! nothing prints outside the driver and the xtask.

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

#[test]
fn crate_dependencies_point_one_way() {
    // crate -> the crates of ours it may depend on (normal dependencies)
    let allowed: &[(&str, &[&str])] = &[
        ("mesh", &[]),
        ("linalg", &[]),
        ("contact", &[]),
        ("fe-assembly", &["mesh"]),
        ("driver", &["mesh", "fe-assembly", "linalg", "contact"]),
    ];
    let ours = ["mesh", "fe-assembly", "linalg", "contact", "driver"];
    for (krate, may) in allowed {
        let manifest = std::fs::read_to_string(root().join("crates").join(krate).join("Cargo.toml")).unwrap();
        let deps = manifest
            .split("[dependencies]")
            .nth(1)
            .unwrap()
            .split("\n[")
            .next()
            .unwrap();
        for other in ours {
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
    for k in ["mesh", "fe-assembly", "linalg", "contact"] {
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
