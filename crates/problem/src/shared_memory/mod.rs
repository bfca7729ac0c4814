//! The default backend: faer's sparse factorisations on one machine. A run without contact
//! is one solve with the factors, refined; a run with contact condenses `K` onto the contact
//! dofs (ordered last, so that the contact block comes off the one factorisation) and solves
//! the dense contact problem by semismooth Newton or a first-order method, or (the paper's
//! Uzawa) solves the primal problem once per first-order step.

use crate::backend::Unsupported;
use crate::backend::{
    At, Backend, Contact, ContactSolve, Fields, Figures, InstantOf, InstantSolution, Limits, Posed, Primed,
};
use crate::boundary::ContactBoundary;
use crate::factorization::{Factorization, Refinement};
use crate::instants::Instants;
use crate::progress::{Event, Reporter};
use crate::scene::{BackendChoice, Rule, Scene};
use crate::ProblemError;
use fe_assembly::{Blocks, Parallelism};
use linalg::{CondensedLoads, CoupledSolver, DirectLdlt, Ordering, PcgParams, PcgStop, SchurPcg};
use std::time::Instant;

/// The default backend, named for its role: one process on one machine's shared memory, its
/// threads (`solver.backend = "faer"`, after the library whose sparse factorisations it
/// runs; also the Schur-complement PCG).
#[derive(Clone, Copy, Debug, Default)]
pub struct SharedMemory;

impl Backend for SharedMemory {
    const NAME: &'static str = "faer";
    type Assembled = Blocks;
    type System = Factored;
    type Error = ProblemError;
    const HELD_TO_TOLERANCE: bool = true;

    fn supports(&self, scene: &Scene) -> Result<(), Unsupported> {
        // the scene asks for another backend: solving it here would ignore that silently
        if scene.solver.backend != BackendChoice::Faer {
            return Err(Unsupported::new(
                Self::NAME,
                "solver.backend",
                format!("solver.backend = \"{}\" asks for the distributed backend (the program built with the `petsc` feature, under mpirun; distributed::solve)", scene.solver.backend),
            )
            .advise("remove solver.backend, or set it to \"faer\""));
        }
        if scene.solver.petsc_options.is_some() {
            return Err(
                Unsupported::new(Self::NAME, "solver.petsc_options", "options for PETSc's database")
                    .advise("remove them, or set solver.backend = \"petsc\""),
            );
        }
        Ok(())
    }

    fn estimate(&self, scene: &Scene) -> Option<(f64, String)> {
        crate::estimate::before_mesh(scene)
    }

    fn estimate_on_mesh(&self, _: &Scene, mesh: &mesh::Mesh, electric: bool) -> Option<(f64, String)> {
        crate::estimate::after_mesh(mesh, electric)
    }

    /// Assembles `A`, `G`, `B` over the free dofs (on rayon's threads), checked finite.
    fn assemble(&mut self, posed: &Posed<'_>) -> Result<Blocks, ProblemError> {
        let blocks = posed.disc.assemble(Parallelism::Rayon);
        let scene = posed.scene.scene();
        ProblemError::check_finite(blocks.a.val(), "the stiffness matrix A", scene)?;
        ProblemError::check_finite(blocks.g.val(), "the coupling matrix G", scene)?;
        ProblemError::check_finite(blocks.b.val(), "the dielectric matrix B", scene)?;
        Ok(blocks)
    }

    fn prepare(
        &mut self,
        posed: &Posed<'_>,
        blocks: Blocks,
        boundary: Option<&ContactBoundary>,
        limits: Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<Factored, ProblemError> {
        factor(posed, blocks, boundary, limits, reporter)
    }

    fn begin(
        &mut self,
        system: &mut Factored,
        posed: &Posed<'_>,
        contact: Option<Contact<'_>>,
        parts: &[Fields],
        reporter: &mut dyn Reporter,
    ) -> Result<Vec<Fields>, ProblemError> {
        let Factored { linear, instants } = system;
        instants
            .begin(linear, posed, contact, parts, reporter)
            .map_err(|e| e.on_scene(&posed.scene))
    }

    fn respond(&mut self, system: &mut Factored, a: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, ProblemError> {
        Instants::respond(&mut system.linear, a)
    }

    fn prime(&mut self, system: &mut Factored, primed: Primed<'_>) -> Result<(), ProblemError> {
        let scene = &primed.posed.scene;
        let Factored { linear, instants } = system;
        instants.prime(linear, primed).map_err(|e| e.on_scene(scene))
    }

    fn solve_posed(
        &mut self,
        system: &mut Factored,
        how: &ContactSolve<'_>,
        at: At<'_>,
        reporter: &mut dyn Reporter,
    ) -> Result<contact::ContactSolution, ProblemError> {
        let Factored { linear, instants } = system;
        instants
            .solve(linear, how, at, reporter)
            .map_err(|e| e.on_scene(how.scene))
    }

    fn own_scale(&self, system: &Factored, factors: &[f64]) -> f64 {
        system.instants.own_scale(factors)
    }

    fn instant_fields(
        &mut self,
        system: &mut Factored,
        posed: &Posed<'_>,
        contact: Option<InstantOf<'_>>,
        reporter: &mut dyn Reporter,
    ) -> Result<Option<InstantSolution>, ProblemError> {
        let Factored { linear, instants } = system;
        instants
            .fields(linear, posed, contact, reporter)
            .map(Some)
            .map_err(|e| e.on_scene(&posed.scene))
    }

    fn defers_fields(&self, _: &Factored) -> bool {
        true
    }

    fn frames_fields(
        &mut self,
        system: &mut Factored,
        frames: Vec<(Posed<'_>, InstantOf<'_>)>,
        _: &mut dyn Reporter,
    ) -> Result<Vec<Option<InstantSolution>>, ProblemError> {
        let Factored { linear, instants } = system;
        let solved = instants.frames_superposed(linear, frames)?;
        Ok(solved.into_iter().map(Some).collect())
    }

    fn finish(&mut self, system: Factored) -> Result<Figures, ProblemError> {
        Ok(system.figures())
    }

    fn at_step(e: ProblemError, k: usize, t: f64) -> ProblemError {
        e.at_step(k, t)
    }
}

/// The linear solver the plan asks for, factored once.
#[allow(clippy::large_enum_variant)] // one per run, moved never
enum LinearSolver {
    /// One `L D Lᵀ` of `K`.
    Direct(DirectLdlt),
    /// The paper's Schur-complement PCG (Cholesky factors of `A` and `B`).
    SchurPcg(SchurPcg),
}

impl LinearSolver {
    fn coupled(&mut self) -> &mut dyn CoupledSolver {
        match self {
            LinearSolver::Direct(d) => d,
            LinearSolver::SchurPcg(p) => p,
        }
    }
}

/// The factored system, and what the run's instants keep on it.
pub struct Factored {
    linear: Linear,
    instants: Instants,
}

/// The assembled blocks and the factored solver.
struct Linear {
    blocks: Blocks,
    solver: LinearSolver,
    pcg_params: PcgParams,
    /// Wall time of the factorisation.
    seconds: f64,
}

impl Factored {
    /// What the factorisation and the solves on it measured, for the report.
    pub(crate) fn figures(&self) -> Figures {
        let linear = &self.linear;
        let (smallest_pivot_ratio, factor_bytes, factor_rate) = match &linear.solver {
            LinearSolver::Direct(d) => {
                let factor = d.factor();
                let rate = factor.flops().map(|f| (f, factor.numeric_seconds()));
                (Some(factor.pivot_ratio()), d.factor_bytes(), rate)
            }
            LinearSolver::SchurPcg(p) => (None, p.factor_bytes(), None),
        };
        Figures {
            factor_seconds: linear.seconds,
            factor_rate,
            condense: self.instants.condense,
            pcg_rel_tol: linear.pcg_params.rel_tol,
            smallest_pivot_ratio,
            refinement_steps: self.instants.refinement,
            factor_bytes,
            petsc: None,
        }
    }
}

impl Linear {
    /// The `L D Lᵀ` of `K`, for what only a direct factorisation does.
    fn direct(&mut self) -> Result<&mut DirectLdlt, ProblemError> {
        match &mut self.solver {
            LinearSolver::Direct(direct) => Ok(direct),
            LinearSolver::SchurPcg(_) => Err(Unsupported::new(
                SharedMemory::NAME,
                "solver.strategy",
                "a condensed contact solve on the Schur-complement PCG (it needs the L D Lᵀ of K)",
            )
            .advise("use a condensed strategy")
            .into()),
        }
    }

    /// `K`'s blocks as linalg takes them.
    fn coupled_blocks(&self) -> linalg::CoupledBlocks<'_> {
        linalg::CoupledBlocks {
            a: &self.blocks.a,
            g: &self.blocks.g,
            b: &self.blocks.b,
        }
    }
}

impl Factorization for Linear {
    fn solve(&mut self, b_u: &[f64], b_phi: &[f64]) -> Result<(Fields, usize), ProblemError> {
        let (mut u, mut phi) = (vec![0.0; b_u.len()], vec![0.0; b_phi.len()]);
        let info = self.solver.coupled().solve(b_u, b_phi, &mut u, &mut phi)?;
        Ok(((u, phi), info.pcg_iters))
    }

    fn condense(&mut self, b_u: &[f64], b_phi: &[f64], dofs: &[usize]) -> Result<linalg::Condensed, ProblemError> {
        Ok(self.direct()?.condense(b_u, b_phi, dofs)?)
    }

    fn solve_with_update(
        &mut self,
        loads: CondensedLoads,
        b_u: &[f64],
        b_phi: &[f64],
        d: &[f64],
    ) -> Result<Fields, ProblemError> {
        Ok(self.direct()?.solve_with_update(loads, b_u, b_phi, d)?)
    }

    /// At most 3 corrections with the factors of `K`, each kept only where it lowers the
    /// residual; none on the Schur-complement PCG (its tolerance is its accuracy).
    fn refine(
        &mut self,
        rhs: linalg::Rhs<'_>,
        u: &mut [f64],
        phi: &mut [f64],
        tol: f64,
    ) -> Result<Refinement, ProblemError> {
        let Linear { blocks, solver, .. } = self;
        let LinearSolver::Direct(direct) = solver else {
            return Ok(Refinement::default());
        };
        let k = linalg::CoupledBlocks {
            a: &blocks.a,
            g: &blocks.g,
            b: &blocks.b,
        };
        Ok(linalg::refine(direct, k, rhs, u, phi, tol, 3)?.into())
    }

    fn refine_many(
        &mut self,
        rhs: &[linalg::Rhs<'_>],
        xs: &mut [Fields],
        tol: f64,
    ) -> Result<Vec<Refinement>, ProblemError> {
        let Linear { blocks, solver, .. } = self;
        let LinearSolver::Direct(direct) = solver else {
            return Ok(vec![Refinement::default(); xs.len()]);
        };
        let k = linalg::CoupledBlocks {
            a: &blocks.a,
            g: &blocks.g,
            b: &blocks.b,
        };
        let refined = linalg::refine_many(direct, k, rhs, xs, tol, 3)?;
        Ok(refined.into_iter().map(Refinement::from).collect())
    }

    fn solve_many(&mut self, rhs: &[(&[f64], &[f64])]) -> Result<Vec<Fields>, ProblemError> {
        match &mut self.solver {
            LinearSolver::Direct(direct) => Ok(direct.solve_many(rhs)?),
            LinearSolver::SchurPcg(_) => rhs.iter().map(|(b_u, b_phi)| Ok(self.solve(b_u, b_phi)?.0)).collect(),
        }
    }

    fn solve_trailing_many(&mut self, dofs: &[usize], updates: &[&[f64]]) -> Result<Option<Vec<Fields>>, ProblemError> {
        match &self.solver {
            LinearSolver::Direct(direct) => Ok(direct.solve_trailing_many(dofs, updates)?),
            LinearSolver::SchurPcg(_) => Ok(None),
        }
    }

    fn equilibrium(&mut self, u: &[f64], phi: &[f64], rhs: linalg::Rhs<'_>) -> Result<f64, ProblemError> {
        Ok(linalg::equilibrium_residual(self.coupled_blocks(), u, phi, rhs))
    }

    fn coupled(&mut self) -> Option<&mut dyn CoupledSolver> {
        Some(self.solver.coupled())
    }

    fn condenses(&self) -> bool {
        matches!(self.solver, LinearSolver::Direct(_))
    }
}

/// Factors the linear solver: the Schur PCG's Cholesky factors, or the `L D Lᵀ` of `K` in
/// geometric nested dissection (measured no slower than AMD in 2D and 1.6x faster in 3D,
/// docs/performance.md), with the contact dofs of `boundary` last for the condensed
/// strategies, to read the contact block off the factor; its elimination tree on all of
/// rayon's threads ([`linalg::pool_par`]).
fn factor(
    posed: &Posed<'_>,
    mut blocks: Blocks,
    boundary: Option<&ContactBoundary>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Factored, ProblemError> {
    let t = Instant::now();
    if let (Some(bed), Some(cb)) = (posed.bed, boundary) {
        // the springs that hold a body only its bed holds (crate::bed), on A's own pattern
        linalg::sparse::add_to_pattern(&mut blocks.a, &cb.normal_springs(bed.stiffness)).map_err(|(i, j)| {
            ProblemError::NoSolution {
                sought: "contact.compliance",
                why: format!("the stiffness matrix stores no entry ({i}, {j}) for the bed's springs at a contact node"),
            }
        })?;
    }
    let (scene, plan) = (posed.scene.scene(), posed.plan());
    let paper = plan.rule == Rule::Paper;
    let pcg_params = PcgParams {
        rel_tol: plan.pcg_tol,
        max_iters: 10_000,
        stop: if paper {
            PcgStop::PaperRz
        } else {
            PcgStop::RelativeResidual
        },
        ..Default::default()
    };
    // the Schur route's Cholesky factors with faer's sequential walk (its parallel dense kernels
    // lose on 2 cores); the L D Lᵀ of K walks its elimination tree on rayon's pool
    let par = faer::Par::Seq;
    let budget = factor_budget(posed, &blocks, boundary, limits)?;
    let too_large = |e: linalg::LinalgError| too_large(e, limits, scene);
    let solver = if plan.linear_strategy.runs_pcg() {
        let pcg = SchurPcg::new_within(blocks.a.clone(), blocks.g.clone(), &blocks.b, pcg_params, par, budget)
            .map_err(too_large)?;
        LinearSolver::SchurPcg(pcg)
    } else {
        let mesh = &posed.setup.mesh;
        let order = posed.disc.dofs.expand_node_order(&mesh.nested_dissection());
        let ordering = match (boundary, plan.linear_strategy.is_condensed()) {
            (Some(cb), true) => Ordering::GivenThenLast {
                order,
                last: cb.condensed_dofs(),
            },
            _ => Ordering::Given(order),
        };
        let watch = crate::progress::FactorWatch::default();
        reporter.event(&Event::Factoring { watch: watch.clone() });
        let blocks3 = [&blocks.a, &blocks.g, &blocks.b];
        LinearSolver::Direct(
            DirectLdlt::new_watched(blocks3, &ordering, (linalg::pool_par(), budget), Some(&watch.0))
                .map_err(too_large)?,
        )
    };
    let seconds = t.elapsed().as_secs_f64();
    reporter.event(&Event::Factored { seconds });
    Ok(Factored {
        linear: Linear {
            blocks,
            solver,
            pcg_params,
            seconds,
        },
        instants: Instants::default(),
    })
}

/// The bytes left for the factor within `limits`, once the assembled blocks and (condensed
/// strategies) the dense contact problem are counted; an error where those alone do not fit.
fn factor_budget(
    posed: &Posed<'_>,
    b: &Blocks,
    boundary: Option<&ContactBoundary>,
    limits: Limits,
) -> Result<Option<usize>, ProblemError> {
    let Some(available) = limits.memory_bytes else {
        return Ok(None);
    };
    let (plan, dofs) = (posed.plan(), &posed.disc.dofs);
    let nnz = b.a.val().len() + b.g.val().len() + b.b.val().len();
    let held = crate::estimate::assembled(nnz, posed.setup.mesh.n_nodes(), dofs.n_u + dofs.n_phi);
    let dense = match boundary {
        Some(cb) if plan.linear_strategy.is_condensed() => cb.dense_bytes(plan.n_tangential()),
        _ => 0.0,
    };
    // the peak of a run is the assembled system and the factor together, times PEAK_RATIO, and
    // BASE_BYTES beside (the factorisation's workspace, the recovery; measured on paper and
    // paper-3d at several sizes): the factor's budget leaves that margin
    let available_f = ((available as f64) - crate::estimate::BASE_BYTES).max(0.0) / crate::estimate::PEAK_RATIO;
    if held + dense > available_f {
        return Err(ProblemError::TooLarge {
            what: format!(
                "the assembled system and the dense contact compliance of a condensed strategy ({})",
                crate::estimate::Bytes(dense)
            ),
            needed: ((held + dense) * crate::estimate::PEAK_RATIO + crate::estimate::BASE_BYTES) as u64,
            available,
            limit: limits.limit(),
        });
    }
    Ok(Some((available_f - held - dense) as usize))
}

/// A linear-algebra error, made [`ProblemError::TooLarge`] where the factor did not fit, and
/// [`ProblemError::IllConditioned`] where it broke down on an ill-conditioned scene.
fn too_large(e: linalg::LinalgError, limits: Limits, scene: &Scene) -> ProblemError {
    let inner = match &e {
        linalg::LinalgError::In { source, .. } => source.as_ref(),
        other => other,
    };
    match (inner, limits.memory_bytes) {
        (linalg::LinalgError::TooLarge { needed, budget }, Some(available)) => ProblemError::TooLarge {
            what: format!(
                "a sparse factor of {}, counted by its symbolic analysis, beside the assembled system",
                crate::estimate::Bytes(*needed as f64)
            ),
            // the rest of the run takes what the factor's budget left out
            needed: (*needed + (available as usize).saturating_sub(*budget)) as u64,
            available,
            limit: limits.limit(),
        },
        _ => ProblemError::linear(e, scene),
    }
}
