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

/// The fidelity report as a table: per ring its height and girth against the body's and the
/// radial gaps all round; then each panel's gap, the lifts' extensions and a line per ring
/// whose shape or girth is limited.
pub fn fidelity_table(fit: &FormFit) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>8} {:>8} {:>7} {:>10} {:>9} {:>7} {:>8} {:>8}  status",
        "ring", "form z", "body z", "error", "mannequin", "form", "error", "rms gap", "max gap"
    );
    for r in &fit.rings {
        let _ = writeln!(
            s,
            "  {:<12} {:>8.1} {:>8.1} {:>7.1} {:>10.1} {:>9.1} {:>7.1} {:>8.1} {:>8.1}  {}",
            r.ring,
            r.form_height_mm,
            r.mannequin_height_mm,
            r.offset_mm,
            r.mannequin_girth_mm,
            r.form_girth_mm,
            r.form_girth_mm - r.mannequin_girth_mm,
            r.rms_radial_gap_mm,
            r.largest_radial_gap_mm,
            r.status(),
        );
    }
    let _ = writeln!(
        s,
        "  (heights above the floor and girths, the form's against the body level's; the radial \
         gaps between the form's skin and the mannequin all round where the ring stands; mm)"
    );
    let _ = writeln!(s, "  each panel's gap, mm (+ outside the mannequin, - pressing in):");
    for r in fit.rings.iter().filter(|r| !r.panel_gaps_mm.is_empty()) {
        let gaps: Vec<String> = r
            .panel_gaps_mm
            .iter()
            .map(|(id, g)| format!("{} {g:+.1}", panel_name(id, &r.ring)))
            .collect();
        let _ = writeln!(s, "    {:<10} {}", r.ring, gaps.join(", "));
    }
    if !fit.lifts_mm.is_empty() {
        let lifts: Vec<String> =
            fit.lifts_mm.iter().map(|(id, e)| format!("{id} {e:.1}")).collect();
        let _ = writeln!(s, "  lifts, mm raised: {}", lifts.join(", "));
    }
    for r in fit.saturated() {
        let actuators: Vec<String> = r.saturated.iter().map(|a| a.to_string()).collect();
        let _ = writeln!(s, "  {}: {} ({})", r.ring, r.girth_reach(), actuators.join(", "));
    }
    s
}

/// An actuator's id without its ring's name in front (`chest-l1` on `chest`: `l1`).
fn panel_name<'a>(id: &'a str, ring: &str) -> &'a str {
    id.strip_prefix(ring).and_then(|rest| rest.strip_prefix('-')).unwrap_or(id)
}
