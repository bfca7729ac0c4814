//! Python values to a scene's TOML values and back, and JSON (a run's report) to Python.

use crate::errors::Kind;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyMapping, PyString};

/// The TOML value of a Python value: `bool`, `int`, `float` (and NumPy's scalars), `str`,
/// sequences (lists, tuples, 1-D arrays) and mappings with string keys. `key` names the value
/// in the error.
pub fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return v
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| Kind::Input.err(format!("{key}: the integer {v} does not fit in 64 bits")));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if let Ok(m) = v.cast::<PyMapping>() {
        let mut table = toml::Table::new();
        for item in m.items()?.iter() {
            let (k, x): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract()?;
            let k: String = k
                .extract()
                .map_err(|_| Kind::Input.err(format!("{key}: a key that is not a string: {k}")))?;
            let value = to_toml(&x, &format!("{key}.{k}"))?;
            table.insert(k, value);
        }
        return Ok(toml::Value::Table(table));
    }
    // NumPy's booleans and 0-d arrays: their Python value
    if v.hasattr("dtype")? && v.hasattr("item")? && v.getattr("ndim").and_then(|d| d.extract::<usize>()).ok() == Some(0)
    {
        return to_toml(&v.call_method0("item")?, key);
    }
    // NumPy's scalars: integers have __index__, floats __float__ (and are not sequences)
    if v.hasattr("__index__")? && !v.hasattr("__len__")? {
        if let Ok(i) = v.extract::<i64>() {
            return Ok(toml::Value::Integer(i));
        }
    }
    if v.hasattr("__float__")? && !v.hasattr("__len__")? {
        if let Ok(x) = v.extract::<f64>() {
            return Ok(toml::Value::Float(x));
        }
    }
    if v.hasattr("__len__")? && v.hasattr("__iter__")? {
        let mut out = vec![];
        for (i, x) in v.try_iter()?.enumerate() {
            out.push(to_toml(&x?, &format!("{key}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    Err(Kind::Input.err(format!(
        "{key}: a value of type `{}` has no meaning in a scene (numbers, strings, booleans, lists and dicts do)",
        v.get_type().name()?
    )))
}

/// The table of a Python mapping (a scene as a dict).
pub fn to_table(v: &Bound<'_, PyAny>) -> PyResult<toml::Table> {
    match to_toml(v, "scene")? {
        toml::Value::Table(t) => Ok(t),
        _ => Err(Kind::Input.err("a scene is a dict of its sections (mesh, material, contact, ...)")),
    }
}

/// The Python value of a TOML value.
pub fn from_toml<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(x) => x.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => {
            let items = a.iter().map(|x| from_toml(py, x)).collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        toml::Value::Table(t) => from_table(py, t)?.into_any(),
    })
}

/// The Python dict of a TOML table.
pub fn from_table<'py>(py: Python<'py>, t: &toml::Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, x) in t {
        d.set_item(k, from_toml(py, x)?)?;
    }
    Ok(d)
}

/// The Python value of JSON text (a run's report), by the standard library's reader: the same
/// dict as `json.load` of `run.json`.
pub fn from_json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}
