//! Solving one ring: the extensions that make the form's section match the mannequin's.
//!
//! The form's section at extensions `e` is modelled as the skin stretched over its panels: the
//! convex hull of the panels (flat plates of their width, tangential, centred at
//! `centre + (base_radius + e) · direction`). Each actuator's shape target is where its
//! direction meets the mannequin's section (`R`, the farthest crossing). The start puts every
//! panel's centre on its target and moves them all by one radial offset `δ`, found by
//! bisection, so that the skin's girth equals the mannequin's tape girth (the common-offset
//! rule, [`Placement::CommonOffset`]); the least-squares placement then moves the panels so
//! that the skin lies as close to the section all round as the girth and the strokes allow
//! ([`Placement::LeastSquares`], [`super::least_squares`]). Extensions stay within the
//! stroke; an actuator whose target lies beyond it is reported with the excess.

use super::least_squares::{self, gap_directions, rms};
use crate::body::regions::Region;
use crate::body::slice::{Contour, convex_hull};
use crate::shape::profiles::{ProfileLayer, Profiles};
use crate::shape::symmetry::rays::cast_along;
use form_description::{ActuatorSpec, Anchor, BodyPart, FormDescription, RingSpec};
use glam::DVec2;
use serde::Serialize;
use std::collections::BTreeMap;

/// The smallest shortfall reported as a shape note, mm: below it the gap is within what the
/// mannequin's own surface is known to (a denoised scan's sections to about a millimetre),
/// and listing it would bury the real problems.
pub const SHAPE_NOTE_MM: f64 = 1.0;

/// How a ring's panels are placed once its girth is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    /// Least squares: the skin as close to the section all round as the girth and the
    /// strokes allow (the `least_squares` module).
    #[default]
    LeastSquares,
    /// Every panel's centre on the section, all moved by one offset to the girth: the rule
    /// before issue 31, the least squares' start and the baseline its gain is measured on.
    CommonOffset,
}

/// An actuator that cannot reach its target by at least [`SHAPE_NOTE_MM`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Saturation {
    /// The actuator.
    pub actuator: String,
    /// How far its target lies beyond its travel (mm): positive past the full stroke (the
    /// mannequin is larger there), negative below the retracted end (smaller).
    pub beyond_mm: f64,
}

/// How one ring fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RingFit {
    /// The ring.
    pub ring: String,
    /// The mannequin level it is anchored to, if any.
    pub anchor: Option<Anchor>,
    /// Where the ring stands on the form, its lifts set (mm above the floor).
    pub form_height_mm: f64,
    /// The body level it stands for, where it shapes the mannequin (mm).
    pub mannequin_height_mm: f64,
    /// `form_height_mm - mannequin_height_mm`: the height error, how far the ring sits
    /// from its level.
    pub offset_mm: f64,
    /// Whether a lift carries the ring: only then is its height a target a drive is judged by
    /// (a ring without one stands where it is built, and the error is only reported).
    pub lifted: bool,
    /// The mannequin's tape girth there (mm); 0 where the mannequin has no section.
    pub mannequin_girth_mm: f64,
    /// The form's girth at the set-points (mm).
    pub form_girth_mm: f64,
    /// The root mean square of the radial gaps between the form's skin and the mannequin's
    /// section where the ring stands (its level's once the lifts reach it, or where the
    /// mannequin has no section at its height), over
    /// [`least_squares::GAP_RAYS`] rays from the ring's axis (mm).
    pub rms_radial_gap_mm: f64,
    /// The largest of those gaps, either way (mm). (Before issue 31 this was the largest
    /// gap at the panels' centres: that is now the largest of [`Self::panel_gaps_mm`].)
    pub largest_radial_gap_mm: f64,
    /// Per actuator, its panel's distance from the mannequin along its direction (mm):
    /// positive where the panel stands outside the mannequin's surface, negative inside.
    pub panel_gaps_mm: BTreeMap<String, f64>,
    /// Actuators resting at an end of their stroke whose targets (their direction's crossing
    /// of the section, moved by the girth's common offset) lie [`SHAPE_NOTE_MM`] or more
    /// beyond it.
    pub saturated: Vec<Saturation>,
}

/// The mannequin's section (relative to the form's axis) at height `z` in `region`: the blend
/// of the two layers around it (layers of one region have the same number of points).
pub fn section_at(profiles: &Profiles, region: Region, z: f64) -> Option<Contour> {
    let layers: Vec<&ProfileLayer> =
        profiles.layers.iter().filter(|l| l.region == region).collect();
    let k = layers.windows(2).position(|w| w[0].z <= z && z <= w[1].z)?;
    let (a, b) = (layers[k], layers[k + 1]);
    let t = if b.z > a.z { (z - a.z) / (b.z - a.z) } else { 0.0 };
    let shift = DVec2::new(profiles.axis_x, 0.0);
    let points = a
        .points
        .iter()
        .zip(&b.points)
        .map(|(p, q)| DVec2::from_array(*p).lerp(DVec2::from_array(*q), t) - shift)
        .collect();
    Some(Contour { points })
}

/// The mannequin region a ring shapes, as its description states.
pub fn region_of(ring: &RingSpec) -> Region {
    match ring.part {
        BodyPart::Torso => Region::Torso,
        BodyPart::LeftLeg => Region::LeftLeg,
        BodyPart::RightLeg => Region::RightLeg,
    }
}

/// The girth of the form's skin on `ring` with its actuators at `positions_mm` (id → mm;
/// missing ids count as retracted).
pub fn ring_girth(
    form: &FormDescription,
    ring: &RingSpec,
    positions_mm: &BTreeMap<String, f64>,
) -> f64 {
    ring_skin(form, ring, positions_mm).perimeter()
}

/// The form's skin on `ring` with its actuators at `positions_mm` (id → mm; missing ids
/// count as retracted): the convex hull of its panels, in the form's frame (x = 0 its
/// symmetry plane).
pub fn ring_skin(
    form: &FormDescription,
    ring: &RingSpec,
    positions_mm: &BTreeMap<String, f64>,
) -> Contour {
    let actuators: Vec<&ActuatorSpec> =
        form.actuators.iter().filter(|a| a.ring == ring.name).collect();
    let extensions: Vec<f64> =
        actuators.iter().map(|a| positions_mm.get(&a.id).copied().unwrap_or(0.0)).collect();
    let points = skin_points(DVec2::from_array(ring.center_mm), &actuators, &extensions);
    Contour { points: convex_hull(&points) }
}

/// Girth of the skin over the panels of `actuators` at `extensions`.
fn skin_girth(centre: DVec2, actuators: &[&ActuatorSpec], extensions: &[f64]) -> f64 {
    Contour { points: convex_hull(&skin_points(centre, actuators, extensions)) }.perimeter()
}

/// The ends of the panels of `actuators` at `extensions`: the skin is their convex hull.
fn skin_points(centre: DVec2, actuators: &[&ActuatorSpec], extensions: &[f64]) -> Vec<DVec2> {
    actuators
        .iter()
        .zip(extensions)
        .flat_map(|(a, &e)| a.panel_ends(centre.to_array(), e).map(DVec2::from_array))
        .collect()
}

/// Halvings of the common offset's bracket: it starts a few hundred mm wide, and 60 halvings
/// leave it below the resolution of an `f64` of that size (2⁻⁶⁰ · 1000 mm ≈ 1e-15 mm).
const BISECTION_STEPS: usize = 60;
/// How far (mm) the bracket's ends lie beyond the offsets at which every panel is retracted
/// and every panel is at full stroke, so that both ends are strictly outside.
const BRACKET_MARGIN_MM: f64 = 1.0;
/// A form girth within this of the mannequin's (mm) counts as matched: far below the
/// millimetre a denoised mannequin's surface is known to ([`SHAPE_NOTE_MM`]).
const GIRTH_MATCHED_MM: f64 = 0.01;

/// Fits one ring standing at `height` for body level `level` (`placed`: (level, height), mm);
/// returns its report and the extensions of its actuators. Steps: take the mannequin's section
/// at the level, then match its girth and shape ([`Panels::place`]); a ring with no section
/// stays retracted.
pub(super) fn fit_ring(
    profiles: &Profiles,
    form: &FormDescription,
    ring: &RingSpec,
    (z, height): (f64, f64),
    rule: Placement,
) -> Result<(RingFit, Vec<(String, f64)>), super::FormFitError> {
    let actuators: Vec<&ActuatorSpec> =
        form.actuators.iter().filter(|a| a.ring == ring.name).collect();
    if actuators.is_empty() {
        return Err(super::FormFitError::EmptyRing(ring.name.clone()));
    }
    let centre = DVec2::from_array(ring.center_mm);
    let mut report = RingFit::placed(ring, z, height);
    report.lifted = form.lifts_of(&ring.name).next().is_some();
    let region = region_of(ring);
    let extensions = match section_at(profiles, region, z) {
        Some(section) => {
            let groups = mirror_groups(&actuators);
            let extensions =
                Panels::against(&section, centre, &actuators).place(rule, &groups, &mut report);
            // The gaps are the skin's to the mannequin where the ring stands: off its level, to
            // the section there (where the mannequin has none, above the neck or below the
            // legs, the level's stand).
            if (height - z).abs() > super::heights::TOLERANCE_MM
                && let Some(there) = section_at(profiles, region, height)
            {
                Panels::against(&there, centre, &actuators).report_gaps(&extensions, &mut report);
            }
            extensions
        }
        // No mannequin there (above the neck, below the legs): the ring stays retracted.
        None => {
            let retracted = vec![0.0; actuators.len()];
            report.form_girth_mm = skin_girth(centre, &actuators, &retracted);
            retracted
        }
    };
    let ids = actuators.iter().map(|a| a.id.clone());
    Ok((report, ids.zip(extensions).collect()))
}

impl RingFit {
    /// The report of `ring` standing at `height` for mannequin level `z`, before it is
    /// shaped: no girths, no gap, nothing saturated.
    fn placed(ring: &RingSpec, z: f64, height: f64) -> Self {
        RingFit {
            ring: ring.name.clone(),
            anchor: ring.anchor,
            form_height_mm: height,
            mannequin_height_mm: z,
            offset_mm: height - z,
            lifted: false,
            mannequin_girth_mm: 0.0,
            form_girth_mm: 0.0,
            rms_radial_gap_mm: 0.0,
            largest_radial_gap_mm: 0.0,
            panel_gaps_mm: BTreeMap::new(),
            saturated: Vec::new(),
        }
    }
}

/// For each of `actuators` (one ring's), the least-squares variable it shares with its mirror
/// partner on the same ring (0-based, dense): the partner it names or that names it.
/// Actuators on the centre line and those whose partner is on another ring (a thigh's) have
/// their own.
fn mirror_groups(actuators: &[&ActuatorSpec]) -> Vec<usize> {
    let mut groups = vec![usize::MAX; actuators.len()];
    let mut next = 0;
    for k in 0..actuators.len() {
        if groups[k] != usize::MAX {
            continue;
        }
        groups[k] = next;
        let a = actuators[k];
        let partner = actuators.iter().position(|b| {
            b.id != a.id
                && (a.mirror.as_deref() == Some(b.id.as_str())
                    || b.mirror.as_deref() == Some(a.id.as_str()))
        });
        if let Some(j) = partner {
            groups[j] = next;
        }
        next += 1;
    }
    groups
}

/// A ring's panels against the mannequin's section: where each actuator's direction meets it,
/// and the section's distance along the gap rays.
pub(super) struct Panels<'a> {
    centre: DVec2,
    actuators: &'a [&'a ActuatorSpec],
    /// Each actuator's direction, and the distance from the ring's axis to the section
    /// along it.
    directions: Vec<DVec2>,
    reach: Vec<f64>,
    /// The gap rays' directions, and the section's distance along each.
    rays: Vec<DVec2>,
    section_radii: Vec<f64>,
    /// The section's tape girth: the girth the skin must take.
    target: f64,
}

impl<'a> Panels<'a> {
    /// The panels of `actuators` around `centre`, against `section` (the farthest crossing
    /// along each actuator's direction).
    fn against(section: &Contour, centre: DVec2, actuators: &'a [&'a ActuatorSpec]) -> Self {
        let directions: Vec<DVec2> =
            actuators.iter().map(|a| DVec2::from_array(a.direction())).collect();
        let rays = gap_directions();
        Panels {
            centre,
            reach: cast_along(section, centre, &directions),
            directions,
            section_radii: cast_along(section, centre, &rays),
            rays,
            actuators,
            target: section.tape_girth(),
        }
    }

    /// The extensions whose skin takes the section's tape girth — girth first, shape second,
    /// by `rule` — filling in `report`'s girths, gaps and saturated actuators.
    fn place(&self, rule: Placement, groups: &[usize], report: &mut RingFit) -> Vec<f64> {
        let targets = self.on_section();
        let delta = self.offset_for_girth(&targets);
        let common = self.clamped(&targets, delta);
        // Where the girth is out of reach, every panel is at an end of its stroke already.
        let matched = (self.skin_girth(&common) - self.target).abs() < GIRTH_MATCHED_MM;
        let mut extensions = common.clone();
        if matched && rule == Placement::LeastSquares {
            // Started from the common offset's (clamped, girth matched) extensions; kept only
            // where the skin's RMS gap is no larger (the solver's sum also holds the panels'
            // depths under the skin).
            let solved = least_squares::solve(self, &common, groups);
            if rms(&self.gaps(&solved)) <= rms(&self.gaps(&common)) {
                extensions = solved;
            }
        }
        report.mannequin_girth_mm = self.target;
        report.form_girth_mm = self.skin_girth(&extensions);
        self.report_gaps(&extensions, report);
        // Where the girth is matched, a target's excess is measured at the common offset (and
        // listed only while its panel rests at that end of its stroke); where it is out of
        // reach, at the shape targets themselves.
        report.saturated =
            self.saturations(&targets, if matched { delta } else { 0.0 }, &extensions);
        extensions
    }

    /// The radial gaps all round (RMS and largest) and each panel's at `extensions`, in
    /// `report`.
    fn report_gaps(&self, extensions: &[f64], report: &mut RingFit) {
        let gaps = self.gaps(extensions);
        report.rms_radial_gap_mm = rms(&gaps);
        report.largest_radial_gap_mm = gaps.iter().fold(0.0, |m, g| m.max(g.abs()));
        let ids = self.actuators.iter().map(|a| a.id.clone());
        report.panel_gaps_mm = ids.zip(self.panel_gaps(extensions)).collect();
    }

    /// The extensions that put every panel's centre on the section.
    fn on_section(&self) -> Vec<f64> {
        self.actuators.iter().zip(&self.reach).map(|(a, r)| r - a.base_radius_mm).collect()
    }

    /// `shape` moved out by `delta`, within each actuator's stroke.
    fn clamped(&self, shape: &[f64], delta: f64) -> Vec<f64> {
        shape.iter().zip(self.actuators).map(|(e, a)| (e + delta).clamp(0.0, a.stroke_mm)).collect()
    }

    /// The skin's girth at `extensions`.
    fn skin_girth(&self, extensions: &[f64]) -> f64 {
        skin_girth(self.centre, self.actuators, extensions)
    }

    /// The common radial offset whose clamped extensions of `shape` give the skin the
    /// section's girth (bisection); the bracket's end when the girth is out of reach.
    fn offset_for_girth(&self, shape: &[f64]) -> f64 {
        let girth = |delta: f64| self.skin_girth(&self.clamped(shape, delta));
        // Bracket: below `lo` every panel is retracted, above `hi` every panel is at full stroke.
        let longest_stroke = self.actuators.iter().map(|a| a.stroke_mm).fold(0.0, f64::max);
        let (mut lo, mut hi) = (
            -shape.iter().copied().fold(f64::NEG_INFINITY, f64::max) - BRACKET_MARGIN_MM,
            longest_stroke - shape.iter().copied().fold(f64::INFINITY, f64::min)
                + BRACKET_MARGIN_MM,
        );
        if girth(hi) <= self.target {
            return hi;
        }
        if girth(lo) >= self.target {
            return lo;
        }
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if girth(mid) < self.target { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    }

    /// The actuators resting at an end of their stroke (at `extensions`) whose target
    /// (`shape` moved by `delta`) lies [`SHAPE_NOTE_MM`] or more beyond that end.
    fn saturations(&self, shape: &[f64], delta: f64, extensions: &[f64]) -> Vec<Saturation> {
        self.actuators
            .iter()
            .zip(shape)
            .zip(extensions)
            .filter_map(|((a, e), &at)| {
                let e = e + delta;
                let (beyond, end) = if e > a.stroke_mm {
                    (e - a.stroke_mm, a.stroke_mm)
                } else {
                    (e.min(0.0), 0.0)
                };
                (beyond.abs() >= SHAPE_NOTE_MM && at == end)
                    .then(|| Saturation { actuator: a.id.clone(), beyond_mm: beyond })
            })
            .collect()
    }

    /// The skin over the panels at `extensions`: their ends' convex hull.
    fn skin(&self, extensions: &[f64]) -> Contour {
        Contour { points: convex_hull(&skin_points(self.centre, self.actuators, extensions)) }
    }

    /// The skin's distance minus the section's along each gap ray, on `skin`.
    fn gaps_of(&self, skin: &Contour) -> Vec<f64> {
        let radii = cast_along(skin, self.centre, &self.rays);
        radii.iter().zip(&self.section_radii).map(|(r, s)| r - s).collect()
    }

    /// The skin's distance minus the section's along each gap ray, at `extensions`.
    fn gaps(&self, extensions: &[f64]) -> Vec<f64> {
        self.gaps_of(&self.skin(extensions))
    }

    /// How far each panel at `extensions` lies under `skin` along its direction: 0 for a
    /// panel that carries the skin, more for one inside its neighbours' hull.
    fn under_skin(&self, skin: &Contour, extensions: &[f64]) -> Vec<f64> {
        let radii = cast_along(skin, self.centre, &self.directions);
        let panels = self.actuators.iter().zip(radii).zip(extensions);
        panels.map(|((a, r), e)| r - (a.base_radius_mm + e)).collect()
    }

    /// Each panel's distance from the section along its direction, at `extensions`: positive
    /// outside the mannequin.
    fn panel_gaps(&self, extensions: &[f64]) -> Vec<f64> {
        let panels = self.actuators.iter().zip(&self.reach).zip(extensions);
        panels.map(|((a, r), e)| a.base_radius_mm + e - r).collect()
    }
}

impl least_squares::Ring for Panels<'_> {
    fn extensions(&self, a: &[f64]) -> Vec<f64> {
        self.clamped(a, self.offset_for_girth(a))
    }

    fn residuals(&self, extensions: &[f64]) -> Vec<f64> {
        let skin = self.skin(extensions);
        let mut residuals = self.gaps_of(&skin);
        residuals.extend(self.under_skin(&skin, extensions));
        residuals
    }
}

#[cfg(test)]
mod tests {
    use super::least_squares::Ring;
    use super::*;
    use std::f64::consts::TAU;

    /// A torso ring of eight actuators 45 degrees apart (front, back and three mirror pairs),
    /// 100 mm from the axis retracted, panels 70 mm wide, 60 mm of stroke.
    fn ring() -> Vec<ActuatorSpec> {
        (0..8)
            .map(|k| {
                let angle = 45.0 * k as f64;
                let partner = (8 - k) % 8;
                ActuatorSpec {
                    id: format!("a{k}"),
                    node: 1,
                    channel: k as u8,
                    ring: "test".into(),
                    angle_deg: angle,
                    base_radius_mm: 100.0,
                    panel_width_mm: 70.0,
                    stroke_mm: 60.0,
                    max_speed_mm_s: 10.0,
                    max_accel_mm_s2: 50.0,
                    force_limit_n: None,
                    mirror: (k > 0 && k < 4).then(|| format!("a{partner}")),
                }
            })
            .collect()
    }

    /// The mirror groups of [`ring`]: a_k shares its variable with a_(8-k).
    fn groups() -> Vec<usize> {
        [0, 1, 2, 3, 4, 3, 2, 1].to_vec()
    }

    /// A section from its radius as a function of the angle from the front (-Y, counter-
    /// clockwise seen from above, as the actuators' angles), sampled finely.
    fn section(radius: impl Fn(f64) -> f64) -> Contour {
        let points = (0..720)
            .map(|i| {
                let a = TAU * i as f64 / 720.0;
                DVec2::new(a.sin(), -a.cos()) * radius(a)
            })
            .collect();
        Contour { points }
    }

    /// Places [`ring`] on `section` by `rule`; returns the extensions and the report.
    fn place(section: &Contour, rule: Placement) -> (Vec<f64>, RingFit) {
        let specs = ring();
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        let panels = Panels::against(section, DVec2::ZERO, &actuators);
        let spec = RingSpec {
            name: "test".into(),
            height_mm: 1000.0,
            center_mm: [0.0, 0.0],
            mirror: None,
            part: BodyPart::Torso,
            anchor: None,
        };
        let mut report = RingFit::placed(&spec, 1000.0, spec.height_mm);
        let extensions = panels.place(rule, &mirror_groups(&actuators), &mut report);
        (extensions, report)
    }

    /// The summed squared gap of extensions `e` on `section`.
    fn cost(section: &Contour, e: &[f64]) -> f64 {
        let specs = ring();
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        let panels = Panels::against(section, DVec2::ZERO, &actuators);
        panels.residuals(e).iter().map(|g| g * g).sum()
    }

    /// Checks the least-squares placement on `section`: girth exact, mirror pairs equal,
    /// within the strokes, no worse than the common offset, and no feasible move nearby
    /// (shape vectors around the solution, girth restored) better. Returns the RMS gaps by
    /// least squares and by the common offset.
    fn check_optimum(section: &Contour) -> (f64, f64) {
        let (e, fit) = place(section, Placement::LeastSquares);
        let (_, before) = place(section, Placement::CommonOffset);
        assert!((fit.form_girth_mm - fit.mannequin_girth_mm).abs() < GIRTH_MATCHED_MM);
        for (k, g) in groups().iter().enumerate() {
            let partner = groups().iter().rposition(|h| h == g).unwrap();
            assert!((e[k] - e[partner]).abs() < 1e-9, "a{k} and its mirror");
            assert!((0.0..=60.0).contains(&e[k]));
        }
        assert!(fit.rms_radial_gap_mm <= before.rms_radial_gap_mm + 1e-9);
        let specs = ring();
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        let panels = Panels::against(section, DVec2::ZERO, &actuators);
        let best = cost(section, &e);
        for k in 0..8 {
            for step in [-0.5, 0.5] {
                let mut shape = e.clone();
                // Move a mirror pair together, so the move stays symmetric.
                for (j, g) in groups().iter().enumerate() {
                    if *g == groups()[k] {
                        shape[j] += step;
                    }
                }
                let moved = panels.extensions(&shape);
                assert!(cost(section, &moved) >= best - 1e-6, "a better placement moving a{k}");
            }
        }
        (fit.rms_radial_gap_mm, before.rms_radial_gap_mm)
    }

    #[test]
    fn a_circle_takes_equal_extensions_at_its_girth() {
        let circle = section(|_| 140.0);
        let (e, fit) = place(&circle, Placement::LeastSquares);
        assert!(e.iter().all(|x| (x - e[0]).abs() < 1e-3), "{e:?}");
        assert!((fit.form_girth_mm - TAU * 140.0).abs() < 0.1, "{}", fit.form_girth_mm);
        check_optimum(&circle);
    }

    #[test]
    fn mirror_partners_share_a_variable() {
        let specs = ring();
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        assert_eq!(mirror_groups(&actuators), groups());
    }

    /// The skin of [`ring`] at `known` extensions as a section.
    fn skin_of(specs: &[ActuatorSpec], known: &[f64]) -> Contour {
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        Contour { points: convex_hull(&skin_points(DVec2::ZERO, &actuators, known)) }
    }

    #[test]
    fn a_section_shaped_as_the_panels_is_found_from_elsewhere() {
        // The skin of the ring at known extensions (mirror-symmetric, every panel on the
        // skin) as the section: the optimum is those extensions, with no gap; the solver
        // finds them from a start 4-6 mm off (the common offset's would start on them).
        let specs = ring();
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        let known = [25.0, 22.0, 30.0, 24.0, 18.0, 24.0, 30.0, 22.0];
        let skin = skin_of(&specs, &known);
        let panels = Panels::against(&skin, DVec2::ZERO, &actuators);
        assert!(panels.panel_gaps(&known).iter().all(|g| g.abs() < 1e-9), "all on the skin");
        let off = [29.0, 17.0, 34.0, 19.0, 23.0, 19.0, 34.0, 17.0];
        let e = least_squares::solve(&panels, &panels.extensions(&off), &groups());
        for k in 0..8 {
            assert!((e[k] - known[k]).abs() < 0.01, "a{k}: {} vs {}", e[k], known[k]);
        }
        assert!(rms(&panels.gaps(&e)) < 0.01);
    }

    #[test]
    fn an_optimum_at_a_stroke_end_is_kept_there() {
        // As above, with the side panels' (a2, a6) stroke ending at their known 30 mm, and a
        // start that puts them at that end: they stay there, and the rest find their places.
        let mut specs = ring();
        for k in [2, 6] {
            specs[k].stroke_mm = 30.0;
        }
        let actuators: Vec<&ActuatorSpec> = specs.iter().collect();
        let known = [25.0, 22.0, 30.0, 24.0, 18.0, 24.0, 30.0, 22.0];
        let panels = Panels::against(&skin_of(&specs, &known), DVec2::ZERO, &actuators);
        let start = panels.extensions(&[21.0, 26.0, 36.0, 20.0, 14.0, 20.0, 36.0, 26.0]);
        assert_eq!([start[2], start[6]], [30.0, 30.0], "the start is at the stroke's end");
        let e = least_squares::solve(&panels, &start, &groups());
        for k in 0..8 {
            assert!((e[k] - known[k]).abs() < 0.01, "a{k}: {} vs {}", e[k], known[k]);
            assert!(e[k] <= specs[k].stroke_mm);
        }
    }

    #[test]
    fn an_ellipse_and_a_flat_backed_section_are_at_their_least_squares_optimum() {
        let ellipse = section(|a| {
            let (x, y) = (a.sin() / 160.0, a.cos() / 115.0);
            1.0 / (x * x + y * y).sqrt()
        });
        // Round in front, flat across the back (y = 95 mm behind the axis).
        let flat_back = section(|a| {
            let behind = -a.cos();
            if behind > 0.0 { 140.0_f64.min(95.0 / behind) } else { 140.0 }
        });
        for (name, s) in [("ellipse", ellipse), ("flat back", flat_back)] {
            let (after, before) = check_optimum(&s);
            eprintln!("{name}: RMS gap {after:.2} mm, by one offset {before:.2} mm");
        }
    }

    #[test]
    fn a_section_beyond_the_strokes_keeps_every_panel_at_its_end() {
        let big = section(|_| 200.0);
        let (e, fit) = place(&big, Placement::LeastSquares);
        assert!(e.iter().all(|&x| x == 60.0), "{e:?}");
        assert!(fit.mannequin_girth_mm - fit.form_girth_mm > 200.0);
        assert_eq!(fit.saturated.len(), 8);
    }
}
