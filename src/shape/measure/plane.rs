//! Sections of a body by a plane that need not be horizontal, and what a tape reads along
//! them: a limb's girth across its axis, the neck base's girth, the arc over the shoulders.
//!
//! The body is turned so that the plane becomes z = 0 and cut there by the ordinary slicer,
//! so an oblique section is as exact as a horizontal one.

use crate::body::mesh::Mesh;
use crate::body::slice::{Contour, convex_hull, sections};
use glam::{DQuat, DVec2, DVec3};

/// One loop of a body's section by a plane, in the plane's own 2-D coordinates.
pub struct PlaneLoop {
    /// The point the loop was looked for around; the plane's origin.
    origin: DVec3,
    /// Turns body directions into the plane's frame (the plane's normal onto +Z).
    turn: DQuat,
    /// The loop in the plane's coordinates (mm).
    pub contour: Contour,
}

impl PlaneLoop {
    /// The loop of `body`'s section by the plane through `origin` with `normal` that holds
    /// `origin`, or else the one whose centroid is nearest; `None` if the plane misses.
    pub fn around(body: &Mesh, origin: DVec3, normal: DVec3) -> Option<PlaneLoop> {
        let turn = DQuat::from_rotation_arc(normal.normalize(), DVec3::Z);
        let turned = body.map_positions(|p| turn * (p - origin));
        let section = sections(&turned, &[0.0]).swap_remove(0);
        let distance =
            |c: &Contour| if c.contains(DVec2::ZERO) { 0.0 } else { c.centroid().length() };
        let contour =
            section.loops.into_iter().min_by(|a, b| distance(a).total_cmp(&distance(b)))?;
        Some(PlaneLoop { origin, turn, contour })
    }

    /// A body point projected into the plane's coordinates.
    pub fn to_plane(&self, p: DVec3) -> DVec2 {
        (self.turn * (p - self.origin)).truncate()
    }

    /// A point of the plane in body coordinates.
    pub fn to_body(&self, p: DVec2) -> DVec3 {
        self.origin + self.turn.inverse() * p.extend(0.0)
    }
}

/// What a tape laid over `contour` reads from its point nearest `from` to its point nearest
/// `to`, along the side of the loop that holds its point nearest `through`: the tape bridges
/// hollows as it does around a girth, so this is the outer chain of the convex hull of that
/// stretch of the loop (the chain on `through`'s side of the chord between the ends).
pub fn tape_arc(contour: &Contour, from: DVec2, to: DVec2, through: DVec2) -> f64 {
    let points = &contour.points;
    let n = points.len();
    let nearest = |ps: &[DVec2], q: DVec2| {
        (0..ps.len()).min_by(|&a, &b| ps[a].distance(q).total_cmp(&ps[b].distance(q)))
    };
    let (Some(a), Some(b), Some(t)) =
        (nearest(points, from), nearest(points, to), nearest(points, through))
    else {
        return 0.0;
    };
    // Walking forward from a to b, is t passed? Else the stretch is the other way round.
    let steps = |from: usize, to: usize| (to + n - from) % n;
    let (start, len) = if steps(a, t) <= steps(a, b) { (a, steps(a, b)) } else { (b, steps(b, a)) };
    let stretch: Vec<DVec2> = (0..=len).map(|k| points[(start + k) % n]).collect();
    let hull = convex_hull(&stretch);
    let (Some(ha), Some(hb)) = (nearest(&hull, points[a]), nearest(&hull, points[b])) else {
        return 0.0;
    };
    // The hull's two chains between the ends; the tape lies along the one on the outer side.
    let chain = |from: usize, to: usize| -> Vec<DVec2> {
        let m = hull.len();
        (0..=(to + m - from) % m).map(|k| hull[(from + k) % m]).collect()
    };
    let (pa, pb) = (hull[ha], hull[hb]);
    let side = |p: DVec2| (pb - pa).perp_dot(p - pa);
    // `through`'s side; where it lies on the chord, the side away from the loop's centre.
    let outer = match side(points[t]) {
        0.0 => -side(contour.centroid()).signum(),
        s => s.signum(),
    };
    let bulge = |c: &[DVec2]| c.iter().map(|&p| outer * side(p)).fold(0.0, f64::max);
    let (one, other) = (chain(ha, hb), chain(hb, ha));
    let tape = if bulge(&one) >= bulge(&other) { one } else { other };
    tape.windows(2).map(|w| w[0].distance(w[1])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn circle(centre: DVec2, radius: f64, count: usize) -> Vec<DVec2> {
        (0..count)
            .map(|k| centre + DVec2::from_angle(TAU * k as f64 / count as f64) * radius)
            .collect()
    }

    #[test]
    fn a_tape_over_half_a_circle_reads_half_its_perimeter() {
        let c = Contour { points: circle(DVec2::ZERO, 100.0, 3600) };
        let arc = tape_arc(&c, DVec2::new(100.0, 0.0), DVec2::new(-100.0, 0.0), DVec2::Y * 100.0);
        assert!((arc - PI * 100.0).abs() < 0.01, "{arc}");
        let other = tape_arc(&c, DVec2::new(100.0, 0.0), DVec2::new(-100.0, 0.0), -DVec2::Y);
        assert!((other - PI * 100.0).abs() < 0.01, "{other}");
        let quarter = tape_arc(&c, DVec2::new(100.0, 0.0), DVec2::Y * 100.0, DVec2::ONE);
        assert!((quarter - PI * 50.0).abs() < 0.01, "{quarter}");
    }

    #[test]
    fn a_tape_bridges_a_hollow_in_the_stretch() {
        // A square 200 mm wide with a notch 30 mm deep in its top side: over the top, a tape
        // from corner to corner reads the straight 200 mm.
        let points = [
            (-100., -100.),
            (100., -100.),
            (100., 100.),
            (10., 100.),
            (0., 70.),
            (-10., 100.),
            (-100., 100.),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
        let c = Contour { points };
        let arc =
            tape_arc(&c, DVec2::new(100., 100.), DVec2::new(-100., 100.), DVec2::new(0., 90.));
        assert!((arc - 200.0).abs() < 1e-9, "{arc}");
    }
}
