//! Form descriptions: which nodes a robotic dress form has, which actuators they drive, and
//! where those actuators push on the body — what the dressform host and the form's nodes
//! (real or simulated) agree on besides the wire protocol.
//!
//! A description is TOML ([`FormDescription::from_toml_str`], [`FormDescription::load`]);
//! [`reference()`] is the form shipped in `forms/reference.toml` (64 panel actuators on 8 nodes,
//! neck to mid-thigh, and 8 lifts on a ninth); [`builtin()`] also gives `male`
//! (`forms/male.toml`). The host (`dressform`: fitting, set-points, the controller) and the
//! simulator (`form-sim`) both read descriptions from here; this crate knows nothing of either.
//! Beside the form: [`skin`] (the skin over a ring, its girth and each panel's share) and
//! [`garment`] (a garment put on the form, for fit tests).
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
//! anchor = "chest"       # optional: the body level it stands for (see "Ring roles")
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
//! # force_limit_n = 50.0 # optional: the force that stalls it (default 50 N)
//! mirror = "chest-r1"    # left actuators name their right partner
//!
//! [[lift]]               # optional: a height axis
//! id = "torso-length"
//! node = 9               # on the bus a lift is one more actuator
//! channel = 0
//! rings = ["chest", "shoulders", "neck"]  # the rings it raises
//! stroke_mm = 120.0      # upward travel
//! max_speed_mm_s = 30.0
//! max_accel_mm_s2 = 60.0
//! ```
//!
//! **Geometry.** Coordinates are the mannequin's canonical frame: millimetres, Z up with the
//! floor at z = 0, +X = the subject's left, the subject faces -Y. `angle_deg` is measured
//! around the ring's axis from the **front (-Y), increasing towards the subject's left
//! (+X)** — counter-clockwise seen from above — so 90° is the left side, 180° the back and
//! 270° the right side; the outward direction is `(sin a, -cos a, 0)`. At extension `e`
//! (0..=stroke) a panel's centre is at `center + (base_radius + e) · direction`, at the
//! ring's height ([`FormSpec::panel_position`]). A ring's `height_mm` is with every lift
//! retracted; its height is that plus the extensions of every lift listing it
//! ([`FormSpec::ring_height`]), so lifts stack. On the bus a lift is an actuator like the
//! panels' ([`FormSpec::axes`] lists both as the bus sees them): no message is specific to it.
//!
//! **Symmetry.** The form is mirror-symmetric about the plane x = 0. A left actuator names its
//! right partner with `mirror` (either side may name the other): the partner sits on the same
//! ring (or, for an off-centre ring, on its mirror ring at the mirrored centre) at angle
//! `360 - a`, with the same stroke, limits, base radius and panel width. Actuators on the
//! centre line (0° or 180° on a ring centred on the body axis) are their own mirror.
//!
//! **Ring roles.** A ring states what it shapes (`part`: a torso ring is centred on x = 0, a
//! leg ring sits on its leg's side) and, for the rings set to a body level, that level
//! (`anchor`: `neck`, `shoulders`, `chest`, `under-bust`, `waist`, `abdomen`, `hip` on torso
//! rings, each at most once; `thigh` on leg rings, once per leg); nothing is guessed from a
//! ring's name or position.
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
//! match its centre, an anchor used twice or of the wrong part, and lifts raising unknown,
//! repeated or no rings, one side without a mirror partner, or able to bring two rings closer
//! than [`MIN_RING_SPACING_MM`]. Ids may use letters, digits,
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
pub mod garment;
mod number;
pub mod skin;
mod validate;

pub use description::{
    ActuatorSpec, Anchor, Axis, BodyPart, DEFAULT_FORCE_LIMIT_N, FormDescription, FormSpec,
    LiftSpec, NodeSpec, RingSpec,
};
pub use file::{BUILTIN, FormError, MALE_TOML, REFERENCE_TOML, builtin, builtin_toml, reference};
pub use number::{Number, number};
pub use validate::{MIN_RING_SPACING_MM, Problem};
