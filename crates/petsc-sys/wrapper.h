/* What the safe layer (crates/petsc) uses: vectors, matrices, partitioning, Krylov solvers,
   preconditioners, the options database; MPI's predefined communicators. */
#include <petscksp.h>
#include <petscmat.h>
#include <petscvec.h>
#include <petscis.h>
#include <petscsys.h>
