//! The torso: a loft of horizontal sections, each two half-superellipses (front and back)
//! sharing a half-width, whose sizes vary smoothly with height; breasts blended on the front;
//! flat, rounded ends at the crotch and under the neck; and a height-dependent horizontal
//! scale that calibration uses to hit the requested girths.

use glam::DVec3;

use super::primitives::{Aabb, Ellipsoid, Monotone, smooth_max, smooth_min};

/// One horizontal torso section (a knot of the loft), millimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Section {
    /// Height of the section.
    pub z: f64,
    /// Half-width (x extent either side of x = 0).
    pub half_width: f64,
    /// Y of the front-most point (negative: the subject faces -Y).
    pub y_front: f64,
    /// Y of the back-most point.
    pub y_back: f64,
    /// Superellipse exponent of the front half (2 = ellipse, larger = boxier).
    pub n_front: f64,
    /// Superellipse exponent of the back half.
    pub n_back: f64,
}

impl Section {
    /// Y of the section's centre (half-way between front and back).
    pub fn centre_y(&self) -> f64 {
        0.5 * (self.y_front + self.y_back)
    }

    /// The section scaled by `s` about (0, 0): widths, depths and centre.
    pub fn scaled(&self, s: f64) -> Section {
        Section {
            half_width: self.half_width * s,
            y_front: self.y_front * s,
            y_back: self.y_back * s,
            ..*self
        }
    }

    /// Distance from the centre to the boundary in the unit direction (`ux`, `uy`).
    pub fn boundary_radius(&self, ux: f64, uy: f64) -> f64 {
        let c = self.centre_y();
        let (depth, n) = if uy < 0.0 {
            (c - self.y_front, self.n_front)
        } else {
            (self.y_back - c, self.n_back)
        };
        let rho = ((ux.abs() / self.half_width).powf(n) + (uy.abs() / depth).powf(n)).powf(1.0 / n);
        1.0 / rho
    }

    /// Radial signed distance of (`x`, `y`) to the section boundary: the distance along the ray
    /// from the centre (at least the true distance outside, exact for a circle).
    pub fn radial_distance(&self, x: f64, y: f64) -> f64 {
        let dy = y - self.centre_y();
        let r = x.hypot(dy);
        if r < 1e-9 {
            return -self.half_width.min(0.5 * (self.y_back - self.y_front));
        }
        r - self.boundary_radius(x / r, dy / r)
    }

    /// Y of the front boundary at lateral offset `x` (|x| <= half-width).
    pub fn front_y_at(&self, x: f64) -> f64 {
        let t = (x.abs() / self.half_width).min(1.0);
        let depth = self.centre_y() - self.y_front;
        self.centre_y() - depth * (1.0 - t.powf(self.n_front)).max(0.0).powf(1.0 / self.n_front)
    }

    /// Perimeter of the section (convex for exponents >= 1, so also its tape girth).
    pub fn perimeter(&self) -> f64 {
        const N: usize = 720;
        let c = self.centre_y();
        let point = |i: usize| {
            let t = i as f64 / N as f64 * std::f64::consts::TAU;
            let (uy, ux) = t.sin_cos();
            let r = self.boundary_radius(ux, uy);
            (r * ux, c + r * uy)
        };
        (0..N)
            .map(|i| {
                let (a, b) = (point(i), point(i + 1));
                (a.0 - b.0).hypot(a.1 - b.1)
            })
            .sum()
    }
}

/// The loft: sections interpolated between knots with [`Monotone`] splines.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Loft {
    zs: Vec<f64>,
    fields: [Monotone; 5],
}

impl Loft {
    /// Loft through `knots` (at least two, strictly increasing in z).
    pub fn new(knots: &[Section]) -> Loft {
        let zs: Vec<f64> = knots.iter().map(|k| k.z).collect();
        let field = |f: fn(&Section) -> f64| {
            let ys: Vec<f64> = knots.iter().map(f).collect();
            Monotone::new(&zs, &ys)
        };
        Loft {
            fields: [
                field(|k| k.half_width),
                field(|k| k.y_front),
                field(|k| k.y_back),
                field(|k| k.n_front),
                field(|k| k.n_back),
            ],
            zs,
        }
    }

    /// The section at height `z` (clamped to the knots' range).
    pub fn at(&self, z: f64) -> Section {
        let n = self.zs.len();
        let z = z.clamp(self.zs[0], self.zs[n - 1]);
        let i = self.zs.partition_point(|&k| k <= z).clamp(1, n - 1) - 1;
        let h = self.zs[i + 1] - self.zs[i];
        let t = (z - self.zs[i]) / h;
        let v = |f: usize| self.fields[f].eval(i, t, h);
        Section { z, half_width: v(0), y_front: v(1), y_back: v(2), n_front: v(3), n_back: v(4) }
    }
}

/// Horizontal scale of the torso as a function of height: the calibrated factors at the hip,
/// waist and chest levels, the chest's kept up to the armpits, and 1 at the shoulders; joined
/// by smoothsteps (so each knot is a flat point), constant beyond the end knots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScaleProfile {
    /// Heights of the knots (increasing).
    pub z: [f64; 5],
    /// Scale factors at the knots.
    pub s: [f64; 5],
}

impl ScaleProfile {
    /// Scale at height `z`.
    pub fn at(&self, z: f64) -> f64 {
        if z <= self.z[0] {
            return self.s[0];
        }
        if z >= self.z[4] {
            return self.s[4];
        }
        let i = self.z.partition_point(|&k| k <= z).clamp(1, 4) - 1;
        let t = (z - self.z[i]) / (self.z[i + 1] - self.z[i]);
        let w = t * t * (3.0 - 2.0 * t);
        self.s[i] + (self.s[i + 1] - self.s[i]) * w
    }

    /// Largest factor.
    fn max(&self) -> f64 {
        self.s.iter().fold(1.0f64, |m, &s| m.max(s))
    }
}

/// The torso solid.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Torso {
    pub loft: Loft,
    pub scale: ScaleProfile,
    /// Soft-tissue masses in left-right pairs (breasts, buttocks) in the unscaled frame of the
    /// loft, each pair with the width it blends in with (the pair first with itself, so the
    /// result does not depend on the side order).
    pub masses: Vec<([Ellipsoid; 2], f64)>,
    /// Bottom plane (between the thighs) and its edge rounding.
    pub bottom_z: f64,
    pub bottom_round: f64,
    /// Top plane (inside the neck) and its edge rounding.
    pub top_z: f64,
    pub top_round: f64,
}

impl Torso {
    /// Signed distance estimate from `p`: the loft's radial distance, cut by the end planes,
    /// blended with the masses; horizontally scaled about each section's centre.
    pub fn distance(&self, p: DVec3) -> f64 {
        let section = self.loft.at(p.z);
        let s = self.scale.at(p.z);
        let yc = section.centre_y();
        let q = DVec3::new(p.x / s, yc + (p.y - yc) / s, p.z);
        let mut d = s * section.radial_distance(q.x, q.y);
        d = smooth_max(d, self.bottom_z - p.z, self.bottom_round);
        d = smooth_max(d, p.z - self.top_z, self.top_round);
        for ([left, right], blend) in &self.masses {
            // Skip a pair that provably cannot change the value (as the body does for parts).
            let near = left.bounds().distance(q).min(right.bounds().distance(q));
            let ratio = left.bound_ratio().min(right.bound_ratio());
            if near > 0.0 && s * (ratio * near - 0.25 * blend) >= d + blend {
                continue;
            }
            let pair = smooth_min(left.distance(q), right.distance(q), *blend);
            d = smooth_min(d, s * pair, *blend);
        }
        d
    }

    /// Bounding box, from the knots (the interpolant never leaves their range) and masses.
    pub fn bounds(&self, knots: &[Section]) -> Aabb {
        let s = self.scale.max();
        let mut bb = Aabb {
            min: DVec3::new(0.0, f64::MAX, self.bottom_z),
            max: DVec3::new(0.0, f64::MIN, self.top_z),
        };
        for k in knots {
            let c = k.centre_y();
            let grow = |y: f64| c + (y - c) * s;
            bb.min = bb.min.min(DVec3::new(-k.half_width * s, grow(k.y_front), bb.min.z));
            bb.max = bb.max.max(DVec3::new(k.half_width * s, grow(k.y_back), bb.max.z));
        }
        bb.min.z = bb.min.z.max(self.bottom_z);
        bb.max.z = bb.max.z.min(self.top_z);
        for mass in self.masses.iter().flat_map(|m| &m.0) {
            // Scaled about a section centre within 300 mm of the origin.
            let e = mass.bounds();
            let margin = DVec3::new(1.0, 1.0 + (s - 1.0).abs() * 300.0, 1.0);
            bb = bb.union(Aabb {
                min: (e.min.min(e.min * s) - margin).with_z(e.min.z),
                max: (e.max.max(e.max * s) + margin).with_z(e.max.z),
            });
        }
        bb
    }

    /// The largest blend width of the masses (the torso's value lies at most about twice this
    /// below the smallest value of its parts).
    pub fn mass_blend(&self) -> f64 {
        self.masses.iter().map(|m| m.1).fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ellipse(a: f64, b: f64) -> Section {
        Section { z: 0.0, half_width: a, y_front: -b, y_back: b, n_front: 2.0, n_back: 2.0 }
    }

    #[test]
    fn ellipse_perimeter_matches_ramanujan() {
        let (a, b): (f64, f64) = (150.0, 100.0);
        let h = ((a - b) / (a + b)).powi(2);
        let ramanujan =
            std::f64::consts::PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()));
        let p = ellipse(a, b).perimeter();
        assert!((p - ramanujan).abs() / ramanujan < 1e-4, "{p} vs {ramanujan}");
    }

    #[test]
    fn radial_distance_sign_and_scale() {
        let s = ellipse(150.0, 100.0);
        assert!(s.radial_distance(150.0, 0.0).abs() < 1e-9);
        assert!(s.radial_distance(0.0, -100.0).abs() < 1e-9);
        assert!((s.radial_distance(160.0, 0.0) - 10.0).abs() < 1e-9);
        assert!(s.radial_distance(10.0, 10.0) < 0.0);
        assert!((s.front_y_at(0.0) + 100.0).abs() < 1e-9);
        assert!(s.front_y_at(150.0).abs() < 1e-9);
    }

    #[test]
    fn monotone_spline_has_no_overshoot_and_flat_extrema() {
        let knots: Vec<Section> = [(0.0, 100.0), (10.0, 150.0), (20.0, 120.0), (30.0, 121.0)]
            .iter()
            .map(|&(z, a)| Section { z, ..ellipse(a, 50.0) })
            .collect();
        let loft = Loft::new(&knots);
        for i in 0..=300 {
            let z = i as f64 * 0.1;
            let a = loft.at(z).half_width;
            assert!((100.0..=150.0).contains(&a), "{z}: {a}");
        }
        // The maximum stays at the knot.
        assert!(loft.at(9.9).half_width < 150.0 && loft.at(10.1).half_width < 150.0);
        assert_eq!(loft.at(10.0).half_width, 150.0);
        assert_eq!(loft.at(-5.0).half_width, 100.0);
        assert_eq!(loft.at(35.0).half_width, 121.0);
    }

    #[test]
    fn scale_profile_passes_through_levels() {
        let s = ScaleProfile {
            z: [800.0, 1000.0, 1200.0, 1250.0, 1350.0],
            s: [1.1, 0.9, 1.05, 1.05, 1.0],
        };
        assert_eq!(s.at(700.0), 1.1);
        assert_eq!(s.at(1000.0), 0.9);
        assert_eq!(s.at(1200.0), 1.05);
        assert_eq!(s.at(1230.0), 1.05);
        assert_eq!(s.at(1400.0), 1.0);
        let mid = s.at(900.0);
        assert!(mid < 1.1 && mid > 0.9);
        // Flat at a knot: the scale barely changes 1 mm away.
        assert!((s.at(1001.0) - 0.9).abs() < 1e-4);
    }
}
