//! Least-squares placement of one ring's panels (issue 31).
//!
//! The extensions `e` minimise the squared radial gaps between the form's skin over its panels
//! and the mannequin's section, seen from the ring's axis along [`GAP_RAYS`] evenly spread
//! rays,
//!
//! `min Σ_j (r_j(e) - ρ_j)²  subject to  girth(e) = G  and  0 <= e_k <= stroke_k`,
//!
//! `r_j` the skin's distance along ray `j`, `ρ_j` the section's, `G` the section's tape girth,
//! plus how far each panel lies under the skin (weighted as one ray): a panel inside its
//! neighbours' hull changes no ray's gap, and would otherwise drift with the girth's offset
//! instead of carrying the skin.
//! The girth constraint is eliminated: a shape vector `a` gives `e = clamp(a + δ(a))`, `δ(a)`
//! the common offset that makes the girth exact (`Panels::offset_for_girth` in
//! [`super::rings`], by bisection), so every extension the solver tries is feasible, and every
//! feasible `e` is some `a`'s. `a` is improved by Levenberg-Marquardt (damped Gauss-Newton)
//! with a Jacobian by central differences; after each step `a` is set to the extensions it
//! gave, so a clamped actuator sits exactly at its bound, where it still has a one-sided slope
//! (one that does better inside its stroke comes back), and the offset's free direction (any
//! constant added to `a`) never accumulates. Mirror partners on the ring share one variable,
//! so a symmetric section gets a symmetric placement. The start is the common-offset rule's
//! extensions (each panel's centre on the section, all moved out by one offset); the caller
//! keeps them where the solution's skin is not closer.
//!
//! Written by hand: the problem is a handful of variables with a non-smooth constraint that a
//! bisection already solves, and a general optimiser crate would not know to keep the girth.

use glam::DVec2;
use nalgebra::{DMatrix, DVector};

/// Rays along which the gaps are taken: every degree, far finer than the panels (8-10 per
/// ring, 36-45 degrees apart), so a gap between two panels counts as much as one at a panel;
/// a whole degree, so panels at whole-degree angles see their neighbours' rays alike.
pub const GAP_RAYS: usize = 360;

/// Step of the central differences (mm): far above the bisection's resolution (about
/// 1e-15 mm) and far below a panel's width.
const DIFFERENCE_MM: f64 = 0.05;
/// Iterations at most: each costs one residual per variable pair and a few trial steps; on
/// the reference form's rings the extensions settle within a few dozen.
const MAX_ITERATIONS: usize = 40;
/// Stop when no extension moves more than this in a step (mm): a hundredth of the
/// actuators' resolution (0.01 mm, the wire contract's position unit).
const STEP_TOLERANCE_MM: f64 = 1e-4;
/// Levenberg-Marquardt damping (relative to the normal matrix's diagonal): the smallest
/// used, where the problem is nearly linear (Gauss-Newton's step); the factor it moves by
/// after a rejected or accepted step; and the largest tried before the solve stops (a step
/// then shorter than [`STEP_TOLERANCE_MM`]). The usual choices (Nocedal and Wright, ch. 10).
const DAMPING_MIN: f64 = 1e-3;
const DAMPING_FACTOR: f64 = 10.0;
const DAMPING_MAX: f64 = 1e8;

/// What the solver needs of a ring: the extensions of a shape vector (girth exact), and the
/// residuals whose squares it sums at those extensions.
pub(super) trait Ring {
    /// The feasible extensions of shape vector `a`: `clamp(a + δ(a))`.
    fn extensions(&self, a: &[f64]) -> Vec<f64>;
    /// The skin's distance minus the section's along each gap ray, then how far each panel
    /// lies under the skin, at `extensions`.
    fn residuals(&self, extensions: &[f64]) -> Vec<f64>;
}

/// The least-squares extensions of `ring` from `start` (feasible extensions, mirror partners
/// equal); `groups[k]` is the variable actuator `k` shares with its mirror partner (0-based,
/// dense).
pub(super) fn solve(ring: &impl Ring, start: &[f64], groups: &[usize]) -> Vec<f64> {
    let n = groups.iter().max().map_or(0, |g| g + 1);
    let spread = |v: &DVector<f64>| -> Vec<f64> { groups.iter().map(|&g| v[g]).collect() };
    // Each group's variable: the mean of its actuators' extensions.
    let gather = |e: &[f64]| -> DVector<f64> {
        let mut x = DVector::zeros(n);
        let mut counts = vec![0.0; n];
        for (k, &g) in groups.iter().enumerate() {
            x[g] += e[k];
            counts[g] += 1.0;
        }
        debug_assert!(counts.iter().all(|&c| c > 0.0), "groups are dense");
        x.component_div_assign(&DVector::from_vec(counts));
        x
    };
    let residual = |x: &DVector<f64>| {
        let e = ring.extensions(&spread(x));
        (DVector::from_vec(ring.residuals(&e)), e)
    };
    let mut x = gather(start);
    let (mut r, mut e) = residual(&x);
    let mut cost = r.norm_squared();
    let mut damping = DAMPING_MIN;
    for _ in 0..MAX_ITERATIONS {
        let mut jacobian = DMatrix::zeros(r.len(), n);
        for g in 0..n {
            let mut up = x.clone();
            up[g] += DIFFERENCE_MM;
            let mut down = x.clone();
            down[g] -= DIFFERENCE_MM;
            let column = (residual(&up).0 - residual(&down).0) / (2.0 * DIFFERENCE_MM);
            jacobian.set_column(g, &column);
        }
        let normal = jacobian.transpose() * &jacobian;
        let gradient = jacobian.transpose() * &r;
        let mut moved = 0.0;
        while damping <= DAMPING_MAX {
            let mut damped = normal.clone();
            for g in 0..n {
                damped[(g, g)] += damping * normal[(g, g)].max(1.0);
            }
            let Some(step) = damped.cholesky().map(|c| c.solve(&(-&gradient))) else {
                damping *= DAMPING_FACTOR;
                continue;
            };
            let (next_r, next_e) = residual(&(&x + &step));
            let next_cost = next_r.norm_squared();
            if next_cost < cost {
                moved = next_e.iter().zip(&e).fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
                (x, r, e, cost) = (gather(&next_e), next_r, next_e, next_cost);
                damping = (damping / DAMPING_FACTOR).max(DAMPING_MIN);
                break;
            }
            damping *= DAMPING_FACTOR;
        }
        if moved <= STEP_TOLERANCE_MM {
            break;
        }
    }
    e
}

/// The root mean square of `gaps` (mm).
pub fn rms(gaps: &[f64]) -> f64 {
    if gaps.is_empty() {
        return 0.0;
    }
    (gaps.iter().map(|g| g * g).sum::<f64>() / gaps.len() as f64).sqrt()
}

/// The unit directions of the [`GAP_RAYS`] rays.
pub(super) fn gap_directions() -> Vec<DVec2> {
    (0..GAP_RAYS).map(|i| crate::shape::symmetry::rays::direction(i, GAP_RAYS)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear ring: gaps `A e - b` with `e = a + δ`, `δ` making `sum(e) = total`, no bounds.
    struct Linear {
        a: DMatrix<f64>,
        b: DVector<f64>,
        total: f64,
    }

    impl Ring for Linear {
        fn extensions(&self, a: &[f64]) -> Vec<f64> {
            let delta = (self.total - a.iter().sum::<f64>()) / a.len() as f64;
            a.iter().map(|x| x + delta).collect()
        }
        fn residuals(&self, e: &[f64]) -> Vec<f64> {
            (&self.a * DVector::from_column_slice(e) - &self.b).iter().copied().collect()
        }
    }

    #[test]
    fn a_linear_problem_reaches_its_constrained_optimum() {
        // min |A e - b|² subject to e1 + e2 + e3 = 6, by the KKT system.
        let a = DMatrix::from_row_slice(4, 3, &[1., 0., 0., 0., 2., 0., 0., 0., 1., 1., 1., 0.]);
        let b = DVector::from_vec(vec![1.0, 6.0, 4.0, 2.0]);
        let ring = Linear { a: a.clone(), b: b.clone(), total: 6.0 };
        let got = solve(&ring, &[2.0, 2.0, 2.0], &[0, 1, 2]);
        let mut kkt = DMatrix::zeros(4, 4);
        kkt.view_mut((0, 0), (3, 3)).copy_from(&(a.transpose() * &a));
        for k in 0..3 {
            kkt[(k, 3)] = 1.0;
            kkt[(3, k)] = 1.0;
        }
        let mut rhs = DVector::zeros(4);
        rhs.rows_mut(0, 3).copy_from(&(a.transpose() * &b));
        rhs[3] = 6.0;
        let want = kkt.lu().solve(&rhs).unwrap();
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-3, "{k}: {} vs {}", got[k], want[k]);
        }
    }

    #[test]
    fn grouped_variables_move_together() {
        let a = DMatrix::identity(3, 3);
        let b = DVector::from_vec(vec![1.0, 5.0, 3.0]);
        let ring = Linear { a, b, total: 9.0 };
        let got = solve(&ring, &[3.0, 3.0, 3.0], &[0, 1, 0]);
        assert!((got[0] - got[2]).abs() < 1e-9);
        // Best with e0 = e2: e0 = e2 = 2, e1 = 5.
        assert!((got[0] - 2.0).abs() < 1e-3 && (got[1] - 5.0).abs() < 1e-3, "{got:?}");
    }
}
