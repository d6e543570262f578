//! The plan of a move: every set-point's actuator with its checked target and limits, the
//! set-points checked against the description's strokes first (refused or clamped, nothing
//! outside a stroke: the rule of [`crate::form::safety`] and "Safety" in
//! `docs/controller-and-safety.md`).

use form_description::FormDescription;

use super::motion::PlannedTarget;
use crate::form::setpoints::{OutOfStroke, SetPoints};

/// Set-points clamped into the stroke: `(actuator id, asked mm, used mm)`.
pub type Clamped = Vec<(String, f64, f64)>;

/// The plan of a move: every set-point's actuator with its checked target and limits.
pub fn plan(
    form: &FormDescription,
    setpoints: &SetPoints,
    clamp: bool,
) -> Result<(Vec<PlannedTarget>, Clamped), OutOfStroke> {
    let checked = setpoints.check(form, clamp)?;
    let plan = checked
        .targets
        .iter()
        .filter_map(|(id, &target)| {
            let spec = form.axis(id)?;
            Some(PlannedTarget {
                id: id.clone(),
                node: spec.node_id()?,
                actuator: spec.actuator()?,
                target,
                max_speed: spec.max_speed(),
                max_accel: spec.max_accel(),
                stroke: spec.stroke().hundredths_mm(),
            })
        })
        .collect();
    Ok((plan, checked.clamped))
}
