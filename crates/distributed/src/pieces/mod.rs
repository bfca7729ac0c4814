//! A run in which no rank holds the whole mesh (issue 45's route): each rank generates its
//! piece of the scene's mesh ([`mesh::Blocks`]: its block of cells and one layer of ghosts),
//! sets it up ([`problem::backend::setup_piece`]), numbers the unknowns with the other ranks
//! ([`Layout::of_piece`]), assembles its own cells and solves by the Krylov route; each rank
//! then holds the solution at its piece's nodes (fetched from their owners, never gathered)
//! and recovers the fields on its piece's cells.
//!
//! Where the pieces come from ([`PieceMesh`]): a generated rectangle or box, each rank making
//! its block; or a Gmsh mesh split into one file per rank, each rank reading its part and the
//! parts completing each other (`parts`).
//!
//! What it solves today: a generated rectangle or box, or a Gmsh mesh of one body, of order 1
//! (an error against a field solution summed over the ranks' own cells), with floating
//! terminals (`floating`), at one instant or along a load path, without contact or with the
//! contact the active sets hold (the paper's base model, on one zone or several:
//! [`crate::active_sets_hold`]), each rank iterating on the contact points at the nodes it
//! owns; every other scene is refused by key ([`pieces_support`]). The run's
//! report is made of sums over the ranks ([`PieceSolution::report`]), completed on rank 0 from
//! the gathered surfaces ([`PieceSolution::gathered`]); the driver writes each rank's piece of
//! the solution.
//!
//! Why the pieces are complete: a rank's own node lies only in cells of its piece (its own and
//! the ghost layer), so its rows of the matrix, of the loads and of their lifting by prescribed
//! values are summed from the piece alone, and the fields of every own cell are recovered
//! from the piece's nodal values.

mod floating;
mod gather;
mod parts;
mod path;
mod report;
mod weakening;

pub use gather::Gathered;
pub use path::{EachStep, PieceFrame, PieceStep};

use crate::active::{residual, step};
use crate::contact::{active_set, shared_components, ActiveSetParams, ContactRows};
use crate::error::DistributedError;
use crate::krylov::{configure, KrylovFields};
use crate::layout::Layout;
use crate::supports::shared_refusal;
use crate::system::{assemble, System};
use crate::MAX_ACTIVE_SET_STEPS;
use contact::{PointValues, Spread};
use fe_assembly::CellFields;
use floating::Floating;
use mesh::{Blocks, MeshPiece};
use petsc::{Index, Petsc, Vector};
use problem::backend::{setup_piece, ContactBoundary, ContactSolve, Unsupported};
use problem::terminal_groups;
use problem::ContactResult;
use problem::{Event, ProblemError, Reporter, Scene, SetupError};
use std::time::Instant;

/// The backend name a run on pieces refuses under.
const NAME: &str = "petsc";

/// Where the pieces of a run come from.
#[derive(Clone, Debug)]
pub enum PieceMesh {
    /// The scene's generated rectangle or box: each rank makes its block of cells and one
    /// layer of ghosts ([`mesh::Blocks`]).
    Generated,
    /// A mesh that the one rank of a one-rank run holds whole (read from the scene's file).
    Whole(mesh::Mesh),
    /// The files of a mesh that Gmsh split, one per partition and rank, in rank order
    /// ([`mesh::parts_of`]): each rank reads its own ([`mesh::read_msh_part`]).
    Parts(Vec<std::path::PathBuf>),
}

/// One rank's share of a run on pieces.
pub struct PieceSolution {
    /// The rank's piece: its mesh as set up (the scene's regions and electrodes), its cells'
    /// and nodes' owners and their numbers in the whole mesh.
    pub piece: MeshPiece,
    /// The displacement at each node of the piece (`z = 0` in 2D).
    pub u: Vec<[f64; 3]>,
    /// The potential at each node of the piece (0 where a node has none).
    pub phi: Vec<f64>,
    /// Stress, strain, electric displacement and field in each cell of the piece (the ghost
    /// cells' too: they are their owners' values).
    pub fields: CellFields,
    /// The run's report (`run.json`), the same on every rank, from sums over the ranks; its
    /// contact section and an indenter's figures are rank 0's, from the gathered points
    /// ([`PieceSolution::gathered`]).
    pub report: problem::RunReport,
    /// The rank's share of the contact solution, where the scene has contact.
    pub contact: Option<PieceContact>,
}

/// Whether a run on pieces solves `scene`: a generated rectangle or box (graded, layered or
/// not; not rounded), or a Gmsh mesh, of order 1, with or without floating terminals, its
/// contact (if any) one the active sets hold, at one instant or along a load path (an error against a
/// contact's closed form, Hertz's or Cattaneo-Mindlin's, from the points rank 0 gathers; the
/// half-space's needs a body of revolution, which pieces do not take).
///
/// # Errors
/// [`Unsupported`], naming the key of what a run on pieces does not solve yet.
pub fn pieces_support(scene: &Scene) -> Result<(), Unsupported> {
    if let Some((key, what)) = problem::backend::piece_refusal(&scene.mesh) {
        return Err(Unsupported::new(NAME, key, format!("{what} on a mesh made in pieces"))
            .advise("a run whose every rank holds the whole mesh solves it"));
    }
    // contact by the active sets, on each rank's own points
    if scene.zones().is_empty() {
        return Ok(());
    }
    crate::supports::active_sets_hold_at_instants(scene, None).map_err(|e| {
        Unsupported::new(
            NAME,
            &e.key,
            format!(
                "{} on a mesh made in pieces (contact there is the active sets')",
                e.feature
            ),
        )
        .advise("a run whose every rank holds the whole mesh solves it")
    })
}

/// Solves `scene` on the ranks of `petsc`, each rank holding only its piece of the mesh, and
/// returns each rank's share. Collective. `limits.memory_bytes` is what one rank may take:
/// the estimate of a rank's peak is checked against it before the piece is made, on every
/// rank. `reporter` hears the contact iteration's progress (only rank 0's should print).
///
/// # Errors
/// [`Unsupported`] (as a scene error) for what a run on pieces does not solve; more ranks than
/// the mesh has cells along its axes; the estimate over the limit ([`ProblemError::TooLarge`]
/// naming the rank); the set-up's errors; the active sets' and PETSc's.
pub fn solve_on_pieces(
    petsc: &Petsc,
    scene: &Scene,
    source: PieceMesh,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
) -> Result<PieceSolution, DistributedError> {
    solve_path_on_pieces(petsc, scene, source, limits, reporter, &mut |_| Ok(()))
}

/// [`solve_on_pieces`], each instant of the scene's path (none for a static scene) handed to
/// `each` on every rank as it is solved: its row, and at the instants the path writes, the
/// rank's piece of its fields (for a caller that writes a path's files as it goes). The
/// solution returned is the last instant's, its report with the path's section.
///
/// # Errors
/// As [`solve_on_pieces`]; the error `each` returns on any rank (every rank then stops).
pub fn solve_path_on_pieces(
    petsc: &Petsc,
    scene: &Scene,
    source: PieceMesh,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
    each: &mut EachStep<'_>,
) -> Result<PieceSolution, DistributedError> {
    let valid = scene.validate()?;
    pieces_support(scene).map_err(ProblemError::from)?;
    let start = Instant::now();
    let generated = matches!(source, PieceMesh::Generated);
    let (blocks, mut piece, setup, (terminals, floating)) = set_up(petsc, valid, source, limits, reporter)?;
    let mut disc = agree(petsc, setup.discretize().map_err(DistributedError::from), "discretise")?;
    held_on_pieces(petsc, &disc, &piece, generated)?;
    let tie = floating.untie(&mut disc);
    let (b_u, b_phi) = agree(petsc, loads(&disc, &setup, valid), "assemble their loads")?;
    let t_setup = start.elapsed().as_secs_f64();
    let layout = Layout::of_piece(petsc, &piece, &disc.dofs, tie)?;
    let mut system = assemble(petsc, &disc, &layout, (&b_u, &b_phi, &floating.charges(1.0)))?;
    // loads finite one by one whose squares overflow (a pressure or a charge of 1e308): named
    // as the default backend names them, not left to the Krylov solve's NaN (the norm is
    // reduced: every rank alike)
    ProblemError::check_finite(&[system.load_norm], "the norm of the loads", &valid)?;
    let fields = KrylovFields::new(petsc, &setup, &layout);
    let t_assembly = start.elapsed().as_secs_f64() - t_setup;
    let owned: Vec<bool> = piece.node_rank.iter().map(|&r| r == petsc.rank()).collect();
    let run = Run {
        petsc,
        scene,
        setup: &setup,
        layout: &layout,
        owned: &owned,
        piece: &piece,
        terminals: &terminals,
        floating: &floating,
    };
    let (x, solved, contact, path) = instants(&run, &mut disc, (&mut system, &fields), (limits, reporter), each)?;
    let t_solve = start.elapsed().as_secs_f64() - t_setup - t_assembly;
    reporter.event(&Event::Krylov {
        iterations: solved.iterations,
        reason: &solved.reason,
        setup_seconds: solved.setup_seconds,
    });
    let equilibrium = match contact {
        Some(_) => 0.0,
        None => system.reactions(&x)?.norm()? / system.load_norm.max(f64::MIN_POSITIVE),
    };
    let (u, phi) = nodal(&x, &layout)?;
    let recovered = disc.recover(&u, &phi);
    let finite = ProblemError::check_finite(&recovered.stress, "the stress", &valid);
    agree(petsc, finite.map_err(DistributedError::from), "recover their fields")?;
    let shares = run.shares(&disc);
    let timings = problem::report::Timings {
        setup: t_setup,
        assembly: t_assembly,
        factorization: solved.setup_seconds,
        contact: t_solve * f64::from(u8::from(contact.is_some())),
        solve: t_solve,
        total: start.elapsed().as_secs_f64(),
        ..Default::default()
    };
    let figures = report::Figures {
        solved: &solved,
        contact: contact.as_ref(),
        equilibrium,
        unknowns: (0..petsc.size()).map(|r| layout.owned(r).len()).collect(),
        timings,
        blocks,
        nonzeros: petsc.sum(&[system.matrix.local_info()?.0])?[0],
    };
    let mut report = shares.report(&u, &phi, figures)?;
    report.path = path;
    exact_heard(&report, reporter);
    drop(disc);
    piece.mesh = setup.mesh;
    Ok(PieceSolution {
        piece,
        u,
        phi,
        fields: recovered,
        contact,
        report,
    })
}

/// The run's instants: a linear solve, a static contact solve, or a path's instants
/// ([`path::walk`]); the last instant's solution vector, the Krylov solves' figures, its
/// contact and the path's section of the report.
#[allow(clippy::type_complexity)]
fn instants<'p>(
    run: &Run<'_, 'p>,
    disc: &mut fe_assembly::Discretization<'_>,
    (system, fields): (&mut System<'p>, &KrylovFields),
    (limits, reporter): (problem::Limits, &mut dyn Reporter),
    each: &mut EachStep<'_>,
) -> Result<
    (
        Vector<'p>,
        Solved,
        Option<PieceContact>,
        Option<problem::report::PathReport>,
    ),
    DistributedError,
> {
    let (petsc, scene) = (run.petsc, run.scene);
    if scene.zones().is_empty() {
        let options = configure(petsc, scene, run.layout, None, true)?;
        let (x, solved) = linear(petsc, fields, system, options)?;
        return Ok((x, solved, None, None));
    }
    if scene.path.is_some() {
        let w = path::walk(run, disc, (system, fields), (limits, reporter), each)?;
        return Ok((w.x, w.solved, Some(w.contact), Some(w.path)));
    }
    let on = run.on(disc);
    let boundary = on.boundary()?;
    let history = History::none(&boundary);
    let (x, solved, contact) = on.contact((system, fields), boundary, (history, 1.0), limits, reporter)?;
    Ok((x, solved, Some(contact), None))
}

/// The piece's load vectors, checked finite.
fn loads(
    disc: &fe_assembly::Discretization<'_>,
    setup: &problem::backend::Setup,
    valid: problem::Valid<'_>,
) -> Result<(Vec<f64>, Vec<f64>), DistributedError> {
    let (b_u, b_phi) = disc.rhs(&setup.loads)?;
    ProblemError::check_finite(&b_u, "the mechanical load vector", &valid)?;
    ProblemError::check_finite(&b_phi, "the electric load vector", &valid)?;
    Ok((b_u, b_phi))
}

/// `result` where every rank has one; where some rank has an error, an error on every rank
/// (the rank's own; on the others one that says how many ranks could not `doing`), so that
/// no rank goes on to a collective call the failed ones never make (a broken cell of one
/// Gmsh part, a cell of one piece without material). Collective.
fn agree<T>(petsc: &Petsc, result: Result<T, DistributedError>, doing: &str) -> Result<T, DistributedError> {
    agree_as(petsc, result, doing, |why| {
        ProblemError::NoSolution {
            sought: "a run on pieces",
            why,
        }
        .into()
    })
}

/// [`agree`], the other ranks' error made by `others` from what it says.
fn agree_as<T>(
    petsc: &Petsc,
    result: Result<T, DistributedError>,
    doing: &str,
    others: impl FnOnce(String) -> DistributedError,
) -> Result<T, DistributedError> {
    let failed = petsc.sum(&[f64::from(u8::from(result.is_err()))])?[0];
    match result {
        Ok(_) if failed > 0.0 => Err(others(format!(
            "{failed} of the {} ranks could not {doing} (each says why)",
            petsc.size()
        ))),
        other => other,
    }
}

/// Tells `reporter` the error against an exact solution, where the report has one.
fn exact_heard(report: &problem::RunReport, reporter: &mut dyn Reporter) {
    if let Some(e) = &report.exact {
        reporter.event(&Event::Exact {
            kind: e.kind(),
            what: e.error_name(),
            error: e.error(),
        });
    }
}

/// Refuses, on every rank alike, a body that the Dirichlet conditions do not hold, as the whole
/// mesh's check does (`fe_assembly::held`): each solid part of the mesh (a generated box is one;
/// a mesh read's are labelled across the pieces, [`parts::solid_labels`]: cells joined through
/// a facet, a hinge does not hold two parts together) has its rigid motions held when the Gram
/// matrix of the conditions at its nodes, summed over the ranks' own nodes
/// (`fe_assembly::rigid_gram`, about its bounding box, [`parts::frames`]), has full rank; the
/// first part that has a free motion is named by its least cell, as the whole mesh's check
/// names it. The potential of a body of one part whose every cell is electric is held when
/// some rank prescribes φ at a node it owns; otherwise each electric part's (joined by electric
/// cells through any node) where some node of it has φ prescribed ([`parts::floating_parts`]).
/// Collective.
fn held_on_pieces(
    petsc: &Petsc,
    disc: &fe_assembly::Discretization<'_>,
    piece: &MeshPiece,
    generated: bool,
) -> Result<(), DistributedError> {
    let (dim, rank, mesh) = (disc.dofs.dim, petsc.rank(), disc.mesh);
    let owned: Vec<usize> = (0..piece.node_rank.len())
        .filter(|&v| piece.node_rank[v] == rank)
        .collect();
    let (bodies, frames) = if generated {
        // one body: every owned node, the box's frame
        let one = parts::Bodies {
            labels: vec![0],
            nodes: vec![owned.clone()],
            cells: vec![piece.n_global_cells as f64],
        };
        (one, vec![parts::frame(petsc, mesh, piece)?])
    } else {
        let labels = parts::solid_labels(petsc, mesh, piece)?;
        let bodies = parts::bodies(petsc, mesh, piece, &labels)?;
        let frames = parts::frames(petsc, mesh, &bodies)?;
        (bodies, frames)
    };
    let mut grams = vec![];
    for (nodes, &frame) in bodies.nodes.iter().zip(&frames) {
        grams.extend(fe_assembly::rigid_gram(mesh, &disc.dofs, nodes.iter().copied(), frame));
    }
    let grams = petsc.sum(&grams)?;
    let width = grams.len() / bodies.labels.len().max(1);
    for (b, &frame) in frames.iter().enumerate() {
        let free = fe_assembly::free_in(dim, &grams[b * width..(b + 1) * width], frame);
        if !free.is_empty() {
            let unheld = fe_assembly::Unheld::Motion {
                count: free.len(),
                motions: free.join("; "),
                cell: bodies.labels[b] as usize,
                cells: bodies.cells[b] as usize,
                with_supports: false,
            };
            return Err(fe_assembly::AssemblyError::from(unheld).into());
        }
    }
    let cells = piece.n_global_cells;
    let electric = (0..piece.own_cells).filter(|&c| disc.cell_electric[c]).count() as f64;
    let fixed = |v: usize| matches!(disc.dofs.phi[v], fe_assembly::Dof::Fixed(_));
    let prescribed = owned.iter().filter(|&&v| fixed(v)).count() as f64;
    let sums = petsc.sum(&[electric, prescribed])?;
    // one body of electric cells alone: its potential is held where some rank prescribes it;
    // otherwise each electric part (joined by electric cells) must be
    let floating = if sums[0] == 0.0 {
        0
    } else if sums[0] == cells as f64 && bodies.labels.len() == 1 {
        usize::from(sums[1] == 0.0)
    } else {
        parts::floating_parts(petsc, mesh, piece, &disc.cell_electric, &fixed)?
    };
    if floating > 0 {
        let unheld = fe_assembly::Unheld::Potential { cell: 0, cells };
        return Err(fe_assembly::AssemblyError::from(unheld).into());
    }
    Ok(())
}

/// This rank's piece set up: the blocks per axis (a mesh read: its parts, `[p, 1, 1]`), the
/// piece (its mesh taken by the set-up), the set-up
/// with the conditions that reach the piece, and the terminals' groups of the whole scene with
/// its floating terminals (their charges taken out of the set-up's loads); the plan and units
/// reported. Collective.
#[allow(clippy::type_complexity)]
fn set_up(
    petsc: &Petsc,
    valid: problem::Valid<'_>,
    source: PieceMesh,
    limits: problem::Limits,
    reporter: &mut dyn Reporter,
) -> Result<([usize; 3], MeshPiece, problem::backend::Setup, (Vec<String>, Floating)), DistributedError> {
    let scene = valid.scene();
    // a mesh read is numbered as its generator made it, which puts neighbours far apart in
    // memory: its pieces are numbered along a space-filling curve (the generated grid's order
    // is already near)
    let (blocks, mut piece) = match source {
        PieceMesh::Generated => make_piece(petsc, scene, limits).map(|(b, p)| (b.p, p))?,
        PieceMesh::Whole(mesh) => {
            parts::check_memory(petsc, &mesh, limits)?;
            ([1, 1, 1], MeshPiece::whole(mesh).in_space_order())
        }
        PieceMesh::Parts(files) => (
            [petsc.size(), 1, 1],
            parts::read(petsc, &files, limits)?.in_space_order(),
        ),
    };
    let dim = piece.mesh.dim;
    let taken = std::mem::replace(&mut piece.mesh, mesh::Mesh::empty(dim));
    let mut setup = agree(
        petsc,
        setup_piece(valid, taken).map_err(DistributedError::from),
        "set up their piece",
    )?;
    check_regions_and_electrodes(petsc, scene, &setup.mesh, piece.own_cells)?;
    // the pictures rank 0 draws from gathered surfaces: a 3D box's face `front`; a 2D body's
    // pictures draw the whole mesh, which no rank holds here
    if dim == 2 {
        let drawn = |o: &problem::Output| !matches!(o, problem::Output::Deformed | problem::Output::Potential);
        setup.plan.outputs.retain(drawn);
    }
    reporter.event(&Event::Planned(&setup.plan));
    reporter.event(&Event::Units(&setup.units));
    let terminals: Vec<String> = terminal_groups(&setup).into_iter().map(String::from).collect();
    let floating = Floating::take(&mut setup);
    conditions_on_the_piece(petsc, &mut setup)?;
    Ok((blocks, piece, setup, (terminals, floating)))
}

/// How a solve on the pieces went.
struct Solved {
    iterations: usize,
    reason: String,
    options: String,
    /// The preconditioners' set-up, s.
    setup_seconds: f64,
}

/// The blocks of the scene's mesh among the ranks, the estimate of a rank's peak checked, and
/// this rank's piece. Every rank decides alike.
fn make_piece(petsc: &Petsc, scene: &Scene, limits: problem::Limits) -> Result<(Blocks, MeshPiece), ProblemError> {
    let (rank, ranks) = (petsc.rank(), petsc.size());
    let m = &scene.mesh;
    let dim = m.lo.len();
    let n = m.cells_per_axis();
    let cells = [n[0], n[1], n.get(2).copied().unwrap_or(1)];
    let blocks = Blocks::new(dim, cells, ranks).ok_or_else(|| {
        SetupError::new(
            "mesh.n",
            format!(
                "{ranks} ranks cannot each hold a block of the {} cells per axis (mesh.n): fewer ranks, or a finer mesh",
                cells[..dim].iter().map(usize::to_string).collect::<Vec<_>>().join(" x ")
            ),
        )
    })?;
    check_memory(scene, &blocks, rank, limits)?;
    let piece = match dim {
        2 => blocks.rectangle_piece([m.lo[0], m.lo[1]], [m.hi[0], m.hi[1]], rank),
        _ => blocks.box_piece([m.lo[0], m.lo[1], m.lo[2]], [m.hi[0], m.hi[1], m.hi[2]], rank),
    };
    Ok((blocks, piece))
}

/// The linear problem: one Krylov solve.
fn linear<'p>(
    petsc: &'p Petsc,
    fields: &KrylovFields,
    system: &mut System<'p>,
    options: String,
) -> Result<(Vector<'p>, Solved), DistributedError> {
    let t = Instant::now();
    let mut ksp = fields.krylov(petsc, &mut system.matrix)?;
    let setup_seconds = t.elapsed().as_secs_f64();
    let mut x = system.rhs.duplicate()?;
    let info = ksp.solve(&system.rhs, &mut x)?;
    if !info.reason.starts_with("CONVERGED") {
        return Err(ProblemError::NoSolution {
            sought: "the Krylov solve on the pieces",
            why: format!("{} after {} iterations", info.reason, info.iterations),
        }
        .into());
    }
    Ok((
        x,
        Solved {
            iterations: info.iterations,
            reason: info.reason,
            options,
            setup_seconds,
        },
    ))
}

/// What a rank's piece holds of the run, for its contact, but its discretisation (which a
/// path's instants rescale).
#[derive(Clone, Copy)]
struct Run<'a, 'p> {
    petsc: &'p Petsc,
    scene: &'a Scene,
    setup: &'a problem::backend::Setup,
    layout: &'a Layout,
    /// Whether this rank owns each node of its piece.
    owned: &'a [bool],
    /// The piece (its numbers in the whole mesh, its own cells; its mesh is the set-up's).
    piece: &'a MeshPiece,
    /// The terminals' groups of the whole scene.
    terminals: &'a [String],
    /// The floating terminals of the whole scene, with their charges.
    floating: &'a Floating,
}

impl<'a, 'p> Run<'a, 'p> {
    /// What the run's piece holds for the report, on the discretisation `disc`.
    fn shares<'b>(&'b self, disc: &'b fe_assembly::Discretization<'b>) -> report::Shares<'b>
    where
        'a: 'b,
    {
        report::Shares {
            petsc: self.petsc,
            scene: self.scene,
            setup: self.setup,
            disc,
            owned: self.owned,
            global_node: &self.piece.global_node,
            terminals: self.terminals,
            floating: self.floating,
            tie: &self.layout.tie,
            own_cells: self.piece.own_cells,
            cells: self.piece.n_global_cells,
        }
    }

    /// The run on the discretisation `disc`.
    fn on<'b>(&self, disc: &'b fe_assembly::Discretization<'b>) -> OnPiece<'b, 'p>
    where
        'a: 'b,
    {
        OnPiece { run: *self, disc }
    }
}

/// What a rank's piece holds of the run, for its contact.
struct OnPiece<'a, 'p> {
    run: Run<'a, 'p>,
    disc: &'a fe_assembly::Discretization<'a>,
}

impl<'a, 'p> std::ops::Deref for OnPiece<'a, 'p> {
    type Target = Run<'a, 'p>;
    fn deref(&self) -> &Run<'a, 'p> {
        &self.run
    }
}

impl<'p> OnPiece<'_, 'p> {
    /// This rank's contact points (those at the nodes it owns) at the scene's values; refused
    /// on every rank alike where no rank has any. Collective.
    fn boundary(&self) -> Result<ContactBoundary, DistributedError> {
        let specs = self.scene.zones();
        let boundary = ContactBoundary::of_groups_on_piece(self.disc, &specs, self.owned)?;
        // each zone's points over the ranks
        let mut counts = vec![0.0; specs.len()];
        for &k in &boundary.group_of {
            counts[k] += 1.0;
        }
        let counts = self.petsc.sum(&counts)?;
        if let Some(k) = (0..specs.len()).find(|&k| counts[k] == 0.0) {
            return Err(ProblemError::from(SetupError::new(
                "contact.group",
                format!(
                    "contact group `{}` has no contact point: Dirichlet conditions prescribe the normal displacement of all its nodes, or an indenter reaches none of them",
                    specs[k].group
                ),
            ))
            .into());
        }
        // a node's points on one component: told on every rank, at the lowest such rank's point
        let law = self.setup.plan.law(&boundary.points, &boundary.group_of);
        let shared = shared_components(&boundary.points, &boundary.nodes, &law);
        let rank = self.petsc.rank();
        let first = self.petsc.max(&[shared.map_or(0.0, |_| (rank + 1) as f64)])?[0];
        if first > 0.0 {
            let mine = shared.filter(|_| first as usize == rank + 1);
            let at = self
                .petsc
                .sum(&mine.map_or([0.0; 3], |i| boundary.points.position[i]))?;
            return Err(ProblemError::from(shared_refusal([at[0], at[1], at[2]])).into());
        }
        Ok(boundary)
    }

    /// Contact by the active sets on this rank's points `boundary` (an instant's: a path's
    /// gaps scaled), each step one Krylov solve of the whole system; what the iteration decides
    /// on is reduced. `history`: friction's frame (the tangential displacements at the
    /// instant before) and the multipliers to start from, at this rank's points.
    fn contact(
        &self,
        (system, fields): (&System<'p>, &KrylovFields),
        mut boundary: ContactBoundary,
        (history, load): (History<'p>, f64),
        limits: problem::Limits,
        reporter: &mut dyn Reporter,
    ) -> Result<(Vector<'p>, Solved, PieceContact), DistributedError> {
        let (petsc, scene, layout) = (self.petsc, self.scene, self.layout);
        let total = petsc.sum(&[boundary.points.len() as f64])?[0];
        let how = ContactSolve::new(&self.setup.plan, scene, &boundary, limits.interrupt);
        let options = configure(petsc, scene, layout, Some(how.tol), true)?;
        let params = ActiveSetParams {
            tol: how.tol,
            max_steps: MAX_ACTIVE_SET_STEPS,
        };
        let tol = how.tol;
        let mut progress = |p: &contact::Progress| reporter.event(&Event::Contact { progress: p, tol });
        let mut t_pc = 0.0;
        let mut solve_one = |m: &mut petsc::Matrix<'p>, b: &Vector<'p>, x: &mut Vector<'p>, loose: Option<f64>| {
            step(petsc, fields, &mut t_pc, (m, b, x), loose)
        };
        let (nodes, shift) = (boundary.nodes.clone(), history.shift);
        let frame = shift.clone();
        let mut krylov = 0;
        // the active sets on `points` from the multipliers `start` (and the solution `warm`)
        let mut solve_at = |points: &contact::ContactPoints,
                            start: Option<PointValues>,
                            warm: Option<Vector<'p>>|
         -> Result<crate::contact::ContactOutcome<'p>, DistributedError> {
            let rows = ContactRows::new(petsc, (points, &nodes, &how.law), false, layout, system)?
                .with_history(shift.clone(), start);
            let out = active_set(
                petsc,
                layout,
                system,
                (&rows, warm),
                params,
                &mut solve_one,
                &mut progress,
            )?;
            krylov += out.krylov_iterations;
            Ok(out)
        };
        // slip-weakening friction: the fixed point on the coefficients around the active sets
        // (on every rank alike: a rank may hold no point of the zone)
        let weakens = petsc.max(&[f64::from(u8::from(boundary.points.weakens()))])?[0] > 0.0;
        let mut solve_at = |points: &contact::ContactPoints,
                            start: Option<PointValues>,
                            warm: Option<Vector<'p>>|
         -> Result<crate::contact::ContactOutcome<'p>, DistributedError> {
            match weakens {
                true => weakening::weakened(petsc, (points, &frame), (start, warm), tol, &mut solve_at),
                false => solve_at(points, start, warm),
            }
        };
        let out = match problem::backend::ForceControl::of(scene, &boundary) {
            None => solve_at(&boundary.points, history.lambda, history.x)?,
            Some(control) => forced(
                petsc,
                &mut boundary.points,
                (&control, load, history.lambda),
                &mut solve_at,
            )?,
        };
        // the coefficients at the answer's slips, which its statuses and report read
        if weakens {
            boundary.points = boundary
                .points
                .at_slips(&weakening::increments(&out.solution.u, &frame));
        }
        let equilibrium = residual(system, &out.x, (&boundary, &out.solution), self.layout, petsc)?;
        let sol = &out.solution;
        let force: f64 = (0..sol.lambda.normal.len())
            .map(|i| boundary.points.weight[i] * sol.lambda.normal[i])
            .sum();
        let on_piece = self.on_piece(&boundary, sol)?;
        let contact = PieceContact {
            on_piece,
            steps: sol.info.newton_iters,
            residual: sol.info.complementarity,
            equilibrium,
            normal_force: petsc.sum(&[force])?[0],
            points: total as usize,
            solution: out.solution,
            boundary,
        };
        let solved = Solved {
            iterations: krylov,
            reason: out.reason,
            options,
            setup_seconds: t_pc,
        };
        Ok((out.x, solved, contact))
    }
}

/// Force control on this rank's `points`: the depth that carries `control`'s force times
/// `load` (a path's load factor), each evaluation `solve` at that depth from the last
/// multipliers (the first from `start`), the search's every step the same on every rank (the
/// force, the first touch and the face's size summed or bounded over the ranks); the depth
/// found's outcome, the search's last solve where it is the one found, else one more from its
/// multipliers. Leaves the points at that depth. Collective.
fn forced<'p>(
    petsc: &Petsc,
    points: &mut contact::ContactPoints,
    (control, load, start): (&problem::backend::ForceControl, f64, Option<PointValues>),
    solve: &mut impl FnMut(
        &contact::ContactPoints,
        Option<PointValues>,
        Option<Vector<'p>>,
    ) -> Result<crate::contact::ContactOutcome<'p>, DistributedError>,
) -> Result<crate::contact::ContactOutcome<'p>, DistributedError> {
    let mut last = None;
    let found = contact::solve_force_controlled_spread(
        points,
        control.driven.as_deref(),
        control.force * load,
        start,
        |points, start| {
            let out = solve(points, start, None)?;
            let sol = out.solution.clone();
            last = Some(out);
            Ok::<_, DistributedError>(sol)
        },
        |how, x| {
            Ok::<_, DistributedError>(match how {
                Spread::Sum => petsc.sum(&[x])?[0],
                Spread::Min => -petsc.max(&[-x])?[0],
                Spread::Max => petsc.max(&[x])?[0],
            })
        },
    )
    .map_err(problem::backend::ForceControl::failed::<DistributedError>)?;
    match last.filter(|o: &crate::contact::ContactOutcome<'p>| o.solution.lambda == found.lambda) {
        Some(out) => Ok(out),
        None => solve(points, Some(found.lambda), None),
    }
}

impl OnPiece<'_, '_> {
    /// The contact at every node of the piece's own cells, for its piece of the outputs: the
    /// points there (as their owners make them: every facet around such a node is in the
    /// piece), their multipliers, displacements and statuses fetched from the ranks that own
    /// them through a directory over the whole mesh's node numbers. Without it a piece's own
    /// cells would show no contact at the nodes it shares with a lower rank. Collective.
    fn on_piece(
        &self,
        own: &ContactBoundary,
        sol: &contact::ContactSolution,
    ) -> Result<ContactResult, DistributedError> {
        let (petsc, mesh) = (self.petsc, self.disc.mesh);
        let mut in_own_cells = vec![false; mesh.n_nodes()];
        for c in 0..self.piece.own_cells {
            for &v in mesh.cell(c) {
                in_own_cells[v] = true;
            }
        }
        let all = ContactBoundary::of_groups_on_piece(self.disc, &self.scene.zones(), &in_own_cells)?;
        let nt = own.points.n_tangential();
        // per node: 1 + its status's code (0: no point written), λ_n, u_n, λ_t, u_t
        let width = 3 + 2 * nt;
        let (lo, hi) = petsc.split(width * self.piece.n_global_nodes);
        let mut directory = Vector::mpi(petsc, hi - lo)?;
        let (mut at, mut values) = (vec![], vec![]);
        for (i, &v) in own.nodes.iter().enumerate() {
            let first = width * self.piece.global_node[v];
            let status = 1.0 + gather::status_code(sol.status[i]);
            // (frictionless: no tangential multipliers)
            let lt = sol
                .lambda
                .tangential
                .get(i * nt..(i + 1) * nt)
                .unwrap_or(&[0.0; 2][..nt]);
            let row = [status, sol.lambda.normal[i], sol.u.normal[i]]
                .into_iter()
                .chain(lt.iter().copied())
                .chain(sol.u.tangential[i * nt..(i + 1) * nt].iter().copied());
            for (j, x) in row.enumerate() {
                at.push(Layout::index(first + j));
                values.push(x);
            }
        }
        directory.set_values(&at, &values)?;
        directory.assemble()?;
        let asked: Vec<_> = all
            .nodes
            .iter()
            .flat_map(|&v| (0..width).map(move |j| (v, j)))
            .map(|(v, j)| Layout::index(width * self.piece.global_node[v] + j))
            .collect();
        let rows = directory.fetch(&asked)?;
        let n = all.points.len();
        let (mut lambda, mut u) = (contact::PointValues::zeros(n, nt), contact::PointValues::zeros(n, nt));
        let mut status = Vec::with_capacity(n);
        for (i, row) in rows.chunks_exact(width).enumerate() {
            status.push(match row[0] {
                0.0 => contact::Status::Separated,
                x => gather::status_of(x - 1.0),
            });
            (lambda.normal[i], u.normal[i]) = (row[1], row[2]);
            lambda.tangential[i * nt..(i + 1) * nt].copy_from_slice(&row[3..3 + nt]);
            u.tangential[i * nt..(i + 1) * nt].copy_from_slice(&row[3 + nt..]);
        }
        let solution = contact::ContactSolution {
            lambda,
            u,
            status,
            info: sol.info.clone(),
            electric: None,
        };
        Ok(ContactResult::condensed(all, solution))
    }
}

/// What a contact solve starts from: friction's frame (the tangential displacements at a
/// path's instant before, at this rank's points), and that instant's multipliers and solution
/// vector (none for a static run, or a path's first instant).
struct History<'p> {
    shift: contact::PointValues,
    lambda: Option<contact::PointValues>,
    x: Option<Vector<'p>>,
}

impl History<'_> {
    /// No history: a static run's, a path's first instant's.
    fn none(boundary: &ContactBoundary) -> Self {
        History {
            shift: contact::PointValues::zeros(boundary.points.len(), boundary.points.n_tangential()),
            lambda: None,
            x: None,
        }
    }
}

/// A rank's share of the contact solution of a run on pieces.
pub struct PieceContact {
    /// The contact at every node of the rank's own cells (those another rank owns fetched
    /// from it): what its piece of the outputs shows.
    pub on_piece: ContactResult,
    /// The rank's contact points (at the nodes of its piece it owns).
    pub boundary: ContactBoundary,
    /// Their multipliers, displacements and statuses.
    pub solution: contact::ContactSolution,
    /// Active-set steps.
    pub steps: usize,
    /// The complementarity residual over every rank's points.
    pub residual: f64,
    /// The equilibrium residual `|K x - b - f_c| / max(|loads|, |f_c|)` over all unknowns.
    pub equilibrium: f64,
    /// The normal force `Σ w λ_n` over every rank's points.
    pub normal_force: f64,
    /// Contact points over every rank.
    pub points: usize,
}

/// The solution `x` at every node of the piece: each node's unknowns fetched from the rank
/// that owns them (the displacements, then the potential where the node has one: its own or
/// its floating terminal's).
fn nodal(x: &Vector<'_>, layout: &Layout) -> Result<(Vec<[f64; 3]>, Vec<f64>), DistributedError> {
    let n = layout.first.len();
    let rows: Vec<Index> = (0..n)
        .flat_map(|v| (layout.first[v]..layout.first[v] + layout.dim).chain(layout.phi_row(v)))
        .map(Layout::index)
        .collect();
    let values = x.fetch(&rows)?;
    let (mut u, mut phi) = (vec![[0.0; 3]; n], vec![0.0; n]);
    let mut at = 0;
    for v in 0..n {
        u[v][..layout.dim].copy_from_slice(&values[at..at + layout.dim]);
        at += layout.dim;
        if layout.has_phi[v] {
            phi[v] = values[at];
            at += 1;
        }
    }
    Ok((u, phi))
}

/// The estimate of a rank's peak on pieces (its share of the unknowns, its piece's cells)
/// against what one rank may take; refused on every rank alike (the estimate is the largest
/// block's), naming the rank that reaches it.
fn check_memory(scene: &Scene, blocks: &Blocks, rank: usize, limits: problem::Limits) -> Result<(), ProblemError> {
    let Some(available) = limits.memory_bytes else {
        return Ok(());
    };
    let Some((dim, _, cells, unknowns)) = problem::backend::generated_sizes(scene) else {
        return Ok(());
    };
    // the largest block's share, widened by its ghost layer on both sides of every cut axis
    let widened: f64 = (0..dim)
        .map(|k| {
            let own = blocks.cells(k, 0).len();
            let ghosts = 2 * usize::from(blocks.p[k] > 1);
            (own + ghosts) as f64 / blocks.n[k] as f64
        })
        .product();
    let (cells, unknowns) = (cells * widened, unknowns * widened);
    let bytes = crate::run::BYTES_PER_UNKNOWN * unknowns + crate::run::BYTES_PER_CELL * cells;
    if bytes > available as f64 {
        return Err(ProblemError::TooLarge {
            what: format!(
                "rank {rank} of {}: a piece of {cells:.3e} cells and {unknowns:.3e} unknowns",
                blocks.ranks()
            ),
            needed: bytes as u64,
            available,
            limit: limits.memory_limit.unwrap_or("the memory available to one rank"),
        });
    }
    Ok(())
}

/// The Dirichlet conditions of the set-up that reach the piece: a condition on a group of
/// which the piece holds no facet (for a potential: no node of an electric cell) fixes
/// nothing here and is dropped (the dof map refuses a
/// condition that reaches no unknown); one that no piece reaches is kept on every rank, so that
/// each refuses it alike.
fn conditions_on_the_piece(petsc: &Petsc, setup: &mut problem::backend::Setup) -> Result<(), DistributedError> {
    let mesh = &setup.mesh;
    // the nodes that carry a potential on this piece: those of its electric cells (where the
    // materials do not cover the cells, every node: the discretisation refuses them)
    let mut carries_phi = vec![true; mesh.n_nodes()];
    if let Ok(of) = fe_assembly::cell_materials(mesh, &setup.materials) {
        carries_phi.fill(false);
        let electric = |&(c, _): &(usize, &[usize])| setup.materials[of[c]].1.electric;
        for (_, cell) in mesh.iter_cells().enumerate().filter(electric) {
            for &v in cell {
                carries_phi[v] = true;
            }
        }
    }
    let here: Vec<bool> = setup
        .constraints
        .iter()
        .map(|c| {
            let on_phi = matches!(c.field, fe_assembly::Field::Potential | fe_assembly::Field::Floating);
            mesh.boundaries
                .get(&c.group)
                .is_some_and(|g| g.facets.iter().any(|&v| !on_phi || carries_phi[v]))
        })
        .collect();
    let counts: Vec<f64> = here.iter().map(|&h| f64::from(u8::from(h))).collect();
    let anywhere = petsc.sum(&counts)?;
    let mut k = 0;
    setup.constraints.retain(|_| {
        let keep = here[k] || anywhere[k] == 0.0;
        k += 1;
        keep
    });
    Ok(())
}

/// Refuses a region (`mesh.region`) that holds no cell, or an electrode that covers no facet,
/// on every piece: counted on each rank's own cells and summed.
fn check_regions_and_electrodes(
    petsc: &Petsc,
    scene: &Scene,
    mesh: &mesh::Mesh,
    own_cells: usize,
) -> Result<(), DistributedError> {
    let regions: Vec<&str> = scene.mesh.regions.iter().map(|r| r.name.as_str()).collect();
    let electrodes: Vec<String> = (0..scene.electrodes().len())
        .map(|k| scene.electrodes()[k].group_name(k))
        .collect();
    let mut counts: Vec<f64> = regions
        .iter()
        .map(|r| {
            mesh.regions
                .get(*r)
                .map_or(0, |c| c.iter().filter(|&&c| c < own_cells).count()) as f64
        })
        .collect();
    counts.extend(
        electrodes
            .iter()
            .map(|e| mesh.boundaries.get(e).map_or(0, |g| g.n_facets()) as f64),
    );
    let sums = petsc.sum(&counts)?;
    if let Some(k) = (0..regions.len()).find(|&k| sums[k] == 0.0) {
        return Err(ProblemError::from(problem::backend::region_without_cells(regions[k])).into());
    }
    if let Some(k) = (0..electrodes.len()).find(|&k| sums[regions.len() + k] == 0.0) {
        return Err(ProblemError::from(problem::backend::electrode_without_facets(scene, k)).into());
    }
    Ok(())
}
