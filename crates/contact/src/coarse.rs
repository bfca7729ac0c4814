//! Nested iteration for Newton's start: the contact problem on a coarser set of its own points,
//! solved first (by the same method, recursively), its multipliers interpolated to every point.
//!
//! Semismooth Newton moves the boundary between the stick, slip and separated zones by a few
//! points per step, so that from zero multipliers its step count grows with the number of
//! points across a zone (measured on the condensed finite-element problems: 4, 4, 6, 7, 8 steps
//! on `paper-slip` at n = 16 ... 256; 5 ... 9 on `paper-compliance`). Started from the answer of
//! a problem with half the points per direction, the zones are already where they belong to
//! within a coarse spacing, and the fine problem needs the few steps that place them to its own
//! spacing: the step count no longer grows with the points (nested iteration, the classical
//! remedy of Newton-type methods on discretised problems: Hackbusch, *Multi-Grid Methods and
//! Applications*, 1985, ch. 5; for the primal-dual active set method on obstacle problems,
//! Hintermüller, Ito and Kunisch, SIAM J. Optim. 13 (2003) 865).
//!
//! The coarser problem is made from the points alone, with no mesh. The chosen points are a
//! maximal independent set at 1.5 nearest-neighbour spacings (every other point along a line,
//! about one in four on a surface grid). The multipliers of every point are interpolated from
//! the chosen ones, `λ = P λ_c` (`P`: the inverse-distance mean of the nearest chosen points,
//! two on a line and four on a surface, which is the linear interpolant between neighbours on a
//! uniform line; a chosen point takes its own value), and the coarse problem is the Galerkin
//! one on those tractions: with `W_c = diag(Pᵀ W 1)` the coarse weights (the same total),
//! the coarse displacements are the weighted means `u_c = W_c⁻¹ Pᵀ W u`, so that
//!
//! ```text
//! u_c = u₀,c - D_c W_c λ_c,   D_c = W_c⁻¹ Pᵀ W D W P W_c⁻¹   (symmetric, as D),
//! ```
//!
//! with the gaps, friction coefficients and Tresca bounds averaged the same way. (Forces
//! gathered on the chosen points instead, `D_c = D` at the chosen rows, are point loads on the
//! fine mesh, whose local compliance is larger than the distributed traction's: measured, the
//! stick zone of `paper-slip` then came out 8 points off at n = 256, 11 at n = 512.)

use crate::operator::{Compliance, DenseContactProblem};
use crate::points::{ContactPoints, PointValues};
use crate::solution::Law;
use rayon::prelude::*;

/// Points below which no coarser problem is made: its solve would cost as much as the steps it
/// saves.
pub(crate) const MIN_POINTS: usize = 48;

/// Squared distance, in nearest-neighbour spacings, within which a chosen point excludes
/// another from the coarser set.
const REACH2: f64 = 1.5 * 1.5;

/// A coarser set of points and the interpolation from it.
pub(crate) struct Coarsening {
    /// The chosen points, increasing.
    chosen: Vec<usize>,
    /// For each point, its interpolation weights: `(index in chosen, weight)`, summing to 1.
    interpolation: Vec<Vec<(usize, f64)>>,
    /// The coarse weights `Pᵀ W 1`.
    weight: Vec<f64>,
}

/// `|a - b|²`.
fn distance2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum()
}

/// The coarser set of `points`, or `None` where it would not be one: too few points, points
/// that share a position (the contacts of rigid bodies, given without one), or a set that does
/// not shrink by a quarter.
pub(crate) fn coarsen(points: &ContactPoints) -> Option<Coarsening> {
    let n = points.len();
    if n < MIN_POINTS {
        return None;
    }
    let x = &points.position;
    // each point's nearest-neighbour spacing (squared)
    let spacing: Vec<f64> = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| distance2(&x[i], &x[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    if spacing.iter().any(|&s| !(s > 0.0 && s.is_finite())) {
        return None;
    }
    // a maximal independent set at REACH spacings, in the points' order
    let mut chosen: Vec<usize> = vec![];
    for i in 0..n {
        if chosen
            .iter()
            .all(|&c| distance2(&x[i], &x[c]) > REACH2 * spacing[c].max(spacing[i]))
        {
            chosen.push(i);
        }
    }
    if 4 * chosen.len() > 3 * n {
        return None;
    }
    let k = if points.dim == 2 { 2 } else { 4 }.min(chosen.len());
    let mut near: Vec<(f64, usize)> = Vec::with_capacity(chosen.len());
    let interpolation: Vec<Vec<(usize, f64)>> = (0..n)
        .map(|i| {
            near.clear();
            near.extend(chosen.iter().enumerate().map(|(a, &c)| (distance2(&x[i], &x[c]), a)));
            near.select_nth_unstable_by(k - 1, |p, q| p.0.total_cmp(&q.0));
            let nearest = &near[..k];
            if let Some(&(_, own)) = nearest.iter().find(|p| p.0 == 0.0) {
                return vec![(own, 1.0)];
            }
            let total: f64 = nearest.iter().map(|p| 1.0 / p.0.sqrt()).sum();
            nearest.iter().map(|p| (p.1, 1.0 / p.0.sqrt() / total)).collect()
        })
        .collect();
    let mut weight = vec![0.0; chosen.len()];
    for (i, row) in interpolation.iter().enumerate() {
        for &(a, p) in row {
            weight[a] += p * points.weight[i];
        }
    }
    if weight.iter().any(|&w| !(w > 0.0)) {
        return None;
    }
    Some(Coarsening {
        chosen,
        interpolation,
        weight,
    })
}

impl Coarsening {
    /// The weighted mean `W_c⁻¹ Pᵀ W v` of one value per point.
    fn mean(&self, v: &[f64], points: &ContactPoints) -> Vec<f64> {
        let mut out = vec![0.0; self.chosen.len()];
        for (i, row) in self.interpolation.iter().enumerate() {
            for &(a, p) in row {
                out[a] += p * points.weight[i] * v[i];
            }
        }
        out.iter_mut().zip(&self.weight).for_each(|(o, w)| *o /= w);
        out
    }

    /// The points of the coarser problem: the chosen ones with the coarse weights, their gaps
    /// and friction coefficients the weighted means.
    pub(crate) fn points(&self, points: &ContactPoints) -> ContactPoints {
        let pick = |v: &dyn Fn(usize) -> [f64; 3]| self.chosen.iter().map(|&i| v(i)).collect::<Vec<_>>();
        ContactPoints {
            dim: points.dim,
            position: pick(&|i| points.position[i]),
            normal: pick(&|i| points.normal[i]),
            tangent: self.chosen.iter().map(|&i| points.tangent[i]).collect(),
            weight: self.weight.clone(),
            gap: self.mean(&points.gap, points),
            friction: self.mean(&points.friction, points),
            held: self.chosen.iter().map(|&i| points.held[i]).collect(),
            foundation: points.foundation,
            foundations: if points.foundations.is_empty() {
                vec![]
            } else {
                self.chosen.iter().map(|&i| points.foundation_of(i)).collect()
            },
            slipped: if points.slipped.is_empty() {
                vec![]
            } else {
                self.mean(&points.slipped, points)
            },
            weakening: if points.weakening.is_empty() {
                vec![]
            } else {
                self.chosen.iter().map(|&i| points.weakening_of(i).copied()).collect()
            },
            tresca: if points.tresca.is_empty() {
                vec![]
            } else {
                self.chosen.iter().map(|&i| points.tresca_of(i)).collect()
            },
        }
    }

    /// The law of the coarser problem (Tresca's bounds averaged).
    pub(crate) fn law(&self, law: &Law, points: &ContactPoints) -> Law {
        match law {
            Law::Tresca(bound) => Law::Tresca(self.mean(bound, points)),
            other => other.clone(),
        }
    }

    /// `P` in the flat layout `[normal (n); tangential (n·nt)]`: per fine row, its coarse rows
    /// and weights (a tangential component through the three-dimensional vector, onto the
    /// fine point's own tangents).
    fn flat_interpolation(&self, points: &ContactPoints, nt: usize) -> Vec<Vec<(usize, f64)>> {
        let (n, nc) = (points.len(), self.chosen.len());
        let mut rows: Vec<Vec<(usize, f64)>> = self.interpolation.clone();
        for i in 0..n {
            for j in 0..nt {
                let mut row = vec![];
                for &(a, p) in &self.interpolation[i] {
                    let c = self.chosen[a];
                    for k in 0..nt {
                        let dot: f64 = (0..3).map(|e| points.tangent[c][k][e] * points.tangent[i][j][e]).sum();
                        if dot != 0.0 {
                            row.push((nc + a * nt + k, p * dot));
                        }
                    }
                }
                rows.push(row);
            }
        }
        rows
    }

    /// The coarser problem (the module's Galerkin problem); `None` where `D` is not dense.
    pub(crate) fn problem(
        &self,
        compliance: Compliance<'_>,
        u0: &PointValues,
        points: &ContactPoints,
    ) -> Option<DenseContactProblem> {
        let Compliance::Dense(d) = compliance else {
            return None;
        };
        let (n, nt) = (u0.n_points(), u0.n_tangential());
        let (m, nc) = (n * (1 + nt), self.chosen.len());
        let mc = nc * (1 + nt);
        let p = self.flat_interpolation(points, nt);
        let w = |r: usize| points.weight[if r < n { r } else { (r - n) / nt }];
        let wc = |a: usize| self.weight[if a < nc { a } else { (a - nc) / nt }];
        // T = D W P (m x mc), then D_c = W_c⁻¹ Pᵀ W T W_c⁻¹, both by rows on rayon's pool (`D`
        // is read once, `m²` values). Each task writes its fresh rows before it adds to them: a
        // fresh page read first maps the shared zero page, and the write after it faults again
        // and flushes the page from the other cores' TLBs, an interrupt to each (docs/
        // performance.md, "The zero page": 80 MB on 2 threads, 0.12 s read first, 0.025 s
        // written first)
        let mut t = vec![0.0; m * mc];
        if mc > 0 {
            t.par_chunks_mut(mc).enumerate().for_each(|(r, out)| {
                out.fill(0.0);
                let row = &d[r * m..(r + 1) * m];
                for (c, entries) in p.iter().enumerate() {
                    let v = row[c] * w(c);
                    for &(a, pv) in entries {
                        out[a] += v * pv;
                    }
                }
            });
        }
        // Pᵀ by its rows: the fine rows of each coarse one, in increasing order
        let mut pt: Vec<Vec<(usize, f64)>> = vec![vec![]; mc];
        for (r, entries) in p.iter().enumerate() {
            for &(a, pv) in entries {
                pt[a].push((r, pv));
            }
        }
        let mut dc = vec![0.0; mc * mc];
        if mc > 0 {
            dc.par_chunks_mut(mc).zip(&pt).enumerate().for_each(|(a, (dst, fine))| {
                dst.fill(0.0);
                for &(r, pv) in fine {
                    let s = pv * w(r);
                    dst.iter_mut()
                        .zip(&t[r * mc..(r + 1) * mc])
                        .for_each(|(x, y)| *x += s * y);
                }
                for (b, x) in dst.iter_mut().enumerate() {
                    *x /= wc(a) * wc(b);
                }
            });
        }
        // u₀,c = W_c⁻¹ Pᵀ W u₀
        let flat = u0.to_flat();
        let mut uc = vec![0.0; mc];
        for (r, entries) in p.iter().enumerate() {
            for &(a, pv) in entries {
                uc[a] += pv * w(r) * flat[r];
            }
        }
        uc.iter_mut().enumerate().for_each(|(a, v)| *v /= wc(a));
        let tangential = uc.split_off(nc);
        Some(DenseContactProblem {
            u0: PointValues::from_parts(uc, tangential, nt).ok()?,
            compliance: dc,
            weight: self.weight.clone(),
            nt,
        })
    }

    /// The coarse multipliers interpolated to every point, `λ = P λ_c`.
    pub(crate) fn prolong(&self, coarse: &PointValues, points: &ContactPoints) -> PointValues {
        let (n, nt) = (points.len(), coarse.n_tangential());
        let flat = coarse.to_flat();
        let values: Vec<f64> = self
            .flat_interpolation(points, nt)
            .iter()
            .map(|row| row.iter().map(|&(a, p)| p * flat[a]).sum())
            .collect();
        let mut values = values;
        let tangential = values.split_off(n);
        PointValues::from_parts(values, tangential, nt).unwrap_or_else(|_| PointValues::zeros(n, nt))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` points along a line (`dim = 2`) or on an `n x n` grid (`dim = 3`), spacing `h`.
    fn points(n: usize, dim: usize, h: f64) -> ContactPoints {
        let position: Vec<[f64; 3]> = if dim == 2 {
            (0..n).map(|i| [i as f64 * h, 0.0, 0.0]).collect()
        } else {
            (0..n * n)
                .map(|k| [(k % n) as f64 * h, (k / n) as f64 * h, 0.0])
                .collect()
        };
        let m = position.len();
        ContactPoints {
            dim,
            position,
            normal: vec![[0.0, 0.0, -1.0]; m],
            tangent: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; m],
            weight: vec![h; m],
            gap: (0..m).map(|i| i as f64).collect(),
            friction: vec![0.3; m],
            held: vec![[false; 2]; m],
            foundation: Default::default(),
            foundations: vec![],
            slipped: vec![],
            weakening: vec![],
            tresca: vec![],
        }
    }

    #[test]
    fn a_line_keeps_every_other_point_and_a_grid_one_in_four() {
        let line = coarsen(&points(101, 2, 0.01)).unwrap();
        assert_eq!(line.chosen, (0..101).step_by(2).collect::<Vec<_>>());
        let grid = coarsen(&points(21, 3, 0.5)).unwrap();
        assert_eq!(grid.chosen.len(), 11 * 11);
        // too few points, or points that share a position: no coarser set
        assert!(coarsen(&points(MIN_POINTS - 1, 2, 1.0)).is_none());
        let mut same = points(60, 2, 1.0);
        same.position[7] = same.position[8];
        assert!(coarsen(&same).is_none());
    }

    #[test]
    fn the_interpolation_is_linear_on_a_line_and_keeps_the_weight() {
        let pts = points(101, 2, 0.01);
        let c = coarsen(&pts).unwrap();
        // a linear field of the chosen points is interpolated exactly
        let coarse = PointValues::from_parts(
            c.chosen.iter().map(|&i| 2.0 + 3.0 * pts.position[i][0]).collect(),
            c.chosen.iter().map(|&i| -pts.position[i][0]).collect(),
            1,
        )
        .unwrap();
        let fine = c.prolong(&coarse, &pts);
        for i in 0..101 {
            let x = pts.position[i][0];
            assert!((fine.normal[i] - (2.0 + 3.0 * x)).abs() < 1e-12);
            assert!((fine.tangential[i] + x).abs() < 1e-12);
        }
        let total: f64 = c.weight.iter().sum();
        assert!((total - 101.0 * 0.01).abs() < 1e-12);
        // the gaps' weighted mean: a linear gap stays linear at the interior chosen points
        let coarse_points = c.points(&pts);
        assert!((coarse_points.gap[10] - 20.0).abs() < 1e-9);
    }

    #[test]
    fn the_coarse_compliance_is_the_galerkin_one() {
        // D = the inverse of a chain's stiffness (SPD), three rows per point in 3D
        let pts = points(9, 3, 1.0);
        let (n, nt) = (pts.len(), 2);
        let m = n * (1 + nt);
        let d: Vec<f64> = (0..m * m)
            .map(|k| {
                let (i, j) = (k / m, k % m);
                1.0 / (1.0 + (i as f64 - j as f64).abs()) + if i == j { 1.0 } else { 0.0 }
            })
            .collect();
        let u0 = PointValues::from_parts((0..n).map(|i| i as f64).collect(), vec![0.5; n * nt], nt).unwrap();
        let c = coarsen(&pts).unwrap();
        let coarse = c.problem(Compliance::Dense(&d), &u0, &pts).unwrap();
        let mc = coarse.m();
        // symmetric, and its action is the mean of the fine one under interpolated forces
        for a in 0..mc {
            for b in 0..mc {
                assert!((coarse.compliance[a * mc + b] - coarse.compliance[b * mc + a]).abs() < 1e-12);
            }
        }
        let lc = PointValues::from_parts(
            (0..c.chosen.len()).map(|a| 1.0 + a as f64).collect(),
            (0..c.chosen.len() * nt).map(|a| 0.1 * a as f64).collect(),
            nt,
        )
        .unwrap();
        let l = c.prolong(&lc, &pts);
        let (lf, lcf) = (l.to_flat(), lc.to_flat());
        let w = |r: usize| pts.weight[if r < n { r } else { (r - n) / nt }];
        let fine_u: Vec<f64> = (0..m)
            .map(|r| (0..m).map(|s| d[r * m + s] * w(s) * lf[s]).sum())
            .collect();
        let p = c.flat_interpolation(&pts, nt);
        let wc = |a: usize| {
            c.weight[if a < c.chosen.len() {
                a
            } else {
                (a - c.chosen.len()) / nt
            }]
        };
        let mut mean = vec![0.0; mc];
        for (r, entries) in p.iter().enumerate() {
            for &(a, pv) in entries {
                mean[a] += pv * w(r) * fine_u[r] / wc(a);
            }
        }
        for a in 0..mc {
            let coarse_u: f64 = (0..mc).map(|b| coarse.compliance[a * mc + b] * wc(b) * lcf[b]).sum();
            assert!((coarse_u - mean[a]).abs() < 1e-10 * mean[a].abs().max(1.0), "{a}");
        }
    }
}
