//! The fault spec grammar (see the module docs): parsing, printing, and checking the names
//! against a form.

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use super::{ActuatorFaultAt, FaultSpec, NodeFault, NodeFaultAt, Window};
use crate::node::ActuatorFault;
use form_description::{FormDescription, number};

/// A fault spec item that could not be understood, or names what the form lacks.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("fault spec item `{item}`: {problem}")]
pub struct FaultSpecError {
    /// The item, as written.
    pub item: String,
    /// What is wrong with it.
    pub problem: String,
}

fn error(item: &str, problem: impl Into<String>) -> FaultSpecError {
    FaultSpecError { item: item.to_string(), problem: problem.into() }
}

impl FromStr for FaultSpec {
    type Err = FaultSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let mut faults = FaultSpec::default();
        for item in spec.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            parse_item(item, &mut faults)?;
        }
        Ok(faults)
    }
}

fn parse_item(item: &str, faults: &mut FaultSpec) -> Result<(), FaultSpecError> {
    if let Some((target, fault)) = item.split_once(':') {
        return match node_address(target) {
            Some(node) => {
                let node = node.ok_or_else(|| error(item, "node addresses are 1..=63"))?;
                let (fault, window) = parse_node_fault(fault).map_err(|p| error(item, p))?;
                faults.nodes.push(NodeFaultAt { node, fault, window });
                Ok(())
            }
            None => {
                let (fault, at) = parse_actuator_fault(fault).map_err(|p| error(item, p))?;
                faults.actuators.push(ActuatorFaultAt { actuator: target.to_string(), fault, at });
                Ok(())
            }
        };
    }
    let bus = &mut faults.bus;
    let result = if let Some(value) = item.strip_prefix("seed=") {
        value.parse().map(|seed| faults.seed = seed).map_err(|_| "seed must be an integer".into())
    } else if let Some(value) = item.strip_prefix("drop=") {
        probability(value).map(|p| bus.drop = p)
    } else if let Some(value) = item.strip_prefix("corrupt=") {
        probability(value).map(|p| bus.corrupt = p)
    } else if let Some(value) = item.strip_prefix("delay=") {
        duration(value).map(|d| bus.delay = d)
    } else if let Some(value) = item.strip_prefix("busoff") {
        window(value).map(|w| bus.bus_off.push(w))
    } else {
        Err("expected seed=, drop=, corrupt=, delay=, busoff@..., nodeN:... or <actuator>:..."
            .into())
    };
    result.map_err(|p| error(item, p))
}

/// `Some(Some(n))` for `node<n>` with a valid address, `Some(None)` for another number,
/// `None` if the target is not `node<digits>`.
fn node_address(target: &str) -> Option<Option<u8>> {
    let digits = target.strip_prefix("node")?;
    if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
        return None;
    }
    Some(digits.parse().ok().filter(|n| (1..=63).contains(n)))
}

fn parse_node_fault(fault: &str) -> Result<(NodeFault, Window), String> {
    if let Some(at) = fault.strip_prefix("reboot@") {
        return Ok((NodeFault::Reboot, Window { from: duration(at)?, until: None }));
    }
    if let Some(rest) = fault.strip_prefix("silent") {
        return Ok((NodeFault::Silent, window(rest)?));
    }
    if let Some(rest) = fault.strip_prefix("slow=") {
        let (delay, when) = match rest.split_once('@') {
            Some((delay, when)) => (delay, window(&format!("@{when}"))?),
            None => (rest, Window { from: Duration::ZERO, until: None }),
        };
        return Ok((NodeFault::Slow(duration(delay)?), when));
    }
    Err(format!("unknown node fault `{fault}` (expected reboot@T, silent@T[..T], slow=D[@T[..T]])"))
}

fn parse_actuator_fault(fault: &str) -> Result<(ActuatorFault, Duration), String> {
    if let Some(at) = fault.strip_prefix("stall@") {
        return Ok((ActuatorFault::Stall, duration(at)?));
    }
    if let Some(at) = fault.strip_prefix("encoder@") {
        return Ok((ActuatorFault::Encoder, duration(at)?));
    }
    Err(format!("unknown actuator fault `{fault}` (expected stall@T or encoder@T)"))
}

fn window(text: &str) -> Result<Window, String> {
    let text = text.strip_prefix('@').ok_or("expected @time or @time..time")?;
    match text.split_once("..") {
        Some((from, until)) => {
            let (from, until) = (duration(from)?, duration(until)?);
            if until <= from {
                return Err(format!("the window ends ({until:?}) before it starts ({from:?})"));
            }
            Ok(Window { from, until: Some(until) })
        }
        None => Ok(Window { from: duration(text)?, until: None }),
    }
}

fn duration(text: &str) -> Result<Duration, String> {
    let (amount, ns_per_unit) = if let Some(n) = text.strip_suffix("us") {
        (n, 1e3)
    } else if let Some(n) = text.strip_suffix("ms") {
        (n, 1e6)
    } else if let Some(n) = text.strip_suffix('s') {
        (n, 1e9)
    } else {
        return Err(format!("`{text}` needs a unit: us, ms or s"));
    };
    // Rounded to the nanosecond, so that `1.5s` and `1500ms` are the same duration.
    let ns = amount.parse::<f64>().map(|n| (n * ns_per_unit).round());
    match ns {
        Ok(ns) if (0.0..LONGEST_S * 1e9).contains(&ns) => Ok(Duration::from_nanos(ns as u64)),
        _ => Err(format!("`{text}` is not a duration from 0 to {} s", number(LONGEST_S))),
    }
}

/// The longest time a spec names, s: about 32 years, beyond any run, and in nanoseconds well
/// within what a `Duration` built from a `u64` holds.
const LONGEST_S: f64 = 1e9;

fn probability(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|p| (0.0..1.0).contains(p))
        .ok_or_else(|| format!("`{text}` is not a probability in [0, 1)"))
}

impl FaultSpec {
    /// Checks that every node and actuator the spec names is in `form`.
    pub fn check(&self, form: &FormDescription) -> Result<(), FaultSpecError> {
        for n in &self.nodes {
            if !form.nodes.iter().any(|spec| spec.address == n.node) {
                let item = format!("node{}:{}", n.node, NodeItem(n));
                return Err(error(&item, format!("the form has no node {}", n.node)));
            }
        }
        for a in &self.actuators {
            if form.axis(&a.actuator).is_none() {
                let item = ActuatorItem(a).to_string();
                return Err(error(&item, format!("the form has no actuator `{}`", a.actuator)));
            }
        }
        Ok(())
    }
}

/// Prints a duration as the grammar reads it.
struct Time(Duration);

impl fmt::Display for Time {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let us = self.0.as_micros();
        if us.is_multiple_of(1_000_000) {
            write!(f, "{}s", us / 1_000_000)
        } else if us.is_multiple_of(1000) {
            write!(f, "{}ms", us / 1000)
        } else {
            write!(f, "{us}us")
        }
    }
}

impl fmt::Display for Window {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "@{}", Time(self.from))?;
        match self.until {
            Some(until) => write!(f, "..{}", Time(until)),
            None => Ok(()),
        }
    }
}

struct NodeItem<'a>(&'a NodeFaultAt);

impl fmt::Display for NodeItem<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let NodeFaultAt { fault, window, .. } = self.0;
        match fault {
            NodeFault::Reboot => write!(f, "reboot@{}", Time(window.from)),
            NodeFault::Silent => write!(f, "silent{window}"),
            NodeFault::Slow(delay) => write!(f, "slow={}{window}", Time(*delay)),
        }
    }
}

struct ActuatorItem<'a>(&'a ActuatorFaultAt);

impl fmt::Display for ActuatorItem<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0;
        let fault = match a.fault {
            ActuatorFault::Stall => "stall",
            ActuatorFault::Encoder => "encoder",
        };
        write!(f, "{}:{fault}@{}", a.actuator, Time(a.at))
    }
}

impl fmt::Display for FaultSpec {
    /// The spec in the grammar it is parsed from (durations to the microsecond).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut items = Vec::new();
        if self.seed != 0 {
            items.push(format!("seed={}", self.seed));
        }
        if self.bus.drop != 0.0 {
            items.push(format!("drop={}", self.bus.drop));
        }
        if self.bus.corrupt != 0.0 {
            items.push(format!("corrupt={}", self.bus.corrupt));
        }
        if !self.bus.delay.is_zero() {
            items.push(format!("delay={}", Time(self.bus.delay)));
        }
        items.extend(self.bus.bus_off.iter().map(|w| format!("busoff{w}")));
        items.extend(self.nodes.iter().map(|n| format!("node{}:{}", n.node, NodeItem(n))));
        items.extend(self.actuators.iter().map(|a| ActuatorItem(a).to_string()));
        f.write_str(&items.join(","))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "drop=0.05,corrupt=0.01,delay=2ms,busoff@3s..3200ms,node3:reboot@1500ms,\
                        node2:silent@2s..2500ms,node5:slow=40ms,chest-l1:stall@500ms,\
                        thigh-r-back:encoder@1s,seed=7";

    #[test]
    fn a_full_spec_parses_into_its_parts() {
        let spec: FaultSpec = SPEC.parse().unwrap();
        assert_eq!(spec.seed, 7);
        assert_eq!(spec.bus.drop, 0.05);
        assert_eq!(spec.bus.delay, Duration::from_millis(2));
        let bus_off =
            Window { from: Duration::from_secs(3), until: Some(Duration::from_millis(3200)) };
        assert_eq!(spec.bus.bus_off, [bus_off]);
        assert_eq!(spec.nodes.len(), 3);
        assert_eq!(spec.nodes[2].fault, NodeFault::Slow(Duration::from_millis(40)));
        assert_eq!(spec.nodes[2].window.from, Duration::ZERO);
        assert_eq!(spec.actuators[0].actuator, "chest-l1");
        assert_eq!(spec.actuators[1].fault, ActuatorFault::Encoder);
    }

    #[test]
    fn printing_gives_back_the_same_spec() {
        let spec: FaultSpec = SPEC.parse().unwrap();
        let again: FaultSpec = spec.to_string().parse().unwrap();
        assert_eq!(again, spec);
        assert_eq!("".parse::<FaultSpec>().unwrap(), FaultSpec::default());
        assert_eq!(FaultSpec::default().to_string(), "");
    }

    #[test]
    fn bad_items_are_named_with_the_problem() {
        for (spec, words) in [
            ("drop=1.5", "probability"),
            ("delay=5", "unit"),
            ("node0:reboot@1s", "1..=63"),
            ("node3:rebot@1s", "unknown node fault"),
            ("chest-l1:jam@1s", "unknown actuator fault"),
            ("busoff@2s..1s", "before it starts"),
            ("flood=3", "expected"),
            ("node3:silent", "@time"),
            ("delay=-1ms", "not a duration"),
            ("node3:reboot@1e308s", "is not a duration from 0 to 1e9 s"),
        ] {
            let error = spec.parse::<FaultSpec>().unwrap_err();
            assert!(error.to_string().contains(words), "{spec}: {error}");
            assert!(error.to_string().contains(spec.split(',').next().unwrap()), "{error}");
        }
    }

    #[test]
    fn names_are_checked_against_the_form() {
        let form = form_description::reference();
        assert!(SPEC.parse::<FaultSpec>().unwrap().check(&form).is_ok());
        let error = "node10:reboot@1s".parse::<FaultSpec>().unwrap().check(&form).unwrap_err();
        assert!(error.to_string().contains("no node 10"), "{error}");
        // A lift is an actuator like the panels': it can be stalled too.
        assert!("height:stall@1s".parse::<FaultSpec>().unwrap().check(&form).is_ok());
        let error = "chest-l9:stall@1s".parse::<FaultSpec>().unwrap().check(&form).unwrap_err();
        assert!(error.to_string().contains("no actuator `chest-l9`"), "{error}");
    }
}
