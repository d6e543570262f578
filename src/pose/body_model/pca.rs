//! The PCA shape space (paper eq. 2): `V(beta) = mean + sum_k beta_k sigma_k u_k`, from the
//! principal components of a population of bodies in the template's topology.
//!
//! A population is given as `body_i = offset + sum_j c_ij b_j` (MakeHuman bodies: the base mesh
//! plus weighted targets; registered meshes: `b_j` the meshes, `c` the identity). The centred
//! data matrix is then `C_c B` and its principal directions follow from two small matrices,
//! `K = C_c^T C_c / (N - 1)` and the Gram matrix `G = B B^T`: if `K^1/2 G K^1/2 a = lambda a`,
//! then `u = B^T K^1/2 a / sqrt(lambda)` is a unit principal direction with variance `lambda`.
//! This is exactly the SVD of the N bodies, without forming them. Every sum runs in a fixed
//! order, so a rebuild gives the same bits.

use glam::DVec3;
use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;

/// Principal components of a population.
#[derive(Debug, Clone, PartialEq)]
pub struct PrincipalComponents {
    /// The population's mean body.
    pub mean: Vec<DVec3>,
    /// Unit principal directions (over all 3V coordinates), largest variance first.
    pub directions: Vec<Vec<DVec3>>,
    /// Each direction's variance (mm², over the whole body vector).
    pub variances: Vec<f64>,
    /// The population's total variance (mm²): the sum over all its directions.
    pub total_variance: f64,
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.dot(*q)).sum()
}

/// The symmetric square root of a positive semi-definite matrix (negative rounding clipped).
fn sqrt_psd(m: DMatrix<f64>) -> DMatrix<f64> {
    let e = SymmetricEigen::new(m);
    let root = e.eigenvalues.map(|l| l.max(0.0).sqrt());
    &e.eigenvectors * DMatrix::from_diagonal(&root) * e.eigenvectors.transpose()
}

/// The `k` leading principal components of the bodies `offset + coefficients[i] . basis`.
/// Each direction's sign makes its largest coordinate positive.
pub fn principal_components(
    offset: &[DVec3],
    basis: &[Vec<DVec3>],
    coefficients: &[Vec<f64>],
    k: usize,
) -> PrincipalComponents {
    let (n, m) = (coefficients.len(), basis.len());
    let centre: Vec<f64> =
        (0..m).map(|j| coefficients.iter().map(|c| c[j]).sum::<f64>() / n as f64).collect();
    let mean: Vec<DVec3> = (0..offset.len())
        .into_par_iter()
        .map(|v| offset[v] + (0..m).map(|j| centre[j] * basis[j][v]).sum::<DVec3>())
        .collect();
    let centred = DMatrix::from_fn(n, m, |i, j| coefficients[i][j] - centre[j]);
    let k_matrix = centred.transpose() * &centred / (n.max(2) - 1) as f64;
    let gram_rows: Vec<Vec<f64>> = (0..m)
        .into_par_iter()
        .map(|a| (0..m).map(|b| dot(&basis[a], &basis[b])).collect())
        .collect();
    let gram = DMatrix::from_fn(m, m, |a, b| gram_rows[a.min(b)][a.max(b)]);
    let root = sqrt_psd(k_matrix.clone());
    let inner = &root * &gram * &root;
    let inner = (&inner + inner.transpose()) / 2.0;
    let eigen = SymmetricEigen::new(inner);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let total_variance = (&k_matrix * &gram).trace();
    let (mut directions, mut variances) = (Vec::new(), Vec::new());
    for &e in order.iter().take(k) {
        let lambda = eigen.eigenvalues[e];
        if lambda <= 0.0 {
            break;
        }
        let along = &root * eigen.eigenvectors.column(e) / lambda.sqrt();
        let mut u: Vec<DVec3> = (0..offset.len())
            .into_par_iter()
            .map(|v| (0..m).map(|j| along[j] * basis[j][v]).sum())
            .collect();
        let largest =
            u.iter().flat_map(|p| p.to_array()).max_by(|a, b| a.abs().total_cmp(&b.abs()));
        if largest.is_some_and(|x| x < 0.0) {
            u.iter_mut().for_each(|p| *p = -*p);
        }
        directions.push(u);
        variances.push(lambda);
    }
    PrincipalComponents { mean, directions, variances, total_variance }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_covariance_of_explicit_bodies() {
        // Three bodies on two basis vectors over two vertices.
        let offset = vec![DVec3::ONE, DVec3::ZERO];
        let basis = vec![vec![DVec3::X, DVec3::Y], vec![DVec3::Z, DVec3::X * 2.0]];
        let coefficients = vec![vec![1.0, 0.0], vec![0.0, 2.0], vec![2.0, 1.0]];
        let c = principal_components(&offset, &basis, &coefficients, 2);
        // Explicit data matrix, covariance, and its action on each direction.
        let bodies: Vec<Vec<f64>> = coefficients
            .iter()
            .map(|co| {
                (0..2)
                    .flat_map(|v| {
                        (offset[v] + co[0] * basis[0][v] + co[1] * basis[1][v]).to_array()
                    })
                    .collect()
            })
            .collect();
        let mean: Vec<f64> =
            (0..6).map(|d| bodies.iter().map(|b| b[d]).sum::<f64>() / 3.0).collect();
        let cov = |a: usize, b: usize| {
            bodies.iter().map(|x| (x[a] - mean[a]) * (x[b] - mean[b])).sum::<f64>() / 2.0
        };
        let flat_mean: Vec<f64> = c.mean.iter().flat_map(|p| p.to_array()).collect();
        assert!(flat_mean.iter().zip(&mean).all(|(a, b)| (a - b).abs() < 1e-12));
        assert!(((0..6).map(|d| cov(d, d)).sum::<f64>() - c.total_variance).abs() < 1e-12);
        for (u, lambda) in c.directions.iter().zip(&c.variances) {
            let u: Vec<f64> = u.iter().flat_map(|p| p.to_array()).collect();
            for a in 0..6 {
                let su: f64 = (0..6).map(|b| cov(a, b) * u[b]).sum();
                assert!((su - lambda * u[a]).abs() < 1e-12, "not an eigenvector");
            }
        }
        assert!(c.variances[0] >= c.variances[1]);
    }
}
