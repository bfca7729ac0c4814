//! Frictional contact problems in the text format of the Siconos project (its numerics
//! library's `frictionContact_printInFile`), the format of the problems Siconos and FCLib use
//! to compare solvers; their error measure; and their mapping onto this crate's problem.
//!
//! A problem is `u = W r + q` with, at every contact, `u_N ≥ 0`, `r_N ≥ 0`, `|r_T| ≤ μ r_N`
//! and De Saxcé's complementarity (`r_T` opposes `u_T` when sliding). Each contact's values are
//! contiguous, normal first: `[r_N, r_T1 (, r_T2)]`.
//!
//! The file holds, whitespace-separated: the dimension (2 or 3), the number of contacts, the
//! matrix `W`, then `q` (one value per row) and `μ` (one per contact), and, from Siconos'
//! older printers, the flag `isComplete` (0 or 1); nothing else (a file with more data than its
//! counts announce is refused). `W` is a Siconos
//! "NumericsMatrix": its storage (0 dense, 1 sparse block, 2 sparse), its two sizes, then
//! - dense: the two sizes again and the values column by column;
//! - sparse block: the number of blocks, of block rows and of block columns, the cumulative
//!   sizes of the block rows and of the block columns, the lengths of the two index arrays, the
//!   block-row pointers and block-column indices (compressed rows of blocks), then each block:
//!   its number and its values column by column;
//! - sparse: the origin (triplet, compressed column or compressed row), then CSparse's printout
//!   of the matrix (`cs_print`: a banner, `m-by-n, nzmax: …` and one line per entry, under a
//!   `col j : locations a to b` line per column when compressed). Its values carry the six
//!   digits that `cs_print` writes, as Siconos itself reads them.
//!
//! Mapping (checked in the tests): with `D = W` permuted to this crate's layout (normals
//! first), weights 1, `u0 = -q`, gaps 0 and friction `μ`, this crate's `λ` is Siconos' `r` and
//! its `u` is `-(W r + q)`.

use crate::operator::{DenseContactProblem, SparseContactProblem};
use crate::points::{ContactPoints, PointValues};
use faer::sparse::{SparseRowMat, Triplet};

/// How `W` was stored in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// Every entry, column by column.
    Dense,
    /// Dense blocks in compressed block rows (Siconos' "SBM").
    SparseBlock,
    /// CSparse's text printout (triplets or compressed columns).
    Sparse,
}

/// A frictional contact problem of Siconos: `u = W r + q`, friction coefficients `μ`.
#[derive(Clone, Debug)]
pub struct FrictionProblem {
    /// Dimension: 2 (one tangential direction) or 3.
    pub dim: usize,
    /// The Delassus operator `W`, `nc·dim` square, in Siconos' layout (contact by contact).
    pub w: SparseRowMat<usize, f64>,
    /// `q`, one value per row of `W`.
    pub q: Vec<f64>,
    /// `μ`, one per contact.
    pub mu: Vec<f64>,
    /// How the file stored `W`.
    pub storage: Storage,
}

/// What is wrong with a file that does not hold a problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// A token that is not what the format has at that place.
    #[error("line {line}: expected {expected}, found `{found}`")]
    Unexpected {
        /// 1-based line of the token.
        line: usize,
        /// What the format has there.
        expected: String,
        /// The token.
        found: String,
    },
    /// The text ends early.
    #[error("the file ends where {expected} was expected")]
    Truncated {
        /// What the format has there.
        expected: String,
    },
    /// Well-formed, but not a problem (sizes that disagree, a value out of range).
    #[error("{0}")]
    Invalid(String),
}

/// Tokens and lines of the text, with the line number of each.
struct Cursor<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> Cursor<'a> {
    fn skip_space(&mut self) {
        let rest = &self.text[self.pos..];
        let skip = rest.len() - rest.trim_start().len();
        self.line += rest[..skip].matches('\n').count();
        self.pos += skip;
    }

    /// The next whitespace-separated token.
    fn token(&mut self, expected: &str) -> Result<(&'a str, usize), FormatError> {
        self.skip_space();
        let rest = &self.text[self.pos..];
        let len = rest.find(char::is_whitespace).unwrap_or(rest.len());
        if len == 0 {
            return Err(FormatError::Truncated {
                expected: expected.into(),
            });
        }
        self.pos += len;
        Ok((&rest[..len], self.line))
    }

    fn int(&mut self, expected: &str) -> Result<usize, FormatError> {
        let (t, line) = self.token(expected)?;
        t.parse().map_err(|_| FormatError::Unexpected {
            line,
            expected: expected.into(),
            found: t.into(),
        })
    }

    /// A finite number.
    fn float(&mut self, expected: &str) -> Result<f64, FormatError> {
        let (t, line) = self.token(expected)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(FormatError::Unexpected {
                line,
                expected: format!("{expected} (a finite number)"),
                found: t.into(),
            }),
        }
    }

    fn ints(&mut self, n: usize, expected: &str) -> Result<Vec<usize>, FormatError> {
        (0..n).map(|_| self.int(expected)).collect()
    }

    /// The next line that is not blank, trimmed.
    fn line(&mut self, expected: &str) -> Result<(&'a str, usize), FormatError> {
        self.skip_space();
        if self.pos == self.text.len() {
            return Err(FormatError::Truncated {
                expected: expected.into(),
            });
        }
        let rest = &self.text[self.pos..];
        let len = rest.find('\n').unwrap_or(rest.len());
        self.pos += len;
        Ok((rest[..len].trim(), self.line))
    }
}

impl FrictionProblem {
    /// Reads a problem from the text of a Siconos file.
    ///
    /// # Errors
    /// A [`FormatError`] that names the line and what was expected there, or the sizes or
    /// values that disagree (a non-square `W`, a negative `μ`, a value that is not finite).
    pub fn parse(text: &str) -> Result<Self, FormatError> {
        let mut c = Cursor { text, pos: 0, line: 1 };
        let dim = c.int("the dimension")?;
        if dim != 2 && dim != 3 {
            return Err(FormatError::Invalid(format!("dimension {dim}: only 2 and 3 exist")));
        }
        let nc = c.int("the number of contacts")?;
        if nc == 0 {
            return Err(FormatError::Invalid("the problem has no contacts".into()));
        }
        let m = nc * dim;
        let storage = c.int("the storage of W (0 dense, 1 sparse block, 2 sparse)")?;
        let (rows, cols) = (c.int("the rows of W")?, c.int("the columns of W")?);
        if rows != m || cols != m {
            return Err(FormatError::Invalid(format!(
                "W is {rows} x {cols}; {nc} contacts in {dim}D need {m} x {m}"
            )));
        }
        let (storage, entries) = match storage {
            0 => (Storage::Dense, dense(&mut c, m)?),
            1 => (Storage::SparseBlock, sparse_block(&mut c, m)?),
            2 => (Storage::Sparse, sparse(&mut c, m)?),
            s => {
                return Err(FormatError::Invalid(format!(
                    "W's storage {s} is unknown (0 dense, 1 sparse block, 2 sparse)"
                )))
            }
        };
        let w = SparseRowMat::try_new_from_triplets(m, m, &entries)
            .map_err(|e| FormatError::Invalid(format!("W: {e:?}")))?;
        let q = (0..m).map(|_| c.float("a value of q")).collect::<Result<Vec<_>, _>>()?;
        let mu = (0..nc)
            .map(|_| c.float("a friction coefficient"))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(i) = mu.iter().position(|&v| v < 0.0) {
            return Err(FormatError::Invalid(format!(
                "contact {i}: friction coefficient {} is negative",
                mu[i]
            )));
        }
        // Siconos' `isComplete` flag, which its older printers write after μ
        let before_flag = (c.pos, c.line);
        if !matches!(c.token(""), Ok(("0" | "1", _))) {
            (c.pos, c.line) = before_flag;
        }
        // the file is read exactly: data after μ mean that the counts do not fit the data
        if let Ok((extra, line)) = c.token("") {
            return Err(FormatError::Invalid(format!(
                "line {line}: `{}` after the {nc} friction coefficients: the file holds more than its header announces (a count of contacts too small, or a second problem)",
                extra.chars().take(40).collect::<String>()
            )));
        }
        Ok(FrictionProblem { dim, w, q, mu, storage })
    }

    /// Why `W` is not a Delassus operator (`H M⁻¹ Hᵀ`, positive semidefinite), where a
    /// contact's own block shows it: a block whose symmetric part has a negative eigenvalue
    /// (beyond round-off of the block's size) makes `W` indefinite, a problem no contact
    /// solver's theory covers. `None` where every block is semidefinite.
    pub fn indefinite(&self) -> Option<String> {
        let d = self.dim;
        for c in 0..self.n_contacts() {
            let mut b = [[0.0f64; 3]; 3];
            for (i, row) in b.iter_mut().enumerate().take(d) {
                for (j, v) in row.iter_mut().enumerate().take(d) {
                    *v = 0.5 * (entry(self, c * d + i, c * d + j) + entry(self, c * d + j, c * d + i));
                }
            }
            let size = b.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            let m = faer::Mat::<f64>::from_fn(d, d, |i, j| b[i][j]);
            let lowest = m
                .self_adjoint_eigenvalues(faer::Side::Lower)
                .map_or(f64::NAN, |e| e.first().copied().unwrap_or(0.0));
            if !(lowest >= -1e-12 * size) {
                return Some(format!(
                    "W is indefinite: the block of contact {c} has the eigenvalue {lowest:.3e} (a Delassus operator W = H M⁻¹ Hᵀ is positive semidefinite)"
                ));
            }
        }
        None
    }

    /// Number of contacts.
    pub fn n_contacts(&self) -> usize {
        self.mu.len()
    }

    /// The largest asymmetry of `W`, `max |W_ij - W_ji|` relative to `max |W_ij|` (Siconos'
    /// files are often asymmetric in their last printed digits).
    pub fn asymmetry(&self) -> f64 {
        let w = self.w.as_ref();
        let (mut diff, mut size) = (0.0f64, 0.0f64);
        for i in 0..w.nrows() {
            for (j, &v) in w.col_idx_of_row(i).zip(w.val_of_row(i)) {
                size = size.max(v.abs());
                diff = diff.max((v - entry(self, j, i)).abs());
            }
        }
        if size > 0.0 {
            diff / size
        } else {
            0.0
        }
    }

    /// `u = W r + q`, in Siconos' layout.
    pub fn velocity(&self, r: &[f64]) -> Vec<f64> {
        let w = self.w.as_ref();
        (0..w.nrows())
            .map(|i| {
                w.col_idx_of_row(i)
                    .zip(w.val_of_row(i))
                    .map(|(j, v)| v * r[j])
                    .sum::<f64>()
                    + self.q[i]
            })
            .collect()
    }

    /// Siconos' error of `r` (with `u = W r + q`): the natural map of De Saxcé's cone
    /// complementarity, `‖r - P_K(r - (u + μ |u_T| e_N))‖`, divided by
    /// `max(‖q‖, ‖r‖, ‖u‖)` (not divided where all three vanish): [`crate::desaxce_residual`]
    /// with this crate's `u = -(W r + q)`.
    pub fn error(&self, r: &[f64]) -> f64 {
        let lambda = self.values(r);
        let u = self.values(&self.velocity(r).iter().map(|v| -v).collect::<Vec<_>>());
        crate::desaxce_residual(&self.points(), &crate::Law::Coulomb, &lambda, &u, &self.loads())
    }

    /// A vector in Siconos' layout as this crate's values.
    fn values(&self, x: &[f64]) -> PointValues {
        let mut flat = vec![0.0; x.len()];
        for (k, v) in x.iter().enumerate() {
            flat[self.to_crate(k)] = *v;
        }
        PointValues::from_flat(&flat, self.n_contacts(), self.dim - 1)
    }

    /// The index in this crate's layout (`[normal (nc); tangential (nc·(dim-1))]`) of row `k`
    /// of Siconos' layout.
    fn to_crate(&self, k: usize) -> usize {
        let (i, c) = (k / self.dim, k % self.dim);
        let nc = self.n_contacts();
        if c == 0 {
            i
        } else {
            nc + i * (self.dim - 1) + c - 1
        }
    }

    /// The problem's contact points in this crate's terms: weights 1, gaps 0, friction `μ`
    /// (the geometry is not used by the solvers; normals along the last axis).
    pub fn points(&self) -> ContactPoints {
        let nc = self.n_contacts();
        let normal = if self.dim == 2 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        ContactPoints {
            dim: self.dim,
            position: vec![[0.0; 3]; nc],
            normal: vec![normal; nc],
            tangent: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; nc],
            weight: vec![1.0; nc],
            gap: vec![0.0; nc],
            friction: self.mu.clone(),
            held: vec![[false; 2]; nc],
            foundation: Default::default(),
            foundations: vec![],
            slipped: vec![],
            weakening: vec![],
            tresca: vec![],
        }
    }

    /// `u0 = -q` in this crate's layout.
    fn loads(&self) -> PointValues {
        let mut flat = vec![0.0; self.q.len()];
        for (k, q) in self.q.iter().enumerate() {
            flat[self.to_crate(k)] = -q;
        }
        PointValues::from_flat(&flat, self.n_contacts(), self.dim - 1)
    }

    /// The problem as a [`SparseContactProblem`] (`D` = `W` in this crate's layout).
    pub fn sparse_problem(&self) -> SparseContactProblem {
        let w = self.w.as_ref();
        let mut entries = Vec::with_capacity(w.compute_nnz());
        for i in 0..w.nrows() {
            for (j, &v) in w.col_idx_of_row(i).zip(w.val_of_row(i)) {
                entries.push(Triplet::new(self.to_crate(i), self.to_crate(j), v));
            }
        }
        let m = w.nrows();
        let compliance =
            SparseRowMat::try_new_from_triplets(m, m, &entries).expect("a permutation of a valid matrix is valid");
        SparseContactProblem {
            u0: self.loads(),
            compliance,
            weight: vec![1.0; self.n_contacts()],
            nt: self.dim - 1,
        }
    }

    /// The problem as a [`DenseContactProblem`] (`m²` values: for small problems).
    pub fn dense_problem(&self) -> DenseContactProblem {
        let w = self.w.as_ref();
        let m = w.nrows();
        let mut compliance = vec![0.0; m * m];
        for i in 0..m {
            for (j, &v) in w.col_idx_of_row(i).zip(w.val_of_row(i)) {
                compliance[self.to_crate(i) * m + self.to_crate(j)] = v;
            }
        }
        DenseContactProblem {
            u0: self.loads(),
            compliance,
            weight: vec![1.0; self.n_contacts()],
            nt: self.dim - 1,
        }
    }

    /// This crate's multipliers as Siconos' `r` (contact by contact).
    pub fn reaction(&self, lambda: &PointValues) -> Vec<f64> {
        let mut r = vec![0.0; self.q.len()];
        for (k, slot) in r.iter_mut().enumerate() {
            let j = self.to_crate(k);
            *slot = if j < self.n_contacts() {
                lambda.normal[j]
            } else {
                lambda.tangential[j - self.n_contacts()]
            };
        }
        r
    }
}

impl FrictionProblem {
    /// The problem in Siconos' text format: `W` stored densely where it has at most 10⁶
    /// entries, else in CSparse's compressed columns (as Siconos writes its large problems).
    /// This module and Siconos read either back.
    pub fn to_text(&self) -> String {
        let m = self.q.len();
        let mut s = format!("{}\n{}\n", self.dim, self.n_contacts());
        if m * m <= 1_000_000 {
            s += &format!("0\n{m}\n{m}\n{m}\t{m}\n");
            for col in 0..m {
                for row in 0..m {
                    s += &format!("{:.17e} ", entry(self, row, col));
                }
                s.push('\n');
            }
        } else {
            let csc = self.w.to_col_major().expect("a valid matrix");
            let csc = csc.as_ref();
            let nnz = csc.compute_nnz();
            s += &format!("2\n{m}\n{m}\n2\nCSparse Version 3.1.9 (written by piezocontact)\n");
            s += &format!("{m}-by-{m}, nzmax: {nnz} nnz: {nnz}, 1-norm: 0\n");
            let mut at = 0;
            for col in 0..m {
                let rows: Vec<(usize, f64)> = csc
                    .row_idx_of_col(col)
                    .zip(csc.val_of_col(col).iter().copied())
                    .collect();
                s += &format!(
                    "    col {col} : locations {at} to {}\n",
                    at as i64 + rows.len() as i64 - 1
                );
                for (row, v) in rows {
                    s += &format!("      {row} : {v:.17e}\n");
                }
                at += csc.row_idx_of_col(col).count();
            }
        }
        for v in &self.q {
            s += &format!("{v:.17e} ");
        }
        s.push('\n');
        for v in &self.mu {
            s += &format!("{v:.17e} ");
        }
        s.push('\n');
        s
    }

    /// A rigid multibody problem, as the time-stepping schemes of Siconos or LMGC90 make them:
    /// `bodies` rigid bodies (3 velocities each in 2D, 6 in 3D) with random masses and
    /// inertias `M`, laid on a square grid, and `contacts` contacts, each between two
    /// neighbours on the grid or a body and the ground, with a random frame and lever arms: `H` maps body velocities to contact velocities,
    /// `W = H M⁻¹ Hᵀ` (semidefinite, of rank at most the number of body velocities) and
    /// `q = H v` for random free velocities `v` (so that a solution exists), friction
    /// coefficients in `[0.1, 1]`. The same `seed` gives the same problem. For testing solvers
    /// on the hard class of rank-deficient problems.
    pub fn multibody(dim: usize, bodies: usize, contacts: usize, seed: u64) -> Self {
        assert!((dim == 2 || dim == 3) && bodies > 0 && contacts > 0);
        let mut rng = SplitMix(seed);
        let dofs = if dim == 2 { 3 } else { 6 };
        let nb = bodies * dofs;
        // M⁻¹ per body velocity: a mass in [1, 10], inertias in [0.1, 1] of it
        let inv_mass: Vec<f64> = (0..bodies)
            .flat_map(|_| {
                let m = 1.0 + 9.0 * rng.unit();
                let mut v = vec![1.0 / m; dim];
                v.extend((dim..dofs).map(|_| 1.0 / (m * (0.1 + 0.9 * rng.unit()))));
                v
            })
            .collect();
        let m = contacts * dim;
        // H by blocks: per contact, the bodies it touches with its dim x dofs block
        let mut touching: Vec<Vec<(usize, Vec<f64>)>> = vec![Vec::new(); contacts];
        for touch in touching.iter_mut() {
            let frame = rng.frame(dim);
            let a = rng.below(bodies);
            let ground = rng.unit() < 0.3 || bodies == 1;
            // a neighbour of `a` on the square grid of bodies (bodies touch their neighbours,
            // as in a pile), wrapping around the ends
            let side = (bodies as f64).sqrt().ceil() as usize;
            let step = if rng.unit() < 0.5 { 1 } else { side };
            let b = (a + step) % bodies;
            for (body, sign) in [(a, 1.0), (b, -1.0)] {
                if sign < 0.0 && ground {
                    continue;
                }
                let arm: Vec<f64> = (0..dim).map(|_| 2.0 * rng.unit() - 1.0).collect();
                // velocity of the contact point of `body`: v + ω × arm
                let mut jac = vec![vec![0.0; dofs]; dim];
                for k in 0..dim {
                    jac[k][k] = 1.0;
                }
                if dim == 2 {
                    jac[0][2] = -arm[1];
                    jac[1][2] = arm[0];
                } else {
                    // ω × r = -[r]ₓ ω
                    let r = &arm;
                    let skew = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
                    for i in 0..3 {
                        for j in 0..3 {
                            jac[i][3 + j] = -skew[i][j];
                        }
                    }
                }
                let mut block = vec![0.0; dim * dofs];
                for (k, axis) in frame.iter().enumerate() {
                    for j in 0..dofs {
                        block[k * dofs + j] = sign * (0..dim).map(|i| axis[i] * jac[i][j]).sum::<f64>();
                    }
                }
                touch.push((body, block));
            }
        }
        let v: Vec<f64> = (0..nb).map(|_| 2.0 * rng.unit() - 1.0).collect();
        let mut q = vec![0.0; m];
        let mut on_body: Vec<Vec<(usize, usize)>> = vec![Vec::new(); bodies];
        for (c, touch) in touching.iter().enumerate() {
            for (t, (body, block)) in touch.iter().enumerate() {
                on_body[*body].push((c, t));
                for k in 0..dim {
                    q[c * dim + k] += (0..dofs).map(|j| block[k * dofs + j] * v[body * dofs + j]).sum::<f64>();
                }
            }
        }
        // W = H M⁻¹ Hᵀ, body by body: the blocks of every pair of contacts on one body
        let mut entries = Vec::new();
        for (body, list) in on_body.iter().enumerate() {
            let inv = &inv_mass[body * dofs..(body + 1) * dofs];
            for &(c1, t1) in list {
                let b1 = &touching[c1][t1].1;
                for &(c2, t2) in list {
                    let b2 = &touching[c2][t2].1;
                    for i in 0..dim {
                        for j in 0..dim {
                            let w: f64 = (0..dofs).map(|k| b1[i * dofs + k] * inv[k] * b2[j * dofs + k]).sum();
                            entries.push(Triplet::new(c1 * dim + i, c2 * dim + j, w));
                        }
                    }
                }
            }
        }
        FrictionProblem {
            dim,
            w: SparseRowMat::try_new_from_triplets(m, m, &entries).expect("valid entries"),
            q,
            mu: (0..contacts).map(|_| 0.1 + 0.9 * rng.unit()).collect(),
            storage: Storage::Dense,
        }
    }
}

/// A small deterministic generator (SplitMix64) for [`FrictionProblem::multibody`].
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n - 1)
    }

    /// A random orthonormal frame, normal first.
    fn frame(&mut self, dim: usize) -> Vec<Vec<f64>> {
        let mut axes: Vec<Vec<f64>> = Vec::new();
        while axes.len() < dim {
            let mut v: Vec<f64> = (0..dim).map(|_| 2.0 * self.unit() - 1.0).collect();
            for a in &axes {
                let d: f64 = v.iter().zip(a).map(|(x, y)| x * y).sum();
                v.iter_mut().zip(a).for_each(|(x, y)| *x -= d * y);
            }
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 0.1 {
                axes.push(v.into_iter().map(|x| x / n).collect());
            }
        }
        axes
    }
}

/// `W_ij` (0 where not stored).
fn entry(p: &FrictionProblem, i: usize, j: usize) -> f64 {
    let w = p.w.as_ref();
    w.col_idx_of_row(i)
        .zip(w.val_of_row(i))
        .find(|(c, _)| *c == j)
        .map_or(0.0, |(_, v)| *v)
}

type Entries = Vec<Triplet<usize, usize, f64>>;

/// Dense storage: the sizes again, then the values column by column.
fn dense(c: &mut Cursor<'_>, m: usize) -> Result<Entries, FormatError> {
    let (r, k) = (c.int("the rows of W, again")?, c.int("the columns of W, again")?);
    if (r, k) != (m, m) {
        return Err(FormatError::Invalid(format!(
            "W's dense part is {r} x {k}; the header said {m} x {m}"
        )));
    }
    let mut entries = Vec::new();
    for col in 0..m {
        for row in 0..m {
            let v = c.float("an entry of W")?;
            if v != 0.0 {
                entries.push(Triplet::new(row, col, v));
            }
        }
    }
    Ok(entries)
}

/// Cumulative block sizes `[e_0, e_1, …]` (each block's end) as block starts and sizes;
/// checked increasing and ending at `m`.
fn block_ranges(ends: &[usize], m: usize, what: &str) -> Result<Vec<(usize, usize)>, FormatError> {
    let mut start = 0;
    let mut out = Vec::with_capacity(ends.len());
    for &end in ends {
        if end <= start {
            return Err(FormatError::Invalid(format!(
                "W's {what} block sizes are not increasing ({end} after {start})"
            )));
        }
        out.push((start, end - start));
        start = end;
    }
    if start != m {
        return Err(FormatError::Invalid(format!(
            "W's {what} blocks end at {start}, not {m}"
        )));
    }
    Ok(out)
}

/// Sparse block storage (Siconos' `SBM_new_from_file`).
fn sparse_block(c: &mut Cursor<'_>, m: usize) -> Result<Entries, FormatError> {
    let n_blocks = c.int("the number of blocks")?;
    if n_blocks == 0 {
        return Ok(Vec::new());
    }
    let block_rows = c.int("the number of block rows")?;
    let block_cols = c.int("the number of block columns")?;
    let rows = block_ranges(&c.ints(block_rows, "a block row's end")?, m, "row")?;
    let cols = block_ranges(&c.ints(block_cols, "a block column's end")?, m, "column")?;
    let filled1 = c.int("the length of the block-row pointers")?;
    let filled2 = c.int("the number of stored blocks")?;
    if filled1 != block_rows + 1 || filled2 != n_blocks {
        return Err(FormatError::Invalid(format!(
            "W's block index has {filled1} row pointers and {filled2} blocks; {block_rows} block rows and {n_blocks} blocks need {} and {n_blocks}",
            block_rows + 1
        )));
    }
    let row_ptr = c.ints(filled1, "a block-row pointer")?;
    let col_idx = c.ints(filled2, "a block-column index")?;
    if row_ptr[0] != 0 || row_ptr.windows(2).any(|p| p[1] < p[0]) || row_ptr[block_rows] != n_blocks {
        return Err(FormatError::Invalid(
            "W's block-row pointers do not run from 0 up to the number of blocks".into(),
        ));
    }
    if let Some(&j) = col_idx.iter().find(|&&j| j >= block_cols) {
        return Err(FormatError::Invalid(format!(
            "W's block-column index {j} is beyond its {block_cols} block columns"
        )));
    }
    let mut entries = Vec::new();
    for (bi, &(r0, nr)) in rows.iter().enumerate() {
        for b in row_ptr[bi]..row_ptr[bi + 1] {
            let number = c.int("a block's number")?;
            if number != b {
                return Err(FormatError::Invalid(format!("W's block {b} is numbered {number}")));
            }
            let (c0, nk) = cols[col_idx[b]];
            for col in 0..nk {
                for row in 0..nr {
                    let v = c.float("an entry of a block of W")?;
                    if v != 0.0 {
                        entries.push(Triplet::new(r0 + row, c0 + col, v));
                    }
                }
            }
        }
    }
    Ok(entries)
}

/// Sparse storage: the origin, then CSparse's printout (`CSparseMatrix_new_from_file`).
fn sparse(c: &mut Cursor<'_>, m: usize) -> Result<Entries, FormatError> {
    c.int("the sparse matrix's origin")?;
    // the banner ("CSparse Version …"), then the line with the sizes
    let (mut header, mut line) = c.line("CSparse's header")?;
    while !header.contains("-by-") {
        (header, line) = c.line("CSparse's line `m-by-n, nzmax: … nnz: …`")?;
    }
    let unexpected = |expected: &str, found: &str, line: usize| FormatError::Unexpected {
        line,
        expected: expected.into(),
        found: found.into(),
    };
    let triplet = header.starts_with("triplet:");
    let sizes = header.trim_start_matches("triplet:").trim();
    let by = |s: &str| -> Option<(usize, usize)> {
        let (a, rest) = s.split_once("-by-")?;
        let b = rest.split(|ch: char| ch == ',' || ch.is_whitespace()).next()?;
        Some((a.trim().parse().ok()?, b.parse().ok()?))
    };
    let (rows, cols) = by(sizes).ok_or_else(|| unexpected("`m-by-n, …`", header, line))?;
    if (rows, cols) != (m, m) {
        return Err(FormatError::Invalid(format!(
            "W's sparse part is {rows} x {cols}; the header said {m} x {m}"
        )));
    }
    let nnz: usize = header
        .split_once("nnz:")
        .and_then(|(_, rest)| rest.trim().split(|ch: char| ch == ',' || ch.is_whitespace()).next())
        .and_then(|t| t.parse().ok())
        .ok_or_else(|| unexpected("`nnz: N` in CSparse's header", header, line))?;
    // an untrusted count: the text left bounds the entries it can hold (4 bytes each at least)
    let mut entries = Vec::with_capacity(nnz.min((c.text.len() - c.pos) / 4));
    // "i : x" (compressed) or "i j : x" (triplet)
    let mut entry = |c: &mut Cursor<'_>, col: Option<usize>| -> Result<(), FormatError> {
        let expected = if col.is_some() { "`i : x`" } else { "`i j : x`" };
        let (text, line) = c.line(expected)?;
        let (index, value) = text.split_once(':').ok_or_else(|| unexpected(expected, text, line))?;
        let mut idx = index.split_whitespace().map(str::parse::<usize>);
        let (i, j) = match (idx.next(), col, idx.next()) {
            (Some(Ok(i)), Some(j), None) => (i, j),
            (Some(Ok(i)), None, Some(Ok(j))) => (i, j),
            _ => return Err(unexpected(expected, text, line)),
        };
        let v = match value.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => return Err(unexpected("a finite entry", text, line)),
        };
        if i >= m || j >= m {
            return Err(FormatError::Invalid(format!(
                "line {line}: W's entry ({i}, {j}) is outside {m} x {m}"
            )));
        }
        entries.push(Triplet::new(i, j, v));
        Ok(())
    };
    if triplet {
        for _ in 0..nnz {
            entry(c, None)?;
        }
    } else {
        for col in 0..m {
            let expected = format!("`col {col} : locations a to b`");
            let (text, line) = c.line(&expected)?;
            let range = text
                .strip_prefix("col")
                .and_then(|s| s.split_once(": locations"))
                .and_then(|(j, range)| {
                    let (a, b) = range.split_once("to")?;
                    let (a, b) = (a.trim().parse::<i64>().ok()?, b.trim().parse::<i64>().ok()?);
                    (j.trim().parse::<usize>().ok()? == col).then_some((a, b))
                })
                .ok_or_else(|| unexpected(&expected, text, line))?;
            for _ in range.0..=range.1 {
                entry(c, Some(col))?;
            }
        }
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One 3D contact: W = diag(2, 1, 1) stored densely, q = (-1, 0.5, 0), μ = 0.3.
    const ONE: &str = "3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 1 0\n0 0 1\n-1 0.5 0\n0.3\n";

    #[test]
    fn reads_the_three_storages_alike() {
        let dense = FrictionProblem::parse(ONE).unwrap();
        assert_eq!((dense.dim, dense.n_contacts(), dense.storage), (3, 1, Storage::Dense));
        let block = "3\n1\n1\n3\n3\n1\n1\n1\n3\n3\n2\n1\n0\n1\n0\n0\n2 0 0 0 1 0 0 0 1\n-1 0.5 0\n0.3\n";
        let sparse = "3\n1\n2\n3\n3\n3\nCSparse Version 3.1.9, May 4, 2016.  Copyright\n3-by-3, nzmax: 3 nnz: 3, 1-norm: 2\n    col 0 : locations 0 to 0\n      0 : 2\n    col 1 : locations 1 to 1\n      1 : 1\n    col 2 : locations 2 to 2\n      2 : 1\n-1 0.5 0\n0.3\n";
        let triplet = "3\n1\n2\n3\n3\n1\nCSparse banner\ntriplet: 3-by-3, nzmax: 3 nnz: 3\n    0 0 : 2\n    1 1 : 1\n    2 2 : 1\n-1 0.5 0\n0.3\n";
        for (text, storage) in [
            (block, Storage::SparseBlock),
            (sparse, Storage::Sparse),
            (triplet, Storage::Sparse),
        ] {
            let p = FrictionProblem::parse(text).unwrap();
            assert_eq!(p.storage, storage);
            assert_eq!(p.velocity(&[1.0, 2.0, 3.0]), dense.velocity(&[1.0, 2.0, 3.0]));
            assert_eq!((p.q.clone(), p.mu.clone()), (dense.q.clone(), dense.mu.clone()));
        }
    }

    /// The hand solution of [`ONE`]: the contact closes (u_N = 0 needs r_N = 1/2); sticking
    /// would need r_T = (-0.5, 0), beyond μ r_N = 0.15, so it slides against u_T with
    /// |r_T| = 0.15: r_T = (-0.15, 0), u_T = (0.35, 0).
    #[test]
    fn the_error_vanishes_at_the_hand_solution_only() {
        let p = FrictionProblem::parse(ONE).unwrap();
        let r = [0.5, -0.15, 0.0];
        assert!(p.error(&r) < 1e-16, "{}", p.error(&r));
        assert!(p.error(&[0.5, 0.0, 0.0]) > 1e-2);
        assert!(p.error(&[0.4, -0.12, 0.0]) > 1e-2);
        // in this crate's terms: λ = r, u = -(W r + q)
        let dense = p.dense_problem();
        let mut u = PointValues::zeros(1, 2);
        crate::ContactOperator::displacement(&mut dense.clone(), &p.values(&r), &mut u).unwrap();
        let v = p.velocity(&r);
        assert_eq!(p.reaction(&u), v.iter().map(|x| -x).collect::<Vec<_>>());
    }

    #[test]
    fn bad_files_are_named() {
        let cases = [
            ("", "ends where the dimension"),
            ("4\n1\n", "dimension 4"),
            ("3\n0\n", "no contacts"),
            ("3\n1\n0\n3\n2\n", "W is 3 x 2"),
            ("3\n1\n7\n3\n3\n", "storage 7"),
            ("3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 x 0\n", "line 8: expected an entry of W"),
            ("3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 1 0\n0 0 nan\n", "a finite number"),
            ("3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 1 0\n0 0 1\n-1 0.5 0\n-0.3\n", "negative"),
            (
                "3\n1\n0\n3\n3\n3\t3\n2 0 0\n0 1 0\n0 0 1\n-1 0.5\n",
                "ends where a value of q",
            ),
        ];
        for (text, needle) in cases {
            let e = FrictionProblem::parse(text).unwrap_err().to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }
}
