//! The fit test's pictures: `fit.png` ([`fit_png`]), each ring the garment covers seen from
//! above with its panels coloured by their contact pressure in the comfort bands, and
//! `sweep.svg` ([`sweep_svg`]), each ring's mean pressure against its girth through a sweep.

use std::fmt::Write;

use form_description::FormDescription;
use form_description::skin::RingSkin;
use glam::{DVec2, DVec3};

use super::raster::{self, Canvas, Colour};
use super::{BACKGROUND, INK, PAD_PX, POSTERIZE_MASK, SUPERSAMPLE, TOP_PX, encode_png};
use crate::form::fit_test::comfort::{COMFORT_LIMIT_KPA, LOOSE_BELOW_KPA, TIGHT_ABOVE_KPA};
use crate::form::fit_test::sweep::Sweep;
use crate::form::fit_test::{FitTest, RingFit};

/// One ring's view from above: its square and the room under it for its text (pixels).
const CELL_PX: usize = 220;
const CELL_TEXT_PX: usize = 36;
/// Ring views per row.
const CELL_COLUMNS: usize = 3;
/// A text line's height with spacing, and a text's inset (pixels).
const TEXT_LINE_PX: usize = 12;
const TEXT_INSET_PX: usize = 4;
/// Room under the picture for the legend (pixels).
const LEGEND_PX: usize = 30;
/// Widths (pixels): the skin's outline and a panel's bar.
const OUTLINE_PX: f64 = 1.5;
const PANEL_PX: f64 = 7.0;

const SKIN_LINE: Colour = [0.55, 0.55, 0.55];
/// A panel's colour by band: no contact, loose, comfortable, critical, too tight.
const BANDS: [Colour; 5] = [
    [0.75, 0.75, 0.75],
    [0.55, 0.75, 0.95],
    [0.2, 0.65, 0.25],
    [0.95, 0.55, 0.05],
    [0.85, 0.1, 0.1],
];

/// The colour of a panel's pressure.
fn band_colour(contact: bool, kpa: f64) -> Colour {
    match kpa {
        _ if !contact => BANDS[0],
        p if p < LOOSE_BELOW_KPA => BANDS[1],
        p if p <= COMFORT_LIMIT_KPA => BANDS[2],
        p if p <= TIGHT_ABOVE_KPA => BANDS[3],
        _ => BANDS[4],
    }
}

/// `fit.png` of `fit` with the form's actuators at `positions_mm`, encoded as PNG.
pub fn fit_png(
    form: &FormDescription,
    fit: &FitTest,
    positions_mm: &std::collections::BTreeMap<String, f64>,
) -> Vec<u8> {
    let skins: Vec<(&RingFit, RingSkin, DVec2)> = fit
        .rings
        .iter()
        .filter_map(|r| {
            let skin = RingSkin::of(form, &r.ring, positions_mm)?;
            let centre = DVec2::from_array(form.ring(&r.ring)?.center_mm);
            Some((r, skin, centre))
        })
        .collect();
    let reach = skins
        .iter()
        .flat_map(|(_, skin, centre)| {
            skin.corners
                .iter()
                .map(move |c| (DVec2::from_array(c.point) - *centre).abs().max_element())
        })
        .fold(1.0, f64::max);
    let columns = CELL_COLUMNS.min(skins.len().max(1));
    let rows = skins.len().div_ceil(columns).max(1);
    let width = columns * CELL_PX + 2 * PAD_PX as usize;
    let height = TOP_PX + rows * (CELL_PX + CELL_TEXT_PX) + LEGEND_PX;
    let mut rgb = vec![255u8; width * height * 3];
    let title = format!("{} on the form, from above (front down)", fit.garment);
    raster::text(&mut rgb, width, (PAD_PX as usize, TEXT_INSET_PX), &title, 1, INK);
    let ss = SUPERSAMPLE as f64;
    let scale = (0.5 * CELL_PX as f64 - PAD_PX) / reach;
    for (k, (ring, skin, centre)) in skins.iter().enumerate() {
        let mut canvas = Canvas::new(CELL_PX * SUPERSAMPLE, CELL_PX * SUPERSAMPLE, BACKGROUND);
        let half = 0.5 * CELL_PX as f64;
        let at = |p: [f64; 2], depth: f64| {
            let q = DVec2::from_array(p) - *centre;
            DVec3::new((half + q.x * scale) * ss, (half - q.y * scale) * ss, depth)
        };
        let n = skin.corners.len();
        for i in 0..n {
            let (a, b) = (skin.corners[i].point, skin.corners[(i + 1) % n].point);
            canvas.line(at(a, 2.0), at(b, 2.0), OUTLINE_PX * ss, SKIN_LINE);
        }
        for (a, panel) in skin.actuators.iter().zip(&ring.panels) {
            let e = positions_mm.get(&a.id).copied().unwrap_or(0.0);
            let ring_centre = [centre.x, centre.y];
            let [p, q] = a.panel_ends(ring_centre, e).map(|end| at(end, 1.0));
            canvas.line(p, q, PANEL_PX * ss, band_colour(panel.contact, panel.pressure_kpa));
        }
        let (w, h, pixels) = canvas.downsample(SUPERSAMPLE);
        let (col, row) = (k % columns, k / columns);
        let (cx, cy) = (PAD_PX as usize + col * CELL_PX, TOP_PX + row * (CELL_PX + CELL_TEXT_PX));
        for y in 0..h.min(height.saturating_sub(cy)) {
            let to = 3 * ((cy + y) * width + cx);
            rgb[to..to + 3 * w].copy_from_slice(&pixels[3 * y * w..3 * (y + 1) * w]);
        }
        let lines = [
            format!("{}: {}", ring.ring, ring.verdict.words()),
            format!("mean {:.2} max {:.2} kPa", ring.mean_pressure_kpa, ring.max_pressure_kpa),
        ];
        for (i, line) in lines.iter().enumerate() {
            let y = cy + CELL_PX + TEXT_INSET_PX / 2 + TEXT_LINE_PX * i;
            raster::text(&mut rgb, width, (cx + TEXT_INSET_PX, y), line, 1, INK);
        }
    }
    let legend = format!(
        "panels: grey no contact, blue under {LOOSE_BELOW_KPA}, green to {COMFORT_LIMIT_KPA}, \
         orange to {TIGHT_ABOVE_KPA}, red over {TIGHT_ABOVE_KPA} kPa"
    );
    let y = height - LEGEND_PX + TEXT_INSET_PX;
    raster::text(&mut rgb, width, (PAD_PX as usize, y), &legend, 1, INK);
    rgb.iter_mut().for_each(|v| *v &= POSTERIZE_MASK);
    encode_png(width, height, &rgb)
}

/// The chart's size and margins (pixels).
const CHART_W: f64 = 720.0;
const CHART_H: f64 = 420.0;
const LEFT: f64 = 60.0;
const RIGHT: f64 = 170.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 50.0;
/// The rings' line colours, in turn.
const LINES: [&str; 8] =
    ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f"];

/// `sweep.svg`: every ring's mean pressure (kPa) against its girth offset (mm) through
/// `sweep`, the comfort bands' limits as dashed lines and each crossing of the limit marked.
pub fn sweep_svg(sweep: &Sweep) -> String {
    let deltas: Vec<f64> = sweep.steps.iter().map(|s| s.delta_mm).collect();
    let (x0, x1) = (
        deltas.first().copied().unwrap_or(0.0),
        deltas.last().copied().unwrap_or(1.0).max(deltas.first().copied().unwrap_or(0.0) + 1.0),
    );
    let top_kpa = sweep
        .steps
        .iter()
        .flat_map(|s| s.fit.rings.iter().map(|r| r.mean_pressure_kpa))
        .fold(TIGHT_ABOVE_KPA * 1.2, f64::max);
    let (plot_w, plot_h) = (CHART_W - LEFT - RIGHT, CHART_H - TOP - BOTTOM);
    let x = |d: f64| LEFT + (d - x0) / (x1 - x0) * plot_w;
    let y = |p: f64| TOP + plot_h - p / top_kpa * plot_h;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{CHART_W}\" height=\"{CHART_H}\" \
         viewBox=\"0 0 {CHART_W} {CHART_H}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let _ = writeln!(
        s,
        "<text x=\"{LEFT}\" y=\"20\" font-size=\"14\">Mean pressure per ring through the size sweep</text>"
    );
    // Axes, ticks and labels.
    let _ = writeln!(
        s,
        "<path d=\"M{LEFT} {TOP} V{:.1} H{:.1}\" stroke=\"black\" fill=\"none\"/>",
        TOP + plot_h,
        LEFT + plot_w
    );
    for &d in &deltas {
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" y1=\"{1:.1}\" x2=\"{0:.1}\" y2=\"{2:.1}\" stroke=\"black\"/>\
             <text x=\"{0:.1}\" y=\"{3:.1}\" text-anchor=\"middle\" font-size=\"10\">{4:+}</text>",
            x(d),
            TOP + plot_h,
            TOP + plot_h + 4.0,
            TOP + plot_h + 16.0,
            d
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">girth offset from the customer's (mm)</text>",
        LEFT + plot_w / 2.0,
        CHART_H - 12.0
    );
    let ticks = (top_kpa / 0.5).floor() as usize;
    for k in 0..=ticks {
        let p = k as f64 * 0.5;
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\" font-size=\"10\">{p:.1}</text>",
            LEFT - 6.0,
            y(p) + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<text transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\">kPa</text>",
        TOP + plot_h / 2.0
    );
    // The comfort bands' limits.
    for (limit, name, colour) in [
        (LOOSE_BELOW_KPA, "loose below", "#7fa7d9"),
        (COMFORT_LIMIT_KPA, "comfort limit", "#f28e1c"),
        (TIGHT_ABOVE_KPA, "too tight above", "#d62728"),
    ] {
        let _ = writeln!(
            s,
            "<line x1=\"{LEFT}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"{colour}\" \
             stroke-dasharray=\"6 4\"/><text x=\"{2:.1}\" y=\"{3:.1}\" font-size=\"10\" \
             fill=\"{colour}\">{name} {limit} kPa</text>",
            y(limit),
            LEFT + plot_w,
            LEFT + 4.0,
            y(limit) - 3.0
        );
    }
    // One line per ring, its crossing marked.
    let rings: Vec<&str> = sweep
        .steps
        .first()
        .map(|st| st.fit.rings.iter().map(|r| r.ring.as_str()).collect())
        .unwrap_or_default();
    for (k, ring) in rings.iter().enumerate() {
        let colour = LINES[k % LINES.len()];
        let mut d = String::new();
        for step in &sweep.steps {
            if let Some(r) = step.fit.rings.iter().find(|r| r.ring == *ring) {
                let pen = if d.is_empty() { 'M' } else { 'L' };
                let _ = write!(d, "{pen}{:.1} {:.1} ", x(step.delta_mm), y(r.mean_pressure_kpa));
            }
        }
        let _ = writeln!(
            s,
            "<path d=\"{}\" stroke=\"{colour}\" stroke-width=\"2\" fill=\"none\"/>",
            d.trim_end()
        );
        let ly = TOP + 16.0 * k as f64;
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" y1=\"{1:.1}\" x2=\"{2:.1}\" y2=\"{1:.1}\" stroke=\"{colour}\" \
             stroke-width=\"2\"/><text x=\"{3:.1}\" y=\"{4:.1}\">{ring}</text>",
            LEFT + plot_w + 12.0,
            ly,
            LEFT + plot_w + 32.0,
            LEFT + plot_w + 38.0,
            ly + 4.0
        );
        if let Some(c) = sweep.crossings.iter().find(|c| c.ring == *ring) {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"none\" stroke=\"{colour}\" \
                 stroke-width=\"2\"><title>{ring} crosses {} kPa at {:.1} mm</title></circle>",
                x(c.delta_mm),
                y(sweep.limit_kpa),
                sweep.limit_kpa,
                c.girth_mm
            );
        }
    }
    let _ = writeln!(s, "</svg>");
    s
}
