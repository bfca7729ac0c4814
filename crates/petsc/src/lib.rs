//! A thin safe layer over PETSc, for the distributed backend of piezocontact.
//!
//! PETSc (the Portable, Extensible Toolkit for Scientific Computation) is the engine that
//! MOOSE, FEniCS, deal.II and PERMON build their parallel solvers on. This crate wraps what the
//! backend uses and nothing more, in PETSc's own words:
//!
//! - [`Petsc`]: the library, initialised once per process (`PetscInitialize` with MPI), and
//!   finalised when dropped; every object borrows it, so none outlives it. Its communicator is
//!   `PETSC_COMM_WORLD`: [`Petsc::rank`], [`Petsc::size`] and a few collectives.
//! - [`Vector`]: a parallel `Vec` (each rank owns a contiguous range of entries).
//! - [`Matrix`]: a parallel sparse `Mat` of type AIJ (rows owned by ranks in contiguous ranges,
//!   entries anywhere set through PETSc's assembly, which sends off-rank ones to their owners).
//! - [`Ksp`]: a Krylov solver with its preconditioner (`KSP`, `PC`), field splits by
//!   [`IndexSet`], options from the options database ([`Petsc::insert_options`]).
//! - [`Mumps`]: a sparse matrix factored by MUMPS on the ranks (its own C interface), with the
//!   Schur complement of chosen unknowns whole on rank 0, solves in two halves around it.
//! - [`partition()`]: a graph partitioned among the ranks (`MatPartitioning` on a `MATMPIADJ`).
//!
//! Errors are typed ([`PetscError`]): PETSc's error handler is replaced by one that records the
//! message and returns the code, so nothing is printed and every call's failure comes back as a
//! `Result` naming the call and PETSc's message.
//!
//! The crate knows no finite elements (as `linalg` does not). With the feature `bind` off it is
//! empty, so the default build of the workspace needs no PETSc.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # #[cfg(feature = "bind")] {
//! use petsc::{Ksp, Matrix, Petsc, Vector};
//! let p = Petsc::init()?;
//! let n = 100; // global size; rows split evenly among the ranks
//! let (lo, hi) = p.split(n);
//! let mut a = Matrix::aij(&p, hi - lo, n, &vec![3; hi - lo], &vec![1; hi - lo])?;
//! for i in lo..hi {
//!     let (r, c0) = (i as petsc::Index, i.saturating_sub(1) as petsc::Index);
//!     let cols: Vec<petsc::Index> = (c0..=(i + 1).min(n - 1) as petsc::Index).collect();
//!     let vals: Vec<f64> = cols.iter().map(|&c| if c == r { 2.0 } else { -1.0 }).collect();
//!     a.add_values(&[r], &cols, &vals)?;
//! }
//! a.assemble()?;
//! let b = Vector::filled(&p, hi - lo, 1.0)?;
//! let mut x = Vector::mpi(&p, hi - lo)?;
//! let mut ksp = Ksp::new(&p, &a)?;
//! ksp.set_types("cg", "jacobi")?;
//! let info = ksp.solve(&b, &mut x)?;
//! assert!(info.reason.starts_with("CONVERGED"));
//! # }
//! # Ok(())
//! # }
//! ```
// Without the feature the items the docs link to do not exist.
#![cfg_attr(not(feature = "bind"), allow(rustdoc::broken_intra_doc_links))]

#[cfg(feature = "bind")]
mod error;
#[cfg(feature = "bind")]
mod ksp;
#[cfg(feature = "bind")]
mod matrix;
#[cfg(feature = "bind")]
pub mod mumps;
#[cfg(feature = "bind")]
mod partition;
#[cfg(feature = "bind")]
mod petsc;
#[cfg(feature = "bind")]
pub mod testing;
#[cfg(feature = "bind")]
mod vector;

#[cfg(feature = "bind")]
pub use error::{PetscError, Result};
#[cfg(feature = "bind")]
pub use ksp::{IndexSet, Ksp, KspInfo};
#[cfg(feature = "bind")]
pub use matrix::Matrix;
#[cfg(feature = "bind")]
pub use mumps::{Mumps, Symmetry};
#[cfg(feature = "bind")]
pub use partition::partition;
#[cfg(feature = "bind")]
pub use petsc::{Index, Petsc};
#[cfg(feature = "bind")]
pub use vector::Vector;
