//! `dressform setpoints <profiles.json> [--form <form.toml>] -o <setpoints.json> [--json]`:
//! the actuator set-points that give the robotic form the mannequin's shape, and how well it
//! fits. The file records each ring's target girth, so `drive` can tell whether the form took
//! the shape.

use super::Failure;
use super::link::FormArg;
use dressform::form::form_fit::{FormFit, fit, regions_of};
use dressform::shape::profiles::Profiles;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct SetpointsArgs {
    /// The mannequin's profiles.json (from `dressform symmetrize`).
    profiles: PathBuf,
    #[command(flatten)]
    form: FormArg,
    /// Where to write the set-point file.
    #[arg(short, long)]
    out: PathBuf,
    /// Print the fidelity report as JSON instead of the table.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &SetpointsArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let profiles =
        Profiles::load(&args.profiles, &regions_of(&form)).map_err(Failure::bad_input)?;
    let fitted = fit(&profiles, &form)
        .map_err(|e| Failure::bad_input(format!("{}: {e}", args.profiles.display())))?;
    fitted.setpoints().save(&args.out).map_err(Failure::other)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&fitted).map_err(Failure::other)?);
    } else {
        out!("{}", fidelity_table(&fitted));
        outln!("set-points written to {}", args.out.display());
    }
    Ok(())
}

/// The fidelity report as a table, with a line per ring whose shape or girth is limited.
pub fn fidelity_table(fit: &FormFit) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>8} {:>8} {:>11} {:>9} {:>8} {:>8}  status",
        "ring", "form z", "body z", "mannequin", "form", "rms gap", "max gap"
    );
    for r in &fit.rings {
        let _ = writeln!(
            s,
            "  {:<12} {:>8.0} {:>8.0} {:>11.1} {:>9.1} {:>8.1} {:>8.1}  {}",
            r.ring,
            r.form_height_mm,
            r.mannequin_height_mm,
            r.mannequin_girth_mm,
            r.form_girth_mm,
            r.rms_radial_gap_mm,
            r.largest_radial_gap_mm,
            r.status(),
        );
    }
    let _ = writeln!(
        s,
        "  (girths, and the radial gaps between the form's skin and the mannequin all round, mm)"
    );
    for r in fit.saturated() {
        let actuators: Vec<String> = r.saturated.iter().map(|a| a.to_string()).collect();
        let _ = writeln!(s, "  {}: {} ({})", r.ring, r.girth_reach(), actuators.join(", "));
    }
    s
}
