//! `dressform setpoints <profiles.json> --form <form.toml> -o <setpoints.json> [--json]`: the
//! actuator set-points that give the robotic form the mannequin's shape, and how well it fits.

use super::Failure;
use dressform::fitting::{Fit, fit};
use dressform::profiles::Profiles;
use dressform::setpoints::SetPoints;
use sim::form::FormDescription;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct SetpointsArgs {
    /// The mannequin's profiles.json (from `dressform symmetrize`).
    profiles: PathBuf,
    /// The form description (TOML).
    #[arg(long)]
    form: PathBuf,
    /// Where to write the set-point file.
    #[arg(short, long)]
    out: PathBuf,
    /// Print the fidelity report as JSON instead of the table.
    #[arg(long)]
    json: bool,
}

/// Reads a profiles.json file.
pub fn load_profiles(path: &Path) -> Result<Profiles, Failure> {
    let bytes = std::fs::read(path)
        .map_err(|e| Failure::bad_input(format!("{}: cannot read: {e}", path.display())))?;
    Profiles::from_json(&bytes).map_err(|e| Failure::bad_input(format!("{}: {e}", path.display())))
}

pub fn run(args: &SetpointsArgs) -> Result<(), Failure> {
    let profiles = load_profiles(&args.profiles)?;
    let form = FormDescription::load(&args.form).map_err(Failure::bad_input)?;
    let fitted = fit(&profiles, &form)
        .map_err(|e| Failure::bad_input(format!("{}: {e}", args.profiles.display())))?;
    SetPoints::new(form.name.clone(), fitted.positions_mm.clone())
        .save(&args.out)
        .map_err(Failure::other)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&fitted).map_err(Failure::other)?);
    } else {
        out!("{}", fidelity_table(&fitted));
        outln!("set-points written to {}", args.out.display());
    }
    Ok(())
}

/// The fidelity report as a table, with a line per saturated ring.
pub fn fidelity_table(fit: &Fit) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>8} {:>8} {:>11} {:>9} {:>9} {:>8}",
        "ring", "form z", "body z", "mannequin", "form", "gap", "status"
    );
    for r in &fit.rings {
        let status = if r.mannequin_girth_mm == 0.0 {
            "no body"
        } else if r.saturated.is_empty() {
            "ok"
        } else {
            "limited"
        };
        let _ = writeln!(
            s,
            "  {:<12} {:>8.0} {:>8.0} {:>11.1} {:>9.1} {:>9.1} {:>8}",
            r.ring,
            r.form_height_mm,
            r.mannequin_height_mm,
            r.mannequin_girth_mm,
            r.form_girth_mm,
            r.largest_radial_gap_mm,
            status
        );
    }
    let _ = writeln!(s, "  (girths and the largest radial gap between panel and mannequin, mm)");
    for r in fit.saturated() {
        let excess = r.mannequin_girth_mm - r.form_girth_mm;
        let size = if excess > 0.5 {
            format!("{excess:.0} mm of girth beyond the form's largest size")
        } else if excess < -0.5 {
            format!("{:.0} mm of girth below the form's smallest size", -excess)
        } else {
            "girth matched; shape limited".to_string()
        };
        let actuators: Vec<String> = r
            .saturated
            .iter()
            .map(|a| {
                let side = if a.beyond_mm > 0.0 {
                    "beyond its stroke"
                } else {
                    "inside its retracted end"
                };
                format!("{} {:.1} mm {side}", a.actuator, a.beyond_mm.abs())
            })
            .collect();
        let _ = writeln!(s, "  {}: {size} ({})", r.ring, actuators.join(", "));
    }
    s
}
