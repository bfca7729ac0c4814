//! Who owns what: the cells partitioned among the ranks, the nodes owned by the lowest rank of
//! their cells, and each node's unknowns numbered so that every rank owns a contiguous range.

use fe_assembly::{Dof, DofMap};
use mesh::Mesh;
use petsc::{partition, Index, Petsc, PetscError, Vector};

/// The distribution of a mesh's cells and unknowns among the ranks. The same on every rank.
#[derive(Clone, Debug)]
pub struct Layout {
    /// Spatial dimension (displacement components per node).
    pub dim: usize,
    /// The rank that assembles each cell.
    pub cell_rank: Vec<usize>,
    /// The rank that owns each node (the lowest rank among its cells').
    pub node_rank: Vec<usize>,
    /// The global number of each node's first unknown; its `dim` displacements follow, then
    /// its potential where it has one.
    pub first: Vec<usize>,
    /// Whether each node carries a potential.
    pub has_phi: Vec<bool>,
    /// Whether the system has potentials at all: some node of some rank carries one (the same
    /// on every rank, which must build the same solver; on pieces a rank may hold no electric
    /// cell where another does).
    pub coupled: bool,
    /// Each rank's first unknown, and one past the last rank's (`ranks + 1` entries).
    pub rank_start: Vec<usize>,
    /// The floating terminal (an index into the run's terminals, the same on every rank) whose
    /// one potential each node's is tied to: such a node has no potential unknown of its own
    /// (its cells' potential rows and columns are the terminal's, [`Layout::phi_row`]).
    pub tie: Vec<Option<usize>>,
    /// Floating terminals: each one's potential the last rank's, after its nodes' unknowns
    /// ([`Layout::terminal_row`]).
    pub terminals: usize,
}

impl Layout {
    /// Partitions `mesh` among the ranks of `petsc` and numbers the unknowns of `dofs`
    /// (displacements at every node, prescribed or not; potentials where `dofs` has them).
    /// Collective.
    pub fn new(petsc: &Petsc, mesh: &Mesh, dofs: &DofMap) -> Result<Layout, PetscError> {
        let cell_rank = partition_cells(petsc, mesh)?;
        let (n, dim, ranks) = (mesh.n_nodes(), mesh.dim, petsc.size());
        let mut node_rank = vec![usize::MAX; n];
        for (c, cell) in mesh.iter_cells().enumerate() {
            for &v in cell {
                node_rank[v] = node_rank[v].min(cell_rank[c]);
            }
        }
        // a node in no cell (refused by the mesh checks) would belong to rank 0
        for r in &mut node_rank {
            if *r == usize::MAX {
                *r = 0;
            }
        }
        let has_phi: Vec<bool> = (0..n).map(|v| !matches!(dofs.phi[v], Dof::Absent)).collect();
        let mut first = vec![0; n];
        let mut rank_start = Vec::with_capacity(ranks + 1);
        let mut next = 0;
        for r in 0..ranks {
            rank_start.push(next);
            for v in (0..n).filter(|&v| node_rank[v] == r) {
                first[v] = next;
                next += dim + usize::from(has_phi[v]);
            }
        }
        rank_start.push(next);
        Ok(Layout {
            dim,
            cell_rank,
            node_rank,
            first,
            coupled: has_phi.iter().any(|&p| p),
            has_phi,
            rank_start,
            tie: vec![None; n],
            terminals: 0,
        })
    }

    /// The layout of a run whose every rank holds only its piece of the mesh (`piece`, its
    /// block of cells and one layer of ghosts, numbered locally; `dofs` the piece's dof map):
    /// the same numbering as [`Layout::new`] gives a whole mesh (each rank's nodes contiguous,
    /// node by node), with every entry indexed by the piece's local nodes and cells. A rank
    /// numbers its own nodes; the first unknown of a node another rank owns comes from that
    /// rank through a directory, a parallel vector indexed by the whole mesh's node numbers
    /// (each rank holds `1/p` of it). `piece.mesh` is not read: the run may have taken it for
    /// its set-up. `(tie, terminals)`: the floating terminal each node's potential is tied to
    /// (`dofs` untied: a potential at every node that carries one), and how many terminals the
    /// whole run has; their potentials are the last rank's last unknowns. Collective.
    pub fn of_piece(
        petsc: &Petsc,
        piece: &mesh::MeshPiece,
        dofs: &DofMap,
        (tie, terminals): (Vec<Option<usize>>, usize),
    ) -> Result<Layout, PetscError> {
        let (rank, ranks, dim) = (petsc.rank(), petsc.size(), dofs.dim);
        let n = piece.global_node.len();
        let has_phi: Vec<bool> = (0..n).map(|v| !matches!(dofs.phi[v], Dof::Absent)).collect();
        let width: Vec<usize> = (0..n)
            .map(|v| dim + usize::from(has_phi[v] && tie[v].is_none()))
            .collect();
        let mut mine: usize = (0..n).filter(|&v| piece.node_rank[v] == rank).map(|v| width[v]).sum();
        if rank + 1 == ranks {
            mine += terminals;
        }
        let counts = petsc.all_gather(mine as u64)?;
        let mut rank_start = Vec::with_capacity(ranks + 1);
        let mut next = 0;
        for c in &counts {
            rank_start.push(next);
            next += *c as usize;
        }
        rank_start.push(next);
        // the directory: at each node's whole-mesh number `g`, its first unknown (at 2 g, exact
        // in f64 to 2^53) and what its potential is (at 2 g + 1: 0 none, 1 its own, 2 + t
        // floating terminal t's), set by its owner. A node of the piece's ghost cells alone
        // takes both from its owner, who sees every cell around it: its piece may see none
        // of the electric cells, or of the terminal's facets, that the node has.
        let (lo, hi) = petsc.split(piece.n_global_nodes);
        let mut directory = Vector::mpi(petsc, 2 * (hi - lo))?;
        let (mut first, mut has_phi, mut tie) = (vec![usize::MAX; n], has_phi, tie);
        let (mut at, mut values) = (vec![], vec![]);
        let mut f = rank_start[rank];
        for v in (0..n).filter(|&v| piece.node_rank[v] == rank) {
            first[v] = f;
            let code = match (has_phi[v], tie[v]) {
                (false, _) => 0,
                (true, None) => 1,
                (true, Some(t)) => 2 + t,
            };
            at.extend([2 * piece.global_node[v], 2 * piece.global_node[v] + 1].map(Layout::index));
            values.extend([f as f64, code as f64]);
            f += width[v];
        }
        directory.set_values(&at, &values)?;
        directory.assemble()?;
        let others: Vec<usize> = (0..n).filter(|&v| piece.node_rank[v] != rank).collect();
        let asked: Vec<Index> = others
            .iter()
            .flat_map(|&v| [2 * piece.global_node[v], 2 * piece.global_node[v] + 1])
            .map(Layout::index)
            .collect();
        for (&v, x) in others.iter().zip(directory.fetch(&asked)?.chunks_exact(2)) {
            first[v] = x[0] as usize;
            let code = x[1] as usize;
            (has_phi[v], tie[v]) = (code > 0, code.checked_sub(2));
        }
        let here = f64::from(u8::from(has_phi.iter().any(|&p| p)));
        let coupled = petsc.max(&[here])?[0] > 0.0;
        Ok(Layout {
            dim,
            cell_rank: piece.cell_rank.clone(),
            node_rank: piece.node_rank.clone(),
            first,
            coupled,
            has_phi,
            rank_start,
            tie,
            terminals,
        })
    }

    /// Unknowns in all.
    pub fn n_global(&self) -> usize {
        *self.rank_start.last().unwrap_or(&0)
    }

    /// The unknowns `rank` owns.
    pub fn owned(&self, rank: usize) -> std::ops::Range<usize> {
        self.rank_start[rank]..self.rank_start[rank + 1]
    }

    /// The unknowns of node `v`: `dim` displacements, then its potential if it has one of its
    /// own (not tied to a floating terminal's).
    pub fn node_dofs(&self, v: usize) -> std::ops::Range<usize> {
        self.first[v]..self.first[v] + self.dim + usize::from(self.own_phi(v))
    }

    /// Whether node `v` has a potential unknown of its own (it carries a potential, not tied
    /// to a floating terminal's).
    pub fn own_phi(&self, v: usize) -> bool {
        self.has_phi[v] && self.tie[v].is_none()
    }

    /// The row of node `v`'s potential: its own, or its floating terminal's; `None` where it
    /// carries none.
    pub fn phi_row(&self, v: usize) -> Option<usize> {
        match self.tie[v] {
            Some(t) => Some(self.terminal_row(t)),
            None => self.has_phi[v].then_some(self.first[v] + self.dim),
        }
    }

    /// The row of floating terminal `t`'s potential (the last rank's).
    pub fn terminal_row(&self, t: usize) -> usize {
        self.n_global() - self.terminals + t
    }

    /// The rank that owns the floating terminals' rows.
    pub fn terminals_rank(&self) -> usize {
        self.rank_start.len() - 2
    }

    /// The nodes `rank` owns, in the order of their unknowns.
    pub fn owned_nodes(&self, rank: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.node_rank.len()).filter(move |&v| self.node_rank[v] == rank)
    }

    /// A global unknown as PETSc's index.
    pub fn index(i: usize) -> Index {
        i as Index
    }
}

/// The rank of each cell: the dual graph (cells sharing a facet) of this rank's share of the
/// cells, partitioned by PETSc, gathered on every rank.
fn partition_cells(petsc: &Petsc, mesh: &Mesh) -> Result<Vec<usize>, PetscError> {
    let n_cells = mesh.n_cells();
    if petsc.size() == 1 {
        return Ok(vec![0; n_cells]);
    }
    let (lo, hi) = petsc.split(n_cells);
    let (off, node_cells) = mesh.node_cells();
    let mut offsets = vec![0];
    let mut neighbours = vec![];
    for c in lo..hi {
        let cell = mesh.cell(c);
        // the other cell on each facet: the cells of the facet's first node that hold all of
        // the facet's nodes (the cell's nodes but one)
        for skip in 0..cell.len() {
            let facet: Vec<usize> = (0..cell.len()).filter(|&i| i != skip).map(|i| cell[i]).collect();
            let v0 = facet[0];
            let other = node_cells[off[v0]..off[v0 + 1]]
                .iter()
                .copied()
                .find(|&d| d != c && facet[1..].iter().all(|v| node_cells[off[*v]..off[*v + 1]].contains(&d)));
            if let Some(d) = other {
                neighbours.push(d);
            }
        }
        offsets.push(neighbours.len());
    }
    let parts = partition(petsc, &offsets, &neighbours, n_cells)?;
    let local: Vec<i32> = parts.iter().map(|&p| p as i32).collect();
    let all = petsc.all_gather_i32(&local)?;
    Ok(all.into_iter().map(|p| p as usize).collect())
}
