//! The report of a run on pieces (`run.json`), from sums and maxima over the ranks: nothing of
//! the size of the whole mesh is gathered. Every rank makes the same report; its contact
//! section is the gathered contact points' ([`super::gather`]), on rank 0.

use super::{PieceContact, Solved};
use crate::error::DistributedError;
use fe_assembly::{Discretization, Dof};
use petsc::Petsc;
use problem::backend::Setup;
use problem::report::{
    rule_in_words, DofsReport, Iterations, Memory, MeshReport, Residuals, SceneReport, SolverReport, TerminalReport,
    Timings,
};
use problem::{PetscReport, RunReport, Scene};

/// What a rank's piece holds for the report, measured before its set-up is dropped.
pub(super) struct Shares<'a> {
    pub(super) petsc: &'a Petsc,
    pub(super) scene: &'a Scene,
    pub(super) setup: &'a Setup,
    pub(super) disc: &'a Discretization<'a>,
    /// Whether this rank owns each node of its piece.
    pub(super) owned: &'a [bool],
    /// Each node's number in the whole mesh.
    pub(super) global_node: &'a [usize],
    /// The terminals' groups (those of the whole scene, before the piece dropped the
    /// conditions it does not reach).
    pub(super) terminals: &'a [String],
    /// The floating terminals among them.
    pub(super) floating: &'a super::Floating,
    /// The floating terminal each node's potential is tied to (the layout's).
    pub(super) tie: &'a [Option<usize>],
    /// This rank's own cells.
    pub(super) own_cells: usize,
    /// The whole mesh's cells.
    pub(super) cells: usize,
}

/// The figures of the solve, for the report.
pub(super) struct Figures<'a> {
    pub(super) solved: &'a Solved,
    pub(super) contact: Option<&'a PieceContact>,
    /// `|K x - b| / |b|` of a run without contact.
    pub(super) equilibrium: f64,
    /// The unknowns each rank owns (the layout's ranges, known on every rank).
    pub(super) unknowns: Vec<usize>,
    pub(super) timings: Timings,
    /// The blocks of cells per axis, one per rank.
    pub(super) blocks: [usize; 3],
    /// The matrix's stored entries over the ranks.
    pub(super) nonzeros: f64,
}

impl Shares<'_> {
    /// The run's report, the same on every rank (collective); its contact section empty (the
    /// caller's, from the gathered points).
    pub(super) fn report(&self, u: &[[f64; 3]], phi: &[f64], f: Figures<'_>) -> Result<RunReport, DistributedError> {
        let (petsc, scene, setup) = (self.petsc, self.scene, self.setup);
        let plan = &setup.plan;
        let dofs = &self.disc.dofs;
        let dim = setup.mesh.dim;
        let (mut free_u, mut free_phi, mut nodes) = (0.0, 0.0, 0.0);
        for v in (0..self.owned.len()).filter(|&v| self.owned[v]) {
            nodes += 1.0;
            free_u += (0..dim)
                .filter(|&k| matches!(dofs.u[v * dim + k], Dof::Free(_)))
                .count() as f64;
            // (a floating terminal's potential counted once, below)
            free_phi += f64::from(u8::from(matches!(dofs.phi[v], Dof::Free(_)) && self.tie[v].is_none()));
        }
        let sums = petsc.sum(&[free_u, free_phi, nodes])?;
        let free_phi = sums[1] as usize + self.floating.len();
        let h = petsc.max(&[setup.mesh.h_max()])?[0];
        let info = f.contact.map(|c| &c.solution.info);
        let equilibrium = f.contact.map_or(f.equilibrium, |c| c.equilibrium);
        let cells_per_rank = petsc.all_gather(self.own_cells as u64)?;
        // the errors against a field solution: each rank's own cells' squares, summed
        let exact = match &setup.exact {
            Some(ex) => {
                let own = self.disc.error_norms_on(u, phi, &ex.exact, 0..self.own_cells);
                let sums = petsc.sum(&own.squares())?;
                Some(ex.report(&fe_assembly::ErrorNorms::from_squares(&sums), plan.electric))
            }
            None => None,
        };
        Ok(RunReport {
            scene: SceneReport::of(scene),
            plan: plan.clone(),
            mesh: MeshReport {
                n_nodes: sums[2] as usize,
                n_cells: self.cells,
                h,
                cells_per_axis: scene.mesh.cells_per_axis(),
                reoriented_cells: 0,
                coincident_nodes: 0,
                // a seam across pieces is no piece's: not looked for
                seam_facets: 0,
                seam_size: 0.0,
                unused_nodes: 0,
                curved_cells: 0,
            },
            dofs: DofsReport {
                u: sums[0] as usize,
                phi: free_phi,
            },
            contact: Default::default(),
            exact,
            iterations: Iterations::of(info, 0),
            residuals: Residuals {
                equilibrium,
                complementarity: info.map_or(0.0, |i| i.complementarity),
                converged_to_tolerance: plan.rule == problem::Rule::Tight
                    && equilibrium <= problem::equilibrium_tol(plan)
                    && info.is_none_or(|i| i.complementarity <= plan.tol),
            },
            timings_s: f.timings,
            memory: Memory::default(),
            solver: SolverReport {
                strategy: plan.linear_strategy,
                rule: rule_in_words(plan.rule).into(),
                tol: plan.tol,
                ..SolverReport::of(info)
            },
            petsc: Some(PetscReport {
                ranks: petsc.size(),
                unknowns: f.unknowns.iter().sum(),
                nonzeros: f.nonzeros,
                krylov_iterations: f.solved.iterations,
                reason: f.solved.reason.clone(),
                options: f.solved.options.clone(),
                cells_per_rank: cells_per_rank.into_iter().map(|c| c as usize).collect(),
                unknowns_per_rank: f.unknowns,
                peak_bytes_per_rank: vec![],
                preconditioner_setup_s: f.solved.setup_seconds,
                pieces: Some(f.blocks),
            }),
            path: None,
            terminals: self.terminals(u, phi)?,
            indenter: None,
            units: setup.units.clone(),
        })
    }

    /// The terminals' charges, each rank's share over the nodes it owns summed, and each
    /// one's potential at its node of the lowest number in the whole mesh. Collective.
    pub(super) fn terminals(&self, u: &[[f64; 3]], phi: &[f64]) -> Result<Vec<TerminalReport>, DistributedError> {
        if self.terminals.is_empty() {
            return Ok(vec![]);
        }
        let petsc = self.petsc;
        let groups: Vec<&str> = self.terminals.iter().map(String::as_str).collect();
        let shares = self
            .disc
            .charges_at(u, phi, &groups, &self.setup.loads, Some(self.owned))?;
        let charges = petsc.sum(&shares)?;
        let mut out = vec![];
        for (group, charge) in groups.iter().zip(charges) {
            // the group's first node in the whole mesh's numbering, found among the owners'
            let first = self
                .setup
                .mesh
                .boundary(group)
                .map(|g| g.nodes())
                .unwrap_or_default()
                .into_iter()
                .filter(|&v| self.owned[v])
                .min_by_key(|&v| self.global_node[v]);
            let lowest = first.map_or(f64::INFINITY, |v| self.global_node[v] as f64);
            let least = -petsc.max(&[-lowest])?[0];
            let mine = first
                .filter(|&v| self.global_node[v] as f64 == least)
                .map_or(0.0, |v| phi[v]);
            // an electrode of `x_range`: the extent its facets cover, over the pieces
            let covered_x = if self.setup.ranged_electrodes.iter().any(|e| e == group) {
                let [lo, hi] = self
                    .setup
                    .mesh
                    .boundary(group)
                    .map_or([f64::INFINITY, f64::NEG_INFINITY], |g| {
                        problem::backend::x_extent(&self.setup.mesh, g)
                    });
                let extent = petsc.max(&[-lo, hi])?;
                Some([-extent[0], extent[1]])
            } else {
                None
            };
            out.push(TerminalReport {
                group: group.to_string(),
                potential: petsc.sum(&[mine])?[0],
                charge,
                floating: self.floating.holds(group),
                covered_x,
            });
        }
        Ok(out)
    }
}
