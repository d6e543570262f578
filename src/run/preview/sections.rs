//! `sections.svg` (paper Fig. 9 and 11): at the chest, waist and hip, seen from above with the
//! front at the bottom, the scan's section, the sections of the bodies made by mirroring its
//! left and its right half, and the mannequin's symmetric ring, with their tape girths.
//! Written as text: the figure is a few paths and labels.

use crate::body::mesh::Mesh;
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use crate::run::pipeline::Symmetrized;
use glam::DVec2;
use std::fmt::Write;

/// Pixels per millimetre.
const SCALE: f64 = 0.8;
/// Margin around each panel's drawing (pixels).
const MARGIN: f64 = 20.0;
/// Room for the panel's title above and its legend below (pixels).
const TITLE: f64 = 24.0;
const LEGEND: f64 = 70.0;

/// The four curves of a panel, in drawing order: name, stroke colour, stroke width, dash
/// pattern. The mannequin's ring goes first, wide and light, so the others show on it.
const STYLES: [(&str, &str, f64, &str); 4] = [
    ("mannequin", "#b0b0b0", 4.0, ""),
    ("scan", "#000000", 1.0, ""),
    ("left-mirrored", "#1f77b4", 1.2, "6 3"),
    ("right-mirrored", "#ff7f0e", 1.2, "2 3"),
];

/// The part of `c` on one side of x = `axis` with its mirror image: the section of the body
/// made by mirroring that half (two closed paths that meet on the plane, where they share a
/// cut edge that is no part of the outline).
fn mirrored(c: &Contour, axis: f64, left: bool) -> [Contour; 2] {
    let half = if left { c.clip_x(axis, f64::INFINITY) } else { c.clip_x(f64::NEG_INFINITY, axis) };
    let image =
        Contour { points: half.points.iter().map(|p| DVec2::new(2.0 * axis - p.x, p.y)).collect() };
    [half, image]
}

/// How close to the symmetry plane both ends of an edge lie for it to be a cut along the plane
/// (mm): the clipping interpolates, so its points sit on the plane up to rounding.
const ON_PLANE_MM: f64 = 1e-6;

/// An SVG path through closed `loops`, drawn with `to_svg`, leaving out the edges that lie on
/// the plane x = `seam` (where a mirrored half meets its image, the body has no outline).
fn path(loops: &[&Contour], seam: Option<f64>, to_svg: &dyn Fn(DVec2) -> DVec2) -> String {
    let mut d = String::new();
    for c in loops {
        let n = c.points.len();
        let on_seam = |i: usize| {
            let (a, b) = (c.points[i], c.points[(i + 1) % n]);
            seam.is_some_and(|x| (a.x - x).abs() < ON_PLANE_MM && (b.x - x).abs() < ON_PLANE_MM)
        };
        // Start just after an edge left out, if any, so each stretch is drawn in one piece.
        let start = (0..n).find(|&i| on_seam(i)).map_or(0, |i| (i + 1) % n);
        let mut pen_down = false;
        for step in 0..n {
            let i = (start + step) % n;
            let q = to_svg(c.points[i]);
            let _ = write!(d, "{}{:.1} {:.1} ", if pen_down { "L" } else { "M" }, q.x, q.y);
            pen_down = !on_seam(i);
        }
        if pen_down {
            let q = to_svg(c.points[start]);
            let _ = write!(d, "L{:.1} {:.1} ", q.x, q.y);
        }
    }
    d
}

/// `sections.svg` for `scan` (the body the mannequin was built from, canonical frame) and
/// `result`.
pub fn sections_svg(scan: &Mesh, result: &Symmetrized) -> String {
    let m = &result.mannequin;
    let c = &result.comparison;
    let heights = [c.levels.chest, c.levels.waist, c.levels.hip];
    let sections = SegmentedBody::with_regions(scan, &result.regions).torso_sections(&heights);
    let empty = Contour::default();
    let rings: Vec<Contour> = heights
        .iter()
        .map(|&z| {
            let layer = m.torso.iter().min_by(|a, b| (a.z - z).abs().total_cmp(&(b.z - z).abs()));
            Contour { points: layer.map_or_else(Vec::new, |l| l.points.clone()) }
        })
        .collect();
    // One frame for all panels: the sections' extent around the symmetry plane.
    let all = sections.iter().flatten().chain(&rings).flat_map(|c| c.points.iter());
    let (lo, hi) = all
        .fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let half_width = (hi.x - m.axis).max(m.axis - lo.x);
    let (panel_w, drawing_h) =
        (2.0 * (half_width * SCALE + MARGIN), (hi.y - lo.y) * SCALE + 2.0 * MARGIN);
    let panel_h = TITLE + drawing_h + LEGEND;

    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" font-family="sans-serif" font-size="12">"#,
        3.0 * panel_w,
        panel_h
    );
    let _ = writeln!(
        svg,
        "<title>Sections at the chest, waist and hip seen from above, front at the bottom: the scan, \
         the left- and right-mirrored bodies and the symmetric mannequin (paper Fig. 9 and 11)</title>"
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, row) in c.table.iter().enumerate() {
        let x0 = k as f64 * panel_w;
        let to_svg = |p: DVec2| {
            DVec2::new(
                x0 + panel_w / 2.0 + (p.x - m.axis) * SCALE,
                TITLE + MARGIN + (hi.y - p.y) * SCALE,
            )
        };
        let section = sections[k].as_ref().unwrap_or(&empty);
        let [l0, l1] = mirrored(section, m.axis, true);
        let [r0, r1] = mirrored(section, m.axis, false);
        let curves: [(Vec<&Contour>, Option<f64>); 4] = [
            (vec![&rings[k]], None),
            (vec![section], None),
            (vec![&l0, &l1], Some(m.axis)),
            (vec![&r0, &r1], Some(m.axis)),
        ];
        let mirrored_row = |body: &str| c.mirrored.iter().find(|r| r.body == body);
        let girth_of =
            |body: &str| mirrored_row(body).map_or(0.0, |r| [r.chest, r.waist, r.hip][k]);
        let girths = [
            row.mannequin.tape,
            row.input.tape,
            girth_of("left-mirrored"),
            girth_of("right-mirrored"),
        ];
        let _ = writeln!(
            svg,
            r#"<text x="{:.0}" y="16" font-weight="bold">{} (z = {:.0} mm)</text>"#,
            x0 + MARGIN,
            row.measure,
            row.z
        );
        let axis_x = x0 + panel_w / 2.0;
        let _ = writeln!(
            svg,
            r##"<line x1="{axis_x:.1}" y1="{:.1}" x2="{axis_x:.1}" y2="{:.1}" stroke="#bbbbbb" stroke-dasharray="1 3"/>"##,
            TITLE,
            TITLE + drawing_h
        );
        for (k_curve, ((name, colour, width, dash), (loops, seam))) in
            STYLES.iter().zip(&curves).enumerate()
        {
            let dash = if dash.is_empty() {
                String::new()
            } else {
                format!(r#" stroke-dasharray="{dash}""#)
            };
            let _ = writeln!(
                svg,
                r#"<path d="{}" fill="none" stroke="{colour}" stroke-width="{width}"{dash}/>"#,
                path(loops, *seam, &to_svg).trim_end()
            );
            let _ = writeln!(
                svg,
                r#"<text x="{:.0}" y="{:.0}" fill="{colour}">{name}: tape girth {:.1} mm</text>"#,
                x0 + MARGIN,
                TITLE + drawing_h + 14.0 * (k_curve + 1) as f64,
                girths[k_curve]
            );
        }
    }
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mirrored_half_is_drawn_without_its_cut_along_the_plane() {
        let square = Contour {
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 1.0),
            ],
        };
        let same = |p: DVec2| p;
        assert_eq!(path(&[&square], Some(0.0), &same), "M0.0 0.0 L1.0 0.0 L1.0 1.0 L0.0 1.0 ");
        assert_eq!(
            path(&[&square], None, &same),
            "M0.0 0.0 L1.0 0.0 L1.0 1.0 L0.0 1.0 L0.0 0.0 ",
            "a whole section is closed"
        );
    }
}
