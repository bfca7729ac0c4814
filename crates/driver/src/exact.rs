//! Known solutions a scene can be checked against (the `[exact]` section; SCENES.md section 6):
//! the fields of a manufactured or affine solution, and the contact tractions of Hertz and
//! Cattaneo-Mindlin. A run that has one reports its errors in `run.json` under `exact`, with
//! `error` the headline figure the verification study plots.

use crate::scene::{ExactSpec, Scene};
use crate::DriverError;
use contact::{ContactPoints, ContactSolution, Status};
use fe_assembly::{Discretization, Exact};
use serde_json::{json, Value};
use std::f64::consts::PI;

/// The kinds of exact solution, with what each measures.
pub const KINDS: &[(&str, &str)] = &[
    (
        "manufactured",
        "relative energy-norm error of (u, φ) against the manufactured solution",
    ),
    (
        "affine",
        "relative energy-norm error against the affine solution (a patch test: round-off)",
    ),
    (
        "hertz",
        "relative l2 error of the nodal contact pressure against Hertz's, over |x| ≤ 1.5 a",
    ),
    (
        "cattaneo-mindlin",
        "relative l2 error of the nodal tangential traction against Cattaneo-Mindlin's, over |x| ≤ 1.5 a",
    ),
];

fn dim_of(s: &Scene) -> Option<usize> {
    match s.mesh.kind.as_str() {
        "rectangle" => Some(2),
        "box" => Some(3),
        _ => None,
    }
}

/// The groups where a field solution is prescribed.
pub fn groups(x: &ExactSpec, s: &Scene) -> Vec<String> {
    if !x.groups.is_empty() {
        return x.groups.clone();
    }
    let sides: &[&str] = if dim_of(s) == Some(3) {
        &["left", "right", "bottom", "top", "front", "back"]
    } else {
        &["left", "right", "bottom", "top"]
    };
    sides.iter().map(|g| g.to_string()).collect()
}

/// Checks an `[exact]` section against its scene (called by the scene's validation).
pub fn validate(x: &ExactSpec, s: &Scene) -> Result<(), String> {
    if !KINDS.iter().any(|(k, _)| *k == x.kind) {
        let names: Vec<&str> = KINDS.iter().map(|(k, _)| *k).collect();
        return Err(format!("exact.kind `{}` is unknown ({})", x.kind, names.join(", ")));
    }
    let law = s.contact.as_ref().map_or("none", |c| c.law.as_str());
    match x.kind.as_str() {
        "manufactured" | "affine" => {
            if law != "none" {
                return Err(format!(
                    "exact.kind `{}` is a solution without contact; set contact.law = \"none\"",
                    x.kind
                ));
            }
            if s.material.len() != 1 {
                return Err(format!("exact.kind `{}` needs exactly one [[material]]", x.kind));
            }
            if dim_of(s).is_none() && x.groups.is_empty() {
                return Err(format!(
                    "exact.kind `{}` on a Gmsh mesh needs exact.groups (the boundary groups to prescribe it on)",
                    x.kind
                ));
            }
            // a Gmsh mesh's dimension is known once it is read: checked again there
            if let Some(dim) = dim_of(s) {
                affine_lengths(x, dim)?;
            }
            if let Some(v) = x.u0.iter().chain(&x.grad_u).chain(&x.grad_phi).find(|v| !v.is_finite()) {
                return Err(format!("exact: the value {v} is not finite"));
            }
            if !x.phi0.is_finite() {
                return Err("exact.phi0 is not finite".into());
            }
        }
        _ => {
            if dim_of(s) != Some(2) {
                return Err(format!(
                    "exact.kind `{}` is a plane-strain solution: it needs mesh.kind = \"rectangle\"",
                    x.kind
                ));
            }
            let c = s.contact.as_ref().filter(|c| c.gap_curvature > 0.0).ok_or_else(|| {
                format!(
                    "exact.kind `{}` needs contact with a curved gap (contact.gap_curvature > 0)",
                    x.kind
                )
            })?;
            if x.kind == "hertz" && law != "signorini" {
                return Err("exact.kind `hertz` is frictionless: set contact.law = \"signorini\"".into());
            }
            if x.kind == "cattaneo-mindlin" && !(law == "coulomb" && c.friction > 0.0) {
                return Err(
                    "exact.kind `cattaneo-mindlin` needs contact.law = \"coulomb\" with contact.friction > 0".into(),
                );
            }
            if s.material.len() != 1 || s.material[0].young.is_none() || s.material[0].poisson.is_none() {
                return Err(format!(
                    "exact.kind `{}` needs one isotropic material (young, poisson)",
                    x.kind
                ));
            }
        }
    }
    Ok(())
}

/// Checks the lengths of an `affine` solution's data in dimension `dim` (empty means zero).
fn affine_lengths(x: &ExactSpec, dim: usize) -> Result<(), String> {
    let ok = |v: &[f64], n: usize| v.is_empty() || v.len() == n;
    if x.kind != "affine" || (ok(&x.u0, dim) && ok(&x.grad_u, dim * dim) && ok(&x.grad_phi, dim)) {
        Ok(())
    } else {
        Err(format!(
            "exact (affine) in {dim}D needs u0 of {dim}, grad_u of {} (row-major) and grad_phi of {dim} values",
            dim * dim
        ))
    }
}

/// The field solution of a `manufactured` or `affine` scene in dimension `dim` (the mesh's:
/// a Gmsh mesh's affine data are checked against it here).
pub fn field_solution(s: &Scene, dim: usize) -> Result<Option<Exact>, DriverError> {
    let Some(x) = s.exact.as_ref() else {
        return Ok(None);
    };
    affine_lengths(x, dim).map_err(DriverError::Input)?;
    let pad = |v: &[f64], n: usize| -> Vec<f64> {
        let mut out = vec![0.0; n];
        out[..v.len().min(n)].copy_from_slice(&v[..v.len().min(n)]);
        out
    };
    match x.kind.as_str() {
        "manufactured" => Ok(Some(Exact::manufactured(dim))),
        "affine" => {
            let (u0, g, gp) = (pad(&x.u0, 3), pad(&x.grad_u, dim * dim), pad(&x.grad_phi, 3));
            let mut grad_u = [[0.0; 3]; 3];
            for k in 0..dim {
                for j in 0..dim {
                    grad_u[k][j] = g[k * dim + j];
                }
            }
            Ok(Some(Exact::affine(
                dim,
                [u0[0], u0[1], u0[2]],
                grad_u,
                x.phi0,
                [gp[0], gp[1], gp[2]],
            )))
        }
        _ => Ok(None),
    }
}

/// The `exact` section of run.json: the errors of a field solution.
pub fn field_errors(
    kind: &str,
    disc: &Discretization<'_>,
    u: &[[f64; 3]],
    phi: &[f64],
    exact: &Exact,
    electric: bool,
) -> Value {
    let e = disc.error_norms(u, phi, exact);
    json!({
        "kind": kind,
        "error": e.rel_energy(),
        "error_name": if electric { "relative energy-norm error of (u, φ)" } else { "relative energy-norm error of u" },
        "l2_u": e.l2_u, "l2_phi": e.l2_phi, "energy": e.energy,
        "rel_l2_u": e.rel_l2_u(),
        "rel_l2_phi": if electric { e.rel_l2_phi() } else { 0.0 },
        "rel_energy": e.rel_energy(),
    })
}

/// Hertz's half-width and peak pressure for the load `p` per unit length (Johnson 1985, section
/// 4.2): `a² = 4 P R / (π E*)`, `p0 = 2 P / (π a)`, with `E* = E / (1 - ν²)` against a rigid
/// foundation.
pub fn hertz(p: f64, radius: f64, young: f64, poisson: f64) -> (f64, f64) {
    let e_star = young / (1.0 - poisson * poisson);
    let a = (4.0 * p * radius / (PI * e_star)).sqrt();
    (a, 2.0 * p / (PI * a))
}

/// Cattaneo-Mindlin's tangential traction (Johnson 1985, section 7.1) for the friction
/// coefficient `f`, Hertz's `a` and `p0`, and the stick half-width `c = a √(1 - Q/(F P))`:
/// `q = F p0 √(1 - x²/a²) - F p0 (c/a) √(1 - x²/c²)` (the second term for `|x| < c` only).
pub fn cattaneo_traction(x: f64, f: f64, a: f64, p0: f64, c: f64) -> f64 {
    let slip = f * p0 * (1.0 - x * x / (a * a)).max(0.0).sqrt();
    let stick = if x.abs() < c {
        f * p0 * (c / a) * (1.0 - x * x / (c * c)).sqrt()
    } else {
        0.0
    };
    slip - stick
}

/// Relative discrete l2 error of `values` against `exact(x)` over the points with
/// `|x| ≤ reach`.
fn profile_error(xs: &[f64], values: &[f64], reach: f64, exact: impl Fn(f64) -> f64) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for (&x, &v) in xs.iter().zip(values) {
        if x.abs() <= reach {
            let e = exact(x);
            err += (v - e).powi(2);
            norm += e * e;
        }
    }
    (err / norm).sqrt()
}

/// Half the extent and the centre of the points whose flag is set.
fn extent(xs: &[f64], flag: impl Fn(usize) -> bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, &x) in xs.iter().enumerate() {
        if flag(i) {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if lo > hi {
        (0.0, 0.0)
    } else {
        ((hi - lo) / 2.0, (hi + lo) / 2.0)
    }
}

/// The `exact` section of run.json for a Hertz or Cattaneo-Mindlin scene: the load, Hertz's
/// `a` and `p0`, the measured contact and stick zones, and the profile errors.
pub fn contact_errors(s: &Scene, points: &ContactPoints, sol: &ContactSolution, p: f64, q: f64) -> Option<Value> {
    let x = s.exact.as_ref()?;
    let c = s.contact.as_ref()?;
    let m = s.material.first()?;
    let (young, poisson) = (m.young?, m.poisson?);
    let radius = 1.0 / c.gap_curvature;
    let x0 = c.gap_center.as_ref().and_then(|v| v.first().copied()).unwrap_or(0.0);
    let xs: Vec<f64> = points.position.iter().map(|p| p[0] - x0).collect();
    let (a, p0) = hertz(p, radius, young, poisson);
    let (a_h, centre) = extent(&xs, |i| sol.lambda.normal[i] > 0.0);
    let pressure_error = profile_error(&xs, &sol.lambda.normal, 1.5 * a, |x| {
        p0 * (1.0 - x * x / (a * a)).max(0.0).sqrt()
    });
    let peak = sol.lambda.normal.iter().cloned().fold(0.0, f64::max);
    let mut out = json!({
        "kind": x.kind,
        "load_p": p, "radius": radius, "a": a, "p0": p0,
        "a_h": a_h, "contact_centre": centre,
        "a_error": (a_h - a).abs() / a,
        "peak_error": (peak - p0).abs() / p0,
        "pressure_error": pressure_error,
    });
    if x.kind == "hertz" {
        out["error"] = json!(pressure_error);
        out["error_name"] = json!(KINDS[2].1);
    } else {
        let f = c.friction;
        let cc = a * (1.0 - (q / (f * p)).min(1.0)).sqrt();
        let (c_h, stick_centre) = extent(&xs, |i| sol.status[i] == Status::Stick);
        let nt = sol.lambda.tangential.len() / points.len().max(1);
        let t: Vec<f64> = (0..points.len())
            .map(|i| {
                (0..nt)
                    .map(|k| sol.lambda.tangential[i * nt + k].powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let e = profile_error(&xs, &t, 1.5 * a, |x| cattaneo_traction(x, f, a, p0, cc));
        out["load_q"] = json!(q);
        out["c"] = json!(cc);
        out["c_h"] = json!(c_h);
        out["c_error"] = json!((c_h - cc).abs() / a);
        out["stick_offset"] = json!(stick_centre / a);
        out["error"] = json!(e);
        out["error_name"] = json!(KINDS[3].1);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Johnson's numbers: P = 1, R = 1, E* = 1 gives a = 2/√π and p0 = 1/√π; the
    /// Cattaneo traction integrates to Q.
    #[test]
    fn hertz_and_cattaneo_formulas() {
        let (a, p0) = hertz(1.0, 1.0, 1.0, 0.0);
        assert!((a - 2.0 / PI.sqrt()).abs() < 1e-14);
        assert!((p0 - 1.0 / PI.sqrt()).abs() < 1e-14);
        // ∫ q dx = F P - F P (c/a)² = Q by construction of c
        let (f, q): (f64, f64) = (0.5, 0.3);
        let c = a * (1.0 - q / f).sqrt();
        let n = 200_000;
        let h = 2.0 * a / n as f64;
        let integral: f64 = (0..n)
            .map(|i| cattaneo_traction(-a + (i as f64 + 0.5) * h, f, a, p0, c) * h)
            .sum();
        assert!((integral - q).abs() < 1e-5, "{integral}");
    }
}
