//! The skin over a ring: what a tape measure or a garment lying on the ring touches.
//!
//! A ring's panels are flat plates; the skin stretched over them is the convex hull of the
//! panels' ends ([`ActuatorSpec::panel_ends`]) in the ring's plane, a polygon that turns only
//! at its corners. Its perimeter is the ring's girth on the form. A panel's *share* of the skin
//! is half of each skin edge at its corners: where a band lying on the ring presses, the
//! panel carries that length of it (0 for a panel under its neighbours' skin). The host uses
//! it to turn a panel's measured force into a contact pressure, the simulator to put a
//! garment's load on the panels; both read it from here.

use std::collections::BTreeMap;

use super::description::{ActuatorSpec, FormDescription};

/// kPa per N/mm²: a force over a contact area in mm² as a pressure.
pub const KPA_PER_N_PER_MM2: f64 = 1000.0;

/// One corner of a ring's skin: a panel's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkinCorner {
    /// Where it is, mm, in the form's X-Y plane.
    pub point: [f64; 2],
    /// Whose end it is: an index into [`RingSkin::actuators`].
    pub panel: usize,
}

/// The skin over one ring at given actuator extensions.
#[derive(Clone, Debug, PartialEq)]
pub struct RingSkin<'a> {
    /// The ring's actuators, in description order.
    pub actuators: Vec<&'a ActuatorSpec>,
    /// The skin's corners, counter-clockwise seen from above, without collinear or repeated
    /// points.
    pub corners: Vec<SkinCorner>,
}

impl<'a> RingSkin<'a> {
    /// The skin over `ring` of `form` with the actuators at `positions_mm` (id → extension,
    /// mm; missing ones retracted); `None` for a ring the form lacks or without actuators.
    pub fn of(
        form: &'a FormDescription,
        ring: &str,
        positions_mm: &BTreeMap<String, f64>,
    ) -> Option<Self> {
        let ring = form.ring(ring)?;
        let actuators: Vec<&ActuatorSpec> =
            form.actuators.iter().filter(|a| a.ring == ring.name).collect();
        if actuators.is_empty() {
            return None;
        }
        let mut ends = Vec::with_capacity(2 * actuators.len());
        for (panel, a) in actuators.iter().enumerate() {
            let extension = positions_mm.get(&a.id).copied().unwrap_or(0.0);
            ends.extend(
                a.panel_ends(ring.center_mm, extension).map(|point| SkinCorner { point, panel }),
            );
        }
        Some(Self { actuators, corners: convex_hull(ends) })
    }

    /// The edge from corner `i` to the next, mm.
    pub fn edge(&self, i: usize) -> [f64; 2] {
        let n = self.corners.len();
        let (a, b) = (self.corners[i].point, self.corners[(i + 1) % n].point);
        [b[0] - a[0], b[1] - a[1]]
    }

    /// The skin's perimeter: the ring's girth on the form, mm.
    pub fn girth_mm(&self) -> f64 {
        (0..self.corners.len()).map(|i| length(self.edge(i))).sum()
    }

    /// The pull a band of unit tension (per unit width) puts on corner `i`: along the edge
    /// after it minus along the edge before it (a vector of length `2 sin(θ/2)` for a turn by
    /// `θ`, pointing into the ring: the capstan balance of a string over a peg); zero at a
    /// corner with a zero-length edge.
    pub fn corner_pull(&self, i: usize) -> [f64; 2] {
        let n = self.corners.len();
        let (before, after) = (self.edge((i + n - 1) % n), self.edge(i));
        let (l_in, l_out) = (length(before), length(after));
        if l_in == 0.0 || l_out == 0.0 {
            return [0.0, 0.0];
        }
        [after[0] / l_out - before[0] / l_in, after[1] / l_out - before[1] / l_in]
    }

    /// How a band of unit tension per unit width loads each panel, by index into
    /// [`Self::actuators`] (see [`PanelGain`]).
    pub fn gains(&self) -> Vec<PanelGain> {
        let mut gains = vec![PanelGain { axial: 0.0, normal: 0.0 }; self.actuators.len()];
        for (i, corner) in self.corners.iter().enumerate() {
            let pull = self.corner_pull(i);
            let [dx, dy] = self.actuators[corner.panel].direction();
            let gain = &mut gains[corner.panel];
            gain.axial += (-(pull[0] * dx + pull[1] * dy)).max(0.0);
            gain.normal += length(pull);
        }
        gains
    }

    /// Every panel's share of the skin, mm, by index into [`Self::actuators`]: half of each
    /// edge at its corners (they add up to the girth).
    pub fn shares_mm(&self) -> Vec<f64> {
        let n = self.corners.len();
        let mut shares = vec![0.0; self.actuators.len()];
        for i in 0..n {
            let half_edges = 0.5 * (length(self.edge((i + n - 1) % n)) + length(self.edge(i)));
            shares[self.corners[i].panel] += half_edges;
        }
        shares
    }
}

/// How a band lying on the skin loads one panel, per unit of the band's tension times its
/// width (N per N): the sum over the panel's corners of the pull's part along the actuator,
/// inwards (`axial`: what its force sensor measures), and of the whole pull (`normal`: what
/// presses on the panel, the lateral part carried by its guides). A panel under its
/// neighbours' skin has neither. A measured force `F` thus means a band force `F / axial` per
/// unit gain, pressing with `F × normal / axial` (Laplace's law on the polygon: the normals add
/// up to `Σ 2 sin(θ/2)`, within a percent of the circle's `2π` for a ring of eight panels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelGain {
    /// Along the actuator, inwards.
    pub axial: f64,
    /// The whole press.
    pub normal: f64,
}

/// The length of a vector, mm.
pub fn length(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

/// The convex hull of `points`, counter-clockwise, without collinear or repeated points
/// (Andrew's monotone chain). Written here rather than taken from a geometry crate: a skin
/// is a few dozen points, and this crate is shared by the host and the simulator with no
/// geometry dependency.
fn convex_hull(mut points: Vec<SkinCorner>) -> Vec<SkinCorner> {
    points
        .sort_by(|a, b| a.point[0].total_cmp(&b.point[0]).then(a.point[1].total_cmp(&b.point[1])));
    if points.len() < 3 {
        return points;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<SkinCorner> = Vec::with_capacity(2 * points.len());
    for pass in [false, true] {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &SkinCorner>> =
            if pass { Box::new(points.iter().rev()) } else { Box::new(points.iter()) };
        for &p in ordered {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2].point, hull[hull.len() - 1].point, p.point) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ActuatorSpec, reference};

    /// Four panels 100 mm wide at 100 mm from the axis: the skin is an octagon whose corners
    /// (the panels' ends) all turn 45 degrees. At a corner the band's pull per unit tension is
    /// `2 sin(22.5°)` = 0.765 across the corner, of which 0.707 lies along the panel's
    /// actuator (by hand: the edges leave along (1, 0) and (1, 1)/√2). Each panel has two
    /// corners: axial √2, normal 4 sin(π/8).
    #[test]
    fn a_bands_press_splits_into_the_actuators_part_and_the_guides_by_hand() {
        let mut spec = reference().into_spec();
        spec.lifts.clear();
        spec.nodes.retain(|n| n.address == 1);
        spec.rings.retain(|r| r.name == "chest");
        spec.actuators = (0..4)
            .map(|k| ActuatorSpec {
                id: format!("p{k}"),
                node: 1,
                channel: k as u8,
                ring: "chest".into(),
                angle_deg: 90.0 * k as f64,
                base_radius_mm: 100.0,
                panel_width_mm: 100.0,
                stroke_mm: 50.0,
                max_speed_mm_s: 10.0,
                max_accel_mm_s2: 50.0,
                force_limit_n: None,
                mirror: match k {
                    1 => Some("p3".into()),
                    _ => None,
                },
            })
            .collect();
        let form = FormDescription::try_from(spec).unwrap();
        let skin = RingSkin::of(&form, "chest", &BTreeMap::new()).unwrap();
        assert_eq!(skin.corners.len(), 8);
        let quarter = std::f64::consts::FRAC_PI_8;
        for gain in skin.gains() {
            assert!((gain.axial - 2.0f64.sqrt()).abs() < 1e-9, "{gain:?}");
            assert!((gain.normal - 4.0 * quarter.sin()).abs() < 1e-9, "{gain:?}");
        }
        for share in skin.shares_mm() {
            // Its own 100 mm and half of each 70.7 mm gap edge beside it.
            assert!((share - (100.0 + 50.0 * 2.0f64.sqrt())).abs() < 1e-9, "{share}");
        }
    }

    /// On the reference form's waist, retracted and extended: the shares add up to the girth,
    /// the side panels carry the skin while the front and back ones lie under their
    /// neighbours' (the waist is an ellipse), and moving every panel out by `d` grows the
    /// girth by less than the `2π d` of a circle.
    #[test]
    fn shares_add_up_to_the_girth() {
        let form = reference();
        let retracted = RingSkin::of(&form, "waist", &BTreeMap::new()).unwrap();
        let out: BTreeMap<String, f64> =
            retracted.actuators.iter().map(|a| (a.id.clone(), 10.0)).collect();
        let extended = RingSkin::of(&form, "waist", &out).unwrap();
        for skin in [&retracted, &extended] {
            let shares = skin.shares_mm();
            assert!((shares.iter().sum::<f64>() - skin.girth_mm()).abs() < 1e-9);
            assert!(shares.iter().all(|&s| s >= 0.0), "{shares:?}");
            let side = skin.actuators.iter().position(|a| a.angle_deg == 90.0).unwrap();
            assert!(shares[side] > 0.0, "{shares:?}");
        }
        let growth = extended.girth_mm() - retracted.girth_mm();
        assert!(growth > 0.0 && growth <= std::f64::consts::TAU * 10.0 + 1e-9, "{growth}");
        assert!(RingSkin::of(&form, "no-such-ring", &BTreeMap::new()).is_none());
    }
}
