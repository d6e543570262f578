//! The size sweep (US 9,696,130's progressive adjustment): every ring the garment covers grown
//! and shrunk through a range of girths around the customer's, the pressure read at each step,
//! and where the garment starts to bind.
//!
//! A step moves every panel of a covered ring out (or in) by the same distance, found by
//! bisection so that the ring's skin gains the step's girth ([`step_setpoints`]; a ring at the
//! end of its strokes stays there, and its girth tells). [`analyse`] finds, per ring, the girth
//! where its mean pressure crosses the comfort limit (linear between the two steps around it),
//! the first ring to cross (where the garment binds) and the range of steps where no ring is
//! over the limit (its usable size range).

use std::collections::BTreeMap;
use std::str::FromStr;

use form_description::FormDescription;
use form_description::garment::{GarmentKind, GarmentSpec};
use form_description::skin::RingSkin;
use serde::Serialize;

use super::FitTest;
use crate::form::setpoints::SetPoints;

/// The default sweep, mm of girth: -40 to +40 in 5 mm steps (17 steps).
pub const DEFAULT_SWEEP: &str = "-40:40:5";
/// The most steps a sweep may take: each is a move of the form and a force reading.
pub const MAX_STEPS: usize = 101;
/// Bisection steps for a ring's offset: 2^-40 of the stroke, far below the wire's 0.01 mm.
const BISECTIONS: usize = 40;

/// The girths a sweep steps through, relative to the customer's, mm.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SweepRange {
    /// The first step.
    pub from_mm: f64,
    /// The last step (reached when the steps land on it).
    pub to_mm: f64,
    /// Between steps, above 0.
    pub step_mm: f64,
}

impl SweepRange {
    /// How many steps, as a float (a parsed range has at most [`MAX_STEPS`]).
    fn count(&self) -> f64 {
        ((self.to_mm - self.from_mm) / self.step_mm + 1e-9).floor() + 1.0
    }

    /// Every step, from `from_mm` up; 0 exactly when the range passes through it.
    pub fn deltas(&self) -> Vec<f64> {
        let count = self.count().clamp(1.0, MAX_STEPS as f64) as usize;
        (0..count)
            .map(|k| self.from_mm + k as f64 * self.step_mm)
            .map(|d| if d.abs() < 1e-9 * self.step_mm { 0.0 } else { d })
            .collect()
    }
}

impl FromStr for SweepRange {
    type Err = String;

    /// `FROM:TO:STEP` in mm, `FROM <= 0 <= TO` (the customer's own girths are a step),
    /// `STEP > 0`, at most [`MAX_STEPS`] steps.
    fn from_str(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let [from, to, step] = parts[..] else {
            return Err(format!("`{text}`: give FROM:TO:STEP in mm, as {DEFAULT_SWEEP}"));
        };
        let number =
            |s: &str| {
                s.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    format!("`{text}`: `{s}` is not a number (give FROM:TO:STEP in mm)")
                })
            };
        let range =
            SweepRange { from_mm: number(from)?, to_mm: number(to)?, step_mm: number(step)? };
        if range.step_mm <= 0.0 {
            return Err(format!("`{text}`: the step must be above 0 mm"));
        }
        if range.from_mm > range.to_mm {
            return Err(format!("`{text}`: FROM must not be above TO"));
        }
        if range.from_mm > 0.0 || range.to_mm < 0.0 {
            return Err(format!("`{text}`: the range must include 0 (the customer's girths)"));
        }
        let steps = range.count();
        // NaN (an infinite range over an infinite step) counts as too many.
        if steps.is_nan() || steps > MAX_STEPS as f64 {
            return Err(format!("`{text}` takes {steps:.0} steps; at most {MAX_STEPS}"));
        }
        if !range.deltas().contains(&0.0) {
            return Err(format!("`{text}`: the steps must land on 0 (FROM a multiple of STEP)"));
        }
        Ok(range)
    }
}

/// `base` with every ring `garment` covers grown by `delta_mm` of girth (its target girth
/// too); other actuators as in `base`.
pub fn step_setpoints(
    form: &FormDescription,
    garment: &GarmentSpec,
    base: &SetPoints,
    delta_mm: f64,
) -> SetPoints {
    let mut step = base.clone();
    if delta_mm == 0.0 {
        return step;
    }
    for band in &garment.bands {
        let Some(skin) = RingSkin::of(form, &band.ring, &base.positions_mm) else { continue };
        let wanted = skin.girth_mm() + delta_mm;
        let longest = skin.actuators.iter().map(|a| a.stroke_mm).fold(0.0, f64::max);
        let at = |offset: f64| -> BTreeMap<String, f64> {
            let mut positions = base.positions_mm.clone();
            for a in &skin.actuators {
                let from = base.positions_mm.get(&a.id).copied().unwrap_or(0.0);
                positions.insert(a.id.clone(), (from + offset).clamp(0.0, a.stroke_mm));
            }
            positions
        };
        let girth =
            |offset: f64| RingSkin::of(form, &band.ring, &at(offset)).map_or(0.0, |s| s.girth_mm());
        let (mut lo, mut hi) = (-longest, longest);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if girth(mid) < wanted { lo = mid } else { hi = mid }
        }
        let ring: Vec<&str> = skin.actuators.iter().map(|a| a.id.as_str()).collect();
        for (id, e) in at(0.5 * (lo + hi)) {
            if ring.contains(&id.as_str()) {
                step.positions_mm.insert(id, e);
            }
        }
        if let Some(target) = step.target_girths_mm.get_mut(&band.ring) {
            *target += delta_mm;
        }
    }
    step
}

/// One step of a sweep: how far from the customer's girths, and the fit there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepStep {
    /// Girth added to every covered ring, mm.
    pub delta_mm: f64,
    /// The garment's fit at this step.
    pub fit: FitTest,
}

/// Where a ring's mean pressure crosses the sweep's limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Crossing {
    /// The ring.
    pub ring: String,
    /// The form's girth there, mm (between the two steps around it, linear in pressure;
    /// the first step's when the ring is over the limit from the start).
    pub girth_mm: f64,
    /// The sweep's offset there, mm.
    pub delta_mm: f64,
    /// The first step at or over the limit, mm.
    pub step_delta_mm: f64,
    /// The ring was over the limit from the sweep's first step: it crosses somewhere below.
    pub from_start: bool,
}

/// What a sweep found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sweep {
    /// The pressure a sweep looks for, kPa: the comfort limit for daily wear (where the
    /// garment binds), class I's lower bound for a compression garment (where it starts to
    /// compress).
    pub limit_kpa: f64,
    /// Every step, smallest first.
    pub steps: Vec<SweepStep>,
    /// Each ring's crossing of the limit, if it crossed within the sweep.
    pub crossings: Vec<Crossing>,
    /// The first ring to cross: where the garment starts to bind.
    pub binds: Option<Crossing>,
    /// The steps where no ring is over the limit and every ring took its step's girth (the
    /// run nearest the customer's girths), mm of offset: the garment's usable size range.
    pub usable_mm: Option<[f64; 2]>,
    /// Steps where some ring could not take its girth (its panels at the ends of their
    /// strokes), mm of offset: left out of the crossings and the usable range.
    pub saturated_mm: Vec<f64>,
}

/// How far a ring's girth on the form may be off its step's before the step counts as out of
/// the form's reach, mm: the girth tolerance a drive judges a shape by.
const REACH_MM: f64 = crate::form::form_fit::DEFAULT_GIRTH_TOLERANCE_MM;

/// Whether every ring of `fit` took its girth (within [`REACH_MM`]).
fn reached(fit: &FitTest) -> bool {
    fit.rings
        .iter()
        .all(|r| r.body_girth_mm.is_none_or(|b| (r.form_girth_mm - b).abs() <= REACH_MM))
}

/// The pressure a sweep of a garment of `kind` looks for ([`Sweep::limit_kpa`]).
pub fn limit_for(kind: GarmentKind) -> f64 {
    match kind {
        GarmentKind::Daily => super::comfort::COMFORT_LIMIT_KPA,
        GarmentKind::Compression => super::comfort::CLASS_I_FROM_KPA,
    }
}

/// Finds the crossings, the binding ring and the usable range of `steps` (smallest first)
/// against `limit_kpa`.
pub fn analyse(steps: Vec<SweepStep>, limit_kpa: f64) -> Sweep {
    let saturated_mm: Vec<f64> =
        steps.iter().filter(|s| !reached(&s.fit)).map(|s| s.delta_mm).collect();
    let rings: Vec<String> = steps
        .first()
        .map(|s| s.fit.rings.iter().map(|r| r.ring.clone()).collect())
        .unwrap_or_default();
    let mut crossings = Vec::new();
    for ring in &rings {
        let curve: Vec<(f64, f64, f64)> = steps
            .iter()
            .filter(|s| reached(&s.fit))
            .filter_map(|s| {
                let r = s.fit.rings.iter().find(|r| &r.ring == ring)?;
                Some((s.delta_mm, r.form_girth_mm, r.mean_pressure_kpa))
            })
            .collect();
        let Some(k) = curve.iter().position(|&(_, _, p)| p >= limit_kpa) else { continue };
        let (delta_k, girth_k, p_k) = curve[k];
        let (girth_mm, delta_mm) = match k.checked_sub(1).map(|j| curve[j]) {
            Some((delta_j, girth_j, p_j)) if p_k > p_j => {
                let t = (limit_kpa - p_j) / (p_k - p_j);
                (girth_j + t * (girth_k - girth_j), delta_j + t * (delta_k - delta_j))
            }
            _ => (girth_k, delta_k),
        };
        crossings.push(Crossing {
            ring: ring.clone(),
            girth_mm,
            delta_mm,
            step_delta_mm: delta_k,
            from_start: k == 0,
        });
    }
    let binds = crossings.iter().min_by(|a, b| a.delta_mm.total_cmp(&b.delta_mm)).cloned();
    let ok: Vec<bool> = steps
        .iter()
        .map(|s| reached(&s.fit) && s.fit.rings.iter().all(|r| r.mean_pressure_kpa <= limit_kpa))
        .collect();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (k, &fine) in ok.iter().enumerate() {
        match runs.last_mut() {
            Some(run) if fine && run.1 + 1 == k => run.1 = k,
            _ if fine => runs.push((k, k)),
            _ => {}
        }
    }
    let distance = |&(a, b): &(usize, usize)| {
        let (lo, hi) = (steps[a].delta_mm, steps[b].delta_mm);
        if lo <= 0.0 && hi >= 0.0 { 0.0 } else { lo.abs().min(hi.abs()) }
    };
    let usable_mm = runs
        .iter()
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        .map(|&(a, b)| [steps[a].delta_mm, steps[b].delta_mm]);
    Sweep { limit_kpa, steps, crossings, binds, usable_mm, saturated_mm }
}

/// The sweep as a table: pressure per ring and step, then the crossings.
pub fn table(sweep: &Sweep) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let rings: Vec<&str> = sweep
        .steps
        .first()
        .map(|st| st.fit.rings.iter().map(|r| r.ring.as_str()).collect())
        .unwrap_or_default();
    let _ = write!(s, "  {:>7}", "step");
    for ring in &rings {
        let _ = write!(s, " {ring:>16}");
    }
    let _ = writeln!(s);
    for step in &sweep.steps {
        let _ = write!(s, "  {:>+7.1}", step.delta_mm);
        for r in &step.fit.rings {
            let cell = format!("{:.1} {:.2}", r.form_girth_mm, r.mean_pressure_kpa);
            let _ = write!(s, " {cell:>16}");
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "  (each ring's girth on the form, mm, and mean pressure, kPa, at each step's offset)"
    );
    for c in &sweep.crossings {
        if c.from_start {
            let _ = writeln!(
                s,
                "  {} is over {:.2} kPa from the first step ({:.1} mm)",
                c.ring, sweep.limit_kpa, c.girth_mm
            );
        } else {
            let _ = writeln!(
                s,
                "  {} crosses {:.2} kPa at {:.1} mm ({:+.1} mm; first step over: {:+.1})",
                c.ring, sweep.limit_kpa, c.girth_mm, c.delta_mm, c.step_delta_mm
            );
        }
    }
    if !sweep.saturated_mm.is_empty() {
        let steps: Vec<String> = sweep.saturated_mm.iter().map(|d| format!("{d:+.0}")).collect();
        let _ = writeln!(
            s,
            "  beyond the form's reach (a ring at the ends of its strokes) at {} mm: left out",
            steps.join(", ")
        );
    }
    match &sweep.binds {
        Some(b) => {
            let _ = writeln!(s, "  binds first at the {} ({:+.1} mm)", b.ring, b.delta_mm);
        }
        None => {
            let _ = writeln!(s, "  no ring crosses {} kPa within the sweep", sweep.limit_kpa);
        }
    }
    match sweep.usable_mm {
        Some([a, b]) => {
            let _ = writeln!(s, "  usable from {a:+.1} to {b:+.1} mm of girth");
        }
        None => {
            let _ = writeln!(s, "  no step where every ring is under {} kPa", sweep.limit_kpa);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_step() {
        let r: SweepRange = DEFAULT_SWEEP.parse().unwrap();
        assert_eq!(r.deltas().len(), 17);
        assert_eq!(r.deltas()[0], -40.0);
        assert_eq!(*r.deltas().last().unwrap(), 40.0);
        assert!("1:0:1".parse::<SweepRange>().unwrap_err().contains("FROM must not"));
        assert!("10:20:5".parse::<SweepRange>().unwrap_err().contains("include 0"));
        assert!("-7:10:5".parse::<SweepRange>().unwrap_err().contains("land on 0"));
        assert!("0:1e12:1".parse::<SweepRange>().unwrap_err().contains("at most"));
        assert!("-1e308:1e308:1".parse::<SweepRange>().unwrap_err().contains("at most"));
        assert!("0:10:0".parse::<SweepRange>().unwrap_err().contains("above 0"));
        assert!("0:1000:1".parse::<SweepRange>().unwrap_err().contains("at most"));
        assert!("a:1:1".parse::<SweepRange>().unwrap_err().contains("not a number"));
        assert!("1:2".parse::<SweepRange>().unwrap_err().contains("FROM:TO:STEP"));
    }

    #[test]
    fn a_step_grows_each_covered_ring_by_its_girth() {
        let form = form_description::reference();
        let garment = GarmentSpec::from_toml_str(
            form_description::garment::shipped("jersey-top").unwrap(),
            &form,
        )
        .unwrap();
        let positions = form.actuators.iter().map(|a| (a.id.clone(), 20.0)).collect();
        let base = SetPoints {
            format: crate::form::setpoints::FORMAT.into(),
            form: form.name.clone(),
            positions_mm: positions,
            target_girths_mm: BTreeMap::from([("waist".to_string(), 800.0)]),
            target_heights_mm: BTreeMap::new(),
        };
        for delta in [-30.0, 15.0] {
            let step = step_setpoints(&form, &garment, &base, delta);
            for ring in ["chest", "under-bust", "waist"] {
                let g0 = RingSkin::of(&form, ring, &base.positions_mm).unwrap().girth_mm();
                let g1 = RingSkin::of(&form, ring, &step.positions_mm).unwrap().girth_mm();
                assert!((g1 - g0 - delta).abs() < 0.01, "{ring}: {g0} -> {g1}");
            }
            let hip = form.actuators.iter().find(|a| a.ring == "hip").unwrap();
            assert_eq!(step.positions_mm[&hip.id], 20.0, "a ring the garment lacks stays");
            assert_eq!(step.target_girths_mm["waist"], 800.0 + delta);
        }
    }
}
