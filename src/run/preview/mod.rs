//! Pictures of a result, so that every run can be looked at:
//! - `preview.png` ([`preview_png`]): the scan (and for `reconstruct` its pose-symmetric body)
//!   and the mannequin side by side in front,
//!   three-quarter and side views, shaded, with the chest, waist and hip levels drawn around
//!   both as a tape would lie, and their girths in a legend; software-rendered
//!   ([`raster`]: a depth buffer, 2×2 supersampling);
//! - `sections.svg` ([`sections_svg`], paper Fig. 9 and 11): at the chest, waist and hip, the
//!   scan's section, the sections of the left- and right-mirrored bodies and the symmetric ring
//!   overlaid, with their girths.
//!
//! - `form-fit.png` ([`form_fit_png`]): the robotic form's rings over the mannequin where the
//!   lifts set them, and each ring seen from above: the mannequin's section there, the form's
//!   skin and its panels coloured by their gap.
//! - `fit.png` and `sweep.svg` ([`fit_png`], [`sweep_svg`]): a garment's fit test on the
//!   form: each ring from above with its panels coloured by pressure, and the pressure
//!   against girth through a size sweep.
//!
//! They draw the canonical frame: heights on the scan and on the mannequin line up.

mod fit_test;
mod form_fit;
mod raster;
mod sections;

pub use fit_test::{fit_png, sweep_svg};
pub use form_fit::form_fit_png;
pub use sections::sections_svg;

use crate::body::mesh::Mesh;
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use crate::run::pipeline::Symmetrized;
use glam::DVec3;
use raster::{Canvas, Colour};
use rayon::prelude::*;

/// A view: its name and the camera's turn about the vertical from the front (degrees,
/// towards the subject's left).
struct View {
    name: &'static str,
    yaw_deg: f64,
}

/// The three views: front, three-quarter (35 degrees, as `shared/tools/look.py` draws it)
/// and side (from the subject's left).
const VIEWS: [View; 3] = [
    View { name: "front", yaw_deg: 0.0 },
    View { name: "three-quarter", yaw_deg: 35.0 },
    View { name: "side", yaw_deg: 90.0 },
];

/// Height of the standing scan in the picture (pixels).
const BODY_PX: f64 = 400.0;
/// Supersampling factor in each direction (anti-aliasing).
const SUPERSAMPLE: usize = 2;
/// Margin around a body in its panel (pixels).
const PAD_PX: f64 = 8.0;
/// Room above the bodies for the view names and below them for the legend (pixels).
const TOP_PX: usize = 30;
const BOTTOM_PX: usize = 44;
/// Extra room between two views (pixels).
const VIEW_GAP_PX: usize = 12;
/// How far the level lines are drawn in front of the surface (mm), so that they show on it.
const LINE_LIFT_MM: f64 = 4.0;
/// Width of a level line (pixels).
const LINE_PX: f64 = 1.5;

const BACKGROUND: Colour = [1.0, 1.0, 1.0];
const SKIN: Colour = [0.84, 0.71, 0.59];
const FORM: Colour = [0.86, 0.85, 0.80];
/// Chest, waist and hip, in the colours of `sections.svg`.
const LEVEL_COLOURS: [Colour; 3] = [[0.84, 0.15, 0.16], [0.17, 0.63, 0.17], [0.12, 0.47, 0.71]];
const INK: [u8; 3] = [40, 40, 40];
/// Keeps the top 6 bits of each colour channel (see [`preview_rgb`]).
const POSTERIZE_MASK: u8 = 0b1111_1100;
/// Light: ambient part, the rest Lambertian.
const AMBIENT: f32 = 0.25;

/// The camera of a view: screen right, the direction the camera looks along (depth), up.
fn camera(view: &View) -> (DVec3, DVec3) {
    let a = view.yaw_deg.to_radians();
    (DVec3::new(a.cos(), a.sin(), 0.0), DVec3::new(-a.sin(), a.cos(), 0.0))
}

/// Unit vertex normals: the area-weighted sum of the normals of the triangles around each
/// vertex.
fn vertex_normals(mesh: &Mesh) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let n = mesh.scaled_normal(t);
        for &v in tri {
            normals[v as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// A line drawn around a body as a tape would lie: a closed contour (canonical frame) at a
/// height, in a colour; `None` where the body has no section.
struct Level {
    z: f64,
    contour: Option<Contour>,
    colour: Colour,
}

impl Level {
    /// The chest, waist and hip lines of `contours` at `heights`, in [`LEVEL_COLOURS`].
    fn measured(contours: Vec<Option<Contour>>, heights: [f64; 3]) -> Vec<Level> {
        (contours.into_iter().zip(heights).zip(LEVEL_COLOURS))
            .map(|((contour, z), colour)| Level { z, contour, colour })
            .collect()
    }
}

/// One body in one view: what to draw and where.
struct Panel<'a> {
    mesh: &'a Mesh,
    normals: &'a [DVec3],
    colour: Colour,
    /// The lines around this body.
    levels: &'a [Level],
    view: &'a View,
    /// Left edge of the body's extent in the view (mm along screen right) and the panel's
    /// width (final pixels).
    left_mm: f64,
    width: usize,
}

impl Panel<'_> {
    /// Renders the panel at `scale` pixels per mm (supersampled), the crown at `top_mm`.
    fn render(&self, scale: f64, top_mm: f64, height: usize) -> Canvas {
        let (right, depth) = camera(self.view);
        let ss = SUPERSAMPLE as f64;
        let to_screen = |p: DVec3| {
            DVec3::new(
                (PAD_PX + (p.dot(right) - self.left_mm) * scale) * ss,
                (TOP_PX as f64 + (top_mm - p.z) * scale) * ss,
                p.dot(depth),
            )
        };
        let light = (-depth + DVec3::Z * 0.5 + right * 0.3).normalize();
        let screen: Vec<DVec3> = self.mesh.positions.iter().map(|&p| to_screen(p)).collect();
        let shade: Vec<Colour> = self
            .normals
            .iter()
            .map(|n| {
                let k = AMBIENT + (1.0 - AMBIENT) * n.dot(light).abs() as f32;
                self.colour.map(|c| c * k)
            })
            .collect();
        let mut canvas = Canvas::new(self.width * SUPERSAMPLE, height * SUPERSAMPLE, BACKGROUND);
        for tri in &self.mesh.triangles {
            canvas.triangle(tri.map(|v| screen[v as usize]), tri.map(|v| shade[v as usize]));
        }
        for Level { z, contour, colour } in self.levels {
            let Some(contour) = contour else { continue };
            let n = contour.points.len();
            for k in 0..n {
                let [a, b] = [contour.points[k], contour.points[(k + 1) % n]]
                    .map(|p| to_screen(p.extend(*z)) - DVec3::Z * LINE_LIFT_MM);
                canvas.line(a, b, LINE_PX * ss, *colour);
            }
        }
        canvas
    }
}

/// A body the preview shows: its mesh, vertex normals, colour and level lines.
type Shown<'a> = (&'a Mesh, &'a [DVec3], Colour, &'a [Level]);

/// Horizontal extent of `mesh` seen in `view` (mm along screen right).
fn extent(mesh: &Mesh, view: &View) -> (f64, f64) {
    let (right, _) = camera(view);
    mesh.positions
        .iter()
        .map(|p| p.dot(right))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), u| (lo.min(u), hi.max(u)))
}

/// `preview.png`: `bodies` (canonical frame, each with its label, such as "scan" or
/// "pose-symmetric"; the last the one the mannequin was built from) and the mannequin of
/// `result` beside them, encoded as PNG.
pub fn preview_png(bodies: &[(&Mesh, &str)], result: &Symmetrized) -> Vec<u8> {
    let (width, height, rgb) = preview_rgb(bodies, result);
    encode_png(width, height, &rgb)
}

/// An 8-bit RGB image (`width` × `height`, row by row) as PNG.
fn encode_png(width: usize, height: usize, rgb: &[u8]) -> Vec<u8> {
    let mut png = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new_with_quality(
        &mut png,
        image::codecs::png::CompressionType::Default,
        image::codecs::png::FilterType::Adaptive,
    );
    image::ImageEncoder::write_image(
        encoder,
        rgb,
        width as u32,
        height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .expect("encoding a PNG into memory cannot fail");
    png
}

/// The preview as 8-bit RGB: (width, height, pixels row by row).
fn preview_rgb(bodies: &[(&Mesh, &str)], result: &Symmetrized) -> (usize, usize, Vec<u8>) {
    let m = &result.mannequin;
    let levels = &result.comparison.levels;
    let heights = [levels.chest, levels.waist, levels.hip];
    let body_levels: Vec<Vec<Level>> = (bodies.iter())
        .map(|(mesh, _)| {
            let body = SegmentedBody::with_regions(mesh, &result.regions);
            Level::measured(body.torso_sections(&heights), heights)
        })
        .collect();
    let ring_at = |z: f64| {
        m.torso
            .iter()
            .min_by(|a, b| (a.z - z).abs().total_cmp(&(b.z - z).abs()))
            .map(|l| Contour { points: l.points.clone() })
    };
    let ring_levels = Level::measured(heights.iter().map(|&z| ring_at(z)).collect(), heights);
    let body_normals: Vec<Vec<DVec3>> =
        bodies.par_iter().map(|(mesh, _)| vertex_normals(mesh)).collect();
    let form_normals = vertex_normals(&m.mesh);
    let bounds = crate::body::mesh::Aabb::around(
        bodies.iter().flat_map(|(b, _)| b.positions.iter().copied()),
    )
    .expect("a scan has triangles");
    let scale = BODY_PX / bounds.size().z;
    // Per view: each body in skin colour with its levels, then the mannequin.
    let shown: Vec<Shown> = (bodies.iter())
        .zip(&body_normals)
        .zip(&body_levels)
        .map(|(((mesh, _), normals), levels)| (*mesh, &normals[..], SKIN, &levels[..]))
        .chain([(&m.mesh, &form_normals[..], FORM, &ring_levels[..])])
        .collect();
    let names: Vec<&str> = bodies.iter().map(|(_, name)| *name).chain(["mannequin"]).collect();

    let mut panels = Vec::with_capacity(shown.len() * VIEWS.len());
    for view in &VIEWS {
        for (&(mesh, normals, colour, levels), name) in shown.iter().zip(&names) {
            let (lo, hi) = extent(mesh, view);
            // As wide as the body, or as its label where that is wider (a body seen from the
            // side is narrower than "pose-symmetric").
            let body_px = (hi - lo) * scale;
            let label_px = (name.len() * raster::GLYPH_PX) as f64;
            let width = (body_px.max(label_px) + 2.0 * PAD_PX).ceil() as usize;
            panels.push(Panel { mesh, normals, colour, levels, view, left_mm: lo, width });
        }
    }
    let height = TOP_PX + BODY_PX.ceil() as usize + PAD_PX as usize + BOTTOM_PX;
    let rendered: Vec<(usize, usize, Vec<u8>)> = panels
        .par_iter()
        .map(|p| p.render(scale, bounds.max.z, height).downsample(SUPERSAMPLE))
        .collect();

    // Side by side: the bodies of a view together, a gap between views.
    let width = rendered.iter().map(|r| r.0).sum::<usize>() + VIEW_GAP_PX * (VIEWS.len() - 1);
    let mut rgb = vec![255u8; width * height * 3];
    let mut x = 0;
    for (k, (w, h, pixels)) in rendered.iter().enumerate() {
        for row in 0..*h {
            let to = 3 * (row * width + x);
            rgb[to..to + 3 * w].copy_from_slice(&pixels[3 * row * w..3 * (row + 1) * w]);
        }
        let (view, body) = (k / shown.len(), k % shown.len());
        if body == 0 {
            raster::text(&mut rgb, width, (x + PAD_PX as usize, 4), VIEWS[view].name, 1, INK);
        }
        raster::text(&mut rgb, width, (x + PAD_PX as usize, 16), names[body], 1, INK);
        x += w + if body + 1 == shown.len() { VIEW_GAP_PX } else { 0 };
    }
    let built_from = bodies.last().map_or("body", |(_, name)| name);
    legend(&mut rgb, width, height, built_from, result);
    // 64 levels per channel: no visible difference on the shading, a third smaller file.
    rgb.iter_mut().for_each(|v| *v &= POSTERIZE_MASK);
    (width, height, rgb)
}

/// The legend under the bodies: each level's colour, height and girths.
fn legend(rgb: &mut [u8], width: usize, height: usize, name: &str, result: &Symmetrized) {
    for (k, (row, colour)) in result.comparison.table.iter().zip(LEVEL_COLOURS).enumerate() {
        let y = height - BOTTOM_PX + 6 + 12 * k;
        let ink = colour.map(|c| (c * 255.0) as u8);
        raster::fill(rgb, width, (PAD_PX as usize, y), (16, 8), ink);
        let words = format!(
            "{:<5} z {:>4.0} mm   tape girth: {name} {:.1} mm, mannequin {:.1} mm ({:+.2})",
            row.measure, row.z, row.input.tape, row.mannequin.tape, row.tape_change_mm
        );
        raster::text(rgb, width, (PAD_PX as usize + 24, y), &words, 1, INK);
    }
}
