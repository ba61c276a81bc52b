//! The Python extension `blackhole._native` (feature `python`, built by
//! maturin from `pyproject.toml`): scenes from files, text or dicts with the
//! command line's overrides, renders on either backend returned as numpy
//! arrays that view the film without copies, the colour pipeline and
//! closed forms on arrays. The package around it is `src/python/blackhole`.

mod colour;
mod image;
mod scene;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

pyo3::create_exception!(
    blackhole,
    BlackholeError,
    pyo3::exceptions::PyValueError,
    "A scene, an override, a backend or an output the renderer refuses; the message is the command line's."
);

/// The error as the command line prints it (with its causes), raised as
/// [`BlackholeError`].
pub(crate) fn error(e: impl Into<anyhow::Error>) -> PyErr {
    BlackholeError::new_err(format!("{:#}", e.into()))
}

/// How deep scene values nest at most (a scene is a few levels deep; a
/// value that contains itself would recurse for ever).
const MAX_DEPTH: usize = 64;

/// A Python value as TOML: bool, int, float, str, lists and tuples of
/// them, dicts with string keys; numpy scalars and arrays as the numbers
/// and lists they hold. `at` names where it came from.
pub(crate) fn to_toml(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    to_toml_at(v, at, 0)
}

fn to_toml_at(v: &Bound<'_, PyAny>, at: &str, depth: usize) -> PyResult<toml::Value> {
    if depth > MAX_DEPTH {
        return Err(BlackholeError::new_err(format!(
            "{at}: nested more than {MAX_DEPTH} levels deep (a value that contains itself?)"
        )));
    }
    // bool before int: Python's bool is an int; numpy's bool_ is neither.
    let numpy_bool = matches!(v.get_type().name()?.to_string().as_str(), "bool_" | "bool");
    if v.is_instance_of::<PyBool>() || numpy_bool {
        return Ok(toml::Value::Boolean(v.is_truthy()?));
    }
    // numpy arrays as the lists they hold (before __index__, which arrays
    // also have).
    if v.hasattr("ndim")? && v.getattr("ndim")?.extract::<usize>().is_ok_and(|d| d > 0) {
        return to_toml_at(&v.call_method0("tolist")?, at, depth + 1);
    }
    let is_float = v.is_instance_of::<PyFloat>();
    if v.is_instance_of::<PyInt>() || (!is_float && v.hasattr("__index__")?) {
        let i = v.call_method0("__index__")?;
        let i: i64 = i.extract().map_err(|_| {
            BlackholeError::new_err(format!("{at}: {v} does not fit in a 64-bit integer"))
        })?;
        return Ok(toml::Value::Integer(i));
    }
    if is_float {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(toml::Value::String(s.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(toml::Value::Table(to_table_at(d, at, depth + 1)?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, e) in v.try_iter()?.enumerate() {
            out.push(to_toml_at(&e?, &format!("{at}[{i}]"), depth + 1)?);
        }
        return Ok(toml::Value::Array(out));
    }
    // numpy floats and other real numbers.
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    let kind = v.get_type().name()?;
    Err(BlackholeError::new_err(format!(
        "{at}: a {kind} is not a scene value: expected a bool, int, float, str, list or dict"
    )))
}

/// A dict with string keys as a TOML table.
pub(crate) fn to_table(d: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    to_table_at(d, at, 0)
}

fn to_table_at(d: &Bound<'_, PyDict>, at: &str, depth: usize) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let Ok(key) = k.cast::<PyString>() else {
            return Err(BlackholeError::new_err(format!(
                "{at}: the key {} is not a string",
                k.repr()?
            )));
        };
        let key: String = key.extract()?;
        let here = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        t.insert(key, to_toml_at(&v, &here, depth)?);
    }
    Ok(t)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // At import, before any render thread: Mesa's runtime folder.
    crate::gpu::ensure_runtime_dir();
    m.add("BlackholeError", m.py().get_type::<BlackholeError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    scene::register(m)?;
    image::register(m)?;
    colour::register(m)?;
    Ok(())
}
