//! Validation of a form description: every problem, each naming what and where.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::{
    Force, HUNDREDTHS_PER_MM, HUNDREDTHS_PER_N, NodeId, Position, TENTHS_PER_MM_S2,
};

use super::description::{ActuatorSpec, Axis, BodyPart, FormDescription, FormSpec, RingSpec};
use super::number::number;

/// Smallest stroke, mm: one step of the wire's positions (0.01 mm).
const MIN_STROKE_MM: f64 = 1.0 / HUNDREDTHS_PER_MM;
/// Smallest speed the wire carries above zero (0.01 mm/s), mm/s.
const MIN_SPEED_MM_S: f64 = 1.0 / HUNDREDTHS_PER_MM;
/// Smallest acceleration the wire carries above zero (0.1 mm/s²), mm/s².
const MIN_ACCEL_MM_S2: f64 = 1.0 / TENTHS_PER_MM_S2;
/// Largest speed the wire carries (`u16` in 0.01 mm/s), mm/s.
const MAX_SPEED_MM_S: f64 = 655.35;
/// Largest acceleration the wire carries (`u16` in 0.1 mm/s²), mm/s².
const MAX_ACCEL_MM_S2: f64 = 6553.5;
/// Smallest force limit the wire carries above zero (0.01 N), N.
const MIN_FORCE_N: f64 = 1.0 / HUNDREDTHS_PER_N;
/// Tolerance when comparing mirrored quantities (mm, degrees).
const MIRROR_TOLERANCE: f64 = 1e-6;
/// The least vertical distance between two rings at any extension of the lifts, mm: a
/// design margin, not a measured one (a description gives the panels' widths but not their
/// heights, and two rings closer than a centimetre could not both carry panels). Lifts may not
/// carry a ring onto or past another.
pub const MIN_RING_SPACING_MM: f64 = 10.0;

/// One problem found in a form description.
#[derive(Clone, Debug, PartialEq)]
pub enum Problem {
    /// The description has no node.
    NoNodes,
    /// A node's address is outside 1..=63.
    NodeAddress {
        /// The address.
        address: u8,
    },
    /// Two nodes have the same address.
    DuplicateNode {
        /// The address.
        address: u8,
    },
    /// A node drives no actuator.
    NodeWithoutActuators {
        /// The node's address.
        address: u8,
    },
    /// A node's channels are not numbered 0..n-1.
    ChannelGap {
        /// The node's address.
        address: u8,
        /// Its channels, sorted.
        channels: Vec<u8>,
    },
    /// Two rings have the same name.
    DuplicateRing {
        /// The name.
        ring: String,
    },
    /// A ring field is out of range.
    RingValue {
        /// The ring.
        ring: String,
        /// The field.
        field: &'static str,
        /// Why.
        problem: String,
    },
    /// A ring's mirror is missing, unknown or not mirrored.
    RingMirror {
        /// The ring.
        ring: String,
        /// Why.
        problem: String,
    },
    /// An actuator id is empty, has characters other than letters, digits, `-`, `_`, `.`,
    /// or is reserved (`node<N>`).
    BadId {
        /// The id.
        id: String,
    },
    /// Two actuators have the same id.
    DuplicateActuator {
        /// The id.
        id: String,
    },
    /// An actuator names a node the description lacks.
    UnknownNode {
        /// The actuator.
        actuator: String,
        /// The address it names.
        node: u8,
    },
    /// An actuator names a ring the description lacks.
    UnknownRing {
        /// The actuator.
        actuator: String,
        /// The ring it names.
        ring: String,
    },
    /// An actuator's channel is outside 0..=7.
    ChannelOutOfRange {
        /// The actuator.
        actuator: String,
        /// The channel.
        channel: u8,
    },
    /// Two actuators use the same channel of a node.
    ChannelTaken {
        /// The node's address.
        node: u8,
        /// The channel.
        channel: u8,
        /// The first actuator on it.
        first: String,
        /// The second one.
        second: String,
    },
    /// An actuator field is out of range (a negative stroke, a zero speed, ...).
    Value {
        /// The actuator.
        actuator: String,
        /// The field.
        field: &'static str,
        /// The value.
        value: f64,
        /// The allowed range.
        expected: &'static str,
    },
    /// An actuator's `mirror` names no actuator.
    UnknownMirror {
        /// The actuator.
        actuator: String,
        /// The id it names.
        mirror: String,
    },
    /// An actuator is named as the mirror of two different actuators, or names one while
    /// another names it.
    MirrorConflict {
        /// The actuator.
        actuator: String,
        /// Its two claimed partners.
        partners: [String; 2],
    },
    /// A mirror pair is not symmetric.
    Asymmetric {
        /// The actuator naming the partner.
        actuator: String,
        /// The partner.
        partner: String,
        /// What differs.
        problem: String,
    },
    /// An actuator off the centre line has no mirror partner.
    Unpaired {
        /// The actuator.
        actuator: String,
    },
    /// A lift's `rings` are empty, unknown or repeated, or its mirror does not mirror it.
    Lift {
        /// The lift.
        lift: String,
        /// Why.
        problem: String,
    },
    /// Lifts can bring two rings closer than [`MIN_RING_SPACING_MM`] (or past each other).
    RingsMeet {
        /// The upper ring (with every lift retracted).
        upper: String,
        /// The lower ring.
        lower: String,
        /// Their spacing with the lower ring's own lifts extended and the upper's retracted.
        closest_mm: f64,
    },
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoNodes => f.write_str("no `[[node]]`: a form needs at least one node"),
            Self::NodeAddress { address } => {
                write!(f, "node {address}: `address` must be in 1..=63")
            }
            Self::DuplicateNode { address } => write!(f, "node {address}: address used twice"),
            Self::NodeWithoutActuators { address } => {
                write!(f, "node {address}: drives no actuator")
            }
            Self::ChannelGap { address, channels } => write!(
                f,
                "node {address}: channels {channels:?} must be numbered 0..{} without gaps",
                channels.len()
            ),
            Self::DuplicateRing { ring } => write!(f, "ring `{ring}`: name used twice"),
            Self::RingValue { ring, field, problem } => {
                write!(f, "ring `{ring}`: `{field}` {problem}")
            }
            Self::RingMirror { ring, problem } => write!(f, "ring `{ring}`: {problem}"),
            Self::BadId { id } => write!(
                f,
                "actuator id {id:?}: use letters, digits, `-`, `_` and `.` (and not `node<N>`, \
                 which names nodes in fault specs)"
            ),
            Self::DuplicateActuator { id } => write!(f, "actuator `{id}`: id used twice"),
            Self::UnknownNode { actuator, node } => {
                write!(f, "actuator `{actuator}`: `node` {node} is not a `[[node]]` address")
            }
            Self::UnknownRing { actuator, ring } => {
                write!(f, "actuator `{actuator}`: `ring` \"{ring}\" is not a `[[ring]]` name")
            }
            Self::ChannelOutOfRange { actuator, channel } => write!(
                f,
                "actuator `{actuator}`: `channel` {channel} must be in 0..={}",
                MAX_ACTUATORS - 1
            ),
            Self::ChannelTaken { node, channel, first, second } => {
                write!(f, "node {node}: channel {channel} is used by both `{first}` and `{second}`")
            }
            Self::Value { actuator, field, value, expected } => {
                write!(
                    f,
                    "actuator `{actuator}`: `{field}` = {} must be {expected}",
                    number(*value)
                )
            }
            Self::UnknownMirror { actuator, mirror } => {
                write!(f, "actuator `{actuator}`: `mirror` \"{mirror}\" is not an actuator id")
            }
            Self::MirrorConflict { actuator, partners: [a, b] } => {
                write!(f, "actuator `{actuator}`: paired as the mirror of both `{a}` and `{b}`")
            }
            Self::Asymmetric { actuator, partner, problem } => {
                write!(f, "actuators `{actuator}` and `{partner}` are not a mirror pair: {problem}")
            }
            Self::Unpaired { actuator } => write!(
                f,
                "actuator `{actuator}`: off the centre line and without a mirror partner \
                 (name it with `mirror`)"
            ),
            Self::Lift { lift, problem } => write!(f, "lift `{lift}`: {problem}"),
            Self::RingsMeet { upper, lower, closest_mm } => write!(
                f,
                "rings `{upper}` and `{lower}`: the lifts can bring them to {} mm apart; keep \
                 at least {MIN_RING_SPACING_MM} mm (shorten a stroke or raise `{upper}`)",
                number(*closest_mm)
            ),
        }
    }
}

impl TryFrom<FormSpec> for FormDescription {
    type Error = Vec<Problem>;

    /// Validates `spec` (see the crate's rules); `Err` lists every problem found.
    fn try_from(spec: FormSpec) -> Result<Self, Vec<Problem>> {
        spec.problems().map(|()| FormDescription(spec))
    }
}

impl FormSpec {
    /// Checks the description; `Err` lists every problem found.
    fn problems(&self) -> Result<(), Vec<Problem>> {
        let mut problems = Vec::new();
        self.check_nodes(&mut problems);
        self.check_rings(&mut problems);
        self.check_actuators(&mut problems);
        self.check_channels(&mut problems);
        self.check_mirrors(&mut problems);
        self.check_lifts(&mut problems);
        self.check_ring_spacing(&mut problems);
        if problems.is_empty() { Ok(()) } else { Err(problems) }
    }

    fn check_nodes(&self, problems: &mut Vec<Problem>) {
        if self.nodes.is_empty() {
            problems.push(Problem::NoNodes);
        }
        let mut seen = HashSet::new();
        for node in &self.nodes {
            let address = node.address;
            if NodeId::new(address).is_none() {
                problems.push(Problem::NodeAddress { address });
            } else if !seen.insert(address) {
                problems.push(Problem::DuplicateNode { address });
            } else if !self.axes().any(|a| a.node == address) {
                problems.push(Problem::NodeWithoutActuators { address });
            }
        }
    }

    fn check_rings(&self, problems: &mut Vec<Problem>) {
        let mut seen = HashSet::new();
        for ring in &self.rings {
            let name = ring.name.clone();
            if !seen.insert(ring.name.as_str()) {
                problems.push(Problem::DuplicateRing { ring: name.clone() });
            }
            if !(ring.height_mm.is_finite() && ring.height_mm > 0.0) {
                let problem =
                    format!("= {} must be a height above the floor (> 0)", number(ring.height_mm));
                problems.push(Problem::RingValue {
                    ring: name.clone(),
                    field: "height_mm",
                    problem,
                });
            }
            if !ring.center_mm.iter().all(|c| c.is_finite()) {
                let problem = format!("= {} must be finite", point(ring.center_mm));
                problems.push(Problem::RingValue {
                    ring: name.clone(),
                    field: "center_mm",
                    problem,
                });
            }
            if let Some(problem) = part_problem(ring) {
                problems.push(Problem::RingValue { ring: name.clone(), field: "part", problem });
            }
            if let Some(problem) = self.anchor_problem(ring) {
                problems.push(Problem::RingValue { ring: name.clone(), field: "anchor", problem });
            }
            if let Some(problem) = self.ring_mirror_problem(ring) {
                problems.push(Problem::RingMirror { ring: name, problem });
            }
        }
    }

    /// A torso level on a leg ring or a leg's on a torso ring, or one another ring of the same
    /// part (earlier in the file) already has.
    fn anchor_problem(&self, ring: &RingSpec) -> Option<String> {
        let anchor = ring.anchor?;
        if anchor.is_leg() != (ring.part != BodyPart::Torso) {
            let (level, other) = if anchor.is_leg() { ("leg", "torso") } else { ("torso", "leg") };
            return Some(format!(
                "\"{}\" is a {level} level; a {other} ring has none",
                anchor.name()
            ));
        }
        let first = self.rings.iter().find(|r| r.anchor == Some(anchor) && r.part == ring.part)?;
        (first.name != ring.name).then(|| {
            format!("\"{}\" is already the anchor of ring `{}`", anchor.name(), first.name)
        })
    }

    fn ring_mirror_problem(&self, ring: &RingSpec) -> Option<String> {
        let centred = ring.center_mm[0] == 0.0;
        let named_by = self.rings.iter().find(|r| r.mirror.as_deref() == Some(&ring.name));
        let mirror = match (&ring.mirror, named_by) {
            (Some(name), _) => match self.ring(name) {
                Some(mirror) => mirror,
                None => return Some(format!("`mirror` \"{name}\" is not a ring")),
            },
            (None, Some(mirror)) => mirror,
            (None, None) if centred => return None,
            (None, None) => {
                return Some("is off the centre line (x ≠ 0): name its mirror ring".into());
            }
        };
        if centred {
            return Some("is centred (x = 0), so it is its own mirror: drop `mirror`".into());
        }
        if let (Some(named), Some(by)) = (&ring.mirror, named_by)
            && by.name != *named
        {
            return Some(format!("mirrors `{named}` but `{}` names it as mirror", by.name));
        }
        let expected = [-ring.center_mm[0], ring.center_mm[1]];
        if !close(mirror.center_mm[0], expected[0])
            || !close(mirror.center_mm[1], expected[1])
            || !close(mirror.height_mm, ring.height_mm)
        {
            return Some(format!(
                "its mirror `{}` must be at the same height with centre {}",
                mirror.name,
                point(expected)
            ));
        }
        None
    }

    /// Every actuator's and lift's bus fields ([`Self::check_axis`]), and the panels' geometry.
    fn check_actuators(&self, problems: &mut Vec<Problem>) {
        let mut seen = HashSet::new();
        for axis in self.axes() {
            self.check_axis(axis, &mut seen, problems);
        }
        for a in &self.actuators {
            if self.ring(&a.ring).is_none() {
                problems
                    .push(Problem::UnknownRing { actuator: a.id.clone(), ring: a.ring.clone() });
            }
            let checks: [(&'static str, f64, bool, &'static str); 3] = [
                ("angle_deg", a.angle_deg, (0.0..360.0).contains(&a.angle_deg), "in [0, 360)"),
                ("base_radius_mm", a.base_radius_mm, a.base_radius_mm > 0.0, "> 0"),
                ("panel_width_mm", a.panel_width_mm, a.panel_width_mm > 0.0, "> 0"),
            ];
            push_values(&a.id, checks, problems);
        }
    }

    /// An actuator's or lift's id, node, channel, stroke and limits.
    fn check_axis<'a>(
        &self,
        a: Axis<'a>,
        seen: &mut HashSet<&'a str>,
        problems: &mut Vec<Problem>,
    ) {
        if !is_valid_id(a.id) {
            problems.push(Problem::BadId { id: a.id.to_string() });
        } else if !seen.insert(a.id) {
            problems.push(Problem::DuplicateActuator { id: a.id.to_string() });
        }
        if !self.nodes.iter().any(|n| n.address == a.node) {
            problems.push(Problem::UnknownNode { actuator: a.id.to_string(), node: a.node });
        }
        if usize::from(a.channel) >= MAX_ACTUATORS {
            problems.push(Problem::ChannelOutOfRange {
                actuator: a.id.to_string(),
                channel: a.channel,
            });
        }
        let max_stroke = Position::MAX.mm();
        let max_force = Force::MAX.n();
        let checks: [(&'static str, f64, bool, &'static str); 4] = [
            (
                "stroke_mm",
                a.stroke_mm,
                a.stroke_mm >= MIN_STROKE_MM && a.stroke_mm <= max_stroke,
                "in 0.01..=655.34",
            ),
            (
                "max_speed_mm_s",
                a.max_speed_mm_s,
                a.max_speed_mm_s >= MIN_SPEED_MM_S && a.max_speed_mm_s <= MAX_SPEED_MM_S,
                "in 0.01..=655.35",
            ),
            (
                "max_accel_mm_s2",
                a.max_accel_mm_s2,
                a.max_accel_mm_s2 >= MIN_ACCEL_MM_S2 && a.max_accel_mm_s2 <= MAX_ACCEL_MM_S2,
                "in 0.1..=6553.5",
            ),
            (
                "force_limit_n",
                a.force_limit_n.unwrap_or(max_force),
                a.force_limit_n.is_none_or(|f| f >= MIN_FORCE_N && f <= max_force),
                "in 0.01..=327.67",
            ),
        ];
        push_values(a.id, checks, problems);
    }

    fn check_channels(&self, problems: &mut Vec<Problem>) {
        let mut by_node: BTreeMap<u8, BTreeMap<u8, &str>> = BTreeMap::new();
        for a in self.axes().filter(|a| usize::from(a.channel) < MAX_ACTUATORS) {
            let channels = by_node.entry(a.node).or_default();
            if let Some(first) = channels.get(&a.channel) {
                problems.push(Problem::ChannelTaken {
                    node: a.node,
                    channel: a.channel,
                    first: first.to_string(),
                    second: a.id.to_string(),
                });
            } else {
                channels.insert(a.channel, a.id);
            }
        }
        for (address, channels) in by_node {
            let channels: Vec<u8> = channels.into_keys().collect();
            if channels.iter().enumerate().any(|(i, &c)| usize::from(c) != i) {
                problems.push(Problem::ChannelGap { address, channels });
            }
        }
    }

    fn check_mirrors(&self, problems: &mut Vec<Problem>) {
        let by_id: HashMap<&str, &ActuatorSpec> =
            self.actuators.iter().map(|a| (a.id.as_str(), a)).collect();
        let mut partner: HashMap<&str, &str> = HashMap::new();
        for a in &self.actuators {
            let Some(name) = a.mirror.as_deref() else { continue };
            let Some(b) = by_id.get(name) else {
                problems.push(Problem::UnknownMirror {
                    actuator: a.id.clone(),
                    mirror: name.to_string(),
                });
                continue;
            };
            for (x, y) in [(a.id.as_str(), name), (name, a.id.as_str())] {
                match partner.get(x) {
                    Some(&other) if other != y => problems.push(Problem::MirrorConflict {
                        actuator: x.to_string(),
                        partners: [other.to_string(), y.to_string()],
                    }),
                    _ => {
                        partner.insert(x, y);
                    }
                }
            }
            if let Some(problem) = self.asymmetry(a, b) {
                problems.push(Problem::Asymmetric {
                    actuator: a.id.clone(),
                    partner: b.id.clone(),
                    problem,
                });
            }
        }
        for a in &self.actuators {
            if !partner.contains_key(a.id.as_str()) && !self.on_centre_line(a) {
                problems.push(Problem::Unpaired { actuator: a.id.clone() });
            }
        }
    }

    /// Each lift's rings (known, not repeated) and mirror rule: a lift raising rings on one
    /// side names a partner raising the mirror rings with the same stroke and limits; one
    /// without a partner raises both sides alike.
    fn check_lifts(&self, problems: &mut Vec<Problem>) {
        for lift in &self.lifts {
            let mut problem = |problem: String| {
                problems.push(Problem::Lift { lift: lift.id.clone(), problem });
            };
            if lift.rings.is_empty() {
                problem("`rings` is empty: name the rings it raises".into());
            }
            for (k, name) in lift.rings.iter().enumerate() {
                if self.ring(name).is_none() {
                    problem(format!("`rings` names \"{name}\", not a `[[ring]]` name"));
                } else if lift.rings[..k].contains(name) {
                    problem(format!("`rings` names `{name}` twice"));
                }
            }
            let named_by: Vec<&str> = (self.lifts.iter())
                .filter(|m| m.mirror.as_deref() == Some(lift.id.as_str()))
                .map(|m| m.id.as_str())
                .collect();
            let partners: BTreeSet<&str> =
                lift.mirror.iter().map(String::as_str).chain(named_by.iter().copied()).collect();
            if let [a, b, ..] = partners.iter().collect::<Vec<_>>()[..] {
                problem(format!("paired as the mirror of both `{a}` and `{b}`"));
                continue;
            }
            let partner = match (&lift.mirror, named_by.first()) {
                (Some(name), _) => match self.lift(name) {
                    Some(partner) => partner,
                    None => {
                        problem(format!("`mirror` \"{name}\" is not a lift"));
                        continue;
                    }
                },
                (None, Some(_)) => continue, // checked from the side naming the pair
                (None, None) => lift,
            };
            // The partner raises exactly the mirror images of this lift's rings.
            let mirrored: BTreeSet<&str> = lift.rings.iter().map(|r| self.mirror_ring(r)).collect();
            let theirs: BTreeSet<&str> = partner.rings.iter().map(String::as_str).collect();
            let by =
                if partner.id == lift.id { "it".to_string() } else { format!("`{}`", partner.id) };
            if let Some(ring) = lift.rings.iter().find(|r| !theirs.contains(self.mirror_ring(r))) {
                problem(format!(
                    "raises `{ring}` but {by} does not raise its mirror `{}`: raise both sides \
                     alike or pair the lift with one raising the other side (`mirror`)",
                    self.mirror_ring(ring)
                ));
            } else if let Some(extra) = theirs.difference(&mirrored).next() {
                problem(format!(
                    "{by} also raises `{extra}`, whose mirror this lift does not raise: a mirror \
                     pair raises mirror images"
                ));
            }
            let limits = [
                ("stroke_mm", lift.stroke_mm, partner.stroke_mm),
                ("max_speed_mm_s", lift.max_speed_mm_s, partner.max_speed_mm_s),
                ("max_accel_mm_s2", lift.max_accel_mm_s2, partner.max_accel_mm_s2),
                (
                    "force_limit_n",
                    lift.force_limit_n.unwrap_or(0.0),
                    partner.force_limit_n.unwrap_or(0.0),
                ),
            ];
            if let Some((field, x, y)) = limits.iter().find(|(_, x, y)| !close(*x, *y)) {
                problem(format!(
                    "its mirror `{}` has another `{field}` ({} and {})",
                    partner.id,
                    number(*x),
                    number(*y)
                ));
            }
        }
    }

    /// Every two rings at different heights stay [`MIN_RING_SPACING_MM`] apart however the
    /// lifts stand: the closest they come is with the lower ring's own lifts (those not also
    /// carrying the upper ring) at full stroke.
    fn check_ring_spacing(&self, problems: &mut Vec<Problem>) {
        for upper in &self.rings {
            for lower in self.rings.iter().filter(|r| r.height_mm < upper.height_mm) {
                let raised: f64 = self
                    .lifts_of(&lower.name)
                    .filter(|l| !l.rings.contains(&upper.name))
                    .map(|l| l.stroke_mm)
                    .sum();
                let closest_mm = upper.height_mm - lower.height_mm - raised;
                if raised > 0.0 && closest_mm < MIN_RING_SPACING_MM {
                    problems.push(Problem::RingsMeet {
                        upper: upper.name.clone(),
                        lower: lower.name.clone(),
                        closest_mm,
                    });
                }
            }
        }
    }

    /// The ring mirroring `name`: the one it names, the one naming it, or itself (centred).
    fn mirror_ring<'a>(&'a self, name: &'a str) -> &'a str {
        let Some(ring) = self.ring(name) else { return name };
        match &ring.mirror {
            Some(mirror) => mirror,
            None => self
                .rings
                .iter()
                .find(|r| r.mirror.as_deref() == Some(name))
                .map_or(name, |r| r.name.as_str()),
        }
    }

    /// Whether an actuator is its own mirror: at 0° or 180° on a ring centred on x = 0.
    fn on_centre_line(&self, a: &ActuatorSpec) -> bool {
        let centred = self.ring(&a.ring).is_some_and(|r| r.center_mm[0] == 0.0);
        centred && (close(a.angle_deg, 0.0) || close(a.angle_deg, 180.0))
    }

    /// What makes `b` not the mirror image of `a`, if anything.
    fn asymmetry(&self, a: &ActuatorSpec, b: &ActuatorSpec) -> Option<String> {
        if a.id == b.id {
            return (!self.on_centre_line(a))
                .then(|| "only centre-line actuators (0° or 180°) mirror themselves".into());
        }
        self.ring(&a.ring)?;
        let mirror_ring = self.mirror_ring(&a.ring);
        if b.ring != mirror_ring {
            return Some(format!("`{}` is on ring `{}`, expected `{mirror_ring}`", b.id, b.ring));
        }
        let mirrored = (360.0 - a.angle_deg).rem_euclid(360.0);
        let turn = (b.angle_deg - mirrored).rem_euclid(360.0);
        if turn.min(360.0 - turn) > MIRROR_TOLERANCE {
            return Some(format!(
                "angles {}° and {}° are not mirrored (expected {}°)",
                number(a.angle_deg),
                number(b.angle_deg),
                number(mirrored)
            ));
        }
        let fields = [
            ("stroke_mm", a.stroke_mm, b.stroke_mm),
            ("max_speed_mm_s", a.max_speed_mm_s, b.max_speed_mm_s),
            ("max_accel_mm_s2", a.max_accel_mm_s2, b.max_accel_mm_s2),
            (
                "force_limit_n",
                Axis::from(a).force_limit_n.unwrap_or(0.0),
                Axis::from(b).force_limit_n.unwrap_or(0.0),
            ),
            ("base_radius_mm", a.base_radius_mm, b.base_radius_mm),
            ("panel_width_mm", a.panel_width_mm, b.panel_width_mm),
        ];
        fields
            .iter()
            .find(|(_, x, y)| !close(*x, *y))
            .map(|(field, x, y)| format!("`{field}` differs ({} and {})", number(*x), number(*y)))
    }
}

/// A [`Problem::Value`] for each `(field, value, ok, expected)` not ok or not finite.
fn push_values<const N: usize>(
    id: &str,
    checks: [(&'static str, f64, bool, &'static str); N],
    problems: &mut Vec<Problem>,
) {
    for (field, value, ok, expected) in checks {
        // NaN fails every comparison, infinities fail the ranges.
        if !(ok && value.is_finite()) {
            problems.push(Problem::Value { actuator: id.to_string(), field, value, expected });
        }
    }
}

/// A ring's part against its centre: a torso ring on the body axis (x = 0), a leg ring on its
/// own side.
fn part_problem(ring: &RingSpec) -> Option<String> {
    let x = ring.center_mm[0];
    let fits = match ring.part {
        BodyPart::Torso => x == 0.0,
        BodyPart::LeftLeg => x > 0.0,
        BodyPart::RightLeg => x < 0.0,
    };
    (!fits && x.is_finite()).then(|| match ring.part {
        BodyPart::Torso => format!(
            "the ring is off the body axis (x = {} mm): a leg ring says \
             `part = \"left-leg\"` (x > 0) or `\"right-leg\"` (x < 0)",
            number(x)
        ),
        leg => {
            format!("\"{}\" needs its centre on that side (x = {} mm)", leg.name(), number(x))
        }
    })
}

/// A ring centre as problems show it: `[x, y]`, each number short.
fn point([x, y]: [f64; 2]) -> String {
    format!("[{}, {}]", number(x), number(y))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= MIRROR_TOLERANCE
}

/// Letters, digits, `-`, `_`, `.`; not empty; not `node<digits>` (fault specs' node names).
fn is_valid_id(id: &str) -> bool {
    let charset = id.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c));
    let node_name = id.strip_prefix("node").is_some_and(|n| n.chars().all(|c| c.is_ascii_digit()));
    !id.is_empty() && charset && !node_name
}
