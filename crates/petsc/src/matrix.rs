//! A parallel sparse matrix (`MATAIJ`: `MATMPIAIJ` on several ranks, `MATSEQAIJ` on one).
//!
//! Rows are owned in contiguous ranges. Entries may be added on any rank; PETSc's assembly
//! sends the off-rank ones to their owners. Preallocation is by row: `d_nnz[i]` entries of row
//! `i` in this rank's own column range (the diagonal block), `o_nnz[i]` outside it.

use std::marker::PhantomData;
use std::ops::Range;

use petsc_sys as sys;

use crate::error::{check, PetscError, Result};
use crate::petsc::{index, Index, Petsc};
use crate::vector::Vector;

/// A parallel sparse matrix in PETSc's AIJ (compressed row) format.
#[derive(Debug)]
pub struct Matrix<'p> {
    pub(crate) raw: sys::Mat,
    pub(crate) petsc: &'p Petsc,
    _not_send: PhantomData<*const ()>,
}

impl<'p> Matrix<'p> {
    /// A square matrix with `local` rows (and columns) on this rank and `global` in all,
    /// preallocated by row. Adding an entry outside the preallocation is an error, not a slow
    /// reallocation.
    pub fn aij(petsc: &'p Petsc, local: usize, global: usize, d_nnz: &[Index], o_nnz: &[Index]) -> Result<Self> {
        Matrix::aij_blocked(petsc, local, global, 1, d_nnz, o_nnz)
    }

    /// As [`Matrix::aij`], with `bs` unknowns per node (interlaced; `local` a multiple of it):
    /// algebraic multigrid aggregates nodes, not single unknowns.
    pub fn aij_blocked(
        petsc: &'p Petsc,
        local: usize,
        global: usize,
        bs: usize,
        d_nnz: &[Index],
        o_nnz: &[Index],
    ) -> Result<Self> {
        if d_nnz.len() != local || o_nnz.len() != local {
            return Err(PetscError::Argument(format!(
                "preallocation for {} and {} rows, the matrix has {local} rows on this rank",
                d_nnz.len(),
                o_nnz.len()
            )));
        }
        if bs == 0 || !local.is_multiple_of(bs) {
            return Err(PetscError::Argument(format!(
                "{local} rows are not whole blocks of {bs}"
            )));
        }
        let (l, g) = (
            index("a matrix's local rows", local)?,
            index("a matrix's rows", global)?,
        );
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; `raw` receives the matrix.
        check("MatCreate", unsafe { sys::MatCreate(petsc.comm(), &mut raw) })?;
        let m = Matrix {
            raw,
            petsc,
            _not_send: PhantomData,
        };
        let aij = c"aij";
        // SAFETY: a live matrix, configured in PETSc's order (sizes, block size, type, then
        // preallocation); the preallocation arrays have `local` entries each. Of the two
        // preallocation calls, the one of the matrix's actual type acts, the other is a no-op.
        unsafe {
            check("MatSetSizes", sys::MatSetSizes(m.raw, l, l, g, g))?;
            check(
                "MatSetBlockSize",
                sys::MatSetBlockSize(m.raw, index("a block size", bs)?),
            )?;
            check("MatSetType", sys::MatSetType(m.raw, aij.as_ptr()))?;
            check(
                "MatSeqAIJSetPreallocation",
                sys::MatSeqAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr()),
            )?;
            check(
                "MatMPIAIJSetPreallocation",
                sys::MatMPIAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()),
            )?;
            check(
                "MatSetOption",
                sys::MatSetOption(
                    m.raw,
                    sys::MatOption::MAT_NEW_NONZERO_ALLOCATION_ERR,
                    sys::PetscBool::PETSC_TRUE,
                ),
            )?;
        }
        Ok(m)
    }

    /// A copy (structure and values; the block size and near null space too).
    pub fn duplicate(&self) -> Result<Self> {
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: a live, assembled matrix; `raw` receives the copy.
        check("MatDuplicate", unsafe {
            sys::MatDuplicate(self.raw, sys::MatDuplicateOption::MAT_COPY_VALUES, &mut raw)
        })?;
        Ok(Matrix {
            raw,
            petsc: self.petsc,
            _not_send: PhantomData,
        })
    }

    /// Row `r` (one this rank owns) of an assembled matrix: its columns (global, increasing)
    /// and values.
    pub fn row(&self, r: Index) -> Result<(Vec<Index>, Vec<f64>)> {
        let mut n: Index = 0;
        let (mut cols, mut vals): (*const Index, *const f64) = (std::ptr::null(), std::ptr::null());
        // SAFETY: a live, assembled matrix; the arrays hold `n` entries until restored below.
        unsafe {
            check("MatGetRow", sys::MatGetRow(self.raw, r, &mut n, &mut cols, &mut vals))?;
            let len = n.max(0) as usize;
            let out = if len == 0 {
                (vec![], vec![])
            } else {
                (
                    std::slice::from_raw_parts(cols, len).to_vec(),
                    std::slice::from_raw_parts(vals, len).to_vec(),
                )
            };
            check(
                "MatRestoreRow",
                sys::MatRestoreRow(self.raw, r, &mut n, &mut cols, &mut vals),
            )?;
            Ok(out)
        }
    }

    /// The rows this rank owns.
    pub fn ownership(&self) -> Result<Range<usize>> {
        let (mut lo, mut hi): (Index, Index) = (0, 0);
        // SAFETY: a live matrix.
        check("MatGetOwnershipRange", unsafe {
            sys::MatGetOwnershipRange(self.raw, &mut lo, &mut hi)
        })?;
        Ok(lo as usize..hi as usize)
    }

    /// Adds the dense block `values` (row-major, `rows.len() x cols.len()`) at global
    /// `rows` x `cols`; negative indices are skipped (PETSc's convention). Call
    /// [`Matrix::assemble`] before use.
    pub fn add_values(&mut self, rows: &[Index], cols: &[Index], values: &[f64]) -> Result<()> {
        self.values(rows, cols, values, sys::InsertMode::ADD_VALUES)
    }

    /// As [`Matrix::add_values`], but setting the entries.
    pub fn set_values(&mut self, rows: &[Index], cols: &[Index], values: &[f64]) -> Result<()> {
        self.values(rows, cols, values, sys::InsertMode::INSERT_VALUES)
    }

    fn values(&mut self, rows: &[Index], cols: &[Index], values: &[f64], mode: sys::InsertMode::Type) -> Result<()> {
        if rows.len() * cols.len() != values.len() {
            return Err(PetscError::Argument(format!(
                "a {}x{} block given {} values",
                rows.len(),
                cols.len(),
                values.len()
            )));
        }
        // SAFETY: a live matrix; the arrays have the lengths passed.
        check("MatSetValues", unsafe {
            sys::MatSetValues(
                self.raw,
                index("a block's rows", rows.len())?,
                rows.as_ptr(),
                index("a block's columns", cols.len())?,
                cols.as_ptr(),
                values.as_ptr(),
                mode,
            )
        })
    }

    /// Completes the additions: off-rank entries go to their owners (collective).
    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: a live matrix; collective, as the caller's code is.
        unsafe {
            check(
                "MatAssemblyBegin",
                sys::MatAssemblyBegin(self.raw, sys::MatAssemblyType::MAT_FINAL_ASSEMBLY),
            )?;
            check(
                "MatAssemblyEnd",
                sys::MatAssemblyEnd(self.raw, sys::MatAssemblyType::MAT_FINAL_ASSEMBLY),
            )
        }
    }

    /// Declares the matrix symmetric (lets preconditioners and Krylov methods use it).
    pub fn set_symmetric(&mut self) -> Result<()> {
        // SAFETY: a live matrix.
        check("MatSetOption", unsafe {
            sys::MatSetOption(self.raw, sys::MatOption::MAT_SYMMETRIC, sys::PetscBool::PETSC_TRUE)
        })
    }

    /// `y = A x`.
    pub fn mult(&self, x: &Vector<'_>, y: &mut Vector<'_>) -> Result<()> {
        // SAFETY: live objects; PETSc checks the layouts.
        check("MatMult", unsafe { sys::MatMult(self.raw, x.raw, y.raw) })
    }

    /// The rigid-body modes of the nodes at `coords` (this rank's nodes, `dim` coordinates
    /// each, interlaced, in the matrix's row order) as the near null space that smoothed
    /// aggregation (GAMG) builds its coarse spaces from. The matrix's rows must be those nodes'
    /// `dim` displacements, interlaced.
    pub fn set_rigid_body_modes(&mut self, dim: usize, coords: &[f64]) -> Result<()> {
        let space = RigidBodyModes::new(self.petsc, dim, coords)?;
        // SAFETY: live objects; the matrix takes its own reference to the null space.
        check("MatSetNearNullSpace", unsafe {
            sys::MatSetNearNullSpace(self.raw, space.raw)
        })
    }

    /// Eliminates the rows and columns `rows` (global, any rank's) symmetrically: their
    /// entries become zero but a `diag` on the diagonal, and `b` is corrected so that the
    /// solution takes the values of `x` there (`b -= A_{:,rows} x_rows`, `b_rows = diag x_rows`).
    /// Collective.
    pub fn zero_rows_columns(&mut self, rows: &[Index], diag: f64, x: &Vector<'_>, b: &mut Vector<'_>) -> Result<()> {
        // SAFETY: live objects; `rows` has the length passed.
        check("MatZeroRowsColumns", unsafe {
            sys::MatZeroRowsColumns(
                self.raw,
                index("a count of rows", rows.len())?,
                rows.as_ptr(),
                diag,
                x.raw,
                b.raw,
            )
        })
    }

    /// Entries stored on this rank, and the memory PETSc counts for them (bytes).
    pub fn local_info(&self) -> Result<(f64, f64)> {
        let mut info = sys::MatInfo::default();
        // SAFETY: a live, assembled matrix; `info` is written by PETSc.
        check("MatGetInfo", unsafe {
            sys::MatGetInfo(self.raw, sys::MatInfoType::MAT_LOCAL, &mut info)
        })?;
        Ok((info.nz_used, info.memory))
    }
}

impl Drop for Matrix<'_> {
    fn drop(&mut self) {
        // SAFETY: our reference to a live matrix, released once (a KSP holding it keeps its own).
        unsafe {
            sys::MatDestroy(&mut self.raw);
        }
    }
}

/// The rigid-body modes of a set of nodes (`MatNullSpaceCreateRigidBody`), released on drop.
pub(crate) struct RigidBodyModes {
    pub(crate) raw: sys::MatNullSpace,
}

impl RigidBodyModes {
    /// The modes of this rank's nodes at `coords` (`dim` coordinates each, interlaced).
    pub(crate) fn new(petsc: &Petsc, dim: usize, coords: &[f64]) -> Result<Self> {
        if dim == 0 || !coords.len().is_multiple_of(dim) {
            return Err(PetscError::Argument(format!(
                "{} coordinates are not whole points of dimension {dim}",
                coords.len()
            )));
        }
        let v = Vector::from_local(petsc, coords)?;
        // SAFETY: a live vector.
        check("VecSetBlockSize", unsafe {
            sys::VecSetBlockSize(v.raw, index("a dimension", dim)?)
        })?;
        let mut raw: sys::MatNullSpace = std::ptr::null_mut();
        // SAFETY: a live vector with its block size; the space copies what it needs.
        check("MatNullSpaceCreateRigidBody", unsafe {
            sys::MatNullSpaceCreateRigidBody(v.raw, &mut raw)
        })?;
        Ok(RigidBodyModes { raw })
    }
}

impl Drop for RigidBodyModes {
    fn drop(&mut self) {
        // SAFETY: our reference, released once.
        unsafe {
            sys::MatNullSpaceDestroy(&mut self.raw);
        }
    }
}
