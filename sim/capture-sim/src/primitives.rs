//! Signed distance primitives the body is built from (negative inside, millimetres), their
//! bounding boxes, and the smooth union that blends them.

use glam::DVec3;

/// Quadratic polynomial smooth minimum with blend width `k` (mm): equal to `min(a, b)` when
/// `|a - b| >= k`, otherwise up to `k / 4` below it, which rounds the crease where two shapes
/// meet. Its gradient is a convex combination of the inputs' gradients.
pub(crate) fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    if k <= 0.0 {
        return a.min(b);
    }
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// Smooth maximum (smooth intersection), the mirror of [`smooth_min`]; never below `max(a, b)`.
pub(crate) fn smooth_max(a: f64, b: f64, k: f64) -> f64 {
    -smooth_min(-a, -b, k)
}

/// Axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    /// The smallest box holding both boxes.
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// Euclidean distance from `p` to the box (0 inside).
    pub fn distance(&self, p: DVec3) -> f64 {
        let d = (self.min - p).max(p - self.max).max(DVec3::ZERO);
        d.length()
    }
}

/// A round cone: the convex hull of two spheres (a capsule whose radius changes linearly).
/// Its value is the exact Euclidean signed distance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RoundCone {
    a: DVec3,
    ra: f64,
    rb: f64,
    ba: DVec3,
    l2: f64,
    rr: f64,
    a2: f64,
    il2: f64,
    bounds: Aabb,
}

impl RoundCone {
    /// Round cone from the sphere (`a`, `ra`) to the sphere (`b`, `rb`). When one sphere holds
    /// the other, the larger sphere alone is used.
    pub fn new(a: DVec3, ra: f64, b: DVec3, rb: f64) -> RoundCone {
        let ba = b - a;
        let l2 = ba.length_squared().max(1e-12);
        let rr = ra - rb;
        let bounds = Aabb {
            min: (a - DVec3::splat(ra)).min(b - DVec3::splat(rb)),
            max: (a + DVec3::splat(ra)).max(b + DVec3::splat(rb)),
        };
        RoundCone { a, ra, rb, ba, l2, rr, a2: l2 - rr * rr, il2: 1.0 / l2, bounds }
    }

    /// Signed distance from `p` (after Inigo Quilez's closed form, one square root).
    pub fn distance(&self, p: DVec3) -> f64 {
        if self.a2 <= 0.0 {
            // One sphere contains the other.
            let (c, r) =
                if self.ra >= self.rb { (self.a, self.ra) } else { (self.a + self.ba, self.rb) };
            return (p - c).length() - r;
        }
        let pa = p - self.a;
        let y = pa.dot(self.ba);
        let z = y - self.l2;
        let x2 = (pa * self.l2 - self.ba * y).length_squared();
        let y2 = y * y * self.l2;
        let z2 = z * z * self.l2;
        let k = self.rr.signum() * self.rr * self.rr * x2;
        if z.signum() * self.a2 * z2 > k {
            return (x2 + z2).sqrt() * self.il2 - self.rb;
        }
        if y.signum() * self.a2 * y2 < k {
            return (x2 + y2).sqrt() * self.il2 - self.ra;
        }
        ((x2 * self.a2 * self.il2).sqrt() + y * self.rr) * self.il2 - self.ra
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}

/// An ellipsoid with arbitrary orientation. Its value is the first-order distance estimate
/// `(rho - 1) / |grad rho|` of the normalised radius `rho`: exact on the surface, 1-Lipschitz
/// near it, and at least `min_radius / max_radius` times the true distance outside.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ellipsoid {
    centre: DVec3,
    axes: [DVec3; 3],
    inv_r: DVec3,
    inv_r2: DVec3,
    min_r: f64,
    ratio: f64,
    bounds: Aabb,
}

impl Ellipsoid {
    /// Ellipsoid at `centre` with semi-axes `radii` along the orthonormal `axes`.
    pub fn new(centre: DVec3, axes: [DVec3; 3], radii: DVec3) -> Ellipsoid {
        let extent = DVec3::new(
            axis_extent(&axes, radii, 0),
            axis_extent(&axes, radii, 1),
            axis_extent(&axes, radii, 2),
        );
        Ellipsoid {
            centre,
            axes,
            inv_r: radii.recip(),
            inv_r2: (radii * radii).recip(),
            min_r: radii.min_element(),
            ratio: radii.min_element() / radii.max_element(),
            bounds: Aabb { min: centre - extent, max: centre + extent },
        }
    }

    /// Axis-aligned ellipsoid.
    pub fn aligned(centre: DVec3, radii: DVec3) -> Ellipsoid {
        Ellipsoid::new(centre, [DVec3::X, DVec3::Y, DVec3::Z], radii)
    }

    /// Approximate signed distance from `p` (see the type's doc).
    pub fn distance(&self, p: DVec3) -> f64 {
        let d = p - self.centre;
        let q = DVec3::new(d.dot(self.axes[0]), d.dot(self.axes[1]), d.dot(self.axes[2]));
        let k0 = (q * self.inv_r).length();
        let k1 = (q * self.inv_r2).length();
        if k1 < 1e-12 {
            return -self.min_r;
        }
        k0 * (k0 - 1.0) / k1
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Lower bound of `distance / true distance` outside the ellipsoid.
    pub fn bound_ratio(&self) -> f64 {
        self.ratio
    }
}

/// Half-extent along world axis `i` of an ellipsoid with the given axes and radii.
fn axis_extent(axes: &[DVec3; 3], radii: DVec3, i: usize) -> f64 {
    (0..3).map(|j| (radii[j] * axes[j][i]).powi(2)).sum::<f64>().sqrt()
}

/// Monotone piecewise-cubic Hermite interpolation (Fritsch-Carlson): C1, no overshoot, flat at
/// local extrema of the data, constant beyond the end knots.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Monotone {
    ys: Vec<f64>,
    slopes: Vec<f64>,
}

impl Monotone {
    /// Interpolant through (`xs[i]`, `ys[i]`); `xs` strictly increasing, at least two knots.
    pub fn new(xs: &[f64], ys: &[f64]) -> Monotone {
        let n = xs.len();
        let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n - 1).map(|i| (ys[i + 1] - ys[i]) / h[i]).collect();
        let mut slopes = vec![0.0; n];
        slopes[0] = delta[0];
        slopes[n - 1] = delta[n - 2];
        for i in 1..n - 1 {
            if delta[i - 1] * delta[i] > 0.0 {
                let w1 = 2.0 * h[i] + h[i - 1];
                let w2 = h[i] + 2.0 * h[i - 1];
                slopes[i] = (w1 + w2) / (w1 / delta[i - 1] + w2 / delta[i]);
            }
        }
        // Keep the end slopes from overshooting.
        for (s, d) in [(0, delta[0]), (n - 1, delta[n - 2])] {
            if slopes[s] * d <= 0.0 || d == 0.0 {
                slopes[s] = 0.0;
            }
        }
        Monotone { ys: ys.to_vec(), slopes }
    }

    /// Value in segment `i` at fraction `t` of its length `h`.
    pub fn eval(&self, i: usize, t: f64, h: f64) -> f64 {
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        h00 * self.ys[i]
            + h10 * h * self.slopes[i]
            + h01 * self.ys[i + 1]
            + h11 * h * self.slopes[i + 1]
    }
}

/// A straight tube of varying radius: the axis from `a` to `b`, the radius a monotone spline
/// of the distance along it (flat at local extrema), hemispherical ends. Its value, the radial
/// distance to the surface circle at the point's own axial position, is at least the true
/// distance outside and exact where the radius is constant.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tube {
    a: DVec3,
    axis: DVec3,
    length: f64,
    stations: Vec<f64>,
    radius: Monotone,
    bounds: Aabb,
}

impl Tube {
    /// Tube from `a` to `b` with radii `(fraction of the length, radius)`, fractions
    /// increasing from 0 to 1.
    pub fn new(a: DVec3, b: DVec3, radii: &[(f64, f64)]) -> Tube {
        let length = a.distance(b).max(1e-9);
        let stations: Vec<f64> = radii.iter().map(|&(f, _)| f * length).collect();
        let rs: Vec<f64> = radii.iter().map(|&(_, r)| r).collect();
        let r_max = rs.iter().fold(0.0f64, |m, &r| m.max(r));
        Tube {
            a,
            axis: (b - a) / length,
            length,
            radius: Monotone::new(&stations, &rs),
            stations,
            bounds: Aabb {
                min: a.min(b) - DVec3::splat(r_max),
                max: a.max(b) + DVec3::splat(r_max),
            },
        }
    }

    /// Radius at distance `t` along the axis (clamped to the ends).
    fn radius_at(&self, t: f64) -> f64 {
        let n = self.stations.len();
        let t = t.clamp(self.stations[0], self.stations[n - 1]);
        let i = self.stations.partition_point(|&k| k <= t).clamp(1, n - 1) - 1;
        let h = self.stations[i + 1] - self.stations[i];
        self.radius.eval(i, (t - self.stations[i]) / h, h)
    }

    /// Signed distance estimate from `p`.
    pub fn distance(&self, p: DVec3) -> f64 {
        let ap = p - self.a;
        let t = ap.dot(self.axis);
        if t <= 0.0 {
            return ap.length() - self.radius_at(0.0);
        }
        if t >= self.length {
            return (ap - self.axis * self.length).length() - self.radius_at(self.length);
        }
        (ap - self.axis * t).length() - self.radius_at(t)
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_min_is_min_far_apart_and_below_near() {
        assert_eq!(smooth_min(1.0, 30.0, 20.0), 1.0);
        assert_eq!(smooth_min(-4.0, 50.0, 20.0), -4.0);
        assert!((smooth_min(5.0, 5.0, 20.0) - 0.0).abs() < 1e-12);
        assert!(smooth_min(5.0, 10.0, 20.0) < 5.0);
        assert!(smooth_max(5.0, 10.0, 20.0) > 10.0);
    }

    #[test]
    fn round_cone_is_exact_distance() {
        let c = RoundCone::new(DVec3::ZERO, 10.0, DVec3::new(0.0, 0.0, 100.0), 5.0);
        // Beside the bottom sphere, below it, above the top sphere.
        assert!((c.distance(DVec3::new(0.0, 0.0, -20.0)) - 10.0).abs() < 1e-9);
        assert!((c.distance(DVec3::new(0.0, 0.0, 110.0)) - 5.0).abs() < 1e-9);
        // The side is a line from (10.0, 0) to (5, 100) tilted by asin(5/100).
        let mid = c.distance(DVec3::new(7.5, 0.0, 50.0));
        assert!(mid.abs() < 0.05, "{mid}");
        assert!(c.distance(DVec3::new(0.0, 0.0, 50.0)) < -7.0);
        assert!(
            c.bounds().distance(DVec3::new(30.0, 0.0, 50.0))
                <= c.distance(DVec3::new(30.0, 0.0, 50.0))
        );
    }

    #[test]
    fn tube_follows_its_radius_profile() {
        let t = Tube::new(
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 100.0),
            &[(0.0, 10.0), (0.5, 20.0), (1.0, 5.0)],
        );
        assert!((t.distance(DVec3::new(20.0, 0.0, 50.0))).abs() < 1e-9);
        assert!((t.distance(DVec3::new(0.0, 0.0, -4.0)) + 6.0).abs() < 1e-9);
        assert!((t.distance(DVec3::new(0.0, 0.0, 110.0)) - 5.0).abs() < 1e-9);
        // Monotone between knots: never thicker than the largest radius.
        for i in 0..=100 {
            let r = -t.distance(DVec3::new(0.0, 0.0, i as f64));
            assert!((5.0 - 1e-9..=20.0 + 1e-9).contains(&r), "{i}: {r}");
        }
        let outside = DVec3::new(40.0, 0.0, 30.0);
        assert!(t.bounds().distance(outside) <= t.distance(outside));
    }

    #[test]
    fn ellipsoid_surface_and_bound() {
        let e = Ellipsoid::aligned(DVec3::new(1.0, 2.0, 3.0), DVec3::new(10.0, 20.0, 40.0));
        for p in
            [DVec3::new(11.0, 2.0, 3.0), DVec3::new(1.0, 22.0, 3.0), DVec3::new(1.0, 2.0, -37.0)]
        {
            assert!(e.distance(p).abs() < 1e-9);
        }
        let outside = DVec3::new(1.0, 2.0, 60.0);
        let d = e.distance(outside);
        assert!(d > 0.0 && d <= 17.0 + 1e-9 && d >= 17.0 * e.bound_ratio());
        assert!(e.distance(DVec3::new(1.0, 2.0, 3.0)) < 0.0);
    }
}
