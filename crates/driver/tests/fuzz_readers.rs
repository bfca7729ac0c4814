//! Mutation fuzzing of the two readers of user input, by proptest: the shipped scenes and the
//! Gmsh fixtures (ASCII and binary), cut short, with bytes deleted, inserted or flipped, numbers
//! replaced by NaN, infinities, zeros, negatives and huge values, lines duplicated or swapped.
//! Every mutant must give a scene or mesh, or a typed error: never a panic. Scenes that still
//! read are run whole on a small mesh (without outputs), so that values that pass the reader
//! (a NaN constant, a zero friction, a huge gap) are fuzzed through the solver as well.
//!
//! The case counts are proptest's (`PROPTEST_CASES` raises them); the default run tries
//! `SCENE_CASES + MESH_CASES` mutants.

use problem::MeshKind;
use proptest::prelude::*;

const SCENE_CASES: u32 = 400;
const MESH_CASES: u32 = 600;

/// Replacements for a number.
const SPECIAL: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e-308",
    "18446744073709551616",
    "2.5",
    "",
];

/// `PROPTEST_CASES` where set, else the default of the test.
fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[derive(Clone, Debug)]
enum Edit {
    Truncate(f64),
    Delete(f64, usize),
    Insert(f64, Vec<u8>),
    Flip(f64, u8),
    Number(f64, usize),
    DuplicateLine(f64),
    SwapLines(f64, f64),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0.0..1.0f64).prop_map(Edit::Truncate),
        (0.0..1.0f64, 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        (0.0..1.0f64, prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(p, b)| Edit::Insert(p, b)),
        (0.0..1.0f64, any::<u8>()).prop_map(|(p, b)| Edit::Flip(p, b)),
        (0.0..1.0f64, 0..SPECIAL.len()).prop_map(|(p, k)| Edit::Number(p, k)),
        (0.0..1.0f64).prop_map(Edit::DuplicateLine),
        (0.0..1.0f64, 0.0..1.0f64).prop_map(|(a, b)| Edit::SwapLines(a, b)),
    ]
}

/// Mostly numbers replaced (the scene still parses and its values reach the solver), some
/// edits of the text.
fn value_edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        6 => (0.0..1.0f64, 0..SPECIAL.len()).prop_map(|(p, k)| Edit::Number(p, k)),
        1 => edit(),
    ]
}

fn at(len: usize, p: f64) -> usize {
    ((len as f64 * p) as usize).min(len)
}

/// The byte ranges of the lines of `b`.
fn lines(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = vec![];
    let mut start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < b.len() {
        out.push((start, b.len()));
    }
    out
}

/// The byte ranges of the numbers of `b` (a digit, with signs, dots and exponents around it).
fn numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let part = |c: u8| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+' | b'e' | b'E');
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let mut s = i;
            while s > 0 && part(b[s - 1]) {
                s -= 1;
            }
            let mut e = i;
            while e < b.len() && part(b[e]) {
                e += 1;
            }
            out.push((s, e));
            i = e;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(mut b: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let len = b.len();
        match e {
            Edit::Truncate(p) => b.truncate(at(len, *p)),
            Edit::Delete(p, n) => {
                let s = at(len, *p);
                b.drain(s..(s + n).min(len));
            }
            Edit::Insert(p, bytes) => {
                let s = at(len, *p);
                b.splice(s..s, bytes.iter().copied());
            }
            Edit::Flip(p, x) => {
                if len > 0 {
                    let s = at(len - 1, *p);
                    b[s] ^= x | 1;
                }
            }
            Edit::Number(p, k) => {
                let nums = numbers(&b);
                if !nums.is_empty() {
                    let (s, e) = nums[at(nums.len() - 1, *p)];
                    b.splice(s..e, SPECIAL[*k].bytes());
                }
            }
            Edit::DuplicateLine(p) => {
                let ls = lines(&b);
                if !ls.is_empty() {
                    let (s, e) = ls[at(ls.len() - 1, *p)];
                    let line = b[s..e].to_vec();
                    b.splice(e..e, line);
                }
            }
            Edit::SwapLines(p, q) => {
                let ls = lines(&b);
                if ls.len() > 1 {
                    let (i, j) = (at(ls.len() - 1, *p), at(ls.len() - 1, *q));
                    let (i, j) = (i.min(j), i.max(j));
                    if i != j {
                        let (a, c) = (ls[i], ls[j]);
                        let mut out = b[..a.0].to_vec();
                        out.extend_from_slice(&b[c.0..c.1]);
                        out.extend_from_slice(&b[a.1..c.0]);
                        out.extend_from_slice(&b[a.0..a.1]);
                        out.extend_from_slice(&b[c.1..]);
                        b = out;
                    }
                }
            }
        }
    }
    b
}

fn fixture(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../mesh/tests/fixtures")
        .join(name);
    std::fs::read(path).expect("a mesh fixture")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(MESH_CASES), failure_persistence: None, ..ProptestConfig::default() })]

    /// A mutated Gmsh file reads into a mesh that passes or fails its quality check, or gives
    /// a typed error; it never panics.
    #[test]
    fn mutated_meshes_never_panic(which in 0usize..3, edits in prop::collection::vec(edit(), 1..5)) {
        let name = ["layered2d.msh", "quads2d.msh", "box3d_bin.msh"][which];
        let bytes = apply(fixture(name), &edits);
        if let Ok(m) = mesh::read_msh_bytes(&bytes, "fuzz.msh") {
            let _ = m.check();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(SCENE_CASES), failure_persistence: None, ..ProptestConfig::default() })]

    /// A mutated shipped scene reads, or gives a typed error; one that reads runs whole on a
    /// small mesh (the mesh size is forced down), to an answer or a typed error.
    #[test]
    fn mutated_scenes_never_panic(which in 0usize..files::scene_file::SHIPPED.len(), edits in prop::collection::vec(value_edit(), 1..4)) {
        let (name, text) = files::scene_file::SHIPPED[which];
        let bytes = apply(text.as_bytes().to_vec(), &edits);
        let text = String::from_utf8_lossy(&bytes);
        let Ok(scene) = files::scene_file::parse(&text, name, &[]) else { return Ok(()) };
        // the mesh forced down to 3 cells along each axis it has
        let small = scene.mesh.sized(3);
        if let Ok(scene) = files::scene_file::parse(&text, name, &small) {
            // a tolerance below round-off only makes the solvers run to their iteration limits
            if scene.solver.tol >= 1e-13 && scene.mesh.kind != MeshKind::Gmsh {
                let source = files::scene_file::Source { label: name.into(), dir: ".".into() };
                let _ = files::run::solve(&scene, &source, &mut problem::Silent);
            }
        }
    }
}
