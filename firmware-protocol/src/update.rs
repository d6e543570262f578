//! A synchronised move of the whole form: staged targets for every node, then one SYNC.
//!
//! Like a CANopen PDO set latched by SYNC, or a Dynamixel sync write: the host stages each
//! node's targets (no answer), then broadcasts one `Sync` carrying the move's duration; every
//! node starts at once and plans each actuator's move to last exactly that long, so all
//! actuators arrive together. [`packets`] yields the fewest packets that do it: a node's
//! set-points cannot share a frame with another node's (the id names one node), so
//!
//! * classic CAN: one 8-byte `Targets` frame per half-node with something to move
//!   (⌈2·k / 8⌉ per node moving k actuators), plus the SYNC: **19 frames** for the reference
//!   form (72 actuators, lifts included, on 9 nodes);
//! * CAN FD and serial: one 16-byte `AllTargets` per node, plus the SYNC: **10 frames**.
//!
//! A duration is feasible for an actuator when it is at least [`shortest_duration_ms`] for
//! the distance and the actuator's limits; host and node use this one formula.

use crate::Link;
use crate::actuator::{Accel, MAX_ACTUATORS, Position, Speed};
use crate::message::{Half, Message, NodeId, Packet, Positions8, Sync};

/// The targets of one node in a form update (`None`: leave that actuator where it is).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeTargets {
    /// The node.
    pub node: NodeId,
    /// Targets of its actuators 0..=7.
    pub targets: [Option<Position>; MAX_ACTUATORS],
}

/// The packets of a full-form update over `link`, in sending order: every node's staged
/// targets, then the broadcast `Sync`. Nodes and halves without any target are skipped.
pub fn packets(nodes: &[NodeTargets], sync: Sync, link: Link) -> impl Iterator<Item = Packet> + '_ {
    let staged = nodes.iter().flat_map(move |n| {
        let all = Positions8 { positions: n.targets };
        let messages = match link {
            Link::ClassicCan => [
                Some(Message::Targets(all.half(Half::Lower))),
                Some(Message::Targets(all.half(Half::Upper))),
            ],
            Link::CanFd | Link::Serial => [Some(Message::AllTargets(all)), None],
        };
        messages
            .into_iter()
            .flatten()
            .filter(|m| match m {
                Message::Targets(four) => four.positions.iter().any(Option::is_some),
                _ => n.targets.iter().any(Option::is_some),
            })
            .map(move |m| Packet::node(n.node, m))
    });
    staged.chain([Packet::broadcast(Message::Sync(sync))])
}

/// The shortest move (ms, rounded up) over `distance` (0.01 mm) within `max_speed` and
/// `max_accel`: a triangular or trapezoidal velocity profile starting and ending at rest.
/// `None` if a limit is zero and the distance is not.
pub fn shortest_duration_ms(distance: u16, max_speed: Speed, max_accel: Accel) -> Option<u32> {
    let (max_speed, max_accel) = (max_speed.hundredths_mm_s(), max_accel.tenths_mm_s2());
    if distance == 0 {
        return Some(0);
    }
    if max_speed == 0 || max_accel == 0 {
        return None;
    }
    // Work in 0.01 mm, 0.01 mm/s, 0.01 mm/s² and integers, so both sides round alike.
    let (d, v, a) = (u64::from(distance), u64::from(max_speed), 10 * u64::from(max_accel));
    let ms = if d * a <= v * v {
        // Triangle, never reaching max_speed: t = 2·√(d/a) s = √(4·10⁶·d/a) ms.
        let square = (4_000_000 * d).div_ceil(a);
        let root = square.isqrt();
        if root * root < square { root + 1 } else { root }
    } else {
        // Trapezoid: ramps of v/a each way, cruising for the rest: t = d/v + v/a.
        (1000 * d).div_ceil(v) + (1000 * v).div_ceil(a)
    };
    Some(u32::try_from(ms).unwrap_or(u32::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`shortest_duration_ms`] with the limits in their wire units.
    fn duration(distance: u16, speed: u16, accel: u16) -> Option<u32> {
        shortest_duration_ms(
            distance,
            Speed::from_hundredths_mm_s(speed),
            Accel::from_tenths_mm_s2(accel),
        )
    }

    #[test]
    fn a_move_that_reaches_max_speed_is_a_trapezoid() {
        // 50 mm at 10 mm/s with 100 mm/s²: ramps of 0.1 s (0.5 mm each), 4.9 s cruise.
        assert_eq!(duration(5000, 1000, 1000), Some(5100));
    }

    #[test]
    fn a_short_move_is_a_triangle() {
        // 1 mm with 100 mm/s²: 2·√(0.01) s = 200 ms, peak 10 mm/s (= max_speed, the boundary).
        assert_eq!(duration(100, 1000, 1000), Some(200));
        // 0.25 mm: 2·√(0.0025) = 100 ms.
        assert_eq!(duration(25, 1000, 1000), Some(100));
    }

    proptest::proptest! {
        #[test]
        fn the_integer_formula_rounds_the_exact_duration_up_by_under_2_ms(
            distance in 1..=u16::MAX, max_speed in 1..=u16::MAX, max_accel in 1..=u16::MAX,
        ) {
            let (d, v, a) = (distance as f64 / 100.0, max_speed as f64 / 100.0, max_accel as f64 / 10.0);
            let exact_s = if d * a <= v * v { 2.0 * (d / a).sqrt() } else { d / v + v / a };
            let ms = duration(distance, max_speed, max_accel).unwrap() as f64;
            proptest::prop_assert!(ms >= exact_s * 1000.0 - 1e-6 && ms < exact_s * 1000.0 + 2.0);
        }
    }

    #[test]
    fn zero_limits_make_any_move_infeasible() {
        assert_eq!(duration(0, 0, 0), Some(0));
        assert_eq!(duration(1, 0, 10), None);
        assert_eq!(duration(1, 10, 0), None);
    }

    #[test]
    fn halves_and_nodes_without_targets_are_skipped() {
        let node = NodeId::new(2).unwrap();
        let mut targets = [None; MAX_ACTUATORS];
        targets[5] = Position::new(1000);
        let idle = NodeTargets { node: NodeId::new(3).unwrap(), targets: [None; MAX_ACTUATORS] };
        let nodes = [NodeTargets { node, targets }, idle];
        let sync = Sync { duration_ms: 1000 };
        let classic: Vec<_> =
            packets(&nodes, sync, Link::ClassicCan).map(|p| p.message.code()).collect();
        assert_eq!(classic, [crate::Code::TargetsUpper, crate::Code::Sync]);
        assert_eq!(packets(&nodes, sync, Link::Serial).count(), 2);
    }
}
