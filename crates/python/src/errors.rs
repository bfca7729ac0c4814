//! The exceptions of the package, one per kind of failure, and the map from the library's typed
//! errors to them. The message is always the Rust error's own.
//!
//! ```text
//! PiezocontactError(Exception)
//! ├── InputError(PiezocontactError, ValueError)   a scene value, a material, a file, an array
//! │   └── MeshError(InputError)                   a mesh that does not read or is broken
//! ├── SolverError(PiezocontactError, ArithmeticError)  a linear solve, a number that overflowed, too large a run
//! │   └── ConvergenceError(SolverError)           the contact solve did not converge
//! └── OutputError(PiezocontactError, OSError)     a file that cannot be written
//! ```

use files::Error;
use problem::ProblemError;
use pyo3::exceptions::{PyArithmeticError, PyException, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// The kinds of failure, each one exception class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The base class (a failure that is none of the others).
    Base,
    /// A bad input.
    Input,
    /// A bad mesh.
    Mesh,
    /// A numerical failure.
    Solver,
    /// A contact solve that did not converge.
    Convergence,
    /// A file that cannot be written.
    Output,
}

impl Kind {
    /// The class's name, its parents, and its docstring.
    fn spec(self) -> (&'static str, &'static [Kind], &'static str) {
        match self {
            Kind::Base => ("PiezocontactError", &[], "Every error of piezocontact."),
            Kind::Input => (
                "InputError",
                &[Kind::Base],
                "A scene value, material, file or array that cannot be used; the message names it.",
            ),
            Kind::Mesh => (
                "MeshError",
                &[Kind::Input],
                "A mesh that does not read, or is broken (a bad cell, a missing group, overlapping cells).",
            ),
            Kind::Solver => (
                "SolverError",
                &[Kind::Base],
                "A numerical failure: a singular system, a result that is not finite, a run too large for the memory.",
            ),
            Kind::Convergence => (
                "ConvergenceError",
                &[Kind::Solver],
                "The contact solve did not converge; the message gives its last residual and what to try.",
            ),
            Kind::Output => (
                "OutputError",
                &[Kind::Base],
                "An output file or directory that cannot be written.",
            ),
        }
    }

    /// All kinds, parents before children.
    pub const ALL: [Kind; 6] = [
        Kind::Base,
        Kind::Input,
        Kind::Mesh,
        Kind::Solver,
        Kind::Convergence,
        Kind::Output,
    ];

    fn index(self) -> usize {
        Kind::ALL.iter().position(|&k| k == self).unwrap_or(0)
    }

    /// The class, made once per interpreter.
    pub fn class(self, py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
        static CLASSES: [PyOnceLock<Py<PyType>>; 6] = [const { PyOnceLock::new() }; 6];
        let cell = &CLASSES[self.index()];
        if let Some(c) = cell.get(py) {
            return Ok(c.bind(py));
        }
        let (name, parents, doc) = self.spec();
        let mut bases: Vec<Bound<'_, PyAny>> = vec![];
        for p in parents {
            bases.push(p.class(py)?.clone().into_any());
        }
        // a Python builtin beside the package's parent, so that `except ValueError` catches
        // bad input as Python code expects
        match self {
            Kind::Base => bases.push(py.get_type::<PyException>().into_any()),
            Kind::Input => bases.push(py.get_type::<PyValueError>().into_any()),
            Kind::Solver => bases.push(py.get_type::<PyArithmeticError>().into_any()),
            Kind::Output => bases.push(py.get_type::<PyOSError>().into_any()),
            Kind::Mesh | Kind::Convergence => {}
        }
        let namespace = PyDict::new(py);
        namespace.set_item("__module__", "piezocontact")?;
        namespace.set_item("__doc__", doc)?;
        if self == Kind::Base {
            // the scene key at fault, on the instances of a scene value's error (to_py)
            namespace.set_item("key", py.None())?;
        }
        let class = py
            .get_type::<PyType>()
            .call1((name, PyTuple::new(py, bases)?, namespace))?
            .cast_into::<PyType>()?;
        let _ = cell.set(py, class.unbind());
        Ok(cell.get(py).expect("set just above").bind(py))
    }

    /// An exception of this kind with `message`.
    pub fn err(self, message: impl Into<String>) -> PyErr {
        let message = message.into();
        Python::attach(|py| match self.class(py) {
            Ok(class) => PyErr::from_type(class.clone(), message),
            Err(e) => e,
        })
    }
}

/// The kind of a run's error.
pub fn kind_of_problem(e: &ProblemError) -> Kind {
    match e {
        ProblemError::AtStep { source, .. } => kind_of_problem(source),
        // a group the scene names and the mesh lacks is the mesh's error, wherever it is found
        ProblemError::Mesh(_) | ProblemError::Assembly(fe_assembly::AssemblyError::Mesh(_)) => Kind::Mesh,
        // a backend that does not solve the scene: the scene asks for another (a ValueError, by key)
        ProblemError::Scene(_)
        | ProblemError::Setup(_)
        | ProblemError::Unsupported(_)
        | ProblemError::Assembly(_)
        | ProblemError::Material(_) => Kind::Input,
        ProblemError::Linalg(_)
        | ProblemError::NotFinite { .. }
        | ProblemError::TooLarge { .. }
        | ProblemError::IllConditioned { .. } => Kind::Solver,
        // a residual that is not a number: the data overflowed, the solve did not fail to converge
        ProblemError::Contact { source, .. } if source.residual().is_some_and(|r| !r.is_finite()) => Kind::Solver,
        // not converged: within its iterations, or within the time `run` was given; one more
        // unknown (a depth, a potential) not found
        ProblemError::Contact { .. } | ProblemError::NoSolution { .. } => Kind::Convergence,
        ProblemError::Interrupted {
            why: contact::Interruption::Deadline,
            ..
        } => Kind::Convergence,
        ProblemError::Interrupted { .. } => Kind::Base,
        // a kind the core adds later (its errors are non-exhaustive): the base class until it
        // is given its own
        _ => Kind::Base,
    }
}

/// The kind of an error of the files or the run.
pub fn kind_of(e: &Error) -> Kind {
    match e {
        Error::Scene { .. } | Error::File { .. } | Error::Usage(_) => Kind::Input,
        Error::Mesh(_) => Kind::Mesh,
        Error::Problem(p) => kind_of_problem(p),
        Error::Output { .. } | Error::OutputConflict { .. } | Error::Picture { .. } => Kind::Output,
        _ => Kind::Base,
    }
}

/// The exception of an error of the files or the run, with its message; where the error is a
/// scene value's, its `key` attribute names the key (`None` elsewhere).
pub fn to_py(e: Error) -> PyErr {
    let err = kind_of(&e).err(e.to_string());
    let key = scene_key(&e);
    Python::attach(|py| {
        // an exception without the attribute is still the right exception
        let _ = err.value(py).setattr("key", key);
    });
    err
}

/// The scene key an error names: a value the scene's validation refused, or the key of an
/// override that does not apply.
pub fn scene_key(e: &Error) -> Option<String> {
    match e {
        Error::Scene {
            source: files::SceneFileError::Invalid(s),
            ..
        }
        | Error::Problem(ProblemError::Scene(s)) => Some(s.key.clone()),
        Error::Problem(ProblemError::Setup(s)) => Some(s.key.clone()),
        Error::Problem(ProblemError::Unsupported(u)) => Some(u.key.clone()),
        Error::Problem(ProblemError::NoSolution { sought, .. }) => Some(sought.to_string()),
        Error::Scene {
            source: files::SceneFileError::Override { key, .. },
            ..
        } => Some(key.clone()),
        _ => None,
    }
}

/// The exception of a mesh error, with its message.
pub fn mesh_err(e: mesh::MeshError) -> PyErr {
    Kind::Mesh.err(format!("mesh: {e}"))
}

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    for k in Kind::ALL {
        m.add(k.spec().0, k.class(m.py())?)?;
    }
    Ok(())
}
