//! Robust weights for the fit's pairs (eq. 4's data term made robust): Geman-McClure,
//! `rho(r) = r^2 / (r^2 + sigma^2)` up to a constant factor, minimised by iteratively reweighted
//! least squares with the weight `w(r) = (sigma^2 / (sigma^2 + r^2))^2`. Pairs much further
//! apart than `sigma` barely count, so the scale `sigma` is annealed from coarse to fine.

/// The IRLS weight of a pair `r` millimetres apart at scale `sigma` (mm).
pub fn geman_mcclure(r: f64, sigma: f64) -> f64 {
    let s2 = sigma * sigma;
    let q = s2 / (s2 + r * r);
    q * q
}

/// The Geman-McClure cost of a residual `r` at scale `sigma`, scaled to behave like `r^2`
/// near zero (`sigma^2 r^2 / (sigma^2 + r^2)`): what the weights of [`geman_mcclure`] minimise.
pub fn cost(r2: f64, sigma: f64) -> f64 {
    let s2 = sigma * sigma;
    s2 * r2 / (s2 + r2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_fall_from_one_to_nothing_beyond_the_scale() {
        assert_eq!(geman_mcclure(0.0, 10.0), 1.0);
        assert!((geman_mcclure(10.0, 10.0) - 0.25).abs() < 1e-12);
        assert!(geman_mcclure(100.0, 10.0) < 1e-3);
        // The cost is r^2 near zero and bounded by sigma^2.
        assert!((cost(0.01, 10.0) - 0.01).abs() < 1e-6);
        assert!(cost(1e8, 10.0) < 100.0);
    }
}
