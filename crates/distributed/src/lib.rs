//! The piezocontact problem on the ranks of an MPI run, through PETSc (`solver.backend =
//! "petsc"`): Krylov methods whose cost grows linearly with the mesh, and several processes
//! (or machines), where the default backend factors one sparse matrix on one machine.
//!
//! The run is [`problem::run`]'s, with this crate's [`DistributedMemory`] for what differs; on every
//! rank:
//!
//! 1. **set up**: the scene's mesh, materials, conditions and loads ([`problem::backend::setup`]),
//!    the same on every rank (a mesh is small beside its matrix);
//! 2. **partition** ([`Layout`]): the cells' dual graph (cells sharing a facet) partitioned among
//!    the ranks by PETSc's `MatPartitioning` (PT-Scotch); a node belongs to the lowest rank of
//!    its cells; each rank numbers its nodes' unknowns contiguously, node by node
//!    (`u_x, u_y[, u_z][, φ]`);
//! 3. **assemble** ([`system`]): each rank adds its own cells' element matrices into a
//!    parallel AIJ matrix (PETSc sends the entries of other ranks' rows to them), with the
//!    potential's equations negated, `[[A, Gᵀ], [-G, B]] [u; φ] = [b_u; -b_φ]`, so that the
//!    Schur complement of the potentials, `B + G A⁻¹ Gᵀ`, is positive definite; prescribed
//!    unknowns are eliminated symmetrically (`MatZeroRowsColumns`);
//! 4. **solve**: PCFIELDSPLIT with the Schur complement of the potentials (the paper's
//!    Algorithm 3 in PETSc's words), algebraic multigrid (GAMG, with the rigid-body modes) on
//!    the elastic block, FGMRES outside; CG with GAMG where the body has no potential. Every
//!    choice can be overridden by PETSc's options (`solver.petsc_options`);
//! 5. **recover**: the solution gathered on rank 0, which recovers the fields and reports, as
//!    the default backend does; the other ranks return `None`.
//!
//! Contact ([`contact`]) is a primal-dual active set iteration on the full system, each step
//! one Krylov solve: no dense compliance, whose size grows like the square of the contact
//! boundary's.
//!
//! With the feature `petsc` off the crate holds only [`supports`]: what the backend solves,
//! told from the scene.
// Without the feature the items the docs link to do not exist.
#![cfg_attr(not(feature = "petsc"), allow(rustdoc::broken_intra_doc_links))]

mod supports;

pub use supports::{
    active_sets_hold, active_sets_hold_on, direct as factors_directly, repeats_contact_solves, supports,
};

#[cfg(feature = "petsc")]
mod active;
#[cfg(feature = "petsc")]
pub mod contact;
#[cfg(feature = "petsc")]
mod direct;
#[cfg(feature = "petsc")]
mod error;
#[cfg(feature = "petsc")]
mod free;
#[cfg(feature = "petsc")]
mod krylov;
#[cfg(feature = "petsc")]
mod layout;
#[cfg(feature = "petsc")]
mod pieces;
#[cfg(feature = "petsc")]
mod run;
#[cfg(feature = "petsc")]
pub mod system;

#[cfg(feature = "petsc")]
pub use active::MAX_ACTIVE_SET_STEPS;
#[cfg(feature = "petsc")]
pub use direct::Direct;
#[cfg(feature = "petsc")]
pub use error::DistributedError;
#[cfg(feature = "petsc")]
pub use krylov::{COUPLED_OPTIONS, ELASTIC_OPTIONS, PIECES_ELASTIC_BLOCK};
#[cfg(feature = "petsc")]
pub use layout::Layout;
#[cfg(feature = "petsc")]
pub use pieces::{
    pieces_support, solve_on_pieces, solve_path_on_pieces, EachStep, Gathered, PieceContact, PieceFrame, PieceMesh,
    PieceSolution, PieceStep,
};
#[cfg(feature = "petsc")]
pub use run::{
    direct_exceeds, solve, solve_path, solve_with, Assembled, ContactRoute, DistributedMemory, Prepared,
    ACTIVE_SETS_FROM, ACTIVE_SETS_ZONE,
};
