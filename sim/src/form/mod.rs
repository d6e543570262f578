//! Form descriptions: which nodes a robotic dress form has, which actuators they drive, and
//! where those actuators push on the body.
//!
//! A description is TOML ([`FormDescription::from_toml_str`], [`FormDescription::load`]);
//! [`reference()`] is the form shipped in `sim/forms/reference.toml` (64 actuators on 8 nodes,
//! neck to mid-thigh). The root package and the simulator both read descriptions from here.
//!
//! ```toml
//! name = "reference"
//!
//! [[node]]
//! address = 2            # bus address, 1..=63
//! label = "chest"        # optional, for people
//!
//! [[ring]]
//! name = "chest"
//! height_mm = 1280.0     # height of the ring above the floor
//! center_mm = [0.0, 0.0] # optional: the ring's axis in the X-Y plane (default: body axis)
//! # mirror = "..."       # off-centre rings (thighs) name their mirror ring
//!
//! [[actuator]]
//! id = "chest-l1"        # stable id, used by set-point files and fault specs
//! node = 2               # node address
//! channel = 1            # actuator index on that node, 0..=7
//! ring = "chest"
//! angle_deg = 45.0       # around the ring axis, see below
//! base_radius_mm = 121.6 # panel distance from the ring axis when retracted
//! panel_width_mm = 81.0  # panel chord, tangential to the ring
//! stroke_mm = 60.0       # travel outwards from the retracted position
//! max_speed_mm_s = 12.0
//! max_accel_mm_s2 = 50.0
//! mirror = "chest-r1"    # left actuators name their right partner
//! ```
//!
//! **Geometry.** Coordinates are the mannequin's canonical frame: millimetres, Z up with the
//! floor at z = 0, +X = the subject's left, the subject faces -Y. `angle_deg` is measured
//! around the ring's axis from the **front (-Y), increasing towards the subject's left
//! (+X)** — counter-clockwise seen from above — so 90° is the left side, 180° the back and
//! 270° the right side; the outward direction is `(sin a, -cos a, 0)`. At extension `e`
//! (0..=stroke) a panel's centre is at `center + (base_radius + e) · direction`, at the
//! ring's height ([`FormDescription::panel_position`]).
//!
//! **Symmetry.** The form is mirror-symmetric about the plane x = 0. A left actuator names its
//! right partner with `mirror` (either side may name the other): the partner sits on the same
//! ring (or, for an off-centre ring, on its mirror ring at the mirrored centre) at angle
//! `360 - a`, with the same stroke, limits, base radius and panel width. Actuators on the
//! centre line (0° or 180° on a ring centred on the body axis) are their own mirror.
//!
//! **Validation** ([`FormDescription::validate`], run by the loaders) reports every problem
//! at once, each naming the node, ring or actuator and the field: node addresses outside
//! 1..=63 or used twice, nodes without actuators, duplicate ids, unknown nodes or rings,
//! channels outside 0..=7, used twice or not numbered 0..n-1 on a node (the protocol numbers
//! a node's actuators from 0), non-finite, zero or negative lengths, strokes, speeds and
//! accelerations or ones the wire cannot carry (stroke ≤ 655.34 mm, speed ≤ 655.35 mm/s,
//! acceleration ≤ 6553.5 mm/s²), angles outside [0, 360), asymmetric or conflicting mirror
//! pairs and actuators off the centre line without a partner. Ids may use letters, digits,
//! `-`, `_` and `.`; `node<N>` is reserved for node names in fault specs.
//!
//! A node reports one set of capabilities (the weakest of its actuators), and its actuators'
//! speed and acceleration limits default to them, so give all actuators of a node the same
//! limits (the reference form does).

mod description;
mod validate;

pub use description::{ActuatorSpec, FormDescription, NodeSpec, RingSpec};
pub use validate::Problem;

use std::path::PathBuf;

/// The reference form's description, as shipped in `sim/forms/reference.toml`.
pub const REFERENCE_TOML: &str = include_str!("../../forms/reference.toml");

/// The shipped reference form: 64 actuators on 8 nodes from neck to mid-thigh (see
/// `sim/README.md` for its layout).
pub fn reference() -> FormDescription {
    // The file is part of the crate and a test checks it validates.
    FormDescription::from_toml_str(REFERENCE_TOML)
        .unwrap_or_else(|error| unreachable!("the shipped reference form is invalid: {error}"))
}

/// Why a form description could not be used.
#[derive(Debug, thiserror::Error)]
pub enum FormError {
    /// The file could not be read.
    #[error("cannot read form description {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML, or not the shape of a form description (the message names the field).
    #[error("{}{source}", origin(path))]
    Toml {
        /// The file, if read from one.
        path: Option<PathBuf>,
        /// The parser's error, with line, column and field.
        source: toml::de::Error,
    },
    /// Well-formed but inconsistent: every problem found.
    #[error("{}invalid form description:{}", origin(path), list(problems))]
    Invalid {
        /// The file, if read from one.
        path: Option<PathBuf>,
        /// Every problem, in file order.
        problems: Vec<Problem>,
    },
}

fn origin(path: &Option<PathBuf>) -> String {
    path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default()
}

fn list(problems: &[Problem]) -> String {
    problems.iter().map(|p| format!("\n  - {p}")).collect()
}
