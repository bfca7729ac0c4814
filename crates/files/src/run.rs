//! The run of one scene by the application: the Gmsh mesh read where the scene has one (the
//! problem library does no IO), the problem solved, the report completed with what only the
//! application knows (where the scene came from, the process's peak memory), and the outputs
//! of the plan written as one set.

use crate::output;
use crate::scene_file::Source;
use crate::Error;
use problem::{MeshKind, Reporter, Scene, Solution};
use std::path::Path;

/// Bytes of peak resident memory of this process (VmHWM), 0 where unknown.
pub fn peak_memory_bytes() -> u64 {
    crate::memory::peak_bytes()
}

/// The memory limits of a run in this process as one of `ranks` processes of one machine:
/// what [`crate::memory::available_to_one_of`] finds (the machine's memory shared, a
/// process's own limits its own).
pub fn memory_limits(ranks: u64) -> (Option<u64>, Option<&'static str>) {
    match crate::memory::available_to_one_of(ranks) {
        Some(a) => (Some(a.bytes), Some(a.limit)),
        None => (None, None),
    }
}

/// The mesh of `scene`: its Gmsh file read (relative to the scene's `source`), or the one
/// `given` (a `given` scene's), or none (a generated mesh, made by the problem).
pub fn mesh_of(scene: &Scene, source: &Source, given: Option<mesh::Mesh>) -> Result<Option<mesh::Mesh>, Error> {
    Ok(match (scene.mesh.kind, &scene.mesh.file, given) {
        (MeshKind::Gmsh, Some(file), None) => Some(mesh::read_msh(source.dir.join(file))?),
        (_, _, given) => given,
    })
}

/// The limits of one run in this process: the memory available, and `interrupt`.
fn limits(interrupt: contact::Interrupt) -> problem::Limits {
    let (memory_bytes, memory_limit) = memory_limits(1);
    problem::Limits {
        memory_bytes,
        memory_limit,
        interrupt,
    }
}

/// The capacitance matrix between the terminals of `scene` (from `source`: its Gmsh file
/// read; `given` the mesh of a `given` scene), [`problem::capacitance`].
///
/// # Errors
/// [`Error::Mesh`] for a Gmsh file that does not read, [`Error::Problem`] for the problem's.
pub fn capacitance(scene: &Scene, source: &Source, given: Option<mesh::Mesh>) -> Result<problem::Capacitance, Error> {
    Ok(problem::capacitance(scene, mesh_of(scene, source, given)?)?)
}

/// Solves `scene` (from `source`) within the memory this machine has available, reporting to
/// `reporter`; writes nothing.
///
/// # Errors
/// [`Error::Mesh`] for a Gmsh file that does not read, [`Error::Problem`] for the
/// run's own errors.
pub fn solve(scene: &Scene, source: &Source, reporter: &mut dyn Reporter) -> Result<Solution, Error> {
    solve_with(scene, source, None, contact::Interrupt::NONE, reporter)
}

/// As [`solve`], with the mesh of a `given` scene (`mesh.kind = "given"`), and stopped by
/// `interrupt` between steps or within the contact solve (a
/// [`problem::ProblemError::is_interrupted`] error).
///
/// # Errors
/// As [`solve`].
pub fn solve_with(
    scene: &Scene,
    source: &Source,
    given: Option<mesh::Mesh>,
    interrupt: contact::Interrupt,
    reporter: &mut dyn Reporter,
) -> Result<Solution, Error> {
    let mesh = mesh_of(scene, source, given)?;
    let limits = limits(interrupt);
    let mut solution = problem::solve_within(scene, mesh, limits, reporter)?;
    solution.report.scene.source = source.label.clone();
    solution.report.memory.peak_bytes = peak_memory_bytes();
    Ok(solution)
}

/// Solves a scene with a `[path]` (the quasi-static process), as [`solve_with`] does one
/// instant, calling `each` with every instant in order, with its fields where `with_fields`
/// (every `path.output_every`-th instant: to write its files, a step's fields dropped once it
/// returns); the last instant is returned, its report with the path's rows.
///
/// # Errors
/// As [`solve`], and the error `each` returns.
pub fn solve_path_with(
    scene: &Scene,
    source: &Source,
    given: Option<mesh::Mesh>,
    (interrupt, with_fields): (contact::Interrupt, bool),
    reporter: &mut dyn Reporter,
    each: &mut dyn FnMut(problem::Step<'_>) -> Result<(), Error>,
) -> Result<Solution, Error> {
    let mesh = mesh_of(scene, source, given)?;
    let limits = limits(interrupt);
    // the caller's error, carried past the problem's
    let mut failed = None;
    let solved = problem::solve_path(scene, mesh, limits, reporter, with_fields, &mut |step| {
        each(step).map_err(|e| {
            let message = e.to_string();
            failed = Some(e);
            problem::ProblemError::Stopped(message)
        })
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let mut solution = solved?.last;
    solution.report.scene.source = source.label.clone();
    solution.report.memory.peak_bytes = peak_memory_bytes();
    Ok(solution)
}

/// Solves a scene with a `[path]` and writes its set into `dir` as it goes: each instant's
/// `step-NNNN.vtu` written and dropped (not held), then the last instant's files, `path.csv`,
/// `path.pvd` and the path's pictures, the set turned to as a whole at the end (nothing on
/// error).
///
/// # Errors
/// As [`run`].
pub fn run_path(scene: &Scene, source: &Source, dir: &Path, reporter: &mut dyn Reporter) -> Result<Solution, Error> {
    let mut writer = output::SetWriter::begin(dir, &output::PathFiles::expected_names(scene))?;
    let mut files = output::PathFiles::new(scene);
    let mut solution = solve_path_with(
        scene,
        source,
        None,
        (contact::Interrupt::NONE, true),
        reporter,
        &mut |step| files.step(&step, &mut writer),
    )?;
    let outputs = files.finish(&mut solution, &mut writer)?;
    writer.write_all(outputs)?;
    writer.finish()?;
    Ok(solution)
}

/// As [`solve`], then writes the plan's outputs into `dir` (as one set; nothing on error).
///
/// # Errors
/// As [`solve`], and [`Error::Output`] or [`Error::Picture`] for the files.
pub fn run(scene: &Scene, source: &Source, dir: &Path, reporter: &mut dyn Reporter) -> Result<Solution, Error> {
    if scene.path.is_some() {
        return run_path(scene, source, dir, reporter);
    }
    output::check_target(dir)?;
    let solution = solve(scene, source, reporter)?;
    output::write(&solution, dir)?;
    Ok(solution)
}
