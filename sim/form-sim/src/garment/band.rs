//! The load a band puts on its ring's panels (see the module above for the model).

use std::collections::BTreeMap;

use form_description::FormDescription;
use form_description::skin::{KPA_PER_N_PER_MM2, RingSkin};

use super::BandSpec;

/// Millimetres per metre: tensions are per metre of band width, widths in mm.
const MM_PER_M: f64 = 1000.0;

/// What one panel carries.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelLoad {
    /// Its actuator.
    pub actuator: String,
    /// The force pressing it inwards along its actuator, N: what its sensor reads.
    pub force_n: f64,
    /// The whole press of the band on it, N (the part across its actuator goes into its
    /// guides).
    pub normal_n: f64,
    /// Its share of the band: half of each skin edge at its ends times the band's width, mm²
    /// (0 for a panel under its neighbours' skin, which the band does not touch).
    pub area_mm2: f64,
}

impl PanelLoad {
    /// The contact pressure, kPa: the press over the panel's share of the band.
    pub fn pressure_kpa(&self) -> f64 {
        if self.area_mm2 > 0.0 { KPA_PER_N_PER_MM2 * self.normal_n / self.area_mm2 } else { 0.0 }
    }
}

/// A band on its ring, at the form's actuator positions.
#[derive(Clone, Debug, PartialEq)]
pub struct BandLoad {
    /// The ring.
    pub ring: String,
    /// The skin's girth, what the band is stretched to when tight, mm.
    pub skin_girth_mm: f64,
    /// The band's relaxed girth minus the skin's, mm: negative where the band is stretched.
    pub ease_mm: f64,
    /// Its strain, % (0 when loose).
    pub strain_percent: f64,
    /// Its tension, N per metre of width (0 when loose).
    pub tension_n_per_m: f64,
    /// The band's width, mm.
    pub width_mm: f64,
    /// Every panel of the ring.
    pub panels: Vec<PanelLoad>,
}

impl BandLoad {
    /// The mean pressure over the band, kPa: its whole press over the band's area (the skin's
    /// girth times its width); Laplace's `2π T / C` on the panel polygon.
    pub fn mean_pressure_kpa(&self) -> f64 {
        let force: f64 = self.panels.iter().map(|p| p.normal_n).sum();
        KPA_PER_N_PER_MM2 * force / (self.skin_girth_mm * self.width_mm)
    }
}

/// The load `band` puts on the panels of its ring of `form` with the actuators at
/// `positions_mm` (id → extension, mm; missing ones retracted); `None` for a ring without
/// actuators.
pub fn band_load(
    form: &FormDescription,
    band: &BandSpec,
    positions_mm: &BTreeMap<String, f64>,
) -> Option<BandLoad> {
    let skin = RingSkin::of(form, &band.ring, positions_mm)?;
    let skin_girth_mm = skin.girth_mm();
    let ease_mm = band.relaxed_girth_mm - skin_girth_mm;
    let strain_percent = (100.0 * -ease_mm / band.relaxed_girth_mm).max(0.0);
    let tension_n_per_m = band.stretch().tension(strain_percent);
    let width_m = band.width_mm / MM_PER_M;
    let mut panels: Vec<PanelLoad> = skin
        .actuators
        .iter()
        .zip(skin.shares_mm())
        .map(|(a, share)| PanelLoad {
            actuator: a.id.clone(),
            force_n: 0.0,
            normal_n: 0.0,
            area_mm2: share * band.width_mm,
        })
        .collect();
    for (panel, gain) in panels.iter_mut().zip(skin.gains()) {
        panel.force_n = tension_n_per_m * width_m * gain.axial;
        panel.normal_n = tension_n_per_m * width_m * gain.normal;
    }
    Some(BandLoad {
        ring: band.ring.clone(),
        skin_girth_mm,
        ease_mm,
        strain_percent,
        tension_n_per_m,
        width_mm: band.width_mm,
        panels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::garment::{GarmentSpec, Stretch};
    use form_description::ActuatorSpec;
    use std::f64::consts::TAU;

    /// A round ring of 16 panels, 60 mm from the axis retracted, 20 mm wide.
    fn round_form() -> FormDescription {
        let mut spec = form_description::reference().into_spec();
        spec.lifts.clear();
        spec.nodes.retain(|n| n.address <= 2);
        spec.rings.retain(|r| r.name == "chest");
        spec.actuators = (0..16)
            .map(|k| ActuatorSpec {
                id: format!("p{k}"),
                node: 1 + (k / 8) as u8,
                channel: (k % 8) as u8,
                ring: "chest".into(),
                angle_deg: 22.5 * k as f64,
                base_radius_mm: 60.0,
                panel_width_mm: 20.0,
                stroke_mm: 100.0,
                max_speed_mm_s: 10.0,
                max_accel_mm_s2: 50.0,
                force_limit_n: None,
                mirror: (k > 0 && k < 8).then(|| format!("p{}", 16 - k)),
            })
            .collect();
        FormDescription::try_from(spec).unwrap()
    }

    fn garment(form: &FormDescription, band: &str) -> GarmentSpec {
        GarmentSpec::from_toml_str(
            &format!("name = \"t\"\n[[band]]\nring = \"chest\"\n{band}"),
            form,
        )
        .unwrap()
    }

    /// On a round ring every panel presses with Laplace's `T / r` (here the 32-gon's corners
    /// carry `2 T sin(θ/2)` for `T θ`: 0.6% under) and the mean is `2π T / C`.
    #[test]
    fn a_tight_band_on_a_round_ring_follows_laplaces_law() {
        let form = round_form();
        let positions: BTreeMap<String, f64> =
            form.actuators.iter().map(|a| (a.id.clone(), 40.0)).collect();
        let band = &garment(&form, "relaxed_girth_mm = 600.0\ntension_n_per_m_per_percent = 10.0")
            .bands[0];
        let load = band_load(&form, band, &positions).unwrap();
        let strain = 100.0 * (load.skin_girth_mm - 600.0) / 600.0;
        assert!((load.strain_percent - strain).abs() < 1e-9 && strain > 0.0);
        assert!((load.ease_mm + load.skin_girth_mm - 600.0).abs() < 1e-9);
        let laplace = TAU * load.tension_n_per_m / load.skin_girth_mm; // kPa: N/m over mm
        assert!((load.mean_pressure_kpa() / laplace - 1.0).abs() < 0.01, "{load:?}");
        for p in &load.panels {
            assert!((p.pressure_kpa() / laplace - 1.0).abs() < 0.01, "{p:?} vs {laplace}");
        }
        // The forces add up to the band's: 2π T times its width, within the polygon's 0.6%.
        let total: f64 = load.panels.iter().map(|p| p.force_n).sum();
        let band_force = TAU * load.tension_n_per_m * band.width_mm / MM_PER_M;
        assert!((total / band_force - 1.0).abs() < 0.01, "{total} vs {band_force}");
    }

    /// A band at least as long as the skin carries nothing.
    #[test]
    fn a_loose_band_carries_nothing() {
        let form = round_form();
        let band = &garment(&form, "relaxed_girth_mm = 900.0\ntension_n_per_m_per_percent = 10.0")
            .bands[0];
        let load = band_load(&form, band, &BTreeMap::new()).unwrap();
        assert!(load.ease_mm > 0.0);
        assert_eq!((load.strain_percent, load.tension_n_per_m), (0.0, 0.0));
        assert!(load.panels.iter().all(|p| p.force_n == 0.0 && p.pressure_kpa() == 0.0));
    }

    /// A measured curve is read linearly between its points and along its last slope beyond.
    #[test]
    fn a_measured_curve_interpolates() {
        let curve = Stretch::Measured { points: vec![[0.0, 0.0], [10.0, 60.0], [20.0, 150.0]] };
        assert_eq!(curve.tension(-5.0), 0.0);
        assert!((curve.tension(5.0) - 30.0).abs() < 1e-12);
        assert!((curve.tension(15.0) - 105.0).abs() < 1e-12);
        assert!((curve.tension(30.0) - 240.0).abs() < 1e-12);
    }

    /// Bad descriptions are refused with every problem named.
    #[test]
    fn bad_descriptions_name_the_band_and_field() {
        let form = round_form();
        let text = "name = \"t\"\n[[band]]\nring = \"knee\"\nrelaxed_girth_mm = -1\n\
                    tension_n_per_m_per_percent = 1\n[[band]]\nring = \"chest\"\n\
                    relaxed_girth_mm = 900\nforce_extension = [[0, 0], [10, 50], [5, 60]]\n";
        let message = GarmentSpec::from_toml_str(text, &form).unwrap_err().to_string();
        assert!(
            message.contains("band `knee`: the form \"reference\" has no ring `knee`"),
            "{message}"
        );
        assert!(
            message.contains("band `knee`: `relaxed_girth_mm` = -1 must be a length"),
            "{message}"
        );
        assert!(message.contains("band `chest`: `force_extension`: strain must rise"), "{message}");
        let both = "name = \"t\"\n[[band]]\nring = \"chest\"\nrelaxed_girth_mm = 900\n";
        let message = GarmentSpec::from_toml_str(both, &form).unwrap_err().to_string();
        assert!(message.contains("one of the two"), "{message}");
        let typo = "name = \"t\"\n[[band]]\nring = \"chest\"\nrelaxed_girth = 900\n";
        let message = GarmentSpec::from_toml_str(typo, &form).unwrap_err().to_string();
        assert!(message.contains("relaxed_girth"), "{message}");
    }
}
