//! Scene files (TOML) to the typed [`problem::Scene`]: a shipped scene by name or a file by
//! path, with `--set` overrides applied to its TOML tree before it is read, so that a typo
//! names itself (unknown keys are refused) and a value of the wrong kind names its key.
//!
//! An override is `KEY=VALUE` (a dotted key; the value read as TOML, else as a fraction `p/q`,
//! else as a bare string) or `~KEY`, which removes the key (as Hydra's overrides do): for a key
//! that does not apply once another is changed, e.g. `--set contact.law=signorini --set
//! ~contact.friction`.

use crate::{Error, SceneFileError};
use problem::Scene;
use std::path::{Path, PathBuf};

/// The scenes shipped with the program, by name (their files are in `scenes/`).
pub const SHIPPED: &[(&str, &str)] = &[
    ("paper", include_str!("../../../scenes/paper.toml")),
    ("paper-slip", include_str!("../../../scenes/paper-slip.toml")),
    ("paper-cycle", include_str!("../../../scenes/paper-cycle.toml")),
    ("actuator-cycle", include_str!("../../../scenes/actuator-cycle.toml")),
    (
        "mindlin-sphere-cycle",
        include_str!("../../../scenes/mindlin-sphere-cycle.toml"),
    ),
    (
        "paper-frictionless",
        include_str!("../../../scenes/paper-frictionless.toml"),
    ),
    ("paper-stick", include_str!("../../../scenes/paper-stick.toml")),
    ("paper-tresca", include_str!("../../../scenes/paper-tresca.toml")),
    (
        "paper-compliance",
        include_str!("../../../scenes/paper-compliance.toml"),
    ),
    (
        "paper-slip-weakening",
        include_str!("../../../scenes/paper-slip-weakening.toml"),
    ),
    (
        "paper-conductive",
        include_str!("../../../scenes/paper-conductive.toml"),
    ),
    (
        "paper-conducting",
        include_str!("../../../scenes/paper-conducting.toml"),
    ),
    (
        "manufactured-conducting",
        include_str!("../../../scenes/manufactured-conducting.toml"),
    ),
    ("paper-elastic", include_str!("../../../scenes/paper-elastic.toml")),
    ("hertz-sphere", include_str!("../../../scenes/hertz-sphere.toml")),
    ("indent-sphere", include_str!("../../../scenes/indent-sphere.toml")),
    ("indent-cone", include_str!("../../../scenes/indent-cone.toml")),
    ("indent-punch", include_str!("../../../scenes/indent-punch.toml")),
    (
        "indent-sphere-3d",
        include_str!("../../../scenes/indent-sphere-3d.toml"),
    ),
    ("pfm", include_str!("../../../scenes/pfm.toml")),
    ("sensor", include_str!("../../../scenes/sensor.toml")),
    ("corner", include_str!("../../../scenes/corner.toml")),
    ("paper-3d", include_str!("../../../scenes/paper-3d.toml")),
    ("actuator", include_str!("../../../scenes/actuator.toml")),
    ("pzt5a-si", include_str!("../../../scenes/pzt5a-si.toml")),
    ("pfm-film", include_str!("../../../scenes/pfm-film.toml")),
    ("pfm-curve", include_str!("../../../scenes/pfm-curve.toml")),
    ("stack", include_str!("../../../scenes/stack.toml")),
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
    (
        "cattaneo-mindlin-cycle",
        include_str!("../../../scenes/cattaneo-mindlin-cycle.toml"),
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
/// [`Error::Scene`] naming the scene and what is wrong: no such scene or file, a file
/// that is not a regular file, TOML that does not parse, an override that does not apply, or
/// a value that [`Scene::validate`] refuses.
pub fn load(name_or_path: &str, overrides: &[String]) -> Result<(Scene, Source), Error> {
    let (text, source) = text(name_or_path)?;
    let scene = parse(&text, name_or_path, overrides)?;
    Ok((scene, source))
}

/// The TOML text of a shipped scene by name, or of a scene file by path, and where it came
/// from (a shipped scene's relative paths resolve against the working directory).
///
/// # Errors
/// [`Error::Scene`] naming the scene: no such scene or file, a file that is not a
/// regular file or does not read.
pub fn text(name_or_path: &str) -> Result<(String, Source), Error> {
    let err = |e: SceneFileError| Error::scene(name_or_path, e);
    let (text, dir) = if let Some((_, text)) = SHIPPED.iter().find(|(n, _)| *n == name_or_path) {
        (text.to_string(), std::env::current_dir().unwrap_or_default())
    } else if Path::new(name_or_path).exists() {
        // a FIFO or a device would block the read, or never end it
        if !std::fs::metadata(name_or_path).is_ok_and(|m| m.is_file()) {
            return Err(err(SceneFileError::NotAFile));
        }
        let text = std::fs::read_to_string(name_or_path).map_err(|e| err(SceneFileError::Read(e)))?;
        let dir = Path::new(name_or_path)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        (text, dir)
    } else {
        return Err(err(SceneFileError::NotFound {
            shipped: SHIPPED.iter().map(|(n, _)| *n).collect(),
        }));
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
/// [`Error::Scene`], labelled `label`.
pub fn parse(text: &str, label: &str, overrides: &[String]) -> Result<Scene, Error> {
    let mut tree: toml::Table = text.parse().map_err(|e: toml::de::Error| Error::scene(label, e))?;
    for o in overrides {
        apply(&mut tree, o).map_err(|message| {
            Error::scene(
                label,
                SceneFileError::Override {
                    set: o.clone(),
                    key: override_key(o).trim().to_string(),
                    message,
                },
            )
        })?;
    }
    from_tree(tree, label)
}

/// Reads the typed scene from a TOML tree (a scene file's, or one built by a program) and
/// validates it.
///
/// # Errors
/// [`Error::Scene`], labelled `label`, naming the key at fault.
pub fn from_tree(tree: toml::Table, label: &str) -> Result<Scene, Error> {
    let scene: Scene = toml::Value::Table(tree.clone())
        .try_into()
        .map_err(|e: toml::de::Error| Error::scene(label, placed(&tree, e)))?;
    scene.validate().map_err(|e| Error::scene(label, e))?;
    Ok(scene)
}

/// The error `e` of reading the typed scene from `tree`, its key named with the place of its
/// table in an array of tables, as `--set` names it (`contact.1.electric`, "the second
/// `[[contact]]`"): toml names the key `contact.electric` whichever of the tables holds it.
/// The place is found from the span of the same error in the tree written out as text (each
/// table of an array there under a `[[contact]]` header of its own); `e` as it is where the
/// key is not in such an array of several tables.
fn placed(tree: &toml::Table, e: toml::de::Error) -> toml::de::Error {
    let shown = e.to_string();
    let Some((before, after)) = shown.split_once("in `") else {
        return e;
    };
    let Some((path, rest)) = after.split_once('`') else {
        return e;
    };
    let (head, tail) = path.split_once('.').map_or((path, None), |(h, t)| (h, Some(t)));
    let Some(tables) = tree.get(head).and_then(toml::Value::as_array) else {
        return e;
    };
    if tables.len() < 2 || !tables.iter().all(toml::Value::is_table) {
        return e;
    }
    let Ok(text) = toml::to_string(tree) else {
        return e;
    };
    let Some(at) = toml::from_str::<Scene>(&text).err().and_then(|e| e.span()) else {
        return e;
    };
    let header = format!("[[{head}]]");
    let Some(index) = text[..at.end]
        .lines()
        .filter(|line| line.trim() == header)
        .count()
        .checked_sub(1)
        .filter(|&i| i < tables.len())
    else {
        return e;
    };
    let key = match tail {
        Some(tail) => format!("{head}.{index}.{tail}"),
        None => format!("{head}.{index}"),
    };
    <toml::de::Error as serde::de::Error>::custom(format!(
        "{before}in `{key}` (the {} `{header}`){rest}",
        ordinal(index + 1)
    ))
}

/// "first", "second", ... for small `n`, "21st" and so on beyond.
fn ordinal(n: usize) -> String {
    const WORDS: [&str; 10] = [
        "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth",
    ];
    match n {
        1..=10 => WORDS[n - 1].to_string(),
        _ => {
            let suffix = match (n % 10, n % 100) {
                (_, 11..=13) => "th",
                (1, _) => "st",
                (2, _) => "nd",
                (3, _) => "rd",
                _ => "th",
            };
            format!("{n}{suffix}")
        }
    }
}

/// Applies one override, `a.b.c=value` or `~a.b.c`, to the tree.
fn apply(tree: &mut toml::Table, o: &str) -> Result<(), String> {
    let value = match o.strip_prefix('~') {
        Some(_) => None,
        None => {
            let (_, raw) = o.split_once('=').ok_or("expected KEY=VALUE, or ~KEY to remove a key")?;
            Some(parse_value(raw.trim())?)
        }
    };
    set(tree, override_key(o), value)
}

/// The key of an override: `KEY` of `KEY=VALUE` or of `~KEY` (the whole text where it has
/// neither form).
pub fn override_key(o: &str) -> &str {
    match o.strip_prefix('~') {
        Some(key) => key,
        None => o.split_once('=').map_or(o, |(key, _)| key),
    }
}

/// The value of the dotted `key` in the tree, read as [`set`] writes it: an array of tables
/// entered by a 0-based index (`contact.1.gap`, `contact[1].gap`) or as its one table
/// (`material.young`), a section written as one table by index 0 too (`contact.0.gap` on a
/// scene of one `[contact]`). `Ok(None)` where the tree holds no such key.
///
/// # Errors
/// A key that is no dotted key; a key that enters an array of several tables without an
/// index (which of them is meant is not said).
pub fn get<'t>(tree: &'t toml::Table, key: &str) -> Result<Option<&'t toml::Value>, String> {
    let path = key_path(key)?;
    let Some((first, rest)) = path.split_first() else {
        return Err("an empty key".into());
    };
    let Some(mut at) = tree.get(first) else {
        return Ok(None);
    };
    let mut walked = first.clone();
    for part in rest {
        let index = part.parse::<usize>().ok();
        let next = match (at, index) {
            (toml::Value::Array(a), Some(i)) => a.get(i),
            (toml::Value::Array(a), None) => match &a[..] {
                [toml::Value::Table(t)] => t.get(part),
                tables if tables.iter().all(toml::Value::is_table) => {
                    return Err(format!(
                        "`{walked}` holds {} tables: name one by its 0-based index, as `{walked}.0.{part}`",
                        tables.len()
                    ))
                }
                _ => None,
            },
            (toml::Value::Table(t), _) if t.contains_key(part) => t.get(part),
            (toml::Value::Table(_), Some(0)) => Some(at),
            _ => None,
        };
        let Some(next) = next else {
            return Ok(None);
        };
        at = next;
        walked = format!("{walked}.{part}");
    }
    Ok(Some(at))
}

/// The sections a scene holds as one table or as an array of tables.
const ONE_OR_MANY: [&str; 3] = ["contact", "electrode", "load"];

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
    let path = key_path(key)?;
    let (last, parents) = path.split_last().ok_or("an empty key")?;
    let mut table = tree;
    let mut walked = String::new();
    let mut parts = parents.iter().peekable();
    while let Some(part) = parts.next() {
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(part);
        // a component of a list the scene leaves out: no list to set it in (a table by its
        // index is another matter: it adds one to an array of tables, `dirichlet.0={...}`)
        let by_index = parts.peek().is_none() && last.parse::<usize>().is_ok();
        let absent = !table.contains_key(part.as_str()) && !ONE_OR_MANY.contains(&part.as_str());
        if by_index && absent && !matches!(value, Some(toml::Value::Table(_))) {
            return Err(format!(
                "the scene has no `{walked}`, so `{walked}.{last}` names a component of nothing: give the whole list (`{walked}=[...]`)"
            ));
        }
        let entry = table.entry(part.to_string()).or_insert_with(|| match by_index {
            // the array of tables a table by its index starts (`mesh.region.0={...}`)
            true => toml::Value::Array(vec![]),
            false => toml::Value::Table(toml::Table::new()),
        });
        // a section a scene holds as one table or as an array of tables (`[contact]` or
        // `[[contact]]`), named by an index: the one table is the array's first (`contact.0.gap`
        // on a scene of one `[contact]`), and one past it a new one (`contact.1.group` adds a
        // second zone), as in an array
        let index = parts.peek().copied().unwrap_or(last).parse::<usize>().is_ok();
        if index && walked == *part && ONE_OR_MANY.contains(&part.as_str()) {
            one_table_as_array(entry);
        }
        table = match entry {
            toml::Value::Table(t) => t,
            toml::Value::Array(a) => {
                // a whole table of the array, by its index (`~dirichlet.1` removes the second)
                if parts.peek().is_none() {
                    if let Ok(i) = last.parse::<usize>() {
                        if !a.is_empty() && !a.iter().any(toml::Value::is_table) {
                            return set_component(a, i, value, &walked);
                        }
                        return set_table(a, i, value, &format!("{walked}.{i}"));
                    }
                }
                // an array of tables: entered by a 0-based index, or as its one table
                let at = match parts.peek().and_then(|p| p.parse::<usize>().ok()) {
                    Some(i) => {
                        parts.next();
                        walked.push_str(&format!(".{i}"));
                        i
                    }
                    None if a.len() == 1 => 0,
                    None => {
                        return Err(format!(
                            "`{walked}` holds {} tables: name one by its 0-based index, as `{walked}.0.{}` (or `{walked}[0]`)",
                            a.len(),
                            path[walked.matches('.').count() + 1..].join(".")
                        ))
                    }
                };
                let n = a.len();
                if at == n {
                    // one past the last: a new table (`--set dirichlet.2.group=bottom` adds a
                    // third condition)
                    a.push(toml::Value::Table(toml::Table::new()));
                }
                match a.get_mut(at) {
                    Some(toml::Value::Table(t)) => t,
                    Some(_) => return Err(format!("`{walked}` is not a table")),
                    None => return Err(beyond(&walked, part, n)),
                }
            }
            _ => return Err(format!("`{walked}` is not a table")),
        };
    }
    put(table, key, &path, value)
}

/// Sets `path`'s last key (the dotted `key`) in `table`, its parent, to `value`, or removes it
/// ([`set`]).
fn put(table: &mut toml::Table, key: &str, path: &[String], value: Option<toml::Value>) -> Result<(), String> {
    let last = path.last().ok_or("an empty key")?;
    match value {
        Some(toml::Value::String(file)) if key.trim() == "mesh.file" && Path::new(&file).is_relative() => {
            let typed_here = std::env::current_dir().map_or_else(|_| PathBuf::from(&file), |d| d.join(&file));
            table.insert(last.to_string(), toml::Value::String(typed_here.display().to_string()));
        }
        Some(v) => {
            // an array of tables ([[material]]) does not take one table in its place
            if let (Some(toml::Value::Array(a)), toml::Value::Table(_)) = (table.get(last.as_str()), &v) {
                if a.iter().all(toml::Value::is_table) {
                    return Err(format!(
                        "`{key}` is an array of tables ([[{last}]], {} of them): one is replaced by its index (`{key}.0={{...}}`), its keys set one by one (`{key}.0.KEY=...`, or `{key}.KEY=...` where it holds one), or the whole array given (`{key}=[{{...}}]`)",
                        a.len()
                    ));
                }
            }
            // mesh.h and mesh.n are two ways to give one size: the one set replaces the other
            if let Some(other) = alternative(path) {
                table.remove(other);
            }
            table.insert(last.to_string(), v);
        }
        None => {
            table
                .remove(last.as_str())
                .ok_or_else(|| format!("the scene has no `{key}` to remove"))?;
        }
    }
    Ok(())
}

/// A section written as one table made an array of that one table (of none where the table
/// is empty: a section the scene lacks, made on the way).
fn one_table_as_array(entry: &mut toml::Value) {
    if let toml::Value::Table(t) = entry {
        let one = std::mem::take(t);
        let tables = if one.is_empty() {
            vec![]
        } else {
            vec![toml::Value::Table(one)]
        };
        *entry = toml::Value::Array(tables);
    }
}

/// The message for `walked`, an index past one beyond the `n` tables of `part`.
fn beyond(walked: &str, part: &str, n: usize) -> String {
    match n {
        0 => format!("`{walked}` is beyond the tables of `{part}` (it has none: add one as `{part}.0`)"),
        1 => format!("`{walked}` is beyond the one table of `{part}` (index 0; `{part}.1` adds a second)"),
        n => format!(
            "`{walked}` is beyond the {n} tables of `{part}` (indices 0 to {}; `{part}.{n}` adds one)",
            n - 1
        ),
    }
}

/// Replaces component `i` of `list`, the list of values (numbers: a vector, a tensor's
/// constants) at `key` (`--set load.direction.1=0.5`, a sweep of `material.0.c.3`): in range,
/// by a value of the kind the list holds; a component is not removed nor added (the list's
/// length is its meaning).
fn set_component(list: &mut [toml::Value], i: usize, value: Option<toml::Value>, key: &str) -> Result<(), String> {
    let n = list.len();
    let whole = || list.iter().map(toml::Value::to_string).collect::<Vec<_>>().join(", ");
    let number = |v: &toml::Value| v.is_integer() || v.is_float();
    match value {
        None => Err(format!(
            "`{key}.{i}` is a component of the list `{key}` = [{}]: a component is not removed; give the whole list (`{key}=[...]`)",
            whole()
        )),
        Some(_) if i >= n => Err(format!(
            "`{key}.{i}` is beyond the {n} components of `{key}` = [{}] (indices 0 to {}); give the whole list to change its length (`{key}=[...]`)",
            whole(),
            n - 1
        )),
        // a number for a number (the reader takes an integer where a real is asked)
        Some(v) if number(&v) && number(&list[i]) => {
            list[i] = match (&list[i], v) {
                (toml::Value::Float(_), toml::Value::Integer(k)) => toml::Value::Float(k as f64),
                (_, v) => v,
            };
            Ok(())
        }
        Some(v) if v.same_type(&list[i]) => {
            list[i] = v;
            Ok(())
        }
        Some(v) => Err(format!(
            "`{key}.{i}` is a component of the list `{key}` = [{}]: give one value of its kind (not {v})",
            whole()
        )),
    }
}

/// Removes (`value` `None`) or replaces the table at `i` of an array of tables; one past the
/// last appends. `key` names it in messages.
fn set_table(a: &mut Vec<toml::Value>, i: usize, value: Option<toml::Value>, key: &str) -> Result<(), String> {
    let n = a.len();
    match value {
        None if i < n => {
            a.remove(i);
            Ok(())
        }
        None => Err(match n {
            0 => format!("the scene has no `{key}` to remove (it has no such table)"),
            1 => format!("the scene has no `{key}` to remove (it has one table, index 0)"),
            _ => format!("the scene has no `{key}` to remove (it has {n} tables, indices 0 to {})", n - 1),
        }),
        Some(t @ toml::Value::Table(_)) if i <= n => {
            if i == n {
                a.push(t);
            } else {
                a[i] = t;
            }
            Ok(())
        }
        Some(toml::Value::Table(_)) => Err(beyond(key, key.rsplit_once('.').map_or(key, |(part, _)| part), n)),
        Some(v) => Err(format!("`{key}` is a table of the array: give one, as `{key}={{ ... }}`, or set its keys as `{key}.KEY=VALUE` (not {v})")),
    }
}

/// Whether two dotted keys of one change would overwrite each other: the same key
/// (`dirichlet[1].phi` is `dirichlet.1.phi`; `material.young` is `material.0.young`, the one
/// table of an array being entered either way), one a table that holds the other (`mesh` and
/// `mesh.n`), or two ways to give one quantity (`mesh.n` and `mesh.h`). A key that is no
/// dotted key overlaps nothing (its own error comes when it is set).
pub fn keys_overlap(a: &str, b: &str) -> bool {
    // an index 0 names what the key without it names where the array holds one table
    let first_table = |p: Vec<String>| -> Vec<String> {
        p.into_iter()
            .enumerate()
            .filter(|(k, part)| *k == 0 || part != "0")
            .map(|(_, part)| part)
            .collect()
    };
    let (Ok(a), Ok(b)) = (key_path(a).map(first_table), key_path(b).map(first_table)) else {
        return false;
    };
    let within = |outer: &[String], inner: &[String]| inner.starts_with(outer);
    let alternative_of = |p: &[String], q: &[String]| {
        p.len() == q.len() && p[..p.len() - 1] == q[..q.len() - 1] && alternative(p) == q.last().map(String::as_str)
    };
    within(&a, &b) || within(&b, &a) || alternative_of(&a, &b)
}

/// The key that gives the same quantity as the dotted `path` another way (`mesh.h` and
/// `mesh.n`), which a change of `path` replaces.
fn alternative(path: &[String]) -> Option<&'static str> {
    match path {
        [mesh, key] if mesh == "mesh" && key == "h" => Some("n"),
        [mesh, key] if mesh == "mesh" && key == "n" => Some("h"),
        _ => None,
    }
}

/// A dotted key's parts, with `name[i]` read as `name.i` (an array of tables' entry).
fn key_path(key: &str) -> Result<Vec<String>, String> {
    let mut out = vec![];
    for part in key.trim().split('.') {
        match part.split_once('[') {
            Some((name, rest)) => {
                let index = rest.strip_suffix(']').filter(|i| i.parse::<usize>().is_ok());
                match index {
                    Some(i) if !name.is_empty() => {
                        out.push(name.to_string());
                        out.push(i.to_string());
                    }
                    _ => return Err(format!("`{part}` in `{key}` is not `name[index]`")),
                }
            }
            None if part.is_empty() => return Err(format!("`{key}` is not a dotted key")),
            None => out.push(part.to_string()),
        }
    }
    Ok(out)
}

fn parse_value(raw: &str) -> Result<toml::Value, String> {
    let digits = raw.strip_prefix(['-', '+']).unwrap_or(raw);
    let overflows = |x: f64| x.is_infinite() && !digits.to_ascii_lowercase().starts_with("inf");
    if raw.parse::<f64>().is_ok_and(overflows) {
        return Err(format!(
            "`{raw}` is beyond double precision (a magnitude above {:e})",
            f64::MAX
        ));
    }
    if let Ok(t) = format!("v = {raw}").parse::<toml::Table>() {
        if let Some(v) = t.get("v") {
            return Ok(v.clone());
        }
    }
    // a number TOML does not hold is named as one, not taken for a string
    if !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit() || c == '_') {
        return Err(format!("`{raw}` is an integer beyond 64 bits (at most {})", i64::MAX));
    }
    if let Ok(x) = raw.parse::<f64>() {
        // forms TOML lacks but Rust reads: `1.`, `.5`, `1e5` with a capital E and the like
        return Ok(toml::Value::Float(x));
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
    fn keys_that_overwrite_each_other_overlap() {
        for (a, b) in [
            ("mesh.n", "mesh.n"),
            ("mesh", "mesh.n"),
            ("mesh.n", "mesh.h"),
            ("dirichlet[1].phi", "dirichlet.1.phi"),
            ("contact", "contact.1.gap"),
            ("material.young", "material.0.young"),
            ("contact.0.friction", "contact.friction"),
            ("contact[0].gap", "contact.gap"),
        ] {
            assert!(keys_overlap(a, b) && keys_overlap(b, a), "{a} {b}");
        }
        for (a, b) in [
            ("mesh.n", "mesh.nx"),
            ("mesh.n", "load.p"),
            ("dirichlet.0.phi", "dirichlet.1.phi"),
            ("contact.1.gap", "contact.gap"),
            ("mesh.", "mesh.n"),
        ] {
            assert!(!keys_overlap(a, b), "{a} {b}");
        }
    }

    #[test]
    fn overrides_set_and_remove_keys_and_name_what_does_not_apply() {
        let (s, _) = load("paper", &["mesh.n=16".into(), "mesh.h=1/32".into()]).unwrap();
        assert_eq!(s.mesh.n, None, "mesh.h replaces mesh.n");
        assert_eq!(s.mesh.h, Some(1.0 / 32.0));
        // signorini with the paper's friction coefficient left in: refused, naming the key
        let e = load("paper", &["contact.law=signorini".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("contact.friction does not apply"), "{e}");
        let (s, _) = load("paper", &["contact.law=signorini".into(), "~contact.friction".into()]).unwrap();
        assert_eq!(s.contact_law(), problem::ContactLaw::Signorini);
        let e = load("paper", &["~contact.nothing".into()]).unwrap_err();
        assert!(e.to_string().contains("no `contact.nothing` to remove"), "{e}");
        // the override's key is kept as data, as a scene value's is
        let crate::Error::Scene {
            source: crate::SceneFileError::Override { key, .. },
            ..
        } = &e
        else {
            panic!("{e}")
        };
        assert_eq!(key, "contact.nothing");
        // a choice that does not exist names itself and its key
        let e = load("paper", &["solver.strategy=fast".into()]).unwrap_err().to_string();
        assert!(e.contains("fast") && e.contains("solver.strategy"), "{e}");
    }

    /// A key of the second or third of several `[[contact]]` (or `[[dirichlet]]`) tables is
    /// named with its place, as `--set` names it: toml's own path, `contact.electric`, does not
    /// say which; the values the typed scene refuses are named so by its validation.
    #[test]
    fn a_key_in_an_array_of_tables_is_named_with_its_place() {
        let refused = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            load("corner", &sets).unwrap_err().to_string()
        };
        for (sets, expected) in [
            (
                &["contact.1.gap=\"a\""][..],
                "in `contact.1.gap` (the second `[[contact]]`)",
            ),
            (
                &["contact.0.gap=\"a\""][..],
                "in `contact.0.gap` (the first `[[contact]]`)",
            ),
            (&["~contact.1.group"][..], "in `contact.1` (the second `[[contact]]`)"),
            (&["contact.2.gap=0.0"][..], "in `contact.2` (the third `[[contact]]`)"),
            (
                &["contact.1.indenter={shape=\"sphere\",radius=\"a\"}"][..],
                "in `contact.1.indenter.radius` (the second `[[contact]]`)",
            ),
            (
                &["dirichlet.1.uy=\"x\""][..],
                "in `dirichlet.1.uy` (the second `[[dirichlet]]`)",
            ),
            (
                &["contact.1.normal=[0.0, 0.0]"][..],
                "[[contact]] 1 on `top`: contact.1.normal is the zero vector",
            ),
            (
                &["dirichlet.1.phi=nan"][..],
                "dirichlet on `bottom`: dirichlet.phi = NaN",
            ),
        ] {
            let e = refused(sets);
            assert!(e.contains(expected), "{sets:?}: {e}");
        }
        // one table: toml's path is unambiguous, and kept
        let e = load("paper", &["material.0.young=\"x\"".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("in `material.young`"), "{e}");
        let e = load("paper", &["load.p=nan".into()]).unwrap_err().to_string();
        assert!(e.contains("load on `top`: load.p = NaN"), "{e}");
        assert_eq!(
            (ordinal(1), ordinal(10), ordinal(11), ordinal(22), ordinal(103)),
            (
                "first".into(),
                "tenth".into(),
                "11th".into(),
                "22nd".into(),
                "103rd".into()
            )
        );
    }

    /// A section a scene holds as one table (`[contact]`) is named by index as an array's
    /// tables are: index 0 is the table, 1 adds a second, beyond is refused; a section the scene
    /// lacks takes its first table at index 0.
    #[test]
    fn one_table_is_named_by_index_as_an_array_is() {
        let (s, _) = load("paper", &["contact.0.friction=0.3".into()]).unwrap();
        assert_eq!(s.contacts().len(), 1);
        assert_eq!(s.first_contact().unwrap().friction(), 0.3);
        let second = [
            "contact.1.group=\"top\"",
            "contact.1.law=\"signorini\"",
            "contact.1.normal=[0.0, 1.0]",
        ];
        let (s, _) = load("paper", &second.map(String::from)).unwrap();
        assert_eq!(s.contacts().len(), 2);
        assert_eq!(s.contacts()[1].group, "top");
        let e = load("paper", &["contact.2.gap=0.0".into()]).unwrap_err().to_string();
        assert!(e.contains("`contact.2` is beyond the one table of `contact`"), "{e}");
        // a whole table past the end says how many there are (it said "indices 0 to 0" of none)
        let e = load("paper", &["electrode.1={group=\"top\", v=0.01}".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("it has none: add one as `electrode.0`"), "{e}");
        let sets = ["electrode.0.group=\"top\"".into(), "electrode.0.v=0.0".into()];
        let (s, _) = load("sensor", &sets).unwrap();
        assert_eq!(s.electrodes().len(), 1);
        let e = load("sensor", &["electrode.1.group=\"top\"".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("it has none: add one as `electrode.0`"), "{e}");
    }

    /// A key is read as it is set: by index in an array of tables, the one table of an array
    /// or of a section written as one table with or without index 0; an array of several
    /// tables entered without an index is an error, not an absent key.
    #[test]
    fn keys_are_read_as_they_are_set() {
        let corner: toml::Table = text("corner").unwrap().0.parse().unwrap();
        let value = |key: &str| get(&corner, key).unwrap().cloned();
        assert_eq!(value("contact.1.group"), Some(toml::Value::String("top".into())));
        assert_eq!(value("contact[0].group"), Some(toml::Value::String("right".into())));
        assert_eq!(value("material.model"), value("material.0.model"));
        assert!(value("material.model").is_some());
        assert_eq!(value("contact.2.group"), None);
        assert_eq!(value("mesh.nothing"), None);
        let e = get(&corner, "contact.group").unwrap_err();
        assert!(e.contains("`contact` holds 2 tables"), "{e}");
        let paper: toml::Table = text("paper").unwrap().0.parse().unwrap();
        let friction = get(&paper, "contact.friction").unwrap().cloned();
        assert_eq!(get(&paper, "contact.0.friction").unwrap().cloned(), friction);
        assert!(friction.is_some());
    }

    /// A table given where the scene has an array of tables is refused with the three ways
    /// that work; each of them is taken.
    #[test]
    fn a_table_in_place_of_an_array_of_tables_says_how_to_set_it() {
        let e = load("paper", &["material={crystal=\"PZT-5A\", units=\"GPa\"}".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("array of tables ([[material]]") && e.contains("`material.0={...}`"),
            "{e}"
        );
        for set in [
            "material.0={region=\"body\", crystal=\"PZT-5A\", units=\"GPa\", poling=[0.0, 1.0, 0.0]}",
            "material=[{region=\"body\", crystal=\"PZT-5A\", units=\"GPa\", poling=[0.0, 1.0, 0.0]}]",
        ] {
            let (s, _) = load("paper", &[set.into()]).unwrap_or_else(|e| panic!("{set}: {e}"));
            assert_eq!(s.material.len(), 1, "{set}");
        }
    }

    /// A component of a list of numbers is set by its index (a vector's, a tensor's constant:
    /// what a sweep varies); removing one, one past the end or one of another kind is refused
    /// with the list shown (it was told to be "a table of the array").
    #[test]
    fn a_component_of_a_list_is_set_by_its_index() {
        let (s, _) = load("paper", &["load.direction.1=0.5".into(), "material.0.c.3=100".into()]).unwrap();
        assert_eq!(s.loads()[0].direction, [0.0, 0.5]);
        assert_eq!(s.material[0].c[3], 100.0);
        // a table by its index still adds one to an array the scene leaves out
        let region = "mesh.region.0={name=\"a\", lo=[0.0, 0.0], hi=[1.0, 1.0]}";
        let (s, _) = load("paper", &[region.into()]).unwrap();
        assert_eq!(s.mesh.regions.len(), 1);
        for (set, says) in [
            ("~load.direction.1", "a component is not removed"),
            (
                "load.direction.2=1.0",
                "beyond the 2 components of `load.direction` = [0.0, 1.0] (indices 0 to 1)",
            ),
            ("load.direction.0=\"x\"", "give one value of its kind"),
            (
                "contact.gap_center.0=1.0",
                "the scene has no `contact.gap_center`, so `contact.gap_center.0` names a component of nothing",
            ),
            ("mesh.region.0=1.0", "names a component of nothing"),
        ] {
            let e = load("paper", &[set.into()]).unwrap_err().to_string();
            assert!(e.contains(says) && !e.contains("table"), "{set}: {e}");
        }
    }

    #[test]
    fn numbers_out_of_range_are_named_as_numbers() {
        for (set, says) in [
            ("load.p=1e400", "beyond double precision"),
            ("load.p=-1e400", "beyond double precision"),
            ("mesh.n=99999999999999999999", "an integer beyond 64 bits"),
        ] {
            let e = load("paper", &[set.into()]).unwrap_err().to_string();
            assert!(e.contains(says) && !e.contains("invalid type: string"), "{set}: {e}");
        }
        let (s, _) = load("paper", &["load.p=-2.5E0".into()]).unwrap();
        assert_eq!(s.loads()[0].p, -2.5);
    }

    #[test]
    fn mesh_h_and_mesh_n_replace_each_other_and_arrays_of_tables_are_reached_by_index() {
        let (s, _) = load("paper", &["mesh.h=1/16".into()]).unwrap();
        assert_eq!((s.mesh.n, s.mesh.h), (None, Some(1.0 / 16.0)));
        let (s, _) = load("paper", &["mesh.h=1/16".into(), "mesh.n=8".into()]).unwrap();
        assert_eq!((s.mesh.n, s.mesh.h), (Some(8), None));
        // the second material of a two-material scene, by index either way
        let (s, _) = load("layered", &["material.1.young=0.02".into()]).unwrap();
        assert_eq!(s.material[1].young, Some(0.02));
        let (s, _) = load("layered", &["material[1].poisson=0.25".into()]).unwrap();
        assert_eq!(s.material[1].poisson, Some(0.25));
        let e = load("layered", &["material.young=1".into()]).unwrap_err().to_string();
        assert!(e.contains("holds 2 tables") && e.contains("material.0.young"), "{e}");
        let e = load("layered", &["material.5.young=1".into()]).unwrap_err().to_string();
        assert!(e.contains("beyond the 2 tables"), "{e}");
        let (s, _) = load("paper", &["dirichlet.1.phi=0.5".into()]).unwrap();
        assert_eq!(s.dirichlet[1].phi, Some(0.5));
        // a whole table removed by its index, and only one that is there
        let (s, _) = load("paper", &["~dirichlet.1".into()]).unwrap();
        assert_eq!((s.dirichlet.len(), s.dirichlet[0].group.as_str()), (1, "left"));
        let e = load("paper", &["~dirichlet.2".into()]).unwrap_err().to_string();
        assert!(e.contains("no `dirichlet.2` to remove (it has 2 tables"), "{e}");
        let e = load("paper", &["dirichlet.0=3".into()]).unwrap_err().to_string();
        assert!(e.contains("`dirichlet.0` is a table of the array"), "{e}");
        // one past the last adds a table
        let (s, _) = load("paper", &["dirichlet.2.group=bottom".into(), "dirichlet.2.ux=0".into()]).unwrap();
        assert_eq!((s.dirichlet.len(), s.dirichlet[2].ux), (3, Some(0.0)));
    }
}
