//! The projections onto the multiplier sets, each written once and used everywhere.

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
    let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm > radius {
        let s = radius / norm;
        x.iter_mut().for_each(|v| *v *= s);
    }
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
    }
}
