//! The report's one template: plain HTML and CSS, checked at compile time and escaped by
//! construction (maud); only the pictures dressform drew go in as they are. The style is for
//! the screen and for A4 paper: dark text on white, each part on a page of its own when
//! printed.

use super::embed::{inline_svg, png_data_uri};
use super::measured::{Reading, Row, Values};
use super::{Figure, FitTestPart, FormPart, Measured, Report, SweepPart};
use crate::form::form_fit::RingStatus;
use maud::{DOCTYPE, Markup, PreEscaped, html};

/// The style sheet: A4 with 12 mm margins (`@page`), the body as wide as the printed page's
/// text, each part (`section`) on a new page when printed, tables kept whole row by row, no
/// dark backgrounds.
const STYLE: &str = r#"
@page { size: A4; margin: 12mm; }
:root { color-scheme: light; }
body { font: 10pt/1.35 "DejaVu Sans", "Liberation Sans", Arial, sans-serif; color: #111;
       background: #fff; margin: 0 auto; padding: 10mm; max-width: 186mm; }
header { border-bottom: 2px solid #222; margin-bottom: 4mm; }
h1 { font-size: 18pt; margin: 0 0 1mm; }
.kind { font-size: 9pt; letter-spacing: 0.08em; text-transform: uppercase; color: #555;
        margin: 0; }
.meta { color: #444; margin: 0 0 2mm; }
h2 { font-size: 13pt; margin: 6mm 0 2mm; border-bottom: 1px solid #999; break-after: avoid; }
h3 { font-size: 11pt; margin: 4mm 0 1mm; break-after: avoid; }
p { margin: 1mm 0 2mm; }
table { border-collapse: collapse; width: 100%; margin: 2mm 0 3mm; }
th, td { padding: 1mm 1.5mm; border-bottom: 1px solid #d4d4d4; text-align: left;
         vertical-align: top; }
thead th { border-bottom: 1.5px solid #444; font-size: 8.5pt; vertical-align: bottom; }
thead th.num { white-space: normal; }
tbody th { font-weight: 600; white-space: nowrap; }
tr { break-inside: avoid; }
thead { display: table-header-group; }
.num { text-align: right; white-space: nowrap; font-variant-numeric: tabular-nums; }
td.definition { font-size: 8.5pt; color: #333; }
tr.unreliable { background: #fdf1f1; }
.reason, .note, .flagged { color: #9a1b1b; }
td.verdict { white-space: nowrap; }
.mark { display: inline-block; box-sizing: border-box; width: 1.3em; height: 1.3em;
        line-height: 1.1em; border: 1.5px solid #b00020; border-radius: 50%; color: #b00020;
        text-align: center; font-weight: bold; font-size: 0.85em; }
figure { margin: 3mm 0; break-inside: avoid; }
figure img, figure svg { display: block; max-width: 100%; height: auto; margin: 0 auto; }
figcaption { font-size: 8.5pt; color: #444; margin-top: 1mm; }
code { font-size: 0.95em; }
@media print {
  body { padding: 0; max-width: none; }
  section + section { break-before: page; }
}
"#;

/// `report` as one self-contained HTML page (see [`super`]).
pub fn render(report: &Report) -> String {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { "dressform report: " (report.customer) }
                style { (PreEscaped(STYLE)) }
            }
            body {
                header {
                    p.kind { "Customer report" }
                    h1 { (report.customer) }
                    p.meta {
                        "Made " (report.date) " (UTC) by dressform " (env!("CARGO_PKG_VERSION"))
                    }
                }
                @if !report.body.is_empty() {
                    section #body {
                        h2 { "The body" }
                        @for f in &report.body { (figure(f)) }
                    }
                }
                @if let Some(measured) = &report.measurements { (measurements(measured)) }
                @if let Some(form) = &report.form { (form_part(form)) }
                @if let Some(fit) = &report.fit_test { (fit_test(fit)) }
            }
        }
    }
    .into_string()
}

/// The mark beside a value that is not there or not to be trusted.
fn mark() -> Markup {
    html! { span.mark role="img" aria-label="warning" title="warning" { "!" } }
}

/// `value` rounded to one decimal, one that rounds to zero made 0 (never "-0.0").
fn tenths(value: f64) -> f64 {
    let rounded = (value * 10.0).round() / 10.0;
    if rounded == 0.0 { 0.0 } else { rounded }
}

/// A number to one decimal.
fn one(value: f64) -> String {
    format!("{:.1}", tenths(value))
}

/// A number to one decimal with its sign.
fn signed(value: f64) -> String {
    format!("{:+.1}", tenths(value))
}

/// A number to one decimal, or a dash for none.
fn maybe(value: Option<f64>) -> String {
    value.map_or_else(|| "–".to_string(), one)
}

/// A picture with its caption: an SVG inline, a PNG as a `data:` URI.
fn figure(f: &Figure) -> Markup {
    html! {
        figure {
            @if f.file.ends_with(".svg") {
                (PreEscaped(inline_svg(&String::from_utf8_lossy(f.bytes))))
            } @else {
                img src=(png_data_uri(f.bytes)) alt=(f.caption);
            }
            figcaption { (f.caption) " (" code { (f.file) } ")" }
        }
    }
}

/// The measurement table, and the warnings on it.
fn measurements(measured: &Result<Measured, String>) -> Markup {
    html! {
        section #measurements {
            h2 { "Measurements" }
            @match measured {
                Err(why) => p.note { (mark()) " The body could not be measured: " (why) },
                Ok(m) => {
                    p {
                        "The ISO 8559-1 body dimensions of " (m.body) ", in millimetres; left "
                        "and right are the customer's. " (mark()) " marks a value that is not "
                        "measured and says why: a number outside a body's range is held back, "
                        "never printed."
                    }
                    table.measurements {
                        thead {
                            tr {
                                th { "Measurement" }
                                th.num { "Value" }
                                th.num { "Left" }
                                th.num { "Right" }
                                th.num { "L\u{a0}−\u{a0}R" }
                                th { "Definition (ISO 8559-1)" }
                            }
                        }
                        tbody { @for row in m.rows() { (measurement(&row)) } }
                    }
                    @if !m.warnings.is_empty() {
                        h3 { "Notes on the measurements" }
                        @for warning in &m.warnings { p.note { (mark()) " " (warning) } }
                    }
                }
            }
        }
    }
}

/// One row of the measurement table.
fn measurement(row: &Row) -> Markup {
    let reasons = row.reasons();
    let unreliable = (!reasons.is_empty()).then_some("unreliable");
    html! {
        tr id=(row.definition.key) class=[unreliable] {
            th scope="row" {
                (row.definition.name)
                @if row.unit != "mm" { " (" (row.unit) ")" }
            }
            @match &row.values {
                Values::One(value) => { td.num { (reading(value)) } td {} td {} td {} },
                Values::Sides { left, right, difference } => {
                    td {}
                    td.num { (reading(left)) }
                    td.num { (reading(right)) }
                    td.num { @if let Some(d) = difference { (signed(*d)) } }
                },
            }
            td.definition {
                (row.definition.definition)
                @for (side, why) in &reasons {
                    br;
                    span.reason {
                        "Not measured" @if let Some(side) = side { " (" (side) ")" } ": " (why)
                    }
                }
            }
        }
    }
}

/// A value of the measurement table: its number, or "not measured".
fn reading(value: &Reading) -> Markup {
    match value {
        Reading::Number(v) => html! { (one(*v)) },
        Reading::NotMeasured(_) => html! { (mark()) " not measured" },
    }
}

/// The form's fit: per ring its height and girth against the body's, the gaps, its status.
fn form_part(part: &FormPart) -> Markup {
    let fit = part.fit;
    html! {
        section #form {
            h2 { "The form: " (fit.form) }
            p {
                "Each ring of the form at the body level it stands for (heights above the "
                "floor), its panels set to the mannequin's girth there; the gaps are between "
                "the form's skin and the mannequin all round where the ring stands. "
                "Millimetres; errors are the form's minus the body's."
            }
            table.form {
                thead {
                    tr {
                        th { "Ring" }
                        th.num { "Form z" }
                        th.num { "Body z" }
                        th.num { "Height error" }
                        th.num { "Mannequin girth" }
                        th.num { "Form girth" }
                        th.num { "Girth error" }
                        th.num { "RMS gap" }
                        th.num { "Max gap" }
                        th { "Status" }
                    }
                }
                tbody {
                    @for r in &fit.rings {
                        @let status = r.status();
                        @let fine = matches!(status, RingStatus::Ok | RingStatus::NoBody);
                        tr {
                            th scope="row" { (r.ring) }
                            td.num { (one(r.form_height_mm)) }
                            td.num { (one(r.mannequin_height_mm)) }
                            td.num { (one(r.offset_mm)) }
                            td.num { (one(r.mannequin_girth_mm)) }
                            td.num { (one(r.form_girth_mm)) }
                            td.num { (one(r.form_girth_mm - r.mannequin_girth_mm)) }
                            td.num { (one(r.rms_radial_gap_mm)) }
                            td.num { (one(r.largest_radial_gap_mm)) }
                            td.flagged[!fine] {
                                @if !fine { (mark()) " " }
                                (status.to_string())
                            }
                        }
                    }
                }
            }
            @for r in fit.saturated() {
                @let actuators: Vec<String> = r.saturated.iter().map(ToString::to_string).collect();
                p.note {
                    (mark()) " " (r.ring) ": " (r.girth_reach().to_string())
                    " (" (actuators.join(", ")) ")"
                }
            }
            @if let Some(f) = &part.figure { (figure(f)) }
        }
    }
}

/// The garment's fit test: per ring its girths, ease, pressures and verdict; the sweep.
fn fit_test(part: &FitTestPart) -> Markup {
    let fit = part.fit;
    html! {
        section #fit-test {
            h2 { "Garment fit test: " (fit.garment) }
            p {
                "The garment (" (fit.kind) " wear) on the form shaped to the customer. Girths and "
                "ease in millimetres (ease: the garment's relaxed girth minus the body's, "
                "negative where it stretches on the customer), pressures in kPa, imbalance: "
                "the standard deviation of the ring's panel forces, N."
            }
            table.fit-test {
                thead {
                    tr {
                        th { "Ring" }
                        th.num { "Relaxed girth" }
                        th.num { "Body girth" }
                        th.num { "On the form" }
                        th.num { "Ease" }
                        th.num { "Mean pressure" }
                        th.num { "Max pressure" }
                        th.num { "Imbalance" }
                        th { "Verdict" }
                    }
                }
                tbody {
                    @for r in &fit.rings {
                        @let flagged = r.verdict.flagged();
                        tr {
                            th scope="row" { (r.ring) }
                            td.num { (one(r.relaxed_girth_mm)) }
                            td.num { (maybe(r.body_girth_mm)) }
                            td.num { (one(r.garment_girth_mm)) }
                            td.num { (maybe(r.ease_mm)) }
                            td.num { (format!("{:.2}", r.mean_pressure_kpa)) }
                            td.num { (format!("{:.2}", r.max_pressure_kpa)) }
                            td.num { (format!("{:.2}", r.imbalance_n)) }
                            td.verdict.flagged[flagged] {
                                @if flagged { (mark()) " " }
                                (r.verdict.words())
                            }
                        }
                    }
                }
            }
            @if let Some(f) = &part.figure { (figure(f)) }
            @if let Some(sweep) = &part.sweep { (sweep_part(sweep)) }
        }
    }
}

/// The size sweep: each ring's girth on the form and mean pressure at every step, where the
/// garment binds and its usable range.
fn sweep_part(part: &SweepPart) -> Markup {
    let sweep = part.sweep;
    let rings: Vec<&str> = sweep
        .steps
        .first()
        .map(|step| step.fit.rings.iter().map(|r| r.ring.as_str()).collect())
        .unwrap_or_default();
    html! {
        h3 { "Size sweep" }
        p {
            "Every ring the garment covers stepped through girths around the customer's: its "
            "girth on the form (mm) and mean pressure (kPa) at each offset; the limit is "
            (sweep.limit_kpa) " kPa."
        }
        table.sweep {
            thead {
                tr {
                    th.num { "Offset" }
                    @for ring in &rings { th.num { (ring) } }
                }
            }
            tbody {
                @for step in &sweep.steps {
                    tr {
                        th.num scope="row" { (signed(step.delta_mm)) }
                        @for r in &step.fit.rings {
                            td.num.flagged[r.mean_pressure_kpa > sweep.limit_kpa] {
                                (one(r.form_girth_mm)) " / " (format!("{:.2}", r.mean_pressure_kpa))
                            }
                        }
                    }
                }
            }
        }
        @for c in &sweep.crossings {
            p {
                (c.ring) " crosses " (sweep.limit_kpa) " kPa at " (one(c.girth_mm)) " mm ("
                (signed(c.delta_mm)) " mm)."
            }
        }
        p {
            @match &sweep.binds {
                Some(b) => {
                    "The garment binds first at the " (b.ring) " ("
                    (signed(b.delta_mm)) " mm). "
                },
                None => { "No ring crosses " (sweep.limit_kpa) " kPa within the sweep. " },
            }
            @match sweep.usable_mm {
                Some([a, b]) => {
                    "Usable from " (signed(a)) " to " (signed(b))
                    " mm of girth."
                },
                None => { "No step has every ring under " (sweep.limit_kpa) " kPa." },
            }
        }
        @if let Some(f) = &part.figure { (figure(f)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::measure::Unreliable;
    use serde_json::json;

    /// A report of a scan whose right wrist was held back (issue 33's 57.7 mm): the table has
    /// the row, "not measured" with the mark and the reason, and never the number; the page
    /// has no script and fetches nothing; text is escaped.
    #[test]
    fn a_held_back_measurement_shows_its_mark_and_reason_never_its_number() {
        let reason = "outside 100-250, an adult's range (the section may cut a limb)";
        let measured = Measured {
            body: "the scan",
            dimensions: json!({
                "stature_mm": 1870.0,
                "chest_girth_mm": 1012.4,
                "shoulder_slope_deg": { "left": 21.0, "right": 20.5, "difference": 0.5 },
                "wrist_girth_mm": { "left": 203.3, "right": null, "difference": null },
            }),
            unreliable: vec![Unreliable {
                measurement: "wrist_girth_mm.right".into(),
                value: 57.7,
                reason: reason.into(),
            }],
            warnings: vec!["a hole in the scan crosses the waist level".into()],
        };
        let svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"20\" height=\"10\"/>";
        let report = Report {
            customer: "scan <7>".into(),
            date: "2026-01-02".into(),
            body: vec![
                Figure { file: "preview.png", bytes: b"\x89PNG", caption: "the bodies" },
                Figure { file: "sections.svg", bytes: svg.as_bytes(), caption: "the sections" },
            ],
            measurements: Some(Ok(measured)),
            form: None,
            fit_test: None,
        };
        let html = render(&report);
        assert!(html.starts_with("<!DOCTYPE html>"), "{html}");
        assert!(html.contains("<h1>scan &lt;7&gt;</h1>"), "escaped");
        assert!(html.contains("2026-01-02"));
        assert!(html.contains(concat!("dressform ", env!("CARGO_PKG_VERSION"))));
        assert!(html.contains("src=\"data:image/png;base64,iVBORw==\""), "{html}");
        assert!(html.contains("<svg viewBox=\"0 0 20 10\""), "inline, scalable");
        let wrist_at = html.find("<tr id=\"wrist_girth_mm\" class=\"unreliable\">").unwrap();
        let wrist = &html[wrist_at..html[wrist_at..].find("</tr>").unwrap() + wrist_at];
        assert!(wrist.contains("203.3") && wrist.contains("class=\"mark\""), "{wrist}");
        assert!(wrist.contains("not measured"), "{wrist}");
        assert!(wrist.contains(&format!("Not measured (right): {reason}")), "{wrist}");
        assert!(!html.contains("57.7"), "a held-back number is never shown");
        assert!(html.contains("<tr id=\"chest_girth_mm\"><th scope=\"row\">Chest girth"));
        assert!(html.contains("Shoulder slope (°)") && html.contains("+0.5"));
        assert!(html.contains("a hole in the scan crosses the waist level"));
        assert!(!html.contains("<script") && !html.contains("src=\"http"));
    }
}
