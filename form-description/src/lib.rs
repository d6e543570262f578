//! Form descriptions: which nodes a robotic dress form has, which actuators they drive, and
//! where those actuators push on the body — what the dressform host and the form's nodes
//! (real or simulated) agree on besides the wire protocol.
//!
//! A description is TOML ([`FormDescription::from_toml_str`], [`FormDescription::load`]);
//! [`reference()`] is the form shipped in `forms/reference.toml` (64 actuators on 8 nodes,
//! neck to mid-thigh). The host (`dressform`: fitting, set-points, the controller) and the
//! simulator (`form-sim`) both read descriptions from here; this crate knows nothing of either.
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
//! anchor = "chest"       # optional: set to the mannequin's neck, chest, waist or hip level
//! # part = "left-leg"    # what it shapes: "torso" (default), "left-leg" or "right-leg"
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
//! ring's height ([`FormSpec::panel_position`]).
//!
//! **Symmetry.** The form is mirror-symmetric about the plane x = 0. A left actuator names its
//! right partner with `mirror` (either side may name the other): the partner sits on the same
//! ring (or, for an off-centre ring, on its mirror ring at the mirrored centre) at angle
//! `360 - a`, with the same stroke, limits, base radius and panel width. Actuators on the
//! centre line (0° or 180° on a ring centred on the body axis) are their own mirror.
//!
//! **Ring roles.** A ring states what it shapes (`part`: a torso ring is centred on x = 0, a
//! leg ring sits on its leg's side) and, for the rings set to a mannequin level, that level
//! (`anchor`, each at most once); nothing is guessed from a ring's name or position.
//!
//! **Validation.** A [`FormDescription`] exists only validated: the loaders and
//! `FormDescription::try_from(`[`FormSpec`]`)` (what a file says, unchecked) report every
//! problem at once, each naming the node, ring or actuator and the field: node addresses outside
//! 1..=63 or used twice, nodes without actuators, duplicate ids, unknown nodes or rings,
//! channels outside 0..=7, used twice or not numbered 0..n-1 on a node (the protocol numbers
//! a node's actuators from 0), non-finite, zero or negative lengths, strokes, speeds and
//! accelerations or ones the wire cannot carry (stroke ≤ 655.34 mm, speed ≤ 655.35 mm/s,
//! acceleration ≤ 6553.5 mm/s²), angles outside [0, 360), asymmetric or conflicting mirror
//! pairs, actuators off the centre line without a partner, a ring's `part` that does not
//! match its centre and an anchor used twice or on a leg ring. Ids may use letters, digits,
//! `-`, `_` and `.`; `node<N>` is reserved for node names in fault specs.
//!
//! Problems show the numbers a file gives short ([`number`]: `1e308`, not 309 digits), so the
//! reason always fits on its line.
//!
//! A node reports one set of capabilities (the weakest of its actuators), and its actuators'
//! speed and acceleration limits default to them, so give all actuators of a node the same
//! limits (the reference form does).

mod description;
mod file;
mod number;
mod validate;

pub use description::{
    ActuatorSpec, Anchor, BodyPart, FormDescription, FormSpec, NodeSpec, RingSpec,
};
pub use file::{FormError, REFERENCE_TOML, reference};
pub use number::{Number, number};
pub use validate::Problem;
