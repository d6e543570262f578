//! The description's types: what a file says ([`FormSpec`], unchecked) and the validated
//! [`FormDescription`]; look-ups and geometry.

use std::collections::BTreeMap;
use std::ops::Deref;

use firmware_protocol::{Accel, Actuator, Force, NodeId, Position, Speed};
use serde::{Deserialize, Serialize};

/// A robotic dress form that passed validation: its nodes, the rings its actuators sit on,
/// and the actuators. The only ways to get one are the loaders and `FormDescription::try_from`
/// a [`FormSpec`], which validate; it reads as its [`FormSpec`] (through `Deref`) and cannot
/// be changed.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct FormDescription(pub(crate) FormSpec);

/// What a form description file says, not yet validated: deserialise into this, then
/// [`FormDescription::try_from`] it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormSpec {
    /// A name for people and logs.
    pub name: String,
    /// The controller boards on the bus (`[[node]]`).
    #[serde(rename = "node", default)]
    pub nodes: Vec<NodeSpec>,
    /// Horizontal rows of actuators (`[[ring]]`).
    #[serde(rename = "ring", default)]
    pub rings: Vec<RingSpec>,
    /// The actuators that push panels out of the rings (`[[actuator]]`).
    #[serde(rename = "actuator", default)]
    pub actuators: Vec<ActuatorSpec>,
    /// The height axes that raise rings (`[[lift]]`); a form may have none.
    #[serde(rename = "lift", default, skip_serializing_if = "Vec::is_empty")]
    pub lifts: Vec<LiftSpec>,
}

/// One node (controller board).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    /// Its bus address, 1..=63.
    pub address: u8,
    /// What it drives, for people.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// A horizontal ring of actuators at one height.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RingSpec {
    /// Its name (`neck`, `chest`, `thigh-l`, ...).
    pub name: String,
    /// Height above the floor with every lift retracted, mm ([`FormSpec::ring_height`]).
    pub height_mm: f64,
    /// The ring's axis in the X-Y plane, mm: `[0, 0]` (the body axis) unless off-centre,
    /// like a thigh.
    #[serde(default, skip_serializing_if = "is_origin")]
    pub center_mm: [f64; 2],
    /// For an off-centre ring: the ring that mirrors it across x = 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror: Option<String>,
    /// The part of the body it shapes: the torso (default) or a leg.
    #[serde(default, skip_serializing_if = "BodyPart::is_torso")]
    pub part: BodyPart,
    /// The mannequin level the ring is set to, if any (the other rings are placed between
    /// the anchored ones).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<Anchor>,
}

/// The part of the body a ring shapes. A torso ring is centred on the body axis (x = 0); a
/// leg ring sits on its leg's side.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BodyPart {
    /// The torso.
    #[default]
    Torso,
    /// The subject's left leg (+X).
    LeftLeg,
    /// The subject's right leg (-X).
    RightLeg,
}

impl BodyPart {
    fn is_torso(&self) -> bool {
        *self == BodyPart::Torso
    }

    /// Its name in a description file.
    pub fn name(self) -> &'static str {
        match self {
            BodyPart::Torso => "torso",
            BodyPart::LeftLeg => "left-leg",
            BodyPart::RightLeg => "right-leg",
        }
    }
}

/// A body level a ring can be set to (each at most once per form; the host defines where each
/// lies on a mannequin). The torso's levels, top to bottom, then the thigh's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Anchor {
    /// The neck landmark.
    Neck,
    /// The shoulders: between the neck and the armpits.
    Shoulders,
    /// The chest level.
    Chest,
    /// The fold under the bust.
    UnderBust,
    /// The waist level.
    Waist,
    /// The abdomen: midway between the waist and the hip.
    Abdomen,
    /// The hip level.
    Hip,
    /// The thigh girth's level, just under the crotch (a leg level: both thigh rings).
    Thigh,
}

impl Anchor {
    /// Its name in a description file.
    pub fn name(self) -> &'static str {
        match self {
            Anchor::Neck => "neck",
            Anchor::Shoulders => "shoulders",
            Anchor::Chest => "chest",
            Anchor::UnderBust => "under-bust",
            Anchor::Waist => "waist",
            Anchor::Abdomen => "abdomen",
            Anchor::Hip => "hip",
            Anchor::Thigh => "thigh",
        }
    }

    /// Whether it is a leg's level (set on both legs' rings) rather than the torso's.
    pub fn is_leg(self) -> bool {
        self == Anchor::Thigh
    }
}

fn is_origin(center: &[f64; 2]) -> bool {
    *center == [0.0, 0.0]
}

/// One linear actuator pushing one panel of the form.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// Stable id (`chest-l2`): set-point files and fault specs name actuators by it.
    pub id: String,
    /// Address of the node driving it.
    pub node: u8,
    /// Its index on that node, 0..=7.
    pub channel: u8,
    /// The ring it sits on.
    pub ring: String,
    /// Angle around the ring's axis, degrees in [0, 360): 0 = front (-Y), 90 = the subject's
    /// left (+X), counter-clockwise seen from above.
    pub angle_deg: f64,
    /// Distance of the panel from the ring's axis when fully retracted, mm.
    pub base_radius_mm: f64,
    /// Width of the panel (its chord, tangential to the ring), mm.
    pub panel_width_mm: f64,
    /// Travel from fully retracted (0) outwards, mm.
    pub stroke_mm: f64,
    /// Speed limit, mm/s.
    pub max_speed_mm_s: f64,
    /// Acceleration (and deceleration) limit, mm/s².
    pub max_accel_mm_s2: f64,
    /// The force that stalls it (its node latches `OVER_FORCE`), N; default
    /// [`DEFAULT_FORCE_LIMIT_N`]. Nodes of protocol 1.1 measure force.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_limit_n: Option<f64>,
    /// Id of its mirror partner (a left actuator names its right partner).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror: Option<String>,
}

/// A height axis: a linear actuator that raises the rings it carries by its extension. A
/// ring's height is its `height_mm` plus the extensions of every lift carrying it, so lifts
/// stack: a column under the whole form, a torso-length axis above the waist, ... On the bus a
/// lift is one more actuator (an [`Axis`]): the same messages, limits and safety rules.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiftSpec {
    /// Stable id (`torso-length`), unique among actuators and lifts.
    pub id: String,
    /// Address of the node driving it.
    pub node: u8,
    /// Its index on that node, 0..=7 (numbered with the node's actuators).
    pub channel: u8,
    /// The rings it raises.
    pub rings: Vec<String>,
    /// Travel upwards from fully retracted (0), mm.
    pub stroke_mm: f64,
    /// Speed limit, mm/s.
    pub max_speed_mm_s: f64,
    /// Acceleration (and deceleration) limit, mm/s².
    pub max_accel_mm_s2: f64,
    /// The force that stalls it, N; without one the host leaves the node's own limit (its
    /// rated force): a lift carries its rings' weight, which no panel's limit fits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_limit_n: Option<f64>,
    /// Id of its mirror partner, for a lift raising rings on one side only (a left thigh's
    /// names the right thigh's); a lift raising both sides alike is its own mirror.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror: Option<String>,
}

/// What the bus knows of an actuator, a panel's or a lift's alike: where it is, how far and
/// how fast it may move. The controller and the simulated nodes see a form as these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis<'a> {
    /// Its id.
    pub id: &'a str,
    /// Address of the node driving it.
    pub node: u8,
    /// Its index on that node.
    pub channel: u8,
    /// Travel from fully retracted (0), mm.
    pub stroke_mm: f64,
    /// Speed limit, mm/s.
    pub max_speed_mm_s: f64,
    /// Acceleration (and deceleration) limit, mm/s².
    pub max_accel_mm_s2: f64,
    /// The force that stalls it, N: the description's, a panel's default
    /// [`DEFAULT_FORCE_LIMIT_N`], or none for a lift without one (the node's rated force).
    pub force_limit_n: Option<f64>,
}

/// The force limit of a panel's actuator whose description gives none, N. A safety margin
/// on both sides: twice the 25 N a panel of the reference form carries under a firm
/// compression garment (4 kPa over an 80 × 80 mm panel), and under half of the 110 N that
/// ISO/TS 15066 (Table A.2) allows as a quasi-static contact force on the abdomen, the
/// lowest of the torso's limits, so a panel pushing on a person stops well before it hurts.
pub const DEFAULT_FORCE_LIMIT_N: f64 = 50.0;

impl<'a> From<&'a ActuatorSpec> for Axis<'a> {
    fn from(a: &'a ActuatorSpec) -> Self {
        Axis {
            id: &a.id,
            node: a.node,
            channel: a.channel,
            stroke_mm: a.stroke_mm,
            max_speed_mm_s: a.max_speed_mm_s,
            max_accel_mm_s2: a.max_accel_mm_s2,
            force_limit_n: Some(a.force_limit_n.unwrap_or(DEFAULT_FORCE_LIMIT_N)),
        }
    }
}

impl<'a> From<&'a LiftSpec> for Axis<'a> {
    fn from(l: &'a LiftSpec) -> Self {
        Axis {
            id: &l.id,
            node: l.node,
            channel: l.channel,
            stroke_mm: l.stroke_mm,
            max_speed_mm_s: l.max_speed_mm_s,
            max_accel_mm_s2: l.max_accel_mm_s2,
            force_limit_n: l.force_limit_n,
        }
    }
}

impl Axis<'_> {
    /// The stroke as a protocol position (0.01 mm).
    pub fn stroke(&self) -> Position {
        Position::from_mm(self.stroke_mm as f32).unwrap_or(Position::ZERO)
    }

    /// The speed limit in the protocol's unit (validation keeps it in range).
    pub fn max_speed(&self) -> Speed {
        Speed::from_mm_s(self.max_speed_mm_s).unwrap_or_default()
    }

    /// The acceleration limit in the protocol's unit (validation keeps it in range).
    pub fn max_accel(&self) -> Accel {
        Accel::from_mm_s2(self.max_accel_mm_s2).unwrap_or_default()
    }

    /// The force limit in the protocol's unit, if the description sets one (validation keeps
    /// it in range).
    pub fn force_limit(&self) -> Option<Force> {
        self.force_limit_n.and_then(Force::from_n)
    }

    /// Its node's id, if the address is valid.
    pub fn node_id(&self) -> Option<NodeId> {
        NodeId::new(self.node)
    }

    /// Its index on the node, if valid.
    pub fn actuator(&self) -> Option<Actuator> {
        Actuator::new(self.channel)
    }
}

impl ActuatorSpec {
    /// The unit vector, in the X-Y plane, along which its panel moves out.
    pub fn direction(&self) -> [f64; 2] {
        let angle = self.angle_deg.to_radians();
        [angle.sin(), -angle.cos()]
    }

    /// The two ends of its panel (a plate of `panel_width_mm`, tangential) in the X-Y plane
    /// with the ring's axis at `centre` and the actuator at `extension_mm`: clockwise end
    /// first, seen from above. The skin over a ring is the convex hull of its panels' ends.
    pub fn panel_ends(&self, centre: [f64; 2], extension_mm: f64) -> [[f64; 2]; 2] {
        let [dx, dy] = self.direction();
        let (r, half) = (self.base_radius_mm + extension_mm, 0.5 * self.panel_width_mm);
        let middle = [centre[0] + r * dx, centre[1] + r * dy];
        [
            [middle[0] + half * dy, middle[1] - half * dx],
            [middle[0] - half * dy, middle[1] + half * dx],
        ]
    }
}

impl Deref for FormDescription {
    type Target = FormSpec;

    fn deref(&self) -> &FormSpec {
        &self.0
    }
}

impl FormDescription {
    /// The unchecked description, to edit (a copy of a form with one change) and validate
    /// again.
    pub fn into_spec(self) -> FormSpec {
        self.0
    }
}

impl FormSpec {
    /// The nodes' ids, in file order (valid addresses only).
    pub fn node_ids(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.nodes.iter().filter_map(|n| NodeId::new(n.address))
    }

    /// Every actuator on the bus: the panels' (`[[actuator]]`), then the lifts.
    pub fn axes(&self) -> impl Iterator<Item = Axis<'_>> {
        self.actuators.iter().map(Axis::from).chain(self.lifts.iter().map(Axis::from))
    }

    /// The actuator or lift with this id, as the bus knows it.
    pub fn axis(&self, id: &str) -> Option<Axis<'_>> {
        self.axes().find(|a| a.id == id)
    }

    /// The actuators and lifts of a node, by channel.
    pub fn actuators_of(&self, node: NodeId) -> Vec<Axis<'_>> {
        let mut axes: Vec<_> = self.axes().filter(|a| a.node == node.get()).collect();
        axes.sort_by_key(|a| a.channel);
        axes
    }

    /// The panel actuator with this id.
    pub fn actuator(&self, id: &str) -> Option<&ActuatorSpec> {
        self.actuators.iter().find(|a| a.id == id)
    }

    /// The lift with this id.
    pub fn lift(&self, id: &str) -> Option<&LiftSpec> {
        self.lifts.iter().find(|l| l.id == id)
    }

    /// A ring's height above the floor with the lifts at `positions_mm` (id → extension;
    /// missing lifts count as retracted): its `height_mm` plus every carrying lift's extension.
    pub fn ring_height(&self, ring: &RingSpec, positions_mm: &BTreeMap<String, f64>) -> f64 {
        let lifted = self.lifts_of(&ring.name).map(|l| positions_mm.get(&l.id).copied());
        ring.height_mm + lifted.map(|e| e.unwrap_or(0.0)).sum::<f64>()
    }

    /// The lifts that carry `ring`.
    pub fn lifts_of<'a>(&'a self, ring: &'a str) -> impl Iterator<Item = &'a LiftSpec> + 'a {
        self.lifts.iter().filter(move |l| l.rings.iter().any(|r| r == ring))
    }

    /// The ring with this name.
    pub fn ring(&self, name: &str) -> Option<&RingSpec> {
        self.rings.iter().find(|r| r.name == name)
    }

    /// Where an actuator or lift is on the bus: its node and index.
    pub fn locate(&self, id: &str) -> Option<(NodeId, Actuator)> {
        let axis = self.axis(id)?;
        Some((axis.node_id()?, axis.actuator()?))
    }

    /// The actuator or lift at this node and index.
    pub fn actuator_at(&self, node: NodeId, actuator: Actuator) -> Option<Axis<'_>> {
        self.axes().find(|a| a.node == node.get() && a.actuator() == Some(actuator))
    }

    /// An actuator's mirror partner: the one it names, the one naming it, or itself for a
    /// centre-line actuator.
    pub fn mirror_of(&self, id: &str) -> Option<&ActuatorSpec> {
        let actuator = self.actuator(id)?;
        if let Some(partner) = actuator.mirror.as_deref() {
            return self.actuator(partner);
        }
        Some(self.actuators.iter().find(|a| a.mirror.as_deref() == Some(id)).unwrap_or(actuator))
    }

    /// Where an actuator's panel centre is, in the canonical frame (mm), at `extension_mm`
    /// from retracted, with the lifts retracted.
    pub fn panel_position(&self, id: &str, extension_mm: f64) -> Option<[f64; 3]> {
        let actuator = self.actuator(id)?;
        let ring = self.ring(&actuator.ring)?;
        let [dx, dy] = actuator.direction();
        let radius = actuator.base_radius_mm + extension_mm;
        Some([ring.center_mm[0] + radius * dx, ring.center_mm[1] + radius * dy, ring.height_mm])
    }
}
