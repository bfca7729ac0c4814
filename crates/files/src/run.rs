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

/// The memory limits of a run in this process: what [`crate::memory::available`] finds,
/// shared among `ranks` processes of one machine.
pub fn memory_limits(ranks: u64) -> (Option<u64>, Option<&'static str>) {
    match crate::memory::available() {
        Some(a) => (Some(a.bytes / ranks.max(1)), Some(a.limit)),
        None => (None, None),
    }
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
    let mesh = match (scene.mesh.kind, &scene.mesh.file, given) {
        (MeshKind::Gmsh, Some(file), None) => Some(mesh::read_msh(source.dir.join(file))?),
        (_, _, given) => given,
    };
    let (memory_bytes, memory_limit) = memory_limits(1);
    let limits = problem::Limits {
        memory_bytes,
        memory_limit,
        interrupt,
    };
    let mut solution = problem::solve_within(scene, mesh, limits, reporter)?;
    solution.report.scene.source = source.label.clone();
    solution.report.memory.peak_bytes = peak_memory_bytes();
    Ok(solution)
}

/// Solves a scene with a `[path]` (the quasi-static process), as [`solve_with`] does one
/// instant, gathering the files of every step ([`output::PathFiles`]); writes nothing.
///
/// # Errors
/// As [`solve`], and [`Error::Picture`] for a step's file.
pub fn solve_path(
    scene: &Scene,
    source: &Source,
    interrupt: contact::Interrupt,
    reporter: &mut dyn Reporter,
) -> Result<(Solution, output::Outputs), Error> {
    let mesh = match (scene.mesh.kind, &scene.mesh.file) {
        (MeshKind::Gmsh, Some(file)) => Some(mesh::read_msh(source.dir.join(file))?),
        _ => None,
    };
    let (memory_bytes, memory_limit) = memory_limits(1);
    let limits = problem::Limits {
        memory_bytes,
        memory_limit,
        interrupt,
    };
    // every plan writes solution.vtu: the series too
    let mut files = output::PathFiles::new(&[problem::Output::SolutionVtu]);
    let mut failed = None;
    let solved = problem::solve_path(scene, mesh, limits, reporter, &mut |step| {
        files.step(&step).map_err(|e| {
            let message = e.to_string();
            failed = Some(e);
            problem::SceneError::new("path", message).into()
        })
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let mut solution = solved?.last;
    solution.report.scene.source = source.label.clone();
    solution.report.memory.peak_bytes = peak_memory_bytes();
    let out = files.finish(&solution)?;
    Ok((solution, out))
}

/// As [`solve`], then writes the plan's outputs into `dir` (as one set; nothing on error).
///
/// # Errors
/// As [`solve`], and [`Error::Output`] or [`Error::Picture`] for the files.
pub fn run(scene: &Scene, source: &Source, dir: &Path, reporter: &mut dyn Reporter) -> Result<Solution, Error> {
    if scene.path.is_some() {
        let (solution, out) = solve_path(scene, source, contact::Interrupt::NONE, reporter)?;
        out.into(dir).commit()?;
        return Ok(solution);
    }
    let solution = solve(scene, source, reporter)?;
    output::write(&solution, dir)?;
    Ok(solution)
}
