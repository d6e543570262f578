//! A garment on the simulated form: the load a garment ([`GarmentSpec`], described in
//! `form_description::garment`) puts on the form's panels ([`band_load`]).
//!
//! A garment is described per ring of the form as a band: its relaxed girth and how it
//! stretches (a linear tension per unit width per percent of strain, or a measured
//! force-extension table as an EN 14704-1 strip test gives). On the form a band lies on the
//! ring's skin, the convex hull of its panels. A band whose relaxed girth is at least the
//! skin's girth is loose and carries nothing; a tighter one is stretched to the skin's girth and
//! carries the tension `T(strain)` (N per metre of band width). The skin is a polygon, so the
//! band turns only at its corners, the panels' ends: at a corner turning by `θ` it presses
//! inwards with `2 T sin(θ/2)` per metre of width, along the corner's bisector (the capstan
//! balance of a string over a peg). Each panel's actuator carries the part of its ends' forces
//! along its direction. Spread over the panel's share of the band (half of each skin edge at
//! its ends, times the band's width), that is Laplace's law, `P = T / r` with `r` the local
//! radius of curvature of the panel layout; on a round ring `P = 2π T / C`.

mod band;

pub use band::{BandLoad, PanelLoad, band_load};
pub use form_description::garment::{
    BandSpec, DEFAULT_BAND_WIDTH_MM, GarmentError, GarmentKind, GarmentSpec, SHIPPED, Stretch,
};

#[cfg(test)]
mod tests {
    use super::*;
    use form_description::{FormDescription, reference};
    use std::collections::BTreeMap;

    /// The demo customer's girths at the rings the garments cover (mm, from the demo's fit).
    const DEMO_GIRTHS: [(&str, f64); 5] = [
        ("chest", 960.0),
        ("under-bust", 855.0),
        ("waist", 801.6),
        ("abdomen", 917.1),
        ("hip", 1002.3),
    ];

    /// The reference form with each of those rings' panels moved out alike until the skin
    /// has the customer's girth (bisection), the rest retracted.
    fn shaped(form: &FormDescription) -> BTreeMap<String, f64> {
        let mut positions = BTreeMap::new();
        for (ring, girth) in DEMO_GIRTHS {
            let probe = BandSpec {
                ring: ring.into(),
                relaxed_girth_mm: girth,
                width_mm: DEFAULT_BAND_WIDTH_MM,
                tension_n_per_m_per_percent: Some(0.0),
                force_extension: None,
            };
            let (mut lo, mut hi) = (0.0, 60.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                for a in form.actuators.iter().filter(|a| a.ring == ring) {
                    positions.insert(a.id.clone(), mid);
                }
                let skin = band_load(form, &probe, &positions).unwrap().skin_girth_mm;
                if skin < girth { lo = mid } else { hi = mid }
            }
        }
        positions
    }

    fn loads(name: &str) -> Vec<BandLoad> {
        let form = reference();
        let text = SHIPPED.iter().find(|(n, _)| *n == name).unwrap().1;
        let garment = GarmentSpec::from_toml_str(text, &form).unwrap();
        let positions = shaped(&form);
        garment.bands.iter().map(|b| band_load(&form, b, &positions).unwrap()).collect()
    }

    /// On a form shaped to the demo customer: the fitted woven dress touches nothing; the one
    /// too small at the waist stretches 5% there and nowhere else; the jersey top is stretched
    /// at every band to a few tenths of a kPa; the compression body presses 2 kPa or more.
    #[test]
    fn the_shipped_garments_fit_the_demo_customer_as_described() {
        for band in loads("woven-dress") {
            assert!(band.ease_mm >= 20.0 - 1.0 && band.tension_n_per_m == 0.0, "{band:?}");
        }
        for band in loads("woven-dress-small-waist") {
            if band.ring == "waist" {
                assert!((band.ease_mm + 41.6).abs() < 1.0, "{band:?}");
                assert!((band.strain_percent - 5.5).abs() < 0.2, "{band:?}");
                assert!(band.mean_pressure_kpa() > 2.0, "{band:?}");
            } else {
                assert_eq!(band.tension_n_per_m, 0.0, "{band:?}");
            }
        }
        for band in loads("jersey-top") {
            let p = band.mean_pressure_kpa();
            assert!((0.2..1.3).contains(&p), "{}: {p} kPa", band.ring);
        }
        for band in loads("compression-garment") {
            let p = band.mean_pressure_kpa();
            assert!(p > 1.3, "{}: {p} kPa", band.ring);
        }
    }
}
