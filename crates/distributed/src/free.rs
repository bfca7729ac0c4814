//! The free unknowns `[u; φ]` of the discretisation as one vector, as MUMPS and the Krylov
//! route's map take them, and back.

use problem::backend::Fields;

/// `[a; b]`.
pub(crate) fn joined(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().chain(b).copied().collect()
}

/// `x` split after its `n_u` displacements.
pub(crate) fn split(mut x: Vec<f64>, n_u: usize) -> Fields {
    let phi = x.split_off(n_u);
    (x, phi)
}

/// `x` copied into `u` and `phi` (of `x`'s length together).
pub(crate) fn copy_into(x: &[f64], u: &mut [f64], phi: &mut [f64]) {
    let (xu, xp) = x.split_at(u.len());
    u.copy_from_slice(xu);
    phi.copy_from_slice(xp);
}
