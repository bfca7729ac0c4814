//! The projections onto the multiplier sets, each written once and used everywhere.

/// The squares' sum of a norm, kept where it can be trusted: far from the ends of the range
/// of `f64`, where it neither overflowed nor lost its digits to underflow.
#[inline]
pub(crate) fn trusted(sum_of_squares: f64) -> bool {
    sum_of_squares > 1e-290 && sum_of_squares < 1e290
}

/// The Euclidean norm of a short vector (a point's tangential components), with no overflow
/// or underflow in the squares, whatever the size of the data.
#[inline]
pub fn norm(x: &[f64]) -> f64 {
    let s: f64 = x.iter().map(|v| v * v).sum();
    if trusted(s) {
        s.sqrt()
    } else if s == 0.0 && x.iter().all(|v| *v == 0.0) {
        0.0
    } else {
        x.iter().fold(0.0, |a, &v| a.hypot(v))
    }
}

/// Projection onto the normal cone `{λ_n ≥ 0}`: a clamp at zero. (NaN maps to 0.)
#[inline]
pub fn project_nonnegative(x: f64) -> f64 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// Projection onto the friction disc `{|λ_t| ≤ radius}` in the tangent plane (an interval in
/// 2D, a disc in 3D): cap the magnitude at `radius`. A non-positive radius maps to 0.
#[inline]
pub fn project_disc(x: &mut [f64], radius: f64) {
    if !(radius > 0.0) {
        x.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    let norm = norm(x);
    if norm > radius {
        let s = radius / norm;
        x.iter_mut().for_each(|v| *v *= s);
    }
}

/// The piece of the friction disc's projection `P_S(q)` (radius `S`, [`project_disc`]) on
/// which `q` lies, with what its value and derivative need there: every semismooth Newton
/// method on the natural map picks a point's tangential branch by it (the condensed Newton's
/// generalised Jacobian, the PETSc backend's active sets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DiscPiece {
    /// `S ≤ 0` (or not a number): `P_S(q) = 0`, derivative 0 (no friction there, or the
    /// point out of contact).
    Zero,
    /// `|q| ≤ S`: `P_S(q) = q`, derivative the identity (stick).
    Inside,
    /// `|q| > S`: `P_S(q) = S d` with `d = q / |q|`, derivative `κ (I - d dᵀ)` in `q` (and
    /// `d` in `S`), `κ = S / |q| < 1` (slip).
    Boundary {
        /// `κ = S / |q|`.
        ratio: f64,
        /// `d = q / |q|` (its first `q.len()` components).
        direction: [f64; 2],
    },
}

/// Which piece of the friction disc's projection of radius `radius` `q` (one or two
/// tangential components) lies on ([`DiscPiece`]).
#[inline]
pub fn disc_piece(q: &[f64], radius: f64) -> DiscPiece {
    if !(radius > 0.0) {
        return DiscPiece::Zero;
    }
    let qn = norm(q);
    if qn <= radius {
        return DiscPiece::Inside;
    }
    let mut direction = [0.0; 2];
    for (d, &x) in direction.iter_mut().zip(q) {
        *d = x / qn;
    }
    DiscPiece::Boundary {
        ratio: radius / qn,
        direction,
    }
}

/// Projection onto Coulomb's cone `K = {(x_n, x_t): |x_t| ≤ μ x_n}` (Siconos' and De Saxcé's
/// convention: `x[0]` the normal component, `x[1..]` the tangential ones): `x` itself inside
/// `K`, `0` in the polar cone `{μ |x_t| ≤ -x_n}`, else the point of the cone's boundary
/// `t (1, μ x_t/|x_t|)` with `t = (x_n + μ |x_t|) / (1 + μ²)`. `μ = 0` gives `(max(x_n, 0), 0)`.
#[inline]
pub fn project_cone(x: &mut [f64], mu: f64) {
    let (xn, xt) = x.split_first_mut().expect("a point has a normal component");
    let nt = norm(xt);
    if nt <= mu * *xn {
        return;
    }
    if mu * nt <= -*xn {
        *xn = 0.0;
        xt.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    let t = (*xn + mu * nt) / (1.0 + mu * mu);
    *xn = t;
    // nt > 0 here: nt = 0 with xn < 0 is in the polar cone, with xn ≥ 0 inside K
    let s = mu * t / nt;
    xt.iter_mut().for_each(|v| *v *= s);
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn examples() {
        assert_eq!(project_nonnegative(-2.0), 0.0);
        assert_eq!(project_nonnegative(3.0), 3.0);
        let mut x = [3.0, 4.0];
        project_disc(&mut x, 1.0);
        assert!((x[0] - 0.6).abs() < 1e-15 && (x[1] - 0.8).abs() < 1e-15);
        let mut y = [0.1];
        project_disc(&mut y, 0.0);
        assert_eq!(y, [0.0]);
        // the cone: inside, polar, and the boundary point of a 3-4-5 triangle
        let mut c = [2.0, 0.3, 0.4];
        project_cone(&mut c, 1.0);
        assert_eq!(c, [2.0, 0.3, 0.4]);
        let mut c = [-2.0, 0.3, 0.4];
        project_cone(&mut c, 1.0);
        assert_eq!(c, [0.0, 0.0, 0.0]);
        let mut c = [0.0, 3.0, 4.0];
        project_cone(&mut c, 1.0);
        assert!((c[0] - 2.5).abs() < 1e-15 && (c[1] - 1.5).abs() < 1e-15 && (c[2] - 2.0).abs() < 1e-15);
        let mut c = [1.0, 3.0];
        project_cone(&mut c, 0.0);
        assert_eq!(c, [1.0, 0.0]);
    }

    /// The pieces agree with the projection: its value `q`, `0` or `S d`, on each.
    #[test]
    fn the_discs_pieces_agree_with_its_projection() {
        for (q, radius) in [
            (vec![3.0, 4.0], 1.0),
            (vec![0.3, 0.4], 1.0),
            (vec![-2.0], 0.5),
            (vec![0.1, 0.2], 0.0),
            (vec![1e-300, 1e-300], 1e-301),
        ] {
            let mut projected = q.clone();
            project_disc(&mut projected, radius);
            let value: Vec<f64> = match disc_piece(&q, radius) {
                DiscPiece::Zero => vec![0.0; q.len()],
                DiscPiece::Inside => q.clone(),
                DiscPiece::Boundary { ratio, direction } => {
                    assert!(ratio < 1.0, "{q:?} {radius}");
                    direction[..q.len()].iter().map(|d| radius * d).collect()
                }
            };
            for (a, b) in value.iter().zip(&projected) {
                assert!(
                    (a - b).abs() <= 1e-15 * b.abs().max(1e-300),
                    "{q:?} {radius}: {value:?} vs {projected:?}"
                );
            }
        }
    }
}
