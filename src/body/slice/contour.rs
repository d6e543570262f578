//! One closed loop of a cross-section and what a tailor measures on it.

use crate::body::mesh::Aabb;
use glam::DVec2;

/// A closed polygon in a horizontal plane (the last point connects back to the first),
/// counter-clockwise seen from above for the outside of a body.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Contour {
    /// The loop's points (x, y).
    pub points: Vec<DVec2>,
}

impl Contour {
    /// The loop's edges as point pairs, including the closing edge.
    pub(crate) fn edges(&self) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
        let next = self.points.iter().skip(1).chain(self.points.first());
        self.points.iter().copied().zip(next.copied())
    }

    /// Length of the contour itself (follows every concavity).
    pub fn perimeter(&self) -> f64 {
        self.edges().map(|(a, b)| a.distance(b)).sum()
    }

    /// The loop's bounding box (in the plane z = 0), or `None` for a loop without points.
    pub fn bounds(&self) -> Option<Aabb> {
        Aabb::around(self.points.iter().map(|p| p.extend(0.0)))
    }

    /// The centre of the loop's bounding box (paper eq. 5 and eq. 9); the origin for a loop
    /// without points.
    pub fn bbox_centre(&self) -> DVec2 {
        self.bounds().map_or(DVec2::ZERO, |b| (0.5 * (b.min + b.max)).truncate())
    }

    /// Tape girth: the perimeter of the convex hull, what a tape measure laid around reads.
    ///
    /// ```
    /// use dressform::body::slice::Contour;
    /// use glam::DVec2;
    ///
    /// // A 100 mm square with a notch 30 mm deep in one side: the tape bridges the notch.
    /// let points = [(0., 0.), (100., 0.), (100., 100.), (60., 100.), (50., 70.), (40., 100.), (0., 100.)]
    ///     .map(|(x, y)| DVec2::new(x, y))
    ///     .to_vec();
    /// let notched = Contour { points };
    /// assert!((notched.tape_girth() - 400.0).abs() < 1e-9);
    /// assert!(notched.perimeter() > 400.0); // the contour itself follows the notch
    /// ```
    pub fn tape_girth(&self) -> f64 {
        let hull = convex_hull(&self.points);
        Contour { points: hull }.perimeter()
    }

    /// Signed area (shoelace): positive when counter-clockwise.
    pub fn signed_area(&self) -> f64 {
        0.5 * self.edges().map(|(a, b)| a.perp_dot(b)).sum::<f64>()
    }

    /// Centroid of the enclosed region (falls back to the mean point for a zero-area loop).
    pub fn centroid(&self) -> DVec2 {
        // The shoelace sums of the area and of the first moments, in one pass over the edges.
        let (twice_area, sum) = self.edges().fold((0.0, DVec2::ZERO), |(area, sum), (a, b)| {
            let cross = a.perp_dot(b);
            (area + cross, sum + (a + b) * cross)
        });
        let area = 0.5 * twice_area;
        if area.abs() < f64::EPSILON {
            let n = self.points.len().max(1) as f64;
            return self.points.iter().copied().sum::<DVec2>() / n;
        }
        sum / (6.0 * area)
    }

    /// The part of the loop between the vertical lines x = `lo` and x = `hi` (Sutherland-
    /// Hodgman clipping; the cuts become straight edges along the lines).
    pub fn clip_x(&self, lo: f64, hi: f64) -> Contour {
        let keep_right = clip_half_plane(&self.points, |p| p.x - lo);
        Contour { points: clip_half_plane(&keep_right, |p| hi - p.x) }
    }

    /// The part of the loop where `normal . p <= offset` (Sutherland-Hodgman clipping; the cut
    /// becomes a straight edge along the line).
    pub fn clip_half_plane(&self, normal: DVec2, offset: f64) -> Contour {
        Contour { points: clip_half_plane(&self.points, |p| offset - normal.dot(p)) }
    }

    /// The part of the loop where `side(p) >= 0`, for a `side` linear along each edge (or
    /// nearly so: crossings are interpolated linearly); the cuts become straight edges.
    pub fn keep_where(&self, side: impl Fn(DVec2) -> f64) -> Contour {
        Contour { points: clip_half_plane(&self.points, side) }
    }

    /// How many of `points` lie inside the loop ([`Self::contains`]); the loop's bounding box
    /// is found once and the points outside it are not tested against every edge.
    pub fn count_inside<'p>(&self, points: impl IntoIterator<Item = &'p DVec2>) -> usize {
        self.inside(points).count()
    }

    /// Whether any of `points` lies inside the loop ([`Self::count_inside`]).
    pub fn holds_any<'p>(&self, points: impl IntoIterator<Item = &'p DVec2>) -> bool {
        self.inside(points).next().is_some()
    }

    /// Those of `points` inside the loop, the bounding box tested first, then only the edges
    /// of the point's [`Strips`] strip: the same answer as [`Self::contains`], without every
    /// edge for every point (a loop held against another's 2,000 points).
    fn inside<'p>(
        &self,
        points: impl IntoIterator<Item = &'p DVec2>,
    ) -> impl Iterator<Item = &'p DVec2> {
        let bounds = self.bounds();
        let strips = bounds.map(|b| Strips::new(&self.points, b.min.y, b.max.y));
        points.into_iter().filter(move |&&p| {
            bounds.is_some_and(|b| {
                (b.min.x..=b.max.x).contains(&p.x) && (b.min.y..=b.max.y).contains(&p.y)
            }) && strips.as_ref().is_some_and(|s| s.contains(&self.points, p))
        })
    }

    /// Whether `p` lies inside the loop (even-odd rule).
    pub fn contains(&self, p: DVec2) -> bool {
        let mut inside = false;
        for (a, b) in self.edges() {
            if crosses(a, b, p) {
                inside = !inside;
            }
        }
        inside
    }
}

/// A loop's edges sorted into horizontal strips, for many even-odd tests against one loop.
///
/// The even-odd test toggles only at edges whose height range holds the point's `y`; every such
/// edge is listed in the point's strip (strip numbers grow with `y`, so the strip of any `y`
/// between an edge's ends lies between theirs). Testing those edges with the same expression as
/// [`Contour::contains`] gives the same answer, bit for bit.
struct Strips {
    /// The bottom of the first strip and the strips' common height.
    y0: f64,
    height: f64,
    /// Edge numbers (edge `i` runs from point `i` to the next), strip by strip: strip `r`'s
    /// are `edges[starts[r]..starts[r + 1]]`.
    edges: Vec<u32>,
    starts: Vec<u32>,
}

/// Edges per strip on average, for a loop that goes round once (two edges cross each height).
const EDGES_PER_STRIP: usize = 4;

impl Strips {
    /// The strips of the closed polygon `points`, whose heights span `y0..=y1`.
    fn new(points: &[DVec2], y0: f64, y1: f64) -> Strips {
        let n = points.len();
        let count = (n / EDGES_PER_STRIP).max(1);
        let height = (y1 - y0) / count as f64;
        let mut strips = Strips { y0, height, edges: Vec::new(), starts: vec![0; count + 1] };
        let span = |i: usize| {
            let (a, b) = (points[i].y, points[(i + 1) % n].y);
            strips.strip(a.min(b), count)..=strips.strip(a.max(b), count)
        };
        let spans: Vec<_> = (0..n).map(span).collect();
        for r in spans.iter().flat_map(|s| s.clone()) {
            strips.starts[r + 1] += 1;
        }
        for r in 0..count {
            strips.starts[r + 1] += strips.starts[r];
        }
        let mut next = strips.starts.clone();
        strips.edges = vec![0; strips.starts[count] as usize];
        for (i, span) in spans.into_iter().enumerate() {
            for r in span {
                strips.edges[next[r] as usize] = i as u32;
                next[r] += 1;
            }
        }
        strips
    }

    /// The strip holding height `y`, of `count` (heights outside the loop's in the end ones).
    fn strip(&self, y: f64, count: usize) -> usize {
        let r = ((y - self.y0) / self.height).floor();
        if r.is_nan() { 0 } else { (r.max(0.0) as usize).min(count - 1) }
    }

    /// Whether `p` lies inside the closed polygon `points` (these strips' polygon) by the
    /// even-odd rule: [`Contour::contains`], on the edges of `p`'s strip only.
    fn contains(&self, points: &[DVec2], p: DVec2) -> bool {
        let count = self.starts.len() - 1;
        let r = self.strip(p.y, count);
        let n = points.len();
        let mut inside = false;
        for &i in &self.edges[self.starts[r] as usize..self.starts[r + 1] as usize] {
            let (a, b) = (points[i as usize], points[(i as usize + 1) % n]);
            if crosses(a, b, p) {
                inside = !inside;
            }
        }
        inside
    }
}

/// Whether the ray from `p` towards +x crosses the edge from `a` to `b` (the even-odd rule's
/// step: an edge counts at its lower end, not its upper).
fn crosses(a: DVec2, b: DVec2, p: DVec2) -> bool {
    (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)
}

/// The part of the closed polygon `points` where `side(p) >= 0` (`side` linear in `p`).
fn clip_half_plane(points: &[DVec2], side: impl Fn(DVec2) -> f64) -> Vec<DVec2> {
    let n = points.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// Convex hull of `points`, counter-clockwise, without collinear points (Andrew's monotone
/// chain). Written here because it is a dozen lines and the geometry crates that offer it
/// would bring their own point types for this one function.
pub fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in iter {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop(); // the last point of each chain starts the other
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn circle(r: f64, n: usize) -> Contour {
        Contour {
            points: (0..n)
                .map(|i| {
                    let a = 2.0 * PI * i as f64 / n as f64;
                    DVec2::new(r * a.cos(), r * a.sin())
                })
                .collect(),
        }
    }

    #[test]
    fn circle_measures() {
        let c = circle(100.0, 3600);
        assert!((c.perimeter() - 200.0 * PI).abs() < 0.01);
        assert!((c.tape_girth() - c.perimeter()).abs() < 1e-9);
        assert!((c.signed_area() - PI * 1e4).abs() < 1.0);
        assert!(c.centroid().length() < 1e-9);
        assert!(c.contains(DVec2::ZERO) && !c.contains(DVec2::new(101.0, 0.0)));
    }

    #[test]
    fn tape_bridges_a_concavity() {
        // A square with a notch: the tape reads the square's perimeter.
        let pts = [(0., 0.), (10., 0.), (10., 10.), (6., 10.), (5., 2.), (4., 10.), (0., 10.)];
        let c = Contour { points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect() };
        assert!((c.tape_girth() - 40.0).abs() < 1e-12);
        assert!(c.perimeter() > 40.0);
    }

    #[test]
    fn clipping_a_circle_to_a_band() {
        let c = circle(10.0, 3600).clip_x(-6.0, 6.0);
        assert!(c.points.iter().all(|p| p.x >= -6.0 - 1e-9 && p.x <= 6.0 + 1e-9));
        // Two arcs of half-angle acos(0.6) each side... the band keeps x in [-6, 6].
        let arc = 2.0 * 10.0 * (2.0 * (0.6f64).asin());
        let expected = arc + 2.0 * 16.0;
        assert!((c.perimeter() - expected).abs() < 0.01, "{} vs {expected}", c.perimeter());
    }

    #[test]
    fn hull_of_degenerate_input() {
        assert_eq!(convex_hull(&[]).len(), 0);
        let line = [DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0)];
        assert!(convex_hull(&line).len() <= 2);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// The strips give every point the answer of the plain even-odd test: on polygons
        /// that cross themselves, with coordinates on a coarse grid so that points often sit
        /// at a vertex's height, on an edge or on the bounding box.
        #[test]
        fn strips_agree_with_every_edge(
            corners in proptest::collection::vec((0i32..12, 0i32..12), 1..40),
            probes in proptest::collection::vec((-1i32..26, -1i32..26), 1..60),
        ) {
            let loop_ = Contour {
                points: corners.iter().map(|&(x, y)| DVec2::new(x as f64, y as f64)).collect(),
            };
            let probes: Vec<DVec2> =
                probes.iter().map(|&(x, y)| DVec2::new(x as f64 * 0.5, y as f64 * 0.5)).collect();
            let held: Vec<&DVec2> = loop_.inside(&probes).collect();
            let expected: Vec<&DVec2> = probes.iter().filter(|&&p| loop_.contains(p)).collect();
            proptest::prop_assert_eq!(held, expected);
        }
    }
}
