//! The library handle: initialisation with MPI, the world communicator, the options database,
//! and the few collectives the backend needs (sums, maxima, gathers to rank 0).

use std::ffi::{c_int, c_void, CString};
use std::marker::PhantomData;
use std::sync::atomic::{AtomicBool, Ordering};

use petsc_sys as sys;

use crate::error::{check, check_mpi, install_handler, PetscError, Result};

/// PETSc's integer (`PetscInt`): indices and sizes as PETSc takes them.
pub type Index = sys::PetscInt;

/// Set once `PetscInitialize` has been called in this process: PETSc cannot start twice.
static STARTED: AtomicBool = AtomicBool::new(false);

/// PETSc, initialised (with MPI, if PETSc started it) for as long as this value lives.
///
/// One per process. Every PETSc object of this crate borrows it, so none outlives the
/// `PetscFinalize` that dropping it calls. Not `Send`: PETSc is called from one thread.
#[derive(Debug)]
pub struct Petsc {
    rank: usize,
    size: usize,
    _not_send: PhantomData<*const ()>,
}

impl Petsc {
    /// Initialises PETSc (and MPI) without command-line arguments: options come through
    /// [`Petsc::insert_options`] (and the `PETSC_OPTIONS` environment variable, which PETSc reads).
    pub fn init() -> Result<Self> {
        if STARTED.swap(true, Ordering::SeqCst) {
            return Err(PetscError::AlreadyInitialised);
        }
        // SAFETY: first and only initialisation in this process (checked above); PETSc accepts
        // null argc/argv, file and help.
        let code = unsafe {
            sys::PetscInitialize(
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null(),
                std::ptr::null(),
            )
        };
        check("PetscInitialize", code)?;
        install_handler()?;
        let (mut rank, mut size): (c_int, c_int) = (0, 0);
        // SAFETY: PETSc is initialised, so is MPI; the communicator is PETSc's world.
        unsafe {
            check_mpi("MPI_Comm_rank", sys::MPI_Comm_rank(sys::PETSC_COMM_WORLD, &mut rank))?;
            check_mpi("MPI_Comm_size", sys::MPI_Comm_size(sys::PETSC_COMM_WORLD, &mut size))?;
        }
        Ok(Petsc {
            rank: rank as usize,
            size: size as usize,
            _not_send: PhantomData,
        })
    }

    /// This process's rank in the world communicator.
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The number of ranks.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The world communicator (`PETSC_COMM_WORLD`).
    pub(crate) fn comm(&self) -> sys::MPI_Comm {
        // SAFETY: set by PetscInitialize, read-only afterwards.
        unsafe { sys::PETSC_COMM_WORLD }
    }

    /// The even split of `n` items among the ranks: this rank's half-open range (the first
    /// `n % size` ranks get one more), as PETSc's `PETSC_DECIDE` makes it.
    pub fn split(&self, n: usize) -> (usize, usize) {
        let (q, r) = (n / self.size, n % self.size);
        let lo = self.rank * q + self.rank.min(r);
        (lo, lo + q + usize::from(self.rank < r))
    }

    /// Adds options to PETSc's database, as on PETSc's command line: `"-ksp_type cg -pc_type gamg"`.
    /// They act on objects configured afterwards by their `set_from_options`.
    pub fn insert_options(&self, options: &str) -> Result<()> {
        let text =
            CString::new(options).map_err(|_| PetscError::Argument("PETSc options contain a NUL byte".into()))?;
        // SAFETY: PETSc is initialised; the global database (null) is PETSc's default.
        check("PetscOptionsInsertString", unsafe {
            sys::PetscOptionsInsertString(std::ptr::null_mut(), text.as_ptr())
        })
    }

    /// Whether this PETSc was built with the external package `name` (`"hypre"`, `"mumps"`,
    /// `"ptscotch"`, ...).
    pub fn has_package(&self, name: &str) -> Result<bool> {
        let text = CString::new(name).map_err(|_| PetscError::Argument("a package name contains a NUL byte".into()))?;
        let mut has = sys::PetscBool::PETSC_FALSE;
        // SAFETY: PETSc is initialised; the name is NUL-terminated.
        check("PetscHasExternalPackage", unsafe {
            sys::PetscHasExternalPackage(text.as_ptr(), &mut has)
        })?;
        Ok(has == sys::PetscBool::PETSC_TRUE)
    }

    /// PETSc's version, e.g. "Petsc Release Version 3.18.5, ...".
    pub fn version(&self) -> Result<String> {
        let mut buf = vec![0u8; 256];
        // SAFETY: the buffer's length is passed.
        check("PetscGetVersion", unsafe {
            sys::PetscGetVersion(buf.as_mut_ptr().cast(), buf.len())
        })?;
        let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
        Ok(String::from_utf8_lossy(&buf[..end]).into_owned())
    }

    /// The sum over ranks of each entry (every rank gets the sums).
    pub fn sum(&self, values: &[f64]) -> Result<Vec<f64>> {
        self.all_reduce(values, Reduce::Sum)
    }

    /// The maximum over ranks of each entry.
    pub fn max(&self, values: &[f64]) -> Result<Vec<f64>> {
        self.all_reduce(values, Reduce::Max)
    }

    fn all_reduce(&self, values: &[f64], op: Reduce) -> Result<Vec<f64>> {
        let mut out = vec![0.0; values.len()];
        let count = mpi_count(values.len())?;
        // SAFETY: buffers of `count` doubles; Open MPI's predefined handles are the addresses
        // of its predefined objects (what its MPI_DOUBLE, MPI_SUM macros expand to).
        let code = unsafe {
            let op = match op {
                Reduce::Sum => &raw mut sys::ompi_mpi_op_sum,
                Reduce::Max => &raw mut sys::ompi_mpi_op_max,
            };
            sys::MPI_Allreduce(
                values.as_ptr().cast(),
                out.as_mut_ptr().cast(),
                count,
                (&raw mut sys::ompi_mpi_double).cast(),
                op.cast(),
                self.comm(),
            )
        };
        check_mpi("MPI_Allreduce", code)?;
        Ok(out)
    }

    /// Ends every rank of the run at once (`MPI_Abort`), with `code`: for a rank that cannot go
    /// on while the others wait for it in a collective.
    pub fn abort(&self, code: i32) -> ! {
        // SAFETY: PETSc (so MPI) is initialised; MPI_Abort does not return.
        unsafe {
            sys::MPI_Abort(self.comm(), code);
        }
        std::process::exit(code)
    }

    /// Rank 0's `values` on every rank (the other ranks' `values` overwritten; every rank
    /// passes a slice of the same length).
    pub fn broadcast(&self, values: &mut [f64]) -> Result<()> {
        let count = mpi_count(values.len())?;
        // SAFETY: a buffer of `count` doubles on every rank; MPI_DOUBLE is f64.
        let code = unsafe {
            sys::MPI_Bcast(
                values.as_mut_ptr().cast(),
                count,
                (&raw mut sys::ompi_mpi_double).cast(),
                0,
                self.comm(),
            )
        };
        check_mpi("MPI_Bcast", code)
    }

    /// Rank 0's `bytes` on every rank (the others' replaced; their lengths need not agree).
    pub fn broadcast_bytes(&self, bytes: &mut Vec<u8>) -> Result<()> {
        let mut len = [bytes.len() as f64];
        self.broadcast(&mut len)?;
        bytes.resize(len[0] as usize, 0);
        let count = mpi_count(bytes.len())?;
        // SAFETY: a buffer of `count` bytes on every rank (resized above to rank 0's length);
        // MPI_BYTE is u8.
        let code = unsafe {
            sys::MPI_Bcast(
                bytes.as_mut_ptr().cast(),
                count,
                (&raw mut sys::ompi_mpi_byte).cast(),
                0,
                self.comm(),
            )
        };
        check_mpi("MPI_Bcast", code)
    }

    /// Every rank's `value`, in rank order, on every rank.
    pub fn all_gather(&self, value: u64) -> Result<Vec<u64>> {
        let mut out = vec![0u64; self.size];
        // SAFETY: one unsigned long per rank, `out` holds `size` of them.
        let code = unsafe {
            sys::MPI_Allgather(
                (&raw const value).cast(),
                1,
                (&raw mut sys::ompi_mpi_unsigned_long).cast(),
                out.as_mut_ptr().cast(),
                1,
                (&raw mut sys::ompi_mpi_unsigned_long).cast(),
                self.comm(),
            )
        };
        check_mpi("MPI_Allgather", code)?;
        Ok(out)
    }

    /// The ranks' slices concatenated in rank order on rank 0 (`None` on the other ranks).
    pub fn gather_f64(&self, local: &[f64]) -> Result<Option<Vec<f64>>> {
        // SAFETY: the datatype matches the element type.
        unsafe { self.gather(local, (&raw mut sys::ompi_mpi_double).cast()) }
    }

    /// As [`Petsc::gather_f64`], for `i32` (e.g. statuses or indices).
    pub fn gather_i32(&self, local: &[i32]) -> Result<Option<Vec<i32>>> {
        // SAFETY: the datatype matches the element type.
        unsafe { self.gather(local, (&raw mut sys::ompi_mpi_int).cast()) }
    }

    /// The ranks' slices concatenated in rank order, on every rank.
    pub fn all_gather_i32(&self, local: &[i32]) -> Result<Vec<i32>> {
        let (counts, displs, total) = self.layout(local.len())?;
        let mut out = vec![0i32; total];
        // SAFETY: counts and displacements agree with the buffers; MPI_INT is i32.
        let code = unsafe {
            sys::MPI_Allgatherv(
                local.as_ptr().cast::<c_void>(),
                mpi_count(local.len())?,
                (&raw mut sys::ompi_mpi_int).cast(),
                out.as_mut_ptr().cast::<c_void>(),
                counts.as_ptr(),
                displs.as_ptr(),
                (&raw mut sys::ompi_mpi_int).cast(),
                self.comm(),
            )
        };
        check_mpi("MPI_Allgatherv", code)?;
        Ok(out)
    }

    /// Every rank's count of `n`, their displacements in the concatenation, and its length.
    fn layout(&self, n: usize) -> Result<(Vec<c_int>, Vec<c_int>, usize)> {
        let counts = self.all_gather(n as u64)?;
        let counts: Vec<c_int> = counts.iter().map(|&c| mpi_count(c as usize)).collect::<Result<_>>()?;
        let mut displs = Vec::with_capacity(counts.len());
        let mut total = 0usize;
        for &c in &counts {
            displs.push(mpi_count(total)?);
            total += c as usize;
        }
        Ok((counts, displs, total))
    }

    /// # Safety
    /// `datatype` is the MPI datatype of `T`.
    unsafe fn gather<T: Copy + Default>(&self, local: &[T], datatype: sys::MPI_Datatype) -> Result<Option<Vec<T>>> {
        let (counts, displs, total) = self.layout(local.len())?;
        let mut out = if self.rank == 0 {
            vec![T::default(); total]
        } else {
            vec![]
        };
        // SAFETY: counts and displacements agree with the buffers (gathered above); `datatype`
        // is `T`'s (the caller's promise).
        let code = unsafe {
            sys::MPI_Gatherv(
                local.as_ptr().cast::<c_void>(),
                mpi_count(local.len())?,
                datatype,
                out.as_mut_ptr().cast::<c_void>(),
                counts.as_ptr(),
                displs.as_ptr(),
                datatype,
                0,
                self.comm(),
            )
        };
        check_mpi("MPI_Gatherv", code)?;
        Ok((self.rank == 0).then_some(out))
    }
}

impl Drop for Petsc {
    fn drop(&mut self) {
        // SAFETY: every object borrowing `self` has been dropped (the borrow checker's
        // guarantee); PETSc finalises MPI if it started it. An error here has no one to go to.
        unsafe {
            sys::PetscFinalize();
        }
    }
}

#[derive(Clone, Copy)]
enum Reduce {
    Sum,
    Max,
}

/// A length as MPI's `int`.
fn mpi_count(n: usize) -> Result<c_int> {
    c_int::try_from(n).map_err(|_| PetscError::IndexOverflow {
        what: "an MPI count",
        value: n,
        max: c_int::MAX as i64,
    })
}

/// A size or index as PETSc's [`Index`].
pub(crate) fn index(what: &'static str, n: usize) -> Result<Index> {
    Index::try_from(n).map_err(|_| PetscError::IndexOverflow {
        what,
        value: n,
        max: Index::MAX as i64,
    })
}
