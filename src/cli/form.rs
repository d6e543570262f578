//! `dressform form show [--form <form.toml>] [--toml]`: the form description a command
//! uses — the built-in reference form unless `--form` names a file — as a summary, or as
//! TOML to copy and edit (`dressform form show --toml > myform.toml`).

use super::Failure;
use super::link::FormArg;
use dressform::form::form_fit::ring_girth;
use form_description::FormDescription;
use std::collections::BTreeMap;

#[derive(Debug, clap::Args)]
pub struct FormArgs {
    #[command(subcommand)]
    action: FormAction,
}

#[derive(Debug, clap::Subcommand)]
enum FormAction {
    /// Print the form description: a summary, or its TOML with --toml.
    Show(ShowArgs),
}

#[derive(Debug, clap::Args)]
struct ShowArgs {
    #[command(flatten)]
    form: FormArg,
    /// Print the TOML text (the built-in form's, with its comments) instead of a summary.
    #[arg(long)]
    toml: bool,
}

pub fn run(args: &FormArgs) -> Result<(), Failure> {
    let FormAction::Show(show) = &args.action;
    let form = show.form.load()?;
    if show.toml {
        // Loading checked that it reads and validates.
        out!("{}", show.form.toml_text()?);
    } else {
        out!("{}", summary(&form));
    }
    Ok(())
}

/// Nodes, rings (with their girth range) and actuators.
fn summary(form: &FormDescription) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "form \"{}\": {} nodes, {} rings, {} actuators, {} lifts",
        form.name,
        form.nodes.len(),
        form.rings.len(),
        form.actuators.len(),
        form.lifts.len()
    );
    for node in &form.nodes {
        let count = form.axes().filter(|a| a.node == node.address).count();
        let label = node.label.as_deref().unwrap_or("-");
        let _ = writeln!(s, "  node {:>2}  {label:<20} {count} actuators", node.address);
    }
    let _ = writeln!(
        s,
        "  {:<12} {:>9} {:>16} {:>22} {:>16}",
        "ring", "height", "centre (x, y)", "girth range (mm)", "height range"
    );
    for ring in &form.rings {
        let at = |stroke: bool| -> BTreeMap<String, f64> {
            let on_ring = form.actuators.iter().filter(|a| a.ring == ring.name);
            on_ring.map(|a| (a.id.clone(), if stroke { a.stroke_mm } else { 0.0 })).collect()
        };
        let (small, large) =
            (ring_girth(form, ring, &at(false)), ring_girth(form, ring, &at(true)));
        let centre = format!("({:.0}, {:.0})", ring.center_mm[0], ring.center_mm[1]);
        let range = format!("{small:.0} .. {large:.0}");
        let raised: BTreeMap<String, f64> =
            form.lifts_of(&ring.name).map(|l| (l.id.clone(), l.stroke_mm)).collect();
        let heights = format!("{:.0} .. {:.0}", ring.height_mm, form.ring_height(ring, &raised));
        let _ = writeln!(
            s,
            "  {:<12} {:>9.0} {centre:>16} {range:>22} {heights:>16}",
            ring.name, ring.height_mm
        );
    }
    let _ = writeln!(
        s,
        "  {:<16} {:>4} {:>3} {:<12} {:>6} {:>7} {:>6} {:>7} {:>7} {:>8}",
        "actuator", "node", "ch", "ring", "angle", "radius", "panel", "stroke", "mm/s", "mm/s²"
    );
    for a in &form.actuators {
        let _ = writeln!(
            s,
            "  {:<16} {:>4} {:>3} {:<12} {:>6.1} {:>7.1} {:>6.1} {:>7.1} {:>7.1} {:>8.1}",
            a.id,
            a.node,
            a.channel,
            a.ring,
            a.angle_deg,
            a.base_radius_mm,
            a.panel_width_mm,
            a.stroke_mm,
            a.max_speed_mm_s,
            a.max_accel_mm_s2
        );
    }
    if !form.lifts.is_empty() {
        let _ = writeln!(
            s,
            "  {:<16} {:>4} {:>3} {:>7} {:>7} {:>8}  raises",
            "lift", "node", "ch", "stroke", "mm/s", "mm/s²"
        );
    }
    for l in &form.lifts {
        let _ = writeln!(
            s,
            "  {:<16} {:>4} {:>3} {:>7.1} {:>7.1} {:>8.1}  {}",
            l.id,
            l.node,
            l.channel,
            l.stroke_mm,
            l.max_speed_mm_s,
            l.max_accel_mm_s2,
            l.rings.join(", ")
        );
    }
    s
}
