//! The numeric `L D Lᵀ` of a supernodal symbolic factor on every core of rayon's pool: the
//! supernodes' elimination tree is walked from the leaves, and subtrees that share no
//! supernode are factored at the same time (they read only their own descendants and write
//! only their own values), the supernodes above them with faer's parallel dense kernels and
//! their columns assembled in pieces on different threads (each piece reads every descendant's
//! update of its columns, and writes only its own columns).
//!
//! Each supernode is the left-looking step of faer's sequential
//! `factorize_supernodal_numeric_ldlt` (faer 0.24): gather the matrix's columns, subtract
//! `L_d D_d L_dᵀ` of every descendant `d` whose row pattern meets the supernode, factor the
//! diagonal block densely (`L D Lᵀ`, no pivoting) and solve for the rows below it. The values
//! are laid out as faer lays them, so every solve and every view of the factor (the trailing
//! block of the contact dofs) reads them unchanged. faer parallelises only inside a supernode,
//! which on a 2D mesh's many small supernodes costs more than it gains
//! (docs/performance.md); here the tree gives the second core its own half of the work.

use crate::progress::FactorProgress;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LdltParams, LdltRegularization,
};
use faer::linalg::matmul::triangular::BlockStructure;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::SparseColMatRef;
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

mod analysis;
mod solve;

pub(crate) use analysis::supernodal;

/// Subtrees with fewer floating-point operations than this are factored on one core, in
/// order (a task of this size takes about 2 ms; below it the cost of a task's scratch and of
/// stealing it shows).
const SEQUENTIAL_FLOPS: f64 = 2e7;

/// The narrowest piece of a supernode's columns assembled on a thread of its own (wide
/// supernodes, above the independent subtrees, are cut into pieces: [`column_pieces`]).
const PIECE_COLS: usize = 32;

/// From this many columns on, a supernode's dense `L D Lᵀ` updates its trailing block
/// [`WIDE_PANEL`] columns at a time rather than faer's default 128: each panel's update reads
/// and writes the whole trailing triangle, and on the root of a 3D mesh (10 630 columns at
/// `paper-3d` n = 32) 128-column panels make that traffic what two cores wait on.
const WIDE_FROM: usize = 4096;

/// The panel of a wide supernode's dense `L D Lᵀ` ([`WIDE_FROM`]).
const WIDE_PANEL: usize = 512;

/// Why the numeric factorisation of a supernode stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Breakdown {
    /// A zero pivot at this (permuted) index.
    ZeroPivot(usize),
    /// A NaN or an infinity (an overflow) at this index of the factor's values: each
    /// supernode's values are checked right after it is factored, while they are in cache,
    /// rather than all of them in one pass after (a 5 GB factor read again on one core).
    NonFinite(usize),
}

/// What the parallel numeric factorisation needs beyond faer's symbolic factor, computed once
/// per pattern: the supernodes' tree, the descendants that update each supernode, the work of
/// each subtree, and the matrix's lower triangle in the factor's order (its pattern, and where
/// each value comes from).
#[derive(Debug)]
pub(crate) struct Tree {
    /// `parent[s]`: the supernode holding the first row of `s`'s pattern (`usize::MAX` for a
    /// root).
    parent: Vec<usize>,
    /// `first[s]`: the first supernode of `s`'s subtree, which is `first[s]..=s` (postorder).
    first: Vec<usize>,
    /// `updaters[upd_ptr[s]..upd_ptr[s + 1]]`: the supernodes whose pattern meets `s`'s columns.
    upd_ptr: Vec<usize>,
    updaters: Vec<usize>,
    /// Floating-point operations of each supernode's subtree.
    work: Vec<f64>,
    /// Floating-point operations of each supernode's own columns.
    own_work: Vec<f64>,
    /// The lower triangle in the factor's order: column pointers, rows, and the index of each
    /// value in the input matrix's values.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    src: Vec<usize>,
}

impl Tree {
    /// The tree of `sym`'s supernodes, and `a`'s lower triangle in the order `inv`
    /// (`inv[old] = new`): `lower` where it was built already ([`Lower::new`], while the
    /// symbolic factorisation ran), else now, beside the tree's shape. `None` where the
    /// supernodes are not in postorder (each subtree contiguous), which the schedule needs.
    pub(crate) fn new(
        sym: &SymbolicSupernodalCholesky<usize>,
        a: SparseColMatRef<'_, usize, f64>,
        inv: Option<&[usize]>,
        lower: Option<Lower>,
    ) -> Option<Tree> {
        let (shape, lower) = match lower {
            Some(lower) => (Tree::shape(sym), lower),
            None => rayon::join(|| Tree::shape(sym), || Lower::new(a, inv)),
        };
        let (parent, first, upd_ptr, updaters, (work, own_work)) = shape?;
        let Lower { col_ptr, rows, src } = lower;
        Some(Tree {
            parent,
            first,
            upd_ptr,
            updaters,
            work,
            own_work,
            col_ptr,
            row_idx: rows,
            src,
        })
    }

    /// The supernodes' parents, first descendants, updaters (pointers and list), and subtree
    /// and own work; `None` where they are not in postorder.
    #[allow(clippy::type_complexity)]
    fn shape(
        sym: &SymbolicSupernodalCholesky<usize>,
    ) -> Option<(Vec<usize>, Vec<usize>, Vec<usize>, Vec<usize>, (Vec<f64>, Vec<f64>))> {
        let ns = sym.n_supernodes();
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (cp_row, row_idx) = (sym.col_ptr_for_row_idx(), sym.row_idx());
        let of_col = supernode_of_column(sym);
        let mut parent = vec![usize::MAX; ns];
        let mut size = vec![1usize; ns];
        let mut work = vec![0.0; ns];
        let mut lists: Vec<Vec<usize>> = vec![Vec::new(); ns];
        for d in 0..ns {
            let pattern = &row_idx[cp_row[d]..cp_row[d + 1]];
            if let Some(&r) = pattern.first() {
                parent[d] = of_col[r];
            }
            let mut last = usize::MAX;
            for &r in pattern {
                let s = of_col[r];
                if s != last {
                    lists[s].push(d);
                    last = s;
                }
            }
            let w = end[d] - begin[d];
            work[d] += (0..w)
                .map(|j| {
                    let c = (w - 1 - j + pattern.len()) as f64;
                    c * (c + 3.0)
                })
                .sum::<f64>();
        }
        let own_work = work.clone();
        for s in 0..ns {
            if parent[s] != usize::MAX {
                if parent[s] <= s {
                    return None;
                }
                size[parent[s]] += size[s];
                work[parent[s]] += work[s];
            }
        }
        let first: Vec<usize> = (0..ns).map(|s| s + 1 - size[s]).collect();
        // postorder: every supernode's subtree is the range of its size ending at it
        for s in 0..ns {
            let p = parent[s];
            if p != usize::MAX && !(first[p] <= first[s] && s < p) {
                return None;
            }
        }
        let mut upd_ptr = Vec::with_capacity(ns + 1);
        upd_ptr.push(0);
        let mut updaters = Vec::new();
        for l in lists {
            updaters.extend(l);
            upd_ptr.push(updaters.len());
        }
        Some((parent, first, upd_ptr, updaters, (work, own_work)))
    }

    /// The operations of a numeric factorisation: the supernodes' own work, summed.
    pub(crate) fn work_total(&self) -> f64 {
        self.own_work.iter().sum()
    }

    /// Factors `a` (the pattern the tree was built for) into `values`, faer's supernodal
    /// layout, on rayon's pool, every value checked finite; each supernode's work added to
    /// `progress` as it is done.
    pub(crate) fn factor(
        &self,
        sym: &SymbolicSupernodalCholesky<usize>,
        a: SparseColMatRef<'_, usize, f64>,
        values: &mut [f64],
        (par, progress): (Par, Option<&FactorProgress>),
    ) -> Result<(), Breakdown> {
        if let Some(p) = progress {
            p.start(&self.own_work);
        }
        let ctx = Ctx {
            sym,
            tree: self,
            values: a.val(),
            par,
            progress,
        };
        let ns = sym.n_supernodes();
        ctx.forest(0, ns, values, 0)
    }
}

/// How a range of supernodes, a union of whole subtrees, is walked ([`Tree::split`]).
pub(crate) enum Split {
    /// On this thread, in order.
    InOrder,
    /// The range's one root: the subtree below it apart from it (before it when factoring or
    /// sweeping forward, after it when sweeping back).
    Root(usize),
    /// Two groups of whole subtrees, `lo..mid` and `mid..hi`, at the same time.
    Between(usize),
}

impl Tree {
    /// How the supernodes `lo..hi` (whole subtrees) are walked, given the `size` of each
    /// subtree by its root: in order on this thread where they are smaller than `sequential`
    /// in all (or the pool has one thread); the one root apart where there is one; else cut
    /// between two groups of whole subtrees of about half the size each.
    pub(crate) fn split(&self, lo: usize, hi: usize, size: impl Fn(usize) -> f64, sequential: f64) -> Split {
        let roots: Vec<usize> = (lo..hi).filter(|&s| self.parent[s] >= hi).collect();
        let total: f64 = roots.iter().map(|&r| size(r)).sum();
        if total < sequential || rayon::current_num_threads() < 2 {
            return Split::InOrder;
        }
        if let [root] = roots[..] {
            return Split::Root(root);
        }
        let mut acc = 0.0;
        let mut cut = roots[roots.len() - 1];
        for &r in &roots {
            acc += size(r);
            if acc >= total / 2.0 {
                cut = r;
                break;
            }
        }
        // the last root ends the range: cut before its subtree instead of after it
        Split::Between(if cut == hi - 1 { self.first[cut] } else { cut + 1 })
    }
}

/// The order `fwd` (`inv` its inverse; both empty: no order given) made a postorder of its
/// elimination tree: children before their parent, every subtree contiguous, roots and
/// children kept in their order. The tree by Liu's algorithm with path compression (Liu, ACM
/// TOMS 12 (1986)) on the pattern of `a` in the order `fwd`. With it, the tree in the new
/// order (`parent[k]`, `usize::MAX` for a root). `None` where no order was given.
pub(crate) fn postordered(
    a: SparseColMatRef<'_, usize, f64>,
    fwd: &[usize],
    inv: &[usize],
) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = a.nrows();
    if fwd.len() != n || inv.len() != n {
        return None;
    }
    // for each new column k, the new rows i < k of its upper part: gathered by ranges of the
    // input's columns at the same time, each range's own lists (the tree is the same whatever
    // the ranges; the lists' page faults and the scattered reads of `inv` shared out)
    let chunks: Vec<(Vec<usize>, Vec<usize>)> = column_ranges(a, rayon::current_num_threads())
        .into_par_iter()
        .map(|cols| upper_lists(a, inv, cols))
        .collect();
    let parent = elimination_tree(n, &chunks);
    let (child_ptr, children) = children_of(&parent);
    let mut out = Vec::with_capacity(n);
    // the new place of each column, to carry the tree over
    let mut place = vec![0usize; n];
    let roots = (0..n).filter(|&k| parent[k] == usize::MAX);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for r in roots {
        stack.push((r, child_ptr[r]));
        while let Some((v, c)) = stack.pop() {
            if c < child_ptr[v + 1] {
                stack.push((v, c + 1));
                let w = children[c];
                stack.push((w, child_ptr[w]));
            } else {
                place[v] = out.len();
                out.push(fwd[v]);
            }
        }
    }
    let mut new_parent = vec![usize::MAX; n];
    for (v, &p) in parent.iter().enumerate() {
        if p != usize::MAX {
            new_parent[place[v]] = place[p];
        }
    }
    Some((out, new_parent))
}

/// The children of each node of the forest `parent` (`usize::MAX` for a root), in increasing
/// order: `children[ptr[k]..ptr[k + 1]]`.
fn children_of(parent: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let n = parent.len();
    let mut ptr = vec![0usize; n + 1];
    for &p in parent {
        if p != usize::MAX {
            ptr[p + 1] += 1;
        }
    }
    for k in 0..n {
        ptr[k + 1] += ptr[k];
    }
    let mut at = ptr.clone();
    let mut children = vec![0usize; ptr[n]];
    for (c, &p) in parent.iter().enumerate() {
        if p != usize::MAX {
            children[at[p]] = c;
            at[p] += 1;
        }
    }
    (ptr, children)
}

/// The parent of each of the `n` columns in the elimination tree (`usize::MAX` for a root), by
/// Liu's algorithm with path compression, from lists by column `k` of the rows `i < k` of its
/// upper part (from several ranges of the input's columns: [`upper_lists`]).
fn elimination_tree(n: usize, lists: &[(Vec<usize>, Vec<usize>)]) -> Vec<usize> {
    let mut parent = vec![usize::MAX; n];
    let mut ancestor = vec![usize::MAX; n];
    for k in 0..n {
        for &i0 in lists.iter().flat_map(|(ptr, upper)| &upper[ptr[k]..ptr[k + 1]]) {
            let mut i = i0;
            while i != usize::MAX && i < k {
                let up = ancestor[i];
                ancestor[i] = k;
                if up == usize::MAX {
                    parent[i] = k;
                }
                i = up;
            }
        }
    }
    parent
}

/// `0..n` cut into at most `parts` ranges of the columns of `a` with about as many entries
/// each.
fn column_ranges(a: SparseColMatRef<'_, usize, f64>, parts: usize) -> Vec<std::ops::Range<usize>> {
    let n = a.ncols();
    let sym = a.symbolic();
    let total: usize = (0..n).map(|j| sym.row_idx_of_col_raw(j).len()).sum();
    let share = total.div_ceil(parts.max(1)).max(1);
    let (mut ranges, mut start, mut acc) = (Vec::new(), 0, 0);
    for j in 0..n {
        acc += sym.row_idx_of_col_raw(j).len();
        if acc >= share * (ranges.len() + 1) && ranges.len() + 1 < parts {
            ranges.push(start..j + 1);
            start = j + 1;
        }
    }
    ranges.push(start..n);
    ranges
}

/// The entries of the columns `cols` of `a`'s lower triangle (entries above the diagonal are
/// not read) in the order `inv`, as lists by new column `k` of the new rows `i < k` (the upper
/// part of the reordered matrix, no diagonal): `upper[ptr[k]..ptr[k + 1]]`.
pub(super) fn upper_lists(
    a: SparseColMatRef<'_, usize, f64>,
    inv: &[usize],
    cols: std::ops::Range<usize>,
) -> (Vec<usize>, Vec<usize>) {
    let n = a.nrows();
    let sym = a.symbolic();
    let mut ptr = vec![0usize; n + 1];
    for j in cols.clone() {
        for &i in sym.row_idx_of_col_raw(j) {
            let (pi, pj) = (inv[i], inv[j]);
            if i > j {
                ptr[pi.max(pj) + 1] += 1;
            }
        }
    }
    for k in 0..n {
        ptr[k + 1] += ptr[k];
    }
    let mut next = ptr.clone();
    let mut upper = vec![0usize; ptr[n]];
    for j in cols {
        for &i in sym.row_idx_of_col_raw(j) {
            let (pi, pj) = (inv[i], inv[j]);
            if i > j {
                let k = pi.max(pj);
                upper[next[k]] = pi.min(pj);
                next[k] += 1;
            }
        }
    }
    (ptr, upper)
}

/// The supernode each column belongs to.
fn supernode_of_column(sym: &SymbolicSupernodalCholesky<usize>) -> Vec<usize> {
    let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
    let mut of_col = vec![0usize; sym.nrows()];
    for s in 0..sym.n_supernodes() {
        of_col[begin[s]..end[s]].fill(s);
    }
    of_col
}

/// The columns of `sym` (in its order) reordered so that its supernodes come in postorder,
/// every subtree contiguous and ending at its root (roots and children in their order, so a
/// connected factor's last supernode stays last): `order[new] = old` in `sym`'s order. A
/// postorder is an equivalent ordering (the same elimination tree, the same fill; Liu, SIAM
/// J. Matrix Anal. Appl. 11 (1990)), so the symbolic analysis of the reordered matrix finds
/// the same supernodes.
pub(crate) fn postorder(sym: &SymbolicSupernodalCholesky<usize>) -> Vec<usize> {
    let ns = sym.n_supernodes();
    let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
    let (cp_row, row_idx) = (sym.col_ptr_for_row_idx(), sym.row_idx());
    let of_col = supernode_of_column(sym);
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); ns];
    let mut roots = vec![];
    for d in 0..ns {
        match row_idx[cp_row[d]..cp_row[d + 1]].first() {
            Some(&r) => children[of_col[r]].push(d),
            None => roots.push(d),
        }
    }
    let mut order = Vec::with_capacity(sym.nrows());
    // depth first, children before their parent
    let mut stack: Vec<(usize, usize)> = roots.iter().rev().map(|&r| (r, 0)).collect();
    while let Some((s, next)) = stack.pop() {
        if let Some(&c) = children[s].get(next) {
            stack.push((s, next + 1));
            stack.push((c, 0));
        } else {
            order.extend(begin[s]..end[s]);
        }
    }
    order
}

/// A matrix's lower triangle in a factor's order: column pointers, rows (in no particular
/// order within a column) and the index of each value in the matrix's values.
#[derive(Debug)]
pub(crate) struct Lower {
    col_ptr: Vec<usize>,
    rows: Vec<usize>,
    src: Vec<usize>,
}

impl Lower {
    /// The lower triangle of `a` (whose lower triangle is read) in the order `inv`
    /// (`inv[old] = new`; `None`: the identity): two counting passes, no sort. It needs only
    /// the order, so it is built while the symbolic factorisation runs.
    pub(crate) fn new(a: SparseColMatRef<'_, usize, f64>, inv: Option<&[usize]>) -> Lower {
        let n = a.nrows();
        let p = |i: usize| inv.map_or(i, |v| v[i]);
        let sym = a.symbolic();
        // the (row, column) in the new order of each lower entry, column the smaller
        let place = |i: usize, j: usize| {
            let (pi, pj) = (p(i), p(j));
            if pi >= pj {
                (pi, pj)
            } else {
                (pj, pi)
            }
        };
        let mut col_ptr = vec![0usize; n + 1];
        for j in 0..n {
            for &i in sym.row_idx_of_col_raw(j) {
                if i >= j {
                    col_ptr[place(i, j).1 + 1] += 1;
                }
            }
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let nnz = col_ptr[n];
        let mut next = col_ptr.clone();
        let (mut rows, mut src) = (vec![0usize; nnz], vec![0usize; nnz]);
        let all_rows = sym.row_idx();
        for j in 0..n {
            for k in sym.col_range(j) {
                let i = all_rows[k];
                if i >= j {
                    let (r, c) = place(i, j);
                    rows[next[c]] = r;
                    src[next[c]] = k;
                    next[c] += 1;
                }
            }
        }
        Lower { col_ptr, rows, src }
    }
}

/// One factorisation's shared, read-only state.
struct Ctx<'a> {
    sym: &'a SymbolicSupernodalCholesky<usize>,
    tree: &'a Tree,
    /// The input matrix's values, read through `tree.src`.
    values: &'a [f64],
    par: Par,
    progress: Option<&'a FactorProgress>,
}

/// A task's workspace: the map from a row to its place in the current supernode, the
/// buffers of the descendants' updates, and the dense factorisation's.
struct Scratch {
    local: Vec<usize>,
    bufs: Bufs,
    dense: MemBuffer,
}

/// Columns of a supernode being assembled: the supernode `s`, its columns `cols` (local
/// indices), and their values (column-major, the supernode's rows).
struct Piece<'a> {
    s: usize,
    cols: std::ops::Range<usize>,
    piece: &'a mut [f64],
}

/// The factor's values computed so far: `values[k]` is the factor's value `from + k`.
#[derive(Clone, Copy)]
struct Done<'a> {
    values: &'a [f64],
    from: usize,
}

/// The buffers of one descendant's update: its rows' places in the supernode, `M D` and the
/// product `W` (they only grow: their old contents are overwritten).
#[derive(Default)]
struct Bufs {
    rows: Vec<usize>,
    scaled: Vec<f64>,
    update: Vec<f64>,
}

impl Scratch {
    fn new(n: usize, max_cols: usize, par: Par) -> Scratch {
        Scratch {
            local: vec![usize::MAX; n],
            bufs: Bufs::default(),
            dense: MemBuffer::new(cholesky_in_place_scratch::<f64>(max_cols, par, dense_params(max_cols))),
        }
    }
}

/// Where a supernode of `ncols` columns and `nrows` rows is cut into pieces of columns
/// assembled on different threads (their boundaries, from 0 to `ncols`): about the same part
/// of the lower trapezoid each, four pieces per thread for the balance, none narrower than
/// [`PIECE_COLS`]; one piece where `par` is sequential.
fn column_pieces(ncols: usize, nrows: usize, par: Par) -> Vec<usize> {
    let threads = match par {
        Par::Seq => 1,
        Par::Rayon(t) => t.get(),
    };
    let pieces = (4 * threads).min(ncols / PIECE_COLS).max(1);
    if threads < 2 || pieces < 2 {
        return vec![0, ncols];
    }
    // column j holds nrows - j values of the lower trapezoid
    let area = |j: usize| (j * (2 * nrows - j + 1) / 2) as f64;
    let share = area(ncols) / pieces as f64;
    let mut cuts = vec![0];
    for j in 1..ncols {
        if area(j) >= share * cuts.len() as f64 && j - cuts[cuts.len() - 1] >= PIECE_COLS {
            cuts.push(j);
        }
    }
    cuts.push(ncols);
    cuts
}

impl Ctx<'_> {
    /// Factors the supernodes `lo..hi`, a union of whole subtrees, into `values` (theirs,
    /// starting at value `off` of the factor).
    fn forest(&self, lo: usize, hi: usize, values: &mut [f64], off: usize) -> Result<(), Breakdown> {
        if lo == hi {
            return Ok(());
        }
        let t = self.tree;
        let mid = match t.split(lo, hi, |r| t.work[r], SEQUENTIAL_FLOPS) {
            Split::InOrder => return self.in_order(lo, hi, values, off, Par::Seq),
            Split::Root(root) => {
                let cpv = self.sym.col_ptr_for_val();
                let (below, mine) = values.split_at_mut(cpv[root] - off);
                self.forest(lo, root, below, off)?;
                let mut scratch = self.scratch(root, root + 1, self.par);
                return self.node(root, (below, mine), off, &mut scratch, self.par);
            }
            Split::Between(mid) => mid,
        };
        let cpv = self.sym.col_ptr_for_val();
        let (left, right) = values.split_at_mut(cpv[mid] - off);
        let (a, b) = rayon::join(
            || self.forest(lo, mid, left, off),
            || self.forest(mid, hi, right, cpv[mid]),
        );
        a.and(b)
    }

    fn scratch(&self, lo: usize, hi: usize, par: Par) -> Scratch {
        let (begin, end) = (self.sym.supernode_begin(), self.sym.supernode_end());
        let max_cols = (lo..hi).map(|s| end[s] - begin[s]).max().unwrap_or(0);
        Scratch::new(self.sym.nrows(), max_cols, par)
    }

    /// Factors the supernodes `lo..hi` one after another on this thread.
    fn in_order(&self, lo: usize, hi: usize, values: &mut [f64], off: usize, par: Par) -> Result<(), Breakdown> {
        let mut scratch = self.scratch(lo, hi, par);
        let cpv = self.sym.col_ptr_for_val();
        for s in lo..hi {
            let (below, mine) = values.split_at_mut(cpv[s] - off);
            self.node(s, (below, mine), off, &mut scratch, par)?;
        }
        Ok(())
    }

    /// The columns `cols` of supernode `s` (its local indices) into `piece` (column-major,
    /// the supernode's rows): the matrix's entries, less the updates `L_d D_d L_dᵀ` of its
    /// descendants (in `done`, the factor's values computed so far) that meet these columns.
    /// `local` maps a row of the supernode's pattern to its place.
    fn assemble(&self, target: Piece<'_>, done: Done<'_>, local: &[usize], bufs: &mut Bufs, par: Par) {
        let Piece { s, cols, piece } = target;
        let Done {
            values: head,
            from: off,
        } = done;
        let sym = self.sym;
        let t = self.tree;
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (cp_row, cpv, rows) = (sym.col_ptr_for_row_idx(), sym.col_ptr_for_val(), sym.row_idx());
        let (s_start, s_end) = (begin[s], end[s]);
        let nrows = s_end - s_start + cp_row[s + 1] - cp_row[s];
        let place = |r: usize| if r < s_end { r - s_start } else { local[r] };
        piece.fill(0.0);
        for j in cols.clone() {
            let col = &mut piece[(j - cols.start) * nrows..(j - cols.start + 1) * nrows];
            let g = s_start + j;
            for k in t.col_ptr[g]..t.col_ptr[g + 1] {
                col[place(t.row_idx[k])] += self.values[t.src[k]];
            }
        }
        let (c0, c1) = (s_start + cols.start, s_start + cols.end);
        for &d in &t.updaters[t.upd_ptr[s]..t.upd_ptr[s + 1]] {
            let d_pattern = &rows[cp_row[d]..cp_row[d + 1]];
            let d_ncols = end[d] - begin[d];
            let ld = MatRef::from_column_major_slice(
                &head[cpv[d] - off..cpv[d + 1] - off],
                d_ncols + d_pattern.len(),
                d_ncols,
            );
            // the descendant's rows from the piece's first column on; the first `mid` of them
            // are the piece's columns
            let start = d_pattern.partition_point(|&r| r < c0);
            let mid = d_pattern[start..].partition_point(|&r| r < c1);
            let hit = &d_pattern[start..];
            let below = ld.subrows(d_ncols + start, hit.len());
            bufs.rows.clear();
            bufs.rows.extend(hit.iter().map(|&r| place(r)));
            subtract_update((&mut *piece, nrows, cols.start), ld, below, mid, bufs, par);
        }
    }

    /// The left-looking step of supernode `s`: its columns of the matrix, less the updates of
    /// its descendants (in `parts.0`, the factor's values from `off` to `s`'s), factored into
    /// `parts.1` (starting with `s`'s values).
    fn node(
        &self,
        s: usize,
        parts: (&[f64], &mut [f64]),
        off: usize,
        scratch: &mut Scratch,
        par: Par,
    ) -> Result<(), Breakdown> {
        let (head, tail) = parts;
        let sym = self.sym;
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (cp_row, cpv, rows) = (sym.col_ptr_for_row_idx(), sym.col_ptr_for_val(), sym.row_idx());
        let (s_start, s_end) = (begin[s], end[s]);
        let pattern = &rows[cp_row[s]..cp_row[s + 1]];
        let ncols = s_end - s_start;
        let nrows = ncols + pattern.len();
        for (i, &r) in pattern.iter().enumerate() {
            scratch.local[r] = i + ncols;
        }
        // column-major, nrows x ncols
        let ls = &mut tail[..cpv[s + 1] - cpv[s]];
        let cuts = column_pieces(ncols, nrows, par);
        let local = &scratch.local;
        if let [0, all] = cuts[..] {
            let target = Piece {
                s,
                cols: 0..all,
                piece: ls,
            };
            self.assemble(
                target,
                Done {
                    values: head,
                    from: off,
                },
                local,
                &mut scratch.bufs,
                par,
            );
        } else {
            // pieces of columns on different threads: each reads every descendant and writes
            // only its own columns
            let mut pieces = Vec::with_capacity(cuts.len() - 1);
            let mut rest = &mut *ls;
            for w in cuts.windows(2) {
                let (piece, after) = rest.split_at_mut((w[1] - w[0]) * nrows);
                pieces.push((w[0]..w[1], piece));
                rest = after;
            }
            pieces
                .into_par_iter()
                .for_each_init(Bufs::default, |bufs, (cols, piece)| {
                    let done = Done {
                        values: head,
                        from: off,
                    };
                    self.assemble(Piece { s, cols, piece }, done, local, bufs, Par::Seq)
                });
        }
        for &r in pattern {
            scratch.local[r] = usize::MAX;
        }
        let ls = MatMut::from_column_major_slice_mut(ls, nrows, ncols);
        let (mut top, mut bot) = ls.split_at_row_mut(ncols);
        cholesky_in_place(
            top.rb_mut(),
            LdltRegularization::default(),
            par,
            MemStack::new(&mut scratch.dense),
            dense_params(ncols),
        )
        .map_err(|e| match e {
            faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index } => {
                Breakdown::ZeroPivot(index + s_start)
            }
        })?;
        for j in 0..ncols {
            for i in 0..j {
                top[(i, j)] = 0.0;
            }
        }
        faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(
            top.rb(),
            bot.rb_mut().transpose_mut(),
            par,
        );
        for j in 0..ncols {
            let d = top[(j, j)].recip();
            for i in 0..bot.nrows() {
                bot[(i, j)] *= d;
            }
        }
        if let Some(i) = first_non_finite(&tail[..cpv[s + 1] - cpv[s]], par) {
            return Err(Breakdown::NonFinite(cpv[s] + i));
        }
        if let Some(p) = self.progress {
            p.add(self.tree.own_work[s]);
        }
        Ok(())
    }
}

/// faer's parameters for the dense `L D Lᵀ` of a supernode of `ncols` columns: its defaults,
/// with [`WIDE_PANEL`] columns per panel from [`WIDE_FROM`] columns on.
fn dense_params(ncols: usize) -> faer::Spec<LdltParams, f64> {
    let mut params = faer::Spec::<LdltParams, f64>::default();
    if ncols >= WIDE_FROM {
        params.block_size = WIDE_PANEL;
    }
    params
}

/// The first NaN or infinity of `v`, read on rayon's pool where `par` is (a wide supernode's
/// millions of values, where no other task runs; a whole factor faer walked).
pub(crate) fn first_non_finite(v: &[f64], par: Par) -> Option<usize> {
    const CHUNK: usize = 1 << 16;
    let bad = |x: &f64| !x.is_finite();
    match par {
        Par::Rayon(_) if v.len() > CHUNK => {
            let c = v.par_chunks(CHUNK).position_first(|c| c.iter().any(bad))?;
            Some(c * CHUNK + v[c * CHUNK..].iter().position(bad)?)
        }
        _ => v.iter().position(bad),
    }
}

/// From this many columns on, an update's top square is computed as its lower half alone
/// (`triangular::matmul`) and the rows below it by a second product; below, one product of
/// the whole block costs less than two.
const TRIANGLE_SPLIT: usize = 32;

/// `L_s -= W` (`ls`: columns of the supernode's values from column `col0` on, column-major,
/// with the supernode's number of rows), `W = B D Mᵀ` with `B` the rows of descendant `ld`
/// from the first of these columns on (`below`), `M` its first `mid` rows and `D` the
/// descendant's pivots; `W`'s row `i` goes to row `bufs.rows[i]` of `L_s`, its column `j` to
/// column `bufs.rows[j]` (only `i ≥ j`: the factor is lower triangular). Below
/// [`TRIANGLE_SPLIT`] columns one dense product (the top square's upper half computed and
/// dropped: one call costs less than two on the small blocks of a 2D mesh), from it on the top
/// square's lower half and the rows below it apart (the wide supernodes of a 3D mesh, where
/// `mid` is most of `m`: up to half the flops saved); then the scatter.
fn subtract_update(
    ls: (&mut [f64], usize, usize),
    ld: MatRef<'_, f64>,
    below: MatRef<'_, f64>,
    mid: usize,
    bufs: &mut Bufs,
    par: Par,
) {
    let Bufs { rows, scaled, update } = bufs;
    let (m, w) = (below.nrows(), below.ncols());
    if mid == 0 || m == 0 {
        return;
    }
    // M D, mid x w (the buffers only grow: their old contents are overwritten)
    if scaled.len() < mid * w {
        scaled.resize(mid * w, 0.0);
    }
    let mut md = MatMut::from_column_major_slice_mut(&mut scaled[..mid * w], mid, w);
    for k in 0..w {
        let d = ld[(k, k)];
        let src = below.col(k);
        for i in 0..mid {
            md[(i, k)] = src[i] * d;
        }
    }
    if update.len() < m * mid {
        update.resize(m * mid, 0.0);
    }
    let mut wm = MatMut::from_column_major_slice_mut(&mut update[..m * mid], m, mid);
    if mid >= TRIANGLE_SPLIT {
        // the top square's lower half alone, then the rows below it
        let (top, rest) = wm.split_at_row_mut(mid);
        let (b_top, b_rest) = below.split_at_row(mid);
        faer::linalg::matmul::triangular::matmul(
            top,
            BlockStructure::TriangularLower,
            Accum::Replace,
            b_top,
            BlockStructure::Rectangular,
            md.rb().transpose(),
            BlockStructure::Rectangular,
            1.0,
            par,
        );
        if m > mid {
            faer::linalg::matmul::matmul(rest, Accum::Replace, b_rest, md.rb().transpose(), 1.0, par);
        }
    } else {
        faer::linalg::matmul::matmul(wm.rb_mut(), Accum::Replace, below, md.rb().transpose(), 1.0, par);
    }
    let wv = &update[..m * mid];
    let (ls, nrows, col0) = ls;
    for j in 0..mid {
        let c = rows[j] - col0;
        let dst = &mut ls[c * nrows..(c + 1) * nrows];
        let src = &wv[j * m..(j + 1) * m];
        for i in j..m {
            dst[rows[i]] -= src[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pieces_cover_the_columns_with_about_equal_work() {
        let area = |nrows: usize, a: usize, b: usize| (a..b).map(|j| (nrows - j) as f64).sum::<f64>();
        for (ncols, nrows, threads) in [
            (4896, 4896, 2),
            (2420, 5024, 2),
            (300, 900, 3),
            (70, 70, 2),
            (1000, 1000, 1),
        ] {
            let cuts = column_pieces(ncols, nrows, Par::rayon(threads));
            assert_eq!((cuts[0], cuts[cuts.len() - 1]), (0, ncols));
            assert!(cuts.len() - 1 <= 4 * threads, "{cuts:?}");
            if threads == 1 || ncols < 2 * PIECE_COLS {
                assert_eq!(cuts, vec![0, ncols]);
                continue;
            }
            assert!(cuts.len() > 2, "{ncols} columns on {threads} threads: one piece");
            let share = area(nrows, 0, ncols) / (cuts.len() - 1) as f64;
            for w in cuts.windows(2) {
                assert!(w[1] > w[0]);
                let got = area(nrows, w[0], w[1]);
                // every piece but the last is at least PIECE_COLS wide and near its share
                if w[1] < ncols {
                    assert!(w[1] - w[0] >= PIECE_COLS);
                    assert!(got <= 1.5 * share && got >= 0.5 * share, "{w:?}: {got} against {share}");
                }
            }
        }
        assert_eq!(column_pieces(500, 600, Par::Seq), vec![0, 500]);
    }

    /// The postorder of a grid Laplacian's elimination tree in a scrambled order is one (every
    /// column's parent after it, every subtree contiguous), and the same on pools of 1 to 3
    /// threads, whose ranges of columns gather the pattern in 1 to 3 parts.
    #[test]
    fn the_postorder_is_one_and_does_not_depend_on_the_threads() {
        use faer::sparse::{SparseColMat, Triplet};
        let side = 23;
        let n = side * side;
        let mut t = vec![];
        for i in 0..n {
            t.push(Triplet::new(i, i, 4.0));
            for j in [i + 1, i + side] {
                if j < n && (j != i + 1 || j % side != 0) {
                    t.push(Triplet::new(j, i, -1.0));
                }
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
        // a scrambled order: i * 7 mod n (7 and 529 are coprime)
        let fwd: Vec<usize> = (0..n).map(|i| i * 7 % n).collect();
        let mut inv = vec![0; n];
        for (new, &old) in fwd.iter().enumerate() {
            inv[old] = new;
        }
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                (
                    column_ranges(a.as_ref(), threads),
                    postordered(a.as_ref(), &fwd, &inv).unwrap(),
                )
            })
        };
        let (ranges, (post, post_parent)) = on(1);
        assert_eq!(ranges, vec![0..n]);
        for threads in [2, 3] {
            let (ranges, again) = on(threads);
            assert_eq!(ranges.len(), threads);
            assert!(ranges.windows(2).all(|w| w[0].end == w[1].start) && ranges[threads - 1].end == n);
            assert_eq!(again.0, post, "{threads} threads");
        }
        // the tree in the postorder: parents after their children, subtrees contiguous
        let mut post_inv = vec![0; n];
        for (new, &old) in post.iter().enumerate() {
            post_inv[old] = new;
        }
        let parent = elimination_tree(n, &[upper_lists(a.as_ref(), &post_inv, 0..n)]);
        assert_eq!(post_parent, parent, "the tree carried over to the new order");
        let mut size = vec![1usize; n];
        for k in 0..n {
            if parent[k] != usize::MAX {
                assert!(parent[k] > k);
                size[parent[k]] += size[k];
            }
        }
        for k in 0..n {
            let p = parent[k];
            // k's subtree is the range of its size ending at k, inside its parent's
            assert!(p == usize::MAX || p + 1 - size[p] <= k + 1 - size[k], "column {k}");
        }
        // and postordering it again changes nothing
        assert_eq!(postordered(a.as_ref(), &post, &post_inv).unwrap().0, post);
    }
}
