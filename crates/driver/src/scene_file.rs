//! Scene files (TOML) to the typed [`problem::Scene`]: a shipped scene by name or a file by
//! path, with `--set` overrides applied to its TOML tree before it is read, so that a typo
//! names itself (unknown keys are refused) and a value of the wrong kind names its key.
//!
//! An override is `KEY=VALUE` (a dotted key; the value read as TOML, else as a fraction `p/q`,
//! else as a bare string) or `~KEY`, which removes the key (as Hydra's overrides do): for a key
//! that does not apply once another is changed, e.g. `--set contact.law=signorini --set
//! ~contact.friction`.

use crate::DriverError;
use problem::Scene;
use std::path::{Path, PathBuf};

/// The scenes shipped with the program, by name (their files are in `scenes/`).
pub const SHIPPED: &[(&str, &str)] = &[
    ("paper", include_str!("../../../scenes/paper.toml")),
    ("paper-slip", include_str!("../../../scenes/paper-slip.toml")),
    (
        "paper-frictionless",
        include_str!("../../../scenes/paper-frictionless.toml"),
    ),
    ("paper-stick", include_str!("../../../scenes/paper-stick.toml")),
    ("paper-tresca", include_str!("../../../scenes/paper-tresca.toml")),
    ("paper-elastic", include_str!("../../../scenes/paper-elastic.toml")),
    ("paper-3d", include_str!("../../../scenes/paper-3d.toml")),
    ("actuator", include_str!("../../../scenes/actuator.toml")),
    ("pzt5a-si", include_str!("../../../scenes/pzt5a-si.toml")),
    ("layered", include_str!("../../../scenes/layered.toml")),
    (
        "near-incompressible",
        include_str!("../../../scenes/near-incompressible.toml"),
    ),
    ("hertz", include_str!("../../../scenes/hertz.toml")),
    (
        "cattaneo-mindlin",
        include_str!("../../../scenes/cattaneo-mindlin.toml"),
    ),
    ("manufactured", include_str!("../../../scenes/manufactured.toml")),
    ("manufactured-3d", include_str!("../../../scenes/manufactured-3d.toml")),
    ("patch", include_str!("../../../scenes/patch.toml")),
];

/// Where a scene came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The name or path given.
    pub label: String,
    /// The directory relative paths (a Gmsh file) resolve against.
    pub dir: PathBuf,
}

/// Reads a shipped scene by name, or a scene file by path, and applies the overrides.
///
/// # Errors
/// [`DriverError::Scene`] naming the scene and what is wrong: no such scene or file, a file
/// that is not a regular file, TOML that does not parse, an override that does not apply, or
/// a value that [`Scene::validate`] refuses.
pub fn load(name_or_path: &str, overrides: &[String]) -> Result<(Scene, Source), DriverError> {
    let (text, source) = text(name_or_path)?;
    let scene = parse(&text, name_or_path, overrides)?;
    Ok((scene, source))
}

/// The TOML text of a shipped scene by name, or of a scene file by path, and where it came
/// from (a shipped scene's relative paths resolve against the working directory).
///
/// # Errors
/// [`DriverError::Scene`] naming the scene: no such scene or file, a file that is not a
/// regular file or does not read.
pub fn text(name_or_path: &str) -> Result<(String, Source), DriverError> {
    let err = |message: String| DriverError::Scene {
        file: name_or_path.into(),
        message,
    };
    let (text, dir) = if let Some((_, text)) = SHIPPED.iter().find(|(n, _)| *n == name_or_path) {
        (text.to_string(), std::env::current_dir().unwrap_or_default())
    } else if Path::new(name_or_path).exists() {
        // a FIFO or a device would block the read, or never end it
        if !std::fs::metadata(name_or_path).is_ok_and(|m| m.is_file()) {
            return Err(err("is not a regular file".into()));
        }
        let text = std::fs::read_to_string(name_or_path).map_err(|e| err(e.to_string()))?;
        let dir = Path::new(name_or_path)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        (text, dir)
    } else {
        let names: Vec<&str> = SHIPPED.iter().map(|(n, _)| *n).collect();
        return Err(err(format!(
            "no shipped scene of that name and no such file (shipped: {})",
            names.join(", ")
        )));
    };
    let source = Source {
        label: name_or_path.into(),
        dir,
    };
    Ok((text, source))
}

/// Parses scene text, applies the overrides to its TOML tree, reads the typed scene and
/// validates it.
///
/// # Errors
/// [`DriverError::Scene`], labelled `label`.
pub fn parse(text: &str, label: &str, overrides: &[String]) -> Result<Scene, DriverError> {
    let err = |message: String| DriverError::Scene {
        file: label.into(),
        message,
    };
    let mut tree: toml::Table = text.parse().map_err(|e: toml::de::Error| err(e.to_string()))?;
    for o in overrides {
        apply(&mut tree, o).map_err(|m| err(format!("--set {o}: {m}")))?;
    }
    from_tree(tree, label)
}

/// Reads the typed scene from a TOML tree (a scene file's, or one built by a program) and
/// validates it.
///
/// # Errors
/// [`DriverError::Scene`], labelled `label`, naming the key at fault.
pub fn from_tree(tree: toml::Table, label: &str) -> Result<Scene, DriverError> {
    let err = |message: String| DriverError::Scene {
        file: label.into(),
        message,
    };
    let scene: Scene = toml::Value::Table(tree)
        .try_into()
        .map_err(|e: toml::de::Error| err(e.to_string()))?;
    scene.validate().map_err(|e| err(e.to_string()))?;
    Ok(scene)
}

/// Applies one override, `a.b.c=value` or `~a.b.c`, to the tree.
fn apply(tree: &mut toml::Table, o: &str) -> Result<(), String> {
    let (key, value) = match o.strip_prefix('~') {
        Some(key) => (key, None),
        None => {
            let (key, raw) = o.split_once('=').ok_or("expected KEY=VALUE, or ~KEY to remove a key")?;
            (key, Some(parse_value(raw.trim())?))
        }
    };
    set(tree, key, value)
}

/// Sets the dotted `key` of the tree to `value`, or removes it where `value` is `None`;
/// the tables on the way are made where missing, and a table array of one table (a scene's
/// one `[[material]]`) is entered as that table. A relative `mesh.file` is made absolute
/// against the working directory: it was typed there (on the command line, or in Python), not
/// in the scene file's directory, against which the file's own paths resolve.
///
/// # Errors
/// A message naming the part of the key that is not a table, or the key that is not there to
/// remove.
pub fn set(tree: &mut toml::Table, key: &str, value: Option<toml::Value>) -> Result<(), String> {
    let path: Vec<&str> = key.trim().split('.').collect();
    if path.iter().any(|p| p.is_empty()) {
        return Err(format!("`{key}` is not a dotted key"));
    }
    let (last, parents) = path.split_last().ok_or("an empty key")?;
    let mut table = tree;
    for part in parents {
        let entry = table
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            toml::Value::Array(a) if a.len() == 1 => match &mut a[0] {
                toml::Value::Table(t) => t,
                _ => return Err(format!("`{part}` is not a table")),
            },
            _ => return Err(format!("`{part}` is not a table")),
        };
    }
    match value {
        Some(toml::Value::String(file)) if key.trim() == "mesh.file" && Path::new(&file).is_relative() => {
            let typed_here = std::env::current_dir().map_or_else(|_| PathBuf::from(&file), |d| d.join(&file));
            table.insert(last.to_string(), toml::Value::String(typed_here.display().to_string()));
        }
        Some(v) => {
            table.insert(last.to_string(), v);
        }
        None => {
            table
                .remove(*last)
                .ok_or_else(|| format!("the scene has no `{key}` to remove"))?;
        }
    }
    Ok(())
}

fn parse_value(raw: &str) -> Result<toml::Value, String> {
    if let Ok(t) = format!("v = {raw}").parse::<toml::Table>() {
        if let Some(v) = t.get("v") {
            return Ok(v.clone());
        }
    }
    if let Some((p, q)) = raw.split_once('/') {
        if let (Ok(p), Ok(q)) = (p.trim().parse::<f64>(), q.trim().parse::<f64>()) {
            return Ok(toml::Value::Float(p / q));
        }
    }
    if raw.is_empty() {
        return Err("empty value".into());
    }
    Ok(toml::Value::String(raw.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_set_and_remove_keys_and_name_what_does_not_apply() {
        let (s, _) = load("paper", &["mesh.n=16".into(), "mesh.h=1/32".into()]).unwrap();
        assert_eq!(s.mesh.n, Some(16));
        assert_eq!(s.mesh.h, Some(1.0 / 32.0));
        // signorini with the paper's friction coefficient left in: refused, naming the key
        let e = load("paper", &["contact.law=signorini".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("contact.friction does not apply"), "{e}");
        let (s, _) = load("paper", &["contact.law=signorini".into(), "~contact.friction".into()]).unwrap();
        assert_eq!(s.contact_law(), problem::ContactLaw::Signorini);
        let e = load("paper", &["~contact.nothing".into()]).unwrap_err().to_string();
        assert!(e.contains("no `contact.nothing` to remove"), "{e}");
        // a choice that does not exist names itself and its key
        let e = load("paper", &["solver.strategy=fast".into()]).unwrap_err().to_string();
        assert!(e.contains("fast") && e.contains("solver.strategy"), "{e}");
    }
}
