//! The supernodal symbolic factor of a matrix whose order is a postorder of its elimination
//! tree (as [`super::postordered`] makes it), from its lower triangle in that order
//! ([`super::Lower`]) and the tree: the column counts of `L` by Gilbert, Ng and Peyton's
//! algorithm, in time about proportional to the matrix's entries (SIAM J. Matrix Anal. Appl.
//! 15 (1994); the form of Davis, *Direct Methods for Sparse Linear Systems*, SIAM 2006,
//! §4.5), then faer's supernodal structure from them. faer's own analysis counts the columns
//! by walking each row's subtree, in time proportional to the entries of `L` (0.67 s of its
//! 0.83 s at `paper-3d` n = 32), so that the counts are the part of the analysis worth
//! replacing. The result is the one faer computes for the same order: the tests compare them.

use super::Lower;
use crate::LinalgError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::simplicial::{
    prefactorize_symbolic_cholesky, prefactorize_symbolic_cholesky_scratch,
};
use faer::sparse::linalg::cholesky::supernodal::{
    factorize_supernodal_symbolic_cholesky, factorize_supernodal_symbolic_cholesky_scratch, SymbolicSupernodalCholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

/// No parent: a root of the elimination tree.
const ROOT: usize = usize::MAX;

/// The supernodal symbolic factor of `a` (its lower triangle is read) in the order `inv`
/// (`inv[old] = new`), with `parent` its elimination tree in that order, which must be a
/// postorder (children before parents, every subtree contiguous); with it, `a`'s lower
/// triangle in that order (built beside the upper triangle's pattern). faer's relaxed
/// supernodes (its default parameters, as its own analysis uses).
///
/// # Errors
/// [`LinalgError::Symbolic`] where faer refuses the structure (an index overflow).
pub(crate) fn supernodal(
    a: SparseColMatRef<'_, usize, f64>,
    inv: &[usize],
    parent: &[usize],
) -> Result<(SymbolicSupernodalCholesky<usize>, Lower), LinalgError> {
    let n = parent.len();
    let (lower, (col_ptr, rows)) = rayon::join(|| Lower::new(a, Some(inv)), || super::upper_lists(a, inv, 0..n));
    let counts = column_counts(&lower, parent);
    let upper = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &col_ptr, None, &rows);
    // faer takes the tree only as computed by its own analysis of a matrix: that of the tree's
    // own pattern (column j: the diagonal and `parent[j]`), whose elimination tree is the tree
    // itself, costs one step per column (its counts, those of a factor with no fill, are not
    // used)
    let (child_ptr, children) = super::children_of(parent);
    let mut tree_ptr = Vec::with_capacity(n + 1);
    let mut tree_rows = Vec::with_capacity(children.len() + n);
    tree_ptr.push(0);
    for k in 0..n {
        // the children in increasing order, then the diagonal (the largest row of its column)
        tree_rows.extend_from_slice(&children[child_ptr[k]..child_ptr[k + 1]]);
        tree_rows.push(k);
        tree_ptr.push(tree_rows.len());
    }
    let tree = SymbolicSparseColMatRef::new_checked(n, n, &tree_ptr, None, &tree_rows);
    let mut etree = vec![0isize; n];
    let mut no_fill = vec![0usize; n];
    let mut mem = MemBuffer::new(prefactorize_symbolic_cholesky_scratch::<usize>(n, tree_rows.len()));
    let etree = prefactorize_symbolic_cholesky(&mut etree, &mut no_fill, tree, MemStack::new(&mut mem));
    let mut mem = MemBuffer::new(factorize_supernodal_symbolic_cholesky_scratch::<usize>(n));
    let sym =
        factorize_supernodal_symbolic_cholesky(upper, etree, &counts, MemStack::new(&mut mem), Default::default())
            .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
    Ok((sym, lower))
}

/// The number of entries of each column of `L` (its diagonal included), for the matrix whose
/// lower triangle is `lower` and whose elimination tree is `parent`, the order a postorder of
/// it. Gilbert, Ng and Peyton: a column's count is the number of leaves of the row subtrees
/// that reach it, less their overlaps, which sit at the least common ancestors of consecutive
/// leaves (found by a disjoint-set forest with path compression); each is recorded as a
/// difference at one node and the differences summed up the tree.
pub(crate) fn column_counts(lower: &Lower, parent: &[usize]) -> Vec<usize> {
    let n = parent.len();
    // first[j]: the first descendant of j in the postorder (the order itself); a leaf is
    // its own first descendant
    let mut first = vec![ROOT; n];
    let mut delta = vec![0isize; n];
    for k in 0..n {
        let mut j = k;
        delta[k] = isize::from(first[k] == ROOT);
        while j != ROOT && first[j] == ROOT {
            first[j] = k;
            j = parent[j];
        }
    }
    let mut ancestor: Vec<usize> = (0..n).collect();
    let mut max_first = vec![ROOT; n];
    let mut prev_leaf = vec![ROOT; n];
    for j in 0..n {
        if parent[j] != ROOT {
            delta[parent[j]] -= 1;
        }
        for &i in &lower.rows[lower.col_ptr[j]..lower.col_ptr[j + 1]] {
            // is j a leaf of row i's subtree (no earlier column of it below j)?
            if i <= j || (max_first[i] != ROOT && first[j] <= max_first[i]) {
                continue;
            }
            max_first[i] = first[j];
            let previous = prev_leaf[i];
            prev_leaf[i] = j;
            delta[j] += 1;
            if previous != ROOT {
                // the overlap of the paths from the two leaves up to i starts at their
                // least common ancestor
                let mut q = previous;
                while q != ancestor[q] {
                    q = ancestor[q];
                }
                let mut s = previous;
                while s != q {
                    let up = ancestor[s];
                    ancestor[s] = q;
                    s = up;
                }
                delta[q] -= 1;
            }
        }
        if parent[j] != ROOT {
            ancestor[j] = parent[j];
        }
    }
    for j in 0..n {
        if parent[j] != ROOT {
            delta[parent[j]] += delta[j];
        }
    }
    delta.into_iter().map(|d| d as usize).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, simplicial, CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering,
    };
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::{SparseColMat, Triplet};
    use faer::Side;
    use proptest::prelude::*;

    /// A symmetric pattern's lower triangle: a grid of `side²` nodes with `dofs` unknowns each,
    /// coupled to their neighbours, plus `extra` long-range pairs (`pairs`, folded into range);
    /// and entries above the diagonal (`above`, unknowns folded into range), which an analysis
    /// of the lower triangle must not read.
    fn matrix(
        side: usize,
        dofs: usize,
        pairs: &[(usize, usize)],
        above: &[(usize, usize)],
    ) -> SparseColMat<usize, f64> {
        let nodes = side * side;
        let n = nodes * dofs;
        let mut t = vec![];
        let mut couple = |p: usize, q: usize| {
            for a in 0..dofs {
                for b in 0..dofs {
                    let (i, j) = (p * dofs + a, q * dofs + b);
                    if i > j {
                        t.push(Triplet::new(i, j, -1.0));
                    }
                }
            }
        };
        for p in 0..nodes {
            couple(p, p);
            if p % side + 1 < side {
                couple(p + 1, p);
            }
            if p + side < nodes {
                couple(p + side, p);
            }
        }
        for &(p, q) in pairs {
            let (p, q) = (p % nodes, q % nodes);
            if p != q {
                couple(p.max(q), p.min(q));
            }
        }
        for &(i, j) in above {
            let (i, j) = (i % n, j % n);
            if i != j {
                t.push(Triplet::new(i.min(j), i.max(j), 1.0));
            }
        }
        for i in 0..n {
            t.push(Triplet::new(i, i, 8.0));
        }
        // duplicates (a pair drawn twice) are summed
        SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap()
    }

    /// faer's analysis and this one, for `a` in the order `fwd` made a postorder.
    fn both(
        a: &SparseColMat<usize, f64>,
        fwd: &[usize],
    ) -> (Vec<usize>, Vec<usize>, SymbolicSupernodalCholesky<usize>, Vec<usize>) {
        let n = a.nrows();
        let mut inv = vec![0; n];
        for (new, &old) in fwd.iter().enumerate() {
            inv[old] = new;
        }
        let (post, parent) = super::super::postordered(a.as_ref(), fwd, &inv).unwrap();
        let mut post_inv = vec![0; n];
        for (new, &old) in post.iter().enumerate() {
            post_inv[old] = new;
        }
        let (ours, lower) = supernodal(a.as_ref(), &post_inv, &parent).unwrap();
        (post, post_inv, ours, column_counts(&lower, &parent))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The column counts are faer's (its walk of every row's subtree), and the supernodes,
        /// their patterns and the factor's layout are those of faer's own analysis in the same
        /// order, on grids with long-range couplings in scrambled orders.
        #[test]
        fn the_analysis_is_faers(
            side in 2usize..14,
            dofs in 1usize..4,
            pairs in proptest::collection::vec((0usize..200, 0usize..200), 0..12),
            above in proptest::collection::vec((0usize..600, 0usize..600), 0..8),
            stride in 1usize..50,
        ) {
            let a = matrix(side, dofs, &pairs, &above);
            let n = a.nrows();
            // a scrambled order: i * s mod n with s coprime to n
            let s = (stride..stride + n + 1).find(|s| gcd(*s, n) == 1).unwrap();
            let fwd: Vec<usize> = (0..n).map(|i| i * s % n).collect();
            let (post, post_inv, ours, counts) = both(&a, &fwd);

            // faer's counts, on the lower triangle's pattern made upper in the same order
            let perm = PermRef::new_checked(&post, &post_inv, n);
            let mut t = vec![];
            for j in 0..n {
                for &i in a.symbolic().row_idx_of_col_raw(j).iter().filter(|&&i| i >= j) {
                    let (pi, pj) = (post_inv[i], post_inv[j]);
                    t.push(Triplet::new(pi.min(pj), pi.max(pj), 1.0));
                }
            }
            let upper = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
            let mut etree = vec![0isize; n];
            let mut faer_counts = vec![0usize; n];
            let mut mem = MemBuffer::new(simplicial::prefactorize_symbolic_cholesky_scratch::<usize>(n, upper.compute_nnz()));
            simplicial::prefactorize_symbolic_cholesky(&mut etree, &mut faer_counts, upper.symbolic(), MemStack::new(&mut mem));
            prop_assert_eq!(&counts, &faer_counts);

            let params = CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let theirs = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Custom(perm), params).unwrap();
            let SymbolicCholeskyRaw::Supernodal(theirs) = theirs.raw() else {
                panic!("forced supernodal");
            };
            prop_assert_eq!(ours.supernode_begin(), theirs.supernode_begin());
            prop_assert_eq!(ours.col_ptr_for_row_idx(), theirs.col_ptr_for_row_idx());
            prop_assert_eq!(ours.col_ptr_for_val(), theirs.col_ptr_for_val());
            prop_assert_eq!(ours.row_idx(), theirs.row_idx());
        }
    }

    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
}
