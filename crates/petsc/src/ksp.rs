//! Krylov solvers and their preconditioners (`KSP`, `PC`), and index sets (`IS`) for field
//! splits.

use std::ffi::{CStr, CString};
use std::marker::PhantomData;

use petsc_sys as sys;

use crate::error::{check, PetscError, Result};
use crate::matrix::{Matrix, RigidBodyModes};
use crate::petsc::{index, Index, Petsc};
use crate::vector::Vector;

/// A Krylov solver with its preconditioner, for one operator.
#[derive(Debug)]
pub struct Ksp<'p> {
    raw: sys::KSP,
    _petsc: &'p Petsc,
    _not_send: PhantomData<*const ()>,
}

/// What a solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct KspInfo {
    /// Krylov iterations.
    pub iterations: usize,
    /// The last residual norm the method saw (preconditioned or not, as the method uses).
    pub residual_norm: f64,
    /// PETSc's name of the reason it stopped (e.g. `CONVERGED_RTOL`).
    pub reason: String,
}

fn c_string(what: &str, s: &str) -> Result<CString> {
    CString::new(s).map_err(|_| PetscError::Argument(format!("{what} {s:?} contains a NUL byte")))
}

impl<'p> Ksp<'p> {
    /// A solver for `a` (which is also the matrix the preconditioner is built from). PETSc
    /// keeps its own reference to `a`.
    pub fn new(petsc: &'p Petsc, a: &Matrix<'p>) -> Result<Self> {
        let mut raw: sys::KSP = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; `raw` receives the solver.
        check("KSPCreate", unsafe { sys::KSPCreate(petsc.comm(), &mut raw) })?;
        let ksp = Ksp {
            raw,
            _petsc: petsc,
            _not_send: PhantomData,
        };
        // SAFETY: live objects.
        check("KSPSetOperators", unsafe {
            sys::KSPSetOperators(ksp.raw, a.raw, a.raw)
        })?;
        Ok(ksp)
    }

    fn pc(&self) -> Result<sys::PC> {
        let mut pc: sys::PC = std::ptr::null_mut();
        // SAFETY: a live solver; the PC is borrowed, not referenced.
        check("KSPGetPC", unsafe { sys::KSPGetPC(self.raw, &mut pc) })?;
        Ok(pc)
    }

    /// The Krylov method and the preconditioner by PETSc's names (`"cg"`, `"gmres"`,
    /// `"preonly"`; `"gamg"`, `"hypre"`, `"fieldsplit"`, `"lu"`, `"jacobi"`, ...).
    pub fn set_types(&mut self, ksp_type: &str, pc_type: &str) -> Result<()> {
        let (k, p) = (c_string("a KSP type", ksp_type)?, c_string("a PC type", pc_type)?);
        // SAFETY: live objects; PETSc copies the names.
        unsafe {
            check("KSPSetType", sys::KSPSetType(self.raw, k.as_ptr()))?;
            check("PCSetType", sys::PCSetType(self.pc()?, p.as_ptr()))
        }
    }

    /// Relative and absolute tolerances on the residual norm, and the iteration limit.
    pub fn set_tolerances(&mut self, rtol: f64, atol: f64, max_iters: usize) -> Result<()> {
        // SAFETY: a live solver; PETSC_DEFAULT (-2) keeps the divergence tolerance.
        check("KSPSetTolerances", unsafe {
            sys::KSPSetTolerances(self.raw, rtol, atol, -2.0, index("an iteration limit", max_iters)?)
        })
    }

    /// The relative tolerance on the residual norm in force (after the options are read).
    pub fn relative_tolerance(&self) -> Result<f64> {
        let (mut rtol, mut atol, mut dtol) = (0.0, 0.0, 0.0);
        let mut max_iters: sys::PetscInt = 0;
        // SAFETY: a live solver; PETSc writes the four values.
        check("KSPGetTolerances", unsafe {
            sys::KSPGetTolerances(self.raw, &mut rtol, &mut atol, &mut dtol, &mut max_iters)
        })?;
        Ok(rtol)
    }

    /// The relative tolerance on the residual norm alone (the others kept).
    pub fn set_relative_tolerance(&mut self, rtol: f64) -> Result<()> {
        // SAFETY: a live solver; PETSC_DEFAULT (-2) keeps the absolute and divergence
        // tolerances and the iteration limit.
        check("KSPSetTolerances", unsafe {
            sys::KSPSetTolerances(self.raw, rtol, -2.0, -2.0, -2)
        })
    }

    /// The divergence tolerance alone (the others kept): the solve stops as diverged where
    /// the residual norm exceeds `dtol` times the right-hand side's (PETSc's default `1e5`).
    pub fn set_divergence_tolerance(&mut self, dtol: f64) -> Result<()> {
        // SAFETY: a live solver; PETSC_DEFAULT (-2) keeps the others.
        check("KSPSetTolerances", unsafe {
            sys::KSPSetTolerances(self.raw, -2.0, -2.0, dtol, -2)
        })
    }

    /// The prefix of this solver's options in the database (`"elastic_"` reads
    /// `-elastic_ksp_type`, ...).
    pub fn set_options_prefix(&mut self, prefix: &str) -> Result<()> {
        let p = c_string("an options prefix", prefix)?;
        // SAFETY: a live solver; PETSc copies the prefix.
        check("KSPSetOptionsPrefix", unsafe {
            sys::KSPSetOptionsPrefix(self.raw, p.as_ptr())
        })
    }

    /// Reads the options database (`-ksp_type`, `-pc_type`, `-ksp_monitor`, ... with the
    /// prefix): what the user passed overrides what the code set before this call.
    pub fn set_from_options(&mut self) -> Result<()> {
        // SAFETY: a live solver.
        check("KSPSetFromOptions", unsafe { sys::KSPSetFromOptions(self.raw) })
    }

    /// Names the unknowns `is` as the field `name` of a `fieldsplit` preconditioner.
    pub fn set_field(&mut self, name: &str, is: &IndexSet<'p>) -> Result<()> {
        let n = c_string("a field name", name)?;
        // SAFETY: live objects; PETSc references the index set.
        check("PCFieldSplitSetIS", unsafe {
            sys::PCFieldSplitSetIS(self.pc()?, n.as_ptr(), is.raw)
        })
    }

    /// The Krylov method's name (`"cg"`, `"fgmres"`, `"preonly"`, ...), as configured.
    pub fn kind(&self) -> Result<String> {
        let mut name: sys::KSPType = std::ptr::null();
        // SAFETY: a live solver; the name is PETSc's static string (or null before a type is set).
        check("KSPGetType", unsafe { sys::KSPGetType(self.raw, &mut name) })?;
        if name.is_null() {
            return Ok(String::new());
        }
        // SAFETY: a NUL-terminated string of PETSc's.
        Ok(unsafe { CStr::from_ptr(name) }.to_string_lossy().into_owned())
    }

    /// Starts from the values in `x` instead of zero.
    pub fn set_initial_guess_nonzero(&mut self, nonzero: bool) -> Result<()> {
        let flag = if nonzero {
            sys::PetscBool::PETSC_TRUE
        } else {
            sys::PetscBool::PETSC_FALSE
        };
        // SAFETY: a live solver.
        check("KSPSetInitialGuessNonzero", unsafe {
            sys::KSPSetInitialGuessNonzero(self.raw, flag)
        })
    }

    /// Builds the preconditioner now (otherwise the first solve does): lets a caller time the
    /// set-up apart from the solve.
    pub fn set_up(&mut self) -> Result<()> {
        // SAFETY: a live solver with its operators.
        check("KSPSetUp", unsafe { sys::KSPSetUp(self.raw) })
    }

    /// Solves `A x = b`. A solve that stops without converging is
    /// [`PetscError::KspDiverged`], with its reason.
    pub fn solve(&mut self, b: &Vector<'_>, x: &mut Vector<'_>) -> Result<KspInfo> {
        // SAFETY: live objects; PETSc checks the layouts.
        check("KSPSolve", unsafe { sys::KSPSolve(self.raw, b.raw, x.raw) })?;
        let (mut its, mut reason, mut rnorm): (Index, sys::KSPConvergedReason::Type, f64) = (0, 0, 0.0);
        // SAFETY: a live solver after a solve.
        unsafe {
            check("KSPGetIterationNumber", sys::KSPGetIterationNumber(self.raw, &mut its))?;
            check(
                "KSPGetConvergedReason",
                sys::KSPGetConvergedReason(self.raw, &mut reason),
            )?;
            check("KSPGetResidualNorm", sys::KSPGetResidualNorm(self.raw, &mut rnorm))?;
        }
        let info = KspInfo {
            iterations: its.max(0) as usize,
            residual_norm: rnorm,
            reason: reason_name(reason),
        };
        if reason < 0 {
            return Err(PetscError::KspDiverged {
                reason: info.reason,
                iterations: info.iterations,
                residual_norm: rnorm,
            });
        }
        Ok(info)
    }
}

/// PETSc's name of a `KSPConvergedReason`.
fn reason_name(reason: sys::KSPConvergedReason::Type) -> String {
    // SAFETY: `KSPConvergedReasons` points into PETSc's table of names, shifted so that it is
    // indexed by the reason itself (from -11 to 9 in PETSc 3.18); out of that range we give the
    // number.
    unsafe {
        let table = sys::KSPConvergedReasons;
        if table.is_null() || !(-11..=9).contains(&reason) {
            return format!("reason {reason}");
        }
        let name = *table.offset(reason as isize);
        if name.is_null() {
            format!("reason {reason}")
        } else {
            CStr::from_ptr(name).to_string_lossy().into_owned()
        }
    }
}

impl Drop for Ksp<'_> {
    fn drop(&mut self) {
        // SAFETY: our live solver, released once.
        unsafe {
            sys::KSPDestroy(&mut self.raw);
        }
    }
}

/// A parallel set of global indices (`IS`): this rank's part of a field, say.
#[derive(Debug)]
pub struct IndexSet<'p> {
    pub(crate) raw: sys::IS,
    petsc: &'p Petsc,
    _not_send: PhantomData<*const ()>,
}

impl<'p> IndexSet<'p> {
    /// The set of this rank's `indices` (global; PETSc copies them).
    pub fn new(petsc: &'p Petsc, indices: &[Index]) -> Result<Self> {
        let mut raw: sys::IS = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; the array has the length passed and is copied.
        check("ISCreateGeneral", unsafe {
            sys::ISCreateGeneral(
                petsc.comm(),
                index("an index set's size", indices.len())?,
                indices.as_ptr(),
                sys::PetscCopyMode::PETSC_COPY_VALUES,
                &mut raw,
            )
        })?;
        Ok(IndexSet {
            raw,
            petsc,
            _not_send: PhantomData,
        })
    }

    /// The block size of the set (unknowns per node, interlaced), which the field's
    /// sub-matrix inherits in a field split.
    pub fn set_block_size(&mut self, bs: usize) -> Result<()> {
        // SAFETY: a live index set.
        check("ISSetBlockSize", unsafe {
            sys::ISSetBlockSize(self.raw, index("a block size", bs)?)
        })
    }

    /// The rigid-body modes of the field's nodes (`dim` coordinates each, interlaced, in the
    /// set's order) as the near null space of its sub-matrix in a field split (PCFIELDSPLIT
    /// looks for a `"nearnullspace"` composed with the set), for algebraic multigrid.
    pub fn set_rigid_body_modes(&mut self, dim: usize, coords: &[f64]) -> Result<()> {
        let space = RigidBodyModes::new(self.petsc, dim, coords)?;
        let name = c"nearnullspace";
        // SAFETY: live objects; composing takes a reference to the space.
        check("PetscObjectCompose", unsafe {
            sys::PetscObjectCompose(self.raw.cast(), name.as_ptr(), space.raw.cast())
        })
    }
}

impl Drop for IndexSet<'_> {
    fn drop(&mut self) {
        // SAFETY: our live index set, released once.
        unsafe {
            sys::ISDestroy(&mut self.raw);
        }
    }
}
