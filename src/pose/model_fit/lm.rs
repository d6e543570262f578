//! One damped Gauss-Newton (Levenberg-Marquardt) iteration of eq. 4 for fixed
//! correspondences: the normal equations `(J^T W J + priors) dx = -J^T W r`, accumulated over
//! the model's vertices in parallel (in a fixed order), solved for the active parameters with
//! damping `lambda diag(H)`; the damping grows until the step lowers the energy.

use super::correspondences::Quadratics;
use super::params::{Params, Posed, PreparedModel};
use super::priors::Priors;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// The first damping factor (relative to the diagonal), and how it changes after a rejected or
/// accepted step: Nielsen's classic choices, simplified.
pub const LAMBDA_START: f64 = 1e-3;
const LAMBDA_UP: f64 = 10.0;
const LAMBDA_DOWN: f64 = 3.0;
/// A step is given up when the damping exceeds this (the energy is at a minimum along every
/// direction the linearisation sees).
const LAMBDA_MAX: f64 = 1e8;

/// The energy of eq. 4 at `params`: the data cost of the posed vertices plus the priors.
pub fn energy(priors: &Priors, data: &Quadratics, params: &Params, posed: &Posed) -> f64 {
    data.cost(&posed.vertices) + priors.cost(params)
}

/// The result of one iteration.
pub struct Step {
    /// The new parameters (the old ones when no step lowered the energy).
    pub params: Params,
    /// The energy before and after.
    pub before: f64,
    /// The energy after the step.
    pub after: f64,
    /// The damping to start the next iteration with.
    pub lambda: f64,
}

/// One LM iteration of the data term `data` and the regularisers `priors` over the parameters
/// marked `active`, from `params` (posed as `posed`).
pub fn iterate(
    prep: &PreparedModel,
    priors: &Priors,
    data: &Quadratics,
    params: &Params,
    posed: &Posed,
    active: &[bool],
    lambda: f64,
) -> Step {
    let n = prep.layout.size();
    let (mut h, mut g) = normal_equations(prep, data, posed, active);
    priors.add_to(prep.layout, params, posed, &mut h, &mut g);
    let parents = &prep.model.skeleton.parents;
    let index: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
    let m = index.len();
    let hr = DMatrix::from_fn(m, m, |r, c| h[(index[r], index[c])]);
    let gr = DVector::from_fn(m, |r, _| g[index[r]]);
    let before = energy(priors, data, params, posed);
    let mut lambda = lambda;
    while lambda <= LAMBDA_MAX {
        let mut damped = hr.clone();
        for i in 0..m {
            damped[(i, i)] += lambda * hr[(i, i)].max(f64::EPSILON);
        }
        if let Some(chol) = damped.cholesky() {
            let dx = chol.solve(&(-&gr));
            let mut full = vec![0.0; n];
            index.iter().zip(dx.iter()).for_each(|(&i, &d)| full[i] = d);
            let next = params.step(prep.layout, posed, parents, &full);
            let next_posed = prep.pose(&next);
            let after = energy(priors, data, &next, &next_posed);
            if after < before {
                return Step { params: next, before, after, lambda: lambda / LAMBDA_DOWN };
            }
        }
        lambda *= LAMBDA_UP;
    }
    Step { params: params.clone(), before, after: before, lambda }
}

/// Data terms (at most one per model vertex) per block of [`normal_equations`]: the built-in
/// model's 13,380 vertices make 14 blocks, which 2 to 8 threads share about evenly
/// ([`crate::body::mesh::reduce::BLOCK`], 4,096, would make three and a small fourth); a block's own
/// `n x n` sums (n = 83 parameters: 55 kB) cost little beside its terms.
const TERMS_PER_BLOCK: usize = 1024;

/// `J^T W J` and `J^T W r` of the data term (halved: the cost is `x^T A x - 2 c.x + e`, its
/// gradient `2 (A x - c)`, its Gauss-Newton Hessian `2 J^T A J`; the priors use the same halves),
/// in the rows and columns of the `active` parameters only (the others stay zero). Summed over fixed blocks of terms in parallel, the blocks then added in order (as
/// [`crate::body::mesh::reduce`] does): a rayon `fold().reduce()` groups the additions as threads
/// steal work, and a last-bit difference in one step grows through the fit into every output
/// (issue 29: the same scan gave different files).
fn normal_equations(
    prep: &PreparedModel,
    data: &Quadratics,
    posed: &Posed,
    active: &[bool],
) -> (DMatrix<f64>, DVector<f64>) {
    let n = prep.layout.size();
    let zeros = || (DMatrix::zeros(n, n), DVector::zeros(n));
    let blocks: Vec<(DMatrix<f64>, DVector<f64>)> = data
        .terms
        .par_chunks(TERMS_PER_BLOCK)
        .map(|block| {
            let (mut h, mut g) = zeros();
            let (mut cols, mut ac) = (Vec::new(), Vec::new());
            for (v, a, c, _) in block {
                prep.jacobian(posed, *v, &mut cols);
                // The rows and columns of parameters the stage holds fixed are never read.
                cols.retain(|&(i, _)| active[i]);
                let r = *a * posed.vertices[*v] - *c;
                cols.iter().for_each(|&(i, col)| g[i] += col.dot(r));
                // Each entry takes one addition per term, so the loops may run column by
                // column (along the matrix's storage) without changing a bit.
                ac.clear();
                ac.extend(cols.iter().map(|(_, col)| *a * *col));
                for (&(j, _), acj) in cols.iter().zip(&ac) {
                    let column = &mut h.as_mut_slice()[j * n..(j + 1) * n];
                    cols.iter().for_each(|&(i, col)| column[i] += col.dot(*acj));
                }
            }
            (h, g)
        })
        .collect();
    blocks.into_iter().fold(zeros(), |(h1, g1), (h2, g2)| (h1 + h2, g1 + g2))
}
