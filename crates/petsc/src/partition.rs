//! A graph partitioned among the ranks: PETSc's `MatPartitioning` on the graph as a
//! `MATMPIADJ`, by PT-Scotch unless `-mat_partitioning_type` says otherwise.
//!
//! The graph is given distributed: this rank holds the vertices of a contiguous range, each
//! with its neighbours' global numbers (compressed rows, no self-loops). The answer is the part
//! (the rank to own it) of each of this rank's vertices.

use std::ffi::{c_void, CString};

use petsc_sys as sys;

use crate::error::{check, PetscError, Result};
use crate::petsc::{index, Index, Petsc};

/// An array of `n` PETSc indices allocated by PETSc (`MatCreateMPIAdj` takes ownership of its
/// arrays and frees them with `PetscFree`), filled from `values`.
fn petsc_array(values: &[Index]) -> Result<*mut Index> {
    let mut ptr: *mut Index = std::ptr::null_mut();
    let bytes = std::mem::size_of_val(values).max(std::mem::size_of::<Index>());
    let (func, file) = (c"petsc::partition", c"partition.rs");
    // SAFETY: PetscMallocA(1, clear, line, function, file, bytes, &ptr) allocates one array of
    // `bytes` bytes into `ptr`; we then copy `values.len()` indices into it.
    unsafe {
        check(
            "PetscMallocA",
            sys::PetscMallocA(
                1,
                sys::PetscBool::PETSC_FALSE,
                line!() as i32,
                func.as_ptr(),
                file.as_ptr(),
                bytes,
                (&raw mut ptr).cast::<c_void>(),
            ),
        )?;
        std::ptr::copy_nonoverlapping(values.as_ptr(), ptr, values.len());
    }
    Ok(ptr)
}

/// The part (owning rank, `0..size`) of each of this rank's vertices.
///
/// `offsets` has one more entry than this rank has vertices (`offsets[0] = 0`); vertex `v`'s
/// neighbours, by global number, are `neighbours[offsets[v]..offsets[v + 1]]`; `global` is the
/// number of vertices in all. Collective. On one rank every vertex is part 0, without a
/// partitioner.
pub fn partition(petsc: &Petsc, offsets: &[usize], neighbours: &[usize], global: usize) -> Result<Vec<usize>> {
    let local = offsets.len().saturating_sub(1);
    if offsets.first().copied().unwrap_or(0) != 0 || offsets.last().copied().unwrap_or(0) != neighbours.len() {
        return Err(PetscError::Argument(format!(
            "a graph's offsets run from {:?} to {:?} for {} neighbours",
            offsets.first(),
            offsets.last(),
            neighbours.len()
        )));
    }
    if let Some(&bad) = neighbours.iter().find(|&&n| n >= global) {
        return Err(PetscError::Argument(format!(
            "a neighbour {bad} outside the graph's {global} vertices"
        )));
    }
    if petsc.size() == 1 {
        return Ok(vec![0; local]);
    }
    let i: Vec<Index> = offsets
        .iter()
        .map(|&o| index("a graph offset", o))
        .collect::<Result<_>>()?;
    let j: Vec<Index> = neighbours
        .iter()
        .map(|&n| index("a vertex", n))
        .collect::<Result<_>>()?;
    let (ip, jp) = (petsc_array(&i)?, petsc_array(&j)?);
    let mut adj: sys::Mat = std::ptr::null_mut();
    // SAFETY: `ip` and `jp` are PETSc arrays of the sizes MATMPIADJ reads; it owns them now.
    check("MatCreateMPIAdj", unsafe {
        sys::MatCreateMPIAdj(
            petsc.comm(),
            index("a graph's local vertices", local)?,
            index("a graph's vertices", global)?,
            ip,
            jp,
            std::ptr::null_mut(),
            &mut adj,
        )
    })?;
    let parts = apply(petsc, adj, local);
    // SAFETY: our adjacency matrix, released once (with its arrays).
    unsafe {
        sys::MatDestroy(&mut adj);
    }
    parts
}

fn apply(petsc: &Petsc, adj: sys::Mat, local: usize) -> Result<Vec<usize>> {
    let mut part: sys::MatPartitioning = std::ptr::null_mut();
    let mut is: sys::IS = std::ptr::null_mut();
    let scotch = CString::new("ptscotch").expect("no NUL");
    // SAFETY: live objects created here and released below, on every path.
    unsafe {
        let run = (|| {
            check(
                "MatPartitioningCreate",
                sys::MatPartitioningCreate(petsc.comm(), &mut part),
            )?;
            check(
                "MatPartitioningSetAdjacency",
                sys::MatPartitioningSetAdjacency(part, adj),
            )?;
            check(
                "MatPartitioningSetNParts",
                sys::MatPartitioningSetNParts(part, index("a number of parts", petsc.size())?),
            )?;
            check(
                "MatPartitioningSetType",
                sys::MatPartitioningSetType(part, scotch.as_ptr()),
            )?;
            check(
                "MatPartitioningSetFromOptions",
                sys::MatPartitioningSetFromOptions(part),
            )?;
            check("MatPartitioningApply", sys::MatPartitioningApply(part, &mut is))?;
            let mut n: Index = 0;
            check("ISGetLocalSize", sys::ISGetLocalSize(is, &mut n))?;
            if n as usize != local {
                return Err(PetscError::Argument(format!(
                    "the partitioner gave {n} parts for {local} vertices"
                )));
            }
            let mut idx: *const Index = std::ptr::null();
            check("ISGetIndices", sys::ISGetIndices(is, &mut idx))?;
            let out = if local == 0 {
                vec![]
            } else {
                std::slice::from_raw_parts(idx, local)
                    .iter()
                    .map(|&p| p as usize)
                    .collect()
            };
            check("ISRestoreIndices", sys::ISRestoreIndices(is, &mut idx))?;
            Ok(out)
        })();
        if !is.is_null() {
            sys::ISDestroy(&mut is);
        }
        if !part.is_null() {
            sys::MatPartitioningDestroy(&mut part);
        }
        run
    }
}
