//! The run of one scene on the ranks of an MPI run, with the PETSc backend (the feature
//! `petsc`): the mesh read on every rank, the problem solved by `distributed`, the outputs
//! written by rank 0.

mod pieces;

use crate::DriverError;
use files::run::{memory_limits, peak_memory_bytes};
use files::{output, scene_file::Source};
use problem::{MeshKind, Reporter, Scene, Solution};
use std::path::Path;

/// Solves `scene` on the ranks of an MPI run with the PETSc backend (`solver.backend =
/// "petsc"`), and writes the outputs from rank 0 (as one set; nothing on error). Every rank
/// calls it; rank 0 returns the solution, with each rank's peak memory in `run.json`'s `petsc`
/// section, the others `None`. Only rank 0 reports to `reporter`.
///
/// # Errors
/// As [`files::run::run`], and [`DriverError::Petsc`] for PETSc's and MPI's.
pub fn run_distributed(
    scene: &Scene,
    source: &Source,
    dir: &Path,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DriverError> {
    let petsc = petsc::Petsc::init()?;
    // the ranks of one machine share its memory (on several machines this is conservative)
    let memory = memory_limits(petsc.size() as u64);
    run_on(&petsc, scene, source, dir, memory, reporter)
}

/// [`run_distributed`] on PETSc initialised by the caller, each rank's memory given: the bytes
/// it may use and the limit they come from (the least of the ranks' is taken), as
/// [`files::run::memory_limits`] finds them.
///
/// # Errors
/// As [`run_distributed`].
pub fn run_on(
    petsc: &petsc::Petsc,
    scene: &Scene,
    source: &Source,
    dir: &Path,
    memory: (Option<u64>, Option<&'static str>),
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DriverError> {
    let mut silent = problem::Silent;
    let reporter: &mut dyn Reporter = if petsc.rank() == 0 { reporter } else { &mut silent };
    let (memory_bytes, memory_limit) = agreed_limits(petsc, memory)?;
    writable_output(petsc, dir)?;
    let limits = problem::Limits {
        memory_bytes,
        memory_limit,
        ..Default::default()
    };
    let mesh = match route(scene, source, petsc.size(), memory_bytes)? {
        Route::Pieces(from) => return pieces::run(scene, source, dir, (petsc, limits), from, reporter),
        Route::Whole(mesh) => mesh,
    };
    // a path's steps written by rank 0 as they come, into a set committed at the end
    let mut writer = match (petsc.rank(), &scene.path) {
        (0, Some(_)) => Some(output::SetWriter::begin(
            dir,
            &output::PathFiles::expected_names(scene),
        )?),
        _ => None,
    };
    let mut files = output::PathFiles::new(scene);
    let mut each = |step: problem::Step<'_>| match writer.as_mut() {
        Some(w) => files.step(&step, w).map_err(|e| problem::ProblemError::NoSolution {
            sought: "a path's step file",
            why: e.to_string(),
        }),
        None => Ok(()),
    };
    let generated = mesh.is_none();
    let solved = distributed::solve_path(scene, mesh, petsc, limits, reporter, &mut each);
    let solved = match solved {
        // MUMPS' own estimate after its analysis (the one before the mesh is a lower one) or its
        // allocation: a generated body's load path (or its force control's search, its slip
        // weakening's fixed point) runs on pieces instead, which factor nothing (the whole
        // mesh's other static runs take the active sets there, in the same run); the set begun
        // is abandoned before any instant was written
        Err(distributed::DistributedError::Petsc(
            petsc::PetscError::MumpsTooLarge { .. } | petsc::PetscError::Mumps { info: -13, .. },
        )) if generated
            && (scene.path.is_some() || distributed::repeats_contact_solves(scene))
            && distributed::pieces_support(scene).is_ok() =>
        {
            drop(writer);
            let from = distributed::PieceMesh::Generated;
            return pieces::run(scene, source, dir, (petsc, limits), from, reporter);
        }
        other => other.map_err(driver_error)?,
    };
    let peaks = petsc.all_gather(peak_memory_bytes())?;
    let Some(mut solution) = solved else {
        return Ok(None);
    };
    solution.report.scene.source = source.label.clone();
    solution.report.memory.peak_bytes = peaks.first().copied().unwrap_or(0);
    if let Some(p) = solution.report.petsc.as_mut() {
        p.peak_bytes_per_rank = peaks;
    }
    match writer {
        Some(mut w) => {
            let outputs = files.finish(&mut solution, &mut w)?;
            w.write_all(outputs)?;
            w.finish()?;
        }
        None => output::write(&solution, dir)?,
    }
    Ok(Some(solution))
}

/// The route of a run: on pieces (no rank holds the whole mesh, [`pieces`]), or with the whole
/// mesh on every rank (the mesh read, where the scene names a file).
enum Route {
    Pieces(distributed::PieceMesh),
    Whole(Option<mesh::Mesh>),
}

/// The route of `scene` on `ranks` ranks (each may take `memory_bytes`). A Gmsh mesh split
/// into as many parts as there are ranks (`mesh_1.msh` .. `mesh_p.msh` beside the `mesh.msh`
/// the scene names) runs on pieces, each rank reading its part (the whole file is not read, and
/// need not exist). Otherwise a 3D body that the pieces solve ([`distributed::pieces_support`])
/// runs on them without contact, or with contact and at least [`distributed::ACTIVE_SETS_FROM`]
/// unknowns (where the whole mesh's route would take the same active sets for speed; below,
/// MUMPS' condensed route is as fast, issue 44's measurements), or, along a load path or with
/// force control or slip weakening (contact solved many times over), where MUMPS'
/// factorisation would not fit (the whole mesh's route walks a path on one factorisation,
/// the faster while it fits: `paper-3d` n = 20, 7 instants, 14 s by the default backend against
/// 61 s on pieces on 2 ranks): a generated box on any count of ranks, a Gmsh mesh read whole on
/// one rank. The rest takes the whole mesh's route.
fn route(scene: &Scene, source: &Source, ranks: usize, memory_bytes: Option<u64>) -> Result<Route, DriverError> {
    let solved = distributed::pieces_support(scene).is_ok();
    let file = match (scene.mesh.kind, &scene.mesh.file) {
        (MeshKind::Gmsh, Some(file)) => Some(source.dir.join(file)),
        _ => None,
    };
    let parts = file.as_deref().map(mesh::parts_of).unwrap_or_default();
    if solved && ranks > 1 && parts.len() == ranks {
        return Ok(Route::Pieces(distributed::PieceMesh::Parts(parts)));
    }
    let mesh = match &file {
        Some(path) => Some(mesh::read_msh(path).map_err(files::Error::from)?),
        None => None,
    };
    let unknowns = match &mesh {
        Some(m) => (m.n_nodes() * (m.dim + 1)) as f64,
        None => problem::backend::generated_sizes(scene).map_or(0.0, |(_, _, _, n)| n),
    };
    let dim = mesh.as_ref().map_or(scene.mesh.lo.len(), |m| m.dim);
    // (a path, force control's search and slip weakening's fixed point solve the contact many
    // times: MUMPS' route, which factors once, is the faster where it fits)
    let large = match scene.path.is_some() || distributed::repeats_contact_solves(scene) {
        true => distributed::direct_exceeds(scene, mesh.as_ref(), ranks, memory_bytes),
        false => scene.zones().is_empty() || unknowns >= distributed::ACTIVE_SETS_FROM,
    };
    Ok(match (mesh, solved && dim == 3 && large) {
        (None, true) => Route::Pieces(distributed::PieceMesh::Generated),
        (Some(m), true) if ranks == 1 => Route::Pieces(distributed::PieceMesh::Whole(m)),
        (mesh, _) => Route::Whole(mesh),
    })
}

/// A distributed error as the driver's.
fn driver_error(e: distributed::DistributedError) -> DriverError {
    match e {
        distributed::DistributedError::Problem(p) => DriverError::from(p),
        distributed::DistributedError::Petsc(p) => DriverError::Petsc(p),
        distributed::DistributedError::Contact(c) => DriverError::ActiveSet(c),
        other => DriverError::Distributed(other),
    }
}

/// Whether rank 0, which writes the outputs, can write them into `dir`, asked before the run
/// ([`output::check_target`]) and agreed: every rank stops where it cannot (rank 0 with the
/// reason), none goes on alone into the run's collective steps.
fn writable_output(petsc: &petsc::Petsc, dir: &Path) -> Result<(), DriverError> {
    let mine = if petsc.rank() == 0 {
        output::check_target(dir).err()
    } else {
        None
    };
    let refused = petsc.all_gather(u64::from(mine.is_some()))?;
    match (mine, refused.first()) {
        (Some(e), _) => Err(e.into()),
        (None, Some(1)) => Err(DriverError::Usage(format!(
            "rank 0 cannot write the outputs into {} (its message says why)",
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// The least of the ranks' memory limits, on every rank: each rank reads its own (the machine's
/// memory at its own moment, its own `ulimit`), and a run that one rank refused by its estimate
/// while the others went on would leave them waiting in their next collective call. The limit's
/// name is this rank's where its own is the least, else another rank's.
fn agreed_limits(
    petsc: &petsc::Petsc,
    (bytes, limit): (Option<u64>, Option<&'static str>),
) -> Result<(Option<u64>, Option<&'static str>), DriverError> {
    let least = petsc
        .all_gather(bytes.unwrap_or(u64::MAX))?
        .into_iter()
        .min()
        .unwrap_or(u64::MAX);
    Ok(match (least, bytes) {
        (u64::MAX, _) => (None, None),
        (least, Some(mine)) if mine == least => (Some(least), limit),
        (least, _) => (
            Some(least),
            Some("the memory limit of another rank (the least of the ranks')"),
        ),
    })
}
