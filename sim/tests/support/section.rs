//! Test-only plane sections and convex-hull girths of a triangle surface (the dressform slicer
//! will replace this in the cross-crate tests).

use std::collections::HashMap;

use sim::capture::TriangleSurface;

/// The closed loops of the section of `s` by the plane at height `z`, as polygons (x, y).
pub fn section_loops(s: &TriangleSurface, z: f64) -> Vec<Vec<[f64; 2]>> {
    let p = |i: u32| s.positions[i as usize];
    let above = |i: u32| p(i)[2] >= z;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut next: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    let mut point: HashMap<(u32, u32), [f64; 2]> = HashMap::new();
    for t in &s.triangles {
        // Order the two crossed edges: the one the triangle's boundary crosses upwards first,
        // so neighbouring triangles chain head to tail.
        let mut crossing: Vec<(u32, u32)> =
            (0..3).map(|e| (t[e], t[(e + 1) % 3])).filter(|&(a, b)| above(a) != above(b)).collect();
        if crossing.len() != 2 {
            continue;
        }
        if above(crossing[0].0) {
            crossing.swap(0, 1);
        }
        for &(a, b) in &crossing {
            let (pa, pb) = (p(a), p(b));
            let u = (z - pa[2]) / (pb[2] - pa[2]);
            point.insert(key(a, b), [pa[0] + u * (pb[0] - pa[0]), pa[1] + u * (pb[1] - pa[1])]);
        }
        next.insert(key(crossing[0].0, crossing[0].1), key(crossing[1].0, crossing[1].1));
    }
    let mut loops = Vec::new();
    let mut done = std::collections::HashSet::new();
    for &start in next.keys() {
        if done.contains(&start) {
            continue;
        }
        let mut poly = Vec::new();
        let mut k = start;
        while done.insert(k) {
            poly.push(point[&k]);
            match next.get(&k) {
                Some(&n) => k = n,
                None => break,
            }
        }
        if k == start && poly.len() >= 3 {
            loops.push(poly);
        }
    }
    loops
}

/// Whether `q` lies inside the polygon (even-odd rule).
pub fn contains(poly: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > q[0] {
                inside = !inside;
            }
        }
    }
    inside
}

/// Perimeter of the convex hull of `pts`.
pub fn hull_perimeter(pts: &[[f64; 2]]) -> f64 {
    let mut p = pts.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Vec<[f64; 2]> =
            if pass == 0 { p.clone() } else { p.iter().rev().copied().collect() };
        for q in ordered {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    (0..hull.len())
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .sum()
}

/// Tape girth of the mesh at height `z`: hull perimeter of the section loop containing
/// `centre`, and how many loops the section has.
pub fn tape_girth(s: &TriangleSurface, z: f64, centre: [f64; 2]) -> Option<(f64, usize)> {
    let loops = section_loops(s, z);
    let torso = loops.iter().find(|l| contains(l, centre))?;
    Some((hull_perimeter(torso), loops.len()))
}
