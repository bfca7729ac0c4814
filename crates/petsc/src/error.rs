//! PETSc's errors as a typed error: the call that failed, PETSc's code, and PETSc's message.
//!
//! [`install_handler`] replaces PETSc's error handler (which prints a traceback) by one that
//! records the first message of an error and returns its code; [`check`] turns a call's code
//! into a [`PetscError`] with that message.

use std::cell::RefCell;
use std::ffi::{c_char, c_int, c_void, CStr};

use petsc_sys as sys;

/// Bytes in a MiB.
const MIB: f64 = (1u64 << 20) as f64;

/// The result of a call into PETSc.
pub type Result<T> = std::result::Result<T, PetscError>;

/// What went wrong in a call into PETSc, or in the layer's own checks around it.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PetscError {
    /// A PETSc routine returned an error code.
    #[error("PETSc: {call} failed (error {code}): {message}")]
    Call {
        /// The routine called (e.g. `KSPSolve`).
        call: &'static str,
        /// PETSc's error code (`PETSC_ERR_*`).
        code: i32,
        /// PETSc's message: the specific one of the failing routine when there is one, else the
        /// code's generic text.
        message: String,
    },
    /// An MPI routine returned an error code.
    #[error("MPI: {call} failed (error {code})")]
    Mpi {
        /// The routine called.
        call: &'static str,
        /// MPI's error code.
        code: i32,
    },
    /// PETSc is initialised once per process, and cannot be initialised again after
    /// finalisation.
    #[error("PETSc is already initialised in this process (or was finalised: it cannot start again)")]
    AlreadyInitialised,
    /// A size or an index does not fit PETSc's integer (`PetscInt`, 32 bits in Debian's build).
    #[error("{what} = {value} does not fit PETSc's index type (at most {max}); build PETSc with 64-bit indices")]
    IndexOverflow {
        /// What was being converted.
        what: &'static str,
        /// Its value.
        value: usize,
        /// The largest `PetscInt`.
        max: i64,
    },
    /// The arguments of a call do not agree with each other (lengths, ranges).
    #[error("{0}")]
    Argument(String),
    /// MUMPS failed (its `INFOG(1)` negative).
    #[error("MUMPS: the {what} failed (INFOG(1) = {info}, INFOG(2) = {detail}): {meaning}")]
    Mumps {
        /// The phase (analysis, factorisation, a solve's half).
        what: &'static str,
        /// MUMPS' `INFOG(1)`.
        info: i32,
        /// MUMPS' `INFOG(2)`, the detail of the error.
        detail: i32,
        /// What the code means.
        meaning: String,
    },
    /// MUMPS' analysis estimates more memory for its factorisation on a rank than the rank
    /// may use: refused before the factorisation allocates it.
    #[error("MUMPS' analysis estimates {:.0} MiB on its most loaded rank for the factorisation, more than the {:.0} MiB a rank has for it", *needed as f64 / MIB, *available as f64 / MIB)]
    MumpsTooLarge {
        /// MUMPS' estimate (`INFOG(16)`, millions of bytes), bytes.
        needed: u64,
        /// What a rank may use, bytes.
        available: u64,
    },
    /// A Krylov solve stopped without converging; `reason` is PETSc's `KSPConvergedReason`.
    #[error("the Krylov solve did not converge: {reason} after {iterations} iterations (residual norm {residual_norm:.3e}); try other -ksp_type/-pc_type options, or -ksp_max_it")]
    KspDiverged {
        /// PETSc's name of the reason (e.g. `DIVERGED_ITS`).
        reason: String,
        /// Iterations done.
        iterations: usize,
        /// The last residual norm.
        residual_norm: f64,
    },
}

thread_local! {
    /// The first message of the error being raised (PETSc calls the handler once per level of
    /// its traceback; the first call carries the specific message).
    static LAST: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// PETSc's error handler while the layer is in use: records the first message, returns `n`.
/// It neither prints nor panics (a panic cannot cross this `extern "C"` boundary).
unsafe extern "C" fn record(
    _comm: sys::MPI_Comm,
    line: c_int,
    func: *const c_char,
    file: *const c_char,
    n: sys::PetscErrorCode,
    p: sys::PetscErrorType::Type,
    mess: *const c_char,
    _ctx: *mut c_void,
) -> sys::PetscErrorCode {
    if p == sys::PetscErrorType::PETSC_ERROR_INITIAL {
        // SAFETY: PETSc passes NUL-terminated strings or null pointers.
        let text =
            |s: *const c_char| unsafe { (!s.is_null()).then(|| CStr::from_ptr(s).to_string_lossy().into_owned()) };
        let message = match (text(mess), text(func), text(file)) {
            (Some(m), Some(f), Some(file)) if !m.is_empty() => format!("{m} (in {f}, {file}:{line})"),
            (Some(m), _, _) => m,
            _ => String::new(),
        };
        LAST.with(|l| *l.borrow_mut() = Some(message));
    }
    n
}

/// Makes [`record`] PETSc's error handler.
pub(crate) fn install_handler() -> Result<()> {
    // SAFETY: PETSc is initialised (called from `Petsc::init`), `record` has the handler's type.
    let code = unsafe { sys::PetscPushErrorHandler(Some(record), std::ptr::null_mut()) };
    check("PetscPushErrorHandler", code)
}

/// Turns a PETSc return code into a result, with the message the handler recorded.
pub(crate) fn check(call: &'static str, code: sys::PetscErrorCode) -> Result<()> {
    if code == 0 {
        LAST.with(|l| l.borrow_mut().take());
        return Ok(());
    }
    let specific = LAST.with(|l| l.borrow_mut().take()).filter(|m| !m.is_empty());
    let message = specific.unwrap_or_else(|| generic(code));
    Err(PetscError::Call { call, code, message })
}

/// PETSc's generic text for an error code.
fn generic(code: sys::PetscErrorCode) -> String {
    let mut text: *const c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage writes a pointer to a static string (or leaves it null).
    let rc = unsafe { sys::PetscErrorMessage(code, &mut text, std::ptr::null_mut()) };
    if rc != 0 || text.is_null() {
        return "unknown error".to_owned();
    }
    // SAFETY: a static NUL-terminated string of PETSc's.
    unsafe { CStr::from_ptr(text) }.to_string_lossy().into_owned()
}

/// Checks an MPI return code.
pub(crate) fn check_mpi(call: &'static str, code: c_int) -> Result<()> {
    if code == 0 {
        Ok(())
    } else {
        Err(PetscError::Mpi { call, code })
    }
}
