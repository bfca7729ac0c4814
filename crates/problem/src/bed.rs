//! A body that only its compliant bed holds.
//!
//! Every solve needs the stiffness `K` invertible, and a compliant bed holds a body only where
//! it presses: a block on rollers whose vertical translation nothing prescribes is held by the
//! bed it rests on, but `K` alone is singular. The run holds such a body with springs
//! `S = Σ_i k_s w_i n_i n_iᵀ` along the bed's normal at its points, assembled into `K`
//! ([`ContactBoundary::normal_springs`]), and takes them out again by a fixed point on the
//! loads (a proximal-point iteration in the springs' norm):
//!
//! `(K + S) u_{j+1} + contact(u_{j+1}) = b + S u_j`,
//!
//! whose fixed point solves `K u + contact(u) = b`. In a motion the bed holds the error falls
//! by `k_s / (k_s + t)` per step, `t` the bed's tangent stiffness where it presses; where the
//! bed lets a point go, by `k_s / (k_s + c / h)`, `c / h` the body's own stiffness there. The
//! springs are taken at [`SPRING_FRACTION`] of the smaller of the two (the tangent at the mean
//! pressure the loads put on the bed, the largest elastic constant over the bed's median
//! spacing), so each step gains two digits or more, at the price of two decades of `K`'s
//! conditioning in the motions the bed holds. Each step is a contact solve of the backend, the
//! springs' forces among its loads (an instant of the run's walk); the run stops where a step changes the springs' forces by less than
//! [`SETTLED`] of the loads, or where the change stops falling (its round-off floor) below
//! half the equilibrium residual a run must reach; the change is added to the residual the
//! run reports.
//!
//! A body that the bed holds nowhere (the loads lift it off) has no solution: a typed
//! [`ProblemError::NoSolution`], as has a fixed point that does not settle.

use crate::backend::{Bed, Posed};
use crate::boundary::ContactBoundary;
use crate::ProblemError;
use contact::{ContactSolution, Foundation, PointValues};

/// The springs' stiffness as a fraction of the bed's tangent stiffness at the loads' mean
/// pressure: the fixed point's error falls by about this much per step where the bed presses
/// everywhere (less where it presses part of the bed).
pub const SPRING_FRACTION: f64 = 1e-2;

/// The fixed point stops where a step changes the springs' forces by less than this fraction
/// of the loads: a thousandth of the equilibrium residual a run must reach
/// ([`crate::EQUILIBRIUM_TOL`]), which the change adds to.
pub const SETTLED: f64 = 1e-11;

/// At most this many steps of the fixed point.
pub const MAX_STEPS: usize = 60;

/// Adds a force-controlled indenter's force to the `resultant` of the loads (and to their
/// `size`): each of its points' share along the point's inward normal. Whether there is one.
fn indenter_presses(posed: &Posed<'_>, boundary: &ContactBoundary, resultant: &mut [f64; 3], size: &mut f64) -> bool {
    let Some(control) = crate::outer::ForceControl::of(posed.scene.scene(), boundary) else {
        return false;
    };
    let points = &boundary.points;
    let driven: Vec<usize> = (0..points.len())
        .filter(|&i| control.driven.as_ref().is_none_or(|d| d[i]))
        .collect();
    let area: f64 = driven.iter().map(|&i| points.weight[i]).sum();
    for &i in &driven {
        for (r, n) in resultant.iter_mut().zip(points.normal[i]) {
            *r -= control.force * points.weight[i] / area * n;
        }
    }
    *size += control.force;
    true
}

/// No solution where nothing the run knows of beforehand presses the body onto its bed: the
/// loads (and a force-controlled indenter's force) float it or lift it off. Where another zone
/// presses on a rigid obstacle (an indenter at a depth, a rigid foundation), its force is found
/// only by the solve, and the springs that hold the body are sized by a force known before it:
/// the message says so, and what to give instead.
fn not_pressed(posed: &Posed<'_>, boundary: &ContactBoundary, force: f64, size: f64, pressed: bool) -> ProblemError {
    let rigid: Vec<&str> = boundary
        .groups
        .iter()
        .enumerate()
        .filter(|&(k, _)| {
            (0..boundary.points.len())
                .any(|i| boundary.group_of[i] == k && boundary.points.foundation_of(i) == Foundation::Rigid)
        })
        .map(|(_, g)| g.as_str())
        .collect();
    let what = if pressed {
        "the loads and the indenter's force"
    } else {
        "the loads"
    };
    let mut why = format!(
        "only the compliant bed holds the body, and {what} do not press it onto the bed (their resultant along the bed's normal is {force:.3e}, of loads of size {size:.3e})"
    );
    match (rigid.is_empty(), posed.scene.scene().indenter_contact()) {
        (true, _) => why.push_str(": the body floats or lifts off"),
        (false, Some((_, c))) if c.indenter.as_ref().is_some_and(|i| i.force.is_none()) => why.push_str(&format!(
            ": the indenter at a depth on `{}` presses it, with a force only the solve finds, and the springs that hold the body in the meantime are sized by a force known before it: press with a force (contact.indenter.force), add a load, or hold the body by a Dirichlet condition",
            c.group
        )),
        (false, _) => why.push_str(&format!(
            ": the rigid zone{} `{}` may press it, with a force only the solve finds, and the springs that hold the body in the meantime are sized by a force known before it: add a load that presses it onto the bed, or hold the body by a Dirichlet condition",
            if rigid.len() > 1 { "s" } else { "" },
            rigid.join("`, `")
        )),
    }
    ProblemError::NoSolution {
        sought: "contact.compliance",
        why,
    }
}

impl Bed {
    /// The springs a run needs: `None` where the Dirichlet conditions hold the body (or there
    /// is no compliant bed), the springs where only the bed holds some rigid motion.
    ///
    /// # Errors
    /// [`fe_assembly::Unheld`] (as an assembly error) naming the motions that the conditions
    /// and the bed together leave free; [`ProblemError::NoSolution`] where the loads press
    /// nothing onto the bed.
    pub(crate) fn needed(posed: &Posed<'_>, boundary: Option<&ContactBoundary>) -> Result<Option<Bed>, ProblemError> {
        let compliant =
            |b: &ContactBoundary, i: usize| matches!(b.points.foundation_of(i), Foundation::Compliant { .. });
        let supports: Vec<fe_assembly::Support> = match boundary {
            Some(b) => b
                .supports()
                .into_iter()
                .enumerate()
                .filter(|(i, _)| compliant(b, *i))
                .map(|(_, s)| s)
                .collect(),
            None => vec![],
        };
        let held = posed
            .disc
            .check_held_with(&supports)
            .map_err(fe_assembly::AssemblyError::from)?;
        let (fe_assembly::Held::WithSupports, Some(boundary)) = (held, boundary) else {
            return Ok(None);
        };
        // the compliant points' area and their zones' laws (each zone its own bed)
        let points = &boundary.points;
        let beds: Vec<usize> = (0..points.len()).filter(|&i| compliant(boundary, i)).collect();
        let mut laws: Vec<(f64, f64)> = vec![];
        for &i in &beds {
            if let Foundation::Compliant { stiffness, exponent } = points.foundation_of(i) {
                if !laws.contains(&(stiffness, exponent)) {
                    laws.push((stiffness, exponent));
                }
            }
        }
        // the mean pressure the loads put on the bed: their resultant along the bed's mean
        // normal over its area; a resultant that does not press the body onto the bed leaves it
        // nothing to hold it by (it floats, or lifts off)
        let area: f64 = beds.iter().map(|&i| points.weight[i]).sum();
        let b = &posed.loads.b_u;
        let dim = posed.disc.dofs.dim;
        let mut resultant = [0.0f64; 3];
        for (v, d) in posed.disc.dofs.u.iter().enumerate() {
            if let fe_assembly::Dof::Free(j) = d {
                resultant[v % dim] += b[*j];
            }
        }
        let mut normal = [0.0f64; 3];
        for &i in &beds {
            for (m, n) in normal.iter_mut().zip(points.normal[i]) {
                *m += points.weight[i] * n;
            }
        }
        let mut size: f64 = b.iter().map(|x| x.abs()).sum();
        let pressed = indenter_presses(posed, boundary, &mut resultant, &mut size);
        let length = normal.iter().map(|n| n * n).sum::<f64>().sqrt();
        let force: f64 = resultant.iter().zip(&normal).map(|(f, n)| f * n).sum::<f64>() / length;
        let pressure = force / area;
        if !(force > 1e-12 * size && pressure.is_finite()) {
            return Err(not_pressed(posed, boundary, force, size, pressed));
        }
        // k [p]^m at the pressure P: p = (P / k)^(1/m), tangent k m p^(m-1); the softest bed's
        let tangent = laws
            .iter()
            .map(|&(stiffness, exponent)| {
                let penetration = (pressure / stiffness).powf(1.0 / exponent);
                stiffness * exponent * penetration.powf(exponent - 1.0)
            })
            .fold(f64::INFINITY, f64::min);
        // no stiffer than a fraction of the body's own stiffness at the bed, c / h: where the
        // bed lets a point go, the spring alone holds it, and the fixed point's error there
        // falls by k_s / (k_s + c / h)
        let c = posed
            .setup
            .materials
            .iter()
            .flat_map(|(_, m)| (0..m.c.len().isqrt()).map(|k| m.c[k * m.c.len().isqrt() + k]))
            .fold(0.0f64, f64::max);
        let mut weights: Vec<f64> = beds.iter().map(|&i| points.weight[i]).collect();
        weights.sort_by(f64::total_cmp);
        let h = weights[weights.len() / 2].powf(1.0 / (dim as f64 - 1.0));
        let body = c / h;
        let springs = SPRING_FRACTION * tangent.min(body);
        if !(springs > 0.0 && springs.is_finite()) {
            return Err(ProblemError::NoSolution {
                sought: "contact.compliance",
                why: format!(
                    "the bed's tangent stiffness at the loads' mean pressure {pressure:.3e} is {tangent:.3e}: no spring of finite positive stiffness holds the body in its place"
                ),
            });
        }
        Ok(Some(Bed {
            stiffness: springs,
            tangent,
            body,
        }))
    }

    /// Why a run of a body only this bed holds is ill-conditioned, in words: a bed far softer
    /// than the body sinks it by many times its own deformation, whose digits the
    /// displacement's rigid part takes.
    pub fn conditioning_in_words(&self) -> String {
        format!(
            "only its compliant bed holds the body, and the bed's tangent stiffness {:.3e} is {:.1e} of the body's own at the bed (c / h = {:.3e}): the body sinks about {:.0e} times as far as it deforms, and its rigid motion takes the digits of its deformation (hold that motion with a Dirichlet condition, or stiffen the bed)",
            self.tangent,
            self.tangent / self.body,
            self.body,
            self.body / self.tangent
        )
    }
}

/// The springs' multipliers at the solution `sol` (a spring's force is a multiplier
/// `-k_s (u_n - u_n,prescribed)` at its point: [`ContactBoundary::spring_multipliers`]), and
/// their forces' change from `current`, relative to `scale` (the loads') or the contact
/// forces, the larger.
///
/// # Errors
/// [`ProblemError::NoSolution`] where the body moved off its bed (no point pressed).
pub(crate) fn settle(
    boundary: &ContactBoundary,
    bed: Bed,
    sol: &ContactSolution,
    current: &PointValues,
    scale: f64,
) -> Result<(PointValues, f64), ProblemError> {
    let next = boundary.spring_multipliers(bed.stiffness, &sol.u.normal, current.n_tangential());
    let mut step = next.clone();
    for (d, c) in step.normal.iter_mut().zip(&current.normal) {
        *d -= c;
    }
    let moved = linalg::norm(&boundary.forces(&step));
    if moved > 0.0 && !sol.lambda.normal.iter().any(|&l| l > 0.0) {
        let why =
            "the loads lift the body off its compliant bed (no point presses on it), and only the bed holds it".into();
        return Err(ProblemError::NoSolution {
            sought: "contact.compliance",
            why,
        });
    }
    let scale = scale.max(linalg::norm(&boundary.forces(&sol.lambda)));
    Ok((next, if moved == 0.0 { 0.0 } else { moved / scale }))
}

/// Whether the fixed point has settled at a step that changed the springs' forces by
/// `change` (`last` the step before's): below [`SETTLED`], or no longer falling (its round-off
/// floor) below half the equilibrium residual a run must reach.
pub(crate) fn settled(change: f64, last: f64) -> bool {
    change <= SETTLED || (change <= 0.5 * crate::EQUILIBRIUM_TOL && change > 0.5 * last)
}

/// The fixed point that did not settle in [`MAX_STEPS`], its last change `change`.
pub(crate) fn unsettled(change: f64) -> ProblemError {
    ProblemError::NoSolution {
        sought: "contact.compliance",
        why: format!(
            "the fixed point on the springs that hold the body in its bed's place did not settle in {MAX_STEPS} steps (last change {change:.1e} of the loads, {SETTLED:.0e} sought)"
        ),
    }
}
