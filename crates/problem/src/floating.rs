//! Floating terminals (`dirichlet.charge`): a group whose potential is unknown, one value over
//! the group, with the charge on it given (0: an open circuit, a sensor's electrode).
//!
//! The problem without contact is linear in the terminals' potentials, so the potentials come
//! by superposition: the charges `Q⁰` of the run with every floating terminal grounded, the
//! capacitance matrix `C` between the terminals ([`crate::capacitance`]), and
//! `C_ff V = Q - Q⁰` on the floating ones (`f`); the final run prescribes `V` and is the
//! answer, its charges the given ones (checked).

use crate::backend::Limits;
use crate::run::{run, Solution};
use crate::scene::{Scene, SceneError};
use crate::{Faer, ProblemError, Reporter, Silent};

/// The floating terminals of `scene`: each `(group, charge)`, in the order of its conditions.
pub(crate) fn floating(scene: &Scene) -> Vec<(String, f64)> {
    scene
        .dirichlet
        .iter()
        .filter_map(|d| d.charge.map(|q| (d.group.clone(), q)))
        .collect()
}

/// `scene` with its floating terminals at the potentials `v` (in the order of [`floating`]).
fn at_potentials(scene: &Scene, v: &[f64]) -> Scene {
    let mut out = scene.clone();
    let mut values = v.iter();
    for d in out.dirichlet.iter_mut().filter(|d| d.charge.is_some()) {
        d.phi = values.next().copied();
        d.charge = None;
    }
    out
}

/// Solves a scene with floating terminals (validated by the caller's run: no contact, no path,
/// the default backend): the grounded run, the capacitance matrix, the final run at the
/// potentials that carry the given charges. `reporter` follows the final run.
///
/// # Errors
/// The runs' errors; a floating terminal that shares a node with another terminal (one
/// conductor: key `dirichlet.charge`); floating terminals whose capacitance block is singular
/// (a terminal no field reaches).
pub(crate) fn solve_floating(
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
    limits: Limits,
    reporter: &mut dyn Reporter,
) -> Result<Solution, ProblemError> {
    scene.validate()?;
    let terminals = floating(scene);
    let grounded = at_potentials(scene, &vec![0.0; terminals.len()]);
    let first = run(&mut Faer, &grounded, mesh.clone(), limits, &mut Silent)?
        .expect("the default backend runs in one process, which holds the solution");
    let c = crate::capacitance(&grounded, mesh.clone())?;
    let place = |group: &str| {
        c.terminals.iter().position(|t| t == group).ok_or_else(|| {
            let joined = c.terminals.iter().find(|t| t.split('+').any(|g| g == group));
            SceneError::new(
                "dirichlet.charge",
                format!(
                    "the floating terminal `{group}` shares a node with another terminal ({}): they are one conductor",
                    joined.map_or("?", String::as_str)
                ),
            )
        })
    };
    let index: Vec<usize> = terminals.iter().map(|(g, _)| place(g)).collect::<Result<_, _>>()?;
    // the charge on each floating terminal in the grounded run: the negative of its flux
    let grounded_charge = |group: &str| {
        first
            .report
            .terminals
            .iter()
            .find(|t| t.group == group)
            .map_or(0.0, |t| -t.charge)
    };
    let k = terminals.len();
    let block = nalgebra::DMatrix::from_fn(k, k, |i, j| c.matrix[index[i]][index[j]]);
    let rhs = nalgebra::DVector::from_fn(k, |i, _| terminals[i].1 - grounded_charge(&terminals[i].0));
    let v = block
        .clone()
        .lu()
        .solve(&rhs)
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .ok_or_else(|| {
            SceneError::new(
            "dirichlet.charge",
            "the floating terminals' capacitance is singular: no field reaches one of them (ground another terminal)",
        )
        })?;
    let mut solution = run(&mut Faer, &at_potentials(scene, v.as_slice()), mesh, limits, reporter)?
        .expect("the default backend runs in one process, which holds the solution");
    for t in &mut solution.report.terminals {
        t.floating = terminals.iter().any(|(g, _)| g == &t.group);
    }
    Ok(solution)
}
