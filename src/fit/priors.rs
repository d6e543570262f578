//! The priors of the fit energy (eq. 4's regularisers): a Gaussian prior on the shape
//! coefficients (beta is in standard deviations of the population, so `|beta|^2` is its
//! negative log-likelihood up to a constant), and a weak pull of every bone's angle towards the
//! rest pose so that bones the scan cannot see (hands, feet in a hole) stay put.
//!
//! Both are in the units of the data term: the mean squared distance per pair (mm^2).

/// The cost of one standard deviation of shape, in mm^2 of mean squared distance: a shape
/// coefficient must buy at least about a millimetre of fit to be used (chosen by the recovered
/// poses of `tests/pose_symmetry.rs`; the scans' noise is 0.5-1 mm).
pub const BETA_PRIOR_MM2: f64 = 1.0;

/// The cost of a radian of bone rotation (mm^2 per rad^2 of mean squared distance): small, a
/// tie-breaker for bones with no data, not a pull on limbs the scan shows (10 degrees cost
/// 0.3 mm^2).
pub const POSE_PRIOR_MM2_PER_RAD2: f64 = 10.0;
