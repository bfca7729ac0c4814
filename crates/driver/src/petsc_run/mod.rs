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
    let mesh = match (scene.mesh.kind, &scene.mesh.file) {
        (MeshKind::Gmsh, Some(file)) => Some(mesh::read_msh(source.dir.join(file)).map_err(files::Error::from)?),
        _ => None,
    };
    let mut silent = problem::Silent;
    let reporter: &mut dyn Reporter = if petsc.rank() == 0 { reporter } else { &mut silent };
    // the ranks of one machine share its memory (on several machines this is conservative)
    let (memory_bytes, memory_limit) = agreed_limits(&petsc, memory_limits(petsc.size() as u64))?;
    let limits = problem::Limits {
        memory_bytes,
        memory_limit,
        ..Default::default()
    };
    if on_pieces(scene) {
        return pieces::run(scene, source, dir, (&petsc, limits), reporter);
    }
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
    let solved = distributed::solve_path(scene, mesh, &petsc, limits, reporter, &mut each).map_err(driver_error)?;
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

/// Whether a run takes the route on which no rank holds the whole mesh ([`pieces`]): a 3D
/// generated body that the pieces solve ([`distributed::pieces_support`]), without contact, or
/// with contact and at least [`distributed::ACTIVE_SETS_FROM`] unknowns (where the whole
/// mesh's route would take the same active sets for speed; below, MUMPS' condensed route is
/// as fast, issue 44's measurements).
fn on_pieces(scene: &Scene) -> bool {
    let unknowns = problem::backend::generated_sizes(scene).map_or(0.0, |(_, _, _, n)| n);
    scene.mesh.lo.len() == 3
        && distributed::pieces_support(scene).is_ok()
        && (scene.zones().is_empty() || unknowns >= distributed::ACTIVE_SETS_FROM)
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
