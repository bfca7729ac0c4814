//! MUMPS, the MUltifrontal Massively Parallel sparse direct Solver, called through its own C
//! interface (`dmumps_c`) on PETSc's communicator: the matrix given in pieces by the ranks
//! (distributed assembled entries, summed where two ranks give one), factored on all of them,
//! with the right-hand sides and the solutions whole on rank 0 (MUMPS' host).
//!
//! Why not PETSc's `MATSOLVERMUMPS`: PETSc's interface refuses MUMPS' Schur complement on
//! more than one rank (`MatFactorSetSchurIS`: "Parallel Schur complements not yet supported
//! from PETSc", PETSc 3.18's `mumps.c`), and the Schur complement of a few chosen unknowns
//! (a contact zone's) is what this layer's user wants of the factorisation. MUMPS itself
//! computes it on any number of ranks and returns it whole on its host (`ICNTL(19) = 1`); the
//! solves then go in MUMPS' two halves: the condensation of a right-hand side onto the Schur
//! unknowns (`ICNTL(26) = 1`, the forward half), and the expansion of their solution back to
//! every unknown (`ICNTL(26) = 2`). The MUMPS users' guide (5.5, sections 5.15 and 5.16) is
//! the reference for every control set here.

use crate::error::{PetscError, Result};
use crate::petsc::Petsc;
use petsc_sys as sys;

/// MUMPS' jobs (its users' guide, section 5.1).
const JOB_INIT: i32 = -1;
const JOB_END: i32 = -2;
const JOB_FACTOR: i32 = 2;
const JOB_SOLVE: i32 = 3;
const JOB_ANALYSE: i32 = 1;

/// How many times a factorisation whose workspace MUMPS' estimate left too small (`INFOG(1)`
/// -8 or -9) is tried again, each time with twice the extra space (`ICNTL(14)`).
const WORKSPACE_RETRIES: usize = 4;

/// The symmetry MUMPS is told of (its `SYM`): it decides the factorisation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// Symmetric positive definite (`L Lᵀ`, `SYM = 1`); one triangle's entries given.
    Definite,
    /// Symmetric, possibly indefinite (`L D Lᵀ` with 2 x 2 pivots, `SYM = 2`); one
    /// triangle's entries given.
    Indefinite,
    /// Symmetric quasi-definite, `[[A, Gᵀ], [G, -B]]` with `A` and `B` positive definite
    /// (`L D Lᵀ` without pivoting, `SYM = 2` and `CNTL(1) = 0`): its `L D Lᵀ` exists in every
    /// symmetric order (Vanderbei, SIAM J. Optim. 5 (1995) 100), as the default backend takes
    /// it, and MUMPS' threshold pivoting would delay pivots for nothing. One triangle's
    /// entries given.
    QuasiDefinite,
    /// Unsymmetric (`L U`, `SYM = 0`); every entry given.
    General,
}

/// A sparse matrix of order `n` factored by MUMPS on every rank of `petsc`, with the Schur
/// complement of its chosen unknowns (possibly none) whole on rank 0.
pub struct Mumps<'p> {
    petsc: &'p Petsc,
    /// MUMPS' instance (boxed: MUMPS keeps no pointer to it, but it is large).
    id: Box<sys::DMUMPS_STRUC_C>,
    n: usize,
    /// The entries this rank gave (1-based), which MUMPS reads until the instance ends.
    irn: Vec<i32>,
    jcn: Vec<i32>,
    values: Vec<f64>,
    /// The pivot order given (`perm_in[i]`: the 1-based position of unknown `i`), or empty.
    perm_in: Vec<i32>,
    /// The Schur unknowns (1-based) and their Schur complement, row-major (rank 0).
    schur_list: Vec<i32>,
    schur: Vec<f64>,
    /// Whether MUMPS' initialisation succeeded (its instance is then ended on drop).
    initialised: bool,
    /// What MUMPS was told of the matrix (after its initialisation, which resets the controls,
    /// [`Mumps::configure`] reads it).
    symmetry: Symmetry,
    /// Wall time of the numeric factorisation (its retries with more workspace included), s.
    numeric_seconds: f64,
}

impl<'p> Mumps<'p> {
    /// Analyses and factors the matrix of order `n` whose entries `(rows[e], cols[e],
    /// values[e])` (0-based) this rank holds; MUMPS sums the entries given twice, by one rank or
    /// several. With a symmetric `symmetry`, give one triangle (`rows[e] >= cols[e]`). `schur`:
    /// the unknowns whose Schur complement is wanted (the same on every rank; empty for none).
    /// `order`: the pivot order (every unknown once, the Schur unknowns last; rank 0's is read),
    /// or `None` for MUMPS' own choice. Give one where there is a Schur complement: MUMPS then
    /// orders by AMD alone (measured: METIS and SCOTCH asked for, AMD used), whose fill on a 3D
    /// mesh costs 20 to 35 times a nested dissection's flops. `memory`: the bytes a rank may
    /// use, checked against MUMPS' own estimate after its analysis, before the factorisation
    /// allocates (`None`: not checked). Collective.
    ///
    /// # Errors
    /// [`PetscError::Argument`] where the entries disagree or an index is out of range;
    /// [`PetscError::MumpsTooLarge`] where MUMPS' estimate exceeds `memory`;
    /// [`PetscError::Mumps`] where MUMPS fails (a singular matrix among its reasons).
    pub fn factor(
        petsc: &'p Petsc,
        n: usize,
        (rows, cols, values): (&[usize], &[usize], Vec<f64>),
        symmetry: Symmetry,
        schur: &[usize],
        order: Option<&[usize]>,
        memory: Option<u64>,
    ) -> Result<Self> {
        if rows.len() != cols.len() || rows.len() != values.len() {
            return Err(PetscError::Argument(format!(
                "MUMPS' entries: {} rows, {} columns, {} values",
                rows.len(),
                cols.len(),
                values.len()
            )));
        }
        if let Some(bad) = rows.iter().chain(cols).chain(schur).find(|&&i| i >= n) {
            return Err(PetscError::Argument(format!(
                "MUMPS' index {bad} is out of a matrix of order {n}"
            )));
        }
        let one_based = |v: &[usize]| -> Result<Vec<i32>> { v.iter().map(|&i| fortran_index(i + 1)).collect() };
        let perm_in = match order {
            Some(order) => position_of(order, n)?,
            None => vec![],
        };
        let mut m = Mumps {
            petsc,
            id: Box::default(),
            n,
            irn: one_based(rows)?,
            jcn: one_based(cols)?,
            values,
            perm_in,
            schur_list: one_based(schur)?,
            schur: vec![],
            initialised: false,
            symmetry,
            numeric_seconds: 0.0,
        };
        m.id.sym = match symmetry {
            Symmetry::Definite => 1,
            Symmetry::Indefinite | Symmetry::QuasiDefinite => 2,
            Symmetry::General => 0,
        };
        m.id.par = 1; // the host works too
                      // SAFETY: PETSc is initialised (the borrow of `petsc`), so MPI is; the communicator is
                      // PETSc's.
        m.id.comm_fortran = unsafe { sys::MPI_Comm_c2f(petsc.comm()) };
        m.call(JOB_INIT, "initialisation")?;
        m.initialised = true;
        m.configure()?;
        m.call(JOB_ANALYSE, "analysis")?;
        let needed = m.estimated_bytes();
        if let Some(available) = memory.filter(|&a| needed > a) {
            return Err(PetscError::MumpsTooLarge { needed, available });
        }
        let started = std::time::Instant::now();
        m.call(JOB_FACTOR, "factorisation")
            .or_else(|e| m.factor_with_more_space(e))?;
        m.numeric_seconds = started.elapsed().as_secs_f64();
        m.symmetrise_schur();
        Ok(m)
    }

    /// The controls: silent, distributed entries, the Schur complement centralised by rows on
    /// the host, dense right-hand sides and solutions on the host.
    fn configure(&mut self) -> Result<()> {
        let id = &mut *self.id;
        // ICNTL(1..4): no output streams; errors come back through INFOG
        id.icntl[0] = -1;
        id.icntl[1] = -1;
        id.icntl[2] = -1;
        id.icntl[3] = 0;
        id.icntl[17] = 3; // ICNTL(18): the entries distributed, as the ranks give them
        if self.symmetry == Symmetry::QuasiDefinite {
            id.cntl[0] = 0.0; // CNTL(1): no threshold pivoting
        }
        id.n = fortran_index(self.n)?;
        id.nnz_loc = self.values.len() as i64;
        id.nz_loc = i32::try_from(self.values.len()).unwrap_or(0);
        id.irn_loc = self.irn.as_mut_ptr();
        id.jcn_loc = self.jcn.as_mut_ptr();
        id.a_loc = self.values.as_mut_ptr();
        if !self.perm_in.is_empty() {
            id.icntl[6] = 1; // ICNTL(7): the pivot order given, in PERM_IN (read on the host)
            id.perm_in = self.perm_in.as_mut_ptr();
        }
        if !self.schur_list.is_empty() {
            let k = self.schur_list.len();
            id.icntl[18] = 1; // ICNTL(19): the Schur complement whole on the host, by rows
            id.size_schur = fortran_index(k)?;
            id.schur_lld = fortran_index(k)?;
            id.listvar_schur = self.schur_list.as_mut_ptr();
            if self.petsc.rank() == 0 {
                self.schur = vec![0.0; k * k];
                id.schur = self.schur.as_mut_ptr();
            }
        }
        Ok(())
    }

    /// The factorisation again with twice the workspace, where MUMPS' estimate of it was short.
    fn factor_with_more_space(&mut self, first: PetscError) -> Result<()> {
        let mut last = first;
        for _ in 0..WORKSPACE_RETRIES {
            if !matches!(last, PetscError::Mumps { info: -8 | -9, .. }) {
                return Err(last);
            }
            // ICNTL(14): the percentage of extra workspace (MUMPS' default 20 to 35)
            self.id.icntl[13] = (self.id.icntl[13].max(20)) * 2;
            match self.call(JOB_FACTOR, "factorisation") {
                Ok(()) => return Ok(()),
                Err(e) => last = e,
            }
        }
        Err(last)
    }

    /// A symmetric factorisation returns the Schur complement's lower triangle, and of the
    /// upper one only what its fronts happened to hold (measured: whole blocks of it left
    /// unset above a few hundred unknowns): the upper triangle is taken from the lower.
    fn symmetrise_schur(&mut self) {
        let k = self.schur_list.len();
        if self.id.sym == 0 || self.schur.len() != k * k {
            return;
        }
        let s = &mut self.schur;
        for i in 0..k {
            for j in i + 1..k {
                s[i * k + j] = s[j * k + i];
            }
        }
    }

    /// The entries this rank gave, as MUMPS reads them: rows and columns 1-based (MUMPS
    /// summed duplicates; these are as given).
    pub fn entries(&self) -> (&[i32], &[i32], &[f64]) {
        (&self.irn, &self.jcn, &self.values)
    }

    /// The order of the matrix.
    pub fn order(&self) -> usize {
        self.n
    }

    /// The Schur complement of the chosen unknowns, `k x k` row-major in their order, on rank
    /// 0 (`None` on the others, and without chosen unknowns).
    pub fn schur_complement(&self) -> Option<&[f64]> {
        (!self.schur.is_empty()).then_some(&self.schur[..])
    }

    /// Solves in place: `rhs` (rank 0's; of length [`Mumps::order`] on rank 0, anything on the
    /// others) becomes the solution on rank 0. Without chosen unknowns only. Collective.
    ///
    /// # Errors
    /// [`PetscError::Argument`] with chosen unknowns (use [`Mumps::condense`] and
    /// [`Mumps::expand`]) or a right-hand side of the wrong length; MUMPS' errors.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        if !self.schur_list.is_empty() {
            return Err(PetscError::Argument(
                "a MUMPS factorisation with a Schur complement solves in two halves (condense, expand)".into(),
            ));
        }
        self.solve_phase(rhs, 0, &mut [])
    }

    /// The forward half of a solve with the Schur complement: `rhs` (rank 0's) is condensed
    /// onto the chosen unknowns, `b_s - K_si K_ii⁻¹ b_i`, returned on rank 0 (empty on the
    /// others); `rhs` then holds what [`Mumps::expand`] needs. Collective.
    ///
    /// # Errors
    /// MUMPS' errors; a right-hand side of the wrong length.
    pub fn condense(&mut self, rhs: &mut [f64]) -> Result<Vec<f64>> {
        let mut reduced = vec![
            0.0;
            if self.petsc.rank() == 0 {
                self.schur_list.len()
            } else {
                0
            }
        ];
        self.solve_phase(rhs, 1, &mut reduced)?;
        Ok(reduced)
    }

    /// The backward half: with `rhs` as [`Mumps::condense`] left it and `x_s` the chosen
    /// unknowns' solution (rank 0's), `rhs` becomes the whole solution on rank 0. MUMPS keeps
    /// the forward half inside itself for one expansion: it must follow its condensation, with
    /// no other solve between (else MUMPS' `INFOG(1) = -35`). Collective.
    ///
    /// # Errors
    /// MUMPS' errors; arguments of the wrong length.
    pub fn expand(&mut self, rhs: &mut [f64], x_s: &[f64]) -> Result<()> {
        let mut x = x_s.to_vec();
        if self.petsc.rank() == 0 && x.len() != self.schur_list.len() {
            return Err(PetscError::Argument(format!(
                "the Schur unknowns' solution has {} values for {} unknowns",
                x.len(),
                self.schur_list.len()
            )));
        }
        self.solve_phase(rhs, 2, &mut x)?;
        if self.petsc.rank() == 0 {
            for (&i, v) in self.schur_list.iter().zip(&x) {
                rhs[(i - 1) as usize] = *v;
            }
        }
        Ok(())
    }

    /// One solve phase (`ICNTL(26)` = `phase`), the reduced right-hand side in `reduced`.
    fn solve_phase(&mut self, rhs: &mut [f64], phase: i32, reduced: &mut [f64]) -> Result<()> {
        let host = self.petsc.rank() == 0;
        if host && rhs.len() != self.n {
            return Err(PetscError::Argument(format!(
                "a right-hand side of {} values for a matrix of order {}",
                rhs.len(),
                self.n
            )));
        }
        let id = &mut *self.id;
        id.icntl[19] = 0; // ICNTL(20): dense right-hand side on the host
        id.icntl[20] = 0; // ICNTL(21): the solution on the host
        id.icntl[25] = phase; // ICNTL(26)
        id.nrhs = 1;
        id.lrhs = fortran_index(self.n)?;
        if host {
            id.rhs = rhs.as_mut_ptr();
            id.redrhs = reduced.as_mut_ptr();
            id.lredrhs = fortran_index(reduced.len().max(1))?;
        }
        let result = self.call(
            JOB_SOLVE,
            match phase {
                1 => "condensation of a right-hand side",
                2 => "expansion of the Schur unknowns' solution",
                _ => "solve",
            },
        );
        self.id.rhs = std::ptr::null_mut();
        self.id.redrhs = std::ptr::null_mut();
        result
    }

    /// MUMPS' estimate after its analysis of the memory its factorisation takes in core on the
    /// most loaded rank (`INFOG(16)`, millions of bytes), in bytes; the same on every rank.
    pub fn estimated_bytes(&self) -> u64 {
        u64::try_from(self.id.infog[15]).unwrap_or(0) * 1_000_000
    }

    /// Floating-point operations of the factorisation, over all ranks (`RINFOG(3)`).
    pub fn factor_flops(&self) -> f64 {
        self.id.rinfog[2]
    }

    /// Wall time of the numeric factorisation (the analysis left out), s.
    pub fn numeric_seconds(&self) -> f64 {
        self.numeric_seconds
    }

    /// Bytes of the factors over all ranks (`INFOG(9)` entries of 8 bytes; a negative `INFOG`
    /// counts millions).
    pub fn factor_bytes(&self) -> f64 {
        let entries = self.id.infog[8];
        let entries = if entries < 0 {
            -(entries as f64) * 1e6
        } else {
            entries as f64
        };
        8.0 * entries
    }

    /// Calls MUMPS with `job`; its `INFOG(1)` made an error.
    fn call(&mut self, job: i32, what: &'static str) -> Result<()> {
        self.id.job = job;
        // SAFETY: the instance was initialised by JOB_INIT (or this is it); every pointer in it
        // points into a buffer of `self` that outlives the call, of the length MUMPS is told.
        unsafe { sys::dmumps_c(&mut *self.id) };
        let (info, detail) = (self.id.infog[0], self.id.infog[1]);
        if info < 0 {
            return Err(PetscError::Mumps {
                what,
                info,
                detail,
                meaning: meaning(info, detail),
            });
        }
        Ok(())
    }
}

impl Drop for Mumps<'_> {
    fn drop(&mut self) {
        // an instance that never initialised has nothing to free
        if self.initialised {
            // errors here have no one to go to
            let _ = self.call(JOB_END, "termination");
        }
    }
}

/// `perm_in[i]`, the 1-based position of unknown `i` in the pivot `order` (`order[p] = i`).
fn position_of(order: &[usize], n: usize) -> Result<Vec<i32>> {
    let mut perm = vec![0; n];
    for (p, &i) in order.iter().enumerate() {
        if i >= n || perm[i] != 0 {
            return Err(PetscError::Argument(format!(
                "MUMPS' pivot order: unknown {i} out of range or given twice"
            )));
        }
        perm[i] = fortran_index(p + 1)?;
    }
    if order.len() != n {
        return Err(PetscError::Argument(format!(
            "MUMPS' pivot order holds {} of {n} unknowns",
            order.len()
        )));
    }
    Ok(perm)
}

/// An index as MUMPS' (32-bit) integer.
fn fortran_index(i: usize) -> Result<i32> {
    i32::try_from(i).map_err(|_| PetscError::IndexOverflow {
        what: "a MUMPS index",
        value: i,
        max: i32::MAX as i64,
    })
}

/// What MUMPS' `INFOG(1)` (with `INFOG(2)`) means, for the common failures (users' guide,
/// section 8).
fn meaning(info: i32, detail: i32) -> String {
    match info {
        -5 | -7 | -13 => "MUMPS could not allocate its memory".into(),
        -8 | -9 | -14 | -15 => "MUMPS' workspace was too small (ICNTL(14))".into(),
        -10 => "the matrix is numerically singular (a body or a potential not held?)".into(),
        -16 => format!("the order {detail} is out of range"),
        -17 | -20 | -22 => "an argument of the solve was invalid".into(),
        -35 => "an expansion without the condensation just before it".into(),
        _ => "see MUMPS' users' guide, section 8".into(),
    }
}
