//! Garment fit testing on the form (issue 30; US 9,696,130's sizing mannequin): a garment on
//! the form shaped to a customer, judged by the pressure it puts on each ring.
//!
//! The form's panels measure their load along their actuators (protocol 1.1). A band lying on
//! the ring's skin presses on the panels' ends, where the skin turns; the part of that press
//! along a panel's actuator is what its sensor reads, the rest goes into its guides. The skin's
//! geometry gives both parts per unit of band tension ([`RingSkin::gains`]), so a measured
//! force becomes the press on the panel; over the panel's share of the skin
//! ([`RingSkin::shares_mm`]) times the band's width it is the panel's contact pressure, and the
//! ring's total press over the skin's girth times the width is its mean pressure — on a round
//! ring Laplace's `P = 2π T / C`. Per ring the test reports
//! the garment's girth on the form, its ease over the body (relaxed girth minus the body's
//! girth at the ring's level: negative where it is stretched), the mean and largest pressure,
//! the imbalance (the standard deviation of the ring's panel forces) and a verdict by comfort
//! band ([`comfort`]). [`sweep`] steps the rings' girths through a range.
//!
//! A panel touches the garment when its mean force stands out of the sensor's noise: more
//! than [`CONTACT_STANDARD_ERRORS`] standard errors of its mean, and at least the wire's
//! 0.01 N.

pub mod comfort;
pub mod sweep;

use std::collections::BTreeMap;

use firmware_protocol::HUNDREDTHS_PER_N;
use form_description::FormDescription;
use form_description::garment::{GarmentKind, GarmentSpec};
use form_description::skin::{KPA_PER_N_PER_MM2, RingSkin};
use serde::Serialize;

pub use comfort::Verdict;

use crate::form::controller::ForceSample;

/// How many standard errors of its mean a panel's force must stand out by to count as
/// contact: 4 (a false contact once in 30,000 panels of pure noise).
pub const CONTACT_STANDARD_ERRORS: f64 = 4.0;
/// The smallest force that counts as contact, N: one step of the wire (0.01 N).
const LEAST_CONTACT_N: f64 = 1.0 / HUNDREDTHS_PER_N;

/// One panel under the garment.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PanelPressure {
    /// Its actuator.
    pub actuator: String,
    /// Its force was read (a node of protocol 1.1 with a sensor on it); without it the ring
    /// is [`Verdict::NotMeasured`].
    pub measured: bool,
    /// Its mean force along its actuator, N (what its sensor measures; 0 unread).
    pub force_n: f64,
    /// The force the garment presses it with, N: the measured force over the part of the
    /// band's press its actuator carries ([`PanelGain`](form_description::skin::PanelGain)).
    pub normal_n: f64,
    /// Its share of the skin, mm (times the band's width: its contact area).
    pub share_mm: f64,
    /// It touches the garment.
    pub contact: bool,
    /// Its contact pressure, kPa (0 without contact).
    pub pressure_kpa: f64,
}

/// The garment on one ring.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RingFit {
    /// The ring.
    pub ring: String,
    /// The garment band's width, mm.
    pub band_width_mm: f64,
    /// The garment's relaxed girth there, mm.
    pub relaxed_girth_mm: f64,
    /// The customer's girth at the ring's body level, mm (what the form was shaped to).
    pub body_girth_mm: Option<f64>,
    /// The form's girth where it stands (its skin), mm.
    pub form_girth_mm: f64,
    /// The garment's girth on the form: the form's where it is stretched, else its relaxed
    /// girth, mm.
    pub garment_girth_mm: f64,
    /// Relaxed girth minus the body's, mm: negative where the garment is stretched on the
    /// customer.
    pub ease_mm: Option<f64>,
    /// Mean contact pressure, kPa: the ring's force over the skin's girth times the width.
    pub mean_pressure_kpa: f64,
    /// The largest panel pressure, kPa.
    pub max_pressure_kpa: f64,
    /// The standard deviation of the ring's panel forces, N.
    pub imbalance_n: f64,
    /// Some panel touches the garment.
    pub contact: bool,
    /// The verdict.
    pub verdict: Verdict,
    /// Every panel of the ring.
    pub panels: Vec<PanelPressure>,
}

/// A garment's fit on the form.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitTest {
    /// The garment's name.
    pub garment: String,
    /// Daily wear or compression.
    pub kind: &'static str,
    /// Every ring the garment covers, in the garment's order.
    pub rings: Vec<RingFit>,
}

impl FitTest {
    /// The rings flagged (daily wear critical or too tight).
    pub fn flagged(&self) -> impl Iterator<Item = &RingFit> {
        self.rings.iter().filter(|r| r.verdict.flagged())
    }
}

/// Judges `garment` on `form` with the actuators at `positions_mm` feeling `forces`; the
/// body's girths by ring (from the set-points) give the ease.
pub fn assess(
    form: &FormDescription,
    garment: &GarmentSpec,
    body_girths_mm: &BTreeMap<String, f64>,
    positions_mm: &BTreeMap<String, f64>,
    forces: &BTreeMap<String, ForceSample>,
) -> FitTest {
    let rings = garment
        .bands
        .iter()
        .filter_map(|band| {
            let skin = RingSkin::of(form, &band.ring, positions_mm)?;
            let form_girth_mm = skin.girth_mm();
            let panels: Vec<PanelPressure> = skin
                .actuators
                .iter()
                .zip(skin.shares_mm())
                .zip(skin.gains())
                .map(|((a, share_mm), gain)| {
                    let sample = forces.get(&a.id);
                    let measured = sample.is_some();
                    let force_n = sample.map_or(0.0, |s| s.mean_n);
                    let noise = sample.map_or(0.0, |s| {
                        CONTACT_STANDARD_ERRORS * s.sd_n / f64::from(s.readings.max(1)).sqrt()
                    });
                    let contact = force_n > noise.max(LEAST_CONTACT_N) && gain.axial > 0.0;
                    let normal_n = if contact { force_n * gain.normal / gain.axial } else { 0.0 };
                    let area = share_mm * band.width_mm;
                    let pressure_kpa =
                        if contact { KPA_PER_N_PER_MM2 * normal_n / area } else { 0.0 };
                    PanelPressure {
                        actuator: a.id.clone(),
                        measured,
                        force_n,
                        normal_n,
                        share_mm,
                        contact,
                        pressure_kpa,
                    }
                })
                .collect();
            let contact = panels.iter().any(|p| p.contact);
            // Folded from +0.0: `Sum` starts at -0.0, which would print as "-0.00".
            let pressing = panels.iter().map(|p| p.normal_n).fold(0.0, |a, f| a + f);
            let mean_pressure_kpa = KPA_PER_N_PER_MM2 * pressing / (form_girth_mm * band.width_mm);
            let max_pressure_kpa = panels.iter().map(|p| p.pressure_kpa).fold(0.0, f64::max);
            let n = panels.len().max(1) as f64;
            let mean_force = panels.iter().map(|p| p.force_n).sum::<f64>() / n;
            let imbalance_n =
                (panels.iter().map(|p| (p.force_n - mean_force).powi(2)).sum::<f64>() / n).sqrt();
            let verdict = match garment.kind {
                _ if panels.iter().any(|p| !p.measured) => Verdict::NotMeasured,
                GarmentKind::Daily => Verdict::daily(mean_pressure_kpa, contact),
                GarmentKind::Compression => Verdict::compression(mean_pressure_kpa, contact),
            };
            let body_girth_mm = body_girths_mm.get(&band.ring).copied();
            Some(RingFit {
                ring: band.ring.clone(),
                band_width_mm: band.width_mm,
                relaxed_girth_mm: band.relaxed_girth_mm,
                body_girth_mm,
                form_girth_mm,
                garment_girth_mm: form_girth_mm.max(band.relaxed_girth_mm),
                ease_mm: body_girth_mm.map(|b| band.relaxed_girth_mm - b),
                mean_pressure_kpa,
                max_pressure_kpa,
                imbalance_n,
                contact,
                verdict,
                panels,
            })
        })
        .collect();
    let kind = match garment.kind {
        GarmentKind::Daily => "daily",
        GarmentKind::Compression => "compression",
    };
    FitTest { garment: garment.name.clone(), kind, rings }
}

/// The fit test as a table: a line per ring, then each flagged ring in words.
pub fn table(fit: &FitTest) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "{} ({} wear) on the form:", fit.garment, fit.kind);
    let _ = writeln!(
        s,
        "  {:<12} {:>8} {:>8} {:>8} {:>7} {:>8} {:>8} {:>9}  verdict",
        "ring", "relaxed", "body", "on form", "ease", "mean", "max", "imbalance"
    );
    let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
    for r in &fit.rings {
        let _ = writeln!(
            s,
            "  {:<12} {:>8.1} {:>8} {:>8.1} {:>7} {:>8.2} {:>8.2} {:>9.2}  {}",
            r.ring,
            r.relaxed_girth_mm,
            mm(r.body_girth_mm),
            r.garment_girth_mm,
            mm(r.ease_mm),
            r.mean_pressure_kpa,
            r.max_pressure_kpa,
            r.imbalance_n,
            r.verdict.words()
        );
    }
    let _ = writeln!(
        s,
        "  (girths and ease in mm, ease = relaxed - body, negative where stretched; pressures \
         in kPa; imbalance = the standard deviation of the ring's panel forces, N)"
    );
    for r in fit.flagged() {
        let _ = writeln!(
            s,
            "  {}: {} at {:.2} kPa (over {} kPa): the garment is {:.0} mm too small there",
            r.ring,
            r.verdict.words().to_lowercase(),
            r.mean_pressure_kpa,
            comfort::COMFORT_LIMIT_KPA,
            -r.ease_mm.unwrap_or(r.relaxed_girth_mm - r.form_girth_mm)
        );
    }
    s
}
