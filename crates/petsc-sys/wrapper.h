/* What the safe layer (crates/petsc) uses: vectors, matrices, partitioning, Krylov solvers,
   preconditioners, the options database; MPI's predefined communicators; MUMPS' C interface
   (the distributed direct factorisation with its Schur complement, which PETSc's own MUMPS
   interface refuses on more than one rank). */
#include <petscksp.h>
#include <petscmat.h>
#include <petscvec.h>
#include <petscis.h>
#include <petscsys.h>
#include <dmumps_c.h>
