//! Heights first (issue 31): the lifts' extensions that bring every ring as close to the body
//! level it stands for ([`super::RingLevels`]) as the strokes allow.
//!
//! A ring's height is linear in the lifts' extensions `x` (`h = h₀ + A x`, `A[r][g]` = 1 where
//! lift `g` carries ring `r`), so the heights are one bounded linear least-squares problem,
//!
//! `min Σ_r (h₀_r + (A x)_r - L_r)²  subject to  0 <= x_g <= stroke_g`,
//!
//! solved by Stark and Parker's bounded-variable least squares (BVLS, an active-set method:
//! the Lawson-Hanson NNLS loop with an upper bound too): variables leave their bound while the
//! gradient points into the box, the free ones are solved by an unconstrained least squares
//! (SVD, so a lift carrying the same rings as another is no singularity), and a step that would
//! leave the box stops at the first bound it meets. A mirror pair of lifts shares one variable.
//! It ends at a point satisfying the Karush-Kuhn-Tucker conditions, the optimum of a convex
//! problem. Written by hand: a few variables, and no maintained Rust crate offers bounded
//! least squares.

use form_description::{FormDescription, LiftSpec};
use nalgebra::{DMatrix, DVector};
use std::collections::BTreeMap;

use super::RingLevels;

/// Gradient and bound tolerance (mm): a thousandth of the wire contract's position unit
/// (0.01 mm), far below anything a lift can resolve. A ring this close to its level stands
/// at it ([`super::rings`] takes its gaps there).
pub(super) const TOLERANCE_MM: f64 = 1e-5;
/// Singular values below this fraction of the largest count as zero in the free variables'
/// solve (rings carried by exactly the same lifts).
const SVD_EPSILON: f64 = 1e-12;
/// Variables freed at most: each free either lowers the sum of squares or is refused until
/// the point moves (at most one refusal per variable in a row), so a few per variable do;
/// the bound is a guard, never reached on the reference form's eight lifts.
const MAX_CHANGES: usize = 200;

/// Where the lifts stand and the rings they carry end up.
#[derive(Debug, Clone, PartialEq)]
pub struct Heights {
    /// Lift id → extension (mm), within its stroke.
    pub lifts_mm: BTreeMap<String, f64>,
    /// Ring name → height above the floor (mm).
    pub rings_mm: BTreeMap<String, f64>,
}

/// The lifts of `form` set so that its rings stand as close to `levels` as the strokes allow
/// (least squares over all rings); a form without lifts keeps its rings where they are built.
pub fn solve(form: &FormDescription, levels: &RingLevels) -> Heights {
    let groups = mirror_groups(&form.lifts);
    let n = groups.iter().copied().max().map_or(0, |g| g + 1);
    let rings = &form.rings;
    let mut a = DMatrix::<f64>::zeros(rings.len(), n);
    let mut upper = vec![f64::INFINITY; n];
    for (lift, &g) in form.lifts.iter().zip(&groups) {
        upper[g] = upper[g].min(lift.stroke_mm);
        for (r, ring) in rings.iter().enumerate() {
            // Lifts add up: a ring carried by both lifts of a mirror pair rises by twice the
            // shared variable, as `FormSpec::ring_height` sums them.
            if lift.rings.contains(&ring.name) {
                a[(r, g)] += 1.0;
            }
        }
    }
    // The heights still to gain: level minus built height.
    let b =
        DVector::from_iterator(rings.len(), rings.iter().map(|r| levels.of(&r.name) - r.height_mm));
    let x = bounded_least_squares(&a, &b, &upper);
    let lifts_mm: BTreeMap<String, f64> =
        form.lifts.iter().zip(&groups).map(|(l, &g)| (l.id.clone(), x[g])).collect();
    let rings_mm = rings.iter().map(|r| (r.name.clone(), form.ring_height(r, &lifts_mm))).collect();
    Heights { lifts_mm, rings_mm }
}

/// The variable of each lift: a lift shares its mirror partner's (the one it names or that
/// names it; validation allows one partner per lift); 0-based, dense.
fn mirror_groups(lifts: &[LiftSpec]) -> Vec<usize> {
    let mut groups: Vec<usize> = Vec::with_capacity(lifts.len());
    for (k, lift) in lifts.iter().enumerate() {
        let partner = lifts[..k].iter().position(|m| {
            m.mirror.as_deref() == Some(lift.id.as_str())
                || lift.mirror.as_deref() == Some(m.id.as_str())
        });
        let next = groups.iter().max().map_or(0, |g| g + 1);
        groups.push(partner.map_or(next, |j| groups[j]));
    }
    groups
}

/// Whether a variable is held at a bound or free.
#[derive(Clone, Copy, PartialEq)]
enum State {
    Lower,
    Upper,
    Free,
}

/// `argmin ‖A x - b‖²` over `0 <= x <= upper` by BVLS (see the module documentation); `upper`
/// has one bound per column of `a`, each at least 0.
pub fn bounded_least_squares(a: &DMatrix<f64>, b: &DVector<f64>, upper: &[f64]) -> Vec<f64> {
    let n = a.ncols();
    let mut x = vec![0.0; n];
    let mut state = vec![State::Lower; n];
    // A variable freed without moving anything (rounding sent its solve back out of the box)
    // is not tried again until the point moves: Stark and Parker's guard against cycling.
    let mut refused = vec![false; n];
    for _ in 0..MAX_CHANGES {
        // The descent direction's components, -∇/2 = Aᵀ(b - A x).
        let w = a.transpose() * (b - a * DVector::from_column_slice(&x));
        let into_box = |k: usize| match state[k] {
            State::Lower => w[k] > TOLERANCE_MM && upper[k] > 0.0,
            State::Upper => w[k] < -TOLERANCE_MM,
            State::Free => false,
        };
        let candidates = (0..n).filter(|&k| !refused[k] && into_box(k));
        let Some(k) = candidates.max_by(|&i, &j| w[i].abs().total_cmp(&w[j].abs())) else {
            break; // Karush-Kuhn-Tucker: no bound variable wants to move in
        };
        state[k] = State::Free;
        let before = x.clone();
        solve_free(a, b, upper, &mut x, &mut state);
        if x == before {
            refused[k] = true;
        } else {
            refused.fill(false);
        }
    }
    x
}

/// The free variables solved with the others held, stepping back into the box: where the
/// solution leaves it, `x` moves towards it as far as the first bound it meets, that variable
/// is bound, and the rest are solved again.
fn solve_free(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    upper: &[f64],
    x: &mut [f64],
    state: &mut [State],
) {
    let n = x.len();
    // Each pass binds at least one variable or ends: at most n + 1 passes.
    for _ in 0..=n {
        let free: Vec<usize> = (0..n).filter(|&k| state[k] == State::Free).collect();
        let z = free_solution(a, b, x, &free);
        let mut alpha = 1.0;
        for (&k, &zk) in free.iter().zip(&z) {
            let limit = if zk < 0.0 {
                0.0
            } else if zk > upper[k] {
                upper[k]
            } else {
                continue;
            };
            alpha = f64::min(alpha, ((limit - x[k]) / (zk - x[k])).clamp(0.0, 1.0));
        }
        for (&k, &zk) in free.iter().zip(&z) {
            x[k] = (x[k] + alpha * (zk - x[k])).clamp(0.0, upper[k]);
        }
        if alpha >= 1.0 {
            return;
        }
        for &k in &free {
            if x[k] <= TOLERANCE_MM {
                (x[k], state[k]) = (0.0, State::Lower);
            } else if x[k] >= upper[k] - TOLERANCE_MM {
                (x[k], state[k]) = (upper[k], State::Upper);
            }
        }
    }
}

/// The unconstrained least-squares values of the `free` variables with the others held at `x`.
fn free_solution(a: &DMatrix<f64>, b: &DVector<f64>, x: &[f64], free: &[usize]) -> Vec<f64> {
    if free.is_empty() {
        return Vec::new();
    }
    let mut rest = b.clone();
    for (k, &xk) in x.iter().enumerate() {
        if !free.contains(&k) {
            rest -= a.column(k) * xk;
        }
    }
    let columns: Vec<DVector<f64>> = free.iter().map(|&k| a.column(k).into_owned()).collect();
    let af = DMatrix::from_columns(&columns);
    let svd = af.svd(true, true);
    let cut = SVD_EPSILON * svd.singular_values.max();
    svd.solve(&rest, cut)
        .map_or_else(|_| free.iter().map(|&k| x[k]).collect(), |z| z.iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of three lifts over three rings (lift k carries rings k..): the unconstrained
    /// optimum puts every ring on its level; a stroke too short leaves its ring below and the
    /// lifts above it make up the rest for the rings they carry.
    #[test]
    fn a_chain_of_lifts_reaches_every_level_the_strokes_allow() {
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0]);
        let b = DVector::from_column_slice(&[30.0, 50.0, 65.0]);
        let x = bounded_least_squares(&a, &b, &[100.0, 100.0, 100.0]);
        for (got, want) in x.iter().zip([30.0, 20.0, 15.0]) {
            assert!((got - want).abs() < 1e-9, "{x:?}");
        }
        // The first lift's stroke is 10: rings 2 and 3 still reach their levels.
        let x = bounded_least_squares(&a, &b, &[10.0, 100.0, 100.0]);
        for (got, want) in x.iter().zip([10.0, 40.0, 15.0]) {
            assert!((got - want).abs() < 1e-9, "{x:?}");
        }
        // Levels below the rings: everything stays retracted.
        let x = bounded_least_squares(&a, &(-b), &[100.0, 100.0, 100.0]);
        assert_eq!(x, vec![0.0; 3]);
    }

    /// One lift carrying two rings whose levels ask 10 and 30 mm: the mean, 20, inside the
    /// stroke; 15 at a stroke of 15; and two lifts carrying the same ring are no
    /// singularity.
    #[test]
    fn a_lift_carrying_several_rings_sets_them_to_the_mean_gain() {
        let a = DMatrix::from_row_slice(2, 1, &[1.0, 1.0]);
        let b = DVector::from_column_slice(&[10.0, 30.0]);
        assert!((bounded_least_squares(&a, &b, &[100.0])[0] - 20.0).abs() < 1e-9);
        assert!((bounded_least_squares(&a, &b, &[15.0])[0] - 15.0).abs() < 1e-9);
        let twin = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
        let x = bounded_least_squares(&twin, &DVector::from_column_slice(&[50.0]), &[30.0, 30.0]);
        assert!((x[0] + x[1] - 50.0).abs() < 1e-9, "{x:?}");
    }

    /// A lift shares the variable of the partner it names or that names it, listed before or
    /// after it; the others have their own.
    #[test]
    fn mirror_partners_share_a_variable() {
        let lift = |id: &str, mirror: Option<&str>| LiftSpec {
            id: id.into(),
            node: 1,
            channel: 0,
            rings: vec![],
            stroke_mm: 10.0,
            max_speed_mm_s: 10.0,
            max_accel_mm_s2: 10.0,
            force_limit_n: None,
            mirror: mirror.map(String::from),
        };
        let lifts = [lift("a", Some("b")), lift("c", None), lift("b", None), lift("d", Some("c"))];
        assert_eq!(mirror_groups(&lifts), [0, 1, 0, 1]);
    }

    /// Against brute force on random boxes: no grid point of the box has a smaller sum.
    #[test]
    fn the_solution_is_the_boxes_optimum() {
        let a = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0]);
        for (b, upper) in [
            ([5.0, 40.0, 30.0, 70.0], [20.0, 20.0]),
            ([-5.0, 10.0, 12.0, 3.0], [8.0, 50.0]),
            ([60.0, 60.0, 60.0, -10.0], [30.0, 30.0]),
        ] {
            let b = DVector::from_column_slice(&b);
            let cost = |x: &[f64]| (&b - &a * DVector::from_column_slice(x)).norm_squared();
            let best = bounded_least_squares(&a, &b, &upper);
            let steps = 200;
            for i in 0..=steps {
                for j in 0..=steps {
                    let x =
                        [upper[0] * i as f64 / steps as f64, upper[1] * j as f64 / steps as f64];
                    assert!(cost(&best) <= cost(&x) + 1e-9, "{best:?} vs {x:?}");
                }
            }
        }
    }
}
