//! `run(scene)`: the solve on a worker thread with the GIL released, its progress lines passed
//! to Python by the calling thread, which also watches for signals: Ctrl-C sets the run's
//! cancel flag, the run stops at its next check (between steps, or at the next iteration of
//! the contact solve), and `KeyboardInterrupt` is raised with nothing written.

use crate::errors::to_py;
use crate::result::{RunResult, Series};
use crate::scene::Scene;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

thread_local! {
    /// The cancel flags this thread's runs are not using. `Interrupt` takes a flag that lives
    /// for the program, so a flag is made once and kept; each run takes its own (a run started
    /// from a progress callback of another is nested in it, and must not share its flag) and
    /// gives it back when it ends.
    static FREE: std::cell::RefCell<Vec<&'static AtomicBool>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A cancel flag of its own for one run, cleared, given back to [`FREE`] when dropped.
struct Flag(&'static AtomicBool);

impl Flag {
    fn take() -> Self {
        let flag = FREE
            .with(|f| f.borrow_mut().pop())
            .unwrap_or_else(|| Box::leak(Box::new(AtomicBool::new(false))));
        flag.store(false, Ordering::Relaxed);
        Flag(flag)
    }
}

impl Drop for Flag {
    fn drop(&mut self) {
        FREE.with(|f| f.borrow_mut().push(self.0));
    }
}

/// How often the calling thread looks for signals while the solve runs.
const POLL: Duration = Duration::from_millis(50);

/// A reporter that sends each event's line to the calling thread.
struct Send(mpsc::Sender<String>);

impl problem::Reporter for Send {
    fn event(&mut self, event: &problem::Event<'_>) {
        if let Some(line) = event.line() {
            // the receiver outlives the solve; a send can only fail once it is gone
            let _ = self.0.send(line);
        }
    }
}

/// Where the progress lines go.
enum Progress<'py> {
    Quiet,
    Stderr(Bound<'py, PyAny>),
    Call(Bound<'py, PyAny>),
}

impl<'py> Progress<'py> {
    fn of(py: Python<'py>, progress: &Bound<'py, PyAny>) -> PyResult<Self> {
        if progress.is_callable() {
            return Ok(Progress::Call(progress.clone()));
        }
        Ok(if progress.is_truthy()? {
            Progress::Stderr(py.import("sys")?.getattr("stderr")?)
        } else {
            Progress::Quiet
        })
    }

    fn line(&self, line: &str) -> PyResult<()> {
        match self {
            Progress::Quiet => {}
            Progress::Stderr(err) => {
                err.call_method1("write", (format!("{line}\n"),))?;
                err.call_method0("flush")?;
            }
            Progress::Call(f) => {
                f.call1((line,))?;
            }
        }
        Ok(())
    }
}

/// A scene for the PETSc backend: what that backend would not solve, first (as the program
/// built without it says); the default backend then refuses another's scene.
fn petsc_supports(scene: &problem::Scene) -> PyResult<()> {
    if scene.solver.backend != problem::BackendChoice::Petsc {
        return Ok(());
    }
    distributed::supports(scene).map_err(|e| to_py(problem::ProblemError::from(e).into()))
}

/// The instant a run given `timeout` seconds stops at: none for no timeout, for `inf` and for
/// a limit beyond the clock's end; at the first check for 0.
fn deadline(timeout: Option<f64>) -> PyResult<Option<std::time::Instant>> {
    let now = std::time::Instant::now();
    Ok(match timeout {
        Some(0.0) => Some(now),
        Some(t) => files::limits::seconds(t, "timeout =")
            .map_err(to_py)?
            .and_then(|d| now.checked_add(d)),
        None => None,
    })
}

/// Solves `scene` and returns its `Result`. `progress`: False (nothing), True (a line per step
/// and per outer contact iteration on `sys.stderr`), or a callable that takes each line.
/// `series`: for a scene with a `[path]`, keep the contact values of every point at every
/// instant (`Result.path`'s `lambda_n`, ...); the rows are kept either way.
/// `timeout`: seconds after which the run stops at its next check (`ConvergenceError`).
/// Ctrl-C stops the run at its next check and raises `KeyboardInterrupt`; nothing is
/// written. Errors: `InputError`, `MeshError`, `SolverError`, `ConvergenceError`.
#[pyfunction]
#[pyo3(signature = (scene, progress = None, timeout = None, series = false))]
pub fn run(
    py: Python<'_>,
    scene: &Scene,
    progress: Option<&Bound<'_, PyAny>>,
    timeout: Option<f64>,
    series: bool,
) -> PyResult<RunResult> {
    petsc_supports(&scene.scene)?;
    let deadline = deadline(timeout)?;
    let progress = match progress {
        Some(p) => Progress::of(py, p)?,
        None => Progress::Quiet,
    };
    let flag = Flag::take();
    let cancel = flag.0;
    let interrupt = contact::Interrupt {
        deadline,
        cancel: Some(cancel),
    };
    let (tx, rx) = mpsc::channel();
    // `detach` takes a closure that may cross threads; a receiver is not `Sync`
    let rx = std::sync::Mutex::new(rx);
    let given = scene.mesh.as_deref().cloned();
    let (typed, source) = (&scene.scene, &scene.source);
    let mut signal: Option<PyErr> = None;
    let mut callback: Option<PyErr> = None;
    let solved = std::thread::scope(|s| {
        let worker = s.spawn(move || {
            let mut reporter = Send(tx);
            if !(series && typed.path.is_some()) {
                return files::run::solve_with(typed, source, given, interrupt, &mut reporter).map(|s| (s, None));
            }
            // every instant's contact values, kept
            let mut kept = Series::default();
            let each = &mut |step: problem::Step<'_>| {
                kept.push(step.contact);
                Ok(())
            };
            let solved = files::run::solve_path_with(typed, source, given, (interrupt, false), &mut reporter, each);
            solved.map(|s| (s, Some(kept)))
        });
        loop {
            match py.detach(|| {
                rx.lock()
                    .map_or(Err(mpsc::RecvTimeoutError::Disconnected), |r| r.recv_timeout(POLL))
            }) {
                Ok(line) => {
                    if callback.is_none() {
                        if let Err(e) = progress.line(&line) {
                            // a progress callback that raises stops the run, and its error is raised
                            callback = Some(e);
                            cancel.store(true, Ordering::Relaxed);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if signal.is_none() {
                if let Err(e) = py.check_signals() {
                    signal = Some(e);
                    cancel.store(true, Ordering::Relaxed);
                }
            }
        }
        py.detach(|| worker.join())
    });
    let solved = match solved {
        Ok(s) => s,
        Err(_) => return Err(crate::errors::Kind::Base.err("the solve panicked (a bug: please report it)")),
    };
    if let Some(e) = signal.or(callback) {
        if let Err(files::Error::Problem(p)) = &solved {
            if p.is_interrupted() {
                // say where the run stopped, beside the KeyboardInterrupt
                let note = format!("piezocontact: the run stopped: {p}");
                let value = e.value(py);
                // `add_note` is Python 3.11's; before, the list is only an attribute
                if value.call_method1("add_note", (&note,)).is_err() {
                    let _ = value.setattr("__notes__", vec![note]);
                }
            }
        }
        return Err(e);
    }
    solved
        .map(|(solution, series)| RunResult { solution, series })
        .map_err(to_py)
}

/// The capacitance matrix between the terminals of `scene` (its electrode and the groups at a
/// prescribed potential; the displacements it prescribes held at 0, no load, the contact face
/// free): a dict with `terminals` (names; groups joined by a node as one, `a+b`), `matrix`
/// (`C[i, j]`: the charge on terminal i per unit potential of terminal j), `asymmetry` and
/// `column_sum` (reciprocity and Gauss's law, relative: round-off), `unit` (the scene's
/// charge per its potential, e.g. `pC/kV`) and `notes` (what the set-up noted: an electrode
/// the mesh covers less of than its `x_range`, ...; a list of strings, empty where nothing).
/// Errors: `InputError`, `MeshError`, `SolverError`.
#[pyfunction]
pub fn capacitance<'py>(py: Python<'py>, scene: &Scene) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let given = scene.mesh.as_deref().cloned();
    let c = files::run::capacitance(&scene.scene, &scene.source, given).map_err(to_py)?;
    let n = c.terminals.len();
    let matrix = numpy::ndarray::Array2::from_shape_fn((n, n), |(i, j)| c.matrix[i][j]);
    let out = pyo3::types::PyDict::new(py);
    out.set_item("terminals", c.terminals)?;
    out.set_item("matrix", crate::arrays::owned(py, matrix))?;
    out.set_item("asymmetry", c.asymmetry)?;
    out.set_item("column_sum", c.column_sum)?;
    out.set_item("unit", c.unit)?;
    out.set_item("notes", c.notes)?;
    Ok(out)
}
