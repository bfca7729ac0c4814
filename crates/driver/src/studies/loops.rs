//! The friction loop of `mindlin-sphere-cycle` against Mindlin and Deresiewicz's closed form:
//! the energy one cycle dissipates, at a mesh size and a number of steps (docs/theory.md,
//! "Load paths"; `cargo run --release -p driver --example sphere_loop`).

use crate::DriverError;
use files::scene_file;
use problem::{Limits, Silent};

/// One cycle's figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopFigures {
    /// The loop's area: the trapezoidal integral of the tangential force along the drive (x)
    /// over the prescribed displacement, from t = 1 to 3.
    pub area: f64,
    /// Mindlin and Deresiewicz's dissipation at the computed `P` and `Q*` (Hertz's `a` of `P`).
    pub closed_form: f64,
    /// The mean normal force over the cycle.
    pub normal_force: f64,
    /// The tangential force's amplitude `Q*`, half its range between the turns.
    pub amplitude: f64,
    /// The tangential force along the drive at the first instant, the normal load on and no
    /// tangential displacement: 0 in the theory (Dundurs' `β = 0`), the coupling of normal and
    /// tangential loading in the finite body.
    pub offset: f64,
}

/// The loop of `mindlin-sphere-cycle` at `mesh.n = n`, with `steps` path steps over its three
/// legs where given (the scene's 24 otherwise).
///
/// # Errors
/// The scene's or the run's error.
pub fn sphere_loop(n: usize, steps: Option<usize>) -> Result<LoopFigures, DriverError> {
    sphere_loop_of_order(n, steps, 1)
}

/// [`sphere_loop`] with elements of `order` (`mesh.order`: 1 or 2).
///
/// # Errors
/// The scene's or the run's error.
pub fn sphere_loop_of_order(n: usize, steps: Option<usize>, order: usize) -> Result<LoopFigures, DriverError> {
    let mut sets = vec![format!("mesh.n={n}"), format!("mesh.order={order}")];
    sets.extend(steps.map(|s| format!("path.steps={s}")));
    sphere_loop_with(&sets)
}

/// The loop of `mindlin-sphere-cycle` with the overrides `sets` (`--set`'s `KEY=VALUE`: a mesh
/// of one's own, `mesh.kind="gmsh"` and its `mesh.file`, refined towards the contact).
///
/// # Errors
/// The scene's or the run's error.
pub fn sphere_loop_with(sets: &[String]) -> Result<LoopFigures, DriverError> {
    let (scene, source) = scene_file::load("mindlin-sphere-cycle", sets)?;
    let mesh = files::run::mesh_of(&scene, &source, None)?;
    let m = &scene.material[0];
    let missing = || DriverError::Usage("mindlin-sphere-cycle lost its isotropic material or its drive".into());
    let (young, poisson) = (m.young.ok_or_else(missing)?, m.poisson.ok_or_else(missing)?);
    let c = scene.first_contact().cloned().ok_or_else(missing)?;
    let drive = scene.dirichlet.first().and_then(|d| d.u.as_ref()).ok_or_else(missing)?[0];
    let p = problem::solve_path(&scene, mesh, Limits::default(), &mut Silent, false, &mut |_| Ok(()))
        .map_err(files::Error::from)?;
    let rows = p.last.report.path.ok_or_else(missing)?.rows;
    let cycle: Vec<_> = rows.iter().filter(|r| r.t >= 1.0 - 1e-9).collect();
    let q = |r: &problem::report::StepRow| r.tangential_resultant[0];
    let area: f64 = cycle
        .windows(2)
        .map(|w| 0.5 * (q(w[0]) + q(w[1])) * (w[1].factors[2] - w[0].factors[2]) * drive)
        .sum();
    let normal_force = cycle.iter().map(|r| r.normal_force).sum::<f64>() / cycle.len() as f64;
    let turn = cycle
        .iter()
        .position(|r| (r.t - 2.0).abs() < 1e-9)
        .ok_or_else(missing)?;
    let amplitude = 0.5 * (q(cycle[0]) - q(cycle[turn]));
    let offset = rows.first().map_or(0.0, q);
    let a = problem::hertz_sphere(normal_force, 1.0 / c.gap_curvature, young, poisson);
    let closed_form =
        problem::mindlin_deresiewicz_dissipation(normal_force, amplitude, c.friction(), a, young, poisson);
    Ok(LoopFigures {
        area,
        closed_form,
        normal_force,
        amplitude,
        offset,
    })
}
