//! Compares the outputs of two sets of runs, directory by directory: `run.json` (every number
//! and string, but the timings, the factorisation's rate and the peak memory, which differ from
//! run to run), `contact.csv` and `solution.vtu` (every number), and which files each directory
//! holds; the `.vtu` files' binary arrays (`format="binary"`: base64 of an 8-byte count, then
//! the values) are decoded and compared as numbers. Numbers agree when
//! `|a - b| <= tol max(|a|, |b|, floor)`, with `floor` the largest magnitude of the same file's
//! numbers times 1e-12 (round-off of a sum).
//!
//! Written to check that a change of the code's shape changed no answer (issue 11: the typed
//! core); the one field renamed on purpose, `solver.step_r` of a Newton run, becomes
//! `solver.augmentation_c`, and the check maps the old name onto the new.
//!
//!   cargo run --release -p driver --example compare_outputs -- BEFORE AFTER [--tol 1e-9]

use base64::Engine;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// Keys whose values are measurements of this run, not of the answer.
const VOLATILE: &[&str] = &["timings_s", "path.steps_s", "memory.peak_bytes", "solver.factor_gflops"];

fn flatten(prefix: &str, v: &Value, out: &mut BTreeMap<String, Value>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&key, x, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                flatten(&format!("{prefix}[{i}]"), x, out);
            }
        }
        _ => {
            out.insert(prefix.to_string(), v.clone());
        }
    }
}

/// `text` with each binary `<DataArray>`'s base64 written out as its values (`Float64`,
/// `Float32`, `Int32`, `Int64`, `UInt8`, `UInt32`, `UInt64`), one token each; an array that
/// does not decode is left as it is (its bytes then compared as a word).
fn decoded(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("<DataArray") {
        let Some(open_end) = rest[at..].find('>').map(|e| at + e + 1) else {
            break;
        };
        let Some(close) = rest[open_end..].find("</DataArray>").map(|e| open_end + e) else {
            break;
        };
        let tag = &rest[at..open_end];
        out.push_str(&rest[..open_end]);
        let body = rest[open_end..close].trim();
        match (tag.contains("format=\"binary\""), values(tag, body)) {
            (true, Some(v)) => out.push_str(&v),
            _ => out.push_str(&rest[open_end..close]),
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}

/// The values of a binary array's base64 `body`, by the `type` of its `tag`.
fn values(tag: &str, body: &str) -> Option<String> {
    let kind = tag.split("type=\"").nth(1)?.split('"').next()?;
    let bytes = base64::engine::general_purpose::STANDARD.decode(body).ok()?;
    let data = bytes.get(8..)?;
    let of =
        |w: usize, f: &dyn Fn(&[u8]) -> String| -> String { data.chunks_exact(w).map(f).collect::<Vec<_>>().join(" ") };
    Some(match kind {
        "Float64" => of(8, &|c| f64::from_le_bytes(c.try_into().unwrap()).to_string()),
        "Float32" => of(4, &|c| f32::from_le_bytes(c.try_into().unwrap()).to_string()),
        "Int64" => of(8, &|c| i64::from_le_bytes(c.try_into().unwrap()).to_string()),
        "UInt64" => of(8, &|c| u64::from_le_bytes(c.try_into().unwrap()).to_string()),
        "Int32" => of(4, &|c| i32::from_le_bytes(c.try_into().unwrap()).to_string()),
        "UInt32" => of(4, &|c| u32::from_le_bytes(c.try_into().unwrap()).to_string()),
        "UInt8" => of(1, &|c| c[0].to_string()),
        _ => return None,
    })
}

fn tokens(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| c.is_whitespace() || c == ',' || c == '"' || c == '<' || c == '>')
}

/// The numbers of a text, in order (tokens that parse as f64).
fn numbers(text: &str) -> Vec<f64> {
    tokens(text).filter_map(|t| t.parse::<f64>().ok()).collect()
}

/// The other tokens of a text, in order (names, a point's status).
fn words(text: &str) -> Vec<&str> {
    tokens(text).filter(|t| t.parse::<f64>().is_err()).collect()
}

/// The largest relative difference of two lists of numbers, and whether their lengths agree.
fn compare_numbers(a: &[f64], b: &[f64]) -> (f64, bool) {
    let floor = a.iter().chain(b).fold(0.0f64, |m, x| m.max(x.abs())) * 1e-12;
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| {
            if x == y {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs()).max(floor)
            }
        })
        .fold(0.0, f64::max);
    (worst, a.len() == b.len())
}

fn compare_json(a: &Value, b: &Value, tol: f64, problems: &mut Vec<String>) -> f64 {
    let (mut fa, mut fb) = (BTreeMap::new(), BTreeMap::new());
    flatten("", a, &mut fa);
    flatten("", b, &mut fb);
    // the renamed field: a Newton run's `c` was `step_r` (in outputs older than the field)
    let renamed = !fa.contains_key("solver.augmentation_c");
    if !renamed {
    } else if fa.get("solver.strategy") == Some(&Value::String("newton-condensed".into())) {
        if let Some(v) = fa.remove("solver.step_r") {
            if fb.get("iterations.newton_fallback") != Some(&Value::Bool(true)) {
                fa.insert("solver.step_r".into(), Value::Null);
            }
            fa.insert("solver.augmentation_c".into(), v);
        }
    } else {
        fa.entry("solver.augmentation_c".into()).or_insert(Value::Null);
    }
    let volatile = |k: &str| VOLATILE.iter().any(|v| k.starts_with(v));
    let floor = fa
        .values()
        .chain(fb.values())
        .filter_map(Value::as_f64)
        .fold(0.0f64, |m, x| m.max(x.abs()))
        * 1e-16;
    let mut worst = 0.0f64;
    for key in fa.keys().chain(fb.keys()).collect::<std::collections::BTreeSet<_>>() {
        if volatile(key) {
            continue;
        }
        match (fa.get(key), fb.get(key)) {
            (Some(x), Some(y)) => match (x.as_f64(), y.as_f64()) {
                (Some(p), Some(q)) if p != q => {
                    let d = (p - q).abs() / p.abs().max(q.abs()).max(floor);
                    worst = worst.max(d);
                    if d > tol {
                        problems.push(format!("run.json {key}: {p} vs {q}"));
                    }
                }
                (Some(_), Some(_)) => {}
                _ if x != y => problems.push(format!("run.json {key}: {x} vs {y}")),
                _ => {}
            },
            (x, y) => problems.push(format!("run.json {key}: {x:?} vs {y:?}")),
        }
    }
    worst
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tol = args
        .iter()
        .position(|a| a == "--tol")
        .and_then(|i| args.get(i + 1))
        .and_then(|t| t.parse().ok())
        .unwrap_or(1e-9);
    let (Some(before), Some(after)) = (args.first(), args.get(1)) else {
        eprintln!("usage: compare_outputs BEFORE AFTER [--tol 1e-9]");
        std::process::exit(2);
    };
    let mut dirs: Vec<String> = std::fs::read_dir(before)
        .expect("the BEFORE directory")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    dirs.sort();
    let mut failed = 0;
    println!("| run | run.json | contact.csv | solution.vtu | files | verdict |\n|---|---|---|---|---|---|");
    for d in &dirs {
        let (a, b) = (Path::new(before).join(d), Path::new(after).join(d));
        let mut problems = vec![];
        let list = |p: &Path| -> Vec<String> {
            let mut v: Vec<String> = std::fs::read_dir(p)
                .map(|r| {
                    r.filter_map(|e| e.ok())
                        .map(|e| e.file_name().to_string_lossy().into_owned())
                        .collect()
                })
                .unwrap_or_default();
            v.sort();
            v
        };
        let (la, lb) = (list(&a), list(&b));
        if la != lb {
            problems.push(format!("files {la:?} vs {lb:?}"));
        }
        let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
        let json = |p: &Path| serde_json::from_str::<Value>(&read(p)).unwrap_or(Value::Null);
        let j = compare_json(
            &json(&a.join("run.json")),
            &json(&b.join("run.json")),
            tol,
            &mut problems,
        );
        let mut cell = |name: &str| -> String {
            if !a.join(name).exists() {
                return "-".into();
            }
            let (ta, tb) = (decoded(&read(&a.join(name))), decoded(&read(&b.join(name))));
            let (w, same_len) = compare_numbers(&numbers(&ta), &numbers(&tb));
            if !same_len || w > tol {
                problems.push(format!(
                    "{name}: largest relative difference {w:.1e}, same length {same_len}"
                ));
            }
            if words(&ta) != words(&tb) {
                problems.push(format!("{name}: the words (names, status) differ"));
            }
            format!("{w:.1e}")
        };
        let (csv, vtu) = (cell("contact.csv"), cell("solution.vtu"));
        let verdict = if problems.is_empty() {
            "same".to_string()
        } else {
            problems.join("; ")
        };
        failed += usize::from(!problems.is_empty());
        println!(
            "| {d} | {j:.1e} | {csv} | {vtu} | {} | {verdict} |",
            if la == lb {
                la.len().to_string()
            } else {
                "differ".into()
            }
        );
    }
    println!(
        "\n{} runs compared (tolerance {tol:.0e}, timings and peak memory left out): {} differ",
        dirs.len(),
        failed
    );
    if failed > 0 {
        std::process::exit(1);
    }
}
