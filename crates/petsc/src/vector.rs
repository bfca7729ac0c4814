//! A parallel vector (`VECMPI`): each rank owns a contiguous range of the entries.

use std::marker::PhantomData;
use std::ops::Range;

use petsc_sys as sys;

use crate::error::{check, PetscError, Result};
use crate::petsc::{index, Index, Petsc};

/// A parallel PETSc vector; this rank owns the entries of [`Vector::ownership`].
#[derive(Debug)]
pub struct Vector<'p> {
    pub(crate) raw: sys::Vec,
    pub(crate) petsc: &'p Petsc,
    _not_send: PhantomData<*const ()>,
}

impl<'p> Vector<'p> {
    /// A vector with `local` entries on this rank (the global size is the sum over ranks),
    /// set to zero.
    pub fn mpi(petsc: &'p Petsc, local: usize) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: PETSc is initialised (borrowed); `raw` receives the new vector.
        check("VecCreateMPI", unsafe {
            sys::VecCreateMPI(
                petsc.comm(),
                index("a vector's local size", local)?,
                sys::PETSC_DETERMINE,
                &mut raw,
            )
        })?;
        let mut v = Vector::wrap(petsc, raw);
        v.set_all(0.0)?;
        Ok(v)
    }

    /// A vector with `local` entries on this rank, all equal to `value`.
    pub fn filled(petsc: &'p Petsc, local: usize, value: f64) -> Result<Self> {
        let mut v = Vector::mpi(petsc, local)?;
        v.set_all(value)?;
        Ok(v)
    }

    /// A vector whose owned entries are `local` (this rank's part, in order).
    pub fn from_local(petsc: &'p Petsc, local: &[f64]) -> Result<Self> {
        let mut v = Vector::mpi(petsc, local.len())?;
        v.with_local_mut(|x| x.copy_from_slice(local))?;
        Ok(v)
    }

    pub(crate) fn wrap(petsc: &'p Petsc, raw: sys::Vec) -> Self {
        Vector {
            raw,
            petsc,
            _not_send: PhantomData,
        }
    }

    /// A new vector of the same layout, set to zero.
    pub fn duplicate(&self) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: `self.raw` is a live vector.
        check("VecDuplicate", unsafe { sys::VecDuplicate(self.raw, &mut raw) })?;
        let mut v = Vector::wrap(self.petsc, raw);
        v.set_all(0.0)?;
        Ok(v)
    }

    /// A new vector of the same layout and values.
    pub fn copy(&self) -> Result<Self> {
        let v = self.duplicate()?;
        // SAFETY: live vectors of one layout.
        check("VecCopy", unsafe { sys::VecCopy(self.raw, v.raw) })?;
        Ok(v)
    }

    /// The global indices this rank owns.
    pub fn ownership(&self) -> Result<Range<usize>> {
        let (mut lo, mut hi): (Index, Index) = (0, 0);
        // SAFETY: a live vector.
        check("VecGetOwnershipRange", unsafe {
            sys::VecGetOwnershipRange(self.raw, &mut lo, &mut hi)
        })?;
        Ok(lo as usize..hi as usize)
    }

    /// Sets every entry to `value`.
    pub fn set_all(&mut self, value: f64) -> Result<()> {
        // SAFETY: a live vector.
        check("VecSet", unsafe { sys::VecSet(self.raw, value) })
    }

    /// Adds `values` at the global `indices` (any rank's); call [`Vector::assemble`] before use.
    pub fn add_values(&mut self, indices: &[Index], values: &[f64]) -> Result<()> {
        self.set_values_mode(indices, values, sys::InsertMode::ADD_VALUES)
    }

    /// Sets `values` at the global `indices` (any rank's); call [`Vector::assemble`] before use.
    pub fn set_values(&mut self, indices: &[Index], values: &[f64]) -> Result<()> {
        self.set_values_mode(indices, values, sys::InsertMode::INSERT_VALUES)
    }

    fn set_values_mode(&mut self, indices: &[Index], values: &[f64], mode: sys::InsertMode::Type) -> Result<()> {
        if indices.len() != values.len() {
            return Err(PetscError::Argument(format!(
                "{} indices for {} values",
                indices.len(),
                values.len()
            )));
        }
        // SAFETY: a live vector; both arrays hold `n` entries.
        check("VecSetValues", unsafe {
            sys::VecSetValues(
                self.raw,
                index("a count of values", indices.len())?,
                indices.as_ptr(),
                values.as_ptr(),
                mode,
            )
        })
    }

    /// Completes [`Vector::add_values`]/[`Vector::set_values`]: sends off-rank entries to
    /// their owners (collective).
    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: a live vector; collective on all ranks, as the caller's code is.
        unsafe {
            check("VecAssemblyBegin", sys::VecAssemblyBegin(self.raw))?;
            check("VecAssemblyEnd", sys::VecAssemblyEnd(self.raw))
        }
    }

    /// A copy of this rank's entries.
    pub fn local(&self) -> Result<Vec<f64>> {
        let n = self.ownership()?.len();
        let mut ptr: *const f64 = std::ptr::null();
        // SAFETY: the array holds the `n` owned entries until it is restored, just below.
        unsafe {
            check("VecGetArrayRead", sys::VecGetArrayRead(self.raw, &mut ptr))?;
            let out = if n == 0 {
                vec![]
            } else {
                std::slice::from_raw_parts(ptr, n).to_vec()
            };
            check("VecRestoreArrayRead", sys::VecRestoreArrayRead(self.raw, &mut ptr))?;
            Ok(out)
        }
    }

    /// Lets `f` change this rank's entries in place.
    pub fn with_local_mut<R>(&mut self, f: impl FnOnce(&mut [f64]) -> R) -> Result<R> {
        let n = self.ownership()?.len();
        let mut ptr: *mut f64 = std::ptr::null_mut();
        // SAFETY: the array holds the `n` owned entries, exclusively ours until restored; if
        // `f` panics the vector is left checked out, which PETSc tolerates until destruction.
        unsafe {
            check("VecGetArray", sys::VecGetArray(self.raw, &mut ptr))?;
            let slice: &mut [f64] = if n == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(ptr, n)
            };
            let r = f(slice);
            check("VecRestoreArray", sys::VecRestoreArray(self.raw, &mut ptr))?;
            Ok(r)
        }
    }

    /// The Euclidean norm (collective).
    pub fn norm(&self) -> Result<f64> {
        let mut n = 0.0;
        // SAFETY: a live vector.
        check("VecNorm", unsafe {
            sys::VecNorm(self.raw, sys::NormType::NORM_2, &mut n)
        })?;
        Ok(n)
    }

    /// `self += alpha x` (same layout).
    pub fn axpy(&mut self, alpha: f64, x: &Vector<'_>) -> Result<()> {
        // SAFETY: live vectors; PETSc checks the layouts.
        check("VecAXPY", unsafe { sys::VecAXPY(self.raw, alpha, x.raw) })
    }

    /// The whole vector, in global order, on rank 0 (`None` on the other ranks).
    pub fn gather(&self) -> Result<Option<Vec<f64>>> {
        self.petsc.gather_f64(&self.local()?)
    }

    /// The entries at the global `indices` (any rank's), in their order, on this rank: a
    /// `VecScatter` from this vector into a sequential one. Collective (every rank calls it,
    /// each with its own indices); what a rank receives is what it asks for, so a rank's
    /// memory grows with its own indices, never with the global size.
    pub fn fetch(&self, indices: &[Index]) -> Result<Vec<f64>> {
        let n = index("a count of entries to fetch", indices.len())?;
        let mut is: sys::IS = std::ptr::null_mut();
        let mut seq: sys::Vec = std::ptr::null_mut();
        let mut scatter: sys::VecScatter = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; the index set copies `indices`; the sequential vector
        // lives on this process alone (MPI_COMM_SELF, a predefined communicator); every object
        // created here is destroyed below on every path after its creation.
        unsafe {
            let comm_self: sys::MPI_Comm = (&raw mut sys::ompi_mpi_comm_self).cast();
            let created = check(
                "ISCreateGeneral",
                sys::ISCreateGeneral(
                    comm_self,
                    n,
                    indices.as_ptr(),
                    sys::PetscCopyMode::PETSC_COPY_VALUES,
                    &mut is,
                ),
            )
            .and_then(|()| check("VecCreateSeq", sys::VecCreateSeq(comm_self, n, &mut seq)))
            .and_then(|()| {
                check(
                    "VecScatterCreate",
                    sys::VecScatterCreate(self.raw, is, seq, std::ptr::null_mut(), &mut scatter),
                )
            })
            .and_then(|()| {
                check(
                    "VecScatterBegin",
                    sys::VecScatterBegin(
                        scatter,
                        self.raw,
                        seq,
                        sys::InsertMode::INSERT_VALUES,
                        sys::ScatterMode::SCATTER_FORWARD,
                    ),
                )
            })
            .and_then(|()| {
                check(
                    "VecScatterEnd",
                    sys::VecScatterEnd(
                        scatter,
                        self.raw,
                        seq,
                        sys::InsertMode::INSERT_VALUES,
                        sys::ScatterMode::SCATTER_FORWARD,
                    ),
                )
            });
            let out = created.and_then(|()| {
                let mut ptr: *const f64 = std::ptr::null();
                check("VecGetArrayRead", sys::VecGetArrayRead(seq, &mut ptr))?;
                let out = if indices.is_empty() {
                    vec![]
                } else {
                    std::slice::from_raw_parts(ptr, indices.len()).to_vec()
                };
                check("VecRestoreArrayRead", sys::VecRestoreArrayRead(seq, &mut ptr))?;
                Ok(out)
            });
            if !scatter.is_null() {
                sys::VecScatterDestroy(&mut scatter);
            }
            if !seq.is_null() {
                sys::VecDestroy(&mut seq);
            }
            if !is.is_null() {
                sys::ISDestroy(&mut is);
            }
            out
        }
    }
}

impl Drop for Vector<'_> {
    fn drop(&mut self) {
        // SAFETY: our reference to a live vector, released once.
        unsafe {
            sys::VecDestroy(&mut self.raw);
        }
    }
}
