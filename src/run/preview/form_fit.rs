//! `form-fit.png`: how the robotic form takes the mannequin (issue 31's picture). Left, the
//! mannequin in front and side views with every ring's skin drawn where the lifts set it (in
//! the ring's colour: dark where it stands at its body level, orange where it is off by more
//! than the default height tolerance); right, each ring from above: the mannequin's section where the ring
//! stands (grey), the form's skin (dark) and every panel as a bar coloured by its gap, blue
//! standing out from the mannequin, red pressing into it, full colour at [`FULL_GAP_MM`].

use super::raster::{self, Canvas, Colour};
use super::{BACKGROUND, FORM, INK, Level, PAD_PX, POSTERIZE_MASK, Panel, SUPERSAMPLE, TOP_PX};
use super::{VIEWS, encode_png, extent, vertex_normals};
use crate::body::slice::Contour;
use crate::form::form_fit::{
    DEFAULT_HEIGHT_TOLERANCE_MM, FormFit, region_of, ring_skin, section_at,
};
use crate::run::pipeline::Symmetrized;
use form_description::FormDescription;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Height of the mannequin in the picture (pixels).
const BODY_PX: f64 = 480.0;
/// One ring's top view: its square (pixels), and the room under it for two lines of text.
const CELL_PX: usize = 190;
const CELL_TEXT_PX: usize = 24;
/// Ring views per row.
const CELL_COLUMNS: usize = 3;
/// A gap this large (mm) gets a panel's full colour.
const FULL_GAP_MM: f64 = 20.0;
/// A ring off its level by more than this (mm) is drawn in [`OFF_COLOUR`]: the default
/// tolerance a drive judges it by.
const OFF_LEVEL_MM: f64 = DEFAULT_HEIGHT_TOLERANCE_MM;
/// Widths (pixels): a section or skin line, and a panel's bar.
const OUTLINE_PX: f64 = 1.5;
const PANEL_PX: f64 = 5.0;
/// Room under the picture for the legend (pixels).
const LEGEND_PX: usize = 42;
/// A line of text's height with its spacing (pixels: the 8-pixel font and 3-4 between).
const TEXT_LINE_PX: usize = 12;
/// Where the two header lines start (pixels from the top), and a text's inset in a cell.
const HEADER_Y: [usize; 2] = [4, 16];
const TEXT_INSET_PX: usize = 4;
/// Depths of a ring view's drawing, nearest last drawn over: the section, the skin, panels.
const SECTION_DEPTH: f64 = 3.0;
const SKIN_DEPTH: f64 = 2.0;
const PANEL_DEPTH: f64 = 1.0;

const ON_LEVEL: Colour = [0.15, 0.2, 0.35];
const OFF_COLOUR: Colour = [0.95, 0.5, 0.05];
const SECTION: Colour = [0.6, 0.6, 0.6];
const SKIN_LINE: Colour = [0.15, 0.15, 0.15];
const OUTSIDE: Colour = [0.1, 0.35, 0.9];
const PRESSING: Colour = [0.9, 0.1, 0.1];
const NEUTRAL: Colour = [0.7, 0.7, 0.7];

/// `form-fit.png` of `fit` (a fit of `form` to the mannequin of `result`), encoded as PNG.
pub fn form_fit_png(result: &Symmetrized, fit: &FormFit, form: &FormDescription) -> Vec<u8> {
    let m = &result.mannequin;
    let axis = DVec2::new(result.profiles.axis_x, 0.0);
    // The rings' skins where they stand, in the mannequin's frame.
    let levels: Vec<Level> = (form.rings.iter())
        .zip(&fit.rings)
        .map(|(ring, r)| {
            let skin = ring_skin(form, ring, &fit.positions_mm);
            let contour = Contour { points: skin.points.iter().map(|&p| p + axis).collect() };
            let colour = if r.offset_mm.abs() > OFF_LEVEL_MM { OFF_COLOUR } else { ON_LEVEL };
            Level { z: r.form_height_mm, contour: Some(contour), colour }
        })
        .collect();
    let normals = vertex_normals(&m.mesh);
    let bounds = crate::body::mesh::Aabb::around(m.mesh.positions.iter().copied());
    let Some(bounds) = bounds else { return encode_png(1, 1, &[255; 3]) };
    let scale = BODY_PX / bounds.size().z;
    let body_height = TOP_PX + BODY_PX.ceil() as usize + PAD_PX as usize;
    let views = [&VIEWS[0], &VIEWS[2]];
    let panels: Vec<Panel> = views
        .iter()
        .map(|view| {
            let (lo, hi) = extent(&m.mesh, view);
            let width = ((hi - lo) * scale + 2.0 * PAD_PX).ceil() as usize;
            Panel {
                mesh: &m.mesh,
                normals: &normals,
                colour: FORM,
                levels: &levels,
                view,
                left_mm: lo,
                width,
            }
        })
        .collect();
    let rendered: Vec<Image> = panels
        .par_iter()
        .map(|p| p.render(scale, bounds.max.z, body_height).downsample(SUPERSAMPLE))
        .collect();
    let cells = ring_cells(result, fit, form);
    let rows = fit.rings.len().div_ceil(CELL_COLUMNS);
    let cells_width = CELL_COLUMNS * CELL_PX;
    let cells_height = TOP_PX + rows * (CELL_PX + CELL_TEXT_PX);
    let bodies_width: usize = rendered.iter().map(|r| r.0).sum();
    let width = bodies_width + cells_width + 2 * PAD_PX as usize;
    let height = body_height.max(cells_height) + LEGEND_PX;
    let mut rgb = vec![255u8; width * height * 3];
    let mut x = 0;
    for ((w, h, pixels), view) in rendered.iter().zip(views) {
        blit(&mut rgb, width, (x, 0), (*w, *h), pixels);
        raster::text(&mut rgb, width, (x + PAD_PX as usize, HEADER_Y[0]), view.name, 1, INK);
        x += w;
    }
    let title = "the form's rings over the mannequin";
    raster::text(&mut rgb, width, (PAD_PX as usize, HEADER_Y[1]), title, 1, INK);
    let x0 = x + 2 * PAD_PX as usize;
    raster::text(&mut rgb, width, (x0, HEADER_Y[0]), "each ring from above", 1, INK);
    for (k, ((w, h, pixels), lines)) in cells.iter().enumerate() {
        let (col, row) = (k % CELL_COLUMNS, k / CELL_COLUMNS);
        let (cx, cy) = (x0 + col * CELL_PX, TOP_PX + row * (CELL_PX + CELL_TEXT_PX));
        blit(&mut rgb, width, (cx, cy), (*w, *h), pixels);
        for (i, line) in lines.iter().enumerate() {
            let y = cy + CELL_PX + TEXT_INSET_PX / 2 + (TEXT_LINE_PX - 1) * i;
            raster::text(&mut rgb, width, (cx + TEXT_INSET_PX, y), line, 1, INK);
        }
    }
    let legend = [
        format!("rings: dark at their body level, orange off it by over {OFF_LEVEL_MM} mm"),
        "from above, front down: grey the mannequin's section, black the form's skin;".to_string(),
        format!(
            "panels blue standing out from the mannequin, red pressing in (full at {FULL_GAP_MM} mm)"
        ),
    ];
    for (k, line) in legend.iter().enumerate() {
        let y = height - LEGEND_PX + TEXT_INSET_PX + TEXT_LINE_PX * k;
        raster::text(&mut rgb, width, (PAD_PX as usize, y), line, 1, INK);
    }
    rgb.iter_mut().for_each(|v| *v &= POSTERIZE_MASK);
    encode_png(width, height, &rgb)
}

/// An 8-bit RGB image: width, height, pixels row by row.
type Image = (usize, usize, Vec<u8>);

/// Each ring's top view and its two lines of text.
fn ring_cells(
    result: &Symmetrized,
    fit: &FormFit,
    form: &FormDescription,
) -> Vec<(Image, [String; 2])> {
    let profiles = &result.profiles;
    let views: Vec<(Option<Contour>, Contour, DVec2)> = (form.rings.iter())
        .zip(&fit.rings)
        .map(|(ring, r)| {
            let section = section_at(profiles, region_of(ring), r.form_height_mm);
            (section, ring_skin(form, ring, &fit.positions_mm), DVec2::from_array(ring.center_mm))
        })
        .collect();
    // One scale for all: the widest skin or section fills a cell.
    let reach = views
        .iter()
        .flat_map(|(section, skin, centre)| {
            let section = section.iter().flat_map(|c| c.points.iter());
            section.chain(&skin.points).map(move |p| (*p - *centre).abs().max_element())
        })
        .fold(1.0, f64::max);
    let ss = SUPERSAMPLE as f64;
    let scale = (0.5 * CELL_PX as f64 - PAD_PX) / reach;
    (form.rings.iter())
        .zip(&fit.rings)
        .zip(&views)
        .map(|((ring, r), (section, skin, centre))| {
            let mut canvas = Canvas::new(CELL_PX * SUPERSAMPLE, CELL_PX * SUPERSAMPLE, BACKGROUND);
            let half = 0.5 * CELL_PX as f64;
            // Seen from above, the front (-Y) down: screen x = x, screen y = -y.
            let at = |p: DVec2, depth: f64| {
                let q = p - *centre;
                DVec3::new((half + q.x * scale) * ss, (half - q.y * scale) * ss, depth)
            };
            let outline = |canvas: &mut Canvas, c: &Contour, colour: Colour, depth: f64| {
                let n = c.points.len();
                for k in 0..n {
                    let (a, b) = (c.points[k], c.points[(k + 1) % n]);
                    canvas.line(at(a, depth), at(b, depth), OUTLINE_PX * ss, colour);
                }
            };
            if let Some(section) = section {
                outline(&mut canvas, section, SECTION, SECTION_DEPTH);
            }
            outline(&mut canvas, skin, SKIN_LINE, SKIN_DEPTH);
            for a in form.actuators.iter().filter(|a| a.ring == ring.name) {
                let e = fit.positions_mm.get(&a.id).copied().unwrap_or(0.0);
                let [p, q] = a
                    .panel_ends(ring.center_mm, e)
                    .map(|end| at(DVec2::from_array(end), PANEL_DEPTH));
                let gap = r.panel_gaps_mm.get(&a.id).copied().unwrap_or(0.0);
                canvas.line(p, q, PANEL_PX * ss, gap_colour(gap));
            }
            let lines = [
                format!("{} z{:.0} {:+.1}", r.ring, r.form_height_mm, r.offset_mm),
                format!("gap rms {:.1} max {:.1}", r.rms_radial_gap_mm, r.largest_radial_gap_mm),
            ];
            (canvas.downsample(SUPERSAMPLE), lines)
        })
        .collect()
}

/// A panel's colour for its gap: [`NEUTRAL`] at 0, towards [`OUTSIDE`] standing out and
/// [`PRESSING`] pressing in, full at [`FULL_GAP_MM`].
fn gap_colour(gap: f64) -> Colour {
    let t = (gap.abs() / FULL_GAP_MM).min(1.0) as f32;
    let to = if gap >= 0.0 { OUTSIDE } else { PRESSING };
    std::array::from_fn(|i| NEUTRAL[i] + t * (to[i] - NEUTRAL[i]))
}

/// Copies the `size` RGB image `pixels` into `rgb` (`width` wide) at `at`.
fn blit(rgb: &mut [u8], width: usize, at: (usize, usize), size: (usize, usize), pixels: &[u8]) {
    let height = rgb.len() / 3 / width;
    for row in 0..size.1.min(height.saturating_sub(at.1)) {
        let w = size.0.min(width.saturating_sub(at.0));
        let to = 3 * ((at.1 + row) * width + at.0);
        rgb[to..to + 3 * w].copy_from_slice(&pixels[3 * row * size.0..3 * row * size.0 + 3 * w]);
    }
}
